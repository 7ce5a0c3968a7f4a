"""sphinx-gallery hooks for the ballc docs (named by string in conf.py, so that Sphinx
can cache its configuration).

``example_argv`` gives each example its command line: ``--out`` into
docs/_build/gallery-output/<example>/ (emptied first), never into the source tree.
``gif_scraper`` puts the GIFs an example writes there (the 3-D animation) on its page,
after the code block that wrote them.
"""
import shutil
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst

OUTPUT = Path(__file__).resolve().parent / "_build" / "gallery-output"
_shown = set()


def example_output(src_file) -> Path:
    return OUTPUT / Path(src_file).stem


def example_argv(gallery_conf, script_vars):
    out = example_output(script_vars["src_file"])
    shutil.rmtree(out, ignore_errors=True)
    argv = ["--out", str(out)]
    if out.name == "seed_reproduction":
        argv += ["--frames", "60"]     # the GIF on the page: ~0.5 MB
    return argv


def gif_scraper(block, block_vars, gallery_conf):
    out = example_output(block_vars["src_file"])
    new = sorted((p for p in out.glob("*.gif") if p not in _shown),
                 key=lambda p: p.stat().st_mtime)
    images = []
    for gif, image_path in zip(new, block_vars["image_path_iterator"]):
        target = Path(image_path).with_suffix(".gif")
        shutil.copyfile(gif, target)
        _shown.add(gif)
        images.append(str(target))
    return figure_rst(images, gallery_conf["src_dir"])


#: The order of the gallery: the seed first, then the questions it raises.
ORDER = ["seed_reproduction.py", "superball.py", "superball_passive.py", "superball_rolling.py",
         "compare_tangential_models.py",
         "restitution_calibration.py", "sweep_mixture_mu.py", "plates_orientation.py",
         "fit_superball.py",
         "fit_kharaz.py",
         "choose_integrator.py"]


class ExampleOrder:
    """``within_subsection_order``: the examples in ORDER, any other one after them."""

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename):
        name = Path(filename).name
        return (ORDER.index(name) if name in ORDER else len(ORDER), name)

    def __repr__(self):
        return "gallery_helpers.ExampleOrder"
