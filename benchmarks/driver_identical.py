"""Do the C segment loop and the Python one give the same bits?  (docs/c_loop_plan.md)

    python -m benchmarks.driver_identical [--quick]

One process: each case runs with the Python driver (BALLC_PYTHON_DRIVER=1) and with the
default (the C loop where the run is in its subset), and every output is compared:
t, y, flags, latch (np.array_equal, NaN equal to NaN, and dtype and memory order),
status, message, nfev/njev/nlu, t_events/y_events, every field of every contact
(value and type), method_switches, and Result.sol's pieces and values.  A case marked
C-eligible fails if it ran in Python (``_driver``), so a fallback cannot pass vacuously.
Exit status 0 when all are identical, 1 otherwise.

Cases (see cases()): the comeback map's cells Scene(mixture=m, friction_coefficient=mu),
1.2 s at rtol = atol = 1e-3, m in {0, 0.3, 0.7, 1}, mu in {0, 0.2, 0.5, 1}, both
methods; the seed scene Scene() for 5 s at the default tolerance and at 1e-6; other
paths of stage 1 (a start in contact, regularised friction, max_step and first_step, y0,
passing through, the ceiling, a call budget); stage 2a, the rest checks (rest, uniform
rolling, checks that find neither); 2b, t_eval and dense output; 2c, method "auto" and
exact flight; 3, the compliant law's modes at 1e-4/1e-6/1e-9; 4, user events (terminal
and not, callables and LinearEvents); ballc.orbit (the seed's wobbling roll, refused
trials); per-state atol and a LinearEvent of several states in exact flight.  scipy's
methods run in the C loop too, not bit-identically (tests/test_c_integrators.py compares
them).
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

import ballc

METHODS = ("dop853", "radau5")
#: tests/test_auto_method.py's stiff scene (method "auto" switches on it)
STEEL = dict(tangential_model="friction", ball_youngs_modulus=2e11, plane_youngs_modulus=2e11,
             c_tau=0.5, observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))


def cases(quick=False):
    mixtures = (0.0, 0.3, 0.7, 1.0)
    mus = (0.0, 0.2, 0.5, 1.0)
    if quick:
        mixtures, mus = (0.0, 0.3), (0.2, 1.0)
    out = []
    for m in mixtures:
        for mu in mus:
            for method in METHODS:
                out.append((f"map m={m} mu={mu} {method}", dict(mixture=m, friction_coefficient=mu),
                            1.2, dict(method=method, rtol=1e-3, atol=1e-3), True))
    for method in METHODS:
        out.append((f"seed 5 s {method} default tol", {}, 5.0, dict(method=method), True))
        out.append((f"seed 5 s {method} 1e-6", {}, 5.0,
                    dict(method=method, rtol=1e-6, atol=1e-6), True))
    # other paths of the C loop: a start in contact, regularised friction, max_step and
    # first_step, a user y0, passing through (status 1), the ceiling, a call budget
    # (status -1)
    out += [
        ("start in contact", dict(position=(0, 0, 0.9999), velocity=(0.3, 0, 0),
                                  angular_velocity=(0, 0, 0), c_tau=0.2), 3.0,
         dict(method="dop853", rtol=1e-4, atol=1e-4), True),
        ("regularised friction", dict(friction_regularization="max"), 1.2,
         dict(method="radau5", rtol=1e-4, atol=1e-4), True),
        ("max_step, first_step", dict(mixture=0.3, friction_coefficient=0.5), 1.2,
         dict(method="dop853", rtol=1e-5, atol=1e-5, max_step=0.01, first_step=1e-4), True),
        ("y0", {}, 1.0, dict(method="radau5", rtol=1e-6, atol=1e-6,
                            y0=[1, 0.1, 0, 0, 0, 0, 3, 5, 1, 0, 1, 0, -2, 0, 0, 0, 0, 0, 0]),
         True),
        ("passing through", dict(velocity=(0, 0, -2000.0), ball_youngs_modulus=1e4), 0.1,
         dict(method="dop853", rtol=1e-3, atol=1e-3), True),
        ("ceiling", dict(position=(0, 0, 2.0), velocity=(1.0, 0, 14.0), ceiling_height=5.0,
                         friction_coefficient=0.6), 2.0,
         dict(method="dop853", rtol=1e-6, atol=1e-6), True),
        ("call budget", dict(mixture=0.3, friction_coefficient=0.2), 1.2,
         dict(method="radau5", rtol=1e-3, atol=1e-3, max_nfev=300), True),
    ]
    # stage 2a: the rest checks (ballc.resting): rest, uniform rolling and sliding, and
    # checks that find neither (the next one scheduled)
    for method in METHODS:
        out += [
            (f"drop, rests 1e6 s {method} 1e-6", dict(velocity=(0, 0, 0), observer_mass=0),
             1e6, dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False), True),
            (f"drop, rests 100 s {method} 1e-4", dict(velocity=(0, 0, 0), observer_mass=0),
             100.0, dict(method=method, rtol=1e-4, atol=1e-4, exact_flight=False), True),
            (f"seed 30 s {method} 1e-6 (checks)", {}, 30.0,
             dict(method=method, rtol=1e-6, atol=1e-6), True),
            (f"massless observer 100 s {method} 1e-6 (rolls)", dict(observer_mass=0), 100.0,
             dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False), True),
            (f"massless observer 1e6 s {method} 1e-6 (rolls)", dict(observer_mass=0), 1e6,
             dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False), True),
            (f"rest {method}", dict(position=(0, 0, 0.9999), velocity=(0, 0, 0),
                                    angular_velocity=(0, 0, 0), c_tau=0.2, observer_mass=0),
             6.0, dict(method=method, rtol=1e-4, atol=1e-4, exact_flight=False), True),
            (f"rest, observer below {method}", dict(position=(0, 0, 0.9999),
                                                   velocity=(0, 0, 0),
                                                   angular_velocity=(0, 0, 0), c_tau=0.2,
                                                   observer_position=(0, 0, -0.5)), 6.0,
             dict(method=method, rtol=1e-4, atol=1e-4), True),
            (f"mu=0, no end state {method}", dict(observer_mass=0, friction_coefficient=0.0,
                                            velocity=(1.0, 0, 0)), 60.0,
             dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False), True),
        ]
    # stage 2b: t_eval and dense output (Result.sol compared at its pieces' ends and
    # on a grid)
    for method in METHODS:
        out += [
            (f"seed 5 s t_eval {method}", {}, 5.0,
             dict(method=method, t_eval=np.linspace(0, 5.0, 101)), True),
            (f"seed 5 s t_eval, no 0 {method} 1e-6", {}, 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, t_eval=np.linspace(0.01, 4.0, 37)),
             True),
            (f"seed 5 s dense output {method}", {}, 5.0,
             dict(method=method, dense_output=True), True),
            (f"map cell dense + t_eval {method}", dict(mixture=0.3, friction_coefficient=0.2),
             1.2, dict(method=method, rtol=1e-3, atol=1e-3, dense_output=True,
                       t_eval=[0.0, 0.3, 0.6, 1.2]), True),
            (f"drop, rests, dense output {method}", dict(velocity=(0, 0, 0), observer_mass=0),
             1e6, dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False,
                       dense_output=True), True),
            (f"rolls, dense output {method}", dict(observer_mass=0), 100.0,
             dict(method=method, rtol=1e-6, atol=1e-6, exact_flight=False,
                  dense_output=True), True),
            (f"call budget, dense output {method}", dict(mixture=0.3, friction_coefficient=0.2),
             1.2, dict(method=method, rtol=1e-3, atol=1e-3, max_nfev=300, dense_output=True),
             True),
        ]
    # stage 2c: method "auto" (method_switches compared too)
    out += [
        ("auto: seed 5 s", {}, 5.0, dict(method="auto"), True),
        ("auto: seed 5 s 1e-6, dense output", {}, 5.0,
         dict(method="auto", rtol=1e-6, atol=1e-6, dense_output=True), True),
        ("auto: seed 30 s 1e-6 (rest checks)", {}, 30.0,
         dict(method="auto", rtol=1e-6, atol=1e-6), True),
        ("auto: steel ball 1e-9, dense (switches)", STEEL, 3.0,
         dict(method="auto", rtol=1e-9, atol=1e-9, dense_output=True, exact_flight=False),
         True),
        ("auto: steel ball 1e-10 (switches)", STEEL, 5.0,
         dict(method="auto", rtol=1e-10, atol=1e-10, exact_flight=False), True),
        ("auto: steel ball 1e-9, t_eval", STEEL, 3.0,
         dict(method="auto", rtol=1e-9, atol=1e-9, t_eval=np.linspace(0.0, 3.0, 301),
              exact_flight=False), True),
        ("auto: map cell", dict(mixture=0.3, friction_coefficient=0.2), 1.2,
         dict(method="auto", rtol=1e-3, atol=1e-3), True),
        ("auto: drop, rests", dict(velocity=(0, 0, 0), observer_mass=0), 1e6,
         dict(method="auto", rtol=1e-6, atol=1e-6, exact_flight=False), True),
    ]
    # stage 2c: exact flight (ballc.flight: a massless observer's scene)
    throw = dict(observer_mass=0, position=(0, 0, 3.0), velocity=(2.0, 0.5, 4.0),
                 angular_velocity=(3.0, -1.0, 20.0))
    for method in METHODS + ("auto",):
        out += [
            (f"flight: throw 5 s {method}", throw, 5.0, dict(method=method), True),
            (f"flight: throw 5 s {method} 1e-6, dense, t_eval", throw, 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, dense_output=True,
                  t_eval=np.linspace(0.0, 5.0, 77)), True),
            (f"flight: Scene(observer_mass=0) 100 s {method} 1e-6", dict(observer_mass=0),
             100.0, dict(method=method, rtol=1e-6, atol=1e-6), True),
            (f"flight: Scene(observer_mass=0) 1e6 s {method} 1e-6, dense",
             dict(observer_mass=0), 1e6, dict(method=method, rtol=1e-6, atol=1e-6,
                                              dense_output=True), True),
            (f"flight: drop, rests {method}", dict(velocity=(0, 0, 0), observer_mass=0), 1e6,
             dict(method=method, rtol=1e-6, atol=1e-6), True),
            (f"flight: steel, max_step {method}", STEEL, 3.0,
             dict(method=method, rtol=1e-8, atol=1e-8, max_step=0.01), True),
        ]
    out += [("flight: ceiling, massless", dict(observer_mass=0, position=(0, 0, 2.0),
                                               velocity=(1.0, 0, 14.0), ceiling_height=5.0,
                                               friction_coefficient=0.6), 2.0,
             dict(method="dop853", rtol=1e-6, atol=1e-6, dense_output=True), True)]
    # stage 3: the compliant law's exact modes (ballc.compliantmodes)
    for method in METHODS + ("auto",):
        for tol in (1e-4, 1e-6, 1e-9):
            out.append((f"compliant 5 s {method} {tol:g}", dict(tangential_model="compliant"),
                        5.0, dict(method=method, rtol=tol, atol=tol), True))
    out += [
        ("compliant, steel, dense", dict(STEEL, tangential_model="compliant"), 2.0,
         dict(method="radau5", rtol=1e-6, atol=1e-6, dense_output=True), True),
        ("compliant, no damping", dict(tangential_model="compliant",
                                       tangential_damping_ratio=0.0), 3.0,
         dict(method="dop853", rtol=1e-6, atol=1e-6), True),
        ("compliant, smooth (no modes)", dict(tangential_model="compliant",
                                              friction_regularization="smooth"), 2.0,
         dict(method="radau5", rtol=1e-6, atol=1e-6), True),
        ("compliant, massless, rests", dict(tangential_model="compliant", observer_mass=0,
                                            velocity=(0, 0, 0)), 1e6,
         dict(method="radau5", rtol=1e-6, atol=1e-6), True),
    ]
    # issue 28: the viscoelastic damping's contacts begin at the arming depth (without
    # modes too), and a sliding contact's Jacobian is taken at every step
    # (benchmarks.hard_compliant's scenes)
    hard = dict(ball_youngs_modulus=2e11, tangential_model="compliant", restitution=0.5)
    for method in METHODS:
        out += [
            (f"compliant, steel drop, viscoelastic, mu 0 {method}",
             dict(hard, normal_damping="viscoelastic", friction_coefficient=0.0,
                  velocity=(0, 0, 0)), 3.0, dict(method=method), True),
            (f"compliant, steel throw, spinning {method}",
             dict(hard, friction_coefficient=0.1, tangential_stiffness_ratio=1.0,
                  position=(0, 0, 3.0), velocity=(4.0, 1.0, -6.0),
                  angular_velocity=(30.0, 60.0, 5.0)), 0.5, dict(method=method), True),
        ]
    # stage 4: the user's events (callables called back from C; LinearEvents in C)
    def apex(t, y):   # vz falling through 0: each apex of a bounce
        return y[12]
    apex.direction = -1

    def low(t, y):    # z below 0.5 m, terminal
        return y[6] - 0.5
    low.terminal = True

    def twice(t, y):  # the second time z falls through 1.2 m stops the run
        return y[6] - 1.2
    twice.terminal, twice.direction = 2, -1
    height = ballc.events.LinearEvent.of_state("z", 1.0, -2.0, terminal=False, direction=0)
    height_stop = ballc.events.LinearEvent.of_state("z", 1.0, -0.8, terminal=3, direction=-1)
    for method in METHODS + ("auto",):
        out += [
            (f"user: apex, not terminal {method}", {}, 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[apex]), True),
            (f"user: terminal {method}", {}, 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[apex, low]), True),
            (f"user: terminal at the 2nd, dense {method}", {}, 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[twice, apex],
                  dense_output=True), True),
            (f"user: LinearEvents, flight {method}", dict(observer_mass=0), 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[height, height_stop]), True),
            (f"user: LinearEvent + callable, flight {method}", dict(observer_mass=0), 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[height, apex],
                  t_eval=np.linspace(0.0, 5.0, 51)), True),
            (f"user: compliant, terminal {method}", dict(tangential_model="compliant"), 5.0,
             dict(method=method, rtol=1e-6, atol=1e-6, events=[twice]), True),
        ]
    # ballc.orbit: the seed's trials and its wobbling roll (the orbit in C for both)
    out += [
        ("orbit: seed 100 s, dense", {}, 100.0, dict(dense_output=True), True),
        ("orbit: seed 100 s, auto", {}, 100.0, dict(method="auto", rtol=1e-8, atol=1e-8), True),
        ("orbit: refused trials (spin 30, 120 s)", dict(angular_velocity=(0, 0, 30)), 120.0,
         dict(method="dop853", rtol=1e-6, atol=1e-6), True),
    ]
    # what the C loop took on last (issue 29b): per-state atol, a LinearEvent of several
    # states in exact flight (plain C dots: identical here, not promised); scipy's methods
    # run in the C loop too, to within rounding of the Python driver's, not bit for bit
    # (tests/test_c_integrators.py)
    atol = np.full(19, 1e-6)
    atol[[6, 12]] = 1e-9
    out += [
        ("per-state atol, seed 5 s radau5", {}, 5.0,
         dict(method="radau5", rtol=1e-6, atol=atol), True),
        ("a LinearEvent of several states in exact flight", dict(observer_mass=0),
         2.0, dict(method="dop853", rtol=1e-6, atol=1e-6, events=[ballc.events.LinearEvent(
             np.eye(19)[6] + np.eye(19)[4], -1.0)]), True),
    ]
    return out


def run(scene_kw, t_end, kw, python):
    if python:
        os.environ["BALLC_PYTHON_DRIVER"] = "1"
    else:
        os.environ.pop("BALLC_PYTHON_DRIVER", None)
    try:
        return ballc.simulate(ballc.Scene(**scene_kw), t_end, progress=False, **kw)
    finally:
        os.environ.pop("BALLC_PYTHON_DRIVER", None)


def same(a, b):
    """Equal bits and the same type (arrays: dtype, shape, order too)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return (a.dtype == b.dtype and a.shape == b.shape
                and a.flags.f_contiguous == b.flags.f_contiguous
                and a.flags.c_contiguous == b.flags.c_contiguous
                and np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, (float, np.floating)):
        return (a == b and np.signbit(a) == np.signbit(b)) or (a != a and b != b)
    if hasattr(a, "__dataclass_fields__"):
        return all(same(getattr(a, k), getattr(b, k)) for k in a.__dataclass_fields__)
    return a == b


def sol_values(result):
    """Result.sol at its pieces' ends and on a grid of 1001 times (None without)."""
    sol = result.sol
    if sol is None:
        return None
    times = np.concatenate([[a for a, _, _ in sol.pieces], [b for _, b, _ in sol.pieces],
                            np.linspace(sol.t_min, sol.t_max, 1001)])
    out = [np.array([(a, b) for a, b, _ in sol.pieces])]
    for where in [times] + [np.linspace(a, b, 11) for a, b, _ in sol.pieces]:
        try:
            out.append(sol(where))
        except (ValueError, IndexError) as error:   # a piece without steps: as Python's
            out.append(type(error).__name__)
    return out


def differences(p, c):
    found = [] if same(sol_values(p), sol_values(c)) else ["sol"]
    for name in ("t", "y", "flags", "latch", "status", "message", "nfev", "njev", "nlu",
                 "t_events", "y_events", "contacts", "method_switches"):
        if not same(getattr(p, name), getattr(c, name)):
            found.append(name)
    return found


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a few map cells only")
    args = parser.parse_args(argv)
    bad = 0
    for name, scene_kw, t_end, kw, eligible in cases(args.quick):
        p = run(scene_kw, t_end, kw, True)
        c = run(scene_kw, t_end, kw, False)
        driver = getattr(c, "_driver", "?")
        if getattr(p, "_driver", "?") != "python":
            print(f"{name}: BALLC_PYTHON_DRIVER did not select the Python driver")
            bad += 1
        diff = differences(p, c)
        verdict = "identical" if not diff else "DIFFERENT: " + ", ".join(diff)
        if eligible and driver != "c":
            verdict += " (FELL BACK to Python)"
            bad += 1
        elif not eligible and driver != "python":
            verdict += " (ran in C but should fall back)"
            bad += 1
        bad += bool(diff)
        print(f"{name:40s} driver={driver:7s} {verdict}", flush=True)
    print("all identical" if not bad else f"{bad} problem(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
