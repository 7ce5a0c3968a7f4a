"""The periodic end state (ballc.orbit): a ball with an eccentric observer that rolls on
with its wobble is continued as a relative periodic orbit.  Oracles: the integrator
itself running on through the same time (rest=False) at a tight tolerance, the group
law G^k = G...G applied k times, and the symmetry the closed form rests on, broken
on purpose."""
import math

import numpy as np
import pytest

import ballc
from ballc import layout, modes, orbit

_P, _V, _W = layout.POSITION, layout.VELOCITY, layout.ANGULAR_VELOCITY


def _after_the_orbit_starts(result, t_end, n=9):
    contact = result.contacts[-1]
    start = contact.t_rolling if contact.t_rolling == contact.t_rolling else contact.t_sliding
    assert start == start and start < t_end
    return np.linspace(start, t_end, n)


@pytest.fixture(scope="module")
def seed_reference():
    """The seed scene integrated on through 400 s at 1e-12, no end state."""
    return ballc.simulate(ballc.Scene(), 400.0, rest=False, rtol=1e-12, atol=1e-12,
                          dense_output=True)


@pytest.mark.parametrize("tol", [1e-6, 1e-8, None])
def test_the_orbit_is_as_accurate_as_integrating_on(seed_reference, tol):
    """The seed's ball rolls on from ~63 s as an orbit; its state over the next 340 s
    is as far from a 1e-12 integration as a plain integration at the same tolerance
    (the error is the history's, not the orbit's) -- and at the default tolerance
    within 1e-5 m and 1e-8 m/s."""
    options = {} if tol is None else {"rtol": tol, "atol": tol}
    run = ballc.simulate(ballc.Scene(), 400.0, dense_output=True, **options)
    plain = ballc.simulate(ballc.Scene(), 400.0, dense_output=True, rest=False, **options)
    assert "relative periodic orbit" in run.message and "relative" not in plain.message
    assert run.contacts[-1].transitions[-1] == (run.contacts[-1].t_rolling, "rolling")
    times = _after_the_orbit_starts(run, 400.0)
    exact = seed_reference.sol(times)
    for block in (_P, _V, _W, layout.QUATERNION):
        orbit_error = np.max(np.abs(run.sol(times)[block] - exact[block]))
        plain_error = np.max(np.abs(plain.sol(times)[block] - exact[block]))
        assert orbit_error <= 1.2 * plain_error + 1e-9, (block, orbit_error, plain_error)
    if tol is None:
        assert np.max(np.abs(run.sol(times)[_P] - exact[_P])) < 1e-5
        assert np.max(np.abs(run.sol(times)[_V] - exact[_V])) < 1e-8


@pytest.mark.parametrize("scene, t_end", [
    (ballc.Scene(tangential_model="friction"), 1500.0),    # rocks back and forth
    (ballc.Scene(ball_youngs_modulus=2e11, velocity=(-1.0, 1.0, -3.0)), 300.0),   # steel
])
def test_other_wobbling_balls_follow_the_integration(scene, t_end):
    run = ballc.simulate(scene, t_end, dense_output=True)
    reference = ballc.simulate(scene, t_end, rest=False, rtol=1e-12, atol=1e-12,
                               dense_output=True)
    assert run.status == 0 and "relative periodic orbit" in run.message
    times = _after_the_orbit_starts(run, t_end)
    got, exact = run.sol(times), reference.sol(times)
    assert np.max(np.abs(got[_P] - exact[_P])) < 1e-5
    assert np.max(np.abs(got[_V] - exact[_V])) < 1e-8
    assert np.max(np.abs(got[layout.QUATERNION] - exact[layout.QUATERNION])) < 1e-5


def test_the_seed_scene_finishes_a_billion_seconds():
    """Issue 21's target: status 0, the end state named, every sample finite, the
    energy balance closed (no drift warning), the last sample at t_end -- on the C loop
    (its trial and measurement in C, issue 29)."""
    run = ballc.simulate(ballc.Scene(), 1e9)
    assert run.status == 0 and run.t[-1] == 1e9
    assert "relative periodic orbit" in run.message and "drifted" not in run.message
    assert np.all(np.isfinite(run.y))
    assert run.t.size < 40_000
    start = run.contacts[-1].t_rolling
    assert 30 < start < 100
    # the centre stays at the rolling height; the speed is the rolling speed
    late = run.t > start
    z = run.y[layout.INDEX["z"], late]
    assert np.ptp(z) < 1e-6
    speed = np.hypot(*run.y[_V][:2, late])
    assert 0.79 < speed.min() <= speed.max() < 0.82


def test_a_power_of_the_motion_is_the_motion_applied_again_and_again():
    rng = np.random.default_rng(7)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    motion = orbit.Motion(0.37, (1.5, -0.4), -2.1, axis, dissipated=(1e-3, 2e-3))
    y = ballc.Scene().initial_state()
    y[_W] = (0.3, -0.2, 0.5)
    y[layout.DEFLECTION["floor"]] = (1e-4, -2e-4)
    repeated = y.copy()
    for k in range(8):
        np.testing.assert_allclose(motion.apply(y, k), repeated, rtol=0, atol=1e-12)
        repeated = motion.apply(repeated)
    # and backwards: G^-k undoes G^k
    np.testing.assert_allclose(motion.apply(motion.apply(y, 5), -5), y, rtol=0, atol=1e-12)
    # over many columns at once, k per column
    ks = np.arange(8)
    many = motion.apply(np.repeat(y[:, None], ks.size, axis=1), ks)
    for k in ks:
        np.testing.assert_allclose(many[:, k], motion.apply(y, k), rtol=0, atol=1e-14)
    # a turn by 0: the shift adds up k times
    straight = orbit.Motion(0.0, (1.5, -0.4), 0.0, axis)
    np.testing.assert_allclose(straight.apply(y, 5)[_P][:2], y[_P][:2] + (7.5, -2.0))


def test_the_motion_keeps_the_quaternion_a_rotation_about_the_balls_axis():
    """G turns the ball about its own axis: the axis in space turns only about the
    vertical, and its tilt (a_z) is unchanged."""
    scene = ballc.Scene()
    axis = orbit.body_axis(scene)
    y = scene.initial_state()
    y[layout.QUATERNION] = (0.8, 0.2, -0.5, 0.26)
    y[layout.QUATERNION] /= np.linalg.norm(y[layout.QUATERNION])
    moved = orbit.Motion(1.1, (0, 0), 2.3, axis).apply(y)
    assert math.isclose(orbit.tilt(moved, axis), orbit.tilt(y, axis), abs_tol=1e-14)
    turned_by_psi_only = orbit.Motion(0.0, (0, 0), 2.3, axis).apply(y)
    rotation = ballc.orientation.rotation_matrix
    np.testing.assert_allclose(rotation(turned_by_psi_only[:4]) @ axis,
                               rotation(y[:4]) @ axis, atol=1e-14)


def test_a_latched_dig_in_direction_breaks_the_symmetry():
    """Criterion 2: the dig-in law pushes along a direction latched in space, so turning
    the scene does not turn its force: not equivariant.  Coulomb's stick is."""
    for model, expected in (("dig-in", False), ("friction", True)):
        scene = ballc.Scene(tangential_model=model)
        y = scene.initial_state()
        y[layout.INDEX["z"]] = scene.radius - 0.01
        y[_V] = (0.4, -0.3, -0.1)
        y[_W] = (0.2, 0.5, 0.1)
        flags = modes.flags(scene, {"floor": True, "ceiling": False})
        latch = np.zeros(ballc._core.N_LATCH)
        latch[0] = 0.3
        latch[1:4] = (0.6, 0.0, -0.8)
        got = orbit.equivariant(scene.parameter_vector(), latch, flags, y,
                                orbit.body_axis(scene))
        assert got is expected, model


def test_a_wobble_that_is_not_a_relative_periodic_orbit_is_integrated():
    """Criterion 4: without friction a wobbling ball slides on at its constant momentum
    while its wobble precesses -- periodic only in a moving frame, not up to a turn and
    a shift of the scene.  Its trials are refused (the misfit is ~1e10 tolerances) and
    the run integrates on."""
    scene = ballc.Scene(tangential_model="friction", friction_coefficient=0.0)
    run = ballc.simulate(scene, 3000.0)
    assert run.status == 0 and "orbit" not in run.message
    contact = run.contacts[-1]
    assert math.isnan(contact.t_rolling) and math.isnan(contact.t_sliding)


def test_a_ball_that_slides_freely_goes_on_uniformly():
    """mu = 0, massless observer: the ball ends up sliding on the floor for ever; from
    the uniform check on, the state is the closed form, equal to integrating on."""
    scene = ballc.Scene(tangential_model="friction", friction_coefficient=0.0,
                        observer_mass=0.0)
    run = ballc.simulate(scene, 100.0, dense_output=True)
    contact = run.contacts[-1]
    assert "slides uniformly" in run.message
    assert math.isnan(contact.t_rolling) and 30 < contact.t_sliding < 100
    assert contact.transitions[-1] == (contact.t_sliding, "free_sliding")
    reference = ballc.simulate(scene, 100.0, rest=False, rtol=1e-12, atol=1e-12,
                               dense_output=True)
    times = np.linspace(contact.t_sliding, 100.0, 5)
    np.testing.assert_allclose(run.sol(times)[_P], reference.sol(times)[_P], atol=1e-6)
    np.testing.assert_allclose(run.sol(times)[_V], reference.sol(times)[_V], atol=1e-8)
    assert np.hypot(*run.y[_V][:2, -1]) > 1.0   # it slides: no friction slowed it


def test_the_sampled_orbit_is_its_dense_output():
    run = ballc.simulate(ballc.Scene(), 1e6, dense_output=True)
    late = run.t > run.contacts[-1].t_rolling
    np.testing.assert_allclose(run.sol(run.t[late]), run.y[:, late], rtol=0, atol=1e-12)


def test_a_refused_trial_is_not_followed_by_another_at_once():
    """A fast-spinning wobbling ball whose wobble still changes refuses trial after trial:
    the next starts only at the next scheduled rest check, not where the last ended (770
    back-to-back trials made such a run 78 % slower).  The C loop logs its trials."""
    run = ballc.simulate(ballc.Scene(angular_velocity=(0, 0, 30)), 120.0)
    trials = run._orbit_trials
    assert run.status == 0 and len(trials) >= 2
    assert not any(accepted for *_, accepted in trials)
    for (_, end, _), (start, _, _) in zip(trials, trials[1:]):
        assert start > end, trials


def _synthetic_orbit(scene, period, turn, spin, centre):
    """y(t) of a made-up relative periodic orbit, exact by construction: the ball's axis
    a tilts periodically, theta(t) = 0.4 + 0.2 sin(2 pi t / T), while the scene turns
    about the vertical at ``turn`` rad/s about ``centre`` and the ball spins about a
    at ``spin`` rad/s; so y(t + T) = G y(t) with phi = turn T, psi = spin T,
    d = centre - R(phi) centre and the work T times its rate."""
    axis = orbit.body_axis(scene)
    q_of = ballc.orientation.quaternion_multiply

    def about(angle, direction):
        half = 0.5 * np.asarray(angle)[..., None]
        return np.concatenate([np.cos(half), np.sin(half) * np.asarray(direction)], axis=-1)

    def sol(t):
        t = np.asarray(t, dtype=float)
        theta = 0.4 + 0.2 * np.sin(2 * np.pi * t / period)
        q = q_of(q_of(about(turn * t, (0, 0, 1)), about(theta, (1, 0, 0))),
                 about(spin * t, axis))
        c, s = np.cos(turn * t), np.sin(turn * t)
        y = np.zeros(t.shape + (ballc._core.N_STATES,))
        y[..., layout.QUATERNION] = q
        y[..., 4] = centre[0] + 0.7 * c - 0.2 * s
        y[..., 5] = centre[1] + 0.7 * s + 0.2 * c
        y[..., 6] = scene.radius - 0.0174
        w = (0.3 + 0.1 * np.sin(2 * np.pi * t / period), -0.5, 1.1)
        y[..., 7], y[..., 8], y[..., 9] = c * w[0] - s * w[1], s * w[0] + c * w[1], w[2]
        y[..., 10], y[..., 11] = -0.8 * s, 0.8 * c
        y[..., layout.INDEX["dissipated_normal"]] = 1e-3 * t
        return np.moveaxis(y, -1, 0)

    return sol


def test_the_measurement_finds_a_made_up_orbit_exactly():
    """Criteria 3-5 on a solution known in closed form: the period to the root finder's
    tolerance, G as constructed, each crossing a root of the tilt's middle level, and the
    closed form G^k y(c0 + s) equal to the solution itself 5000 periods on."""
    scene = ballc.Scene()
    period, turn, spin, centre = 2.0, 0.3, 1.3, np.array([0.4, -0.9])
    sol = _synthetic_orbit(scene, period, turn, spin, centre)
    axis = orbit.body_axis(scene)
    t1 = orbit.TRIAL_PERIODS * period
    threshold = ballc.resting.energy_threshold(scene, 1e-10, 1e-10)
    found = orbit.measure(sol, 0.0, t1, axis, period, 1e-10, 1e-10, threshold,
                          scene.parameter_vector())
    assert found is not None
    c0, measured, motion, rate = found
    assert abs(measured - period) < 1e-12
    phi = turn * period
    assert abs(motion.phi - phi) < 1e-12 and abs(motion.psi - spin * period) < 1e-12
    rotation = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    np.testing.assert_allclose(motion.d, centre - rotation @ centre, rtol=0, atol=1e-12)
    np.testing.assert_allclose(motion.dissipated, (1e-3 * period, 0.0), rtol=0, atol=1e-15)
    assert abs(rate) < 1e-12
    # c0: the first upward crossing of the middle of the sampled tilt, to rounding
    grid = np.linspace(0.0, t1, int(orbit.TILT_SAMPLES * t1 / period) + 2)
    a_z = np.array([orbit.tilt(sol(t), axis) for t in grid])
    level = 0.5 * (a_z.max() + a_z.min())
    below = np.flatnonzero((a_z[:-1] < level) & (a_z[1:] >= level))[0]
    assert grid[below] <= c0 <= grid[below + 1]
    assert abs(orbit.tilt(sol(c0), axis) - level) < 1e-14
    far = c0 + 5000 * period + np.array([0.0, 0.3, 1.7])
    closed = orbit.RelativePeriodicOrbit(t1, 1e5, c0, measured, motion, sol)
    np.testing.assert_allclose(closed(far), sol(far), rtol=0, atol=1e-8)


def test_a_made_up_motion_that_does_not_repeat_is_refused():
    """Criterion 4: the same made-up motion with its centre drifting (not a turn and a
    shift of the scene) is no relative periodic orbit."""
    scene = ballc.Scene()
    periodic = _synthetic_orbit(scene, 2.0, 0.3, 1.3, np.array([0.4, -0.9]))

    def drifting(t):
        y = periodic(t)
        y[4] = y[4] + 1e-6 * np.asarray(t) ** 2
        return y

    threshold = ballc.resting.energy_threshold(scene, 1e-10, 1e-10)
    assert orbit.measure(drifting, 0.0, 7.0, orbit.body_axis(scene), 2.0, 1e-10, 1e-10,
                         threshold, scene.parameter_vector()) is None
