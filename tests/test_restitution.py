"""ballc.restitution: the restitution of the Hunt-Crossley and viscoelastic (Hertz viscous)
normal damping laws and their inverses, against direct integrations of the impact ODEs."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ballc.restitution import (RESTITUTION_RANGE, VISCOELASTIC_LARGE_GAMMA_COEFFICIENT,
                               hunt_crossley_chi_for_restitution,
                               hunt_crossley_restitution_of_chi, restitution_limits,
                               viscoelastic_gamma_for_restitution,
                               viscoelastic_restitution)

RESTITUTIONS = [0.05] + [k / 10 for k in range(1, 11)]


# --- Hunt-Crossley ---------------------------------------------------------------------

def hc_residual(chi, e):
    return chi * (1 + e) - math.log((1 + chi) / (1 - chi * e))


@pytest.mark.parametrize("chi", [1e-9, 1e-4, 0.05, 0.0999, 0.1, 0.5, 1.0, 1.5, 3.087, 9.998,
                                 40.0, 1e3, 1e6])
def test_hc_forward_solves_the_relation(chi):
    e = hunt_crossley_restitution_of_chi(chi)
    assert 0 < e < 1 and e <= 1 / chi
    if chi * e < 1 - 1e-12:       # else 1 - chi e is lost to rounding: e = 1/chi
        assert abs(hc_residual(chi, e)) < 1e-13 * max(1.0, chi)
    else:
        assert e == pytest.approx(1 / chi, rel=1e-14)


def test_hc_forward_small_chi_series_is_continuous():
    below, above = (hunt_crossley_restitution_of_chi(0.1 * (1 + s * 1e-15)) for s in (-1, 1))
    assert abs(below - above) < 1e-15
    assert hunt_crossley_restitution_of_chi(0.0) == 1.0
    assert hunt_crossley_restitution_of_chi(1e-8) == pytest.approx(1 - 2e-8 / 3, rel=1e-15)


def hc_impact_direct(chi, m=0.7, k0=3.0e5, v0=1.3):
    """e of m rho'' = -max(0, k0 rho^1.5 (1 + chi rho'/v0)), rho(0) = 0, rho'(0) = v0."""
    def rhs(t, y):
        rho, v = y
        return [v, -max(0.0, k0 * max(rho, 0.0) ** 1.5 * (1 + chi * v / v0)) / m]

    def exit_(t, y):
        return y[0]
    exit_.terminal, exit_.direction = True, -1
    t_hertz = (m / (k0 * math.sqrt(v0))) ** 0.4
    sol = solve_ivp(rhs, (0, 1e3 * t_hertz), [0.0, v0], method="DOP853", rtol=1e-12,
                    atol=[1e-16, 1e-14], events=exit_, first_step=1e-6 * t_hertz)
    return -sol.y_events[0][0][1] / v0


@pytest.mark.parametrize("chi, known", [(9.998, 0.1000), (3.087, 0.300), (0.4, None),
                                        (0.05, None)])
def test_hc_against_direct_integration(chi, known):
    e = hunt_crossley_restitution_of_chi(chi)
    assert hc_impact_direct(chi) == pytest.approx(e, rel=1e-10)
    if known is not None:
        assert e == pytest.approx(known, abs=1e-4)


@pytest.mark.parametrize("e", RESTITUTIONS + [1 - 1e-12, 1 - 1e-6, 0.9, 0.89999, 1e-3, 1e-8])
def test_hc_round_trip(e):
    chi = hunt_crossley_chi_for_restitution(e)
    assert hunt_crossley_restitution_of_chi(chi) == pytest.approx(e, rel=1e-13, abs=0)
    if e == 1:
        assert chi == 0.0


def test_hc_inverse_is_accurate_near_one():
    # chi ~ 3/2 (1 - e): relative accuracy of chi itself, not only of e
    for d in (1e-14, 1e-10, 1e-6, 1e-3):
        chi = hunt_crossley_chi_for_restitution(1 - d)
        d_exact = 1 - (1 - d)             # the d that 1 - d holds in floating point
        assert chi == pytest.approx(1.5 * d_exact * (1 + d_exact), rel=2e-3 * d + 1e-15)


@pytest.mark.parametrize("bad", [0.0, -0.1, 1.0000001, 2, math.nan, math.inf, "x", None,
                                 True])
def test_hc_inverse_rejects(bad):
    with pytest.raises(ValueError, match=r"restitution = .*\(0, 1\]"):
        hunt_crossley_chi_for_restitution(bad)


@pytest.mark.parametrize("bad", [-1e-9, math.nan, math.inf])
def test_hc_forward_rejects(bad):
    with pytest.raises(ValueError, match="chi"):
        hunt_crossley_restitution_of_chi(bad)


# --- viscoelastic ------------------------------------------------------------------------

def viscoelastic_direct(gamma, m, k0, v0):
    """e of the dimensional impact m rho'' = -max(0, k0 rho^1.5 + 2 gamma sqrt(m 3/2 k0
    sqrt(rho)) rho'), rho(0) = 0, rho'(0) = v0, integrated plainly in time (DOP853): the
    force is clamped at 0, after which the ball flies free (e = -rho'/v0 there)."""
    def force(rho, v):
        rho = max(rho, 0.0)
        return k0 * rho ** 1.5 + 2 * gamma * math.sqrt(m * 1.5 * k0 * math.sqrt(rho)) * v

    def rhs(t, y):
        return [y[1], -max(0.0, force(*y)) / m]

    def released(t, y):       # the force would turn negative (only after the turning point)
        return force(*y) if y[1] < 0 else 1.0
    released.terminal, released.direction = True, -1

    def exit_(t, y):
        return y[0]
    exit_.terminal, exit_.direction = True, -1
    t_hertz = (m / (k0 * math.sqrt(v0))) ** 0.4
    sol = solve_ivp(rhs, (0, 1e3 * t_hertz), [0.0, v0], method="DOP853", rtol=1e-12,
                    atol=[1e-15 * v0 * t_hertz, 1e-15 * v0], events=[released, exit_],
                    first_step=1e-9 * t_hertz)
    y = sol.y_events[0][0] if sol.t_events[0].size else sol.y_events[1][0]
    return -y[1] / v0


@pytest.mark.parametrize("gamma", [0.01, 0.1, 0.4, 1.0, 3.0])
def test_viscoelastic_against_direct_integration(gamma):
    e = viscoelastic_restitution(gamma)
    for m, k0, v0 in [(1.0, 1.0, 1.0), (0.0041, 8.6e9, 2.7)]:   # independent of m, k0, v0
        assert viscoelastic_direct(gamma, m, k0, v0) == pytest.approx(e, rel=1e-10)


def test_viscoelastic_limits():
    assert viscoelastic_restitution(0.0) == 1.0
    # small gamma: 1 - e^2 ~ 6.8829 gamma, computed without cancellation
    q = [(1 - viscoelastic_restitution(g)) * 2 / g for g in (1e-9, 1e-10)]
    assert q[0] == pytest.approx(6.88286, rel=1e-4) and q[1] == pytest.approx(q[0], rel=1e-6)
    # large gamma: e ~ 5 / (24 gamma^2) -> 0 only as gamma -> inf
    for g in (1e2, 1e3):
        assert viscoelastic_restitution(g) * g * g == pytest.approx(
            VISCOELASTIC_LARGE_GAMMA_COEFFICIENT, rel=2 / g)
    gammas = np.logspace(-4, 3, 36)
    es = [viscoelastic_restitution(g) for g in gammas]
    assert all(a > b > 0 for a, b in zip(es, es[1:]))


@pytest.mark.parametrize("e", RESTITUTIONS + [1 - 1e-9, 1e-4])
def test_viscoelastic_round_trip(e):
    gamma = viscoelastic_gamma_for_restitution(e)
    assert viscoelastic_restitution(gamma) == pytest.approx(e, rel=1e-12)
    assert viscoelastic_gamma_for_restitution(e) == gamma        # cached
    if e == 1:
        assert gamma == 0.0


def test_viscoelastic_inverse_near_one_is_relatively_accurate():
    gamma = viscoelastic_gamma_for_restitution(1 - 1e-9)
    assert gamma == pytest.approx(2e-9 / 6.88286, rel=1e-4)


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.5, math.nan, "x"])
def test_viscoelastic_inverse_rejects(bad):
    with pytest.raises(ValueError, match=r"restitution = .*\(0, 1\]"):
        viscoelastic_gamma_for_restitution(bad)


def test_limits():
    limits = restitution_limits()
    assert RESTITUTION_RANGE == (0.0, 1.0)
    assert set(limits) == {"hunt_crossley", "viscoelastic"}
    for law in limits.values():
        assert law["restitution"] == RESTITUTION_RANGE
