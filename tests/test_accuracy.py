"""Harmonic accuracy control and the physical sanity checks of every response.

Independent references: the time integration of the same oscillator (no harmonic truncation at
all), the linear limit (one harmonic is exact), and a hand-made branch for each sanity check.
"""
import warnings

import numpy as np
import pytest

from bladedamp import FrictionOscillator
from bladedamp.hbm.accuracy import (AccuracyWarning, auto_sets, check_points, harmonic_error)
from bladedamp.hbm.fourier import enriched
from bladedamp.hbm.continuation import NewtonResult
from bladedamp.hbm.fourier import HarmonicBasis
from bladedamp.response import physical_checks

# the issue's inclined-contact oscillator: the normal load varies with the motion, and the paper's
# one-harmonic balance puts the peak at 65 rad/s with 9.1e-5 m where the time integration has 1.0e-5 m
INCLINED = dict(mass=12.98, stiffness=12660.0, damping=1.289, contact_stiffness=112900.0,
                friction_coefficient=0.764, normal_load=0.05, forcing=0.2903, contact_angle=0.68766)
RANGE = (28.8258, 121.761)    # rad/s
RANGE_HZ = tuple(w / (2 * np.pi) for w in RANGE)    # what frequency_response takes


def test_embed_keeps_the_signal_and_zero_pads_new_harmonics():
    a, b = HarmonicBasis((1, 3)), HarmonicBasis((0, 1, 2, 3, 4))
    X = np.random.default_rng(0).normal(size=(a.n_coeffs, 2))
    Y = a.embed(X, b)
    assert a.n_samples == b.n_samples
    assert np.allclose(b.to_time(Y), a.to_time(X))            # the same signal, sample by sample
    assert np.allclose(Y[b.cos_index(0)], 0) and np.allclose(Y[b.cos_index(2):b.cos_index(2) + 2], 0)
    assert np.allclose(b.embed(Y, a), X)          # and back: dropping the added harmonics


def test_enriched_set_adds_the_static_term_and_two_harmonics():
    assert enriched((1,)) == (0, 1, 2, 3)
    assert enriched((0, 1, 2, 3)) == (0, 1, 2, 3, 4, 5)
    assert auto_sets(3) == ((0, 1), (0, 1, 2, 3))
    with pytest.raises(ValueError, match="max_harmonic"):
        auto_sets(0)


def test_check_points_start_at_the_peak_and_avoid_folds():
    a = np.array([0, 1, 2, 3, 9, 3, 2, 1, 0, 0, 0.0])
    idx = check_points(a, turning_points=[8], n_points=4)
    assert idx[0] == 4 and not set(idx) & {6, 7, 8, 9, 10}


def test_linear_system_has_zero_harmonic_error():
    """Without contact force (mu = 0, flat contact) the system is linear: one harmonic is exact."""
    osc = FrictionOscillator(friction_coefficient=0.0, normal_load=0.0, damping=5.0)
    r = osc.frequency_response(70.0 / (2 * np.pi), 130.0 / (2 * np.pi), harmonics=(1,))
    assert r.success and r.harmonic_error < 1e-9 and r.harmonics_converged


@pytest.mark.slow   # 8-26 s: kept out of the default run (under 10 min); CI runs it
def test_one_harmonic_on_an_inclined_contact_is_flagged_and_auto_is_right():
    """The issue's case: the one-harmonic answer is 8.7x the time integration and nothing said so.
    Now its error estimate is far above the tolerance, and the default answer agrees with the time
    integration (the reference without any truncation) to the estimate it states."""
    osc = FrictionOscillator(**INCLINED)
    with pytest.warns(AccuracyWarning, match=r"one-harmonic curve: its peak may be off by up to \d+ %; run with "
                                             r"harmonics='auto' or \(0, 1, 2, 3\)"):
        paper = osc.frequency_response(*RANGE_HZ, harmonics=(1,))
    assert paper.harmonic_error > 0.1 and not paper.harmonics_converged
    assert "exceeds the tolerance" in paper.message
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)
        auto = osc.frequency_response(*RANGE_HZ)
    assert auto.success and 0 in auto.basis.harmonics and max(auto.basis.harmonics) >= 5
    f, a = auto.peak()                          # [Hz], [m]
    ref = osc.time_response([f]).amplitude[0]
    # the time integration lies within the stated estimate (and within 3 % in absolute terms)
    assert abs(a - ref) / ref < max(auto.harmonic_error, 0.0) + 0.01, (a, ref, auto.harmonic_error)
    assert abs(a - ref) / ref < 0.03
    # the paper's setting is wrong there by far more than its own estimate would allow to pass
    assert abs(paper.peak()[1] - ref) / ref > 0.5


def test_forcing_one_harmonic_in_the_estimate_would_be_caught():
    """harmonic_error against the set itself finds nothing: the estimate works only through
    enrichment (a test of the test)."""
    osc = FrictionOscillator(**INCLINED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(*RANGE_HZ, harmonics=(0, 1))
    same = harmonic_error(osc, r, harmonics=(0, 1))
    richer = harmonic_error(osc, r)
    assert same.error < 1e-6 < 0.01 < richer.error


def test_estimate_falls_back_on_the_damped_newton(monkeypatch):
    """Where the plain Newton in the enriched set does not converge from the lifted solution
    (the reference 1 g cylinder's (0..7) peak, 90-100 Hz: "not verified" before), the damped
    Newton of the robust start gives the estimate; without either it is NaN ("not verified").
    Here the plain Newton is made to fail on the inclined oscillator."""
    import bladedamp.hbm.accuracy as accuracy

    osc = FrictionOscillator(**INCLINED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(*RANGE_HZ, harmonics=(0, 1, 2, 3))
    plain = harmonic_error(osc, r)
    solve = accuracy.newton
    monkeypatch.setattr(accuracy, "newton", lambda fun, x0, *a, **k: solve(fun, x0, *a, **k)
                        if k.get("line_search") is not None else NewtonResult(x0, False, 20, 1.0))
    damped = harmonic_error(osc, r)
    assert np.isfinite(plain.error) and damped.error == pytest.approx(plain.error, rel=1e-6, abs=1e-9)
    monkeypatch.setattr(accuracy, "newton", lambda fun, x0, *a, **k: NewtonResult(x0, False, 20, 1.0))
    assert np.isnan(harmonic_error(osc, r).error)


def test_estimate_retries_a_failed_point_with_more_samples(monkeypatch):
    """Where neither Newton converges in the enriched set at its first sampling (random oscillator
    154's peak: the lift-off instant between AFT samples), the point is solved once more with
    ENRICHED_SAMPLES_GROWTH x the samples instead of leaving the estimate "not verified". Here both
    Newtons (plain and with line search) are made to fail at the first sampling on the inclined oscillator."""
    import bladedamp.hbm.accuracy as accuracy

    osc = FrictionOscillator(**INCLINED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(*RANGE_HZ, harmonics=(0, 1, 2, 3))
    first = max(HarmonicBasis(enriched(r.basis.harmonics)).n_samples, r.basis.n_samples)
    plain = harmonic_error(osc, r)

    def failing_at_first(solver, failed):
        def solve(fun, x0, *args, **kwargs):            # the system is the one of its factorize
            if kwargs["factorize"].__self__.basis.n_samples == first:
                return failed(x0)
            return solver(fun, x0, *args, **kwargs)
        return solve

    monkeypatch.setattr(accuracy, "newton", failing_at_first(accuracy.newton,
                                                             lambda x0: NewtonResult(x0, False, 20, 1.0)))
    finer = harmonic_error(osc, r)
    assert np.all(np.isfinite(finer.errors)), finer.errors
    # the same estimate to within the sampling error of 4 x the samples
    assert finer.error == pytest.approx(plain.error, rel=0.1, abs=1e-3)


def test_physical_checks_flag_range_dissipation_and_step():
    w = 2 * np.pi * np.linspace(90.0, 100.0, 11)
    work = np.ones(11)
    ok = physical_checks(w, (w[0], w[-1]), np.full((11, 2), 0.1), work, max_step=0.2)
    assert ok == {}
    bad_w = w.copy()
    bad_w[3] = -1.0
    assert "range" in physical_checks(bad_w, (w[0], w[-1]), np.full((11, 2), 0.1), work)
    diss = np.full((11, 2), 0.1)
    diss[5, 1] = -0.03 * work[5]     # -3 %: far below the AFT sampling floor (2 pi / 64)^2 ~ 1 %
    assert "dissipation" in physical_checks(w, (w[0], w[-1]), diss, work)
    assert "step" in physical_checks(w[::5], (w[0], w[-1]), np.full((3, 2), 0.1), work[:3], max_step=0.1)


def test_negative_dissipation_is_re_evaluated_with_a_finer_aft():
    """A point below rounding is re-evaluated (``refine``, only those points); it fails only if
    still below SAMPLING_FLOOR there, and the message says the finer sampling confirmed it."""
    from bladedamp.response import REFINE_SAMPLES_FACTOR, SAMPLING_FLOOR

    w = 2 * np.pi * np.linspace(90.0, 100.0, 11)
    work = np.ones(11)
    diss = np.full((11, 3), 0.1)
    diss[4, 2] = -4e-8                      # a sampling error: gone at the finer sampling
    diss[7, 0] = -2e-4                      # one that stays
    asked = []

    def refine(indices, stays=True):
        asked.append(list(indices))
        fine = diss[indices].copy()
        fine[fine < 0] = -10 * SAMPLING_FLOOR if stays else 1e-18
        return fine

    failed = physical_checks(w, (w[0], w[-1]), diss, work, n_samples=64, refine=refine)
    assert asked == [[4, 7]]                # only the suspect points
    assert "dissipation" in failed and f"{REFINE_SAMPLES_FACTOR * 64} AFT samples" in failed["dissipation"]
    assert physical_checks(w, (w[0], w[-1]), diss, work, refine=lambda i: refine(i, stays=False)) == {}
    asked.clear()
    assert physical_checks(w, (w[0], w[-1]), np.full((11, 3), 0.1), work, refine=refine) == {} and not asked


def test_work_bound_is_the_largest_work_of_the_harmonic_amplitudes():
    """pi sum_h h |F_h||W_h|: the work of a force 90 deg ahead of the motion in every harmonic
    (the most dissipative phase), whatever the phases; the static term does none."""
    from bladedamp.hbm.fourier import HarmonicBasis

    basis = HarmonicBasis((0, 1, 3))
    rng = np.random.default_rng(3)
    W = rng.normal(size=basis.n_coeffs)
    amp_f = {1: 2.0, 3: 0.5}
    F = np.zeros(basis.n_coeffs)
    F[basis.cos_index(0)] = 7.0
    for h, a in amp_f.items():            # F_h = a e^{i pi/2} W_h / |W_h|: in phase with the velocity
        j = basis.cos_index(h)
        wc, ws = W[j], W[j + 1]
        F[j], F[j + 1] = a * ws / np.hypot(wc, ws), -a * wc / np.hypot(wc, ws)
    bound = basis.work_bound(F, W)
    expected = sum(np.pi * h * a * np.hypot(W[basis.cos_index(h)], W[basis.cos_index(h) + 1]) for h, a in amp_f.items())
    assert bound == pytest.approx(expected, rel=1e-12)
    assert abs(basis.work_per_cycle(F, W)) == pytest.approx(expected, rel=1e-12)   # attained
    G = F.copy()
    G[1:] = np.roll(G[1:], 1)                # any other phases: |work| <= bound
    assert abs(basis.work_per_cycle(G, W)) <= basis.work_bound(G, W) * (1 + 1e-12)


def test_dissipation_is_judged_against_the_contacts_own_energy_scale():
    """Off resonance the excitation work nearly vanishes while a stuck contact still stores
    energy: a negative dissipation of 1e-7 of the contact's work bound (a force-harmonic error
    of that order) passes with the bound and fails against the excitation work alone; one of
    1e-4 of the bound fails either way."""
    w = 2 * np.pi * np.linspace(90.0, 100.0, 11)
    work = np.full(11, 1e-3)
    bound = np.full((11, 2), 1.0)
    diss = np.full((11, 2), 0.1)
    diss[3, 0] = -1e-7
    refine = lambda i: diss[i]                  # the finer AFT confirms it
    assert "dissipation" in physical_checks(w, (w[0], w[-1]), diss, work, refine=refine)
    assert physical_checks(w, (w[0], w[-1]), diss, work, refine=refine, work_bound=bound) == {}
    diss[3, 0] = -1e-4
    failed = physical_checks(w, (w[0], w[-1]), diss, work, refine=refine, work_bound=bound)
    assert "energy scale" in failed["dissipation"] and "-0.01 %" in failed["dissipation"]


def test_negative_dissipation_is_aft_sampling_error():
    """A Jenkins contact driven by any periodic motion absorbs oint T du >= 0, and for a
    harmonic-balance motion that is the work of the retained harmonics (Parseval): a negative
    value is the AFT's time sampling, never the harmonic truncation, so it must vanish as the
    samples grow, for the same coefficients. Random oscillator 12 (inclined contact lifting off,
    (0, 1, 2, 3), 256 samples), its most negative point: measured -1.1e-3 / -1.4e-5 / -7.3e-7 /
    -6.7e-8 / -1.1e-8 of the excitation work at 256 / 1024 / 4096 / 16384 / 65536 samples."""
    import sys
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_random_designs import oscillator_design
    from bladedamp import FrictionOscillator

    d = oscillator_design(12)
    osc = FrictionOscillator(**d["params"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(d["omega_start"] / (2 * np.pi), d["omega_end"] / (2 * np.pi),
                                   harmonics=d["harmonics"], n_samples=256, max_step=0.05)
    e = osc.energy_balance(r)
    k = int(np.argmin(e[:, 2] / np.abs(e[:, 0])))
    rel = [osc.hbm_system(r.basis.harmonics, T).element_dissipation(r.coefficients[k].ravel(), r.omega[k])[0]
           / abs(e[k, 0]) for T in (256, 4096, 65536)]
    assert rel[0] < -1e-4                                  # the solve's sampling gives energy back ...
    assert abs(rel[1]) < abs(rel[0]) / 100 and abs(rel[2]) < abs(rel[1]) / 10     # ... and it converges to 0


def test_a_force_harmonic_sized_energy_error_off_resonance_is_cured_and_the_branch_is_accurate():
    """Random oscillator 12 (inclined contact lifting off, (0, 1, 2, 3)) with 256 AFT samples, the
    automatic first choice for an inclined contact: near 1.46 rad/s its contact gives energy back,
    -1e-3 of the (small) excitation work, but only about -1e-7 of its own work bound once
    re-evaluated with 16 x the samples: a force-harmonic error of that order (judged against the
    excitation work alone the refined check fails too). The result itself reports the 256-sample
    dissipation, so the oscillator holds it at its own samples (``judge_solution_samples``): the
    256-sample branch fails the dissipation check, naming the AFT's energy error, and the default
    grows the samples until no point gives energy back beyond its stated AFT error. Its curve was
    right all along: within 1e-3 of the 4096-sample one at the peak."""
    import sys
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_random_designs import oscillator_design

    d = oscillator_design(12)
    osc = FrictionOscillator(**d["params"])
    f0, f1 = d["omega_start"] / (2 * np.pi), d["omega_end"] / (2 * np.pi)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        coarse = osc.frequency_response(f0, f1, harmonics=(0, 1, 2, 3), n_samples=256, max_step=0.05)
        fine = osc.frequency_response(f0, f1, harmonics=(0, 1, 2, 3), n_samples=4096, max_step=0.05)
        auto = osc.frequency_response(f0, f1, harmonics=(0, 1, 2, 3), max_step=0.05)
    assert not coarse.success and "the AFT's energy error" in coarse.failed_checks["dissipation"], coarse.message
    assert fine.success and auto.success and auto.basis.n_samples > 256, auto.message
    e = osc.energy_balance(coarse)
    system = osc.hbm_system(coarse.basis.harmonics, 4096)
    k = int(np.argmin(e[:, 2] / np.abs(e[:, 0])))
    x, w = coarse.coefficients[k].ravel(), coarse.omega[k]
    assert e[k, 2] / abs(e[k, 0]) < -1e-4                                      # against the work: fails
    bound = system.element_work_bound(x, w)[0]
    assert bound > 10 * abs(e[k, 0])                                           # a contact storing energy
    assert abs(system.element_dissipation(x, w)[0]) / bound < 1e-6              # a force-harmonic error
    assert physical_checks(coarse.omega, (coarse.omega[0], coarse.omega[-1]), e[:, 2:], e[:, 0],
                           refine=lambda i: [system.element_dissipation(coarse.coefficients[j].ravel(),
                                                                        coarse.omega[j]) for j in i]) != {}
    a = [np.hypot(r.coefficients[:, r.basis.cos_index(1), 0], r.coefficients[:, r.basis.cos_index(1) + 1, 0])
         for r in (coarse, fine)]
    assert a[0].max() == pytest.approx(a[1].max(), rel=1e-3)


def test_automatic_sampling_grows_further_only_for_a_branch_that_failed_the_dissipation_check():
    """sampled_response: a branch that reached the end and failed only the dissipation check (the
    AFT's sampling error) may grow to ``most_for_dissipation``; a branch that stalled stops at
    ``most``; a success stops at once. A fake solve records the samples it is asked for."""
    from bladedamp.hbm.fourier import HarmonicBasis
    from bladedamp.response import FrequencyResponse, sampled_response, with_checks

    def fake(passes_at, failure):
        asked = []

        def solve(n):     # a continuation that reached the end (or stalled), then the checks
            asked.append(n)
            ok = n >= passes_at
            reached = ok or failure == "dissipation"
            message = "reached the end" if reached else "continuation did not converge after omega = 1 rad/s"
            # a stalled branch may fail the dissipation check too: only reached_end tells them apart
            checks = {} if ok else {"dissipation": "negative"}
            branch = FrequencyResponse(np.ones(3), np.zeros((3, 3, 1)), HarmonicBasis((1,), n), ("x",), reached, message)
            return with_checks(branch, checks)
        return solve, asked

    solve, asked = fake(1024, "dissipation")
    r = sampled_response(solve, None, 64, 256, 1024)
    assert asked == [64, 256, 1024] and r.success and "raised to 1024 (the branch failed with 64, 256)" in r.message
    solve, asked = fake(1024, "dissipation")
    assert not sampled_response(solve, None, 64, 256).success and asked == [64, 256]      # without the option
    solve, asked = fake(1024, "stall")
    r = sampled_response(solve, None, 64, 256, 1024)
    assert asked == [64, 256] and not r.success                 # a stalled branch does not get a third try
    solve, asked = fake(64, "dissipation")
    assert sampled_response(solve, None, 64, 256, 1024).success and asked == [64]
    solve, asked = fake(1024, "dissipation")
    assert not sampled_response(solve, 128, 64, 256, 1024).success and asked == [128]   # given: used once


def issue_disk_with_negative_dissipation():
    """The issue's disk (EO 8, 74.86 deg platforms, a 0.058 g cylinder separated about half the cycle)."""
    from bladedamp import ContactProperties, CylinderDamper, TunedDisk, reference_blade

    return TunedDisk(reference_blade(), CylinderDamper(5.815e-05, 0.002, 0.02,
                                                       ContactProperties(0.63, 1.7e7, 1.25, 1.0, 10.0, 4, 5)),
                     16, 8, np.radians(74.86), np.radians(74.86), 0.0261,
                     2.38 * np.array([0.1, -0.1, 0, 0, 0, 0.001]))


def test_negative_dissipation_of_a_disk_is_not_success():
    """The issue's disk with one harmonic and 64 AFT samples: its contacts give energy back (down
    to -0.43 % of the excitation work, -4.3e-4 of the contact point's work bound; -2.4e-6 of that
    once re-evaluated with 1024 samples, at 6 points) while the energy balance holds to rounding.
    That is the AFT's sampling of the lift-off, too coarse for this design: not success. (With
    256 samples: -4.4e-5 of the bound, and below the 1e-6 floor once re-evaluated: it passes.)"""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = issue_disk_with_negative_dissipation().frequency_response(85.0, 123.2, harmonics=(1,), max_step=0.05,
                                                                      n_samples=64)
    assert np.max(r.energy_balance_error()) < 1e-8         # the energy balance cannot see it
    assert "dissipation" in r.failed_checks and not r.success, r.message


@pytest.mark.slow
def test_automatic_sampling_cures_the_negative_dissipation_of_a_disk():
    """The same disk with the default (automatic) sampling: 64 samples fail the dissipation check,
    so it is solved once more with 256, where every check passes. The peak is within 1.2e-4
    relative of the 1024-sample branch's (3.9569 / 3.9565 mm): far below the 1 % target."""
    disk = issue_disk_with_negative_dissipation()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(85.0, 123.2, harmonics=(1,), max_step=0.05)
        fine = disk.frequency_response(85.0, 123.2, harmonics=(1,), max_step=0.05, n_samples=1024)
    assert r.success and not r.failed_checks and r.basis.n_samples == 256, r.message
    assert "raised to 256 (the branch failed with 64)" in r.message
    assert abs(r.peak_amplitude / fine.peak_amplitude - 1) < 1e-3


@pytest.mark.slow
@pytest.mark.parametrize("kind, mass, expected", [("cylinder", 1e-3, (0, 1, 2, 3, 4, 5)),
                                                   ("wedge", 0.3e-3, (0, 1, 2, 3, 4, 5, 6, 7))])
def test_default_disk_frf_meets_the_tolerance(kind, mass, expected):
    """Issue 12 item 1 on the reference dampers: the default answer is converged to 1 %.
    Measured 2026-12-01: cylinder (0..5) 0.53 %, wedge (0..7) 0.99 % (both 2-5 % with (0..3))."""
    import bladedamp as bd

    with warnings.catch_warnings():
        warnings.simplefilter("error", AccuracyWarning)       # a default above the tolerance fails here
        r = bd.reference_disk(kind, mass).frequency_response(90.0, 105.0)
    assert r.success and r.harmonics_converged
    assert not r.stopped_by                                     # the default budget is not met
    assert r.harmonic_error <= r.harmonic_tolerance == 0.01
    assert max(r.basis.harmonics) > 3 and max(r.basis.harmonics) <= max(expected)   # (0..3) is 2-5 % off


def test_a_budget_that_runs_out_on_a_richer_set_keeps_the_complete_branch_of_the_poorer_one():
    """The automatic choice never replaces a branch that reached the end of its range by a
    partial one: where the budget runs out on the branch of a richer harmonic set, the answer is
    the poorer set's complete branch with its own error estimate, OUT_OF_BUDGET (the search
    stopped), the message naming the set that did not finish. The reference 1 g cylinder's (0, 1)
    branch is above the 1 % tolerance (the automatic choice goes on: its prediction skips
    (0, 1, 2, 3), whose points change by more than 1 % in (0, ..., 5)); a point budget 10 points
    longer than that branch runs out on the (0, ..., 5) branch."""
    import bladedamp as bd
    from bladedamp.response import Status

    disk = bd.reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        poorer = disk.frequency_response(90.0, 105.0, harmonics=(0, 1))
        assert poorer.success and poorer.harmonic_error > poorer.harmonic_tolerance, poorer.message
        r = disk.frequency_response(90.0, 105.0, point_budget=len(poorer.omega) + 10)
    assert r.basis.harmonics == (0, 1) and r.status is Status.OUT_OF_BUDGET and not r.success
    np.testing.assert_array_equal(r.omega, poorer.omega)
    np.testing.assert_array_equal(r.coefficients, poorer.coefficients)
    assert r.harmonic_error == poorer.harmonic_error
    assert r.stopped_by.startswith("budget: ") and r.stopped_by in r.message
    assert "harmonics (0, 1, 2, 3, 4, 5) stopped before the end of the range" in r.message


def cut_at_half(r):
    """The branch of response ``r`` cut at half its points: a branch that failed short of the end."""
    from bladedamp.response import FrequencyResponse

    k = len(r.omega) // 2
    return FrequencyResponse(r.omega[:k], r.coefficients[:k], r.basis, r.dof_names, False,
                             f"continuation did not converge after omega = {r.omega[k - 1]:.6g} rad/s")


def test_a_richer_set_that_fails_short_of_the_end_ends_the_automatic_choice():
    """Where a richer harmonic set's branch does not reach the end of the range (every retry of
    it failed) after a poorer set's did, the automatic choice stops there: the sets richer still
    are not computed (on the random EO >= 6 wedges they failed the same way, for most of the
    analysis' CPU time: benchmarks/README.md), and the answer is the poorer set's complete branch,
    unchanged, with its own error estimate (the issue's inclined oscillator: (0, 1) is 2-3x off
    its enriched set), the message naming the set that did not converge and where it stopped.
    The failure of (0, 1, 2, 3) is made here by cutting its real branch at half its points."""
    from bladedamp.hbm.accuracy import converged_response
    from bladedamp.response import Status

    osc = FrictionOscillator(**INCLINED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = {H: osc.frequency_response(*RANGE_HZ, harmonics=H)
                for H in ((0, 1), (0, 1, 2, 3))}
    assert all(r.success for r in full.values())
    asked = []

    def solve(H):
        asked.append(H)
        return full[H] if H == (0, 1) else cut_at_half(full[H])

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = converged_response(osc, solve, max_harmonic=7)
        alone = converged_response(osc, lambda H: full[H], harmonics=(0, 1))
    poorer, cut = full[(0, 1)], full[(0, 1, 2, 3)]
    assert asked == [(0, 1), (0, 1, 2, 3)]                      # (0, ..., 5) and richer never computed
    assert r.basis.harmonics == (0, 1) and r.success and not r.stopped_by
    np.testing.assert_array_equal(r.omega, poorer.omega)
    np.testing.assert_array_equal(r.coefficients, poorer.coefficients)
    assert r.harmonic_error == alone.harmonic_error > r.harmonic_tolerance     # its own estimate, above 1 %
    assert r.status is Status.COMPLETE_ABOVE_TOLERANCE and r.harmonics_converged is False
    stop_hz = cut.omega[len(cut.omega) // 2 - 1] / (2 * np.pi)
    assert (f"harmonics (0, 1, 2, 3) did not converge to the end of the range (its branch got no further than "
            f"{stop_hz:.6g} Hz), so no richer set was tried") in r.message
    # a richer set that reaches the end replaces the poorer one as before
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        both = converged_response(osc, lambda H: full[H], max_harmonic=3)
    assert both.basis.harmonics == (0, 1, 2, 3) and "no richer set was tried" not in both.message


@pytest.mark.parametrize("guard_stalls", [True, False])
def test_the_richer_sets_branches_are_stall_guarded_for_the_disks_only(guard_stalls):
    """``converged_response(guard_stalls=True)`` (the tuned and mistuned disks) computes a richer
    set's branches, once a poorer set's reached the end, within the continuation's stall guard:
    the zigzag branch of test_continuation_contract, continued inside that richer set's solve,
    ends as stalled there, and runs to max_points without the option (the oscillator's) and in
    the first set's solve either way."""
    from test_continuation_contract import stalling_zigzag

    from bladedamp.hbm.accuracy import converged_response
    from bladedamp.hbm.continuation import continuation

    osc = FrictionOscillator(**INCLINED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = {H: osc.frequency_response(*RANGE_HZ, harmonics=H) for H in ((0, 1), (0, 1, 2, 3))}
    ends = {}

    def solve(H):
        fun, x0, w0 = stalling_zigzag()
        ends[H] = continuation(fun, x0, w0, 12.0, x_scale=1.0, residual_scale=1.0, max_step=0.05,
                               max_points=1000).message
        return full[H]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        converged_response(osc, solve, max_harmonic=3, guard_stalls=guard_stalls)
    assert "max_points" in ends[(0, 1)]
    assert ("stalled" in ends[(0, 1, 2, 3)]) == guard_stalls, ends


def test_the_prediction_skips_only_sets_above_the_tolerance_and_keeps_the_answer():
    """``converged_response(predict=True)`` (the tuned disk's automatic choice) computes fewer
    branches than the set-by-set search and returns the same answer here: the issue's inclined
    oscillator, whose (0, 1) branch is 2-3x off. Each set it skips, computed on its own, fails its
    own estimate (the independent check of the prediction: the set-by-set search's own verdict)."""
    from bladedamp.frf import branch_solver
    from bladedamp.hbm.accuracy import HARMONIC_TOLERANCE, converged_response

    osc = FrictionOscillator(**INCLINED)
    solve = branch_solver(osc, *RANGE_HZ)
    asked = {False: [], True: []}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = {p: converged_response(osc, lambda H, p=p: asked[p].append(H) or solve(H), max_harmonic=9, predict=p)
             for p in (False, True)}
        skipped = [H for H in asked[False] if H not in asked[True]]
        own = {H: harmonic_error(osc, solve(H)).error for H in skipped}
    assert set(asked[True]) < set(asked[False]) and skipped, asked      # the prediction saved a branch
    assert all(e > HARMONIC_TOLERANCE for e in own.values()), own
    assert r[True].basis.harmonics == r[False].basis.harmonics
    np.testing.assert_array_equal(r[True].coefficients, r[False].coefficients)
    assert r[True].harmonic_error == r[False].harmonic_error and r[True].message == r[False].message


def test_a_predicted_set_that_fails_falls_back_on_the_skipped_sets():
    """Where the set the prediction goes to does not reach the end of the range, the skipped sets
    are computed in turn: the answer is the set-by-set search's (here the issue's inclined
    oscillator, its branch of the predicted set cut at half its points as in
    test_a_richer_set_that_fails_short_of_the_end_ends_the_automatic_choice)."""
    from bladedamp.frf import branch_solver
    from bladedamp.hbm.accuracy import converged_response

    osc = FrictionOscillator(**INCLINED)
    solve = branch_solver(osc, *RANGE_HZ)
    asked = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        converged_response(osc, lambda H: asked.append(H) or solve(H), max_harmonic=9, predict=True)
    predicted = asked[1]                          # the set computed after (0, 1)
    assert predicted != (0, 1, 2, 3), asked       # the prediction skipped (0, 1, 2, 3)

    def cut(H):
        return cut_at_half(solve(H)) if H == predicted else solve(H)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = {p: converged_response(osc, cut, max_harmonic=9, predict=p) for p in (False, True)}
    assert r[True].basis.harmonics == r[False].basis.harmonics
    np.testing.assert_array_equal(r[True].coefficients, r[False].coefficients)
    assert r[True].message == r[False].message
