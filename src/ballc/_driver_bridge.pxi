# Included by _core.pyx after _radau5_bridge.pxi.  Bridge to the segment loop in C
# (``_driver.c``, ballc_drive), the one driver of ballc.simulate: the scene's constants
# (converted once per scene: DriveScene) and the run's in, the run's buffers out (Drive,
# read on demand).  Only converts: ballc.loop_constants computes the constants,
# ballc.loop_result builds the Result; _driver.c computes.

from cpython.exc cimport PyErr_CheckSignals
from libc.stdlib cimport free

cdef extern from "_driver.h":
    double BALLC_CLEAR_FACTOR, BALLC_PASS_FACTOR, BALLC_STOP_FACTOR, BALLC_APPROACH_FRACTION
    double BALLC_MIN_IMPACT_RATE, BALLC_CHECK_GROWTH, BALLC_FLIGHT_MAX_TURN, BALLC_ARM_ULPS
    long BALLC_FLIGHT_MAX_SAMPLES
    int BALLC_MAX_RELATCH, BALLC_MAX_TRANSITIONS, BALLC_MAX_STALLED
    int BALLC_STEPS_PER_CONTACT, BALLC_IMPACT_SPAN, BALLC_FLIGHT_MIN_INTERVALS
    int BALLC_MAX_ROLL_SAMPLES
    ctypedef struct ballc_flight:
        double t0, rate
    void ballc_flight_init(ballc_flight *, double, const double *, const double *, int) nogil
    void ballc_flight_at(const ballc_flight *, double, double *) nogil
    ctypedef struct ballc_rolling:
        double t0, w0, spin_rate
    void ballc_rolling_init(ballc_rolling *, double, const double *, const double *, double,
                            const double *, int) nogil
    void ballc_rolling_at(const ballc_rolling *, double, double *) nogil
    double ballc_rolling_angle(const ballc_rolling *, double) nogil
    int ballc_flight_crossings(double, double, double, int, double, double *) nogil
    enum:
        BALLC_DRIVE_OK, BALLC_DRIVE_FAILED, BALLC_DRIVE_UNSETTLED, BALLC_DRIVE_THROUGH,
        BALLC_DRIVE_ABORTED, BALLC_DRIVE_NO_MEMORY, BALLC_DRIVE_TERMINATED,
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


DRIVE_OK, DRIVE_FAILED, DRIVE_UNSETTLED, DRIVE_THROUGH, DRIVE_TERMINATED, DRIVE_ABORTED = (
    BALLC_DRIVE_OK, BALLC_DRIVE_FAILED, BALLC_DRIVE_UNSETTLED, BALLC_DRIVE_THROUGH,
    BALLC_DRIVE_TERMINATED, BALLC_DRIVE_ABORTED)

#: The automaton's constants, from _driver.h (ballc.stickslip, compliantmodes, resting,
#: flight and modes name them)
CLEAR_FACTOR, PASS_FACTOR, STOP_FACTOR = BALLC_CLEAR_FACTOR, BALLC_PASS_FACTOR, BALLC_STOP_FACTOR
APPROACH_FRACTION, MAX_RELATCH = BALLC_APPROACH_FRACTION, BALLC_MAX_RELATCH
MAX_TRANSITIONS, MAX_STALLED = BALLC_MAX_TRANSITIONS, BALLC_MAX_STALLED
MIN_IMPACT_RATE = BALLC_MIN_IMPACT_RATE
STEPS_PER_CONTACT, IMPACT_SPAN = BALLC_STEPS_PER_CONTACT, BALLC_IMPACT_SPAN
CHECK_GROWTH = BALLC_CHECK_GROWTH
FLIGHT_MIN_INTERVALS, FLIGHT_MAX_TURN = BALLC_FLIGHT_MIN_INTERVALS, BALLC_FLIGHT_MAX_TURN
FLIGHT_MAX_SAMPLES, MAX_ROLL_SAMPLES = BALLC_FLIGHT_MAX_SAMPLES, BALLC_MAX_ROLL_SAMPLES
ARM_ULPS = BALLC_ARM_ULPS
#: A contact's phases in Drive.phases(): slip, stick, then its closed-form end state
PHASE_NAMES = ("slip", "stick", "rest", "rolling", "free_sliding")


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
    stops."""
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
            width, n_latch = (<list>ctx)[4]   # the run's states and latched values
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


cdef int _state_width(const double[::1] y0) except -1:
    """The length of a state (a scene's: the ball's states and 2 per plane, then with
    rolling resistance its ball state and 3 per plane), checked."""
    cdef Py_ssize_t n = y0.shape[0]
    cdef int planes
    for planes in range(1, BALLC_MAX_PLANES + 1):
        if n == _ball_and_plane_states(planes) or n == (
                _ball_and_plane_states(planes) + BALLC_N_ROLLING_BALL_STATES
                + BALLC_N_ROLLING_PLANE_STATES * planes):
            return <int>n
    raise ValueError(f"y0 must have {BALLC_N_BALL_STATES} + {BALLC_N_PLANE_STATES} per plane "
                     f"values, and with rolling resistance {BALLC_N_ROLLING_BALL_STATES} + "
                     f"{BALLC_N_ROLLING_PLANE_STATES} per plane more (1 to "
                     f"{BALLC_MAX_PLANES} planes), got {n}")


def flight_states(double t0, const double[::1] y0, const double[::1] gravity, t):
    """The exact free flight from (t0, y0) (a scene's state) under ``gravity`` (the
    acceleration vector, m/s^2) at the times t (_driver.c's ballc_flight): (states,) for a
    scalar t, (states, len(t)) for a 1-D array."""
    cdef ballc_flight f
    cdef Py_ssize_t i
    cdef int n = _state_width(y0)
    _check("gravity", gravity.shape[0], 3)
    times = np.asarray(t, dtype=float)
    cdef const double[::1] tv = np.ascontiguousarray(times.ravel())
    out = np.empty((tv.shape[0], n))
    cdef double[:, ::1] o = out
    ballc_flight_init(&f, t0, &y0[0], &gravity[0], n)
    for i in range(tv.shape[0]):
        ballc_flight_at(&f, tv[i], &o[i, 0])
    return out[0] if times.ndim == 0 else out.T


def rolling_states(double t0, const double[::1] y0, const double[::1] acceleration,
                   double radius, const double[::1] normal, t):
    """Rolling down an unbounded incline from (t0, y0), its centre's ``acceleration``
    (m/s^2) along the plane of unit ``normal`` (_driver.c's ballc_rolling, the end state
    ACCELERATING), at the times t: (states,) for a scalar t, (states, len(t)) for a 1-D
    array."""
    cdef ballc_rolling f
    cdef Py_ssize_t i
    cdef int n = _state_width(y0)
    _check("acceleration", acceleration.shape[0], 3)
    _check("normal", normal.shape[0], 3)
    times = np.asarray(t, dtype=float)
    cdef const double[::1] tv = np.ascontiguousarray(times.ravel())
    out = np.empty((tv.shape[0], n))
    cdef double[:, ::1] o = out
    ballc_rolling_init(&f, t0, &y0[0], &acceleration[0], radius, &normal[0], n)
    for i in range(tv.shape[0]):
        ballc_rolling_at(&f, tv[i], &o[i, 0])
    return out[0] if times.ndim == 0 else out.T


def rolling_angle(double t0, const double[::1] y0, const double[::1] acceleration,
                  double radius, const double[::1] normal, double t):
    """The turn (rad) about its fixed axis of the rolling of :func:`rolling_states` by t."""
    cdef ballc_rolling f
    cdef int n = _state_width(y0)
    _check("acceleration", acceleration.shape[0], 3)
    _check("normal", normal.shape[0], 3)
    ballc_rolling_init(&f, t0, &y0[0], &acceleration[0], radius, &normal[0], n)
    return ballc_rolling_angle(&f, t)


def flight_crossings(double c0, double c1, double c2, int direction, double s_max):
    """The roots of c0 + c1 s + c2 s^2 in [0, s_max] where it changes sign in
    ``direction``, increasing (_driver.c's, which locates an exact flight's events)."""
    cdef double out[2]
    cdef int n = ballc_flight_crossings(c0, c1, c2, direction, s_max, out)
    return [out[i] for i in range(n)]


cdef class DriveScene:
    """The constants of the C loop that depend on the scene alone (ballc_drive_config's
    scene part), converted once from ``k`` (ballc.loop_constants); ``params`` (the
    parameter vector, its plane table included) is kept for the runs, with the run's
    ``n_planes``, ``n_states`` and ``n_latch`` it sets, ``python`` for Python's own."""
    cdef ballc_drive_config c
    cdef readonly object params
    cdef readonly int n_planes, n_states, n_latch
    cdef public dict python   # what Python keeps of the scene's constants (loop_constants)

    def __init__(self, params, dict k):
        cdef int p, j
        cdef const double[::1] pv
        self.params = np.array(params, dtype=float)
        self.params.flags.writeable = False
        self.python = {}
        pv = self.params
        self.n_planes = _planes_of(pv)   # checks the parameters' length and plane table
        self.n_states, self.n_latch = _states(pv, self.n_planes), _latches(self.n_planes)
        memset(&self.c, 0, sizeof(ballc_drive_config))
        self.c.params = &pv[0]
        self.c.observer_bits = k["observer_bits"]
        self.c.exact = k["exact"]
        self.c.radius = k["radius"]
        self.c.weight = k["weight"]
        self.c.hertz_k = k["hertz_k"]
        self.c.total_mass = k["total_mass"]
        self.c.rest_period = k["rest_period"]
        self.c.resting_plane = k["resting_plane"]
        self.c.rolling = k["rolling"]
        self.c.twisting = k["twisting"]
        self.c.compliant_modes = k["compliant_modes"]
        self.c.starts_armed = k["starts_armed"]
        self.c.arm_force_depth = k["arm_force_depth"]
        self.c.restick_factor = k["restick_factor"]
        self.c.damping_positive = k["damping_positive"]
        self.c.contact_time_base = k["contact_time_base"]
        self.c.observer_massive = k["observer_massive"]
        self.c.rolls_allowed = k["rolls_allowed"]
        self.c.orbit_applies = k["orbit_applies"]
        self.c.rho_eq = k["rho_eq"]
        self.c.z_eq = k["z_eq"]
        self.c.rest_weight = k["rest_weight"]
        self.c.observer_weight = k["observer_weight"]
        self.c.rolls_level = k["rolls_level"]
        self.c.half_mass = k["half_mass"]
        self.c.rest_factor = k["rest_factor"]
        for j in range(3):
            self.c.orbit_axis[j] = k["orbit_axis"][j]
        _check("contact_bits", len(k["contact_bits"]), self.n_planes)
        for p in range(self.n_planes):
            self.c.contact_bits[p] = k["contact_bits"][p]


def drive(DriveScene scene, const double[::1] y0, dict k, progress=None):
    """Run the segment loop in C for ``scene``'s constants and the run's ``k``
    (ballc.loop_constants.run_constants), each segment integrated by ``k["method"]``: a
    compiled one, or one of scipy's (through _scipy_integrate).  ``progress``: None, or a
    tqdm bar advanced to the simulated time (at most every ``k["poll_interval"]`` s of
    wall time).  Returns the run (a Drive); raises what a user's event, an integrator
    or Ctrl-C raised."""
    cdef ballc_drive_config c = scene.c   # the scene's part, copied; the run's below
    cdef Drive run = Drive.__new__(Drive)
    cdef int rc
    cdef const double[::1] t_eval = k["t_eval"]   # None: no t_eval
    cdef const double[:, ::1] ucoef
    cdef const double[::1] uoffset, uscale
    cdef const int[::1] ulinear, uindex, ucount, udirection, urearm
    cdef const double[::1] atol_states = k["atol_states"]   # None: one atol
    users = k["users"]   # None: no user events
    cdef int width = scene.n_states
    cdef list user_ctx = [users["user_events"] if users else None, [],
                          users["user_rearms"] if users else None, progress,
                          (width, scene.n_latch)]
    _check("y0", y0.shape[0], width)
    c.rtol = k["rtol"]
    c.atol = k["atol"]
    c.t_end = k["t_end"]
    c.max_step = k["max_step"]
    first_step = k["first_step"]
    c.has_first_step = first_step is not None
    c.first_step = first_step if c.has_first_step else 0.0
    max_nfev = k["max_nfev"]
    c.max_nfev = 0 if max_nfev is None else max_nfev
    c.integrate = NULL   # the compiled integrators (radau5_solve)
    c.integrate_ctx = NULL
    c.interpolant = NULL
    if k["scipy"]:   # one of scipy's methods, called back segment by segment
        run.scipy_run = _ScipyRun(k["method"], k["scipy_atol"], scene.params, user_ctx[1])
        c.method = BALLC_METHOD_SCIPY
        c.integrate = _scipy_integrate
        c.integrate_ctx = <void *>run.scipy_run
        c.interpolant = _scipy_interpolant
    else:
        c.method = _method_code(k["method"])
    c.atol_states = NULL
    if atol_states is not None:
        c.atol_states = &atol_states[0]
    c.progress = NULL
    if progress is not None:
        c.progress = _drive_progress
    c.poll_interval = k["poll_interval"]
    c.rearm_fun = _drive_user_rearm
    c.controller = _controller[0]
    c.checks_rest = k["checks_rest"]
    c.rest_threshold = k["rest_threshold"]
    c.rolls_dv = k["rolls_dv"]
    c.t_eval = NULL
    c.n_eval = 0
    if t_eval is not None:
        c.n_eval = t_eval.shape[0]
        c.t_eval = &t_eval[0] if c.n_eval else &y0[0]   # non-NULL: t_eval given
    c.dense_output = k["dense_output"]
    c.exact_flight = k["exact_flight"]
    c.user_fun = _drive_user_event
    c.user_ctx = <void *>user_ctx
    c.interrupted = _drive_interrupted
    c.n_user = 0
    c.user_flight = 1
    c.user_coef = c.user_offset = c.user_scale = NULL
    c.user_linear = c.user_index = c.user_count = c.user_direction = NULL
    c.user_rearm = NULL
    if users:
        ucoef = users["user_coef"]
        _check("user_coef's columns", ucoef.shape[1], width)
        uoffset = users["user_offset"]
        uscale = users["user_scale"]
        ulinear = users["user_linear"]
        uindex = users["user_index"]
        ucount = users["user_count"]
        udirection = users["user_direction"]
        urearm = users["user_rearm"]
        c.n_user = ucount.shape[0]
        c.user_flight = users["user_flight"]
        c.user_rearm = &urearm[0]
        c.user_coef = &ucoef[0, 0]
        c.user_offset = &uoffset[0]
        c.user_scale = &uscale[0]
        c.user_linear = &ulinear[0]
        c.user_index = &uindex[0]
        c.user_count = &ucount[0]
        c.user_direction = &udirection[0]
    run.n_planes, run.width, run.n_latch = scene.n_planes, width, scene.n_latch
    with nogil:
        rc = ballc_drive(&c, &y0[0], &run.o)
    run.owns = 1
    if rc == BALLC_DRIVE_NO_MEMORY:
        raise MemoryError("ballc_drive: out of memory")
    if rc == BALLC_DRIVE_USER_ERROR:   # the user's exception, an integrator's, Ctrl-C
        raise user_ctx[1][0]
    run._samples()
    return run


cdef class Drive:
    """One run of the C loop (ballc_drive_output): its samples ``t`` (n,) and ``rows``
    (n, the scene's states), its scalars as attributes, the rest read on demand (the C
    buffers are freed with it)."""
    cdef ballc_drive_output o
    cdef int owns
    cdef readonly int n_planes, width, n_latch   # the scene's planes, states, latch
    cdef _ScipyRun scipy_run
    cdef readonly object t, rows

    def __dealloc__(self):
        if self.owns:
            ballc_drive_free(&self.o)

    cdef _samples(self):
        """t and rows copied out; the C buffers of the samples freed at once."""
        cdef long n = self.o.n
        cdef double[::1] tv
        cdef double[:, ::1] rv
        t = np.empty(n)
        rows = np.empty((n, self.width))
        if n:
            tv = t
            rv = rows
            memcpy(&tv[0], self.o.t, n * sizeof(double))
            memcpy(&rv[0, 0], self.o.y, n * self.width * sizeof(double))
        free(self.o.t)
        free(self.o.y)
        self.o.t = self.o.y = NULL
        self.t, self.rows = t, rows

    @property
    def stop_code(self): return self.o.stop_code
    @property
    def status(self): return self.o.status
    @property
    def stop_plane(self): return self.o.stop_plane
    @property
    def t_run(self): return self.o.t_run
    @property
    def fail_end(self): return self.o.fail_end
    @property
    def message(self): return self.o.message.decode()
    @property
    def in_contact(self):
        return tuple(bool(self.o.in_contact[p]) for p in range(self.n_planes))
    @property
    def transitions(self):
        return tuple(self.o.transitions[p] for p in range(self.n_planes))
    @property
    def stalled(self): return self.o.stalled
    @property
    def unsettled_compliant(self): return bool(self.o.unsettled_compliant)
    @property
    def nfev(self): return self.o.nfev
    @property
    def njev(self): return self.o.njev
    @property
    def nlu(self): return self.o.nlu
    @property
    def stiff_at(self): return self.o.stiff_at
    @property
    def segments(self): return self.o.segments
    @property
    def end_kind(self): return self.o.end_kind
    @property
    def end_plane(self): return self.o.end_plane
    @property
    def end_t(self): return self.o.end_t
    @property
    def end_y(self):
        return np.array([self.o.end_y[j] for j in range(self.width)])
    @property
    def end_acceleration(self):
        """ACCELERATING (rolling down an incline): the centre's acceleration (m/s^2)."""
        return np.array([self.o.end_acceleration[j] for j in range(3)])
    @property
    def profiled(self): return bool(self.o.profiled)
    @property
    def integrator_ns(self): return self.o.integrator_ns
    @property
    def drive_ns(self): return self.o.drive_ns
    @property
    def integrator_prof(self):
        """A -DRADAU5_PROFILE build's integrator counters, summed; else None."""
        if not self.o.profiled:
            return None
        return dict(zip(("fun", "jac", "factor", "solve", "events", "total", "total_ns"),
                        [self.o.integrator_prof[j] for j in range(7)]))

    def blocks(self):
        """(counts (blocks,), flags (blocks,) int64, latches (blocks, the scene's latch)):
        the samples' blocks, each computed with one segment's flags and latch."""
        cdef long m = self.o.n_blocks
        cdef double[:, ::1] lv
        counts = np.array([self.o.block_count[i] for i in range(m)], dtype=np.intp)
        flags = np.array([self.o.block_flags[i] for i in range(m)], dtype=np.int64)
        latches = np.empty((m, self.n_latch))
        if m:
            lv = latches
            memcpy(&lv[0, 0], self.o.block_latch, m * self.n_latch * sizeof(double))
        return counts, flags, latches

    def contacts(self):
        """The contacts' records as arrays, one row per contact: "plane", "ended",
        "passed_through", "kernel_rate" (ints), "t_start", "t_end", "rate",
        "max_penetration" (n,), "v_before", "w_before", "v_after", "w_after", "digin"
        (n, 3), "contact_point" (the centre at the deepest penetration, x, y, z) (n, 3),
        "lost" (normal, tangential) (n, 2); a contact that did not end has NaN for t_end,
        v_after, w_after and lost."""
        cdef long n = self.o.n_contacts, i
        cdef int j
        cdef ballc_contact_rec *rec
        ints = np.empty((4, n), dtype=np.intc)
        scalars = np.empty((4, n))
        vectors = np.empty((6, n, 3))
        pairs = np.empty((1, n, 2))
        cdef int[:, ::1] iv = ints
        cdef double[:, ::1] sv = scalars
        cdef double[:, :, ::1] vv = vectors, pv = pairs
        for i in range(n):
            rec = &self.o.contacts[i]
            iv[0, i], iv[1, i] = rec.plane, rec.ended
            iv[2, i], iv[3, i] = rec.passed_through, rec.rate_is_kernel_value
            sv[0, i], sv[1, i], sv[2, i], sv[3, i] = (rec.t_start, rec.t_end, rec.rate,
                                                      rec.max_penetration)
            for j in range(3):
                vv[0, i, j] = rec.v_before[j]
                vv[1, i, j] = rec.w_before[j]
                vv[2, i, j] = rec.v_after[j]
                vv[3, i, j] = rec.w_after[j]
                vv[4, i, j] = rec.digin[j]
                vv[5, i, j] = rec.contact_point[j]
            for j in range(2):
                pv[0, i, j] = rec.lost[j]
            if not rec.ended:
                sv[1, i] = NAN
                for j in range(3):
                    vv[2, i, j] = NAN
                    vv[3, i, j] = NAN
                pv[0, i, 0] = pv[0, i, 1] = NAN
        return dict(plane=ints[0], ended=ints[1], passed_through=ints[2], kernel_rate=ints[3],
                    t_start=scalars[0], t_end=scalars[1], rate=scalars[2],
                    max_penetration=scalars[3], v_before=vectors[0], w_before=vectors[1],
                    v_after=vectors[2], w_after=vectors[3], digin=vectors[4],
                    contact_point=vectors[5], lost=pairs[0])

    def phases(self):
        """[(contact index, t, phase code: PHASE_NAMES)], in order."""
        return [(self.o.phases[i].contact, self.o.phases[i].t, self.o.phases[i].phase)
                for i in range(self.o.n_phases)]

    def open_contacts(self):
        """The open contact's index per plane (the scene's planes, in order), -1 none."""
        return tuple(self.o.open[p] for p in range(self.n_planes))

    def user_hits(self):
        """(event index (m,) intc, t (m,), states (m, the scene's states)): the user's
        events' hits."""
        cdef long m = self.o.n_user_hits
        cdef double[:, ::1] rv
        event = np.array([self.o.user_hit_event[i] for i in range(m)], dtype=np.intc)
        times = np.array([self.o.user_hit_t[i] for i in range(m)], dtype=float)
        states = np.empty((m, self.width))
        if m:
            rv = states
            memcpy(&rv[0, 0], self.o.user_hit_y, m * self.width * sizeof(double))
        return event, times, states

    def switches(self):
        """method "auto": [(t, method switched to)]."""
        return [(self.o.switch_t[i], _METHOD_NAMES[self.o.switch_to[i]])
                for i in range(self.o.n_switches)]

    def trials(self):
        """ballc.orbit's trials: [(t_from, t_to, accepted)]."""
        return [(self.o.trials[3 * i], self.o.trials[3 * i + 1], bool(self.o.trials[3 * i + 2]))
                for i in range(self.o.n_trials)]

    def segment_log(self):
        """The segment log: the bytes C wrote (SEGMENT_RECORD each)."""
        if not self.o.n_log:
            return b""
        return (<char *>self.o.log)[:self.o.n_log * sizeof(ballc_segment_rec)]

    def orbit(self):
        """ballc.orbit's end: (c0, period, G, rate, its base's pieces), or None."""
        if not self.o.end_orbit:
            return None
        return (self.o.orbit.c0, self.o.orbit.period, _motion_tuple(&self.o.orbit.g),
                self.o.orbit.rate, _dense_pieces(&self.o.orbit_base))

    def pieces(self):
        """Dense output, per segment: (t0, t1, dense_t, dense_c, terms, dense_kind) the
        compiled integrators' steps, (t0, t1, y0) an exact flight, (t0, t1, interpolant)
        an integrator's own (scipy's OdeSolution)."""
        cdef ballc_piece_rec *piece
        cdef double[:, ::1] dtv, dcv
        cdef int[::1] dkv
        cdef long i
        pieces = []
        for i in range(self.o.n_pieces):
            piece = &self.o.pieces[i]
            if piece.own:
                pieces.append((piece.t0, piece.t1,
                               self.scipy_run.interpolants[piece.interpolant]))
                continue
            if piece.flight:
                pieces.append((piece.t0, piece.t1,
                               np.array([piece.y0[j] for j in range(self.width)])))
                continue
            dense_t = np.empty((piece.n_steps, 2))
            dense_c = np.empty((piece.n_steps, (1 + piece.terms) * self.width))
            dense_kind = np.empty(piece.n_steps, dtype=np.intc)
            if piece.n_steps:
                dtv = dense_t
                dcv = dense_c
                dkv = dense_kind
                memcpy(&dtv[0, 0], self.o.dense_t + 2 * piece.step0,
                       piece.n_steps * 2 * sizeof(double))
                memcpy(&dcv[0, 0], self.o.dense_c + piece.coef0,
                       piece.n_steps * (1 + piece.terms) * self.width * sizeof(double))
                memcpy(&dkv[0], self.o.dense_kind + piece.step0, piece.n_steps * sizeof(int))
            pieces.append((piece.t0, piece.t1, dense_t, dense_c, piece.terms, dense_kind))
        return pieces


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
