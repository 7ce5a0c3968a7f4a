"""The driver: integrate segment by segment between contact events.

Each segment integrates a pure right-hand side (compiled, with analytic Jacobian)
whose active terms are fixed for the segment: free flight, or in contact with the
floor and/or ceiling.  Contact start and end are terminal integrator events, so
no step ever straddles a contact boundary.  At contact start the penetration rate
``rhodot^-`` and the dig-in direction are latched from the exact event state.
"""
from __future__ import annotations

import math
import sys

import numpy as np
from scipy.integrate import solve_ivp

from . import _core
from .result import Contact, Result
from .scene import Scene, SceneError

SCIPY_METHODS = ("Radau", "BDF", "LSODA", "DOP853", "RK45", "RK23")
IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")
PLANES = ("floor", "ceiling")

#: Smallest penetration rate latched at impact (m/s).  A contact that starts
#: with a smaller rate (grazing, or a ball settling) uses this instead, so that
#: Hunt-Crossley's damping chi = 3/2 (1 - c_tau) k0 / |rhodot^-| stays finite.
MIN_IMPACT_RATE = 1e-9

_STATE = {name: i for i, name in enumerate(_core.STATE_NAMES)}
_Z, _VZ = _STATE["z"], _STATE["vz"]
_OMEGA, _V = _STATE["omega_x"], _STATE["vx"]
_KIN_PER_PLANE = _core.CONTACT_KINEMATICS_NOUT // len(PLANES)


def _penetration(plane, scene):
    """rho(y) of ``plane``: positive when the ball overlaps it (m)."""
    r, h = scene.radius, scene.ceiling_height
    if plane == "floor":
        return lambda t, y: r - y[_Z]
    return lambda t, y: y[_Z] - (h - r)


def _event(function, terminal, direction):
    function.terminal = terminal
    function.direction = direction
    return function


def _segment_events(scene, in_contact):
    """Events of one segment: [(kind, plane, event function)]."""
    events = []
    for plane in PLANES:
        rho = _penetration(plane, scene)
        if in_contact[plane]:
            r = scene.radius
            normal = 1.0 if plane == "floor" else -1.0
            events.append(("leave", plane, _event(lambda t, y, rho=rho: rho(t, y), True, -1)))
            events.append(("through", plane,
                           _event(lambda t, y, rho=rho, r=r: rho(t, y) - r, True, 1)))
            events.append(("deepest", plane,
                           _event(lambda t, y, s=normal: -s * y[_VZ], False, -1)))
        else:
            events.append(("enter", plane, _event(lambda t, y, rho=rho: rho(t, y), True, 1)))
    return events


def _flags(scene, in_contact):
    flags = _core.FLAGS["observer"] if scene.observer_mass != 0 else 0
    mixture = scene.effective_mixture
    for plane in PLANES:
        if not in_contact[plane]:
            continue
        if mixture < 1:
            flags |= _core.FLAGS[f"{plane}_friction"]
        if mixture > 0:
            flags |= _core.FLAGS[f"{plane}_digin"]
    return flags


def _latch_values(y, params, plane):
    """(rhodot^-, unit dig-in direction) of ``plane`` at state y."""
    kin = _core.contact_kinematics(np.ascontiguousarray(y[None, :]), params)[0]
    k = PLANES.index(plane) * _KIN_PER_PLANE
    rate, velocity = kin[k + 1], kin[k + 2:k + 5]
    speed = np.linalg.norm(velocity)
    if speed > 0:
        direction = velocity / speed
    else:
        direction = np.array([0.0, 0.0, -1.0 if plane == "floor" else 1.0])
    return max(rate, MIN_IMPACT_RATE), direction


def integrate_segment(system, t0, t1, y0, events, *, method, rtol, atol, t_eval, max_step):
    """Integrate one smooth segment; returns a solve_ivp-style solution.

    This is the one seam between the driver and an integrator.  The solution must
    have ``t, y, t_events, y_events, status (0 reached t1, 1 terminal event, -1
    failure), message, nfev, njev, nlu``.  Events are solve_ivp-style callables with
    ``terminal`` and ``direction`` attributes.
    """
    options = {"jac": system.jacobian} if method in IMPLICIT_METHODS else {}
    return solve_ivp(system, (t0, t1), y0, method=method, rtol=rtol, atol=atol,
                     t_eval=t_eval, events=events, max_step=max_step, **options)


#: scipy raises any rtol below 100 machine epsilons to that value (with a warning);
#: ballc rejects such an rtol instead of silently integrating with another one.
MIN_RTOL = 100 * np.finfo(float).eps


def _check_options(scene, t_end, method, rtol, atol, max_step=np.inf):
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a ballc.Scene, got {type(scene).__name__}")
    try:
        if isinstance(t_end, (str, bytes, bool, np.bool_)):
            raise TypeError   # float("5") or float(True) would pass
        t_end = float(t_end)
    except (TypeError, ValueError):
        raise SceneError(f"t_end = {t_end!r} is not allowed: must be a number > 0") from None
    if not (math.isfinite(t_end) and t_end > 0):
        raise SceneError(f"t_end = {t_end!r} is not allowed: must be finite and > 0")
    if method not in SCIPY_METHODS:
        raise SceneError(f"method = {method!r} is not allowed: must be one of {SCIPY_METHODS}")
    for name, value in (("rtol", rtol), ("atol", atol)):
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise SceneError(f"{name} = {value!r} is not allowed: must be a number "
                             "(atol: or one per state)") from None
        if not (np.all(np.isfinite(array)) and np.all(array > 0)):
            raise SceneError(f"{name} = {value!r} is not allowed: must be finite and > 0")
    if np.ndim(rtol) != 0:
        raise SceneError(f"rtol = {rtol!r} is not allowed: must be a single number")
    if float(rtol) < MIN_RTOL:
        raise SceneError(f"rtol = {rtol!r} is not allowed: must be >= 100 machine "
                         f"epsilons = {MIN_RTOL:.3g}")
    if np.ndim(atol) > 1 or np.ndim(atol) == 1 and np.size(atol) != len(_core.STATE_NAMES):
        raise SceneError(f"atol = {atol!r} is not allowed: must be a number or one per "
                         f"state ({len(_core.STATE_NAMES)}: {', '.join(_core.STATE_NAMES)})")
    try:
        max_step_ok = float(max_step) > 0   # NaN fails too
    except (TypeError, ValueError):
        max_step_ok = False
    if not max_step_ok:
        raise SceneError(f"max_step = {max_step!r} is not allowed: must be a number > 0 "
                         "(inf for no limit)")
    return t_end


def simulate(scene: Scene, t_end: float, *, method: str = "Radau", rtol: float = 1e-10,
             atol: float = 1e-10, t_eval=None, max_step: float = np.inf,
             progress: bool | None = None) -> Result:
    """Simulate ``scene`` from t = 0 to ``t_end`` (s).

    Parameters
    ----------
    scene : Scene
    t_end : float
        End time (s), > 0.
    method : str
        A scipy.integrate.solve_ivp method: "Radau" (default), "BDF", "LSODA" (given
        the analytic Jacobian), "DOP853", "RK45", "RK23".
    rtol, atol : float
        Tolerances per segment, as in solve_ivp.
    t_eval : array_like, optional
        Times (s) at which to store the solution; by default every solver step and
        every contact event.
    max_step : float
        Largest step (s).
    progress : bool, optional
        Show a tqdm progress bar in simulated time (advanced once per segment).
        None (default): only when stderr is a terminal.

    Returns
    -------
    Result
        ``status`` 0 when t_end was reached, 1 when a terminal condition stopped the
        run (the ball passed through a plane), -1 when the integrator failed; the
        arrays always hold what was computed up to there.
    """
    t_end = _check_options(scene, t_end, method, rtol, atol, max_step)
    if t_eval is not None:
        t_eval_given = t_eval
        try:
            t_eval = np.asarray(t_eval, dtype=float)
        except (TypeError, ValueError):
            raise SceneError(f"t_eval = {t_eval_given!r} is not allowed: must be "
                             "numbers") from None
        if t_eval.ndim != 1 or not np.all(np.isfinite(t_eval)) or np.any(
                np.diff(t_eval) <= 0) or t_eval.size and (t_eval[0] < 0 or t_eval[-1] > t_end):
            raise SceneError(f"t_eval = {t_eval_given!r} is not allowed: must be a 1-D, "
                             f"strictly increasing sequence within [0, t_end = {t_end}]")

    params = scene.parameter_vector()
    latch = np.zeros(_core.N_LATCH)
    y = scene.initial_state()
    t = 0.0
    in_contact = {plane: False for plane in PLANES}
    open_contacts: dict[str, Contact] = {}
    contacts: list[Contact] = []
    ts, ys = [np.array([t])], [y[:, None]]
    if t_eval is not None:
        keep = t_eval == 0.0
        ts, ys = [t_eval[keep]], [np.repeat(y[:, None], keep.sum(), axis=1)]
    # Per stored sample: the flags and latched values of the segment that computed it,
    # so outputs that need the right-hand side (the observer's acceleration) can
    # re-evaluate it exactly as integrated.  Same shapes as ts/ys (one column per sample).
    flag_columns = [np.full(ts[0].size, _flags(scene, in_contact), dtype=np.int32)]
    latch_columns = [np.zeros((_core.N_LATCH, ts[0].size))]
    bar = _progress_bar(progress, t_end)
    nfev = njev = nlu = 0
    status, message = 0, "The solver successfully reached the end of the integration interval."

    while t < t_end:
        if bar is not None:
            bar.update(t - bar.n)
        system = _core.System(params, latch, _flags(scene, in_contact))
        events = _segment_events(scene, in_contact)
        segment_eval = None
        if t_eval is not None:
            segment_eval = t_eval[(t_eval > t) & (t_eval <= t_end)]
        sol = integrate_segment(system, t, t_end, y, [e[2] for e in events], method=method,
                                rtol=rtol, atol=atol, t_eval=segment_eval, max_step=max_step)
        nfev += sol.nfev
        njev += sol.njev
        nlu += sol.nlu
        first = 1 if t_eval is None else 0   # the segment's start is already stored
        ts.append(sol.t[first:])
        ys.append(sol.y[:, first:])
        flag_columns.append(np.full(ts[-1].size, system.flags, dtype=np.int32))
        latch_columns.append(np.repeat(latch[:, None], ts[-1].size, axis=1))
        for (kind, plane, _), t_hits, y_hits in zip(events, sol.t_events, sol.y_events):
            if kind == "deepest" and len(t_hits):
                depth = max(_penetration(plane, scene)(0, yy) for yy in y_hits)
                open_contacts[plane].max_penetration = max(
                    open_contacts[plane].max_penetration, depth)

        if sol.status == -1:
            status, message = -1, f"integrator failed at t = {sol.t[-1]:.6g} s: {sol.message}"
            break
        if sol.status == 0:
            break
        fired = [(kind, plane, i) for i, (kind, plane, fn) in enumerate(events)
                 if fn.terminal and len(sol.t_events[i])]
        kind, plane, index = fired[0]
        t = float(sol.t_events[index][-1])
        y = np.array(sol.y_events[index][-1])
        y[:4] /= np.linalg.norm(y[:4])
        if kind == "enter":
            rate, direction = _latch_values(y, params, plane)
            k = PLANES.index(plane) * _core.N_LATCH_PER_PLANE
            latch[k] = rate
            latch[k + 1:k + 4] = direction
            in_contact[plane] = True
            contact = Contact(plane=plane, t_start=t, velocity_before=y[_V:_V + 3].copy(),
                              angular_velocity_before=y[_OMEGA:_OMEGA + 3].copy(),
                              penetration_rate_at_impact=rate, digin_direction=direction)
            open_contacts[plane] = contact
            contacts.append(contact)
        elif kind == "leave":
            in_contact[plane] = False
            contact = open_contacts.pop(plane)
            contact.t_end = t
            contact.velocity_after = y[_V:_V + 3].copy()
            contact.angular_velocity_after = y[_OMEGA:_OMEGA + 3].copy()
        else:  # "through"
            open_contacts[plane].max_penetration = scene.radius
            status = 1
            message = (f"ball passed through the {plane} at t = {t:.6g} s "
                       "(penetration reached the ball's radius)")
            break

    if bar is not None:
        bar.update((t_end if status == 0 else t) - bar.n)
        bar.close()
    for plane, contact in open_contacts.items():   # still in contact at the end
        depth = _penetration(plane, scene)(0, ys[-1][:, -1]) if ys[-1].size else 0.0
        contact.max_penetration = max(contact.max_penetration, depth)
    return Result(t=np.concatenate(ts), y=np.concatenate(ys, axis=1), scene=scene,
                  status=status, message=message, nfev=nfev, njev=njev, nlu=nlu,
                  contacts=contacts, flags=np.concatenate(flag_columns),
                  latch=np.concatenate(latch_columns, axis=1))


def _progress_bar(progress, t_end):
    """A tqdm bar over simulated time, or None (progress=None: only on a terminal)."""
    if progress is None:
        progress = sys.stderr.isatty()
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=t_end, unit="s", desc="simulate", leave=False,
                bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")
