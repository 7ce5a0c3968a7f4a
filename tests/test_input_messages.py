"""Issue 28, item 6: inputs that were silently ignored or whose errors did not say what
happened -- each now a clear error naming the input, its value and what is allowed,
with plain numbers (never numpy's reprs such as np.float64(1.0))."""
import pandas as pd
import pytest

import ballc
from ballc.sweep import load_sweep_file

STEEL = ballc.Scene(radius=0.01, mass=0.0327, ceiling_height=1.0, position=(0.0, 0.0, 0.5),
                    ball_youngs_modulus=2e11, plane_youngs_modulus=2e11,
                    tangential_model="compliant")


def _data(**extra):
    return pd.DataFrame(dict(vx=[1.0, 2.0], vy=[0.0, 0.0], vz=[-1.0, -1.0], wx=[0.0, 0.0],
                             wy=[0.0, 0.0], wz=[0.0, 0.0], vx_after=[0.8, 1.6], **extra))


@pytest.mark.parametrize("column, suggestion", [("vz_afer", "vz_after"),
                                                ("wz after", "wz_after"),
                                                ("spin_after", None)])
def test_fit_rejects_a_misspelt_rebound_column(column, suggestion):
    """Before: a misspelt rebound column was silently left out of the fit (the fit ran
    on the other columns alone)."""
    with pytest.raises(ballc.SceneError) as caught:
        ballc.fit_impacts(STEEL, _data(**{column: [-0.5, -0.5]}),
                          free=("friction_coefficient",))
    message = str(caught.value)
    assert repr(column) in message and "vx_after, vy_after, vz_after" in message
    if suggestion:
        assert f"did you mean {suggestion!r}" in message


def test_fit_allows_columns_that_are_not_rebounds():
    """Labels (fit_kharaz's "what") and a fit's own *_fit predictions are not rebound
    columns and do not look like one: they are allowed and ignored."""
    fit = ballc.fit_impacts(STEEL, _data(what=["a", "b"], vx_after_fit=[0.7, 1.5]),
                            free=("friction_coefficient",), max_nfev=2)
    assert fit.values.size == 1


def test_fit_messages_print_plain_numbers():
    """Before: "velocity = (np.float64(1.0), np.float64(0.0), np.float64(1.0)) is not
    allowed"; now plain numbers, and the data row named."""
    data = _data()
    data.loc[1, "vz"] = 1.0              # moving away from the floor
    with pytest.raises(ballc.SceneError) as caught:
        ballc.fit_impacts(STEEL, data, free=("friction_coefficient",))
    message = str(caught.value)
    assert "np." not in message, message
    assert "data row 1" in message and "velocity = (2.0, 0.0, 1.0)" in message


def test_impact_messages_print_plain_numbers():
    import numpy as np
    with pytest.raises(ballc.SceneError) as caught:
        ballc.impact(STEEL, np.array([1.0, 0.0, np.inf]), (0.0, 0.0, 0.0))
    assert "np." not in str(caught.value) and "[1.0, 0.0, inf]" in str(caught.value)


@pytest.mark.parametrize("keep", [0.5, 0.98])
def test_a_truncated_npz_is_a_value_error_naming_the_file(tmp_path, keep):
    """Before: zipfile.BadZipFile("File is not a zip file"), without the file's name;
    the README promises a ValueError naming it."""
    path = tmp_path / "run.npz"
    ballc.simulate(ballc.Scene(), 0.2).save(path)
    data = path.read_bytes()
    cut = tmp_path / "cut.npz"
    cut.write_bytes(data[:int(keep * len(data))])
    with pytest.raises(ValueError, match=r"cannot load .*cut\.npz.*truncated"):
        ballc.load(cut)


def test_a_damaged_npz_member_is_a_value_error_naming_the_file(tmp_path):
    """An archive whose directory is whole but whose data is damaged: the error comes
    when an array is read (a CRC or zlib error), and names the file too."""
    path = tmp_path / "run.npz"
    ballc.simulate(ballc.Scene(), 0.2).save(path)
    data = bytearray(path.read_bytes())
    middle = len(data) // 3
    data[middle:middle + 64] = bytes(64)
    damaged = tmp_path / "damaged.npz"
    damaged.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"cannot load .*damaged\.npz"):
        ballc.load(damaged)


def test_a_sweep_of_a_vector_field_over_numbers_says_how_to_sweep_vectors(tmp_path):
    """Before: velocity = [-5, 5, -25] said "velocity must be 3 numbers, got -5"."""
    (tmp_path / "s.toml").write_text("t_end = 0.2\n[parameters]\nvelocity = [-5, 5, -25]\n")
    with pytest.raises(ballc.SceneError) as caught:
        load_sweep_file(tmp_path / "s.toml")
    message = str(caught.value)
    assert "velocity = [-5, 5, -25]" in message
    assert "single numbers -5, 5, -25" in message
    assert "velocity = [[-5, 5, -25], [...], ...]" in message
    assert "velocity = [[-5, 5, -25]]" in message


def test_a_sweep_over_vectors_runs_each_vector():
    """The form the message gives: a list of vectors, one run each."""
    table = ballc.sweep(ballc.Scene(), {"velocity": [[-5, 5, -25], [0, 0, -1]]}, 0.1,
                        workers=1)
    assert [tuple(v) for v in table["velocity"]] == [(-5, 5, -25), (0, 0, -1)]
