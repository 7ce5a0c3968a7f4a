"""Named rows of the state vector, from the generated layout (``ballc._core``).

The order of states is generated (codegen/model.py -> generated/ballc_kernels.h) and
never retyped: every module that needs a block of the state takes it from here.  A run's
states are the ball's 15 (the same rows in every run: INDEX), then two per plane of its
scene, in the plane table's order (:func:`deflection`; the scene's ``state_names``).
"""
from __future__ import annotations

from . import _core

#: The ball's states' rows (and the seed's planes' deflections: ``floor_deflection_x``..)
INDEX = _core.STATE_INDEX
#: The seed's planes (the ceiling_height shorthand), whose layout ``_core.STATE_NAMES`` is.
PLANES = _core.SEED_PLANES


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
#: The first of the planes' own states (the ball's states come first).
FIRST_PLANE_STATE = len(_core.BALL_STATE_NAMES)


def deflection(plane: int) -> slice:
    """The rows of the tangential deflection (x, y) of the plane with index ``plane``."""
    first = FIRST_PLANE_STATE + len(_core.PLANE_STATE_FIELDS) * plane
    return slice(first, first + 2)
