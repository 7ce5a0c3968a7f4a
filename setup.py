"""Build the compiled core: generated/ kernels + src/ballc glue, bridged by Cython."""
from Cython.Build import cythonize
from setuptools import Extension, setup

core = Extension(
    "ballc._core",
    sources=["src/ballc/_core.pyx", "src/ballc/_system.c", "generated/ballc_kernels.c"],
    include_dirs=["generated", "src/ballc"],
    extra_compile_args=["-O2", "-std=c99"],
)

setup(ext_modules=cythonize([core], compiler_directives={"language_level": 3}))
