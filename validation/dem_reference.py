"""An independent explicit DEM stepping of ballc's compliant contact law (the oracle).

A sphere (mass m, kg; isotropic inertia I, kg m^2; radius R, m) hits the floor z = 0
(normal n = +z) with no gravity.  The contact law is the one of docs/contact_laws.md,
stepped as the DEM codes step it (LAMMPS ``mindlin_rescale/force``, Kratos
``DEM_D_Hertz_viscous_Coulomb``): the stored tangential force is truncated at the
Coulomb cap after each step (no smooth yield).  Nothing here imports ballc.

Per step (dt = t_c / N, t_c Hertz's contact time) with penetration rho (m), its rate
rhodot = -v_z (m/s) and the slip velocity v_t (m/s, the in-plane part of v + omega x a,
a = -R n the arm to the contact point):

* normal, Hertz: F_H = k0 rho^(3/2), k_n = 3/2 k0 sqrt(rho) (N/m)
  - "hunt_crossley": F_n = max(0, F_H (1 + chi rhodot / |rhodot^-|)), rhodot^- the
    impact normal speed;
  - "viscoelastic":  F_n = max(0, F_H + c_n rhodot), c_n = 2 gamma sqrt(m k_n);
* tangential, incremental Mindlin, k_t = kappa k_n: if the contact unloads
  (rho < rho_prev) F_el *= k_t(rho) / k_t(rho_prev) = sqrt(rho / rho_prev); then
  F_el -= k_t v_t dt; then the Coulomb truncation F_el *= min(1, mu F_n / |F_el|)
  (the truncated force is stored);
* tangential damping: V = -c_t v_t, c_t = 2 gamma_t sqrt(m k_t), only with the capacity
  the elastic force leaves: alpha = min(1, max(0, mu F_n - |F_el|) / |V|),
  F_t = F_el + alpha V (so |F_t| <= mu F_n);
* rolling and twisting (optional, ``rolling`` / ``twisting``): LAMMPS' rolling sds and
  twisting sds (validation/rolling_reference.py) on F_n, their torques R n x F_r and
  R F_w n;
* motion: m dv/dt = F_n n + F_t, I domega/dt = a x F_t (+ the rolling and twisting
  torques), velocity Verlet with the forces at step n+1 taken from the position at n+1
  and the half-step velocities (as LAMMPS).

The run starts at first touch (rho = 0) and stops when rho <= 0 again.
"""
from __future__ import annotations

import math

import numpy as np

from .rolling_reference import rolling_sds, twisting_sds

#: Hertz's elastic impact lasts t_c = HERTZ_TIME_CONSTANT (m / k0)^(2/5) v^(-1/5):
#: with rho_max = (5 m v^2 / (4 k0))^(2/5),
#: t_c = 2 rho_max / v * int_0^1 dx / sqrt(1 - x^(5/2)) and the integral is
#: (2/5) B(2/5, 1/2) = (2/5) sqrt(pi) Gamma(2/5) / Gamma(9/10), so the constant is
#: (4/5) (5/4)^(2/5) sqrt(pi) Gamma(2/5) / Gamma(9/10) = 3.21807 (the often quoted
#: "2.87 (m^2 / (R E*^2 v))^(1/5)" is the same with k0 = 4/3 sqrt(R) E*, rounded).
HERTZ_TIME_CONSTANT = (0.8 * 1.25 ** 0.4 * math.sqrt(math.pi)
                       * math.gamma(0.4) / math.gamma(0.9))


def hertz_contact_time(mass, k0, speed):
    """Duration (s) of the elastic Hertz impact m rho'' = -k0 rho^(3/2) at normal
    ``speed`` (m/s); mass in kg, k0 in N/m^(3/2)."""
    return HERTZ_TIME_CONSTANT * (mass / k0) ** 0.4 * speed ** -0.2


def dem_impact(*, mass, radius, inertia, k0, kappa, mu, velocity,
               angular_velocity=(0.0, 0.0, 0.0), normal_damping="hunt_crossley",
               chi=0.0, gamma=0.0, gamma_t=0.0, steps_per_contact=20000,
               midpoint_stiffness=False, rolling=None, twisting=None):
    """One impact on the floor, stepped explicitly; see the module docstring.

    Parameters: mass m* (kg), radius R (m), inertia I (kg m^2, scalar), k0 (N/m^1.5),
    kappa = k_t / k_n (1), mu (1), velocity and angular_velocity at first touch (m/s,
    rad/s; velocity[2] < 0), normal_damping "hunt_crossley" (uses chi) or "viscoelastic"
    (uses gamma), gamma_t the tangential damping ratio, steps_per_contact N
    (dt = hertz_contact_time / N).  ``midpoint_stiffness``: while the contact loads, take
    the k_t of the increment F_el -= k_t v_t dt at the step's mean penetration instead of
    the new one (the DEM codes'); the same law, but second order instead of first in the
    sticking phase (about 100 times smaller errors at the same N for high mu).
    ``rolling``, ``twisting``: None, or dict(k=N/m, gamma=N s/m, mu=1) of LAMMPS' rolling
    sds / twisting sds in force form (validation/rolling_reference.py).

    Returns a dict: velocity_after, angular_velocity_after (3-arrays), contact_time (s,
    rho's zero crossing interpolated linearly), max_penetration (m, sampled at the
    steps), dissipated (J, kinetic energy before - after), normal_impulse,
    tangential_impulse (N s, 3-arrays), dt (s), steps.
    """
    if normal_damping not in ("hunt_crossley", "viscoelastic"):
        raise ValueError(f"normal_damping {normal_damping!r}: 'hunt_crossley' or "
                         "'viscoelastic'")
    v = [float(c) for c in velocity]
    w = [float(c) for c in angular_velocity]
    if not v[2] < 0:
        raise ValueError(f"velocity[2] = {v[2]}: the ball must approach the floor")
    speed_in = -v[2]
    dt = hertz_contact_time(mass, k0, speed_in) / steps_per_contact
    hm, hI, R = 0.5 * dt / mass, 0.5 * dt / inertia, radius
    hc = normal_damping == "hunt_crossley"
    v0, w0 = np.array(v), np.array(w)

    rho = rho_prev = rho_max = 0.0
    fx = fy = 0.0                      # stored elastic tangential force F_el (N)
    Fx = Fy = Fz = 0.0                 # total force on the ball at the current step (N)
    Tx = Ty = Tz = 0.0                 # rolling and twisting torques at that step (N m)
    roll_history, twist_history = [0.0, 0.0], [0.0]
    steps, max_steps = 0, 100 * steps_per_contact
    while True:
        # half kick (torque = a x F_t with a = (0, 0, -R): (R Fy, -R Fx, 0)), drift
        v[0] += hm * Fx; v[1] += hm * Fy; v[2] += hm * Fz
        w[0] += hI * R * Fy + hI * Tx; w[1] -= hI * R * Fx - hI * Ty; w[2] += hI * Tz
        rho_prev, rho = rho, rho - dt * v[2]
        steps += 1
        if rho <= 0.0:                 # contact over; no force at this step
            contact_time = (steps - 1 + rho_prev / (rho_prev - rho)) * dt
            break
        if steps > max_steps:
            raise RuntimeError(f"contact did not end within {max_steps} steps")
        rho_max = max(rho_max, rho)
        rhodot = -v[2]
        # normal force
        sq = math.sqrt(rho)
        FH = k0 * rho * sq
        if hc:
            Fn = FH * (1.0 + chi * rhodot / speed_in)
        else:
            Fn = FH + 2.0 * gamma * math.sqrt(mass * 1.5 * k0 * sq) * rhodot
        Fn = max(Fn, 0.0)
        # tangential: slip velocity v + w x a, a = (0, 0, -R)
        ux, uy = v[0] - R * w[1], v[1] + R * w[0]
        kt = kappa * 1.5 * k0 * sq
        if rho < rho_prev:
            scale = math.sqrt(rho / rho_prev)
            fx *= scale; fy *= scale
        kdt = dt * (kappa * 1.5 * k0 * math.sqrt(0.5 * (rho + rho_prev))
                    if midpoint_stiffness and rho >= rho_prev else kt)
        fx -= kdt * ux; fy -= kdt * uy
        cap = mu * Fn
        fel = math.hypot(fx, fy)
        if fel > cap:
            fx *= cap / fel; fy *= cap / fel
            fel = cap
        ct = 2.0 * gamma_t * math.sqrt(mass * kt)
        vis = ct * math.hypot(ux, uy)
        alpha = min(1.0, (cap - fel) / vis) if vis > 0.0 else 0.0
        Fx, Fy, Fz = fx - alpha * ct * ux, fy - alpha * ct * uy, Fn
        Tx = Ty = Tz = 0.0
        if rolling is not None:   # v_roll = R (omega x n), torque R n x F_r
            frx, fry = rolling_sds(roll_history, (R * w[1], -R * w[0]), dt, normal_force=Fn,
                                   **rolling)
            Tx, Ty = -R * fry, R * frx
        if twisting is not None:   # v_twist = R omega . n, torque R F_w n
            Tz = R * twisting_sds(twist_history, R * w[2], dt, normal_force=Fn, **twisting)
        # second half kick
        v[0] += hm * Fx; v[1] += hm * Fy; v[2] += hm * Fz
        w[0] += hI * R * Fy + hI * Tx; w[1] -= hI * R * Fx - hI * Ty; w[2] += hI * Tz

    v1, w1 = np.array(v), np.array(w)
    kinetic = lambda vv, ww: 0.5 * mass * vv @ vv + 0.5 * inertia * ww @ ww  # noqa: E731
    impulse = mass * (v1 - v0)
    return dict(velocity_after=v1, angular_velocity_after=w1, contact_time=contact_time,
                max_penetration=rho_max, dissipated=kinetic(v0, w0) - kinetic(v1, w1),
                normal_impulse=np.array([0.0, 0.0, impulse[2]]),
                tangential_impulse=np.array([impulse[0], impulse[1], 0.0]),
                dt=dt, steps=steps)


def rebound_difference(a, b, radius, speed):
    """max |difference| of two rebounds' centre velocities and angular velocities times
    the radius (m/s), divided by ``speed`` (1)."""
    dv = np.abs(a["velocity_after"] - b["velocity_after"])
    dw = np.abs(a["angular_velocity_after"] - b["angular_velocity_after"]) * radius
    return float(max(dv.max(), dw.max()) / speed)


def dem_impact_converged(*, rel_tol=1e-4, steps_per_contact=2000, max_steps_per_contact=
                         2 ** 21, **kwargs):
    """:func:`dem_impact` at N, 2N, 4N, ... (N = ``steps_per_contact``) until two
    successive rebounds agree to ``rel_tol`` of the impact speed (the centre velocity
    and omega R, every component; the difference estimates the finer run's error: it
    equals it for first-order convergence, three times it for second-order).

    Returns the finer run's dict plus ``error_estimate`` (that difference / speed, 1) and
    ``steps_per_contact``.  RuntimeError if N would exceed ``max_steps_per_contact``.
    An estimate, not a bound: over 90 random oblique spinning impacts at rel_tol 1e-5 the
    error against a 16 times finer run reached 1.2 times it (viscoelastic damping, whose
    c_n ~ rho^(1/4) makes the convergence irregular).  ``kwargs`` go to dem_impact.
    """
    speed = float(np.linalg.norm(kwargs["velocity"]))
    n = steps_per_contact
    coarse = dem_impact(steps_per_contact=n, **kwargs)
    while 2 * n <= max_steps_per_contact:
        n *= 2
        fine = dem_impact(steps_per_contact=n, **kwargs)
        diff = rebound_difference(coarse, fine, kwargs["radius"], speed)
        if diff <= rel_tol:
            return dict(fine, error_estimate=diff, steps_per_contact=n)
        coarse = fine
    raise RuntimeError(f"no convergence to {rel_tol:g} of the impact speed with up to "
                       f"{max_steps_per_contact} steps per contact (last difference "
                       f"{diff:.3g})")
