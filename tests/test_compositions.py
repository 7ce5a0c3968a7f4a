"""The seed's contact laws as compositions of parts (codegen/contact.py COMPOSITIONS).

Checked in numbers at random states, parameters and latches, in a plane's own frame (the
floor's: codegen derives every law there once; the C core applies it to each plane turned,
which tests/test_plane_frame.py checks):

* each part is the equation its docstring gives (written here again in numpy, with the
  contact-point kinematics computed here too);
* each law codegen emits (contact.TANGENTIAL_LAWS, and the friction law's normal share
  that kernels.py takes from COMPOSITIONS["friction_normal"]) is the composition of its
  table's parts: the parts evaluated one after the other on numbers, normal -> damping
  -> tangential, weighted, give the law's force;
* and the table holds the seed's laws: each law against the seed's formula written here
  in numpy (the compiled laws are held to the seed's own formulation by
  test_against_seed.py);
* the friction law's normal share is the friction law with mu = 0, and the mixture's
  two shares add up to 1.
"""
import numpy as np
import pytest

sm = pytest.importorskip("sympy")
me = pytest.importorskip("sympy.physics.mechanics")

from codegen import contact  # noqa: E402
from codegen.model import FRAME_PLANE, PARAMETER_NAMES, build_model  # noqa: E402

SEED_LAWS = ("friction", "digin")
POINTS = 25


@pytest.fixture(scope="module")
def model():
    return build_model()


def random_point(rng, model, plane):
    """(sympy substitution, numbers by name) for a ball in contact with ``plane``."""
    p = {
        "mass": rng.uniform(0.5, 2), "observer_mass": rng.uniform(0, 0.5),
        "gravity_x": 0.0, "gravity_y": 0.0, "gravity_z": -rng.uniform(0, 15),
        "radius": rng.uniform(0.5, 1.5),
        "observer_alpha": rng.uniform(-0.5, 0.5), "observer_beta": rng.uniform(-0.5, 0.5),
        "observer_gamma": rng.uniform(-0.5, 0.5), "inertia_xx": rng.uniform(0.3, 0.6),
        "inertia_yy": rng.uniform(0.3, 0.6), "inertia_zz": rng.uniform(0.3, 0.6),
        "mixture": rng.uniform(0, 1),
        "ball_poisson_ratio": rng.uniform(0, 0.5), "plane_poisson_ratio": rng.uniform(0, 0.5),
        "ball_youngs_modulus": 10 ** rng.uniform(3, 6),
        "plane_youngs_modulus": 10 ** rng.uniform(6, 11),
        "c_tau": rng.uniform(0.3, 1), "friction_coefficient": rng.uniform(0, 1.5),
        "friction_regularization_speed": 10 ** rng.uniform(-10, -1),
        "smooth_friction": float(rng.integers(2)), "tangential_stiffness_ratio": 0.8,
        "normal_damping_model": 0.0, "damping_ratio": 0.1, "tangential_damping_ratio": 0.1,
        # rolling resistance: its own part (tests/test_rolling.py); none of these laws
        # reads it
        "rolling_resistance": 0.0, "rolling_stiffness": 0.0, "rolling_damping": 0.0,
        "twisting_resistance": 0.0, "twisting_stiffness": 0.0, "twisting_damping": 0.0,
    }
    p["plane_count"] = 1.0   # the plane table (run time): no law reads it
    assert set(p) == set(PARAMETER_NAMES)
    r = p["radius"]
    z = r - rng.uniform(0, 0.3 * r)
    q = rng.normal(size=4)
    state = {"qw": q[0], "qx": q[1], "qy": q[2], "qz": q[3],
             "x": rng.uniform(-5, 5), "y": rng.uniform(-5, 5), "z": z}
    state.update(zip(("omega_x", "omega_y", "omega_z"), rng.uniform(-10, 10, 3)))
    state.update(zip(("vx", "vy", "vz"), rng.uniform(-10, 10, 3)))
    direction = rng.normal(size=3)
    latch = [rng.uniform(1, 30), *(direction / np.linalg.norm(direction))]
    values = {model.p[k]: sm.Float(v) for k, v in p.items()}
    values.update({s: sm.Float(state.get(str(s.func), 0.0)) for s in model.states})
    values.update({s: sm.Float(v) for s, v in zip(contact.latch_symbols(model, plane), latch)})
    numbers = dict(p, **state, rate_at_impact=latch[0], direction=np.array(latch[1:]))
    return values, numbers


def evaluate(expr, values):
    return float(sm.sympify(expr).xreplace(values).evalf())


def components(vector, model, values):
    N = model.frame
    return np.array([evaluate(me.dot(vector, e), values) for e in (N.x, N.y, N.z)])


def kinematics(plane, n):
    """(normal, rho, rhodot, contact-point velocity) from the numbers, in numpy, in the
    plane's own frame (normal +z through the origin)."""
    assert plane == FRAME_PLANE
    normal = np.array([0.0, 0.0, 1.0])
    arm = -n["radius"] * normal
    velocity = np.array([n["vx"], n["vy"], n["vz"]]) + np.cross(
        [n["omega_x"], n["omega_y"], n["omega_z"]], arm)
    return normal, n["radius"] - n["z"], -velocity @ normal, velocity


def hertz_k0(n):
    sigma = ((1 - n["ball_poisson_ratio"]**2) / n["ball_youngs_modulus"]
             + (1 - n["plane_poisson_ratio"]**2) / n["plane_youngs_modulus"])
    return 4 / 3 * np.sqrt(n["radius"]) / sigma


def recording(force):
    """A normal_force(rate) that returns the symbol F and records the rates asked for."""
    rates = []

    def normal_force(rate):
        rates.append(rate)
        return force
    return normal_force, rates


@pytest.mark.parametrize("plane", [FRAME_PLANE])
def test_parts_are_their_equations(model, plane):
    rng = np.random.default_rng(208)
    F, E, K, rate = sm.symbols("F E K rate")
    rate_at_impact = contact.latch_symbols(model, plane)[0]
    _, rho_symbol = contact.plane_geometry(model, plane)
    elastic, stiffness = contact.hertz_normal(model, rho_symbol)
    for _ in range(POINTS):
        values, n = random_point(rng, model, plane)
        normal, rho, rhodot, velocity = kinematics(plane, n)
        k0 = hertz_k0(n)
        np.testing.assert_allclose(evaluate(elastic, values), k0 * rho**1.5, rtol=1e-12)
        np.testing.assert_allclose(evaluate(stiffness, values), 1.5 * k0 * rho**0.5, rtol=1e-12)

        numbers = {**values, E: sm.Float(rng.uniform(0, 100)), K: sm.Float(7.0),
                   rate: sm.Float(rng.uniform(-30, 30))}
        chi = 1.5 * (1 - n["c_tau"])
        expected = float(numbers[E]) * (1 + chi * float(numbers[rate]) / n["rate_at_impact"])
        np.testing.assert_allclose(
            evaluate(contact.hunt_crossley(model, E, K, rate, rate_at_impact), numbers),
            expected, rtol=1e-12)

        f = rng.uniform(0, 100)
        numbers = {**values, F: sm.Float(f)}
        slip = velocity - (velocity @ normal) * normal
        speed = np.hypot(slip[0], slip[1])
        eps = n["friction_regularization_speed"]
        size = np.hypot(speed, eps) if n["smooth_friction"] else max(speed, eps)
        coulomb = f * normal - n["friction_coefficient"] * f * slip / size
        for part, force, rate_asked in (
                (contact.coulomb_friction, coulomb, rhodot),
                (contact.no_friction, f * normal, rhodot),
                (contact.dig_in, -f * n["direction"], velocity @ n["direction"])):
            normal_force, rates = recording(F)
            ours = components(part(model, plane, normal_force), model, numbers)
            np.testing.assert_allclose(ours, force, rtol=1e-12, atol=1e-12 * f, err_msg=part.__name__)
            assert len(rates) == 1, part.__name__
            np.testing.assert_allclose(evaluate(rates[0], values), rate_asked, rtol=1e-12,
                                       atol=1e-12 * np.abs(velocity).max(), err_msg=part.__name__)


def seed_formula(name, plane, n):
    """The seed's law ``name`` (weighted) from the numbers, in numpy."""
    normal, rho, rhodot, velocity = kinematics(plane, n)
    chi = 1.5 * (1 - n["c_tau"]) / n["rate_at_impact"]
    elastic = hertz_k0(n) * rho**1.5
    f_n = max(0.0, elastic * (1 + chi * rhodot))
    if name == "digin":
        d = n["direction"]
        return n["mixture"] * max(0.0, elastic * (1 + chi * (velocity @ d))) * -d
    force = f_n * normal
    if name == "friction":
        slip = velocity - (velocity @ normal) * normal
        speed = np.hypot(slip[0], slip[1])
        eps = n["friction_regularization_speed"]
        size = np.hypot(speed, eps) if n["smooth_friction"] else max(speed, eps)
        force = force - n["friction_coefficient"] * f_n * slip / size
    return (1 - n["mixture"]) * force


def composed_by_hand(model, plane, parts, values):
    """The law of ``parts`` evaluated part after part on numbers (not contact.compose)."""
    _, rho = contact.plane_geometry(model, plane)
    rate_at_impact = contact.latch_symbols(model, plane)[0]
    elastic, stiffness = (sm.Float(evaluate(e, values)) for e in parts.normal(model, rho))

    def normal_force(rate):
        damped = parts.damping(model, elastic, stiffness, sm.Float(evaluate(rate, values)),
                               rate_at_impact)
        return sm.Float(max(0.0, evaluate(damped, values)))

    force = components(parts.tangential(model, plane, normal_force), model, values)
    return evaluate(parts.weight(model), values) * force


def codegen_law(model, plane, name):
    """The law a kernel of codegen is derived from (kernels.derive)."""
    if name in contact.TANGENTIAL_LAWS:
        return contact.TANGENTIAL_LAWS[name](model, plane)
    assert name == "friction_normal"
    return contact.compose(model, plane, contact.COMPOSITIONS[name])


def test_the_table_holds_the_seed_laws():
    assert set(contact.TANGENTIAL_LAWS) == {"friction", "digin", "compliant", "compliant_sliding",
                                            "compliant_elastic"}
    assert set(contact.COMPOSITIONS) == {*SEED_LAWS, "friction_normal"}


@pytest.mark.parametrize("name", [*SEED_LAWS, "friction_normal"])
@pytest.mark.parametrize("plane", [FRAME_PLANE])
def test_codegen_laws_are_their_compositions(model, plane, name):
    rng = np.random.default_rng(2020)
    law = codegen_law(model, plane, name)
    parts = contact.COMPOSITIONS[name]
    clamped = 0
    for _ in range(POINTS):
        values, n = random_point(rng, model, plane)
        ours = components(law.force, model, values)
        expected = composed_by_hand(model, plane, parts, values)
        np.testing.assert_allclose(ours, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
        np.testing.assert_allclose(evaluate(law.weight, values), evaluate(parts.weight(model), values),
                                   rtol=1e-15)
        seed = seed_formula(name, plane, n)
        np.testing.assert_allclose(ours, seed, rtol=1e-9, atol=1e-9 * np.abs(seed).max())
        clamped += not np.any(expected)
    assert clamped < POINTS   # most points carry a load


@pytest.mark.parametrize("plane", [FRAME_PLANE])
def test_friction_normal_is_friction_without_mu_and_shares_add_up(model, plane):
    rng = np.random.default_rng(7)
    mu = model.p["friction_coefficient"]
    friction = contact.TANGENTIAL_LAWS["friction"](model, plane)
    share = contact.compose(model, plane, contact.COMPOSITIONS["friction_normal"])
    for _ in range(10):
        values, _ = random_point(rng, model, plane)
        without_mu = {**values, mu: sm.Float(0)}
        np.testing.assert_array_equal(components(share.force, model, values),
                                      components(friction.force, model, without_mu))
        shares = [evaluate(contact.COMPOSITIONS[k].weight(model), values) for k in SEED_LAWS]
        assert sum(shares) == pytest.approx(1, abs=1e-15)
