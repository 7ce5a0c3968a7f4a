"""
The superball with rolling resistance
=====================================

Does rolling resistance -- the normal force acting off the centre, Rod Cross's D of "Grip-slip
behavior of a bouncing ball" (Am. J. Phys. 70, 2002), a torque N D = mu_r r N against the
rolling (the exact model, Ai et al.'s type A: :doc:`/contact_laws`, "Rolling resistance") --
bring back a rubber ball whose tangential stiffness is rubber's own?  Cross measured a
superball's mu >~ 0.9, e_y = 0.97 and e_x = 0.49.

Over mu_r = ``rolling_resistance`` in {0, 0.02, 0.05, 0.1} and kappa =
``tangential_stiffness_ratio`` in {2/7, 0.5, 2/3, Mindlin's for rubber on granite}, with the
passive compliant law, mu = 0.9 and e = ``restitution`` = 0.97:

* left: e_t, the contact point's tangential restitution (Cross's e_x; ``Impact.e_t``), of a
  2.5-cm, 50-g superball (E = 2 MPa, nu = 0.49) hitting granite (E = 50 GPa, nu = 0.25) at
  3 m/s, against the incident angle from the normal, beside Cross's 0.49;
* right: the seed's under-table verdict -- the seed's throw (``ballc.Scene()``, thrown
  towards -x and down between the floor and the "table") with the same law, kappa, mu_r,
  mu and e: did it come back (:func:`ballc.outcome.came_back`, after the first three
  contacts, floor-table-floor)?

Run it on its own::

    python examples/superball_rolling.py [--out DIR] [--figure PATH]

It prints both tables and writes the figure (default
``ballc-output/superball_rolling/superball_rolling.png``; the docs' copy is ``docs/superball_rolling.png``).
"""

# %%
# The impacts and the throws
# --------------------------
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import ballc
from ballc.scene import mindlin_stiffness_ratio

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="The superball with rolling resistance.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/superball_rolling"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--figure", type=Path, default=None, metavar="PATH",
                    help="figure path, default DIR/superball_rolling.png")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)
figure = args.figure or args.out / "superball_rolling.png"

RUBBER = mindlin_stiffness_ratio(0.49, 0.25, 2e6, 5e10)   # 4 G*/E*, ~0.68
KAPPAS = {"2/7": 2 / 7, "0.5": 0.5, "2/3": 2 / 3, f"rubber {RUBBER:.2f}": RUBBER}
MU_RS = [0.0, 0.02, 0.05, 0.1]
ANGLES = np.arange(5.0, 81.0, 5.0)
CROSS_EX = 0.49

superball = ballc.Scene(mass=0.05, radius=0.025, ball_youngs_modulus=2e6,
                        ball_poisson_ratio=0.49, plane_youngs_modulus=5e10,
                        plane_poisson_ratio=0.25, friction_coefficient=0.9, restitution=0.97,
                        tangential_model="compliant", observer_mass=0.0, ceiling_height=0.7,
                        position=(0.0, 0.0, 0.3), velocity=(0.0, 0.0, -3.0))
e_t = {}
for name, kappa in KAPPAS.items():
    for mu_r in MU_RS:
        scene = superball.replace(tangential_stiffness_ratio=kappa, rolling_resistance=mu_r)
        e_t[name, mu_r] = ballc.impact_table(scene, angles=ANGLES, speed=3.0)["e_t"].to_numpy()

seed = ballc.Scene().replace(tangential_model="compliant", friction_coefficient=0.9,
                             restitution=0.97)
verdicts = ballc.sweep(seed, {"rolling_resistance": MU_RS,
                              "tangential_stiffness_ratio": list(KAPPAS.values())}, 5.0,
                       workers=1)

# %%
# The tables
# ----------
print(f"e_t at 3 m/s (Cross's superball: e_x = {CROSS_EX}); angles {ANGLES[0]:g}..{ANGLES[-1]:g} deg")
for (name, mu_r), values in e_t.items():
    middle = values[(ANGLES >= 20) & (ANGLES <= 60)]
    print(f"kappa {name:12s} mu_r {mu_r:4.2f}: e_t {values.min():+.2f}..{values.max():+.2f}"
          f" (20..60 deg: {middle.min():+.2f}..{middle.max():+.2f})")
print("\nthe seed's throw under the table, 5 s: came back?")
print(verdicts[["rolling_resistance", "tangential_stiffness_ratio", "came_back", "contacts",
                "status"]].to_string(index=False, float_format=lambda v: f"{v:.3g}"))

# %%
# The figure
# ----------
fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5), constrained_layout=True,
                                  gridspec_kw=dict(width_ratios=[2, 1]))
colours = dict(zip(KAPPAS, ["#1f77b4", "#2ca02c", "#ff7f0e", "#d62728"]))
styles = dict(zip(MU_RS, ["-", "--", "-.", ":"]))
for (name, mu_r), values in e_t.items():
    left.plot(ANGLES, values, styles[mu_r], color=colours[name], marker=".",
              label=f"kappa {name}, mu_r {mu_r:g}")
left.axhline(CROSS_EX, color="k", lw=2, alpha=0.5, label="Cross's superball, e_x = 0.49")
left.set(xlabel="incident angle from the normal (deg)",
         ylabel="e_t = -u_t' / u_t (contact point)",
         title="superball (2.5 cm, 50 g, E 2 MPa) on granite, 3 m/s, mu 0.9, e 0.97")
left.grid(alpha=0.3)
left.legend(fontsize=7, ncols=2)
grid = np.zeros((len(MU_RS), len(KAPPAS)))
for i, mu_r in enumerate(MU_RS):
    for j, kappa in enumerate(KAPPAS.values()):
        row = verdicts[(verdicts["rolling_resistance"] == mu_r)
                       & (verdicts["tangential_stiffness_ratio"] == kappa)].iloc[0]
        came = row["came_back"]
        grid[i, j] = 2 if str(came) == "<NA>" else int(bool(came))
        right.text(j, i, {0: "no", 1: "came back", 2: "?"}[int(grid[i, j])], ha="center",
                   va="center", fontsize=9)
right.imshow(grid, cmap=matplotlib.colors.ListedColormap(["#d62728", "#2ca02c", "#bbbbbb"]),
             vmin=0, vmax=2, origin="lower", aspect="auto")
right.set_xticks(range(len(KAPPAS)), list(KAPPAS), fontsize=8)
right.set_yticks(range(len(MU_RS)), [f"{m:g}" for m in MU_RS])
right.set(xlabel="tangential stiffness ratio kappa", ylabel="rolling resistance mu_r",
          title="seed's throw under the table: came back?")
fig.suptitle("Rolling resistance (exact model) and the superball")
figure.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(figure, dpi=100)
print("wrote", figure)
