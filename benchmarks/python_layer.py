"""The Python layer around the C loop: CPU per run against another build, in one run.

    python -m benchmarks.python_layer [--before SRC] [--after SRC] [--rounds 5]
                                      [--cases flight map ...] [--no-map]

For issue 29, item 4 (a thinner Python layer).  Each case is timed in a child process per
build (``PYTHONPATH`` = that build's ``src``, which the child checks it imported), the two
builds alternating round by round; each figure is the best of ``--rounds`` rounds of
``time.process_time`` per run (after warm-up runs), so both builds meet the same load.
BEFORE defaults to d33fe92 built in place at /work/base_d33 (the last main with two
drivers), AFTER to this tree.  Cases:

* ``flight``: ``simulate(Scene(), 1e-3)``, a free flight of 1 ms: the Python layer's own
  cost (validation, the one C call, the Result);
* ``map``: a 1.2-s map throw, ``Scene(mixture=0.3, friction_coefficient=0.2)``, dop853 at
  rtol = atol = 1e-3, and ``map radau5`` the same with radau5;
* ``billion``: ``simulate(Scene(), 1e9)`` (the seed's 35 contacts, its rolling, the orbit
  of its observer's wobble to 1e9 s), and ``31 s``: the same to t = 31 s only (its
  bouncing: what the integration of a run to 1e9 s cannot shorten);
* ``scipy``: the seed for 1.2 s at rtol = atol = 1e-6 with each of scipy's methods;
* ``sweep``: the 100 x 100 comeback map (``ballc.sweep(Scene(), {mixture, mu}, 1.2,
  workers=2)``, rtol = atol = 1e-3, radau5), wall time (time.perf_counter), and how many
  cells came back (``--no-map`` leaves it out).

Prints a markdown table: case, before, after, after / before.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BEFORE = Path("/work/base_d33/src")

CHILD = r"""
import json, sys, time, warnings
from pathlib import Path
src, case, n, rounds = Path(sys.argv[1]).resolve(), sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
sys.path.insert(0, str(src))
import numpy as np
import ballc
assert Path(ballc.__file__).resolve().parent == src / "ballc", (ballc.__file__, str(src))
warnings.simplefilter("ignore")
from ballc import Scene, simulate
seed, cell = Scene(), Scene(mixture=0.3, friction_coefficient=0.2)
SCIPY = ("Radau", "BDF", "LSODA", "DOP853", "RK45", "RK23")
RUNS = {
    "flight": lambda: simulate(seed, 1e-3),
    "map": lambda: simulate(cell, 1.2, method="dop853", rtol=1e-3, atol=1e-3),
    "map radau5": lambda: simulate(cell, 1.2, method="radau5", rtol=1e-3, atol=1e-3),
    "billion": lambda: simulate(seed, 1e9),
    "31 s": lambda: simulate(seed, 31.0),
    **{f"scipy {m}": (lambda m=m: simulate(seed, 1.2, method=m, rtol=1e-6, atol=1e-6))
       for m in SCIPY},
}


def sweep():
    grid = np.linspace(0.0, 1.0, 100)
    started = time.perf_counter()
    table = ballc.sweep(seed, {"mixture": grid, "friction_coefficient": grid}, 1.2,
                        workers=2, rtol=1e-3, atol=1e-3, progress=False)
    wall = time.perf_counter() - started
    return wall, int((table["came_back"] == True).sum())   # noqa: E712 (nullable)


if case == "sweep":
    best = min(sweep() for _ in range(rounds))
    print(json.dumps({"seconds": best[0], "came_back": best[1]}))
else:
    run = RUNS[case]
    for _ in range(max(1, n // 10)):
        run()
    best = float("inf")
    for _ in range(rounds):
        started = time.process_time()
        for _ in range(n):
            run()
        best = min(best, (time.process_time() - started) / n)
    print(json.dumps({"seconds": best}))
"""

#: case -> (runs per round, unit, scale)
CASES = {
    "flight": (2000, "ms", 1e3), "map": (300, "ms", 1e3), "map radau5": (300, "ms", 1e3),
    "billion": (3, "s", 1.0), "31 s": (3, "s", 1.0),
    **{f"scipy {m}": (2, "ms", 1e3) for m in ("Radau", "BDF", "LSODA", "DOP853", "RK45",
                                              "RK23")},
    "sweep": (1, "s wall", 1.0),
}


def measure(src: Path, case: str, rounds: int) -> dict:
    n = CASES[case][0]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BALLC_PYTHON_DRIVER")}
    out = subprocess.run([sys.executable, "-c", CHILD, str(src), case, str(n), str(rounds)],
                         check=True, env=env, cwd=ROOT, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", type=Path, default=BEFORE)
    parser.add_argument("--after", type=Path, default=ROOT / "src")
    parser.add_argument("--rounds", type=int, default=5,
                        help="rounds per child (best of them), and alternations of builds")
    parser.add_argument("--cases", nargs="+", default=None, choices=list(CASES))
    parser.add_argument("--no-map", action="store_true", help="leave out the 100 x 100 map")
    args = parser.parse_args(argv)
    cases = args.cases or [c for c in CASES if not (c == "sweep" and args.no_map)]
    print(f"before: {args.before}\nafter: {args.after}\nload average at the start: "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs\n", flush=True)
    print("| case | before | after | after / before |")
    print("|---|---|---|---|")
    for case in cases:
        _, unit, scale = CASES[case]
        best = {"before": None, "after": None}
        extra = {}
        # the builds alternate: rounds of the sweep are its own (one map each)
        alternations = args.rounds if case != "sweep" else 2
        inner = 3 if case != "sweep" else 1
        for _ in range(alternations):
            for name, src in (("before", args.before), ("after", args.after)):
                found = measure(src, case, inner)
                if best[name] is None or found["seconds"] < best[name]:
                    best[name] = found["seconds"]
                if "came_back" in found:
                    extra[name] = found["came_back"]
        line = (f"| {case} | {best['before'] * scale:.4g} {unit} | {best['after'] * scale:.4g} "
                f"{unit} | {best['after'] / best['before']:.2f} |")
        if extra:
            line += f" cells that came back: {extra.get('before')} / {extra.get('after')}"
        print(line, flush=True)


if __name__ == "__main__":
    main()
