"""
The superball under a table
===========================

Throw a superball forward and down under a table: it bounces on the floor, on the
underside of the table and on the floor again, and comes back out towards you.  This
example runs ``examples/superball.toml`` (a 5 cm rubber ball, a 0.7 m table) with the
*compliant* tangential model -- an elastic tangential spring at the contact, stiffness
ratio 2/7 of the normal one, capped at mu times the normal force -- and the same throw
with pure Coulomb *friction*, which never brings the ball back
(see :doc:`/tangential_models`).

Run it on its own::

    python examples/superball.py [--out DIR]

It writes ``superball.png`` and the contact tables into ``DIR`` (default:
``ballc-output/superball/``, git-ignored).
"""

# %%
# The scene and the two models
# ----------------------------
import argparse
import dataclasses
import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

import ballc
from ballc.outcome import came_back

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="The superball thrown under a table.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/superball"),
                    metavar="DIR", help="output folder, default %(default)s")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

superball = ballc.Scene.from_toml(Path(sys.argv[0]).resolve().with_name("superball.toml"))
scenes = {"compliant (kappa = 2/7)": superball,
          "friction (Coulomb)": dataclasses.replace(superball, tangential_model="friction")}
print(f"table height {superball.ceiling_height} m, ball radius {superball.radius} m, "
      f"thrown at {superball.velocity} m/s")

# %%
# Simulate 0.5 s of each
# ----------------------
# Enough for floor, table, floor.  After each contact the sign of the x-velocity tells
# the direction of travel: the throw is towards +x, so "came back" means vx < 0 after
# those three contacts.
results = {}
for label, scene in scenes.items():
    result = ballc.simulate(scene, 0.5)
    results[label] = result
    print(f"--- {label}: came back: {came_back(result)}")
    print(result.contact_table())
    result.contacts_csv(args.out / f"contacts_{scene.tangential_model}.csv")

# %%
# Side view
# ---------
# The centre's path in the x-z plane, between the floor (z = 0) and the table's
# underside; the dots mark where each contact starts.
fig, ax = plt.subplots(figsize=(9, 5), constrained_layout=True)
for label, result in results.items():
    line, = ax.plot(result.position[0], result.position[2], label=label)
    starts = [result.position[:, result.t.searchsorted(c.t_start)] for c in result.contacts]
    ax.plot([p[0] for p in starts], [p[2] for p in starts], "o", color=line.get_color(), ms=4)
for height in (0.0, superball.ceiling_height):
    ax.axhline(height, color="0.3", lw=2)
ax.annotate("thrown here", superball.position[::2], xytext=(-0.1, 0.45),
            arrowprops=dict(arrowstyle="->"))
ax.set(xlabel="x of the centre (m)", ylabel="z of the centre (m)",
       title="Superball under a table: compliant contact comes back, friction does not",
       ylim=(-0.05, superball.ceiling_height + 0.05))
ax.legend(loc="center right")
fig.savefig(args.out / "superball.png", dpi=100)

# %%
# Spin
# ----
# Friction can at most bring the contact point to rest (rolling); the compliant
# spring stores tangential energy and gives it back, overshooting rolling: the spin
# about y is larger after each contact, and the contact point's velocity, and with it
# the direction of travel, reverses.
fig, ax = plt.subplots(figsize=(9, 3.5), constrained_layout=True)
for label, result in results.items():
    ax.plot(result.t, result.angular_velocity[1], label=label)
ax.set(xlabel="time (s)", ylabel="angular velocity about y (rad/s)")
ax.legend()
fig.savefig(args.out / "superball_spin.png", dpi=100)
print("wrote", args.out / "superball.png", args.out / "superball_spin.png")
