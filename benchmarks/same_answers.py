"""Do two builds of ballc give the same answers, to within each run's own integration error?

    python -m benchmarks.same_answers BEFORE_SRC AFTER_SRC [--quick] [--only TEXT] [--verbose]

For changes that may move bits but must not move results (issue 29: the C loop became
the only driver; its numerics no longer reproduce CPython's ``hypot`` or the BLAS ``dot``).
BEFORE_SRC and AFTER_SRC are ``src`` directories of two checkouts with their extension
built in place (``python setup.py build_ext --inplace``), e.g. a clone of d33fe92 (the last
main with two drivers) and this tree.

One child process per build imports ballc from its ``src`` (and checks that it did) and runs
the cases; the AFTER build also runs each case's *reference*: the same scene at a tolerance
1000 times tighter (at most 1e-13, radau5).  For each case the printed quantities are the
status, the contact times (start, end) and the final mechanical state (centre, velocity,
angular velocity; the quaternion as the rotation it stands for), and

* ``error``: the BEFORE run's own error, its distance to the reference;
* ``moved``: the distance between the BEFORE and AFTER runs;
* ``after's error``: the AFTER run's distance to the same reference (printed, not scored:
  by the triangle inequality moved <= error + after's error, so a case that fails has an
  AFTER run farther from the reference than the BEFORE run in that quantity).

A case passes when both runs end with the same status and the same number of contacts on the
same planes, and ``moved <= 3 error + floor`` for every quantity (floor: 1e-12 of the
quantity's scale).  A chaotic case (the comeback map at rtol 1e-3 over 1.2 s) has a large
error of its own, which then bounds what may move; that is what "within its error" means.
A case whose BEFORE and AFTER statuses differ fails whatever its error.

Cases: the seed scene for 5 s at rtol = atol = 1e-6 and 1e-10 with every method (radau5,
dop853, auto and scipy's Radau, BDF, LSODA, DOP853, RK45, RK23; scipy at 1e-10 only
"Radau" and "DOP853": the others crawl there), the comeback map's 16 cells with radau5 and
dop853 at 1e-3, the compliant throw (``Scene(tangential_model="compliant")``, 5 s, both
methods), a steel ball (both methods, 1e-8), ``simulate(Scene(), 1e9)`` (its orbit: the
period and the final state compared), and the stress matrix (tests/test_stress.py: every
``simulate`` call its tests make, with radau5 and with dop853, recorded in the child).
Exit status 0 when every case passes.  Takes ~10-20 min on 2 cores (``--quick``: ~2 min).
"""
from __future__ import annotations

import argparse
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent

CHILD = r"""
import importlib.util, pickle, sys, warnings
from pathlib import Path
src, out, root, quick, only, reference = (Path(sys.argv[1]).resolve(), sys.argv[2],
                                          Path(sys.argv[3]), sys.argv[4] == "1", sys.argv[5],
                                          sys.argv[6] == "1")
sys.path.insert(0, str(src))
import numpy as np
import ballc
assert Path(ballc.__file__).resolve().parent == src / "ballc", (ballc.__file__, str(src))
warnings.simplefilter("ignore")
spec = importlib.util.spec_from_file_location("same_answers_cases", root / "benchmarks" / "same_answers.py")
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
cases = module.cases(quick, root)
results = {}
for name, fields, t_end, kw in cases:
    if only and only not in name:
        continue
    if reference:
        tol = max(min(kw.get("rtol", 1e-10), kw.get("atol", 1e-10)) * 1e-3, 1e-13)
        kw = dict(kw, method="radau5", rtol=tol, atol=tol, max_nfev=None)
        kw.pop("first_step", None)
    try:
        r = ballc.simulate(ballc.Scene(**fields), t_end, **kw)
    except Exception as error:   # a case a build refuses: recorded, compared as a status
        results[name] = {"error": f"{type(error).__name__}: {error}"}
        continue
    results[name] = module.summary(r)
with open(out, "wb") as f:
    pickle.dump(results, f)
"""


def summary(result) -> dict:
    """What a run amounts to: status, contacts, final mechanical state, the message."""
    y = result.y[:, -1]
    q = y[:4] / np.linalg.norm(y[:4])
    return {
        "status": int(result.status),
        "message": result.message,
        "t_last": float(result.t[-1]),
        "planes": [c.plane for c in result.contacts],
        "t_start": np.array([c.t_start for c in result.contacts], dtype=float),
        "t_end": np.array([c.t_end for c in result.contacts], dtype=float),
        "position": np.array(y[4:7], dtype=float),
        "angular_velocity": np.array(y[7:10], dtype=float),
        "velocity": np.array(y[10:13], dtype=float),
        "rotation": _rotation(q),
    }


def _rotation(q):
    w, x, y, z = q
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def stress_cases(root: Path) -> list:
    """Every simulate call tests/test_stress.py's tests make, with radau5 and dop853: the
    tests are run with ballc.simulate replaced by a recorder (their assertions ignored)."""
    import importlib.util
    import inspect
    import itertools

    import ballc
    spec = importlib.util.spec_from_file_location("stress_matrix", root / "tests" / "test_stress.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    recorded = []

    class Recorded(Exception):
        pass

    def recorder(scene, t_end, **kw):
        recorded.append((scene.to_dict() if hasattr(scene, "to_dict") else {}, t_end, kw))
        raise Recorded

    class MonkeyPatch:   # what the tests' monkeypatch fixture is asked for
        def setattr(self, *args, **kwargs):
            pass

    real = ballc.simulate
    ballc.simulate = recorder
    try:
        for name, function in inspect.getmembers(module, inspect.isfunction):
            if not name.startswith("test_"):
                continue
            marks = getattr(function, "pytestmark", [])
            axes = []
            for m in marks:
                if m.name != "parametrize":
                    continue
                names = [n.strip() for n in m.args[0].split(",")]
                axes.append([dict(zip(names, v if len(names) > 1 else (v,))) for v in m.args[1]])
            for combo in itertools.product(*axes) if axes else [()]:
                kwargs = {}
                for part in combo:
                    kwargs.update(part)
                if "monkeypatch" in inspect.signature(function).parameters:
                    kwargs["monkeypatch"] = MonkeyPatch()
                try:
                    function(**kwargs)
                except Recorded:
                    pass
                except Exception:
                    pass
    finally:
        ballc.simulate = real
    out = []
    for k, (fields, t_end, kw) in enumerate(recorded):
        for method in ("radau5", "dop853"):
            kw_method = dict(kw, method=method)
            shown = ", ".join(f"{key}={value:g}" for key, value in sorted(kw_method.items())
                              if isinstance(value, float))
            out.append((f"stress {k} {method} t_end={t_end:g} {shown}", fields, t_end, kw_method))
    return out


def cases(quick: bool, root: Path) -> list:
    """(name, Scene fields, t_end, simulate keywords)."""
    out = []
    tols = (1e-6,) if quick else (1e-6, 1e-10)
    for tol in tols:
        methods = ["radau5", "dop853", "auto", "Radau", "DOP853"]
        if tol > 1e-8 and not quick:
            methods += ["BDF", "LSODA", "RK45", "RK23"]
        for method in methods:
            out.append((f"seed 5 s {method} {tol:g}", {}, 5.0,
                        dict(method=method, rtol=tol, atol=tol)))
    mixtures, mus = ((0.0, 0.3), (0.2, 1.0)) if quick else ((0.0, 0.3, 0.7, 1.0),
                                                            (0.0, 0.2, 0.5, 1.0))
    for m in mixtures:
        for mu in mus:
            for method in ("radau5", "dop853"):
                out.append((f"map m={m} mu={mu} {method}", dict(mixture=m, friction_coefficient=mu),
                            1.2, dict(method=method, rtol=1e-3, atol=1e-3)))
    for method in ("radau5", "dop853"):
        out.append((f"compliant throw 5 s {method}", dict(tangential_model="compliant"), 5.0,
                    dict(method=method)))
        out.append((f"steel ball 5 s {method} 1e-8", dict(
            tangential_model="friction", ball_youngs_modulus=2e11, plane_youngs_modulus=2e11,
            c_tau=0.5, observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0)),
            5.0, dict(method=method, rtol=1e-8, atol=1e-8)))
    out.append(("seed 1e9 s", {}, 1e9, {}))
    if not quick:
        out += stress_cases(root)
    return out


def run(src: Path, where: Path, quick: bool, only: str, reference: bool) -> dict:
    target = where / f"{abs(hash((str(src), reference)))}.pkl"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BALLC_PYTHON_DRIVER")}
    subprocess.run([sys.executable, "-c", CHILD, str(src), str(target), str(ROOT),
                    "1" if quick else "0", only, "1" if reference else "0"],
                   check=True, env=env, cwd=where)
    with open(target, "rb") as f:
        return pickle.load(f)


QUANTITIES = ("t_start", "t_end", "position", "velocity", "angular_velocity", "rotation")


def distance(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return np.inf
    both_nan = np.isnan(a) & np.isnan(b)
    d = np.abs(np.where(both_nan, 0.0, a - b))
    return float(np.nanmax(np.where(np.isnan(d), np.inf, d), initial=0.0))


def compare(before: dict, after: dict, reference: dict | None) -> tuple[bool, list[str]]:
    """Whether ``after`` is ``before`` to within before's own error; the lines to print."""
    if "error" in before or "error" in after:
        same = before.get("error") == after.get("error")
        return same, [f"    before: {before.get('error', 'ran')}; after: {after.get('error', 'ran')}"]
    lines, ok = [], True
    if before["status"] != after["status"]:
        ok = False
        lines.append(f"    status {before['status']} -> {after['status']}: {after['message'][:100]}")
    if before["planes"] != after["planes"]:
        ok = False
        lines.append(f"    contacts {len(before['planes'])} -> {len(after['planes'])}")
    for key in QUANTITIES:
        moved = distance(before[key], after[key])
        if reference is None or "error" in reference or reference["planes"] != before["planes"]:
            error = after_error = np.inf if reference is not None else 0.0
        else:
            error = distance(before[key], reference[key])
            after_error = distance(after[key], reference[key])
        scale = float(np.nanmax(np.abs(np.asarray(before[key], dtype=float)), initial=1.0))
        floor = 1e-12 * max(scale, 1.0)
        passed = moved <= 3 * error + floor
        ok &= passed or before["planes"] != after["planes"]
        lines.append(f"    {'ok ' if passed else 'BAD'} {key:17s} moved {moved:9.3g}  error {error:9.3g}"
                     f"  (after's error {after_error:9.3g})")
    return ok, lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path, help="src/ of the first build (e.g. d33fe92)")
    parser.add_argument("after", type=Path, help="src/ of the second build (this tree)")
    parser.add_argument("--quick", action="store_true", help="a few cases of each kind")
    parser.add_argument("--only", default="", help="only the cases whose name contains this")
    parser.add_argument("--verbose", action="store_true",
                        help="print every case's quantities, not only those that differ")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        before = run(args.before.resolve(), Path(tmp), args.quick, args.only, False)
        after = run(args.after.resolve(), Path(tmp), args.quick, args.only, False)
        reference = run(args.after.resolve(), Path(tmp), args.quick, args.only, True)
    failed = 0
    for name in before:
        ok, lines = compare(before[name], after.get(name, {"error": "missing"}), reference.get(name))
        failed += not ok
        status = before[name].get("status", "-")
        print(f"{'same     ' if ok else 'DIFFERENT'} {name} (status {status})")
        if not ok or args.only or args.verbose:
            print("\n".join(lines))
    print(f"{len(before) - failed} of {len(before)} cases the same within their own error")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
