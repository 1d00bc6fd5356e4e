"""Mistuned bladed disk: the full assembly of n blades and n dampers (Eq. 16-20).

Every blade has its own :class:`~bladedamp.blade.ModalBlade` (natural frequencies, modal
damping, optionally mode shapes) and every damper its own mass, friction coefficient and
geometry (the paper's "contact mistuning"). Unknowns, harmonic-major as everywhere in
:mod:`bladedamp.hbm`: the modal coordinates of blade 0, 1, ..., n-1, then the six rigid-body
coordinates of each damper that has a mass. Damper k sits between blade k (its OL platform)
and blade k+1 (that blade's OR platform), exactly as in :class:`~bladedamp.disk.TunedDisk`;
each position is described by its :class:`~bladedamp.diskmodel.DamperPosition` (damper, platform
angles, gaps, the preload law: geometry, ``platform_offsets``, ``G_P``, ``G_D``, seating / static
approach, centrifugal force), the same description as the tuned disk's one position, and the
shared behaviour is :class:`~bladedamp.diskmodel.DiskModel`'s, so a tuned MistunedDisk is the
TunedDisk written out blade by blade.

Engine-order excitation: blade k's first-harmonic force is f e^{i k dphi}, dphi = 2 pi EO / n,
so that the tuned solution is blade 0's cyclic solution with harmonic h of blade k turned by
e^{i h k dphi} (Eq. 24, 25).

Cyclic sectors of several blades: with ``len(blades) = s`` dividing ``n_blades`` the model is
one sector of s blades of a disk that repeats it n/s times; the last damper then couples
blade s-1 to blade 0 of the next sector, whose harmonic h is blade 0's times e^{i h s dphi}.
``s = n`` is the full assembly (e^{i h n dphi} = 1), ``s = 1`` the tuned disk, ``s = 2`` the
paper's alternating mistuning (case d).

Time sampling (AFT): the contact forces are evaluated at ``n_samples`` instants per period, and
in a tuned travelling wave blade k's motion is blade 0's shifted by k dphi; the discrete friction
laws are shift-invariant only when that shift is a whole number of samples. Each damper is
therefore sampled on its own grid, shifted by its phase k dphi (a rotation of its harmonic
coefficients before the AFT and back after it, :meth:`~bladedamp.diskmodel.AssemblyContacts.grid_rotations`;
nothing to do where the shift is whole samples, n = 16 and EO = 1 at 64 samples): a tuned full
assembly equals the cyclic solution to rounding at any ``n_samples``, and the default is the
tuned disk's (64 for one harmonic at any n; before, it was rounded up to a multiple of
n / gcd(n, EO), T = n above 64 blades, which made the contact kernel's cost grow as n^2). A branch
that fails its checks with the default is solved once more with ``AUTO_SAMPLES_GROWTH`` times
the samples, as the tuned disk's (:func:`bladedamp.response.sampled_response`).

The Jacobian is sparse (each damper couples two neighbours): the structural matrices and
the contact map are scipy.sparse matrices (the Jacobian itself dense up to
``AssemblySystem.ring_dense_limit`` unknowns with the ring solver, the default, and up to
``AssemblySystem.dense_limit`` with the others). The continuation factorises it, and its bordered
form, with :class:`~bladedamp.hbm.linsolve.BlockRing`: the damper coordinates condensed, then
block LU around the ring of blades, O(n) in the blades (``AssemblySystem.linear_solver``;
"condensation" is the former dense-condensation / sparse-LU path). The contact points of all
dampers are evaluated in one call of the point-contact kernel when the dampers share their
normal law (always for frequency or mass mistuning), otherwise damper by damper.
"""
from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field
from typing import ClassVar, Sequence

import numpy as np
import scipy.sparse as sp
from numba import njit

from . import validation
from .blade import PLATFORM_ANGLE, ModalBlade
from .diskmodel import (DAMPER_DOFS, DEFAULT_DAMPER_RADIUS, AssemblyContacts, DamperPosition, DiskModel,
                        DiskModelResponse, check_blade_bounded, contact_rows, peak_checked_response, rest_response,
                        rotor_speed_in_hz, with_stop_check)
from .frf import branch_solver, checked_range
from .hbm.accuracy import HARMONIC_TOLERANCE
from .hbm.continuation import DEFAULT_CPU_BUDGET_S, DEFAULT_MAX_STEP, DEFAULT_POINT_BUDGET, Branch, continuation
from .hbm.linsolve import BlockCondensation, BlockRing, one_blas_thread
from .hbm.linsolve import factorize as lu_factorize
from .hbm.peaks import PEAK_MAX_ITERATIONS, PeakSolver, first_harmonic_output
from .hbm.fourier import HarmonicBasis
from .hbm.system import Coupling, HarmonicBalanceSystem
from .response import continuation_note, refined_peak


def sparse_real_form(basis: HarmonicBasis, per_harmonic) -> sp.csr_matrix:
    """Sparse version of :meth:`HarmonicBasis.real_form`: ``per_harmonic(h)`` returns a complex
    scipy.sparse (or dense) (n_out, n_in) matrix; block [[Gr, Gi], [-Gi, Gr]] per harmonic."""
    blocks = {h: sp.coo_matrix(per_harmonic(h)) for h in basis.harmonics}
    n_out, n_in = blocks[basis.harmonics[0]].shape
    C = basis.n_coeffs
    rows, cols, vals = [], [], []
    for h, g in blocks.items():
        j = basis.cos_index(h)
        r, c, v = g.row, g.col, g.data
        gr, gi = np.real(v), np.imag(v)
        if h == 0:
            if np.any(np.abs(gi) > 1e-12 * (1 + np.abs(v).max(initial=0.0))):
                raise ValueError("the static (h = 0) block of a linear map must be real")
            rows.append(j * n_out + r), cols.append(j * n_in + c), vals.append(gr)
            continue
        for dr, dc, val in ((0, 0, gr), (0, 1, gi), (1, 0, -gi), (1, 1, gr)):
            rows.append((j + dr) * n_out + r), cols.append((j + dc) * n_in + c), vals.append(val)
    out = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                        shape=(C * n_out, C * n_in)).tocsr()
    out.eliminate_zeros()
    return out


@dataclass
class AssemblySystem(HarmonicBalanceSystem):
    """HarmonicBalanceSystem of a MistunedDisk with a fast sparse assembly of the Jacobian.

    Same residual as the generic sparse path of HarmonicBalanceSystem (tested against it); the
    contact term T^T J_c T is formed damper by damper on the 2 n_m + 6 structural DOFs (all
    harmonics) each damper touches, from the nonzeros of its block of T (:func:`_project_blocks`),
    and the Jacobian's CSC pattern is computed once.

    Attributes formed once when built (read-only; shared by :meth:`with_linear_parts` copies
    except ``linear_coo``), with N = n_unknowns:

    * ``linear_coo``: [K_0, M_2, G] (N, N) of :meth:`dynamic_stiffness` (A = K_0 - Omega^2 M_2
      + Omega G) as scipy COO matrices, their entries in the Jacobian pattern's order;
    * ``contact_blocks``: ``(T, T^T, Tb, Tb^T, idx)`` of the contact map T (C n_local, N) (CSR):
      Tb (n_d, C L, m) the rows of damper d restricted to its m structural columns idx (n_d, m),
      or None (no couplings, or dampers touching different numbers of DOFs);
    * ``contact_nonzeros``: the nonzeros of Tb row by row (:func:`projection_rows`), with ``contact_blocks``;
    * ``jacobian_pattern``: ``(inverse, indices, indptr, nnz)``: the CSC pattern (int32 indices,
      indptr) of the Jacobian's nnz entries and, for each summed term (linear parts' entries,
      then each damper's m x m block), the index of the entry it adds to;
    * ``jacobian_template``: the (N, N) CSC matrix of that pattern each sparse Jacobian copies
      (its index arrays shared);
    * ``dense_index``: (nnz,) row-major flat position of each pattern entry in the dense Jacobian;
    * ``condensation_solver``: the damper-condensation factorization (callable on a dense
      Jacobian), or None; ``ring_solver``: the :class:`~bladedamp.hbm.linsolve.BlockRing` set
      up by :meth:`use_ring`, or None.
    """

    def __post_init__(self):
        basis, N = self.basis, self.n_dof
        C = basis.n_coeffs
        self._linear_parts()
        parts = self.linear_coo
        rows = [p.row for p in parts]
        cols = [p.col for p in parts]
        self.contact_blocks = None
        self.condensation_solver = None
        if self.couplings:
            c = self.couplings[0]
            T = sp.csr_matrix(c.matrix)
            nd, L = c.element.n_dampers, c.element.damper_local
            Tb, idx = [], []
            for d in range(nd):
                r = (np.arange(C)[:, None] * L * nd + L * d + np.arange(L)[None, :]).ravel()
                Td = T[r]
                cols_d = np.unique(Td.indices)
                Tb.append(Td[:, cols_d].toarray())
                idx.append(cols_d)
            if len({len(i) for i in idx}) == 1:
                Tb, idx = np.array(Tb), np.array(idx)
                self.contact_blocks = (T, T.T.tocsr(), Tb, np.swapaxes(Tb, 1, 2).copy(), idx)
                self.contact_nonzeros = projection_rows(Tb)
                m = idx.shape[1]
                rows.append(np.broadcast_to(idx[:, :, None], (nd, m, m)).ravel())
                cols.append(np.broadcast_to(idx[:, None, :], (nd, m, m)).ravel())
                self.condensation_solver = self._damper_condensation(idx)
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        key = cols.astype(np.int64) * N * C + rows
        unique, inverse = np.unique(key, return_inverse=True)
        n = N * C
        self.jacobian_pattern = (inverse, (unique % n).astype(np.int32),
                         np.searchsorted(unique // n, np.arange(n + 1)).astype(np.int32), len(unique))
        # the sparse Jacobian's matrix: each evaluation is a shallow copy holding new values, its
        # index arrays shared (scipy's constructor checks them anew: 11 against 2 us)
        self.jacobian_template = sp.csc_matrix((np.zeros(len(unique)),) + self.jacobian_pattern[1:3], shape=(n, n))
        # dense position (row-major) of each pattern entry, for the dense Jacobian
        self.dense_index = (unique % n) * n + unique // n
        self.dense = n <= self.dense_limit

    def with_linear_parts(self, damping, stiffness) -> "AssemblySystem":
        """This system with other damping and stiffness matrices (n_dof, n_dof) [1/s, 1/s^2] of the
        same sparsity (a :meth:`MistunedDisk.mistuned` copy's blades): the mass, excitation,
        contacts, static stiffness, the Jacobian's pattern and the linear solver are shared, only
        the linear parts' values are new, so the residual is bit-identical to that of a system
        built anew with these matrices. This system is left as it is.

        Raises ValueError if the sparsity of the linear parts differs from this system's."""
        other = self.with_matrices(damping, stiffness)
        other._linear_parts()
        if any(not (np.array_equal(a.row, b.row) and np.array_equal(a.col, b.col)) for a, b in zip(other.linear_coo, self.linear_coo)):
            raise ValueError("damping and stiffness must have the sparsity of the system's own (its Jacobian's "
                             "pattern is shared)")
        return other

    #: systems with at most this many unknowns return a dense Jacobian (an n x n copy per
    #: evaluation is cheaper than sparse assembly and LU below this size; benchmarks/README.md,
    #: 'Moved from the package's docstrings', mistuned.py, 'dense_limit')
    dense_limit = 1500
    #: with the ring solver (:meth:`uses_ring`), systems with more unknowns than this return a
    #: sparse Jacobian: the ring gathers its blocks from the CSC arrays, so the dense n x n
    #: Jacobian and its bordered copy (0.8 MB each at n = 320) are only memory traffic
    #: (benchmarks/README.md, 'Moved from the package's docstrings', mistuned.py,
    #: 'ring_dense_limit'). Small assemblies (2-6 blades, n <= 120) stay dense
    ring_dense_limit = 200

    def _damper_condensation(self, idx):
        """BlockCondensation of the damper coordinates: each damper's rows hold its own
        coordinates and those of the two blades it touches (``idx``: the unknowns of each
        damper's contact map, all harmonics); None if that does not hold."""
        n_blade = self.n_dof - 6 * idx.shape[0]
        N = self.n_dof
        is_damper = (idx % N) >= n_blade
        counts = is_damper.sum(axis=1)
        if counts.min() != counts.max():
            return None
        interior = np.array([i[d] for i, d in zip(idx, is_damper)])
        coupled = np.array([i[~d] for i, d in zip(idx, is_damper)])
        # the damper's mass / static-retention rows must not reach outside its own block
        for matrix in self._sparse_parts:
            m = sp.csr_matrix(matrix)
            block = np.full(m.shape[0], -1)
            block[interior.ravel()] = np.repeat(np.arange(interior.shape[0]), interior.shape[1])
            r, c = m.nonzero()
            inside = block[r] >= 0
            if np.any(block[r[inside]] != block[c[inside]]):
                return None
        return BlockCondensation(interior, coupled, self.n_unknowns)

    #: the linear solver of :meth:`factorize`: "auto" (the ring from :attr:`ring_min_blades`
    #: blades on, else "condensation"), "ring" (:class:`~bladedamp.hbm.linsolve.BlockRing`,
    #: O(n) in the blades), "condensation" (damper coordinates condensed, dense LU of the
    #: blades' Schur complement, for dense Jacobians; sparse LU for sparse ones), "lu"
    linear_solver = "auto"
    #: blades from which "auto" takes the ring: every ring. The ring is no slower than the
    #: condensation at any count and faster the more blades (benchmarks/README.md, 'Mistuned full
    #: assembly: cost per FRF point against the number of blades'), and it gives det A's sign
    #: (``solve.sign``), the condensation not
    ring_min_blades = 2
    ring_solver = None
    _ring_blades = 0
    _solvers = ("auto", "ring", "condensation", "lu")

    def use_ring(self, n_blades: int, n_modes: int, positions) -> bool:
        """Set up :class:`~bladedamp.hbm.linsolve.BlockRing` for a ring of ``n_blades`` blades of
        ``n_modes`` modal coordinates each (unknowns harmonic-major, blades first, then the
        dampers) whose d-th damper sits between blade ``positions[d]`` and the next; True if the
        contact map has that pattern (each damper couples exactly those two blades)."""
        self.ring_solver, self._ring_blades = None, 0
        N, C = self.n_dof, self.basis.n_coeffs
        nd = len(positions)
        if n_blades < 2 or N != n_blades * n_modes + 6 * nd or (nd and self.condensation_solver is None):
            return False
        groups = (np.arange(C)[None, :, None] * N + np.arange(n_blades)[:, None, None] * n_modes
                  + np.arange(n_modes)[None, None, :]).reshape(n_blades, C * n_modes)
        links = np.asarray(positions, dtype=np.intp)
        interior = None
        if nd:
            cond = self.condensation_solver
            interior = cond.interior
            for d, k in enumerate(links):
                pair = np.concatenate([groups[k], groups[(k + 1) % n_blades]])
                if cond.coupled[d].size != pair.size or not np.array_equal(np.sort(cond.coupled[d]), np.sort(pair)):
                    return False
        try:
            self.ring_solver = BlockRing(groups, interior, links, self.n_unknowns)
        except ValueError:                   # the unknowns are not blades and dampers only
            return False
        self._ring_blades = n_blades
        return True

    def uses_ring(self) -> bool:
        """Whether :meth:`factorize` takes the ring: set up by :meth:`use_ring` and chosen by
        :attr:`linear_solver`."""
        solver = self.linear_solver
        return self.ring_solver is not None and (solver == "ring" or (solver == "auto" and
                                                                self._ring_blades >= self.ring_min_blades))

    def factorize(self, A):
        """The linear solver of the continuation (:attr:`linear_solver`): the ring
        (:class:`~bladedamp.hbm.linsolve.BlockRing`, dense or sparse A) when set up by
        :meth:`use_ring` and chosen; else the condensation of the damper coordinates
        (:class:`~bladedamp.hbm.linsolve.BlockCondensation`) for dense Jacobians, or LU."""
        solver = self.linear_solver
        if solver not in self._solvers:
            raise ValueError(f"linear_solver must be one of {self._solvers} (got {solver!r})")
        if self.uses_ring():
            return self.ring_solver(A)
        if solver != "lu" and self.condensation_solver is not None and not sp.issparse(A):
            return self.condensation_solver(A)
        return lu_factorize(A)

    def _linear_parts(self):
        """The linear parts K_0, M_2, G (:meth:`_sparse_dynamic_stiffness`) as the residual uses
        them: COO (their values in the Jacobian's pattern order) and CSC arrays (data, indices,
        indptr) for :func:`_linear_residual`."""
        self._sparse_dynamic_stiffness(1.0)         # forms the parts (once)
        self.linear_coo = [m.tocoo() for m in self._sparse_parts]
        self._csc = tuple((m.data, m.indices, m.indptr) for m in self._sparse_parts)

    def residual(self, x, omega, jacobian=True):
        """R, the sparse (or dense) Jacobian and dR/domega, or R, None, None. The linear parts,
        the contact map's products and the Jacobian's values are formed in numba kernels
        (:func:`_linear_residual`, :func:`_csr_matvec_add`, :func:`_jacobian_values`) in the
        order of the scipy / numpy operations they replaced, so R and dR/domega are the same
        numbers (tested); the Jacobian's contact part T^T J_c T by :func:`_project_blocks`, equal to
        the dense products to rounding (tested against their bound). The sparse Jacobian is a
        copy of one template matrix (:attr:`jacobian_template`) holding the new values: every
        Jacobian of the system shares the template's index arrays (do not change them in place; :func:`~bladedamp.hbm.continuation.bordered_matrix` relies on
        them to reuse its bordered pattern; timings: benchmarks/README.md, 'Moved from the
        package's docstrings', mistuned.py)."""
        if self.couplings and self.contact_blocks is None:
            return super().residual(x, omega, jacobian)
        basis = self.basis
        C = basis.n_coeffs
        x = np.ascontiguousarray(x, dtype=float)
        f, df = self.excitation(omega)
        n = x.size
        R, Rw, m2x, gx = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
        _linear_residual(self._csc, x, omega ** 2, omega, -2 * omega, f, df, jacobian, R, Rw, m2x, gx)
        contact = np.empty(0)
        if self.couplings:
            T, TT, Tb, TbT, _ = self.contact_blocks
            element = self.couplings[0].element
            local = np.zeros(T.shape[0])
            _csr_matvec_add(T.data, T.indices, T.indptr, x, local)
            force, blocks, domega = element.evaluate(local.reshape(C, element.n_local), basis, omega, jacobian)
            _csr_matvec_add(TT.data, TT.indices, TT.indptr, np.ascontiguousarray(force).ravel(), R)
            if jacobian:
                contact = np.ascontiguousarray(blocks)
                if domega is not None:
                    _csr_matvec_add(TT.data, TT.indices, TT.indptr, np.ascontiguousarray(domega).ravel(), Rw)
        if not jacobian:
            return R, None, None
        inverse, indices, indptr, nnz = self.jacobian_pattern
        data = np.zeros(nnz)
        k = _jacobian_values(inverse, self.linear_coo[0].data, self.linear_coo[1].data, self.linear_coo[2].data,
                             -omega ** 2, omega, data)
        if contact.size:
            _project_blocks(contact, *self.contact_nonzeros, Tb.shape[2], inverse[k:], data)
        if self.dense:
            J = np.zeros(n * n)
            J[self.dense_index] = data
            return R, J.reshape(n, n), Rw
        J = copy.copy(self.jacobian_template)
        J.data = data
        return R, J, Rw


def projection_rows(Tb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nonzeros of each damper's contact map block Tb (n_d, r, m) row by row, as
    :func:`_project_blocks` reads them: (pointers (n_d, r + 1) into the flat (columns, values))
    (int64, int64, float). Tb is sparse (each damper's local coordinates of harmonic h depend only
    on the structural unknowns of harmonic h, and a damper's local motion on few modal
    coordinates): 6.6 % of its entries on the 16-blade reference disk with harmonics (0..3)."""
    nd, r, _ = Tb.shape
    pointers = np.zeros((nd, r + 1), dtype=np.int64)
    columns, values = [], []
    start = 0
    for d in range(nd):
        rows, cols = np.nonzero(Tb[d])
        pointers[d] = start + np.searchsorted(rows, np.arange(r + 1))
        columns.append(cols), values.append(Tb[d][rows, cols])
        start += len(cols)
    return pointers, np.concatenate(columns).astype(np.int64), np.concatenate(values)


@njit(cache=True)
def _project_blocks(blocks, pointers, columns, values, m, inverse, data):
    """Adds each damper's Tb_d^T B_d Tb_d (m, m), its contact Jacobian B_d (``blocks`` (n_d, r, r),
    C-contiguous) projected by its contact map block Tb_d (r, m) given by its nonzeros row by row
    (:func:`projection_rows`), to the Jacobian's values: entry (i, j) of damper d's product to
    ``data[inverse[(d m + i) m + j]]``, dampers in turn (as np.bincount sums the flat products).
    Two sparse passes, each over contiguous rows (Q = Tb^T B, (m, r); then out^T = Tb^T Q^T):
    about nnz (r + m) products a damper instead of a dense product's r m (r + m) (15x fewer on the
    16-blade disk with harmonics (0..3)); its sums run in another order than a dense product's, so
    each product agrees with ``np.matmul(Tb.T, np.matmul(B, Tb))`` to rounding (within r eps of
    the sum of its terms' magnitudes), not bit for bit."""
    nd, r = blocks.shape[0], blocks.shape[1]
    Q = np.empty((m, r))
    QT = np.empty((r, m))
    outT = np.empty((m, m))
    for d in range(nd):
        Q[:, :] = 0.0
        for a in range(r):
            for k in range(pointers[d, a], pointers[d, a + 1]):
                b, t = columns[k], values[k]
                for j in range(r):
                    Q[b, j] += t * blocks[d, a, j]
        for b in range(m):
            for j in range(r):
                QT[j, b] = Q[b, j]
        outT[:, :] = 0.0
        for a in range(r):
            for k in range(pointers[d, a], pointers[d, a + 1]):
                b, t = columns[k], values[k]
                for j in range(m):
                    outT[b, j] += t * QT[a, j]
        base = d * m * m
        for i in range(m):
            for j in range(m):
                data[inverse[base + i * m + j]] += outT[j, i]


@njit(cache=True)
def _csc_matvec(data, indices, indptr, x, y):
    """y = A x (y (n,) overwritten) for the CSC matrix A = (data, indices, indptr), column by
    column as scipy's csc_matvec sums (the same numbers as ``A @ x``)."""
    y[:] = 0.0
    for j in range(indptr.size - 1):
        xj = x[j]
        for k in range(indptr[j], indptr[j + 1]):
            y[indices[k]] += data[k] * xj


@njit(cache=True)
def _csr_matvec_add(data, indices, indptr, x, y):
    """y += A x for the CSR matrix A = (data, indices, indptr): each row's sum formed from zero,
    as scipy's csr_matvec does, then added (the same numbers as ``y += A @ x``)."""
    for i in range(indptr.size - 1):
        s = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * x[indices[k]]
        y[i] += s


@njit(cache=True)
def _linear_residual(parts, x, omega2, omega, minus_two_omega, f, df, jacobian, R, Rw, m2x, gx):
    """The linear part of :meth:`AssemblySystem.residual`: R = K_0 x - omega2 M_2 x + omega G x - f
    and, with ``jacobian``, Rw = minus_two_omega M_2 x + G x - df, in numpy's order of the
    operations (the same numbers). parts: the CSC arrays (data, indices, indptr) of K_0, M_2, G
    [N/m, kg, N s/m in modal units]; x, f, df (n,); outputs R, Rw and the work arrays m2x, gx (n,)."""
    (k_data, k_indices, k_indptr), (m_data, m_indices, m_indptr), (g_data, g_indices, g_indptr) = parts
    _csc_matvec(m_data, m_indices, m_indptr, x, m2x)
    _csc_matvec(g_data, g_indices, g_indptr, x, gx)
    _csc_matvec(k_data, k_indices, k_indptr, x, R)
    for i in range(R.size):
        R[i] = R[i] - omega2 * m2x[i] + omega * gx[i] - f[i]
    if jacobian:
        for i in range(R.size):
            Rw[i] = minus_two_omega * m2x[i] + gx[i] - df[i]


@njit(cache=True)
def _jacobian_values(inverse, k_values, m_values, g_values, minus_omega2, omega, data):
    """The linear parts' Jacobian values in its pattern order: data[inverse[i]] += v_i over the
    values v of K_0, minus_omega2 M_2, omega G (COO order), in turn, as np.bincount sums them (the
    same numbers); ``data`` (nnz,) zeroed by the caller. Returns the number of values added (the
    contacts' follow, :func:`_project_blocks`)."""
    k = 0
    for v in k_values:
        data[inverse[k]] += v
        k += 1
    for v in m_values:
        data[inverse[k]] += minus_omega2 * v
        k += 1
    for v in g_values:
        data[inverse[k]] += omega * v
        k += 1
    return k


def _as_list(name, value, n):
    if isinstance(value, (list, tuple)):
        if len(value) != n:
            raise ValueError(f"{name} must have one entry per blade of the model ({n}), got {len(value)}")
        return list(value)
    return [value] * n


@dataclass
class MistunedDisk(DiskModel):
    """Bladed disk with an individual blade and damper at every position (Eq. 16-20).

    Parameters
    ----------
    blades : sequence of s ModalBlade (same number of modes and the same point positions;
        natural frequencies, damping ratios and mode shapes may differ)
    dampers : one damper for all positions, or a sequence of s dampers (CylinderDamper,
        WedgeDamper or None; None or mass 0: no damper at that position); damper k sits
        between blade k (OL) and blade k+1 (OR)
    n_blades : blades of the whole disk; default s (full assembly). Must be a multiple of s:
        the model is then one cyclic sector of s blades (s = 1: the tuned disk)
    gamma_left, gamma_right : platform angles [rad] in (0, pi/2), one for all positions or a
        sequence of s: position k's damper lies on blade k's OL platform (gamma_left[k]) and
        blade k+1's OR platform (gamma_right[k])
    initial_gaps : None, one (2, P) array of gaps [m] (as :class:`~bladedamp.disk.TunedDisk`) for
        all positions, or a list of s such arrays / None: each damper's own misfit
    engine_order, damper_radius, excitation, rotor_speed_hz, damper_inertia : as
        :class:`~bladedamp.disk.TunedDisk` (the same for every position; ``rotor_speed_hz`` in Hz,
        revolutions per second)
    """

    blades: Sequence[ModalBlade]
    dampers: object = None
    n_blades: int | None = None
    engine_order: int = 1
    gamma_left: float | Sequence[float] = PLATFORM_ANGLE
    gamma_right: float | Sequence[float] = PLATFORM_ANGLE
    damper_radius: float = DEFAULT_DAMPER_RADIUS
    excitation: np.ndarray = field(default_factory=lambda: np.array([0.1, 0, 0, 0, 0, 0]))
    rotor_speed_hz: float | None = None
    damper_inertia: bool = True
    initial_gaps: object = None
    #: (s,) each blade's mistuning factor on the design blade's frequencies (``from_tuned``,
    #: ``mistuned``), None: the blades as given (factors 1); what ``mistuning.kappa[k]``'s
    #: derivative is taken in (:meth:`~bladedamp.diskmodel.DiskModel.parameter_derivatives`)
    kappa: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: linear solver of the continuation (:attr:`AssemblySystem.linear_solver`); set it on an
    #: instance (``disk.linear_solver = "condensation"``) to change that disk's solver
    linear_solver: ClassVar[str] = "auto"

    def __post_init__(self):
        self.rotor_speed_hz = rotor_speed_in_hz(self.rotor_speed_hz)
        if isinstance(self.blades, ModalBlade) or len(self.blades) == 0:
            raise ValueError("blades must be a non-empty sequence of ModalBlade (one per blade of the model)")
        self.blades = list(self.blades)
        s = len(self.blades)
        if self.n_blades is None:
            self.n_blades = s
        self.n_blades = validation.integer("n_blades", self.n_blades, minimum=2)
        if self.n_blades % s:
            raise ValueError(f"n_blades ({self.n_blades}) must be a multiple of len(blades) ({s})")
        nm = self.blades[0].n_modes
        names = sorted(self.blades[0].points)
        for k, b in enumerate(self.blades):
            if not isinstance(b, ModalBlade):
                raise ValueError(f"blades[{k}] must be a ModalBlade (got {type(b).__name__})")
            if b.n_modes != nm:
                raise ValueError(f"blades must have the same number of modes (blades[0]: {nm}, blades[{k}]: {b.n_modes})")
            if sorted(b.points) != names:
                raise ValueError(f"blades must have the same point positions (blades[{k}] differs from blades[0])")
        # all blades' points at once (np.allclose per point and blade was 5 ms of a 16-blade disk's construction)
        positions = np.array([[b.points[p] for p in names] for b in self.blades])      # (s, points, 3)
        close = np.isclose(positions, positions[0]).all(axis=(1, 2))
        if not close.all():
            raise ValueError(f"blades must have the same point positions (blades[{int(np.argmin(close))}] differs "
                             "from blades[0])")
        flexible = [b.flexible_platform for b in self.blades]
        if any(flexible) and not all(flexible):
            raise ValueError("blades must all carry per-point platform data (solid blades: flexible platforms) "
                             f"or none (blades {[k for k, f in enumerate(flexible) if f]} do, the others not)")
        self.dampers = _as_list("dampers", self.dampers, s)
        angles = {}
        for name in ("gamma_left", "gamma_right"):
            value = getattr(self, name)
            angles[name] = _as_list(name, list(value) if isinstance(value, np.ndarray) and value.ndim else value, s)
        gaps = _as_list("initial_gaps", self.initial_gaps, s)
        self.engine_order = validation.integer("engine_order (EO)", self.engine_order, minimum=0)
        # one description per damper position (the angles validated there), the same blades' points
        self.positions = [DamperPosition(d, gl, gr, g, self.damper_radius, self.engine_order,
                                         self.rotor_speed_hz).validate()
                          for d, gl, gr, g in zip(self.dampers, angles["gamma_left"], angles["gamma_right"], gaps)]
        self.validate_parameters(any(p.has_damper for p in self.positions))
        self._systems = {}

    def __getstate__(self):
        # the cached systems hold closures (their excitation) and are rebuilt on demand; a
        # mistuned copy unpickled builds its own (its source's set-up is not carried along)
        state = self.__dict__.copy()
        state.pop("_systems", None)
        state.pop("_setup_source", None)
        return state

    def mistuned(self, kappa) -> "MistunedDisk":
        """This disk with blade k's natural frequencies times ``kappa[k]`` (every mode; the
        paper's mistuning factors, on top of the blades' own), everything else the same.

        ``kappa``: (s,) values > 0. The copy's harmonic-balance systems (:meth:`hbm_system`) are
        this disk's with the blades' damping and stiffness replaced
        (:meth:`AssemblySystem.with_linear_parts`): the dampers' contacts and maps, the
        excitation, the Jacobian's sparsity and the ring solver's set-up do not depend on the
        blades' frequencies, so they are built once here (and kept) and shared by every copy.
        The residuals are bit-identical to those of :meth:`from_tuned` with the same factors
        (tested), and the copy costs a fraction of ``from_tuned`` with its system built anew
        (benchmarks/README.md, 'Moved from the package's docstrings', mistuned.py)."""
        kappa = np.asarray(validation.positive("kappa (mistuning factors)", kappa), dtype=float)
        if kappa.shape != (self.n_sector,):
            raise ValueError(f"kappa (mistuning factors) must have {self.n_sector} entries, one per blade "
                             f"(got shape {kappa.shape})")
        out = dataclasses.replace(self, blades=[b.scaled(k) for b, k in zip(self.blades, kappa)],
                                  kappa=kappa * self.mistuning_factors)
        out._setup_source = self
        return out

    @classmethod
    def from_tuned(cls, disk: DiskModel, kappa=None, dampers="same", n_sector: int | None = None) -> "MistunedDisk":
        """The disk of ``disk`` with blade k's frequencies times ``kappa[k]`` (the paper's
        mistuning factor, all modes alike) and optionally its own ``dampers``.

        ``kappa``: None (tuned) or n_sector values > 0; ``dampers``: "same" (the disk's damper
        everywhere), None (no dampers), one damper or a list; ``n_sector``: blades in the model
        (default ``disk.n_blades``, the full assembly)."""
        s = disk.n_blades if n_sector is None else validation.integer("n_sector", n_sector, minimum=1)
        if kappa is None:
            kappa = np.ones(s)
        kappa = np.asarray(validation.positive("kappa (mistuning factors)", kappa), dtype=float)
        if kappa.shape != (s,):
            raise ValueError(f"kappa (mistuning factors) must have {s} entries, one per blade (got shape {kappa.shape})")
        blades = [disk.blade.scaled(k) for k in kappa]
        same = isinstance(dampers, str) and dampers == "same"
        return cls(blades, disk.damper if same else dampers, disk.n_blades, disk.engine_order,
                   disk.gamma_left, disk.gamma_right, disk.damper_radius, disk.excitation, disk.rotor_speed_hz,
                   disk.damper_inertia, disk.initial_gaps, kappa=kappa)

    def with_dampers(self, change) -> "MistunedDisk":
        """This disk with every damper d replaced by ``change(d)`` (a new disk; positions without one keep none)."""
        return dataclasses.replace(self, dampers=[None if d is None else change(d) for d in self.dampers])

    def with_blades(self, change) -> "MistunedDisk":
        """This disk with blade k replaced by ``change(k, blade)`` (a new disk)."""
        return dataclasses.replace(self, blades=[change(k, b) for k, b in enumerate(self.blades)])

    @property
    def mistuning_factors(self) -> np.ndarray:
        """(s,) :attr:`kappa`, or ones where the blades were given as they are."""
        return np.ones(self.n_sector) if self.kappa is None else np.asarray(self.kappa, dtype=float)

    # ----- layout ----------------------------------------------------------------------
    @property
    def n_sector(self) -> int:
        """Blades in the model (s)."""
        return len(self.blades)

    @property
    def n_modes(self) -> int:
        return self.blades[0].n_modes

    @property
    def active_dampers(self) -> list[int]:
        """Positions whose damper has a mass."""
        return [k for k, p in enumerate(self.positions) if p.has_damper]

    @property
    def n_dof(self) -> int:
        return self.n_sector * self.n_modes + 6 * len(self.active_dampers)

    def blade_slice(self, k: int) -> slice:
        return slice(k * self.n_modes, (k + 1) * self.n_modes)

    def damper_slice(self, d: int) -> slice:
        """DOFs of the d-th active damper."""
        start = self.n_sector * self.n_modes + 6 * d
        return slice(start, start + 6)

    # ----- the layout of DiskModel: s blades, a damper at each position with a mass ----------
    @property
    def model_blades(self) -> list[ModalBlade]:
        """The s blades written out (:class:`~bladedamp.diskmodel.DiskModel`)."""
        return self.blades

    @property
    def active_positions(self) -> list[int]:
        """:attr:`active_dampers`."""
        return self.active_dampers

    def damper_unknowns(self, d: int) -> slice:
        """:meth:`damper_slice`."""
        return self.damper_slice(d)

    def seated_damper(self, k: int, omega: float) -> np.ndarray:
        """(6,) position ``k``'s damper seated frictionlessly under F_CG at ``omega`` [rad/s] (``seat``)."""
        return self.positions[k].seated(omega)

    def scales(self, system: HarmonicBalanceSystem, w0: float, w1: float) -> np.ndarray:
        """:meth:`unknown_scales` (the former name)."""
        return self.unknown_scales(system, w0, w1)

    @property
    def dof_names(self) -> tuple[str, ...]:
        modes = self.blades[0].mode_names or tuple(f"q{j + 1}" for j in range(self.n_modes))
        names = [f"b{k}_q_{m}" for k in range(self.n_sector) for m in modes]
        names += [f"d{k}_{n}" for k in self.active_dampers for n in DAMPER_DOFS]
        return tuple(names)

    # ----- harmonic balance ------------------------------------------------------------
    def default_samples(self, harmonics) -> int:
        """HarmonicBasis' default sample count, as the tuned disk's: each damper is sampled on a
        grid shifted by its interblade phase (:meth:`~bladedamp.diskmodel.AssemblyContacts.grid_rotations`), so the
        count need not be a multiple of n / gcd(n, EO) (see the module notes)."""
        return HarmonicBasis(tuple(harmonics)).n_samples

    def hbm_system(self, harmonics=(1,), n_samples=None, static_retention: float = 1e-4,
                   linear_solver: str | None = None) -> HarmonicBalanceSystem:
        """The sparse harmonic balance of the model (see TunedDisk.hbm_system for ``static_retention``).

        ``linear_solver``: the system's ``factorize`` (:attr:`AssemblySystem.linear_solver`:
        "auto", "ring", "condensation" or "lu"); default :attr:`linear_solver` of the disk."""
        if linear_solver is not None and linear_solver not in AssemblySystem._solvers:
            raise ValueError(f"linear_solver must be one of {AssemblySystem._solvers} (got {linear_solver!r})")
        if n_samples is None:
            n_samples = self.default_samples(harmonics)
        solver = self.linear_solver if linear_solver is None else linear_solver
        # one system per setting and disk: the FRF, its range extensions and the peak solves of a
        # Monte Carlo disk share it (building it took 28 ms, 0.3 of a solved peak's cost). The
        # disk is fixed at construction (its positions are built then), so the cache never goes stale.
        key = (tuple(int(h) for h in harmonics), int(n_samples), float(static_retention), solver)
        systems = self.__dict__.setdefault("_systems", {})
        if key not in systems:
            source = self.__dict__.get("_setup_source")
            if source is not None:       # a mistuned copy (:meth:`mistuned`): only K and D differ
                systems[key] = source.hbm_system(*key).with_linear_parts(*self.blade_matrices())
            else:
                systems[key] = self._build_system(key[0], key[1], key[2], solver)
        return systems[key]

    def blade_matrices(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """(damping, stiffness) (n_dof, n_dof) of the blades' modal equations (Eq. 5): diagonal,
        2 D_j omega_0j [1/s] and omega_0j^2 [1/s^2] on blade k's modal coordinates, empty rows for
        the dampers' (every diagonal entry stored, zeros included, so that the sparsity does not
        depend on the values: :meth:`mistuned` copies share it)."""
        N, n = self.n_dof, self.n_sector * self.n_modes
        w0 = np.concatenate([b.natural_angular_frequencies for b in self.blades])
        zeta = np.concatenate([b.damping_ratios for b in self.blades])
        diagonal = np.arange(n)
        return tuple(sp.csr_matrix((values, (diagonal, diagonal)), shape=(N, N))
                     for values in (2 * zeta * w0, w0 ** 2))

    def _build_system(self, harmonics, n_samples, static_retention, linear_solver) -> HarmonicBalanceSystem:
        """A new :meth:`hbm_system` (its arguments resolved)."""
        basis = HarmonicBasis(tuple(harmonics), n_samples)
        C, nm, s, N = basis.n_coeffs, self.n_modes, self.n_sector, self.n_dof
        active = self.active_dampers
        mass = sp.lil_matrix((N, N))
        damp, stiff = self.blade_matrices()
        forces = []
        for k, b in enumerate(self.blades):
            sl = self.blade_slice(k)
            mass[sl, sl] = np.eye(nm)
            forces.append(b.shape("excitation").T @ self.excitation)
        contacts, maps, static = [], [], None
        if basis.has_static and active:
            static = sp.lil_matrix((N, N))
        shared = {}       # positions with the same damper, angles and gaps share geometry and approach
        for d, k in enumerate(active):
            position = self.positions[k]
            same = (id(position.damper), position.gamma_left, position.gamma_right, id(position.initial_gaps))
            if same not in shared:
                g = position.damper_geometry()
                shared[same] = (g, position.approach_function(g, basis))
            g, approach = shared[same]
            sl = self.damper_slice(d)
            if self.damper_inertia:
                mass[sl, sl] = g.inertia
            # damper k: blade k's OL platform, blade k+1's OR platform (that of the next sector's blade 0)
            element, G_D, G_P = position.contacts(g, approach, self.blades[k], self.blades[(k + 1) % s])
            contacts.append(element)
            maps.append((G_D, G_P))
            if static is not None:
                static[sl, sl] = DamperPosition.retention(g, static_retention)
        dphi = self.interblade_phase
        L = contacts[0].n_local if contacts else 12           # local coordinates per damper
        couplings = []
        if active:
            # each damper sampled on its own grid, shifted by its travelling-wave phase (exact tuned = cyclic at any T)
            grid_phase = np.array([k * dphi for k in active]) if dphi else None
            couplings.append(Coupling(AssemblyContacts(contacts, grid_phase=grid_phase),
                                      self.contact_coupling(basis, maps, L, L != 12), "damper contacts"))
        j1 = basis.cos_index(1)
        f1 = np.zeros((C, N))
        for k, f in enumerate(forces):
            theta = k * dphi                                   # X = F e^{i k dphi} = a - i b
            f1[j1, self.blade_slice(k)] = f * np.cos(theta)
            f1[j1 + 1, self.blade_slice(k)] = -f * np.sin(theta)

        # the static harmonic's centrifugal force on each damper, radially outwards (its z): the
        # laws built once, one per distinct damper (validation at the boundary, not per residual)
        j0 = basis.cos_index(0) if basis.has_static else None
        laws, radial = {}, []
        if basis.has_static:
            for d, k in enumerate(active):
                key = id(self.positions[k].damper)
                if key not in laws:
                    laws[key] = (self.positions[k].centrifugal_law(), [])
                laws[key][1].append(self.damper_slice(d).start + 2)
            radial = [(law, np.array(z)) for law, z in laws.values()]

        def excitation(omega):
            f, df = f1.copy(), np.zeros((C, N))
            for law, z in radial:
                F, dF = law(omega)
                f[j0, z] = F
                df[j0, z] = dF
            return f.ravel(), df.ravel()

        system = AssemblySystem(basis, mass.tocsr(), damp, stiff, excitation, couplings,
                                None if static is None else static.tocsr())
        system.use_ring(s, nm, active)
        system.linear_solver = linear_solver
        if system.uses_ring() and system.n_unknowns > system.ring_dense_limit:
            system.dense = False
        return system

    def contact_coupling(self, basis: HarmonicBasis, kinematics, n_local: int, flexible: bool) -> sp.csr_matrix:
        """The real-form map (C n_local n_d, C N) from the ring's unknowns to every damper's local
        coordinates (Eq. 6 with Eq. 16-20): damper d (on blade k) sees blade k's OL platform and
        blade k+1's OR platform (the next sector's blade 0 turned by its phase) through its rigid
        kinematics ``kinematics[d]`` = (G_D (12, 6), G_P (12, 12)), and with ``flexible`` platforms
        both blades' modal coordinates. Linear in the kinematics: with their derivatives and
        ``flexible`` False it is the map's derivative."""
        nm, s, N = self.n_modes, self.n_sector, self.n_dof
        active, dphi, L = self.active_dampers, self.interblade_phase, n_local
        w_rows, left_rows, right_rows = contact_rows(L // 2, nm)

        def contact_map(h):
            T = sp.lil_matrix((L * len(active), N), dtype=complex)
            for d, k in enumerate(active):
                G_D, G_P = kinematics[d]
                nxt = (k + 1) % s
                phase = np.exp(1j * h * s * dphi) if k + 1 == s else 1.0   # next sector's blade 0
                rows = L * d + w_rows if L != 12 else slice(12 * d, 12 * d + 12)
                T[rows, self.blade_slice(k)] = -G_P[:, :6] @ self.blades[k].shape("OL")
                T[rows, self.blade_slice(nxt)] = T[rows, self.blade_slice(nxt)].toarray() \
                    - phase * (G_P[:, 6:] @ self.blades[nxt].shape("OR"))
                T[rows, self.damper_slice(d)] = G_D
                if flexible:                 # flexible platforms: the modal coordinates of both blades
                    T[L * d + left_rows, self.blade_slice(k)] = np.eye(nm)
                    T[L * d + right_rows, self.blade_slice(nxt)] = phase * np.eye(nm)
            return T.tocsr()

        return sparse_real_form(basis, contact_map)

    def frequency_response(self, f_start_hz: float, f_end_hz: float, harmonics="auto", n_samples=None,
                           max_step: float = DEFAULT_MAX_STEP, tuned_peak_amplitude: float | None = None,
                           harmonic_tolerance: float = HARMONIC_TOLERANCE, max_harmonic: int = 3,
                           estimate_harmonic_error: bool = True, check_stop: bool = False, check_peak: bool = False,
                           cpu_budget_s: float = DEFAULT_CPU_BUDGET_S, point_budget: int = DEFAULT_POINT_BUDGET,
                           **continuation_options) -> "MistunedResponse":
        """Forced response of every blade from ``f_start_hz`` to ``f_end_hz`` [Hz] by continuation.

        ``harmonics``, ``harmonic_tolerance``, ``max_harmonic``: as :meth:`TunedDisk.frequency_response`
        (the error estimate is over every blade's tip), but ``max_harmonic`` defaults to 3 here:
        the full assembly costs about 4x the cyclic sector per harmonic set, so the tuned
        disk's cap of 7 would make the default FRF take minutes. On the reference dampers
        (0, 1, 2, 3) is 2-5 % off, and the result says so (``harmonics_converged`` False and the
        message); pass ``max_harmonic=7`` for the 1 % answer. ``tuned_peak_amplitude`` [m]: the tuned disk's
        peak, kept for amplification factors. ``n_samples``: AFT samples per period; None
        (default): :meth:`default_samples`, and once ``AUTO_SAMPLES_GROWTH`` times more if that
        branch fails (:func:`bladedamp.response.sampled_response`, as the tuned disk).
        ``estimate_harmonic_error=False`` (given harmonics only) skips the error estimate, which
        costs about as much as a one-harmonic FRF of the assembly (5 enriched Newton solves of
        the full assembly with the static term); the result then says "not estimated".
        ``check_stop``: where the branch ends before the end of the range, integrate the assembly
        in time just beyond where it got furthest (:meth:`stop_check`, at ``f_start_hz`` when no
        point was kept) and put the verdict in the result, as :meth:`TunedDisk.frequency_response`
        (its ``stop_check`` and message); rigid platforms only (what :meth:`time_response` models).
        A failed branch without it says how to tell. ``check_peak``: for a branch that reached the
        end, the time integration at the peak's frequency gives a direct harmonic error estimate,
        or fails the response where the vibration there does not settle, as
        :meth:`TunedDisk.frequency_response` (:meth:`peak_check`, :func:`~bladedamp.diskmodel.with_peak_check`).
        Without dynamic excitation (``excitation`` zero) the response is rest, exactly
        (:func:`~bladedamp.diskmodel.rest_response`). Without dampers, a range holding the natural
        frequency of an excited blade mode without modal damping has no bounded response and is
        refused with a ValueError (:meth:`check_bounded`).
        ``cpu_budget_s`` [s] and ``point_budget``: the CPU time (``time.process_time``) and the
        continuation points this whole analysis may spend, the time integrations of
        ``check_stop`` and ``check_peak`` excepted (:class:`bladedamp.hbm.continuation.Budget`;
        defaults ``DEFAULT_CPU_BUDGET_S``, ``DEFAULT_POINT_BUDGET``). Where it runs out the branch
        ends there with every point it has, status ``OUT_OF_BUDGET`` (not ``success``), and
        ``stopped_by`` and the message say what ran out and at which frequency.
        """
        for name, on in (("check_stop", check_stop), ("check_peak", check_peak)):
            if on and any(b.flexible_platform for b in self.blades):
                raise ValueError(f"{name} integrates the disk in time, which models rigid platforms only: "
                                 f"use rigid-platform blades or {name}=False")
        w0, w1 = checked_range(self, f_start_hz, f_end_hz)
        if not np.any(self.excitation):
            return rest_response(self, w0, w1, max_step, harmonic_tolerance, lambda system, branch:
                                 MistunedResponse.from_branch(self, system, branch, tuned_peak_amplitude))
        can_check = not any(b.flexible_platform for b in self.blades)
        solve = branch_solver(self, f_start_hz, f_end_hz, n_samples, max_step, None, cpu_budget_s, point_budget,
                              **continuation_options)
        response = peak_checked_response(self, self, solve, harmonics, harmonic_tolerance, max_harmonic,
                                         estimate_harmonic_error, check_peak, can_check)
        if tuned_peak_amplitude is not None:       # kept for the amplification factors
            response = dataclasses.replace(response, tuned_peak_amplitude=tuned_peak_amplitude)
        return with_stop_check(self, response, f_start_hz, check_stop)

    # ----- the protocol of bladedamp.frf (the FRF driver) ----------------------------------
    def check_bounded(self, f_start_hz: float, f_end_hz: float) -> None:
        """ValueError where no bounded periodic response exists in ``f_start_hz``..``f_end_hz``
        [Hz]: without dampers every blade is on its own, as a tuned disk without damper
        (:func:`~bladedamp.diskmodel.check_blade_bounded` of each blade); with dampers nothing is refused."""
        if not self.active_dampers:
            for blade in self.blades:
                check_blade_bounded(blade, self.excitation, False, f_start_hz, f_end_hz)

    def response_from_branch(self, system: HarmonicBalanceSystem, branch) -> "MistunedResponse":
        """:meth:`MistunedResponse.from_branch` of this disk."""
        return MistunedResponse.from_branch(self, system, branch)

    def branch_energies(self, system: HarmonicBalanceSystem, branch, response: "MistunedResponse"):
        """(excitation work (n,), each damper's dissipation (n, n_d), its work bound (n, n_d)) per
        period [J] of ``response``."""
        return response.excitation_work, response.damper_dissipation, response.damper_work_bound

    def refined_dissipation(self, system: HarmonicBalanceSystem, branch) -> np.ndarray:
        """(k, n_d) each damper's dissipation per period [J] of ``branch`` on ``system``."""
        return MistunedResponse.from_branch(self, system, branch).damper_dissipation

    @staticmethod
    def time_output_amplitudes(check) -> np.ndarray:
        """(n_f, 3 s) first-harmonic tip amplitudes [m] of every blade of a :meth:`time_response`
        ``check``, ordered as :meth:`output_amplitudes`."""
        return check.tip_amplitude.reshape(len(check.tip_amplitude), -1)

    # ----- the protocol of bladedamp.hbm.accuracy ----------------------------------------
    def output_amplitudes(self, coefficients: np.ndarray, basis: HarmonicBasis) -> np.ndarray:
        """(n, 3 s) first-harmonic tip amplitudes of every blade [m] of coefficients (n, C, n_dof)."""
        j1, nm, s = basis.cos_index(1), self.n_modes, self.n_sector
        q1 = (coefficients[:, j1, :s * nm] - 1j * coefficients[:, j1 + 1, :s * nm]).reshape(-1, s, nm)
        tips = np.stack([b.shape("tip")[:3] for b in self.blades])            # (s, 3, nm)
        return np.abs(np.einsum("pkm,kim->pki", q1, tips)).reshape(len(coefficients), 3 * s)

    @one_blas_thread
    def extend_response(self, response: "MistunedResponse", f_end_hz: float, max_step: float = DEFAULT_MAX_STEP,
                        **continuation_options) -> "MistunedResponse":
        """``response`` continued from its end (or its start) to ``f_end_hz`` [Hz], beyond the
        range it covers, as one response: the wider range without recomputing the part known.
        The continuation starts from the stored solution at that end (same harmonics and
        samples); its scales are those of the whole new range."""
        validation.positive("f_end_hz", f_end_hz)
        w_new = 2 * np.pi * f_end_hz
        w_first, w_last = float(response.omega[0]), float(response.omega[-1])
        forward = np.sign(w_last - w_first)
        if forward * (w_new - w_last) > 0:
            end = -1
        elif forward * (w_first - w_new) > 0:
            end = 0
        else:
            lo, hi = sorted((w_first, w_last))
            raise ValueError(f"f_end_hz must lie outside the response's range {lo / (2 * np.pi):.6g}-"
                             f"{hi / (2 * np.pi):.6g} Hz (got {f_end_hz:.6g})")
        basis = response.basis
        system = self.hbm_system(basis.harmonics, basis.n_samples)
        x0 = response.coefficients[end].ravel()
        w0 = float(response.omega[end])
        lo, hi = sorted((w0, w_new))
        scales = np.maximum(self.unknown_scales(system, lo, hi), np.abs(response.coefficients).max(axis=0).ravel())
        piece = continuation(system.residual, x0, w0, w_new, x_scale=scales, factorize=system.factorize,
                             max_step=max_step, retry_x_scale=self.retry_scales(system, scales), **continuation_options)
        old = response.coefficients.reshape(len(response.omega), -1)
        n_old = len(response.omega)
        if end == -1:
            omega = np.concatenate([response.omega, piece.omega[1:]])
            x = np.vstack([old, piece.x[1:]])
            iterations = np.concatenate([response.iterations, piece.iterations[1:]])
            turning = np.concatenate([response.turning_points, piece.turning_points + n_old - 1])
        else:
            k = len(piece.omega) - 1
            omega = np.concatenate([piece.omega[:0:-1], response.omega])
            x = np.vstack([piece.x[:0:-1], old])
            iterations = np.concatenate([piece.iterations[:0:-1], response.iterations])
            turning = np.concatenate([k - piece.turning_points, response.turning_points + k])
        success = bool(response.success and piece.success)
        message, ran_out = (piece.message, piece.out_of_points) if not piece.success else (response.message, 0)
        branch = Branch(omega, x, iterations, success, message, np.sort(turning).astype(int), out_of_points=ran_out)
        return MistunedResponse.from_branch(self, system, branch, response.tuned_peak_amplitude)

    @one_blas_thread
    def solve_peaks(self, response: "MistunedResponse", candidates, direction: int = 0, tol: float = 1e-10,
                    max_iter: int = PEAK_MAX_ITERATIONS) -> list[tuple[float, float] | None]:
        """Local peaks of tip amplitudes u_``direction`` solved on the response curve, one per
        candidate ``(blade, index)``: blade ``blade``'s peak next to sample ``index`` of
        ``response`` (a local maximum of its sampled curve). Returns, per candidate, (peak [m],
        frequency [Hz]), or None where it is not solved (a fold next to the sample, a Newton
        solve that does not converge): :class:`bladedamp.hbm.peaks.PeakSolver`, whose tangents
        at the branch's points are shared by all blades. The branch only has to bracket the
        peak, so the continuation may take long steps there (the Monte Carlo's
        :data:`~bladedamp.studies.mistuning.MONTE_CARLO_MAX_STEP`)."""
        basis = response.basis
        system = self.hbm_system(basis.harmonics, basis.n_samples)
        solver = PeakSolver(system, response.omega, response.coefficients, tol, max_iter)
        nm, out = self.n_modes, []
        for blade, index in candidates:
            tip = first_harmonic_output(basis, system.n_dof, np.arange(nm) + blade * nm,
                                        self.blades[blade].shape("tip")[direction])
            solved = solver.solve(index, tip)
            out.append(None if solved is None else (solved[0], solved[1] / (2 * np.pi)))
        return out

    def full_assembly(self) -> "MistunedDisk":
        """This model (:class:`bladedamp.hbm.monodromy.AssemblyModel`; a full assembly when
        :attr:`has_period_map`)."""
        return self

    def assembly_coefficients(self, full, coefficients, basis) -> np.ndarray:
        """The solution ``coefficients`` (C * N,) or (C, N) as (C, N) (the model is its own
        assembly ``full``)."""
        return np.asarray(coefficients, dtype=float).reshape(basis.n_coeffs, full.n_dof)

    @property
    def has_period_map(self) -> bool:
        """Whether the monodromy method has a period map: every blade in the model
        (:class:`bladedamp.hbm.monodromy.PeriodMapModel`)."""
        return self.n_sector == self.n_blades

@dataclass
class MistunedResponse(DiskModelResponse):
    """Frequency response of every blade of a :class:`MistunedDisk`: the attributes of
    :class:`~bladedamp.diskmodel.DiskModelResponse` (``tip_amplitude`` (n_points, s, 3) [m], each blade's;
    the energies of the whole model; ``stop_check``, ``peak_check``) and

    damper_dissipation : (n_points, n_active_dampers) friction dissipation of each damper [J]
    damper_work_bound : (n_points, n_active_dampers) each damper's energy scale per period, the
        largest work its force and motion harmonics could do (HarmonicBasis.work_bound) [J]
    tuned_peak_amplitude : the tuned disk's peak u_x [m] if given (amplification factors)

    ``blade_peak_amplitudes`` / ``blade_peak_frequencies_hz`` are the (s,) blades' peaks and their
    frequencies (parabola-refined, :meth:`peaks`); ``peak_amplitude`` / ``peak_frequency_hz``, floats
    as on every response, are the largest of them and its frequency.
    """

    damper_dissipation: np.ndarray = None
    damper_work_bound: np.ndarray = None
    tuned_peak_amplitude: float | None = None

    @classmethod
    def from_branch(cls, disk: MistunedDisk, system: HarmonicBalanceSystem, branch, tuned_peak_amplitude=None):
        basis = system.basis
        C, N, s = basis.n_coeffs, system.n_dof, disk.n_sector
        X = branch.x.reshape(-1, C, N)
        tip = disk.output_amplitudes(X, basis).reshape(len(X), s, 3)
        nd = len(disk.active_dampers)
        exc, visc = cls.linear_energies(system, branch)
        diss, bound = np.zeros((len(branch.omega), nd)), np.zeros((len(branch.omega), nd))
        for i, (x, w) in enumerate(zip(branch.x, branch.omega)):
            if nd:
                c = system.couplings[0]
                local = (c.matrix @ x).reshape(C, c.element.n_local)
                force, _, _ = c.element.harmonic_forces(local, basis, w, False)
                diss[i] = basis.work_per_cycle(force, local).reshape(nd, -1).sum(axis=1)
                bound[i] = basis.work_bound(force, local).reshape(nd, -1).sum(axis=1)
        return cls(branch.omega, X, basis, disk.dof_names, branch.success, "", branch.iterations,
                   branch.turning_points, notes=(continuation_note(branch),), tip_amplitude=tip, excitation_work=exc,
                   viscous_dissipation=visc, dissipated_energy=diss.sum(axis=1), damper_dissipation=diss,
                   damper_work_bound=bound,
                   tuned_peak_amplitude=tuned_peak_amplitude, disk=disk, stopped_by=branch.stopped_by)

    @property
    def n_sector(self) -> int:
        return self.tip_amplitude.shape[1]

    def peaks(self, direction: int = 0, solve_within: float | None = None,
              tol: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
        """(peak tip amplitude [m], its frequency [Hz]) of every blade, (s,) each, parabola-refined.

        ``solve_within``: None, or a fraction; then every local maximum of a blade's sampled
        curve within that fraction of the largest blade peak (parabola-refined) is solved on the
        response curve by the peak condition (:meth:`MistunedDisk.solve_peaks`, Newton tolerance
        ``tol``) and the blade's peak is the largest of them (the parabola's where none is
        solved). The largest blade peak is then accurate even on a coarse branch."""
        out = [refined_peak(self.frequency_hz, self.tip_amplitude[:, k, direction]) for k in range(self.n_sector)]
        peak, freq = np.array([o[0] for o in out]), np.array([o[1] for o in out])
        if solve_within is None or len(self.omega) < 3:
            return peak, freq
        a = self.tip_amplitude[:, :, direction]
        # the margin is taken from the largest sample, not the largest parabola: on a coarse
        # branch a parabola through unevenly spaced samples can overshoot the curve (by a few
        # per cent), and would push the true largest peak out
        threshold = (1 - validation.in_range("solve_within", solve_within, 0.0, 1.0)) * a.max()
        local = (a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])
        interior = local & (a[1:-1] >= threshold)
        # and a blade whose parabola reaches the margin has its sampled maximum solved too
        highest = np.argmax(a, axis=0)
        for k in np.nonzero(peak >= threshold)[0]:
            if 0 < highest[k] < len(a) - 1:
                interior[highest[k] - 1, k] = True
        f = self.frequency_hz
        candidates = [(int(k), int(i) + 1) for i, k in zip(*np.nonzero(interior))]
        best = {k: [] if 0 < highest[k] < len(f) - 1 else [(peak[k], freq[k])] for k, _ in candidates}
        for (k, i), solved in zip(candidates, self.disk.solve_peaks(self, candidates, direction, tol)):
            # the sampled maximum is one of the local maxima unless it lies at an end of the range
            best[k].append(solved if solved is not None else refined_peak(f, a[:, k], i))
        for k, values in best.items():
            peak[k], freq[k] = max(values, key=lambda t: t[0])
        return peak, freq

    @property
    def blade_peak_amplitudes(self) -> np.ndarray:
        """(s,) peak first-harmonic tip amplitude u_x of every blade [m] (parabola-refined, :meth:`peaks`)."""
        return self.peaks()[0]

    @property
    def blade_peak_frequencies_hz(self) -> np.ndarray:
        """(s,) frequency of each blade's peak [Hz] (parabola-refined, as :attr:`blade_peak_amplitudes`)."""
        return self.peaks()[1]

    @property
    def peak_amplitude(self) -> float:
        """The largest peak first-harmonic tip amplitude u_x of any blade [m], the largest of
        :attr:`blade_peak_amplitudes` (nan for an empty branch)."""
        return float(self.peaks()[0].max()) if len(self.omega) else float("nan")

    @property
    def peak_frequency_hz(self) -> float:
        """The frequency of :attr:`peak_amplitude` [Hz] (nan for an empty branch)."""
        if not len(self.omega):
            return float("nan")
        peak, freq = self.peaks()
        return float(freq[np.argmax(peak)])

    def peak_curve(self) -> np.ndarray:
        """(n, s) first-harmonic tip amplitude |u_x| of every blade at every point [m]: the
        response's :attr:`peak_at_range_end` when any blade's largest lies at an end of the range."""
        return self.tip_amplitude[:, :, 0]

    def amplification(self, tuned_peak_amplitude: float | None = None) -> np.ndarray:
        """(s,) peak of each blade over the tuned disk's peak."""
        ref = self.tuned_peak_amplitude if tuned_peak_amplitude is None else tuned_peak_amplitude
        if ref is None:
            raise ValueError("tuned_peak_amplitude is needed for amplification factors (give it here or to frequency_response)")
        return self.blade_peak_amplitudes / validation.positive("tuned_peak_amplitude", ref)

    def plot(self, ax=None, *, tuned=None, direction: int = 0, highlight=None, title: str | None = None,
             measured=None):
        """Tip amplitude of every blade [mm] over frequency [Hz] (the paper's Figs. 13-17);
        ``tuned``: a tuned DiskResponse drawn as a thick dashed line; ``highlight``: blade
        indices (0-based) drawn in colour and labelled (default: largest and smallest peak);
        ``measured``: a measurement or its file drawn beside them in mm
        (:func:`bladedamp.measurement.draw_measurement`; an FRF times the excitation force)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 4.5))
        peaks = self.blade_peak_amplitudes
        if highlight is None:
            highlight = sorted({int(np.argmax(peaks)), int(np.argmin(peaks))})
        from . import palette

        for k in range(self.n_sector):
            if k in highlight:
                ax.plot(self.frequency_hz, 1e3 * self.tip_amplitude[:, k, direction], lw=1.6,
                        color=palette.series(list(highlight).index(k)),
                        label=f"blade {k + 1} (peak {1e3 * peaks[k]:.3f} mm)")
            else:
                ax.plot(self.frequency_hz, 1e3 * self.tip_amplitude[:, k, direction], color="0.6", lw=0.8)
        if tuned is not None:
            ax.plot(tuned.frequency_hz, 1e3 * tuned.tip_amplitude[:, direction], "k--", lw=2, label="tuned")
        elif self.tuned_peak_amplitude is not None:
            ax.axhline(1e3 * self.tuned_peak_amplitude, color="k", ls="--", lw=1.5, label="tuned peak")
        if title:
            ax.set_title(title)
        return self.finish_plot(ax, direction, measured, legend=dict(fontsize=8))
