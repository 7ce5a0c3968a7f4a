"""
Choosing the integrator: radau5 or dop853
=========================================

ballc has two compiled integrators, run by the same C loop with the same events and
output: **radau5** (Radau IIA, order 5, implicit: the default, robust on every scene)
and **dop853** (Dormand & Prince, explicit, order 8: no Jacobian, no linear algebra).
This example runs the seed's throw (5 s) with both at tolerances 1e-4 ... 1e-12 and
plots the CPU time against the final-state error (position, m, and velocity, m/s)
measured against radau5 at 1e-13: the curve further down and to the left is the
cheaper one at equal error.  Then a stiff scene, a steel-hard ball that comes to rest
and rolls, where dop853's steps are held at its stability limit: the run's message says
so (what this costs: :doc:`/limits`).

Run it on its own::

    python examples/choose_integrator.py [--out DIR] [--t-end 5]

It writes ``DIR/work_precision_seed.png`` (default ``DIR``:
``ballc-output/choose_integrator/``).  CPU times are those of this machine and run
(best of 3): a loaded machine moves them, not the errors.
"""

# %%
# CPU against error on the seed's throw
# -------------------------------------
import argparse
import time
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import ballc

matplotlib.use("Agg")   # write files, never open a window

parser = argparse.ArgumentParser(description="radau5 against dop853: CPU time against "
                                 "error on the seed's throw, and a stiff scene")
parser.add_argument("--out", type=Path, default=Path("ballc-output/choose_integrator"),
                    metavar="DIR", help="output folder, default %(default)s")
parser.add_argument("--t-end", type=float, default=5.0, help="simulated time (s)")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)


def final_state(result):
    return np.concatenate([result.position[:, -1], result.velocity[:, -1]])


scene = ballc.Scene()
reference = final_state(ballc.simulate(scene, args.t_end, rtol=1e-13, atol=1e-13))
tolerances = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
fig, ax = plt.subplots(figsize=(7, 4.8))
for method, marker in (("radau5", "o-"), ("dop853", "s-")):
    cpu, error = [], []
    for tol in tolerances:
        best = np.inf
        for _ in range(3):
            started = time.process_time()
            result = ballc.simulate(scene, args.t_end, method=method, rtol=tol, atol=tol)
            best = min(best, time.process_time() - started)
        cpu.append(best)
        error.append(np.abs(final_state(result) - reference).max())
        print(f"{method}  rtol = atol = {tol:.0e}: {1e3 * best:7.2f} ms CPU, "
              f"final error {error[-1]:.1e}, {result.nfev} RHS calls")
    line, = ax.loglog(error, 1e3 * np.array(cpu), marker, label=method)
    for tol, e, c in zip(tolerances, error, cpu):
        ax.annotate(f"{tol:.0e}", (e, 1e3 * c), fontsize=7, color=line.get_color(),
                    xytext=(3, 3), textcoords="offset points")
ax.set_xlabel("final-state error (m, m/s) against radau5 at 1e-13")
ax.set_ylabel("CPU per run (ms)")
ax.set_title(f"Seed throw, {args.t_end:g} s: CPU against error (labels: rtol = atol)")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
figure = args.out / "work_precision_seed.png"
fig.savefig(figure, dpi=110)
print(f"wrote {figure}")

# %%
# A stiff scene: a steel-hard ball at rest
# ----------------------------------------
# Dropped from 1 m above the floor with 0.5 m/s sideways, it settles in about 2 s and
# then rolls in permanent contact: the contact spring of a 2e11-Pa ball is stiff for an
# explicit method.  dop853 notices (Hairer's stiffness test) and says so in the message.
steel = ballc.Scene(tangential_model="friction", ball_youngs_modulus=2e11,
                    plane_youngs_modulus=2e11, c_tau=0.5, observer_mass=0.0,
                    position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))
for method in ("radau5", "dop853"):
    started = time.process_time()
    result = ballc.simulate(steel, 5.0, method=method, rtol=1e-6, atol=1e-6)
    print(f"{method}: {1e3 * (time.process_time() - started):.1f} ms CPU, "
          f"{result.nfev} RHS calls, status {result.status}")
    print(f"  {result.message}")
