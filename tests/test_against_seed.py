"""ballc's compiled equations against the seed's own lambdified sympy formulation.

The oracle is codegen/seed_reference.py: the seed's KanesMethod model in body-fixed
123 angles, lambdified exactly like the seed does, solved with numpy.linalg.solve.
ballc is a separate derivation (quaternion, split kernels, Schur solve), so
agreement of the generalized-speed derivatives checks the whole compiled path.
"""
import numpy as np
import pytest

import ballc
from ballc import _core
from ballc.orientation import angles_123_from_quaternion, quaternion_from_angles_123, rotation_matrix
from codegen.seed_reference import SEED_PARAMETER_NAMES, angles_123_dcm, seed_energies, seed_state_derivative

MODELS = ("friction", "dig-in", "mixture")


def seed_parameters(scene, latch):
    """The seed's 26 parameters for a ballc scene and latched values."""
    values = dict(zip(_core.PARAMETER_NAMES, scene.parameter_vector()))
    c = _core.N_LATCH_PER_PLANE   # the ceiling's latched values start here
    seed = {
        "m": scene.mass, "mo": scene.observer_mass, "g": scene.gravity, "r": scene.radius,
        "alpha": scene.observer_position[0], "beta": scene.observer_position[1],
        "gamma": scene.observer_position[2], "iXX": scene.inertia[0],
        "iYY": scene.inertia[1], "iZZ": scene.inertia[2], "H": scene.ceiling_height,
        "mixtur": values["mixture"], "nyb": scene.ball_poisson_ratio,
        "nyp": scene.plane_poisson_ratio, "Eb": scene.ball_youngs_modulus,
        "Ep": scene.plane_youngs_modulus, "ctau": scene.c_tau,
        "mu": scene.friction_coefficient,
        "rhodtu": latch[0], "ru1": latch[1], "ru2": latch[2], "ru3": latch[3],
        "rhodto": latch[c], "ro1": latch[c + 1], "ro2": latch[c + 2], "ro3": latch[c + 3],
    }
    return [seed[name] for name in SEED_PARAMETER_NAMES]


def random_scene(rng, model):
    inertia = rng.uniform(0.3, 0.6, 3)   # any three of these satisfy the triangle inequality
    direction = rng.normal(size=3)
    observer = direction / np.linalg.norm(direction) * rng.uniform(0.0, 0.95)
    return ballc.Scene(
        mass=rng.uniform(0.5, 2.0), observer_mass=rng.uniform(0.0, 0.5),
        radius=rng.uniform(0.5, 1.5), gravity=rng.uniform(0, 15), ceiling_height=10.0,
        inertia=tuple(inertia), observer_position=tuple(observer),
        ball_youngs_modulus=10 ** rng.uniform(3, 6), plane_youngs_modulus=10 ** rng.uniform(6, 11),
        ball_poisson_ratio=rng.uniform(0, 0.5), plane_poisson_ratio=rng.uniform(0, 0.5),
        c_tau=rng.uniform(0.5, 1.0), friction_coefficient=rng.uniform(0, 1),
        mixture=rng.uniform(0, 1), tangential_model=model)


def random_state(rng, scene, where):
    """(ballc state, seed state, latch, flags) with the ball free / on floor / on ceiling."""
    r, h = scene.radius, scene.ceiling_height
    z = {"free": rng.uniform(r, h - r), "floor": r - rng.uniform(0, 0.5 * r),
         "ceiling": h - r + rng.uniform(0, 0.5 * r)}[where]
    angles = rng.uniform(-np.pi, np.pi, 3)
    angles[1] = rng.uniform(-1.4, 1.4)
    position = np.array([*rng.uniform(-5, 5, 2), z])
    omega = rng.uniform(-10, 10, 3)
    velocity = rng.uniform(-10, 10, 3)
    seed_y = np.concatenate([angles, position, omega, velocity])
    deflections = rng.uniform(-1e-3, 1e-3, 4) * r     # compliant model's tangential springs
    auxiliary = np.concatenate([rng.uniform(-10, 10, 2), deflections])   # dissipated, deflections
    y = np.concatenate([quaternion_from_angles_123(angles), position, omega, velocity, auxiliary])
    latch = np.zeros(_core.N_LATCH)
    for k in range(0, _core.N_LATCH, _core.N_LATCH_PER_PLANE):
        direction = rng.normal(size=3)
        latch[k] = rng.uniform(1, 30)
        latch[k + 1:k + 4] = direction / np.linalg.norm(direction)
    flags = _core.FLAGS["observer"] if scene.observer_mass else 0
    mixture = scene.effective_mixture
    if where != "free" and scene.tangential_model == "compliant":
        flags |= _core.FLAGS[f"{where}_compliant"]
    elif where != "free":
        if mixture < 1:
            flags |= _core.FLAGS[f"{where}_friction"]
        if mixture > 0:
            flags |= _core.FLAGS[f"{where}_digin"]
    return y, seed_y, latch, flags


def brackets_positive(scene, y, latch, where):
    """True when both Hunt-Crossley brackets are > 0, i.e. ballc's no-adhesion clamp
    (absent from the seed) is inactive.  Written from the formulas, not from ballc."""
    if where == "free":
        return True
    r = scene.radius
    omega, velocity = y[7:10], y[10:13]
    arm = np.array([0, 0, -r if where == "floor" else r])
    vcp = velocity + np.cross(omega, arm)
    n = np.array([0, 0, 1.0 if where == "floor" else -1.0])
    k = 0 if where == "floor" else _core.N_LATCH_PER_PLANE
    a = 1.5 * (1 - scene.c_tau) / latch[k]
    return 1 + a * (-vcp @ n) > 0.05 and 1 + a * (vcp @ latch[k + 1:k + 4]) > 0.05


def comparable_states(rng, model, where, count):
    """``count`` random (scene, y, seed_y, latch, flags) at which ballc and the seed
    share their equations (both Hunt-Crossley brackets positive)."""
    found = 0
    while found < count:
        scene = random_scene(rng, model)
        y, seed_y, latch, flags = random_state(rng, scene, where)
        if brackets_positive(scene, y, latch, where):
            found += 1
            yield scene, y, seed_y, latch, flags


@pytest.mark.parametrize("where", ["free", "floor", "ceiling"])
@pytest.mark.parametrize("model", MODELS)
def test_speed_derivatives_match_seed(seed_model, rng, where, model):
    for scene, y, seed_y, latch, flags in comparable_states(rng, model, where, 60):
        ours = _core.rhs(y, scene.parameter_vector(), latch, flags)
        theirs = seed_state_derivative(seed_y, seed_parameters(scene, latch))
        np.testing.assert_allclose(ours[7:13], theirs[6:], rtol=1e-9,
                                   atol=1e-9 * np.abs(theirs[6:]).max())
        # the centre's kinematics are the seed's too
        np.testing.assert_allclose(ours[4:7], theirs[3:6], rtol=1e-15)


def test_quaternion_kinematics_rotate_with_omega(rng):
    """dR/dt = [omega]x R: finite differences of R along qdot, no ballc formula involved."""
    scene = ballc.Scene()
    for _ in range(50):
        y, _, latch, flags = random_state(rng, scene, "free")
        qdot = _core.rhs(y, scene.parameter_vector(), latch, flags)[:4]
        h = 1e-6
        dR = (rotation_matrix(y[:4] + h * qdot) - rotation_matrix(y[:4] - h * qdot)) / (2 * h)
        w = y[7:10]
        skew = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        np.testing.assert_allclose(dR, skew @ rotation_matrix(y[:4]), atol=1e-7 * (1 + abs(w).max()))
        assert abs(y[:4] @ qdot) < 1e-12 * (1 + abs(w).max())   # norm preserved


@pytest.mark.parametrize("where", ["free", "floor", "ceiling"])
def test_energies_match_seed(seed_model, rng, where):
    for _ in range(40):
        scene = random_scene(rng, "mixture")
        y, seed_y, latch, _ = random_state(rng, scene, where)
        ours = _core.energies(y[None, :], scene.parameter_vector())[0]
        theirs = seed_energies(seed_y, seed_parameters(scene, latch))
        np.testing.assert_allclose(ours[0], theirs["kinetic"], rtol=1e-12)
        np.testing.assert_allclose(ours[1], theirs["potential"], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(ours[2] + ours[3], theirs["spring"], rtol=1e-12, atol=1e-300)


def test_observer_position_matches_seed(seed_model, rng):
    for _ in range(40):
        scene = random_scene(rng, "mixture")
        y, seed_y, latch, _ = random_state(rng, scene, "free")
        ours = _core.observer_positions(y[None, :], scene.parameter_vector())[0]
        theirs = np.ravel(seed_model.observer_position_lam(*seed_y, *seed_parameters(scene, latch)))
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


def test_orientation_conversions_match_sympy_dcm(rng):
    for _ in range(50):
        angles = rng.uniform(-np.pi, np.pi, 3)
        angles[1] = rng.uniform(-1.5, 1.5)
        q = quaternion_from_angles_123(angles)
        np.testing.assert_allclose(rotation_matrix(q), angles_123_dcm(*angles), atol=1e-14)
        np.testing.assert_allclose(angles_123_from_quaternion(q), angles, atol=1e-12)


@pytest.mark.parametrize("where", ["free", "floor", "ceiling"])
@pytest.mark.parametrize("model", MODELS + ("compliant",))
def test_analytic_jacobian_matches_finite_differences(rng, where, model):
    for _ in range(8):
        scene = random_scene(rng, model)
        y, _, latch, flags = random_state(rng, scene, where)
        if not brackets_positive(scene, y, latch, where):
            continue
        p = scene.parameter_vector()
        jac = _core.jacobian(y, p, latch, flags)
        fd = np.empty_like(jac)
        n = _core.N_STATES
        for j in range(n):
            h = 1e-6 * max(1.0, abs(y[j])) if j < 13 else 1e-9
            e = np.zeros(n)
            e[j] = h
            fd[:, j] = (_core.rhs(y + e, p, latch, flags) - _core.rhs(y - e, p, latch, flags)) / (2 * h)
            if model == "compliant" and where != "free":
                # the Jacobian is of the law without its dilution term (codegen/contact.py
                # JACOBIAN_FORMS): take the term's own derivative out of the differences
                fd[:, j] -= (_dilution(scene, y + e, where) - _dilution(scene, y - e, where)) / (2 * h)
        scale = np.abs(fd).max(axis=1, keepdims=True) + 1e-12
        assert np.all(np.abs(jac - fd) <= 1e-5 * scale + 1e-6), np.abs(jac - fd).max()


def _dilution(scene, y, plane):
    """The compliant law's dilution term, written here from docs/contact_laws.md: its
    share -max(rhodot, 0)/(2 rho) s of the deflection rate, and its share
    +k_t |s|^2 max(rhodot, 0)/(2 rho) of the tangential dissipation rate (a loaded
    contact, F_n > 0, as brackets_positive ensures)."""
    names = _core.STATE_NAMES
    z, vz = y[names.index("z")], y[names.index("vz")]
    rho = scene.radius - z if plane == "floor" else scene.radius - (scene.ceiling_height - z)
    rhodot = -vz if plane == "floor" else vz
    i = names.index(f"{plane}_deflection_x")
    s = y[i:i + 2]
    rate = max(rhodot, 0.0) / (2 * max(rho, 1e-30))
    k_t = scene.tangential_stiffness_ratio * 1.5 * scene.hertz_stiffness * np.sqrt(max(rho, 0.0))
    out = np.zeros(len(names))
    out[i:i + 2] = -rate * s
    out[names.index("dissipated_tangential")] = k_t * (s @ s) * rate
    return out
