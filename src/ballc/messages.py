"""What a run's ``message`` says: how it ended, in words, from the C loop's output.

The C loop (``_driver.c``) stops with a code (``_core.DRIVE_*``) and the numbers the
words need; :func:`run_message` writes them.  The warnings added after it (a tolerance
looser than ballc is tested at, an energy balance that drifted, dop853 finding the scene
stiff) are ballc.outcome's.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, layout, resting

SUCCESS = "The solver successfully reached the end of the integration interval."
TERMINATED = "A termination event occurred."
#: What the transitions are called in the message of a run whose modes did not settle.
COULOMB_TRANSITIONS = "stick-slip"
COMPLIANT_TRANSITIONS = "the compliant law's elastic/sliding"
#: Below this absolute tolerance (m, m/s) a contact's state can be tighter than the
#: rounding of its depth r - z allows (see failure_hint).
TIGHT_ATOL = 1e-10
#: The C loop's end states (_driver.h: BALLC_END_*; 0 none) by name.
END_KINDS = (None, "rest", "rolling", "free_sliding", "accelerating")


def run_message(scene, options, run) -> str:
    """The message of the finished ``run`` (a ``_core.Drive``) of ``scene`` with
    ``options``, before the warnings."""
    code = run.stop_code
    names = scene.plane_names
    if code == _core.DRIVE_FAILED:
        return failure_message(scene, options, run.message, run.nfev, run.fail_end,
                               dict(zip(names, run.in_contact)))
    if code == _core.DRIVE_ABORTED:
        return (f"the run stopped at t = {run.t_run:.6g} s where it cannot go on: "
                f"{run.message}")
    if code == _core.DRIVE_UNSETTLED:
        what = COMPLIANT_TRANSITIONS if run.unsettled_compliant else COULOMB_TRANSITIONS
        plane = run.stop_plane
        return unsettled_message(what, names[plane], run.transitions[plane], run.stalled,
                                 run.t_run)
    if code == _core.DRIVE_TERMINATED:
        return TERMINATED
    if code == _core.DRIVE_THROUGH:
        return through_message(names[run.stop_plane], run.t_run)
    end = END_KINDS[run.end_kind]
    if not end:
        return SUCCESS
    plane, when = names[run.end_plane], run.end_t
    orbit = run.orbit()
    if orbit is not None:
        return orbit_message(scene.parameter_vector(), plane, when, run.end_y, end,
                             orbit[1], orbit[2][0], orbit[3], options.t_end)
    if end == "rest":
        return rest_message(scene, plane, when)
    if end == "accelerating":
        return accelerating_message(plane, when, run.end_y, run.end_acceleration)
    return motion_message(scene, plane, when, run.end_y, end)


def rest_message(scene, plane, t):
    """The message of a run that came to rest on ``plane`` at ``t``."""
    return (f"{SUCCESS} The ball came to rest on the {plane} at t = {t:.9g} s "
            f"(ballc.resting: static Hertz equilibrium, penetration "
            f"{resting.equilibrium_penetration(scene):.6g} m); from there "
            "to t_end the state is that rest state.")


def motion_message(scene, plane, t, y, kind):
    """The message of a run that goes on uniformly (``kind`` "rolling" or
    "free_sliding") on ``plane`` from ``t`` in state ``y``: its speed along the plane."""
    n = scene.planes[scene.plane_names.index(plane)].unit_normal
    velocity = y[layout.VELOCITY]
    if n[0] == 0 and n[1] == 0:   # horizontal: the horizontal speed
        v = math.hypot(*velocity[:2])
    else:
        v = float(np.linalg.norm(velocity - (velocity @ n) * n))
    what = "rolls uniformly" if kind == "rolling" else (
        "slides uniformly (no force opposes its slip)")
    if kind == "rolling" and scene.rolling_resistance > 0:   # held: it can only spin
        spin = float(y[layout.ANGULAR_VELOCITY] @ n)
        what = (f"is held by its rolling resistance and sticks, spinning about the normal "
                f"at {spin:.6g} rad/s (no twisting resistance stops it),")
    return (f"{SUCCESS} The ball {what} on the {plane} from t = "
            f"{t:.9g} s at {v:.6g} m/s (ballc.resting: static Hertz "
            f"equilibrium, penetration "
            f"{resting.equilibrium_penetration(scene):.6g} m); from there "
            f"to t_end the state is that {kind.replace('free_', '')}, in "
            "closed form.")


def accelerating_message(plane, t, y, acceleration) -> str:
    """The message of a run that rolls down ``plane`` uniformly accelerated from ``t``
    (state ``y``, the centre's ``acceleration``)."""
    v = float(np.linalg.norm(y[layout.VELOCITY]))
    return (f"{SUCCESS} The ball rolls down the {plane} without slip from t = {t:.9g} s at "
            f"{v:.6g} m/s, uniformly accelerated at {float(np.linalg.norm(acceleration)):.6g} "
            "m/s^2 (g_t / (1 + I / (m r^2)), g_t gravity along the plane; nothing else is "
            "reached by t_end); from there to t_end the state is that rolling, in closed "
            "form.")


def why_no_end_state(scene, contacts, t_end) -> str:
    """What a run that went on to ``t_end`` in a long contact (more than REST_PERIODS
    small-oscillation periods) says about why no end state finished it in closed form:
    rest and uniform rolling are exact only on a plane whose normal is opposite gravity,
    alone (resting.resting_plane_index); on any other plane -- an incline, where rolling
    is uniformly accelerated -- or against two planes at once the integration goes on.
    "" when no such contact was open at the end."""
    open_ = [c for c in contacts if c.t_end != c.t_end and c.t_rest != c.t_rest
             and c.t_rolling != c.t_rolling and c.t_sliding != c.t_sliding]
    if not open_ or not scene.gravity_magnitude > 0:
        return ""
    long_ago = t_end - resting.REST_PERIODS * resting.oscillation_period(scene)
    open_ = [c for c in open_ if c.t_start <= long_ago]
    if not open_:
        return ""
    names = " and the ".join(c.plane for c in open_)
    index = resting.resting_plane_index(scene)
    if len(open_) > 1:
        why = (f"the ball is in contact with the {names} at once (rest and uniform rolling "
               "are checked on a plane whose normal is opposite gravity, alone)")
    elif index is None or open_[0].plane != scene.plane_names[index]:
        why = (f"the ball is in contact with the {names}, whose normal is not opposite "
               "gravity: rest and uniform rolling are exact end states only on such a "
               "plane; rolling down an incline, uniformly accelerated, ends in closed form "
               "only once it rolls without slip straight down the slope without spin "
               "about the normal, reaching no other plane by t_end (a massless observer, "
               "isotropic inertia)")
    else:
        return ""
    return f" No closed-form end state: {why}; the integration went on to t_end."


def orbit_message(params, plane, t, y, kind, period, phi, rate, t_end):
    """The message of a run that goes on from ``t`` (state ``y``) as a relative periodic
    orbit of ``period`` (s) turning by ``phi`` (rad) per period, its mechanical energy
    having changed at ``rate`` (W) over the trial."""
    what = "rolls" if kind == "rolling" else "slides freely"
    kinetic = float(_core.energies(np.ascontiguousarray(y[None, :]), params)[0, 0])
    neglected = -rate * (t_end - t)
    share = neglected / kinetic if kinetic > 0 else math.inf
    return (
        f"{SUCCESS} The ball {what} on the {plane} from t = {t:.9g} s with the "
        f"wobble of its eccentric observer, a relative periodic orbit (ballc.orbit): "
        f"every {period:.9g} s its state repeats turned by {phi:.6g} rad about "
        f"the vertical; from there to t_end the state is that orbit, in closed form. "
        f"The orbit holds the mechanical energy constant; over the trial it changed at "
        f"{rate:.2g} W (the contact's dissipation, and the integration's error at this "
        f"tolerance), {-neglected:.2g} J by t_end ({abs(share):.2g} of the kinetic "
        f"energy)" + (": more than 1 %, so a tighter rtol would resolve it better."
                      if abs(share) > 0.01 else "."))


def unsettled_message(what, plane, transitions, stalled, t):
    """The message of a run stopped because ``plane``'s ``what`` transitions did not
    settle."""
    return (f"{what} transitions on the {plane} did not settle: {transitions} mode changes "
            f"in one contact, {stalled} of them at t = {t:.17g} s")


def through_message(plane, t):
    """The message of a run stopped where the ball passed through ``plane``."""
    return (f"ball passed through the {plane} at t = {t:.6g} s "
            "(penetration reached the ball's radius)")


def failure_message(scene, options, reason, nfev, end, in_contact):
    """The message of a run whose integrator failed at ``end`` after ``nfev`` calls in
    all, with the integrator's ``reason``."""
    if "max_nfev" in reason:
        reason = (f"gave up after {nfev} right-hand-side evaluations in all "
                  f"(max_nfev = {options.max_nfev})")
    return (f"integrator failed at t = {end:.6g} s: {reason}"
            + failure_hint(scene, in_contact, options.atol))


def failure_hint(scene, in_contact, atol=None):
    """Why a contact segment may defeat the integrator, when the cause is one of the
    usual ones (:func:`_tight_atol_hint`, :func:`_regularised_friction_hint`); "" out of
    contact."""
    if not any(in_contact.values()):
        return ""
    return _tight_atol_hint(atol) + _regularised_friction_hint(scene)


def _tight_atol_hint(atol):
    """An absolute tolerance below the rounding of the contact depth r - z (a stiff ball
    at rest: z ~ r, so r - z keeps few digits, and the Hertz force's rounding noise
    keeps the Newton iteration from converging to a centre height or vertical velocity
    within atol; measured: a steel ball, E = 2e11 Pa, at rest, crawled with atol = 1e-12
    and ran with atol = 1e-10 on z or vz alone, docs/limits.md)."""
    if atol is None or float(np.min(atol)) >= TIGHT_ATOL:
        return ""
    return (f" (in contact with atol = {float(np.min(atol)):g}: so tight an absolute "
            "tolerance on the centre's height and vertical velocity can be below the "
            "rounding noise of the contact depth r - z, most of all for a hard ball "
            f"at rest; try atol >= {TIGHT_ATOL:g} (one number, or per state: "
            "scene.state_names))")


def _regularised_friction_hint(scene):
    """The seed's regularised Coulomb law ("max", "smooth") with a small v_s."""
    if scene.tangential_model not in ("friction", "mixture"):
        return ""
    if scene.friction_coefficient == 0 or scene.effective_mixture == 1:
        return ""
    if scene.friction_regularization == "exact":
        return ""
    return (f" (in contact with regularised Coulomb friction: below the regularisation "
            f"speed {scene.friction_regularization_speed:g} m/s friction is a viscous law "
            "of coefficient mu F_n / v_s, too stiff to resolve for hard materials or loose "
            "tolerances; use friction_regularization='exact' (the default), or tighter rtol)")
