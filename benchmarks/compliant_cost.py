"""CPU at equal error of two builds' compliant tangential laws (radau5 and dop853).

    python -m benchmarks.compliant_cost BEFORE_SRC AFTER_SRC [--rounds 7] [--repeat 3]
                                        [--max-nfev 3000000] [--no-write]

BEFORE_SRC and AFTER_SRC are ``src`` directories of two checkouts with their extension
built in place (``python setup.py build_ext --inplace``), as for
``benchmarks.compare_builds``: e.g. a clone of 97b7ab3 (the old secant compliant law) and
this tree (the passive compliant law).  The scenes are those of
``benchmarks.compliant_precision`` (the seed throw, 5 s, ``tangential_model="compliant"``
with the seed's mu = 0.1 and Mindlin's stiffness ratio, and with stiffness ratio 2/7,
mu = 1), built from the same keyword arguments in both builds.  Each round starts one
child process per build, in alternating order; each child runs every scene with
``method="radau5"`` and ``method="dop853"`` at rtol = atol = 1e-4 .. 1e-10 (one per
decade), CPU by ``time.process_time`` around ``ballc.simulate``, best of ``--repeat``
inside the child; the figure kept per build is the best over rounds.

Error: max |difference| of the final centre position (m) and velocity (m/s) at 5 s
against the SAME build's radau5 at rtol = atol = 1e-12 (each law against its own
converged answer: the two laws differ, so a cross-build error means nothing).  The
reference's own error is estimated as its distance to radau5 at 1e-13 (printed).

CPU at equal error: per build, scene and method, log CPU is interpolated linearly in
log error along the runs in tolerance order (loose to tight; status != 0 runs, and
status-0 runs with another number of contacts than the reference -- a wrong answer --
left out), taking the first crossing of the target error; the table gives new/old
(AFTER over BEFORE) at every decade of error both builds reach, and the same for RHS
calls.  Prints the tables and writes
them to docs/compliant_cost.md (AFTER's docs directory is this tree's).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path

T_END = 5.0
TOLERANCES = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
METHODS = ("radau5", "dop853")
REFERENCE_TOL, CHECK_TOL = 1e-12, 1e-13
# benchmarks.compliant_precision.SCENES, as keyword arguments (both builds build them)
SCENES = {
    "compliant, seed (mu 0.1, Mindlin ratio)": dict(tangential_model="compliant"),
    "compliant, ratio 2/7, mu 1": dict(tangential_model="compliant",
                                       tangential_stiffness_ratio=2 / 7,
                                       friction_coefficient=1.0),
}
TARGETS = tuple(10.0 ** -k for k in range(2, 11))
DOCS = Path(__file__).resolve().parent.parent / "docs"

CHILD = r"""
import json, sys, time
import numpy as np
import ballc
spec = json.loads(sys.argv[1])

def final(result):
    return np.concatenate([result.position[:, -1], result.velocity[:, -1]]).tolist()

out = {"__file__": ballc.__file__, "runs": []}
if spec["reference"]:
    for name, kwargs in spec["scenes"].items():
        scene = ballc.Scene(**kwargs)
        for tol in spec["reference"]:
            result = ballc.simulate(scene, spec["t_end"], method="radau5", rtol=tol, atol=tol)
            out["runs"].append(dict(scene=name, tol=tol, status=int(result.status),
                                    nfev=int(result.nfev), contacts=len(result.contacts),
                                    final=final(result)))
else:
    for name, kwargs in spec["scenes"].items():
        scene = ballc.Scene(**kwargs)
        for method in spec["methods"]:
            for tol in spec["tols"]:
                best = None
                for _ in range(spec["repeat"]):
                    started = time.process_time()
                    result = ballc.simulate(scene, spec["t_end"], method=method, rtol=tol,
                                            atol=tol, max_nfev=spec["max_nfev"])
                    cpu = time.process_time() - started
                    if best is None or cpu < best["cpu"]:
                        best = dict(scene=name, method=method, tol=tol, cpu=cpu,
                                    status=int(result.status), nfev=int(result.nfev),
                                    njev=int(result.njev), nlu=int(result.nlu),
                                    contacts=len(result.contacts),
                                    message=str(result.message), final=final(result))
                    if result.status != 0:
                        break
                out["runs"].append(best)
print(json.dumps(out))
"""


def run_child(src, spec):
    env = dict(os.environ, PYTHONPATH=str(Path(src).resolve()))
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(spec)], env=env,
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def distance(a, b):
    return max(abs(x - y) for x, y in zip(a, b))


def cost_at(points, target):
    """log-log interpolated (CPU, RHS calls) at which the runs (tolerance order) first
    reach ``target``.

    ``points``: (error, cpu, nfev) of the runs kept, loose to tight.  None when no run's
    error is at or below ``target``, or when the loosest run is already below it (the
    curve does not reach that far left)."""
    if not points or points[0][0] < target:
        return None
    for (e0, *c0), (e1, *c1) in zip(points, points[1:] + [(None, None, None)]):
        if e0 == target:
            return tuple(c0)
        if e1 is not None and e0 > target > e1:
            s = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return tuple(math.exp(math.log(a) + s * (math.log(b) - math.log(a)))
                         for a, b in zip(c0, c1))
    return None


def machine_state():
    load = os.getloadavg()
    return f"{os.cpu_count()} cores, load average {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--max-nfev", type=int, default=3_000_000)
    parser.add_argument("--no-write", action="store_true", help="print only")
    args = parser.parse_args(argv)
    builds = {"before": args.before, "after": args.after}
    state_start = machine_state()
    print("machine at start:", state_start, flush=True)

    refs, paths = {}, {}
    for name, src in builds.items():
        out = run_child(src, dict(scenes=SCENES, t_end=T_END,
                                  reference=[REFERENCE_TOL, CHECK_TOL]))
        paths[name] = out["__file__"]
        for run in out["runs"]:
            refs.setdefault(name, {}).setdefault(run["scene"], {})[run["tol"]] = run
    spec = dict(scenes=SCENES, t_end=T_END, reference=None, methods=list(METHODS),
                tols=list(TOLERANCES), repeat=args.repeat, max_nfev=args.max_nfev)
    best = {name: {} for name in builds}
    for round_ in range(args.rounds):
        order = list(builds) if round_ % 2 == 0 else list(builds)[::-1]
        for name in order:
            out = run_child(builds[name], spec)
            for run in out["runs"]:
                key = (run["scene"], run["method"], run["tol"])
                kept = best[name].get(key)
                if kept is not None and (kept["nfev"], kept["status"]) != (run["nfev"],
                                                                          run["status"]):
                    print(f"  warning: {name} {key} not deterministic", flush=True)
                if kept is None or run["cpu"] < kept["cpu"]:
                    best[name][key] = run
        print(f"  round {round_ + 1}/{args.rounds} done ({machine_state()})", flush=True)
    state_end = machine_state()

    lines = ["# CPU at equal error: the passive compliant law against the old one", "",
             "Generated by `python -m benchmarks.compliant_cost BEFORE_SRC AFTER_SRC` "
             f"(--rounds {args.rounds} --repeat {args.repeat}); machine at start: "
             f"{state_start}; at end: {state_end} (shared with other work; CPU is "
             "time.process_time, the best over rounds, so load adds less than to wall "
             "time but still some).", "",
             f"* before: `{paths['before']}`", f"* after: `{paths['after']}`", "",
             f"Scenes of `benchmarks.compliant_precision`, {T_END:g} s, rtol = atol.  CPU: "
             f"best of {args.repeat} inside each child x {args.rounds} rounds of alternating "
             "child processes.  Error: max |final centre position (m), velocity (m/s) - the "
             f"same build's radau5 at {REFERENCE_TOL:.0e}|.  Runs with status != 0, or with "
             "another number of contacts than the reference (error in parentheses), are "
             f"shown and left out of the interpolation; runs stop after {args.max_nfev} RHS calls.",
             ""]

    lines += ["## References (radau5, each build against itself)", "",
              "| scene | build | status 1e-12 | RHS calls 1e-12 | contacts | "
              "|1e-12 - 1e-13| | |before - after| at 1e-12 |", "|---|---|---|---|---|---|---|"]
    for scene in SCENES:
        cross = distance(refs["before"][scene][REFERENCE_TOL]["final"],
                         refs["after"][scene][REFERENCE_TOL]["final"])
        for name in builds:
            r, c = refs[name][scene][REFERENCE_TOL], refs[name][scene][CHECK_TOL]
            lines.append(f"| {scene} | {name} | {r['status']} | {r['nfev']} | "
                         f"{r['contacts']} | {distance(r['final'], c['final']):.1e} | "
                         f"{cross:.1e} |")
    lines.append("")

    curves = {}
    notes = []
    for scene in SCENES:
        lines += [f"## {scene}", "",
                  "| method | rtol = atol | build | status | CPU ms | RHS calls | LU | "
                  "contacts | error |", "|---|---|---|---|---|---|---|---|---|"]
        for method in METHODS:
            for name in builds:
                ref = refs[name][scene][REFERENCE_TOL]["final"]
                points, previous = [], None
                for tol in TOLERANCES:
                    run = best[name][(scene, method, tol)]
                    reference = refs[name][scene][REFERENCE_TOL]
                    error = distance(run["final"], ref) if run["status"] == 0 else None
                    if error is not None and run["contacts"] != reference["contacts"]:
                        notes.append(f"{scene}, {method}, {name} at {tol:.0e}: status 0 "
                                     f"but {run['contacts']} contacts (reference "
                                     f"{reference['contacts']}), error {error:.1e}: a wrong "
                                     "answer, left out of the interpolation")
                        error = None
                    elif error is not None:
                        if previous is not None and error > previous:
                            notes.append(f"{scene}, {method}, {name}: error rises from "
                                         f"{previous:.1e} to {error:.1e} going to {tol:.0e}")
                        points.append((error, run["cpu"], run["nfev"]))
                        previous = error
                    elif run["status"] != 0:
                        notes.append(f"{scene}, {method}, {name} at {tol:.0e}: status "
                                     f"{run['status']}: {run['message']}")
                curves[(scene, method, name)] = points
            for tol in TOLERANCES:
                for name in builds:
                    run = best[name][(scene, method, tol)]
                    error = distance(run["final"], refs[name][scene][REFERENCE_TOL]["final"])
                    lines.append(f"| {method} | {tol:.0e} | {name} | {run['status']} | "
                                 f"{1e3 * run['cpu']:.2f} | {run['nfev']} | {run['nlu']} | "
                                 f"{run['contacts']} | "
                                 + (f"{error:.1e}" if run["status"] == 0 and run["contacts"]
                                    == refs[name][scene][REFERENCE_TOL]["contacts"]
                                    else f"({error:.1e}, left out)")
                                 + " |")
        lines.append("")

    lines += ["## CPU at equal error (log-log interpolation), new/old = after/before", "",
              "| scene | method | error | before CPU ms | after CPU ms | CPU after/before | "
              "RHS calls after/before |", "|---|---|---|---|---|---|---|"]
    summary = []
    for scene in SCENES:
        for method in METHODS:
            for target in TARGETS:
                old = cost_at(curves[(scene, method, "before")], target)
                new = cost_at(curves[(scene, method, "after")], target)
                if old is None or new is None:
                    continue
                summary.append((scene, method, target, new[0] / old[0]))
                lines.append(f"| {scene} | {method} | {target:.0e} | {1e3 * old[0]:.2f} | "
                             f"{1e3 * new[0]:.2f} | {new[0] / old[0]:.2f} | "
                             f"{new[1] / old[1]:.2f} |")
    lines.append("")
    if summary:
        worst = max(summary, key=lambda row: row[3])
        within = sum(ratio <= 1.2 for *_, ratio in summary)
        lines += [f"Ratios <= 1.2: {within} of {len(summary)}; largest {worst[3]:.2f} "
                  f"({worst[0]}, {worst[1]}, error {worst[2]:.0e}).", ""]
    lines += ["## Notes", ""] + ([f"* {note}" for note in notes] or ["* none"]) + [""]
    print("\n" + "\n".join(lines))
    if not args.no_write:
        DOCS.mkdir(exist_ok=True)
        (DOCS / "compliant_cost.md").write_text("\n".join(lines))
        print("wrote", DOCS / "compliant_cost.md")


if __name__ == "__main__":
    main()
