"""radau5 against dop853 on hard balls with the compliant law (issue 28, item 3).

    python -m benchmarks.hard_compliant [--rounds 3] [--budget 20000000]

The scenes: a ball of Young's modulus E (2e11 Pa, steel; and 1e7 Pa) with the compliant
tangential law, restitution e = 0.5, each normal damping (Hunt-Crossley and
viscoelastic):

* **drop**: released at rest from z = 5 m (4 m above contact), mu = 0, 3 s -- it
  bounces ~11 times and settles by ~2.7 s;
* **throw**: from z = 3 m at (4, 1, -6) m/s spinning at (30, 60, 5) rad/s, kappa = 1,
  mu = 0.1, 2 s -- 6 contacts, each sliding under a slip of ~60 m/s.

Every other field is the default (plane 2e10 Pa, observer 1e-4 kg), rtol = atol = 1e-10
(simulate's default).  For each scene and method: status, RHS calls, CPU seconds
(time.process_time, best of ``--rounds``), and the CPU ratio radau5 / dop853 measured in
the same run; then each method's error against dop853 run 1000x tighter (rtol = atol =
1e-13): the largest difference of the contact start times (s), of the rebound
velocities (m/s) and of the final position and velocity.

``--sweep N``: instead, N random spinning throws from z = 3 m (seed 1: E 1e6 ... 2e11 Pa
log-uniform, mu in {0.05, 0.1, 0.3, 0.8}, kappa in {0.3, 1, 2}, e in {0.3, 0.5, 0.9},
both dampings and observer masses 0 and 1e-4 kg in turn, velocity and spin uniform), 2 s
each with both methods and a 3 M-call budget: the count of each status, and every run
that did not end with status 0.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import ballc

METHODS = ("radau5", "dop853")
DAMPINGS = ("hunt_crossley", "viscoelastic")
MODULI = (2e11, 1e7)


def drop(damping, modulus):
    return ballc.Scene(ball_youngs_modulus=modulus, tangential_model="compliant",
                       normal_damping=damping, restitution=0.5, friction_coefficient=0.0,
                       velocity=(0.0, 0.0, 0.0))


def throw(damping, modulus):
    return ballc.Scene(ball_youngs_modulus=modulus, tangential_model="compliant",
                       normal_damping=damping, restitution=0.5, friction_coefficient=0.1,
                       tangential_stiffness_ratio=1.0, position=(0.0, 0.0, 3.0),
                       velocity=(4.0, 1.0, -6.0), angular_velocity=(30.0, 60.0, 5.0))


SCENES = {"drop": (drop, 3.0), "throw": (throw, 2.0)}


def timed(scene, t_end, method, rounds, budget):
    best, result = np.inf, None
    for _ in range(rounds):
        start = time.process_time()
        result = ballc.simulate(scene, t_end, method=method, max_nfev=budget)
        best = min(best, time.process_time() - start)
    return result, best


def differences(a, b):
    """(contact start times, rebound velocities, final position and velocity): the largest
    absolute difference between two results, over the contacts both have."""
    n = min(len(a.contacts), len(b.contacts))
    starts = max((abs(a.contacts[i].t_start - b.contacts[i].t_start) for i in range(n)),
                 default=np.nan)
    closed = [i for i in range(n) if np.isfinite(a.contacts[i].t_end)
              and np.isfinite(b.contacts[i].t_end)]
    rebound = max((float(np.max(np.abs(a.contacts[i].velocity_after
                                       - b.contacts[i].velocity_after))) for i in closed),
                  default=np.nan)
    final = float(np.max(np.abs(np.concatenate([a.position[:, -1] - b.position[:, -1],
                                                a.velocity[:, -1] - b.velocity[:, -1]]))))
    return starts, rebound, final


def random_throws(n, seed=1):
    """(index, scene) of ``--sweep``'s random spinning throws."""
    rng = np.random.default_rng(seed)
    for i in range(n):
        damping = DAMPINGS[i % 2]
        modulus = float(10 ** rng.uniform(6, 11.3))
        observer = (0.0, 1e-4)[(i // 2) % 2]
        velocity = rng.uniform(-6, 6, 3)
        velocity[2] = -abs(velocity[2]) - 0.5
        spin = rng.uniform(-80, 80, 3)
        mu = float(rng.choice([0.05, 0.1, 0.3, 0.8]))
        kappa = float(rng.choice([0.3, 1.0, 2.0]))
        e = float(rng.choice([0.3, 0.5, 0.9]))
        yield i, ballc.Scene(ball_youngs_modulus=modulus, tangential_model="compliant",
                             restitution=e, normal_damping=damping, friction_coefficient=mu,
                             tangential_stiffness_ratio=kappa, position=(0.0, 0.0, 3.0),
                             velocity=tuple(velocity), angular_velocity=tuple(spin),
                             observer_mass=observer)


def sweep(n):
    counts = {}
    for i, scene in random_throws(n):
        for method in METHODS:
            result = ballc.simulate(scene, 2.0, method=method, max_nfev=3_000_000)
            counts[method, result.status] = counts.get((method, result.status), 0) + 1
            if result.status != 0:
                print(f"{i} {method} {scene.normal_damping} E {scene.ball_youngs_modulus:.3g} "
                      f"mu {scene.friction_coefficient} kappa "
                      f"{scene.tangential_stiffness_ratio} e {scene.restitution} observer "
                      f"{scene.observer_mass}: status {result.status}, {result.nfev} calls: "
                      f"{result.message[:100]}", flush=True)
    for (method, status), count in sorted(counts.items()):
        print(f"{method}: status {status} in {count} of {n}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--budget", type=float, default=2e7)
    parser.add_argument("--sweep", type=int, default=0, help="N random spinning throws")
    args = parser.parse_args(argv)
    if args.sweep:
        sweep(args.sweep)
        return
    print("| scene | damping | E (Pa) | radau5 status | radau5 RHS calls | dop853 status "
          "| dop853 RHS calls | CPU radau5 / dop853 | contacts (r5, d8, ref) "
          "| radau5 error: starts, rebounds, final | dop853 error: starts, rebounds, final |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, (make, t_end) in SCENES.items():
        for damping in DAMPINGS:
            for modulus in MODULI:
                scene = make(damping, modulus)
                (r5, c5), (d8, c8) = (timed(scene, t_end, m, args.rounds, int(args.budget))
                                      for m in METHODS)
                ref = ballc.simulate(scene, t_end, method="dop853", rtol=1e-13, atol=1e-13,
                                     max_nfev=int(args.budget))
                errors = [" / ".join(f"{e:.1e}" for e in differences(r, ref)) for r in (r5, d8)]
                print(f"| {name} | {damping} | {modulus:g} | {r5.status} | {r5.nfev:,} "
                      f"| {d8.status} | {d8.nfev:,} | {c5 / c8:.2f} ({c5:.3f} s / {c8:.3f} s) "
                      f"| {len(r5.contacts)}, {len(d8.contacts)}, {len(ref.contacts)} "
                      f"| {errors[0]} | {errors[1]} |", flush=True)


if __name__ == "__main__":
    main()
