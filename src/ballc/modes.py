"""Which kernels run, and what a contact latches when it starts.

A segment's *mode* is which planes the ball touches and, with exact Coulomb friction,
each contact's slip/stick mode (ballc.stickslip).  :func:`flags` maps it to the C
kernels that run; :func:`latch_values` is what a contact start latches.
"""
from __future__ import annotations

import math

import numpy as np

from . import _core, compliantmodes, stickslip

PLANES = ("floor", "ceiling")
_KIN_PER_PLANE = _core.CONTACT_KINEMATICS_PER_PLANE

#: Smallest penetration rate latched at impact (m/s).  A contact that starts
#: with a smaller rate (grazing, or a ball settling) uses this instead, so that
#: Hunt-Crossley's damping chi = 3/2 (1 - c_tau) k0 / |rhodot^-| stays finite.
MIN_IMPACT_RATE = 1e-9


def flags(scene, in_contact, coulomb=None, compliant=None, armed=None):
    """The C flags of a segment: the observer's kernels (when it has mass), each
    contact's laws (compliant; or friction and/or dig-in by the mixture) and, with
    ``coulomb`` (plane -> "slip", "slip_fixed", "stick" or None), each contact's
    exact Coulomb mode; with ``compliant`` (plane -> "elastic", "sliding" or None) and
    ``armed`` (plane -> bool), each compliant contact's mode (ballc.compliantmodes)."""
    flags = _core.FLAGS["observer"] if scene.observer_mass != 0 else 0
    mixture = scene.effective_mixture
    for plane in PLANES:
        if not in_contact[plane]:
            continue
        if scene.tangential_model == "compliant":
            flags |= compliantmodes.mode_flags(plane, compliant[plane] if compliant else None,
                                               armed[plane] if armed else False)
            continue
        if mixture < 1:
            flags |= _core.FLAGS[f"{plane}_friction"]
        if mixture > 0:
            flags |= _core.FLAGS[f"{plane}_digin"]
        if coulomb:
            flags |= stickslip.mode_flags(plane, coulomb[plane])
    return flags


def contact_flags(scene, plane: int) -> int:
    """The flags of a contact with the plane with index ``plane`` (its laws: compliant;
    or friction and/or dig-in by the mixture), without its modes: what the C loop adds
    its modes to."""
    if scene.tangential_model == "compliant":
        return _core.flag("compliant", plane)
    mixture = scene.effective_mixture
    return ((_core.flag("friction", plane) if mixture < 1 else 0)
            | (_core.flag("digin", plane) if mixture > 0 else 0))


def latch_values(y, params, plane, scene=None):
    """(rhodot^-, unit dig-in direction) of ``plane`` at state y.

    At a contact start rho = 0 and rhodot^- is the penetration rate.  A scene that
    starts in contact (rho > 0) latches the rate at which an elastic (Hertz) approach
    would have arrived at its present penetration and rate:
    rhodot^- = sqrt(rhodot^2 + 4/5 k0 rho^(5/2) / m_total), from the energy balance
    1/2 m rhodot^-^2 = 1/2 m rhodot^2 + 2/5 k0 rho^(5/2).  (A ball resting at its
    static penetration thus has the damping it would have after a gentle landing,
    not the infinite damping of rhodot^- = 0.)
    """
    kin = _core.contact_kinematics(np.ascontiguousarray(y[None, :]), params)[0]
    k = PLANES.index(plane) * _KIN_PER_PLANE
    rho, rate, velocity = kin[k], kin[k + 1], kin[k + 2:k + 5]
    if scene is not None and rho > 0:
        stored = 0.8 * scene.hertz_stiffness * rho ** 2.5 / (scene.mass + scene.observer_mass)
        rate = math.sqrt(rate * rate + stored)
    speed = math.sqrt(velocity.dot(velocity))   # np.linalg.norm's formula, without its overhead
    if speed > 0:
        direction = velocity / speed
    else:
        direction = np.array([0.0, 0.0, -1.0 if plane == "floor" else 1.0])
    return max(rate, MIN_IMPACT_RATE), direction
