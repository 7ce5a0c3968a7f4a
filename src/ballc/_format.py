"""Numbers in messages: plain, as a user typed them (-3.0, not np.float64(-3.0))."""
from __future__ import annotations

import numpy as np


def plain(value) -> str:
    """``repr(value)`` with numpy scalars as Python numbers and numpy arrays, lists and
    tuples of them as lists and tuples of Python numbers."""
    return repr(_python(value))


def _python(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return type(value)(_python(v) for v in value)
    return value
