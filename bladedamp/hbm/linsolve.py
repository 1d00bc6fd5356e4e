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

import functools
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve
from scipy.sparse.linalg import splu


_BLAS_CONTROLLER = None


def one_blas_thread(fn):
    """Run ``fn`` with the BLAS (OpenBLAS, MKL) limited to one thread, restored afterwards.

    The harmonic balance factorises many small dense matrices (70-300 unknowns per tuned
    sector): for these a threaded BLAS is slower, and far slower when the cores are shared
    (measured on the 2-core box under load: LU of a 150 x 150 matrix 0.67 ms with one thread,
    24 ms with two; the wedge's (0, ..., 7) FRF spent half its time in LU). The studies run
    their own processes in parallel instead (:mod:`bladedamp.studies.parallel`).
    """
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        global _BLAS_CONTROLLER
        if _BLAS_CONTROLLER is None:
            from threadpoolctl import ThreadpoolController
            _BLAS_CONTROLLER = ThreadpoolController()
        with _BLAS_CONTROLLER.limit(limits=1, user_api="blas"):
            return fn(*args, **kwargs)
    return wrapper


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
        A = A.toarray() if sp.issparse(A) else np.ascontiguousarray(A, dtype=float)
        n = A.shape[0]
        exterior, coupled, pos = self.layout(n)
        q = self.interior
        nb, b = q.shape
        m = coupled.shape[1]
        ne = exterior.size
        S = np.empty((ne, ne))
        inv, X, Acq = np.empty((nb, b, b)), np.empty((nb, b, m)), np.empty((nb, m, b))
        condition = _condense(A, q, coupled, pos, exterior, S, inv, X, Acq)
        if not np.isfinite(condition) or condition > self.max_condition:
            return factorize(A)
        solve_exterior = factorize(S)

        def solve(rhs):
            rhs = np.asarray(rhs, dtype=float)
            extra = rhs.shape[1:]
            r = np.ascontiguousarray(rhs.reshape(n, -1))
            yq, be = _condensed_rhs(r, q, pos, exterior, inv, Acq)
            xe = solve_exterior(be)
            return _condensed_back(r, xe, yq, q, pos, exterior, X).reshape((n,) + extra)

        return solve


@njit(cache=True)
def _condense(A, q, coupled, pos, exterior, S, inv, X, Acq):
    """S = A_ee - sum_k A_ck A_kk^-1 A_kc (scattered to the coupled rows/columns of block k);
    fills inv = A_kk^-1, X = A_kk^-1 A_kc, Acq = A_ck. Returns the largest 1-norm condition
    number of the blocks (inf if one is singular). Gauss-Jordan with partial pivoting per block."""
    nb, b = q.shape
    m = coupled.shape[1]
    ne = exterior.size
    for i in range(ne):
        ei = exterior[i]
        for j in range(ne):
            S[i, j] = A[ei, exterior[j]]
    worst = 0.0
    work = np.empty((b, 2 * b))
    for k in range(nb):
        norm_a = 0.0
        for j in range(b):
            col = 0.0
            for i in range(b):
                v = A[q[k, i], q[k, j]]
                work[i, j] = v
                work[i, b + j] = 1.0 if i == j else 0.0
                col += abs(v)
            norm_a = max(norm_a, col)
        for c in range(b):
            p = c
            for i in range(c + 1, b):
                if abs(work[i, c]) > abs(work[p, c]):
                    p = i
            if work[p, c] == 0.0:
                return np.inf
            if p != c:
                for j in range(2 * b):
                    work[c, j], work[p, j] = work[p, j], work[c, j]
            d = 1.0 / work[c, c]
            for j in range(2 * b):
                work[c, j] *= d
            for i in range(b):
                if i != c and work[i, c] != 0.0:
                    f = work[i, c]
                    for j in range(2 * b):
                        work[i, j] -= f * work[c, j]
        norm_inv = 0.0
        for j in range(b):
            col = 0.0
            for i in range(b):
                inv[k, i, j] = work[i, b + j]
                col += abs(work[i, b + j])
            norm_inv = max(norm_inv, col)
        worst = max(worst, norm_a * norm_inv)
        for i in range(m):
            for j in range(b):
                Acq[k, i, j] = A[coupled[k, i], q[k, j]]
        for i in range(b):
            for j in range(m):
                s = 0.0
                for l in range(b):
                    s += inv[k, i, l] * A[q[k, l], coupled[k, j]]
                X[k, i, j] = s
        for i in range(m):
            pi = pos[k, i]
            for j in range(m):
                s = 0.0
                for l in range(b):
                    s += Acq[k, i, l] * X[k, l, j]
                S[pi, pos[k, j]] -= s
    return worst


@njit(cache=True)
def _condensed_rhs(r, q, pos, exterior, inv, Acq):
    """yq = A_kk^-1 r_k per block and the exterior right-hand side r_e - sum_k A_ck yq_k."""
    nb, b = q.shape
    m = pos.shape[1]
    nr = r.shape[1]
    yq = np.zeros((nb, b, nr))
    be = np.empty((exterior.size, nr))
    for i in range(exterior.size):
        for c in range(nr):
            be[i, c] = r[exterior[i], c]
    for k in range(nb):
        for i in range(b):
            for l in range(b):
                v = inv[k, i, l]
                for c in range(nr):
                    yq[k, i, c] += v * r[q[k, l], c]
        for i in range(m):
            for l in range(b):
                v = Acq[k, i, l]
                for c in range(nr):
                    be[pos[k, i], c] -= v * yq[k, l, c]
    return yq, be


@njit(cache=True)
def _condensed_back(r, xe, yq, q, pos, exterior, X):
    """The full solution: exterior part xe, interior x_k = yq_k - X_k xe[coupled_k]."""
    nb, b = q.shape
    m = pos.shape[1]
    nr = r.shape[1]
    out = np.empty(r.shape)
    for i in range(exterior.size):
        for c in range(nr):
            out[exterior[i], c] = xe[i, c]
    for k in range(nb):
        for i in range(b):
            for c in range(nr):
                s = yq[k, i, c]
                for j in range(m):
                    s -= X[k, i, j] * xe[pos[k, j], c]
                out[q[k, i], c] = s
    return out
