"""ballc: an elastic ball bouncing between two planes, with a compiled core.

>>> import ballc
>>> result = ballc.simulate(ballc.Scene(), t_end=5.0)
>>> print(result.contact_table())
"""
from ._core import PARAMETER_NAMES, STATE_NAMES
from .result import Contact, Result, load
from .rigid import RigidImpact, hunt_crossley_restitution, rigid_impact
from .scene import TANGENTIAL_MODELS, Scene, SceneError
from .simulate import simulate
from .sweep import sweep

__version__ = "0.1.0"
__all__ = ["Contact", "PARAMETER_NAMES", "Result", "RigidImpact", "STATE_NAMES", "Scene",
           "SceneError", "TANGENTIAL_MODELS", "hunt_crossley_restitution", "load",
           "rigid_impact", "simulate", "sweep"]
