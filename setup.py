"""Build the compiled core: generated/ kernels + src/ballc glue, bridged by Cython.

One extension module, ``ballc._core``: the generated kernels, ``_system.c``, the
integrator (its loop and both methods' steps) and its LU are compiled and linked once,
so no build or partial rebuild can leave two copies of the model that disagree.  ``ballc._radau5`` is a
plain Python module re-exporting the solver's bridge (``_radau5_bridge.pxi``, included
by ``_core.pyx``).
"""
from pathlib import Path

from Cython.Build import cythonize
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

core = Extension(
    "ballc._core",
    sources=["src/ballc/_core.pyx", "src/ballc/_system.c", "generated/ballc_kernels.c",
             "src/ballc/_integrator.c", "src/ballc/_radau_iia.c", "src/ballc/_dop853.c",
             "src/ballc/_lu.c", "src/ballc/_driver.c", "src/ballc/_dense.c",
             "src/ballc/_orbit.c", "src/ballc/_plane.c", "src/ballc/_rolling.c"],
    include_dirs=["generated", "src/ballc"],
    depends=["src/ballc/_radau5_bridge.pxi", "src/ballc/_driver_bridge.pxi",
             "src/ballc/_orbit_bridge.pxi", "src/ballc/_dense.h", "src/ballc/_orbit.h",
             "src/ballc/_scipy_bridge.pxi",
             "src/ballc/_driver.h", "src/ballc/_system.h", "src/ballc/_plane.h", "src/ballc/_lu.h",
             "src/ballc/_rolling.h",
             "src/ballc/_integrator.h", "src/ballc/_integrator_private.h",
             "src/ballc/_radau_iia.h", "src/ballc/_dop853.h",
             "generated/ballc_kernels.h"],
    # -fno-math-errno: sqrt never sets errno, so it is one instruction and repeated
    # calls in the generated kernels are shared (the results are the same bits).
    # -fcx-limited-range: complex * and / as the textbook formulas (radau5's complex
    # Newton system; its values are finite and far from overflow), not libgcc's
    # __muldc3 / __divdc3 with their inf/NaN recovery.
    # -fno-wrapv: Python's CFLAGS carry -fwrapv (CPython's own code relies on signed
    # overflow wrapping; ballc's does not overflow), under which GCC leaves loops with an
    # int index scalar: without it the integrator's and the right-hand side's loops over
    # the state are vectorized (element-wise only: the same bits), ~8 % of a rolling run.
    extra_compile_args=["-O3", "-std=c99", "-fno-math-errno", "-fcx-limited-range",
                        "-fno-wrapv"],
)


class BuildExt(build_ext):
    """build_ext that removes what older builds left in place: a stale in-place
    ``_radau5`` extension (before the single core) would shadow ``_radau5.py`` and run
    its own, older copy of the kernels (``tests/test_core_bridge.py`` checks for it).
    Done for in-place builds and for editable installs, which copy the extension into
    the source tree."""

    def run(self):
        if self.inplace or getattr(self, "editable_mode", False):
            for stale in Path("src/ballc").glob("_radau5.*.so"):
                stale.unlink()
            for stale in Path("src/ballc").glob("_radau5.*.pyd"):
                stale.unlink()
        super().run()


setup(ext_modules=cythonize([core], compiler_directives={"language_level": 3}),
      cmdclass={"build_ext": BuildExt})
