"""
Reproducing the seed
====================

The seed is the sympy/PyDy-style gallery example "ball bouncing between two planes" by
Peter Stahlecker.  It reports 9 contacts (floor and ceiling alternating, the first at
t = 0.156 s), an energy of 386.59 J -> 109.70 J and the x-velocity reversing at the
first ceiling contact (-2.63 -> +2.20 m/s).  This example runs the same scene
(``examples/seed.toml``) for 5 s, prints ballc's numbers next to the seed's, draws the
coordinates, the energies, the contact points and what the observer feels, and writes
the figures, the contact table (CSV), the result (``.npz``) and the 3-D animation
(GIF) into an output folder.

Run it on its own::

    python examples/seed_reproduction.py [--out DIR] [--frames N]

``DIR`` defaults to ``ballc-output/seed_reproduction/`` (git-ignored).
"""

# %%
# Options and the scene
# ---------------------
# The scene file sits next to this script; every field is in SI units.
import argparse
import sys
import time
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

import ballc
from ballc.outcome import format_summary

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="Reproduce the seed's run and its figures.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/seed_reproduction"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--frames", type=int, default=100,
                    metavar="N", help="frames of the 3-D animation, default %(default)s")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

scene_file = Path(sys.argv[0]).resolve().with_name("seed.toml")
scene = ballc.Scene.from_toml(scene_file)
print(scene_file.read_text())

# %%
# Simulate 5 s
# ------------
# ``rtol = atol = 1e-10`` by default; the compiled radau5 integrator takes a fraction
# of a second.
started = time.perf_counter()
result = ballc.simulate(scene, 5.0)
print(f"simulated 5 s in {time.perf_counter() - started:.2f} s")
print(format_summary(result))
print(result.contact_table())

# %%
# Against the seed's numbers
# --------------------------
total = result.energy["total"]
ceiling = next(c for c in result.contacts if c.plane == "ceiling")
print("seed:  9 contacts, 386.59 J -> 109.70 J, vx -2.63 -> +2.20 m/s at the first "
      "ceiling contact")
print(f"ballc: {len(result.contacts)} contacts, {total[0]:.2f} J -> {total[-1]:.2f} J, "
      f"vx {ceiling.velocity_before[0]:+.2f} -> {ceiling.velocity_after[0]:+.2f} m/s")

# %%
# Coordinates
# -----------
# Centre position (m), centre velocity (m/s) and angular velocity (rad/s) against time.
fig, axes = result.plot()
fig.savefig(args.out / "coordinates.png", dpi=100)

# %%
# Energy
# ------
# Kinetic, potential and spring energy, the work dissipated in the contacts, and
# their sum ``balance``, which stays at the initial energy.
fig, ax = result.plot_energy()
# sphinx_gallery_thumbnail_number = 2
fig.savefig(args.out / "energy.png", dpi=100)

# %%
# Where the ball touched the planes
# ---------------------------------
# A top view of the contact points, coloured by time.
fig, ax = result.plot_contacts()
fig.savefig(args.out / "contacts_top_view.png", dpi=100)

# %%
# What the observer feels
# -----------------------
# The specific force (acceleration minus gravity, in g) on the observer particle
# inside the ball: what an accelerometer there would record.
fig, axes = result.plot_observer()
fig.savefig(args.out / "observer.png", dpi=100)

# %%
# Files
# -----
# The contact table as CSV (each column's unit in its header) and the whole result as
# ``.npz`` (``ballc.load`` reads it back).
result.contacts_csv(args.out / "contacts.csv")
result.save(args.out / "seed.npz")
print((args.out / "contacts.csv").read_text().splitlines()[0])
print("loaded back:", ballc.load(args.out / "seed.npz").y.shape)

# %%
# The 3-D animation
# -----------------
# The planes, the ball turning, the observer (red) and the contact points; written as
# a GIF (``result.animate`` returns the matplotlib ``FuncAnimation``).  Frames are
# equally spaced in simulated time.
animation = result.animate(args.out / "animation.gif", frames=args.frames)
plt.close("all")   # the GIF is the animation
print("wrote", args.out / "animation.gif")
