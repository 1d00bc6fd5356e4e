"""Derivatives of responses and peaks in design parameters (issue 36 item 1) against central
differences of full solves (every parameter perturbed in the model itself, the system built
anew, Newton to 1e-13 from the unperturbed solution) and against closed forms.

Tolerance: relative 1e-5 (the issue's). With a step of 1e-6 of the parameter the differences'
truncation is O(1e-12) and their rounding about the Newton tolerance over the step (1e-13 / 1e-6
= 1e-7); the analytic derivatives agree to 1e-7 or better where the response is smooth."""
import dataclasses

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.diskmodel import parse_parameter_key
from bladedamp.hbm.newton import newton
from bladedamp.hbm.peaks import PeakSolver
from bladedamp.hbm.sensitivity import PEAK_KINK_SPACING, peak_sensitivities
from bladedamp.hbm.system import linear_forces
from bladedamp.mistuned import MistunedDisk

RTOL = 1e-5
STEP = 1e-6


def perturbed(disk, key, h):
    """``disk`` with the design-file ``key`` moved by h (in the key's unit), built anew."""
    name, index = parse_parameter_key(key)
    contact = disk.damper.contact if disk.damper is not None else None
    fields = {"damper.friction_coefficient": "friction_coefficient",
              "damper.tangential_stiffness_per_length_n_per_m2": "tangential_stiffness_per_length",
              "damper.normal_to_tangential_stiffness": "normal_to_tangential_stiffness",
              "damper.roughness_reference_load_n": "roughness_reference_load"}
    if name in fields:
        value = getattr(contact, fields[name]) + h
        damper = dataclasses.replace(disk.damper, contact=dataclasses.replace(contact, **{fields[name]: value}))
        return dataclasses.replace(disk, damper=damper)
    if name == "damper.mass_g":
        return dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, mass=disk.damper.mass + 1e-3 * h))
    if name == "disk.damper_radius_mm":
        return dataclasses.replace(disk, damper_radius=disk.damper_radius + 1e-3 * h)
    if name == "disk.rotor_speed_rpm":
        return dataclasses.replace(disk, rotor_speed_hz=disk.rotor_speed_hz + h / 60)
    if name == "disk.excitation_n_nm":
        e = disk.excitation.copy()
        e[index] += h
        return dataclasses.replace(disk, excitation=e)
    if name == "blade.natural_frequencies_hz":
        f = disk.blade.natural_frequencies_hz.copy()
        f[index] += h
        return dataclasses.replace(disk, blade=disk.blade.with_frequencies(f))
    if name == "blade.damping_ratio":
        z = disk.blade.damping_ratios.copy()
        z[slice(None) if index is None else index] += h
        return dataclasses.replace(disk, blade=dataclasses.replace(disk.blade, damping_ratios=z))
    raise AssertionError(key)


def central_difference(build, key, value, response, i):
    """d|u_blade|/dp at point i of ``response`` by central differences of Newton solves of the
    models ``build(key, +-h)``."""
    h = STEP * abs(value)
    x0, w = response.coefficients[i].ravel(), float(response.omega[i])
    outputs = response.blade_outputs(0)
    amplitudes = []
    for sign in (1, -1):
        system = build(key, sign * h).hbm_system(response.basis.harmonics, response.basis.n_samples)
        solved = newton(system.residual, x0, w, np.abs(x0).max(), 1.0, tol=1e-13, factorize=system.factorize)
        assert solved.converged
        amplitudes.append(np.abs(outputs @ solved.x))
    return (amplitudes[0] - amplitudes[1]) / (2 * h)


def check_points(response, build, keys, points):
    sens = response.sensitivities(keys)
    for i in points:
        for j, key in enumerate(keys):
            fd = central_difference(build, key, sens.values[j], response, i)
            scale = np.abs(fd).max()
            assert scale > 0, key
            assert np.abs(sens.d_tip_amplitude[i, j] - fd).max() <= RTOL * scale, (key, i, sens.d_tip_amplitude[i, j], fd)


@pytest.fixture(scope="module")
def reference_static():
    disk = bd.reference_disk("cylinder", 1e-3)
    return disk, disk.frequency_response(93.0, 97.0, harmonics=(0, 1, 2, 3), n_samples=64,
                                         estimate_harmonic_error=False)


def test_linear_forces_is_the_dynamic_stiffness_times_x():
    disk = bd.reference_disk("cylinder", 1e-3)
    system = disk.hbm_system((0, 1, 2), 32)
    x = np.random.default_rng(0).normal(size=system.n_unknowns)
    A, _ = system.dynamic_stiffness(600.0)
    expected = A @ x
    got = linear_forces(system.basis, x, 600.0, system.mass, system.damping, system.stiffness, system.static_stiffness)
    assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max()


def test_tuned_point_derivatives_with_static_harmonic_match_differences(reference_static):
    disk, response = reference_static
    keys = ["damper.mass_g", "damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2",
            "damper.normal_to_tangential_stiffness", "disk.damper_radius_mm", "disk.excitation_n_nm[0]",
            "blade.natural_frequencies_hz[0]", "blade.damping_ratio"]
    n = len(response.omega)
    check_points(response, lambda k, h: perturbed(disk, k, h), keys, [n // 4, n // 2])


def test_one_harmonic_power_law_wedge_derivatives_match_differences():
    """Without a static harmonic the preload enters through the seating's approach (the
    'approach' direction), with the power law through its scale and exponent."""
    disk = bd.reference_disk("wedge", 2e-3)
    contact = dataclasses.replace(disk.damper.contact, roughness_exponent=1.5)
    disk = dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact=contact))
    response = disk.frequency_response(92.0, 100.0, harmonics=(1,), n_samples=64, estimate_harmonic_error=False)
    keys = ["damper.mass_g", "damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2",
            "damper.normal_to_tangential_stiffness", "damper.roughness_reference_load_n", "disk.damper_radius_mm"]
    n = len(response.omega)
    check_points(response, lambda k, h: perturbed(disk, k, h), keys, [n // 3, n // 2])


def test_mistuned_point_derivatives_match_differences():
    tuned = dataclasses.replace(bd.reference_disk("cylinder", 0.3e-3), n_blades=4)
    kappa = np.array([1.0, 1.01, 0.99, 1.02])
    disk = MistunedDisk.from_tuned(tuned, kappa)
    response = disk.frequency_response(92.0, 99.0, harmonics=(0, 1, 2), n_samples=32, estimate_harmonic_error=False)

    def build(key, h):
        if key.startswith("mistuning.kappa"):
            k = kappa.copy()
            k[parse_parameter_key(key)[1]] += h
            return MistunedDisk.from_tuned(tuned, k)
        return MistunedDisk.from_tuned(perturbed(tuned, key, h), kappa)

    keys = ["damper.mass_g", "damper.friction_coefficient", "mistuning.kappa[2]", "blade.natural_frequencies_hz[0]",
            "blade.damping_ratio[0]", "disk.excitation_n_nm[0]"]
    check_points(response, build, keys, [len(response.omega) // 2])


def precise_peak(model, response, x, w):
    """(peak |u|, Omega*) of ``model`` by bisection on the sign of the slope d|u|/dOmega (each a
    Newton solve to 1e-14) to 1e-15 of Omega: the peak of the full solve, kink or not."""
    system = model.hbm_system(response.basis.harmonics, response.basis.n_samples)
    output = response.blade_outputs(0)[0]

    def at(omega, start):
        r = newton(system.residual, start, omega, np.abs(start).max(), 1.0, tol=1e-14, factorize=system.factorize)
        assert r.converged
        u, du = output @ r.x, output @ -r.solve(r.dR_domega)
        return r.x, float(np.real(np.conj(u) * du)) / abs(u), abs(u)

    low, high = w * (1 - 1e-5), w * (1 + 1e-5)
    x_low, g_low, _ = at(low, x)
    _, g_high, _ = at(high, x)
    assert g_low > 0 > g_high
    while high - low > 1e-15 * w:
        middle = 0.5 * (low + high)
        x_mid, g_mid, _ = at(middle, x_low)
        if g_mid > 0:
            low, x_low = middle, x_mid
        else:
            high = middle
    return at(low, x_low)[2], 0.5 * (low + high)


def test_peak_derivatives_on_a_kink_match_differences_of_full_solves():
    """The reference 1 g cylinder's peak (one harmonic) sits on a kink of the sampled friction
    (the slope jumps from +2e-6 to -5.6e-6 within 1e-11 of Omega*): the envelope theorem alone is
    wrong there, the two-sided formula of hbm.sensitivity is exact to first order."""
    disk = bd.reference_disk("cylinder", 1e-3)
    response = disk.frequency_response(90.0, 100.0, harmonics=(1,), n_samples=64, estimate_harmonic_error=False)
    keys = ["damper.mass_g", "damper.friction_coefficient", "disk.excitation_n_nm[0]"]
    peak = response.peak_sensitivities(keys)
    X = response.coefficients.reshape(len(response.omega), -1)
    i = int(np.argmax(response.tip_amplitude[:, 0]))
    for key, value in zip(keys, peak.values):
        h = STEP * abs(value)
        plus = precise_peak(perturbed(disk, key, h), response, X[i], response.omega[i])
        minus = precise_peak(perturbed(disk, key, -h), response, X[i], response.omega[i])
        d_amplitude = (plus[0] - minus[0]) / (2 * h)
        d_frequency = (plus[1] - minus[1]) / (2 * h) / (2 * np.pi)
        assert abs(peak[key].peak_amplitude - d_amplitude) <= RTOL * abs(d_amplitude), key
        assert abs(peak[key].peak_frequency_hz - d_frequency) <= RTOL * abs(d_frequency), key


def test_kinked_peak_derivatives_take_nine_jacobians():
    """The reference 1 g cylinder's kinked peak (one harmonic, 64 samples; the peak solver's Omega*
    2.7e-8 below the kink): the Jacobians at the peak, at the far side (the spacings 1e-8 and
    1e-7 of Omega*, two Newton iterations each) and at the pair at the kink (two each), counted
    (not timed): 9, where the symmetric pairs took 13. dR/dp at the pair comes from the pair's own
    Jacobian evaluations (no kernel call of its own)."""
    disk = bd.reference_disk("cylinder", 1e-3)
    response = disk.frequency_response(90.0, 100.0, harmonics=(1,), n_samples=64, estimate_harmonic_error=False)
    system = response.model_system()
    output = response.blade_outputs(0)[0]
    X = response.coefficients.reshape(len(response.omega), -1)
    solver = PeakSolver(system, response.omega, X)
    _, w, x = solver.solve_state(int(np.argmax(np.abs(X @ output))), output)
    dR_dp = disk.parameter_derivatives(system, ["damper.mass_g", "damper.friction_coefficient"])
    counts = {"jacobians": 0, "dR/dp": 0}
    residual, element = system.residual, dR_dp.element
    directions_at = element.directions_at

    def counted_residual(x, omega, jacobian=True):
        counts["jacobians"] += jacobian
        return residual(x, omega, jacobian)

    def counted_directions(local, basis, offsets, d_maps, moves, jacobian):
        counts["dR/dp"] += not jacobian
        return directions_at(local, basis, offsets, d_maps, moves, jacobian)

    system.residual, element.directions_at = counted_residual, counted_directions
    try:
        peak = peak_sensitivities(system, x, w, output, dR_dp, solver.x_scale, 1.0)
    finally:
        del system.residual, element.directions_at
    assert peak is not None and peak.spacing == PEAK_KINK_SPACING * w
    assert counts == {"jacobians": 9, "dR/dp": 0}, counts


def test_stuck_damper_peak_is_linear_in_the_excitation():
    """Closed form: a damper that never slips (mu = 2, a small excitation) leaves the system
    linear, so the peak amplitude is proportional to the excitation (elasticity exactly 1) and
    its frequency does not depend on it; the smooth peak's formula (second order) gives both."""
    disk = bd.reference_disk("cylinder", 1e-3)
    contact = dataclasses.replace(disk.damper.contact, friction_coefficient=2.0)
    disk = dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact=contact),
                               excitation=np.array([1e-3, 0, 0, 0, 0, 0]))
    peak = bd.peak_sensitivities(disk, (94.5, 97.0), ["disk.excitation_n_nm[0]"], harmonics=(0, 1),
                                 n_samples=32, estimate_harmonic_error=False)
    d = peak["disk.excitation_n_nm[0]"]
    assert abs(d.peak_amplitude * 1e-3 / peak.peak_amplitude - 1) <= 1e-7
    assert abs(d.peak_frequency_hz) * 1e-3 <= 1e-7 * peak.peak_frequency_hz


def test_parameter_errors_name_the_key(reference_static):
    disk, response = reference_static
    with pytest.raises(ValueError, match="damper.mass_kg"):
        response.sensitivities(["damper.mass_kg"])
    with pytest.raises(ValueError, match="no such dimension"):
        response.sensitivities(["damper.contact_height_mm"])            # a cylinder has none
    with pytest.raises(ValueError, match="n_blades"):
        response.sensitivities(["disk.n_blades"])
    with pytest.raises(ValueError, match="MistunedDisk"):
        response.sensitivities(["mistuning.kappa[0]"])
    with pytest.raises(ValueError, match=r"j in 0\.\.3"):
        response.sensitivities(["blade.natural_frequencies_hz[7]"])
    with pytest.raises(ValueError, match="rotor_speed_rpm"):
        response.sensitivities(["disk.rotor_speed_rpm"])
    with pytest.raises(ValueError, match="an oscillator's parameters"):
        bd.peak_sensitivities(bd.FrictionOscillator(), (10.0, 20.0), ["damper.mass_g"])
    with pytest.raises(TypeError):
        bd.peak_sensitivities(object(), (10.0, 20.0), ["damper.mass_g"])


def test_results_save_and_load(tmp_path, reference_static):
    _, response = reference_static
    peak = response.peak_sensitivities(["damper.mass_g", "damper.friction_coefficient"])
    loaded = bd.load(peak.save(tmp_path / "peak"))
    assert loaded.parameters == peak.parameters
    assert np.array_equal(loaded.d_peak_amplitude, peak.d_peak_amplitude)
    assert loaded["damper.mass_g"] == peak["damper.mass_g"]
    sens = response.sensitivities(["damper.mass_g"])
    again = bd.load(sens.save(tmp_path / "sens"))
    assert np.array_equal(again.d_tip_amplitude, sens.d_tip_amplitude)
    assert "damper.mass_g" in peak.table()


@pytest.mark.parametrize("kind, harmonics", [("cylinder", (0, 1, 2)), ("cylinder", (1,)), ("wedge", (0, 1, 2))])
def test_geometry_derivatives_match_differences(kind, harmonics):
    """The platform angles move the contact frames, centres and platform offsets (the contacts'
    map T), a wedge's section and inertia, and, without a static harmonic, each patch's seating
    load; the length the points along the faces, the stiffnesses per length and the inertia; a
    wedge's height its section and the points across its faces. The cylinder radius moves the
    centres along the normals and the rotary inertia, which leaves the rigid-platform response
    unchanged to rounding (both the derivative and the differences are zero there: compared with
    the floor 1e-8 a / p)."""
    disk = bd.reference_disk(kind, 1e-3 if kind == "cylinder" else 0.3e-3)
    response = disk.frequency_response(92.0, 99.0, harmonics=harmonics, n_samples=32, estimate_harmonic_error=False)
    keys = ["disk.gamma_left_deg", "disk.gamma_right_deg", "damper.length_mm",
            "damper.cylinder_radius_mm" if kind == "cylinder" else "damper.contact_height_mm"]
    sens = response.sensitivities(keys)
    i = len(response.omega) // 2
    for j, key in enumerate(keys):
        fd = central_difference(lambda k, h: disk.with_parameters({k: sens.values[j] + h}), key, sens.values[j],
                                response, i)
        floor = 1e-8 * sens.tip_amplitude[i].max() / sens.values[j]
        assert np.abs(sens.d_tip_amplitude[i, j] - fd).max() <= RTOL * np.abs(fd).max() + floor, key


def test_polygon_inertia_derivative_is_that_of_the_section():
    """The hand-written tangents of the prism's centroid and inertia against central differences
    of the same function (a polynomial of the vertices: the differences' truncation is O(h^2))."""
    from bladedamp.damper.geometry import polygon_inertia

    rng = np.random.default_rng(5)
    poly = np.array([[0.0, 0.0], [2e-3, -1.5e-3], [-1.8e-3, -1.2e-3]])
    d_poly = rng.normal(size=poly.shape)
    _, _, d_cg, d_M = polygon_inertia(poly, 1e-3, 0.02, d_poly, 0.3)
    h = 1e-9
    (cp, Mp, _, _), (cm, Mm, _, _) = (polygon_inertia(poly + s * h * d_poly, 1e-3, 0.02 + s * h * 0.3) for s in (1, -1))
    assert np.allclose(d_cg, (cp - cm) / (2 * h), rtol=1e-6, atol=1e-9)
    assert np.allclose(d_M, (Mp - Mm) / (2 * h), rtol=1e-6, atol=1e-12)


def test_with_parameters_is_the_independent_perturbation():
    disk = bd.reference_disk("cylinder", 1e-3)
    for key, value in (("damper.mass_g", 1.5), ("damper.friction_coefficient", 0.25), ("disk.excitation_n_nm[0]", 0.2),
                       ("blade.natural_frequencies_hz[0]", 96.0), ("blade.damping_ratio", 0.002)):
        a = disk.with_parameters({key: value})
        b = perturbed(disk, key, value - disk.parameter_value(key))
        assert a.parameter_value(key) == pytest.approx(value) and b.parameter_value(key) == pytest.approx(value)
        sa, sb = a.hbm_system((0, 1), 16), b.hbm_system((0, 1), 16)
        x = np.random.default_rng(3).normal(scale=1e-5, size=sa.n_unknowns)
        assert np.allclose(sa.residual(x, 600.0, False)[0], sb.residual(x, 600.0, False)[0], rtol=1e-12, atol=0)


@pytest.mark.parametrize("oscillator", [bd.FrictionOscillator(),
                                        bd.FrictionOscillator(contact_angle=0.3, cubic_stiffness=1e7, forcing=1.5)],
                         ids=["flat", "inclined-cubic"])
def test_oscillator_point_derivatives_match_differences(oscillator):
    """Every field of the oscillator (the inclined contact's angle through the map, the normal
    law's stiffness and preload through the approach) against central differences."""
    response = oscillator.frequency_response(10.0, 30.0, harmonics=(0, 1, 2, 3), n_samples=64)
    keys = [k for k in oscillator.PARAMETERS if oscillator.parameter_value(k) != 0]
    sens = oscillator.sensitivities(response, keys)
    output = oscillator.output(response.basis)
    i = int(np.argmax(sens.tip_amplitude[:, 0])) - 3
    x0, w = response.coefficients[i].ravel(), float(response.omega[i])
    for j, key in enumerate(keys):
        h = STEP * abs(sens.values[j])
        amplitudes = []
        for sign in (1, -1):
            system = dataclasses.replace(oscillator, **{key: sens.values[j] + sign * h}).hbm_system(
                response.basis.harmonics, response.basis.n_samples)
            solved = newton(system.residual, x0, w, np.abs(x0).max(), 1.0, tol=1e-13)
            amplitudes.append(abs(output @ solved.x))
        fd = (amplitudes[0] - amplitudes[1]) / (2 * h)
        floor = 1e-8 * sens.tip_amplitude[i, 0] / abs(sens.values[j])      # k_N of a flat contact: both zero
        assert abs(sens.d_tip_amplitude[i, j, 0] - fd) <= RTOL * abs(fd) + floor, key


def test_oscillator_in_gross_slip_peaks_at_the_free_natural_frequency():
    """Closed form: with the contact slipping through nearly all the period (F far above mu N0)
    the resonance lies at sqrt(k / m) / 2 pi, so its relative sensitivities to m and k are -1/2
    and +1/2 (to the share of the period the contact sticks, 0.1 % here)."""
    peak = bd.peak_sensitivities(bd.FrictionOscillator(forcing=5.0), (10.0, 30.0), ["mass", "stiffness"],
                                 harmonics=(0, 1, 2, 3), n_samples=64)
    _, frequency = peak.elasticities()
    assert frequency == pytest.approx([-0.5, 0.5], abs=1e-3)


def test_zero_excitation_is_rest_with_the_stuck_receptance_as_derivative():
    """Zero excitation: the response is rest, so the peak has no derivatives (a ValueError that says
    so, not 'could not be solved'); at each frequency every key that leaves rest at rest has the
    derivative 0 (to the AFT's rounding of the contacts' constant forces), and an excitation key the
    one-sided derivative of |u| = F |H| as F grows, the stuck linear receptance |H| times the unit
    force (F_x and M_x here: the tip's x motion). Against full Newton solves at F = 1 mN with
    mu = 2 (the damper never slips and the normal law is linear: the response is exactly linear in
    F), |u| / F to 1e-10 (measured 3e-14: the solves' tolerance 1e-14)."""
    disk = bd.reference_disk("cylinder", 1e-3)
    rest = dataclasses.replace(disk, excitation=np.zeros(6))
    keys = ["disk.excitation_n_nm[0]", "disk.excitation_n_nm[4]", "damper.mass_g", "damper.friction_coefficient",
            "blade.natural_frequencies_hz[0]", "blade.damping_ratio"]
    with pytest.raises(ValueError, match="the excitation is zero: the response is rest and has no peak"):
        bd.peak_sensitivities(rest, (90.0, 100.0), keys)
    response = rest.frequency_response(90.0, 100.0)
    sens = response.sensitivities(keys)
    assert np.isfinite(sens.d_tip_amplitude).all() and not sens.tip_amplitude.any()
    receptance = sens.d_tip_amplitude[:, :2, 0]
    assert (receptance > 0).all()
    # the other keys: 0 (p dA/dp against the receptance times 1 N: rounding, measured 1e-17)
    others = np.abs(sens.d_tip_amplitude[:, 2:, 0]) * np.abs(sens.values[2:])
    assert others.max() <= 1e-12 * receptance.max()
    contact = dataclasses.replace(disk.damper.contact, friction_coefficient=2.0)
    output = response.blade_outputs(0)[0]
    for j in range(2):
        force = 1e-3
        loaded = dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact=contact),
                                     excitation=force * np.eye(6)[(0, 4)[j]])
        system = loaded.hbm_system(response.basis.harmonics, response.basis.n_samples)
        for i in range(0, len(response.omega), 10):
            w = float(response.omega[i])
            start = loaded.initial_guess(system, w)
            solved = newton(system.residual, start, w, np.abs(start).max(), 1.0, tol=1e-14, factorize=system.factorize)
            assert solved.converged
            assert abs(abs(output @ solved.x) / force - receptance[i, j]) <= 1e-10 * receptance[i, j], (j, i)


def test_geometry_derivatives_of_dampers_with_their_own_masses_match_differences():
    """A mistuned wedge disk whose four dampers differ in mass: each damper's inertia derivative is
    its own (m times a function of the section). Every position's height and angle move together
    (``with_parameters``), against central differences as above. Giving every damper the last
    one's inertia derivative was 1.5e-4 off in the height (measured), above the 1e-5. Dampers that
    differ in more than their mass (the points and stiffnesses being position 0's) are refused."""
    tuned = dataclasses.replace(bd.reference_disk("wedge", 0.3e-3), n_blades=4)
    dampers = [dataclasses.replace(tuned.damper, mass=1e-3 * m) for m in (0.3, 0.5, 0.2, 0.4)]
    disk = MistunedDisk.from_tuned(tuned, np.array([1.0, 1.01, 0.99, 1.02]), dampers=dampers)
    response = disk.frequency_response(94.0, 98.0, harmonics=(0, 1, 2), n_samples=32, estimate_harmonic_error=False)
    keys = ["damper.contact_height_mm", "disk.gamma_left_deg", "damper.length_mm"]
    sens = response.sensitivities(keys)
    i = int(np.argmax(sens.tip_amplitude.max(axis=1))) - 2
    for j, key in enumerate(keys):
        fd = central_difference(lambda k, h: disk.with_parameters({k: sens.values[j] + h}), key, sens.values[j],
                                response, i)
        assert np.abs(sens.d_tip_amplitude[i, j] - fd).max() <= RTOL * np.abs(fd).max(), key
    longer = MistunedDisk.from_tuned(tuned, dampers=dampers[:3] + [dataclasses.replace(dampers[3], length=25e-3)])
    with pytest.raises(ValueError, match="differ from position to position in more than their mass"):
        longer.parameter_derivatives(longer.hbm_system((0, 1), 16), ["damper.contact_height_mm"])


def test_peak_of_two_close_maxima_is_the_larger_and_differentiated():
    """The reference 0.7 g cylinder with one harmonic over 92-100 Hz has two maxima 3 mHz apart
    (the AFT's kinks: samples 216 and 218 of the branch are both local maxima, the sample between
    falls on both sides, so neither pair beside the largest sample rose at its left end and the
    peak solver gave up: no peak derivatives). The peak is that of a dense scan of Newton solves
    over 95.150-95.175 Hz (0.05 mHz apart: the solved peak may lie above the scan's largest by the
    largest slope times half a spacing, and not below it beyond the solves' 1e-12), the larger of
    the two; its derivatives against central differences of peaks solved by bisection (as above)."""
    disk = bd.reference_disk("cylinder", 0.7e-3)
    response = disk.frequency_response(92.0, 100.0, harmonics=(1,), estimate_harmonic_error=False)
    keys = ["damper.mass_g", "damper.friction_coefficient", "disk.excitation_n_nm[0]"]
    peak = response.peak_sensitivities(keys)
    system = response.model_system()
    output = response.blade_outputs(0)[0]
    X = response.coefficients.reshape(len(response.omega), -1)
    i = int(np.argmax(np.abs(X @ output)))
    scan, slopes, x = [], [], X[i]
    for f in np.arange(95.150, 95.175, 5e-5):
        solved = newton(system.residual, x, 2 * np.pi * f, np.abs(x).max(), 1.0, tol=1e-13, factorize=system.factorize)
        assert solved.converged
        x = solved.x
        u, du = output @ x, output @ -solved.solve(solved.dR_domega)
        scan.append(abs(u))
        slopes.append(abs(np.real(np.conj(u) * du)) / abs(u))
    scan = np.array(scan)
    maxima = np.flatnonzero((scan[1:-1] > scan[:-2]) & (scan[1:-1] > scan[2:])) + 1
    assert len(maxima) >= 2                                          # the case: more than one maximum
    largest = int(np.argmax(scan))
    bound = max(slopes) * 2 * np.pi * 2.5e-5
    assert -1e-12 * scan[largest] <= peak.peak_amplitude - scan[largest] <= bound
    assert abs(peak.peak_frequency_hz - (95.150 + 5e-5 * largest)) <= 5e-5
    for key, value in zip(keys, peak.values):
        h = STEP * abs(value)
        plus = precise_peak(perturbed(disk, key, h), response, X[i], 2 * np.pi * peak.peak_frequency_hz)
        minus = precise_peak(perturbed(disk, key, -h), response, X[i], 2 * np.pi * peak.peak_frequency_hz)
        d_amplitude = (plus[0] - minus[0]) / (2 * h)
        d_frequency = (plus[1] - minus[1]) / (2 * h) / (2 * np.pi)
        assert abs(peak[key].peak_amplitude - d_amplitude) <= RTOL * abs(d_amplitude), key
        assert abs(peak[key].peak_frequency_hz - d_frequency) <= RTOL * abs(d_frequency), key
