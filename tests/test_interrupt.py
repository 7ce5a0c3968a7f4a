"""Ctrl-C (SIGINT) on the console commands, sent from this test process to a
``python -m ballc`` subprocess, as a terminal sends it (to the whole process group) or
to the parent process alone; and the parent killed outright.

No test here depends on timing: each waits (with generous timeouts, which only bound a
hang) for what the command itself reports -- its first line on stdout, or the progress
bar on a pseudo-terminal counting the finished runs -- before it sends the signal, and
the scenes' slow runs would need minutes to hours to finish, so what is asserted (rows
written, exit code, no process left) is the same whatever the machine's load.  The
worker processes are found in /proc (Linux).
"""
import os
import re
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

import ballc

from test_cli import ENV

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="needs /proc and a pseudo-terminal (Linux)")

#: Bounds of the waits: a hang fails the test after this long instead of blocking.
WAIT = 120.0
#: Exit code of an interrupted command: 128 + SIGINT.
INTERRUPTED = 130

#: A scene of elastic bounces with solve_ivp's RK45 (Python, ~50 k calls/s): a run of
#: 1e6 s needs its whole call budget (2e7 calls: minutes), while c_tau = 0.5 and 0.6
#: come to rest within 15 s and end in closed form (~0.1 s).  Sweep order: the two
#: fast runs first, then the two slow ones.
SWEEP_FILE = """\
t_end = 1e6
[scene]
velocity = [0.0, 0.0, 0.0]
observer_mass = 0.0
tangential_model = "friction"
friction_coefficient = 0.0
[parameters]
c_tau = [0.5, 0.6, 1.0, 0.999999]
[simulate]
method = "RK45"
"""
FAST = [0.5, 0.6]


def _process(pid):
    """(state, ppid, start time) of process ``pid`` from /proc, or None if gone."""
    try:
        with open(f"/proc/{pid}/stat") as stream:
            fields = stream.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return fields[0], int(fields[1]), int(fields[19])


def _descendants(pid) -> dict:
    """{pid: its start time} of the live descendants of ``pid`` -- the pool's workers
    (children with the fork start method; grandchildren, under a fork server, with the
    forkserver one)."""
    parents = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            info = _process(int(name))
            if info and info[0] != "Z":
                parents[int(name)] = (info[1], info[2])
    found, frontier = {}, {pid}
    while frontier:
        frontier = {child for child, (parent, _) in parents.items() if parent in frontier}
        found.update({child: parents[child][1] for child in frontier})
    return found


def _alive(pid, started) -> bool:
    """Process ``pid`` (started at ``started``: not a later one with a reused pid) is
    still running (a zombie has ended)."""
    info = _process(pid)
    return info is not None and info[2] == started and info[0] != "Z"


class _Command:
    """``python -m ballc *args`` in its own session (its own process group, as a
    terminal's foreground job), stdout a pipe and stderr a pseudo-terminal, so that
    the command shows its progress bar as on a terminal."""

    def __init__(self, *args, cwd):
        import fcntl
        import pty
        import struct
        import termios
        self.master, slave = pty.openpty()
        # a terminal's size (a new pseudo-terminal has 0 columns: no room for a bar)
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
        self.proc = subprocess.Popen([sys.executable, "-m", "ballc", *args], cwd=cwd,
                                     env=ENV, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=slave,
                                     start_new_session=True, text=True)
        os.close(slave)
        self.err = ""
        self.workers = {}

    def _read_err(self, timeout) -> bool:
        ready, _, _ = select.select([self.master], [], [], timeout)
        if not ready:
            return True
        try:
            chunk = os.read(self.master, 4096)
        except OSError:          # EIO: the command has ended, the terminal is closed
            return False
        if not chunk:
            return False
        self.err += chunk.decode(errors="replace")
        return True

    def wait_for_finished_runs(self, count):
        """Wait until the progress bar shows ``count`` finished runs; record the
        workers (the command's descendants) alive then."""
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            done = [int(n) for n in re.findall(r"(\d+)/\d+ \[", self.err)]
            if done and max(done) >= count:
                self.workers = _descendants(self.proc.pid)
                return
            if not self._read_err(0.5) or self.proc.poll() is not None:
                break
        self.kill()
        pytest.fail(f"no progress to {count} finished runs: {self.err!r}")

    def wait_for_first_line(self):
        """Wait until the command has printed its first line (it flushes it)."""
        line = self.proc.stdout.readline()
        assert line.startswith("ballc"), (line, self.err)
        return line

    def finish(self):
        """Wait for the end; (exit code, stdout, stderr)."""
        try:
            out, _ = self.proc.communicate(timeout=WAIT)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"still running {WAIT:g} s after the signal: {self.err!r}")
        while self._read_err(0.2):
            pass
        os.close(self.master)
        return self.proc.returncode, out, self.err.replace("\r\n", "\n")

    def kill(self):
        for pid, started in self.workers.items():
            if _alive(pid, started):
                os.kill(pid, signal.SIGKILL)
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


def _no_process_left(workers):
    """Every worker recorded has ended (its parent, if still there, has reaped it, or
    the init process has); waits up to WAIT for that."""
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        left = [pid for pid, started in workers.items() if _alive(pid, started)]
        if not left:
            return
        time.sleep(0.2)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    pytest.fail(f"worker processes {left} still running {WAIT:g} s later")


def _last_line(err):
    lines = [line for line in err.splitlines() if line.strip()]
    return lines[-1] if lines else ""


def _assert_partial_sweep(out_folder, out, err, total=4):
    """Exit code 130 handled by the caller; here: no traceback, one line saying the
    sweep was interrupted after k of ``total`` runs, and sweep.csv holding exactly those
    k finished rows (the fast ones among them), with honest numbers."""
    assert "Traceback" not in err, err
    message = _last_line(err)
    assert "interrupted" in message and "Ctrl-C" in message, err
    finished = int(re.search(rf"(\d+) of {total} runs", message).group(1))
    table = pd.read_csv(out_folder / "sweep.csv")
    assert len(table) == finished >= len(FAST), (message, table)
    assert set(FAST) <= set(table["c_tau"])
    assert (table["status"] == 0).all() and (table["t_final"] == 1e6).all()
    assert "sweep.csv" in out


def _pool_sweep(tmp_path):
    """``ballc sweep`` started on the slow sweep file with 2 workers, in ``tmp_path``."""
    text = SWEEP_FILE.replace("t_end = 1e6\n", "t_end = 1e6\nworkers = 2\n")
    (tmp_path / "slow.toml").write_text(text)
    return _Command("sweep", "slow.toml", "--out", "out", cwd=tmp_path)


@pytest.mark.parametrize("to_group", [True, False], ids=["to the group", "to the parent"])
def test_ctrl_c_stops_a_pool_sweep_and_its_workers(tmp_path, to_group):
    """Issue 28, item 2: a Ctrl-C sent to the process group (a terminal's) kept a pool
    sweep running for its whole slow runs (its workers caught KeyboardInterrupt as a
    run's result and went on; the parent waited for them); sent to the parent alone it
    left the workers orphaned, running.  Now both end the sweep: the workers are
    stopped, the finished rows are written, one line says so, exit code 130."""
    command = _pool_sweep(tmp_path)
    try:
        command.wait_for_finished_runs(len(FAST))
        assert len(command.workers) >= 2, command.workers
        (os.killpg if to_group else os.kill)(command.proc.pid, signal.SIGINT)
        code, out, err = command.finish()
    finally:
        command.kill()
    assert code == INTERRUPTED, (code, out, err)
    _no_process_left(command.workers)
    _assert_partial_sweep(tmp_path / "out", out, err)


def test_a_pool_sweeps_workers_end_with_their_parent(tmp_path):
    """A parent killed outright (SIGKILL: no chance to stop its workers) must not leave
    them running: each worker watches its parent and ends when it is gone."""
    command = _pool_sweep(tmp_path)
    try:
        command.wait_for_finished_runs(len(FAST))
        assert len(command.workers) >= 2, command.workers
        os.kill(command.proc.pid, signal.SIGKILL)
        command.proc.wait(timeout=WAIT)
        _no_process_left(command.workers)
    finally:
        command.kill()
        os.close(command.master)


def test_ctrl_c_stops_a_serial_sweep_with_its_finished_rows(tmp_path):
    """Issue 28, item 6: ``--workers 1`` printed a KeyboardInterrupt traceback and left an
    empty folder.  Now: the finished rows written, one line, exit code 130."""
    (tmp_path / "slow.toml").write_text(SWEEP_FILE)
    command = _Command("sweep", "slow.toml", "--out", "out", "--workers", "1", cwd=tmp_path)
    try:
        command.wait_for_finished_runs(len(FAST))
        os.killpg(command.proc.pid, signal.SIGINT)
        code, out, err = command.finish()
    finally:
        command.kill()
    assert code == INTERRUPTED, (code, out, err)
    _assert_partial_sweep(tmp_path / "out", out, err)


SLOW_SCENE = """\
velocity = [0.0, 0.0, 0.0]
observer_mass = 0.0
c_tau = 1.0
tangential_model = "friction"
friction_coefficient = 0.0
[simulate]
t_end = 1e6
method = "RK45"
"""


def test_ctrl_c_on_run_ends_in_one_line_and_leaves_no_empty_folder(tmp_path):
    """Issue 28, item 6: Ctrl-C on ``ballc run`` printed a KeyboardInterrupt traceback
    and left the (empty) output folder it had made.  Now: one line, exit code 130, and
    the folder it made is removed again, since nothing was written into it."""
    (tmp_path / "slow.toml").write_text(SLOW_SCENE)
    command = _Command("run", "slow.toml", "--out", "out", cwd=tmp_path)
    try:
        command.wait_for_first_line()
        os.killpg(command.proc.pid, signal.SIGINT)
        code, out, err = command.finish()
    finally:
        command.kill()
    assert code == INTERRUPTED, (code, out, err)
    assert "Traceback" not in err, err
    assert "interrupted" in _last_line(err) and "Ctrl-C" in _last_line(err), err
    assert not (tmp_path / "out").exists()


def test_an_interrupted_serial_sweep_keeps_its_finished_rows(monkeypatch):
    """ballc.sweep itself: a KeyboardInterrupt in the third of four runs (raised by the
    run, no signal involved) ends the sweep with SweepInterrupted -- a KeyboardInterrupt,
    so a script stops as on any Ctrl-C -- holding the two finished rows, in grid order,
    equal to those of the same runs swept alone."""
    module = sys.modules["ballc.sweep"]
    calls = []
    original = module._run_one

    def third_interrupted(*args):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return original(*args)
    monkeypatch.setattr(module, "_run_one", third_interrupted)
    base = ballc.Scene(gravity=0.0, c_tau=0.99, ball_youngs_modulus=3e7,
                       position=(0.0, 0.0, 1.025))
    heights = [2.05, 2.5, 3.0, 3.5]
    with pytest.raises(KeyboardInterrupt) as caught:
        ballc.sweep(base, {"ceiling_height": heights}, 0.3, workers=1)
    assert isinstance(caught.value, ballc.SweepInterrupted)
    partial = caught.value.table
    monkeypatch.setattr(module, "_run_one", original)
    alone = ballc.sweep(base, {"ceiling_height": heights[:2]}, 0.3, workers=1)
    pd.testing.assert_frame_equal(partial, alone)
    assert "2 of 4 runs" in str(caught.value)


def test_an_interrupted_dask_sweep_cancels_its_runs_and_keeps_its_finished_rows(monkeypatch):
    """The Dask path: a KeyboardInterrupt while the results come in (raised by the
    results' iterator after two of four, no signal involved) cancels the runs left on
    the cluster and raises SweepInterrupted with the two rows, equal to a serial sweep's."""
    distributed = pytest.importorskip("distributed")
    cancelled = []

    def two_then_ctrl_c(futures):
        distributed.wait(futures)
        yield from list(futures)[:2]
        raise KeyboardInterrupt
    monkeypatch.setattr(distributed, "as_completed", two_then_ctrl_c)
    base = ballc.Scene(gravity=0.0, c_tau=0.99, ball_youngs_modulus=3e7,
                       position=(0.0, 0.0, 1.025))
    heights = [2.05, 2.5, 3.0, 3.5]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        original = client.cancel
        monkeypatch.setattr(client, "cancel",
                            lambda futures, **kw: (cancelled.extend(futures),
                                                   original(futures, **kw)))
        with pytest.raises(ballc.SweepInterrupted) as caught:
            ballc.sweep(base, {"ceiling_height": heights}, 0.3, client=client)
    assert len(cancelled) == len(heights)
    alone = ballc.sweep(base, {"ceiling_height": heights[:2]}, 0.3, workers=1)
    pd.testing.assert_frame_equal(caught.value.table, alone)
    assert caught.value.finished == 2 and caught.value.total == 4
