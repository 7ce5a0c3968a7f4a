"""The kernel families emitted to generated/: what each C function computes.

The dynamic equations ``M(q) udot = F(x)`` are split by linearity so that a scene
pays only for what acts on it:

* ``ball``      M and F of the ball alone (gravity, gyroscopic terms),
* ``observer``  the observer particle's additive share of M and F (zero when m_o = 0),
* ``<plane>_<law>`` generalized forces of one contact law on one plane
  (only called while that plane is in contact and the law has weight).

``M`` is stored as 16 numbers: the symmetric 3x3 block ``J`` (J00 J01 J02 J11 J12 J22),
the 3x3 coupling block ``B`` row-major, and the scalar ``D`` of the block ``D I3``:
``M = [[J, B], [B^T, D I3]]``.  Every value kernel has a ``_jac`` twin with the
derivatives needed by the analytic Jacobian.
"""
from __future__ import annotations

import sympy as sm
import sympy.physics.mechanics as me

from . import contact
from .emit import Kernel
from .model import PLANES, STATE_NAMES, Model, bodies, build_model, gravity_loads, kanes_equations

MASS_LAYOUT = ("J00", "J01", "J02", "J11", "J12", "J22",
               "B00", "B01", "B02", "B10", "B11", "B12", "B20", "B21", "B22", "D")
J_INDEX = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def pack_mass(M: sm.Matrix) -> list:
    """The 16 numbers of MASS_LAYOUT, after checking M has the assumed structure."""
    D = M[3, 3]
    for i in range(3):
        for j in range(3):
            expected = D if i == j else 0
            if sm.simplify(M[3 + i, 3 + j] - expected) != 0:
                raise ValueError("mass matrix: lower-right block is not D*I3")
            if sm.expand(M[3 + j, i] - M[i, 3 + j]) != 0:
                raise ValueError("mass matrix: coupling blocks are not transposes")
    J = [M[i, j] for i, j in J_INDEX]
    B = [M[i, 3 + j] for i in range(3) for j in range(3)]
    return J + B + [D]


def _zero_when(expr, symbol):
    return expr.subs(symbol, 0)


def derive(model: Model | None = None):
    """Derive everything once: returns (model, dict of sympy pieces)."""
    model = model or build_model()
    N = model.frame
    ball, observer = bodies(model)
    contact_forces = {}
    loads = gravity_loads(model, ball) + gravity_loads(model, observer)
    force_symbols = []
    for plane in PLANES:
        fs = sm.symbols(f"F_{plane}_x F_{plane}_y F_{plane}_z")
        force_symbols += fs
        point = contact.contact_point(model, plane)
        loads.append((point, fs[0]*N.x + fs[1]*N.y + fs[2]*N.z))
        contact_forces[plane] = fs
    M, F = kanes_equations(model, [ball, observer], loads)

    mo = model.p["observer_mass"]
    zero_forces = {f: 0 for f in force_symbols}
    F_free = F.xreplace(zero_forces)
    pieces = {
        "M_ball": M.subs(mo, 0), "M_observer": M - M.subs(mo, 0),
        "F_ball": F_free.subs(mo, 0), "F_observer": F_free - F_free.subs(mo, 0),
    }
    for plane in PLANES:
        G = F.jacobian(sm.Matrix(contact_forces[plane]))   # generalized-force map, 6x3
        for law, function in contact.TANGENTIAL_LAWS.items():
            point, force = function(model, plane)
            f = sm.Matrix([me.dot(force, v) for v in (N.x, N.y, N.z)])
            pieces[f"{plane}_{law}"] = G * f
    return model, pieces


def _dynamics_kernels(model, name, M, F, what):
    x = model.states
    q = model.coordinates[:4]
    a = sm.symbols("a0:6")
    mass = pack_mass(M)
    Ma = M * sm.Matrix(a)
    return [
        Kernel(name, f"{what}: mass blocks (16, MASS_LAYOUT) then forcing (6).",
               mass + list(F), []),
        Kernel(f"{name}_jac",
               f"{what}: dF/dx (6x13 row-major) then d(M a)/dq (6x4 row-major).",
               list(F.jacobian(x)) + list(Ma.jacobian(q)), list(a),
               "a (6): the vector M is multiplied with (udot)"),
    ]


def build_kernels():
    """All kernels, in emission order, and the model they came from."""
    model, pieces = derive()
    x = model.states
    kernels = [
        Kernel("kinematics", "Time derivatives of qw qx qy qz x y z (7).",
               list(model.kinematics), []),
        Kernel("kinematics_jac", "d(kinematics)/dx (7x13 row-major).",
               list(model.kinematics.jacobian(x)), []),
    ]
    kernels += _dynamics_kernels(model, "ball", pieces["M_ball"], pieces["F_ball"], "Ball")
    kernels += _dynamics_kernels(model, "observer", pieces["M_observer"],
                                 pieces["F_observer"], "Observer particle")
    for plane in PLANES:
        latch = contact.latch_symbols(model, plane)
        for law in contact.TANGENTIAL_LAWS:
            gf = pieces[f"{plane}_{law}"]
            doc = f"{plane} contact, {law} law (weighted):"
            extra_doc = "latched rhodot^-, d_x, d_y, d_z of this plane"
            kernels.append(Kernel(f"{plane}_{law}", f"{doc} generalized forces (6).",
                                  list(gf), list(latch), extra_doc))
            kernels.append(Kernel(f"{plane}_{law}_jac", f"{doc} d(generalized forces)/dx"
                                  " (6x13 row-major).", list(gf.jacobian(x)), list(latch),
                                  extra_doc))
    kernels += output_kernels(model)
    return model, kernels


def output_kernels(model: Model):
    """Energies, contact-point kinematics and observer position."""
    N = model.frame
    ball, observer = bodies(model)
    g = model.p["gravity"]
    kinetic = ball.kinetic_energy(N) + observer.kinetic_energy(N)
    potential = ball.mass*g*model.states[6] + observer.mass*g*me.dot(
        model.observer.pos_from(model.centre), N.z) + observer.mass*g*model.states[6]
    energy = [kinetic, potential] + [contact.spring_energy(model, plane) for plane in PLANES]

    kin = []
    for plane in PLANES:
        _, velocity, rho, rhodot = contact.contact_kinematics(model, plane)
        kin += [rho, rhodot] + [me.dot(velocity, v) for v in (N.x, N.y, N.z)]

    rel = model.observer.pos_from(model.centre)
    observer_position = [model.states[4 + i] + me.dot(rel, v)
                         for i, v in enumerate((N.x, N.y, N.z))]
    return [
        Kernel("energy", "Energies (J): kinetic, potential, spring floor, spring ceiling.",
               energy, []),
        Kernel("contact_kinematics", "Per plane (floor, ceiling): rho, rhodot, contact-point"
               " velocity x y z (10).", kin, []),
        Kernel("observer_position", "Observer position in N (3).", observer_position, []),
    ]


__all__ = ["MASS_LAYOUT", "STATE_NAMES", "build_kernels", "derive"]
