"""Harmonic balance residual of a linear structure with nonlinear elements (AFT).

    R(x, Omega) = A(Omega) x + sum_e T_e^T f_e(T_e x, Omega) - f_ext(Omega) = 0

``x`` holds the harmonic coefficients of all degrees of freedom (harmonic-major, see
:mod:`bladedamp.hbm.fourier`), ``A`` the real-form dynamic stiffness built from M, D, K,
``T_e`` the (real-form, possibly harmonic-dependent, e.g. cyclic) map from the structure to
the local coordinates of element ``e`` and ``f_e`` its AFT forces with their analytic
Jacobian. Because the same ``T_e`` maps displacements out and forces back, the Jacobian
``T^T (df/dw) T`` and the energy balance are exact by construction.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Callable, Protocol

import numpy as np
import scipy.sparse as sp

from .fourier import HarmonicBasis
from .linsolve import SPARSE_MIN_UNKNOWNS, dense_array, prefers_sparse
from .linsolve import factorize as lu_factorize


class NonlinearElement(Protocol):
    """What an element provides to the harmonic balance (the contract, with units, shapes and the
    sign convention, is in :mod:`bladedamp.hbm.elements`; subclass
    :class:`~bladedamp.hbm.elements.TimeDomainElement` to give only the force in time)."""

    n_local: int

    def harmonic_forces(self, local: np.ndarray, basis: HarmonicBasis, omega: float, jacobian: bool = True):
        """Return ``(force (C, n_local), d force / d local (C*n_local, C*n_local) or None,
        d force / d omega (C*n_local,) or None)``; force conjugate to ``local`` (restoring)."""
        ...


# Coupling.support: the restricted map is used where it saves at least this many multiply-adds
# in T^T (dF/dw) T; below, the two fancy-indexed copies (~9 us) cost more than they save
# (timings: benchmarks/README.md, 'Moved from the package's docstrings', hbm/system.py)
PRUNE_MIN_SAVING = 200_000


@dataclass
class Coupling:
    """An element and the real-form map ``matrix`` (C*n_local, C*n_dof) from the structure to it.

    ``matrix @ x`` (x the structure's harmonic coefficients, harmonic-major) are the element's
    local coefficients, and ``matrix.T`` carries its restoring forces back. ``name`` labels it.

    A dense map often has rows or columns that are identically zero: local directions no
    motion of the structure reaches (a point contact's eta and zeta in a tangential-only
    joint), unknowns the element does not see (the modes or masses away from it). The forces
    and the Jacobian are carried back (:meth:`add_forces`, :meth:`add_jacobian`) through the
    map restricted to its other rows and columns (:meth:`support`, found once per matrix):
    the same products without the terms that are exactly zero.
    """

    element: NonlinearElement
    matrix: np.ndarray
    name: str = ""
    _support: tuple | None = field(default=None, init=False, repr=False, compare=False)

    def support(self):
        """``(rows, columns, reduced)`` of a dense map with identically zero rows or columns: the
        indices (int arrays) of its rows and columns with a nonzero entry and ``reduced`` =
        ``matrix[rows][:, columns]`` (len(rows), len(columns)); None where the restricted
        products would not be cheaper (no zero rows or columns, fewer than PRUNE_MIN_SAVING
        multiply-adds saved per Jacobian) or for a sparse map. Found once for the matrix it is
        asked of."""
        if self._support is None or self._support[0] is not self.matrix:
            structure = None
            if not sp.issparse(self.matrix):
                nonzero = np.asarray(self.matrix) != 0
                rows, cols = np.flatnonzero(nonzero.any(axis=1)), np.flatnonzero(nonzero.any(axis=0))
                (m, n), (p, q) = nonzero.shape, (rows.size, cols.size)
                if (m * m * n + n * m * n) - (p * p * q + q * p * q) >= PRUNE_MIN_SAVING:
                    # flat indices of the (rows, rows) block of dF/dw and the (cols, cols) block
                    # of the Jacobian: take / flat assignment are ~3x faster than np.ix_ indexing
                    structure = (rows, cols, np.ascontiguousarray(self.matrix[np.ix_(rows, cols)]),
                                 (rows[:, None] * m + rows[None, :]).ravel(),
                                 (cols[:, None] * n + cols[None, :]).ravel())
            self._support = (self.matrix, structure)
        return None if self._support[1] is None else self._support[1][:3]

    def add_forces(self, out: np.ndarray, force: np.ndarray) -> None:
        """``out += matrix.T @ force``, in place: ``force`` (C*n_local,) the element's (restoring)
        force coefficients or their omega-derivative [N], ``out`` (C*n_dof,) ndarray."""
        support = self.support()
        if support is None:
            out += self.matrix.T @ force
            return
        rows, cols, reduced = support
        out[cols] += reduced.T @ force[rows]

    def add_jacobian(self, out, jac):
        """``out + matrix.T @ jac @ matrix``: ``jac`` (C*n_local, C*n_local) the element's
        d force / d local [N/m], ``out`` (C*n_dof, C*n_dof) dense (added in place, returned)
        or scipy.sparse (a new sparse matrix is returned)."""
        if sp.issparse(out):
            T = sp.csr_matrix(self.matrix)
            return out + T.T @ sp.csr_matrix(jac) @ T
        support = self.support()
        if support is None or sp.issparse(jac):
            out += self.matrix.T @ jac @ self.matrix
            return out
        rows, cols, reduced, local_block, block = self._support[1]
        product = reduced.T @ np.asarray(jac).take(local_block).reshape(rows.size, rows.size) @ reduced
        if out.flags.c_contiguous:
            flat = out.reshape(-1)                # a view: the block is added in place
            flat[block] += product.ravel()
        else:
            out[np.ix_(cols, cols)] += product
        return out


@dataclass
class HarmonicBalanceSystem:
    """Residual, analytic Jacobian and omega-derivative of a harmonic balance problem.

    Parameters
    ----------
    basis : HarmonicBasis
    mass, damping, stiffness : (n, n) arrays [kg, N s/m, N/m] (or modal equivalents)
    excitation : callable omega -> (f (C*n,), df/domega (C*n,)), harmonic-major
    couplings : nonlinear elements with their maps
    static_stiffness : optional (n, n) stiffness acting on the static harmonic only (e.g. to fix
        a position that nothing else fixes statically) [N/m]
    storage : "auto" (default), "dense" or "sparse": how the Jacobian is assembled and
        factorised, whatever the format (ndarray or scipy.sparse) of the matrices given. "auto"
        chooses by size and fill (:func:`~bladedamp.hbm.linsolve.prefers_sparse`): dense below
        SPARSE_MIN_UNKNOWNS unknowns (decided at the first residual); from there on the first
        Jacobian is assembled sparse and its count of nonzero entries decides, once, for every
        later evaluation (above SPARSE_MAX_FILL dense, that first evaluation repeated densely).
        Until the choice is made :attr:`sparse` follows the matrices given.

    A dense and a sparse assembly of the same system give the same residual and Jacobian to
    rounding.
    """

    basis: HarmonicBasis
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    excitation: Callable[[float], tuple[np.ndarray, np.ndarray]]
    couplings: list[Coupling] = field(default_factory=list)
    static_stiffness: np.ndarray | None = None
    storage: str = "auto"
    _sparse_parts: tuple | None = field(default=None, init=False, repr=False)
    _dense_parts: tuple | None = field(default=None, init=False, repr=False)
    _sparse_choice: bool | None = field(default=None, init=False, repr=False)
    _assembly_couplings: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    _storages = ("auto", "dense", "sparse")

    @property
    def sparse(self) -> bool:
        """Whether the Jacobian is assembled with scipy.sparse matrices: as :attr:`storage` says;
        for "auto" the choice once made (at the first residual), before it whether any of the
        matrices given is sparse. Raises ValueError for a storage other than "auto", "dense",
        "sparse"."""
        if self.storage not in self._storages:
            raise ValueError(f"storage must be one of {self._storages} (got {self.storage!r})")
        if self.storage != "auto":
            return self.storage == "sparse"
        if self._sparse_choice is not None:
            return self._sparse_choice
        return any(sp.issparse(m) for m in (self.mass, self.damping, self.stiffness)) or \
            any(sp.issparse(c.matrix) for c in self.couplings)

    def _assembled_couplings(self, sparse: bool) -> list:
        """The couplings with their maps in the assembly's format (scipy CSR for a sparse one,
        ndarray for a dense one), converted once; the same objects where they already are."""
        if sparse not in self._assembly_couplings:
            self._assembly_couplings[sparse] = [
                c if sp.issparse(c.matrix) == sparse else
                Coupling(c.element, sp.csr_matrix(c.matrix) if sparse else c.matrix.toarray(), c.name)
                for c in self.couplings]
        return self._assembly_couplings[sparse]

    @property
    def n_dof(self) -> int:
        if sp.issparse(self.mass):
            return self.mass.shape[0]
        return np.atleast_2d(self.mass).shape[0]

    @property
    def n_unknowns(self) -> int:
        return self.n_dof * self.basis.n_coeffs

    def _sparse_dynamic_stiffness(self, omega: float):
        """Sparse A = K_0 - Omega^2 M_2 + Omega G and dA/dOmega, the three parts assembled once
        (harmonic-major Kronecker products, as :meth:`HarmonicBasis.dynamic_stiffness`)."""
        if self._sparse_parts is None:
            basis = self.basis
            C = basis.n_coeffs
            mass, damping, stiffness = (sp.csr_matrix(m) for m in (self.mass, self.damping, self.stiffness))
            K0 = sp.kron(sp.identity(C), stiffness, format="csc")
            if self.static_stiffness is not None and basis.has_static:
                sel = sp.csr_matrix(([1.0], ([basis.cos_index(0)], [basis.cos_index(0)])), shape=(C, C))
                K0 = K0 + sp.kron(sel, sp.csr_matrix(self.static_stiffness), format="csc")
            M2 = sp.kron(sp.diags(basis.order.astype(float) ** 2), mass, format="csc")
            G = sp.kron(sp.csr_matrix(basis.derivative), damping, format="csc")
            self._sparse_parts = (K0.tocsc(), M2.tocsc(), G.tocsc())
        K0, M2, G = self._sparse_parts
        return (K0 - omega ** 2 * M2 + omega * G).tocsc(), (-2 * omega * M2 + G).tocsc()

    def with_matrices(self, damping, stiffness) -> "HarmonicBalanceSystem":
        """A shallow copy of this system with other damping and stiffness matrices (n_dof, n_dof)
        (the units of :attr:`damping` and :attr:`stiffness`); the basis, mass, excitation,
        couplings and static stiffness are shared, the cached Omega-independent parts of the
        dynamic stiffness are formed anew on first use. This system is left as it is."""
        other = copy.copy(self)
        other.damping, other.stiffness = damping, stiffness
        other._sparse_parts = other._dense_parts = None
        other._assembly_couplings = dict(self._assembly_couplings)
        return other

    def dynamic_stiffness(self, omega: float, derivative: bool = True):
        """(A, dA/domega) of the linear part at ``omega`` [rad/s] (the residual's variable): the
        harmonic dynamic stiffness of M, D, K with the static stiffness on the static harmonic;
        dense (C*n, C*n) ndarrays (new arrays at each call; dA/domega None without
        ``derivative``), or scipy.sparse for a sparse system."""
        return self._dynamic_stiffness(omega, derivative, self.sparse)

    def _dynamic_stiffness(self, omega, derivative, sparse):
        """:meth:`dynamic_stiffness` assembled sparse or dense (``sparse``)."""
        if sparse:
            return self._sparse_dynamic_stiffness(omega)
        if self._dense_parts is None:      # the Omega-independent parts and their nonzero pattern, built once
            parts = self.basis.dynamic_stiffness_parts(*(dense_array(m) for m in (self.mass, self.damping, self.stiffness)))
            self._dense_parts = (parts, self.basis.dynamic_stiffness_pattern(parts))
        A, dA = self.basis.dynamic_stiffness(omega, None, None, None, self._dense_parts[0], derivative,
                                             self._dense_parts[1])
        if self.static_stiffness is not None and self.basis.has_static:
            n = self.n_dof
            j = self.basis.cos_index(0)
            A[j * n:(j + 1) * n, j * n:(j + 1) * n] += dense_array(self.static_stiffness)
        return A, dA

    def linear_solution(self, omega: float) -> np.ndarray:
        """Solution without the nonlinear elements (initial guess, scaling)."""
        A, _ = self.dynamic_stiffness(omega)
        f, _ = self.excitation(omega)
        if sp.issparse(A):
            from scipy.sparse.linalg import splu
            return splu(A.tocsc()).solve(f)
        return np.linalg.lstsq(A, f, rcond=None)[0]

    def add(self, element: NonlinearElement, matrix, name: str = "") -> "HarmonicBalanceSystem":
        """A new system with one more nonlinear element: ``element`` seen through the real-form
        map ``matrix`` (C*n_local, C*n_dof, e.g. ``TunedDisk.point_map``); this system is left
        as it is. The new system is a plain :class:`HarmonicBalanceSystem` (the generic
        residual): a model's specialised assembly (the mistuned disk's) knows only its own
        elements, so it is not carried over; the residual is the same to rounding.

        Raises ValueError if the map's shape does not fit ``element.n_local`` and this system.
        """
        return with_element(self, element, matrix, name)

    def factorize(self, A):
        """The linear solver for this system's Newton and arc-length steps: ``A`` (dR/dx, or it
        bordered by one row and column) -> ``solve(b)``. Dense or sparse LU here; assemblies
        override it with a structured one."""
        return lu_factorize(A)

    def residual(self, x: np.ndarray, omega: float, jacobian: bool = True):
        """``(R, dR/dx, dR/domega)``; the last two are None when ``jacobian`` is False. The
        Jacobian is a dense ndarray or a scipy CSC matrix as :attr:`sparse` says (for
        :attr:`storage` "auto" chosen here, see the class)."""
        basis = self.basis
        C = basis.n_coeffs
        sparse = self.sparse
        choosing = self.storage == "auto" and self._sparse_choice is None
        if choosing:
            if self.n_unknowns < SPARSE_MIN_UNKNOWNS:
                self._sparse_choice = sparse = False
                choosing = False
            elif not jacobian:
                choosing = False            # decided by the first Jacobian; until then as given
            else:
                sparse = True               # assembled sparse, its nonzeros counted below
        A, dA = self._dynamic_stiffness(omega, jacobian, sparse)
        f, df = self.excitation(omega)
        R = A @ x - f
        J = (A.copy() if sparse else A) if jacobian else None       # dense A is new at each call: J grows in it
        Rw = dA @ x - df if jacobian else None
        for c in self._assembled_couplings(sparse):
            local = (c.matrix @ x).reshape(C, c.element.n_local)
            force, jac, domega = c.element.harmonic_forces(local, basis, omega, jacobian)
            c.add_forces(R, force.ravel())
            if jacobian:
                J = c.add_jacobian(J, jac)
                if domega is not None:
                    c.add_forces(Rw, domega)
        if sparse and jacobian:
            J = J.tocsc()
        if choosing:
            self._sparse_choice = prefers_sparse(J.shape[0], J.count_nonzero())
            if not self._sparse_choice:
                return self.residual(x, omega, jacobian)          # this evaluation again, dense
        return R, J, Rw

    def excitation_work(self, x: np.ndarray, omega: float) -> float:
        """Work of the excitation on the structure per period [J]."""
        C = self.basis.n_coeffs
        f, _ = self.excitation(omega)
        return float(np.sum(self.basis.work_per_cycle(f.reshape(C, -1), x.reshape(C, -1))))

    def viscous_dissipation(self, x: np.ndarray, omega: float) -> float:
        """Energy dissipated by the viscous damping per period [J] (oint v^T D dx)."""
        C = self.basis.n_coeffs
        X = x.reshape(C, -1)
        velocity = omega * (self.basis.derivative @ X)
        damping = self.damping if sp.issparse(self.damping) else np.atleast_2d(self.damping)
        return float(np.sum(self.basis.work_per_cycle(np.asarray((damping @ velocity.T).T), X)))

    def element_dissipation(self, x: np.ndarray, omega: float) -> list[float]:
        """Energy absorbed by each nonlinear element per period [J] (oint f . dw)."""
        return self.element_energies(x, omega)[0]

    def element_work_bound(self, x: np.ndarray, omega: float) -> list[float]:
        """Each nonlinear element's energy scale per period [J]: the largest work its force and
        motion harmonics could do (:meth:`HarmonicBasis.work_bound`)."""
        return self.element_energies(x, omega)[1]

    def element_energies(self, x: np.ndarray, omega: float) -> tuple[list[float], list[float]]:
        """(dissipation, work bound) of each nonlinear element per period [J] (see
        :meth:`element_dissipation`, :meth:`element_work_bound`), from one evaluation of its forces."""
        C = self.basis.n_coeffs
        dissipation, bound = [], []
        for c in self.couplings:
            local = (c.matrix @ x).reshape(C, c.element.n_local)
            force, _, _ = c.element.harmonic_forces(local, self.basis, omega, False)
            dissipation.append(float(np.sum(self.basis.work_per_cycle(force, local))))
            bound.append(float(np.sum(self.basis.work_bound(force, local))))
        return dissipation, bound


def linear_forces(basis: HarmonicBasis, x: np.ndarray, omega: float, mass=None, damping=None, stiffness=None,
                  static_stiffness=None) -> np.ndarray:
    """``A(Omega) x`` (C*m,) of the given matrices (m, n) (dense or scipy.sparse, all with the same
    m rows; None: zero) without forming A: the same dynamic stiffness as
    :meth:`HarmonicBasis.dynamic_stiffness` (K_0 - Omega^2 M_2 + Omega G, harmonic-major) with
    ``static_stiffness`` on the static harmonic, applied to the coefficients ``x`` (C*n,) [m] at
    ``omega`` [rad/s]. A is linear in the matrices, so with their derivatives in a parameter this
    is dR/dp of the linear part (:mod:`bladedamp.hbm.sensitivity`) [N per unit of the parameter];
    with k such derivatives stacked (m = k n) the k products at once, (C, k, n) harmonic-major."""
    C = basis.n_coeffs
    X = np.asarray(x, dtype=float).reshape(C, -1)
    given = [m for m in (stiffness, mass, damping, static_stiffness) if m is not None]
    out = np.zeros((C, given[0].shape[0] if given else X.shape[1]))

    def times(matrix, Y):                  # Y @ matrix.T, matrix dense or sparse
        return np.asarray((matrix @ Y.T).T)

    if stiffness is not None:
        out += times(stiffness, X)
    if mass is not None:
        out -= omega ** 2 * times(mass, basis.order.astype(float)[:, None] ** 2 * X)
    if damping is not None:
        out += omega * times(damping, basis.derivative @ X)
    if static_stiffness is not None and basis.has_static:
        j = basis.cos_index(0)
        out[j] += times(static_stiffness, X[j:j + 1])[0]
    return out.ravel()


def with_element(system: HarmonicBalanceSystem, element: NonlinearElement, matrix, name: str = "") -> HarmonicBalanceSystem:
    """``system`` with ``element`` added through the real-form map ``matrix`` (see
    :meth:`HarmonicBalanceSystem.add`); ``system`` itself is not changed."""
    n_local = getattr(element, "n_local", None)
    if not callable(getattr(element, "harmonic_forces", None)) or not isinstance(n_local, (int, np.integer)) \
            or n_local < 1:
        raise TypeError(f"element must have an integer n_local >= 1 and a method harmonic_forces "
                        f"(see bladedamp.hbm.elements; got {type(element).__name__})")
    C = system.basis.n_coeffs
    shape = (C * int(n_local), system.n_unknowns)
    if not sp.issparse(matrix):
        matrix = np.asarray(matrix, dtype=float)
    if matrix.shape != shape:
        raise ValueError(f"matrix of element {name or type(element).__name__!r} must be (C*n_local, C*n_dof) = "
                         f"{shape} for this system (C = {C} coefficients, n_local = {n_local}, "
                         f"n_dof = {system.n_dof}); got {matrix.shape}")
    return HarmonicBalanceSystem(system.basis, system.mass, system.damping, system.stiffness, system.excitation,
                                 list(system.couplings) + [Coupling(element, matrix, name)], system.static_stiffness,
                                 system.storage)
