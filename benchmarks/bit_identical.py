"""Do two builds of ballc give the same bits?  For changes that must not change results
(a file split, a rename, a refactoring of the C core).

    python -m benchmarks.bit_identical BEFORE_SRC AFTER_SRC

BEFORE_SRC and AFTER_SRC are ``src`` directories of two checkouts with their extension
built in place (``python setup.py build_ext --inplace``), e.g. a clone of an older
commit and this tree (as for ``benchmarks/compare_builds.py``).  One child process per
build imports ballc from its ``src`` (and checks that it did), runs the cases below and
saves every array and counter of the results; the parent compares them with
``np.array_equal`` (NaN equal to NaN) and ``==``.  Exit status 0 when every case is
bit-identical, 1 otherwise.

Cases: ``ballc.simulate(ballc.Scene(), 5)`` with method radau5 and dop853 at the default
tolerances (rtol = atol = 1e-10) and at 1e-6 and 1e-3, and
``Scene(tangential_model="compliant")`` for 5 s with radau5 (default and 1e-6); the
compliant law's modes (the seed's compliant scene, dop853, and stiffness ratio 2/7 with
mu = 1, both methods, at 1e-4, 1e-6, 1e-9); five cells of the comeback map (mixture, mu)
with both methods at 1e-3; with
radau5 and dop853 at 1e-8: work_precision's stiff steel scene with ``dense_output`` (sol
on a grid compared too), the default scene with ``t_eval``, and the stress matrix's
grazing impact (vz = 0).

States are compared by name: a state only the later build has (issue 31's rolling
resistance states, last in the state) must be 0 throughout, in every case (none of them
has rolling resistance), and the states both builds have must be bit-identical.
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

CHILD = r"""
import pickle, sys
from pathlib import Path
src = Path(sys.argv[1]).resolve()
sys.path.insert(0, str(src))
import numpy as np
import ballc
assert Path(ballc.__file__).resolve().parent == src / "ballc", (ballc.__file__, str(src))
cases = [
    ("default scene, radau5, default tol", {}, dict(method="radau5")),
    ("default scene, dop853, default tol", {}, dict(method="dop853")),
    ("default scene, radau5, 1e-6", {}, dict(method="radau5", rtol=1e-6, atol=1e-6)),
    ("default scene, dop853, 1e-6", {}, dict(method="dop853", rtol=1e-6, atol=1e-6)),
    ("default scene, radau5, 1e-3", {}, dict(method="radau5", rtol=1e-3, atol=1e-3)),
    ("default scene, dop853, 1e-3", {}, dict(method="dop853", rtol=1e-3, atol=1e-3)),
    ("compliant scene, radau5, default tol", dict(tangential_model="compliant"),
     dict(method="radau5")),
    ("compliant scene, radau5, 1e-6", dict(tangential_model="compliant"),
     dict(method="radau5", rtol=1e-6, atol=1e-6)),
]
# the compliant law's modes with both methods (benchmarks.compliant_cost's scenes)
ratio = dict(tangential_model="compliant", tangential_stiffness_ratio=2 / 7,
             friction_coefficient=1.0)
for tol in (1e-4, 1e-6, 1e-9):
    cases += [
        (f"compliant scene, dop853, {tol:g}", dict(tangential_model="compliant"),
         dict(method="dop853", rtol=tol, atol=tol)),
        (f"compliant ratio 2/7 mu 1, dop853, {tol:g}", ratio,
         dict(method="dop853", rtol=tol, atol=tol)),
        (f"compliant ratio 2/7 mu 1, radau5, {tol:g}", ratio,
         dict(method="radau5", rtol=tol, atol=tol)),
    ]
# cells of the comeback map (benchmarks.comeback_map: 1.2-s throws at 1e-3, run for 5 s
# here), both methods
for mixture, mu in ((0.0, 0.0), (0.0, 0.5), (0.3, 0.2), (0.7, 1.0), (1.0, 0.6)):
    for method in ("radau5", "dop853"):
        cases.append((f"map cell mixture {mixture} mu {mu}, {method}, 1e-3",
                      dict(mixture=mixture, friction_coefficient=mu),
                      dict(method=method, rtol=1e-3, atol=1e-3)))
steel = dict(tangential_model="friction", ball_youngs_modulus=2e11, plane_youngs_modulus=2e11,
             c_tau=0.5, observer_mass=0.0, position=(0.0, 0.0, 2.0), velocity=(0.5, 0.0, 0.0))
for method in ("radau5", "dop853"):
    cases += [
        (f"steel scene, {method}, 1e-8, dense output", steel,
         dict(method=method, rtol=1e-8, atol=1e-8, dense_output=True)),
        (f"default scene, {method}, 1e-8, t_eval", {},
         dict(method=method, rtol=1e-8, atol=1e-8, t_eval=np.linspace(0.0, 5.0, 501))),
        (f"grazing (stress), {method}, 1e-8", dict(tangential_model="friction",
         position=(0.0, 0.0, 1.0), velocity=(5.0, 0.0, 0.0)),
         dict(method=method, rtol=1e-8, atol=1e-10)),
    ]

def plain(value):
    # numbers, strings and arrays as they are; containers and dataclasses element-wise
    if isinstance(value, np.ndarray) or value is None or isinstance(value, (str, bool, int, float)):
        return value
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if hasattr(value, "__dataclass_fields__"):
        return {k: plain(getattr(value, k)) for k in value.__dataclass_fields__}
    if isinstance(value, np.generic):
        return value.item()
    return repr(value)

out = {}
for name, scene_kw, kw in cases:
    r = ballc.simulate(ballc.Scene(**scene_kw), 5.0, **kw)
    out[name] = {
        "t": r.t, "y": r.y, "status": r.status, "message": r.message, "nfev": r.nfev,
        "njev": r.njev, "nlu": r.nlu, "t_events": plain(r.t_events),
        "y_events": plain(r.y_events), "contacts": plain(r.contacts),
    }
    if r.sol is not None:   # the dense output, on a fine grid
        out[name]["sol"] = r.sol(np.linspace(0.0, r.t[-1], 2001))
out["__states__"] = list(ballc._core.STATE_NAMES)
with open(sys.argv[2], "wb") as f:
    pickle.dump((ballc.__file__, out), f)
"""


def run(src: Path, where: Path) -> tuple[str, dict]:
    """The cases' results from the ballc under ``src`` (a child process)."""
    target = where / f"{abs(hash(str(src)))}.pkl"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    subprocess.run([sys.executable, "-c", CHILD, str(src), str(target)], check=True,
                   env=env, cwd=where)
    with open(target, "rb") as f:
        return pickle.load(f)


def differences(a, b, path="") -> list[str]:
    """Where ``a`` and ``b`` differ (bit for bit for arrays and floats; NaN == NaN)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape or a.dtype != b.dtype:
            return [f"{path}: shape/dtype {a.shape} {a.dtype} vs {b.shape} {b.dtype}"]
        equal_nan = a.dtype.kind in "fc"
        if not np.array_equal(a, b, equal_nan=equal_nan):
            if equal_nan:
                worst = np.nanmax(np.abs(a - b)) if a.size else 0.0
                return [f"{path}: arrays differ (max |diff| {worst:.3g})"]
            return [f"{path}: arrays differ"]
        return []
    if isinstance(a, dict) and isinstance(b, dict):
        # a field only the later build has (a contact's new column) is no difference
        # of results while it says nothing (NaN); fields both have must be equal
        added = [k for k in b if k not in a and not _blank(b[k])]
        removed = [k for k in a if k not in b]
        if added or removed:
            return [f"{path}: keys only before {sorted(removed)}, only after {sorted(added)}"]
        return [d for k in a for d in differences(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} vs {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return []
    return [] if a == b else [f"{path}: {a!r} vs {b!r}"]


def aligned(before: dict, after: dict) -> tuple[dict, list[str]]:
    """``after`` with its state rows (y, sol) and columns (y_events) in the order of
    ``before``'s states, and the differences of the states only ``after`` has (they
    must be 0 throughout)."""
    names_a, names_b = before["__states__"], after["__states__"]
    if names_a == names_b:
        return after, []
    missing = [name for name in names_a if name not in names_b]
    if missing:
        return after, [f"states only before: {missing}"]
    keep = [names_b.index(name) for name in names_a]
    extra = [i for i, name in enumerate(names_b) if name not in names_a]
    found, problems = {"__states__": names_a}, []
    for case, result in after.items():
        if case == "__states__":
            continue
        result = dict(result)
        for key in ("y", "sol"):
            if key in result:
                rows = np.asarray(result[key])
                if np.any(rows[extra] != 0):
                    problems.append(f"{case}.{key}: a state only after is not 0")
                result[key] = rows[keep]
        events = []
        for block in result["y_events"]:
            block = np.asarray(block)
            if block.size and np.any(block[:, extra] != 0):
                problems.append(f"{case}.y_events: a state only after is not 0")
            events.append(block[:, keep] if block.ndim == 2 else block)
        result["y_events"] = events
        found[case] = result
    return found, problems


def _blank(value) -> bool:
    """Whether a field's value says nothing: NaN, or empty."""
    try:
        return bool(np.all(np.isnan(np.asarray(value, dtype=float))))
    except (TypeError, ValueError):
        return value in (None, [], "")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path, help="src/ of the first build")
    parser.add_argument("after", type=Path, help="src/ of the second build")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        file_a, before = run(args.before.resolve(), Path(tmp))
        file_b, after = run(args.after.resolve(), Path(tmp))
    print(f"before: {file_a}\nafter:  {file_b}")
    before.setdefault("__states__", after.get("__states__"))
    after, problems = aligned(before, after)
    failed = bool(problems)
    for d in problems:
        print("DIFFERENT  " + d)
    for name in before:
        if name == "__states__":
            continue
        diff = differences(before[name], after[name])
        a = before[name]
        summary = f"{len(a['t'])} points, nfev {a['nfev']}, njev {a['njev']}, nlu {a['nlu']}"
        print(f"{'identical' if not diff else 'DIFFERENT'}  {name}  ({summary})")
        for d in diff[:10]:
            print("    " + d)
        failed |= bool(diff)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
