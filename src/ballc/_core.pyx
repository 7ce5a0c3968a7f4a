# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Bridge to the compiled core: typed memoryviews in, C called, arrays out.

Private: use the ``ballc`` package.  Every entry point checks lengths; typed
memoryviews reject wrong dtypes and non-contiguous arrays with ValueError.

The one extension module of ballc: the generated kernels, ``_system.c``, the radau5
solver and its LU are compiled and linked once, here.  The solver's bridge lives in
``_radau5_bridge.pxi`` (included at the end) and is imported as ``ballc._radau5``, a
thin module that re-exports it.
"""
import numpy as np
from libc.math cimport NAN, isfinite

cdef extern from "ballc_kernels.h":
    int BALLC_N_STATES, BALLC_N_PARAMETERS, BALLC_N_LATCH, BALLC_N_LATCH_PER_PLANE
    int BALLC_N_PARAMETER_CONSTANTS
    const char *const BALLC_PARAMETER_CONSTANT_NAMES[]
    void ballc_parameter_constants(const double *, double *) nogil
    const char *const BALLC_STATE_NAMES[]
    const char *const BALLC_PARAMETER_NAMES[]
    const char *const BALLC_PARAMETER_UNITS[]
    const char *const BALLC_LATCH_NAMES[]
    const char *BALLC_GENERATOR_VERSION
    int BALLC_OBSERVER_POSITION_NOUT, BALLC_N_PLANES, BALLC_N_ROLLING_STATES
    void ballc_observer_position(const double *, const double *, const double *, const double *,
        double *) nogil
    void ballc_hertz_stiffness(const double *, const double *, const double *, const double *,
        double *) nogil

cdef extern from "_system.h":
    int BALLC_WITH_OBSERVER, BALLC_FLOOR_FRICTION, BALLC_FLOOR_DIGIN
    int BALLC_CEILING_FRICTION, BALLC_CEILING_DIGIN
    int BALLC_FLOOR_COMPLIANT, BALLC_CEILING_COMPLIANT
    int BALLC_OK
    int ballc_rhs(const double *, const double *, const double *, int, double *) nogil
    int ballc_jacobian(const double *, const double *, const double *, int, double *) nogil
    ctypedef struct ballc_plane_t:
        double frame[3][3]     # rows t1, t2, n
    ctypedef struct ballc_parameters_t:
        const double *values
        double *constants      # an array in C (BALLC_N_PARAMETER_CONSTANTS)
        ballc_plane_t *planes  # an array in C (BALLC_N_PLANES)
    void ballc_parameters_init(ballc_parameters_t *, const double *) nogil
    int BALLC_ENERGY_NOUT, BALLC_CONTACT_KINEMATICS_NOUT, BALLC_SLIP_NOUT
    void ballc_energy(const double *, const ballc_parameters_t *, double *) nogil
    void ballc_contact_kinematics(const double *, const ballc_parameters_t *, double *) nogil
    void ballc_slip_state(const double *, const ballc_parameters_t *, int, double *) nogil
    int ballc_rhs_checked_inputs(const double *, const ballc_parameters_t *, const double *,
                                 int, double *) nogil
    int ballc_jacobian_checked_inputs(const double *, const ballc_parameters_t *,
                                      const double *, int, double *) nogil
    int ballc_contact_forces(const double *, const double *, const double *, int, double *) nogil
    int ballc_contact_forces_prepared(const double *, const ballc_parameters_t *,
                                      const double *, int, double *) nogil
    int ballc_stick_state(const double *, const double *, const double *, int, int,
                          double *) nogil
    int ballc_remove_slip(const double *, const double *, int, int, double *) nogil
    int BALLC_FLOOR_SLIP, BALLC_CEILING_SLIP, BALLC_FLOOR_STICK, BALLC_CEILING_STICK
    int BALLC_FLOOR_SLIP_FIXED, BALLC_CEILING_SLIP_FIXED
    int BALLC_FLOOR_COMPLIANT_SLIDING, BALLC_CEILING_COMPLIANT_SLIDING
    int BALLC_COMPLIANT_MARGINS
    int BALLC_FLOOR_COMPLIANT_ELASTIC, BALLC_CEILING_COMPLIANT_ELASTIC
    int ballc_compliant_margins(const double *, const double *, const double *, int,
                                double *) nogil
    int ballc_compliant_margins_prepared(const double *, const ballc_parameters_t *,
                                         const double *, int, int, double *) nogil
    int BALLC_ROLLING_STATE_NOUT, BALLC_SDS_MARGINS
    int ballc_rolling_margins(const double *, const ballc_parameters_t *, const double *, int,
                              int, double *) nogil
    int ballc_rolling_state(const double *, const ballc_parameters_t *, const double *, int,
                            int, double *) nogil
    int ballc_remove_velocities(const double *, const ballc_parameters_t *, const double *,
                                int, int, int, double *) nogil

N_STATES = BALLC_N_STATES
#: the rolling resistance's states, last in the state (codegen model.ROLLING_STATE_NAMES)
N_ROLLING_STATES = BALLC_N_ROLLING_STATES
N_PARAMETERS = BALLC_N_PARAMETERS
N_LATCH = BALLC_N_LATCH
N_LATCH_PER_PLANE = BALLC_N_LATCH_PER_PLANE
STATE_NAMES = tuple(BALLC_STATE_NAMES[i].decode() for i in range(BALLC_N_STATES))
#: state name -> index in the state vector (from the generated layout)
STATE_INDEX = {name: i for i, name in enumerate(STATE_NAMES)}
PARAMETER_NAMES = tuple(BALLC_PARAMETER_NAMES[i].decode() for i in range(BALLC_N_PARAMETERS))
PARAMETER_UNITS = tuple(BALLC_PARAMETER_UNITS[i].decode() for i in range(BALLC_N_PARAMETERS))
LATCH_NAMES = tuple(BALLC_LATCH_NAMES[i].decode() for i in range(BALLC_N_LATCH))
#: The parameter constants (parameter-only subexpressions of the kernels), each named by
#: its sympy expression of PARAMETER_NAMES; see codegen/emit.py.
PARAMETER_CONSTANT_NAMES = tuple(BALLC_PARAMETER_CONSTANT_NAMES[i].decode()
                                 for i in range(BALLC_N_PARAMETER_CONSTANTS))
GENERATOR_VERSION = BALLC_GENERATOR_VERSION.decode()
FLAGS = {
    "observer": BALLC_WITH_OBSERVER,
    "floor_friction": BALLC_FLOOR_FRICTION,
    "floor_digin": BALLC_FLOOR_DIGIN,
    "ceiling_friction": BALLC_CEILING_FRICTION,
    "ceiling_digin": BALLC_CEILING_DIGIN,
    "floor_compliant": BALLC_FLOOR_COMPLIANT,
    "ceiling_compliant": BALLC_CEILING_COMPLIANT,
    "floor_slip": BALLC_FLOOR_SLIP,
    "ceiling_slip": BALLC_CEILING_SLIP,
    "floor_stick": BALLC_FLOOR_STICK,
    "ceiling_stick": BALLC_CEILING_STICK,
    "floor_slip_fixed": BALLC_FLOOR_SLIP_FIXED,
    "ceiling_slip_fixed": BALLC_CEILING_SLIP_FIXED,
    "floor_compliant_sliding": BALLC_FLOOR_COMPLIANT_SLIDING,
    "ceiling_compliant_sliding": BALLC_CEILING_COMPLIANT_SLIDING,
    "floor_compliant_elastic": BALLC_FLOOR_COMPLIANT_ELASTIC,
    "ceiling_compliant_elastic": BALLC_CEILING_COMPLIANT_ELASTIC,
}
ENERGY_NOUT = BALLC_ENERGY_NOUT
CONTACT_KINEMATICS_NOUT = BALLC_CONTACT_KINEMATICS_NOUT


cdef inline void _check(name, Py_ssize_t got, Py_ssize_t expected) except *:
    if got != expected:
        raise ValueError(f"{name} must have length {expected}, got {got}")


cdef enum:
    BALLC_MAX_STATES = 64   # the stack buffer System copies a state into

if BALLC_N_STATES > BALLC_MAX_STATES:   # a layout that outgrew the buffer: refuse to load
    raise ImportError(f"ballc._core: {BALLC_N_STATES} states exceed the {BALLC_MAX_STATES}-"
                      "state buffer of System; raise BALLC_MAX_STATES in _core.pyx")


cdef inline void _copy_state(const double[:] y, double *ys) except *:
    """Copy a (possibly strided) state into a C buffer; integrators may pass views."""
    _check("y", y.shape[0], BALLC_N_STATES)
    cdef Py_ssize_t i
    for i in range(y.shape[0]):
        ys[i] = y[i]


cdef class System:
    """f(t, y) and its Jacobian for one integration segment.

    ``params`` (N_PARAMETERS) and ``latch`` (N_LATCH) are copied; ``flags`` selects
    the contributions (see FLAGS).  A state at which the equations cannot be
    evaluated (non-finite values, mass matrix not positive definite) gives NaNs,
    which makes the integrator reject the step; ``failures`` counts them.
    """
    cdef double[::1] _params
    cdef double[::1] _latch
    cdef object _params_array, _latch_array   # the arrays _params and _latch view
    cdef readonly int flags
    cdef public long nfev, njev, failures

    def __init__(self, const double[::1] params, const double[::1] latch, int flags):
        _check("params", params.shape[0], BALLC_N_PARAMETERS)
        _check("latch", latch.shape[0], BALLC_N_LATCH)
        self._params_array = np.empty(BALLC_N_PARAMETERS)
        self._latch_array = np.empty(BALLC_N_LATCH)
        self._params = self._params_array
        self._latch = self._latch_array
        self._params[:] = params
        self._latch[:] = latch
        self.flags = flags
        self.nfev = 0
        self.njev = 0
        self.failures = 0

    @property
    def params(self):
        """The parameter vector (a copy)."""
        return self._params_array.copy()

    @property
    def latch(self):
        """The latched values (a copy)."""
        return self._latch_array.copy()

    def __call__(self, double t, const double[:] y):
        cdef double ys[BALLC_MAX_STATES]
        _copy_state(y, ys)
        out = np.empty(BALLC_N_STATES)
        cdef double[::1] o = out
        self.nfev += 1
        if ballc_rhs(ys, &self._params[0], &self._latch[0], self.flags, &o[0]) != BALLC_OK:
            self.failures += 1
            out.fill(np.nan)
        return out

    def jacobian(self, double t, const double[:] y):
        cdef double ys[BALLC_MAX_STATES]
        _copy_state(y, ys)
        out = np.empty((BALLC_N_STATES, BALLC_N_STATES))
        cdef double[:, ::1] o = out
        self.njev += 1
        if ballc_jacobian(ys, &self._params[0], &self._latch[0], self.flags,
                          &o[0, 0]) != BALLC_OK:
            self.failures += 1
            out.fill(np.nan)
        return out


def rhs(const double[::1] y, const double[::1] params, const double[::1] latch, int flags):
    """State derivative (N_STATES) at one state; raises if it cannot be evaluated."""
    _check("y", y.shape[0], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latch", latch.shape[0], BALLC_N_LATCH)
    out = np.empty(BALLC_N_STATES)
    cdef double[::1] o = out
    cdef int status = ballc_rhs(&y[0], &params[0], &latch[0], flags, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"right-hand side failed with C status {status}")
    return out


def jacobian(const double[::1] y, const double[::1] params, const double[::1] latch,
             int flags):
    """Jacobian (N_STATES x N_STATES) at one state; raises if it cannot be evaluated."""
    _check("y", y.shape[0], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latch", latch.shape[0], BALLC_N_LATCH)
    out = np.empty((BALLC_N_STATES, BALLC_N_STATES))
    cdef double[:, ::1] o = out
    cdef int status = ballc_jacobian(&y[0], &params[0], &latch[0], flags, &o[0, 0])
    if status != BALLC_OK:
        raise FloatingPointError(f"Jacobian failed with C status {status}")
    return out


def rhs_per_sample(const double[:, ::1] states, const double[::1] params,
                   const double[:, ::1] latch, const int[::1] flags):
    """(n, N_STATES): the state derivative at each state row, with that row's latched
    values and flags (what ``rhs`` gives row by row, in one call); a row whose
    right-hand side cannot be evaluated raises, as ``rhs`` does."""
    _check("states.shape[1]", states.shape[1], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latch.shape[1]", latch.shape[1], BALLC_N_LATCH)
    _check("latch.shape[0]", latch.shape[0], states.shape[0])
    _check("flags", flags.shape[0], states.shape[0])
    out = np.empty((states.shape[0], BALLC_N_STATES))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    cdef int status
    for i in range(states.shape[0]):
        status = ballc_rhs(&states[i, 0], &params[0], &latch[i, 0], flags[i], &o[i, 0])
        if status != BALLC_OK:
            raise FloatingPointError(
                f"right-hand side failed with C status {status} at row {i}")
    return out


ctypedef void (*kernel_fn)(const double *, const double *, const double *, const double *,
                           double *) nogil
ctypedef void (*system_fn)(const double *, const ballc_parameters_t *, double *) nogil


cdef object _per_row(kernel_fn kernel, int nout, const double[:, ::1] states,
                     const double[::1] params):
    _check("states.shape[1]", states.shape[1], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    out = np.empty((states.shape[0], nout))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(states.shape[0]):
        kernel(&states[i, 0], &params[0], prepared.constants, NULL, &o[i, 0])
    return out


cdef object _per_row_of_system(system_fn function, int nout, const double[:, ::1] states,
                               const double[::1] params):
    _check("states.shape[1]", states.shape[1], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    out = np.empty((states.shape[0], nout))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(states.shape[0]):
        function(&states[i, 0], &prepared, &o[i, 0])
    return out


def energies(const double[:, ::1] states, const double[::1] params):
    """(n, 6): kinetic, potential, spring floor, spring ceiling, tangential spring floor,
    tangential spring ceiling (J) per state row."""
    return _per_row_of_system(ballc_energy, BALLC_ENERGY_NOUT, states, params)


def contact_kinematics(const double[:, ::1] states, const double[::1] params):
    """(n, 10): per plane rho, rhodot, contact-point velocity x, y, z (inertial)."""
    return _per_row_of_system(ballc_contact_kinematics, BALLC_CONTACT_KINEMATICS_NOUT, states,
                              params)


def plane_frames(const double[::1] params):
    """(N_PLANES, 3, 3): each plane's frame as the C core builds it from the parameters'
    plane table, rows t1, t2, n (inertial components; see _plane.h)."""
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    out = np.empty((BALLC_N_PLANES, 3, 3))
    cdef ballc_parameters_t prepared
    cdef int p, i, j
    ballc_parameters_init(&prepared, &params[0])
    for p in range(BALLC_N_PLANES):
        for i in range(3):
            for j in range(3):
                out[p, i, j] = prepared.planes[p].frame[i][j]
    return out


def observer_positions(const double[:, ::1] states, const double[::1] params):
    """(n, 3): observer position in the inertial frame (m)."""
    return _per_row(ballc_observer_position, BALLC_OBSERVER_POSITION_NOUT, states, params)


def contact_forces(const double[:, ::1] states, const double[::1] params,
                   const double[::1] latch, int flags):
    """(n, 6): sum of the contact forces on the ball (N), floor x y z then ceiling x y z,
    at each state row, for the contact laws selected by ``flags``."""
    _check("states.shape[1]", states.shape[1], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latch", latch.shape[0], BALLC_N_LATCH)
    out = np.empty((states.shape[0], 6))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    for i in range(states.shape[0]):
        if ballc_contact_forces(&states[i, 0], &params[0], &latch[0], flags, &o[i, 0]) != BALLC_OK:
            o[i, :] = np.nan
    return out


def _plane_index(int plane):
    if plane not in (0, 1):
        raise ValueError(f"plane must be 0 (floor) or 1 (ceiling), got {plane}")
    return plane


def slip_map(const double[::1] params, int plane):
    """(2, N_STATES): du/dx of the slip velocity u of ``plane``'s contact point, its
    components along the plane's tangents t1, t2 (plane_frames); u is linear in the
    state, u = slip_map . y."""
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _plane_index(plane)
    cdef double ys[BALLC_MAX_STATES]
    out = np.empty(BALLC_SLIP_NOUT)
    cdef double[::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(BALLC_N_STATES):
        ys[i] = 0.0
    ballc_slip_state(ys, &prepared, plane, &o[0])
    return out[2:2 + 2 * BALLC_N_STATES].reshape(2, BALLC_N_STATES)


cdef void _check_plane_call(const double[::1] y, const double[::1] params,
                            const double[::1] latch, int plane) except *:
    """The lengths of a per-plane entry point's inputs, and its plane."""
    _check("y", y.shape[0], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latch", latch.shape[0], BALLC_N_LATCH)
    _plane_index(plane)


def stick_state(const double[::1] y, const double[::1] params, const double[::1] latch,
                int flags, int plane):
    """(lambda_x, lambda_y, N, margin) of a sticking ``plane``: the constraint force (N)
    that holds the slip velocity, the friction share's normal force (N) and
    mu N - |lambda| (N); raises if it cannot be evaluated (flags must hold the plane's
    friction and stick flags)."""
    _check_plane_call(y, params, latch, plane)
    out = np.empty(4)
    cdef double[::1] o = out
    cdef int status = ballc_stick_state(&y[0], &params[0], &latch[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"stick state failed with C status {status}")
    return out


def compliant_margins(const double[::1] y, const double[::1] params, const double[::1] latch,
                      int plane):
    """The compliant law's mode guards on ``plane`` at state y: (yield margin
    1 - k_t |s| / (mu F_n) (1), re-stick margin (m/s), s_cap = mu F_n / k_t (m), k_t (N/m),
    the elastic mode's capacity margin (mu F_n - |F_el|) - |V| (N), its negative); see
    codegen/contact.py, compliant_margins.  Raises if they are not finite."""
    _check_plane_call(y, params, latch, plane)
    out = np.empty(BALLC_COMPLIANT_MARGINS)
    cdef double[::1] o = out
    cdef int status = ballc_compliant_margins(&y[0], &params[0], &latch[0], plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"compliant margins failed with C status {status}")
    return out


def remove_slip(const double[::1] y, const double[::1] params, int flags, int plane):
    """The state with ``plane``'s slip velocity set to zero by a tangential impulse at
    the contact point (for slip-to-stick transitions, where it is at rounding level)."""
    _check("y", y.shape[0], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _plane_index(plane)
    out = np.empty(BALLC_N_STATES)
    cdef double[::1] o = out
    cdef int status = ballc_remove_slip(&y[0], &params[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"remove_slip failed with C status {status}")
    return out


def rolling_state(const double[::1] y, const double[::1] params, const double[::1] latch,
                  int flags, int plane):
    """Rolling resistance on ``plane`` (src/ballc/_rolling.h) under ``flags`` and the
    modes in ``latch``: (lambda (3: the rolling force along t1, t2 and the twisting force
    that hold the held parts, N), F_n (N), the rolling margin mu_r F_n - |lambda_r| (N),
    the twisting margin mu_t F_n - |lambda_w| (N), the rolling velocity (2, m/s), the
    twisting velocity (m/s)); raises if it cannot be evaluated (the plane must be in
    contact under ``flags``)."""
    _check_plane_call(y, params, latch, plane)
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    out = np.empty(BALLC_ROLLING_STATE_NOUT)
    cdef double[::1] o = out
    cdef int status = ballc_rolling_state(&y[0], &prepared, &latch[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"rolling state failed with C status {status}")
    return out


def rolling_margins(const double[::1] y, const double[::1] params, const double[::1] latch,
                    int flags, int plane):
    """The sds model's guards on ``plane`` (codegen contact.sds_margins), per part
    (rolling, twisting): yield margin 1 - k |xi| / (mu F_n), re-stick margin (m/s, with
    the penetration acceleration of the dynamics under ``flags`` and ``latch``) and the
    deflection at the cap mu F_n / k (m)."""
    _check_plane_call(y, params, latch, plane)
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    out = np.empty(BALLC_SDS_MARGINS)
    cdef double[::1] o = out
    cdef int status = ballc_rolling_margins(&y[0], &prepared, &latch[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"rolling margins failed with C status {status}")
    return out


#: ballc_remove_velocities' mask bits (_rolling.h BALLC_HOLD_*)
HOLD_SLIP, HOLD_ROLLING, HOLD_TWISTING = 1, 2, 4


def remove_velocities(const double[::1] y, const double[::1] params, const double[::1] latch,
                      int flags, int plane, int mask):
    """The state with ``plane``'s velocities in ``mask`` (HOLD_SLIP, HOLD_ROLLING,
    HOLD_TWISTING) set to zero by one impulse of the constraint forces that hold them."""
    _check_plane_call(y, params, latch, plane)
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    out = np.empty(BALLC_N_STATES)
    cdef double[::1] o = out
    cdef int status = ballc_remove_velocities(&y[0], &prepared, &latch[0], flags, plane, mask,
                                              &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"remove_velocities failed with C status {status}")
    return out


def contact_forces_per_sample(const double[:, ::1] states, const double[::1] params,
                              const double[:, ::1] latches, const int[::1] flags):
    """(n, 6): as contact_forces, with each state row's own latched values (row of
    ``latches``, (n, N_LATCH)) and flags -- one call for a whole run's samples."""
    _check("states.shape[1]", states.shape[1], BALLC_N_STATES)
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    _check("latches.shape[1]", latches.shape[1], BALLC_N_LATCH)
    _check("latches.shape[0]", latches.shape[0], states.shape[0])
    _check("flags", flags.shape[0], states.shape[0])
    out = np.empty((states.shape[0], 6))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i, j
    cdef bint params_finite = True
    cdef ballc_parameters_t prepared
    for j in range(params.shape[0]):
        params_finite = params_finite and isfinite(params[j])
    ballc_parameters_init(&prepared, &params[0])   # once for all rows
    with nogil:
        for i in range(states.shape[0]):
            if not params_finite or ballc_contact_forces_prepared(
                    &states[i, 0], &prepared, &latches[i, 0], flags[i], &o[i, 0]) != BALLC_OK:
                for j in range(6):
                    o[i, j] = NAN
    return out
# ---- the radau5 integrator (imported as ballc._radau5) ----

include "_radau5_bridge.pxi"
include "_orbit_bridge.pxi"
include "_scipy_bridge.pxi"
include "_driver_bridge.pxi"


def parameter_constants(const double[::1] params):
    """The parameter constants (PARAMETER_CONSTANT_NAMES) of a parameter vector, as the
    kernels read them (computed in C, once per segment, by the integrator's adapter)."""
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    out = np.empty(BALLC_N_PARAMETER_CONSTANTS)
    cdef double[::1] o = out
    if BALLC_N_PARAMETER_CONSTANTS:
        ballc_parameter_constants(&params[0], &o[0])
    return out


def hertz_stiffness(const double[::1] params):
    """k0 (N/m^(3/2)) of the generated contact law, from the parameter vector."""
    _check("params", params.shape[0], BALLC_N_PARAMETERS)
    cdef double state[BALLC_MAX_STATES]
    cdef double k0
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    ballc_hertz_stiffness(state, &params[0], prepared.constants, NULL, &k0)
    return k0
