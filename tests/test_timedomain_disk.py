"""The bladed disk in the time domain: full-assembly time integration against the HBM.

The time integration (:func:`bladedamp.timedomain.disk_time_response`, explicit central
differences of the whole assembly, the AFT's own return-map step for every contact point,
from the static equilibrium under F_CG) has no harmonic truncation and no AFT sampling: it is
the independent check of the harmonic balance on the same equations (same M, D, K, contact
maps, patches and loads, taken from the HBM model objects).

HBM values at exact frequencies: continuation over the range, the branch interpolated at the
frequency and corrected by Newton there (``hbm_tip``).
"""
import dataclasses

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.blade import reference_blade
from bladedamp.damper.geometry import CylinderDamper, WedgeDamper
from bladedamp.disk import TunedDisk
from bladedamp.mistuned import MistunedDisk
from bladedamp.reference import (DAMPER_RADIUS, EXCITATION_FX, PLATFORM_ANGLE, reference_contact,
                                 reference_damper)
from bladedamp.timedomain import DiskTimeResponse, drift_verdict, hbm_tip_at, map_convergence

# The HBM harmonics of the validation: None is frequency_response's default ("auto", the
# harmonics chosen to its tolerance). Forcing (1,) here must make the wedge test fail.
HBM_HARMONICS = None

# 7 frequencies across the reference 1F resonance (cylinder 1 g peak 95.33 Hz, wedge 0.3 g
# 95.43-95.61 Hz by the HBM), with the wedge's 95.1 / 96.1 Hz of the earlier measurement
FREQUENCIES_1F = np.array([92.0, 94.0, 95.1, 95.4, 95.7, 96.1, 98.0])


def hbm_tip(disk, f_hz, harmonics, pad_hz=1.0):
    """HBM first-harmonic tip amplitude at exact frequencies: (n, 3) tuned, (n, s, 3) mistuned [m]."""
    return hbm_tip_at(disk, f_hz, harmonics, pad_hz=pad_hz)


def small_disk(damper, n_blades=4, blade=None, **kwargs):
    """The reference blade and platforms in a disk of ``n_blades`` (EO = 1 unless given)."""
    return TunedDisk(blade or reference_blade(), damper, n_blades, kwargs.pop("engine_order", 1), PLATFORM_ANGLE,
                     PLATFORM_ANGLE, DAMPER_RADIUS, np.asarray(EXCITATION_FX, dtype=float), **kwargs)


# ---------------------------------------------------------------------------------------
# fast: linear limits, a small mistuned disk, the drift detector, bad input
# ---------------------------------------------------------------------------------------
def test_no_damper_is_the_closed_form_linear_response():
    """No damper: every blade's tip is the modal closed form |Phi_tip S^-1 Phi_exc^T f| (Eq. 4-5),
    off and at the 95 Hz resonance; the discretisation error of 512 steps per period is ~1e-4."""
    disk = small_disk(None, blade=dataclasses.replace(reference_blade(), damping_ratios=0.005))
    f = np.array([90.0, 95.0, 100.0])
    tr = disk.time_response(f, tol=1e-7)
    assert tr.periodic.all(), tr.message
    ref = np.abs(disk.blade.linear_frf(f, disk.excitation))[:, :3]
    err = np.abs(tr.tip_amplitude / ref[:, None, :] - 1)[:, :, 0]
    print("rel err per frequency (max over blades):", err.max(axis=1))
    assert err.max() < 1e-3
    # energy balance of the time integration: excitation work = viscous dissipation
    assert tr.energy_balance_error().max() < 1e-3
    assert np.all(tr.dissipated_energy == 0)


def test_stuck_damper_is_the_linear_hbm():
    """mu = 1e3: every contact point sticks (the linear stuck system); the time integration
    equals the HBM (which is then linear) at 92 and 96 Hz, and dissipates nothing in friction."""
    blade = dataclasses.replace(reference_blade(), damping_ratios=0.005)
    damper = CylinderDamper(1e-3, 2e-3, 20e-3, reference_contact(friction_coefficient=1e3))
    disk = small_disk(damper, blade=blade)
    f = np.array([92.0, 96.0])
    tr = disk.time_response(f, tol=1e-7)
    assert tr.periodic.all(), tr.message
    assert np.all(tr.point_state[:, :, 0] == 1.0)            # stuck throughout
    hbm = hbm_tip(disk, f, (1,))
    err = np.abs(tr.tip_amplitude[:, :, 0] / hbm[:, None, 0] - 1)
    print("stuck: rel err per frequency (max over blades):", err.max(axis=1))
    assert err.max() < 2e-3
    assert np.all(tr.dissipated_energy == 0)


def small_wedge(mass=3e-4):
    """The reference wedge with 3 x 3 points per contact (faster; HBM and time integration
    use the same points)."""
    return WedgeDamper(mass, 2e-3, 20e-3, reference_contact(points_across_height=3, points_along_length=3))


def test_mistuned_wedge_disk_matches_the_hbm():
    """A 4-blade mistuned disk (kappa 1, 1.005, 0.995, 1) with 0.3 g wedges (3 x 3 points) in
    slip at 97 Hz: the HBM with HBM_HARMONICS within 2 % of the time integration on every
    blade (measured 0.3-1.3 %; the one-harmonic HBM is 0.9-3.2 % off); energy balance of the
    time integration (its works the mean over the periods of the mean tip amplitudes: the motion
    fluctuates by 9e-5 per period, and its last period alone was 5.8e-3 off on one machine); the
    dampers dissipate."""
    disk = MistunedDisk.from_tuned(small_disk(small_wedge()), kappa=[1.0, 1.005, 0.995, 1.0])
    f = np.array([97.0])
    tr = disk.time_response(f)
    assert tr.periodic.all(), tr.message
    assert tr.dissipated_energy.min() > 0.3 * tr.excitation_work.min()     # the dampers work
    assert np.ptp(tr.tip_amplitude[0, :, 0]) > 0.1 * tr.tip_amplitude[0, :, 0].max()   # mistuned: blades differ
    hbm = hbm_tip(disk, f, HBM_HARMONICS, pad_hz=0.3)
    err = np.abs(hbm[:, :, 0] / tr.tip_amplitude[:, :, 0] - 1)
    print("mistuned 4 blades: rel err per blade:", err)
    assert err.max() < 0.02
    assert tr.energy_balance_error().max() < 5e-3


def test_rough_power_law_contacts():
    """The rough-surface normal law (RoughnessNormalLaw, exponent 1.5): the time integration
    seats the dampers on the same static loads as the HBM's seating (Eq. 26 load, flexible
    blades) and, at 96 Hz (stuck, the normal law nonlinear), agrees with the HBM within 1 %
    (measured 0.25 %)."""
    damper = WedgeDamper(3e-4, 2e-3, 20e-3, reference_contact(points_across_height=3, points_along_length=3,
                                                              roughness_exponent=1.5))
    disk = small_disk(damper)
    tr = disk.time_response(96.0)
    assert tr.periodic.all(), tr.message
    hbm = hbm_tip(disk, 96.0, HBM_HARMONICS, pad_hz=0.3)
    err = np.abs(tr.tip_amplitude[0, :, 0] / hbm[0, 0] - 1)
    print("power law 96 Hz: rel err per blade", err)
    assert err.max() < 0.01


def test_light_damper_is_not_refused_by_rounding():
    """The check that a damper's mass rows couple to nothing else compared two sums of the same
    entries, which differ by rounding (2.7e-20 for random disk 102's 0.042 g cylinder): every
    time integration of that disk was refused. Now the off-block entries themselves are tested."""
    import sys
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_random_designs import disk_design, make_disk

    r = make_disk(disk_design(102)).time_response(95.0, min_periods=1, max_periods=2)
    assert list(r.status) == ["not settled"]                 # integrated (2 periods), not refused


def test_rolling_cylinder_is_detected():
    """The 4-blade disk with the 1 g cylinder at its 102 Hz resonance (EO = 1, 90 deg between
    neighbours): the cylinder keeps rolling, its roll angle phi_y growing steadily period after
    period (measured ~1e-3 rad per period) while the tip amplitudes settle on average; the time
    integration says so (status "drifting", not periodic) instead of reporting a steady state."""
    disk = small_disk(reference_damper("cylinder", 1e-3))
    tr = disk.time_response(102.0, max_periods=1500)
    print(tr.message[0])
    assert not tr.periodic[0]
    assert tr.status[0] == "drifting" and "phi_y" in tr.message[0]
    roll = tr.damper_history[0][:, :, 4]                       # (periods, dampers) mean phi_y
    assert np.all(np.abs(roll[-1] - roll[-41]) > 40 * 1e-4)    # > 0.1 mrad per period on every damper
    assert tr.dissipated_energy[0] > 0.5 * tr.excitation_work[0]


def test_engine_order_0_cylinder_does_not_damp():
    """EO = 0 (all blades in phase; rotor speed 95 Hz): the paper says the cylinder rolls and does
    not damp. In this model neighbouring platforms move alike, so the cylinder moves rigidly
    with them: every point sticks, nothing is dissipated, nothing drifts, and the tip vibrates
    as without a damper (measured 1.644 mm against 1.700 mm at 95 Hz, the damper's mass
    lowering the resonance)."""
    disk = small_disk(reference_damper("cylinder", 1e-3), engine_order=0, rotor_speed_hz=95.0)
    tr = disk.time_response(95.0)
    assert tr.periodic[0] and tr.status[0] == "periodic", tr.message
    assert np.all(tr.point_state[0, :, 0] == 1.0) and tr.dissipated_energy[0] == 0.0
    free = np.abs(disk.blade.linear_frf(95.0, disk.excitation))[0, 0]
    assert 0.9 < tr.tip_amplitude[0, :, 0].min() / free < 1.0


def test_static_state_with_a_misfit_is_the_seating():
    """Per-point initial gaps (a wedge that does not fit: gaps growing across the contact height,
    opposite on OL and OR): the time integration's static state under F_CG (flexible blades,
    frictionless) carries the same per-point normal loads as the HBM's rigid-platform seating
    (kinetics.seat) to 1e-6, and leaves the same points open."""
    from bladedamp.damper.kinetics import seat
    from bladedamp.timedomain import frictionless_static_state, assembly_arrays, point_normal_forces

    xi = np.repeat(np.linspace(-1.0, 1.0, 3), 3)                  # 3 x 3 points, xi-major
    disk = small_disk(small_wedge(), initial_gaps=np.array([5e-6 * (1 + xi), 5e-6 * (1 - xi)]))
    arrays = assembly_arrays(MistunedDisk.from_tuned(disk))
    w = 2 * np.pi * 97.0
    f = arrays.system.excitation(w)[0].reshape(3, -1)
    x0 = frictionless_static_state(arrays, f[0])
    loads, _ = point_normal_forces(arrays, arrays.offset - arrays.point_map[2::3] @ x0)
    geometry = disk.damper_geometry()
    _, approach, _ = seat(geometry, disk.centrifugal_force(97.0)[0])
    ref = np.concatenate([p.normal_law.force(approach[c], p.weights)[0] for c, p in enumerate(geometry.patches)])
    per_damper = loads.reshape(4, -1)
    assert np.abs(per_damper - ref[None, :]).max() < 1e-6 * ref.max()
    assert np.any(ref == 0) and np.all((per_damper == 0) == (ref == 0)[None, :])


def test_drift_verdict():
    """The detector of a non-periodic damper: a steady drift is reported with its rate, a
    decaying or oscillating transient of the mean is not."""
    W = 40
    p = np.arange(W + 1)[:, None, None]
    scale = np.array([1e-6] * 3 + [1e-3] * 3)
    base = np.zeros((W + 1, 2, 6))
    drifting = base.copy()
    drifting[:, 1, 4] = 1e-5 * p[:, 0, 0]                           # phi_y of damper 1: 1e-5 rad / period
    d, a, rate = drift_verdict(drifting, scale, 1e-5)
    assert (d, a) == (1, 4) and rate == pytest.approx(1e-5)
    decaying = base.copy()
    decaying[:, 0, 4] = 1e-3 * 0.9 ** p[:, 0, 0]                    # settles geometrically
    assert drift_verdict(decaying, scale, 1e-5) is None
    beating = base.copy()
    beating[:, 0, 2] = 1e-7 * np.sin(2 * np.pi * p[:, 0, 0] / 30)  # a beat of the transient
    assert drift_verdict(beating, scale, 1e-5) is None
    slow = base.copy()
    slow[:, 0, 4] = 1e-9 * p[:, 0, 0]                               # below 10 tol of the amplitude
    assert drift_verdict(slow, scale, 1e-5) is None


def test_map_convergence_bounds_the_residual_drift():
    """The convergence of the period-to-period map: first harmonics approaching their limit as a
    damped transient (geometric decay of the distance, with a period-2 ringing that never decays,
    as the dampers on their contact springs, within the accepted fluctuation) converge, and the
    residual drift it states bounds the last block mean's true distance from the limit; a
    transient not yet decayed, a ringing beyond the accepted fluctuation, a motion that keeps
    changing (random first harmonics, as a damper hopping) or moves steadily do not converge."""
    p, tol, fluct = 800, 1e-3, 2e-4
    k = np.arange(p)[:, None]
    limit = np.array([1.0 + 0.5j, 0.2 - 0.1j])
    ringing = 1e-4 * (-1.0) ** k
    verdicts = []
    for rate in (2e-3, 6e-3, 2e-2):                     # sigma T per period
        h = limit + 0.3 * np.exp(-rate * k) * np.exp(0.05j * k) + ringing
        converged, residual, q, L, _, _ = map_convergence(h, 1e-3, tol, fluct)
        true = np.abs(h[-L:].mean(axis=0) - limit).max() / np.abs(limit).max()
        assert L == p // 4 and true <= residual, (rate, true, residual)
        verdicts.append(converged)
    # 0.3 exp(-1.6) = 6 % of the transient left after 800 periods: not converged; exp(-16): converged
    assert verdicts[0] is False and verdicts[2] is True
    assert not map_convergence(h + 10 * ringing, 1e-3, tol, fluct).converged   # ringing 1e-3 > fluctuation_tol
    rng = np.random.default_rng(3)
    hopping = limit * (1 + 0.05 * rng.standard_normal((p, 1)))
    assert not map_convergence(hopping, 1e-3, tol, fluct).converged
    walking = limit * (1 + 1e-4 * k)
    assert not map_convergence(walking, 1e-3, tol, fluct).converged
    assert not map_convergence(h[:3], 1e-3, tol, fluct).converged      # no block to judge


def test_a_lightly_damped_transient_is_periodic_not_unsettled():
    """The stop check's "not settled" must mean no periodic motion. The 4-blade disk with the 1 g
    cylinder at 101 Hz (blade damping ratio 1e-3: the transient from rest decays as
    exp(-zeta omega_n t), 0.6 % per period, and beats): after 600 periods the first harmonics
    still change by more than tol per period (the criterion of consecutive settled periods says
    "not settled"), but the period-to-period map converges: status "periodic", its residual
    drift stated, and the tip amplitudes (the mean of the last block) lie within that residual
    drift of the motion a 1500-period run settles on (there by the strict criterion, whose own
    remaining transient is at most tol / (1 - exp(-sigma T)) with its trend <= tol per period),
    and within 2 % of the HBM (the case the verdict must accept). With too few periods for the map to converge, "not settled" with the residual drift."""
    disk = small_disk(reference_damper("cylinder", 1e-3))
    short = disk.time_response(101.0, max_periods=600)
    long = disk.time_response(101.0, max_periods=1500)
    print(short.message[0], long.message[0], sep="\n")
    assert long.periodic[0] and long.periods[0] < 1500 and np.isnan(long.residual_drift[0])
    assert short.periods[0] == 600 and short.settling[0] > 1e-5     # the old criterion: not settled
    assert short.status[0] == "periodic" and "residual drift" in short.message[0]
    drift = short.residual_drift[0]
    assert 0 < drift <= 1e-3
    sigma_t = short.decay_rate * 2 * np.pi / short.omega[0]
    assert sigma_t == pytest.approx(1e-3 * 95.0 / 101.0 * 2 * np.pi, rel=1e-6)   # zeta omega_1 T
    a_short, a_long = short.tip_amplitude[0].max(axis=0)[0], long.tip_amplitude[0].max(axis=0)[0]
    assert abs(a_short - a_long) / a_long <= drift + 1e-5 / -np.expm1(-sigma_t)
    # and the HBM ((0, 1, 2, 3), 0.036 % from (0, ..., 5) at the peak) agrees: measured 0.06 %
    hbm = hbm_tip(disk, [101.0], (0, 1, 2, 3))[0, 0]
    assert abs(a_short - hbm) / hbm < 0.02
    early = disk.time_response(101.0, max_periods=300)
    assert early.status[0] == "not settled" and "residual drift" in early.message[0]
    assert early.residual_drift[0] > 1e-3


@pytest.mark.parametrize("call,match", [
    (lambda d: d.time_response(-1.0), "f_hz"),
    (lambda d: d.time_response(95.0, tol=0.5), "tol"),
    (lambda d: d.time_response(95.0, steps_per_period=16), "steps_per_period"),
    (lambda d: d.time_response(95.0, max_periods=5), "max_periods"),
    (lambda d: MistunedDisk.from_tuned(d, n_sector=2).time_response(95.0), "full assembly"),
    (lambda d: dataclasses.replace(d, damper_inertia=False).time_response(95.0), "damper_inertia"),
])
def test_bad_input(call, match):
    disk = small_disk(reference_damper("cylinder", 1e-3))
    with pytest.raises(ValueError, match=match):
        call(disk)


def test_result_plot_and_shapes():
    import matplotlib
    matplotlib.use("Agg")
    disk = small_disk(None, blade=dataclasses.replace(reference_blade(), damping_ratios=0.02))
    tr = disk.time_response([94.0, 96.0])
    assert isinstance(tr, DiskTimeResponse)
    assert tr.tip_amplitude.shape == (2, 4, 3) and tr.periodic.shape == (2,)
    assert np.allclose(tr.frequency_hz, [94.0, 96.0])
    assert all(s == "periodic" for s in tr.status)
    ax = tr.plot()
    assert ax.get_ylabel().startswith("tip amplitude")


# ---------------------------------------------------------------------------------------
# slow: the reference disk across 1F, HBM against time integration
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def reference_runs():
    """Time integration and HBM of the reference disk with the 1 g cylinder and the 0.3 g
    wedge at FREQUENCIES_1F (computed once for the slow tests)."""
    out = {}
    for kind, mass in (("cylinder", 1e-3), ("wedge", 3e-4)):
        disk = bd.reference_disk(kind, mass=mass)
        tr = disk.time_response(FREQUENCIES_1F)
        out[kind] = dict(disk=disk, tr=tr, h1=hbm_tip(disk, FREQUENCIES_1F, (1,)),
                         hbm=hbm_tip(disk, FREQUENCIES_1F, HBM_HARMONICS))
        for i, f in enumerate(FREQUENCIES_1F):
            td = tr.tip_amplitude[i, :, 0].mean()
            print(f"{kind} {f:6.2f} Hz: time {1e3 * td:.5f} mm, H1 {100 * (out[kind]['h1'][i, 0] / td - 1):+.2f} %, "
                  f"H{HBM_HARMONICS} {100 * (out[kind]['hbm'][i, 0] / td - 1):+.2f} %  [{tr.message[i]}]")
    return out


def _errors(run, key):
    td = run["tr"].tip_amplitude[:, :, 0].mean(axis=1)
    return run[key][:, 0] / td - 1


@pytest.mark.slow
def test_wedge_hbm_within_2_percent_of_time_integration(reference_runs):
    """0.3 g wedge, 7 frequencies across 1F: the time integration is periodic everywhere and
    the HBM with HBM_HARMONICS is within 2 % of it (measured: max 1.5 % at 95.4 Hz, the peak;
    0.03-0.8 % elsewhere)."""
    run = reference_runs["wedge"]
    assert run["tr"].periodic.all(), run["tr"].message
    err = _errors(run, "hbm")
    print("wedge HBM", HBM_HARMONICS, "errors [%]:", np.round(100 * err, 2))
    assert np.abs(err).max() < 0.02


@pytest.mark.slow
def test_wedge_one_harmonic_hbm_is_not_within_2_percent(reference_runs):
    """The earlier measurement holds: the one-harmonic HBM of the 0.3 g wedge is far from the
    time integration near the peak (measured: -16.9 % at 95.1 Hz, -16.6 % at 95.4 Hz, +13.4 % at
    96.1 Hz), while HBM_HARMONICS is within 2 % (previous test). Lift-off at the wedge's edges
    makes the contact forces strongly non-harmonic."""
    err = _errors(reference_runs["wedge"], "h1")
    print("wedge HBM (1,) errors [%]:", np.round(100 * err, 2))
    i95, i96 = list(FREQUENCIES_1F).index(95.1), list(FREQUENCIES_1F).index(96.1)
    assert abs(err[i95]) > 0.1 and abs(err[i96]) > 0.1
    assert np.abs(err).max() > 0.02


@pytest.mark.slow
def test_cylinder_hbm_against_time_integration(reference_runs):
    """1 g cylinder, 7 frequencies across 1F. Where the contacts stick (92, 94, 98 Hz) the time
    integration is periodic and the HBM is within 0.1 %. In the slip range (95.1-96.1 Hz) the
    time integration does not reach a periodic state: the cylinder rolls (phi_y grows by
    0.6-10 mrad per period, steadily) while the tip amplitude settles on average; the HBM, which
    assumes a periodic motion, is then within 2 % only at 95.1, 95.4 and 96.1 Hz (see the next
    test for 95.7 Hz)."""
    run = reference_runs["cylinder"]
    tr = run["tr"]
    err = _errors(run, "hbm")
    print("cylinder HBM", HBM_HARMONICS, "errors [%]:", np.round(100 * err, 2), "status", list(tr.status))
    stuck = np.isin(FREQUENCIES_1F, [92.0, 94.0, 98.0])
    assert tr.periodic[stuck].all()
    assert np.abs(err[stuck]).max() < 1e-3
    rolling = ~stuck
    assert all(s == "drifting" for s in tr.status[rolling])
    assert all("phi_y" in m for m in tr.message[rolling])
    for i in np.flatnonzero(rolling & ~np.isclose(FREQUENCIES_1F, 95.7)):
        assert abs(err[i]) < 0.02, (FREQUENCIES_1F[i], err[i])


@pytest.mark.slow
def test_cylinder_hbm_within_2_percent_at_every_frequency(reference_runs):
    """The issue's target for the cylinder: the default HBM within 2 % of the time integration
    at all 7 frequencies, including the four where the cylinder keeps rolling (against their
    mean tip amplitude). Met since the default harmonics go up to 7 (the cylinder's choice is
    (0, ..., 5)): measured 2026-12-01 errors 0.01 / 0.01 / -0.00 / -1.11 / -0.18 / 0.23 / -0.02 %
    (with (0, 1, 2, 3) it was +2.5 % at 95.7 Hz, then a strict xfail)."""
    err = _errors(reference_runs["cylinder"], "hbm")
    assert np.abs(err).max() < 0.02


@pytest.mark.slow
def test_time_integration_converges_in_the_step():
    """The discretisation error of the default 512 steps per period: the 4-blade wedge disk in
    gross slip at 98 Hz changes by < 0.3 % at 1024 and 2048 steps (measured 0.04 %, 0.14 %)."""
    disk = small_disk(reference_damper("wedge", 3e-4))
    a = [disk.time_response(98.0, steps_per_period=n).tip_amplitude[0, :, 0].mean() for n in (512, 1024, 2048)]
    print("tip [mm] at 512 / 1024 / 2048 steps:", np.round(1e3 * np.array(a), 6))
    assert abs(a[1] / a[0] - 1) < 3e-3 and abs(a[2] / a[0] - 1) < 3e-3


@pytest.mark.slow
def test_gross_slip_needs_more_harmonics():
    """The 4-blade wedge disk (EO = 1, 90 deg interblade phase) in gross slip at 98 Hz: (0, 1, 2, 3)
    is NOT within 2 % of the time integration (measured -5.6 %), (0, 1, ..., 7) is (measured
    +0.3 %): the harmonics the HBM needs depend on the case."""
    disk = small_disk(reference_damper("wedge", 3e-4))
    td = disk.time_response(98.0).tip_amplitude[0, :, 0].mean()
    e3 = hbm_tip(disk, 98.0, (0, 1, 2, 3))[0, 0] / td - 1
    e7 = hbm_tip(disk, 98.0, tuple(range(8)))[0, 0] / td - 1
    print(f"98 Hz: (0..3) {100 * e3:+.2f} %, (0..7) {100 * e7:+.2f} %")
    assert abs(e3) > 0.02
    assert abs(e7) < 0.01
