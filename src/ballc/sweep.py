"""Parameter sweeps: every combination of some scene fields, run in parallel.

    table = ballc.sweep(ballc.Scene(), {"mixture": [0, 0.5, 1],
                                        "friction_coefficient": [0.0, 0.1]}, t_end=1.2)

runs on a local process pool by default (``workers``: number of processes, default all
cores; 1 runs in this process), and on a Dask distributed cluster when given
``client=`` (a ``distributed.Client`` or a scheduler address such as
"tcp://host:8786"; the workers need ballc installed).  The same call either way, and
the same table: one row per scene, in the order of the combinations.

Ctrl-C (SIGINT, to the whole process group as a terminal sends it, or to this process
alone) stops a sweep within about a second, however long its runs: the local pool's
workers ignore SIGINT and are stopped by this process (a worker also ends by itself
when this process is gone), and :class:`SweepInterrupted` -- a KeyboardInterrupt --
carries the rows finished so far.
"""
from __future__ import annotations

import contextlib
import inspect
import itertools
import math
import numbers
import os
import signal
import sys
import threading
from pathlib import Path

from . import planes as plane_sweep
from ._format import plain
from .outcome import CAME_BACK_AFTER_CONTACTS, summary
from .planes import PlaneError
from .scene import Scene, SceneError, read_toml, reject_unknown_keys

#: Columns every row has besides the swept parameters (see ballc.outcome.summary).
SUMMARY_COLUMNS = ("contacts", "came_back", "first_reversal_time", "energy_initial",
                   "energy_final", "energy_lost", "energy_lost_fraction", "t_final",
                   "status", "message")


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by Ctrl-C (a KeyboardInterrupt, so a script stops as on any
    Ctrl-C).  ``table``: the rows of the runs that had finished, in grid order, as
    :func:`sweep` returns them; ``finished`` of ``total`` runs."""

    def __init__(self, table, finished: int, total: int):
        super().__init__(f"interrupted (Ctrl-C) after {finished} of {total} runs had "
                         "finished")
        self.table, self.finished, self.total = table, finished, total


def _run_one(changes: dict, scene: Scene, t_end: float, options: dict, outputs: dict,
             checked: dict | None = None) -> dict:
    """One simulation -> one row (runs in a worker; module-level so it pickles).  The
    scene is the one validated before any run: a worker does not validate it again, and
    ``checked`` (a dict kept over a batch) holds simulate's options checked once per
    batch and state layout."""
    from .simulate import run_checked, simulate
    row = dict(changes)
    try:
        if checked is None or options.get("y0") is not None:
            result = simulate(scene, t_end, progress=False, **options)
        else:
            result = run_checked(scene, _checked_options(checked, scene, t_end, options),
                                 scene._initial, progress=False,
                                 rest=options.get("rest", True))
    except Exception as error:    # one failed scene must not lose the sweep
        row.update({name: float("nan") for name in SUMMARY_COLUMNS})
        row.update(status=-1, message=f"{type(error).__name__}: {error}",
                   **{name: float("nan") for name in outputs})
        return row
    row.update(summary(result))
    row.update({name: function(result) for name, function in outputs.items()})
    return row


def _checked_options(checked: dict, scene: Scene, t_end: float, options: dict):
    """simulate's options (but progress, y0, rest) checked for ``scene`` as simulate
    checks them, once per state layout (they depend on the scene only through its
    state names: a per-state atol, a LinearEvent's coefficients)."""
    from .options import check_options
    found = checked.get(scene.state_names)
    if found is None:
        given = {k: v for k, v in options.items() if k not in ("y0", "rest")}
        found = checked[scene.state_names] = check_options(scene, t_end, **given)
    return found


def _named_outputs(outputs) -> dict:
    if outputs is None:
        return {}
    if callable(outputs):
        outputs = [outputs]
    if not isinstance(outputs, dict):
        outputs = {function.__name__: function for function in outputs}
    for name, function in outputs.items():
        if not callable(function):
            raise TypeError(f"output {name!r} must be a function of a Result, got {function!r}")
    return dict(outputs)


def _values(value) -> list:
    """A parameter's values: a list as it is, one value (a number, a string) as [value]."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return [value]
    return list(value)


def combinations(base_scene: Scene, parameters: dict) -> list:
    """[(changes, scene)] for every combination, validated before anything runs.  A
    parameter given one value instead of a list (``{"mixture": 0.3}``) is that value.
    Besides the scene's fields, ``planes.tilt`` and ``planes.<i>.tilt`` turn the base
    scene's planes about the y axis (rad; ballc.planes)."""
    if not isinstance(base_scene, Scene):
        raise TypeError(f"base_scene must be a ballc.Scene, got {type(base_scene).__name__}")
    if not isinstance(parameters, dict):
        raise SceneError(f"parameters = {parameters!r} is not allowed: must be a dict of "
                         "scene field -> list of values")
    parameters = _flat(parameters)
    names = list(parameters)
    grids = [_values(parameters[name]) for name in names]
    for name, grid in zip(names, grids):
        if not grid:
            raise SceneError(f"sweep parameter {name!r} has no values")
        _check_vector_grid(name, parameters[name], grid)
    cases = []
    for values in itertools.product(*grids):
        changes = dict(zip(names, values))
        cases.append((changes, _scene_of(base_scene, changes)))   # validates
    return cases


def _flat(parameters: dict) -> dict:
    """The parameters with a nested ``planes`` table (a TOML sweep file's unquoted
    ``planes.tilt`` and ``planes.0.tilt`` keys) as the dotted names."""
    nested = parameters.get("planes")
    if not isinstance(nested, dict):
        return parameters
    flat = {}
    for name, value in parameters.items():
        if name != "planes":
            flat[name] = value
            continue
        for key, inner in nested.items():
            if isinstance(inner, dict):
                flat.update({f"planes.{key}.{k}": v for k, v in inner.items()})
            else:
                flat[f"planes.{key}"] = inner
    return flat


def _scene_of(base_scene: Scene, changes: dict) -> Scene:
    """The base scene with ``changes``: its fields replaced ("did you mean" for an
    unknown one), then its planes turned by the planes' sweep parameters."""
    turns = {k: v for k, v in changes.items() if plane_sweep.is_sweep_key(k)}
    scene = base_scene.replace(**{k: v for k, v in changes.items() if k not in turns})
    if not turns:
        return scene
    try:
        return scene.replace(planes=plane_sweep.swept(scene.planes, turns))
    except PlaneError as error:
        raise SceneError(str(error)) from None


def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _check_vector_grid(name, given, grid) -> None:
    """A vector field (velocity, angular_velocity, ...) given a flat list of numbers: its
    values to sweep are each a vector, so say what was understood and how to write it."""
    if name not in Scene.VECTOR_FIELDS or not all(_is_number(v) for v in grid):
        return
    shown = plain(given)
    raise SceneError(
        f"sweep parameter {name} = {shown} is not allowed: a parameter's list holds the "
        f"values to sweep, one run each, so this sweeps {name} over the single numbers "
        f"{', '.join(plain(v) for v in grid)}, but each value of {name} is a vector of 3 "
        f"numbers.  To sweep {name} over vectors, list them: {name} = "
        f"[{shown}, [...], ...]; for this one vector in every run write {name} = "
        f"[{shown}] (or set it in the base scene)")


def check_workers(workers, name="workers"):
    """The one rule for the number of local processes, in Python, sweep files and the
    CLI: None (all cores) or a whole number >= 1."""
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise SceneError(f"{name} = {workers!r} is not allowed: must be a whole number >= 1 "
                         "(or None: all cores)")
    return workers


#: simulate's keyword options a sweep passes on (progress is the sweep's own).
def _simulate_option_names() -> tuple:
    from .simulate import simulate
    return tuple(name for name, p in inspect.signature(simulate).parameters.items()
                 if p.kind is p.KEYWORD_ONLY and name != "progress")


def check_simulate_options(base_scene: Scene, t_end, options: dict) -> float:
    """t_end and simulate's options checked as ``ballc.simulate`` checks them, before
    any run (an unknown option gets a "did you mean"); returns t_end as a float."""
    from .options import check_options
    from .simulate import check_initial_state
    names = _simulate_option_names()
    reject_unknown_keys(options, names, "simulate option", ", ".join(names))
    given = {k: v for k, v in options.items() if k != "y0"}
    t_end = check_options(base_scene, t_end, **given).t_end
    if options.get("y0") is not None:
        check_initial_state(base_scene, options["y0"])
    return t_end


def sweep(base_scene: Scene, parameters: dict, t_end: float, *, outputs=None,
          workers: int | None = None, client=None, progress: bool | None = None,
          **simulate_options):
    """Simulate every combination of ``parameters`` on top of ``base_scene``.

    Parameters
    ----------
    base_scene : Scene
    parameters : dict
        Scene field -> list of values, e.g. ``{"mixture": [0, 0.5], "c_tau": [0.8, 0.9]}``.
    t_end : float
        Simulated time of each run (s).
    outputs : callable, list of callables or dict name -> callable, optional
        Extra columns: functions of a Result returning a number (must pickle: define
        them at module level).
    workers : int, optional
        Local processes, a whole number >= 1 (default None: all cores); 1 runs
        serially in this process.
    client : distributed.Client or str, optional
        Run on this Dask cluster (a scheduler address is connected to and closed after).
    progress : bool, optional
        tqdm bar over finished runs; None: only when stderr is a terminal.
    **simulate_options
        Passed to :func:`ballc.simulate` (method, rtol, atol, max_step, ...).

    Everything -- the parameters and every combination of them, ``t_end``, ``workers``
    and the simulate options -- is checked before the first run: an invalid one raises
    :class:`ballc.SceneError` naming it, its value and what is allowed.

    Returns
    -------
    pandas.DataFrame
        One row per combination, in ``itertools.product`` order: the swept values, then
        contacts, came_back (pandas' nullable boolean: True, False, or <NA> when
        undetermined -- fewer completed contacts than the criterion needs -- or when
        the run raised), first_reversal_time (s), energies (J), t_final (s), status,
        message, and the extra outputs.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C (a KeyboardInterrupt): the runs still going are stopped (a run
        interrupted is lost), and its ``table`` holds the rows of the finished ones.
    """
    cases = combinations(base_scene, parameters)
    t_end = check_simulate_options(base_scene, t_end, simulate_options)
    workers = check_workers(workers)
    named = _named_outputs(outputs)
    tasks = [(changes, scene, t_end, simulate_options, named) for changes, scene in cases]
    if progress is None:
        progress = sys.stderr.isatty()
    rows = [None] * len(tasks)       # filled in as the runs finish
    columns = [*parameters, *SUMMARY_COLUMNS, *named]
    try:
        if client is not None:
            _on_dask(client, tasks, rows, progress)
        elif workers == 1 or len(tasks) == 1:
            _in_this_process(tasks, rows, progress)
        else:
            _on_local_pool(tasks, workers, rows, progress)
    except KeyboardInterrupt:
        finished = [row for row in rows if row is not None]
        raise SweepInterrupted(_table(finished, columns), len(finished),
                               len(tasks)) from None
    return _table(rows, columns)


def _table(rows, columns):
    """The sweep's DataFrame of ``rows`` (dicts), with ``columns`` also when empty."""
    import pandas as pd
    table = pd.DataFrame(rows, columns=None if rows else columns)
    # three-valued: True, False, <NA> (undetermined, or the run raised)
    table["came_back"] = table["came_back"].astype("boolean")
    return table


def _bar(iterable, progress, total):
    if not progress:
        return iterable
    from tqdm import tqdm
    # mininterval 0: every finished run (pool: batch of runs) is shown at once
    return tqdm(iterable, total=total, desc="sweep", unit="run", mininterval=0)


def _in_this_process(tasks, rows, progress):
    """The runs one after the other in this process (workers = 1)."""
    bar = _bar(None, progress, len(tasks)) if progress else None
    checked = {}
    try:
        for i, task in enumerate(tasks):
            rows[i] = _run_one(*task, checked)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()


def _run_batch(batch):
    """Several runs in one worker call: one round trip per batch, not per run."""
    checked = {}
    return [_run_one(*task, checked) for task in batch]


#: A pool worker checks this often (s) whether the process that started it is still
#: there, and ends if not (its parent was killed without stopping it).
PARENT_CHECK_INTERVAL = 0.5


def _start_worker():
    """Initializer of each local pool worker.  SIGINT is ignored: a terminal's Ctrl-C
    reaches the whole process group, and the parent alone decides -- it stops the
    workers (a worker that took Ctrl-C for its run's result would go on with the next
    run).  The parent blocks SIGINT while it starts the workers (``_sigint_held``), so
    no Ctrl-C reaches a worker before this.  And a thread ends the worker when its
    parent is gone (killed outright, with no chance to stop it): no orphan runs on."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)       # also drops a pending SIGINT
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    threading.Thread(target=_end_with_parent, args=(os.getppid(),), daemon=True,
                     name="ballc-sweep-parent-watch").start()


def _end_with_parent(parent: int):
    import time
    while os.getppid() == parent:
        time.sleep(PARENT_CHECK_INTERVAL)
    os._exit(1)


@contextlib.contextmanager
def _sigint_held():
    """SIGINT blocked in this thread (the workers started in it inherit that until
    ``_start_worker`` ignores it); a Ctrl-C meanwhile is delivered at the end."""
    if not hasattr(signal, "pthread_sigmask"):      # (Windows: no process groups)
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _stop_workers(pool):
    """Stop a local pool now: no new run starts, the running ones are killed.  (The
    workers' processes are the executor's ``_processes``, the only handle on them before
    Python 3.14's ``terminate_workers``; taken before ``shutdown``, which drops them.)"""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        process.join(timeout=5)


def _on_local_pool(tasks, workers, rows, progress):
    from concurrent.futures import ProcessPoolExecutor, as_completed
    workers = min(workers or os.cpu_count() or 1, len(tasks))   # None: all cores
    # ~48 batches per worker: a map's runs cost a fraction of a millisecond each, so
    # submitting them one by one spent as much time in inter-process traffic as in
    # simulating; and the last batches, when a worker may wait for the other, are short
    size = max(1, math.ceil(len(tasks) / (48 * workers)))
    batches = [(start, tasks[start:start + size]) for start in range(0, len(tasks), size)]
    bar = _bar(None, progress, len(tasks)) if progress else None
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_start_worker)
    futures = {}
    try:
        with _sigint_held():       # the workers start (are forked) in these submits
            futures = {pool.submit(_run_batch, batch): start for start, batch in batches}
        import pandas   # noqa: F401 (the table's, imported while the workers run)
        for future in as_completed(futures):
            _keep(future.result(), futures[future], rows, bar)
    except BaseException:
        # Ctrl-C (or any error): stop the workers now, keep what has finished
        _stop_workers(pool)
        for future, start in futures.items():
            if (rows[start] is None and future.done() and not future.cancelled()
                    and future.exception() is None):
                _keep(future.result(), start, rows, None)
        raise
    else:
        pool.shutdown()
    finally:
        if bar is not None:
            bar.close()


def _keep(done, start, rows, bar):
    """A finished batch's rows into their places (grid order), counted on the bar."""
    for offset, row in enumerate(done):
        rows[start + offset] = row
    if bar is not None:
        bar.update(len(done))      # the bar counts runs, not batches


#: Seconds a Dask scheduler address is given to answer (distributed's default: 30).
CONNECT_TIMEOUT = 5.0


def _distributed():
    try:
        import distributed
    except ModuleNotFoundError:
        raise ModuleNotFoundError("client= needs Dask distributed: "
                                  "pip install 'ballc[dask]'") from None
    return distributed


def connect(address: str, name: str = "client"):
    """A ``distributed.Client`` of the Dask scheduler at ``address``; a ValueError naming
    ``name``, the address and what is allowed when none answers there within
    CONNECT_TIMEOUT s (checked before anything runs or is written)."""
    Client = _distributed().Client
    if not isinstance(address, str) or not address.strip():
        raise ValueError(f"{name} = {address!r} is not allowed: must be a Dask scheduler's "
                         "address such as tcp://host:8786 (or, for client=, a "
                         "distributed.Client)")
    try:
        _answers(address)
        return Client(address, timeout=CONNECT_TIMEOUT)
    except Exception as error:      # a bad address, nothing there, something else there
        reason = " ".join(str(error).split()) or type(error).__name__
        raise ValueError(f"{name} = {address!r} is not allowed: no Dask scheduler answered "
                         f"there within {CONNECT_TIMEOUT:g} s ({reason}); must be the "
                         "address of a running scheduler, such as tcp://host:8786") from None


def _answers(address: str) -> None:
    """Raise unless something accepts a TCP connection at a tcp:// ``address`` within
    CONNECT_TIMEOUT s -- checked before a ``distributed.Client`` is made, because a Client
    that fails to connect stays registered as dask's default scheduler and would divert
    later dask work in this process (xarray's writers, for one)."""
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port
    scheme, location = parse_address(address)
    if scheme not in ("tcp", "tls"):
        return          # other transports: the Client's own connect timeout decides
    host, port = parse_host_port(location)
    with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT):
        pass


def _on_dask(client, tasks, rows, progress):
    as_completed = _distributed().as_completed
    own = isinstance(client, str)
    if own:
        client = connect(client)
    futures = []
    try:
        futures = [client.submit(_run_one, *task, pure=False) for task in tasks]
        index = {future.key: i for i, future in enumerate(futures)}
        for future in _bar(as_completed(futures), progress, len(tasks)):
            rows[index[future.key]] = future.result()
    except BaseException:          # Ctrl-C (or any error): no run left on the cluster
        if futures:
            client.cancel(futures)
        raise
    finally:
        if own:
            client.close()


# --- sweep files (``ballc sweep sweep.toml``) ---

def load_sweep_file(path) -> dict:
    """Read a sweep file::

        t_end = 1.2                 # s, each run
        workers = 2                 # optional, local processes
        base = "seed.toml"          # optional scene file (relative to this file) ...
        [scene]                     # ... and/or scene fields overriding it
        c_tau = 0.9
        [parameters]                # scene field -> values; every combination is run
        mixture = [0.0, 0.5, 1.0]   # (one value, mixture = 0.3, is that value)
        friction_coefficient = [0.0, 0.1]
        [simulate]                  # optional: rtol, atol, method, exact_flight
        rtol = 1e-3

    Everything is checked here, before anything runs or is written: the keys, the
    scenes of every combination, t_end, workers and the [simulate] options.
    Returns {"base_scene", "parameters", "t_end", "workers", "simulate"}.
    """
    path = Path(path)
    data = read_toml(path)
    try:
        return _checked_sweep_file(path, data)
    except SceneError as error:
        raise SceneError(f"{path}: {error}") from None


#: Keys of a sweep file's [simulate] table (those of a scene file's, but t_end: the
#: sweep file has it at the top).
SWEEP_SIMULATE_KEYS = ("rtol", "atol", "method", "exact_flight")


def _checked_sweep_file(path, data) -> dict:
    known = ("t_end", "workers", "base", "scene", "parameters", "simulate")
    reject_unknown_keys(data, known, "sweep key", ", ".join(known))
    if not isinstance(data.get("parameters"), dict) or not data["parameters"]:
        raise SceneError("needs a [parameters] table (scene field -> list of values)")
    scene = Scene()
    if "base" in data:
        scene = Scene.from_toml(path.parent / data["base"])
    if "scene" in data:
        try:
            scene = scene.replace(**data["scene"])
        except SceneError as error:
            raise SceneError(f"[scene]: {error}") from None
    options = data.get("simulate", {})
    if not isinstance(options, dict):
        raise SceneError(f"simulate = {options!r} is not allowed: must be a [simulate] "
                         f"table with the keys {', '.join(SWEEP_SIMULATE_KEYS)}")
    try:
        reject_unknown_keys(options, SWEEP_SIMULATE_KEYS, "key",
                            ", ".join(SWEEP_SIMULATE_KEYS))
    except SceneError as error:
        raise SceneError(f"[simulate]: {error}") from None
    t_end = check_simulate_options(scene, data.get("t_end", 5.0), options)
    combinations(scene, data["parameters"])        # every scene, validated
    return {"base_scene": scene, "parameters": data["parameters"], "t_end": t_end,
            "workers": check_workers(data.get("workers")), "simulate": dict(options)}


def run_sweep_file(path, *, out=None, workers=None, scheduler=None) -> int:
    """``ballc sweep``: run a sweep file, write sweep.csv (+ a heat map for 2 parameters).
    The file and the scheduler (an address is connected to) are checked before the
    output folder is made.  On Ctrl-C the rows of the finished runs are written, and
    the SweepInterrupted raised again."""
    spec = load_sweep_file(path)
    workers = check_workers(workers, "--workers")
    client = connect(scheduler, "--scheduler") if isinstance(scheduler, str) else scheduler
    try:
        return _run_checked_sweep_file(path, spec, out, workers, client)
    finally:
        if client is not scheduler:
            client.close()


def _run_checked_sweep_file(path, spec, out, workers, client) -> int:
    out = Path(out) if out else Path(Path(path).stem)
    out.mkdir(parents=True, exist_ok=True)
    names = list(spec["parameters"])
    count = 1
    for values in spec["parameters"].values():
        count *= len(_values(values))
    processes = min(workers or spec["workers"] or os.cpu_count() or 1, count)
    where = f"Dask scheduler {client.scheduler.address}" if client is not None else \
        f"{processes} local process{'es' if processes > 1 else ''}"
    print(f"ballc sweep {path}: {count} run{'s' if count > 1 else ''} of {spec['t_end']:g} s "
          f"over {', '.join(names)} on {where} -> {out}/", flush=True)
    try:
        table = sweep(spec["base_scene"], spec["parameters"], spec["t_end"],
                      workers=workers or spec["workers"], client=client, **spec["simulate"])
    except SweepInterrupted as interrupted:
        written = _write_sweep_outputs(interrupted.table, out, names)
        what = (f"the {interrupted.finished} of {interrupted.total} runs that finished"
                if interrupted.finished else "no run had finished (the header only)")
        print(f"wrote {', '.join(str(p) for p in written)}: {what}")
        raise
    written = _write_sweep_outputs(table, out, names)
    verdicts = table["came_back"]
    print(f"{int(verdicts.eq(True).sum())} of {len(table)} scenes came back, "
          f"{int(verdicts.eq(False).sum())} did not, {int(verdicts.isna().sum())} "
          f"undetermined (fewer than {CAME_BACK_AFTER_CONTACTS} completed contacts); "
          f"{int((table['status'] != 0).sum())} did not reach t_end")
    print("wrote " + ", ".join(str(p) for p in written))
    return 0


def _write_sweep_outputs(table, out, names) -> list:
    """sweep.csv and, for two parameters (and some rows), the heat map came_back.png."""
    table.to_csv(out / "sweep.csv", index=False)
    written = [out / "sweep.csv"]
    if len(names) == 2 and len(table):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .plot import plot_sweep_map
        fig, _ = plot_sweep_map(table, x=names[1], y=names[0])
        fig.savefig(out / "came_back.png", dpi=100)
        plt.close(fig)
        written.append(out / "came_back.png")
    return written
