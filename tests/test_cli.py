"""The console commands end to end, in a subprocess, on short scenes."""
import os
import subprocess
import sys

import pytest

import ballc

ENV = {**os.environ, "MPLBACKEND": "Agg"}


def run_ballc(*args, cwd):
    return subprocess.run([sys.executable, "-m", "ballc", *args], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=120)


def test_demo_writes_every_output(tmp_path):
    done = run_ballc("demo", "--t-end", "0.7", "--frames", "12", "--out", "demo", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = tmp_path / "demo"
    for name in ("coordinates.png", "energy.png", "contacts_top_view.png", "observer.png",
                 "contacts.csv", "animation.gif"):
        assert (out / name).stat().st_size > 0, name
    assert "contacts in 0.7 s" in done.stdout
    assert "CAME BACK" in done.stdout or "did NOT come back" in done.stdout
    lines = (out / "contacts.csv").read_text().splitlines()
    assert lines[0].startswith("contact,plane,t_start") and len(lines) == 1 + 2   # 2 contacts

    from PIL import Image
    with Image.open(out / "animation.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames == 12


def test_run_reads_a_scene_file_and_saves_the_result(tmp_path):
    ballc.Scene(mixture=0.0).to_toml(tmp_path / "scene.toml")
    done = run_ballc("run", "scene.toml", "--t-end", "0.3", "--out", "out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    result = ballc.load(tmp_path / "out" / "result.npz")
    assert result.scene == ballc.Scene(mixture=0.0)
    assert result.t[-1] == pytest.approx(0.3)


def test_run_names_a_misspelt_field(tmp_path):
    (tmp_path / "bad.toml").write_text("mixtur = 0.5\n")
    done = run_ballc("run", "bad.toml", cwd=tmp_path)
    assert done.returncode == 2
    assert "did you mean 'mixture'" in done.stderr and "bad.toml" in done.stderr
