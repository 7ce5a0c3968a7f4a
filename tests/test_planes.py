"""Planes at any orientation (issue 30b): the API, and the runs against closed forms.

* the API: ballc.Plane and Scene(planes=...), its validation (each message names the
  field and what is allowed), the layout (15 states and 2 per plane, named by the
  planes), [[planes]] in TOML files, a sweep of the planes' tilt;
* an incline at theta (exact Coulomb friction): a ball released on it rolls without slip
  with a = g sin(theta) / (1 + k), k = I / (m r^2), when mu >= tan(theta) / (1 + 1/k)
  (solid: 5/7 g sin(theta), mu_c = 2/7 tan(theta)), else it slides with
  a = g (sin(theta) - mu cos(theta)) while its spin grows at mu g cos(theta) r m / I;
  both sides of mu_c, a solid and a hollow ball.  The lever arm of the friction force is
  exactly r: the laws apply the contact force at the undeformed sphere's point -r n
  (codegen/contact.py), so the static penetration (here rho_eq = 1.1e-4 r) enters
  neither the rolling constraint v = r omega nor the torque r F_t;
* symmetry: the seed scene turned as a whole by a random rotation gives the same
  contacts and its trajectory turned back, with every tangential model;
* Hefner's vertical channel: ballc's rigid rough-ball map (e = e_t = 1) over one
  cycle (two walls) is a rotation by phi, cos(phi) = (1 - 6k + k^2) / (1 + k)^2, so the
  trapped ball's height oscillates with a period of 2 pi / phi cycles, 4 pi T / phi
  (T = (W - 2r) / |v_x| the flight between the walls); a compliant run of a stiff rough
  ball follows ballc's map with its own tangential restitution, contact by contact;
* two contacts at once: a ball rolling along a wedge's groove;
* a box of six planes: over 10 s the ball stays inside and the energy balance closes.
"""
import math

import numpy as np
import pytest

import ballc
from ballc import _core
from ballc.orientation import quaternion_multiply, rotation_matrix
from ballc.planes import Plane, box, channel, rotation_y, tilted, turned, wedge
from ballc.rigid import rigid_impact

G = 9.81


# -------------------------------------------------------------------------------------
# The API and its validation
# -------------------------------------------------------------------------------------

def test_the_seed_scene_is_unchanged():
    scene = ballc.Scene()
    assert scene.ceiling_height == 10.0 and scene.gravity == 9.81
    assert scene.plane_names == ("floor", "ceiling")
    assert scene.state_names == ballc.STATE_NAMES and len(ballc.STATE_NAMES) == 19
    assert ballc.STATE_NAMES[15:] == ("floor_deflection_x", "floor_deflection_y",
                                      "ceiling_deflection_x", "ceiling_deflection_y")
    assert scene.to_dict()["planes"] is None
    assert ballc.Scene.from_dict(scene.to_dict()) == scene
    floor, ceiling = scene.planes
    assert floor == Plane((0, 0, 0), (0, 0, 1), "floor")
    assert ceiling == Plane((0, 0, 10), (0, 0, -1), "ceiling")


def test_the_layout_follows_the_planes():
    scene = ballc.Scene(planes=box((4, 4, 4), (0, 0, 2)), radius=0.5, position=(0, 0, 2))
    assert len(scene.state_names) == 15 + 2 * 6
    assert scene.state_names[15:17] == ("floor_deflection_x", "floor_deflection_y")
    assert scene.state_names[-2:] == ("north_deflection_x", "north_deflection_y")
    assert scene.initial_state().shape == (27,)
    params = scene.parameter_vector()
    assert len(params) == len(scene.parameter_names) == 32 + 6 * 6   # rolling: 6 of 32
    assert params[scene.parameter_names.index("plane_count")] == 6
    unnamed = ballc.Scene(planes=[Plane(), Plane((0, 0, 3), (0, 0, -1))], position=(0, 0, 1.5))
    assert unnamed.plane_names == ("plane0", "plane1")


def test_gravity_a_number_or_a_vector():
    assert list(ballc.Scene().gravity_vector) == [0.0, 0.0, -9.81]
    scene = ballc.Scene(gravity=(1.0, 0.0, -9.0))
    assert scene.gravity == (1.0, 0.0, -9.0)
    assert scene.gravity_magnitude == pytest.approx(math.hypot(1, 9))
    for bad, allowed in (((1, 2), "3 finite numbers"), ((0, math.nan, 1), "3 finite numbers"),
                         (-1.0, ">= 0"), ("up", "real number")):
        with pytest.raises(ballc.SceneError, match=f"gravity.*{allowed}"):
            ballc.Scene(gravity=bad)


@pytest.mark.parametrize("normal", [(0, 0, 0), (0, math.nan, 1), (0, math.inf, 0), (1, 2)])
def test_a_bad_normal_is_named(normal):
    with pytest.raises(ballc.SceneError, match="normal"):
        ballc.Scene(planes=[Plane(normal=normal)])


def test_the_number_of_planes_is_one_to_six():
    with pytest.raises(ballc.SceneError, match="1 to 6 planes"):
        ballc.Scene(planes=())
    seven = box((4, 4, 4), (0, 0, 2)) + (Plane((0, 0, 1), (0, 1, 1), "extra"),)
    with pytest.raises(ballc.SceneError, match="7 given.*1 to 6"):
        ballc.Scene(planes=seven, position=(0, 0, 2))


def test_a_start_outside_the_planes_is_named():
    planes = channel(3.0)
    with pytest.raises(ballc.SceneError, match="position.*'ceiling'.*> 0"):
        ballc.Scene(planes=planes, position=(0, 0, 3.5))
    with pytest.raises(ballc.SceneError, match="position.*'floor'"):
        ballc.Scene(planes=planes, position=(0, 0, -0.1))
    scene = ballc.Scene(planes=planes, position=(0, 0, 1.5))
    with pytest.raises(ballc.SceneError, match="y0's position.*'ceiling'"):
        ballc.simulate(scene, 0.1, y0=np.r_[scene.initial_state()[:6], 4.0,
                                            scene.initial_state()[7:]])


def test_planes_that_leave_no_room_are_named():
    with pytest.raises(ballc.SceneError, match="'floor' and 'ceiling' leave no room.*1.9"):
        ballc.Scene(planes=channel(1.9), position=(0, 0, 0.95))
    walls = (Plane((0, 0, 0), (0, 0, 1), "a"), Plane((0, 0, 0), (1, 1, -1), "b"),
             Plane((0, 0, 0), (-1, 1, -1), "c"), Plane((0, 3, 0), (0, -1, 0), "d"))
    with pytest.raises(ballc.SceneError, match="leave no room"):   # a small pyramid
        ballc.Scene(planes=walls, radius=1.0, position=(0, 0.5, 0.2))


def test_ceiling_height_and_planes_are_one_or_the_other():
    with pytest.raises(ballc.SceneError, match="ceiling_height = 5.*given with planes"):
        ballc.Scene(planes=channel(6.0, 0.1), ceiling_height=5.0)
    with pytest.raises(ballc.SceneError, match="name = 'floor'.*another plane"):
        ballc.Scene(planes=(Plane(name="floor"), Plane((0, 0, 5), (0, 0, -1), "floor")))
    scene = ballc.Scene(planes=channel(6.0))
    assert scene.replace(ceiling_height=7.0).planes == ballc.Scene(ceiling_height=7.0).planes
    import dataclasses
    assert dataclasses.replace(ballc.Scene(), ceiling_height=7.0).planes[1].point[2] == 7.0


def test_planes_in_scene_files_round_trip(tmp_path):
    scene = ballc.Scene(planes=wedge(math.radians(50)), gravity=(0.5, 0.0, -9.8),
                        position=(2.0, 0.0, 0.5), radius=0.2)
    path = tmp_path / "wedge.toml"
    scene.to_toml(path)
    text = path.read_text()
    assert text.count("[[planes]]") == 2 and 'name = "upper"' in text
    assert ballc.Scene.from_toml(path) == scene
    path.write_text(text.replace('name = "upper"', 'name = "upper"\ntilt = 1'))
    with pytest.raises(ballc.SceneError, match="planes\\[1\\]: unknown field 'tilt'"):
        ballc.Scene.from_toml(path)


def test_a_sweep_tilts_the_planes():
    import importlib
    combinations = importlib.import_module("ballc.sweep").combinations
    cases = combinations(ballc.Scene(), {"planes.tilt": [0.0, 0.3], "planes.1.tilt": [0.1]})
    (_, flat), (changes, tilted_pair) = cases
    assert changes == {"planes.tilt": 0.3, "planes.1.tilt": 0.1}
    floor, ceiling = tilted_pair.planes
    assert np.allclose(floor.unit_normal, rotation_y(0.3) @ [0, 0, 1])
    assert np.allclose(ceiling.unit_normal, rotation_y(0.4) @ [0, 0, -1])
    assert flat.planes[0] == ballc.Scene().planes[0]
    nested = combinations(ballc.Scene(), {"planes": {"tilt": [0.3], "1": {"tilt": [0.1]}}})
    assert nested[0][1] == tilted_pair
    with pytest.raises(ballc.SceneError, match="planes.2.tilt.*2 planes"):
        combinations(ballc.Scene(), {"planes.2.tilt": [0.1]})


# -------------------------------------------------------------------------------------
# An incline at theta, exact Coulomb friction
# -------------------------------------------------------------------------------------

THETA = math.radians(25)
RADIUS, MASS = 0.1, 1.0


def incline_scene(mu, k):
    """A ball at rest on the incline at its static penetration, and the incline."""
    plane = tilted(Plane(name="incline"), THETA)
    n = plane.unit_normal
    down = np.array([math.cos(THETA), 0.0, -math.sin(THETA)])
    inertia = k * MASS * RADIUS ** 2
    scene = ballc.Scene(planes=(plane,), radius=RADIUS, mass=MASS, observer_mass=0.0,
                        inertia=(inertia,) * 3, ball_youngs_modulus=1e8,
                        tangential_model="friction", friction_coefficient=mu, c_tau=0.5,
                        position=(0.0, 0.0, 1.0), velocity=(0.0, 0.0, 0.0))
    load = MASS * G * math.cos(THETA)
    rho_eq = (load / scene.hertz_stiffness) ** (2 / 3)   # the Hertz force carries the load
    return scene.replace(position=tuple((RADIUS - rho_eq) * n)), plane


def incline_run(mu, k, t_end=0.4):
    """A ball released at rest on the incline, at its static penetration, integrated to
    t_end (rest=False: no end state): (result, the plane's unit normal, the downhill
    direction, the closed-form load m g cos(theta))."""
    scene, plane = incline_scene(mu, k)
    result = ballc.simulate(scene, t_end, rtol=1e-10, atol=1e-12, rest=False)
    assert result.status == 0, result.message
    n = plane.unit_normal
    down = np.array([math.cos(THETA), 0.0, -math.sin(THETA)])
    return result, n, down, MASS * G * math.cos(THETA)


@pytest.mark.parametrize("k", [0.4, 2 / 3], ids=["solid", "hollow"])
@pytest.mark.parametrize("side", [1.05, 0.95], ids=["rolls", "slides"])
def test_incline_against_the_closed_forms(k, side):
    mu_c = math.tan(THETA) / (1 + 1 / k)           # solid: 2/7 tan(theta)
    mu = side * mu_c
    result, n, down, load = incline_run(mu, k)
    t, v, w = result.t, result.velocity, result.angular_velocity
    axis = np.cross(n, down)                        # a spin that rolls downhill
    speed, spin = down @ v, axis @ w
    late = t > 0.1
    accel = np.polyfit(t[late], speed[late], 1)[0]
    spin_rate = np.polyfit(t[late], spin[late], 1)[0]
    if side > 1:   # rolls: a = g sin / (1 + k), v = r omega with the arm exactly r
        expected = G * math.sin(THETA) / (1 + k)
        assert accel == pytest.approx(expected, rel=1e-11)
        assert np.allclose(speed[late], RADIUS * spin[late], rtol=0, atol=1e-10)
        assert [c.transitions[-1][1] for c in result.contacts] == ["stick"]
    else:          # slides: a = g (sin - mu cos), spin-up mu N r / I
        assert accel == pytest.approx(G * (math.sin(THETA) - mu * math.cos(THETA)), rel=1e-11)
        assert spin_rate == pytest.approx(mu * load * RADIUS / (k * MASS * RADIUS ** 2),
                                          rel=1e-11)
        assert np.all(speed[late] > RADIUS * spin[late] + 1e-6)
    # no motion across the slope, none into the plane: the normal stays at rest
    assert np.max(np.abs(v[1])) < 1e-12 and np.max(np.abs(n @ v)) < 1e-9


def test_rolling_down_an_incline_ends_in_closed_form():
    """Rolling down the unbounded incline (massless observer, isotropic inertia) ends in
    closed form at a rest check: uniformly accelerated at 5/7 g sin(theta), the state at
    t_end (and the dense output) that of the integration without end states; sliding, a
    wall ahead, or a throw across the slope do not, and the message says why."""
    mu_c = math.tan(THETA) / (1 + 1 / 0.4)
    scene, plane = incline_scene(1.05 * mu_c, 0.4)
    ended = ballc.simulate(scene, 4.0, rtol=1e-10, atol=1e-12, dense_output=True)
    whole = ballc.simulate(scene, 4.0, rtol=1e-10, atol=1e-12, rest=False)
    assert ended.status == whole.status == 0
    a = G * math.sin(THETA) / 1.4
    assert f"uniformly accelerated at {a:.6g} m/s^2" in ended.message
    assert 0 < ended.contacts[-1].t_rolling < 1.0 and ended.nfev < whole.nfev / 10
    for rows in (slice(4, 7), slice(7, 10), slice(10, 13)):
        assert np.allclose(ended.y[rows, -1], whole.y[rows, -1], rtol=1e-9, atol=1e-9)
    t = np.linspace(ended.contacts[-1].t_rolling, 4.0, 7)
    index = np.searchsorted(whole.t, t)
    assert np.allclose(ended.sol(whole.t[index])[4:13], whole.y[4:13, index], rtol=1e-9,
                       atol=1e-9)
    q_end, q_whole = ended.y[0:4, -1], whole.y[0:4, -1]
    assert min(np.abs(q_end - q_whole).max(), np.abs(q_end + q_whole).max()) < 1e-7
    # sliding: no closed form
    sliding = ballc.simulate(incline_scene(0.95 * mu_c, 0.4)[0], 1.0)
    assert "incline, whose normal is not opposite gravity" in sliding.message
    # a wall across the slope 3 m down (reached at ~1.6 s): no closed form before it
    wall = Plane((3.0 * math.cos(THETA), 0.0, -3.0 * math.sin(THETA)),
                 (-math.cos(THETA), 0.0, math.sin(THETA)), "wall")
    walled = ballc.simulate(scene.replace(planes=(plane, wall)), 3.0)
    assert "wall" in [c.plane for c in walled.contacts]
    assert math.isnan(walled.contacts[0].t_rolling)
    # thrown across the slope: it never rolls straight down, no closed form
    across = ballc.simulate(scene.replace(velocity=(0.0, 1.0, 0.0)), 1.0)
    assert math.isnan(across.contacts[-1].t_rolling)
    assert "straight down the slope" in across.message


# -------------------------------------------------------------------------------------
# Symmetry: the seed turned as a whole
# -------------------------------------------------------------------------------------

def turned_seed(model, rotation_quaternion):
    """The seed (``model``) and the same scene turned by R as a whole: its planes,
    gravity, position, velocity, angular velocity and the ball's orientation (y0)."""
    base = ballc.Scene(tangential_model=model,
                       **({"friction_coefficient": 0.5} if model == "compliant" else {}))
    R = rotation_matrix(rotation_quaternion[None, :])[0]
    scene = base.replace(planes=tuple(turned(p, R) for p in base.planes),
                         gravity=tuple(R @ base.gravity_vector),
                         position=tuple(R @ base.position), velocity=tuple(R @ base.velocity),
                         angular_velocity=tuple(R @ base.angular_velocity))
    y0 = scene.initial_state()
    y0[0:4] = quaternion_multiply(rotation_quaternion, base.initial_state()[0:4])
    return base, scene, y0, R


@pytest.mark.parametrize("model", ["mixture", "friction", "dig-in", "compliant"])
def test_the_seed_turned_as_a_whole(model):
    q = np.random.default_rng(20261128).normal(size=4)
    q /= np.linalg.norm(q)
    base, scene, y0, R = turned_seed(model, q)
    t_end = 2.5
    a = ballc.simulate(base, t_end, dense_output=True)
    b = ballc.simulate(scene, t_end, y0=y0, dense_output=True)
    assert a.status == b.status == 0
    assert [c.plane for c in a.contacts] == [c.plane for c in b.contacts]
    assert len(a.contacts) >= 3
    for ca, cb in zip(a.contacts, b.contacts):
        assert cb.t_start == pytest.approx(ca.t_start, abs=1e-8)
        assert cb.t_end == pytest.approx(ca.t_end, abs=1e-8)
        assert np.allclose(R.T @ cb.velocity_after, ca.velocity_after, atol=1e-7)
        assert np.allclose(R.T @ cb.angular_velocity_after, ca.angular_velocity_after,
                           atol=1e-7)
        assert cb.max_penetration == pytest.approx(ca.max_penetration, abs=1e-8)
        assert cb.rebound_ratio == pytest.approx(ca.rebound_ratio, abs=1e-8)
    t = np.linspace(0, t_end, 400)
    ya, yb = a.sol(t), b.sol(t)
    for rows in (slice(4, 7), slice(7, 10), slice(10, 13)):
        assert np.allclose(R.T @ yb[rows], ya[rows], rtol=0, atol=1e-7)
    turned_back = quaternion_multiply(np.array([q[0], -q[1], -q[2], -q[3]]), yb[0:4].T).T
    assert np.allclose(turned_back, ya[0:4], atol=1e-7)
    assert np.allclose(yb[13:15], ya[13:15], rtol=1e-8, atol=1e-8)   # dissipated work
    # each plane's deflection, in its frame: the turned plane's frame is not R's image of
    # the first's, a turn within the plane
    frames_a = _core.plane_frames(base.parameter_vector())
    frames_b = _core.plane_frames(scene.parameter_vector())
    for p in range(2):
        rows = slice(15 + 2 * p, 17 + 2 * p)
        inertial = frames_a[p, :2].T @ ya[rows]               # s in inertial components
        in_b = frames_b[p, :2] @ (R @ inertial)
        assert np.allclose(in_b, yb[rows], rtol=0, atol=1e-9)


def test_a_turned_floor_keeps_its_end_state():
    """A ball without an observer (exact flight under the turned gravity vector) settles
    to uniform rolling on the turned floor, whose normal is opposite the turned gravity
    to rounding: the same end state from the same time, its state turned back."""
    q = np.random.default_rng(7).normal(size=4)
    q /= np.linalg.norm(q)
    R = rotation_matrix(q[None, :])[0]
    base = ballc.Scene(observer_mass=0.0, c_tau=0.5, velocity=(0.5, 0.0, -1.0),
                       position=(0.0, 0.0, 1.5))
    scene = base.replace(planes=tuple(turned(p, R) for p in base.planes),
                         gravity=tuple(R @ base.gravity_vector), position=tuple(R @ base.position),
                         velocity=tuple(R @ base.velocity))
    y0 = scene.initial_state()
    y0[0:4] = quaternion_multiply(q, base.initial_state()[0:4])
    a = ballc.simulate(base, 20.0, rtol=1e-8, atol=1e-8)
    b = ballc.simulate(scene, 20.0, rtol=1e-8, atol=1e-8, y0=y0)
    assert "rolls uniformly on the floor" in a.message and "at 0.357143 m/s" in a.message
    assert b.message.replace(f"{b.contacts[-1].t_rolling:.9g}", "T") == \
        a.message.replace(f"{a.contacts[-1].t_rolling:.9g}", "T")
    assert [c.t_start for c in b.contacts] == pytest.approx([c.t_start for c in a.contacts],
                                                            abs=1e-7)
    assert b.contacts[-1].t_rolling == pytest.approx(a.contacts[-1].t_rolling, abs=1e-7)
    for rows in (slice(4, 7), slice(7, 10), slice(10, 13)):
        assert np.allclose(R.T @ b.y[rows, -1], a.y[rows, -1], rtol=0, atol=1e-7)


# -------------------------------------------------------------------------------------
# Hefner's vertical channel
# -------------------------------------------------------------------------------------

WIDTH, R_BALL, M_BALL = 0.12, 0.025, 0.05
WALLS = (Plane((-WIDTH / 2, 0, 0), (1, 0, 0), "left"),
         Plane((WIDTH / 2, 0, 0), (-1, 0, 0), "right"))


def rigid_channel(velocity, spin, impacts, k, e_t=1.0):
    """ballc's rigid map (ballc.rigid.rigid_impact: e = 1, sticking, e_t) between the
    channel's walls, with exact flights: (t, centre, v, omega) after each impact."""
    c, v, w, t = np.zeros(3), np.array(velocity, float), np.array(spin, float), 0.0
    g = np.array([0.0, 0.0, -G])
    out = []
    for _ in range(impacts):
        wall = WALLS[1] if v[0] > 0 else WALLS[0]
        x_hit = (WIDTH / 2 - R_BALL) * (1 if v[0] > 0 else -1)
        dt = (x_hit - c[0]) / v[0]
        c, v, t = c + v * dt + 0.5 * g * dt * dt, v + g * dt, t + dt
        hit = rigid_impact(v, w, mass=M_BALL, radius=R_BALL, inertia=k * M_BALL * R_BALL ** 2,
                           restitution=1.0, friction_coefficient=1e12,
                           tangential_restitution=e_t, plane=wall)
        v, w = hit.velocity, hit.angular_velocity
        out.append((t, c.copy(), v.copy(), w.copy()))
    return out


@pytest.mark.parametrize("k", [0.4, 2 / 3, 0.1])
def test_hefner_channel_rotation_from_ballcs_map(k):
    """One cycle (right wall, left wall) of ballc's map, linear in (v_z, r omega_y): a
    rotation by phi with cos(phi) = (1 - 6k + k^2) / (1 + k)^2 (det 1, no damping), so
    the height at every second impact is A + B cos(phi n) + C sin(phi n): the trapped
    ball oscillates with a period of 2 pi / phi cycles."""
    def cycle(vz, s):
        hits = rigid_channel((2.0, 0.0, vz), (0.0, s / R_BALL, 0.0), 2, k)
        v, w = hits[-1][2], hits[-1][3]
        return np.array([v[2], R_BALL * w[1]])
    # the linear part: gravity's kicks drop out of differences
    base = cycle(0.0, 0.0)
    M = np.column_stack([cycle(1.0, 0.0) - base, cycle(0.0, 1.0) - base])
    cos_phi = (1 - 6 * k + k * k) / (1 + k) ** 2
    assert np.trace(M) / 2 == pytest.approx(cos_phi, abs=1e-12)
    assert np.linalg.det(M) == pytest.approx(1.0, abs=1e-12)
    phi = math.acos(cos_phi)
    hits = rigid_channel((2.0, 0.0, -1.0), (0.0, 0.0, 0.0), 120, k)
    z = np.array([hit[1][2] for hit in hits[1::2]])   # at the right wall
    n = np.arange(z.size)
    basis = np.column_stack([np.ones_like(n), np.cos(phi * n), np.sin(phi * n)])
    fit, *_ = np.linalg.lstsq(basis, z, rcond=None)
    assert np.max(np.abs(basis @ fit - z)) < 1e-12          # exactly that oscillation
    assert np.ptp(z) > 0.01 and np.max(np.abs(z)) < 0.2     # trapped, oscillating
    period = 2 * math.pi / phi * 2 * (WIDTH - 2 * R_BALL) / 2.0   # s
    assert period == pytest.approx(4 * math.pi * (WIDTH - 2 * R_BALL) / 2.0 / phi)


def test_hefner_channel_compliant_ball_follows_the_map():
    """A stiff rough superball with ballc's compliant law (restitution 1, mu = 10,
    kappa = 0.27, no tangential damping) in the channel: its tangential restitution is
    e_t ~ 0.83 (the passive law's unloading loses the rest), and contact by contact its
    height, vertical speed and spin follow ballc's rigid map with that e_t (the contacts
    last 0.35 ms, in which the map's instantaneous impacts fall behind by a contact's
    time each) -- the 'damped oscillator and falling body' of Hefner's e_t < 1.

    atol 1e-10, not 1e-11 (the error message's advice for contacts): at 1e-11 the end
    of a sliding contact (rho -> 0, where the spring's rate follows the shrinking cap,
    ~rho'/rho, and rho carries the rounding of the wall's position) is approached in
    steps of ~10 ulp(t) with Newton's increments at that rounding, and 4 in 1000
    throws perturbed by k 1e-13 m/s fail (docs/limits.md); at 1e-10 none does."""
    scene = ballc.Scene(planes=WALLS, radius=R_BALL, mass=M_BALL, observer_mass=0.0,
                        ball_youngs_modulus=1e9, plane_youngs_modulus=2e11,
                        ball_poisson_ratio=0.49, tangential_model="compliant",
                        friction_coefficient=10.0, restitution=1.0,
                        tangential_stiffness_ratio=0.27, tangential_damping_ratio=0.0,
                        position=(0.0, 0.0, 0.0), velocity=(2.0, 0.0, -1.0))
    result = ballc.simulate(scene, 1.0, rtol=1e-9, atol=1e-10)
    assert result.status == 0 and len(result.contacts) == 28
    ratios = []
    for c in result.contacts:
        def slip(v, w):
            u = v + np.cross(w, -R_BALL * c.normal)
            return u - (u @ c.normal) * c.normal
        before = slip(c.velocity_before, c.angular_velocity_before)
        ratios.append(-(slip(c.velocity_after, c.angular_velocity_after) @ before)
                      / (before @ before))
        assert c.rebound_ratio == pytest.approx(1.0, abs=2e-4)
    e_t = float(np.mean(ratios))
    assert 0.8 < e_t < 0.87 and np.std(ratios) < 0.003
    hits = rigid_channel((2.0, 0.0, -1.0), (0.0, 0.0, 0.0), len(result.contacts), 0.4, e_t)
    for k, (c, (t, centre, v, w)) in enumerate(zip(result.contacts, hits)):
        assert c.t_start - t == pytest.approx(k * c.duration, abs=2e-4)
        z = result.position[2][np.searchsorted(result.t, c.t_start)]
        assert z == pytest.approx(centre[2], abs=2e-3)
        assert c.velocity_after[2] == pytest.approx(v[2], abs=1e-2)
        assert c.angular_velocity_after[1] == pytest.approx(w[1], abs=0.5)
    heights = result.position[2]
    assert heights.min() > -0.1 and heights[-1] < -0.05   # sinks slowly: free fall 4.9 m


# -------------------------------------------------------------------------------------
# Two contacts at once; a box of six planes
# -------------------------------------------------------------------------------------

def test_rolling_along_a_wedges_groove():
    """Thrown into a V of two planes at 40 degrees, the ball ends rolling along the
    groove on both planes at once (both sticking, solved jointly): no slip at either
    contact point, v_y = -r cos(40) omega_x, at a constant speed, energy balanced."""
    a = math.radians(40)
    planes = (Plane((0, 0, 0), (math.sin(a), 0, math.cos(a)), "left"),
              Plane((0, 0, 0), (-math.sin(a), 0, math.cos(a)), "right"))
    scene = ballc.Scene(planes=planes, radius=0.1, observer_mass=0.0, ball_youngs_modulus=1e7,
                        tangential_model="friction", friction_coefficient=0.6, c_tau=0.5,
                        position=(0.02, 0.0, 0.3), velocity=(0.5, 0.2, 0.0),
                        angular_velocity=(0.0, 3.0, 0.0))
    result = ballc.simulate(scene, 2.0, rtol=1e-8, atol=1e-10)
    assert result.status == 0, result.message
    last = result.segments[-1]
    assert list(last["before"]) == ["stick", "stick"] and last["end"] == "t_end"
    late = result.t > 1.5
    v, w = result.velocity[:, late], result.angular_velocity[:, late]
    assert np.ptp(v[1]) < 1e-9 and abs(v[1, -1]) > 0.05
    assert np.allclose(v[1], -0.1 * math.cos(a) * w[0], rtol=0, atol=1e-9)
    assert np.max(np.abs(v[[0, 2]])) < 1e-9
    balance = result.energy["balance"]
    assert abs(balance[-1] - balance[0]) < 1e-6 * balance[0]
    assert "in contact with the right and the left at once" in result.message


def test_a_box_of_six_planes_holds_the_ball():
    walls = box((2.0, 2.0, 2.0), (0.0, 0.0, 1.0))
    scene = ballc.Scene(planes=walls, radius=0.2, mass=0.5, observer_mass=0.0,
                        ball_youngs_modulus=1e6, c_tau=0.97, friction_coefficient=0.2,
                        position=(0.3, 0.3, 1.2), velocity=(4.0, 6.0, 7.0))
    result = ballc.simulate(scene, 10.0, rtol=1e-8, atol=1e-9)
    assert result.status == 0, result.message
    assert len({c.plane for c in result.contacts}) == 6
    for plane in scene.planes:   # the centre never leaves, never within r/2 of a wall
        heights = plane.unit_normal @ (result.position - np.array(plane.point)[:, None])
        assert heights.min() > 0.5 * scene.radius
    balance = result.energy["balance"]
    assert abs(balance[-1] - balance[0]) < 1e-6 * balance[0]
    assert result.energy["dissipated"][-1] > 0


# -------------------------------------------------------------------------------------
# Pictures: each plane where it is, the contact table naming the plane
# -------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def wedge_run():
    scene = ballc.Scene(planes=wedge(math.radians(50)), radius=0.2, observer_mass=0.0,
                        position=(2.0, 0.0, 0.5), velocity=(-3.0, 0.5, 1.0))
    return ballc.simulate(scene, 1.2)


def test_the_contact_table_names_the_plane(wedge_run):
    table = wedge_run.contact_table()
    planes = [c.plane for c in wedge_run.contacts]
    assert set(planes) == {"lower", "upper"}
    rows = table.splitlines()[3:3 + len(planes)]
    assert [row.split()[1] for row in rows] == planes
    frame = wedge_run.contacts_dataframe()
    assert list(frame["plane"]) == planes and "contact_point_z" in frame


def _on_plane(points, plane, tol=1e-9):
    return np.allclose(np.asarray(points) @ plane.unit_normal, plane.offset, atol=tol)


def test_figures_draw_each_plane_where_it_is(wedge_run, tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from ballc.plot import contact_points
    scene = wedge_run.scene
    for contact, point in zip(wedge_run.contacts, contact_points(wedge_run)):
        assert _on_plane([point], scene.planes[scene.plane_names.index(contact.plane)])
    fig, ax = wedge_run.plot_side_view()
    drawn = {line.get_label(): line.get_xydata() for line in ax.get_lines()}
    for plane, name in zip(scene.planes, scene.plane_names):
        xz = drawn[f"plane {name}"]   # the plane contains the y axis: its (x, z) line
        n = plane.unit_normal
        assert len(xz) >= 3 and np.allclose(xz @ n[[0, 2]], plane.offset, atol=1e-9)
    matplotlib.pyplot.close(fig)
    animation = wedge_run.animate(tmp_path / "wedge.gif", frames=2)
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    polygons = [c for c in animation._fig.axes[0].collections if isinstance(c, Poly3DCollection)]
    assert len(polygons) == 2
    matplotlib.pyplot.close(animation._fig)


def test_the_html_view_puts_each_plane_where_it_is(wedge_run):
    pytest.importorskip("meshcat")
    from test_html_view import commands
    from ballc.html_view import scene_html
    page = commands(scene_html(wedge_run))
    base = "/meshcat/ballc/planes"
    for plane, name in zip(wedge_run.scene.planes, wedge_run.scene.plane_names):
        matrix = np.asarray(page["set_transform"][f"{base}/{name}"]["matrix"]).reshape(
            4, 4, order="F")   # three.js: column-major
        assert np.allclose(matrix[:3, 2], plane.unit_normal)      # the slab's normal
        depth = page["set_object"][f"{base}/{name}"]["object"]["geometries"][0]["depth"]
        face = matrix[:3, 3] + 0.5 * depth * plane.unit_normal     # its face towards the ball
        assert _on_plane([face], plane)


def test_ballc_run_takes_a_scene_file_with_planes(tmp_path, capsys):
    """`ballc run` on a TOML file with [[planes]]: the contact table names the planes and
    the side view is written with the other figures."""
    from ballc.cli import main
    scene = ballc.Scene(planes=channel(3.0, math.radians(10)), radius=0.3,
                        observer_mass=0.0, position=(0.0, 0.0, 1.5), velocity=(-2.0, 0.0, -4.0))
    scene.to_toml(tmp_path / "channel.toml")
    code = main(["run", str(tmp_path / "channel.toml"), "--t-end", "1.5", "--out",
                 str(tmp_path / "out")])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert " 1 floor " in printed.out   # the contact table names the plane
    written = {p.name for p in (tmp_path / "out").iterdir()}
    assert {"side_view.png", "contacts_top_view.png", "contacts.csv"} <= written


def test_impact_needs_the_seeds_planes():
    with pytest.raises(ballc.SceneError, match="ceiling_height \\(not planes\\)"):
        ballc.impact(ballc.Scene(planes=channel(5.0), position=(0, 0, 2)), (1.0, 0.0, -2.0))
