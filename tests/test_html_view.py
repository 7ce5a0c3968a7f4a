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


def commands(text):
    """The meshcat commands embedded in a page, unpacked: {path: command} per type."""
    import base64

    import numpy as np
    import umsgpack
    found = {}
    for blob in re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)', text):
        command = umsgpack.unpackb(base64.b64decode(blob))
        key = command.get("path") or command["animations"][0]["path"]
        found.setdefault(command["type"], {})[key] = command
    # a transform as its translation (three.js matrices are column-major: 12, 13, 14)
    found["translation"] = {path: np.asarray(c["matrix"])[12:15]
                            for path, c in found.get("set_transform", {}).items()}
    return found


def test_the_page_holds_the_scene_and_the_runs_motion(result):
    """The planes' faces at z = 0 and z = H, a marker at each contact point, and keyframes
    at fps per second of playback whose centres are the run's (interpolated here)."""
    import numpy as np
    from ballc.html_view import scene_html
    h = result.scene.ceiling_height
    for fps, speed in ((10, 0.5), (7, 2.0)):
        page = commands(scene_html(result, fps=fps, speed=speed))
        base = "/meshcat/ballc"
        for plane, face in (("floor", 0.0), ("ceiling", h)):
            box = page["set_object"][f"{base}/planes/{plane}"]["object"]["geometries"][0]
            z = page["translation"][f"{base}/planes/{plane}"][2]
            inner = z + box["depth"] / 2 if plane == "floor" else z - box["depth"] / 2
            assert inner == pytest.approx(face, abs=1e-12), plane
        for i, contact in enumerate(result.contacts, 1):
            expected = [*contact.contact_point, 0.0 if contact.plane == "floor" else h]
            assert page["translation"][f"{base}/contacts/{i}"] == pytest.approx(expected)
        assert f"{base}/contacts/{len(result.contacts) + 1}" not in page["translation"]
        clip = page["set_animation"][f"{base}/ball"]["animations"][0]["clip"]
        assert clip["fps"] == fps
        tracks = {track["name"]: track["keys"] for track in clip["tracks"]}
        t0, t1 = result.t[0], result.t[-1]
        count = int(np.ceil((t1 - t0) / speed * fps)) + 1
        assert [key["time"] for key in tracks[".position"]] == list(range(count))
        times = np.linspace(t0, t1, count)
        for key, t in zip(tracks[".position"], times):
            centre = [np.interp(t, result.t, row) for row in result.position]
            assert key["value"] == pytest.approx(centre, abs=1e-12)
        quaternions = np.array([key["value"] for key in tracks[".quaternion"]])
        assert np.allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-12)
        qw, qx, qy, qz = result.quaternion[:, -1]     # meshcat's order: x, y, z, w
        assert quaternions[-1] == pytest.approx([qx, qy, qz, qw], abs=1e-12)


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
