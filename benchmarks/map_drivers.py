"""The 100 x 100 comeback map with the segment loop in C and in Python, in one run.

    python -m benchmarks.map_drivers [--n 100] [--rounds 2] [--methods radau5 dop853]

The seed throw (``ballc.Scene()``, 1.2 s) over mixture x friction coefficient in
[0, 1] x [0, 1], ``ballc.sweep(..., workers=2)``, rtol = atol = 1e-3 (issue 22's map).
Each round runs the map with the Python driver (BALLC_PYTHON_DRIVER=1, inherited by the
sweep's worker processes) and with the default (the C loop where the run is in its
subset: every cell of this map), alternating, and reports the wall time
(time.perf_counter) of each, and how many cells came back (both drivers must agree).
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

import ballc

T_END = 1.2


def one_map(n, method):
    grid = {"mixture": np.linspace(0.0, 1.0, n),
            "friction_coefficient": np.linspace(0.0, 1.0, n)}
    started = time.perf_counter()
    rows = ballc.sweep(ballc.Scene(), grid, T_END, workers=2, method=method, rtol=1e-3,
                       atol=1e-3)
    wall = time.perf_counter() - started
    came = rows["came_back"].astype(str).tolist()   # True, False or <NA>
    return wall, came.count("True"), came


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--methods", nargs="+", default=["radau5", "dop853"])
    args = parser.parse_args(argv)
    print(f"| method | driver | wall (s), each round | cells that came back |")
    print("|---|---|---|---|")
    for method in args.methods:
        walls = {"python": [], "c": []}
        answers = {}
        for _ in range(args.rounds):
            for driver in ("python", "c"):
                if driver == "python":
                    os.environ["BALLC_PYTHON_DRIVER"] = "1"
                else:
                    os.environ.pop("BALLC_PYTHON_DRIVER", None)
                wall, count, came = one_map(args.n, method)
                walls[driver].append(wall)
                answers[driver] = (count, came)
        os.environ.pop("BALLC_PYTHON_DRIVER", None)
        for driver in ("python", "c"):
            times = " / ".join(f"{w:.2f}" for w in walls[driver])
            print(f"| {method} | {driver} | {times} | {answers[driver][0]} |")
        if answers["python"][1] != answers["c"][1]:
            raise SystemExit(f"{method}: the two drivers' maps differ")


if __name__ == "__main__":
    main()
