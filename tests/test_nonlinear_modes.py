"""EPMC nonlinear modes (bladedamp.hbm.nonlinear_modes): linear limits, energy, synthesis vs HBM FRFs."""
import dataclasses
import warnings

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.hbm.nonlinear_modes import NonlinearModeResponse, nonlinear_mode
from bladedamp.oscillator import FrictionOscillator

OSC = FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)   # m 1 kg, k = k_T = 1e4 N/m, mu N = 0.9 N


@pytest.fixture(scope="module")
def osc_mode():
    return nonlinear_mode(OSC)                       # default range: stuck to gross slip


@pytest.mark.parametrize("harmonics", [(1,), (1, 3)])
def test_oscillator_stuck_and_free_limits(harmonics):
    k, kt, m, c = OSC.stiffness, OSC.contact_stiffness, OSC.mass, OSC.damping
    r = nonlinear_mode(OSC, amplitudes=[1e-8, 1e6], harmonics=harmonics)
    assert r.success, r.message
    w = 2 * np.pi * r.frequency_hz
    np.testing.assert_allclose(w[0], np.sqrt((k + kt) / m), rtol=1e-6)
    np.testing.assert_allclose(r.damping_ratio[0], c / (2 * np.sqrt(m * (k + kt))), rtol=1e-6)
    np.testing.assert_allclose(w[1], np.sqrt(k / m), rtol=1e-6)
    np.testing.assert_allclose(r.damping_ratio[1], c / (2 * np.sqrt(m * k)), rtol=1e-5)
    # mass-normalised shape: first harmonic of x = a / sqrt(m), sine coefficient 0
    j1 = r.basis.cos_index(1)
    np.testing.assert_allclose(r.coefficients[:, j1, 0], 1 / np.sqrt(m), rtol=1e-6)
    assert np.all(np.abs(r.coefficients[:, j1 + 1, 0]) < 1e-12)


def test_default_range_goes_from_stuck_to_gross_slip(osc_mode):
    r = osc_mode
    assert r.success, r.message
    k, kt, m = OSC.stiffness, OSC.contact_stiffness, OSC.mass
    f_stuck, f_free = np.sqrt((k + kt) / m) / (2 * np.pi), np.sqrt(k / m) / (2 * np.pi)
    np.testing.assert_allclose(r.frequency_hz[0], f_stuck, rtol=1e-9)
    assert abs(r.frequency_hz[-1] - f_free) < 0.01 * (f_stuck - f_free)       # the backbone has dropped to ~free
    assert r.damping_ratio.max() > 5 * r.damping_ratio[0]                      # friction damping peaks in between
    # slip onset mu N / k_T = 9e-5 m lies inside the range
    assert r.modal_amplitude[0] < 9e-5 < r.modal_amplitude[-1]


@pytest.mark.parametrize("harmonics", [(1,), (1, 3, 5)])
def test_damping_is_the_dissipated_energy(harmonics):
    """2 zeta omega oint x'^T M x' dt = dissipated energy per cycle, for any truncation."""
    r = nonlinear_mode(OSC, amplitudes=np.logspace(-5, -1.5, 8), harmonics=harmonics)
    assert r.success, r.message
    basis = r.basis
    for a, w, z, X, E in zip(r.modal_amplitude, r.omega, r.damping_ratio, r.coefficients, r.dissipated_energy):
        x = a * X                                             # no static harmonic here
        velocity = w * (basis.derivative @ x)                 # x' coefficients
        weights = np.where(basis.order == 0, 2 * np.pi, np.pi) / w    # oint over t = (1 / w) oint over tau
        kinetic = float(np.sum(weights * (velocity[:, 0] * OSC.mass * velocity[:, 0])))
        np.testing.assert_allclose(2 * z * w * kinetic, E, rtol=1e-8)
        assert E > 0


@pytest.mark.parametrize("forcing", [0.5, 2.0, 8.0])
def test_single_mode_synthesis_matches_the_frf_peak(osc_mode, forcing):
    """Microslip (0.5 N), around the damping optimum (2 N), towards gross slip (8 N)."""
    peak = osc_mode.forced_peak(scale=forcing / OSC.forcing)
    assert peak["found"], peak["message"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        frf = dataclasses.replace(OSC, forcing=forcing).frequency_response(12.0, 26.0, harmonics=(1,))
    assert frf.success, frf.message
    np.testing.assert_allclose(peak["output_amplitude"][0], frf.peak_amplitude, rtol=0.03)
    np.testing.assert_allclose(peak["frequency_hz"], frf.peak_frequency_hz, rtol=0.03)
    # an explicit force vector gives the same
    again = osc_mode.forced_peak(np.array([forcing]))
    np.testing.assert_allclose(again["modal_amplitude"], peak["modal_amplitude"], rtol=1e-12)


DISKS = {}


def reference(kind, harmonics=(1,)):
    """The reference disk with the 1 g cylinder or the 0.3 g wedge and its 1F mode (cached)."""
    if (kind, harmonics) not in DISKS:
        disk = bd.reference_disk(kind, 1e-3 if kind == "cylinder" else 0.3e-3)
        DISKS[kind, harmonics] = (disk, nonlinear_mode(disk, harmonics=harmonics))
    return DISKS[kind, harmonics]


@pytest.fixture(scope="module")
def disk():
    return reference("cylinder")[0]


@pytest.fixture(scope="module")
def disk_mode():
    return reference("cylinder")[1]


def test_disk_small_amplitude_is_the_linear_stuck_mode(disk, disk_mode):
    """Against the linear stuck FRF of the sector (dR/dx at rest: contacts stuck): its peak
    frequency, and its peak amplitude = |phi^H F| |tip(phi)| / (2 zeta omega^2) of the mode."""
    from scipy.optimize import minimize_scalar

    r = disk_mode
    assert r.success, r.message
    assert r.dof_names[r.reference_dof] == "q_1F"
    system = disk.hbm_system((1,))
    C, n = system.basis.n_coeffs, system.n_dof

    def tip(f_hz):
        w = 2 * np.pi * f_hz
        _, J, _ = system.residual(np.zeros(system.n_unknowns), w)
        x = np.linalg.solve(J, system.excitation(w)[0])
        return disk.output_amplitudes(x.reshape(1, C, n), system.basis)[0, 0]

    f0 = r.frequency_hz[0]
    best = minimize_scalar(lambda f: -tip(f), bounds=(0.99 * f0, 1.01 * f0), method="bounded",
                           options={"xatol": 1e-7})
    np.testing.assert_allclose(r.frequency_hz[0], best.x, rtol=1e-5)
    np.testing.assert_allclose(r.frequency_hz[0], r.linear_frequency_hz, rtol=1e-9)
    w0, z0 = 2 * np.pi * r.frequency_hz[0], r.damping_ratio[0]
    modal_force = abs(r.shape(1)[0].conj() @ r.excitation)
    tip_per_a = r.output_amplitude[0, 0] / r.modal_amplitude[0]
    np.testing.assert_allclose(-best.fun, modal_force * tip_per_a / (2 * z0 * w0 ** 2), rtol=0.01)
    assert r.damping_ratio.max() > 2 * z0                       # the damper adds damping in microslip
    assert r.frequency_hz[-1] < r.frequency_hz[0] - 0.5          # and softens the mode


@pytest.mark.parametrize("kind, forcing, harmonics", [("cylinder", 0.1, (1,)),
                                                      pytest.param("cylinder", 1.0, (1,), marks=pytest.mark.slow),
                                                      pytest.param("wedge", 0.01, (1,), marks=pytest.mark.slow),
                                                      ("wedge", 0.1, (1,)), ("cylinder", 0.1, (0, 1))])
def test_disk_synthesis_matches_the_frf_peak(kind, forcing, harmonics):
    """EO = 1: the synthesis peak of the 1F nonlinear mode (interpolated between its points)
    against the HBM FRF peak, at the reference excitation 0.1 N and at 0.01 N / 1 N (near stuck,
    towards gross slip; slow: test_disk_synthesis_over_the_excitation_range covers 0.01-1 N with
    the resolved peaks); with a static harmonic the centrifugal preload F_CG stays in the
    autonomous problem."""
    disk, mode = reference(kind, harmonics)
    assert mode.success, mode.message
    peak = mode.forced_peak(scale=forcing / disk.excitation[0])
    assert peak["found"], peak["message"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                       # one harmonic: AccuracyWarning
        frf = dataclasses.replace(disk, excitation=disk.excitation * forcing / disk.excitation[0]) \
            .frequency_response(90, 105, harmonics=harmonics)
    assert frf.success, frf.message
    np.testing.assert_allclose(peak["output_amplitude"][0], frf.peak_amplitude, rtol=0.03)
    np.testing.assert_allclose(peak["frequency_hz"], frf.peak_frequency_hz, rtol=0.005)


def test_save_load_and_plot(osc_mode, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    path = osc_mode.save(tmp_path / "mode")
    back = bd.load(path)
    assert isinstance(back, NonlinearModeResponse)
    np.testing.assert_array_equal(back.damping_ratio, osc_mode.damping_ratio)
    np.testing.assert_array_equal(back.coefficients, osc_mode.coefficients)
    assert back.basis.harmonics == osc_mode.basis.harmonics
    np.testing.assert_allclose(back.forced_peak()["modal_amplitude"], osc_mode.forced_peak()["modal_amplitude"])
    ax_f, ax_z = back.plot()
    assert ax_f.get_xscale() == "log" and ax_z.get_xscale() == "log"


def test_bad_inputs_name_the_parameter_and_range():
    with pytest.raises(ValueError, match=r"mode must be an integer in \[0, 0\]"):
        nonlinear_mode(OSC, mode=1)
    with pytest.raises(ValueError, match="harmonics must contain 1"):
        nonlinear_mode(OSC, harmonics=(0, 3))
    with pytest.raises(ValueError, match=r"amplitudes \(modal amplitudes\) must be in \(0, inf\)"):
        nonlinear_mode(OSC, amplitudes=[1e-3, -1.0])
    with pytest.raises(ValueError, match=r"max_log_step \(decades\) must be in \(0.0, 2.0\]"):
        nonlinear_mode(OSC, max_log_step=0)
    with pytest.raises(TypeError, match="hbm_system"):
        nonlinear_mode(object())
    with pytest.raises(ValueError, match=r"resolve_peaks \(excitation scales\) must be in \(0, inf\)"):
        nonlinear_mode(OSC, resolve_peaks=[1.0, 0.0])
    with pytest.raises(ValueError, match="force must have shape"):
        nonlinear_mode(OSC, amplitudes=[1e-5, 1e-4]).forced_peak(np.ones(3))


def test_top_level_export():
    assert bd.nonlinear_mode is nonlinear_mode


def test_resolved_peaks_are_epmc_roots_independent_of_the_points():
    """``resolve_peaks``: the synthesis peak is an EPMC solution at the root of
    h(a) = 2 zeta omega^2 sqrt(1 - zeta^2) a - |phi^H F| (a direct EPMC solve at that amplitude
    gives h = 0 and the same tip amplitude), so it does not depend on the mode's points; the
    interpolated peak of 15 points is off by percents."""
    from bladedamp.hbm.nonlinear_modes import peak_function

    scales = (0.25, 1.0, 4.0)
    coarse, fine = (nonlinear_mode(OSC, n_points=n, resolve_peaks=scales) for n in (15, 60))
    assert "3 of 3 forced peaks resolved" in coarse.message
    interpolated = nonlinear_mode(OSC, n_points=15)
    for s in scales:
        p_coarse, p_fine = coarse.forced_peak(scale=s), fine.forced_peak(scale=s)
        np.testing.assert_allclose(p_coarse["output_amplitude"], p_fine["output_amplitude"], rtol=1e-7)
        np.testing.assert_allclose(p_coarse["frequency_hz"], p_fine["frequency_hz"], rtol=1e-9)
    worst = max(abs(interpolated.forced_peak(scale=s)["output_amplitude"][0]
                    / fine.forced_peak(scale=s)["output_amplitude"][0] - 1) for s in scales)
    assert worst > 1e-2, "15 interpolated points should not resolve the peak"
    peak = coarse.forced_peak(scale=1.0)
    direct = nonlinear_mode(OSC, amplitudes=[peak["modal_amplitude"]])
    h = peak_function(direct.modal_amplitude, direct.omega, direct.damping_ratio, direct.shape(1), direct.excitation)
    assert abs(h[0]) < 1e-8 * abs(direct.shape(1)[0].conj() @ direct.excitation)
    np.testing.assert_allclose(direct.output_amplitude[0], peak["output_amplitude"], rtol=1e-8)


def free_disk(kind, **contact):
    """The reference disk of ``kind`` with its damper's contact properties changed."""
    disk = reference(kind)[0]
    return dataclasses.replace(disk, damper=dataclasses.replace(
        disk.damper, contact=dataclasses.replace(disk.damper.contact, **contact)))


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_disk_free_limit_is_the_linear_mode_without_tangential_stiffness(kind):
    """The free limit: with friction coefficient 0 the contacts carry their (linear) normal
    springs and no tangential force, so the nonlinear mode is, at every amplitude, the linear
    mode of the disk whose contacts have no tangential stiffness (k_T 1e-12 of the reference, k_N
    unchanged: its first mode of the blade, above the damper's rigid-body modes), frequency and
    damping ratio to rounding. The reference damper (mu = 0.3) tends to it at gross slip."""
    from bladedamp.hbm.nonlinear_modes import linear_stuck_mode

    contact = reference(kind)[0].damper.contact
    r = nonlinear_mode(free_disk(kind, friction_coefficient=0.0), amplitudes=np.logspace(-6, -3, 4))
    assert r.success, r.message
    soft = free_disk(kind, tangential_stiffness_per_length=1e-12 * contact.tangential_stiffness_per_length,
                     normal_to_tangential_stiffness=1e12 * contact.normal_to_tangential_stiffness)
    system = soft.hbm_system((1,))
    mode = 0
    while True:                          # skip the damper's rigid-body modes (roll, slide: ~0.2 Hz)
        w, zeta, _, _, _ = linear_stuck_mode(soft, system, mode)
        if w > 2 * np.pi * 50:
            break
        mode += 1
    np.testing.assert_allclose(2 * np.pi * r.frequency_hz, w, rtol=1e-9)
    np.testing.assert_allclose(r.damping_ratio, zeta, rtol=1e-8)
    # not the stuck mode (the tangential springs in): the check can tell them apart
    stuck = reference(kind)[1]
    assert stuck.linear_frequency_hz - r.frequency_hz[0] > 0.5
    # the reference damper at the top of its default range (gross slip) has nearly reached it
    assert abs(stuck.frequency_hz[-1] / r.frequency_hz[0] - 1) < 1e-4


SYNTHESIS_LEVELS = (0.01, 0.03, 0.1, 0.3, 1.0)      # first-harmonic tip force [N], the range


@pytest.fixture(scope="module")
def resolved_modes():
    """The 1F mode of each reference damper with the synthesis peaks of every level resolved."""
    out = {}
    for kind in ("cylinder", "wedge"):
        disk = reference(kind)[0]
        out[kind] = nonlinear_mode(disk, resolve_peaks=np.array(SYNTHESIS_LEVELS) / disk.excitation[0])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("level", SYNTHESIS_LEVELS)
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_disk_synthesis_over_the_excitation_range(resolved_modes, kind, level):
    """Issue 14 item 3: the single-nonlinear-mode synthesis of the 1 g cylinder and the 0.3 g
    wedge against the HBM FRF peak (one harmonic, both), 0.01-1 N, from near stuck to gross slip.
    The issue's bound is 3 %; measured (one run) at most 0.06 % in amplitude and 0.008 % in
    frequency with the resolved peaks, so 1 % and 0.1 % are asserted. From 0.03 N on, the stuck
    linear mode's resonance misses the peak by more than 10 % (15 % to a factor 3.5): the
    agreement is the nonlinear mode's."""
    disk = reference(kind)[0]
    mode = resolved_modes[kind]
    assert mode.success and f"{len(SYNTHESIS_LEVELS)} of {len(SYNTHESIS_LEVELS)} forced peaks resolved" in mode.message
    scale = level / disk.excitation[0]
    peak = mode.forced_peak(scale=scale)
    assert peak["found"], peak["message"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                       # one harmonic: AccuracyWarning
        frf = dataclasses.replace(disk, excitation=disk.excitation * scale).frequency_response(90, 105, harmonics=(1,))
    assert frf.success, frf.message
    np.testing.assert_allclose(peak["output_amplitude"][0], frf.peak_amplitude, rtol=0.01)
    np.testing.assert_allclose(peak["frequency_hz"], frf.peak_frequency_hz, rtol=1e-3)
    if level >= 0.03:                 # the stuck linear mode's resonance is off by more than 10 %
        z0, w0 = mode.damping_ratio[0], 2 * np.pi * mode.frequency_hz[0]
        linear = abs(mode.shape(1)[0].conj() @ mode.excitation) * scale \
            * (mode.output_amplitude[0, 0] / mode.modal_amplitude[0]) / (2 * z0 * w0 ** 2)
        assert abs(linear / frf.peak_amplitude - 1) > 0.1
