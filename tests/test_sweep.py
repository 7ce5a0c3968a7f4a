"""Sweeps: validated up front; 2 local workers and a Dask cluster give exactly the serial table."""
import pandas as pd
import pytest

import ballc

BASE = ballc.Scene()
GRID = {"mixture": [0.0, 1.0], "friction_coefficient": [0.0, 0.1]}
T_END = 0.7


def final_height(result):
    """An extra output column (module level, so it pickles)."""
    return float(result.position[2, -1])


@pytest.fixture(scope="module")
def serial():
    return ballc.sweep(BASE, GRID, T_END, workers=1, outputs=[final_height])


def test_serial_table_has_one_row_per_combination(serial):
    assert len(serial) == 4
    assert list(serial[["mixture", "friction_coefficient"]].itertuples(index=False, name=None)) \
        == [(0.0, 0.0), (0.0, 0.1), (1.0, 0.0), (1.0, 0.1)]
    for column in ("contacts", "came_back", "energy_lost", "status", "message", "final_height"):
        assert column in serial
    # 0.7 s of the seed throw: its floor (t = 0.156 s) and ceiling (0.575 s) contacts, as
    # the seed's own run has them (shared NOTES); the next floor contact is at 1.03 s
    assert (serial["status"] == 0).all() and (serial["contacts"] == 2).all()
    one = ballc.simulate(BASE.replace(mixture=1.0, friction_coefficient=0.1), T_END)
    assert serial["final_height"].iloc[3] == one.position[2, -1]


def test_two_local_workers_equal_serial_exactly(serial):
    parallel = ballc.sweep(BASE, GRID, T_END, workers=2, outputs=[final_height])
    pd.testing.assert_frame_equal(parallel, serial, check_exact=True)


def test_dask_cluster_equals_serial_exactly(serial):
    distributed = pytest.importorskip("distributed", reason="Dask is the optional 'dask' extra")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            on_client = ballc.sweep(BASE, GRID, T_END, client=client, outputs=[final_height])
        by_address = ballc.sweep(BASE, GRID, T_END, client=cluster.scheduler_address,
                                 outputs=[final_height])
    pd.testing.assert_frame_equal(on_client, serial, check_exact=True)
    pd.testing.assert_frame_equal(by_address, serial, check_exact=True)


def test_bad_parameters_fail_before_anything_runs():
    with pytest.raises(ballc.SceneError, match="did you mean 'mixture'"):
        ballc.sweep(BASE, {"mixtur": [0.1]}, T_END)
    with pytest.raises(ballc.SceneError, match="mixture"):
        ballc.sweep(BASE, {"mixture": [0.5, 2.0]}, T_END)


def test_sweep_file_runs_from_the_command_line(tmp_path):
    import os
    import subprocess
    import sys
    BASE.to_toml(tmp_path / "base.toml")
    (tmp_path / "s.toml").write_text(
        't_end = 0.7\nworkers = 2\nbase = "base.toml"\n[parameters]\n'
        'mixture = [0.0, 1.0]\nfriction_coefficient = [0.0, 0.1]\n')
    done = subprocess.run([sys.executable, "-m", "ballc", "sweep", "s.toml", "--out", "o"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(tmp_path / "o" / "sweep.csv")
    assert len(table) == 4 and (tmp_path / "o" / "came_back.png").stat().st_size > 0


def test_dask_worker_processes_give_the_same_bits():
    """Dask workers in their own processes (their own BLAS threading settings) give the
    same bits as this process: radau5 solves its Newton systems with ballc's own LU, so
    no result depends on how a LAPACK build splits its work (issue 9 measured 8.4e-8 J
    of difference in energy_final with LAPACK)."""
    distributed = pytest.importorskip("distributed", reason="Dask is the optional 'dask' extra")
    grid = {"mixture": [0.0, 0.375], "friction_coefficient": [0.1, 0.4]}
    here = ballc.sweep(BASE, grid, 1.2, workers=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            there = ballc.sweep(BASE, grid, 1.2, client=client)
    pd.testing.assert_frame_equal(there, here, check_exact=True)
    assert (here["status"] == 0).all()


# --- issue 21, item 2: everything is checked before anything runs ---

def test_a_single_value_is_one_value():
    """{"mixture": 0.3} (a number, not a list) is the one value 0.3, as is a string."""
    table = ballc.sweep(BASE, {"mixture": 0.3, "tangential_model": "friction"}, 0.2, workers=1)
    assert len(table) == 1
    assert table["mixture"].iloc[0] == 0.3 and table["tangential_model"].iloc[0] == "friction"


@pytest.mark.parametrize("options, named", [
    ({"t_end": -1}, "t_end = -1"),
    ({"rtoll": 1e-3}, "did you mean 'rtol'"),
    ({"rtol": -1e-6}, "rtol = -1e-06"),
    ({"method": "radau"}, "method = 'radau'"),
    ({"workers": 0}, "workers = 0"),
    ({"workers": 1.5}, "workers = 1.5"),
])
def test_t_end_workers_and_simulate_options_fail_before_any_run(options, named, monkeypatch):
    """Before: t_end = -1 and rtoll = 1e-3 returned rows of status -1, workers = 0 ran
    on all cores.  Now each raises before the first run."""
    import importlib
    sweep_module = importlib.import_module("ballc.sweep")

    def no_run(*args):
        raise AssertionError("a run started")
    monkeypatch.setattr(sweep_module, "_run_one", no_run)
    arguments = {"t_end": 1.2, "workers": 1, **options}
    with pytest.raises(ballc.SceneError, match=named.replace("(", r"\(")):
        ballc.sweep(BASE, {"mixture": [0.1, 0.2]}, **arguments)


@pytest.mark.parametrize("text, named", [
    ("t_end = -1\n[parameters]\nmixture = 0.3\n", "t_end = -1"),
    ("t_end = 0.2\n[parameters]\nmixture = [0.3, 2.0]\n", "mixture = 2.0"),
    ("t_end = 0.2\n[parameters]\nmixture = 0.3\n[simulate]\nrtoll = 1e-3\n", "did you mean 'rtol'"),
    ("t_end = 0.2\n[parameters]\nmixture = 0.3\n[simulate]\nrtol = 2e-20\n", "rtol = 2e-20"),
    ("t_end = 0.2\nworkers = 0\n[parameters]\nmixture = 0.3\n", "workers = 0"),
])
def test_an_invalid_sweep_file_makes_no_output_folder(tmp_path, capsys, text, named):
    from ballc.cli import main
    (tmp_path / "s.toml").write_text(text)
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert named in captured.err and "s.toml" in captured.err
    assert captured.out == "" and not out.exists()


def test_a_sweep_file_runs_its_simulate_table_and_one_value(tmp_path, capsys):
    """[simulate] options reach every run (they were accepted and ignored before), and
    a scalar parameter is one run."""
    from ballc.cli import main
    (tmp_path / "s.toml").write_text(
        "t_end = 0.3\n[parameters]\nmixture = 0.3\n[simulate]\nrtol = 1e-3\natol = 1e-3\n")
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o")]) == 0
    assert "1 run of 0.3 s over mixture on 1 local process" in capsys.readouterr().out
    table = pd.read_csv(tmp_path / "o" / "sweep.csv")
    one = ballc.simulate(BASE.replace(mixture=0.3), 0.3, rtol=1e-3, atol=1e-3)
    assert len(table) == 1 and table["energy_final"].iloc[0] == pytest.approx(
        float(one.energy["total"][-1]), rel=1e-12)


def test_workers_is_one_rule_in_python_and_on_the_command_line(tmp_path, capsys):
    from ballc.cli import main
    with pytest.raises(ballc.SceneError, match="workers = 0"):
        ballc.sweep(BASE, {"mixture": 0.3}, 0.2, workers=0)
    (tmp_path / "s.toml").write_text("t_end = 0.2\n[parameters]\nmixture = 0.3\n")
    with pytest.raises(SystemExit) as exit_:
        main(["sweep", str(tmp_path / "s.toml"), "--workers", "0"])
    assert exit_.value.code == 2 and "workers = '0'" in capsys.readouterr().err


# --- issue 21, section 6: rows in the order of the grid, not of completion ---

def _last_submitted_first(futures):
    """concurrent.futures.as_completed, but deterministic and out of order: wait for
    every future, then hand them over last submitted first."""
    from concurrent.futures import wait
    futures = list(futures)
    wait(futures)
    return reversed(futures)


def test_rows_follow_the_grid_whatever_order_the_runs_complete_in(monkeypatch):
    """The local pool's runs handed back in reverse order of submission (as_completed
    replaced by a deterministic reversal: no timing, no machine load involved).  Oracle:
    row i must hold the grid's i-th value and the numbers of a direct ballc.simulate of
    that scene (its contact count, final energy and final height).  A table filled in
    completion order puts the last ceiling height (and its numbers) in row 0."""
    import concurrent.futures
    monkeypatch.setattr(concurrent.futures, "as_completed", _last_submitted_first)
    base = ballc.Scene(gravity=0.0, c_tau=0.99, ball_youngs_modulus=3e7,
                       position=(0.0, 0.0, 1.025))
    heights = [2.05, 2.5, 3.0, 3.5]
    table = ballc.sweep(base, {"ceiling_height": heights}, 0.3, workers=2,
                        outputs=[final_height])
    assert list(table["ceiling_height"]) == heights
    for i, height in enumerate(heights):
        one = ballc.simulate(base.replace(ceiling_height=height), 0.3)
        assert table["status"].iloc[i] == 0
        assert table["contacts"].iloc[i] == len(one.contacts)
        assert table["energy_final"].iloc[i] == pytest.approx(float(one.energy["total"][-1]),
                                                              rel=1e-12)
        assert table["final_height"].iloc[i] == one.position[2, -1]
    # the runs differ, so a misplaced row cannot pass for the right one
    assert len(set(table["final_height"])) == len(heights)


def test_dask_rows_follow_the_grid_whatever_order_they_complete_in(monkeypatch):
    """As the local pool's test above, on Dask: distributed.as_completed replaced by a
    deterministic reversal (every future waited for, then handed back last submitted
    first), so that a table filled in completion order is wrong on every run, not only
    when the cluster happens to finish out of order.  Oracle: direct ballc.simulate
    runs of each row's scene."""
    distributed = pytest.importorskip("distributed", reason="Dask is the optional 'dask' extra")

    def last_submitted_first(futures, *args, **kwargs):
        futures = list(futures)
        distributed.wait(futures)
        return reversed(futures)

    monkeypatch.setattr(distributed, "as_completed", last_submitted_first)
    base = ballc.Scene(gravity=0.0, c_tau=0.99, ball_youngs_modulus=3e7,
                       position=(0.0, 0.0, 1.025))
    heights = [2.05, 2.5, 3.0, 3.5]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            table = ballc.sweep(base, {"ceiling_height": heights}, 0.3, client=client,
                                outputs=[final_height])
    assert list(table["ceiling_height"]) == heights
    for i, height in enumerate(heights):
        one = ballc.simulate(base.replace(ceiling_height=height), 0.3)
        assert table["status"].iloc[i] == 0
        assert table["contacts"].iloc[i] == len(one.contacts)
        assert table["final_height"].iloc[i] == one.position[2, -1]
    assert len(set(table["final_height"])) == len(heights)
