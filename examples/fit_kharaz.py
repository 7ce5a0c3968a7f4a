"""
Fitting mu and kappa to alumina on glass
========================================

Kharaz, Gorham & Salman (2001) shot 5 mm alumina spheres at a soda-lime glass anvil at
3.9 m/s and measured, against the incident angle from the normal, the tangential
restitution v_t'/v_t, the spin after the impact and the rebound angle.  This example fits
the passive compliant law's friction coefficient mu and stiffness ratio kappa to all three
with :func:`ballc.fit_impacts`, the other inputs those of MFIX's DEM05 case (Hertz,
E = 380 / 70 GPa, nu = 0.23 / 0.25, normal restitution 1), and prints them with their
standard errors beside the nominal mu = 0.092 and Mindlin's kappa = 4 G*/E* of these
materials.  The data and their provenance: ``validation/kharaz2001.py``.

Run it from the repository root::

    python examples/fit_kharaz.py [--out DIR] [--figure PATH]

It writes ``fit_kharaz.csv`` into ``DIR`` (default ``ballc-output/fit_kharaz/``) and the
figure to ``PATH`` (default ``DIR/fit_kharaz.png``; the docs' copy is
``docs/fit_kharaz.png``).
"""

# %%
# The scene and the data
# ----------------------
import argparse
import math
import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import ballc

matplotlib.use("Agg")   # write files, never open a window

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parents[1]))
from validation import kharaz2001 as kgs   # noqa: E402  (the repository's validation/)

parser = argparse.ArgumentParser(description="Fit mu and kappa to Kharaz et al. (2001).")
parser.add_argument("--out", type=Path, default=Path("ballc-output/fit_kharaz"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--figure", type=Path, default=None, metavar="PATH",
                    help="figure path, default DIR/fit_kharaz.png")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)
figure = args.figure or args.out / "fit_kharaz.png"

r = kgs.DIAMETER / 2
m = kgs.DENSITY * 4 / 3 * math.pi * r ** 3
alumina = ballc.Scene(
    mass=m, observer_mass=0.0, radius=r, gravity=0.0, ceiling_height=1.0,
    inertia=(0.4 * m * r * r,) * 3, position=(0.0, 0.0, 0.5),
    ball_youngs_modulus=kgs.BALL_YOUNGS_MODULUS, ball_poisson_ratio=kgs.BALL_POISSON_RATIO,
    plane_youngs_modulus=kgs.WALL_YOUNGS_MODULUS, plane_poisson_ratio=kgs.WALL_POISSON_RATIO,
    restitution=kgs.NORMAL_RESTITUTION, friction_coefficient=kgs.FRICTION_COEFFICIENT,
    tangential_model="compliant")
kappa_mindlin = alumina.tangential_stiffness_ratio     # the default: 4 G*/E*
print(f"alumina sphere: r = {r * 1e3} mm, m = {m * 1e3:.4g} g; Mindlin's kappa = "
      f"{kappa_mindlin:.4f} (MFIX's linear kt/kn = {kgs.LINEAR_KT_OVER_KN:.4f})")


def incident(angle):
    a = math.radians(angle)
    return dict(vx=kgs.SPEED * math.sin(a), vy=0.0, vz=-kgs.SPEED * math.cos(a),
                wx=0.0, wy=0.0, wz=0.0)


# One row per measured point; NaN = not measured in that row.  The spin is about +y for
# a ball moving towards +x.  The rebound angle fixes v_x' given v_z', taken as the
# model's (restitution 1: v_z' = -v_z).
rows = []
for angle, e_t in zip(kgs.TANGENTIAL_RESTITUTION_ANGLE, kgs.TANGENTIAL_RESTITUTION):
    row = incident(angle)
    rows.append({**row, "what": "tangential restitution", "angle": angle,
                 "vx_after": e_t * row["vx"], "wy_after": np.nan})
for angle, spin in zip(kgs.ANGULAR_VELOCITY_ANGLE, kgs.ANGULAR_VELOCITY):
    rows.append({**incident(angle), "what": "spin", "angle": angle,
                 "vx_after": np.nan, "wy_after": spin})
for angle, out in zip(kgs.REBOUND_ANGLE_INCIDENT, kgs.REBOUND_ANGLE):
    row = incident(angle)
    vz_after = -kgs.NORMAL_RESTITUTION * row["vz"]
    rows.append({**row, "what": "rebound angle", "angle": angle,
                 "vx_after": vz_after * math.tan(math.radians(out)), "wy_after": np.nan})
data = pd.DataFrame(rows)

# %%
# The fit
# -------
# Residuals are (model - measured) / incident speed for velocities and
# / (incident speed / r) for spins; standard errors from the Jacobian at the optimum.
fit = ballc.fit_impacts(alumina, data, free=("friction_coefficient",
                                             "tangential_stiffness_ratio"))
print(fit.summary())
(mu, kappa), (mu_err, kappa_err) = fit.values, fit.standard_errors
print(f"\n{'':22s}{'fitted':>18s}{'nominal':>12s}")
print(f"{'mu':22s}{mu:10.4f} +- {mu_err:.4f}{kgs.FRICTION_COEFFICIENT:12.4f}  (MFIX DEM05)")
print(f"{'kappa':22s}{kappa:10.4f} +- {kappa_err:.4f}{kappa_mindlin:12.4f}  (Mindlin 4G*/E*)")
fit.predicted.to_csv(args.out / "fit_kharaz.csv", index=False)

# Each kind of measurement on its own: do they agree?
print("\nfitted to one kind of measurement at a time:")
for what in data["what"].unique():
    part = ballc.fit_impacts(alumina, data[data["what"] == what].reset_index(drop=True),
                             free=("friction_coefficient", "tangential_stiffness_ratio"))
    (m_, k_), (dm, dk) = part.values, part.standard_errors
    print(f"  {what:24s} mu = {m_:.4f} +- {dm:.4f}   kappa = {k_:.4f} +- {dk:.4f}")

# %%
# Model against measurement
# -------------------------
# The fitted law and the nominal one (mu = 0.092, Mindlin's kappa) over 0-65 degrees.
angles = np.linspace(0.5, 65, 60)


def curves(scene):
    e_t, spin, rebound = [], [], []
    for angle in angles:
        row = incident(angle)
        hit = ballc.impact(scene, (row["vx"], 0.0, row["vz"]))
        vx, _, vz = hit.velocity_after
        e_t.append(vx / row["vx"])
        spin.append(hit.angular_velocity_after[1])
        rebound.append(math.degrees(math.atan2(vx, vz)))
    return e_t, spin, rebound


models = {f"fitted: mu = {mu:.3f}, kappa = {kappa:.3f}": fit.scene,
          f"nominal: mu = {kgs.FRICTION_COEFFICIENT}, kappa = {kappa_mindlin:.3f}": alumina}
measured = [(kgs.TANGENTIAL_RESTITUTION_ANGLE, kgs.TANGENTIAL_RESTITUTION,
             "tangential restitution v_t'/v_t"),
            (kgs.ANGULAR_VELOCITY_ANGLE, kgs.ANGULAR_VELOCITY, "spin after (rad/s)"),
            (kgs.REBOUND_ANGLE_INCIDENT, kgs.REBOUND_ANGLE, "rebound angle (deg)")]
fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
for (label, scene), style in zip(models.items(), ("-", "--")):
    for ax, values in zip(axes, curves(scene)):
        ax.plot(angles, values, style, color="C0" if style == "-" else "C1", label=label)
for ax, (x, y, name) in zip(axes, measured):
    ax.plot(x, y, "ks", ms=5, label="Kharaz, Gorham & Salman (2001)")
    ax.set(xlabel="incident angle from the normal (deg)", ylabel=name)
axes[0].legend(fontsize=8)
fig.suptitle("5 mm alumina on soda-lime glass, 3.9 m/s: passive compliant law")
figure.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(figure, dpi=100)
print("wrote", figure, args.out / "fit_kharaz.csv")
