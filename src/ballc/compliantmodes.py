"""The compliant law's Coulomb cap as exact modes: elastic and sliding.

The DEM codes step the incremental Mindlin spring explicitly and truncate the stored
force to the cap mu F_n after each step.  In the limit dt -> 0 that is a hybrid system
with two modes per contact (docs/contact_laws.md, "Exact elastic and sliding modes"):

* **elastic** (below the cap; the ``<plane>_compliant_elastic`` kernels): the spring
  alone, s' = v_t - max(rhodot, 0)/(2 rho) s, F_el = -k_t s, with viscous damping
  within the capacity the elastic force leaves.  Guard **yield**: 1 - k_t |s| / (mu F_n)
  falls below 0 (the spring reaches the cap, stretched by the slip or by a cap that
  shrinks).
* **sliding** (at the cap; the ``<plane>_compliant_sliding`` kernels): F = -mu F_n e,
  e = s/|s|, with |s| = s_cap = mu F_n / k_t and e turning with the slip velocity:
  s' = (v_t - (e . v_t) e) f + s d ln(s_cap)/dt (f = 1 above |s| = 1e-12 m, see
  contact.TURN_FLOOR), ds_cap/dt with the exact penetration acceleration (the C core
  adds its share after solving the dynamics).  Guard **restick**: the elastic law would
  stretch the spring slower than the cap grows, (e . v_t - max(rhodot, 0)/(2 rho) |s|)
  - ds_cap/dt falls below 0.

In the elastic mode a third guard, **capacity** (:func:`capacity_guard`), ends a
segment without a mode change where the viscous damping saturates the capacity the
elastic force leaves (or stops saturating it): a kink of the force that an integrator's
error estimate can step over.

A compliant contact begins where the penetration reaches the arming depth (ARM_ULPS
ulp of the plane's position, and Hertz's force ARM_FORCE; the impulse before it is left
out: with Hunt-Crossley damping below 1e-6 N for ~1e-10 s, with the viscoelastic one
4/5 c_n rho there, see :func:`starts_armed`): below it rho's rounding, and the kernels'
1e-12-N load floor, would decide the mode changes.  It starts in the mode of its self-similar
start (:func:`start`): sliding when the spring, at the cap along the slip velocity,
would outgrow it (the re-stick margin there is >= 0; for Hunt-Crossley this is kappa
|v_t| >= mu (1 + chi) rhodot^-, the ratio of the self-similar start s = 2/3 v_t t),
elastic otherwise.  At a yield (:func:`decide`) the spring is at the cap to the
integration's tolerance: it slides when the re-stick margin is >= 0, else stays
elastic (it only touched the cap) and is brought back to the cap.  At a re-stick a
spring beyond the cap is brought back to it.  Every such reset only lowers the spring
energy 1/2 k_t |s|^2, and books what it releases to the tangential dissipated work, so
the energy balance stays exact and the dissipated work never decreases (a sliding start
puts (mu F_n)^2 / (2 k_t) into the spring unbooked: below 1e-12 N^2 / (2 k_t), ~1e-15 J).  The sliding
law keeps |s| / s_cap (its radial rate is relative), so the approximate penetration
acceleration in ds_cap/dt (-F_n/m* + g n_z; an observer makes it inexact) errs by a
factor on |s|, never driving s through 0 before s_cap.

With ``friction_regularization`` "max" or "smooth" the law runs without modes, capped
by its smooth yield alone (contact.YIELD_EXPONENT).  This module holds the decisions at
the mode boundaries; the driver (simulate.py) holds the segment loop.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, layout, stickslip

PLANES = ("floor", "ceiling")
MODES = ("elastic", "sliding")
#: The guards' event kinds: the arming's (a contact starting shallower than the arming
#: depth), the elastic mode's (and its capacity kink's), the sliding mode's.
GUARDS = ("arm", "yield", "capacity", "restick")
_DEFLECTION = layout.DEFLECTION
_DISSIPATED_TANGENTIAL = layout.INDEX["dissipated_tangential"]
_TANGENTIAL_DAMPING = _core.PARAMETER_NAMES.index("tangential_damping_ratio")

#: The guards are armed once the penetration reaches ARM_ULPS units in the last place of
#: the plane's position (rho = r - z is resolved to one of them): before, rho's rounding
#: alone moves the margins by more than 1e-6 of themselves (at the contact start, by
#: 10 %), and mode changes would follow rounding.  Up to there the contact is in its
#: self-similar start, whose mode does not change; the elastic kernels' smooth yield
#: caps it meanwhile.  (4e-13 m for a 2.5-mm ball, 4e-12 m for the seed's: 1e-7 of
#: their peak penetrations.)
ARM_ULPS = 2.0 ** 20
#: ... and once Hertz's force k0 rho^(3/2) reaches ARM_FORCE (N): the kernels treat a
#: normal force below 1e-12 N as a fraction of a load (F_n / max(F_n, 1e-12 N), which
#: keeps their derivatives finite), so the law is exact only well above it (1e-6 N:
#: 1e-8 m for the seed's rubber ball).
ARM_FORCE = 1e-6

#: A sliding start with s_cap = 0 takes this |s| (m) along the slip, so that its
#: direction s/|s| is defined (the kernels take s/|s| as 0 below |s| = 1e-140 m).
START_DEFLECTION = 1e-100


def uses_modes(scene) -> bool:
    """Whether ``scene``'s contacts run the compliant law as exact elastic/sliding modes
    (not with mu = 0: no tangential force, the spring stays relaxed)."""
    return (scene.tangential_model == "compliant" and scene.friction_regularization == "exact"
            and scene.friction_coefficient > 0)


def starts_armed(scene) -> bool:
    """Whether ``scene``'s compliant contacts begin at the arming depth
    (:func:`arm_penetration`) instead of at rho = 0: with the modes (their guards), and
    with the viscoelastic damping.  Its force c_n rhodot, c_n = 2 gamma sqrt(m* k_n) ~
    rho^(1/4), rises from rho = 0 with an infinite slope and no scale: an implicit
    step from rho = 0 sees no force at its start, nor a slope that linearises it, at
    any step size, so radau5's Newton iteration never converged there (a steel ball
    dropped with mu = 0 failed at its first contact, issue 28).  From the arming depth
    a step of ~rho / rhodot resolves it and the steps grow from there.  What it leaves
    out is the impulse of the approach to that depth, the integral of c_n rhodot dt =
    c_n drho: 4/5 c_n rho at the arming depth, whatever the impact speed (6e-8 N s for
    a 1-kg steel ball of 1 m, 7e-9 of its momentum at 8.9 m/s: docs/limits.md)."""
    return uses_modes(scene) or (scene.tangential_model == "compliant"
                                 and scene.normal_damping == "viscoelastic")


def mode_flags(plane: str, mode: str | None, armed: bool = True) -> int:
    """The C flag of the compliant law on ``plane`` in ``mode``: the sliding kernels;
    the elastic mode's (the spring alone) once its guards are ``armed``; else (mode
    None: no modes, or before the arming) the law with its smooth yield."""
    if mode == "sliding":
        return _core.FLAGS[f"{plane}_compliant_sliding"]
    if mode == "elastic" and armed:
        return _core.FLAGS[f"{plane}_compliant_elastic"]
    return _core.FLAGS[f"{plane}_compliant"]


def margins(y, params, latch, plane: str) -> np.ndarray:
    """(yield margin (1), re-stick margin (m/s), s_cap (m), k_t (N/m), capacity margin
    (N), its negative) at state y (_core.compliant_margins)."""
    return _core.compliant_margins(np.ascontiguousarray(y, dtype=float), params, latch,
                                   PLANES.index(plane))


_EPS = float(np.finfo(float).eps)


#: A compliant contact with modes is integrated in steps of at most its Hertz time over
#: this, for IMPACT_SPAN Hertz times from its start (see step_bound).
STEPS_PER_CONTACT = 16
IMPACT_SPAN = 4


def contact_time_base(scene) -> float:
    """3.2145 (m / k0)^(2/5) (s (m/s)^(1/5)): :func:`contact_time` at a unit rate (the C
    loop multiplies it by rate^(-1/5) in the same order)."""
    m = scene.mass + scene.observer_mass
    return 3.2145 * (m / scene.hertz_stiffness) ** 0.4


def contact_time(scene, rate: float) -> float:
    """The elastic Hertz contact time (s) at impact rate ``rate`` (m/s):
    t_c = 3.2145 (m / k0)^(2/5) v^(-1/5) (ballc.impact.hertz_contact_time)."""
    return contact_time_base(scene) * rate ** -0.2


def step_bound(scene, rate: float, t_start: float) -> tuple[float, float]:
    """(largest step (s), until when (s)) within a compliant contact that starts at
    ``t_start`` with impact rate (the latched rhodot^-, m/s) ``rate``: t_c /
    STEPS_PER_CONTACT for IMPACT_SPAN t_c (t_c: :func:`contact_time`).  The guards of
    the modes are found by their sign at the ends of steps: a phase shorter than a step
    (a re-stick and the slide after it inside one step) would be stepped over unseen --
    measured, dop853 at rtol 1e-4 on the seed's compliant throw took the ceiling contact
    in 3 steps and missed its stick phase (0.014 s of 0.062 s), final error 0.63 -- so an
    impact is resolved by at least STEPS_PER_CONTACT steps, as DEM codes take their time
    step a fraction of t_c.  A contact that outlasts IMPACT_SPAN t_c (a ball coming to
    rest, rolling) goes on with the tolerance's steps: bounded for ever, a steel ball's
    resting contact took 2e7 calls by 3.3 s."""
    t_c = contact_time(scene, rate)
    return t_c / STEPS_PER_CONTACT, t_start + IMPACT_SPAN * t_c


def plane_position(scene, plane: str) -> float:
    """The centre's height z (m) at which the ball touches ``plane`` (rho = 0)."""
    return scene.radius if plane == "floor" else scene.ceiling_height - scene.radius


def arm_force_depth(scene) -> float:
    """(ARM_FORCE / k0)^(2/3) (m): the penetration at which Hertz's force is ARM_FORCE,
    arm_penetration's floor (the C loop takes the ulps of each plane's position
    itself)."""
    return (ARM_FORCE / scene.hertz_stiffness) ** (2.0 / 3.0)


def arm_penetration(scene, plane: str) -> float:
    """The penetration (m) at which the guards of a contact with ``plane`` are armed:
    ARM_ULPS ulp of the plane's position, and Hertz's force ARM_FORCE."""
    return max(ARM_ULPS * math.ulp(plane_position(scene, plane)),
               (ARM_FORCE / scene.hertz_stiffness) ** (2.0 / 3.0))


def _rounding(scene, plane, rho0):
    """The relative rounding of margins computed from rho >= rho0: a few ulp of the
    plane's position over rho0, and never below 64 eps."""
    return max(64 * _EPS, 8 * math.ulp(plane_position(scene, plane)) / max(rho0, 1e-300))


def guard(scene, mode: str, armed: bool, y0, params, latch, plane: str, rho0: float):
    """(event kind, offset) of the guard of ``mode`` on ``plane`` for a segment starting
    at y0 with penetration rho0: the guard g + offset falls through 0 ("arm", before
    the guards are ``armed``: the penetration rises through arm_penetration), the
    offset a margin past g's zero (its rounding) so that a segment starting on it (a
    mode just entered there) does not fire at once and rounding does not fire it."""
    if not armed:
        return "arm", -arm_penetration(scene, plane)
    rounding = _rounding(scene, plane, rho0)
    if mode == "elastic":
        return "yield", rounding
    ratio = scene.friction_coefficient / max(scene.tangential_stiffness_ratio, 1e-300)
    return "restick", rounding * stickslip.speed_scale(scene, y0) * max(1.0, ratio)


#: The capacity guard's rows of :func:`margins`: the capacity margin, and its negative.
CAPACITY_ROWS = (4, 5)


def capacity_guard(scene, y0, params, latch, plane: str, rho0: float, row=None):
    """(row of :func:`margins`, offset) of the elastic mode's capacity guard on ``plane``
    for a segment starting at y0, or None without viscous damping: the capacity margin
    (mu F_n - |F_el|) - |V| crosses 0 where the viscous force saturates the capacity the
    elastic force leaves, or stops saturating it -- a kink of the tangential force and of
    the dissipation rate that an integrator's error estimate can step over (radau5 did,
    at rtol 1e-9: 1.5e-6 J of tangential work, 1e-6 m/s off by t = 5 s).  The segment
    ends there, in the same mode.  The row (the margin or its negative, falling through
    0): ``row`` after a capacity event (the other one than the event's: the state there,
    a step's end point, can sit on the near side of the kink its dense output located,
    and the margin's sign would fire the same crossing again), else the margin's sign
    at y0; the offset is its rounding times mu F_n."""
    if not params[_TANGENTIAL_DAMPING] > 0:
        return None
    values = margins(y0, params, latch, plane)
    if row is None:
        row = CAPACITY_ROWS[0] if values[CAPACITY_ROWS[0]] >= 0 else CAPACITY_ROWS[1]
    cap = float(values[2] * values[3])
    return row, _rounding(scene, plane, rho0) * max(cap, 1e-12)


def start(y, params, latch, plane: str):
    """(mode, state) at a contact start (s = 0): the self-similar start s = 2/3 v_t t
    (elastic; for Hunt-Crossley k_t |s| / (mu F_n) = kappa |v_t| / (mu (1 + chi)
    rhodot^-) at all t) or at the cap (sliding): :func:`decide` with the spring put at
    the cap along the slip velocity.  The margins' ratios do not depend on the rounding
    of rho (s_cap and the rates are proportional to it), so the decision is sound where
    rho itself is not resolved."""
    return decide(y, params, latch, plane, arming=True)


def _along_slip(y, params, latch, plane: str):
    """The deflection at the cap along the slip velocity (2, m), START_DEFLECTION long
    where s_cap is 0; None without slip."""
    values = y.tolist() if isinstance(y, np.ndarray) else list(y)
    ux, uy = stickslip.slip_velocity_of(stickslip.slip_terms(params, plane), values)
    speed = math.hypot(ux, uy)
    if not speed > 0:
        return None
    s_cap = float(margins(y, params, latch, plane)[2])
    length = s_cap if s_cap > 0 else START_DEFLECTION
    return [length * ux / speed, length * uy / speed]


def load_vanished(y, params, latch, plane: str) -> bool:
    """Whether a yield fired where the load vanished with the spring far below the cap
    (k_t |s| < mu F_n / 2, or no load at all): the yield margin reads -1 without load,
    so a contact whose spring is (nearly) relaxed "yields" at its last instant.  There
    the guards are disarmed (the smooth-yield kernels take the contact to its end, the
    load ~0), instead of sliding on a spring of rounding-level |s|."""
    margin, _, s_cap = margins(y, params, latch, plane).tolist()[:3]
    return not s_cap > 0 or margin > 0.5


def decide(y, params, latch, plane: str, arming=False):
    """(mode, state) where the elastic spring meets the cap (a yield, or the arming of a
    contact's guards): "sliding" when the re-stick margin with the spring at the cap
    (along the slip velocity when it is still relaxed) is >= 0 -- the elastic law would
    stretch it past the cap.  Then a relaxed spring, or one at the arming (the
    self-similar start, whose s the integration set with errors larger than s), is
    put at the cap along the slip velocity; a spring at a
    yield keeps its |s| (s_cap to the integration's tolerance; the sliding law keeps
    |s| / s_cap, and booking the tolerance-sized difference could show as negative
    dissipation).  Else "elastic", with a spring beyond the cap brought back to it."""
    s = np.asarray(y)[_DEFLECTION[plane]]
    trial = at_cap(y, params, latch, plane, only_down=False)
    # at the arming the contact is still in its self-similar start, s along v_t: the
    # slip velocity gives that direction without the integration's error in s (larger
    # than s itself there)
    relaxed = arming or not math.hypot(*s.tolist()) > 0
    if relaxed:
        along = _along_slip(y, params, latch, plane)
        if along is None:
            return "elastic", y
        trial[_DEFLECTION[plane]] = along
    if margins(trial, params, latch, plane)[1] >= 0:
        return "sliding", (trial if relaxed else y)
    return "elastic", at_cap(y, params, latch, plane)


def at_cap(y, params, latch, plane: str, only_down=True) -> np.ndarray:
    """The state with |s| = s_cap (its direction kept), the spring energy 1/2 k_t |s|^2
    it releases booked as tangential dissipated work (the balance stays exact);
    ``only_down``: a spring below the cap is left as it is (no booking of negative
    dissipation: only a trial state may be put up to the cap)."""
    y = np.array(y, dtype=float)
    s = y[_DEFLECTION[plane]]
    size = math.hypot(*s.tolist())
    if not size > 0:
        return y
    s_cap, k_t = margins(y, params, latch, plane).tolist()[2:4]
    if only_down and size <= s_cap:
        return y
    y[_DEFLECTION[plane]] = s * (s_cap / size)
    y[_DISSIPATED_TANGENTIAL] += 0.5 * k_t * (size * size - s_cap * s_cap)
    return y


def restick(y, params, latch, plane: str) -> np.ndarray:
    """The state at a re-stick (the elastic mode follows): a spring beyond the cap (by
    the integration's tolerance) brought back to it."""
    return at_cap(y, params, latch, plane)
