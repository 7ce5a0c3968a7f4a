"""Dense output: a continuous solution y(t) over a whole run, piecewise across events.

Each segment between events has its integrator's own interpolant (radau5: the
collocation polynomial of every step, as scipy's ``RadauDenseOutput``; dop853: its
7th-order interpolant, as scipy's ``Dop853DenseOutput``; scipy's
methods: their ``OdeSolution``).  :class:`PiecewiseSolution` joins them the way
scipy's ``OdeSolution`` joins steps: ``sol(t)`` for a scalar t gives the state
(N_STATES,), for an array of times (N_STATES, len(t)).  At an event time shared by
two segments the later segment is used (the state after a latch or a projection).

Like scipy's own solution across solve_ivp's events, sol(t) is continuous within a
segment but may jump at a mode change (a contact start or end, stick <-> slip): the
later segment starts from the event state the driver computed -- a step taken to the
event's time, and at a stick start that state projected onto zero slip -- while the
earlier segment's interpolant ends at its own value there.  The two agree to the
integration tolerance, not exactly (seed, 5 s, rtol 1e-10: 4.2e-9 rad/s in
omega_y at the slip -> stick change at t = 2.6973 s).
"""
from __future__ import annotations

import numpy as np

from . import _core


class CompiledInterpolant:
    """The compiled integrator's dense output of one segment: per step (t_old, t_new),
    y_old and the step's terms (rows of N_STATES), x = (t - t_old) / (t_new - t_old).

    radau5 (3 terms, as scipy's ``RadauDenseOutput``): y = y_old + q1 x + q2 x^2 + q3 x^3.
    dop853 (7 terms F0..F6, as scipy's ``Dop853DenseOutput``):
    y = y_old + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + x (F4 + (1 - x) (F5 + x F6)))))).
    method="auto" (``kinds``: each step's own number of terms): both kinds in one
    segment, each step evaluated by its own formula.  Evaluated in C (_dense.c, the
    one evaluation: the C loop's orbit measurement uses it too).
    """

    def __init__(self, steps, coefficients, terms=3, kinds=None):
        self.steps = np.ascontiguousarray(steps, dtype=float).reshape(-1, 2)
        self.terms = int(terms)
        #: per step, its own number of terms: 3 (radau5) or 7 (dop853); with
        #: method="auto" the two alternate, a radau5 step's rows padded with zeros
        self.kinds = (np.full(len(self.steps), self.terms, dtype=np.intc) if kinds is None
                      else np.ascontiguousarray(kinds, dtype=np.intc).reshape(len(self.steps)))
        width = np.asarray(coefficients).shape[1] if np.ndim(coefficients) == 2 else 0
        self.n = width // (1 + self.terms)
        self.coefficients = np.ascontiguousarray(coefficients, dtype=float).reshape(
            len(self.steps), (1 + self.terms) * self.n)
        self.t_min = float(self.steps[0, 0]) if len(self.steps) else np.nan
        self.t_max = float(self.steps[-1, 1]) if len(self.steps) else np.nan

    def __call__(self, t):
        """y(t): (n,) for a scalar t, (n, len(t)) for a 1-D array of times."""
        t = np.asarray(t, dtype=float)
        y = _core.dense_states(self.steps, self.coefficients, self.kinds, self.terms, self.n,
                               np.ascontiguousarray(t.ravel()))
        return y[:, 0] if t.ndim == 0 else y


class PiecewiseSolution:
    """y(t) over [t_start, t_end] of a run, from the interpolants of its segments."""

    def __init__(self, pieces):
        """``pieces``: [(t0, t1, interpolant)] in time order, t1 of one = t0 of the next."""
        self.pieces = [(float(a), float(b), f) for a, b, f in pieces if b >= a]
        self.t_min = self.pieces[0][0] if self.pieces else np.nan
        self.t_max = self.pieces[-1][1] if self.pieces else np.nan
        self._ends = np.array([b for _, b, _ in self.pieces])

    def __call__(self, t):
        """The state at ``t`` (s): (N_STATES,) for a scalar, (N_STATES, len(t)) for a
        1-D array as scipy's OdeSolution, and (N_STATES,) + t.shape for any other
        array (numpy's rule; scipy's OdeSolution fails on them)."""
        t = np.asarray(t, dtype=float)
        scalar = t.ndim == 0
        tt = t.ravel()
        if not self.pieces:
            raise ValueError("no dense output: the run integrated nothing")
        if np.any((tt < self.t_min) | (tt > self.t_max)) or not np.all(np.isfinite(tt)):
            raise ValueError(f"t = {t!r} is outside the run's interval "
                             f"[{self.t_min}, {self.t_max}]")
        which = np.searchsorted(self._ends, tt, side="right")
        which = np.minimum(which, len(self.pieces) - 1)
        out = None
        for k in np.unique(which):
            mask = which == k
            values = np.asarray(self.pieces[k][2](tt[mask]))
            values = values.reshape(-1, 1) if values.ndim == 1 else values
            if out is None:
                out = np.empty((values.shape[0], tt.size))
            out[:, mask] = values
        if out is None:    # no times: (N_STATES, 0), as scipy
            first = np.asarray(self.pieces[0][2](np.array([self.t_min])))
            out = np.empty((first.reshape(first.shape[0], -1).shape[0], 0))
        return out[:, 0] if scalar else out.reshape((out.shape[0],) + t.shape)

    def __repr__(self):
        return (f"PiecewiseSolution({len(self.pieces)} segments over "
                f"[{self.t_min:.6g}, {self.t_max:.6g}] s)")
