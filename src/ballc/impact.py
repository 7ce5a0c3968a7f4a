"""One impact from a given incident state, tables of impacts, and fits to measured bounces.

``impact(scene, velocity, angular_velocity, plane)`` integrates a single contact of the
scene's ball with one plane, starting just clear of it, with :func:`ballc.simulate`
(the same equations, integrator and contact events as a full run), and returns the
rebound: velocities and spin after, duration, deepest penetration, and the normal and
tangential coefficients of restitution

* e_n = -v_n' / v_n   (v_n = v . n, n the plane's normal towards the ball);
* e_t = -u' . u / |u|^2, u = v_t + omega x (-r n) the tangential velocity of the
  contact point (the "contact-point" tangential restitution of Maw, Barber & Fawcett;
  +1: the contact point's slip is reversed, 0: it ends rolling, NaN when u = 0).

``impact_table`` runs many impacts (incident angle from the normal, speed, spin) into a
pandas table; ``fit_impacts`` fits named Scene fields (mu, the tangential stiffness
ratio, c_tau, ...) to measured rebounds by nonlinear least squares.

Conventions.  Gravity: the scene's gravity acts during the impact (set
``scene.replace(gravity=0)`` for the DEM benchmarks' gravity-free impacts); the ball
starts ``gap`` radii clear of the plane with the velocity that ballistic flight through
that gap turns into ``velocity`` at first touch, and the velocity reported "before" is
the state at the contact-start event.  Orientation: the scene's ``angles`` (it matters
only through the observer mass and an anisotropic inertia).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import compliantmodes
from ._format import plain
from .result import Result
from .scene import Scene, SceneError
from .simulate import simulate

PLANES = ("floor", "ceiling")
#: Incident and rebound columns of impact tables and of ``fit_impacts``' data.
INCIDENT_COLUMNS = ("vx", "vy", "vz", "wx", "wy", "wz")
REBOUND_COLUMNS = tuple(f"{c}_after" for c in INCIDENT_COLUMNS)


@dataclass(frozen=True)
class Impact:
    """The rebound of one impact (SI units, inertial components)."""

    plane: str
    velocity_before: np.ndarray          # m/s, at the contact-start event
    angular_velocity_before: np.ndarray  # rad/s
    velocity_after: np.ndarray           # m/s, at the contact-end event
    angular_velocity_after: np.ndarray   # rad/s
    duration: float                      # s
    max_penetration: float               # m
    normal_restitution: float            # e_n = -v_n'/v_n
    tangential_restitution: float        # e_t = -u'.u/|u|^2 (contact point), NaN if u = 0
    contact_velocity_before: np.ndarray  # u, tangential contact-point velocity (m/s)
    contact_velocity_after: np.ndarray   # u'
    result: Result                       # the simulation (one contact)

    @property
    def e_n(self) -> float:
        return self.normal_restitution

    @property
    def e_t(self) -> float:
        return self.tangential_restitution

    def as_dict(self) -> dict:
        row = {}
        for name, before, after in (("v", self.velocity_before, self.velocity_after),
                                    ("w", self.angular_velocity_before,
                                     self.angular_velocity_after)):
            for axis, b, a in zip("xyz", before, after):
                row[f"{name}{axis}"] = float(b)
                row[f"{name}{axis}_after"] = float(a)
        row.update(e_n=self.normal_restitution, e_t=self.tangential_restitution,
                   duration=self.duration, max_penetration=self.max_penetration,
                   status=int(self.result.status))
        return row


def _normal(plane):
    return np.array([0.0, 0.0, 1.0 if plane == "floor" else -1.0])


def contact_point_velocity(velocity, angular_velocity, radius, plane="floor"):
    """Tangential velocity u = v_t + omega x (-r n) of the contact point (m/s)."""
    n = _normal(plane)
    u = np.asarray(velocity, float) + np.cross(np.asarray(angular_velocity, float),
                                               -radius * n)
    return u - (u @ n) * n


def _vector(name, value):
    try:
        if isinstance(value, (str, bytes)):
            raise TypeError
        v = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise SceneError(f"{name} = {plain(value)} is not allowed: must be 3 numbers") \
            from None
    if v.shape != (3,):
        raise SceneError(f"{name} = {plain(value)} is not allowed: must be 3 numbers")
    if not np.all(np.isfinite(v)):
        raise SceneError(f"{name} = {plain(value)} is not allowed: every component must be "
                         "finite")
    return v


def hertz_contact_time(scene: Scene, speed: float) -> float:
    """Duration (s) of an elastic Hertz impact at normal ``speed`` (m/s):
    t_c = 3.2145 (m / k0)^(2/5) v^(-1/5), k0 = scene.hertz_stiffness
    (:func:`ballc.compliantmodes.contact_time`)."""
    return compliantmodes.contact_time(scene, speed)


def _default_atol(scene, speed):
    # Overlaps are small: the absolute tolerance must resolve the Hertz penetration, not
    # the radius (1e-6 of it), but not much below simulate's 1e-10 either: much tighter
    # (1e-15 m) stalls the compliant law's stick/slip at the first touch.
    m = scene.mass + scene.observer_mass
    depth = (1.25 * m * speed ** 2 / scene.hertz_stiffness) ** 0.4
    return min(1e-10, 1e-6 * depth, 1e-6 * 0.5 * m * speed ** 2)


def impact(scene: Scene, velocity, angular_velocity=(0.0, 0.0, 0.0), plane: str = "floor",
           *, gap: float = 1e-6, rtol: float = 1e-10, atol: float | None = None,
           method: str = "radau5", max_nfev: int | None = 2_000_000) -> Impact:
    """One impact of ``scene``'s ball on ``plane`` from the given incident state.

    Parameters
    ----------
    scene : Scene
        Material, contact model, mass, radius, gravity (kept; see the module docstring),
        orientation.  Its position, velocity and angular velocity are replaced.
    velocity : 3 floats
        Centre velocity at first touch (m/s); must approach ``plane`` (vz < 0 for the
        floor, > 0 for the ceiling).
    angular_velocity : 3 floats
        Angular velocity (rad/s, inertial components).
    plane : "floor" or "ceiling"
    gap : float
        Start this many radii clear of the plane (default 1e-6), in (0, 0.5].
    rtol, atol : float
        simulate's tolerances; atol default: the smallest of 1e-10 and 1e-6 times the
        Hertz penetration and m v^2/2 (so that tiny balls keep their accuracy).
    method : str
        simulate's integrator.
    max_nfev : int or None
        simulate's call budget (default 2e6, a few seconds: one impact of a
        well-posed scene takes ~1e4).  When it is exhausted, RuntimeError.

    Returns
    -------
    Impact
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a ballc.Scene, got {type(scene).__name__}")
    if plane not in PLANES:
        raise SceneError(f"plane = {plane!r} is not allowed: must be 'floor' or 'ceiling'")
    if scene.ceiling_height is None or isinstance(scene.gravity, tuple):
        raise SceneError("scene is not allowed: ballc.impact simulates one impact on the "
                         "seed's floor or ceiling, so its scene gives ceiling_height (not "
                         "planes) and gravity as a number (along -z)")
    v = _vector("velocity", velocity)
    w = _vector("angular_velocity", angular_velocity)
    try:
        gap_ok = not isinstance(gap, (str, bytes, bool)) and 0 < float(gap) <= 0.5
    except (TypeError, ValueError):
        gap_ok = False
    if not gap_ok:
        raise SceneError(f"gap = {plain(gap)} is not allowed: must be a number in (0, 0.5] "
                         "(radii)")
    n = _normal(plane)
    approach = -float(v @ n)
    if not approach > 0:
        raise SceneError(f"velocity = {plain(tuple(v))} is not allowed: the ball must move "
                         f"towards the {plane} (v_z {'< 0' if plane == 'floor' else '> 0'}), "
                         f"its normal velocity is {-approach:g} m/s")
    r, g = scene.radius, scene.gravity
    clearance = gap * r
    # vz at the start such that free flight through the gap arrives with vz:
    # floor: vz^2 = vz0^2 + 2 g h;  ceiling: vz^2 = vz0^2 - 2 g h.
    vz2 = v[2] ** 2 - 2 * g * clearance * (1 if plane == "floor" else -1)
    if vz2 <= 0:
        raise SceneError(f"velocity = {tuple(v)} is not allowed: the normal speed "
                         f"{approach:g} m/s is too small to cross the start gap "
                         f"({clearance:g} m) against gravity; use a smaller gap")
    v0 = v.copy()
    v0[2] = math.copysign(math.sqrt(vz2), v[2])
    z0 = r + clearance if plane == "floor" else scene.ceiling_height - r - clearance
    start = scene.replace(position=(0.0, 0.0, z0), velocity=tuple(v0),
                          angular_velocity=tuple(w))
    if atol is None:
        atol = _default_atol(scene, approach)
    t_gap = clearance / approach
    t_end = t_gap + 3.0 * hertz_contact_time(scene, approach)
    for _ in range(8):
        result = simulate(start, t_end, method=method, rtol=rtol, atol=atol,
                          progress=False, max_nfev=max_nfev)
        done = [c for c in result.contacts if c.plane == plane and np.isfinite(c.t_end)]
        if done or result.status != 0:
            break
        t_end *= 3.0
    if not done:
        raise RuntimeError(f"the {plane} contact did not end (status {result.status}: "
                           f"{result.message})")
    contact = done[0]
    vb, va = contact.velocity_before, contact.velocity_after
    wb, wa = contact.angular_velocity_before, contact.angular_velocity_after
    ub = contact_point_velocity(vb, wb, r, plane)
    ua = contact_point_velocity(va, wa, r, plane)
    slip2 = float(ub @ ub)
    e_t = -float(ua @ ub) / slip2 if slip2 > (1e-12 * approach) ** 2 else math.nan
    return Impact(plane=plane, velocity_before=vb.copy(), angular_velocity_before=wb.copy(),
                  velocity_after=va.copy(), angular_velocity_after=wa.copy(),
                  duration=float(contact.duration),
                  max_penetration=float(contact.max_penetration),
                  normal_restitution=contact.rebound_ratio,
                  tangential_restitution=e_t, contact_velocity_before=ub,
                  contact_velocity_after=ua, result=result)


def impact_table(scene: Scene, angles=(15.0, 30.0, 45.0, 60.0, 75.0), speed: float = 1.0,
                 spin=0.0, plane: str = "floor", **options):
    """Impacts at incident ``angles`` (degrees from the plane's normal: 0 = head-on,
    as in Chung & Ooi), all at ``speed`` (m/s), in the x-z plane (tangential velocity
    along +x), with ``spin`` (rad/s about y, one value or one per angle; on the floor
    the contact point moves at u_x = v_x - r w_y, so positive spin is backspin).

    Returns a pandas DataFrame, one row per impact: ``angle`` (deg), ``speed``,
    ``spin``, the incident ``vx..wz`` and rebound ``vx_after..wz_after``, ``e_n``,
    ``e_t``, ``duration``, ``max_penetration``, ``status``.  ``options`` go to
    :func:`impact`.  (A serial loop; ``ballc.sweep`` runs scenes on process pools.)
    """
    import pandas as pd
    angles = np.atleast_1d(np.asarray(angles, dtype=float))
    if angles.ndim != 1 or not np.all(np.isfinite(angles)) or np.any(angles < 0) or \
            np.any(angles >= 90):
        raise SceneError(f"angles = {plain(angles)} is not allowed: must be degrees in [0, 90)")
    try:
        speed = float(speed)
    except (TypeError, ValueError):
        raise SceneError(f"speed = {plain(speed)} is not allowed: must be a number > 0") from None
    if not (math.isfinite(speed) and speed > 0):
        raise SceneError(f"speed = {plain(speed)} is not allowed: must be finite and > 0")
    spins = np.broadcast_to(np.asarray(spin, dtype=float), angles.shape)
    if not np.all(np.isfinite(spins)):
        raise SceneError(f"spin = {plain(spin)} is not allowed: must be finite")
    down = -1.0 if plane == "floor" else 1.0
    rows = []
    for angle, s in zip(angles, spins):
        theta = math.radians(angle)
        hit = impact(scene, (speed * math.sin(theta), 0.0, down * speed * math.cos(theta)),
                     (0.0, s, 0.0), plane, **options)
        rows.append({"angle": angle, "speed": speed, "spin": s, **hit.as_dict()})
    return pd.DataFrame(rows)


@dataclass
class ImpactFit:
    """What ``fit_impacts`` found."""

    scene: Scene                 # base scene with the fitted fields
    free: tuple                  # the fitted Scene fields
    values: np.ndarray           # their fitted values
    standard_errors: np.ndarray  # sqrt(diag((J^T J)^-1) s^2), same order
    residuals: np.ndarray        # (simulated - measured) / scale, per measured value
    predicted: "object"          # DataFrame: the data's rows with the fitted model's rebounds
    cost: float                  # sum of squared residuals / 2
    success: bool
    message: str
    nfev: int

    def summary(self) -> str:
        lines = [f"fit of {len(self.residuals)} measured values, {len(self.free)} "
                 f"parameters: {self.message}"]
        for name, value, error in zip(self.free, self.values, self.standard_errors):
            lines.append(f"  {name:28s} = {value:.6g} +- {error:.2g}")
        rms = math.sqrt(2 * self.cost / max(len(self.residuals), 1))
        lines.append(f"  rms residual {rms:.3g} (velocities / incident speed, spins / "
                     "(incident speed / r))")
        return "\n".join(lines)


#: Bounds of the fields one would fit (others: (-inf, inf) unless positive by nature).
FIT_BOUNDS = {
    "friction_coefficient": (0.0, 20.0),
    "tangential_stiffness_ratio": (1e-3, 20.0),
    "c_tau": (1e-3, 1.0),
    "mixture": (0.0, 1.0),
}


def _reject_misspelt_columns(columns) -> None:
    """A column that is none of the incident or rebound columns but looks like one (ends
    in "_after", or is close to one's name: "vz_afer", "wx after") would be silently
    left out of the fit: a SceneError naming it.  Other columns (labels, notes, and a
    fit's own "<rebound>_fit" predictions) are allowed and ignored."""
    import difflib
    known = INCIDENT_COLUMNS + REBOUND_COLUMNS
    for column in columns:
        name = str(column)
        if name in known or name in {f"{c}_fit" for c in REBOUND_COLUMNS}:
            continue
        close = difflib.get_close_matches(name, known, n=1, cutoff=0.75)
        if close or name.endswith("_after"):
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SceneError(f"data column {name!r} is not allowed: it is none of the "
                             f"incident columns {', '.join(INCIDENT_COLUMNS)} nor the "
                             f"rebound columns {', '.join(REBOUND_COLUMNS)}, but looks like "
                             f"one{hint}, and would be left out of the fit")


def _data_frame(data):
    import pandas as pd
    frame = data if isinstance(data, pd.DataFrame) else pd.DataFrame(data)
    missing = [c for c in INCIDENT_COLUMNS if c not in frame.columns]
    if missing:
        raise SceneError(f"data is missing the incident column(s) {missing}: needs "
                         f"{list(INCIDENT_COLUMNS)}")
    _reject_misspelt_columns(frame.columns)
    measured = [c for c in REBOUND_COLUMNS if c in frame.columns]
    if not measured:
        raise SceneError(f"data has no rebound column: needs at least one of "
                         f"{list(REBOUND_COLUMNS)}")
    incident = frame[list(INCIDENT_COLUMNS)].to_numpy(dtype=float)
    if not np.all(np.isfinite(incident)):
        raise SceneError("data's incident columns vx..wz must be finite in every row")
    return frame, incident, measured


def fit_impacts(base_scene: Scene, data, free=("friction_coefficient",
                                               "tangential_stiffness_ratio", "c_tau"),
                plane: str = "floor", *, x0=None, bounds=None, diff_step: float = 1e-4,
                max_nfev: int = 60, verbose: int = 0, **options) -> ImpactFit:
    """Fit the Scene fields ``free`` to measured rebounds (scipy.optimize.least_squares).

    ``data``: a table (DataFrame or dict of columns), one row per impact, with the
    incident ``vx, vy, vz, wx, wy, wz`` (m/s, rad/s, at first touch) and any of the
    measured ``vx_after ... wz_after``; NaN (or a missing column) = not measured.
    Residuals are (simulated - measured) divided by the row's incident speed for
    velocities and by incident speed / radius for angular velocities, so that every
    column weighs alike.  Starting values: ``x0`` or the base scene's; ``bounds``:
    {field: (low, high)}, default ``FIT_BOUNDS``.  Standard errors come from the
    Jacobian at the solution, sqrt(diag((J^T J)^-1) s^2), s^2 = 2 cost / (N - p).
    ``options`` go to :func:`impact` (e.g. rtol).
    """
    import pandas as pd
    from scipy.optimize import least_squares
    if not isinstance(base_scene, Scene):
        raise TypeError(f"base_scene must be a ballc.Scene, got {type(base_scene).__name__}")
    if isinstance(free, str):
        free = (free,)
    free = tuple(free)
    fields = base_scene.to_dict()
    for name in free:
        if name not in fields or not isinstance(fields[name], (int, float)) or \
                isinstance(fields[name], bool):
            raise SceneError(f"free = {free!r} is not allowed: {name!r} is not a numeric "
                             "Scene field")
    if not free:
        raise SceneError("free = () is not allowed: name at least one Scene field")
    if plane not in PLANES:
        raise SceneError(f"plane = {plane!r} is not allowed: must be 'floor' or 'ceiling'")
    frame, incident, measured = _data_frame(data)
    target = frame[measured].to_numpy(dtype=float)
    mask = np.isfinite(target)
    speeds = np.linalg.norm(incident[:, :3], axis=1)
    scale = np.array([[s if c.startswith("v") else s / base_scene.radius for c in measured]
                      for s in speeds])
    n_values = int(mask.sum())
    if n_values < len(free):
        raise SceneError(f"data has {n_values} measured values: too few to fit {len(free)} "
                         "parameters")
    limits = {**FIT_BOUNDS, **(bounds or {})}
    low = np.array([limits.get(name, (-np.inf, np.inf))[0] for name in free])
    high = np.array([limits.get(name, (-np.inf, np.inf))[1] for name in free])
    start = np.array([float(fields[name]) for name in free] if x0 is None else x0, float)
    start = np.clip(start, low + 1e-12 * np.maximum(1, abs(low)), high - 1e-12 * np.maximum(
        1, abs(high)))
    index = [REBOUND_COLUMNS.index(c) for c in measured]

    def rebounds(values):
        scene = base_scene.replace(**dict(zip(free, map(float, values))))
        out = np.empty((len(incident), len(REBOUND_COLUMNS)))
        for i, row in enumerate(incident):
            try:
                hit = impact(scene, row[:3], row[3:], plane, **options)
            except SceneError as error:
                raise SceneError(f"data row {plain(frame.index[i])}: {error}") from None
            out[i] = np.concatenate([hit.velocity_after, hit.angular_velocity_after])
        return out

    def residual(values):
        simulated = rebounds(values)[:, index]
        return ((simulated - target) / scale)[mask]

    solution = least_squares(residual, start, bounds=(low, high), diff_step=diff_step,
                             x_scale="jac", max_nfev=max_nfev, verbose=verbose)
    jac = solution.jac
    dof = max(n_values - len(free), 1)
    s2 = 2 * solution.cost / dof
    try:
        covariance = np.linalg.inv(jac.T @ jac) * s2
        errors = np.sqrt(np.clip(np.diag(covariance), 0, None))
    except np.linalg.LinAlgError:
        errors = np.full(len(free), np.inf)
    fitted = base_scene.replace(**dict(zip(free, map(float, solution.x))))
    predicted = frame.copy()
    best = rebounds(solution.x)
    for j, column in enumerate(REBOUND_COLUMNS):
        predicted[f"{column}_fit"] = best[:, j]
    return ImpactFit(scene=fitted, free=free, values=solution.x.copy(),
                     standard_errors=errors, residuals=solution.fun.copy(),
                     predicted=predicted, cost=float(solution.cost),
                     success=bool(solution.success), message=solution.message,
                     nfev=int(solution.nfev))
