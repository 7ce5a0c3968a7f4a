"""
Does it come back when the plates are tilted? Maps over tilt, opening and throw
===============================================================================

The IYPT 2015 problem asks for "the parameters influencing the motion, including the
orientation of the plates".  Here the seed's ball is thrown between its two plates
(the floor and the underside of the table, 10 m apart) at its speed of 26 m/s, down
and forward (towards -x) at an angle from the vertical -- the *throw* -- and whether
it comes back (its x-velocity after the first three contacts against the throw's,
``ballc.outcome.came_back``) is mapped over

* the plates' tilt, both together: the pair turned about the y axis through the
  start's foot (``planes.tilt``; positive: the plates rise in the throw's direction,
  -x, away from the thrower),
* the wedge's opening angle: the lower plate level, the upper one turned about the y
  axis through its own point (``planes.1.tilt``; positive: the gap widens in the
  throw's direction, negative: it narrows ahead of the ball),

each against the throw, for the seed's mixture law and for ballc's passive compliant
law (``tangential_model="compliant"``, Mindlin's stiffness, the seed's mu = 0.1).
Four maps of 9 x 7 runs of 2 s each, about two seconds on 2 cores.

Run it on its own::

    python examples/plates_orientation.py [--out DIR] [--coarse]

It writes ``DIR/plates_orientation.csv`` (every run) and ``DIR/plates_orientation.png``
(default ``DIR``: ``ballc-output/plates_orientation/``).  ``--coarse``: 5 x 4 grids.
"""

# %%
# The grids
# ---------
import argparse
import math
import time
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd

import ballc
from ballc.plot import plot_sweep_map

matplotlib.use("Agg")   # write files, never open a window
import matplotlib.pyplot as plt  # noqa: E402

parser = argparse.ArgumentParser(description="Does the ball come back when the plates are "
                                 "tilted? Maps over tilt, opening and throw.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/plates_orientation"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--coarse", action="store_true", help="5 x 4 grids (quick)")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

angles = [-20, -10, -5, 0, 5, 10, 20] if not args.coarse else [-20, 0, 20]
throws = [5, 10, 15, 20, 25, 30, 35, 40, 45] if not args.coarse else [5, 15, 30, 45]
speed = math.hypot(5.0, 5.0, 25.0)            # the seed's throw, 26 m/s
velocities = [(-speed * math.sin(math.radians(a)), 0.0, -speed * math.cos(math.radians(a)))
              for a in throws]
laws = {"the seed's mixture law": {},
        "the passive compliant law": {"tangential_model": "compliant"}}
arrangements = {"both plates tilted": ("planes.tilt", "tilt of both plates (deg)"),
                "a wedge": ("planes.1.tilt", "the wedge's opening (deg)")}

# %%
# Run the sweeps
# --------------
# One sweep per law and arrangement; each row gets the throw's angle and the plates'
# angle in degrees for the maps.
started = time.perf_counter()
tables = []
for law, fields in laws.items():
    base = ballc.Scene(**fields)
    for arrangement, (parameter, _) in arrangements.items():
        table = ballc.sweep(base, {parameter: [math.radians(a) for a in angles],
                                   "velocity": velocities}, t_end=2.0, rtol=1e-6, atol=1e-6)
        table["law"], table["arrangement"] = law, arrangement
        table["throw (deg)"] = [round(math.degrees(math.atan2(-v[0], -v[2])))
                                for v in table["velocity"]]
        table["plates (deg)"] = [round(math.degrees(a)) for a in table[parameter]]
        tables.append(table.drop(columns=[parameter]))
runs = pd.concat(tables, ignore_index=True)
print(f"{len(runs)} runs in {time.perf_counter() - started:.1f} s; came back in "
      f"{int((runs['came_back'] == True).sum())}")   # noqa: E712 (pandas' nullable bool)
runs.drop(columns=["message"]).to_csv(args.out / "plates_orientation.csv", index=False)

# %%
# The maps
# --------
# Green: came back; red: did not; yellow: undetermined (fewer than three contacts in
# 2 s).  Each cell's text: the energy lost.
fig, axes = plt.subplots(2, 2, figsize=(13, 10), constrained_layout=True)
for row, law in zip(axes, laws):
    for ax, (arrangement, (_, label)) in zip(row, arrangements.items()):
        chosen = runs[(runs["law"] == law) & (runs["arrangement"] == arrangement)]
        plot_sweep_map(chosen, x="throw (deg)", y="plates (deg)", ax=ax)
        ax.set_title(f"{law}, {arrangement}", fontsize=11)
        ax.set_xlabel("the throw: its angle from the vertical (deg)")
        ax.set_ylabel(label)
fig.suptitle("Does the ball come back? The seed's throw between tilted plates and a wedge")
fig.savefig(args.out / "plates_orientation.png", dpi=90)
print("wrote", args.out / "plates_orientation.csv", args.out / "plates_orientation.png")

# %%
# What the maps say
# -----------------
# The mixture law's dig-in part sends the ball back almost everywhere: on level plates
# for all but the flattest throw, and it fails only where the plates fall away in the
# throw's direction (negative tilt) and the throw is steep.  The compliant law, whose
# tangential spring gives back only what it stored, brings the ball back where the
# plates rise in the throw's direction (gravity's component along them returns it), or
# where the wedge narrows ahead of the ball (negative opening: the upper plate meets it
# head-on and turns its forward speed back); on level plates it does so for one throw
# only.
summary = runs.groupby(["law", "arrangement"])["came_back"].apply(
    lambda column: f"{int((column == True).sum())} of {len(column)}")   # noqa: E712
print(summary.to_string())
assert np.all(runs["status"] == 0), runs.loc[runs["status"] != 0, "message"].tolist()
