"""Exact Coulomb friction as events: the slip and stick modes of a contact.

With ``friction_regularization="exact"`` (the default), a contact with a Coulomb part
(the friction model, and the friction share 1 - mixture of the mixture) alternates
smooth segments of three kinds instead of integrating the seed's regularised law
``mu F_n u / max(|u|, v_s)``, whose viscous core (time constant ~ m v_s / (mu F_n),
about 1e-12 s) makes loose tolerances crawl and chatter:

* **slip**: F_t = -mu N u/|u| (N the friction share's normal force), u the slip
  velocity.  Its *approach* event fires when u . d (d latched at the segment start)
  falls to a small speed ``clear`` (see :func:`clear_speed`); there the direction is
  frozen -- or re-latched and left free, if u has only turned away from d, or if u
  misses zero by more than the integration error can explain
  (:func:`passes_by_zero`: a slip that swings past zero, as in the seed scene's
  contacts, which miss it by ~1e-5 m/s); the next approach of such a slip fires at
  min(clear, |u|/2).  Such a re-latch leaves the right-hand side as it is, so radau5
  makes it without ending the segment (the approach event's ``rearm``, see
  simulate._Run.rearm_approach).
* **slip with a fixed direction**: F_t = -mu N d.  Near zero slip u/|u| is singular
  (its Jacobian grows like 1/|u|, and an implicit step across u = 0 cannot converge
  when u misses zero by the integration error), so the last approach to zero and the
  first departure from it keep the direction they had: its *stop* event is u . d = 0,
  its *clear* event u . d = 2 clear (then free slip resumes).  Over the few
  microseconds this lasts the true direction turns by no more than the integration
  error of u.
* **stick**: u held constant (at zero) by a tangential constraint force lambda
  computed in C from the equations of motion (a 2x2 Delassus solve).  Its *release*
  event is mu N - |lambda| = 0 (evaluated in C by radau5 and through ``_core`` by
  scipy's methods); the slip that follows starts along -lambda, so the friction force
  is continuous.

At a stop, a slip left over within the integration error (at most STOP_FACTOR times
:func:`error_speed`) is removed by a tangential impulse, and the contact sticks if
lambda lies in the cone |lambda| <= mu N, else slips on from rest along -lambda; a
larger one passes by zero and slips on freely.  (Freezing and removing every miss
below ``clear`` -- 100 times the error -- made the seed scene's final state 100 times
the tolerance off, 2.8e-6 m at 1e-8: measured.)  The seed's law is the limit
v_s -> 0 of this one.  Contact start and end close any mode.  This module holds the
decisions at the mode boundaries; the driver (simulate.py) holds the segment loop.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from . import _core, layout

PLANES = ("floor", "ceiling")
_LATCH = {name: i for i, name in enumerate(_core.LATCH_NAMES[:_core.N_LATCH_PER_PLANE])}
_SLIP_DIRECTION = _LATCH["floor_slip_direction_x"]

#: The slip speed below which the direction is held fixed: CLEAR_FACTOR times the
#: integration error scale rtol (|v| + r |omega|) + atol (see clear_speed).
CLEAR_FACTOR = 100.0

#: A slip that misses zero by more than PASS_FACTOR times the integration error scale
#: (see error_speed) passes by zero: its direction is re-latched and stays free,
#: instead of being frozen and the miss removed as if it were integration error.
#: Freezing a slip that truly misses zero by delta costs an error of a few delta, so
#: the factor bounds that error.
PASS_FACTOR = 3.0

#: At a stop (u . d = 0 with the direction held), a slip left over up to STOP_FACTOR
#: times the integration error scale is removed and the contact settles (sticks, or
#: slips from rest along -lambda, the direction it leaves in); only a larger one passes
#: by zero.  Measured over the 12 mu x mixture throws (1.2 s) at rtol 1e-4 .. 1e-10 and
#: the seed's 5-s throw at 1e-3 .. 1e-10 (1, 2, 5 per decade), worst final error over
#: rtol: 32 and 42 with (PASS, STOP) = (3, 10); 274 and 42 with (10, 10); 45 and 687
#: with (3, 3) -- a stop's leftover of 3.6 x the error taken for a pass left the slip
#: frozen along the wrong direction for 50 us (tests/test_stickslip.py).
STOP_FACTOR = 10.0

#: A slip that passes by zero is re-latched with its next approach event at
#: min(clear, APPROACH_FRACTION |u|): u . d falling to that fraction of the slip speed
#: it had at the event.
APPROACH_FRACTION = 0.5

#: At most this many re-latches of the slip direction per contact (a direction that
#: keeps turning away from its latched value) before a stop is forced.
MAX_RELATCH = 1000

#: At most this many mode changes in one contact: more means the transitions do not
#: settle (a Zeno-like sequence), and the run stops honestly.
MAX_TRANSITIONS = 100_000

#: At most this many mode changes in a row without time moving on: an event that keeps
#: firing at its segment's start.  The run stops honestly instead of looping.
MAX_STALLED = 100


def uses_exact_coulomb(scene) -> bool:
    """Whether ``scene``'s contacts have a Coulomb part integrated as stick/slip events."""
    return (scene.friction_regularization == "exact"
            and scene.tangential_model in ("friction", "mixture")
            and scene.effective_mixture < 1 and scene.friction_coefficient > 0)


def mode_flags(plane: str, mode: str | None) -> int:
    """The C flags of a plane's Coulomb mode ("slip", "slip_fixed", "stick" or None)."""
    return _core.FLAGS[f"{plane}_{mode}"] if mode else 0


#: plane -> where its slip direction d (x, y) sits in the latch vector
_SLIP_DIRECTION_SLICE = {
    plane: slice(i * _core.N_LATCH_PER_PLANE + _SLIP_DIRECTION,
                 i * _core.N_LATCH_PER_PLANE + _SLIP_DIRECTION + 2)
    for i, plane in enumerate(PLANES)}


def slip_direction(latch: np.ndarray, plane: str) -> np.ndarray:
    """The slip direction d latched for ``plane`` (a view into ``latch``)."""
    return latch[_SLIP_DIRECTION_SLICE[plane]]


def set_slip_direction(latch: np.ndarray, plane: str, direction) -> None:
    latch[_SLIP_DIRECTION_SLICE[plane]] = direction


_VELOCITY, _ANGULAR = layout.VELOCITY, layout.ANGULAR_VELOCITY


def speed_scale(scene, y) -> float:
    """|v| + r |omega| (m/s): the scale slip speeds are compared with."""
    values = y.tolist() if isinstance(y, np.ndarray) else list(y)   # Python floats: cheap
    return (math.hypot(*values[_VELOCITY]) + scene.radius * math.hypot(*values[_ANGULAR])
            + 1e-300)


def error_speed(scene, y, rtol, atol) -> float:
    """The integration error scale of the slip velocity u (m/s):
    rtol (|v| + r |omega|) + atol."""
    largest_atol = atol if isinstance(atol, float) else float(np.max(atol))
    return float(rtol) * speed_scale(scene, y) + largest_atol


def clear_speed(scene, y, rtol, atol) -> float:
    """The slip speed (m/s) below which the slip direction is held fixed: well above
    the integration error of u (CLEAR_FACTOR times :func:`error_speed`), so that a
    free-direction step never has to cross the singular u = 0."""
    return CLEAR_FACTOR * error_speed(scene, y, rtol, atol)


def passes_by_zero(u, direction, error) -> bool:
    """Whether slip u, on its way down along ``direction``, misses u = 0 by more than
    the integration error can explain: its part across ``direction`` exceeds
    PASS_FACTOR times ``error`` (m/s).  Such a slip turns past zero (its direction
    swings) and is resolved as free slip; only a miss within the error is an
    approach to zero (stop, then stick or slip from rest)."""
    along = float(u[0] * direction[0] + u[1] * direction[1])
    across = math.sqrt(max(float(u[0] * u[0] + u[1] * u[1]) - along * along, 0.0))
    return across > PASS_FACTOR * error


def force_scale(scene, load) -> float:
    """A force (N) at rounding level of the stick force: 64 eps of weight + load."""
    weight = (scene.mass + scene.observer_mass) * scene.gravity_magnitude
    return 64 * np.finfo(float).eps * (weight + abs(load))


def slip_map(params, plane: str) -> np.ndarray:
    """du/dy (2 x N_STATES) of ``plane``'s slip velocity u (u is linear in the state),
    kept per parameter vector (a run asks for it at every event).  Read-only: shared
    between callers."""
    return _slip_map(np.ascontiguousarray(params, dtype=float).tobytes(), plane)


@functools.lru_cache(maxsize=16)
def _slip_map(params_bytes: bytes, plane: str) -> np.ndarray:
    found = _core.slip_map(np.frombuffer(params_bytes), PLANES.index(plane))
    found.flags.writeable = False
    return found


def slip_stop_coefficients(params, plane: str, direction) -> np.ndarray:
    """Coefficients c of the stop event u . d = c . y (u is linear in the state):
    d_x du_x/dy + d_y du_y/dy, elementwise (the same bits with every BLAS)."""
    rows = slip_map(params, plane)
    return float(direction[0]) * rows[0] + float(direction[1]) * rows[1]


def slip_velocity(params, plane: str, y) -> np.ndarray:
    """The slip velocity u (m/s, 2) of ``plane`` at state y: du/dy . y over the few
    states it depends on, in Python floats in a fixed order (cheaper than a matrix
    product at this size, and the same bits with every BLAS)."""
    values = y.tolist() if isinstance(y, np.ndarray) else list(y)
    return np.array(slip_velocity_of(slip_terms(params, plane), values))


def slip_terms(params, plane: str) -> tuple:
    """Per row of :func:`slip_map`: its nonzero (state index, coefficient) pairs (kept
    per parameter vector)."""
    return _slip_terms(np.ascontiguousarray(params, dtype=float).tobytes(), plane)


def slip_velocity_of(terms, values) -> tuple:
    """(u_x, u_y) (m/s, Python floats) from :func:`slip_terms` and the state as a list:
    what :func:`slip_velocity` computes, for callers that keep the terms."""
    return tuple(sum([c * values[j] for j, c in row]) for row in terms)


@functools.lru_cache(maxsize=16)
def _slip_terms(params_bytes: bytes, plane: str) -> tuple:
    """Per row of :func:`slip_map`: its nonzero (state index, coefficient) pairs."""
    rows = _slip_map(params_bytes, plane)
    return tuple(tuple((int(j), float(row[j])) for j in np.flatnonzero(row)) for row in rows)


def settle(scene, params, latch, base_flags: int, plane: str, y):
    """The mode a contact takes on at zero slip: ("stick", None, y0) when the constraint
    force that holds it lies in the friction cone, else ("slip_fixed", direction, y0):
    slip from rest along -lambda.  y0 is y with the slip velocity projected to exactly
    zero."""
    index = PLANES.index(plane)
    y0 = _core.remove_slip(np.ascontiguousarray(y, dtype=float), params, base_flags, index)
    stick_flags = base_flags | mode_flags(plane, "stick")
    lam_x, lam_y, load, margin = _core.stick_state(y0, params, latch, stick_flags, index)
    size = float(np.hypot(lam_x, lam_y))
    if margin >= -force_scale(scene, load) or size == 0:
        return "stick", None, y0
    return "slip_fixed", -np.array([lam_x, lam_y]) / size, y0
