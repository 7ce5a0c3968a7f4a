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
