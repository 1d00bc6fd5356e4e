"""Stability of bladed-disk solutions (issue 14, items 1 and 2): Hill's method on the sparse
Jacobian of the full assembly (MistunedDisk) against the cyclic sector, and the unstable
segment of a disk confirmed by a time integration.

The case: a tuned 4-blade disk (the reference blade, modal damping 1 % in every mode, 1 N
engine-order-1 excitation at the tip) without dampers, each blade with a hardening cubic
spring k3 = 3e9 N/m^3 on its tip's x motion (``CubicSpring`` through the element API). The
element is memoryless, so Hill's method gives the exponents exactly, and the 1F resonance bends
over into two folds (103.2 and 98.7 Hz). Without dampers the blades are not coupled: the full
assembly's spectrum is the sector's four times over. That makes two things checkable exactly:

* the assembly's exponents, from its sparse Jacobian, equal the sector's (the same stable
  verdicts, the same largest real part, the folds at the same points);
* at a fold of the travelling wave all four blades fold at once: four real exponents cross
  zero together, so det J of the assembly (the sector's to the fourth power) keeps its sign
  and the determinant-sign criterion (the one used for friction) cannot see the unstable
  segment, while Hill's method does; the bordered determinant flips there (three more null
  directions besides the tangent: branches on which the blades split between the upper and
  the lower solution).

With the blades coupled tip to tip by a linear spring (``TipLink``, memoryless), the sector's
exponents are among the assembly's (the engine order's travelling waves are an invariant
subspace), and the assembly has more: other nodal diameters.

The reference friction disk is not such a case: it keeps det J > 0 and no fold on 90-105 Hz
(tests/test_stability.py::test_reference_disk_has_no_fold_and_keeps_det_j_positive); its
determinant sign cannot see a Neimark-Sacker crossing, for which Hill's method on friction is
not valid; the monodromy matrix of the disk (tests/test_monodromy_disk.py) has the period map.
"""
from __future__ import annotations

import dataclasses
import time
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import solve_ivp
from scipy.sparse.linalg import spsolve

import bladedamp as bd
from bladedamp.hbm import Coupling, CubicSpring, TimeDomainElement
from bladedamp.hbm.stability import branch_stability, determinant_sign, floquet_exponents
from bladedamp.mistuned import MistunedDisk

K3 = 3e9                 # [N/m^3] on the tip's x motion
N_BLADES = 4


def cubic_disk():
    ref = bd.reference_disk("cylinder", 1e-3)
    blade = dataclasses.replace(ref.blade, damping_ratios=np.full(ref.blade.n_modes, 0.01))
    return dataclasses.replace(ref, blade=blade, damper=None, n_blades=N_BLADES, excitation=10 * ref.excitation)


def tip_springs(disk):
    return lambda basis: [Coupling(CubicSpring(K3), disk.point_map(basis, "tip", (0,)), "tip cubic")]


def assembly_system(assembly, harmonics=(1,)):
    """The full assembly's (sparse) harmonic balance with the cubic spring at every blade's tip."""
    system = assembly.hbm_system(harmonics)
    for k in range(assembly.n_sector):
        system = system.add(CubicSpring(K3), assembly.point_map(system.basis, "tip", (0,), blade=k), f"tip cubic {k}")
    system.storage = "sparse"       # what these tests check: the sparse path (automatic would choose dense at 32 unknowns)
    return system


def expand(assembly, basis, coefficients):
    """Sector solutions (n, C, n_m) -> full-assembly unknowns (n, C * n_dof): harmonic h of blade
    k is blade 0's turned by e^{i h k dphi} (complex X = a - i b; the static term unchanged)."""
    n, C, nm = coefficients.shape
    X = np.zeros((n, C, assembly.n_dof))
    for k in range(assembly.n_sector):
        sl = assembly.blade_slice(k)
        for h in basis.harmonics:
            j = basis.cos_index(h)
            if h == 0:
                X[:, j, sl] = coefficients[:, j]
                continue
            z = (coefficients[:, j] - 1j * coefficients[:, j + 1]) * np.exp(1j * h * k * assembly.interblade_phase)
            X[:, j, sl], X[:, j + 1, sl] = z.real, -z.imag
    return X.reshape(n, -1)


@pytest.fixture(scope="module")
def sector():
    disk = cubic_disk()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bd.hbm.accuracy.AccuracyWarning)       # one harmonic, on purpose
        r = bd.frequency_response(disk, (90.0, 110.0), harmonics=(1,), stability=True,
                                  extra_couplings=tip_springs(disk), max_step=0.05)
    assert r.success, r.message
    return disk, r


@pytest.fixture(scope="module")
def assembly(sector):
    disk, r = sector
    full = MistunedDisk.from_tuned(disk, dampers=None)
    system = assembly_system(full, r.basis.harmonics)
    return full, system, expand(full, r.basis, r.coefficients)


def test_the_sector_has_two_folds_and_hill_puts_the_unstable_segment_between_them(sector):
    """The cyclic sector with the element API's cubic spring: Hill's method (memoryless), the
    stability changes at the two turning points and only there, no branch point."""
    _, r = sector
    assert r.stability_method == "hill"
    tp = sorted(int(t) for t in r.turning_points)
    assert len(tp) == 2 and len(r.bifurcations["fold"]) == 2 and r.bifurcations["branch point"] == []
    assert all(abs(c - t) <= 1 for c, t in zip(sorted(r.bifurcations["fold"]), tp))
    assert r.stable[:tp[0] - 1].all() and r.stable[tp[1] + 1:].all() and not r.stable[tp[0] + 1:tp[1] - 1].any()
    assert r.frequency_hz[tp[0]] == pytest.approx(103.19, abs=0.05) and r.frequency_hz[tp[1]] == pytest.approx(98.72, abs=0.05)


def test_full_assembly_on_its_sparse_jacobian_gives_the_sector_verdicts(sector, assembly):
    """Item 1, mistuned disk: Hill's method on the assembly's sparse Jacobian, at the sector's
    points written out blade by blade: the same stable verdicts, the same largest real part (the
    assembly's spectrum is the sector's four times over), the stability changes at the same folds;
    det J of the assembly stays positive where the sector's is negative."""
    disk, r = sector
    full, system, X = assembly
    assert system.sparse
    # the written-out sector solutions solve the assembly (tuned full assembly = cyclic)
    f_norm = np.linalg.norm(system.excitation(float(r.omega[0]))[0])
    assert max(np.linalg.norm(system.residual(x, w, False)[0]) for x, w in zip(X, r.omega)) < 1e-10 * f_norm
    tp = sorted(int(t) for t in r.turning_points)
    idx = np.array(sorted(set(range(0, len(r.omega), 12)) | {t + s for t in tp for s in range(-2, 3)}))
    scales = full.unknown_scales(system, float(r.omega.min()), float(r.omega.max()))
    st = branch_stability(system, X[idx], r.omega[idx], scales)
    assert st.method == "hill"
    np.testing.assert_array_equal(st.stable, r.stable[idx])
    cyclic_max = np.nanmax(r.floquet_exponents.real, axis=1)[idx]
    np.testing.assert_allclose(st.max_real, cyclic_max, rtol=1e-6, atol=1e-9 * float(r.omega.max()))
    assert st.kinds == ("fold", "fold")
    assert [int(idx[c]) for c in st.changes] == [int(idx[c]) for c in np.flatnonzero(r.stable[idx][1:] != r.stable[idx][:-1])]
    # the unstable segment by det J: the sector's is negative, the assembly's (its 4th power) not
    mid = (tp[0] + tp[1]) // 2
    sec_system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples).add(
        CubicSpring(K3), disk.point_map(r.basis, "tip", (0,)), "tip cubic")
    _, J_sector, _ = sec_system.residual(r.coefficients[mid].ravel(), float(r.omega[mid]))
    _, J_full, _ = system.residual(X[mid], float(r.omega[mid]))
    assert sp.issparse(J_full)
    assert determinant_sign(J_sector) < 0 < determinant_sign(J_full)
    assert determinant_sign(J_full.toarray()) > 0          # the sparse LU's sign is the dense one's
    # the bordered determinant flips at both folds: three more null directions there
    assert len(st.branch_points) == 2 and all(min(abs(int(idx[b]) - t) for t in tp) <= 2 for b in st.branch_points)


def test_shift_invert_on_the_assembly_gives_the_dense_exponents(sector, assembly):
    """The sparse eigen-solver (ARPACK shift-invert, the ``n_near`` exponents nearest to zero)
    against every eigenvalue by QZ, at a stable and an unstable point of the same assembly."""
    _, r = sector
    _, system, X = assembly
    tp = sorted(int(t) for t in r.turning_points)
    for i in (tp[0] - 20, (tp[0] + tp[1]) // 2, tp[1] + 20):
        w = float(r.omega[i])
        dense = floquet_exponents(system, X[i], w)                # half the spectrum or more: QZ
        near = floquet_exponents(system, X[i], w, n_near=24)
        assert dense.eigensolver == "dense" and near.eigensolver == "shift-invert"
        assert dense.stable == near.stable == bool(r.stable[i])
        # the sector's resolved exponents (the assembly's four equal copies count once: a copy
        # within DUPLICATE_TOLERANCE of one kept is dropped)
        cyclic = r.floquet_exponents[i][np.isfinite(r.floquet_exponents[i])]
        # matched one to one, nearest first (sort_complex orders a conjugate pair by the rounding
        # of its real parts: an arc-length change of the branch swapped two such pairs)
        assert len(dense.exponents) == len(cyclic)
        unmatched = list(cyclic)
        for e in dense.exponents:
            k = int(np.argmin(np.abs(np.array(unmatched) - e)))
            assert abs(unmatched[k] - e) <= 1e-7 * abs(e), (e, unmatched[k])
            unmatched.pop(k)
        assert near.max_real == pytest.approx(dense.max_real, rel=1e-8, abs=1e-10 * w)
        # every exponent found by shift-invert is one of the dense ones
        gap = [np.min(np.abs(dense.exponents - m)) for m in near.exponents]
        assert max(gap) < 1e-6 * w


class TipLink(TimeDomainElement):
    """A linear spring k [N/m] between the x motions of two blade tips (u0, u1) [m]:
    f = k (u0 - u1) (1, -1), memoryless (the ring coupling the dampers would give, without their
    hysteresis)."""

    n_local = 2

    def __init__(self, stiffness):
        self.stiffness = stiffness

    def forces_in_time(self, u, omega):
        d = u[:, 0] - u[:, 1]
        k = self.stiffness * np.array([[1.0, -1.0], [-1.0, 1.0]])
        return self.stiffness * np.stack([d, -d], axis=1), np.broadcast_to(k, (len(u), 2, 2)).copy()


LINK = 600.0             # [N/m]: the nodal diameters of 1F split by ~1 Hz each (ND 0: 95 Hz)


@pytest.fixture(scope="module")
def ring(sector):
    """The disk of ``sector`` with neighbouring tips linked (``TipLink``): the sector's FRF with
    stability, the full assembly's system and the sector's points written out on it."""
    disk = sector[0]
    tip = disk.blade.shape("tip")[0]

    def neighbour(h):                    # (this tip, next tip): harmonic h of the next is e^{i h dphi} times
        out = np.zeros((2, disk.blade.n_modes), dtype=complex)
        out[0], out[1] = tip, np.exp(1j * h * disk.interblade_phase) * tip
        return out

    links = lambda basis: tip_springs(disk)(basis) + [Coupling(TipLink(LINK), basis.real_form(neighbour), "tip link")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bd.hbm.accuracy.AccuracyWarning)
        r = bd.frequency_response(disk, (90.0, 110.0), harmonics=(1,), stability=True, extra_couplings=links,
                                  max_step=0.05)
    assert r.success and r.stability_method == "hill" and len(r.bifurcations["fold"]) == 2
    full = MistunedDisk.from_tuned(disk, dampers=None)
    system = assembly_system(full, r.basis.harmonics)
    C = r.basis.n_coeffs
    for k in range(full.n_sector):
        T = np.zeros((2 * C, system.n_unknowns))          # local (C, 2) harmonic-major: rows (c, i)
        T[0::2] = full.point_map(system.basis, "tip", (0,), blade=k)
        T[1::2] = full.point_map(system.basis, "tip", (0,), blade=(k + 1) % full.n_sector)
        system = system.add(TipLink(LINK), sp.csr_matrix(T), f"tip link {k}")
    return r, full, system, expand(full, r.basis, r.coefficients)


def test_coupled_ring_assembly_holds_the_sector_exponents(ring):
    """Blades coupled tip to tip (``TipLink``, memoryless): the travelling waves of the engine
    order are an invariant subspace of the full assembly, so at every point the sector's resolved
    exponents are among the assembly's (sparse Jacobian, 4 x (4 modes + 2 links)), and the
    assembly is unstable wherever the sector is; it may be unstable where the sector is not (other
    nodal diameters: test_ring_assembly_instability_missed_by_the_sector_in_the_time_domain)."""
    r, full, system, X = ring
    f_norm = np.linalg.norm(system.excitation(float(r.omega[0]))[0])
    tp = sorted(int(t) for t in r.turning_points)
    idx = sorted(set(range(0, len(r.omega), 16)) | {tp[0] - 10, (tp[0] + tp[1]) // 2, tp[1] + 1, tp[1] + 10})
    unstable_seen = 0
    for i in idx:
        w = float(r.omega[i])
        assert np.linalg.norm(system.residual(X[i], w, False)[0]) < 1e-10 * f_norm
        full_point = floquet_exponents(system, X[i], w)
        assert full_point.method == "hill" and full_point.eigensolver == "dense"
        sector_exponents = r.floquet_exponents[i][np.isfinite(r.floquet_exponents[i])]
        gap = [np.min(np.abs(full_point.exponents - m)) for m in sector_exponents]
        assert max(gap) < 1e-7 * w, (i, sector_exponents, full_point.exponents)
        assert full_point.max_real >= np.max(sector_exponents.real) - 1e-9 * w
        if not r.stable[i]:
            assert not full_point.stable
            unstable_seen += 1
    assert unstable_seen >= 1


@pytest.mark.slow
def test_ring_assembly_instability_missed_by_the_sector_in_the_time_domain(ring):
    """Just before the upper fold the full assembly of the linked ring is unstable where the
    sector is stable (measured: a pair of exponents Re +0.33 1/s, Im 0.09 rad/s, other nodal
    diameters; the sector's largest -0.39 1/s). Time integration of the assembly from the HBM
    solution: there the blades split (blades 1 and 3 drop to ~5 % of the travelling wave within
    150 periods, 0 and 2 stay: a standing pattern), while 10 points earlier, stable for both, every
    blade returns to the travelling wave. The seed is the one-harmonic solution's own truncation
    error (~0.1 %: a snapshot of it is not a symmetric state of the flow); a perturbation of 1e-5
    or 1e-2 of blade 0 gives the same split."""
    r, full, system, X = ring
    tp = min(int(t) for t in r.turning_points)
    window = [i for i in range(tp - 6, tp + 1) if r.stable[i]
              and not floquet_exponents(system, X[i], float(r.omega[i])).stable]
    assert window, "no point of the branch between the assembly's loss of stability and the sector's fold"
    for i, missed in ((window[-1], True), (window[-1] - 10, False)):
        assert floquet_exponents(system, X[i], float(r.omega[i])).stable != missed
        w = float(r.omega[i])
        amplitude = _integrate_assembly(full, X[i], w, periods=150, link=LINK,
                                        perturbation=1e-3 * float(np.abs(r.coefficients[i, :, 0]).max()), blades=[0])
        ratio = amplitude / r.tip_amplitude[i, 0]
        if missed:
            assert ratio.min() < 0.5 and ratio.max() > 0.9, ratio      # the travelling wave is left
        else:
            np.testing.assert_allclose(ratio, 1.0, rtol=3e-3)


def _integrate_assembly(assembly, x0, omega, periods, perturbation, link=0.0, blades=None):
    """The assembly's modal equations q_k'' + 2 zeta w q_k' + w^2 q_k + phi (k3 (phi . q_k)^3 +
    link (2 u_k - u_{k+1} - u_{k-1})) = f cos(omega t + k dphi) (phi the tip's x shape, u_k =
    phi . q_k; unit modal masses) by DOP853 from the harmonic-balance state at t = 0 (``x0``:
    harmonics (1,)) with the first modal coordinate of ``blades`` (default all) moved by
    ``perturbation`` [m]; returns the first-harmonic tip amplitude [m] of every blade over the
    last period. Independent of bladedamp's integrators."""
    blade = assembly.blades[0]
    nm, s = assembly.n_modes, assembly.n_sector
    w0 = blade.natural_angular_frequencies
    zeta = blade.damping_ratios
    phi = blade.shape("tip")[0]
    f = blade.shape("excitation").T @ assembly.excitation
    theta = assembly.interblade_phase * np.arange(s)
    X = x0.reshape(2, assembly.n_dof)[:, :s * nm].reshape(2, s, nm)          # cos, sin coefficients
    q0 = X[0].copy()
    q0[list(range(s)) if blades is None else blades, 0] += perturbation
    v0 = omega * X[1]

    def rhs(t, y):
        q, v = y[:s * nm].reshape(s, nm), y[s * nm:].reshape(s, nm)
        u = q @ phi
        restoring = K3 * u ** 3 + link * (2 * u - np.roll(u, -1) - np.roll(u, 1))
        a = np.cos(omega * t + theta)[:, None] * f - 2 * zeta * w0 * v - w0 ** 2 * q - restoring[:, None] * phi
        return np.concatenate([v.ravel(), a.ravel()])

    T = 2 * np.pi / omega
    t_eval = np.linspace((periods - 1) * T, periods * T, 129)[:-1]
    sol = solve_ivp(rhs, (0.0, periods * T), np.concatenate([q0.ravel(), v0.ravel()]), method="DOP853",
                    rtol=1e-9, atol=1e-13, t_eval=t_eval)
    u = sol.y[:s * nm].reshape(s, nm, -1).transpose(0, 2, 1) @ phi           # (s, samples)
    return 2 * np.abs(np.fft.rfft(u, axis=1)[:, 1]) / u.shape[1]


@pytest.mark.slow
@pytest.mark.parametrize("where", ["upper stable", "unstable", "lower stable"])
def test_disk_stability_confirmed_by_time_integration(sector, assembly, where):
    """Item 2, disk: the full assembly integrated in time from the HBM solution with a small
    perturbation (1e-3 of the amplitude on every blade) stays on it at stable points and leaves
    the unstable segment for a stable solution of the same frequency (the largest exponent there
    is ~ +10 1/s: the perturbation grows 1000-fold in 0.7 s)."""
    _, r = sector
    full, _, X = assembly
    tp = sorted(int(t) for t in r.turning_points)
    i = {"upper stable": tp[0] - 20, "unstable": (tp[0] + tp[1]) // 2, "lower stable": tp[1] + 20}[where]
    assert r.stable[i] == (where != "unstable")
    w = float(r.omega[i])
    a = r.tip_amplitude[:, 0]
    amplitude = _integrate_assembly(full, X[i], w, periods=250 if where == "unstable" else 60,
                                    perturbation=1e-3 * float(np.abs(r.coefficients[i, :, 0]).max()))
    if where == "unstable":
        assert np.all(np.abs(amplitude / a[i] - 1) > 0.05), "the motion must leave the unstable solution"
        near = r.stable & (np.abs(r.omega - w) < 2e-3 * w)
        for A in amplitude:                                     # every blade on a stable solution
            assert np.min(np.abs(a[near] / A - 1)) < 1e-2
    else:
        np.testing.assert_allclose(amplitude, a[i], rtol=2e-3)


@pytest.mark.slow
def test_full_assembly_continuation_folds_where_the_sector_does(sector):
    """The assembly's own continuation (sparse LU) with Hill's method on every point: the folds
    and the stability changes at the sector's frequencies; the stability's cost is reported
    against the solve's (``bifurcations["seconds"]`` is the sector's)."""
    from bladedamp.hbm.continuation import continuation

    disk, r = sector
    full = MistunedDisk.from_tuned(disk, dampers=None)
    system = assembly_system(full, r.basis.harmonics)
    w0, w1 = float(r.omega[0]), float(r.omega[-1])
    scales = full.unknown_scales(system, w0, w1)
    t0 = time.perf_counter()
    _, J0, _ = system.residual(np.zeros(system.n_unknowns), w0)
    x0 = spsolve(J0.tocsc(), system.excitation(w0)[0])
    branch = continuation(system.residual, x0, w0, w1, x_scale=scales, factorize=system.factorize, max_step=0.05)
    solve = time.perf_counter() - t0
    assert branch.success, branch.message
    st = branch_stability(system, branch.x, branch.omega, scales)
    assert st.method == "hill" and st.kinds == ("fold", "fold")
    f_full = np.sort(branch.omega[branch.turning_points]) / (2 * np.pi)
    f_sector = np.sort(r.omega[r.turning_points]) / (2 * np.pi)
    np.testing.assert_allclose(f_full, f_sector, rtol=2e-4)
    f_change = np.sort(branch.omega[st.changes]) / (2 * np.pi)
    np.testing.assert_allclose(f_change, f_sector, rtol=2e-3)
    assert st.seconds > 0 and solve > 0
    print(f"assembly: solve {solve:.2f} s, stability {st.seconds:.2f} s ({st.seconds / solve:.2f} of the solve), "
          f"{len(branch.omega)} points")
