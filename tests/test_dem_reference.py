"""validation/dem_reference.py (the explicit DEM oracle) against independent facts:
Hertz's contact time, Hunt-Crossley's restitution, passivity, gross sliding, convergence.
"""
import math

import numpy as np
import pytest

from validation.dem_reference import (HERTZ_TIME_CONSTANT, dem_impact,
                                      dem_impact_converged, hertz_contact_time,
                                      rebound_difference)

# Al oxide sphere on a rigid plane (Chung & Ooi test 3/4 material), SI units
R = 0.0025
M = 4.0 / 3.0 * math.pi * R ** 3 * 4000.0
I = 0.4 * M * R ** 2
NU = 0.23
K0 = 4.0 / 3.0 * math.sqrt(R) * 3.8e11 / (1 - NU ** 2)
KAPPA = 2 * (1 - NU) / (2 - NU)
BALL = dict(mass=M, radius=R, inertia=I, k0=K0)


def test_hertz_constant_by_quadrature():
    # t_c = 2 rho_max / v * int_0^1 dx / sqrt(1 - x^(5/2)), rho_max = (5 m v^2/(4 k0))^(2/5);
    # x = 1 - u^2 removes the endpoint singularity; Gauss-Legendre on u in (0, 1)
    u, wts = np.polynomial.legendre.leggauss(60)
    u = 0.5 * (u + 1.0)
    integral = 0.5 * np.sum(wts * 2 * u / np.sqrt(1 - (1 - u ** 2) ** 2.5))
    constant = 2 * 1.25 ** 0.4 * integral
    assert constant == pytest.approx(HERTZ_TIME_CONSTANT, rel=1e-12)
    assert HERTZ_TIME_CONSTANT == pytest.approx(3.21807, abs=1e-5)


@pytest.mark.parametrize("speed", [0.2, 3.9])
def test_elastic_normal_impact(speed):
    hit = dem_impact(**BALL, kappa=KAPPA, mu=0.0, velocity=(0.0, 0.0, -speed),
                     steps_per_contact=4000)
    assert hit["velocity_after"][2] / speed == pytest.approx(1.0, abs=1e-4)
    assert hit["contact_time"] == pytest.approx(hertz_contact_time(M, K0, speed), rel=1e-6)
    assert hit["max_penetration"] == pytest.approx(
        (1.25 * M * speed ** 2 / K0) ** 0.4, rel=1e-6)


def test_frictionless_oblique_keeps_tangential_motion():
    v, w = np.array([1.0, -2.0, -3.0]), np.array([300.0, 200.0, -100.0])
    hit = dem_impact(**BALL, kappa=KAPPA, mu=0.0, velocity=v, angular_velocity=w,
                     steps_per_contact=2000)
    assert np.allclose(hit["velocity_after"], [1.0, -2.0, 3.0], rtol=0, atol=3e-4)
    assert np.allclose(hit["angular_velocity_after"], w, rtol=0, atol=1e-12)


def chi_of_restitution(e):
    """Solve chi (1 + e) = ln((1 + chi)/(1 - chi e)) for chi in (0, 1/e) by bisection."""
    f = lambda chi: math.log1p(chi) - math.log1p(-chi * e) - chi * (1 + e)  # noqa: E731
    lo, hi = 1e-6, (1.0 - 1e-12) / e          # f(lo) < 0 < f(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("e", [0.3, 0.7, 0.98])
def test_hunt_crossley_restitution(e):
    chi = chi_of_restitution(e)
    hit = dem_impact(**BALL, kappa=KAPPA, mu=0.0, velocity=(0.0, 0.0, -3.9), chi=chi,
                     steps_per_contact=4000)
    assert hit["velocity_after"][2] / 3.9 == pytest.approx(e, abs=1e-3)


def random_oblique(rng, speed=3.9):
    """Incident angle 5..85 deg, random azimuth, spin |omega| R <= 2 speed about a random
    axis, kappa 0.1..1.2, mu 0.05..1.5."""
    theta, phi = np.radians(rng.uniform(5, 85)), rng.uniform(0, 2 * np.pi)
    v = speed * np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                          -np.cos(theta)])
    axis = rng.normal(size=3)
    w = axis / np.linalg.norm(axis) * rng.uniform(0, 2) * speed / R
    return dict(velocity=v, angular_velocity=w, kappa=rng.uniform(0.1, 1.2),
                mu=rng.uniform(0.05, 1.5))


def test_no_energy_gain_without_damping(rng):
    for _ in range(30):
        case = random_oblique(rng)
        hit = dem_impact(**BALL, **case, steps_per_contact=2000)
        v, w = case["velocity"], case["angular_velocity"]
        kinetic = 0.5 * M * v @ v + 0.5 * I * w @ w
        assert hit["dissipated"] >= -1e-12 * kinetic, case


def test_damping_dissipates(rng):
    for _ in range(5):
        case = random_oblique(rng)
        plain = dem_impact(**BALL, **case, steps_per_contact=2000)
        damped = dem_impact(**BALL, **case, normal_damping="viscoelastic", gamma=0.2,
                            gamma_t=0.2, steps_per_contact=2000)
        assert damped["dissipated"] > plain["dissipated"] > 0


@pytest.mark.parametrize("spin", [0.0, 400.0])
def test_gross_sliding_impulse_ratio(spin):
    # slip 5 |v_n| along x (spin about y adds to it): kappa v_t > mu v_n puts F_el at the
    # cap from the first step, and the slip cannot stop (it loses 3.5 mu (1 + e) v_n)
    mu, vn = 0.1, 3.0
    hit = dem_impact(**BALL, kappa=KAPPA, mu=mu, velocity=(5 * vn, 0.0, -vn),
                     angular_velocity=(0.0, -spin, 0.0), chi=0.2, gamma_t=0.3,
                     steps_per_contact=4000)
    jt = np.linalg.norm(hit["tangential_impulse"])
    jn = hit["normal_impulse"][2]
    assert jt / (mu * jn) == pytest.approx(1.0, abs=1e-3)
    assert hit["tangential_impulse"][0] < 0 and abs(hit["tangential_impulse"][1]) < 1e-12


@pytest.mark.parametrize("damping", [{}, dict(chi=0.3, gamma_t=0.25),
                                     dict(normal_damping="viscoelastic", gamma=0.3,
                                          gamma_t=0.3)])
def test_convergence_estimate_holds(rng, damping):
    case = random_oblique(rng)
    tol = 1e-4
    conv = dem_impact_converged(**BALL, **case, **damping, rel_tol=tol)
    assert conv["error_estimate"] <= tol
    # the estimate is honest: a run with 4x the steps is within tol of the returned one
    finer = dem_impact(**BALL, **case, **damping,
                       steps_per_contact=4 * conv["steps_per_contact"])
    assert rebound_difference(conv, finer, R, 3.9) <= tol


@pytest.mark.parametrize("damping", [{}, dict(chi=0.3, gamma_t=0.25)])
def test_midpoint_stiffness_converges_to_the_same_law(rng, damping):
    # two quadratures of the loading increment -k_t v_t dt, one limit
    tol = 1e-5
    for _ in range(3):
        case = random_oblique(rng)
        dem = dem_impact_converged(**BALL, **case, **damping, rel_tol=tol)
        mid = dem_impact_converged(**BALL, **case, **damping, rel_tol=tol,
                                   midpoint_stiffness=True)
        assert rebound_difference(dem, mid, R, 3.9) <= 2 * tol


def test_convergence_cap_raises():
    with pytest.raises(RuntimeError, match="no convergence"):
        dem_impact_converged(**BALL, kappa=1.0, mu=1.5, velocity=(1.0, 0.0, -3.0),
                             angular_velocity=(0.0, 0.0, 0.0), rel_tol=1e-12,
                             steps_per_contact=500, max_steps_per_contact=2000)


# ---------------------------------------------------------------- validation/dem_agreement
def test_agreement_mapping_and_random_impacts():
    from types import SimpleNamespace

    from validation.dem_agreement import (hunt_crossley_chi, random_impacts,
                                          reference_parameters)
    for e in (0.2, 0.9, 0.999):
        assert hunt_crossley_chi(e) == pytest.approx(chi_of_restitution(e), rel=1e-9)
    assert hunt_crossley_chi(1.0) == 0.0
    # a scene of today's ballc (no damping fields): zero damping, chi from c_tau
    old = SimpleNamespace(gravity=0.0, inertia=(I, I, I), mass=M, observer_mass=0.0,
                          radius=R, hertz_stiffness=K0, tangential_stiffness_ratio=0.5,
                          friction_coefficient=0.3, c_tau=0.9)
    p = reference_parameters(old)
    assert (p["normal_damping"], p["gamma"], p["gamma_t"]) == ("hunt_crossley", 0.0, 0.0)
    assert p["chi"] == pytest.approx(0.15) and p["k0"] == K0 and p["inertia"] == I
    new = SimpleNamespace(**vars(old), normal_damping="viscoelastic", damping_ratio=0.2,
                          tangential_damping_ratio=0.3, restitution=None)
    p = reference_parameters(new)
    assert (p["normal_damping"], p["gamma"], p["gamma_t"]) == ("viscoelastic", 0.2, 0.3)
    with pytest.raises(ValueError, match="isotropic"):
        reference_parameters(SimpleNamespace(**{**vars(old), "inertia": (I, I, 2 * I)}))

    impacts = random_impacts(50, seed=3)
    assert impacts == random_impacts(50, seed=3)
    for d in impacts:
        v, w = np.array(d["velocity"]), np.array(d["angular_velocity"])
        angle = np.degrees(np.arccos(-v[2] / np.linalg.norm(v)))
        assert 5 <= angle <= 85 and np.linalg.norm(w) * d["radius"] <= 2 * 3.9 + 1e-12
        assert 0.1 <= d["tangential_stiffness_ratio"] <= 1.2
        assert 0.05 <= d["friction_coefficient"] <= 1.5
        assert d["gravity"] == 0.0 and d["observer_mass"] == 0.0 and d["c_tau"] == 1.0
