"""Damper design by nonlinear modes (bladedamp.studies.backbone) against the FRF optimum."""
import dataclasses
import warnings

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.studies.backbone import BackboneDesign, optimal_mass_by_backbone
from bladedamp.studies.mass import optimal_mass


@pytest.fixture(scope="module")
def design():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return optimal_mass_by_backbone("cylinder", [0.05, 0.1], bracket=(0.3e-3, 4e-3), grid_per_decade=3,
                                        xatol=0.01)


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
