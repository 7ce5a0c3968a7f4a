"""ballc.html_view: the interactive 3-D view is one self-contained HTML file."""
import re

import pytest

import ballc

pytest.importorskip("meshcat", reason="needs the html extra (meshcat)")
from ballc.html_view import write_html  # noqa: E402


@pytest.fixture(scope="module")
def result():
    return ballc.simulate(ballc.Scene(), 1.2)


def assert_self_contained(text):
    """A page that plays offline: no script, stylesheet, image or fetch from another
    file or address (plain bool asserts: a failing diff of a 1-MB page takes minutes)."""
    assert text.startswith("<!DOCTYPE html>")
    assert "new MeshCat.Viewer" in text and "handle_command_bytearray" in text
    assert re.search(r"""<script[^>]*\bsrc\s*=""", text, re.I) is None
    assert re.search(r"""<link[^>]*\bhref\s*=""", text, re.I) is None
    assert re.search(r"""fetch\(\s*["'](?!data:)""", text) is None
    assert re.search(r"""(src|href)\s*=\s*["']https?://""", text, re.I) is None


def test_writes_a_self_contained_page(result, tmp_path):
    path = write_html(result, tmp_path / "run.html", fps=10)
    text = path.read_text(encoding="utf-8")
    assert_self_contained(text)
    # every contact has its marker and the ball its animation (set_animation command)
    assert text.count("fetch(\"data:application/octet-binary;base64,") > len(result.contacts)
    assert f"{len(result.contacts)} contacts" in text


def test_keyframes_follow_fps_and_speed(result):
    from ballc.html_view import scene_html
    slow, fast = scene_html(result, fps=10, speed=0.5), scene_html(result, fps=10, speed=2.0)
    assert len(slow) > len(fast)      # more keyframes for a slower playback


@pytest.mark.parametrize("options, message", [
    (dict(fps=0), "fps = 0"), (dict(fps=2.5), "fps = 2.5"), (dict(speed=0.0), "speed = 0.0"),
    (dict(speed=float("nan")), "speed = nan")])
def test_bad_options_are_named(result, tmp_path, options, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        write_html(result, tmp_path / "x.html", **options)
    assert not (tmp_path / "x.html").exists()


def test_refuses_other_suffixes(result, tmp_path):
    with pytest.raises(ValueError, match=r"\.html"):
        write_html(result, tmp_path / "x.png")


def test_cli_run_writes_the_view(tmp_path):
    """`ballc run --html` writes view.html beside the figures (one subprocess, 0.3 s)."""
    import os
    import subprocess
    import sys
    pytest.importorskip("meshcat")
    ballc.Scene().to_toml(tmp_path / "scene.toml")
    done = subprocess.run([sys.executable, "-m", "ballc", "run", "scene.toml", "--t-end", "0.3",
                           "--out", "out", "--html"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    assert_self_contained((tmp_path / "out" / "view.html").read_text(encoding="utf-8"))
