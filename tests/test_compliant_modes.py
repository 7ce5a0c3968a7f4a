"""The compliant law's exact elastic/sliding modes (ballc.compliantmodes): each checked
against an independent oracle -- the self-similar start's closed-form ratio, the Coulomb
cap itself, the same run at a tighter tolerance -- not against ballc's own numbers."""
import math

import numpy as np
import pytest

import ballc
from ballc import _core, _radau5, layout
from validation.dem_reference import hertz_contact_time

PLANE_FLAGS = {"sliding": _core.FLAGS["floor_compliant_sliding"],
               "elastic": _core.FLAGS["floor_compliant_elastic"]}


def _impact_scene(**law):
    """A 5-mm steel-on-glass-like ball (no gravity, no observer), Hunt-Crossley."""
    return ballc.Scene(mass=4e-3, radius=5e-3, observer_mass=0.0, gravity=0.0,
                       ceiling_height=1.0, position=(0.0, 0.0, 0.5), velocity=(0, 0, -1),
                       ball_youngs_modulus=2e11, ball_poisson_ratio=0.3,
                       plane_youngs_modulus=7e10, plane_poisson_ratio=0.22,
                       tangential_model="compliant", **law)


@pytest.mark.parametrize("ratio", [0.8, 1.25])
def test_a_contact_starts_in_the_mode_of_its_self_similar_start(ratio):
    # Hunt-Crossley with chi = 3/2 (1 - c_tau): at the start rho = v_n t, F_n =
    # k0 rho^(3/2) (1 + chi), the elastic spring s = 2/3 v_t t (dilution), so
    # k_t |s| / (mu F_n) = kappa |v_t| / (mu (1 + chi) v_n) at every t: above 1 the
    # contact starts sliding, below it starts elastic (sticking)
    kappa, mu, c_tau, v_n = 0.7, 0.4, 0.5, 2.0
    chi = 1.5 * (1 - c_tau)
    v_t = ratio * mu * (1 + chi) * v_n / kappa
    scene = _impact_scene(c_tau=c_tau, tangential_stiffness_ratio=kappa,
                          friction_coefficient=mu)
    hit = ballc.impact(scene, (v_t, 0.0, -v_n))
    first = hit.result.contacts[0].transitions[0][1]
    assert first == ("slip" if ratio > 1 else "stick"), hit.result.contacts[0].transitions


def _samples(result, mode):
    """(F_n, |F_t|) of the floor at the samples computed in ``mode``, inside contact."""
    flags = np.asarray(result.flags)
    inside = (flags & PLANE_FLAGS[mode]) != 0
    latch = result.latch if result.latch.shape[0] == result.t.size else result.latch.T
    forces = _core.contact_forces_per_sample(
        np.ascontiguousarray(result.y.T[inside]), result.scene.parameter_vector(),
        np.ascontiguousarray(latch[inside]), np.ascontiguousarray(flags[inside], np.int64))
    return forces[:, 2], np.hypot(forces[:, 0], forces[:, 1])


def test_sliding_carries_the_cap_and_elastic_stays_below_it():
    # a spinning oblique impact that slides, sticks and slides again
    scene = _impact_scene(c_tau=0.5, tangential_stiffness_ratio=0.6, friction_coefficient=0.3)
    hit = ballc.impact(scene, (1.0, 0.3, -2.0), (40.0, -90.0, 30.0), rtol=1e-10)
    phases = [phase for _, phase in hit.result.contacts[0].transitions]
    assert "slip" in phases and "stick" in phases, phases
    mu = scene.friction_coefficient
    f_n, f_t = _samples(hit.result, "sliding")
    loaded = f_n > 1e-6 * f_n.max()
    assert loaded.sum() > 10
    np.testing.assert_allclose(f_t[loaded], mu * f_n[loaded], rtol=1e-12)
    f_n, f_t = _samples(hit.result, "elastic")
    assert f_n.size > 10
    assert np.all(f_t <= mu * f_n * (1 + 1e-5) + 1e-12 * f_n.max())


def test_mode_changes_converge_with_the_tolerance():
    # the seed's throw with the compliant law (observer included): the times of every
    # contact start and mode change at rtol 1e-8 within 1e-6 s of those at 1e-11 (no
    # decision flips with the tolerance), and the final state within 1e-4
    scene = ballc.Scene(tangential_model="compliant")
    loose, tight = (ballc.simulate(scene, 1.2, rtol=tol, atol=tol) for tol in (1e-8, 1e-11))
    assert loose.status == tight.status == 0
    assert len(loose.contacts) == len(tight.contacts) >= 3
    for a, b in zip(loose.contacts, tight.contacts):
        assert [p for _, p in a.transitions] == [p for _, p in b.transitions]
        times_a = np.array([t for t, _ in a.transitions])
        times_b = np.array([t for t, _ in b.transitions])
        assert np.abs(times_a - times_b).max() < 1e-6, (a.transitions, b.transitions)
    assert np.abs(loose.y[:13, -1] - tight.y[:13, -1]).max() < 1e-4


def test_the_smooth_yield_stays_an_option_and_agrees():
    # friction_regularization "smooth" runs the law without modes: no sliding kernel
    # ever runs, and the rebound is within 1 % of the exact modes' (the smooth yield's
    # measured difference from the DEM truncation)
    kwargs = dict(c_tau=0.5, tangential_stiffness_ratio=0.6, friction_coefficient=0.3)
    exact = ballc.impact(_impact_scene(**kwargs), (1.0, 0.3, -2.0), (40.0, -90.0, 30.0))
    smooth = ballc.impact(_impact_scene(friction_regularization="smooth", **kwargs),
                          (1.0, 0.3, -2.0), (40.0, -90.0, 30.0))
    assert not np.any(np.asarray(smooth.result.flags) & PLANE_FLAGS["sliding"])
    assert not smooth.result.contacts[0].transitions
    speed = math.hypot(1.0, 0.3, 2.0)
    assert np.abs(exact.velocity_after - smooth.velocity_after).max() < 0.01 * speed


def test_a_hard_ball_s_small_bounces_end_without_stalling():
    # work_precision's "steel, compliant" scene: a steel-hard ball bouncing lower and lower
    # then rolling.  Its contacts end with a nearly relaxed spring, where the yield margin
    # (-1 without load) fires at the load's last instant; sliding on a rounding-level
    # spring there stalled radau5 (t = 2.215 s).  Oracle: the run at a tighter tolerance,
    # and the energy balance.
    steel = dict(ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, c_tau=0.5,
                 observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))
    scene = ballc.Scene(tangential_model="compliant", **steel)
    loose, tight = (ballc.simulate(scene, 5.0, rtol=tol, atol=tol) for tol in (1e-8, 1e-10))
    assert loose.status == tight.status == 0, (loose.message, tight.message)
    assert len(loose.contacts) >= 10
    assert np.abs(loose.y[:13, -1] - tight.y[:13, -1]).max() < 1e-6
    energy = tight.energy
    assert np.all(np.diff(energy["dissipated_tangential"]) >= -1e-12 * energy["total"][0])


@pytest.mark.parametrize("regularization", ["exact", "smooth"])
def test_without_friction_the_tangential_state_is_untouched(regularization):
    # mu = 0: no tangential force (the cap is 0, the spring stays relaxed), so with a
    # massless observer the in-plane velocity and the spin pass every contact unchanged
    # (before: both laws crawled at the first contact, 5e6 calls, the spring turning at
    # |v_t| / |s| with |s| ~ 1e-10 m)
    scene = ballc.Scene(tangential_model="compliant", friction_coefficient=0.0,
                        observer_mass=0.0, angular_velocity=(3.0, -2.0, 1.0),
                        friction_regularization=regularization)
    result = ballc.simulate(scene, 2.0, rtol=1e-8, atol=1e-10, max_nfev=200_000)
    assert result.status == 0 and len(result.contacts) >= 3
    v, w = result.y[layout.VELOCITY], result.y[layout.ANGULAR_VELOCITY]
    assert np.abs(v[:2] - np.array(scene.velocity[:2])[:, None]).max() <= 1e-12
    assert np.abs(w - np.array(scene.angular_velocity)[:, None]).max() <= 1e-12
    assert result.energy["tangential_spring"].max() == 0.0


def test_a_short_stick_phase_is_not_stepped_over_at_a_loose_tolerance():
    # Oracle: the same scene at a tight tolerance.  The seed's compliant ceiling contact
    # (0.574 .. 0.636 s) sticks from 0.618 to 0.632 s; dop853 at rtol 1e-4 took that
    # contact in 3 steps, the last from 0.614 s to the contact's end with the re-stick
    # margin positive at both ends: it slid through (phases ['slip'] instead of
    # ['slip', 'stick', 'slip']) and ended 0.63 off.  Steps within a compliant contact
    # are now at most t_c / 16 (compliantmodes.largest_step).
    scene = ballc.Scene(tangential_model="compliant")
    reference = ballc.simulate(scene, 5.0, rtol=1e-10, atol=1e-10)
    loose = ballc.simulate(scene, 5.0, method="dop853", rtol=1e-4, atol=1e-4)
    phases = [[phase for _, phase in c.transitions] for c in loose.contacts]
    assert phases == [[phase for _, phase in c.transitions] for c in reference.contacts]
    error = max(np.max(np.abs(loose.position[:, -1] - reference.position[:, -1])),
                np.max(np.abs(loose.velocity[:, -1] - reference.velocity[:, -1])))
    assert error < 1e-2, error


@pytest.mark.parametrize("method", ["dop853", "radau5"])
def test_steps_within_a_compliant_contact_are_a_fraction_of_its_hertz_time(method):
    # Oracle: the elastic Hertz contact time at each contact's latched impact rate, from
    # validation/dem_reference.py (its exact constant, 3.218..., above ballc's 3.2145)
    scene = ballc.Scene(tangential_model="compliant")
    run = ballc.simulate(scene, 1.2, method=method, rtol=1e-3, atol=1e-3)
    assert len(run.contacts) == 3
    for contact in run.contacts:
        inside = (run.t >= contact.t_start) & (run.t <= contact.t_end)
        steps = np.diff(run.t[inside])
        t_c = hertz_contact_time(scene.mass + scene.observer_mass, scene.hertz_stiffness,
                                 contact.penetration_rate_at_impact)
        assert steps.size >= 8
        assert steps.max() <= t_c / ballc.compliantmodes.STEPS_PER_CONTACT * (1 + 1e-12)


def test_the_sliding_spring_turns_with_the_slip_as_the_dem_truncation_does():
    # Oracle: the DEM codes' truncation step (validation/dem_reference.py's algorithm),
    # written out here.  At the cap the elastic force is F = -k_t s with |k_t s| = mu F_n;
    # one step adds the slip, s_trial = s + v_t dt, and the force is put back on the cap
    # along s_trial: the direction e = s/|s| turns at de/dt = (v_t - (e . v_t) e) / |s|,
    # so the part of ds/dt across e is the part of v_t across e, whatever happens to |s|.
    # A spring held in its direction while sliding (the slip turning, not the force)
    # leaves that part 0.  State: a sliding floor contact with s along y and the slip
    # along x (no spin, so the slip is the centre's velocity), |s| = 1 um.
    scene = ballc.Scene(tangential_model="compliant", observer_mass=0.0)
    y = scene.initial_state()
    rho, v_t = 1e-3 * scene.radius, (0.7, 0.0)
    y[layout.INDEX["z"]] = scene.radius - rho
    y[layout.VELOCITY] = (v_t[0], v_t[1], -0.5)
    y[layout.ANGULAR_VELOCITY] = 0.0
    s = np.array([0.0, 1e-6])
    y[layout.DEFLECTION["floor"]] = s
    latch = np.zeros(_core.N_LATCH)
    latch[0], latch[1:4] = 1.0, (1.0, 0.0, 0.0)   # the impact's rate and dig-in direction
    flags = _core.FLAGS["floor_compliant_sliding"]   # the sliding mode's kernels alone
    rate = _core.System(scene.parameter_vector(), latch, flags)(0.0, y)[
        layout.DEFLECTION["floor"]]
    # the DEM step, dt -> 0: e(dt) = (s + v_t dt) / |s + v_t dt|
    dt = 1e-9 * np.linalg.norm(s) / np.linalg.norm(v_t)
    trial = s + np.array(v_t) * dt
    turned = (trial / np.linalg.norm(trial) - s / np.linalg.norm(s)) / dt * np.linalg.norm(s)
    assert rate[0] == pytest.approx(turned[0], rel=1e-6)    # across e: v_t's part
    assert rate[0] == pytest.approx(v_t[0], rel=1e-6)


def test_the_compliant_throw_converges_across_the_viscous_capacity_kink():
    """The elastic mode's viscous damping is cut to the capacity the elastic force leaves:
    a kink of the force and of the dissipation rate, which radau5's error estimate
    stepped over at rtol 1e-9 (1.5e-6 J of tangential work in one step; the error then
    stalled at ~1.5e-6 from rtol 1e-8 to 1e-9).  The capacity guard makes the integrator
    step to it.  Oracle: convergence -- the error against a 1e-12 run falls with the
    tolerance."""
    scene = ballc.Scene(tangential_model="compliant")
    runs = {tol: ballc.simulate(scene, 5.0, rtol=tol, atol=tol) for tol in (1e-12, 1e-9, 1e-8)}
    reference = runs[1e-12].y[:, -1]
    error = {tol: np.max(np.abs(runs[tol].y[:, -1] - reference)) for tol in (1e-9, 1e-8)}
    assert error[1e-9] < 1e-7 and error[1e-8] < 1e-6, error


@pytest.mark.parametrize("vy", [-3.0, 3.0])
def test_a_sliding_start_puts_the_spring_along_the_slip(vy):
    """A contact that starts sliding (mu = 0.2, a slip of ~3 m/s against an approach of
    ~3.7 m/s) puts its spring at the cap along the slip velocity: no spin, so the slip
    is the horizontal velocity (1, vy), and the deflection right after the start points
    that way (closed form: the direction of u), with either sign of u_y."""
    scene = ballc.Scene(tangential_model="compliant", observer_mass=0.0, friction_coefficient=0.2,
                        position=(0.0, 0.0, 1.5), velocity=(1.0, vy, -2.0))
    result = ballc.simulate(scene, 0.2)
    first = result.contacts[0]
    assert first.transitions[0] == (first.t_start, "slip")
    after = np.searchsorted(result.t, first.t_start, side="right")
    names = ballc.STATE_NAMES
    s = result.y[[names.index("floor_deflection_x"), names.index("floor_deflection_y")], after]
    u = result.y[[names.index("vx"), names.index("vy")], after]
    assert np.dot(s, u) / (np.linalg.norm(s) * np.linalg.norm(u)) > 1 - 1e-6


@pytest.mark.parametrize("mode", ["sliding", "elastic"])
def test_a_step_ending_exactly_at_a_leaving_contacts_end_converges(mode):
    """A compliant contact leaves with a deflection (the spring stops moving below the
    kernels' 1e-12 N force floor, so |s| ~ 5e-13 m is left when rho reaches 0), and
    a step of radau5 can end exactly on rho = 0.  There the law carries nothing: with
    no adhesion its force and rates are 0 at rho <= 0 (checked below: the right-hand
    side is the flight's), so its Jacobian from that side is the flight's too.  Its
    kernels' derivatives at rho = 0 were half the loaded side's, through the floors of
    rho and sqrt(rho) (1e-30 m): 7e27 W/m in the tangential dissipation's row, with
    which Newton failed and the run ended in 'step size less than spacing' (found as
    1 to 3 in 60 perturbed throws of Hefner's channel).  The stiff rough superball of
    that scene, on the floor: exactly at rho = 0, leaving at 2 m/s, slipping, spinning."""
    scene = ballc.Scene(radius=0.025, mass=0.05, observer_mass=0.0, ball_youngs_modulus=1e9,
                        plane_youngs_modulus=2e11, ball_poisson_ratio=0.49,
                        tangential_model="compliant", friction_coefficient=10.0,
                        restitution=1.0, tangential_stiffness_ratio=0.27,
                        tangential_damping_ratio=0.0)
    y = scene.initial_state()
    y[layout.INDEX["z"]] = scene.radius
    assert scene.radius - y[layout.INDEX["z"]] == 0.0          # rho = 0 exactly
    y[layout.VELOCITY] = (1.0, 0.0, 2.0)
    y[layout.ANGULAR_VELOCITY] = (0.0, 30.0, 0.0)
    y[layout.DEFLECTION["floor"]] = (5e-13, 0.0)
    latch = np.zeros(_core.N_LATCH)
    latch[0], latch[1:4] = 2.0, (0.0, 0.0, -1.0)
    params, flags = scene.parameter_vector(), PLANE_FLAGS[mode]
    for below in (0.0, -1e-15):   # at the end, and just past it (before the leave event)
        z = y.copy()
        z[layout.INDEX["z"]] = scene.radius - below
        np.testing.assert_array_equal(_core.rhs(z, params, latch, flags),
                                      _core.rhs(z, params, latch, 0))
        np.testing.assert_array_equal(_core.jacobian(z, params, latch, flags),
                                      _core.jacobian(z, params, latch, 0))
    sol = _radau5.solve_system(params, latch, flags, (1.0, 1.0 + 1e-6), y, rtol=1e-9,
                               atol=1e-11, max_nfev=20000)
    assert sol.status == 0, sol.message
