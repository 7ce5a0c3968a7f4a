"""Parameter sweeps: every combination of some scene fields, run in parallel.

    table = ballc.sweep(ballc.Scene(), {"mixture": [0, 0.5, 1],
                                        "friction_coefficient": [0.0, 0.1]}, t_end=1.2)

runs on a local process pool by default (``workers``: number of processes, default all
cores; 1 runs in this process), and on a Dask distributed cluster when given
``client=`` (a ``distributed.Client`` or a scheduler address such as
"tcp://host:8786"; the workers need ballc installed).  The same call either way, and
the same table: one row per scene, in the order of the combinations.
"""
from __future__ import annotations

import inspect
import itertools
import math
import os
import sys
from pathlib import Path

from .outcome import CAME_BACK_AFTER_CONTACTS, summary
from .scene import Scene, SceneError, read_toml, reject_unknown_keys

#: Columns every row has besides the swept parameters (see ballc.outcome.summary).
SUMMARY_COLUMNS = ("contacts", "came_back", "first_reversal_time", "energy_initial",
                   "energy_final", "energy_lost", "energy_lost_fraction", "t_final",
                   "status", "message")


def _run_one(changes: dict, scene: dict, t_end: float, options: dict, outputs: dict) -> dict:
    """One simulation -> one row (runs in a worker; module-level so it pickles)."""
    from .simulate import simulate
    row = dict(changes)
    try:
        result = simulate(Scene.from_dict(scene), t_end, progress=False, **options)
    except Exception as error:    # one failed scene must not lose the sweep
        row.update({name: float("nan") for name in SUMMARY_COLUMNS})
        row.update(status=-1, message=f"{type(error).__name__}: {error}",
                   **{name: float("nan") for name in outputs})
        return row
    row.update(summary(result))
    row.update({name: function(result) for name, function in outputs.items()})
    return row


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
    parameter given one value instead of a list (``{"mixture": 0.3}``) is that value."""
    if not isinstance(base_scene, Scene):
        raise TypeError(f"base_scene must be a ballc.Scene, got {type(base_scene).__name__}")
    if not isinstance(parameters, dict):
        raise SceneError(f"parameters = {parameters!r} is not allowed: must be a dict of "
                         "scene field -> list of values")
    names = list(parameters)
    grids = [_values(parameters[name]) for name in names]
    for name, grid in zip(names, grids):
        if not grid:
            raise SceneError(f"sweep parameter {name!r} has no values")
    cases = []
    for values in itertools.product(*grids):
        changes = dict(zip(names, values))
        cases.append((changes, base_scene.replace(**changes)))   # validates ("did you mean")
    return cases


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
    """
    import pandas as pd

    cases = combinations(base_scene, parameters)
    t_end = check_simulate_options(base_scene, t_end, simulate_options)
    workers = check_workers(workers)
    named = _named_outputs(outputs)
    tasks = [(changes, scene.to_dict(), t_end, simulate_options, named)
             for changes, scene in cases]
    if progress is None:
        progress = sys.stderr.isatty()
    if client is not None:
        rows = _on_dask(client, tasks, progress)
    elif workers == 1 or len(tasks) == 1:
        rows = [_run_one(*task) for task in _bar(tasks, progress, len(tasks))]
    else:
        rows = _on_local_pool(tasks, workers, progress)
    table = pd.DataFrame(rows)
    # three-valued: True, False, <NA> (undetermined, or the run raised)
    table["came_back"] = table["came_back"].astype("boolean")
    return table


def _bar(iterable, progress, total):
    if not progress:
        return iterable
    from tqdm import tqdm
    return tqdm(iterable, total=total, desc="sweep", unit="run")


def _run_batch(batch):
    """Several runs in one worker call: one round trip per batch, not per run."""
    return [_run_one(*task) for task in batch]


def _on_local_pool(tasks, workers, progress):
    from concurrent.futures import ProcessPoolExecutor, as_completed
    workers = min(workers or os.cpu_count() or 1, len(tasks))   # None: all cores
    # ~16 batches per worker: a map's runs cost milliseconds each, so submitting them
    # one by one spent as much time in inter-process traffic as in simulating
    size = max(1, math.ceil(len(tasks) / (16 * workers)))
    batches = [(start, tasks[start:start + size]) for start in range(0, len(tasks), size)]
    rows = [None] * len(tasks)
    bar = _bar(None, progress, len(tasks)) if progress else None
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(_run_batch, batch): start for start, batch in batches}
        for future in as_completed(futures):
            start = futures[future]
            done = future.result()
            for offset, row in enumerate(done):
                rows[start + offset] = row
            if bar is not None:
                bar.update(len(done))      # the bar counts runs, not batches
    if bar is not None:
        bar.close()
    return rows


def _on_dask(client, tasks, progress):
    try:
        from distributed import Client, as_completed
    except ModuleNotFoundError:
        raise ModuleNotFoundError("client= needs Dask distributed: "
                                  "pip install 'ballc[dask]'") from None
    own = isinstance(client, str)
    if own:
        client = Client(client)
    try:
        futures = [client.submit(_run_one, *task, pure=False) for task in tasks]
        index = {future.key: i for i, future in enumerate(futures)}
        rows = [None] * len(tasks)
        for future in _bar(as_completed(futures), progress, len(tasks)):
            rows[index[future.key]] = future.result()
        return rows
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
    The file is checked completely before the output folder is made."""
    spec = load_sweep_file(path)
    workers = check_workers(workers, "--workers")
    out = Path(out) if out else Path(Path(path).stem)
    out.mkdir(parents=True, exist_ok=True)
    names = list(spec["parameters"])
    count = 1
    for values in spec["parameters"].values():
        count *= len(_values(values))
    processes = min(workers or spec["workers"] or os.cpu_count() or 1, count)
    where = f"Dask scheduler {scheduler}" if scheduler else \
        f"{processes} local process{'es' if processes > 1 else ''}"
    print(f"ballc sweep {path}: {count} run{'s' if count > 1 else ''} of {spec['t_end']:g} s "
          f"over {', '.join(names)} on {where} -> {out}/")
    table = sweep(spec["base_scene"], spec["parameters"], spec["t_end"],
                  workers=workers or spec["workers"], client=scheduler, **spec["simulate"])
    table.to_csv(out / "sweep.csv", index=False)
    written = [out / "sweep.csv"]
    if len(names) == 2:
        import matplotlib
        matplotlib.use("Agg")
        from .plot import plot_sweep_map
        fig, _ = plot_sweep_map(table, x=names[1], y=names[0])
        fig.savefig(out / "came_back.png", dpi=100)
        written.append(out / "came_back.png")
    verdicts = table["came_back"]
    print(f"{int(verdicts.eq(True).sum())} of {len(table)} scenes came back, "
          f"{int(verdicts.eq(False).sum())} did not, {int(verdicts.isna().sum())} "
          f"undetermined (fewer than {CAME_BACK_AFTER_CONTACTS} completed contacts); "
          f"{int((table['status'] != 0).sum())} did not reach t_end")
    print("wrote " + ", ".join(str(p) for p in written))
    return 0
