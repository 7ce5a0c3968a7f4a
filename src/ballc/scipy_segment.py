"""scipy's methods on one segment: ``solve_ivp`` on the compiled right-hand side.

The segment loop in C (ballc._core.drive, ``_driver.c``) integrates each segment through
its integrator interface.  For scipy's methods ("Radau", "BDF", "LSODA", "DOP853",
"RK45", "RK23") its bridge (``_scipy_bridge.pxi``) calls :func:`solve` with the
segment's right-hand side, a ``_core.System`` (given its analytic Jacobian for the
implicit methods), and the segment's events as thin callables over the C loop's own
guards; modes, latches, resets and rest checks stay in C.  scipy has no call budget of
its own: :func:`_call_budget` gives it one as a terminal event.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from .options import IMPLICIT_METHODS


def solve(system, t0, t1, y0, events, *, method, rtol, atol, t_eval, max_step,
          max_nfev=None, first_step=None, dense_output=False):
    """``solve_ivp`` of ``system`` (a ``_core.System``) from (t0, y0) towards t1 with
    ``events``; its OdeResult with ``t`` and ``y`` as arrays (also when no t_eval point
    fell in the segment), ``sol`` its interpolant with ``dense_output``.  ``max_nfev``:
    give up (status -1, keeping what was computed) after that many right-hand-side
    calls; ``first_step`` (None: scipy's choice) must fit in the segment."""
    options = {"jac": system.jacobian} if method in IMPLICIT_METHODS else {}
    if first_step is not None:
        options["first_step"] = first_step
    budget = [_call_budget(system, max_nfev)] if max_nfev is not None else []
    sol = solve_ivp(system, (t0, t1), y0, method=method, rtol=rtol, atol=atol,
                    t_eval=t_eval, events=list(events) + budget, max_step=max_step,
                    dense_output=dense_output, **options)
    # solve_ivp leaves t and y as empty lists when no t_eval point fell in the segment
    sol.t = np.asarray(sol.t, dtype=float)
    sol.y = np.asarray(sol.y, dtype=float).reshape(len(y0), sol.t.size)
    if budget:
        if len(sol.t_events[-1]):
            sol.status = -1
            sol.message = (f"gave up at t = {sol.t[-1]:.9g} after {sol.nfev} right-hand-side "
                           "evaluations (max_nfev)")
        sol.t_events, sol.y_events = sol.t_events[:-1], sol.y_events[:-1]
    return sol


def _call_budget(system, max_nfev):
    """A terminal solve_ivp event that stops the integration gracefully at the end of
    the first step after which ``system`` has been called ``max_nfev`` more times
    (solve_ivp has no call budget of its own).  It is +1 before that step's end time
    and -1 from it on, so the event search puts the root at that step's end."""
    start, stop = system.nfev, []

    def g(t, y):
        if not stop and system.nfev - start >= max_nfev:
            stop.append(t)
        return -1.0 if stop and t >= stop[0] else 1.0
    g.terminal = True
    g.direction = -1
    return g
