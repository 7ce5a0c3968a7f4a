"""The Chung & Ooi (2011) sphere-on-rigid-plane tests, run with ballc.

Each test function returns (rows, figure): rows are :class:`Row` (one compared curve
each: error, threshold, pass/fail), the figure draws ballc against the references.

Parameter mapping (every test): the sphere's E, nu -> ``ball_youngs_modulus``,
``ball_poisson_ratio``; the rigid plane -> ``plane_youngs_modulus`` = 1e9 E (Kratos uses
7e20 Pa, Yade 1000 E: any value >> E gives the same E*), ``plane_poisson_ratio`` = the
sphere's; mass = 4/3 pi R^3 rho, inertia 2/5 m R^2, no observer (``observer_mass`` 0),
no gravity (as in the DEM codes' runs); the restitution e -> ``Scene.restitution``
(Hunt-Crossley's chi inverted exactly, ballc.restitution); mu ->
``friction_coefficient``; the tangential stiffness kappa = 4 G*/E* -> the default
``tangential_stiffness_ratio`` (Mindlin's, from the moduli and Poisson ratios; for a
rigid plane 2 (1 - nu) / (2 - nu)).  Tangential models: "compliant" (Mindlin-type spring
with Coulomb cap) wherever tangential behaviour is tested, and "friction" (exact
Coulomb stick/slip, no tangential compliance) for the sliding regimes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import ballc

from . import reference as ref


@dataclass
class Row:
    test: str
    curve: str
    model: str
    error: float          # 100 sum|sim - ref| / sum|ref|, percent
    threshold: float      # percent
    source: str           # which threshold
    status: str = ""      # "pass", "FAIL", or "LIMIT" (not representable, reported)
    note: str = ""
    strict: tuple | None = None   # (threshold %, source): a stricter reading, reported only

    def __post_init__(self):
        if self.status == "REPORT":
            return
        if not self.status:
            self.status = "pass" if self.error <= self.threshold else "FAIL"
        if self.strict is not None:
            verdict = "meets" if self.error <= self.strict[0] else "does NOT meet"
            extra = f"{verdict} {self.strict[1]} (= {self.strict[0]:g} % if a fraction)"
            self.note = f"{self.note}; {extra}" if self.note else extra


def relative_error(sim, reference):
    """The DEM benchmarks' measure: 100 sum|sim - ref| / sum|ref| (percent)."""
    sim, reference = np.asarray(sim, float), np.asarray(reference, float)
    return 100.0 * np.sum(np.abs(sim - reference)) / np.sum(np.abs(reference))


def material(radius, density, youngs, poisson, restitution=1.0, mu=0.0,
             model="compliant", **extra):
    """A ballc Scene for a sphere hitting a rigid plane (see the module docstring)."""
    mass = 4.0 / 3.0 * math.pi * radius ** 3 * density
    return ballc.Scene(
        mass=mass, radius=radius, observer_mass=0.0, gravity=0.0,
        ceiling_height=10 * radius, position=(0.0, 0.0, 5 * radius),
        velocity=(0.0, 0.0, -1.0), ball_youngs_modulus=youngs, ball_poisson_ratio=poisson,
        plane_youngs_modulus=1e9 * youngs, plane_poisson_ratio=poisson,
        restitution=restitution, friction_coefficient=mu,
        tangential_model=model, **extra)


# Kratos's thresholds.  KRATOS_CLASS: Chung_Ooi_class.py (python_scripts, commit
# 6022a0af), "error < 10.0" percent for every benchmark.  The unit tests
# tests/DEM3D_chung_ooi_tests/test*_data/Chung_Ooi_test_*.py use assertAlmostEqual(error,
# 0, delta=...) with COC.ComputeRelativeError, whose definition is not in the stored copy
# (not found); read as a fraction of the same measure, the deltas are the percentages below.
KRATOS_CLASS = (10.0, "Kratos Chung_Ooi_class")
KRATOS_TEST2 = {"force_time": (0.33, "Kratos test 2: delta 3.3e-3"),
                "force_overlap": (0.30, "Kratos test 2: delta 3e-3")}
KRATOS_TEST4 = {"restitution": (1.6, "Kratos test 4: delta 1.6e-2"),
                "spin": (2.2, "Kratos test 4: delta 2.2e-2"),
                "angle": (2.5, "Kratos test 4: delta 2.5e-2")}


#: The issue's bar for the compliant law against the DEM codes' algorithm run on the same
#: inputs (validation/dem_reference.py): 2 % in Kratos's measure.
DEM_ALGORITHM = (2.0, "DEM algorithm, same law: <= 2 %")


class ReferenceImpact:
    """validation/dem_reference.py's explicit DEM stepping of the compliant law, with
    the attributes of ballc.Impact the tests read (velocity_after,
    angular_velocity_after, contact_velocity_after, e_t)."""

    def __init__(self, scene, velocity, angular_velocity=(0.0, 0.0, 0.0)):
        from .dem_agreement import reference_parameters
        from .dem_reference import dem_impact_converged
        out = dem_impact_converged(**reference_parameters(scene), velocity=velocity,
                                   angular_velocity=angular_velocity, rel_tol=1e-4)
        self.velocity_after = np.asarray(out["velocity_after"])
        self.angular_velocity_after = np.asarray(out["angular_velocity_after"])
        arm = np.array([0.0, 0.0, -scene.radius])
        self.contact_velocity_after = self.velocity_after + np.cross(
            self.angular_velocity_after, arm)
        before = np.asarray(velocity, float) + np.cross(np.asarray(angular_velocity, float),
                                                        arm)
        u, u_after = before[:2], self.contact_velocity_after[:2]
        self.e_t = -float(u_after @ u) / float(u @ u)      # as ballc.Impact.e_t


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


# ----------------------------------------------------------------------------- test 2
def hertz_reference(scene, speed, times):
    """Hertz's elastic impact integrated independently (scipy DOP853, rtol 1e-12):
    m rho'' = -k0 rho^(3/2), rho(0) = 0, rho'(0) = speed.  Returns (rho, force) at
    ``times`` (s) after first touch (0 after the contact)."""
    from scipy.integrate import solve_ivp
    k0, m = scene.hertz_stiffness, scene.mass

    def rhs(t, y):
        return [y[1], -k0 * max(y[0], 0.0) ** 1.5 / m]
    leave = lambda t, y: y[0] if t > 0 else 1.0  # noqa: E731
    leave.terminal, leave.direction = True, -1
    from ballc.impact import hertz_contact_time
    sol = solve_ivp(rhs, (0, 10 * hertz_contact_time(scene, speed)),
                    [0.0, speed], method="DOP853", rtol=1e-12, atol=1e-20, dense_output=True,
                    events=leave)
    t_c = sol.t_events[0][0]
    rho = np.where((times >= 0) & (times <= t_c), sol.sol(np.clip(times, 0, t_c))[0], 0.0)
    rho = np.maximum(rho, 0.0)
    return rho, k0 * rho ** 1.5, t_c


def test2_elastic_normal():
    """Elastic normal impact of a sphere with a rigid plane: force-time and
    force-overlap against the paper's (Hertz) curves and Hertz integrated here."""
    speed = 0.2
    scene = material(0.1, 2699.0, 7.0e10, 0.30, restitution=1.0, mu=0.0, model="friction")
    hit = ballc.impact(scene, (0.0, 0.0, -speed))
    t0 = hit.result.contacts[0].t_start
    # sample the same trajectory at the reference times (simulate with t_eval)
    start_scene = scene.replace(position=tuple(hit.result.position[:, 0]),
                                velocity=tuple(hit.result.velocity[:, 0]))
    t_ref = ref.TEST2_FORCE_TIME[:, 0] * 1e-6
    dense = np.linspace(0, hit.duration, 400)
    t_eval = np.unique(np.concatenate([t0 + np.clip(t_ref, 0, hit.duration), t0 + dense]))
    run = ballc.simulate(start_scene, t0 + hit.duration * 1.01, t_eval=t_eval, rtol=1e-10,
                         atol=1e-10 * hit.max_penetration)
    rho_of = lambda t: np.interp(t, run.t - t0, np.maximum(scene.radius - run.position[2], 0))  # noqa: E731
    k0 = scene.hertz_stiffness
    force_sim = k0 * rho_of(t_ref) ** 1.5 / 1e3                        # kN
    err_ft = relative_error(force_sim, ref.TEST2_FORCE_TIME[:, 1])
    rho_h, f_h, t_c = hertz_reference(scene, speed, t_ref)
    err_hertz = relative_error(force_sim, f_h / 1e3)
    # force-overlap: ballc's force at the reference overlaps (loading branch)
    overlap = ref.TEST2_FORCE_OVERLAP[:, 0] * 1e-6
    force_ov = k0 * overlap ** 1.5 / 1e3
    err_fo = relative_error(force_ov, ref.TEST2_FORCE_OVERLAP[:, 1])
    # and the whole force-overlap path of the simulation against Hertz's law
    rho_run = np.maximum(scene.radius - run.position[2], 0)
    rows = [
        Row("2 elastic normal", "force-time vs paper (Kratos ref.)", "(normal only)", err_ft,
            *KRATOS_CLASS, strict=KRATOS_TEST2["force_time"]),
        Row("2 elastic normal", "force-time vs Hertz (scipy)", "(normal only)", err_hertz,
            0.01, "ballc: 0.01 % (analytical curve)"),
        Row("2 elastic normal", "force-overlap vs paper (Kratos ref.)", "(normal only)",
            err_fo, *KRATOS_CLASS, strict=KRATOS_TEST2["force_overlap"],
            note="ballc's force is Hertz's to 1e-9: this is the digitised points' scatter"),
        Row("2 elastic normal", "contact time vs Hertz", "(normal only)",
            100 * abs(hit.duration - t_c) / t_c, 0.01, "ballc: 0.01 % (analytical)",
            note=f"t_c = {hit.duration * 1e6:.2f} us, Hertz {t_c * 1e6:.2f} us"),
    ]
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    td = dense
    a1.plot(td * 1e6, k0 * rho_of(td) ** 1.5 / 1e3, "-", label="ballc")
    a1.plot(*ref.TEST2_FORCE_TIME.T, "o", mfc="none", label="Chung & Ooi (Kratos data)")
    a1.plot(td * 1e6, hertz_reference(scene, speed, td)[1] / 1e3, "k:", label="Hertz (scipy)")
    a1.set(xlabel="time (us)", ylabel="normal force (kN)",
           title=f"Test 2: force-time (error {err_ft:.2f} %)")
    a2.plot(rho_run * 1e6, k0 * rho_run ** 1.5 / 1e3, "-", label="ballc (whole path)")
    a2.plot(*ref.TEST2_FORCE_OVERLAP.T, "o", mfc="none", label="Chung & Ooi (Kratos data)")
    a2.set(xlabel="overlap (um)", ylabel="normal force (kN)",
           title=f"Test 2: force-overlap (error {err_fo:.2f} %)")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend()
    fig.suptitle("Al alloy sphere R = 0.1 m, 0.2 m/s, rigid plane, E = 70 GPa, nu = 0.3")
    return rows, fig


# ----------------------------------------------------------------------------- test 3
def test3_restitution():
    """Normal impact with damping: output restitution against input restitution."""
    e_in = np.array([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])    # Kratos test 3's inputs
    lowest = 0.0     # Scene.restitution inverts Hunt-Crossley exactly for any e > 0
    ok = e_in > lowest
    e_out = np.full(e_in.shape, np.nan)
    fine = np.linspace(0.05, 1.0, 20)
    e_fine = []
    for values, out in ((e_in[ok], None), (fine, e_fine)):
        for i, e in enumerate(values):
            scene = material(0.0025, 4000.0, 3.8e11, 0.23, restitution=e, model="friction")
            measured = ballc.impact(scene, (0.0, 0.0, -3.9)).e_n
            if out is None:
                e_out[np.flatnonzero(ok)[i]] = measured
            else:
                out.append(measured)
    err = relative_error(e_out[ok], e_in[ok])
    worst = np.nanmax(np.abs(e_out - e_in))
    rows = [Row("3 restitution", f"e_out vs e_in at e_in = {', '.join(f'{e:g}' for e in e_in[ok])}", "(normal only)",
                err, 0.1, "Kratos test 3: |e_out - e_in| <= 1e-3",
                note=f"max |e_out - e_in| = {worst:.1e}"),
            Row("3 restitution", f"e_in = {', '.join(f'{e:g}' for e in e_in[~ok])}", "(normal only)", math.nan,
                math.nan, "-", status="LIMIT",
                note="the family's limit: e -> 0 is chi -> infinity (Hunt-Crossley) and "
                     "gamma -> infinity (viscoelastic), never reached")]
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    ax.plot([0, 1], [0, 1], "k:", label="reference: e_out = e_in (Chung & Ooi)")
    ax.plot(fine, e_fine, "-", label="ballc (Scene.restitution)")
    ax.plot(e_in[ok], e_out[ok], "o", label="ballc at Kratos's inputs")
    ax.set(xlabel="input restitution", ylabel="output restitution -v_n'/v_n",
           title=f"Test 3: Al oxide, 3.9 m/s (error {err:.2g} %)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    return rows, fig


# ----------------------------------------------------------------------------- test 4
def _test4_run(model, impact=ballc.impact):
    scene = material(0.0025, 4000.0, 3.8e11, 0.23, restitution=0.98, mu=0.092, model=model)
    angles = np.arange(5.0, 86.0, 5.0)
    out = {"angle": angles, "restitution": [], "spin": [], "rebound": []}
    for angle in angles:
        th = math.radians(angle)
        hit = impact(scene, (3.9 * math.sin(th), 0.0, -3.9 * math.cos(th)))
        v, w = hit.velocity_after, hit.angular_velocity_after
        out["restitution"].append(v[0] / (3.9 * math.sin(th)))
        out["spin"].append(-w[1])                              # Kratos's sign
        u = v[0] - scene.radius * w[1]
        out["rebound"].append(math.degrees(math.atan(u / v[2])))
    return {k: np.asarray(v) for k, v in out.items()}


def test4_oblique_constant_speed():
    """Oblique impacts at constant speed 3.9 m/s and incident angle 5..85 degrees."""
    curves = (("restitution", "v_t'/v_t", ref.TEST4_TANGENTIAL_RESTITUTION),
              ("spin", "angular velocity", ref.TEST4_ANGULAR_VELOCITY),
              ("angle", "rebound angle", ref.TEST4_REBOUND_ANGLE))
    runs = {m: _test4_run(m) for m in ("compliant", "friction")}
    dem = _test4_run("compliant", ReferenceImpact)
    rows = []
    for key, label, _ in curves:
        series = "rebound" if key == "angle" else key
        rows.append(Row("4 oblique, |v| const", label + " vs DEM algorithm", "compliant",
                        relative_error(runs["compliant"][series], dem[series]),
                        *DEM_ALGORITHM))
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), constrained_layout=True)
    for (key, label, data), ax in zip(curves, axes):
        x_ref = np.round(data[:, 0])
        for model, run in runs.items():
            series = run["rebound" if key == "angle" else key]
            sim = np.interp(x_ref, run["angle"], series)
            err = relative_error(sim, data[:, 1])
            if model == "compliant":
                rows.append(Row("4 oblique, |v| const", label, model, err, *KRATOS_CLASS,
                                strict=KRATOS_TEST4[key]))
            else:
                # friction has no tangential compliance: compare the gross-sliding regime
                # (incident angle above the rolling limit tan = 3.5 mu (1 + e) = 0.64)
                sliding = x_ref >= 35
                err_s = relative_error(sim[sliding], data[sliding, 1])
                rows.append(Row("4 oblique, |v| const", label + " (sliding, >= 35 deg)",
                                model, err_s, *KRATOS_CLASS, strict=KRATOS_TEST4[key],
                                note=f"all angles: {err:.1f} %"))
            ax.plot(run["angle"], series, "-" if model == "compliant" else "--",
                    label=f"ballc {model}")
        ax.plot(*data.T, "o", mfc="none", color="k", label="Chung & Ooi (Kratos ref.)")
        if key == "angle":
            ax.plot(*ref.TEST4_REBOUND_ANGLE_EXPERIMENT.T, "x", color="r",
                    label="experiment (Kharaz et al.)")
        ax.set(xlabel="incident angle from the normal (deg)", ylabel=label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Test 4: Al oxide sphere R = 2.5 mm, 3.9 m/s, e = 0.98, mu = 0.092")
    return rows, fig


#: Why the compliant rows of tests 5 and 6 against the paper's curves are reported, not
#: scored: an independent explicit DEM stepping of the same passive incremental law with
#: Mindlin's kappa = 2(1-nu)/(2-nu) misses the test-5 steel curves by 48 % and 21 %, as
#: ballc does; with kappa ~ 0.3 it fits them within 4 %: the paper's curves do not assume
#: Mindlin's kappa (and test 6's need DEM-style viscous damping in both directions).
#: ballc's defaults are not tuned to them (docs/contact_laws.md).
PAPER_KAPPA_NOTE = ("reported, not scored: the paper's curve assumes another tangential "
                    "stiffness than Mindlin's kappa (a DEM stepping of this law with "
                    "Mindlin's kappa misses it alike)")


# ----------------------------------------------------------------------------- test 5
# Kratos uses R = 1e-5 m.  The normalised results do not depend on R (Hertz contact, e = 1:
# self-similar; checked: R = 1e-5 and 1e-3 agree to 1e-9 with the compliant model), but
# ballc's exact-Coulomb stick/slip ("friction") does not settle for R = 1e-5 m at
# V_t/(mu V_n) = 3 (100000 mode changes; see docs/validation.md), so ballc runs R = 1 mm.
TEST5_RADIUS = 1e-3


def _test5_run(model, xs, impact=ballc.impact):
    mu, vn = 0.3, 5.0
    scene = material(TEST5_RADIUS, 7850.0, 2.08e11, 0.30, restitution=1.0, mu=mu, model=model)
    recoil, spin = [], []
    for x in xs:
        hit = impact(scene, (x * mu * vn, 0.0, -vn))
        v, w = hit.velocity_after, hit.angular_velocity_after
        u = v[0] - scene.radius * w[1]
        recoil.append(u / (mu * v[2]))
        spin.append(-scene.radius * w[1] / (mu * vn))
    return np.array(recoil), np.array(spin)


def test5_tangential_velocity():
    """Constant normal velocity, varying tangential velocity: normalised recoil angle
    and spin against normalised incident angle."""
    curves = (("normalised recoil angle u'/(mu V_n')", ref.TEST5_RECOIL, 0),
              ("normalised spin r w'/(mu V_n)", ref.TEST5_SPIN, 1))
    fine = np.linspace(0.05, 14, 60)
    runs_fine = {m: _test5_run(m, fine) for m in ("compliant", "friction")}
    rows = []
    xs = ref.TEST5_RECOIL[:, 0]
    ours, dem = _test5_run("compliant", xs), _test5_run("compliant", xs, ReferenceImpact)
    for i, label in enumerate(("normalised recoil angle", "normalised spin")):
        rows.append(Row("5 varying V_t", label + " vs DEM algorithm", "compliant",
                        relative_error(ours[i], dem[i]), *DEM_ALGORITHM))
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
    for (label, data, k), ax in zip(curves, axes):
        for model in ("compliant", "friction"):
            sim = _test5_run(model, data[:, 0])[k]
            if model == "compliant":
                rows.append(Row("5 varying V_t", label, model, relative_error(sim, data[:, 1]),
                                *KRATOS_CLASS, status="REPORT", note=PAPER_KAPPA_NOTE))
            else:
                sliding = data[:, 0] >= 7.0    # rigid gross sliding: V_t >= 3.5 mu (1+e) V_n
                rows.append(Row("5 varying V_t", label + " (sliding, x >= 7)", model,
                                relative_error(sim[sliding], data[sliding, 1]),
                                *KRATOS_CLASS,
                                note=f"all x: {relative_error(sim, data[:, 1]):.1f} %"))
            ax.plot(fine, runs_fine[model][k], "-" if model == "compliant" else "--",
                    label=f"ballc {model}")
        ax.plot(*data.T, "o", mfc="none", color="k", label="Chung & Ooi steel (Kratos data)")
        if k == 0:
            ax.plot(*ref.TEST5_RECOIL_FEM.T, "s", mfc="none", color="0.5", ms=4,
                    label="FEM (in the paper)")
            fem = ref.TEST5_RECOIL_FEM
            sliding = fem[:, 0] >= 7.0
            sim = _test5_run("compliant", fem[sliding, 0])[0]
            rows.append(Row("5 varying V_t", label + " vs FEM, sliding (Kratos's check)",
                            "compliant", relative_error(sim, fem[sliding, 1]), *KRATOS_CLASS))
        ax.set(xlabel="normalised incident angle V_t/(mu V_n)", ylabel=label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Test 5: steel sphere, V_n = 5 m/s, e = 1, mu = 0.3, nu = 0.3")
    return rows, fig


# ----------------------------------------------------------------------------- test 6
def _test6_run(model, tangents, impact=ballc.impact):
    mu, e, vn, r = 0.4, 0.5, 0.2, 0.1
    scene = material(r, 2700.0, 7.0e10, 0.33, restitution=e, mu=mu, model=model)
    beta, recoil = [], []
    for tan_in in tangents:
        u = vn * tan_in                                 # contact-point speed, from spin only
        hit = impact(scene, (0.0, 0.0, -vn), (0.0, -u / r, 0.0))
        beta.append(hit.e_t)
        recoil.append(hit.contact_velocity_after[0] / hit.velocity_after[2])
    return np.array(beta), np.array(recoil)


def test6_spin_only():
    """Impacts with incident spin only: contact-point tangential restitution and recoil
    angle against the incident angle (x = 3.5 mu (1 + e) V_n / u)."""
    k = 3.5 * 0.4 * 1.5                                 # 3.5 mu (1 + e)
    rows = []
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
    beta_ref, recoil_ref = ref.TEST6_BETA, ref.TEST6_RECOIL
    fine_tan = np.geomspace(0.06, 12, 60)
    fine = {m: _test6_run(m, fine_tan) for m in ("compliant", "friction")}
    tangents = recoil_ref[:, 0]
    ours, dem = _test6_run("compliant", tangents), _test6_run("compliant", tangents,
                                                               ReferenceImpact)
    for i, label in enumerate(("beta = -u'/u", "tan recoil angle")):
        rows.append(Row("6 spin only", label + " vs DEM algorithm", "compliant",
                        relative_error(ours[i], dem[i]), *DEM_ALGORITHM))
    for model in ("compliant", "friction"):
        beta = _test6_run(model, k / beta_ref[:, 0])[0]
        recoil = _test6_run(model, recoil_ref[:, 0])[1]
        if model == "compliant":
            rows.append(Row("6 spin only", "beta = -u'/u", model,
                            relative_error(beta, beta_ref[:, 1]), *KRATOS_CLASS,
                            status="REPORT", note=PAPER_KAPPA_NOTE))
            rows.append(Row("6 spin only", "tan recoil angle", model,
                            relative_error(recoil, recoil_ref[:, 1]), *KRATOS_CLASS,
                            status="REPORT", note=PAPER_KAPPA_NOTE))
        else:
            s1, s2 = beta_ref[:, 0] <= 1.0, recoil_ref[:, 0] >= k
            rows.append(Row("6 spin only", "beta (sliding, x <= 1)", model,
                            relative_error(beta[s1], beta_ref[s1, 1]), *KRATOS_CLASS,
                            note=f"all x: {relative_error(beta, beta_ref[:, 1]):.0f} %"))
            rows.append(Row("6 spin only", "tan recoil angle (sliding, tan >= 2.1)", model,
                            relative_error(recoil[s2], recoil_ref[s2, 1]), *KRATOS_CLASS,
                            note=f"all: {relative_error(recoil, recoil_ref[:, 1]):.0f} %"))
        style = "-" if model == "compliant" else "--"
        axes[0].plot(k / fine_tan, fine[model][0], style, label=f"ballc {model}")
        axes[1].plot(fine_tan, fine[model][1], style, label=f"ballc {model}")
    axes[0].plot(*beta_ref.T, "o", mfc="none", color="k", label="Chung & Ooi Al alloy (Kratos data)")
    axes[1].plot(*recoil_ref.T, "o", mfc="none", color="k", label="Chung & Ooi Al alloy (Kratos data)")
    axes[0].set(xscale="log", xlabel="3.5 mu (1 + e) V_n / u", ylabel="beta = -u'/u")
    axes[1].set(xlabel="tan(incident angle) = u / V_n", ylabel="tan(recoil angle) = u'/V_n'")
    for a in axes:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle("Test 6: Al alloy sphere R = 0.1 m, V_n = 0.2 m/s, spin only, e = 0.5, mu = 0.4")
    return rows, fig


def test7_rolling_resistance():
    """Rolling resistance (issue 31): validation/rolling_cases.py."""
    from .rolling_cases import test7_rolling_resistance as test
    return test()


TESTS = {"2": test2_elastic_normal, "3": test3_restitution, "4": test4_oblique_constant_speed,
         "5": test5_tangential_velocity, "6": test6_spin_only, "7": test7_rolling_resistance}
