"""The hybrid automaton (ballc.automaton): every transition a run takes is a row of the
table, and the default test run takes every row.  The oracle is the table itself, checked
against what the driver does: each event's mode before and after."""
import importlib

import numpy as np
import pytest

import ballc
from ballc import automaton, layout

simulate_module = importlib.import_module("ballc.simulate")


def _record(monkeypatch):
    """Wrap the driver's handler and its checks: [(event, plane, mode before, mode
    after)]."""
    seen = []
    handle = simulate_module._Run.handle

    def recording_handle(run, kind, plane):
        before = run.mode(plane)
        handle(run, kind, plane)
        seen.append((kind, plane, before, run.mode(plane)))

    monkeypatch.setattr(simulate_module._Run, "handle", recording_handle)
    for kind in ("rest check", "uniform check", "orbit check"):
        _record_check(monkeypatch, seen, kind)
    return seen


def _record_check(monkeypatch, seen, kind):
    name = automaton.handler_of(kind)
    check = getattr(simulate_module._Run, name)

    def recording_check(run, plane, *args):
        before = run.mode(plane)
        found = check(run, plane, *args)
        seen.append((kind, plane, before, run.mode(plane)))
        return found

    monkeypatch.setattr(simulate_module._Run, name, recording_check)


def _shallow_start():
    """A compliant scene starting in contact, shallower than the arming depth."""
    scene = ballc.Scene(tangential_model="compliant")
    y0 = scene.initial_state()
    depth = 0.25 * ballc.compliantmodes.arm_penetration(scene, "floor")
    y0[layout.INDEX["z"]] = scene.radius - depth
    y0[layout.INDEX["vz"]] = -1.0
    y0[layout.INDEX["vx"]] = 3.0
    return scene, y0


SCENES = {
    # the seed: exact Coulomb friction (approach, stop, clear, stick, release); its slips
    # that approach zero and grow again (clear) come after its first 5 s
    "seed": (lambda: (ballc.Scene(), None), 10.0),
    "friction": (lambda: (ballc.Scene(tangential_model="friction"), None), 2.5),
    "dig-in": (lambda: (ballc.Scene(tangential_model="dig-in"), None), 5.0),   # through
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
}


@pytest.fixture(scope="module")
def transitions():
    with pytest.MonkeyPatch.context() as monkeypatch:
        # the Python driver's handlers are what this records (the C loop is
        # bit-identical to it: tests/test_c_driver.py)
        monkeypatch.setenv("BALLC_PYTHON_DRIVER", "1")
        seen = _record(monkeypatch)
        for name, (make, t_end) in SCENES.items():
            scene, y0 = make()
            for tol in (1e-5, 1e-6):
                ballc.simulate(scene, t_end, y0=y0, rtol=tol, atol=tol)
        # the compliant elastic mode's capacity kink: ballc's integrators step to it and go
        # on inside the segment (the guard re-armed in C); scipy's end the segment there
        ballc.simulate(ballc.Scene(tangential_model="compliant"), 0.3, method="RK45",
                       rtol=1e-5, atol=1e-5)
        return list(seen)


def test_every_transition_taken_is_a_row_of_the_table(transitions):
    assert transitions
    for kind, plane, before, after in transitions:
        rows = automaton.transitions_from(kind)
        assert len(rows) == 1, kind
        row = rows[0]
        assert before in row.sources, (kind, before, row.sources)
        assert after in row.targets, (kind, after, row.targets)


def test_the_default_run_takes_every_row(transitions):
    taken = {kind for kind, *_ in transitions}
    assert taken == {row.event for row in automaton.TRANSITIONS}, (
        {row.event for row in automaton.TRANSITIONS} - taken)


def test_the_default_run_reaches_every_end_state(transitions):
    reached = {after for *_, after in transitions}
    assert set(automaton.END_MODES) <= reached, set(automaton.END_MODES) - reached


def test_every_handler_exists_and_modes_are_named():
    for row in automaton.TRANSITIONS:
        assert callable(getattr(simulate_module._Run, row.handler)), row
        assert set(row.sources) <= set(automaton.MODES) and set(row.targets) <= set(
            automaton.MODES), row
    with pytest.raises(ValueError, match="not in the automaton"):
        automaton.handler_of("teleport")
