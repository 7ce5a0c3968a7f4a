"""Two builds of ballc on the same runs, interleaved: CPU per simulate and its split.

    python -m benchmarks.compare_builds BEFORE_SRC AFTER_SRC [--tol 1e-3 1e-8 1e-10 1e-12]
                                        [--rounds 5] [--t-end 5]

BEFORE_SRC and AFTER_SRC are ``src`` directories of two checkouts with their extension
built in place (``python setup.py build_ext --inplace``), e.g. a clone of an older
commit and this tree.  Each round starts one child process per build, in alternating
order, and each child times ``ballc.simulate(ballc.Scene(), t_end, rtol=tol, atol=tol)``
(``time.process_time``, best of 3 inside the child) and splits that time into

* ``solver``: inside ``ballc._core.drive``, the segment loop in C with the integrators
  and its bridge (a build without the C loop: inside ``ballc._radau5.solve_system``),
* ``post``: ``outcome.summarize_contact_forces`` and ``outcome.balance_warning``,
* ``driver``: the rest (Python around the C loop; without it, the segment loop in Python).

Accepted steps come from the C loop's segment log (``result.segments``; a build with the
C loop but no log prints -1: wrapping solve_system there would make it take the Python
driver).

The printed figure per build is the best over rounds (a loaded machine only adds time),
so two builds are compared on the same machine state as far as interleaving allows.
Also printed: RHS calls, accepted steps and the final state's error against the AFTER
build at 1e-13 (so a speed-up that changes results shows up).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import importlib, json, sys, time
import numpy as np
import ballc
from ballc import _radau5, outcome
driver = importlib.import_module("ballc.simulate")
t_end, tols = float(sys.argv[1]), [float(x) for x in sys.argv[2].split(",")]
acc = {"solver": 0.0, "post": 0.0, "nstep": 0}

def timed(function, key):
    def wrapper(*args, **kwargs):
        started = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            acc[key] += time.process_time() - started
    return wrapper

from ballc import _core
if hasattr(_core, "drive"):   # the C loop: its one call
    _core.drive = timed(_core.drive, "solver")
else:
    original = _radau5.solve_system
    def solve_system(*args, **kwargs):
        started = time.process_time()
        sol = original(*args, **kwargs)
        acc["solver"] += time.process_time() - started
        acc["nstep"] += sol.nstep
        return sol
    _radau5.solve_system = solve_system
outcome.summarize_contact_forces = timed(outcome.summarize_contact_forces, "post")
outcome.balance_warning = timed(outcome.balance_warning, "post")
out = {"__file__": ballc.__file__}
for tol in tols:
    best = None
    for _ in range(3):
        acc.update(solver=0.0, post=0.0, nstep=0)
        started = time.process_time()
        result = ballc.simulate(ballc.Scene(), t_end, rtol=tol, atol=tol)
        total = time.process_time() - started
        log = getattr(result, "segments", None)
        if log is not None:
            acc["nstep"] = int(log["nstep"].sum())
        elif hasattr(_core, "drive"):
            acc["nstep"] = -1
        if best is None or total < best["total"]:
            best = dict(total=total, solver=acc["solver"], post=acc["post"],
                        nstep=acc["nstep"], nfev=int(result.nfev),
                        final=np.concatenate([result.position[:, -1],
                                              result.velocity[:, -1]]).tolist())
    out[repr(tol)] = best
print(json.dumps(out))
"""


def run_child(src, t_end, tols):
    env = dict(os.environ, PYTHONPATH=str(Path(src).resolve()))
    done = subprocess.run([sys.executable, "-c", CHILD, repr(t_end), ",".join(map(repr, tols))],
                          env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def reference(src, t_end):
    env = dict(os.environ, PYTHONPATH=str(Path(src).resolve()))
    code = ("import json, numpy as np, ballc; r = ballc.simulate(ballc.Scene(), %r, "
            "rtol=1e-13, atol=1e-13); print(json.dumps(np.concatenate([r.position[:, -1], "
            "r.velocity[:, -1]]).tolist()))" % t_end)
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--tol", type=float, nargs="+", default=[1e-3, 1e-8, 1e-10, 1e-12])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=5.0)
    args = parser.parse_args(argv)
    builds = {"before": args.before, "after": args.after}
    best = {name: {} for name in builds}
    paths = {}
    for round_ in range(args.rounds):
        order = list(builds) if round_ % 2 == 0 else list(builds)[::-1]
        for name in order:
            figures_by_tol = run_child(builds[name], args.t_end, args.tol)
            paths[name] = figures_by_tol.pop("__file__")
            for tol, figures in figures_by_tol.items():
                kept = best[name].get(tol)
                if kept is None or figures["total"] < kept["total"]:
                    best[name][tol] = figures
    ref = reference(args.after, args.t_end)
    for name in builds:
        print(f"{name}: {paths[name]}")
    print(f"seed scene, {args.t_end:g} s; CPU ms per simulate, best of {args.rounds} rounds x 3 "
          "(builds interleaved); error: final centre position/velocity against AFTER at 1e-13")
    print(f"{'tol':>7s} {'build':>7s} {'total':>8s} {'solver':>8s} {'driver':>8s} {'post':>7s} "
          f"{'steps':>6s} {'RHS':>7s} {'us/step':>8s} {'error':>9s} {'before/after':>12s}")
    for tol in map(repr, args.tol):
        for name in builds:
            f = best[name][tol]
            driver = f["total"] - f["solver"] - f["post"]
            error = max(abs(a - b) for a, b in zip(f["final"], ref))
            ratio = (best["before"][tol]["total"] / best["after"][tol]["total"]
                     if name == "after" else float("nan"))
            print(f"{float(tol):7.0e} {name:>7s} {1e3 * f['total']:8.2f} {1e3 * f['solver']:8.2f} "
                  f"{1e3 * driver:8.2f} {1e3 * f['post']:7.2f} {f['nstep']:6d} {f['nfev']:7d} "
                  f"{1e6 * f['solver'] / max(f['nstep'], 1):8.2f} {error:9.2e} "
                  + (f"{ratio:11.2f}x" if name == "after" else ""))


if __name__ == "__main__":
    main()
