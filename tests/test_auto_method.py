"""method="auto" (issue 22 item 3): dop853 switching to radau5 where Hairer's stiffness
test fires, and back where radau5's steps are within dop853's stability bound.

Oracles: the matrix exponential (y' = A y), the two methods on their own (auto before
any switch is dop853 step for step; on a stiff scene it agrees with radau5 at a tight
tolerance), the dense output against the integrator's own t_eval values, the call budget.
"""
import math

import numpy as np
import pytest
from scipy.linalg import expm

import ballc
from ballc import _radau5
from ballc.dense import CompiledInterpolant

#: y' = A y: a slow rotation (period ~6 s) beside a fast decay (rate 1e4): once the
#: decay is over, dop853's steps are held at 6.1 / 1e4 by stability (stiff).
STIFF_A = np.array([[0.0, 1.0, 0.0], [-1.0, -0.1, 0.0], [0.0, 0.0, -1e4]])
STIFF_Y0 = np.array([1.0, 0.0, 1.0])
#: the same rotation alone: not stiff
CALM_A = STIFF_A[:2, :2]

#: work_precision's stiff scene: a steel-hard ball dropped with a sideways push, which
#: settles by t ~ 2.2 s and then rolls in permanent floor contact.
STEEL = ballc.Scene(tangential_model="friction", ball_youngs_modulus=2e11,
                    plane_youngs_modulus=2e11, c_tau=0.5, observer_mass=0.0,
                    position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))


def exact(A, y0, t):
    return expm(A * t) @ y0


def test_auto_is_dop853_step_for_step_until_it_switches():
    """Not stiff: no switch, and the very same run as dop853 (points, calls, no LU); the
    only extra work is the stiffness probe's Jacobian every 15 steps."""
    opts = dict(rtol=1e-9, atol=1e-12)
    auto = _radau5.solve_linear(CALM_A, (0.0, 20.0), [1.0, 0.0], method="auto", **opts)
    dop = _radau5.solve_linear(CALM_A, (0.0, 20.0), [1.0, 0.0], method="dop853", **opts)
    assert auto.switches == [] and auto.method_end == "dop853"
    assert np.array_equal(auto.t, dop.t) and np.array_equal(auto.y, dop.y)
    assert (auto.nfev, auto.nlu, auto.nstep) == (dop.nfev, 0, dop.nstep)
    assert auto.njev == dop.nstep // 15 and dop.njev == 0
    assert auto.nstep_implicit == 0
    assert np.allclose(auto.y[:, -1], exact(CALM_A, [1.0, 0.0], 20.0), rtol=0, atol=1e-7)


def test_auto_switches_to_radau5_on_a_stiff_system_and_stays_accurate():
    opts = dict(rtol=1e-8, atol=1e-10)
    auto = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, method="auto", **opts)
    dop = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, method="dop853", **opts)
    assert auto.status == 0
    # one switch, to radau5, at the latest where dop853's own test fired (stiff_at: the
    # start of its 15th stiff step, of ~6e-4 s; the probe may see it first)
    assert [m for _, m in auto.switches] == ["radau5"]
    t_switch = auto.switches[0][0]
    assert np.isfinite(dop.stiff_at) and t_switch < dop.stiff_at + 1e-3
    assert 1e-3 < t_switch < 0.05   # the fast decay is over within ~3 ms
    # up to the switch, the run is dop853's
    before = auto.t <= t_switch
    assert np.array_equal(auto.t[before], dop.t[:before.sum()])
    assert np.array_equal(auto.y[:, before], dop.y[:, :before.sum()])
    # afterwards radau5: few steps, with Jacobians and LUs
    assert auto.nstep_implicit > 0 and auto.njev >= 1 and auto.nlu >= 2
    assert auto.nfev < dop.nfev / 5
    assert auto.method_end == "radau5"
    for t, y in zip(auto.t[::7], auto.y.T[::7]):
        assert np.allclose(y, exact(STIFF_A, STIFF_Y0, t), rtol=1e-5, atol=1e-8)


def test_auto_switches_back_when_radau5_steps_are_within_dop853s_bound():
    """Started implicit on a system that is not stiff: after AUTO_NONSTIFF_STEPS (15)
    radau5 steps with h rho(J) < 6.1 it hands over to dop853."""
    auto = _radau5.solve_linear(CALM_A, (0.0, 20.0), [1.0, 0.0], method="auto",
                                auto_implicit=True, rtol=1e-9, atol=1e-12)
    assert [m for _, m in auto.switches] == ["dop853"]
    assert auto.nstep_implicit == 15
    assert auto.method_end == "dop853" and auto.nstep > 15
    assert auto.njev >= 1   # the Jacobian radau5 started with
    assert np.allclose(auto.y[:, -1], exact(CALM_A, [1.0, 0.0], 20.0), rtol=0, atol=1e-7)


def test_mixed_dense_output_keeps_each_steps_own_interpolant():
    """Dense output of a run with both kinds of steps: each step marked with its own
    kind, and the interpolant evaluated in Python agrees with the integrator's values at
    t_eval (computed in C from the same steps) and with the exact solution."""
    t_eval = np.linspace(0.0, 20.0, 2001)
    opts = dict(rtol=1e-8, atol=1e-10, method="auto")
    sol = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, dense_output=True, **opts)
    at = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, t_eval=t_eval, **opts)
    steps, coefficients, terms, kinds = sol.dense
    assert terms == 7 and set(kinds.tolist()) == {3, 7}
    # the radau5 steps are those after the switch, and padded with zero rows
    t_switch = sol.switches[0][0]
    assert np.all((kinds == 3) == (steps[:, 0] >= t_switch))
    n = STIFF_A.shape[0]
    radau_rows = coefficients[kinds == 3].reshape(-1, 8, n)
    assert np.all(radau_rows[:, 4:] == 0)
    interpolant = CompiledInterpolant(*sol.dense)
    values = interpolant(t_eval)
    assert np.allclose(values, at.y, rtol=1e-12, atol=1e-14)
    truth = np.array([exact(STIFF_A, STIFF_Y0, t) for t in t_eval]).T
    assert np.allclose(values, truth, rtol=1e-5, atol=1e-8)


def test_events_located_on_the_radau5_part_of_an_auto_run():
    """A linear event y0 = 0 (the rotation's zeros, at t ~ pi (k + 1/2)) after the switch:
    located on radau5's interpolant, at the exact solution's zeros."""

    class Zero:
        coefficients = np.array([1.0, 0.0, 0.0])
        offset = 0.0
        terminal = False
        direction = 0

    sol = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, events=[Zero()], rtol=1e-10,
                               atol=1e-12, method="auto")
    assert sol.switches and sol.switches[0][0] < 1.0
    from scipy.optimize import brentq
    roots = sol.t_events[0]
    assert len(roots) == 6   # zeros of the damped rotation in (0, 20)
    for r in roots:
        truth = brentq(lambda t: exact(STIFF_A, STIFF_Y0, t)[0], r - 0.1, r + 0.1,
                       xtol=1e-14)
        assert r == pytest.approx(truth, abs=1e-8)


def test_auto_on_the_stiff_scene_agrees_with_radau5_and_switches_once_settled():
    auto = ballc.simulate(STEEL, 5.0, method="auto", rtol=1e-10, atol=1e-10)
    radau = ballc.simulate(STEEL, 5.0, method="radau5", rtol=1e-10, atol=1e-10)
    assert auto.status == 0 and radau.status == 0
    assert np.allclose(auto.y[:13, -1], radau.y[:13, -1], rtol=0, atol=1e-7)
    assert len(auto.contacts) == len(radau.contacts)
    starts = np.array([c.t_start for c in auto.contacts])
    assert np.allclose(starts, [c.t_start for c in radau.contacts], rtol=0, atol=1e-8)
    # it switched to radau5, and only once the ball was in long contact (the bounces
    # before are short and not stiff for dop853): measured first switch at t ~ 2.2 s
    assert auto.method_switches and auto.method_switches[0][1] == "radau5"
    assert 2.0 < auto.method_switches[0][0] < 3.0
    assert "dop853 found the scene stiff" not in auto.message
    # far cheaper than dop853 there
    dop = ballc.simulate(STEEL, 5.0, method="dop853", rtol=1e-10, atol=1e-10)
    assert auto.nfev < dop.nfev / 3


def test_auto_on_a_rubber_ball_scene_is_dop853():
    """work_precision's conservative oblique throw (rubber ball, no friction) is not
    stiff: auto never switches, and its run is dop853's (the probe's Jacobians aside)."""
    scene = ballc.Scene(c_tau=1.0, friction_coefficient=0.0, mixture=0.0,
                        velocity=(3.0, 1.0, -20.0))
    auto = ballc.simulate(scene, 2.0, method="auto", rtol=1e-8, atol=1e-8)
    dop = ballc.simulate(scene, 2.0, method="dop853", rtol=1e-8, atol=1e-8)
    assert auto.method_switches == []
    assert np.array_equal(auto.t, dop.t) and np.array_equal(auto.y, dop.y)
    assert (auto.nfev, auto.nlu) == (dop.nfev, 0)
    assert dop.method_switches is None


def test_auto_on_the_seed_scene_is_dop853():
    """The seed's rubber ball is not stiff: auto never switches -- not even where a slip
    nears zero and the exact Coulomb law's Jacobian (mu N / |u|) is large, which the
    probe alone took for stiffness -- and its run is dop853's."""
    auto = ballc.simulate(ballc.Scene(), 5.0, method="auto", rtol=1e-10, atol=1e-10)
    dop = ballc.simulate(ballc.Scene(), 5.0, method="dop853", rtol=1e-10, atol=1e-10)
    assert auto.method_switches == []
    assert np.array_equal(auto.t, dop.t) and np.array_equal(auto.y, dop.y)
    assert (auto.nfev, auto.nlu) == (dop.nfev, 0) and auto.njev > 0   # probes


def test_statistics_add_up_over_segments():
    """simulate's nfev, njev and nlu are the sums of its segments' (the C loop's segment
    log), each counting both methods' calls (auto: the switch's Jacobian too)."""
    result = ballc.simulate(STEEL, 3.0, method="auto", rtol=1e-8, atol=1e-8)
    segments = result.segments
    assert segments is not None   # the C loop ran it
    assert result.nfev == segments["nfev"].sum()
    assert result.njev == segments["njev"].sum()
    assert result.nlu == segments["nlu"].sum()
    to_radau = sum(1 for _, m in result.method_switches if m == "radau5")
    assert to_radau >= 1 and result.njev >= to_radau
    assert segments["switches"].sum() == len(result.method_switches)
    for row in segments:   # each switch inside the segment that made it
        inside = [t for t, _ in result.method_switches if row["t_start"] <= t <= row["t_end"]]
        assert len(inside) >= row["switches"]
    # a segment without a radau5 step has no LU, and a Jacobian only per 15 dop853
    # steps (the stiffness probe)
    plain = segments[(segments["method"] == "dop853") & (segments["switches"] == 0)]
    assert len(plain)
    assert np.all(plain["method_end"] == "dop853")
    assert np.all(plain["nlu"] == 0) and np.all(plain["njev"] <= plain["nstep"] // 15)


def test_a_budget_stopped_auto_run_is_an_honest_failure():
    result = ballc.simulate(STEEL, 5.0, method="auto", rtol=1e-8, atol=1e-8, max_nfev=3000)
    assert result.status == -1
    assert "max_nfev = 3000" in result.message
    assert result.nfev >= 3000
    assert result.t.size > 1 and result.t[-1] < 5.0 and np.all(np.diff(result.t) > 0)
    assert np.all(np.isfinite(result.y))


def test_a_budget_stopped_auto_segment_keeps_its_points():
    sol = _radau5.solve_linear(STIFF_A, (0.0, 20.0), STIFF_Y0, method="auto", rtol=1e-8,
                               atol=1e-10, max_nfev=2000)
    assert sol.status == -1 and "max_nfev" in sol.message
    assert sol.t.size > 10 and sol.t[-1] < 20.0
    for t, y in zip(sol.t[::5], sol.y.T[::5]):
        assert np.allclose(y, exact(STIFF_A, STIFF_Y0, t), rtol=1e-5, atol=1e-8)


def test_auto_dense_output_over_a_run_with_switches():
    """simulate's sol(t) with auto, across segments of both methods, matches its own
    samples (t_eval) at the tolerance."""
    t_eval = np.linspace(0.0, 3.0, 301)
    dense = ballc.simulate(STEEL, 3.0, method="auto", rtol=1e-9, atol=1e-9, dense_output=True)
    sampled = ballc.simulate(STEEL, 3.0, method="auto", rtol=1e-9, atol=1e-9, t_eval=t_eval)
    assert dense.method_switches
    values = dense.sol(t_eval)
    assert np.allclose(values[:13], sampled.y[:13], rtol=0, atol=1e-6)


def test_method_auto_is_validated_and_named_in_errors():
    with pytest.raises(ballc.SceneError, match=r"method = 'Auto'.*'auto'"):
        ballc.simulate(ballc.Scene(), 0.1, method="Auto")
    with pytest.raises(ValueError, match=r"method = 'lsoda' is not allowed: must be "
                                         r"'radau5', 'dop853' or 'auto'"):
        _radau5.solve_linear(CALM_A, (0.0, 1.0), [1.0, 0.0], rtol=1e-6, atol=1e-9,
                             method="lsoda")
    assert "auto" in ballc.options.METHODS


def test_switch_back_uses_the_spectral_radius_not_a_norm():
    """The switch-back test's rho(J) is the spectral radius (power iterations), not a
    norm: J = [[-1, 1e4], [0, -2]] has |J| ~ 1e4 but eigenvalues -1 and -2, so radau5's
    steps (h ~ 0.1 .. 1) are well within dop853's bound and it hands over after 15."""
    A = np.array([[-1.0, 1e4], [0.0, -2.0]])
    sol = _radau5.solve_linear(A, (0.0, 20.0), [1.0, 1.0], method="auto",
                               auto_implicit=True, rtol=1e-6, atol=1e-9)
    assert [m for _, m in sol.switches] == ["dop853"] and sol.nstep_implicit == 15
    assert np.allclose(sol.y[:, -1], exact(A, [1.0, 1.0], 20.0), rtol=1e-5, atol=1e-9)


def test_a_transient_then_stiffness_switches_both_ways():
    """A damped pair at |lambda| = 1e3 started implicit: during its transient (~5 ms)
    radau5's steps are bounded by accuracy below 6.1e-3 s, so it hands over to dop853;
    once the transient has decayed, dop853's steps are held at its stability bound and it
    hands back to radau5 (once the state is within atol of zero).  The solution stays the matrix exponential's."""
    fast = np.array([[0.0, 1e3], [-1e3, -1e3]])   # eigenvalues -500 +- 866i
    sol = _radau5.solve_linear(fast, (0.0, 1.0), [1.0, 0.0], method="auto",
                               auto_implicit=True, rtol=1e-6, atol=1e-9)
    assert [m for _, m in sol.switches] == ["dop853", "radau5"]
    (t_explicit, _), (t_implicit, _) = sol.switches
    assert t_explicit < 5e-3 < t_implicit < 0.5   # measured 1.05e-3 and 0.169
    assert sol.method_end == "radau5" and sol.status == 0
    for t, y in zip(sol.t, sol.y.T):
        assert np.allclose(y, exact(fast, [1.0, 0.0], t), rtol=0, atol=1e-5)


def test_either_stiffness_test_switches_to_radau5():
    """docs/architecture.md, "The automatic method": auto switches to radau5 once Hairer's
    test has seen 15 stiff steps in a row *or* once the probe finds the steps stiff.
    On the steel scene at rtol 3e-4 Hairer's test never fires: dop853 run alone over the
    whole 5 s does not report the scene stiff.  auto is that dop853 run step for step
    until it switches, so a switch there is the probe's alone -- and it must come (measured
    at t = 2.24 s, once the ball rolls in persistent contact), with far fewer calls than
    dop853's.  Not a switch on the probe without Hairer's evidence: that is
    test_auto_on_the_seed_scene_is_dop853."""
    opts = dict(rtol=3e-4, atol=3e-4)
    dop = ballc.simulate(STEEL, 5.0, method="dop853", **opts)
    auto = ballc.simulate(STEEL, 5.0, method="auto", **opts)
    assert dop.status == 0 and auto.status == 0
    assert "found the scene stiff" not in dop.message   # Hairer's test never fired
    assert auto.method_switches and auto.method_switches[0][1] == "radau5"
    t_switch = auto.method_switches[0][0]
    assert 2.0 < t_switch < 3.0
    before = auto.t < t_switch
    assert np.array_equal(auto.t[before], dop.t[:before.sum()])
    assert auto.nfev < dop.nfev / 3
