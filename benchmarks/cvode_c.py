"""radau5 and dop853 against SUNDIALS CVODE, all driven from C: no Python per call.

    python -m benchmarks.cvode_c [--quick] [--repeat N] [--out DIR]

benchmarks/peers.py drives CVODE through scikit-sundae's Python callbacks and subtracts
an estimate of their cost.  Here the same replay runs in C: the seed scene's segments
are recorded as in peers.py (``record_segments``, ``replayable``), written to a text
file, and a small C program (benchmarks/cvode_harness.c) integrates every segment
from its recorded start state to its recorded end time with

- ``radau5``: ballc's ``radau5_solve`` (src/ballc/_integrator.c with the Radau IIA
  step of src/ballc/_radau_iia.c), set up as
  ``ballc._radau5.solve_system`` sets it up (scipy's step control, every step stored);
- ``dop853``: the same ``radau5_solve`` with ``method = RADAU5_METHOD_DOP853``
  (src/ballc/_dop853.c): Dormand & Prince's explicit Runge-Kutta pair of order 8, scipy's
  DOP853 step by step in C, in the same loop with the same set-up; no Jacobian, no LU
  (``solve_system(..., method="dop853")``);
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
those of peers.py (``errors``, ``near_singular``, ``equal_error_ratios``), for every
contender against the end states of the same radau5 1e-12 reference run.  Two
equal-error tables: CVODE's CPU at radau5's error over radau5's, and CVODE's and
radau5's CPU at dop853's error over dop853's (with CVODE over ballc's best: the cheaper
of dop853 and radau5 at that error).  The harness's radau5 and dop853 end states are
checked bit for bit against ``solve_system``'s (method "radau5" / "dop853").

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
CONTENDERS = {"radau5": "radau5", "dop853": "dop853", "cvode_bdf": "CVODE BDF",
              "cvode_adams": "CVODE Adams"}
#: ballc's integrators (``solve_system``'s ``method``) and CVODE's
BALLC = ("radau5", "dop853")
CVODE = ("CVODE BDF", "CVODE Adams")
#: per base of an equal-error table: the contenders whose CPU is interpolated at its error
RATIO_PEERS = {"radau5": CVODE, "dop853": CVODE + ("radau5",)}
#: peers.py's 1e-3 .. 1e-14, and 1e-15: CVODE is 100-1000x less accurate than radau5 at
#: equal tolerance here and needs 1e-13 .. 1e-15 to reach radau5's errors at 1e-9, 1e-10
#: (radau5 runs down to 100 machine epsilons, ballc's limit)
TOLERANCES = peers.TOLERANCES + (1e-15,)
QUICK_TOLERANCES = peers.QUICK_TOLERANCES
#: best of REPEAT passes: a pass lasts 2-120 ms, and on the shared 2-core machine best of 5
#: was seen to swing by up to a third at single tolerances between runs (best of 20: a few %)
REPEAT = 20
#: radau5's (dop853's) tolerances of the summary range
RATIO_RANGE = (1e-3, 1e-10)
#: the summary's range over all segments leaves out the radau5 (dop853) tolerances where
#: its err6 over all segments is above this (the near-singular segments diverged)
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


def same_as_ballc(y_end, segments, tol, method="radau5"):
    """How many of the harness's radau5 (``method`` "dop853": dop853) end states are bit
    for bit those of ``ballc._radau5.solve_system`` (peers.run_radau5) on the same
    segment."""
    return sum(np.array_equal(y, peers.run_radau5(s, None, tol, method)[0])
               for y, s in zip(y_end, segments))


def ratios(rows, tolerances, key, base="radau5"):
    """{(contender, base tol): contender's CPU / base's CPU at the base's ``key`` error}
    for the contenders RATIO_PEERS[base] (peers.equal_error_ratios: a float, or "n/r" /
    "<")."""
    out = peers.equal_error_ratios(rows, tolerances, key, base, RATIO_PEERS[base])
    return {k: v[0] for k, v in out.items()}


def best_ratios(rows, tolerances, key):
    """{(CVODE contender, dop853 tol): CVODE's CPU / ballc's best CPU at dop853's ``key``
    error}, ballc's best being the cheaper of dop853 and radau5 (radau5's CPU
    interpolated at dop853's error; dop853 alone where radau5 has no such point);
    "n/r" / "<" as in ``ratios``."""
    got = ratios(rows, tolerances, key, "dop853")
    out = {}
    for (p, t), v in got.items():
        if p == "radau5":
            continue
        r5 = got.get(("radau5", t))
        out[(p, t)] = v if isinstance(v, str) or isinstance(r5, str) else v / min(1.0, r5)
    return out


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
    for name in BALLC:
        for tol in tolerances:
            if (name, tol) not in rows:   # the harness does not run it below 100 eps
                rows[(name, tol)] = {"skipped": f"below ballc's limit "
                                                f"{peers.RADAU5_MIN_TOL:.2g}"}
            else:   # the harness's radau5/dop853 against ballc's (the Python bridge)
                rows[(name, tol)]["same_as_ballc"] = same_as_ballc(
                    out["runs"][(name, tol)]["y_end"], segments, tol, name)
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


def ratio_lines(bench, tolerances, base="radau5"):
    """The equal-error table of ``base`` (radau5 or dop853): per base tolerance, each of
    RATIO_PEERS[base]'s CPU at the base's error over the base's CPU; for dop853 also
    CVODE's over ballc's best (``best_ratios``)."""
    rows = bench["rows"]
    peers_ = RATIO_PEERS[base]
    cols = [(p, None) for p in peers_]
    if base == "dop853":
        cols += [(p, "best") for p in CVODE]

    def head(c, kind):
        return f"{c[0]} / ballc's best ({kind})" if c[1] else f"{c[0]} ({kind})"
    tables = {}
    for key in ("err6", "err6_regular"):
        got = ratios(rows, tolerances, key, base)
        best = best_ratios(rows, tolerances, key) if base == "dop853" else {}
        tables[key] = {(c, t): (best if c[1] else got).get((c[0], t)) for c in cols
                       for t in tolerances}
    lines = [f"| {base} tol | {base} CPU s | {base} err6 | "
             + " | ".join(head(c, "all") for c in cols) + f" | {base} err6 (regular) | "
             + " | ".join(head(c, "regular") for c in cols) + " |",
             "|---|---|---|" + "---|" * len(cols) + "---|" + "---|" * len(cols)]
    for tol in tolerances:
        b = rows.get((base, tol), {})
        if "cpu" not in b:
            continue
        lines.append(f"| {tol:.0e} | {b['cpu']:.3g} | {b['err6']:.1e} | "
                     + " | ".join(peers._g(tables["err6"][(c, tol)]) for c in cols)
                     + f" | {b['err6_regular']:.1e} | "
                     + " | ".join(peers._g(tables["err6_regular"][(c, tol)]) for c in cols)
                     + " |")
    return lines


def summary(bench, tolerances, contender="CVODE BDF", key="err6_regular", span=RATIO_RANGE,
            base="radau5", best=False):
    """(min, max, tolerances left out) of the contender's equal-error ratio over the
    base's (radau5's or dop853's) tolerances in ``span``: numeric ratios only, and for
    err6 over all segments only where the base's err6 is below DIVERGED; (None, None,
    ...) when none is left.  ``best`` (base dop853): over ballc's best instead."""
    rows = bench["rows"]
    got = best_ratios(rows, tolerances, key) if best else ratios(rows, tolerances, key, base)
    values, left_out = [], []
    for (p, t), v in sorted(got.items(), key=lambda kv: -kv[0][1]):
        if p != contender or not span[1] <= t <= span[0]:
            continue
        if isinstance(v, str) or (key == "err6" and rows[(base, t)]["err6"] >= DIVERGED):
            left_out.append(t)
        else:
            values.append(v)
    return (min(values) if values else None, max(values) if values else None, left_out)


def summary_text(bench, tolerances, contender, key, base="radau5", best=False):
    lo, hi, left_out = summary(bench, tolerances, contender, key, base=base, best=best)
    text = "n/a" if lo is None else f"{lo:.2f}–{hi:.2f}×"
    if left_out:
        text += " (not at " + ", ".join(f"{t:.0e}" for t in left_out) + ")"
    return text


def dop853_is_best(bench, tolerances, key):
    """The dop853 tolerances in RATIO_RANGE where radau5 was cheaper than dop853 at
    dop853's ``key`` error (radau5 / dop853 < 1): there ballc's best is radau5."""
    got = ratios(bench["rows"], tolerances, key, "dop853")
    return [t for (p, t), v in got.items() if p == "radau5" and not isinstance(v, str)
            and v < 1 and RATIO_RANGE[1] <= t <= RATIO_RANGE[0]]


def same_text(bench, tolerances):
    rows, n = bench["rows"], len(bench["segments"])
    parts = []
    for name in BALLC:
        same = [rows[(name, t)]["same_as_ballc"] for t in tolerances
                if "same_as_ballc" in rows.get((name, t), {})]
        if all(k == n for k in same):
            parts.append(f"the harness's {name} end states are bit for bit those of "
                         f"ballc's own {name} (`ballc._radau5.solve_system(..., "
                         f"method=\"{name}\")`) on all {n} segments at every tolerance")
        else:
            parts.append(f"the harness's {name} end states equal ballc's own {name}'s on "
                         + ", ".join(f"{k}" for k in same)
                         + f" of {n} segments at the tolerances in turn")
    return "; ".join(parts)


def rejected_text(bench, tolerances, shown=(1e-8, 1e-12)):
    """dop853's rejected steps at the tolerances ``shown``, in free flight (no flag but
    the observer's) and in the contact segments, from ``ballc._radau5.solve_system(...,
    method="dop853")`` on each segment (the harness's dop853 is bit for bit the same:
    ``same_as_ballc``)."""
    from ballc import _radau5
    free = _core.FLAGS["observer"]
    parts, contact, flight = [], [], []
    for tol in shown:
        if ("dop853", tol) not in bench["rows"] or tol < peers.RADAU5_MIN_TOL:
            continue
        counts = {True: [0, 0], False: [0, 0]}    # contact?: [rejected, attempted]
        for seg in bench["segments"]:
            sol = _radau5.solve_system(seg.params, seg.latch, seg.flags, (seg.t0, seg.t1),
                                       seg.y0, rtol=tol, atol=tol, method="dop853")
            c = counts[bool(seg.flags & ~free)]
            c[0] += sol.nreject
            c[1] += sol.nstep + sol.nreject
        contact.append(counts[True])
        flight.append(counts[False])
        parts.append(f"at {tol:.0e} dop853 rejected {counts[True][0]} of {counts[True][1]} "
                     f"attempted steps in the contact segments and {counts[False][0]} of "
                     f"{counts[False][1]} in free flight")
    if not parts:
        return "dop853 was not run at " + " or ".join(f"{t:.0e}" for t in shown)
    text = "Here (`solve_system`'s `nreject`) " + "; ".join(parts)
    if all(c[0] for c in contact) and not any(f[0] for f in flight):
        text += (": the rejections, all in contact, are consistent with a step held near "
                 "the stability limit there")
    return text


def print_report(bench, tolerances):
    print(f"SUNDIALS {bench['sundials']} (library file: {bench['sundials_file']})")
    print(f"check: {same_text(bench, tolerances)}")
    for line in (table_lines(bench, tolerances) + [""] + ratio_lines(bench, tolerances)
                 + [""] + ratio_lines(bench, tolerances, "dop853")):
        print(line)
    span = f"{RATIO_RANGE[0]:.0e}..{RATIO_RANGE[1]:.0e}"
    for key in ("err6", "err6_regular"):
        for base, names in (("radau5", CVODE), ("dop853", CVODE + ("radau5",))):
            for name in names:
                print(f"{name} / {base} CPU at equal {key}, {base} tol {span}: "
                      f"{summary_text(bench, tolerances, name, key, base)}")
        for name in CVODE:
            print(f"{name} / ballc's best CPU at dop853's {key}, dop853 tol {span}: "
                  f"{summary_text(bench, tolerances, name, key, 'dop853', best=True)}")
        print(f"dop853 tolerances in {span} where radau5 is cheaper at equal {key}: "
              f"{dop853_is_best(bench, tolerances, key) or 'none'}")


def write_markdown(bench, tolerances, args, elapsed, path):
    segs, rows = bench["segments"], bench["rows"]
    n_near = sum(peers.near_singular(s) for s in segs)

    rejected = rejected_text(bench, tolerances)

    def span_text(name, key, base="radau5", best=False):
        return summary_text(bench, tolerances, name, key, base, best)
    span = f"{RATIO_RANGE[0]:.0e}..{RATIO_RANGE[1]:.0e}"
    radau5_cheaper = {k: dop853_is_best(bench, tolerances, k) for k in ("err6_regular", "err6")}
    if not any(radau5_cheaper.values()):
        best_text = ("radau5 was never cheaper than dop853 at dop853's error there (radau5 / "
                     f"dop853: {span_text('radau5', 'err6_regular', 'dop853')} regular, "
                     f"{span_text('radau5', 'err6', 'dop853')} all), so dop853 is ballc's "
                     "best and these are CVODE's CPU over ballc's best")
    else:
        best_text = ("radau5 was cheaper than dop853 at dop853's error at "
                     + ", ".join(f"{t:.0e}" for t in sorted(
                         set().union(*radau5_cheaper.values()), reverse=True))
                     + "; over ballc's best (the cheaper of the two) CVODE BDF takes "
                     f"{span_text('CVODE BDF', 'err6_regular', 'dop853', True)} and CVODE "
                     f"Adams {span_text('CVODE Adams', 'err6_regular', 'dop853', True)} "
                     "(regular segments)")
    lines = [
        "# radau5 and dop853 against CVODE, all driven from C", "",
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
        f"tolerances {span} "
        f"(CVODE Adams: {span_text('CVODE Adams', 'err6_regular')}); at equal err6 over "
        f"all segments {span_text('CVODE BDF', 'err6')} (Adams "
        f"{span_text('CVODE Adams', 'err6')}).  Against ballc's explicit dop853, at equal "
        "err6 over the regular segments CVODE BDF takes "
        f"**{span_text('CVODE BDF', 'err6_regular', 'dop853')}** and CVODE Adams "
        f"**{span_text('CVODE Adams', 'err6_regular', 'dop853')}** dop853's CPU for "
        f"dop853's tolerances {span}; at equal err6 over all segments "
        f"{span_text('CVODE BDF', 'err6', 'dop853')} (Adams "
        f"{span_text('CVODE Adams', 'err6', 'dop853')}); {best_text}.  Tolerances are left "
        "out of a range where the other never got as accurate as the base (radau5 or "
        "dop853) or was more accurate even at its loosest tolerance, and out of the "
        "ranges over all segments where the base's err6 over all segments is "
        f"{DIVERGED:g} or more (diverged near-singular segments).  A ratio above 1 means "
        "ballc's integrator is faster.", "",
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
        "- **equal-error ratio**: a contender's CPU, log-log interpolated between its two "
        "tolerances whose errors bracket the base's (radau5's or dop853's) error at that "
        "tolerance, over the base's CPU (`benchmarks.peers.equal_error_ratios`); `n/r`: "
        "the contender never got that accurate; `<`: it was more accurate even at its "
        "loosest tolerance.  **ballc's best** at dop853's error: the cheaper of dop853 "
        "and radau5 there (dop853 where radau5 has no interpolated point).", "",
        "Every contender's error is measured the same way, against the end states of the "
        f"one radau5 {peers.REFERENCE_TOL:g} reference run (dop853's too).", "",
        "Contenders, all in one C process, on the same compiled right-hand side and analytic "
        "Jacobian (`ballc_rhs_checked_inputs` / `ballc_jacobian_checked_inputs`, the "
        "parameters prepared once per segment with `ballc_parameters_init`), compiled from "
        "ballc's own C sources with setup.py's flags "
        f"(`{' '.join(CFLAGS)}`):", "",
        "- `radau5`: `radau5_solve`, set up as `ballc._radau5.solve_system` sets it up "
        "(scipy's step control, initial step from scipy's rule, every step stored, "
        "`outputs_checked`); the end state is the last stored step's.",
        "- `dop853`: the same `radau5_solve`, set up the same way, with `method = "
        "RADAU5_METHOD_DOP853` (`src/ballc/_dop853.c`, `ballc.simulate(..., "
        "method=\"dop853\")`): Dormand & Prince's explicit Runge–Kutta pair of order 8, "
        "scipy's DOP853 (its 12 stages, its error estimate from the embedded orders 5 and "
        "3, its step control and initial step) step by step in C, in radau5's loop.  "
        "Explicit: no Jacobian, no LU, no Newton iteration (its Jac and LU columns are 0); "
        "12 RHS calls per attempted step (accepted or rejected) and 2 per segment for the "
        "initial step.",
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
        "RHS / Jac / steps / LU: totals over the segments (steps: accepted steps; for "
        "CVODE, LU is the number of linear-solver setups, each a new I - γJ and its LU; "
        "the Jacobian is re-evaluated only in some of them; dop853 has neither).", ""]
    lines += table_lines(bench, tolerances)
    lines += ["", "## CPU ratio CVODE / radau5 at equal error", "",
              "For each tolerance of radau5: CVODE's CPU at radau5's error there over "
              "radau5's CPU (> 1: radau5 faster).  At loose tolerances err6 over all "
              "segments is O(1) for every contender (the near-singular segments diverge): "
              "read the (regular) columns there.", ""]
    lines += ratio_lines(bench, tolerances)
    lines += ["", "## CPU ratio CVODE / dop853 and radau5 / dop853 at equal error", "",
              "For each tolerance of dop853: CVODE's and radau5's CPU at dop853's error "
              "there over dop853's CPU (> 1: dop853 faster), and CVODE's CPU over ballc's "
              "best there (the cheaper of dop853 and radau5; dop853 where radau5's column is "
              "`<` or `n/r`).", ""]
    lines += ratio_lines(bench, tolerances, "dop853")
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
        "run down to 1e-15 to reach radau5's errors, and dop853 lies in between; compare "
        "at equal error (the ratio tables), not along rows.",
        "- dop853 is explicit: its step is bounded by stability as well as by accuracy, "
        "so the stiffer the scene, the more it loses to radau5; this page is one scene.  "
        f"{rejected}.",
        "- The ratio is at equal err6 (centre position and velocity at the segment "
        "ends), the error of docs/work_precision.md.  At equal err12 it can differ.",
        "- The error is measured against radau5's own 1e-12 run at the same end times: "
        "below about 1e-11 it mixes the reference's own error into the contenders' "
        "(and favours radau5, which errs like its reference, over dop853 and CVODE).",
        "- Each segment starts fresh (initial step chosen by each solver), as in ballc after "
        "a contact event.  radau5 and dop853 allocate their work space and store every "
        "step per call (as in ballc); CVODE reuses its solver object across segments "
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
