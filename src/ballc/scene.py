"""Scene: every parameter and initial condition of one simulation, with units.

Defaults are the seed's (the gallery example "ball bouncing between two planes" by
Peter Stahlecker).  SI units.  The fields, their units, seed symbols and defaults are
in :class:`Scene`'s docstring (its Parameters and the table in its Notes).
"""
from __future__ import annotations

import difflib
import functools
import json
import math
from dataclasses import dataclass, fields

import numpy as np

from . import _core
from ._errors import SceneError
from ._format import plain
from .orientation import quaternion_from_angles_123
from .planes import MAX_PLANES, Plane, PlaneError, check_room, names_of, seed_planes

#: The values of ``Scene.tangential_model``.
TANGENTIAL_MODELS = ("mixture", "friction", "dig-in", "compliant")
FRICTION_REGULARIZATIONS = ("exact", "max", "smooth")
#: The values of ``Scene.rolling_model`` (docs/contact_laws.md, "Rolling resistance").
ROLLING_MODELS = ("exact", "sds")
#: The sds model's default dashpot as a fraction of its critical damping (Ai et al. 2011
#: recommend eta_r = 0.3): gamma = ROLLING_DAMPING_FRACTION * 2 sqrt(I_r k) / r.
ROLLING_DAMPING_FRACTION = 0.3
#: The values of ``Scene.normal_damping`` (docs/contact_laws.md).
NORMAL_DAMPINGS = ("hunt_crossley", "viscoelastic")
#: c_tau when a scene gives neither c_tau nor restitution (the seed's value).
DEFAULT_C_TAU = 0.9
#: The rim speed r |omega| must be below this many times the ball's wave speed
#: c = sqrt(E / rho) (``wave_speed``).  A ball spinning at rim speed r omega is
#: stretched by its centrifugal force by a strain of order rho omega^2 r^2 / E =
#: (r omega / c)^2: 100 (10,000 %) at 10 c, where rubber breaks at ~ 7.  Far beyond it
#: the rigid ball that ballc simulates is no model of any ball (docs/limits.md); and a
#: spin costs about omega t_end steps, so an absurd one crawled to the call budget.
#: (The stress matrix spins the default ball, c = 112 m/s, at rim speeds up to 1000 m/s.)
SPEED_LIMIT = 10.0
#: The centre's speed |v| must be below the speed of light (m/s): ballc's mechanics is
#: Newton's.  (A throw far beyond the wave speed is allowed: its impact ends honestly,
#: the ball passing through the plane.)
SPEED_OF_LIGHT = 299_792_458.0

#: Scene field -> seed symbol(s).
SEED_SYMBOLS = {
    "mass": "m", "observer_mass": "mo", "radius": "r", "gravity": "g",
    "ceiling_height": "H", "inertia": ("iXX", "iYY", "iZZ"),
    "observer_position": ("alpha", "beta", "gamma"),
    "ball_youngs_modulus": "Eb", "plane_youngs_modulus": "Ep",
    "ball_poisson_ratio": "nyb", "plane_poisson_ratio": "nyp", "c_tau": "ctau",
    "friction_coefficient": "mu", "mixture": "mixtur",
    "position": ("m1", "m2", "m3"), "velocity": ("um1", "um2", "um3"),
    "angles": ("q1", "q2", "q3"), "angular_velocity": ("u1", "u2", "u3"),
}


@dataclass(frozen=True)
class Scene:
    """One ball between planes: a floor (z = 0) and a ceiling (z = ceiling_height), or
    one to six planes at any orientation (``planes``).

    All quantities in SI units.  ``Scene(**fields)`` validates; invalid values raise
    :class:`SceneError` naming the field, the value and what is allowed (an unknown
    field gets a "did you mean").  Scenes are frozen: :meth:`replace` makes a changed
    copy.

    Parameters
    ----------
    mass : float
        Mass of the ball (kg), > 0.  Default 1.0.
    observer_mass : float
        Mass of the observer particle inside the ball (kg), >= 0.  Default 1e-4.
    radius : float
        Radius of the ball (m), > 0.  Default 1.0.
    gravity : float or tuple of 3 float
        Gravitational acceleration (m/s^2): a number g >= 0 points along -z, (0, 0, -g);
        or the acceleration as a vector (3 finite numbers).  Default 9.81.
    ceiling_height : float or None
        Height H of the ceiling above the floor (m), > 2 radius: the shorthand for the
        seed's two planes, the floor (0, 0, 0), normal (0, 0, 1), and the ceiling
        (0, 0, H), normal (0, 0, -1), named "floor" and "ceiling".  Default 10.0; None
        (and it must not be given) with ``planes``.
    planes : tuple of ballc.Plane, optional
        One to six planes, each a point and a normal pointing into the space where the
        ball lives (:class:`ballc.Plane`; a mapping of point, normal and name is taken
        too, as a TOML ``[[planes]]`` table gives it); none may face another closer than
        2 radius, and together they must leave room for the ball.  The state vector has
        15 states and two per plane, each plane's tangential deflection
        ``<name>_deflection_x``, ``_y`` (:attr:`state_names`).  Default (None): the
        ``ceiling_height`` shorthand.
    inertia : tuple of 3 float, optional
        Principal moments of inertia about the ball's x, y, z axes (kg m^2).
        Default (None): 2/5 mass radius^2 each, a solid sphere.
    observer_position : tuple of 3 float
        Position of the observer in the ball frame, in units of the radius (1).
        Default (0.7, 0, 0.7).
    ball_youngs_modulus, plane_youngs_modulus : float
        Young's moduli of the ball and of both planes (Pa), > 0.
        Defaults 3e3 and 2e10.
    ball_poisson_ratio, plane_poisson_ratio : float
        Poisson ratios of the ball and of the planes (1), in (-1, 0.5].
        Defaults 0.25 and 0.15.
    c_tau : float, optional
        Hunt-Crossley parameter (1), in (0, 1]: 1 is perfectly elastic; close to the
        coefficient of restitution of a normal impact for c_tau near 1.  Default 0.9
        (the seed's) unless ``restitution`` is given: a scene gives one or the other.
    restitution : float, optional
        Coefficient of restitution e of the normal law (1), in (0, 1]: the exit / entry
        normal speed ratio of an isolated normal impact without gravity, inverted exactly
        for the normal damping in use (Hunt-Crossley: chi (1 + e) = ln[(1 + chi)/(1 - chi
        e)], any e > 0, where c_tau only reaches e > 0.4877; viscoelastic: gamma(e) of the
        dimensionless Hertz impact, :mod:`ballc.restitution`).  Default None (c_tau).
        It is a parameter of the law, not the rebound a run shows: gravity acts during a
        contact too and lowers a floor rebound (raises a ceiling one) by about a third of
        g t_c / abs(v_n after) (t_c the contact time) -- on the default soft ball (contacts
        of ~0.1 s) e = 0.1 rebounds from the seed throw's first impact at 0.082 -- and the
        dig-in law pushes along the contact point's velocity at impact, normal part
        included.  Each contact's measured ratio is ``Contact.rebound_ratio``; the
        contact table names the contacts where gravity's impulse is more than 10 % of
        the exit speed (``Result.gravity_affected_contacts``).
    normal_damping : str
        "hunt_crossley" (default, the seed's) or "viscoelastic" (the DEM codes' Hertz
        viscous damping c_n = 2 gamma sqrt(m* k_n), clamped so the force is never
        attractive; only with ``tangential_model = "compliant"``).  See
        docs/contact_laws.md.
    damping_ratio : float, optional
        gamma of the viscoelastic normal damping (1), >= 0; or give ``restitution``.
    tangential_damping_ratio : float, optional
        gamma_t of the compliant law's tangential damping c_t = 2 gamma_t sqrt(m* k_t)
        (1), >= 0.  Default (None): with the compliant law, the viscoelastic gamma of
        the scene's normal restitution (Kratos' choice, the same gamma as the normal
        force); the other laws have no tangential damping and leave it None.
    friction_coefficient : float
        Coulomb friction coefficient mu (1), >= 0.  Default 0.1.
    mixture : float
        Weight of the dig-in law in the "mixture" model (1), in [0, 1]: tangential
        force = (1 - mixture) friction + mixture dig-in.  Default 0.375.
    tangential_model : str
        "mixture" (default), "friction" (mixture taken as 0), "dig-in" (mixture taken
        as 1) or "compliant": ballc's passive tangential-compliance model, the DEM
        codes' incremental Mindlin spring of stiffness ``tangential_stiffness_ratio``
        times the normal contact stiffness, damped, capped at mu F_n
        (docs/contact_laws.md).
    friction_regularization_speed : float
        Regularisation speed v_s of the "max" and "smooth" friction laws (m/s), > 0.
        Default 1e-10, as in the seed's code.
    friction_regularization : str
        "exact" (default: Coulomb's law itself, the limit v_s -> 0 of the seed's; stick
        and slip are separate modes whose transitions are integrator events, see
        ``ballc.stickslip``; for the compliant law, its Coulomb cap as exact elastic and
        sliding modes, the DEM codes' truncation in the limit dt -> 0, see
        ``ballc.compliantmodes``), "max" (the seed's literal v_t / max(abs(v_t), v_s)) or
        "smooth" (v_t / sqrt(abs(v_t)^2 + v_s^2)); for the compliant law either of these
        two runs it with its smooth yield instead of modes (docs/contact_laws.md).
    tangential_stiffness_ratio : float, optional
        Tangential / normal contact stiffness ratio kappa of the compliant model (1).
        Default (None): Mindlin's 4 G* / E*, from the Poisson ratios and the moduli.
    rolling_resistance : float
        Rolling resistance coefficient mu_r (1), >= 0: the contact resists the ball's
        rolling relative to the plane with a torque of at most mu_r radius F_n (F_n the
        normal force), a fourth part of every contact law (docs/contact_laws.md,
        "Rolling resistance").  Default 0: none (every result as without it).
    rolling_model : str
        "exact" (default; Ai et al.'s type A with holding): while the ball rolls a torque
        mu_r r F_n opposes the rolling; where the rolling velocity reaches 0 and the
        torque that holds it is within the cap, the ball holds -- exact events, as
        Coulomb's stick and slip.  "sds" (LAMMPS' ``rolling sds``): a rolling spring
        ``rolling_stiffness`` with a dashpot ``rolling_damping`` and a slider at the cap,
        in ballc's passive form.  The same model serves the twisting part.
    rolling_stiffness : float, optional
        k_r of the sds model's rolling spring (N/m; its torque r k_r xi for a rolling
        displacement xi of the contact, LAMMPS' k_roll).  Default (None): Ai et al.'s
        2.25 mu_r^2 k_n at the ball's static load (k_n = 3/2 k0 rho_eq^(1/2)).
    rolling_damping : float, optional
        gamma_r of the sds model's rolling dashpot (N s/m; LAMMPS' gamma_roll), >= 0.
        Default (None): 0.3 of its critical value 2 sqrt((I + m r^2) k_r) / r.
    twisting_resistance : float
        Twisting resistance coefficient mu_t (1), >= 0: the contact resists the ball's
        spin about the plane's normal with a torque of at most mu_t radius F_n, in the
        model ``rolling_model``.  Default 0: none.
    twisting_stiffness, twisting_damping : float, optional
        The sds model's twisting spring k_w (N/m; torque r k_w xi_w) and dashpot (N s/m).
        Defaults (None): k_w = the rolling spring's default, gamma_w = 0.3 of
        2 sqrt(I k_w) / r.
    position : tuple of 3 float
        Initial position of the centre (m), on the ball's side of every plane, less than
        one radius deep in it (0 < z < ceiling_height with the shorthand).  Default
        (0, 0, 5).
    velocity : tuple of 3 float
        Initial velocity of the centre (m/s).  Default (-5, 5, -25).
    angles : tuple of 3 float
        Initial orientation as the seed's body-fixed 123 angles q1, q2, q3 (rad).
        Default (0, 0, 0).
    angular_velocity : tuple of 3 float
        Initial angular velocity, inertial components (rad/s).  Default (0, 0, 0).

    Notes
    -----
    The fields with the seed's symbols (the seed's defaults are ballc's):

    =================================  ==============  ===========  ====================
    field                              seed symbol     unit         default
    =================================  ==============  ===========  ====================
    mass                               m               kg           1.0
    observer_mass                      mo              kg           1e-4
    radius                             r               m            1.0
    gravity                            g               m/s^2        9.81
    ceiling_height                     H               m            10.0
    inertia (about ball x, y, z)       iXX, iYY, iZZ   kg m^2       2/5 m r^2 each
    observer_position (ball frame)     alpha, beta,    r (radius)   (0.7, 0, 0.7)
                                       gamma
    ball_youngs_modulus                Eb              Pa           3e3
    plane_youngs_modulus               Ep              Pa           2e10
    ball_poisson_ratio                 nyb             1            0.25
    plane_poisson_ratio                nyp             1            0.15
    c_tau                              ctau            1            0.9 (or restitution)
    restitution                        (none)          1            None (c_tau)
    normal_damping                     (none)          (none)       "hunt_crossley"
    damping_ratio                      (none)          1            None
    tangential_damping_ratio           (none)          1            compliant: from e
    friction_coefficient               mu              1            0.1
    mixture                            mixtur          1            0.375
    tangential_model                   (none)          (none)       "mixture"
    friction_regularization_speed      (1e-10 in the   m/s          1e-10
                                       seed's code)
    friction_regularization            (none)          (none)       "exact" (or "max",
                                                                    "smooth")
    tangential_stiffness_ratio         (none)          1            Mindlin (compliant)
    rolling_resistance                 (none)          1            0.0
    rolling_model                      (none)          (none)       "exact" (or "sds")
    rolling_stiffness                  (none)          N/m          sds: Ai et al.
    rolling_damping                    (none)          N s/m        sds: 0.3 critical
    twisting_resistance                (none)          1            0.0
    twisting_stiffness                 (none)          N/m          sds: as rolling
    twisting_damping                   (none)          N s/m        sds: 0.3 critical
    planes                             (none)          (none)       None: the floor and
                                                                    ceiling_height's
                                                                    ceiling
    position (centre)                  m1, m2, m3      m            (0, 0, 5)
    velocity (centre)                  um1, um2, um3   m/s          (-5, 5, -25)
    angles (body-fixed 123)            q1, q2, q3      rad          (0, 0, 0)
    angular_velocity (inertial comps)  u1, u2, u3      rad/s        (0, 0, 0)
    =================================  ==============  ===========  ====================

    A scene may start in contact with a plane (0 < z < H): see :func:`simulate`'s
    notes on what such a start latches.  The seed's latched values rhodtu, rhodto,
    ru1..3, ro1..3 are not parameters: ballc latches them itself at each contact start.
    """

    mass: float = 1.0
    observer_mass: float = 1e-4
    radius: float = 1.0
    gravity: float | tuple = 9.81
    ceiling_height: float | None = 10.0
    inertia: tuple | None = None
    observer_position: tuple = (0.7, 0.0, 0.7)
    ball_youngs_modulus: float = 3e3
    plane_youngs_modulus: float = 2e10
    ball_poisson_ratio: float = 0.25
    plane_poisson_ratio: float = 0.15
    c_tau: float | None = None
    restitution: float | None = None
    normal_damping: str = "hunt_crossley"
    damping_ratio: float | None = None
    tangential_damping_ratio: float | None = None
    friction_coefficient: float = 0.1
    mixture: float = 0.375
    tangential_model: str = "mixture"
    friction_regularization_speed: float = 1e-10
    friction_regularization: str = "exact"
    tangential_stiffness_ratio: float | None = None
    rolling_resistance: float = 0.0
    rolling_model: str = "exact"
    rolling_stiffness: float | None = None
    rolling_damping: float | None = None
    twisting_resistance: float = 0.0
    twisting_stiffness: float | None = None
    twisting_damping: float | None = None
    position: tuple = (0.0, 0.0, 5.0)
    velocity: tuple = (-5.0, 5.0, -25.0)
    angles: tuple = (0.0, 0.0, 0.0)
    angular_velocity: tuple = (0.0, 0.0, 0.0)
    planes: tuple | None = None

    def __new__(cls, *args, **kwargs):
        # Unknown keyword -> SceneError with a "did you mean" (the dataclass __init__
        # would raise a bare TypeError without a suggestion).
        _reject_unknown_fields(kwargs)
        scene = super().__new__(cls)
        # ceiling_height given with planes is a contradiction; its default is not
        object.__setattr__(scene, "_ceiling_given", kwargs.get("ceiling_height") is not None)
        return scene

    #: The fields that are 3-vectors (a tuple of 3 floats each).
    VECTOR_FIELDS = ("inertia", "observer_position", "position", "velocity", "angles",
                     "angular_velocity")

    def __post_init__(self):
        _resolve_planes(self)
        for name in self.VECTOR_FIELDS:
            value = getattr(self, name)
            if value is None or (type(value) is tuple and len(value) == 3 and all(
                    type(v) is float for v in value)):   # a vector already (a replace)
                continue
            try:
                if isinstance(value, (str, bytes)) or any(
                        isinstance(v, (str, bytes, bool, np.bool_)) for v in value):
                    raise TypeError   # "123" would otherwise become (1.0, 2.0, 3.0)
                vector = tuple(float(v) for v in value)
            except (TypeError, ValueError):
                raise SceneError(f"{name} must be 3 numbers, got {value!r}") from None
            if len(vector) != 3:
                raise SceneError(f"{name} must be 3 numbers, got {len(vector)}: {value!r}")
            object.__setattr__(self, name, vector)
        if self.tangential_stiffness_ratio is None:
            object.__setattr__(self, "tangential_stiffness_ratio",
                               mindlin_stiffness_ratio(self.ball_poisson_ratio,
                                                       self.plane_poisson_ratio,
                                                       self.ball_youngs_modulus,
                                                       self.plane_youngs_modulus))
        if self.inertia is None:
            try:
                i = 0.4 * float(self.mass) * float(self.radius) ** 2
            except (TypeError, ValueError):
                i = math.nan   # _validate reports the bad mass or radius first
            object.__setattr__(self, "inertia", (i, i, i))
        _validate(self)
        _resolve_damping(self)   # after _validate: c_tau, if given, is a valid number
        _resolve_rolling(self)

    @classmethod
    def from_dict(cls, values: dict) -> "Scene":
        """Scene from a mapping; unknown keys raise with a suggestion."""
        _reject_unknown_fields(values)
        return cls(**values)

    def to_dict(self) -> dict:
        """Every field by name (SI units), as ``from_dict`` and the TOML files take them."""
        # every field is a number, a string, None or a tuple of floats (__post_init__):
        # immutable, so a shallow copy is asdict's (whose deep copy cost a sweep of the
        # 100 x 100 map ~1 s in its parent process)
        mine = self.__dict__   # (a frozen dataclass keeps its fields there)
        values = {name: mine[name] for name in _FIELD_NAMES}
        for name in getattr(self, "_derived", ()):
            values[name] = None     # computed from another field: not an input
        # the seed's planes are the shorthand's (ceiling_height); given planes as tables
        values["planes"] = None if self.ceiling_height is not None else [
            plane.to_dict() for plane in self.planes]
        return values

    @classmethod
    def from_toml(cls, path) -> "Scene":
        """Scene from a TOML file of scene fields (SI units, as in the table above).

        A ``[simulate]`` table (e.g. ``t_end``) is for ``ballc run`` and is ignored here.
        Errors (unreadable TOML, unknown field, invalid value) raise SceneError naming the file.
        """
        values = read_toml(path)
        values.pop("simulate", None)
        try:
            return cls.from_dict(values)
        except SceneError as error:
            raise SceneError(f"{path}: {error}") from None

    def to_toml(self, path) -> None:
        """Write every field to a TOML file that ``Scene.from_toml`` reads back equal."""
        lines = ["# ballc scene: SI units, fields as in README.md 'Scene fields'"]
        values = self.to_dict()
        planes = values.pop("planes")
        lines += [f"{name} = {_toml_value(value)}" for name, value in values.items()
                  if value is not None]
        for plane in planes or ():   # [[planes]] tables: after every plain key
            lines += ["", "[[planes]]"] + [f"{key} = {_toml_value(value)}"
                                           for key, value in plane.items()]
        with open(path, "w", encoding="utf-8") as stream:
            stream.write("\n".join(lines) + "\n")

    def __getstate__(self):
        """The fields and what they derive, without the C loop's converted constants
        (ballc.loop_constants keeps them on the scene; rebuilt where it runs)."""
        state = dict(self.__dict__)
        state.pop("_drive_scene", None)
        return state

    def replace(self, **changes) -> "Scene":
        """A copy with some fields changed (validated).  Giving one of c_tau,
        restitution and damping_ratio drops the others (a scene gives one)."""
        values = self.to_dict()
        if changes.get("planes") is not None:   # planes replace the shorthand
            values["ceiling_height"] = None
        elif "ceiling_height" in changes:
            values["planes"] = None
        if any(name in changes for name in _DAMPING_INPUTS) or "normal_damping" in changes:
            keep = "restitution" if "normal_damping" in changes else None
            for name in _DAMPING_INPUTS:
                if name != keep:
                    values[name] = None
        return Scene.from_dict({**values, **changes})

    @property
    def normal_restitution(self) -> float:
        """Coefficient of restitution e of a normal impact with this scene's normal law
        (1): ``restitution`` if given, else the one its c_tau or damping_ratio gives."""
        from . import restitution as law
        if self.restitution is not None:
            return float(self.restitution)
        if self.normal_damping == "viscoelastic":
            return law.viscoelastic_restitution(self.damping_ratio)
        return law.hunt_crossley_restitution_of_chi(1.5 * (1 - self.c_tau))

    @property
    def hunt_crossley_chi(self) -> float:
        """chi of the Hunt-Crossley bracket 1 + chi rhodot / |rhodot^-| (1)."""
        from . import restitution as law
        if self.normal_damping == "hunt_crossley" and self.restitution is not None:
            return law.hunt_crossley_chi_for_restitution(self.restitution)
        return 1.5 * (1 - (self.c_tau if self.c_tau is not None else 1.0))

    @property
    def effective_mixture(self) -> float:
        """Weight of the dig-in law actually used (0 for "friction", 1 for "dig-in"; the
        compliant model has no dig-in part)."""
        return {"friction": 0.0, "dig-in": 1.0, "compliant": 0.0}.get(
            self.tangential_model, self.mixture)

    @functools.cached_property
    def hertz_stiffness(self) -> float:
        """k0 = 4 / (3 (sigma_b + sigma_p)) sqrt(r), sigma = (1 - nu^2) / E, N/m^(3/2):
        evaluated by the generated kernel, so the formula exists once (codegen/contact.py)."""
        return float(_core.hertz_stiffness(self.parameter_vector()))

    def parameter_vector(self) -> np.ndarray:
        """Parameters in the generated layout order (``ballc._core.PARAMETER_NAMES``);
        a fresh copy each call (the scene is frozen: built once)."""
        return self._parameters.copy()

    @functools.cached_property
    def plane_names(self) -> tuple:
        """Each plane's name (its own, or ``plane<i>``), in the plane table's order."""
        return names_of(self.planes)

    @functools.cached_property
    def state_names(self) -> tuple:
        """The names of the state vector's rows: the ball's 15, then each plane's
        ``<name>_deflection_x``, ``_y`` (the seed's: ``ballc.STATE_NAMES``); with rolling
        resistance (:attr:`rolling_on`) then ``dissipated_rolling`` and each plane's
        rolling springs ``<name>_rolling_x``, ``_rolling_y``, ``_twisting``."""
        return _state_names(self.plane_names, self.rolling_on)

    @property
    def rolling_on(self) -> bool:
        """Whether the scene has rolling or twisting resistance (its runs then have its
        states; without it every run is as before, bit for bit)."""
        return self.rolling_resistance > 0 or self.twisting_resistance > 0

    @functools.cached_property
    def parameter_names(self) -> tuple:
        """The names of :meth:`parameter_vector`'s entries."""
        return _parameter_names(self.plane_names)

    @functools.cached_property
    def latch_names(self) -> tuple:
        """The names of the latched values (per plane, LATCH fields)."""
        return _latch_names(self.plane_names)

    @property
    def gravity_vector(self) -> np.ndarray:
        """The gravitational acceleration as a vector (m/s^2): (0, 0, -g) for a number."""
        if isinstance(self.gravity, tuple):
            return np.array(self.gravity)
        return np.array([0.0, 0.0, -float(self.gravity)])

    @property
    def gravity_magnitude(self) -> float:
        """The length of the gravity vector (m/s^2)."""
        if isinstance(self.gravity, tuple):
            return math.sqrt(sum(g * g for g in self.gravity))
        return float(self.gravity)

    @functools.cached_property
    def _parameters(self) -> np.ndarray:
        ix, iy, iz = self.inertia
        a, b, c = self.observer_position
        gx, gy, gz = self.gravity_vector
        values = {
            "mass": self.mass, "observer_mass": self.observer_mass,
            "gravity_x": gx, "gravity_y": gy, "gravity_z": gz,
            "radius": self.radius,
            "observer_alpha": a, "observer_beta": b, "observer_gamma": c,
            "inertia_xx": ix, "inertia_yy": iy, "inertia_zz": iz,
            "mixture": self.effective_mixture,
            "ball_poisson_ratio": self.ball_poisson_ratio,
            "plane_poisson_ratio": self.plane_poisson_ratio,
            "ball_youngs_modulus": self.ball_youngs_modulus,
            "plane_youngs_modulus": self.plane_youngs_modulus,
            "c_tau": 1.0 - self.hunt_crossley_chi / 1.5,
            "friction_coefficient": self.friction_coefficient,
            "friction_regularization_speed": self.friction_regularization_speed,
            "smooth_friction": float(self.friction_regularization == "smooth"),
            "tangential_stiffness_ratio": self.tangential_stiffness_ratio,
            "normal_damping_model": float(self.normal_damping == "viscoelastic"),
            "damping_ratio": self.damping_ratio or 0.0,
            "tangential_damping_ratio": self.tangential_damping_ratio or 0.0,
            "rolling_resistance": self.rolling_resistance,
            "rolling_stiffness": self.rolling_stiffness or 0.0,
            "rolling_damping": self.rolling_damping or 0.0,
            "twisting_resistance": self.twisting_resistance,
            "twisting_stiffness": self.twisting_stiffness or 0.0,
            "twisting_damping": self.twisting_damping or 0.0,
            # the plane table: its count, then a point and a normal (towards the ball) per
            # plane, in PLANE_FIELD_NAMES' order (point x, y, z, normal x, y, z)
            "plane_count": len(self.planes),
        }
        return np.array([float(values[name]) for name in _core.BASE_PARAMETER_NAMES]
                        + [v for plane in self.planes for v in (*plane.point, *plane.normal)])

    def initial_state(self) -> np.ndarray:
        """State vector in the generated layout order (:attr:`state_names`); a fresh copy
        each call."""
        return self._initial.copy()

    @functools.cached_property
    def _initial(self) -> np.ndarray:
        """The initial state, built once (read-only: every run starts from it)."""
        at = _core.STATE_INDEX
        state = np.zeros(len(self.state_names))   # the dissipated work and deflections: zero
        state[at["qw"]:at["qw"] + 4] = _quaternion_of(*self.angles)
        for name, first in (("position", "x"), ("angular_velocity", "omega_x"),
                            ("velocity", "vx")):
            state[at[first]:at[first] + 3] = getattr(self, name)
        state.flags.writeable = False
        return state


# The layouts' names, each built once per set of planes (a sweep makes thousands of
# scenes with the same planes; names are tuples of str: immutable).
_state_names = functools.lru_cache(maxsize=256)(_core.state_names)
_parameter_names = functools.lru_cache(maxsize=256)(_core.parameter_names)
_latch_names = functools.lru_cache(maxsize=256)(_core.latch_names)

# Scene._parameters writes each plane's point, then its normal: the generated order.
if _core.PLANE_FIELD_NAMES != tuple(f"{what}_{axis}" for what in ("point", "normal")
                                    for axis in "xyz"):
    raise ImportError(f"the generated plane fields {_core.PLANE_FIELD_NAMES} are not point "
                      "x, y, z then normal x, y, z, the order Scene._parameters writes")

#: The Scene fields' names, in order (dataclasses.fields is slow to ask every time).
_FIELD_NAMES = tuple(f.name for f in fields(Scene))
_FIELD_SET = frozenset(_FIELD_NAMES)


def _seed_form(planes) -> bool:
    """Whether ``planes`` are the ceiling_height shorthand's, for some height (what
    ``dataclasses.replace`` passes back with the ceiling_height it is given)."""
    if not isinstance(planes, tuple) or len(planes) != 2 or not all(
            isinstance(p, Plane) for p in planes):
        return False
    floor, ceiling = planes
    return (floor == Plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), "floor")
            and ceiling.name == "ceiling" and ceiling.normal == (0.0, 0.0, -1.0)
            and ceiling.point[:2] == (0.0, 0.0))


def _resolve_planes(s: Scene) -> None:
    """The scene's planes: the ceiling_height shorthand's two, or the given ones (1 to
    MAX_PLANES, each a Plane, names unique); SceneError naming the field otherwise.  The
    shorthand's planes given back with a ceiling_height (``dataclasses.replace``) are the
    shorthand of that height."""
    if getattr(s, "_ceiling_given", False) and _seed_form(s.planes):
        object.__setattr__(s, "planes", None)
    if s.planes is None:
        if s.ceiling_height is None:
            raise SceneError("ceiling_height = None is not allowed without planes: give "
                             "ceiling_height (the seed's floor and ceiling) or planes")
        try:
            object.__setattr__(s, "planes", seed_planes(float(s.ceiling_height)))
        except (TypeError, ValueError, PlaneError):
            _fail("ceiling_height", s.ceiling_height, "must be a real number")
        return
    if getattr(s, "_ceiling_given", False):
        raise SceneError(f"ceiling_height = {plain(s.ceiling_height)} is given with planes: "
                         "ceiling_height is the shorthand for the seed's floor and ceiling, "
                         "give one or the other")
    object.__setattr__(s, "ceiling_height", None)
    given = s.planes
    if isinstance(given, (Plane, dict, str, bytes)) or not hasattr(given, "__len__"):
        raise SceneError(f"planes = {plain(given)} is not allowed: must be a sequence of "
                         f"1 to {MAX_PLANES} ballc.Plane")
    if not 1 <= len(given) <= MAX_PLANES:
        raise SceneError(f"planes: {len(given)} given is not allowed: a scene has 1 to "
                         f"{MAX_PLANES} planes")
    try:
        planes = tuple(Plane.of(plane, i) for i, plane in enumerate(given))
    except PlaneError as error:
        raise SceneError(str(error)) from None
    names = names_of(planes)
    for i, name in enumerate(names):
        if name in names[:i]:
            raise SceneError(f"planes[{i}]: name = {name!r} is not allowed: another plane has "
                             "it (each plane's name names its states and contacts)")
    object.__setattr__(s, "planes", planes)


@functools.lru_cache(maxsize=256)
def _quaternion_of(q1: float, q2: float, q3: float) -> np.ndarray:
    """quaternion_from_angles_123 of the seed's three angles (rad), kept: a sweep asks
    for the same few initial orientations thousands of times (read-only: callers copy)."""
    found = quaternion_from_angles_123(np.array([q1, q2, q3]))
    found.flags.writeable = False
    return found


_DAMPING_INPUTS = ("c_tau", "restitution", "damping_ratio")


def _resolve_damping(s: Scene) -> None:
    """Check that the scene gives one normal damping input, fill in c_tau's default, the
    viscoelastic gamma of a restitution, and (compliant law only: no other law has
    tangential damping, and the inversion costs ~60 ms per new restitution) the
    tangential damping ratio's default."""
    from . import restitution as law
    derived = []
    if s.normal_damping not in NORMAL_DAMPINGS:
        close = difflib.get_close_matches(str(s.normal_damping), NORMAL_DAMPINGS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise SceneError(f"normal_damping = {s.normal_damping!r} is not allowed: must be one "
                         f"of {NORMAL_DAMPINGS}{hint}")
    given = [name for name in _DAMPING_INPUTS if getattr(s, name) is not None]
    if len(given) > 1:
        raise SceneError(f"{' and '.join(given)} are both given: a scene gives one of "
                         f"{', '.join(_DAMPING_INPUTS)} (replace() drops the others)")
    if s.restitution is not None:
        if not 0 < _finite("restitution", s.restitution) <= 1:
            _fail("restitution", s.restitution, "must be a number in (0, 1]")
        object.__setattr__(s, "restitution", float(s.restitution))
    if s.normal_damping == "viscoelastic":
        if s.c_tau is not None:
            raise SceneError("c_tau is given with normal_damping = 'viscoelastic': give "
                             "restitution or damping_ratio (gamma) instead")
        if s.restitution is None and s.damping_ratio is None:
            raise SceneError("normal_damping = 'viscoelastic' needs restitution (e in "
                             "(0, 1]) or damping_ratio (gamma >= 0)")
        if s.damping_ratio is not None:
            _non_negative("damping_ratio", s.damping_ratio)
        else:
            object.__setattr__(s, "damping_ratio",
                               law.viscoelastic_gamma_for_restitution(s.restitution))
            derived.append("damping_ratio")
    else:
        if s.damping_ratio is not None:
            raise SceneError("damping_ratio (gamma) is the viscoelastic law's: with "
                             "normal_damping = 'hunt_crossley' give c_tau or restitution")
        if s.c_tau is None and s.restitution is None:
            object.__setattr__(s, "c_tau", DEFAULT_C_TAU)
    if s.tangential_damping_ratio is None and s.tangential_model == "compliant":
        gamma = s.damping_ratio if s.normal_damping == "viscoelastic" else \
            law.viscoelastic_gamma_for_restitution(s.normal_restitution)
        object.__setattr__(s, "tangential_damping_ratio", float(gamma))
        derived.append("tangential_damping_ratio")
    elif s.tangential_damping_ratio is not None:
        _non_negative("tangential_damping_ratio", s.tangential_damping_ratio)
    object.__setattr__(s, "_derived", tuple(derived))


_ROLLING_SPRING_FIELDS = ("rolling_stiffness", "rolling_damping", "twisting_stiffness",
                          "twisting_damping")


def _resolve_rolling(s: Scene) -> None:
    """Check the rolling part's fields and fill in the sds model's defaults (after
    _resolve_damping: it appends to the derived fields)."""
    for name in ("rolling_resistance", "twisting_resistance"):
        _non_negative(name, getattr(s, name))
        object.__setattr__(s, name, float(getattr(s, name)))
    if s.rolling_model not in ROLLING_MODELS:
        close = difflib.get_close_matches(str(s.rolling_model), ROLLING_MODELS, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        _fail("rolling_model", s.rolling_model, f"must be one of {ROLLING_MODELS}{hint}")
    given = [name for name in _ROLLING_SPRING_FIELDS if getattr(s, name) is not None]
    if s.rolling_model != "sds" and given:
        _fail(given[0], getattr(s, given[0]), "it is a parameter of the sds model: give "
              "rolling_model = 'sds' with it (the exact model has no spring)")
    for name in given:
        if name.endswith("stiffness"):
            if not _finite(name, getattr(s, name)) > 0:
                _fail(name, getattr(s, name), "must be a finite number > 0")
        else:
            _non_negative(name, getattr(s, name))
        object.__setattr__(s, name, float(getattr(s, name)))
    if s.rolling_model != "sds" or not (s.rolling_resistance > 0 or s.twisting_resistance > 0):
        return
    derived = list(s._derived)
    missing = [f"{part}_stiffness" for part in ("rolling", "twisting")
               if getattr(s, f"{part}_resistance") > 0
               and getattr(s, f"{part}_stiffness") is None]
    if missing and not s.gravity_magnitude > 0:
        _fail(missing[0], None, "needs a value without gravity: its default is Ai et al.'s "
              "2.25 mu_r^2 k_n at the ball's static load, which gravity = 0 does not have")
    if missing:   # Ai et al. (2011): k_r = 2.25 mu_r^2 k_n (force per displacement)
        k0 = s.hertz_stiffness
        load = (s.mass + s.observer_mass) * s.gravity_magnitude
        k_n = 1.5 * k0 * (load / k0) ** (1.0 / 3.0)
        mu = max(s.rolling_resistance, s.twisting_resistance)
        default = 2.25 * mu ** 2 * k_n
        for name in missing:
            object.__setattr__(s, name, float(default))
            derived.append(name)
    radius, mass = float(s.radius), float(s.mass)
    inertia = {"rolling_damping": (sum(s.inertia) / 3 + mass * radius ** 2, "rolling_stiffness"),
               "twisting_damping": (sum(s.inertia) / 3, "twisting_stiffness")}
    for name, (moment, spring) in inertia.items():
        if getattr(s, name) is None and getattr(s, spring) is not None:
            gamma = ROLLING_DAMPING_FRACTION * 2 * math.sqrt(moment * getattr(s, spring)) / radius
            object.__setattr__(s, name, float(gamma))
            derived.append(name)
    object.__setattr__(s, "_derived", tuple(derived))
    s.__dict__.pop("_parameters", None)   # cached by hertz_stiffness, before the defaults


def _non_negative(name, value):
    if not _finite(name, value) >= 0:
        _fail(name, value, "must be a finite number >= 0")


def mindlin_stiffness_ratio(nu_ball, nu_plane, e_ball, e_plane):
    """Mindlin's tangential / normal contact stiffness ratio kappa = 4 G* / E*.

    1/E* = (1 - nu_b^2)/E_b + (1 - nu_p^2)/E_p, 1/G* = (2 - nu_b)/G_b + (2 - nu_p)/G_p,
    G = E / (2 (1 + nu)); for equal materials kappa = 2 (1 - nu) / (2 - nu).
    Non-numeric inputs give NaN (validation reports them).
    """
    try:
        nu_b, nu_p, e_b, e_p = (float(v) for v in (nu_ball, nu_plane, e_ball, e_plane))
        g_b, g_p = e_b / (2 * (1 + nu_b)), e_p / (2 * (1 + nu_p))
        e_star = 1 / ((1 - nu_b ** 2) / e_b + (1 - nu_p ** 2) / e_p)
        g_star = 1 / ((2 - nu_b) / g_b + (2 - nu_p) / g_p)
        return 4 * g_star / e_star
    except (TypeError, ValueError, ZeroDivisionError):
        return math.nan


def _reject_unknown_fields(values) -> None:
    if not (hasattr(values, "keys") and values.keys() <= _FIELD_SET):   # else: all known
        reject_unknown_keys(values, _FIELD_NAMES, "scene field", "the Scene fields")


def reject_unknown_keys(values, known, what: str, allowed: str) -> None:
    """SceneError with a "did you mean" for the first key of ``values`` not in ``known``
    (``what``: e.g. "scene field"; ``allowed``: how to name the known keys)."""
    for key in values:
        if key not in known:
            close = difflib.get_close_matches(str(key), list(known), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise SceneError(f"unknown {what} {key!r} is not allowed: must be one of "
                             f"{allowed}{hint}")


def read_toml(path) -> dict:
    """The TOML file at ``path`` as a dict (tomllib, or tomli on Python 3.10)."""
    try:
        import tomllib
    except ModuleNotFoundError:    # Python 3.10
        import tomli as tomllib
    with open(path, "rb") as stream:
        try:
            return tomllib.load(stream)
        except tomllib.TOMLDecodeError as error:
            raise SceneError(f"{path}: not valid TOML: {error}") from None
        except UnicodeDecodeError as error:
            raise SceneError(f"{path}: not UTF-8 text, as TOML must be (byte "
                             f"0x{error.object[error.start]:02x} at offset {error.start})") from None


def _toml_value(value) -> str:
    """A scene value as TOML: numbers (repr: exact round trip), strings, flat arrays."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, np.integer, np.floating)):
        return repr(float(value)) if isinstance(value, (float, np.floating)) else str(int(value))
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} ({type(value).__name__}) to TOML")


def _fail(name, value, allowed):
    raise SceneError(f"{name} = {plain(value)} is not allowed: {allowed}")


def _finite(name, value) -> float:
    """``value`` as a finite float, or SceneError naming ``name``."""
    if type(value) is float:   # most fields, a replace()'s all: no conversion to check
        if not math.isfinite(value):
            _fail(name, value, "must be finite")
        return value
    # Strings and bools would pass float() but are not numbers (a str field
    # would break arithmetic later, e.g. in hertz_stiffness).
    if isinstance(value, (str, bytes, bool, np.bool_)):
        _fail(name, value, "must be a real number")
    try:
        x = float(value)
    except (TypeError, ValueError):
        _fail(name, value, "must be a real number")
    if not math.isfinite(x):
        _fail(name, value, "must be finite")
    return x


def wave_speed(scene) -> float:
    """The ball's (bar) wave speed sqrt(E_b / rho) (m/s), rho = mass / (4/3 pi r^3) its
    mean density: the speed scale of its elasticity (see SPEED_LIMIT)."""
    density = float(scene.mass) / (4.0 / 3.0 * math.pi * float(scene.radius) ** 3)
    return math.sqrt(float(scene.ball_youngs_modulus) / density)


def check_speeds(scene, velocity, angular_velocity, names=("velocity", "angular_velocity")):
    """SceneError unless the centre speed |velocity| is below the speed of light and the
    rim speed radius |angular_velocity| below SPEED_LIMIT times the ball's wave speed
    (``names``: what to call the two vectors in the message)."""
    speed = math.hypot(*velocity)
    if not speed < SPEED_OF_LIGHT:
        _fail(names[0], tuple(velocity), f"its speed {speed:.3g} m/s must be below the "
              f"speed of light, {SPEED_OF_LIGHT:.9g} m/s (ballc's mechanics is Newton's)")
    limit = SPEED_LIMIT * wave_speed(scene)
    rim = float(scene.radius) * math.hypot(*angular_velocity)
    if not rim < limit:
        _fail(names[1], tuple(angular_velocity), f"its rim speed radius * |omega| = "
              f"{rim:.3g} m/s must be below {SPEED_LIMIT:g} times the ball's wave speed "
              f"sqrt(E / rho) = {limit / SPEED_LIMIT:.4g} m/s, i.e. < {limit:.4g} m/s, "
              f"|omega| < {limit / float(scene.radius):.4g} rad/s (spinning faster, no ball "
              "stays the rigid body ballc simulates: docs/limits.md)")


def _validate(s: Scene) -> None:
    fail, finite = _fail, _finite

    for name in ("mass", "radius", "ball_youngs_modulus", "plane_youngs_modulus",
                 "friction_regularization_speed"):
        if not finite(name, getattr(s, name)) > 0:
            fail(name, getattr(s, name), "must be > 0")
    if s.ceiling_height is not None and not finite("ceiling_height", s.ceiling_height) > 0:
        fail("ceiling_height", s.ceiling_height, "must be > 0")
    for name in ("observer_mass", "friction_coefficient"):
        if not finite(name, getattr(s, name)) >= 0:
            fail(name, getattr(s, name), "must be >= 0")
    _validate_gravity(s)
    for name in ("ball_poisson_ratio", "plane_poisson_ratio"):
        if not -1 < finite(name, getattr(s, name)) <= 0.5:
            fail(name, getattr(s, name), "must be in (-1, 0.5]")
    if s.c_tau is not None and not 0 < finite("c_tau", s.c_tau) <= 1:
        fail("c_tau", s.c_tau, "must be in (0, 1]")
    if s.normal_damping == "viscoelastic" and s.tangential_model != "compliant":
        fail("normal_damping", s.normal_damping, "'viscoelastic' is a part of the compliant "
             "law: use it with tangential_model = 'compliant'")
    if not 0 <= finite("mixture", s.mixture) <= 1:
        fail("mixture", s.mixture, "must be in [0, 1]")
    if not finite("tangential_stiffness_ratio", s.tangential_stiffness_ratio) > 0:
        fail("tangential_stiffness_ratio", s.tangential_stiffness_ratio, "must be > 0")
    if s.friction_regularization not in FRICTION_REGULARIZATIONS:
        fail("friction_regularization", s.friction_regularization,
             f"must be one of {FRICTION_REGULARIZATIONS}")
    if s.tangential_model not in TANGENTIAL_MODELS:
        close = difflib.get_close_matches(str(s.tangential_model), TANGENTIAL_MODELS, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        fail("tangential_model", s.tangential_model, f"must be one of {TANGENTIAL_MODELS}{hint}")
    if s.ceiling_height is not None and not s.ceiling_height > 2 * s.radius:
        fail("ceiling_height", s.ceiling_height, f"must be > 2 * radius = {2 * s.radius}")
    for name in Scene.VECTOR_FIELDS:
        vector = getattr(s, name)
        for i, v in enumerate(vector):
            if not math.isfinite(v):
                fail(f"{name}[{i}]", v, f"every component must be finite (got {name} = {vector})")
    ix, iy, iz = s.inertia
    if min(s.inertia) <= 0:
        fail("inertia", s.inertia, "every moment of inertia must be > 0")
    if ix + iy < iz or iy + iz < ix or iz + ix < iy:
        fail("inertia", s.inertia, "moments must satisfy the triangle inequality "
             "(each <= the sum of the other two)")
    if sum(v * v for v in s.observer_position) >= 1:
        fail("observer_position", s.observer_position,
             "the observer must lie strictly inside the ball (alpha^2 + beta^2 + gamma^2 < 1)")
    if s.ceiling_height is not None:
        z = s.position[2]
        if not 0 < z < s.ceiling_height:
            fail("position", s.position, f"the centre must start between the planes, less "
                 f"than one radius deep in either: 0 < z < {s.ceiling_height}")
    else:
        try:
            check_room(s.planes, float(s.radius))
        except PlaneError as error:
            raise SceneError(f"planes: {error}") from None
        check_inside(s, s.position)
    check_speeds(s, s.velocity, s.angular_velocity)


def check_inside(s: Scene, position, name="position") -> None:
    """SceneError unless the centre ``position`` is on the ball's side of every plane of
    ``s``, less than one radius deep in it (n . (c - p) > 0)."""
    for plane, label in zip(s.planes, s.plane_names):
        height = plane.height(position)
        if not height > 0:
            _fail(name, tuple(float(v) for v in position),
                  f"the centre must start on the ball's side of every plane, less than one "
                  f"radius deep in it: its height above plane {label!r} is n . (c - p) = "
                  f"{height:.6g} m, must be > 0 (a penetration below radius = {s.radius})")


def _validate_gravity(s: Scene) -> None:
    """gravity: a number >= 0 (along -z), or a vector of 3 finite numbers (stored as a
    tuple of floats)."""
    g = s.gravity
    if isinstance(g, (list, tuple, np.ndarray)):
        try:
            if any(isinstance(v, (str, bytes, bool, np.bool_)) for v in g):
                raise TypeError
            vector = tuple(float(v) for v in g)
        except (TypeError, ValueError):
            _fail("gravity", g, "must be a number >= 0 (along -z) or 3 numbers (a vector)")
        if len(vector) != 3 or not all(math.isfinite(v) for v in vector):
            _fail("gravity", g, "must be a number >= 0 (along -z) or 3 finite numbers (a "
                  "vector)")
        object.__setattr__(s, "gravity", vector)
        return
    if not _finite("gravity", g) >= 0:
        _fail("gravity", g, "must be >= 0 (a number points along -z; give a vector of 3 "
              "numbers for any other direction)")

