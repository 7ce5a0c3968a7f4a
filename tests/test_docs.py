"""The documentation site: its sources are complete (fast, default run) and it builds
warning-free with its gallery (marker ``docs``: python -m pytest -m docs)."""
import ast
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

import ballc

REPOSITORY = Path(__file__).resolve().parents[1]
DOCS = REPOSITORY / "docs"
EXAMPLES = REPOSITORY / "examples"
needs_sources = pytest.mark.skipif(not (DOCS / "conf.py").is_file(),
                                   reason="needs the source tree")
GALLERY = ["seed_reproduction", "superball", "compare_tangential_models",
           "restitution_calibration", "sweep_mixture_mu", "plates_orientation", "fit_superball",
           "choose_integrator"]


@needs_sources
def test_every_public_name_has_an_api_entry():
    text = (DOCS / "api.rst").read_text(encoding="utf-8")
    missing = [name for name in ballc.__all__
               if not any(f":: {name}" in line for line in text.splitlines())]
    assert not missing, f"not in docs/api.rst: {missing}"


@needs_sources
def test_every_doc_page_is_in_the_toctree():
    index = (DOCS / "index.rst").read_text(encoding="utf-8")
    for page in DOCS.glob("*.md"):
        assert f"   {page.stem}\n" in index, page.name


@needs_sources
@pytest.mark.parametrize("name", GALLERY)
def test_examples_are_gallery_scripts(name):
    source = (EXAMPLES / f"{name}.py").read_text(encoding="utf-8")
    docstring = ast.get_docstring(ast.parse(source))
    title, underline = docstring.strip().splitlines()[:2]
    assert underline == "=" * len(title), f"{name}: no reST title in the module docstring"
    assert source.count("\n# %%\n") >= 2, f"{name}: not split into # %% cells"
    assert f"ballc-output/{name}" in source          # still writes to its ignored folder


@needs_sources
def test_gallery_order_names_every_example():
    sys.path.insert(0, str(DOCS))
    try:
        spec = importlib.util.spec_from_file_location("gallery_order",
                                                      DOCS / "gallery_helpers.py")
        if importlib.util.find_spec("sphinx_gallery") is None:
            pytest.skip("sphinx-gallery is not installed")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(DOCS))
    assert sorted(module.ORDER) == sorted(p.name for p in EXAMPLES.glob("*.py"))


@needs_sources
def test_superball_example_takes_an_output_folder(tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(EXAMPLES / "superball.py"), "--out", "x"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "came back: True" in done.stdout and "came back: False" in done.stdout
    assert sorted(p.name for p in (tmp_path / "x").iterdir()) == [
        "contacts_compliant.csv", "contacts_friction.csv", "superball.png",
        "superball_spin.png"]


@pytest.mark.docs
@pytest.mark.timeout(1200)
@needs_sources
def test_docs_build_warning_free(tmp_path):
    for module in ("sphinx", "sphinx_gallery", "numpydoc", "myst_parser"):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"{module} is not installed (pip install '.[docs]')")
    html = tmp_path / "html"
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-b", "html",
                           "-d", str(tmp_path / "doctrees"), "docs", str(html)],
                          cwd=REPOSITORY, capture_output=True, text=True, timeout=1100,
                          env={**os.environ, "BALLC_DOCS_RUN_ALL": "1"})   # run every example
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    for page in ["index", "api", "user_guide", "gallery/index"] + [
            f"gallery/{name}" for name in GALLERY]:
        assert (html / f"{page}.html").is_file(), page
    gallery = (html / "gallery" / "seed_reproduction.html").read_text(encoding="utf-8")
    assert gallery.count("sphx_glr_seed_reproduction_00") >= 5    # 4 figures + the GIF
    assert (html / "_images" / "sphx_glr_seed_reproduction_005.gif").is_file()
    api = (html / "api.html").read_text(encoding="utf-8")
    for name in ballc.__all__:
        assert f'id="ballc.{name}"' in api, name
