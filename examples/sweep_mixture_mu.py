"""
Does the seed throw come back? A mixture x mu map
=================================================

Runs the seed scene for every combination of 7 ``mixture`` values and 6 friction
coefficients ``mu`` (42 scenes of 1.2 s: enough for the floor-ceiling-floor sequence)
with :func:`ballc.sweep`, on all local cores or on a Dask cluster, and draws whether
the ball came back as a map (came back, did not, or undetermined: fewer than the three
contacts the criterion needs).  Under ten seconds on 2 cores.

Run it on its own::

    python examples/sweep_mixture_mu.py [--out DIR] [--scheduler tcp://host:8786] [--coarse]

It writes ``DIR/sweep.csv`` and ``DIR/came_back.png`` (default ``DIR``:
``ballc-output/sweep_mixture_mu/``).  ``--coarse`` runs a 4 x 3 grid instead.  The
same sweep from the command line: ``ballc sweep examples/sweep.toml``.
"""

# %%
# The grid
# --------
import argparse
import time
from pathlib import Path

import matplotlib

import ballc
from ballc.plot import plot_sweep_map

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="Does the seed throw come back? A mixture x mu "
                                 "map.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/sweep_mixture_mu"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--scheduler", default=None, help="Dask scheduler address")
parser.add_argument("--coarse", action="store_true", help="a 4 x 3 grid (quick)")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

if args.coarse:
    parameters = {"mixture": [0.0, 0.2, 0.4, 0.6], "friction_coefficient": [0.0, 0.1, 0.8]}
else:
    parameters = {"mixture": [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
                  "friction_coefficient": [0.0, 0.05, 0.1, 0.2, 0.4, 0.8]}

# %%
# Run the sweep
# -------------
# One row per run: the swept values, ``contacts``, ``came_back``, energies (J),
# ``status`` and ``message``.
started = time.perf_counter()
table = ballc.sweep(ballc.Scene(), parameters, t_end=1.2, client=args.scheduler)
print(f"{len(table)} runs in {time.perf_counter() - started:.1f} s")
print(table.drop(columns="message").to_string(index=False))
table.to_csv(args.out / "sweep.csv", index=False)

# %%
# The map
# -------
fig, ax = plot_sweep_map(table, x="friction_coefficient", y="mixture")
ax.set_title("Seed throw (c_tau 0.9): does it come back after floor, ceiling, floor?\n"
             "(cell text: energy lost in 1.2 s)")
fig.savefig(args.out / "came_back.png", dpi=100)
print("wrote", args.out / "sweep.csv", args.out / "came_back.png")
