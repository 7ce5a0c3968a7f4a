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
"""
from __future__ import annotations

import sympy as sm
import sympy.physics.mechanics as me

from .model import LATCH_FIELDS, Model, contact_point


def plane_geometry(model: Model, plane: str):
    """(normal towards the ball, penetration rho) of ``plane``."""
    N = model.frame
    p = model.p
    z = model.states[6]
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


def friction_model_force(model: Model, plane: str):
    """(point, force vector) of the seed's friction model, weighted by 1 - mixture."""
    N = model.frame
    point, velocity, _, _ = contact_kinematics(model, plane)
    normal, _ = plane_geometry(model, plane)
    f_n = normal_force(model, plane)
    slip = velocity - me.dot(velocity, normal)*normal
    sx, sy = me.dot(slip, N.x), me.dot(slip, N.y)
    eps = model.p["friction_regularization_speed"]
    # max(|v_t|, eps) written as sqrt(max(|v_t|^2, eps^2)): same value, but its
    # derivative stays finite at zero slip (no 0/0 in the Jacobian).
    slip_speed = sm.sqrt(sm.Max(sx**2 + sy**2, eps**2))
    tangential = -model.p["friction_coefficient"] * f_n / slip_speed * (sx*N.x + sy*N.y)
    weight = 1 - model.p["mixture"]
    return point, weight * (f_n*normal + tangential)


def digin_model_force(model: Model, plane: str):
    """(point, force vector) of the seed's dig-in model, weighted by mixture."""
    N = model.frame
    point, velocity, rho, _ = contact_kinematics(model, plane)
    rate_at_impact, dx, dy, dz = latch_symbols(model, plane)
    direction = dx*N.x + dy*N.y + dz*N.z
    f_d = _hunt_crossley(model, rho, me.dot(velocity, direction), rate_at_impact)
    return point, model.p["mixture"] * f_d * (-direction)


TANGENTIAL_LAWS = {
    "friction": friction_model_force,
    "digin": digin_model_force,
}


def spring_energy(model: Model, plane: str):
    """Hertz elastic energy 2/5 k0 rho^(5/2) stored in the contact with ``plane``."""
    _, rho = plane_geometry(model, plane)
    return sm.Rational(2, 5) * hertz_stiffness(model) * _positive(rho)**sm.Rational(5, 2)
