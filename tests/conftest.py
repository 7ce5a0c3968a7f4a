"""Shared fixtures: the seed's own sympy formulation, lambdified (the oracle)."""
import numpy as np
import pytest


@pytest.fixture(scope="session")
def seed_model():
    from codegen.seed_reference import build_seed_model
    return build_seed_model()


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
