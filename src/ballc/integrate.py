"""The one seam between the driver and an integrator: integrate one smooth segment.

``method`` "radau5" runs ballc's compiled Radau IIA (scipy's Radau, step by step in
C) on the system's C right-hand side and Jacobian, "dop853" ballc's compiled DOP853
(scipy's DOP853, in the same C loop, with the same events), "auto" the two switching in
that loop (docs/architecture.md, "The automatic method"); any other is handed to scipy's
``solve_ivp`` by :func:`ballc.scipy_segment.solve` (with the analytic Jacobian when
implicit, and a call budget).  With
``exact_flight``, a free-flight segment that has an exact solution (massless observer,
isotropic inertia, only linear events: :func:`ballc.flight.applies`) is not integrated
at all but propagated in closed form by :func:`ballc.flight.propagate`, whatever the
method.
"""
from __future__ import annotations

import numpy as np

from typing import NamedTuple

from . import _core, _radau5, dense, flight, scipy_segment
from .options import COMPILED_METHODS


class Segment(NamedTuple):
    """What a segment integrates: the parameter vector, the latched values and the flags
    of ``_core.System``, held as they are (no copies: the compiled integrators copy
    what they may write, and scipy's methods get a ``_core.System`` built from it)."""
    params: np.ndarray
    latch: np.ndarray
    flags: int


def integrate_segment(system, t0, t1, y0, events, *, method, rtol, atol, t_eval, max_step,
                      max_nfev=None, first_step=None, dense_output=False, exact_flight=False,
                      auto_implicit=False):
    """Integrate one smooth segment; returns a solve_ivp-style solution.

    This is the one seam between the driver and an integrator.  The solution has
    ``t, y, t_events, y_events, status (0 reached t1, 1 terminal event, -1 failure),
    message, nfev, njev, nlu`` and, with ``dense_output``, ``interpolant``: a callable
    y(t) over [t0, t_last] (see ballc.dense).  ``system``: a ``_core.System``, or a
    :class:`Segment` (the same inputs, not copied).  Events are callables g(t, y) with
    ``terminal`` and ``direction``: :class:`ballc.events.LinearEvent` and
    :class:`ballc.events.StickRelease`, which radau5 evaluates in C, or any other
    (a user's), which it calls back.  ``max_nfev``: give up (status -1, keeping what
    was computed) after that many right-hand-side calls.  ``exact_flight``: propagate
    the segment in closed form when :func:`ballc.flight.applies` (then ``nfev`` is 0,
    ``first_step`` and ``max_nfev`` play no part, ``max_step`` only bounds the spacing
    of the samples, and the solution has ``exact_flight = True``).  ``auto_implicit``
    (method "auto" only): start with radau5 instead of dop853 (the driver's segment
    that continues one which ended with radau5, with its step).  Method "auto" also
    returns ``switches``, [(t, method switched to)], and ``method_end``.
    """
    events = list(events)
    if exact_flight and flight.applies(system, events):
        return flight.propagate(system, t0, t1, y0, events, t_eval=t_eval,
                                max_step=max_step, dense_output=dense_output)
    if first_step is not None:   # a step carried over may be longer than what is left
        first_step = min(first_step, t1 - t0)
    if method in COMPILED_METHODS:
        sol = _radau5.solve_system(system.params, system.latch, system.flags, (t0, t1), y0,
                                   rtol=rtol, atol=atol, max_step=max_step, t_eval=t_eval,
                                   events=events, max_nfev=max_nfev, first_step=first_step,
                                   dense_output=dense_output, method=method,
                                   auto_implicit=auto_implicit and method == "auto")
        if dense_output:
            sol.interpolant = dense.CompiledInterpolant(*sol.dense)
        return sol
    if isinstance(system, Segment):
        system = _core.System(system.params, system.latch, system.flags)
    sol = scipy_segment.solve(system, t0, t1, y0, events, method=method, rtol=rtol,
                              atol=atol, t_eval=t_eval, max_step=max_step,
                              max_nfev=max_nfev, first_step=first_step,
                              dense_output=dense_output)
    if dense_output:
        sol.interpolant = sol.sol
    return sol


#: Below this absolute tolerance (m, m/s) a contact's state can be tighter than the
#: rounding of its depth r - z allows (see failure_hint).
TIGHT_ATOL = 1e-10


def failure_hint(scene, in_contact, atol=None):
    """Why a contact segment may defeat the integrator, when the cause is one of the
    usual ones (:func:`_tight_atol_hint`, :func:`_regularised_friction_hint`); "" out of
    contact."""
    if not any(in_contact.values()):
        return ""
    return _tight_atol_hint(atol) + _regularised_friction_hint(scene)


def _tight_atol_hint(atol):
    """An absolute tolerance below the rounding of the contact depth r - z (a stiff ball
    at rest: z ~ r, so r - z keeps few digits, and the Hertz force's rounding noise
    keeps the Newton iteration from converging to a centre height or vertical velocity
    within atol; measured: a steel ball, E = 2e11 Pa, at rest, crawled with atol = 1e-12
    and ran with atol = 1e-10 on z or vz alone, docs/limits.md)."""
    if atol is None or float(np.min(atol)) >= TIGHT_ATOL:
        return ""
    return (f" (in contact with atol = {float(np.min(atol)):g}: so tight an absolute "
            "tolerance on the centre's height and vertical velocity can be below the "
            "rounding noise of the contact depth r - z, most of all for a hard ball "
            f"at rest; try atol >= {TIGHT_ATOL:g} (one number, or per state: "
            "ballc.STATE_NAMES))")


def _regularised_friction_hint(scene):
    """The seed's regularised Coulomb law ("max", "smooth") with a small v_s."""
    if scene.tangential_model not in ("friction", "mixture"):
        return ""
    if scene.friction_coefficient == 0 or scene.effective_mixture == 1:
        return ""
    if scene.friction_regularization == "exact":
        return ""
    return (f" (in contact with regularised Coulomb friction: below the regularisation "
            f"speed {scene.friction_regularization_speed:g} m/s friction is a viscous law "
            "of coefficient mu F_n / v_s, too stiff to resolve for hard materials or loose "
            "tolerances; use friction_regularization='exact' (the default), or tighter rtol)")
