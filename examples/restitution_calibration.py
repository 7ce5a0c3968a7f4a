"""c_tau -> coefficient of restitution, measured on single normal impacts.

    python examples/restitution_calibration.py [--out DIR]

Gravity off, no spin, the ball moves straight down onto the floor at 5 m/s, so the
impact is purely normal; the restitution is e = -vz_after / vz_before of the one
contact.  Hunt-Crossley with the ballc/seed bracket 1 + 3/2 (1 - c_tau) rhodot/rhodot^-
gives e close to c_tau (for c_tau near 1); this measures it, prints the table and
draws DIR/restitution.png (default DIR: ballc-output/restitution_calibration/).
"""
import argparse
from pathlib import Path

import ballc

SPEED = 5.0                       # m/s, impact speed
C_TAUS = [0.3, 0.5, 0.7, 0.8, 0.9, 0.95, 1.0]


def restitution(c_tau: float, speed: float = SPEED) -> float:
    scene = ballc.Scene(gravity=0.0, observer_mass=0.0, c_tau=c_tau,
                        position=(0.0, 0.0, 1.5), velocity=(0.0, 0.0, -speed))
    result = ballc.simulate(scene, 1.0 / speed + 0.3)
    (contact,) = result.contacts
    return -contact.velocity_after[2] / contact.velocity_before[2]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path,
                        default=Path("ballc-output/restitution_calibration"),
                        help="output folder (default: %(default)s)")
    out = parser.parse_args(argv).out

    measured = [restitution(c) for c in C_TAUS]
    print(f"{'c_tau':>6} {'e = -vz+/vz-':>13}")
    for c_tau, e in zip(C_TAUS, measured):
        print(f"{c_tau:6.2f} {e:13.5f}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    ax.plot(C_TAUS, measured, "o-", label="measured (ballc)")
    ax.plot([0, 1], [0, 1], "k:", label="e = c_tau")
    ax.set(xlabel="c_tau (1)", ylabel="coefficient of restitution e (1)",
           title=f"Hunt-Crossley: c_tau vs restitution, normal impact at {SPEED} m/s")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.savefig(out / "restitution.png", dpi=100)
    print("wrote", out / "restitution.png")


if __name__ == "__main__":
    main()
