"""ballc.impact / impact_table / fit_impacts / c_tau_for_restitution, and the
Chung & Ooi validation (slow)."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import ballc
from ballc import SceneError

ROOT = Path(__file__).resolve().parents[1]


def steel(**changes):
    """A 10 mm steel ball on a steel floor (contact ~35 us: cheap impacts)."""
    r = 0.005
    values = dict(mass=4 / 3 * math.pi * r ** 3 * 7850, radius=r, observer_mass=0.0,
                  ball_youngs_modulus=2.1e11, ball_poisson_ratio=0.3,
                  plane_youngs_modulus=2.1e11, plane_poisson_ratio=0.3, c_tau=0.9,
                  friction_coefficient=0.3, tangential_model="compliant",
                  ceiling_height=0.1, position=(0.0, 0.0, 0.05))
    values.update(changes)
    return ballc.Scene(**values)


@pytest.mark.parametrize("model", ["compliant", "friction"])
@pytest.mark.parametrize("plane", ["floor", "ceiling"])
def test_impact_agrees_with_a_full_throw(model, plane):
    """A thrown ball (gravity on, spinning) and ballc.impact from the incident state
    of its first contact give the same rebound to 1e-6."""
    scene = steel(tangential_model=model)
    if plane == "floor":
        throw = scene.replace(position=(0.0, 0.0, 0.02), velocity=(0.7, -0.2, -1.0),
                              angular_velocity=(5.0, 30.0, -3.0))
    else:
        throw = scene.replace(position=(0.0, 0.0, 0.08), velocity=(0.7, -0.2, 1.5),
                              angular_velocity=(5.0, 30.0, -3.0))
    result = ballc.simulate(throw, 0.03)
    first = result.contacts[0]
    assert first.plane == plane and np.isfinite(first.t_end)
    hit = ballc.impact(scene, first.velocity_before, first.angular_velocity_before, plane)
    np.testing.assert_allclose(hit.velocity_before, first.velocity_before, rtol=0, atol=1e-6)
    np.testing.assert_allclose(hit.velocity_after, first.velocity_after, rtol=0, atol=1e-6)
    np.testing.assert_allclose(hit.angular_velocity_after, first.angular_velocity_after,
                               rtol=1e-6, atol=1e-6 / scene.radius * 1e-3)
    assert hit.duration == pytest.approx(first.duration, rel=1e-6)
    assert hit.max_penetration == pytest.approx(first.max_penetration, rel=1e-6)


def test_normal_restitution_is_hunt_crossleys():
    for e in (0.6, 0.8, 0.95):
        scene = steel(gravity=0.0, c_tau=ballc.c_tau_for_restitution(e))
        hit = ballc.impact(scene, (0.0, 0.0, -2.0))
        assert hit.e_n == pytest.approx(e, abs=1e-8)
        assert math.isnan(hit.e_t)        # no slip at all: e_t undefined


def test_rigid_limits_of_the_tangential_restitution():
    scene = steel(gravity=0.0, tangential_model="friction", friction_coefficient=0.3)
    # gross sliding: Coulomb's map (rigid_impact), e_t = -(1 - 3.5 mu (1+e) v_n / u)
    v = (3.0, 0.0, -0.5)
    hit = ballc.impact(scene, v)
    rigid = ballc.rigid_impact(v, (0, 0, 0), mass=scene.mass, radius=scene.radius,
                               restitution=hit.e_n, friction_coefficient=0.3)
    np.testing.assert_allclose(hit.velocity_after, rigid.velocity, atol=1e-6)
    # rolling exit: e_t = 0
    assert ballc.impact(scene, (0.3, 0.0, -1.0)).e_t == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("angle, spin", [(75.0, 0.0), (80.0, 0.0), (60.0, -300.0)])
def test_tangential_restitution_in_gross_sliding(angle, spin):
    """Coulomb friction sliding through the whole impact (a solid sphere, no gravity):
    the friction impulse mu (1 + e) m v_n opposes the slip u and changes the contact
    point's velocity 1 + m r^2 / I = 7/2 times as much as the centre's, so
    u' = u (1 - 3.5 mu (1 + e) v_n / |u|) and e_t = -u'.u/|u|^2 = -(1 - 3.5 mu (1+e) v_n/|u|),
    with e = -v_z'/v_z from the velocities (and Hunt-Crossley's root of
    chi (1+e) = ln((1+chi)/(1-chi e)), chi = 3/2 (1 - c_tau))."""
    mu = 0.3
    scene = steel(gravity=0.0, tangential_model="friction", friction_coefficient=mu)
    theta = math.radians(angle)
    hit = ballc.impact(scene, (math.sin(theta), 0.0, -math.cos(theta)), (0.0, spin, 0.0))
    (contact,) = hit.result.contacts
    assert [phase for _, phase in contact.transitions] == ["slip"]     # never sticks
    vb, va, wb = hit.velocity_before, hit.velocity_after, hit.angular_velocity_before
    v_n, e = -vb[2], -va[2] / vb[2]
    chi = 1.5 * (1 - scene.c_tau)
    assert e == pytest.approx(brentq(lambda x: chi * (1 + x) - math.log((1 + chi) / (1 - chi * x)),
                                     0.5, 1.0), abs=1e-8)
    u = math.hypot(vb[0] - scene.radius * wb[1], vb[1] + scene.radius * wb[0])
    assert 3.5 * mu * (1 + e) * v_n < 0.7 * u          # sliding to the end, with margin
    expected = -(1 - 3.5 * mu * (1 + e) * v_n / u)
    assert expected < -0.2                              # far from 0 (rolling) and from +
    assert hit.e_t == pytest.approx(expected, abs=1e-8)


@pytest.mark.parametrize("kwargs, message", [
    (dict(velocity=(1.0, 0.0, 1.0)), "velocity"),             # moving away from the floor
    (dict(velocity=(1.0, 0.0, 0.0)), "velocity"),
    (dict(velocity=(1.0, 0.0)), "velocity"),
    (dict(velocity=(1.0, 0.0, float("nan"))), "velocity"),
    (dict(velocity="abc"), "velocity"),
    (dict(velocity=(0.0, 0.0, -1.0), angular_velocity=(1.0, 2.0)), "angular_velocity"),
    (dict(velocity=(0.0, 0.0, -1.0), angular_velocity=(1.0, float("inf"), 0.0)),
     "angular_velocity"),
    (dict(velocity=(0.0, 0.0, -1.0), plane="wall"), "plane"),
    (dict(velocity=(0.0, 0.0, -1.0), plane="ceiling"), "velocity"),   # ceiling: vz > 0
    (dict(velocity=(0.0, 0.0, -1.0), gap=0.0), "gap"),
    (dict(velocity=(0.0, 0.0, -1.0), gap=2.0), "gap"),
])
def test_impact_rejects_bad_inputs_by_name(kwargs, message):
    with pytest.raises(SceneError, match=message):
        ballc.impact(steel(), **kwargs)


def test_impact_needs_a_scene():
    with pytest.raises(TypeError, match="Scene"):
        ballc.impact({"mass": 1}, (0, 0, -1))


def test_c_tau_for_restitution_inverts_hunt_crossley():
    for c_tau in (0.01, 0.2, 0.5, 0.8, 0.95, 0.999):
        e = ballc.hunt_crossley_restitution(c_tau)
        assert ballc.c_tau_for_restitution(e) == pytest.approx(c_tau, rel=1e-9, abs=1e-9)
    assert ballc.c_tau_for_restitution(1.0) == 1.0
    assert ballc.hunt_crossley_restitution(ballc.c_tau_for_restitution(0.99999)) == \
        pytest.approx(0.99999, abs=1e-8)
    for bad in (0.4, 0.0, -0.1, 1.01, float("nan"), "x"):
        with pytest.raises(ValueError, match="restitution"):
            ballc.c_tau_for_restitution(bad)


def hunt_crossley_restitution_by_integration(scene):
    """Oracle: e of one Hunt-Crossley impact, integrated here with scipy's solve_ivp:
    m x'' = -k0 x^(3/2) (1 + chi x'/v0), chi = 3/2 (1 - c_tau), from x = 0, x' = v0
    (x the penetration) until x returns to 0; e = -x'(end) / v0.  Plain physics, not
    ballc's restitution formula (e depends on c_tau only: any v0 does)."""
    from scipy.integrate import solve_ivp
    m, k0, v0 = scene.mass + scene.observer_mass, scene.hertz_stiffness, 1.0
    chi = 1.5 * (1 - scene.c_tau)
    depth = (1.25 * m * v0 ** 2 / k0) ** 0.4       # Hertz's deepest penetration

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -k0 * x ** 1.5 * (1 + chi * y[1] / v0) / m]

    def out(t, y):
        return y[0]
    out.terminal, out.direction = True, -1
    t_c = 3.3 * depth / v0                          # > the elastic duration 2.94 depth/v0
    sol = solve_ivp(rhs, (0.0, 2 * t_c), [0.0, v0], events=out, rtol=1e-12,
                    atol=[1e-14 * depth, 1e-14 * v0], first_step=1e-6 * t_c)
    assert sol.status == 1 and sol.t_events[0].size == 1
    return -sol.y_events[0][0][1] / v0


def test_impact_table():
    table = ballc.impact_table(steel(gravity=0.0), angles=[0, 30, 60], speed=1.5, spin=10.0)
    assert list(table["angle"]) == [0, 30, 60]
    for column in ("vx", "vz", "wy", "vx_after", "wz_after", "e_n", "e_t", "duration",
                   "max_penetration", "status"):
        assert column in table.columns
    np.testing.assert_allclose(table["vz"], -1.5 * np.cos(np.radians([0, 30, 60])), atol=1e-6)
    assert (table["wy"] == 10.0).all()
    # Rebound values against independent oracles (gravity off, no observer mass).
    scene = steel(gravity=0.0)
    e = hunt_crossley_restitution_by_integration(scene)
    # the integration agrees with the exact relation chi (1 + e) = ln((1 + chi)/(1 - chi e))
    chi = 1.5 * (1 - scene.c_tau)
    assert chi * (1 + e) == pytest.approx(math.log((1 + chi) / (1 - chi * e)), abs=1e-10)
    # The normal motion does not feel the tangential force: vz_after = -e vz in every
    # row, spinning and oblique ones included (measured agreement: 1e-11 relative).
    np.testing.assert_allclose(table["vz_after"], -e * table["vz"], rtol=1e-8)
    np.testing.assert_allclose(table["e_n"], e, rtol=1e-8)
    # Head-on without spin: nothing tangential happens; and gross sliding (the contact
    # point slips at > 1.5 times the rigid rolling threshold 3.5 mu (1 + e) v_n: it
    # slides throughout): the tangential force is mu F_n during the whole contact, so the
    # rigid Coulomb map of a solid sphere holds (written out here, not rigid_impact):
    #   u = vx - r wy (the contact point's velocity on the floor, omega x (-r z)),
    #   delta vx = -mu (1 + e) v_n sign(u)  (impulse mu P_n, P_n = m (1 + e) v_n),
    #   delta wy = -r m delta vx / I = -5/2 delta vx / r  (I = 2/5 m r^2; torque of
    #   the impulse at (-r z): (-r z) x (P x) = -r P y),  vy, wx, wz unchanged (0).
    # Measured agreement of the compliant law there: 4e-12 relative.
    rows = ballc.impact_table(scene, angles=[0, 75, 85], speed=1.5, spin=[0.0, 10.0, -20.0])
    r, mu = scene.radius, scene.friction_coefficient
    inertia = 2 / 5 * scene.mass * r ** 2
    v_n = -rows["vz"].to_numpy()
    u = rows["vx"].to_numpy() - r * rows["wy"].to_numpy()
    head_on, sliding = slice(0, 1), slice(1, 3)
    assert np.all(u[sliding] > 1.5 * 3.5 * mu * (1 + e) * v_n[sliding])   # gross sliding
    assert u[head_on] == 0.0
    dvx = -mu * (1 + e) * v_n * np.sign(u)        # 0 head-on
    dwy = -r * scene.mass * dvx / inertia
    np.testing.assert_allclose(rows["vx_after"], rows["vx"] + dvx, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(rows["wy_after"], rows["wy"] + dwy, rtol=1e-8,
                               atol=1e-9 / r)
    np.testing.assert_allclose(rows["vz_after"], e * v_n, rtol=1e-8)
    for column in ("vy_after", "wx_after", "wz_after"):
        np.testing.assert_allclose(rows[column], 0.0, atol=1e-12)
    with pytest.raises(SceneError, match="angles"):
        ballc.impact_table(steel(), angles=[95])
    with pytest.raises(SceneError, match="speed"):
        ballc.impact_table(steel(), speed=-1)


def test_fit_impacts_recovers_known_parameters():
    """Synthetic bounces made with known mu, kappa, c_tau are fitted back to 1 %."""
    truth = dict(friction_coefficient=0.45, tangential_stiffness_ratio=0.5, c_tau=0.85)
    base = steel(gravity=0.0)
    table = ballc.impact_table(base.replace(**truth), angles=[10, 25, 40, 55, 70],
                               speed=2.0, spin=[0.0, 50.0, -80.0, 0.0, 120.0])
    from ballc.impact import INCIDENT_COLUMNS
    data = table[list(INCIDENT_COLUMNS)
                 + ["vx_after", "vz_after", "wy_after"]].copy()
    data.loc[1, "wy_after"] = np.nan                     # an unmeasured value
    fit = ballc.fit_impacts(base.replace(friction_coefficient=0.3,
                                         tangential_stiffness_ratio=0.8, c_tau=0.7), data)
    for name, value in truth.items():
        assert getattr(fit.scene, name) == pytest.approx(value, rel=0.01), fit.summary()
    assert len(fit.residuals) == 3 * 5 - 1
    assert np.all(np.isfinite(fit.standard_errors))
    assert "friction_coefficient" in fit.summary()


# --- issue 28: fit_impacts' standard errors against the textbook and the refits' spread ---
#: A linear least-squares problem: the friction law sliding through the whole impact
#: (no gravity) changes vx by -mu (1 + e) v_n sign(u) and wy by +5/2 mu (1 + e) v_n
#: sign(u) / r (test_tangential_restitution_in_gross_sliding), exactly linear in mu.
#: Rows (angle from the normal in degrees, wy in rad/s) in gross sliding for any mu
#: below 0.6, at 2 m/s.
LINEAR_ROWS = ((60.0, -600.0), (70.0, -400.0), (75.0, -200.0))
LINEAR_MU = 0.3
NOISE = 1e-3   # of the incident speed (velocities) and of speed / r (spins)


def linear_problem():
    """(base scene, incident rows, a, b) with the rebounds, scaled as fit_impacts scales
    its residuals, a + b mu by the rigid Coulomb map written out (columns vx_after,
    wy_after; e by Hunt-Crossley's relation chi (1+e) = ln((1+chi)/(1-chi e)))."""
    scene = steel(gravity=0.0, tangential_model="friction", friction_coefficient=LINEAR_MU)
    chi = 1.5 * (1 - scene.c_tau)
    e = brentq(lambda x: chi * (1 + x) - math.log((1 + chi) / (1 - chi * x)), 0.5, 1.0)
    r, speed = scene.radius, 2.0
    incident, a, b = [], [], []
    for angle, wy in LINEAR_ROWS:
        theta = math.radians(angle)
        vx, vz = speed * math.sin(theta), -speed * math.cos(theta)
        u = vx - r * wy
        assert u > 3.5 * 0.6 * (1 + e) * -vz        # sliding to the end up to mu = 0.6
        incident.append((vx, 0.0, vz, 0.0, wy, 0.0))
        a += [vx / speed, wy / (speed / r)]
        b += [-(1 + e) * -vz / speed, 2.5 * (1 + e) * -vz / r / (speed / r)]
    return scene, np.array(incident), np.array(a), np.array(b)


def noisy_table(incident, a, b, rng, speed=2.0, radius=None):
    """The rebounds a + b mu plus Gaussian noise of NOISE, in the fit's scaled units,
    as a table of measured values (unscaled)."""
    import pandas as pd
    from ballc.impact import INCIDENT_COLUMNS
    measured = a + b * LINEAR_MU + NOISE * rng.standard_normal(a.size)
    table = pd.DataFrame(incident, columns=list(INCIDENT_COLUMNS))
    table["vx_after"] = measured[0::2] * speed
    table["wy_after"] = measured[1::2] * speed / radius
    return table, measured


def textbook(measured, a, b):
    """Linear least squares y = a + b mu: the estimate, and its standard error
    sqrt(s^2 (J^T J)^-1), s^2 = |residual|^2 / (N - p), J = b, p = 1."""
    mu = float(b @ (measured - a) / (b @ b))
    residual = a + b * mu - measured
    s2 = float(residual @ residual) / (measured.size - 1)
    return mu, math.sqrt(s2 / float(b @ b))


def test_fit_standard_errors_are_the_textbook_formula(rng):
    """One fit of noisy rebounds of the linear problem: its value and standard error are
    the textbook linear least-squares estimate and error computed here (the compliant
    friction law is the rigid map to ~1e-11 of the speed, the noise is 1e-3)."""
    scene, incident, a, b = linear_problem()
    table, measured = noisy_table(incident, a, b, rng, radius=scene.radius)
    fit = ballc.fit_impacts(scene.replace(friction_coefficient=0.2), table,
                            free=("friction_coefficient",))
    mu, error = textbook(measured, a, b)
    assert fit.values[0] == pytest.approx(mu, abs=1e-3 * error)
    assert fit.standard_errors[0] == pytest.approx(error, rel=1e-3)
    assert 2 * fit.cost == pytest.approx(error ** 2 * float(b @ b) * (measured.size - 1),
                                         rel=1e-3)


def test_fit_standard_errors_match_the_spread_of_refits(rng):
    """200 refits of the linear problem, each with its own noise (the seeded rng): the
    fit's reported standard error (the root mean square over the refits: E[s^2] =
    sigma^2) is the spread of the fitted mu, and both are the noise propagated by hand,
    NOISE / |b|.  Sampling uncertainty: ~5 % for the standard deviation of 200 values,
    ~2 % for the mean of 200 s^2 with 5 degrees of freedom; the bands are 4 of those
    (an error off by sqrt(2) is 30 % off).  Measured: spread 1.018, reported 0.984 of
    NOISE / |b|."""
    scene, incident, a, b = linear_problem()
    values, errors = [], []
    for _ in range(200):
        table, _ = noisy_table(incident, a, b, rng, radius=scene.radius)
        fit = ballc.fit_impacts(scene, table, free=("friction_coefficient",), rtol=1e-8)
        values.append(fit.values[0])
        errors.append(fit.standard_errors[0])
    spread = float(np.std(values, ddof=1))
    reported = math.sqrt(float(np.mean(np.square(errors))))
    expected = NOISE / math.sqrt(float(b @ b))
    assert reported == pytest.approx(expected, rel=0.1)
    assert spread == pytest.approx(expected, rel=0.2)
    assert reported == pytest.approx(spread, rel=0.2)


def rigid_coulomb_bounce(vx, vz, wy, radius, mu, e):
    """Oracle: the rigid Coulomb impact of a solid sphere (I = 2/5 m r^2) on the floor,
    in the x-z plane, in closed form.  u = vx - r wy is the contact point's velocity.
    Per unit mass, the tangential impulse that stops the contact point (it leaves
    rolling, e_t = 0) is p = -u / (1 + m r^2 / I) = -2/7 u; if |p| > mu (1 + e) |vz| it
    slides throughout instead: p = -mu (1 + e) |vz| sign(u).  Then vx' = vx + p,
    vz' = -e vz and wy' = wy - r p m / I = wy - 5/2 p / r (the impulse acts at -r z)."""
    u = vx - radius * wy
    p = -2 / 7 * u
    cap = mu * (1 + e) * abs(vz)
    if abs(p) > cap:
        p = -cap * math.copysign(1.0, u)
    return vx + p, -e * vz, wy - 2.5 * p / radius


def test_fit_impacts_recovers_a_rigid_coulomb_bounce():
    """Rebounds "measured" on the rigid Coulomb map written above (mu = 0.35, e = 0.75;
    not made by ballc) are fitted back by ballc.fit_impacts:

    * with the friction law, in gross sliding and in the rolling-exit regime: that law
      is the rigid map's compliant limit in both (measured on these rows: rebound
      differences <= 3e-11 of the speed), so mu and e come back to 1e-6;
    * with the compliant law (kappa fixed) on gross-sliding rows only, where the force
      is mu F_n throughout and the rigid map holds (measured: <= 1e-11; in the rolling-
      exit regime the tangential spring leaves the rigid map by up to 7 % of the speed
      in vx and 17 % in r wy, so those rows are not used): mu and e to 1e-6.

    fit_impacts fits c_tau; its e is computed here from the Hunt-Crossley relation
    chi (1 + e) = ln((1 + chi) / (1 - chi e)), chi = 3/2 (1 - c_tau) (brentq)."""
    from scipy.optimize import brentq
    mu, e = 0.35, 0.75
    speed = 2.0
    rows = {   # (angle from the normal in degrees, spin wy in rad/s): u / (3.5 mu (1+e) v_n)
        "friction": [(15, 0.0),        # 0.12: rolls
                     (30, 300.0),      # -0.13: backspin, rolls
                     (60, 0.0),        # 0.81: rolls
                     (45, -400.0),     # 1.13: slides
                     (70, 0.0),        # 1.28: slides
                     (80, 0.0)],       # 2.65: slides
        "compliant": [(45, -400.0), (70, 0.0), (80, 0.0)],
    }

    def restitution(c_tau):
        chi = 1.5 * (1 - c_tau)
        return brentq(lambda x: chi * (1 + x) - math.log((1 + chi) / (1 - chi * x)),
                      1e-9, min(1.0, 1 / chi) * (1 - 1e-12), xtol=1e-15)

    for model, incidents in rows.items():
        base = steel(gravity=0.0, tangential_model=model, friction_coefficient=0.2,
                     c_tau=0.95)
        data = []
        for angle, wy in incidents:
            vx, vz = speed * math.sin(math.radians(angle)), -speed * math.cos(math.radians(angle))
            vx_after, vz_after, wy_after = rigid_coulomb_bounce(vx, vz, wy, base.radius, mu, e)
            data.append(dict(vx=vx, vy=0.0, vz=vz, wx=0.0, wy=wy, wz=0.0,
                             vx_after=vx_after, vz_after=vz_after, wy_after=wy_after))
        fit = ballc.fit_impacts(base, data, free=("friction_coefficient", "c_tau"))
        assert fit.scene.friction_coefficient == pytest.approx(mu, rel=1e-6), fit.summary()
        assert restitution(fit.scene.c_tau) == pytest.approx(e, rel=1e-6), fit.summary()
        assert np.abs(fit.residuals).max() < 1e-7, fit.summary()


def test_fit_impacts_rejects_bad_inputs():
    base = steel()
    good = {"vx": [1.0], "vy": [0.0], "vz": [-1.0], "wx": [0.0], "wy": [0.0], "wz": [0.0],
            "vx_after": [0.5], "vz_after": [0.9], "wy_after": [10.0]}
    with pytest.raises(SceneError, match="incident column"):
        ballc.fit_impacts(base, {k: v for k, v in good.items() if k != "wz"})
    with pytest.raises(SceneError, match="rebound column"):
        ballc.fit_impacts(base, {k: v for k, v in good.items() if "after" not in k})
    with pytest.raises(SceneError, match="radius_of"):
        ballc.fit_impacts(base, good, free=("radius_of",))
    with pytest.raises(SceneError, match="too few"):
        ballc.fit_impacts(base, {**good, "vz_after": [np.nan], "wy_after": [np.nan]})


# Known disagreements of the compliant model with the paper's DEM curves (reported in
# docs/validation.md, not hidden): the regime where the tangential spring matters.
#: The compliant law against the paper's curves of tests 5 and 6: reported, not scored
#: (they assume another kappa than Mindlin's; validation/cases.py PAPER_KAPPA_NOTE); the
#: same curves are scored against the DEM algorithm on the paper's inputs instead.
REPORTED = {
    ("5 varying V_t", "compliant", "normalised recoil angle u'/(mu V_n')"),
    ("5 varying V_t", "compliant", "normalised spin r w'/(mu V_n)"),
    ("6 spin only", "compliant", "beta = -u'/u"),
    ("6 spin only", "compliant", "tan recoil angle"),
    # rolling resistance's sds against LAMMPS' algorithm where the two laws differ (a
    # dashpot; twisting): docs/contact_laws.md, "sds"
    ("7 rolling resistance", "sds",
     "sds vs LAMMPS rolling sds, dashpot 0.3 critical: worst rebound difference"),
    ("7 rolling resistance", "sds",
     "sds vs LAMMPS rolling sds, twisting, no dashpot: worst rebound difference"),
}


@pytest.fixture(scope="module")
def validation_rows():
    sys.path.insert(0, str(ROOT))
    from validation.cases import TESTS
    rows = []
    for test in TESTS.values():
        test_rows, fig = test()
        import matplotlib.pyplot as plt
        plt.close(fig)
        rows += test_rows
    return rows


@pytest.mark.slow
def test_validation_runs(tmp_path):
    """``python -m validation`` runs, writes one figure per test, and exits 0 (every
    scored row passes)."""
    run = subprocess.run([sys.executable, "-m", "validation", "--out", str(tmp_path)],
                         cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [
        f"test{k}.png" for k in (2, 3, 4, 5, 6, 7)]
    failed = [line for line in run.stdout.splitlines() if " FAIL " in line]
    assert not failed, run.stdout
    assert run.returncode == 0, run.stdout + run.stderr


@pytest.mark.slow
def test_validation_curves(validation_rows):
    """Every scored curve passes its threshold; the reported ones are exactly REPORTED."""
    for row in validation_rows:
        if row.status == "LIMIT":
            continue
        key = (row.test, row.model, row.curve)
        if key in REPORTED:
            assert row.status == "REPORT", key
        else:
            assert row.status == "pass", (key, row.error, row.threshold)
