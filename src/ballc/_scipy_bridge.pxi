# Included by _core.pyx after _driver_bridge.pxi.  scipy's methods ("Radau", "BDF",
# "LSODA", "DOP853", "RK45", "RK23") behind the C loop's integrator interface
# (_driver.h: ballc_integrator): _scipy_integrate integrates one segment by calling
# ballc.scipy_segment.solve (solve_ivp on the compiled right-hand side, a
# ``System`` of this module, with its analytic Jacobian for the implicit methods) with
# the segment's events as _Guard callables over the C loop's own guards
# (radau5_event_value on the segment's problem, valid while that segment is integrated),
# and copies its solution into the radau5_result the loop reads.  Its dense output
# stays a Python object (scipy's OdeSolution), kept here and referenced by the piece's
# id.  Only converts: the loop (modes, latches, resets, rest checks) stays in C.

from libc.stdlib cimport malloc
from libc.string cimport memset, strncpy

cdef extern from "_driver.h":
    enum: BALLC_METHOD_SCIPY

cdef extern from "_driver.h":
    ctypedef struct ballc_segment:
        ballc_flags flags
        const double *latch
        const double *params
        long interpolant
        int n_latch
    int BALLC_INTEGRATOR_RAISED

cdef extern from "_integrator.h":
    double radau5_event_value(const radau5_problem *, int, double, const double *,
                              int *) nogil


class _Kept(Exception):
    """A user's event raised inside solve_ivp: its exception is kept (the bridge raises
    it); this one only stops solve_ivp."""


cdef class _Guard:
    """Event ``e`` of the segment being integrated, as solve_ivp calls an event: g(t, y)
    with ``terminal`` and ``direction``; its value is the C loop's (radau5_event_value:
    the row dotted with y plus the offset, or the system's guard -- stick release, the
    compliant law's margins -- or the user's callable, plus the offset)."""
    cdef const radau5_problem *p
    cdef int e
    cdef list errors
    cdef readonly object terminal
    cdef readonly int direction

    def __call__(self, double t, y):
        cdef const double[::1] v
        cdef int status
        cdef double g
        if self.p == NULL:
            raise RuntimeError("this event belonged to a segment that is over")
        try:
            v = y
        except (TypeError, ValueError):
            v = np.ascontiguousarray(y, dtype=float)
        if v.shape[0] != self.p.n:
            raise ValueError(f"y must have {self.p.n} values, got {v.shape[0]}")
        g = radau5_event_value(self.p, self.e, t, &v[0], &status)
        if status and self.errors:   # a user's callable raised: stop solve_ivp
            raise _Kept()
        return g


cdef class _ScipyRun:
    """One run's scipy method: its name, atol as given (one float or per state), the
    exceptions kept for drive to raise (shared with the user events') and the dense
    output's interpolants, by id."""
    cdef object method, atol, solve
    cdef list errors, interpolants
    cdef object params
    cdef int n_states

    def __init__(self, method, atol, params, list errors):
        from . import scipy_segment
        self.method, self.atol, self.params = method, atol, params
        self.n_states = layout_of(params)[1]
        self.errors = errors
        self.interpolants = []
        self.solve = scipy_segment.solve


cdef int _scipy_integrate(void *ctx, const radau5_problem *p, ballc_segment *seg,
                          radau5_result *res) noexcept nogil:
    """ballc_integrator for scipy's methods (ctx: a _ScipyRun)."""
    with gil:
        return _scipy_segment(<_ScipyRun>ctx, p, seg, res)


cdef int _scipy_segment(_ScipyRun run, const radau5_problem *p, ballc_segment *seg,
                        radau5_result *res) noexcept:
    cdef int e, m = p.n_events
    cdef _Guard guard
    cdef list guards = []
    memset(res, 0, sizeof(radau5_result))
    res.stiff_at = NAN
    res.method_end = BALLC_METHOD_SCIPY
    res.status = RADAU5_FAILED
    seg.interpolant = -1
    try:
        latch = np.empty(seg.n_latch)
        for e in range(seg.n_latch):
            latch[e] = seg.latch[e]
        system = System(run.params, latch, seg.flags)
        for e in range(m):
            guard = _Guard.__new__(_Guard)
            guard.p = p
            guard.e = e
            guard.errors = run.errors
            guard.terminal = p.ev_terminal[e] if p.ev_terminal[e] > 1 else p.ev_terminal[e] == 1
            guard.direction = p.ev_direction[e]
            guards.append(guard)
        y0 = np.empty(p.n)
        for e in range(p.n):
            y0[e] = p.y0[e]
        t_eval = None
        if p.t_eval != NULL:
            t_eval = np.array([p.t_eval[e] for e in range(p.n_eval)], dtype=float)
        sol = run.solve(system, p.t0, p.t_bound, y0, guards, method=run.method,
                        rtol=p.rtol, atol=run.atol, t_eval=t_eval, max_step=p.max_step,
                        max_nfev=p.max_nfev if p.max_nfev > 0 else None,
                        first_step=p.first_step if p.first_step > 0 else None,
                        dense_output=bool(p.dense_output))
        if not _fill_result(sol, m, p.n, res):
            return RADAU5_OUT_OF_MEMORY
        if p.dense_output and sol.sol is not None:
            run.interpolants.append(sol.sol)
            seg.interpolant = len(run.interpolants) - 1
        return RADAU5_DONE
    except _Kept:
        return BALLC_INTEGRATOR_RAISED
    except BaseException as error:   # an exception (Ctrl-C too) is kept for drive to raise
        run.errors.append(error)
        return BALLC_INTEGRATOR_RAISED
    finally:
        for guard in guards:
            guard.p = NULL


cdef int _scipy_interpolant(void *ctx, long id, long n, const double *t,
                            double *y) noexcept nogil:
    """ballc_interpolant_fn for scipy's methods (ctx: a _ScipyRun): its kept
    interpolant ``id`` (an OdeSolution) at n times, rows into y; an exception is kept."""
    cdef const double[:, ::1] values
    cdef long i
    with gil:
        run = <_ScipyRun>ctx
        try:
            times = np.array([t[i] for i in range(n)], dtype=float)
            values = np.ascontiguousarray(
                np.asarray(run.interpolants[id](times), dtype=float).reshape(
                    run.n_states, n).T)
            if n:
                memcpy(y, &values[0, 0], n * run.n_states * sizeof(double))
            return 0
        except BaseException as error:
            run.errors.append(error)
            return -1


def _scipy_interpolant_rows(interpolant, t, params):
    """``interpolant`` (a scipy OdeSolution) at the times t as C code reads a scipy
    run's interpolant (_scipy_interpolant): rows (len(t), states) (tests); ``params``:
    the run's parameter vector (its states)."""
    cdef const double[::1] tv = np.ascontiguousarray(t, dtype=float)
    run = _ScipyRun("Radau", 1.0, np.ascontiguousarray(params, dtype=float), [])
    run.interpolants.append(interpolant)
    out = np.empty((tv.shape[0], run.n_states))
    cdef double[:, ::1] ov = out
    if _scipy_interpolant(<void *>run, 0, tv.shape[0], &tv[0] if tv.shape[0] else NULL,
                          &ov[0, 0] if tv.shape[0] else NULL):
        raise run.errors[0]
    return out


cdef bint _fill_result(sol, int m, int n_states, radau5_result *res) except -1:
    """solve_ivp's solution as radau5_solve's result (its buffers malloc'd: radau5_free
    frees them); False when out of memory."""
    cdef const double[::1] tv
    cdef const double[:, ::1] yv
    cdef Py_ssize_t n, h, k, i, hits
    t = np.ascontiguousarray(sol.t, dtype=float)
    y = np.ascontiguousarray(np.asarray(sol.y, dtype=float).T)   # samples x states
    n = t.shape[0]
    res.t_out = <double *>malloc(max(n, 1) * sizeof(double))
    res.y_out = <double *>malloc(max(n, 1) * n_states * sizeof(double))
    if res.t_out == NULL or res.y_out == NULL:
        return False
    if n:
        tv = t
        yv = y
        memcpy(res.t_out, &tv[0], n * sizeof(double))
        memcpy(res.y_out, &yv[0, 0], n * n_states * sizeof(double))
    res.n_out = n
    hits = sum(len(te) for te in sol.t_events)
    res.hit_event = <int *>malloc(max(hits, 1) * sizeof(int))
    res.hit_t = <double *>malloc(max(hits, 1) * sizeof(double))
    res.hit_y = <double *>malloc(max(hits, 1) * n_states * sizeof(double))
    if res.hit_event == NULL or res.hit_t == NULL or res.hit_y == NULL:
        return False
    h = 0
    for k in range(m):   # grouped by event, each in order (the loop reads them so)
        te = sol.t_events[k]
        if not len(te):
            continue
        ye = np.ascontiguousarray(sol.y_events[k], dtype=float).reshape(-1, n_states)
        yv = ye
        for i in range(len(te)):
            res.hit_event[h] = k
            res.hit_t[h] = te[i]
            memcpy(res.hit_y + h * n_states, &yv[i, 0],
                   n_states * sizeof(double))
            h += 1
    res.n_hits = h
    status = int(sol.status)
    res.status = (RADAU5_REACHED if status == 0 else RADAU5_EVENT if status == 1
                  else RADAU5_FAILED)
    message = str(sol.message).encode("utf-8", "replace")[:239]
    strncpy(res.message, message, 239)
    res.message[239] = 0
    res.nfev = sol.nfev
    res.njev = sol.njev
    res.nlu = sol.nlu
    return True
