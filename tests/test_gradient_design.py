"""Gradient-based design over several parameters (issue 36 item 2): the known one-parameter
optimum (the paper's 1 g cylinder at EO 1, 71 % below the undamped peak) to 1 %; on two- and
three-parameter problems the optimum of a dense grid search with at most a tenth of its solves
(slow)."""
import itertools

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.studies.gradient import optimal_design

RANGE = (90.0, 105.0)
UNDAMPED_PEAK = 1.6996e-3            # the reference blade without damper, one harmonic [m]


def test_one_parameter_optimum_is_the_papers_1_g_and_71_percent():
    disk = bd.reference_disk("cylinder", 3e-3)
    optimum = optimal_design(disk, ["damper.mass_g"], [[0.1, 20.0]], RANGE, harmonics=(1,), n_starts=2)
    assert optimum.success
    assert abs(optimum["damper.mass_g"] - 1.0) <= 0.01
    assert abs((1 - optimum.peak_amplitude / UNDAMPED_PEAK) - 0.71) <= 0.01
    assert optimum.n_responses <= 30
    assert "damper.mass_g" in optimum.table()


def test_bad_bounds_are_refused():
    disk = bd.reference_disk("cylinder", 1e-3)
    with pytest.raises(ValueError, match="low < high"):
        optimal_design(disk, ["damper.mass_g"], [[2.0, 1.0]], RANGE)


def grid_peak(point):
    """The peak [m] (inf where the response fails) of the reference cylinder (from 3 g) with the
    grid point ``(keys, values)`` set, one harmonic over 90-105 Hz."""
    keys, values = point
    disk = bd.reference_disk("cylinder", 3e-3).with_parameters(dict(zip(keys, values)))
    response = disk.frequency_response(*RANGE, harmonics=(1,))
    return response.peak_amplitude if response.success else np.inf


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")
@pytest.mark.parametrize("keys, axes", [
    (["damper.mass_g", "disk.gamma_left_deg"], [np.geomspace(0.1, 20.0, 20), np.linspace(20.0, 60.0, 20)]),
    (["damper.mass_g", "disk.gamma_left_deg", "disk.gamma_right_deg"],
     [np.geomspace(0.1, 20.0, 10), np.linspace(20.0, 60.0, 10), np.linspace(20.0, 60.0, 10)]),
])
def test_several_parameters_reach_the_dense_grid_optimum_with_a_tenth_of_its_solves(keys, axes):
    """Mass and one or both platform angles (box 0.1-20 g, 20-60 deg): the optimiser's peak is at
    most the grid's lowest (to 0.5 %: the grid's points are not the optimum; the peaks are solved
    to the continuation's accuracy) with at most a tenth of the grid's frequency responses (400
    and 1000; measured: 22 responses and 0.3955 mm against the 16 x 16 grid's 0.3973 mm on its
    bound, and 81 and 0.3540 mm against 0.3695 mm; benchmarks/README.md). The grid runs on two
    processes."""
    from concurrent.futures import ProcessPoolExecutor

    points = [(keys, p) for p in itertools.product(*axes)]
    with ProcessPoolExecutor(2) as pool:
        peaks = list(pool.map(grid_peak, points, chunksize=8))
    optimum = optimal_design(bd.reference_disk("cylinder", 3e-3), keys, [[a[0], a[-1]] for a in axes], RANGE,
                             harmonics=(1,))
    assert optimum.n_responses <= len(points) / 10, (optimum.n_responses, len(points))
    assert optimum.peak_amplitude <= 1.005 * min(peaks), (optimum.table(), min(peaks))
