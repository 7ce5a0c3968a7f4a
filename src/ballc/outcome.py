"""What one simulation amounts to: contacts, energy lost, and "did the ball come back".

"Came back" is the superball-under-a-table question: a ball thrown forward bounces on
the floor, on the underside of the table (the ceiling) and on the floor again; it came
back when, after those first ``after_contacts`` = 3 completed contacts, its x-velocity
has the opposite sign of the x-velocity it was thrown with.  (With fewer completed
contacts the last completed one decides; with none, it did not come back.)
"""
from __future__ import annotations

import numpy as np

#: Contacts of the classic experiment: floor, table underside, floor.
CAME_BACK_AFTER_CONTACTS = 3


def came_back(result, after_contacts: int = CAME_BACK_AFTER_CONTACTS) -> bool:
    """True when the x-velocity after the first ``after_contacts`` completed contacts
    is opposite to the initial x-velocity (see the module docstring)."""
    thrown = result.velocity[0, 0]
    done = [c for c in result.contacts if np.isfinite(c.t_end)][:after_contacts]
    if not done or thrown == 0:
        return False
    return bool(np.sign(done[-1].velocity_after[0]) == -np.sign(thrown))


def first_reversal(result):
    """The first contact at which the x-velocity changed sign, or None."""
    for contact in result.contacts:
        before, after = contact.velocity_before[0], contact.velocity_after[0]
        if np.isfinite(after) and before * after < 0:
            return contact
    return None


def summary(result) -> dict:
    """Plain numbers of one run: contacts, came_back, energies (J), solver status."""
    total = result.energy["total"]
    reversal = first_reversal(result)
    return {
        "contacts": len(result.contacts),
        "came_back": came_back(result),
        "first_reversal_time": reversal.t_start if reversal else float("nan"),   # s
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
    verdict = "CAME BACK" if s["came_back"] else "did NOT come back"
    lines.append(f"the ball {verdict} (x-velocity after the first {CAME_BACK_AFTER_CONTACTS} "
                 f"contacts vs. the throw)")
    return "\n".join(lines)
