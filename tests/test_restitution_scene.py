"""Scene.restitution reaches any e in (0, 1] with the law in use: a normal impact's
exit/entry speed ratio, measured by integration, equals the e asked for (the inversion
in ballc.restitution against ballc's own generated force)."""
import math

import numpy as np
import pytest

import ballc
from ballc import SceneError


def normal_impact(e, **law):
    r, density, E, nu = 0.0025, 4000.0, 3.8e11, 0.23
    scene = ballc.Scene(mass=4 / 3 * math.pi * r ** 3 * density, radius=r, observer_mass=0.0,
                        gravity=0.0, ceiling_height=10 * r, position=(0, 0, 5 * r),
                        velocity=(0, 0, -1), ball_youngs_modulus=E, ball_poisson_ratio=nu,
                        plane_youngs_modulus=1e9 * E, plane_poisson_ratio=nu,
                        friction_coefficient=0.0, restitution=e, **law)
    return ballc.impact(scene, (0.0, 0.0, -3.9), rtol=1e-10).e_n


@pytest.mark.parametrize("e", [0.05, 0.2, 0.49, 0.8, 1.0])
def test_hunt_crossley_restitution_below_c_taus_limit(e):
    # c_tau in (0, 1] only reaches e > 0.4877; restitution reaches every e
    assert normal_impact(e, tangential_model="friction") == pytest.approx(e, abs=1e-6)


@pytest.mark.parametrize("e", [0.1, 0.3, 0.7, 0.95])
def test_viscoelastic_restitution(e):
    assert normal_impact(e, tangential_model="compliant",
                         normal_damping="viscoelastic") == pytest.approx(e, abs=1e-6)


def test_a_scene_gives_one_damping_input():
    with pytest.raises(SceneError, match="c_tau and restitution"):
        ballc.Scene(c_tau=0.9, restitution=0.5)
    with pytest.raises(SceneError, match="restitution = 0.0"):
        ballc.Scene(restitution=0.0)
    with pytest.raises(SceneError, match="needs restitution"):
        ballc.Scene(tangential_model="compliant", normal_damping="viscoelastic")
    with pytest.raises(SceneError, match="part of the compliant"):
        ballc.Scene(normal_damping="viscoelastic", restitution=0.5)
    with pytest.raises(SceneError, match="did you mean 'viscoelastic'"):
        ballc.Scene(tangential_model="compliant", normal_damping="viscoelastc",
                    restitution=0.5)
    scene = ballc.Scene(restitution=0.3)
    assert scene.replace(c_tau=0.8).restitution is None        # replace drops the other
    assert ballc.Scene.from_dict(scene.to_dict()) == scene     # round trip


def test_tangential_damping_ratio_defaults_to_the_viscoelastic_gamma_of_e():
    from ballc.restitution import viscoelastic_gamma_for_restitution
    scene = ballc.Scene(tangential_model="compliant", restitution=0.5)
    assert scene.tangential_damping_ratio == pytest.approx(
        viscoelastic_gamma_for_restitution(0.5), rel=1e-12)
    assert ballc.Scene(tangential_model="compliant", c_tau=1.0).tangential_damping_ratio == 0.0
    # no other law has tangential damping: nothing is derived (the inversion costs ~60 ms)
    assert ballc.Scene(c_tau=0.8).tangential_damping_ratio is None
    assert np.isfinite(ballc.Scene().parameter_vector()).all()
