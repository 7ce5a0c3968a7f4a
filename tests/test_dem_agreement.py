"""ballc's compliant law against the explicit DEM oracle (validation/dem_reference.py),
on a few fixed impacts: fast checks that the law's parts (tangential stiffness, the
exact modes and the smooth yield, tangential damping, dilution) are the oracle's
(benchmarks/plant_defects.py)."""
import numpy as np
import pytest

import ballc
from validation.dem_agreement import compare, random_impacts, reference_parameters
from validation.dem_reference import dem_impact_converged


@pytest.mark.parametrize("seed", [0, 1])
def test_random_impacts_agree_with_the_dem_oracle(seed):
    # 12 undamped 3-D oblique spinning impacts with the exact elastic/sliding modes (the
    # default): the bar is 1 % of the impact speed; measured over 300 such
    # impacts the worst is of the order of the oracle's own convergence (rel_tol)
    errors = compare(random_impacts(6, seed=seed), rel_tol=1e-5)
    assert errors.max() < 1e-3, errors


@pytest.mark.parametrize("seed", [0, 1])
def test_smooth_yield_agrees_with_the_dem_oracle(seed):
    # the law without modes (friction_regularization "smooth"): the cap by the smooth
    # yield of exponent 64 alone; its worst over 300 impacts is 0.81 %
    impacts = [dict(kwargs, friction_regularization="smooth")
               for kwargs in random_impacts(6, seed=seed)]
    errors = compare(impacts, rel_tol=1e-4)
    assert errors.max() < 0.01, errors


def _oblique(**law):
    """A 30 deg oblique impact at 3.9 m/s without spin, kappa 0.8, mu 1 (mostly
    sticking: the rebound spin shows the tangential stiffness)."""
    scene = dict(random_impacts(1, seed=0)[0])
    v = 3.9 * np.array([np.sin(np.radians(30.0)), 0.0, -np.cos(np.radians(30.0))])
    scene.update(velocity=tuple(float(c) for c in v), angular_velocity=(0.0, 0.0, 0.0),
                 tangential_stiffness_ratio=0.8, friction_coefficient=1.0, **law)
    return ballc.Scene(**scene)


@pytest.mark.parametrize("law", [dict(c_tau=1.0),
                                 dict(c_tau=0.6, tangential_damping_ratio=0.3)],
                         ids=["elastic", "damped"])
def test_oblique_impact_rebound_spin_matches_the_dem_oracle(law):
    # measured: 3.1e-5 (elastic), 1.4e-5 (damped) relative
    scene = _oblique(**law)
    hit = ballc.impact(scene, scene.velocity, scene.angular_velocity)
    ref = dem_impact_converged(**reference_parameters(scene), velocity=scene.velocity,
                               angular_velocity=scene.angular_velocity, rel_tol=1e-5)
    ours, theirs = hit.angular_velocity_after[1], ref["angular_velocity_after"][1]
    assert abs(ours - theirs) < 1e-3 * abs(theirs), (ours, theirs)   # measured 3e-5
