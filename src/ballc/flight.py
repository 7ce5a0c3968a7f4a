"""Exact free flight: a flight segment propagated in closed form instead of integrated.

When it applies (:func:`applies`) the equations of a free-flight segment have an exact
solution: no contact kernel runs, the observer is massless (its kernels are off, so the
ball is one rigid body) and the inertia is isotropic (``inertia_xx == inertia_yy ==
inertia_zz``, bit for bit), so the torque-free ball spins at a constant angular
velocity omega (inertial components, as in the state) and its centre follows a
parabola under gravity.  With ballc's quaternion kinematics qdot = 1/2 [0, omega] (x) q
(Hamilton, scalar first, omega inertial; codegen/model.py),

    q(s)  = exp(omega s / 2) (x) q0 = cos(|omega| s / 2) q0 + sin(|omega| s / 2) [0, n] (x) q0
    r(s)  = r0 + v0 s + a s^2 / 2,    v(s) = v0 + a s,    a = (0, 0, -gravity)

with s = t - t0 and n = omega / |omega|; omega, the dissipated work and the tangential
deflections stay constant.

Events.  Every event of the segment must be a :class:`ballc.events.LinearEvent` whose
coefficients leave the quaternion out (the driver's contact-start events are
``rho - threshold``, linear in z).  On the exact solution such an event is a quadratic
g(s) = c0 + c1 s + c2 s^2 whose roots are computed in closed form with the
cancellation-free formula (q = -(c1 + sign(c1) sqrt(c1^2 - 4 c2 c0)) / 2, roots q / c2
and c0 / q).  A root counts as the integrators count it: a sign change in the event's
direction (a tangency, a double root, is no crossing; a root at s = 0 counts, as in the
integrators' g_old <= 0 <= g_new test, which the driver's thresholds keep segments
away from).  The earliest root of a terminal event ends the segment, as in radau5 (ties:
the event listed first); the hits of the other events up to it are recorded.  Any other
event -- a user's callable, a stick release -- makes :func:`applies` false and the
segment is integrated as before: user events keep exactly the semantics (and the calls)
they have with the integrator.

Samples.  With ``t_eval``: exactly the given times up to the segment's end.  Without: the
start, the end and evenly spaced times in between, at least :data:`MIN_INTERVALS`
intervals, more so that the ball turns by at most :data:`MAX_TURN` rad per interval and
that no interval is longer than ``max_step`` -- so plots of the centre and of the
orientation stay smooth.  ``dense_output``: the exact solution itself
(:class:`FreeFlight`), valid on [t0, end] of the segment.

The result is shaped like the integrators' (:func:`ballc.integrate.integrate_segment`):
``t, y, t_events, y_events, status, message, success, nfev = njev = nlu = nstep =
nreject = 0, h_next = 0`` and ``exact_flight = True``.
"""
from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import OptimizeResult

from . import _core, layout
from .events import is_linear

_PARAMETER = {name: i for i, name in enumerate(_core.PARAMETER_NAMES)}
_QUATERNION = layout.QUATERNION
_POSITION = layout.POSITION
_OMEGA = layout.ANGULAR_VELOCITY
_VELOCITY = layout.VELOCITY
_Z, _VZ = layout.INDEX["z"], layout.INDEX["vz"]
_TO_VELOCITY = _VELOCITY.start - _POSITION.start
_OBSERVER_MASS, _IXX, _IYY, _IZZ = (_PARAMETER[name] for name in (
    "observer_mass", "inertia_xx", "inertia_yy", "inertia_zz"))
_GRAVITY = [_PARAMETER[f"gravity_{axis}"] for axis in "xyz"]

#: Fewest sample intervals of an exact flight segment without t_eval.
MIN_INTERVALS = 32
#: Largest rotation of the ball between two samples without t_eval (rad).
MAX_TURN = math.pi / 16

SUCCESS = "The solver successfully reached the end of the integration interval."
TERMINATED = "A termination event occurred."


def scene_allows(params) -> bool:
    """Whether the parameters admit exact flight: massless observer, isotropic inertia
    (gravity, any constant vector, makes the centre's path a parabola)."""
    p = params
    return bool(p[_OBSERVER_MASS] == 0 and p[_IXX] == p[_IYY] == p[_IZZ])


def applies(system, events) -> bool:
    """Whether the segment of ``system`` (a ``_core.System``) with ``events`` is exact
    free flight: no kernel but the ball's (flags 0: no contact, no observer), a
    massless observer, isotropic inertia, and every event a LinearEvent of the states
    whose flight is polynomial (not the quaternion)."""
    if system.flags != 0 or not scene_allows(system.params):
        return False
    return all(is_linear(e) and polynomial_in_flight(e) for e in events)


def polynomial_in_flight(event) -> bool:
    """Whether a LinearEvent leaves the quaternion out: on the exact flight it is then a
    polynomial in t (its roots in closed form, :meth:`FreeFlight.event_polynomial`)."""
    return (event._index is not None and event._index >= _QUATERNION.stop
            or not np.any(event.coefficients[_QUATERNION]))


class FreeFlight:
    """The exact free-flight solution from (t0, y0): ``sol(t)`` gives the state
    (states,) at a scalar t, (states, len(t)) at an array of times, like the
    integrators' interpolants.  ``gravity``: a number g (along -z, (0, 0, -g)) or the
    acceleration vector.  ``t_min``/``t_max``: the segment it was built for."""

    def __init__(self, t0, y0, gravity, t_max=None):
        self.t0 = float(t0)
        self.y0 = np.array(y0, dtype=float)
        g = np.asarray(gravity, dtype=float)
        #: the gravity vector (m/s^2)
        self.gravity = np.array([0.0, 0.0, -float(g)]) if g.ndim == 0 else g.reshape(3).copy()
        self.t_min = self.t0
        self.t_max = self.t0 if t_max is None else float(t_max)
        wx, wy, wz = (float(v) for v in self.y0[_OMEGA])
        self.rate = math.sqrt(wx * wx + wy * wy + wz * wz)
        nx, ny, nz = (wx / self.rate, wy / self.rate, wz / self.rate) if self.rate > 0 else (
            0.0, 0.0, 0.0)
        # [0, n] (x) q0: the quaternion's direction of motion on the unit 3-sphere
        qw, qx, qy, qz = (float(v) for v in self.y0[_QUATERNION])
        turned = (-(nx * qx + ny * qy + nz * qz), nx * qw + ny * qz - nz * qy,
                  ny * qw + nz * qx - nx * qz, nz * qw + nx * qy - ny * qx)
        # y(s) = c0 + c1 s + c2 s^2 + c3 cos(|omega| s / 2) + c4 sin(|omega| s / 2)
        n = self.y0.size
        c = np.zeros((5, n))
        c[0] = self.y0
        c[0, _QUATERNION] = 0.0
        c[1, _POSITION] = self.y0[_VELOCITY]
        c[1, _VELOCITY] = self.gravity
        c[2, _POSITION] = 0.5 * self.gravity
        c[3, _QUATERNION] = self.y0[_QUATERNION]
        c[4, _QUATERNION] = turned
        self._c = c

    def __call__(self, t):
        if np.ndim(t) == 0:
            s = float(t) - self.t0
            half = 0.5 * self.rate * s
            c = self._c
            return c[0] + c[1] * s + c[2] * (s * s) + c[3] * math.cos(half) + c[4] * math.sin(
                half)
        s = np.asarray(t, dtype=float).ravel() - self.t0
        half = 0.5 * self.rate * s
        basis = np.empty((5, s.size))
        basis[0] = 1.0
        basis[1] = s
        np.multiply(s, s, out=basis[2])
        np.cos(half, out=basis[3])
        np.sin(half, out=basis[4])
        # einsum's own loops (no BLAS): the same bits on every machine
        return np.einsum("kn,km->nm", self._c, basis)

    def event_polynomial(self, event):
        """(c0, c1, c2): ``event`` (a LinearEvent without quaternion terms) on this
        solution, g(t0 + s) = c0 + c1 s + c2 s^2."""
        g = self.gravity
        if event._index is not None:     # one state (all of the driver's events)
            k, scale, y0 = event._index, event._scale, self.y0
            position = _POSITION.start <= k < _POSITION.stop
            velocity = _VELOCITY.start <= k < _VELOCITY.stop
            c0 = scale * y0[k] + event.offset
            c1 = scale * (y0[k + _TO_VELOCITY] if position else
                          g[k - _VELOCITY.start] if velocity else 0.0)
            c2 = 0.5 * scale * g[k - _POSITION.start] if position else 0.0
            return float(c0), float(c1), float(c2)
        c = event.coefficients
        c0 = float(c @ self.y0) + event.offset
        c1 = float(c[_POSITION] @ self.y0[_VELOCITY])
        c2 = 0.0
        for i in range(3):   # gravity's share (its zero components none)
            if g[i] != 0:
                c1 += c[_VELOCITY.start + i] * g[i]
                c2 += 0.5 * c[_POSITION.start + i] * g[i]
        return float(c0), float(c1), float(c2)


def crossings(c0, c1, c2, direction, s_max):
    """Roots s in [0, s_max] of c0 + c1 s + c2 s^2 where it changes sign in
    ``direction`` (> 0 rising, < 0 falling, 0 either), in increasing order."""
    if c2 == 0:
        if c1 == 0:
            return []
        roots = [(-c0 / c1, c1 > 0)]
    else:
        disc = c1 * c1 - 4.0 * c2 * c0
        if not disc > 0:          # no real root, or a tangency: no sign change
            return []
        q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
        low, high = sorted((q / c2, c0 / q))
        # opening upwards: falls through the lower root, rises through the higher
        roots = [(low, c2 < 0), (high, c2 > 0)]
    return [s for s, rising in roots if 0 <= s <= s_max
            and (direction == 0 or (direction > 0) == rising)]


@functools.lru_cache(maxsize=16)
def _fractions(n):
    """0, 1/n, ..., 1: the sample grid of n intervals (read only)."""
    grid = np.arange(n + 1) / n
    grid.flags.writeable = False
    return grid


def propagate(system, t0, t1, y0, events, *, t_eval=None, max_step=np.inf,
              dense_output=False):
    """The exact free-flight segment from (t0, y0) to t1 or its first terminal event
    (see the module's docstring); ``system``, ``events``, ``t_eval``, ``max_step`` and
    ``dense_output`` as for :func:`ballc.integrate.integrate_segment`."""
    flight = FreeFlight(t0, y0, system.params[_GRAVITY])
    span = t1 - t0
    hits = []                     # (s, event index)
    counts = [_core.terminal_count(event.terminal) for event in events]
    for k, event in enumerate(events):
        roots = crossings(*flight.event_polynomial(event), event.direction, span)
        if counts[k]:             # terminal at its counts[k]-th occurrence
            roots = roots[:counts[k]]
        hits += [(s, k) for s in roots]
    hits.sort()
    seen, stop = [0] * len(events), None
    for s, k in hits:
        seen[k] += 1
        if counts[k] and seen[k] >= counts[k]:
            stop = (s, k)
            break
    if stop is not None:
        hits = [h for h in hits if h <= stop]
        t_stop = min(t0 + stop[0], t1)
        status, message = 1, TERMINATED
    else:
        t_stop, status, message = t1, 0, SUCCESS
    flight.t_max = t_stop

    if t_eval is not None:
        t = np.asarray(t_eval, dtype=float)
        t = t[(t >= t0) & (t <= t_stop)]
    else:
        turn = flight.rate * (t_stop - t0) / MAX_TURN
        longest = (t_stop - t0) / max_step if max_step < np.inf else 0.0
        n = max(MIN_INTERVALS, math.ceil(turn), math.ceil(longest))
        t = t0 + (t_stop - t0) * _fractions(n)
        t[-1] = t_stop
    y = flight(t) if t.size else np.empty((len(y0), 0))

    t_events = [[] for _ in events]
    for s, k in hits:
        t_events[k].append(t_stop if (s, k) == stop else min(t0 + s, t1))
    empty = np.empty((0, len(y0)))
    y_events = [empty if not te else y[:, -1:].T.copy() if te == [t_stop] and t_eval is None
                else flight(te).T for te in t_events]
    return OptimizeResult(t=t, y=y, t_events=[np.array(te, dtype=float) for te in t_events],
                          y_events=y_events, status=status, message=message, success=True,
                          nfev=0, njev=0, nlu=0, nstep=0, nreject=0, h_next=0.0, sol=None,
                          interpolant=flight if dense_output else None, exact_flight=True)
