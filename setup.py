"""Build the compiled core: generated/ kernels + src/ballc glue, bridged by Cython."""
from Cython.Build import cythonize
from setuptools import Extension, setup

core = Extension(
    "ballc._core",
    sources=["src/ballc/_core.pyx", "src/ballc/_system.c", "generated/ballc_kernels.c"],
    include_dirs=["generated", "src/ballc"],
    extra_compile_args=["-O2", "-std=c99"],
)

# The compiled Radau IIA integrator; it calls ballc_rhs / ballc_jacobian directly, so it
# links its own copy of the system and kernels.  Its linear algebra is _lu.c (no LAPACK).
radau5 = Extension(
    "ballc._radau5",
    sources=["src/ballc/_radau5.pyx", "src/ballc/_radau5_solver.c", "src/ballc/_lu.c",
             "src/ballc/_system.c", "generated/ballc_kernels.c"],
    include_dirs=["generated", "src/ballc"],
    extra_compile_args=["-O2", "-std=c99"],
)

setup(ext_modules=cythonize([core, radau5], compiler_directives={"language_level": 3}))
