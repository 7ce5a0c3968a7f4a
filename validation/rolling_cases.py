"""Test 7 of ``python -m validation``: rolling resistance (issue 31) against closed forms
and against LAMMPS' rolling sds algorithm stepped explicitly.

Rows (one compared quantity each, its error in percent):

* exact model (Ai et al.'s type A with holding), a stiff ball rolling at 1 m/s on a
  floor (mu_r = 0.01): the time and distance to holding against t = v0/a, s = v0^2/(2a),
  a = mu_r g / (1 + I/(m r^2)), solid and hollow; on an incline tan(theta) = 3 mu_r the
  acceleration g (sin(theta) - mu_r cos(theta)) / (1 + I/(m r^2));
* sds model: the small rolling oscillation's period against 2 pi / sqrt(k/(m (1 + I/(m r^2))));
* sds model against LAMMPS' rolling sds (validation/rolling_reference.py in
  validation/dem_reference.py's stepping), random oblique spinning impacts of the Al
  oxide sphere (validation/rolling_agreement.py): the worst rebound difference (centre
  velocity, omega R) in percent of the impact speed, against the issue's 1 %, without a
  dashpot (the same law); with LAMMPS' dashpot, and with twisting, reported: there the
  laws differ (docs/contact_laws.md, "sds").
"""
from __future__ import annotations

import math

import numpy as np

import ballc

G = 9.81
#: The issue's bar for ballc's sds against LAMMPS' algorithm: 1 % of the impact speed.
LAMMPS_BAR = (1.0, "issue 31: 1 % of the impact speed")
#: Closed forms: the integration's tolerance, not a physics bar.
CLOSED_FORM = (1e-4, "closed form, rtol 1e-9 run: 1e-4 %")


def stiff_scene(**changes):
    """A stiff ball (steel-like moduli), radius 0.1 m, 1 kg, no observer, rolling
    resistance 0.01, at its static Hertz equilibrium on the floor: the normal force is
    m g from the start (``changes``: Scene fields)."""
    fields = dict(tangential_model="friction", observer_mass=0.0, radius=0.1, mass=1.0,
                  ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, c_tau=0.5,
                  friction_coefficient=0.5, rolling_resistance=0.01, position=(0, 0, 0.1),
                  velocity=(0.0, 0.0, 0.0))
    fields.update(changes)
    scene = ballc.Scene(**fields)
    return scene.replace(position=(0.0, 0.0, scene.radius
                                   - ballc.resting.equilibrium_penetration(scene)))


def _percent(sim, ref):
    return 100.0 * abs(sim - ref) / abs(ref)


def test7_rolling_resistance():
    from .cases import Row, _plt
    from .rolling_agreement import compare, random_impacts
    S = ballc._core.STATE_INDEX
    rows = []
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), constrained_layout=True)
    # exact model on a floor: the stop
    for name, ratio in (("solid", 0.4), ("hollow", 2 / 3)):
        v0, mu_r, r = 1.0, 0.01, 0.1
        scene = stiff_scene(inertia=(ratio * r * r,) * 3, velocity=(v0, 0, 0),
                       angular_velocity=(0, v0 / r, 0))
        a = mu_r * G / (1 + ratio)
        result = ballc.simulate(scene, 1.5 * v0 / a, rtol=1e-9, atol=1e-10)
        log = result.segments
        held = log[(log["end"] == "roll_stop") & (log["rolling_after"][:, 0] == "holding")]
        t = held["t_end"][0]
        x = result.y[S["x"], np.searchsorted(result.t, t)]
        rows.append(Row("7 rolling resistance", f"exact, {name}: time to holding",
                        "exact", _percent(t, v0 / a), *CLOSED_FORM))
        rows.append(Row("7 rolling resistance", f"exact, {name}: distance to holding",
                        "exact", _percent(x, v0 ** 2 / (2 * a)), *CLOSED_FORM))
        axes[0].plot(result.t, result.y[S["vx"]], label=f"ballc exact, {name}")
        axes[0].plot([0, v0 / a], [v0, 0], "k:", lw=1)
    axes[0].set(xlabel="t (s)", ylabel="v_x (m/s)",
                title="rolling at 1 m/s, mu_r = 0.01 (dotted: closed form)")
    # exact model on an incline (gravity turned by theta)
    mu_r = 0.02
    theta = math.atan(3 * mu_r)
    scene = stiff_scene(rolling_resistance=mu_r)
    params = scene.parameter_vector()
    names = ballc._core.PARAMETER_NAMES
    params[[names.index(f"gravity_{k}") for k in "xyz"]] = \
        G * np.array([math.sin(theta), 0.0, -math.cos(theta)])
    params.flags.writeable = False
    scene.__dict__["_parameters"] = params
    result = ballc.simulate(scene, 1.0, rtol=1e-9, atol=1e-10, rest=False, exact_flight=False)
    later = result.t > 0.2
    slope = np.polyfit(result.t[later], result.y[S["vx"], later], 1)[0]
    rows.append(Row("7 rolling resistance", "exact, incline tan = 3 mu_r: acceleration",
                    "exact", _percent(slope, G * (math.sin(theta) - mu_r * math.cos(theta))
                                      / 1.4), *CLOSED_FORM))
    # sds: the small oscillation
    k = 100.0
    scene = stiff_scene(rolling_model="sds", rolling_resistance=0.1, rolling_stiffness=k,
                   rolling_damping=0.0, velocity=(1e-3, 0, 0), angular_velocity=(0, 1e-2, 0))
    result = ballc.simulate(scene, 3.0, rtol=1e-10, atol=1e-12, rest=False)
    vx = result.y[S["vx"]]
    i = np.flatnonzero(np.sign(vx[1:]) * np.sign(vx[:-1]) < 0)
    crossings = result.t[i] - vx[i] * (result.t[i + 1] - result.t[i]) / (vx[i + 1] - vx[i])
    period = 2 * np.mean(np.diff(crossings))
    rows.append(Row("7 rolling resistance", "sds: small rolling oscillation's period",
                    "sds", _percent(period, 2 * math.pi / math.sqrt(k / 1.4)), *CLOSED_FORM))
    # sds against LAMMPS' algorithm
    worst = {}
    for label, damping, twisting in (("no dashpot", 0.0, False),
                                     ("dashpot 0.3 critical", 0.3, False),
                                     ("twisting, no dashpot", 0.0, True)):
        impacts = random_impacts(20, 7, damping)
        if not twisting:
            impacts = [dict(i, twisting_resistance=0.0) for i in impacts]
        errors = 100 * compare(impacts)
        worst[label] = errors
        axes[1].plot(np.sort(errors), np.linspace(0, 1, errors.size), "o-", ms=3, label=label)
        curve = f"sds vs LAMMPS rolling sds, {label}: worst rebound difference"
        note = f"median {np.median(errors):.2g} %"
        if label == "no dashpot":
            rows.append(Row("7 rolling resistance", curve, "sds", float(errors.max()),
                            *LAMMPS_BAR, note=note))
        else:
            why = ("ballc's sds caps the spring and fits the dashpot in the capacity it "
                   "leaves (passive); LAMMPS rescales the spring so that spring + dashpot "
                   "sit at the cap, storing energy from nothing where the dashpot alone "
                   "exceeds it" if damping else
                   "LAMMPS' twisting rescale sets the spring along the twist velocity "
                   "(Marshall's -mu F_n sign(omega_n)); ballc's twisting slider is its "
                   "rolling one in 1 D")
            rows.append(Row("7 rolling resistance", curve, "sds", float(errors.max()),
                            math.nan, "reported, not scored", status="REPORT",
                            note=f"{note}; {why}"))
    axes[1].axvline(1.0, color="k", ls=":", lw=1)
    axes[1].set(xscale="log", xlabel="|ballc - LAMMPS| / |v| (%)", ylabel="fraction of impacts",
                title="20 random oblique spinning impacts (Al oxide, 3.9 m/s)")
    axes[2].axis("off")
    text = "\n".join(f"{r.curve[:60]}\n    {r.error:.3g} %  {r.status}" for r in rows)
    axes[2].text(0, 1, text, va="top", family="monospace", fontsize=7)
    for ax in axes[:2]:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Test 7: rolling resistance (issue 31)")
    return rows, fig
