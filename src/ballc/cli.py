"""Console entry points: ``ballc demo``, ``ballc run scene.toml``, ``ballc sweep sweep.toml``.

``ballc demo``   the seed scene: figures, 3D animation, contact table (CSV), summary.
``ballc run``    the same for a scene file (see ``Scene.from_toml``), plus the result (.npz).
``ballc sweep``  a parameter sweep from a TOML file (see ``ballc.sweep.load_sweep_file``):
                 a CSV table and, for two parameters, a heat map of "came back".
"""
from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

from .outcome import format_summary
from .scene import Scene, SceneError
from .simulate import simulate

DEMO_FRAMES = 100


def write_contacts_csv(result, path) -> None:
    """One row per contact (SI units): plane, times, velocities before/after, penetration."""
    rows = [{"contact": i, **c.as_dict()} for i, c in enumerate(result.contacts, 1)]
    names = list(rows[0]) if rows else ["contact", "plane", "t_start", "t_end"]
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=names)
        writer.writeheader()
        writer.writerows(rows)


def write_outputs(result, out: Path, *, animate: bool, frames: int) -> list[Path]:
    """Figures (PNG), contact table (CSV) and optionally the animation (GIF, + MP4 with
    ffmpeg) of ``result`` into ``out``; returns the paths written."""
    import matplotlib
    matplotlib.use("Agg")            # files only: never open a window
    import matplotlib.pyplot as plt

    from .animate import animate as make_animation
    from .animate import has_ffmpeg

    out.mkdir(parents=True, exist_ok=True)
    written = []
    figures = (("coordinates.png", result.plot), ("energy.png", result.plot_energy),
               ("contacts_top_view.png", result.plot_contacts),
               ("observer.png", result.plot_observer))
    for name, make in figures:
        fig, _ = make()
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        written.append(out / name)
    write_contacts_csv(result, out / "contacts.csv")
    written.append(out / "contacts.csv")
    if animate:
        names = ["animation.gif"] + (["animation.mp4"] if has_ffmpeg() else [])
        for name in names:
            animation = make_animation(result, out / name, frames=frames)
            plt.close(animation._fig)
            written.append(out / name)
    return written


def _report(result, written, seconds) -> None:
    print(format_summary(result))
    print()
    print(result.contact_table())
    print()
    print("wrote " + ", ".join(str(p) for p in written))
    print(f"[{seconds['simulate']:.2f} s simulation, {seconds['outputs']:.2f} s figures "
          f"and animation]")


def _simulate_and_write(scene, t_end, out, animate, frames, save=False):
    started = time.perf_counter()
    result = simulate(scene, t_end)
    simulated = time.perf_counter()
    written = write_outputs(result, out, animate=animate, frames=frames)
    if save:
        result.save(out / "result.npz")
        written.append(out / "result.npz")
    seconds = {"simulate": simulated - started, "outputs": time.perf_counter() - simulated}
    _report(result, written, seconds)
    return result


def _demo(args) -> int:
    scene = Scene()
    print(f"ballc demo: the seed scene (c_tau {scene.c_tau}, mu {scene.friction_coefficient}, "
          f"mixture {scene.mixture}) for {args.t_end:g} s -> {args.out}/")
    result = _simulate_and_write(scene, args.t_end, Path(args.out), not args.no_animation,
                                 args.frames)
    return 0 if result.success else 1


def _run(args) -> int:
    from .scene import read_toml
    path = Path(args.scene)
    scene = Scene.from_toml(path)
    settings = read_toml(path).get("simulate", {})
    t_end = args.t_end if args.t_end is not None else settings.get("t_end", 5.0)
    out = Path(args.out) if args.out else Path(path.stem)
    print(f"ballc run {path} for {t_end:g} s -> {out}/")
    result = _simulate_and_write(scene, t_end, out, args.animate, args.frames, save=True)
    return 0 if result.success else 1


def _sweep(args) -> int:
    from .sweep import run_sweep_file
    return run_sweep_file(args.file, out=args.out, workers=args.workers,
                          scheduler=args.scheduler)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="ballc", description="ballc: a ball between two planes")
    commands = parser.add_subparsers(dest="command", required=True)

    demo = commands.add_parser("demo", help="the seed scene: figures, animation, contact table")
    demo.add_argument("--t-end", type=float, default=5.0, help="simulated time in s (default 5)")
    demo.add_argument("--out", default="ballc-demo", help="output folder (default ballc-demo)")
    demo.add_argument("--frames", type=int, default=DEMO_FRAMES,
                      help=f"animation frames (default {DEMO_FRAMES})")
    demo.add_argument("--no-animation", action="store_true", help="skip the GIF/MP4")
    demo.set_defaults(run=_demo)

    run = commands.add_parser("run", help="simulate a scene file (TOML)")
    run.add_argument("scene", help="scene file, e.g. examples/seed.toml")
    run.add_argument("--t-end", type=float, default=None,
                     help="simulated time in s (default: [simulate] t_end of the file, else 5)")
    run.add_argument("--out", default=None, help="output folder (default: the file's stem)")
    run.add_argument("--animate", action="store_true", help="also write the 3D animation")
    run.add_argument("--frames", type=int, default=DEMO_FRAMES, help="animation frames")
    run.set_defaults(run=_run)

    sweep = commands.add_parser("sweep", help="a parameter sweep from a TOML file")
    sweep.add_argument("file", help="sweep file, e.g. examples/sweep.toml")
    sweep.add_argument("--out", default=None, help="output folder (default: the file's stem)")
    sweep.add_argument("--workers", type=int, default=None,
                       help="local worker processes (default: the file's, else all cores)")
    sweep.add_argument("--scheduler", default=None,
                       help="Dask scheduler address (tcp://host:8786): run on that cluster")
    sweep.set_defaults(run=_sweep)

    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except (SceneError, FileNotFoundError) as error:
        print(f"ballc {args.command}: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
