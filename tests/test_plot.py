"""Plot API: each call returns matplotlib objects with labelled axes; the animation is a
GIF with the requested number of frames; `import ballc` does not import matplotlib."""
import subprocess
import sys

import numpy as np
import pytest

import ballc

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


@pytest.fixture(scope="module")
def result():
    return ballc.simulate(ballc.Scene(), 0.7)


def test_import_ballc_stays_light():
    code = ("import sys, ballc; heavy = [m for m in ('matplotlib', 'pandas', 'tqdm', 'xarray',"
            " 'distributed') if m in sys.modules]; print(heavy)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "[]", done.stdout + done.stderr


def test_figures_have_labelled_axes(result):
    import matplotlib.pyplot as plt
    for make in (result.plot, result.plot_energy, result.plot_contacts, result.plot_observer):
        fig, axes = make()
        assert isinstance(fig, matplotlib.figure.Figure)
        for ax in np.atleast_1d(axes):
            assert ax.get_ylabel()
        assert np.atleast_1d(axes)[-1].get_xlabel()
        plt.close(fig)


def test_energy_plot_draws_dissipated_terms_when_present(result):
    import matplotlib.pyplot as plt
    energy = dict(result.energy)
    energy["dissipated_normal"] = np.linspace(0, 1, result.t.size)
    result._energy, saved = energy, result._energy
    try:
        fig, ax = result.plot_energy()
        labels = [line.get_label() for line in ax.get_lines()]
    finally:
        result._energy = saved
    assert labels[:3] == ["kinetic", "potential", "spring"]
    assert "dissipated normal" in labels and labels[-1] == "total"
    plt.close(fig)


def test_animation_is_a_gif_with_the_requested_frames(result, tmp_path):
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation
    from PIL import Image
    animation = result.animate(tmp_path / "a.gif", frames=7)
    assert isinstance(animation, FuncAnimation) and len(animation.frame_times) == 7
    plt.close(animation._fig)
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames == 7


def test_animation_rejects_unknown_formats(result, tmp_path):
    with pytest.raises(ValueError, match="gif or .mp4"):
        result.animate(tmp_path / "a.avi", frames=2)


def test_coordinate_components_have_distinct_line_styles(result):
    """The seed throw's omega_x and omega_y are equal: one of them must not hide the other."""
    import matplotlib.pyplot as plt
    fig, axes = result.plot()
    try:
        for ax in axes:
            styles = [line.get_linestyle() for line in ax.get_lines()[:3]]
            assert len(set(styles)) == 3, styles
            legend = ax.get_legend()
            assert [h.get_linestyle() for h in legend.legend_handles] == styles
    finally:
        plt.close(fig)


def test_top_view_legend_explains_the_arrows(result):
    import matplotlib.pyplot as plt
    fig, ax = result.plot_contacts()
    try:
        labels = [text.get_text() for text in ax.get_legend().get_texts()]
        assert any("next contact" in label for label in labels), labels
    finally:
        plt.close(fig)


def test_animation_legend_explains_arrows_and_dashed_lines(result, tmp_path):
    import matplotlib.pyplot as plt
    animation = result.animate(tmp_path / "a.gif", frames=2)
    try:
        (legend,) = animation._fig.legends
        handles = {text.get_text(): handle for text, handle in
                   zip(legend.get_texts(), legend.legend_handles)}
        arrow = [h for label, h in handles.items() if "next contact" in label]
        dashed = [h for label, h in handles.items() if "in order" in label]
        assert len(arrow) == 1 and matplotlib.colors.same_color(arrow[0].get_color(), "red")
        assert len(dashed) == 1 and dashed[0].get_linestyle() == "--"
        assert matplotlib.colors.same_color(dashed[0].get_color(), "green")
        assert any("observer" in label for label in handles)
    finally:
        plt.close(animation._fig)


def test_animation_rejects_no_frames(result):
    for frames in (0, -5, 2.5, True):
        with pytest.raises(ValueError, match="frames = "):
            result.animate(frames=frames)


def test_sweep_map_of_came_back_has_a_two_colour_legend():
    import matplotlib.pyplot as plt
    import pandas as pd
    from ballc.plot import CAME_BACK_COLOURS, plot_sweep_map
    table = pd.DataFrame({"mixture": [0.0, 0.0, 0.5, 0.5], "friction_coefficient": [0.1, 0.2] * 2,
                          "came_back": [False, False, True, False],
                          "energy_lost_fraction": [0.4, 0.4, 0.1, 0.4], "status": [0] * 4})
    fig, ax = plot_sweep_map(table, x="friction_coefficient", y="mixture")
    try:
        assert fig.axes == [ax]                                    # no colour bar
        legend = ax.get_legend()
        labels = [text.get_text() for text in legend.get_texts()]
        assert labels == ["came back", "did not come back"]
        colours = [patch.get_facecolor() for patch in legend.get_patches()]
        assert matplotlib.colors.same_color(colours, [CAME_BACK_COLOURS["yes"],
                                                      CAME_BACK_COLOURS["no"]])
        image = ax.get_images()[0]
        cells = image.to_rgba(image.get_array())
        assert matplotlib.colors.same_color(cells[1, 0], CAME_BACK_COLOURS["yes"])
        assert matplotlib.colors.same_color(cells[0, 0], CAME_BACK_COLOURS["no"])
    finally:
        plt.close(fig)
