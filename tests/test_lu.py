"""ballc's own LU (src/ballc/_lu.c), which solves radau5's Newton systems.

Checked through the private test entry point ``_radau5._lu_solve`` against
numpy.linalg.solve (LAPACK), and, at the level of a whole simulation, for
reproducibility: the same scene gives the same bits in this process and in a
freshly spawned worker process (the LAPACK version did not: a threaded BLAS
summed in a different order on a Dask worker).
"""
import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import ballc
from ballc import _core, _radau5

SIZES = [1, 2, 3, 5, 13, 19, 40, 64]


def _random(rng, n, complex_):
    a = rng.standard_normal((n, n))
    b = rng.standard_normal(n)
    if complex_:
        a = a + 1j * rng.standard_normal((n, n))
        b = b + 1j * rng.standard_normal(n)
    return a, b


def _check(a, b, rtol=1e-12):
    x = _radau5._lu_solve(a, b)
    ref = np.linalg.solve(a, b)
    assert x.dtype == ref.dtype
    assert np.max(np.abs(x - ref)) <= rtol * np.max(np.abs(ref))
    # backward error of a pivoted LU: a few eps times the growth
    assert np.max(np.abs(a @ x - b)) <= 1e-13 * np.abs(a).sum(axis=1).max() * np.max(np.abs(x))


@pytest.mark.parametrize("complex_", [False, True], ids=["real", "complex"])
@pytest.mark.parametrize("n", SIZES)
def test_well_conditioned(rng, n, complex_):
    a, b = _random(rng, n, complex_)
    a += 2 * np.sqrt(n) * np.eye(n)   # diagonally heavy: condition number ~ 10
    _check(a, b)


@pytest.mark.parametrize("complex_", [False, True], ids=["real", "complex"])
@pytest.mark.parametrize("n", SIZES[1:])
def test_needs_pivoting(rng, n, complex_):
    # a well-conditioned matrix with its rows shuffled: small or zero leading
    # entries, which elimination without row interchanges gets badly wrong
    a, b = _random(rng, n, complex_)
    a = (a + 2 * np.sqrt(n) * np.eye(n))[rng.permutation(n)]
    a[0, 0] = 0.0   # first pivot exactly zero
    _check(a, b, rtol=1e-10)


@pytest.mark.parametrize("complex_", [False, True], ids=["real", "complex"])
def test_small_pivoting_cases(complex_):
    c = 1j if complex_ else 1.0
    cases = [
        (np.array([[0.0, 1.0], [1.0, 0.0]]) * c, np.array([2.0, 3.0]) * c),
        (np.array([[1e-20, 1.0], [1.0, 1.0]]) * c, np.array([1.0, 2.0])),   # no pivoting: x0 = 0
        (np.array([[0.0, 2.0, 1.0], [0.0, 0.0, 3.0], [4.0, 1.0, 0.0]]) * c, np.array([1.0, 2.0, 3.0])),
    ]
    for a, b in cases:
        _check(a, b)
    x = _radau5._lu_solve(np.array([[1e-20, 1.0], [1.0, 1.0]]), np.array([1.0, 2.0]))
    np.testing.assert_allclose(x, [1.0, 1.0], rtol=1e-15)


@pytest.mark.parametrize("h", [1e-6, 1e-3, 1e-1])
def test_radau5_newton_matrices(h):
    """The matrices radau5 factors: MU_REAL / h I - J and MU_COMPLEX / h I - J, with
    J ballc's Jacobian (all contact terms on) at the seed's initial state."""
    mu_real = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)
    mu_complex = (3 + 0.5 * (3 ** (1 / 3) - 3 ** (2 / 3))) - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6))
    scene = ballc.Scene()
    jac = _core.jacobian(scene.initial_state(), scene.parameter_vector(), np.ones(_core.N_LATCH),
                         sum(_core.FLAGS.values()))
    n = jac.shape[0]
    b = np.random.default_rng(1).standard_normal(n)
    for mu, rhs in [(mu_real, b), (mu_complex, b * (1 - 2j))]:
        a = mu / h * np.eye(n) - jac
        _check(a, rhs, rtol=1e-10)


@pytest.mark.parametrize("complex_", [False, True], ids=["real", "complex"])
def test_singular_raises(complex_):
    c = 1j if complex_ else 1.0
    singular = [
        np.zeros((3, 3)),
        np.array([[1.0, 2.0], [2.0, 4.0]]),                  # exact zero in the last pivot
        np.array([[1.0, 5.0, 2.0], [3.0, 0.0, 6.0], [-2.0, 7.0, -4.0]]),   # column 2 = 2 x column 0
    ]
    for a in singular:
        with pytest.raises(np.linalg.LinAlgError, match="singular matrix: the pivot of column"):
            _radau5._lu_solve(a * c, np.ones(a.shape[0]))


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="n x n"):
        _radau5._lu_solve(np.ones((2, 3)), np.ones(2))
    with pytest.raises(ValueError, match="n x n"):
        _radau5._lu_solve(np.eye(2), np.ones(3))
    with pytest.raises(ValueError, match="finite"):
        _radau5._lu_solve(np.array([[np.nan]]), np.ones(1))


def test_inputs_not_modified():
    a = np.array([[0.0, 1.0], [2.0, 3.0]])
    b = np.array([1.0, 1.0])
    a0, b0 = a.copy(), b.copy()
    _radau5._lu_solve(a, b)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b, b0)


# ---- reproducibility of a whole simulation ----

def _seed_run():
    result = ballc.simulate(ballc.Scene(), 1.2)
    return _radau5.__file__, result.t, result.y


def test_simulation_bit_identical_in_process_and_in_a_spawned_worker():
    where, t1, y1 = _seed_run()
    _, t2, y2 = _seed_run()
    with ProcessPoolExecutor(max_workers=1,
                             mp_context=multiprocessing.get_context("spawn")) as pool:
        where_worker, t3, y3 = pool.submit(_seed_run).result(timeout=240)
    assert where_worker == where   # the worker ran the same build
    assert y1.shape[1] > 100
    for t, y in [(t2, y2), (t3, y3)]:
        np.testing.assert_array_equal(t, t1)
        np.testing.assert_array_equal(y, y1)   # exact, not approximate
        assert y.tobytes() == y1.tobytes()     # signed zeros and NaN payloads too
