"""Trivial inputs give trivial answers (zero excitation: rest; a vanishing damper: the disk
without one) and every run ends (a budget for every analysis; a range without a bounded
response, or a contact stiffness that is no contact, is refused before any solve)."""
from __future__ import annotations

import dataclasses
import re
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import bladedamp.hbm.continuation as continuation_module
from bladedamp import FrictionOscillator
from bladedamp.cli import main
from bladedamp.damper.geometry import (CONTACT_STIFFNESS_PER_LENGTH_RANGE, MIN_DAMPER_MASS, ContactProperties,
                                       CylinderDamper, WedgeDamper)
from bladedamp.hbm.continuation import DEFAULT_CPU_BUDGET_S, Budget
from bladedamp.mistuned import MistunedDisk
from bladedamp.reference import reference_blade, reference_disk
from bladedamp.response import Status

F_RANGE = (90.0, 105.0)


def quiet(f, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*args, **kw)


# ---------------------------------------------------------------------------------------
# a budget for every analysis
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def oscillator_frf():
    osc = FrictionOscillator()
    full = quiet(osc.frequency_response, 10.0, 30.0, harmonics=(1,))
    assert full.success and not full.stopped_by, full.message
    return osc, full


def test_a_point_budget_stops_the_oscillator_keeping_its_points(oscillator_frf):
    osc, full = oscillator_frf
    n = len(full.omega) // 3
    r = quiet(osc.frequency_response, 10.0, 30.0, harmonics=(1,), point_budget=n)
    assert not r.success and len(r.omega) == n
    assert r.stopped_by == f"budget: {n} continuation points ran out at {r.frequency_hz[-1]:.6g} Hz"
    assert r.stopped_by in r.message and r.status is Status.OUT_OF_BUDGET
    # the points kept are those of the run without a budget
    np.testing.assert_allclose(r.coefficients, full.coefficients[:n], rtol=0,
                               atol=1e-12 * np.abs(full.coefficients).max())


def test_a_cpu_budget_stops_the_oscillator_keeping_its_points(oscillator_frf, monkeypatch):
    """A clock that advances 1 s at every reading: the budget of 30 s runs out after about 30
    points (one reading per point kept, a few more before the first)."""
    osc, full = oscillator_frf
    clock = iter(np.arange(1e6))
    monkeypatch.setattr(continuation_module.time, "process_time", lambda: float(next(clock)))
    r = quiet(osc.frequency_response, 10.0, 30.0, harmonics=(1,), cpu_budget_s=30.0)
    monkeypatch.undo()
    assert not r.success and 10 < len(r.omega) <= 30 < len(full.omega)
    assert r.stopped_by == f"budget: 30 CPU s ran out at {r.frequency_hz[-1]:.6g} Hz"
    assert r.stopped_by in r.message and r.status is Status.OUT_OF_BUDGET
    n = len(r.omega)
    np.testing.assert_allclose(r.coefficients, full.coefficients[:n], rtol=0,
                               atol=1e-12 * np.abs(full.coefficients).max())


def test_a_budget_spent_before_the_branch_starts_keeps_no_point_and_says_so():
    r = quiet(FrictionOscillator().frequency_response, 10.0, 30.0, harmonics=(1,), cpu_budget_s=1e-12)
    assert not r.success and len(r.omega) == 0
    assert r.stopped_by == "budget: 1e-12 CPU s ran out at 10 Hz" and r.stopped_by in r.message
    assert r.status is Status.OUT_OF_BUDGET


@pytest.mark.parametrize("cpu, points, name", [(0.0, 10, "cpu_budget_s"), (np.nan, 10, "cpu_budget_s"),
                                               (1.0, 0, "point_budget"), (1.0, 2.5, "point_budget")])
def test_budgets_are_validated(cpu, points, name):
    with pytest.raises(ValueError, match=name):
        Budget(cpu, points)


def test_a_point_budget_stops_the_tuned_disk_keeping_its_points():
    disk = reference_disk("cylinder", 1e-3)
    full = quiet(disk.frequency_response, *F_RANGE, harmonics=(1,), estimate_harmonic_error=False)
    assert full.success
    r = quiet(disk.frequency_response, *F_RANGE, harmonics=(1,), estimate_harmonic_error=False, point_budget=25)
    assert not r.success and len(r.omega) == 25
    assert r.stopped_by == f"budget: 25 continuation points ran out at {r.frequency_hz[-1]:.6g} Hz"
    assert r.stopped_by in r.message and r.status is Status.OUT_OF_BUDGET
    np.testing.assert_allclose(r.tip_amplitude, full.tip_amplitude[:25], rtol=1e-10)


def test_a_point_budget_stops_the_mistuned_disk_keeping_its_points():
    tuned = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    disk = MistunedDisk.from_tuned(tuned, kappa=[0.98, 1.0, 1.01, 1.03])
    r = quiet(disk.frequency_response, *F_RANGE, harmonics=(1,), estimate_harmonic_error=False, point_budget=8)
    assert not r.success and len(r.omega) == 8
    assert r.stopped_by == f"budget: 8 continuation points ran out at {r.frequency_hz[-1]:.6g} Hz"
    assert r.status is Status.OUT_OF_BUDGET
    assert np.all(np.diff(r.omega) > 0) and np.all(np.isfinite(r.tip_amplitude))


def test_the_default_budget_is_not_met_by_the_reference_disk_in_the_papers_setting():
    """The default CPU budget is a guard against runs without end: the reference cylinder's
    one-harmonic FRF uses a small fraction of it and reaches the end."""
    disk = reference_disk("cylinder", 1e-3)
    budget = Budget()
    r = quiet(disk.frequency_response, *F_RANGE, harmonics=(1,))
    assert r.success and not r.stopped_by, r.message
    assert budget.cpu_used() < DEFAULT_CPU_BUDGET_S / 10


# ---------------------------------------------------------------------------------------
# zero excitation: rest
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge", None])
def test_a_disk_without_excitation_is_at_rest(kind):
    """The answer is zero; the zero state solves the disk's first-harmonic residual to the
    rounding of its contact forces (the preload, a few N)."""
    disk = reference_disk(kind, 1e-3, excitation=np.zeros(6))
    r = quiet(disk.frequency_response, *F_RANGE)
    assert r.success and r.harmonics_converged and r.harmonic_error == 0.0, r.message
    assert r.status is Status.COMPLETE_VERIFIED and not r.peak_at_range_end     # at rest: no resonance to miss
    assert r.frequency_hz[0] == F_RANGE[0] and r.frequency_hz[-1] == F_RANGE[1]
    assert np.all(r.tip_amplitude == 0.0) and np.all(r.coefficients == 0.0)
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples)
    preload = max(disk.static_normal_loads(F_RANGE[1]).max(), 1.0)
    for x, w in zip(r.coefficients[::10], r.omega[::10]):
        assert np.linalg.norm(system.residual(x.ravel(), w)[0]) < 1e-12 * preload


def test_a_mistuned_disk_without_excitation_is_at_rest():
    tuned = dataclasses.replace(reference_disk("cylinder", 1e-3, excitation=np.zeros(6)), n_blades=4)
    disk = MistunedDisk.from_tuned(tuned, kappa=[0.98, 1.0, 1.01, 1.03])
    r = quiet(disk.frequency_response, *F_RANGE)
    assert r.success and np.all(r.tip_amplitude == 0.0), r.message
    assert r.status is Status.COMPLETE_VERIFIED and not r.peak_at_range_end
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples)
    x, w = r.coefficients[len(r.omega) // 2].ravel(), r.omega[len(r.omega) // 2]
    assert np.linalg.norm(system.residual(x, w)[0]) < 1e-12 * max(tuned.static_normal_loads(F_RANGE[1]).max(), 1.0)


def test_an_oscillator_without_forcing_is_at_rest():
    r = quiet(FrictionOscillator(forcing=0.0).frequency_response, 10.0, 30.0)
    assert r.success and np.all(r.coefficients == 0.0), r.message
    assert r.status.complete and not r.peak_at_range_end


# ---------------------------------------------------------------------------------------
# a vanishing damper: the disk without one
# ---------------------------------------------------------------------------------------
def damper_free_peak(disk) -> float:
    """Largest first-harmonic tip amplitude u_x [m] near 1F of the blade without damper, from
    its modal closed form sum_j phi_tip,j phi_exc,j^T F / (omega_j^2 - Omega^2 + 2 i D_j omega_j Omega)."""
    blade = disk.blade
    w0 = blade.natural_angular_frequencies
    force = blade.shape("excitation").T @ disk.excitation
    tip = blade.shape("tip")[0]

    def minus_amplitude(f_hz):
        w = 2 * np.pi * f_hz
        return -abs(np.sum(tip * force / (w0 ** 2 - w ** 2 + 2j * blade.damping_ratios * w0 * w)))

    found = minimize_scalar(minus_amplitude, bounds=(94.0, 96.0), method="bounded", options={"xatol": 1e-9})
    return -found.fun


def test_the_lightest_damper_gives_the_damper_free_limit():
    """The damper's effect vanishes with its mass (its preload m R Omega^2 and its inertia are
    both proportional to it): the peak's deficit from the damper-free closed form shrinks in
    proportion to the mass, by 10 from 1e-6 to 1e-7 kg (within 1 %: the second order in the mass
    is of the relative size of the deficit itself, 1e-3), and at MIN_DAMPER_MASS it is below
    2e-4 of the peak (the bound MIN_DAMPER_MASS is chosen by)."""
    free = damper_free_peak(reference_disk(None))
    deficits = []
    for mass in (10 * MIN_DAMPER_MASS, MIN_DAMPER_MASS):
        disk = quiet(reference_disk, "cylinder", mass)          # below the plausible range: a warning
        r = quiet(disk.frequency_response, *F_RANGE, harmonics=(1,), estimate_harmonic_error=False)
        assert r.success, r.message
        solved = disk.solve_peak(r)
        assert solved is not None
        deficits.append(1 - solved[0] / free)
    assert 0 < deficits[1] < 2e-4
    assert 10 / 1.01 < deficits[0] / deficits[1] < 10 * 1.01
    # the wedge, with the static harmonic that lets its mean position follow the platforms
    # (MIN_DAMPER_MASS's bound for the wedge: 0.1 %)
    disk = quiet(reference_disk, "wedge", MIN_DAMPER_MASS)
    r = quiet(disk.frequency_response, *F_RANGE, harmonics=(0, 1), estimate_harmonic_error=False)
    assert r.success, r.message
    assert 0 < 1 - disk.solve_peak(r)[0] / free < 1e-3


@pytest.mark.parametrize("make", [lambda m: CylinderDamper(m), lambda m: WedgeDamper(m, 2e-3),
                                  lambda m: reference_disk("cylinder", m)])
@pytest.mark.parametrize("mass", [1e-303, 1e-9, 0.5 * MIN_DAMPER_MASS])
def test_a_damper_lighter_than_the_minimum_is_refused(make, mass):
    with pytest.raises(ValueError, match=r"damper mass must be 0 \(no damper\) or in \[1e-07, inf\) kg"):
        make(mass)


def test_a_zero_mass_is_the_disk_without_damper():
    assert not reference_disk("cylinder", 0.0).has_damper
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # below the plausible range: a warning, not an error
        assert reference_disk("cylinder", MIN_DAMPER_MASS).has_damper


@pytest.mark.parametrize("text, needles", [
    ("[damper]\nmass_g = 1e-300\n", ("[damper] mass_g = 1e-300", "0.0001, 1000] g")),
    ("[damper]\ntangential_stiffness_per_length_n_per_m2 = 1e-6\n", ("[damper]", "plausible range")),
])
def test_the_cli_refuses_a_vanishing_damper_and_a_non_contact(tmp_path, capsys, text, needles):
    path = tmp_path / "design.toml"
    path.write_text(text)
    assert main(["frf", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err and not re.search(r"\bnan\b", err), err
    for needle in (str(path),) + needles:
        assert needle in lines[0], (needle, lines[0])
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------------------
# no bounded response, no contact: refused before any solve
# ---------------------------------------------------------------------------------------
def test_the_undamped_oscillator_above_the_friction_limit_is_refused():
    osc = FrictionOscillator(damping=0.0)
    assert osc.forcing > 4 * osc.friction_coefficient * osc.normal_load / np.pi
    with pytest.raises(ValueError, match=r"damping = 0 .* forcing \|F\| = 1 N exceeds the friction limit "
                                         r"4 mu N0 / pi = 0.381972 N .* 15.9155 Hz"):
        osc.frequency_response(10.0, 30.0)
    # bounded: with viscous damping, below the limit, or a range without the natural frequency
    FrictionOscillator(damping=1e-3).check_bounded(10.0, 30.0)
    FrictionOscillator(damping=0.0, forcing=0.99 * 4 * 0.3 / np.pi).check_bounded(10.0, 30.0)
    FrictionOscillator(damping=0.0).check_bounded(17.0, 30.0)


def test_the_undamped_oscillator_above_the_friction_limit_grows_without_bound_in_time():
    """Independent: the time integration at the natural frequency from rest never settles and
    its amplitude grows; below the friction limit it stays bounded by the stuck and free
    linear responses' scale."""
    osc = FrictionOscillator(damping=0.0)
    f_n = osc.linear_natural_frequencies_hz()[0]
    short = osc.time_response(f_n, max_periods=100, min_periods=100)
    long = osc.time_response(f_n, max_periods=400, min_periods=400)
    assert not long.converged[0]
    # energy input pi F X per cycle against at most 4 mu N X dissipated: X grows linearly in time
    assert long.max_displacement[0] > 3 * short.max_displacement[0]


def test_an_undamped_disk_mode_no_damper_touches_is_refused():
    blade = dataclasses.replace(reference_blade(), damping_ratios=np.zeros(4))
    disk = dataclasses.replace(reference_disk(None), blade=blade)
    with pytest.raises(ValueError, match=r"blade mode 1F has damping_ratios = 0.* 95 Hz inside the range"):
        disk.frequency_response(*F_RANGE)
    disk.check_bounded(100.0, 105.0)                           # no natural frequency inside: bounded
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(100.0, 105.0, harmonics=(1,))
    # independent: the undamped modal closed form at 100 Hz
    w0 = blade.natural_angular_frequencies
    w = 2 * np.pi * 100.0
    closed = abs(np.sum(blade.shape("tip")[0] * (blade.shape("excitation").T @ disk.excitation) / (w0 ** 2 - w ** 2)))
    assert r.success and r.tip_amplitude[0, 0] == pytest.approx(closed, rel=1e-9)


def test_an_undamped_mistuned_disk_without_dampers_is_refused():
    blade = dataclasses.replace(reference_blade(), damping_ratios=np.zeros(4))
    tuned = dataclasses.replace(reference_disk(None), blade=blade, n_blades=4)
    disk = MistunedDisk.from_tuned(tuned, kappa=[0.98, 1.0, 1.01, 1.03])
    with pytest.raises(ValueError, match=r"blade mode 1F has damping_ratios = 0"):
        disk.frequency_response(*F_RANGE)


def test_a_contact_stiffness_that_is_no_contact_is_refused_with_the_plausible_range():
    low, high = CONTACT_STIFFNESS_PER_LENGTH_RANGE
    with pytest.raises(ValueError, match=r"normal_to_tangential_stiffness x tangential_stiffness_per_length .* "
                                         r"plausible range \[100000, 1e\+13\]"):
        ContactProperties(tangential_stiffness_per_length=1e-6)
    with pytest.raises(ValueError, match="tangential_stiffness_per_length must be in"):
        ContactProperties(tangential_stiffness_per_length=10 * high)
    # the frictionless limit k_T -> 0 with the normal springs kept is a contact
    ContactProperties(tangential_stiffness_per_length=1e-5, normal_to_tangential_stiffness=2e12)
    ContactProperties(tangential_stiffness_per_length=low, normal_to_tangential_stiffness=1.0)


def test_the_cli_names_a_response_without_points_and_prints_no_nan(tmp_path, capsys, monkeypatch):
    """A response that kept no point (here: its budget spent before the first) has no peak: the
    command says so, and no number it prints is nan."""
    from bladedamp.disk import TunedDisk

    computed = TunedDisk.frequency_response

    def spent(self, *args, **options):
        return computed(self, *args, **{**options, "cpu_budget_s": 1e-12})

    monkeypatch.setattr(TunedDisk, "frequency_response", spent)
    path = tmp_path / "design.toml"
    path.write_text("[analysis]\nfrequency_range_hz = [92.0, 99.0]\nharmonics = [1]\n")
    assert main(["frf", str(path), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "EO1 no peak: no point computed" in err and "out of budget" in err
    assert not re.search(r"\bnan\b", err), err
