"""CPU per run of one comeback-map cell with the C segment loop and with the Python one,
and the share of a C-driven run spent outside the integrator (docs/c_loop_plan.md, 3).

    python -m benchmarks.c_driver_cost [--profiled]

Scene(mixture=0.3, friction_coefficient=0.2), 1.2 s, rtol = atol = 1e-3, dop853 and
radau5: time.process_time, best of 5 rounds of 200 runs after 30 warm-up runs, both
drivers in the same process (BALLC_PYTHON_DRIVER selects the Python one).  With
--profiled, ballc is first built with -DRADAU5_PROFILE into a temporary directory
(benchmarks.profile_step.build_profiled) and the C run also reports the thread CPU time
inside radau5_solve (summed over segments) and inside ballc_drive (the whole C loop): the
rest of the run is the Python layer (validation, the bridge, post-processing).  The
profiled build's timers add a little per call, so take the plain numbers for the totals.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = r"""
import os, sys, time
import ballc
scene = ballc.Scene(mixture=0.3, friction_coefficient=0.2)
kw = dict(rtol=1e-3, atol=1e-3, progress=False)

def best(method, python, n=200, rounds=5):
    if python:
        os.environ["BALLC_PYTHON_DRIVER"] = "1"
    else:
        os.environ.pop("BALLC_PYTHON_DRIVER", None)
    try:
        for _ in range(30):
            ballc.simulate(scene, 1.2, method=method, **kw)
        found = None
        for _ in range(rounds):
            started = time.process_time()
            shares = [0.0, 0.0]
            for _ in range(n):
                r = ballc.simulate(scene, 1.2, method=method, **kw)
                counts = getattr(r, "_driver_counts", None)
                if counts and counts["profiled"]:
                    shares[0] += counts["integrator_ns"] * 1e-9
                    shares[1] += counts["drive_ns"] * 1e-9
            total = (time.process_time() - started) / n
            if found is None or total < found[0]:
                found = (total, shares[0] / n, shares[1] / n, r._driver)
        return found
    finally:
        os.environ.pop("BALLC_PYTHON_DRIVER", None)

for method in ("dop853", "radau5"):
    py = best(method, True)
    c = best(method, False)
    line = (f"{method}: Python driver {py[0] * 1e3:.3f} ms/run, C driver ({c[3]}) "
            f"{c[0] * 1e3:.3f} ms/run ({py[0] / c[0]:.2f}x)")
    if c[1]:
        line += (f"; inside radau5_solve {c[1] * 1e3:.3f} ms, C loop (ballc_drive) "
                 f"{c[2] * 1e3:.3f} ms, so outside the integrator "
                 f"{(c[0] - c[1]) / c[0]:.0%} of the run (C loop's own "
                 f"{(c[2] - c[1]) * 1e6:.0f} us, Python layer {(c[0] - c[2]) * 1e3:.3f} ms)")
    print(line, flush=True)
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profiled", action="store_true")
    args = parser.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ)
    if args.profiled:
        from benchmarks.profile_step import build_profiled
        where = Path(tempfile.mkdtemp(prefix="ballc_prof_"))
        lib = build_profiled(where, quiet=True)
        env["PYTHONPATH"] = str(lib)
    else:
        env["PYTHONPATH"] = str(root / "src")
    return subprocess.run([sys.executable, "-c", CHILD], env=env).returncode


if __name__ == "__main__":
    sys.exit(main())
