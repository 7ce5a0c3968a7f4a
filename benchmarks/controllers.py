"""radau5's step control: scipy's Radau against elements of Hairer's RADAU5, at equal error.

    python -m benchmarks.controllers [--repeat 3] [--variants elements|all|NAME,...]
                                     [--scenes NAME,...] [--no-write]

radau5 ports scipy's Radau step control; Hairer & Wanner's RADAU5 (radau5.f, RADCOR
and ESTRAD) controls the same method differently.  Each difference is a bit of the
solver's private ``controller`` option (``_integrator.h``, RADAU5_CTRL_*):

* ``nit7``   at most 7 Newton iterations (scipy 6), safety 0.9 (1 + 2 nit)/(newt + 2 nit)
* ``limits`` h_new/h in [0.2, 8] (scipy [0.2, 10]), no growth right after a rejection
* ``pred``   Gustafsson's predictive factor after accepted steps only (min with the
  standard factor, plain safety, previous error floored at 0.01); a rejected step
  uses the standard factor alone (scipy applies the predictive one on both)
* ``hold``   keep h and the LU when h_new/h is in [1, 1.2] (scipy: whenever < 1.2,
  i.e. it also keeps h when the controller asks for a *smaller* step)
* ``jac``    a new Jacobian after an accepted step iff the Newton contraction
  theta > 0.001 (scipy: iff more than 2 iterations and rate > 0.001)
* ``tol``    RADAU5's tolerance transformation rtol' = 0.1 rtol^(2/3),
  atol' = rtol' atol / rtol (the Newton stopping tolerance fnewt is the same function
  of the tolerance in use as scipy's, so this element only relabels the tolerance)
* ``scale``  the error scale from |y| at the step start (scipy max(|y|, |y_new|))

Scenes: those of benchmarks/work_precision.py (seed, conservative oblique, friction
only), 5 s.  The final error of one run jumps by up to a decade from one tolerance to
the next (nine contacts amplify it erratically), which would drown differences of
10-30 % at equal error; so each scene is an ensemble of ``--members`` throws (its
velocity scaled by 1, 1.01, 0.99, 1.02, 0.98, ...), each with its own reference, and a
run of the ensemble costs the sum and errs the geometric mean over its throws.
Tolerances rtol = atol = 10^(-3 - k/2), k = 0..18 (1e-3 .. 1e-12).  For each scene,
variant and tolerance: RHS calls, steps, rejected steps, LU factorisations, Jacobians,
CPU (time.process_time around each ``ballc.simulate``, best of ``--repeat``, all
variants interleaved in one process so that the machine's load falls on all of them)
and the final error (max |final centre position (m), velocity (m/s) - reference|), the
reference being radau5 with scipy's control at 1e-13 (as work_precision and
seed_tolerance).  Equal error: each variant's cost (calls, CPU) is interpolated
log-log on its work-precision front (the runs no cheaper run beats in error) at the
errors scipy's control reaches at 1e-3, 1e-4, ..., 1e-12; the tables give variant /
scipy, and their geometric mean over the columns both reach.  Writes
docs/controllers.md.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import ballc
from ballc import _core, _radau5

from .work_precision import SCENES, T_END   # the work-precision scenes, not a copy

TOLERANCES = tuple(10.0 ** (-3 - k / 2) for k in range(19))
TARGETS = tuple(10.0 ** -k for k in range(3, 13))   # scipy's tolerances giving the errors
ELEMENTS = ("nit7", "limits", "pred", "hold", "jac", "scale", "tol")
#: The candidate: every RADAU5 element that changes the control, not the meaning of rtol.
HAIRER_NO_TOL = ("nit7", "limits", "pred", "hold", "jac", "scale")
_IDX = [_core.STATE_NAMES.index(n) for n in ("x", "y", "z", "vx", "vy", "vz")]
DOCS = Path(__file__).resolve().parent.parent / "docs"


def variants(which):
    out = {"scipy": ()}
    if which in ("elements", "all"):
        out.update({e: (e,) for e in ELEMENTS})
        out["hold+jac"] = ("hold", "jac")
        out["hairer (all)"] = ELEMENTS
        out["hairer - tol"] = HAIRER_NO_TOL
        out["hairer - tol - pred"] = tuple(x for x in HAIRER_NO_TOL if x != "pred")
    if which == "all":
        out.update({f"hairer - tol - {e}": tuple(x for x in HAIRER_NO_TOL if x != e)
                    for e in HAIRER_NO_TOL if e != "pred"})
    if which not in ("elements", "all"):
        for name in which.split(","):
            if name != "scipy":
                out[name] = tuple(x for x in name.split("+") if x)
    return out


def run(scene, tol, elements):
    """CPU, result and the solver's counts summed over the run's segments (steps,
    rejections, LU factorisations, Jacobians: the C loop's segment log)."""
    previous = _radau5._set_controller(list(elements))
    try:
        started = time.process_time()
        result = ballc.simulate(scene, T_END, rtol=tol, atol=tol)
        cpu = time.process_time() - started
    finally:
        _radau5._set_controller(previous)
    log = result.segments
    if log is None:
        raise SystemExit("the run did not take the C loop: it has no segment log")
    return cpu, result, {key: int(log[key].sum()) for key in ("nstep", "nreject", "nlu", "njev")}


def members(scene, k):
    factors = [1.0] + [1 + s * 0.01 * (i // 2 + 1) for i, s in
                       zip(range(k - 1), [1, -1] * k)]
    return [scene.replace(velocity=tuple(f * v for v in scene.velocity)) for f in factors]


def front(points):
    """The work-precision front of (error, cost) points: sorted by error, each kept only
    if it is cheaper than every point with a smaller error."""
    pts = sorted((e, c) for e, c in points if np.isfinite(e) and e > 0)
    keep, best = [], np.inf
    for e, c in pts:
        if c < best:
            keep.append((e, c))
            best = c
    return keep


def cost_at(points, error):
    """log-log interpolation of cost on the front at ``error``; NaN outside its range."""
    f = front(points)
    if len(f) < 2:
        return np.nan
    e = np.log([p[0] for p in f])
    c = np.log([p[1] for p in f])
    x = np.log(error)
    if x < e[0] - 1e-9 or x > e[-1] + 1e-9:
        return np.nan
    return float(np.exp(np.interp(x, e, c)))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--variants", default="elements",
                        help="elements (scipy, each element, hairer), all (also hairer "
                             "without each element), or names joined by , (elements "
                             "joined by +)")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--members", type=int, default=4)
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    chosen = variants(args.variants)
    scenes = args.scenes.split(",")
    started_all = time.time()
    table = {}       # (scene, variant) -> list of rows
    notes = {}
    for scene_name in scenes:
        throws = members(SCENES[scene_name], args.members)
        refs = [run(m, 1e-13, ())[1] for m in throws]
        ref_finals = [r.y[_IDX, -1] for r in refs]
        checks = [run(m, 1e-12, ())[1] for m in throws]
        checks_h = [run(m, 1e-13, HAIRER_NO_TOL)[1] for m in throws]
        notes[scene_name] = (
            max(float(np.abs(c.y[_IDX, -1] - f).max()) for c, f in zip(checks, ref_finals)),
            max(float(np.abs(c.y[_IDX, -1] - f).max()) for c, f in zip(checks_h, ref_finals)),
            [len(r.contacts) for r in refs])
        print(f"{scene_name}: reference (scipy control, 1e-13) vs scipy 1e-12 "
              f"{notes[scene_name][0]:.1e}, vs hairer - tol 1e-13 {notes[scene_name][1]:.1e}",
              flush=True)
        for tol in TOLERANCES:
            best = {(v, i): np.inf for v in chosen for i in range(len(throws))}
            results = {}
            for _ in range(args.repeat):   # interleaved: the load falls on every variant
                for i, throw in enumerate(throws):
                    for v, elements in chosen.items():
                        cpu, result, c = run(throw, tol, elements)
                        best[(v, i)] = min(best[(v, i)], cpu)
                        results[(v, i)] = (result, c)
            for v in chosen:
                errors, row = [], dict(tol=tol, nfev=0, cpu=0.0, status=0, nstep=0,
                                       nreject=0, nlu=0, njev=0, contacts=[])
                for i in range(len(throws)):
                    result, c = results[(v, i)]
                    errors.append(float(np.abs(result.y[_IDX, -1] - ref_finals[i]).max())
                                  if result.status == 0 else np.nan)
                    row["nfev"] += result.nfev
                    row["cpu"] += best[(v, i)]
                    row["status"] = min(row["status"], result.status)
                    row["contacts"].append(len(result.contacts))
                    for key in c:
                        row[key] += c[key]
                row["error"] = float(np.exp(np.mean(np.log(errors))))
                row["error0"] = errors[0]
                table.setdefault((scene_name, v), []).append(row)
            print(f"  {tol:.1e}: " + "  ".join(
                f"{v} {table[(scene_name, v)][-1]['nfev']}/{table[(scene_name, v)][-1]['error']:.1e}"
                for v in chosen), flush=True)
    elapsed = time.time() - started_all
    lines = markdown(table, notes, chosen, scenes, args, elapsed)
    print("\n".join(lines))
    if not args.no_write:
        (DOCS / "controllers.md").write_text("\n".join(lines) + "\n")
        print("wrote", DOCS / "controllers.md")


def equal_error(table, scene_name, variant, key):
    base = table[(scene_name, "scipy")]
    rows = table[(scene_name, variant)]
    out = []
    for target in TARGETS:
        at = min(base, key=lambda r: abs(np.log(r["tol"] / target)))
        error = at["error"]
        b = cost_at([(r["error"], r[key]) for r in base], error)
        v = cost_at([(r["error"], r[key]) for r in rows], error)
        out.append((error, v / b if np.isfinite(b) and b > 0 else np.nan))
    return out


def _f(x, fmt):
    return "–" if x is None or not np.isfinite(x) else format(x, fmt)


def geomean(ratios):
    r = [x for x in ratios if np.isfinite(x)]
    return float(np.exp(np.mean(np.log(r)))) if r else np.nan


def markdown(table, notes, chosen, scenes, args, elapsed):
    lines = [
        "# Step control: scipy's Radau against Hairer's RADAU5", "",
        "Generated by `python -m benchmarks.controllers` on a 2-core machine shared with "
        f"other work ({elapsed:.0f} s; CPU best of {args.repeat}, variants interleaved).  "
        "The script's docstring says what each element is; `hairer (all)` is every "
        "element of RADAU5's control, `hairer - tol` all but the tolerance relabelling, "
        "`hairer - tol - pred` also without the predictive controller.", "",
        f"Each scene is an ensemble of {args.members} throws (its velocity scaled by "
        "1, 1.01, 0.99, 1.02, ...): a single run's final error jumps by up to a decade "
        "between neighbouring tolerances, the ensemble's geometric mean much less.  "
        "Reference: each throw with scipy's control at rtol = atol = 1e-13.  Error: "
        "geometric mean over the throws of max |final centre position (m), velocity "
        "(m/s) - reference| at 5 s; cost: sum over the throws.  **Equal error**: a "
        "variant's cost interpolated (log-log, on its work-precision front) at the error "
        "scipy's control reaches at the column's tolerance, divided by scipy's cost "
        "there; below 1 is better; – where the variant's runs do not reach that error; "
        "gmean: the geometric mean of the row.  Errors near the reference's own "
        "uncertainty (given per scene) are not resolved.", ""]
    lines += ["## Summary", "",
              "A variant would replace scipy's control as the default only if it were "
              "ahead at equal error across the range on every scene.  Per scene: the "
              "geometric mean of the equal-error ratios (variant / scipy) over the "
              "columns of the tables below, and in brackets their smallest and largest.",
              "",
              "| variant | " + " | ".join(f"{n}: calls | {n}: CPU" for n in scenes) + " |",
              "|---|" + "---|---|" * len(scenes)]
    for v in chosen:
        if v == "scipy":
            continue
        cells = []
        for scene_name in scenes:
            for key in ("nfev", "cpu"):
                r = [x for _, x in equal_error(table, scene_name, v, key) if np.isfinite(x)]
                cells.append(f"{geomean(r):.2f} ({min(r):.2f}–{max(r):.2f})" if r else "–")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    lines.append("")
    for scene_name in scenes:
        unc, unc_h, ncontacts = notes[scene_name]
        lines += [f"## {scene_name}", "",
                  f"Reference uncertainty (max over the throws): scipy's control at 1e-12 "
                  f"is {unc:.1e} from it, `hairer - tol` at 1e-13 {unc_h:.1e}; contacts of "
                  f"the throws: {ncontacts}.", ""]
        for key, label in (("nfev", "RHS calls"), ("cpu", "CPU")):
            lines += [f"Equal-error {label}, variant / scipy (first row: scipy's error at "
                      "that tolerance):", "",
                      "| variant | " + " | ".join(f"{t:.0e}" for t in TARGETS) + " | gmean |",
                      "|---|" + "---|" * (len(TARGETS) + 1)]
            errors = [e for e, _ in equal_error(table, scene_name, "scipy", key)]
            lines.append("| (scipy error) | " + " | ".join(_f(e, ".1e") for e in errors)
                         + " | |")
            for v in chosen:
                if v == "scipy":
                    continue
                ratios = [r for _, r in equal_error(table, scene_name, v, key)]
                lines.append(f"| {v} | " + " | ".join(_f(r, ".2f") for r in ratios)
                             + f" | {_f(geomean(ratios), '.2f')} |")
            lines.append("")
        lines += ["Runs at every other tolerance (sums over the throws; error: their "
                  "geometric mean, and the unperturbed throw's alone):", "",
                  "| variant | rtol = atol | RHS calls | steps | rejected | LU | Jacobians "
                  "| CPU ms | error | error (throw 1) | contacts |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for v in chosen:
            for r in table[(scene_name, v)][::2]:
                status = "" if r["status"] == 0 else f" (status {r['status']})"
                same = "same" if r["contacts"] == ncontacts else str(r["contacts"])
                lines.append(f"| {v} | {r['tol']:.0e} | {r['nfev']} | {r['nstep']} | "
                             f"{r['nreject']} | {r['nlu']} | {r['njev']} | "
                             f"{1e3 * r['cpu']:.1f} | {_f(r['error'], '.1e')}{status} | "
                             f"{_f(r['error0'], '.1e')} | {same} |")
        lines.append("")
    return lines


if __name__ == "__main__":
    main()
