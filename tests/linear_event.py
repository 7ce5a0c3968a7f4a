"""A linear event g(y) = coefficients . y + offset of any length, as
``ballc._radau5.solve_linear`` reads it (ballc.events.LinearEvent is ballc's system's,
of N_STATES coefficients): shared by the compiled integrators' tests."""
import numpy as np


class Event:
    def __init__(self, coefficients, offset, terminal, direction):
        self.coefficients, self.offset = np.asarray(coefficients, dtype=float), offset
        self.terminal, self.direction = terminal, direction
