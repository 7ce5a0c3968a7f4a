"""Figures of long runs (issue 28, item 6): a run that ends in closed form (rest, uniform
rolling or sliding, a rolling orbit) is drawn up to the start of that closed form plus
a margin, with the start marked and the closed form to t_end named; ``t_window=(t0, t1)``
(``--t-window T0 T1``) draws any window.  Before: a 1e9-s run of the seed throw was one
linear axis to 1e9 s shaded as one contact, and its top view a 3-km circle of the orbit
with the 35 contacts crushed into a blob at its edge."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import ballc  # noqa: E402
from ballc import plot  # noqa: E402

T_END = 1e9


@pytest.fixture(scope="module")
def long_run():
    """The seed throw for 1e9 s: it rolls on in a relative periodic orbit (closed form)
    from about 62.6 s."""
    return ballc.simulate(ballc.Scene(), T_END)


def _closed_form_start(result):
    """Oracle, from the contacts alone: the last contact's rest/rolling/sliding time."""
    last = result.contacts[-1]
    times = [t for t in (last.t_rest, last.t_rolling, last.t_sliding) if np.isfinite(t)]
    return min(times)


def _drawn_times(ax):
    return np.concatenate([line.get_xdata() for line in ax.get_lines()
                           if len(line.get_xdata()) > 2])


def _has_closed_form_note(fig):
    return any("closed form" in text.get_text() for ax in fig.axes for text in ax.texts)


@pytest.mark.parametrize("figure", ["plot", "plot_energy", "plot_observer"])
def test_a_long_run_is_drawn_to_its_closed_form_plus_a_margin(long_run, figure):
    t_c = _closed_form_start(long_run)
    assert 10.0 < t_c < 1e3 and long_run.t[-1] == T_END
    fig, axes = getattr(long_run, figure)()
    try:
        for ax in np.atleast_1d(axes):
            low, high = ax.get_xlim()
            # the eventful part and a margin, not 1e9 s
            assert low <= 0.0 and t_c < high <= (1 + plot.CLOSED_FORM_MARGIN) * t_c * 1.001
            drawn = _drawn_times(ax)
            # lines end at the last sample in the window: no chord over the closed form
            # to its next sparse sample (2.4e5 s here)
            assert drawn.max() <= high and drawn.min() <= 1.0
            # the start of the closed form is marked
            assert any(np.allclose(line.get_xdata(), t_c) for line in ax.get_lines()
                       if len(line.get_xdata()) == 2)
        assert _has_closed_form_note(fig)
        assert f"{T_END:g}" in " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    finally:
        plt.close(fig)


def test_the_top_view_of_a_long_run_draws_its_eventful_path(long_run):
    """The centre path drawn is that up to the margin after the closed form starts, so
    the 35 contacts are not crushed by the 3-km circle the orbit traces in 1e9 s."""
    t_c = _closed_form_start(long_run)
    end = (1 + plot.CLOSED_FORM_MARGIN) * t_c
    fig, ax = long_run.plot_contacts()
    try:
        path = ax.get_lines()[0]
        inside = long_run.t <= end
        expected = long_run.position[:2, inside]
        span = np.ptp(expected, axis=1)
        drawn_span = np.ptp(np.vstack([path.get_xdata(), path.get_ydata()]), axis=1)
        assert np.all(drawn_span <= span * 1.05 + 1e-9), (drawn_span, span)
        assert np.all(np.ptp(long_run.position[:2], axis=1) > 10 * span)  # the whole: a blob
        assert _has_closed_form_note(fig)
        # every contact is drawn (all start before the closed form)
        points = sum(len(c.get_offsets()) for c in ax.collections)
        assert points == len(long_run.contacts) == 35
        # numbers: the first and the last, and none written over another (the last
        # hops before rolling are close together)
        numbers = {a.get_text(): np.array(a.xy) for a in ax.texts if a.get_text().isdigit()}
        assert {"1", "35"} <= set(numbers)
        where = np.array(list(numbers.values()))
        span = max(np.ptp(np.vstack([where, np.c_[path.get_xdata(), path.get_ydata()]]),
                          axis=0))
        gaps = np.hypot(*(where[:, None, :] - where[None, :, :]).transpose(2, 0, 1))
        assert gaps[np.triu_indices(len(where), 1)].min() >= plot.LABEL_SPACING * span
    finally:
        plt.close(fig)


def test_an_explicit_time_window(long_run):
    window = (10.0, 20.0)
    for figure in ("plot", "plot_energy", "plot_observer", "plot_contacts"):
        fig, axes = getattr(long_run, figure)(t_window=window)
        try:
            if figure == "plot_contacts":
                ax = axes
                starts = [c.t_start for c in long_run.contacts]
                shown = [t for t in starts if window[0] <= t <= window[1]]
                points = sum(len(c.get_offsets()) for c in ax.collections)
                assert points == len(shown) > 0
                inside = (long_run.t >= window[0]) & (long_run.t <= window[1])
                drawn = ax.get_lines()[0].get_xdata()
                assert np.ptp(drawn) <= np.ptp(long_run.position[0, inside]) * 1.05 + 1e-9
                continue
            for ax in np.atleast_1d(axes):
                assert ax.get_xlim() == window
                drawn = _drawn_times(ax)
                # the samples in the window and one on each side of it
                assert drawn.min() >= long_run.t[long_run.t < window[0]][-1]
                assert drawn.max() <= long_run.t[long_run.t > window[1]][0]
        finally:
            plt.close(fig)


def test_a_short_run_is_drawn_whole():
    """A run without a long closed-form tail keeps its whole time axis."""
    result = ballc.simulate(ballc.Scene(), 1.2)
    fig, axes = result.plot()
    try:
        assert axes[0].get_xlim()[1] >= 1.2 and not _has_closed_form_note(fig)
    finally:
        plt.close(fig)


@pytest.mark.parametrize("window", [(5.0, 1.0), (1.0, np.nan), (2e9, 3e9), (1.0,), "all"])
def test_a_bad_time_window_is_rejected_naming_it(long_run, window):
    with pytest.raises(ValueError, match=r"t_window = .* is not allowed"):
        long_run.plot(t_window=window)


def test_the_command_line_passes_its_time_window(tmp_path, monkeypatch):
    """``ballc run --t-window T0 T1`` draws every figure over that window."""
    from ballc import cli
    seen = []
    original = plot.plot_coordinates

    def spy(result, **options):
        seen.append(options.get("t_window"))
        return original(result, **options)
    monkeypatch.setattr(plot, "plot_coordinates", spy)
    scene = tmp_path / "s.toml"
    scene.write_text("[simulate]\nt_end = 0.6\n")
    assert cli.main(["run", str(scene), "--t-window", "0.1", "0.4",
                     "--out", str(tmp_path / "out")]) == 0
    assert seen == [(0.1, 0.4)]


@pytest.mark.parametrize("args, shown", [(["0.4", "0.1"], "--t-window"),
                                         (["7", "8"], "--t-window")])
def test_a_bad_command_line_time_window_is_one_line_before_anything_runs(tmp_path, args,
                                                                        shown, capsys):
    from ballc import cli
    scene = tmp_path / "s.toml"
    scene.write_text("[simulate]\nt_end = 0.6\n")
    code = cli.main(["run", str(scene), "--t-window", *args, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and shown in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_a_window_after_a_run_that_stopped_early_draws_the_whole_run(tmp_path, capsys):
    """--t-window is checked against [0, t_end] before the run; a run that then stops
    early (dig-in passes through the floor at 3.4 s) still gets its figures, of the
    whole run, with a note saying why."""
    from ballc import cli
    scene = tmp_path / "s.toml"
    scene.write_text('tangential_model = "dig-in"\n[simulate]\nt_end = 5.0\n')
    code = cli.main(["run", str(scene), "--t-window", "4.5", "5", "--out",
                     str(tmp_path / "out")])
    assert code == 1                          # the run did not reach t_end
    assert (tmp_path / "out" / "coordinates.png").is_file()
    assert "the figures show the whole run" in capsys.readouterr().err
