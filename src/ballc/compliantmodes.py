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

In the elastic mode a third guard, **capacity** (the C loop's capacity guard), ends a
segment without a mode change where the viscous damping saturates the capacity the
elastic force leaves (or stops saturating it): a kink of the force that an integrator's
error estimate can step over.

A compliant contact begins where the penetration reaches the arming depth (ARM_ULPS
ulp of the plane's position, and Hertz's force ARM_FORCE; the impulse before it, below
1e-6 N for ~1e-10 s, is left out): below it rho's rounding, and the kernels' 1e-12-N
load floor, would decide the mode changes.  It starts in the mode of its self-similar
start: sliding when the spring, at the cap along the slip velocity,
would outgrow it (the re-stick margin there is >= 0; for Hunt-Crossley this is kappa
|v_t| >= mu (1 + chi) rhodot^-, the ratio of the self-similar start s = 2/3 v_t t),
elastic otherwise.  At a yield the spring is at the cap to the
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
by its smooth yield alone (contact.YIELD_EXPONENT).  The C loop (``_driver.c``:
start_compliant, decide, at_cap, compliant_event and the guards of segment_events)
makes these decisions; this module names the constants and gives the C loop the
per-scene ones (the arming depth, Hertz's contact time).
"""
from __future__ import annotations

import math

import numpy as np

from . import _core

PLANES = ("floor", "ceiling")
MODES = ("elastic", "sliding")
#: The guards' event kinds: the arming's (a contact starting shallower than the arming
#: depth), the elastic mode's (and its capacity kink's), the sliding mode's.
GUARDS = ("arm", "yield", "capacity", "restick")
_TANGENTIAL_DAMPING = _core.PARAMETER_NAMES.index("tangential_damping_ratio")

#: The guards are armed once the penetration reaches ARM_ULPS units in the last place of
#: the plane's position (rho = r - z is resolved to one of them): before, rho's rounding
#: alone moves the margins by more than 1e-6 of themselves (at the contact start, by
#: 10 %), and mode changes would follow rounding.  Up to there the contact is in its
#: self-similar start, whose mode does not change; the elastic kernels' smooth yield
#: caps it meanwhile.  (4e-13 m for a 2.5-mm ball, 4e-12 m for the seed's: 1e-7 of
#: their peak penetrations.)
ARM_ULPS = _core.ARM_ULPS   # 2^20, _driver.h's
#: ... and once Hertz's force k0 rho^(3/2) reaches ARM_FORCE (N): the kernels treat a
#: normal force below 1e-12 N as a fraction of a load (F_n / max(F_n, 1e-12 N), which
#: keeps their derivatives finite), so the law is exact only well above it (1e-6 N:
#: 1e-8 m for the seed's rubber ball).
ARM_FORCE = 1e-6

#: A compliant contact with modes is integrated in steps of at most its Hertz time t_c
#: over STEPS_PER_CONTACT, for IMPACT_SPAN t_c from its start.  The guards of the modes
#: are found by their sign at the ends of steps: a phase shorter than a step (a re-stick
#: and the slide after it inside one step) would be stepped over unseen -- measured,
#: dop853 at rtol 1e-4 on the seed's compliant throw took the ceiling contact in 3 steps
#: and missed its stick phase (0.014 s of 0.062 s), final error 0.63 -- so an impact is
#: resolved by at least STEPS_PER_CONTACT steps, as DEM codes take their time step a
#: fraction of t_c.  A contact that outlasts IMPACT_SPAN t_c (a ball coming to rest,
#: rolling) goes on with the tolerance's steps: bounded for ever, a steel ball's resting
#: contact took 2e7 calls by 3.3 s.  The segment that reaches the bound's end ends
#: there (the automaton's "step bound", no mode change).
STEPS_PER_CONTACT = _core.STEPS_PER_CONTACT
IMPACT_SPAN = _core.IMPACT_SPAN


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


def margins(y, params, latch, plane: str) -> np.ndarray:
    """(yield margin (1), re-stick margin (m/s), s_cap (m), k_t (N/m), capacity margin
    (N), its negative) at state y (_core.compliant_margins)."""
    return _core.compliant_margins(np.ascontiguousarray(y, dtype=float),
                                   np.ascontiguousarray(params, dtype=float),
                                   np.ascontiguousarray(latch, dtype=float),
                                   PLANES.index(plane))


def contact_time_base(scene) -> float:
    """3.2145 (m / k0)^(2/5) (s (m/s)^(1/5)): :func:`contact_time` at a unit rate (the C
    loop multiplies it by rate^(-1/5))."""
    m = scene.mass + scene.observer_mass
    return 3.2145 * (m / scene.hertz_stiffness) ** 0.4


def contact_time(scene, rate: float) -> float:
    """The elastic Hertz contact time (s) at impact rate ``rate`` (m/s):
    t_c = 3.2145 (m / k0)^(2/5) v^(-1/5) (ballc.impact.hertz_contact_time)."""
    return contact_time_base(scene) * rate ** -0.2


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
