"""Work-precision against the stiff peers from PyPI, on ballc's own compiled system.

    python -m benchmarks.peers [--quick] [--repeat N] [--budget SECONDS] [--no-c-cost]

Needs the optional peers: ``pip install ".[bench]"`` (scikit-sundae, assimulo-testing).

Method.  A reference run of the seed scene, ``ballc.simulate(ballc.Scene(), 5.0,
rtol=1e-12, atol=1e-12)`` (default friction law, "exact"), is recorded segment by
segment: start time and state, end time and state (the state at the event that ended
the segment, as the driver received it, or at t_end), and the segment's parameters,
latched values and flags.  The recording reads the C loop's segment log
(``result.segments``) with the run's samples and dense output, which change nothing of
the run.  Then every contender integrates EVERY
segment from the reference's start state to the reference's end time, on the same
compiled right-hand side and analytic Jacobian (``ballc._core.System(params, latch,
flags)``), at rtol = atol = tol; no events, no output but the end state:

- ``radau5``: ballc's solver, ``ballc._radau5.solve_system`` (C callbacks, no Python);
- ``dop853``: ballc's other compiled integrator, Dormand & Prince's explicit DOP853
  (order 8, scipy's DOP853 step by step in C), through the same ``solve_system`` with
  ``method="dop853"`` (C callbacks; no Jacobian, no LU);
- ``CVODE BDF`` and ``CVODE Adams``: SUNDIALS CVODE through scikit-sundae
  (``sksundae.cvode.CVODE``, dense linear solver, user Jacobian, ``tstop`` at the
  segment's end so that it steps onto it rather than interpolating back);
- ``assimulo Radau5ODE``: assimulo's C translation of Hairer's RADAU5
  (``assimulo.solvers.Radau5ODE`` on an ``Explicit_Problem`` with ``jac``);
- ``Hairer RADAU5 (f2py)``: Hairer and Wanner's Fortran RADAU5 through the f2py
  wrapper in the same wheel (``assimulo.lib.radau5.radau5``), called directly
  (IOUT = 0, default WORK/IWORK parameters, analytic full Jacobian).

The peers call the RHS and the Jacobian through Python; radau5 and dop853 call them in
C (so they have no callback cost to subtract: their "C-level" CPU is their CPU).

Measured per tolerance: total CPU over the segments (``time.process_time``, best of
``--repeat``; within a repeat the contenders run one after another in a rotated
order, all in this one process, so that a burst of load on the shared machine hits
them alike), RHS calls, Jacobian calls, steps, and the error: the max over segments
of |end state - reference end state|, in two norms: ``err6``, the inf-norm over the
centre position (m) and velocity (m/s) -- the error of docs/work_precision.md -- and
``err12``, the inf-norm over the 12 mechanical degrees of freedom: centre (m),
rotation (rad, the rotation vector of q_ref^-1 q), angular velocity (rad/s) and
velocity (m/s).

Callback overhead.  For each peer, the CPU per call of the very callables it is given
(its RHS wrapper, its Jacobian wrapper) is timed from a Python loop at each segment
kind's start state; radau5's C-level cost per RHS and Jacobian call of each kind is
measured in a ``-DRADAU5_PROFILE`` build of ballc (built once into a temporary
directory, run in a child process; ``--no-c-cost`` skips it and takes the C cost as
zero, which over-corrects).  The "C-level" CPU of a peer is its raw CPU minus
sum over segments of (RHS calls x (Python per-call - C per-call) + Jacobian calls x
(same for the Jacobian)): an estimate of what it would cost with C callbacks.  It
leaves in the peers' own per-call bridge work (array wrapping in Cython/f2py) and
per-step Python (assimulo's solout), so it is an upper bound of the C-level cost.

Writes docs/peers.png and docs/peers.md.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import ballc
from ballc import _core, _radau5

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
T_END = 5.0
REFERENCE_TOL = 1e-12
#: 1e-3 .. 1e-12, and 1e-13, 1e-14 beyond: at equal tolerance the peers are 100-1000x
#: less accurate than radau5 here, so without them no peer would reach radau5's errors
#: below 1e-8 and there would be nothing to compare at equal error.
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14)
QUICK_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
#: radau5 refuses rtol < 100 machine epsilons (ballc.options)
RADAU5_MIN_TOL = 100 * np.finfo(float).eps
CONTENDERS = ("radau5", "dop853", "CVODE BDF", "CVODE Adams", "assimulo Radau5ODE",
              "Hairer RADAU5 (f2py)")
#: ballc's own compiled integrators (C callbacks, rtol >= RADAU5_MIN_TOL)
BALLC = ("radau5", "dop853")
#: the others, called back through Python
PEERS = tuple(name for name in CONTENDERS if name not in BALLC)
MISSING = ('benchmarks/peers.py needs the optional peers (scikit-sundae, assimulo-testing): '
           'pip install ".[bench]"')

_S = _core.STATE_INDEX
CENTRE = [_S[n] for n in ("x", "y", "z")]
VELOCITY = [_S[n] for n in ("vx", "vy", "vz")]
OMEGA = [_S[n] for n in ("omega_x", "omega_y", "omega_z")]
QUAT = [_S[n] for n in ("qw", "qx", "qy", "qz")]
IDX6 = CENTRE + VELOCITY


def import_peers():
    """(CVODE, Explicit_Problem, Radau5ODE, f2py radau5 module); SystemExit with a
    one-line message naming the extra when a peer is missing."""
    try:
        from assimulo.lib import radau5 as fortran_radau5
        from assimulo.problem import Explicit_Problem
        from assimulo.solvers import Radau5ODE
        from sksundae.cvode import CVODE
    except ImportError as exc:
        raise SystemExit(f"{MISSING} ({exc})") from None
    return CVODE, Explicit_Problem, Radau5ODE, fortran_radau5


# ---- the reference's segments ----

@dataclass
class Segment:
    t0: float
    y0: np.ndarray
    t1: float
    y1: np.ndarray      # the reference's end state (before the driver's event handling)
    params: np.ndarray
    latch: np.ndarray
    flags: int
    nfev: int           # the reference run's RHS calls in this segment

    def system(self):
        return _core.System(self.params, self.latch, self.flags)


def record_segments(scene=None, t_end=T_END, rtol=REFERENCE_TOL, atol=REFERENCE_TOL):
    """(result, segments): a ballc.simulate run and its smooth segments, as the C loop's
    segment log (``result.segments``) and the run's samples and dense output give them
    (dense output changes nothing of the run: tests/test_peers_bench.py).

    A segment's start state is its piece of ``result.sol`` at its start (each
    integrator's interpolant gives its first step's start state there, exactly), its end
    state the run's last sample in it (the state at the event that ended it, before the
    driver handled it, or at t_end), its flags and latch those of its samples.  A
    segment in which radau5 re-armed an event (a slip's approach re-latched without
    ending the segment) is recorded as one piece per latch, split where the latch of its
    samples changes: the samples up to a re-arming carry the latch before it, and the
    last of them is the step's end at the event, the state the re-arming took; so every
    piece integrates one fixed right-hand side (a replay without events would otherwise
    run on with the first latch, whose slip orientation flips where u . d < 0).  The
    segment's RHS calls are counted on its first piece.  A segment of zero length (an
    event at its very start) has no samples and nothing to replay: its states and latch
    are NaN and its flags -1."""
    scene = ballc.Scene() if scene is None else scene
    result = ballc.simulate(scene, t_end, rtol=rtol, atol=atol, dense_output=True)
    log = result.segments
    if log is None:
        raise RuntimeError("the run did not take the C loop: it has no segment log")
    params = scene.parameter_vector()
    pieces = result.sol.pieces
    assert len(pieces) == len(log), (len(pieces), len(log))
    segments = []
    for row, (a, b, interpolant) in zip(log, pieces):
        t0, t1, nfev = float(row["t_start"]), float(row["t_end"]), int(row["nfev"])
        assert (a, b) == (t0, t1), ((a, b), (t0, t1))
        inside = np.flatnonzero((result.t > t0) & (result.t <= t1))
        if not inside.size:
            nothing = np.full(_core.N_STATES, np.nan)
            segments.append(Segment(t0, nothing, t1, nothing, params,
                                    np.full(_core.N_LATCH, np.nan), -1, nfev))
            continue
        assert result.t[inside[-1]] == t1
        flags = int(result.flags[inside[0]])
        latch = result.latch[:, inside]
        cuts = [k for k in range(1, inside.size)
                if not np.array_equal(latch[:, k], latch[:, k - 1])]
        starts = [(t0, np.asarray(interpolant(t0), dtype=float), latch[:, 0])] + [
            (float(result.t[inside[k - 1]]), result.y[:, inside[k - 1]], latch[:, k])
            for k in cuts]
        ends = [(t, y) for t, y, _ in starts[1:]] + [(t1, result.y[:, inside[-1]])]
        for k, ((ta, ya, la), (tb, yb)) in enumerate(zip(starts, ends)):
            segments.append(Segment(ta, np.array(ya), tb, np.array(yb), params,
                                    np.array(la), flags, nfev if k == 0 else 0))
    return result, segments


#: A segment whose exact-Coulomb slip starts this close to zero slip (m/s) is
#: "near-singular": the slip direction u/|u| turns fast there, and where the ball goes
#: depends on which side of u = 0 the slip passes; errors of the size of the tolerance
#: come out O(1) at the segment's end (see the caveats of docs/peers.md).
NEAR_SINGULAR_SLIP = 1e-3


def near_singular(segment):
    """Does the segment start in free-direction slip with |u| < NEAR_SINGULAR_SLIP?"""
    from ballc import stickslip
    for plane in ("floor", "ceiling"):
        if segment.flags & _core.FLAGS[f"{plane}_slip"]:
            u = stickslip.slip_velocity(segment.params, plane, segment.y0)
            if float(np.hypot(*u)) < NEAR_SINGULAR_SLIP:
                return True
    return False


def replayable(segments):
    """The segments of positive length (an event at a segment's very start ends a
    zero-length one: nothing to integrate)."""
    return [s for s in segments if s.t1 > s.t0]


# ---- errors ----

def _rotation_error(q, q_ref):
    """Rotation vector (rad) of q_ref^-1 q (both unit, scalar first)."""
    w0, v0 = q_ref[0], -np.asarray(q_ref[1:])
    w1, v1 = q[0], np.asarray(q[1:])
    w = w0 * w1 - v0 @ v1
    v = w0 * v1 + w1 * v0 + np.cross(v0, v1)
    if w < 0:
        w, v = -w, -v
    s = np.linalg.norm(v)
    return np.zeros(3) if s == 0 else 2 * np.arctan2(s, w) * v / s


def errors(y, y_ref):
    """(err6, err12) of one end state: see the module docstring."""
    if not np.all(np.isfinite(y)):
        return np.inf, np.inf
    e6 = float(np.abs(y[IDX6] - y_ref[IDX6]).max())
    q = y[QUAT] / np.linalg.norm(y[QUAT])
    rot = _rotation_error(q, y_ref[QUAT] / np.linalg.norm(y_ref[QUAT]))
    e12 = max(e6, float(np.abs(rot).max()), float(np.abs(y[OMEGA] - y_ref[OMEGA]).max()))
    return e6, e12


# ---- the contenders: one segment each, (end state, counts) ----

def run_radau5(segment, system, tol, method="radau5"):
    """ballc's own integrator on one segment; ``method``: "radau5" or "dop853"
    (``ballc._radau5.solve_system``'s)."""
    sol = _radau5.solve_system(segment.params, segment.latch, segment.flags,
                               (segment.t0, segment.t1), segment.y0, rtol=tol, atol=tol,
                               method=method)
    if sol.status != 0:
        raise RuntimeError(sol.message)
    return sol.y[:, -1], {"nfev": sol.nfev, "njev": sol.njev, "nstep": sol.nstep,
                          "nlu": sol.nlu}


def run_dop853(segment, system, tol):
    """ballc's compiled DOP853 (explicit, order 8) in radau5's loop: no Jacobian, no LU."""
    return run_radau5(segment, system, tol, method="dop853")


def cvode_callbacks(system):
    def rhsfn(t, y, yp):
        yp[:] = system(t, y)

    def jacfn(t, y, yp, JJ):
        JJ[:, :] = system.jacobian(t, y)
    return rhsfn, jacfn


def make_cvode(method):
    CVODE = import_peers()[0]

    def run(segment, system, tol, count_steps=False):
        rhsfn, jacfn = cvode_callbacks(system)
        solver = CVODE(rhsfn, method=method, rtol=tol, atol=tol, jacfn=jacfn,
                       max_num_steps=10**9)
        solver.init_step(segment.t0, segment.y0)
        nstep = None
        if count_steps:   # one call per internal step (stats only: not timed)
            nstep, res = 0, None
            while res is None or float(np.max(res.t)) < segment.t1:
                res = solver.step(segment.t1, method="onestep", tstop=segment.t1)
                if not res.success:
                    break
                nstep += 1
        else:
            res = solver.step(segment.t1, tstop=segment.t1)
        if not res.success:
            raise RuntimeError(res.message)
        return np.array(res.y).reshape(-1), {"nfev": res.nfev, "njev": res.njev,
                                             "nstep": nstep}
    return run


def assimulo_solver(segment, system, tol):
    _, Explicit_Problem, Radau5ODE, _ = import_peers()
    problem = Explicit_Problem(lambda t, y: system(t, y), segment.y0, segment.t0)
    problem.jac = lambda t, y: system.jacobian(t, y)
    solver = Radau5ODE(problem)
    solver.verbosity = 50      # quiet
    solver.usejac = True
    solver.rtol, solver.atol = tol, tol
    solver.maxsteps = 10**8
    return solver


def run_assimulo(segment, system, tol):
    solver = assimulo_solver(segment, system, tol)
    t, y = solver.simulate(segment.t1)
    st = solver.statistics
    return np.array(y[-1]), {"nfev": st["nfcns"], "njev": st["njacs"], "nstep": st["nsteps"],
                             "nlu": st["nlus"]}


def fortran_callbacks(system):
    def fcn(x, y):
        return system(x, y), [0]

    def jac(x, y):
        return system.jacobian(x, y), [0]
    return fcn, jac


def _no_mass(am, n=None):
    return am


def _no_solout(*args):
    return 0


def run_fortran(segment, system, tol):
    fortran_radau5 = import_peers()[3]
    n = _core.N_STATES
    fcn, jac = fortran_callbacks(system)
    work = np.zeros(n * (n + n + 3 * n + 12) + 20)   # full Jacobian, no mass matrix
    iwork = np.zeros(3 * n + 20, dtype=np.intc)
    iwork[1] = 10**9                                 # IWORK(2): max steps
    x, y, h, iwork, idid = fortran_radau5.radau5(
        fcn, segment.t0, segment.y0.copy(), segment.t1, 0.0, np.full(n, tol),
        np.full(n, tol), 1, jac, 1, n, n, _no_mass, 0, n, n, _no_solout, 0, work, iwork)
    # RADAU5 stops with IDID = -3 ("step size too small") when the last step to XEND
    # would be below 10 UROUND |X|, i.e. when it is already within rounding of XEND:
    # that is reaching XEND (the state differs by |v| x 1e-15 s at most), counted.
    at_end = idid == -3 and abs(x - segment.t1) <= 64 * np.finfo(float).eps * abs(segment.t1)
    if (idid < 0 and not at_end) or not (x == segment.t1 or at_end):
        raise RuntimeError(f"RADAU5 IDID = {idid} at x = {x!r}")
    # IWORK(14..20): NFCN NJAC NSTEP NACCPT NREJCT NDEC NSOL
    return np.array(y), {"nfev": int(iwork[13]), "njev": int(iwork[14]),
                         "nstep": int(iwork[15]), "nlu": int(iwork[18]), "end_exit": at_end}


def contenders():
    return {"radau5": run_radau5, "dop853": run_dop853, "CVODE BDF": make_cvode("BDF"),
            "CVODE Adams": make_cvode("Adams"), "assimulo Radau5ODE": run_assimulo,
            "Hairer RADAU5 (f2py)": run_fortran}


@contextlib.contextmanager
def _fortran_stdout_silenced():
    """RADAU5 writes its messages (e.g. the end-of-interval exit above) to unit 6:
    send the process's stdout to /dev/null meanwhile."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def run_all(run, segments, systems, tol, **options):
    """One pass over the segments: CPU seconds, per-segment (end state, counts)."""
    quiet = _fortran_stdout_silenced() if run is run_fortran else contextlib.nullcontext()
    with quiet:
        started = time.process_time()
        out = [run(seg, system, tol, **options) for seg, system in zip(segments, systems)]
        cpu = time.process_time() - started
    return cpu, out


# ---- callback cost: Python per call (peers) and C per call (radau5, profiled build) ----

def _per_call(fn, args, calls):
    best = np.inf
    for _ in range(5):     # best of 5 rounds of calls / 5
        started = time.process_time()
        for _ in range(calls // 5):
            fn(*args)
        best = min(best, (time.process_time() - started) / (calls // 5))
    return best


def python_callback_costs(segments, calls=100_000):
    """{peer: {flags: (s per RHS call, s per Jacobian call)}}: the callables each peer
    is given, called from a Python loop at the start state of a segment of each kind.
    Also "bare": ``system(t, y)`` and ``system.jacobian(t, y)`` themselves."""
    kinds = {}
    for seg in segments:
        kinds.setdefault(seg.flags, seg)
    costs = {name: {} for name in ("bare",) + PEERS}
    for flags, seg in kinds.items():
        system = seg.system()
        t, y = seg.t0, seg.y0.copy()
        y.setflags(write=False)               # as the peers hand it over
        yp, jj = np.empty_like(y), np.empty((y.size, y.size))
        rhsfn, jacfn = cvode_callbacks(system)
        fcn, fjac = fortran_callbacks(system)
        solver = assimulo_solver(seg, system, 1e-6)
        solver.set_problem_data()             # sets solver.f: the RHS callable it hands over
        pairs = {"bare": ((system, (t, y)), (system.jacobian, (t, y))),
                 "CVODE BDF": ((rhsfn, (t, y, yp)), (jacfn, (t, y, yp, jj))),
                 "assimulo Radau5ODE": ((solver.f, (t, y)), (solver._jacobian, (t, y))),
                 "Hairer RADAU5 (f2py)": ((fcn, (t, y)), (fjac, (t, y)))}
        pairs["CVODE Adams"] = pairs["CVODE BDF"]
        for name, ((f, fa), (j, ja)) in pairs.items():
            costs[name][flags] = (_per_call(f, fa, calls), _per_call(j, ja, calls // 10))
    return costs


def c_costs_child(tols=(1e-8, 1e-12)):
    """In a -DRADAU5_PROFILE build: {flags: (s per RHS call, s per Jacobian call)} inside
    radau5's C (replay of every segment of that kind, best of 3 per tolerance)."""
    _, segments = record_segments()
    segments = replayable(segments)
    out = {}
    for flags in sorted({s.flags for s in segments}):
        best_f, best_j = np.inf, np.inf
        for tol in tols:
            for _ in range(3):
                fun = jac = total = ns = 0.0
                nfev = njev = 0
                for seg in (s for s in segments if s.flags == flags):
                    sol = _radau5.solve_system(seg.params, seg.latch, seg.flags,
                                               (seg.t0, seg.t1), seg.y0, rtol=tol, atol=tol)
                    if "profile" not in sol:
                        raise SystemExit("not a -DRADAU5_PROFILE build")
                    p = sol.profile
                    fun, jac = fun + p["fun"], jac + p["jac"]
                    total, ns = total + p["total"], ns + p["total_ns"]
                    nfev, njev = nfev + sol.nfev, njev + sol.njev
                s_per_tick = ns / total * 1e-9
                best_f = min(best_f, fun * s_per_tick / nfev)
                best_j = min(best_j, jac * s_per_tick / njev)
        out[str(flags)] = (best_f, best_j)
    print(json.dumps(out))


def c_callback_costs():
    """Build a profiling ballc into a temporary directory and run c_costs_child there;
    {flags: (s per RHS call, s per Jacobian call)}, or None when that fails."""
    from benchmarks.profile_step import build_profiled
    with tempfile.TemporaryDirectory(prefix="ballc-prof-") as where:
        try:
            lib = build_profiled(Path(where), quiet=True)
        except subprocess.CalledProcessError as exc:
            print(f"profiled build failed ({exc}): C per-call cost taken as 0", flush=True)
            return None
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(lib), str(ROOT)]))
        child = subprocess.run([sys.executable, "-m", "benchmarks.peers", "--c-costs-child"],
                               cwd=ROOT, env=env, capture_output=True, text=True)
    if child.returncode != 0:
        print(f"profiled run failed: {child.stderr.strip().splitlines()[-1:]}: C per-call "
              "cost taken as 0", flush=True)
        return None
    return {int(k): tuple(v) for k, v in json.loads(child.stdout.strip().splitlines()[-1]).items()}


def overhead(counts, segments, py, c):
    """CPU (s) the Python callbacks add over C ones: per segment, RHS calls x (Python
    per-call - C per-call) + Jacobian calls x (the same for the Jacobian)."""
    total = 0.0
    for n, seg in zip(counts, segments):
        f_py, j_py = py[seg.flags]
        f_c, j_c = c[seg.flags] if c else (0.0, 0.0)
        total += n["nfev"] * max(f_py - f_c, 0.0) + n["njev"] * max(j_py - j_c, 0.0)
    return total


# ---- the benchmark ----

def versions():
    from importlib.metadata import version

    def v(dist):
        try:
            return version(dist)
        except Exception:
            return "?"
    out = {"ballc": f"{ballc.__version__} (this tree)", "scikit-sundae": v("scikit-sundae"),
           "assimulo-testing": v("assimulo-testing"), "numpy": np.__version__,
           "python": platform.python_version(), "machine": platform.machine()}
    try:
        import sksundae
        out["SUNDIALS"] = getattr(sksundae, "__sundials_version__", None) or "bundled"
    except Exception:
        pass
    return out


def benchmark(tolerances, repeat, budget, c_cost=True, log=print):
    import_peers()
    result, segments = record_segments()
    segments = replayable(segments)
    systems = [s.system() for s in segments]
    log(f"reference: seed scene, {T_END:g} s, rtol = atol = {REFERENCE_TOL:g}: status "
        f"{result.status}, {len(segments)} segments of positive length, {result.nfev} RHS calls")
    runners = contenders()
    rows = {}          # (name, tol) -> dict
    dropped = {}       # name -> tolerance at which it ran out of budget
    for k, tol in enumerate(tolerances):
        best = {}
        outputs = {}
        if tol < RADAU5_MIN_TOL:
            for name in BALLC:
                rows[(name, tol)] = {"skipped": "rtol below ballc's limit "
                                                f"{RADAU5_MIN_TOL:.2g}"}
        for rep in range(repeat):
            order = CONTENDERS[rep % len(CONTENDERS):] + CONTENDERS[:rep % len(CONTENDERS)]
            for name in order:
                if name in dropped or (rep > 0 and name not in outputs):
                    continue
                if name in BALLC and tol < RADAU5_MIN_TOL:
                    continue
                if rep > 0 and best[name] > budget:
                    continue              # one pass was enough for a slow one
                try:
                    cpu, out = run_all(runners[name], segments, systems, tol)
                except Exception as exc:  # a failure is reported, not hidden
                    rows[(name, tol)] = {"error": f"{type(exc).__name__}: {exc}"[:160]}
                    continue
                best[name] = min(best.get(name, np.inf), cpu)
                outputs[name] = out
        for name in CONTENDERS:
            if name in dropped or name not in outputs:
                if name in dropped:
                    rows[(name, tol)] = {"skipped": f"too slow from {dropped[name]:.0e} on"}
                continue
            out = outputs[name]
            errs = [errors(y, seg.y1) for (y, _), seg in zip(out, segments)]
            totals = {key: sum(c[key] for _, c in out) if all(c.get(key) is not None
                                                              for _, c in out) else None
                      for key in ("nfev", "njev", "nstep", "nlu")}
            if name.startswith("CVODE"):   # steps: a separate, untimed one-step pass
                _, counted = run_all(runners[name], segments, systems, tol, count_steps=True)
                totals["nstep"] = sum(c["nstep"] for _, c in counted)
            regular = [e[0] for e, seg in zip(errs, segments) if not near_singular(seg)]
            rows[(name, tol)] = {"cpu": best[name], "err6": max(e[0] for e in errs),
                                 "err6_regular": max(regular),
                                 "err12": max(e[1] for e in errs),
                                 "counts": [c for _, c in out],
                                 "end_exits": sum(bool(c.get("end_exit")) for _, c in out),
                                 **totals}
            r = rows[(name, tol)]
            log(f"  {tol:.0e} {name:22s} {r['cpu']:8.4f} s  err6 {r['err6']:.1e}  err12 "
                f"{r['err12']:.1e}  err6 regular {r['err6_regular']:.1e}  RHS {r['nfev']}  "
                f"Jac {r['njev']}  steps {r['nstep']}")
            if best[name] > 4 * budget and k + 1 < len(tolerances):
                dropped[name] = tolerances[k + 1]
        for (name, t), r in rows.items():
            if t == tol and "error" in r:
                log(f"  {tol:.0e} {name:22s} failed: {r['error']}")
    log("Python callback cost per call ...")
    py = python_callback_costs(segments)
    c = None
    if c_cost:
        log("C cost per call (profiled build) ...")
        c = c_callback_costs()
    for (name, tol), r in rows.items():
        if "cpu" in r and name in PEERS:
            r["overhead"] = overhead(r["counts"], segments, py[name], c)
            r["cpu_c"] = max(r["cpu"] - r["overhead"], 0.0)
    return {"segments": segments, "result": result, "rows": rows, "py": py, "c": c,
            "versions": versions(), "dropped": dropped}


# ---- report ----

def _interp_cpu(points, err):
    """CPU at error ``err`` on a contender's curve ``points`` ((cpu, err) in tolerance
    order, loosest first): log-log interpolated between the first two consecutive
    tolerances whose errors bracket ``err``; None when none do."""
    pts = [(c, e) for c, e in points if np.isfinite(e) and e > 0 and c > 0]
    for (c0, e0), (c1, e1) in zip(pts, pts[1:]):
        if min(e0, e1) <= err <= max(e0, e1):
            if e1 == e0:
                return min(c0, c1)
            w = (np.log(err) - np.log(e0)) / (np.log(e1) - np.log(e0))
            return float(np.exp(np.log(c0) + w * (np.log(c1) - np.log(c0))))
    return None


def equal_error_ratios(rows, tolerances, key="err6", base="radau5", peers=None):
    """{(contender, tol): (raw ratio, corrected ratio)}: the contender's CPU at the base's
    (radau5's, or dop853's) error at that tolerance (interpolated on its curve) over the
    base's CPU, for ``peers`` (default: every contender in ``rows`` but the base).
    ballc's compiled ones (BALLC) have no callback cost: their corrected ratio is their
    raw one."""
    out = {}
    if peers is None:
        peers = [name for name in dict.fromkeys(name for name, _ in rows) if name != base]
    for peer in peers:
        c_key = "cpu" if peer in BALLC else "cpu_c"
        pts = [(rows[(peer, t)]["cpu"], rows[(peer, t)][key]) for t in tolerances
               if "cpu" in rows.get((peer, t), {})]
        pts_c = [(rows[(peer, t)][c_key], rows[(peer, t)][key]) for t in tolerances
                 if c_key in rows.get((peer, t), {})]
        for t in tolerances:
            ref = rows.get((base, t), {})
            if "cpu" not in ref:
                continue
            raw, cor = _interp_cpu(pts, ref[key]), _interp_cpu(pts_c, ref[key])
            if raw is None:      # say why: never that accurate, or always more accurate
                finite = [e for _, e in pts if np.isfinite(e)]
                out[(peer, t)] = ("n/r" if finite and ref[key] < min(finite) else "<", "")
                continue
            out[(peer, t)] = (raw / ref["cpu"], None if cor is None else cor / ref["cpu"])
    return out


def _g(x, fmt=".2g"):
    if isinstance(x, str):
        return x
    return "" if x is None else format(x, fmt)


def plot(bench, tolerances, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = bench["rows"]
    fig, axes = plt.subplots(2, 2, figsize=(13, 10.5), sharex=True)
    styles = dict(zip(CONTENDERS, ("o-", "D-", "s--", "^--", "v--", "d--")))
    colours = dict(zip(CONTENDERS, ("black", "tab:red", "tab:blue", "tab:cyan", "tab:orange",
                                    "tab:brown")))
    n_near = sum(near_singular(s) for s in bench["segments"])
    for i, (err_key, err_label) in enumerate((
            ("err6", f"all {len(bench['segments'])} segments"),
            ("err6_regular", f"without the {n_near} near-singular slip starts"))):
        for j, (key, title) in enumerate((("cpu", "raw CPU (peers call back into Python; "
                                                  "radau5, dop853 in C)"),
                                          ("cpu_c", "peers: Python callback cost subtracted "
                                                    "(est. C-level)"))):
            ax = axes[i, j]
            for name in CONTENDERS:
                k = "cpu" if name in BALLC else key
                pts = [(rows[(name, t)][k], max(rows[(name, t)][err_key], 1e-16), t)
                       for t in tolerances if k in rows.get((name, t), {})]
                if not pts:
                    continue
                cpu, err, tols = zip(*pts)
                ax.loglog(cpu, err, styles[name], color=colours[name], ms=4,
                          label="dop853 (ballc, compiled)" if name == "dop853" else name,
                          lw=1.6 if name in BALLC else 1.0)
                if name in BALLC:
                    below = name == "dop853"
                    for c, e, t in zip(cpu, err, tols):
                        ax.annotate(f"{t:.0e}", (c, e), fontsize=6,
                                    xytext=(3, -9 if below else 3), textcoords="offset points",
                                    color=colours[name])
            ax.set_title(f"{title}\nerror: {err_label}", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            if i == 1:
                ax.set_xlabel("CPU time over all segments (s)")
            if j == 0:
                ax.set_ylabel("max end-of-segment error, centre position / velocity (m, m/s)",
                              fontsize=8)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"Segment replay of the seed scene ({T_END:g} s), same compiled RHS and "
                 "analytic Jacobian for every contender; rtol = atol (labels on radau5, dop853)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_markdown(bench, tolerances, args, elapsed, path):
    rows, segs = bench["rows"], bench["segments"]
    ratios = equal_error_ratios(rows, tolerances)
    kinds = sorted({s.flags for s in segs})
    flag_names = {v: k for k, v in _core.FLAGS.items()}

    def kind(flags):
        names = [flag_names[b] for b in sorted(flag_names) if flags & b]
        return ", ".join(names) if names else "free flight (no flags)"
    lines = [
        "# Peers: radau5 and dop853 against CVODE and Hairer's RADAU5", "",
        f"Generated by `python -m benchmarks.peers{' --quick' if args.quick else ''}` "
        f"({elapsed:.0f} s wall; 2-core machine shared with other work: CPU is "
        f"`time.process_time()`, best of {args.repeat}, the contenders interleaved in one "
        "process).  Needs `pip install \".[bench]\"`.", "",
        "## Method", "",
        f"The seed scene (`ballc.Scene()`, default exact Coulomb friction) is simulated for "
        f"{T_END:g} s with radau5 at rtol = atol = {REFERENCE_TOL:g}; its smooth segments "
        f"({len(segs)} of positive length) are recorded as the driver integrates them: "
        "start time and state, end time and state (at the event that ended the segment), "
        "parameters, latched values and flags.  Every contender then integrates every "
        "segment from the reference's start state to the reference's end time on the same "
        "compiled right-hand side and analytic Jacobian (`ballc._core.System`), at "
        "rtol = atol = tol, without events; CPU is the total over the segments, the error "
        "the max over the segments of |end state - reference end state|.", "",
        "- **err6**: inf-norm over centre position (m) and velocity (m/s) -- the error of "
        "[work_precision](work_precision.md).  The figure and the equal-error ratios use it.",
        "- **err12**: inf-norm over the 12 mechanical degrees of freedom: centre (m), "
        "rotation (rad; rotation vector of q_ref^-1 q), angular velocity (rad/s), velocity "
        "(m/s).",
        "- **C-level CPU** of a peer: raw CPU minus, per segment, RHS calls x (the Python "
        "per-call cost of the very callable the peer is given - radau5's C per-call cost) "
        "and the same for Jacobian calls; the Python cost is timed from a Python loop at "
        "each segment kind's start state, the C cost inside radau5 in a "
        "`-DRADAU5_PROFILE` build.  It leaves in each peer's own bridge (array wrapping in "
        "Cython / f2py before the callable runs) and per-step Python (assimulo's `solout`), "
        "so it is an *upper bound* of what the peer would cost with C callbacks -- a loose "
        "one: for CVODE, driven from C on the same replay ([cvode_c](cvode_c.md), "
        "`python -m benchmarks.cvode_c`), the measured CPU is 4-12x below this estimate, "
        "and CVODE BDF is level with radau5 there (CVODE Adams faster at tight "
        "tolerances).",
        "- **equal-error ratio**: the contender's CPU interpolated (log-log, between its "
        "two neighbouring tolerances) at radau5's err6 for that tolerance, over radau5's "
        "CPU; `n/r` when the contender never got that accurate, `<` when it was more "
        "accurate even at its loosest tolerance.", "",
        "Contenders: `radau5` -- `ballc._radau5.solve_system` (C callbacks); `dop853` -- "
        "ballc's other compiled integrator, Dormand & Prince's explicit DOP853 (order 8, "
        "scipy's DOP853 step by step in C), the same `solve_system` with "
        "`method=\"dop853\"` (C callbacks, no Jacobian, no LU: its C-level CPU is its "
        "CPU); `CVODE BDF`, "
        "`CVODE Adams` -- SUNDIALS CVODE via scikit-sundae, dense linear solver, user "
        "Jacobian, `tstop` at the segment end, `max_num_steps` unlimited; `assimulo Radau5ODE`"
        " -- assimulo's C translation of Hairer's RADAU5 (defaults: initial step 0.01, "
        "newt 7, thet 1e-3); `Hairer RADAU5 (f2py)` -- the Fortran RADAU5 of Hairer and "
        "Wanner from the same wheel (`assimulo.lib.radau5`), default WORK/IWORK, IOUT = 0.",
        "",
        "Versions: " + ", ".join(f"{k} {v}" for k, v in bench["versions"].items()) + ".", "",
        "![peers](peers.png)", "",
        "## Table", "",
        "RHS / Jac / steps: calls and steps summed over the segments (CVODE's steps from an "
        "untimed one-step pass).  err6 (regular): err6 without the "
        f"{sum(near_singular(s) for s in segs)} segments that start in slip with "
        f"|u| < {NEAR_SINGULAR_SLIP:g} m/s (see the caveats).", "",
        "| tol | contender | CPU s | C-level CPU s | err6 | err6 (regular) | err12 | RHS | "
        "Jac | steps |",
        "|---|---|---|---|---|---|---|---|---|---|"]
    for tol in tolerances:
        for name in CONTENDERS:
            r = rows.get((name, tol))
            if r is None:
                continue
            if "error" in r:
                lines.append(f"| {tol:.0e} | {name} | failed: {r['error']} | | | | | | | |")
                continue
            if "skipped" in r:
                lines.append(f"| {tol:.0e} | {name} | not run: {r['skipped']} | | | | | | | |")
                continue
            lines.append(
                f"| {tol:.0e} | {name} | {r['cpu']:.3g} | {_g(r.get('cpu_c'), '.3g')} | "
                f"{r['err6']:.1e} | {r['err6_regular']:.1e} | {r['err12']:.1e} | {r['nfev']} "
                f"| {r['njev']} | {_g(r['nstep'], 'd')} |")
    ratio_all = equal_error_ratios(rows, tolerances, "err6")
    ratio_reg = equal_error_ratios(rows, tolerances, "err6_regular")
    others = [name for name in CONTENDERS[1:]
              if any(name == n for n, _ in ratio_all)]
    lines += ["", "## CPU ratio contender / radau5 at equal error", "",
              "For each tolerance of radau5: the contender's CPU at radau5's error there "
              "(log-log interpolation between the first two consecutive tolerances of the "
              "contender whose errors bracket it) over radau5's CPU; for the peers raw / "
              "C-level (Python callback cost subtracted), for dop853 (compiled, no callback "
              "cost) one number.  `n/r`: the contender never got that accurate at any "
              "measured tolerance; `<`: it was more accurate than that even at its "
              "loosest tolerance (no CPU to interpolate).  Where radau5's err6 over all "
              "segments is O(1) (the near-singular segments diverged, loose tolerances) the "
              "(all) ratios compare diverged trajectories and mean nothing: read the "
              "(regular) ones there.", "",
              "| radau5 tol | radau5 err6 | " + " | ".join(f"{p} (all)" for p in others)
              + " | radau5 err6 (regular) | " + " | ".join(f"{p} (regular)" for p in others)
              + " |", "|---|---|" + "---|" * len(others) + "---|" + "---|" * len(others)]

    def cell(ratio, name=None):
        raw, cor = ratio if ratio else (None, None)
        if isinstance(raw, str):
            return raw
        if name in BALLC:
            return _g(raw)
        return "" if raw is None and cor is None else f"{_g(raw)} / {_g(cor)}"
    for tol in tolerances:
        base = rows.get(("radau5", tol), {})
        if "cpu" not in base:
            continue
        lines.append(f"| {tol:.0e} | {base['err6']:.1e} | "
                     + " | ".join(cell(ratio_all.get((p, tol)), p) for p in others)
                     + f" | {base['err6_regular']:.1e} | "
                     + " | ".join(cell(ratio_reg.get((p, tol)), p) for p in others) + " |")
    dop = [(tol, ratio_reg[("dop853", tol)][0]) for tol in tolerances
           if isinstance(ratio_reg.get(("dop853", tol), (None,))[0], float)]
    if dop:
        lines += ["", "dop853 / radau5 at equal err6 (regular), by radau5's tolerance: "
                  + ", ".join(f"{tol:.0e}: {ratio:.2g}" for tol, ratio in dop)
                  + " (< 1: dop853 cheaper).  Both call the same compiled RHS from C, so "
                  "this is the integrators alone; dop853 is explicit (no Jacobian, no LU) "
                  "and these segments are not stiff (the seed's rubber ball; see "
                  "[work_precision](work_precision.md#when-dop853-is-the-wrong-choice) for a "
                  "stiff scene)."]
    py, c = bench["py"], bench["c"]
    lines += ["", "## Callback cost per call (µs)", "",
              "Python: the callable each peer is given, called from a Python loop (best of "
              "5 rounds of 2e4 RHS / 2e3 Jacobian calls) at the start state of a segment of "
              "each kind;"
              " `bare` is `System.__call__` / `System.jacobian` itself.  C: inside radau5 "
              "(`-DRADAU5_PROFILE` build, replay of the segments of that kind)"
              + ("" if c else " -- not measured in this run, taken as 0") + ".", "",
              "| segment kind (flags) | C RHS | C Jac | " + " | ".join(
                  f"{n} RHS | {n} Jac" for n in ("bare", "CVODE BDF", "assimulo Radau5ODE",
                                                 "Hairer RADAU5 (f2py)"))
              + " |", "|---|---|---|" + "---|---|" * 4]
    for flags in kinds:
        cf, cj = c[flags] if c else (0.0, 0.0)
        cells = []
        for n in ("bare", "CVODE BDF", "assimulo Radau5ODE", "Hairer RADAU5 (f2py)"):
            f, j = py[n][flags]
            cells += [f"{1e6 * f:.2f}", f"{1e6 * j:.2f}"]
        lines.append(f"| {kind(flags)} ({flags}) | {1e6 * cf:.3f} | {1e6 * cj:.3f} | "
                     + " | ".join(cells) + " |")
    lines.append("")
    lines += ["(CVODE Adams is given the same callables as CVODE BDF.)", "",
              "## Caveats", "",
              "- Same tolerance is not same accuracy: Hairer's RADAU5 (both the Fortran and "
              "assimulo's translation) replaces rtol by 0.1 rtol^(2/3) internally (and atol "
              "in proportion), CVODE uses a WRMS norm, radau5 (scipy's controller) its own; "
              "compare at equal error (the ratio columns, the figure), not at equal tol.",
              "- The error is measured against radau5's own 1e-12 run at the same end times: "
              "below about 1e-11 it mixes the reference's own error into the contenders' "
              "(and favours a method that errs like radau5).",
              f"- Near-singular segments ({sum(near_singular(s) for s in segs)} of {len(segs)}):"
              " the second half of most contacts starts in free-direction slip with "
              "|u| ~ 1e-5 m/s -- the reference's slip trajectory passes that close to u = 0, "
              "where the Coulomb direction u/|u| turns fast, and its approach event re-latched"
              " the direction there.  Where the ball goes next depends on which side of u = 0 "
              "the slip passes, so an error of 1e-6 in u can change the end velocity by "
              "metres per second: at loose tolerances err6 over all segments is O(1) for every"
              " contender (a property of the problem, and of replaying segments cut for "
              "tol = 1e-12 -- ballc at a loose tolerance cuts them where its own clear speed, "
              "proportional to the tolerance, says).  err6 (regular) leaves those segments out;"
              " both are given.",
              "- Reference consistency: the peers' errors keep falling at 1e-13 and 1e-14 "
              "(beyond the 1e-3..1e-12 range, added for that and so that the peers reach "
              "radau5's errors), so down to ~1e-10 they are the peers' own, not the "
              "reference's.",
              "- Hairer's Fortran RADAU5 stops with IDID = -3 when its last step to XEND "
              "would be below 10 UROUND |X| (the end is within rounding); that exit is taken "
              "as reaching the end (counted: "
              + ", ".join(f"{t:.0e}: {rows[('Hairer RADAU5 (f2py)', t)]['end_exits']}"
                          for t in tolerances
                          if "end_exits" in rows.get(("Hairer RADAU5 (f2py)", t), {}))
              + " segments per tolerance).",
              "- Each segment starts fresh (initial step chosen by the solver), as in ballc "
              "after a contact event; the driver's step carry-over at stick/slip "
              "transitions is not replayed.",
              "- The peers pay per-segment construction in Python (CVODE object, "
              "assimulo problem and solver); it is in the raw CPU and not subtracted.",
              "- The C-level estimate subtracts only the callable's own cost measured from "
              "Python; the peers' bridges may cost more per call from C (array wrapping) "
              "and assimulo calls a Python `solout` every step: the estimate is an upper "
              "bound.",
              "- 2 shared cores: timings noisy at the 10-20 % level even as best of "
              f"{args.repeat}; loosest-tolerance runs last a few ms."]
    if bench["dropped"]:
        lines.append("- Not run at tighter tolerances after a pass took > 4 x the budget: "
                     + ", ".join(f"{n} (from {t:.0e})" for n, t in bench["dropped"].items())
                     + ".")
    lines.append("")
    path.write_text("\n".join(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="4 tolerances, best of 2")
    parser.add_argument("--repeat", type=int, default=None, help="best of N (default 5)")
    parser.add_argument("--budget", type=float, default=20.0,
                        help="CPU s of one pass after which a contender is not repeated")
    parser.add_argument("--no-c-cost", action="store_true",
                        help="skip the profiled build; C per-call cost taken as 0")
    parser.add_argument("--c-costs-child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, default=DOCS)
    args = parser.parse_args(argv)
    if args.c_costs_child:
        c_costs_child()
        return
    import_peers()
    args.repeat = args.repeat or (2 if args.quick else 5)
    tolerances = QUICK_TOLERANCES if args.quick else TOLERANCES
    started = time.time()
    bench = benchmark(tolerances, args.repeat, args.budget, c_cost=not args.no_c_cost,
                      log=lambda *a: print(*a, flush=True))
    elapsed = time.time() - started
    print_table(bench, tolerances)
    args.out.mkdir(parents=True, exist_ok=True)
    plot(bench, tolerances, args.out / "peers.png")
    write_markdown(bench, tolerances, args, elapsed, args.out / "peers.md")
    print(f"wrote {args.out / 'peers.png'} and {args.out / 'peers.md'} ({elapsed:.0f} s)")


def print_table(bench, tolerances):
    rows = bench["rows"]
    ratios = equal_error_ratios(rows, tolerances, "err6")
    regular = equal_error_ratios(rows, tolerances, "err6_regular")
    print("x: CPU / radau5's at equal err6 (raw, C-level); reg: the same on err6 (regular)")
    print(f"{'tol':>6s} {'contender':21s} {'CPU s':>8s} {'C-lvl s':>8s} {'err6':>7s} "
          f"{'err6reg':>7s} {'err12':>7s} {'RHS':>8s} {'Jac':>6s} {'steps':>7s} "
          f"{'x raw':>6s} {'x C':>6s} {'reg raw':>7s} {'reg C':>6s}")
    for tol in tolerances:
        for name in CONTENDERS:
            r = rows.get((name, tol))
            if r is None or "cpu" not in r:
                if r is not None:
                    print(f"{tol:6.0e} {name:21s} {r.get('error') or r.get('skipped')}")
                continue
            raw, cor = ratios.get((name, tol), (None, None))
            rraw, rcor = regular.get((name, tol), (None, None))
            print(f"{tol:6.0e} {name:21s} {r['cpu']:8.4f} {_g(r.get('cpu_c'), '8.4f'):>8s} "
                  f"{r['err6']:7.1e} {r['err6_regular']:7.1e} {r['err12']:7.1e} "
                  f"{r['nfev']:8d} {r['njev']:6d} {_g(r['nstep'], '7d'):>7s} "
                  f"{_g(raw, '6.2g'):>6s} {_g(cor, '6.2g'):>6s} {_g(rraw, '7.2g'):>7s} "
                  f"{_g(rcor, '6.2g'):>6s}")


if __name__ == "__main__":
    main()
