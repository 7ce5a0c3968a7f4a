"""Quaternions <-> the seed's body-fixed 123 angles (numpy, no sympy).

Convention: the quaternion (qw, qx, qy, qz) rotates ball-frame components into
inertial ones, ``v_N = R(q) v_A``.  The seed's ``A.orient_body_fixed(N, (q1, q2, q3),
'123')`` is ``R = Rx(q1) Ry(q2) Rz(q3)``.
"""
from __future__ import annotations

import numpy as np


def _axis_quaternion(angle, axis):
    angle = np.asarray(angle, dtype=float)
    q = np.zeros(angle.shape + (4,))
    q[..., 0] = np.cos(angle / 2)
    q[..., 1 + axis] = np.sin(angle / 2)
    return q


def quaternion_multiply(a, b):
    """Hamilton product a (x) b of (..., 4) arrays, scalar first."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    aw, av = a[..., 0], a[..., 1:]
    bw, bv = b[..., 0], b[..., 1:]
    w = aw * bw - np.sum(av * bv, axis=-1)
    ax, ay, az = av[..., 0], av[..., 1], av[..., 2]   # av x bv, as np.cross computes it
    bx, by, bz = bv[..., 0], bv[..., 1], bv[..., 2]     # (without its axis handling)
    cross = np.stack([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], axis=-1)
    v = aw[..., None] * bv + bw[..., None] * av + cross
    return np.concatenate([w[..., None], v], axis=-1)


def quaternion_from_angles_123(angles):
    """Unit quaternion(s) (..., 4) of body-fixed 123 angles (..., 3) in rad."""
    angles = np.asarray(angles, dtype=float)
    q = quaternion_multiply(_axis_quaternion(angles[..., 0], 0),
                            _axis_quaternion(angles[..., 1], 1))
    return quaternion_multiply(q, _axis_quaternion(angles[..., 2], 2))


def rotation_matrix(quaternion):
    """R (..., 3, 3) with v_N = R v_A, for quaternions of any non-zero norm."""
    q = np.asarray(quaternion, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([w*w + x*x - y*y - z*z, 2*(x*y - w*z), 2*(x*z + w*y)], axis=-1),
        np.stack([2*(x*y + w*z), w*w - x*x + y*y - z*z, 2*(y*z - w*x)], axis=-1),
        np.stack([2*(x*z - w*y), 2*(y*z + w*x), w*w - x*x - y*y + z*z], axis=-1),
    ], axis=-2)


def angles_123_from_quaternion(quaternion):
    """Body-fixed 123 angles (..., 3) in rad; q2 in [-pi/2, pi/2], q1, q3 in (-pi, pi].

    At gimbal lock (|q2| = pi/2) only q1 + q3 (or q1 - q3) is defined; q3 is then 0.
    """
    R = rotation_matrix(quaternion)
    q2 = np.arcsin(np.clip(R[..., 0, 2], -1.0, 1.0))
    locked = np.abs(R[..., 0, 2]) > 1 - 1e-12
    q1 = np.where(locked, np.arctan2(R[..., 2, 1], R[..., 1, 1]),
                  np.arctan2(-R[..., 1, 2], R[..., 2, 2]))
    q3 = np.where(locked, 0.0, np.arctan2(-R[..., 0, 1], R[..., 0, 0]))
    return np.stack([q1, q2, q3], axis=-1)
