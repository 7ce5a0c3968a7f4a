"""Contact laws, as sympy expressions of the contact-point kinematics, composed of parts.

Every law is derived once, in a plane's own frame (model.FRAME_PLANE: the plane z = 0
with its unit normal ``n`` = +z towards the ball, the floor's case); the C core applies it
to every plane, turning the contact into that frame and the forces back
(src/ballc/_plane.c).  In that frame:

* penetration ``rho = r - distance(centre, plane)`` (positive in contact),
* penetration rate ``rhodot = -v_cp . n`` (positive while moving into the plane),
* ``rhodot^-`` the penetration rate latched at the start of the contact,
* Hertz stiffness ``k0 = 4 / (3 (sigma_b + sigma_p)) sqrt(r)``, ``sigma = (1 - nu^2) / E``.

A law is normal x damping x tangential, as LAMMPS GRANULAR's sub-models (docs/contact_laws.md):

* normal: ``hertz_normal``, F_H = k0 rho^(3/2) and k_n = 3/2 k0 rho^(1/2);
* damping: ``hunt_crossley``, the seed's bracket F_H [1 + chi rate / |rhodot^-|] with
  chi = 3/2 (1 - c_tau); ``hunt_crossley_damping`` (F_H chi rhodot / |rhodot^-|) and
  ``viscoelastic_damping`` (2 gamma sqrt(m* k_n) rhodot), the terms the compliant law
  adds to F_H (``damped_normal``; the sum rounds differently from the bracket).  The
  damped force is clamped at 0 (no adhesion: ballc's addition; the seed's formula
  turns attractive when the ball leaves faster than ``|rhodot^-| / chi``);
* tangential: ``coulomb_friction`` (F_n n - mu F_n v_t / max(|v_t|, eps), v_t the slip
  velocity in the plane, eps the seed's 1e-10 m/s; or / sqrt(|v_t|^2 + eps^2) with
  ``smooth_friction``), ``dig_in`` (-F_d d along the unit
  contact-point velocity d latched at impact start, F_d the damped normal force on the
  rate v_cp . d), ``no_friction`` (F_n n); the compliant law's ``incremental_mindlin``
  (a deflection state per plane) + ``capacity_damping``.

Compositions (``COMPOSITIONS``, assembled by ``compose``; weights as the seed's mixture):

* friction = hertz_normal x hunt_crossley x coulomb_friction, weight 1 - mixture;
* dig-in = hertz_normal x hunt_crossley x dig_in, weight mixture;
* mixture = friction + dig-in (the C core adds the two kernels);
* friction_normal = hertz_normal x hunt_crossley x no_friction, weight 1 - mixture
  (the friction law's normal share, for exact Coulomb friction);
* compliant (ballc's own, not in the seed; ``compliant_model_force``) = hertz_normal x
  (hunt_crossley_damping | viscoelastic_damping) x (incremental_mindlin + capacity_damping).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sm
import sympy.physics.mechanics as me

from .model import (LATCH_FIELDS, ROLLING_SPRING_FIELDS, Model, contact_point,
                    require_frame_plane)


def plane_geometry(model: Model, plane: str):
    """(normal towards the ball, penetration rho) of ``plane``, in its own frame: N.z
    and r - z (model.FRAME_PLANE only)."""
    require_frame_plane(plane)
    return model.frame.z, model.p["radius"] - model.state("z")


def hertz_stiffness(model: Model):
    """k0 of a sphere of radius r on a half-space (N / m^(3/2))."""
    p = model.p
    sigma_ball = (1 - p["ball_poisson_ratio"]**2) / p["ball_youngs_modulus"]
    sigma_plane = (1 - p["plane_poisson_ratio"]**2) / p["plane_youngs_modulus"]
    return sm.Rational(4, 3) / (sigma_ball + sigma_plane) * sm.sqrt(p["radius"])


def latch_symbols(model: Model, plane: str):
    """The latched symbols (LATCH_FIELDS: rhodot^-, d_x, d_y, d_z, ...) of ``plane``
    (model.FRAME_PLANE only: every plane's latch is turned into its frame at run time)."""
    require_frame_plane(plane)
    return model.latches[:len(LATCH_FIELDS)]


def contact_kinematics(model: Model, plane: str):
    """(point, velocity vector, rho, rhodot) of the contact point on ``plane``."""
    point = contact_point(model, plane)
    normal, rho = plane_geometry(model, plane)
    velocity = point.vel(model.frame)
    rhodot = -me.dot(velocity, normal)
    return point, velocity, rho, rhodot


def _positive(expr):
    return sm.Max(expr, 0)


def slip_kinematics(model: Model, plane: str):
    """(point, contact-point velocity, normal, in-plane slip components (sx, sy))."""
    N = model.frame
    point, velocity, _, _ = contact_kinematics(model, plane)
    normal, _ = plane_geometry(model, plane)
    slip = velocity - me.dot(velocity, normal)*normal
    return point, velocity, normal, (me.dot(slip, N.x), me.dot(slip, N.y))


# --- the seed's parts (normal: hertz_normal, below); composed by compose (COMPOSITIONS) --


def hunt_crossley(model: Model, elastic, stiffness, rate, rate_at_impact):
    """The seed's Hunt-Crossley damping, as the bracket: F_H [1 + chi rate / |rhodot^-|]
    (N, before the no-adhesion clamp), chi = 3/2 (1 - c_tau).

    The seed multiplies F_H by the bracket; F_H + hunt_crossley_damping (the compliant
    law's sum) is the same force but rounds differently, so each law keeps its form.
    """
    return elastic * (1 + _hunt_crossley_chi(model) * rate / sm.Abs(rate_at_impact))


def coulomb_friction(model: Model, plane: str, normal_force):
    """The seed's friction: F_n n + F_t with F_n = normal_force(rhodot) and regularised
    Coulomb friction F_t = -mu F_n v_t / max(|v_t|, v_s) (the seed's, ``smooth_friction``
    = 0) or -mu F_n v_t / sqrt(|v_t|^2 + v_s^2) (``smooth_friction`` = 1); v_t the slip
    velocity, v_s = ``friction_regularization_speed`` (the seed's 1e-10 m/s)."""
    N = model.frame
    _, _, normal, (sx, sy) = slip_kinematics(model, plane)
    _, _, _, rhodot = contact_kinematics(model, plane)
    f_n = normal_force(rhodot)
    eps = model.p["friction_regularization_speed"]
    smooth = model.p["smooth_friction"]
    # max(|v_t|, eps) written as sqrt(max(|v_t|^2, eps^2)): same value, but its
    # derivative stays finite at zero slip (no 0/0 in the Jacobian).
    seed_speed = sm.sqrt(sm.Max(sx**2 + sy**2, eps**2))
    smooth_speed = sm.sqrt(sx**2 + sy**2 + eps**2)
    slip_speed = (1 - smooth)*seed_speed + smooth*smooth_speed
    tangential = -model.p["friction_coefficient"] * f_n / slip_speed * (sx*N.x + sy*N.y)
    return f_n*normal + tangential


def no_friction(model: Model, plane: str, normal_force):
    """No tangential force: F_n n with F_n = normal_force(rhodot)."""
    normal, _ = plane_geometry(model, plane)
    _, _, _, rhodot = contact_kinematics(model, plane)
    f_n = normal_force(rhodot)
    return f_n * normal


def dig_in(model: Model, plane: str, normal_force):
    """The seed's dig-in: the whole force along -d, d the unit contact-point velocity
    latched at impact start, of size F_d = normal_force(v_cp . d) (the normal law on the
    rate along d instead of rhodot; no force along n of its own)."""
    N = model.frame
    _, velocity, _, _ = contact_kinematics(model, plane)
    _, dx, dy, dz = latch_symbols(model, plane)[:4]
    direction = dx*N.x + dy*N.y + dz*N.z
    return normal_force(me.dot(velocity, direction)) * (-direction)


def friction_model_force(model: Model, plane: str):
    """The seed's friction law (COMPOSITIONS["friction"]), weight 1 - mixture."""
    return compose(model, plane, COMPOSITIONS["friction"])


def digin_model_force(model: Model, plane: str):
    """The seed's dig-in law (COMPOSITIONS["digin"]), weight mixture."""
    return compose(model, plane, COMPOSITIONS["digin"])


def deflection_symbols(model: Model, plane: str):
    """The tangential deflection states (x, y) of ``plane`` (model.FRAME_PLANE only)."""
    require_frame_plane(plane)
    return model.state("deflection_x"), model.state("deflection_y")


#: Sharpness n of the compliant model's yield: flow ~ (|F_el| / mu F_n)^n.  Chosen by
#: measurement against the DEM codes' truncation (validation/dem_reference.py):
#: see docs/contact_laws.md.
YIELD_EXPONENT = 64
#: The yield's factor r^n is clipped at 256 (r <= 256^(1/n)): beyond it the flow only
#: needs to pull |F_el| back under the cap (the applied force is capped exactly anyway),
#: and an unbounded factor would make the end of a contact (where mu F_n -> 0 faster
#: than k_t |s|) arbitrarily stiff.
_RATIO2_CLIP = sm.Integer(2)**sm.Rational(16, YIELD_EXPONENT)

# Floors far below any physical value (1e-12 N, 1e-15 m) keep every quotient and its
# derivative finite where the contact has no load or no deflection yet.
_FORCE_FLOOR2, _LENGTH_FLOOR2 = sm.Float(1e-24), sm.Float(1e-30)
_LENGTH_FLOOR = sm.Float(1e-30)


def _rho_floor(rho):
    """The penetration as a divisor: max(rho, 0) floored at 1e-30 m."""
    return sm.Max(_positive(rho), _LENGTH_FLOOR)


def _hunt_crossley_chi(model: Model):
    """chi = 3/2 (1 - c_tau) of the Hunt-Crossley bracket 1 + chi rhodot / |rhodot^-|."""
    return sm.Rational(3, 2) * (1 - model.p["c_tau"])


def _sqrt_positive(x):
    """sqrt(x) for x >= 0 written as x / sqrt(max(x, 1e-30)): the same value, exactly 0
    at 0, and a finite derivative there (d sqrt(x)/dx is infinite at 0, which would put
    inf * 0 = NaN into the Jacobian at contact start)."""
    return x / sm.sqrt(sm.Max(x, 1e-30))


# --- the compliant law's parts (docs/contact_laws.md): normal x damping x tangential --


def hertz_normal(model: Model, rho):
    """Hertz's elastic normal force k0 rho^(3/2) and its tangent stiffness 3/2 k0 rho^(1/2)."""
    k0 = hertz_stiffness(model)
    rho_pos = _positive(rho)
    return k0 * rho_pos**sm.Rational(3, 2), sm.Rational(3, 2) * k0 * _sqrt_positive(rho_pos)


def effective_mass(model: Model):
    """m* of the ball on a wall (kg): its whole mass, observer included."""
    return model.p["mass"] + model.p["observer_mass"]


def hunt_crossley_damping(model: Model, elastic, stiffness, rhodot, rate_at_impact):
    """Hunt-Crossley damping force (N): F_H chi rhodot / |rhodot^-|, chi = 3/2 (1 - c_tau)."""
    return elastic * _hunt_crossley_chi(model) * rhodot / sm.Abs(rate_at_impact)


def viscoelastic_damping(model: Model, elastic, stiffness, rhodot, rate_at_impact):
    """The DEM codes' viscous normal damping (N): 2 gamma sqrt(m* k_n) rhodot."""
    gamma = model.p["damping_ratio"]
    return 2 * gamma * _sqrt_positive(effective_mass(model) * stiffness) * rhodot


def damped_normal(model: Model, rho, rhodot, rate_at_impact):
    """(F_n >= 0, k_n): Hertz plus the scene's normal damping (``normal_damping_model``
    0: Hunt-Crossley, 1: viscoelastic), clamped at 0 (no adhesion)."""
    elastic, stiffness = hertz_normal(model, rho)
    select = model.p["normal_damping_model"]
    damping = (1 - select) * hunt_crossley_damping(model, elastic, stiffness, rhodot,
                                                   rate_at_impact) \
        + select * viscoelastic_damping(model, elastic, stiffness, rhodot, rate_at_impact)
    return _positive(elastic + damping), stiffness


def penetration_acceleration(plane: str):
    """The symbol of rho'' on ``plane`` (m/s^2): the exact penetration acceleration,
    which the C core computes from the solved accelerations (-n . a, a the centre's)
    and supplies to the kernels whose rates are affine in it (ACCELERATION_LAWS,
    compliant_margins)."""
    return sm.Symbol(f"{plane}_rho_acceleration")


def gravity_into_plane(plane: str):
    """The symbol of gravity's component into ``plane``, -n . g (m/s^2): a plane kernel's
    input (model.PLANE_INPUT_NAMES), which the C core computes from the gravity vector
    and the plane's normal (the seed's g on the floor, -g on the ceiling)."""
    return sm.Symbol(f"{plane}_gravity_into_plane")


def normal_force_rate(model: Model, plane: str, rho, rhodot, rate_at_impact, f_n,
                      accel=None):
    """dF_n/dt (N/s) of the damped normal force ``f_n`` (damped_normal's) while it is
    positive, affine in the penetration's acceleration ``accel`` (rho'', m/s^2).
    Without it, rho'' is taken as the contact's own, -F_n/m* - n . g: exact for a ball
    in one contact without observer, and what the Jacobian forms and the regularised
    law's yield use; the sliding mode and its re-stick guard get the exact rho''
    (penetration_acceleration)."""
    elastic, stiffness = hertz_normal(model, rho)
    mass = effective_mass(model)
    if accel is None:
        accel = -f_n / mass + gravity_into_plane(plane)
    select = model.p["normal_damping_model"]
    # Hunt-Crossley: P = F_H (1 + chi rhodot / |v-|)
    chi = _hunt_crossley_chi(model) / sm.Abs(rate_at_impact)
    hc = stiffness * (1 + chi * rhodot) * rhodot + elastic * chi * accel
    # viscoelastic: P = F_H + 2 gamma sqrt(m* k_n) rhodot, dk_n/drho = k_n / (2 rho)
    c_n = 2 * model.p["damping_ratio"] * _sqrt_positive(mass * stiffness)
    ve = (stiffness + c_n * rhodot / (4 * _rho_floor(rho))) * rhodot + c_n * accel
    return (1 - select) * hc + select * ve


def tangential_stiffness(model: Model, stiffness):
    """k_t = kappa k_n (N/m): the tangential spring's stiffness from the normal one."""
    return model.p["tangential_stiffness_ratio"] * stiffness


@dataclass
class CompliantContact:
    """What every part of the compliant law on one plane reads: the contact point, the
    plane's normal, the slip velocity (2), rho, rhodot, the damped normal force F_n,
    the normal stiffness k_n, the cap mu F_n and dF_n/dt."""

    point: me.Point
    normal: me.Vector
    slip: tuple
    rho: sm.Expr
    rhodot: sm.Expr
    normal_force: sm.Expr
    stiffness: sm.Expr
    cap: sm.Expr
    normal_force_rate: sm.Expr


def compliant_contact(model: Model, plane: str, accel=None) -> CompliantContact:
    """The compliant law's shared quantities on ``plane`` (CompliantContact); dF_n/dt
    with the penetration acceleration ``accel`` (normal_force_rate)."""
    point, _, normal, slip = slip_kinematics(model, plane)
    _, _, rho, rhodot = contact_kinematics(model, plane)
    rate_at_impact = latch_symbols(model, plane)[0]
    f_n, stiffness = damped_normal(model, rho, rhodot, rate_at_impact)
    cap = model.p["friction_coefficient"] * f_n
    f_rate = normal_force_rate(model, plane, rho, rhodot, rate_at_impact, f_n, accel)
    return CompliantContact(point, normal, slip, rho, rhodot, f_n, stiffness, cap, f_rate)


def loaded(model: Model, normal_force):
    """1 while the tangential spring can carry a force, 0 when it cannot, as a factor of
    its deflection rate: F_n / max(F_n, 1e-12 N) (below the force floor a fraction, which
    keeps the derivatives finite), and 0 when mu = 0 (a cap of 0: the DEM codes'
    truncation holds the stored force at 0, and the spring stays relaxed)."""
    return (normal_force / sm.Max(normal_force, sm.sqrt(_FORCE_FLOOR2))
            * sm.Heaviside(model.p["friction_coefficient"], 0))


def incremental_mindlin(model: Model, plane: str, stiffness, rho, rhodot, normal_force, cap,
                        slip, normal_force_rate, dilute=True, smooth_yield=True):
    """The incremental (passive) Mindlin tangential spring with a Coulomb cap.

    Returns (capped elastic force F_e (2), deflection rate s' (2), the rate of the
    spring's stored energy 1/2 k_t |s|^2 (W), k_t).
    k_t = kappa k_n; F_el = -k_t s; s' = v_t - max(rhodot, 0)/(2 rho) s - phi s with the
    smooth yield phi = x max(s.v_t, 0)/|s|^2 + min(x, 1) max(-d ln(cap/k_t)/dt, 0) with
    x = max(r^n - 1, 0), r = k_t |s| / cap (r^n <= 256): nothing below the cap (the
    elastic law exact there), a flow growing from the cap up; the second term follows
    a cap that shrinks as rho does; the
    applied force F_e = F_el min(1, cap/|F_el|).  ``dilute=False`` leaves the middle
    term out (the Jacobian's form: see JACOBIAN_FORMS).  ``smooth_yield=False``: the
    spring alone, phi = 0 and F_e = F_el (the elastic mode of the exact modes, whose
    guard keeps it below the cap).
    """
    sx, sy = deflection_symbols(model, plane)
    vx, vy = slip
    k_t = tangential_stiffness(model, stiffness)
    size2 = sx**2 + sy**2
    ratio2 = sm.Min(k_t**2 * size2 / sm.Max(cap**2, _FORCE_FLOOR2), _RATIO2_CLIP)
    loading = sm.Max(sx*vx + sy*vy, 0) / sm.Max(size2, _LENGTH_FLOOR2)
    # dk_t/dt / k_t = rhodot / (2 rho)
    stiffening = rhodot / (2 * _rho_floor(rho))
    # the DEM codes truncate the stored force to the cap also when the cap shrinks faster
    # than k_t: the second term, with the relative rate of cap / k_t,
    # dF_n/dt / F_n - rhodot / (2 rho) (Hertz undamped: rhodot / rho)
    relative = normal_force_rate / sm.Max(normal_force, sm.sqrt(_FORCE_FLOOR2)) - stiffening
    shrinking = _positive(-relative)
    excess = _positive(ratio2**(YIELD_EXPONENT // 2) - 1)     # 0 below the cap
    flow = excess * loading + sm.Min(excess, 1) * shrinking if smooth_yield else sm.S.Zero
    dilution = _positive(rhodot) / (2 * _rho_floor(rho)) if dilute else sm.S.Zero
    # the deflection only moves while the contact carries a load (F_n > 0): a contact
    # segment starts where its event located rho = 0, possibly a rounding below it, and
    # a damped normal force may reach 0 (its clamp) before rho does; the DEM codes'
    # truncation then holds the stored force at 0, and ballc stops the deflection: the
    # spring's energy 1/2 k_t |s|^2 goes to 0 with k_t by the contact's end and is
    # counted as dissipated (no energy is created either way)
    in_contact = loaded(model, normal_force)
    rate = [in_contact * (v - (dilution + flow) * s) for v, s in zip((vx, vy), (sx, sy))]
    elastic = [-k_t * sx, -k_t * sy]
    size = sm.sqrt(sm.Max(k_t**2 * size2, cap**2, _FORCE_FLOOR2))
    capped = [f * cap / size for f in elastic] if smooth_yield else elastic
    # d/dt (1/2 k_t |s|^2) = k_t s.s' + 1/2 |s|^2 dk_t/dt
    storage = k_t * (sx*rate[0] + sy*rate[1]) + k_t * size2 / 2 * stiffening
    return capped, rate, storage, k_t


#: |s|^2 below which the sliding mode's direction s/|s| is taken as 0 (m^2): far below
#: any deflection the mode sees (a sliding contact starts at |s| = mu F_n / k_t of a
#: penetration of ~1e-17 m, ~1e-18 m), and its square root (1e-140 m) is not subnormal.
_DIRECTION_FLOOR2 = sm.Float(1e-280)
#: k_t as a divisor (N/m): k_t is 0 only where F_n is 0 too (no penetration); far below
#: any k_t in contact (~1 N/m at rho ~ 1e-17 m for the hardest materials, 1e-4 for a
#: soft one), and large enough that the Jacobian's d(1/k_t) stays finite (its terms are
#: multiplied by F_n = 0 there: a NaN otherwise).
_STIFFNESS_FLOOR = sm.Float(1e-100)


def capped_deflection(model: Model, k_t, stiffening, normal_force, normal_force_rate):
    """The deflection at the Coulomb cap, s_cap = mu F_n / k_t (m), and its rate (m/s):
    d/dt (mu F_n / k_t) = mu dF_n/dt / k_t - s_cap dk_t/dt / k_t, dk_t/dt / k_t =
    ``stiffening`` = rhodot / (2 rho)."""
    mu = model.p["friction_coefficient"]
    stiffness = sm.Max(k_t, _STIFFNESS_FLOOR)
    s_cap = mu * normal_force / stiffness
    return s_cap, mu * normal_force_rate / stiffness - s_cap * stiffening


#: Below |s| = TURN_FLOOR (m) the sliding spring's direction turns with the slip at
#: most at |v_t| / TURN_FLOOR: de/dt = (v_t - (e . v_t) e) / max(|s|, TURN_FLOOR).  The
#: exact rate, |v_t| / |s|, grows without bound as a sliding contact unloads (s_cap ->
#: 0), which stalls any integrator there (steps ~ |s| / |v_t|, shrinking with |s|);
#: the force it turns is mu F_n <= k_t TURN_FLOOR then (1e-12 m: 1e-6 of the
#: deflections of a 2.5-mm alumina impact at 3.9 m/s, 1e-8 of the seed's).
TURN_FLOOR = sm.Float(1e-12)


def turn_reach(model: Model, plane: str):
    """max(|s|, TURN_FLOOR) (m): the length the direction's turn rate is divided by."""
    sx, sy = deflection_symbols(model, plane)
    return sm.Max(sm.sqrt(sm.Max(sx**2 + sy**2, _DIRECTION_FLOOR2)), TURN_FLOOR)


def turn_factor(model: Model, plane: str):
    """|s| / max(|s|, TURN_FLOOR): 1 above the floor (see TURN_FLOOR)."""
    sx, sy = deflection_symbols(model, plane)
    size = sm.sqrt(sm.Max(sx**2 + sy**2, _DIRECTION_FLOOR2))
    return size / sm.Max(size, TURN_FLOOR)


def sliding_direction(model: Model, plane: str):
    """The unit deflection e = s/|s| (2), 0 where |s|^2 < 1e-280 m^2."""
    sx, sy = deflection_symbols(model, plane)
    size = sm.sqrt(sm.Max(sx**2 + sy**2, _DIRECTION_FLOOR2))
    return [sx / size, sy / size]


def sliding_mindlin(model: Model, plane: str, stiffness, rho, rhodot, normal_force, cap, slip,
                    normal_force_rate, direction, turn, jacobian_form=False, reach=None):
    """The incremental Mindlin spring in its sliding mode: the DEM codes' truncation in
    the limit dt -> 0 (docs/contact_laws.md, "Exact elastic and sliding modes").

    The stored force sits at the cap, F_el = -mu F_n e with e = s/|s| (``direction``);
    |s| follows s_cap = mu F_n / k_t and e turns with the slip velocity's part across
    it: s' = (v_t - (e . v_t) e) f + s d ln(s_cap)/dt, which keeps |s| / s_cap constant
    (1: a mode change puts the spring at the cap) and gives de/dt = (v_t - (e . v_t) e)
    / |s|, the truncated increment's direction (``turn`` f = 1, or less below
    TURN_FLOOR).  The radial part is relative, so that s never passes through 0 before
    s_cap does (with the open-loop e ds_cap/dt, the seed's throw with its observer drove
    s through 0 at a contact's end, and radau5 stalled there).  ds_cap/dt holds the
    exact penetration acceleration (compliant_sliding_force): with the contact's own
    (-F_n/m* + g n_z), a massive observer made |s| drift off s_cap -- 3x above it, with
    the dissipated work falling, for an observer as heavy as the ball (issue 20's
    property test, found in stop 22).
    It is stiff as F_n -> 0 at the end (d ln(s_cap)/dt -> -inf): ``jacobian_form`` keeps
    that decay in d/ds and leaves out the growth while the cap rises (~ +1/t at a start:
    the dilution's trap, see JACOBIAN_FORMS).  ``reach`` (the Jacobian form, with e and
    the turn held): max(|s|, TURN_FLOOR), held too, and the turn is written to first
    order in the part of s across the held e, s_perp = s - (e . s) e: (v_t - (e . v_t)
    e) f - ((e . v_t) s_perp + e (v_t . s_perp)) / reach.  At the state s_perp = 0 (the
    same value), and its d/ds is the exact turn's, the mode's stiffness (e . v_t) / |s|
    across e (/ TURN_FLOOR below it), computed without 1/|s| (|s| ~ mu: 1e-127 m for a
    hypothesis-drawn mu of 1e-126 overflowed the exact form's d(s/|s|)/ds).
    Returns
    (applied force (2), deflection rate (2), rate of the stored energy 1/2 k_t |s|^2
    (W), k_t).  No viscous damping: it is dropped while sliding (capacity 0).
    """
    sx, sy = deflection_symbols(model, plane)
    vx, vy = slip
    ex, ey = direction
    k_t = tangential_stiffness(model, stiffness)
    stiffening = rhodot / (2 * _rho_floor(rho))
    s_cap, s_cap_rate = capped_deflection(model, k_t, stiffening, normal_force,
                                          normal_force_rate)
    in_contact = loaded(model, normal_force)
    # d ln(s_cap)/dt = dF_n/dt / F_n - rhodot / (2 rho); below the force floor (F_n <
    # 1e-12 N, a contact's last instants) both terms are scaled by F_n / 1e-12 N alike
    # (in_contact), which keeps the sign of d(F_n / k_t)/dt and stays bounded -- with the
    # floor on the first term only, a leaving contact's -rhodot/(2 rho) made |s| grow
    # at ~1e12 /s there and stalled the integrator (a steel ball's small bounces)
    relative = (normal_force_rate / sm.Max(normal_force, sm.sqrt(_FORCE_FLOOR2))
                - in_contact * stiffening)
    if jacobian_form:
        # the same value where |s| = s_cap; its d/ds keeps the decay while the cap
        # shrinks (min(relative, 0): stiff as F_n -> 0 at the contact's end, which Newton
        # needs) and leaves out the growth while it rises (~ +1/t from the start)
        shrinking = sm.Min(relative, 0)
        radial = [ex * s_cap_rate + (sx - s_cap * ex) * shrinking,
                  ey * s_cap_rate + (sy - s_cap * ey) * shrinking]
    else:
        radial = [sx * relative, sy * relative]
    along = ex * vx + ey * vy
    across = [(v - along * e) * turn for v, e in zip((vx, vy), (ex, ey))]
    if reach is not None:
        perp = [sx - (ex * sx + ey * sy) * ex, sy - (ex * sx + ey * sy) * ey]
        slip_perp = vx * perp[0] + vy * perp[1]
        across = [a - (along * p + e * slip_perp) / reach
                  for a, p, e in zip(across, perp, (ex, ey))]
    rate = [in_contact * (a + w) for a, w in zip(across, radial)]
    force = [-cap * ex, -cap * ey]
    storage = k_t * (sx*rate[0] + sy*rate[1]) + k_t * (sx**2 + sy**2) / 2 * stiffening
    return force, rate, storage, k_t


def compliant_sliding_force(model: Model, plane: str, jacobian_form=False):
    """The compliant law's sliding mode (``<plane>_compliant_sliding``): the same normal
    force, the tangential force -mu F_n e at the cap (sliding_mindlin).
    ``jacobian_form``: the direction e, the turn factor and max(|s|, TURN_FLOOR) enter
    as symbols defined before the kernel's code (``ContactLaw.frozen``), and the turn of
    e towards v_t is written to first order across e (sliding_mindlin's ``reach``): its
    d/ds is the exact one, the mode's stiffness (e . v_t) / |s| (see JACOBIAN_FORMS)."""
    N = model.frame
    # the value's rates take the exact rho'' (affine in it: the C core adds its share,
    # ACCELERATION_LAWS); the Jacobian form keeps the contact's own
    c = compliant_contact(model, plane,
                          None if jacobian_form else penetration_acceleration(plane))
    exact = sliding_direction(model, plane) + [turn_factor(model, plane)]
    frozen = None
    held = exact + [None]
    if jacobian_form:
        exact.append(turn_reach(model, plane))
        held = list(sm.symbols(f"{plane}_sliding_direction_x {plane}_sliding_direction_y "
                               f"{plane}_sliding_turn {plane}_sliding_reach"))
        frozen = list(zip(held, exact))
    tangential, rate, storage, _ = sliding_mindlin(model, plane, c.stiffness, c.rho, c.rhodot,
                                                   c.normal_force, c.cap, c.slip,
                                                   c.normal_force_rate, held[:2], held[2],
                                                   jacobian_form, held[3])
    force = c.normal_force*c.normal + tangential[0]*N.x + tangential[1]*N.y
    return ContactLaw(c.point, force, sm.S.One, deflection_rate=rate,
                      tangential_storage=storage, frozen=frozen)


def compliant_margins(model: Model, plane: str):
    """The guards of the compliant law's modes on ``plane`` (``<plane>_compliant_margins``):

    * yield margin 1 - k_t |s| / (mu F_n) (1): the elastic mode ends where it falls
      below 0;
    * re-stick margin (m/s): (e . v_t - max(rhodot, 0)/(2 rho) |s|) - ds_cap/dt, how much
      faster the elastic law would stretch the spring than the cap grows; the sliding
      mode ends where it falls below 0;
    * s_cap = mu F_n / k_t (m) and k_t (N/m): what a mode change resets to;
    * capacity margin (N): (mu F_n - |F_el|) - |V| of the elastic mode's viscous
      damping (capacity_margin), whose zero is a kink the exact modes end a segment at.

    The re-stick margin is affine in the exact penetration acceleration rho''
    (penetration_acceleration(plane)), which the C core supplies.
    """
    c = compliant_contact(model, plane, penetration_acceleration(plane))
    f_n, rho, rhodot, slip = c.normal_force, c.rho, c.rhodot, c.slip
    sx, sy = deflection_symbols(model, plane)
    k_t = tangential_stiffness(model, c.stiffness)
    stiffening = rhodot / (2 * _rho_floor(rho))
    s_cap, s_cap_rate = capped_deflection(model, k_t, stiffening, f_n, c.normal_force_rate)
    size = sm.sqrt(sx**2 + sy**2)
    ex, ey = sliding_direction(model, plane)
    dilution = _positive(rhodot) / (2 * _rho_floor(rho))
    stretch = ex * slip[0] + ey * slip[1] - dilution * size
    yield_margin = 1 - k_t * size / sm.Max(c.cap, sm.sqrt(_FORCE_FLOOR2))
    # with no load (F_n = 0: past the contact's end, or at its clamp) both modes apply no
    # tangential force and the deflection stands still.  The yield margin reads -1 there:
    # a loaded spring's r = k_t |s| / (mu F_n) grows without bound as the load goes, so
    # an elastic contact always yields before it ends, and a step that jumps from
    # below the cap to past the end must still see the crossing.  The re-stick margin
    # reads +1 (a sliding contact never re-sticks by losing its load).
    in_contact = sm.Heaviside(f_n, 0)
    idle = 1 - in_contact
    # the elastic mode's force is F_el = -k_t s (no smooth yield: compliant_elastic_force)
    capacity = capacity_margin(model, k_t, c.cap, [-k_t * sx, -k_t * sy], slip)
    return [in_contact * yield_margin - idle, in_contact * (stretch - s_cap_rate) + idle,
            s_cap, k_t, capacity]


def _capacity(model: Model, k_t, cap, capped, slip):
    """(V, the capacity cap - |F_e| left (>= 0), |V|) of capacity_damping (N)."""
    c_t = 2 * model.p["tangential_damping_ratio"] * _sqrt_positive(effective_mass(model) * k_t)
    viscous = [-c_t * v for v in slip]
    spare = _positive(cap - sm.sqrt(sm.Max(capped[0]**2 + capped[1]**2, _FORCE_FLOOR2)))
    viscous_size = sm.sqrt(sm.Max(viscous[0]**2 + viscous[1]**2, _FORCE_FLOOR2))
    return viscous, spare, viscous_size


def capacity_damping(model: Model, k_t, cap, capped, slip):
    """The viscous tangential force (2) within the capacity the elastic force leaves:
    V = -c_t v_t, c_t = 2 gamma_t sqrt(m* k_t), scaled by
    alpha = min(1, max(0, cap - |F_e|) / |V|).  alpha has a kink where the capacity
    saturates, spare = |V| (capacity_margin): the exact modes end a segment there."""
    viscous, spare, viscous_size = _capacity(model, k_t, cap, capped, slip)
    alpha = sm.Min(1, spare / viscous_size)
    return [alpha * f for f in viscous]


def capacity_margin(model: Model, k_t, cap, capped, slip):
    """(cap - |F_e|) - |V| (N): > 0 while the viscous force fits in the capacity the
    elastic force leaves (alpha = 1), < 0 while it is cut to it (capacity_damping);
    its zero is a kink of the tangential force and of the dissipation rate."""
    _, spare, viscous_size = _capacity(model, k_t, cap, capped, slip)
    return spare - viscous_size


def compliant_elastic_force(model: Model, plane: str, jacobian_form=False):
    """The compliant law's elastic mode (``<plane>_compliant_elastic``): the law of
    compliant_model_force without its smooth yield and cap -- below the cap they are
    inactive, and the mode's yield guard ends it there (ballc.compliantmodes)."""
    return compliant_model_force(model, plane, jacobian_form, smooth_yield=False)


def compliant_model_force(model: Model, plane: str, jacobian_form=False, smooth_yield=True):
    """ballc's passive compliant law (not in the seed): docs/contact_laws.md.

    Normal: Hertz with Hunt-Crossley or viscoelastic damping.  Tangential: the DEM
    codes' incremental Mindlin spring (a deflection state per plane, zero at contact
    start) with a smooth Coulomb yield, plus viscous damping within the capacity the
    elastic force leaves, |F_t| <= mu F_n.  ``jacobian_form``: the law whose
    derivatives the Jacobian kernel holds (JACOBIAN_FORMS).
    """
    N = model.frame
    c = compliant_contact(model, plane)
    capped, rate, storage, k_t = incremental_mindlin(model, plane, c.stiffness, c.rho,
                                                     c.rhodot, c.normal_force, c.cap, c.slip,
                                                     c.normal_force_rate,
                                                     dilute=not jacobian_form,
                                                     smooth_yield=smooth_yield)
    viscous = capacity_damping(model, k_t, c.cap, capped, c.slip)
    tangential = [e + v for e, v in zip(capped, viscous)]
    force = c.normal_force*c.normal + tangential[0]*N.x + tangential[1]*N.y
    return ContactLaw(c.point, force, sm.S.One, deflection_rate=rate,
                      tangential_storage=storage)


def tangential_spring_energy(model: Model, plane: str):
    """The compliant law's tangential spring energy 1/2 k_t |s|^2 = 1/2 |F_el|^2 / k_t (J)."""
    _, rho = plane_geometry(model, plane)
    _, stiffness = hertz_normal(model, rho)
    sx, sy = deflection_symbols(model, plane)
    return tangential_stiffness(model, stiffness) * (sx**2 + sy**2) / 2


@dataclass
class ContactLaw:
    """What one law applies at one plane's contact point."""

    point: me.Point
    force: me.Vector           # on the ball, at the contact point, weight included
    weight: sm.Expr            # share of the Hertz spring this law carries
    deflection_rate: list | None = None   # d/dt of the plane's deflection states
    tangential_storage: sm.Expr | None = None  # d/dt of its tangential spring's energy
    #: [(symbol, expression)] computed before the Jacobian kernel's code and held
    #: constant by its differentiation (a Jacobian form's frozen quantities)
    frozen: list | None = None


#: Laws whose Jacobian kernel is derived from a form of the law other than its value
#: kernel's.  The compliant law's dilution term max(rhodot, 0)/(2 rho) s is singular at
#: contact start (rho -> 0; its exact solution s = 2/3 v_t t is smooth): a Jacobian
#: taken there holds ~1e16 in ds'/ds, and the implicit integrators' simplified Newton,
#: reusing it later where the true value is ~1/t, takes tiny increments in s for
#: convergence and returns a wrong deflection (measured: the energy balance of the
#: compliant seed throw drifted by 18 J at rtol 1e-8; scipy's Radau the same).  The
#: Jacobian leaves the term out: a stiffness underestimated by 1/(2t) where the steps
#: are ~t costs Newton little and never converges falsely (docs/contact_laws.md).
#: The sliding mode's direction e = s/|s| has de/ds ~ 1/|s|: its Jacobian holds e fixed
#: in the force -mu F_n e and in the radial rate, but keeps the exact d/ds of the turn of
#: e towards v_t, (v_t - (e . v_t) e) / |s| -- the mode's own stiffness, (e . v_t) / |s|
#: across e (written to first order in the part of s across the held e, divided by the
#: held max(|s|, TURN_FLOOR), so that no 1/|s| is evaluated: sliding_mindlin).  That is no ~1/t: ~1e7 /s through a spinning steel ball's contact (|v_t| =
#: 64 m/s, |s| ~ 5e-6 m) where its steps are ~1e-5 s, ~1e12 /s where it starts sliding
#: at the arming depth (|s| ~ 4e-11 m).  Left to Newton (before issue 28) it held radau5
#: to steps of ~2e-8 s with a Jacobian at nearly every one: 9.9 M calls for 2 s of that
#: ball's bounces, against dop853's 45 k.  Because it follows |s| step by step, a
#: Jacobian kept from an earlier step overestimates it (|s| grows ~ t from the start),
#: and Newton then settled on a wrong direction of s (1e-5 m/s off after one contact at
#: rtol 1e-10): a sliding segment takes its Jacobian at every step
#: (radau5_problem.jacobian_every_step).
JACOBIAN_FORMS = {
    "compliant": lambda model, plane: compliant_model_force(model, plane, jacobian_form=True),
    "compliant_sliding": lambda model, plane: compliant_sliding_force(model, plane,
                                                                      jacobian_form=True),
    "compliant_elastic": lambda model, plane: compliant_elastic_force(model, plane,
                                                                      jacobian_form=True),
}


@dataclass(frozen=True)
class Composition:
    """A contact law as parts, as LAMMPS GRANULAR's sub-models (normal, damping,
    tangential), and its weight.

    * normal(model, rho) -> (elastic force F_H, tangent stiffness k_n);
    * damping(model, F_H, k_n, rate, rhodot^-) -> the damped normal force (N) on a
      penetration rate, before the no-adhesion clamp;
    * tangential(model, plane, normal_force) -> the force on the ball at the contact
      point, unweighted, with normal_force(rate) = max(0, damping(F_H, k_n, rate));
    * weight(model) -> the law's share of the mixture (its kernel is weighted by it).
    """

    normal: Callable
    damping: Callable
    tangential: Callable
    weight: Callable


def compose(model: Model, plane: str, parts: Composition) -> ContactLaw:
    """The law made of ``parts`` on ``plane``: weight * tangential(normal_force)."""
    _, rho = plane_geometry(model, plane)
    rate_at_impact = latch_symbols(model, plane)[0]
    elastic, stiffness = parts.normal(model, rho)

    def normal_force(rate):
        return _positive(parts.damping(model, elastic, stiffness, rate, rate_at_impact))

    weight = parts.weight(model)
    force = parts.tangential(model, plane, normal_force)
    return ContactLaw(contact_point(model, plane), weight * force, weight)


def friction_share(model: Model):
    """1 - mixture: the friction law's share of the seed's mixture."""
    return 1 - model.p["mixture"]


def digin_share(model: Model):
    """mixture: the dig-in law's share of the seed's mixture."""
    return model.p["mixture"]


#: The seed's laws as compositions of parts.  The seed's mixture is no law of its own:
#: the C core adds the friction and dig-in kernels, weighted 1 - mixture and mixture.
#: "friction_normal" is the friction law's normal share (its kernel serves exact,
#: event-driven Coulomb friction, which applies the tangential force itself).  The
#: compliant law is composed by compliant_model_force: hertz_normal x damped_normal's
#: damping (hunt_crossley_damping or viscoelastic_damping, added to F_H) x
#: incremental_mindlin + capacity_damping.
COMPOSITIONS = {
    "friction": Composition(hertz_normal, hunt_crossley, coulomb_friction, friction_share),
    "digin": Composition(hertz_normal, hunt_crossley, dig_in, digin_share),
    "friction_normal": Composition(hertz_normal, hunt_crossley, no_friction, friction_share),
}

#: Laws whose auxiliary rates (dissipation, deflection) are affine in the exact
#: penetration acceleration rho'' (penetration_acceleration): their value kernel is
#: emitted at rho'' = 0 and a ``_acceleration`` kernel gives the rates' coefficients of
#: rho'', which the C core multiplies with the solved rho'' (the forces do not depend on
#: it, so it follows from the solve).
ACCELERATION_LAWS = ("compliant_sliding",)

TANGENTIAL_LAWS = {
    "friction": friction_model_force,
    "digin": digin_model_force,
    "compliant": compliant_model_force,
    "compliant_sliding": compliant_sliding_force,
    "compliant_elastic": compliant_elastic_force,
}


def dissipation_rates(model: Model, plane: str, law: ContactLaw):
    """(normal, tangential) rate of dissipated work (W) of ``law`` on ``plane``.

    With F the law's force and v the contact-point velocity, the contact's power on
    the ball is F . v = -(F . n) rhodot + F_t . v_t; the Hertz spring (the law's
    share ``weight`` of it) stores k0 rho^(3/2) rhodot.  So the normal part
    dissipates (F . n) rhodot - weight k0 rho^(3/2) rhodot and the tangential part
    -F_t . v_t, less what a tangential spring stores (the compliant law's
    1/2 k_t |s|^2, an energy output of its own).  A negative rate is energy injected
    (the dig-in law does that; the compliant law never does: docs/contact_laws.md).
    """
    _, velocity, rho, rhodot = contact_kinematics(model, plane)
    normal, _ = plane_geometry(model, plane)
    f_normal = me.dot(law.force, normal)
    elastic = law.weight * hertz_stiffness(model) * _positive(rho)**sm.Rational(3, 2)
    tangential_force = law.force - f_normal*normal
    tangential = -me.dot(tangential_force, velocity)
    if law.tangential_storage is not None:
        tangential -= law.tangential_storage
    return f_normal*rhodot - elastic*rhodot, tangential


def spring_energy(model: Model, plane: str):
    """Hertz elastic energy 2/5 k0 rho^(5/2) stored in the contact with ``plane``."""
    _, rho = plane_geometry(model, plane)
    return sm.Rational(2, 5) * hertz_stiffness(model) * _positive(rho)**sm.Rational(5, 2)


# --- the rolling part: the law's fourth part (LAMMPS GRANULAR's rolling and twisting
# sub-models; docs/contact_laws.md, "Rolling resistance") --------------------------------


def rolling_velocities(model: Model, plane: str):
    """The contact's rolling and twisting velocities in the plane's frame (m/s): the
    rolling velocity v_roll = r (omega x n) (2: along t1, t2; LAMMPS' vrl with
    R_eff = r, Wang et al. 2015, eq. 31) and the twisting velocity v_twist = r omega . n
    (LAMMPS' magtwist times r).  A ball rolling without slip along u at speed v has
    v_roll = v u: the velocity of its centre."""
    normal, _ = plane_geometry(model, plane)
    N = model.frame
    omega = model.ball_frame.ang_vel_in(N)
    r = model.p["radius"]
    rolling = r * me.cross(omega, normal)
    return [me.dot(rolling, N.x), me.dot(rolling, N.y), r * me.dot(omega, normal)]


def rolling_torque(model: Model, plane: str, rolling_force, twisting_force):
    """The torque on the ball (about its centre) of a rolling force F_r (2: along t1,
    t2) and a twisting force F_w (1): r n x F_r + r F_w n (N m), LAMMPS' torroll =
    R_eff (n x F_r) and tortwist along n.  Its power on the ball is
    F_r . v_roll + F_w v_twist (rolling_velocities): a force against the rolling
    velocity is passive."""
    normal, _ = plane_geometry(model, plane)
    N = model.frame
    r = model.p["radius"]
    force = rolling_force[0] * N.x + rolling_force[1] * N.y
    return r * me.cross(normal, force) + r * twisting_force * normal


def rolling_load(model: Model, plane: str):
    """The normal force F_n (N) that caps the rolling and twisting torques: the
    contact's normal x damping parts (damped_normal: Hertz with the scene's normal
    damping, clamped at 0), as LAMMPS' rolling sub-model reads Fncrit from its normal
    sub-model.  For the friction and compliant laws it is their normal force; the seed's
    dig-in law, whose force is along the direction latched at impact, has no normal
    force of its own, and its share of the mixture adds none to the cap."""
    _, _, rho, rhodot = contact_kinematics(model, plane)
    rate_at_impact = latch_symbols(model, plane)[0]
    f_n, _ = damped_normal(model, rho, rhodot, rate_at_impact)
    return f_n



def rolling_spring_symbols(model: Model, plane: str):
    """The plane's rolling spring's deflection (xi_x, xi_y along t1, t2, xi_w about n;
    m): model.ROLLING_SPRING_FIELDS (model.FRAME_PLANE only)."""
    require_frame_plane(plane)
    return [model.state(name) for name in ROLLING_SPRING_FIELDS]


def rolling_spring_energy(model: Model, plane: str):
    """The energy stored in the sds rolling and twisting springs (J):
    1/2 k_r (xi_x^2 + xi_y^2) + 1/2 k_w xi_w^2 (0 for the exact model, whose spring
    states stay 0)."""
    xx, xy, xw = rolling_spring_symbols(model, plane)
    return (model.p["rolling_stiffness"] * (xx**2 + xy**2)
            + model.p["twisting_stiffness"] * xw**2) / 2


# --- the rolling part's sds model (LAMMPS rolling sds / twisting sds, ballc's passive
# form): a spring, a dashpot within the capacity the spring leaves, a slider at the cap --

#: The rolling part's two parts: (first component of the velocities and springs, count).
ROLLING_PARTS = {"rolling": (0, 2), "twisting": (2, 1)}


def rolling_part(model: Model, plane: str, part: str):
    """(spring deflection xi, velocity w, stiffness k, dashpot gamma, mu) of the part
    ``part`` ("rolling": 2 components along t1, t2; "twisting": 1, about n)."""
    first, count = ROLLING_PARTS[part]
    xi = rolling_spring_symbols(model, plane)[first:first + count]
    w = rolling_velocities(model, plane)[first:first + count]
    p = model.p
    return xi, w, p[f"{part}_stiffness"], p[f"{part}_damping"], p[f"{part}_resistance"]


def _part_forces(part, force):
    """(rolling force (2), twisting force) of a part's force (its components)."""
    return (list(force), 0) if part == "rolling" else ([0, 0], force[0])


def _rolling_loaded(normal_force):
    """1 while the contact carries a load, as a factor of a spring's rate: F_n / max(F_n,
    1e-12 N) (below the force floor a fraction: finite derivatives)."""
    return normal_force / sm.Max(normal_force, sm.sqrt(_FORCE_FLOOR2))


def sds_spring(model: Model, plane: str, part: str):
    """The sds part below its cap (the spring mode): F = F_el + alpha V with the spring
    F_el = -k xi and the dashpot V = -gamma w cut to the capacity the spring leaves,
    alpha = min(1, max(0, mu F_n - |F_el|) / |V|) (the compliant law's capacity damping:
    passive, |F| <= mu F_n); xi' = w while the contact carries a load.

    LAMMPS caps the sum -k xi - gamma w instead and rescales xi so that the sum sits at
    the cap; where the dashpot alone exceeds the cap (a contact's start, where the cap is
    0) that rescale stores energy from nothing.  ballc keeps the spring below the cap and
    the dashpot within what it leaves (Kratos' choice for the tangential law): the same
    law when gamma = 0, and passive whatever gamma (docs/contact_laws.md).
    Returns (force (the part's components), xi' (its components), dissipation rate (W)).
    """
    xi, w, k, gamma, mu = rolling_part(model, plane, part)
    f_n = rolling_load(model, plane)
    cap = mu * f_n
    elastic = [-k * x for x in xi]
    viscous = [-gamma * v for v in w]
    spare = _positive(cap - sm.sqrt(sm.Max(sum(e**2 for e in elastic), _FORCE_FLOOR2)))
    viscous_size = sm.sqrt(sm.Max(sum(v**2 for v in viscous), _FORCE_FLOOR2))
    alpha = sm.Min(1, spare / viscous_size)
    force = [e + alpha * v for e, v in zip(elastic, viscous)]
    rate = [_rolling_loaded(f_n) * v for v in w]
    dissipation = -sum(f * v for f, v in zip(force, w)) \
        - k * sum(x * r for x, r in zip(xi, rate))
    return force, rate, dissipation


def slider_grows(model: Model, plane: str):
    """1 while the cap grows (dF_n/dt >= 0 with the contact's own rho''), else 0: which
    radial form the sds slider takes (sds_slider)."""
    return sm.Heaviside(_load_and_rate(model, plane)[1], 0)


def _load_and_rate(model: Model, plane: str, accel=None):
    """(F_n, dF_n/dt) of the plane's contact as its rolling part sees them: the normal
    force (rolling_load) and its rate with the penetration acceleration ``accel``
    (normal_force_rate; None: the contact's own rho'')."""
    _, _, rho, rhodot = contact_kinematics(model, plane)
    rate_at_impact = latch_symbols(model, plane)[0]
    f_n = rolling_load(model, plane)
    return f_n, normal_force_rate(model, plane, rho, rhodot, rate_at_impact, f_n, accel)


def sds_slider(model: Model, plane: str, part: str, accel=None, grows=None):
    """The sds part at its cap (the slider mode; LAMMPS' rescale in the limit dt -> 0):
    F = -mu F_n e, e = xi/|xi|, no dashpot (no capacity left), and
    xi' = (w - (e . w) e) f + radial: |xi| stays mu F_n / k (a mode change puts the
    spring at the cap), and e turns towards w at (w - (e . w) e)/|xi|, the truncated
    increment's direction (f = |xi| / max(|xi|, TURN_FLOOR); the twisting part has no
    turn).  The radial part follows the cap: e mu dF_n/dt / k while it grows (open loop:
    a relative rate xi dF_n/dt / F_n is ~ 3/t at a contact's start, where F_n grows from
    0, and radau5 stepping over that growth turned the spring round), xi d ln(F_n)/dt
    while it shrinks (closed loop: xi reaches 0 with the cap, not before or after, at a
    contact's end) -- the same rate where |xi| = mu F_n / k, chosen by the sign of
    dF_n/dt with the contact's own rho'' (so that the rates stay affine in the exact one).
    dF_n/dt holds the penetration acceleration ``accel`` (rho'', normal_force_rate;
    None: the contact's own).  Its dissipation rate is
    mu F_n ((e . w) - mu dF_n/dt / k) >= 0 while it slides (its re-stick margin >= 0).
    ``grows``: a symbol for slider_grows, held constant by the Jacobian (its derivative
    is a Dirac delta).  Returns (force, xi', dissipation rate)."""
    xi, w, k, gamma, mu = rolling_part(model, plane, part)
    f_n, f_rate = _load_and_rate(model, plane, accel)
    cap = mu * f_n
    size = sm.sqrt(sm.Max(sum(x**2 for x in xi), _DIRECTION_FLOOR2))
    e = [x / size for x in xi]
    along = sum(a * b for a, b in zip(e, w))
    turn = size / sm.Max(size, TURN_FLOOR)
    across = [(v - along * d) * turn for v, d in zip(w, e)] if len(xi) == 2 else [0]
    if grows is None:
        grows = slider_grows(model, plane)
    growing = grows * mu * f_rate / sm.Max(k, _STIFFNESS_FLOOR)
    shrinking = (1 - grows) * f_rate / sm.Max(f_n, sm.sqrt(_FORCE_FLOOR2))
    loaded = _rolling_loaded(f_n)
    rate = [loaded * (a + d * growing + x * shrinking) for a, d, x in zip(across, e, xi)]
    force = [-cap * d for d in e]
    dissipation = -sum(f * v for f, v in zip(force, w)) \
        - k * sum(x * r for x, r in zip(xi, rate))
    return force, rate, dissipation


def sds_margins(model: Model, plane: str, part: str, accel):
    """The sds part's mode guards: the yield margin 1 - k |xi| / (mu F_n) (the spring
    mode ends where it falls below 0; -1 without load), the re-stick margin (m/s)
    (e . w) - mu dF_n/dt / k (how much faster the spring would stretch than the cap
    grows; the slider ends where it falls below 0; +1 without load), affine in the
    penetration acceleration ``accel``, and the deflection at the cap mu F_n / k (m)."""
    xi, w, k, gamma, mu = rolling_part(model, plane, part)
    f_n, f_rate = _load_and_rate(model, plane, accel)
    cap = mu * f_n
    stiffness = sm.Max(k, _STIFFNESS_FLOOR)
    size = sm.sqrt(sm.Max(sum(x**2 for x in xi), _DIRECTION_FLOOR2))
    along = sum(x / size * v for x, v in zip(xi, w))
    in_contact = sm.Heaviside(f_n, 0)
    idle = 1 - in_contact
    yield_margin = 1 - k * sm.sqrt(sum(x**2 for x in xi)) / sm.Max(cap, sm.sqrt(_FORCE_FLOOR2))
    restick = along - mu * f_rate / stiffness
    return [in_contact * yield_margin - idle, in_contact * restick + idle, cap / stiffness]
