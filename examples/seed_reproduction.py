"""Reproduce the seed's run and its figures.

    python examples/seed_reproduction.py [--out DIR]

The seed is the sympy/PyDy-style gallery example "ball bouncing between two planes" by
Peter Stahlecker.  It reports 9 contacts (floor and ceiling alternating, the first at
t = 0.156 s), energy 386.59 J -> 109.70 J and the x-velocity reversing at the first
ceiling contact (-2.63 -> +2.20 m/s); this prints ballc's numbers next to those and
writes the coordinate, energy, contact and observer figures, the 3D animation and the
result into DIR (default: ballc-output/seed_reproduction/).
"""
import argparse
import time
from pathlib import Path

import ballc
from ballc.cli import write_outputs
from ballc.outcome import format_summary


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("ballc-output/seed_reproduction"),
                        help="output folder (default: %(default)s)")
    out = parser.parse_args(argv).out

    scene = ballc.Scene.from_toml(Path(__file__).with_name("seed.toml"))
    started = time.perf_counter()
    result = ballc.simulate(scene, 5.0)
    print(f"simulated 5 s in {time.perf_counter() - started:.2f} s")
    print(format_summary(result))
    print(result.contact_table())
    total = result.energy["total"]
    print("\nseed: 9 contacts, 386.59 J -> 109.70 J, vx -2.63 -> +2.20 at the first "
          "ceiling contact")
    ceiling = next(c for c in result.contacts if c.plane == "ceiling")
    print(f"ballc: {len(result.contacts)} contacts, {total[0]:.2f} J -> {total[-1]:.2f} J, "
          f"vx {ceiling.velocity_before[0]:+.2f} -> {ceiling.velocity_after[0]:+.2f}")
    written = write_outputs(result, out, animate=True, frames=100)
    result.save(out / "seed.npz")
    print("wrote", ", ".join(map(str, written + [out / "seed.npz"])))


if __name__ == "__main__":
    main()
