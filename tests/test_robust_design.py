"""Designs robust to mistuning (issue 36 item 3): the first-order perturbation estimate of the
mistuned statistics against Monte Carlo, and the robust objective's gradient and optimum."""
import numpy as np
import pytest

import bladedamp as bd
from bladedamp.mistuned import MistunedDisk
from bladedamp.studies.gradient import optimal_design
from bladedamp.studies.mistuning import mistuned_response, monte_carlo
from bladedamp.studies.robust import (disk_settings, kappa_keys, mistuning_gradient, perturbation_estimate,
                                      robust_design, robust_objective, statistic_weights)


@pytest.fixture(scope="module")
def disk():
    return bd.reference_disk("cylinder", 1e-3)


def test_every_blade_gradient_is_blade_0s_shifted(disk):
    """Rotating the tuned disk by j sectors maps blade 0 onto blade j and only shifts the
    travelling-wave excitation's phase, so blade j's peak derivatives in the factors are blade 0's
    rolled by j (the perturbation estimate uses only blade 0's). Both from one branch: equal to
    the rounding of the peak solves (1e-6 of the largest entry; measured 1e-9)."""
    n = disk.n_blades
    response = mistuned_response(disk, np.ones(n), None, assembly=MistunedDisk.from_tuned(disk), **disk_settings())
    keys = kappa_keys(n)
    g0 = response.peak_sensitivities(keys, blade=0).d_peak_amplitude
    for j in (1, 5):
        gj = response.peak_sensitivities(keys, blade=j)
        assert gj.blade == j
        np.testing.assert_allclose(gj.d_peak_amplitude, np.roll(g0, j), rtol=0, atol=1e-6 * np.abs(g0).max())
    # and blade 0's is what mistuning_gradient reports: the first-order expansion's gradient
    np.testing.assert_allclose(mistuning_gradient(disk).gradient, g0, rtol=0, atol=1e-6 * np.abs(g0).max())


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")   # the paper's one harmonic, on purpose
def test_uniform_mistuning_is_the_cyclic_models_frequency_scaling(disk):
    """All factors changed together is the tuned disk with every blade frequency scaled: the sum
    of blade 0's 16 derivatives (full assembly) equals sum_j f_j dA/df_j of the one-sector cyclic
    model's peak (another model and residual), to the peak solves' rounding (1e-6 of the largest
    derivative; measured 1e-10-5e-10 over four ranges of the cyclic model). A coarse branch whose
    peak solve lands on a lower kink of the sampled friction (1.4e-4 below, seen with a wider
    range) gives another derivative (9 % of the sum): this is the range the Monte Carlo uses."""
    gradient = mistuning_gradient(disk)
    keys = [f"blade.natural_frequencies_hz[{j}]" for j in range(len(disk.blade.natural_frequencies_hz))]
    cyclic = bd.peak_sensitivities(disk, (90.0, 100.0), keys, harmonics=(1,))
    uniform = sum(disk.parameter_value(k) * cyclic[k].peak_amplitude for k in keys)
    assert abs(gradient.gradient.sum() - uniform) <= 1e-6 * np.abs(gradient.gradient).max()
    assert gradient.tuned_peak_amplitude == pytest.approx(cyclic.peak_amplitude, rel=1e-6)


def test_without_mistuning_the_estimate_is_the_tuned_peak(disk):
    """The limit std = 0: every blade's peak is A0, the check disks are the tuned disk itself, so
    the remainder and the stated error vanish."""
    estimate = perturbation_estimate(disk, 0.0, n_check=2, n_samples=100)
    a0 = estimate.tuned_peak_amplitude
    np.testing.assert_allclose([estimate.mean, estimate.quantile_value], a0, rtol=1e-13)   # a sum's rounding
    np.testing.assert_allclose(estimate.check_peaks, a0, rtol=1e-12)
    assert estimate.error <= 1e-12 * a0


@pytest.mark.parametrize("q", [0.05, 0.5, 0.95, 0.999])
def test_quantile_weights_are_numpys_quantile(q):
    values = np.random.default_rng(3).standard_normal(37)
    rounding = 1e-14 * np.abs(values).max()                      # a sum's rounding
    np.testing.assert_allclose(statistic_weights(values, q) @ values, np.quantile(values, q), rtol=0, atol=rounding)
    np.testing.assert_allclose(statistic_weights(values, "mean") @ values, values.mean(), rtol=0, atol=rounding)
    for bad in (1.5, "median", None):
        with pytest.raises(ValueError, match="statistic"):
            statistic_weights(values, bad)


def test_robust_objective_gradient_is_the_difference_of_its_copies(disk):
    """The mean of the largest blade peak of two mistuned copies (std 2 %, common random numbers)
    and its analytic gradient in the damper mass against central differences of the objective
    (step 1e-4 g). Sampled friction puts kinks into each copy's peak, so the differences agree to
    the kinks' scatter only: 1e-2 relative (measured 2.5e-3 per copy, 7e-4 for the mean of four)."""
    keys = ["damper.mass_g"]
    objective = robust_objective(disk, keys, 0.02, 2, seed=0)
    h = 1e-4
    plus, minus = (robust_objective(disk.with_parameters({"damper.mass_g": 1.0 + s * h}), keys, 0.02, 2, seed=0)
                   for s in (1, -1))
    np.testing.assert_array_equal(plus.kappa, objective.kappa)                      # the same copies
    np.testing.assert_allclose(objective.disk_gradients[:, 0], (plus.disk_peaks - minus.disk_peaks) / (2 * h), rtol=1e-2)
    np.testing.assert_allclose(objective.gradient[0], (plus.value - minus.value) / (2 * h), rtol=1e-2)
    assert objective.value == pytest.approx(objective.disk_peaks.mean(), rel=1e-14)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")   # the paper's one harmonic, on purpose
def test_perturbation_estimate_within_its_error_of_a_1000_disk_monte_carlo(disk):
    """At a small mistuning (std 0.01 %) the first-order estimate of the mean largest blade peak
    (the expansion sampled 2e5 times, its error stated from 16 check disks) lies within its stated
    error of the mean of 1000 Monte Carlo disks (on Dask), widened by the Monte Carlo's own
    standard error (twice) and the peaks' resolution between the two peak solvers (2e-4 of A0:
    the sampled friction's kinks; the cyclic and the full-assembly tuned peaks differ by 1.4e-4).
    And the estimate says something: its rise over A0 is more than five times its error."""
    std = 1e-4
    estimate = perturbation_estimate(disk, std)
    a0 = estimate.tuned_peak_amplitude
    mc = monte_carlo(disk, 1000, std=std, seed=1, n_workers=2, tol=1e-8, tuned_peak_amplitude=a0)
    assert mc.valid.all(), mc.errors
    peaks = mc.peak_amplitude.max(axis=1)
    standard_error = peaks.std(ddof=1) / np.sqrt(len(peaks))
    bound = estimate.error + 2 * standard_error + 2e-4 * a0
    print(estimate.table())
    print(f"Monte Carlo 1000 disks: mean {1e3 * peaks.mean():.5f} mm +- {1e3 * standard_error:.3g}; "
          f"difference {1e3 * (peaks.mean() - estimate.mean):.3g} mm against the bound {1e3 * bound:.3g} mm")
    assert abs(peaks.mean() - estimate.mean) <= bound
    assert estimate.mean - a0 > 5 * estimate.error


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")   # the paper's one harmonic, on purpose
def test_robust_mass_optimum_is_lighter_than_the_tuned_optimum(disk):
    """The damper mass minimising the mean largest blade peak of 12 mistuned disks (std 2 %, the
    paper's) against the mass minimising the tuned peak. Physics: mistuning spreads the blades'
    resonances, and the neighbours' different motion raises the slip across a light damper, so
    mistuning lowers the peak of a slipping (light) damper, while a stuck (heavy) damper gains
    nothing and the disk's localisation raises it (the paper: at its tuned optimum, 1 g, the
    mistuned peak is close to the tuned one, at 5 g above it). The amplification mistuned / tuned
    so grows with the mass, and the robust optimum is lighter: at the tuned optimum the robust
    objective still falls towards lighter dampers (positive derivative), and it ends lower there.
    Measured with 20 disks in [0.2, 3] g: the robust optimum 0.556 g against the tuned 0.997 g, the
    mean largest blade peak 0.393 mm there against 0.464 mm at the tuned optimum, whose derivative
    is +0.21 mm/g (12 disks: half the CPU time for the same question)."""
    bounds = [[0.3, 2.0]]
    tuned = optimal_design(disk, ["damper.mass_g"], bounds, (88.0, 106.0), harmonics=(1,))
    robust = robust_design(disk, ["damper.mass_g"], bounds, std=0.02, n_disks=12, seed=0, n_workers=2,
                           scheduler=None)
    at_tuned = robust_objective(disk.with_parameters({"damper.mass_g": tuned["damper.mass_g"]}), ["damper.mass_g"],
                                0.02, 12, seed=0, n_workers=2, scheduler=None)
    print(tuned.table())
    print(robust.table())
    print(f"robust objective at the tuned optimum: {1e3 * at_tuned.value:.4f} mm, d/dm {1e3 * at_tuned.gradient[0]:.4f} mm/g")
    assert robust.success and tuned.success
    assert at_tuned.gradient[0] > 0
    assert robust["damper.mass_g"] < tuned["damper.mass_g"]
    assert robust.peak_amplitude < at_tuned.value


@pytest.mark.slow
def test_a_copy_the_coarse_branch_misleads_is_solved_on_the_fine_branch():
    """A random 8-blade wedge at EO 3, std 2 %, copy 0: on the coarse branch (0.4 Hz) the peak solve
    starts at a blade's local maximum near 100.86 Hz and cannot be differentiated; the copy is then
    solved on the fine branch (FINE_SETTINGS), whose peak is the largest blade's (blade 6 at 100.98
    Hz): the same answer as asking the fine branch directly, bit for bit."""
    import dataclasses

    from bladedamp.studies.mistuning import random_kappa
    from bladedamp.studies.robust import FINE_SETTINGS, mistuned_peak

    disk = dataclasses.replace(bd.reference_disk("wedge", 2e-3), engine_order=3, n_blades=8)
    assembly = MistunedDisk.from_tuned(disk)
    kappa = random_kappa(8, 0.02, seed=[0, 0])
    keys = ["damper.friction_coefficient"]
    coarse = disk_settings()
    with pytest.raises(ValueError, match="no peak derivatives"):
        mistuned_response(disk, kappa, None, assembly=assembly, **coarse).peak_sensitivities(keys)
    result, reason = mistuned_peak(disk, assembly, kappa, keys, None, coarse)
    assert reason == ""
    direct = mistuned_response(disk, kappa, None, assembly=assembly,
                               **dict(coarse, **FINE_SETTINGS)).peak_sensitivities(keys)
    assert result.blade == direct.blade == 6
    assert result.peak_amplitude == direct.peak_amplitude
    np.testing.assert_array_equal(result.d_peak_amplitude, direct.d_peak_amplitude)


@pytest.mark.parametrize("key, needle", [("damper.colour", "unknown"), ("mistuning.kappa[0]", "random"),
                                         ("blade.natural_frequencies_hz[9]", "out of range")])
def test_a_bad_key_is_refused_before_any_copy_is_solved(disk, key, needle):
    with pytest.raises(ValueError, match=needle) as error:
        robust_objective(disk, [key], 0.02, 200, seed=0)       # 200 copies would take minutes
    assert key in str(error.value)
