"""ballc's compliant law against the explicit DEM oracle (validation/dem_reference.py).

``compare(impacts)`` runs each impact (a dict of :class:`ballc.Scene` fields; the
incident state is the dict's ``velocity`` and ``angular_velocity``) with
``ballc.impact`` on the floor and with :func:`dem_reference.dem_impact_converged`, and
returns, per impact, the largest |difference| of the rebound centre velocity and
contact-point velocity v + omega x (-R n) (every component), divided by the impact
speed |v| (1).  ``python -m validation.dem_agreement [n] [seed]`` prints it for
``random_impacts(n, seed)``.

Scene -> reference: k0 = hertz_stiffness (N/m^1.5), kappa = tangential_stiffness_ratio,
m* = mass + observer_mass (kg), I = inertia[0] (isotropic only, kg m^2), mu =
friction_coefficient; normal_damping, damping_ratio (gamma) and tangential_damping_ratio
(gamma_t) read with getattr (absent or None: "hunt_crossley", 0, 0, as for a ballc that
predates them); Hunt-Crossley's chi from ``restitution`` e when the scene has one
(chi (1 + e) = ln((1 + chi)/(1 - chi e))), else chi = 3/2 (1 - c_tau).
Scenes must have gravity 0 (the oracle has none).
"""
from __future__ import annotations

import math

import numpy as np

from .dem_reference import dem_impact_converged

# Chung & Ooi's Al oxide (validation/cases.py, tests 3 and 4): SI units
AL_OXIDE = dict(radius=0.0025, density=4000.0, youngs=3.8e11, poisson=0.23)


def hunt_crossley_chi(e):
    """chi (1) solving chi (1 + e) = ln((1 + chi)/(1 - chi e)) for e in (0, 1]
    (bisection on (0, 1/e); e = 1 gives 0)."""
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution {e} not in (0, 1]")
    if e == 1.0:
        return 0.0
    f = lambda chi: math.log1p(chi) - math.log1p(-chi * e) - chi * (1 + e)  # noqa: E731
    lo, hi = 0.0, 1.0 / e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def reference_parameters(scene):
    """The keyword arguments of :func:`dem_reference.dem_impact` for ``scene``'s
    material and law (see the module docstring)."""
    if scene.gravity != 0.0:
        raise ValueError(f"gravity = {scene.gravity}: the DEM oracle has none (use 0)")
    inertia = np.asarray(scene.inertia, float)
    if not np.allclose(inertia, inertia[0], rtol=1e-12, atol=0.0):
        raise ValueError(f"inertia {tuple(inertia)} is not isotropic")
    damping = getattr(scene, "normal_damping", None) or "hunt_crossley"
    restitution = getattr(scene, "restitution", None)
    if damping == "hunt_crossley" and restitution is not None:
        chi = hunt_crossley_chi(restitution)
    else:
        chi = 1.5 * (1.0 - scene.c_tau) if scene.c_tau is not None else 0.0
    return dict(mass=scene.mass + scene.observer_mass, radius=scene.radius,
                inertia=float(inertia[0]), k0=scene.hertz_stiffness,
                kappa=scene.tangential_stiffness_ratio, mu=scene.friction_coefficient,
                normal_damping=damping, chi=chi,
                gamma=getattr(scene, "damping_ratio", None) or 0.0,
                gamma_t=getattr(scene, "tangential_damping_ratio", None) or 0.0)


def _rebound(velocity, angular_velocity, radius):
    """(centre velocity, contact-point velocity v + omega x (0, 0, -R)) in m/s."""
    v, w = np.asarray(velocity, float), np.asarray(angular_velocity, float)
    return v, v + np.cross(w, [0.0, 0.0, -radius])


def compare(scene_kwargs_list, rel_tol=1e-5, **reference_options):
    """Per impact: max |ballc - reference| of the rebound centre and contact-point
    velocities / impact speed (1), as an array.  The reference is converged to
    ``rel_tol`` of the impact speed (dem_impact_converged, which gets
    ``reference_options``, e.g. midpoint_stiffness=True)."""
    import ballc
    errors = []
    for kwargs in scene_kwargs_list:
        scene = ballc.Scene(**kwargs)
        v_in, w_in = scene.velocity, scene.angular_velocity
        if scene.tangential_model != "compliant":
            raise ValueError(f"tangential_model {scene.tangential_model!r}: the oracle "
                             "is the compliant law's")
        hit = ballc.impact(scene, v_in, w_in)
        ref = dem_impact_converged(**reference_parameters(scene), velocity=v_in,
                                   angular_velocity=w_in, rel_tol=rel_tol,
                                   **reference_options)
        ours = _rebound(hit.velocity_after, hit.angular_velocity_after, scene.radius)
        theirs = _rebound(ref["velocity_after"], ref["angular_velocity_after"],
                          scene.radius)
        diff = max(np.abs(a - b).max() for a, b in zip(ours, theirs))
        errors.append(diff / np.linalg.norm(v_in))
    return np.array(errors)


def random_impacts(n, seed, speed=3.9):
    """``n`` random 3-D oblique spinning impacts on the floor, as dicts of Scene fields:
    the Al oxide sphere of validation/cases.py (R 2.5 mm, 4000 kg/m^3, E 3.8e11 Pa,
    nu 0.23, rigid plane 1e9 E, no observer, no gravity), c_tau 1 (no damping),
    kappa 0.1..1.2, mu 0.05..1.5, |v| = ``speed`` (m/s) at 5..85 deg from the normal in
    a random azimuth, spin |omega| R in 0..2 |v| about a uniformly random axis."""
    rng = np.random.default_rng(seed)
    r, rho, E, nu = (AL_OXIDE[k] for k in ("radius", "density", "youngs", "poisson"))
    impacts = []
    for _ in range(n):
        theta, phi = np.radians(rng.uniform(5.0, 85.0)), rng.uniform(0.0, 2 * np.pi)
        v = speed * np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                              -np.cos(theta)])
        axis = rng.normal(size=3)
        w = axis / np.linalg.norm(axis) * rng.uniform(0.0, 2.0) * speed / r
        impacts.append(dict(
            mass=4.0 / 3.0 * math.pi * r ** 3 * rho, radius=r, observer_mass=0.0,
            gravity=0.0, ceiling_height=10 * r, position=(0.0, 0.0, 5 * r),
            ball_youngs_modulus=E, ball_poisson_ratio=nu, plane_youngs_modulus=1e9 * E,
            plane_poisson_ratio=nu, c_tau=1.0, tangential_model="compliant",
            tangential_stiffness_ratio=float(rng.uniform(0.1, 1.2)),
            friction_coefficient=float(rng.uniform(0.05, 1.5)),
            velocity=tuple(float(c) for c in v),
            angular_velocity=tuple(float(c) for c in w)))
    return impacts


if __name__ == "__main__":
    import sys
    args = [int(a) for a in sys.argv[1:]]
    n, seed = (args + [20, 0][len(args):])[:2]
    errors = compare(random_impacts(n, seed))
    for i, err in enumerate(errors):
        print(f"impact {i:3d}: max |ballc - DEM| / |v| = {err:.3e}")
    print(f"worst {errors.max():.3e}, median {np.median(errors):.3e}")
