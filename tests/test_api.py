"""One API (issue 13, item 2): Hz at every public frequency argument, the oscillator included;
``bladedamp.frequency_response`` for every model; one set of result names; one ``plot``
signature; implausible masses and lengths warned about."""
import dataclasses
import inspect
import warnings

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.validation import PlausibilityWarning
from bladedamp.mistuned import MistunedDisk, MistunedResponse
from bladedamp.studies import design as sd
from bladedamp.studies import mass as sm
from bladedamp.studies import mistuning as mt
from bladedamp.timedomain import DiskTimeResponse, TimeResponse

F0 = 95.0                       # Hz: the reference disk's damped 1F resonance (95.3 Hz) and the oscillator's


def stiff_oscillator():
    """An oscillator whose contact never slips (mu N0 huge), tuned to F0 with the contact stuck:
    k + k_T = m (2 pi F0)^2."""
    k = (2 * np.pi * F0) ** 2
    return bd.FrictionOscillator(mass=1.0, stiffness=0.5 * k, contact_stiffness=0.5 * k, damping=20.0,
                                 normal_load=1e6, forcing=1.0)


def test_the_oscillator_and_the_disk_read_the_same_frequency_unit():
    """Both given the range 90-100 [Hz] by the same call: both peaks near 95 Hz. Read as rad/s
    (the oscillator's old unit) the oscillator's range would hold no resonance at all."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        osc = bd.frequency_response(stiff_oscillator(), (90.0, 100.0), harmonics=(1,))
        disk = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (90.0, 100.0), harmonics=(1,), max_step=0.05)
    assert osc.success and disk.success, (osc.message, disk.message)
    assert osc.frequency_hz.min() == pytest.approx(90.0) and osc.frequency_hz.max() == pytest.approx(100.0)
    assert abs(osc.peak_frequency_hz - F0) < 0.2, osc.peak_frequency_hz
    assert abs(disk.peak_frequency_hz - F0) < 1.0, disk.peak_frequency_hz
    # interior peaks, not the range's end: both resonances are inside 90-100 Hz
    assert osc.peak_amplitude > 2 * osc.harmonic_amplitude()[[0, -1]].max()
    np.testing.assert_allclose(osc.omega, 2 * np.pi * osc.frequency_hz)       # omega: the only rad/s


def test_oscillator_time_response_and_linear_amplitude_take_hz():
    osc = stiff_oscillator()
    f = np.linspace(80.0, 110.0, 301)
    assert f[np.argmax(osc.linear_amplitude(f, stuck=True))] == pytest.approx(F0, abs=0.1)
    tr = osc.time_response([F0], steps_per_period=512, min_periods=5, max_periods=60, tol=1e-3)
    np.testing.assert_allclose(tr.omega, [2 * np.pi * F0])
    np.testing.assert_allclose(tr.frequency_hz, [F0])


def test_public_frequency_arguments_are_named_in_hz():
    for method in (bd.FrictionOscillator.frequency_response, bd.TunedDisk.frequency_response,
                   MistunedDisk.frequency_response):
        assert list(inspect.signature(method).parameters)[1:3] == ["f_start_hz", "f_end_hz"], method
    for method in (bd.FrictionOscillator.time_response, bd.TunedDisk.time_response, MistunedDisk.time_response):
        assert list(inspect.signature(method).parameters)[1] == "f_hz", method
    assert list(inspect.signature(bd.FrictionOscillator.linear_amplitude).parameters)[1] == "f_hz"
    assert list(inspect.signature(bd.frequency_response).parameters)[:2] == ["model", "f_range_hz"]
    for cls in (bd.TunedDisk, MistunedDisk):             # the rotor speed: revolutions per second
        params = inspect.signature(cls).parameters
        assert "rotor_speed_hz" in params and params["rotor_speed_hz"].default is None, cls
    for method in (bd.ModalBlade.dynamic_stiffness, bd.ModalBlade.linear_frf):
        assert list(inspect.signature(method).parameters)[1] == "f_hz", method


def test_blade_frequency_arguments_in_hz_are_eq5():
    """ModalBlade.dynamic_stiffness(f_hz=) is Eq. 5 at Omega = 2 pi f; linear_frf(f_hz=) peaks at the
    1F natural frequency in Hz; f_hz is the first argument (positional or keyword); a NaN is a
    ValueError naming f_hz."""
    blade = bd.reference_blade()
    f = 100.0
    w0, w = blade.natural_angular_frequencies, 2 * np.pi * f
    np.testing.assert_allclose(blade.dynamic_stiffness(f_hz=f), w0 ** 2 - w ** 2 + 2j * blade.damping_ratios * w0 * w,
                               rtol=1e-14)
    force = np.array([0.1, 0, 0, 0, 0, 0])
    grid = np.linspace(94.0, 96.0, 2001)
    f1 = blade.natural_frequencies_hz[0]
    assert grid[np.argmax(np.abs(blade.linear_frf(f_hz=grid, force=force)[:, 0]))] == pytest.approx(f1, abs=2e-3)
    np.testing.assert_array_equal(blade.linear_frf(grid, force), blade.linear_frf(f_hz=grid, force=force))
    with pytest.raises(ValueError, match="f_hz"):
        blade.dynamic_stiffness(np.nan)


def test_frequency_response_of_anything_else_is_a_type_error_naming_it():
    with pytest.raises(TypeError, match="got bladedamp.blade.modal.ModalBlade"):
        bd.frequency_response(bd.reference_blade(), (90.0, 100.0))
    with pytest.raises(TypeError, match="got builtins.str"):
        bd.frequency_response("cylinder", (90.0, 100.0))
    with pytest.raises(ValueError, match="f_range_hz"):
        bd.frequency_response(stiff_oscillator(), 95.0)


RESPONSES = [bd.FrequencyResponse, bd.DiskResponse, MistunedResponse]
OLD_NAMES = ("peak_tip", "peak_tip_amplitude", "resonance_hz", "resonance_frequency_hz", "peak_hz",
             "tuned_peak_tip", "undamped_peak_tip", "optimal_peak_tip", "grid_peak_tip", "max_peak_tip")
RESULTS = RESPONSES + [TimeResponse, DiskTimeResponse, sm.PeakEvaluation, sm.MassSweep, sm.MassOptimum,
                       sd.EngineOrderSweep, sd.PlatformAngleStudy, sd.ContactState, sd.LiftoffMap, sd.DesignMap,
                       mt.MistuningCase, mt.MonteCarloResult, mt.Arrangement]


@pytest.mark.parametrize("cls", RESPONSES, ids=lambda c: c.__name__)
def test_every_response_names_its_peak_the_same_way(cls):
    assert isinstance(inspect.getattr_static(cls, "peak_amplitude"), property)
    assert isinstance(inspect.getattr_static(cls, "peak_frequency_hz"), property)


@pytest.mark.parametrize("cls", RESULTS, ids=lambda c: c.__name__)
def test_no_result_keeps_an_old_name(cls):
    names = {f.name for f in dataclasses.fields(cls)} | set(dir(cls))
    assert not any(old in names for old in OLD_NAMES), sorted(names & set(OLD_NAMES))


@pytest.mark.parametrize("cls", [c for c in RESULTS if hasattr(c, "plot")], ids=lambda c: c.__name__)
def test_one_plot_signature_ax_first_then_keywords(cls):
    params = list(inspect.signature(cls.plot).parameters.values())[1:]
    assert params[0].name == "ax" and params[0].default is None, cls
    assert all(p.kind in (p.KEYWORD_ONLY, p.VAR_KEYWORD) for p in params[1:]), [(p.name, p.kind) for p in params]


def test_tuned_and_mistuned_peaks_have_the_same_names_and_types():
    """Issue 34 item 2: on both disk responses ``peak_amplitude`` / ``peak_frequency_hz`` are floats
    (the largest tip amplitude u_x of any blade and its frequency) and ``blade_peak_amplitudes`` /
    ``blade_peak_frequencies_hz`` the (s,) blades' peaks ((1,) for the tuned reference sector); the
    mistuned float is the largest of its blades' parabola-refined peaks (``peaks()``), at least
    the largest sample of any blade and within 1 % of it."""
    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tuned = td.frequency_response(88.0, 104.0, harmonics=(1,), max_step=0.1)      # resonance 102.3 Hz
        ring = MistunedDisk.from_tuned(td, [1.01, 0.99, 1.02, 1.0]).frequency_response(92.0, 99.0, harmonics=(1,),
                                                                                      max_step=0.1)
    for r, s in ((tuned, 1), (ring, 4)):
        assert type(r.peak_amplitude) is float and type(r.peak_frequency_hz) is float, type(r).__name__
        assert isinstance(r.blade_peak_amplitudes, np.ndarray) and r.blade_peak_amplitudes.shape == (s,)
        assert isinstance(r.blade_peak_frequencies_hz, np.ndarray) and r.blade_peak_frequencies_hz.shape == (s,)
        assert r.peak_amplitude == r.blade_peak_amplitudes.max()
        assert r.peak_frequency_hz == r.blade_peak_frequencies_hz[np.argmax(r.blade_peak_amplitudes)]
        assert not r.peak_at_range_end and r.frequency_hz[0] < r.peak_frequency_hz < r.frequency_hz[-1]
    assert tuned.peak_amplitude == tuned.tip_amplitude[:, 0].max()
    peak, freq = ring.peaks()
    np.testing.assert_array_equal(ring.blade_peak_amplitudes, peak)
    np.testing.assert_array_equal(ring.blade_peak_frequencies_hz, freq)
    assert np.all((freq > 92.0) & (freq < 99.0))
    largest_sample = ring.tip_amplitude[:, :, 0].max()
    assert largest_sample <= ring.peak_amplitude <= 1.01 * largest_sample


# ----- plausible masses and lengths --------------------------------------------------------
def test_a_one_kilogram_damper_warns_naming_parameter_value_unit_and_range():
    with pytest.warns(PlausibilityWarning, match=r"damper mass = 1.0 kg is outside the plausible range 1e-05-0.1 kg"):
        bd.reference_disk("cylinder", mass=1.0)


@pytest.mark.parametrize("make, name", [
    (lambda: bd.CylinderDamper(1e-3, radius=2.0), "cylinder radius = 2.0 m"),
    (lambda: bd.WedgeDamper(1e-3, contact_height=2.0), "contact_height h_C = 2.0 m"),
    (lambda: bd.WedgeDamper(1e-3, length=1e-6), "damper length l_C = 1e-06 m"),
    (lambda: bd.CylinderDamper(1e-7), "damper mass = 1e-07 kg"),
    (lambda: dataclasses.replace(bd.reference_disk("cylinder", 1e-3), damper_radius=26.1), "damper_radius R = 26.1 m"),
])
def test_implausible_damper_numbers_warn(make, name):
    with pytest.warns(PlausibilityWarning, match=name.replace("(", r"\(").replace(")", r"\)")):
        make()


def test_plausible_designs_and_no_damper_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        bd.reference_disk("cylinder", 1e-3)
        bd.reference_disk("wedge", 0.28e-3)
        bd.reference_disk("cylinder", 15e-3)
        bd.CylinderDamper(0.0)                  # mass 0: no damper


def test_centrifugal_force_takes_hz():
    """damper.kinetics.centrifugal_force (Eq. 26) at f_hz [Hz]: m R (2 pi f)^2 / EO^2, and at a
    fixed rotor_speed_hz [Hz] m R (2 pi n)^2; a missing argument is a ValueError naming it."""
    from bladedamp.damper import centrifugal_force

    m, R, f = 1.3e-3, 0.05, 95.0
    for eo in (1, 3):
        F, dF = centrifugal_force(m, R, f_hz=f, engine_order=eo)
        assert F == pytest.approx(m * R * (2 * np.pi * f) ** 2 / eo ** 2, rel=1e-14)
        assert dF == pytest.approx(2 * F / (2 * np.pi * f), rel=1e-14)          # per rad/s of Omega_E
    F0, dF0 = centrifugal_force(m, R, f_hz=f, engine_order=0, rotor_speed_hz=50.0)
    assert F0 == pytest.approx(m * R * (2 * np.pi * 50.0) ** 2, rel=1e-14) and dF0 == 0.0
    for bad, name in ((lambda: centrifugal_force(m, R, f_hz=f, engine_order=0), "rotor_speed_hz"),
                      (lambda: centrifugal_force(m, R, f_hz=f), "engine_order"),
                      (lambda: centrifugal_force(m, R, engine_order=1), "f_hz"),
                      (lambda: centrifugal_force(m, R, f_hz=f, engine_order=0, rotor_speed_hz=-1.0), "rotor_speed_hz")):
        with pytest.raises(ValueError, match=name):
            bad()
