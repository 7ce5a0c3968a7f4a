"""The Result of a run, from the C loop's output (``_core.Drive``).

The samples ``t`` and ``y`` and the scalars are read at once; the rest -- the contacts
and their force summaries, ``flags`` and ``latch``, the user events' hits, the dense
output, the segment log and the message with its warnings -- is built from the C loop's
output when first asked for (Result._pending), once.  Only converts: every number is
the C loop's.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, layout, messages, orbit, outcome
from .dense import CompiledInterpolant, PiecewiseSolution
from .flight import FreeFlight
from .resting import Constant
from .result import Contact, Result

PLANES = layout.PLANES


def result_of(scene, options, run) -> Result:
    """The Result of ``run`` (a ``_core.Drive``) of ``scene`` with ``options``."""
    result = Result.__new__(Result)
    result.__dict__.update(
        t=run.t, y=run.rows.T, scene=scene, status=run.status, nfev=run.nfev,
        njev=run.njev, nlu=run.nlu, state_names=_core.STATE_NAMES, _energy=None,
        method_switches=run.switches() if options.method == "auto" else None,
        _pending={
            "contacts": lambda r: _contacts(r, run),
            "flags": lambda r: _blocks(r, run)[0],
            "latch": lambda r: _blocks(r, run)[1],
            "t_events": lambda r: _user_events(r, run, options)[0],
            "y_events": lambda r: _user_events(r, run, options)[1],
            "sol": lambda r: _dense(scene, run, options) if options.dense_output else None,
            "_segment_log": lambda r: run.segment_log(),
            "message": lambda r: _message(r, scene, options, run),
            "_orbit_trials": lambda r: run.trials(),   # ballc.orbit's: (from, to, accepted)
            "_driver_counts": lambda r: {               # the C loop's counters
                "segments": run.segments, "profiled": run.profiled,
                "integrator_ns": run.integrator_ns, "drive_ns": run.drive_ns,
                "integrator_prof": run.integrator_prof}})
    return result


def _message(result, scene, options, run) -> str:
    """How the run ended (ballc.messages) and the warnings of ballc.outcome."""
    message = messages.run_message(scene, options, run)
    message += outcome.tolerance_warning(options.rtol, options.atol)
    message += outcome.balance_warning(result, options.rtol)
    if options.method == "dop853":   # auto switched to radau5 where the test fired
        stiff_at = run.stiff_at
        message += outcome.stiffness_note(None if math.isnan(stiff_at) else stiff_at)
    return message


def _blocks(result, run):
    """(flags (n,) int32, latch (N_LATCH, n)): each sample's segment's; both are kept."""
    counts, flags, latches = run.blocks()
    flags = np.repeat(flags, counts)
    latch = np.repeat(latches, counts, axis=0).T
    result.__dict__["flags"], result.__dict__["latch"] = flags, latch
    result._pending.pop("flags", None)
    result._pending.pop("latch", None)
    return flags, latch


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


def _contacts(result, run) -> list:
    """The run's contacts, their phases and end states; their force summaries are
    computed on first access to one (ballc.outcome.summarize_contact_forces).  Their
    vectors are rows of one array per field (a contact that did not end: NaN after)."""
    found = run.contacts()
    t_end, lost, rates = found["t_end"].tolist(), found["lost"].tolist(), found["rate"]
    v_before, w_before, v_after, w_after, digin, point = (found[name] for name in (
        "v_before", "w_before", "v_after", "w_after", "digin", "contact_point"))
    contacts = []
    summary = lambda: outcome.summarize_contact_forces(result)   # noqa: E731
    for k, (plane, kernel_rate, t_start, depth) in enumerate(zip(
            found["plane"].tolist(), found["kernel_rate"].tolist(), found["t_start"].tolist(),
            found["max_penetration"].tolist())):
        contact = Contact.__new__(Contact)
        contact.__dict__.update(
            plane=PLANES[plane], t_start=t_start, t_end=t_end[k],
            velocity_before=v_before[k], angular_velocity_before=w_before[k],
            penetration_rate_at_impact=rates[k] if kernel_rate else float(rates[k]),
            digin_direction=digin[k], velocity_after=v_after[k],
            angular_velocity_after=w_after[k], max_penetration=depth,
            contact_point=point[k], energy_lost_normal=lost[k][0],
            energy_lost_tangential=lost[k][1], transitions=[], t_rest=math.nan,
            t_rolling=math.nan, t_sliding=math.nan, _summary=summary)
        contacts.append(contact)
    for k, when, phase in run.phases():
        name = _core.PHASE_NAMES[phase]
        contacts[k].transitions.append((when, name))
        if phase >= 2:   # its closed-form end state (ballc.resting, ballc.orbit)
            setattr(contacts[k], {"rest": "t_rest", "rolling": "t_rolling"}.get(
                name, "t_sliding"), when)
    return contacts


def _dense(scene, run, options):
    """sol(t) over the run: the segments' interpolants, and the closed-form end's."""
    gravity = float(scene.gravity)
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
        else:
            closed = FreeFlight(when, y, 0.0, t_max=options.t_end)
        pieces.append((when, options.t_end, closed))
    return PiecewiseSolution(pieces)

