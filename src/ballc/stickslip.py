"""Exact Coulomb friction as events: the slip and stick modes of a contact.

With ``friction_regularization="exact"`` (the default), a contact with a Coulomb part
(the friction model, and the friction share 1 - mixture of the mixture) alternates
smooth segments of three kinds instead of integrating the seed's regularised law
``mu F_n u / max(|u|, v_s)``, whose viscous core (time constant ~ m v_s / (mu F_n),
about 1e-12 s) makes loose tolerances crawl and chatter:

* **slip**: F_t = -mu N u/|u| (N the friction share's normal force), u the slip
  velocity.  Its *approach* event fires when u . d (d latched at the segment start)
  falls to a small speed ``clear`` (CLEAR_FACTOR times the error scale below); there
  the direction is frozen -- or re-latched and left free, if u has only turned away
  from d, or if u misses zero by more than the integration error can explain
  (PASS_FACTOR times it: a slip that swings past zero, as in the seed scene's
  contacts, which miss it by ~1e-5 m/s); the next approach of such a slip fires at
  min(clear, |u|/2).  Such a re-latch leaves the right-hand side as it is, so the
  compiled integrators make it without ending the segment (the approach event is
  re-armed in C).
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
the error scale rtol (|v| + r |omega|) + atol, atol's largest) is removed by a
tangential impulse, and the contact sticks if lambda lies in the cone |lambda| <= mu N, else slips on from rest along -lambda; a
larger one passes by zero and slips on freely.  (Freezing and removing every miss
below ``clear`` -- 100 times the error -- made the seed scene's final state 100 times
the tolerance off, 2.8e-6 m at 1e-8: measured.)  The seed's law is the limit
v_s -> 0 of this one.  Contact start and end close any mode.  The C loop
(``_driver.c``: start_coulomb, coulomb_event, settle, and the approach's re-arm) makes
these decisions, with the constants below; this module names them and gives the C loop
the slip velocity's map (:func:`slip_map`).
"""
from __future__ import annotations

import functools

import numpy as np

from . import _core

PLANES = ("floor", "ceiling")

#: The slip speed below which the direction is held fixed: CLEAR_FACTOR times the
#: integration error scale rtol (|v| + r |omega|) + atol (atol: its largest).
CLEAR_FACTOR = _core.CLEAR_FACTOR

#: A slip that misses zero by more than PASS_FACTOR times the integration error scale
#: passes by zero: its direction is re-latched and stays free, instead of being frozen
#: and the miss removed as if it were integration error.  Freezing a slip that truly
#: misses zero by delta costs an error of a few delta, so the factor bounds that error.
PASS_FACTOR = _core.PASS_FACTOR

#: At a stop (u . d = 0 with the direction held), a slip left over up to STOP_FACTOR
#: times the integration error scale is removed and the contact settles (sticks, or
#: slips from rest along -lambda, the direction it leaves in); only a larger one passes
#: by zero.  Measured over the 12 mu x mixture throws (1.2 s) at rtol 1e-4 .. 1e-10 and
#: the seed's 5-s throw at 1e-3 .. 1e-10 (1, 2, 5 per decade), worst final error over
#: rtol: 32 and 42 with (PASS, STOP) = (3, 10); 274 and 42 with (10, 10); 45 and 687
#: with (3, 3) -- a stop's leftover of 3.6 x the error taken for a pass left the slip
#: frozen along the wrong direction for 50 us (tests/test_stickslip.py).
STOP_FACTOR = _core.STOP_FACTOR

#: A slip that passes by zero is re-latched with its next approach event at
#: min(clear, APPROACH_FRACTION |u|): u . d falling to that fraction of the slip speed
#: it had at the event.
APPROACH_FRACTION = _core.APPROACH_FRACTION

#: At most this many re-latches of the slip direction per contact (a direction that
#: keeps turning away from its latched value) before a stop is forced.
MAX_RELATCH = _core.MAX_RELATCH

#: At most this many mode changes in one contact: more means the transitions do not
#: settle (a Zeno-like sequence), and the run stops honestly.
MAX_TRANSITIONS = _core.MAX_TRANSITIONS

#: At most this many mode changes in a row without time moving on: an event that keeps
#: firing at its segment's start.  The run stops honestly instead of looping.
MAX_STALLED = _core.MAX_STALLED


def uses_exact_coulomb(scene) -> bool:
    """Whether ``scene``'s contacts have a Coulomb part integrated as stick/slip events."""
    return (scene.friction_regularization == "exact"
            and scene.tangential_model in ("friction", "mixture")
            and scene.effective_mixture < 1 and scene.friction_coefficient > 0)


def slip_map(params, plane: str) -> np.ndarray:
    """du/dy (2 x N_STATES) of ``plane``'s slip velocity u (u is linear in the state),
    kept per parameter vector.  Read-only: shared between callers."""
    return _slip_map(np.ascontiguousarray(params, dtype=float).tobytes(), plane)


@functools.lru_cache(maxsize=16)
def _slip_map(params_bytes: bytes, plane: str) -> np.ndarray:
    found = _core.slip_map(np.frombuffer(params_bytes), PLANES.index(plane))
    found.flags.writeable = False
    return found


def slip_velocity(params, plane: str, y) -> np.ndarray:
    """The slip velocity u (m/s, 2) of ``plane`` at state y (one state, or N_STATES rows
    of states: then (2, n)): du/dy . y."""
    return slip_map(params, plane) @ np.asarray(y, dtype=float)
