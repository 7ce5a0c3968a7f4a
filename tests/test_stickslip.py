"""Exact Coulomb friction (stick and slip as events) against independent oracles.

The oracles: Coulomb's skid-to-roll solution of a sphere on a plane, the rigid
Coulomb impact map's rolling boundary (a closed form), the seed's own regularised law
at a tight tolerance (its v_s -> 0 limit is this model), and the equations of motion
themselves (the stick force keeps the slip velocity exactly constant).
"""
import math

import numpy as np
import pytest

import ballc
from ballc import _core, layout, stickslip

G = 9.81


def skid_scene(mu, v0, spin=0.0):
    """A solid sphere (no observer, c_tau = 1) launched along the floor at v0 without
    spin, resting at its static penetration (m g / k0)^(2/3) with no vertical speed,
    so that F_n = m g throughout (the friction acts at (0, 0, -r): no vertical force)."""
    base = ballc.Scene(observer_mass=0.0, c_tau=1.0, tangential_model="friction",
                       friction_coefficient=mu, gravity=G, velocity=(v0, 0.0, 0.0),
                       angular_velocity=(0.0, spin, 0.0))
    rho = (base.mass * G / base.hertz_stiffness) ** (2 / 3)
    return base.replace(position=(0.0, 0.0, base.radius - rho))


@pytest.mark.parametrize("tol", [1e-3, 1e-6, 1e-10])
@pytest.mark.parametrize("mu, v0", [(0.3, 2.0), (0.1, 5.0), (0.8, 0.5)])
def test_skid_to_roll_matches_coulomb_theory(mu, v0, tol):
    """Coulomb: the contact point slides for t* = 2 v0 / (7 mu g), then the sphere rolls
    at 5 v0 / 7 and the contact point stays at rest (no force acts along the floor).
    The slip phase is linear in t, so every tolerance must find t* to ~1e-13."""
    scene = skid_scene(mu, v0)
    result = ballc.simulate(scene, 2.5 * 2 * v0 / (7 * mu * G), rtol=tol, atol=tol)
    assert result.status == 0, result.message
    (contact,) = result.contacts
    t_star = 2 * v0 / (7 * mu * G)
    assert [phase for _, phase in contact.transitions] == ["slip", "stick"]
    assert contact.transitions[1][0] == pytest.approx(t_star, rel=1e-6)
    assert result.velocity[0, -1] == pytest.approx(5 * v0 / 7, rel=1e-6)
    sticking = result.t >= contact.transitions[1][0]
    slip = result.velocity[0] - scene.radius * result.angular_velocity[1]
    assert np.max(np.abs(slip[sticking])) <= 1e-12
    # the normal force is m g throughout: the ball stays at its static penetration
    np.testing.assert_allclose(result.position[2], scene.position[2], rtol=0, atol=1e-12)
    # the contact table's phase times come from the events
    assert contact.time_slipping == pytest.approx(t_star, rel=1e-6)
    assert contact.time_sticking == pytest.approx(result.t[-1] - t_star, rel=1e-6)


def test_backspin_reverses_then_rolls():
    """With backspin omega0 (about +y, for motion along +x the rolling spin is v/r
    about +y: backspin is negative) the slip is v0 - r omega0 > 0 and Coulomb gives
    rolling at (5 v0 + 2 r omega0) / 7, here negative: the ball comes back."""
    mu, v0, omega0 = 0.4, 1.0, -6.0
    scene = skid_scene(mu, v0, spin=omega0)
    u0 = v0 - scene.radius * omega0
    t_star = 2 * u0 / (7 * mu * G)
    result = ballc.simulate(scene, 2 * t_star, rtol=1e-8, atol=1e-8)
    (contact,) = result.contacts
    assert contact.transitions[1] == (pytest.approx(t_star, rel=1e-6), "stick")
    expected = (5 * v0 + 2 * scene.radius * omega0) / 7
    assert expected < 0
    assert result.velocity[0, -1] == pytest.approx(expected, rel=1e-6)


def steel_oblique(u, mu=0.2, c_tau=0.9, tol=1e-10):
    """A steel ball hits the floor at normal speed 1 m/s, tangential speed u, no spin,
    gravity off, exact Coulomb friction."""
    from test_physics import STEEL
    scene = ballc.Scene(**{**STEEL, "gravity": 0.0, "observer_mass": 0.0, "c_tau": c_tau,
                           "friction_coefficient": mu, "tangential_model": "friction",
                           "position": (0.0, 0.0, STEEL["radius"] + 1e-4),
                           "velocity": (0.6 * u, 0.8 * u, -1.0)})
    result = ballc.simulate(scene, 4e-4, rtol=tol, atol=tol)
    assert result.status == 0, result.message
    (contact,) = result.contacts
    return scene, contact


@pytest.mark.parametrize("side, rolls", [(0.999, True), (1.001, False)])
def test_rolling_boundary_of_the_rigid_coulomb_map(side, rolls):
    """Without tangential compliance the slip only loses speed in proportion to the
    normal impulse, so a compliant impact ends rolling exactly when the rigid map's
    |u| <= 3.5 mu (1 + e) |v_n| (solid sphere), e the Hunt-Crossley restitution.
    0.1 % either side of that boundary decides the outcome."""
    mu, c_tau = 0.2, 0.9
    e = ballc.hunt_crossley_restitution(c_tau)
    u = side * 3.5 * mu * (1 + e) * 1.0
    scene, contact = steel_oblique(u, mu, c_tau)
    w, v = contact.angular_velocity_after, contact.velocity_after
    slip = np.hypot(*(v[:2] + np.cross(w, [0, 0, -scene.radius])[:2]))
    assert (contact.transitions[-1][1] == "stick") == rolls
    if rolls:
        assert slip <= 1e-12
    else:
        assert slip > 1e-4 * u
    rigid = ballc.rigid_impact(contact.velocity_before, contact.angular_velocity_before,
                               mass=scene.mass, radius=scene.radius, restitution=e,
                               friction_coefficient=mu)
    np.testing.assert_allclose(contact.velocity_after, rigid.velocity, atol=1e-3 * u)


@pytest.fixture(scope="module")
def seed_pair():
    """The seed scene at rtol = atol = 1e-12 with the seed's literal law (v_s = 1e-10)
    and with exact Coulomb friction."""
    kw = dict(rtol=1e-12, atol=1e-12)
    literal = ballc.simulate(ballc.Scene(friction_regularization="max"), 5.0, **kw)
    exact = ballc.simulate(ballc.Scene(), 5.0, **kw)
    return literal, exact


def test_seed_scene_agrees_with_the_seeds_law(seed_pair):
    """v_s = 1e-10 m/s is the seed's regularisation: its effect on positions and
    velocities is far below 1e-6, so the two models agree there at every contact end
    and at t = 5 s; and both show the seed's 9 alternating contacts."""
    literal, exact = seed_pair
    assert literal.status == exact.status == 0
    assert [c.plane for c in exact.contacts] == [c.plane for c in literal.contacts] \
        == ["floor", "ceiling"] * 4 + ["floor"]
    for a, b in zip(literal.contacts, exact.contacts):
        assert b.t_end == pytest.approx(a.t_end, abs=1e-6)
        np.testing.assert_allclose(b.velocity_after, a.velocity_after, atol=1e-6)
        np.testing.assert_allclose(b.angular_velocity_after, a.angular_velocity_after, atol=1e-6)
    np.testing.assert_allclose(exact.position[:, -1], literal.position[:, -1], atol=1e-6)
    np.testing.assert_allclose(exact.velocity[:, -1], literal.velocity[:, -1], atol=1e-6)


def test_seed_scene_comes_back_at_the_first_ceiling_contact(seed_pair):
    """The seed's published run: x-velocity -2.63 -> +2.20 m/s at the first ceiling
    contact (shared NOTES, measured on the seed's own code)."""
    _, exact = seed_pair
    ceiling = exact.contacts[1]
    assert ceiling.velocity_before[0] == pytest.approx(-2.63, abs=0.01)
    assert ceiling.velocity_after[0] == pytest.approx(2.20, abs=0.01)


def test_phase_times_add_up_to_the_contact(seed_pair):
    """The stick and slip times come from the transition events and fill the contact."""
    _, exact = seed_pair
    for contact in exact.contacts:
        times = [t for t, _ in contact.transitions] + [contact.t_end]
        assert times[0] == contact.t_start and np.all(np.diff(times) >= 0)
        assert contact.time_sticking + contact.time_slipping == pytest.approx(
            contact.duration, rel=1e-12)


def test_stick_force_holds_the_slip_velocity(rng):
    """In stick mode the constraint force makes du/dt = 0 exactly (the equations of
    motion, evaluated independently by the right-hand side), and sits in or out of the
    cone as the margin says."""
    scene = ballc.Scene(mixture=0.375)
    params = scene.parameter_vector()
    for plane, index in (("floor", 0), ("ceiling", 1)):
        flags = (_core.FLAGS["observer"] | _core.FLAGS[f"{plane}_friction"]
                 | _core.FLAGS[f"{plane}_digin"] | _core.FLAGS[f"{plane}_stick"])
        du_dx = _core.slip_map(params, index)
        for _ in range(30):
            y = scene.initial_state()
            y[4:7] = [0, 0, rng.uniform(0.6, 0.95) if plane == "floor" else 9.3]
            y[7:13] = rng.uniform(-5, 5, 6)
            y[:4] = rng.normal(size=4)
            y[:4] /= np.linalg.norm(y[:4])
            latch = np.zeros(_core.N_LATCH)
            k = index * _core.N_LATCH_PER_PLANE
            latch[k] = rng.uniform(1, 20)
            d = rng.normal(size=3)
            latch[k + 1:k + 4] = d / np.linalg.norm(d)
            ydot = _core.rhs(y, params, latch, flags)
            assert np.max(np.abs(du_dx @ ydot)) <= 1e-12 * np.max(np.abs(ydot))
            lam_x, lam_y, load, margin = _core.stick_state(y, params, latch, flags, index)
            assert margin == pytest.approx(scene.friction_coefficient * load
                                           - math.hypot(lam_x, lam_y), abs=1e-12 * load)


def test_remove_slip_is_an_impulse_at_the_contact_point(rng):
    """The projection at a stop is a tangential impulse at the contact point: it zeroes
    u, leaves vz and omega_z unchanged, and conserves the angular momentum about the
    contact point, m (r e_z) x v + I omega (no observer: a plain sphere)."""
    scene = ballc.Scene(observer_mass=0.0)
    params = scene.parameter_vector()
    inertia = scene.inertia[0]
    for _ in range(20):
        y = scene.initial_state()
        y[7:13] = rng.uniform(-5, 5, 6)
        out = _core.remove_slip(y, params, 0, 0)
        assert np.max(np.abs(_core.slip_map(params, 0) @ out)) <= 1e-14
        assert out[12] == pytest.approx(y[12], abs=1e-14)
        assert out[9] == pytest.approx(y[9], abs=1e-14)
        arm = [0.0, 0.0, scene.radius]

        def momentum(x):
            return scene.mass * np.cross(arm, x[10:13]) + inertia * x[7:10]
        np.testing.assert_allclose(momentum(out), momentum(y), atol=1e-13)
        assert np.array_equal(out[:7], y[:7]) and np.array_equal(out[13:], y[13:])


def test_a_slip_that_passes_by_zero_is_integrated_through():
    """The seed scene's contacts slip past u = 0, missing it by ~1e-5 m/s (the direction
    swings through 180 degrees in microseconds).  At rtol = 1e-8 the clear speed is
    ~2e-5 m/s: freezing the direction there and removing the miss at the stop as if it
    were integration error (the rule before PASS_FACTOR) left every post-contact
    velocity 130-250 x rtol off the 1e-12 run; integrated through, they are within
    0.5-7 x rtol (measured), bounded here by 20 x rtol.  The first 1.2 s (three
    contacts) are well conditioned."""
    tol = 1e-8
    reference = ballc.simulate(ballc.Scene(), 1.2, rtol=1e-12, atol=1e-12)
    result = ballc.simulate(ballc.Scene(), 1.2, rtol=tol, atol=tol)
    assert len(result.contacts) == len(reference.contacts) == 3
    for ours, ref in zip(result.contacts, reference.contacts):
        np.testing.assert_allclose(ours.velocity_after, ref.velocity_after, rtol=0,
                                   atol=20 * tol)
        np.testing.assert_allclose(ours.angular_velocity_after, ref.angular_velocity_after,
                                   rtol=0, atol=20 * tol / ballc.Scene().radius)


@pytest.mark.parametrize("tol", [1e-6, 1e-8])
def test_every_mu_mixture_throw_converges_with_the_tolerance(tol):
    """The 12 mu x mixture throws (1.2 s, three contacts, well conditioned): the final
    centre position (m), velocity (m/s) and r omega (m/s) are within 100 x rtol of the
    1e-12 run (speeds reach 36 m/s).  Measured worst: 32 x.  A rule whose error does not
    shrink with the tolerance fails here: freezing every slip that comes within 100 x
    the integration error of zero (the rule before PASS_FACTOR) left 130-290 x, and
    a PASS_FACTOR of 10 left 274 x (mu 0.4, mixture 0.7 at 1e-8)."""
    def final(result):
        return np.concatenate([result.position[:, -1], result.velocity[:, -1],
                               result.scene.radius * result.angular_velocity[:, -1]])
    for mu in (0.0, 0.1, 0.4, 0.8):
        for mixture in (0.0, 0.375, 0.7):
            scene = ballc.Scene(friction_coefficient=mu, mixture=mixture)
            reference = ballc.simulate(scene, 1.2, rtol=1e-12, atol=1e-12)
            result = ballc.simulate(scene, 1.2, rtol=tol, atol=tol)
            assert result.status == 0 and len(result.contacts) == len(reference.contacts)
            error = np.abs(final(result) - final(reference)).max()
            assert error <= 100 * tol, (mu, mixture, error / tol)


def test_the_seed_throw_converges_with_the_tolerance():
    """The seed's 5-s throw (nine contacts) at rtol = atol 1e-3 .. 1e-9, 1, 2 and 5 per
    decade: the final centre position (m) and velocity (m/s) are within 100 x rtol of
    the 1e-13 run.  Measured worst: 36 x.  Before stepping to events and PASS_FACTOR
    the error sat at 1.8e-6 .. 3.9e-6 from 1.5e-8 to 2e-9 (up to 1950 x) and was 2.2e-3
    at 2e-8; a STOP_FACTOR of 3 left 687 x at 5e-7.  The equal-error ratio against the
    seed's pipeline (benchmarks/seed_vs_ballc.py) rests on this."""
    scene = ballc.Scene()
    reference = ballc.simulate(scene, 5.0, rtol=1e-13, atol=1e-13)

    def final(result):
        return np.concatenate([result.position[:, -1], result.velocity[:, -1]])
    for exponent in range(3, 10):
        for mantissa in (5, 2, 1):
            tol = mantissa * 10.0 ** -exponent
            if tol > 1e-3:
                continue
            result = ballc.simulate(scene, 5.0, rtol=tol, atol=tol)
            assert result.status == 0 and len(result.contacts) == 9
            error = np.abs(final(result) - final(reference)).max()
            assert error <= 100 * tol, (tol, error / tol)


def test_loose_tolerances_finish_quickly_on_the_seed_scene():
    """No cliff: every tolerance from 1e-3 to 1e-8 finishes the 5-s seed throw with
    status 0 and fewer right-hand-side calls than the next tighter tolerance (the
    seed's own law needed millions of calls, or failed, between 1e-4 and 1e-7)."""
    calls = []
    for tol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        result = ballc.simulate(ballc.Scene(), 5.0, rtol=tol, atol=tol, max_nfev=200_000)
        assert result.status == 0, (tol, result.message)
        assert len(result.contacts) == 9
        calls.append(result.nfev)
    assert calls == sorted(calls)
    assert calls[-1] < 60_000


@pytest.mark.parametrize("method", ["Radau", "BDF"])
def test_scipy_methods_use_the_same_events(method):
    """scipy's implicit methods run the same stick/slip modes (the release event is a
    Python callable through _core): same phases and outcome as radau5."""
    scene = skid_scene(0.3, 2.0)
    t_star = 2 * 2.0 / (7 * 0.3 * G)
    result = ballc.simulate(scene, 2 * t_star, method=method, rtol=1e-9, atol=1e-9)
    (contact,) = result.contacts
    assert [phase for _, phase in contact.transitions] == ["slip", "stick"]
    assert contact.transitions[1][0] == pytest.approx(t_star, rel=1e-6)
    assert result.velocity[0, -1] == pytest.approx(5 * 2.0 / 7, rel=1e-6)


def test_start_in_contact_latches_the_elastic_approach_rate():
    """A scene that starts with penetration rho and rate rhodot latches the rate an
    elastic approach would have had there: 1/2 m r'^2 = 1/2 m rhodot^2 + 2/5 k0 rho^5/2."""
    scene = ballc.Scene(observer_mass=0.0, position=(0, 0, 0.9), velocity=(0, 0, -0.3))
    rho, rate = 0.1, 0.3
    expected = math.sqrt(rate ** 2 + 0.8 * scene.hertz_stiffness * rho ** 2.5 / scene.mass)
    result = ballc.simulate(scene, 0.5)
    assert result.contacts[0].t_start == 0.0
    assert result.contacts[0].penetration_rate_at_impact == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("plane", ["floor", "ceiling"])
def test_start_in_contact_latch_counts_the_observer_mass(plane):
    """The same latch with an observer as heavy as the ball: the whole moving mass
    m_total = m + m_o carries the kinetic energy, 1/2 m_total r'^2 = 1/2 m_total rhodot^2
    + 2/5 k0 rho^5/2 (2/5 k0 rho^5/2 = the Hertz force's work, integral of k0 s^3/2 ds),
    rho and rhodot from the centre's height and vertical speed.  The C loop
    latches it."""
    H, r = 10.0, 1.0
    z, vz = (0.9, -0.3) if plane == "floor" else (H - 0.9, 0.3)
    scene = ballc.Scene(mass=1.0, observer_mass=1.0, radius=r, ceiling_height=H,
                        position=(0.3, -0.2, z), velocity=(0.4, 0.1, vz),
                        angular_velocity=(2.0, -1.0, 0.5))
    rho = r - z if plane == "floor" else z + r - H           # 0.1 m
    rate = -vz if plane == "floor" else vz                    # 0.3 m/s, approaching
    m_total = scene.mass + scene.observer_mass
    expected = math.sqrt(rate ** 2 + 2 * (2 / 5) * scene.hertz_stiffness * rho ** 2.5 / m_total)
    ball_only = math.sqrt(rate ** 2 + 0.8 * scene.hertz_stiffness * rho ** 2.5 / scene.mass)
    assert ball_only > 1.3 * expected                        # the observer matters here
    result = ballc.simulate(scene, 0.05)
    first = result.contacts[0]
    assert first.plane == plane and first.t_start == 0.0
    assert first.penetration_rate_at_impact == pytest.approx(expected, rel=1e-9)


def test_uses_exact_coulomb_only_where_there_is_coulomb_friction():
    assert stickslip.uses_exact_coulomb(ballc.Scene())
    assert stickslip.uses_exact_coulomb(ballc.Scene(tangential_model="friction"))
    assert not stickslip.uses_exact_coulomb(ballc.Scene(friction_regularization="max"))
    assert not stickslip.uses_exact_coulomb(ballc.Scene(tangential_model="dig-in"))
    assert not stickslip.uses_exact_coulomb(ballc.Scene(tangential_model="compliant"))
    assert not stickslip.uses_exact_coulomb(ballc.Scene(friction_coefficient=0.0))


WORK_PRECISION_SCENES = {
    "seed": (ballc.Scene(), 5.0),
    "friction": (ballc.Scene(tangential_model="friction"), 5.0),
    "mu 0.1 mixture 0": (ballc.Scene(friction_coefficient=0.1, mixture=0.0), 1.2),
    "mu 0.4 mixture 0.375": (ballc.Scene(friction_coefficient=0.4, mixture=0.375), 1.2),
    "mu 0.8 mixture 0.7": (ballc.Scene(friction_coefficient=0.8, mixture=0.7), 1.2),
}


@pytest.mark.parametrize("name", list(WORK_PRECISION_SCENES))
def test_work_precision_has_no_cliff(name):
    """rtol = atol from 1e-3 to 1e-12: every run finishes (status 0), a looser
    tolerance never costs more calls than the next tighter one, and the final error
    (against 1e-13) falls by orders of magnitude every three decades of tolerance."""
    scene, t_end = WORK_PRECISION_SCENES[name]
    reference = ballc.simulate(scene, t_end, rtol=1e-13, atol=1e-13)
    assert reference.status == 0
    calls, errors = [], {}
    for exponent in range(3, 13):
        tol = 10.0 ** -exponent
        result = ballc.simulate(scene, t_end, rtol=tol, atol=tol, max_nfev=500_000)
        assert result.status == 0, (tol, result.message)
        calls.append(result.nfev)
        errors[exponent] = np.max(np.abs(result.y[4:13, -1] - reference.y[4:13, -1]))
    assert calls == sorted(calls), calls
    assert errors[3] > errors[6] > errors[9] > errors[12], errors
    assert errors[3] < 0.2 and errors[9] < 1e-6


def test_a_ten_micron_steel_ball_settles_to_rolling():
    """Kratos's Chung & Ooi test 5 ball (steel, R = 10 um, e = 1, mu = 0.3) at
    V_t / (mu V_n) = 3 < 3.5 (1 + e): the rigid Coulomb map says it leaves rolling at
    5/7 of its tangential speed.  Its slip stops within ~1e-16 s of a 1e-8-s contact:
    the stop event must be found inside such short steps (it once fired at the step's
    start, 100,000 times)."""
    radius, density = 1e-5, 7850.0
    mass = 4 / 3 * math.pi * radius ** 3 * density
    v_n, v_t = 3.9, 0.9 * 3.9
    scene = ballc.Scene(mass=mass, radius=radius, inertia=(0.4 * mass * radius ** 2,) * 3,
                        observer_mass=0.0, gravity=0.0, ball_youngs_modulus=2.08e11,
                        plane_youngs_modulus=2.08e11, ball_poisson_ratio=0.3,
                        plane_poisson_ratio=0.3, c_tau=1.0, friction_coefficient=0.3,
                        tangential_model="friction", ceiling_height=1.0,
                        position=(0, 0, radius * (1 + 1e-6)), velocity=(v_t, 0, -v_n))
    result = ballc.simulate(scene, 2e-7, rtol=1e-10, atol=1e-16, max_nfev=200_000)
    assert result.status == 0, result.message
    (contact,) = result.contacts
    assert [phase for _, phase in contact.transitions] == ["slip", "stick"]
    assert contact.velocity_after[0] == pytest.approx(5 / 7 * v_t, rel=1e-6)
    assert contact.velocity_after[2] == pytest.approx(v_n, rel=1e-6)


def test_re_arming_an_approach_changes_the_path_not_the_result():
    """The compiled integrators re-arm a free slip's approach event where the C loop's
    decision is to re-latch it (a slip swinging past zero fires it 3-7 times within a
    microsecond), instead of ending the segment: the seed's first 1.2 s at 1e-8 make
    several re-latches inside segments (the log counts them, each one segment fewer),
    and the contacts come out within 20 x rtol of the 1e-12 run, whose re-latches fall
    elsewhere (test_a_slip_that_passes_by_zero_is_integrated_through)."""
    tol = 1e-8
    ours = ballc.simulate(ballc.Scene(), 1.2, rtol=tol, atol=tol)
    tight = ballc.simulate(ballc.Scene(), 1.2, rtol=1e-12, atol=1e-12)
    assert ours.status == tight.status == 0
    assert len(ours.contacts) == len(tight.contacts) == 3
    rearmed = ours.segments[ours.segments["rearms"] > 0]   # where, in the C loop's log
    assert ours.segments["rearms"].sum() >= 3
    assert set(rearmed["rearm_kind"]) == {"approach"}
    assert set(rearmed["rearm_before"]) == set(rearmed["rearm_after"]) == {"slip"}
    for a, b in zip(ours.contacts, tight.contacts):
        assert [p for _, p in a.transitions] == [p for _, p in b.transitions]
        np.testing.assert_allclose(a.velocity_after, b.velocity_after, rtol=0, atol=20 * tol)
        np.testing.assert_allclose(a.angular_velocity_after, b.angular_velocity_after,
                                   rtol=0, atol=20 * tol / ballc.Scene().radius)


def test_each_sample_keeps_the_slip_direction_it_was_computed_with():
    """A re-armed approach changes the latched slip direction d within a segment; the
    free slip's force is along u/|u| turned by d only where u . d < 0, so each stored
    sample must carry the d in force when it was computed (its contact forces are
    evaluated again from it).  Then every free-slip sample has u . d > 0; with the
    segment's last d for all of them, the seed's samples before a swing past zero
    would have u . d < 0 (their forces re-evaluated with the wrong sign)."""
    scene = ballc.Scene()
    result = ballc.simulate(scene, 1.2, rtol=1e-8, atol=1e-8)
    params = scene.parameter_vector()
    checked = 0
    for plane in ("floor", "ceiling"):
        free = (result.flags & _core.FLAGS[f"{plane}_slip"]) != 0
        first = _core.LATCH_NAMES.index(f"{plane}_slip_direction_x")
        rows = slice(first, first + 2)
        for k in np.flatnonzero(free):
            u = stickslip.slip_velocity(params, plane, result.y[:, k])
            d = result.latch[rows, k]
            assert u @ d > 0, (plane, result.t[k], u, d)
            checked += 1
    assert checked > 50


# --- issue 21, section 6: the stick release and a slip from rest against closed forms ---
#
# The scene: a plain solid sphere (no observer, I = 2/5 m r^2, gravity off) hits the
# floor at v = (u0, 0, -w0) without spin, with the mixture law: the friction share
# (1 - m) x [Hertz-Hunt-Crossley normal + Coulomb] plus the dig-in share m, a force
# -F_d d along the contact-point velocity d latched at impact, d = (u0, 0, -w0) / |v|
# (codegen/contact.py: dig_in).  Written out here from the laws' definitions:
#
#   friction share's normal force  N   = (1 - m) F_H (1 + chi s),   s = rhodot / w0
#   dig-in force                   F_d = m F_H (1 + chi a s),       a = w0 / |v| = |d_z|
#
# F_H = k0 rho^(3/2), chi = 3/2 (1 - c_tau), rhodot = -v_z (the contact point is at
# -r e_z: its normal velocity is v_z).  Every tangential force acts at -r e_z, so with
# the contact point held (stick) the sphere needs no net tangential force at all
# (m a_t = T, I alpha = r T and a_t = r alpha give T = 0): the stick force is
# lambda = -(dig-in's tangential part) = +m F_H (1 + chi a s) b e_x, b = u0 / |v|, and
# the Coulomb cone |lambda| <= mu N reads, with A = m b and B = mu (1 - m),
#
#   A (1 + chi a s) <= B (1 + chi s).
#
# F_H cancels: stick holds down to the rate s* = (B - A) / (chi (a A - B)), where the
# contact must release -- a closed form for v_z at the release, v_z = -s* w0.

def _mixture_throw(mu, m, c_tau, u0=1.0, w0=1.0):
    return ballc.Scene(observer_mass=0.0, gravity=0.0, tangential_model="mixture",
                       mixture=m, c_tau=c_tau, friction_coefficient=mu,
                       position=(0.0, 0.0, 1.0 + 1e-3), velocity=(u0, 0.0, -w0))


@pytest.mark.parametrize("s_star", [0.3, -0.2])
def test_stick_releases_where_the_coulomb_cone_says(s_star):
    """Oracle: the cone condition above, in closed form.  mu is chosen so that stick
    must end at the rate s = s* (0.3: while the ball still moves in; -0.2: on its way
    out, Hunt-Crossley e = 0.663 at c_tau = 0.5): the release must come at
    v_z = -s* w0 (measured: within 2e-11 m/s at 1e-10), with |lambda| / mu N, computed
    from the state with the laws above, below 1 at every stick sample and 1 at the
    release.  Through the stick the centre's tangential velocity and the spin stay
    constant (T = 0).  A cone off by 2 (|lambda| <= 2 mu N) releases at s = -1.00 / -1.05
    here, after the contact has ended: no release at all."""
    m, c_tau, u0, w0 = 0.5, 0.5, 1.0, 1.0
    chi = 1.5 * (1 - c_tau)
    speed = math.hypot(u0, w0)
    a, b = w0 / speed, u0 / speed
    A = m * b
    B = A * (1 + chi * a * s_star) / (1 + chi * s_star)     # so that the release is at s*
    mu = B / (1 - m)
    assert (B - A) / (chi * (a * A - B)) == pytest.approx(s_star, rel=1e-12)
    scene = _mixture_throw(mu, m, c_tau, u0, w0)
    result = ballc.simulate(scene, 0.15, rtol=1e-10, atol=1e-10)
    assert result.status == 0, result.message
    (contact,) = result.contacts
    assert [phase for _, phase in contact.transitions] == ["slip", "stick", "slip"]
    t_stick, t_release = contact.transitions[1][0], contact.transitions[2][0]

    r = scene.radius
    sigma = ((1 - scene.ball_poisson_ratio ** 2) / scene.ball_youngs_modulus
             + (1 - scene.plane_poisson_ratio ** 2) / scene.plane_youngs_modulus)
    k0 = 4 / 3 / sigma * math.sqrt(r)

    def cone_ratio(k):
        """|lambda| / (mu N) at sample k, from the state and the laws written above."""
        rho = r - result.position[2, k]
        s = -result.velocity[2, k] / w0
        f_h = k0 * rho ** 1.5
        return (m * f_h * (1 + chi * a * s) * b) / (mu * (1 - m) * f_h * (1 + chi * s))

    release = np.flatnonzero(result.t == t_release)[0]     # the state at the event
    assert -result.velocity[2, release] / w0 == pytest.approx(s_star, abs=1e-8)
    assert cone_ratio(release) == pytest.approx(1.0, abs=1e-8)
    sticking = np.flatnonzero((result.t >= t_stick) & (result.t < t_release))
    assert len(sticking) > 10
    assert max(cone_ratio(k) for k in sticking) < 1
    # stuck: no net tangential force, the contact point at rest
    for row in (result.velocity[0], result.angular_velocity[1]):
        assert np.ptp(row[sticking]) <= 1e-9
    slip = result.velocity[0] - r * result.angular_velocity[1]
    assert np.max(np.abs(slip[sticking])) <= 1e-12
    # after the release the contact point slips back, along -lambda = -e_x
    after = result.t > t_release
    assert slip[after][-1] < -1e-3


def _settles(result, plane):
    """[(mode, slip direction, v_z)] of each settle on ``plane`` the C loop's segment log
    reports: a stop whose slip was left within the integration error ends in stick or
    in a slip from rest (slip_fixed), and one beyond it slips on (slip).  The direction
    is the one latched for the next segment (its samples' latch; None for stick; NaN
    when the run stopped there), v_z the state's at the stop (the segment's last
    sample)."""
    segments = result.segments
    k = layout.PLANES.index(plane)
    columns = [_core.LATCH_NAMES.index(f"{plane}_slip_direction_{axis}") for axis in "xy"]
    found = []
    for row in segments[(segments["end"] == "stop") & (segments["plane"] == plane)]:
        mode = str(row["after"][k])
        if mode == "slip":
            continue
        at = np.flatnonzero(result.t == row["t_end"])[-1]
        direction = None
        if mode == "slip_fixed":
            direction = result.latch[columns, at + 1] if at + 1 < result.t.size else (
                np.full(2, np.nan))
        found.append((mode, direction, float(result.velocity[2, at])))
    return found


def test_a_slip_from_rest_leaves_along_minus_lambda_and_friction_dissipates():
    """Oracle: closed forms of the same scene with c_tau = 1 (chi = 0: N = (1 - m) F_H,
    F_d = m F_H, both proportional to F_H, and the normal force conservative: v_z goes
    from -w0 to +w0).  mu = 0.3 < m b / (1 - m) = 0.71: the cone cannot hold the
    contact point, so where the slip has come to rest (settle) it slips on from rest
    along -lambda = -e_x, the way dig-in's tangential part pushes it, and friction
    turns round to +e_x, opposing that slip (dissipating: power mu N u_x < 0).  With
    the solid sphere's du = 3.5 dv_x and impulse ratios dv_x / dv_z =
    -(A +- B) / ((1 - m) + m a) before / after the settle:

        u after = 3.5 R_after (2 w0 - u0 / (3.5 |R_before|))   (= -1.2651 m/s)
        v_x after = u0 - u0 / 3.5 + u_after / 3.5              (= 0.35283 m/s)

    Measured: both within 1e-9 at 1e-10.  A slip from rest started along +lambda puts
    friction along the slip (it would inject energy): the slip turns against its
    direction at once and the run stalls (100,000 mode changes, status -1)."""
    m, mu, u0, w0 = 0.5, 0.3, 1.0, 1.0
    speed = math.hypot(u0, w0)
    a, b = w0 / speed, u0 / speed
    A, B = m * b, mu * (1 - m)
    assert A > B                                   # outside the cone: no stick
    r_before = -(A + B) / ((1 - m) + m * a)
    r_after = -(A - B) / ((1 - m) + m * a)
    scene = _mixture_throw(mu, m, 1.0, u0, w0)
    result = ballc.simulate(scene, 0.15, rtol=1e-10, atol=1e-10, max_nfev=100_000)
    settles = _settles(result, "floor")

    # the path: one settle, a slip from rest along -lambda / |lambda| = -e_x
    assert len(settles) >= 1
    mode, direction, vz_at_settle = settles[0]
    assert mode == "slip_fixed"
    np.testing.assert_allclose(direction, [-1.0, 0.0], atol=1e-12)
    # ... reached when u0 / 3.5 of tangential speed is gone, at dv_z = that / |R_before|
    assert vz_at_settle + w0 == pytest.approx(u0 / 3.5 / abs(r_before), rel=1e-8)
    assert len(settles) == 1 and result.status == 0, result.message
    (contact,) = result.contacts
    r = scene.radius
    slip = result.velocity[0] - r * result.angular_velocity[1]
    t_settle = result.t[np.argmin(np.abs(result.velocity[2] - vz_at_settle))]
    out = (result.t > t_settle) & (result.t <= contact.t_end)
    # the slip grows along -e_x from rest, and only grows (friction never drives it)
    assert np.all(slip[out] <= 1e-12) and np.all(np.diff(slip[out]) <= 1e-12)
    u_after = 3.5 * r_after * (2 * w0 - u0 / 3.5 / abs(r_before))
    assert contact.velocity_after[2] == pytest.approx(w0, abs=1e-9)
    assert slip[-1] == pytest.approx(u_after, abs=1e-9)
    # friction's share of the tangential impulse after the settle (the total, minus
    # dig-in's -A int F_H dt, int F_H dt = dv_z / ((1 - m) + m a)) points along +e_x,
    # against the slip (u_x <= 0 throughout): its power mu N u_x is <= 0, it dissipates
    k = np.flatnonzero(result.t == t_settle)[-1]
    dvx = contact.velocity_after[0] - result.velocity[0, k]
    dvz = contact.velocity_after[2] - result.velocity[2, k]
    friction_impulse = scene.mass * (dvx + A * dvz / ((1 - m) + m * a))
    assert friction_impulse == pytest.approx(scene.mass * B * dvz / ((1 - m) + m * a),
                                             rel=1e-8)
    assert friction_impulse > 0
    assert contact.velocity_after[0] == pytest.approx(u0 - u0 / 3.5 + u_after / 3.5,
                                                      abs=1e-9)
