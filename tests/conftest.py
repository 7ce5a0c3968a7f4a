"""Shared fixtures: the seed's own sympy formulation, lambdified (the oracle); and
Hypothesis made reproducible."""
import numpy as np
import pytest


def _no_local_constants():
    """Hypothesis (>= 6.131) also draws constants it harvests from the source of every
    local module imported so far -- all of ballc, the tests, the benchmarks -- so even
    with derandomize=True the examples changed with any edit of the source and with
    which tests ran before (a property test's examples differed between running its
    file alone and the whole suite).  ballc's property tests must draw the same
    examples on every run: no harvested constants (Hypothesis' own still apply)."""
    try:
        from hypothesis.internal.conjecture import providers
    except ImportError:   # another Hypothesis: nothing to switch off
        return
    if hasattr(providers, "is_local_module_file"):
        providers.is_local_module_file = lambda path: False


_no_local_constants()


@pytest.fixture(scope="session")
def seed_model():
    from codegen.seed_reference import build_seed_model
    return build_seed_model()


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
