"""How much of a run is Python around the C loop, for two builds measured in one run.

    python -m benchmarks.driver_share BEFORE_SRC AFTER_SRC [--rounds 5] [--runs 100]

BEFORE_SRC and AFTER_SRC are ``src`` directories of two checkouts with their extension
built in place (``python setup.py build_ext --inplace``), as for
``benchmarks.bit_identical``.  Each round starts one child process per build, in
alternating order; a child imports ballc from its ``src`` (and checks that it did), wraps
simulate's one call into the segment loop in C (``ballc._core.drive``) in a timer, and
times ``--runs`` runs of each case with ``time.perf_counter``, after a warm-up.  Per build
and case the round with the least total time is kept.  (A build whose run does not take
the C loop spends all of it in Python.)

Columns: the run's time (ms), the time inside ``_core.drive`` (the C loop with the
integrators, and its Cython bridge: the constants in, the run's buffers out), the rest
("Python": validation, the C loop's constants, the Result and its post-processing), the
Python share of the run, the segments per run (the segment log's, ``result.segments``)
and the Python per segment (µs).  Issue 29's target: a 1.2-s map throw with dop853 at
rtol 1e-3 in <= 0.3 ms of CPU.

Cases: the comeback map's throw (``ballc.Scene()``, 1.2 s, rtol = atol = 1e-3) with dop853
and radau5, and benchmarks.compliant_cost's "ratio 2/7, mu 1" compliant scene (5 s) with
dop853 at 1e-4 and 1e-6.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

CASES = {
    "map throw, dop853, 1e-3": ({}, 1.2, dict(method="dop853", rtol=1e-3, atol=1e-3)),
    "map throw, radau5, 1e-3": ({}, 1.2, dict(method="radau5", rtol=1e-3, atol=1e-3)),
    "compliant 2/7 mu 1, dop853, 1e-4": (
        dict(tangential_model="compliant", tangential_stiffness_ratio=2 / 7,
             friction_coefficient=1.0), 5.0, dict(method="dop853", rtol=1e-4, atol=1e-4)),
    "compliant 2/7 mu 1, dop853, 1e-6": (
        dict(tangential_model="compliant", tangential_stiffness_ratio=2 / 7,
             friction_coefficient=1.0), 5.0, dict(method="dop853", rtol=1e-6, atol=1e-6)),
}

CHILD = r"""
import json, sys, time
from pathlib import Path
src = Path(sys.argv[1]).resolve()
sys.path.insert(0, str(src))
import ballc
assert Path(ballc.__file__).resolve().parent == src / "ballc", (ballc.__file__, str(src))
seam = getattr(ballc._core, "drive", None)
inside = [0.0, 0]

def timed(*args, **kwargs):
    started = time.perf_counter()
    try:
        return seam(*args, **kwargs)
    finally:
        inside[0] += time.perf_counter() - started

def segments_of(result):
    log = getattr(result, "segments", None)
    if log is not None:
        return len(log)
    counts = getattr(result, "_driver_counts", None)
    return counts["segments"] if counts else float("nan")

if seam is not None:
    ballc._core.drive = timed
spec = json.loads(sys.argv[2])
out = {}
for name, (scene_kw, t_end, kw) in spec["cases"].items():
    scene = ballc.Scene(**scene_kw)
    for _ in range(max(spec["runs"] // 10, 3)):
        ballc.simulate(scene, t_end, progress=False, **kw)
    inside[:] = [0.0, 0]
    started = time.perf_counter()
    for _ in range(spec["runs"]):
        result = ballc.simulate(scene, t_end, progress=False, **kw)
    total = time.perf_counter() - started
    out[name] = dict(total=total / spec["runs"], inside=inside[0] / spec["runs"],
                     segments=segments_of(result), nfev=int(result.nfev),
                     status=int(result.status))
print(json.dumps(out))
"""


def measure(src: Path, runs: int) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    spec = json.dumps({"cases": CASES, "runs": runs})
    done = subprocess.run([sys.executable, "-c", CHILD, str(src), spec], check=True,
                          env=env, capture_output=True, text=True)
    return json.loads(done.stdout)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path, help="src/ of the first build")
    parser.add_argument("after", type=Path, help="src/ of the second build")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--runs", type=int, default=100)
    args = parser.parse_args(argv)
    builds = {"before": args.before.resolve(), "after": args.after.resolve()}
    best: dict[tuple[str, str], dict] = {}
    for k in range(args.rounds):
        order = list(builds) if k % 2 == 0 else list(builds)[::-1]
        for build in order:
            for name, row in measure(builds[build], args.runs).items():
                kept = best.get((build, name))
                if kept is None or row["total"] < kept["total"]:
                    best[(build, name)] = row
        print(f"  round {k + 1}/{args.rounds} done", file=sys.stderr)
    print(f"before: {builds['before']}\nafter:  {builds['after']}\n")
    print("| case | build | run ms | C loop + bridge ms | Python ms | Python share | "
          "segments | Python µs/segment | RHS calls | status |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in CASES:
        for build in builds:
            r = best[(build, name)]
            driver = r["total"] - r["inside"]
            print(f"| {name} | {build} | {1e3 * r['total']:.3f} | {1e3 * r['inside']:.3f} | "
                  f"{1e3 * driver:.3f} | {driver / r['total']:.0%} | {r['segments']:.0f} | "
                  f"{1e6 * driver / r['segments']:.1f} | {r['nfev']} | {r['status']} |")
        ratio = best[("after", name)]["total"] / best[("before", name)]["total"]
        print(f"| {name} | after/before | {ratio:.2f} | | | | | | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
