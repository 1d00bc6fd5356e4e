"""Design search beyond the paper, lift-off onset and the process-parallel study runner."""
import numpy as np
import pytest

from bladedamp.reference import reference_disk
from bladedamp.studies.design import design_map, liftoff_onset, wedge_liftoff_map
from bladedamp.studies.mass import peak_response
from bladedamp.studies.parallel import parallel_map


def _square(x):
    return x * x


def test_parallel_map_keeps_order_and_reports_progress():
    seen = []
    out = parallel_map(_square, range(7), processes=2, progress=lambda d, n: seen.append((d, n)))
    assert out == [x * x for x in range(7)]
    assert seen[-1] == (7, 7) and len(seen) == 7


def test_design_map_grid_equals_direct_peaks_and_optimum_is_the_grid_minimum():
    masses, angles = np.array([0.5e-3, 2e-3]), np.array([35.0, 85.0])
    dm = design_map(reference_disk("cylinder"), masses, angles, processes=2)
    assert dm.peak_amplitude.shape == (2, 2)
    # one grid point recomputed directly: the parallel map must return the same number
    import dataclasses
    disk = dataclasses.replace(reference_disk("cylinder", masses[1]), gamma_right=np.radians(angles[1]))
    direct = peak_response(disk)[0]
    assert dm.peak_amplitude[1, 1] == pytest.approx(direct, rel=1e-12), (dm.peak_amplitude[1, 1], direct)
    opt = dm.optimum
    assert opt["peak_tip_mm"] == pytest.approx(1e3 * np.nanmin(dm.peak_amplitude))
    assert 0 < opt["reduction_pct"] < 100


def test_liftoff_ratio_grows_with_excitation_and_matches_the_map():
    onset = liftoff_onset(reference_disk("wedge", 1e-3), [2e-3], [0.02, 0.2], processes=1)
    r_low, r_high = onset["max_ratio"][0]
    # one harmonic, fixed preload: the normal vibration grows with the excitation
    assert r_high > r_low, (r_low, r_high)
    lift = wedge_liftoff_map(reference_disk("wedge", 1e-3, excitation=np.array([0.2, 0, 0, 0, 0, 0])))
    assert r_high == pytest.approx(lift.ratio.max(), rel=1e-9)


@pytest.mark.parametrize("bad", [dict(masses=[]), dict(masses=[-1e-3]), dict(gamma_right_deg=[95.0]),
                                 dict(disk=reference_disk(None)), dict(contact_height=2e-3)])
def test_design_map_bad_input(bad):
    args = dict(disk=reference_disk("cylinder"), masses=[1e-3], gamma_right_deg=[35.0])
    args.update(bad)
    with pytest.raises(ValueError):
        design_map(**args)


def test_liftoff_onset_bad_input():
    with pytest.raises(ValueError, match="contact_heights"):
        liftoff_onset(reference_disk("wedge"), [-1e-3], [0.1])
    with pytest.raises(ValueError, match="forces"):
        liftoff_onset(reference_disk("wedge"), [1e-3], [])
    with pytest.raises(ValueError, match="wedge"):
        liftoff_onset(reference_disk("cylinder"), [1e-3], [0.1])
