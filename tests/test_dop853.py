"""dop853 (ballc's compiled DOP853, in radau5's loop) against scipy's DOP853, against
exact solutions, and against radau5 (an independent method) on ballc's scenes.

dop853 is scipy's DOP853 step by step (same coefficients, error norm and step-size
control), so on a problem without events it takes the same steps and the same number
of right-hand-side calls; the values differ by rounding (summation order).  Its events,
their refinement and re-arming, t_eval and dense output are radau5's code, with
DOP853's 7th-order interpolant in place of Radau's cubic.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients
from scipy.linalg import expm

import ballc
from ballc import _radau5
from linear_event import Event

# A lightly damped oscillator and a slow decay: smooth, not stiff.
A_SMOOTH = np.array([[-0.1, 3.0, 0.0], [-3.0, -0.1, 0.0], [0.5, 0.0, -0.7]])
Y0_SMOOTH = np.array([1.0, 0.0, 2.0])


def _exact(t):
    return np.array([expm(A_SMOOTH * tt) @ Y0_SMOOTH for tt in np.atleast_1d(t)]).T


def test_coefficients_are_scipys():
    ours = _radau5._dop853_constants()
    d = dop853_coefficients
    for name, theirs in (("A", d.A), ("B", d.B), ("C", d.C), ("E3", d.E3), ("E5", d.E5),
                         ("D", d.D)):
        np.testing.assert_array_equal(ours[name], theirs, err_msg=name)


@pytest.mark.parametrize("tol", [1e-4, 1e-8, 1e-12])
def test_steps_and_calls_are_those_of_scipy_dop853(tol):
    """Without events or t_eval: the same number of steps and right-hand-side calls (2 to
    start, 12 per attempted step) and the same end state (to 1e-12).  The step points
    agree to 1e-4 relative, not to rounding: the error estimate is a small difference of
    nearly equal stage sums, so a different summation order moves it, and the next step
    size with it (measured: 2e-9 at 1e-8, 7e-6 at 1e-12, where the estimate is
    close to rounding itself)."""
    ours = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=tol, atol=tol,
                                method="dop853")
    ref = solve_ivp(lambda t, y: A_SMOOTH @ y, (0, 10.0), Y0_SMOOTH, method="DOP853",
                    rtol=tol, atol=tol)
    assert ours.status == 0 and ours.njev == 0 and ours.nlu == 0
    assert ours.t.size == ref.t.size > 5
    np.testing.assert_allclose(ours.t, ref.t, rtol=1e-4, atol=0)
    assert ours.nfev == ref.nfev == 2 + 12 * (ours.nstep + ours.nreject)
    np.testing.assert_allclose(ours.y[:, -1], ref.y[:, -1], rtol=0, atol=1e-12)


def test_the_error_follows_the_tolerance():
    """Against the matrix exponential at every step end: within a few tolerances (an
    8th-order method's global error at these tolerances), and 1e4 times smaller for a
    1e4 times smaller tolerance (at least 1e3: order 8 of the error per unit step)."""
    errors = []
    for tol in (1e-6, 1e-10):
        sol = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=tol, atol=tol,
                                   method="dop853")
        errors.append(np.abs(sol.y - _exact(sol.t)).max())
        assert errors[-1] < 10 * tol
    assert errors[1] < errors[0] / 1e3


def test_events_dense_output_and_t_eval_use_the_7th_order_interpolant():
    """y = (cos 3t, -3 sin 3t): falling zeros of y0 at pi/6 (not terminal), the terminal
    rise of y0 - 0.5 at 5 pi/9.  The roots are located on the dense output to 1e-10 at
    rtol 1e-10; the terminal state is a step's end (refined); the t_eval samples and the
    dense output agree with the exact solution between the step ends (a cubic there
    would be off by ~1e-6 with DOP853's long steps)."""
    A = np.array([[0.0, 1.0], [-9.0, 0.0]])
    events = [Event([1.0, 0.0], 0.0, False, -1), Event([1.0, 0.0], -0.5, True, 1)]
    t_stop = 5 * np.pi / 9
    t_eval = np.linspace(0, 1.9, 77)
    sol = _radau5.solve_linear(A, (0, 3), np.array([1.0, 0.0]), rtol=1e-10, atol=1e-10,
                               events=events, method="dop853", t_eval=t_eval)
    assert sol.status == 1
    np.testing.assert_allclose(sol.t_events[0], [np.pi / 6], rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.t_events[1], [t_stop], rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.y_events[1][0], [0.5, -3 * np.sin(3 * t_stop)],
                               rtol=0, atol=1e-9)
    np.testing.assert_array_equal(sol.t, t_eval[t_eval <= t_stop])
    np.testing.assert_allclose(sol.y, [np.cos(3 * sol.t), -3 * np.sin(3 * sol.t)],
                               rtol=0, atol=1e-9)

    dense = _radau5.solve_linear(A, (0, 3), np.array([1.0, 0.0]), rtol=1e-10, atol=1e-10,
                                 method="dop853", dense_output=True)
    interpolant = ballc.dense.CompiledInterpolant(*dense.dense)
    assert interpolant.terms == 7 and len(interpolant.steps) == dense.nstep
    t = np.linspace(0, 3, 301)
    np.testing.assert_allclose(interpolant(t), [np.cos(3 * t), -3 * np.sin(3 * t)],
                               rtol=0, atol=1e-9)


def test_extra_stages_only_where_the_dense_output_is_used():
    """An event that never changes sign costs nothing; a t_eval point inside a step
    costs that step its 3 extra stages (scipy computes them on every step when there
    are events)."""
    base = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=1e-8, atol=1e-8,
                                method="dop853")
    quiet = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=1e-8, atol=1e-8,
                                 method="dop853", events=[Event([0, 0, 1.0], 5.0, True, 0)])
    one = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=1e-8, atol=1e-8,
                               method="dop853", t_eval=[base.t[3] / 2 + base.t[4] / 2])
    assert quiet.nfev == base.nfev
    assert one.nfev == base.nfev + 3


def test_failure_and_budget_are_honest():
    """y' = 1000 y overflows: status -1 with the points so far.  A stiff system (an
    eigenvalue -1e5) is stable for DOP853 only with steps below ~6e-5: it spends its
    budget and says so, with what it computed (radau5 is the method for it)."""
    sol = _radau5.solve_linear(np.array([[1000.0]]), (0, 10.0), np.array([1.0]),
                               rtol=1e-6, atol=1e-6, method="dop853")
    assert sol.status == -1 and "step size" in sol.message and 0.5 < sol.t[-1] < 0.8
    assert np.all(np.isfinite(sol.y))
    stiff = np.array([[-1e5, 0.0], [1.0, -1.0]])
    budget = _radau5.solve_linear(stiff, (0, 10.0), np.array([1.0, 1.0]), rtol=1e-6,
                                  atol=1e-6, method="dop853", max_nfev=20_000)
    assert budget.status == -1 and "max_nfev" in budget.message
    assert 20_000 <= budget.nfev < 20_000 + 16 and 0 < budget.t[-1] < 10.0
    np.testing.assert_allclose(budget.y[1], np.exp(-budget.t) * (1 + 1e-5) - 1e-5 * np.exp(
        -1e5 * budget.t), rtol=0, atol=1e-5)
    with pytest.raises(ValueError, match="method = 'rk4'"):
        _radau5.solve_linear(stiff, (0, 1.0), np.ones(2), rtol=1e-6, atol=1e-6, method="rk4")


SCENES = {
    "seed": ballc.Scene(),
    "conservative": ballc.Scene(c_tau=1.0, friction_coefficient=0.0, mixture=0.0,
                                velocity=(3.0, 1.0, -20.0)),
    "friction": ballc.Scene(tangential_model="friction"),
}


@pytest.fixture(scope="module", params=list(SCENES))
def runs(request):
    scene = SCENES[request.param]
    t_eval = np.linspace(0.0, 5.0, 501)
    out = {m: ballc.simulate(scene, 5.0, method=m, rtol=1e-12, atol=1e-12, t_eval=t_eval)
           for m in ("dop853", "DOP853", "radau5")}
    return request.param, out


@pytest.mark.parametrize("other", ["DOP853", "radau5"])
def test_ballc_scenes_agree_with_scipys_dop853_and_with_radau5(runs, other):
    """The same contacts (planes, times to 1e-9 s), final states (1e-8 m, m/s) and
    samples as scipy's DOP853 (the same method) and radau5 (another one) at 1e-12.
    A sample inside a contact moves by the contact's time shift times the acceleration
    there (up to ~1e4 m/s^2): measured against radau5, contact times within 2.3e-10 s,
    final states within 3e-10, samples within 4.8e-9 m and 2.9e-7 m/s (conservative
    scene; both DOP853s differ from radau5 by about as much); the bounds are 10x.
    scipy's DOP853 takes its event states from the interpolant (ballc steps to them):
    its contact times drift from ours by up to 1.1e-9 s over 11 contacts (bound 3e-9),
    and its final height by 2.4e-8 m with them (bound 1e-7)."""
    name, out = runs
    ours, ref = out["dop853"], out[other]
    assert ours.status == ref.status == 0 and len(ours.contacts) >= 8
    assert [c.plane for c in ours.contacts] == [c.plane for c in ref.contacts]
    times = np.array([[c.t_start, c.t_end] for c in ours.contacts])
    ref_times = np.array([[c.t_start, c.t_end] for c in ref.contacts])
    np.testing.assert_allclose(times, ref_times, rtol=0, atol=1e-9 if other == "radau5" else 3e-9)
    # scipy's drift of the contact times, times |vz| ~ 20 m/s, moves its final state
    np.testing.assert_allclose(ours.y[:12, -1], ref.y[:12, -1], rtol=0,
                               atol=1e-8 if other == "radau5" else 1e-7)
    np.testing.assert_allclose(ours.position, ref.position, rtol=0, atol=5e-8)
    np.testing.assert_allclose(ours.velocity, ref.velocity, rtol=0, atol=3e-6)
    np.testing.assert_allclose(ours.angular_velocity, ref.angular_velocity, rtol=0, atol=3e-6)


def test_energy_is_conserved_when_nothing_dissipates():
    """c_tau = 1, no friction: kinetic + potential + Hertz spring energy is constant
    (each stored step end, also mid-contact), to 1e-9 of its value at 1e-12 (measured
    1.7e-10) and to 5e-3 at 1e-6 (measured 5.7e-4): the drift follows the tolerance."""
    for tol, bound in ((1e-12, 1e-9), (1e-6, 5e-3)):
        run = ballc.simulate(SCENES["conservative"], 5.0, method="dop853", rtol=tol, atol=tol)
        total = run.energy["total"]
        assert len(run.contacts) >= 8
        assert np.ptp(total) <= bound * np.abs(total).max()


def test_a_stiff_system_is_noticed():
    """Hairer's stiffness test (15 steps in a row with |h lambda| > 6.1): a decay of rate
    1e4 beside a slow one is reported (stiff_at: the step where it fired, early on);
    the smooth system is not; nor is anything radau5 integrates."""
    stiff = _radau5.solve_linear(np.array([[-1e4, 0.0], [1.0, -1.0]]), (0, 1.0),
                                 np.array([1.0, 1.0]), rtol=1e-6, atol=1e-6, method="dop853")
    assert stiff.status == 0 and 0 < stiff.stiff_at < 0.05   # measured 0.012
    smooth = _radau5.solve_linear(A_SMOOTH, (0, 10.0), Y0_SMOOTH, rtol=1e-6, atol=1e-6,
                                  method="dop853")
    assert np.isnan(smooth.stiff_at)
    radau = _radau5.solve_linear(np.array([[-1e4, 0.0], [1.0, -1.0]]), (0, 1.0),
                                 np.array([1.0, 1.0]), rtol=1e-6, atol=1e-6)
    assert np.isnan(radau.stiff_at)


def test_simulate_says_when_dop853_found_the_scene_stiff():
    """The compliant law's smooth yield (friction_regularization "smooth": no exact
    modes) is stiff for an explicit method: the run's message says so (measured: from
    the first contact, t = 0.156 s), and still finishes; the rubber ball with the
    default law is not stiff."""
    compliant = ballc.simulate(ballc.Scene(tangential_model="compliant",
                                           friction_regularization="smooth"), 1.0,
                               method="dop853", rtol=1e-6, atol=1e-6)
    assert compliant.status == 0 and "found the scene stiff" in compliant.message
    assert "method='radau5'" in compliant.message
    seed = ballc.simulate(ballc.Scene(), 1.0, method="dop853", rtol=1e-6, atol=1e-6)
    assert seed.status == 0 and "stiff" not in seed.message


def test_every_friction_and_mixture_throw_converges():
    """The 12 throws mu in {0, 0.1, 0.4, 0.8} x mixture in {0, 0.375, 0.7} (1.2 s of the
    seed's throw, contacts with stick/slip transitions) end with status 0 and a final
    state (position, m; velocity, m/s) within 1000 rtol of radau5's at 1e-12, at rtol
    1e-6 and 1e-10.  Measured worst: 264 rtol at 1e-6, 255 rtol at 1e-10 (30 at 1e-4,
    277 at 1e-8): about 10x radau5's error at the same tolerance, as on the seed."""
    for mu in (0.0, 0.1, 0.4, 0.8):
        for mixture in (0.0, 0.375, 0.7):
            scene = ballc.Scene(friction_coefficient=mu, mixture=mixture)
            ref = ballc.simulate(scene, 1.2, rtol=1e-12, atol=1e-12)
            expected = np.concatenate([ref.position[:, -1], ref.velocity[:, -1]])
            for tol in (1e-6, 1e-10):
                run = ballc.simulate(scene, 1.2, method="dop853", rtol=tol, atol=tol)
                assert run.status == 0, (mu, mixture, tol, run.message)
                final = np.concatenate([run.position[:, -1], run.velocity[:, -1]])
                assert np.abs(final - expected).max() <= 1e3 * tol, (mu, mixture, tol)
