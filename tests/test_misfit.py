"""A damper that does not fit (the paper's manufacturing tolerance): mesh-derived initial gaps
drive the contact model, which then seats the damper on part of its faces."""
import dataclasses

import numpy as np
import pytest

from bladedamp import geometry as G
from bladedamp.damper.kinetics import seat
from bladedamp.reference import reference_disk

DEG = np.pi / 180


@pytest.fixture(scope="module")
def wedge():
    return reference_disk("wedge", 1e-3)


def test_nominal_shape_gives_zero_gaps_and_the_nominal_solution(wedge):
    gaps = G.misfit_gaps(wedge, G.wedge_mesh(wedge.damper, wedge.gamma_left, wedge.gamma_right))
    assert np.abs(gaps).max() < 1e-12, np.abs(gaps).max()
    nominal = wedge.frequency_response(93.0, 98.0, harmonics=(1,), max_step=0.05)
    fitted = dataclasses.replace(wedge, initial_gaps=gaps).frequency_response(93.0, 98.0, harmonics=(1,), max_step=0.05)
    err = abs(fitted.peak_amplitude / nominal.peak_amplitude - 1)
    assert err < 1e-9, f"zero gaps change the peak by {err:.1e}"


def test_misfit_wedge_seats_on_one_edge_and_solves(wedge):
    bad = G.wedge_mesh(wedge.damper, wedge.gamma_left + 1 * DEG, wedge.gamma_right)
    gaps = G.misfit_gaps(wedge, bad)
    h = wedge.damper.contact_height
    # OL face: gap opening linearly across the height, uniform along the length; OR fits
    ol = gaps[0].reshape(wedge.damper.contact.points_across_height, -1)
    assert np.allclose(ol, ol[:, :1], atol=1e-12)
    assert ol.min() == pytest.approx(0.0, abs=h * np.tan(1 * DEG) / 5)
    assert ol.max() > 0.6 * h * np.tan(1 * DEG)
    assert np.abs(gaps[1]).max() < 1e-9
    disk = dataclasses.replace(wedge, initial_gaps=gaps)
    geometry = disk.damper_geometry()
    F = disk.centrifugal_force(95.0)[0]
    _, approach, loads = seat(geometry, F)
    # force balance of the seating is kept (frictionless, same angles) ...
    np.testing.assert_allclose(loads, geometry.frictionless_normal_loads(F), rtol=1e-8)
    # ... the frictionless wedge self-aligns: it rolls by half the misfit, so each face misfits by
    # 0.5 deg: the approach varies linearly across the height with slope tan(0.5 deg), mirrored
    # between OL and OR (symmetric platforms)
    n_xi = ol.shape[0]
    xi = geometry.patches[0].xi.reshape(n_xi, -1)[:, 0]
    a_ol, a_or = (approach[c].reshape(n_xi, -1)[:, 0] for c in range(2))
    slope = np.polyfit(xi, a_ol, 1)[0]
    assert abs(slope) == pytest.approx(np.tan(0.5 * DEG), rel=1e-3), slope
    np.testing.assert_allclose(a_ol, a_or[::-1], rtol=1e-9)
    # a 3 deg misfit exceeds what the preload closes: the open edge of each face lifts off
    bad3 = G.wedge_mesh(wedge.damper, wedge.gamma_left + 3 * DEG, wedge.gamma_right)
    a3 = seat(dataclasses.replace(wedge, initial_gaps=G.misfit_gaps(wedge, bad3)).damper_geometry(), F)[1]
    for c in range(2):
        rows = a3[c].reshape(n_xi, -1)[:, 0]
        assert rows.min() < 0 < rows.max(), rows
        touching = np.flatnonzero(rows > 0)
        assert touching[0] == 0 or touching[-1] == n_xi - 1, rows   # the contact sits at one edge
    r = disk.frequency_response(93.0, 98.0, harmonics=(1,), max_step=0.05)
    assert r.success, r.message
    assert r.energy_balance_error().max() < 1e-6
    nominal = wedge.frequency_response(93.0, 98.0, harmonics=(1,), max_step=0.05)
    change = r.peak_amplitude / nominal.peak_amplitude - 1
    print(f"\n[misfit 1 deg] peak {1e3 * r.peak_amplitude:.4f} mm vs fitted "
          f"{1e3 * nominal.peak_amplitude:.4f} mm ({100 * change:+.1f} %)")
    assert abs(change) > 1e-3, "a partial contact must change the response"


def test_bad_gaps_are_rejected_when_the_disk_is_made(wedge):
    with pytest.raises(ValueError, match="initial_gaps"):
        dataclasses.replace(wedge, initial_gaps=np.zeros((2, 3)))
    P = wedge.damper_geometry().patches[0].n_points
    with pytest.raises(ValueError, match="initial_gaps"):
        dataclasses.replace(wedge, initial_gaps=np.full((2, P), np.nan))
