"""Does the seed throw come back?  A mixture x mu map, as a PNG heat map.

    python examples/sweep_mixture_mu.py [--out DIR] [--scheduler tcp://host:8786]

Runs 7 x 6 = 42 scenes of 1.2 s (enough for the floor-table-floor sequence) on all
local cores, or on a Dask cluster with --scheduler, and writes DIR/sweep.csv and
DIR/came_back.png (default DIR: ballc-output/sweep_mixture_mu/).  About half a minute
on 2 cores.  The same sweep from the command line: ``ballc sweep examples/sweep.toml``.
"""
import argparse
import time
from pathlib import Path

import numpy as np

import ballc
from ballc.plot import plot_sweep_map


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("ballc-output/sweep_mixture_mu"),
                        help="output folder (default: %(default)s)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    parameters = {"mixture": list(np.round(np.linspace(0.0, 0.6, 7), 3)),
                  "friction_coefficient": [0.0, 0.05, 0.1, 0.2, 0.4, 0.8]}
    started = time.perf_counter()
    table = ballc.sweep(ballc.Scene(), parameters, t_end=1.2, client=args.scheduler)
    print(f"{len(table)} runs in {time.perf_counter() - started:.1f} s")
    print(table.drop(columns="message").to_string(index=False))
    table.to_csv(args.out / "sweep.csv", index=False)

    import matplotlib
    matplotlib.use("Agg")
    fig, ax = plot_sweep_map(table, x="friction_coefficient", y="mixture")
    ax.set_title("Seed throw (c_tau 0.9): does it come back after floor, ceiling, floor?\n"
                 "(cell text: energy lost in 1.2 s)")
    fig.savefig(args.out / "came_back.png", dpi=100)
    print("wrote", args.out / "sweep.csv", args.out / "came_back.png")


if __name__ == "__main__":
    main()
