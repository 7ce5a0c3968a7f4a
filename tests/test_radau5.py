"""radau5 (ballc's compiled Radau IIA) against scipy's Radau, and against exact solutions.

radau5 is a port of scipy's Radau: same method, same error control, same event
logic.  The two differ only by floating-point rounding (summation order, ballc's
own LU (_lu.c) instead of LAPACK's through lu_solve), so at rtol = atol = 1e-12 they
take (nearly) the same steps.  What the tolerances below allow:

* Smooth segments: both solutions are within a few local tolerances of the true
  one per step, and the contacts amplify differences by a modest factor; at
  1e-12 a bound of 1e-8 (positions, m) is ~1e4 x the per-step tolerance and
  the measured differences are 1e-12 .. 1e-10.
* Contact times: each is an event root (brentq to 4 eps) on a dense output
  accurate to ~tolerance; the difference between the two integrators is
  a state difference divided by |vz| ~ 15..25 m/s, so 1e-9 s is generous.
* The observer-free scene is ill-conditioned: nothing but friction couples the
  spin, and its last contact (stick/slip transitions) amplifies rounding, so
  scipy's Radau itself moves by 1.2e-4 m (positions; 1.6e-4 m/s, 2.3e-4 rad/s)
  between rtol = 1e-12 and 1e-13 there, and radau5 moves by 1.2e-4 m between two
  builds whose Newton solves differ only in rounding (the full 19 x 19 LU, and the
  coupled block with the outputs substituted).  radau5 vs Radau at the same 1e-12
  differ by 0.6e-4 .. 1.1e-4 m; the bound for this scene is 3e-4 m / 1e-3 m/s,
  about twice the reference's own uncertainty.
"""
import math

import numpy as np
import pytest
from scipy.linalg import expm

import ballc
from ballc import _core, _radau5
from ballc.events import LinearEvent
from linear_event import Event

TOL = 1e-12

SCENES = {
    "seed": ballc.Scene(),
    "conservative": ballc.Scene(c_tau=1.0, friction_coefficient=0.0, mixture=0.0,
                                velocity=(3.0, 1.0, -20.0)),
    "friction": ballc.Scene(tangential_model="friction"),
    "no observer": ballc.Scene(observer_mass=0.0),
}


def _contact_times(result):
    return np.array([[c.t_start, c.t_end] for c in result.contacts])


@pytest.fixture(scope="module", params=list(SCENES))
def pair(request):
    scene = SCENES[request.param]
    t_eval = np.linspace(0.0, 5.0, 501)
    ours = ballc.simulate(scene, 5.0, method="radau5", rtol=TOL, atol=TOL, t_eval=t_eval)
    ref = ballc.simulate(scene, 5.0, method="Radau", rtol=TOL, atol=TOL, t_eval=t_eval)
    return request.param, ours, ref


def test_same_outcome_and_contacts(pair):
    name, ours, ref = pair
    assert ours.status == ref.status == 0
    assert [c.plane for c in ours.contacts] == [c.plane for c in ref.contacts]
    assert len(ours.contacts) >= 8
    # ill-conditioned scene (see the module docstring): a position difference of up to
    # 1e-4 m shifts a contact by up to ~1e-4 m / 15 m/s
    atol = 1e-5 if name == "no observer" else 1e-9
    np.testing.assert_allclose(_contact_times(ours), _contact_times(ref), rtol=0, atol=atol)


def test_trajectories_agree_at_common_times(pair):
    """The observer-free scene is left out: its own trajectory moves by 4e-4 m between
    rtol = 1e-12 and 1e-13 (radau5 with itself; its stick/slip decisions sit close to
    the friction cone), so two integrators cannot be held closer than that -- a bound
    at that level would test rounding, not the integrator.  Its contacts are compared
    in test_same_outcome_and_contacts."""
    name, ours, ref = pair
    if name == "no observer":
        pytest.skip("ill-conditioned scene: see the docstring")
    np.testing.assert_array_equal(ours.t, ref.t)
    np.testing.assert_allclose(ours.position, ref.position, rtol=0, atol=1e-8)
    np.testing.assert_allclose(ours.velocity, ref.velocity, rtol=0, atol=1e-7)
    np.testing.assert_allclose(ours.angular_velocity, ref.angular_velocity, rtol=0, atol=1e-7)


def test_work_is_that_of_scipy_radau(pair):
    """Same algorithm (scipy's step control, radau5's default; the other controllers are
    held to the reference by test_every_controller_reaches_the_reference, not to scipy's
    counts): the RHS-call counts of a whole run differ by rounding-level step
    changes and by the step radau5's driver carries across stick/slip transitions
    (measured: 0.05 .. 0.6 %), radau5 steps again to each terminal event where
    scipy interpolates (+1.2 % on the observer-free scene, whose slips swing past zero:
    stepping there takes ~13 short steps, where scipy's state is the dense output of a
    step across the slip law's jump), and radau5 re-arms a slip's approach event where
    the driver restarts scipy (measured with both, at 1e-12: seed -1.0 %, conservative
    +0.1 %, friction +0.6 %, no observer +2.2 %); 2 % bounds them (the README says so),
    3 % on the observer-free scene: its stick/slip decisions sit close to the friction
    cone, and radau5's count there moves by rounding alone -- 96,050 .. 97,185 calls
    (scipy's: 94,922) with the initial vx changed by 0 .. 5 ulp (measured on d33fe92;
    the plain C hypot of the one driver moved it to 97,014)."""
    name, ours, ref = pair
    bound = 0.03 if name == "no observer" else 0.02
    assert abs(ours.nfev - ref.nfev) <= bound * ref.nfev


def test_free_flight_is_exactly_ballistic():
    """No observer, no contact: the centre moves on a parabola and the spin is constant;
    Radau IIA (order 5) integrates polynomials of degree <= 3 exactly (to rounding)."""
    scene = ballc.Scene(observer_mass=0.0, velocity=(1.0, -2.0, 3.0), position=(0, 0, 5.0),
                        angular_velocity=(0.3, -0.2, 0.5))
    t = np.linspace(0, 0.6, 13)
    result = ballc.simulate(scene, 0.6, method="radau5", t_eval=t, rtol=1e-6, atol=1e-6)
    assert result.status == 0 and not result.contacts
    np.testing.assert_allclose(result.position[2], 5.0 + 3.0 * t - 9.81 / 2 * t ** 2,
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.position[0], t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.position[1], -2.0 * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.angular_velocity,
                               np.repeat([[0.3], [-0.2], [0.5]], t.size, axis=1), atol=1e-13)


def test_linear_system_matches_the_matrix_exponential():
    """y' = A y with a stiff, oscillatory A: the error follows the tolerance."""
    A = np.array([[-1.0, 20.0, 0.0], [-20.0, -1.0, 0.0], [0.0, 1.0, -1e4]])
    y0 = np.array([1.0, 0.0, 1.0])
    t = np.linspace(0, 2, 9)
    exact = np.array([expm(A * tt) @ y0 for tt in t]).T
    for tol, bound in ((1e-6, 1e-4), (1e-10, 1e-8)):
        sol = _radau5.solve_linear(A, (0, 2), y0, rtol=tol, atol=tol, t_eval=t)
        assert sol.status == 0
        np.testing.assert_allclose(sol.y, exact, rtol=0, atol=bound)


def test_linear_events_are_located_on_the_dense_output():
    """y = (cos 3t, -3 sin 3t).  Falling zeros of y0 at t = pi/6, pi/6 + 2pi/3, ...;
    the terminal event y0 - 0.5 rising first at 3t = 5 pi / 3."""
    A = np.array([[0.0, 1.0], [-9.0, 0.0]])
    events = [Event([1.0, 0.0], 0.0, False, -1), Event([1.0, 0.0], -0.5, True, 1)]
    sol = _radau5.solve_linear(A, (0, 3), np.array([1.0, 0.0]), rtol=1e-12, atol=1e-12,
                               events=events)
    t_stop = 5 * np.pi / 9
    assert sol.status == 1 and sol.message == "A termination event occurred."
    np.testing.assert_allclose(sol.t_events[0], [np.pi / 6], rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.t_events[1], [t_stop], rtol=0, atol=1e-10)
    assert sol.t[-1] == sol.t_events[1][0]
    np.testing.assert_allclose(sol.y_events[1][0], [0.5, -3 * np.sin(3 * t_stop)],
                               rtol=0, atol=1e-9)


def test_the_state_at_a_terminal_event_is_a_step_end_not_the_dense_output():
    """The same oscillator, stopped where y0 = 0.5 first rises.  The state radau5
    returns there is compared with the exact solution at the time it reports (so the
    root's own error does not count).  Stepping to the event (the default) leaves the
    global error of the step end points; the crossing step's dense output (solve_ivp's
    state, refine_events=False) adds its own interpolation error, measured 10x (1e-6)
    and 25x (1e-8) larger."""
    A = np.array([[0.0, 1.0], [-9.0, 0.0]])
    stop = [Event([1.0, 0.0], -0.5, True, 1)]

    def state_error(tol, refine):
        sol = _radau5.solve_linear(A, (0, 3), np.array([1.0, 0.0]), rtol=tol, atol=tol,
                                   events=stop, refine_events=refine)
        assert sol.status == 1 and sol.t[-1] == sol.t_events[0][0]
        np.testing.assert_array_equal(sol.y[:, -1], sol.y_events[0][0])
        t = sol.t_events[0][0]
        return np.abs(sol.y_events[0][0] - [np.cos(3 * t), -3 * np.sin(3 * t)]).max()

    for tol in (1e-6, 1e-8):
        stepped, interpolated = state_error(tol, True), state_error(tol, False)
        assert stepped <= 0.3 * interpolated
        assert stepped <= 0.1 * tol


def test_stepping_to_an_event_backwards_and_with_t_eval():
    """Integrating backwards (t from 3 to 0) with t_eval: the step to the event runs in
    the direction of integration, the t_eval points up to the event are stored from the
    new step, and the event state is as accurate as forwards."""
    A = np.array([[0.0, 1.0], [-9.0, 0.0]])
    y0 = np.array([np.cos(9.0), -3 * np.sin(9.0)])
    t_eval = np.linspace(3.0, 0.0, 31)
    sol = _radau5.solve_linear(A, (3.0, 0.0), y0, rtol=1e-8, atol=1e-8, t_eval=t_eval,
                               events=[Event([1.0, 0.0], -0.5, True, 0)])
    assert sol.status == 1
    t = sol.t_events[0][0]
    assert 2.4 < t < 2.5 and np.all(sol.t > t)
    np.testing.assert_array_equal(sol.t, t_eval[t_eval > t])
    exact = np.array([np.cos(3 * sol.t), -3 * np.sin(3 * sol.t)])
    np.testing.assert_allclose(sol.y, exact, rtol=0, atol=1e-7)
    np.testing.assert_allclose(sol.y_events[0][0], [np.cos(3 * t), -3 * np.sin(3 * t)],
                               rtol=0, atol=1e-9)


def test_dense_output_and_samples_agree_across_stepped_events():
    """With dense_output the interpolant of the step taken to each event replaces the
    crossing step's: sol(t) reproduces the stored event states and the t_eval samples
    of the same run to rounding (before stepping to events the seed scene's contact
    starts differed by 6e-9: the crossing step's cubic against the next segment's
    normalised start)."""
    scene = ballc.Scene()
    run = ballc.simulate(scene, 1.2, rtol=1e-8, atol=1e-8, dense_output=True)
    for contact in run.contacts:
        for t in (contact.t_start, contact.t_end):
            for j in np.flatnonzero(run.t == t):
                np.testing.assert_allclose(run.sol(t), run.y[:, j], rtol=0, atol=1e-9)
    t_eval = np.linspace(0.0, 1.2, 101)
    sampled = ballc.simulate(scene, 1.2, rtol=1e-8, atol=1e-8, t_eval=t_eval)
    np.testing.assert_allclose(sampled.y, run.sol(t_eval), rtol=0, atol=1e-12)


def test_failure_is_honest_and_returns_what_was_computed():
    """y' = 1000 y overflows near t = 0.71: status -1, a message, the points so far."""
    sol = _radau5.solve_linear(np.array([[1000.0]]), (0, 10.0), np.array([1.0]),
                               rtol=1e-6, atol=1e-6)
    assert sol.status == -1 and not sol.success
    assert "step size" in sol.message
    assert 0.5 < sol.t[-1] < 0.8
    assert np.all(np.isfinite(sol.y)) and sol.y.shape == (1, sol.t.size)
    bad = _radau5.solve_linear(np.array([[1e308]]), (0, 1.0), np.array([1e10]),
                               rtol=1e-6, atol=1e-6)
    assert bad.status == -1 and "initial state" in bad.message
    np.testing.assert_array_equal(bad.t, [0.0])


def test_bad_options_are_named():
    A = np.eye(2)
    with pytest.raises(ValueError, match="rtol"):
        _radau5.solve_linear(A, (0, 1), [1.0, 1.0], rtol=-1.0, atol=1e-6)
    with pytest.raises(ValueError, match="max_step"):
        _radau5.solve_linear(A, (0, 1), [1.0, 1.0], rtol=1e-6, atol=1e-6, max_step=0.0)
    with pytest.raises(ValueError, match="t_eval"):
        _radau5.solve_linear(A, (0, 1), [1.0, 1.0], rtol=1e-6, atol=1e-6, t_eval=[0.5, 0.2])
    with pytest.raises(ValueError, match="y0"):
        _radau5.solve_linear(A, (0, 1), [1.0], rtol=1e-6, atol=1e-6)
    with pytest.raises(TypeError, match="linear event"):
        _radau5.solve_linear(A, (0, 1), [1.0, 1.0], rtol=1e-6, atol=1e-6,
                             events=[lambda t, y: y[0]])


# ---- step control (radau5_problem.controller; benchmarks/controllers.py) ----

#: RADAU5's control without its tolerance relabelling (the candidate of
#: benchmarks/controllers.py), and each of its elements alone.
_HAIRER = ("nit7", "limits", "pred", "hold", "jac", "scale")


@pytest.fixture(scope="module", params=["seed", "conservative", "friction"])
def reference(request):
    """scipy's Radau at 1e-12 (the oracle of the pair fixture)."""
    t_eval = np.linspace(0.0, 5.0, 501)
    ref = ballc.simulate(SCENES[request.param], 5.0, method="Radau", rtol=TOL, atol=TOL,
                         t_eval=t_eval)
    return request.param, t_eval, ref


@pytest.mark.parametrize("controller", ["scipy", "hairer-tol", "jac", "hold+jac"])
def test_every_controller_reaches_the_reference(reference, controller):
    """Whatever the step control, radau5 at 1e-12 is the same trajectory as scipy's
    Radau at 1e-12 (bounds as in test_trajectories_agree_at_common_times) with the same
    contacts: the controllers choose different steps, not different solutions."""
    name, t_eval, ref = reference
    elements = {"scipy": (), "hairer-tol": _HAIRER}.get(controller,
                                                        tuple(controller.split("+")))
    previous = _radau5._set_controller(list(elements))
    try:
        ours = ballc.simulate(SCENES[name], 5.0, method="radau5", rtol=TOL, atol=TOL,
                              t_eval=t_eval)
    finally:
        _radau5._set_controller(previous)
    assert ours.status == ref.status == 0
    assert [c.plane for c in ours.contacts] == [c.plane for c in ref.contacts]
    np.testing.assert_allclose(_contact_times(ours), _contact_times(ref), rtol=0, atol=1e-9)
    np.testing.assert_allclose(ours.position, ref.position, rtol=0, atol=1e-8)
    np.testing.assert_allclose(ours.velocity, ref.velocity, rtol=0, atol=1e-7)
    np.testing.assert_allclose(ours.angular_velocity, ref.angular_velocity, rtol=0, atol=1e-7)


def test_tolerance_transformation_only_relabels():
    """RADAU5's rtol' = 0.1 rtol^(2/3) (the ``tol`` element): the solver then runs
    exactly as scipy's control at rtol' (its Newton tolerance is the same function of
    the tolerance in use), step for step."""
    A = np.array([[-1.0, 20.0, 0.0], [-20.0, -1.0, 0.0], [0.0, 1.0, -1e4]])
    y0 = np.array([1.0, 0.0, 1.0])
    for tol in (1e-4, 1e-9):
        relabelled = _radau5.solve_linear(A, (0, 2), y0, rtol=tol, atol=tol, controller="tol")
        inner = 0.1 * tol ** (2 / 3)
        plain = _radau5.solve_linear(A, (0, 2), y0, rtol=inner, atol=inner, controller=0)
        assert (relabelled.nfev, relabelled.nstep, relabelled.nlu) == (
            plain.nfev, plain.nstep, plain.nlu)
        np.testing.assert_array_equal(relabelled.y, plain.y)


def test_controller_elements_are_named():
    assert _radau5._controller_bits("scipy") == 0
    assert _radau5._controller_bits(["jac", "hold"]) == (
        _radau5.CONTROLLER_ELEMENTS["jac"] | _radau5.CONTROLLER_ELEMENTS["hold"])
    with pytest.raises(ValueError, match="controller element"):
        _radau5._controller_bits(["gustafsson"])
    with pytest.raises(ValueError, match="controller element"):
        _radau5.solve_linear(np.eye(1), (0, 1), [1.0], rtol=1e-6, atol=1e-6,
                             controller="nope")


def test_a_non_finite_right_hand_side_of_ballc_is_reported_not_integrated():
    """radau5 leaves the finiteness check of ballc's own right-hand side to ballc_rhs
    (radau5_problem.outputs_checked): a state whose derivative overflows must still end
    the integration with status -1 and the reason, not run on NaNs."""
    scene = ballc.Scene()
    y0 = scene.initial_state()
    y0[_core.STATE_INDEX["omega_x"]] = 1e300        # omega^2 overflows
    latch = np.zeros(_core.N_LATCH)
    sol = _radau5.solve_system(scene.parameter_vector(), latch, _core.FLAGS["observer"],
                               (0.0, 1.0), y0, rtol=1e-6, atol=1e-6)
    assert sol.status == -1 and not sol.success
    assert "cannot be evaluated at the initial state" in sol.message


def _falling_ball():
    """A ball in free flight from rest at z = 5 m: z(t) = 5 - g t^2 / 2 exactly."""
    scene = ballc.Scene(position=(0.0, 0.0, 5.0), velocity=(0.0, 0.0, 0.0),
                        angular_velocity=(0.0, 0.0, 0.0))
    return scene, scene.parameter_vector(), np.zeros(_core.N_LATCH), scene.initial_state()


@pytest.mark.parametrize("method", ["radau5", "dop853"])
def test_a_re_armed_event_moves_on_without_a_stop(method):
    """radau5 calls a terminal event's ``rearm`` where it fires: a new (coefficients,
    offset) goes on integrating without a stop or a hit; None stops there as usual.
    A falling ball's height event re-armed from 4.5 to 4 to 3 to 2 m: three re-arms at
    the exact times of those heights (the state handed to rearm is a step's end), one
    hit at the last, and the samples run through them.  The same loop with DOP853's
    steps (method "dop853") does the same."""
    scene, params, latch, y0 = _falling_ball()
    g = abs(scene.gravity)
    heights = [4.5, 4.0, 3.0, 2.0]
    seen = []

    def rearm(t, y):
        seen.append((t, y[_core.STATE_NAMES.index("z")]))
        if len(seen) == len(heights):
            return None
        return event.coefficients, -heights[len(seen)], latch
    event = LinearEvent.of_state("z", 1.0, -heights[0], terminal=True, direction=-1)
    event.rearm = rearm
    sol = _radau5.solve_system(params, latch, 0, (0.0, 2.0), y0, rtol=1e-10, atol=1e-10,
                               events=[event], method=method)
    expected = [math.sqrt(2 * (5.0 - h) / g) for h in heights]
    assert sol.status == 1 and sol.n_rearmed == 3
    np.testing.assert_allclose([t for t, _ in seen], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose([z for _, z in seen], heights, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sol.t_events[0], expected[-1:], rtol=0, atol=1e-12)
    assert sol.t[-1] == sol.t_events[0][0]
    for t_rearm in expected[:-1]:   # each re-arming state is a stored step end
        assert np.min(np.abs(sol.t - t_rearm)) < 1e-12
    np.testing.assert_allclose(sol.y[_core.STATE_NAMES.index("z")],
                               5.0 - g * sol.t ** 2 / 2, rtol=0, atol=1e-11)


def test_a_re_arming_that_fails_is_reported():
    scene, params, latch, y0 = _falling_ball()

    def broken(t, y):
        raise RuntimeError("rearm broke")

    def wrong_shape(t, y):
        return np.ones(3), 0.0, latch
    for rearm, error, match in [(broken, RuntimeError, "rearm broke"),
                                (wrong_shape, ValueError, "rearm coefficients")]:
        event = LinearEvent.of_state("z", 1.0, -4.0, terminal=True, direction=-1)
        event.rearm = rearm
        with pytest.raises(error, match=match):
            _radau5.solve_system(params, latch, 0, (0.0, 2.0), y0, rtol=1e-8, atol=1e-8,
                                 events=[event])
    event = LinearEvent.of_state("z", 1.0, -4.0, terminal=True, direction=-1)
    event.rearm = broken
    with pytest.raises(TypeError, match="re-arm"):
        _radau5.solve_linear(np.eye(_core.N_STATES), (0.0, 1.0), y0, rtol=1e-8, atol=1e-8,
                             events=[event])
