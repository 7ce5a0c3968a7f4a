"""The segment loop in C (_driver.c, ballc._core.drive) against the Python driver: the
same bits for the runs in its subset, the Python driver for the others
(docs/c_loop_plan.md; benchmarks/driver_identical.py runs the whole list)."""
from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import ballc
from ballc import _core

FIELDS = ("t", "y", "flags", "latch")

#: The C loop reproduces this process's math.hypot (CPython's own algorithm, which
#: changes between versions) and numpy's length-3 dot (a BLAS ddot: an FMA chain here).
#: Where they differ -- another CPython, another BLAS or CPU -- simulate checks it once
#: and takes the Python driver for every run: results are the Python driver's there, and
#: the tests that compare the two drivers, or the ports with those functions, are
#: skipped (they cannot pass on another machine's numerics; none of them may fail there).
C_NUMERICS = sys.modules["ballc.simulate"]._c_numerics_agree()
needs_c_numerics = pytest.mark.skipif(
    not C_NUMERICS, reason="this process's math.hypot or numpy dot differ from the C loop's "
    "ports: every run takes the Python driver (docs/c_loop_plan.md)")


def _run(monkeypatch, python, scene, t_end, **kwargs):
    with monkeypatch.context() as patch:
        if python:
            patch.setenv("BALLC_PYTHON_DRIVER", "1")
        else:
            patch.delenv("BALLC_PYTHON_DRIVER", raising=False)
        return ballc.simulate(scene, t_end, progress=False, **kwargs)


def _assert_identical(p, c):
    assert p._driver == "python" and c._driver == "c"
    for name in FIELDS:
        a, b = getattr(p, name), getattr(c, name)
        assert a.dtype == b.dtype and a.flags.f_contiguous == b.flags.f_contiguous, name
        assert np.array_equal(a, b), name
    assert (p.status, p.message, p.nfev, p.njev, p.nlu) == (c.status, c.message, c.nfev,
                                                            c.njev, c.nlu)
    assert len(p.contacts) == len(c.contacts)
    for a, b in zip(p.contacts, c.contacts):
        for field in a.__dataclass_fields__:
            x, y = getattr(a, field), getattr(b, field)
            assert type(x) is type(y), field
            if isinstance(x, np.ndarray):
                assert np.array_equal(x, y, equal_nan=True), field
            elif isinstance(x, float):
                assert x == y or (math.isnan(x) and math.isnan(y)), field
            else:
                assert x == y, field


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5"])
@pytest.mark.parametrize("mixture, mu", [(0.0, 0.5), (0.3, 0.2), (0.7, 1.0), (1.0, 0.2)])
def test_map_cells_are_bit_identical(monkeypatch, method, mixture, mu):
    scene = ballc.Scene(mixture=mixture, friction_coefficient=mu)
    kw = dict(method=method, rtol=1e-3, atol=1e-3)
    _assert_identical(_run(monkeypatch, True, scene, 1.2, **kw),
                      _run(monkeypatch, False, scene, 1.2, **kw))


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5"])
def test_the_seed_is_bit_identical(monkeypatch, method):
    """5 s at the default tolerance: re-latches accepted inside the integrator (the
    samples split at each), clear events, stops and settles."""
    scene = ballc.Scene()
    _assert_identical(_run(monkeypatch, True, scene, 5.0, method=method),
                      _run(monkeypatch, False, scene, 5.0, method=method))


@needs_c_numerics
def test_a_failure_and_the_call_budget_are_bit_identical(monkeypatch):
    scene = ballc.Scene(mixture=0.3, friction_coefficient=0.2)
    kw = dict(method="dop853", rtol=1e-3, atol=1e-3, max_nfev=300)
    p = _run(monkeypatch, True, scene, 1.2, **kw)
    assert p.status == -1
    _assert_identical(p, _run(monkeypatch, False, scene, 1.2, **kw))


@pytest.mark.parametrize("kwargs", [
    dict(method="Radau"), dict(atol=np.full(_core.N_STATES, 1e-3)),
    dict(events=[ballc.events.LinearEvent(np.eye(_core.N_STATES)[6]
                                          + np.eye(_core.N_STATES)[4], -1.0)]),
], ids=["scipy", "atol per state", "LinearEvent of several states"])
def test_runs_outside_the_subset_fall_back(monkeypatch, kwargs):
    kwargs = dict(dict(method="dop853", rtol=1e-3, atol=1e-3), **kwargs)
    # (a massless observer: exact flight would take the LinearEvent with a BLAS dot)
    result = _run(monkeypatch, False, ballc.Scene(observer_mass=0), 0.5, **kwargs)
    assert result._driver == "python"


def test_an_orbit_trial_falls_back(monkeypatch):
    # the seed rolls on from 30.9 s: its rest checks find neither rest nor uniform motion
    # (it is Routh's sphere), and one where an orbit's trial may start falls back
    kw = dict(method="dop853", rtol=1e-6, atol=1e-6)
    c = _run(monkeypatch, False, ballc.Scene(), 100.0, **kw)
    p = _run(monkeypatch, True, ballc.Scene(), 100.0, **kw)
    assert c._driver == "python"
    assert np.array_equal(c.t, p.t) and np.array_equal(c.y, p.y) and c.message == p.message


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5"])
@pytest.mark.parametrize("case", ["rest", "rolling", "checks"])
def test_the_rest_checks_are_bit_identical(monkeypatch, method, case):
    """Stage 2a: a rest check that finds rest, uniform rolling (then the closed-form
    end), or nothing (the seed before an orbit's trial could fit)."""
    scene, t_end, kw = {
        "rest": (ballc.Scene(velocity=(0, 0, 0), observer_mass=0), 1e6,
                 dict(exact_flight=False)),
        "rolling": (ballc.Scene(observer_mass=0), 1e6, dict(exact_flight=False)),
        "checks": (ballc.Scene(), 30.0, {}),
    }[case]
    kw = dict(kw, method=method, rtol=1e-6, atol=1e-6)
    p = _run(monkeypatch, True, scene, t_end, **kw)
    expected = {"rest": "came to rest", "rolling": "rolls uniformly",
                "checks": ""}[case]
    assert expected in p.message
    _assert_identical(p, _run(monkeypatch, False, scene, t_end, **kw))


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5"])
def test_t_eval_and_dense_output_are_bit_identical(monkeypatch, method):
    """Stage 2b: t_eval (with and without 0) and Result.sol, here with a rest end's
    closed-form piece too, and on a failed run."""
    seed = ballc.Scene()
    drop = ballc.Scene(velocity=(0, 0, 0), observer_mass=0)
    cell = ballc.Scene(mixture=0.3, friction_coefficient=0.2)
    for scene, t_end, kw in [
            (seed, 5.0, dict(t_eval=np.linspace(0.0, 5.0, 51))),
            (seed, 5.0, dict(t_eval=[0.5, 1.5, 2.5], dense_output=True)),
            (drop, 1e6, dict(rtol=1e-6, atol=1e-6, exact_flight=False, dense_output=True)),
            (cell, 1.2, dict(rtol=1e-3, atol=1e-3, max_nfev=300, dense_output=True))]:
        kw = dict(kw, method=method)
        p = _run(monkeypatch, True, scene, t_end, **kw)
        c = _run(monkeypatch, False, scene, t_end, **kw)
        _assert_identical(p, c)
        if kw.get("dense_output"):
            assert [(a, b) for a, b, _ in p.sol.pieces] == [(a, b) for a, b, _ in c.sol.pieces]
            for (a, b, f), (_, _, g) in zip(p.sol.pieces, c.sol.pieces):
                if b > a and getattr(f, "steps", np.ones(1)).size:
                    times = np.linspace(a, b, 7)
                    assert np.array_equal(f(times), g(times))


@needs_c_numerics
@pytest.mark.parametrize("scene, t_end, kw", [
    ({}, 5.0, {}),
    (dict(tangential_model="friction", ball_youngs_modulus=2e11, plane_youngs_modulus=2e11,
          c_tau=0.5, observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0)),
     3.0, dict(rtol=1e-9, atol=1e-9, dense_output=True, exact_flight=False)),
    (dict(velocity=(0, 0, 0), observer_mass=0), 1e6,
     dict(rtol=1e-6, atol=1e-6, exact_flight=False, dense_output=True)),
], ids=["seed", "steel", "rests"])
def test_method_auto_is_bit_identical(monkeypatch, scene, t_end, kw):
    """Stage 2c: method "auto", its switches and the method carried across segments."""
    scene = ballc.Scene(**scene)
    kw = dict(kw, method="auto")
    p = _run(monkeypatch, True, scene, t_end, **kw)
    c = _run(monkeypatch, False, scene, t_end, **kw)
    _assert_identical(p, c)
    assert p.method_switches == c.method_switches
    if kw.get("dense_output"):
        times = np.linspace(0.0, t_end if t_end < 10 else 100.0, 501)
        assert np.array_equal(p.sol(times), c.sol(times))


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5", "auto"])
def test_exact_flight_is_bit_identical(monkeypatch, method):
    """Stage 2c: a massless observer's throw (ballc.flight's closed-form segments and
    contact starts), with t_eval and dense output, and a run that rolls on."""
    throw = ballc.Scene(observer_mass=0, position=(0, 0, 3.0), velocity=(2.0, 0.5, 4.0),
                        angular_velocity=(3.0, -1.0, 20.0))
    for scene, t_end, kw in [
            (throw, 5.0, {}),
            (throw, 5.0, dict(rtol=1e-6, atol=1e-6, dense_output=True,
                              t_eval=np.linspace(0.0, 5.0, 41))),
            (ballc.Scene(observer_mass=0), 100.0, dict(rtol=1e-6, atol=1e-6))]:
        kw = dict(kw, method=method)
        p = _run(monkeypatch, True, scene, t_end, **kw)
        c = _run(monkeypatch, False, scene, t_end, **kw)
        _assert_identical(p, c)
        assert p.method_switches == c.method_switches
        if kw.get("dense_output"):
            times = np.linspace(0.0, t_end, 501)
            assert np.array_equal(p.sol(times), c.sol(times))


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5", "auto"])
@pytest.mark.parametrize("tol", [1e-4, 1e-6, 1e-9])
def test_the_compliant_modes_are_bit_identical(monkeypatch, method, tol):
    """Stage 3: the compliant law's exact modes (arming, yield/decide, re-stick, the
    capacity guard re-armed in C, the step bound's segment ends)."""
    scene = ballc.Scene(tangential_model="compliant")
    kw = dict(method=method, rtol=tol, atol=tol)
    p = _run(monkeypatch, True, scene, 5.0, **kw)
    c = _run(monkeypatch, False, scene, 5.0, **kw)
    _assert_identical(p, c)
    assert any(phase == "stick" for k in c.contacts for _, phase in k.transitions)
    assert any(phase == "slip" for k in c.contacts for _, phase in k.transitions)


@needs_c_numerics
@pytest.mark.parametrize("method", ["dop853", "radau5"])
def test_user_events_are_bit_identical(monkeypatch, method):
    """Stage 4: the user's callables (called back from C, as often as by the Python
    driver), terminal at a count, and LinearEvents (also in exact flight)."""
    calls = []

    def apex(t, y):
        calls.append(t)
        return y[12]
    apex.direction = -1

    def twice(t, y):
        return y[6] - 1.2
    twice.terminal, twice.direction = 2, -1
    height = ballc.events.LinearEvent.of_state("z", 1.0, -0.8, terminal=3, direction=-1)
    for scene, kw in [(ballc.Scene(), dict(events=[apex])),
                      (ballc.Scene(), dict(events=[twice, apex], dense_output=True)),
                      (ballc.Scene(observer_mass=0), dict(events=[height, apex]))]:
        kw = dict(kw, method=method, rtol=1e-6, atol=1e-6)
        calls.clear()
        p = _run(monkeypatch, True, scene, 5.0, **kw)
        python_calls = list(calls)
        calls.clear()
        c = _run(monkeypatch, False, scene, 5.0, **kw)
        _assert_identical(p, c)
        assert calls == python_calls
        for a, b in zip(p.t_events + p.y_events, c.t_events + c.y_events):
            assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)


@needs_c_numerics
def test_a_user_event_that_raises_raises_as_in_python(monkeypatch):
    def bad(t, y):
        if t > 0.5:
            raise KeyError("boom")
        return 1.0

    def nan(t, y):
        return float("nan") if t > 0.5 else 1.0
    for event, error in ((bad, KeyError), (nan, ValueError)):
        messages = []
        for python in (True, False):
            with pytest.raises(error) as caught:
                _run(monkeypatch, python, ballc.Scene(), 2.0, method="dop853", events=[event])
            messages.append(str(caught.value))
        assert messages[0] == messages[1]


@needs_c_numerics
def test_the_python_driver_switch():
    """BALLC_PYTHON_DRIVER is read per call."""
    import os
    scene = ballc.Scene(mixture=0.3, friction_coefficient=0.2)
    os.environ["BALLC_PYTHON_DRIVER"] = "1"
    try:
        assert ballc.simulate(scene, 0.3, method="dop853", rtol=1e-3, atol=1e-3,
                              progress=False)._driver == "python"
    finally:
        del os.environ["BALLC_PYTHON_DRIVER"]
    assert ballc.simulate(scene, 0.3, method="dop853", rtol=1e-3, atol=1e-3,
                          progress=False)._driver == "c"


# ---- the numerics the C loop must share with CPython and numpy (docs/c_loop_plan.md 1.5)

@needs_c_numerics
def test_the_hypot_port_is_math_hypot():
    rng = np.random.default_rng(22)
    for n in (2, 3, 4):
        v = rng.standard_normal((100_000, n)) * np.exp(rng.uniform(-700, 700, (100_000, 1)))
        v[:100] = rng.standard_normal((100, n)) * 5e-324 * 1e3   # subnormals
        v[100:110] = 0.0
        ours = _core._hypot_many(np.ascontiguousarray(v))
        theirs = np.array([math.hypot(*row) for row in v.tolist()])
        assert np.array_equal(ours, theirs), n


def test_the_ulp_port_is_math_ulp():
    rng = np.random.default_rng(23)
    x = rng.standard_normal(50_000) * np.exp(rng.uniform(-700, 700, 50_000))
    values = x.tolist() + [0.0, 5e-324, 1.7976931348623157e308, -1.0, math.inf]
    assert all(_core._py_ulp(a) == math.ulp(a) for a in values)


@needs_c_numerics
def test_the_fma_dot_is_numpys_dot():
    """modes.latch_values takes |v| as sqrt(v.dot(v)): numpy's (BLAS) dot, which the C
    loop reproduces as fma(c, c, fma(b, b, a a)).  A BLAS or CPU that sums otherwise
    fails here (then the C loop is not bit-identical on contact starts)."""
    rng = np.random.default_rng(24)
    v = rng.standard_normal((200_000, 3)) * np.exp(rng.uniform(-20, 20, (200_000, 1)))
    theirs = np.array([row.dot(row) for row in v])
    assert np.array_equal(_core._dot3_fma_many(np.ascontiguousarray(v)), theirs)


def test_the_numerics_check_decides_the_driver(monkeypatch):
    """Where the process's hypot or dot differ from the ports, every run in the C loop's
    subset takes the Python driver; where they agree (here), the C loop."""
    driver = sys.modules["ballc.simulate"]
    scene = ballc.Scene(mixture=0.3, friction_coefficient=0.2)
    kw = dict(method="dop853", rtol=1e-3, atol=1e-3)
    monkeypatch.setattr(driver, "_NUMERICS_AGREE", [False])
    assert _run(monkeypatch, False, scene, 0.3, **kw)._driver == "python"
    monkeypatch.setattr(driver, "_NUMERICS_AGREE", [True])
    assert _run(monkeypatch, False, scene, 0.3, **kw)._driver == "c"


def test_a_wrapped_integrator_seam_gets_the_python_driver(monkeypatch):
    driver = __import__("sys").modules["ballc.simulate"]
    calls = []
    original = driver.integrate_segment

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)
    monkeypatch.setattr(driver, "integrate_segment", counting)
    result = _run(monkeypatch, False, ballc.Scene(), 0.5, method="dop853", rtol=1e-3,
                  atol=1e-3)
    assert result._driver == "python" and calls


#: The child of test_ctrl_c_stops_a_long_c_run: a run of millions of elastic bounces
#: (1e7 s, hours of work) in the C loop, sampled only at its ends (t_eval) so that its
#: memory stays bounded however long it runs; "started" once the next line is the run.
_LONG_RUN = """
import signal
import sys
import numpy as np
import ballc
# a terminal's process: Ctrl-C raises KeyboardInterrupt (a process started in the
# background by a shell without job control inherits SIGINT ignored)
signal.signal(signal.SIGINT, signal.default_int_handler)
scene = ballc.Scene(velocity=(0.0, 0.0, 0.0), observer_mass=0.0, c_tau=1.0,
                    tangential_model="friction", friction_coefficient=0.0)
t_eval = np.array([0.0, 1e7])
ballc.simulate(scene, 10.0, t_eval=[0.0, 10.0], progress=False)   # imports, first calls
c_loop = sys.modules["ballc.simulate"]._c_config(
    scene, ballc.options.check_options(scene, 1e7, t_eval=t_eval), False, True) is not None
print("started", "c" if c_loop else "python", flush=True)
ballc.simulate(scene, 1e7, t_eval=t_eval, progress=False, max_nfev=10**12)
print("finished", flush=True)
"""


def test_ctrl_c_stops_a_long_c_run():
    """The C loop asks for pending signals (before each segment; a bounce is a few
    segments), as the Python driver can be interrupted between segments: a Ctrl-C
    (SIGINT) sent from this process to a child running a long C run ends it with
    KeyboardInterrupt, promptly.  The signal comes from another process, after the
    child said the run starts (and a second more, so that it lands inside the run
    rather than just before it -- either way the child must stop, so no outcome of
    this test depends on scheduling); 60 s is the generous bound on "promptly" (the
    run would take hours)."""
    import os
    import signal
    import subprocess
    import time
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    env.pop("BALLC_PYTHON_DRIVER", None)
    child = subprocess.Popen([sys.executable, "-c", _LONG_RUN], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = child.stdout.readline()
        assert line.split()[:1] == ["started"], (line, child.stderr.read())
        if C_NUMERICS:
            assert line.split()[1] == "c"
        time.sleep(1.0)
        child.send_signal(signal.SIGINT)
        try:
            out, err = child.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            out = err = None
    finally:
        if child.poll() is None:
            child.kill()
            child.communicate()
    assert out is not None, "the run went on for 60 s after the Ctrl-C"
    assert "finished" not in out
    assert child.returncode != 0
    assert err.rstrip().splitlines()[-1] == "KeyboardInterrupt", err
