"""Planes at any orientation: a point and a normal each, the ball on the normal's side.

A :class:`Plane` is a point ``p`` on it and its normal ``n`` (any length > 0), pointing
into the space where the ball lives; the ball's penetration of it is
rho = r - n . (c - p) for the centre c, n made unit.  A :class:`ballc.Scene` takes one to
:data:`MAX_PLANES` of them (``Scene(planes=...)``); without, its ``ceiling_height`` is
the shorthand for the seed's two: the floor (0, 0, 0), (0, 0, 1) and the ceiling
(0, 0, H), (0, 0, -1) (:func:`seed_planes`).

Helpers build the usual arrangements -- :func:`tilted` (a plane turned about the y
axis), :func:`channel` (two parallel plates, tilted together), :func:`wedge` (two
plates meeting at a line), :func:`box` (six walls) -- and :func:`turned` turns a plane
by any rotation (a scene turned as a whole).

Sweeps (``ballc.sweep``) vary the planes with these parameters (angles in rad, about
the y axis, positive from +z towards +x, the right-hand rule about +y):

* ``planes.tilt``: every plane of the base scene turned together about the y axis
  through the origin (the plates' tilt, both together);
* ``planes.<i>.tilt``: the base scene's plane ``i`` (its index, from 0) turned about
  the y axis through its own point.

Both are measured from the base scene's planes; a sweep may give both (the plane's own
tilt first, then all of them together).
"""
from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass

import numpy as np

from . import _core
from ._errors import SceneError
from ._format import plain

#: The most planes a scene may have (the C core's arrays are sized by it).
MAX_PLANES = _core.MAX_PLANES
#: A plane's name: it names the plane's states (``<name>_deflection_x``), its latched
#: values, its contacts and its column in the segment log.
NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
#: How far (m) the planes must leave room for the ball beyond touching it, relative to
#: the radius, for "room for the ball" (two parallel plates 2 r apart leave none).
ROOM_MARGIN = 1e-9


class PlaneError(SceneError):
    """A plane has a value ballc cannot simulate (a ballc.SceneError)."""


def _vector(name, value) -> tuple:
    """``value`` as 3 finite floats, or PlaneError naming ``name``."""
    try:
        if isinstance(value, (str, bytes)) or any(
                isinstance(v, (str, bytes, bool, np.bool_)) for v in value):
            raise TypeError
        vector = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise PlaneError(f"{name} = {plain(value)} is not allowed: must be 3 numbers") from None
    if len(vector) != 3:
        raise PlaneError(f"{name} = {plain(value)} is not allowed: must be 3 numbers, got "
                         f"{len(vector)}")
    for i, v in enumerate(vector):
        if not math.isfinite(v):
            raise PlaneError(f"{name} = {plain(value)} is not allowed: every component must "
                             f"be finite ({name}[{i}] = {v})")
    return vector


@dataclass(frozen=True)
class Plane:
    """A plane through ``point`` (m) with the normal ``normal`` pointing into the space
    where the ball lives (any length > 0; 1 after normalising, as the C core takes it).

    Parameters
    ----------
    point : tuple of 3 float
        A point of the plane (m).  Default (0, 0, 0).
    normal : tuple of 3 float
        Its normal, towards the ball (1); finite and not zero.  Default (0, 0, 1): a
        floor.
    name : str, optional
        Its name (letters, digits and underscores, starting with a letter): it names the
        plane's contacts, states (``<name>_deflection_x``, ``_y``) and latched values.
        Default (None): the scene names it ``plane<i>`` by its index.
    """

    point: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)
    name: str | None = None

    def __post_init__(self):
        label = f"plane {self.name!r}" if isinstance(self.name, str) else "plane"
        object.__setattr__(self, "point", _vector(f"{label}: point", self.point))
        normal = _vector(f"{label}: normal", self.normal)
        size = math.sqrt(sum(v * v for v in normal))
        if not (size > 0 and math.isfinite(size)):
            raise PlaneError(f"{label}: normal = {plain(self.normal)} is not allowed: must "
                             "not be zero (it points into the space where the ball lives)")
        object.__setattr__(self, "normal", normal)
        if self.name is not None and not (isinstance(self.name, str)
                                          and NAME_PATTERN.match(self.name)):
            raise PlaneError(f"plane: name = {plain(self.name)} is not allowed: must be "
                             "letters, digits and underscores, starting with a letter")

    @functools.cached_property
    def unit_normal(self) -> np.ndarray:
        """The normal made unit (1; read-only)."""
        n = np.array(self.normal)
        n /= math.sqrt(float(n @ n))
        n.flags.writeable = False
        return n

    @property
    def offset(self) -> float:
        """n . p with n the unit normal (m): the plane is {x : n . x = offset}."""
        return float(self.unit_normal @ np.array(self.point))

    def height(self, centre) -> float:
        """The centre's height above the plane, n . (c - p) (m; negative behind it)."""
        return float(self.unit_normal @ (np.asarray(centre, dtype=float) - self.point))

    def named(self, name: str) -> "Plane":
        """The same plane with the name ``name``."""
        return Plane(self.point, self.normal, name)

    def to_dict(self) -> dict:
        """The plane's fields, as ``Scene.from_dict`` and the TOML ``[[planes]]`` take them."""
        values = {"point": self.point, "normal": self.normal}
        if self.name is not None:
            values["name"] = self.name
        return values

    @classmethod
    def of(cls, value, index: int) -> "Plane":
        """A plane from a Plane, a mapping of its fields (a TOML ``[[planes]]`` table) or
        (point, normal[, name]); PlaneError naming ``planes[index]`` otherwise."""
        if isinstance(value, Plane):
            return value
        try:
            if isinstance(value, dict):
                unknown = set(value) - {"point", "normal", "name"}
                if unknown:
                    raise PlaneError(f"planes[{index}]: unknown field "
                                     f"{sorted(unknown)[0]!r} is not allowed: a plane has "
                                     "point, normal and name")
                return cls(**value)
            if isinstance(value, (tuple, list)) and len(value) in (2, 3) and not all(
                    isinstance(v, (int, float)) for v in value):
                return cls(*value)
        except PlaneError as error:
            raise PlaneError(f"planes[{index}]: {error}") from None
        raise PlaneError(f"planes[{index}] = {plain(value)} is not allowed: must be a "
                         "ballc.Plane, a table of point, normal (and name), or (point, "
                         "normal[, name])")


@functools.lru_cache(maxsize=64)
def seed_planes(ceiling_height: float) -> tuple:
    """The seed's planes: the floor z = 0 (normal +z) and the ceiling z = H (normal -z).
    Planes are frozen: the scenes of one height share them (a sweep makes thousands)."""
    return (Plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), "floor"),
            Plane((0.0, 0.0, float(ceiling_height)), (0.0, 0.0, -1.0), "ceiling"))


def names_of(planes) -> tuple:
    """Each plane's name: its own, or ``plane<i>``."""
    return tuple(p.name if p.name is not None else f"plane{i}" for i, p in enumerate(planes))


def rotation_y(angle: float) -> np.ndarray:
    """The rotation by ``angle`` (rad) about the y axis (right-hand rule: +z towards +x)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _clean(vector) -> tuple:
    """A turned vector as floats, its components within 1e-15 of 0 set to 0 (a plane
    turned by a multiple of 90 degrees stays exactly axis-aligned)."""
    return tuple(0.0 if abs(v) < 1e-15 else float(v) for v in vector)


def turned(plane: Plane, rotation, about=(0.0, 0.0, 0.0)) -> Plane:
    """``plane`` turned by the rotation matrix ``rotation`` about the point ``about``."""
    R = np.asarray(rotation, dtype=float)
    centre = np.asarray(about, dtype=float)
    point = centre + R @ (np.array(plane.point) - centre)
    return Plane(tuple(float(v) for v in point), _clean(R @ np.array(plane.normal)),
                 plane.name)


def tilted(plane: Plane, angle: float, about=None) -> Plane:
    """``plane`` turned by ``angle`` (rad) about the y axis through ``about`` (default:
    its own point)."""
    return turned(plane, rotation_y(angle), plane.point if about is None else about)


def channel(gap: float, tilt: float = 0.0, names=("floor", "ceiling")) -> tuple:
    """Two parallel plates ``gap`` (m) apart, facing each other -- the seed's floor and
    ceiling -- turned together by ``tilt`` (rad) about the y axis through the origin
    (tilt = pi/2: two vertical walls, Hefner's channel)."""
    R = rotation_y(tilt)
    return tuple(turned(p.named(name), R) for p, name in zip(seed_planes(gap), names))


def wedge(opening: float, tilt: float = 0.0, names=("lower", "upper")) -> tuple:
    """Two plates meeting along the y axis with the angle ``opening`` (rad, in (0, pi))
    between them, the space of the ball between them opening towards +x: the lower the
    plane z = 0, the upper turned by ``opening`` about the y axis; both then turned by
    ``tilt`` (rad) about the y axis."""
    if not 0 < opening < math.pi:
        raise PlaneError(f"opening = {plain(opening)} is not allowed: must be in (0, pi)")
    lower = Plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), names[0])
    upper = turned(Plane((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), names[1]), rotation_y(-opening))
    R = rotation_y(tilt)
    return turned(lower, R), turned(upper, R)


def box(size=(2.0, 2.0, 2.0), centre=(0.0, 0.0, 0.0)) -> tuple:
    """Six walls of the box ``size`` (m, along x, y, z) around ``centre``, facing in:
    named floor, ceiling, west (-x), east (+x), south (-y), north (+y)."""
    sx, sy, sz = _vector("size", size)
    cx, cy, cz = _vector("centre", centre)
    return (Plane((cx, cy, cz - sz / 2), (0.0, 0.0, 1.0), "floor"),
            Plane((cx, cy, cz + sz / 2), (0.0, 0.0, -1.0), "ceiling"),
            Plane((cx - sx / 2, cy, cz), (1.0, 0.0, 0.0), "west"),
            Plane((cx + sx / 2, cy, cz), (-1.0, 0.0, 0.0), "east"),
            Plane((cx, cy - sy / 2, cz), (0.0, 1.0, 0.0), "south"),
            Plane((cx, cy + sy / 2, cz), (0.0, -1.0, 0.0), "north"))


def check_room(planes, radius: float) -> None:
    """PlaneError unless the planes leave room for a ball of ``radius`` (m): some centre
    at least ``radius`` from every plane, on its side.  Two facing parallel planes must
    be more than 2 r apart (named in the message); three or more planes are checked
    together (a linear programme)."""
    units = [p.unit_normal for p in planes]
    names = names_of(planes)
    for a in range(len(planes)):
        for b in range(a + 1, len(planes)):
            if float(units[a] @ units[b]) < -1 + 1e-12:   # facing each other
                gap = float(units[a] @ (np.array(planes[b].point) - planes[a].point))
                if not gap > 2 * radius * (1 + ROOM_MARGIN):
                    raise PlaneError(
                        f"planes {names[a]!r} and {names[b]!r} leave no room for the ball: "
                        f"they face each other {gap:.6g} m apart, which must be more than "
                        f"2 * radius = {2 * radius:.6g} m")
    if len(planes) >= 3 and not _room(tuple((tuple(u), float(u @ p.point)) for u, p in
                                            zip(units, planes)), float(radius)):
        raise PlaneError(f"planes {', '.join(map(repr, names))} leave no room for the ball: "
                         f"no centre is {radius:.6g} m (the radius) from every one of them "
                         "on its side")


@functools.lru_cache(maxsize=256)
def _room(planes: tuple, radius: float) -> bool:
    """Whether some c has n . c - offset > r (1 + ROOM_MARGIN) for every (n, offset):
    max s subject to n . c - s >= offset + r, s <= 1 (scipy's linprog)."""
    from scipy.optimize import linprog
    A = np.array([[-n[0], -n[1], -n[2], 1.0] for n, _ in planes])
    b = np.array([-(offset + radius) for _, offset in planes])
    found = linprog(c=[0.0, 0.0, 0.0, -1.0], A_ub=A, b_ub=b,
                    bounds=[(None, None)] * 3 + [(None, max(radius, 1.0))], method="highs")
    return bool(found.status == 0 and -found.fun > radius * ROOM_MARGIN)


#: A sweep parameter that turns the planes (see the module docstring).
SWEEP_KEY = re.compile(r"planes\.(?:(\d+)\.)?tilt\Z")


def is_sweep_key(name) -> bool:
    """Whether ``name`` is one of the planes' sweep parameters."""
    return isinstance(name, str) and SWEEP_KEY.match(name) is not None


def swept(planes, changes: dict) -> tuple:
    """The base scene's ``planes`` turned as the planes' sweep parameters in ``changes``
    say (each plane's own tilt first, then all of them together); PlaneError for an index
    out of range or a tilt that is not a finite number."""
    planes = list(planes)
    together = None
    for name, value in changes.items():
        match = SWEEP_KEY.match(name)
        try:
            angle = float(value)
            if isinstance(value, bool) or not math.isfinite(angle):
                raise ValueError
        except (TypeError, ValueError):
            raise PlaneError(f"{name} = {plain(value)} is not allowed: must be a finite angle "
                             "(rad)") from None
        if match.group(1) is None:
            together = angle
            continue
        index = int(match.group(1))
        if index >= len(planes):
            raise PlaneError(f"{name} is not allowed: the base scene has {len(planes)} "
                             f"plane{'s' if len(planes) > 1 else ''} (indices 0 to "
                             f"{len(planes) - 1})")
        planes[index] = tilted(planes[index], angle)
    if together is not None:
        R = rotation_y(together)
        planes = [turned(p, R) for p in planes]
    return tuple(planes)


# -------------------------------------------------------------------------------------
# Drawing a plane where it is (the figures, the animation, the HTML view)
# -------------------------------------------------------------------------------------

def tangents(plane: Plane) -> np.ndarray:
    """(2, 3): two orthonormal vectors along ``plane``, t1 x t2 = n (the C core's frame,
    _plane.c: t1 the axis the normal has least of made perpendicular to it)."""
    n = plane.unit_normal
    k = int(np.argmin(np.abs(n)))
    t1 = np.eye(3)[k] - n[k] * n
    t1 /= np.linalg.norm(t1)
    return np.array([t1, np.cross(n, t1)])


def foot(plane: Plane, point) -> np.ndarray:
    """The point of ``plane`` nearest ``point`` (3): ``point`` less its height along the
    normal (a horizontal plane: the plane's own z, exactly)."""
    point = np.asarray(point, dtype=float)
    n = plane.unit_normal
    if n[0] == 0 and n[1] == 0:
        return np.array([point[0], point[1], plane.point[2]])
    return point - plane.height(point) * n


def clipped(plane: Plane, low, high) -> np.ndarray:
    """(k, 3): the polygon where ``plane`` cuts the box [low, high] (3 each), its corners
    in order around it (k = 0 when it misses the box)."""
    low, high = np.asarray(low, float), np.asarray(high, float)
    n, offset = plane.unit_normal, plane.offset
    corners = np.array([[(high if (c >> i) & 1 else low)[i] for i in range(3)]
                        for c in range(8)])
    side = corners @ n - offset
    points = []
    for a in range(8):
        for i in range(3):
            b = a | (1 << i)
            if b == a:
                continue
            sa, sb = side[a], side[b]
            if sa == 0:
                points.append(corners[a])
            if (sa < 0 < sb) or (sb < 0 < sa):
                points.append(corners[a] + sa / (sa - sb) * (corners[b] - corners[a]))
    if len(points) < 3:
        return np.empty((0, 3))
    points = np.unique(np.round(np.array(points), 12), axis=0)
    if len(points) < 3:
        return np.empty((0, 3))
    t = tangents(plane)
    middle = points.mean(axis=0)
    angle = np.arctan2((points - middle) @ t[1], (points - middle) @ t[0])
    return points[np.argsort(angle)]


def drawing_box(scene, positions, margin: float = 1.5) -> tuple:
    """(low, high): the box a picture of ``scene`` shows: the centre's path
    (``positions``, (3, n)) and ``margin`` radii around it; with the seed's two planes,
    from below the floor to above the ceiling (as the pictures always showed them)."""
    r = float(scene.radius)
    low = np.min(positions, axis=1) - margin * r
    high = np.max(positions, axis=1) + margin * r
    if scene.ceiling_height is not None:
        low[2], high[2] = -0.5, float(scene.ceiling_height) + 0.5
        low[:2], high[:2] = min(low[0], low[1], -0.5), max(high[0], high[1], 0.5)
    return low, high
