"""simulate(): validate, run the segment loop in C, return the Result.

The hybrid automaton (ballc.automaton) -- pick the mode, integrate, handle the event,
go on -- is one C function, ``ballc_drive`` (``_driver.c``, docs/driver.md), which
integrates each segment through its integrator interface (radau5, dop853 and auto in
C; scipy's methods called back through ``_scipy_bridge.pxi``).  Here: the options are
validated (ballc.options), the initial state checked, the constants handed over
(ballc.loop_constants: the scene's once per scene, the run's), the C loop run
(``_core.drive``) with the progress bar advanced from C, and the Result built from its
output (ballc.loop_result), lazily.
"""
from __future__ import annotations

import numpy as np

from . import _core, layout
from ._format import plain
from .loop_constants import run_constants, scene_constants
from .loop_result import result_of
from .options import DEFAULT_MAX_NFEV, METHODS, check_options  # noqa: F401 (re-exported)
from .progress import progress_bar
from .result import Result
from .scene import Scene, SceneError, check_inside, check_speeds

_STATE = layout.INDEX
_QUATERNION = layout.QUATERNION


def check_initial_state(scene, y0):
    """The full initial state: the scene's, or ``y0`` (one value per state of the scene,
    ``scene.state_names``; the quaternion normalised) checked to be finite with the centre
    on the ball's side of every plane."""
    if y0 is None:
        return scene.initial_state()
    names = scene.state_names
    try:
        y = np.array(y0, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"y0 = {plain(y0)} is not allowed: must be {len(names)} numbers "
                         f"({', '.join(names)})") from None
    if y.shape != (len(names),) or not np.all(np.isfinite(y)):
        raise SceneError(f"y0 = {plain(y0)} is not allowed: must be {len(names)} finite "
                         f"numbers ({', '.join(names)})")
    size = np.linalg.norm(y[_QUATERNION])
    if not size > 0:
        raise SceneError("y0 is not allowed: its quaternion (qw, qx, qy, qz) is zero")
    y[_QUATERNION] /= size
    if scene.ceiling_height is not None:
        if not 0 < y[_STATE["z"]] < scene.ceiling_height:
            raise SceneError(f"y0 is not allowed: z = {plain(y[_STATE['z']])} must be between "
                             f"the planes, 0 < z < {scene.ceiling_height}")
    else:
        check_inside(scene, y[layout.POSITION], "y0's position (x, y, z)")
    check_speeds(scene, y[_STATE["vx"]:_STATE["vz"] + 1],
                 y[_STATE["omega_x"]:_STATE["omega_z"] + 1],
                 ("y0's velocity (vx, vy, vz)",
                  "y0's angular velocity (omega_x, omega_y, omega_z)"))
    return y


def simulate(scene: Scene, t_end: float, *, method: str = "radau5", rtol: float = 1e-10,
             atol: float = 1e-10, t_eval=None, max_step: float = np.inf,
             first_step: float | None = None, events=None, dense_output: bool = False,
             y0=None, progress: bool | None = None,
             max_nfev: int | None = DEFAULT_MAX_NFEV, exact_flight: bool = True,
             rest: bool = True) -> Result:
    """Simulate ``scene`` from t = 0 to ``t_end`` (s), like ``scipy.integrate.solve_ivp``.

    Parameters
    ----------
    scene : Scene
        The ball, the planes, the contact models and the initial state (SI units).
    t_end : float
        End time (s), > 0.
    method : str
        "radau5" (default): ballc's compiled Radau IIA (order 5) -- scipy's Radau
        algorithm in C, same error control and events, except that the state at a
        terminal event (a contact or stick/slip boundary, or a terminal user event) is
        the end of a step taken to the event's time, not the dense output's value there.
        "dop853": ballc's compiled DOP853 (Dormand & Prince, explicit, order 8) --
        scipy's DOP853 in C, in radau5's loop with the same events; no Jacobian and no
        linear algebra, so at tight tolerances (rtol <= 1e-8) on scenes that are not
        stiff (the seed's rubber ball) it needs several times less CPU than radau5 for
        the same error.  Explicit: on stiff scenes (hard materials, compliant
        tangential laws, sticking with large stiffness) its steps are bounded by
        stability, not accuracy, and radau5 is the one to use.
        "auto": per segment dop853 first, switching to radau5 where Hairer's stiffness
        test fires (15 steps in a row held at dop853's stability limit) or a Jacobian
        probe every 15 steps finds them stiff, and back where radau5's steps are within
        half dop853's stability bound for 15 steps, in the same loop
        with the same events and output (each step keeps its own method's interpolant); a
        segment that continues the last one with its step (a stick/slip transition, a
        rest check) continues with its method too.  ``result.method_switches`` lists the
        switches.  Until it switches it is dop853, step for step.  It is not the
        default: docs/auto_method.md has the measurements against the rule.
        Or a scipy.integrate.solve_ivp
        method: "Radau" (the reference radau5 is tested against), "BDF", "LSODA" (given
        the analytic Jacobian), "DOP853", "RK45", "RK23".
    rtol, atol : float
        Tolerances per segment, as in solve_ivp (atol: one number or one per state).
    t_eval : array_like, optional
        Times (s) at which to store the solution; by default every solver step and
        every event.
    max_step : float
        Largest step (s).
    first_step : float, optional
        Initial step (s) of the first segment; default: chosen by the integrator.
    events : callable or list of callables, optional
        As solve_ivp's: g(t, y) with optional ``terminal`` (bool) and ``direction``
        attributes; their zeros are located on the dense output and returned in
        ``result.t_events`` / ``result.y_events`` (one array per event).  A terminal
        event ends the run with status 1.  ``y`` is the full state (``scene.state_names``).
    dense_output : bool
        Build ``result.sol``: the continuous solution sol(t) over the run, piecewise
        across contact and stick/slip events, from each integrator's own interpolant.
    y0 : array_like, optional
        The full initial state (``scene.state_names``: quaternion, centre, angular
        velocity, velocity, then the auxiliary states, two per plane) instead of the
        scene's; the quaternion is normalised.  A state in contact with a plane starts that contact (see
        ballc.modes for what it latches).
    max_nfev : int or None
        Give up (status -1, message, results so far) after this many right-hand-side
        evaluations in all (default 2e7); None: no limit.
    progress : bool, optional
        Show a tqdm progress bar in simulated time (refreshed at most every 0.1 s of
        wall time).  None (default): only when stderr is a terminal.  Whatever the
        method, Ctrl-C stops a run within about 0.1 s (KeyboardInterrupt).
    exact_flight : bool
        True (default): a free-flight segment is propagated in closed form, not
        integrated, when that is exact -- massless observer (``observer_mass = 0``) and
        isotropic inertia (all three moments equal) -- whatever ``method``: constant
        angular velocity, a parabola for the centre, the contact start at the root of
        its event in closed form (ballc.flight).  Its samples are ``t_eval``'s, or
        else the segment's start, end and evenly spaced times between (at least 32
        intervals, at most pi/16 rad of rotation and ``max_step`` apart); it costs no
        right-hand-side call.  A segment with a user event that is not a
        ``ballc.events.LinearEvent`` is integrated as before.  False: every segment is
        integrated by ``method``.
    rest : bool
        True (default): a ball that has come to rest on the floor -- the plane whose
        normal is opposite gravity (the criterion of
        ballc.resting: a contact lasting 20 small-oscillation periods, energy above
        the static Hertz equilibrium below that of an oscillation of 10 tolerances)
        is put in the rest state and the run finishes analytically: ``message`` says
        when, and so does the contact's ``t_rest``; likewise a ball rolling uniformly
        without slip at the equilibrium, or sliding with no force opposing its slip,
        when its rotation is exact (massless observer, isotropic inertia), goes on in
        closed form (``t_rolling``, ``t_sliding``), and a ball with an eccentric
        observer (isotropic inertia) that rolls on with its wobble goes on as a
        relative periodic orbit, measured over a trial of 3.5 periods (ballc.orbit;
        ``t_rolling``, or ``t_sliding`` when it slides; the message says what it
        neglects); on an incline, a ball rolling straight down it without slip and
        reaching no other plane by t_end goes on uniformly accelerated in closed form
        (``t_rolling``).  Checked only without
        ``t_eval`` and user ``events``.  False: integrate to t_end whatever happens.

    Returns
    -------
    Result
        ``status`` 0 when t_end was reached, 1 when a terminal condition stopped the
        run (the ball passed through a plane, or a terminal user event), -1 when the
        integrator failed, the mode changes did not settle or the run could not go on
        (``message`` says which); the arrays always hold what was computed up to there.
        ``t``, ``y`` and the scalars are there at once; the rest (contacts, ``flags``,
        ``latch``, the events' hits, ``sol``, ``segments``, ``message``) is built from
        the C loop's output on first access.
    """
    options = check_options(scene, t_end, method, rtol, atol, max_step, first_step, t_eval,
                            max_nfev, events, dense_output, exact_flight)
    y = scene._initial if y0 is None else check_initial_state(scene, y0)
    return run_checked(scene, options, y, progress, rest)


def run_checked(scene: Scene, options, y, progress=None, rest: bool = True) -> Result:
    """:func:`simulate`'s run from its checked arguments: ``options``
    (ballc.options.check_options of this scene, or of one with the same state names) and
    ``y`` (the full initial state, checked).  A sweep checks its options once, not
    once per cell."""
    constants = scene_constants(scene)
    run_given = run_constants(scene, options, rest)
    bar = progress_bar(progress, options.t_end)   # advanced from C, throttled in wall time
    try:
        run = _core.drive(constants, y, run_given, bar)
        if bar is not None:   # to where the run ended
            bar.update((options.t_end if run.status == 0 else run.t_run) - bar.n)
    finally:
        if bar is not None:
            bar.close()
    return result_of(scene, options, run, bool(run_given["checks_rest"]))
