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
    energy balance closed (no drift warning), the last sample at t_end."""
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
        np.testing.assert_allclose(motion.power(k).apply(y), repeated, rtol=0, atol=1e-12)
        repeated = motion.apply(repeated)
    # over many columns at once, k per column
    ks = np.arange(8)
    many = motion.power(ks).apply(np.repeat(y[:, None], ks.size, axis=1))
    for k in ks:
        np.testing.assert_allclose(many[:, k], motion.power(k).apply(y), rtol=0, atol=1e-14)
    # a turn by 0: the shift adds up k times
    straight = orbit.Motion(0.0, (1.5, -0.4), 0.0, axis)
    np.testing.assert_allclose(straight.power(5).apply(y)[_P][:2], y[_P][:2] + (7.5, -2.0))


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


def test_a_refused_trial_is_not_followed_by_another_at_once(monkeypatch):
    """A fast-spinning wobbling ball whose wobble still changes refuses trial after trial:
    the next starts only at the next scheduled rest check, not where the last ended (770
    back-to-back trials made such a run 78 % slower)."""
    trials = []
    init = orbit.Trial.__init__

    def recording(self, plane, t_from, t_to, guess):
        init(self, plane, t_from, t_to, guess)
        trials.append((t_from, t_to))

    monkeypatch.setattr(orbit.Trial, "__init__", recording)
    run = ballc.simulate(ballc.Scene(angular_velocity=(0, 0, 30)), 120.0)
    assert run.status == 0 and len(trials) >= 2
    for (_, end), (start, _) in zip(trials, trials[1:]):
        assert start > end, trials
