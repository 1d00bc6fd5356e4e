"""Bad input is refused with a ValueError that names the parameter; models validate when they are
built, never inside their residuals (validation at the boundary)."""
import warnings

import numpy as np
import pytest

from bladedamp import (ContactPatch, FrictionOscillator, HarmonicBasis, LinearNormalLaw, MistunedDisk,
                       RoughnessNormalLaw, reference_disk, validation)
from bladedamp.contact.point import PointContactElement
from bladedamp.hbm.continuation import continuation

LAW = LinearNormalLaw(1e5)


def _patch(**kw):
    args = dict(height=0.004, length=0.02, tangential_stiffness=1e5, friction_coefficient=0.4, normal_law=LAW)
    args.update(kw)
    return ContactPatch(**args)


def _dummy_residual(x, omega):
    return x - 1.0, np.eye(x.size), np.zeros(x.size)


CASES = {
    # negative / zero stiffness
    "negative stiffness": (lambda: FrictionOscillator(stiffness=-1.0), "stiffness"),
    "zero contact stiffness": (lambda: FrictionOscillator(contact_stiffness=0.0), "contact_stiffness"),
    "negative normal stiffness": (lambda: FrictionOscillator(normal_stiffness=-1.0), "normal_stiffness"),
    "negative patch k_T": (lambda: _patch(tangential_stiffness=-1e5), "tangential stiffness"),
    "negative law k_N": (lambda: LinearNormalLaw(-1.0), "normal stiffness"),
    "negative point k_T": (lambda: PointContactElement(-1.0, 0.3, LAW, 1.0, 0.0), "tangential stiffness"),
    # friction coefficient
    "negative mu (oscillator)": (lambda: FrictionOscillator(friction_coefficient=-0.1), "friction_coefficient"),
    "negative mu (patch)": (lambda: _patch(friction_coefficient=-0.4), "friction coefficient"),
    "negative mu (point)": (lambda: PointContactElement(1e4, -0.3, LAW, 1.0, 0.0), "friction coefficient"),
    # other physical parameters
    "negative mass": (lambda: FrictionOscillator(mass=-1.0), "mass"),
    "negative damping": (lambda: FrictionOscillator(damping=-1.0), "damping"),
    "negative normal load": (lambda: FrictionOscillator(normal_load=-1.0), "normal_load"),
    "contact angle 90 deg": (lambda: FrictionOscillator(contact_angle=np.pi / 2), "contact_angle"),
    "roughness exponent < 1": (lambda: RoughnessNormalLaw(1e5, 10.0, 0.5), "exponent"),
    "patch weights not summing to 1": (lambda: _patch(n_xi=1, n_eta=2, weights=[0.3, 0.3]), "weights"),
    "patch n_xi = 0": (lambda: _patch(n_xi=0), "n_xi"),
    # NaN / inf
    "NaN forcing": (lambda: FrictionOscillator(forcing=np.nan), "forcing"),
    "inf mass": (lambda: FrictionOscillator(mass=np.inf), "mass"),
    "NaN normal load": (lambda: FrictionOscillator(normal_load=np.nan), "normal_load"),
    "NaN cubic stiffness": (lambda: FrictionOscillator(cubic_stiffness=np.nan), "cubic_stiffness"),
    "NaN law k_N": (lambda: LinearNormalLaw(np.nan), "normal stiffness"),
    "NaN patch height": (lambda: _patch(height=np.nan), "contact height"),
    "NaN f_start_hz": (lambda: FrictionOscillator().frequency_response(np.nan, 16.0), "f_start_hz"),
    "NaN initial guess": (lambda: continuation(_dummy_residual, np.array([np.nan]), 1.0, 2.0), "x0"),
    "NaN harmonic": (lambda: HarmonicBasis((1, np.nan)), "harmonics"),
    "NaN n_samples": (lambda: HarmonicBasis((1, 3), np.nan), "n_samples"),
    "inf n_samples": (lambda: HarmonicBasis((1, 3), np.inf), "n_samples"),
    "NaN patch n_eta": (lambda: _patch(n_eta=np.nan), "n_eta"),
    # harmonics
    "empty harmonics": (lambda: HarmonicBasis(()), "harmonics"),
    "empty harmonics (FRF)": (lambda: FrictionOscillator().frequency_response(14.0, 16.0, harmonics=()), "harmonics"),
    "negative harmonic": (lambda: HarmonicBasis((-1, 1)), "harmonics"),
    "fractional harmonic": (lambda: HarmonicBasis((1.5,)), "harmonics"),
    "only the static term": (lambda: HarmonicBasis((0,)), "harmonic"),
    # samples
    "n_samples too small": (lambda: HarmonicBasis((1, 3), 6), "n_samples"),
    "n_samples too small (FRF)": (lambda: FrictionOscillator().frequency_response(14.0, 16.0, harmonics=(1, 3),
                                                                                   n_samples=5), "n_samples"),
    "steps_per_period too small": (lambda: FrictionOscillator().time_response([16.0], steps_per_period=8),
                                   "steps_per_period"),
    "steps_per_period unstable": (lambda: FrictionOscillator().time_response([0.16], steps_per_period=16),
                                  "steps_per_period"),
    # frequency ranges
    "f_start_hz == f_end_hz (FRF)": (lambda: FrictionOscillator().frequency_response(16.0, 16.0), "f_end_hz"),
    "omega_start == omega_end (continuation)": (lambda: continuation(_dummy_residual, np.zeros(1), 5.0, 5.0),
                                                "omega_end"),
    "negative f_start_hz": (lambda: FrictionOscillator().frequency_response(-16.0, 16.0), "f_start_hz"),
    "negative frequency (time response)": (lambda: FrictionOscillator().time_response([-16.0]), "f_hz"),
    "time response from a NaN start": (lambda: FrictionOscillator().time_response([16.0], initial_displacement=np.nan),
                                       "initial_displacement"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_raises_value_error_naming_the_parameter(case):
    make, name = CASES[case]
    with pytest.raises(ValueError, match=name):
        make()


def _models_and_points():
    """(name, system, x, omega [rad/s]) of the three model kinds, each built (and its start point
    computed) before any residual is evaluated."""
    disk = reference_disk("cylinder", 1e-3)
    omega = 2 * np.pi * 95.0
    tuned = disk.hbm_system((0, 1, 2, 3))
    kappa = 1.0 + 0.03 * np.random.default_rng(7).standard_normal(4)
    ring = MistunedDisk.from_tuned(disk, kappa, n_sector=4)
    mistuned = ring.hbm_system((0, 1, 2, 3))
    oscillator = FrictionOscillator().hbm_system((1, 3))
    x_osc = 0.1 * np.random.default_rng(8).standard_normal(oscillator.n_unknowns)
    return [("tuned disk", tuned, disk.initial_guess(tuned, omega), omega),
            ("mistuned disk", mistuned, ring.initial_guess(mistuned, omega), omega),
            ("friction oscillator", oscillator, x_osc, 1.0)]


def _count_validation_calls(monkeypatch) -> list:
    """The list to which every call of a public function of bladedamp.validation appends its name."""
    calls = []
    for name in dir(validation):
        f = getattr(validation, name)
        if (not name.startswith("_") and callable(f) and not isinstance(f, type)
                and getattr(f, "__module__", None) == validation.__name__):
            def counted(*args, _f=f, _name=name, **kwargs):
                calls.append(_name)
                return _f(*args, **kwargs)
            monkeypatch.setattr(validation, name, counted)
    validation.positive("the counter itself", 1.0)
    assert calls == ["positive"]
    calls.clear()
    return calls


def test_residuals_do_not_validate(monkeypatch):
    """Validation at the boundary (issue 34 item 6): a model's inputs are checked when it is built,
    so evaluating its residual, with or without the Jacobian, calls no function of
    bladedamp.validation."""
    cases = _models_and_points()
    calls = _count_validation_calls(monkeypatch)
    for name, system, x, omega in cases:
        for jacobian in (True, False):
            calls.clear()
            system.residual(x, omega, jacobian=jacobian)
            assert calls == [], f"{name} residual (jacobian={jacobian}) validated: {calls}"


def test_continuation_points_do_not_validate(monkeypatch):
    """The continuation's per-point code (predictor, corrector, step control, the model's point
    callbacks) validates nothing: a sweep's validation calls (its options and start, once) do not
    grow with its number of points."""
    oscillator = FrictionOscillator()
    calls = _count_validation_calls(monkeypatch)
    counts, points = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for max_step in (0.05, 0.01):
            calls.clear()
            response = oscillator.frequency_response(0.5, 1.5, harmonics=(1, 3), max_step=max_step)
            points.append(response.frequency_hz.size)
            counts.append(len(calls))
    assert points[1] > 3 * points[0]
    assert counts[0] == counts[1], f"validation calls {counts} for {points} points"
