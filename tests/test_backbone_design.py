"""Damper design by nonlinear modes (bladedamp.studies.backbone) against the FRF optimum."""
import dataclasses
import functools
import warnings

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.studies.backbone import BackboneDesign, optimal_mass_by_backbone
from bladedamp.studies.mass import optimal_mass


DESIGN = dict(excitation_levels=[0.05, 0.1], bracket=(0.3e-3, 4e-3), grid_per_decade=3, xatol=0.01)


def backbone_design(**options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return optimal_mass_by_backbone("cylinder", **DESIGN, **options)


@pytest.fixture(scope="module")
def design():
    return backbone_design()


@pytest.fixture(scope="module")
def full_design():
    """Every mass by its full nonlinear mode (no peak tracked in mass)."""
    return backbone_design(track=False)


def test_backbone_optimum_is_the_calibrated_one_and_scales_with_the_force(design, tmp_path):
    assert not design.at_bound.any(), design.message
    assert design.peak_amplitude.shape == (len(design.mass), 2)
    assert abs(1e3 * design.optimal_mass[1] - 1.0) < 0.05            # ~1 g at 0.1 N (README: 1.001 g by FRFs)
    assert abs(design.optimal_reduction[1] - 0.711) < 0.015
    # linear contact laws: homogeneous in (force, mass)
    np.testing.assert_allclose(design.optimal_mass[0], design.optimal_mass[1] / 2, rtol=0.05)
    back = bd.load(design.save(tmp_path / "bb"))
    assert isinstance(back, BackboneDesign)
    np.testing.assert_array_equal(back.optimal_mass, design.optimal_mass)
    np.testing.assert_array_equal(back.peak_amplitude, design.peak_amplitude)
    design.plot()


@pytest.mark.slow
def test_backbone_optimum_within_2_percent_of_the_frf_optimum(design):
    disk = bd.reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # the FRF optimum to 0.5 % in mass (its default xatol, 2 %, is as wide as the tolerance)
        frf = optimal_mass(dataclasses.replace(disk, excitation=0.5 * disk.excitation), bounds=(0.1e-3, 2e-3),
                           xatol=5e-3)
    assert frf.success, frf.message
    assert abs(design.optimal_mass[0] / frf.mass - 1) < 0.02


def test_tracked_peak_is_the_full_modes_resolved_peak():
    """A peak tracked in mass (an EPMC Newton solve at the new mass from the neighbour's solution
    at its peak, then the secant on the synthesis condition) is the full mode's resolved peak at
    that mass: the same EPMC root, to the root search's 1e-7 in log a."""
    from bladedamp.hbm.nonlinear_modes import nonlinear_mode, peak_function, tracked_forced_peak
    from bladedamp.studies.mass import with_mass

    disk = bd.reference_disk("cylinder", 1e-3)
    scales = np.array([0.05, 0.1, 0.2]) / disk.excitation[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        near, target = (nonlinear_mode(with_mass(disk, m), n_points=30, tol=1e-9, resolve_peaks=scales)
                        for m in (1e-3, 1.2e-3))
    for s in scales:
        full = target.forced_peak(scale=s)
        tracked = tracked_forced_peak(with_mass(disk, 1.2e-3), near, s, tol=1e-9)
        assert tracked["found"], tracked["message"]
        assert tracked["solves"] <= 8
        np.testing.assert_allclose(tracked["output_amplitude"], full["output_amplitude"], rtol=1e-7)
        np.testing.assert_allclose(tracked["frequency_hz"], full["frequency_hz"], rtol=1e-9)
        r = tracked["mode"]
        h = peak_function(r.modal_amplitude, r.omega, r.damping_ratio, r.shape(1), s * r.excitation)
        assert abs(h[0]) < 1e-6 * abs(r.shape(1)[0].conj() @ (s * r.excitation))
        # the tracked solution is itself a start (the next mass of a refinement)
        again = tracked_forced_peak(with_mass(disk, 1.2e-3), r, s, tol=1e-9)
        np.testing.assert_allclose(again["output_amplitude"], tracked["output_amplitude"], rtol=1e-7)


def test_tracked_refinement_keeps_the_optimum_of_full_modes(design, full_design):
    """The refinement masses' peaks tracked from their neighbours, instead of a full mode each,
    give the same optima (to 1e-4: the peaks agree to ~1e-7, the Brent search's valley is 1e-5
    deep over its tolerance)."""
    assert design.tracked_masses and not design.fallback_masses, design.message
    assert not full_design.tracked_masses
    assert len(design.mass) == len(full_design.mass)
    np.testing.assert_allclose(design.optimal_mass, full_design.optimal_mass, rtol=1e-4)
    np.testing.assert_allclose(design.optimal_peak_amplitude, full_design.optimal_peak_amplitude, rtol=1e-6)


def test_failed_tracking_falls_back_to_the_full_mode(full_design, monkeypatch):
    """A tracking that does not converge (here: one secant step allowed) is reported not found,
    and the refinement computes that mass's full mode: the design of full modes exactly."""
    import bladedamp.hbm.nonlinear_modes as nm

    disk = bd.reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = nm.nonlinear_mode(disk, n_points=30, tol=1e-9, resolve_peaks=[0.5])
    from bladedamp.studies.mass import with_mass
    failed = nm.tracked_forced_peak(with_mass(disk, 1.2e-3), start, 0.5, tol=1e-9, maxiter=1)
    assert not failed["found"] and failed["mode"] is None and np.isnan(failed["output_amplitude"]).all()
    assert "no EPMC root of the synthesis condition" in failed["message"]

    monkeypatch.setattr(nm, "tracked_forced_peak", functools.partial(nm.tracked_forced_peak, maxiter=1))
    fallback = backbone_design()
    assert fallback.fallback_masses and not fallback.tracked_masses, fallback.message
    assert "by a full mode where that failed" in fallback.message
    np.testing.assert_array_equal(fallback.mass, full_design.mass)
    np.testing.assert_array_equal(fallback.optimal_mass, full_design.optimal_mass)
