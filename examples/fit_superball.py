"""
Fitting the compliant model to bounces
======================================

Fit the compliant model to superball bounces with ballc.fit_impacts, then throw the
ball under the table.

    python examples/fit_superball.py [--out DIR]

writes DIR/fit_superball.png and DIR/bounces.csv (default DIR:
ballc-output/fit_superball/).

THE DATA ARE SYNTHETIC.  No published, numerical measurement of a superball's oblique
bounce was found for this example: Cross, "Grip-slip behavior of a bouncing ball",
Am. J. Phys. 70, 1093 (2002), and Cross, "Oblique bounce of a rubber ball", Exp. Mech.
(2014), give their superball results as figures, not as numbers in text or tables, and
no digitised copy was found (see docs/validation.md).  So the "measurements" here are
made by ballc itself with known parameters (kappa = 2/7, mu = 1, c_tau = 0.95: a
superball-like contact whose contact point leaves with its slip reversed) on the seed's
ball, at five incident angles; fit_impacts starts from Mindlin's kappa for rubber (2/3),
mu = 0.5, c_tau = 0.8 and must find them back.  Replace DATA by measured rebounds
(columns vx..wz, vx_after..wz_after; NaN where not measured) to fit a real ball.

Then the seed's under-table throw (1.2 s) runs with the fitted parameters and with
Mindlin's kappa = 2/3 and 0.857; ballc.outcome.came_back says whether the ball came back.
"""

# %%
# Synthetic bounces from known parameters
# ---------------------------------------
import argparse
import time
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import ballc
from ballc.outcome import came_back

matplotlib.use("Agg")   # write files, never open a window

TRUE = dict(tangential_stiffness_ratio=2 / 7, friction_coefficient=1.0, c_tau=0.95)
START = dict(tangential_stiffness_ratio=2 / 3, friction_coefficient=0.5, c_tau=0.8)
ANGLES = [15, 30, 45, 60, 75]     # degrees from the normal
SPEED = 25.0                      # m/s, the seed throw's normal speed

parser = argparse.ArgumentParser(description="Fit the compliant model to bounces.")
parser.add_argument("--out", type=Path, default=Path("ballc-output/fit_superball"),
                    metavar="DIR", help="output folder, default %(default)s")
out = parser.parse_args().out
out.mkdir(parents=True, exist_ok=True)
t0 = time.perf_counter()

seed = ballc.Scene(tangential_model="compliant", observer_mass=0.0)
base = seed.replace(gravity=0.0)              # single impacts without gravity
data = ballc.impact_table(base.replace(**TRUE), angles=ANGLES, speed=SPEED)
data = data[["angle", "vx", "vy", "vz", "wx", "wy", "wz", "vx_after", "vz_after",
             "wy_after", "e_t"]]
data.to_csv(out / "bounces.csv", index=False)
print("synthetic bounces (ballc with", TRUE, "):")
print(data.round(4).to_string(index=False))

# %%
# The fit: least squares over mu, kappa and c_tau
# ------------------------------------------------
fit = ballc.fit_impacts(base.replace(**START), data,
                        free=("friction_coefficient", "tangential_stiffness_ratio", "c_tau"))
print(fit.summary())
for name, value in TRUE.items():
    print(f"  {name:28s} true {value:.6g}, fitted {getattr(fit.scene, name):.6g}")

# %%
# The under-table throw with the fitted parameters, and with Mindlin's kappa
# --------------------------------------------------------------------------
fitted = {name: getattr(fit.scene, name) for name in TRUE}
throws = {"fitted": fitted,
          "Mindlin rubber kappa = 2/3": {**fitted, "tangential_stiffness_ratio": 2 / 3},
          "Mindlin seed kappa = 0.857": {**fitted, "tangential_stiffness_ratio":
                                         seed.tangential_stiffness_ratio}}
print("under-table throw (seed scene, 1.2 s):")
results = {}
for label, values in throws.items():
    result = ballc.simulate(seed.replace(**values), 1.2)
    results[label] = result
    print(f"  {label:30s} came back: {came_back(result)}")

fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
fine = ballc.impact_table(fit.scene, angles=np.linspace(5, 85, 17), speed=SPEED)
start = ballc.impact_table(base.replace(**START), angles=np.linspace(5, 85, 17), speed=SPEED)
a1.plot(data["angle"], data["e_t"], "o", label="synthetic data (ballc, known parameters)")
a1.plot(fine["angle"], fine["e_t"], "-", label="fitted compliant model")
a1.plot(start["angle"], start["e_t"], ":", label="start (Mindlin rubber kappa = 2/3)")
a1.set(xlabel="incident angle from the normal (deg)",
       ylabel="tangential restitution of the contact point e_t = -u'/u",
       title="fit_impacts on synthetic superball bounces")
for label, result in results.items():
    a2.plot(result.t, result.position[0], label=f"{label}: came back {came_back(result)}")
a2.set(xlabel="time (s)", ylabel="x of the centre (m)",
       title="seed throw under the table, compliant model")
for a in (a1, a2):
    a.grid(alpha=0.3)
    a.legend(fontsize=8)
fig.savefig(out / "fit_superball.png", dpi=90)
print(f"wrote {out / 'fit_superball.png'}, {out / 'bounces.csv'} "
      f"({time.perf_counter() - t0:.1f} s)")
