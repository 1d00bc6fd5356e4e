"""Linear solves of the harmonic balance (bladedamp.hbm.linsolve): the block condensation of the
damper coordinates equals a plain LU of the same matrix, bordered or not, on random structured
matrices and on the Jacobians of mistuned assemblies; it falls back to LU for nearly singular
blocks and rejects inconsistent layouts."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp

from conftest import border, scale_columns

from bladedamp import FrictionOscillator
from bladedamp.hbm.continuation import bordered_matrix
from bladedamp.hbm.linsolve import BlockCondensation, factorize
from bladedamp.mistuned import MistunedDisk
from bladedamp.reference import reference_disk
from bladedamp.studies import mistuning as mt


def structured(rng, n_ext=12, n_blocks=4, b=3):
    """A ring of exterior groups with interior blocks between neighbours (like blades and dampers)."""
    n = n_ext + n_blocks * b
    A = np.zeros((n, n))
    group = n_ext // n_blocks
    A[:n_ext, :n_ext] = rng.standard_normal((n_ext, n_ext)) + n_ext * np.eye(n_ext)
    interior, coupled = [], []
    for k in range(n_blocks):
        q = n_ext + b * k + np.arange(b)
        c = np.concatenate([group * k + np.arange(group), group * ((k + 1) % n_blocks) + np.arange(group)])
        A[np.ix_(q, q)] = rng.standard_normal((b, b)) + 5 * np.eye(b)
        A[np.ix_(q, c)] = rng.standard_normal((b, c.size))
        A[np.ix_(c, q)] = rng.standard_normal((c.size, b))
        interior.append(q)
        coupled.append(c)
    return A, BlockCondensation(np.array(interior), np.array(coupled), n)


def test_dense_lu_is_scipys_and_gives_the_sign_of_the_determinant():
    """factorize of a dense matrix (DenseLU: LAPACK getrf / getrs called directly) solves with the
    same numbers as scipy's lu_factor / lu_solve (bit-identical), and its sign of det A, from
    the factors, is np.linalg.slogdet's, on random matrices of both signs and sizes 1..200 and on
    the bordered Jacobians of a friction oscillator's branch; a singular matrix raises."""
    rng = np.random.default_rng(31)
    signs = set()
    for n in (1, 2, 9, 50, 129, 200):
        for _ in range(5):
            A = rng.standard_normal((n, n))
            b = rng.standard_normal((n, 3))
            solve, lu = factorize(A), scipy.linalg.lu_factor(A)
            assert np.array_equal(solve(b), scipy.linalg.lu_solve(lu, b))
            assert np.array_equal(solve(b[:, 0]), scipy.linalg.lu_solve(lu, b[:, 0]))
            sign, logdet = np.linalg.slogdet(A)
            assert solve.sign == sign and abs(solve.logabsdet - logdet) <= 1e-12 * max(1.0, abs(logdet))
            signs.add(solve.sign)
    assert signs == {-1, 1}
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    system = osc.hbm_system((1, 3, 5))
    r = osc.frequency_response(14.0, 22.0, harmonics=(1, 3, 5))
    for x, omega in zip(r.coefficients.reshape(len(r.omega), -1), r.omega):
        _, J, Rw = system.residual(x, omega)
        A = border(J, Rw, rng.standard_normal(J.shape[0] + 1))
        assert factorize(A).sign == np.linalg.slogdet(A)[0]
    for singular in (np.zeros((3, 3)), np.array([[1.0, 2.0], [2.0, 4.0]]), np.array([[np.nan, 1.0], [1.0, 1.0]])):
        with pytest.raises(np.linalg.LinAlgError):
            factorize(singular)


@pytest.mark.parametrize("bordered", [False, True])
def test_condensation_equals_lu_on_a_structured_matrix(bordered):
    rng = np.random.default_rng(1)
    A, cond = structured(rng)
    if bordered:
        A = border(A, rng.standard_normal(A.shape[0]), rng.standard_normal(A.shape[0] + 1))
    b = rng.standard_normal((A.shape[0], 3))
    x = cond(A)(b)
    assert np.abs(x - np.linalg.solve(A, b)).max() < 1e-12 * np.abs(x).max()
    assert np.allclose(cond(sp.csc_matrix(A))(b[:, 0]), x[:, 0], rtol=0, atol=1e-12 * np.abs(x).max())


def test_nearly_singular_block_falls_back_to_lu(monkeypatch):
    import bladedamp.hbm.linsolve as linsolve

    rng = np.random.default_rng(2)
    A, cond = structured(rng)
    q = cond.interior[1]
    A[np.ix_(q, q)] = np.outer(np.ones(3), [1.0, 2.0, 3.0]) + 1e-15 * np.eye(3)   # rank one
    calls = []
    monkeypatch.setattr(linsolve, "factorize", lambda M: calls.append(M.shape) or factorize(M))
    b = rng.standard_normal(A.shape[0])
    x = cond(A)(b)
    assert calls == [A.shape], "the whole matrix goes to LU"
    assert np.abs(x - np.linalg.solve(A, b)).max() < 1e-8 * np.abs(x).max()


def test_bad_layouts_are_rejected():
    with pytest.raises(ValueError, match="distinct"):
        BlockCondensation([[0, 1], [1, 2]], [[3], [4]], 5)
    with pytest.raises(ValueError, match="exterior"):
        BlockCondensation([[0, 1]], [[1]], 5)
    rng = np.random.default_rng(3)
    A, cond = structured(rng)
    with pytest.raises(ValueError, match="system size"):
        cond(np.eye(A.shape[0] + 2))


@pytest.mark.parametrize("kind, harmonics", [("cylinder", (1,)), ("wedge", (0, 1, 2))])
def test_condensation_on_mistuned_jacobians(kind, harmonics):
    """The bordered Jacobian of a 16-blade mistuned assembly (the arc-length corrector's matrix):
    condensation of the damper coordinates equals the LU solution to 1e-10 relative."""
    disk = reference_disk(kind, 1e-3)
    md = MistunedDisk.from_tuned(disk, mt.random_kappa(16, 0.02, seed=[0, 1]))
    system = md.hbm_system(harmonics, linear_solver="condensation")   # the ring: tests/test_ring_solver.py
    w = 2 * np.pi * 95.0
    x = md.initial_guess(system, w)
    x = x * (1 + 0.3 * np.random.default_rng(0).standard_normal(x.size))   # some slip and lift-off
    R, J, Rw = system.residual(x, w)
    assert isinstance(J, np.ndarray) and system.condensation_solver is not None
    A = border(J, Rw, np.random.default_rng(1).standard_normal(J.shape[0] + 1))
    for M in (J, A):
        b = np.random.default_rng(2).standard_normal(M.shape[0])
        y, y_lu = system.factorize(M)(b), factorize(M)(b)
        err = np.abs(y - y_lu).max() / np.abs(y_lu).max()
        assert err < 1e-10, f"condensation differs from LU by {err:.2e}"


def test_bordered_forms_the_indices_once_per_pattern():
    """The continuation's bordered matrix [[J diag(s), column] factor; row] of a sparse J: the
    entries of border(scale_columns(J)) (scaled the same way), its index arrays formed once
    for J's pattern and shared by the next bordered matrix of a Jacobian with the same index
    arrays (the assembly's Jacobians share theirs); another pattern is bordered anew."""
    rng = np.random.default_rng(3)
    n = 40
    J = sp.random(n, n, density=0.2, format="csc", random_state=rng) + sp.identity(n, format="csc")
    J2 = J.copy()
    J2.indices, J2.indptr = J.indices, J.indptr            # another Jacobian with the same index arrays
    J2.data = rng.standard_normal(J.nnz)
    other = sp.random(n, n, density=0.1, format="csc", random_state=rng) + sp.identity(n, format="csc")
    factor = 0.3
    previous = None
    for M in (J, J2, other):
        column, row, scale = rng.standard_normal(n), rng.standard_normal(n + 1), rng.uniform(0.5, 2, n)
        A = bordered_matrix(M, column, row, scale, factor)
        B = border(scale_columns(M, scale * factor), column * factor, row)
        assert A.shape == (n + 1, n + 1) and np.array_equal(A.toarray(), B.toarray())
        assert np.array_equal(A.indices, B.indices) and np.array_equal(A.indptr, B.indptr)
        if M is J2:
            assert A.indices is previous.indices and A.indptr is previous.indptr
        if M is other:
            assert A.indices is not previous.indices
        previous = A


def test_prefers_sparse_at_the_measured_crossover():
    """The dense / sparse choice: sparse exactly from SPARSE_MIN_UNKNOWNS unknowns at a fill of at
    most SPARSE_MAX_FILL; a size or count out of range is a ValueError naming it."""
    from bladedamp.hbm.linsolve import SPARSE_MAX_FILL, SPARSE_MIN_UNKNOWNS, prefers_sparse

    n = SPARSE_MIN_UNKNOWNS
    limit = int(SPARSE_MAX_FILL * n * n)
    assert prefers_sparse(n, limit) and not prefers_sparse(n, limit + 1)
    assert not prefers_sparse(n - 1, n - 1)                  # diagonal, but small
    assert prefers_sparse(10 * n, 10 * n)
    with pytest.raises(ValueError, match="n_unknowns"):
        prefers_sparse(-1, 0)
    with pytest.raises(ValueError, match="nonzeros"):
        prefers_sparse(n, n * n + 1)
