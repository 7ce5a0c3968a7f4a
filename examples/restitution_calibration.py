"""
Calibrating c_tau: the coefficient of restitution
=================================================

How does the Hunt-Crossley parameter ``c_tau`` translate into the coefficient of
restitution e of an impact?  Gravity off, no spin, the ball moves straight down onto
the floor at 5 m/s, so the impact is purely normal; e = -vz_after / vz_before of the
one contact.  The Hunt-Crossley bracket 1 + 3/2 (1 - c_tau) rhodot/rhodot^- (the
seed's and ballc's) gives e close to c_tau for c_tau near 1; this measures it against
the closed form :func:`ballc.hunt_crossley_restitution`.

Run it on its own::

    python examples/restitution_calibration.py [--out DIR]

It prints the table and writes ``DIR/restitution.png`` (default ``DIR``:
``ballc-output/restitution_calibration/``).
"""

# %%
# One normal impact
# -----------------
import argparse
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

import ballc

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="c_tau -> coefficient of restitution, measured "
                                 "on single normal impacts.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/restitution_calibration"),
                    metavar="DIR", help="output folder, default %(default)s")
args = parser.parse_args()

SPEED = 5.0                       # m/s, impact speed
C_TAUS = [0.3, 0.5, 0.7, 0.8, 0.9, 0.95, 1.0]


def restitution(c_tau: float, speed: float = SPEED) -> float:
    """e = -vz_after / vz_before of one normal impact at ``speed`` (m/s)."""
    scene = ballc.Scene(gravity=0.0, observer_mass=0.0, c_tau=c_tau,
                        position=(0.0, 0.0, 1.5), velocity=(0.0, 0.0, -speed))
    result = ballc.simulate(scene, 1.0 / speed + 0.3)
    (contact,) = result.contacts
    return -contact.velocity_after[2] / contact.velocity_before[2]


# %%
# Measure e for a range of c_tau
# ------------------------------
measured = [restitution(c) for c in C_TAUS]
closed_form = [ballc.hunt_crossley_restitution(c) for c in C_TAUS]
print(f"{'c_tau':>6} {'e = -vz+/vz-':>13} {'closed form':>12}")
for c_tau, e, e_formula in zip(C_TAUS, measured, closed_form):
    print(f"{c_tau:6.2f} {e:13.5f} {e_formula:12.5f}")

# %%
# Plot
# ----
args.out.mkdir(parents=True, exist_ok=True)
fig, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
ax.plot(C_TAUS, measured, "o-", label="measured (ballc)")
ax.plot(C_TAUS, closed_form, "x", ms=9, label="hunt_crossley_restitution")
ax.plot([0, 1], [0, 1], "k:", label="e = c_tau")
ax.set(xlabel="c_tau (1)", ylabel="coefficient of restitution e (1)",
       title=f"Hunt-Crossley: c_tau vs restitution,\nnormal impact at {SPEED} m/s")
ax.grid(alpha=0.3)
ax.legend()
fig.savefig(args.out / "restitution.png", dpi=100)
print("wrote", args.out / "restitution.png")
