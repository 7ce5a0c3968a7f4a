"""Plant known defects, one at a time, and check that the default test suite catches each.

    python -m benchmarks.plant_defects [--only NAME ...] [--full] [--no-baseline] [--keep]
                                       [--tests PATH ...]

For each defect: copy the working tree (without .git, build products, caches) to a
temporary directory, apply one text substitution (the pattern must occur exactly the
expected number of times, or the script stops with an error: a refactoring must not
turn a planted defect into a silent no-op), regenerate the C kernels with
``python -m codegen`` when the defect is in codegen/ (and check that generated/ did
change), rebuild the extensions (``python setup.py build_ext --inplace``) and run the
default suite there (``python -m pytest -q -x -p no:cacheprovider``, PYTHONPATH = the
copy's src; ``--full``: without -x, to count every failing test; ``--tests``: only
these test files, e.g. to see which oracle tests catch what).  A clean copy is run
first (the baseline) so that a "caught" cannot be a failure that was there already.

Prints a table: defect, failing tests (with -x: 1 = caught, the first failing test
named), time.  Takes ~2-4 min per defect on 2 cores (mostly compiling).  Not part of the
test suite.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IGNORE = shutil.ignore_patterns(".git", "build", "dist", "__pycache__", "*.so", "*.egg-info",
                                ".pytest_cache", ".hypothesis", "ballc-demo")


@dataclass(frozen=True)
class Defect:
    name: str
    path: str            # file in the repository
    old: str             # exact text to replace
    new: str
    regenerate: bool     # codegen/ changed: run python -m codegen in the copy
    count: int = 1       # expected number of occurrences of ``old``


DEFECTS = [
    Defect("ceiling damping sign flipped (HC normal force of the friction law)",
           "codegen/contact.py",   # coulomb_friction and no_friction (its normal share)
           "    f_n = normal_force(rhodot)\n",
           "    f_n = normal_force(rhodot if plane == 'floor' else -rhodot)\n",
           regenerate=True, count=2),
    Defect("Hertz exponent 3/2 -> 1.4 (hertz_normal's force: every law)", "codegen/contact.py",
           "    return k0 * rho_pos**sm.Rational(3, 2), ",
           "    return k0 * rho_pos**sm.Rational(7, 5), ", regenerate=True),
    Defect("tangential dissipation rate sign flipped", "codegen/contact.py",
           "    tangential = -me.dot(tangential_force, velocity)\n",
           "    tangential = me.dot(tangential_force, velocity)\n",
           regenerate=True),
    Defect("compliant: tangential stiffness factor 1 instead of 3/2 (k_t * 2/3)",
           "codegen/contact.py",
           '    return model.p["tangential_stiffness_ratio"] * stiffness\n',
           '    return model.p["tangential_stiffness_ratio"] * stiffness * sm.Rational(2, 3)\n',
           regenerate=True),
    Defect("compliant: yield exponent 64 -> 2", "codegen/contact.py",
           "YIELD_EXPONENT = 64\n", "YIELD_EXPONENT = 2\n", regenerate=True),
    Defect("compliant: tangential damping sign flipped (viscous = +c_t v)",
           "codegen/contact.py",
           "    viscous = [-c_t * v for v in slip]\n",
           "    viscous = [c_t * v for v in slip]\n", regenerate=True),
    Defect("compliant: dilution (loading) term dropped", "codegen/contact.py",
           "    dilution = _positive(rhodot) / (2 * _rho_floor(rho)) if dilute ",
           "    dilution = sm.S.Zero if dilute ", regenerate=True),
    Defect("compliant modes: the sliding force at 0.9 of the cap", "codegen/contact.py",
           "    force = [-cap * ex, -cap * ey]\n",
           "    force = [-0.9 * cap * ex, -0.9 * cap * ey]\n", regenerate=True),
    Defect("compliant modes: the sliding spring does not turn with the slip",
           "codegen/contact.py",
           "    rate = [in_contact * ((v - along * e) * turn + w)\n",
           "    rate = [in_contact * ((v - along * e) * 0 + w)\n", regenerate=True),
    # in the C loop, the one driver (issue 29)
    Defect("C loop: per-contact energy split swapped (normal <-> tangential)",
           "src/ballc/_driver.c",
           "    rec->lost[0] = r->y[BALLC_STATE_DISSIPATED_NORMAL] - r->dissipated_at_start[p][0];\n"
           "    rec->lost[1] = r->y[BALLC_STATE_DISSIPATED_TANGENTIAL] - "
           "r->dissipated_at_start[p][1];\n",
           "    rec->lost[1] = r->y[BALLC_STATE_DISSIPATED_NORMAL] - r->dissipated_at_start[p][0];\n"
           "    rec->lost[0] = r->y[BALLC_STATE_DISSIPATED_TANGENTIAL] - "
           "r->dissipated_at_start[p][1];\n", regenerate=False),
    Defect("C loop: start-in-contact latch without the observer mass", "src/ballc/_driver.c",
           "pow(rho, 2.5) / c->total_mass;\n",
           "pow(rho, 2.5) / c->params[BALLC_PARAMETER_MASS];\n", regenerate=False),
    # each caught by its own test (named), not by a comparison of two drivers
    Defect("C loop: dig-in direction latched reversed", "src/ballc/_driver.c",  # test_physics
           "direction[i] = v[i] / speed;", "direction[i] = -v[i] / speed;", regenerate=False),
    Defect("C loop: slip from rest starts along +lambda (settle)", "src/ballc/_driver.c",
           "double d[2] = {-out[0] / size, -out[1] / size};",   # test_stickslip
           "double d[2] = {out[0] / size, out[1] / size};", regenerate=False),
    Defect("C loop: compliant modes, a yield never slides", "src/ballc/_driver.c",
           "    if (m[1] >= 0) {\n", "    if (m[1] >= 1e300) {\n",   # test_compliant_modes
           regenerate=False),
    Defect("C loop: compliant elastic mode, the viscous capacity's kink not guarded",
           "src/ballc/_driver.c", "if (elastic && c->damping_positive) {",
           "if (elastic && 0) {", regenerate=False),   # test_compliant_modes
    Defect("C loop: compliant modes, a sliding start's slip direction loses the sign of u_y",
           "src/ballc/_driver.c", "    along[1] = length * u[1] / speed;",   # test_impact
           "    along[1] = length * fabs(u[1]) / speed;", regenerate=False),
    Defect("impact's tangential restitution e_t sign flipped", "src/ballc/impact.py",
           "    e_t = -float(ua @ ub) / slip2 if ",
           "    e_t = float(ua @ ub) / slip2 if ", regenerate=False),
    Defect("sweep rows stored in completion order (local pool)", "src/ballc/sweep.py",
           "        rows[start + offset] = row\n",
           "        rows[rows.index(None)] = row\n", regenerate=False),
    Defect("Coulomb cone off by 2 (stick holds until |lambda| = 2 mu N)", "src/ballc/_system.c",
           "    out[3] = params[BALLC_PARAMETER_FRICTION_COEFFICIENT] * ev.load[plane]\n",
           "    out[3] = 2 * params[BALLC_PARAMETER_FRICTION_COEFFICIENT] * ev.load[plane]\n",
           regenerate=False),
    Defect("compliant sliding: the rho'' share of ds_cap/dt left out (the contact's own "
           "acceleration only)", "src/ballc/_system.c",
           "            for (int i = 0; i < 4; i++) xdot[target[i]] += coefficients[i] * rho_dd;\n",
           "            for (int i = 0; i < 4; i++) xdot[target[i]] += 0 * coefficients[i] * rho_dd;\n",
           regenerate=False),
    Defect("rigid map: r instead of r^2 in the tangential mass", "src/ballc/rigid.py",
           "tangential_mass = 1.0 / (1.0 / mass + radius ** 2 / inertia)",
           "tangential_mass = 1.0 / (1.0 / mass + radius / inertia)", regenerate=False),
    Defect("rigid map: tangential restitution sign flipped (1 - e_t)", "src/ballc/rigid.py",
           "p_t = -tangential_mass * (1 + tangential_restitution) * u",
           "p_t = -tangential_mass * (1 - tangential_restitution) * u", regenerate=False),
    Defect("radau5 T[0][0] off in its 7th significant digit", "src/ballc/_radau_iia.c",
           "{0.09443876248897524, -0.14125529502095421, 0.03002919410514742}",
           "{0.09443877248897524, -0.14125529502095421, 0.03002919410514742}",
           regenerate=False),
]


def run(cmd, cwd, env, log, timeout):
    """Run ``cmd``; append its output to ``log``; return (returncode, output)."""
    proc = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=timeout)
    with open(log, "a") as f:
        f.write(f"$ {' '.join(cmd)}\n{proc.stdout}\n")
    return proc.returncode, proc.stdout


def plant(copy: Path, defect: Defect):
    target = copy / defect.path
    text = target.read_text()
    found = text.count(defect.old)
    if found != defect.count:
        raise SystemExit(f"defect {defect.name!r}: pattern found {found} times in "
                         f"{defect.path} (expected {defect.count}); update DEFECTS:\n"
                         f"{defect.old!r}")
    target.write_text(text.replace(defect.old, defect.new))


def summary_of(output: str):
    """(failed + errors, passed, first failing test id) from pytest -q output."""
    counts = {}
    for key in ("failed", "passed", "error", "errors"):
        m = re.findall(rf"(\d+) {key}\b", output)
        counts[key] = int(m[-1]) if m else 0
    first = re.search(r"^(?:FAILED|ERROR) (\S+)", output, re.MULTILINE)
    return (counts["failed"] + counts["error"] + counts["errors"], counts["passed"],
            first.group(1) if first else "")


def check_one(defect: Defect | None, full: bool, keep: bool, timeout: float, tests=()):
    started = time.perf_counter()
    copy = Path(tempfile.mkdtemp(prefix="ballc-defect-")) / "repo"
    shutil.copytree(ROOT, copy, ignore=IGNORE)
    log = copy.parent / "log.txt"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(copy / "src"), str(copy)]),
           "PYTHONDONTWRITEBYTECODE": "1"}
    try:
        if defect is not None:
            plant(copy, defect)
            if defect.regenerate:
                before = {p.name: p.read_text() for p in (copy / "generated").iterdir()}
                rc, out = run([sys.executable, "-m", "codegen"], copy, env, log, timeout)
                if rc != 0:
                    raise SystemExit(f"python -m codegen failed for {defect.name!r}:\n{out}")
                after = {p.name: p.read_text() for p in (copy / "generated").iterdir()}
                kernels = {k for k in after if k.endswith(".c")}
                if all(before.get(k) == after[k] for k in kernels):
                    raise SystemExit(f"defect {defect.name!r} did not change the generated "
                                     "kernels")
        rc, out = run([sys.executable, "setup.py", "build_ext", "--inplace"], copy, env, log,
                      timeout)
        if rc != 0:
            raise SystemExit(f"build failed ({defect and defect.name}); see {log}")
        rc, out = run([sys.executable, "-c", "import ballc; print(ballc.__file__)"], copy, env,
                      log, 60)
        if not out.strip().startswith(str(copy)):
            raise SystemExit(f"the copy imports ballc from {out.strip()}, not from {copy}")
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
        if not full:
            cmd.append("-x")
        cmd.extend(tests)
        rc, out = run(cmd, copy, env, log, timeout)
        failing, passed, first = summary_of(out)
        if rc not in (0, 1):     # 2: interrupted, 3: internal error, 4: usage, 5: no tests
            raise SystemExit(f"pytest exited with {rc}; see {log}\n{out[-2000:]}")
        return failing, passed, first, time.perf_counter() - started
    finally:
        if not keep:
            shutil.rmtree(copy.parent, ignore_errors=True)
        else:
            print(f"    kept {copy} (log: {log})", flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="*", default=None,
                        help="run only defects whose name contains one of these words")
    parser.add_argument("--full", action="store_true",
                        help="run the whole suite (no -x): count every failing test")
    parser.add_argument("--no-baseline", action="store_true",
                        help="skip the run of the unmodified copy")
    parser.add_argument("--keep", action="store_true", help="keep the temporary copies")
    parser.add_argument("--tests", nargs="*", default=[],
                        help="test files or ids to run instead of the default suite")
    parser.add_argument("--timeout", type=float, default=1800,
                        help="seconds per command (default 1800)")
    args = parser.parse_args(argv)

    defects = [d for d in DEFECTS
               if args.only is None or any(w.lower() in d.name.lower() for w in args.only)]
    rows = []
    for defect in ([None] if not args.no_baseline else []) + defects:
        name = defect.name if defect else "(baseline: no defect)"
        print(f"... {name}", flush=True)
        failing, passed, first, seconds = check_one(defect, args.full, args.keep,
                                                    args.timeout, args.tests)
        if defect is None:
            verdict = "clean" if failing == 0 else "BASELINE FAILS"
        else:
            verdict = "caught" if failing else "NOT caught"
        rows.append((name, verdict, failing, passed, first, seconds))
        print(f"    {verdict}: {failing} failing, {passed} passed, {seconds:.0f} s "
              f"{first}", flush=True)

    mode = ("whole suite" if args.full else "-x: stops at the first failure") + (
        f"; only {' '.join(args.tests)}" if args.tests else "")
    print(f"\n| defect | verdict | failing tests ({mode}) | first failing test | time (s) |")
    print("|---|---|---|---|---|")
    for name, verdict, failing, passed, first, seconds in rows:
        print(f"| {name} | {verdict} | {failing} ({passed} passed) | {first or '-'} | "
              f"{seconds:.0f} |")
    missed = [r[0] for r in rows if r[1] in ("NOT caught", "BASELINE FAILS")]
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
