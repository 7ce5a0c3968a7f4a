"""Long runs: what the seed scene costs for 10 .. 1e6 s of simulated time (issue 21, item 1).

    python -m benchmarks.long_runs [--t-ends 10 100 1000 1e6] [--method radau5]
                                   [--no-figures] [--scene seed|drop]

For each t_end: ``ballc.simulate(scene, t_end)`` with the default options (radau5,
rtol = atol = 1e-10, exact Coulomb friction, max_nfev = 2e7), timed in wall-clock and
CPU (time.process_time), with its status, the simulated time reached, the integrator
segments (calls of the driver's integrate_segment, counted by a wrapper), the steps of
the last segment, the right-hand-side calls, the samples, the contacts, and the median
step after the last contact started.  For the largest run, the figures
(``result.plot()``, ``plot_energy()``, ``plot_observer()``, ``plot_contacts()``, matplotlib
Agg, not saved) are timed too.  ``--scene drop``: a vertical drop without spin or
observer (the seed's materials), a ball that truly comes to rest, for the resting end
state.  Prints the table and writes it to docs/long_runs.md (``--out`` to change).
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

import ballc

SIM = sys.modules["ballc.simulate"]
DOCS = Path(__file__).resolve().parent.parent / "docs"


def drop_scene():
    """The seed's ball dropped vertically from 5 m, no spin, no observer: it bounces,
    stays in contact, and its normal oscillation dies out (it rests)."""
    return dataclasses.replace(ballc.Scene(), velocity=(0.0, 0.0, 0.0), observer_mass=0.0)


SCENES = {"seed": ballc.Scene, "drop": drop_scene}


class Segments:
    """Counts the driver's integrate_segment calls and the steps of the last one."""

    def __init__(self):
        self.inner = SIM.integrate_segment
        self.count, self.last_steps = 0, 0

    def __call__(self, *args, **options):
        sol = self.inner(*args, **options)
        self.count += 1
        self.last_steps = int(sol.get("nstep", len(sol["t"])) or len(sol["t"]))
        return sol

    def __enter__(self):
        SIM.integrate_segment = self
        return self

    def __exit__(self, *exc):
        SIM.integrate_segment = self.inner


def run(scene, t_end, method):
    with Segments() as segments:
        wall, cpu = time.perf_counter(), time.process_time()
        result = ballc.simulate(scene, t_end, method=method, progress=False)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    last = result.contacts[-1].t_start if result.contacts else 0.0
    late = np.diff(result.t[result.t >= last])
    return dict(t_end=t_end, status=result.status, reached=float(result.t[-1]), wall=wall,
                cpu=cpu, segments=segments.count, last_steps=segments.last_steps,
                nfev=result.nfev, samples=result.t.size, contacts=len(result.contacts),
                median_step=float(np.median(late)) if late.size else float("nan"),
                message=result.message.split(". ")[0]), result


def time_figures(result):
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
    return times


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--t-ends", type=float, nargs="+", default=[10, 100, 1000, 1e6])
    parser.add_argument("--method", default="radau5")
    parser.add_argument("--scene", choices=sorted(SCENES), default="seed")
    parser.add_argument("--no-figures", action="store_true")
    parser.add_argument("--out", type=Path, default=DOCS / "long_runs.md")
    args = parser.parse_args(argv)
    scene = SCENES[args.scene]()
    rows, largest = [], None
    for t_end in args.t_ends:
        row, result = run(scene, t_end, args.method)
        rows.append(row)
        largest = result
        print(row, flush=True)
    header = ("| t_end (s) | status | reached (s) | wall (s) | CPU (s) | segments | steps of "
              "last segment | RHS calls | samples | contacts | median step after last "
              "contact start (s) | message |")
    lines = [f"# Long runs ({args.scene} scene, {args.method}, default options)", "",
             f"Made by `python -m benchmarks.long_runs {' '.join(argv or sys.argv[1:])}`.", "",
             header, "|" + "---|" * (header.count("|") - 1)]
    for r in rows:
        lines.append(f"| {r['t_end']:g} | {r['status']} | {r['reached']:.6g} | {r['wall']:.3g} "
                     f"| {r['cpu']:.3g} | {r['segments']} | {r['last_steps']} | {r['nfev']} "
                     f"| {r['samples']} | {r['contacts']} | {r['median_step']:.4g} "
                     f"| {r['message']} |")
    if not args.no_figures and largest is not None:
        times = time_figures(largest)
        lines += ["", f"Figures of the largest run ({largest.t.size} samples), matplotlib Agg, "
                  "drawn, not saved:", "", "| figure | wall (s) |", "|---|---|"]
        lines += [f"| {name}() | {seconds:.3g} |" for name, seconds in times.items()]
        lines.append(f"| all | {sum(times.values()):.3g} |")
    text = "\n".join(lines) + "\n"
    print(text)
    args.out.write_text(text)


if __name__ == "__main__":
    main()
