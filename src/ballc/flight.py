"""Exact free flight: a flight segment propagated in closed form instead of integrated.

When it applies -- ``exact_flight`` on and :func:`scene_allows` -- the equations of a
free-flight segment have an exact solution: no contact kernel runs, the observer is
massless (its kernels are off, so the ball is one rigid body) and the inertia is isotropic (``inertia_xx == inertia_yy ==
inertia_zz``, bit for bit), so the torque-free ball spins at a constant angular
velocity omega (inertial components, as in the state) and its centre follows a
parabola under gravity.  With ballc's quaternion kinematics qdot = 1/2 [0, omega] (x) q
(Hamilton, scalar first, omega inertial; codegen/model.py),

    q(s)  = exp(omega s / 2) (x) q0 = cos(|omega| s / 2) q0 + sin(|omega| s / 2) [0, n] (x) q0
    r(s)  = r0 + v0 s + a s^2 / 2,    v(s) = v0 + a s,    a = the gravity vector

with s = t - t0 and n = omega / |omega|; omega, the dissipated work and the tangential
deflections stay constant.

The C loop (``_driver.c``: flight_segment, ballc_flight_init/_at) propagates such a
segment instead of integrating it, whatever the method.

Events.  Every event of the segment must be a :class:`ballc.events.LinearEvent` whose
coefficients leave the quaternion out (the driver's contact-start events are
``rho - threshold``, linear in the centre: in one coordinate for a plane along an
axis, in x, y, z for a tilted one).  On the exact solution such an event is a quadratic
g(s) = c0 + c1 s + c2 s^2 whose roots are computed in closed form with the
cancellation-free formula (q = -(c1 + sign(c1) sqrt(c1^2 - 4 c2 c0)) / 2, roots q / c2
and c0 / q).  A root counts as the integrators count it: a sign change in the event's
direction (a tangency, a double root, is no crossing; a root at s = 0 counts, as in the
integrators' g_old <= 0 <= g_new test, which the driver's thresholds keep segments
away from).  The earliest root of a terminal event ends the segment, as in radau5 (ties:
the event listed first); the hits of the other events up to it are recorded.  Any other
event -- a user's callable (or a LinearEvent with quaternion terms:
:func:`polynomial_in_flight`) -- makes the segment integrated as before: user events
keep exactly the semantics (and the calls) they have with the integrator.

Samples.  With ``t_eval``: exactly the given times up to the segment's end.  Without: the
start, the end and evenly spaced times in between, at least :data:`MIN_INTERVALS`
intervals, more so that the ball turns by at most :data:`MAX_TURN` rad per interval and
that no interval is longer than ``max_step`` -- so plots of the centre and of the
orientation stay smooth; more than FLIGHT_MAX_SAMPLES (1e8) stop the run honestly.
``dense_output``: the exact solution itself (:class:`FreeFlight`, evaluated by the same
C), valid on [t0, end] of the segment.  A flown segment costs no right-hand-side call.
"""
from __future__ import annotations

import numpy as np

from . import _core, layout

_PARAMETER = {name: i for i, name in enumerate(_core.PARAMETER_NAMES)}
_QUATERNION = layout.QUATERNION
_OBSERVER_MASS, _IXX, _IYY, _IZZ = (_PARAMETER[name] for name in (
    "observer_mass", "inertia_xx", "inertia_yy", "inertia_zz"))

#: Fewest sample intervals of an exact flight segment without t_eval.
MIN_INTERVALS = _core.FLIGHT_MIN_INTERVALS
#: Largest rotation of the ball between two samples without t_eval (rad): pi / 16.
MAX_TURN = _core.FLIGHT_MAX_TURN


def scene_allows(params) -> bool:
    """Whether the parameters admit exact flight: massless observer, isotropic inertia
    (gravity, any constant vector, makes the centre's path a parabola)."""
    p = params
    return bool(p[_OBSERVER_MASS] == 0 and p[_IXX] == p[_IYY] == p[_IZZ])


def polynomial_in_flight(event) -> bool:
    """Whether a LinearEvent leaves the quaternion out: on the exact flight it is then a
    polynomial in t, its roots in closed form."""
    return (event._index is not None and event._index >= _QUATERNION.stop
            or not np.any(event.coefficients[_QUATERNION]))


class FreeFlight:
    """The exact free-flight solution from (t0, y0) under ``gravity`` (m/s^2: a number g,
    along -z, (0, 0, -g), or the acceleration vector; 0: uniform motion): ``sol(t)``
    gives the state (states,) at a scalar t, (states, len(t)) at an array of times, like
    the integrators' interpolants; evaluated in C (``_core.flight_states``, the C loop's
    own).  ``t_min``/``t_max``: the segment it was built for."""

    def __init__(self, t0, y0, gravity, t_max=None):
        self.t0 = float(t0)
        self.y0 = np.array(y0, dtype=float)
        g = np.asarray(gravity, dtype=float)
        #: the gravity vector (m/s^2)
        self.gravity = np.array([0.0, 0.0, -float(g)]) if g.ndim == 0 else g.reshape(3).copy()
        self.t_min = self.t0
        self.t_max = self.t0 if t_max is None else float(t_max)

    def __call__(self, t):
        return _core.flight_states(self.t0, self.y0, self.gravity, t)
