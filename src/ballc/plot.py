"""Static figures of a Result (matplotlib, imported only when a figure is made).

Every function takes a :class:`ballc.Result` and returns ``(figure, axes)``; pass
``ax=`` (or ``axes=``) to draw into existing axes.  Time in s, lengths in m, speeds in
m/s, energies in J, specific force in g (9.80665 m/s^2).
"""
from __future__ import annotations

import numpy as np

PLANE_COLOURS = {"floor": "tab:brown", "ceiling": "tab:cyan"}
PLANE_MARKERS = {"floor": "o", "ceiling": "^"}
#: Energy keys drawn first, in this order; any other key (e.g. dissipated_*) follows,
#: and "total" comes last, thick.
ENERGY_ORDER = ("kinetic", "potential", "spring")
#: Line style of the x, y, z components: distinct, so that equal components (the seed
#: throw's omega_x and omega_y) stay visible on top of each other.
COMPONENT_STYLES = ("-", "--", ":")
#: Sweep map colours of "came back": yes, no, and no answer (failed run, NaN).
CAME_BACK_COLOURS = {"yes": "#1a9850", "no": "#d73027", "undetermined": "#fee08b",
                     "none": "0.85"}


def _verdict_value(value) -> float:
    """came_back as a cell value: 1 yes, 0 no, 0.5 undetermined (None, NaN, <NA>)."""
    import pandas as pd
    return 0.5 if pd.isna(value) else float(bool(value))


def _pyplot():
    """matplotlib.pyplot, imported on first use (it picks Agg when there is no display)."""
    import matplotlib.pyplot as plt
    return plt


def scene_title(scene) -> str:
    """One line naming the tangential model and its parameters."""
    model = (f"mixture {scene.mixture:g}" if scene.tangential_model == "mixture"
             else f"{scene.tangential_model} model")
    return (f"$c_\\tau$ = {scene.c_tau:g}, $\\mu$ = {scene.friction_coefficient:g}, "
            f"{model}")


def shade_contacts(ax, result) -> None:
    """Shade the time spans of the contacts (floor brown, ceiling cyan)."""
    for contact in result.contacts:
        end = contact.t_end if np.isfinite(contact.t_end) else result.t[-1]
        ax.axvspan(contact.t_start, end, color=PLANE_COLOURS[contact.plane], alpha=0.2, lw=0)


def plot_coordinates(result, axes=None, figsize=(10, 8)):
    """Centre position, centre velocity and angular velocity against time.

    Returns (figure, array of 3 axes).  Contacts are shaded (floor brown, ceiling cyan);
    the x, y, z components are solid, dashed and dotted (``COMPONENT_STYLES``).
    """
    plt = _pyplot()
    if axes is None:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=figsize, constrained_layout=True)
    else:
        fig = axes[0].figure
    panels = ((result.position, "centre position (m)", ("x", "y", "z")),
              (result.velocity, "centre velocity (m/s)", ("$v_x$", "$v_y$", "$v_z$")),
              (result.angular_velocity, "angular velocity (rad/s)",
               ("$\\omega_x$", "$\\omega_y$", "$\\omega_z$")))
    for ax, (values, label, names) in zip(axes, panels):
        for row, name, style in zip(values, names, COMPONENT_STYLES):
            ax.plot(result.t, row, label=name, lw=1.5 if style == ":" else 1.2, ls=style)
        shade_contacts(ax, result)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=3)
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title("Ball centre (shaded: contacts, brown floor, cyan ceiling)\n"
                      + scene_title(result.scene))
    return fig, axes


def plot_energy(result, ax=None, figsize=(10, 5)):
    """Every entry of ``result.energy`` against time (J); "total" thick and last."""
    plt = _pyplot()
    fig, ax = (plt.subplots(figsize=figsize, constrained_layout=True) if ax is None
               else (ax.figure, ax))
    energy = result.energy
    names = [k for k in ENERGY_ORDER if k in energy]
    names += [k for k in energy if k not in names and k != "total"]
    for name in names:
        style = "--" if name.startswith("dissipated") else ":" if name == "balance" else "-"
        ax.plot(result.t, energy[name], label=name.replace("_", " "), lw=1.2, ls=style)
    if "total" in energy:
        ax.plot(result.t, energy["total"], label="total", color="k", lw=2)
    shade_contacts(ax, result)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("Energies (shaded: contacts)\n" + scene_title(result.scene))
    ax.grid(alpha=0.3)
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5))
    return fig, ax


#: What a contact point is, in every figure, the animation and contacts.csv.
CONTACT_POINT = "the centre's (x, y) at maximum penetration"


def contact_points(result) -> np.ndarray:
    """(k, 3) the contact points (m): each contact's ``contact_point`` -- the centre's
    (x, y) at maximum penetration, as contacts.csv's contact_point_x/y -- on its plane."""
    points = np.empty((len(result.contacts), 3))
    for i, contact in enumerate(result.contacts):
        z = 0.0 if contact.plane == "floor" else result.scene.ceiling_height
        points[i] = (*contact.contact_point, z)
    return points


def plot_contacts_top_view(result, ax=None, figsize=(7, 6.5)):
    """Top view (x, y): the centre's path and the contact points coloured by time,
    numbered, with arrows from each to the next (floor o, ceiling ^)."""
    plt = _pyplot()
    fig, ax = (plt.subplots(figsize=figsize, constrained_layout=True) if ax is None
               else (ax.figure, ax))
    ax.plot(result.position[0], result.position[1], color="0.6", lw=0.8,
            label="centre path")
    ax.plot(*result.position[:2, 0], "kx", ms=8, label="start")
    points = contact_points(result)
    times = np.array([c.t_start for c in result.contacts])
    if len(points):
        norm = plt.Normalize(0.0, max(result.t[-1], 1e-12))
        cmap = plt.get_cmap("plasma")
        for plane in ("floor", "ceiling"):
            chosen = [i for i, c in enumerate(result.contacts) if c.plane == plane]
            if chosen:
                ax.scatter(points[chosen, 0], points[chosen, 1], c=times[chosen], cmap=cmap,
                           norm=norm, marker=PLANE_MARKERS[plane], s=80, edgecolors="k",
                           zorder=3, label=f"{plane} contact")
        for i, (x, y, _) in enumerate(points, 1):
            ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(6, 6),
                        fontsize=9)
        for (x0, y0, _), (x1, y1, _), t in zip(points[:-1], points[1:], times[1:]):
            ax.annotate("", (x1, y1), (x0, y0), arrowprops=dict(
                arrowstyle="->", color=cmap(norm(t)), lw=1.5, shrinkA=6, shrinkB=6))
        if len(points) > 1:     # the arrows are annotations: a legend entry by proxy
            ax.plot([], [], color=cmap(0.5), lw=1.5, marker=">", markevery=[1],
                    label="to the next contact\n(coloured by its time)")
        fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                     label="contact start time (s)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Contact points ({CONTACT_POINT}), top view\n"
                 + scene_title(result.scene), fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig, ax


def plot_observer(result, axes=None, figsize=(10, 7)):
    """The observer's specific force (acceleration - gravity) in g: ball-frame
    components (what an accelerometer inside the ball reads) and inertial ones."""
    plt = _pyplot()
    if axes is None:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=figsize, constrained_layout=True)
    else:
        fig = axes[0].figure
    inertial = result.observer_specific_force
    ball = result.observer_specific_force_ball
    magnitude = np.linalg.norm(inertial, axis=0)
    for ax, values, frame in ((axes[0], ball, "ball frame"), (axes[1], inertial, "inertial")):
        for row, axis in zip(values, "xyz"):
            ax.plot(result.t, row, lw=1.0, label=f"{axis}")
        ax.plot(result.t, magnitude, color="k", lw=0.8, ls="--", label="|f|")
        shade_contacts(ax, result)
        ax.set_ylabel(f"specific force, {frame} (g)")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=4)
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
