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

**Criterion** (:func:`measure`), at a rest check that found neither rest nor uniform
motion (ballc.resting), all of:

1. the scene is Routh's sphere (isotropic inertia, a massive observer) on the floor;
2. the equations of the segment are equivariant under G at the state, to rounding:
   f(G y) = G_* f(y) (:func:`equivariant`; a latched dig-in direction that pushes,
   for example, breaks the symmetry and fails this);
3. over a trial integration of three periods (the driver's tolerances and events; no
   event may fire), the tilt of a crosses a level upwards at c0 < c1 < c2 with
   c2 - c1 = c1 - c0 = T to REST_FACTOR tolerances;
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
from scipy.optimize import brentq

from . import _core, layout, resting
from .orientation import quaternion_multiply, rotation_matrix

_PARAMETER = {name: i for i, name in enumerate(_core.PARAMETER_NAMES)}
_Q, _P, _W, _V = layout.QUATERNION, layout.POSITION, layout.ANGULAR_VELOCITY, layout.VELOCITY
_DISSIPATED = layout.DISSIPATED
#: How each plane's deflection (in its own frame, components along t1, t2) turns when the
#: scene turns by phi about the vertical: by phi n_z -- the floor's (normal +z) with it,
#: the ceiling's (normal -z: t1 = x, t2 = -y) against it.
_DEFLECTION_TURN = {"floor": 1.0, "ceiling": -1.0}

#: Periods integrated to measure the orbit: one to measure G, one to test it, and the
#: stretch before the first crossing.
TRIAL_PERIODS = 3.5

#: Samples of the tilt per period, to bracket its crossings.
TILT_SAMPLES = 64


def sample_times(t0, t1, period):
    """Sample times of an orbit's closed-form stretch after t0 up to t1: 32 per period,
    at most ballc.resting.MAX_ROLL_SAMPLES (sol(t) is exact anywhere)."""
    n = min(resting.MAX_ROLL_SAMPLES, max(32, math.ceil(32 * (t1 - t0) / period)))
    t = t0 + (t1 - t0) * np.arange(1, n + 1) / n
    t[-1] = t1
    return t


def applies(scene) -> bool:
    """Routh's sphere on the floor: g > 0, isotropic inertia, a massive observer."""
    p = scene.parameter_vector()
    return bool(scene.gravity > 0 and scene.observer_mass > 0
                and p[_PARAMETER["inertia_xx"]] == p[_PARAMETER["inertia_yy"]]
                == p[_PARAMETER["inertia_zz"]])


def body_axis(scene) -> np.ndarray:
    """The unit axis a of the ball's mass distribution, in ball components (the
    observer's direction; any axis when the observer sits at the centre)."""
    p = np.array(scene.observer_position, dtype=float)
    norm = math.sqrt(float(p.dot(p)))
    return p / norm if norm > 0 else np.array([0.0, 0.0, 1.0])


class Motion:
    """G = (phi, d, psi, dissipated): turn the scene by phi about the vertical, shift it
    by d = (dx, dy), turn the ball by psi about its axis a, add ``dissipated`` (J,
    normal and tangential) to the dissipated work."""

    def __init__(self, phi, d, psi, axis, dissipated=(0.0, 0.0)):
        self.phi, self.psi = np.asarray(phi, dtype=float), np.asarray(psi, dtype=float)
        self.d = tuple(np.asarray(part, dtype=float) for part in d)
        self.axis = np.asarray(axis, dtype=float)
        self.dissipated = np.array(dissipated, dtype=float)

    def power(self, k):
        """G^k for integers k >= 0 (an int, or an array: then phi, psi, the shift and
        the work are arrays over k): phi and psi times k, the shift summed in closed
        form, d (e^(i k phi) - 1) / (e^(i phi) - 1)."""
        k = np.asarray(k, dtype=float)
        half = 0.5 * self.phi
        if abs(math.sin(half)) > 1e-300:
            factor = np.exp(1j * (k - 1) * half) * (np.sin(k * half) / math.sin(half))
        else:
            factor = k + 0j
        shift = complex(self.d[0], self.d[1]) * factor
        work = np.multiply.outer(self.dissipated, k)
        return Motion(k * self.phi, (shift.real, shift.imag), k * self.psi, self.axis, work)

    def apply(self, y, rate=False):
        """G y for states y (N_STATES,) or (N_STATES, n); with ``rate``, G_* of a time
        derivative (no shift, no added work).  phi, psi, d and the work may be arrays
        over the n columns (:meth:`power` of an array)."""
        y = np.array(y, dtype=float)
        c, s = np.cos(self.phi), np.sin(self.phi)
        half, spin_half = 0.5 * self.phi, 0.5 * self.psi
        zero = np.zeros_like(half)
        vertical = np.stack([np.cos(half), zero, zero, np.sin(half)], axis=-1)
        spin = np.concatenate([np.cos(spin_half)[..., None],
                               np.sin(spin_half)[..., None] * self.axis], axis=-1)
        out = y.copy()
        q = np.moveaxis(y[_Q], 0, -1)
        out[_Q] = np.moveaxis(quaternion_multiply(quaternion_multiply(vertical, q), spin),
                              -1, 0)
        turns = [(block, 1.0) for block in (_P, _W, _V)]
        turns += [(layout.DEFLECTION[plane], _DEFLECTION_TURN[plane]) for plane in layout.PLANES]
        for block, sense in turns:
            x, yy = y[block.start], y[block.start + 1]
            out[block.start] = c * x - sense * s * yy
            out[block.start + 1] = sense * s * x + c * yy
        if not rate:
            out[_P.start] += self.d[0]
            out[_P.start + 1] += self.d[1]
            work = self.dissipated
            out[_DISSIPATED] += work[:, None] if y.ndim == 2 and work.ndim == 1 else work
        return out


def tilt(y, axis):
    """The vertical component of the ball's axis a in inertial components, a_z."""
    q = np.moveaxis(np.asarray(y)[_Q], 0, -1)
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    norm2 = qw * qw + qx * qx + qy * qy + qz * qz
    # third row of R(q) (orientation.rotation_matrix), over |q|^2
    row = (2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), qw * qw - qx * qx - qy * qy + qz * qz)
    return (row[0] * axis[0] + row[1] * axis[1] + row[2] * axis[2]) / norm2


def equivariant(params, latch, flags, y, axis) -> bool:
    """Criterion 2: f(G y) = G_* f(y) to rounding, for a G that turns, shifts and spins."""
    test = Motion(1.0, (0.37, -0.21), 0.7, axis)
    latch = np.ascontiguousarray(latch, dtype=float)
    params = np.ascontiguousarray(params, dtype=float)
    f = _core.rhs(np.ascontiguousarray(y), params, latch, int(flags))
    f_moved = _core.rhs(np.ascontiguousarray(test.apply(y)), params, latch, int(flags))
    expected = test.apply(f, rate=True)
    scale = float(np.max(np.abs(f))) + float(np.linalg.norm(
        [params[_PARAMETER[f"gravity_{axis}"]] for axis in "xyz"]))
    return bool(np.max(np.abs(f_moved - expected)) <= 1e3 * np.finfo(float).eps * scale)


def _fit(y0, y1, axis):
    """The motion G with G y0 ~ y1: phi from the horizontal turn of a and of omega, d
    from the centre, psi from the ball's remaining turn about a."""
    turned = []
    for y in (y0, y1):
        R = rotation_matrix(y[_Q])
        a = R @ axis
        w = y[_W] / max(math.sqrt(float(y[_W].dot(y[_W]))), 1e-300)
        turned.append((complex(a[0], a[1]), complex(w[0], w[1])))
    z = sum(second * first.conjugate() for first, second in zip(turned[0], turned[1]))
    phi = math.atan2(z.imag, z.real)
    c, s = math.cos(phi), math.sin(phi)
    x0, yy0 = y0[_P.start], y0[_P.start + 1]
    d = (y1[_P.start] - (c * x0 - s * yy0), y1[_P.start + 1] - (s * x0 + c * yy0))
    vertical = np.array([math.cos(0.5 * phi), 0.0, 0.0, math.sin(0.5 * phi)])
    conj = np.array([1.0, -1.0, -1.0, -1.0])
    spin = quaternion_multiply(quaternion_multiply(y0[_Q] * conj, vertical * conj), y1[_Q])
    psi = 2.0 * math.atan2(float(spin[1:].dot(axis)), float(spin[0]))
    return Motion(phi, d, psi, axis, y1[_DISSIPATED] - y0[_DISSIPATED])


class Trial:
    """The segments integrated to measure an orbit on ``plane``: from t_from, in one
    mode, to t_to (TRIAL_PERIODS times the ``guess`` of its period)."""

    def __init__(self, plane, t_from, t_to, guess):
        self.plane, self.t_from, self.t_to, self.guess = plane, t_from, t_to, guess
        self.pieces = []
        self.broken = False

    def add(self, t0, t1, interpolant):
        """One more segment [t0, t1] and its interpolant; a segment ended by an event
        (t1 None), without dense output, or not continuing the last breaks the trial."""
        end = self.pieces[-1][1] if self.pieces else self.t_from
        if t1 is None or interpolant is None or t0 != end:
            self.broken = True
        else:
            self.pieces.append((t0, t1, interpolant))

    def solution(self, t):
        """y(t') over [t_from, t] from the trial's segments, or None when it broke."""
        if self.broken or not self.pieces or self.pieces[-1][1] != t:
            return None
        from .dense import PiecewiseSolution
        return PiecewiseSolution(self.pieces)


class RelativePeriodicOrbit:
    """y(t) from t_min on: the trial's integrated solution up to c0, then
    G^k y(c0 + s) with t = c0 + k T + s, 0 <= s < T, y over [c0, c1] the trial's."""

    def __init__(self, t_min, t_max, c0, period, motion, interpolant):
        self.t_min, self.t_max = float(t_min), float(t_max)
        self.c0, self.period, self.motion = float(c0), float(period), motion
        self.interpolant = interpolant

    def __call__(self, t):
        scalar = np.ndim(t) == 0
        tt = np.atleast_1d(np.asarray(t, dtype=float)).ravel()
        out = np.empty((_core.N_STATES, tt.size))
        before = tt < self.c0
        if np.any(before):
            out[:, before] = np.asarray(self.interpolant(tt[before])).reshape(
                _core.N_STATES, -1)
        after = ~before
        if np.any(after):
            k = np.floor((tt[after] - self.c0) / self.period)
            s = tt[after] - self.c0 - k * self.period
            s = np.clip(s, 0.0, self.period)
            base = np.asarray(self.interpolant(self.c0 + s)).reshape(_core.N_STATES, -1)
            out[:, after] = self.motion.power(k).apply(base)
        return out[:, 0] if scalar else out


def _crossings(interpolant, t0, t1, axis, level, samples):
    """Upward crossings of tilt = level in [t0, t1], each refined to rounding."""
    times = np.linspace(t0, t1, samples)
    values = tilt(interpolant(times), axis) - level
    found = []
    for i in range(samples - 1):
        if values[i] < 0 <= values[i + 1]:
            found.append(brentq(lambda t: float(tilt(interpolant(t), axis)) - level,
                                times[i], times[i + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps))
    return found


def measure(interpolant, t0, t1, axis, guess, rtol, atol, energy_threshold, params):
    """Criteria 3-5 on a trial solution over [t0, t1] (``guess``: about one period):
    (c0, T, G, the mechanical energy's rate of change over the two periods (W)), or
    None."""
    samples = int(TILT_SAMPLES * (t1 - t0) / guess) + 2
    times = np.linspace(t0, t1, samples)
    a_z = tilt(interpolant(times), axis)
    highest, lowest = float(a_z.max()), float(a_z.min())
    if highest - lowest < 1e-6:   # no wobble to measure
        return None
    level = 0.5 * (highest + lowest)
    ups = _crossings(interpolant, t0, t1, axis, level, samples)
    if len(ups) < 3:
        return None
    c0, c1, c2 = ups[:3]
    period = c1 - c0
    y0, y1, y2 = (np.asarray(interpolant(c)) for c in (c0, c1, c2))
    if abs((c2 - c1) - period) * float(np.max(np.abs(y1[_V]))) > resting.REST_FACTOR * (
            float(np.max(atol)) + rtol):
        return None
    motion = _fit(y0, y1, axis)
    s = np.linspace(0.0, period, TILT_SAMPLES + 1)
    first, second = interpolant(c0 + s), interpolant(c1 + s)
    moved = motion.apply(first)
    scale = atol[:, None] + rtol * np.abs(second) if np.ndim(atol) else atol + rtol * np.abs(second)
    misfit = np.abs(moved - second) / scale
    misfit[_DISSIPATED] = 0.0   # the work is checked as energy (criterion 5)
    if not float(np.max(misfit)) <= resting.REST_FACTOR:
        return None
    e = _core.energies(np.ascontiguousarray(np.stack([y0, y2])), params)
    mechanical = e.sum(axis=1)
    change = float(mechanical[1] - mechanical[0])
    if not abs(change) <= resting.REST_FACTOR * rtol * float(e[0, 0]) + energy_threshold:
        return None
    return c0, period, motion, change / (c2 - c0)
