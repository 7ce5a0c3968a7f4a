"""The seed's lambdify pipeline against ballc, in one process, same scene and tolerances.

    python -m benchmarks.seed_vs_ballc [--t-end 5] [--rtol 1e-12]

Prints CPU seconds (time.process_time around the integration only), RHS calls and
the CPU ratio; the seed's model build (sympy, lambdify) is not counted.
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
    parser.add_argument("--repeat", type=int, default=3, help="ballc repetitions (best taken)")
    args = parser.parse_args(argv)

    build_seed_model()   # build outside the timed region
    seed = run_seed_pipeline(args.t_end, rtol=args.rtol, atol=args.rtol)
    ballc_cpu = []
    for _ in range(args.repeat):
        started = time.process_time()
        ours = ballc.simulate(ballc.Scene(), args.t_end, rtol=args.rtol, atol=args.rtol)
        ballc_cpu.append(time.process_time() - started)
    best = min(ballc_cpu)

    final_seed = seed["y"][:, -1]
    final_ours = ours.y[:, -1]
    position_diff = np.abs(final_seed[3:6] - final_ours[4:7]).max()
    print(f"scene: seed defaults, {args.t_end:g} s, Radau, rtol = atol = {args.rtol:g}")
    print(f"{'pipeline':28s} {'CPU s':>9s} {'RHS calls':>10s} {'Jacobians':>10s} {'LU':>7s} {'contacts':>8s}")
    print(f"{'seed (lambdify + numpy)':28s} {seed['cpu_seconds']:9.3f} {seed['nfev']:10d} "
          f"{seed['njev']:10d} {seed['nlu']:7d} {len(seed['contacts']):8d}")
    print(f"{'ballc (compiled, scipy)':28s} {best:9.3f} {ours.nfev:10d} {ours.njev:10d} "
          f"{ours.nlu:7d} {len(ours.contacts):8d}")
    print(f"CPU ratio seed / ballc: {seed['cpu_seconds'] / best:.1f}x "
          f"(ballc best of {args.repeat}: {', '.join(f'{c:.3f}' for c in ballc_cpu)} s)")
    print(f"max |final position difference| between the two: {position_diff:.2e} m")


if __name__ == "__main__":
    main()
