"""The driver: integrate segment by segment between contact events.

Each segment integrates a pure right-hand side (compiled, with analytic Jacobian)
whose active terms are fixed for the segment: free flight, or in contact with the
floor and/or ceiling.  Contact start and end are terminal integrator events, so
no step ever straddles a contact boundary.  At contact start the penetration rate
``rhodot^-`` and the dig-in direction are latched from the exact event state.
"""
from __future__ import annotations

import difflib
import math
import sys

import numpy as np
from scipy.integrate import solve_ivp

from . import _core, _radau5, stickslip
from .result import Contact, Result
from .scene import Scene, SceneError

SCIPY_METHODS = ("Radau", "BDF", "LSODA", "DOP853", "RK45", "RK23")
IMPLICIT_METHODS = ("Radau", "BDF", "LSODA")
#: "radau5": ballc's compiled Radau IIA (order 5), scipy's Radau step by step in C.
METHODS = ("radau5",) + SCIPY_METHODS
PLANES = ("floor", "ceiling")

#: Default budget of right-hand-side evaluations of one simulate call.
DEFAULT_MAX_NFEV = 20_000_000

#: Smallest penetration rate latched at impact (m/s).  A contact that starts
#: with a smaller rate (grazing, or a ball settling) uses this instead, so that
#: Hunt-Crossley's damping chi = 3/2 (1 - c_tau) k0 / |rhodot^-| stays finite.
MIN_IMPACT_RATE = 1e-9

_STATE = _core.STATE_INDEX
_QUATERNION = slice(_STATE["qw"], _STATE["qw"] + 4)
_OMEGA, _V = _STATE["omega_x"], _STATE["vx"]
_KIN_PER_PLANE = _core.CONTACT_KINEMATICS_NOUT // len(PLANES)
_DISSIPATED = [_STATE["dissipated_normal"], _STATE["dissipated_tangential"]]
_DEFLECTION = {plane: [_STATE[f"{plane}_deflection_x"], _STATE[f"{plane}_deflection_y"]]
               for plane in PLANES}


class LinearEvent:
    """An event that is a linear functional of the state: g(y) = coefficients . y + offset.

    Callable like a solve_ivp event, ``event(t, y)``, with solve_ivp's ``terminal``
    and ``direction`` attributes; radau5 reads ``coefficients`` and ``offset`` and
    evaluates it in C.  Every event of the driver is of this form.
    """

    __slots__ = ("coefficients", "offset", "terminal", "direction", "_index", "_scale")

    def __init__(self, coefficients, offset=0.0, terminal=False, direction=0):
        self.coefficients = np.array(coefficients, dtype=float)
        if self.coefficients.shape != (_core.N_STATES,):
            raise ValueError(f"coefficients must have shape ({_core.N_STATES},), "
                             f"got {self.coefficients.shape}")
        self.offset = float(offset)
        self.terminal = bool(terminal)
        self.direction = direction
        nonzero = np.flatnonzero(self.coefficients)
        # one state only (all of the driver's): skip the dot product when called
        self._index = int(nonzero[0]) if nonzero.size == 1 else None
        self._scale = float(self.coefficients[nonzero[0]]) if nonzero.size == 1 else 0.0

    @classmethod
    def of_state(cls, name, scale=1.0, offset=0.0, terminal=False, direction=0):
        """g(y) = scale * y[name] + offset."""
        coefficients = np.zeros(_core.N_STATES)
        coefficients[_STATE[name]] = scale
        return cls(coefficients, offset, terminal, direction)

    def shifted(self, delta, terminal, direction):
        """g(y) + delta, with its own terminal and direction."""
        return LinearEvent(self.coefficients, self.offset + delta, terminal, direction)

    def __call__(self, t, y):
        if self._index is not None:
            return self._scale * y[self._index] + self.offset
        return float(self.coefficients @ y) + self.offset

    def __repr__(self):
        terms = " + ".join(f"{c:g}*{_core.STATE_NAMES[i]}"
                           for i, c in enumerate(self.coefficients) if c)
        return (f"LinearEvent({terms} + {self.offset:g}, terminal={self.terminal}, "
                f"direction={self.direction})")


def _penetration(plane, scene):
    """rho(y) of ``plane`` (a LinearEvent): positive when the ball overlaps it (m)."""
    r, h = scene.radius, scene.ceiling_height
    if plane == "floor":
        return LinearEvent.of_state("z", -1.0, r)
    return LinearEvent.of_state("z", 1.0, -(h - r))


def contact_threshold(scene, plane, rho0, entering):
    """How far past rho = 0 a contact's start (or end) event sits, for a segment that
    starts at penetration ``rho0`` (m).

    The event is g = rho - threshold (start) or rho + threshold (end), and the threshold
    puts g(t0) strictly (by >= 4 ulp of the boundary height) on the near side of its
    zero.  Without it a segment starting on a boundary sits on the ~1-ulp plateau where
    rho rounds to exactly 0, which the event search counts as a crossing at t0: a ball
    leaving slowly would "re-enter" at once while still moving away, then "leave"
    again, one ulp per segment, for ever.  A segment that starts a little on the far
    side (an event root located to ~1e-14 m) raises the threshold past rho0, so that a
    crossing within the first step cannot be masked by a second one.  The thresholds
    are of order 1e-15 .. 1e-13 m: the contact force they leave out is negligible.
    """
    boundary = scene.radius if plane == "floor" else scene.ceiling_height - scene.radius
    base = 4 * np.spacing(boundary)
    far_side = rho0 if entering else -rho0
    return max(base, far_side + base)


def _segment_events(scene, in_contact, y0, coulomb=None, params=None, latch=None, flags=0,
                    clear=0.0):
    """Events of one segment starting at state y0: [(kind, plane, event)].

    ``coulomb``: each plane's exact-Coulomb mode ("slip", "slip_fixed", "stick" or None;
    see ballc.stickslip), ``clear`` the slip speed (m/s) below which the slip
    direction is held fixed.  The stop and release events sit a rounding-level margin
    past their zero, so that a segment starting on it (slip from rest, a stick that
    starts at the cone) does not fire at once.
    """
    events = []
    for plane in PLANES:
        rho = _penetration(plane, scene)
        rho0 = rho(0.0, y0)
        if in_contact[plane]:
            normal = 1.0 if plane == "floor" else -1.0
            threshold = contact_threshold(scene, plane, rho0, entering=False)
            events.append(("leave", plane, rho.shifted(threshold, True, -1)))
            events.append(("through", plane, rho.shifted(-scene.radius, True, 1)))
            events.append(("deepest", plane,
                           LinearEvent.of_state("vz", -normal, 0.0, False, -1)))
        else:
            threshold = contact_threshold(scene, plane, rho0, entering=True)
            events.append(("enter", plane, rho.shifted(-threshold, True, 1)))
        mode = coulomb[plane] if coulomb else None
        if mode in ("slip", "slip_fixed"):
            k = PLANES.index(plane) * _core.N_LATCH_PER_PLANE + stickslip._SLIP_DIRECTION
            along = stickslip.slip_stop_coefficients(params, plane, latch[k:k + 2])
            if mode == "slip":   # free direction: freeze it when u . d falls to `clear`
                events.append(("approach", plane, LinearEvent(along, -clear, True, -1)))
            else:                # fixed direction: stop at u . d = 0, or go free at 2 clear
                margin = 4 * np.spacing(stickslip.speed_scale(scene, y0))
                events.append(("stop", plane, LinearEvent(along, margin, True, -1)))
                events.append(("clear", plane, LinearEvent(along, -2 * clear, True, 1)))
        elif mode == "stick":
            load = _core.stick_state(y0, params, latch, flags, PLANES.index(plane))[2]
            events.append(("release", plane, stickslip.StickRelease(
                plane, params, latch, flags, stickslip.force_scale(scene, load))))
    return events


def _flags(scene, in_contact, coulomb=None):
    flags = _core.FLAGS["observer"] if scene.observer_mass != 0 else 0
    mixture = scene.effective_mixture
    for plane in PLANES:
        if not in_contact[plane]:
            continue
        if scene.tangential_model == "compliant":
            flags |= _core.FLAGS[f"{plane}_compliant"]
            continue
        if mixture < 1:
            flags |= _core.FLAGS[f"{plane}_friction"]
        if mixture > 0:
            flags |= _core.FLAGS[f"{plane}_digin"]
        if coulomb:
            flags |= stickslip.mode_flags(plane, coulomb[plane])
    return flags


def _latch_values(y, params, plane, scene=None):
    """(rhodot^-, unit dig-in direction) of ``plane`` at state y.

    At a contact start rho = 0 and rhodot^- is the penetration rate.  A scene that
    starts in contact (rho > 0) latches the rate at which an elastic (Hertz) approach
    would have arrived at its present penetration and rate:
    rhodot^- = sqrt(rhodot^2 + 4/5 k0 rho^(5/2) / m_total), from the energy balance
    1/2 m rhodot^-^2 = 1/2 m rhodot^2 + 2/5 k0 rho^(5/2).  (A ball resting at its
    static penetration thus has the damping it would have after a gentle landing,
    not the infinite damping of rhodot^- = 0.)
    """
    kin = _core.contact_kinematics(np.ascontiguousarray(y[None, :]), params)[0]
    k = PLANES.index(plane) * _KIN_PER_PLANE
    rho, rate, velocity = kin[k], kin[k + 1], kin[k + 2:k + 5]
    if scene is not None and rho > 0:
        stored = 0.8 * scene.hertz_stiffness * rho ** 2.5 / (scene.mass + scene.observer_mass)
        rate = math.sqrt(rate * rate + stored)
    speed = np.linalg.norm(velocity)
    if speed > 0:
        direction = velocity / speed
    else:
        direction = np.array([0.0, 0.0, -1.0 if plane == "floor" else 1.0])
    return max(rate, MIN_IMPACT_RATE), direction


def integrate_segment(system, t0, t1, y0, events, *, method, rtol, atol, t_eval, max_step,
                      max_nfev=None):
    """Integrate one smooth segment; returns a solve_ivp-style solution.

    This is the one seam between the driver and an integrator.  The solution must
    have ``t, y, t_events, y_events, status (0 reached t1, 1 terminal event, -1
    failure), message, nfev, njev, nlu``.  Events are :class:`LinearEvent` (callable
    like solve_ivp events, with ``terminal`` and ``direction``).  ``method`` "radau5"
    runs ballc's compiled Radau IIA on the system's C right-hand side and Jacobian;
    any other is handed to scipy's solve_ivp (with the analytic Jacobian when implicit).
    ``max_nfev``: give up (status -1, keeping what was computed) after that many
    right-hand-side calls.
    """
    if method == "radau5":
        return _radau5.solve_system(system.params, system.latch, system.flags, (t0, t1), y0,
                                    rtol=rtol, atol=atol, max_step=max_step, t_eval=t_eval,
                                    events=events, max_nfev=max_nfev)
    options = {"jac": system.jacobian} if method in IMPLICIT_METHODS else {}
    budget = [_call_budget(system, max_nfev)] if max_nfev is not None else []
    sol = solve_ivp(system, (t0, t1), y0, method=method, rtol=rtol, atol=atol,
                    t_eval=t_eval, events=list(events) + budget, max_step=max_step, **options)
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
    return _event(g, True, -1)


def _event(function, terminal, direction):
    function.terminal = terminal
    function.direction = direction
    return function


#: scipy raises any rtol below 100 machine epsilons to that value (with a warning);
#: ballc rejects such an rtol instead of silently integrating with another one.
MIN_RTOL = 100 * np.finfo(float).eps


def _failure_hint(scene, in_contact):
    """Why a contact segment may defeat the integrator, when the cause is the usual one."""
    if not any(in_contact.values()) or scene.tangential_model not in ("friction", "mixture"):
        return ""
    if scene.friction_coefficient == 0 or scene.effective_mixture == 1:
        return ""
    return (f" (in contact with Coulomb friction: below the regularisation speed "
            f"{scene.friction_regularization_speed:g} m/s friction is a viscous law of "
            "coefficient mu F_n / v_s, too stiff to resolve for hard materials or loose "
            "tolerances; try friction_regularization='smooth' with "
            "friction_regularization_speed >= 1e-6 m/s, or tighter rtol)")


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
    if method not in METHODS:
        close = difflib.get_close_matches(str(method), METHODS, n=1, cutoff=0.5) or [
            m for m in METHODS if m.lower() == str(method).lower()]
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise SceneError(f"method = {method!r} is not allowed: must be one of {METHODS}{hint}")
    for name, value in (("rtol", rtol), ("atol", atol)):
        try:
            if isinstance(value, (str, bytes, bool, np.bool_)) or np.asarray(value).dtype.kind \
                    not in "iuf":
                raise TypeError   # float("1e-5") or float(True) would pass
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


def simulate(scene: Scene, t_end: float, *, method: str = "radau5", rtol: float = 1e-10,
             atol: float = 1e-10, t_eval=None, max_step: float = np.inf,
             progress: bool | None = None, max_nfev: int | None = DEFAULT_MAX_NFEV) -> Result:
    """Simulate ``scene`` from t = 0 to ``t_end`` (s).

    Parameters
    ----------
    scene : Scene
    t_end : float
        End time (s), > 0.
    method : str
        "radau5" (default): ballc's compiled Radau IIA (order 5) -- scipy's Radau
        algorithm in C, same error control and events, ~40-70x less CPU.  Or a
        scipy.integrate.solve_ivp method: "Radau" (the reference radau5 is tested
        against), "BDF", "LSODA" (given the analytic Jacobian), "DOP853", "RK45", "RK23".
    rtol, atol : float
        Tolerances per segment, as in solve_ivp.
    t_eval : array_like, optional
        Times (s) at which to store the solution; by default every solver step and
        every contact event.
    max_step : float
        Largest step (s).
    max_nfev : int or None
        Give up (status -1, message, results so far) after this many right-hand-side
        evaluations in all (default 2e7, about half a minute of radau5); None: no limit.
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
    if max_nfev is not None and (isinstance(max_nfev, bool) or not isinstance(
            max_nfev, (int, np.integer)) or max_nfev <= 0):
        raise SceneError(f"max_nfev = {max_nfev!r} is not allowed: must be None or an "
                         "integer > 0")
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
    exact = stickslip.uses_exact_coulomb(scene)
    in_contact = {plane: False for plane in PLANES}
    coulomb: dict[str, str | None] = {plane: None for plane in PLANES}
    relatches = {plane: 0 for plane in PLANES}
    transitions = {plane: 0 for plane in PLANES}
    open_contacts: dict[str, Contact] = {}
    dissipated_at_start: dict[str, np.ndarray] = {}
    contacts: list[Contact] = []

    def begin_contact(plane, y):
        """Latch the contact's values at state y; returns the (possibly projected) state."""
        rate, direction = _latch_values(y, params, plane, scene)
        k = PLANES.index(plane) * _core.N_LATCH_PER_PLANE
        latch[k] = rate
        latch[k + 1:k + 4] = direction
        y[_DEFLECTION[plane]] = 0.0      # the tangential spring starts relaxed
        in_contact[plane] = True
        contact = Contact(plane=plane, t_start=t, velocity_before=y[_V:_V + 3].copy(),
                          angular_velocity_before=y[_OMEGA:_OMEGA + 3].copy(),
                          penetration_rate_at_impact=rate, digin_direction=direction)
        _record_depth(contact, _penetration(plane, scene)(0, y), y)
        open_contacts[plane] = contact
        contacts.append(contact)
        dissipated_at_start[plane] = y[_DISSIPATED].copy()
        relatches[plane] = transitions[plane] = 0
        if exact:
            y = start_slip_or_settle(plane, y)
        return y

    def start_slip_or_settle(plane, y):
        """At a contact start: slip freely when |u| is clear of zero, with a fixed
        direction below that, settle (stick, or slip from rest) at u = 0."""
        u = stickslip.slip_velocity(params, plane, y)
        speed = float(np.hypot(*u))
        if speed > 2 * stickslip.clear_speed(scene, y, rtol, atol):
            set_mode(plane, "slip", u / speed)
        elif speed > 0:
            set_mode(plane, "slip_fixed", u / speed)
        else:
            y = settle(plane, y)
        return y

    def settle(plane, y):
        mode, direction, y = stickslip.settle(scene, params, latch, _flags(scene, in_contact),
                                              plane, y)
        set_mode(plane, mode, direction)
        return y

    def set_mode(plane, mode, direction=None):
        """Enter ``mode`` on ``plane`` at the current t; the contact records when each
        phase of slip or stick begins."""
        phase = "stick" if mode == "stick" else "slip"
        coulomb[plane] = mode
        transitions[plane] += 1
        if direction is not None:
            stickslip.set_slip_direction(latch, plane, direction)
        record = open_contacts[plane].transitions
        if not record or record[-1][1] != phase:
            record.append((t, phase))

    def coulomb_transition(kind, plane, y):
        """The next exact-Coulomb mode after event ``kind`` on ``plane`` (see stickslip)."""
        u = stickslip.slip_velocity(params, plane, y)
        speed = float(np.hypot(*u))
        clear = stickslip.clear_speed(scene, y, rtol, atol)
        if kind == "approach":   # u . d fell to `clear`: near zero, or only turned away
            relatches[plane] += 1
            if speed <= 2 * clear or relatches[plane] > stickslip.MAX_RELATCH:
                set_mode(plane, "slip_fixed", u / speed)
            else:
                set_mode(plane, "slip", u / speed)
        elif kind == "stop":     # u . d = 0 with the direction held: what is left is error
            if speed <= clear:
                y = settle(plane, y)
            else:
                set_mode(plane, "slip", u / speed)
        elif kind == "clear":    # clear of zero again: the direction goes free
            set_mode(plane, "slip", u / speed)
        else:                    # "release": |lambda| reached mu N; slip from rest along -lambda
            stick_flags = _flags(scene, in_contact, coulomb)
            lam = _core.stick_state(y, params, latch, stick_flags, PLANES.index(plane))[:2]
            size = float(np.hypot(*lam))
            direction = -lam / size if size > 0 else latch_slip_direction(latch, plane)
            y = _core.remove_slip(y, params, _flags(scene, in_contact), PLANES.index(plane))
            set_mode(plane, "slip_fixed", direction)
        return y

    for plane in PLANES:   # a scene may start in contact (issue 9): latch as documented
        if _penetration(plane, scene)(0.0, y) > 0:
            y = begin_contact(plane, y)
    ts, ys = [np.array([t])], [y[:, None]]
    if t_eval is not None:
        keep = t_eval == 0.0
        ts, ys = [t_eval[keep]], [np.repeat(y[:, None], keep.sum(), axis=1)]
    # Per stored sample: the flags and latched values of the segment that computed it,
    # so outputs that need the right-hand side (the observer's acceleration) can
    # re-evaluate it exactly as integrated.  Same shapes as ts/ys (one column per sample).
    flag_columns = [np.full(ts[0].size, _flags(scene, in_contact, coulomb), dtype=np.int32)]
    latch_columns = [np.repeat(latch[:, None], ts[0].size, axis=1)]
    bar = _progress_bar(progress, t_end)
    nfev = njev = nlu = 0
    status, message = 0, "The solver successfully reached the end of the integration interval."

    while t < t_end:
        if bar is not None:
            bar.update(t - bar.n)
        flags = _flags(scene, in_contact, coulomb)
        system = _core.System(params, latch, flags)
        clear = stickslip.clear_speed(scene, y, rtol, atol)
        events = _segment_events(scene, in_contact, y, coulomb, params, latch, flags, clear)
        segment_eval = None
        if t_eval is not None:
            segment_eval = t_eval[(t_eval > t) & (t_eval <= t_end)]
        remaining = None if max_nfev is None else max(max_nfev - nfev, 1)
        sol = integrate_segment(system, t, t_end, y, [e[2] for e in events], method=method,
                                rtol=rtol, atol=atol, t_eval=segment_eval, max_step=max_step,
                                max_nfev=remaining)
        nfev += sol.nfev
        njev += sol.njev
        nlu += sol.nlu
        first = 1 if t_eval is None else 0   # the segment's start is already stored
        # Issue 6: an event at the segment's very start (a ball that starts touching a
        # plane and moving into it) ends a zero-length segment whose event sample
        # repeats t; keep only later samples so that result.t stays strictly increasing.
        later = sol.t[first:] > t
        ts.append(sol.t[first:][later])
        ys.append(sol.y[:, first:][:, later])
        flag_columns.append(np.full(ts[-1].size, system.flags, dtype=np.int32))
        latch_columns.append(np.repeat(latch[:, None], ts[-1].size, axis=1))
        for (kind, plane, _), t_hits, y_hits in zip(events, sol.t_events, sol.y_events):
            if kind == "deepest" and len(t_hits):
                for yy in y_hits:
                    _record_depth(open_contacts[plane], _penetration(plane, scene)(0, yy), yy)

        if sol.status == -1:
            status = -1
            message = (f"integrator failed at t = {sol.t[-1]:.6g} s: {sol.message}"
                       + _failure_hint(scene, in_contact))
            break
        if sol.status == 0:
            break
        fired = [(kind, plane, i) for i, (kind, plane, fn) in enumerate(events)
                 if fn.terminal and len(sol.t_events[i])]
        kind, plane, index = fired[0]
        t = float(sol.t_events[index][-1])
        y = np.array(sol.y_events[index][-1])
        y[_QUATERNION] /= np.linalg.norm(y[_QUATERNION])
        if kind == "enter":
            y = begin_contact(plane, y)
        elif kind in ("approach", "stop", "clear", "release"):
            if transitions[plane] >= stickslip.MAX_TRANSITIONS:
                status = -1
                message = (f"stick-slip transitions on the {plane} did not settle: "
                           f"{transitions[plane]} mode changes in one contact by t = {t:.9g} s")
                break
            y = coulomb_transition(kind, plane, y)
        elif kind == "leave":
            in_contact[plane] = False
            coulomb[plane] = None
            contact = open_contacts.pop(plane)
            contact.t_end = t
            contact.velocity_after = y[_V:_V + 3].copy()
            contact.angular_velocity_after = y[_OMEGA:_OMEGA + 3].copy()
            lost = y[_DISSIPATED] - dissipated_at_start.pop(plane)
            contact.energy_lost_normal, contact.energy_lost_tangential = map(float, lost)
        else:  # "through"
            contact = open_contacts.pop(plane)   # ended by passing through: no t_end
            contact.max_penetration = scene.radius
            status = 1
            message = (f"ball passed through the {plane} at t = {t:.6g} s "
                       "(penetration reached the ball's radius)")
            break

    if bar is not None:
        bar.update((t_end if status == 0 else t) - bar.n)
        bar.close()
    for plane, contact in open_contacts.items():   # still in contact at the end
        if ys[-1].size:
            _record_depth(contact, _penetration(plane, scene)(0, ys[-1][:, -1]), ys[-1][:, -1])
    result = Result(t=np.concatenate(ts), y=np.concatenate(ys, axis=1), scene=scene,
                    status=status, message=message, nfev=nfev, njev=njev, nlu=nlu,
                    contacts=contacts, flags=np.concatenate(flag_columns),
                    latch=np.concatenate(latch_columns, axis=1))
    summarize_contact_forces(result)
    result.message += _balance_warning(result, rtol)
    return result


def _balance_warning(result, rtol):
    """A warning for the message when the integrated energy balance does not close.

    kinetic + potential + spring + dissipated is conserved by the equations for every
    model (dissipation is integrated with the motion), so a drift beyond what the
    tolerances allow is an integration artefact, not physics: say so.
    """
    balance = result.energy["balance"]
    scale = max(abs(balance[0]), 1.0)
    drift = float(np.max(np.abs(balance - balance[0])))
    allowed = max(1e-6, 1e3 * float(np.max(rtol))) * scale
    if not drift > allowed:
        return ""
    return (f" Warning: the energy balance (kinetic + potential + spring + dissipated) "
            f"drifted by {drift:.3g} J ({drift / scale:.2g} of the initial energy): the "
            "integration is not accurate at this tolerance, so neither is this result; "
            "tighten rtol/atol.")


def latch_slip_direction(latch, plane):
    k = PLANES.index(plane) * _core.N_LATCH_PER_PLANE + stickslip._SLIP_DIRECTION
    return np.array(latch[k:k + 2])


def _record_depth(contact, depth, y):
    """Keep the deepest penetration of a contact and where it happened."""
    if depth >= contact.max_penetration:
        contact.max_penetration = float(depth)
        contact.contact_point = y[[_STATE["x"], _STATE["y"]]].copy()


#: |F_t| >= STICK_SLIP_THRESHOLD * mu F_n counts as slipping (at the Coulomb cap).
STICK_SLIP_THRESHOLD = 0.999


def summarize_contact_forces(result):
    """Peak normal force and sticking / slipping time of every contact, from the
    stored samples (solver steps, or t_eval: the resolution is that of the samples);
    with exact Coulomb friction the sticking and slipping times come from the
    transition events instead."""
    scene = result.scene
    params = scene.parameter_vector()
    mu = scene.friction_coefficient
    for contact in result.contacts:
        end = contact.t_end if np.isfinite(contact.t_end) else result.t[-1]
        inside = np.flatnonzero((result.t >= contact.t_start) & (result.t <= end))
        if inside.size == 0:
            continue
        k = PLANES.index(contact.plane)
        normal = 1.0 if contact.plane == "floor" else -1.0
        states = np.ascontiguousarray(result.y[:, inside].T)
        forces = np.empty((inside.size, 3))
        for j, i in enumerate(inside):
            f = _core.contact_forces(states[j:j + 1], params,
                                     np.ascontiguousarray(result.latch[:, i]),
                                     int(result.flags[i]))[0]
            forces[j] = f[3 * k:3 * k + 3]
        f_n = forces[:, 2] * normal
        f_t = np.hypot(forces[:, 0], forces[:, 1])
        contact.peak_normal_force = float(f_n.max())
        if contact.transitions:   # exact Coulomb friction: the phases are events
            contact.time_sticking, contact.time_slipping = _phase_times(contact, end)
            continue
        slipping = (f_t >= STICK_SLIP_THRESHOLD * mu * f_n) & (f_n > 0)
        t = result.t[inside]
        dt = np.diff(t)
        slip_fraction = 0.5 * (slipping[1:].astype(float) + slipping[:-1])
        contact.time_slipping = float(np.sum(dt * slip_fraction))
        contact.time_sticking = float(np.sum(dt) - contact.time_slipping)


def _phase_times(contact, end):
    """(time sticking, time slipping) from a contact's transition events (s)."""
    starts = [t for t, _ in contact.transitions] + [end]
    durations = np.diff(starts)
    sticking = sum(d for d, (_, phase) in zip(durations, contact.transitions) if phase == "stick")
    return float(sticking), float(end - contact.t_start - sticking)


def _progress_bar(progress, t_end):
    """A tqdm bar over simulated time, or None (progress=None: only on a terminal)."""
    if progress is None:
        progress = sys.stderr.isatty()
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=t_end, unit="s", desc="simulate", leave=False,
                bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")
