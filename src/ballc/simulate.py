"""The driver: the segment loop -- pick the mode, integrate, handle the event, go on.

Each segment integrates a pure right-hand side (compiled, with analytic Jacobian)
whose active terms are fixed for the segment (ballc.modes): free flight, or in
contact with the floor or the ceiling, and with exact Coulomb friction each
contact's slip or stick mode (ballc.stickslip).  Mode changes are terminal
integrator events (ballc.events), so no step ever straddles one.  At a contact
start the penetration rate ``rhodot^-`` and the dig-in direction are latched from
the exact event state.  Options are validated by ballc.options, the integrator is
behind ballc.integrate, and a finished run is post-processed by ballc.outcome.
"""
from __future__ import annotations

import math
import os

import numpy as np

from . import (_core, _radau5, automaton, compliantmodes, events as ev, layout, modes,
               orbit, outcome, resting, stickslip)
from ._format import plain
from .dense import CompiledInterpolant, PiecewiseSolution
from .flight import FreeFlight, polynomial_in_flight, scene_allows as flight_scene_allows
from .integrate import Segment, failure_hint, integrate_segment
from .options import (DEFAULT_MAX_NFEV, METHODS, SCIPY_METHODS,  # noqa: F401 (METHODS re-exported)
                      check_options)
from .progress import progress_bar
from .result import Contact, Result
from .samples import Samples
from .user_events import CheckedEvent, UserEvents
from .scene import Scene, SceneError, check_inside, check_speeds

PLANES = layout.PLANES
_STATE = layout.INDEX
_QUATERNION, _DISSIPATED, _DEFLECTION = layout.QUATERNION, layout.DISSIPATED, layout.DEFLECTION
_CENTRE_XY = layout.rows("x", 2)
SUCCESS = "The solver successfully reached the end of the integration interval."
TERMINATED = "A termination event occurred."
#: What the transitions are called in the message of a run whose modes did not settle.
COULOMB_TRANSITIONS = "stick-slip"
COMPLIANT_TRANSITIONS = "the compliant law's elastic/sliding"
#: Events after which the next segment starts with the last segment's next step size.
CARRY_STEP = ("approach", "stop", "clear", "release", "arm", "yield", "restick", "capacity")


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


def _unit(u, speed):
    """u / |u| as an array (u: two floats, speed: |u| > 0)."""
    return np.array([u[0] / speed, u[1] / speed])


class _Run:
    """The state of one simulation between segments: contacts, modes and latches."""

    def __init__(self, scene, options, y):
        self.scene, self.options = scene, options
        self.params = scene.parameter_vector()
        self.latch = np.zeros(_core.N_LATCH)
        self.t, self.y = 0.0, y
        self.exact = stickslip.uses_exact_coulomb(scene)
        self.compliant_modes = compliantmodes.uses_modes(scene)
        self.compliant: dict[str, str | None] = {plane: None for plane in PLANES}
        # the elastic mode's capacity guard row after a capacity event (compliantmodes)
        self.capacity_row: dict[str, int | None] = {plane: None for plane in PLANES}
        self.fired = None   # the driver event being handled
        self.fired_row = None   # a capacity guard's row when it fired (C may toggle it)
        self.armed = {plane: False for plane in PLANES}   # the compliant guards
        self.in_contact = {plane: False for plane in PLANES}
        self.passed: set[str] = set()   # the planes the ball passed through
        self.coulomb: dict[str, str | None] = {plane: None for plane in PLANES}
        self.approach: dict[str, float | None] = {plane: None for plane in PLANES}
        self.relatches = {plane: 0 for plane in PLANES}
        self.transitions = {plane: 0 for plane in PLANES}
        self.open: dict[str, Contact] = {}
        self.dissipated_at_start: dict[str, np.ndarray] = {}
        self.contacts: list[Contact] = []
        self.status, self.message = 0, SUCCESS
        self.last_transition, self.stalled = None, 0   # mode changes that left t unchanged
        self.rearmed: list[tuple[float, np.ndarray]] = []   # this segment's: (t, latch before)
        self.rest_check: dict[str, float] = {}   # plane -> the time of its next rest check
        self.t_rest = None                        # when the ball came to rest (ballc.resting)
        # ballc.orbit: the ball's axis when the scene is Routh's sphere, and the trial
        # under way (the segments integrated to measure an orbit)
        self.orbit_axis = orbit.body_axis(scene) if orbit.applies(scene) else None
        self.orbit_trial: orbit.Trial | None = None
        self.trial_failed = False   # the rest check just ended a trial that was refused
        self._flags: dict[tuple, int] = {}
        self.segment_events = ev.SegmentEvents(scene)
        self.rho = self.segment_events.rho            # plane -> rho(t, y)
        self.arm_depth = self.segment_events.arm_depth
        self.resting_plane = resting.resting_plane(scene)
        # plane -> (the largest step in its contact's impact, the time that bound ends)
        self.contact_step: dict[str, tuple[float, float]] = {}
        self._slip_terms = {plane: stickslip.slip_terms(self.params, plane) for plane in PLANES}

    def flags(self, with_coulomb=True):
        key = (self.in_contact["floor"], self.in_contact["ceiling"],
               self.coulomb["floor"], self.coulomb["ceiling"], with_coulomb,
               self.compliant["floor"], self.compliant["ceiling"],
               self.armed["floor"], self.armed["ceiling"])
        found = self._flags.get(key)
        if found is None:   # a run visits a handful of modes: compute each once
            found = self._flags[key] = modes.flags(
                self.scene, self.in_contact, self.coulomb if with_coulomb else None,
                self.compliant, self.armed)
        return found

    # ---- contacts ----

    def begin_contact(self, kind, plane):
        """Latch the contact's values at the current state; with exact Coulomb friction
        pick its first mode (the state may be projected onto zero slip)."""
        y = self.y
        rate, direction = modes.latch_values(y, self.params, plane, self.scene)
        k = PLANES.index(plane) * _core.N_LATCH_PER_PLANE
        self.latch[k] = rate
        self.latch[k + 1:k + 4] = direction
        y[_DEFLECTION[plane]] = 0.0      # the tangential spring starts relaxed
        self.in_contact[plane] = True
        contact = Contact(plane=plane, t_start=self.t, velocity_before=y[layout.VELOCITY].copy(),
                          normal=self.scene.planes[PLANES.index(plane)].unit_normal,
                          angular_velocity_before=y[layout.ANGULAR_VELOCITY].copy(),
                          penetration_rate_at_impact=rate, digin_direction=direction)
        record_depth(contact, self.rho[plane](0, y), y)
        self.open[plane] = contact
        self.contacts.append(contact)
        self.dissipated_at_start[plane] = y[_DISSIPATED].copy()
        self.relatches[plane] = self.transitions[plane] = 0
        self.rest_check[plane] = resting.first_check(self.scene, self.t) \
            if plane == self.resting_plane else math.inf
        if self.exact:
            self.start_coulomb(plane)
        if self.compliant_modes:
            # a contact starts where rho reaches the arming depth (events.segment_events);
            # one that starts shallower (a scene's initial state) arms there
            self.armed[plane] = self.rho[plane](0, y) >= 0.5 * self.arm_depth[plane]
            mode, self.y = compliantmodes.start(y, self.params, self.latch, plane)
            self.set_compliant(plane, mode)
            self.contact_step[plane] = compliantmodes.step_bound(self.scene, rate, self.t)

    def end_contact(self, kind, plane):
        y = self.y
        self.rest_check.pop(plane, None)
        self.contact_step.pop(plane, None)
        self.in_contact[plane] = False
        self.coulomb[plane] = self.approach[plane] = self.compliant[plane] = None
        self.capacity_row[plane] = None
        contact = self.open.pop(plane)
        contact.t_end = self.t
        contact.velocity_after = y[layout.VELOCITY].copy()
        contact.angular_velocity_after = y[layout.ANGULAR_VELOCITY].copy()
        lost = y[_DISSIPATED] - self.dissipated_at_start.pop(plane)
        contact.energy_lost_normal, contact.energy_lost_tangential = map(float, lost)

    def max_step(self):
        """The largest step (s) of the next segment: the user's, and within a compliant
        contact's impact a fraction of its Hertz time (compliantmodes.step_bound)."""
        step = self.options.max_step
        if not self.contact_step:
            return step
        for bound, until in self.contact_step.values():
            if until > self.t:
                step = min(step, bound)
        return step

    def step_bound_end(self):
        """When the next compliant contact's step bound ends (s; inf without one): a
        segment ends there, so that a persistent contact goes on with the user's."""
        if not self.contact_step:
            return math.inf
        return min([until for _, until in self.contact_step.values() if until > self.t],
                   default=math.inf)

    # ---- the compliant law's modes (ballc.compliantmodes) ----

    def set_compliant(self, plane, mode):
        """Enter the compliant law's ``mode`` on ``plane`` now; the contact records its
        phases as Coulomb's: "slip" (sliding, at the cap) and "stick" (elastic)."""
        self.compliant[plane] = mode
        self.capacity_row[plane] = None
        self.transitions[plane] += 1
        self.record_phase(plane, "slip" if mode == "sliding" else "stick")

    def record_phase(self, plane, phase):
        """The contact on ``plane`` enters ``phase`` ("slip" or "stick") now, unless it
        is in it already (its record of phase starts)."""
        record = self.open[plane].transitions
        if not record or record[-1][1] != phase:
            record.append((self.t, phase))

    def settles(self, plane, what):
        """Count a mode change of ``plane`` now; False (and the run stopped, status -1)
        when its ``what`` transitions have reached a limit (see unsettled)."""
        self.stalled = self.stalled_at(self.t)
        self.last_transition = self.t
        if not self.unsettled(plane, self.stalled):
            return True
        self.status = -1
        self.message = _unsettled_message(what, plane, self.transitions[plane], self.stalled,
                                          self.t)
        return False

    def compliant_event(self, kind, plane):
        """The compliant law's next mode after its guard ``kind`` fired on ``plane``."""
        if not self.settles(plane, COMPLIANT_TRANSITIONS):
            return
        if kind == "capacity":   # a kink of the elastic mode: the segment ends, no change;
            first, second = compliantmodes.CAPACITY_ROWS   # the next watches the way back
            self.capacity_row[plane] = second if self.fired_row == first else first
            return
        if kind == "arm":
            self.armed[plane] = True
        elif kind == "yield" and compliantmodes.load_vanished(self.y, self.params, self.latch,
                                                              plane):
            self.armed[plane] = False     # the contact's last instants: disarmed
            self.set_compliant(plane, "elastic")
            return
        if kind in ("arm", "yield"):
            mode, self.y = compliantmodes.decide(self.y, self.params, self.latch, plane,
                                                 arming=kind == "arm")
            self.set_compliant(plane, mode)
        else:
            self.y = compliantmodes.restick(self.y, self.params, self.latch, plane)
            self.set_compliant(plane, "elastic")

    # ---- exact Coulomb modes (ballc.stickslip) ----

    def clear_speed(self):
        return stickslip.clear_speed(self.scene, self.y, self.options.rtol, self.options.atol)

    def set_mode(self, plane, mode, direction=None, approach=None):
        """Enter ``mode`` on ``plane`` now; the contact records when each phase of slip
        or stick begins.  ``approach``: the slip speed u . d (m/s) at which a free slip's
        approach event fires, when it is not the clear speed (a slip passing by zero)."""
        phase = "stick" if mode == "stick" else "slip"
        self.coulomb[plane] = mode
        self.approach[plane] = approach
        self.transitions[plane] += 1
        if direction is not None:
            stickslip.set_slip_direction(self.latch, plane, direction)
        self.record_phase(plane, phase)

    def settle(self, plane):
        mode, direction, self.y = stickslip.settle(self.scene, self.params, self.latch,
                                                   self.flags(False), plane, self.y)
        self.set_mode(plane, mode, direction)

    def start_coulomb(self, plane):
        """At a contact start: slip freely when |u| is clear of zero, with a fixed
        direction below that, settle (stick, or slip from rest) at u = 0."""
        u, speed, _, clear = self.slip(plane, self.y)
        if speed > 2 * clear:
            self.set_mode(plane, "slip", _unit(u, speed))
        elif speed > 0:
            self.set_mode(plane, "slip_fixed", _unit(u, speed))
        else:
            self.settle(plane)

    def coulomb_event(self, kind, plane):
        """The next exact-Coulomb mode after event ``kind`` on ``plane`` (see stickslip)."""
        if not self.settles(plane, COULOMB_TRANSITIONS):
            return
        u, speed, error, clear = self.slip(plane, self.y)
        direction = _unit(u, speed) if speed > 0 else None
        if kind == "approach":
            # u . d fell to its threshold: u is near zero, passing by it, or has only
            # turned away from d
            self.relatches[plane] += 1
            if (self.relatches[plane] <= stickslip.MAX_RELATCH
                    and self.slips_on_freely(plane, u, speed, error, clear)):
                self.set_mode(plane, "slip", direction, approach=self.approach_speed(clear, speed))
            else:
                self.set_mode(plane, "slip_fixed", direction)
        elif kind == "stop":
            # u . d = 0 with the direction held: a slip left within the integration error
            # is error (settle); one beyond it passes by zero and slips on freely
            if speed <= stickslip.STOP_FACTOR * error:
                self.settle(plane)
            else:
                self.set_mode(plane, "slip", direction, approach=self.approach_speed(clear, speed))
        elif kind == "clear":    # clear of zero again: the direction goes free
            self.set_mode(plane, "slip", direction)
        else:                    # "release": |lambda| reached mu N; slip from rest along -lambda
            index = PLANES.index(plane)
            lam = _core.stick_state(self.y, self.params, self.latch, self.flags(), index)[:2]
            size = float(np.hypot(*lam))
            direction = -lam / size if size > 0 else None
            self.y = _core.remove_slip(self.y, self.params, self.flags(False), index)
            self.set_mode(plane, "slip_fixed", direction)

    def stalled_at(self, t):
        """How many mode changes in a row a change at time t makes without time moving on."""
        return self.stalled + 1 if t == self.last_transition else 0

    def unsettled(self, plane, stalled):
        """Whether ``plane``'s stick-slip transitions have reached a limit (too many in
        one contact, or ``stalled`` at one time): then they do not settle."""
        return (self.transitions[plane] >= stickslip.MAX_TRANSITIONS
                or stalled >= stickslip.MAX_STALLED)

    def slip(self, plane, y):
        """(u (m/s, two floats), |u|, error scale, clear speed) of ``plane``'s slip at
        state y (see stickslip.error_speed and clear_speed)."""
        values = y.tolist()
        u = stickslip.slip_velocity_of(self._slip_terms[plane], values)
        error = stickslip.error_speed(self.scene, values, self.options.rtol, self.options.atol)
        return u, math.hypot(*u), error, stickslip.CLEAR_FACTOR * error

    def slips_on_freely(self, plane, u, speed, error, clear):
        """At an approach: whether the slip is not coming to rest but only turned away
        from d (|u| still clear of zero) or passing by zero (stickslip.passes_by_zero):
        then its direction is re-latched and stays free."""
        return speed > 2 * clear or stickslip.passes_by_zero(
            u, stickslip.slip_direction(self.latch, plane).tolist(), error)

    @staticmethod
    def approach_speed(clear, speed):
        """Where a re-latched free slip's next approach fires (u . d, m/s)."""
        return min(clear, stickslip.APPROACH_FRACTION * speed)

    def rearm_approach(self, plane):
        """The ``rearm`` callable of ``plane``'s approach event (see ballc.events): radau5
        calls it at the event's state, and it takes :meth:`coulomb_event`'s decision
        there.  When that is to re-latch a free slip (u passes by zero, or has only
        turned away from d), it applies it and re-arms the event without ending the
        segment: the right-hand side is the same on both sides (a free slip's force is
        along u/|u|, turned by d only where u . d < 0, which neither the old nor the new
        d is there).  Any other outcome, or a limit reached, declines (None) without
        changing anything: the segment ends and coulomb_event decides as always.  A
        slip swinging past zero fires the event 3-7 times in a microsecond; re-armed,
        that is one segment instead of several."""
        def rearm(t, y):
            stalled = self.stalled_at(t)
            if (self.unsettled(plane, stalled)
                    or self.relatches[plane] + 1 > stickslip.MAX_RELATCH):
                return None
            u, speed, error, clear = self.slip(plane, y)
            if not self.slips_on_freely(plane, u, speed, error, clear):
                return None
            self.stalled, self.last_transition = stalled, t
            self.relatches[plane] += 1
            self.rearmed.append((t, self.latch.copy()))
            direction = _unit(u, speed)
            approach = self.approach_speed(clear, speed)
            self.set_mode(plane, "slip", direction, approach=approach)
            return (stickslip.slip_stop_coefficients(self.params, plane, direction), -approach,
                    self.latch)
        return rearm

    # ---- the resting end state (ballc.resting) ----

    def rest_candidate(self):
        """(plane, time of its next rest check) when the ball is in contact with the
        resting plane alone, else (None, inf)."""
        plane = self.resting_plane
        if plane is None or not self.in_contact[plane] or any(
                self.in_contact[other] for other in PLANES if other != plane):
            return None, math.inf
        return plane, self.rest_check.get(plane, math.inf)

    def end_state(self, plane, t_end):
        """At a rest check: (sample times to t_end, the closed-form solution from now)
        when the contact with ``plane`` has reached an end state -- rest, uniform
        rolling or sliding, the orbit of a wobble whose trial ends now -- else None."""
        if self.check_rest(plane):
            return _closed_form("rest", self.t, self.y, t_end)
        if self.check_rolling(plane) is not None:
            return _closed_form("rolling", self.t, self.y, t_end)
        periodic = self.check_orbit(plane, t_end)
        if periodic is not None:
            return orbit.sample_times(self.t, t_end, periodic.period), periodic
        return None

    def check_rest(self, plane):
        """At a rest check: True (and the rest state entered) when the contact with
        ``plane`` is at rest (resting.at_rest), else schedule the next check."""
        contact = self.open[plane]
        if not resting.at_rest(self.scene, self.y, plane, contact.t_start, self.t,
                               self.options.rtol, self.options.atol):
            self.rest_check[plane] = resting.next_check(self.scene, contact.t_start, self.t)
            return False
        return self.enter_rest(plane)

    def check_rolling(self, plane):
        """At a rest check that found no rest: the uniform state (a new state) when the
        contact rolls or slides freely and uniformly (resting.rolls), else None."""
        contact = self.open[plane]
        speed = self.slip(plane, self.y)[1]
        found = resting.rolls(self.scene, self.y, plane, contact.t_start, self.t,
                              self.options.rtol, self.options.atol, speed, self.params,
                              self.latch, self.flags())
        if found is None:
            return None
        self.y, kind = found
        self.enter_motion(plane, kind)
        self.message = _motion_message(self.scene, plane, self.t, self.y, kind)
        return self.y

    def enter_motion(self, plane, kind):
        """Record that ``plane``'s contact goes on in closed form as ``kind``
        ("rolling" or "free_sliding") from now."""
        _record_end(self.open[plane], kind, self.t)

    # ---- the periodic end state (ballc.orbit) ----

    def plan_orbit_trial(self, plane, t_end):
        """At a rest check that found neither rest nor uniform motion, with no trial
        under way: start an orbit's trial (ballc.orbit) when the scene is Routh's sphere
        and its equations are equivariant here (criteria 1-2) and the trial ends before
        t_end; the next rest check is at the latest at the trial's end."""
        if self.orbit_axis is None or self.orbit_trial is not None:
            return
        if self.trial_failed:   # not at once again: at the next scheduled rest check
            self.trial_failed = False
            return
        omega = self.y[layout.ANGULAR_VELOCITY]
        rate = math.sqrt(float(omega.dot(omega)))
        if not rate > 0:
            return
        guess = 2 * math.pi / rate
        t_to = self.t + orbit.TRIAL_PERIODS * guess
        if not t_to < t_end or not orbit.equivariant(self.params, self.latch, self.flags(),
                                                     self.y, self.orbit_axis):
            return
        self.orbit_trial = orbit.Trial(plane, self.t, t_to, guess)
        self.rest_check[plane] = min(self.rest_check[plane], t_to)

    def check_orbit(self, plane, t_end):
        """At a rest check: when it ends the trial under way, the relative periodic
        orbit from self.t to t_end (ballc.orbit.RelativePeriodicOrbit) if criteria 3-5
        hold, else None (and the trial is over); before the trial's end, None and the
        next check at the latest at its end."""
        trial = self.orbit_trial
        if trial is None or trial.plane != plane:
            return None
        if self.t < trial.t_to:
            self.rest_check[plane] = min(self.rest_check[plane], trial.t_to)
            return None
        self.orbit_trial = None
        self.trial_failed = True
        interpolant = trial.solution(self.t)
        if interpolant is None:
            return None
        options = self.options
        found = orbit.measure(interpolant, trial.t_from, self.t, self.orbit_axis, trial.guess,
                              options.rtol, options.atol,
                              resting.energy_threshold(self.scene, options.rtol, options.atol),
                              self.params)
        if found is None:
            return None
        self.trial_failed = False
        c0, period, motion, rate = found
        _, speed, error, _ = self.slip(plane, self.y)
        # sticking (Coulomb's stick, the compliant law's elastic mode) is rolling
        kind = "rolling" if self.mode(plane) in ("stick", "elastic") or (
            speed <= resting.REST_FACTOR * error) else "free_sliding"
        self.enter_motion(plane, kind)
        self.message = _orbit_message(self.params, plane, self.t, self.y, kind, period,
                                      motion.phi, rate, t_end)
        return orbit.RelativePeriodicOrbit(self.t, t_end, c0, period, motion, interpolant)

    def enter_rest(self, plane):
        self.y = resting.rest_state(self.scene, self.y, plane)
        self.t_rest = self.t
        _record_end(self.open[plane], "rest", self.t)
        self.message = _rest_message(self.scene, plane, self.t)
        return True

    # ---- one event ----

    def handle(self, kind, plane):
        """Apply a terminal event of the driver that fired at (self.t, self.y): the
        handler ballc.automaton's table names for it."""
        getattr(self, automaton.handler_of(kind))(kind, plane)

    def mode(self, plane):
        """``plane``'s mode, as ballc.automaton names it."""
        if not self.in_contact[plane]:
            return "passed_through" if self.status == 1 and plane in self.passed else "flight"
        contact = self.open.get(plane)
        if contact is not None and not math.isnan(contact.t_rest):
            return "resting"
        if contact is not None and not math.isnan(contact.t_rolling):
            return "rolling"
        if contact is not None and not math.isnan(contact.t_sliding):
            return "free_sliding"
        return self.coulomb[plane] or self.compliant[plane] or "contact"

    def pass_through(self, kind, plane):
        """The ball passed through ``plane`` (rho reached r): the run stops, status 1."""
        contact = self.open.pop(plane)   # ended by passing through: no t_end
        contact.max_penetration = self.scene.radius
        self.in_contact[plane] = False
        self.passed.add(plane)
        self.status = 1
        self.message = _through_message(plane, self.t)


def _rest_message(scene, plane, t):
    """The message of a run that came to rest on ``plane`` at ``t`` (either driver)."""
    return (f"{SUCCESS} The ball came to rest on the {plane} at t = {t:.9g} s "
            f"(ballc.resting: static Hertz equilibrium, penetration "
            f"{resting.equilibrium_penetration(scene):.6g} m); from there "
            "to t_end the state is that rest state.")


def _motion_message(scene, plane, t, y, kind):
    """The message of a run that goes on uniformly (``kind`` "rolling" or
    "free_sliding") on ``plane`` from ``t`` in state ``y`` (either driver): its speed
    along the plane."""
    n = scene.planes[scene.plane_names.index(plane)].unit_normal
    velocity = y[layout.VELOCITY]
    if n[0] == 0 and n[1] == 0:   # horizontal: the horizontal speed
        v = float(np.hypot(*velocity[:2]))
    else:
        v = float(np.linalg.norm(velocity - (velocity @ n) * n))
    what = "rolls uniformly" if kind == "rolling" else (
        "slides uniformly (no force opposes its slip)")
    if kind == "rolling" and scene.rolling_resistance > 0:   # held: it can only spin
        spin = float(y[layout.ANGULAR_VELOCITY] @ n)
        what = (f"is held by its rolling resistance and sticks, spinning about the normal "
                f"at {spin:.6g} rad/s (no twisting resistance stops it),")
    return (f"{SUCCESS} The ball {what} on the {plane} from t = "
            f"{t:.9g} s at {v:.6g} m/s (ballc.resting: static Hertz "
            f"equilibrium, penetration "
            f"{resting.equilibrium_penetration(scene):.6g} m); from there "
            f"to t_end the state is that {kind.replace('free_', '')}, in "
            "closed form.")


def _orbit_message(params, plane, t, y, kind, period, phi, rate, t_end):
    """The message of a run that goes on from ``t`` (state ``y``) as a relative periodic
    orbit of ``period`` (s) turning by ``phi`` (rad) per period, its mechanical energy
    having changed at ``rate`` (W) over the trial (either driver)."""
    what = "rolls" if kind == "rolling" else "slides freely"
    kinetic = float(_core.energies(np.ascontiguousarray(y[None, :]), params)[0, 0])
    neglected = -rate * (t_end - t)
    share = neglected / kinetic if kinetic > 0 else math.inf
    return (
        f"{SUCCESS} The ball {what} on the {plane} from t = {t:.9g} s with the "
        f"wobble of its eccentric observer, a relative periodic orbit (ballc.orbit): "
        f"every {period:.9g} s its state repeats turned by {phi:.6g} rad about "
        f"the vertical; from there to t_end the state is that orbit, in closed form. "
        f"The orbit holds the mechanical energy constant; over the trial it changed at "
        f"{rate:.2g} W (the contact's dissipation, and the integration's error at this "
        f"tolerance), {-neglected:.2g} J by t_end ({abs(share):.2g} of the kinetic "
        f"energy)" + (": more than 1 %, so a tighter rtol would resolve it better."
                      if abs(share) > 0.01 else "."))


def _unsettled_message(what, plane, transitions, stalled, t):
    """The message of a run stopped because ``plane``'s ``what`` transitions did not
    settle (either driver)."""
    return (f"{what} transitions on the {plane} did not settle: {transitions} mode changes "
            f"in one contact, {stalled} of them at t = {t:.17g} s")


def _through_message(plane, t):
    """The message of a run stopped where the ball passed through ``plane`` (either
    driver)."""
    return (f"ball passed through the {plane} at t = {t:.6g} s "
            "(penetration reached the ball's radius)")


def _failure_message(scene, options, reason, nfev, end, in_contact):
    """The message of a run whose integrator failed at ``end`` after ``nfev`` calls in
    all, with the integrator's ``reason`` (either driver)."""
    if "max_nfev" in reason:
        reason = (f"gave up after {nfev} right-hand-side evaluations in all "
                  f"(max_nfev = {options.max_nfev})")
    return (f"integrator failed at t = {end:.6g} s: {reason}"
            + failure_hint(scene, in_contact, options.atol))


def _record_end(contact, kind, t):
    """Record on ``contact`` the end state ``kind`` ("rest", "rolling" or
    "free_sliding") it entered at ``t`` (either driver)."""
    if kind == "rest":
        contact.t_rest = t
    elif kind in ("rolling", "accelerating"):
        contact.t_rolling = t
    else:
        contact.t_sliding = t
    contact.transitions.append((t, "rolling" if kind == "accelerating" else kind))


def _closed_form(kind, t, y, t_end, acceleration=None, radius=None, normal=None):
    """(sample times after t up to t_end, the closed-form solution from (t, y)) of the
    end state ``kind``: the rest state, uniform motion (either driver), or rolling down
    an incline uniformly accelerated (``acceleration``, the C loop's)."""
    if kind == "rest":
        return np.array([t_end]), resting.Constant(y)
    if kind == "accelerating":
        motion = resting.AcceleratedRolling(t, y, acceleration, radius, normal, t_max=t_end)
        return motion.sample_times(t_end), motion
    motion = FreeFlight(t, y, 0.0, t_max=t_end)
    return resting.rolling_samples(t, t_end, motion.rate), motion


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
        scene's; the quaternion is
        normalised.  A state in contact with a plane starts that contact (see
        ballc.modes.latch_values for what it latches).
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
        True (default): a ball that has come to rest on the floor (the criterion of
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
        neglects).  Checked only without
        ``t_eval`` and user ``events``.  False: integrate to t_end whatever happens.

    Returns
    -------
    Result
        ``status`` 0 when t_end was reached, 1 when a terminal condition stopped the
        run (the ball passed through a plane, or a terminal user event), -1 when the
        integrator failed; the arrays always hold what was computed up to there.
    """
    options = check_options(scene, t_end, method, rtol, atol, max_step, first_step, t_eval,
                            max_nfev, events, dense_output, exact_flight)
    y_start = check_initial_state(scene, y0)
    seed_layout = _python_driver_runs(scene)
    if not seed_layout or (not os.environ.get("BALLC_PYTHON_DRIVER") and _seams_untouched()):
        config = _c_config(scene, options, progress, rest, checked=not seed_layout)
        if config is not None:
            result = _simulate_c(scene, options, y_start, config, progress)
            if result is not None:
                return result
        if not seed_layout:
            raise SceneError(
                "this run needs what only the Python driver does (a kernel that failed where "
                "it raises), and the Python driver runs only the seed's floor and ceiling "
                "with gravity along -z: simulate() cannot run this scene")
        if scene.rolling_on:
            raise SceneError(
                "this run needs what only the Python driver does (a kernel that failed where "
                "it raises), and rolling resistance runs in the C loop only: simulate() "
                "cannot run this scene")
    run = _Run(scene, options, y_start)
    run.driver = "python"
    t_end, t_eval = options.t_end, options.t_eval
    for plane in PLANES:   # a scene may start in contact: latch as documented in modes
        if ev.penetration(plane, scene)(0.0, run.y) > 0:
            run.begin_contact("enter", plane)
    samples = Samples()
    if t_eval is None:
        samples.add(np.array([0.0]), run.y[:, None], run.flags(), run.latch)
    else:
        keep = t_eval == 0.0
        samples.add(t_eval[keep], np.repeat(run.y[:, None], keep.sum(), axis=1), run.flags(),
                    run.latch)
    skip = 1 if t_eval is None else 0   # a segment's first sample is its start, already stored
    users = UserEvents(options.events)
    user = users.events
    user_t = [[] for _ in user]
    user_y = [[] for _ in user]
    pieces = []
    bar = progress_bar(progress, t_end)
    nfev = njev = nlu = 0
    first = options.first_step
    implicit = False   # method="auto": the segment starts with radau5 (the step carried over)
    switches = []      # method="auto": (t, method switched to), over the run
    stiff_at = None
    checks_rest = rest and t_eval is None and not user

    while run.t < t_end and run.status == 0:
        if bar is not None:
            bar.update(run.t - bar.n)
        flags = run.flags()
        system = Segment(run.params, run.latch, flags)
        driver_events = run.segment_events(run.in_contact, run.y, run.coulomb, run.params,
                                           run.latch, flags, run.clear_speed, run.approach,
                                           run.rearm_approach, run.compliant, run.armed,
                                           run.capacity_row)
        run.rearmed = []
        rest_plane, t_check = run.rest_candidate() if checks_rest else (None, math.inf)
        # a rest check, or the end of a compliant contact's step bound, ends the segment
        t_stop = min(t_check, t_end, run.step_bound_end())
        t_from = run.t
        trial = run.orbit_trial is not None   # an orbit's trial needs dense output
        segment_eval = None
        if t_eval is not None:
            segment_eval = t_eval[(t_eval > run.t) & (t_eval <= t_stop)]
        remaining = None if options.max_nfev is None else max(options.max_nfev - nfev, 1)
        events = [event for _, _, event in driver_events]
        if user:
            events += users.for_segment()
        sol = integrate_segment(system, run.t, t_stop, run.y, events,
                                method=options.method, rtol=options.rtol, atol=options.atol,
                                t_eval=segment_eval, max_step=run.max_step(),
                                max_nfev=remaining, first_step=first,
                                dense_output=options.dense_output or trial,
                                exact_flight=options.exact_flight, auto_implicit=implicit)
        first = None
        implicit = False
        # every integrator's solution is a solve_ivp-style OptimizeResult, a dict: item
        # access is a dict lookup (its attribute access goes through a Python __getattr__)
        nfev += sol["nfev"]
        njev += sol["njev"]
        nlu += sol["nlu"]
        if stiff_at is None and math.isfinite(sol.get("stiff_at", math.nan)):
            stiff_at = sol["stiff_at"]   # dop853's stiffness test fired in this segment
        if options.method == "auto":
            switches += sol.get("switches", ())
        t, t_events, y_events, status = sol["t"], sol["t_events"], sol["y_events"], sol["status"]
        # An event at the segment's very start ends a zero-length segment whose event
        # sample repeats t; keep only later samples so that result.t stays increasing.
        samples.add_later(t, sol["y"], run.t, skip, flags, run.latch, run.rearmed)
        n_driver = len(driver_events)
        fired, t_fired = -1, np.inf   # the earliest terminal event that fired
        for i, hits in enumerate(t_events):
            if not len(hits):
                continue
            if i < n_driver and driver_events[i][0] == "deepest":
                plane = driver_events[i][1]
                for yy in y_events[i]:
                    record_depth(run.open[plane], run.rho[plane](0, yy), yy)
            elif 0 < _core.terminal_count(events[i].terminal) <= len(hits) \
                    and hits[-1] < t_fired:   # stopped at its last occurrence left
                fired, t_fired = i, float(hits[-1])
        if user:
            users.count(t_events[n_driver:])
            for k in range(len(user)):
                user_t[k].append(np.asarray(t_events[n_driver + k], dtype=float))
                user_y[k].append(np.asarray(y_events[n_driver + k], dtype=float).reshape(
                    -1, _core.N_STATES))

        if status == -1:
            run.status = -1
            run.message = _failure_message(scene, options, sol.message, nfev,
                                           t[-1] if t.size else run.t, run.in_contact)
            if options.dense_output and t.size:
                pieces.append((run.t, float(t[-1]), sol.interpolant))
            break
        if trial:
            run.orbit_trial.add(t_from, t_stop if status == 0 else None, sol.get("interpolant"))
        if status == 0:
            if options.dense_output:
                pieces.append((run.t, t_stop, sol.interpolant))
            run.t = t_stop
            if t_stop < t_end:   # a rest check (or a step bound's end)
                run.y = np.array(sol["y"][:, -1])
                if t_stop != t_check:   # only a step bound ended: go on with a fresh step
                    first, implicit = None, sol.get("method_end") == "radau5"
                    continue
                ending = run.end_state(rest_plane, t_end)
                if ending is not None:   # to t_end in closed form
                    times, closed = ending
                    samples.add(times, closed(times), flags, run.latch)
                    if options.dense_output:
                        pieces.append((run.t, t_end, closed))
                    run.y = samples.last_state.copy()
                    run.t = t_end
                    break
                run.plan_orbit_trial(rest_plane, t_end)
                # the next segment starts with its own first step: a step carried over
                # from a segment cut at the check made radau5 crawl in a steel ball's
                # sticking contact (tests/test_stress.py, the ball at rest for 60 s:
                # 3e6 calls by t = 2.5 s instead of 2e4 for the whole run); auto keeps
                # the method it ended with
                first, implicit = None, sol.get("method_end") == "radau5"
                continue
            break
        if fired < 0:
            raise RuntimeError("the integrator stopped on a terminal event (status 1) but "
                               "reported no terminal event hit")
        if options.dense_output:
            pieces.append((run.t, t_fired, sol.interpolant))
        run.t = t_fired
        run.y = state = np.array(y_events[fired][-1])
        quaternion = state[_QUATERNION]   # a view: normalised in place
        quaternion /= math.hypot(*quaternion.tolist())
        if fired >= n_driver:   # a terminal user event
            run.status, run.message = 1, TERMINATED
            break
        kind, plane, run.fired = driver_events[fired]
        if kind == "capacity":   # its row may have toggled inside the segment (C re-arms)
            codes = sol.get("system_events")
            run.fired_row = run.fired._margin if codes is None else _core.margin_event_row(
                int(codes[fired]))
        run.handle(kind, plane)
        h_next = sol.get("h_next", 0)
        if kind in CARRY_STEP and h_next > 0:
            # within a contact the dynamics do not jump at a stick/slip transition: go on
            # with the step the controller had chosen instead of a fresh start
            first = min(h_next, run.max_step())
            # method="auto": the step carried over is the method's, so is the method
            implicit = sol.get("method_end") == "radau5"

    if bar is not None:
        bar.update((t_end if run.status == 0 else run.t) - bar.n)
        bar.close()
    last = samples.last_state
    for plane, contact in run.open.items():   # still in contact at the end
        if last is not None:
            record_depth(contact, ev.penetration(plane, scene)(0, last), last)
    t, y, flags, latch = samples.arrays()
    result = Result(t=t, y=y, scene=scene, status=run.status, message=run.message,
                    nfev=nfev, njev=njev, nlu=nlu, contacts=run.contacts, flags=flags,
                    latch=latch,
                    t_events=[np.concatenate(k) if k else np.empty(0) for k in user_t],
                    y_events=[np.concatenate(k) if k else np.empty((0, _core.N_STATES))
                              for k in user_y],
                    sol=PiecewiseSolution(pieces) if options.dense_output else None,
                    method_switches=switches if options.method == "auto" else None)
    result._driver = "python"
    return _finish(result, options, stiff_at)


def _finish(result, options, stiff_at):
    """The post-processing of a finished run (either driver)."""
    outcome.summarize_contact_forces(result)
    result.message += outcome.tolerance_warning(options.rtol, options.atol)
    result.message += outcome.balance_warning(result, options.rtol)
    if options.method == "dop853":   # auto switched to radau5 where the test fired
        result.message += outcome.stiffness_note(stiff_at)
    return result


# ---- the segment loop in C (ballc._core.drive, _driver.c; docs/c_loop_plan.md) ----
#
# simulate() runs the loop in C when the run is in its subset (_c_config), the
# environment variable BALLC_PYTHON_DRIVER is not set (to anything non-empty) and the
# integrator seam is not wrapped (_seams_untouched).  The results are bit-identical to
# the Python loop above (benchmarks/driver_identical.py, tests/test_c_driver.py).
# Everything else, and a C run that meets what it does not port (a kernel failure
# where Python raises), runs the Python loop from the start.  A rest check that finds
# rest, uniform motion or a relative periodic orbit (ballc.orbit, measured in C) ends
# the C run; the closed-form samples and the message are added here.  ``result._driver`` says which ran ("c" or "python").

#: The C loop's end states (_driver.h: BALLC_END_*; 0 none) by name.
_END_KINDS = (None, "rest", "rolling", "free_sliding", "accelerating")
_SEAMS = (integrate_segment, _radau5.solve_system)


def _seams_untouched():
    """Whether the Python driver's seam to the integrators (integrate_segment here,
    ballc._radau5.solve_system) is the original: a caller that wraps it (a recording,
    a profile, a test counting segments) instruments the Python driver, so gets it."""
    return (globals()["integrate_segment"] is _SEAMS[0]
            and _radau5.solve_system is _SEAMS[1])


_NUMERICS_AGREE: list = []   # once per process: [bool]


def _c_numerics_agree():
    """Whether this process's math.hypot and numpy dot are those the C loop reproduces
    (CPython 3.11's vector_norm, a BLAS ddot of length 3 as an FMA chain): checked once
    on a few thousand random vectors; if not, every run takes the Python driver."""
    if not _NUMERICS_AGREE:
        rng = np.random.default_rng(2022)
        v = rng.standard_normal((4000, 4)) * np.exp(rng.uniform(-30, 30, (4000, 1)))
        three = np.ascontiguousarray(v[:, :3])
        agree = np.array_equal(_core._dot3_fma_many(three),
                               np.array([row.dot(row) for row in three]))
        for n in (2, 3, 4):
            rows = np.ascontiguousarray(v[:, :n])
            agree = agree and np.array_equal(
                _core._hypot_many(rows), np.array([math.hypot(*r) for r in rows.tolist()]))
        _NUMERICS_AGREE.append(bool(agree))
    return _NUMERICS_AGREE[0]


def _python_driver_runs(scene) -> bool:
    """Whether the Python driver (simulate._Run: the seed's floor and ceiling only) can
    run ``scene``: the ceiling_height shorthand and gravity along -z."""
    return scene.ceiling_height is not None and not isinstance(scene.gravity, tuple)


def _c_config(scene, options, progress, rest, checked=False):
    """The constants of a C run (a dict for _core.drive), or None when the run is not
    in the C loop's subset: every method (scipy's through the loop's integrator
    interface), atol one number or one per state, any user events, t_eval (if given)
    strictly increasing, and the process's hypot and dot as the C loop reproduces them
    (_c_numerics_agree).  (``progress``: the bar is the caller's, advanced from C.)
    ``checked``: a scene only the C loop runs (not the seed's planes): the numerics check
    does not apply."""
    width = len(scene.state_names)
    users = _c_user_events(options.events, width)
    t_eval = options.t_eval
    if t_eval is not None:   # the C loop takes each segment's points as a range
        t_eval = np.ascontiguousarray(t_eval, dtype=float)
        if t_eval.ndim != 1 or not np.all(np.diff(t_eval) > 0):
            return None
    if not checked and not _c_numerics_agree():
        return None
    params = scene.parameter_vector()
    n_planes = len(scene.planes)
    flight_allowed = bool(options.exact_flight and flight_scene_allows(params))
    atol = options.atol
    per_state = type(atol) is not float
    observer = _core.flag("observer", 0) if scene.observer_mass != 0 else 0
    resting_plane = resting.resting_plane_index(scene)
    # the rest checks' constants (resting.at_rest, rolls; an incline's, _driver.c)
    checks = resting_plane is not None or scene.gravity_magnitude > 0
    period = resting.REST_PERIODS * resting.oscillation_period(scene) if checks else math.inf
    rest_consts = dict(rest_threshold=math.inf, rho_eq=1.0, z_eq=0.0, rest_weight=0.0,
                       observer_weight=0.0, rolls_dv=0.0, rolls_level=0.0, half_mass=0.0)
    if checks:
        rho_eq = resting.equilibrium_penetration(scene)
        rest_consts = dict(
            rest_threshold=resting.energy_threshold(scene, options.rtol, options.atol),
            rho_eq=rho_eq, z_eq=scene.radius - rho_eq,
            rest_weight=resting.total_mass(scene) * scene.gravity_magnitude,
            observer_weight=scene.observer_mass * scene.gravity_magnitude,
            rolls_dv=resting.speed_tolerance(scene, options.rtol, options.atol),
            rolls_level=float(resting.steady_level(scene)),
            half_mass=0.5 * resting.total_mass(scene))
    modes_on = compliantmodes.uses_modes(scene)
    return dict(
        **rolling_config(scene),
        compliant_modes=int(modes_on),
        starts_armed=int(compliantmodes.starts_armed(scene)),
        arm_force_depth=compliantmodes.arm_force_depth(scene),
        restick_factor=max(1.0, scene.friction_coefficient
                           / max(scene.tangential_stiffness_ratio, 1e-300)),
        damping_positive=int(params[compliantmodes._TANGENTIAL_DAMPING] > 0),
        contact_time_base=compliantmodes.contact_time_base(scene),
        observer_massive=int(scene.observer_mass > 0),
        rolls_allowed=int(flight_scene_allows(params)), orbit_applies=int(orbit.applies(scene)),
        orbit_axis=[float(a) for a in orbit.body_axis(scene)], rest_factor=resting.REST_FACTOR,
        **rest_consts,
        params=params, rtol=options.rtol, t_end=options.t_end,
        atol=float(np.max(atol)) if per_state else atol,   # stickslip.error_speed's
        atol_states=np.ascontiguousarray(atol, dtype=float) if per_state else None,
        scipy=options.method in SCIPY_METHODS, scipy_atol=atol,
        max_step=float(options.max_step), first_step=options.first_step,
        max_nfev=options.max_nfev, method=options.method, observer_bits=observer,
        contact_bits=[modes.contact_flags(scene, plane) for plane in range(n_planes)],
        exact=int(stickslip.uses_exact_coulomb(scene)), radius=float(scene.radius),
        weight=(scene.mass + scene.observer_mass) * scene.gravity_magnitude,
        hertz_k=scene.hertz_stiffness, total_mass=scene.mass + scene.observer_mass,
        rest_period=period,
        resting_plane=-1 if resting_plane is None else resting_plane,
        checks_rest=int(bool(rest) and t_eval is None and not options.events),
        t_eval=t_eval, dense_output=int(bool(options.dense_output)),
        exact_flight=int(flight_allowed), **users)


def rolling_config(scene):
    """The rolling part's constants of a C run (_driver.h): each part's model (0 off, 1
    exact, 2 sds); both 0 without rolling resistance (the run has no rolling states)."""
    model = ROLLING_MODEL_CODES[scene.rolling_model]
    rolling = model if scene.rolling_resistance > 0 else 0
    twisting = model if scene.twisting_resistance > 0 else 0
    return dict(rolling=rolling, twisting=twisting)


#: Scene.rolling_model -> the C loop's code (_driver.h ballc_drive_config.rolling)
ROLLING_MODEL_CODES = {"exact": 1, "sds": 2}


def _c_user_events(events, width):
    """The user's events as the C loop takes them (UserEvents.for_segment): a dict of
    arrays (``width``: the run's states).  A LinearEvent (a subclass too) is
    evaluated in C from its coefficients and offset, and its ``rearm``, if any, called
    back; one whose class overrides ``__call__`` (then its own function), and any other
    callable, is called back (CheckedEvent)."""
    events = list(events or ())
    n = len(events)
    if n == 0:   # the common case: the same (read-only) arrays every run
        if width not in _NO_USER_EVENTS:
            _NO_USER_EVENTS[width] = _c_user_events_of([], width)
        return _NO_USER_EVENTS[width]
    return _c_user_events_of(events, width)


_NO_USER_EVENTS: dict = {}


def _c_user_events_of(events, width):
    n = len(events)
    users = UserEvents(events)
    coef, offset = np.zeros((n, width)), np.zeros(n)
    scale, index = np.zeros(n), np.full(n, -1, dtype=np.intc)
    linear, direction = np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc)
    rearm = np.zeros(n, dtype=np.intc)
    callables, rearms, flies = [], [], True
    for k, event in enumerate(events):   # (options.check_events checked them)
        sign = float(getattr(event, "direction", 0))
        direction[k] = (sign > 0) - (sign < 0)
        if ev.is_linear(event):
            linear[k], coef[k], offset[k] = 1, event.coefficients, float(event.offset)
            if event._index is not None:
                index[k], scale[k] = event._index, event._scale
            flies = flies and polynomial_in_flight(event)   # as flight.applies
            callables.append(None)
            rearms.append(event.rearm)
            rearm[k] = event.rearm is not None
        else:
            flies = False
            callables.append(CheckedEvent(event, k, 0, getattr(event, "direction", 0)))
            rearms.append(None)
    return dict(user_coef=coef, user_offset=offset, user_scale=scale, user_index=index,
                user_linear=linear, user_direction=direction,
                user_count=np.array(users.counts, dtype=np.intc), user_events=callables,
                user_rearm=rearm, user_rearms=rearms, user_flight=int(flies))


def _simulate_c(scene, options, y, config, progress):
    """simulate() with the loop in C; None when it needs the Python loop."""
    bar = progress_bar(progress, options.t_end)   # advanced from C, throttled in wall time
    try:
        out = _core.drive(config["params"], y, config, bar)
        if bar is not None and out is not None:   # to where the run ended
            bar.update((options.t_end if out["status"] == 0 else out["t_run"]) - bar.n)
    finally:
        if bar is not None:
            bar.close()
    if out is None:
        return None
    counts = out["counts"]
    t = out["t"]
    rows = out["rows"]
    block_flags, latches = out["block_flags"], out["latches"]
    end_kind = out["end_kind"]
    gravity = scene.gravity_vector
    names = scene.plane_names
    pieces = [(piece[0], piece[1], _piece(piece, gravity)) for piece in out["pieces"]]
    end = _END_KINDS[end_kind]
    periodic = out["orbit"]   # (c0, period, G, rate, its base's pieces) or None
    if end:   # a rest check found an end state: to t_end in closed form
        when = out["end_t"]
        if periodic is None:
            times, closed = _closed_form(end, when, out["end_y"], options.t_end,
                                         out["end_acceleration"], scene.radius,
                                         scene.planes[out["end_plane"]].unit_normal)
        else:   # ballc.orbit: G^k of the trial's solution over [c0, c0 + T]
            c0, period, motion, _, base = periodic
            base = PiecewiseSolution([(a, b, CompiledInterpolant(*rest)) for a, b, *rest in base])
            closed = orbit.RelativePeriodicOrbit(when, options.t_end, c0, period,
                                                 orbit.Motion.from_array(motion), base)
            times = orbit.sample_times(when, options.t_end, period)
        if options.dense_output:
            pieces.append((when, options.t_end, closed))
        t = np.concatenate([t, times])
        rows = np.concatenate([rows, closed(times).T])
        counts = np.append(counts, times.size)
        block_flags = np.append(block_flags, block_flags[-1])
        latches = np.concatenate([latches, latches[-1:]])
    states = rows.T
    flags = np.repeat(block_flags, counts)
    latch = np.repeat(latches, counts, axis=0).T
    contacts = []
    for rec in out["contacts"]:
        rate = np.float64(rec["rate"]) if rec["rate_is_kernel_value"] else rec["rate"]
        contact = Contact(plane=names[rec["plane"]], t_start=rec["t_start"],
                          normal=scene.planes[rec["plane"]].unit_normal,
                          velocity_before=np.array(rec["v_before"]),
                          angular_velocity_before=np.array(rec["w_before"]),
                          penetration_rate_at_impact=rate,
                          digin_direction=np.array(rec["digin"]))
        contact.max_penetration = rec["max_penetration"]
        if not math.isnan(rec["contact_point"][0]):
            contact.contact_point = np.array(rec["contact_point"][:2])
            contact.contact_point_z = rec["contact_point"][2]
        if rec["ended"]:
            contact.t_end = rec["t_end"]
            contact.velocity_after = np.array(rec["v_after"])
            contact.angular_velocity_after = np.array(rec["w_after"])
            contact.energy_lost_normal, contact.energy_lost_tangential = rec["lost"]
        if rec["passed_through"]:
            contact.max_penetration = scene.radius
        contacts.append(contact)
    for k, when, phase in out["phases"]:
        contacts[k].transitions.append((when, "stick" if phase else "slip"))
    message = SUCCESS
    if end:   # as _Run.enter_rest / enter_motion
        plane = names[out["end_plane"]]
        when = out["end_t"]
        _record_end(contacts[out["open"][out["end_plane"]]], end, when)
        if periodic is not None:
            message = _orbit_message(config["params"], plane, when, out["end_y"], end,
                                     periodic[1], periodic[2][0], periodic[3], options.t_end)
        elif end == "rest":
            message = _rest_message(scene, plane, when)
        elif end == "accelerating":
            message = resting.accelerating_message(scene, plane, when, out["end_y"],
                                                   out["end_acceleration"], SUCCESS)
        else:
            message = _motion_message(scene, plane, when, out["end_y"], end)
    if counts[-1]:   # still in contact at the end
        last = states[:, -1]
        for index, k in enumerate(out["open"]):
            if k >= 0:
                record_depth(contacts[k], penetration(scene, index, last), last)
    code, status = out["stop_code"], out["status"]
    user_event, user_t, user_y = out["user_hits"]
    n_user = len(config["user_count"])
    if code == _core.DRIVE_FAILED:
        message = _failure_message(scene, options, out["message"], out["nfev"],
                                   out["fail_end"], dict(zip(names, out["in_contact"])))
    elif code == _core.DRIVE_UNSETTLED:
        what = (COMPLIANT_TRANSITIONS if out["unsettled_compliant"]
                else COULOMB_TRANSITIONS)
        message = _unsettled_message(what, names[out["stop_plane"]],
                                     out["transitions"][out["stop_plane"]], out["stalled"],
                                     out["t_run"])
    elif code == _core.DRIVE_TERMINATED:
        message = TERMINATED
    elif code == _core.DRIVE_THROUGH:
        message = _through_message(names[out["stop_plane"]], out["t_run"])
    elif code == _core.DRIVE_OK and not end and config["checks_rest"]:
        message += resting.why_no_end_state(scene, contacts, options.t_end)
    result = Result(t=t, y=states, scene=scene, status=status, message=message,
                    state_names=scene.state_names,
                    nfev=out["nfev"], njev=out["njev"], nlu=out["nlu"], contacts=contacts,
                    flags=flags, latch=latch,
                    t_events=[user_t[user_event == k] for k in range(n_user)],
                    y_events=[user_y[user_event == k] for k in range(n_user)],
                    sol=PiecewiseSolution(pieces) if options.dense_output else None,
                    method_switches=out["switches"] if options.method == "auto" else None,
                    _segment_log=out["segment_log"])
    result._driver = "c"
    result._driver_counts = {key: out[key] for key in (
        "segments", "profiled", "integrator_ns", "drive_ns", "integrator_prof")}
    #: ballc.orbit's trials: [(t_from, t_to, accepted)]
    result._orbit_trials = out["trials"]
    stiff_at = out["stiff_at"]
    return _finish(result, options, None if math.isnan(stiff_at) else stiff_at)


def _piece(piece, gravity):
    """One piece of a C run's dense output, from the bridge: (t0, t1, dense_t, dense_c,
    terms, kinds) the compiled integrators' steps, (t0, t1, y0) an exact flight, (t0,
    t1, interpolant) an integrator's own (scipy's)."""
    if len(piece) > 3:
        return CompiledInterpolant(*piece[2:])
    if isinstance(piece[2], np.ndarray):
        return FreeFlight(piece[0], piece[2], gravity, t_max=piece[1])
    return piece[2]


def penetration(scene, plane: int, y) -> float:
    """The ball's penetration rho = r - n . (c - p) (m) of the scene's plane with index
    ``plane`` at state y, as the C loop's events take it (_driver.c, plane_geometry: the
    one coordinate of an axis-aligned plane, scale y[k] + (r + n_k p_k))."""
    plane = scene.planes[plane]
    n, point = plane.unit_normal, plane.point
    r = float(scene.radius)
    position = y[layout.POSITION]
    axes = np.flatnonzero(n)
    if axes.size == 1:
        k = int(axes[0])
        return float(-n[k] * position[k] + (r + n[k] * point[k]))
    return float(-n[0] * position[0] + -n[1] * position[1] + -n[2] * position[2]
                 + (r + (n[0] * point[0] + n[1] * point[1] + n[2] * point[2])))


def record_depth(contact, depth, y):
    """Keep the deepest penetration of a contact and where it happened."""
    if depth >= contact.max_penetration:
        contact.max_penetration = float(depth)
        contact.contact_point = y[_CENTRE_XY].copy()
        contact.contact_point_z = float(y[_STATE["z"]])
