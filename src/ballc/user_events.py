"""The user's event functions as each segment's integrator sees them.

``simulate(events=...)`` takes solve_ivp's events: g(t, y) with optional ``terminal``
(a bool, or as scipy >= 1.12 an integer k: stop at the k-th occurrence) and
``direction``.  A run is many segments, so :class:`UserEvents` counts each event's
occurrences over the run and gives each segment's integrator the occurrences still
left (its ``terminal``).  A function of the user's is called through
:class:`CheckedEvent`, which raises when it returns NaN or another non-number (NaN
is never a sign change: such an event would silently never fire).  A
``ballc.events.LinearEvent`` of the user's cannot return NaN and is evaluated in C or
in closed form: it is passed on as it is (a copy when it counts occurrences).
"""
from __future__ import annotations

import math

from . import _core
from .events import LinearEvent


class CheckedEvent:
    """``function(t, y)`` as a float, or ValueError naming the event, t and the value."""

    __slots__ = ("function", "index", "terminal", "direction")

    def __init__(self, function, index, terminal, direction):
        self.function, self.index = function, index
        self.terminal, self.direction = terminal, direction

    def __call__(self, t, y):
        value = self.function(t, y)
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if not math.isfinite(number):
            raise ValueError(f"events[{self.index}] returned {value!r} at t = {float(t)!r} s: "
                             "an event function must return a finite number (NaN is never "
                             "a sign change, so the event could never fire)")
        return number


class UserEvents:
    """The user's events over one run: each segment's versions and their counts."""

    def __init__(self, events):
        self.events = list(events)
        self.counts = [_core.terminal_count(getattr(e, "terminal", False))
                       for e in self.events]
        self.seen = [0] * len(self.events)

    def for_segment(self) -> list:
        """The events to integrate the next segment with: ``terminal`` is the number of
        occurrences left before the run stops (0: not terminal)."""
        segment = []
        for k, event in enumerate(self.events):
            left = self.counts[k] - self.seen[k] if self.counts[k] else 0
            direction = getattr(event, "direction", 0)
            if isinstance(event, LinearEvent):
                segment.append(event if left == self.counts[k] else
                               event.shifted(0.0, left, direction))
            else:
                segment.append(CheckedEvent(event, k, left, direction))
        return segment

    def count(self, t_events) -> None:
        """Add a segment's occurrences (its t_events of the user's events, in order)."""
        for k, hits in enumerate(t_events):
            self.seen[k] += len(hits)
