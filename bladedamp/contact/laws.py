"""Normal contact laws of a point contact: force from the local approach (penetration).

A law describes a whole contact area; the points of a discretised patch carry a share
``weight`` of it (weights sum to 1), so a patch of 1 point and a patch of 100 points
under the same law have the same total stiffness. The approach ``a`` [m] is positive
when the bodies press into each other; ``a <= 0`` is lift-off (zero force). The law itself
(N and dN/da of one point) is written once, in :mod:`bladedamp.contact.normal`; a law object
here is its kind code and parameters (:func:`normal_law_parameters`) with the checks of its
inputs and the inverse (approach for a load).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import validation
from .normal import LAW_LINEAR, LAW_POWER, normal_forces


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

    kind = LAW_LINEAR

    @property
    def parameters(self) -> np.ndarray:
        """(k_N, 0, 0): the parameters of :func:`bladedamp.contact.normal.normal_force`."""
        return np.array([float(self.stiffness), 0.0, 0.0])

    def force(self, approach: np.ndarray, weight: np.ndarray):
        """Normal force N [N] and its derivative dN/da [N/m] at the approach a [m] of points of
        ``weight`` [-], both of the broadcast shape of ``approach`` and ``weight``
        (:func:`bladedamp.contact.normal.normal_forces`)."""
        return normal_forces(self.kind, self.parameters, weight, approach)

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

    kind = LAW_POWER

    @property
    def parameters(self) -> np.ndarray:
        """(N_ref, a_ref, p): the parameters of :func:`bladedamp.contact.normal.normal_force`."""
        return np.array([float(self.reference_load), float(self.reference_approach), float(self.exponent)])

    def force(self, approach: np.ndarray, weight: np.ndarray):
        """As :meth:`LinearNormalLaw.force`."""
        return normal_forces(self.kind, self.parameters, weight, approach)

    def approach_for_load(self, load: np.ndarray, weight: np.ndarray) -> np.ndarray:
        ratio = np.maximum(np.asarray(load, dtype=float), 0.0) / (self.reference_load * weight)
        return self.reference_approach * ratio ** (1.0 / self.exponent)

    def stiffness_at_load(self, load: float) -> float:
        p = self.exponent
        return self.stiffness * (max(load, 0.0) / self.reference_load) ** ((p - 1) / p)


NormalLaw = LinearNormalLaw | RoughnessNormalLaw


def normal_law_parameters(law):
    """(kind, parameters (3,)) of a normal law the fused kernels evaluate themselves
    (:func:`bladedamp.contact.normal.normal_force`), or None.

    LinearNormalLaw: (LAW_LINEAR, [k_N, 0, 0]); RoughnessNormalLaw: (LAW_POWER, [N_ref, a_ref, p]).
    Exact types only (a subclass may change ``force``)."""
    if type(law) in (LinearNormalLaw, RoughnessNormalLaw):
        return law.kind, law.parameters
    return None
