"""Work-precision: CPU time against error, per integrator, on three scenes.

    python -m benchmarks.work_precision [--quick] [--budget SECONDS] [--peers]

For each scene a reference is computed with radau5 at rtol = atol = 1e-13 (its
distance to radau5 at 1e-12 is printed as the reference's own uncertainty).  Then
for each tolerance rtol = atol (1e-3 .. 1e-12) and each method -- ballc's two compiled
integrators, radau5 (Radau IIA, order 5, implicit) and dop853 (Dormand & Prince's
explicit pair of order 8: scipy's DOP853 step by step in C, in radau5's loop with the
same events and output), and scipy's Radau, BDF, LSODA and DOP853 through solve_ivp
(scipy's DOP853 is the algorithm ballc's dop853 is a port of) -- it measures CPU seconds
(time.process_time around ``ballc.simulate``; a run under 0.1 s is repeated within one
timing window of at least 0.1 s -- with RLIMIT_CPU set (below) the process clock
advances in 4-ms ticks here -- and the best of 2 windows is kept), the final-state
error (max |difference| of centre position (m) and velocity (m/s) at t_end) and the
contact-time error (max |difference| of contact start/end times, s; "count" when the
number of contacts differs).  Each run happens in a child process
with a CPU-time budget (RLIMIT_CPU): a run that exceeds it is reported as such.

The scenes use the default friction law, exact Coulomb friction as stick/slip events
(``friction_regularization="exact"``).  On the seed and friction-only scenes radau5
also runs two regularised laws as extra curves: the seed's literal
``max(|v_t|, 1e-10 m/s)`` ("max") -- at loose tolerances its viscous core makes the
integrator crawl (the cliff "exact" removes) -- and ``"smooth"`` with v_s = 1e-4 m/s.
Each law's error is measured against its own radau5 1e-13 reference (so it is the
integration error); the distance between the laws' references is printed too.

Equal error: for each scene and each error level 1e-3 .. 1e-9 (a decade above the
reference's own uncertainty), the CPU of each method's cheapest run whose final error
is at most that level and stays so at every tighter tolerance, and which method is
cheapest there.

Stiffness: dop853 is explicit, so where the system is stiff its steps are bounded by
stability, not accuracy.  Two stiff scenes -- a steel-hard ball (E = 2e11 Pa, ball and
planes) dropped with a sideways push, which settles by t ~ 2.2 s and then rolls in
permanent floor contact (the contact's normal spring, and with the compliant
tangential law its tangential spring, stiff), with the default exact friction and with
``tangential_model="compliant"``, 5 s, and the first also for 20 s -- are run with
radau5 and dop853 at a few tolerances, against radau5 at 1e-11 (radau5 at 1e-12 and
1e-13 stalls in that resting contact; the reference's uncertainty is its distance to
dop853 at 1e-12).

A compact table runs the 12 scenes mu in {0, 0.1, 0.4, 0.8} x mixture in {0, 0.375,
0.7} (1.2 s of the seed throw) with radau5 at every tolerance: status and RHS calls.

The seed's own pipeline (lambdify + numpy + scipy Radau, ``codegen.seed_reference``)
is the baseline on the seed scene, only at rtol = atol = 1e-9 and 1e-12 (with
--quick: 1e-12 only): it costs 7-30 s per run (at 1e-6 it exceeded 240 s).  Its contacts come from 1-ms
samples, so only its final-state error is reported.

Also measured: the per-scene specialisations (contact kernels skipped in free
flight, observer kernels skipped when observer_mass = 0), as CPU per RHS call of the
same trajectory with the kernels switched on and off.

Writes docs/work_precision.png and docs/work_precision.md.  ``--peers`` then runs
``benchmarks.peers`` (ballc's radau5 and dop853 against SUNDIALS CVODE and Hairer's
RADAU5 on the same compiled system; docs/peers.md), which needs ``pip install ".[bench]"``.
"""
from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import queue as queue_module
import resource
import time
from pathlib import Path

import numpy as np

import ballc
from ballc import _core, _radau5

T_END = 5.0
SCENES = {
    "seed": ballc.Scene(),
    "conservative oblique": ballc.Scene(c_tau=1.0, friction_coefficient=0.0, mixture=0.0,
                                        velocity=(3.0, 1.0, -20.0)),
    "friction only": ballc.Scene(tangential_model="friction"),
}
SCENE_NOTES = {
    "seed": "the seed's defaults (mixture 0.375, mu 0.1, c_tau 0.9)",
    "conservative oblique": "c_tau = 1, mu = 0, mixture = 0, velocity (3, 1, -20) m/s",
    "friction only": "tangential_model = friction: every contact ends rolling",
}
#: ballc's compiled integrators, then scipy's (solve_ivp); "DOP853" is scipy's, the
#: algorithm ballc's "dop853" is a port of.
METHODS = ("radau5", "dop853", "Radau", "BDF", "LSODA", "DOP853")
COMPILED = ("radau5", "dop853")
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
QUICK_TOLERANCES = (1e-6, 1e-9, 1e-12)
SEED_TOLERANCES = (1e-9, 1e-12)   # at 1e-6 the seed's run exceeded 240 s
#: Regularised friction laws run with radau5 as extra curves on these scenes.
LAW_SCENES = ("seed", "friction only")
LAWS = {
    "radau5, 'max' v_s=1e-10": {"friction_regularization": "max",
                                "friction_regularization_speed": 1e-10},
    "radau5, 'smooth' v_s=1e-4": {"friction_regularization": "smooth",
                                  "friction_regularization_speed": 1e-4},
}
#: Error levels of the equal-error summary (down to a decade above the references'
#: own uncertainty, 1e-10 .. 3e-10).
EQUAL_ERRORS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
#: Stiff scenes (radau5 against dop853 only): a steel-hard ball that settles and rolls.
_STEEL = dict(ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, c_tau=0.5,
              observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))
STIFF_SCENES = {   # name -> (scene, t_end)
    "steel, exact friction": (ballc.Scene(tangential_model="friction", **_STEEL), 5.0),
    "steel, exact friction, 20 s": (ballc.Scene(tangential_model="friction", **_STEEL), 20.0),
    "steel, compliant": (ballc.Scene(tangential_model="compliant", **_STEEL), 5.0),
}
STIFF_NOTE = ("a 1-kg, 1-m ball with E = 2e11 Pa (ball and planes), c_tau = 0.5, dropped "
              "from 1 m above the floor with 0.5 m/s sideways: 18 contacts, settled by "
              "t ~ 2.2 s, then rolling in permanent floor contact to t = 5 s (and 20 s)")
STIFF_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
STIFF_REFERENCE = ("radau5", 1e-11)
STIFF_CHECK = ("dop853", 1e-12)
#: The mu x mixture set (1.2 s of the seed throw, radau5, status and RHS calls).
GRID_MU = (0.0, 0.1, 0.4, 0.8)
GRID_MIXTURE = (0.0, 0.375, 0.7)
GRID_T_END = 1.2
PEERS_NOTE = ("radau5 and dop853 against other solvers on the same compiled right-hand "
              "side and Jacobian -- SUNDIALS CVODE (BDF, Adams) and Hairer's RADAU5 "
              "(Fortran and assimulo's C translation) -- segment by segment: "
              "[peers](peers.md) "
              "(`python -m benchmarks.peers`, or `--peers` here; needs "
              "`pip install \".[bench]\"`).")
_IDX = [_core.STATE_NAMES.index(n) for n in ("x", "y", "z", "vx", "vy", "vz")]
DOCS = Path(__file__).resolve().parent.parent / "docs"


def _summary(result):
    return {"final": result.y[_IDX, -1].copy(), "status": result.status,
            "inaccurate": "energy balance" in result.message,
            "contacts": np.array([[c.t_start, c.t_end] for c in result.contacts]),
            "nfev": result.nfev}


def _scene(scene_name, law=None):
    return SCENES[scene_name].replace(**LAWS[law]) if law else SCENES[scene_name]


#: A run shorter than this (CPU s) is repeated within one timing window this long: with
#: RLIMIT_CPU set the process clock advances in ticks of 4 ms here, as long as the
#: cheapest runs.
MIN_WINDOW = 0.1


def _run_ballc(scene_name, method, tol, law=None, scene=None, t_end=T_END, timed=True):
    scene = scene if scene is not None else _scene(scene_name, law)
    best, result = np.inf, None
    for _ in range(2 if timed else 1):
        runs, started = 0, time.process_time()
        while True:
            result = ballc.simulate(scene, t_end, method=method, rtol=tol, atol=tol)
            runs += 1
            elapsed = time.process_time() - started
            if not timed or elapsed >= MIN_WINDOW:
                break
        best = min(best, elapsed / runs)
        if best > 1.0:
            break
    return {"cpu": best, **_summary(result)}


def _run_seed(tol):
    from codegen.seed_reference import build_seed_model, run_seed_pipeline
    build_seed_model()
    seed = run_seed_pipeline(T_END, rtol=tol, atol=tol)
    final = np.concatenate([seed["y"][3:6, -1], seed["y"][9:12, -1]])
    return {"cpu": seed["cpu_seconds"], "final": final, "status": seed["status"],
            "contacts": None, "nfev": seed["nfev"]}


def _child(queue, fn, args, budget):
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # A CPU-time budget (the kernel stops the child with SIGXCPU), not a wall-time one:
    # on a machine shared with other work a wall budget cuts runs short by the load.
    limit = max(1, math.ceil(budget + time.process_time()))
    resource.setrlimit(resource.RLIMIT_CPU, (limit, limit + 5))
    try:
        queue.put(fn(*args))
    except Exception as exc:   # reported in the table, not hidden
        queue.put({"error": f"{type(exc).__name__}: {exc}"})


def _bounded(fn, args, budget):
    """fn(*args) in a child process; None when it exceeds ``budget`` CPU seconds
    (or, as a safety net, 20 budgets + 60 s of wall time)."""
    ctx = mp.get_context("fork")
    queue = ctx.Queue()
    proc = ctx.Process(target=_child, args=(queue, fn, args, budget))
    proc.start()
    deadline = time.monotonic() + 20 * budget + 60
    try:
        while time.monotonic() < deadline:
            try:
                return queue.get(timeout=0.2)
            except queue_module.Empty:
                if not proc.is_alive():     # stopped by its CPU limit (or crashed)
                    try:
                        return queue.get(timeout=1.0)
                    except queue_module.Empty:
                        return None
        return None
    finally:
        if proc.is_alive():
            proc.terminate()
        proc.join()


def _errors(run, ref):
    final = float(np.abs(run["final"] - ref["final"]).max())
    if run["contacts"] is None:
        contact = None
    elif run["contacts"].shape != ref["contacts"].shape:
        contact = "count"
    else:
        contact = float(np.nanmax(np.abs(run["contacts"] - ref["contacts"])))
    return final, contact


def _specialisation_rows():
    """CPU per RHS call of the same radau5 integration with kernels on and off.

    observer_mass = 0 makes the observer's terms vanish, and in free flight the contact
    terms vanish (penetration < 0), so switching their kernels on changes the cost only,
    not the trajectory: the "same result" column checks that.
    """
    scene = ballc.Scene(observer_mass=0.0)
    params = scene.parameter_vector()
    first = ballc.simulate(scene, 0.3, rtol=1e-12, atol=1e-12).contacts[0]
    latch = np.zeros(_core.N_LATCH)
    for k, sign in ((0, -1.0), (_core.N_LATCH_PER_PLANE, 1.0)):   # floor, ceiling
        latch[k] = first.penetration_rate_at_impact
        latch[k + 1:k + 4] = first.digin_direction * (-sign if k else 1.0)
    at_contact = ballc.simulate(scene, first.t_start, rtol=1e-12, atol=1e-12).y[:, -1]
    floor = _core.FLAGS["floor_friction"] | _core.FLAGS["floor_digin"]
    contact = floor | _core.FLAGS["ceiling_friction"] | _core.FLAGS["ceiling_digin"]
    cases = [  # label, start state, span, flags off, extra flags on
        ("observer kernels, in a floor contact (observer_mass = 0)", at_contact,
         (first.t_start, first.t_start + 0.05), floor, _core.FLAGS["observer"]),
        ("contact kernels, in free flight", scene.initial_state(), (0.0, 0.15), 0, contact),
    ]
    rows = []
    for label, y0, span, off, on in cases:
        cost = {}
        for flags in (off, off | on):
            best = np.inf
            for _ in range(5):
                started = time.process_time()
                for _ in range(20):
                    sol = _radau5.solve_system(params, latch, flags, span, y0,
                                               rtol=1e-12, atol=1e-12)
                best = min(best, (time.process_time() - started) / 20)
            cost[flags] = (best, sol.nfev, sol.y[:, -1])
        (t_off, n_off, y_off), (t_on, n_on, y_on) = cost[off], cost[off | on]
        same = bool(np.allclose(y_off, y_on, rtol=1e-13, atol=1e-13)) and n_off == n_on
        rows.append((label, t_on / n_on * 1e6, t_off / n_off * 1e6, t_on / t_off, same))
    return rows


def _cpu(x):
    """CPU seconds as ms with 2 significant digits (3 above 100 ms)."""
    ms = 1e3 * x
    if ms >= 1000:
        return f"{x:.3g} s"
    return f"{ms:.3g} ms" if ms >= 100 else f"{ms:.2g} ms"


def _equal_error_lines(results, references, law_references):
    lines = ["## Cheapest at equal error", "",
             "For each error level: the CPU of each method's cheapest run whose final-state "
             "error is at most that level *and* from whose tolerance on every tighter run "
             "stays within it too (so a lucky cancellation at one loose tolerance does not "
             "count), with that run's rtol = atol in brackets; `–`: no tolerance got there "
             "(or a tighter one left it again).  Levels down to 1e-9, a decade above the "
             "references' own uncertainty.  Exact friction (the regularised laws are "
             "another model, the seed pipeline another implementation: in the tables "
             "below).  **dop853 / radau5**: the ratio of the two compiled methods' CPU.", ""]
    for scene_name in SCENES:
        cheapest = _equal_error(results, references, law_references, scene_name, METHODS)
        lines += [f"**{scene_name}**", "",
                  "| error ≤ | " + " | ".join(METHODS) + " | cheapest | dop853 / radau5 |",
                  "|---|" + "---|" * (len(METHODS) + 2)]
        for level in EQUAL_ERRORS:
            cells, best = [], None
            for method in METHODS:
                got = cheapest.get((method, level))
                cells.append("–" if got is None else f"{_cpu(got[0])} ({got[1]:.0e})")
                if got is not None and (best is None or got[0] < best[1]):
                    best = (method, got[0])
            r5, d8 = cheapest.get(("radau5", level)), cheapest.get(("dop853", level))
            ratio = f"{d8[0] / r5[0]:.2g}" if r5 and d8 else "–"
            lines.append(f"| {level:.0e} | " + " | ".join(cells) + " | "
                         + (best[0] if best else "–") + f" | {ratio} |")
        lines.append("")
    return lines


def _stiff_lines(stiff, budget):
    lines = ["## When dop853 is the wrong choice", ""]
    facts = []
    for name, data in stiff.items():
        ref, (u_final, _) = data["reference"]
        if ref is None or "error" in ref or ref["status"] != 0:
            facts.append(f"{name}: the reference run failed, no errors measured.")
            continue
        runs = {(method, tol): run for method, tol, run in data["rows"]}

        def show(method, tol):
            run = runs.get((method, tol))
            if run is None:
                return f"{method} > {budget:g} s CPU (stopped)"
            if "error" in run:
                return f"{method} failed ({run['error']})"
            status = "" if run["status"] == 0 else f", status {run['status']}"
            return (f"{method} {_cpu(run['cpu'])}, {run['nfev']:,} RHS calls, error "
                    f"{_errors(run, ref)[0]:.1e}{status}")
        for tol in (1e-6, 1e-10):
            if ("radau5", tol) in runs:
                facts.append(f"{name}, rtol = atol = {tol:.0e}: {show('radau5', tol)}; "
                             f"{show('dop853', tol)}.")
    calls = {name: [run["nfev"] for method, tol, run in data["rows"]
                    if method == "dop853" and run is not None and "error" not in run
                    and run["status"] == 0 and 1e-10 <= tol <= 1e-8]
             for name, data in stiff.items()}
    lines += [
        "dop853 is explicit: its step is bounded by the stability of the fastest mode, "
        "whatever the tolerance.  The seed's rubber ball (E = 3 kPa) is not stiff -- "
        "its contacts last tenths of a second and the steps must resolve them anyway -- "
        "so on the three scenes above the two compete on accuracy alone (the equal-error "
        "tables).  "
        "A stiff scene: " + STIFF_NOTE + "; once at rest, the floor's contact spring (and, "
        "with `tangential_model=\"compliant\"`, the tangential spring) has a period of a "
        "fraction of a millisecond while the motion is a slow roll.  Measured (CPU per run, "
        "RHS calls, final-state error against radau5 at "
        f"{STIFF_REFERENCE[1]:.0e}):", ""]
    lines += [f"- {fact}" for fact in facts]
    wild = []   # dop853 runs that went wrong: final error >= 1e-2
    for name, data in stiff.items():
        ref = data["reference"][0]
        if ref is None or "error" in ref or ref["status"] != 0:
            continue
        for method, tol, run in data["rows"]:
            if (method == "dop853" and run is not None and "error" not in run
                    and _errors(run, ref)[0] >= 1e-2):
                wild.append(f"{name}, rtol = atol = {tol:.0e}: {run['nfev']:,} RHS calls, "
                            f"{_cpu(run['cpu'])}, final error {_errors(run, ref)[0]:.1e}")
    lines += ["", "dop853's RHS calls hardly depend on the tolerance there ("
              + "; ".join(f"{name}: {min(c):,} .. {max(c):,} for rtol 1e-8 .. 1e-10"
                          for name, c in calls.items() if c)
              + "): it runs at its stability limit, 12 calls a step (15 where the "
              "dense output is needed) at steps of a fraction of a millisecond for every "
              "second the ball rests; radau5 takes steps of the size the slow roll allows, "
              "so the gap grows with the time spent in contact (compare 5 s with 20 s)."
              + (("  At looser tolerances it can do worse -- more calls, not fewer, and "
                  "a wrong end state (an explicit method's error estimate is no stability "
                  "check): " + "; ".join(wild) + ".") if wild else "")
              + "  Use radau5 (the "
              "default) for hard materials, long resting or rolling contacts and the "
              "compliant tangential law; dop853 where the equal-error table above says so, on "
              "scenes that are not stiff.",
              ""]
    lines += ["| scene | method | rtol = atol | CPU | RHS calls | final error | contacts |",
              "|---|---|---|---|---|---|---|"]
    for name, data in stiff.items():
        ref, (u_final, _) = data["reference"]
        ok = ref is not None and "error" not in ref and ref["status"] == 0
        for method, tol, run in data["rows"]:
            if run is None:
                lines.append(f"| {name} | {method} | {tol:.0e} | > {budget:g} s (stopped) "
                             "| | | |")
            elif "error" in run:
                lines.append(f"| {name} | {method} | {tol:.0e} | {run['error']} | | | |")
            else:
                status = "" if run["status"] == 0 else f" (status {run['status']})"
                err = f"{_errors(run, ref)[0]:.1e}" if ok else "–"
                lines.append(f"| {name} | {method} | {tol:.0e} | {_cpu(run['cpu'])}{status} "
                             f"| {run['nfev']} | {err} | {len(run['contacts'])} |")
    stalled = [name for name, data in stiff.items() for method, tol, run in data["rows"]
               if method == "radau5" and tol < STIFF_REFERENCE[1]
               and (run is None or "error" in run or run["status"] != 0)]
    lines += ["", "Reference: " + "; ".join(
        f"{name}: {STIFF_REFERENCE[0]} at {STIFF_REFERENCE[1]:.0e} (status "
        f"{data['reference'][0]['status'] if data['reference'][0] else 'stopped'}), its "
        f"distance to {STIFF_CHECK[0]} at {STIFF_CHECK[1]:.0e} "
        f"{_fmt(data['reference'][1][0], 1)}"
        for name, data in stiff.items())
        + f" (radau5 at {STIFF_REFERENCE[1]:.0e}, not 1e-13 as above"
        + (": radau5 at tighter tolerances did not finish within the budget here ("
           + "; ".join(f"*{name}*" for name in stalled) + "): it stalls in the resting "
           "contact, a radau5 problem, not dop853's" if stalled else "") + ").  Errors "
        "below a scene's reference distance are not resolved.", ""]
    return lines


def _fmt(x, digits=2):
    return "–" if x is None else (x if isinstance(x, str) else f"{x:.{digits}e}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="3 tolerances, seed pipeline at 1e-12 only (a few minutes)")
    parser.add_argument("--budget", type=float, default=None,
                        help="CPU seconds per ballc run before it is reported as too "
                             "slow (default 8, quick 5)")
    parser.add_argument("--no-seed", action="store_true", help="skip the seed's pipeline")
    parser.add_argument("--peers", action="store_true",
                        help="then run benchmarks.peers (radau5 against CVODE and Hairer's "
                             "RADAU5; needs pip install \".[bench]\"; --quick passed on)")
    args = parser.parse_args(argv)
    if args.peers:   # fail now, not after the main run, when a peer is missing
        from benchmarks import peers
        peers.import_peers()
    tolerances = QUICK_TOLERANCES if args.quick else TOLERANCES
    seed_tolerances = () if args.no_seed else ((1e-12,) if args.quick else SEED_TOLERANCES)
    budget = args.budget or (5.0 if args.quick else 8.0)
    started_all = time.time()

    results = {}   # (scene, method) -> list of (tol, run or None)
    references = {}     # scene -> (reference, its uncertainty)
    law_references = {}  # (scene, law) -> (reference, uncertainty, distance to exact)
    for scene_name in SCENES:
        ref = _bounded(_run_ballc, (scene_name, "radau5", 1e-13), 120)
        check = _bounded(_run_ballc, (scene_name, "radau5", 1e-12), 120)
        references[scene_name] = (ref, _errors(check, ref))
        print(f"{scene_name}: reference radau5 1e-13, {ref['cpu']:.3f} s; vs 1e-12: "
              f"final {references[scene_name][1][0]:.1e}, contacts "
              f"{_fmt(references[scene_name][1][1], 1)}", flush=True)
        for method in METHODS:
            results[(scene_name, method)] = _tolerance_rows(
                scene_name, method, None, tolerances, budget, ref)
        if scene_name not in LAW_SCENES:
            continue
        for law in LAWS:
            law_ref = _bounded(_run_ballc, (scene_name, "radau5", 1e-13, law), 120)
            law_check = _bounded(_run_ballc, (scene_name, "radau5", 1e-12, law), 120)
            law_references[(scene_name, law)] = (law_ref, _errors(law_check, law_ref),
                                                 _errors(law_ref, ref))
            print(f"{scene_name}, {law}: reference 1e-13 vs 1e-12 final "
                  f"{law_references[(scene_name, law)][1][0]:.1e}; vs exact's reference: "
                  f"final {law_references[(scene_name, law)][2][0]:.1e}", flush=True)
            results[(scene_name, law)] = _tolerance_rows(scene_name, "radau5", law,
                                                         tolerances, budget, law_ref)
    stiff = _stiff_rows(budget)
    grid = _grid_rows(tolerances, budget)
    seed_rows = []
    for tol in seed_tolerances:
        run = _bounded(_run_seed, (tol,), 120)
        seed_rows.append((tol, run))
        print(f"  seed pipeline {tol:.0e}: "
              + ("> 120 s" if run is None else f"{run['cpu']:.2f} s"), flush=True)
    results[("seed", "seed pipeline")] = seed_rows
    special = _specialisation_rows()
    elapsed = time.time() - started_all

    DOCS.mkdir(exist_ok=True)
    _plot(results, references, law_references, budget, DOCS / "work_precision.png")
    _write_markdown(results, references, law_references, grid, special, stiff, budget,
                    elapsed, args, tolerances, DOCS / "work_precision.md")
    print(f"wrote {DOCS / 'work_precision.png'} and {DOCS / 'work_precision.md'} "
          f"({elapsed:.0f} s)")
    if args.peers:
        peers.main(["--quick"] if args.quick else [])


def _reference(references, law_references, scene_name, method):
    if method in LAWS:
        return law_references[(scene_name, method)][0]
    return references[scene_name][0]


def _tolerance_rows(scene_name, method, law, tolerances, budget, ref):
    rows = []
    label = law or method
    for tol in tolerances:
        run = _bounded(_run_ballc, (scene_name, method, tol, law), budget)
        rows.append((tol, run))
        print(f"  {label:26s} {tol:.0e}: "
              + ("> budget" if run is None else
                 run.get("error") or f"{run['cpu']:.3f} s, {run['nfev']} calls, status "
                 f"{run['status']}, final err {_errors(run, ref)[0]:.1e}"), flush=True)
    return rows


def _stiff_rows(budget):
    """{scene: {"reference": (run, uncertainty), "check": run, "rows": [(method, tol, run
    or None)]}}: radau5 and dop853 on the stiff scenes (see the module docstring)."""
    out = {}
    for name, (scene, t_end) in STIFF_SCENES.items():
        ref = _bounded(_run_ballc, (name, *STIFF_REFERENCE, None, scene, t_end), 120)
        check = _bounded(_run_ballc, (name, *STIFF_CHECK, None, scene, t_end), 120)
        uncertainty = (_errors(check, ref) if ref is not None and check is not None
                       and "error" not in ref and "error" not in check else (None, None))
        print(f"{name}: reference {STIFF_REFERENCE[0]} {STIFF_REFERENCE[1]:.0e} status "
              f"{ref and ref.get('status')}; vs {STIFF_CHECK[0]} {STIFF_CHECK[1]:.0e}: final "
              f"{_fmt(uncertainty[0], 1)}", flush=True)
        rows = []
        for tol in STIFF_TOLERANCES:
            for method in COMPILED:
                run = _bounded(_run_ballc, (name, method, tol, None, scene, t_end), budget)
                rows.append((method, tol, run))
                print(f"  {method:8s} {tol:.0e}: " + (
                    "> budget" if run is None else run.get("error") or
                    f"{run['cpu']:.4f} s, {run['nfev']} calls, status {run['status']}, "
                    f"final err {_errors(run, ref)[0]:.1e}"), flush=True)
        out[name] = {"reference": (ref, uncertainty), "check": check, "rows": rows}
    return out


def _equal_error(results, references, law_references, scene_name, methods):
    """{(method, level): (cpu, tol)}: the cheapest run of ``method`` whose final error is
    at most ``level`` and from whose tolerance on every tighter run (that finished) is
    too -- a lucky cancellation at one loose tolerance does not count; missing when no
    run got there.  A run with status != 0 counts as failing every level."""
    out = {}
    for method in methods:
        rows = results.get((scene_name, method), [])
        ref = _reference(references, law_references, scene_name, method)
        runs = sorted(((tol, run["cpu"], _errors(run, ref)[0] if run["status"] == 0
                        else np.inf) for tol, run in rows
                       if run is not None and "error" not in run), reverse=True)
        for level in EQUAL_ERRORS:
            ok = [(cpu, tol) for k, (tol, cpu, _) in enumerate(runs)
                  if all(err <= level for _, _, err in runs[k:])]
            if ok:
                out[(method, level)] = min(ok)
    return out


def _grid_rows(tolerances, budget):
    """{(mu, mixture): [(tol, run or None)]}: the mu x mixture set, radau5, 1.2 s."""
    grid = {}
    for mu in GRID_MU:
        for mixture in GRID_MIXTURE:
            scene = ballc.Scene(friction_coefficient=mu, mixture=mixture)
            rows = [(tol, _bounded(_run_ballc, ("seed", "radau5", tol, None, scene,
                                                GRID_T_END, False), budget))
                    for tol in tolerances]
            grid[(mu, mixture)] = rows
            print(f"  mu {mu:g}, mixture {mixture:g}: " + ", ".join(
                f"{tol:.0e} " + ("> budget" if run is None else run.get("error") or
                                 f"{run['nfev']}/{run['status']}") for tol, run in rows),
                  flush=True)
    return grid


def _plot(results, references, law_references, budget, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    fig, axes = plt.subplots(1, len(SCENES), figsize=(5.6 * len(SCENES), 6.4))
    styles = {"radau5": ("o-", "tab:blue"), "dop853": ("D-", "tab:red"),
              "Radau": ("s--", "tab:orange"), "BDF": ("^--", "tab:green"),
              "LSODA": ("v--", "tab:purple"), "DOP853": ("d--", "tab:brown"),
              "seed pipeline": ("X:", "tab:gray")}
    labels = {"radau5": "radau5 (ballc, exact friction)",
              "dop853": "dop853 (ballc, compiled DOP853)",
              "DOP853": "DOP853 (scipy solve_ivp; dop853's original)"}
    law_styles = {law: (style, colour) for law, style, colour in
                  zip(LAWS, ("P-", "*-"), ("black", "tab:cyan"))}
    for ax, scene_name in zip(axes, SCENES):
        for (name, method), rows in results.items():
            if name != scene_name:
                continue
            ref = _reference(references, law_references, scene_name, method)
            pts = [(run["cpu"], max(_errors(run, ref)[0], 1e-16), tol) for tol, run in rows
                   if run is not None and "error" not in run]
            if not pts:
                continue
            cpu, err, tols = zip(*pts)
            if method in LAWS:
                style, colour = law_styles[method]
                slow = [f"{tol:.0e}" for tol, run in rows if run is None]
                failed = [f"{tol:.0e}" for tol, run in rows
                          if run is not None and "error" not in run and run["status"] != 0]
                label = method + "".join(
                    f"\n  {what} at {', '.join(tols)}" for what, tols in
                    ((f"> {budget:g} s CPU budget", slow), ("status != 0", failed)) if tols)
                ax.loglog(cpu, err, style, color=colour, label=label, ms=5, lw=1.2)
            else:
                style, colour = styles[method]
                ax.loglog(cpu, err, style, color=colour, label=labels.get(method, method),
                          ms=5 if method in COMPILED else 4,
                          lw=1.6 if method in COMPILED else 1.0)
            if method in ("radau5", "dop853", "seed pipeline") or method in LAWS:
                below = method == "dop853"   # its labels under the points, radau5's above
                for c, e, t in zip(cpu, err, tols):
                    ax.annotate(f"{t:.0e}", (c, e), fontsize=6, xytext=(3, -9 if below else 3),
                                textcoords="offset points",
                                color="tab:red" if below else "black")
        ax.set_title(scene_name)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("CPU time (s)")
        ax.set_ylabel("final-state error (m, m/s)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    fig.suptitle(f"ballc work-precision, {T_END:g} s, rtol = atol (labels), "
                 "error vs radau5 at 1e-13 (same friction law); default friction: exact "
                 "(stick/slip events)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def _write_markdown(results, references, law_references, grid, special, stiff, budget,
                    elapsed, args, tolerances, path):
    lines = ["# Work-precision", "",
             f"Generated by `python -m benchmarks.work_precision{' --quick' if args.quick else ''}`"
             f" ({elapsed:.0f} s wall, 2-core machine shared with other work: CPU times are "
             "`time.process_time()` per run, best of 2; a run under "
             f"{MIN_WINDOW:g} s is repeated within one timing window of at least "
             f"{MIN_WINDOW:g} s, since under the CPU budget (RLIMIT_CPU) the process clock "
             "advances in 4-ms ticks).  "
             "Scenes: 5 s each.", "",
             "Methods: ballc's two compiled integrators -- **radau5** (Radau IIA, order 5, "
             "implicit: scipy's Radau in C, the default) and **dop853** (Dormand & Prince's "
             "explicit pair of order 8: scipy's DOP853 step by step in C, in radau5's loop "
             "with the same events, stepping to events, re-arming and output; no Jacobian, "
             "no linear algebra) -- and scipy's Radau, BDF, LSODA (given the analytic "
             "Jacobian) and DOP853 through `solve_ivp` on the same compiled right-hand side "
             "(`ballc.simulate(..., method=...)`); scipy's DOP853 is the algorithm dop853 "
             "is a port of.  dop853 is explicit: on stiff scenes its steps are bounded by "
             "stability, not accuracy (see [When dop853 is the wrong choice]"
             "(#when-dop853-is-the-wrong-choice)).", "",
             "Friction: the default, exact Coulomb friction as stick/slip events "
             "(`friction_regularization=\"exact\"`).  On the seed and friction-only scenes "
             "radau5 also runs the seed's literal law `\"max\"` (v_s = 1e-10 m/s: its "
             "viscous core makes loose tolerances crawl, the cliff the events remove) and "
             "`\"smooth\"` with v_s = 1e-4 m/s; their errors are against their own radau5 "
             "1e-13 reference (integration error only), and the distance of each law's "
             "reference from the exact one is given (the model difference).", "",
             "Error: final-state error = max |difference| of the centre position (m) and "
             "velocity (m/s) at t = 5 s; contact error = max |difference| of contact start/end "
             "times (s), \"count\" when the number of contacts differs.  Reference: radau5 at "
             "rtol = atol = 1e-13.  `> budget`: the run exceeded "
             f"{budget:g} s of CPU and was stopped.", "", "![work-precision](work_precision.png)", "",
             PEERS_NOTE, ""]
    lines += _equal_error_lines(results, references, law_references)
    lines += _stiff_lines(stiff, budget)
    for scene_name in SCENES:
        ref, (ref_final, ref_contact) = references[scene_name]
        lines += [f"## {scene_name}", "", f"{SCENE_NOTES[scene_name]}.  Reference "
                  f"uncertainty (radau5 1e-12 vs 1e-13): final {ref_final:.1e}, contacts "
                  f"{_fmt(ref_contact, 1)}.", ""]
        for (name, law), (_, (u_final, _), (d_final, d_contact)) in law_references.items():
            if name == scene_name:
                lines += [f"- {law}: own reference uncertainty {u_final:.1e}; its reference "
                          f"vs exact's: final {d_final:.1e}, contacts {_fmt(d_contact, 1)}."]
        lines += ["",
                  "| method | rtol = atol | CPU s | RHS calls | final error | contact error "
                  "| CPU vs radau5 |", "|---|---|---|---|---|---|---|"]
        r5 = {tol: run for tol, run in results[(scene_name, "radau5")]}
        for (name, method), rows in results.items():
            if name != scene_name:
                continue
            for tol, run in rows:
                if run is None:
                    lines.append(f"| {method} | {tol:.0e} | > budget | | | | |")
                    continue
                if "error" in run:
                    lines.append(f"| {method} | {tol:.0e} | {run['error']} | | | | |")
                    continue
                final, contact = _errors(run, _reference(references, law_references,
                                                         scene_name, method))
                base = r5.get(tol)
                ratio = (f"{run['cpu'] / base['cpu']:.2g}x" if base is not None
                         and "error" not in base else "")
                note = "" if run["status"] == 0 else f" (status {run['status']})"
                if run.get("inaccurate"):
                    note += " (energy balance off: flagged not accurate)"
                lines.append(f"| {method} | {tol:.0e} | {run['cpu']:.3g}{note} | "
                             f"{run['nfev']} | {final:.1e} | {_fmt(contact, 1)} | {ratio} |")
        lines.append("")
    lines += [f"## mu x mixture, {GRID_T_END:g} s of the seed throw, radau5", "",
              "RHS calls per run at rtol = atol; every cell is status 0 unless marked "
              "(`s1`: passed through a plane, `s-1`: integrator failed, `> budget`: "
              f"stopped after {budget:g} s CPU).  Default (exact) friction.", "",
              "| mu | mixture | " + " | ".join(f"{tol:.0e}" for tol in tolerances) + " |",
              "|---|---|" + "---|" * len(tolerances)]
    for (mu, mixture), rows in grid.items():
        cells = []
        for tol, run in rows:
            if run is None:
                cells.append("> budget")
            elif "error" in run:
                cells.append(run["error"])
            else:
                cells.append(f"{run['nfev']}" + ("" if run["status"] == 0
                                                 else f" s{run['status']}")
                             + (" (balance off)" if run.get("inaccurate") else ""))
        lines.append(f"| {mu:g} | {mixture:g} | " + " | ".join(cells) + " |")
    lines.append("")
    lines += ["## Skipping what a scene does not need", "",
              "radau5 (rtol = atol = 1e-12) on the same trajectory with kernels forced on and "
              "off (observer_mass = 0 zeroes the observer's terms; in free flight the contact "
              "terms are zero): same result and RHS count, so the ratio is the cost of the "
              "kernels alone.  µs of integration (everything radau5 does) per RHS call.", "",
              "| kernels | µs per RHS call, on | off | CPU ratio on/off | same result |",
              "|---|---|---|---|---|"]
    for label, on, off, ratio, same in special:
        lines.append(f"| {label} | {on:.3f} | {off:.3f} | {ratio:.2f} | {same} |")
    lines.append("")
    path.write_text("\n".join(lines))


if __name__ == "__main__":
    main()
