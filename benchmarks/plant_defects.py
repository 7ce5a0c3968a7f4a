"""Plant known defects, one at a time, and check that the default test suite catches each
by an ordinary assertion.

    python -m benchmarks.plant_defects [--only WORD ...] [--jobs N] [--codegen-jobs N]
                                       [--suite] [--no-suite] [--tests ID ...] [--check]
                                       [--keep] [--cache DIR]

Every entry of DEFECTS is one text substitution in one file (the pattern must occur
exactly ``count`` times on the current tree, or nothing runs: a refactoring must not
turn a planted defect into a silent no-op; ``--check`` checks only that, and
tests/test_plant_defects.py checks it in the default run) and names the test(s) that
should catch it.

One work copy of the tree per job (``--jobs``, default 1), copied once (without .git
and build products) and built once.  For each defect, in that copy:

1. plant it; a defect in codegen/ gets the generated C of the planted generator (made
   by ``python -m codegen`` in a copy of codegen/ alone, in background processes
   (``--codegen-jobs``) while other defects run, and cached by the hash of codegen/'s
   text: a later run reuses it); generated/ must change;
2. rebuild only when a compiled source changed (``setup.py build_ext --inplace`` with
   ``benchmarks/compile_cache.py`` as the compiler: a source whose preprocessed text
   is unchanged is a copy from the object cache, so a defect in one C file recompiles
   that file, and taking it out again is a link);
3. run its named tests (``pytest -x``); only if they do not catch it, the rest of the
   default suite (``pytest -x``, after one run of the unplanted suite, the baseline);
4. restore the file (and generated/).

A defect is *caught* when a test fails by an assertion (AssertionError, pytest.fail,
pytest.raises not raising) or by another exception raised in a test ("error", also a
catch but named as such).  A test that hits its pytest-timeout (``--test-timeout``,
default the project's 300 s), a pytest run killed by ``--timeout``, a crash of pytest
or a failed build is never a catch: it is reported as "timeout" or "crash" and the
defect counts as not caught.  Before the defects, the named tests run on the
unplanted copy (the baseline), so that a catch cannot be a failure that was there
already.

Prints a line per defect as it finishes, then a table: defect, verdict, how it was
caught (the failing test, assertion / error / timeout and the failure's first line,
named test or suite), time.  Caches (objects, generated C) live in ``--cache``
(default $XDG_CACHE_HOME/ballc-plant-defects or ~/.cache/ballc-plant-defects).  Not part
of the test suite.  Exit status 0 when every defect was caught and the baseline passed.

Adding a defect is one ``Defect(...)`` entry: the name, the file, the exact text and
its replacement, and the test(s) that catch it (find them with ``--only NAME --suite``).
"""
from __future__ import annotations

import argparse
import hashlib
import os
import queue
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import xml.etree.ElementTree as ElementTree
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IGNORE = shutil.ignore_patterns(".git", "build", "dist", "__pycache__", "*.so", "*.egg-info",
                                ".pytest_cache", ".hypothesis", "ballc-demo", "ballc-output",
                                "_build", ".venv*")
#: the files a build compiles (a change elsewhere needs no rebuild)
COMPILED = ("src/ballc/*.c", "src/ballc/*.h", "src/ballc/*.pyx", "src/ballc/*.pxi",
            "generated/*", "setup.py")
COMPILER = [sys.executable, str(Path(__file__).resolve().parent / "compile_cache.py"),
            os.environ.get("CC", "gcc")]


@dataclass(frozen=True)
class Defect:
    name: str
    path: str                 # file in the repository
    old: str                  # exact text to replace
    new: str
    tests: tuple = ()         # the test ids that catch it: run first
    count: int = 1            # expected number of occurrences of ``old``

    @property
    def regenerate(self) -> bool:
        """A defect in the generator: generated/ is made again from it."""
        return self.path.startswith("codegen/")


DEFECTS = [
    Defect("Hunt-Crossley damping sign flipped (the friction law's normal force; every "
           "plane: the laws are generated once, in the plane's own frame)",
           "codegen/contact.py",   # coulomb_friction and no_friction (its normal share)
           "    f_n = normal_force(rhodot)\n",
           "    f_n = normal_force(-rhodot)\n", count=2,
           tests=("tests/test_oracles.py::test_hunt_crossley_impact_at_the_ceiling",)),
    Defect("Hertz exponent 3/2 -> 1.4 (hertz_normal's force: every law)", "codegen/contact.py",
           "    return k0 * rho_pos**sm.Rational(3, 2), ",
           "    return k0 * rho_pos**sm.Rational(7, 5), ",
           tests=("tests/test_physics.py::test_hertz_impact_penetration_and_duration",)),
    Defect("tangential dissipation rate sign flipped", "codegen/contact.py",
           "    tangential = -me.dot(tangential_force, velocity)\n",
           "    tangential = me.dot(tangential_force, velocity)\n",
           tests=("tests/test_oracles.py::test_friction_model_dissipation_rates_are_nonnegative",)),
    Defect("compliant: tangential stiffness factor 1 instead of 3/2 (k_t * 2/3)",
           "codegen/contact.py",
           '    return model.p["tangential_stiffness_ratio"] * stiffness\n',
           '    return model.p["tangential_stiffness_ratio"] * stiffness * sm.Rational(2, 3)\n',
           tests=("tests/test_dem_agreement.py::test_random_impacts_agree_with_the_dem_oracle",)),
    Defect("compliant: yield exponent 64 -> 2", "codegen/contact.py",
           "YIELD_EXPONENT = 64\n", "YIELD_EXPONENT = 2\n",
           tests=("tests/test_dem_agreement.py::test_smooth_yield_agrees_with_the_dem_oracle",)),
    Defect("compliant: tangential damping sign flipped (viscous = +c_t v)",
           "codegen/contact.py",
           "    viscous = [-c_t * v for v in slip]\n",
           "    viscous = [c_t * v for v in slip]\n",
           tests=("tests/test_oracles.py::test_compliant_model_dissipation_rates",)),
    Defect("compliant: dilution (loading) term dropped", "codegen/contact.py",
           "    dilution = _positive(rhodot) / (2 * _rho_floor(rho)) if dilute ",
           "    dilution = sm.S.Zero if dilute ",
           tests=("tests/test_oracles.py::test_compliant_single_impact_does_not_gain_energy",)),
    Defect("compliant modes: the sliding force at 0.9 of the cap", "codegen/contact.py",
           "    force = [-cap * ex, -cap * ey]\n",
           "    force = [-0.9 * cap * ex, -0.9 * cap * ey]\n",
           tests=("tests/test_compliant_modes.py::"
                  "test_sliding_carries_the_cap_and_elastic_stays_below_it",)),
    Defect("compliant modes: the sliding spring does not turn with the slip",
           "codegen/contact.py",
           "    across = [(v - along * e) * turn for v, e in zip((vx, vy), (ex, ey))]\n",
           "    across = [(v - along * e) * 0 for v, e in zip((vx, vy), (ex, ey))]\n",
           tests=("tests/test_compliant_modes.py::"
                  "test_the_sliding_spring_turns_with_the_slip_as_the_dem_truncation_does",)),
    # the two above in the C loop, which the default runs take (issue 29)
    Defect("C loop: per-contact energy split swapped (normal <-> tangential)",
           "src/ballc/_driver.c",
           "    rec->lost[0] = r->y[BALLC_STATE_DISSIPATED_NORMAL] - r->dissipated_at_start[p][0];\n"
           "    rec->lost[1] = r->y[BALLC_STATE_DISSIPATED_TANGENTIAL] - "
           "r->dissipated_at_start[p][1];\n",
           "    rec->lost[1] = r->y[BALLC_STATE_DISSIPATED_NORMAL] - r->dissipated_at_start[p][0];\n"
           "    rec->lost[0] = r->y[BALLC_STATE_DISSIPATED_TANGENTIAL] - "
           "r->dissipated_at_start[p][1];\n",
           tests=("tests/test_physics.py::test_contact_energy_split_between_normal_and_tangential",)),
    Defect("C loop: start-in-contact latch without the observer mass", "src/ballc/_driver.c",
           "pow(rho, 2.5) / c->total_mass;\n",
           "pow(rho, 2.5) / c->params[BALLC_PARAMETER_MASS];\n",
           tests=("tests/test_stickslip.py::test_start_in_contact_latch_counts_the_observer_mass",)),
    # the C loop's copies of defects planted above in Python that only the Python
    # driver runs (each caught without a comparison of the drivers: the test named)
    Defect("C loop: dig-in direction latched reversed", "src/ballc/_driver.c",
           "direction[i] = v[i] / speed;", "direction[i] = -v[i] / speed;",
           tests=("tests/test_physics.py::test_vertical_drop_never_moves_horizontally",)),
    Defect("C loop: slip from rest starts along +lambda (settle)", "src/ballc/_driver.c",
           "double d[2] = {-out[0] / size, -out[1] / size};",
           "double d[2] = {out[0] / size, out[1] / size};",
           tests=("tests/test_stickslip.py",)),
    Defect("C loop: compliant modes, a yield never slides", "src/ballc/_driver.c",
           "    if (m[1] >= 0) {\n", "    if (m[1] >= 1e300) {\n",
           tests=("tests/test_compliant_modes.py",)),
    Defect("C loop: compliant elastic mode, the viscous capacity's kink not guarded",
           "src/ballc/_driver.c", "if (elastic && c->damping_positive) {",
           "if (elastic && 0) {",
           tests=("tests/test_compliant_modes.py",
                  "tests/test_automaton.py::test_the_default_run_takes_every_row")),
    Defect("C loop: compliant modes, a sliding start's slip direction loses the sign of u_y",
           "src/ballc/_driver.c", "    along[1] = length * u[1] / speed;",
           "    along[1] = length * fabs(u[1]) / speed;",
           tests=("tests/test_impact.py::test_impact_agrees_with_a_full_throw",)),
    Defect("impact's tangential restitution e_t sign flipped", "src/ballc/impact.py",
           "    e_t = -float(ua @ ub) / slip2 if ",
           "    e_t = float(ua @ ub) / slip2 if ",
           tests=("tests/test_impact.py::test_tangential_restitution_in_gross_sliding",)),
    Defect("sweep rows stored in completion order (local pool)", "src/ballc/sweep.py",
           "        rows[start + offset] = row\n",
           "        rows[rows.index(None)] = row\n",
           tests=("tests/test_sweep.py::"
                  "test_rows_follow_the_grid_whatever_order_the_runs_complete_in",)),
    Defect("Coulomb cone off by 2 (stick holds until |lambda| = 2 mu N)", "src/ballc/_system.c",
           "    out[3] = params->values[BALLC_PARAMETER_FRICTION_COEFFICIENT] * ev.load[plane]\n",
           "    out[3] = 2 * params->values[BALLC_PARAMETER_FRICTION_COEFFICIENT] * ev.load[plane]\n",
           tests=("tests/test_stickslip.py::test_stick_releases_where_the_coulomb_cone_says",)),
    Defect("compliant sliding: the rho'' share of ds_cap/dt left out (the contact's own "
           "acceleration only)", "src/ballc/_system.c",
           "            for (int i = 0; i < 4; i++) xdot[target[i]] += coefficients[i] * rho_dd;\n",
           "            for (int i = 0; i < 4; i++) xdot[target[i]] += 0 * coefficients[i] * rho_dd;\n",
           tests=("tests/test_passivity.py::"
                  "test_a_heavy_observer_keeps_the_sliding_spring_at_the_cap",)),
    Defect("rigid map: r instead of r^2 in the tangential mass", "src/ballc/rigid.py",
           "tangential_mass = 1.0 / (1.0 / mass + radius ** 2 / inertia)",
           "tangential_mass = 1.0 / (1.0 / mass + radius / inertia)",
           tests=("tests/test_physics.py::test_rigid_map_is_garwins_superball_map",)),
    Defect("rigid map: tangential restitution sign flipped (1 - e_t)", "src/ballc/rigid.py",
           "p_t = -tangential_mass * (1 + tangential_restitution) * u",
           "p_t = -tangential_mass * (1 - tangential_restitution) * u",
           tests=("tests/test_physics.py::test_rigid_map_is_garwins_superball_map",)),
    Defect("radau5 T[0][0] off in its 7th significant digit", "src/ballc/_radau_iia.c",
           "{0.09443876248897524, -0.14125529502095421, 0.03002919410514742}",
           "{0.09443877248897524, -0.14125529502095421, 0.03002919410514742}",
           tests=("tests/test_radau5_constants.py::test_arrays_match_scipy",)),
    # issue 28: the three that survived, the Dask order, a flipped REST_FACTOR
    Defect("rest and orbit threshold 10x looser (REST_FACTOR 10 -> 100)", "src/ballc/resting.py",
           "REST_FACTOR = 10.0\n", "REST_FACTOR = 100.0\n",
           tests=("tests/test_resting.py::test_at_rest_is_the_documented_energy_bound",
                  "tests/test_resting.py::"
                  "test_rest_is_declared_at_the_first_check_below_the_bound")),
    Defect("rest and orbit threshold flipped (REST_FACTOR 10 -> 0.1)", "src/ballc/resting.py",
           "REST_FACTOR = 10.0\n", "REST_FACTOR = 0.1\n",
           tests=("tests/test_resting.py::test_at_rest_is_the_documented_energy_bound",
                  "tests/test_resting.py::"
                  "test_rest_is_declared_at_the_first_check_below_the_bound")),
    Defect("method='auto' switches to radau5 only when both tests fire",
           "src/ballc/_integrator.c",
           "if (s->stiff_steps < AUTO_STIFF_STEPS && !s->stiff_probe) return 0;",
           "if (s->stiff_steps < AUTO_STIFF_STEPS || !s->stiff_probe) return 0;",
           tests=("tests/test_auto_method.py::test_either_stiffness_test_switches_to_radau5",)),
    Defect("method='auto' switches to radau5 on Hairer's test alone (the probe ignored)",
           "src/ballc/_integrator.c",
           "if (s->stiff_steps < AUTO_STIFF_STEPS && !s->stiff_probe) return 0;",
           "if (s->stiff_steps < AUTO_STIFF_STEPS) return 0;",
           tests=("tests/test_auto_method.py::test_either_stiffness_test_switches_to_radau5",)),
    Defect("method='auto': the probe switches without Hairer's evidence",
           "src/ballc/_integrator.c",
           "            && s->stiff_steps >= AUTO_PROBE_EVIDENCE)\n",
           "            && 1)\n",
           tests=("tests/test_auto_method.py::test_auto_on_the_seed_scene_is_dop853",)),
    Defect("the C loop never asks for a pending signal (Ctrl-C)",
           "src/ballc/_driver_bridge.pxi",
           "        try:\n            _check_signals()\n",
           "        try:\n            pass\n",
           tests=("tests/test_c_integrators.py::test_ctrl_c_stops_a_long_segment",)),
    Defect("fit_impacts' standard errors / sqrt(2) (s^2 = cost / dof)", "src/ballc/impact.py",
           "    s2 = 2 * solution.cost / dof\n", "    s2 = solution.cost / dof\n",
           tests=("tests/test_impact.py::test_fit_standard_errors_are_the_textbook_formula",
                  "tests/test_impact.py::test_fit_standard_errors_match_the_spread_of_refits")),
    Defect("sweep rows stored in completion order (Dask)", "src/ballc/sweep.py",
           "            rows[index[future.key]] = future.result()\n",
           "            rows[rows.index(None)] = future.result()\n",
           tests=("tests/test_sweep.py::"
                  "test_dask_rows_follow_the_grid_whatever_order_they_complete_in",)),
    Defect("plane frame: a plane's normal left unnormalised", "src/ballc/_plane.c",
           "        n[i] = normal[i] / length;\n", "        n[i] = normal[i];\n",
           tests=("tests/test_plane_frame.py",)),
    Defect("plane frame: a tangent basis that is not orthogonal (t1 the axis, not made "
           "perpendicular to n)", "src/ballc/_plane.c",
           "    for (int i = 0; i < 3; i++) t1[i] = (i == k) - along * n[i];\n",
           "    for (int i = 0; i < 3; i++) t1[i] = (i == k);\n",
           tests=("tests/test_plane_frame.py",)),
    Defect("plane frame: a plane's forces not turned back", "src/ballc/_system.c",
           "        ballc_plane_to_inertial(pl, sum + BALLC_LAW_GENERALIZED_FORCE, 2);\n", "",
           tests=("tests/test_plane_frame.py",)),
    # planes at any orientation (issue 30b)
    Defect("planes: two sticking planes get no constraint force (not solved jointly)",
           "src/ballc/_system.c", "    } else if (k > 1) {\n",
           "    } else if (k > BALLC_MAX_PLANES) {\n",
           tests=("tests/test_planes.py::test_rolling_along_a_wedges_groove",)),
    Defect("planes: a tilted plane's penetration event leaves out n . p",
           "src/ballc/_driver.c",
           "            g->offset = radius + (n[0] * point[0] + n[1] * point[1] + n[2] * point[2]);\n",
           "            g->offset = radius;\n",
           tests=("tests/test_planes.py::test_the_seed_turned_as_a_whole",)),
    Defect("planes: exact flight takes gravity's z component only", "src/ballc/_driver.c",
           "        f->c[1][BALLC_STATE_VX + i] = gravity[i];\n",
           "        f->c[1][BALLC_STATE_VX + i] = i == 2 ? gravity[i] : 0.0;\n",
           tests=("tests/test_planes.py::test_a_turned_floor_keeps_its_end_state",)),
    Defect("planes: rolling down an incline in closed form without the rolling inertia",
           "src/ballc/_driver.c",
           "    double factor = 1.0 / (1.0 + c->params[BALLC_PARAMETER_INERTIA_XX] / "
           "(M * radius * radius));\n", "    double factor = 1.0;\n",
           tests=("tests/test_planes.py::test_rolling_down_an_incline_ends_in_closed_form",)),
    Defect("planes: the incline's closed form ignores the planes ahead",
           "src/ballc/_driver.c",
           "        if (ballc_flight_crossings(rho_of(r, q, y), c1, c2, 1, c->t_end - r->t, "
           "roots)) return 0;\n",
           "        if (0 && ballc_flight_crossings(rho_of(r, q, y), c1, c2, 1, "
           "c->t_end - r->t, roots)) return 0;\n",
           tests=("tests/test_planes.py::test_rolling_down_an_incline_ends_in_closed_form",)),
    # rolling resistance (issue 31)
    Defect("rolling resistance: the cap on the friction force r mu F_n instead of r F_n "
           "(mu_r r F_t of a sliding contact)", "codegen/contact.py",
           "    f_n, _ = damped_normal(model, rho, rhodot, rate_at_impact)\n    return f_n\n",
           "    f_n, _ = damped_normal(model, rho, rhodot, rate_at_impact)\n"
           "    return model.p[\"friction_coefficient\"] * f_n\n",
           tests=("tests/test_rolling.py::"
                  "test_a_rolling_ball_stops_where_and_when_the_closed_form_says",)),
    Defect("rolling resistance: the torque along the rolling direction (r F_r x n, not "
           "r n x F_r)", "codegen/contact.py",
           "    return r * me.cross(normal, force) + r * twisting_force * normal\n",
           "    return r * me.cross(force, normal) + r * twisting_force * normal\n",
           tests=("tests/test_rolling.py::"
                  "test_a_rolling_ball_stops_where_and_when_the_closed_form_says",)),
    Defect("rolling resistance on the planes: every plane's rolling springs at the first "
           "plane's states", "src/ballc/_system.c",
           "                                          + BALLC_N_ROLLING_PLANE_STATES * p : -1;\n",
           "                                          + BALLC_N_ROLLING_PLANE_STATES * 0 : -1;\n",
           tests=("tests/test_rolling.py::"
                  "test_the_floor_as_the_third_of_four_planes_stops_the_ball_as_alone",)),
    Defect("rolling resistance, sds: the slider's spring not rescaled with the cap (its "
           "radial rate dropped)", "codegen/contact.py",
           "    rate = [loaded * (a + d * growing + x * shrinking) for a, d, x in zip(across, "
           "e, xi)]\n",
           "    rate = [loaded * a for a, d, x in zip(across, e, xi)]\n",
           tests=("tests/test_rolling.py::test_the_sds_slider_decelerates_as_the_exact_model",
                  "tests/test_rolling_agreement.py::"
                  "test_ballc_sds_agrees_with_lammps_without_a_dashpot")),
]


# ---- checking the table against the tree ----

def problems_with(defects, root=ROOT):
    """What keeps DEFECTS from applying to the tree at ``root``: a pattern found another
    number of times than expected, a named test that does not exist, a codegen defect
    without a test.  [] when every entry applies."""
    found = []
    names = set()
    for defect in defects:
        if defect.name in names:
            found.append(f"{defect.name!r}: two defects with this name")
        names.add(defect.name)
        target = root / defect.path
        if not target.is_file():
            found.append(f"{defect.name!r}: no file {defect.path}")
            continue
        count = target.read_text().count(defect.old)
        if count != defect.count:
            found.append(f"{defect.name!r}: pattern found {count} times in {defect.path} "
                         f"(expected {defect.count}):\n    {defect.old!r}")
        if defect.old == defect.new:
            found.append(f"{defect.name!r}: the replacement is the pattern")
        for test in defect.tests:
            path, _, function = test.partition("::")
            function = function.split("[")[0].split("::")[-1]
            source = root / path
            if not source.is_file() or (function and f"def {function}(" not in
                                        source.read_text()):
                found.append(f"{defect.name!r}: its test {test} does not exist")
    return found


# ---- running commands ----

class Log:
    """Everything the commands printed, in one file per run (lines tagged per job)."""

    def __init__(self, path: Path):
        self.path = path
        self.lock = threading.Lock()

    def write(self, tag, text):
        with self.lock, open(self.path, "a") as f:
            f.write(f"[{tag}] {text}\n")


def run(cmd, cwd, env, log, tag, timeout):
    """(returncode or None when killed at ``timeout`` s, output).  The command runs in its
    own process group, and the whole group is killed at the timeout."""
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        rc = None
    log.write(tag, f"$ {' '.join(map(str, cmd))}  (cwd {cwd}) -> {rc}\n{out}")
    return rc, out


# ---- the generated C of a codegen defect ----

def codegen_key(codegen_dir: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted(codegen_dir.glob("*.py")):
        digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    try:
        import sympy
        digest.update(sympy.__version__.encode())
    except ImportError:
        pass
    return digest.hexdigest()


def generate(defect: Defect, cache: Path, log: Log, timeout: float) -> Path:
    """The directory of the generated files for ``defect`` (codegen run in a copy of
    codegen/ alone, or taken from the cache)."""
    with tempfile.TemporaryDirectory(prefix="ballc-codegen-") as scratch:
        copy = Path(scratch) / "codegen"
        shutil.copytree(ROOT / "codegen", copy, ignore=IGNORE)
        plant_text(copy.parent, defect)
        done = cache / "generated" / codegen_key(copy)
        if (done / "ballc_kernels.c").is_file():
            return done
        out = Path(scratch) / "out"
        env = {**os.environ, "PYTHONPATH": scratch, "PYTHONDONTWRITEBYTECODE": "1"}
        rc, text = run([sys.executable, "-m", "codegen", "--out", str(out)], scratch, env,
                       log, "codegen", timeout)
        if rc != 0:
            raise RuntimeError(f"python -m codegen failed for {defect.name!r} "
                               f"({'timeout' if rc is None else rc}); see {log.path}")
        done.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(dir=done.parent, prefix=".part-"))
        for path in out.iterdir():
            shutil.copy2(path, staging / path.name)
        try:
            staging.rename(done)
        except OSError:          # another run made it meanwhile
            shutil.rmtree(staging, ignore_errors=True)
        return done


def plant_text(root: Path, defect: Defect):
    target = root / defect.path
    text = target.read_text()
    if text.count(defect.old) != defect.count:
        raise RuntimeError(f"defect {defect.name!r}: its pattern is no longer found "
                           f"{defect.count} times in {defect.path}")
    target.write_text(text.replace(defect.old, defect.new))


# ---- test outcomes ----

@dataclass
class Outcome:
    kind: str                 # "pass", "assertion", "error", "timeout", "crash"
    test: str = ""            # the first failing test
    detail: str = ""          # its failure's first line
    failed: int = 0
    passed: int = 0

    @property
    def caught(self) -> bool:
        return self.kind in ("assertion", "error")


def _test_id(case) -> str:
    module = case.get("classname", "")
    path = module.replace(".", "/") + ".py" if module else case.get("file", "")
    return f"{path}::{case.get('name', '')}"


def outcome_of(junit: Path, rc, output: str) -> Outcome:
    """What a pytest run (its junit XML, return code and output) found."""
    if rc is None:
        return Outcome("timeout", detail="the pytest run was killed at the harness's timeout")
    if rc not in (0, 1) or not junit.is_file():
        tail = output.strip().splitlines()[-1:] or [""]
        return Outcome("crash", detail=f"pytest exited with {rc}: {tail[0][:200]}")
    suite = ElementTree.parse(junit).getroot()
    cases = list(suite.iter("testcase"))
    first, failed = None, 0
    for case in cases:
        bad = case.find("failure")
        if bad is None:
            bad = case.find("error")
        if bad is not None:
            failed += 1
            first = first or (case, bad)
    skipped = sum(1 for case in cases if case.find("skipped") is not None)
    passed = len(cases) - failed - skipped
    if first is None:
        if rc != 0:
            return Outcome("crash", detail=f"pytest exited with {rc} and no failing test",
                           passed=passed)
        return Outcome("pass", passed=passed)
    case, bad = first
    message = (bad.get("message") or "").strip()
    line = message.splitlines()[0][:200] if message else ""
    if "Timeout" in message and message.startswith("Failed: Timeout"):
        kind = "timeout"
    elif bad.tag == "failure" and (message.startswith(("AssertionError", "assert ", "Failed:"))
                                   or message.startswith("E ") or not message):
        kind = "assertion"
    else:
        kind = "error"
    if bad.tag == "error" and not line.startswith("failed on"):
        line = "(setup/teardown) " + line
    return Outcome(kind, _test_id(case), line, failed, passed)


# ---- a work copy ----

class WorkCopy:
    """A copy of the tree, built, in which defects are planted one at a time."""

    def __init__(self, where: Path, cache: Path, log: Log, tag: str, args):
        self.root = where / "repo"
        self.cache, self.log, self.tag, self.args = cache, log, tag, args
        shutil.copytree(ROOT, self.root, ignore=IGNORE)
        self.env = {**os.environ,
                    "PYTHONPATH": os.pathsep.join([str(self.root / "src"), str(self.root)]),
                    "PYTHONDONTWRITEBYTECODE": "1", "MPLBACKEND": "Agg",
                    "CC": " ".join(COMPILER), "BALLC_COMPILE_CACHE": str(cache / "objects")}
        self.env.pop("LDSHARED", None)
        self.generated = {p.name: p.read_bytes() for p in (self.root / "generated").iterdir()}
        self.built = None
        self.build()
        rc, out = run([sys.executable, "-c", "import ballc; print(ballc.__file__)"],
                      self.root, self.env, log, tag, 120)
        if rc != 0 or not out.strip().startswith(str(self.root)):
            raise RuntimeError(f"the copy imports ballc from {out.strip()!r}, not from "
                               f"{self.root}")
        self.serial = 0

    def compiled_state(self) -> str:
        digest = hashlib.sha256()
        for pattern in COMPILED:
            for path in sorted(self.root.glob(pattern)):
                digest.update(path.name.encode() + b"\0" + path.read_bytes())
        return digest.hexdigest()

    def build(self) -> bool:
        """Rebuild when a compiled source changed since the last build; False if it failed."""
        state = self.compiled_state()
        if state == self.built:
            return True
        rc, _ = run([sys.executable, "setup.py", "build_ext", "--inplace"], self.root,
                    self.env, self.log, self.tag, self.args.timeout)
        if rc != 0:
            return False
        self.built = state
        return True

    def plant(self, defect: Defect, generated: Path | None):
        self.original = (self.root / defect.path).read_text()
        plant_text(self.root, defect)
        if generated is not None:
            changed = False
            for path in generated.iterdir():
                new = path.read_bytes()
                if path.name.endswith(".c") and new != self.generated.get(path.name):
                    changed = True
                (self.root / "generated" / path.name).write_bytes(new)
            if not changed:
                raise RuntimeError(f"defect {defect.name!r} did not change the generated C")

    def restore(self, defect: Defect):
        (self.root / defect.path).write_text(self.original)
        for name, data in self.generated.items():
            path = self.root / "generated" / name
            if path.read_bytes() != data:
                path.write_bytes(data)

    def pytest(self, tests) -> Outcome:
        self.serial += 1
        junit = self.root.parent / f"junit-{self.serial}.xml"
        cmd = [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
               f"--junitxml={junit}", "-o", f"timeout={self.args.test_timeout:g}", *tests]
        rc, out = run(cmd, self.root, self.env, self.log, self.tag, self.args.timeout)
        if rc == 5 or (rc == 4 and "not found" in out):
            raise RuntimeError(f"pytest found no tests among {list(tests)} (rc {rc}): are they "
                               "in the default run (not slow, stress or docs)?")
        return outcome_of(junit, rc, out)


# ---- one defect ----

@dataclass
class Row:
    name: str
    verdict: str       # caught, NOT caught, timeout, crash, build failed, clean, BASELINE FAILS
    how: str
    seconds: float


def describe(outcome: Outcome, stage: str) -> str:
    if outcome.kind == "pass":
        return f"{outcome.passed} passed ({stage})"
    if outcome.kind == "crash":
        return f"crash ({stage}): {outcome.detail}"
    what = {"assertion": "assertion", "error": "error", "timeout": "timeout"}[outcome.kind]
    return f"{what} in {outcome.test} ({stage}): {outcome.detail}"


class Harness:
    def __init__(self, args, cache: Path, log: Log):
        self.args, self.cache, self.log = args, cache, log
        self.suite_baseline = None          # the default suite on the unplanted tree
        self.suite_lock = threading.Lock()

    def suite_is_clean(self, copy: WorkCopy) -> Outcome:
        """The default suite's run on the unplanted tree (once per harness run)."""
        with self.suite_lock:
            if self.suite_baseline is None:
                copy.build()
                self.suite_baseline = copy.pytest(())
                print(f"    baseline, whole default suite: "
                      f"{describe(self.suite_baseline, 'suite')}", flush=True)
            return self.suite_baseline

    def check(self, copy: WorkCopy, defect: Defect, generated) -> Row:
        started = time.perf_counter()
        explicit = self.args.tests
        named = () if self.args.suite else (tuple(explicit) or defect.tests)
        try:
            copy.plant(defect, generated() if defect.regenerate else None)
            if not copy.build():
                return Row(defect.name, "build failed", f"see {self.log.path}",
                           time.perf_counter() - started)
            how = []
            outcome = Outcome("pass")
            if named:
                outcome = copy.pytest(named)
                how.append(describe(outcome, "named"))
            if not outcome.caught and not explicit and not self.args.no_suite:
                copy.restore(defect)
                if not copy.build():   # the baseline runs the unplanted build
                    return Row(defect.name, "build failed", f"see {self.log.path}",
                               time.perf_counter() - started)
                clean = self.suite_is_clean(copy)
                copy.plant(defect, generated() if defect.regenerate else None)
                if not copy.build():
                    return Row(defect.name, "build failed", f"see {self.log.path}",
                               time.perf_counter() - started)
                if clean.kind != "pass":
                    how.append("the suite fails without the defect: not run")
                else:
                    outcome = copy.pytest(())
                    how.append(describe(outcome, "suite"))
        finally:
            copy.restore(defect)
        verdict = ("caught" if outcome.caught else
                   {"pass": "NOT caught", "timeout": "timeout", "crash": "crash"}[outcome.kind])
        return Row(defect.name, verdict, "; ".join(how), time.perf_counter() - started)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="*", default=None,
                        help="run only defects whose name contains one of these words")
    parser.add_argument("--suite", action="store_true",
                        help="skip the named tests: the default suite (-x) for each defect "
                             "(to find which test catches a new one)")
    parser.add_argument("--no-suite", action="store_true",
                        help="the named tests only (a defect they miss is 'NOT caught')")
    parser.add_argument("--tests", nargs="*", default=[],
                        help="run these test ids for every defect instead")
    parser.add_argument("--check", action="store_true",
                        help="only check that every DEFECTS entry applies to the tree")
    parser.add_argument("--no-baseline", action="store_true",
                        help="skip the named tests' run on the unplanted tree")
    parser.add_argument("--jobs", type=int, default=1,
                        help="defects checked at once, each in its own copy (default 1)")
    parser.add_argument("--codegen-jobs", type=int, default=2,
                        help="codegen runs at once for the codegen defects whose C is not "
                             "cached (default 2; ~75 s of CPU each)")
    parser.add_argument("--keep", action="store_true", help="keep the work copies")
    parser.add_argument("--cache", type=Path, default=None,
                        help="object and generated-C cache (default "
                             "$XDG_CACHE_HOME/ballc-plant-defects)")
    parser.add_argument("--test-timeout", type=float, default=300,
                        help="pytest-timeout per test, s (default 300: the project's)")
    parser.add_argument("--timeout", type=float, default=1800,
                        help="s per command (build, codegen, pytest run; default 1800)")
    args = parser.parse_args(argv)

    problems = problems_with(DEFECTS)
    if problems:
        print("DEFECTS does not apply to this tree:\n" + "\n".join(problems), file=sys.stderr)
        return 2
    if args.check:
        print(f"all {len(DEFECTS)} defects apply")
        return 0
    defects = [d for d in DEFECTS
               if args.only is None or any(w.lower() in d.name.lower() for w in args.only)]
    if not defects:
        print("no defect matches --only", file=sys.stderr)
        return 2

    started = time.perf_counter()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cache = (args.cache or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
             / "ballc-plant-defects").resolve()
    cache.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix="ballc-defects-"))
    log = Log(scratch / "log.txt")
    print(f"work copies and log in {scratch}; caches in {cache}", flush=True)

    # the generated C of the codegen defects, made in the background meanwhile
    generator = ThreadPoolExecutor(max_workers=max(1, args.codegen_jobs))
    futures = {d.name: generator.submit(generate, d, cache, log, args.timeout)
               for d in defects if d.regenerate}
    # codegen defects last: their C is made while the others run
    ordered = sorted(defects, key=lambda d: d.regenerate)

    harness = Harness(args, cache, log)
    rows, failures = [], 0
    try:
        jobs = max(1, min(args.jobs, len(ordered)))
        copies = [WorkCopy(scratch / f"copy{i}", cache, log, f"job{i}", args)
                  for i in range(jobs)]
        print(f"    {jobs} copy(ies) built in {time.perf_counter() - started:.0f} s",
              flush=True)
        named = sorted({t for d in defects for t in (args.tests or d.tests)})
        work = queue.Queue()
        if named and not args.no_baseline and not args.suite:
            work.put(None)                   # the baseline: the named tests, no defect
        for defect in ordered:
            work.put(defect)
        lock = threading.Lock()

        def worker(copy):
            nonlocal failures
            while True:
                try:
                    defect = work.get_nowait()
                except queue.Empty:
                    return
                t0 = time.perf_counter()
                try:
                    if defect is None:
                        base = copy.pytest(named)
                        row = Row("(baseline: the named tests, no defect)",
                                  "clean" if base.kind == "pass" else "BASELINE FAILS",
                                  describe(base, "named"), time.perf_counter() - t0)
                    else:
                        future = futures.get(defect.name)
                        row = harness.check(copy, defect, future.result if future else None)
                except Exception as error:      # the harness's own failure: never a catch
                    row = Row(defect.name if defect else "(baseline)", "harness error",
                              f"{type(error).__name__}: {error}", time.perf_counter() - t0)
                with lock:
                    failures += defect is None and row.verdict != "clean"
                    rows.append(row)
                    print(f"... {row.name}: {row.verdict}, {row.how}, {row.seconds:.0f} s",
                          flush=True)

        threads = [threading.Thread(target=worker, args=(copy,)) for copy in copies]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        generator.shutdown(wait=True, cancel_futures=True)
        if not args.keep:
            for path in scratch.glob("copy*"):
                shutil.rmtree(path, ignore_errors=True)

    wall = time.perf_counter() - started
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    print("\n| defect | verdict | how | time (s) |")
    print("|---|---|---|---|")
    order = {d.name: i for i, d in enumerate(DEFECTS)}
    for row in sorted(rows, key=lambda r: order.get(r.name, -1)):
        print(f"| {row.name} | {row.verdict} | {row.how} | {row.seconds:.0f} |")
    missed = [r for r in rows if r.verdict not in ("caught", "clean")]
    print(f"\n{sum(r.verdict == 'caught' for r in rows)} of {len(defects)} defects caught; "
          f"total {wall:.0f} s wall, {cpu:.0f} s CPU in child processes, {args.jobs} job(s); "
          f"log: {log.path}")
    return 1 if missed or failures else 0


if __name__ == "__main__":
    sys.exit(main())
