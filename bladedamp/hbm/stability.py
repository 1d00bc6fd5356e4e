"""Stability of harmonic balance solutions by Hill's method.

A periodic solution x(t) of ``M x'' + D x' + K x + f(x) = F(t)`` is perturbed by
``dx(t) = e^{lambda t} p(tau)``, ``tau = Omega t``, with ``p`` periodic and expanded in the same
harmonic basis as ``x``. Linearising about the solution and balancing the harmonics gives the
quadratic eigenvalue problem of the Hill matrix (Lazarus & Thomas 2010; Krack & Gross 2019,
Sec. 3.6)::

    (J + lambda Delta_1 + lambda^2 Delta_2) p = 0,
    Delta_1 = 2 Omega (nabla (x) M) + I (x) D,      Delta_2 = I (x) M,

where ``J = dR/dx`` is the harmonic balance Jacobian (which already holds ``-Omega^2 nabla^2 (x)
M + Omega nabla (x) D + K`` and the AFT linearisation of the nonlinear forces), ``nabla`` the
derivative matrix of the basis and ``(x)`` the harmonic-major Kronecker product of
:mod:`bladedamp.hbm.fourier`. Its ``2 n C`` eigenvalues are the Floquet exponents of the
solution, each repeated with shifts ``i k Omega`` (an exponent is defined modulo ``i Omega``).

Selection of the ``2 n`` physical exponents (n DOF), by the eigenvectors (Lazarus & Thomas
2010 note that the truncation error grows from the centre of the spectrum outward; Guillot,
Lazarus, Thomas, Vergez & Cochelin 2020 select by the eigenvectors). An eigenvector ``p`` is
written in complex exponentials ``e^{i k tau}``, ``k = -H..H``, with weight centroid
``kbar = sum k |p_k|^2 / sum |p_k|^2``. The perturbation ``e^{lambda t} p`` then oscillates at
its own frequency ``Im lambda + kbar Omega``, the same for every copy ``lambda - i k Omega``, so
``mu = Re lambda + i (Im lambda + kbar Omega)`` names the exponent without the ambiguity modulo
``i Omega``. Copies are visited best-centred first (smallest |kbar|, then smallest |Im lambda|:
the classic imaginary-part criterion) and one is kept per distinct ``mu``. This also works for
a basis without the static term such as the paper's ``(1,)``, where every eigenvector sits at
``k = +-1`` and the smallest-|Im lambda| rule alone keeps two copies of a low mode and loses a
high one. Only the real parts decide stability.

Resolved exponents only. The truncated Hill matrix represents perturbations up to the basis's
highest harmonic H: its eigenvalues converge from the centre of the spectrum outward (Lazarus &
Thomas 2010), and an exponent whose perturbation oscillates faster than about (H + 1/2) Omega
(|Im lambda + kbar Omega|, kbar the eigenvector's weight centroid) is not resolved. For friction
there is a second reason: the AFT Jacobian is the linearisation of the hysteretic contact forces
for periodic perturbations, exact as lambda -> 0 (where folds, branch points and the onset of
instability are) but not for fast ones, whose reversal points move with e^{lambda t}. The stiff
contact modes of a damper (the 1 g cylinder on its contacts: 13 000-26 000 rad/s, 20-40 Omega at
1F) are such: with the contacts slipping, the one-harmonic Hill matrix gives them real parts
up to +3500 1/s, a growth that a time integration of the same disk does not show. Such
exponents are kept in ``unresolved`` and do not decide stability.

A solution is *stable* when every resolved exponent has a negative real part (to a tolerance
relative to Omega). A fold (a real exponent through zero) and a Neimark-Sacker bifurcation (a
complex pair through the imaginary axis) are told apart by the imaginary part of the exponent
that crosses.

Hysteretic elements (friction). Hill's method needs the linearised force to be a linear
time-periodic operator of the perturbation. A smooth or memoryless element (a cubic spring, a
unilateral spring) gives one, k(t) dx(t), and the method is exact. A friction contact does not:
in stick the force perturbation is k_T (dx(t) - dx(t_r)), with memory of the last reversal
t_r, so for a perturbation e^{lambda t} p(tau) the linearisation depends on lambda through
e^{-lambda (t - t_r)}. The AFT Jacobian is its value at lambda = 0, and the Hill matrix built
on it loses the copy structure of the exponents (the copies lambda +- i Omega, for which the
memory factor is of order 1, get different real parts). On the 1-DOF Jenkins oscillator,
Hill's method on its AFT Jacobian gives -c / 2m, the viscous decay alone, where the monodromy
matrix of the time integration (:mod:`bladedamp.hbm.monodromy`, memory included) gives a
decay many times faster (the friction damps the perturbation too); taking every distinct copy
instead of the 2 n best-centred ones, Hill can even show positive real parts where a time
integration started on the HBM solution returns to it (numbers: benchmarks/README.md, 'Moved
from the package's docstrings', hbm/stability.py). So
for systems with hysteretic elements, stability is decided by the one statement that holds
exactly: at lambda = 0 the linearisation is the AFT Jacobian J, and the characteristic function
P(lambda) = det(J(lambda) + lambda Delta_1 + lambda^2 Delta_2) is real on the real axis with
P(+inf) > 0 (M positive definite); so **det J < 0 proves a real positive exponent: unstable**.
Between two such sign changes (folds, branch points) a branch's stability is that of its
neighbour: stable where the branch starts from the linear limit and keeps det J > 0. A
Neimark-Sacker bifurcation (or a period doubling) of a friction-damped system cannot be found
this way; ``method="monodromy"`` (:mod:`bladedamp.hbm.monodromy`: the Floquet multipliers of
the period map of a time integration started on the HBM solution, the slider positions part of
the state) finds all three, for the models it has a period map for (the FrictionOscillator, and
the bladed disk: a TunedDisk's sector solution written out on the full assembly, or a
full-assembly MistunedDisk, by the time domain's integrator of the assembly; its cost is
~100-1600 x the HBM solve per point, see that module).
The result says which method was used (``method``: "hill", "determinant sign" or "monodromy").
The default ("auto") stays Hill / determinant sign: the monodromy integrates 7 trajectories
over one period per point, several times the cost, and on the 1-DOF friction oscillator it
puts the folds where det J does (within a point).

For a tuned disk computed by cyclic symmetry the perturbations are those of the same
travelling-wave family; the full assembly (:class:`~bladedamp.mistuned.MistunedDisk`) covers
all nodal diameters. Its exponents hold the sector's, and can hold more: on a 4-blade ring of
blades with cubic tip springs linked tip to tip, the assembly
loses stability one point before the sector's fold, to other nodal diameters, and a time
integration of the assembly leaves the travelling wave there. Conversely, a fold of the
travelling wave that every blade makes at once (uncoupled blades) is an even number of real
crossings for the assembly: det J keeps its sign (and the bordered determinant flips, a branch
point), so the determinant sign alone does not see it there.
"""
from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from .linsolve import dense_array, one_blas_thread, permutation_sign


def hill_matrices(system, omega: float):
    """``(Delta_1, Delta_2)`` of the Hill quadratic eigenvalue problem (see module docstring)
    at ``omega`` [rad/s]; dense or scipy.sparse like the system's matrices; each (N, N) with
    N = ``system.n_unknowns``."""
    basis = system.basis
    C = basis.n_coeffs
    if system.sparse:
        mass = sp.csr_matrix(system.mass)
        damping = sp.csr_matrix(system.damping)
        nabla = sp.csr_matrix(basis.derivative)
        eye = sp.identity(C, format="csr")
        d1 = 2 * omega * sp.kron(nabla, mass) + sp.kron(eye, damping)
        d2 = sp.kron(eye, mass)
        return d1.tocsc(), d2.tocsc()
    mass, damping = dense_array(system.mass), dense_array(system.damping)     # given sparse, assembled dense
    d1 = 2 * omega * np.kron(basis.derivative, mass) + np.kron(np.eye(C), damping)
    d2 = np.kron(np.eye(C), mass)
    return d1, d2


def harmonic_weights(vectors: np.ndarray, basis, n_dof: int):
    """``(k, weight)``: the exponential harmonic numbers ``k`` (K,) and the weight (K, m) of
    each of the ``m`` eigenvectors (N, m) on ``e^{i k tau}`` (summed over the DOFs, normalised to
    1 per vector)."""
    C = basis.n_coeffs
    P = vectors.reshape(C, n_dof, -1)
    ks, rows = [], []
    for h in basis.harmonics:
        j = basis.cos_index(h)
        if h == 0:
            ks.append(0)
            rows.append(np.sum(np.abs(P[j]) ** 2, axis=0))
            continue
        a, b = P[j], P[j + 1]
        for sign in (1, -1):
            # a cos + b sin = (a - i b)/2 e^{i h tau} + (a + i b)/2 e^{-i h tau}
            ks.append(sign * h)
            rows.append(np.sum(np.abs(0.5 * (a - 1j * sign * b)) ** 2, axis=0))
    weight = np.array(rows)
    weight /= np.maximum(weight.sum(axis=0, keepdims=True), 1e-300)
    return np.array(ks), weight


def hysteretic(system) -> bool:
    """Whether any nonlinear element of ``system`` may have memory (does not declare
    ``memoryless = True``, see :mod:`bladedamp.hbm.elements`)."""
    return any(not getattr(c.element, "memoryless", False) for c in system.couplings)


def determinant_sign(A) -> int:
    """Sign (+1, -1, 0) of det A for a dense ndarray or a scipy.sparse matrix (by its LU)."""
    if sp.issparse(A):
        from scipy.sparse.linalg import splu

        try:
            lu = splu(sp.csc_matrix(A))
        except RuntimeError:           # exactly singular
            return 0
        diag = lu.U.diagonal()
        sign = np.prod(np.sign(diag))
        for perm in (lu.perm_r, lu.perm_c):
            sign *= permutation_sign(perm.astype(np.intp))
        return int(sign)
    sign, _ = np.linalg.slogdet(np.asarray(A))
    return int(np.sign(sign))


@dataclass
class FloquetResult:
    """Floquet exponents of one harmonic balance solution.

    Attributes
    ----------
    exponents : (k,) the physical exponents mu resolved by the basis [1/s], largest real part
        first, each with its perturbation's own frequency Im mu (see :func:`physical_exponents`;
        an exponent is defined modulo i Omega, this is the representative the motion shows)
    all_exponents : (m,) every finite eigenvalue of the Hill problem that was computed [1/s]
    omega : excitation angular frequency [rad/s]
    stable : every selected exponent has Re lambda < ``tolerance`` * omega
    tolerance : the relative threshold on Re lambda / omega used for ``stable``
    method : "hill" (every element memoryless: the exponents decide), "determinant sign"
        (hysteretic elements: ``stable`` is det J > 0, exponents are not computed; see the
        module docstring) or "monodromy" (the multipliers of the period map decide; ``exponents``
        are log(mu) / T of its nonzero multipliers, Im in (-Omega/2, Omega/2])
    jacobian_sign : sign of det(dR/dx) at the point
    floquet_multipliers : (k,) the multipliers exp(lambda T) of ``exponents`` from the raw Hill
        eigenvalues lambda (the centroid frequency of ``exponents`` is a label, not a copy
        lambda + i k Omega, so exp(exponents T) has the right modulus but not the right phase);
        for "monodromy" the eigenvalues of the monodromy matrix, largest modulus first, zeros
        included; None for the determinant sign
    periodicity_error : for method "monodromy": |P(z) - z| / the orbit's largest |x|, the HBM
        solution's distance from a periodic orbit of the discretised period map
    eigensolver : for method "hill": "dense" (every eigenvalue of the (2N, 2N) pencil by QZ) or
        "shift-invert" (a sparse Jacobian and fewer than half the eigenvalues wanted: the
        ``n_near`` nearest to zero by ARPACK); "" for the other methods
    unresolved : (2n - k,) physical exponents whose perturbation frequency lies beyond the basis's
        highest harmonic H, |Im mu| > (H + 1/2) Omega: not resolved by the
        truncated Hill matrix, so they do not decide ``stable`` (see the module docstring)
    """

    exponents: np.ndarray
    all_exponents: np.ndarray
    omega: float
    stable: bool
    tolerance: float
    unresolved: np.ndarray = None
    method: str = "hill"
    jacobian_sign: int = 0
    floquet_multipliers: np.ndarray = None
    periodicity_error: float = float("nan")
    eigensolver: str = ""

    @property
    def max_real(self) -> float:
        """Largest real part of the selected exponents [1/s]."""
        return float(self.exponents.real.max()) if self.exponents.size else float("nan")

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers (see ``floquet_multipliers``)."""
        if self.floquet_multipliers is not None:
            return self.floquet_multipliers
        return np.exp(self.exponents * 2 * np.pi / self.omega)

    def unstable_kind(self) -> str:
        """'' if stable; 'real' when the leading unstable exponent is real (a fold or a branch
        point nearby; always so for the determinant-sign method), 'period doubling', 'complex'
        when it is a complex pair (Neimark-Sacker); 'unresolved' when no exponent is resolved
        by the basis (then ``stable`` is False: not shown stable)."""
        if self.stable:
            return ""
        if self.method == "determinant sign":
            return "real"
        if not self.exponents.size:
            return "unresolved"
        kind = multiplier_crossing(self.multipliers[:1] if self.method == "hill" else self.multipliers)
        return {"fold": "real", "neimark-sacker": "complex"}.get(kind, kind)


REAL_PHASE_TOLERANCE = 1e-3   # a multiplier within this fraction of a cycle of the real axis is real


def multiplier_crossing(multipliers: np.ndarray) -> str:
    """Kind of the largest multiplier (by modulus) of ``multipliers`` (k,) complex: 'fold' (real,
    positive: a turning point or a branch point), 'period doubling' (real, negative) or
    'neimark-sacker' (a complex pair); real means within ``REAL_PHASE_TOLERANCE`` of a cycle of
    the real axis. A real multiplier crosses the unit circle alone, a complex one with its
    conjugate."""
    lead = multipliers[np.argmax(np.abs(multipliers))]
    phase = np.mod(np.angle(lead) / (2 * np.pi), 1.0)
    if min(phase, 1 - phase) < REAL_PHASE_TOLERANCE:
        return "fold"
    if abs(phase - 0.5) < REAL_PHASE_TOLERANCE:
        return "period doubling"
    return "neimark-sacker"


STABILITY_TOLERANCE = 1e-7   # Re lambda / Omega below which an exponent counts as not growing
DUPLICATE_TOLERANCE = 1e-4   # copies of one exponent agree in (Re, own frequency) to this x Omega


def physical_exponents(values: np.ndarray, vectors: np.ndarray, basis, n_dof: int, omega: float,
                       n_select: int | None = None) -> np.ndarray:
    """The physical exponents (at most ``n_select``; default all distinct ones) among the Hill eigenpairs (``values`` (m,),
    ``vectors`` (N, m)), each written with its perturbation's own frequency:
    ``mu = Re lambda + i (Im lambda + kbar Omega)``, kbar the eigenvector's weight centroid on
    the exponential harmonics (the same for every copy lambda - i k Omega of one exponent).

    Copies are taken best-centred first (smallest |kbar|, then smallest |Im lambda|: the
    copies the truncation resolves best) and one per exponent is kept: a copy whose mu lies
    within ``DUPLICATE_TOLERANCE * omega`` of one already kept is dropped."""
    mu, kept = _physical_selection(values, vectors, basis, n_dof, omega, n_select)
    return mu[kept]


def _physical_selection(values, vectors, basis, n_dof, omega, n_select):
    """(mu (m,), kept indices) of :func:`physical_exponents`."""
    k, weight = harmonic_weights(vectors, basis, n_dof)
    centroid = k @ weight                                   # (m,)
    mu = values.real + 1j * (values.imag + centroid * omega)
    order = np.lexsort((np.abs(values.imag), np.round(np.abs(centroid), 6)))
    kept = []
    tol = DUPLICATE_TOLERANCE * omega
    for j in order:
        if all(abs(mu[j] - mu[i]) > tol for i in kept):
            kept.append(j)
            if n_select is not None and len(kept) == n_select:
                break
    return mu, np.array(kept, dtype=int)


def floquet_exponents(system, x: np.ndarray, omega: float, tolerance: float = STABILITY_TOLERANCE,
                      n_near: int | None = None, method: str = "auto", model=None) -> FloquetResult:
    """Floquet exponents of the solution ``x`` (N,) of ``system`` at ``omega`` [rad/s] by Hill's
    method.

    ``method``: "auto" (Hill's method when every element is memoryless, otherwise the
    determinant sign, see the module docstring), "hill" (forced, also on hysteretic elements:
    for study only, its exponents are then not those of the system), "determinant sign" or
    "monodromy" (the multipliers of the period map of ``model``, whose ``hbm_system`` gave
    ``system``; see :mod:`bladedamp.hbm.monodromy`).

    Dense systems: every eigenvalue of the linearised (2N, 2N) pencil. Sparse systems (the
    mistuned assembly): the ``n_near`` (default ``max(24, 4 n_dof)``) eigenvalues nearest to zero
    by shift-invert Arnoldi, the region where the exponents of the lightly damped modes near
    resonance cross the imaginary axis; the exponents of far modes are not computed. When that
    is half the spectrum or more (``n_near >= N``; always for one harmonic, N = 2 n_dof) every
    eigenvalue is computed densely instead (``FloquetResult.eigensolver`` says which).
    """
    _check_method(method, model)
    _, J, _ = system.residual(x, omega, True)
    return _floquet_from_jacobian(system, J, omega, tolerance, n_near, method, x, model)


METHODS = ("auto", "hill", "determinant sign", "monodromy")


def _check_method(method, model):
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(repr(m) for m in METHODS)} (got {method!r})")
    if method == "monodromy":
        from .monodromy import supports

        if model is None or not supports(model):
            raise ValueError(f"method 'monodromy' needs the model and has a period map for the FrictionOscillator, "
                             f"the TunedDisk and the full-assembly MistunedDisk only "
                             f"(got model={type(model).__qualname__}); use method 'auto'")


def _floquet_from_jacobian(system, J, omega, tolerance, n_near, method, x=None, model=None) -> FloquetResult:
    """:func:`floquet_exponents` from the Jacobian dR/dx at the point (computed once per point
    by :func:`branch_stability`, which also needs it for the bordered determinant)."""
    sign = determinant_sign(J)
    if method == "monodromy":
        from .monodromy import monodromy_multipliers

        mu, error = monodromy_multipliers(model, x, system.basis, omega)
        growth = np.log(np.maximum(np.abs(mu), 1e-300)) / (2 * np.pi)        # Re lambda / Omega
        exponents = np.log(mu[np.abs(mu) > 1e-12]) * omega / (2 * np.pi)    # mu = exp(lambda T); 0: a slipping slider
        return FloquetResult(exponents, exponents, float(omega), bool(growth.max() < tolerance), tolerance,
                             np.zeros(0, dtype=complex), "monodromy", sign, mu, error)
    if method == "determinant sign" or (method == "auto" and hysteretic(system)):
        empty = np.zeros(0, dtype=complex)
        return FloquetResult(empty, empty, float(omega), sign > 0, tolerance, empty, "determinant sign", sign)
    d1, d2 = hill_matrices(system, omega)
    n_dof = system.n_dof
    N = system.n_unknowns
    n_wanted = n_near or max(24, 4 * n_dof)
    if sp.issparse(J) and n_wanted < N:
        eigensolver = "shift-invert"
        values, vectors = _sparse_quadratic_eigs(J, d1, d2, omega, n_wanted)
    else:
        # half the spectrum or more (always so for one harmonic, C = 2: 4 n_dof = 2 N): ARPACK
        # cannot return all 2 N eigenvalues (at most 2 N - 2) and is not faster than the dense QZ
        # there (timings: benchmarks/README.md, 'Moved from the package's docstrings',
        # hbm/stability.py)
        eigensolver = "dense"
        dense = (lambda A: A.toarray()) if sp.issparse(J) else np.asarray
        values, vectors = _dense_quadratic_eig(dense(J), dense(d1), dense(d2))
    keep = np.isfinite(values)
    values, vectors = values[keep], vectors[:, keep]
    # all distinct exponents, then at most 2 n of the resolved ones: copies of the unresolved
    # fast modes of a strongly nonlinear solution need not coincide (their vectors spread over
    # the few harmonics), and a cap of 2 n before the resolution test would let them crowd out a
    # resolved one
    mu, kept = _physical_selection(values, vectors, system.basis, n_dof, omega, None)
    mu, lam = mu[kept], values[kept]
    resolved = np.abs(mu.imag) <= (max(system.basis.harmonics) + 0.5) * omega
    # at most 2 n resolved exponents, best-centred first: the further distinct ones are copies
    # whose truncation error separated them from their exponent (on a Duffing oscillator they
    # can show Re lambda > 0 well before the fold, where the monodromy matrix and the
    # best-centred copies agree on stability)
    decisive_index = np.flatnonzero(resolved)[:2 * n_dof]
    order = decisive_index[np.argsort(-mu[decisive_index].real)]
    decisive, multipliers = mu[order], np.exp(lam[order] * 2 * np.pi / omega)
    unresolved = mu[~resolved]
    unresolved = unresolved[np.argsort(-unresolved.real)]
    stable = bool(decisive.size and decisive.real.max() < tolerance * omega)
    return FloquetResult(decisive, values, float(omega), stable, tolerance, unresolved, "hill", sign, multipliers,
                         eigensolver=eigensolver)


def _dense_quadratic_eig(J, d1, d2):
    """All eigenpairs of (J + l d1 + l^2 d2) p = 0 by the first companion linearisation
    [[0, I], [-J, -d1]] z = l [[I, 0], [0, d2]] z, z = (p, l p); returns (values, p-vectors)."""
    N = J.shape[0]
    eye = np.eye(N)
    A = np.block([[np.zeros((N, N)), eye], [-J, -d1]])
    B = np.block([[eye, np.zeros((N, N))], [np.zeros((N, N)), d2]])
    values, vectors = scipy.linalg.eig(A, B)
    return values, vectors[:N]


def _sparse_quadratic_eigs(J, d1, d2, omega, k):
    """``k`` eigenpairs of the quadratic problem nearest to a small positive shift (sparse)."""
    from scipy.sparse.linalg import eigs

    N = J.shape[0]
    eye = sp.identity(N, format="csc")
    zero = sp.csc_matrix((N, N))
    A = sp.bmat([[zero, eye], [-J, -d1]], format="csc")
    B = sp.bmat([[eye, zero], [zero, d2]], format="csc")
    sigma = 1e-3 * omega
    values, vectors = eigs(A, k=min(k, 2 * N - 2), M=B, sigma=sigma, which="LM")
    return values, vectors[:N]


@dataclass
class BranchStability:
    """Stability along a branch of harmonic balance solutions.

    Attributes
    ----------
    stable : (n,) bool per point
    floquet_exponents : (n, k) resolved exponents per point [1/s], largest real part first
        (nan-padded; width 0 for the determinant-sign method; for "monodromy" log(mu) / T of the
        nonzero multipliers, largest modulus first)
    max_real : (n,) largest real part per point [1/s] (nan for the determinant-sign method)
    changes : indices i where stability changes between points i and i + 1
    kinds : for each change, 'fold' (a real exponent crosses: a turning point or a branch
        point), 'period doubling', 'neimark-sacker' (a complex pair crosses) or 'unresolved'
    branch_points : indices i where the determinant of the bordered Jacobian [[dR/dx,
        dR/domega], [tangent]] changes sign between points i and i + 1 (a turning point keeps
        it, a branch point flips it)
    method : "hill", "determinant sign" or "monodromy" (see :class:`FloquetResult`)
    seconds : time spent [s]
    """

    stable: np.ndarray
    floquet_exponents: np.ndarray
    max_real: np.ndarray
    changes: np.ndarray
    kinds: tuple
    branch_points: np.ndarray
    method: str
    seconds: float


@one_blas_thread       # many small determinants, which threads slow down (benchmarks/README.md,
                       # 'Moved from the package's docstrings', hbm/stability.py)
def branch_stability(system, coefficients: np.ndarray, omega: np.ndarray, x_scale=1.0,
                     tolerance: float = STABILITY_TOLERANCE, method: str = "auto", model=None) -> BranchStability:
    """Stability of every point of a branch (:func:`floquet_exponents`) and its branch points:
    ``coefficients`` (n, C, n_dof) or (n, N), ``omega`` (n,) [rad/s]; ``x_scale`` (scalar or
    (N,)) scales the unknowns of the tangent as in the continuation (the bordered determinant's
    sign does not depend on it, its conditioning does); ``model`` (whose ``hbm_system`` gave
    ``system``) for method "monodromy"."""
    _check_method(method, model)
    t0 = time.perf_counter()
    omega = np.asarray(omega, dtype=float)
    X = np.asarray(coefficients).reshape(len(omega), -1)
    tangents, scale, w_scale = _secant_tangents(X, omega, x_scale)
    results, bordered = [], np.zeros(len(omega), dtype=int)
    for i, w in enumerate(omega):          # one Jacobian per point serves both determinants
        _, J, Jw = system.residual(X[i], float(w), True)
        results.append(_floquet_from_jacobian(system, J, float(w), tolerance, None, method, X[i], model))
        bordered[i] = _bordered_sign(J, Jw, tangents[i], scale, w_scale)
    width = max((r.exponents.size for r in results), default=0)
    exps = np.full((len(omega), width), np.nan + 0j)
    for i, r in enumerate(results):
        exps[i, :r.exponents.size] = r.exponents
    stable = np.array([r.stable for r in results], dtype=bool)
    max_real = np.array([r.max_real for r in results])
    changes = np.flatnonzero(stable[1:] != stable[:-1])
    kinds = []
    for i in changes:
        r = results[i] if not results[i].stable else results[i + 1]
        kinds.append({"real": "fold", "complex": "neimark-sacker"}.get(r.unstable_kind(), r.unstable_kind()))
    branch_points = np.flatnonzero(bordered[1:] * bordered[:-1] < 0)
    method = results[0].method if results else "hill"
    return BranchStability(stable, exps, max_real, changes, tuple(kinds), branch_points, method,
                           time.perf_counter() - t0)


def _secant_tangents(X, omega, x_scale):
    """``(tangents (n, N + 1), scale (N,), w_scale)``: the unit secant tangent at every point
    (central where possible) in scaled unknowns (x / x_scale, omega / range)."""
    n = len(omega)
    scale = np.broadcast_to(np.asarray(x_scale, dtype=float), X.shape[1:])
    w_scale = max(float(np.ptp(omega)), 1e-300)
    Y = np.column_stack([X / scale, omega / w_scale])
    T = Y[np.minimum(np.arange(n) + 1, n - 1)] - Y[np.maximum(np.arange(n) - 1, 0)]
    T /= np.maximum(np.linalg.norm(T, axis=1, keepdims=True), 1e-300)
    return T, scale, w_scale


def _bordered_sign(J, Jw, t, scale, w_scale) -> int:
    """Sign of det [[dR/dx, dR/domega], [t_x, t_omega]] in the scaled unknowns of ``t``
    (0 for a single-point branch, whose tangent is zero)."""
    if not np.any(t):
        return 0
    if sp.issparse(J):
        A = sp.bmat([[sp.csc_matrix(J) @ sp.diags(scale), sp.csc_matrix(Jw[:, None] * w_scale)],
                     [sp.csr_matrix(t[None, :-1]), sp.csr_matrix([[t[-1]]])]], format="csc")
    else:
        A = np.block([[np.asarray(J) * scale[None, :], (Jw * w_scale)[:, None]], [t[None, :]]])
    return determinant_sign(A)


def with_stability(model, response, method: str = "auto"):
    """``response`` (of ``model``'s ``frequency_response``) with ``stable``,
    ``floquet_exponents``, ``bifurcations`` and ``stability_method`` filled in
    (:func:`branch_stability` on the model's harmonic balance of the response's basis).
    ``bifurcations`` holds the stability changes by kind and the branch points; the time spent
    is in ``bifurcations["seconds"]``. A warning raised at several points of the branch (the
    monodromy's AccuracyWarning where the HBM state is not a periodic orbit) is raised once, at
    the caller's line, the first point's message with the number of points that raised it."""
    if not len(response.omega):
        return response
    basis = response.basis
    system = model.hbm_system(basis.harmonics, basis.n_samples)
    w = response.omega
    scales = model.unknown_scales(system, float(w.min()), float(w.max()))
    with warnings.catch_warnings(record=True) as raised:
        st = branch_stability(system, response.coefficients, w, scales, method=method, model=model)
    first = {}
    for caught in raised:
        first.setdefault(caught.category, [caught.message, 0])[1] += 1
    for category, (message, count) in first.items():
        more = f" (the same at {count - 1} more of the branch's {len(w)} points)" if count > 1 else ""
        warnings.warn(f"{message}{more}", category, stacklevel=2)
    bifurcations = {kind: [int(i) for i, k in zip(st.changes, st.kinds) if k == kind] for kind in set(st.kinds)}
    bifurcations["branch point"] = [int(i) for i in st.branch_points]
    bifurcations["seconds"] = st.seconds
    return dataclasses.replace(response, stable=st.stable, floquet_exponents=st.floquet_exponents,
                               bifurcations=bifurcations, stability_method=st.method)
