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
