"""The O(n) ring solver (bladedamp.hbm.linsolve.BlockRing): on random periodic block-tridiagonal
matrices, with interior (damper) blocks and the arc-length border, dense and sparse, it equals
numpy's dense solve and gives det A's sign and log |det A|; n = 2 and n = 3 (where the
neighbours are the corner blocks); a fold of J (J singular, the bordered matrix regular); the
fallback to LU; the Jacobians of mistuned assemblies; and mistuned FRFs equal point by point
to those of the damper condensation."""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from conftest import border

from bladedamp.hbm.linsolve import BlockRing, factorize
from bladedamp.mistuned import AssemblySystem, MistunedDisk
from bladedamp.reference import reference_disk
from bladedamp.studies import mistuning as mt


def ring_matrix(rng, n, b=3, q=2, links=None, bordered=False, shuffle=True):
    """A random ring of n blocks of size b (block k coupled to k - 1 and k + 1 mod n, each
    coupling block random, summed for n = 2) with an interior block of size q on each of
    ``links`` (default: one per ring position), coupled to ring blocks l and l + 1; unknowns in
    random order. Returns (A, BlockRing)."""
    links = np.arange(n) if links is None else np.asarray(links)
    m = links.size
    size = n * b + m * q
    order = rng.permutation(size) if shuffle else np.arange(size)
    groups, interior = order[:n * b].reshape(n, b), order[n * b:].reshape(m, q)
    N = size + bordered
    A = np.zeros((N, N))
    for k in range(n):
        g, h = groups[k], groups[(k + 1) % n]
        A[np.ix_(g, g)] += rng.standard_normal((b, b)) + 2 * b * np.eye(b)
        A[np.ix_(g, h)] += rng.standard_normal((b, b))
        A[np.ix_(h, g)] += rng.standard_normal((b, b))
    for j, l in enumerate(links):
        iq, c = interior[j], np.concatenate([groups[l], groups[(l + 1) % n]])
        A[np.ix_(iq, iq)] = rng.standard_normal((q, q)) + 2 * q * np.eye(q)
        A[np.ix_(iq, c)] = rng.standard_normal((q, c.size))
        A[np.ix_(c, iq)] = rng.standard_normal((c.size, q))
    if bordered:
        A[size] = rng.standard_normal(N)
        A[:, size] = rng.standard_normal(N)
    return A, BlockRing(groups, interior if m else None, links if m else None)


def check(A, ring, rng, tol=1e-12, method="ring"):
    """ring(A) solves like numpy (one and several right-hand sides, dense and sparse A) and
    gives det A's sign and log |det A|."""
    sign, logdet = np.linalg.slogdet(A)
    B = rng.standard_normal((A.shape[0], 3))
    ref = np.linalg.solve(A, B)
    for M in (A, sp.csc_matrix(A), sp.csr_matrix(A)):
        solve = ring(M)
        assert solve.method == method
        x = solve(B)
        assert x.shape == B.shape
        err = np.abs(x - ref).max() / np.abs(ref).max()
        assert err < tol, f"{type(M).__name__}: differs from numpy by {err:.2e}"
        assert np.allclose(solve(B[:, 0]), x[:, 0], rtol=0, atol=1e-14 * np.abs(x).max())
        assert solve.sign == int(sign)
        assert abs(solve.logabsdet - logdet) < 1e-10 * max(1.0, abs(logdet))


@pytest.mark.parametrize("n", [2, 3, 4, 5, 9])
@pytest.mark.parametrize("bordered", [False, True])
@pytest.mark.parametrize("with_interior", [False, True])
def test_random_rings_equal_dense_solve(n, bordered, with_interior):
    rng = np.random.default_rng([n, bordered, with_interior])
    A, ring = ring_matrix(rng, n, links=None if with_interior else [], bordered=bordered)
    check(A, ring, rng)


def test_two_and_three_blocks_where_neighbours_are_the_corners():
    """n = 2: blocks 0 and 1 are each other's left and right neighbour, A[0, 1] is the sum of
    both couplings (both interior blocks reach it); n = 3: every off-diagonal block is also a
    corner. Contiguous and shuffled unknowns, an interior block on one link only."""
    rng = np.random.default_rng(7)
    for n in (2, 3):
        for links in ([0, 1] if n == 2 else [0, 1, 2], [1], [0, 0]):
            for shuffle in (False, True):
                A, ring = ring_matrix(rng, n, b=4, q=3, links=links, bordered=True, shuffle=shuffle)
                check(A, ring, rng)
    # n = 2 without interior blocks: A[0, 1] and A[1, 0] are plain dense blocks
    A, ring = ring_matrix(rng, 2, b=5, links=[], bordered=True, shuffle=False)
    A[:10, :10] = rng.standard_normal((10, 10)) + 10 * np.eye(10)
    check(A, ring, rng)


@pytest.mark.parametrize("block", [0, 3, 5])
def test_fold_singular_jacobian_regular_bordered_matrix(block):
    """At a fold of the branch J is singular and the bordered matrix is not: the border
    eliminated last after J (Keller's bordering) fails there, the ring keeps it in its dense
    last block. J is made singular by removing the smallest singular value of its Schur
    complement onto ring block ``block`` from that block's diagonal."""
    rng = np.random.default_rng(11 + block)
    n, b = 6, 3
    A, ring = ring_matrix(rng, n, b=b, q=2, bordered=True)
    size = ring.size
    J = A[:size, :size]
    g = ring.groups[block]
    rest = np.setdiff1d(np.arange(size), g)
    S = J[np.ix_(g, g)] - J[np.ix_(g, rest)] @ np.linalg.solve(J[np.ix_(rest, rest)], J[np.ix_(rest, g)])
    u, s, vt = np.linalg.svd(S)
    A[np.ix_(g, g)] -= s[-1] * np.outer(u[:, -1], vt[-1])
    sv = np.linalg.svd(A[:size, :size], compute_uv=False)
    assert sv[-1] < 1e-13 * sv[0], "J must be singular"
    assert np.linalg.cond(A) < 1e8, "the bordered matrix must be regular"
    check(A, ring, rng, tol=1e-10)


def test_ill_conditioned_pivot_and_singular_blocks_fall_back_to_lu():
    rng = np.random.default_rng(5)
    # a singular first pivot (ring block 0 rank-deficient), the whole matrix regular
    A, ring = ring_matrix(rng, 5, b=3, links=[], bordered=True)
    g = ring.groups[0]
    A[np.ix_(g, g)] = np.outer([1.0, 2.0, 3.0], [1.0, -1.0, 0.5])
    check(A, ring, rng, tol=1e-10, method="lu")
    # a singular interior block
    A, ring = ring_matrix(rng, 4, b=3, q=2, bordered=True)
    iq = ring.interior[2]
    A[np.ix_(iq, iq)] = np.outer([1.0, 1.0], [2.0, 2.0])
    check(A, ring, rng, tol=1e-10, method="lu")
    # a sparse entry off the ring (blocks 0 and 2 of 5 coupled): LU, still right
    A, ring = ring_matrix(rng, 5, b=3, q=2, bordered=True)
    A[ring.groups[0][0], ring.groups[2][1]] = 0.7
    solve = ring(sp.csc_matrix(A))
    assert solve.method == "lu"
    b = rng.standard_normal(A.shape[0])
    assert np.allclose(solve(b), np.linalg.solve(A, b), rtol=0, atol=1e-12 * np.abs(np.linalg.solve(A, b)).max())
    assert solve.sign == int(np.linalg.slogdet(A)[0])
    # a singular matrix raises as the dense LU does
    A, ring = ring_matrix(rng, 4, b=3, q=2)
    A[:, ring.groups[1][0]] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        ring(A)


def test_bad_layouts_are_rejected():
    with pytest.raises(ValueError, match="at least 2"):
        BlockRing([[0, 1]])
    with pytest.raises(ValueError, match="exactly once"):
        BlockRing([[0, 1], [1, 2]])
    with pytest.raises(ValueError, match="exactly once"):
        BlockRing([[0, 1], [2, 3]], [[4, 5]], [0], size=7)
    with pytest.raises(ValueError, match="one entry per interior"):
        BlockRing([[0, 1], [2, 3]], [[4, 5]], [0, 1])
    with pytest.raises(ValueError, match="ring blocks"):
        BlockRing([[0, 1], [2, 3]], [[4, 5]], [2])
    ring = BlockRing([[0, 1], [2, 3]], [[4, 5]], [0])
    with pytest.raises(ValueError, match="system size"):
        ring(np.eye(8))


def jacobians(md, harmonics, seed=0):
    """(system, J, bordered J) of ``md`` at 95 Hz near its stuck linear solution, perturbed for
    some slip and lift-off."""
    system = md.hbm_system(harmonics)
    w = 2 * np.pi * 95.0
    x = md.initial_guess(system, w)
    x = x * (1 + 0.3 * np.random.default_rng(seed).standard_normal(x.size))
    R, J, Rw = system.residual(x, w)
    A = border(J, Rw, np.random.default_rng(seed + 1).standard_normal(J.shape[0] + 1))
    return system, J, A


@pytest.mark.parametrize("kind, harmonics, n", [("cylinder", (1,), 16), ("cylinder", (1,), 2),
                                                ("cylinder", (1, 2), 3), ("wedge", (0, 1, 2), 5)])
def test_ring_on_mistuned_jacobians(kind, harmonics, n):
    """The Jacobian and the bordered Jacobian of mistuned assemblies, dense and sparse: the ring
    equals LU to 1e-10 relative and its sign is slogdet's (the continuation's orientation)."""
    disk = dataclasses.replace(reference_disk(kind, 1e-3), n_blades=n)
    md = MistunedDisk.from_tuned(disk, mt.random_kappa(n, 0.02, seed=[0, n]))
    system, J, A = jacobians(md, harmonics)
    assert system.ring_solver is not None and system.linear_solver == "auto"
    for M in (J, A, sp.csc_matrix(A)):
        solve = system.factorize(M)
        assert solve.method == "ring"
        b = np.random.default_rng(2).standard_normal(M.shape[0])
        y, y_lu = solve(b), factorize(M)(b)
        err = np.abs(y - y_lu).max() / np.abs(y_lu).max()
        assert err < 1e-10, f"ring differs from LU by {err:.2e}"
        dense = M.toarray() if sp.issparse(M) else M
        assert solve.sign == int(np.linalg.slogdet(dense)[0])


@pytest.mark.parametrize("n, bordered, with_interior", [(5, True, True), (2, False, True), (3, True, False)])
def test_sparse_blocks_are_the_dense_blocks(n, bordered, with_interior):
    """BlockRing.blocks of a sparse matrix (scattered through the per-pattern map of its stored
    entries, formed once per pattern and kept for the last two) holds exactly the entries the
    dense matrix's blocks are indexed from: equal bit for bit, for a first matrix of a pattern,
    another matrix of the same index arrays (the map reused), a second pattern, and the first
    again; n = 2 (both couplings summed in Up) and 3 included. A nonzero entry off the ring's
    pattern gives None (the caller's LU), a stored zero there does not."""
    rng = np.random.default_rng(n)
    A, ring = ring_matrix(rng, n, links=None if with_interior else [], bordered=bordered)
    S = sp.csc_matrix(A)
    S2 = S.copy()
    S2.indices, S2.indptr = S.indices, S.indptr                 # same index arrays, new values
    S2.data = rng.standard_normal(S.nnz)
    other = sp.csc_matrix(A + np.diag(np.full(A.shape[0], 0.5)))    # another pattern object
    for M in (S, S2, other, S, S2):
        got, ref = ring.blocks(M), ring.blocks(M.toarray())
        assert got[0] == ref[0] and got[6] == ref[6]
        for a, b in zip(got[1:6] + got[7:], ref[1:6] + ref[7:]):
            assert np.array_equal(a, b)
    g = ring.groups
    if n > 3:
        off = A.copy()
        off[g[0][0], g[2][0]] = 1.0                              # blocks 0 and 2: not neighbours
        assert ring.blocks(sp.csc_matrix(off)) is None
        off[g[0][0], g[2][0]] = 0.0
        stored = sp.csc_matrix(off)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sp.SparseEfficiencyWarning)
            stored[g[0][0], g[2][0]] = 0.0                         # explicitly stored zero
        assert stored.nnz == S.nnz + 1 and ring.blocks(stored) is not None


def test_ring_on_sectors_and_missing_dampers():
    """A two-blade sector of an 8-blade disk (the last damper couples blade 1 to the next
    sector's blade 0, turned by the interblade phase) and a full assembly with two massless
    dampers (fewer interior blocks than blades): ring = LU. One blade (the tuned sector) has
    no ring and keeps the condensation."""
    disk = reference_disk("cylinder", 1e-3)
    sector = MistunedDisk.from_tuned(dataclasses.replace(disk, n_blades=8), [1.0, 1.03], n_sector=2)
    gaps = MistunedDisk(sector.blades[:1] * 6, [disk.damper, None, disk.damper, disk.damper, None, disk.damper])
    for md, harmonics in ((sector, (1, 2)), (gaps, (1,))):
        system, J, A = jacobians(md, harmonics)
        assert system.ring_solver is not None
        for M in (A, sp.csc_matrix(A)):
            solve = system.factorize(M)
            assert solve.method == "ring"
            b = np.random.default_rng(3).standard_normal(M.shape[0])
            y_lu = factorize(M)(b)
            assert np.abs(solve(b) - y_lu).max() < 1e-10 * np.abs(y_lu).max()
    one = MistunedDisk.from_tuned(dataclasses.replace(disk, n_blades=8), [1.0], n_sector=1)
    system, J, A = jacobians(one, (1,))
    assert system.ring_solver is None
    assert not hasattr(system.factorize(A), "method")          # BlockCondensation's solve


def test_linear_solver_option():
    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    md = MistunedDisk.from_tuned(disk, mt.random_kappa(4, 0.02, seed=1))
    with pytest.raises(ValueError, match="linear_solver"):
        md.hbm_system((1,), linear_solver="cholesky")
    _, J, A = jacobians(md, (1,))
    for name, method in (("ring", "ring"), ("lu", None), ("condensation", None)):
        system = md.hbm_system((1,), linear_solver=name)
        assert getattr(system.factorize(A), "method", None) == method
    md.linear_solver = "lu"                                      # the instance's choice
    assert md.hbm_system((1,)).linear_solver == "lu"
    assert MistunedDisk.linear_solver == "auto"


def frf(md, solver, f_range, harmonics=(1,)):
    md.linear_solver = solver
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return md.frequency_response(*f_range, harmonics=harmonics, max_step=0.05)


@pytest.mark.parametrize("n, f_range, sparse", [(6, (93.0, 97.0), False), (3, (93.0, 97.0), False),
                                                (2, (94.0, 96.5), False), (5, (94.0, 96.0), True)])
def test_mistuned_frf_with_the_ring_equals_the_condensation(n, f_range, sparse, monkeypatch):
    """The same branch point by point (number of points, iterations, omega and every
    coefficient to 1e-10), with the dense Jacobians of small assemblies (condensation + dense
    LU before) and with sparse ones (sparse LU before)."""
    if sparse:
        monkeypatch.setattr(AssemblySystem, "dense_limit", 0)
    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=n)
    md = MistunedDisk.from_tuned(disk, mt.random_kappa(n, 0.02, seed=3))
    assert md.hbm_system((1,)).dense is not sparse
    old, new = frf(md, "condensation", f_range), frf(md, "ring", f_range)
    assert old.success and new.success
    assert len(new.omega) == len(old.omega) > 20
    assert np.array_equal(new.iterations, old.iterations)
    assert np.abs(new.omega - old.omega).max() < 1e-10 * old.omega.max()
    scale = np.abs(old.coefficients).max()
    assert np.abs(new.coefficients - old.coefficients).max() < 1e-10 * scale
    assert np.isclose(new.harmonic_error, old.harmonic_error, rtol=1e-8)


def test_one_column_substitutions_give_the_many_column_numbers():
    """The ring's one-column paths (the solves' right-hand sides: mm_subtract and lu_solve_inplace with a
    single column, lu_solve_transposed_inplace) sum each row in a register: the same numbers, bit for
    bit, as the many-column loops (which subtract term by term in memory) on the same column."""
    from bladedamp.hbm.linsolve import lu_factor_inplace, lu_solve_inplace, lu_solve_transposed_inplace, mm_subtract

    rng = np.random.default_rng(11)
    q = 21
    W = rng.standard_normal((q, q)) + q * np.eye(q)
    piv = np.empty(q, dtype=np.intp)
    lu_factor_inplace(W, piv)
    A, B, C = rng.standard_normal((q, 13)), rng.standard_normal((13, 1)), rng.standard_normal((q, 1))
    wide, wide_C = np.hstack([B, rng.standard_normal((13, 2))]), np.hstack([C, np.zeros((q, 2))])
    mm_subtract(A, B, C)
    mm_subtract(A, wide, wide_C)
    assert np.array_equal(C[:, 0], wide_C[:, 0])
    b = rng.standard_normal((q, 1))
    b_wide = np.hstack([b, rng.standard_normal((q, 3))])
    lu_solve_inplace(W, piv, b)
    lu_solve_inplace(W, piv, b_wide)
    assert np.array_equal(b[:, 0], b_wide[:, 0])
    x = rng.standard_normal(q)
    expected = x.copy()                 # W^-T x term by term, as the loops were
    for i in range(q):
        for l in range(i):
            expected[i] -= W[l, i] * expected[l]
        expected[i] /= W[i, i]
    for i in range(q - 1, -1, -1):
        for l in range(i + 1, q):
            expected[i] -= W[l, i] * expected[l]
    for c in range(q - 1, -1, -1):
        if piv[c] != c:
            expected[c], expected[piv[c]] = expected[piv[c]], expected[c]
    lu_solve_transposed_inplace(W, piv, x)
    assert np.array_equal(x, expected)
