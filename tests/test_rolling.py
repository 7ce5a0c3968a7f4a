"""Rolling resistance (issue 31), its exact model (Ai et al.'s type A with holding):
against closed forms.

* A stiff ball rolling at v0 on a floor decelerates at mu_r g / (1 + I/(m r^2)): a solid
  ball stops after s = 7 v0^2 / (10 mu_r g) at t = 7 v0 / (5 mu_r g), a hollow one
  (I = 2/3 m r^2) after 5 v0^2 / (6 mu_r g) at 5 v0 / (3 mu_r g); the work the rolling
  torque dissipated is the kinetic energy it had; then it holds, and rests in closed form.
* On an incline (gravity turned by theta against the floor's normal: the same physics
  as a plane turned, docs/contact_laws.md) a ball at rest holds when tan(theta) <= mu_r
  and tan(theta) <= mu; with tan(theta) > mu_r it rolls down at
  g (sin(theta) - mu_r cos(theta)) / (1 + I/(m r^2)); with mu < tan(theta) it slides.
* The seed's throw with mu_r = 0.01 runs to 1e9 s and ends in closed form.
* The sds model (LAMMPS' rolling sds, ballc's passive form): a ball rolling a little on
  its spring oscillates at Omega = sqrt(k_r / (m (1 + I/(m r^2)))), damped by its dashpot
  as theta'' + gamma_r / (m (1 + I/(m r^2))) theta' + Omega^2 theta = 0; rolling
  faster, its spring yields to the slider, whose torque is the exact model's.
* Bad rolling parameters are refused by name.
"""
import math

import numpy as np
import pytest

import ballc
from ballc import _core
from validation.rolling_cases import stiff_scene   # the scene the validation scores

S = _core.STATE_INDEX
G = 9.81


def tilted(scene, theta):
    """``scene`` with its gravity turned by theta about y: g (sin(theta), 0, -cos(theta)),
    the floor an incline falling along +x (a stand-in for a plane turned by theta)."""
    params = scene.parameter_vector()
    names = _core.PARAMETER_NAMES
    params[[names.index(f"gravity_{k}") for k in "xyz"]] = \
        scene.gravity * np.array([math.sin(theta), 0.0, -math.cos(theta)])
    params.flags.writeable = False
    scene.__dict__["_parameters"] = params   # Scene caches its parameter vector here
    return scene


def stop_of(result, plane=0):
    """(t, x) where the rolling part of the plane with index ``plane`` first holds (the
    segment log's roll_stop)."""
    log = result.segments
    held = log[(log["end"] == "roll_stop") & (log["rolling_after"][:, plane] == "holding")]
    assert held.size, "the ball never held"
    t = held["t_end"][0]
    k = np.searchsorted(result.t, t)
    return t, result.y[S["x"], k]


@pytest.mark.parametrize("hollow", [False, True], ids=["solid", "hollow"])
@pytest.mark.parametrize("mu_r", [0.01, 0.05])
def test_a_rolling_ball_stops_where_and_when_the_closed_form_says(hollow, mu_r):
    v0, r, m = 1.0, 0.1, 1.0
    ratio = 2 / 3 if hollow else 2 / 5          # I / (m r^2)
    inertia = (ratio * m * r * r,) * 3
    scene = stiff_scene(rolling_resistance=mu_r, inertia=inertia, velocity=(v0, 0, 0),
                        angular_velocity=(0, v0 / r, 0))
    a = mu_r * G / (1 + ratio)
    t_stop, s_stop = v0 / a, v0 ** 2 / (2 * a)
    if not hollow:
        assert t_stop == pytest.approx(7 * v0 / (5 * mu_r * G))
        assert s_stop == pytest.approx(7 * v0 ** 2 / (10 * mu_r * G))
    result = ballc.simulate(scene, 2 * t_stop, rtol=1e-9, atol=1e-10)
    assert result.status == 0, result.message
    t, x = stop_of(result)
    assert t == pytest.approx(t_stop, rel=1e-7)
    assert x == pytest.approx(s_stop, rel=1e-7)
    # uniformly decelerated before: v(t) = v0 - a t, rolling without slip
    before = (result.t > 0.1 * t_stop) & (result.t < 0.9 * t_stop)
    np.testing.assert_allclose(result.y[S["vx"], before], v0 - a * result.t[before],
                               rtol=0, atol=1e-8)
    np.testing.assert_allclose(r * result.y[S["omega_y"], before],
                               result.y[S["vx"], before], rtol=0, atol=1e-8)
    # the rolling torque dissipated the kinetic energy; then at rest, in closed form
    energy = result.energy
    kinetic = 0.5 * m * v0 ** 2 + 0.5 * inertia[1] * (v0 / r) ** 2
    assert energy["dissipated_rolling"][-1] == pytest.approx(kinetic, rel=1e-7)
    assert np.ptp(energy["balance"]) < 1e-9 * kinetic
    assert np.all(np.diff(energy["dissipated_rolling"]) >= -1e-15)
    assert "came to rest" in result.message
    assert np.all(result.y[S["vx"]:S["vx"] + 3, -1] == 0)
    assert result.y[S["x"], -1] == pytest.approx(s_stop, rel=1e-7)


def test_without_rolling_resistance_the_ball_rolls_on():
    """mu_r = 0: no torque, the stiff ball rolls on at v0."""
    scene = stiff_scene(rolling_resistance=0.0, velocity=(1.0, 0, 0),
                        angular_velocity=(0, 10.0, 0))
    result = ballc.simulate(scene, 30.0, rtol=1e-9, atol=1e-10)
    assert result.status == 0, result.message
    np.testing.assert_allclose(result.y[S["vx"]], 1.0, rtol=1e-9)
    assert np.all(result.energy["dissipated_rolling"] == 0)
    assert set(result.segments["rolling_before"].ravel()) == {"none"}


def incline_run(theta, mu, mu_r, t_end=1.0):
    scene = tilted(stiff_scene(friction_coefficient=mu, rolling_resistance=mu_r), theta)
    return scene, ballc.simulate(scene, t_end, rtol=1e-9, atol=1e-10, rest=False,
                                 exact_flight=False)


def test_a_ball_on_an_incline_holds_when_tan_theta_is_within_mu_r_and_mu():
    mu_r = 0.02
    theta = math.atan(0.8 * mu_r)
    scene, result = incline_run(theta, 0.5, mu_r)
    assert result.status == 0, result.message
    log = result.segments
    assert set(log["rolling_before"][:, 0]) == {"holding"}
    assert set(log["before"][:, 0]) == {"stick"}
    speed = np.hypot(*result.y[S["vx"]:S["vx"] + 3])
    assert speed.max() < 1e-9
    # the holding force: the rolling torque r F_r balances the friction's, r m g sin(theta)
    k = -1
    y = np.ascontiguousarray(result.y[:, k])
    state = _core.rolling_state(y, scene.parameter_vector(),
                                np.ascontiguousarray(result.latch[:, k]),
                                int(result.flags[k]), 0)
    assert np.hypot(state[0], state[1]) == pytest.approx(G * math.sin(theta), rel=1e-6)
    assert state[3] == pytest.approx(G * math.cos(theta), rel=1e-6)


@pytest.mark.parametrize("mu_r", [0.01, 0.03])
def test_a_ball_on_a_steeper_incline_rolls_down_at_the_closed_form_acceleration(mu_r):
    theta = math.atan(3 * mu_r)
    scene, result = incline_run(theta, 0.5, mu_r)
    assert result.status == 0, result.message
    a = G * (math.sin(theta) - mu_r * math.cos(theta)) / 1.4
    later = result.t > 0.2
    t, vx = result.t[later], result.y[S["vx"], later]
    slope = np.polyfit(t, vx, 1)[0]
    assert slope == pytest.approx(a, rel=1e-6)
    log = result.segments
    assert log["rolling_after"][-1, 0] in ("rolling", "rolling_fixed")
    assert log["after"][-1, 0] == "stick"   # rolls without slip: mu >= the needed


def test_a_held_ball_slides_down_an_incline_steeper_than_mu():
    """tan(theta) <= mu_r but > mu: the rolling holds, the contact slides at
    g (sin(theta) - mu cos(theta))."""
    mu, mu_r = 0.02, 0.1
    theta = math.atan(2 * mu)
    scene, result = incline_run(theta, mu, mu_r)
    assert result.status == 0, result.message
    later = result.t > 0.2
    slope = np.polyfit(result.t[later], result.y[S["vx"], later], 1)[0]
    assert slope == pytest.approx(G * (math.sin(theta) - mu * math.cos(theta)), rel=1e-6)
    assert np.abs(result.y[S["omega_y"], later]).max() < 1e-9   # held: no rolling


@pytest.mark.parametrize("twisting", [0.0, 0.01])
def test_the_seed_throw_with_rolling_resistance_ends_in_closed_form(twisting):
    """The seed's throw with mu_r = 0.01 to 1e9 s: it holds and sticks within ~44 s and
    goes on in closed form -- spinning slowly about the normal without twisting
    resistance (its eccentric observer's wobble left it ~9e-4 rad/s), at rest with it.
    The calls (~1.4e5) bound its cost without timing it (<= 0.2 s measured)."""
    scene = ballc.Scene(rolling_resistance=0.01, twisting_resistance=twisting)
    result = ballc.simulate(scene, 1e9)
    assert result.status == 0, result.message
    assert result.t[-1] == 1e9
    assert result.nfev < 200_000
    if twisting:
        assert "came to rest" in result.message
        assert np.all(result.y[S["omega_x"]:S["omega_x"] + 3, -1] == 0)
    else:
        assert "held by its rolling resistance" in result.message
        spin = result.y[S["omega_z"], -1]
        assert abs(spin) > 0 and np.hypot(*result.y[S["omega_x"]:S["omega_y"] + 1, -1]) \
            < 1e-12 * abs(spin) + 1e-15
    balance = result.energy["balance"]
    assert abs(balance[-1] - balance[0]) < 1e-6 * balance[0]
    assert np.all(np.diff(result.energy["dissipated_rolling"]) >= -1e-12)


@pytest.mark.parametrize("fields, name", [
    (dict(rolling_resistance=-0.1), "rolling_resistance"),
    (dict(rolling_resistance=float("nan")), "rolling_resistance"),
    (dict(twisting_resistance=-1.0), "twisting_resistance"),
    (dict(rolling_model="exakt"), "rolling_model"),
    (dict(rolling_stiffness=10.0), "rolling_stiffness"),
    (dict(rolling_model="sds", rolling_resistance=0.1, rolling_stiffness=-1.0),
     "rolling_stiffness"),
    (dict(rolling_model="sds", rolling_resistance=0.1, rolling_damping=-1.0),
     "rolling_damping"),
    (dict(rolling_model="sds", rolling_resistance=0.1, gravity=0.0), "rolling_stiffness"),
])
def test_bad_rolling_parameters_are_refused_by_name(fields, name):
    with pytest.raises(ballc.SceneError, match=name):
        ballc.Scene(**fields)


def zero_crossings(t, v):
    """The times where v changes sign, interpolated linearly."""
    k = np.flatnonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)
    return t[k] - v[k] * (t[k + 1] - t[k]) / (v[k + 1] - v[k])


@pytest.mark.parametrize("gamma", [0.0, 1.0])
@pytest.mark.parametrize("hollow", [False, True], ids=["solid", "hollow"])
def test_the_sds_spring_oscillates_at_its_closed_form_frequency(gamma, hollow):
    """A ball held by the sds rolling spring (below its cap; Coulomb sticks), pushed a
    little: the rolling angle obeys (I + m r^2) theta'' + gamma r^2 theta' + k r^2 theta
    = 0, so v_x crosses 0 every half period pi / sqrt(Omega^2 - beta^2), Omega^2 =
    k / (m (1 + I/(m r^2))), beta = gamma / (2 m (1 + I/(m r^2)))."""
    k, m, r, v0 = 100.0, 1.0, 0.1, 1e-3
    ratio = 2 / 3 if hollow else 2 / 5
    scene = stiff_scene(rolling_model="sds", rolling_resistance=0.1, rolling_stiffness=k,
                        rolling_damping=gamma, inertia=(ratio * m * r * r,) * 3,
                        velocity=(v0, 0, 0), angular_velocity=(0, v0 / r, 0))
    result = ballc.simulate(scene, 3.0, rtol=1e-10, atol=1e-12, rest=False)
    assert result.status == 0, result.message
    assert set(result.segments["rolling_before"][:, 0]) == {"spring"}
    assert set(result.segments["before"][:, 0]) == {"stick"}
    omega2 = k / (m * (1 + ratio))
    beta = gamma / (2 * m * (1 + ratio))
    half = math.pi / math.sqrt(omega2 - beta ** 2)
    crossings = zero_crossings(result.t, result.y[S["vx"]])
    assert len(crossings) >= 6
    np.testing.assert_allclose(np.diff(crossings), half, rtol=1e-5)
    energy = result.energy
    assert np.ptp(energy["balance"]) < 1e-9 * energy["total"][0]
    if gamma:   # the dashpot dissipates; the spring stores and gives back
        assert energy["dissipated_rolling"][-1] > 0
        assert np.all(np.diff(energy["dissipated_rolling"]) >= -1e-18)
    else:
        assert abs(energy["dissipated_rolling"][-1]) < 1e-15
        # all the kinetic energy in the spring at the turning points (the samples come
        # within 1e-5 of them)
        assert energy["rolling_spring"].max() == pytest.approx(
            0.5 * m * v0 ** 2 * (1 + ratio), rel=1e-4)


def test_the_sds_slider_decelerates_as_the_exact_model():
    """Rolling fast, the sds spring yields to its slider at once (roll_yield), whose
    torque is mu_r r F_n: the ball stops where the exact model's does, then springs back
    by the spring's deflection at the cap, mu_r m g / k_r."""
    k, v0, mu_r = 1e4, 1.0, 0.01
    scene = stiff_scene(rolling_model="sds", rolling_resistance=mu_r, rolling_stiffness=k,
                        rolling_damping=10.0, velocity=(v0, 0, 0), angular_velocity=(0, 10.0, 0))
    result = ballc.simulate(scene, 30.0, rtol=1e-9, atol=1e-10)
    assert result.status == 0, result.message
    log = result.segments
    assert log["end"][0] == "roll_yield" and log["rolling_after"][0, 0] == "slider"
    a = mu_r * G / 1.4
    restick = log[log["end"] == "roll_restick"]
    assert restick["t_end"][0] == pytest.approx(v0 / a, rel=1e-7)
    assert result.y[S["x"], -1] == pytest.approx(v0 ** 2 / (2 * a) - mu_r * G / k, rel=1e-7)
    assert "came to rest" in result.message
    energy = result.energy
    assert energy["dissipated_rolling"][-1] == pytest.approx(0.7, rel=1e-7)
    assert np.ptp(energy["balance"]) < 1e-9


@pytest.mark.parametrize("model", ["exact", "sds"])
def test_a_spinning_ball_stops_its_spin_at_the_closed_form_time(model):
    """Twisting resistance: a stiff ball at rest on the floor spinning about the normal at
    omega0 feels mu_t r m g against the spin, so it stops at t = I omega0 / (mu_t r m g)
    -- the exact model holds there (twist_stop -> holding); the sds slider re-sticks on
    its spring (twist_restick) later by half its loading time t_y = xi_cap / (r omega0),
    xi_cap = mu_t m g / k_w (its spring stretched to the cap carried half the torque
    meanwhile) -- and its rolling is never touched."""
    w0, mu_t, r, m = 10.0, 0.1, 0.1, 1.0
    springs = dict(twisting_stiffness=1e4, twisting_damping=0.0) if model == "sds" else {}
    scene = stiff_scene(rolling_model=model, rolling_resistance=0.05, twisting_resistance=mu_t,
                        angular_velocity=(0, 0, w0), **springs)
    result = ballc.simulate(scene, 1.0, rtol=1e-9, atol=1e-10, rest=False)
    assert result.status == 0, result.message
    delay = 0.0 if model == "exact" else \
        0.5 * mu_t * m * G / springs["twisting_stiffness"] / (r * w0)
    t_stop = scene.inertia[2] * w0 / (mu_t * r * m * G) + delay
    log = result.segments
    end = "twist_stop" if model == "exact" else "twist_restick"
    after = "holding" if model == "exact" else "spring"
    stop = log[(log["end"] == end) & (log["twisting_after"][:, 0] == after)]
    assert stop["t_end"][0] == pytest.approx(t_stop, rel=1e-7 if model == "exact" else 1e-6)
    before = (result.t < 0.9 * t_stop) & (result.t > 1e-3)
    np.testing.assert_allclose(result.y[S["omega_z"], before],
                               w0 - mu_t * r * m * G / scene.inertia[2]
                               * (result.t[before] - delay),
                               rtol=0, atol=1e-7)
    assert np.abs(result.y[S["vx"]:S["vx"] + 3]).max() < 1e-12
    energy = result.energy
    assert energy["dissipated_rolling"][-1] == pytest.approx(
        0.5 * scene.inertia[2] * w0 ** 2 - energy["rolling_spring"][-1]
        - energy["kinetic"][-1], rel=1e-6)


# --- on i30b's planes: the rolling part is the law's in a plane's own frame, applied per
# plane at run time (any plane, any number of planes, its states per plane) -------------


def plane_incline(theta, mu, mu_r, hollow=False):
    """A stiff ball at rest at its static penetration on a real tilted plane (the only
    plane: its normal (sin(theta), 0, cos(theta)), falling along +x), gravity along -z."""
    ratio = 2 / 3 if hollow else 2 / 5
    plane = ballc.Plane((0.0, 0.0, 0.0), (math.sin(theta), 0.0, math.cos(theta)), "incline")
    scene = ballc.Scene(planes=(plane,), tangential_model="friction", observer_mass=0.0,
                        radius=0.1, mass=1.0, inertia=(ratio * 0.01,) * 3,
                        ball_youngs_modulus=2e11, plane_youngs_modulus=2e11, c_tau=0.5,
                        friction_coefficient=mu, rolling_resistance=mu_r,
                        position=(0.0, 0.0, 1.0), velocity=(0.0, 0.0, 0.0))
    rho_eq = (G * math.cos(theta) / scene.hertz_stiffness) ** (2 / 3)
    n = np.array(plane.unit_normal)
    return scene.replace(position=tuple((0.1 - rho_eq) * n)), n, ratio


def test_on_a_tilted_plane_a_ball_holds_when_tan_theta_is_within_mu_r():
    """tan(theta) = 0.8 mu_r <= mu: held and sticking, still; to 1e3 s it rests on the
    incline in closed form (the rest check of a held, sticking ball)."""
    mu_r = 0.02
    theta = math.atan(0.8 * mu_r)
    scene, n, _ = plane_incline(theta, 0.5, mu_r)
    result = ballc.simulate(scene, 1.0, rtol=1e-9, atol=1e-10, rest=False)
    assert result.status == 0, result.message
    log = result.segments
    assert set(log["rolling_before"][:, 0]) == {"holding"}
    assert set(log["before"][:, 0]) == {"stick"}
    assert np.hypot.reduce(result.velocity, axis=0).max() < 1e-9
    y = np.ascontiguousarray(result.y[:, -1])
    state = _core.rolling_state(y, scene.parameter_vector(),
                                np.ascontiguousarray(result.latch[:, -1]),
                                int(result.flags[-1]), 0)
    # the holding force balances the friction's moment: |lambda_r| = m g sin(theta)
    assert np.hypot(state[0], state[1]) == pytest.approx(G * math.sin(theta), rel=1e-6)
    assert state[3] == pytest.approx(G * math.cos(theta), rel=1e-6)
    long = ballc.simulate(scene, 1e3)
    assert long.status == 0 and "came to rest" in long.message, long.message
    assert np.all(long.velocity[:, -1] == 0)


@pytest.mark.parametrize("hollow", [False, True], ids=["solid", "hollow"])
@pytest.mark.parametrize("mu_r", [0.01, 0.03])
def test_on_a_tilted_plane_a_ball_rolls_down_at_the_closed_form_acceleration(mu_r, hollow):
    """tan(theta) = 3 mu_r: a = g (sin(theta) - mu_r cos(theta)) / (1 + I/(m r^2)) down
    the slope, rolling without slip, nothing across it or into the plane."""
    theta = math.atan(3 * mu_r)
    scene, n, ratio = plane_incline(theta, 0.5, mu_r, hollow)
    result = ballc.simulate(scene, 1.0, rtol=1e-9, atol=1e-10, rest=False)
    assert result.status == 0, result.message
    down = np.array([math.cos(theta), 0.0, -math.sin(theta)])
    later = result.t > 0.2
    speed = down @ result.velocity[:, later]
    slope = np.polyfit(result.t[later], speed, 1)[0]
    assert slope == pytest.approx(G * (math.sin(theta) - mu_r * math.cos(theta)) / (1 + ratio),
                                  rel=1e-6)
    spin = np.cross(n, down) @ result.angular_velocity[:, later]
    np.testing.assert_allclose(speed, 0.1 * spin, rtol=0, atol=1e-8)
    assert np.abs(result.velocity[1]).max() < 1e-12
    assert np.abs(n @ result.velocity).max() < 1e-8
    assert result.segments["rolling_after"][-1, 0] in ("rolling", "rolling_fixed")


@pytest.mark.parametrize("model", ["exact", "sds"])
def test_the_floor_as_the_third_of_four_planes_stops_the_ball_as_alone(model):
    """The rolling part of any plane of the table: the floor third of four planes (a
    ceiling and two far walls first) stops a solid ball rolling at v0 as the floor alone
    does, at t = 7 v0 / (5 mu_r g) (exact; sds: the same within its spring's loading),
    with its own rolling spring states (``floor_rolling_x``, ...)."""
    mu_r, v0 = 0.05, 1.0
    planes = (ballc.Plane((0, 0, 2), (0, 0, -1), "ceiling"),
              ballc.Plane((-5, 0, 0), (1, 0, 0), "west"),
              ballc.Plane((0, 0, 0), (0, 0, 1), "floor"),
              ballc.Plane((0, 5, 0), (0, -1, 0), "north"))
    alone = stiff_scene(rolling_resistance=mu_r, rolling_model=model, velocity=(v0, 0, 0),
                        angular_velocity=(0, v0 / 0.1, 0))
    boxed = alone.replace(planes=planes)
    assert boxed.state_names[15 + 8:] == (
        "dissipated_rolling", "ceiling_rolling_x", "ceiling_rolling_y", "ceiling_twisting",
        "west_rolling_x", "west_rolling_y", "west_twisting", "floor_rolling_x",
        "floor_rolling_y", "floor_twisting", "north_rolling_x", "north_rolling_y",
        "north_twisting")
    t_stop = 7 * v0 / (5 * mu_r * G)
    runs = [ballc.simulate(s, 2 * t_stop, rtol=1e-9, atol=1e-10, rest=False)
            for s in (alone, boxed)]
    for r in runs:
        assert r.status == 0, r.message
    a, b = runs
    if model == "exact":
        assert stop_of(b, 2)[0] == pytest.approx(t_stop, rel=1e-7)
        assert stop_of(b, 2)[0] == pytest.approx(stop_of(a)[0], rel=1e-9)
    names = b.state_names
    np.testing.assert_allclose(b.y[names.index("x"), -1], a.y[S["x"], -1], rtol=1e-7)
    np.testing.assert_allclose(b.energy["dissipated_rolling"][-1],
                               a.energy["dissipated_rolling"][-1], rtol=1e-7)
    for other in ("ceiling", "west", "north"):   # springs of planes never touched: 0
        assert np.all(b.y[names.index(f"{other}_rolling_x")] == 0)


def test_a_ball_rolling_along_a_grooves_two_planes_stops_at_the_closed_form_time():
    """A V-groove of two planes at 40 degrees, the ball rolling along it without slip on
    both (each carrying N = m g / (2 cos a)): the two rolling torques mu_r r N add up to
    mu_r r m g about the groove's axis, and the ball decelerates at
    a = mu_r g cos(a) / (I/(m r^2) + cos(a)^2), stops at v0 / a, then stays held -- both
    planes' rolling parts and sticks solved together (_system.c's one Delassus solve)."""
    angle, mu_r, v0 = math.radians(40), 0.05, 0.5
    c = math.cos(angle)
    planes = (ballc.Plane((0, 0, 0), (math.sin(angle), 0, c), "left"),
              ballc.Plane((0, 0, 0), (-math.sin(angle), 0, c), "right"))
    base = stiff_scene(rolling_resistance=mu_r, friction_coefficient=0.6).replace(
        planes=planes, position=(0.0, 0.0, 0.5))
    rho = (G / (2 * c) / base.hertz_stiffness) ** (2 / 3)
    scene = base.replace(position=(0.0, 0.0, (0.1 - rho) / c), velocity=(0.0, v0, 0.0),
                         angular_velocity=(-v0 / (0.1 * c), 0.0, 0.0))
    a = mu_r * G * c / (0.4 + c * c)
    result = ballc.simulate(scene, 1.5 * v0 / a, rtol=1e-9, atol=1e-10, rest=False)
    assert result.status == 0, result.message
    assert stop_of(result)[0] == pytest.approx(v0 / a, rel=1e-7)
    mid = (result.t > 0.1 * v0 / a) & (result.t < 0.9 * v0 / a)
    assert np.polyfit(result.t[mid], result.velocity[1, mid], 1)[0] == pytest.approx(-a,
                                                                                     rel=1e-7)
    assert tuple(result.segments["before"][-1]) == ("stick", "stick")
    late = result.t > 1.05 * v0 / a
    assert np.abs(result.velocity[:, late]).max() < 1e-12
    assert np.abs(result.angular_velocity[:, late]).max() < 1e-11
    kinetic = 0.5 * v0 ** 2 + 0.5 * 0.004 * (v0 / (0.1 * c)) ** 2
    assert result.energy["dissipated_rolling"][-1] == pytest.approx(kinetic, rel=1e-7)
    assert np.ptp(result.energy["balance"]) < 1e-9 * kinetic


def test_the_dense_output_of_an_exact_flight_with_rolling_states_is_the_parabola():
    """A thrown ball with rolling resistance (its state holds the rolling block) flies in
    closed form (exact flight): its dense output in the flight is the parabola
    x0 + v0 t + g t^2 / 2, and its rolling states stay as they were (0)."""
    x0, v0 = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 2.0])
    scene = stiff_scene().replace(position=tuple(x0), velocity=tuple(v0))
    assert "dissipated_rolling" in scene.state_names
    result = ballc.simulate(scene, 0.3, dense_output=True, exact_flight=True)
    assert result.status == 0, result.message
    assert "flight" in set(result.segments["method"])
    t = np.linspace(0.0, 0.3, 7)
    y = result.sol(t)
    expected = x0[:, None] + v0[:, None] * t + 0.5 * np.array([0, 0, -G])[:, None] * t ** 2
    np.testing.assert_allclose(y[[S["x"], S["y"], S["z"]]], expected, rtol=0, atol=1e-12)
    rolling = [scene.state_names.index(n) for n in scene.state_names
               if n == "dissipated_rolling" or n.endswith(("rolling_x", "rolling_y", "twisting"))]
    assert len(rolling) == 1 + 3 * len(scene.planes) and np.all(y[rolling] == 0)
