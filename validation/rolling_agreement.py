"""ballc's rolling resistance (sds model, with the compliant law) against LAMMPS' rolling
and twisting sds algorithm, stepped explicitly (validation/rolling_reference.py in
validation/dem_reference.py's stepping).

``compare(impacts)`` runs each impact (a dict of :class:`ballc.Scene` fields with
``rolling_model = "sds"``) with ``ballc.impact`` and with the reference converged in its
time step, and returns per impact the largest |difference| of the rebound centre
velocity and of omega R (every component), divided by the impact speed (1).
``python -m validation.rolling_agreement [n] [seed] [damping]`` prints it for
``random_impacts(n, seed, damping)``.

ballc's sds is LAMMPS' with one change that keeps it passive: LAMMPS caps the sum of
spring and dashpot and rescales the spring so that the sum sits at the cap, ballc caps the
spring and fits the dashpot in the capacity it leaves (docs/contact_laws.md).  Without a
dashpot (``damping`` 0) they are the same law; with one they differ where the dashpot
alone would exceed the cap.
"""
from __future__ import annotations

import math

import numpy as np

from .dem_agreement import AL_OXIDE, random_impacts as tangential_impacts, reference_parameters
from .dem_reference import dem_impact_converged, rebound_difference


def rolling_parameters(scene):
    """The reference's ``rolling`` and ``twisting`` dicts of an sds scene."""
    parts = {}
    for part in ("rolling", "twisting"):
        mu = getattr(scene, f"{part}_resistance")
        parts[part] = None if mu == 0 else dict(
            k=getattr(scene, f"{part}_stiffness"), gamma=getattr(scene, f"{part}_damping"),
            mu=mu)
    return parts


def compare(scene_kwargs_list, rel_tol=1e-5):
    """Per impact: max |ballc - reference| of the rebound centre velocity and omega R,
    over the impact speed (1), as an array."""
    import ballc
    errors = []
    for kwargs in scene_kwargs_list:
        scene = ballc.Scene(**kwargs)
        if scene.rolling_model != "sds":
            raise ValueError("the reference is the sds model's (rolling_model = 'sds')")
        v_in, w_in = scene.velocity, scene.angular_velocity
        hit = ballc.impact(scene, v_in, w_in)
        ref = dem_impact_converged(**reference_parameters(scene), **rolling_parameters(scene),
                                   velocity=v_in, angular_velocity=w_in, rel_tol=rel_tol)
        ours = dict(velocity_after=np.asarray(hit.velocity_after),
                    angular_velocity_after=np.asarray(hit.angular_velocity_after))
        errors.append(rebound_difference(ours, ref, scene.radius, np.linalg.norm(v_in)))
    return np.array(errors)


def random_impacts(n, seed, damping=0.0, speed=3.9):
    """validation.dem_agreement's random oblique spinning impacts of the Al oxide sphere
    (kappa 0.1..1.2, mu 0.05..1.5), with rolling and twisting resistance in the sds
    model: mu_r, mu_t in 0.01..0.3, each spring k in 10^5..10^9 N/m (a rolling period from
    ~100 contact times to ~0.1 of one), each dashpot ``damping`` times its critical value
    2 sqrt(I_r k) / R (I_r = I + m R^2 rolling, I twisting)."""
    rng = np.random.default_rng(1000 + seed)
    r = AL_OXIDE["radius"]
    impacts = []
    for kwargs in tangential_impacts(n, seed, speed):
        mass = kwargs["mass"]
        inertia = 0.4 * mass * r * r
        fields = dict(kwargs, rolling_model="sds")
        for part, moment in (("rolling", inertia + mass * r * r), ("twisting", inertia)):
            k = float(10 ** rng.uniform(5, 9))
            fields[f"{part}_resistance"] = float(rng.uniform(0.01, 0.3))
            fields[f"{part}_stiffness"] = k
            fields[f"{part}_damping"] = float(damping * 2 * math.sqrt(moment * k) / r)
        impacts.append(fields)
    return impacts


if __name__ == "__main__":
    import sys
    args = sys.argv[1:]
    n = int(args[0]) if args else 10
    seed = int(args[1]) if len(args) > 1 else 0
    damping = float(args[2]) if len(args) > 2 else 0.0
    errors = compare(random_impacts(n, seed, damping))
    for i, err in enumerate(errors):
        print(f"impact {i:3d}: max |ballc - LAMMPS sds| / |v| = {err:.3e}")
    print(f"worst {errors.max():.3e}, median {np.median(errors):.3e}")
