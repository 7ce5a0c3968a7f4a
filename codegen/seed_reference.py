"""Faithful, independent transcription of the seed's model (the ORACLE / BASELINE).

The seed is ``shared/seed/ball_between_two_planes.txt``: a ``sympy.physics.mechanics``
notebook of an elastic ball bouncing between the planes z = 0 and z = H, with a
Hunt-Crossley normal force, Coulomb friction ("friction model") and a "dig-in" model
mixed by ``mixtur``.  This module re-derives exactly the seed's formulation so that

* tests can use it as an oracle for the separately derived quaternion model, and
* benchmarks can use its ``lambdify`` + ``np.linalg.solve`` right-hand side and its
  ``solve_ivp(..., method='Radau')`` run as the baseline.

Nothing is improved here on purpose: the seed's German names (``abstand``, ``richtung``,
``wurzel``, ``zaehler``, ...), its ``Heaviside(x, 0.)``, ``Max(|v_t|, 1e-10)``, ``Abs``,
float exponents (``3/2`` -> 1.5, ``5 / 2`` -> 2.5), float constants (``1.``,
``4. / (3.*...)``, ``sm.S(1.)``) and the order in which it builds the expressions are
kept, so that ``count_ops`` gives the seed's published figures (60,602 for
``forcing_full``, 3,337 for ``mass_matrix_full``).

Formulation (as in the seed)
----------------------------
* States, ``qL`` (12): q1, q2, q3 (body-fixed '123' angles of the ball frame A w.r.t. N),
  m1, m2, m3 (centre of the ball in N), u1, u2, u3 (angular velocity of A in N, expressed
  in N), um1, um2, um3 (velocity of the centre, in N).  Explicit kinematics (sympy's
  default), so the full mass matrix is ``[[I6, 0], [0, A]]``.
* Parameters, ``pL`` (26), in the seed's order: m, mo, g, r, alpha, beta, gamma, iXX, iYY,
  iZZ, H, mixtur, nyb, nyp, Eb, Ep, ctau, mu, rhodtu, rhodto, ru1, ru2, ru3, ro1, ro2, ro3.
  ``rhodtu``/``rhodto`` (approach speed at impact) and ``ru*``/``ro*`` (dig-in direction)
  are *not* physical constants: the seed's RHS writes them during integration (see
  :func:`run_seed_pipeline`).

Public API
----------
``build_seed_model()``                    cached model (sympy expressions + lambdified functions)
``seed_state_derivative(y12, params26)``  the seed's ``gradient`` without side effects
``seed_energies(y12, params26)``          kinetic / potential / spring energy
``run_seed_pipeline(...)``                the seed's Radau run, side effects included
``angles_123_dcm(q1, q2, q3)``            N_C_A for body-fixed 123 angles
``SEED_DEFAULTS``, ``SEED_PARAMETER_NAMES``, ``SEED_STATE_NAMES``, ``SEED_INITIAL_STATE``,
``seed_default_parameter_values()``

Build time and verification (2-core development machine, Python 3.11, sympy 1.14)
----------------------------------------------------------------------------------
``build_seed_model()`` takes about 1.4-1.7 s wall: ~1.2 s for Kane's equations
(``KanesMethod`` + ``kanes_equations``), ~0.3 s for ``lambdify(forcing_full, cse=True)``,
well under 0.1 s for each of the other nine lambdifications.  The breakdown of every build
is stored in ``model.build_seconds``; later calls hit the ``lru_cache``.

``count_ops``: 60,602 (``forcing_full``) and 3,337 (``mass_matrix_full``), as published.
:func:`run_seed_pipeline` with the defaults gives nfev 151,847, njev 135, nlu 2,616,
153,725 RHS calls in all, final energy 109.70 J (from 386.59 J), 9 contacts at the times in
``shared/NOTES.md`` -- bit-for-bit the same trajectory as the seed's own code (extracted
from the notebook text and run unchanged, minus matplotlib) on the same machine.  The
seed's published 151,645 and NOTES' 151,729 differ slightly (not reproduced here, with any
PYTHONHASHSEED; the count is sensitive to floating-point details of the platform).  CPU time in
``solve_ivp`` was 22-26 s here for both this module and the seed's own code
(~88-150 us per RHS call, depending on load).
"""

from __future__ import annotations

import functools
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import sympy as sm
import sympy.physics.mechanics as me
from scipy.integrate import solve_ivp

__all__ = [
    "SeedModel",
    "SEED_PARAMETER_NAMES",
    "SEED_STATE_NAMES",
    "SEED_DEFAULTS",
    "SEED_INITIAL_STATE",
    "seed_default_parameter_values",
    "build_seed_model",
    "seed_state_derivative",
    "seed_energies",
    "run_seed_pipeline",
    "angles_123_dcm",
]

# ---------------------------------------------------------------------------------------
# Names, defaults and initial state (the seed's "Set parameters" cell)
# ---------------------------------------------------------------------------------------

#: The 26 parameter names, exactly the seed's symbol names, in the seed's order (pL).
SEED_PARAMETER_NAMES = (
    "m", "mo", "g", "r", "alpha", "beta", "gamma", "iXX", "iYY", "iZZ", "H", "mixtur",
    "nyb", "nyp", "Eb", "Ep", "ctau", "mu", "rhodtu", "rhodto",
    "ru1", "ru2", "ru3", "ro1", "ro2", "ro3",
)

#: The 12 state names in the seed's order (qL = q_ind + u_ind).
SEED_STATE_NAMES = (
    "q1", "q2", "q3", "m1", "m2", "m3", "u1", "u2", "u3", "um1", "um2", "um3",
)

_mb1 = 1.0
_r1 = 1.0
_iXX1 = 2.0 / 5.0 * _mb1 * _r1**2  # "from the internet" (solid sphere), as in the seed

#: The seed's default parameter values (``pL_vals``), keyed by parameter name.
SEED_DEFAULTS = {
    "m": _mb1,
    "mo": 0.0001,
    "g": 9.81,
    "r": _r1,
    "alpha": 0.7,
    "beta": 0.0,
    "gamma": 0.7,
    "iXX": _iXX1,
    "iYY": _iXX1,
    "iZZ": _iXX1,
    "H": 10.0,
    "mixtur": 0.375,
    "nyb": 0.25,      # Poisson's ratio for rubber
    "nyp": 0.15,      # Poisson's ratio for concrete
    "Eb": 3.0e3,      # Young's modulus of the ball (rubber is really about 3e9)
    "Ep": 2.0e10,     # Young's modulus of the plane
    "ctau": 0.90,     # Hunt-Crossley experimental constant
    "mu": 0.1,        # coefficient of friction
    "rhodtu": 1.0,    # written during integration; "any value o.k."
    "rhodto": 1.0,
    "ru1": 1.0, "ru2": 1.0, "ru3": 1.0,
    "ro1": 1.0, "ro2": 1.0, "ro3": 1.0,
}

#: The seed's initial state y0: q = 0, 0, 0; m = 0, 0, 5; u = 0, 0, 0; um = -5, 5, -25.
SEED_INITIAL_STATE = (0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, -5.0, 5.0, -25.0)


def seed_default_parameter_values():
    """Return a fresh list of the 26 default parameter values in the seed's order (pL_vals)."""
    return [SEED_DEFAULTS[name] for name in SEED_PARAMETER_NAMES]


# ---------------------------------------------------------------------------------------
# The symbolic model
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class SeedModel:
    """Everything :func:`build_seed_model` derives from the seed's formulation.

    All lambdified functions take ``(*qL, *pL)``: the 12 states followed by the 26
    parameters, in the seed's order, exactly like the seed's ``*_lam`` functions.
    """

    state_symbols: list            # qL, 12 dynamicsymbols
    parameter_symbols: list        # pL, 26 symbols
    parameter_names: list          # 26 strings (the seed's symbol names)
    mass_matrix_full: sm.Matrix    # 12 x 12
    forcing_full: sm.Matrix        # 12 x 1
    kinetic_energy: sm.Expr
    potential_energy: sm.Expr
    spring_energy: sm.Expr
    rhodtu_expr: sm.Expr           # speed of BCPu towards the lower plane
    rhodto_expr: sm.Expr           # speed of BCPo towards the upper plane
    richtungu_expr: list           # 3 components (N) of the unit velocity of BCPu
    richtungo_expr: list           # 3 components (N) of the unit velocity of BCPo
    observer_position_expr: list   # 3 components (N) of the position of Po
    MM_lam: object
    force_lam: object
    kin_lam: object
    pot_lam: object
    spring_lam: object
    rhodtu_lam: object
    rhodto_lam: object
    richtungu_lam: object
    richtungo_lam: object
    observer_position_lam: object
    build_seconds: dict = field(default_factory=dict)  # wall-clock breakdown of the build


@functools.lru_cache(maxsize=None)
def build_seed_model():
    """Derive the seed's equations of motion with Kane's method and lambdify them.

    This is a line-by-line transcription of the seed's cells "Kane's Equations of Motion",
    "Points of impact", the four force functions, "Kane's equations", the energy cell and
    "Lambdification" (plus the animation cell's observer position ``Po_loc``).

    The result is cached: only the first call pays the build (about 1.5 s, see the module
    docstring); later calls return the same :class:`SeedModel` object.
    """
    timings = {}
    t_start = time.perf_counter()

    # Kane's Equations of Motion ------------------------------------------------------
    t = me.dynamicsymbols._t

    N, A = sm.symbols('N, A', cls=me.ReferenceFrame)
    O, Dmc, Po, BCPu, BCPo = sm.symbols('O, Dmc, Po, BCPu, BCPo', cls=me.Point)

    q1, q2, q3, u1, u2, u3 = me.dynamicsymbols('q1, q2, q3, u1, u2, u3')
    m1, m2, m3, um1, um2, um3 = me.dynamicsymbols('m1, m2, m3, um1, um2, um3')

    m, mo, g, r, alpha, beta, gamma, iXX, iYY, iZZ, H = sm.symbols(
        'm, mo, g, r, alpha, beta, gamma, iXX, iYY, iZZ, H')
    nyb, nyp, Eb, Ep, rhodtu, rhodto, ctau, mu = sm.symbols(
        'nyb, nyp, Eb, Ep, rhodtu, rhodto, ctau, mu')
    ru1, ru2, ru3, ro1, ro2, ro3 = sm.symbols('ru1, ru2, ru3, ro1, ro2, ro3')

    mixtur = sm.symbols('mixtur')

    A.orient_body_fixed(N, (q1, q2, q3), '123')
    rot = A.ang_vel_in(N)
    A.set_ang_vel(N, u1*N.x + u2*N.y + u3*N.z)
    rot1 = A.ang_vel_in(N)

    O.set_vel(N, 0)

    Dmc.set_pos(O, m1*N.x + m2*N.y + m3*N.z)
    Dmc.set_vel(N, um1*N.x + um2*N.y + um3*N.z)

    Po.set_pos(Dmc, r * (alpha*A.x + beta*A.y + gamma*A.z))
    _ = Po.v2pt_theory(Dmc, N, A)

    # Points of impact: BCPu (m1, m2, m3 - r) and BCPo (m1, m2, m3 + r), fixed on the ball.
    BCPu.set_pos(Dmc, -r*N.z)
    BCPu.v2pt_theory(Dmc, N, A)
    BCPo.set_pos(Dmc, r*N.z)
    BCPo.v2pt_theory(Dmc, N, A)

    # Friction model, lower plane -------------------------------------------------------
    def fric_lower_plane(rhodtu):
        # force acting on BCPu

        # should always be positive, the ball must not fall through the planes
        abstand = m3
        # pointing towards the ball
        richtung = N.z
        # positive in the ball has penetrated the plane
        rho = r - abstand
        # speed of the contact point of the ball
        vCP = BCPu.vel(N)
        # speed component in Z direction pointing from the ball to the plane
        rhodt = me.dot(vCP, richtung)
        rho = sm.Abs(rho)

        # determine k0
        wurzel = sm.sqrt(r)
        sigma_b = (1. - nyb**2) / Eb
        sigma_s = (1. - nyp**2) / Ep
        k0 = 4. / (3.*(sigma_b + sigma_s)) * wurzel

        # Impact force on BCPu in Z direction
        forcec = (k0 * rho**(3/2) * (1. + 3./2. * (1 - ctau) * (-rhodt) /
                                     sm.Abs(rhodtu)) * richtung *
                  sm.Heaviside(r - abstand, 0.))

        # The speed component of vCP in the plane is the speed minus its component
        # perpendicular to the plane.
        vx = vCP - (me.dot(vCP, richtung)) * richtung
        forcef = (forcec.magnitude() * mu * (-vx) * sm.Heaviside(r - abstand, 0.) *
                  1. / sm.Max(vx.magnitude(), 1.e-10))

        # The force acting on BCPu is returned
        return forcec + forcef

    # Friction model, upper plane -------------------------------------------------------
    def fric_upper_plane(rhodto):
        # force acting on BCPo
        # should always be positive, the ball must not fall through the planes
        abstand = H - m3
        # pointing towards the ball
        richtung = -N.z
        # positive in the ball has penetrated the plane
        rho = r - abstand
        # speed of the contact point of the ball
        vCP = BCPo.vel(N)
        # speed component in Z direction pointing from the ball to the plane
        rhodt = me.dot(vCP, richtung)
        rho = sm.Abs(rho)

        # determine k0
        wurzel = sm.sqrt(r)
        sigma_b = (1. - nyb**2) / Eb
        sigma_s = (1. - nyp**2) / Ep
        k0 = 4. / (3.*(sigma_b + sigma_s)) * wurzel

        # Impact force on BCPo in Z direction
        forcec = (k0 * rho**(3/2) * (1. + 3./2. * (1 - ctau) * (-rhodt) /
                                     sm.Abs(rhodto)) * richtung *
                  sm.Heaviside(r - abstand, 0.))

        vx = vCP - (me.dot(vCP, richtung)) * richtung

        forcef = (forcec.magnitude() * mu * (-vx) * sm.Heaviside(r - abstand, 0.) *
                  1./sm.Max(vx.magnitude(), 1.e-10))

        return forcec + forcef

    # Dig-in model, lower plane ---------------------------------------------------------
    def HC_lower_plane(rhodtu, ru1, ru2, ru3):
        # force acting on BCPu
        # should always be positive, the ball must not fall through the planes
        abstand = m3
        # speed of the contact point on the ball
        vCP = BCPu.vel(N)
        # pointing towards the ball (the stored direction of vCP before the impact)
        richtung = -(ru1*N.x + ru2*N.y + ru3*N.z)
        # positive in the ball has penetrated the plane
        rho = r - abstand
        # speed component pointing from the ball to the plane
        rhodt = me.dot(vCP, richtung)
        rho = sm.Abs(rho)

        # determine k0
        wurzel = sm.sqrt(r)
        sigma_b = (1. - nyb**2) / Eb
        sigma_p = (1. - nyp**2) / Ep
        k0 = 4. / (3.*(sigma_b + sigma_p)) * wurzel

        # Impact force on BCPu
        forcec = (k0 * rho**(3/2) * (1. + 3./2. * (1 - ctau) * (-rhodt) /
                                     sm.Abs(rhodtu)) * richtung *
                  sm.Heaviside(r - abstand, 0.))

        # The force acting on BCPu is returned
        return forcec

    # Dig-in model, upper plane ---------------------------------------------------------
    def HC_upper_plane(rhodto, ro1, ro2, ro3):
        # force acting on BCPo

        abstand = H - m3
        vCP = BCPo.vel(N)
        richtung = -(ro1*N.x + ro2*N.y + ro3*N.z)
        rho = r - abstand

        rhodt = me.dot(vCP, richtung)
        rho = sm.Abs(rho)

        # determine k0
        wurzel = sm.sqrt(r)
        sigma_b = (1. - nyb**2) / Eb
        sigma_s = (1. - nyp**2) / Ep
        k0 = 4. / (3.*(sigma_b + sigma_s)) * wurzel

        # Impact force on BCPo
        forcec = (k0 * rho**(3/2) * (1. + 3./2. * (1 - ctau) * (-rhodt) /
                                     sm.Abs(rhodto)) * richtung *
                  sm.Heaviside(r - abstand, 0.))

        return forcec

    # Kane's equations ------------------------------------------------------------------
    Ib = me.inertia(A, iXX, iYY, iZZ)
    body = me.RigidBody('body', Dmc, A, m, (Ib, Dmc))
    Poa = me.Particle('Poa', Po, mo)
    BODY = [body, Poa]

    F1f = [(Dmc, -m*g*N.z), (Po, -mo*g*N.z)]
    F2f = [(BCPu, (sm.S(1.) - mixtur) * fric_lower_plane(rhodtu))]
    F3f = [(BCPo, (sm.S(1.) - mixtur) * fric_upper_plane(rhodto))]

    F2hc = [(BCPu, mixtur * HC_lower_plane(rhodtu, ru1, ru2, ru3))]
    F3hc = [(BCPo, mixtur * HC_upper_plane(rhodto, ro1, ro2, ro3))]

    FL = (F1f + F2f + F3f) + (F2hc + F3hc)

    q_ind = [q1, q2, q3] + [m1, m2, m3]
    u_ind = [u1, u2, u3] + [um1, um2, um3]

    kd = [me.dot(rot - rot1, uv) for uv in A] + [i - j.diff(t)
                                                 for i, j in zip((um1, um2, um3),
                                                                 (m1, m2, m3))]

    KM = me.KanesMethod(N, q_ind=q_ind, u_ind=u_ind, kd_eqs=kd)
    (fr, frstar) = KM.kanes_equations(BODY, FL)

    MM = KM.mass_matrix_full
    force = KM.forcing_full
    timings["kane"] = time.perf_counter() - t_start

    # Energies --------------------------------------------------------------------------
    t_mark = time.perf_counter()
    pot_energie = (m * g * me.dot(Dmc.pos_from(O), N.z) + mo * g *
                   me.dot(Po.pos_from(O), N.z))
    kin_energie = sum([koerper.kinetic_energy(N) for koerper in BODY])

    rho1 = r - m3               # positive if impact with lower plane
    rho2 = r - (H - m3)         # positive if impact with upper plane
    sigma_b = (1. - nyb**2) / Eb
    sigma_p = (1. - nyp**2) / Ep
    k0 = 4. / (3.*(sigma_b + sigma_p)) * sm.sqrt(r)

    spring_energie = (2. / 5. * k0 * sm.Abs(rho1)**(5 / 2) *
                      sm.Heaviside(rho1, 0.) + 2. / 5. * k0 *
                      sm.Abs(rho2)**(5 / 2) * sm.Heaviside(rho2, 0.))

    # speed of BCPu in direction of the lower plane
    rhodtuu = me.dot(BCPu.vel(N), -N.z)
    rhodtoo = me.dot(BCPo.vel(N), N.z)       # analoguously dto.

    richtungu = [me.dot(BCPu.vel(N).normalize(), uv) for uv in N]
    richtungo = [me.dot(BCPo.vel(N).normalize(), uv) for uv in N]

    # location of particle (from the seed's animation cell)
    Po_loc = [me.dot(Po.pos_from(O), uv) for uv in N]
    timings["energies_and_auxiliaries"] = time.perf_counter() - t_mark

    # Lambdification --------------------------------------------------------------------
    qL = q_ind + u_ind
    pL1 = [m, mo, g, r, alpha, beta, gamma, iXX, iYY, iZZ, H, mixtur]
    pL2 = [nyb, nyp, Eb, Ep, ctau, mu, rhodtu, rhodto, ru1, ru2, ru3, ro1,
           ro2, ro3]
    pL = pL1 + pL2

    def _lam(key, expr):
        t0 = time.perf_counter()
        fn = sm.lambdify(qL + pL, expr, cse=True)
        timings["lambdify_" + key] = time.perf_counter() - t0
        return fn

    MM_lam = _lam("MM", MM)
    force_lam = _lam("force", force)

    pot_lam = _lam("pot", pot_energie)
    kin_lam = _lam("kin", kin_energie)
    spring_lam = _lam("spring", spring_energie)

    rhodtu_lam = _lam("rhodtu", rhodtuu)
    rhodto_lam = _lam("rhodto", rhodtoo)

    richtungu_lam = _lam("richtungu", richtungu)
    richtungo_lam = _lam("richtungo", richtungo)

    Po_loc_lam = _lam("observer_position", Po_loc)

    timings["total"] = time.perf_counter() - t_start

    names = [str(s) for s in pL]
    assert tuple(names) == SEED_PARAMETER_NAMES, names

    return SeedModel(
        state_symbols=qL,
        parameter_symbols=pL,
        parameter_names=names,
        mass_matrix_full=MM,
        forcing_full=force,
        kinetic_energy=kin_energie,
        potential_energy=pot_energie,
        spring_energy=spring_energie,
        rhodtu_expr=rhodtuu,
        rhodto_expr=rhodtoo,
        richtungu_expr=richtungu,
        richtungo_expr=richtungo,
        observer_position_expr=Po_loc,
        MM_lam=MM_lam,
        force_lam=force_lam,
        kin_lam=kin_lam,
        pot_lam=pot_lam,
        spring_lam=spring_lam,
        rhodtu_lam=rhodtu_lam,
        rhodto_lam=rhodto_lam,
        richtungu_lam=richtungu_lam,
        richtungo_lam=richtungo_lam,
        observer_position_lam=Po_loc_lam,
        build_seconds=timings,
    )


# ---------------------------------------------------------------------------------------
# Numerical helpers
# ---------------------------------------------------------------------------------------

def seed_state_derivative(y12, params26):
    """Return dy/dt (12 values) of the seed's model: the seed's ``gradient`` without side effects.

    ``np.linalg.solve(MM_lam(*y, *p), force_lam(*y, *p))`` flattened; ``y12`` in the order of
    :data:`SEED_STATE_NAMES`, ``params26`` in the order of :data:`SEED_PARAMETER_NAMES`.
    Nothing is written into ``params26``.
    """
    model = build_seed_model()
    y = [float(v) for v in y12]
    p = [float(v) for v in params26]
    if len(y) != 12 or len(p) != 26:
        raise ValueError(f"expected 12 states and 26 parameters, got {len(y)} and {len(p)}")
    sol = np.linalg.solve(model.MM_lam(*y, *p), model.force_lam(*y, *p))
    return np.asarray(sol, dtype=float).reshape(12)


def seed_energies(y12, params26):
    """Return the seed's energies at state ``y12``: dict with "kinetic", "potential", "spring".

    Kinetic energy of ball and observer, potential energy m g m3 + mo g z_Po, and the
    Hertz spring energy 2/5 k0 |rho|^2.5 H(rho, 0.) for each plane, exactly as the seed.
    """
    model = build_seed_model()
    y = [float(v) for v in y12]
    p = [float(v) for v in params26]
    return {
        "kinetic": float(model.kin_lam(*y, *p)),
        "potential": float(model.pot_lam(*y, *p)),
        "spring": float(model.spring_lam(*y, *p)),
    }


class _SeedGradient:
    """The seed's ``gradient(t, y, args)``, side effects included, with per-run state.

    The seed keeps ``zaehler``, ``impact_list``, ``zeit_list`` and ``params_list`` as module
    globals; here they are attributes of one instance per run, so that runs do not leak
    into each other.  ``r1`` and ``H1`` (the seed's global floats) are taken from the
    parameter list at the start of the run.  ``args`` (the parameter list handed to
    ``solve_ivp``) is mutated exactly like in the seed: ``args[-8]`` (rhodtu) or ``args[-7]``
    (rhodto) on every call while the ball is within 0.01 of a plane, and the dig-in
    direction ``args[-6:-3]`` / ``args[-3:]`` while the contact point moves into the plane.
    """

    def __init__(self, model, r1, H1):
        self.MM_lam = model.MM_lam
        self.force_lam = model.force_lam
        self.rhodtu_lam = model.rhodtu_lam
        self.rhodto_lam = model.rhodto_lam
        self.richtungu_lam = model.richtungu_lam
        self.richtungo_lam = model.richtungo_lam
        self.r1 = r1
        self.H1 = H1
        self.zaehler = 0
        self.impact_list = []
        self.zeit_list = []
        self.params_list = []
        self.calls = 0          # every call, including scipy's uncounted Jacobian columns
        self.writes = 0         # number of calls inside the 0.01 band (parameter writes)

    def __call__(self, t, y, args):
        self.calls += 1
        r1, H1 = self.r1, self.H1
        # set rhodtu / rhodto
        if r1 < y[5] < r1 + 0.01:
            self.zaehler += 1
            self.writes += 1
            args[-8] = self.rhodtu_lam(*y, *args)
            if self.zaehler == 1:
                self.impact_list.append([t, y[3], y[4], y[5]])

            tu1, tu2, tu3 = self.richtungu_lam(*y, *args)
            # I want the speed vector only when the ball moves into the plane,
            # not when it moves out. this would give the wrong direction.
            if tu3 < 0.:
                args[-6], args[-5], args[-4] = tu1, tu2, tu3

        elif r1 < H1 - y[5] < r1 + 0.01:
            self.zaehler += 1
            self.writes += 1
            args[-7] = self.rhodto_lam(*y, *args)
            if self.zaehler == 1:
                self.impact_list.append([t, y[3], y[4], y[5]])

            to1, to2, to3 = self.richtungo_lam(*y, *args)
            # Same idea as above.
            if to3 > 0.:
                args[-3], args[-2], args[-1] = to1, to2, to3

        else:
            self.zaehler = 0

        self.zeit_list.append(t)
        self.params_list.append(args)   # the same list object every time, as in the seed

        sol = np.linalg.solve(self.MM_lam(*y, *args), self.force_lam(*y, *args))
        return np.array(sol).T[0]


def _contacts_from_trajectory(t, y, r1, H1):
    """Contacts found from the sampled trajectory.

    A floor contact is a run of samples with m3 < r, a ceiling contact a run with
    m3 > H - r.  Returns ``(contacts, intervals)``: ``contacts`` is a list of
    ``(t_first_sample, plane)``; ``intervals`` adds, per contact, the first and last sample
    times, the peak penetration and um1 at the sample before / after the contact.
    """
    m3 = y[5]
    um1 = y[9]
    contacts, intervals = [], []
    n = len(t)
    for plane, mask, depth in (("floor", m3 < r1, r1 - m3),
                               ("ceiling", m3 > H1 - r1, m3 - (H1 - r1))):
        i = 0
        while i < n:
            if mask[i]:
                j = i
                while j + 1 < n and mask[j + 1]:
                    j += 1
                before = max(i - 1, 0)
                after = min(j + 1, n - 1)
                intervals.append({
                    "plane": plane,
                    "t_start": float(t[i]),
                    "t_end": float(t[j]),
                    "peak_penetration": float(np.max(depth[i:j + 1])),
                    "um1_before": float(um1[before]),
                    "um1_after": float(um1[after]),
                })
                i = j + 1
            else:
                i += 1
    intervals.sort(key=lambda d: d["t_start"])
    contacts = [(d["t_start"], d["plane"]) for d in intervals]
    return contacts, intervals


def run_seed_pipeline(t_end=5.0, rtol=1e-12, atol=1e-12, t_eval_points=None, *,
                      params=None, initial_state=None):
    """Reproduce the seed's numerical integration (Radau, side-effecting RHS).

    Parameters
    ----------
    t_end : float
        The seed's ``intervall`` (5 s).
    rtol, atol : float
        Tolerances handed to ``solve_ivp`` (the seed: 1e-12 both).
    t_eval_points : int or None
        Number of output samples on ``np.linspace(0, t_end, n)``; default
        ``int(t_end * 1000)`` like the seed's ``schritte``.
    params : mapping or sequence, optional (keyword only)
        Parameter values (dict by name, overriding :data:`SEED_DEFAULTS`, or 26 values in
        the seed's order).  Default: the seed's values.  A private copy is mutated.
    initial_state : sequence of 12, optional (keyword only)
        Default :data:`SEED_INITIAL_STATE`.

    Returns
    -------
    dict with
        ``cpu_seconds`` (``time.process_time()`` around ``solve_ivp`` only), ``nfev``,
        ``njev``, ``nlu``, ``status``, ``message``, ``t`` (n,), ``y`` (12, n),
        ``contacts`` (list of ``(t, "floor"|"ceiling")``, first sample of each contact
        found from the trajectory), ``contact_intervals`` (details per contact),
        ``initial_energies`` / ``final_energies`` (kinetic, potential, spring, total),
        ``rhs_calls`` (all RHS calls, including the Jacobian columns scipy does not count),
        ``band_calls`` (calls that wrote into the parameter list), ``impact_list`` (the
        seed's own list: [t, m1, m2, m3] at the first call of each band entry),
        ``final_params`` (the mutated parameter list at the end), ``runtime_warnings``
        (count of warnings raised during ``solve_ivp``, e.g. num_jac overflow) and
        ``warning_messages`` (the distinct messages).
    """
    model = build_seed_model()

    if params is None:
        pL_vals = seed_default_parameter_values()
    elif isinstance(params, dict):
        unknown = set(params) - set(SEED_PARAMETER_NAMES)
        if unknown:
            raise KeyError(f"unknown parameter names: {sorted(unknown)}")
        merged = dict(SEED_DEFAULTS)
        merged.update(params)
        pL_vals = [float(merged[name]) for name in SEED_PARAMETER_NAMES]
    else:
        pL_vals = [float(v) for v in params]
        if len(pL_vals) != 26:
            raise ValueError("expected 26 parameter values")
    y0 = list(SEED_INITIAL_STATE if initial_state is None else initial_state)
    if len(y0) != 12:
        raise ValueError("expected 12 initial state values")

    r1 = pL_vals[SEED_PARAMETER_NAMES.index("r")]
    H1 = pL_vals[SEED_PARAMETER_NAMES.index("H")]
    alpha1, beta1, gamma1 = pL_vals[4:7]
    if alpha1**2 + beta1**2 + gamma1**2 >= 1.:
        raise ValueError('Observer is outside of the ball')

    intervall = float(t_end)
    schritte = int(intervall * 1000.) if t_eval_points is None else int(t_eval_points)
    times = np.linspace(0, intervall, schritte)
    t_span = (0., intervall)

    initial_energies = seed_energies(y0, pL_vals)
    initial_energies["total"] = sum(initial_energies.values())

    gradient = _SeedGradient(model, r1, H1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cpu0 = time.process_time()
        resultat1 = solve_ivp(gradient, t_span, y0, t_eval=times, args=(pL_vals,),
                              atol=atol, rtol=rtol, method='Radau')
        cpu_seconds = time.process_time() - cpu0

    contacts, intervals = _contacts_from_trajectory(resultat1.t, resultat1.y, r1, H1)

    final_energies = seed_energies(resultat1.y[:, -1], pL_vals)
    final_energies["total"] = sum(final_energies.values())

    return {
        "cpu_seconds": cpu_seconds,
        "nfev": int(resultat1.nfev),
        "njev": int(resultat1.njev),
        "nlu": int(resultat1.nlu),
        "status": int(resultat1.status),
        "message": resultat1.message,
        "t": resultat1.t,
        "y": resultat1.y,
        "contacts": contacts,
        "contact_intervals": intervals,
        "initial_energies": initial_energies,
        "final_energies": final_energies,
        "rhs_calls": gradient.calls,
        "band_calls": gradient.writes,
        "impact_list": gradient.impact_list,
        "final_params": list(pL_vals),
        "runtime_warnings": len(caught),
        "warning_messages": sorted({str(w.message) for w in caught}),
    }


# ---------------------------------------------------------------------------------------
# Orientation conversion
# ---------------------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _dcm_123_lam():
    """Lambdify sympy's ``N.dcm(A)`` for ``A.orient_body_fixed(N, (q1, q2, q3), '123')``."""
    q1, q2, q3 = sm.symbols('q1, q2, q3')
    N, A = sm.symbols('N, A', cls=me.ReferenceFrame)
    A.orient_body_fixed(N, (q1, q2, q3), '123')
    return sm.lambdify((q1, q2, q3), N.dcm(A), modules="numpy")


def angles_123_dcm(q1, q2, q3):
    """Direction cosine matrix N_C_A (3 x 3 numpy array) of the seed's body-fixed 123 angles.

    Obtained by lambdifying sympy's ``N.dcm(A)`` after
    ``A.orient_body_fixed(N, (q1, q2, q3), '123')`` -- the seed's orientation.

    Convention (verified numerically against ``A.x.express(N)`` etc. and against the
    elementary rotations; see the self-check at the bottom of this module):

    * the columns are A.x, A.y, A.z expressed in N, so ``v_N = DCM @ v_A`` and
      ``v_A = DCM.T @ v_N``;
    * ``DCM = Rx(q1) @ Ry(q2) @ Rz(q3)`` with the usual right-handed active rotation
      matrices ``Rx(a) = [[1, 0, 0], [0, cos a, -sin a], [0, sin a, cos a]]`` etc.: rotate
      by q1 about N.x, then by q2 about the rotated y axis, then by q3 about the twice
      rotated z axis.

    Scalar angles only.
    """
    return np.array(_dcm_123_lam()(float(q1), float(q2), float(q3)), dtype=float)


def _elementary_123(q1, q2, q3):
    """Rx(q1) @ Ry(q2) @ Rz(q3) built by hand (used by the self-check only)."""
    c1, s1, c2, s2, c3, s3 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2), np.cos(q3), np.sin(q3)
    rx = np.array([[1, 0, 0], [0, c1, -s1], [0, s1, c1]])
    ry = np.array([[c2, 0, s2], [0, 1, 0], [-s2, 0, c2]])
    rz = np.array([[c3, -s3, 0], [s3, c3, 0], [0, 0, 1]])
    return rx @ ry @ rz


# ---------------------------------------------------------------------------------------
# Self-check
# ---------------------------------------------------------------------------------------

if __name__ == "__main__":
    wall0 = time.perf_counter()
    mdl = build_seed_model()
    print(f"build_seed_model(): {time.perf_counter() - wall0:.2f} s wall")
    for key, val in mdl.build_seconds.items():
        print(f"    {key:28s} {val:7.2f} s")
    wall1 = time.perf_counter()
    build_seed_model()
    print(f"second (cached) call: {1e3 * (time.perf_counter() - wall1):.3f} ms")

    print(f"forcing_full has {sm.count_ops(mdl.forcing_full):,} operations (seed: 60,602)")
    print(f"mass_matrix_full has {sm.count_ops(mdl.mass_matrix_full):,} operations (seed: 3,337)")

    p_def = seed_default_parameter_values()
    dy = seed_state_derivative(SEED_INITIAL_STATE, p_def)
    print("derivative at the seed's initial state:")
    for name, val in zip(SEED_STATE_NAMES, dy):
        print(f"    d{name}/dt = {val: .10g}")
    e0 = seed_energies(SEED_INITIAL_STATE, p_def)
    print("energies at the initial state:", {k: round(v, 6) for k, v in e0.items()},
          f"total {sum(e0.values()):.6f}")

    # orientation convention
    rng = np.random.default_rng(0)
    qs = rng.uniform(-np.pi, np.pi, size=3)
    _q1, _q2, _q3 = sm.symbols('q1, q2, q3')
    _N, _A = sm.symbols('N, A', cls=me.ReferenceFrame)
    _A.orient_body_fixed(_N, (_q1, _q2, _q3), '123')
    subs = dict(zip((_q1, _q2, _q3), qs))
    cols = np.array([[float(_v.express(_N).dot(_e).subs(subs)) for _e in _N]
                     for _v in (_A.x, _A.y, _A.z)]).T
    dcm = angles_123_dcm(*qs)
    print("angles_123_dcm: max|DCM - [A.x A.y A.z]_N| =",
          f"{np.max(np.abs(dcm - cols)):.2e};",
          f"max|DCM - Rx Ry Rz| = {np.max(np.abs(dcm - _elementary_123(*qs))):.2e}")

    print("running the seed's pipeline (Radau, rtol = atol = 1e-12, 5 s) ...")
    res = run_seed_pipeline()
    print(f"    status {res['status']}: {res['message']}")
    print(f"    cpu_seconds {res['cpu_seconds']:.2f}, nfev {res['nfev']:,}, njev {res['njev']}, "
          f"nlu {res['nlu']:,}, all RHS calls {res['rhs_calls']:,}, "
          f"band (parameter-writing) calls {res['band_calls']:,}")
    print(f"    runtime warnings during solve_ivp: {res['runtime_warnings']} "
          f"{res['warning_messages']}")
    print(f"    {len(res['contacts'])} contacts (from the trajectory, first sample):")
    for d in res["contact_intervals"]:
        print(f"      {d['plane']:8s} t = {d['t_start']:.3f} .. {d['t_end']:.3f} s, "
              f"peak penetration {d['peak_penetration']:.3f}, "
              f"um1 {d['um1_before']:+.3f} -> {d['um1_after']:+.3f} m/s")
    print(f"    seed's own impact_list: {len(res['impact_list'])} entries")
    ei, ef = res["initial_energies"], res["final_energies"]
    print(f"    energy: initial total {ei['total']:.2f} J -> final total {ef['total']:.2f} J "
          f"(kinetic {ef['kinetic']:.4f}, potential {ef['potential']:.4f}, "
          f"spring {ef['spring']:.4f})")
