"""The observer: the acceleration a sensor fixed inside the ball would feel.

The ball is rigid, so the observer point O (at ``rho`` from the centre C) moves with

    a_O = a_C + alpha x rho + omega x (omega x rho)

where a_C and the angular acceleration alpha are the time derivatives of the centre
velocity and of the angular velocity (inertial components), taken from the compiled
right-hand side at each stored sample, with the flags and latched contact values of
the segment that computed that sample (``Result.flags``/``Result.latch``).

An accelerometer does not sense gravity's free fall: it reads the *specific force*
f = a_O - g_vec with g_vec = (0, 0, -gravity).  In free flight f = omega x (omega x rho)
(zero for a non-spinning ball); resting on the floor f = (0, 0, +gravity).
"""
from __future__ import annotations

import numpy as np

from . import _core, layout
from .orientation import rotation_matrix

#: 1 g in m/s^2 (standard gravity), the unit of the specific force outputs.
STANDARD_GRAVITY = 9.80665


def state_derivatives(result) -> np.ndarray:
    """(N_STATES, n) dy/dt at every stored sample, as integrated (SI units per second)."""
    if result.flags is None or result.latch is None:
        raise ValueError("this Result has no per-sample flags/latch (made by an older ballc); "
                         "re-run the simulation to get the observer's acceleration")
    return _core.rhs_per_sample(np.ascontiguousarray(result.y.T),
                                result.scene.parameter_vector(),
                                np.ascontiguousarray(result.latch.T),
                                np.ascontiguousarray(result.flags, dtype=np.int64)).T


def observer_acceleration(result) -> np.ndarray:
    """(3, n) inertial acceleration of the observer point (m/s^2)."""
    dydt = state_derivatives(result)
    centre_acceleration = dydt[layout.VELOCITY]
    angular_acceleration = dydt[layout.ANGULAR_VELOCITY]
    omega = result.y[layout.ANGULAR_VELOCITY]
    rho = result.observer_position - result.y[layout.POSITION]
    return (centre_acceleration + np.cross(angular_acceleration, rho, axis=0)
            + np.cross(omega, np.cross(omega, rho, axis=0), axis=0))


def specific_force(result, frame: str = "inertial") -> np.ndarray:
    """(3, n) specific force on the observer in g (acceleration minus gravity).

    ``frame``: "inertial" (components along the fixed x, y, z axes) or "ball"
    (components along the ball's body axes: what a strapped-down accelerometer reads).
    """
    if frame not in ("inertial", "ball"):
        raise ValueError(f"frame = {frame!r} is not allowed: must be 'inertial' or 'ball'")
    force = observer_acceleration(result)
    force -= result.scene.gravity_vector[:, None]
    force /= STANDARD_GRAVITY
    return to_ball_frame(result, force) if frame == "ball" else force


def to_ball_frame(result, vectors) -> np.ndarray:
    """(3, n) inertial components at each sample -> the ball's body-axis components."""
    rotation = rotation_matrix(result.y[layout.QUATERNION].T)          # v_N = R v_A
    return np.einsum("nji,jn->in", rotation, vectors)                  # v_A = R^T v_N
