"""radau5 against SUNDIALS CVODE, both driven from C: no Python per call.

    python -m benchmarks.cvode_c [--quick] [--repeat N] [--out DIR]

benchmarks/peers.py drives CVODE through scikit-sundae's Python callbacks and subtracts
an estimate of their cost.  Here the same replay runs in C: the seed scene's segments
are recorded as in peers.py (``record_segments``, ``replayable``), written to a text
file, and a small C program (benchmarks/cvode_harness.c) integrates every segment
from its recorded start state to its recorded end time with

- ``radau5``: ballc's ``radau5_solve`` (src/ballc/_radau5_solver.c), set up as
  ``ballc._radau5.solve_system`` sets it up (scipy's step control, every step stored);
- ``CVODE BDF`` and ``CVODE Adams``: SUNDIALS CVODE (defaults: Newton iteration, dense
  direct linear solver, maximum order 5 / 12), ballc's analytic Jacobian (transposed
  into SUNDIALS' column-major matrix), ``CVodeSetStopTime`` at the segment's end;

on ballc's compiled right-hand side and Jacobian (``ballc_rhs_checked_inputs`` /
``ballc_jacobian_checked_inputs``, parameters prepared once per segment), at
rtol = atol = tol.  The CPU of a pass over all segments is measured in C
(``clock_gettime(CLOCK_PROCESS_CPUTIME_ID)``), best of ``--repeat`` (20) rounds over all
tolerances, the contenders taking turns in a rotated order.  The harness is compiled here,
in a temporary directory, with the system C compiler and setup.py's flags, from ballc's
own C sources;
SUNDIALS is the build bundled in the scikit-sundae wheel (``scikit_sundae.libs``), linked
by full path (no headers needed: the harness declares the prototypes it uses).

The errors (err6, err6 over the regular segments, err12) and the equal-error ratio are
those of peers.py (``errors``, ``near_singular``, ``equal_error_ratios``).

Writes docs/cvode_c.md.
"""
from __future__ import annotations

import argparse
import ast
import os
import platform
import re
import shlex
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

import numpy as np

import ballc
from ballc import _core
from benchmarks import peers

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
HARNESS = Path(__file__).resolve().parent / "cvode_harness.c"


def _core_extension():
    """The keywords of setup.py's ``Extension("ballc._core", ...)`` (literals only), read
    from its source so that the harness is compiled from the same C files, include
    directories and flags as ``_core`` without repeating them here."""
    for node in ast.walk(ast.parse((ROOT / "setup.py").read_text())):
        if (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Extension"
                and node.args and ast.literal_eval(node.args[0]) == "ballc._core"):
            return {k.arg: ast.literal_eval(k.value) for k in node.keywords
                    if k.arg in ("sources", "include_dirs", "extra_compile_args")}
    raise RuntimeError("setup.py has no Extension('ballc._core', ...)")


_CORE = _core_extension()
#: ballc's C sources (the extension's, without its Cython bridge), include directories
#: and flags, as setup.py builds ``_core``
C_SOURCES = [ROOT / s for s in _CORE["sources"] if s.endswith(".c")]
INCLUDE_DIRS = [ROOT / d for d in _CORE["include_dirs"]]
CFLAGS = list(_CORE["extra_compile_args"])
SUNDIALS_LIBS = ("sundials_core", "sundials_nvecserial", "sundials_sunmatrixdense",
                 "sundials_sunlinsoldense", "sundials_cvode")
#: the harness's names -> peers.py's
CONTENDERS = {"radau5": "radau5", "cvode_bdf": "CVODE BDF", "cvode_adams": "CVODE Adams"}
#: peers.py's 1e-3 .. 1e-14, and 1e-15: CVODE is 100-1000x less accurate than radau5 at
#: equal tolerance here and needs 1e-13 .. 1e-15 to reach radau5's errors at 1e-9, 1e-10
#: (radau5 runs down to 100 machine epsilons, ballc's limit)
TOLERANCES = peers.TOLERANCES + (1e-15,)
QUICK_TOLERANCES = peers.QUICK_TOLERANCES
#: best of REPEAT passes: a pass lasts 2-120 ms, and on the shared 2-core machine best of 5
#: was seen to swing by up to a third at single tolerances between runs (best of 20: a few %)
REPEAT = 20
#: radau5's tolerances of the summary range
RATIO_RANGE = (1e-3, 1e-10)
#: the summary's range over all segments leaves out the radau5 tolerances where
#: radau5's err6 over all segments is above this (the near-singular segments diverged)
DIVERGED = 1e-3


class Unavailable(RuntimeError):
    """No SUNDIALS libraries or no C compiler: the benchmark cannot run here."""


def sundials_dir():
    """The directory of the SUNDIALS libraries bundled with scikit-sundae."""
    site = Path(sysconfig.get_paths()["platlib"])
    libs = site / "scikit_sundae.libs"
    if not libs.is_dir():
        raise Unavailable(f"no {libs} (scikit-sundae's bundled SUNDIALS): "
                          'pip install ".[bench]"')
    return libs


def sundials_libraries(libs=None):
    """{name: path} of the SUNDIALS shared libraries the harness links."""
    libs = sundials_dir() if libs is None else libs
    found = {}
    for name in SUNDIALS_LIBS:
        candidates = sorted(libs.glob(f"lib{name}-*.so*")) or sorted(libs.glob(f"lib{name}.so*"))
        if not candidates:
            raise Unavailable(f"no lib{name} in {libs}")
        found[name] = candidates[0]
    return found


def sundials_version_from_name(path):
    """'7.9.0' from 'libsundials_cvode-cf29dc23.so.7.9.0'."""
    match = re.search(r"\.so\.(\d+(?:\.\d+)*)$", Path(path).name)
    return match.group(1) if match else "?"


def compiler():
    cc = os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc"
    cc = shlex.split(cc)
    if not cc or subprocess.run(["sh", "-c", f"command -v {shlex.quote(cc[0])}"],
                                capture_output=True).returncode != 0:
        raise Unavailable(f"no C compiler ({' '.join(cc) or 'CC'})")
    return cc


def build_harness(where: Path) -> Path:
    """Compile benchmarks/cvode_harness.c with ballc's C sources into where/; the
    compiler's output is shown and a failure raises CalledProcessError."""
    libs = sundials_libraries()
    exe = where / "cvode_harness"
    command = (compiler() + CFLAGS + [f"-I{d}" for d in INCLUDE_DIRS]
               + ["-o", str(exe), str(HARNESS)] + [str(s) for s in C_SOURCES]
               + [str(p) for p in libs.values()]
               + [f"-Wl,-rpath,{sundials_dir()}", "-lm"])
    done = subprocess.run(command, capture_output=True, text=True)
    if done.stdout or done.stderr or done.returncode:
        print(" ".join(command), file=sys.stderr)
        print(done.stdout + done.stderr, file=sys.stderr, end="")
    done.check_returncode()
    return exe


# ---- the segment file ----

def write_segments(segments, path: Path):
    """The harness's input: a header line, then per segment: flags, t0, t1, params,
    latch, y0 (repr of each float: exact round trip through strtod)."""
    lines = [f"{_core.N_STATES} {_core.N_PARAMETERS} {_core.N_LATCH} {len(segments)}"]
    for s in segments:
        numbers = [s.t0, s.t1, *s.params, *s.latch, *s.y0]
        lines.append(f"{int(s.flags)} " + " ".join(repr(float(x)) for x in numbers))
    path.write_text("\n".join(lines) + "\n")


def read_segments(path: Path):
    """(flags, t0, t1, params, latch, y0) per segment, as written by write_segments
    (for the tests: what the harness reads)."""
    lines = path.read_text().splitlines()
    ns, np_, nl, m = (int(v) for v in lines[0].split())
    out = []
    for line in lines[1:1 + m]:
        fields = line.split()
        values = np.array([float(v) for v in fields[1:]])
        assert values.size == 2 + np_ + nl + ns
        out.append((int(fields[0]), values[0], values[1], values[2:2 + np_],
                    values[2 + np_:2 + np_ + nl], values[2 + np_ + nl:]))
    return out


# ---- running it ----

def parse_output(text, n_segments):
    """{"sundials": version, "runs": {(contender, tol): {...}}} from the harness's
    output; each run has cpu, nfev, njev, nstep, nlu, failed, y_end (segments x
    N_STATES) and fails ({segment: code})."""
    runs, version = {}, "?"
    for line in text.splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "sundials":
            version = f[1]
        elif f[0] == "run":
            runs[(CONTENDERS[f[1]], float(f[2]))] = {
                "cpu": float(f[3]), "nfev": int(f[4]), "njev": int(f[5]), "nstep": int(f[6]),
                "nlu": int(f[7]), "failed": int(f[8]),
                "y_end": np.full((n_segments, _core.N_STATES), np.nan), "fails": {}}
        elif f[0] == "end":
            runs[(CONTENDERS[f[1]], float(f[2]))]["y_end"][int(f[3])] = [float(v) for v in f[4:]]
        elif f[0] == "fail":
            runs[(CONTENDERS[f[1]], float(f[2]))]["fails"][int(f[3])] = int(f[4])
    return {"sundials": version, "runs": runs}


def run_harness(exe, segments, tolerances, repeat, where: Path):
    seg_file = where / "segments.txt"
    write_segments(segments, seg_file)
    done = subprocess.run([str(exe), str(seg_file), str(repeat)]
                          + [repr(float(t)) for t in tolerances],
                          capture_output=True, text=True)
    if done.stderr:
        print(done.stderr, file=sys.stderr, end="")
    if done.returncode != 0:
        raise RuntimeError(f"cvode_harness exited with {done.returncode}")
    return parse_output(done.stdout, len(segments))


def rows_from_runs(runs, segments):
    """peers.py's rows: {(contender, tol): {cpu, err6, err6_regular, err12, nfev, njev,
    nstep, nlu, failed}}."""
    rows = {}
    regular = [not peers.near_singular(s) for s in segments]
    for key, run in runs.items():
        errs = [peers.errors(y, s.y1) for y, s in zip(run["y_end"], segments)]
        rows[key] = {"cpu": run["cpu"], "err6": max(e[0] for e in errs),
                     "err6_regular": max(e[0] for e, r in zip(errs, regular) if r),
                     "err12": max(e[1] for e in errs),
                     **{k: run[k] for k in ("nfev", "njev", "nstep", "nlu", "failed")}}
    return rows


def same_as_ballc(y_end, segments, tol):
    """How many of the harness's radau5 end states are bit for bit those of
    ``ballc._radau5.solve_system`` (peers.run_radau5) on the same segment."""
    return sum(np.array_equal(y, peers.run_radau5(s, None, tol)[0])
               for y, s in zip(y_end, segments))


def ratios(rows, tolerances, key):
    """{(CVODE contender, radau5 tol): CVODE CPU / radau5 CPU at radau5's ``key`` error}
    (peers.equal_error_ratios: a float, or "n/r" / "<")."""
    out = peers.equal_error_ratios(rows, tolerances, key)
    return {k: v[0] for k, v in out.items() if k[0] in CONTENDERS.values()}


def benchmark(tolerances, repeat, log=print):
    result, segments = peers.record_segments()
    segments = peers.replayable(segments)
    log(f"reference: seed scene, {peers.T_END:g} s, rtol = atol = {peers.REFERENCE_TOL:g}: "
        f"status {result.status}, {len(segments)} segments of positive length")
    libs = sundials_libraries()
    with tempfile.TemporaryDirectory(prefix="ballc-cvode-") as where:
        exe = build_harness(Path(where))
        log(f"harness built; running {len(tolerances)} tolerances, best of {repeat} ...")
        out = run_harness(exe, segments, tolerances, repeat, Path(where))
    rows = rows_from_runs(out["runs"], segments)
    for tol in tolerances:
        if ("radau5", tol) not in rows:   # the harness does not run it below 100 eps
            rows[("radau5", tol)] = {"skipped": f"below radau5's limit "
                                                f"{peers.RADAU5_MIN_TOL:.2g}"}
        else:   # the harness's radau5 against ballc's (the Python bridge, same C code)
            rows[("radau5", tol)]["same_as_ballc"] = same_as_ballc(
                out["runs"][("radau5", tol)]["y_end"], segments, tol)
    return {"segments": segments, "rows": rows, "sundials": out["sundials"],
            "sundials_file": sundials_version_from_name(libs["sundials_cvode"]),
            "libs": libs}


# ---- report ----

def table_lines(bench, tolerances):
    rows = bench["rows"]
    lines = ["| tol | contender | CPU s | err6 | err6 (regular) | err12 | RHS | Jac | steps | "
             "LU / lin. setups | failed segments |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for tol in tolerances:
        for name in CONTENDERS.values():
            r = rows.get((name, tol))
            if r is None:
                continue
            if "skipped" in r:
                lines.append(f"| {tol:.0e} | {name} | not run: {r['skipped']} |"
                             + " |" * 8)
                continue
            lines.append(f"| {tol:.0e} | {name} | {r['cpu']:.3g} | {r['err6']:.1e} | "
                         f"{r['err6_regular']:.1e} | {r['err12']:.1e} | {r['nfev']} | "
                         f"{r['njev']} | {r['nstep']} | {r['nlu']} | {r['failed']} |")
    return lines


def ratio_lines(bench, tolerances):
    rows = bench["rows"]
    all_ = ratios(rows, tolerances, "err6")
    reg = ratios(rows, tolerances, "err6_regular")
    peers_ = [n for n in CONTENDERS.values() if n != "radau5"]
    lines = ["| radau5 tol | radau5 CPU s | radau5 err6 | "
             + " | ".join(f"{p} (all)" for p in peers_) + " | radau5 err6 (regular) | "
             + " | ".join(f"{p} (regular)" for p in peers_) + " |",
             "|---|---|---|" + "---|" * len(peers_) + "---|" + "---|" * len(peers_)]
    for tol in tolerances:
        base = rows.get(("radau5", tol), {})
        if "cpu" not in base:
            continue
        lines.append(f"| {tol:.0e} | {base['cpu']:.3g} | {base['err6']:.1e} | "
                     + " | ".join(peers._g(all_.get((p, tol))) for p in peers_)
                     + f" | {base['err6_regular']:.1e} | "
                     + " | ".join(peers._g(reg.get((p, tol))) for p in peers_) + " |")
    return lines


def summary(bench, tolerances, contender="CVODE BDF", key="err6_regular", span=RATIO_RANGE):
    """(min, max, tolerances left out) of the contender's equal-error ratio over
    radau5's tolerances in ``span``: numeric ratios only, and for err6 over all segments
    only where radau5's err6 is below DIVERGED; (None, None, ...) when none is left."""
    rows = bench["rows"]
    got = ratios(rows, tolerances, key)
    values, left_out = [], []
    for (p, t), v in sorted(got.items(), key=lambda kv: -kv[0][1]):
        if p != contender or not span[1] <= t <= span[0]:
            continue
        if isinstance(v, str) or rows[("radau5", t)][key] >= DIVERGED:
            left_out.append(t)
        else:
            values.append(v)
    return (min(values) if values else None, max(values) if values else None, left_out)


def summary_text(bench, tolerances, contender, key):
    lo, hi, left_out = summary(bench, tolerances, contender, key)
    text = "n/a" if lo is None else f"{lo:.2f}–{hi:.2f}×"
    if left_out:
        text += " (not at " + ", ".join(f"{t:.0e}" for t in left_out) + ")"
    return text


def same_text(bench, tolerances):
    rows, n = bench["rows"], len(bench["segments"])
    same = [rows[("radau5", t)]["same_as_ballc"] for t in tolerances
            if "same_as_ballc" in rows.get(("radau5", t), {})]
    if all(k == n for k in same):
        return (f"the harness's radau5 end states are bit for bit those of ballc's own "
                f"radau5 (`ballc._radau5.solve_system`) on all {n} segments at every "
                "tolerance")
    return ("the harness's radau5 end states equal ballc's own radau5's on "
            + ", ".join(f"{k}" for k in same) + f" of {n} segments at the tolerances in turn")


def print_report(bench, tolerances):
    print(f"SUNDIALS {bench['sundials']} (library file: {bench['sundials_file']})")
    print(f"check: {same_text(bench, tolerances)}")
    for line in table_lines(bench, tolerances) + [""] + ratio_lines(bench, tolerances):
        print(line)
    for key in ("err6", "err6_regular"):
        for name in ("CVODE BDF", "CVODE Adams"):
            print(f"{name} / radau5 CPU at equal {key}, radau5 tol "
                  f"{RATIO_RANGE[0]:.0e}..{RATIO_RANGE[1]:.0e}: "
                  f"{summary_text(bench, tolerances, name, key)}")


def write_markdown(bench, tolerances, args, elapsed, path):
    segs, rows = bench["segments"], bench["rows"]
    n_near = sum(peers.near_singular(s) for s in segs)

    def span_text(name, key):
        return summary_text(bench, tolerances, name, key)
    lines = [
        "# radau5 against CVODE, both driven from C", "",
        f"Generated by `python -m benchmarks.cvode_c{' --quick' if args.quick else ''}` "
        f"({elapsed:.0f} s wall).  CPU is measured inside the C harness with "
        f"`clock_gettime(CLOCK_PROCESS_CPUTIME_ID)` over a pass through all segments, best "
        f"of {args.repeat} rounds over all tolerances (so that a burst of load does not hit "
        "every pass of one tolerance), the contenders taking turns in a rotated order; the "
        "machine has "
        "2 cores and was shared with other work while this ran.  Needs scikit-sundae (for "
        "its bundled SUNDIALS libraries) and a C compiler.", "",
        "Result: at equal err6 over the regular segments, CVODE BDF takes "
        f"**{span_text('CVODE BDF', 'err6_regular')}** radau5's CPU for radau5's "
        f"tolerances {RATIO_RANGE[0]:.0e}..{RATIO_RANGE[1]:.0e} "
        f"(CVODE Adams: {span_text('CVODE Adams', 'err6_regular')}); at equal err6 over "
        f"all segments {span_text('CVODE BDF', 'err6')} (Adams "
        f"{span_text('CVODE Adams', 'err6')}); tolerances are left out where radau5's err6 "
        f"over all segments is {DIVERGED:g} or more (diverged near-singular segments) or "
        "CVODE never got as accurate.  A ratio above 1 means radau5 is faster.", "",
        "## What is measured", "",
        "The replay of [peers](peers.md), without Python: the seed scene "
        f"(`ballc.Scene()`, {peers.T_END:g} s) simulated at rtol = atol = "
        f"{peers.REFERENCE_TOL:g}, its {len(segs)} smooth segments of positive length "
        "recorded by `benchmarks.peers.record_segments` (start time and state, end time and "
        "state, parameters, latch, flags), and every contender integrating every segment "
        "from the recorded start state to the recorded end time at rtol = atol = tol, "
        "without events.  The segments go to the C program "
        "`benchmarks/cvode_harness.c` in a text file; its results "
        "(CPU, counts, end states) come back on its standard output, and the errors are "
        "computed in Python as in peers.py:", "",
        "- **err6**: max over the segments of the inf-norm of the end state's error in "
        "centre position (m) and velocity (m/s); **err6 (regular)**: the same without the "
        f"{n_near} segments that start in slip with |u| < {peers.NEAR_SINGULAR_SLIP:g} m/s "
        "(near-singular: see the caveats of [peers](peers.md)); **err12**: over the 12 "
        "mechanical degrees of freedom.",
        "- **equal-error ratio**: CVODE's CPU, log-log interpolated between its two "
        "tolerances whose errors bracket radau5's error at that tolerance, over radau5's "
        "CPU (`benchmarks.peers.equal_error_ratios`); `n/r`: CVODE never got that "
        "accurate; `<`: CVODE was more accurate even at its loosest tolerance.", "",
        "Contenders, all in one C process, on the same compiled right-hand side and analytic "
        "Jacobian (`ballc_rhs_checked_inputs` / `ballc_jacobian_checked_inputs`, the "
        "parameters prepared once per segment with `ballc_parameters_init`), compiled from "
        "ballc's own C sources with setup.py's flags "
        f"(`{' '.join(CFLAGS)}`):", "",
        "- `radau5`: `radau5_solve`, set up as `ballc._radau5.solve_system` sets it up "
        "(scipy's step control, initial step from scipy's rule, every step stored, "
        "`outputs_checked`); the end state is the last stored step's.",
        "- `CVODE BDF`, `CVODE Adams`: SUNDIALS CVODE "
        f"{bench['sundials']} (`SUNDIALSGetVersion`; library files "
        + ", ".join(f"`{p.name}`" for p in bench["libs"].values())
        + " from the scikit-sundae wheel), one solver object per method re-initialised "
        "per segment (`CVodeReInit`), `CVodeSStolerances(tol, tol)`, the dense direct "
        "linear solver (`SUNLinSol_Dense`: SUNDIALS' own LU, no LAPACK) with "
        "ballc's Jacobian copied from its row-major layout into SUNDIALS' column-major "
        "matrix (the copy is in the timing), `CVodeSetStopTime` at the segment's end (it "
        "steps onto the end rather than interpolating back), `max_num_steps` unlimited, "
        "everything else at CVODE's defaults.", "",
        f"Check: {same_text(bench, tolerances)}.  CVODE here is the solver scikit-sundae "
        "drives in [peers](peers.md), with the same options: its counts and errors there "
        "are the ones here (when both pages come from the same tree); only the callbacks "
        "differ (C here, Python there).", "",
        "## Table", "",
        "RHS / Jac / steps / LU: totals over the segments (for CVODE, LU is the number of "
        "linear-solver setups, each a new I - γJ and its LU; the Jacobian is re-evaluated "
        "only in some of them).", ""]
    lines += table_lines(bench, tolerances)
    lines += ["", "## CPU ratio CVODE / radau5 at equal error", "",
              "For each tolerance of radau5: CVODE's CPU at radau5's error there over "
              "radau5's CPU (> 1: radau5 faster).  At loose tolerances err6 over all "
              "segments is O(1) for every contender (the near-singular segments diverge): "
              "read the (regular) columns there.", ""]
    lines += ratio_lines(bench, tolerances)
    lines += [
        "", "## Caveats", "",
        "- Defaults.  CVODE runs with its defaults apart from the stop time and the step "
        "limit: variable order (BDF 1–5, Adams 1–12), Newton iteration on the corrector "
        "with at most 3 iterations and a convergence test at 0.1 of the error "
        "tolerance, the Newton matrix I - γJ set up again only when γ changed by more than "
        "30 %, after 20 steps, or after a convergence failure, and the Jacobian evaluated "
        "again only after 51 steps or a failure with a stale one.  Nothing was tuned for "
        "either side.  Adams is run with Newton iteration too (CVODE's default since "
        "SUNDIALS 4).",
        "- Same tolerance is not same accuracy: CVODE at a given tol is tens to thousands of "
        "times less accurate than radau5 here (its WRMS error norm against radau5's), so CVODE is "
        "run down to 1e-15 to reach radau5's errors; compare at equal error (the ratio "
        "table), not along rows.",
        "- The ratio is at equal err6 (centre position and velocity at the segment "
        "ends), the error of docs/work_precision.md.  At equal err12 it can differ.",
        "- The error is measured against radau5's own 1e-12 run at the same end times: "
        "below about 1e-11 it mixes the reference's own error into the contenders' "
        "(and favours radau5, which errs like its reference).",
        "- Each segment starts fresh (initial step chosen by each solver), as in ballc after "
        "a contact event.  radau5 allocates its work space and stores every step per call "
        "(as in ballc); CVODE reuses its solver object across segments "
        "(`CVodeReInit`), which is the cheaper way to drive it.",
        "- Timings on a shared 2-core machine, passes of a few ms (loosest tolerances) to "
        "about 0.1 s: best of 5 was seen to swing by up to a third at single tolerances "
        f"between runs, best of 20 by a few %; this run is best of {args.repeat}.",
        "- [peers](peers.md) measures the same replay through Python callbacks and "
        "estimates CVODE's C-level cost by subtracting the callbacks' cost, an upper bound "
        "(scikit-sundae's own per-call and per-step work stays in); this page measures it "
        "without Python.",
        "- CVODE is the wheel's build of SUNDIALS (conda-forge GCC; its optimisation flags "
        "are not recorded in the library), ballc's C is compiled here with setup.py's "
        "flags; both without `-march`.", ""]
    path.write_text("\n".join(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="peers.py's quick tolerances, best of 1")
    parser.add_argument("--repeat", type=int, default=None,
                        help=f"best of N (default {REPEAT})")
    parser.add_argument("--out", type=Path, default=DOCS,
                        help="where cvode_c.md goes (default docs/)")
    args = parser.parse_args(argv)
    args.repeat = args.repeat or (1 if args.quick else REPEAT)
    tolerances = QUICK_TOLERANCES if args.quick else TOLERANCES
    try:
        sundials_libraries()
        compiler()
    except Unavailable as exc:
        raise SystemExit(f"benchmarks/cvode_c.py: {exc}") from None
    started = time.time()
    bench = benchmark(tolerances, args.repeat, log=lambda *a: print(*a, flush=True))
    elapsed = time.time() - started
    print_report(bench, tolerances)
    args.out.mkdir(parents=True, exist_ok=True)
    write_markdown(bench, tolerances, args, elapsed, args.out / "cvode_c.md")
    print(f"wrote {args.out / 'cvode_c.md'} ({elapsed:.0f} s; ballc {ballc.__version__}, "
          f"python {platform.python_version()})")


if __name__ == "__main__":
    main()
