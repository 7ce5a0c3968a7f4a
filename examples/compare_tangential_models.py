"""
Tangential models: does the seed throw come back?
=================================================

The seed's throw (x-velocity -5 m/s) under the four tangential impact models:
Coulomb *friction*, *dig-in*, the seed's *mixture* of both, and ballc's *compliant*
contact (what each assumes: :doc:`/tangential_models`).  Left: the x-coordinate of the
centre against time; "coming back" means x turns around after floor -> ceiling ->
floor.  Right: the energy (kinetic + potential + spring) against time: dig-in alone
gains energy until the ball passes through the floor.

Run it on its own::

    python examples/compare_tangential_models.py [--out DIR] [--t-end 5]

It writes ``DIR/tangential_models.png`` (default ``DIR``:
``ballc-output/compare_tangential_models/``; ``--out docs`` regenerates the figure of
``docs/tangential_models.md``).
"""

# %%
# The four models
# ---------------
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

import ballc

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="The seed's throw under the four tangential "
                                 "models: does the ball come back?")
parser.add_argument("--out", type=Path, default=Path("ballc-output/compare_tangential_models"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--t-end", type=float, default=5.0, help="simulated time (s)")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

MODELS = {
    "friction (Coulomb, mu = 0.1)": dict(tangential_model="friction"),
    "dig-in": dict(tangential_model="dig-in"),
    "mixture 0.375 (seed)": dict(tangential_model="mixture"),
    "compliant (kappa = 2/7, mu = 1)": dict(tangential_model="compliant",
                                            tangential_stiffness_ratio=2 / 7,
                                            friction_coefficient=1.0),
}

# %%
# Simulate and draw
# -----------------
# The signs are those of the x-velocity after each of the first three contacts.
fig, (ax_x, ax_e) = plt.subplots(1, 2, figsize=(13, 4.8))
for label, changes in MODELS.items():
    result = ballc.simulate(ballc.Scene(**changes), args.t_end)
    signs = "".join("+" if c.velocity_after[0] > 0 else "-"
                    for c in result.contacts[:3] if c.t_end == c.t_end)
    note = "" if result.success else " (passed through the floor)"
    line, = ax_x.plot(result.t, result.position[0], label=f"{label}: vx signs {signs}{note}")
    ax_e.plot(result.t, result.energy["total"], color=line.get_color(), label=label)
    print(f"{label:34s} status {result.status}  contacts {len(result.contacts)}  "
          f"vx after first three contacts: {signs}  energy {result.energy['total'][0]:.1f}"
          f" -> {result.energy['total'][-1]:.1f} J")
ax_x.set_ylim(-6, 6)   # dig-in runs off to x > 100 m
ax_x.axhline(0, color="0.6", lw=0.8)
ax_x.set_xlabel("time (s)")
ax_x.set_ylabel("x of the centre (m)")
ax_x.set_title("Seed throw (vx0 = -5 m/s): does it come back?")
ax_x.legend(fontsize=8)
ax_e.set_xlabel("time (s)")
ax_e.set_ylabel("kinetic + potential + spring (J)")
ax_e.set_yscale("log")
ax_e.set_title("Energy: dig-in alone injects energy")
ax_e.legend(fontsize=8)
fig.tight_layout()
figure = args.out / "tangential_models.png"
fig.savefig(figure, dpi=110)
print(f"wrote {figure}")
