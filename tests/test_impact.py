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


def test_impact_table():
    table = ballc.impact_table(steel(gravity=0.0), angles=[0, 30, 60], speed=1.5, spin=10.0)
    assert list(table["angle"]) == [0, 30, 60]
    for column in ("vx", "vz", "wy", "vx_after", "wz_after", "e_n", "e_t", "duration",
                   "max_penetration", "status"):
        assert column in table.columns
    np.testing.assert_allclose(table["vz"], -1.5 * np.cos(np.radians([0, 30, 60])), atol=1e-6)
    assert (table["wy"] == 10.0).all()
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
        f"test{k}.png" for k in (2, 3, 4, 5, 6)]
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
