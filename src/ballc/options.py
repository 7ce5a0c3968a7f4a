"""One validator for :func:`ballc.simulate`'s integration options, every method.

Everything is checked before anything is integrated, and every error names the
option, its value and what is allowed (``ballc.SceneError``).
"""
from __future__ import annotations

import difflib
import math
from typing import NamedTuple

import numpy as np

from . import _core
from ._format import plain
from .events import LinearEvent
from .scene import Scene, SceneError

SCIPY_METHODS = ("Radau", "BDF", "LSODA", "DOP853", "RK45", "RK23")
IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")
#: ballc's compiled integrators: "radau5", Radau IIA (order 5), scipy's Radau step by
#: step in C; "dop853", Dormand & Prince's explicit pair of order 8, scipy's DOP853 step
#: by step in C (for scenes that are not stiff), in the same loop with the same events;
#: "auto", per segment dop853 switching to radau5 where Hairer's stiffness test fires and
#: back where radau5's steps are within dop853's stability bound (LSODA's idea).
COMPILED_METHODS = ("radau5", "dop853", "auto")
METHODS = COMPILED_METHODS + SCIPY_METHODS

#: Default budget of right-hand-side evaluations of one simulate call.
DEFAULT_MAX_NFEV = 20_000_000

#: scipy raises any rtol below 100 machine epsilons to that value (with a warning);
#: ballc rejects such an rtol instead of silently integrating with another one.
MIN_RTOL = float(100 * np.finfo(float).eps)


class Options(NamedTuple):
    """Validated options of one simulate call."""

    t_end: float
    method: str
    rtol: float
    atol: float | np.ndarray
    max_step: float
    first_step: float | None
    t_eval: np.ndarray | None
    max_nfev: int | None
    events: tuple
    dense_output: bool
    exact_flight: bool = True


def _is_number_like(value) -> bool:
    """A real number or an array of them (no strings, bytes or booleans)."""
    if isinstance(value, (str, bytes, bool, np.bool_)):
        return False
    try:
        return np.asarray(value).dtype.kind in "iuf"
    except (TypeError, ValueError):
        return False


def _positive_number(name, value, allow_inf=False, hint="a number > 0") -> float:
    if type(value) is float or type(value) is int:   # the common case, without numpy
        if value > 0 and (value < math.inf or allow_inf and value == math.inf):
            return float(value)
        raise SceneError(f"{name} = {plain(value)} is not allowed: must be {hint}")
    if not _is_number_like(value) or np.ndim(value) != 0:
        raise SceneError(f"{name} = {plain(value)} is not allowed: must be {hint}")
    number = float(value)
    if not (number > 0 and (math.isfinite(number) or allow_inf and number == math.inf)):
        raise SceneError(f"{name} = {plain(value)} is not allowed: must be {hint}")
    return number


def check_method(method) -> str:
    if method in METHODS:
        return method
    close = difflib.get_close_matches(str(method), METHODS, n=1, cutoff=0.5) or [
        m for m in METHODS if m.lower() == str(method).lower()]
    hint = f" (did you mean {plain(close[0])}?)" if close else ""
    raise SceneError(f"method = {plain(method)} is not allowed: must be one of {METHODS}{hint}")


def check_tolerances(rtol, atol, names=_core.STATE_NAMES):
    """(rtol, atol) as float and float-or-array, or SceneError naming the bad one
    (``names``: the run's states, one atol each when it is not one number)."""
    if (type(rtol) is float and type(atol) is float and MIN_RTOL <= rtol < math.inf
            and 0 < atol < math.inf):   # the common case, without numpy
        return rtol, atol
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not _is_number_like(value):
            raise SceneError(f"{name} = {plain(value)} is not allowed: must be a number "
                             "(atol: or one per state)")
        array = np.asarray(value, dtype=float)
        if not (np.all(np.isfinite(array)) and np.all(array > 0)):
            raise SceneError(f"{name} = {plain(value)} is not allowed: must be finite and > 0")
    if np.ndim(rtol) != 0:
        raise SceneError(f"rtol = {plain(rtol)} is not allowed: must be a single number")
    if float(rtol) < MIN_RTOL:
        raise SceneError(f"rtol = {plain(rtol)} is not allowed: must be >= 100 machine "
                         f"epsilons = {MIN_RTOL:.3g}")
    n = len(names)
    if np.ndim(atol) > 1 or np.ndim(atol) == 1 and np.size(atol) != n:
        raise SceneError(f"atol = {plain(atol)} is not allowed: must be a number or one per "
                         f"state ({n}: {', '.join(names)})")
    atol = float(atol) if np.ndim(atol) == 0 else np.array(atol, dtype=float)
    return float(rtol), atol


def check_t_eval(t_eval, t_end):
    if t_eval is None:
        return None
    given = t_eval
    if not _is_number_like(t_eval) and np.size(t_eval) != 0:
        raise SceneError(f"t_eval = {plain(given)} is not allowed: must be numbers")
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.size == 0:
        raise SceneError(f"t_eval = {plain(given)} is not allowed: must hold at least one "
                         "time (None: every solver step and event)")
    if t_eval.ndim != 1 or not np.all(np.isfinite(t_eval)) or np.any(
            np.diff(t_eval) <= 0) or t_eval.size and (t_eval[0] < 0 or t_eval[-1] > t_end):
        raise SceneError(f"t_eval = {plain(given)} is not allowed: must be a 1-D, strictly "
                         f"increasing sequence within [0, t_end = {t_end}]")
    return t_eval


def check_events(events, names=_core.STATE_NAMES) -> tuple:
    """User event functions g(t, y) with solve_ivp's optional ``terminal`` (a bool, or
    an integer k: stop at the k-th occurrence) and ``direction`` (number) attributes
    (``names``: the run's states, a LinearEvent's coefficients one each)."""
    if events is None:
        return ()
    if callable(events):
        events = [events]
    try:
        events = tuple(events)
    except TypeError:
        raise SceneError(f"events = {plain(events)} is not allowed: must be a callable "
                         "g(t, y) or a sequence of them") from None
    for k, event in enumerate(events):
        if not callable(event):
            raise SceneError(f"events[{k}] = {plain(event)} is not allowed: must be a callable "
                             "g(t, y) (with optional terminal and direction attributes)")
        terminal = getattr(event, "terminal", False)
        try:
            _core.terminal_count(terminal)
        except ValueError:
            raise SceneError(f"events[{k}].terminal = {plain(terminal)} is not allowed: must "
                             "be True, False or a whole number k >= 0 (stop at the k-th "
                             "occurrence)") from None
        direction = getattr(event, "direction", 0)
        if not _is_number_like(direction) or np.ndim(direction) != 0 or np.isnan(direction):
            raise SceneError(f"events[{k}].direction = {plain(direction)} is not allowed: must "
                             "be a number (its sign: +1 rising, -1 falling, 0 both)")
        if isinstance(event, LinearEvent):
            _check_linear_event(k, event, names)
    return events


def _check_linear_event(k, event, names):
    """A LinearEvent's coefficients (one finite number per state) and offset (finite)."""
    row = getattr(event, "coefficients", None)
    n = len(names)
    if not (_is_number_like(row) and np.shape(row) == (n,) and np.all(np.isfinite(row))):
        raise SceneError(f"events[{k}].coefficients = {plain(row)} is not allowed: must be "
                         f"{n} finite numbers, one per state ({', '.join(names)})")
    offset = getattr(event, "offset", None)
    if not (_is_number_like(offset) and np.ndim(offset) == 0 and np.isfinite(offset)):
        raise SceneError(f"events[{k}].offset = {plain(offset)} is not allowed: must be a "
                         "finite number")
    rearm = getattr(event, "rearm", None)
    if rearm is not None and not callable(rearm):
        raise SceneError(f"events[{k}].rearm = {plain(rearm)} is not allowed: must be None or "
                         "a callable (t, y) -> None or (coefficients, offset, latch)")


def check_options(scene, t_end, method="radau5", rtol=1e-10, atol=1e-10, max_step=np.inf,
                  first_step=None, t_eval=None, max_nfev=DEFAULT_MAX_NFEV, events=None,
                  dense_output=False, exact_flight=True) -> Options:
    """Validate simulate's options (see :func:`ballc.simulate`); returns :class:`Options`."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a ballc.Scene, got {type(scene).__name__}")
    t_end = _positive_number("t_end", t_end, hint="a finite number > 0")
    method = check_method(method)
    rtol, atol = check_tolerances(rtol, atol, scene.state_names)
    max_step = _positive_number("max_step", max_step, allow_inf=True,
                                hint="a number > 0 (inf for no limit)")
    if first_step is not None:
        first_step = _positive_number("first_step", first_step,
                                      hint=f"None or a number in (0, t_end = {t_end}]")
        if first_step > t_end:
            raise SceneError(f"first_step = {plain(first_step)} is not allowed: must be None or "
                             f"a number in (0, t_end = {t_end}]")
    if max_nfev is not None and (isinstance(max_nfev, (bool, np.bool_)) or not isinstance(
            max_nfev, (int, np.integer)) or max_nfev <= 0):
        raise SceneError(f"max_nfev = {plain(max_nfev)} is not allowed: must be None or an "
                         "integer > 0")
    if not isinstance(dense_output, (bool, np.bool_)):
        raise SceneError(f"dense_output = {plain(dense_output)} is not allowed: must be True "
                         "or False")
    if not isinstance(exact_flight, (bool, np.bool_)):
        raise SceneError(f"exact_flight = {plain(exact_flight)} is not allowed: must be True "
                         "or False")
    return Options(t_end=t_end, method=method, rtol=rtol, atol=atol, max_step=max_step,
                   first_step=first_step, t_eval=check_t_eval(t_eval, t_end),
                   max_nfev=None if max_nfev is None else int(max_nfev),
                   events=check_events(events, scene.state_names),
                   dense_output=bool(dense_output),
                   exact_flight=bool(exact_flight))
