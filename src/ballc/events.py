"""Event functions of the driver and the thresholds that keep segments off their zeros.

Every event is callable like a solve_ivp event, ``event(t, y)``, with solve_ivp's
``terminal`` and ``direction`` attributes, so scipy's methods take them as they are;
radau5 evaluates them in C: :class:`LinearEvent` from its coefficients (on a step
g(t) is a cubic), :class:`StickRelease` through the system (the stick force needs the
equations of motion).

A segment's events (:func:`segment_events`): contact start on each plane out of
contact; contact end, passing through and the deepest point on each plane in contact;
and, with exact Coulomb friction (ballc.stickslip), the slip-mode events (approach,
stop, clear) or the stick-mode release.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from . import _core, compliantmodes, layout, stickslip

PLANES = ("floor", "ceiling")
_STATE = layout.INDEX


class LinearEvent:
    """An event that is a linear functional of the state: g(y) = coefficients . y + offset.

    Callable like a solve_ivp event, ``event(t, y)``, with solve_ivp's ``terminal``
    and ``direction`` attributes; the C loop reads ``coefficients`` and ``offset`` and
    evaluates it in C, with every method (a subclass too, unless it overrides
    ``__call__``: see :func:`is_linear`).  Every event of the driver is of this form.
    ``rearm`` (None, or a callable (t, y) -> None or (coefficients, offset, latch)):
    where the terminal event fires, the compiled methods (radau5, dop853, auto) call it
    at the event's state; None stops there as usual, a triple re-arms it -- the event
    becomes coefficients . y + offset for the rest of the segment (the next segment
    starts with the event as given again), the run goes on from that state with
    ``latch`` (N_LATCH values, which must leave the right-hand side unchanged there;
    the samples from then on carry it) and the hit is not reported (see
    ``ballc._radau5.solve_system``).  Exact flight and scipy's methods ignore it.
    """

    __slots__ = ("coefficients", "offset", "terminal", "direction", "_index", "_scale",
                 "rearm")

    def __init__(self, coefficients, offset=0.0, terminal=False, direction=0):
        self.coefficients = np.array(coefficients, dtype=float)
        if self.coefficients.ndim != 1 or self.coefficients.size < len(_core.BALL_STATE_NAMES):
            raise ValueError(f"coefficients must have one value per state (the seed's "
                             f"{_core.N_STATES}, or its scene's state_names), got shape "
                             f"{self.coefficients.shape}")
        self.offset = float(offset)
        # solve_ivp's: a bool, or k > 0: stop at the k-th occurrence
        self.terminal = terminal if isinstance(terminal, bool) else _core.terminal_count(
            terminal)
        self.direction = direction
        self.rearm = None
        nonzero = np.flatnonzero(self.coefficients)
        # one state only (all of the driver's): skip the dot product when called
        self._index = int(nonzero[0]) if nonzero.size == 1 else None
        self._scale = float(self.coefficients[nonzero[0]]) if nonzero.size == 1 else 0.0

    @classmethod
    def over(cls, coefficients, offset, terminal, direction):
        """The same event over ``coefficients`` that the caller has just computed (a
        float64 array of N_STATES values, owned by the event from now on): no copy, no
        shape check -- for the driver, which makes several per segment."""
        event = cls.__new__(cls)
        event.coefficients, event.offset = coefficients, float(offset)
        event.terminal, event.direction = bool(terminal), direction
        event._index, event._scale = None, 0.0   # several states: the dot product
        event.rearm = None
        return event

    @classmethod
    def of_state(cls, name, scale=1.0, offset=0.0, terminal=False, direction=0, scene=None):
        """g(y) = scale * y[name] + offset; the states of ``scene`` (its ``state_names``;
        default: the seed's planes)."""
        names = _core.STATE_NAMES if scene is None else scene.state_names
        coefficients = np.zeros(len(names))
        coefficients[names.index(name)] = scale
        return cls(coefficients, offset, terminal, direction)

    def shifted(self, delta, terminal, direction):
        """g(y) + delta, with its own terminal and direction (shares the coefficients,
        which are never written: one per segment and event, so kept cheap)."""
        event = LinearEvent.__new__(LinearEvent)
        event.coefficients, event._index, event._scale = (self.coefficients, self._index,
                                                          self._scale)
        event.offset = self.offset + float(delta)
        event.terminal = terminal if isinstance(terminal, bool) else _core.terminal_count(
            terminal)
        event.direction = direction
        event.rearm = None
        return event

    def __call__(self, t, y):
        if self._index is not None:
            return self._scale * y[self._index] + self.offset
        return float(self.coefficients @ y) + self.offset

    def __repr__(self):
        terms = " + ".join(f"{c:g}*{_core.STATE_NAMES[i] if i < _core.N_STATES else f'y[{i}]'}"
                           for i, c in enumerate(self.coefficients) if c)
        return (f"LinearEvent({terms} + {self.offset:g}, terminal={self.terminal}, "
                f"direction={self.direction})")


def is_linear(event) -> bool:
    """Whether ``event`` is evaluated from its ``coefficients`` and ``offset`` as the
    linear functional it declares: a :class:`LinearEvent`, or a subclass of it that
    keeps its ``__call__`` (a subclass that overrides ``__call__`` is a function of its
    own, called back as any user event)."""
    return isinstance(event, LinearEvent) and type(event).__call__ is LinearEvent.__call__


@functools.lru_cache(maxsize=64)
def _penetration_of(plane, radius, ceiling_height):
    if plane == "floor":
        return LinearEvent.of_state("z", -1.0, radius)
    return LinearEvent.of_state("z", 1.0, -(ceiling_height - radius))


@functools.lru_cache(maxsize=64)
def _deepest_of(plane):
    normal = 1.0 if plane == "floor" else -1.0
    return LinearEvent.of_state("vz", -normal, 0.0, False, -1)


def penetration(plane, scene):
    """rho(y) of ``plane`` (a LinearEvent): positive when the ball overlaps it (m)."""
    return _penetration_of(plane, float(scene.radius), float(scene.ceiling_height))


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
    return _past(threshold_base(scene, plane), rho0 if entering else -rho0)


def threshold_base(scene, plane):
    """The least contact threshold on ``plane`` (m): 4 ulp of its position."""
    return 4 * math.ulp(compliantmodes.plane_position(scene, plane))


def _past(base, far_side):
    """contact_threshold from its base and how far the segment starts on the far side."""
    return max(base, far_side + base)


def segment_events(scene, in_contact, y0, coulomb=None, params=None, latch=None, flags=0,
                   clear=0.0, approach=None, rearm=None, compliant=None, armed=None,
                   capacity_row=None):
    """Events of one segment starting at state y0: [(kind, plane, event)].

    ``coulomb``: each plane's exact-Coulomb mode ("slip", "slip_fixed", "stick" or None;
    see ballc.stickslip), ``clear`` the slip speed (m/s) below which the slip
    direction is held fixed (a callable () -> that speed is also taken: it is then
    asked only when a plane slips), ``approach`` (optional, per plane) the speed at
    which a free slip's approach event fires when it is not ``clear`` (a slip passing
    by zero).  The stop and release events sit a rounding-level margin past their zero,
    so that a segment starting on it (slip from rest, a stick that starts at the cone)
    does not fire at once.  ``rearm`` (optional): plane -> the ``rearm`` callable of
    that plane's approach event (see :class:`LinearEvent`).  ``compliant`` (optional,
    per plane): the compliant law's mode ("elastic", "sliding" or None; see
    ballc.compliantmodes), whose guard ends the segment; ``armed`` (per plane): whether
    that guard is armed (else the arming depth is the guard); ``capacity_row`` (per
    plane, optional): the row of the elastic mode's capacity guard after a capacity
    event (compliantmodes.capacity_guard).
    """
    return SegmentEvents(scene)(in_contact, y0, coulomb, params, latch, flags, clear,
                                approach, rearm, compliant, armed, capacity_row)


class SegmentEvents:
    """:func:`segment_events` for one scene, with what does not change between the
    segments of a run worked out once (the driver makes one per run): per plane its
    penetration, deepest-point and passing-through events, the rounding margin of its
    contact threshold and the compliant law's arming depth.  Same events, same bits.
    ``rho`` (plane -> its penetration, a LinearEvent) and ``arm_depth`` (plane -> the
    arming depth, m, where a compliant contact begins; None where contacts begin at rho
    = 0: compliantmodes.starts_armed) serve the driver too."""

    def __init__(self, scene):
        self.scene = scene
        self.rho = {plane: penetration(plane, scene) for plane in PLANES}
        self.arm_depth = ({plane: compliantmodes.arm_penetration(scene, plane)
                           for plane in PLANES}
                          if compliantmodes.starts_armed(scene) else None)
        self.planes = []
        for plane in PLANES:
            rho = self.rho[plane]
            self.planes.append((
                plane, rho, rho._index, rho._scale, rho.offset, threshold_base(scene, plane),
                self.arm_depth[plane] if self.arm_depth else None,
                rho.shifted(-scene.radius, True, 1),               # passing through
                _deepest_of(plane)))

    def __call__(self, in_contact, y0, coulomb=None, params=None, latch=None, flags=0,
                 clear=0.0, approach=None, rearm=None, compliant=None, armed=None,
                 capacity_row=None):
        scene = self.scene
        events = []
        append = events.append
        for plane, rho, index, scale, offset, base, arm, through, deepest in self.planes:
            rho0 = scale * y0[index] + offset                      # rho(0, y0)
            if in_contact[plane]:                                  # contact_threshold's
                threshold = _past(base, -rho0)
                append(("leave", plane, rho.shifted(threshold, True, -1)))
                append(("through", plane, through))
                append(("deepest", plane, deepest))
            else:
                threshold = _past(base, rho0)
                if arm is not None:   # the compliant law starts armed
                    threshold = max(threshold, arm)
                append(("enter", plane, rho.shifted(-threshold, True, 1)))
            mode = coulomb[plane] if coulomb else None
            if mode == "slip" or mode == "slip_fixed":
                if callable(clear):
                    clear = clear()
                along = stickslip.slip_stop_coefficients(params, plane,
                                                         stickslip.slip_direction(latch, plane))
                if mode == "slip":   # free direction: freeze it when u . d falls to `clear`
                    speed = approach.get(plane) if approach else None
                    speed = clear if speed is None else speed
                    event = LinearEvent.over(along, -speed, True, -1)
                    if rearm is not None:
                        event.rearm = rearm(plane)
                    append(("approach", plane, event))
                else:                # fixed direction: stop at u . d = 0, or go free at 2 clear
                    margin = 4 * math.ulp(stickslip.speed_scale(scene, y0))
                    append(("stop", plane, LinearEvent.over(along, margin, True, -1)))
                    append(("clear", plane, LinearEvent.over(along, -2 * clear, True, 1)))
            elif mode == "stick":
                load = _core.stick_state(y0, params, latch, flags, PLANES.index(plane))[2]
                append(("release", plane, StickRelease(
                    plane, params, latch, flags, stickslip.force_scale(scene, load))))
            law_mode = compliant[plane] if compliant else None
            if law_mode is not None:
                kind, offset = compliantmodes.guard(scene, law_mode, armed[plane], y0, params,
                                                    latch, plane, rho0)
                if kind == "arm":     # the penetration rising through the arming depth
                    append((kind, plane, rho.shifted(offset, True, 1)))
                else:
                    append((kind, plane, CompliantGuard(plane, kind, params, latch, offset)))
                if kind == "yield":   # the elastic mode: its viscous capacity's kink too
                    capacity = compliantmodes.capacity_guard(
                        scene, y0, params, latch, plane, rho0,
                        capacity_row.get(plane) if capacity_row else None)
                    if capacity is not None:
                        row, offset = capacity
                        append(("capacity", plane, CompliantGuard(
                            plane, "capacity", params, latch, offset, row)))
        return events


class StickRelease:
    """The stick-to-slip event of ``plane``: g = mu N - |lambda| + offset (N).

    Callable like a solve_ivp event (evaluated through ``_core``); radau5 reads
    ``system_event`` (the plane's index) and ``offset`` and evaluates it in C.
    """

    __slots__ = ("stick_plane", "system_event", "offset", "terminal", "direction", "_params",
                 "_latch", "_flags")

    def __init__(self, plane: str, params, latch, flags: int, offset: float):
        self.stick_plane = self.system_event = PLANES.index(plane)
        self.offset = float(offset)
        self.terminal = True
        self.direction = -1
        self._params = np.ascontiguousarray(params, dtype=float)
        self._latch = np.array(latch, dtype=float)
        self._flags = int(flags)

    def __call__(self, t, y):
        y = np.ascontiguousarray(y, dtype=float)
        return float(_core.stick_state(y, self._params, self._latch, self._flags,
                                       self.stick_plane)[3]) + self.offset

    def __repr__(self):
        return (f"StickRelease({PLANES[self.stick_plane]}: mu N - |lambda| + "
                f"{self.offset:g})")


class CompliantGuard:
    """A guard of the compliant law's modes on ``plane`` (see ballc.compliantmodes):
    ``kind`` "yield" (the elastic mode's end: g = 1 - k_t |s| / (mu F_n) + offset),
    "restick" (the sliding mode's end: g = the re-stick margin + offset, m/s) or
    "capacity" (the elastic mode's viscous capacity saturating or freeing: g = the
    capacity margin, or its negative (``row``), + offset, N; ends the segment, no mode
    change), falling through 0.

    Callable like a solve_ivp event (evaluated through ``_core``); radau5 reads
    ``system_event`` and ``offset`` and evaluates it in C.
    """

    ROWS = {"yield": 0, "restick": 1}   # their rows of compliantmodes.margins
    __slots__ = ("plane", "kind", "system_event", "offset", "terminal", "direction",
                 "toggles", "_params", "_latch", "_margin")

    def __init__(self, plane: str, kind: str, params, latch, offset: float, row=None):
        self.plane, self.kind = PLANES.index(plane), kind
        self._margin = self.ROWS[kind] if row is None else int(row)
        # a capacity guard that fires where radau5/dop853 stepped to it is re-armed in C
        # (its other row: the way back) and the segment goes on; else it ends the segment
        self.toggles = kind == "capacity"
        self.system_event = _core.margin_event_code(self._margin, self.plane)
        self.offset = float(offset)
        self.terminal = True
        self.direction = -1
        self._params = np.ascontiguousarray(params, dtype=float)
        self._latch = np.array(latch, dtype=float)

    def __call__(self, t, y):
        y = np.ascontiguousarray(y, dtype=float)
        margins = _core.compliant_margins(y, self._params, self._latch, self.plane)
        return float(margins[self._margin]) + self.offset

    def __repr__(self):
        return f"CompliantGuard({PLANES[self.plane]} {self.kind} + {self.offset:g})"
