# Included by _core.pyx after _radau5_bridge.pxi.  Bridge to the segment loop in C
# (``_driver.c``, ballc_drive): the constants of one run in, the run's buffers out as
# arrays.  Only converts: simulate.py decides what runs here (simulate._c_config) and
# builds the Result; _driver.c computes.

from cpython.exc cimport PyErr_CheckSignals
from libc.stdlib cimport free

cdef extern from "_driver.h":
    double ballc_py_hypot(int n, const double *values) nogil
    double ballc_py_ulp(double x) nogil
    double ballc_dot3_fma(const double *v) nogil
    enum:
        BALLC_DRIVE_OK, BALLC_DRIVE_FAILED, BALLC_DRIVE_UNSETTLED, BALLC_DRIVE_THROUGH,
        BALLC_DRIVE_FALLBACK, BALLC_DRIVE_NO_MEMORY, BALLC_DRIVE_TERMINATED,
        BALLC_DRIVE_USER_ERROR
    ctypedef struct ballc_drive_config:
        const double *params
        double rtol, atol
        double t_end, max_step, first_step
        int has_first_step
        long max_nfev
        int method, controller
        ballc_flags observer_bits
        ballc_flags contact_bits[6]
        int exact
        double radius, weight, hertz_k, total_mass, rest_period
        int resting_plane, checks_rest
        const double *t_eval
        long n_eval
        int dense_output
        int exact_flight
        int n_user
        const double *user_coef
        const double *user_offset
        const double *user_scale
        const int *user_linear
        const int *user_index
        const int *user_count
        const int *user_direction
        int user_flight
        int (*user_fun)(void *, int, double, const double *, double *) noexcept nogil
        void *user_ctx
        int (*interrupted)(void *) noexcept nogil
        int compliant_modes
        int starts_armed
        double arm_force_depth
        double restick_factor
        int damping_positive
        double contact_time_base
        int observer_massive, rolls_allowed, orbit_applies
        double rest_threshold, rho_eq, z_eq, rest_weight, observer_weight
        double rolls_dv, rolls_level, half_mass
        double orbit_axis[3]
        double rest_factor
        int (*integrate)(void *, const radau5_problem *, ballc_segment *,
                         radau5_result *) noexcept nogil
        void *integrate_ctx
        int (*interpolant)(void *, long, long, const double *, double *) noexcept nogil
        const double *atol_states
        int (*progress)(void *, double) noexcept nogil
        double poll_interval
        const int *user_rearm
        int (*rearm_fun)(void *, int, double, const double *, double *, double *,
                         double *) noexcept nogil
        int rolling, twisting
    ctypedef struct ballc_contact_rec:
        int plane, ended, passed_through, rate_is_kernel_value
        double t_start, t_end
        double v_before[3]
        double w_before[3]
        double v_after[3]
        double w_after[3]
        double rate
        double digin[3]
        double max_penetration
        double contact_point[3]
        double lost[2]
    ctypedef struct ballc_phase_rec:
        long contact
        double t
        int phase
    ctypedef struct ballc_piece_rec:
        double t0, t1
        long step0, n_steps, coef0
        int terms
        int flight
        double y0[46]
        int own
        long interpolant
    enum: BALLC_N_PLANE_MODES, BALLC_N_SEGMENT_ENDS
    const char *ballc_plane_mode_names[]
    const char *ballc_segment_end_names[]
    ctypedef struct ballc_segment_rec:
        double t_start, t_end
        long nfev, njev, nlu, nstep, nreject
        int method, method_end, switches, end, plane, rearms
        signed char before[6]
        signed char after[6]
        signed char rearm_kind, rearm_plane, rearm_before, rearm_after
        signed char rolling_before[6]
        signed char rolling_after[6]
        signed char twisting_before[6]
        signed char twisting_after[6]
    ctypedef struct ballc_drive_output:
        int n_planes, n_states, n_latch
        long n
        double *t
        double *y
        long n_blocks
        long *block_count
        ballc_flags *block_flags
        double *block_latch
        long n_contacts
        ballc_contact_rec *contacts
        long n_phases
        ballc_phase_rec *phases
        int open[6]
        long n_user_hits
        int *user_hit_event
        double *user_hit_t
        double *user_hit_y
        long n_switches
        double *switch_t
        int *switch_to
        long n_pieces
        ballc_piece_rec *pieces
        long n_steps, n_coef
        double *dense_t
        double *dense_c
        int *dense_kind
        int stop_code, status, stop_plane
        double t_run, fail_end
        int in_contact[6]
        long transitions[6]
        long stalled
        int unsettled_compliant
        long nfev, njev, nlu
        double stiff_at
        char message[240]
        long segments
        int end_kind, end_plane
        double end_t
        double end_y[46]
        double end_acceleration[3]
        int profiled
        double integrator_ns, drive_ns
        int end_orbit
        ballc_orbit orbit
        ballc_dense orbit_base
        long n_trials
        double *trials
        long n_log
        ballc_segment_rec *log
        double integrator_prof[7]
    int ballc_drive(const ballc_drive_config *, const double *, ballc_drive_output *) nogil
    void ballc_drive_free(ballc_drive_output *) nogil


DRIVE_OK, DRIVE_FAILED, DRIVE_UNSETTLED, DRIVE_THROUGH, DRIVE_TERMINATED = (
    BALLC_DRIVE_OK, BALLC_DRIVE_FAILED, BALLC_DRIVE_UNSETTLED, BALLC_DRIVE_THROUGH,
    BALLC_DRIVE_TERMINATED)


#: The names of the segment log's codes (_driver.c): a plane's mode (ballc.automaton.MODES),
#: why a segment ended (the automaton's event kinds, then t_end, the checks, ...), and the
#: integrator (-1: an exact flight, -2: one of scipy's methods, the run's).
PLANE_MODES = tuple(ballc_plane_mode_names[i].decode() for i in range(BALLC_N_PLANE_MODES))
SEGMENT_ENDS = tuple(ballc_segment_end_names[i].decode()
                     for i in range(BALLC_N_SEGMENT_ENDS))
SEGMENT_METHODS = {BALLC_METHOD_SCIPY: "scipy", -1: "flight", RADAU5_METHOD_RADAU: "radau5",
                   RADAU5_METHOD_DOP853: "dop853"}


cdef object _segment_record():
    """The numpy dtype of _driver.h's ballc_segment_rec, at the offsets C gives it."""
    cdef ballc_segment_rec g
    cdef char *at = <char *>&g
    offsets = [<char *>&g.t_start - at, <char *>&g.t_end - at, <char *>&g.nfev - at,
               <char *>&g.njev - at, <char *>&g.nlu - at, <char *>&g.nstep - at,
               <char *>&g.nreject - at, <char *>&g.method - at,
               <char *>&g.method_end - at, <char *>&g.switches - at, <char *>&g.end - at,
               <char *>&g.plane - at, <char *>&g.rearms - at, <char *>&g.before[0] - at,
               <char *>&g.after[0] - at, <char *>&g.rearm_kind - at,
               <char *>&g.rearm_plane - at, <char *>&g.rearm_before - at,
               <char *>&g.rearm_after - at, <char *>&g.rolling_before[0] - at,
               <char *>&g.rolling_after[0] - at, <char *>&g.twisting_before[0] - at,
               <char *>&g.twisting_after[0] - at]
    fields = [("t_start", "f8"), ("t_end", "f8"), ("nfev", "l"), ("njev", "l"), ("nlu", "l"),
              ("nstep", "l"), ("nreject", "l"), ("method", "intc"), ("method_end", "intc"), ("switches", "intc"),
              ("end", "intc"), ("plane", "intc"), ("rearms", "intc"),
              ("before", ("i1", (BALLC_MAX_PLANES,))), ("after", ("i1", (BALLC_MAX_PLANES,))),
              ("rearm_kind", "i1"),
              ("rearm_plane", "i1"), ("rearm_before", "i1"), ("rearm_after", "i1"),
              ("rolling_before", ("i1", (BALLC_MAX_PLANES,))),
              ("rolling_after", ("i1", (BALLC_MAX_PLANES,))),
              ("twisting_before", ("i1", (BALLC_MAX_PLANES,))),
              ("twisting_after", ("i1", (BALLC_MAX_PLANES,)))]
    return np.dtype(dict(names=[f[0] for f in fields], formats=[f[1] for f in fields],
                         offsets=offsets, itemsize=sizeof(ballc_segment_rec)))


#: ballc_segment_rec as a numpy record (drive's "segment_log": bytes of these)
SEGMENT_RECORD = _segment_record()


cdef int _check_signals() except -1:
    return PyErr_CheckSignals()


cdef int _drive_interrupted(void *ctx) noexcept nogil:
    """Before each segment: a pending signal's exception (Ctrl-C: KeyboardInterrupt) is
    kept with the user events' exceptions (ctx[1]) for drive to raise, and the run
    stops (the Python driver could be interrupted between segments: so can this)."""
    with gil:
        try:
            _check_signals()
        except BaseException as error:
            (<list>ctx)[1].append(error)
            return 1
    return 0


cdef int _drive_progress(void *ctx, double t) noexcept nogil:
    """The progress bar (ctx[3], a tqdm) to the simulated time t; called from C at most
    every poll_interval s of wall time.  An exception is kept and the run stops."""
    with gil:
        try:
            bar = (<list>ctx)[3]
            bar.update(t - bar.n)
        except BaseException as error:
            (<list>ctx)[1].append(error)
            return 1
    return 0


cdef int _drive_user_rearm(void *ctx, int k, double t, const double *y, double *coef,
                           double *offset, double *latch) noexcept nogil:
    """The ``rearm`` of the user's LinearEvent k (ctx[2][k]) at (t, y), as the radau5
    bridge's _rearm_event calls it: 0 when it declines (None), 1 with the event's new
    coefficients, offset and the latch written, -1 when it raised (kept for drive)."""
    cdef double[::1] yv
    cdef const double[::1] cv, lv
    cdef double off
    cdef int width, n_latch
    with gil:
        errors = (<list>ctx)[1]
        if errors:
            return -1
        try:
            width, n_latch = (<list>ctx)[4]
            state = np.empty(width)
            yv = state
            memcpy(&yv[0], y, width * sizeof(double))
            out = (<list>ctx)[2][k](t, state)
            if out is None:
                return 0
            coefficients, new_offset, new_latch = out
            cv = _checked_row("rearm coefficients", coefficients, width)
            lv = _checked_row("rearm latch", new_latch, n_latch)
            off = float(new_offset)
            if not isfinite(off):
                raise ValueError(f"rearm offset = {new_offset!r} is not allowed: must be "
                                 "finite")
            memcpy(coef, &cv[0], width * sizeof(double))
            memcpy(latch, &lv[0], n_latch * sizeof(double))
            offset[0] = off
            return 1
        except BaseException as error:
            errors.append(error)
            return -1


cdef int _drive_user_event(void *ctx, int k, double t, const double *y,
                           double *g) noexcept nogil:
    """The user's callable event k at (t, y), as the radau5 bridge's _user_event calls
    it: ctx is [the events (simulate's CheckedEvent), the exceptions kept]; an exception
    is kept for drive to raise and the event reads as NaN meanwhile."""
    cdef double[::1] yv
    cdef int width
    with gil:
        events, errors = (<list>ctx)[0], (<list>ctx)[1]
        if errors:
            g[0] = NAN
            return -1
        try:
            width = (<list>ctx)[4][0]
            state = np.empty(width)
            yv = state
            memcpy(&yv[0], y, width * sizeof(double))
            g[0] = float(events[k](t, state))
            return 0
        except BaseException as error:
            errors.append(error)
            g[0] = NAN
            return -1


def _py_hypot(values):
    """The C port of math.hypot (tests)."""
    cdef double v[8]
    cdef int i, n = len(values)
    if n > 8:
        raise ValueError("at most 8 values")
    for i in range(n):
        v[i] = values[i]
    return ballc_py_hypot(n, v)


def _py_ulp(double x):
    """The C port of math.ulp (tests)."""
    return ballc_py_ulp(x)


def _dot3_fma(const double[::1] v):
    """The C helper that reproduces numpy's float64 v.dot(v) of length 3 (tests)."""
    return ballc_dot3_fma(&v[0])


def _dot3_fma_many(const double[:, ::1] v):
    """_dot3_fma per row (tests)."""
    out = np.empty(v.shape[0])
    cdef double[::1] o = out
    cdef Py_ssize_t i
    for i in range(v.shape[0]):
        o[i] = ballc_dot3_fma(&v[i, 0])
    return out


def _hypot_many(const double[:, ::1] v):
    """_py_hypot per row (tests)."""
    out = np.empty(v.shape[0])
    cdef double[::1] o = out
    cdef Py_ssize_t i
    for i in range(v.shape[0]):
        o[i] = ballc_py_hypot(<int>v.shape[1], &v[i, 0])
    return out


def drive(const double[::1] params, const double[::1] y0, dict k, progress=None):
    """Run the segment loop in C with the constants ``k`` (simulate._c_config), each
    segment integrated by ``k["method"]``: a compiled one, or one of scipy's (through
    _scipy_integrate).  ``progress``: None, or a tqdm bar advanced to the simulated time
    (at most every ``k["poll_interval"]`` s of wall time, default 0.1).
    Returns None when the run needs the Python driver (nothing of it is kept), else a
    dict of the run's samples, contacts, phases and end."""
    cdef ballc_drive_config c
    cdef ballc_drive_output o
    cdef int p, row, j, rc
    cdef double[::1] tv
    cdef double[:, ::1] rv, lv
    cdef ballc_contact_rec rec
    cdef Py_ssize_t i
    cdef const double[::1] t_eval = k["t_eval"]   # None: no t_eval
    cdef const double[:, ::1] ucoef = k["user_coef"]
    cdef const double[::1] uoffset = k["user_offset"], uscale = k["user_scale"]
    cdef const int[::1] ulinear = k["user_linear"], uindex = k["user_index"]
    cdef const int[::1] ucount = k["user_count"], udirection = k["user_direction"]
    cdef int n_planes = _planes_of(params)
    cdef int width = _states(params, n_planes), n_latch = _latches(n_planes)
    cdef list user_ctx = [k["user_events"], [], k["user_rearms"], progress, (width, n_latch)]
    cdef const int[::1] urearm = k["user_rearm"]
    cdef const double[::1] atol_states = k["atol_states"]   # None: one atol
    cdef _ScipyRun scipy_run = None
    cdef ballc_piece_rec piece
    cdef double[:, ::1] dtv, dcv
    cdef int[::1] dkv
    _check("y0", y0.shape[0], width)
    if ucoef.shape[0] and ucoef.shape[1] != width:
        raise ValueError(f"user_coef must have {width} columns, got {ucoef.shape[1]}")
    c.params = &params[0]
    c.rtol = k["rtol"]
    c.atol = k["atol"]
    c.t_end = k["t_end"]
    c.max_step = k["max_step"]
    c.has_first_step = k["first_step"] is not None
    c.first_step = k["first_step"] if c.has_first_step else 0.0
    c.max_nfev = 0 if k["max_nfev"] is None else k["max_nfev"]
    c.integrate = NULL   # the compiled integrators (radau5_solve)
    c.integrate_ctx = NULL
    c.interpolant = NULL
    if k["scipy"]:   # one of scipy's methods, called back segment by segment
        scipy_run = _ScipyRun(k["method"], k["scipy_atol"], np.asarray(params), user_ctx[1])
        c.method = BALLC_METHOD_SCIPY
        c.integrate = _scipy_integrate
        c.integrate_ctx = <void *>scipy_run
        c.interpolant = _scipy_interpolant
    else:
        c.method = _method_code(k["method"])
    c.atol_states = NULL
    if atol_states is not None:
        c.atol_states = &atol_states[0]
    c.progress = NULL
    if progress is not None:
        c.progress = _drive_progress
    c.poll_interval = k.get("poll_interval", 0.1)
    c.rearm_fun = _drive_user_rearm
    c.controller = _controller[0]
    c.observer_bits = k["observer_bits"]
    c.exact = k["exact"]
    c.radius = k["radius"]
    c.weight = k["weight"]
    c.hertz_k = k["hertz_k"]
    c.total_mass = k["total_mass"]
    c.rest_period = k["rest_period"]
    c.resting_plane = k["resting_plane"]
    c.checks_rest = k["checks_rest"]
    c.t_eval = NULL
    c.n_eval = 0
    if t_eval is not None:
        c.n_eval = t_eval.shape[0]
        c.t_eval = &t_eval[0] if c.n_eval else &y0[0]   # non-NULL: t_eval given
    c.dense_output = k["dense_output"]
    c.exact_flight = k["exact_flight"]
    c.n_user = ucount.shape[0]
    c.user_flight = k["user_flight"]
    c.user_fun = _drive_user_event
    c.user_ctx = <void *>user_ctx
    c.interrupted = _drive_interrupted
    c.user_coef = c.user_offset = c.user_scale = NULL
    c.user_linear = c.user_index = c.user_count = c.user_direction = NULL
    c.user_rearm = NULL
    if c.n_user:
        c.user_rearm = &urearm[0]
        c.user_coef = &ucoef[0, 0]
        c.user_offset = &uoffset[0]
        c.user_scale = &uscale[0]
        c.user_linear = &ulinear[0]
        c.user_index = &uindex[0]
        c.user_count = &ucount[0]
        c.user_direction = &udirection[0]
    c.rolling = k["rolling"]
    c.twisting = k["twisting"]
    c.compliant_modes = k["compliant_modes"]
    c.starts_armed = k["starts_armed"]
    c.arm_force_depth = k["arm_force_depth"]
    c.restick_factor = k["restick_factor"]
    c.damping_positive = k["damping_positive"]
    c.contact_time_base = k["contact_time_base"]
    c.observer_massive = k["observer_massive"]
    c.rolls_allowed = k["rolls_allowed"]
    c.orbit_applies = k["orbit_applies"]
    c.rest_threshold = k["rest_threshold"]
    c.rho_eq = k["rho_eq"]
    c.z_eq = k["z_eq"]
    c.rest_weight = k["rest_weight"]
    c.observer_weight = k["observer_weight"]
    c.rolls_dv = k["rolls_dv"]
    c.rolls_level = k["rolls_level"]
    c.half_mass = k["half_mass"]
    for j in range(3):
        c.orbit_axis[j] = k["orbit_axis"][j]
    c.rest_factor = k["rest_factor"]
    for p in range(BALLC_MAX_PLANES):
        c.contact_bits[p] = k["contact_bits"][p] if p < n_planes else 0
    with nogil:
        rc = ballc_drive(&c, &y0[0], &o)
    try:
        if rc == BALLC_DRIVE_NO_MEMORY:
            raise MemoryError("ballc_drive: out of memory")
        if rc == BALLC_DRIVE_FALLBACK:
            return None
        if rc == BALLC_DRIVE_USER_ERROR:   # as solve_system: the user's exception
            raise user_ctx[1][0]
        user_event = np.array([o.user_hit_event[i] for i in range(o.n_user_hits)],
                              dtype=np.intc)
        user_t = np.array([o.user_hit_t[i] for i in range(o.n_user_hits)], dtype=float)
        user_y = np.empty((o.n_user_hits, width))
        if o.n_user_hits:
            rv = user_y
            memcpy(&rv[0, 0], o.user_hit_y, o.n_user_hits * width * sizeof(double))
        n = o.n
        t = np.empty(n)
        rows = np.empty((n, width))
        if n:
            tv = t
            rv = rows
            memcpy(&tv[0], o.t, n * sizeof(double))
            memcpy(&rv[0, 0], o.y, n * width * sizeof(double))
        counts = np.array([o.block_count[i] for i in range(o.n_blocks)], dtype=np.intp)
        block_flags = np.array([o.block_flags[i] for i in range(o.n_blocks)], dtype=np.int64)
        latches = np.empty((o.n_blocks, n_latch))
        if o.n_blocks:
            lv = latches
            memcpy(&lv[0, 0], o.block_latch, o.n_blocks * n_latch * sizeof(double))
        contacts = []
        for i in range(o.n_contacts):
            rec = o.contacts[i]
            contacts.append(dict(
                plane=rec.plane, ended=rec.ended, passed_through=rec.passed_through,
                rate_is_kernel_value=rec.rate_is_kernel_value,
                t_start=rec.t_start, t_end=rec.t_end,
                v_before=[rec.v_before[j] for j in range(3)],
                w_before=[rec.w_before[j] for j in range(3)],
                v_after=[rec.v_after[j] for j in range(3)],
                w_after=[rec.w_after[j] for j in range(3)],
                rate=rec.rate, digin=[rec.digin[j] for j in range(3)],
                max_penetration=rec.max_penetration,
                contact_point=[rec.contact_point[0], rec.contact_point[1],
                               rec.contact_point[2]],
                lost=(rec.lost[0], rec.lost[1])))
        phases = [(o.phases[i].contact, o.phases[i].t, o.phases[i].phase)
                  for i in range(o.n_phases)]
        # the segment log, the bytes C wrote (SEGMENT_RECORD each): read when asked for
        segments = (<char *>o.log)[:o.n_log * sizeof(ballc_segment_rec)] if o.n_log else b""
        pieces = []   # dense output: (t0, t1, dense_t, dense_c, terms, dense_kind), or
        for i in range(o.n_pieces):   # (t0, t1, y0) of an exact flight
            piece = o.pieces[i]
            if piece.own:   # the integrator's own interpolant (scipy's OdeSolution)
                pieces.append((piece.t0, piece.t1, scipy_run.interpolants[piece.interpolant]))
                continue
            if piece.flight:
                pieces.append((piece.t0, piece.t1,
                               np.array([piece.y0[j] for j in range(width)])))
                continue
            dense_t = np.empty((piece.n_steps, 2))
            dense_c = np.empty((piece.n_steps, (1 + piece.terms) * width))
            dense_kind = np.empty(piece.n_steps, dtype=np.intc)
            if piece.n_steps:
                dtv = dense_t
                dcv = dense_c
                dkv = dense_kind
                memcpy(&dtv[0, 0], o.dense_t + 2 * piece.step0,
                       piece.n_steps * 2 * sizeof(double))
                memcpy(&dcv[0, 0], o.dense_c + piece.coef0,
                       piece.n_steps * (1 + piece.terms) * width * sizeof(double))
                memcpy(&dkv[0], o.dense_kind + piece.step0, piece.n_steps * sizeof(int))
            pieces.append((piece.t0, piece.t1, dense_t, dense_c, piece.terms, dense_kind))
        orbit = None   # ballc.orbit's end: (c0, period, G, rate) and its base's pieces
        if o.end_orbit:
            orbit = (o.orbit.c0, o.orbit.period, _motion_tuple(&o.orbit.g), o.orbit.rate,
                     _dense_pieces(&o.orbit_base))
        return dict(orbit=orbit,
                    trials=[(o.trials[3 * i], o.trials[3 * i + 1], bool(o.trials[3 * i + 2]))
                            for i in range(o.n_trials)],
                    t=t, rows=rows, counts=counts, block_flags=block_flags, latches=latches,
                    contacts=contacts, phases=phases, pieces=pieces,
                    user_hits=(user_event, user_t, user_y),
                    switches=[(o.switch_t[i], _METHOD_NAMES[o.switch_to[i]])
                              for i in range(o.n_switches)],
                    open=tuple(o.open[p] for p in range(n_planes)),
                    stop_code=o.stop_code, status=o.status, stop_plane=o.stop_plane,
                    t_run=o.t_run, fail_end=o.fail_end, message=o.message.decode(),
                    in_contact=tuple(bool(o.in_contact[p]) for p in range(n_planes)),
                    transitions=tuple(o.transitions[p] for p in range(n_planes)),
                    stalled=o.stalled,
                    unsettled_compliant=bool(o.unsettled_compliant),
                    nfev=o.nfev, njev=o.njev, nlu=o.nlu, stiff_at=o.stiff_at,
                    segments=o.segments, end_kind=o.end_kind, end_plane=o.end_plane,
                    end_t=o.end_t, end_y=np.array([o.end_y[j] for j in range(width)]),
                    end_acceleration=np.array([o.end_acceleration[j] for j in range(3)]),
                    profiled=bool(o.profiled), segment_log=segments,
                    integrator_prof=dict(zip(("fun", "jac", "factor", "solve", "events",
                                              "total", "total_ns"),
                                             [o.integrator_prof[j] for j in range(7)]))
                    if o.profiled else None,
                    integrator_ns=o.integrator_ns, drive_ns=o.drive_ns)
    finally:
        ballc_drive_free(&o)


cdef list _dense_pieces(const ballc_dense *d):
    """The pieces of a C buffer of interpolants: [(t0, t1, dense_t, dense_c, terms,
    dense_kind)], as dense.CompiledInterpolant takes them."""
    cdef list pieces = []
    cdef Py_ssize_t k
    cdef long coef = 0, m, width
    cdef double[:, ::1] dtv, dcv
    cdef int[::1] dkv
    for k in range(d.n_pieces):
        m = d.n_steps[k]
        width = (1 + d.terms[k]) * d.width
        dense_t = np.empty((m, 2))
        dense_c = np.empty((m, width))
        dense_kind = np.empty(m, dtype=np.intc)
        if m:
            dtv = dense_t
            dcv = dense_c
            dkv = dense_kind
            memcpy(&dtv[0, 0], d.steps + 2 * d.step0[k], m * 2 * sizeof(double))
            memcpy(&dcv[0, 0], d.coef + coef, m * width * sizeof(double))
            memcpy(&dkv[0], d.kinds + d.step0[k], m * sizeof(int))
        coef += m * width
        pieces.append((d.t0[k], d.t1[k], dense_t, dense_c, d.terms[k], dense_kind))
    return pieces
