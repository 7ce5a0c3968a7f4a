"""The seed's lambdify pipeline against ballc, in one process, same scene and tolerances.

    python -m benchmarks.seed_vs_ballc [--t-end 5] [--rtol 1e-12]

Prints CPU seconds (time.process_time around the integration only), RHS calls and
the CPU ratio; the seed's model build (sympy, lambdify) is not counted.

Then the comparison at equal error: against a converged reference (radau5 at 1e-13),
the seed's final-state error (centre position, m, and velocity, m/s) is measured, and
each of ballc's compiled integrators (radau5; dop853, the explicit order-8 method) runs
at rtol = atol = 1, 2 and 5 per decade from 1e-6 to 1e-12; per integrator, the cheapest
run whose final error is at most the seed's gives the CPU ratio at equal (or smaller)
error.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import ballc
from codegen.seed_reference import build_seed_model, run_seed_pipeline


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--t-end", type=float, default=5.0)
    parser.add_argument("--rtol", type=float, default=1e-12)
    parser.add_argument("--repeat", type=int, default=5, help="ballc repetitions (best taken)")
    args = parser.parse_args(argv)

    build_seed_model()   # build outside the timed region
    seed = run_seed_pipeline(args.t_end, rtol=args.rtol, atol=args.rtol)
    print(f"scene: seed defaults, {args.t_end:g} s, rtol = atol = {args.rtol:g}")
    print(f"{'pipeline':30s} {'CPU s':>9s} {'RHS calls':>10s} {'Jacobians':>10s} {'LU':>7s} "
          f"{'contacts':>8s} {'seed / this':>11s} {'final |dx| vs seed':>18s}")
    print(f"{'seed (lambdify, scipy Radau)':30s} {seed['cpu_seconds']:9.3f} {seed['nfev']:10d} "
          f"{seed['njev']:10d} {seed['nlu']:7d} {len(seed['contacts']):8d} {1:10.1f}x")
    for label, method in (("ballc, scipy Radau", "Radau"), ("ballc, radau5 (compiled)", "radau5"),
                          ("ballc, dop853 (compiled)", "dop853")):
        cpu = []
        for _ in range(args.repeat):
            started = time.process_time()
            ours = ballc.simulate(ballc.Scene(), args.t_end, method=method, rtol=args.rtol,
                                  atol=args.rtol)
            cpu.append(time.process_time() - started)
        best = min(cpu)
        difference = np.abs(seed["y"][3:6, -1] - ours.position[:, -1]).max()
        print(f"{label:30s} {best:9.3f} {ours.nfev:10d} {ours.njev:10d} {ours.nlu:7d} "
              f"{len(ours.contacts):8d} {seed['cpu_seconds'] / best:10.1f}x {difference:18.2e}")
    print(f"(ballc: best of {args.repeat}; the seed's model build is not timed)")
    equal_error(seed, args)


def _final(y):
    return np.concatenate([y[3:6, -1], y[9:12, -1]])


def equal_error(seed, args):
    """Per compiled integrator, its CPU in the cheapest run whose final error is <= the
    seed's; returns {method: (tol, ratio)}."""
    reference = ballc.simulate(ballc.Scene(), args.t_end, rtol=1e-13, atol=1e-13)
    ref = np.concatenate([reference.position[:, -1], reference.velocity[:, -1]])
    seed_error = np.abs(_final(seed["y"]) - ref).max()
    print(f"\nat equal error (reference: radau5 at 1e-13): the seed's final error "
          f"{seed_error:.2e} in {seed['cpu_seconds']:.3f} s")
    print(f"{'method':>8s} {'rtol = atol':>12s} {'CPU s':>9s} {'final error':>12s} "
          f"{'seed / this':>11s}")
    tolerances = [m * 10.0 ** -e for e in range(6, 13) for m in (5, 2, 1)]
    chosen = {}
    for method in ("radau5", "dop853"):
        for tol in tolerances:
            cpu = []
            for _ in range(args.repeat):
                started = time.process_time()
                ours = ballc.simulate(ballc.Scene(), args.t_end, method=method, rtol=tol,
                                      atol=tol)
                cpu.append(time.process_time() - started)
            error = np.abs(np.concatenate([ours.position[:, -1], ours.velocity[:, -1]])
                           - ref).max()
            ratio = seed["cpu_seconds"] / min(cpu)
            print(f"{method:>8s} {tol:12.0e} {min(cpu):9.4f} {error:12.2e} {ratio:10.0f}x")
            if error <= seed_error and (method not in chosen or ratio > chosen[method][1]):
                chosen[method] = (tol, ratio)
    for method, (tol, ratio) in chosen.items():
        print(f"equal or smaller error than the seed's: {method} at {tol:.0e}, "
              f"{ratio:.0f}x less CPU")
    return chosen


if __name__ == "__main__":
    main()
