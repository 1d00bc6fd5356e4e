"""Normal contact laws of a point contact: force from the local approach (penetration).

A law describes a whole contact area; the points of a discretised patch carry a share
``weight`` of it (weights sum to 1), so a patch of 1 point and a patch of 100 points
under the same law have the same total stiffness. The approach ``a`` [m] is positive
when the bodies press into each other; ``a <= 0`` is lift-off (zero force).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import validation


@dataclass(frozen=True)
class LinearNormalLaw:
    """N = k_N * weight * max(a, 0).

    Parameters
    ----------
    stiffness : float
        Total normal contact stiffness of the area, k_N [N/m].
    """

    stiffness: float

    def __post_init__(self):
        validation.positive("normal stiffness k_N", self.stiffness)

    def force(self, approach: np.ndarray, weight: np.ndarray):
        """Normal force [N] and its derivative in the approach [N/m], same shape as ``approach``."""
        k = self.stiffness * weight
        pressed = approach > 0
        return np.where(pressed, k * approach, 0.0), np.where(pressed, k, 0.0)

    def approach_for_load(self, load: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """Static approach [m] at which a point of ``weight`` carries ``load`` [N]."""
        return np.asarray(load) / (self.stiffness * weight)

    def stiffness_at_load(self, load: float) -> float:
        """Total normal stiffness [N/m] at total load ``load`` [N] (constant here)."""
        return self.stiffness


@dataclass(frozen=True)
class RoughnessNormalLaw:
    """Rough-surface law N = weight * N_ref * (a / a_ref)^p, a_ref = p N_ref / k_ref, p >= 1.

    The stiffness dN/da grows with the approach (more asperities in contact), the
    contact-stiffness nonlinearity the paper attributes to surface roughness. ``p = 1``
    is the linear law; ``p = 1.5`` a Hertz-like asperity law.

    Parameters
    ----------
    stiffness : float
        Total normal stiffness k_ref [N/m] at the reference load.
    reference_load : float
        Total normal load N_ref [N] at which the stiffness is ``stiffness``.
    exponent : float
        p in [1, 5].
    """

    stiffness: float
    reference_load: float
    exponent: float = 1.5

    def __post_init__(self):
        validation.positive("normal stiffness k_N", self.stiffness)
        validation.positive("reference_load", self.reference_load)
        validation.in_range("exponent", self.exponent, 1.0, 5.0)

    @property
    def reference_approach(self) -> float:
        """a_ref = p N_ref / k_ref [m]."""
        return self.exponent * self.reference_load / self.stiffness

    def force(self, approach: np.ndarray, weight: np.ndarray):
        a_ref, p = self.reference_approach, self.exponent
        ratio = np.maximum(approach, 0.0) / a_ref
        n_ref = self.reference_load * weight
        # lift-off (a <= 0): no force and no stiffness (for p = 1, 0**0 would give 1)
        return n_ref * ratio ** p, np.where(approach > 0, n_ref * p / a_ref * ratio ** (p - 1), 0.0)

    def approach_for_load(self, load: np.ndarray, weight: np.ndarray) -> np.ndarray:
        ratio = np.maximum(np.asarray(load, dtype=float), 0.0) / (self.reference_load * weight)
        return self.reference_approach * ratio ** (1.0 / self.exponent)

    def stiffness_at_load(self, load: float) -> float:
        p = self.exponent
        return self.stiffness * (max(load, 0.0) / self.reference_load) ** ((p - 1) / p)


NormalLaw = LinearNormalLaw | RoughnessNormalLaw
