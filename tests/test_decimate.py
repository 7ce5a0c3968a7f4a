"""Decimation for drawing (issue 21): figures of a run with many samples draw at most
plot.MAX_POINTS points per line, by a min/max envelope per time bucket that keeps every
line's extremes and its first and last points; the Result's arrays are not touched."""
import dataclasses

import numpy as np
import pytest

import ballc
from ballc import _core, plot
from ballc.observer import state_derivatives

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def _spiky(n, rng):
    """Non-uniform times with a dense burst, a random walk with narrow spikes."""
    dt = np.where(rng.random(n - 1) < 0.01, 1e-6, rng.random(n - 1))
    t = np.r_[0.0, np.cumsum(dt)]
    values = np.cumsum(rng.standard_normal(n))
    values[rng.integers(0, n, 5)] += 1e3          # one-sample peaks
    values[rng.integers(0, n, 5)] -= 1e3
    return t, values


@pytest.mark.parametrize("max_points", [4, 100, 20000])
def test_decimated_line_keeps_extremes_ends_and_the_budget(max_points):
    rng = np.random.default_rng(1)
    t, values = _spiky(200_000, rng)
    t_kept, kept = plot._for_drawing(t, values, max_points=max_points)
    assert t_kept.size <= max_points and kept.size == t_kept.size
    assert kept.min() == values.min() and kept.max() == values.max()
    assert (t_kept[0], kept[0]) == (t[0], values[0])
    assert (t_kept[-1], kept[-1]) == (t[-1], values[-1])
    assert np.all(np.diff(t_kept) >= 0)
    index = np.searchsorted(t, t_kept)            # kept points are samples, unchanged
    assert np.array_equal(values[index], kept)


def test_several_series_share_the_kept_times_and_keep_each_extreme():
    rng = np.random.default_rng(2)
    t, a = _spiky(50_000, rng)
    b = np.sin(t) + (t == t[12345]) * 50.0
    t_kept, a_kept, b_kept = plot._for_drawing(t, a, b, max_points=1000)
    assert t_kept.size <= 1000
    for full, kept in ((a, a_kept), (b, b_kept)):
        assert kept.min() == full.min() and kept.max() == full.max()


def test_short_series_and_constant_time_are_handled():
    t = np.linspace(0, 1, 50)
    values = t ** 2
    t_kept, kept = plot._for_drawing(t, values, max_points=100)
    assert t_kept is t and kept is values                    # nothing to decimate
    flat = np.zeros(1000)
    values = np.arange(1000.0) % 7
    t_kept, kept = plot._for_drawing(flat, values, max_points=50)
    assert t_kept.size <= 50 and kept.max() == 6 and kept.min() == 0
    with pytest.raises(ValueError, match="too few"):
        plot._for_drawing(np.arange(10.0), np.arange(10.0), np.arange(10.0), max_points=5)


def test_nan_in_a_series_does_not_hide_the_rest():
    t = np.arange(10_000.0)
    values = np.sin(t / 100)
    values[::3] = np.nan
    values[5000] = 9.0
    _, kept = plot._for_drawing(t, values, max_points=200)
    assert np.nanmax(kept) == 9.0 and np.nanmin(kept) == np.nanmin(values)


@pytest.fixture(scope="module")
def long_run():
    """A Result-like run of 100,000 samples: the seed's first 0.7 s (two contacts),
    resampled densely (states by linear interpolation, flags and latch of the sample
    before), so that the figures must decimate."""
    short = ballc.simulate(ballc.Scene(), 0.7)
    t = np.unique(np.r_[np.linspace(0.0, short.t[-1], 100_000 - short.t.size), short.t])
    y = np.array([np.interp(t, short.t, row) for row in short.y])
    source = np.clip(np.searchsorted(short.t, t, side="right") - 1, 0, short.t.size - 1)
    return dataclasses.replace(short, t=t, y=y, flags=short.flags[source],
                               latch=short.latch[:, source], _energy=None, sol=None)


def _lines(axes):
    return [line for ax in np.atleast_1d(axes) for line in ax.get_lines()
            if len(line.get_xdata()) > 2]


def test_figures_of_a_long_run_draw_at_most_max_points(long_run, monkeypatch):
    import matplotlib.pyplot as plt
    monkeypatch.setattr(plot, "OBSERVER_SAMPLES", 30_000)   # the chosen-samples path
    t, y = long_run.t.copy(), long_run.y.copy()
    for make in (long_run.plot, long_run.plot_energy, long_run.plot_observer,
                 long_run.plot_contacts):
        fig, axes = make()
        lines = _lines(axes)
        assert lines, make.__name__
        for line in lines:
            assert len(line.get_xdata()) <= plot.MAX_POINTS, (make.__name__, line)
        plt.close(fig)
    assert np.array_equal(long_run.t, t) and np.array_equal(long_run.y, y)  # data whole
    assert long_run.t.size > 4 * plot.MAX_POINTS


def test_coordinate_lines_keep_each_components_extremes(long_run):
    import matplotlib.pyplot as plt
    fig, axes = long_run.plot()
    drawn = {id(line): line for line in axes[1].get_lines()}
    velocity_lines = [line for line in drawn.values() if line.get_label().startswith("$v")]
    for row, line in zip(long_run.velocity, velocity_lines):
        assert np.max(line.get_ydata()) == row.max()
        assert np.min(line.get_ydata()) == row.min()
    plt.close(fig)


def test_observer_evaluates_every_sample_of_the_impacts(long_run):
    index = plot._observer_indices(long_run, budget=20_000, contact_samples=10_000)
    assert index.size < long_run.t.size
    assert index[0] == 0 and index[-1] == long_run.t.size - 1
    for contact in long_run.contacts:
        if np.isfinite(contact.t_end):
            inside = np.flatnonzero((long_run.t >= contact.t_start)
                                    & (long_run.t <= contact.t_end))
            assert np.isin(inside, index).all()
    # up to the budget, every sample
    assert plot._observer_indices(long_run, budget=10**6).size == long_run.t.size


def test_rhs_per_sample_is_rhs_at_each_sample():
    result = ballc.simulate(ballc.Scene(), 0.4)
    batched = state_derivatives(result)
    params = result.scene.parameter_vector()
    for i in range(0, result.t.size, max(result.t.size // 200, 1)):
        one = _core.rhs(np.ascontiguousarray(result.y[:, i]), params,
                        np.ascontiguousarray(result.latch[:, i]), int(result.flags[i]))
        assert np.array_equal(batched[:, i], one)
