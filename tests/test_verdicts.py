"""Issue 21, item 3: verdicts and warnings a user can trust -- "came back" is
three-valued, the sanity checks are the same for every method, and a tolerance too
loose to trust is named."""
import copy

import numpy as np
import pandas as pd
import pytest

import ballc
from ballc import outcome


@pytest.fixture(scope="module")
def short():
    """0.7 s of the seed throw: its floor and ceiling contacts, not the third."""
    return ballc.simulate(ballc.Scene(), 0.7, rtol=1e-6, atol=1e-6)


def test_fewer_contacts_than_the_criterion_needs_is_undetermined(short):
    """--t-end 0.7 printed "CAME BACK" and --t-end 0.3 "did NOT come back"."""
    assert len(short.contacts) == 2
    assert outcome.came_back(short) is None
    text = outcome.format_summary(short)
    assert "UNDETERMINED" in text and "CAME BACK" not in text and "did NOT" not in text
    assert outcome.came_back(ballc.simulate(ballc.Scene(), 0.3, rtol=1e-6, atol=1e-6)) is None
    full = ballc.simulate(ballc.Scene(), 1.2, rtol=1e-6, atol=1e-6)
    assert len(full.contacts) == 3 and outcome.came_back(full) is True
    assert "the ball CAME BACK" in outcome.format_summary(full)
    friction = ballc.simulate(ballc.Scene(tangential_model="friction"), 1.2, rtol=1e-6,
                              atol=1e-6)
    assert outcome.came_back(friction) is False
    assert "the ball did NOT come back" in outcome.format_summary(friction)


def test_the_sweep_column_is_three_valued():
    table = ballc.sweep(ballc.Scene(), {"tangential_model": ["mixture", "friction"],
                                        "mixture": 0.375}, 1.2, workers=1,
                        rtol=1e-6, atol=1e-6)
    short = ballc.sweep(ballc.Scene(), {"mixture": 0.375}, 0.7, workers=1,
                        rtol=1e-6, atol=1e-6)
    assert str(table["came_back"].dtype) == "boolean"
    assert table["came_back"].tolist() == [True, False]
    assert short["came_back"].isna().all() and short["contacts"].iloc[0] == 2


def test_the_map_has_a_third_colour_for_undetermined():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ballc.plot import CAME_BACK_COLOURS, plot_sweep_map
    table = pd.DataFrame({"mixture": [0.0, 0.0, 0.5, 0.5],
                          "friction_coefficient": [0.1, 0.2] * 2,
                          "came_back": pd.array([False, None, True, False], dtype="boolean"),
                          "energy_lost_fraction": [0.4] * 4, "status": [0] * 4})
    fig, ax = plot_sweep_map(table, x="friction_coefficient", y="mixture")
    try:
        labels = [text.get_text() for text in ax.get_legend().get_texts()]
        assert labels[:2] == ["came back", "did not come back"]
        assert labels[2].startswith("undetermined")
        image = ax.get_images()[0]
        cells = image.to_rgba(image.get_array())
        assert matplotlib.colors.same_color(cells[0, 1], CAME_BACK_COLOURS["undetermined"])
        assert matplotlib.colors.same_color(cells[1, 0], CAME_BACK_COLOURS["yes"])
        assert matplotlib.colors.same_color(cells[0, 0], CAME_BACK_COLOURS["no"])
    finally:
        plt.close(fig)


@pytest.mark.parametrize("method", ["radau5", "dop853"])
def test_rtol_1_is_flagged_whatever_the_method(method):
    """--rtol 1: radau5 ended with 8 contacts instead of 9, status 0 and no warning,
    while dop853 got the energy-balance warning.  Both now say the tolerance is too
    loose to trust, and both fail the same (capped) energy-balance check."""
    result = ballc.simulate(ballc.Scene(), 5.0, method=method, rtol=1.0)
    assert "rtol = 1 is looser than 0.001" in result.message
    assert "do not trust this result" in result.message
    assert "energy balance" in result.message


def test_tolerances_ballc_is_tested_at_get_no_warning(short):
    assert outcome.tolerance_warning(1e-3, 1e-3) == ""
    assert outcome.tolerance_warning(1e-10, np.full(19, 1e-10)) == ""
    assert "atol = 0.01" in outcome.tolerance_warning(1e-6, 1e-2)
    assert "Warning" not in short.message


def test_the_drift_is_written_as_a_percentage_or_a_multiple(short):
    """"drifted by 829 J (2.1 of the initial energy)" read as 2.1 % or 2.1 J."""
    initial = float(short.energy["balance"][0])
    for planted, expected in ((2.1, "2.1× the initial energy"),
                              (0.05, "5 % of the initial energy")):
        drifted = copy.deepcopy(short)
        drifted.y[ballc.STATE_NAMES.index("dissipated_normal"), -1] += planted * initial
        drifted._energy = None
        assert expected in outcome.balance_warning(drifted, 1e-6)
    # the allowance is capped at 1 % of the energy, whatever rtol
    drifted = copy.deepcopy(short)
    drifted.y[ballc.STATE_NAMES.index("dissipated_normal"), -1] += 0.02 * initial
    drifted._energy = None
    assert "2 % of the initial energy" in outcome.balance_warning(drifted, 1.0)


@pytest.mark.parametrize("scene", [ballc.Scene(),                       # comes back
                                   ballc.Scene(tangential_model="friction"),
                                   ballc.Scene(mixture=0.3, friction_coefficient=0.2)])
def test_summary_from_the_run_is_the_summary_from_its_contacts(scene, tmp_path):
    """A run's summary (sweep rows) reads the C loop's contact records; a Result read
    from a file has only its Contact objects: the two must give the same row, including
    the first reversal and the verdict (and the Contact of the first reversal is the one
    at that time)."""
    run = ballc.simulate(scene, 1.2, rtol=1e-6, atol=1e-6)
    path = tmp_path / "run.npz"
    run.save(path)
    loaded = ballc.load(path)
    assert "_contact_records" not in loaded.__dict__
    names = ("t_start", "t_end", "vx_before", "vx_after")
    for name, a, b in zip(names, outcome.contact_columns(run, *names),
                          outcome.contact_columns(loaded, *names)):
        np.testing.assert_array_equal(a, b, err_msg=name)
    from_run, from_file = outcome.summary(run), outcome.summary(loaded)
    assert from_run.keys() == from_file.keys()
    for key, value in from_run.items():
        other = from_file[key]
        if isinstance(value, float) and np.isnan(value):
            assert np.isnan(other), key
        else:
            assert value == other, key
    reversal = outcome.first_reversal(run)
    if reversal is None:
        assert np.isnan(from_run["first_reversal_time"])
    else:
        assert reversal.t_start == from_run["first_reversal_time"]
        assert reversal.velocity_before[0] * reversal.velocity_after[0] < 0
        earlier = [c for c in run.contacts if c.t_start < reversal.t_start]
        assert all(c.velocity_before[0] * c.velocity_after[0] >= 0 for c in earlier)
