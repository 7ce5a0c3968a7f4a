"""radau5's linear algebra: CPU time and step counts of the seed scene, for one build.

    PYTHONPATH=<clone>/src python -m benchmarks.lu_vs_lapack [--repeat 5]

Times ``ballc.simulate(ballc.Scene(), 5.0, rtol=1e-10, atol=1e-10)`` in this process
(best of ``--repeat``, time.process_time around the call) and prints the counts
(nfev, njev, nlu, and nstep / nreject summed over the segments of the C loop's
segment log, ``result.segments``; a build without one: over the calls of
``_radau5.solve_system``, wrapped, which in such an older build made simulate take its
Python driver).  Run it once
against a build that factors radau5's Newton matrices with LAPACK (before
src/ballc/_lu.c) and once against a build that uses _lu.c, and compare: the script
itself does not care which build it imports, it prints the path.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import ballc
from ballc import _radau5


def _counting(solve_system, totals):
    """Wrap _radau5.solve_system to sum nstep / nreject over segments (an older build
    without the segment log, where the wrapper made simulate take its Python driver)."""
    def wrapped(*args, **kwargs):
        sol = solve_system(*args, **kwargs)
        totals["nstep"] += sol.nstep
        totals["nreject"] += sol.nreject
        return sol
    return wrapped


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=5.0)
    parser.add_argument("--tol", type=float, default=1e-10)
    args = parser.parse_args(argv)

    def run():
        return ballc.simulate(ballc.Scene(), args.t_end, rtol=args.tol, atol=args.tol)

    result = run()   # counts (and warm-up)
    log = getattr(result, "segments", None)
    if log is not None:
        totals = {"nstep": int(log["nstep"].sum()), "nreject": int(log["nreject"].sum())}
    else:
        totals = {"nstep": 0, "nreject": 0}
        original = _radau5.solve_system
        _radau5.solve_system = _counting(original, totals)
        try:
            run()
        finally:
            _radau5.solve_system = original
    cpu = []
    for _ in range(args.repeat):
        started = time.process_time()
        again = run()
        cpu.append(time.process_time() - started)
        assert np.array_equal(again.y, result.y), "not reproducible in-process"
    print(f"build: {_radau5.__file__}")
    print(f"scene: seed defaults, {args.t_end:g} s, rtol = atol = {args.tol:g}, "
          f"best of {args.repeat}")
    print(f"CPU s best {min(cpu):.4f}  median {np.median(cpu):.4f}  all "
          + " ".join(f"{c:.4f}" for c in cpu))
    print(f"nfev {result.nfev}  njev {result.njev}  nlu {result.nlu}  "
          f"nstep {totals['nstep']}  nreject {totals['nreject']}  contacts {len(result.contacts)}  "
          f"status {result.status}")
    print(f"final state {np.array2string(result.y[:, -1], precision=17, max_line_width=200)}")


if __name__ == "__main__":
    main()
