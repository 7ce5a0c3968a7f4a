"""The periodic end state of a ball with an eccentric observer: a relative periodic orbit.

A ball whose inertia is isotropic and whose observer has mass is Routh's sphere: a
sphere whose mass centre is off its centre, on an axis of symmetry of its inertia (the
axis a from the centre through the observer; the ball's own inertia is isotropic and
the point mass adds m_o (|p|^2 I - p p^T), symmetric about p).  Rolling (or sliding)
on the floor it wobbles: the tilt of a oscillates with a period T while the whole
motion turns about the vertical.  ballc's equations of a floor contact are invariant
under three motions that map solutions onto solutions:

* a turn of the whole scene by phi about the vertical,
* a horizontal shift d of the whole scene,
* a turn of the ball by psi about its own axis a (it leaves the mass distribution,
  the sphere and hence every force unchanged).

So when the motion's shape (the tilt of a, the heights, the speeds relative to a)
repeats after T, the whole state repeats up to one such motion G = (phi, d, psi):
y(t + T) = G y(t), and y(t + k T) = G^k y(t) for every k -- the motion is a relative
periodic orbit, and its state at any time is one integrated period moved by G^k, in
closed form (:class:`RelativePeriodicOrbit`):

    rotation about the vertical:  k phi
    shift:                        d (e^(i k phi) - 1) / (e^(i phi) - 1)   (x + i y)
    turn about a:                 k psi
    dissipated work:              + k (its increase over one period)

The computation is in C (``_orbit.c``): the C loop (``_driver.c``) runs the trial and
the measurement at its rest checks, and samples the orbit to t_end (32 samples per
period, at most ballc.resting.MAX_ROLL_SAMPLES); this module gives it the scene's
constants and reaches the same functions through the bridge (``_core.orbit_*``: the
dense output, and tests); it keeps no second copy of G or of the criteria.

**Criterion** (:func:`measure`), at a rest check that found neither rest nor uniform
motion (ballc.resting), all of:

1. the scene is Routh's sphere (isotropic inertia, a massive observer) on the floor;
2. the equations of the segment are equivariant under G at the state, to rounding:
   f(G y) = G_* f(y) (:func:`equivariant`; a latched dig-in direction that pushes,
   for example, breaks the symmetry and fails this);
3. over a trial integration of three periods (the driver's tolerances and events; no
   event may fire), the tilt of a crosses a level upwards at c0 < c1 < c2 with
   c2 - c1 = c1 - c0 = T to REST_FACTOR tolerances (each crossing bracketed on a grid of
   TILT_SAMPLES per period and refined by Brent's method to ~1e-15 s);
4. G, measured from c0 to c1, moves the whole integrated second period onto the third:
   |G y(c0 + s) - y(c1 + s)| for the states of [c1, c2] at most REST_FACTOR times
   the integration tolerance (atol + rtol |y|), each component;
5. the mechanical energy changed over the trial's two periods by at most REST_FACTOR
   rtol times the kinetic energy, plus the rest check's energy threshold
   (ballc.resting.energy_threshold): what the contact dissipates per period is at
   the scale of the error the tolerance lets an integration make.

**What it neglects**: that dissipation, period after period.  The ball's Hertz contact
damps the normal oscillation its wobble drives, so a real rolling Routh sphere slows
down, very slowly: the seed's ball dissipates ~6e-15 W (measured at rtol 1e-10 and
1e-12 alike), 6e-6 J -- 1.3e-5 of its kinetic energy -- in 1e9 s; an integration at
rtol 1e-8 drifts faster than that (3.7e-14 W).  The message reports the measured rate
and the energy the orbit neglects up to t_end; docs/limits.md, "Long runs", says
what that means for positions at very long times.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, resting

_PARAMETER = {name: i for i, name in enumerate(_core.PARAMETER_NAMES)}

#: Periods integrated to measure the orbit: one to measure G, one to test it, and the
#: stretch before the first crossing (_orbit.h).
TRIAL_PERIODS = _core.ORBIT_TRIAL_PERIODS

#: Samples of the tilt per period, to bracket its crossings (_orbit.h).
TILT_SAMPLES = _core.ORBIT_TILT_SAMPLES


def applies(scene) -> bool:
    """Routh's sphere on the floor: g > 0 along -z, every plane horizontal (the scene
    symmetric about the vertical: the motion G turns it into itself), isotropic inertia,
    a massive observer; no rolling resistance (it dissipates the rolling, and the motion
    does not turn its states)."""
    p = scene._parameters   # (read only)
    g = scene.gravity_vector
    return bool(g[2] < 0 and g[0] == 0 and g[1] == 0 and scene.observer_mass > 0
                and not scene.rolling_on
                and all(plane.normal[0] == 0 and plane.normal[1] == 0
                        for plane in scene.planes)
                and p[_PARAMETER["inertia_xx"]] == p[_PARAMETER["inertia_yy"]]
                == p[_PARAMETER["inertia_zz"]])


def body_axis(scene) -> np.ndarray:
    """The unit axis a of the ball's mass distribution, in ball components (the
    observer's direction; any axis when the observer sits at the centre)."""
    p = np.array(scene.observer_position, dtype=float)
    norm = math.sqrt(float(p.dot(p)))
    return p / norm if norm > 0 else np.array([0.0, 0.0, 1.0])


#: The seed's planes as a motion sees them (_core.motion_planes): two, the floor's
#: deflection turning with the scene, the ceiling's against it.
SEED_PLANES = (2.0, 1.0, -1.0) + (0.0,) * (_core.MAX_PLANES - 2)


class Motion:
    """G = (phi, d, psi, dissipated): turn the scene by phi about the vertical, shift it
    by d = (dx, dy), turn the ball by psi about its axis a, add ``dissipated`` (J,
    normal and tangential) to the dissipated work.  ``planes``: the scene's planes as G
    turns their deflections (_core.motion_planes: their number, then +1 or -1 each;
    default the seed's floor and ceiling)."""

    def __init__(self, phi, d, psi, axis, dissipated=(0.0, 0.0), planes=SEED_PLANES):
        self.phi, self.psi = float(phi), float(psi)
        self.d = (float(d[0]), float(d[1]))
        self.axis = np.array(axis, dtype=float).reshape(3)
        self.dissipated = np.array(dissipated, dtype=float).reshape(2)
        self.planes = tuple(float(v) for v in planes)

    @classmethod
    def from_array(cls, values):
        """G from its _core.MOTION_SIZE numbers (phi, dx, dy, psi, axis, work, planes)."""
        v = [float(x) for x in values]
        return cls(v[0], v[1:3], v[3], v[4:7], v[7:9], v[9:])

    def as_array(self):
        return np.array([self.phi, *self.d, self.psi, *self.axis, *self.dissipated,
                         *self.planes])

    def apply(self, y, k=1, rate=False):
        """G^k y for states y (N_STATES,) or (N_STATES, n), k an integer or one per
        column (phi and psi times k, the shift summed in closed form,
        d (e^(i k phi) - 1) / (e^(i phi) - 1)); with ``rate``, G_* of a time derivative
        (no shift, no added work)."""
        return _core.motion_apply(self.as_array(), y, k, rate)


def tilt(y, axis):
    """The vertical component of the ball's axis a in inertial components, a_z."""
    return _core.orbit_tilt(y, np.ascontiguousarray(axis, dtype=float))


def equivariant(params, latch, flags, y, axis) -> bool:
    """Criterion 2: f(G y) = G_* f(y) to rounding, for a G that turns, shifts and spins."""
    return _core.orbit_equivariant(np.ascontiguousarray(params, dtype=float),
                                   np.ascontiguousarray(latch, dtype=float), int(flags),
                                   np.ascontiguousarray(y, dtype=float),
                                   np.ascontiguousarray(axis, dtype=float))


class RelativePeriodicOrbit:
    """y(t) = G^k y(c0 + s) with t = c0 + k T + s, 0 <= s < T, y over [c0, c0 + T] the
    trial's integrated solution ``base``; the dense output of a run from t_min (the
    trial's end) to t_max.  Evaluated in C (_orbit.c)."""

    def __init__(self, t_min, t_max, c0, period, motion, base):
        self.t_min, self.t_max = float(t_min), float(t_max)
        self.c0, self.period, self.motion = float(c0), float(period), motion
        self.base = base
        self._motion = motion.as_array()

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        y = _core.orbit_states(np.ascontiguousarray(t.ravel()), self.c0, self.period,
                               self._motion, self.base)
        return y[:, 0] if t.ndim == 0 else y


def measure(interpolant, t0, t1, axis, guess, rtol, atol, energy_threshold, params):
    """Criteria 3-5 on a trial solution over [t0, t1] (``guess``: about one period):
    (c0, T, G, the mechanical energy's rate of change over the two periods (W)), or
    None."""
    found = _core.orbit_measure(
        interpolant, float(t0), float(t1), np.ascontiguousarray(axis, dtype=float),
        float(guess), float(rtol),
        np.ascontiguousarray(np.broadcast_to(atol, (_core.layout_of(params)[1],)), dtype=float),
        resting.REST_FACTOR, float(energy_threshold), np.ascontiguousarray(params, dtype=float))
    if found is None:
        return None
    c0, period, motion, rate = found
    return c0, period, Motion.from_array(motion), rate
