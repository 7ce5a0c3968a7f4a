"""Named rows of the state vector, from the generated layout (``ballc._core``).

The order of states is generated (codegen/model.py -> generated/ballc_kernels.h) and
never retyped: every module that needs a block of the state takes it from here.
"""
from __future__ import annotations

from . import _core

INDEX = _core.STATE_INDEX
PLANES = ("floor", "ceiling")


def rows(name: str, count: int = 3) -> slice:
    """The ``count`` rows of the state starting at state ``name``."""
    first = INDEX[name]
    return slice(first, first + count)


QUATERNION = rows("qw", 4)
POSITION = rows("x")
ANGULAR_VELOCITY = rows("omega_x")
VELOCITY = rows("vx")
DISSIPATED = rows("dissipated_normal", 2)          # normal, tangential (J)
DEFLECTION = {plane: rows(f"{plane}_deflection_x", 2) for plane in PLANES}
