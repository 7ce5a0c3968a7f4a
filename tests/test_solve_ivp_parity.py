"""simulate as a solve_ivp user expects it: dense output, events, first_step, y0.

Oracles: the ballistic parabola of free flight (no contact before t = 0.15 s in the
seed throw), continuity of the state across contact events, and scipy's own event
semantics (terminal, direction).
"""
import math

import numpy as np
import pytest

import ballc
from ballc import _core

Z = _core.STATE_INDEX["z"]
VZ = _core.STATE_INDEX["vz"]
G = 9.81


def flight_height(t, z0=5.0, vz0=-25.0):
    return z0 + vz0 * t - 0.5 * G * t * t


def first_floor_contact_time(scene=ballc.Scene()):
    """The ballistic time at which z = r (the seed throw: z0 = 5, vz0 = -25)."""
    z0, vz0, r = scene.position[2], scene.velocity[2], scene.radius
    return (-vz0 - math.sqrt(vz0 ** 2 + 2 * G * (z0 - r))) / (-G)


@pytest.mark.parametrize("method", ["radau5", "dop853", "Radau"])
def test_dense_output_follows_the_parabola_in_flight(method):
    """In free flight (before the first contact) sol(t) is the integrator's interpolant
    of an exact parabola: it must match it to the tolerance's order."""
    result = ballc.simulate(ballc.Scene(), 0.6, method=method, rtol=1e-10, atol=1e-10,
                            dense_output=True)
    t = np.linspace(0.0, 0.9 * first_floor_contact_time(), 57)
    np.testing.assert_allclose(result.sol(t)[Z], flight_height(t), atol=1e-8)
    assert result.sol(0.05).shape == (len(ballc.STATE_NAMES),)
    assert result.sol(t).shape == (len(ballc.STATE_NAMES), t.size)


@pytest.mark.parametrize("method", ["radau5", "dop853", "Radau"])
def test_dense_output_agrees_with_the_stored_samples_across_contacts(method):
    """Over a run with contacts and stick/slip events the interpolant passes through
    every stored sample (the integrator's own steps) and is continuous at the events."""
    result = ballc.simulate(ballc.Scene(), 1.2, method=method, rtol=1e-9, atol=1e-9,
                            dense_output=True)
    assert result.status == 0 and len(result.contacts) == 3
    # At an event the later segment starts from the event state with its quaternion
    # renormalised (a jump of the norm's drift, ~1e-10): the only difference allowed.
    np.testing.assert_allclose(result.sol(result.t), result.y, rtol=1e-12, atol=1e-9)
    for contact in result.contacts:
        for t_event in (contact.t_start, contact.t_end):
            before, after = result.sol(t_event - 1e-12), result.sol(t_event + 1e-12)
            np.testing.assert_allclose(before[:13], after[:13], atol=1e-6)
    with pytest.raises(ValueError, match="outside"):
        result.sol(1.3)


def test_no_dense_output_by_default():
    assert ballc.simulate(ballc.Scene(), 0.1).sol is None


@pytest.mark.parametrize("method", ["radau5", "dop853", "Radau", "BDF"])
def test_user_event_finds_the_ballistic_crossing(method):
    """g = z - 3 m falling: the parabola crosses at t = (25 - sqrt(625 - 2 g 2)) / g...
    solved exactly; the event is not terminal, so the run goes on to t_end."""
    def height(t, y):
        return y[Z] - 3.0
    height.direction = -1
    result = ballc.simulate(ballc.Scene(), 0.4, method=method, rtol=1e-10, atol=1e-10,
                            events=height)
    expected = (-25.0 + math.sqrt(25.0 ** 2 - 2 * G * (3.0 - 5.0))) / G
    assert result.status == 0 and result.t[-1] == 0.4
    assert len(result.t_events) == 1 and result.t_events[0].shape == (1,)
    assert result.t_events[0][0] == pytest.approx(expected, abs=1e-9)
    assert result.y_events[0][0, Z] == pytest.approx(3.0, abs=1e-9)


def test_terminal_user_event_stops_the_run_with_status_one():
    """Like solve_ivp: a terminal event ends the integration there, status 1."""
    def apex(t, y):   # vz = 0 after the first bounce: the top of the flight
        return y[VZ]
    apex.terminal = True
    apex.direction = -1
    # a vertical throw under a high ceiling: after the first bounce the ball rises to
    # its apex, at t_end + vz_after / g (free flight)
    scene = ballc.Scene(ceiling_height=100.0, velocity=(0.0, 0.0, -5.0))
    result = ballc.simulate(scene, 3.0, events=[apex])
    assert result.status == 1 and result.message == "A termination event occurred."
    bounce = result.contacts[0]
    vz_after = bounce.velocity_after[2]
    assert result.t[-1] == pytest.approx(bounce.t_end + vz_after / G, abs=1e-8)
    assert result.t_events[0][-1] == result.t[-1]


def test_a_failing_user_event_raises_its_error():
    def broken(t, y):
        raise RuntimeError("user event failed")
    with pytest.raises(RuntimeError, match="user event failed"):
        ballc.simulate(ballc.Scene(), 0.1, events=broken)


def test_bad_events_and_options_are_named():
    with pytest.raises(ballc.SceneError, match="events"):
        ballc.simulate(ballc.Scene(), 0.1, events=[3.0])
    with pytest.raises(ballc.SceneError, match="first_step"):
        ballc.simulate(ballc.Scene(), 0.1, first_step=0.0)
    with pytest.raises(ballc.SceneError, match="first_step"):
        ballc.simulate(ballc.Scene(), 0.1, first_step=1.0)
    with pytest.raises(ballc.SceneError, match="dense_output"):
        ballc.simulate(ballc.Scene(), 0.1, dense_output="yes")


def test_first_step_is_used():
    """The first step of the run is the one asked for: the second stored time."""
    result = ballc.simulate(ballc.Scene(), 0.05, first_step=1e-5)
    assert result.t[1] == pytest.approx(1e-5, rel=1e-12)


def test_start_from_a_full_state_or_a_quaternion():
    """y0 = the scene's own initial state gives the same bits; a quaternion start is the
    same rotation as the equivalent 123 angles."""
    scene = ballc.Scene(angles=(0.3, -0.2, 0.1), angular_velocity=(1.0, 2.0, 3.0))
    default = ballc.simulate(scene, 0.3)
    given = ballc.simulate(scene, 0.3, y0=scene.initial_state())
    assert np.array_equal(default.y, given.y)
    y0 = scene.initial_state()
    y0[:4] *= 2.5      # any non-zero scale: normalised
    scaled = ballc.simulate(scene, 0.3, y0=y0)
    np.testing.assert_allclose(scaled.y, default.y, rtol=1e-12, atol=1e-12)
    with pytest.raises(ballc.SceneError, match="quaternion"):
        ballc.simulate(scene, 0.3, y0=np.zeros(len(ballc.STATE_NAMES)))
    with pytest.raises(ballc.SceneError, match="y0"):
        ballc.simulate(scene, 0.3, y0=[1.0, 2.0])


# --- issue 21, item 4: the remaining gaps ---

def test_an_empty_t_eval_is_a_clear_error():
    """t_eval=[] raised a bare IndexError from the post-processing."""
    with pytest.raises(ballc.SceneError, match=r"t_eval = \[\] is not allowed: must hold "
                                               "at least one time"):
        ballc.simulate(ballc.Scene(), 0.5, t_eval=[])


@pytest.mark.parametrize("method, exact_flight", [("radau5", True), ("radau5", False),
                                                  ("dop853", False), ("RK45", False)])
@pytest.mark.parametrize("terminal", [2, 3])
def test_terminal_k_stops_at_the_kth_occurrence(method, exact_flight, terminal):
    """As scipy >= 1.12: terminal = k stops at the k-th occurrence, counted over the
    whole run (here each falling crossing of z = 4 m is in another flight segment),
    with a function of the user's and with a LinearEvent (closed form in exact flight)."""
    scene = ballc.Scene(observer_mass=0.0)

    def below(t, y):
        return y[Z] - 4.0
    below.direction, below.terminal = -1, terminal
    linear = ballc.events.LinearEvent.of_state("z", offset=-4.0, terminal=terminal,
                                               direction=-1)
    free = ballc.simulate(scene, 5.0, events=lambda t, y: y[Z] - 4.0, method=method,
                          exact_flight=exact_flight, rtol=1e-9, atol=1e-9)
    falling = free.t_events[0][free.y_events[0][:, VZ] < 0]
    assert len(falling) >= 3
    for event in (below, linear):
        result = ballc.simulate(scene, 5.0, events=event, method=method,
                                exact_flight=exact_flight, rtol=1e-9, atol=1e-9)
        assert result.status == 1 and len(result.t_events[0]) == terminal
        np.testing.assert_allclose(result.t_events[0], falling[:terminal], rtol=1e-7)
        assert result.t[-1] == pytest.approx(falling[terminal - 1], rel=1e-7)


@pytest.mark.parametrize("method", ["radau5", "dop853", "RK45"])
def test_terminal_k_counts_occurrences_within_one_segment(method):
    """cos(100 t) = 0 three times in the first flight segment (t < 0.155 s)."""
    def g(t, y):
        return math.cos(100 * t)
    g.terminal = 3
    result = ballc.simulate(ballc.Scene(), 1.0, events=g, method=method, rtol=1e-9,
                            atol=1e-9, max_step=0.005)
    expected = np.pi * np.array([1, 3, 5]) / 200
    np.testing.assert_allclose(result.t_events[0], expected, rtol=1e-8)
    assert result.status == 1 and result.t[-1] == pytest.approx(expected[-1], rel=1e-8)


@pytest.mark.parametrize("terminal", [1.5, -1, "yes"])
def test_a_bad_terminal_is_named(terminal):
    def g(t, y):
        return y[Z] - 4.0
    g.terminal = terminal
    with pytest.raises(ballc.SceneError, match=r"events\[0\].terminal = "):
        ballc.simulate(ballc.Scene(), 0.5, events=g)


@pytest.mark.parametrize("method", ["radau5", "RK45"])
def test_an_event_returning_nan_raises(method):
    """It was silently never triggered."""
    def g(t, y):
        return math.nan if t > 0.05 else 1.0
    with pytest.raises(ValueError, match=r"events\[0\] returned nan at t = .* finite number"):
        ballc.simulate(ballc.Scene(), 0.5, events=[g], method=method)


def test_a_result_is_read_like_scipys_oderesult():
    """scipy's OdeResult is a dict: r['t'] as well as r.t."""
    result = ballc.simulate(ballc.Scene(), 0.3, dense_output=True)
    for key in ("t", "y", "sol", "t_events", "y_events", "nfev", "status", "message",
                "success"):
        assert result[key] is getattr(result, key) or result[key] == getattr(result, key)
        assert key in result
    assert set(dict(result)) == set(result.keys())
    with pytest.raises(KeyError, match="result.position"):
        result["position"]


def test_sol_takes_arrays_of_any_shape():
    """sol on a 2-D array raised IndexError: it gives (N_STATES,) + t.shape, each
    column the state at that time."""
    result = ballc.simulate(ballc.Scene(), 1.2, dense_output=True)
    times = np.array([[0.1, 0.2, 0.3], [0.6, 0.9, 1.1]])
    values = result.sol(times)
    assert values.shape == (len(ballc.STATE_NAMES), 2, 3)
    for index in np.ndindex(times.shape):
        np.testing.assert_array_equal(values[(slice(None),) + index], result.sol(times[index]))
    assert result.sol(np.empty((0,))).shape == (len(ballc.STATE_NAMES), 0)
