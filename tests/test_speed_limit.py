"""The scene's speeds are checked (docs/limits.md): a spin far beyond what any ball
survives (its rim speed against the ball's own wave speed) and a throw at the speed of
light are rejected before anything runs, with an error naming the field, the value and
the limit -- instead of a run crawling to its call budget, or numpy's warnings from
overflowing numbers."""
import math
import warnings

import numpy as np
import pytest

import ballc
from ballc.scene import SPEED_LIMIT, SPEED_OF_LIGHT, wave_speed


def test_wave_speed_is_sqrt_e_over_density():
    """Oracle: c = sqrt(E / rho), rho = m / (4/3 pi r^3), by hand for two balls."""
    scene = ballc.Scene()                     # 1 kg, r = 1 m, E = 3 kPa
    rho = 1.0 / (4.0 / 3.0 * math.pi)
    assert wave_speed(scene) == pytest.approx(math.sqrt(3e3 / rho), rel=1e-14)
    steel = ballc.Scene(mass=7800 * 4 / 3 * math.pi * 0.01 ** 3, radius=0.01,
                        ceiling_height=1.0, position=(0, 0, 0.5),
                        ball_youngs_modulus=2e11, plane_youngs_modulus=2e11)
    assert wave_speed(steel) == pytest.approx(math.sqrt(2e11 / 7800), rel=1e-12)


@pytest.mark.parametrize("spin", [1e12, 1e300])
def test_an_absurd_spin_is_rejected_at_once(spin):
    """Issue 28, item 6: 1e12 rad/s was accepted and crawled 12-30 s to the call
    budget; 1e300 leaked numpy's RuntimeWarning (outcome.py)."""
    with pytest.raises(ballc.SceneError, match=r"angular_velocity = .*is not allowed.*"
                       r"rim speed.*wave speed"):
        ballc.Scene(angular_velocity=(0.0, 0.0, spin))


@pytest.mark.parametrize("speed", [1e12, 1e300])
def test_an_absurd_throw_is_rejected_at_once(speed):
    with pytest.raises(ballc.SceneError, match=r"velocity = .*is not allowed.*speed of "
                       r"light"):
        ballc.Scene(velocity=(speed, 0.0, -speed))


def test_the_limit_is_where_it_is_documented():
    """Just inside the limits is a valid scene; just outside is not: the rim speed
    r |w| against SPEED_LIMIT times the wave speed, the centre speed |v| against the
    speed of light (a throw far faster than the wave speed is allowed: it ends with an
    honest "passed through")."""
    scene = ballc.Scene()
    c = wave_speed(scene)
    limit = SPEED_LIMIT * c / scene.radius
    ballc.Scene(angular_velocity=(0.0, 0.6 * limit, 0.8 * limit * (1 - 1e-9)))
    with pytest.raises(ballc.SceneError, match="angular_velocity"):
        ballc.Scene(angular_velocity=(0.0, 0.6 * limit, 0.8 * limit * (1 + 1e-9)))
    ballc.Scene(velocity=(0.0, 0.0, -SPEED_OF_LIGHT * (1 - 1e-9)))
    with pytest.raises(ballc.SceneError, match="velocity"):
        ballc.Scene(velocity=(0.0, 0.0, -SPEED_OF_LIGHT))
    fast = ballc.simulate(ballc.Scene(velocity=(0.0, 0.0, -10 * c)), 1.0)
    assert fast.status == 1 and "passed through" in fast.message


def test_y0_is_held_to_the_same_limit():
    scene = ballc.Scene()
    y0 = scene.initial_state()
    y0[list(ballc.STATE_NAMES).index("omega_z")] = 1e12
    with pytest.raises(ballc.SceneError, match="y0.*rim speed"):
        ballc.simulate(scene, 1.0, y0=y0)


def test_a_spin_at_the_limit_runs_without_numpy_warnings():
    """The fastest spin allowed on the default ball: an answer, and no numpy warning
    leaks (every warning an error here)."""
    scene = ballc.Scene()
    spin = 0.99 * SPEED_LIMIT * wave_speed(scene) / scene.radius
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = ballc.simulate(scene.replace(angular_velocity=(0.0, 0.0, spin)), 0.05)
    assert np.isfinite(result.y).all()
