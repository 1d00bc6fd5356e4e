"""Gradient-based design over several parameters (issue 36 item 2): the known one-parameter
optimum (the paper's 1 g cylinder at EO 1, 71 % below the undamped peak) to 1 %. The two- and
three-parameter problems against dense grids are measured by benchmarks/bench_gradient_design.py
(the issue's tenth of the grid's solves is not met yet: see benchmarks/README.md)."""
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
