"""The compiled layer rejects bad arrays with Python exceptions instead of crashing."""
import numpy as np
import pytest

import ballc
from ballc import _core

P = ballc.Scene().parameter_vector()
Y = ballc.Scene().initial_state()
L = np.ones(_core.N_LATCH)


def test_layout_comes_from_generated_code():
    assert _core.STATE_NAMES[:4] == ("qw", "qx", "qy", "qz") and len(_core.STATE_NAMES) == _core.N_STATES
    assert len(_core.PARAMETER_NAMES) == _core.N_PARAMETERS == P.size


@pytest.mark.parametrize("bad", [np.zeros(12), np.zeros(14), np.zeros(0)])
def test_wrong_state_length_raises(bad):
    with pytest.raises(ValueError, match="length"):
        _core.rhs(bad, P, L, 0)
    with pytest.raises(ValueError, match="length"):
        _core.System(P, L, 0)(0.0, bad)


def test_wrong_parameter_and_latch_lengths_raise():
    with pytest.raises(ValueError, match="params"):
        _core.rhs(Y, P[:-1], L, 0)
    with pytest.raises(ValueError, match="latch"):
        _core.jacobian(Y, P, L[:3], 0)
    with pytest.raises(ValueError):
        _core.energies(np.zeros((3, 5)), P)


def test_wrong_dtype_and_non_contiguous_raise():
    with pytest.raises(ValueError):
        _core.rhs(Y.astype(np.float32), P, L, 0)
    with pytest.raises(ValueError):
        _core.rhs(np.zeros(26)[::2], P, L, 0)
    with pytest.raises(TypeError):
        _core.rhs([1.0] * 13, P, L, 0)


def test_integrator_callable_accepts_strided_views():
    f = _core.System(P, L, 0)
    strided = np.repeat(Y, 2)[::2]
    np.testing.assert_array_equal(f(0.0, strided), _core.rhs(Y, P, L, 0))


def test_singular_mass_matrix_gives_nan_not_crash():
    p = P.copy()
    p[_core.PARAMETER_NAMES.index("mass")] = 0.0
    p[_core.PARAMETER_NAMES.index("observer_mass")] = 0.0
    with pytest.raises(FloatingPointError):
        _core.rhs(Y, p, L, 0)
    assert np.all(np.isnan(_core.System(p, L, 0)(0.0, Y)))
