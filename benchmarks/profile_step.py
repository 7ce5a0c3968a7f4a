"""Where a radau5 step goes: µs per accepted step, split into RHS, Jacobian,
factorisation, solves, events (their values after each step and their roots) and the
rest, on the seed scene.

    python -m benchmarks.profile_step [--build DIR] [--t-end 5] [--tol 1e-8 1e-10 1e-12]
                                      [--method radau5|dop853]

``--method dop853``: the same for ballc's explicit DOP853 (same loop; no Jacobian,
factorisation or solves: its step is 12 RHS calls and their combinations).

The split needs a build of ``ballc._core`` with the solver's timers compiled in
(``-DRADAU5_PROFILE``: time-stamp-counter reads around every right-hand side, Jacobian,
factorisation, solve and event check, see ``_integrator_private.h``, used by
``_integrator.c`` and ``_radau_iia.c``). ``--build DIR`` makes one in DIR (about a
minute; the normal build is not touched) and runs this script against it in a child
process; without ``--build`` the script uses whatever ``ballc`` it imports, and prints
only the uninstrumented figures when that build has no timers.

Printed per tolerance: accepted steps, RHS / Jacobian / LU calls per step, and CPU µs
per accepted step inside ``radau5_solve`` (thread CPU time of the instrumented run;
its timers add ~10 ns per timed call) split in proportion to the time-stamp-counter
ticks of each part (on a loaded machine a preemption falls on a part in proportion
to its length, so the shares stay fair), summed over the segments by the C loop
(``result._driver_counts``); then the CPU of the whole C loop (``ballc_drive``) and of
the simulate call (``time.process_time``, the Python layer included) per step.  The
steps are the segment log's (``result.segments``).  Best of ``--repeat`` runs.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PARTS = ("fun", "jac", "factor", "solve", "events")
LABELS = {"fun": "RHS", "jac": "Jacobian", "factor": "factor", "solve": "solves",
          "events": "events"}


def build_profiled(where: Path, quiet: bool = False) -> Path:
    """Build ballc with -DRADAU5_PROFILE into where/lib (a copy of the package);
    ``quiet``: the compiler's output only when the build fails."""
    lib, tmp = where / "lib", where / "tmp"
    env = dict(os.environ, CFLAGS=(os.environ.get("CFLAGS", "") + " -DRADAU5_PROFILE").strip())
    subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--build-lib", str(lib),
                    "--build-temp", str(tmp), "--force"], cwd=ROOT, env=env, check=True,
                   capture_output=quiet)
    for source in (ROOT / "src" / "ballc").glob("*.py"):
        shutil.copy2(source, lib / "ballc" / source.name)
    return lib


def measure(t_end, tol, repeat, method="radau5"):
    """The run's counts (its segment log's steps, the result's calls), and with a
    profiled build the C loop's integrator counters (``_driver_counts``); CPU of the
    simulate call.  Best of ``repeat``."""
    import ballc

    best = None
    for _ in range(repeat):
        started = time.process_time()
        result = ballc.simulate(ballc.Scene(), t_end, method=method, rtol=tol, atol=tol)
        cpu = time.process_time() - started
        segments = result.segments
        if segments is None:
            raise SystemExit("the run did not take the C loop: no segment log")
        counts = result._driver_counts
        totals = dict(nstep=int(segments["nstep"].sum()),
                      nreject=int(segments["nreject"].sum()), cpu=cpu,
                      profiled=bool(counts["profiled"]), drive_ns=counts["drive_ns"],
                      nfev=result.nfev, njev=result.njev, nlu=result.nlu,
                      **(counts["integrator_prof"] or dict.fromkeys(PARTS + ("total", "total_ns"),
                                                                    0.0)))
        key = totals["total_ns"] if totals["profiled"] else totals["cpu"]
        if best is None or key < best[0]:
            best = (key, totals)
    return best[1]


def report(t_end, tols, repeat, method="radau5"):
    import ballc
    print(f"build: {ballc.__file__}")
    print(f"scene: seed defaults, {t_end:g} s, rtol = atol = tol, method {method}, "
          f"best of {repeat}")
    header = (f"{'tol':>7s} {'steps':>6s} {'rej':>5s} {'RHS/st':>6s} {'Jac/st':>6s} {'LU/st':>6s} "
              f"{'us/step':>7s} " + " ".join(f"{LABELS[k]:>8s}" for k in PARTS)
              + f" {'rest':>8s} {'C loop':>8s} {'run':>8s}")
    print(header)
    for tol in tols:
        m = measure(t_end, tol, repeat, method)
        n = m["nstep"]
        line = (f"{tol:7.0e} {n:6d} {m['nreject']:5d} {m['nfev'] / n:6.2f} {m['njev'] / n:6.3f} "
                f"{m['nlu'] / n:6.3f} ")
        if m["profiled"]:
            us_per_tick = m["total_ns"] / m["total"] / 1e3
            parts = {k: m[k] * us_per_tick / n for k in PARTS}
            total = m["total"] * us_per_tick / n
            rest = total - sum(parts.values())
            line += f"{total:7.2f} " + " ".join(
                f"{parts[k]:4.2f} {100 * parts[k] / total:2.0f}%" for k in PARTS)
            line += f" {rest:4.2f} {100 * rest / total:2.0f}% {m['drive_ns'] / 1e3 / n:8.2f}"
        else:
            line += f"{'-':>7s} " + " ".join(f"{'-':>8s}" for _ in PARTS) + (
                f" {'-':>8s} {'-':>8s}")
        line += f" {1e6 * m['cpu'] / n:8.2f}"
        print(line, flush=True)
    print("us/step and the split: CPU inside radau5_solve (timers compiled in), summed over "
          "the segments; 'C loop': CPU of the whole segment loop in C (ballc_drive) / "
          "accepted steps; 'run': process time of the simulate call / accepted steps "
          "(the Python layer included)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", type=Path, help="build a profiling ballc in this directory "
                        "and run against it")
    parser.add_argument("--t-end", type=float, default=5.0)
    parser.add_argument("--tol", type=float, nargs="+", default=[1e-8, 1e-10, 1e-12])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--method", choices=("radau5", "dop853"), default="radau5")
    args = parser.parse_args(argv)
    if args.build is not None:
        lib = build_profiled(args.build.resolve())
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(lib), str(ROOT)]))
        command = [sys.executable, "-m", "benchmarks.profile_step", "--t-end", str(args.t_end),
                   "--repeat", str(args.repeat), "--method", args.method,
                   "--tol", *map(str, args.tol)]
        raise SystemExit(subprocess.run(command, cwd=ROOT, env=env).returncode)
    report(args.t_end, args.tol, args.repeat, args.method)


if __name__ == "__main__":
    main()
