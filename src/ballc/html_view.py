"""An interactive 3-D view of a Result as one self-contained HTML page (meshcat).

Use::

    from ballc.html_view import write_html
    write_html(result, "run.html")        # open it in a browser: drag to turn, scroll to zoom

The page is meshcat's viewer (three.js, WebGL; the viewer Drake uses) with its
JavaScript inlined and the scene and its animation embedded as meshcat's own msgpack
commands, as meshcat's static HTML export writes them: it needs no server, no network
and no other file.  The scene: the floor (z = 0) and the ceiling (z = H) as translucent
slabs, the ball as a wireframe sphere turning with the ball, the observer as a red dot
fixed in the ball, the path of the centre (green) and the contact points (orange on the
floor, blue on the ceiling).  The ball's motion is a meshcat animation (position and
quaternion keyframes, ``fps`` per second of playback, played in a loop); its controls
(play, pause, time scale) are in the viewer's "Animations" menu.

Needs the ``html`` extra (``pip install "ballc[html]"``: meshcat); imported only when
called.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

_TEMPLATE = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
  body {{ margin: 0; }}
  #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
  #ballc-caption {{ position: absolute; left: 10px; bottom: 10px; font: 13px sans-serif;
                    color: #222; background: rgba(255, 255, 255, 0.75); padding: 4px 8px;
                    border-radius: 4px; pointer-events: none; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="ballc-caption">{caption}</div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
{commands}
</script>
</body>
</html>
"""


class _Recorder:
    """A meshcat window that keeps the commands instead of sending them to a server."""

    def __init__(self, packb):
        self._packb = packb
        self.commands = []

    def send(self, command):
        self.commands.append(self._packb(command.lower()))


def _import_meshcat():
    try:
        import meshcat
        import meshcat.animation
        import meshcat.geometry
        import meshcat.transformations
        import umsgpack
    except ImportError as error:
        raise ImportError("ballc.html_view needs meshcat: pip install 'ballc[html]' "
                          f"(or pip install meshcat): {error}") from None
    return meshcat, umsgpack


def _command_js(data: bytes) -> str:
    """One packed meshcat command as the JavaScript meshcat's static export writes."""
    import base64
    return ('fetch("data:application/octet-binary;base64,'
            + base64.b64encode(data).decode("ascii")
            + '").then(res => res.arrayBuffer())'
            '.then(buffer => viewer.handle_command_bytearray(new Uint8Array(buffer)));\n')


def scene_html(result, *, fps: int = 30, speed: float = 1.0, loop: bool = True,
               title: str | None = None) -> str:
    """The page of :func:`write_html` as a string (see there)."""
    meshcat, umsgpack = _import_meshcat()
    g = meshcat.geometry
    tf = meshcat.transformations
    from .animate import _sample

    if not (isinstance(fps, (int, np.integer)) and fps >= 1):
        raise ValueError(f"fps = {fps!r} is not allowed: must be a whole number >= 1")
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed = {speed!r} is not allowed: must be a finite number > 0")
    scene = result.scene
    seed = scene.ceiling_height is not None   # the seed's floor and ceiling
    position = np.asarray(result.position)
    r = float(scene.radius)
    h = float(scene.ceiling_height) if seed else float(np.ptp(position[2]) + 4 * r)
    t0, t1 = float(result.t[0]), float(result.t[-1])

    recorder = _Recorder(umsgpack.packb)
    root = meshcat.Visualizer(window=recorder)
    root["/Grid"].set_property("visible", False)
    root["/Axes"].set_property("visible", False)
    vis = root["ballc"]     # the scene, shifted so that the viewer's orbit centre is its middle

    # The planes: slabs whose faces are the planes, covering the motion (the seed's: z = 0
    # and z = H; any other plane: a square slab along it around the path's middle).
    low = position[:2].min(axis=1) - 2 * r
    high = position[:2].max(axis=1) + 2 * r
    centre = (low + high) / 2
    size = np.maximum(high - low, 4 * r)
    size = np.maximum(size, 0.5 * max(size.max(), h))     # no thin strip for a 1-D throw
    thickness = 0.02 * max(h, 4 * r)
    plane = g.MeshLambertMaterial(color=0x7fa7b5, opacity=0.35)
    middle = np.r_[centre, (position[2].min() + position[2].max()) / 2]
    if seed:
        for name, z in (("floor", -thickness / 2), ("ceiling", h + thickness / 2)):
            vis["planes"][name].set_object(g.Box([size[0], size[1], thickness]), plane)
            vis["planes"][name].set_transform(tf.translation_matrix([centre[0], centre[1], z]))
    else:
        from .planes import foot, tangents
        side = 1.2 * max(size.max(), h)
        for each, name in zip(scene.planes, scene.plane_names):
            frame = np.eye(4)   # the slab's axes: the plane's t1, t2 and n
            frame[:3, :3] = np.column_stack([*tangents(each), each.unit_normal])
            frame[:3, 3] = foot(each, middle) - 0.5 * thickness * each.unit_normal
            vis["planes"][name].set_object(g.Box([side, side, thickness]), plane)
            vis["planes"][name].set_transform(frame)

    # The ball (wireframe, so that its turning shows) and the observer fixed in it.
    vis["ball"].set_object(g.Sphere(r), g.MeshBasicMaterial(color=0x2040c0, wireframe=True))
    vis["ball/observer"].set_object(g.Sphere(0.08 * r), g.MeshLambertMaterial(color=0xd01010))
    vis["ball/observer"].set_transform(
        tf.translation_matrix(r * np.asarray(scene.observer_position, dtype=float)))

    # The path of the centre and the contact points.
    step = max(1, position.shape[1] // 4000)
    vis["path"].set_object(g.Line(g.PointsGeometry(position[:, ::step].astype(np.float32)),
                                  g.LineBasicMaterial(color=0x229922)))
    from .plot import contact_points
    for i, (contact, point) in enumerate(zip(result.contacts, contact_points(result))):
        x, y = contact.contact_point
        if not (np.isfinite(x) and np.isfinite(y) and np.all(np.isfinite(point))):
            continue
        on_floor = contact.plane == "floor" if seed else (
            scene.plane_names.index(contact.plane) % 2 == 0)
        marker = g.MeshLambertMaterial(color=0xe07010 if on_floor else 0x1060e0)
        vis["contacts"][str(i + 1)].set_object(g.Sphere(0.12 * r), marker)
        vis["contacts"][str(i + 1)].set_transform(tf.translation_matrix(point))

    # The motion: keyframes at fps per second of playback.
    count = max(2, int(math.ceil((t1 - t0) / speed * fps)) + 1)
    times = np.linspace(t0, t1, count)
    centres, quaternions, _ = _sample(result, times)
    animation = meshcat.animation.Animation(default_framerate=fps)
    for frame, (c, q) in enumerate(zip(centres, quaternions)):
        matrix = tf.quaternion_matrix(q)          # (qw, qx, qy, qz), ball -> inertial
        matrix[:3, 3] = c
        with animation.at_frame(vis, frame) as frame_vis:
            frame_vis["ball"].set_transform(matrix)
    root.set_animation(animation, play=True, repetitions=1_000_000 if loop else 1)

    # The camera orbits the origin: put the middle of the box between the planes there,
    # and look from the side of the main horizontal direction of motion (not along it),
    # a little from above.
    vis.set_transform(tf.translation_matrix([-centre[0], -centre[1],
                                             -h / 2 if seed else -middle[2]]))
    reach = 1.25 * max(h, size[0], size[1])
    spread = position[:2] - position[:2].mean(axis=1, keepdims=True)
    main = np.linalg.eigh(spread @ spread.T)[1][:, -1]            # principal direction
    azimuth = math.atan2(main[1], main[0]) + math.radians(70)
    eye = reach * np.array([math.cos(azimuth), math.sin(azimuth), 0.35])
    # the camera object's own coordinates are three.js's (y up): (x, z, -y)
    root["/Cameras/default/rotated/<object>"].set_property("position",
                                                           [eye[0], eye[2], -eye[1]])

    viewer_js = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(
        encoding="utf-8")
    title = title or f"ballc: {len(result.contacts)} contacts in {t1 - t0:g} s"
    caption = (f"{title}; ball radius {r:g} m, ceiling at {h:g} m; drag to turn, scroll to "
               f"zoom; playback {speed:g}x (controls: Animations)")
    return _TEMPLATE.format(title=_escape(title), caption=_escape(caption),
                            viewer_js=viewer_js,
                            commands="".join(_command_js(c) for c in recorder.commands))


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def write_html(result, path, *, fps: int = 30, speed: float = 1.0, loop: bool = True,
               title: str | None = None) -> Path:
    """Write an interactive 3-D view of ``result`` to one self-contained HTML file.

    Parameters
    ----------
    result : Result
        A simulated run.
    path : str or Path
        The HTML file to write (its folder must exist).
    fps : int
        Keyframes per second of playback (1/s).
    speed : float
        Playback speed: simulated seconds per second of playback (1).
    loop : bool
        Play the motion in a loop (default) or once.
    title : str, optional
        Page title; default: the number of contacts and the simulated time.

    Returns
    -------
    Path
        ``path``.  The page inlines meshcat's viewer (about 0.9 MB) and references
        no other file or address.
    """
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise ValueError(f"{path}: an HTML view is written to a .html file")
    text = scene_html(result, fps=fps, speed=speed, loop=loop, title=title)
    path.write_text(text, encoding="utf-8")
    return path
