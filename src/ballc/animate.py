"""3D animation of a Result, like the seed's but in seconds (matplotlib).

Two translucent planes (floor z = 0, ceiling z = H), the ball as a wireframe sphere
turning with the ball, the observer as a red dot, the contact points coloured by time,
joined in order by green dashed lines with a red arrow pointing to the next; a legend
says which is which.  Frames are taken at equal steps of simulated
time (interpolated), so the animation runs at a constant speed; static artists are
drawn once and only the ball, the observer and the contact markers change per frame.
"""
from __future__ import annotations

import shutil
import subprocess

import numpy as np

from .orientation import rotation_matrix

#: Default number of frames: enough to follow the bounces, few enough to write in seconds.
DEFAULT_FRAMES = 100


def check_frames(frames) -> int:
    """``frames`` as an int >= 1, else ValueError naming the value (the one check of the
    frame count: ``animate`` and ``ballc --frames`` use it)."""
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) and not (
            isinstance(frames, (float, np.floating)) and float(frames).is_integer()):
        raise ValueError(f"frames = {frames!r} is not allowed: must be a whole number >= 1")
    if frames < 1:
        raise ValueError(f"frames = {frames!r} is not allowed: must be >= 1")
    return int(frames)


def _sphere_mesh(radius, count=13):
    """(3, count, count) points of a sphere of ``radius`` in ball-frame coordinates (m)."""
    u = np.linspace(0, 2 * np.pi, count)
    v = np.linspace(0, np.pi, count)
    return radius * np.array([np.outer(np.cos(u), np.sin(v)),
                              np.outer(np.sin(u), np.sin(v)),
                              np.outer(np.ones_like(u), np.cos(v))])


def _sample(result, times):
    """Centre (k, 3), unit quaternions (k, 4), observer (k, 3) at ``times`` (linear interp.)."""
    def interp(rows):
        return np.stack([np.interp(times, result.t, row) for row in rows], axis=-1)
    quaternion = interp(result.quaternion)
    return (interp(result.position),
            quaternion / np.linalg.norm(quaternion, axis=-1, keepdims=True),
            interp(result.observer_position))


def animate(result, path=None, *, frames: int = DEFAULT_FRAMES, fps: int = 20, dpi: int = 80,
            figsize=(6.4, 6.4), elevation: float = 25.0, azimuth: float = 30.0):
    """Animate ``result`` in 3D; write it to ``path`` if given.

    Parameters
    ----------
    path : str or Path, optional
        ".gif" (Pillow) or ".mp4" (needs ffmpeg on the PATH).
    frames : int
        Number of frames, at equal steps of simulated time from t[0] to t[-1].
    fps : int
        Frames per second of the written file.
    dpi, figsize
        Size of each frame: figsize (inches) x dpi.

    Returns
    -------
    matplotlib.animation.FuncAnimation
        Its figure is ``animation._fig``; ``animation.frame_times`` holds the simulated
        time (s) of each frame.
    """
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation
    from matplotlib.ticker import MaxNLocator

    from .planes import clipped, drawing_box
    from .plot import contact_points, plane_style, scene_title

    frames = check_frames(frames)
    scene = result.scene
    times = np.linspace(result.t[0], result.t[-1], frames)
    centre, quaternion, observer = _sample(result, times)
    rotation = rotation_matrix(quaternion)                     # (k, 3, 3), v_N = R v_A
    mesh = _sphere_mesh(scene.radius)
    points = contact_points(result)
    starts = np.array([c.t_start for c in result.contacts])

    # the box shown: the path and 1.5 radii around it (with the seed's planes, the floor
    # to the ceiling); each plane drawn where it cuts that box
    box_low, box_high = drawing_box(scene, centre.T)
    if scene.ceiling_height is None:   # a cube around the middle of the path
        middle, half = (box_low + box_high) / 2, np.max(box_high - box_low) / 2
        box_low, box_high = middle - half, middle + half
    fig = plt.figure(figsize=figsize, dpi=dpi)
    ax = fig.add_subplot(111, projection="3d")
    ax.view_init(elev=elevation, azim=azimuth)
    ax.set(xlim=(box_low[0], box_high[0]), ylim=(box_low[1], box_high[1]),
           zlim=(box_low[2], box_high[2]), xlabel="x (m)", ylabel="y (m)", zlabel="z (m)")
    span = box_high - box_low
    ax.set_box_aspect(tuple(span / span[0]))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):     # few tick labels: text is most of a frame
        axis.set_major_locator(MaxNLocator(4))
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    for plane, name in zip(scene.planes, scene.plane_names):
        polygon = clipped(plane, box_low, box_high)
        if len(polygon):
            colour = "c" if scene.ceiling_height is not None else plane_style(scene, name)[0]
            alpha = 0.1 if name == "ceiling" and scene.ceiling_height is not None else 0.2
            ax.add_collection3d(Poly3DCollection([polygon], color=colour, alpha=alpha))

    cmap = plt.get_cmap("plasma")
    colours = cmap(starts / max(result.t[-1], 1e-12)) if len(starts) else []
    markers = [ax.plot(*p[:, None], marker="o", ms=7, color=c, visible=False)[0]
               for p, c in zip(points, colours)]
    arrows = []
    for p0, p1, c in zip(points[:-1], points[1:], colours[1:]):
        mid, step = (p0 + p1) / 2, p1 - p0
        arrows.append(ax.quiver(*mid, *step, length=0.6, normalize=True, color="red",
                                lw=1.5, arrow_length_ratio=0.6, visible=False))
    path_line, = ax.plot([], [], [], color="green", lw=0.6, ls="--")
    observer_dot, = ax.plot([], [], [], "o", color="red", ms=6)
    ax.set_title(scene_title(scene), fontsize=10)
    # What the symbols mean (proxies: quivers and hidden markers have no legend handle).
    from matplotlib.lines import Line2D
    legend = [Line2D([], [], ls="", marker="o", color="red", ms=6, label="the observer"),
              Line2D([], [], ls="", marker="o", color=cmap(0.5), ms=7,
                     label="contact point: centre at max. penetration\n"
                           "(colour: time, dark early, light late)"),
              Line2D([], [], color="green", lw=0.8, ls="--",
                     label="contact points in order"),
              Line2D([], [], ls="", marker=r"$\uparrow$", color="red", ms=10,
                     label="direction to the next contact")]
    fig.legend(handles=legend, loc="lower center", ncol=2, fontsize=8, frameon=False)
    clock = fig.text(0.02, 0.97, "", fontsize=11, va="top", family="monospace")
    state = {"ball": None}

    def update(frame):
        if state["ball"] is not None:
            state["ball"].remove()
        ball = np.einsum("ij,jkl->ikl", rotation[frame], mesh) + centre[frame][:, None, None]
        state["ball"] = ax.plot_wireframe(*ball, color="b", alpha=0.6, lw=0.4)
        observer_dot.set_data_3d(*observer[frame][:, None])
        shown = starts <= times[frame]
        for marker, visible in zip(markers, shown):
            marker.set_visible(visible)
        for arrow, visible in zip(arrows, shown[1:]):
            arrow.set_visible(visible)
        k = int(shown.sum())
        path_line.set_data_3d(*points[:k].T) if k else path_line.set_data_3d([], [], [])
        clock.set_text(f"t = {times[frame]:5.2f} s")
        return [state["ball"], observer_dot, path_line, clock, *markers, *arrows]

    dynamic = [observer_dot, path_line, clock, *markers, *arrows]
    if path is not None:
        _write(fig, ax, update, dynamic, frames, str(path), fps)
    animation = FuncAnimation(fig, update, frames=frames, interval=1000 / fps, blit=False)
    animation.frame_times = times
    if path is not None:
        # already rendered to the file: silence matplotlib's "deleted without rendering"
        animation._draw_was_started = True
    return animation


def _rendered_frames(fig, ax, update, dynamic, frames):
    """RGBA arrays (h, w, 4) of each frame, drawn fast: the static scene (planes, axes)
    is rendered once; per frame only the changing artists are drawn over it.  (The
    ball is therefore always drawn in front of the translucent planes.)"""
    for artist in dynamic:
        artist.set_animated(True)          # left out of the background
    try:
        fig.canvas.draw()
        background = fig.canvas.copy_from_bbox(fig.bbox)
        renderer = fig.canvas.get_renderer()
        for frame in range(frames):
            changed = update(frame)
            fig.canvas.restore_region(background)
            for artist in changed:
                if not artist.get_visible():
                    continue
                if hasattr(artist, "do_3d_projection"):
                    artist.do_3d_projection()
                artist.draw(renderer)
            yield np.asarray(fig.canvas.buffer_rgba()).copy()
    finally:
        for artist in dynamic:
            artist.set_animated(False)


def _write(fig, ax, update, dynamic, frames, path, fps):
    """Write the frames to a .gif (Pillow) or .mp4 (ffmpeg through a pipe)."""
    lower = path.lower()
    if not lower.endswith((".gif", ".mp4")):
        raise ValueError(f"animation path {path!r}: use a .gif or .mp4 file name")
    if lower.endswith(".mp4") and not has_ffmpeg():
        raise RuntimeError("writing .mp4 needs ffmpeg on the PATH; write a .gif instead")
    images = _rendered_frames(fig, ax, update, dynamic, frames)
    if lower.endswith(".gif"):
        from PIL import Image
        pictures = [Image.fromarray(rgba[..., :3]).quantize(
            method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE) for rgba in images]
        pictures[0].save(path, save_all=True, append_images=pictures[1:], loop=0,
                         duration=round(1000 / fps))
        return
    first = next(images)
    height, width = first.shape[:2]
    command = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba",
               "-s", f"{width}x{height}", "-r", str(fps), "-i", "-",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", path]
    with subprocess.Popen(command, stdin=subprocess.PIPE) as ffmpeg:
        ffmpeg.stdin.write(first.tobytes())
        for rgba in images:
            ffmpeg.stdin.write(rgba.tobytes())
        ffmpeg.stdin.close()
        if ffmpeg.wait() != 0:
            raise RuntimeError(f"ffmpeg failed writing {path!r}")


def has_ffmpeg() -> bool:
    """True when ffmpeg is on the PATH (MP4 output possible)."""
    return shutil.which("ffmpeg") is not None
