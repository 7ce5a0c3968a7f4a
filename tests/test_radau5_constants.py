"""radau5's method constants against scipy's Radau module (the oracle it was ported from).

radau5 (src/ballc/_radau_iia.c) claims to be scipy.integrate.Radau step for step:
the same Radau IIA (order 5) collocation nodes C, error-estimate weights E, the
transformation T / TI that block-diagonalises the method's matrix (eigenvalues
MU_REAL and MU_COMPLEX), dense-output matrix P, and the same Newton and step-size
controller limits.  A constant off in its 7th digit still integrates (the Newton
iteration converges a little slower, the error estimate is a little off), so no
trajectory test would notice it; comparing the numbers does.  Both compute them the
same way (literals, or the same closed forms in sqrt(6) and cube roots of 3), so they
must agree to rounding: 1e-15 relative.
"""
import numpy as np
import pytest
from scipy.integrate._ivp import radau as scipy_radau

from ballc import _radau5


@pytest.fixture(scope="module")
def ours():
    return _radau5._constants()


@pytest.mark.parametrize("name", ["C", "E", "T", "TI", "P", "TI_COMPLEX"])
def test_arrays_match_scipy(ours, name):
    """Tableau nodes, error weights, transformation and its inverse, dense output."""
    np.testing.assert_allclose(ours[name], getattr(scipy_radau, name), rtol=1e-15, atol=0)
    assert ours[name].shape == np.shape(getattr(scipy_radau, name))


@pytest.mark.parametrize("name", ["MU_REAL", "MU_COMPLEX"])
def test_eigenvalues_match_scipy(ours, name):
    """The real and complex eigenvalues of the inverse Radau IIA matrix."""
    theirs = getattr(scipy_radau, name)
    assert abs(ours[name] - theirs) <= 1e-15 * abs(theirs)


@pytest.mark.parametrize("name", ["NEWTON_MAXITER", "MIN_FACTOR", "MAX_FACTOR"])
def test_controller_constants_match_scipy(ours, name):
    """Newton iteration cap and the step-size change limits: exact."""
    assert ours[name] == getattr(scipy_radau, name)


def test_constants_are_the_radau_iia_method(ours):
    """Independent of scipy: C are the Radau IIA (order 5) nodes (4 -+ sqrt 6)/10, 1,
    TI is T's inverse, and T^-1 A T is block-diagonal with MU_REAL and the complex pair
    MU_COMPLEX for the Butcher matrix A of Radau IIA (Hairer & Wanner, IV.5)."""
    s6 = np.sqrt(6.0)
    np.testing.assert_allclose(ours["C"], [(4 - s6) / 10, (4 + s6) / 10, 1.0], rtol=1e-15)
    np.testing.assert_allclose(ours["TI"] @ ours["T"], np.eye(3), atol=1e-14)
    a = np.array([[(88 - 7 * s6) / 360, (296 - 169 * s6) / 1800, (-2 + 3 * s6) / 225],
                  [(296 + 169 * s6) / 1800, (88 + 7 * s6) / 360, (-2 - 3 * s6) / 225],
                  [(16 - s6) / 36, (16 + s6) / 36, 1 / 9]])
    block = ours["TI"] @ np.linalg.inv(a) @ ours["T"]
    mu = ours["MU_COMPLEX"]
    np.testing.assert_allclose(block, [[ours["MU_REAL"], 0, 0], [0, mu.real, -mu.imag],
                                       [0, mu.imag, mu.real]], atol=1e-12)
