"""Contact laws of the seed, as sympy expressions of the contact-point kinematics.

For a plane with unit normal ``n`` pointing towards the ball (floor: +z, ceiling: -z):

* penetration ``rho = r - distance(centre, plane)`` (positive in contact),
* penetration rate ``rhodot = -v_cp . n`` (positive while moving into the plane),
* Hertz stiffness ``k0 = 4 / (3 (sigma_b + sigma_p)) sqrt(r)``, ``sigma = (1 - nu^2) / E``,
* Hunt-Crossley normal force
  ``F_n = max(0, k0 rho^(3/2) [1 + 3/2 (1 - c_tau) rhodot / |rhodot^-|])``
  where ``rhodot^-`` is the penetration rate latched at the start of the contact.
  The clamp at 0 (no adhesion) is ballc's addition: the seed's formula turns
  attractive when the ball leaves faster than ``|rhodot^-| / (3/2 (1 - c_tau))``.

Tangential models (seed, weighted by ``mixture``):

* friction: ``(1 - mixture) (F_n n - mu F_n v_t / max(|v_t|, eps))``, with ``v_t`` the
  slip velocity of the contact point in the plane and ``eps`` the seed's 1e-10 m/s;
* dig-in: ``mixture F_d (-d)`` where ``d`` is the unit contact-point velocity latched
  at impact start and ``F_d = max(0, k0 rho^(3/2) [1 + 3/2 (1 - c_tau) (v_cp . d) / |rhodot^-|])``.

ballc's own addition, not in the seed: the compliant law (see compliant_model_force).
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sm
import sympy.physics.mechanics as me

from .model import LATCH_FIELDS, Model, contact_point


def plane_geometry(model: Model, plane: str):
    """(normal towards the ball, penetration rho) of ``plane``."""
    N = model.frame
    p = model.p
    z = model.state("z")
    if plane == "floor":
        return N.z, p["radius"] - z
    return -N.z, p["radius"] - (p["ceiling_height"] - z)


def hertz_stiffness(model: Model):
    """k0 of a sphere of radius r on a half-space (N / m^(3/2))."""
    p = model.p
    sigma_ball = (1 - p["ball_poisson_ratio"]**2) / p["ball_youngs_modulus"]
    sigma_plane = (1 - p["plane_poisson_ratio"]**2) / p["plane_youngs_modulus"]
    return sm.Rational(4, 3) / (sigma_ball + sigma_plane) * sm.sqrt(p["radius"])


def latch_symbols(model: Model, plane: str):
    """The four latched symbols (rhodot^-, d_x, d_y, d_z) of ``plane``."""
    offset = 0 if plane == "floor" else len(LATCH_FIELDS)
    return model.latches[offset:offset + len(LATCH_FIELDS)]


def contact_kinematics(model: Model, plane: str):
    """(point, velocity vector, rho, rhodot) of the contact point on ``plane``."""
    point = contact_point(model, plane)
    normal, rho = plane_geometry(model, plane)
    velocity = point.vel(model.frame)
    rhodot = -me.dot(velocity, normal)
    return point, velocity, rho, rhodot


def _positive(expr):
    return sm.Max(expr, 0)


def _hunt_crossley(model, rho, rate, rate_at_impact):
    k0 = hertz_stiffness(model)
    damping = sm.Rational(3, 2) * (1 - model.p["c_tau"]) * rate / sm.Abs(rate_at_impact)
    return _positive(k0 * _positive(rho)**sm.Rational(3, 2) * (1 + damping))


def normal_force(model: Model, plane: str):
    """Unweighted Hunt-Crossley normal force magnitude F_n >= 0 on ``plane``."""
    _, _, rho, rhodot = contact_kinematics(model, plane)
    rate_at_impact = latch_symbols(model, plane)[0]
    return _hunt_crossley(model, rho, rhodot, rate_at_impact)


def slip_kinematics(model: Model, plane: str):
    """(point, contact-point velocity, normal, in-plane slip components (sx, sy))."""
    N = model.frame
    point, velocity, _, _ = contact_kinematics(model, plane)
    normal, _ = plane_geometry(model, plane)
    slip = velocity - me.dot(velocity, normal)*normal
    return point, velocity, normal, (me.dot(slip, N.x), me.dot(slip, N.y))


def friction_model_force(model: Model, plane: str):
    """Seed's friction model: HC normal force and Coulomb friction, weight 1 - mixture.

    The Coulomb direction is ``-v_t / max(|v_t|, v_s)`` (the seed's, ``smooth_friction``
    = 0) or ``-v_t / sqrt(|v_t|^2 + v_s^2)`` (``smooth_friction`` = 1).
    """
    N = model.frame
    point, _, normal, (sx, sy) = slip_kinematics(model, plane)
    f_n = normal_force(model, plane)
    eps = model.p["friction_regularization_speed"]
    smooth = model.p["smooth_friction"]
    # max(|v_t|, eps) written as sqrt(max(|v_t|^2, eps^2)): same value, but its
    # derivative stays finite at zero slip (no 0/0 in the Jacobian).
    seed_speed = sm.sqrt(sm.Max(sx**2 + sy**2, eps**2))
    smooth_speed = sm.sqrt(sx**2 + sy**2 + eps**2)
    slip_speed = (1 - smooth)*seed_speed + smooth*smooth_speed
    tangential = -model.p["friction_coefficient"] * f_n / slip_speed * (sx*N.x + sy*N.y)
    weight = 1 - model.p["mixture"]
    return ContactLaw(point, weight * (f_n*normal + tangential), weight)


def digin_model_force(model: Model, plane: str):
    """Seed's dig-in model: HC force along the latched direction, weight mixture."""
    N = model.frame
    point, velocity, rho, _ = contact_kinematics(model, plane)
    rate_at_impact, dx, dy, dz = latch_symbols(model, plane)[:4]
    direction = dx*N.x + dy*N.y + dz*N.z
    f_d = _hunt_crossley(model, rho, me.dot(velocity, direction), rate_at_impact)
    weight = model.p["mixture"]
    return ContactLaw(point, weight * f_d * (-direction), weight)


def deflection_symbols(model: Model, plane: str):
    return model.state(f"{plane}_deflection_x"), model.state(f"{plane}_deflection_y")


#: Sharpness n of the compliant model's yield: flow ~ (|F_el| / mu F_n)^n.
YIELD_EXPONENT = 8


def compliant_model_force(model: Model, plane: str):
    """Tangential compliance with a Coulomb cap (ballc's model, not in the seed).

    Normal: the HC force.  Tangential: an elastic deflection ``s`` of the contact
    (a state, zero at contact start) with Mindlin-type stiffness proportional to the
    normal tangent stiffness, ``k_t = kappa * 3/2 k0 rho^(1/2)``, damped like the
    normal force (``c_t = kappa * 3/2 (1 - c_tau) k0 rho^(3/2) / |rhodot^-|``):
    ``F_el = -k_t s - c_t sdot``, capped at ``|F_t| <= mu F_n``.  The deflection
    follows the slip velocity while it sticks and stops growing at the cap
    (elastic-plastic, Bouc-Wen-type smooth yield with exponent YIELD_EXPONENT):
    ``sdot = v_t - r^n max(0, s_hat . v_t) s_hat``, ``r = k_t |s| / (mu F_n)``
    (r clipped at 2).  Unloading is elastic.
    """
    N = model.frame
    p = model.p
    point, _, normal, (vx, vy) = slip_kinematics(model, plane)
    _, _, rho, _ = contact_kinematics(model, plane)
    f_n = normal_force(model, plane)
    kappa = p["tangential_stiffness_ratio"]
    k0 = hertz_stiffness(model)
    rho_pos = _positive(rho)
    # sqrt(rho) written as rho / sqrt(max(rho, 1e-30)): same value, exactly 0 out of
    # contact, and a finite derivative at rho = 0 (d sqrt(rho)/d rho is infinite there,
    # which would put inf * 0 = NaN into the Jacobian at contact start).
    stiffness = kappa * sm.Rational(3, 2) * k0 * rho_pos / sm.sqrt(sm.Max(rho_pos, 1e-30))
    damping = kappa * sm.Rational(3, 2) * (1 - p["c_tau"]) * k0 * rho_pos**sm.Rational(3, 2) \
        / sm.Abs(latch_symbols(model, plane)[0])
    sx, sy = deflection_symbols(model, plane)
    cap = p["friction_coefficient"] * f_n
    # Floors far below any physical value (1e-12 N, 1e-15 m) keep every quotient and
    # its derivative finite where the contact has no load or no deflection yet.
    force_floor, length_floor = sm.Float(1e-24), sm.Float(1e-30)
    ratio2 = sm.Min(stiffness**2 * (sx**2 + sy**2) / sm.Max(cap**2, force_floor), 4)
    loading = sm.Max(sx*vx + sy*vy, 0) / sm.Max(sx**2 + sy**2, length_floor)
    flow = ratio2**(YIELD_EXPONENT // 2) * loading
    rate = [vx - flow*sx, vy - flow*sy]
    trial = [-stiffness*s - damping*r for s, r in zip((sx, sy), rate)]
    trial_size = sm.sqrt(sm.Max(trial[0]**2 + trial[1]**2, cap**2, force_floor))
    tangential = [f * cap / trial_size for f in trial]   # = trial unless above the cap
    force = f_n*normal + tangential[0]*N.x + tangential[1]*N.y
    return ContactLaw(point, force, sm.S.One, deflection_rate=rate)


@dataclass
class ContactLaw:
    """What one law applies at one plane's contact point."""

    point: me.Point
    force: me.Vector           # on the ball, at the contact point, weight included
    weight: sm.Expr            # share of the Hertz spring this law carries
    deflection_rate: list | None = None   # d/dt of the plane's deflection states


TANGENTIAL_LAWS = {
    "friction": friction_model_force,
    "digin": digin_model_force,
    "compliant": compliant_model_force,
}


def dissipation_rates(model: Model, plane: str, law: ContactLaw):
    """(normal, tangential) rate of dissipated work (W) of ``law`` on ``plane``.

    With F the law's force and v the contact-point velocity, the contact's power on
    the ball is F . v = -(F . n) rhodot + F_t . v_t; the Hertz spring (the law's
    share ``weight`` of it) stores k0 rho^(3/2) rhodot.  So the normal part
    dissipates (F . n) rhodot - weight k0 rho^(3/2) rhodot and the tangential part
    -F_t . v_t (including, for the compliant law, the energy momentarily held by
    its tangential spring; it is released by the end of the contact).  A negative
    rate is energy injected (the dig-in law does that).
    """
    _, velocity, rho, rhodot = contact_kinematics(model, plane)
    normal, _ = plane_geometry(model, plane)
    f_normal = me.dot(law.force, normal)
    elastic = law.weight * hertz_stiffness(model) * _positive(rho)**sm.Rational(3, 2)
    tangential_force = law.force - f_normal*normal
    return f_normal*rhodot - elastic*rhodot, -me.dot(tangential_force, velocity)


def spring_energy(model: Model, plane: str):
    """Hertz elastic energy 2/5 k0 rho^(5/2) stored in the contact with ``plane``."""
    _, rho = plane_geometry(model, plane)
    return sm.Rational(2, 5) * hertz_stiffness(model) * _positive(rho)**sm.Rational(5, 2)
