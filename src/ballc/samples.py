"""The samples a run stores, segment by segment, and their assembly into Result arrays.

Per stored sample: its time, its state, and the flags and latched values of the
segment that computed it, so that outputs which need the right-hand side (the
observer's acceleration, contact forces) can re-evaluate it exactly as integrated.
Segments are kept as views of the integrator's arrays and joined once, at the end.
"""
from __future__ import annotations

import numpy as np


class Samples:
    """The stored samples of a run, one block per segment (see the module docstring)."""

    def __init__(self):
        self._times, self._states = [], []
        self._flags, self._latches, self._counts = [], [], []

    def add(self, t, y, flags, latch):
        """Store times ``t`` (k,) and states ``y`` (N_STATES, k) computed with ``flags``
        and ``latch`` (copied)."""
        self._times.append(t)
        self._states.append(y)
        self._flags.append(flags)
        self._latches.append(latch.copy())
        self._counts.append(t.size)

    def add_later(self, t, y, after, first, flags, latch, changes=()):
        """Store a segment's samples from index ``first`` on that are later than time
        ``after`` (``t`` is non-decreasing: the others are the first few).  ``changes``:
        (time, latch before it) where the latch changed within the segment (a re-armed
        event): the samples up to each such time were computed with that latch, the
        rest with ``latch``."""
        n = t.size
        while first < n and t[first] <= after:
            first += 1
        for when, before in changes:
            cut = max(first, int(np.searchsorted(t, when, side="right")))
            self.add(t[first:cut], y[:, first:cut], flags, before)
            first = cut
        self.add(t[first:], y[:, first:], flags, latch)

    @property
    def last_state(self):
        """The last state of the last block stored, or None when that block is empty."""
        y = self._states[-1]
        return y[:, -1] if y.shape[1] else None

    def arrays(self):
        """(t (n,), y (N_STATES, n), flags (n,) int64, latch (N_LATCH, n)).  ``y`` and
        ``latch`` are in Fortran order: their transposes, one row per sample (what the
        per-sample C kernels take), are contiguous."""
        t = np.concatenate(self._times)
        y = np.concatenate([block.T for block in self._states]).T
        flags = np.repeat(np.array(self._flags, dtype=np.int64), self._counts)
        latch = np.repeat(np.array(self._latches), self._counts, axis=0).T
        return t, y, flags, latch
