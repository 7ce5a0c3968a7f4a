"""Static figures of a Result (matplotlib, imported only when a figure is made).

Every function takes a :class:`ballc.Result` and returns ``(figure, axes)``; pass
``ax=`` (or ``axes=``) to draw into existing axes.  Time in s, lengths in m, speeds in
m/s, energies in J, specific force in g (9.80665 m/s^2).

Lines drawn from per-sample arrays are decimated for drawing (``_for_drawing``: at most
``MAX_POINTS`` points, a min/max envelope per time bucket), so a run of millions of
samples draws in about a second; the Result's arrays are never changed.

Long runs: a run that ends in closed form (at rest, rolling or sliding uniformly, or in
a rolling orbit: the last contact's ``t_rest``, ``t_rolling`` or ``t_sliding``) is drawn
from its start to that closed form's start plus ``CLOSED_FORM_MARGIN`` of it, with the
start marked and a note "closed form to t_end" (a 1e9-s run is then not one linear
axis to 1e9 s).  ``t_window=(t0, t1)`` (s) draws any window of the run instead.
"""
from __future__ import annotations

import numpy as np

PLANE_COLOURS = {"floor": "tab:brown", "ceiling": "tab:cyan"}
PLANE_MARKERS = {"floor": "o", "ceiling": "^"}
#: The colours and markers of the other planes, by their index in the scene.
OTHER_COLOURS = ("tab:green", "tab:purple", "tab:olive", "tab:pink", "tab:gray", "tab:blue")
OTHER_MARKERS = ("s", "D", "v", "P", "X", "*")


def plane_style(scene, name) -> tuple:
    """(colour, marker) of the plane ``name`` of ``scene`` in every figure: the seed's
    floor brown o and ceiling cyan ^; any other by its index."""
    if name in PLANE_COLOURS and scene.ceiling_height is not None:
        return PLANE_COLOURS[name], PLANE_MARKERS[name]
    index = scene.plane_names.index(name)
    return OTHER_COLOURS[index % len(OTHER_COLOURS)], OTHER_MARKERS[index % len(OTHER_MARKERS)]


def planes_key(scene) -> str:
    """"brown floor, cyan ceiling": what each plane's colour is, for a title."""
    return ", ".join(f"{plane_style(scene, name)[0].removeprefix('tab:')} {name}"
                     for name in scene.plane_names)
#: Energy keys drawn first, in this order; any other key (e.g. dissipated_*) follows,
#: and "total" comes last, thick.
ENERGY_ORDER = ("kinetic", "potential", "spring")
#: Line style of the x, y, z components: distinct, so that equal components (the seed
#: throw's omega_x and omega_y) stay visible on top of each other.
COMPONENT_STYLES = ("-", "--", ":")
#: Sweep map colours of "came back": yes, no, and no answer (failed run, NaN).
CAME_BACK_COLOURS = {"yes": "#1a9850", "no": "#d73027", "undetermined": "#fee08b",
                     "none": "0.85"}


#: At most this many points per line drawn from per-sample arrays (see ``_for_drawing``):
#: about 10 per pixel column of a 2000-pixel-wide figure, so a decimated line looks the
#: same as the full one, and a figure of any run draws in about a second.
MAX_POINTS = 20000


def _drawn_indices(t, series, max_points: int = MAX_POINTS) -> np.ndarray:
    """Sorted indices of the samples to draw: all of them when there are at most
    ``max_points``; else the first, the last, and in each of equal time buckets the
    sample of each series' minimum and of its maximum (a min/max envelope: no peak is
    lost, however narrow).  At most ``max_points`` indices."""
    t = np.asarray(t)
    n = t.size
    if n <= max_points:
        return np.arange(n)
    series = [np.asarray(values) for values in series]
    buckets = (max_points - 2) // (2 * max(len(series), 1))
    if buckets < 1:
        raise ValueError(f"max_points = {max_points} is too few for {len(series)} series: "
                         f"needs at least {2 * len(series) + 2}")
    # equal time buckets (a pixel column is a span of time); by index if t is constant.
    # t is nondecreasing: each bucket is a run of samples, found by binary search.
    if t[-1] > t[0]:
        starts = np.searchsorted(t, np.linspace(t[0], t[-1], buckets + 1)[:-1], "left")
    else:
        starts = np.linspace(0, n, buckets + 1)[:-1].astype(np.intp)
    starts = np.unique(starts)                              # empty buckets dropped
    segment = np.zeros(n, dtype=np.intp)                    # bucket of each sample
    segment[starts[1:]] = 1
    np.cumsum(segment, out=segment)
    keep = [np.array([0, n - 1])]
    for values in series:
        values = np.ascontiguousarray(values, dtype=float)
        for reduce in (np.fmin, np.fmax):                   # fmin/fmax: NaN ignored
            extreme = reduce.reduceat(values, starts)
            hits = np.flatnonzero(values == extreme[segment])
            first = np.r_[True, segment[hits[1:]] != segment[hits[:-1]]]
            keep.append(hits[first])                        # first hit in its bucket
    return np.unique(np.concatenate(keep))


def _for_drawing(t, *series, max_points: int = MAX_POINTS):
    """``(t, *series)`` reduced to at most ``max_points`` samples for drawing: the first
    and last samples and, per time bucket, each series' minimum and maximum (so peaks and
    contacts stay visible; ``_drawn_indices``).  Only what is drawn is reduced: the
    Result's arrays are not touched.  All series share the kept times."""
    index = _drawn_indices(t, series, max_points)
    if index.size == np.asarray(t).size:
        return (t, *series)
    return (np.asarray(t)[index], *(np.asarray(values)[index] for values in series))


#: A run that ends in closed form from t_c on is drawn to (1 + this) t_c, when its end
#: is later than that (its eventful part, and some of the closed form).
CLOSED_FORM_MARGIN = 0.25
#: What each end state's start is called in the note on the figures.
_CLOSED_FORMS = (("t_rest", "at rest"), ("t_rolling", "rolling"),
                 ("t_sliding", "sliding"))


def closed_form_start(result):
    """(t_c, what) when the run ends in closed form from t_c (s) on -- the last
    contact's rest, rolling or sliding time, ``what`` "at rest", "rolling" or "sliding"
    -- else None."""
    if not result.contacts:
        return None
    last = result.contacts[-1]
    found = [(getattr(last, name), what) for name, what in _CLOSED_FORMS
             if np.isfinite(getattr(last, name))]
    return min(found) if found else None


def check_t_window(t_window, t_first: float, t_last: float):
    """``t_window`` as (t0, t1) floats: two finite times t0 < t1 (s) overlapping the run's
    [t_first, t_last]; None stays None (the automatic window).  ValueError otherwise."""
    if t_window is None:
        return None
    from ._format import plain
    try:
        if isinstance(t_window, (str, bytes)) or len(t_window) != 2 or any(
                isinstance(v, (str, bytes, bool, np.bool_)) for v in t_window):
            raise TypeError
        t0, t1 = (float(v) for v in t_window)
    except (TypeError, ValueError):
        t0 = t1 = np.nan
    if not (np.isfinite(t0) and np.isfinite(t1) and t0 < t1 and t0 <= t_last
            and t1 >= t_first):
        raise ValueError(f"t_window = {plain(t_window)} is not allowed: must be two finite "
                         f"times t0 < t1 (s) overlapping the run, [{t_first:g}, {t_last:g}] "
                         "s (or None: the whole run, or its eventful part when it ends in "
                         "closed form)")
    return (t0, t1)


def _window(result, t_window):
    """(t0, t1, tail) of a figure: ``t_window`` checked, else the whole run, or for a run
    ending in closed form long after it starts, its start plus CLOSED_FORM_MARGIN;
    ``tail``: (t_c, what) of the closed form when its start is in the window and t_end
    beyond it (to mark), else None."""
    t = result.t
    window = check_t_window(t_window, float(t[0]), float(t[-1]))
    closed = closed_form_start(result)
    if window is None:
        window = (float(t[0]), float(t[-1]))
        if closed is not None and closed[0] > t[0]:
            window = (window[0], min(window[1], (1 + CLOSED_FORM_MARGIN) * closed[0]))
    t0, t1 = window
    tail = closed if (closed is not None and t0 <= closed[0] <= t1 and t1 < t[-1]) \
        else None
    return t0, t1, tail


def _in_window(result, t0: float, t1: float, tail=None):
    """``result`` itself, or a copy holding the samples in [t0, t1] and one on each side
    (so lines run to the window's edges) -- but none after t1 when the closed-form
    ``tail`` starts in the window: its samples are sparse (the next may be 1e5 s on), and
    a line to one would draw a straight chord over the closed form.  The Result is not
    changed."""
    import dataclasses
    t = result.t
    first = max(int(np.searchsorted(t, t0, side="left")) - 1, 0)
    stop = min(int(np.searchsorted(t, t1, side="right")) + (tail is None), t.size)
    if first == 0 and stop == t.size:
        return result
    part = slice(first, stop)
    return dataclasses.replace(
        result, t=t[part], y=result.y[:, part],
        flags=None if result.flags is None else result.flags[part],
        latch=None if result.latch is None else result.latch[:, part],
        _energy=None, sol=None)


def _mark_tail(axes, tail, t_end, note_on=-1) -> None:
    """A dashed line at the closed form's start on every axis of ``axes``, and on
    axes[note_on] the note that the run goes on in closed form to t_end."""
    if tail is None:
        return
    t_c, what = tail
    for ax in axes:
        ax.axvline(t_c, color="0.25", ls="--", lw=1.0)
    # the note in the margin after t_c, where nothing more is drawn
    ax = axes[note_on]
    ax.text(t_c, 0.03, f" {what} from\n t = {t_c:.4g} s:\n closed form\n to t_end =\n"
            f" {t_end:g} s \u2192", transform=ax.get_xaxis_transform(), ha="left",
            va="bottom", fontsize="small", color="0.25")


def _verdict_value(value) -> float:
    """came_back as a cell value: 1 yes, 0 no, 0.5 undetermined (None, NaN, <NA>)."""
    import pandas as pd
    return 0.5 if pd.isna(value) else float(bool(value))


def _pyplot():
    """matplotlib.pyplot, imported on first use (it picks Agg when there is no display)."""
    import matplotlib.pyplot as plt
    return plt


#: The normal damping laws' names in figure titles (``Scene.normal_damping``).
DAMPING_LAW_NAMES = {"hunt_crossley": "Hunt-Crossley", "viscoelastic": "viscoelastic"}


def damping_title(scene) -> str:
    """The normal damping input the scene was given, with its law: c_tau (or its
    default), the restitution e, or the viscoelastic damping ratio gamma.  A scene gives
    exactly one of them (``Scene``); the other two are None or derived from it."""
    law = DAMPING_LAW_NAMES[scene.normal_damping]
    if scene.restitution is not None:
        given = f"e = {scene.restitution:g}"
    elif scene.normal_damping == "viscoelastic":
        given = f"$\\gamma$ = {scene.damping_ratio:g}"
    else:
        given = f"$c_\\tau$ = {scene.c_tau:g}"
    return f"{given} ({law})"


def scene_title(scene) -> str:
    """One line naming the normal damping input (``damping_title``), the friction
    coefficient and the tangential model."""
    model = (f"mixture {scene.mixture:g}" if scene.tangential_model == "mixture"
             else f"{scene.tangential_model} model")
    return f"{damping_title(scene)}, $\\mu$ = {scene.friction_coefficient:g}, {model}"


def shade_contacts(ax, result) -> None:
    """Shade the time spans of the contacts, each in its plane's colour (floor brown,
    ceiling cyan: plane_style)."""
    for contact in result.contacts:
        end = contact.t_end if np.isfinite(contact.t_end) else result.t[-1]
        ax.axvspan(contact.t_start, end, color=plane_style(result.scene, contact.plane)[0],
                   alpha=0.2, lw=0)


def plot_coordinates(result, axes=None, figsize=(10, 8), t_window=None):
    """Centre position, centre velocity and angular velocity against time.

    Returns (figure, array of 3 axes).  Contacts are shaded in their plane's colour
    (floor brown, ceiling cyan);
    the x, y, z components are solid, dashed and dotted (``COMPONENT_STYLES``).
    ``t_window=(t0, t1)``: draw that time window (s); default the whole run, or up to
    the closed-form end state plus a margin (see the module's notes).
    """
    plt = _pyplot()
    t0, t1, tail = _window(result, t_window)
    if axes is None:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=figsize, constrained_layout=True)
    else:
        fig = axes[0].figure
    drawn = _in_window(result, t0, t1, tail)
    panels = ((drawn.position, "centre position (m)", ("x", "y", "z")),
              (drawn.velocity, "centre velocity (m/s)", ("$v_x$", "$v_y$", "$v_z$")),
              (drawn.angular_velocity, "angular velocity (rad/s)",
               ("$\\omega_x$", "$\\omega_y$", "$\\omega_z$")))
    for ax, (values, label, names) in zip(axes, panels):
        for row, name, style in zip(values, names, COMPONENT_STYLES):
            ax.plot(*_for_drawing(drawn.t, row), label=name,
                    lw=1.5 if style == ":" else 1.2, ls=style)
        shade_contacts(ax, result)
        ax.set_xlim(t0, t1)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=3)
    _mark_tail(axes, tail, result.t[-1])
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(f"Ball centre (shaded: contacts, {planes_key(result.scene)})\n"
                      + scene_title(result.scene))
    return fig, axes


def plot_energy(result, ax=None, figsize=(10, 5), t_window=None):
    """Every entry of ``result.energy`` against time (J); "total" thick and last.
    ``t_window``: as :func:`plot_coordinates`'s."""
    plt = _pyplot()
    t0, t1, tail = _window(result, t_window)
    fig, ax = (plt.subplots(figsize=figsize, constrained_layout=True) if ax is None
               else (ax.figure, ax))
    drawn = _in_window(result, t0, t1, tail)
    energy = drawn.energy
    names = [k for k in ENERGY_ORDER if k in energy]
    names += [k for k in energy if k not in names and k != "total"]
    for name in names:
        style = "--" if name.startswith("dissipated") else ":" if name == "balance" else "-"
        ax.plot(*_for_drawing(drawn.t, energy[name]), label=name.replace("_", " "),
                lw=1.2, ls=style)
    if "total" in energy:
        ax.plot(*_for_drawing(drawn.t, energy["total"]), label="total", color="k", lw=2)
    shade_contacts(ax, result)
    ax.set_xlim(t0, t1)
    _mark_tail([ax], tail, result.t[-1])
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("Energies (shaded: contacts)\n" + scene_title(result.scene))
    ax.grid(alpha=0.3)
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5))
    return fig, ax


#: What a contact point is, in every figure, the animation and contacts.csv.
CONTACT_POINT = "the centre's (x, y) at maximum penetration"


def contact_points(result) -> np.ndarray:
    """(k, 3) the contact points (m): each contact's centre at maximum penetration
    (``contact_point``, as contacts.csv's contact_point_x/y, and ``contact_point_z``)
    taken to its foot on the plane (a horizontal plane's: (x, y) at the plane's z)."""
    from .planes import foot
    scene = result.scene
    points = np.empty((len(result.contacts), 3))
    for i, contact in enumerate(result.contacts):
        plane = scene.planes[scene.plane_names.index(contact.plane)]
        points[i] = foot(plane, (*contact.contact_point, contact.contact_point_z))
    return points


def _path_view(result, ax, figsize, t_window, axes):
    """What a view of the centre's path on two of its coordinates (``axes``: 0 x, 1 y,
    2 z) starts with: pyplot, the figure and axes (new ones of ``figsize`` if ``ax`` is
    None), the time window (t0, t1, tail) of :func:`_window`, the path's two coordinates
    in it (decimated for drawing), the indices of the contacts that start in it and their
    contact points."""
    plt = _pyplot()
    t0, t1, tail = _window(result, t_window)
    fig, ax = (plt.subplots(figsize=figsize, constrained_layout=True) if ax is None
               else (ax.figure, ax))
    drawn = _in_window(result, t0, t1, tail)
    inside = (drawn.t >= t0) & (drawn.t <= t1)
    _, a, b = _for_drawing(drawn.t[inside], drawn.position[axes[0], inside],
                           drawn.position[axes[1], inside])
    shown = [i for i, c in enumerate(result.contacts) if t0 <= c.t_start <= t1]
    return plt, fig, ax, (t0, t1, tail), a, b, shown, contact_points(result)[shown]


def plot_contacts_top_view(result, ax=None, figsize=(7, 6.5), t_window=None):
    """Top view (x, y): the centre's path and the contact points coloured by time,
    numbered, with arrows from each to the next (floor o, ceiling ^; plane_style).
    ``t_window``: as :func:`plot_coordinates`'s (the path in it, and the contacts that
    start in it)."""
    plt, fig, ax, (t0, t1, tail), x, y, shown, points = _path_view(
        result, ax, figsize, t_window, (0, 1))
    ax.plot(x, y, color="0.6", lw=0.8, label="centre path")
    if t0 <= result.t[0]:
        ax.plot(*result.position[:2, 0], "kx", ms=8, label="start")
    times = np.array([result.contacts[i].t_start for i in shown])
    if len(points):
        norm = plt.Normalize(t0, max(t1, t0 + 1e-12))
        cmap = plt.get_cmap("plasma")
        for plane in result.scene.plane_names:
            chosen = [k for k, i in enumerate(shown) if result.contacts[i].plane == plane]
            if chosen:
                ax.scatter(points[chosen, 0], points[chosen, 1], c=times[chosen], cmap=cmap,
                           norm=norm, marker=plane_style(result.scene, plane)[1], s=80,
                           edgecolors="k", zorder=3, label=f"{plane} contact")
        view = np.concatenate([np.c_[x, y], points[:, :2]])
        for i in _labelled(points[:, :2], float(np.ptp(view, axis=0).max())):
            ax.annotate(str(shown[i] + 1), points[i, :2], textcoords="offset points",
                        xytext=(6, 6), fontsize=9)
        for (x0, y0, _), (x1, y1, _), t in zip(points[:-1], points[1:], times[1:]):
            ax.annotate("", (x1, y1), (x0, y0), arrowprops=dict(
                arrowstyle="->", color=cmap(norm(t)), lw=1.5, shrinkA=6, shrinkB=6))
        if len(points) > 1:     # the arrows are annotations: a legend entry by proxy
            ax.plot([], [], color=cmap(0.5), lw=1.5, marker=">", markevery=[1],
                    label="to the next contact\n(coloured by its time)")
        fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                     label="contact start time (s)")
    if result.scene.ceiling_height is None:   # planes at any orientation: where they are
        draw_planes(ax, result, (0, 1))
    if tail is not None:
        ax.text(0.02, 0.02, f"path to t = {t1:.4g} s; {tail[1]} from t = {tail[0]:.4g} s: "
                f"closed form to t_end = {result.t[-1]:g} s", transform=ax.transAxes,
                fontsize="small", color="0.25", bbox=dict(facecolor="white", alpha=0.7, lw=0))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Contact points ({CONTACT_POINT}), top view\n"
                 + scene_title(result.scene), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig, ax


#: A contact's number is written next to it unless it would come closer than this
#: fraction of the top view's span to a number already written (many short hops in one
#: place -- the last bounces before rolling -- would write their numbers over each
#: other); the first and the last contact are always numbered.
LABEL_SPACING = 0.04


def _labelled(points, span: float) -> list:
    """Indices of the ``points`` (k, 2) to number: the last, the first, then each in
    turn that is at least LABEL_SPACING * span from every one numbered so far."""
    if not len(points):
        return []
    order = [len(points) - 1, 0, *range(1, len(points) - 1)]
    kept = []
    for i in dict.fromkeys(order):
        if all(np.hypot(*(points[i] - points[j])) >= LABEL_SPACING * span for j in kept):
            kept.append(i)
    return sorted(kept)


#: plot_observer evaluates the specific force (the compiled right-hand side, per
#: sample) at every sample of a run with at most this many, else at about this many
#: chosen samples (``_observer_samples``): a bounded cost, about 0.3 s.
OBSERVER_SAMPLES = 200_000
#: ... and at every sample of each contact with at most this many samples (impacts,
#: where the specific force peaks), however long the run.
OBSERVER_CONTACT_SAMPLES = 5_000


def _observer_indices(result, budget: int = OBSERVER_SAMPLES,
                      contact_samples: int = OBSERVER_CONTACT_SAMPLES) -> np.ndarray:
    """Sorted indices of the samples at which plot_observer evaluates the specific force.

    All samples when there are at most ``budget``.  Otherwise the specific force (which
    needs the right-hand side at each sample) cannot be decimated by its own envelope
    without computing it everywhere, so the samples are chosen from what drives it:

    * every sample of each contact with at most ``contact_samples`` samples: the impacts,
      where the specific force has its peaks, are drawn exactly (the first contacts,
      up to ``budget`` such samples in all);
    * in equal time buckets, the samples of the minimum and the maximum of the centre's
      height, velocity and angular velocity (``_drawn_indices`` with ``budget`` points):
      penetration, impacts and spin-ups, and the first and last samples.

    In a long persistent contact (rest, rolling) the force is then drawn through those
    samples: its envelope there is that of the samples chosen, not of every sample.
    """
    t = result.t
    n = t.size
    if n <= budget:
        return np.arange(n)
    rows = [result.position[2], *result.velocity, *result.angular_velocity]
    keep = [_drawn_indices(t, rows, budget)]
    spent = 0                        # contact samples, at most another ``budget`` in all
    for contact in result.contacts:
        end = contact.t_end if np.isfinite(contact.t_end) else t[-1]
        first, last = np.searchsorted(t, [contact.t_start, end], side="left")
        last = min(int(last) + 1, n)
        if last - first <= contact_samples and spent + last - first <= budget:
            keep.append(np.arange(first, last))
            spent += last - first
    return np.unique(np.concatenate(keep))


def _observer_samples(result):
    """``result`` itself, or a copy holding only the samples of ``_observer_indices``
    (for evaluation and drawing; the Result is not changed)."""
    import dataclasses
    index = _observer_indices(result)
    if index.size == result.t.size or result.flags is None or result.latch is None:
        return result               # (without flags/latch, specific_force says why not)
    return dataclasses.replace(result, t=result.t[index], y=result.y[:, index],
                               flags=result.flags[index], latch=result.latch[:, index],
                               _energy=None, sol=None)


def draw_planes(ax, result, components=(0, 2)) -> None:
    """Each plane of the scene where it is, seen along the remaining axis: the polygon
    where it cuts the picture's box (planes.drawing_box) projected on the axes
    ``components`` (0 x, 1 y, 2 z), filled in its colour (a plane seen edge-on: its
    line), labelled with its name."""
    from .planes import clipped, drawing_box
    scene = result.scene
    low, high = drawing_box(scene, result.position)
    for plane, name in zip(scene.planes, scene.plane_names):
        polygon = clipped(plane, low, high)
        if not len(polygon):
            continue
        colour = plane_style(scene, name)[0]
        shape = polygon[:, components]
        ax.fill(*shape.T, color=colour, alpha=0.25, lw=0)
        ax.plot(*np.vstack([shape, shape[:1]]).T, color=colour, lw=2, label=f"plane {name}")


def plot_side_view(result, ax=None, figsize=(8, 6.5), t_window=None):
    """Side view (x, z): the centre's path, every plane where it is (each in its
    colour, seen along y: a plane containing the y axis as its line) and the contact
    points numbered -- the picture of a tilted pair of plates, a wedge or a channel.
    ``t_window``: as :func:`plot_coordinates`'s."""
    plt, fig, ax, (t0, t1, tail), x, z, shown, points = _path_view(
        result, ax, figsize, t_window, (0, 2))
    draw_planes(ax, result, (0, 2))
    ax.plot(x, z, color="0.35", lw=0.8, label="centre path")
    if t0 <= result.t[0]:
        ax.plot(result.position[0, 0], result.position[2, 0], "kx", ms=8, label="start")
    for k, i in enumerate(shown):
        colour, marker = plane_style(result.scene, result.contacts[i].plane)
        ax.plot(points[k, 0], points[k, 2], marker=marker, color=colour, mec="k", ms=8,
                ls="")
    for i in _labelled(points[:, [0, 2]], max(float(np.ptp(np.r_[x, z])), 1e-12)):
        ax.annotate(str(shown[i] + 1), points[i, [0, 2]], textcoords="offset points",
                    xytext=(6, 6), fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("Side view: the planes where they are, the centre's path and the "
                 "contact points\n" + scene_title(result.scene), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig, ax


def plot_observer(result, axes=None, figsize=(10, 7), t_window=None):
    """The observer's specific force (acceleration - gravity) in g: ball-frame
    components (what an accelerometer inside the ball reads) and inertial ones.
    ``t_window``: as :func:`plot_coordinates`'s."""
    plt = _pyplot()
    t0, t1, tail = _window(result, t_window)
    if axes is None:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=figsize, constrained_layout=True)
    else:
        fig = axes[0].figure
    from .observer import specific_force, to_ball_frame
    # The specific force is evaluated once for both frames, at the samples of the
    # window that _observer_samples picks (all of them up to OBSERVER_SAMPLES); each
    # line is then decimated for drawing by its own min/max envelope.
    drawn = _observer_samples(_in_window(result, t0, t1, tail))
    inertial = specific_force(drawn, frame="inertial")
    ball = to_ball_frame(drawn, inertial)
    magnitude = np.linalg.norm(inertial, axis=0)
    for ax, values, frame in ((axes[0], ball, "ball frame"), (axes[1], inertial, "inertial")):
        for row, axis in zip(values, "xyz"):
            ax.plot(*_for_drawing(drawn.t, row), lw=1.0, label=f"{axis}")
        ax.plot(*_for_drawing(drawn.t, magnitude), color="k", lw=0.8, ls="--", label="|f|")
        shade_contacts(ax, result)
        ax.set_xlim(t0, t1)
        ax.set_ylabel(f"specific force, {frame} (g)")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=4)
    _mark_tail(axes, tail, result.t[-1])
    axes[-1].set_xlabel("time (s)")
    alpha, beta, gamma = result.scene.observer_position
    axes[0].set_title(f"What the observer at ({alpha:g}, {beta:g}, {gamma:g}) r feels: "
                      "acceleration - gravity, in g (0 in free flight without spin)\n"
                      + scene_title(result.scene))
    return fig, axes


def plot_sweep_map(table, x: str, y: str, value: str = "came_back", ax=None,
                   figsize=(8, 6)):
    """Heat map of ``value`` over a two-parameter sweep table (``ballc.sweep``).

    Each cell is one scene; for "came_back" the colour says yes / no / undetermined
    (fewer completed contacts than the criterion needs, or a run that raised) and the
    text gives the fraction of energy lost (%).  Failed runs (status != 0) are marked
    with "!"; a combination missing from the table is grey.
    """
    plt = _pyplot()
    fig, ax = (plt.subplots(figsize=figsize, constrained_layout=True) if ax is None
               else (ax.figure, ax))
    xs = sorted(table[x].unique())
    ys = sorted(table[y].unique())
    grid = np.full((len(ys), len(xs)), np.nan)
    boolean = value == "came_back"
    for _, row in table.iterrows():
        grid[ys.index(row[y]), xs.index(row[x])] = (_verdict_value(row[value]) if boolean
                                                    else float(row[value]))
    if boolean:      # three colours and a legend: a verdict is not a continuous quantity
        from matplotlib.colors import ListedColormap
        cmap = ListedColormap([CAME_BACK_COLOURS["no"], CAME_BACK_COLOURS["undetermined"],
                               CAME_BACK_COLOURS["yes"]]
                              ).with_extremes(bad=CAME_BACK_COLOURS["none"])
    else:
        cmap = plt.get_cmap("viridis")
    image = ax.imshow(grid, origin="lower", cmap=cmap, aspect="auto",
                      vmin=0 if boolean else None, vmax=1 if boolean else None)
    for _, row in table.iterrows():
        i, j = ys.index(row[y]), xs.index(row[x])
        text = (f"{100 * row['energy_lost_fraction']:.0f}%" if boolean
                else f"{row[value]:.3g}")
        if row["status"] != 0:
            text += "!"
        ax.text(j, i, text, ha="center", va="center", fontsize=7, color="k")
    ax.set_xticks(range(len(xs)), [f"{v:g}" for v in xs], rotation=45)
    ax.set_yticks(range(len(ys)), [f"{v:g}" for v in ys])
    ax.set_xlabel(x.replace("_", " "))
    ax.set_ylabel(y.replace("_", " "))
    if boolean:
        from matplotlib.patches import Patch
        handles = [Patch(facecolor=CAME_BACK_COLOURS["yes"], label="came back"),
                   Patch(facecolor=CAME_BACK_COLOURS["no"], label="did not come back")]
        if (grid == 0.5).any():
            handles.append(Patch(facecolor=CAME_BACK_COLOURS["undetermined"],
                                 label="undetermined\n(fewer than 3 contacts)"))
        if np.isnan(grid).any():
            handles.append(Patch(facecolor=CAME_BACK_COLOURS["none"], label="no run"))
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1),
                  title="x-velocity reversed\nafter 3 contacts?", fontsize="small")
        ax.set_title("Does the throw come back?  (cell text: energy lost; !: run failed)")
    else:
        fig.colorbar(image, ax=ax, label=value.replace("_", " "))
        ax.set_title(f"{value.replace('_', ' ')} over the sweep")
    return fig, ax
