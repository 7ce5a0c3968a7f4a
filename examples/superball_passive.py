"""
The superball with the passive compliant law
============================================

The seed's throw (``ballc.Scene()``: a ball thrown towards -x and down between a floor
and a ceiling -- the "table") with ``tangential_model = "compliant"``, the passive
incremental Mindlin law of :doc:`/contact_laws`, over

* kappa = ``tangential_stiffness_ratio`` in {2/7, 0.4, 0.5, 2/3, 0.857},
* mu = ``friction_coefficient`` in {0.3, 0.6, 1, 2},
* e = ``restitution`` (normal impact; ``c_tau`` is not given) in {0.8, 0.9, 1},

for the seed's 5 s.  "Came back" is ballc's criterion (:func:`ballc.outcome.came_back`,
the sweep's ``came_back`` column): the x-velocity after the first three completed
contacts (floor, table, floor) is opposite to the throw's; it is undetermined (<NA>)
with fewer completed contacts or when the run failed.  Every case is run with radau5
(the default) and again with dop853 as a cross-check.

Run it on its own::

    python examples/superball_passive.py [--out DIR] [--figure PATH]

It prints the table, writes ``superball_passive.csv`` into ``DIR`` (default
``ballc-output/superball_passive/``) and the figure to ``PATH`` (default
``DIR/superball_passive.png``; the docs' copy is ``docs/superball_passive.png``).
"""

# %%
# The sweep
# ---------
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

import ballc

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="The superball with the passive law.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/superball_passive"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--figure", type=Path, default=None, metavar="PATH",
                    help="figure path, default DIR/superball_passive.png")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)
figure = args.figure or args.out / "superball_passive.png"

KAPPAS = [2 / 7, 0.4, 0.5, 2 / 3, 0.857]
MUS = [0.3, 0.6, 1.0, 2.0]
ES = [0.8, 0.9, 1.0]
T_END = 5.0   # the seed's

base = ballc.Scene().replace(tangential_model="compliant")
parameters = {"restitution": ES, "tangential_stiffness_ratio": KAPPAS,
              "friction_coefficient": MUS}
tables = {method: ballc.sweep(base, parameters, T_END, method=method, workers=1)
          for method in ("radau5", "dop853")}
table = tables["radau5"]
table["came_back_dop853"] = tables["dop853"]["came_back"]
table["status_dop853"] = tables["dop853"]["status"]
table.to_csv(args.out / "superball_passive.csv", index=False)

# %%
# The table
# ---------
# One row per case: contacts in 5 s, the verdict with radau5 and with dop853, the
# energy left and the solver's status (0: reached 5 s).
failed = table[(table["status"] != 0) | table["came_back"].isna()]
print(f"{len(table)} runs, {int((table['status'] != 0).sum())} radau5 runs did not "
      f"reach {T_END} s, {int(table['came_back'].isna().sum())} undetermined")
differ = table[table["came_back"].astype(object).ne(table["came_back_dop853"].astype(object))]
print(f"radau5 and dop853 disagree on {len(differ)} case(s)")
columns = ["restitution", "tangential_stiffness_ratio", "friction_coefficient",
           "contacts", "came_back", "came_back_dop853", "energy_final", "status"]
with_names = table[columns].rename(columns={
    "restitution": "e", "tangential_stiffness_ratio": "kappa",
    "friction_coefficient": "mu", "came_back": "radau5", "came_back_dop853": "dop853",
    "energy_final": "E_end (J)"})
print(with_names.to_string(index=False, float_format=lambda v: f"{v:.3g}"))

# kappa x mu grids, one per e: came back (Y), did not (n), undetermined (?)
def mark(value):
    return "?" if value is None or value is np.nan or str(value) == "<NA>" else ("Y" if value else "n")


if len(failed):
    print("\nradau5 stopped early (the verdict needs 3 contacts only; dop853 reached 5 s):")
    print(failed[["restitution", "tangential_stiffness_ratio", "friction_coefficient",
                  "contacts", "t_final", "message", "status_dop853"]].to_string(index=False))

for e in ES:
    print(f"\ne = {e}: came back (Y) / did not (n) / undetermined (?); rows kappa, columns mu")
    print("kappa \\ mu " + " ".join(f"{mu:>5g}" for mu in MUS))
    for kappa in KAPPAS:
        row = table[(table["restitution"] == e) & (table["tangential_stiffness_ratio"] == kappa)]
        print(f"{kappa:10.3f} " + " ".join(f"{mark(v):>5}" for v in row["came_back"]))

# %%
# The figure
# ----------
# A panel per e: kappa against mu, each cell coloured by the verdict.
colours = ListedColormap(["#d62728", "#2ca02c", "#bbbbbb"])   # not, came back, undetermined
fig, axes = plt.subplots(1, len(ES), figsize=(12, 4.2), sharey=True, constrained_layout=True)
for ax, e in zip(axes, ES):
    grid = np.full((len(KAPPAS), len(MUS)), 2)
    for i, kappa in enumerate(KAPPAS):
        for j, mu in enumerate(MUS):
            row = table[(table["restitution"] == e) & (table["tangential_stiffness_ratio"] == kappa)
                        & (table["friction_coefficient"] == mu)].iloc[0]
            if row["came_back"] is not None and str(row["came_back"]) != "<NA>":
                grid[i, j] = int(bool(row["came_back"]))
            star = "*" if row["status"] != 0 else ""   # radau5 stopped before 5 s
            ax.text(j, i, f"{row['contacts']}{star}", ha="center", va="center", fontsize=8)
    ax.imshow(grid, cmap=colours, vmin=0, vmax=2, origin="lower", aspect="auto")
    ax.set_xticks(range(len(MUS)), [f"{mu:g}" for mu in MUS])
    ax.set_yticks(range(len(KAPPAS)), ["2/7", "0.4", "0.5", "2/3", "0.857"])
    ax.set(xlabel="friction coefficient mu", title=f"restitution e = {e:g}")
axes[0].set_ylabel("stiffness ratio kappa")
fig.legend(handles=[Patch(color="#2ca02c", label="came back"),
                    Patch(color="#d62728", label="did not"),
                    Patch(color="#bbbbbb", label="undetermined")],
           loc="outside lower center", ncols=3)
fig.suptitle("Seed throw, passive compliant law, 5 s: did the ball come back? "
             "(numbers: contacts in 5 s; *: radau5 stopped early, dop853 agrees)")
figure.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(figure, dpi=100)
print("wrote", figure, args.out / "superball_passive.csv")
