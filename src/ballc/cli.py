"""Console entry points: ``ballc demo``, ``ballc run scene.toml``, ``ballc sweep sweep.toml``.

``ballc demo``   the seed scene: figures, 3D animation, contact table (CSV), summary.
``ballc run``    the same for a scene file (see ``Scene.from_toml``), plus the result (.npz).
``ballc sweep``  a parameter sweep from a TOML file (see ``ballc.sweep.load_sweep_file``):
                 a CSV table and, for two parameters, a heat map of "came back".

Every option, the scene file and the output folder are checked before anything is
simulated or written.  An expected error (invalid scene or option, unreadable file,
output folder that cannot be made) is one line on stderr and exit code 2.  When the
reader of the output goes away (``ballc run ... | head``) the command ends quietly with
exit code 141 (128 + SIGPIPE, what a shell reports for a program ended by a broken pipe).
Ctrl-C (SIGINT) ends a command with one line on stderr and exit code 130 (128 +
SIGINT): ``ballc sweep`` writes the rows of the runs that had finished; ``ballc run`` and
``ballc demo`` keep the files written so far, and remove the output folder again if
they made it and nothing had been written into it (a run interrupted is lost: there is
no partial Result to write).
"""
from __future__ import annotations

import argparse
import contextlib
import inspect
import os
import sys
import tempfile
import time
from pathlib import Path

from .outcome import format_summary
from .scene import Scene, SceneError, read_toml, reject_unknown_keys

DEMO_FRAMES = 100
#: Simulated time (s) when neither --t-end nor the scene file's [simulate] t_end says.
DEFAULT_T_END = 5.0
#: Default parent of ``ballc run`` / ``ballc sweep`` outputs: <this>/<file stem>/.
OUTPUT_ROOT = "ballc-output"
#: Keys of a scene file's [simulate] table; all but t_end are passed to ballc.simulate.
SIMULATE_KEYS = ("t_end", "rtol", "atol", "method", "exact_flight")
#: Those of them that are ballc.simulate options.
SIMULATE_OPTIONS = SIMULATE_KEYS[1:]


class CommandError(Exception):
    """An expected failure of a command (bad path, output folder): one line, exit 2."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C, with what the command leaves behind (its one line on stderr)."""


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (and exit code 2, as argparse's)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def version() -> str:
    """The installed distribution's version, else ``ballc.__version__``."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as distribution_version
    try:
        return distribution_version("ballc")
    except PackageNotFoundError:
        from . import __version__
        return __version__


def _frames(text: str) -> int:
    """argparse type of --frames: a whole number >= 1 (animate's own check)."""
    from .animate import check_frames
    try:
        return check_frames(int(text))
    except ValueError as error:
        message = str(error) if "frames =" in str(error) else \
            f"frames = {text!r} is not allowed: must be a whole number >= 1"
        raise argparse.ArgumentTypeError(message) from None


def _workers(text: str) -> int:
    """argparse type of --workers: ballc.sweep's own rule (a whole number >= 1)."""
    from .sweep import check_workers
    try:
        return check_workers(int(text))
    except (ValueError, SceneError):
        raise argparse.ArgumentTypeError(f"workers = {text!r} is not allowed: must be a "
                                         "whole number >= 1") from None


def write_outputs(result, out: Path, *, animate: bool, frames: int,
                  html: bool = False, t_window=None) -> list[Path]:
    """Figures (PNG; a scene given its planes, not the ceiling_height shorthand, also
    side_view.png), contact table (CSV) and optionally the animation (GIF, + MP4 with
    ffmpeg) and the interactive 3-D view (view.html) of ``result`` into ``out``; returns
    the paths written.  ``t_window``: the figures' time window (ballc.plot)."""
    import matplotlib
    matplotlib.use("Agg")            # files only: never open a window
    import matplotlib.pyplot as plt

    from .animate import animate as make_animation
    from .animate import check_frames, has_ffmpeg

    if animate:
        frames = check_frames(frames)     # before any file is written
    if t_window is not None and t_window[0] > result.t[-1]:
        # checked against [0, t_end] before the run, which then stopped early
        print(f"note: --t-window starts at {t_window[0]:g} s, after the run stopped at "
              f"{result.t[-1]:g} s: the figures show the whole run", file=sys.stderr)
        t_window = None
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    figures = (("coordinates.png", result.plot), ("energy.png", result.plot_energy),
               ("contacts_top_view.png", result.plot_contacts),
               ("observer.png", result.plot_observer))
    if result.scene.ceiling_height is None:   # planes at any orientation: where they are
        figures += (("side_view.png", result.plot_side_view),)
    for name, make in figures:
        fig, _ = make(t_window=t_window)
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        written.append(out / name)
    result.contacts_csv(out / "contacts.csv")
    written.append(out / "contacts.csv")
    if animate:
        names = ["animation.gif"] + (["animation.mp4"] if has_ffmpeg() else [])
        for name in names:
            animation = make_animation(result, out / name, frames=frames)
            plt.close(animation._fig)
            written.append(out / name)
    if html:
        result.to_html(out / "view.html")
        written.append(out / "view.html")
    return written


def _check_html(wanted: bool) -> None:
    """--html needs meshcat: say so before anything is simulated."""
    if wanted:
        from .html_view import _import_meshcat
        try:
            _import_meshcat()
        except ImportError as error:
            raise CommandError(f"--html: {error}") from None


# --- checks made before anything is simulated or written ---

def _scene_file(text: str) -> Path:
    """The path of an existing, regular input file."""
    path = Path(text)
    if not path.exists():
        raise CommandError(f"{path}: no such file")
    if path.is_dir():
        raise CommandError(f"{path}: is a folder, not a TOML file")
    return path


def _output_folder(out: Path) -> Path:
    """Make ``out`` (and its parents) and check that a file can be written into it."""
    if out.exists() and not out.is_dir():
        raise CommandError(f"--out {out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise CommandError(f"--out {out}: cannot create the folder "
                           f"({error.strerror or error})") from None
    try:
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as error:
        raise CommandError(f"--out {out}: cannot write into the folder "
                           f"({error.strerror or error})") from None
    return out


@contextlib.contextmanager
def _output(out: Path):
    """``_output_folder(out)`` for the body of a command.  If the command fails or is
    interrupted with nothing written into a folder it made, the folder is removed again
    (no empty folder is left behind); on Ctrl-C, an :class:`Interrupted` says what is
    left."""
    made = not out.exists()
    out = _output_folder(out)
    try:
        yield out
    except BaseException as error:
        try:
            empty = not any(out.iterdir())
            if made and empty:
                out.rmdir()
        except OSError:
            empty = False
        if isinstance(error, KeyboardInterrupt):
            done = str(error) or "interrupted (Ctrl-C)"
            left = ((f"nothing was written (the folder {out}/ it had made is removed)"
                     if made else f"nothing was written into {out}/") if empty
                    else f"the files written so far are in {out}/")
            raise Interrupted(f"{done}; {left}") from None
        raise


def _simulate_options(scene, t_end, options: dict):
    """(t_end, options for ballc.simulate) checked by ballc.simulate's own validation;
    options not given take simulate's defaults."""
    from .options import check_options
    from .simulate import simulate
    defaults = {name: parameter.default
                for name, parameter in inspect.signature(simulate).parameters.items()
                if name in SIMULATE_OPTIONS}
    given = {name: value for name, value in options.items() if value is not None}
    t_end = check_options(scene, t_end, **{**defaults, **given}).t_end
    return t_end, given


def simulate_table(path, scene=None) -> dict:
    """A scene file's ``[simulate]`` table (SIMULATE_KEYS), validated: unknown keys fail
    with a "did you mean", values by ``ballc.simulate``'s own checks."""
    data = read_toml(path)
    settings = data.get("simulate", {})
    if not isinstance(settings, dict):
        raise SceneError(f"{path}: simulate = {settings!r} is not allowed: must be a "
                         f"[simulate] table with the keys {', '.join(SIMULATE_KEYS)}")
    try:
        reject_unknown_keys(settings, SIMULATE_KEYS, "key",
                            ", ".join(SIMULATE_KEYS))
        _simulate_options(scene or Scene(), settings.get("t_end", DEFAULT_T_END),
                          {k: v for k, v in settings.items() if k != "t_end"})
    except SceneError as error:
        raise SceneError(f"{path}: [simulate]: {error}") from None
    return dict(settings)


# --- the commands ---

def _report(result, written, seconds, animate) -> None:
    print(format_summary(result))
    print()
    print(result.contact_table())
    print()
    print("wrote " + ", ".join(str(p) for p in written))
    outputs = "figures, files and animation" if animate else "figures and files"
    print(f"[{seconds['simulate']:.2f} s simulation, {seconds['outputs']:.2f} s {outputs}]")


def _simulate_and_write(scene, t_end, options, out, animate, frames, save=False, html=False,
                        t_window=None):
    from .simulate import simulate
    started = time.perf_counter()
    result = simulate(scene, t_end, **options)
    simulated = time.perf_counter()
    written = write_outputs(result, out, animate=animate, frames=frames, html=html,
                            t_window=t_window)
    if save:
        result.save(out / "result.npz")
        written.append(out / "result.npz")
    seconds = {"simulate": simulated - started, "outputs": time.perf_counter() - simulated}
    _report(result, written, seconds, animate)
    return result


def _t_window(args, t_end):
    """--t-window checked against the run's [0, t_end] before anything is simulated."""
    if args.t_window is None:
        return None
    from .plot import check_t_window
    try:
        return check_t_window(tuple(args.t_window), 0.0, t_end)
    except ValueError as error:
        raise CommandError(f"--t-window: {error}") from None


def _demo(args) -> int:
    scene = Scene()
    t_end, options = _simulate_options(scene, args.t_end, {})
    t_window = _t_window(args, t_end)
    _check_html(args.html)
    with _output(Path(args.out)) as out:
        print(f"ballc demo: the seed scene (c_tau {scene.c_tau}, mu "
              f"{scene.friction_coefficient}, mixture {scene.mixture}) for {t_end:g} s -> "
              f"{out}/", flush=True)
        result = _simulate_and_write(scene, t_end, options, out, not args.no_animation,
                                     args.frames, html=args.html, t_window=t_window)
    return 0 if result.success else 1


def _run(args) -> int:
    path = _scene_file(args.scene)
    scene = Scene.from_toml(path)
    settings = simulate_table(path, scene)
    t_end = args.t_end if args.t_end is not None else settings.get("t_end", DEFAULT_T_END)
    overrides = {"rtol": args.rtol, "atol": args.atol, "method": args.method,
                 "exact_flight": False if args.no_exact_flight else None}
    options = {name: settings.get(name) for name in SIMULATE_OPTIONS}
    options.update({k: v for k, v in overrides.items() if v is not None})
    t_end, options = _simulate_options(scene, t_end, options)
    t_window = _t_window(args, t_end)
    _check_html(args.html)
    described = "".join(f", {k} {v}" for k, v in options.items())
    with _output(Path(args.out) if args.out else Path(OUTPUT_ROOT) / path.stem) as out:
        print(f"ballc run {path} for {t_end:g} s{described} -> {out}/", flush=True)
        result = _simulate_and_write(scene, t_end, options, out, args.animate, args.frames,
                                     save=True, html=args.html, t_window=t_window)
    return 0 if result.success else 1


def _sweep(args) -> int:
    from .sweep import connect, load_sweep_file, run_sweep_file
    path = _scene_file(args.file)
    load_sweep_file(path)             # all its errors before the output folder is made
    # a scheduler that does not answer: said before the output folder is made
    client = connect(args.scheduler, "--scheduler") if args.scheduler is not None else None
    try:
        with _output(Path(args.out) if args.out else Path(OUTPUT_ROOT) / path.stem) as out:
            return run_sweep_file(path, out=out, workers=args.workers, scheduler=client)
    finally:
        if client is not None:
            client.close()


#: --t-window T0 T1: the figures' time window (the same option on run and demo).
T_WINDOW = ("--t-window",)
T_WINDOW_OPTIONS = dict(
    nargs=2, type=float, metavar=("T0", "T1"), default=None,
    help="draw the figures from T0 to T1 s (default: the whole run, or for a run that "
         "ends in closed form -- at rest, rolling -- up to its start plus a margin)")

#: Options that take a number: "--rtol -1e-6" is joined into "--rtol=-1e-6", since
#: argparse takes "-1e-6" for an option (it knows only negative numbers like -1, -0.5).
NUMBER_OPTIONS = ("--t-end", "--rtol", "--atol", "--frames", "--workers")
#: Exit code when stdout's reader went away (a broken pipe): 128 + SIGPIPE.
BROKEN_PIPE = 141
#: Exit code of a command ended by Ctrl-C: 128 + SIGINT, as a shell reports it.
INTERRUPTED = 130


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def join_negative_numbers(argv: list) -> list:
    """``argv`` with every NUMBER_OPTIONS option followed by a negative number (-1e-6,
    -inf) written as one "--option=value" argument, so that ballc's own check rejects
    the value (naming it and what is allowed) instead of argparse the option."""
    joined, i = [], 0
    while i < len(argv):
        arg = argv[i]
        if (arg in NUMBER_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-")
                and _is_number(argv[i + 1])):
            joined.append(f"{arg}={argv[i + 1]}")
            i += 2
        else:
            joined.append(arg)
            i += 1
    return joined


def _quiet_stdout() -> None:
    """After a broken pipe: send what is left of stdout to /dev/null, so that Python's
    own flush at exit does not report the broken pipe again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


def _one_line(error: BaseException) -> str:
    if isinstance(error, OSError) and error.filename and error.strerror:
        text = f"{error.filename}: {error.strerror}"
    else:
        text = str(error)
    return " ".join(text.split())


def main(argv=None) -> int:
    parser = _Parser(prog="ballc", description="ballc: a ball between two planes")
    parser.add_argument("--version", action="version", version=f"ballc {version()}")
    commands = parser.add_subparsers(dest="command", required=True)

    demo = commands.add_parser("demo", help="the seed scene: figures, animation, contact table")
    demo.add_argument("--t-end", type=float, default=DEFAULT_T_END,
                      help=f"simulated time in s (default {DEFAULT_T_END:g})")
    demo.add_argument("--out", default="ballc-demo", help="output folder (default ballc-demo)")
    demo.add_argument("--frames", type=_frames, default=DEMO_FRAMES,
                      help=f"animation frames, >= 1 (default {DEMO_FRAMES})")
    demo.add_argument("--no-animation", action="store_true", help="skip the GIF/MP4")
    demo.add_argument("--html", action="store_true",
                      help="also write view.html, an interactive 3-D view (needs meshcat)")
    demo.add_argument(*T_WINDOW, **T_WINDOW_OPTIONS)
    demo.set_defaults(run=_demo)

    run = commands.add_parser("run", help="simulate a scene file (TOML)")
    run.add_argument("scene", help="scene file, e.g. examples/seed.toml")
    run.add_argument("--t-end", type=float, default=None,
                     help=f"simulated time in s (default: [simulate] t_end of the file, "
                          f"else {DEFAULT_T_END:g})")
    run.add_argument("--rtol", type=float, default=None,
                     help="relative tolerance (default: [simulate] rtol, else simulate's)")
    run.add_argument("--atol", type=float, default=None,
                     help="absolute tolerance (default: [simulate] atol, else simulate's)")
    run.add_argument("--method", default=None,
                     help="integrator: radau5, dop853 (explicit, order 8: several times "
                          "faster at tight tolerances on scenes that are not stiff), auto "
                          "(dop853, switching to radau5 where the scene turns stiff) or a "
                          "solve_ivp method (default: [simulate] method, else radau5)")
    run.add_argument("--no-exact-flight", action="store_true",
                     help="integrate free flight even where it has a closed form (default: "
                          "[simulate] exact_flight, else closed form where exact)")
    run.add_argument("--out", default=None,
                     help=f"output folder (default: {OUTPUT_ROOT}/<the file's stem>)")
    run.add_argument("--animate", action="store_true", help="also write the 3D animation")
    run.add_argument("--html", action="store_true",
                     help="also write view.html, an interactive 3-D view (needs meshcat)")
    run.add_argument("--frames", type=_frames, default=DEMO_FRAMES,
                     help=f"animation frames, >= 1 (default {DEMO_FRAMES})")
    run.add_argument(*T_WINDOW, **T_WINDOW_OPTIONS)
    run.set_defaults(run=_run)

    sweep = commands.add_parser("sweep", help="a parameter sweep from a TOML file")
    sweep.add_argument("file", help="sweep file, e.g. examples/sweep.toml")
    sweep.add_argument("--out", default=None,
                       help=f"output folder (default: {OUTPUT_ROOT}/<the file's stem>)")
    sweep.add_argument("--workers", type=_workers, default=None,
                       help="local worker processes (default: the file's, else all cores)")
    sweep.add_argument("--scheduler", default=None,
                       help="Dask scheduler address (tcp://host:8786): run on that cluster")
    sweep.set_defaults(run=_sweep)

    args = parser.parse_args(join_negative_numbers(sys.argv[1:] if argv is None else list(argv)))
    try:
        try:
            return args.run(args)
        finally:
            sys.stdout.flush()      # a broken pipe shows here at the latest
    except BrokenPipeError:
        _quiet_stdout()
        return BROKEN_PIPE
    except KeyboardInterrupt as error:
        # Ctrl-C: one line (what is left is in it, see _output), no traceback
        sys.stderr.write("\n" if sys.stderr.isatty() else "")   # after a progress bar
        print(f"ballc {args.command}: {str(error) or 'interrupted (Ctrl-C)'}", file=sys.stderr)
        return INTERRUPTED
    except (CommandError, SceneError, OSError, ValueError) as error:
        # expected: invalid input or an unusable path.  Anything else is a bug: traceback.
        print(f"ballc {args.command}: error: {_one_line(error)}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
