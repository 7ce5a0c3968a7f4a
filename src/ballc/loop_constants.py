"""The C loop's constants: those of a scene, worked out once per scene, and a run's.

The segment loop (``_driver.c``) takes the constants it needs as numbers: each plane's
contact laws (flag bits), the rest checks' and the orbit's constants; the planes'
geometry, thresholds and slip maps it works out itself from the parameters' plane
table.  :func:`scene_constants` computes those of a
scene once and keeps them on the (frozen) scene, converted to C (``_core.DriveScene``);
:func:`run_constants` adds a run's (its tolerances, t_end, output, user events).
Python validates and converts here; every decision is the C loop's.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, compliantmodes, events, modes, orbit, resting, stickslip
from .flight import polynomial_in_flight, scene_allows as flight_scene_allows
from .options import SCIPY_METHODS
from .user_events import CheckedEvent

#: The attribute of a Scene that keeps its DriveScene (not pickled: Scene.__getstate__).
CACHE = "_drive_scene"
#: The progress report's and Ctrl-C's poll, in s of wall time.
POLL_INTERVAL = 0.1


def scene_constants(scene) -> "_core.DriveScene":
    """The scene's constants of the C loop, converted to C once and kept on the scene
    (a frozen Scene cannot change: a changed one is a new Scene, with its own)."""
    found = scene.__dict__.get(CACHE)
    if found is None:
        found = _core.DriveScene(scene.parameter_vector(), _scene_dict(scene))
        object.__setattr__(scene, CACHE, found)
    return found


def _scene_dict(scene) -> dict:
    """The constants of ``scene`` as _core.DriveScene takes them.  The planes'
    geometry, the slip maps and the gravity vector are the C loop's own, from the
    parameters' plane table; here: each plane's contact laws, and the rest checks'
    constants -- on the plane opposite gravity (rest, uniform motion) and, with gravity,
    on an incline (rolling down it)."""
    params = scene._parameters   # (read only; DriveScene keeps a copy)
    observer = _core.flag("observer", 0) if scene.observer_mass != 0 else 0
    resting_plane = resting.resting_plane_index(scene)
    checks = scene.gravity_magnitude > 0   # a plane opposite gravity, or an incline
    total_mass = resting.total_mass(scene)
    radius, gravity = float(scene.radius), scene.gravity_magnitude
    modes_on = compliantmodes.uses_modes(scene)
    rho_eq = resting.equilibrium_penetration(scene) if checks else 1.0
    orbits = orbit.applies(scene)
    return dict(
        **rolling_constants(scene),
        observer_bits=observer,
        contact_bits=[modes.contact_flags(scene, k) for k in range(len(scene.planes))],
        exact=int(stickslip.uses_exact_coulomb(scene)), compliant_modes=int(modes_on),
        starts_armed=int(compliantmodes.starts_armed(scene)),
        arm_force_depth=compliantmodes.arm_force_depth(scene),
        radius=radius, weight=total_mass * gravity,
        hertz_k=scene.hertz_stiffness, total_mass=total_mass,
        restick_factor=max(1.0, scene.friction_coefficient
                           / max(scene.tangential_stiffness_ratio, 1e-300)),
        damping_positive=int(params[compliantmodes._TANGENTIAL_DAMPING] > 0),
        contact_time_base=compliantmodes.contact_time_base(scene),
        resting_plane=-1 if resting_plane is None else resting_plane,
        rest_period=(resting.REST_PERIODS * resting.oscillation_period(scene)
                     if checks else math.inf),
        rho_eq=rho_eq, z_eq=radius - rho_eq if checks else 0.0,
        rest_weight=total_mass * gravity if checks else 0.0,
        observer_weight=scene.observer_mass * gravity if checks else 0.0,
        rolls_level=resting.steady_level(scene) if checks else 0.0,
        half_mass=0.5 * total_mass if checks else 0.0,
        observer_massive=int(scene.observer_mass > 0),
        rolls_allowed=int(flight_scene_allows(params)), orbit_applies=int(orbits),
        orbit_axis=orbit.body_axis(scene).tolist() if orbits else [0.0, 0.0, 1.0],
        rest_factor=resting.REST_FACTOR)


def rolling_constants(scene) -> dict:
    """The rolling part's constants of the C loop (_driver.h): each part's model (0 off, 1
    exact, 2 sds); both 0 without rolling resistance (the run has no rolling states)."""
    model = ROLLING_MODEL_CODES[scene.rolling_model]
    rolling = model if scene.rolling_resistance > 0 else 0
    twisting = model if scene.twisting_resistance > 0 else 0
    return dict(rolling=rolling, twisting=twisting)


#: Scene.rolling_model -> the C loop's code (_driver.h ballc_drive_config.rolling)
ROLLING_MODEL_CODES = {"exact": 1, "sds": 2}


def run_constants(scene, options, rest) -> dict:
    """A run's constants of the C loop (``options``: validated; ``rest``: simulate's)."""
    atol = options.atol
    per_state = type(atol) is not float
    mine = scene_constants(scene).python   # the scene's Python side, and its rest checks'
    flies = mine.get("flies")
    if flies is None:
        flies = mine["flies"] = flight_scene_allows(scene._parameters)
    rest_constants = mine.get((options.rtol, atol)) if not per_state else None
    if rest_constants is None:
        rest_constants = _rest_constants(scene, options.rtol, atol)
        if not per_state:
            if len(mine) > 64:   # a scene run at many tolerances: keep the cache small
                mine.clear()
            mine[options.rtol, atol] = rest_constants
    users = (user_constants(options.events, len(scene.state_names)) if options.events
             else None)
    return dict(
        rtol=options.rtol, atol=float(np.max(atol)) if per_state else atol,
        atol_states=np.ascontiguousarray(atol, dtype=float) if per_state else None,
        scipy=options.method in SCIPY_METHODS, scipy_atol=atol, method=options.method,
        t_end=options.t_end, max_step=options.max_step, first_step=options.first_step,
        max_nfev=options.max_nfev, t_eval=options.t_eval,
        dense_output=int(options.dense_output),
        exact_flight=int(options.exact_flight and flies),
        checks_rest=int(bool(rest) and options.t_eval is None and not options.events),
        rest_threshold=rest_constants[0], rolls_dv=rest_constants[1],
        users=users, poll_interval=POLL_INTERVAL)


def _rest_constants(scene, rtol, atol) -> tuple:
    """(the rest checks' energy threshold (J), the uniform check's speed tolerance (m/s))
    at these tolerances; (inf, 0) without gravity."""
    if not scene.gravity_magnitude > 0:
        return math.inf, 0.0
    return (resting.energy_threshold(scene, rtol, atol),
            resting.speed_tolerance(scene, rtol, atol))


def user_constants(events_given, width=_core.N_STATES) -> dict:
    """The user's events as the C loop takes them: a dict of arrays (``width``: the
    run's states, ``scene.state_names``).  A LinearEvent (a
    subclass too) is evaluated in C from its coefficients and offset, and its ``rearm``,
    if any, called back; one whose class overrides ``__call__`` (then its own function),
    and any other callable, is called back (CheckedEvent)."""
    n = len(events_given)
    coef, offset = np.zeros((n, width)), np.zeros(n)
    scale, index = np.zeros(n), np.full(n, -1, dtype=np.intc)
    linear, direction = np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc)
    rearm, count = np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc)
    callables, rearms, flies = [], [], True
    for k, event in enumerate(events_given):   # (options.check_events checked them)
        sign = float(getattr(event, "direction", 0))
        direction[k] = (sign > 0) - (sign < 0)
        count[k] = _core.terminal_count(getattr(event, "terminal", False))
        if events.is_linear(event):
            linear[k], coef[k], offset[k] = 1, event.coefficients, float(event.offset)
            if event._index is not None:
                index[k], scale[k] = event._index, event._scale
            flies = flies and polynomial_in_flight(event)
            callables.append(None)
            rearms.append(event.rearm)
            rearm[k] = event.rearm is not None
        else:
            flies = False
            callables.append(CheckedEvent(event, k, 0, getattr(event, "direction", 0)))
            rearms.append(None)
    return dict(user_coef=coef, user_offset=offset, user_scale=scale, user_index=index,
                user_linear=linear, user_direction=direction, user_count=count,
                user_events=callables, user_rearm=rearm, user_rearms=rearms,
                user_flight=int(flies))
