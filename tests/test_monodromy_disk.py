"""The monodromy matrix of a bladed disk with friction dampers (issue 14, :func:`bladedamp.hbm.
monodromy.disk_monodromy`): the Floquet multipliers from the period map of the full assembly's
time integration, started on the HBM solution.

* stuck limit: contacts that cannot slip make the assembly linear; its multipliers are checked
  against the eigenvalues of the stuck linear system, taken from the HBM Jacobian (M, D and
  K + contact stiffness of the first-harmonic block), not from the time-domain code: both the
  exact multipliers of the linear central-difference recurrence (to the finite differences'
  accuracy) and the continuous exp(lambda T) to the scheme's second-order error;
* the reference cylinder damper on a 4-blade disk, points across the 1F FRF: stable, as the
  determinant sign says, and the HBM orbit returns onto itself after one period;
* a TunedDisk (sector written out) and the equivalent tuned MistunedDisk (its own solution)
  give the same multipliers;
* models without a period map and solutions without the static harmonic are refused.

Cost: ``nice python benchmarks/bench_monodromy_disk.py 4 16`` (see :mod:`bladedamp.hbm.monodromy`).
"""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
import scipy.linalg

import bladedamp as bd
from bladedamp.blade import reference_blade
from bladedamp.damper.geometry import CylinderDamper
from bladedamp.disk import TunedDisk
from bladedamp.hbm.monodromy import assembly_coefficients, disk_monodromy, monodromy_multipliers
from bladedamp.hbm.stability import floquet_exponents
from bladedamp.mistuned import MistunedDisk
from bladedamp.reference import DAMPER_RADIUS, EXCITATION_FX, PLATFORM_ANGLE, reference_contact


def small_disk(damper, n_blades=4, blade=None, excitation=EXCITATION_FX):
    return TunedDisk(blade or reference_blade(), damper, n_blades, 1, PLATFORM_ANGLE, PLATFORM_ANGLE, DAMPER_RADIUS,
                     np.asarray(excitation, dtype=float))


def quiet_frf(disk, f0, f1, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(f0, f1, **kw)
    assert r.success, r.message
    return r


# ----- stuck limit --------------------------------------------------------------------------

def stuck_linear_system(system, x, omega):
    """(M, D, K_stuck) (N, N) of the assembly from its HBM Jacobian at the stuck solution x:
    the first-harmonic block of dR/dx is [[K - w^2 M, w D], [-w D, K - w^2 M]] (the contacts'
    AFT Jacobian there is their stick stiffness)."""
    N = system.n_dof
    _, J, _ = system.residual(x, omega, True)
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    j = system.basis.cos_index(1)
    c, s = slice(j * N, (j + 1) * N), slice((j + 1) * N, (j + 2) * N)
    M = system.mass.toarray() if hasattr(system.mass, "toarray") else np.asarray(system.mass)
    K = J[c, c] + omega ** 2 * M
    D = J[c, s] / omega
    assert np.abs(J[s, c] + omega * D).max() <= 1e-9 * np.abs(omega * D).max()    # the block structure holds
    assert np.abs(J[s, s] - J[c, c]).max() <= 1e-9 * np.abs(J[c, c]).max()
    return M, D, K


@pytest.fixture(scope="module")
def stuck():
    """A 4-blade tuned full assembly with a 1 g cylinder of mu = 1e3 (every point sticks) and
    blades of 0.5 % modal damping, harmonics (0, 1), at 92 Hz (off the 95 Hz stuck resonance)."""
    blade = dataclasses.replace(reference_blade(), damping_ratios=0.005)
    damper = CylinderDamper(1e-3, 2e-3, 20e-3, reference_contact(friction_coefficient=1e3))
    full = MistunedDisk.from_tuned(small_disk(damper, blade=blade))
    r = quiet_frf(full, 92.0, 92.3, harmonics=(0, 1))
    i = len(r.omega) // 2
    return full, r, i


def test_stuck_contacts_give_the_multipliers_of_the_stuck_linear_system(stuck):
    """Contacts that cannot slip: the period map is linear (x, x_-1, s) -> (x, x_-1, s) with the
    sliders held. Its (2 N + 2 P) monodromy is then block upper triangular with an identity
    slider block: the sliders do not depend on x (that block exactly 0) nor on each other (exactly
    diagonal), and a stuck slider keeps any offset, so its multiplier is 1 up to the rounding of
    the central difference alone, (fl(s + h) - fl(s - h)) / 2 h - 1 <= eps (|s| / h + 1). The
    multipliers of the (2 N, 2 N) block of x are

    * those of the linear central-difference recurrence of M x'' + D x' + K_stuck x = f
      (M, D, K_stuck from the HBM Jacobian, the recurrence's (2N, 2N) matrix to the power
      ``steps``): to 1e-5 (finite differences of a linear map: rounding only; measured 2.9e-7);
    * exp(lambda T) of the continuous system's eigenvalues lambda (lambda^2 M + lambda D + K_stuck
      = 0) to the scheme's error: central differences advance a mode of frequency w with
      (2 / dt) arcsin(w dt / 2) = w (1 + (w dt)^2 / 24 + ...), so its multiplier is off by
      |mu| w T (w dt)^2 / 24 (1F at 512 steps: 4.2e-5; measured equal to that to 1 %). Checked
      for every mode where that bound is below 0.05 (the stiff contact modes, w dt up to 1.6,
      are the discrete scheme's own: checked by the recurrence above).

    No mode of the stuck system grows, by energy: M is symmetric positive definite, K_stuck is
    symmetric (a stuck elastic slider is a spring) and positive definite, D symmetric positive
    semi-definite, so lambda^2 m + lambda d + k = 0 with m, k > 0, d >= 0 for any mode shape u
    (m = u* M u, ...) has Re lambda <= 0. Those properties are asserted to the rounding of the
    AFT's sums over the n_s samples (2 n_s eps of the Jacobian's largest entry). The computed
    lambda's real parts are then zero or negative to their first-order perturbation bound,
    kappa (||A|| + |lambda| ||B||) max(eta, eps) (Stewart and Sun, Matrix Perturbation Theory,
    VI.2; kappa from the left and right eigenvectors, eta the pair's backward error): the stiff,
    lightly damped contact modes have Re lambda ~ -1e-3 1/s at |lambda| ~ 4e4 1/s, a relative
    1e-8 that rounding of the pencil (||K|| ~ 4e7) can move by 1 1/s, so their sign alone
    depends on the BLAS kernels (a strict Re lambda < 0 failed on an AMD EPYC and here with
    OPENBLAS_CORETYPE=Haswell: +2.5e-3 1/s against a bound of 1.7 1/s).
    """
    full, r, i = stuck
    w = float(r.omega[i])
    system = full.hbm_system(r.basis.harmonics, r.basis.n_samples)
    x = r.coefficients[i].ravel()
    mono, z, error, steps, h = disk_monodromy(full, x, r.basis, w)
    N = full.n_dof
    P = (z.size - 2 * N) // 2
    assert P == 4 * 2 * 5 and mono.shape == (2 * N + 2 * P,) * 2
    eps = np.finfo(float).eps
    held = mono[2 * N:, 2 * N:]
    assert np.all(mono[2 * N:, :2 * N] == 0.0)                          # the sliders do not see x
    assert np.all(held == np.diag(np.diag(held)))                        # nor each other
    s, h_s = z[2 * N:], h[2 * N:]
    slider_error = np.abs(np.diag(held) - 1.0) / (eps * (np.abs(s) / h_s + 1.0))
    print(f"held sliders: |mu - 1| / its rounding bound <= {slider_error.max():.2f}")
    assert np.all(slider_error <= 1.0)
    mu_x = np.linalg.eigvals(mono[:2 * N, :2 * N])

    M, D, K = stuck_linear_system(system, x, w)
    T = 2 * np.pi / w
    dt = T / steps
    L = np.linalg.inv(M / dt ** 2 + D / (2 * dt))
    recurrence = np.block([[L @ (2 * M / dt ** 2 - K), L @ (-M / dt ** 2 + D / (2 * dt))],
                           [np.eye(N), np.zeros((N, N))]])
    discrete = np.linalg.eigvals(recurrence) ** steps
    mismatch = max(np.abs(mu_x - d).min() for d in discrete)
    print(f"discrete recurrence: max mismatch {mismatch:.2e} ({steps} steps)")
    assert mismatch < 1e-5

    # passivity of the stuck system, to the AFT's rounding (2 n_s eps of the Jacobian's scale)
    rounding = 2 * r.basis.n_samples * eps * np.abs(K).max()
    assert np.all(M == M.T) and np.linalg.eigvalsh(M).min() > 0
    assert np.abs(K - K.T).max() <= rounding
    assert np.linalg.eigvalsh((K + K.T) / 2).min() > N * rounding
    assert np.abs(D - D.T).max() <= rounding / w
    assert np.linalg.eigvalsh((D + D.T) / 2).min() >= -N * rounding / w

    A = np.block([[np.zeros((N, N)), np.eye(N)], [-K, -D]])
    B = np.block([[np.eye(N), np.zeros((N, N))], [np.zeros((N, N)), M]])
    lam, left, right = scipy.linalg.eig(A, B, left=True, right=True)
    assert lam.size == 2 * N and np.all(np.isfinite(lam))
    norm_a, norm_b = np.linalg.norm(A, 2), np.linalg.norm(B, 2)
    kappa = (np.linalg.norm(left, axis=0) * np.linalg.norm(right, axis=0)
             / np.abs(np.einsum("ik,ij,jk->k", left.conj(), B, right)))
    eta = (np.linalg.norm(A @ right - B @ right * lam, axis=0)
           / ((norm_a + np.abs(lam) * norm_b) * np.linalg.norm(right, axis=0)))
    bound = kappa * (norm_a + np.abs(lam) * norm_b) * np.maximum(eta, eps)
    worst = int(np.argmax(lam.real / bound))
    print(f"largest Re lambda / its perturbation bound: {lam.real[worst]:.3g} / {bound[worst]:.3g} 1/s "
          f"(|lambda| {abs(lam[worst]):.4g} 1/s)")
    assert np.all(lam.real <= bound)
    continuous = np.exp(lam * T)
    w_mode = np.abs(lam)
    bound = np.abs(continuous) * w_mode * T * (w_mode * dt) ** 2 / 24
    resolved = bound < 0.05
    err = np.array([np.abs(mu_x - c).min() for c in continuous])
    print("resolved modes [rad/s]:", np.round(w_mode[resolved]), "error / bound:", np.round(err[resolved] / bound[resolved], 3))
    assert resolved.sum() >= 16                                  # the blade modes at least
    assert np.all(err[resolved] <= 1.2 * bound[resolved] + 1e-6)
    # the 1F mode itself, ~6e-5 off at 512 steps: 1e-4 absolute
    one_f = np.argmin(np.abs(w_mode - 2 * np.pi * 95))
    assert err[one_f] < 1e-4
    # a stuck linear orbit: the HBM solution is the continuous orbit (exact for a linear system)
    print(f"periodicity error {error:.2e}")
    assert error < 5e-3
    res = floquet_exponents(system, x, w, method="monodromy", model=full)
    assert res.method == "monodromy" and res.stable


# ----- the reference damper on a 4-blade disk ----------------------------------------------

FRF_POINTS_HZ = (92.0, 94.0, 95.3, 96.5, 98.0)


@pytest.fixture(scope="module")
def reference4():
    """The reference 1 g cylinder and blade on a 4-blade disk (EO = 1), harmonics (0, 1, 2, 3)."""
    disk = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    return disk, quiet_frf(disk, 90.0, 100.0, harmonics=(0, 1, 2, 3))


def test_reference_cylinder_on_four_blades_is_stable_across_the_1f_frf(reference4):
    """Points below, at and above the 1F peak (slip at the peak): every point stable by the
    multipliers (largest modulus at most 1 + 1e-6: the undamped damper-on-contact modes sit on
    the unit circle), as the determinant sign says, and the HBM orbit returns to itself after
    one period (periodicity error below 5e-3 of each kind's vibration amplitude; measured
    0.4-1.6e-3, most of it the HBM's static retention spring on the damper's mean position,
    1e-4 of the normal stiffness, which the time integration does not have)."""
    disk, r = reference4
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples)
    for f in FRF_POINTS_HZ:
        i = int(np.argmin(np.abs(r.frequency_hz - f)))
        x, w = r.coefficients[i].ravel(), float(r.omega[i])
        mono = floquet_exponents(system, x, w, method="monodromy", model=disk)
        det = floquet_exponents(system, x, w)
        lead = np.abs(mono.multipliers[0])
        print(f"{r.frequency_hz[i]:.2f} Hz: max |mu| - 1 = {lead - 1:.1e}, periodicity error "
              f"{mono.periodicity_error:.2e}, det sign {det.jacobian_sign}")
        assert det.method == "determinant sign" and det.stable
        assert mono.method == "monodromy" and mono.stable == det.stable
        assert lead < 1 + 1e-6
        assert mono.periodicity_error < 5e-3
        # friction or blade damping: most multipliers strictly inside the circle
        assert np.sum(np.abs(mono.multipliers) < 0.99) >= 16


# ----- the tuned sector against the tuned full assembly ---------------------------------------

def test_tuned_sector_and_tuned_assembly_give_the_same_multipliers(reference4):
    """The sector solution (TunedDisk) written out on the full assembly is a solution of the
    assembly's own harmonic balance (residual < 1e-8 of the excitation), and the MistunedDisk's
    own Newton solution there (started 1 % off) gives the same multipliers as the TunedDisk path
    (each within 1e-6; measured ~1e-9)."""
    from bladedamp.hbm.continuation import newton

    disk, r = reference4
    full = MistunedDisk.from_tuned(disk)
    i = int(np.argmin(np.abs(r.frequency_hz - 95.3)))
    w = float(r.omega[i])
    system = full.hbm_system(r.basis.harmonics, r.basis.n_samples)
    X = assembly_coefficients(disk, full, r.coefficients[i], r.basis).ravel()
    scale = max(np.linalg.norm(system.residual(np.zeros_like(X), w, False)[0]), 1e-300)
    assert np.linalg.norm(system.residual(X, w, False)[0]) < 1e-8 * scale
    start = X * (1 + 0.01 * np.cos(np.arange(X.size)))
    sol = newton(system.residual, start, w, full.unknown_scales(system, w, w), scale, tol=1e-12, max_iter=40,
                 factorize=system.factorize)
    assert sol.converged
    mu_tuned, err_tuned = monodromy_multipliers(disk, r.coefficients[i], r.basis, w)
    mu_full, err_full = monodromy_multipliers(full, sol.x, system.basis, w)
    mismatch = max(np.abs(mu_full - a).min() for a in mu_tuned)
    print(f"max mismatch {mismatch:.1e}, periodicity errors {err_tuned:.2e} / {err_full:.2e}")
    assert mu_tuned.size == mu_full.size == 2 * full.n_dof + 2 * 4 * 2 * 5
    assert mismatch < 1e-6 and abs(err_tuned - err_full) < 1e-6


# ----- bad input -------------------------------------------------------------------------------

def test_models_without_a_period_map_and_solutions_without_the_static_harmonic_are_refused(reference4):
    disk, r = reference4
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples)
    x, w = r.coefficients[0].ravel(), float(r.omega[0])
    sector = MistunedDisk.from_tuned(disk, n_sector=2)                 # a cyclic sector of 2 blades
    with pytest.raises(ValueError, match="full-assembly MistunedDisk"):
        floquet_exponents(system, x, w, method="monodromy", model=sector)
    with pytest.raises(ValueError, match="period map"):
        monodromy_multipliers(object(), x, r.basis, w)
    one = disk.hbm_system((1,))
    with pytest.raises(ValueError, match="static harmonic"):
        monodromy_multipliers(disk, np.zeros(one.n_unknowns), one.basis, w)
    with pytest.raises(ValueError, match="steps .per period. must be >="):
        disk_monodromy(disk, x, r.basis, w, steps=64)


# ----- the reference 16-blade disk: a stuck point, and the rolling cylinder -------------------

def test_reference_disk_stuck_point_stable_and_rolling_cylinder_reported():
    """The reference disk (16 blades, 1 g cylinder, (0, 1, 2, 3)). At 92 Hz (contacts stick) the
    HBM orbit is periodic in the time integration (error < 5e-3; measured 3.9e-4) and stable by
    the multipliers, as by det J. At 95.3 Hz (slip) the time integration of this disk does not
    reach a periodic state: the cylinder keeps rolling, phi_y growing by mrad per period
    (tests/test_timedomain_disk.py::test_cylinder_hbm_against_time_integration, slow); the HBM
    holds its mean roll angle only by the static retention spring. The monodromy sees that: one
    period from the HBM state moves phi_y by ~0.01 rad (periodicity error ~0.7 of the rotations'
    vibration amplitude), with an AccuracyWarning naming phi_y."""
    from bladedamp.hbm.accuracy import AccuracyWarning

    disk = bd.reference_disk("cylinder", 1e-3)
    r = quiet_frf(disk, 91.5, 95.6, harmonics=(0, 1, 2, 3))
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples)
    i = int(np.argmin(np.abs(r.frequency_hz - 92.0)))
    x, w = r.coefficients[i].ravel(), float(r.omega[i])
    mono = floquet_exponents(system, x, w, method="monodromy", model=disk)
    print(f"16 blades {r.frequency_hz[i]:.2f} Hz: max |mu| - 1 = {abs(mono.multipliers[0]) - 1:.1e}, "
          f"periodicity error {mono.periodicity_error:.2e}")
    assert mono.stable and floquet_exponents(system, x, w).stable
    assert mono.multipliers.size == 2 * 160 + 2 * 160 and mono.periodicity_error < 5e-3
    i = int(np.argmin(np.abs(r.frequency_hz - 95.3)))
    with pytest.warns(AccuracyWarning, match="phi_y"):
        _, error = monodromy_multipliers(disk, r.coefficients[i], r.basis, float(r.omega[i]))
    print(f"16 blades {r.frequency_hz[i]:.2f} Hz: periodicity error {error:.2f}")
    assert error > 0.1


def test_with_stability_takes_method_monodromy_on_a_disk(reference4):
    """The stability API on a disk FRF: ``with_stability(disk, response, method="monodromy")``
    (a short stretch of the 4-blade reference FRF at the peak): every point stable, as by the
    determinant sign, and ``stability_method`` says which method decided."""
    from bladedamp.hbm.stability import with_stability

    disk, r = reference4
    short = quiet_frf(disk, 95.28, 95.34, harmonics=(0, 1, 2, 3))
    assert 3 <= len(short.omega) <= 60
    mono = with_stability(disk, short, method="monodromy")
    det = with_stability(disk, short)
    assert mono.stability_method == "monodromy" and det.stability_method == "determinant sign"
    assert mono.stable.all() and det.stable.all()
    assert mono.floquet_exponents.shape[0] == len(short.omega)


def test_with_stability_raises_the_monodromy_warning_once_per_call(reference4):
    """At the 4-blade disk's 102.3 Hz resonance the cylinder keeps rolling (the peak check's
    "drifting", test_disk.py): the monodromy of each HBM state warns that it is not a periodic
    orbit. ``with_stability`` over three such points raises that AccuracyWarning once, at the
    caller's line, saying at how many points; each point alone warns (the count can fail)."""
    from bladedamp.hbm.accuracy import AccuracyWarning
    from bladedamp.hbm.stability import with_stability

    disk, _ = reference4
    r = quiet_frf(disk, 102.2, 102.4, harmonics=(0, 1, 2, 3))
    i = int(np.argmin(np.abs(r.frequency_hz - 102.3)))
    three = dataclasses.replace(r, omega=r.omega[i - 1:i + 2], coefficients=r.coefficients[i - 1:i + 2])
    with warnings.catch_warnings(record=True) as raised:
        warnings.simplefilter("always")
        with_stability(disk, three, method="monodromy")
    assert [w.category for w in raised] == [AccuracyWarning], [str(w.message) for w in raised]
    assert raised[0].filename == __file__
    assert "phi_y" in str(raised[0].message) and "(the same at 2 more of the branch's 3 points)" in str(raised[0].message)
