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
complement, which keeps any border, is factorised densely. :class:`BlockRing` goes further for
a ring of such exteriors (the blades of a full disk assembly, each coupled to its two
neighbours through a damper): after the same condensation the blades' system is periodic
block-tridiagonal plus the border, and block LU down the ring factorises it in O(n) blades,
with the sign of det A for the continuation's orientation.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.linalg import get_lapack_funcs
from scipy.sparse.linalg import splu


_BLAS_CONTROLLER = None


def one_blas_thread(fn):
    """Run ``fn`` with the BLAS (OpenBLAS, MKL) limited to one thread, restored afterwards.

    The harmonic balance factorises many small dense matrices (70-300 unknowns per tuned
    sector): for these a threaded BLAS is slower, and far slower when the cores are shared
    (benchmarks/README.md, 'Moved from the package's docstrings', hbm/linsolve.py). The studies run
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


# LAPACK's LU (what scipy.linalg.lu_factor / lu_solve call, without their per-call dispatch:
# 20-40 us on the 9 x 9 bordered matrix of a one-DOF oscillator, more than the LU itself)
_GETRF, _GETRS = get_lapack_funcs(("getrf", "getrs"), dtype=np.float64)


class DenseLU:
    """``solve(b)`` of the LU factorisation of a dense matrix A (LAPACK ``getrf`` with partial
    pivoting, as ``scipy.linalg.lu_factor``, the same numbers), for b (N,) or (N, k).

    ``sign`` (+1 / -1) and ``logabsdet`` of det A come from the factors when asked (U's
    diagonal and the row swaps: no second factorisation, as ``np.linalg.slogdet`` would be).
    Raises ``np.linalg.LinAlgError`` if A is singular (a zero or
    non-finite pivot)."""

    def __init__(self, A):
        lu, piv, info = _GETRF(np.asarray(A, dtype=float))
        if info < 0:
            raise ValueError(f"illegal value in argument {-info} of LAPACK getrf")
        if info > 0 or not np.all(np.isfinite(lu)) or np.any(np.diag(lu) == 0):
            raise np.linalg.LinAlgError("singular matrix")
        self.lu, self.piv = lu, piv

    def __call__(self, b):
        x, info = _GETRS(self.lu, self.piv, np.asarray(b, dtype=float))
        if info != 0:
            raise ValueError(f"illegal value in argument {-info} of LAPACK getrs")
        return x

    @property
    def sign(self) -> int:
        swaps = np.count_nonzero(self.piv != np.arange(self.piv.size))
        return int(np.prod(np.sign(np.diag(self.lu))) * (-1.0) ** swaps)

    @property
    def logabsdet(self) -> float:
        return float(np.sum(np.log(np.abs(np.diag(self.lu)))))


def dense_array(matrix) -> np.ndarray:
    """``matrix`` as a 2-D float ndarray (a scipy.sparse matrix converted, a scalar or a list made
    an array): what a dense assembly of a system's matrices takes, whatever form they were given in."""
    return np.atleast_2d(matrix.toarray() if sp.issparse(matrix) else np.asarray(matrix, dtype=float))


def factorize(A):
    """LU factorisation of a dense ndarray (:class:`DenseLU`, which also gives the sign of det A)
    or a scipy.sparse matrix (sparse LU, COLAMD ordering); returns ``solve(b)`` for one or
    several right-hand sides (columns of b). Raises ``np.linalg.LinAlgError`` (dense) or
    ``RuntimeError`` (sparse) if A is singular."""
    if sp.issparse(A):
        lu = splu(sp.csc_matrix(A))
        return lambda b: lu.solve(np.asarray(b, dtype=float))
    return DenseLU(A)


# Dense or sparse Jacobian (HarmonicBalanceSystem.storage "auto"): sparse from SPARSE_MIN_UNKNOWNS
# unknowns on where at most SPARSE_MAX_FILL of its entries are nonzero. The crossover of one Newton
# iteration (residual with Jacobian, LU, solve; benchmarks/bench_sparse_crossover.py and
# benchmarks/README.md, 'Dense or sparse Jacobian: the crossover'): rings of 2-64 sectors with point
# contacts between them and the reference disk's full assembly turn from dense to sparse between
# 170-280 unknowns (dense 1.7-2.8x faster) and 320-340 (equal to 1.7x slower); the LU alone of a
# matrix of fill 0.375 is no faster sparse up to 2400 unknowns, one of fill 0.2 from 300 on.
SPARSE_MIN_UNKNOWNS = 300
SPARSE_MAX_FILL = 0.3


def prefers_sparse(n_unknowns: int, nonzeros: int) -> bool:
    """Whether a square Jacobian of ``n_unknowns`` rows with ``nonzeros`` nonzero entries is
    assembled and factorised faster as a scipy.sparse matrix than as a dense one: at least
    SPARSE_MIN_UNKNOWNS unknowns and a fill ``nonzeros / n_unknowns**2`` of at most
    SPARSE_MAX_FILL (the measured crossover, see there). Raises ValueError for a negative
    ``n_unknowns`` or ``nonzeros`` outside [0, n_unknowns**2]."""
    n, nnz = int(n_unknowns), int(nonzeros)
    if n < 0:
        raise ValueError(f"n_unknowns must be >= 0 (got {n_unknowns})")
    if not 0 <= nnz <= n * n:
        raise ValueError(f"nonzeros must be in [0, n_unknowns**2] = [0, {n * n}] (got {nonzeros})")
    return n >= SPARSE_MIN_UNKNOWNS and nnz <= SPARSE_MAX_FILL * n * n


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


def _lu_signed(A):
    """:func:`factorize` whose ``solve`` also carries ``sign`` and ``logabsdet`` of det A (from the
    LU factors: :class:`DenseLU`, or ``splu``'s U diagonal and row / column permutations) and
    ``method = "lu"``. Raises as :func:`factorize` if A is singular."""
    if not sp.issparse(A):
        solve = DenseLU(A)
        solve.method = "lu"
        return solve
    lu = splu(sp.csc_matrix(A))
    d = lu.U.diagonal()

    def solve(b):
        return lu.solve(np.asarray(b, dtype=float))
    solve.sign = int(np.prod(np.sign(d)) * permutation_sign(lu.perm_r.astype(np.intp)) *
                     permutation_sign(lu.perm_c.astype(np.intp)))
    solve.logabsdet = float(np.sum(np.log(np.abs(d))))
    solve.method = "lu"
    return solve


@njit(cache=True)
def permutation_sign(perm) -> int:
    """Sign (+1 / -1) of the permutation ``perm`` (an arrangement of 0..n-1), by its cycles. The
    package passes np.intp arrays (one compiled signature; scipy's LU permutations are int32)."""
    n = perm.size
    seen = np.zeros(n, dtype=np.bool_)
    sign = 1
    for i in range(n):
        if seen[i]:
            continue
        j, length = i, 0
        while not seen[j]:
            seen[j] = True
            j = perm[j]
            length += 1
        if length % 2 == 0:
            sign = -sign
    return sign


@dataclass
class BlockRing:
    """O(n) factorisation of a ring of blocks (a callable like :func:`factorize`): a periodic
    block-tridiagonal matrix whose unknowns may include interior blocks, each coupled to two
    neighbouring ring blocks, and one border row and column (the arc-length corrector).

    The system this is for: the full assembly of a mistuned disk, ring block k = blade k's
    modal coordinates (all harmonics), interior block j = the damper between blades
    ``links[j]`` and ``links[j] + 1`` (mod n). The damper's equations hold only its own
    coordinates and those two blades'; a blade's only its own, its two dampers' and the
    border's. Dense LU of the damper-condensed system costs O(n^3), and sparse LU of the bordered
    matrix is no better (the border and the ring's closing corners fill it in); this is linear
    in n (timings: benchmarks/README.md, 'Moved from the package's docstrings', hbm/linsolve.py).

    Parameters
    ----------
    groups : (n, b) int, the unknowns of each ring block in ring order, n >= 2: block k couples
        to blocks k - 1 and k + 1 (mod n; for n = 2 both are the other block)
    interior : (m, q) int or None, the unknowns of each interior block
    links : (m,) int, interior block j couples to ring blocks links[j] and links[j] + 1 (mod n)
    size : unknowns of the system (default: every index of groups and interior, which must
        cover 0..size-1 exactly once). A matrix of size + 1 is bordered: its last row and
        column may couple to every unknown.
    max_condition : a block (interior, or ring pivot) whose 1-norm condition number exceeds
        this sends the matrix to plain LU (also when the sparse pattern leaves the ring).

    Calling it with a square A (dense ndarray or scipy.sparse, size or size + 1) returns
    ``solve(rhs)`` for rhs of shape (N,) or (N, k); ``solve.sign`` (+1 / -1) and
    ``solve.logabsdet`` are the sign and log |det A| of the matrix factorised (exact, from
    the block pivots, no extra work), ``solve.method`` is "ring" (or "lu" for the fallback,
    which also gives them). A singular matrix raises ``np.linalg.LinAlgError``.

    Algorithm (every block operation dense and small: b x b, q x q, or their couplings):

    0. Gather the blocks (:meth:`blocks`): batched numpy fancy indexing of a dense A (O(n b^2)
       reads, the rest of A is not touched), one numba pass over the entries of a sparse one.
    1. Interior blocks (numba, one pass over j): with the coupled unknowns c_j = (ring block
       a = links[j], ring block a + 1, border), LU of A_jj (partial pivoting), X_j = A_jj^-1 A_jc,
       and the Schur complement A_cj X_j subtracted from the ring blocks D_a, D_{a+1}, A[a, a+1],
       A[a+1, a] and the border. det A = prod_j det A_jj * det(condensed ring).
    2. The condensed ring with the border is ordered as blocks 0..n-2, then Z = (block n-1,
       border), of size z = b + 1: a block-tridiagonal chain with an arrowhead Z, since the
       corners A[0, n-1], A[n-1, 0] and the border lie in the arrow. Block LU (block Thomas)
       down the chain (numba, sequential), k = 0..n-2:
           P_k = D_k - A[k, k-1] P_{k-1}^-1 A[k-1, k]                       (b x b pivot)
           E_k = A[k, Z] - A[k, k-1] P_{k-1}^-1 E_{k-1}                    (b x z)
           F_k = A[Z, k] - F_{k-1} P_{k-1}^-1 A[k-1, k]                    (z x b)
           Z  -= F_k P_k^-1 E_k
       each P_k by LU with partial pivoting, then Z (z x z) by LU with partial pivoting. The
       corner blocks enter through E_0 and F_0, and Z is the exact rank-(b + 1) Schur
       (Sherman-Morrison-Woodbury) correction that closes the ring and adds the border: the
       open chain 0..n-2 is eliminated once, with its coupling to the last block and the border
       carried along. det A = prod det A_jj * prod det P_k * det Z (a symmetric reordering
       leaves det A unchanged); forward and back substitution follow the same recurrences.
    3. Stability: the border is not eliminated after J (Keller's bordering, which fails where J
       is singular at a fold of the branch while the bordered matrix is regular): the singular
       direction of J ends up in Z, factorised together with the border with partial pivoting,
       as a dense LU would. The chain pivots P_k are Schur complements of an open chain of
       damped blades (regular); their 1-norm condition numbers and those of the A_jj (Hager's
       estimate from the LU) are checked against ``max_condition``.

    Shapes: n ring blocks of b unknowns, m interior blocks of q, z = b + 1. Factors kept: the LU
    of the A_jj (m, q, q), X (m, q, 2b + 1), A_cj (m, 2b + 1, q); the LU of the P_k (n-1, b, b),
    P_k^-1 A[k, k+1] (n-1, b, b), P_k^-1 E_k (n-1, b, z), F_k (n-1, z, b), A[k+1, k] (n, b, b), Z.
    Cost: O(n (b^3 + q^3 + q^2 b)) to factorise, O(n (b^2 + q^2 + q b)) per right-hand side,
    memory O(n (b^2 + q^2 + q b)).
    """

    groups: np.ndarray
    interior: np.ndarray | None = None
    links: np.ndarray | None = None
    size: int | None = None
    max_condition: float = 1e12

    def __post_init__(self):
        self.groups = np.atleast_2d(np.asarray(self.groups, dtype=np.intp))
        n, b = self.groups.shape
        if n < 2:
            raise ValueError(f"a ring needs at least 2 blocks (got {n})")
        if self.interior is None or np.size(self.interior) == 0:
            self.interior = np.zeros((0, 0), dtype=np.intp)
            self.links = np.zeros(0, dtype=np.intp)
        self.interior = np.atleast_2d(np.asarray(self.interior, dtype=np.intp))
        self.links = np.atleast_1d(np.asarray(self.links, dtype=np.intp))
        m = self.interior.shape[0]
        if self.links.shape != (m,):
            raise ValueError(f"links must have one entry per interior block ({m}), got shape {self.links.shape}")
        if m and (self.links.min() < 0 or self.links.max() >= n):
            raise ValueError(f"links must be ring blocks in [0, {n})")
        flat = np.concatenate([self.groups.ravel(), self.interior.ravel()])
        if self.size is None:
            self.size = int(flat.size)
        if flat.size != self.size or np.unique(flat).size != flat.size or flat.min() < 0 or flat.max() >= self.size:
            raise ValueError(f"groups and interior must hold every unknown 0..{self.size - 1} exactly once")
        owner = np.empty(self.size + 1, dtype=np.intp)
        local = np.empty(self.size + 1, dtype=np.intp)
        owner[self.groups] = np.arange(n)[:, None]
        local[self.groups] = np.arange(b)[None, :]
        if m:
            owner[self.interior] = n + np.arange(m)[:, None]
            local[self.interior] = np.arange(self.interior.shape[1])[None, :]
        owner[self.size], local[self.size] = -1, 0
        self._owner, self._local = owner, local
        self._next = (np.arange(n) + 1) % n
        # the unknowns each interior block couples to: ring blocks a and a + 1
        self._coupled = np.hstack([self.groups[self.links], self.groups[self._next[self.links]]]) if m else None

    # ----- the blocks of A ----------------------------------------------------------------
    def blocks(self, A):
        """The blocks of A (dense or sparse, size or size + 1): ``(bordered, D, Up, Lo, col,
        row, corner, Aqq, Aqc, Acq)`` with D[k] = A[k, k], Up[k] = A[k, k+1], Lo[k] = A[k+1, k]
        (ring blocks, mod n; for n = 2 the two couplings are in Up only), col / row (n, b) the
        border's column and row, corner its diagonal (1 if not bordered), and per interior
        block j: Aqq (m, q, q), Aqc (m, q, 2b + 1), Acq (m, 2b + 1, q) against (ring block
        links[j], ring block links[j] + 1, border). None if a sparse A has entries off the ring."""
        N = A.shape[0]
        if A.shape != (N, N) or N not in (self.size, self.size + 1):
            raise ValueError(f"matrix of shape {A.shape} is neither the system size {self.size} "
                             f"nor bordered ({self.size + 1})")
        bordered = N == self.size + 1
        g, nxt, q = self.groups, self._next, self.interior
        n, b = g.shape
        m, nq = q.shape
        if sp.issparse(A):
            A = A if sp.isspmatrix_csc(A) else sp.csc_matrix(A)
            shapes = ((n, b, b), (n, b, b), (n, b, b), (n, b), (n, b), (1,), (m, nq, nq), (m, nq, 2 * b + 1),
                      (m, 2 * b + 1, nq))
            # where each stored entry of the pattern goes in the blocks (flat), formed once per
            # pattern: a system's Jacobians share their index arrays, and so do their bordered
            # copies (continuation.bordered_matrix); the last two patterns are kept (the
            # Jacobian's and its bordered one's). One read and one write of the slot: a ring may
            # be shared by threads
            known = self.__dict__.get("_gather", ())
            last = next((g for g in known if g[0] is A.indices and g[1] is A.indptr), None)
            if last is None:
                sizes = [int(np.prod(shape)) for shape in shapes]
                offsets = np.concatenate([[0], np.cumsum(sizes)])
                views = [np.arange(offsets[k], offsets[k + 1]).reshape(shape).astype(float)
                         for k, shape in enumerate(shapes)]
                slots = np.full(A.indices.size, -1.0)
                _ring_slots(A.indices, A.indptr, self._owner, self._local, self.links, *views, slots)
                last = (A.indices, A.indptr, slots.astype(np.int64), offsets)
                self._gather = (last,) + tuple(known[:1])
            _, _, slots, offsets = last
            flat = np.zeros(offsets[-1])
            if not _ring_scatter(np.asarray(A.data, dtype=float), slots, flat):
                return None
            D, Up, Lo, col, row, corner, Aqq, Aqc, Acq = (flat[offsets[k]:offsets[k + 1]].reshape(shape)
                                                          for k, shape in enumerate(shapes))
            corner = corner[0] if bordered else 1.0
            return bordered, D, Up, Lo, col, row, corner, Aqq, Aqc, Acq
        A = np.asarray(A, dtype=float)
        D = A[g[:, :, None], g[:, None, :]]
        Up = A[g[:, :, None], g[nxt][:, None, :]]
        Lo = A[g[nxt][:, :, None], g[:, None, :]] if n > 2 else np.zeros((n, b, b))
        Aqq = A[q[:, :, None], q[:, None, :]]
        Aqc = np.zeros((m, nq, 2 * b + 1))
        Acq = np.zeros((m, 2 * b + 1, nq))
        if m:
            c = self._coupled
            Aqc[:, :, :2 * b] = A[q[:, :, None], c[:, None, :]]
            Acq[:, :2 * b, :] = A[c[:, :, None], q[:, None, :]]
        if bordered:
            s = self.size
            col, row, corner = A[g, s], A[s, g], float(A[s, s])
            if m:
                Aqc[:, :, 2 * b] = A[q, s]
                Acq[:, 2 * b, :] = A[s, q]
        else:
            col, row, corner = np.zeros((n, b)), np.zeros((n, b)), 1.0
        return bordered, D, Up, Lo, col, row, corner, Aqq, Aqc, Acq

    def __call__(self, A):
        parts = self.blocks(A)
        if parts is None:
            return _lu_signed(A)
        bordered, D, Up, Lo, col, row, corner, Aqq, Aqc, Acq = parts
        n, b = self.groups.shape
        m, nq = self.interior.shape
        # 1. interior blocks: LU, determinant, condition, Schur complement onto the ring
        qpiv, X = np.empty((m, nq), dtype=np.intp), np.empty((m, nq, 2 * b + 1))
        s_q, l_q, worst_q, d_corner = _ring_condense(Aqq, Aqc, Acq, self.links, D, Up, Lo, col, row, qpiv, X)
        if not np.isfinite(worst_q) or worst_q > self.max_condition:
            return _lu_signed(A)
        # 2. block LU of the chain 0..n-2 with the arrowhead Z = (block n-1, border)
        z = b + 1
        P, ppiv, Xc = np.empty((n - 1, b, b)), np.empty((n - 1, b), dtype=np.intp), np.empty((n - 1, b, b))
        Y, F = np.empty((n - 1, b, z)), np.empty((n - 1, z, b))
        Z, zpiv = np.empty((z, z)), np.empty(z, dtype=np.intp)
        s_r, l_r, worst = _ring_factor(D, Up, Lo, col, row, float(corner) - d_corner, P, ppiv, Xc, Y, F, Z, zpiv)
        if not np.isfinite(worst) or worst > self.max_condition:
            return _lu_signed(A)
        if s_r == 0:
            raise np.linalg.LinAlgError("singular matrix")
        groups, interior, links, size = self.groups, self.interior, self.links, self.size
        N = size + 1 if bordered else size

        def solve(rhs):
            rhs = np.asarray(rhs, dtype=float)
            if rhs.shape[0] != N:
                raise ValueError(f"right-hand side has {rhs.shape[0]} rows, the matrix {N}")
            r = np.ascontiguousarray(rhs.reshape(N, -1))
            out = np.empty(r.shape)
            _ring_substitute(Aqq, qpiv, X, Acq, links, groups, interior, size, bordered,
                             P, ppiv, Xc, Y, F, Lo, Z, zpiv, r, out)
            return out.reshape(rhs.shape)

        solve.sign = int(s_q * s_r)
        solve.logabsdet = float(l_q + l_r)
        solve.method = "ring"
        return solve


@njit(cache=True)
def _ring_slots(indices, indptr, owner, local, links, D, Up, Lo, col, row, corner, Aqq, Aqc, Acq, slots):
    """Where each stored entry p of a CSC pattern (``indices``, ``indptr``) goes in the blocks of
    :meth:`BlockRing.blocks` (owner: ring block 0..n-1, interior block n + j, or -1 for the
    border; local: the index within it): ``slots[p]`` (float, -1 on entry) is set to the value
    the block arrays D ... Acq hold at that place, their own positions in one flat buffer;
    entries off the ring's pattern keep -1. The map of :func:`_ring_scatter`."""
    n, b = D.shape[0], D.shape[1]
    for j in range(indptr.size - 1):
        oj, lj = owner[j], local[j]
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            oi, li = owner[i], local[i]
            if oi >= 0 and oi < n:
                if oj >= 0 and oj < n:
                    if oi == oj:
                        slots[p] = D[oi, li, lj]
                    elif oj == (oi + 1) % n:
                        slots[p] = Up[oi, li, lj]
                    elif oi == (oj + 1) % n:
                        slots[p] = Lo[oj, li, lj]
                elif oj < 0:
                    slots[p] = col[oi, li]
                else:
                    a = links[oj - n]
                    if oi == a:
                        slots[p] = Acq[oj - n, li, lj]
                    elif oi == (a + 1) % n:
                        slots[p] = Acq[oj - n, b + li, lj]
            elif oi < 0:
                if oj < 0:
                    slots[p] = corner[0]
                elif oj < n:
                    slots[p] = row[oj, lj]
                else:
                    slots[p] = Acq[oj - n, 2 * b, lj]
            else:
                k = oi - n
                if oj >= n:
                    if oj != oi:
                        continue
                    slots[p] = Aqq[k, li, lj]
                elif oj < 0:
                    slots[p] = Aqc[k, li, 2 * b]
                else:
                    a = links[k]
                    if oj == a:
                        slots[p] = Aqc[k, li, lj]
                    elif oj == (a + 1) % n:
                        slots[p] = Aqc[k, li, b + lj]


@njit(cache=True)
def _ring_scatter(data, slots, flat):
    """flat[slots[p]] += data[p] over the stored entries p of a CSC matrix in order (the sums of
    :func:`_ring_slots`' places, in the order of the entries), skipping zeros; False if a nonzero entry has no
    slot (-1: off the ring's pattern)."""
    for p in range(data.size):
        v = data[p]
        if v == 0.0:
            continue
        k = slots[p]
        if k < 0:
            return False
        flat[k] += v
    return True


@njit(cache=True)
def copy_matrix(source, target):
    """target[:, :] = source (2D, the same shape, not checked) by explicit loops: numba's array
    assignment compiles a shape check whose error message (string formatting) cost about 5 s of
    CPU time on a cold cache (benchmarks/README.md, 'Start-up and the numba compile cost')."""
    for i in range(source.shape[0]):
        for j in range(source.shape[1]):
            target[i, j] = source[i, j]


@njit(cache=True)
def mm_subtract(A, B, C):
    """C -= A @ B (2D, in place; C shares no memory with A or B). Each C[i, j] has a_il b_lj
    subtracted in the order of l; with one column (the solves' right-hand sides) in a register
    rather than in memory, which the compiler cannot do itself (C might overlap B): the same
    numbers; a solve of the 16-blade disk's bordered Jacobian (n = 321) 13.5 against 29 us."""
    if B.shape[1] == 1:
        for i in range(A.shape[0]):
            s = C[i, 0]
            for l in range(A.shape[1]):
                s -= A[i, l] * B[l, 0]
            C[i, 0] = s
        return
    for i in range(A.shape[0]):
        for l in range(A.shape[1]):
            a = A[i, l]
            for j in range(B.shape[1]):
                C[i, j] -= a * B[l, j]


@njit(cache=True)
def lu_factor_inplace(W, piv):
    """In-place LU with partial pivoting of the square W (LAPACK getrf layout: unit L below the
    diagonal, U on and above, row swaps piv[c] <-> c in order). Returns (sign of det, log |det|,
    1-norm of W before); sign 0 if a pivot is zero or not finite."""
    q = W.shape[0]
    norm = 0.0
    for j in range(q):
        s = 0.0
        for i in range(q):
            s += abs(W[i, j])
        norm = max(norm, s)
    sign, logdet = 1.0, 0.0
    for c in range(q):
        p = c
        for i in range(c + 1, q):
            if abs(W[i, c]) > abs(W[p, c]):
                p = i
        piv[c] = p
        pivot = W[p, c]
        if pivot == 0.0 or not np.isfinite(pivot):
            return 0.0, -np.inf, norm
        if p != c:
            sign = -sign
            for j in range(q):
                W[c, j], W[p, j] = W[p, j], W[c, j]
        if pivot < 0:
            sign = -sign
        logdet += np.log(abs(pivot))
        d = 1.0 / pivot
        for i in range(c + 1, q):
            f = W[i, c] * d
            W[i, c] = f
            for j in range(c + 1, q):
                W[i, j] -= f * W[c, j]
    return sign, logdet, norm


@njit(cache=True)
def lu_solve_inplace(W, piv, B):
    """B <- W^-1 B in place (B: (q, k)) with the factors of :func:`lu_factor_inplace`. One column (k = 1) is
    substituted with each row's sum in a register (as :func:`mm_subtract`; the same numbers)."""
    q, k = B.shape
    for c in range(q):
        p = piv[c]
        if p != c:
            for j in range(k):
                B[c, j], B[p, j] = B[p, j], B[c, j]
    if k == 1:
        for i in range(q):
            s = B[i, 0]
            for l in range(i):
                s -= W[i, l] * B[l, 0]
            B[i, 0] = s
        for i in range(q - 1, -1, -1):
            s = B[i, 0]
            for l in range(i + 1, q):
                s -= W[i, l] * B[l, 0]
            B[i, 0] = s * (1.0 / W[i, i])
        return
    for i in range(q):
        for l in range(i):
            f = W[i, l]
            for j in range(k):
                B[i, j] -= f * B[l, j]
    for i in range(q - 1, -1, -1):
        for l in range(i + 1, q):
            f = W[i, l]
            for j in range(k):
                B[i, j] -= f * B[l, j]
        d = 1.0 / W[i, i]
        for j in range(k):
            B[i, j] *= d


@njit(cache=True)
def lu_solve_transposed_inplace(W, piv, x):
    """x <- W^-T x in place (x: (q,)) with the factors of :func:`lu_factor_inplace` (each row's sum in a
    register, as :func:`lu_solve_inplace`)."""
    q = x.size
    for i in range(q):
        s = x[i]
        for l in range(i):
            s -= W[l, i] * x[l]
        x[i] = s / W[i, i]
    for i in range(q - 1, -1, -1):
        s = x[i]
        for l in range(i + 1, q):
            s -= W[l, i] * x[l]
        x[i] = s
    for c in range(q - 1, -1, -1):
        p = piv[c]
        if p != c:
            x[c], x[p] = x[p], x[c]


@njit(cache=True)
def _inverse_norm1(W, piv):
    """Estimate of ||W^-1||_1 from the factors of :func:`lu_factor_inplace` (Hager's method, two steps as
    LAPACK's dlacon starts: a lower bound, in practice within a small factor)."""
    q = W.shape[0]
    y = np.full((q, 1), 1.0 / q)
    lu_solve_inplace(W, piv, y)
    est = 0.0
    xi = np.empty(q)
    for i in range(q):
        est += abs(y[i, 0])
        xi[i] = 1.0 if y[i, 0] >= 0 else -1.0
    lu_solve_transposed_inplace(W, piv, xi)
    j = 0
    for i in range(q):
        if abs(xi[i]) > abs(xi[j]):
            j = i
    e = np.zeros((q, 1))
    e[j, 0] = 1.0
    lu_solve_inplace(W, piv, e)
    s = 0.0
    for i in range(q):
        s += abs(e[i, 0])
    return max(est, s)


@njit(cache=True)
def _ring_condense(Aqq, Aqc, Acq, links, D, Up, Lo, col, row, qpiv, X):
    """Step 1 of :class:`BlockRing`: Aqq[j] <- its LU (pivots qpiv[j]), X[j] = Aqq[j]^-1 Aqc[j],
    and the Schur complement Acq[j] X[j] subtracted from the ring blocks of links[j],
    links[j] + 1 and the border. Returns (sign of prod det Aqq, log |prod det Aqq|, largest
    1-norm condition number (estimate), the border's diagonal to subtract); condition inf if a
    block is singular."""
    m = Aqq.shape[0]
    n, b = D.shape[0], D.shape[1]
    c2 = 2 * b + 1
    S = np.empty((c2, c2))
    sign, logdet, worst, d_corner = 1.0, 0.0, 0.0, 0.0
    for j in range(m):
        s, l, norm = lu_factor_inplace(Aqq[j], qpiv[j])
        if s == 0.0:
            return 0.0, -np.inf, np.inf, 0.0
        sign *= s
        logdet += l
        worst = max(worst, norm * _inverse_norm1(Aqq[j], qpiv[j]))
        copy_matrix(Aqc[j], X[j])
        lu_solve_inplace(Aqq[j], qpiv[j], X[j])
        S[:] = 0.0
        mm_subtract(Acq[j], X[j], S)                 # S = -Acq X
        a = links[j]
        a1 = (a + 1) % n
        for i in range(b):
            for k in range(b):
                D[a, i, k] += S[i, k]
                D[a1, i, k] += S[b + i, b + k]
                Up[a, i, k] += S[i, b + k]
                Lo[a, i, k] += S[b + i, k]
            col[a, i] += S[i, 2 * b]
            col[a1, i] += S[b + i, 2 * b]
            row[a, i] += S[2 * b, i]
            row[a1, i] += S[2 * b, b + i]
        d_corner -= S[2 * b, 2 * b]
    return sign, logdet, worst, d_corner


@njit(cache=True)
def _ring_factor(D, Up, Lo, col, row, corner, P, ppiv, X, Y, F, Z, zpiv):
    """Block LU of the condensed ring (see :class:`BlockRing`, step 2). Fills P[k] with the LU
    of the pivot P_k (pivots ppiv[k]), X[k] = P_k^-1 A[k, k+1] (k < n-2), Y[k] = P_k^-1 E_k,
    F[k] = F_k and Z with its LU (pivots zpiv). Returns (sign of det, log |det|, largest
    condition number of the P_k (estimate)); sign 0 if Z is singular, condition inf if a P_k is."""
    n, b = D.shape[0], D.shape[1]
    for i in range(b):
        for j in range(b):
            Z[i, j] = D[n - 1, i, j]
        Z[i, b] = col[n - 1, i]
        Z[b, i] = row[n - 1, i]
    Z[b, b] = corner
    sign, logdet, worst = 1.0, 0.0, 0.0
    for k in range(n - 1):
        Fk, E, Pk = F[k], Y[k], P[k]
        E[:] = 0.0
        Fk[:] = 0.0
        if k == n - 2:
            for i in range(b):
                for j in range(b):
                    E[i, j] += Up[k, i, j]
                    Fk[i, j] += Lo[k, i, j]
        if k == 0:
            for i in range(b):
                for j in range(b):
                    E[i, j] += Lo[n - 1, i, j]
                    Fk[i, j] += Up[n - 1, i, j]
        for i in range(b):
            E[i, b] = col[k, i]
            Fk[b, i] = row[k, i]
        copy_matrix(D[k], Pk)
        if k > 0:
            mm_subtract(Lo[k - 1], X[k - 1], Pk)
            mm_subtract(Lo[k - 1], Y[k - 1], E)
            mm_subtract(F[k - 1], X[k - 1], Fk)
        s, l, norm = lu_factor_inplace(Pk, ppiv[k])
        if s == 0.0:
            return 0.0, -np.inf, np.inf
        sign *= s
        logdet += l
        worst = max(worst, norm * _inverse_norm1(Pk, ppiv[k]))
        lu_solve_inplace(Pk, ppiv[k], E)                   # Y[k] = P_k^-1 E_k
        if k < n - 2:
            copy_matrix(Up[k], X[k])
            lu_solve_inplace(Pk, ppiv[k], X[k])
        mm_subtract(Fk, E, Z)
    s, l, _ = lu_factor_inplace(Z, zpiv)
    if s == 0.0:
        return 0.0, -np.inf, worst
    return sign * s, logdet + l, worst


@njit(cache=True)
def _ring_substitute(Qlu, qpiv, X, Acq, links, groups, interior, size, bordered, P, ppiv, Xc, Y, F, Lo, Z, zpiv,
                     r, out):
    """Solve with the factors of :class:`BlockRing` for the right-hand sides r (N, nr) into out:
    interior blocks condensed (yq = Aqq^-1 r_q, ring rhs -= Acq yq), the ring by forward and
    back substitution down the chain and through Z, then the interior unknowns x_q = yq - X x_c."""
    n, b = groups.shape
    m, nq = interior.shape
    nr = r.shape[1]
    z = b + 1
    xr = np.empty((n, b, nr))                      # the ring's right-hand side, then its solution
    for k in range(n):
        for i in range(b):
            for c in range(nr):
                xr[k, i, c] = r[groups[k, i], c]
    gz = np.zeros((z, nr))                          # Z's right-hand side: block n-1 and border
    if bordered:
        for c in range(nr):
            gz[b, c] = r[size, c]
    yq = np.empty((m, nq, nr))
    t = np.empty((2 * b + 1, nr))
    for j in range(m):
        for i in range(nq):
            for c in range(nr):
                yq[j, i, c] = r[interior[j, i], c]
        lu_solve_inplace(Qlu[j], qpiv[j], yq[j])
        t[:] = 0.0
        mm_subtract(Acq[j], yq[j], t)                    # t = -Acq yq
        a = links[j]
        a1 = (a + 1) % n
        for i in range(b):
            for c in range(nr):
                xr[a, i, c] += t[i, c]
                xr[a1, i, c] += t[b + i, c]
        for c in range(nr):
            gz[b, c] += t[2 * b, c]
    for i in range(b):
        for c in range(nr):
            gz[i, c] += xr[n - 1, i, c]
    for k in range(n - 1):                          # forward: w_k = P_k^-1 (r_k - A[k, k-1] w_{k-1})
        if k > 0:
            mm_subtract(Lo[k - 1], xr[k - 1], xr[k])
        lu_solve_inplace(P[k], ppiv[k], xr[k])
        mm_subtract(F[k], xr[k], gz)
    lu_solve_inplace(Z, zpiv, gz)
    for i in range(b):
        for c in range(nr):
            xr[n - 1, i, c] = gz[i, c]
    for k in range(n - 2, -1, -1):                  # back: x_k = w_k - Y_k x_Z - X_k x_{k+1}
        mm_subtract(Y[k], gz, xr[k])
        if k < n - 2:
            mm_subtract(Xc[k], xr[k + 1], xr[k])
    for k in range(n):
        for i in range(b):
            for c in range(nr):
                out[groups[k, i], c] = xr[k, i, c]
    if bordered:
        for c in range(nr):
            out[size, c] = gz[b, c]
    for j in range(m):
        a = links[j]
        a1 = (a + 1) % n
        for i in range(nq):
            for c in range(nr):
                v = yq[j, i, c]
                for l in range(b):
                    v -= X[j, i, l] * xr[a, l, c] + X[j, i, b + l] * xr[a1, l, c]
                v -= X[j, i, 2 * b] * gz[b, c]
                out[interior[j, i], c] = v
