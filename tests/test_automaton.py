"""The hybrid automaton (ballc.automaton): every transition a run takes is a row of the
table, and the default test run takes every row.  The oracle is the table itself, checked
against what the driver reports: the C loop's segment log (``Result.segments``) says for
each segment the event or check that ended it and each plane's mode before and after."""
import re
from pathlib import Path

import numpy as np
import pytest

import ballc
from ballc import automaton, layout


#: The scheduled checks of a rest check, in the order they run: the log names the last
#: that ran (each runs when the one before found nothing, so the earlier ones left the
#: mode as it was).
CHECKS = ("rest check", "uniform check", "orbit check")



def transitions_of(segments):
    """[(event, plane, mode before, mode after)] the C loop reports in a segment log:
    the event (or check) that ended each segment, and each event re-armed inside one."""
    seen = []
    for row in segments:
        end, plane = str(row["end"]), str(row["plane"])
        if row["rearms"]:   # its last re-arm: the guard fired and the segment went on
            seen.append((str(row["rearm_kind"]), str(row["rearm_plane"]),
                         str(row["rearm_before"]), str(row["rearm_after"])))
        if end not in automaton._HANDLERS:   # t_end, a step bound, a failure, a user event
            continue
        k = layout.PLANES.index(plane)
        part = automaton.transitions_from(end)[0].part
        if part != "contact":   # the rolling part's own modes (its second factor)
            seen.append((end, plane, str(row[f"{part}_before"][k]),
                         str(row[f"{part}_after"][k])))
            continue
        before, after = str(row["before"][k]), str(row["after"][k])
        if end in CHECKS:   # the checks before it found nothing: the mode stayed
            seen += [(check, plane, before, before) for check in CHECKS[:CHECKS.index(end)]]
        seen.append((end, plane, before, after))
    return seen


def _shallow_start():
    """A compliant scene starting in contact, shallower than the arming depth."""
    scene = ballc.Scene(tangential_model="compliant")
    y0 = scene.initial_state()
    depth = 0.25 * ballc.compliantmodes.arm_penetration(scene, "floor")
    y0[layout.INDEX["z"]] = scene.radius - depth
    y0[layout.INDEX["vz"]] = -1.0
    y0[layout.INDEX["vx"]] = 3.0
    return scene, y0


def _spinning_stiff_ball():
    """A stiff ball at rest on the floor, spinning about the normal, sds twisting."""
    scene = ballc.Scene(tangential_model="friction", observer_mass=0.0, radius=0.1,
                        ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, c_tau=0.5,
                        friction_coefficient=0.5, rolling_resistance=0.05,
                        twisting_resistance=0.1, rolling_model="sds", position=(0, 0, 0.1),
                        velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 10.0))
    depth = ballc.resting.equilibrium_penetration(scene)
    return scene.replace(position=(0.0, 0.0, scene.radius - depth)), None


SCENES = {
    # the seed: exact Coulomb friction (approach, stop, clear, stick, release); its slips
    # that approach zero and grow again (clear) come after its first 5 s
    "seed": (lambda: (ballc.Scene(), None), 10.0),
    "friction": (lambda: (ballc.Scene(tangential_model="friction"), None), 2.5),
    "dig-in": (lambda: (ballc.Scene(tangential_model="dig-in"), None), 5.0),   # through
    # yield, restick; the elastic mode's capacity kink: radau5 steps to it and re-arms
    # its guard inside the segment (a re-arm in the log)
    "compliant": (lambda: (ballc.Scene(tangential_model="compliant"), None), 2.5),
    "compliant, shallow start": (_shallow_start, 0.01),                         # arm
    "rest": (lambda: (ballc.Scene(velocity=(0, 0, 0), observer_mass=0.0), None), 200.0),
    # the end states in motion: uniform rolling and sliding (massless observer), and the
    # seed's wobbling roll (ballc.orbit; its trial ends at ~63 s)
    "rolling": (lambda: (ballc.Scene(tangential_model="friction", observer_mass=0.0), None),
                100.0),
    "sliding": (lambda: (ballc.Scene(tangential_model="friction", friction_coefficient=0.0,
                                     observer_mass=0.0), None), 100.0),
    "seed, long": (lambda: (ballc.Scene(), None), 100.0),
    # rolling resistance's exact modes (rolling, rolling_fixed, holding; twisting,
    # holding): every one of their events within the seed's ~44 s to rest
    "rolling resistance": (lambda: (ballc.Scene(rolling_resistance=0.1,
                                                twisting_resistance=0.05), None), 100.0),
    # its sds model (spring, slider) with the compliant law; a stiff ball spinning on the
    # floor about the normal, whose twisting slider re-sticks as the spin stops
    "rolling resistance, sds": (lambda: (ballc.Scene(
        rolling_resistance=0.05, twisting_resistance=0.05, rolling_model="sds",
        tangential_model="compliant"), None), 5.0),
    "rolling resistance, spin sds": (_spinning_stiff_ball, 3.0),
}


@pytest.fixture(scope="module")
def runs():
    """{(scene, rtol): Result} of the default runs, and scipy's RK45 on the compliant law
    (its capacity event ends a segment: scipy's methods cannot re-arm)."""
    found = {}
    for name, (make, t_end) in SCENES.items():
        scene, y0 = make()
        for tol in (1e-5, 1e-6):
            found[name, tol] = ballc.simulate(scene, t_end, y0=y0, rtol=tol, atol=tol)
    found["compliant, RK45", 1e-5] = ballc.simulate(
        ballc.Scene(tangential_model="compliant"), 0.3, method="RK45", rtol=1e-5, atol=1e-5)
    return found


@pytest.fixture(scope="module")
def transitions(runs):
    seen = []
    for result in runs.values():   # every run is the C loop's: every run has its log
        seen += transitions_of(result.segments)
    return seen


def test_every_transition_taken_is_a_row_of_the_table(transitions):
    assert transitions
    for kind, plane, before, after in transitions:
        rows = automaton.transitions_from(kind)
        assert len(rows) == 1, kind
        row = rows[0]
        assert before in row.sources, (kind, plane, before, row.sources)
        assert after in row.targets, (kind, plane, after, row.targets)


def test_the_default_run_takes_every_row(transitions):
    taken = {kind for kind, *_ in transitions}
    rows = {row.event for row in automaton.TRANSITIONS}
    assert taken >= rows, rows - taken


def test_the_default_run_reaches_every_end_state(transitions):
    reached = {after for *_, after in transitions}
    assert set(automaton.END_MODES) <= reached, set(automaton.END_MODES) - reached


def test_the_log_is_the_run(runs):
    """Each log is the run it logs: its segments follow each other (the next starts
    where one ended, in the modes it left), their calls add up to the run's, every
    contact starts at an "enter" (or at t = 0), the last segment ends where the
    integration did, and a mode changes only where the log says an event or check
    changed it."""
    for key, result in runs.items():
        segments = result.segments
        assert segments["t_start"][0] == 0.0, key
        np.testing.assert_array_equal(segments["t_start"][1:], segments["t_end"][:-1])
        np.testing.assert_array_equal(segments["before"][1:], segments["after"][:-1])
        for part in ("rolling", "twisting"):
            np.testing.assert_array_equal(segments[f"{part}_before"][1:],
                                          segments[f"{part}_after"][:-1])
        assert np.all(segments["t_end"] >= segments["t_start"]), key
        assert (segments["nfev"].sum(), segments["njev"].sum(), segments["nlu"].sum()) == (
            result.nfev, result.njev, result.nlu), key
        starts = sorted(c.t_start for c in result.contacts if c.t_start > 0)
        entered = segments["t_end"][segments["end"] == "enter"]
        np.testing.assert_array_equal(np.sort(entered), starts)
        last = segments[-1]
        closed_form = last["end"] in CHECKS and any(
            mode in automaton.END_MODES for mode in last["after"])
        assert last["end"] in ("t_end", "through") + CHECKS, (key, last["end"])
        if not closed_form:
            assert last["t_end"] == result.t[-1], key
        unchanged = segments["end"] == "t_end"
        np.testing.assert_array_equal(segments["before"][unchanged],
                                      segments["after"][unchanged])


def test_every_handler_exists_and_modes_are_named():
    """Each row's handler is a function of the C loop (_driver.c) that takes the run, and
    the loop calls it; the modes are the table's (a rolling part's row: that part's)."""
    source = (Path(__file__).resolve().parent.parent / "src" / "ballc" / "_driver.c").read_text()
    for row in automaton.TRANSITIONS:
        assert re.search(rf"^static \w+ {row.handler}\((const )?run_t \*r\b", source, re.M), row
        assert len(re.findall(rf"\b{row.handler}\(r\b", source)) >= 1, row
        modes = (automaton.MODES if row.part == "contact"
                 else automaton.ROLLING_PART_MODES[row.part])
        assert set(row.sources) <= set(modes) and set(row.targets) <= set(modes), row
    with pytest.raises(ValueError, match="not in the automaton"):
        automaton.handler_of("teleport")


def test_the_c_loop_names_the_modes_and_events_of_the_table():
    """The segment log's names (ballc._core, from _driver.c) are the table's."""
    assert ballc._core.PLANE_MODES == automaton.MODES
    kinds = {row.event for row in automaton.TRANSITIONS} - set(CHECKS)
    assert kinds <= set(ballc._core.SEGMENT_ENDS)
    assert set(CHECKS) <= set(ballc._core.SEGMENT_ENDS)
    assert set(automaton.SIMULTANEOUS) <= set(ballc._core.SEGMENT_ENDS)


def test_the_rolling_part_has_a_mode_exactly_while_its_plane_is_in_contact(runs):
    """With rolling resistance, a plane's rolling and twisting parts are in an exact mode
    while it is in contact and "none" in flight (a contact's start sets them, its end
    clears them); without it, "none" throughout."""
    for (name, _), result in runs.items():
        segments = result.segments
        if segments is None:
            continue
        flight = segments["before"] == "flight"
        for part, modes in (("rolling", automaton.EXACT_ROLLING_MODES),
                            ("twisting", automaton.EXACT_TWISTING_MODES)):
            before = segments[f"{part}_before"]
            if not name.startswith("rolling resistance"):
                assert set(before.ravel()) == {"none"}, name
                continue
            if name.endswith("sds"):
                modes = automaton.SDS_MODES
            assert set(before[flight]) == {"none"}
            assert set(before[~flight & (segments["before"] != "resting")]) <= set(modes)
