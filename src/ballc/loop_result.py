"""The Result of a run, from the C loop's output (``_core.Drive``).

The samples ``t`` and ``y`` and the scalars are read at once; the rest -- the contacts
and their force summaries, ``flags`` and ``latch``, the user events' hits, the dense
output, the segment log and the message with its warnings -- is built from the C loop's
output when first asked for (Result._pending), once.  Only converts: every number is
the C loop's.
"""
from __future__ import annotations

import math
import weakref

import numpy as np

from . import _core, messages, orbit, outcome
from .dense import CompiledInterpolant, PiecewiseSolution
from .flight import FreeFlight
from .resting import AcceleratedRolling, Constant
from .result import Contact, Result


def result_of(scene, options, run, checks_rest=False) -> Result:
    """The Result of ``run`` (a ``_core.Drive``) of ``scene`` with ``options``
    (``checks_rest``: the run checked for end states, run_constants' checks_rest)."""
    result = Result.__new__(Result)
    y = run.rows.T
    blocks = _Blocks(run)
    result.__dict__.update(
        t=run.t, y=y, scene=scene, status=run.status, nfev=run.nfev,
        njev=run.njev, nlu=run.nlu, state_names=scene.state_names, _energy=None,
        method_switches=run.switches() if options.method == "auto" else None,
        _pending={
            "_contact_records": lambda r: run.contacts(),
            "contacts": lambda r: _contacts(scene, r._contact_records, run,
                                            _ForceSummary(run.t, y, blocks, scene)),
            "flags": lambda r: blocks.flags(),
            "latch": lambda r: blocks.latch(),
            "t_events": lambda r: _user_events(r, run, options)[0],
            "y_events": lambda r: _user_events(r, run, options)[1],
            "sol": lambda r: _dense(scene, run, options) if options.dense_output else None,
            "_segment_log": lambda r: run.segment_log(),
            "message": lambda r: _message(r, scene, options, run, checks_rest),
            "_orbit_trials": lambda r: run.trials(),   # ballc.orbit's: (from, to, accepted)
            "_driver_counts": lambda r: {               # the C loop's counters
                "segments": run.segments, "profiled": run.profiled,
                "integrator_ns": run.integrator_ns, "drive_ns": run.drive_ns,
                "integrator_prof": run.integrator_prof}})
    return result


def _message(result, scene, options, run, checks_rest) -> str:
    """How the run ended (ballc.messages), why no end state finished a long contact, and
    the warnings of ballc.outcome."""
    message = messages.run_message(scene, options, run)
    if (checks_rest and run.stop_code == _core.DRIVE_OK and not run.end_kind
            and any(k >= 0 for k in run.open_contacts())):
        message += messages.why_no_end_state(scene, result.contacts, options.t_end)
    message += outcome.tolerance_warning(options.rtol, options.atol)
    message += outcome.balance_warning(result, options.rtol)
    if options.method == "dop853":   # auto switched to radau5 where the test fired
        stiff_at = run.stiff_at
        message += outcome.stiffness_note(None if math.isnan(stiff_at) else stiff_at)
    return message


class _Blocks:
    """Each sample's segment's flags (n,) int64 and latch (the latch's values, n), built
    once from
    the run's blocks (for the Result and for the contacts' force summaries)."""

    __slots__ = ("run", "found")

    def __init__(self, run):
        self.run, self.found = run, None

    def _build(self):
        if self.found is None:
            counts, flags, latches = self.run.blocks()
            self.found = (np.repeat(flags, counts), np.repeat(latches, counts, axis=0).T)
            self.run = None
        return self.found

    def flags(self):
        return self._build()[0]

    def latch(self):
        return self._build()[1]


class _ForceSummary:
    """The force summaries of a run's contacts (ballc.outcome.summarize_contacts),
    computed on first access to one: it holds the samples and the contacts weakly, so a
    run's Result and its contacts make no reference cycle (a sweep drops them at once)."""

    __slots__ = ("contacts", "t", "y", "blocks", "scene")

    def __init__(self, t, y, blocks, scene):
        self.contacts, self.t, self.y, self.blocks, self.scene = [], t, y, blocks, scene

    def __call__(self):
        contacts = [found for found in (ref() for ref in self.contacts) if found is not None]
        outcome.summarize_contacts(contacts, self.t, self.y, self.blocks.latch(),
                                   self.blocks.flags(), self.scene)


def _user_events(result, run, options):
    """(t_events, y_events): per user event its hits' times and states; None without
    user events.  Both are kept."""
    n = len(options.events)
    if n:
        event, times, states = run.user_hits()
        found = ([times[event == k] for k in range(n)], [states[event == k] for k in range(n)])
    else:
        found = ([], [])
    result.__dict__["t_events"], result.__dict__["y_events"] = found
    result._pending.pop("t_events", None)
    result._pending.pop("y_events", None)
    return found


def _contacts(scene, found, run, summary) -> list:
    """The run's contacts (``found``: its contact records, run.contacts()), their phases
    and end states; their force summaries are computed on first access to one
    (``summary``, ballc.outcome.summarize_contacts).  Their vectors are rows of one
    array per field (a contact that did not end: NaN after)."""
    t_end, lost, rates = found["t_end"].tolist(), found["lost"].tolist(), found["rate"]
    v_before, w_before, v_after, w_after, digin, point = (found[name] for name in (
        "v_before", "w_before", "v_after", "w_after", "digin", "contact_point"))
    names, planes = scene.plane_names, scene.planes
    contacts = []
    for k, (plane, kernel_rate, t_start, depth) in enumerate(zip(
            found["plane"].tolist(), found["kernel_rate"].tolist(), found["t_start"].tolist(),
            found["max_penetration"].tolist())):
        contact = Contact.__new__(Contact)
        contact.__dict__.update(
            plane=names[plane], t_start=t_start, t_end=t_end[k],
            velocity_before=v_before[k], angular_velocity_before=w_before[k],
            penetration_rate_at_impact=rates[k] if kernel_rate else float(rates[k]),
            digin_direction=digin[k], velocity_after=v_after[k],
            angular_velocity_after=w_after[k], max_penetration=depth,
            contact_point=point[k][:2], contact_point_z=float(point[k][2]),
            normal=planes[plane].unit_normal, energy_lost_normal=lost[k][0],
            energy_lost_tangential=lost[k][1], transitions=[], t_rest=math.nan,
            t_rolling=math.nan, t_sliding=math.nan, _summary=summary)
        contacts.append(contact)
    summary.contacts = [weakref.ref(contact) for contact in contacts]
    for k, when, phase in run.phases():
        name = _core.PHASE_NAMES[phase]
        contacts[k].transitions.append((when, name))
        if phase >= 2:   # its closed-form end state (ballc.resting, ballc.orbit)
            setattr(contacts[k], {"rest": "t_rest", "rolling": "t_rolling"}.get(
                name, "t_sliding"), when)
    return contacts


def _dense(scene, run, options):
    """sol(t) over the run: the segments' interpolants, and the closed-form end's."""
    gravity = scene.gravity_vector
    pieces = []
    for piece in run.pieces():
        if len(piece) > 3:
            interpolant = CompiledInterpolant(*piece[2:])
        elif isinstance(piece[2], np.ndarray):
            interpolant = FreeFlight(piece[0], piece[2], gravity, t_max=piece[1])
        else:
            interpolant = piece[2]
        pieces.append((piece[0], piece[1], interpolant))
    end = messages.END_KINDS[run.end_kind]
    if end:   # to t_end in closed form
        when, y = run.end_t, run.end_y
        periodic = run.orbit()
        if periodic is not None:   # ballc.orbit: G^k of the trial's solution
            c0, period, motion, _, base = periodic
            base = PiecewiseSolution([(a, b, CompiledInterpolant(*rest)) for a, b, *rest in base])
            closed = orbit.RelativePeriodicOrbit(when, options.t_end, c0, period,
                                                 orbit.Motion.from_array(motion), base)
        elif end == "rest":
            closed = Constant(y)
        elif end == "accelerating":
            closed = AcceleratedRolling(when, y, run.end_acceleration, scene.radius,
                                        scene.planes[run.end_plane].unit_normal,
                                        t_max=options.t_end)
        else:
            closed = FreeFlight(when, y, 0.0, t_max=options.t_end)
        pieces.append((when, options.t_end, closed))
    return PiecewiseSolution(pieces)

