"""Property-based tests (hypothesis) over valid scenes: no NaN, passive models never
create energy, mirror-symmetric scenes stay mirror-symmetric, runs are reproducible.

Short runs (a few tenths of a second, started close to the floor so that most examples
contain a contact) and modest example counts keep the default suite fast.
"""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ballc

SETTINGS = settings(max_examples=12, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])
T_END = 0.3


def unit_ball_point(max_norm):
    """A point strictly inside the ball (in radii)."""
    return st.tuples(*[st.floats(-1, 1)] * 3).map(
        lambda p: tuple(max_norm * np.tanh(np.array(p)) / np.sqrt(3)))


#: Every tangential model: the compliant law (a Mindlin tangential spring with a
#: Coulomb cap, its own stick/slip modes) is drawn with its stiffness ratio kappa.
MODELS = ("friction", "mixture", "dig-in", "compliant")


@st.composite
def scenes(draw, models=MODELS, mirror_ready=False):
    radius = draw(st.floats(0.2, 1.0))
    height = radius * draw(st.floats(2.5, 12.0))
    z = draw(st.floats(radius, min(height - radius, radius + 0.5)))
    fields = dict(
        mass=draw(st.floats(0.1, 5.0)),
        radius=radius,
        ceiling_height=height,
        observer_mass=draw(st.sampled_from([0.0, 1e-4, 0.3])),
        observer_position=draw(unit_ball_point(0.95)),
        ball_youngs_modulus=draw(st.sampled_from([1e3, 3e3, 1e5, 1e7])),
        c_tau=draw(st.floats(0.5, 1.0)),
        mixture=draw(st.floats(0.0, 1.0)),
        tangential_model=draw(st.sampled_from(models)),
        # the compliant law's k_t / k_n ratio (2/7: the superball; Mindlin: ~0.8);
        # the other laws ignore it
        tangential_stiffness_ratio=draw(st.floats(0.1, 1.5)),
        # rolling resistance (issue 31): none, or mu_r, mu_t up to 0.5, in either model
        rolling_resistance=draw(st.just(0.0) | st.floats(1e-3, 0.5)),
        twisting_resistance=draw(st.just(0.0) | st.floats(1e-3, 0.5)),
        rolling_model=draw(st.sampled_from(ROLLING_MODELS)),
    )
    # mu in [0, 1]; for the compliant law 0 or [1e-100, 1]: a vanishing but non-zero mu
    # crawled until issue 28 (test_compliant_law_with_a_vanishing_friction_coefficient
    # below), and below ~1e-200 (s_cap = mu F_n / k_t under the direction's 1e-140-m
    # floor) its modes still chatter, with both integrators, until the call budget
    if fields["tangential_model"] == "compliant":
        fields["friction_coefficient"] = draw(st.just(0.0) | st.floats(1e-100, 1.0))
    else:
        fields["friction_coefficient"] = draw(st.floats(0.0, 1.0))
    fields.update(
        position=(draw(st.floats(-1, 1)), draw(st.floats(-1, 1)), z),
        velocity=(draw(st.floats(-5, 5)), draw(st.floats(-5, 5)), draw(st.floats(-10, 3))),
        angular_velocity=tuple(draw(st.floats(-20, 20)) for _ in range(3)),
    )
    if not mirror_ready:
        fields["angles"] = tuple(draw(st.floats(-3, 3)) for _ in range(3))
    return ballc.Scene(**fields)


#: The rolling resistance models drawn (ballc.scene.ROLLING_MODELS).
ROLLING_MODELS = ("exact", "sds")

#: ballc's two compiled integrators: radau5 (the default) and the explicit dop853.
METHODS = ("radau5", "dop853")


@pytest.mark.parametrize("method", METHODS)
@SETTINGS
@given(scene=scenes())
def test_no_nan_and_honest_status(method, scene):
    result = ballc.simulate(scene, T_END, method=method, rtol=1e-7, atol=1e-9)
    assert result.status in (0, 1), result.message
    assert np.all(np.isfinite(result.y)) and np.all(np.isfinite(result.energy["total"]))
    assert np.all(np.diff(result.t) > 0)
    if result.status == 0:
        assert result.t[-1] == T_END
    else:
        assert "passed through" in result.message and result.t[-1] < T_END


@pytest.mark.parametrize("method", METHODS)
@SETTINGS
@given(scene=scenes(models=("friction", "compliant")))
def test_passive_model_never_creates_energy(method, scene):
    """Friction and the compliant law with c_tau <= 1, with or without rolling
    resistance, are passive: E(t_j) <= E(t_i) for all i < j, E = kinetic + potential +
    Hertz spring + the compliant law's tangential spring (its stored energy: 0 for
    friction) + the rolling part's sds springs, up to integration tolerance (1e3 rtol of
    the energy scale; see test_stress.energy_tolerance), and the rolling part's
    dissipated work never falls.  Oracle: the passivity of the laws
    (docs/contact_laws.md): no ballc number is the expected value."""
    rtol = 1e-8
    result = ballc.simulate(scene, T_END, method=method, rtol=rtol, atol=1e-10)
    # a soft, heavy ball can honestly pass through the floor (rho reaches r: outside
    # the model, docs/limits.md); the energy must not rise up to there either
    assert result.status == 0 or "passed through" in result.message
    energy = result.energy
    total = energy["total"]
    np.testing.assert_allclose(total, energy["kinetic"] + energy["potential"]
                               + energy["spring"] + energy["tangential_spring"]
                               + energy["rolling_spring"], rtol=1e-12, atol=1e-12)
    rolling = energy["dissipated_rolling"]
    assert np.all(np.diff(rolling) >= -1e3 * rtol * (abs(total[0]) + 1.0) - 1e-9)
    if scene.rolling_resistance == 0 and scene.twisting_resistance == 0:
        assert np.all(rolling == 0)
    if scene.tangential_model == "friction":
        assert np.all(energy["tangential_spring"] == 0.0)
    rise = np.max(total[1:] - np.minimum.accumulate(total)[:-1], initial=0.0)
    assert rise <= 1e3 * rtol * (abs(total[0]) + 1.0) + 1e-9


#: Reflection y -> -y: positions and velocities flip their y component; the angular
#: velocity is a pseudovector (x and z flip); the rotation R -> S R S flips qx and qz;
#: tangential deflections and rolling springs flip their y component, twisting springs
#: (about the normal, as omega_z) flip.  Everything else is unchanged.
def _mirror_signs(scene):
    flip = {"y", "vy", "omega_x", "omega_z", "qx", "qz"}
    return np.array([-1.0 if name in flip or name.endswith(("deflection_y", "rolling_y",
                                                            "twisting")) else 1.0
                     for name in scene.state_names])


def mirrored(scene):
    (px, py, pz), (vx, vy, vz) = scene.position, scene.velocity
    wx, wy, wz = scene.angular_velocity
    a, b, c = scene.observer_position
    return scene.replace(position=(px, -py, pz), velocity=(vx, -vy, vz),
                         angular_velocity=(-wx, wy, -wz), observer_position=(a, -b, c))


@pytest.mark.parametrize("models", [MODELS[:3], ("compliant",)],
                         ids=["friction-mixture-digin", "compliant"])
@SETTINGS
@given(data=st.data())
def test_mirror_symmetric_scenes_stay_symmetric(models, data):
    """Angles 0 (body frame = inertial frame at t = 0) and the observer reflected with
    the scene: the solution is the reflection of the original one (oracle: the mirror
    symmetry of the equations), compared over the whole of both runs: the same samples
    of the same time grid, the same contacts one to one.  The compliant law is drawn on
    its own (its stick/slip modes and spring deflections must mirror too)."""
    scene = data.draw(scenes(models, mirror_ready=True), label="scene")
    rtol, atol = 1e-10, 1e-12
    t = np.linspace(0.0, T_END, 31)
    one = ballc.simulate(scene, T_END, rtol=rtol, atol=atol, t_eval=t)
    two = ballc.simulate(mirrored(scene), T_END, rtol=rtol, atol=atol, t_eval=t)
    assert one.status == two.status and one.message == two.message
    # Tolerance: both runs are the same problem up to the mirror, so they differ only by
    # the integration error of each, a few rtol per step over a few hundred steps:
    # 1e4 rtol of each component's scale (1e-6 at rtol 1e-10).
    tol = 1e4 * rtol
    if one.status == 0:
        np.testing.assert_array_equal(one.t, t)
        np.testing.assert_array_equal(two.t, t)
    else:
        # a run that stops early (the ball passed through a plane) ends at its event:
        # both stop at the same time, with the same samples of the grid before it
        assert one.t.size == two.t.size
        np.testing.assert_allclose(two.t, one.t, rtol=0, atol=tol * T_END)
    expected = one.y * _mirror_signs(scene)[:, None]
    scale = np.maximum(np.abs(one.y).max(axis=1, keepdims=True), 1.0)
    assert np.all(np.abs(two.y - expected) <= tol * scale)
    # the contact tables, one to one
    assert len(one.contacts) == len(two.contacts)
    assert [c.plane for c in one.contacts] == [c.plane for c in two.contacts]
    flip_v, flip_w = np.array([1.0, -1.0, 1.0]), np.array([-1.0, 1.0, -1.0])
    for a, b in zip(one.contacts, two.contacts):
        assert b.t_start == pytest.approx(a.t_start, rel=0, abs=1e-9)
        if np.isfinite(a.t_end) or np.isfinite(b.t_end):
            assert b.t_end == pytest.approx(a.t_end, rel=0, abs=1e-9)
        speed = max(np.linalg.norm(a.velocity_before), 1.0)
        for before_or_after in ("before", "after"):
            va, vb = (getattr(c, f"velocity_{before_or_after}") for c in (a, b))
            wa, wb = (getattr(c, f"angular_velocity_{before_or_after}") for c in (a, b))
            np.testing.assert_allclose(vb, flip_v * va, rtol=0, atol=tol * speed)
            np.testing.assert_allclose(wb, flip_w * wa, rtol=0,
                                       atol=tol * speed / scene.radius)


@settings(max_examples=6, deadline=None, derandomize=True)
@given(scenes())
def test_same_scene_gives_bit_identical_results(scene):
    one = ballc.simulate(scene, T_END, rtol=1e-7, atol=1e-9)
    two = ballc.simulate(scene, T_END, rtol=1e-7, atol=1e-9)
    assert one.status == two.status and one.message == two.message
    assert np.array_equal(one.t, two.t) and np.array_equal(one.y, two.y)
    assert (one.nfev, one.njev, one.nlu) == (two.nfev, two.njev, two.nlu)
    assert len(one.contacts) == len(two.contacts)
    for a, b in zip(one.contacts, two.contacts):
        assert a.t_start == b.t_start and np.array_equal(a.velocity_after, b.velocity_after,
                                                         equal_nan=True)


def test_compliant_law_with_a_vanishing_friction_coefficient():
    """The compliant law with mu = 1e-15 is a frictionless contact to rounding: it must
    run like mu = 0 (1,445 RHS calls for this scene, which hypothesis found with mu =
    4e-193).  Before issue 28 it exhausted the default 2e7-call budget (status -1; mu =
    1e-4 took 6e5 calls): the sliding mode's Jacobian left out the spring's turn towards
    the slip, (e . v_t) / |s| with |s| ~ mu; now 7,451 calls (1,839 at mu = 1e-4)."""
    scene = ballc.Scene(
        mass=1.5, observer_mass=0.3, radius=0.3, ceiling_height=1.857,
        observer_position=(-0.0117, 0.3446, 0.1727), ball_youngs_modulus=1e5, c_tau=0.99999,
        tangential_model="compliant", tangential_stiffness_ratio=0.488,
        friction_coefficient=1e-15, position=(0.4, 0.0, 0.667), velocity=(0.0, 4.854, -5.364),
        angles=(0.0, -1.5, -1.2), angular_velocity=(-13.29, 14.79, -12.50))
    frictionless = ballc.simulate(scene.replace(friction_coefficient=0.0), T_END,
                                  rtol=1e-7, atol=1e-9)
    assert frictionless.status == 0 and frictionless.nfev < 10_000
    result = ballc.simulate(scene, T_END, rtol=1e-7, atol=1e-9, max_nfev=200_000)
    assert result.status == 0, result.message
    assert result.nfev < 10 * frictionless.nfev
