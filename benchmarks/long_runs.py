"""Long runs: what the seed scene costs for 10 .. 1e9 s of simulated time (issue 21, item 1).

    python -m benchmarks.long_runs [--t-ends 10 100 1000 1e6 1e9] [--method radau5]
                                   [--no-figures] [--scenes seed rolling drop] [--out FILE]

For each t_end: ``ballc.simulate(scene, t_end)`` with the default options (radau5,
rtol = atol = 1e-10, exact Coulomb friction, max_nfev = 2e7), timed in wall-clock and
CPU (time.process_time) as users run it, with its status, the simulated time reached,
the integrator segments and the steps of the last one (the C loop's segment log,
``result.segments``), the right-hand-side calls, the samples, the contacts, and the median
step after the last contact started.  For the largest run, the figures
(``result.plot()``, ``plot_energy()``, ``plot_observer()``, ``plot_contacts()``, matplotlib
Agg, not saved) and the animation (GIF) are timed too.  ``--scene drop``: a vertical
drop without spin or observer (the seed's materials), a ball that truly comes to rest; ``rolling``: the
seed's throw without its observer, which rolls uniformly (closed form in ballc.resting); the seed scene
itself ends rolling with its observer's wobble (the orbit of ballc.orbit).  Each scene is run
with ``rest=True`` (the default: the resting end state of ballc.resting) and with
``rest=False`` (the integrator all the way, what the build before ballc.resting did;
the first 5 s are bit-identical either way), in the same process.  Prints the tables
and writes them to docs/long_runs.md (``--out`` to change).
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

import numpy as np

import ballc
from ballc.messages import SUCCESS

DOCS = Path(__file__).resolve().parent.parent / "docs"


def drop_scene():
    """The seed's ball dropped vertically from 5 m, no spin, no observer: it bounces,
    stays in contact, and its normal oscillation dies out (it rests)."""
    return dataclasses.replace(ballc.Scene(), velocity=(0.0, 0.0, 0.0), observer_mass=0.0)


def rolling_scene():
    """The seed's throw without its observer: it rolls uniformly from t ~ 31 s."""
    return ballc.Scene().replace(observer_mass=0.0)


SCENES = {"seed": ballc.Scene, "drop": drop_scene, "rolling": rolling_scene}


def run(scene, t_end, method, rest):
    """The run timed as users make it, with the counts of its segment log."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = ballc.simulate(scene, t_end, method=method, progress=False, rest=rest)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    log = result.segments   # the C loop's own account
    last = result.contacts[-1].t_start if result.contacts else 0.0
    late = np.diff(result.t[result.t >= last])
    return dict(t_end=t_end, status=result.status, reached=float(result.t[-1]), wall=wall,
                cpu=cpu, segments=len(log), last_steps=int(log["nstep"][-1]),
                nfev=result.nfev, samples=result.t.size, contacts=len(result.contacts),
                median_step=float(np.median(late)) if late.size else float("nan"),
                message=result.message.replace(SUCCESS, "t_end reached.").replace(
                    "|", "/")), result


def time_figures(result):
    """Wall time (s) of each figure (drawn, not saved) and of the animation (the default
    100 frames, written as a GIF to a temporary folder)."""
    import tempfile

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    times = {}
    for name in ("plot", "plot_energy", "plot_observer", "plot_contacts"):
        started = time.perf_counter()
        fig, _ = getattr(result, name)()
        fig.canvas.draw()
        times[name] = time.perf_counter() - started
        plt.close(fig)
    with tempfile.TemporaryDirectory() as folder:
        started = time.perf_counter()
        animation = result.animate(Path(folder) / "run.gif")
        times["animate"] = time.perf_counter() - started
        plt.close(animation._fig)
    return times


HEADER = ("| t_end (s) | rest | status | reached (s) | wall (s) | CPU (s) | segments | "
          "steps of last segment | RHS calls | samples | contacts | median step after last "
          "contact start (s) | message |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-ends", type=float, nargs="+", default=[10, 100, 1000, 1e6, 1e9])
    parser.add_argument("--method", default="radau5")
    parser.add_argument("--scenes", choices=sorted(SCENES), nargs="+", default=["seed", "rolling", "drop"])
    parser.add_argument("--no-figures", action="store_true")
    parser.add_argument("--out", type=Path, default=DOCS / "long_runs.md")
    args = parser.parse_args(argv)
    command = " ".join(sys.argv[1:] if argv is None else argv)
    lines = ["# Long runs", "",
             f"Made by `{('python -m benchmarks.long_runs ' + command).strip()}`.  What the numbers "
             "mean: docs/limits.md, \"Long runs\".  Load average at the start: "
             f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs (the wall times grow with it; "
             "compare the CPU columns).", ""]
    largest = None
    for name in args.scenes:
        scene = SCENES[name]()
        lines += [f"## The {name} scene ({args.method}, default options)", "", HEADER,
                  "|" + "---|" * (HEADER.count("|") - 1)]
        for t_end in args.t_ends:
            for rest in (True, False):
                r, result = run(scene, t_end, args.method, rest)
                print(name, rest, r, flush=True)
                if largest is None or result.t.size > largest.t.size:
                    largest = result
                lines.append(
                    f"| {r['t_end']:g} | {rest} | {r['status']} | {r['reached']:.6g} "
                    f"| {r['wall']:.3g} | {r['cpu']:.3g} "
                    f"| {r['segments']} | {r['last_steps']} "
                    f"| {r['nfev']} | {r['samples']} | {r['contacts']} | {r['median_step']:.4g} "
                    f"| {r['message']} |")
        lines.append("")
    if not args.no_figures and largest is not None:
        times = time_figures(largest)
        figures = {name: s for name, s in times.items() if name != "animate"}
        lines += [f"Figures of the run with the most samples ({largest.t.size}), matplotlib "
                  "Agg, drawn, not saved (each line decimated for drawing to at most "
                  "ballc.plot.MAX_POINTS points, a min/max envelope; the Result keeps every "
                  "sample), and its animation (100 frames, GIF):", "",
                  "| figure | wall (s) |", "|---|---|"]
        lines += [f"| {name}() | {seconds:.3g} |" for name, seconds in figures.items()]
        lines.append(f"| all figures | {sum(figures.values()):.3g} |")
        lines.append(f"| animate() | {times['animate']:.3g} |")
    text = "\n".join(lines) + "\n"
    print(text)
    args.out.write_text(text)


if __name__ == "__main__":
    main()
