"""Every figure's title names the normal damping the scene was given -- c_tau, the
restitution e or the damping ratio gamma -- with its law; a scene given restitution or
damping_ratio (c_tau None) plots, animates and runs through ``ballc run`` (issue 28, 1)."""
import re

import pytest

import ballc

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

COMPLIANT = dict(tangential_model="compliant")
#: (scene fields, what the title must say, what it must not)
CASES = [
    (dict(), [r"$c_\tau$ = 0.9", "Hunt-Crossley"], ["None", "viscoelastic"]),
    (dict(c_tau=0.8), [r"$c_\tau$ = 0.8", "Hunt-Crossley"], ["None", "e ="]),
    (dict(restitution=0.5), ["e = 0.5", "Hunt-Crossley"], ["None", "c_\\tau"]),
    (dict(**COMPLIANT, restitution=0.25), ["e = 0.25", "Hunt-Crossley"], ["None", "c_\\tau"]),
    (dict(**COMPLIANT, normal_damping="viscoelastic", restitution=0.5),
     ["e = 0.5", "viscoelastic"], ["None", "c_\\tau", "gamma"]),
    (dict(**COMPLIANT, normal_damping="viscoelastic", damping_ratio=0.2),
     [r"$\gamma$ = 0.2", "viscoelastic"], ["None", "c_\\tau", "e ="]),
]


@pytest.mark.parametrize("fields, says, never", CASES)
def test_title_names_the_damping_input_given(fields, says, never):
    from ballc.plot import scene_title
    title = scene_title(ballc.Scene(**fields))
    for text in says:
        assert text in title, (text, title)
    for text in never:
        assert text not in title, (text, title)
    assert r"$\mu$ = 0.1" in title


@pytest.mark.parametrize("fields", [CASES[2][0], CASES[4][0], CASES[5][0]],
                         ids=["restitution", "viscoelastic e", "damping_ratio"])
def test_every_figure_of_such_a_scene_is_drawn(fields, tmp_path):
    import matplotlib.pyplot as plt
    import numpy as np

    from ballc.plot import scene_title
    result = ballc.simulate(ballc.Scene(**fields, velocity=(-1.0, 1.0, -5.0),
                                        position=(0.0, 0.0, 2.0)), 0.5)
    assert result.status == 0 and result.contacts
    title = scene_title(result.scene)
    for make in (result.plot, result.plot_energy, result.plot_contacts, result.plot_observer):
        fig, axes = make()
        assert title in np.atleast_1d(axes)[0].get_title()
        plt.close(fig)
    animation = result.animate(tmp_path / "a.gif", frames=3)
    assert title in animation._fig.axes[0].get_title()
    assert (tmp_path / "a.gif").stat().st_size > 0
    plt.close(animation._fig)


def test_ballc_run_of_a_restitution_scene_writes_its_figures(tmp_path, capsys):
    """`ballc run` on a scene given restitution: exit 0 and every figure and file
    written (it printed a traceback, rc 1, and left an empty folder).  In-process."""
    from ballc.cli import main
    ballc.Scene(restitution=0.5, velocity=(-1.0, 1.0, -5.0),
                position=(0.0, 0.0, 2.0)).to_toml(tmp_path / "e.toml")
    code = main(["run", str(tmp_path / "e.toml"), "--t-end", "0.4", "--out",
                 str(tmp_path / "out")])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == ["contacts.csv", "contacts_top_view.png", "coordinates.png",
                       "energy.png", "observer.png", "result.npz"]
    assert re.search(r"\d+ contacts in 0\.4 s", printed.out)
