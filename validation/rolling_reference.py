"""LAMMPS' rolling and twisting sub-models, ``rolling sds`` and ``twisting sds``, as
LAMMPS steps them (src/GRANULAR gran_sub_mod_rolling / gran_sub_mod_twisting, the
kernels gran_rolling_sds and gran_twisting_core), for the explicit DEM oracle
(validation/dem_reference.py, ``dem_impact(rolling=..., twisting=...)``).  Nothing here
imports ballc.

In ballc's force form (docs/contact_laws.md, "Rolling resistance"): a ball of radius R
on a wall with normal n = +z (towards the ball), angular velocity omega:

* rolling velocity v_roll = R (omega x n) (LAMMPS' vrl, R_eff = R for a wall), its
  history xi (m), per step xi += v_roll dt, then the rolling force
  F_r = -k xi - gamma v_roll; when |F_r| > mu F_n (F_n: LAMMPS' Fncrit, the damped normal
  force) the history is rescaled so that the force sits at the cap:
  xi = -(mu F_n F_r/|F_r| + gamma v_roll) / k and F_r = mu F_n F_r/|F_r| (a zero
  history gives no force); the torque on the ball is R n x F_r;
* twisting velocity v_twist = R omega . n, its history xi_w += v_twist dt, the force
  F_w = -k xi_w - gamma v_twist, capped as LAMMPS caps its twisting torque (the history
  set to (mu F_n sign(v_twist) - gamma v_twist) / k, F_w = -mu F_n sign(v_twist)); the
  torque R F_w n.  (LAMMPS' twisting coefficients are these times R^2: k_twist = k R^2,
  damp = gamma R^2, mu_twist = mu R.)
"""
from __future__ import annotations

import math


def rolling_sds(history, v_roll, dt, *, k, gamma, mu, normal_force):
    """One step of LAMMPS' rolling sds: ``history`` (a 2-list, m) updated in place,
    returns the rolling force (fx, fy) (N) for the rolling velocity ``v_roll`` (2, m/s)."""
    history[0] += dt * v_roll[0]
    history[1] += dt * v_roll[1]
    fx = -k * history[0] - gamma * v_roll[0]
    fy = -k * history[1] - gamma * v_roll[1]
    cap = mu * normal_force
    size = math.hypot(fx, fy)
    if size > cap:
        if math.hypot(history[0], history[1]) != 0.0:
            history[0] = -(cap * fx / size + gamma * v_roll[0]) / k
            history[1] = -(cap * fy / size + gamma * v_roll[1]) / k
            fx, fy = cap * fx / size, cap * fy / size
        else:
            fx = fy = 0.0
    return fx, fy


def twisting_sds(history, v_twist, dt, *, k, gamma, mu, normal_force):
    """One step of LAMMPS' twisting sds in force form: ``history`` (a 1-list, m) updated
    in place, returns the twisting force (N) for the twisting velocity ``v_twist``."""
    history[0] += dt * v_twist
    force = -k * history[0] - gamma * v_twist
    cap = mu * normal_force
    sign = (v_twist > 0) - (v_twist < 0)
    if abs(force) > cap:
        history[0] = (cap * sign - gamma * v_twist) / k
        force = -cap * sign
    return force
