"""Linear solves of the harmonic balance: LU of dense or sparse Jacobians, and condensation of
interior blocks.

Newton and the arc-length continuation (:mod:`bladedamp.hbm.continuation`) factorise one
matrix per iteration, either the Jacobian dR/dx or the bordered matrix [[dR/dx, dR/domega],
[tangent]]. :func:`factorize` does that for a dense ndarray or a scipy.sparse matrix.
:class:`BlockCondensation` is the faster route for assemblies whose unknowns split into an
exterior set and interior blocks that couple only among themselves within a block (the six
rigid-body coordinates of each damper, times the harmonics: a damper's equations contain only
its own coordinates and those of the two blades it touches). The interior blocks are
eliminated by their small dense inverses (static condensation) and the exterior Schur
complement, which keeps any border, is factorised densely.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve
from scipy.sparse.linalg import splu


def factorize(A):
    """LU factorisation of a dense ndarray or a scipy.sparse matrix (sparse LU, COLAMD
    ordering); returns ``solve(b)`` for one or several right-hand sides (columns of b).
    Raises ``np.linalg.LinAlgError`` (dense) or ``RuntimeError`` (sparse) if A is singular."""
    if sp.issparse(A):
        lu = splu(sp.csc_matrix(A))
        return lambda b: lu.solve(np.asarray(b, dtype=float))
    with warnings.catch_warnings():
        warnings.simplefilter("error", LinAlgWarning)
        try:
            lu = lu_factor(A, check_finite=False)
        except LinAlgWarning as e:
            raise np.linalg.LinAlgError(str(e)) from None
    if not np.all(np.isfinite(lu[0])) or np.any(np.diag(lu[0]) == 0):
        raise np.linalg.LinAlgError("singular matrix")
    return lambda b: lu_solve(lu, np.asarray(b, dtype=float), check_finite=False)


def solve(A, b):
    """Solve A y = b for a dense ndarray or a scipy.sparse matrix (sparse LU, COLAMD ordering)."""
    if sp.issparse(A):
        return splu(sp.csc_matrix(A)).solve(np.asarray(b, dtype=float))
    return np.linalg.solve(A, b)


@dataclass
class BlockCondensation:
    """Factorisation by condensing interior blocks (a callable like :func:`factorize`).

    Parameters
    ----------
    interior : (n_blocks, b) int, the unknowns of each interior block
    coupled : (n_blocks, m) int, the exterior unknowns each block couples to (rows and columns)
    size : number of unknowns of the system (n). A matrix of size n + 1 (bordered by one row
        and column, as in the arc-length corrector) has its border coupled to every block.
    max_condition : a block whose 1-norm condition estimate exceeds this (nearly singular, e.g.
        a damper in full lift-off without inertia) sends the matrix to :func:`factorize`.

    Entries of A between an interior block and unknowns that are neither its own nor in its
    ``coupled`` set must be zero; this is not checked at each call (the caller's structure
    guarantees it) but the tests compare with the plain LU.
    """

    interior: np.ndarray
    coupled: np.ndarray
    size: int
    max_condition: float = 1e12
    _layout: dict = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self):
        self.interior = np.atleast_2d(np.asarray(self.interior, dtype=np.intp))
        self.coupled = np.atleast_2d(np.asarray(self.coupled, dtype=np.intp))
        if self.interior.shape[0] != self.coupled.shape[0]:
            raise ValueError("interior and coupled must have one row per block")
        flat = self.interior.ravel()
        if np.unique(flat).size != flat.size or flat.min(initial=0) < 0 or flat.max(initial=-1) >= self.size:
            raise ValueError(f"interior indices must be distinct and in [0, {self.size})")
        if np.isin(self.coupled, flat).any():
            raise ValueError("coupled indices must be exterior (not in any interior block)")

    def layout(self, n: int):
        """(exterior indices, coupled indices incl. border, their positions in the exterior)."""
        if n not in self._layout:
            if n not in (self.size, self.size + 1):
                raise ValueError(f"matrix size {n} is neither the system size {self.size} nor bordered ({self.size + 1})")
            mask = np.ones(n, dtype=bool)
            mask[self.interior.ravel()] = False
            exterior = np.flatnonzero(mask)
            coupled = self.coupled
            if n == self.size + 1:
                coupled = np.hstack([coupled, np.full((coupled.shape[0], 1), self.size)])
            position = np.full(n, -1)
            position[exterior] = np.arange(exterior.size)
            self._layout[n] = (exterior, coupled, position[coupled])
        return self._layout[n]

    def __call__(self, A):
        A = A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)
        n = A.shape[0]
        exterior, coupled, pos = self.layout(n)
        q = self.interior
        nb, b = q.shape
        m = coupled.shape[1]
        ne = exterior.size
        Aqq = A[q[:, :, None], q[:, None, :]]                  # (nb, b, b)
        try:
            inv = np.linalg.inv(Aqq)
        except np.linalg.LinAlgError:
            return factorize(A)
        condition = np.abs(Aqq).sum(axis=1).max(axis=1) * np.abs(inv).sum(axis=1).max(axis=1)
        if not np.all(np.isfinite(condition)) or condition.max() > self.max_condition:
            return factorize(A)
        Aqc = A[q[:, :, None], coupled[:, None, :]]            # (nb, b, m)
        Acq = A[coupled[:, :, None], q[:, None, :]]            # (nb, m, b)
        X = inv @ Aqc                                          # Aqq^-1 Aqc
        S = A[exterior[:, None], exterior[None, :]]
        flat = (pos[:, :, None] * ne + pos[:, None, :]).ravel()
        S -= np.bincount(flat, (Acq @ X).ravel(), minlength=ne * ne).reshape(ne, ne)
        solve_exterior = factorize(S)

        def solve(rhs):
            rhs = np.asarray(rhs, dtype=float)
            extra = rhs.shape[1:]
            yq = inv @ rhs[q].reshape(nb, b, -1)               # Aqq^-1 b_q: (nb, b, k)
            be = rhs[exterior].reshape(ne, -1).copy()
            np.subtract.at(be, pos.ravel(), (Acq @ yq).reshape(nb * m, -1))
            xe = solve_exterior(be)
            xq = yq - X @ xe[pos]
            out = np.empty((n, xe.shape[1]))
            out[exterior] = xe
            out[q.ravel()] = xq.reshape(nb * b, -1)
            return out.reshape((n,) + extra)

        return solve
