"""The contact kernel in a plane's own frame (issue 30a).

codegen derives every contact law once, in a plane's own frame (the plane z = 0, normal
+z); the C core applies it to each plane of the plane table (a point and a normal per
plane, in the parameters) by turning the contact into that frame and the forces back
(src/ballc/_plane.c).  Checked here through the compiled system itself:

* equivariance: the whole scene turned by a random rotation R and shifted by p --
  planes (given with normals of other lengths than 1), gravity, position, velocity,
  orientation, angular velocity, the latched dig-in direction -- and each plane's
  tangential quantities (deflection, slip direction) carried into the frame the C core
  builds for the turned plane: the state derivative turns with the scene, the contact
  forces with R, and the scalars (dissipation rates, energies but the potential's shift
  -M g'.p, margins, the normal load) stay; the Jacobian is T J T^T; for every law and mode,
  on both planes;
* the ceiling is the floor turned by pi about x: its frame is (x, -y, -z), and the
  ceiling's contact of the turned state is the floor's contact turned;
* a ball sticking on an incline (exact Coulomb friction, stick) against the closed form
  of rolling without slip: the load m g cos(theta), the constraint force
  m g sin(theta) k / (1 + k) up the slope (k = I / (m r^2)), the acceleration
  g sin(theta) / (1 + k) down it and the rolling spin-up.
"""
import math
import zlib

import numpy as np
import pytest

import ballc
from ballc import _core
from ballc.orientation import quaternion_multiply, rotation_matrix

S = _core.STATE_INDEX
P = {name: i for i, name in enumerate(_core.PARAMETER_NAMES)}
F = _core.FLAGS
PLANES = ("floor", "ceiling")
NLP = _core.N_LATCH_PER_PLANE
_DIGIN = _core.LATCH_NAMES.index("floor_digin_direction_x")
_SLIP = _core.LATCH_NAMES.index("floor_slip_direction_x")
Q, POS, W, V = slice(0, 4), slice(4, 7), slice(7, 10), slice(10, 13)
DEFLECTION = {plane: slice(S[f"{plane}_deflection_x"], S[f"{plane}_deflection_x"] + 2)
              for plane in PLANES}


def plane_entry(plane, field):
    return P[f"{plane}_{field}"]


def point_and_normal(params, plane):
    i = plane_entry(plane, "point_x")
    return params[i:i + 3].copy(), params[i + 3:i + 6].copy()


def set_plane(params, plane, point, normal):
    i = plane_entry(plane, "point_x")
    params[i:i + 3] = point
    params[i + 3:i + 6] = normal


def gravity(params):
    return params[[P["gravity_x"], P["gravity_y"], P["gravity_z"]]]


# -------------------------------------------------------------------------------------
# The laws and modes, as (scene fields, flags of a plane)
# -------------------------------------------------------------------------------------

COMPLIANT = dict(tangential_model="compliant")
VISCOELASTIC = dict(tangential_model="compliant", normal_damping="viscoelastic",
                    restitution=0.6)


def law_flags(*names):
    return lambda plane: sum(F[f"{plane}_{name}"] for name in names)


CASES = {
    "friction": ({}, law_flags("friction")),
    "smooth friction": (dict(friction_regularization="smooth"), law_flags("friction")),
    "dig-in": ({}, law_flags("digin")),
    "mixture": ({}, law_flags("friction", "digin")),
    "exact slip": ({}, law_flags("friction", "digin", "slip")),
    "exact slip, fixed direction": ({}, law_flags("friction", "slip_fixed")),
    "exact stick": ({}, law_flags("friction", "digin", "stick")),
    "compliant": (COMPLIANT, law_flags("compliant")),
    "compliant elastic": (COMPLIANT, law_flags("compliant_elastic")),
    "compliant sliding": (COMPLIANT, law_flags("compliant_sliding")),
    "compliant viscoelastic": (VISCOELASTIC, law_flags("compliant")),
    "compliant viscoelastic elastic": (VISCOELASTIC, law_flags("compliant_elastic")),
    "compliant viscoelastic sliding": (VISCOELASTIC, law_flags("compliant_sliding")),
}


def case(name, observer):
    fields, flags_of = CASES[name]
    scene = ballc.Scene(**fields, observer_mass=0.05 if observer else 0.0,
                        inertia=(0.35, 0.4, 0.45))
    observer_flag = F["observer"] if observer else 0
    return scene, lambda plane: flags_of(plane) | observer_flag


def contact_state(rng, scene, plane):
    """A random state in contact with ``plane`` of the untouched scene (0 < rho < r/4),
    random orientation, spin, velocity, deflections and dissipated work."""
    r, h = scene.radius, scene.ceiling_height
    rho = rng.uniform(0.02, 0.25) * r
    y = np.zeros(_core.N_STATES)
    q = rng.normal(size=4)
    y[Q] = q / np.linalg.norm(q)
    y[S["x"]], y[S["y"]] = rng.uniform(-3, 3, 2)
    y[S["z"]] = r - rho if plane == "floor" else h - r + rho
    y[W] = rng.uniform(-8, 8, 3)
    y[V] = rng.uniform(-6, 6, 3)
    y[S["dissipated_normal"]], y[S["dissipated_tangential"]] = rng.uniform(0, 5, 2)
    for p in PLANES:
        y[DEFLECTION[p]] = rng.normal(size=2) * 1e-3 * r
    return y


def random_latch(rng):
    latch = np.zeros(_core.N_LATCH)
    for k in range(len(PLANES)):
        d = rng.normal(size=3)
        e = rng.normal(size=2)
        latch[k * NLP] = rng.uniform(1, 20)
        latch[k * NLP + _DIGIN:k * NLP + _DIGIN + 3] = d / np.linalg.norm(d)
        latch[k * NLP + _SLIP:k * NLP + _SLIP + 2] = e / np.linalg.norm(e)
    return latch


# -------------------------------------------------------------------------------------
# A motion of the whole scene: x -> p + R x, and what it does to each part of the state
# -------------------------------------------------------------------------------------

class Motion:
    """The scene turned by R = rotation_matrix(q_R) and shifted by p; ``tangent[plane]``
    (2 x 2) carries a plane's tangential components (its frame before) into the frame the
    C core builds for the turned plane; ``slots`` maps each plane to the plane it becomes
    (the ceiling test swaps them)."""

    def __init__(self, q_rotation, shift, params, turned_params, slots=None):
        self.q = np.asarray(q_rotation, dtype=float)
        self.R = rotation_matrix(self.q)
        self.p = np.asarray(shift, dtype=float)
        self.slots = slots or {plane: plane for plane in PLANES}
        before, after = _core.plane_frames(params), _core.plane_frames(turned_params)
        self.frames = after
        self.tangent = {}
        for i, plane in enumerate(PLANES):
            j = PLANES.index(self.slots[plane])
            self.tangent[plane] = after[j][:2] @ self.R @ before[i][:2].T
            # the turned plane's normal is R n (unit, whatever length it was given with)
            np.testing.assert_allclose(after[j][2], self.R @ before[i][2], atol=1e-14)

    def rate(self, f):
        """T_* of a state derivative (or of any state difference): linear."""
        out = f.copy()
        out[Q] = quaternion_multiply(self.q, f[Q])
        out[POS] = self.R @ f[POS]
        out[W] = self.R @ f[W]
        out[V] = self.R @ f[V]
        for plane in PLANES:
            out[DEFLECTION[self.slots[plane]]] = self.tangent[plane] @ f[DEFLECTION[plane]]
        return out

    def state(self, y):
        out = self.rate(y)
        out[POS] += self.p
        return out

    def matrix(self):
        """T as a matrix: the linear part of the motion of a state."""
        return np.column_stack([self.rate(e) for e in np.eye(_core.N_STATES)])

    def latch(self, latch):
        out = latch.copy()
        for i, plane in enumerate(PLANES):
            j = PLANES.index(self.slots[plane])
            block = latch[i * NLP:(i + 1) * NLP]
            new = out[j * NLP:(j + 1) * NLP]
            new[:] = block
            new[_DIGIN:_DIGIN + 3] = self.R @ block[_DIGIN:_DIGIN + 3]   # inertial
            new[_SLIP:_SLIP + 2] = self.tangent[plane] @ block[_SLIP:_SLIP + 2]   # its frame
        return out


def random_rotation(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def turned_scene(rng, params):
    """(q_R, p, turned parameters): planes and gravity turned and shifted, each plane's
    normal given with a random length (the C core normalises it)."""
    q_rotation, shift = random_rotation(rng), rng.uniform(-2, 2, 3)
    R = rotation_matrix(q_rotation)
    turned = params.copy()
    for plane in PLANES:
        point, normal = point_and_normal(params, plane)
        set_plane(turned, plane, shift + R @ point, rng.uniform(0.3, 3.0) * (R @ normal))
    turned[[P["gravity_x"], P["gravity_y"], P["gravity_z"]]] = R @ gravity(params)
    return q_rotation, shift, turned


def scale_of(values):
    return float(np.max(np.abs(values))) + 1e-300


def assert_turned(actual, expected, what, rtol=1e-11):
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale_of(expected),
                               err_msg=what)


def check_equivariance(scene, flags, y, latch, params, turned, motion, plane, with_jacobian):
    """Every output of the system at (y, params) against (motion(y), turned); returns
    whether the plane's contact force was not zero (a damped law may clamp it)."""
    turned_plane = motion.slots[plane]
    y2, latch2 = motion.state(y), motion.latch(latch)
    flags2 = flags(turned_plane)
    flags1 = flags(plane)
    f1 = _core.rhs(y, params, latch, flags1)
    f2 = _core.rhs(y2, turned, latch2, flags2)
    assert_turned(f2, motion.rate(f1), "state derivative")

    forces1 = _core.contact_forces(y[None, :], params, latch, flags1)[0].reshape(2, 3)
    forces2 = _core.contact_forces(y2[None, :], turned, latch2, flags2)[0].reshape(2, 3)
    i, j = PLANES.index(plane), PLANES.index(turned_plane)
    assert_turned(forces2[j], motion.R @ forces1[i], "contact force")

    e1 = _core.energies(y[None, :], params)[0]
    e2 = _core.energies(y2[None, :], turned)[0]
    mass = scene.mass + scene.observer_mass
    shift = -mass * gravity(turned) @ motion.p
    assert e2[0] == pytest.approx(e1[0], rel=1e-12)                       # kinetic
    assert e2[1] == pytest.approx(e1[1] + shift, rel=1e-12, abs=1e-12 * mass * 10)
    for k in (2, 4):                                                     # the springs
        assert e1[k + i] > 0 or k == 4
        assert e2[k + j] == pytest.approx(e1[k + i], rel=1e-11, abs=1e-300)

    kin1 = _core.contact_kinematics(y[None, :], params)[0].reshape(2, 5)
    kin2 = _core.contact_kinematics(y2[None, :], turned)[0].reshape(2, 5)
    assert kin2[j, 0] == pytest.approx(kin1[i, 0], rel=1e-12)              # rho
    assert kin2[j, 1] == pytest.approx(kin1[i, 1], rel=1e-11, abs=1e-12)   # rhodot
    assert_turned(kin2[j, 2:], motion.R @ kin1[i, 2:], "contact-point velocity")

    u1 = _core.slip_map(params, i) @ y
    u2 = _core.slip_map(turned, j) @ y2
    assert_turned(u2, motion.tangent[plane] @ u1, "slip velocity")

    if flags1 & F[f"{plane}_stick"]:
        s1 = _core.stick_state(y, params, latch, flags1, i)
        s2 = _core.stick_state(y2, turned, latch2, flags2, j)
        assert_turned(s2[:2], motion.tangent[plane] @ s1[:2], "stick constraint force", 1e-10)
        assert s2[2] == pytest.approx(s1[2], rel=1e-11)                  # the load N
        assert s2[3] == pytest.approx(s1[3], rel=1e-9, abs=1e-10 * s1[2])   # mu N - |lambda|
        base = flags1 & ~F[f"{plane}_stick"]
        moved1 = _core.remove_slip(y, params, base, i)
        moved2 = _core.remove_slip(y2, turned, flags2 & ~F[f"{turned_plane}_stick"], j)
        assert_turned(moved2, motion.state(moved1), "state with the slip removed")
    if flags1 & (F[f"{plane}_compliant"] | F[f"{plane}_compliant_elastic"]
                 | F[f"{plane}_compliant_sliding"]):
        m1 = _core.compliant_margins(y, params, latch, i)
        m2 = _core.compliant_margins(y2, turned, latch2, j)
        # each margin to 1e-9 of the terms it is a difference of
        scales = [1.0, scale_of(y[V]) + scene.radius * scale_of(y[W]), m1[2], m1[3],
                  abs(m1[4]) + m1[2] * m1[3], abs(m1[5]) + m1[2] * m1[3]]
        assert np.all(np.abs(m2 - m1) <= 1e-9 * np.array(scales)), ("margins", m1, m2)
    if with_jacobian:
        T = motion.matrix()
        j1 = _core.jacobian(y, params, latch, flags1)
        j2 = _core.jacobian(y2, turned, latch2, flags2)
        expected = T @ j1 @ T.T
        rows = np.max(np.abs(expected), axis=1, keepdims=True) + 1e-300
        assert np.all(np.abs(j2 - expected) <= 1e-9 * rows), "Jacobian"
    return bool(np.any(forces1[i] != 0))


@pytest.mark.parametrize("observer", [False, True], ids=["no observer", "observer"])
@pytest.mark.parametrize("name", list(CASES))
def test_the_kernel_turns_with_the_scene(name, observer):
    """For every law and mode, on both planes: the system's outputs at a random contact
    state against those at the scene turned by a random rotation and shift."""
    rng = np.random.default_rng(zlib.crc32(f"{name} {observer}".encode()))
    scene, flags = case(name, observer)
    params = scene.parameter_vector()
    for plane in PLANES:
        loaded = 0
        for _ in range(3):
            y, latch = contact_state(rng, scene, plane), random_latch(rng)
            q_rotation, shift, turned = turned_scene(rng, params)
            motion = Motion(q_rotation, shift, params, turned)
            loaded += check_equivariance(scene, flags, y, latch, params, turned, motion, plane,
                                         with_jacobian="stick" not in name)
        assert loaded   # a force that could have been turned wrong


def test_frames_are_orthonormal_and_right_handed_with_the_unit_normal():
    """The frame the C core builds for any normal (of any length): rows t1, t2, n
    orthonormal, t1 x t2 = n, n the normal divided by its length; the seed's floor
    (x, y, z) and ceiling (x, -y, -z)."""
    rng = np.random.default_rng(30)
    params = ballc.Scene().parameter_vector()
    frames = _core.plane_frames(params)
    np.testing.assert_array_equal(frames[0], np.eye(3))
    np.testing.assert_array_equal(frames[1], np.diag([1.0, -1.0, -1.0]))
    for _ in range(50):
        normals = [rng.normal(size=3) * 10 ** rng.uniform(-3, 3) for _ in PLANES]
        for plane, normal in zip(PLANES, normals):
            set_plane(params, plane, rng.normal(size=3), normal)
        for frame, normal in zip(_core.plane_frames(params), normals):
            np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-15)
            np.testing.assert_allclose(np.cross(frame[0], frame[1]), frame[2], atol=1e-15)
            np.testing.assert_allclose(frame[2], normal / np.linalg.norm(normal), atol=1e-15)


@pytest.mark.parametrize("name", list(CASES))
def test_the_ceiling_is_the_floor_turned_by_pi(name):
    """The ceiling (point (0, 0, H), normal -z) is the floor turned by pi about x and
    lifted by H: with gravity turned too, its contact of the turned state equals the
    floor's contact turned -- the same law, in the frame (x, -y, -z)."""
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    scene, flags = case(name, observer=True)
    params = scene.parameter_vector()
    turned = params.copy()
    turned[P["gravity_z"]] = -params[P["gravity_z"]]
    q_pi = np.array([0.0, 1.0, 0.0, 0.0])   # pi about x
    motion = Motion(q_pi, (0.0, 0.0, scene.ceiling_height), params, turned,
                    slots={"floor": "ceiling", "ceiling": "floor"})
    np.testing.assert_array_equal(motion.tangent["floor"], np.eye(2))
    loaded = 0
    for _ in range(4):
        y, latch = contact_state(rng, scene, "floor"), random_latch(rng)
        loaded += check_equivariance(scene, flags, y, latch, params, turned, motion, "floor",
                                     with_jacobian="stick" not in name)
    assert loaded


@pytest.mark.parametrize("inertia_ratio", [0.4, 2 / 3], ids=["solid", "hollow"])
@pytest.mark.parametrize("theta", [0.3, 1.0])
def test_a_ball_sticking_on_an_incline_rolls_as_the_closed_form(theta, inertia_ratio):
    """A ball at rest on a plane tilted by theta (normal at a random azimuth, given 1.7
    times too long, through a random point), at the static penetration m g cos(theta) =
    k0 rho^(3/2), sticking (exact Coulomb friction): the stick constraint keeps the
    contact point at rest, so the ball rolls without slip.  Closed form (the contact
    point at distance r from the centre: ballc's lever arm, whatever the penetration),
    k = I / (m r^2): load N = m g cos(theta); constraint force m g sin(theta) k / (1 + k)
    up the slope; acceleration g sin(theta) / (1 + k) down it, none across the plane;
    angular acceleration n x a / r; stick margin mu N - |lambda|."""
    rng = np.random.default_rng(int(1000 * theta + 10 * inertia_ratio))
    m, r, g, mu = 1.3, 0.8, 9.81, 2.0
    scene = ballc.Scene(mass=m, radius=r, gravity=g, observer_mass=0.0,
                        inertia=(inertia_ratio * m * r * r,) * 3, tangential_model="friction",
                        friction_coefficient=mu, ceiling_height=10.0)
    params = scene.parameter_vector()
    phi = rng.uniform(0, 2 * np.pi)
    n = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                  math.cos(theta)])
    point = rng.uniform(-2, 2, 3)
    set_plane(params, "floor", point, 1.7 * n)
    k0 = _core.hertz_stiffness(params)
    rho = (m * g * math.cos(theta) / k0) ** (2 / 3)
    y = np.zeros(_core.N_STATES)
    y[Q] = random_rotation(rng)
    y[POS] = point + (r - rho) * n
    latch = np.zeros(_core.N_LATCH)
    latch[0] = 1.0                       # rhodot^- (no rate: the bracket is 1)
    latch[_SLIP:_SLIP + 2] = (1.0, 0.0)
    flags = F["floor_friction"] | F["floor_stick"]

    up = np.array([0.0, 0.0, 1.0]) - n[2] * n      # up the slope, along the plane
    up /= np.linalg.norm(up)
    k = inertia_ratio
    lam_x, lam_y, load, margin = _core.stick_state(y, params, latch, flags, 0)
    t1, t2, _ = _core.plane_frames(params)[0]
    force = lam_x * t1 + lam_y * t2
    assert load == pytest.approx(m * g * math.cos(theta), rel=1e-12)
    np.testing.assert_allclose(force, m * g * math.sin(theta) * k / (1 + k) * up,
                               rtol=0, atol=1e-12 * m * g)
    assert margin == pytest.approx(mu * load - np.linalg.norm(force), rel=1e-12)

    f = _core.rhs(y, params, latch, flags)
    acceleration = -g * math.sin(theta) / (1 + k) * up
    np.testing.assert_allclose(f[V], acceleration, rtol=0, atol=1e-12 * g)
    np.testing.assert_allclose(f[W], np.cross(n, acceleration) / r, rtol=0, atol=1e-12 * g / r)
    np.testing.assert_allclose(f[POS], 0.0, atol=0)
    assert f[S["dissipated_normal"]] == 0 and f[S["dissipated_tangential"]] == 0
    # the contact force: the load along n plus the constraint force
    total = _core.contact_forces(y[None, :], params, latch, flags)[0][:3]
    np.testing.assert_allclose(total, load * n + force, rtol=0, atol=1e-12 * m * g)


def test_codegen_refuses_a_contact_law_that_depends_on_more_than_the_contact_state():
    """A plane kernel reads one contact in its plane's frame only: an expression of the
    orientation (a sphere's contact cannot depend on it) or of the position along the
    plane is refused when generated, naming the state."""
    sm = pytest.importorskip("sympy")
    from codegen.kernels import contact_state
    from codegen.model import build_model
    model = build_model()
    z, qw, x = model.state("z"), model.state("qw"), model.state("x")
    assert contact_state(model, [2 * z], "a law") == [2 * sm.Symbol("z")]
    for bad, name in ((qw * z, "qw"), (x + z, "x")):
        with pytest.raises(ValueError, match=rf"a law depends on {name}\b"):
            contact_state(model, [bad], "a law")
