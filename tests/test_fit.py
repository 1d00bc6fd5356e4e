"""Contact parameters identified from measured responses (issue 36 item 4): synthetic
measurements of a known design at three excitation levels with 2 % noise recover the friction
coefficient and the tangential stiffness within 3 %, with intervals that cover the truth; a
parameter the data do not identify is reported as such."""
import numpy as np
import pytest

import bladedamp as bd
from bladedamp.fit import fit_contact, model_points
from bladedamp.measurement import MeasuredResponse

KEYS = ("damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2")
FORCES = [0.05, 0.1, 0.2]


@pytest.fixture(scope="module")
def synthetic():
    truth = bd.reference_disk("cylinder", 1e-3)
    rng = np.random.default_rng(1)
    f = np.linspace(92.0, 99.0, 30)
    measured = []
    for force in FORCES:
        u, _ = model_points(truth.with_parameters({"disk.excitation_n_nm[0]": force}), f, KEYS, (1,), None, 0.05)
        measured.append(MeasuredResponse(f, np.abs(u) * (1 + 0.02 * rng.standard_normal(len(f))), "m"))
    return truth, measured


def test_with_parameters_sets_the_design_keys():
    disk = bd.reference_disk("cylinder", 1e-3)
    changed = disk.with_parameters({"damper.mass_g": 2.5, "damper.friction_coefficient": 0.4, "disk.damper_radius_mm": 30.0,
                                    "blade.natural_frequencies_hz[1]": 300.0, "disk.excitation_n_nm[0]": 0.2})
    assert changed.damper.mass == pytest.approx(2.5e-3) and changed.damper.contact.friction_coefficient == 0.4
    assert changed.damper_radius == pytest.approx(0.03) and changed.blade.natural_frequencies_hz[1] == 300.0
    assert changed.excitation[0] == 0.2 and disk.damper.mass == 1e-3          # the original is left as it is
    for key in ("damper.mass_g", "damper.friction_coefficient", "disk.damper_radius_mm"):
        assert changed.parameter_value(key) == pytest.approx({"damper.mass_g": 2.5, "damper.friction_coefficient": 0.4,
                                                             "disk.damper_radius_mm": 30.0}[key])


def test_fit_recovers_friction_and_stiffness_with_covering_intervals(synthetic):
    truth, measured = synthetic
    start = truth.with_parameters({KEYS[0]: 0.22, KEYS[1]: 2.3e7})
    fit = fit_contact(start, measured, KEYS, excitations=FORCES)
    assert fit.success and fit.identified.all()
    for j, key in enumerate(KEYS):
        true = truth.parameter_value(key)
        assert abs(fit[key] / true - 1) <= 0.03, key
        assert fit.interval[j, 0] <= true <= fit.interval[j, 1], key
    # the residual is the noise: 2 % relative, its rms within a quarter of that (90 points)
    assert 0.015 <= fit.residual_rms <= 0.025
    assert "damper.friction_coefficient" in fit.table()


def test_a_parameter_without_effect_is_not_identified(synthetic):
    """The power law's reference load does nothing with the linear normal law: the data cannot
    tell it, and the fit says so instead of returning a confident number. Its Jacobian column is
    zero at the start, so it is held there and the others are fitted alone: the fit converges with
    at most the evaluations of the same fit without it (the same least squares; 5 here, 18 when
    the zero direction was searched too), to the same estimates."""
    truth, measured = synthetic
    alone = fit_contact(truth, measured[:1], KEYS, excitations=FORCES[:1])
    assert alone.success and alone.identified.all()
    keys = KEYS + ("damper.roughness_reference_load_n",)
    fit = fit_contact(truth, measured[:1], keys, excitations=FORCES[:1])
    assert fit.success and fit.n_responses <= alone.n_responses
    assert list(fit.identified) == [True, True, False]
    assert fit.estimate[2] == truth.parameter_value(keys[2])                  # held at its start
    np.testing.assert_allclose(fit.estimate[:2], alone.estimate, rtol=1e-9)
    np.testing.assert_allclose(fit.interval[:2], alone.interval, rtol=1e-9)
    assert np.isinf(fit.interval[2]).all() and np.isinf(fit.standard_error[2])
    assert np.isnan(fit.correlation[2, :2]).all()
    assert "not identified" in fit.message and "held at its start value" in fit.message
    assert "not identified" in fit.table()


def test_fit_arguments_are_checked(synthetic):
    truth, measured = synthetic
    with pytest.raises(ValueError, match="one excitation per measurement"):
        fit_contact(truth, measured, KEYS, excitations=[0.1])
    with pytest.raises(ValueError, match="confidence"):
        fit_contact(truth, measured, KEYS, confidence=1.5)
    with pytest.raises(ValueError, match="n_blades"):
        fit_contact(truth, measured, ("disk.n_blades",))
