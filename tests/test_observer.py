"""The observer's specific force against oracles the code under test did not produce:
free flight (0 without spin, the centripetal term with spin), resting contact (+1 g·g0/9.80665
up), and a finite-difference second derivative of the observer's sampled trajectory."""
import numpy as np
import pytest

import ballc
from ballc.observer import STANDARD_GRAVITY


def test_free_flight_without_spin_feels_nothing():
    result = ballc.simulate(ballc.Scene(velocity=(1.0, -2.0, 3.0)), 0.3)
    assert not result.contacts
    assert np.abs(result.observer_specific_force).max() < 1e-12
    assert np.abs(result.observer_specific_force_ball).max() < 1e-12


def test_free_flight_with_spin_feels_the_centripetal_term():
    scene = ballc.Scene(observer_mass=0.0, angular_velocity=(1.0, -2.0, 3.0),
                        velocity=(1.0, 0.0, 2.0))
    result = ballc.simulate(scene, 0.3)
    assert not result.contacts
    rho = result.observer_position - result.position
    omega = result.angular_velocity
    centripetal = np.cross(omega, np.cross(omega, rho, axis=0), axis=0) / STANDARD_GRAVITY
    assert np.abs(result.observer_specific_force - centripetal).max() < 1e-9
    # ball frame: same magnitude, and the accelerometer reading is constant (steady spin)
    ball = result.observer_specific_force_ball
    assert np.allclose(np.linalg.norm(ball, axis=0), np.linalg.norm(centripetal, axis=0))
    assert np.abs(ball - ball[:, :1]).max() < 1e-9


def test_resting_on_the_floor_feels_one_g_up():
    """Released at rest touching the floor: the tiny latched impact rate makes the contact
    heavily (over)damped, the ball creeps towards its static depth, and the observer
    feels the floor's support (to 1e-6 g after 10 s of creep)."""
    scene = ballc.Scene(observer_mass=0.0, position=(0.0, 0.0, 1.0), velocity=(0.0, 0.0, 0.0))
    result = ballc.simulate(scene, 10.0)
    assert len(result.contacts) == 1 and np.isnan(result.contacts[0].t_end)
    force = result.observer_specific_force[:, -1]
    assert force == pytest.approx([0.0, 0.0, scene.gravity / STANDARD_GRAVITY], abs=1e-6)


def test_acceleration_matches_finite_differences_through_contacts():
    """Through contacts (flags and latched values matter): second differences of the
    observer's position on a fine uniform grid agree with the computed acceleration."""
    # dig-in uses both latched values (rate and direction); mu = 0 leaves out Coulomb
    # friction, whose stick-slip kink (1e-10 m/s regularisation) finite differences cannot follow
    scene = ballc.Scene(position=(0.0, 0.0, 1.5), velocity=(-3.0, 2.0, -6.0),
                        angular_velocity=(0.0, 0.0, 2.0), tangential_model="dig-in",
                        friction_coefficient=0.0)
    step = 2e-4
    t_eval = np.arange(0.0, 0.6, step)
    result = ballc.simulate(scene, 0.6, t_eval=t_eval, rtol=1e-12, atol=1e-12)
    assert len(result.contacts) >= 1
    position = result.observer_position
    second = (position[:, 2:] - 2 * position[:, 1:-1] + position[:, :-2]) / step ** 2
    computed = result.observer_acceleration[:, 1:-1]
    contact = (result.flags & ~ballc._core.FLAGS["observer"]) != 0
    # interior samples whose stencil neighbours are in contact too (the force has a kink
    # at contact start and end, where second differences mean nothing)
    in_contact = contact[2:] & contact[1:-1] & contact[:-2]
    assert in_contact.sum() > 50
    scale = np.abs(computed).max()
    assert np.abs(second - computed)[:, in_contact].max() < 1e-4 * scale
