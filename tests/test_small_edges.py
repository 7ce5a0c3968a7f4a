"""Issue 21, item 5: words and small edges -- one definition of the contact point, plain
numbers in messages, errors that name the file, negative numbers on the command line, a
quiet end on a broken pipe, and a clear error for a foreign .npz."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ballc
from ballc.cli import main

ENV = {**os.environ, "MPLBACKEND": "Agg",
       "PYTHONPATH": os.pathsep.join([str(Path(ballc.__file__).resolve().parents[1])]
                                     + [p for p in os.environ.get("PYTHONPATH", "").split(
                                         os.pathsep) if p])}


@pytest.fixture(scope="module")
def seed():
    return ballc.simulate(ballc.Scene(), 1.2)


def test_every_figure_marks_the_contact_point_at_maximum_penetration(seed):
    """The top view and the animation drew the centre at t_start, contacts.csv the
    centre at maximum penetration: now all use Contact.contact_point, and say so."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ballc.plot import contact_points
    expected = np.array([c.contact_point for c in seed.contacts])
    at_start = np.array([[np.interp(c.t_start, seed.t, seed.position[k]) for k in (0, 1)]
                         for c in seed.contacts])
    assert np.abs(expected - at_start).max() > 1e-3        # the two definitions differ
    np.testing.assert_array_equal(contact_points(seed)[:, :2], expected)
    fig, ax = seed.plot_contacts()
    drawn = np.vstack([c.get_offsets() for c in ax.collections if len(c.get_offsets())])
    assert sorted(map(tuple, drawn)) == sorted(map(tuple, expected))
    assert "maximum penetration" in ax.get_title()
    plt.close(fig)
    frame = seed.contacts_dataframe()
    np.testing.assert_array_equal(frame[["contact_point_x", "contact_point_y"]], expected)


def test_numbers_in_messages_are_plain():
    state = ballc.Scene().initial_state()
    state[ballc.STATE_NAMES.index("z")] = -3.0
    with pytest.raises(ballc.SceneError) as error:
        ballc.simulate(ballc.Scene(), 1.0, y0=state)
    assert "z = -3.0 must be" in str(error.value) and "np." not in str(error.value)
    for make in (lambda: ballc.Scene(mass=np.float64(-1.0)),
                 lambda: ballc.simulate(ballc.Scene(), np.float64(-1.0)),
                 lambda: ballc.simulate(ballc.Scene(), 1.0, atol=np.full(3, -1.0))):
        with pytest.raises(ballc.SceneError) as error:
            make()
        assert "np." not in str(error.value) and "-1.0" in str(error.value)


def test_a_scene_file_that_is_not_utf8_is_named(tmp_path, capsys):
    path = tmp_path / "latin1.toml"
    path.write_bytes("mass = 1.0\n# caf\u00e9\n".encode("latin-1"))
    with pytest.raises(ballc.SceneError, match="latin1.toml: not UTF-8"):
        ballc.Scene.from_toml(path)
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "latin1.toml: not UTF-8" in capsys.readouterr().err


def test_negative_numbers_reach_ballcs_own_check(tmp_path, capsys):
    """argparse took "-1e-6" for an option; now ballc's validation names the value."""
    from ballc.cli import join_negative_numbers
    assert join_negative_numbers(["run", "s.toml", "--rtol", "-1e-6", "--t-end", "-inf"]) \
        == ["run", "s.toml", "--rtol=-1e-6", "--t-end=-inf"]
    assert join_negative_numbers(["run", "--out", "-x", "--animate"]) == \
        ["run", "--out", "-x", "--animate"]
    path = tmp_path / "s.toml"
    ballc.Scene().to_toml(path)
    assert main(["run", str(path), "--rtol", "-1e-6", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "rtol = -1e-06 is not allowed: must be finite and > 0" in err
    assert not (tmp_path / "o").exists()


def test_a_broken_pipe_ends_quietly(tmp_path):
    """``ballc run ... | head``: the reader is gone before ballc writes; no "[Errno 32]
    Broken pipe", no traceback, exit code 141 (128 + SIGPIPE)."""
    ballc.Scene().to_toml(tmp_path / "s.toml")
    process = subprocess.Popen(
        [sys.executable, "-m", "ballc", "run", "s.toml", "--t-end", "0.1", "--out", "o"],
        cwd=tmp_path, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()                    # the reader went away
    stderr = process.stderr.read().decode()
    assert process.wait(timeout=120) == 141, stderr
    assert stderr == ""


def test_loading_a_foreign_npz_names_the_file_and_what_is_expected(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, a=np.arange(3))
    with pytest.raises(ValueError, match="other.npz.*not a ballc result file.*it has no "
                                         "header, t, y.*it holds: a.*Result.save"):
        ballc.load(path)
    np.save(tmp_path / "one.npy", np.arange(3))
    (tmp_path / "one.npy").rename(tmp_path / "one.npz")
    with pytest.raises(ValueError, match="one.npz.*not a ballc result file"):
        ballc.load(tmp_path / "one.npz")
    (tmp_path / "text.npz").write_text("hello")
    with pytest.raises(ValueError, match="text.npz.*not an .npz archive"):
        ballc.load(tmp_path / "text.npz")
