"""Derivatives on random valid designs (issue 36 item 1): ``response.sensitivities`` at three
points of the branch (a fifth in, the largest amplitude, four fifths in) of random disks from the
random-design suite's generator (``tests/test_random_designs.py``: both damper kinds, engine
orders 0-5, one harmonic and (0, 1, 2, 3), linear and power normal laws) in every key the design
has, against central differences of full solves (the key set with ``with_parameters``, the system
built anew, Newton to 1e-13 from the point's solution at the same frequency).

The step. A central difference D(h) has the truncation error h^2 a'''/6 and the rounding error
R(h) = 1e-14 a / h (two amplitudes, each solved to about 1e-14 of a: the floor 1e-8 a / p of
test_sensitivities.py at h = 1e-6 p). On these designs a''' is large where the blade frequency
moves a sharp resonance (at h = 1e-6 p the truncation reached 140 % of D at design 13's peak) and
the AFT's kinks (a contact point changing state at a sample instant) lie as close as 1e-8 of the
parameter to a point (design 6), where a difference across the kink is neither side's slope. So
the step starts at h = 1e-6 |p| and is divided by 10 until two successive differences agree,
|D(h) - D(h/10)| <= RTOL |D(h/10)| + R(h/10) (then the h^2 law bounds the truncation of D(h/10)
by |D(h) - D(h/10)| / 99, inside the tolerance, and no kink lies between h/10 and h), at most to
1e-10 |p|; the analytic derivative must then agree with D(h/10) to RTOL |D| + R(h/10), RTOL the
issue's 1e-5. A design whose branch is not complete is skipped (none of these, on this machine)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from bladedamp.hbm.newton import newton
from test_random_designs import disk_design, disk_response, make_disk

RTOL = 1e-5
FIRST_STEP = 1e-6
SMALLEST_STEP = 1e-10
SOLVE_ACCURACY = 1e-14

#: random disks of the suite: 0 cylinder EO 5 (1,); 12 cylinder EO 4 (1,) power law, Table 1
#: excitation; 13 wedge EO 1 (1,); 28 wedge EO 3 (1,) power law; 5 cylinder EO 0 (0, 1, 2, 3)
#: power law (a fixed rotor speed); 33 wedge EO 2 (0, 1, 2, 3) power law (its geometry keys)
DESIGNS = (0, 12, 13, 28, 5, 33)


def keys_of(d: dict, harmonics) -> list[str]:
    """Every key random design ``d`` can be differentiated in (a wedge's geometry with the static harmonic)."""
    keys = ["damper.mass_g", "damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2",
            "damper.normal_to_tangential_stiffness", "disk.damper_radius_mm", "disk.excitation_n_nm[0]",
            "blade.natural_frequencies_hz[0]", "blade.damping_ratio"]
    if d["roughness_exponent"] != 1.0:
        keys.append("damper.roughness_reference_load_n")
    if d["engine_order"] == 0:
        keys.append("disk.rotor_speed_rpm")
    if d["damper"] == "cylinder" or 0 in harmonics:
        keys += ["disk.gamma_left_deg", "disk.gamma_right_deg", "damper.length_mm",
                 "damper.cylinder_radius_mm" if d["damper"] == "cylinder" else "damper.contact_height_mm"]
    return keys


def central_difference(disk, response, key: str, value: float, i: int, h: float) -> float:
    """(|u(p + h)| - |u(p - h)|) / 2h of the reference blade's tip at point i of ``response``."""
    x0, w = response.coefficients[i].ravel(), float(response.omega[i])
    output = response.blade_outputs(0)[0]
    amplitudes = []
    for sign in (1, -1):
        system = disk.with_parameters({key: value + sign * h}).hbm_system(response.basis.harmonics,
                                                                         response.basis.n_samples)
        solved = newton(system.residual, x0, w, np.abs(x0).max(), 1.0, tol=1e-13, factorize=system.factorize)
        assert solved.converged, (key, i, h)
        amplitudes.append(abs(output @ solved.x))
    return (amplitudes[0] - amplitudes[1]) / (2 * h)


def converged_difference(disk, response, key: str, value: float, i: int, amplitude: float) -> tuple[float, float]:
    """(D, its rounding bound R) at the largest step whose difference agrees with the next smaller
    one's (module docstring); AssertionError where none down to SMALLEST_STEP does."""
    h = FIRST_STEP * abs(value)
    previous = central_difference(disk, response, key, value, i, h)
    while h > SMALLEST_STEP * abs(value) * 1.5:
        h /= 10
        current = central_difference(disk, response, key, value, i, h)
        rounding = SOLVE_ACCURACY * amplitude / h
        if abs(previous - current) <= RTOL * abs(current) + rounding:
            return current, rounding
        previous = current
    raise AssertionError(f"{key} at point {i}: the central differences do not settle down to a step of "
                         f"{SMALLEST_STEP:g} of the value")


@pytest.mark.parametrize("index", DESIGNS)
def test_random_design_point_derivatives_match_differences(index):
    d = disk_design(index)
    disk = make_disk(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        response = disk_response(disk, d, check_stop=False)
    if not response.status.complete:
        pytest.skip(f"random disk {index}: {response.status_message}")
    keys = keys_of(d, response.basis.harmonics)
    sens = response.sensitivities(keys)
    n = len(response.omega)
    points = sorted({n // 5, int(np.argmax(sens.tip_amplitude[:, 0])), 4 * n // 5})
    wrong = []
    for i in points:
        amplitude = sens.tip_amplitude[i, 0]
        for j, key in enumerate(keys):
            fd, rounding = converged_difference(disk, response, key, sens.values[j], i, amplitude)
            analytic = sens.d_tip_amplitude[i, j, 0]
            if abs(analytic - fd) > RTOL * abs(fd) + rounding:
                wrong.append(f"{key} at {sens.frequency_hz[i]:.6g} Hz: {analytic:.8e} against {fd:.8e}")
    assert not wrong, f"random disk {index}: " + "; ".join(wrong)
