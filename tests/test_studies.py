"""Damper design studies (bladedamp.studies.design): engine orders, asymmetric platforms,
contact state (Eq. 27, Fig. 11) and wedge lift-off (Fig. 9).

Each test checks a physical statement of the paper (Panning, Sextro, Popp) or a symmetry
of the model, not a stored number of the code under test.
"""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from bladedamp.reference import reference_disk
from bladedamp.studies.design import (contact_state, engine_order_sweep, engine_order_sweeps, eo_trend,
                                      platform_angle_study, wedge_liftoff_map)
from bladedamp.studies.mass import (ROBUST_ATTEMPTS, MassOptimum, bracket_minimum, optimal_mass, peak_response, robust_peak,
                                    with_mass)

ROTOR_SPEED_EO0_HZ = 95.0


def _angles(disk, left_deg, right_deg):
    return dataclasses.replace(disk, gamma_left=np.radians(left_deg), gamma_right=np.radians(right_deg))


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


# ---------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("call, match", [
    (lambda: engine_order_sweep(reference_disk("cylinder"), []), "engine_orders"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [-1]), "engine_orders"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [1], mass_bounds=(0.0, 1e-2)), "mass_bounds"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [1], mass_bounds=(1e-2, 1e-3)), "mass_bounds"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [1], mass_bounds=(-1e-3, 1e-2)), "mass_bounds"),
    (lambda: engine_order_sweep(reference_disk(None), [1]), "damper"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [0], rotor_speed_eo0_hz=0.0), "rotor_speed_eo0_hz"),
    (lambda: engine_order_sweep(reference_disk("cylinder"), [1], f_range_hz=(105.0, 90.0)), "f_range_hz"),
    (lambda: platform_angle_study(reference_disk("cylinder"), []), "gamma_right_deg"),
    (lambda: platform_angle_study(reference_disk("cylinder"), [90.0]), "gamma_right_deg"),
    (lambda: platform_angle_study(reference_disk("cylinder"), [35.0], gamma_left_deg=0.0), "gamma_left_deg"),
    (lambda: platform_angle_study(reference_disk("cylinder"), [35.0], fixed_mass=0.0), "fixed_mass"),
    (lambda: platform_angle_study(reference_disk("cylinder"), [35.0], mass_bounds=(1e-3, 1e-3)), "mass_bounds"),
    (lambda: contact_state(reference_disk(None)), "damper"),
    (lambda: contact_state(reference_disk("cylinder"), f_range_hz=(0.0, 90.0)), "f_range_hz"),
    (lambda: wedge_liftoff_map(reference_disk("wedge"), f_range_hz=()), "f_range_hz"),
])
def test_bad_input_raises_value_error_naming_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# ---------------------------------------------------------------------------------------
# engine orders (Fig. 7, 8)
# ---------------------------------------------------------------------------------------
@pytest.mark.slow   # 8-26 s: kept out of the default run (under 10 min); CI runs it
def test_eo0_cylinder_rolls_optimum_is_the_undamped_amplitude():
    """EO = 0: the cylinder rolls, no mass reduces the resonance by more than 1 %."""
    s = engine_order_sweep(reference_disk("cylinder"), [0], mass_bounds=(1e-4, 1e-2), xatol=0.1)
    assert not s.failures
    assert abs(s.optimal_peak_amplitude[0] / s.undamped_peak_amplitude[0] - 1) < 0.01
    assert np.isnan(s.optimal_mass[0])
    # and the rolling is real: already at a single mass the peak is the undamped one within 1 %
    p, _, _ = peak_response(reference_disk("cylinder", 3e-3, engine_order=0, rotor_speed_hz=ROTOR_SPEED_EO0_HZ))
    assert abs(p / s.undamped_peak_amplitude[0] - 1) < 0.01


def test_eo0_wedge_damps_where_the_cylinder_rolls():
    """EO = 0: the wedge cannot roll (contact height), one mass already damps clearly."""
    wedge = reference_disk("wedge", 1e-3, engine_order=0, rotor_speed_hz=ROTOR_SPEED_EO0_HZ)
    p, _, _ = peak_response(wedge)
    undamped, _, _ = peak_response(reference_disk(None))
    assert p < 0.6 * undamped


@pytest.mark.slow
def test_eo0_wedge_optimum_clearly_below_undamped():
    s = engine_order_sweep(reference_disk("wedge"), [0], mass_bounds=(1e-4, 1e-2), xatol=0.1)
    assert not s.failures
    assert s.reduction[0] > 0.4
    assert np.isfinite(s.optimal_mass[0])


@pytest.mark.slow
def test_optimal_mass_is_a_true_minimum():
    """The optimiser's mass gives a lower peak than 0.8 and 1.25 times that mass (EO = 1)."""
    s = engine_order_sweep(reference_disk("cylinder"), [1], mass_bounds=(5e-5, 5e-3), xatol=0.03)
    m, p = s.optimal_mass[0], s.optimal_peak_amplitude[0]
    assert np.isfinite(m) and s.reduction[0] > 0.3
    disk = reference_disk("cylinder", m, engine_order=1)
    for factor in (0.8, 1.25):
        assert peak_response(with_mass(disk, factor * m))[0] > p


def test_known_optima_are_used_as_given_and_not_recomputed():
    """`reproduce` passes the EO 1 optima of the mass study to the EO study and the 1 g
    reference-angle result to the platform study: those cases must come out exactly as given
    (values no solver would return), and nothing else may be computed for them (every case is
    known here, so a recomputation would replace the values)."""
    fake = {eo: MassOptimum(1e-3 * (eo + 1), 1e-4 * (eo + 1), 1e-3, 1) for eo in (0, 1)}
    cyl, wedge = engine_order_sweeps([reference_disk("cylinder"), reference_disk("wedge")], [1, 0],
                                     known=[fake, {0: fake[1], 1: fake[0]}])
    assert list(cyl.engine_orders) == [1, 0] and list(cyl.optimal_mass) == [2e-3, 1e-3]
    assert list(cyl.optimal_peak_amplitude) == [2e-4, 1e-4] and list(wedge.optimal_mass) == [1e-3, 2e-3]
    assert cyl.kind == "cylinder" and wedge.kind == "wedge"
    single = engine_order_sweep(reference_disk("cylinder"), [0], known=fake)
    assert single.optimal_mass[0] == 1e-3 and single.reduction[0] == pytest.approx(0.9)
    with pytest.raises(ValueError, match="known"):
        engine_order_sweeps([reference_disk("cylinder")], [0], known=[fake, fake])
    pa = platform_angle_study(reference_disk("cylinder"), [35.0], known={35.0: (7e-4, fake[1])})
    assert (pa.peak_amplitude_at_fixed_mass[0], pa.optimal_mass[0], pa.optimal_peak_amplitude[0]) == (7e-4, 2e-3, 2e-4)


# ---------------------------------------------------------------------------------------
# global mass optimisation: grid bracket + bounded local search
# ---------------------------------------------------------------------------------------
def _two_valleys(x):
    """A wide shallow valley at 0.3 (local, 0.5) and a narrow deep one at 0.85 (global, 0.2)."""
    return 1 - 0.5 * np.exp(-((x - 0.3) / 0.15) ** 2) - 0.8 * np.exp(-((x - 0.85) / 0.04) ** 2)


def test_bracket_finds_the_global_of_two_minima_where_brent_alone_stops_at_the_local():
    from scipy.optimize import minimize_scalar

    alone = minimize_scalar(_two_valleys, bounds=(0.0, 1.0), method="bounded", options={"xatol": 1e-4})
    assert abs(alone.x - 0.3) < 1e-3                 # the local search alone: the wrong valley
    x, f, cache, (a, b) = bracket_minimum(_two_valleys, np.linspace(0.0, 1.0, 21), 1e-4, 10.0)
    assert abs(x - 0.85) < 1e-3 and f == pytest.approx(0.2, abs=1e-6)
    assert a < 0.85 < b and b - a == pytest.approx(0.1)
    assert all(x_ in cache for x_ in np.linspace(0.0, 1.0, 21))


def test_bracket_never_returns_a_point_that_could_not_be_computed():
    """NaN (a failed response) inside the deep valley: the answer is a computed point."""
    def f(x):
        return np.nan if 0.8 <= x <= 0.9 else _two_valleys(x)

    x, fx, cache, _ = bracket_minimum(f, np.linspace(0.0, 1.0, 21), 1e-4, 10.0)
    assert np.isfinite(fx) and fx == f(x) and not 0.8 <= x <= 0.9
    assert fx == min(v for v in cache.values() if np.isfinite(v))


def test_eo_trend_tolerance():
    assert eo_trend([71, 90, 95, 95.2, 95.0], 0.5)["grows"]           # a dip within the tolerance
    t = eo_trend([71, 90, 95, 93.4, 98], 0.5)
    assert not t["grows"] and t["dips"] == [(3, pytest.approx(1.6))]
    assert not eo_trend([1.0, np.nan, 3.0], 0.1)["grows"] and eo_trend([1.0, np.nan, 3.0], 0.1)["missing"] == [1]
    assert eo_trend([1.0, 0.95, 1.2], 0.1, relative=True)["grows"]    # 5 % down within 10 %
    assert not eo_trend([1.0, 0.8, 1.2], 0.1, relative=True)["grows"]


@pytest.mark.slow
def test_light_cylinder_at_eo6_fails_with_a_lower_bound_and_is_not_the_optimum():
    """A 0.13 g cylinder at EO 6: the continuation stalls just below the resonance from both
    sides (94.90 / 95.10 Hz, measured); robust_peak reports the failure with the largest
    amplitude it solved, already > 60 % of the undamped peak, far above any optimum."""
    ev = robust_peak(reference_disk("cylinder", 0.1261e-3, engine_order=6))
    undamped, _, _ = peak_response(reference_disk(None, engine_order=6))
    if ev.success:                                  # a better continuation solved it: a true peak
        assert ev.peak_amplitude > 0.6 * undamped
    else:
        # every attempt of ROBUST_ATTEMPTS, then the downward sweep
        assert np.isnan(ev.peak_amplitude) and ev.lower_bound > 0.6 * undamped and ev.attempts == len(ROBUST_ATTEMPTS) + 1
        assert "not covered" in ev.message


@pytest.mark.slow
def test_eo7_cylinder_global_optimum_beyond_the_old_local_one():
    """EO 7: the old local search stopped at 7.1 g (93.4 %), because failed responses of
    light and of 7.9 g masses looked worse than the undamped blade. The bracketed search finds
    a mass with a lower peak than 7.1 g gives, which is a true minimum, and certifies it."""
    disk = reference_disk("cylinder", 1e-2, engine_order=7)
    opt = optimal_mass(disk, bounds=(1e-3, 3e-2), xatol=0.05, grid_per_decade=3)
    assert opt.success, opt.message
    assert opt.peak_amplitude < robust_peak(with_mass(disk, 7.1e-3)).peak_amplitude
    for factor in (0.8, 1.25):
        ev = robust_peak(with_mass(disk, factor * opt.mass))
        assert not ev.success or ev.peak_amplitude > opt.peak_amplitude
    assert len(opt.grid_mass) == len(opt.grid_peak_amplitude) and opt.bracket[0] < opt.mass < opt.bracket[1]


def test_branch_and_bound_of_the_mass_grid_keeps_the_optimum(monkeypatch):
    """The grid masses are evaluated heaviest first, each branch stopped once it is above the best
    peak found before it (TunedDisk.frequency_response(stop_above=...)). The optimum (mass, peak,
    bracket) is exactly that of the search without the stop, and every stopped mass's own peak is
    above it. Measured on the reference cylinders, EO 7: 39 s against several minutes, the same
    optimum to the last digit (tests/data/reproduce_summary.json)."""
    import bladedamp.studies.mass as mass

    disk = reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pruned = optimal_mass(disk, bounds=(0.3e-3, 3e-3), grid_per_decade=3, xatol=0.1)
        plain_case = mass.robust_peak_case
        monkeypatch.setattr(mass, "robust_peak_case", lambda case: plain_case(case[:-1] + (np.inf,)))
        plain = optimal_mass(disk, bounds=(0.3e-3, 3e-3), grid_per_decade=3, xatol=0.1)
    assert pruned.stopped_masses and not plain.stopped_masses and not pruned.failed_masses
    assert (pruned.mass, pruned.peak_amplitude, pruned.bracket) == (plain.mass, plain.peak_amplitude, plain.bracket)
    for m in pruned.stopped_masses:
        k = int(np.argmin(np.abs(plain.grid_mass - m)))
        assert np.isnan(pruned.grid_peak_amplitude[k]) and plain.grid_peak_amplitude[k] > pruned.peak_amplitude
    assert "stopped once above the best peak" in pruned.message


def test_complete_grid_solves_the_stopped_masses_as_the_unpruned_search_does(monkeypatch):
    """``optimal_mass(complete_grid=True)`` (for optimize.png's whole curve) fills the grid masses
    that branch and bound stopped with their full peaks: the same numbers as a search without
    branch and bound, and the same optimum; ``evaluated_mass`` holds the grid and the search's
    points with their peaks."""
    import bladedamp.studies.mass as mass

    disk = reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        complete = optimal_mass(disk, bounds=(0.3e-3, 3e-3), grid_per_decade=3, xatol=0.1, complete_grid=True)
        plain_case = mass.robust_peak_case
        monkeypatch.setattr(mass, "robust_peak_case", lambda case: plain_case(case[:-1] + (np.inf,)))
        plain = optimal_mass(disk, bounds=(0.3e-3, 3e-3), grid_per_decade=3, xatol=0.1)
    assert (complete.mass, complete.peak_amplitude) == (plain.mass, plain.peak_amplitude)
    assert np.all(np.isfinite(complete.grid_peak_amplitude))
    np.testing.assert_allclose(complete.grid_peak_amplitude, plain.grid_peak_amplitude, rtol=1e-9)
    assert np.all(np.diff(complete.evaluated_mass) > 0) and np.all(np.isin(complete.grid_mass, complete.evaluated_mass))
    assert len(complete.evaluated_mass) > len(complete.grid_mass)             # the bounded search's points too
    k = int(np.argmin(np.abs(complete.evaluated_mass - complete.mass)))
    assert complete.evaluated_peak_amplitude[k] == complete.peak_amplitude


# ---------------------------------------------------------------------------------------
# asymmetric platforms (Fig. 10)
# ---------------------------------------------------------------------------------------
@pytest.mark.slow   # 8-26 s: kept out of the default run (under 10 min); CI runs it
def test_mirror_symmetry_standing_wave():
    """(gamma_L, gamma_R) = (35, 60) and (60, 35) are mirror images: same peak. Exact for a
    standing wave (EO = 0; the wedge, since the cylinder rolls there)."""
    d = reference_disk("wedge", 1e-3, engine_order=0, rotor_speed_hz=ROTOR_SPEED_EO0_HZ)
    pa = peak_response(_angles(d, 35, 60), max_step=0.02)[0]
    pb = peak_response(_angles(d, 60, 35), max_step=0.02)[0]
    assert abs(pa - pb) / pa < 1e-4            # measured 1.9e-5 (peak interpolation)


def _mirror_difference_eo1():
    d = reference_disk("cylinder", 1e-3)
    pa = peak_response(_angles(d, 35, 60), (94.0, 97.0), max_step=0.02)[0]
    pb = peak_response(_angles(d, 60, 35), (94.0, 97.0), max_step=0.02)[0]
    return abs(pa - pb) / pa


def test_mirror_symmetry_eo1_within_peak_resolution():
    """EO = 1, 1 g cylinder: exchanging gamma_L and gamma_R changes the peak by < 1e-3
    (measured 2.2e-4; 2.1e-2 before the radial platform mismatch was split half/half)."""
    assert _mirror_difference_eo1() < 1e-3


@pytest.mark.xfail(strict=False, reason=(
    "paper: exchanging gamma_L and gamma_R gives the same results. Measured at EO = 1 (1 g "
    "cylinder, 35/60 vs 60/35 deg): peaks 0.416942 / 0.417035 mm, relative difference 2.2e-4 "
    "(1.9e-4 at max_step 0.005, so not the peak interpolation); at EO = 0 (standing wave) the "
    "difference is 2e-5. A travelling wave (EO != 0, n/2) is mapped to EO -> -EO by the mirror, "
    "so exact equality is not guaranteed with friction and damper inertia."))
def test_mirror_symmetry_eo1_exact_as_in_the_paper():
    assert _mirror_difference_eo1() < 1e-5


def test_platform_angle_study_fixed_mass_symmetric_matches_peak_response():
    s = platform_angle_study(reference_disk("cylinder"), [35.0], optimise=False)
    p, _, _ = peak_response(reference_disk("cylinder", 1e-3))
    assert s.peak_amplitude_at_fixed_mass[0] == pytest.approx(p, rel=1e-9)
    assert s.peak_amplitude_at_fixed_mass[0] < s.undamped_peak_amplitude
    assert np.isnan(s.optimal_mass[0])


# ---------------------------------------------------------------------------------------
# contact state (Eq. 27, Fig. 11)
# ---------------------------------------------------------------------------------------
def test_gamma_r_85_left_sticks_right_slides():
    """Paper: at gamma_R = 85 deg |w*_OL| < 1 (stick, F* ~ w*), |w*_OR| > 1 (slide, |F*| ~ 1).
    Measured: w*_OL = -0.226 - 0.666j (|.| 0.704), w*_OR = 3.031 + 1.335j (|.| 3.31),
    F_N = 10.95 N (OL), 6.31 N (OR)."""
    d = _angles(reference_disk("cylinder", 1e-3), 35, 85)
    cs = contact_state(d)
    assert abs(cs.w_star[0]) < 1
    assert abs(cs.w_star[1]) > 1
    assert abs(cs.F_star[0] - cs.w_star[0]) < 1e-6 * abs(cs.w_star[0])   # whole contact sticks
    assert abs(cs.F_star[1]) < abs(cs.w_star[1])                        # friction-limited
    assert cs.normal_load[1] < cs.normal_load[0]                        # less normal force at OR
    # normalisation (Eq. 27)
    assert cs.normal_load == pytest.approx(d.static_normal_loads(cs.peak_frequency_hz), rel=1e-9)
    assert cs.w_star == pytest.approx(cs.w_xi * cs.tangential_stiffness / (cs.friction_coefficient * cs.normal_load))


def test_symmetric_platforms_equal_contact_states_standing_wave():
    """Symmetric platforms, EO = 0: both contacts see exactly the same normalised motion."""
    cs = contact_state(reference_disk("wedge", 1e-3, engine_order=0, rotor_speed_hz=ROTOR_SPEED_EO0_HZ))
    assert abs(abs(cs.w_star[0]) - abs(cs.w_star[1])) < 1e-6 * abs(cs.w_star[0])
    assert cs.normal_load[0] == pytest.approx(cs.normal_load[1], rel=1e-12)


def test_symmetric_platforms_eo1_equal_magnitude_opposite_phase():
    """Paper: equal conditions at OL and OR, 180 deg phase shift. In the model (travelling
    wave, EO = 1) the magnitudes agree to 3.2 % (2.620 vs 2.538), the phases differ by ~180 deg."""
    cs = contact_state(reference_disk("cylinder", 1e-3))
    a, b = np.abs(cs.w_star)
    assert abs(a - b) / max(a, b) < 0.05
    assert a > 1 and b > 1                     # both slide at the reference optimum
    dphase = np.degrees(np.angle(cs.w_star[1] / cs.w_star[0]))
    assert abs(abs(dphase) - 180) < 10


def test_contact_state_plot():
    import matplotlib
    matplotlib.use("Agg")
    cs = contact_state(reference_disk("cylinder", 1e-3))
    assert cs.plot() is not None


# ---------------------------------------------------------------------------------------
# lift-off (Fig. 9)
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def liftoff_maps():
    """Wedge of 1 g: below (F_x = 0.04 N) and just above (0.07 N) the lift-off threshold."""
    out = {}
    for F in (0.04, 0.07):
        disk = reference_disk("wedge", 1e-3, excitation=np.array([F, 0, 0, 0, 0, 0]))
        out[F] = (disk, wedge_liftoff_map(disk))
    return out


def test_liftoff_ratio_two_ways_agree(liftoff_maps):
    """r from the first-harmonic amplitude and from the AFT time samples of the approach."""
    for disk, lm in liftoff_maps.values():
        T = lm.n_samples
        # max over T samples of cos lies within cos(pi / T) of the true maximum
        assert np.all(lm.ratio_time <= lm.ratio * (1 + 1e-12))
        assert np.all(lm.ratio_time >= lm.ratio * np.cos(np.pi / T) - 1e-12)
        clear = np.abs(lm.ratio - 1) > 1 - np.cos(np.pi / T)
        assert np.array_equal((lm.min_approach < 0)[clear], (lm.ratio > 1)[clear])
        # the static approach is the disk's own preload (TunedDisk.approach_function)
        approach = disk.approach_function(disk.damper_geometry(), disk.hbm_system().basis)
        assert lm.static_approach == pytest.approx(approach(2 * np.pi * lm.peak_frequency_hz)[0], rel=1e-8)


def test_liftoff_first_at_the_edges(liftoff_maps):
    """Increasing the excitation, the first points to lift off (r > 1) are in the outermost
    rows across the contact height (|xi*| = 0.4, the cells at the edges xi* = +-0.5)."""
    _, below = liftoff_maps[0.04]
    _, above = liftoff_maps[0.07]
    assert below.ratio.max() < 1
    assert above.ratio.max() > 1
    edge = np.isclose(np.abs(above.xi_star), np.abs(above.xi_star).max())
    lifted = above.ratio > 1
    assert lifted.any()
    assert np.all(edge[None, :] | ~lifted)
    for c in range(2):                         # the largest ratio of each contact is at an edge
        assert edge[np.argmax(above.ratio[c])]


def test_liftoff_plot(liftoff_maps):
    import matplotlib
    matplotlib.use("Agg")
    assert liftoff_maps[0.07][1].plot() is not None


def test_the_mass_grid_ends_are_the_bounds_and_warn_nothing():
    """exp(log(1e-5)) is 9.999999999999997e-06: a grid built in log(mass) would try a damper
    below its own lower bound (and below the plausible 1e-5 kg); its ends are the bounds."""
    from bladedamp.studies.mass import log_mass_grid, with_mass
    from bladedamp.validation import PlausibilityWarning

    assert np.exp(np.log(1e-5)) < 1e-5                      # the rounding the grid must not pass on
    loggrid, masses = log_mass_grid((1e-5, 2e-2))
    assert masses[0] == 1e-5 and masses[-1] == 2e-2 and len(masses) == 15      # 4 per decade, 3.3 decades
    np.testing.assert_allclose(np.log(masses), loggrid, rtol=4 * np.finfo(float).eps)   # exp, log: an ulp each
    disk = reference_disk("cylinder")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        for m in masses:
            with_mass(disk, float(m))
    with pytest.warns(PlausibilityWarning, match="damper mass = 1e-07 kg") as caught:
        with_mass(disk, 1e-7)                                  # below: warned, at this line
    assert caught[0].filename == __file__
