"""ballc: an elastic ball bouncing between planes, with a compiled core.

>>> import ballc
>>> result = ballc.simulate(ballc.Scene(), t_end=5.0)
>>> print(result.contact_table())
"""
from ._core import PARAMETER_NAMES, STATE_NAMES
from .impact import Impact, ImpactFit, fit_impacts, impact, impact_table
from .planes import Plane
from .result import Contact, Result, load
from .rigid import RigidImpact, c_tau_for_restitution, hunt_crossley_restitution, rigid_impact
from .scene import TANGENTIAL_MODELS, Scene, SceneError
from .simulate import simulate
from .sweep import SweepInterrupted, sweep

__version__ = "0.1.0"
__all__ = ["Contact", "Impact", "ImpactFit", "PARAMETER_NAMES", "Plane", "Result", "RigidImpact",
           "STATE_NAMES", "Scene", "SceneError", "SweepInterrupted", "TANGENTIAL_MODELS", "c_tau_for_restitution",
           "fit_impacts", "hunt_crossley_restitution", "impact", "impact_table", "load",
           "rigid_impact", "simulate", "sweep"]
