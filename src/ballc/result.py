"""Result of a simulation: solve_ivp-shaped arrays plus named views, energies, contacts."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, fields

import numpy as np

from . import _core, automaton, layout
from .orientation import angles_123_from_quaternion

_STATE = layout.INDEX
#: A contact is under gravity when gravity's impulse over it, g t_c, is more than this
#: share of its exit normal speed abs(v_n after) (or the ball did not leave): its
#: rebound ratio is then off the law's e (by about a third of g t_c / abs(v_n after),
#: measured on the soft and hard default balls), so the contact table says so.
GRAVITY_IMPULSE_SHARE = 0.1
#: The unset values of a Contact's vectors (each contact gets its own copy).
_NAN_3, _NAN_2 = np.full(3, np.nan), np.full(2, np.nan)


@dataclass
class Contact:
    """One contact of the ball with a plane (SI units).

    ``t_end`` and the ``*_after`` values are NaN when the simulation ended during
    the contact.  Velocities are of the ball's centre; angular velocities are in
    inertial components.

    Attributes
    ----------
    plane : str
        The plane's name (the scene's ``plane_names``: "floor" or "ceiling" for the
        seed's).
    t_start, t_end : float
        Start and end of the contact (s).
    velocity_before, velocity_after : ndarray, shape (3,)
        Centre velocity at ``t_start`` and at ``t_end`` (m/s).
    angular_velocity_before, angular_velocity_after : ndarray, shape (3,)
        Angular velocity at ``t_start`` and at ``t_end`` (rad/s).
    penetration_rate_at_impact : float
        The latched penetration rate rhodot^- at ``t_start`` (m/s).
    digin_direction : ndarray, shape (3,)
        Unit vector along the contact point's velocity at ``t_start`` (1).
    max_penetration : float
        Largest penetration depth (m).
    contact_point : ndarray, shape (2,)
        Centre (x, y) when the penetration was largest: the contact point (m).
    contact_point_z : float
        Centre z then (m): with (x, y), the centre, whose foot on the plane is the
        contact point (``ballc.plot.contact_points``).
    peak_normal_force : float
        Largest normal force over the stored samples (N).
    energy_lost_normal, energy_lost_tangential : float
        Work dissipated by the normal and by the tangential force (J).
    time_sticking, time_slipping : float
        Time with the tangential force below, and at, the Coulomb cap mu F_n (s).
    transitions : list of (float, str)
        Exact Coulomb friction: the start (s) of each "slip" or "stick" phase.
    normal : ndarray, shape (3,)
        The plane's unit normal, towards the ball (1).

    The properties ``duration`` (s) and ``rebound_ratio`` (-v_n after / v_n before, 1:
    the scene's restitution e only without gravity) are derived from these.
    """

    plane: str                       # the plane's name ("floor", "ceiling", ...)
    t_start: float                   # s
    velocity_before: np.ndarray      # m/s, at t_start
    angular_velocity_before: np.ndarray  # rad/s, at t_start
    penetration_rate_at_impact: float    # m/s, the latched rhodot^-
    digin_direction: np.ndarray      # unit contact-point velocity at t_start
    t_end: float = np.nan            # s
    velocity_after: np.ndarray = field(default_factory=_NAN_3.copy)
    angular_velocity_after: np.ndarray = field(default_factory=_NAN_3.copy)
    max_penetration: float = 0.0     # m
    #: centre (x, y) when the penetration was largest: the contact point (m)
    contact_point: np.ndarray = field(default_factory=_NAN_2.copy)
    #: centre z then (m; NaN in a file from before planes of any orientation)
    contact_point_z: float = np.nan
    peak_normal_force: float = np.nan      # N, largest F . n over the stored samples
    energy_lost_normal: float = np.nan     # J, dissipated by the normal force
    energy_lost_tangential: float = np.nan  # J, dissipated by the tangential force
    time_sticking: float = np.nan          # s, |F_t| below the Coulomb cap mu F_n
    time_slipping: float = np.nan          # s, |F_t| at the cap
    #: exact Coulomb friction: [(t, "slip" or "stick")], the start of each phase (s)
    transitions: list = field(default_factory=list)
    #: when the contact came to rest (ballc.resting), NaN if it did not (s)
    t_rest: float = np.nan
    #: when the contact's rolling was continued in closed form -- uniform
    #: (ballc.resting) or the wobble of an eccentric observer (ballc.orbit) -- NaN if
    #: it was not (s)
    t_rolling: float = np.nan
    #: likewise for a contact sliding with no force opposing the slip (mu = 0) (s)
    t_sliding: float = np.nan
    #: the plane's unit normal, towards the ball (a file from before planes of any
    #: orientation: NaN, the seed's by its name)
    normal: np.ndarray = field(default_factory=_NAN_3.copy)
    #: a run's contacts: computes peak_normal_force, time_sticking and time_slipping of
    #: every contact of the run on first access (ballc.outcome.summarize_contact_forces)
    _summary: object = field(default=None, init=False, repr=False, compare=False)

    def __getattr__(self, name):
        summary = self.__dict__.get("_summary")
        if summary is not None and name in _SUMMARY_FIELDS:
            summary()
            return self.__dict__[name]
        raise AttributeError(f"'Contact' object has no attribute {name!r}")

    def __getstate__(self):
        """Pickled (copied) with its force summaries computed."""
        if self.__dict__.get("_summary") is not None:
            self._summary()
        return dict(self.__dict__)

    @property
    def unit_normal(self) -> np.ndarray:
        """The plane's unit normal towards the ball: ``normal``, or the seed's floor's
        (+z) or ceiling's (-z) by the plane's name when a file did not store it."""
        if self.normal[0] == self.normal[0]:   # stored (not NaN)
            return self.normal
        return np.array([0.0, 0.0, -1.0 if self.plane == "ceiling" else 1.0])

    @property
    def duration(self) -> float:
        """t_end - t_start (s)."""
        return self.t_end - self.t_start

    @property
    def rebound_ratio(self) -> float:
        """The measured normal rebound ratio -v_n after / v_n before (1), v_n = v . n the
        centre's velocity along the plane's normal n towards the ball (+z floor, -z
        ceiling) at ``t_start`` and ``t_end``.  NaN when the contact did not end or did
        not start approaching the plane.  Without gravity it is the normal law's
        restitution e (``Scene.restitution``); under gravity it is not
        (``Result.gravity_affected_contacts``, docs/limits.md)."""
        before = self.normal_velocity(self.velocity_before)
        after = self.normal_velocity(self.velocity_after)
        return -after / before if before < 0 else math.nan

    def normal_velocity(self, velocity) -> float:
        """v . n (m/s): ``velocity``'s component along the plane's normal (towards the
        ball)."""
        n = self.unit_normal
        if n[0] == 0 and n[1] == 0:   # horizontal: the z component, as it is
            return float(velocity[2]) * float(n[2])
        return float(np.asarray(velocity, dtype=float) @ n)

    def as_dict(self) -> dict:
        """The contact as one flat row (the contact table's columns, units in
        ``ballc.result.CONTACT_UNITS``)."""
        row = {"plane": self.plane, "t_start": self.t_start, "t_end": self.t_end,
               "duration": self.duration, "rebound_ratio": self.rebound_ratio,
               "max_penetration": self.max_penetration,
               "contact_point_x": float(self.contact_point[0]),
               "contact_point_y": float(self.contact_point[1]),
               "contact_point_z": float(self.contact_point_z),
               "peak_normal_force": self.peak_normal_force,
               "energy_lost_normal": self.energy_lost_normal,
               "energy_lost_tangential": self.energy_lost_tangential,
               "time_sticking": self.time_sticking, "time_slipping": self.time_slipping,
               "penetration_rate_at_impact": self.penetration_rate_at_impact,
               "t_rest": self.t_rest, "t_rolling": self.t_rolling,
               "t_sliding": self.t_sliding}
        for name in ("velocity_before", "velocity_after", "angular_velocity_before",
                     "angular_velocity_after"):
            for axis, value in zip("xyz", getattr(self, name)):
                row[f"{name}_{axis}"] = float(value)
        return row


#: A Contact's fields that a run computes on first access (Contact._summary).
_SUMMARY_FIELDS = ("peak_normal_force", "time_sticking", "time_slipping")
for _name in _SUMMARY_FIELDS:
    delattr(Contact, _name)   # the dataclass's default: read through __getattr__ instead


#: Unit of each column of :meth:`Contact.as_dict` (the contact CSV's header says them).
CONTACT_UNITS = {
    "plane": "", "t_start": "s", "t_end": "s", "duration": "s", "rebound_ratio": "1",
    "max_penetration": "m",
    "contact_point_x": "m", "contact_point_y": "m", "contact_point_z": "m",
    "peak_normal_force": "N",
    "energy_lost_normal": "J", "energy_lost_tangential": "J", "time_sticking": "s",
    "time_slipping": "s", "penetration_rate_at_impact": "m/s", "t_rest": "s",
    "t_rolling": "s", "t_sliding": "s",
    **{f"{name}_{axis}": unit for name, unit in (
        ("velocity_before", "m/s"), ("velocity_after", "m/s"),
        ("angular_velocity_before", "rad/s"), ("angular_velocity_after", "rad/s"))
       for axis in "xyz"},
}


def _with_unit(name: str) -> str:
    unit = CONTACT_UNITS.get(name, "")
    return f"{name} [{unit}]" if unit else name


@dataclass
class Result:
    """What :func:`ballc.simulate` returns, shaped like scipy's ``OdeResult``.

    ``y`` has one row per state (``state_names``) and one column per time in ``t``.
    ``status``: 0 reached t_end, 1 stopped by a terminal condition (see ``message``),
    -1 the integrator failed; in every case the arrays hold what was computed.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Sample times (s): every solver step and every contact event, or ``t_eval``.
    y : ndarray, shape (len(state_names), n)
        States at ``t``, SI units: quaternion (1), centre position (m), angular
        velocity (rad/s, inertial), centre velocity (m/s), dissipated work (J),
        tangential deflections (m).
    scene : Scene
        The simulated scene.
    status : int
        0: ``t_end`` reached; 1: a terminal condition (the ball passed through a
        plane); -1: the integrator failed.
    message : str
        What happened, in words.
    nfev, njev, nlu : int
        Right-hand-side and Jacobian evaluations, LU decompositions.
    contacts : list of Contact
        One per contact, in time order.
    state_names : tuple of str
        Name of each row of ``y`` (``ballc.STATE_NAMES``).
    flags : ndarray, shape (n,)
        Right-hand-side flags of the segment that computed each sample (int).
    latch : ndarray, shape (N_LATCH, n)
        The latched contact values of that segment (SI units).
    segments : ndarray or None
        The segment log: one row per smooth segment the run integrated, in order (see
        :data:`SEGMENT_FIELDS`); None for a run read from a file.

    A run's Result builds what it is asked for: the arrays ``t`` and ``y`` and the
    scalars are there at once; the contacts (and their force summaries), ``flags``,
    ``latch``, the user events' hits, ``sol``, the segment log and the ``message``
    (with its energy-balance check) are built from the C loop's output on first access,
    each once -- the same values whenever they are read.
    """

    t: np.ndarray
    y: np.ndarray
    scene: object
    status: int
    message: str
    nfev: int
    njev: int
    nlu: int
    contacts: list
    state_names: tuple = _core.STATE_NAMES
    _energy: dict | None = field(default=None, repr=False)
    #: (n,) int: right-hand-side flags of the segment that computed each sample, and
    #: (N_LATCH, n): its latched contact values (see ``ballc._core.FLAGS``/``LATCH_NAMES``).
    flags: np.ndarray | None = field(default=None, repr=False)
    latch: np.ndarray | None = field(default=None, repr=False)
    #: solve_ivp's: per user event (simulate's ``events``), its times (s) and states
    t_events: list | None = field(default=None, repr=False)
    y_events: list | None = field(default=None, repr=False)
    #: with ``dense_output=True``: sol(t), the continuous solution over [0, t[-1]]
    #: (a ballc.dense.PiecewiseSolution), else None
    sol: object = field(default=None, repr=False)
    #: with ``method="auto"``: [(t, method)], each switch of the integrator (s, and
    #: "radau5" or "dop853": the method switched to), in time order; else None
    method_switches: list | None = field(default=None, repr=False)
    #: the C loop's segment log, the bytes it wrote (ballc._core.SEGMENT_RECORD each);
    #: read it as ``segments``
    _segment_log: bytes | None = field(default=None, repr=False)
    #: what a run builds on first access (ballc.loop_result): attribute name -> a
    #: function of the result
    _pending: dict | None = field(default=None, init=False, repr=False, compare=False)

    def __getattr__(self, name):
        pending = self.__dict__.get("_pending")
        if pending and name in pending:
            value = self.__dict__[name] = pending.pop(name)(self)
            return value
        raise AttributeError(f"'Result' object has no attribute {name!r}")

    def __getstate__(self):
        """Pickled (copied) with everything built."""
        for name in list(self.__dict__.get("_pending") or ()):
            getattr(self, name)
        return dict(self.__dict__, _pending=None)

    @property
    def segments(self) -> np.ndarray | None:
        """The segment log (a read-only numpy structured array, one row per segment,
        fields and units in :data:`SEGMENT_FIELDS`), or None for a run read from a
        file.  Built on first access."""
        found = self.__dict__.get("_segments")
        if found is None and self._segment_log is not None:
            found = self.__dict__["_segments"] = segment_table(self._segment_log,
                                                               self.scene.plane_names)
        return found

    @property
    def success(self) -> bool:
        """True only when t_end was reached (status 0)."""
        return self.status == 0

    # scipy's OdeResult is a dict: result["t"] as well as result.t
    def __getitem__(self, key):
        if key in ODE_RESULT_KEYS:
            return getattr(self, key)
        raise KeyError(f"{key!r}: a Result's items are those of scipy's OdeResult "
                       f"({', '.join(ODE_RESULT_KEYS)}); the rest are attributes "
                       f"(result.{key})")

    def __contains__(self, key) -> bool:
        return key in ODE_RESULT_KEYS

    def keys(self) -> tuple:
        """The keys of scipy's OdeResult, which ``result[key]`` reads (``dict(result)``)."""
        return ODE_RESULT_KEYS

    @property
    def quaternion(self) -> np.ndarray:
        """(4, n) unit quaternion (qw, qx, qy, qz), ball frame -> inertial."""
        q = self.y[layout.QUATERNION]
        return q / np.linalg.norm(q, axis=0)

    @property
    def angles(self) -> np.ndarray:
        """(3, n) the seed's body-fixed 123 angles q1, q2, q3 (rad), derived."""
        return angles_123_from_quaternion(self.quaternion.T).T

    @property
    def position(self) -> np.ndarray:
        """(3, n) centre position (m)."""
        return self.y[layout.POSITION]

    @property
    def angular_velocity(self) -> np.ndarray:
        """(3, n) angular velocity, inertial components (rad/s)."""
        return self.y[layout.ANGULAR_VELOCITY]

    @property
    def velocity(self) -> np.ndarray:
        """(3, n) centre velocity (m/s)."""
        return self.y[layout.VELOCITY]

    @property
    def observer_position(self) -> np.ndarray:
        """(3, n) position of the observer particle (m)."""
        return _core.observer_positions(np.ascontiguousarray(self.y.T),
                                        self.scene.parameter_vector()).T

    @property
    def energy(self) -> dict:
        """name -> (n,) array (J).

        ``kinetic``, ``potential`` (gravity), ``spring`` (Hertz, 2/5 k0 rho^(5/2), every
        plane's), ``tangential_spring`` (the compliant law's, ``1/2 k_t |s|^2``; 0 for the
        others), ``rolling_spring`` (the sds rolling and twisting springs', ``1/2 k_r
        |xi_r|^2 + 1/2 k_w xi_w^2``; 0 without them) and their sum ``total`` (the seed's
        total energy, plus the tangential and rolling springs'); ``dissipated_normal``,
        ``dissipated_tangential`` and ``dissipated_rolling`` (the rolling and twisting
        torques'; 0 without rolling resistance): work dissipated by the contact forces
        since t = 0 (integrated with the motion; negative where a model injects energy,
        as dig-in does), ``dissipated`` their sum, and ``balance`` = total + dissipated,
        which stays at the initial energy to integration tolerance for every model.
        """
        if self._energy is None:
            e = _core.energies(np.ascontiguousarray(self.y.T), self.scene.parameter_vector())
            planes = (e.shape[1] - 2) // 3
            spring, tangential_spring = e[:, 2], e[:, 2 + planes]
            rolling_spring = e[:, 2 + 2 * planes]
            for k in range(1, planes):
                spring = spring + e[:, 2 + k]
                tangential_spring = tangential_spring + e[:, 2 + planes + k]
                rolling_spring = rolling_spring + e[:, 2 + 2 * planes + k]
            total = e[:, 0] + e[:, 1] + spring + tangential_spring
            normal = self.y[_STATE["dissipated_normal"]]
            tangential = self.y[_STATE["dissipated_tangential"]]
            dissipated = normal + tangential
            if "dissipated_rolling" in self.state_names:   # rolling resistance's states
                rolling = self.y[self.state_names.index("dissipated_rolling")]
                total = total + rolling_spring
                dissipated = dissipated + rolling
            else:   # without it: none (every sum as without its terms, bit for bit)
                rolling = np.zeros_like(normal)
            self._energy = {"kinetic": e[:, 0], "potential": e[:, 1], "spring": spring,
                            "tangential_spring": tangential_spring,
                            "rolling_spring": rolling_spring,
                            "total": total, "dissipated_normal": normal,
                            "dissipated_tangential": tangential,
                            "dissipated_rolling": rolling,
                            "dissipated": dissipated,
                            "balance": total + dissipated}
        return self._energy

    def contacts_dataframe(self):
        """The contact table as a pandas DataFrame, one row per contact (SI units: the
        unit of each column is ``ballc.result.CONTACT_UNITS[column]``)."""
        import pandas as pd
        return pd.DataFrame([c.as_dict() for c in self.contacts])

    def contacts_csv(self, path) -> None:
        """Write the contact table to a CSV file: one row per contact, numbered from 1 as
        in :meth:`contact_table`; the header names each column's unit, e.g.
        ``t_start [s]`` (a header only when there was no contact)."""
        import csv
        names = list(self.contacts[0].as_dict()) if self.contacts else list(CONTACT_UNITS)
        with open(path, "w", newline="", encoding="utf-8") as stream:
            writer = csv.writer(stream)
            writer.writerow(["contact"] + [_with_unit(name) for name in names])
            for i, contact in enumerate(self.contacts, 1):
                row = contact.as_dict()
                writer.writerow([i] + [row[name] for name in names])

    # --- the observer: what a sensor inside the ball records (see ballc.observer) ---

    @property
    def observer_acceleration(self) -> np.ndarray:
        """(3, n) inertial acceleration of the observer point (m/s^2)."""
        from .observer import observer_acceleration
        return observer_acceleration(self)

    @property
    def observer_specific_force(self) -> np.ndarray:
        """(3, n) specific force on the observer (acceleration - gravity), in g,
        inertial components; 1 g = 9.80665 m/s^2.  At rest on the floor: (0, 0, +1)·g/9.80665."""
        from .observer import specific_force
        return specific_force(self, frame="inertial")

    @property
    def observer_specific_force_ball(self) -> np.ndarray:
        """(3, n) the same specific force in ball-frame components (g): an accelerometer's reading."""
        from .observer import specific_force
        return specific_force(self, frame="ball")

    # --- thin entry points to plot.py / animate.py / io.py (imported lazily) ---

    def plot(self, **options):
        """Coordinates and velocities against time; returns (figure, axes). See ballc.plot."""
        from .plot import plot_coordinates
        return plot_coordinates(self, **options)

    def plot_energy(self, **options):
        """Energies against time; returns (figure, axes). See ballc.plot."""
        from .plot import plot_energy
        return plot_energy(self, **options)

    def plot_observer(self, **options):
        """The observer's specific force (g) against time; returns (figure, axes)."""
        from .plot import plot_observer
        return plot_observer(self, **options)

    def plot_side_view(self, **options):
        """Side view (x, z): the planes where they are, the path, the contact points;
        returns (figure, axes).  See ballc.plot."""
        from .plot import plot_side_view
        return plot_side_view(self, **options)

    def plot_contacts(self, **options):
        """Top view of the contact points coloured by time; returns (figure, axes)."""
        from .plot import plot_contacts_top_view
        return plot_contacts_top_view(self, **options)

    def animate(self, path=None, **options):
        """3D animation (matplotlib FuncAnimation), written to ``path`` (.gif/.mp4) if given."""
        from .animate import animate
        return animate(self, path, **options)

    def to_html(self, path, **options):
        """Write a self-contained HTML page with an interactive 3-D view of the run
        (meshcat; ``pip install 'ballc[html]'``); options as ballc.html_view.write_html."""
        from .html_view import write_html
        return write_html(self, path, **options)

    def save(self, path) -> None:
        """Write to ``path``: .npz (always) or .nc (netCDF, needs xarray). See ballc.io."""
        from .io import save
        save(self, path)

    def gravity_affected_contacts(self) -> list:
        """Indices (from 0) of the contacts whose rebound gravity changed much: gravity's
        impulse over the contact, g t_c, exceeds GRAVITY_IMPULSE_SHARE of the exit
        normal speed; or the ball did not leave -- it came to rest on the plane, or the
        run ended in a contact over which gravity's impulse already exceeds the impact
        speed (its weight holds it there).  Their ``rebound_ratio`` is not the scene's
        restitution e, which is the law's e of an isolated impact without gravity.  (g:
        gravity's component along the plane's normal.)"""
        gravity = self.scene.gravity_vector
        if not np.any(gravity):
            return []
        found = []
        for i, contact in enumerate(self.contacts):
            g = abs(contact.normal_velocity(gravity))
            if not g > 0:
                continue
            if contact.t_rest == contact.t_rest:
                found.append(i)
            elif contact.t_end == contact.t_end:
                exit_speed = abs(contact.normal_velocity(contact.velocity_after))
                if g * contact.duration > GRAVITY_IMPULSE_SHARE * exit_speed:
                    found.append(i)
            elif g * (float(self.t[-1]) - contact.t_start) > abs(
                    contact.normal_velocity(contact.velocity_before)):
                found.append(i)
        return found

    def contact_arrays(self) -> dict:
        """field -> array over the contacts ((k,) or (k, 3)): what files store, and the
        derived ``rebound_ratio`` (for readers of the file; load recomputes it)."""
        arrays = {"rebound_ratio": np.array([c.rebound_ratio for c in self.contacts],
                                            dtype=float)}
        for name in CONTACT_FIELDS:
            values = [getattr(c, name) for c in self.contacts]
            if name == "plane":
                arrays[name] = np.array(values, dtype=str)
            elif name == "transitions":   # variable length: one JSON text per contact
                arrays[name] = np.array([json.dumps(v) for v in values], dtype=str)
            elif values and np.ndim(values[0]) == 1:
                arrays[name] = np.array(values, dtype=float).reshape(len(values), -1)
            else:
                arrays[name] = np.array(values, dtype=float)
        return arrays

    def event_arrays(self) -> dict:
        """The user events' occurrences as files store them, all events in one run of
        rows (a netCDF file has no list of arrays of different lengths): "index" (m,)
        which event (int), "times" (m,) when (s), "states" (m, len(state_names)) the
        states there; :func:`load` splits them back into ``t_events`` and ``y_events``."""
        n = len(self.state_names)
        times = [np.asarray(t, dtype=float) for t in self.t_events or []]
        states = [np.asarray(y, dtype=float).reshape(-1, n) for y in self.y_events or []]
        index = [np.full(len(t), k, dtype=np.int32) for k, t in enumerate(times)]
        return {"index": np.concatenate(index or [np.zeros(0, np.int32)]),
                "times": np.concatenate(times or [np.zeros(0)]),
                "states": np.concatenate(states or [np.zeros((0, n))])}

    def contact_table(self) -> str:
        """The contacts as a fixed-width text table; a second header line gives the units
        (times in s, penetration in m, centre velocities in m/s, the normal rebound ratio
        1).  Lines under it name the contacts where gravity changed the rebound
        (``gravity_affected_contacts``), that came to rest, or were continued in closed
        form."""
        width = max([7] + [len(c.plane) for c in self.contacts])
        head = (f"{'#':>2} {'plane':{width}} {'t_start':>8} {'t_end':>8} {'max pen.':>9} "
                f"{'vx before':>10} {'vx after':>9} {'vy before':>10} {'vy after':>9} "
                f"{'vz before':>10} {'vz after':>9} {'rebound':>8}")
        units = (f"{'':>2} {'':{width}} {'[s]':>8} {'[s]':>8} {'[m]':>9} " +
                 " ".join(f"{'[m/s]':>{width}}" for width in (10, 9, 10, 9, 10, 9)) +
                 f" {'[1]':>8}")
        lines = [head, units, "-" * len(head)]
        for i, c in enumerate(self.contacts, 1):
            vb, va = c.velocity_before, c.velocity_after
            lines.append(f"{i:2d} {c.plane:{width}} {c.t_start:8.4f} {c.t_end:8.4f} "
                         f"{c.max_penetration:9.4f} {vb[0]:10.3f} {va[0]:9.3f} "
                         f"{vb[1]:10.3f} {va[1]:9.3f} {vb[2]:10.3f} {va[2]:9.3f} "
                         f"{c.rebound_ratio:8.4f}")
        if self.contacts:
            lines.append("rebound: the normal rebound ratio -v_n after / v_n before")
        affected = self.gravity_affected_contacts()
        if affected:
            which = ", ".join(str(i + 1) for i in affected)
            lines.append(
                f"contact{'s' if len(affected) > 1 else ''} {which}: gravity acted for much "
                f"of the contact (g t_c > {GRAVITY_IMPULSE_SHARE:g} |v_n after|, or the ball "
                f"did not leave), so the rebound ratio is not the scene's restitution "
                f"e = {self.scene.normal_restitution:.4g}: that is the law's e of an "
                "isolated impact without gravity (docs/limits.md)")
        lines += [f"contact {i}: at rest from t = {c.t_rest:.6g} s (ballc.resting)"
                  for i, c in enumerate(self.contacts, 1) if c.t_rest == c.t_rest]
        lines += [f"contact {i}: {what} from t = {when:.6g} s, in closed form"
                  for i, c in enumerate(self.contacts, 1)
                  for what, when in (("rolling", c.t_rolling), ("sliding freely", c.t_sliding))
                  if when == when]
        return "\n".join(lines)

    def __repr__(self):
        return (f"Result(status={self.status}, message={self.message!r}, "
                f"t=[{self.t[0]:g} .. {self.t[-1]:g}] ({self.t.size} points), "
                f"contacts={len(self.contacts)}, nfev={self.nfev}, njev={self.njev})")


#: The fields a run builds on first access (Result._pending): the dataclass's defaults
#: are read through __getattr__ instead.
for _name in ("flags", "latch", "t_events", "y_events", "sol", "_segment_log"):
    delattr(Result, _name)


#: What ``result[key]`` reads: the items of scipy's OdeResult (a dict).
ODE_RESULT_KEYS = ("t", "y", "sol", "t_events", "y_events", "nfev", "njev", "nlu",
                   "status", "message", "success")

#: Contact fields, in the order files store them.
CONTACT_FIELDS = [f.name for f in fields(Contact) if f.init]


#: The columns of ``Result.segments``: name -> (unit, meaning).  The modes are
#: ballc.automaton.MODES, the event kinds its TRANSITIONS' events; a plane's columns
#: (shape (planes,)) are the scene's planes in order (the seed's: floor, ceiling).
SEGMENT_FIELDS = {
    "t_start": ("s", "when the segment started"),
    "t_end": ("s", "when it ended (a failed one: the last time it reached)"),
    "method": ("", "the integrator it started with: radau5, dop853 (method auto: the one "
               "in use), or flight (exact free flight, ballc.flight)"),
    "method_end": ("", "the integrator of its last step (method auto may switch)"),
    "switches": ("", "method auto: its switches inside the segment"),
    "nfev": ("", "right-hand-side calls of the segment"),
    "njev": ("", "Jacobian evaluations of the segment"),
    "nlu": ("", "LU decompositions of the segment"),
    "nstep": ("", "accepted steps of the segment (0 for an exact flight)"),
    "nreject": ("", "rejected steps of the segment"),
    "end": ("", "why it ended: the event kind that ended it (enter, leave, through, "
            "approach, stop, clear, release, arm, yield, restick, capacity; user: a "
            "terminal user event), or t_end, step bound (a compliant contact's first "
            "steps end), failed (the integrator), or a scheduled rest check named by the "
            "last of its checks that ran, each running when the one before found "
            "nothing: rest check, uniform check, orbit check"),
    "plane": ("", "the plane of that event or check (its name), else ''"),
    "before": ("", "each plane's mode during the segment (the scene's planes in order)"),
    "after": ("", "each plane's mode once its end was handled (the scene's planes)"),
    "rearms": ("", "events re-armed inside the segment without ending it (a free slip's "
               "approach re-latched, the compliant capacity guard turned)"),
    "rearm_kind": ("", "the last of those: its event kind (approach, capacity), or ''"),
    "rearm_plane": ("", "... its plane, or ''"),
    "rearm_before": ("", "... that plane's mode before it, or ''"),
    "rearm_after": ("", "... and after it, or ''"),
    "rolling_before": ("", "each plane's rolling part's mode during the segment (floor, "
                       "ceiling; ballc.automaton.ROLLING_PART_MODES: none, rolling, "
                       "rolling_fixed, holding, spring, slider)"),
    "rolling_after": ("", "... once its end was handled"),
    "twisting_before": ("", "each plane's twisting part's mode during the segment (none, "
                        "twisting, holding, spring, slider)"),
    "twisting_after": ("", "... once its end was handled"),
}


def segment_table(raw: bytes, plane_names=layout.PLANES) -> np.ndarray:
    """The readable segment table (``Result.segments``) of the C loop's log ``raw``
    (records ballc._core.SEGMENT_RECORD, of codes), with names for its codes
    (_core.PLANE_MODES, SEGMENT_ENDS, SEGMENT_METHODS; the scene's ``plane_names``);
    read-only."""
    log = np.frombuffer(raw, dtype=_core.SEGMENT_RECORD)
    modes = np.array(_core.PLANE_MODES + ("",))        # code -1: ''
    planes = np.array(tuple(plane_names) + ("",))
    count = len(plane_names)
    width = max([7] + [len(name) for name in plane_names])
    methods = _core.SEGMENT_METHODS
    low = min(methods)
    method_names = np.array([methods.get(k, str(k)) for k in range(low, max(methods) + 1)])
    ends = np.array(_core.SEGMENT_ENDS + ("",))
    rolling = np.array(automaton.ROLLING_PART_MODES["rolling"])
    twisting = np.array(automaton.ROLLING_PART_MODES["twisting"])
    table = np.empty(log.size, dtype=[
        ("t_start", "f8"), ("t_end", "f8"), ("method", "U6"), ("method_end", "U6"),
        ("switches", "i4"), ("nfev", "i8"), ("njev", "i8"), ("nlu", "i8"), ("nstep", "i8"),
        ("nreject", "i8"), ("end", "U13"),
        ("plane", f"U{width}"), ("before", "U14", (count,)), ("after", "U14", (count,)),
        ("rearms", "i4"), ("rearm_kind", "U8"), ("rearm_plane", f"U{width}"),
        ("rearm_before", "U14"),
        ("rearm_after", "U14"), ("rolling_before", "U13", (count,)),
        ("rolling_after", "U13", (count,)), ("twisting_before", "U13", (count,)),
        ("twisting_after", "U13", (count,))])
    for name in ("t_start", "t_end", "switches", "nfev", "njev", "nlu", "nstep", "nreject",
                 "rearms"):
        table[name] = log[name]
    table["method"] = method_names[log["method"] - low]
    table["method_end"] = method_names[log["method_end"] - low]
    table["end"] = ends[log["end"]]
    user = log["end"] == _core.SEGMENT_ENDS.index("user")   # its plane is the event's index
    table["plane"] = planes[np.where(user, -1, log["plane"])]
    table["before"] = modes[log["before"][:, :count]]
    table["after"] = modes[log["after"][:, :count]]
    table["rearm_kind"] = ends[log["rearm_kind"]]
    table["rearm_plane"] = planes[log["rearm_plane"]]
    table["rearm_before"] = modes[log["rearm_before"]]
    table["rearm_after"] = modes[log["rearm_after"]]
    for part, names in (("rolling", rolling), ("twisting", twisting)):
        for when in ("before", "after"):
            table[f"{part}_{when}"] = names[log[f"{part}_{when}"][:, :count]]
    table.flags.writeable = False
    return table


def _contacts_from(arrays: dict) -> list:
    contacts = []
    for i in range(len(arrays["plane"])):
        values = {}
        for name in CONTACT_FIELDS:
            if name not in arrays:   # a file from before the field existed
                continue
            value = arrays[name][i]
            if name == "plane":
                values[name] = str(value)
            elif name == "transitions":
                values[name] = [(float(t), str(mode)) for t, mode in json.loads(str(value))]
            elif np.ndim(value) == 1:
                values[name] = np.array(value, dtype=float)
            else:
                values[name] = float(value)
        contacts.append(Contact(**values))
    return contacts


def load(path) -> Result:
    """Read a Result written by :meth:`Result.save`.

    Parameters
    ----------
    path : str or Path
        A ``.npz`` file, or ``.nc`` (netCDF, needs xarray); any other suffix raises
        ValueError.

    Returns
    -------
    Result
        The saved run: times (s), states (SI units), contacts and scene.
    """
    from .io import read
    from .scene import Scene
    header, arrays, contacts = read(path)
    flags, latch = arrays["flags"], arrays["latch"]
    return Result(t=arrays["t"], y=arrays["y"], scene=Scene.from_dict(json.loads(header["scene"])),
                  status=int(header["status"]), message=str(header["message"]),
                  nfev=int(header["nfev"]), njev=int(header["njev"]), nlu=int(header["nlu"]),
                  contacts=_contacts_from(contacts),
                  state_names=tuple(str(s) for s in arrays["state_names"]),
                  flags=flags if flags.size else None, latch=latch if latch.size else None,
                  method_switches=_switches_from(header.get("method_switches")),
                  **_events_from(header.get("event_count"), arrays))


def _events_from(count_text, arrays) -> dict:
    """A saved run's ``t_events`` and ``y_events`` (:meth:`Result.event_arrays` split
    per event: an event that never fired gets empty (0,) and (0, n) arrays), or None
    when the run was given no events or the file was written before they were saved."""
    count = json.loads(str(count_text)) if count_text is not None else None
    if count is None:
        return {"t_events": None, "y_events": None}
    index = np.asarray(arrays["event_index"])
    return {"t_events": [arrays["event_times"][index == k] for k in range(count)],
            "y_events": [arrays["event_states"][index == k] for k in range(count)]}


def _switches_from(text) -> list | None:
    """A saved run's ``method_switches`` ([(t, method)], or None: not method="auto", or
    a file written before they were saved)."""
    found = json.loads(str(text)) if text is not None else None
    return None if found is None else [(float(t), str(method)) for t, method in found]
