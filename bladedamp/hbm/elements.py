"""Nonlinear elements for the harmonic balance, and the base class for your own.

The contract of an element (what :class:`~bladedamp.hbm.system.HarmonicBalanceSystem` calls)
--------------------------------------------------------------------------------------------
An element has ``n_local`` local coordinates w (e.g. the tip displacement in x [m], or a
relative displacement across a contact) and a method

    ``harmonic_forces(local, basis, omega, jacobian=True) -> (F, dF/dlocal, dF/domega)``

* ``local`` (C, n_local): the harmonic coefficients of w, harmonic-major in the order of
  ``basis`` (:class:`~bladedamp.hbm.fourier.HarmonicBasis`: static term, then the cosine and
  sine coefficient of each harmonic), SI units of w;
* ``F`` (C, n_local): the coefficients of the element's force f(t) [N, or N m for a rotation],
  **the restoring force conjugate to w**: the force the element exerts on the structure is
  -f, i.e. f enters the residual as ``+ T^T F`` (a spring is f = k w with k > 0), and
  ``oint f . dw`` is the energy the element absorbs per period [J];
* ``dF/dlocal`` (C*n_local, C*n_local): its exact Jacobian (harmonic-major, as ``local.ravel()``),
  or None when ``jacobian`` is False;
* ``dF/domega`` (C*n_local,) or None: the derivative in the angular frequency Omega [rad/s] at
  fixed coefficients, None when the force does not depend on Omega explicitly.

The element is joined to a structure by a :class:`~bladedamp.hbm.system.Coupling`: the
real-form map T (C*n_local, C*n_dof) from the structure's unknowns to ``local``
(``TunedDisk.point_map`` / ``MistunedDisk.point_map`` give the map to a named blade point).

An element may declare ``memoryless = True``: its force at time t depends on its local
displacement at t only (no hysteresis). Hill's method is exact for such elements; elements
without the flag (friction) are treated as hysteretic by :mod:`bladedamp.hbm.stability`.

Writing your own: :class:`TimeDomainElement`
--------------------------------------------
Subclass :class:`TimeDomainElement` and give only the force in time,
``forces_in_time(u, omega) -> (f, df/du)`` with ``u`` (T, n_local) the samples of w over one
period [SI], ``f`` (T, n_local) the restoring force at each sample and ``df/du``
(T, n_local, n_local) its derivative (``df[t, i, j] = d f_i / d u_j`` at sample t). The base class
does the alternating frequency-time step once: synthesis, your forces, analysis, and the exact
Jacobian ``analysis @ blockdiag(df/du) @ synthesis``, vectorised over the samples; it is
``memoryless``. :class:`CubicSpring` and :class:`GapSpring` are written this way.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import validation


class TimeDomainElement:
    """Base class of memoryless nonlinear elements: the AFT written once.

    A subclass sets ``n_local`` (an attribute or a dataclass field) and implements
    :meth:`forces_in_time`; :meth:`harmonic_forces` is then the element's contract with the
    harmonic balance (see the module docstring for units, shapes and the sign convention).
    """

    n_local: int = 1
    memoryless: ClassVar[bool] = True

    def forces_in_time(self, u: np.ndarray, omega: float):
        """Restoring force at every time sample.

        Parameters
        ----------
        u : (T, n_local) local displacements at the samples of one period [SI]
        omega : the angular excitation frequency Omega [rad/s] (for information; a force that
            depends on it explicitly may return a third array, df/domega (T, n_local))

        Returns
        -------
        f : (T, n_local) restoring force conjugate to u [N or N m]
        dfdu : (T, n_local, n_local) d f_i / d u_j at each sample
        """
        raise NotImplementedError(f"{type(self).__name__} must implement forces_in_time(u, omega)")

    def harmonic_forces(self, local, basis, omega=None, jacobian=True):
        """``(F (C, n_local), dF/dlocal (C*n, C*n) or None, dF/domega (C*n,) or None)`` by AFT."""
        local = np.asarray(local, dtype=float)
        C, n = local.shape
        if n != self.n_local:
            raise ValueError(f"{type(self).__name__}: local has {n} coordinates, n_local is {self.n_local}")
        u = basis.synthesis @ local                                    # (T, n)
        out = self.forces_in_time(u, omega)
        f, dfdu = np.asarray(out[0], dtype=float), np.asarray(out[1], dtype=float)
        T = u.shape[0]
        if f.shape != (T, n) or dfdu.shape != (T, n, n):
            raise ValueError(f"{type(self).__name__}.forces_in_time must return f ({T}, {n}) and "
                             f"df/du ({T}, {n}, {n}); got {f.shape} and {dfdu.shape}")
        force = basis.analysis @ f
        if not jacobian:
            return force, None, None
        if n == 1:
            jac = basis.analysis @ (dfdu[:, 0, :] * basis.synthesis)
        else:
            # J[c i, d j] = sum_t analysis[c, t] dfdu[t, i, j] synthesis[t, d]
            jac = np.einsum("ct,tij,td->cidj", basis.analysis, dfdu, basis.synthesis,
                            optimize=True).reshape(C * n, C * n)
        domega = None
        if len(out) > 2 and out[2] is not None:
            domega = (basis.analysis @ np.asarray(out[2], dtype=float)).ravel()
        return force, jac, domega


@dataclass
class CubicSpring(TimeDomainElement):
    """Hardening (or softening) spring f = k3 u^3 [N], k3 in N/m^3 (any finite value); one
    local coordinate u [m]."""

    coefficient: float
    n_local: int = 1

    def __post_init__(self):
        self.coefficient = validation.finite("cubic_stiffness", self.coefficient)
        if self.n_local != 1:
            raise ValueError(f"CubicSpring has one local coordinate (n_local = 1, got {self.n_local})")

    def forces_in_time(self, u, omega=None):
        k3 = self.coefficient
        return k3 * u ** 3, (3 * k3 * u ** 2)[:, :, None]


@dataclass
class GapSpring(TimeDomainElement):
    """Unilateral spring behind a gap, f = k max(0, u - gap) [N]: a contact that closes when the
    local displacement u [m] exceeds ``gap`` (e.g. a tip shroud or a stop), one local coordinate.

    Parameters
    ----------
    stiffness : k [N/m], > 0
    gap : the clearance g [m], >= 0 (0: touching, open for u < 0)
    """

    stiffness: float
    gap: float = 0.0
    n_local: int = 1

    def __post_init__(self):
        self.stiffness = validation.positive("GapSpring stiffness [N/m]", self.stiffness)
        self.gap = validation.positive("GapSpring gap [m]", self.gap, allow_zero=True)
        if self.n_local != 1:
            raise ValueError(f"GapSpring has one local coordinate (n_local = 1, got {self.n_local})")

    def forces_in_time(self, u, omega=None):
        closed = u > self.gap
        return np.where(closed, self.stiffness * (u - self.gap), 0.0), \
            np.where(closed, self.stiffness, 0.0)[:, :, None]
