"""Physics against analytic results and conservation laws (issue 3).

Every expected value here is a formula written in this file or a balance law; none
is produced by the code under test.
"""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import ballc

#: A 10 mm (radius) steel ball on steel: contact ~70 us, 1e4 times shorter than a flight.
STEEL = dict(mass=7800 * 4 / 3 * math.pi * 0.01 ** 3, radius=0.01, ceiling_height=1.0,
             ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, ball_poisson_ratio=0.3,
             plane_poisson_ratio=0.3)
#: The seed's soft ball (E = 3 kPa), its own defaults otherwise.
SOFT = dict()
TIGHT = dict(rtol=1e-12, atol=1e-14)


def normal_impact(material, speed, c_tau, gap_time=1e-4, **changes):
    """One normal impact on the floor with gravity off; returns (scene, its contact)."""
    radius = material.get("radius", 1.0)
    scene = ballc.Scene(**{**material, "gravity": 0.0, "observer_mass": 0.0, "c_tau": c_tau,
                           "friction_coefficient": 0.0, "mixture": 0.0,
                           "position": (0.0, 0.0, radius + speed * gap_time),
                           "velocity": (0.0, 0.0, -speed), **changes})
    k0 = scene.hertz_stiffness
    rho_max = (5 * scene.mass * speed ** 2 / (4 * k0)) ** 0.4
    t_end = gap_time + 4 * rho_max / speed
    result = ballc.simulate(scene, t_end, **TIGHT)
    assert result.status == 0, result.message
    assert len(result.contacts) == 1
    return scene, result.contacts[0]


def hertz_expectation(scene, speed):
    """Hertz: rho_max = (5 m v0^2 / (4 k0))^(2/5), t_c = 2.9432751843 rho_max / v0."""
    k0 = 4 / (3 * ((1 - scene.ball_poisson_ratio ** 2) / scene.ball_youngs_modulus
                   + (1 - scene.plane_poisson_ratio ** 2) / scene.plane_youngs_modulus)) \
        * math.sqrt(scene.radius)
    rho_max = (5 * scene.mass * speed ** 2 / (4 * k0)) ** 0.4
    return rho_max, 2.9432751843 * rho_max / speed


@pytest.mark.parametrize("material, speed", [(SOFT, 25.0), (SOFT, 3.0), (STEEL, 1.0)],
                         ids=["soft-25", "soft-3", "steel-1"])
def test_hertz_impact_penetration_and_duration(material, speed):
    scene, contact = normal_impact(material, speed, c_tau=1.0)
    rho_max, duration = hertz_expectation(scene, speed)
    assert contact.max_penetration == pytest.approx(rho_max, rel=1e-6)
    assert contact.duration == pytest.approx(duration, rel=1e-6)
    assert contact.velocity_after[2] == pytest.approx(speed, rel=1e-8)   # elastic
    if material is STEEL:
        assert contact.duration == pytest.approx(69e-6, rel=0.05)


def hc_restitution_formula(c_tau):
    """e solving a (1 + e) = ln((1 + a) / (1 - a e)), a = 1.5 (1 - c_tau)."""
    a = 1.5 * (1 - c_tau)
    return brentq(lambda e: a * (1 + e) - math.log((1 + a) / (1 - a * e)), 1e-12,
                  min(1.0, 1 / a) * (1 - 1e-15), xtol=1e-15)


@pytest.mark.parametrize("c_tau", [0.5, 0.8, 0.9, 0.95])
@pytest.mark.parametrize("material, speed", [(SOFT, 25.0), (SOFT, 2.0), (STEEL, 1.0),
                                             (STEEL, 0.1)],
                         ids=["soft-25", "soft-2", "steel-1", "steel-0.1"])
def test_hunt_crossley_restitution(material, speed, c_tau):
    _, contact = normal_impact(material, speed, c_tau)
    e = contact.velocity_after[2] / -contact.velocity_before[2]
    assert e == pytest.approx(hc_restitution_formula(c_tau), abs=1e-6)
    assert ballc.hunt_crossley_restitution(c_tau) == pytest.approx(hc_restitution_formula(c_tau),
                                                                   abs=1e-12)


def oblique_impact(u_over_vn, mu, c_tau=0.9, regularization="max", spin=0.0):
    """A steel ball hits the floor obliquely (gravity off); returns (scene, contact)."""
    v_n = 1.0
    scene = ballc.Scene(**{**STEEL, "gravity": 0.0, "observer_mass": 0.0, "c_tau": c_tau,
                           "friction_coefficient": mu, "tangential_model": "friction",
                           "friction_regularization": regularization,
                           "friction_regularization_speed": 1e-10 if regularization == "max"
                           else 1e-7,
                           "position": (0.0, 0.0, STEEL["radius"] + 1e-4),
                           "velocity": (u_over_vn * v_n * 0.8, u_over_vn * v_n * 0.6, -v_n),
                           "angular_velocity": (0.0, 0.0, spin)})
    result = ballc.simulate(scene, 1e-4 + 3e-4, **TIGHT)
    assert result.status == 0, result.message
    assert len(result.contacts) == 1
    return scene, result.contacts[0]


@pytest.mark.parametrize("regularization", ["max", "smooth"])
@pytest.mark.parametrize("u_over_vn, mu", [(0.5, 0.3), (2.0, 0.3), (1.0, 0.1), (0.2, 0.05)],
                         ids=["rolls", "slides", "slides-2", "rolls-2"])
def test_friction_model_approaches_rigid_coulomb_impact(u_over_vn, mu, regularization):
    scene, contact = oblique_impact(u_over_vn, mu, regularization=regularization)
    e = hc_restitution_formula(scene.c_tau)
    v_n = -contact.velocity_before[2]
    u = np.hypot(*contact.velocity_before[:2])     # no spin before: u = v_t
    rolls = u <= 3.5 * mu * (1 + e) * v_n
    rigid = ballc.rigid_impact(contact.velocity_before, contact.angular_velocity_before,
                               mass=scene.mass, radius=scene.radius, restitution=e,
                               friction_coefficient=mu, tangential_restitution=0.0)
    assert rigid.sticking == rolls
    scale = np.linalg.norm(contact.velocity_before)
    np.testing.assert_allclose(contact.velocity_after, rigid.velocity, atol=1e-3 * scale)
    np.testing.assert_allclose(contact.angular_velocity_after * scene.radius,
                               rigid.angular_velocity * scene.radius, atol=1e-3 * scale)
    # rolling at the end <=> the contact point's tangential velocity vanished
    w, v = contact.angular_velocity_after, contact.velocity_after
    slip = v[:2] + np.cross(w, [0, 0, -scene.radius])[:2]
    assert (np.linalg.norm(slip) < 1e-3 * scale) == rolls


def test_rigid_map_rolling_threshold_is_three_and_a_half_mu_one_plus_e():
    """The closed-form threshold of a solid sphere, checked on the map itself."""
    e, mu, v_n = 0.7, 0.2, 2.0
    threshold = 3.5 * mu * (1 + e) * v_n
    for u, sticks in ((0.999 * threshold, True), (1.001 * threshold, False)):
        impact = ballc.rigid_impact([u, 0, -v_n], [0, 0, 0], restitution=e,
                                    friction_coefficient=mu)
        assert impact.sticking == sticks
        assert impact.velocity[2] == pytest.approx(e * v_n)
        # angular momentum about the contact point is conserved in a rigid impact
        r, m, inertia = 1.0, 1.0, 0.4
        before = m * np.cross([0, 0, r], [u, 0, -v_n])
        after = m * np.cross([0, 0, r], impact.velocity) + inertia * impact.angular_velocity
        np.testing.assert_allclose(after[:2], before[:2], atol=1e-12)


@pytest.mark.parametrize("model", ["mixture", "friction", "dig-in", "compliant"])
def test_vertical_drop_never_moves_horizontally(model):
    scene = ballc.Scene(tangential_model=model, velocity=(0.0, 0.0, -10.0),
                        observer_position=(0.0, 0.0, 0.5), observer_mass=0.2)
    result = ballc.simulate(scene, 3.0)
    assert result.status == 0 and len(result.contacts) >= 2
    assert np.abs(result.position[:2]).max() < 1e-9
    assert np.abs(result.angular_velocity).max() < 1e-9


@pytest.mark.parametrize("model", ["mixture", "friction", "compliant"])
def test_energy_balance_closes(model):
    """kinetic + potential + spring + dissipated stays at the initial energy."""
    scene = ballc.Scene(tangential_model=model, friction_coefficient=0.5,
                        angular_velocity=(3.0, -2.0, 5.0), tangential_stiffness_ratio=2 / 7)
    result = ballc.simulate(scene, 5.0)
    assert result.status == 0
    balance = result.energy["balance"]
    assert np.abs(balance / balance[0] - 1).max() < 1e-8
    if model in ("friction", "compliant"):   # passive models
        assert result.energy["dissipated"][-1] > 1.0
        assert all(c.energy_lost_normal + c.energy_lost_tangential > -1e-8 * balance[0]
                   for c in result.contacts)
    if model == "friction":
        # no stored tangential energy: kinetic + potential + spring never increases
        assert np.all(np.diff(result.energy["total"]) < 1e-8 * balance[0])


def test_digin_injects_energy_and_the_balance_shows_it():
    result = ballc.simulate(ballc.Scene(tangential_model="dig-in"), 5.0)
    assert result.status == 1 and "passed through the floor" in result.message
    energy = result.energy
    assert np.abs(energy["balance"] / energy["balance"][0] - 1).max() < 1e-8
    assert energy["dissipated"][-1] < -100.0        # negative dissipation: injected energy
    assert energy["total"][-1] > 2 * energy["total"][0]
    assert np.all(np.isfinite(result.y))


def test_contact_table_energy_matches_the_balance():
    """Per-contact energy lost = drop of (kinetic + potential + spring) over the contact."""
    result = ballc.simulate(ballc.Scene(), 5.0)
    total = result.energy["total"]
    for c in result.contacts:
        i0 = np.argmin(np.abs(result.t - c.t_start))
        i1 = np.argmin(np.abs(result.t - c.t_end))
        lost = total[i0] - total[i1]
        assert c.energy_lost_normal + c.energy_lost_tangential == pytest.approx(lost, abs=1e-6)
        assert c.peak_normal_force > 0
        assert c.time_sticking + c.time_slipping == pytest.approx(c.duration, rel=1e-9)
    frame = result.contacts_dataframe()
    assert list(frame["plane"]) == [c.plane for c in result.contacts]


@pytest.mark.parametrize("case", ["vertical drop", "mu = 0, oblique and spinning",
                                  "slides, then rolls"])
def test_contact_energy_split_between_normal_and_tangential(case):
    """Each contact's energy_lost_normal and _tangential separately.  Gravity off, no
    observer, a solid sphere: the normal motion is decoupled from the tangential one, so
    the normal force dissipates 1/2 m (vz^2 - vz'^2) (energy balance of the normal
    motion); the tangential force dissipates 0 without slip or without friction, and
    1/2 (2/7 m) |u|^2 = m |u|^2 / 7 when the contact-point slip u ends at rolling (the
    relative motion's kinetic energy, reduced mass 2/7 m); both add up to the drop of
    kinetic energy."""
    velocity, spin, mu = {"vertical drop": ((0.0, 0.0, -3.0), (0.0, 0.0, 0.0), 0.3),
                          "mu = 0, oblique and spinning": ((2.0, -1.0, -3.0),
                                                           (1.0, 4.0, 2.0), 0.0),
                          "slides, then rolls": ((2.0, 0.0, -3.0), (0.0, 4.0, 1.0), 0.3),
                          }[case]
    scene, contact = normal_impact(SOFT, 3.0, 0.9, tangential_model="friction",
                                   friction_coefficient=mu, velocity=velocity,
                                   angular_velocity=spin)
    m, r = scene.mass, scene.radius
    vb, va = contact.velocity_before, contact.velocity_after
    wb, wa = contact.angular_velocity_before, contact.angular_velocity_after
    kinetic = [0.5 * m * v @ v + 0.5 * (0.4 * m * r ** 2) * w @ w for v, w in ((vb, wb), (va, wa))]
    normal = 0.5 * m * (vb[2] ** 2 - va[2] ** 2)
    assert normal > 0.1 * 0.5 * m * vb[2] ** 2     # a real loss, not rounding
    # u = v_t + w x (-r e_z) of the contact point, before
    u = np.array([vb[0] - r * wb[1], vb[1] + r * wb[0]])
    if case == "slides, then rolls":
        assert contact.transitions[-1][1] == "stick"        # exits rolling:
        assert abs(va[0] - r * wa[1]) < 1e-9 and abs(va[1] + r * wa[0]) < 1e-9
        tangential = m * (u @ u) / 7
    else:
        tangential = 0.0
    assert contact.energy_lost_normal == pytest.approx(normal, rel=1e-7)
    assert contact.energy_lost_tangential == pytest.approx(tangential, rel=1e-7,
                                                          abs=1e-9 * kinetic[0])
    assert normal + tangential == pytest.approx(kinetic[0] - kinetic[1], rel=1e-7)


def seed_throw(**changes):
    return ballc.simulate(ballc.Scene(**changes), 5.0)


def garwin_signs(scene, planes):
    """Signs of vx after each impact of the ideal superball (Garwin 1969): the rigid map
    with tangential restitution 1 (the contact point's slip reverses), Hunt-Crossley's
    normal restitution, no slip limit; flights change neither vx nor the spin."""
    e = ballc.hunt_crossley_restitution(scene.c_tau)
    v, w, signs = np.array(scene.velocity, dtype=float), np.zeros(3), []
    for plane in planes:
        v[2] = -abs(v[2]) if plane == "floor" else abs(v[2])
        impact = ballc.rigid_impact(v, w, mass=scene.mass, radius=scene.radius,
                                    inertia=scene.inertia[0], restitution=e,
                                    friction_coefficient=1e9, tangential_restitution=1.0,
                                    plane=plane)
        v, w = impact.velocity, impact.angular_velocity
        signs.append(float(np.sign(v[0])))
    return signs


def test_compliant_superball_comes_back():
    """kappa = 2/7 makes the tangential and normal contact frequencies equal for a solid
    sphere, so the compliant contact returns the slip reversed -- Garwin's ideal
    superball.  The signs of vx after floor, ceiling, floor are then those of Garwin's
    rigid map (-, +, +: the ball comes back), computed here by that map."""
    scene = ballc.Scene(tangential_model="compliant", tangential_stiffness_ratio=2 / 7,
                        friction_coefficient=1.0)
    result = ballc.simulate(scene, 5.0)
    signs = [np.sign(c.velocity_after[0]) for c in result.contacts[:3]]
    assert [c.plane for c in result.contacts[:3]] == ["floor", "ceiling", "floor"]
    assert signs == garwin_signs(scene, ["floor", "ceiling", "floor"]) == [-1, 1, 1]


@pytest.mark.parametrize("mu", [0.0, 0.1, 0.3, 1.0, 3.0])
def test_pure_friction_never_comes_back(mu):
    result = seed_throw(tangential_model="friction", friction_coefficient=mu)
    assert result.status == 0
    assert all(c.velocity_after[0] <= 0 for c in result.contacts)


@pytest.mark.parametrize("c_tau", [0.5, 0.9, 0.99, 0.9933, 0.9934, 0.999, 0.99993, 0.999999, 1 - 1e-9, 1 - 1e-13])
def test_hunt_crossley_restitution_near_one(c_tau):
    """Close to c_tau = 1 the defining equation loses its residual to rounding; the
    function must still solve it: a(1 + e) = ln((1 + a)/(1 - a e)) to 1e-13, checked in
    50-digit arithmetic (mpmath, which sympy brings)."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 50
    e = ballc.hunt_crossley_restitution(c_tau)
    a = mp.mpf(1.5) * (1 - mp.mpf(c_tau))
    exact = mp.findroot(lambda x: a * (1 + x) - mp.log((1 + a) / (1 - a * x)), 1 - 2 * a / 3)
    assert abs(e - float(exact)) <= 1e-13


def test_hertz_stiffness_is_the_textbook_formula():
    """k0 = 4/3 E* sqrt(r), 1/E* = (1 - nu_b^2)/E_b + (1 - nu_p^2)/E_p (Johnson, Contact
    Mechanics, eq. 4.22), written here independently of the generated kernel it reads."""
    scene = ballc.Scene(ball_youngs_modulus=3e3, plane_youngs_modulus=2e10, radius=0.7,
                        ball_poisson_ratio=0.25, plane_poisson_ratio=0.15)
    e_star = 1 / ((1 - 0.25 ** 2) / 3e3 + (1 - 0.15 ** 2) / 2e10)
    assert scene.hertz_stiffness == pytest.approx(4 / 3 * e_star * 0.7 ** 0.5, rel=1e-14)
