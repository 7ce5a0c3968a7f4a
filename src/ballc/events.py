"""Events: the user's linear events, and the planes' penetration.

An event is callable like a solve_ivp event, ``event(t, y)``, with solve_ivp's
``terminal`` and ``direction`` attributes.  :class:`LinearEvent` -- a linear functional
of the state -- is evaluated in C by the C loop from its coefficients (on a step g(t) is
a polynomial, and in exact flight its roots are in closed form); any other callable is
called back.  The C loop's own events (``_driver.c``: segment_events; the guards of
ballc.automaton) are of the same kinds: contact start on each plane out of contact
(rho - threshold, :func:`threshold_base`); contact end, passing through and the deepest
point on each plane in contact; and the slip, stick and compliant modes' guards.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from . import _core, compliantmodes, layout

PLANES = ("floor", "ceiling")
_STATE = layout.INDEX


class LinearEvent:
    """An event that is a linear functional of the state: g(y) = coefficients . y + offset.

    Callable like a solve_ivp event, ``event(t, y)``, with solve_ivp's ``terminal``
    and ``direction`` attributes; the C loop reads ``coefficients`` and ``offset`` and
    evaluates it in C, with every method (a subclass too, unless it overrides
    ``__call__``: see :func:`is_linear`).
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
        # one state only: skip the dot product when called (and in exact flight)
        self._index = int(nonzero[0]) if nonzero.size == 1 else None
        self._scale = float(self.coefficients[nonzero[0]]) if nonzero.size == 1 else 0.0

    @classmethod
    def of_state(cls, name, scale=1.0, offset=0.0, terminal=False, direction=0, scene=None):
        """g(y) = scale * y[name] + offset; the states of ``scene`` (its ``state_names``;
        default: the seed's planes)."""
        names = _core.STATE_NAMES if scene is None else scene.state_names
        coefficients = np.zeros(len(names))
        coefficients[names.index(name)] = scale
        return cls(coefficients, offset, terminal, direction)

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


def penetration(plane, scene):
    """rho(y) of ``plane`` (a LinearEvent): positive when the ball overlaps it (m)."""
    return _penetration_of(plane, float(scene.radius), float(scene.ceiling_height))


def threshold_base(scene, plane):
    """The least contact threshold on ``plane`` (m): 4 ulp of its position.

    A contact's start (end) event is rho - threshold (rho + threshold), the threshold
    putting its value at the segment's start strictly (by >= 4 ulp of the boundary
    height) on the near side of its zero -- max(base, base + rho0) for a segment that
    starts at penetration rho0 on the far side.  Without it a segment starting on a
    boundary sits on the ~1-ulp plateau where rho rounds to exactly 0, which the event
    search counts as a crossing at t0: a ball leaving slowly would "re-enter" at once
    while still moving away, then "leave" again, one ulp per segment, for ever.  The
    thresholds are of order 1e-15 .. 1e-13 m: the contact force they leave out is
    negligible."""
    return 4 * math.ulp(compliantmodes.plane_position(scene, plane))
