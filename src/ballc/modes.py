"""Which kernels run, and what a contact latches when it starts.

A segment's *mode* is which planes the ball touches and, with exact Coulomb friction,
each contact's slip/stick mode (ballc.stickslip), or with the compliant law its
elastic/sliding mode (ballc.compliantmodes).  Each is a set of C kernels, chosen by the
right-hand side's flags (``_core.FLAGS``): :func:`flags` gives those of the contacts'
laws, which the C loop takes once per scene and adds each mode's own bits to
(``<plane>_slip``, ``_slip_fixed``, ``_stick``; with the compliant law
``<plane>_compliant_elastic`` once armed or ``_compliant_sliding`` instead).

At a contact start (the automaton's "enter", ``_driver.c``: begin_contact) the C loop
latches, from the contact kinematics at that state, the penetration rate rhodot^- and
the unit dig-in direction (the contact point's velocity; straight into the plane when
it is zero).  A scene that starts in contact (rho > 0) latches the rate at which an
elastic (Hertz) approach would have arrived at its present penetration and rate,
rhodot^- = sqrt(rhodot^2 + 4/5 k0 rho^(5/2) / m_total), from the energy balance
1/2 m rhodot^-^2 = 1/2 m rhodot^2 + 2/5 k0 rho^(5/2), m_total the ball's and the
observer's mass.  (A ball resting at its static penetration thus has the damping it
would have after a gentle landing, not the infinite damping of rhodot^- = 0.)  A rate
below MIN_IMPACT_RATE is latched as MIN_IMPACT_RATE.
"""
from __future__ import annotations

from . import _core

PLANES = ("floor", "ceiling")

#: Smallest penetration rate latched at impact (m/s).  A contact that starts
#: with a smaller rate (grazing, or a ball settling) uses this instead, so that
#: Hunt-Crossley's damping chi = 3/2 (1 - c_tau) k0 / |rhodot^-| stays finite.
MIN_IMPACT_RATE = _core.MIN_IMPACT_RATE


def flags(scene, in_contact):
    """The C flags of a segment in contact with the planes ``in_contact`` (plane ->
    bool), before any mode: the observer's kernels (when it has mass) and each contact's
    laws (the compliant law, with its smooth yield; or friction and/or dig-in by the
    mixture)."""
    flags = _core.FLAGS["observer"] if scene.observer_mass != 0 else 0
    mixture = scene.effective_mixture
    for plane in PLANES:
        if not in_contact[plane]:
            continue
        if scene.tangential_model == "compliant":
            flags |= _core.FLAGS[f"{plane}_compliant"]
            continue
        if mixture < 1:
            flags |= _core.FLAGS[f"{plane}_friction"]
        if mixture > 0:
            flags |= _core.FLAGS[f"{plane}_digin"]
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
