"""The kernel families emitted to generated/: what each C function computes.

The dynamic equations ``M(q) udot = F(x)`` are split by linearity so that a scene
pays only for what acts on it:

* ``ball``      M and F of the ball alone (gravity, gyroscopic terms),
* ``observer``  the observer particle's additive share of M and F (zero when m_o = 0),
* ``plane_<law>`` generalized forces of one contact law on a plane, in the plane's own
  frame (model.FRAME_PLANE), of the contact state (model.CONTACT_STATE_NAMES): the C
  core turns each plane's contact into that frame, calls the kernel and turns the
  forces back (src/ballc/_plane.c), only while that plane is in contact and the law
  has weight,
* ``plane_friction_normal`` the friction law with mu = 0: its normal share, which is
  all exact (event-driven) Coulomb friction takes from it.

Every ``plane_*`` kernel reads the contact state of one plane (its ``state`` argument)
and the plane's inputs (``extra``: model.PLANE_INPUT_NAMES); a contact law that depends
on anything else of the state (the orientation, the position along the plane) is
refused when generated (contact_state).

``M`` is stored as 16 numbers: the symmetric 3x3 block ``J`` (J00 J01 J02 J11 J12 J22),
the 3x3 coupling block ``B`` row-major, and the scalar ``D`` of the block ``D I3``:
``M = [[J, B], [B^T, D I3]]``.  Every value kernel has a ``_jac`` twin with the
derivatives needed by the analytic Jacobian.
"""
from __future__ import annotations

import random

import sympy as sm
import sympy.physics.mechanics as me
from sympy.core.function import AppliedUndef

from . import contact
from .emit import Kernel, forward_jacobian, plain_symbols
from .model import (BALL_STATE_NAMES, CONTACT_STATE, FRAME_PLANE, STATE_NAMES, Model, bodies,
                    build_model, gravity_loads, gravity_vector, kanes_equations,
                    quaternion_dcm)

MASS_LAYOUT = ("J00", "J01", "J02", "J11", "J12", "J22",
               "B00", "B01", "B02", "B10", "B11", "B12", "B20", "B21", "B22", "D")
J_INDEX = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
#: Outputs of every contact-law kernel, in order.
#: (C macro suffix, description, count): BALLC_LAW_<suffix> is the offset of each block.
CONTACT_LAW_LAYOUT = (("GENERALIZED_FORCE", "generalized force", 6),
                      ("FORCE", "force on the ball at the contact point", 3),
                      ("DISSIPATION", "dissipation rate normal, tangential", 2),
                      ("DEFLECTION_RATE", "deflection rate x, y", 2))


def contact_law_offsets():
    """[(macro suffix, offset)] of the blocks of CONTACT_LAW_LAYOUT."""
    offsets, offset = [], 0
    for suffix, _, count in CONTACT_LAW_LAYOUT:
        offsets.append((suffix, offset))
        offset += count
    return offsets


def describe_contact_law_layout():
    return ", ".join(f"{what} ({count})" for _, what, count in CONTACT_LAW_LAYOUT)


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


def _law_outputs(model, plane, force_map, law):
    """A contact law's kernel outputs (CONTACT_LAW_LAYOUT) on ``plane``."""
    N = model.frame
    f = sm.Matrix([me.dot(law.force, v) for v in (N.x, N.y, N.z)])
    dissipation = contact.dissipation_rates(model, plane, law)
    deflection = law.deflection_rate or [0, 0]
    return sm.Matrix([*(force_map * f), *f, *dissipation, *deflection])


def derive(model: Model | None = None):
    """Derive everything once: returns (model, dict of sympy pieces).  The contact laws
    are derived on the plane of model.FRAME_PLANE (a plane's own frame) only."""
    model = model or build_model()
    N = model.frame
    ball, observer = bodies(model)
    loads = gravity_loads(model, ball) + gravity_loads(model, observer)
    plane = FRAME_PLANE
    force_symbols = sm.symbols("F_contact_x F_contact_y F_contact_z")
    point = contact.contact_point(model, plane)
    loads.append((point, sum((f*v for f, v in zip(force_symbols, (N.x, N.y, N.z))),
                             me.Vector(0))))
    M, F = kanes_equations(model, [ball, observer], loads)

    mo = model.p["observer_mass"]
    F_free = F.xreplace({f: 0 for f in force_symbols})
    pieces = {
        "M_ball": M.subs(mo, 0), "M_observer": M - M.subs(mo, 0),
        "F_ball": F_free.subs(mo, 0), "F_observer": F_free - F_free.subs(mo, 0),
    }
    G = F.jacobian(sm.Matrix(force_symbols))   # generalized-force map, 6x3
    pieces["force_map"] = G
    for name, function in contact.TANGENTIAL_LAWS.items():
        pieces[name] = _law_outputs(model, plane, G, function(model, plane))
        if name in contact.JACOBIAN_FORMS:
            form = contact.JACOBIAN_FORMS[name](model, plane)
            pieces[f"{name}_jacobian_form"] = _law_outputs(model, plane, G, form)
            pieces[f"{name}_frozen"] = form.frozen or []
    pieces["friction_normal"] = _law_outputs(
        model, plane, G, contact.compose(model, plane, contact.COMPOSITIONS["friction_normal"]))
    return model, pieces


#: The plain symbols of the contact state (model.CONTACT_STATE_NAMES), in its order.
CONTACT_STATE_SYMBOLS = [sm.Symbol(local) for _, local in CONTACT_STATE]


def contact_state(model: Model, expressions, what):
    """``expressions`` (of the model's state) as expressions of the contact state
    (CONTACT_STATE_SYMBOLS): FRAME_PLANE's centre height, angular velocity, velocity and
    deflection renamed.  Raises if one depends on any other state -- the quaternion (a
    sphere's contact cannot depend on its orientation), the position along the plane,
    the dissipated work or another plane's deflection -- which the C core does not turn
    into the plane's frame."""
    rename = {model.state(name): symbol for (name, _), symbol in
              zip(CONTACT_STATE, CONTACT_STATE_SYMBOLS)}
    result = [sm.sympify(e).xreplace(rename) for e in expressions]
    others = set(model.states) - set(rename)
    found = sorted({str(s.func) for e in result for s in e.atoms(AppliedUndef)
                    if s in others})
    if found:
        raise ValueError(f"{what} depends on {', '.join(found)}: a contact law may depend "
                         "only on the contact state in its plane's frame "
                         f"({', '.join(map(str, CONTACT_STATE_SYMBOLS))})")
    return result


def plane_inputs(model: Model):
    """The symbols of a plane kernel's ``extra`` (model.PLANE_INPUT_NAMES): the plane's
    latched values, then gravity's component into the plane."""
    return [*contact.latch_symbols(model, FRAME_PLANE), contact.gravity_into_plane(FRAME_PLANE)]


def jacobian_kernel(model, name, doc, outputs, extra=(), extra_doc="", prefix="j", frozen=(),
                    state=None):
    """Kernel of d(outputs)/d(state), row-major, by forward_jacobian.  ``frozen``:
    [(symbol, expression)] computed first and differentiated as constants.  ``state``:
    the symbols of the kernel's state (a plane kernel's contact state); by default the
    model's state, differentiated by the ball's states only (BALL_STATE_NAMES: nothing
    of the ball's dynamics depends on a plane's deflection, and a run's planes are known
    at run time only; the C core places the columns)."""
    if state is None:
        states = plain_symbols(model.states)
        replacements = dict(zip(model.states, states))
        variables = states[:len(BALL_STATE_NAMES)]
        others = set(states) - set(variables)
        if any(sm.sympify(e).xreplace(replacements).has(*others) for e in outputs):
            raise ValueError(f"{name}: the ball's dynamics depend on a plane's state")
    else:
        states, replacements = list(state), {}
        variables = states
    outputs = [sm.sympify(e).xreplace(replacements) for e in outputs]
    leading = [(symbol, sm.sympify(e).xreplace(replacements)) for symbol, e in frozen]
    definitions, jac = forward_jacobian(outputs, variables, prefix)
    return Kernel(name, doc, jac, list(extra), extra_doc, leading + definitions, state)


def _dynamics_kernels(model, name, M, F, what):
    n = len(BALL_STATE_NAMES)
    a = sm.symbols("a0:6")
    mass = pack_mass(M)
    Ma = M * sm.Matrix(a)
    # d(M a)/dq is only needed for the 4 quaternion components: take the first 4
    # columns of the full Jacobian of M a.
    dF = jacobian_kernel(model, f"{name}_jac", "", list(F), prefix="f")
    dMa = jacobian_kernel(model, f"{name}_jac", "", list(Ma), prefix="m")
    dMa_q = [dMa.outputs[i * n + k] for i in range(6) for k in range(4)]
    return [
        Kernel(name, f"{what}: mass blocks (16, MASS_LAYOUT) then forcing (6).",
               mass + list(F), []),
        Kernel(f"{name}_jac",
               f"{what}: dF/d(the ball's states) (6x{n} row-major) then d(M a)/dq (6x4 "
               "row-major).",
               dF.outputs + dMa_q, list(a), "a (6): the vector M is multiplied with (udot)",
               dF.definitions + dMa.definitions),
    ]


def build_kernels():
    """All kernels, in emission order, and the model they came from."""
    model, pieces = derive()
    kernels = [
        Kernel("kinematics", "Time derivatives of qw qx qy qz x y z (7).",
               list(model.kinematics), []),
        jacobian_kernel(model, "kinematics_jac", "d(kinematics)/d(the ball's states) "
                        f"(7x{len(BALL_STATE_NAMES)} row-major).", list(model.kinematics)),
    ]
    kernels += _dynamics_kernels(model, "ball", pieces["M_ball"], pieces["F_ball"], "Ball")
    value, M_offset, F_offset = observer_value_kernel(model, pieces)
    jac = _dynamics_kernels(model, "observer", M_offset, F_offset, "Observer particle")[1]
    kernels += [value, jac]
    kernels += plane_kernels(model, pieces)
    kernels += output_kernels(model)
    return model, kernels


def plane_kernels(model: Model, pieces: dict):
    """The kernels of one plane's contact, in its own frame (model.FRAME_PLANE): each
    law, its Jacobian (d/d contact state) and, for ACCELERATION_LAWS, its rates'
    coefficients of rho''; the friction law's normal share; the slip kernel; the
    compliant law's mode guards; the contact's energies and kinematics."""
    plane = FRAME_PLANE
    state = CONTACT_STATE_SYMBOLS
    n = len(state)
    inputs = plane_inputs(model)
    extra_doc = ("the plane's latched rhodot^-, d_x, d_y, d_z (its frame), slip direction "
                 "(2), gravity into the plane -n . g")
    kernels = []

    def local(expressions, name):
        return contact_state(model, expressions, f"plane kernel {name}")

    def law_kernels(law, doc):
        outputs = pieces[law]
        name = f"plane_{law}"
        if law in contact.ACCELERATION_LAWS:
            outputs, coefficients = split_acceleration(outputs, plane)
            kernels.append(Kernel(
                f"{name}_acceleration", f"{doc} the coefficients of the exact "
                "penetration acceleration rho'' in its dissipation rates (normal, "
                "tangential) and deflection rates (x, y) (4); the value kernel's are "
                "at rho'' = 0.", local(coefficients, name), inputs, extra_doc, state=state))
        kernels.append(Kernel(name, f"{doc} {describe_contact_law_layout()}.",
                              local(outputs, name), inputs, extra_doc, state=state))
        form = pieces.get(f"{law}_jacobian_form", outputs)
        note = "" if form is outputs else " (of the law's Jacobian form, " \
            "contact.JACOBIAN_FORMS)"
        frozen = pieces.get(f"{law}_frozen", ())
        frozen = list(zip([s for s, _ in frozen], local([e for _, e in frozen], name)))
        kernels.append(jacobian_kernel(model, f"{name}_jac", f"{doc} d(outputs)/d(contact "
                                       f"state) ({len(outputs)}x{n} row-major){note}.",
                                       local(form, name), inputs, extra_doc, frozen=frozen,
                                       state=state))

    for law in contact.TANGENTIAL_LAWS:
        law_kernels(law, f"A plane's contact in its own frame, {law} law (weighted):")
    # Exact (event-driven) Coulomb friction applies the tangential force itself and
    # takes only the friction law's normal share: its composition with no tangential
    # part (contact.COMPOSITIONS), the law with mu = 0, without the regularised
    # Coulomb part's two square roots and division.
    law_kernels("friction_normal", "A plane's contact in its own frame, friction law with "
                "mu = 0 (its normal share, weighted):")
    kernels += slip_kernels(model, plane, pieces["force_map"])
    kernels += rolling_kernels(model, plane, inputs, extra_doc)
    kernels += sds_kernels(model, plane, inputs, extra_doc)
    margins = contact.compliant_margins(model, plane)
    accel = contact.penetration_acceleration(plane)
    restick = _affine_coefficient(margins[1], accel, "the re-stick margin")
    kernels.append(Kernel(
        "plane_compliant_margins",
        "A plane's contact in its own frame, the compliant law's mode guards "
        "(contact.compliant_margins): yield margin 1 - k_t |s| / (mu F_n), re-stick margin "
        "(m/s) at rho'' = 0, s_cap = mu F_n / k_t (m), k_t (N/m), the elastic mode's "
        "capacity margin (N) and its negative, and the re-stick margin's coefficient of the "
        "exact penetration acceleration rho'' (s).",
        local([margins[0], margins[1].xreplace({accel: 0}), margins[2], margins[3],
               margins[4], -margins[4], restick], "plane_compliant_margins"),
        inputs, extra_doc, state=state))
    _, velocity, rho, rhodot = contact.contact_kinematics(model, plane)
    N = model.frame
    kernels.append(Kernel(
        "plane_energy", "A plane's contact: the Hertz spring's energy 2/5 k0 rho^(5/2) and "
        "the compliant law's tangential spring's 1/2 k_t |s|^2 (J).",
        local([contact.spring_energy(model, plane),
               contact.tangential_spring_energy(model, plane)], "plane_energy"),
        [], state=state))
    kernels.append(Kernel(
        "plane_rolling_energy", "A plane's contact: the energy of the rolling part's sds "
        "springs, 1/2 k_r |xi_roll|^2 + 1/2 k_w xi_twist^2 (J).",
        local([contact.rolling_spring_energy(model, plane)], "plane_rolling_energy"), [],
        state=state))
    kernels.append(Kernel(
        "plane_kinematics", "A plane's contact: rho, rhodot, the contact point's velocity "
        "in the plane's frame (3).",
        local([rho, rhodot] + [me.dot(velocity, v) for v in (N.x, N.y, N.z)],
              "plane_kinematics"), [], state=state))
    return kernels


def _affine_coefficient(expression, symbol, what):
    """d(expression)/d(symbol), checked to be free of the symbol (affine)."""
    coefficient = sm.sympify(expression).diff(symbol)
    if coefficient.has(symbol):
        raise ValueError(f"{what} is not affine in {symbol}")
    return coefficient


def split_acceleration(outputs, plane):
    """A contact law's outputs at rho'' = 0, and the coefficients of rho'' in its
    dissipation and deflection rates (4): the law's rates are affine in it, its forces
    free of it (checked)."""
    accel = contact.penetration_acceleration(plane)
    offsets = dict(contact_law_offsets())
    first = offsets["DISSIPATION"]
    for i in range(first):
        if sm.sympify(outputs[i]).has(accel):
            raise ValueError(f"{plane}: a contact force depends on {accel}")
    coefficients = [_affine_coefficient(outputs[i], accel, f"{plane} law output {i}")
                    for i in range(first, first + 4)]
    return sm.Matrix([sm.sympify(o).xreplace({accel: 0}) for o in outputs]), coefficients


def observer_by_offset(model: Model):
    """The observer's share of M and F in terms of its offset from the centre.

    The same particle, derived again by KanesMethod, but placed at C + p with p =
    (p_x, p_y, p_z) in N given as symbols: fixed in the ball, its velocity is
    v_C + w x p and its acceleration a_C + dw/dt x p + w x (w x p).  The quaternion
    then enters only through p = r R(q) (alpha, beta, gamma), which the kernel
    computes first, instead of through every entry of M and F.
    Returns (offset symbols, their expressions in the state, M (6x6), F (6)).
    """
    N, A = model.frame, model.ball_frame
    offset_symbols = sm.symbols("observer_offset_x observer_offset_y observer_offset_z")
    offset = sum((s * v for s, v in zip(offset_symbols, (N.x, N.y, N.z))), me.Vector(0))
    w = A.ang_vel_in(N)
    point = me.Point("P_o_offset")
    point.set_vel(N, model.centre.vel(N) + me.cross(w, offset))
    point.set_acc(N, model.centre.acc(N) + me.cross(A.ang_acc_in(N), offset)
                  + me.cross(w, me.cross(w, offset)))
    particle = me.Particle("observer_at_offset", point, model.p["observer_mass"])
    M, F = kanes_equations(model, [particle], gravity_loads(model, particle))
    relative = model.observer.pos_from(model.centre)
    expressions = [me.dot(relative, v) for v in (N.x, N.y, N.z)]
    return offset_symbols, expressions, M, F


def observer_value_kernel(model: Model, pieces: dict):
    """The observer's value kernel in the offset form (observer_by_offset), checked
    against the pieces of the whole system's KanesMethod at random points; also M and F
    of that form with p written out in the state (for the Jacobian kernel, whose
    forward-mode differentiation then goes through p)."""
    offset_symbols, expressions, M, F = observer_by_offset(model)
    outputs = pack_mass(M) + list(F)
    # p = R(q) c with R of a quaternion of any norm: (unnormalised R) c / |q|^2, one
    # division (c = r (alpha, beta, gamma) is parameter-only: hoisted by emit)
    qw, qx, qy, qz = model.coordinates[:4]
    inverse_norm2 = sm.Symbol("observer_inverse_norm2")
    unnormalised = quaternion_dcm(qw, qx, qy, qz) * (qw**2 + qx**2 + qy**2 + qz**2)
    p = model.p
    c = sm.Matrix([p["radius"] * p[f"observer_{k}"] for k in ("alpha", "beta", "gamma")])
    definitions = [(inverse_norm2, 1 / (qw**2 + qx**2 + qy**2 + qz**2))]
    definitions += [(s, inverse_norm2 * sm.expand(e))
                    for s, e in zip(offset_symbols, unnormalised * c)]
    for (s, e), relative in zip(definitions[1:], expressions):   # the same offset
        _check_same(model, [e.xreplace({inverse_norm2: definitions[0][1]})], [relative],
                    "observer offset")
    substitute = {s: e.xreplace({inverse_norm2: definitions[0][1]}) for s, e in definitions[1:]}
    whole = pack_mass(pieces["M_observer"]) + list(pieces["F_observer"])
    _check_same(model, [o.xreplace(substitute) for o in outputs], whole,
                "observer kernel (offset form)")
    states = plain_symbols(model.states)
    replacements = dict(zip(model.states, states))
    definitions = [(s, sm.sympify(e).xreplace(replacements)) for s, e in definitions]
    kernel = Kernel("observer", "Observer particle (from its offset p = r R(q) (alpha, "
                    "beta, gamma), computed first): mass blocks (16, MASS_LAYOUT) then "
                    "forcing (6).", [sm.sympify(o).xreplace(replacements) for o in outputs],
                    [], definitions=definitions)
    return kernel, M.xreplace(substitute), F.xreplace(substitute)


def _check_same(model: Model, ours, theirs, what, samples=5, seed=20261123):
    """Raise unless two lists of expressions agree at random states and parameters."""
    rng = random.Random(seed)
    for _ in range(samples):
        values = {s: sm.Float(rng.uniform(0.2, 1.5), 30) for s in model.parameters}
        values.update({s: sm.Float(rng.uniform(-1.5, 1.5), 30) for s in model.states})
        for a, b in zip(ours, theirs):
            va = sm.sympify(a).xreplace(values).evalf(30)
            vb = sm.sympify(b).xreplace(values).evalf(30)
            if abs(va - vb) > 1e-20 * (1 + abs(vb)):
                raise ValueError(f"{what}: {va} != {vb} at a random point")


def slip_kernels(model: Model, plane: str, force_map: sm.Matrix):
    """What exact (event-driven) Coulomb friction needs on a plane, in its own frame:
    two kernels.

    ``plane_slip``: the slip velocity u (2: its components along the plane's tangents
    t1, t2).  ``plane_slip_map``: its derivative du/d(contact state) (2 x
    N_CONTACT_STATES row-major) and the generalized-force map of a tangential force at
    the contact point (6 x 2 row-major: columns for a unit force along t1 and t2, torque
    and force in the plane's frame) -- constants (u is linear in the contact state:
    checked), which the C core turns into a plane's maps by the ball's state once per
    parameter vector.  The driver's stick constraint force and the sliding Coulomb force
    are applied through these maps, so the mechanics of where a contact force acts stay
    derived here.
    """
    _, _, _, slip = contact.slip_kinematics(model, plane)
    slip = contact_state(model, slip, "the slip velocity")
    derivative = [u.diff(x) for u in slip for x in CONTACT_STATE_SYMBOLS]
    tangential_map = contact_state(model, [force_map[i, k] for i in range(6) for k in range(2)],
                                   "the force map")
    constant = derivative + tangential_map
    if any(sm.sympify(e).has(*CONTACT_STATE_SYMBOLS) for e in constant):
        raise ValueError("the slip velocity is not linear in the contact state, or the "
                         "force map depends on it: plane_slip_map would not be constant")
    return [
        Kernel("plane_slip", "A plane's contact in its own frame: slip velocity u (2).",
               slip, [], state=CONTACT_STATE_SYMBOLS),
        Kernel("plane_slip_map", "A plane's contact in its own frame, constants: "
               f"du/d(contact state) (2x{len(CONTACT_STATE_SYMBOLS)} row-major), "
               "generalized-force map of a tangential force at the contact point "
               "(6x2 row-major).", constant, [], state=CONTACT_STATE_SYMBOLS),
    ]


def rolling_kernels(model: Model, plane: str, inputs, extra_doc):
    """What the rolling part (contact.rolling_velocities, rolling_torque, rolling_load)
    needs on a plane, in its own frame: three kernels.

    ``plane_rolling``: the rolling velocity (2, along t1, t2), the twisting velocity and
    the normal force F_n that caps their torques; ``plane_rolling_jac`` its derivative
    d/d(contact state) (4 x N_CONTACT_STATES), whose last row is dF_n/d(contact state)
    (the exact rolling torque's Jacobian).  ``plane_rolling_map``: constants (the
    velocities are linear in the contact state: checked) -- their derivative (3 x
    N_CONTACT_STATES row-major) and the generalized-force map of a unit rolling force
    along t1, t2 and a unit twisting force (6 x 3 row-major: the torque r n x F_r,
    r F_w n in the plane's frame, no force), which the C core turns into a plane's maps
    once per parameter vector, as the slip maps.  The exact rolling and twisting
    torques and their holding constraint are applied through these maps
    (src/ballc/_rolling.c), so where they act stays derived here.
    """
    N = model.frame
    velocities = contact_state(model, contact.rolling_velocities(model, plane),
                               "the rolling velocities")
    load = contact_state(model, [contact.rolling_load(model, plane)], "the rolling load")
    derivative = [v.diff(x) for v in velocities for x in CONTACT_STATE_SYMBOLS]
    partials = me.partial_velocity([model.ball_frame.ang_vel_in(N)], model.speeds, N)[0]
    units = [contact.rolling_torque(model, plane, [1, 0], 0),
             contact.rolling_torque(model, plane, [0, 1], 0),
             contact.rolling_torque(model, plane, [0, 0], 1)]
    torque_map = contact_state(model, [me.dot(unit, partial) for partial in partials
                                       for unit in units], "the rolling force map")
    constant = derivative + torque_map
    if any(sm.sympify(e).has(*CONTACT_STATE_SYMBOLS) for e in constant):
        raise ValueError("the rolling velocities are not linear in the contact state, or "
                         "their force map depends on it: plane_rolling_map would not be "
                         "constant")
    n = len(CONTACT_STATE_SYMBOLS)
    outputs = velocities + load
    return [
        Kernel("plane_rolling", "A plane's contact in its own frame: the rolling velocity "
               "r (omega x n) (2), the twisting velocity r omega . n and the normal force "
               "F_n that caps their torques (contact.rolling_load).", outputs, inputs,
               extra_doc, state=CONTACT_STATE_SYMBOLS),
        jacobian_kernel(model, "plane_rolling_jac", "A plane's contact in its own frame: "
                        f"d(plane_rolling)/d(contact state) ({len(outputs)}x{n} row-major).",
                        outputs, inputs, extra_doc, state=CONTACT_STATE_SYMBOLS),
        Kernel("plane_rolling_map", "A plane's contact in its own frame, constants: "
               f"d(rolling and twisting velocities)/d(contact state) (3x{n} row-major), "
               "generalized-force map of a unit rolling force along t1, t2 and a unit "
               "twisting force (6x3 row-major).", constant, [],
               state=CONTACT_STATE_SYMBOLS),
    ]


def _generalized_torque(model: Model, torque):
    """The generalized forces (6) of a torque on the ball (N m): its dot products with
    the ball's partial angular velocities."""
    N = model.frame
    partials = me.partial_velocity([model.ball_frame.ang_vel_in(N)], model.speeds, N)[0]
    return [me.dot(torque, partial) for partial in partials]


def sds_outputs(model: Model, plane: str, part: str, force, rate, dissipation):
    """An sds kernel's outputs (SDS_LAYOUT): the generalized force of the part's torque
    (6, the plane's frame), its dissipation rate (1) and the rates of the plane's three
    rolling spring states (the other part's 0)."""
    first, count = contact.ROLLING_PARTS[part]
    rolling_force, twisting_force = contact._part_forces(part, force)
    torque = contact.rolling_torque(model, plane, rolling_force, twisting_force)
    rates = [0, 0, 0]
    rates[first:first + count] = rate
    return _generalized_torque(model, torque) + [dissipation] + rates


#: An sds kernel's outputs: generalized force (6), dissipation rate (1), rates of the
#: rolling spring states rolling_x, rolling_y, twisting (3).
SDS_LAYOUT = (("GENERALIZED_FORCE", 6), ("DISSIPATION", 1), ("SPRING_RATE", 3))


def sds_kernels(model: Model, plane: str, inputs, extra_doc):
    """The rolling part's sds model on a plane, in its own frame, per part (rolling,
    twisting): ``plane_<part>_spring`` (below the cap) and ``plane_<part>_slider`` (at
    it; its rates at rho'' = 0, and ``plane_<part>_slider_acceleration`` their
    coefficients of the exact penetration acceleration rho'', which the C core adds after
    the solve), each with its Jacobian (d/d contact state; the slider's with the
    contact's own rho''), and ``plane_<part>_margins`` (yield margin, re-stick margin at
    rho'' = 0, the deflection at the cap mu F_n / k, the re-stick margin's coefficient
    of rho'')."""
    state = CONTACT_STATE_SYMBOLS
    n = len(state)
    accel = contact.penetration_acceleration(plane)
    kernels = []

    def local(expressions, name):
        return contact_state(model, expressions, f"plane kernel {name}")

    layout = "generalized force (6), dissipation rate (1), rolling spring rates (3)"
    for part in contact.ROLLING_PARTS:
        spring = sds_outputs(model, plane, part, *contact.sds_spring(model, plane, part))
        name = f"plane_{part}_spring"
        doc = f"A plane's contact in its own frame, the {part} part's sds spring (below its cap):"
        kernels.append(Kernel(name, f"{doc} {layout}.", local(spring, name), inputs,
                              extra_doc, state=state))
        kernels.append(jacobian_kernel(model, f"{name}_jac", f"{doc} d(outputs)/d(contact "
                                       f"state) ({len(spring)}x{n} row-major).",
                                       local(spring, name), inputs, extra_doc, state=state))
        slider = sds_outputs(model, plane, part,
                             *contact.sds_slider(model, plane, part, accel))
        grows = sm.Symbol(f"{plane}_{part}_slider_grows")
        own = sds_outputs(model, plane, part,
                          *contact.sds_slider(model, plane, part, grows=grows))
        frozen = [(grows, local([contact.slider_grows(model, plane)], name)[0])]
        name = f"plane_{part}_slider"
        doc = f"A plane's contact in its own frame, the {part} part's sds slider (at its cap):"
        for i in range(6):
            if sm.sympify(slider[i]).has(accel):
                raise ValueError(f"{name}: a torque depends on {accel}")
        coefficients = [_affine_coefficient(o, accel, f"{name} output {i}")
                        for i, o in enumerate(slider[6:], 6)]
        value = [sm.sympify(o).xreplace({accel: 0}) for o in slider]
        kernels.append(Kernel(f"{name}_acceleration", f"{doc} the coefficients of the exact "
                              "penetration acceleration rho'' in its dissipation rate and "
                              "spring rates (4); the value kernel's are at rho'' = 0.",
                              local(coefficients, name), inputs, extra_doc, state=state))
        kernels.append(Kernel(name, f"{doc} {layout}.", local(value, name), inputs, extra_doc,
                              state=state))
        kernels.append(jacobian_kernel(model, f"{name}_jac", f"{doc} d(outputs)/d(contact "
                                       f"state) ({len(own)}x{n} row-major; the contact's own "
                                       "rho'', the radial form held).", local(own, name),
                                       inputs, extra_doc, frozen=frozen, state=state))
        margins = contact.sds_margins(model, plane, part, accel)
        restick = _affine_coefficient(margins[1], accel, f"the {part} re-stick margin")
        name = f"plane_{part}_margins"
        kernels.append(Kernel(
            name, f"A plane's contact in its own frame, the {part} part's sds mode guards "
            "(contact.sds_margins): yield margin 1 - k |xi| / (mu F_n), re-stick margin "
            "(m/s) at rho'' = 0, the deflection at the cap mu F_n / k (m), the re-stick "
            "margin's coefficient of rho'' (s).",
            local([margins[0], margins[1].xreplace({accel: 0}), margins[2], restick], name),
            inputs, extra_doc, state=state))
    return kernels


def output_kernels(model: Model):
    """Energies (kinetic, potential), observer position and the Hertz stiffness; the
    contacts' energies and kinematics are plane kernels (plane_kernels)."""
    N = model.frame
    ball, observer = bodies(model)
    g = gravity_vector(model)
    kinetic = ball.kinetic_energy(N) + observer.kinetic_energy(N)
    rel = model.observer.pos_from(model.centre)
    position = sum((model.state(c)*v for c, v in zip("xyz", (N.x, N.y, N.z))), me.Vector(0))
    potential = -ball.mass*me.dot(g, position) - observer.mass*me.dot(g, position + rel)
    observer_position = [model.state(c) + me.dot(rel, v)
                         for c, v in zip("xyz", (N.x, N.y, N.z))]
    return [
        Kernel("mechanical_energy", "Energies (J): kinetic, potential (-m g . c, the "
               "observer's too); the contacts' springs: plane_energy.", [kinetic, potential], []),
        Kernel("observer_position", "Observer position in N (3).", observer_position, []),
        Kernel("hertz_stiffness", "Hertz stiffness k0 (N/m^(3/2)) of the ball on a plane (1): "
               "the one formula, also behind Scene.hertz_stiffness.",
               [contact.hertz_stiffness(model)], []),
    ]


__all__ = ["CONTACT_LAW_LAYOUT", "contact_law_offsets", "MASS_LAYOUT", "STATE_NAMES", "build_kernels", "derive"]
