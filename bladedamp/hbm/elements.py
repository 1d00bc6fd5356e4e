"""Simple nonlinear elements for the harmonic balance (AFT with analytic Jacobian).

An element may declare ``memoryless = True``: its force at time t depends on its local
displacement at t only (no hysteresis). Hill's method is exact for such elements; elements
without the flag (friction) are treated as hysteretic by :mod:`bladedamp.hbm.stability`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .. import _validate


@dataclass
class CubicSpring:
    """Hardening (or softening) spring f = k3 u^3 [N], k3 in N/m^3; one local coordinate."""

    coefficient: float
    n_local: int = 1
    memoryless: ClassVar[bool] = True

    def __post_init__(self):
        _validate.finite("cubic_stiffness", self.coefficient)

    def harmonic_forces(self, local, basis, omega=None, jacobian=True):
        u = basis.synthesis @ local[:, 0]
        force = (basis.analysis @ (self.coefficient * u ** 3))[:, None]
        if not jacobian:
            return force, None, None
        jac = basis.analysis @ ((3 * self.coefficient * u ** 2)[:, None] * basis.synthesis)
        return force, jac, None
