"""The mechanics of ballc: a ball with an observer particle between two planes.

This is the seed's model (shared/seed/ball_between_two_planes.txt) re-derived with
``sympy.physics.mechanics.KanesMethod`` with one deliberate change: the orientation
is a quaternion instead of body-fixed 123 angles, so that the kinematics have no
singularity (the seed's explicit 123-angle kinematics divide by cos q3).

Conventions
-----------
* ``N`` inertial frame, z up.  Gravity is a vector parameter (gravity_x, gravity_y,
  gravity_z: the acceleration; the seed's g along -z is (0, 0, -g)).
* Planes: each a point and a normal (towards the ball), parameters of the run
  (PLANE_FIELDS per plane); the seed's floor is the plane z = 0 and its ceiling z = H.
  The contact laws are derived once, in a plane's own frame (``FRAME_PLANE``: the
  floor's, normal +z through the origin), for the state of one contact in that frame
  (CONTACT_STATE_NAMES); the C core turns each plane's contact into that frame and the
  law's forces back (src/ballc/_plane.c).
* ``A`` ball-fixed frame; ``R = N.dcm(A)`` maps ball-frame components to inertial ones.
* Quaternion ``(qw, qx, qy, qz)`` (Hamilton, scalar first).  ``R`` is built from the
  quaternion divided by its squared norm, so it is a proper rotation for any
  non-zero quaternion; the kinematics ``qdot = 1/2 [0, omega] (x) q`` (omega in
  inertial components) preserve the norm exactly.
* Generalized speeds as in the seed: ``omega_x, omega_y, omega_z`` (angular velocity
  of A in N, N components) and ``vx, vy, vz`` (velocity of the centre in N).

Everything here is symbolic and used at build time only.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sm
import sympy.physics.mechanics as me

T = me.dynamicsymbols._t

# ---------------------------------------------------------------------------
# Names.  The order of these tuples IS the argument layout of the generated C.
# ---------------------------------------------------------------------------
MECHANICAL_STATE_NAMES = (
    "qw", "qx", "qy", "qz",
    "x", "y", "z",
    "omega_x", "omega_y", "omega_z",
    "vx", "vy", "vz",
)
#: States that ride along with the mechanics: dissipated work (J), integrated so that
#: kinetic + potential + spring + dissipated is conserved.
DISSIPATED_STATE_NAMES = ("dissipated_normal", "dissipated_tangential")
#: The ball's states: every run's first states, in this order.
BALL_STATE_NAMES = MECHANICAL_STATE_NAMES + DISSIPATED_STATE_NAMES
#: Each plane's own states, after the ball's, plane after plane (a run's state vector is
#: BALL_STATE_NAMES + PLANE_STATE_FIELDS per plane: 15 + 2 x its number of planes): the
#: elastic tangential deflection (m) of the compliant contact model, in the plane's
#: frame (along its tangents t1, t2).  A run names them ``<plane name>_<field>``.
PLANE_STATE_FIELDS = ("deflection_x", "deflection_y")
#: The most planes a run may have (the run-time arrays of the C core are sized by it).
MAX_PLANES = 6
#: The states of rolling resistance (a scene with rolling or twisting resistance only:
#: without it a run has none of them, and its state is the layout above, bit for bit):
#: after every plane's deflection, the work dissipated by the rolling and twisting
#: torques (J), then per plane, plane after plane, its rolling spring (the rolling
#: part's sds model, LAMMPS ``rolling sds`` and ``twisting sds``): the deflection of the
#: rolling spring along the plane's t1, t2 and of the twisting spring about its normal,
#: as displacements of the contact (m), named ``<plane name>_<field>``.
ROLLING_BALL_STATE_NAMES = ("dissipated_rolling",)
ROLLING_SPRING_FIELDS = ("rolling_x", "rolling_y", "twisting")
#: The model's states: the ball's, and the deflection and rolling spring of the plane
#: the contact laws are derived on (FRAME_PLANE, below); at run time each plane's own
#: (src/ballc/_plane.c).
STATE_NAMES = (BALL_STATE_NAMES + PLANE_STATE_FIELDS + ROLLING_BALL_STATE_NAMES
               + ROLLING_SPRING_FIELDS)

#: (name, seed symbol, unit, description)
PARAMETERS = (
    ("mass", "m", "kg", "mass of the ball"),
    ("observer_mass", "mo", "kg", "mass of the observer particle"),
    ("gravity_x", "-", "m/s^2", "gravitational acceleration, x"),
    ("gravity_y", "-", "m/s^2", "gravitational acceleration, y"),
    ("gravity_z", "-g", "m/s^2", "gravitational acceleration, z (the seed's -g)"),
    ("radius", "r", "m", "radius of the ball"),
    ("observer_alpha", "alpha", "1", "observer position along ball x, in units of r"),
    ("observer_beta", "beta", "1", "observer position along ball y, in units of r"),
    ("observer_gamma", "gamma", "1", "observer position along ball z, in units of r"),
    ("inertia_xx", "iXX", "kg m^2", "central moment of inertia about ball x"),
    ("inertia_yy", "iYY", "kg m^2", "central moment of inertia about ball y"),
    ("inertia_zz", "iZZ", "kg m^2", "central moment of inertia about ball z"),
    ("mixture", "mixtur", "1", "weight of the dig-in model, 1 - weight of friction"),
    ("ball_poisson_ratio", "nyb", "1", "Poisson's ratio of the ball"),
    ("plane_poisson_ratio", "nyp", "1", "Poisson's ratio of the planes"),
    ("ball_youngs_modulus", "Eb", "Pa", "Young's modulus of the ball"),
    ("plane_youngs_modulus", "Ep", "Pa", "Young's modulus of the planes"),
    ("c_tau", "ctau", "1", "Hunt-Crossley restitution constant"),
    ("friction_coefficient", "mu", "1", "Coulomb friction coefficient"),
    ("friction_regularization_speed", "-", "m/s",
     "slip speed scale v_s of the Coulomb regularisation"),
    ("smooth_friction", "-", "1",
     "0: seed's v_t / max(|v_t|, v_s); 1: smooth v_t / sqrt(|v_t|^2 + v_s^2)"),
    ("tangential_stiffness_ratio", "-", "1",
     "compliant model: tangential / normal contact stiffness (Mindlin: 2(1-nu)/(2-nu))"),
    ("normal_damping_model", "-", "1",
     "compliant model's normal damping: 0 Hunt-Crossley, 1 viscoelastic"),
    ("damping_ratio", "-", "1",
     "compliant model, viscoelastic normal damping: c_n = 2 gamma sqrt(m* k_n)"),
    ("tangential_damping_ratio", "-", "1",
     "compliant model's tangential damping: c_t = 2 gamma_t sqrt(m* k_t)"),
    ("rolling_resistance", "-", "1",
     "rolling resistance mu_r: the rolling torque is at most mu_r r F_n (0: none)"),
    ("rolling_stiffness", "-", "N/m",
     "sds rolling spring k_r: rolling force -k_r xi, torque r n x F"),
    ("rolling_damping", "-", "N s/m", "sds rolling dashpot gamma_r: force -gamma_r v_roll"),
    ("twisting_resistance", "-", "1",
     "twisting resistance mu_t: the torque about the normal is at most mu_t r F_n"),
    ("twisting_stiffness", "-", "N/m", "sds twisting spring k_t: force -k_t xi_t, torque r F n"),
    ("twisting_damping", "-", "N s/m", "sds twisting dashpot: force -gamma_t v_twist"),
)
#: The plane table closes the parameters: its number of planes, then PLANE_FIELDS per
#: plane, plane after plane (a run's parameter vector is PARAMETERS + PLANE_FIELDS per
#: plane).
PARAMETERS += (("plane_count", "-", "1",
                f"the number of planes in the plane table that follows (1 to {MAX_PLANES})"),)
#: Each plane's table entry: a point of the plane and its normal, towards the ball (any
#: length > 0: the C core normalises it and builds the plane's frame,
#: src/ballc/_plane.c).  The seed's floor: (0, 0, 0), (0, 0, 1); its ceiling: (0, 0, H),
#: (0, 0, -1).  A run names them ``<plane name>_<field>``.
PLANE_FIELDS = (
    ("point_x", "m", "a point of the plane, x"),
    ("point_y", "m", "a point of the plane, y"),
    ("point_z", "m", "a point of the plane, z"),
    ("normal_x", "1", "the plane's normal towards the ball, x"),
    ("normal_y", "1", "the plane's normal towards the ball, y"),
    ("normal_z", "1", "the plane's normal towards the ball, z"),
)
PARAMETER_NAMES = tuple(p[0] for p in PARAMETERS)

#: The plane whose frame the contact laws are derived in: the floor's (normal +z through
#: the origin).  Every plane's contact is evaluated by these laws, in its own frame.
FRAME_PLANE = "floor"
#: The state of one contact, in its plane's own frame (normal +z, the plane through the
#: origin): the centre's height above the plane, the angular velocity and the centre's
#: velocity in the plane's frame, and the plane's tangential deflection (the compliant
#: law's; it lives in the plane's frame).  The order IS the layout of the plane kernels'
#: ``state`` argument.  Names of the model's states (FRAME_PLANE's) -> contact state.
CONTACT_STATE = (
    ("z", "z"), ("omega_x", "omega_x"), ("omega_y", "omega_y"), ("omega_z", "omega_z"),
    ("vx", "vx"), ("vy", "vy"), ("vz", "vz"),
    ("deflection_x", "deflection_x"), ("deflection_y", "deflection_y"),
) + tuple((name, name) for name in ROLLING_SPRING_FIELDS)
CONTACT_STATE_NAMES = tuple(local for _, local in CONTACT_STATE)

#: Values latched at the start of a contact, per plane, in this order (a run's latch is
#: LATCH_FIELDS per plane, plane after plane, named ``<plane name>_<field>``).
LATCH_FIELDS = (
    ("penetration_rate_at_impact", "rhodtu / rhodto",
     "m/s", "penetration rate when the contact started"),
    ("digin_direction_x", "ru1 / ro1", "1",
     "unit contact-point velocity at impact, x (inertial components)"),
    ("digin_direction_y", "ru2 / ro2", "1", "unit contact-point velocity at impact, y"),
    ("digin_direction_z", "ru3 / ro3", "1", "unit contact-point velocity at impact, z"),
    ("slip_direction_x", "-", "1", "exact Coulomb friction: unit slip direction latched at "
     "the segment start, along the plane's first tangent t1 (its frame, as the slip)"),
    ("slip_direction_y", "-", "1",
     "exact Coulomb friction: unit slip direction latched at the segment start, along t2"),
    ("rolling_mode", "-", "1", "the rolling part's mode (ROLLING_MODE_CODES; 0: none)"),
    ("rolling_direction_x", "-", "1", "exact rolling resistance: unit rolling-velocity "
     "direction latched at the segment start, along t1 (the plane's frame)"),
    ("rolling_direction_y", "-", "1", "exact rolling resistance: ... along t2"),
    ("twisting_mode", "-", "1", "the twisting part's mode (ROLLING_MODE_CODES; 0: none)"),
    ("twisting_direction", "-", "1",
     "exact twisting resistance: the sign of the twisting velocity latched (+1 or -1)"),
)
#: The codes of a plane's rolling and twisting modes in its latch (rolling_mode,
#: twisting_mode): exact (type A with holding) free, direction held, holding; sds
#: spring (below the cap), slider (at the cap).
ROLLING_MODE_CODES = (("none", 0), ("free", 1), ("fixed", 2), ("holding", 3), ("spring", 4),
                      ("slider", 5))
#: The latched symbols of FRAME_PLANE (the contact laws read them, turned into the
#: plane's frame where they are vectors).
LATCH_NAMES = tuple(f[0] for f in LATCH_FIELDS)
#: A plane kernel's ``extra`` argument: the plane's latched values (LATCH_FIELDS, the
#: dig-in direction turned into the plane's frame), then gravity's component into the
#: plane, -n . g (m/s^2; the floor's g in the seed), the one parameter of the scene that
#: depends on the plane.
PLANE_INPUT_NAMES = tuple(f[0] for f in LATCH_FIELDS) + ("gravity_into_plane",)


@dataclass
class Model:
    """Symbols and sympy expressions of the ball model."""

    states: list          # dynamicsymbols in STATE_NAMES order
    parameters: list      # sympy Symbols in PARAMETER_NAMES order
    latches: list         # sympy Symbols in LATCH_NAMES order
    frame: me.ReferenceFrame
    ball_frame: me.ReferenceFrame
    centre: me.Point
    observer: me.Point
    dcm: sm.Matrix        # N.dcm(A)
    kinematics: sm.Matrix  # time derivatives of the 7 coordinates
    p: dict = field(default_factory=dict)  # parameter name -> Symbol

    @property
    def coordinates(self):
        return self.states[:7]

    @property
    def speeds(self):
        return self.states[7:13]

    def state(self, name):
        return self.states[STATE_NAMES.index(name)]


def quaternion_dcm(qw, qx, qy, qz):
    """Rotation matrix (ball -> inertial) of a quaternion of any non-zero norm."""
    s = qw**2 + qx**2 + qy**2 + qz**2
    return sm.Matrix([
        [qw**2 + qx**2 - qy**2 - qz**2, 2*(qx*qy - qw*qz), 2*(qx*qz + qw*qy)],
        [2*(qx*qy + qw*qz), qw**2 - qx**2 + qy**2 - qz**2, 2*(qy*qz - qw*qx)],
        [2*(qx*qz - qw*qy), 2*(qy*qz + qw*qx), qw**2 - qx**2 - qy**2 + qz**2],
    ]) / s


def build_model() -> Model:
    """Frames, points, speeds and kinematics (no forces yet)."""
    states = list(me.dynamicsymbols(" ".join(STATE_NAMES)))
    qw, qx, qy, qz, x, y, z, wx, wy, wz, vx, vy, vz = states[:len(MECHANICAL_STATE_NAMES)]
    p = {name: sm.Symbol(name) for name in PARAMETER_NAMES}
    latches = [sm.Symbol(name) for name in LATCH_NAMES]

    N = me.ReferenceFrame("N")
    A = me.ReferenceFrame("A")
    R = quaternion_dcm(qw, qx, qy, qz)
    A.orient_explicit(N, R)
    A.set_ang_vel(N, wx*N.x + wy*N.y + wz*N.z)

    O = me.Point("O")
    O.set_vel(N, 0)
    centre = me.Point("C")
    centre.set_pos(O, x*N.x + y*N.y + z*N.z)
    centre.set_vel(N, vx*N.x + vy*N.y + vz*N.z)

    r = p["radius"]
    observer = me.Point("P_o")
    observer.set_pos(centre, r*(p["observer_alpha"]*A.x + p["observer_beta"]*A.y
                                + p["observer_gamma"]*A.z))
    observer.v2pt_theory(centre, N, A)

    half = sm.Rational(1, 2)
    kinematics = sm.Matrix([
        -half*(wx*qx + wy*qy + wz*qz),
        half*(wx*qw + wy*qz - wz*qy),
        half*(wy*qw + wz*qx - wx*qz),
        half*(wz*qw + wx*qy - wy*qx),
        vx, vy, vz,
    ])
    return Model(states=states, parameters=[p[n] for n in PARAMETER_NAMES],
                 latches=latches, frame=N, ball_frame=A, centre=centre,
                 observer=observer, dcm=R, kinematics=kinematics, p=p)


def contact_point(model: Model, plane: str) -> me.Point:
    """The point of the ball nearest to ``plane``, in the plane's own frame
    (FRAME_PLANE: the plane z = 0, the ball above it): C - r N.z."""
    require_frame_plane(plane)
    N = model.frame
    point = me.Point(f"contact_{plane}")
    point.set_pos(model.centre, -model.p["radius"]*N.z)
    point.v2pt_theory(model.centre, N, model.ball_frame)
    return point


def require_frame_plane(plane: str):
    """Refuse a plane other than FRAME_PLANE: every other plane is that one turned, at
    run time (src/ballc/_plane.c), and has no law of its own."""
    if plane != FRAME_PLANE:
        raise ValueError(f"the contact laws are derived in the plane's own frame "
                         f"({FRAME_PLANE!r}) only, not for {plane!r}")


def kanes_equations(model: Model, bodies, loads):
    """Mass matrix (6x6) and forcing (6) of the dynamic equations via KanesMethod."""
    kd = [qd.diff(T) - rhs for qd, rhs in zip(model.coordinates, model.kinematics)]
    km = me.KanesMethod(model.frame, q_ind=model.coordinates, u_ind=model.speeds,
                        kd_eqs=kd)
    km.kanes_equations(bodies, loads)
    return km.mass_matrix, km.forcing


def bodies(model: Model):
    """The ball (rigid body) and the observer (particle)."""
    p = model.p
    inertia = me.inertia(model.ball_frame, p["inertia_xx"], p["inertia_yy"], p["inertia_zz"])
    ball = me.RigidBody("ball", model.centre, model.ball_frame, p["mass"],
                        (inertia, model.centre))
    observer = me.Particle("observer", model.observer, p["observer_mass"])
    return ball, observer


def gravity_vector(model: Model) -> me.Vector:
    """The gravitational acceleration (m/s^2), a vector parameter."""
    N, p = model.frame, model.p
    return p["gravity_x"]*N.x + p["gravity_y"]*N.y + p["gravity_z"]*N.z


def gravity_loads(model: Model, body):
    """Weight of one body (ball or observer): its mass times the gravity vector."""
    return [(body.masscenter, body.mass*gravity_vector(model))]
