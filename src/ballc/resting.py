"""The resting end state: a ball in persistent contact that has stopped moving.

A bouncing ball whose bounces die out stays in contact with the floor, and its normal
oscillation about the static Hertz equilibrium decays (Hunt-Crossley or viscoelastic
damping).  Integrating that state to a long t_end costs steps for nothing.  The driver
(ballc.simulate) checks, at times of a persistent contact, whether the ball is at rest
by the criterion below, and if it is finishes the run analytically: the state is the
static equilibrium from then on.

**Criterion** (:func:`at_rest`), at a check time t, all of:

1. the ball is in contact with the plane gravity presses it against (the floor, for
   g > 0; a scene has g >= 0, so never the ceiling) and not with the other one;
2. the contact has lasted at least REST_PERIODS periods of small normal oscillation
   about the equilibrium, T0 = 2 pi / sqrt(k_lin / m_total), k_lin = 3/2 k0
   rho_eq^(1/2) (:func:`oscillation_period`);
3. the mechanical energy above the rest state (:func:`energy_above_rest`: kinetic
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

**The rest state** (:func:`rest_state`): velocities and angular velocity zero, the
centre at the static Hertz equilibrium rho_eq = (m_total g / k0)^(2/3)
(:func:`equilibrium_penetration`), the orientation as it is, the tangential
deflections zero, and the energy above it added to ``dissipated_normal`` so that the
energy balance stays exact.

**Not resting**: a ball that spins about the normal (the model has no torsional
friction: the spin never decays, and its energy is counted in criterion 3), a ball
rolling on the plane (no rolling resistance: it rolls for ever -- the seed scene
does, at ~0.8 m/s, from t = 30.94 s), a ball rocked by an eccentric observer.

**Uniform rolling or sliding** (:func:`rolls`): when the scene's free rotation is exact
(massless observer, isotropic inertia), a contact that has settled at the equilibrium
and rolls, or slides with no force opposing its slip (mu = 0), is continued in closed
form (see :func:`rolls` for the criterion).  With the seed's observer the rolling is
not uniform: ballc.orbit continues it as a relative periodic orbit.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, layout

#: A contact must have lasted this many small-oscillation periods before a rest check.
REST_PERIODS = 20.0

#: The rest state is at most this many integration tolerances from the true motion.
REST_FACTOR = 10.0

#: After a failed check at contact age a, the next is at age a + max(REST_PERIODS T0,
#: CHECK_GROWTH a): a few dozen checks over any run, a detection at most 25 % late.
CHECK_GROWTH = 0.25

_STATE = layout.INDEX
_Z, _VELOCITY, _ANGULAR = _STATE["z"], layout.VELOCITY, layout.ANGULAR_VELOCITY
_DEFLECTION = layout.DEFLECTION


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
        if float(np.linalg.norm(plane.unit_normal + down)) <= OPPOSITE_GRAVITY:
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


def first_check(scene, t_start) -> float:
    return t_start + REST_PERIODS * oscillation_period(scene)


def next_check(scene, t_start, t) -> float:
    return t + max(REST_PERIODS * oscillation_period(scene), CHECK_GROWTH * (t - t_start))


def speed_tolerance(scene, rtol, atol) -> float:
    """dv = REST_FACTOR (atol + rtol sqrt(g r)) (m/s): REST_FACTOR integration
    tolerances of a speed."""
    return REST_FACTOR * (float(np.max(atol)) + rtol * math.sqrt(scene.gravity_magnitude * scene.radius))


def steady_level(scene) -> float:
    """The rounding level (1e3 eps g, m/s^2) below which a state's accelerations count as
    zero (:func:`rolls`' steady state)."""
    return 1e3 * np.finfo(float).eps * scene.gravity_magnitude


def energy_threshold(scene, rtol, atol) -> float:
    """The energy (J) of an oscillation of REST_FACTOR integration tolerances."""
    dx = REST_FACTOR * (float(np.max(atol)) + rtol * scene.radius)
    dv = speed_tolerance(scene, rtol, atol)
    return min(0.5 * linear_stiffness(scene) * dx * dx, 0.5 * total_mass(scene) * dv * dv)


def _observer_offset(scene, y):
    """(horizontal, vertical) offset (m) of the observer from the centre."""
    params = scene.parameter_vector()
    where = _core.observer_positions(np.ascontiguousarray(y[None, :]), params)[0]
    d = where - y[layout.rows("x", 3)]
    return math.hypot(d[0], d[1]), float(d[2])


def energy_above_rest(scene, y, plane="floor") -> float:
    """The mechanical energy (J) of state y above the rest state on ``plane``, each
    term computed without cancellation (see the module docstring)."""
    e = _core.energies(np.ascontiguousarray(y[None, :]), scene.parameter_vector())[0]
    kinetic, tangential_spring = float(e[0]), float(e[4] + e[5])
    rho_eq = equilibrium_penetration(scene)
    rho = scene.radius - y[_Z]
    x = (rho - rho_eq) / rho_eq
    weight = total_mass(scene) * scene.gravity_magnitude
    # (2/5) k0 (rho^(5/2) - rho_eq^(5/2)) - m g (rho - rho_eq), k0 rho_eq^(3/2) = m g
    normal = weight * rho_eq * (0.4 * math.expm1(2.5 * math.log1p(x)) - x) if x > -1 else \
        math.inf
    observer = 0.0
    if scene.observer_mass > 0:
        across, up = _observer_offset(scene, y)
        reach = math.hypot(across, up)
        observer = scene.observer_mass * scene.gravity_magnitude * across * across / (
            reach + abs(up)) if reach > 0 else 0.0
    return kinetic + max(normal, 0.0) + tangential_spring + observer


def at_rest(scene, y, plane, t_start, t, rtol, atol) -> bool:
    """Whether the contact with ``plane`` (since ``t_start``) has come to rest at state
    y and time t (criteria 2-4 of the module docstring; the caller checks 1)."""
    if plane != resting_plane(scene) or t - t_start < REST_PERIODS * oscillation_period(scene):
        return False
    if scene.observer_mass > 0 and _observer_offset(scene, y)[1] >= 0:
        return False
    return energy_above_rest(scene, y, plane) <= energy_threshold(scene, rtol, atol)


def rest_state(scene, y, plane="floor"):
    """The rest state for state y (see the module docstring): a new array."""
    rest = np.array(y, dtype=float)
    rest[_VELOCITY] = 0.0
    rest[_ANGULAR] = 0.0
    rest[_Z] = scene.radius - equilibrium_penetration(scene)
    rest[_DEFLECTION["floor"]] = 0.0
    rest[_DEFLECTION["ceiling"]] = 0.0
    return _booked(scene, y, rest)


def _booked(scene, y, new):
    """``new`` with the mechanical energy y has above it added to dissipated_normal."""
    both = _core.energies(np.ascontiguousarray(np.stack([y, new])), scene.parameter_vector())
    before, after = (float(row[0] + row[1] + row[2] + row[3] + row[4] + row[5])
                     for row in both)
    new[_STATE["dissipated_normal"]] += before - after
    return new


# ---- uniform rolling ----

#: At most this many samples of a closed-form rolling stretch (sol(t) is exact anywhere).
MAX_ROLL_SAMPLES = 4096


def rolling_state(scene, y):
    """The uniform rolling state for y: the centre at the static equilibrium, vz = 0,
    tangential deflections zero, the rest as it is; energy booked (see rest_state)."""
    roll = np.array(y, dtype=float)
    roll[_Z] = scene.radius - equilibrium_penetration(scene)
    roll[_STATE["vz"]] = 0.0
    roll[_DEFLECTION["floor"]] = 0.0
    roll[_DEFLECTION["ceiling"]] = 0.0
    return _booked(scene, y, roll)


def rolls(scene, y, plane, t_start, t, rtol, atol, slip_speed, params, latch, flags):
    """(the uniform state, "rolling" or "free_sliding") when the contact with ``plane``
    (since ``t_start``) moves uniformly at state y and time t, else None.

    Criterion: the scene has an exact free rotation (ballc.flight.scene_allows:
    massless observer, isotropic inertia); the contact has lasted REST_PERIODS T0;
    the energy above the uniform state (vertical kinetic energy, Hertz spring plus
    gravity above rho_eq, tangential spring) is below :func:`energy_threshold`; and the
    uniform state is a steady state of the segment's equations (flags, latch): its
    accelerations, linear and angular (times r), and the deflection rates are at
    rounding level (1e3 eps g).  Then the motion is exact: v and omega constant, the
    centre on a straight line at z_eq, the orientation turning at omega
    (ballc.flight.FreeFlight with g = 0).  It is *rolling* when the slip speed
    ``slip_speed`` is at most REST_FACTOR dv, else *free sliding* (a slip that no
    force opposes: mu = 0, or a tangential law without friction)."""
    from . import flight
    if plane != resting_plane(scene) or t - t_start < REST_PERIODS * oscillation_period(scene):
        return None
    if not flight.scene_allows(params):
        return None
    dv = speed_tolerance(scene, rtol, atol)
    e = _core.energies(np.ascontiguousarray(y[None, :]), params)[0]
    rho_eq = equilibrium_penetration(scene)
    x = (scene.radius - y[_Z] - rho_eq) / rho_eq
    if not x > -1:
        return None
    weight = total_mass(scene) * scene.gravity_magnitude
    above = (0.5 * total_mass(scene) * y[_STATE["vz"]] ** 2 + float(e[4] + e[5])
             + max(weight * rho_eq * (0.4 * math.expm1(2.5 * math.log1p(x)) - x), 0.0))
    if not above <= energy_threshold(scene, rtol, atol):
        return None
    roll = rolling_state(scene, y)
    rate = _core.rhs(np.ascontiguousarray(roll), np.ascontiguousarray(params, dtype=float),
                     np.ascontiguousarray(latch, dtype=float), int(flags))
    level = steady_level(scene)
    if (np.max(np.abs(rate[_VELOCITY])) > level
            or scene.radius * np.max(np.abs(rate[_ANGULAR])) > level
            or np.max(np.abs(rate[_DEFLECTION["floor"]])) > level
            or np.max(np.abs(rate[_DEFLECTION["ceiling"]])) > level):
        return None
    return roll, ("rolling" if slip_speed <= dv else "free_sliding")


def rolling_samples(t0, t1, rate):
    """Sample times of a closed-form rolling stretch after t0 up to t1: the turn at most
    ballc.flight.MAX_TURN per interval, at least 32 and at most MAX_ROLL_SAMPLES."""
    from . import flight
    n = min(MAX_ROLL_SAMPLES, max(flight.MIN_INTERVALS,
                                  math.ceil(rate * (t1 - t0) / flight.MAX_TURN)))
    t = t0 + (t1 - t0) * np.arange(1, n + 1) / n
    t[-1] = t1
    return t


class AcceleratedRolling:
    """The dense output of rolling down an unbounded incline, uniformly accelerated
    (the C loop's end state on an incline, _driver.c: incline_state): from (t0, y0), a
    state rolling without slip (omega = n x v / r), no spin about the normal, moving along
    the acceleration ``acceleration`` = g_t / (1 + I / (m r^2)): the centre
    c0 + v0 s + a s^2 / 2, the velocity v0 + a s, the angular velocity
    omega(s) = (w0 + A s / r) e about the fixed axis e = n x a / A (A the length of a,
    w0 = omega0 . e), the quaternion turned about e by theta(s) = w0 s + A s^2 / (2 r), the
    rest constant
    (s = t - t0; isotropic inertia and a massless observer: the rotation is exact)."""

    def __init__(self, t0, y0, acceleration, radius, normal, t_max=None):
        self.t0, self.y0 = float(t0), np.array(y0, dtype=float)
        self.t_min, self.t_max = self.t0, self.t0 if t_max is None else float(t_max)
        self.a = np.array(acceleration, dtype=float)
        self.spin_rate = float(np.linalg.norm(self.a)) / float(radius)   # rad/s^2
        axis = np.cross(np.asarray(normal, dtype=float), self.a)
        self.axis = axis / np.linalg.norm(axis)                          # n x a / |a|
        self.w0 = float(self.y0[layout.ANGULAR_VELOCITY] @ self.axis)

    def _angle(self, s):
        return self.w0 * s + 0.5 * self.spin_rate * s * s

    def sample_times(self, t_end):
        """Sample times after t0 up to t_end: the turn at most ballc.flight.MAX_TURN per
        interval, at least 32 and at most MAX_ROLL_SAMPLES (sol(t) is exact anywhere)."""
        from . import flight
        turn = abs(self._angle(t_end - self.t0))
        n = min(MAX_ROLL_SAMPLES, max(flight.MIN_INTERVALS, math.ceil(turn / flight.MAX_TURN)))
        t = self.t0 + (t_end - self.t0) * np.arange(1, n + 1) / n
        t[-1] = t_end
        return t

    def __call__(self, t):
        from .orientation import quaternion_multiply
        t = np.asarray(t, dtype=float)
        s = (t - self.t0).ravel()
        y = np.repeat(self.y0[:, None], s.size, axis=1)
        y[layout.POSITION] += self.y0[layout.VELOCITY][:, None] * s + 0.5 * self.a[:, None] * s * s
        y[layout.VELOCITY] += self.a[:, None] * s
        y[layout.ANGULAR_VELOCITY] = self.axis[:, None] * (self.w0 + self.spin_rate * s)
        half = 0.5 * self._angle(s)
        turn = np.column_stack([np.cos(half), np.sin(half)[:, None] * self.axis])
        y[layout.QUATERNION] = quaternion_multiply(turn, self.y0[layout.QUATERNION][None, :]).T
        return y[:, 0] if t.ndim == 0 else y.reshape((-1,) + t.shape)


def accelerating_message(scene, plane, t, y, acceleration, success) -> str:
    """The message of a run that rolls down ``plane`` uniformly accelerated from ``t``."""
    v = float(np.linalg.norm(y[layout.VELOCITY]))
    return (f"{success} The ball rolls down the {plane} without slip from t = {t:.9g} s at "
            f"{v:.6g} m/s, uniformly accelerated at {float(np.linalg.norm(acceleration)):.6g} "
            "m/s^2 (g_t / (1 + I / (m r^2)), g_t gravity along the plane; nothing else is "
            "reached by t_end); from there to t_end the state is that rolling, in closed "
            "form.")


class Constant:
    """The dense output of the rest state: y(t) = y_rest."""

    def __init__(self, y):
        self.y = np.array(y, dtype=float)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            return self.y.copy()
        return np.repeat(self.y[:, None], t.size, axis=1)


def why_no_end_state(scene, contacts, t_end) -> str:
    """What a run that went on to ``t_end`` in a long contact (more than REST_PERIODS
    small-oscillation periods) says about why no end state finished it in closed form:
    rest and uniform rolling are exact only on a plane whose normal is opposite gravity,
    alone (resting_plane_index); on any other plane -- an incline, where rolling is
    uniformly accelerated -- or against two planes at once the integration goes on.
    "" when no such contact was open at the end."""
    open_ = [c for c in contacts if c.t_end != c.t_end and c.t_rest != c.t_rest
             and c.t_rolling != c.t_rolling and c.t_sliding != c.t_sliding]
    if not open_ or not scene.gravity_magnitude > 0:
        return ""
    long_ago = t_end - REST_PERIODS * oscillation_period(scene)
    open_ = [c for c in open_ if c.t_start <= long_ago]
    if not open_:
        return ""
    names = " and the ".join(c.plane for c in open_)
    resting = resting_plane_index(scene)
    if len(open_) > 1:
        why = (f"the ball is in contact with the {names} at once (rest and uniform rolling "
               "are checked on a plane whose normal is opposite gravity, alone)")
    elif resting is None or open_[0].plane != scene.plane_names[resting]:
        why = (f"the ball is in contact with the {names}, whose normal is not opposite "
               "gravity: rest and uniform rolling are exact end states only on such a "
               "plane; rolling down an incline, uniformly accelerated, ends in closed form "
               "only once it rolls without slip straight down the slope without spin "
               "about the normal, reaching no other plane by t_end (a massless observer, "
               "isotropic inertia)")
    else:
        return ""
    return f" No closed-form end state: {why}; the integration went on to t_end."
