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
    enum:
        BALLC_MAX_PLANES
        BALLC_MAX_STATES
        BALLC_MAX_LATCH
        BALLC_MAX_PARAMETERS
    int BALLC_N_BALL_STATES, BALLC_N_PLANE_STATES
    int BALLC_N_ROLLING_BALL_STATES, BALLC_N_ROLLING_PLANE_STATES
    int BALLC_PARAMETER_ROLLING_RESISTANCE, BALLC_PARAMETER_TWISTING_RESISTANCE
    int BALLC_PARAMETER_PLANES, BALLC_PARAMETER_PLANE_COUNT, BALLC_N_PLANE_FIELDS
    int BALLC_N_LATCH_PER_PLANE
    int BALLC_N_PARAMETER_CONSTANTS
    const char *const BALLC_PARAMETER_CONSTANT_NAMES[]
    void ballc_parameter_constants(const double *, double *) nogil
    const char *const BALLC_STATE_NAMES[]
    const char *const BALLC_PLANE_STATE_NAMES[]
    const char *const BALLC_ROLLING_BALL_STATE_NAMES[]
    const char *const BALLC_ROLLING_PLANE_STATE_NAMES[]
    const char *const BALLC_PARAMETER_NAMES[]
    const char *const BALLC_PARAMETER_UNITS[]
    const char *const BALLC_PLANE_FIELD_NAMES[]
    const char *const BALLC_PLANE_FIELD_UNITS[]
    const char *const BALLC_LATCH_FIELD_NAMES[]
    const char *BALLC_GENERATOR_VERSION
    int BALLC_OBSERVER_POSITION_NOUT
    void ballc_observer_position(const double *, const double *, const double *, const double *,
        double *) nogil
    void ballc_hertz_stiffness(const double *, const double *, const double *, const double *,
        double *) nogil

cdef extern from "_system.h":
    ctypedef long long ballc_flags
    ballc_flags BALLC_WITH_OBSERVER
    enum:
        BALLC_KIND_FRICTION, BALLC_KIND_DIGIN, BALLC_KIND_COMPLIANT, BALLC_KIND_SLIP,
        BALLC_KIND_STICK, BALLC_KIND_SLIP_FIXED, BALLC_KIND_COMPLIANT_SLIDING,
        BALLC_KIND_COMPLIANT_ELASTIC, BALLC_N_FLAG_KINDS
    ballc_flags ballc_flag(int, int) nogil
    int BALLC_OK
    int ballc_rhs(const double *, const double *, const double *, ballc_flags, double *) nogil
    int ballc_jacobian(const double *, const double *, const double *, ballc_flags,
                       double *) nogil
    ctypedef struct ballc_plane_t:
        double point[3]
        double frame[3][3]     # rows t1, t2, n
    ctypedef struct ballc_parameters_t:
        const double *values
        int n_planes, n_states, n_latch, n_parameters
        double *constants      # an array in C (BALLC_N_PARAMETER_CONSTANTS)
        ballc_plane_t *planes  # an array in C (BALLC_MAX_PLANES)
    int ballc_parameters_init(ballc_parameters_t *, const double *) nogil
    enum:
        BALLC_MAX_SLIP_NOUT
    int BALLC_CONTACT_KINEMATICS_PER_PLANE
    void ballc_energy(const double *, const ballc_parameters_t *, double *) nogil
    void ballc_contact_kinematics(const double *, const ballc_parameters_t *, double *) nogil
    void ballc_slip_state(const double *, const ballc_parameters_t *, int, double *) nogil
    int ballc_rhs_checked_inputs(const double *, const ballc_parameters_t *, const double *,
                                 ballc_flags, double *) nogil
    int ballc_jacobian_checked_inputs(const double *, const ballc_parameters_t *,
                                      const double *, ballc_flags, double *) nogil
    int ballc_contact_forces(const double *, const double *, const double *, ballc_flags,
                             double *) nogil
    int ballc_contact_forces_prepared(const double *, const ballc_parameters_t *,
                                      const double *, ballc_flags, double *) nogil
    int ballc_stick_state(const double *, const double *, const double *, ballc_flags, int,
                          double *) nogil
    int ballc_remove_slip(const double *, const double *, ballc_flags, int, double *) nogil
    int BALLC_COMPLIANT_MARGINS
    int ballc_compliant_margins(const double *, const double *, const double *, int,
                                double *) nogil
    int ballc_compliant_margins_prepared(const double *, const ballc_parameters_t *,
                                         const double *, ballc_flags, int, int, double *) nogil
    int BALLC_ROLLING_STATE_NOUT, BALLC_SDS_MARGINS
    int ballc_rolling_margins(const double *, const ballc_parameters_t *, const double *,
                              ballc_flags, int, double *) nogil
    int ballc_rolling_state(const double *, const ballc_parameters_t *, const double *,
                            ballc_flags, int, double *) nogil
    int ballc_remove_velocities(const double *, const ballc_parameters_t *, const double *,
                                ballc_flags, int, int, double *) nogil

cdef tuple _decoded(const char *const *names, int n):
    """The first ``n`` of a generated C table of names, as Python strings."""
    cdef int i
    return tuple([names[i].decode() for i in range(n)])


#: The most planes a scene may have, and the layout of a run with n planes: the ball's
#: states (BALL_STATE_NAMES), then PLANE_STATE_FIELDS per plane (``<plane>_<field>``);
#: the scene's parameters (BASE_PARAMETER_NAMES, the last the plane table's count), then
#: PLANE_FIELD_NAMES per plane; LATCH_FIELD_NAMES per plane.  (ballc.layout names them.)
MAX_PLANES = BALLC_MAX_PLANES
BALL_STATE_NAMES = _decoded(BALLC_STATE_NAMES, BALLC_N_BALL_STATES)
PLANE_STATE_FIELDS = _decoded(BALLC_PLANE_STATE_NAMES, BALLC_N_PLANE_STATES)
#: The states of rolling resistance (a run with rolling or twisting resistance only):
#: after every plane's, ROLLING_BALL_STATE_NAMES, then ROLLING_PLANE_STATE_FIELDS per
#: plane (its rolling springs, ``<plane>_<field>``).
ROLLING_BALL_STATE_NAMES = _decoded(BALLC_ROLLING_BALL_STATE_NAMES, BALLC_N_ROLLING_BALL_STATES)
ROLLING_PLANE_STATE_FIELDS = _decoded(BALLC_ROLLING_PLANE_STATE_NAMES, BALLC_N_ROLLING_PLANE_STATES)
BASE_PARAMETER_NAMES = _decoded(BALLC_PARAMETER_NAMES, BALLC_PARAMETER_PLANES)
BASE_PARAMETER_UNITS = _decoded(BALLC_PARAMETER_UNITS, BALLC_PARAMETER_PLANES)
PLANE_FIELD_NAMES = _decoded(BALLC_PLANE_FIELD_NAMES, BALLC_N_PLANE_FIELDS)
PLANE_FIELD_UNITS = _decoded(BALLC_PLANE_FIELD_UNITS, BALLC_N_PLANE_FIELDS)
LATCH_FIELD_NAMES = _decoded(BALLC_LATCH_FIELD_NAMES, BALLC_N_LATCH_PER_PLANE)
N_LATCH_PER_PLANE = BALLC_N_LATCH_PER_PLANE
CONTACT_KINEMATICS_PER_PLANE = BALLC_CONTACT_KINEMATICS_PER_PLANE


def state_names(planes, rolling=False):
    """The state names of a run with the planes named ``planes``, in layout order;
    ``rolling``: with rolling resistance (its states after every plane's)."""
    names = BALL_STATE_NAMES + tuple(f"{plane}_{field}" for plane in planes
                                     for field in PLANE_STATE_FIELDS)
    if rolling:
        names += ROLLING_BALL_STATE_NAMES + tuple(
            f"{plane}_{field}" for plane in planes for field in ROLLING_PLANE_STATE_FIELDS)
    return names


def parameter_names(planes):
    """The parameter names of a run with the planes named ``planes``, in layout order."""
    return BASE_PARAMETER_NAMES + tuple(f"{plane}_{field}" for plane in planes
                                        for field in PLANE_FIELD_NAMES)


def latch_names(planes):
    """The latched values' names of a run with the planes named ``planes``."""
    return tuple(f"{plane}_{field}" for plane in planes for field in LATCH_FIELD_NAMES)


#: The seed's planes (Scene's ceiling_height shorthand: a floor and a ceiling), and the
#: layout of a run with them: its states, parameters and latched values (19, 38, 12).
SEED_PLANES = ("floor", "ceiling")
STATE_NAMES = state_names(SEED_PLANES)
N_STATES = len(STATE_NAMES)
#: state name -> index in the state vector (the ball's states: the same in every run)
STATE_INDEX = {name: i for i, name in enumerate(STATE_NAMES)}
PARAMETER_NAMES = parameter_names(SEED_PLANES)
N_PARAMETERS = len(PARAMETER_NAMES)
PARAMETER_UNITS = BASE_PARAMETER_UNITS + PLANE_FIELD_UNITS * len(SEED_PLANES)
LATCH_NAMES = latch_names(SEED_PLANES)
N_LATCH = len(LATCH_NAMES)
#: The parameter constants (parameter-only subexpressions of the kernels), each named by
#: its sympy expression of PARAMETER_NAMES; see codegen/emit.py.
PARAMETER_CONSTANT_NAMES = tuple(BALLC_PARAMETER_CONSTANT_NAMES[i].decode()
                                 for i in range(BALLC_N_PARAMETER_CONSTANTS))
GENERATOR_VERSION = BALLC_GENERATOR_VERSION.decode()
#: The kinds of the right-hand side's flags (_system.h), in their order.
FLAG_KINDS = ("friction", "digin", "compliant", "slip", "stick", "slip_fixed",
              "compliant_sliding", "compliant_elastic")
if len(FLAG_KINDS) != BALLC_N_FLAG_KINDS:
    raise ImportError("ballc._core: FLAG_KINDS does not match _system.h")


def flag(kind, int plane):
    """The right-hand side's flag of ``kind`` (FLAG_KINDS, or "observer") on the plane
    with index ``plane`` (an int, 64 bits)."""
    if kind == "observer":
        return int(BALLC_WITH_OBSERVER)
    if not 0 <= plane < BALLC_MAX_PLANES:
        raise ValueError(f"plane = {plane} is not allowed: must be 0 to {BALLC_MAX_PLANES - 1}")
    return int(ballc_flag(FLAG_KINDS.index(kind), plane))


#: The flags by name for the seed's planes ("floor_friction", ..., and "observer").
FLAGS = {"observer": int(BALLC_WITH_OBSERVER),
         **{f"{plane}_{kind}": flag(kind, i) for i, plane in enumerate(SEED_PLANES)
            for kind in FLAG_KINDS}}


cdef inline void _check(name, Py_ssize_t got, Py_ssize_t expected) except *:
    if got != expected:
        raise ValueError(f"{name} must have length {expected}, got {got}")


cdef int _planes_of(const double[::1] params) except -1:
    """The number of planes of a parameter vector (its plane table's count), checked with
    the vector's length; ValueError when either is not allowed."""
    if params.shape[0] <= BALLC_PARAMETER_PLANE_COUNT:
        raise ValueError(f"params must have length >= {BALLC_PARAMETER_PLANES} (the scene's "
                         f"parameters, then its plane table), got {params.shape[0]}")
    count = params[BALLC_PARAMETER_PLANE_COUNT]
    if not (1 <= count <= BALLC_MAX_PLANES and count == int(count)):
        raise ValueError(f"params: plane_count = {count!r} is not allowed: must be a whole "
                         f"number from 1 to {BALLC_MAX_PLANES}")
    cdef int n = int(count)
    _check("params", params.shape[0], BALLC_PARAMETER_PLANES + n * BALLC_N_PLANE_FIELDS)
    return n


cdef inline int _ball_and_plane_states(int planes):
    """The number of states of a run with ``planes`` and no rolling resistance."""
    return BALLC_N_BALL_STATES + BALLC_N_PLANE_STATES * planes


cdef inline int _states(const double[::1] params, int planes):
    """The number of states of a run with ``params`` (``planes`` of them): the rolling
    block only when its rolling or twisting resistance is not 0 (_system.c)."""
    cdef int n = BALLC_N_BALL_STATES + BALLC_N_PLANE_STATES * planes
    if (params[BALLC_PARAMETER_ROLLING_RESISTANCE] != 0
            or params[BALLC_PARAMETER_TWISTING_RESISTANCE] != 0):
        n += BALLC_N_ROLLING_BALL_STATES + BALLC_N_ROLLING_PLANE_STATES * planes
    return n


cdef inline int _latches(int planes):
    return BALLC_N_LATCH_PER_PLANE * planes


def layout_of(params):
    """(planes, states, latched values) of a run with the parameter vector ``params``."""
    cdef const double[::1] p = np.ascontiguousarray(params, dtype=float)
    cdef int n = _planes_of(p)
    return n, _states(p, n), _latches(n)


cdef void _copy_state(const double[:] y, double *ys, int n) except *:
    """Copy a (possibly strided) state into a C buffer; integrators may pass views."""
    _check("y", y.shape[0], n)
    cdef Py_ssize_t i
    for i in range(y.shape[0]):
        ys[i] = y[i]


cdef class System:
    """f(t, y) and its Jacobian for one integration segment.

    ``params`` (the run's parameter vector, its plane table included) and ``latch`` (its
    latched values) are copied; ``flags`` selects the contributions (see FLAGS, flag).  A
    state at which the equations cannot be evaluated (non-finite values, mass matrix not
    positive definite) gives NaNs, which makes the integrator reject the step;
    ``failures`` counts them.
    """
    cdef double[::1] _params
    cdef double[::1] _latch
    cdef object _params_array, _latch_array   # the arrays _params and _latch view
    cdef readonly long long flags
    cdef readonly int n_states
    cdef public long nfev, njev, failures

    def __init__(self, const double[::1] params, const double[::1] latch, long long flags):
        cdef int planes = _planes_of(params)
        _check("latch", latch.shape[0], _latches(planes))
        self.n_states = _states(params, planes)
        self._params_array = np.empty(params.shape[0])
        self._latch_array = np.empty(latch.shape[0])
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
        _copy_state(y, ys, self.n_states)
        out = np.empty(self.n_states)
        cdef double[::1] o = out
        self.nfev += 1
        if ballc_rhs(ys, &self._params[0], &self._latch[0], self.flags, &o[0]) != BALLC_OK:
            self.failures += 1
            out.fill(np.nan)
        return out

    def jacobian(self, double t, const double[:] y):
        cdef double ys[BALLC_MAX_STATES]
        _copy_state(y, ys, self.n_states)
        out = np.empty((self.n_states, self.n_states))
        cdef double[:, ::1] o = out
        self.njev += 1
        if ballc_jacobian(ys, &self._params[0], &self._latch[0], self.flags,
                          &o[0, 0]) != BALLC_OK:
            self.failures += 1
            out.fill(np.nan)
        return out


cdef int _check_call(const double[::1] params, Py_ssize_t states, Py_ssize_t latch) except -1:
    """The planes of ``params``, checked with a state's and a latch's length (-1: none)."""
    cdef int planes = _planes_of(params)
    _check("y", states, _states(params, planes))
    if latch >= 0:
        _check("latch", latch, _latches(planes))
    return planes


def rhs(const double[::1] y, const double[::1] params, const double[::1] latch,
        long long flags):
    """State derivative (the run's states) at one state; raises if it cannot be evaluated."""
    _check_call(params, y.shape[0], latch.shape[0])
    out = np.empty(y.shape[0])
    cdef double[::1] o = out
    cdef int status = ballc_rhs(&y[0], &params[0], &latch[0], flags, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"right-hand side failed with C status {status}")
    return out


def jacobian(const double[::1] y, const double[::1] params, const double[::1] latch,
             long long flags):
    """Jacobian (states x states) at one state; raises if it cannot be evaluated."""
    _check_call(params, y.shape[0], latch.shape[0])
    out = np.empty((y.shape[0], y.shape[0]))
    cdef double[:, ::1] o = out
    cdef int status = ballc_jacobian(&y[0], &params[0], &latch[0], flags, &o[0, 0])
    if status != BALLC_OK:
        raise FloatingPointError(f"Jacobian failed with C status {status}")
    return out


def rhs_per_sample(const double[:, ::1] states, const double[::1] params,
                   const double[:, ::1] latch, const long long[::1] flags):
    """(n, states): the state derivative at each state row, with that row's latched
    values and flags (what ``rhs`` gives row by row, in one call); a row whose
    right-hand side cannot be evaluated raises, as ``rhs`` does."""
    _check_call(params, states.shape[1], latch.shape[1])
    _check("latch.shape[0]", latch.shape[0], states.shape[0])
    _check("flags", flags.shape[0], states.shape[0])
    out = np.empty((states.shape[0], states.shape[1]))
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
    _check_call(params, states.shape[1], -1)
    out = np.empty((states.shape[0], nout))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(states.shape[0]):
        kernel(&states[i, 0], &params[0], prepared.constants, NULL, &o[i, 0])
    return out


cdef object _per_row_of_system(system_fn function, int per_plane, int fixed,
                               const double[:, ::1] states, const double[::1] params):
    cdef int planes = _check_call(params, states.shape[1], -1)
    out = np.empty((states.shape[0], fixed + per_plane * planes))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(states.shape[0]):
        function(&states[i, 0], &prepared, &o[i, 0])
    return out


def energies(const double[:, ::1] states, const double[::1] params):
    """(n, 2 + 3 planes): kinetic, potential, each plane's Hertz spring, each plane's
    tangential spring, each plane's rolling springs (0 without rolling resistance) (J)
    per state row."""
    return _per_row_of_system(ballc_energy, 3, 2, states, params)


def contact_kinematics(const double[:, ::1] states, const double[::1] params):
    """(n, 5 planes): per plane rho, rhodot, contact-point velocity x, y, z (inertial)."""
    return _per_row_of_system(ballc_contact_kinematics, BALLC_CONTACT_KINEMATICS_PER_PLANE, 0,
                              states, params)


def plane_frames(const double[::1] params):
    """(planes, 3, 3): each plane's frame as the C core builds it from the parameters'
    plane table, rows t1, t2, n (inertial components; see _plane.h)."""
    cdef int planes = _planes_of(params)
    out = np.empty((planes, 3, 3))
    cdef ballc_parameters_t prepared
    cdef int p, i, j
    ballc_parameters_init(&prepared, &params[0])
    for p in range(planes):
        for i in range(3):
            for j in range(3):
                out[p, i, j] = prepared.planes[p].frame[i][j]
    return out


def observer_positions(const double[:, ::1] states, const double[::1] params):
    """(n, 3): observer position in the inertial frame (m)."""
    return _per_row(ballc_observer_position, BALLC_OBSERVER_POSITION_NOUT, states, params)


def contact_forces(const double[:, ::1] states, const double[::1] params,
                   const double[::1] latch, long long flags):
    """(n, 3 planes): sum of the contact forces on the ball (N), each plane's x y z in
    turn, at each state row, for the contact laws selected by ``flags``."""
    cdef int planes = _check_call(params, states.shape[1], latch.shape[0])
    out = np.empty((states.shape[0], 3 * planes))
    cdef double[:, ::1] o = out
    cdef Py_ssize_t i
    for i in range(states.shape[0]):
        if ballc_contact_forces(&states[i, 0], &params[0], &latch[0], flags, &o[i, 0]) != BALLC_OK:
            o[i, :] = np.nan
    return out


cdef int _plane_index(int plane, int planes) except -1:
    if not 0 <= plane < planes:
        raise ValueError(f"plane must be 0 to {planes - 1} (an index of the plane table), "
                         f"got {plane}")
    return plane


def slip_map(const double[::1] params, int plane):
    """(2, states): du/dx of the slip velocity u of ``plane``'s contact point, its
    components along the plane's tangents t1, t2 (plane_frames); u is linear in the
    state, u = slip_map . y."""
    cdef int planes = _planes_of(params)
    _plane_index(plane, planes)
    cdef int n = _states(params, planes)
    cdef double ys[BALLC_MAX_STATES]
    out = np.empty(BALLC_MAX_SLIP_NOUT)
    cdef double[::1] o = out
    cdef Py_ssize_t i
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    for i in range(n):
        ys[i] = 0.0
    ballc_slip_state(ys, &prepared, plane, &o[0])
    return out[2:2 + 2 * n].reshape(2, n)


cdef void _check_plane_call(const double[::1] y, const double[::1] params,
                            const double[::1] latch, int plane) except *:
    """The lengths of a per-plane entry point's inputs, and its plane."""
    cdef int planes = _check_call(params, y.shape[0], latch.shape[0])
    _plane_index(plane, planes)


def stick_state(const double[::1] y, const double[::1] params, const double[::1] latch,
                long long flags, int plane):
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


def remove_slip(const double[::1] y, const double[::1] params, long long flags, int plane):
    """The state with ``plane``'s slip velocity set to zero by a tangential impulse at
    the contact point (for slip-to-stick transitions, where it is at rounding level);
    every other plane sticking under ``flags`` keeps its slip."""
    cdef int planes = _check_call(params, y.shape[0], -1)
    _plane_index(plane, planes)
    out = np.empty(y.shape[0])
    cdef double[::1] o = out
    cdef int status = ballc_remove_slip(&y[0], &params[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"remove_slip failed with C status {status}")
    return out


def rolling_state(const double[::1] y, const double[::1] params, const double[::1] latch,
                  long long flags, int plane):
    """Rolling resistance on ``plane`` (src/ballc/_rolling.h) under ``flags`` and the
    modes in ``latch``: (lambda (3: the rolling force along t1, t2 and the twisting force
    that hold the held parts, N), F_n (N), the rolling margin mu_r F_n - |lambda_r| (N),
    the twisting margin mu_t F_n - |lambda_w| (N), the rolling velocity (2, m/s), the
    twisting velocity (m/s)); raises if it cannot be evaluated (the plane must be in
    contact under ``flags``)."""
    return _rolling_call(ballc_rolling_state, BALLC_ROLLING_STATE_NOUT, "rolling state",
                         y, params, latch, flags, plane)


def rolling_margins(const double[::1] y, const double[::1] params, const double[::1] latch,
                    long long flags, int plane):
    """The sds model's guards on ``plane`` (codegen contact.sds_margins), per part
    (rolling, twisting): yield margin 1 - k |xi| / (mu F_n), re-stick margin (m/s, with
    the penetration acceleration of the dynamics under ``flags`` and ``latch``) and the
    deflection at the cap mu F_n / k (m)."""
    return _rolling_call(ballc_rolling_margins, BALLC_SDS_MARGINS, "rolling margins",
                         y, params, latch, flags, plane)


ctypedef int (*_rolling_entry)(const double *, const ballc_parameters_t *, const double *,
                               ballc_flags, int, double *) nogil


cdef object _rolling_call(_rolling_entry entry, int n_out, str what, const double[::1] y,
                          const double[::1] params, const double[::1] latch, long long flags,
                          int plane):
    """rolling_state's and rolling_margins' bridge: the inputs checked, the parameters
    prepared, ``entry`` called on ``plane``; its ``n_out`` outputs, or raises naming
    ``what``."""
    _check_plane_call(y, params, latch, plane)
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    out = np.empty(n_out)
    cdef double[::1] o = out
    cdef int status = entry(&y[0], &prepared, &latch[0], flags, plane, &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"{what} failed with C status {status}")
    return out


#: ballc_remove_velocities' mask bits (_rolling.h BALLC_HOLD_*)
HOLD_SLIP, HOLD_ROLLING, HOLD_TWISTING = 1, 2, 4


def remove_velocities(const double[::1] y, const double[::1] params, const double[::1] latch,
                      long long flags, int plane, int mask):
    """The state with ``plane``'s velocities in ``mask`` (HOLD_SLIP, HOLD_ROLLING,
    HOLD_TWISTING) set to zero by one impulse of the constraint forces that hold them."""
    _check_plane_call(y, params, latch, plane)
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    out = np.empty(y.shape[0])
    cdef double[::1] o = out
    cdef int status = ballc_remove_velocities(&y[0], &prepared, &latch[0], flags, plane, mask,
                                              &o[0])
    if status != BALLC_OK:
        raise FloatingPointError(f"remove_velocities failed with C status {status}")
    return out


def contact_forces_per_sample(const double[:, ::1] states, const double[::1] params,
                              const double[:, ::1] latches, const long long[::1] flags):
    """(n, 3 planes): as contact_forces, with each state row's own latched values (row of
    ``latches``) and flags -- one call for a whole run's samples."""
    cdef int planes = _check_call(params, states.shape[1], latches.shape[1])
    _check("latches.shape[0]", latches.shape[0], states.shape[0])
    _check("flags", flags.shape[0], states.shape[0])
    out = np.empty((states.shape[0], 3 * planes))
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
                for j in range(3 * planes):
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
    _planes_of(params)
    out = np.empty(BALLC_N_PARAMETER_CONSTANTS)
    cdef double[::1] o = out
    if BALLC_N_PARAMETER_CONSTANTS:
        ballc_parameter_constants(&params[0], &o[0])
    return out


def hertz_stiffness(const double[::1] params):
    """k0 (N/m^(3/2)) of the generated contact law, from the parameter vector."""
    _planes_of(params)
    cdef double state[BALLC_MAX_STATES]
    cdef double k0
    cdef ballc_parameters_t prepared
    ballc_parameters_init(&prepared, &params[0])
    ballc_hertz_stiffness(state, &params[0], prepared.constants, NULL, &k0)
    return k0
