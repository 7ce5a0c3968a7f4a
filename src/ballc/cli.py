"""Console entry point: ``ballc demo`` runs the seed scene and prints its contacts."""
from __future__ import annotations

import argparse
import sys
import time

from .scene import Scene
from .simulate import simulate


def _demo(args) -> int:
    scene = Scene()
    started = time.process_time()
    result = simulate(scene, args.t_end)
    cpu = time.process_time() - started
    energy = result.energy["total"]
    print(f"ballc demo: the seed scene (mixture {scene.mixture}, mu {scene.friction_coefficient},"
          f" c_tau {scene.c_tau}) for {args.t_end:g} s")
    print(f"{result.message}  [{cpu:.2f} s CPU, {result.nfev} RHS calls]")
    print()
    print(result.contact_table())
    print()
    print(f"energy: {energy[0]:.2f} J -> {energy[-1]:.2f} J")
    reversed_ = [c for c in result.contacts if c.velocity_before[0] * c.velocity_after[0] < 0]
    if reversed_:
        c = reversed_[0]
        print(f"the x-velocity first reverses at the {c.plane} contact at t = {c.t_start:.3f} s"
              f" ({c.velocity_before[0]:+.2f} -> {c.velocity_after[0]:+.2f} m/s)")
    return 0 if result.success else 1


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="ballc", description="ballc: a ball between two planes")
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser("demo", help="simulate the seed scene and print its contact table")
    demo.add_argument("--t-end", type=float, default=5.0, help="simulated time in s (default 5)")
    demo.set_defaults(run=_demo)
    args = parser.parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
