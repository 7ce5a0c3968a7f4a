"""The C loop's segment log (Result.segments): one row per smooth segment, what ended it
and each plane's mode before and after.  The oracles are the run itself (its contacts,
its calls, its samples, its status) and the scene's physics (a massless observer's
flight is exact: no calls).  tests/test_automaton.py checks its transitions against
ballc.automaton."""
import numpy as np
import pytest

import ballc
from ballc import result as result_module
from ballc.events import LinearEvent


def test_the_fields_are_documented():
    log = ballc.simulate(ballc.Scene(), 0.3, rtol=1e-6, atol=1e-6).segments
    assert set(log.dtype.names) == set(result_module.SEGMENT_FIELDS)
    with pytest.raises(ValueError):   # read-only
        log["nfev"][0] = 0


def test_exact_flight_segments_cost_no_call():
    """A massless observer and isotropic inertia: flight in closed form (ballc.flight)."""
    result = ballc.simulate(ballc.Scene(observer_mass=0.0), 1.2, rtol=1e-8, atol=1e-8)
    log = result.segments
    flight = (log["before"] == "flight").all(axis=1)
    assert flight.sum() >= 3
    assert set(log["method"][flight]) == {"flight"} and not log["nfev"][flight].any()
    assert not log["nstep"][flight].any()
    assert set(log["method"][~flight]) == {"radau5"} and log["nstep"][~flight].all()
    assert set(log["end"][flight][:-1]) == {"enter"}


def test_a_compliant_contact_s_step_bound_ends_a_segment_and_changes_no_mode():
    """A ball starting at rest on the floor: its compliant contact lasts beyond its first
    4 Hertz times, whose bounded steps end there (compliantmodes.step_bound)."""
    scene = ballc.Scene(observer_mass=0.0, ball_youngs_modulus=1e7, c_tau=1.0,
                        friction_coefficient=1.0, tangential_model="compliant",
                        tangential_stiffness_ratio=1.0, position=(0.0, 0.0, 1.0),
                        velocity=(0.0, 0.0, 0.0))
    log = ballc.simulate(scene, 0.3, rtol=1e-8, atol=1e-10).segments
    bound = log[log["end"] == "step bound"]
    assert len(bound) == 1
    np.testing.assert_array_equal(bound["before"], bound["after"])
    assert bound["plane"][0] == "" and bound["before"][0][0] in ("elastic", "sliding")


def test_a_failed_run_ends_its_log_where_it_stopped():
    result = ballc.simulate(ballc.Scene(), 1.0, rtol=1e-8, atol=1e-8, max_nfev=3000)
    assert result.status == -1
    last = result.segments[-1]
    assert last["end"] == "failed" and last["t_end"] == result.t[-1]
    np.testing.assert_array_equal(last["before"], last["after"])
    assert result.segments["nfev"].sum() == result.nfev


def test_a_terminal_user_event_ends_the_last_segment():
    apex = LinearEvent.of_state("vz", 1.0)   # v_z = 0 going down: the first apex
    apex.terminal, apex.direction = True, -1
    result = ballc.simulate(ballc.Scene(velocity=(1.0, 0.0, 3.0)), 2.0, events=[apex])
    assert result.status == 1
    last = result.segments[-1]
    assert last["end"] == "user" and last["plane"] == ""
    assert last["t_end"] == result.t_events[0][-1] == result.t[-1]


def test_passing_through_ends_the_run_in_passed_through():
    result = ballc.simulate(ballc.Scene(tangential_model="dig-in"), 5.0, rtol=1e-6,
                            atol=1e-6)
    assert result.status == 1
    last = result.segments[-1]
    assert last["end"] == "through"
    k = ballc.layout.PLANES.index(str(last["plane"]))
    assert last["after"][k] == "passed_through" and last["before"][k] != "flight"


def test_auto_logs_the_method_of_each_segment():
    steel = ballc.Scene(tangential_model="friction", ball_youngs_modulus=2e11,
                        plane_youngs_modulus=2e11, c_tau=0.5, observer_mass=0.0,
                        position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))
    result = ballc.simulate(steel, 3.0, method="auto", rtol=1e-8, atol=1e-8)
    log = result.segments
    assert log["switches"].sum() == len(result.method_switches) >= 1
    assert set(log["method"]) == {"radau5", "dop853", "flight"}   # exact flight: no observer
    # a segment that switched an odd number of times ends with the other method
    odd = log["switches"] % 2 == 1
    assert np.all(log["method"][odd] != log["method_end"][odd])
    assert np.all(log["method"][~odd] == log["method_end"][~odd])


def test_scipy_segments_are_logged_as_scipy():
    """scipy's methods run in the C loop too: each integrated segment is logged with the
    method "scipy" and its own calls, which add up to the run's."""
    result = ballc.simulate(ballc.Scene(), 0.2, method="RK45", rtol=1e-4, atol=1e-4)
    log = result.segments
    assert set(log["method"]) == {"scipy"} and set(log["method_end"]) == {"scipy"}
    assert log["nfev"].sum() == result.nfev > 0


def test_a_saved_result_has_no_log(tmp_path):
    result = ballc.simulate(ballc.Scene(), 0.2, rtol=1e-4, atol=1e-4)
    assert result.segments is not None
    result.save(tmp_path / "run.npz")
    assert ballc.load(tmp_path / "run.npz").segments is None
