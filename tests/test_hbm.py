"""Harmonic balance engine: Fourier basis, residual Jacobian, continuation through folds, failures."""
import dataclasses
import warnings

import numpy as np
import pytest
import scipy.optimize
import scipy.sparse as sp
from conftest import central_difference, duffing_jenkins_residual, relative_matrix_error

from bladedamp import FrictionOscillator
from bladedamp.contact import SEPARATED, SLIP, STICK
from bladedamp.hbm import HarmonicBasis
from bladedamp.hbm.continuation import ConvergenceWarning, continuation, newton
from bladedamp.hbm import system as system_module
from bladedamp.hbm.elements import CubicSpring, GapSpring
from bladedamp.hbm.system import Coupling
from bladedamp.reference import reference_disk


# ---------------------------------------------------------------------------------------
# Fourier basis against analytic signals
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("harmonics", [(1,), (0, 1, 2, 3), (1, 3, 5, 7)], ids=str)
def test_basis_synthesis_derivative_and_work(harmonics):
    """Synthesis, analysis, d/dtau and work_per_cycle against the analytic signals
    x = c0 + sum a_h cos(h tau) + b_h sin(h tau)."""
    basis = HarmonicBasis(harmonics)
    rng = np.random.default_rng(3)
    c = rng.normal(size=(basis.n_coeffs, 2))
    g = rng.normal(size=(basis.n_coeffs, 2))
    tau = basis.tau

    def signal(coeffs, tau, derivative=False):
        out = np.zeros((tau.size, coeffs.shape[1]))
        for h in basis.harmonics:
            j = basis.cos_index(h)
            if h == 0:
                out += 0.0 if derivative else coeffs[j]
            elif derivative:
                out += h * (-np.outer(np.sin(h * tau), coeffs[j]) + np.outer(np.cos(h * tau), coeffs[j + 1]))
            else:
                out += np.outer(np.cos(h * tau), coeffs[j]) + np.outer(np.sin(h * tau), coeffs[j + 1])
        return out

    assert np.allclose(basis.to_time(c), signal(c, tau), atol=1e-13)
    assert np.allclose(basis.to_coeffs(basis.to_time(c)), c, atol=1e-13)
    assert np.allclose(basis.to_time(basis.derivative @ c), signal(c, tau, derivative=True), atol=1e-12)
    # oint f dx over a period by a fine independent quadrature (trapezoid on 10007 points)
    fine = 2 * np.pi * np.arange(10007) / 10007
    W_ref = np.sum(signal(g, fine) * signal(c, fine, derivative=True), axis=0) * 2 * np.pi / fine.size
    W = basis.work_per_cycle(g, c)
    assert np.allclose(W, W_ref, rtol=1e-10, atol=1e-12), f"{W} vs {W_ref}"
    # complex amplitudes X_h = a_h - i b_h: x(tau) = sum_h Re(X_h e^{i h tau})
    X = basis.to_complex(c)
    x_c = sum(np.real(np.outer(np.exp(1j * h * tau), X[h])) for h in basis.harmonics)
    assert np.allclose(x_c, signal(c, tau), atol=1e-13)
    assert np.allclose(basis.from_complex(X), c)


def test_dynamic_stiffness_is_the_equation_of_motion():
    """A(Omega) x = coefficients of M x'' + D x' + K x (x'' w.r.t. t = Omega^2 d2/dtau2), 2 DOF."""
    basis = HarmonicBasis((0, 1, 2, 5))
    M = np.array([[2.0, 0.3], [0.3, 1.0]])
    D = np.array([[0.5, -0.1], [-0.1, 0.2]])
    K = np.array([[3e4, -1e4], [-1e4, 2e4]])
    omega = 123.4
    rng = np.random.default_rng(5)
    X = rng.normal(size=(basis.n_coeffs, 2))
    A, dA = basis.dynamic_stiffness(omega, M, D, K)
    d = basis.derivative
    ref = (X @ K.T) + omega * (d @ X) @ D.T + omega ** 2 * (d @ d @ X) @ M.T
    assert np.allclose((A @ X.ravel()).reshape(X.shape), ref, rtol=1e-12, atol=1e-9)
    dA_fd = (basis.dynamic_stiffness(omega + 1e-4, M, D, K)[0]
             - basis.dynamic_stiffness(omega - 1e-4, M, D, K)[0]) / 2e-4
    assert relative_matrix_error(dA, dA_fd) < 1e-9
    # and the complex form of paper Eq. 5 per harmonic: K - (h Omega)^2 M + i h Omega D
    A_c = basis.real_form(lambda h: K - (h * omega) ** 2 * M + 1j * h * omega * D)
    assert relative_matrix_error(A, A_c) < 1e-14


def test_real_form_is_complex_multiplication():
    """real_form(G_h) acting on coefficients = G_h X_h on complex amplitudes."""
    basis = HarmonicBasis((0, 1, 3))
    rng = np.random.default_rng(7)
    G = {h: rng.normal(size=(2, 3)) + (1j * rng.normal(size=(2, 3)) if h else 0) for h in basis.harmonics}
    X = rng.normal(size=(basis.n_coeffs, 3))
    Y = (basis.real_form(lambda h: G[h]) @ X.ravel()).reshape(basis.n_coeffs, 2)
    Xc, Yc = basis.to_complex(X), basis.to_complex(Y)
    for h in basis.harmonics:
        assert np.allclose(Yc[h], G[h] @ Xc[h], atol=1e-13)


def test_system_dynamic_stiffness_from_cached_parts_is_the_basis_one():
    """HarmonicBalanceSystem.dynamic_stiffness builds the Omega-independent parts once: at every
    frequency it is bit-identical to K_0 - Omega^2 M_2 + Omega G of the parts (with the static
    stiffness on the static harmonic) and to HarmonicBasis.dynamic_stiffness of the matrices,
    returns new arrays, and the cached parts are not changed by it."""
    system = reference_disk("cylinder", 1e-3).hbm_system((0, 1, 2))
    n, j = system.n_dof, system.basis.cos_index(0)
    K0, M2, G = (p.copy() for p in system.basis.dynamic_stiffness_parts(system.mass, system.damping, system.stiffness))
    for omega in (580.0, 600.0, 580.0):
        A, dA = system.dynamic_stiffness(omega)
        A_basis, dA_basis = system.basis.dynamic_stiffness(omega, system.mass, system.damping, system.stiffness)
        A_ref, dA_ref = K0 - omega ** 2 * M2 + omega * G, -2 * omega * M2 + G
        assert np.array_equal(A_basis, A_ref) and np.array_equal(dA_basis, dA_ref)
        A_ref[j * n:(j + 1) * n, j * n:(j + 1) * n] += system.static_stiffness
        assert np.array_equal(A, A_ref) and np.array_equal(dA, dA_ref)
        A_only, none = system.dynamic_stiffness(omega, derivative=False)
        assert none is None and np.array_equal(A_only, A_ref) and A_only is not A
        A += 1.0                                    # the caller may change what it got


def _maps_with_zero_rows_and_columns():
    """Random dense maps with zero rows and columns, and the reference disk's: its damper contacts'
    sector map (no zero row or column) and the map to the blade tip (the damper's columns zero)."""
    rng = np.random.default_rng(21)
    maps = []
    for m, n in ((192, 128), (30, 17), (6, 40)):
        T = rng.standard_normal((m, n))
        T[rng.random(m) < 0.5] = 0.0
        T[:, rng.random(n) < 0.4] = 0.0
        maps.append(T)
    disk = reference_disk("cylinder", 1e-3)
    system = disk.hbm_system((0, 1, 2, 3))
    return maps + [system.couplings[0].matrix, disk.point_map(system.basis, "tip", (0, 1))]


@pytest.mark.parametrize("layout", ["C", "F"])
def test_coupling_projection_on_the_nonzero_rows_and_columns_equals_the_dense_one(monkeypatch, layout):
    """Coupling.add_jacobian and add_forces, through the map restricted to its nonzero rows and
    columns (Coupling.support), equal the dense T^T (dF/dw) T and T^T F to rounding (1e-13 of the
    largest entry), on random maps and the disk's, into a C- or Fortran-ordered Jacobian."""
    monkeypatch.setattr(system_module, "PRUNE_MIN_SAVING", 1)       # restrict every map with a zero row or column
    rng = np.random.default_rng(22)
    restricted = 0
    for T in _maps_with_zero_rows_and_columns():
        m, n = T.shape
        coupling = Coupling(CubicSpring(1.0), T)
        restricted += coupling.support() is not None
        jac, f = rng.standard_normal((m, m)), rng.standard_normal(m)
        J0, R0 = rng.standard_normal((n, n)), rng.standard_normal(n)
        J = np.array(J0, order=layout)
        out = coupling.add_jacobian(J, jac)
        assert out is J
        R = R0.copy()
        coupling.add_forces(R, f)
        assert relative_matrix_error(J - J0, T.T @ jac @ T) < 1e-13
        assert np.abs(R - R0 - T.T @ f).max() <= 1e-13 * np.abs(T.T @ f).max()
    assert restricted == 4          # all but the damper contacts' map


@pytest.mark.parametrize("model", ["flat oscillator", "inclined oscillator", "disk with a tip stop"])
def test_residual_through_the_restricted_maps_equals_the_dense_one(monkeypatch, model):
    """The residual, its Jacobian and omega-derivative with every map restricted to its nonzero rows
    and columns equal those through the dense maps to rounding (1e-13 of the largest entry)."""
    if model == "disk with a tip stop":
        disk = reference_disk("cylinder", 1e-3)
        system = disk.hbm_system((0, 1, 2))
        system = system.add(GapSpring(1e6, 0.0), disk.point_map(system.basis, "tip", (0,)), "tip stop")
        omega = 2 * np.pi * 95.0
    else:
        osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0, normal_stiffness=1.5e4,
                                 contact_angle=0.3 if model == "inclined oscillator" else 0.0)
        system = osc.hbm_system((0, 1, 3))
        omega = 117.0
    x = np.random.default_rng(23).normal(scale=1e-4, size=system.n_unknowns)

    def evaluate(threshold):
        monkeypatch.setattr(system_module, "PRUNE_MIN_SAVING", threshold)
        # the same system with new couplings, which find their support anew under the threshold
        fresh = dataclasses.replace(system, couplings=[dataclasses.replace(c) for c in system.couplings])
        restricted = [c.support() is not None for c in fresh.couplings]
        return fresh.residual(x, omega), restricted

    (R, J, Rw), restricted = evaluate(1)
    (R_d, J_d, Rw_d), dense = evaluate(np.inf)
    assert any(restricted) and not any(dense)
    assert np.abs(R - R_d).max() <= 1e-13 * np.abs(R_d).max()
    assert relative_matrix_error(J, J_d) < 1e-13
    assert np.abs(Rw - Rw_d).max() <= 1e-13 * np.abs(Rw_d).max()


# ---------------------------------------------------------------------------------------
# residual Jacobian against finite differences
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("harmonics", [(1,), (0, 1, 2, 3), (1, 3, 5)], ids=str)
def test_residual_jacobian_matches_finite_differences(harmonics):
    """dR/dx and dR/dOmega of the FrictionOscillator (inclined contact with lift-off, cubic
    spring) equal central differences, at a state with stick, slip and lift-off."""
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0, contact_angle=0.3,
                             normal_stiffness=1.5e4, cubic_stiffness=1e9)
    system = osc.hbm_system(harmonics)
    basis = system.basis
    C = basis.n_coeffs
    rng = np.random.default_rng(11)
    x = rng.normal(scale=3e-4, size=C)
    x[basis.cos_index(1)] = 2.5e-3        # x sin(alpha) reaches -N0/k_N: lift-off
    omega = 117.0
    contact = system.couplings[0]
    pts = contact.element.samples(contact.matrix @ x, basis)
    counts = np.bincount(pts.state.ravel(), minlength=3)
    assert counts[STICK] > 0 and counts[SLIP] > 0 and counts[SEPARATED] > 0, f"state mix {counts}"
    R, J, Rw = system.residual(x, omega)
    step = 1e-6 * np.abs(x).max()
    J_fd = central_difference(lambda y: system.residual(y, omega, jacobian=False)[0], x, step)
    Rw_fd = (system.residual(x, omega + 1e-4, False)[0] - system.residual(x, omega - 1e-4, False)[0]) / 2e-4
    err_x = relative_matrix_error(J, J_fd)
    err_w = np.abs(Rw - Rw_fd).max() / np.abs(Rw).max()
    print(f"states {counts.tolist()}: dR/dx rel err {err_x:.2e}, dR/dOmega rel err {err_w:.2e}")
    assert err_x < 1e-6 and err_w < 1e-6, \
        f"states {counts.tolist()}: dR/dx rel err {err_x:.2e}, dR/dOmega rel err {err_w:.2e}"


# ---------------------------------------------------------------------------------------
# continuation through folds: hardening Duffing + friction
# ---------------------------------------------------------------------------------------
DUFFING = dict(damping=2.0, normal_load=3.0, forcing=2.0, cubic_stiffness=1e9)
FOLD_SAMPLES = 4096          # AFT samples: describing-function error ~1e-7 at the kinks


@pytest.fixture(scope="module")
def duffing_frf():
    osc = FrictionOscillator(**DUFFING)
    return osc, osc.frequency_response(100.0 / (2 * np.pi), 160.0 / (2 * np.pi), harmonics=(1,), n_samples=FOLD_SAMPLES)


def _closed_form_fold(osc, A0, w0):
    """Fold of the single-harmonic describing-function FRF: G = 0 and dG/dA = 0."""
    def eqs(z):
        A, w = z
        h = 1e-6 * A
        G = lambda a: duffing_jenkins_residual(a, w, osc) * a ** 2 / osc.forcing ** 2
        return [G(A), (G(A + h) - G(A - h)) / (2 * h) * A]
    sol = scipy.optimize.root(eqs, [A0, w0], tol=1e-14)
    assert np.max(np.abs(eqs(sol.x))) < 1e-9, sol.message
    return sol.x


def _refined_hbm_fold(system, frf, tp, kind):
    """Extremum of omega along the HBM branch between points tp-1 and tp+1.

    Points y = (x / s, omega / 100) on the hyperplane n . (y - y_tp) = sigma, n the secant
    from tp-1 to tp+1, solved by Newton with the analytic Jacobian; then a bounded scalar
    search for the extremum of omega(sigma).
    """
    s = np.abs(frf.coefficients[tp]).max()
    Y = np.hstack([frf.coefficients[:, :, 0] / s, frf.omega[:, None] / 100])
    n = Y[tp + 1] - Y[tp - 1]
    n /= np.linalg.norm(n)

    def solve(sigma):
        y = Y[tp] + sigma * n
        for _ in range(50):
            R, J, Rw = system.residual(y[:-1] * s, y[-1] * 100)
            G = np.append(R / system.excitation(0)[0].max(), n @ (y - Y[tp]) - sigma)
            M = np.vstack([np.hstack([J * s, Rw[:, None] * 100]) / system.excitation(0)[0].max(), n])
            dy = np.linalg.solve(M, -G)
            y = y + dy
            if np.linalg.norm(dy) < 1e-13:
                return y
        raise AssertionError(f"fold refinement: Newton did not converge at sigma = {sigma}")

    lo, hi = n @ (Y[tp - 1] - Y[tp]), n @ (Y[tp + 1] - Y[tp])
    best = scipy.optimize.minimize_scalar(lambda sg: -kind * solve(sg)[-1], bounds=(lo, hi), method="bounded",
                                          options={"xatol": 1e-12})
    y = solve(best.x)
    return np.hypot(*y[:-1]) * s, y[-1] * 100


def test_continuation_passes_two_folds(duffing_frf):
    """Two turning points; the closed-form folds (describing function of Duffing + Jenkins)
    lie on the branch segments around the turning points; the refined HBM fold matches them:
    frequency to 1e-6, amplitude to 1e-3 (the fold amplitude is where d omega / dA = 0; the ~1e-7 AFT error of the kinked force oscillates in A with a period
    ~1/T, so its A-derivative, which moves the fold, is ~T times larger)."""
    osc, frf = duffing_frf
    assert frf.success, frf.message
    tps = frf.turning_points
    assert len(tps) == 2, f"turning points at {frf.omega[tps]} rad/s"
    a, w = frf.harmonic_amplitude(), frf.omega
    system = osc.hbm_system((1,), FOLD_SAMPLES)
    kinds = []
    for tp in tps:
        A_f, w_f = _closed_form_fold(osc, a[tp], w[tp])
        # the fold lies between the neighbours of the turning point (tp-1 and tp+1)
        lo, hi = a[tp - 1:tp + 2].min(), a[tp - 1:tp + 2].max()
        print(f"closed-form fold amplitude {A_f:.6e}, turning segment [{lo:.6e}, {hi:.6e}]")
        assert lo <= A_f <= hi, f"closed-form fold amplitude {A_f:.6e} not in the turning segment [{lo:.6e}, {hi:.6e}]"
        kind = np.sign(w[tp - 1] - w[tp - 2])     # +1: omega was increasing -> maximum
        kinds.append(kind)
        near = w[max(tp - 5, 0):tp + 5]
        extreme = near.max() if kind > 0 else near.min()
        print(f"closed-form fold frequency {w_f:.6f}, extreme branch frequency {extreme:.6f}")
        assert kind * (extreme - w_f) <= 1e-6 * w_f, f"branch goes beyond the fold frequency {w_f:.6f}: {extreme:.6f}"
        # HBM fold, refined: solutions on hyperplanes across the branch near the turning
        # segment, omega(sigma) maximised/minimised by a bounded scalar search
        A_h, w_h = _refined_hbm_fold(system, frf, tp, kind)
        print(f"HBM fold ({A_h:.6e} m, {w_h:.6f} rad/s) vs closed form ({A_f:.6e} m, {w_f:.6f} rad/s): "
              f"rel {A_h / A_f - 1:.1e}, {w_h / w_f - 1:.1e}")
        assert abs(w_h / w_f - 1) < 1e-6 and abs(A_h / A_f - 1) < 1e-3, \
            f"HBM fold ({A_h:.6e} m, {w_h:.6f} rad/s) vs closed form ({A_f:.6e} m, {w_f:.6f} rad/s): " \
            f"rel {A_h / A_f - 1:.1e}, {w_h / w_f - 1:.1e}"
    assert kinds == [1, -1], "expected the jump-down fold (omega max) first, then the jump-up fold (omega min)"


def test_three_solutions_between_the_folds(duffing_frf):
    """Between the fold frequencies the branch crosses the frequency three times; Newton from
    each crossing converges to the three closed-form amplitudes (1e-5)."""
    osc, frf = duffing_frf
    w = frf.omega
    w_mid = w[frf.turning_points].mean()
    d = w - w_mid
    crossings = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
    assert crossings.size == 3, f"{crossings.size} crossings of {w_mid:.3f} rad/s"
    system = osc.hbm_system((1,), FOLD_SAMPLES)
    amps = []
    for i in crossings:
        res = newton(system.residual, frf.coefficients[i].ravel(), w_mid, np.abs(frf.coefficients[i]).max(),
                     osc.forcing)
        assert res.converged
        amps.append(np.hypot(*res.x))
    grid = np.geomspace(1e-5, 1e-2, 20001)
    g = duffing_jenkins_residual(grid, w_mid, osc)
    roots = [scipy.optimize.brentq(duffing_jenkins_residual, grid[i], grid[i + 1], args=(w_mid, osc), xtol=1e-16)
             for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
    assert len(roots) == 3, f"closed form has {len(roots)} solutions"
    err = np.abs(np.sort(amps) / np.sort(roots) - 1)
    print(f"amplitudes {np.sort(amps)} vs closed form {np.sort(roots)}: rel err {err}")
    assert err.max() < 1e-5, f"amplitudes {np.sort(amps)} vs closed form {np.sort(roots)}: rel err {err}"
    assert len(set(np.round(np.sort(amps) / max(amps), 3))) == 3, "the three solutions must be distinct"


def test_every_branch_point_solves_the_residual(duffing_frf):
    osc, frf = duffing_frf
    system = osc.hbm_system((1,), FOLD_SAMPLES)
    worst = max(np.linalg.norm(system.residual(X.ravel(), om, jacobian=False)[0]) / osc.forcing
                for om, X in zip(frf.omega, frf.coefficients))
    print(f"max scaled residual on the branch {worst:.2e}")
    assert worst < 1e-8, f"max scaled residual on the branch {worst:.2e}"
    # and the closed-form describing-function equation, relative to |F/A|^2
    a = frf.harmonic_amplitude()
    g = duffing_jenkins_residual(a, frf.omega, osc) * a ** 2 / osc.forcing ** 2
    print(f"max |G| A^2/F^2 on the branch {np.abs(g).max():.2e}")
    assert np.abs(g).max() < 1e-5, f"max |G| A^2/F^2 on the branch {np.abs(g).max():.2e}"


@pytest.mark.parametrize("harmonics", [(1, 3), (1, 3, 5, 7)], ids=str)
def test_continuation_passes_corners_of_the_branch(harmonics):
    """Below the resonance the multi-harmonic response has local displacement extrema; when
    one of them reaches the friction limit a new slip phase is born and the AFT residual has
    a kink (the force is C0, not C1, there): the branch has a corner at ~25 and ~39.5 rad/s.
    The pseudo-arclength corrector cycles between the two pieces at any step size; the
    continuation must still reach the end (it used to stop at 25.3 / 39.55 rad/s)."""
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        frf = osc.frequency_response(20.0 / (2 * np.pi), 200.0 / (2 * np.pi), harmonics=harmonics)
    assert frf.success, frf.message
    assert frf.omega[-1] == 200.0 and np.all(np.diff(frf.omega) > 0)
    system = osc.hbm_system(harmonics)
    worst = max(np.linalg.norm(system.residual(X.ravel(), om, jacobian=False)[0]) / osc.forcing
                for om, X in zip(frf.omega, frf.coefficients))
    print(f"max scaled residual on the branch {worst:.2e}")
    assert worst < 1e-8, f"max scaled residual on the branch {worst:.2e}"


# ---------------------------------------------------------------------------------------
# failures are reported, not hidden
# ---------------------------------------------------------------------------------------
class NaNAbove:
    """A broken element: NaN forces above ``omega_bad``."""

    n_local = 1

    def __init__(self, omega_bad):
        self.omega_bad = omega_bad

    def harmonic_forces(self, local, basis, omega, jacobian=True):
        C = basis.n_coeffs
        force = np.zeros((C, 1)) + (np.nan if omega > self.omega_bad else 0.0)
        return force, (np.zeros((C, C)) if jacobian else None), None


def _broken_system(omega_bad):
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    system = osc.hbm_system((1, 3))
    system.couplings.append(Coupling(NaNAbove(omega_bad), np.eye(system.basis.n_coeffs), "broken"))
    return system


def test_nan_element_stops_with_message_and_keeps_branch():
    system = _broken_system(115.0)
    with pytest.warns(ConvergenceWarning, match="115"):
        branch = continuation(system.residual, system.linear_solution(90.0), 90.0, 140.0, x_scale=1e-3)
    assert not branch.success
    assert branch.omega.size > 10 and branch.x.shape == (branch.omega.size, system.n_unknowns)
    assert branch.omega.max() <= 115.0 and branch.omega[-1] > 115.0 - 1e-3, f"stopped at {branch.omega[-1]}"
    assert f"{branch.omega[-1]:.6g}" in branch.message, branch.message
    worst = max(np.linalg.norm(system.residual(x, om, False)[0]) for om, x in zip(branch.omega, branch.x))
    assert worst < 1e-8, "the kept points must be converged solutions"


def test_newton_failure_at_the_start_is_reported():
    system = _broken_system(100.0)
    with pytest.warns(ConvergenceWarning, match=r"start, omega = 120"):
        branch = continuation(system.residual, system.linear_solution(120.0), 120.0, 140.0, x_scale=1e-3)
    assert not branch.success and branch.omega.size == 0 and "120" in branch.message


def test_absurd_settings_fail_gracefully():
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    # a minimum step above the first step: contradictory, refused (issue 12, item 6)
    with pytest.raises(ValueError, match=r"min_step must be in \(0.0, 0.01\]"):
        osc.frequency_response(90.0 / (2 * np.pi), 140.0 / (2 * np.pi), step=0.01, min_step=0.5)
    # too few points for the range
    with pytest.warns(ConvergenceWarning, match="max_points"):
        frf = osc.frequency_response(90.0 / (2 * np.pi), 140.0 / (2 * np.pi), max_points=10)
    assert not frf.success and frf.omega.size == 10 and f"{frf.omega[-1]:.6g}" in frf.message
    assert np.all(np.diff(frf.omega) > 0)


def test_chord_corrector_follows_the_same_branch():
    """continuation(chord=True) keeps the corrector's factorisation while its updates contract:
    the same branch (every point a solution to the tolerance, the same peak) with fewer
    Jacobians; a residual that ignores ``jacobian=False`` is never asked for one without it."""
    osc = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    system = osc.hbm_system((1, 3))
    calls = {"jacobian": 0, "residual only": 0}

    def fun(x, w, jacobian=True):
        calls["jacobian" if jacobian else "residual only"] += 1
        return system.residual(x, w, jacobian)

    x0 = system.linear_solution(90.0)
    newton_branch = continuation(system.residual, x0, 90.0, 140.0, x_scale=1e-3, max_step=0.05, tol=1e-10)
    chord_branch = continuation(fun, x0, 90.0, 140.0, x_scale=1e-3, max_step=0.05, tol=1e-10, chord=True,
                                target_iterations=10)
    assert newton_branch.success and chord_branch.success
    assert calls["residual only"] > 0
    scale = np.abs(newton_branch.x).max()
    for x, w in zip(chord_branch.x, chord_branch.omega):
        assert np.linalg.norm(system.residual(x, w, False)[0]) < 1e-6 * np.linalg.norm(
            system.residual(np.zeros_like(x), w, False)[0])
    a_newton = np.abs(newton_branch.x).max(axis=1).max()
    a_chord = np.abs(chord_branch.x).max(axis=1).max()
    assert abs(a_chord / a_newton - 1) < 2e-2 and scale > 0


def test_work_per_cycle_is_the_tensordot_of_its_definition():
    """HarmonicBasis.work_per_cycle (its products written out for speed) equals, bit for bit, the
    tensordot form of its definition, sum_c w_c F_c (D X)_c with w = 2 pi for the static term and
    pi otherwise, for coefficient arrays of one, two and three axes, and that sum is the mean of
    f dw/dtau over the samples times 2 pi (discrete Parseval)."""
    rng = np.random.default_rng(1)
    for harmonics in ((1,), (0, 1), (0, 1, 2, 3, 4, 5)):
        basis = HarmonicBasis(harmonics)
        C = basis.n_coeffs
        weights = np.where(basis.order == 0, 2 * np.pi, np.pi)
        for shape in ((C,), (C, 1), (C, 10), (C, 3, 12)):
            F, X = rng.normal(size=shape), rng.normal(size=shape)
            reference = np.tensordot(weights, F * np.tensordot(basis.derivative, X, axes=(1, 0)), axes=(0, 0))
            work = basis.work_per_cycle(F, X)
            assert np.shape(work) == np.shape(reference) and np.array_equal(work, reference), (harmonics, shape)
            f, dx = basis.to_time(F), basis.to_time(basis.derivative @ X.reshape(C, -1)).reshape((-1,) + shape[1:])
            np.testing.assert_allclose(work, 2 * np.pi * (f * dx).mean(axis=0), rtol=1e-12, atol=1e-12)


# ---------------------------------------------------------------------------------------
# Dense or sparse Jacobian: the same numbers, chosen by size and fill (issue 37, item 4)
# ---------------------------------------------------------------------------------------
def point_contact_ring(n, harmonics=(0, 1, 2, 3), coupled_stiffness=0.0):
    """A ring of ``n`` sectors of two 3D unit masses (springs 1e6 N/m in a chain from the ground),
    each sector's outer mass tied to the next one's by a preloaded friction point contact, the
    outer masses forced with engine order 1; ``coupled_stiffness`` [N/m] adds a spring of that
    stiffness between every pair of DOFs (a full stiffness matrix). Matrices and contact map sparse."""
    from bladedamp.contact.laws import LinearNormalLaw
    from bladedamp.contact.point import PointContactElement
    from bladedamp.hbm.system import HarmonicBalanceSystem

    basis = HarmonicBasis(harmonics, 32)
    C, N = basis.n_coeffs, 6 * n
    K = sp.kron(sp.identity(n), sp.kron(sp.csr_matrix([[2e6, -1e6], [-1e6, 1e6]]), sp.identity(3)), format="csr")
    if coupled_stiffness:
        K = sp.csr_matrix(K + coupled_stiffness * (N * np.eye(N) - np.ones((N, N))))
    M = sp.identity(N, format="csr")
    outer = 6 * np.arange(n) + 3
    rows = np.arange(3 * n)
    T0 = sp.csr_matrix((np.r_[np.ones(3 * n), -np.ones(3 * n)],
                        (np.r_[rows, rows], np.r_[np.roll(outer, -1).repeat(3) + np.tile(np.arange(3), n),
                                                  outer.repeat(3) + np.tile(np.arange(3), n)])), shape=(3 * n, N))
    f = np.zeros((C, N))
    j = basis.cos_index(1)
    f[j, outer], f[j + 1, outer] = np.cos(2 * np.pi * np.arange(n) / n), -np.sin(2 * np.pi * np.arange(n) / n)
    element = PointContactElement(np.full(n, 1e5), 0.3, LinearNormalLaw(1e5), np.ones(n), np.full(n, 1e-5))
    return HarmonicBalanceSystem(basis, M, 2.0 * M + 2e-6 * K, K, lambda w: (f.ravel(), np.zeros(C * N)),
                                 [Coupling(element, sp.kron(sp.identity(C), T0, format="csr"), "ring")])


def ring_state(system):
    """A state where the ring's contacts stick, slip and (some) lift off: the linear response
    near the first mode, scaled to 20 um."""
    w = 0.9 * np.sqrt(1e6 * (3 - np.sqrt(5)) / 2)
    x = system.linear_solution(w)
    return x * 2e-5 / np.abs(x).max(), w


def test_dense_and_sparse_assembly_give_the_same_residual_jacobian_and_step():
    """storage "dense" and "sparse" of one system (336 unknowns): the residual, dR/domega and the
    Jacobian differ only by the order of their sums, at most m u sum|terms| per entry, u = 2^-53
    and m <= N + C n_local the terms of a sum; the Newton step by at most N u cond(J) relative
    (backward-stable LU, growth factor 1: the bound of a first-order perturbation)."""
    import dataclasses as dc

    base = point_contact_ring(8)
    x, w = ring_state(base)
    dense, sparse = dc.replace(base, storage="dense"), dc.replace(base, storage="sparse")
    Rd, Jd, Rwd = dense.residual(x, w)
    Rs, Js, Rws = sparse.residual(x, w)
    assert isinstance(Jd, np.ndarray) and sp.issparse(Js) and not dense.sparse and sparse.sparse
    N, C = x.size, base.basis.n_coeffs
    u, m = 2.0 ** -53, N + C * base.couplings[0].element.n_local
    A, dA = dense.dynamic_stiffness(w)
    T = np.abs(base.couplings[0].matrix.toarray())
    force, jac, _ = base.couplings[0].element.harmonic_forces((base.couplings[0].matrix @ x).reshape(C, -1),
                                                              base.basis, w)
    f, _ = base.excitation(w)
    scale_r = np.abs(A) @ np.abs(x) + np.abs(f) + T.T @ np.abs(force.ravel())
    assert np.all(np.abs(Rd - Rs) <= m * u * scale_r)
    assert np.all(np.abs(Rwd - Rws) <= m * u * (np.abs(dA) @ np.abs(x)))
    scale_j = np.abs(A) + T.T @ np.abs(jac) @ T
    assert np.all(np.abs(Jd - Js.toarray()) <= m * u * scale_j)
    step_d, step_s = dense.factorize(Jd)(Rd), sparse.factorize(Js)(Rs)
    bound = N * u * np.linalg.cond(Jd)
    assert np.linalg.norm(step_d - step_s) <= bound * np.linalg.norm(step_d) + np.linalg.norm(np.linalg.solve(Jd, Rd - Rs))
    assert bound < 1e-6, "the comparison says something"


@pytest.mark.parametrize("n, coupled, expect_sparse", [(4, 0.0, False), (8, 0.0, True), (8, 1.0, False)],
                         ids=["168 unknowns", "336 unknowns, fill 0.06", "336 unknowns, full stiffness"])
def test_automatic_storage_follows_size_and_fill(n, coupled, expect_sparse):
    """storage "auto" (the default): dense below SPARSE_MIN_UNKNOWNS whatever the matrices given
    (here all sparse), sparse above it at a fill <= SPARSE_MAX_FILL, dense above that fill; the
    Jacobian is then the one the chosen storage gives (the dense one identical, the sparse one the
    same matrix)."""
    import dataclasses as dc

    from bladedamp.hbm import linsolve

    auto = point_contact_ring(n, coupled_stiffness=coupled)
    x, w = ring_state(auto)
    assert auto.sparse, "before the first residual the given matrices' format"
    R, J, Rw = auto.residual(x, w)
    N = x.size
    assert auto.sparse == expect_sparse == sp.issparse(J)
    forced = dc.replace(auto, storage="sparse" if expect_sparse else "dense")
    Rf, Jf, Rwf = forced.residual(x, w)
    fill = (Jf.count_nonzero() if expect_sparse else np.count_nonzero(Jf)) / N ** 2
    assert expect_sparse == (N >= linsolve.SPARSE_MIN_UNKNOWNS and fill <= linsolve.SPARSE_MAX_FILL)
    assert np.array_equal(R, Rf) and np.array_equal(Rw, Rwf)
    assert np.array_equal(J.toarray(), Jf.toarray()) if expect_sparse else np.array_equal(J, Jf)
    R2, J2, _ = auto.residual(x, w)                       # the choice is kept
    assert sp.issparse(J2) == expect_sparse and np.array_equal(R2, R)
