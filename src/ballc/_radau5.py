"""The compiled integrators: a thin view of ``ballc._core``.

Radau IIA (order 5, ``method="radau5"``) and, in the same loop with the same events and
output, Dormand & Prince's explicit DOP853 (order 8, ``method="dop853"``), and the two
switching by stiffness (``method="auto"``).
Private: use ``ballc.simulate(..., method="radau5")`` (or ``"dop853"``, ``"auto"``).  The solver, its LU and the
system it integrates are compiled once, into ``ballc._core`` (see
``_radau5_bridge.pxi``); this module only re-exports its entry points, so there is
one copy of the kernels in the process, never two that could disagree.

``solve_system`` integrates ballc's equations; ``solve_linear`` integrates y' = A y
(used to test the integrator against the matrix exponential); ``_lu_solve`` exposes
ballc's LU, ``_constants`` radau5's method constants and ``_dop853_constants`` DOP853's
coefficients for tests.
"""
from ._core import (CONTROLLER_ELEMENTS, EPS, _constants, _controller_bits,
                    _dop853_constants, _lu_solve, _set_controller, solve_linear,
                    solve_system)

__all__ = ["solve_system", "solve_linear"]
