"""The compiled layer rejects bad arrays with Python exceptions instead of crashing."""
import numpy as np
import pytest

import ballc
from ballc import _core

P = ballc.Scene().parameter_vector()
Y = ballc.Scene().initial_state()
L = np.ones(_core.N_LATCH)


def test_one_compiled_core():
    """The kernels are compiled once: the solver's bridge is ``_core``'s own, and
    ``ballc._radau5`` is a plain module re-exporting it (a stale ``_radau5`` extension
    from an older build would shadow it with its own copy of the kernels)."""
    import importlib.machinery

    from ballc import _radau5
    assert _radau5.__file__.endswith(".py")
    assert _radau5.solve_system is _core.solve_system
    assert _radau5.solve_linear is _core.solve_linear
    assert _radau5._lu_solve is _core._lu_solve
    here = _core.__file__.rsplit("/", 1)[0]
    compiled = [f for f in __import__("os").listdir(here)
                if any(f.endswith(s) for s in importlib.machinery.EXTENSION_SUFFIXES)]
    assert compiled == [_core.__file__.rsplit("/", 1)[1]]


def test_layout_comes_from_generated_code():
    assert _core.STATE_NAMES[:4] == ("qw", "qx", "qy", "qz") and len(_core.STATE_NAMES) == _core.N_STATES
    assert len(_core.PARAMETER_NAMES) == _core.N_PARAMETERS == P.size


def test_parameter_constants_match_their_names():
    """Each parameter constant the kernels read is the value of its name (a sympy
    expression of the parameters), for a scene whose parameters are all distinct."""
    import sympy as sm

    scene = ballc.Scene(mass=1.3, observer_mass=0.2, radius=0.7, c_tau=0.6, mixture=0.3,
                        friction_coefficient=0.4, observer_position=(0.3, -0.2, 0.5))
    params = scene.parameter_vector()
    values = _core.parameter_constants(params)
    assert len(values) == len(_core.PARAMETER_CONSTANT_NAMES) > 0
    symbols = {name: sm.Symbol(name) for name in _core.PARAMETER_NAMES}
    for name, value in zip(_core.PARAMETER_CONSTANT_NAMES, values):
        expected = sm.lambdify(list(symbols.values()), sm.sympify(name, locals=symbols),
                               "math")(*params)
        assert value == pytest.approx(expected, rel=1e-13, abs=1e-15), name
    with pytest.raises(ValueError, match="length"):
        _core.parameter_constants(np.zeros(3))


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


# --- issue 6: more ways to hand the compiled layer bad arrays ------------------------

KERNELS = [_core.energies, _core.contact_kinematics, _core.observer_positions]
ALL_FLAGS = sum(_core.FLAGS.values())


@pytest.mark.parametrize("entry", ["rhs", "jacobian", "System"])
def test_two_dimensional_state_raises(entry):
    y2 = np.ascontiguousarray(Y[None, :])
    call = {"rhs": lambda: _core.rhs(y2, P, L, 0),
            "jacobian": lambda: _core.jacobian(y2, P, L, 0),
            "System": lambda: _core.System(P, L, 0)(0.0, y2)}[entry]
    with pytest.raises(ValueError, match="dimensions"):
        call()


@pytest.mark.parametrize("kernel", KERNELS, ids=lambda k: k.__name__)
@pytest.mark.parametrize("states", [
    np.ascontiguousarray(Y),                            # 1-D
    np.ascontiguousarray(Y[None, None, :]),             # 3-D
    np.asfortranarray(np.tile(Y, (3, 1))),              # not C-contiguous
    np.broadcast_to(Y, (3, Y.size)),                    # zero stride, read-only
    np.tile(Y, (3, 1)).astype(np.float32),              # wrong dtype
    np.tile(Y, (3, 1)).astype(np.int64),
    np.tile(Y, (3, 1)).astype(">f8"),                   # non-native byte order
    np.zeros((3, Y.size - 1)),                          # wrong row length
], ids=["1d", "3d", "fortran", "broadcast", "float32", "int64", "big-endian", "short-rows"])
def test_per_row_kernels_reject_bad_state_arrays(kernel, states):
    with pytest.raises(ValueError):
        kernel(states, P)


@pytest.mark.parametrize("kernel", KERNELS, ids=lambda k: k.__name__)
def test_per_row_kernels_accept_zero_rows(kernel):
    assert kernel(np.zeros((0, Y.size)), P).shape[0] == 0


def test_read_only_arrays_are_accepted_and_not_written():
    """const memoryviews: read-only inputs work and give the same numbers."""
    y, p, lat = Y.copy(), P.copy(), L.copy()
    for a in (y, p, lat):
        a.flags.writeable = False
    np.testing.assert_array_equal(_core.rhs(y, p, lat, ALL_FLAGS), _core.rhs(Y, P, L, ALL_FLAGS))
    np.testing.assert_array_equal(_core.jacobian(y, p, lat, ALL_FLAGS),
                                  _core.jacobian(Y, P, L, ALL_FLAGS))
    np.testing.assert_array_equal(_core.System(p, lat, 0)(0.0, y), _core.rhs(Y, P, L, 0))
    states = np.tile(Y, (2, 1))
    states.flags.writeable = False
    np.testing.assert_array_equal(_core.energies(states, p), _core.energies(np.tile(Y, (2, 1)), P))
    np.testing.assert_array_equal(y, Y)


@pytest.mark.parametrize("bad", [None, "abc", [1.0] * 13, 5.0], ids=repr)
def test_non_array_arguments_raise(bad):
    with pytest.raises((TypeError, ValueError)):
        _core.rhs(bad, P, L, 0)
    with pytest.raises((TypeError, ValueError)):
        _core.System(bad, L, 0)


def test_flags_and_time_of_wrong_type_raise():
    with pytest.raises(OverflowError):
        _core.rhs(Y, P, L, 2 ** 70)   # flags are 64 bits
    with pytest.raises(TypeError):
        _core.System(P, L, 0)("0.0", Y)


#: Every state component: the C layer rejects non-finite inputs before computing.
_DYNAMIC = list(_core.STATE_NAMES)


@pytest.mark.parametrize("flags", [0, ALL_FLAGS], ids=["free", "all-contacts"])
@pytest.mark.parametrize("name", _DYNAMIC)
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_state_raises_or_gives_nan(name, bad, flags):
    """Never a finite answer from a non-finite input the equations use, never a crash."""
    y = Y.copy()
    y[_core.STATE_NAMES.index(name)] = bad
    with pytest.raises(FloatingPointError):
        _core.rhs(y, P, L, flags)
    assert np.all(np.isnan(_core.System(P, L, flags)(0.0, y)))


def test_nan_height_with_contact_laws_on_is_not_silently_accepted():
    y = Y.copy()
    y[_core.STATE_NAMES.index("z")] = np.nan
    with pytest.raises(FloatingPointError):
        _core.rhs(y, P, L, ALL_FLAGS)


def test_nan_contact_parameter_is_not_silently_accepted():
    p = P.copy()
    p[_core.PARAMETER_NAMES.index("c_tau")] = np.nan
    with pytest.raises(FloatingPointError):
        _core.rhs(Y, p, L, ALL_FLAGS)
