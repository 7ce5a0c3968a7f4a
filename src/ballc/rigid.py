"""Rigid impact map of a sphere on a plane (Walton / Garwin-style), in closed form.

One instantaneous impact: normal restitution ``e`` (exit/entry normal speed),
Coulomb friction ``mu`` and tangential restitution ``e_t`` of the contact point's
tangential velocity.  Used as the stiff-material limit of the compliant models and
as a quick estimate.

With n the plane's normal towards the ball, c = -r n the contact point relative to
the centre, u = v_t + omega x c the tangential velocity of the contact point and
m_t = 1 / (1/m + r^2/I) the effective tangential mass of a sphere:

* normal impulse ``P_n = m (1 + e) |v . n|`` (the ball must be approaching);
* tangential impulse ``P_t = -m_t (1 + e_t) u`` if ``|P_t| <= mu P_n`` (the contact
  point sticks: it leaves with ``-e_t u``; e_t = 0 is rolling), otherwise the contact
  slides throughout and ``P_t = -mu P_n u / |u|``.

So with e_t = 0 the contact point ends rolling exactly when
``|u| <= mu (1 + e) |v_n| (1 + m r^2 / I)`` — ``3.5 mu (1 + e) |v_n|`` for a solid sphere.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RigidImpact:
    """Velocities after one rigid impact (SI units, inertial components).

    Attributes
    ----------
    velocity : ndarray, shape (3,)
        Centre velocity after the impact (m/s).
    angular_velocity : ndarray, shape (3,)
        Angular velocity after the impact (rad/s).
    normal_impulse : float
        Normal impulse P_n (N s).
    tangential_impulse : ndarray, shape (3,)
        Tangential impulse P_t, in the plane (N s).
    sticking : bool
        True when the contact point stuck (it left with -e_t u); False when it slid.
    """

    velocity: np.ndarray           # centre velocity after (m/s)
    angular_velocity: np.ndarray   # angular velocity after (rad/s)
    normal_impulse: float          # N s
    tangential_impulse: np.ndarray  # N s, in the plane
    sticking: bool                 # True: the contact point stuck (left with -e_t u)


def _vector(name, value):
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} = {value!r} is not allowed: must be 3 finite numbers")
    return v


def rigid_impact(velocity, angular_velocity, *, mass=1.0, radius=1.0, inertia=None,
                 restitution=1.0, friction_coefficient=0.0, tangential_restitution=0.0,
                 plane="floor") -> RigidImpact:
    """Post-impact velocity and spin of a sphere hitting ``plane`` ("floor"/"ceiling", or
    any plane: a ballc.Plane or its normal towards the ball, 3 numbers).

    Parameters
    ----------
    velocity, angular_velocity : 3 floats
        Centre velocity (m/s) and angular velocity (rad/s) just before the impact.
    mass, radius : float
        Mass (kg) and radius (m) of the ball.
    inertia : float, optional
        Central moment of inertia (kg m^2); default 2/5 m r^2 (solid sphere).
    restitution : float
        Normal restitution e (1), in [0, 1].
    friction_coefficient : float
        Coulomb mu (1), >= 0.
    tangential_restitution : float
        e_t (1), in [-1, 1]: 0 = the contact point ends rolling when it sticks (pure
        Coulomb), 1 = its tangential velocity is reversed (a perfect superball).
    plane : str, ballc.Plane or 3 floats
        "floor" (normal +z), "ceiling" (normal -z), a ballc.Plane, or the plane's normal
        towards the ball (any length > 0).

    Returns
    -------
    RigidImpact
        Velocity (m/s), angular velocity (rad/s) and impulses (N s) after the impact.
    """
    v = _vector("velocity", velocity)
    w = _vector("angular_velocity", angular_velocity)
    n = _normal(plane)
    for name, value, low, high in (("mass", mass, 0, np.inf), ("radius", radius, 0, np.inf)):
        if not (np.isfinite(value) and value > low):
            raise ValueError(f"{name} = {value!r} is not allowed: must be finite and > 0")
    inertia = 0.4 * mass * radius ** 2 if inertia is None else float(inertia)
    if not (np.isfinite(inertia) and inertia > 0):
        raise ValueError(f"inertia = {inertia!r} is not allowed: must be finite and > 0")
    if not 0 <= restitution <= 1:
        raise ValueError(f"restitution = {restitution!r} is not allowed: must be in [0, 1]")
    if not friction_coefficient >= 0:
        raise ValueError(f"friction_coefficient = {friction_coefficient!r} is not allowed: "
                         "must be >= 0")
    if not -1 <= tangential_restitution <= 1:
        raise ValueError(f"tangential_restitution = {tangential_restitution!r} is not "
                         "allowed: must be in [-1, 1]")

    approach = -v @ n
    if approach <= 0:
        raise ValueError(f"velocity = {velocity!r}: the ball is not moving towards the {plane}")
    arm = -radius * n
    u = v + np.cross(w, arm)
    u = u - (u @ n) * n
    p_n = mass * (1 + restitution) * approach
    tangential_mass = 1.0 / (1.0 / mass + radius ** 2 / inertia)
    p_t = -tangential_mass * (1 + tangential_restitution) * u
    sticking = np.linalg.norm(p_t) <= friction_coefficient * p_n
    if not sticking:
        speed = np.linalg.norm(u)
        p_t = -friction_coefficient * p_n * u / speed if speed > 0 else np.zeros(3)
    impulse = p_n * n + p_t
    return RigidImpact(velocity=v + impulse / mass,
                       angular_velocity=w + np.cross(arm, p_t) / inertia,
                       normal_impulse=float(p_n), tangential_impulse=p_t,
                       sticking=bool(sticking))


def _normal(plane) -> np.ndarray:
    """The unit normal (towards the ball) of ``plane``: "floor", "ceiling", a Plane or a
    normal vector."""
    if isinstance(plane, str):
        if plane not in ("floor", "ceiling"):
            raise ValueError(f"plane = {plane!r} is not allowed: must be 'floor', 'ceiling', "
                             "a ballc.Plane or a normal (3 numbers)")
        return np.array([0.0, 0.0, 1.0 if plane == "floor" else -1.0])
    normal = getattr(plane, "normal", plane)
    n = _vector("plane's normal", normal)
    size = float(np.linalg.norm(n))
    if not size > 0:
        raise ValueError(f"plane = {plane!r} is not allowed: its normal must not be zero")
    return n / size


def hunt_crossley_restitution(c_tau: float) -> float:
    """Exit/entry speed ratio e of one Hunt-Crossley impact (no gravity, no clamp active).

    Solves a (1 + e) = ln((1 + a) / (1 - a e)), a = 3/2 (1 - c_tau): e depends on c_tau
    only, not on the speed or the stiffness.  c_tau = 1 gives e = 1.

    Parameters
    ----------
    c_tau : float
        Hunt-Crossley parameter (1), in (0, 1] (``Scene.c_tau``).

    Returns
    -------
    float
        Coefficient of restitution e = exit / entry normal speed (1).
    """
    if not 0 < c_tau <= 1:
        raise ValueError(f"c_tau = {c_tau!r} is not allowed: must be in (0, 1]")
    return _hunt_crossley_restitution_of_a(1.5 * (1 - c_tau))


#: e = 1 + a (c0 + c1 a + ... ): highest power first, for numpy.polyval.
_RESTITUTION_SERIES = [-2848 / 18225, 7648 / 42525, -40 / 189, 104 / 405, -44 / 135, 4 / 9,
                       -2 / 3]


#: Smallest restitution ballc's Hunt-Crossley bracket can give: the limit c_tau -> 0
#: (a = 3/2) of ``hunt_crossley_restitution``, about 0.4877.
def _hunt_crossley_restitution_of_a(a: float) -> float:
    """The root e of a (1 + e) - ln((1 + a) / (1 - a e)) = 0, written with log1p and
    divided by a^2 (the residual is O(a^2)); for a < 1e-2 its series, where the
    residual is lost to rounding.  Accurate to ~1e-15 for every c_tau in (0, 1]."""
    from scipy.optimize import brentq
    if a < 1e-2:   # the root's series in a (sympy, exact coefficients): error O(a^8)
        return 1.0 + float(np.polyval(_RESTITUTION_SERIES, a)) * a
    upper = min(1.0, 1.0 / a) * (1 - 1e-15)

    def residual(e):
        return (a * (1 + e) - np.log1p(a) + np.log1p(-a * e)) / (a * a)
    return brentq(residual, 1e-300, upper, xtol=1e-15, rtol=4 * np.finfo(float).eps)


MIN_HUNT_CROSSLEY_RESTITUTION = _hunt_crossley_restitution_of_a(1.5)


def c_tau_for_restitution(restitution: float) -> float:
    """The c_tau whose Hunt-Crossley impact has the exit/entry speed ratio ``restitution``.

    The inverse of :func:`hunt_crossley_restitution`: solves
    a (1 + e) = ln((1 + a) / (1 - a e)) for a, then c_tau = 1 - 2 a / 3.  The bracket
    1 + 3/2 (1 - c_tau) rhodot / rhodot^- with c_tau in (0, 1] only reaches
    e in (MIN_HUNT_CROSSLEY_RESTITUTION, 1] = (0.4877..., 1]: a smaller restitution raises
    ValueError (that damping law cannot represent it; see docs/validation.md).
    """
    from scipy.optimize import brentq
    try:
        e = float(restitution)
    except (TypeError, ValueError):
        raise ValueError(f"restitution = {restitution!r} is not allowed: must be a number "
                         "in (0.4877, 1]") from None
    if isinstance(restitution, (bool, np.bool_)) or not np.isfinite(e) or not e <= 1:
        raise ValueError(f"restitution = {restitution!r} is not allowed: must be a number "
                         f"in ({MIN_HUNT_CROSSLEY_RESTITUTION:.6g}, 1]")
    if e <= MIN_HUNT_CROSSLEY_RESTITUTION:
        raise ValueError(
            f"restitution = {restitution!r} is not allowed: ballc's Hunt-Crossley force "
            f"cannot dissipate that much (its restitution is > "
            f"{MIN_HUNT_CROSSLEY_RESTITUTION:.6g} for every c_tau in (0, 1])")
    if e == 1:
        return 1.0
    # e(a) falls monotonically from 1 (a = 0) to the minimum (a = 3/2).  Within 1e-4 of
    # e = 1 the root of the restitution equation is lost in rounding (its terms cancel
    # to O(a^3)): there c_tau is interpolated linearly, an O((1 - e)^2) ~ 1e-8 error.
    near = 1.0 - 1e-4
    if e > near:
        return 1.0 - (1.0 - e) / (1.0 - near) * (1.0 - c_tau_for_restitution(near))
    a = brentq(lambda a: _hunt_crossley_restitution_of_a(a) - e, 1e-6, 1.5,
               xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return 1.0 - a / 1.5
