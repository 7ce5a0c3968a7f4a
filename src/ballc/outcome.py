"""What one simulation amounts to: contacts, energy lost, and "did the ball come back".

"Came back" is the superball-under-a-table question: a ball thrown forward bounces on
the floor, on the underside of the table (the ceiling) and on the floor again; it came
back when, after those first ``after_contacts`` = 3 completed contacts, its x-velocity
has the opposite sign of the x-velocity it was thrown with.  The verdict has three
values: True (came back), False (did not: the x-velocity after the third contact is
zero or along the throw) and None, undetermined, when the run completed fewer contacts
than the criterion needs (too short, or it failed first) or the ball was thrown without
x-velocity (there is no "back").
"""
from __future__ import annotations

import math

import numpy as np

from . import _core

#: Contacts of the classic experiment: floor, table underside, floor.
CAME_BACK_AFTER_CONTACTS = 3


def came_back(result, after_contacts: int = CAME_BACK_AFTER_CONTACTS):
    """True when the x-velocity after the first ``after_contacts`` completed contacts
    is opposite to the initial x-velocity, False when it is not, None (undetermined)
    with fewer completed contacts or no initial x-velocity (see the module docstring)."""
    return _came_back(result.velocity[0, 0], *contact_columns(result, "t_end", "vx_after"),
                      after_contacts)


def _came_back(thrown, t_end, after, after_contacts):
    """came_back from the throw's x-velocity and the contacts' t_end and x-velocity after."""
    done = np.flatnonzero(np.isfinite(t_end))[:after_contacts]
    if len(done) < after_contacts or thrown == 0:
        return None
    return bool(np.sign(after[done[-1]]) == -np.sign(thrown))


def verdict(came, after_contacts: int = CAME_BACK_AFTER_CONTACTS) -> str:
    """came_back's answer in words, for the terminal."""
    if came is None:
        return (f"whether the ball came back is UNDETERMINED (it needs {after_contacts} "
                "completed contacts and a throw with x-velocity; run longer)")
    return (f"the ball {'CAME BACK' if came else 'did NOT come back'} (x-velocity after "
            f"the first {after_contacts} contacts vs. the throw)")


def first_reversal(result):
    """The first contact at which the x-velocity changed sign, or None."""
    k = _first_reversal(*contact_columns(result, "vx_before", "vx_after"))
    return None if k is None else result.contacts[k]


def _first_reversal(before, after):
    """The index of the first contact whose x-velocity changed sign, or None."""
    reversed_ = np.flatnonzero(np.isfinite(after) & (before * after < 0))
    return int(reversed_[0]) if len(reversed_) else None


#: contact_columns' names -> (the C loop's contact record, the Contact attribute, and
#: the component of a vector: None for a number)
_CONTACT_COLUMNS = {"t_start": ("t_start", "t_start", None),
                    "t_end": ("t_end", "t_end", None),
                    "vx_before": ("v_before", "velocity_before", 0),
                    "vx_after": ("v_after", "velocity_after", 0)}


def contact_columns(result, *names) -> list:
    """The run's contacts' ``names`` (t_start, t_end (s), vx_before, vx_after (m/s)),
    one array each: from the C loop's contact records when the result has them (a run:
    no Contact object is built), else from its contacts (a Result read from a file)."""
    columns = [_CONTACT_COLUMNS[name] for name in names]
    records = getattr(result, "_contact_records", None)
    if records is not None:
        return [records[key] if i is None else records[key][:, i] for key, _, i in columns]
    contacts = result.contacts
    return [np.array([getattr(c, attribute) if i is None else getattr(c, attribute)[i]
                      for c in contacts], dtype=float) for _, attribute, i in columns]


def summary(result) -> dict:
    """Plain numbers of one run: contacts, came_back (True, False or None:
    undetermined), energies (J), solver status."""
    total = result.energy["total"]
    t_start, t_end, before, after = contact_columns(result, "t_start", "t_end", "vx_before",
                                                    "vx_after")
    reversal = _first_reversal(before, after)
    return {
        "contacts": len(t_start),
        "came_back": _came_back(result.velocity[0, 0], t_end, after, CAME_BACK_AFTER_CONTACTS),
        "first_reversal_time": (float(t_start[reversal]) if reversal is not None
                                else float("nan")),                              # s
        "energy_initial": float(total[0]),                                       # J
        "energy_final": float(total[-1]),                                        # J
        "energy_lost": float(total[0] - total[-1]),                              # J
        "energy_lost_fraction": (float((total[0] - total[-1]) / total[0]) if total[0]
                                 else float("nan")),
        "t_final": float(result.t[-1]),                                          # s
        "status": int(result.status),
        "message": result.message,
    }


def format_summary(result) -> str:
    """A few lines for the terminal."""
    s = summary(result)
    # A model that injects energy (dig-in) ends with more than it started with: say
    # "gained", never "lost -4013.63 J".
    change = "lost" if s["energy_lost"] >= 0 else "gained"
    lines = [
        f"{s['contacts']} contacts in {s['t_final']:g} s; status {s['status']}: {s['message']}",
        f"energy {s['energy_initial']:.2f} J -> {s['energy_final']:.2f} J "
        f"({change} {abs(s['energy_lost']):.2f} J, "
        f"{100 * abs(s['energy_lost_fraction']):.1f} % of the initial energy)",
    ]
    reversal = first_reversal(result)
    if reversal is not None:
        lines.append(f"the x-velocity first reverses at the {reversal.plane} contact at "
                     f"t = {reversal.t_start:.3f} s ({reversal.velocity_before[0]:+.2f} -> "
                     f"{reversal.velocity_after[0]:+.2f} m/s)")
    lines.append(verdict(s["came_back"]))
    return "\n".join(lines)


# ---- post-processing of a finished run (its Result calls these on first access) ----

#: The loosest tolerance ballc is tested at (the stress matrix, the come-back maps'
#: rtol = atol = 1e-3): with a looser rtol or atol the result is not to be trusted,
#: whatever the method and whatever the other checks say (docs/limits.md).
LOOSEST_TRUSTED_TOLERANCE = 1e-3
#: The energy balance may drift by 1e3 rtol of the energy scale, never by more than
#: this fraction of it (1 %; measured on the seed, friction and compliant scenes at
#: rtol = atol 1e-2 ... 1e-6 with both compiled methods: at most 0.34 %).
MAX_BALANCE_DRIFT = 1e-2


def tolerance_warning(rtol, atol) -> str:
    """A warning for the message when rtol or atol is looser than the loosest
    tolerance ballc is tested at (LOOSEST_TRUSTED_TOLERANCE); "" otherwise."""
    largest = [(name, value if type(value) is float else float(np.max(value)))
               for name, value in (("rtol", rtol), ("atol", atol))]
    loose = [f"{name} = {value:g}" for name, value in largest
             if value > LOOSEST_TRUSTED_TOLERANCE]
    if not loose:
        return ""
    return (f" Warning: {' and '.join(loose)} is looser than "
            f"{LOOSEST_TRUSTED_TOLERANCE:g}, the loosest tolerance ballc is tested at: do not "
            "trust this result (contacts can be missed, merged or misplaced); use rtol and "
            f"atol <= {LOOSEST_TRUSTED_TOLERANCE:g}.")


def balance_warning(result, rtol):
    """A warning for the message when the integrated energy balance does not close.

    kinetic + potential + spring + dissipated is conserved by the equations for every
    model (dissipation is integrated with the motion), so a drift beyond what the
    tolerances allow -- 1e3 rtol of the energy scale (the initial energy, at least 1 J),
    at most MAX_BALANCE_DRIFT of it, at least 1e-6 of it -- is an integration artefact,
    not physics: say so.  The same check for every method.
    """
    balance = result.energy["balance"]
    scale = max(abs(balance[0]), 1.0)
    drift = float(np.abs(balance - balance[0]).max())
    largest_rtol = rtol if type(rtol) is float else float(np.max(rtol))
    allowed = max(1e-6, min(1e3 * largest_rtol, MAX_BALANCE_DRIFT)) * scale
    if not drift > allowed:
        return ""
    of = "the initial energy" if abs(balance[0]) >= 1.0 else "1 J"
    share = drift / scale
    share = f"{share:.2g}× {of}" if share >= 1 else f"{100 * share:.2g} % of {of}"
    return (f" Warning: the energy balance (kinetic + potential + spring + dissipated) "
            f"drifted by {drift:.3g} J ({share}): the "
            "integration is not accurate at this tolerance, so neither is this result; "
            "tighten rtol/atol.")


#: |F_t| >= STICK_SLIP_THRESHOLD * mu F_n counts as slipping (at the Coulomb cap).
STICK_SLIP_THRESHOLD = 0.999


def summarize_contact_forces(result):
    """Peak normal force and sticking / slipping time of every contact, from the
    stored samples (solver steps, or t_eval: the resolution is that of the samples);
    with exact Coulomb friction the sticking and slipping times come from the
    transition events instead.  NaN for a contact without samples."""
    summarize_contacts(result.contacts, result.t, result.y, result.latch, result.flags,
                       result.scene)


def summarize_contacts(contacts, t, y, latch, flags, scene):
    """:func:`summarize_contact_forces` of ``contacts`` over a run's samples: times
    ``t``, states ``y`` (N_STATES, n), and each sample's segment's ``latch`` and
    ``flags`` (a run's contacts call it on first access to one of them)."""
    for contact in contacts:
        contact._summary = None
        contact.peak_normal_force = contact.time_sticking = contact.time_slipping = math.nan
    if not contacts:
        return
    names = scene.plane_names
    mu = scene.friction_coefficient
    ends = [c.t_end if np.isfinite(c.t_end) else t[-1] for c in contacts]
    # each contact's samples, t_start <= t <= end: one run of them (t is increasing)
    firsts = np.searchsorted(t, [c.t_start for c in contacts], side="left").tolist()
    stops = np.searchsorted(t, ends, side="right").tolist()
    runs = [(first, stop) for first, stop in zip(firsts, stops) if stop > first]
    if not runs:
        return
    # one C call over every contact's samples, each with its segment's latch and flags
    # (rows of result.y and latch: views, they are Fortran-ordered)
    rows = np.concatenate([np.arange(first, stop) for first, stop in runs])
    forces = _core.contact_forces_per_sample(
        np.ascontiguousarray(y.T[rows]), scene.parameter_vector(),
        np.ascontiguousarray(latch.T[rows]), np.ascontiguousarray(flags[rows], dtype=np.int64))
    offset = 0
    for contact, end, first, stop in zip(contacts, ends, firsts, stops):
        if stop <= first:
            continue
        k = names.index(contact.plane)
        block = forces[offset:offset + stop - first, 3 * k:3 * k + 3]
        offset += stop - first
        n = contact.unit_normal
        if n[0] == 0 and n[1] == 0:   # horizontal: the z component, as it is
            f_n = block[:, 2] * n[2]
            f_t = np.hypot(block[:, 0], block[:, 1])
        else:   # along the normal, and the rest
            f_n = block @ n
            f_t = np.linalg.norm(block - f_n[:, None] * n, axis=1)
        contact.peak_normal_force = float(f_n.max())
        if contact.transitions:   # exact Coulomb friction: the phases are events
            contact.time_sticking, contact.time_slipping = _phase_times(contact, end)
            continue
        slipping = (f_t >= STICK_SLIP_THRESHOLD * mu * f_n) & (f_n > 0)
        times = t[first:stop]
        dt = np.diff(times)
        slip_fraction = 0.5 * (slipping[1:].astype(float) + slipping[:-1])
        contact.time_slipping = float(np.sum(dt * slip_fraction))
        contact.time_sticking = float(np.sum(dt) - contact.time_slipping)


def _phase_times(contact, end):
    """(time sticking, time slipping) from a contact's transition events (s)."""
    starts = [float(t) for t, _ in contact.transitions] + [float(end)]
    durations = [b - a for a, b in zip(starts, starts[1:])]   # np.diff's, in floats
    sticking = sum(d for d, (_, phase) in zip(durations, contact.transitions) if phase == "stick")
    return float(sticking), float(end - contact.t_start - sticking)


def stiffness_note(stiff_at):
    """A note for the message when dop853 found the scene stiff (Hairer's test: 15 steps
    in a row beyond its stability boundary) from ``stiff_at`` (s) on; "" when it did not
    (None or NaN).  The figure it quotes is docs/work_precision.md's stiff table (the
    final state's max error in position, m, and velocity, m/s)."""
    if stiff_at is None or not math.isfinite(stiff_at):
        return ""
    return (f" (dop853 found the scene stiff from t = {stiff_at:.6g} s on: its steps there "
            "were held at its stability limit, which is slow and, across the contact laws' "
            "kinks, can be inaccurate -- a steel-hard ball rolling with the compliant law "
            "ended 0.57 off at rtol 1e-6; method='radau5' is the integrator for stiff scenes)")
