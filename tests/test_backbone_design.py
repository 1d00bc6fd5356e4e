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
    that mass: the same EPMC root, to the root search's 1e-7 in log a; over a grid step of the
    design (0.25 decades of mass) as over a refinement step."""
    from bladedamp.hbm.nonlinear_modes import nonlinear_mode, peak_function, tracked_forced_peaks
    from bladedamp.studies.mass import with_mass

    disk = bd.reference_disk("cylinder", 1e-3)
    scales = np.array([0.05, 0.1, 0.2]) / disk.excitation[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        near, target, far = (nonlinear_mode(with_mass(disk, m), n_points=30, tol=1e-9, resolve_peaks=scales)
                             for m in (1e-3, 1.2e-3, 10 ** -2.75))
    for start, mode, m in ((near, target, 1.2e-3), (near, far, 10 ** -2.75)):
        tracked = tracked_forced_peaks(with_mass(disk, m), start, scales, tol=1e-9)
        assert len(tracked) == len(scales)
        for s, peak in zip(scales, tracked):
            full = mode.forced_peak(scale=s)
            assert peak["found"], peak["message"]
            assert peak["solves"] <= (8 if m == 1.2e-3 else 12)     # measured 6 / 6-10 (the secant's steps)
            np.testing.assert_allclose(peak["output_amplitude"], full["output_amplitude"], rtol=1e-7)
            np.testing.assert_allclose(peak["frequency_hz"], full["frequency_hz"], rtol=1e-9)
            r = peak["mode"]
            h = peak_function(r.modal_amplitude, r.omega, r.damping_ratio, r.shape(1), s * r.excitation)
            assert abs(h[0]) < 1e-6 * abs(r.shape(1)[0].conj() @ (s * r.excitation))
    # a tracked solution is itself a start (the next mass of a refinement)
    again = tracked_forced_peaks(with_mass(disk, m), [p["mode"] for p in tracked], scales, tol=1e-9)
    for p, q in zip(again, tracked):
        np.testing.assert_allclose(p["output_amplitude"], q["output_amplitude"], rtol=1e-7)


def test_tracked_peaks_keep_the_optimum_of_full_modes(design, full_design):
    """One full mode (the first grid mass) and every other peak tracked from its nearest mass,
    instead of a full mode per mass, give the same optima (to 1e-4: the peaks agree to ~1e-7, the
    Brent search's valley is 1e-5 deep over its tolerance)."""
    assert len(design.tracked_masses) == len(design.mass) - 1 and not design.fallback_masses, design.message
    assert "1 full nonlinear mode(s)" in design.message
    assert not full_design.tracked_masses
    assert len(design.mass) == len(full_design.mass)
    np.testing.assert_allclose(design.optimal_mass, full_design.optimal_mass, rtol=1e-4)
    np.testing.assert_allclose(design.optimal_peak_amplitude, full_design.optimal_peak_amplitude, rtol=1e-6)
    # the grid masses (evaluated by both, at every level): the same peaks
    tracked_grid = design.peak_amplitude[np.isin(design.mass, design.grid_mass)]
    full_grid = full_design.peak_amplitude[np.isin(full_design.mass, design.grid_mass)]
    assert tracked_grid.shape == (len(design.grid_mass), 2) and np.isfinite(tracked_grid).all()
    np.testing.assert_allclose(tracked_grid, full_grid, rtol=1e-7)


def test_failed_tracking_falls_back_to_the_full_mode(full_design, monkeypatch):
    """A tracking that does not converge (here: one secant step allowed) is reported not found,
    and the design computes that mass's full mode: the design of full modes exactly."""
    import bladedamp.hbm.nonlinear_modes as nm
    from bladedamp.studies.mass import with_mass

    disk = bd.reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = nm.nonlinear_mode(disk, n_points=30, tol=1e-9, resolve_peaks=[0.5])
    failed, = nm.tracked_forced_peaks(with_mass(disk, 1.2e-3), start, [0.5], tol=1e-9, maxiter=1)
    assert not failed["found"] and failed["mode"] is None and np.isnan(failed["output_amplitude"]).all()
    assert "no EPMC root of the synthesis condition" in failed["message"]

    monkeypatch.setattr(nm, "tracked_forced_peaks", functools.partial(nm.tracked_forced_peaks, maxiter=1))
    fallback = backbone_design()
    assert len(fallback.fallback_masses) == len(fallback.mass) - 1 and not fallback.tracked_masses, fallback.message
    assert "full mode(s) where the tracking failed" in fallback.message
    np.testing.assert_array_equal(fallback.mass, full_design.mass)
    np.testing.assert_array_equal(fallback.optimal_mass, full_design.optimal_mass)
    np.testing.assert_array_equal(fallback.peak_amplitude, full_design.peak_amplitude)


def test_tracked_forced_peaks_refuses_what_is_not_a_start():
    from bladedamp.hbm.nonlinear_modes import tracked_forced_peaks

    disk = bd.reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = bd.nonlinear_mode(disk, amplitudes=[1e-4, 1e-3])
    with pytest.raises(ValueError, match="one entry per scale"):
        tracked_forced_peaks(disk, [start], [0.5, 1.0])
    with pytest.raises(TypeError, match="NonlinearModeResponse"):
        tracked_forced_peaks(disk, [object()], [0.5])
    with pytest.raises(ValueError, match=r"scales must be in \(0, inf\)"):
        tracked_forced_peaks(disk, start, [0.0])
    with pytest.raises(ValueError, match="not a mode of a neighbouring design"):
        tracked_forced_peaks(bd.FrictionOscillator(), start, [1.0])
