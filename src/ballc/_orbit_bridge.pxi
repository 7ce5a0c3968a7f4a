# Included by _core.pyx before _driver_bridge.pxi.  Bridge to the compiled interpolants'
# evaluation (_dense.c) and to the relative periodic orbit (_orbit.c): arrays in, C
# called, arrays out.  A solution given as a Python callable (sol(t) of an array of
# times -> (states, len(t))) is called back in batches.

cdef extern from "_dense.h":
    ctypedef int (*ballc_states_fn)(void *, long, const double *, double *) noexcept
    ctypedef struct ballc_interpolant:
        long n_steps
        const double *steps
        const double *coef
        const int *kinds
        int terms, width
    void ballc_interpolant_at(const ballc_interpolant *, double, double *) nogil
    ctypedef struct ballc_dense:
        long n_pieces
        double *t0
        double *t1
        long *step0
        long *n_steps
        int *terms
        double *steps
        double *coef
        int *kinds
        int width

cdef extern from "_orbit.h":
    double BALLC_ORBIT_TRIAL_PERIODS
    int BALLC_ORBIT_TILT_SAMPLES
    ctypedef struct ballc_motion:
        double phi
        double d[2]
        double psi
        double axis[3]
        double work[2]
        int n_planes
        double sense[6]
    void ballc_motion_power(const ballc_motion *, double, ballc_motion *) nogil
    void ballc_motion_apply(const ballc_motion *, const double *, int, double *) nogil
    void ballc_motion_planes(ballc_motion *, const double *) nogil
    double ballc_orbit_tilt(const double *, const double *) nogil
    int ballc_orbit_equivariant(const double *, const double *, long long, const double *,
                                const double *) nogil
    ctypedef struct ballc_orbit:
        double c0, period
        ballc_motion g
        double rate
    ctypedef struct ballc_orbit_tolerances:
        double rtol
        const double *atol
        double rest_factor
        double energy_threshold
        const double *params
    int ballc_orbit_measure(ballc_states_fn, void *, double, double, const double *, double,
                            const ballc_orbit_tolerances *, ballc_orbit *)
    int ballc_orbit_states(const ballc_orbit *, ballc_states_fn, void *, long,
                           const double *, double *)

#: orbit.TRIAL_PERIODS and TILT_SAMPLES, from _orbit.h
ORBIT_TRIAL_PERIODS = BALLC_ORBIT_TRIAL_PERIODS
ORBIT_TILT_SAMPLES = BALLC_ORBIT_TILT_SAMPLES
#: G as an array: phi, dx, dy, psi, the axis (3), the work (normal, tangential), the
#: number of planes, how each plane's deflection turns (MAX_PLANES: +1 with the scene,
#: -1 against it; ballc_motion)
MOTION_SIZE = 10 + BALLC_MAX_PLANES


def dense_states(const double[:, ::1] steps, const double[:, ::1] coefficients,
                 const int[::1] kinds, int terms, int width, const double[::1] t):
    """A compiled segment's interpolant (dense.CompiledInterpolant) at the times t:
    (width, len(t))."""
    cdef ballc_interpolant f
    cdef Py_ssize_t i, m = steps.shape[0]
    if steps.shape[1] != 2 or kinds.shape[0] != m or coefficients.shape[0] != m \
            or (m and coefficients.shape[1] != (1 + terms) * width) or terms not in (3, 7):
        raise ValueError("dense_states: steps, coefficients and kinds do not agree")
    if m == 0:
        raise ValueError("dense_states: the segment has no steps")
    for i in range(m):
        if (kinds[i] != 3 and kinds[i] != 7) or kinds[i] > terms:
            raise ValueError(f"dense_states: step {i} has {kinds[i]} terms")
    f.n_steps = m
    f.steps = &steps[0, 0]
    f.coef = &coefficients[0, 0]
    f.kinds = &kinds[0]
    f.terms = terms
    f.width = width
    rows = np.empty((t.shape[0], width))
    cdef double[:, ::1] r = rows
    for i in range(t.shape[0]):
        ballc_interpolant_at(&f, t[i], &r[i, 0])
    return rows.T


cdef void _motion_of(const double[::1] m, ballc_motion *g) except *:
    _check("motion", m.shape[0], MOTION_SIZE)
    g.phi = m[0]
    g.d[0] = m[1]
    g.d[1] = m[2]
    g.psi = m[3]
    g.axis[0] = m[4]
    g.axis[1] = m[5]
    g.axis[2] = m[6]
    g.work[0] = m[7]
    g.work[1] = m[8]
    if not (1 <= m[9] <= BALLC_MAX_PLANES):
        raise ValueError(f"motion: {m[9]} planes is not allowed")
    g.n_planes = int(m[9])
    cdef int p
    for p in range(BALLC_MAX_PLANES):
        g.sense[p] = m[10 + p]


cdef tuple _motion_tuple(const ballc_motion *g):
    return (g.phi, g.d[0], g.d[1], g.psi, g.axis[0], g.axis[1], g.axis[2], g.work[0],
            g.work[1], g.n_planes) + tuple(g.sense[p] if p < g.n_planes else 0.0
                                           for p in range(BALLC_MAX_PLANES))


def motion_planes(const double[::1] params):
    """The planes' part of a motion G of the scene with parameters ``params`` (the
    number of planes, how each one's deflection turns: MOTION_SIZE's last numbers)."""
    _planes_of(params)
    cdef ballc_motion g
    ballc_motion_planes(&g, &params[0])
    return _motion_tuple(&g)[9:]


def motion_apply(const double[::1] motion, y, k=1, bint rate=False):
    """G^k y for states y, (states,) or (states, n) (G's scene's states); k an integer,
    or one per column; with ``rate``, G_* of a time derivative (no shift, no work
    added)."""
    cdef ballc_motion g, gk
    _motion_of(motion, &g)
    cdef int width = _ball_and_plane_states(g.n_planes)
    states = np.asarray(y, dtype=float)
    single = states.ndim == 1
    if states.shape[0] != width:
        raise ValueError(f"y must have {width} states (rows), got {states.shape[0]}")
    cdef double[:, ::1] rows = np.ascontiguousarray(states.reshape(width, -1).T)
    cdef Py_ssize_t i, n = rows.shape[0]
    powers = np.broadcast_to(np.asarray(k, dtype=float), (n,))
    out = np.empty((n, width))
    cdef double[:, ::1] o = out
    for i in range(n):
        ballc_motion_power(&g, powers[i], &gk)
        ballc_motion_apply(&gk, &rows[i, 0], rate, &o[i, 0])
    return out[0] if single else out.T


def orbit_tilt(y, const double[::1] axis):
    """a_z, the vertical component of the ball's axis, of states (states, ...)."""
    _check("axis", axis.shape[0], 3)
    states = np.asarray(y, dtype=float)
    cdef double[:, ::1] rows = np.ascontiguousarray(states.reshape(states.shape[0], -1).T)
    out = np.empty(rows.shape[0])
    cdef double[::1] o = out
    cdef Py_ssize_t i
    for i in range(rows.shape[0]):
        o[i] = ballc_orbit_tilt(&rows[i, 0], &axis[0])
    return float(out[0]) if states.ndim == 1 else out.reshape(states.shape[1:])


def orbit_equivariant(const double[::1] params, const double[::1] latch, long long flags,
                      const double[::1] y, const double[::1] axis):
    """Criterion 2 of ballc.orbit: f(G y) = G_* f(y) to rounding."""
    _check_call(params, y.shape[0], latch.shape[0])
    _check("axis", axis.shape[0], 3)
    return bool(ballc_orbit_equivariant(&params[0], &latch[0], flags, &y[0], &axis[0]))


cdef int _python_states(void *ctx, long n, const double *t, double *y) noexcept:
    """ballc_states_fn of a Python solution: ctx is [sol, the exceptions kept, the
    number of states].  Called from C with the GIL held (the bridge's callers below do
    not release it)."""
    cdef double[::1] tv
    cdef double[:, ::1] yv
    sol, errors, width = (<list>ctx)[0], (<list>ctx)[1], (<list>ctx)[2]
    if errors:
        return -1
    try:
        times = np.empty(n)
        tv = times
        memcpy(&tv[0], t, n * sizeof(double))
        values = np.ascontiguousarray(np.asarray(sol(times), dtype=float)
                                      .reshape(width, n).T)
        yv = values
        memcpy(y, &yv[0, 0], n * width * sizeof(double))
        return 0
    except BaseException as error:
        errors.append(error)
        return -1


def orbit_measure(sol, double t0, double t1, const double[::1] axis, double guess,
                  double rtol, const double[::1] atol, double rest_factor,
                  double energy_threshold, const double[::1] params):
    """Criteria 3-5 of ballc.orbit on a trial's solution ``sol`` (a callable y(t) over
    [t0, t1]): (c0, period, G as MOTION_SIZE numbers, the mechanical energy's rate of
    change (W)), or None."""
    _check("axis", axis.shape[0], 3)
    cdef int width = _ball_and_plane_states(_planes_of(params))
    _check("atol", atol.shape[0], width)
    cdef ballc_orbit_tolerances tol
    cdef ballc_orbit found
    cdef list ctx = [sol, [], width]
    tol.rtol = rtol
    tol.atol = &atol[0]
    tol.rest_factor = rest_factor
    tol.energy_threshold = energy_threshold
    tol.params = &params[0]
    cdef int got = ballc_orbit_measure(_python_states, <void *>ctx, t0, t1, &axis[0], guess,
                                       &tol, &found)
    if ctx[1]:
        raise ctx[1][0]
    if got == -2:
        raise MemoryError("orbit_measure: out of memory")
    if got <= 0:
        return None
    return found.c0, found.period, _motion_tuple(&found.g), found.rate


def orbit_states(const double[::1] t, double c0, double period, const double[::1] motion,
                 base):
    """y(t) = G^k base(c0 + s), t = c0 + k T + s (0 <= s < T): (states, len(t));
    ``base``: a callable y(t') over [c0, c0 + T]."""
    cdef ballc_orbit orbit
    orbit.c0 = c0
    orbit.period = period
    orbit.rate = 0.0
    _motion_of(motion, &orbit.g)
    cdef int width = _ball_and_plane_states(orbit.g.n_planes)
    cdef list ctx = [base, [], width]
    out = np.empty((t.shape[0], width))
    cdef double[:, ::1] o = out
    if t.shape[0] == 0:
        return out.T
    cdef int got = ballc_orbit_states(&orbit, _python_states, <void *>ctx, t.shape[0], &t[0],
                                      &o[0, 0])
    if ctx[1]:
        raise ctx[1][0]
    if got:
        raise MemoryError("orbit_states: out of memory")
    return out.T
