"""The resting end state: a ball in persistent contact that has stopped moving.

A bouncing ball whose bounces die out stays in contact with the floor, and its normal
oscillation about the static Hertz equilibrium decays (Hunt-Crossley or viscoelastic
damping).  Integrating that state to a long t_end costs steps for nothing.  The C loop
(``_driver.c``: end_state, at_rest, rolls) checks, at times of a persistent contact --
20 small-oscillation periods into it, then each time its age has grown by a quarter
(CHECK_GROWTH) or 20 periods, whichever is more -- whether the ball is at rest by the
criterion below, and if it is finishes the run analytically: the state is the static
equilibrium from then on.  This module gives it the per-scene constants.

**Criterion**, at a check time t, all of:

1. the ball is in contact with the plane gravity presses it against (the floor, for
   g > 0; a scene has g >= 0, so never the ceiling) and not with the other one;
2. the contact has lasted at least REST_PERIODS periods of small normal oscillation
   about the equilibrium, T0 = 2 pi / sqrt(k_lin / m_total), k_lin = 3/2 k0
   rho_eq^(1/2) (:func:`oscillation_period`);
3. the mechanical energy above the rest state (kinetic
   energy of ball and observer, spin about the normal included; Hertz spring plus
   gravity above their minimum at rho_eq; the compliant law's tangential spring; the
   observer's height above its lowest point) is at most the energy of an oscillation
   of REST_FACTOR times the integration tolerance: min(1/2 k_lin dx^2, 1/2 m_total
   dv^2), dx = REST_FACTOR (atol + rtol r), dv = REST_FACTOR (atol + rtol sqrt(g r))
   (:func:`energy_threshold`).  The energy in contact does not increase (the contact
   forces dissipate, gravity and the springs conserve), so the motion stays within
   that bound for ever, and replacing it with the rest state changes the centre by
   at most ~dx and its velocity by at most ~dv;
4. a massive observer sits below the centre (a ball whose observer is above it is
   in unstable equilibrium at best).

**The rest state**: velocities and angular velocity zero, the
centre at the static Hertz equilibrium rho_eq = (m_total g / k0)^(2/3)
(:func:`equilibrium_penetration`), the orientation as it is, the tangential
deflections zero, and the energy above it added to ``dissipated_normal`` so that the
energy balance stays exact.

**Not resting**: a ball that spins about the normal (the model has no torsional
friction: the spin never decays, and its energy is counted in criterion 3), a ball
rolling on the plane (no rolling resistance: it rolls for ever -- the seed scene
does, at ~0.8 m/s, from t = 30.94 s), a ball rocked by an eccentric observer.

**Uniform rolling or sliding**: when the scene's free rotation is exact
(massless observer, isotropic inertia), a contact that has settled at the equilibrium
and rolls, or slides with no force opposing its slip (mu = 0), is continued in closed
form: the contact has lasted REST_PERIODS T0; the energy above the uniform state
(vertical kinetic energy, Hertz spring plus gravity above rho_eq, tangential spring) is
below :func:`energy_threshold`; and the uniform state (the centre at the equilibrium,
vz = 0, the deflections zero, the energy booked) is a steady state of the segment's
equations -- its accelerations, linear and angular (times r), and the deflection rates
at rounding level (:func:`steady_level`).  Then v and omega are constant, the centre
moves on a straight line at z_eq and the orientation turns at omega (ballc.flight's
exact solution with g = 0).  It is *rolling* when the slip speed is at most REST_FACTOR
dv (:func:`speed_tolerance`), else *free sliding* (a slip that no force opposes: mu = 0,
or a tangential law without friction).  With the seed's observer the rolling is not
uniform: ballc.orbit continues it as a relative periodic orbit.  A closed-form end
state is sampled evenly to t_end: the turn at most ballc.flight.MAX_TURN per interval
(an orbit: 32 samples per period), at least 32 intervals, at most MAX_ROLL_SAMPLES
samples (sol(t) is exact anywhere).
"""
from __future__ import annotations

import math

import numpy as np

from . import _core

#: A contact must have lasted this many small-oscillation periods before a rest check.
REST_PERIODS = 20.0

#: The rest state is at most this many integration tolerances from the true motion.
REST_FACTOR = 10.0

#: After a failed check at contact age a, the next is at age a + max(REST_PERIODS T0,
#: CHECK_GROWTH a): a few dozen checks over any run, a detection at most 25 % late.
CHECK_GROWTH = _core.CHECK_GROWTH

#: At most this many samples of a closed-form end state (sol(t) is exact anywhere).
MAX_ROLL_SAMPLES = _core.MAX_ROLL_SAMPLES
_EPS = float(np.finfo(float).eps)


#: How far (the length of n + g/|g|) a plane's unit normal may be from opposite gravity
#: for rest and uniform rolling on it to count as exact (a scene turned as a whole keeps
#: its floor within rounding of it).
OPPOSITE_GRAVITY = 1e-12


def resting_plane_index(scene) -> int | None:
    """The index of the plane gravity presses the ball against -- the first whose normal
    is opposite gravity (within OPPOSITE_GRAVITY), where rest and uniform rolling are
    exact end states -- or None (g = 0, or no such plane: then the integration goes on)."""
    g = scene.gravity_magnitude
    if not g > 0:
        return None
    down = scene.gravity_vector / g
    for i, plane in enumerate(scene.planes):
        gap = plane.unit_normal + down
        if math.sqrt(float(gap @ gap)) <= OPPOSITE_GRAVITY:
            return i
    return None


def resting_plane(scene) -> str | None:
    """The name of the plane gravity presses the ball against (resting_plane_index), or
    None."""
    index = resting_plane_index(scene)
    return None if index is None else scene.plane_names[index]


def total_mass(scene) -> float:
    return scene.mass + scene.observer_mass


def equilibrium_penetration(scene) -> float:
    """rho_eq = (m_total g / k0)^(2/3) (m): the Hertz force k0 rho^(3/2) carries the weight."""
    return (total_mass(scene) * scene.gravity_magnitude / scene.hertz_stiffness) ** (2.0 / 3.0)


def linear_stiffness(scene) -> float:
    """d(k0 rho^(3/2))/d rho at rho_eq: 3/2 k0 rho_eq^(1/2) (N/m)."""
    return 1.5 * scene.hertz_stiffness * math.sqrt(equilibrium_penetration(scene))


def oscillation_period(scene) -> float:
    """T0 = 2 pi sqrt(m_total / k_lin) (s), the undamped small normal oscillation."""
    return 2 * math.pi * math.sqrt(total_mass(scene) / linear_stiffness(scene))


def _largest(atol) -> float:
    """atol, or its largest value when given per state."""
    return atol if type(atol) is float else float(np.max(atol))


def speed_tolerance(scene, rtol, atol) -> float:
    """dv = REST_FACTOR (atol + rtol sqrt(g r)) (m/s): REST_FACTOR integration
    tolerances of a speed."""
    return REST_FACTOR * (_largest(atol) + rtol * math.sqrt(scene.gravity_magnitude
                                                            * scene.radius))


def steady_level(scene) -> float:
    """The rounding level (1e3 eps g, m/s^2) below which a state's accelerations count as
    zero (uniform motion's steady state)."""
    return 1e3 * _EPS * scene.gravity_magnitude


def energy_threshold(scene, rtol, atol) -> float:
    """The energy (J) of an oscillation of REST_FACTOR integration tolerances."""
    dx = REST_FACTOR * (_largest(atol) + rtol * scene.radius)
    dv = speed_tolerance(scene, rtol, atol)
    return min(0.5 * linear_stiffness(scene) * dx * dx, 0.5 * total_mass(scene) * dv * dv)


class AcceleratedRolling:
    """The dense output of rolling down an unbounded incline, uniformly accelerated (the
    C loop's end state on an incline, _driver.c: incline_state): from (t0, y0), a state
    rolling without slip (omega = n x v / r), no spin about the unit normal ``normal``,
    the centre's acceleration ``acceleration`` = g_t / (1 + I / (m r^2)): the centre
    c0 + v0 s + a s^2 / 2, the velocity v0 + a s, the angular velocity
    omega(s) = (w0 + A s / r) e about the fixed axis e = n x a / A (A the length of a,
    w0 = omega0 . e), the quaternion turned about e by theta(s) = w0 s + A s^2 / (2 r), the
    rest constant (s = t - t0; isotropic inertia and a massless observer: the rotation is
    exact).  Evaluated in C (``_core.rolling_states``, the C loop's own ballc_rolling,
    which samples the end state too)."""

    def __init__(self, t0, y0, acceleration, radius, normal, t_max=None):
        self.t0, self.y0 = float(t0), np.array(y0, dtype=float)
        self.t_min, self.t_max = self.t0, self.t0 if t_max is None else float(t_max)
        self.acceleration = np.array(acceleration, dtype=float).reshape(3)
        self.radius = float(radius)
        self.normal = np.array(normal, dtype=float).reshape(3)

    def __call__(self, t):
        return _core.rolling_states(self.t0, self.y0, self.acceleration, self.radius,
                                    self.normal, t)


class Constant:
    """The dense output of the rest state: y(t) = y_rest."""

    def __init__(self, y):
        self.y = np.array(y, dtype=float)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            return self.y.copy()
        return np.repeat(self.y[:, None], t.size, axis=1)

