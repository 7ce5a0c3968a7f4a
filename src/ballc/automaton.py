"""ballc's hybrid automaton, in one table: the modes of a plane, the guards that end a
segment, and the resets that start the next.

A run is a sequence of smooth segments, integrated one at a time by the segment loop
in C (``_driver.c``, ``ballc_drive``: the one driver, docs/driver.md).  Each plane is
in one *mode* at a time:

* ``flight``: not in contact;
* with exact Coulomb friction (ballc.stickslip; the friction and mixture models):
  ``slip`` (free direction), ``slip_fixed`` (direction held), ``stick``;
* with the compliant law's exact modes (ballc.compliantmodes): ``elastic``, ``sliding``;
* ``contact``: in contact with neither (the dig-in model; the "max" and "smooth"
  regularisations; mu = 0);
* with rolling resistance (docs/contact_laws.md, "Rolling resistance"), each contact's
  *rolling part* has modes of its own, a second factor of the plane's mode
  (:data:`ROLLING_PART_MODES`; the C loop's segment log reports them as
  ``rolling_before``/``_after`` and ``twisting_before``/``_after``): with the exact model
  ``rolling`` (the torque mu_r r F_n against the rolling velocity, its direction free),
  ``rolling_fixed`` (its direction held), ``holding`` (the rolling velocity held at 0 by
  a constraint torque); its twisting part ``twisting`` and ``holding``; with the sds
  model ``spring`` (below the cap) and ``slider`` (at it);
* end states of a run (floor only), each continued in closed form to t_end:
  ``resting`` (ballc.resting), ``rolling`` and ``free_sliding`` (uniform: ballc.resting;
  with the wobble of an eccentric observer: ballc.orbit); ``passed_through`` (the ball
  left through the plane: status 1).

:data:`TRANSITIONS` lists every transition: the event kind (the name the C loop's
segment log gives its guard, ``_core.SEGMENT_ENDS``), the modes it leaves from, the
modes it may lead to, the guard (event function and direction), the reset, and the C
function of ``_driver.c`` that applies it.  :data:`SIMULTANEOUS` is how simultaneous events are
ordered.  One scheduled segment end changes no mode and is not a row: a compliant
contact's step bound (steps of at most t_c/16 for its first 4 t_c,
ballc.compliantmodes.STEPS_PER_CONTACT) ends a segment where it ends, and the next goes
on in the same modes with the tolerance's steps.  The C loop reports each segment's
modes before and after its end (``Result.segments``); tests/test_automaton.py runs
scenes that take every transition, checks each one the C loop reports against this
table, and that each row's handler is the C function that applies it.
docs/architecture.md draws it.
"""
from __future__ import annotations

from dataclasses import dataclass

#: the modes of a contact, per model
COULOMB_MODES = ("slip", "slip_fixed", "stick")
COMPLIANT_MODES = ("elastic", "sliding")
CONTACT_MODES = ("contact",) + COULOMB_MODES + COMPLIANT_MODES
END_MODES = ("resting", "rolling", "free_sliding", "passed_through")
MODES = ("flight",) + CONTACT_MODES + END_MODES
#: The modes of a contact's rolling part, by the code its plane's latch holds them in
#: (codegen model.ROLLING_MODE_CODES: none, free, fixed, holding, spring, slider), for
#: its rolling and its twisting part ("none": no rolling resistance, or no contact).
#: The rolling part's "rolling" is a mode of that part (the ball rolls against its
#: resistance), not the plane's end state "rolling" (uniform rolling, in END_MODES).
ROLLING_PART_MODES = {
    "rolling": ("none", "rolling", "rolling_fixed", "holding", "spring", "slider"),
    "twisting": ("none", "twisting", "twisting", "holding", "spring", "slider"),
}
EXACT_ROLLING_MODES = ("rolling", "rolling_fixed", "holding")
EXACT_TWISTING_MODES = ("twisting", "holding")
SDS_MODES = ("spring", "slider")


@dataclass(frozen=True)
class Transition:
    """One row of the automaton."""

    event: str           # the event kind (_core.SEGMENT_ENDS), or a scheduled check
    sources: tuple       # modes of the plane it leaves from
    targets: tuple       # modes it may lead to
    guard: str           # the event function g and its direction (terminal events)
    reset: str           # what is latched or reset, and how the next mode is chosen
    handler: str         # the function of _driver.c that applies it
    #: whose mode it changes: the plane's ("contact"), or its rolling part's ("rolling",
    #: "twisting": sources and targets are ROLLING_PART_MODES)
    part: str = "contact"


TRANSITIONS = (
    Transition("enter", ("flight",), CONTACT_MODES,
               "rho - threshold rises through 0 (threshold: 4 ulp of the plane's position, "
               "or the compliant law's arming depth)",
               "latch rhodot^- and the dig-in direction; deflection 0; the first Coulomb mode "
               "(slip, slip_fixed, or settle: stick / slip_fixed) or the compliant start "
               "mode (the self-similar start's)", "begin_contact"),
    Transition("leave", CONTACT_MODES, ("flight",),
               "rho + threshold falls through 0", "close the contact's record",
               "end_contact"),
    Transition("through", CONTACT_MODES, ("passed_through",),
               "rho - r rises through 0", "the run stops, status 1", "pass_through"),
    Transition("approach", ("slip",), ("slip", "slip_fixed"),
               "u . d - clear falls through 0 (u the slip velocity, d its latched "
               "direction)", "re-latch d and stay free (a slip passing by zero; radau5 "
               "re-arms the event without ending the segment), else hold d",
               "coulomb_event"),
    Transition("stop", ("slip_fixed",), ("stick", "slip_fixed", "slip"),
               "u . d + margin falls through 0",
               "a slip left within 10 tolerances is removed by an impulse and the contact "
               "settles (stick, or slip from rest along -lambda); a larger one slips on",
               "coulomb_event"),
    Transition("clear", ("slip_fixed",), ("slip",),
               "u . d - 2 clear rises through 0", "the direction goes free",
               "coulomb_event"),
    Transition("release", ("stick",), ("slip_fixed",),
               "mu N - |lambda| + margin falls through 0",
               "slip from rest along -lambda (the slip removed)", "coulomb_event"),
    Transition("arm", COMPLIANT_MODES, COMPLIANT_MODES,
               "rho - arming depth rises through 0 (a scene that starts shallower)",
               "arm the guards; decide at the cap", "compliant_event"),
    Transition("yield", ("elastic",), COMPLIANT_MODES,
               "1 - k_t |s| / (mu F_n) + offset falls through 0",
               "decide at the cap: sliding when the re-stick margin there is >= 0, "
               "else elastic with the spring brought back to the cap; where the load "
               "vanished with the spring far below the cap, elastic and disarmed (the "
               "contact's last instants)", "compliant_event"),
    Transition("capacity", ("elastic",), ("elastic",),
               "(mu F_n - |F_el|) - |V|, or its negative (its sign at the segment's start), "
               "+ offset falls through 0: the viscous damping saturates the capacity the "
               "elastic force leaves, or stops saturating it",
               "none: the segment ends at that kink of the force and of the dissipation "
               "rate, so that no step straddles it", "compliant_event"),
    Transition("restick", ("sliding",), ("elastic",),
               "(e . v_t - max(rhodot, 0)/(2 rho) |s|) - ds_cap/dt + offset falls "
               "through 0", "a spring beyond the cap is brought back to it",
               "compliant_event"),
    Transition("rest check", CONTACT_MODES, ("resting",) + CONTACT_MODES,
               "scheduled (not an event): 20 small-oscillation periods into a floor "
               "contact, then at growing intervals, and at the end of an orbit's trial",
               "the rest state, in closed form to t_end; else the next check",
               "at_rest"),
    Transition("uniform check", CONTACT_MODES, ("rolling", "free_sliding") + CONTACT_MODES,
               "at a rest check that found no rest",
               "uniform rolling or sliding (massless observer, isotropic inertia; "
               "ballc.resting), in closed form to t_end; else go on",
               "rolls"),
    Transition("orbit check", CONTACT_MODES, ("rolling", "free_sliding") + CONTACT_MODES,
               "at a rest check that found neither rest nor uniform motion, when it ends "
               "an orbit's trial (TRIAL_PERIODS periods integrated in one mode)",
               "the relative periodic orbit of an eccentric observer's wobble "
               "(ballc.orbit), in closed form to t_end; else a new trial",
               "check_orbit"),
    # rolling resistance's exact model (src/ballc/_rolling.c): the modes of exact
    # Coulomb friction, for the rolling velocity v_roll = r (omega x n) and the twisting
    # velocity r omega . n; a contact's start sets them as Coulomb's (free, fixed, or
    # settled), its end to none
    Transition("roll_approach", ("rolling",), ("rolling", "rolling_fixed"),
               "v_roll . d - approach falls through 0 (d the rolling velocity's latched "
               "direction)", "re-latch d and stay free (a rolling velocity passing by "
               "zero), else hold d", "rolling_event", "rolling"),
    Transition("roll_stop", ("rolling_fixed",), ("holding", "rolling_fixed", "rolling"),
               "v_roll . d + margin falls through 0",
               "a rolling velocity left within 10 tolerances is removed by an angular "
               "impulse (with the slip, when the contact sticks: one impulse for both) and "
               "the part settles: holding when the force that holds it is within "
               "mu_r F_n, else rolling from rest along -lambda_r; a larger one rolls on",
               "rolling_event", "rolling"),
    Transition("roll_clear", ("rolling_fixed",), ("rolling",),
               "v_roll . d - 2 clear rises through 0", "the direction goes free",
               "rolling_event", "rolling"),
    Transition("roll_release", ("holding",), ("rolling_fixed",),
               "mu_r F_n - |lambda_r| + scale falls through 0 (lambda_r the rolling force "
               "that holds v_roll, solved with the equations of motion and Coulomb's "
               "stick constraint)", "rolls from rest along -lambda_r (what is left of "
               "v_roll removed)", "rolling_event", "rolling"),
    Transition("twist_stop", ("twisting",), ("holding", "twisting"),
               "v_twist d + margin falls through 0 (d its latched sign)",
               "settles as roll_stop (holding, or twisting from rest along -lambda_w); "
               "a larger twisting velocity twists on the other way",
               "rolling_event", "twisting"),
    Transition("twist_release", ("holding",), ("twisting",),
               "mu_t F_n - |lambda_w| + scale falls through 0",
               "twists from rest along -lambda_w", "rolling_event", "twisting"),
    # the sds model (LAMMPS' rolling sds / twisting sds, ballc's passive form): a spring
    # below the cap, a slider at it, for each part; a contact starts with the spring
    # relaxed, and its end relaxes it (the energy booked as dissipated)
    Transition("roll_yield", ("spring",), SDS_MODES,
               "1 - k_r |xi| / (mu_r F_n) + rounding falls through 0",
               "decide at the cap: slider when the re-stick margin there is >= 0, else the "
               "spring brought back to the cap; without load the spring relaxed",
               "rolling_event", "rolling"),
    Transition("roll_restick", ("slider",), ("spring",),
               "(e . v_roll) - mu_r F_n' / k_r + offset falls through 0 (the spring would "
               "stretch slower than the cap grows)", "the spring, at (or brought back to) "
               "the cap", "rolling_event", "rolling"),
    Transition("twist_yield", ("spring",), SDS_MODES, "as roll_yield, for the twisting part",
               "as roll_yield", "rolling_event", "twisting"),
    Transition("twist_restick", ("slider",), ("spring",),
               "as roll_restick, for the twisting part", "as roll_restick", "rolling_event",
               "twisting"),
)

#: How simultaneous events are handled: the earliest terminal event that fired ends the
#: segment (an event at the segment's start is kept off by its threshold or offset);
#: at equal times the first in the C loop's order of a segment's events (_driver.c:
#: segment_events), which is per plane (floor, then ceiling): leave / enter, through,
#: deepest (not terminal), the Coulomb event, the compliant guard; the user's events come
#: after the loop's own.  A mode change at the
#: time of the last one counts as stalled, and 100 in a row stop the run (status -1).
SIMULTANEOUS = ("leave", "enter", "through", "deepest", "approach", "stop", "clear",
                "release", "roll_approach", "roll_stop", "roll_clear", "roll_release",
                "twist_stop", "twist_release", "roll_yield", "roll_restick", "twist_yield",
                "twist_restick", "arm", "yield", "capacity", "restick", "user")

_HANDLERS = {transition.event: transition.handler for transition in TRANSITIONS}


def handler_of(kind: str) -> str:
    """The function of ``_driver.c`` that applies the event ``kind``."""
    try:
        return _HANDLERS[kind]
    except KeyError:
        raise ValueError(f"event kind {kind!r} is not in the automaton "
                         f"({', '.join(_HANDLERS)})") from None


def transitions_from(kind: str):
    """The rows of event ``kind`` (one per kind)."""
    return [transition for transition in TRANSITIONS if transition.event == kind]
