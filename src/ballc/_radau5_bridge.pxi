# Included by _core.pyx (one extension, one compiled copy of the kernels); compiled
# with its directives (boundscheck=False, wraparound=False, initializedcheck=False).
# Bridge to the compiled integrator (``_integrator.c``: the loop; ``_radau_iia.c``: the
# Radau IIA (order 5) step; ``_dop853.c``: the DOP853 step).
#
# Private: use ``ballc.simulate(..., method="radau5")``; imported as ``ballc._radau5``
# (a thin module re-exporting these names).  This part of ``_core`` checks and
# converts arguments, hands a C right-hand side to ``radau5_solve`` and turns its
# buffers into arrays.  The whole integration runs in C without the GIL: no Python
# per step; the Newton systems are solved by ballc's own LU (``_lu.c``), no LAPACK.
#
# ``solve_system`` integrates ballc's equations (``ballc_rhs`` / ``ballc_jacobian``);
# ``solve_linear`` integrates y' = A y (a generic entry point, used to test the
# integrator against the matrix exponential); ``_lu_solve`` exposes the LU for tests.

import numpy as np
from scipy.optimize import OptimizeResult

from libc.math cimport isfinite
from libc.string cimport memcmp, memcpy
from libc.math cimport NAN


cdef extern from "_lu.h":
    int BALLC_LU_OK
    int ballc_lu_factor(int, double *, int *) nogil
    int ballc_lu_factor_complex(int, double complex *, int *) nogil
    void ballc_lu_solve(int, const double *, const int *, double *) nogil
    void ballc_lu_solve_complex(int, const double complex *, const int *,
                                double complex *) nogil

cdef extern from "_integrator.h":
    ctypedef int (*radau5_fun)(void *, double, const double *, double *) noexcept nogil
    ctypedef int (*radau5_jac)(void *, double, const double *, double *) noexcept nogil
    ctypedef int (*radau5_event_fun)(void *, int, double, const double *, double *) noexcept nogil
    ctypedef int (*radau5_rearm_fun)(void *, int, double, const double *) noexcept nogil
    ctypedef struct radau5_problem:
        int n
        radau5_fun fun
        radau5_jac jac
        void *ctx
        double t0, t_bound
        const double *y0
        double rtol
        const double *atol
        double max_step, first_step
        long max_nfev
        const double *t_eval
        long n_eval
        int n_events
        const double *ev_coef
        const double *ev_offset
        const int *ev_nonlinear
        radau5_event_fun ev_fun
        const int *ev_terminal
        const int *ev_direction
        int dense_output
        int controller
        int outputs_checked
        int refine_events
        const int *ev_rearm
        radau5_rearm_fun rearm
        int method
        int jacobian_ahead
        int auto_implicit
        int (*poll)(void *, double) noexcept nogil
        int jacobian_every_step
    ctypedef struct radau5_result:
        int status
        char message[240]
        long nfev, njev, nlu, nstep, nreject
        double h_next
        long n_out
        double *t_out
        double *y_out
        long n_hits
        long n_rearmed
        int *hit_event
        double *hit_t
        double *hit_y
        long n_dense
        double *dense_t
        double *dense_c
        int dense_terms
        int *dense_kind
        double stiff_at
        long n_switches
        double *switch_t
        int *switch_to
        int method_end
        long nstep_implicit
        int profiled
        double prof[7]
    int radau5_solve(const radau5_problem *, radau5_result *) nogil
    int RADAU5_DONE, RADAU5_OUT_OF_MEMORY, RADAU5_BAD_PROBLEM
    int RADAU5_REACHED, RADAU5_EVENT, RADAU5_FAILED, RADAU5_INTERRUPTED
    int RADAU5_METHOD_RADAU, RADAU5_METHOD_DOP853, RADAU5_METHOD_AUTO
    void radau5_free(radau5_result *) nogil


EPS = np.finfo(float).eps

# ---- C adapters: the systems radau5 can integrate ----

ctypedef struct ball_ctx:
    const double *params
    ballc_parameters_t prepared   # params and their constants, prepared once per segment
    double *latch            # writable: a re-armed event may change it
    ballc_flags flags
    int n_states, n_latch    # the run's (its parameters' plane table)
    int *event_plane         # per event: 0 .. MAX_PLANES - 1 stick release of that plane,
                             # margin_event_code(row, plane) row ``row`` of the compliant
                             # margins (0 yield, 1 re-stick, 4/5 the capacity margin and
                             # its negative), -1 linear, -2 - k the user's Python event k
                             # (writable: a capacity guard toggles between rows 4 and 5)
    void *user_events        # list of the user's event callables (borrowed)
    void *errors             # list collecting exceptions raised by them (borrowed)
    void *rearms             # per event: its ``rearm`` callable or None (borrowed)
    double *ev_coef_w        # the event arrays radau5 reads (events x n_states, events)
    double *ev_offset_w
    # the last compliant margins computed (a segment's yield and capacity guards read the
    # same kernel at the same state): the state, the plane (-1: none), whether the
    # re-stick margin's solve was made, the margins
    double *margins_y        # n_states (a buffer solve_system holds)
    int margins_plane
    int margins_solved
    double margins_out[6]

cdef int _ball_fun(void *ctx, double t, const double *y, double *f) noexcept nogil:
    cdef ball_ctx *c = <ball_ctx *>ctx
    return ballc_rhs_checked_inputs(y, &c.prepared, c.latch, c.flags, f)

cdef int _ball_jac(void *ctx, double t, const double *y, double *jac) noexcept nogil:
    cdef ball_ctx *c = <ball_ctx *>ctx
    return ballc_jacobian_checked_inputs(y, &c.prepared, c.latch, c.flags, jac)

cdef int _ball_event(void *ctx, int e, double t, const double *y, double *g) noexcept nogil:
    """The stick-to-slip margin mu N - |lambda| of the event's plane, a compliant mode
    guard (yield or re-stick margin), or a user event."""
    cdef ball_ctx *c = <ball_ctx *>ctx
    cdef double out[6]   # BALLC_COMPLIANT_MARGINS (stick_state's 4 fit)
    cdef int plane = c.event_plane[e]
    cdef int row
    cdef int status
    if plane <= -2:
        with gil:
            return _user_event(c, -2 - plane, t, y, g)
    if plane >= _MARGIN_CODE:
        row = (plane - _MARGIN_CODE) // BALLC_MAX_PLANES
        plane = (plane - _MARGIN_CODE) % BALLC_MAX_PLANES
        if (c.margins_plane == plane and (row != 1 or c.margins_solved)
                and memcmp(c.margins_y, y, c.n_states * sizeof(double)) == 0):
            g[0] = c.margins_out[row]   # the same kernel at the same state: its values
            return BALLC_OK
        status = ballc_compliant_margins_prepared(y, &c.prepared, c.latch, c.flags, plane,
                                                  row, c.margins_out)
        c.margins_plane = plane if status == BALLC_OK else -1
        c.margins_solved = row == 1
        memcpy(c.margins_y, y, c.n_states * sizeof(double))
        g[0] = c.margins_out[row]
        return status
    status = ballc_stick_state(y, c.params, c.latch, c.flags, plane, out)
    g[0] = out[3]
    return status


cdef int _user_event(ball_ctx *c, int k, double t, const double *y, double *g) noexcept:
    """Call the user's event g(t, y) (Python, with the GIL); an exception is kept for
    solve_system to raise and the event reads as NaN (no crossing) meanwhile."""
    cdef double[::1] yv
    errors = <list>c.errors
    if errors:
        g[0] = NAN
        return -1
    try:
        state = np.empty(c.n_states)
        yv = state
        memcpy(&yv[0], y, c.n_states * sizeof(double))
        g[0] = float((<list>c.user_events)[k](t, state))
        return 0
    except BaseException as error:
        errors.append(error)
        g[0] = NAN
        return -1

#: The codes of the system's events: 0 .. MAX_PLANES - 1 a plane's stick release, from
#: _MARGIN_CODE on row ``row`` of a plane's compliant margins (margin_event_code); the
#: capacity guards (rows 4 and 5, per plane): a capacity guard that fires is re-armed in
#: C to watch the way back (row 4 <-> 5).
cdef int _MARGIN_CODE = BALLC_MAX_PLANES
cdef int _CAPACITY_FIRST = BALLC_MAX_PLANES + 4 * BALLC_MAX_PLANES
cdef int _CAPACITY_SECOND = BALLC_MAX_PLANES + 5 * BALLC_MAX_PLANES


def margin_event_code(int row, int plane):
    """The ``system_event`` code of row ``row`` of the compliant margins of the plane with
    index ``plane`` (solve_system's events)."""
    return _MARGIN_CODE + row * BALLC_MAX_PLANES + plane


def margin_event_row(int code):
    """The margins' row of a ``system_event`` code (margin_event_code's inverse)."""
    return (code - _MARGIN_CODE) // BALLC_MAX_PLANES

cdef int _ball_rearm(void *ctx, int e, double t, const double *y) noexcept nogil:
    """Re-arm event e at its hit: a capacity guard toggles its row (no Python, no change
    of the equations: the segment goes on past the kink it ended a step at); any other
    calls its ``rearm``."""
    cdef ball_ctx *c = <ball_ctx *>ctx
    cdef int code = c.event_plane[e]
    if code >= _CAPACITY_FIRST:
        c.event_plane[e] = (code + BALLC_MAX_PLANES if code < _CAPACITY_SECOND
                            else code - BALLC_MAX_PLANES)
        return 1
    with gil:
        return _rearm_event(c, e, t, y)


cdef int _rearm_event(ball_ctx *c, int e, double t, const double *y) noexcept:
    """Call event e's ``rearm(t, y)`` (Python, with the GIL): None declines (the event
    stops the integration as usual); (coefficients (N_STATES,), offset, latch (N_LATCH,))
    re-arms it: written where radau5 and the right-hand side read them.  An exception
    is kept for solve_system to raise, and the event stops the integration meanwhile."""
    cdef double[::1] yv
    cdef const double[::1] cv, lv
    cdef double off
    errors = <list>c.errors
    if errors:
        return 0
    try:
        state = np.empty(c.n_states)
        yv = state
        memcpy(&yv[0], y, c.n_states * sizeof(double))
        out = (<list>c.rearms)[e](t, state)
        if out is None:
            return 0
        coefficients, offset, latch = out
        cv = _checked_row("rearm coefficients", coefficients, c.n_states)
        lv = _checked_row("rearm latch", latch, c.n_latch)
        off = float(offset)
        if not isfinite(off):
            raise ValueError(f"rearm offset = {offset!r} is not allowed: must be finite")
        memcpy(c.ev_coef_w + <size_t>e * c.n_states, &cv[0],
               c.n_states * sizeof(double))
        c.ev_offset_w[e] = off
        memcpy(c.latch, &lv[0], c.n_latch * sizeof(double))
        c.margins_plane = -1   # the margins read the latch
        return 1
    except BaseException as error:
        errors.append(error)
        return 0


ctypedef struct linear_ctx:
    int n
    const double *A

cdef int _linear_fun(void *ctx, double t, const double *y, double *f) noexcept nogil:
    cdef linear_ctx *c = <linear_ctx *>ctx
    cdef int i, j
    cdef double s
    for i in range(c.n):
        s = 0
        for j in range(c.n):
            s += c.A[i * c.n + j] * y[j]
        f[i] = s
    return 0

cdef int _linear_jac(void *ctx, double t, const double *y, double *jac) noexcept nogil:
    cdef linear_ctx *c = <linear_ctx *>ctx
    memcpy(jac, c.A, c.n * c.n * sizeof(double))
    return 0


# ---- argument checks ----

# The checks run once per segment (simulate calls solve_system per smooth piece), so
# they loop in C rather than through numpy's ufunc machinery.

cdef bint _finite(const double[::1] a) noexcept:
    cdef Py_ssize_t i
    for i in range(a.shape[0]):
        if not isfinite(a[i]):
            return False
    return True


cdef bint _finite_nonnegative(const double[::1] a) noexcept:
    cdef Py_ssize_t i
    for i in range(a.shape[0]):
        if not (isfinite(a[i]) and a[i] >= 0):
            return False
    return True


cdef const double[::1] _checked_row(str name, value, Py_ssize_t n, Py_ssize_t index=-1):
    """``value`` as n finite float64s (one view; ``_vector`` for anything else).
    ``index`` >= 0: ``name`` is a format with one field, filled with it only where a
    message needs the name (a per-event check builds no string on the good path)."""
    cdef const double[::1] v
    cdef Py_ssize_t i
    if not (type(value) is np.ndarray and value.dtype == np.float64 and value.shape == (n,)
            and value.flags.c_contiguous):
        value = _vector(name.format(index) if index >= 0 else name, value, n)
    v = value
    for i in range(n):
        if not isfinite(v[i]):
            _vector(name.format(index) if index >= 0 else name, value, n)   # raises, naming it
    return v


def _vector(name, value, n):
    a = np.ascontiguousarray(value, dtype=float)
    if a.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {a.shape}")
    if not _finite(a):
        raise ValueError(f"{name} = {value!r} is not allowed: must be finite")
    return a


def _options(n, t0, t1, rtol, atol, max_step, t_eval, first_step):
    t0, t1 = float(t0), float(t1)
    if not (isfinite(t0) and isfinite(t1)):
        raise ValueError(f"t_span = ({t0}, {t1}) is not allowed: must be finite")
    if not isinstance(rtol, float):
        rtol = float(rtol) if np.ndim(rtol) == 0 else rtol
    if not isinstance(rtol, float) or not (isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol = {rtol!r} is not allowed: must be one finite number > 0")
    if rtol < 100 * EPS:   # as ballc.options: scipy would silently raise it
        raise ValueError(f"rtol = {rtol!r} is not allowed: must be >= 100 machine "
                         f"epsilons = {100 * EPS:.3g}")
    if isinstance(atol, (float, int)):
        atol_v = np.empty(n)   # a writable copy
        atol_v.fill(atol)
    else:
        atol_v = np.array(np.broadcast_to(np.asarray(atol, dtype=float), (n,)))
    if not _finite_nonnegative(atol_v):
        raise ValueError(f"atol = {atol!r} is not allowed: must be finite and >= 0")
    max_step = float(max_step)
    if not max_step > 0:
        raise ValueError(f"max_step = {max_step!r} is not allowed: must be > 0")
    first = 0.0 if first_step is None else float(first_step)
    if first_step is not None and not (isfinite(first) and 0 < first <= abs(t1 - t0)):
        raise ValueError(f"first_step = {first_step!r} is not allowed: must be in "
                         f"(0, {abs(t1 - t0)}]")
    if t_eval is not None:
        t_eval = np.ascontiguousarray(t_eval, dtype=float)
        d = 1.0 if t1 >= t0 else -1.0
        lo, hi = min(t0, t1), max(t0, t1)
        if (t_eval.ndim != 1 or np.any(d * np.diff(t_eval) <= 0)
                or (t_eval.size and (t_eval.min() < lo or t_eval.max() > hi))):
            raise ValueError("t_eval must be 1-D, strictly monotonic in the direction of "
                             f"integration and within t_span = ({t0}, {t1})")
    return t0, t1, rtol, atol_v, max_step, t_eval, first


def terminal_count(terminal) -> int:
    """An event's ``terminal`` as solve_ivp (scipy >= 1.12) reads it: False, None or 0
    -> 0 (not terminal); True -> 1 (stop at the first occurrence); an integer k > 0 ->
    k (stop at the k-th)."""
    if terminal is None or terminal is False:
        return 0
    if terminal is True:
        return 1
    try:
        count = int(terminal)
    except (TypeError, ValueError):
        count = -1
    if count != terminal or count < 0:
        raise ValueError(f"terminal = {terminal!r} is not allowed: must be a boolean or an "
                         "integer >= 0 (stop at that occurrence)")
    return count


def _event_arrays(events, int n):
    """Linear events (``coefficients``, ``offset``), events the system evaluates in C
    (``system_event``, ``offset``: a plane's index, the stick release mu N - |lambda| +
    offset of that plane; margin_event_code(row, plane): a row of the compliant
    margins, 0 the yield margin, 1 the re-stick margin) and, for
    ballc's system, any other callable g(t, y) (a user event, called from C).
    Returns (m, coef, offset, ints, user callables, rearms); ``ints`` (5 rows):
    terminal, direction, plane (-1 linear, 0..5 a system event, -2 - k the user's event
    k), nonlinear (not evaluated from ``coef``) and re-armable (a terminal linear event
    with a ``rearm`` callable, see solve_system, or a system event that ``toggles``: a
    compliant capacity guard); ``rearms``: per event, that callable or None."""
    cdef Py_ssize_t m = len(events), k, size = max(len(events), 1)
    coef = np.zeros((size, n))
    reals = np.zeros(size)
    ints = np.zeros((5, size), dtype=np.intc)
    cdef double[:, ::1] cv = coef
    cdef double[::1] offset = reals
    cdef int[:, ::1] iv = ints   # terminal, direction, plane, nonlinear, re-armable
    cdef const double[::1] row
    iv[2, :] = -1
    users = []
    rearms = [None] * m
    for k in range(m):
        e = events[k]
        c = getattr(e, "coefficients", None)   # the driver's events are LinearEvents
        if c is not None:
            row = _checked_row("events[{}].coefficients", c, n, k)
            memcpy(&cv[k, 0], &row[0], n * sizeof(double))
            offset[k] = float(getattr(e, "offset", 0.0))
        elif hasattr(e, "system_event"):
            iv[2, k] = int(e.system_event)
            iv[3, k] = 1
            offset[k] = float(getattr(e, "offset", 0.0))
            if getattr(e, "toggles", False) and terminal_count(getattr(e, "terminal", False)):
                iv[4, k] = 1   # a capacity guard: re-armed in C (_ball_rearm)
        elif callable(e):
            iv[2, k] = -2 - len(users)
            iv[3, k] = 1
            users.append(e)
        else:
            raise TypeError(f"events[{k}] = {e!r} is neither a linear event (`coefficients` "
                            "and `offset`: g(y) = coefficients . y + offset), a system "
                            "event (`system_event`) nor a callable g(t, y)")
        iv[0, k] = terminal_count(getattr(e, "terminal", False))
        dirn = float(getattr(e, "direction", 0))
        iv[1, k] = (dirn > 0) - (dirn < 0)
        rearm = getattr(e, "rearm", None)
        if rearm is not None and c is not None and iv[0, k]:
            rearms[k] = rearm
            iv[4, k] = 1
    return m, coef, reals, ints, users, rearms


cdef extern from "_integrator.h":
    enum:
        RADAU5_CTRL_NIT7, RADAU5_CTRL_LIMITS, RADAU5_CTRL_PRED, RADAU5_CTRL_HOLD
        RADAU5_CTRL_JAC, RADAU5_CTRL_TOL, RADAU5_CTRL_SCALE, RADAU5_CTRL_HAIRER

#: radau5's step-control elements (internal; see _integrator.h and
#: benchmarks/controllers.py): name -> bit of radau5_problem.controller.
CONTROLLER_ELEMENTS = {
    "nit7": RADAU5_CTRL_NIT7, "limits": RADAU5_CTRL_LIMITS, "pred": RADAU5_CTRL_PRED,
    "hold": RADAU5_CTRL_HOLD, "jac": RADAU5_CTRL_JAC, "tol": RADAU5_CTRL_TOL,
    "scale": RADAU5_CTRL_SCALE,
}
#: The step control every solve uses unless told otherwise (``_set_controller``).
DEFAULT_CONTROLLER = 0
_controller = [DEFAULT_CONTROLLER]


def _controller_bits(controller):
    """``controller``: None (the current one), an int of RADAU5_CTRL_* bits, "scipy",
    "hairer" (every element), or an iterable of element names."""
    if controller is None:
        return _controller[0]
    if controller == "scipy":
        return 0
    if controller == "hairer":
        return RADAU5_CTRL_HAIRER
    if isinstance(controller, (int, np.integer)) and 0 <= controller <= RADAU5_CTRL_HAIRER:
        return int(controller)
    if isinstance(controller, str):
        controller = [controller]
    bits = 0
    for name in controller:
        if name not in CONTROLLER_ELEMENTS:
            raise ValueError(f"controller element {name!r} is not one of "
                             f"{sorted(CONTROLLER_ELEMENTS)}")
        bits |= CONTROLLER_ELEMENTS[name]
    return bits


def _set_controller(controller):
    """Make ``controller`` (see ``_controller_bits``) the step control of every later
    radau5 solve in this process (private: benchmarks and tests); returns the previous
    bits."""
    previous = _controller[0]
    _controller[0] = _controller_bits(controller)
    return previous


cdef object _run(radau5_problem *p, int n, int m):
    cdef radau5_result r
    cdef int rc
    cdef double[::1] tv, htv
    cdef double[:, ::1] yv, hyv, dtv, dcv
    cdef int[::1] hev, dkv
    cdef Py_ssize_t i
    with nogil:
        rc = radau5_solve(p, &r)
    try:
        if rc == RADAU5_OUT_OF_MEMORY:
            raise MemoryError(r.message.decode())
        if rc != RADAU5_DONE:
            raise ValueError(r.message.decode())
        dense = None
        if p.dense_output:
            dense_t = np.empty((r.n_dense, 2))
            dense_c = np.empty((r.n_dense, (1 + r.dense_terms) * n))
            dense_kind = np.empty(r.n_dense, dtype=np.intc)
            if r.n_dense:
                dtv = dense_t
                dcv = dense_c
                dkv = dense_kind
                memcpy(&dtv[0, 0], r.dense_t, r.n_dense * 2 * sizeof(double))
                memcpy(&dcv[0, 0], r.dense_c,
                       r.n_dense * (1 + r.dense_terms) * n * sizeof(double))
                memcpy(&dkv[0], r.dense_kind, r.n_dense * sizeof(int))
            dense = (dense_t, dense_c, r.dense_terms, dense_kind)
        t = np.empty(r.n_out)
        y = np.empty((r.n_out, n))
        if r.n_out:
            tv = t
            yv = y
            memcpy(&tv[0], r.t_out, r.n_out * sizeof(double))
            memcpy(&yv[0, 0], r.y_out, r.n_out * n * sizeof(double))
        hit_event = hit_t = hit_y = None
        if r.n_hits:
            hit_event = np.empty(r.n_hits, dtype=np.intc)
            hit_t = np.empty(r.n_hits)
            hit_y = np.empty((r.n_hits, n))
            hev = hit_event
            htv = hit_t
            hyv = hit_y
            memcpy(&hev[0], r.hit_event, r.n_hits * sizeof(int))
            memcpy(&htv[0], r.hit_t, r.n_hits * sizeof(double))
            memcpy(&hyv[0, 0], r.hit_y, r.n_hits * n * sizeof(double))
        status, message, r_hits = r.status, r.message.decode(), r.n_hits
        counts = dict(nfev=r.nfev, njev=r.njev, nlu=r.nlu, nstep=r.nstep, nreject=r.nreject,
                      h_next=r.h_next, n_rearmed=r.n_rearmed, stiff_at=r.stiff_at,
                      nstep_implicit=r.nstep_implicit,
                      method_end=_METHOD_NAMES[r.method_end],
                      switches=[(r.switch_t[i], _METHOD_NAMES[r.switch_to[i]])
                                for i in range(r.n_switches)])
        if r.profiled:   # a -DRADAU5_PROFILE build (benchmarks/profile_step.py)
            counts["profile"] = dict(zip(("fun", "jac", "factor", "solve", "events",
                                          "total", "total_ns"), [r.prof[i] for i in range(7)]))
    finally:
        radau5_free(&r)
    if r_hits:
        t_events, y_events = _group_hits(hit_event, hit_t, hit_y, m, n)
    else:   # no event hit (most segments of a scene without events)
        no_t, no_y = np.empty(0), np.empty((0, n))
        t_events, y_events = [no_t] * m, [no_y] * m
    return OptimizeResult(t=t, y=y.T, t_events=t_events,
                          y_events=y_events, status=status, message=message,
                          success=status >= 0, sol=None, dense=dense, **counts)


cdef tuple _group_hits(const int[::1] event, const double[::1] t, const double[:, ::1] y,
                       int m, int n):
    """Per event k, the times (hits,) and states (hits, n) of its hits, in order.  The
    events without a hit (most of them) share one pair of empty arrays."""
    cdef Py_ssize_t h, k, i
    cdef double[::1] tv
    cdef double[:, ::1] yv
    t_events, y_events = [], []
    counts = [0] * m
    for h in range(event.shape[0]):
        counts[event[h]] += 1
    no_t, no_y = np.empty(0), np.empty((0, n))
    for k in range(m):
        if not counts[k]:
            t_events.append(no_t)
            y_events.append(no_y)
            continue
        te = np.empty(counts[k])
        ye = np.empty((counts[k], n))
        tv = te
        yv = ye
        i = 0
        for h in range(event.shape[0]):
            if event[h] == k:
                tv[i] = t[h]
                yv[i, :] = y[h, :]
                i += 1
        t_events.append(te)
        y_events.append(ye)
    return t_events, y_events


cdef object _solve(radau5_fun fun, radau5_jac jac, void *ctx, int n, t_span, y0,
                   rtol, atol, max_step, t_eval, events, first_step, max_nfev,
                   radau5_event_fun event_fun=NULL, int[::1] event_plane=None,
                   list users=None, bint dense_output=False, controller=None,
                   bint outputs_checked=False, bint refine_events=True,
                   ball_ctx *ball=NULL, method="radau5", bint jacobian_ahead=False,
                   bint auto_implicit=False, bint jacobian_every_step=False):
    """``ball``: ballc's system context (solve_system), which re-arms events;
    ``jacobian_ahead``, ``auto_implicit``, ``jacobian_every_step``: radau5_problem's."""
    cdef radau5_problem p
    p.method = _method_code(method)
    p.jacobian_ahead = jacobian_ahead
    p.auto_implicit = auto_implicit
    p.jacobian_every_step = jacobian_every_step
    cdef int ctrl = _controller_bits(controller)
    if max_nfev is not None and not (isinstance(max_nfev, (int, np.integer)) and max_nfev > 0):
        raise ValueError(f"max_nfev = {max_nfev!r} is not allowed: must be None or an "
                         "integer > 0")
    t0, t1 = t_span
    t0, t1, rtol, atol_v, max_step, t_eval, first = _options(
        n, t0, t1, rtol, atol, max_step, t_eval, first_step)
    y0 = _vector("y0", y0, n)
    m, coef, offset, ints, found, rearms = _event_arrays(list(events or ()), n)
    cdef int[:, ::1] iv = ints   # terminal, direction, plane, nonlinear, re-armable
    cdef Py_ssize_t k
    cdef bint rearmable = False
    for k in range(m):
        if iv[4, k]:
            if ball == NULL:
                raise TypeError("this system does not re-arm events (a `rearm` callable "
                                "needs ballc's system: solve_system)")
            rearmable = True
        if event_plane is not None:   # the system evaluates its own events: it reads the planes
            event_plane[k] = iv[2, k]
        elif iv[3, k]:
            raise TypeError("this system takes linear events only (`coefficients` and "
                            "`offset`): system and callable events need ballc's "
                            "system (solve_system)")
    if event_plane is not None:
        users.extend(found)
    cdef double[::1] y0v = y0, atolv = atol_v, offv = offset
    cdef double[:, ::1] coefv = coef
    cdef double[::1] tev
    p.n = n
    p.fun = fun
    p.jac = jac
    p.ctx = ctx
    p.t0 = t0
    p.t_bound = t1
    p.y0 = &y0v[0]
    p.rtol = rtol
    p.atol = &atolv[0]
    p.max_step = max_step
    p.first_step = first
    p.max_nfev = 0 if max_nfev is None else max_nfev
    p.t_eval = NULL
    p.n_eval = 0
    if t_eval is not None:
        p.n_eval = t_eval.size
        if t_eval.size:
            tev = t_eval
            p.t_eval = &tev[0]
        else:
            p.t_eval = &y0v[0]   # any non-NULL address: store no point at all
    p.n_events = m
    p.ev_coef = &coefv[0, 0]
    p.ev_offset = &offv[0]
    p.ev_terminal = &iv[0, 0]
    p.ev_direction = &iv[1, 0]
    p.ev_nonlinear = &iv[3, 0]
    p.ev_fun = event_fun
    p.dense_output = dense_output
    p.controller = ctrl
    p.outputs_checked = outputs_checked
    p.refine_events = refine_events
    p.ev_rearm = NULL
    p.rearm = NULL
    p.poll = NULL
    if rearmable:
        ball.rearms = <void *>rearms
        ball.ev_coef_w = &coefv[0, 0]
        ball.ev_offset_w = &offv[0]
        p.ev_rearm = &iv[4, 0]
        p.rearm = _ball_rearm
    return _run(&p, n, m)


#: The compiled methods' names by their C code (radau5_result.method_end, switch_to).
_METHOD_NAMES = {RADAU5_METHOD_RADAU: "radau5", RADAU5_METHOD_DOP853: "dop853"}


cdef int _method_code(method) except -1:
    if method == "radau5":
        return RADAU5_METHOD_RADAU
    if method == "dop853":
        return RADAU5_METHOD_DOP853
    if method == "auto":
        return RADAU5_METHOD_AUTO
    raise ValueError(f"method = {method!r} is not allowed: must be 'radau5', 'dop853' or "
                     "'auto'")


def solve_system(params, latch, long long flags, t_span, y0, *, rtol, atol,
                 max_step=np.inf, t_eval=None, events=(), first_step=None, max_nfev=None,
                 dense_output=False, controller=None, refine_events=True, method="radau5",
                 auto_implicit=False):
    """Integrate ballc's equations (the run's states: its parameters' plane table) over
    ``t_span`` with radau5.

    ``method``: "radau5" (Radau IIA, order 5: scipy's Radau), "dop853" (Dormand &
    Prince's explicit pair of order 8: scipy's DOP853, for scenes that are not stiff;
    ``controller`` and the Jacobian play no part) or "auto" (starts with dop853 --
    with radau5 when ``auto_implicit`` -- and switches to radau5 when Hairer's
    stiffness test fires, back when radau5's steps h rho(J) stay below dop853's
    stability bound; see _integrator.h); the loop, events and output are the same.
    Also returned: ``switches`` [(t, method switched to)], ``method_end`` (the method
    in use at the end) and ``nstep_implicit`` (the radau5 steps of nstep).

    ``params``, ``latch`` and ``flags`` are as for ``_core.System``.  ``events``:
    objects with ``coefficients`` (one per state), ``offset``, ``terminal`` and
    ``direction`` -- g(y) = coefficients . y + offset -- or with ``system_event``
    instead of ``coefficients``: a margin evaluated in C plus ``offset`` (a plane's
    index: the stick-to-slip margin mu N - |lambda| of that plane;
    margin_event_code(row, plane): the compliant law's yield margin (row 0) or its
    re-stick margin (row 1)); or
    any other callable g(t, y) with optional ``terminal``/``direction`` (called from C
    with the GIL; an exception it raises is re-raised after the integration).  A
    terminal linear event may carry ``rearm``: a callable (t, y) -> None or
    (coefficients, offset, latch), called at the event's state (with refine_events,
    once the integration has stepped to its time).  None stops the integration there as
    usual; a triple re-arms it: the event becomes coefficients . y + offset, the system
    goes on with ``latch`` (which must leave the right-hand side unchanged at and just
    past the event), the integration continues from the event's state with its step
    size, Jacobian and history, and the hit is not reported (``n_rearmed`` counts them).
    Returns a solve_ivp-shaped OptimizeResult (t, y, t_events, y_events, status,
    message, success, nfev, njev, nlu) plus nstep and nreject (``y`` is the transpose of
    the solver's rows: shape (states, samples), Fortran order), and ``dense``: with
    ``dense_output``, (dense_t (steps x 2: t_old, t), dense_c (steps x (1 + terms)
    states: y_old, then ``terms`` rows of states: radau5 3, y = y_old + sum_j
    row_j x^(j+1); dop853 7, scipy's Dop853DenseOutput F), terms, kinds (steps,):
    each step's own number of terms -- with "auto" a radau5 step (3) in rows as wide as
    dop853's (7, the rest zeros)), else None.
    ``max_nfev``: give up (status -1, with what was computed) after that many
    right-hand-side calls.  ``controller``: the step control (private; None: the
    process's current one, see ``_set_controller``).  ``refine_events`` (default
    True): the state at a terminal event is the end point of a step taken to the
    event's time (order 5, error-controlled), not the crossing step's dense output
    (a cubic, as in solve_ivp); False: solve_ivp's.
    """
    cdef ball_ctx ctx
    cdef int n_planes = _planes_of(np.ascontiguousarray(params, dtype=float))
    params = _vector("params", params, BALLC_PARAMETER_PLANES + n_planes * BALLC_N_PLANE_FIELDS)
    latch = np.array(_vector("latch", latch, _latches(n_planes)))   # own copy: re-arming writes it
    cdef double[::1] pv = params, lv = latch
    planes_array = np.empty(max(len(events or ()), 1), dtype=np.intc)
    planes_array.fill(-1)
    cdef int[::1] planes = planes_array
    ctx.params = &pv[0]
    ballc_parameters_init(&ctx.prepared, &pv[0])
    ctx.latch = &lv[0]
    ctx.flags = flags
    ctx.n_states = _states(pv, n_planes)
    ctx.n_latch = _latches(n_planes)
    ctx.event_plane = &planes[0]
    margins_state = np.empty(ctx.n_states)
    cdef double[::1] margins_y = margins_state
    ctx.margins_y = &margins_y[0]
    ctx.margins_plane = -1
    users, errors = [], []
    ctx.user_events = <void *>users
    ctx.errors = <void *>errors
    cdef ballc_flags compliant = 0, sliding = 0
    cdef int p
    for p in range(n_planes):
        compliant |= ballc_flag(BALLC_KIND_COMPLIANT, p)
        sliding |= ballc_flag(BALLC_KIND_COMPLIANT_SLIDING, p)
    sol = _solve(_ball_fun, _ball_jac, &ctx, ctx.n_states, t_span, y0, rtol, atol,
                 max_step, t_eval, events, first_step, max_nfev, _ball_event, planes,
                 users, bool(dense_output), controller,
                 True,   # ballc_rhs/ballc_jacobian report non-finite outputs themselves
                 bool(refine_events), &ctx, method, (flags & compliant) != 0,
                 bool(auto_implicit), (flags & sliding) != 0)
    if errors:
        raise errors[0]
    # each system event's code at the end (a capacity guard re-armed in C has toggled)
    sol.system_events = planes_array[:len(events or ())]
    return sol


def solve_linear(A, t_span, y0, *, rtol, atol, max_step=np.inf, t_eval=None, events=(),
                 first_step=None, max_nfev=None, controller=None, refine_events=True,
                 method="radau5", dense_output=False, auto_implicit=False):
    """Integrate y' = A y (A: n x n) with radau5; same result as ``solve_system``
    (``refine_events``, ``method``, ``auto_implicit``: see there)."""
    cdef linear_ctx ctx
    A = np.ascontiguousarray(A, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or A.shape[0] == 0:
        raise ValueError(f"A must be a non-empty square matrix, got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ValueError("A must be finite")
    cdef double[:, ::1] av = A
    ctx.n = A.shape[0]
    ctx.A = &av[0, 0]
    return _solve(_linear_fun, _linear_jac, &ctx, ctx.n, t_span, y0, rtol, atol,
                  max_step, t_eval, events, first_step, max_nfev, NULL, None, None,
                  bool(dense_output), controller, False, bool(refine_events), NULL, method,
                  False, bool(auto_implicit))


def _lu_solve(A, b):
    """Solve A x = b with ballc's LU (``_lu.c``), for tests: real when A and b are
    real, complex otherwise.  Raises numpy.linalg.LinAlgError on an exactly zero pivot."""
    cdef int n, info
    cdef double[:, ::1] ar
    cdef double[::1] br
    cdef double complex[:, ::1] ac
    cdef double complex[::1] bc
    cdef int[::1] pv
    is_complex = np.iscomplexobj(A) or np.iscomplexobj(b)
    dtype = complex if is_complex else float
    A = np.array(A, dtype=dtype, order="C")   # copies: factored in place
    x = np.array(b, dtype=dtype)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or A.shape[0] == 0 or x.shape != (A.shape[0],):
        raise ValueError(f"need A (n x n, n > 0) and b (n), got {A.shape} and {x.shape}")
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(x))):
        raise ValueError("A and b must be finite")
    n = A.shape[0]
    piv = np.empty(n, dtype=np.intc)
    pv = piv
    if is_complex:
        ac = A
        bc = x
        info = ballc_lu_factor_complex(n, &ac[0, 0], &pv[0])
        if info == BALLC_LU_OK:
            ballc_lu_solve_complex(n, &ac[0, 0], &pv[0], &bc[0])
    else:
        ar = A
        br = x
        info = ballc_lu_factor(n, &ar[0, 0], &pv[0])
        if info == BALLC_LU_OK:
            ballc_lu_solve(n, &ar[0, 0], &pv[0], &br[0])
    if info != BALLC_LU_OK:
        raise np.linalg.LinAlgError(f"singular matrix: the pivot of column {info - 1} is "
                                    "exactly zero")
    return x


cdef extern from "_radau_iia.h":
    int RADAU5_N_CONSTANTS
    void radau5_constants(double *out)


def _constants():
    """radau5's method constants as its C code uses them (private; for the tests that
    compare them with scipy.integrate._ivp.radau): dict with C, E (3,), T, TI, P (3, 3),
    MU_REAL, MU_COMPLEX, TI_COMPLEX (3,), NEWTON_MAXITER, MIN_FACTOR, MAX_FACTOR."""
    values = np.empty(RADAU5_N_CONSTANTS)
    cdef double[::1] v = values
    radau5_constants(&v[0])
    return {
        "C": values[0:3].copy(), "E": values[3:6].copy(),
        "T": values[6:15].reshape(3, 3).copy(), "TI": values[15:24].reshape(3, 3).copy(),
        "P": values[24:33].reshape(3, 3).copy(), "MU_REAL": float(values[33]),
        "MU_COMPLEX": complex(values[34], values[35]),
        "TI_COMPLEX": values[36:39] + 1j * values[39:42],
        "NEWTON_MAXITER": int(values[42]), "MIN_FACTOR": float(values[43]),
        "MAX_FACTOR": float(values[44]),
    }


cdef extern from "_dop853.h":
    int DOP853_N_CONSTANTS
    void dop853_constants(double *out)


def _dop853_constants():
    """DOP853's coefficients as its C code uses them (private; for the test that compares
    them with scipy.integrate._ivp.dop853_coefficients): dict with A (16, 16), B (12,),
    C (16,), E3, E5 (13,), D (4, 16)."""
    values = np.empty(DOP853_N_CONSTANTS)
    cdef double[::1] v = values
    dop853_constants(&v[0])
    sizes = (("A", (16, 16)), ("B", (12,)), ("C", (16,)), ("E3", (13,)), ("E5", (13,)),
             ("D", (4, 16)))
    out, k = {}, 0
    for name, shape in sizes:
        size = int(np.prod(shape))
        out[name] = values[k:k + size].reshape(shape).copy()
        k += size
    return out
