"""Peaks solved on a response curve by the peak condition (bladedamp.hbm.peaks, TunedDisk.solve_peak,
the studies' peak searches), against references computed independently: the Hermite interpolant's
maximum of a cubic in closed form, the blade's closed-form modal FRF maximised by scipy, and
the largest point of a dense branch around a friction-damped peak."""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from bladedamp.hbm.peaks import hermite_maximum
from bladedamp.reference import reference_disk
from bladedamp.studies.mass import PEAK_SEARCH_MAX_STEP, peak_response


def test_hermite_maximum_of_a_cubic_is_exact():
    """The cubic Hermite interpolant of a cubic is the cubic itself: its maximum in [0, 1] is the
    root of the cubic's derivative (closed form)."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        t_max, h = rng.uniform(0.1, 0.9), rng.uniform(0.01, 10.0)
        c = rng.uniform(0.5, 2.0)
        # p(x) on [0, h], p'(x) = -c (x - h t_max)(x + h): positive below the maximum, negative above
        def p(x):
            return -c * (x ** 3 / 3 + (h - h * t_max) * x ** 2 / 2 - h * h * t_max * x)

        def dp(x):
            return -c * (x - h * t_max) * (x + h)
        t = hermite_maximum(p(0), dp(0), p(h), dp(h), h)
        assert abs(t - t_max) < 1e-12, (t, t_max)


def test_hermite_maximum_is_the_first_of_two_turns():
    """Slopes positive at both ends and a lower value at the right end (the bracket of a kink):
    the cubic p' = c (x - h t_max)(x - h t_min) turns down at t_max and up at t_min; the maximum
    is t_max, not the minimum."""
    rng = np.random.default_rng(4)
    checked = 0
    while checked < 20:
        t_max, t_min, h, c = rng.uniform(0.05, 0.4), rng.uniform(0.6, 0.95), rng.uniform(0.01, 10.0), rng.uniform(0.5, 2)

        def p(x):
            return c * (x ** 3 / 3 - h * (t_max + t_min) * x ** 2 / 2 + h * h * t_max * t_min * x)

        def dp(x):
            return c * (x - h * t_max) * (x - h * t_min)
        if not (dp(0) > 0 and dp(h) > 0 and p(h) < p(0)):
            continue
        checked += 1
        assert abs(hermite_maximum(p(0), dp(0), p(h), dp(h), h) - t_max) < 1e-12


def test_solved_peak_of_the_linear_disk_is_the_closed_form_maximum():
    """No damper: the tip FRF is the blade's closed-form modal receptance; its maximum, found by
    scipy's bounded minimiser on that formula, is what solve_peak gives from a coarse branch
    (max_step 0.2: 1F bracketed by points about 0.1 Hz apart)."""
    disk = dataclasses.replace(reference_disk("cylinder"), damper=None)
    blade = disk.blade
    modal_force = blade.shape("excitation").T @ disk.excitation

    def tip(f_hz):
        return abs(blade.shape("tip")[0] @ (modal_force / blade.dynamic_stiffness(f_hz)))
    exact = minimize_scalar(lambda f: -tip(f), bounds=(94.0, 96.5), method="bounded", options={"xatol": 1e-10})
    r = disk.frequency_response(90.0, 105.0, harmonics=(1,), max_step=0.2, estimate_harmonic_error=False)
    sample = r.tip_amplitude[:, 0].max()
    peak, f_peak = disk.solve_peak(r)
    print(f"closed form {1e3 * tip(exact.x):.9f} mm at {exact.x:.7f} Hz; solved {1e3 * peak:.9f} mm at "
          f"{f_peak:.7f} Hz; largest of {len(r.omega)} points {sample / tip(exact.x) - 1:+.1e}")
    assert sample < tip(exact.x) * (1 - 1e-5)       # the branch itself misses the peak
    assert abs(peak / tip(exact.x) - 1) < 1e-9
    assert abs(f_peak - exact.x) < 1e-6


@pytest.mark.parametrize("kind, mass", [("cylinder", 1.0e-3), ("wedge", 0.05e-3), ("wedge", 0.28e-3)])
def test_peak_search_matches_a_dense_branch(kind, mass):
    """The studies' peak search (a branch at PEAK_SEARCH_MAX_STEP and the peak solved on it)
    against the largest point of a branch at max_step 0.003 over +-0.15 Hz around the peak
    (about 1 mHz between points). The one-harmonic curve is jagged at the 1e-4 level there (a
    contact point entering slip puts a kink in it), so the dense branch is the reference, not
    a parabola. The 0.28 g wedge's largest point has a kink beside it (the slopes of both
    neighbours are positive, the right one lower): the solve must bracket it by the values.
    Measured: +4.7e-6 (1 g cylinder, 142 points), +1.6e-6 (0.05 g wedge, 135 points), +1.1e-6
    (0.28 g wedge, 96 points): the solved peak lies a little above the dense branch's largest
    point, which misses it by up to its own spacing."""
    disk = reference_disk(kind, mass)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        peak, f_peak, r = peak_response(disk, (90.0, 105.0))
        dense = disk.frequency_response(f_peak - 0.15, f_peak + 0.15, harmonics=(1,), max_step=0.003,
                                        estimate_harmonic_error=False)
    reference = dense.tip_amplitude[:, 0].max()
    print(f"{kind} {1e3 * mass:g} g: {len(r.omega)} points, peak {peak / reference - 1:+.1e} of the dense branch's")
    coarse = disk.frequency_response(90.0, 105.0, harmonics=(1,), max_step=PEAK_SEARCH_MAX_STEP,
                                     estimate_harmonic_error=False)
    assert disk.solve_peak(coarse) == (peak, f_peak)          # solved there, no fallback
    assert abs(peak / reference - 1) < 2e-5


def test_peak_search_falls_back_to_a_finer_branch_where_the_peak_is_not_solved(monkeypatch):
    """Where solve_peak gives None (a fold or a kink next to the largest point), peak_response
    recomputes the branch at PEAK_FALLBACK_MAX_STEP and refines its largest point by the parabola."""
    from bladedamp.disk import TunedDisk
    from bladedamp.response import refined_peak
    from bladedamp.studies import mass as mass_study

    monkeypatch.setattr(TunedDisk, "solve_peak", lambda self, *a, **k: None)
    disk = dataclasses.replace(reference_disk("cylinder"), damper=None)
    peak, f_peak, r = peak_response(disk, (90.0, 105.0), max_step=PEAK_SEARCH_MAX_STEP)
    fine = disk.frequency_response(90.0, 105.0, harmonics=(1,), max_step=mass_study.PEAK_FALLBACK_MAX_STEP,
                                   estimate_harmonic_error=False)
    assert len(r.omega) == len(fine.omega)
    assert (peak, f_peak) == refined_peak(fine.frequency_hz, fine.tip_amplitude[:, 0])


def test_peak_search_solves_on_the_system_with_the_users_elements():
    """A zero-gap spring k max(0, u) at the tip of the bare blade, one harmonic: its fundamental is
    k u / 2 exactly, so the tip FRF is the closed-form receptance of diag(omega_j^2) + (k/2) phi
    phi^T with the modal damping. The peak search (extra_couplings passed through) solves the peak
    on the system with the spring; on the bare blade's system the solve would not converge there."""
    from bladedamp.hbm import Coupling, GapSpring

    disk, k = dataclasses.replace(reference_disk("cylinder"), damper=None), 1e4
    tip_stop = lambda basis: [Coupling(GapSpring(stiffness=k), disk.point_map(basis, "tip", (0,)), "tip stop")]
    blade = disk.blade
    w0, phi = blade.natural_angular_frequencies, blade.shape("tip")[0]
    stiffness = np.diag(w0 ** 2) + 0.5 * k * np.outer(phi, phi)
    modal_force = blade.shape("excitation").T @ disk.excitation

    def tip(f_hz):
        w = 2 * np.pi * f_hz
        dynamic = stiffness - w ** 2 * np.eye(len(w0)) + 1j * w * np.diag(2 * blade.damping_ratios * w0)
        return abs(phi @ np.linalg.solve(dynamic, modal_force))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        peak, f_peak, _ = peak_response(disk, (95.0, 110.0), extra_couplings=tip_stop)
    exact = minimize_scalar(lambda f: -tip(f), bounds=(f_peak - 0.5, f_peak + 0.5), method="bounded",
                            options={"xatol": 1e-10})
    assert abs(peak / tip(exact.x) - 1) < 1e-8 and abs(f_peak - exact.x) < 1e-5


def test_newton_returns_the_factorisation_of_its_last_iterate():
    """newton's ``solve`` and ``dR_domega`` (what the peak solver's tangents now use instead of a
    new Jacobian): -solve(dR_domega) is the tangent dx/dOmega at the solution, equal to that of a
    fresh Jacobian there to 1e-8 (the last iterate met the tolerance), and to central differences."""
    from bladedamp.hbm.continuation import newton

    disk = reference_disk("cylinder", 1e-3)
    system = disk.hbm_system((1,))
    w = 2 * np.pi * 96.0                # slipping: 4 iterations from the stuck linear solution
    x0 = disk.initial_guess(system, w)
    scale = np.maximum(np.abs(x0), 1e-3 * np.abs(x0).max())
    residual_scale = np.linalg.norm(system.excitation(w)[0])
    r = newton(system.residual, x0, w, scale, residual_scale, tol=1e-10, factorize=system.factorize)
    assert r.converged and r.iterations > 2 and r.solve is not None
    tangent = -r.solve(r.dR_domega)
    _, J, Rw = system.residual(r.x, w)
    fresh = -system.factorize(J)(Rw)
    assert np.abs(tangent - fresh).max() <= 1e-8 * np.abs(fresh).max()
    h = 1e-6 * w
    plus, minus = (newton(system.residual, r.x, w + s, scale, residual_scale, tol=1e-12, max_iter=40,
                          factorize=system.factorize) for s in (h, -h))
    assert plus.converged and minus.converged
    difference = (plus.x - minus.x) / (2 * h)
    assert np.abs(tangent - difference).max() <= 1e-4 * np.abs(difference).max()
    failed = newton(system.residual, 3 * r.x, w, scale, residual_scale, tol=1e-10, max_iter=1,
                    factorize=system.factorize)
    assert not failed.converged and failed.solve is None
