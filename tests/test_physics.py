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
    # and against the solid sphere's closed form, written here (no spin before, so the
    # contact point moves with v_t): tangential impulse per unit mass p = -2/7 v_t
    # (rolls) or -mu (1 + e) v_n v_t / |v_t| (slides); at (0, 0, -r) it changes the
    # spin by (-r z) x p m / I = (5/2) (p_y, -p_x, 0) / r  (I = 2/5 m r^2)
    v_t = np.array([*contact.velocity_before[:2], 0.0])
    p = -2 / 7 * v_t if rolls else -mu * (1 + e) * v_n * v_t / u
    np.testing.assert_allclose(contact.velocity_after, v_t + p + [0, 0, e * v_n],
                               atol=1e-3 * scale)
    np.testing.assert_allclose(contact.angular_velocity_after * scene.radius,
                               2.5 * np.array([p[1], -p[0], 0.0]), atol=1e-3 * scale)
    # rolling at the end <=> the contact point's tangential velocity vanished
    w, v = contact.angular_velocity_after, contact.velocity_after
    slip = v[:2] + np.cross(w, [0, 0, -scene.radius])[:2]
    assert (np.linalg.norm(slip) < 1e-3 * scale) == rolls


@pytest.mark.parametrize("shape, ratio", [("solid", 2 / 5), ("hollow", 2 / 3)])
def test_rigid_map_rolling_threshold_is_three_and_a_half_mu_one_plus_e(shape, ratio):
    """The closed-form threshold |u| = mu (1 + e) v_n (1 + m r^2 / I) -- 3.5 mu (1 + e) v_n
    for a solid sphere, 2.5 for a hollow one -- checked on the map itself, with
    r = 0.37 and m = 2.3 (r, r^2 and m no longer coincide with 1).  The solid sphere
    takes rigid_impact's default inertia, the hollow one I = 2/3 m r^2 given."""
    e, mu, v_n = 0.7, 0.2, 2.0
    r, m = 0.37, 2.3
    inertia = ratio * m * r ** 2
    threshold = mu * (1 + e) * v_n * (1 + m * r ** 2 / inertia)
    assert threshold == pytest.approx((3.5 if shape == "solid" else 2.5) * mu * (1 + e) * v_n)
    for u, sticks in ((0.999 * threshold, True), (1.001 * threshold, False)):
        impact = ballc.rigid_impact([u, 0, -v_n], [0, 0, 0], mass=m, radius=r,
                                    inertia=None if shape == "solid" else inertia,
                                    restitution=e, friction_coefficient=mu)
        assert impact.sticking == sticks
        assert impact.velocity[2] == pytest.approx(e * v_n)
        # angular momentum about the contact point is conserved in a rigid impact
        before = m * np.cross([0, 0, r], [u, 0, -v_n])
        after = m * np.cross([0, 0, r], impact.velocity) + inertia * impact.angular_velocity
        np.testing.assert_allclose(after[:2], before[:2], atol=1e-12)
        # the closed-form rebound (tangential impulse per unit mass p along x, acting at
        # (0, 0, -r): it changes wy by -r m p / I):
        # sticking: the contact point leaves rolling, p = -u / (1 + m r^2 / I);
        # sliding: p = -mu (1 + e) v_n
        p = -u / (1 + m * r ** 2 / inertia) if sticks else -mu * (1 + e) * v_n
        np.testing.assert_allclose(impact.velocity, [u + p, 0.0, e * v_n], atol=1e-12)
        np.testing.assert_allclose(impact.angular_velocity, [0.0, -r * m * p / inertia, 0.0],
                                   atol=1e-12)
        if sticks:   # rolling: vx' = r wy'
            assert impact.velocity[0] == pytest.approx(r * impact.angular_velocity[1])


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


#: Garwin's ratio K = I / (m r^2): 2/5 for a solid sphere.
SOLID = 2 / 5


def garwin_map(v_t, r_w, e_t, k=SOLID):
    """Garwin's superball map (Am. J. Phys. 37, 88 (1969)): a no-slip impact that returns
    the contact point's tangential velocity u = v_t - r w reversed, u' = -e_t u:

        v_t' = [(1 - K e_t) v_t + K (1 + e_t) r w] / (1 + K)
        r w' = [(1 + e_t) v_t + (K - e_t) r w] / (1 + K)

    Derivation (per tangential axis): a tangential impulse P (per unit mass p = P/m)
    changes v_t by p and r w by -p r^2 m / I = -p / K (the torque of P at the contact
    point, below), so u changes by p (1 + 1/K); u' = -e_t u needs
    p = -K (1 + e_t) u / (1 + K), which gives the two lines above."""
    return (((1 - k * e_t) * v_t + k * (1 + e_t) * r_w) / (1 + k),
            ((1 + e_t) * v_t + (k - e_t) * r_w) / (1 + k))


def garwin_impact(v, w, radius, e, e_t, plane, k=SOLID):
    """One impact of ballc's 3-D ball by Garwin's map, in ballc's conventions.

    The plane's normal n towards the ball is +z (floor) or -z (ceiling); the contact
    point is at -r n, so its tangential velocity u = v_t + w x (-r n) is
    floor: (vx - r wy, vy + r wx), ceiling: (vx + r wy, vy - r wx).  With s = +1 (floor)
    or -1 (ceiling) that is u = v_t - (r w)_G with Garwin's spin (r w)_G =
    (s r wy, -s r wx): an impulse P at -r n changes w by (-r n) x P / I, i.e. (r w)_G
    by -r^2 P / I on both planes, as garwin_map assumes.  w_z (about the normal) is
    unchanged; the normal velocity leaves with -e times its approach."""
    s = 1.0 if plane == "floor" else -1.0
    v, w = np.asarray(v, float), np.asarray(w, float)
    r_w = np.array([s * radius * w[1], -s * radius * w[0]])
    v_t, r_w = garwin_map(v[:2], r_w, e_t, k)
    return (np.array([v_t[0], v_t[1], -e * v[2]]),
            np.array([-s * r_w[1] / radius, s * r_w[0] / radius, w[2]]))


def garwin_signs(scene, planes):
    """Signs of vx after each impact of the ideal superball: Garwin's map (e_t = 1, no
    slip limit) with Hunt-Crossley's normal restitution (the formula above, not
    ballc's); flights change neither the horizontal velocity nor the spin (no observer
    mass: the centre is the centre of mass)."""
    assert scene.observer_mass == 0.0
    assert scene.inertia[0] == pytest.approx(SOLID * scene.mass * scene.radius ** 2)
    e = hc_restitution_formula(scene.c_tau)
    v, w, signs = np.array(scene.velocity, float), np.array(scene.angular_velocity, float), []
    for plane in planes:
        v[2] = -abs(v[2]) if plane == "floor" else abs(v[2])
        v, w = garwin_impact(v, w, scene.radius, e, 1.0, plane)
        signs.append(float(np.sign(v[0])))
    return signs


@pytest.mark.parametrize("plane", ["floor", "ceiling"])
@pytest.mark.parametrize("e_t", [1.0, 0.4, -0.5])
def test_rigid_map_is_garwins_superball_map(e_t, plane):
    """ballc.rigid_impact with no slip limit (mu = 1e9) against Garwin's closed form,
    written above, for a 3-D spinning ball with r = 0.37 (r and r^2 differ), m = 2.3,
    I = 2/5 m r^2 (the default) and also given explicitly."""
    r, m, e = 0.37, 2.3, 0.8
    v = np.array([1.2, -0.7, -2.0 if plane == "floor" else 2.0])
    w = np.array([4.0, -9.0, 3.0])
    expected_v, expected_w = garwin_impact(v, w, r, e, e_t, plane)
    for inertia in (None, SOLID * m * r ** 2):
        impact = ballc.rigid_impact(v, w, mass=m, radius=r, inertia=inertia, restitution=e,
                                    friction_coefficient=1e9, tangential_restitution=e_t,
                                    plane=plane)
        assert impact.sticking
        np.testing.assert_allclose(impact.velocity, expected_v, rtol=0, atol=1e-12)
        np.testing.assert_allclose(impact.angular_velocity, expected_w, rtol=0, atol=1e-12)
    # the contact point's tangential velocity is reversed with e_t (Garwin's definition)
    n = np.array([0.0, 0.0, 1.0 if plane == "floor" else -1.0])
    u_before = (v + np.cross(w, -r * n))[:2]
    u_after = (expected_v + np.cross(expected_w, -r * n))[:2]
    np.testing.assert_allclose(u_after, -e_t * u_before, atol=1e-12)


@pytest.mark.parametrize("spin", [(0.0, 0.0, 0.0), (0.0, 10.0, 0.0), (0.0, -20.0, 0.0)],
                         ids=["no-spin", "topspin", "backspin"])
def test_compliant_superball_comes_back(spin):
    """kappa = 2/7 makes the tangential and normal contact frequencies equal for a solid
    sphere, so the compliant contact returns the slip reversed -- Garwin's ideal
    superball.  The signs of vx after floor, ceiling, floor are then those of Garwin's
    rigid map, written in this file (garwin_impact).  The ball has r = 0.37 (the seed's
    soft ball scaled: E / r^3 keeps its deepest penetration ~0.5 r) and no observer
    mass.  Without spin it comes back (-, +, +); the spins were chosen so that the map
    evaluated with r^2 in place of r (spin -20 rad/s: -, +, + instead of -, -, +) or 1 in
    place of r (10 rad/s: +, +, + instead of -, +, +) would give other signs."""
    r = 0.37
    scene = ballc.Scene(tangential_model="compliant", tangential_stiffness_ratio=2 / 7,
                        friction_coefficient=1.0, radius=r, inertia=(SOLID * r ** 2,) * 3,
                        ball_youngs_modulus=6e4, observer_mass=0.0, angular_velocity=spin)
    result = ballc.simulate(scene, 5.0)
    assert result.status == 0
    signs = [np.sign(c.velocity_after[0]) for c in result.contacts[:3]]
    assert [c.plane for c in result.contacts[:3]] == ["floor", "ceiling", "floor"]
    assert signs == garwin_signs(scene, ["floor", "ceiling", "floor"])
    if spin == (0.0, 0.0, 0.0):
        assert signs == [-1, 1, 1]


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
