"""The user's event functions, checked as the C loop calls them back.

``simulate(events=...)`` takes solve_ivp's events: g(t, y) with optional ``terminal``
(a bool, or as scipy >= 1.12 an integer k: stop at the k-th occurrence) and
``direction``.  A run is many segments: the C loop counts each event's occurrences over
the run and gives each segment the occurrences still left.  A function of the user's
is called through :class:`CheckedEvent`, which raises when it returns NaN or another
non-number (NaN is never a sign change: such an event would silently never fire).  A
``ballc.events.LinearEvent`` of the user's cannot return NaN and is evaluated in C (or
in closed form in exact flight).
"""
from __future__ import annotations

import math


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
