"""Contact patch: a grid of point contacts on a rectangle, driven by its control point.

The patch frame has its origin at the control point (OL or OR of the paper, Fig. 2), axes
(xi, eta, zeta): zeta the normal from the platform into the damper, xi across the contact
height h_C, eta along the contact length l_C. The six generalised relative displacements of
the control point ``w = (u_xi, u_eta, u_zeta, phi_xi, phi_eta, phi_zeta)`` (Eq. 7) move a point
at (xi, eta) rigidly by ``u + phi x (xi, eta, 0)``; the point forces are summed back to three
forces and three moments about the control point (the transpose of the same map), the six
generalised contact forces of Eq. 11 (on the platform).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .. import validation
from .laws import LinearNormalLaw, RoughnessNormalLaw
from .point import PointContactSamples, point_contact_forces

DOF_NAMES = ("u_xi", "u_eta", "u_zeta", "phi_xi", "phi_eta", "phi_zeta")


def rigid_point_map(xi: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """(P, 3, 6) map from control-point motion w to point displacements (u_xi, u_eta, u_zeta).

    u_xi = w0 - phi_zeta eta, u_eta = w1 + phi_zeta xi, u_zeta = w2 + phi_xi eta - phi_eta xi.
    """
    xi, eta = np.asarray(xi, dtype=float), np.asarray(eta, dtype=float)
    B = np.zeros((xi.size, 3, 6))
    B[:, 0, 0] = 1.0
    B[:, 1, 1] = 1.0
    B[:, 2, 2] = 1.0
    B[:, 0, 5] = -eta
    B[:, 1, 5] = xi
    B[:, 2, 3] = eta
    B[:, 2, 4] = -xi
    return B


@functools.lru_cache(maxsize=64)
def _dof_jacobian_path(b_shape, j_shape):
    """The einsum contraction order of :func:`dof_jacobian` for these operand shapes, found once
    (numpy's optimiser would search it on every call, a noticeable share of an FRF's time)."""
    # m > 6 (a flexible platform's maps): numpy's optimiser would take one 8-loop einsum, 5 x slower
    # than its own m = 6 path (B with B, then the point Jacobian), given here (benchmarks/README.md,
    # 'Moved from the package's docstrings', contact/patch.py)
    if b_shape[-1] != 6:
        return ["einsum_path", (0, 2), (0, 1)]
    return np.einsum_path("lpim,lpaikb,lpkn->lambn", np.empty(b_shape), np.empty(j_shape), np.empty(b_shape),
                          optimize=True)[0]


def dof_jacobian(point_map: np.ndarray, point_jacobian: np.ndarray) -> np.ndarray:
    """The Jacobian of a patch's generalised forces from its points' (Eq. 11 differentiated):
    ``sum_p B_p^T (d f_p / d c_p) B_p`` per pair of harmonic coefficients.

    ``point_map`` B (..., P, 3, m) maps the m local coordinates (the 6 control-point DOF, or a
    flexible platform's 6 + n_m) to each point's (xi, eta, zeta); ``point_jacobian``
    (..., P, C, 3, 3, C) is d f_coef[a, p, i] / d c_p[b, k] (force coefficient a of direction
    i by displacement coefficient b of direction k); returns (..., C, m, C, m). Leading axes
    (patches, dampers) are batched. One optimised einsum over
    flattened leading axes, several times faster than two chained plain einsums
    (benchmarks/README.md, 'Moved from the package's docstrings', contact/patch.py)."""
    lead = point_map.shape[:-3]
    L = int(np.prod(lead, dtype=int))
    B = point_map.reshape((L,) + point_map.shape[-3:])
    J = point_jacobian.reshape((L,) + point_jacobian.shape[-5:])
    out = np.einsum("lpim,lpaikb,lpkn->lambn", B, J, B, optimize=_dof_jacobian_path(B.shape, J.shape))
    return out.reshape(lead + out.shape[1:])


@dataclass
class PatchEvaluation:
    """Result of one AFT evaluation of a patch.

    force : (C, m) harmonic coefficients of the generalised contact forces on the platform [N, N m]
        (m = 6: forces and moments about the control point), conjugate to the local coordinates w
    jacobian : (C*m, C*m) or None, d force / d w (harmonic-major)
    points : PointContactSamples of every point over the period
    """

    force: np.ndarray
    jacobian: np.ndarray | None
    points: PointContactSamples


@dataclass
class ContactPatch:
    """Rectangular contact area discretised into ``n_xi x n_eta`` point contacts.

    Parameters
    ----------
    height : float
        Contact height h_C along xi [m] (0 for a line contact: one row of points).
    length : float
        Contact length l_C along eta [m].
    tangential_stiffness : float
        Total tangential stiffness c_T of the area [N/m], shared by the points.
    friction_coefficient : float
        mu [-].
    normal_law : LinearNormalLaw or RoughnessNormalLaw
        Normal law of the whole area.
    n_xi, n_eta : int
        Points across the height and along the length (midpoints of equal cells).
    weights : array (n_xi*n_eta,), optional
        Share of each point in stiffness and load (default uniform); e.g. a Hertz pressure
        profile for a cylinder.
    initial_gap : array (n_xi*n_eta,), optional
        Gap of each point before loading [m] (default 0: a perfect fit; > 0 open, < 0
        interference), e.g. from a damper whose shape does not fit the platform
        (:func:`bladedamp.geometry.misfit_gaps`). The approach at rest is ``-initial_gap``.
    """

    height: float
    length: float
    tangential_stiffness: float
    friction_coefficient: float
    normal_law: LinearNormalLaw | RoughnessNormalLaw
    n_xi: int = 3
    n_eta: int = 5
    weights: np.ndarray | None = None
    initial_gap: np.ndarray | None = None
    xi: np.ndarray = field(init=False, repr=False)
    eta: np.ndarray = field(init=False, repr=False)
    point_map: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        validation.nonnegative("contact height h_C", self.height)
        validation.positive("contact length l_C", self.length)
        validation.positive("tangential stiffness k_T", self.tangential_stiffness)
        validation.nonnegative("friction coefficient mu", self.friction_coefficient)
        validation.integer("n_xi", self.n_xi, minimum=1)
        validation.integer("n_eta", self.n_eta, minimum=1)
        if not isinstance(self.normal_law, (LinearNormalLaw, RoughnessNormalLaw)):
            raise ValueError("normal_law must be a LinearNormalLaw or RoughnessNormalLaw")
        cx = (np.arange(self.n_xi) + 0.5) / self.n_xi - 0.5
        ce = (np.arange(self.n_eta) + 0.5) / self.n_eta - 0.5
        xi, eta = np.meshgrid(cx * self.height, ce * self.length, indexing="ij")
        self.xi, self.eta = xi.ravel(), eta.ravel()
        if self.weights is None:
            self.weights = np.full(self.n_points, 1.0 / self.n_points)
        else:
            w = validation.nonnegative("weights", self.weights)
            if w.shape != (self.n_points,) or not np.isclose(w.sum(), 1.0):
                raise ValueError(f"weights must be {self.n_points} non-negative values summing to 1")
            self.weights = w
        self.point_map = rigid_point_map(self.xi, self.eta)
        if self.initial_gap is None:
            self.initial_gap = np.zeros(self.n_points)
        else:
            gap = np.asarray(validation.finite("initial_gap", self.initial_gap), dtype=float)
            if gap.shape != (self.n_points,):
                raise ValueError(f"initial_gap must have one value per point, shape ({self.n_points},) m")
            self.initial_gap = gap

    @property
    def n_points(self) -> int:
        return self.n_xi * self.n_eta

    @property
    def normalised_coordinates(self):
        """(xi*, eta*) = (xi / h_C, eta / l_C) of every point (paper Fig. 9)."""
        h = self.height if self.height > 0 else 1.0
        return self.xi / h, self.eta / self.length

    def approach_for_load(self, load: float) -> np.ndarray:
        """Per-point static approach [m] under a total normal load [N] spread by the weights."""
        return self.normal_law.approach_for_load(self.weights * load, self.weights)

    def point_coefficients(self, w: np.ndarray) -> np.ndarray:
        """(C, P, 3) point displacement coefficients from control-point coefficients (C, 6)."""
        return np.einsum("pij,cj->cpi", self.point_map, w)

    def evaluate(self, w, basis, approach_offset, jacobian=True, point_map=None) -> PatchEvaluation:
        """Generalised contact forces (Eq. 11) of the patch for control-point motion ``w``.

        Parameters
        ----------
        w : (C, m) harmonic coefficients of the patch's local coordinates: the relative
            control-point motion (m = 6) [m, rad], or those of ``point_map``
        basis : HarmonicBasis
        approach_offset : (P,) or float, approach at w = 0 [m] (static preload, see
            :meth:`approach_for_load`)
        point_map : (P, 3, m) map from ``w`` to the point displacements (xi, eta, zeta) [m]
            instead of the rigid :attr:`point_map` (e.g. a flexible platform's,
            :func:`bladedamp.diskmodel.contact_point_maps`); the forces are then conjugate to ``w``
        """
        w = np.asarray(w, dtype=float)
        C = basis.n_coeffs
        B = self.point_map if point_map is None else np.asarray(point_map, dtype=float)
        m = B.shape[-1]
        if B.shape != (self.n_points, 3, m) or w.shape != (C, m):
            raise ValueError(f"point_map must have shape ({self.n_points}, 3, m) and w ({C}, m) "
                             f"(got {B.shape} and {w.shape})")
        offset = np.broadcast_to(np.asarray(approach_offset, dtype=float), (self.n_points,))
        pts = point_contact_forces(np.einsum("pij,cj->cpi", B, w), basis,
                                   self.tangential_stiffness * self.weights,
                                   np.full(self.n_points, self.friction_coefficient),
                                   self.normal_law, self.weights, offset, jacobian=jacobian)
        point_force_coeffs = basis.to_coeffs(np.moveaxis(pts.force, 1, 0))  # (C, P, 3)
        force = np.einsum("cpi,pij->cj", point_force_coeffs, B)
        jac = None
        if jacobian:
            # d f_coef[a, p, i] / d c_p[b, k]  (point coefficient blocks are direction-major)
            P, T = self.n_points, basis.n_samples
            jp = np.matmul(basis.analysis, pts.jacobian.reshape(P, T, 9 * C)).reshape(P, C, 3, 3, C)
            jac = dof_jacobian(B, jp).reshape(C * m, C * m)
        return PatchEvaluation(force, jac, pts)

    def equivalent_stiffness(self, w, basis, approach_offset) -> dict[int, np.ndarray]:
        """Complex equivalent stiffnesses per harmonic, k_hat = F_hat / w_hat per DOF (Eq. 10).

        Returns {h: (6,) complex} for h >= 1; entries with w_hat = 0 are NaN (undefined).
        Real part: stiffness, imaginary part: damping (positive when energy is dissipated).
        """
        ev = self.evaluate(w, basis, approach_offset, jacobian=False)
        F, W = basis.to_complex(ev.force), basis.to_complex(np.asarray(w, dtype=float))
        out = {}
        for h in basis.harmonics:
            if h == 0:
                continue
            with np.errstate(divide="ignore", invalid="ignore"):
                out[h] = np.where(np.abs(W[h]) > 0, F[h] / np.where(W[h] == 0, 1, W[h]), np.nan + 0j)
        return out
