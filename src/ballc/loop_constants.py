"""The C loop's constants: those of a scene, worked out once per scene, and a run's.

The segment loop (``_driver.c``) takes the constants it needs as numbers: the flag bits
of each plane's modes, the planes' penetration and thresholds, the slip velocity's map,
the rest checks' and the orbit's constants.  :func:`scene_constants` computes those of a
scene once and keeps them on the (frozen) scene, converted to C (``_core.DriveScene``);
:func:`run_constants` adds a run's (its tolerances, t_end, output, user events).
Python validates and converts here; every decision is the C loop's.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, compliantmodes, events, layout, modes, orbit, resting, stickslip
from .flight import polynomial_in_flight, scene_allows as flight_scene_allows
from .options import SCIPY_METHODS
from .user_events import CheckedEvent

PLANES = layout.PLANES
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


def _flag(name):
    return [_core.FLAGS[f"{plane}_{name}"] for plane in PLANES]


#: The modes' flag bits per plane: the same for every scene
_BITS = dict(
    slip_bits=_flag("slip"), slip_fixed_bits=_flag("slip_fixed"), stick_bits=_flag("stick"),
    compliant_bits=_flag("compliant"), elastic_bits=_flag("compliant_elastic"),
    sliding_bits=_flag("compliant_sliding"),
    compliant_any=_core.FLAGS["floor_compliant"] | _core.FLAGS["ceiling_compliant"],
    compliant_sliding_any=(_core.FLAGS["floor_compliant_sliding"]
                           | _core.FLAGS["ceiling_compliant_sliding"]))


#: in contact with both planes, and each plane's flag bits
_BOTH = {plane: True for plane in PLANES}
_PLANE_BITS = {plane: sum(bit for name, bit in _core.FLAGS.items() if name.startswith(plane))
               for plane in PLANES}


def _scene_dict(scene) -> dict:
    """The constants of ``scene`` as _core.DriveScene takes them."""
    params = scene._parameters   # (read only; DriveScene keeps a copy)
    observer = _core.FLAGS["observer"] if scene.observer_mass != 0 else 0
    resting_plane = resting.resting_plane(scene) is not None
    total_mass = resting.total_mass(scene)
    radius, gravity = float(scene.radius), float(scene.gravity)
    rho = [events.penetration(plane, scene) for plane in PLANES]
    modes_on = compliantmodes.uses_modes(scene)
    rho_eq = resting.equilibrium_penetration(scene) if resting_plane else 1.0
    orbits = orbit.applies(scene)
    laws = modes.flags(scene, _BOTH) ^ observer   # the contacts' laws, both planes
    return dict(
        _BITS, observer_bits=observer,
        contact_bits=[laws & _PLANE_BITS[plane] for plane in PLANES],
        exact=int(stickslip.uses_exact_coulomb(scene)), compliant_modes=int(modes_on),
        radius=radius, gravity=gravity, weight=total_mass * abs(gravity),
        hertz_k=scene.hertz_stiffness, total_mass=total_mass,
        rho_scale=[e._scale for e in rho], rho_offset=[e.offset for e in rho],
        through_offset=[e.offset - radius for e in rho],
        threshold_base=[events.threshold_base(scene, plane) for plane in PLANES],
        slip_map=np.array([_core.slip_map(params, k) for k in range(len(PLANES))]),
        arm_depth=([compliantmodes.arm_penetration(scene, plane) for plane in PLANES]
                   if compliantmodes.starts_armed(scene) else [0.0, 0.0]),
        ulp8=[8 * math.ulp(compliantmodes.plane_position(scene, plane)) for plane in PLANES],
        restick_factor=max(1.0, scene.friction_coefficient
                           / max(scene.tangential_stiffness_ratio, 1e-300)),
        damping_positive=int(params[compliantmodes._TANGENTIAL_DAMPING] > 0),
        contact_time_base=compliantmodes.contact_time_base(scene),
        resting_plane=PLANES.index("floor") if resting_plane else -1,
        rest_period=(resting.REST_PERIODS * resting.oscillation_period(scene)
                     if resting_plane else math.inf),
        rho_eq=rho_eq, z_eq=radius - rho_eq if resting_plane else 0.0,
        rest_weight=total_mass * gravity if resting_plane else 0.0,
        observer_weight=scene.observer_mass * gravity if resting_plane else 0.0,
        rolls_level=resting.steady_level(scene) if resting_plane else 0.0,
        half_mass=0.5 * total_mass if resting_plane else 0.0,
        observer_massive=int(scene.observer_mass > 0),
        rolls_allowed=int(flight_scene_allows(params)), orbit_applies=int(orbits),
        orbit_axis=orbit.body_axis(scene).tolist() if orbits else [0.0, 0.0, 1.0],
        rest_factor=resting.REST_FACTOR)


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
    users = user_constants(options.events) if options.events else None
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
    at these tolerances; (inf, 0) without a resting plane (g = 0)."""
    if resting.resting_plane(scene) is None:
        return math.inf, 0.0
    return (resting.energy_threshold(scene, rtol, atol),
            resting.speed_tolerance(scene, rtol, atol))


def user_constants(events_given) -> dict:
    """The user's events as the C loop takes them: a dict of arrays.  A LinearEvent (a
    subclass too) is evaluated in C from its coefficients and offset, and its ``rearm``,
    if any, called back; one whose class overrides ``__call__`` (then its own function),
    and any other callable, is called back (CheckedEvent)."""
    n = len(events_given)
    coef, offset = np.zeros((n, _core.N_STATES)), np.zeros(n)
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
