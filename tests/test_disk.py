"""Tuned bladed disk with underplatform dampers (paper: Bladed Disk Model Eq. 13-25, Damper
Kinetics Eq. 12, TUNED SYSTEM), on the calibrated reference configuration.

The references are built here from the physics, independently of the harmonic-balance code:
the blade's closed-form modal FRF, the stuck linear system assembled from the patches' point
stiffnesses, rigid-body and equilibrium arguments (rolling at EO = 0, moment balance of the
cylinder), the energy balance, mirror symmetry and finite differences. Measured numbers are
printed (run with ``-s``) and put in the assertion messages.
"""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from conftest import central_difference, relative_matrix_error

from bladedamp.disk import DiskResponse, TunedDisk
from bladedamp.diskmodel import DamperContacts
from bladedamp.hbm.continuation import Branch, newton
from bladedamp.reference import reference_disk

F_RANGE = (92.0, 104.0)            # around the 1F resonance (95 Hz undamped)
MAX_STEP = 0.05
ROTOR_SPEED_95_HZ = 95.0  # EO = 0: the rotor speed of the EO = 1 resonance [Hz, revolutions per second]
REFERENCE_MASS = {"cylinder": 1.0e-3, "wedge": 0.28e-3}   # paper's cylinder optimum; wedge near its optimum
HARMONICS = [(1,), (0, 1, 2, 3)]

_FRF = {}


def frf(kind, mass, harmonics=(1,), f_range=F_RANGE, max_step=MAX_STEP, **disk_options):
    """Frequency response of the reference disk (cached for the session)."""
    key = (kind, mass, tuple(harmonics), tuple(f_range), max_step, tuple(sorted(disk_options.items())))
    if key not in _FRF:
        disk = reference_disk(kind, mass, **disk_options)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = disk.frequency_response(*f_range, harmonics=harmonics, max_step=max_step)
        assert r.success, f"{kind} {mass * 1e3:g} g H={harmonics} {disk_options}: {r.message}"
        _FRF[key] = r
    return _FRF[key]


def peak(r, direction=0):
    """(peak first-harmonic tip amplitude [m], frequency [Hz], index); the peak must be interior and
    is refined by the parabola through the largest point and its neighbours."""
    a, f = r.tip_amplitude[:, direction], r.frequency_hz
    i = int(np.argmax(a))
    assert 0 < i < len(a) - 1, f"peak at the end of the range ({f[i]:.3f} Hz)"
    c = np.polyfit(f[i - 1:i + 2] - f[i], a[i - 1:i + 2], 2)
    if c[0] < 0 and np.all(np.diff(f[i - 1:i + 2]) > 0):
        fv = -c[1] / (2 * c[0])
        if f[i - 1] - f[i] <= fv <= f[i + 1] - f[i]:
            return float(max(a[i], np.polyval(c, fv))), float(f[i] + fv), i
    return float(a[i]), float(f[i]), i


def complex_h1(r, array):
    """Harmonic-1 complex amplitudes X = a - i b (x = Re X e^{i tau}) of ``array`` (n, C, ...)."""
    j = r.basis.cos_index(1)
    return array[:, j] - 1j * array[:, j + 1]


def stuck_linear_tip(disk, omegas):
    """First-harmonic tip amplitudes (n, 3) of the linear system in which every contact point
    sticks: a point of weight w at (xi, eta) on a patch is a spring k_T w, k_T w, k_N w along
    (xi, eta, zeta) driven by the control point's rigid motion u + phi x (xi, eta, 0); the sector's
    complex map is T = [-G_P diag(1, e^{i dphi}) Phi_P, G_D] (Eq. 6, 24) and the system
    (S + T^H K_C T - Omega^2 I_D) q = Phi_E^T f is solved at every frequency."""
    g = disk.damper_geometry()
    blade = disk.blade
    nm = blade.n_modes
    K_C = np.zeros((12, 12))
    for c, patch in enumerate(g.patches):
        k = np.array([patch.tangential_stiffness, patch.tangential_stiffness, patch.normal_law.stiffness])
        for xi, eta, weight in zip(patch.xi, patch.eta, patch.weights):
            r = np.array([xi, eta, 0.0])
            B = np.hstack([np.eye(3), -np.array([np.cross(e, r) for e in np.eye(3)]).T])  # u + phi x r
            K_C[6 * c:6 * c + 6, 6 * c:6 * c + 6] += B.T @ np.diag(k * weight) @ B
    phase = np.ones(12, dtype=complex)
    phase[6:] = np.exp(1j * 2 * np.pi * disk.engine_order / disk.n_blades)
    phi_P = np.vstack([blade.shape("OL"), blade.shape("OR")])
    T = np.hstack([-g.G_P(disk.platform_offsets(g)) @ (phase[:, None] * phi_P), g.G_D])
    w0 = 2 * np.pi * blade.natural_frequencies_hz
    K = np.zeros((nm + 6, nm + 6), dtype=complex)
    K[:nm, :nm] = np.diag(w0 ** 2)
    K += T.conj().T @ K_C @ T
    M = np.zeros((nm + 6, nm + 6))
    M[:nm, :nm] = np.eye(nm)
    if disk.damper_inertia:
        M[nm:, nm:] = g.inertia
    D = np.zeros((nm + 6, nm + 6))
    D[:nm, :nm] = np.diag(2 * blade.damping_ratios * w0)
    f = np.zeros(nm + 6, dtype=complex)
    f[:nm] = blade.shape("excitation").T @ disk.excitation
    tip = blade.shape("tip")[:3]
    return np.array([np.abs(tip @ np.linalg.solve(K - w ** 2 * M + 1j * w * D, f)[:nm]) for w in omegas])


def first_harmonic_tip(disk, system, x):
    C, n, nm = system.basis.n_coeffs, system.n_dof, disk.blade.n_modes
    X = x.reshape(C, n)
    j = system.basis.cos_index(1)
    return abs((X[j, :nm] - 1j * X[j + 1, :nm]) @ disk.blade.shape("tip")[0])


def tip_at(disk, r, omegas, harmonics=(1,)):
    """u_x,tip of ``disk`` at exactly ``omegas``: Newton from the nearest point of its branch ``r``."""
    system = disk.hbm_system(harmonics)
    scale = np.abs(r.coefficients).max(axis=0).ravel()
    scale = np.maximum(scale, 1e-6 * scale.max())
    out = []
    for w in omegas:
        x0 = r.coefficients[np.argmin(np.abs(r.omega - w))].ravel()
        res = newton(system.residual, x0, w, scale, np.linalg.norm(system.residual(np.zeros_like(x0), w, False)[0]))
        assert res.converged, f"Newton did not converge at {w / 2 / np.pi:.4f} Hz"
        out.append(first_harmonic_tip(disk, system, res.x))
    return np.array(out)


class BackwardWave(TunedDisk):
    """The same disk excited by the travelling wave in the other direction (EO -> -EO, i.e.
    n - EO): interblade phase -2 pi EO / n. TunedDisk accepts EO in 0..n/2 only, which is the
    whole range for a mirror-symmetric sector but not for asymmetric platforms."""

    @property
    def interblade_phase(self) -> float:
        return -2 * np.pi * self.engine_order / self.n_blades


def with_angles(disk, left_deg, right_deg, cls=None):
    fields = {f.name: getattr(disk, f.name) for f in dataclasses.fields(TunedDisk)}
    fields.update(gamma_left=np.radians(left_deg), gamma_right=np.radians(right_deg))
    return (cls or type(disk))(**fields)


# ---------------------------------------------------------------------------------------
# 1. limits: no damper (linear blade) and a heavy, stuck damper (linear stuck system)
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", [None, "cylinder", "wedge"])
def test_zero_mass_damper_gives_the_linear_blade_frf(kind):
    """m = 0 (or no damper): DiskResponse.tip_amplitude equals the closed-form modal FRF
    Phi_tip S^-1 Phi_E^T f (Eq. 4-5) at the same frequencies, to 1e-9."""
    r = frf(kind, 0.0)
    disk = r.disk
    assert not disk.has_damper and r.coefficients.shape[2] == disk.blade.n_modes
    ref = np.abs(disk.blade.linear_frf(f_hz=r.frequency_hz, force=disk.excitation)[:, :3])
    err = np.abs(r.tip_amplitude - ref).max() / ref.max()
    p, f, _ = peak(r)
    print(f"\n[linear] {kind}: {len(r.omega)} points, max rel. difference to closed form {err:.2e}, "
          f"peak {p * 1e3:.5f} mm at {f:.4f} Hz")
    assert err < 1e-9, f"no-damper FRF differs from the closed-form modal FRF by {err:.2e}"
    assert np.all(r.dissipated_energy == 0)


@pytest.mark.parametrize("inertia, f_range", [(True, (105.0, 114.0)), (False, (93.0, 99.0))])
def test_heavy_damper_is_the_stuck_linear_system(inertia, f_range):
    """m = 1 kg (paper Fig. 5: "the damper sticks due to very high contact normal forces"): every
    point sticks over the whole period and the response is the linear stuck system assembled
    here from the point stiffnesses. With its inertia the 1 kg damper moves the stuck resonance to
    109.65 Hz (it is heavier than the blade); without it the stuck resonance is at 95.73 Hz."""
    r = frf("cylinder", 1.0, f_range=f_range, damper_inertia=inertia)
    ref = stuck_linear_tip(r.disk, r.omega)
    p, f, i = peak(r)
    p_ref = ref[i, 0]
    stick = r.point_state[..., 0].min()
    err_peak = abs(r.tip_amplitude[i, 0] - p_ref) / p_ref
    err_all = np.abs(r.tip_amplitude - ref).max() / ref.max()
    print(f"\n[stuck] 1 kg, inertia={inertia}: peak {p * 1e3:.5f} mm at {f:.3f} Hz, stuck linear "
          f"{p_ref * 1e3:.5f} mm; rel. difference at the peak {err_peak:.2e}, over the range {err_all:.2e}; "
          f"min stick fraction {stick}")
    assert stick == 1.0, f"some point slips or lifts off: min stick fraction {stick}"
    assert err_peak < 5e-3 and err_all < 1e-6, \
        f"HBM vs stuck linear system: {err_peak:.2e} at the peak, {err_all:.2e} over the range"
    # not the undamped blade (resonance at 95.0 Hz): the stuck damper moves the resonance
    assert abs(f - 95.0) > 0.5, f"stuck resonance {f:.3f} Hz is not distinct from the undamped 95 Hz"


# ---------------------------------------------------------------------------------------
# 2. EO = 0: the cylinder rolls, the wedge cannot
# ---------------------------------------------------------------------------------------
def tangential_amplitude(r, i):
    """Largest first-harmonic tangential (xi, eta) relative displacement amplitude of any patch point."""
    X = complex_h1(r, r.point_displacement[i:i + 1])[0]      # (2, P, 3)
    return float(np.abs(X[..., :2]).max())


def test_eo0_cylinder_rolls_without_slip_or_dissipation():
    """EO = 0 (all blades in phase): the platforms of neighbouring blades rotate by the same angle
    about centres one pitch apart, so the contact points move relative to each other at right
    angles to the (horizontal) line between them, which a cylinder follows by rolling about one
    contact: no slip, no dissipation, the undamped resonance amplitude (paper Fig. 7, 8)."""
    m = REFERENCE_MASS["cylinder"]
    r0 = frf("cylinder", m, engine_order=0, rotor_speed_hz=ROTOR_SPEED_95_HZ)
    r1 = frf("cylinder", m)
    lin = frf(None, 0.0)
    p0, f0, i0 = peak(r0)
    p1, f1, i1 = peak(r1)
    pu, fu, _ = peak(lin)
    t0, t1 = tangential_amplitude(r0, i0), tangential_amplitude(r1, i1)
    slip0, slip1 = r0.point_state[i0, ..., 1].max(), r1.point_state[i1, ..., 1].max()
    diss0 = r0.dissipated_energy[i0] / r0.excitation_work[i0]
    diss1 = r1.dissipated_energy[i1] / r1.excitation_work[i1]
    print(f"\n[EO=0 cylinder] peak {p0 * 1e3:.5f} mm at {f0:.3f} Hz vs undamped {pu * 1e3:.5f} mm at {fu:.3f} Hz "
          f"({p0 / pu - 1:+.2e}); tangential point amplitude {t0:.3e} m vs EO=1 {t1:.3e} m (ratio {t0 / t1:.2e}); "
          f"max slip fraction {slip0} vs EO=1 {slip1}; W_friction/W_exc {diss0:.1e} vs EO=1 {diss1:.3f}")
    assert t0 < 0.01 * t1, f"tangential relative displacement at EO=0 {t0:.2e} m is not < 1 % of EO=1 {t1:.2e} m"
    assert slip0 <= 0.01 * slip1, f"slip fraction at EO=0 {slip0} vs EO=1 {slip1}"
    assert abs(diss0) < 1e-6, f"EO=0 friction dissipation / excitation work = {diss0:.2e}"
    assert abs(p0 / pu - 1) < 0.01, f"EO=0 peak {p0 * 1e3:.5f} mm vs undamped {pu * 1e3:.5f} mm"
    assert diss1 > 0.3, "at EO=1 the same damper must dissipate (else the comparison says nothing)"


def test_eo0_wedge_dissipates():
    """The wedge's flat faces of height h_C cannot roll (paper: "pure rolling is excluded in the
    case of the wedge-shaped damper, even ... (EO = 0)"): it slips, dissipates, damps."""
    m = REFERENCE_MASS["wedge"]
    r0 = frf("wedge", m, engine_order=0, rotor_speed_hz=ROTOR_SPEED_95_HZ)
    pu, _, _ = peak(frf(None, 0.0))
    p0, f0, i0 = peak(r0)
    diss0 = r0.dissipated_energy[i0] / r0.excitation_work[i0]
    slip0 = r0.point_state[i0, ..., 1].max()
    print(f"\n[EO=0 wedge {m * 1e3:g} g] peak {p0 * 1e3:.4f} mm at {f0:.3f} Hz (undamped {pu * 1e3:.4f} mm, "
          f"reduction {1 - p0 / pu:.1%}); W_friction/W_exc {diss0:.3f}; max slip fraction {slip0}")
    assert diss0 > 0.3, f"EO=0 wedge dissipates only {diss0:.3f} of the excitation work"
    assert p0 < 0.5 * pu, f"EO=0 wedge peak {p0 * 1e3:.4f} mm not below half the undamped {pu * 1e3:.4f} mm"


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_eo_half_n_standing_wave_pushes_the_damper_radially(kind):
    """EO = n/2: neighbouring blades move in antiphase (q_i+1 = -q_i). With symmetric platforms
    the damper's surroundings are then mirror-symmetric about its midplane (1F is odd under the
    mirror x -> -x), so the mirror-odd damper motions u_x, phi_y, phi_z vanish and the damper is
    pushed in and out radially (u_z). The stuck start of this case has no damper rotation at all
    (it used to stop Newton at the first point)."""
    r = frf(kind, 1e-3, engine_order=8)
    _, f, i = peak(r)
    names = r.dof_names
    X = np.abs(r.coefficients[i])
    half_length = r.disk.damper.length / 2
    u_z = X[:, names.index("uD_z")].max()
    odd = max(X[:, names.index("uD_x")].max(), half_length * X[:, names.index("phiD_y")].max(),
              half_length * X[:, names.index("phiD_z")].max())
    diss = r.dissipated_energy[i] / r.excitation_work[i]
    print(f"\n[EO=8 {kind} 1 g] peak {r.tip_amplitude[i, 0] * 1e3:.4f} mm at {f:.3f} Hz: damper u_z {u_z:.3e} m, "
          f"mirror-odd motions {odd:.1e} m; W_friction/W_exc {diss:.3f}; energy balance {r.energy_balance_error().max():.1e}")
    assert u_z > 1e-6 and odd < 1e-9 * u_z, f"mirror-odd damper motion {odd:.2e} m vs radial {u_z:.2e} m"
    assert r.energy_balance_error().max() < 1e-6 and diss > 0.01


# ---------------------------------------------------------------------------------------
# 3. symmetric platforms: left and right tangential forces (paper Fig. 11 left)
# ---------------------------------------------------------------------------------------
def test_contact_frames_xi_are_minus_mirror_images():
    """With eta = y at both contacts and right-handed frames, xi_OR is minus the mirror image
    (x -> -x) of xi_OL: both xi point to -x (same circumferential sense), one up, one down the
    groove. So a statement 'mirror images' is about (xi_OL, -xi_OR), and 180 deg about (xi_OL, xi_OR)."""
    g = reference_disk("cylinder").damper_geometry()
    mirror = np.diag([-1.0, 1.0, 1.0])
    xi_l, xi_r = g.frames[0, 0], g.frames[1, 0]
    assert np.allclose(mirror @ xi_l, -xi_r, atol=1e-15), f"xi_OL {xi_l}, xi_OR {xi_r}"
    assert np.allclose(mirror @ g.frames[0, 2], g.frames[1, 2], atol=1e-15)
    assert xi_l[0] < 0 and xi_r[0] < 0


@pytest.mark.parametrize("inertia", [True, False])
def test_symmetric_cylinder_tangential_forces_180_deg_apart(inertia):
    """Moment balance of the cylinder about its axis (Eq. 12, phi_y row): a tangential force
    F_xi at the surface point -rho n (rho the radius) has the moment -rho F_xi about y at both
    contacts (xi_c = eta x zeta_c), so

        F_xi,OL + F_xi,OR = -Omega^2 I_yy phi_D,y / rho      (forces on the platforms)

    i.e. F_xi,OR = -F_xi,OL exactly without damper inertia (180 deg, equal magnitude: the
    paper's Fig. 11 left) and up to the small roll-inertia term with it. Checked at the
    resonance of the 1 g cylinder, where the contacts slip."""
    r = frf("cylinder", REFERENCE_MASS["cylinder"], damper_inertia=inertia)
    _, f, i = peak(r)
    F = complex_h1(r, r.contact_force[i:i + 1])[0]
    W = complex_h1(r, r.relative_motion[i:i + 1])[0]
    fl, fr = F[0], F[6]
    ratio = fr / fl
    phase = np.degrees(np.angle(ratio)) % 360
    w_phase = np.degrees(np.angle(W[6] / W[0])) % 360
    g = r.disk.damper_geometry()
    rho = r.disk.damper.radius
    j = r.dof_names.index("phiD_y")
    phi_y = complex_h1(r, r.coefficients[i:i + 1, :, j])[0]
    inertia_term = -r.omega[i] ** 2 * g.inertia[4, 4] * phi_y / rho if inertia else 0.0
    balance = abs(fl + fr - inertia_term) / abs(fl)
    slip = r.point_state[i, ..., 1].max()
    mu_n = 0.3 * r.normal_load[i]
    print(f"\n[Fig. 11 left, cylinder, inertia={inertia}] at {f:.3f} Hz: F_xi,OL = {fl:.4f} N, F_xi,OR = {fr:.4f} N, "
          f"phase {phase:.3f} deg, |F_OR|/|F_OL| = {abs(ratio):.5f}; w_xi phase {w_phase:.3f} deg, "
          f"|w_OR|/|w_OL| = {abs(W[6] / W[0]):.4f}; moment balance residual {balance:.1e}; "
          f"mu N = {mu_n}, slip fraction {slip}")
    assert slip > 0.2 and abs(fl) > 0.5 * mu_n[0], "the comparison must be made in slip"
    assert balance < 1e-8, f"cylinder moment balance violated: {balance:.2e}"
    tol_deg, tol_mag = (0.5, 0.01) if inertia else (1e-6, 1e-9)
    assert abs(phase - 180.0) < tol_deg, f"F_xi,OR / F_xi,OL phase {phase:.4f} deg"
    assert abs(abs(ratio) - 1) < tol_mag, f"|F_xi,OR| / |F_xi,OL| = {abs(ratio):.6f}"
    if not inertia:
        # equal and opposite forces of the same (odd) contact law: equal and opposite motions
        assert abs(W[6] / W[0] + 1) < 1e-6, f"w_xi,OR / w_xi,OL = {W[6] / W[0]}"


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
@pytest.mark.parametrize("harmonics", HARMONICS)
def test_damper_equilibrium_eq12(kind, harmonics):
    """Eq. 12 per harmonic h at the resonance: G_D^T F_h = (h Omega)^2 I_D u_D,h (forces on the
    platforms; F recomputed from the per-point contact forces). Reported for the wedge as well:
    its tangential forces are NOT 180 deg apart (its normal forces carry moments too)."""
    r = frf(kind, REFERENCE_MASS[kind], harmonics)
    _, f, i = peak(r)
    g = r.disk.damper_geometry()
    nm = r.disk.blade.n_modes
    basis = r.basis
    F = basis.to_complex(r.contact_force[i])
    U = basis.to_complex(r.coefficients[i, :, nm:])
    worst = 0.0
    for h in basis.harmonics:
        lhs = g.G_D.T @ F[h]
        rhs = (h * r.omega[i]) ** 2 * g.inertia @ U[h]
        if h == 0:
            F_cg = r.disk.centrifugal_force(r.frequency_hz[i])[0]
            # static: F_CG radially outwards on the damper, minus the static retention spring
            # (a fraction of k_N on the static damper position, see TunedDisk.hbm_system)
            rhs = np.array([0, 0, F_cg, 0, 0, 0]) - r.disk.hbm_system(harmonics).static_stiffness[nm:, nm:] @ U[0].real
        worst = max(worst, np.abs(lhs - rhs).max() / np.abs(F[1]).max())
    F1 = F[1]
    print(f"\n[Eq. 12 {kind} H={harmonics}] at {f:.3f} Hz: max |G_D^T F - Omega^2 I_D u_D| / |F| = {worst:.1e}; "
          f"F_xi,OR/F_xi,OL = {abs(F1[6] / F1[0]):.4f} at {np.degrees(np.angle(F1[6] / F1[0])):.2f} deg")
    assert worst < 1e-7, f"damper equilibrium (Eq. 12) violated by {worst:.2e}"


# ---------------------------------------------------------------------------------------
# 4. energy balance
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
@pytest.mark.parametrize("harmonics", HARMONICS)
def test_energy_balance_at_every_point(kind, harmonics):
    """W_exc = W_viscous + W_friction per period at every converged point, W_friction summed from
    the per-point forces and displacements (not from the residual assembly)."""
    r = frf(kind, REFERENCE_MASS[kind], harmonics)
    err = r.energy_balance_error()
    share = r.dissipated_energy / r.excitation_work
    print(f"\n[energy {kind} H={harmonics}] {len(r.omega)} points: max rel. error {err.max():.2e}; "
          f"friction share of the excitation work {share.min():.3f}..{share.max():.3f}")
    assert err.max() < 1e-6, f"energy balance error {err.max():.2e} at {r.frequency_hz[np.argmax(err)]:.3f} Hz"
    assert share.max() > 0.5, "friction must carry a real part of the energy for the check to mean anything"


def test_one_harmonic_mean_normal_load_is_the_frictionless_static_load():
    """With harmonics (1,) the preload is the seated static approach: without lift-off the mean
    normal load of each contact is F_CG(Omega) sin(gamma) / sin(2 gamma) at every point."""
    r = frf("cylinder", REFERENCE_MASS["cylinder"])
    gamma = r.disk.gamma_left
    F = np.array([r.disk.centrifugal_force(f)[0] for f in r.frequency_hz])
    expected = F * np.sin(gamma) / np.sin(2 * gamma)
    assert r.point_state[..., 2].max() == 0
    err = np.abs(r.normal_load - expected[:, None]).max() / expected.max()
    assert err < 1e-9, f"mean normal load differs from the frictionless static load by {err:.1e}"


# ---------------------------------------------------------------------------------------
# 6. damper inertia
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_small_damper_inertia_is_negligible(kind):
    """Paper: "the inertia properties of the damper may be neglected because of a small damper
    mass". At the reference masses (1 g, 0.28 g) switching I_D off changes the resonance peak by
    less than 1 % and its frequency by less than 0.05 Hz (a quarter of the undamped half-power
    bandwidth, 2 D f = 0.19 Hz)."""
    m = REFERENCE_MASS[kind]
    p1, f1, _ = peak(frf(kind, m))
    p0, f0, _ = peak(frf(kind, m, damper_inertia=False))
    print(f"\n[inertia {kind} {m * 1e3:g} g] with {p1 * 1e3:.5f} mm at {f1:.4f} Hz, without {p0 * 1e3:.5f} mm "
          f"at {f0:.4f} Hz: peak {p1 / p0 - 1:+.2e}, frequency {f1 - f0:+.4f} Hz")
    assert abs(p1 / p0 - 1) < 0.01 and abs(f1 - f0) < 0.05


def test_heavy_damper_inertia_matters():
    """A 100 g damper sticks; its mass rides on the platforms and lowers the stuck resonance
    from 95.73 Hz (no inertia) by several Hz. The stuck linear system (built independently) shows
    the same shift, so it is the damper's inertia, not a change of contact state."""
    rng = (90.0, 98.0)
    r1 = frf("cylinder", 0.1, f_range=rng)
    r0 = frf("cylinder", 0.1, f_range=rng, damper_inertia=False)
    p1, f1, i1 = peak(r1)
    p0, f0, i0 = peak(r0)
    grid = 2 * np.pi * np.linspace(*rng, 8001)
    lin1 = stuck_linear_tip(r1.disk, grid)[:, 0]
    lin0 = stuck_linear_tip(r0.disk, grid)[:, 0]
    fl1, fl0 = grid[np.argmax(lin1)] / 2 / np.pi, grid[np.argmax(lin0)] / 2 / np.pi
    # amplitude at the inertia-on resonance frequency, both models
    a_on = r1.tip_amplitude[i1, 0]
    a_off = np.interp(r1.frequency_hz[i1], r0.frequency_hz, r0.tip_amplitude[:, 0])
    print(f"\n[inertia 100 g] with I_D: {p1 * 1e3:.4f} mm at {f1:.3f} Hz; without: {p0 * 1e3:.4f} mm at {f0:.3f} Hz "
          f"(shift {f1 - f0:+.3f} Hz; stuck linear {fl1:.3f} / {fl0:.3f} Hz); at {r1.frequency_hz[i1]:.3f} Hz "
          f"{a_on * 1e3:.4f} mm vs {a_off * 1e3:.4f} mm without inertia (x{a_on / a_off:.1f})")
    assert f0 - f1 > 1.0, f"100 g inertia shifts the resonance by only {f1 - f0:+.3f} Hz"
    assert a_on / a_off > 2
    assert abs(f1 - fl1) < 0.01 and abs(f0 - fl0) < 0.01


# ---------------------------------------------------------------------------------------
# 7. one harmonic (the paper) vs harmonics (0, 1, 2, 3)
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_one_harmonic_vs_multi_harmonic_peak(kind):
    """The paper's one-harmonic balance against a static + three harmonics. Bound: 10 %. Single-
    harmonic friction-damper peaks are known to be accurate to a few per cent when the contact
    stays closed; the static harmonic lets the mean normal load move when points lift off (the
    wedge, paper Fig. 9), which the one-harmonic model with a fixed seated preload cannot do."""
    m = REFERENCE_MASS[kind]
    r1 = frf(kind, m, (1,))
    r3 = frf(kind, m, (0, 1, 2, 3))
    p1, f1, i1 = peak(r1)
    p3, f3, i3 = peak(r3)
    diff = p3 / p1 - 1
    sep1 = r1.point_state[i1, ..., 2].max()
    print(f"\n[H=(1,) vs (0,1,2,3) {kind} {m * 1e3:g} g] {p1 * 1e3:.5f} mm at {f1:.3f} Hz vs {p3 * 1e3:.5f} mm at "
          f"{f3:.3f} Hz: difference {diff:+.2%}; mean normal loads {r1.normal_load[i1]} / {r3.normal_load[i3]} N; "
          f"max separated fraction {sep1:.3f} / {r3.point_state[i3, ..., 2].max():.3f}")
    assert np.isfinite(diff) and abs(diff) < 0.10, f"one vs multi-harmonic peak differ by {diff:+.2%}"


# ---------------------------------------------------------------------------------------
# mirror symmetry (paper: "the same results are obtained if the left and right platform
# angle are exchanged")
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_exchanged_platform_angles_standing_wave(kind):
    """EO = 0 is a standing wave: (gamma_L, gamma_R) = (35, 55) deg and (55, 35) deg are mirror
    images of each other and have the same peak."""
    m = REFERENCE_MASS[kind]
    base = reference_disk(kind, m, engine_order=0, rotor_speed_hz=ROTOR_SPEED_95_HZ)
    peaks = []
    for angles in [(35.0, 55.0), (55.0, 35.0)]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = with_angles(base, *angles).frequency_response(*F_RANGE, harmonics=(1,), max_step=MAX_STEP)
        assert r.success, r.message
        peaks.append(peak(r)[:2])
    rel = abs(peaks[1][0] / peaks[0][0] - 1)
    print(f"\n[mirror EO=0 {kind}] (35,55): {peaks[0][0] * 1e3:.6f} mm at {peaks[0][1]:.4f} Hz, "
          f"(55,35): {peaks[1][0] * 1e3:.6f} mm at {peaks[1][1]:.4f} Hz, rel. difference {rel:.1e}")
    assert rel < 1e-6, f"exchanging the platform angles changes the EO=0 peak by {rel:.2e}"


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_exchanged_platform_angles_travelling_wave(kind):
    """EO = 1 is a travelling wave: the mirror image of (gamma_L, gamma_R) under EO is
    (gamma_R, gamma_L) under -EO. That pair gives the same u_x,tip at the same frequencies (to
    Newton precision). Exchanging the angles alone also reverses the wave relative to the
    platforms; that difference is printed, not asserted (forward and backward waves differ when
    the sector is not mirror-symmetric)."""
    m = REFERENCE_MASS[kind]
    base = reference_disk(kind, m)
    a = with_angles(base, 35.0, 55.0)
    b = with_angles(base, 55.0, 35.0, BackwardWave)
    c = with_angles(base, 55.0, 35.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ra, rb, rc = (d.frequency_response(*F_RANGE, harmonics=(1,), max_step=MAX_STEP) for d in (a, b, c))
    assert ra.success and rb.success and rc.success
    pa, fa, ia = peak(ra)
    omegas = ra.omega[max(ia - 3, 0):ia + 4]
    ta = ra.tip_amplitude[max(ia - 3, 0):ia + 4, 0]
    tb = tip_at(b, rb, omegas)
    rel = np.abs(tb / ta - 1).max()
    pc = peak(rc)[0]
    print(f"\n[mirror EO=1 {kind}] (35,55) EO=+1 vs (55,35) EO=-1 at {len(omegas)} frequencies around "
          f"{fa:.3f} Hz: max rel. difference {rel:.1e}; (55,35) EO=+1 peak {pc * 1e3:.5f} mm vs "
          f"{pa * 1e3:.5f} mm ({pc / pa - 1:+.2%})")
    assert rel < 1e-7, f"mirror-image configurations differ by {rel:.2e}"


# ---------------------------------------------------------------------------------------
# analytic Jacobian vs finite differences
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
@pytest.mark.parametrize("harmonics", HARMONICS)
def test_residual_jacobian_matches_finite_differences(kind, harmonics):
    """dR/dx and dR/dOmega of TunedDisk.hbm_system(...).residual against central differences
    (steps 1e-6 of each unknown's scale on the branch, 1e-6 Omega) at the resonance, a slipping
    state. Bound 1e-6 of the largest entry: central-difference truncation and rounding are ~1e-10
    here (the wedge reaches 1e-12)."""
    r = frf(kind, REFERENCE_MASS[kind], harmonics)
    _, f, i = peak(r)
    system = r.disk.hbm_system(harmonics)
    x, w = r.coefficients[i].ravel(), r.omega[i]
    slip = r.point_state[i, ..., 1].mean()
    assert slip > 0.2, f"not a slipping state (mean slip fraction {slip})"
    scale = np.abs(r.coefficients).max(axis=0).ravel()
    scale = np.maximum(scale, 1e-3 * scale.max())
    R, J, Rw = system.residual(x, w)
    J_fd = central_difference(lambda y: system.residual(y, w, jacobian=False)[0], x, 1e-6 * scale)
    h = 1e-6 * w
    Rw_fd = (system.residual(x, w + h, False)[0] - system.residual(x, w - h, False)[0]) / (2 * h)
    err_x = relative_matrix_error(J * scale, J_fd * scale)
    err_w = float(np.abs(Rw - Rw_fd).max() / np.abs(Rw).max())
    print(f"\n[Jacobian {kind} H={harmonics}] at {f:.3f} Hz (slip fraction {slip:.2f}): dR/dx {err_x:.1e}, "
          f"dR/dOmega {err_w:.1e}")
    assert err_w < 1e-6, f"dR/dOmega differs from central differences by {err_w:.2e}"
    assert err_x < 1e-6, f"dR/dx differs from central differences by {err_x:.2e}"


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_omega_derivative_of_the_rotor_speed_dependent_preload(exponent):
    """With one harmonic the preload follows F_CG(Omega) (Eq. 26). dR/dOmega against central
    differences at a slipping state, for the linear normal law (Euler-identity path) and the
    rough-surface power law p = 1.5 (forward-difference path)."""
    from bladedamp.reference import reference_damper
    r = frf("cylinder", REFERENCE_MASS["cylinder"])
    _, _, i = peak(r)
    disk = dataclasses.replace(r.disk, damper=reference_damper("cylinder", REFERENCE_MASS["cylinder"],
                                                               roughness_exponent=exponent))
    system = disk.hbm_system((1,))
    x, w = r.coefficients[i].ravel(), r.omega[i]
    _, _, Rw = system.residual(x, w)
    h = 1e-6 * w
    Rw_fd = (system.residual(x, w + h, False)[0] - system.residual(x, w - h, False)[0]) / (2 * h)
    err = float(np.abs(Rw - Rw_fd).max() / np.abs(Rw).max())
    print(f"\n[dR/dOmega, normal-law exponent {exponent}] rel. error {err:.1e}")
    assert err < 1e-6, f"dR/dOmega differs from central differences by {err:.2e}"


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
@pytest.mark.parametrize("harmonics", HARMONICS)
def test_merged_patch_evaluation_equals_separate_patches(kind, harmonics):
    """DamperContacts.harmonic_forces evaluates both patches in one call of the fused kernel (speed);
    forces, Jacobian and omega-derivative must equal those of two ContactPatch.evaluate calls."""
    r = frf(kind, REFERENCE_MASS[kind], harmonics)
    _, _, i = peak(r)
    system = r.disk.hbm_system(harmonics)
    coupling = system.couplings[0]
    C, w = system.basis.n_coeffs, r.omega[i]
    local = (coupling.matrix @ r.coefficients[i].ravel()).reshape(C, 12)
    force, jac, domega = coupling.element.harmonic_forces(local, system.basis, w)
    offsets, doffsets = coupling.element.approach(w)
    evs = [p.evaluate(local[:, 6 * c:6 * c + 6], system.basis, offsets[c]) for c, p in enumerate(coupling.element.geometry.patches)]
    ref_force = np.hstack([ev.force for ev in evs])
    ref_jac = np.zeros((C, 12, C, 12))
    for c, ev in enumerate(evs):
        ref_jac[:, 6 * c:6 * c + 6, :, 6 * c:6 * c + 6] = ev.jacobian.reshape(C, 6, C, 6)
    assert np.abs(force - ref_force).max() <= 1e-12 * np.abs(ref_force).max()
    assert np.abs(jac - ref_jac.reshape(C * 12, C * 12)).max() <= 1e-12 * np.abs(ref_jac).max()
    if np.any(doffsets != 0):
        h = 1e-7 * w
        f_h = np.hstack([p.evaluate(local[:, 6 * c:6 * c + 6], system.basis, offsets[c] + h * doffsets[c], False).force
                         for c, p in enumerate(coupling.element.geometry.patches)])
        # both ends of the difference without the Jacobian (with it the return map may take
        # extra passes, which moves the forces at the 1e-11 level)
        f_0 = np.hstack([p.evaluate(local[:, 6 * c:6 * c + 6], system.basis, offsets[c], False).force
                         for c, p in enumerate(coupling.element.geometry.patches)])
        ref_dw = ((f_h - f_0) / h).ravel()
        assert np.abs(domega - ref_dw).max() <= 1e-6 * np.abs(ref_dw).max()
    else:
        assert domega is None


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
@pytest.mark.parametrize("harmonics", HARMONICS)
def test_response_contact_quantities_of_all_points_at_once_equal_point_by_point(kind, harmonics, monkeypatch):
    """DiskResponse.from_branch evaluates the contacts of every branch point in one call of the
    point-contact kernel (DamperContacts.evaluate_states); with the batch switched off it takes
    two ContactPatch.evaluate calls per point. Forces, point motions, dissipation, work bound
    and normal loads must agree to rounding; the stick/slip/separated shares to one sample
    (a sample exactly at the slip limit may fall either way by rounding)."""
    r = frf(kind, REFERENCE_MASS[kind], harmonics)
    system = r.disk.hbm_system(harmonics, r.basis.n_samples)
    branch = Branch(r.omega, r.coefficients.reshape(len(r.omega), -1), np.zeros(len(r.omega), dtype=int), True, "")
    batched = DiskResponse.from_branch(r.disk, system, branch)
    monkeypatch.setattr(DamperContacts, "stacked_points", lambda self: None)
    separate = DiskResponse.from_branch(r.disk, r.disk.hbm_system(harmonics, r.basis.n_samples), branch)
    for name in ("contact_force", "relative_motion", "point_displacement", "point_dissipation", "point_work_bound",
                 "normal_load", "dissipated_energy"):
        a, b = getattr(batched, name), getattr(separate, name)
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max(), name
    assert np.abs(batched.point_state - separate.point_state).max() <= 1.0 / r.basis.n_samples + 1e-15
    assert np.mean(batched.point_state != separate.point_state) < 1e-3


# ---------------------------------------------------------------------------------------
# 8. bad input
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("call, match", [
    (lambda: reference_disk("cylinder", 1e-3, engine_order=2.5), "engine_order"),
    (lambda: reference_disk("cylinder", 1e-3, engine_order=-1), "engine_order"),
    (lambda: dataclasses.replace(reference_disk("cylinder"), gamma_left=0.0), "gamma_left"),
    (lambda: dataclasses.replace(reference_disk("cylinder"), gamma_right=np.pi / 2), "gamma_right"),
    (lambda: dataclasses.replace(reference_disk("wedge"), gamma_right=np.radians(95.0)), "gamma_right"),
    (lambda: reference_disk("cylinder", -1e-3), "damper mass"),
    (lambda: reference_disk("cylinder", 1e-3, engine_order=0), "rotor_speed_hz"),
    (lambda: reference_disk("cylinder", 1e-3, engine_order=0, rotor_speed_hz=-5.0), "rotor_speed_hz"),
    (lambda: reference_disk("cylinder", 1e-3, engine_order=0, rotor_speed_hz=float("nan")), "rotor_speed_hz"),
    (lambda: reference_disk("cylinder", excitation=[0.1, 0.0]), "excitation"),
    (lambda: reference_disk("cylinder").frequency_response(92.0, 92.0), "f_end_hz"),
    (lambda: reference_disk("cylinder").frequency_response(-1.0, 92.0), "f_start_hz"),
])
def test_bad_disk_input_raises_value_error_naming_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_wedge_without_contact_height_is_rejected():
    from bladedamp.damper import WedgeDamper
    with pytest.raises(ValueError, match="contact_height"):
        TunedDisk(reference_disk("wedge").blade, WedgeDamper(1e-3, contact_height=None))


@pytest.mark.parametrize("engine_order", [1, 2])
def test_rotor_speed_in_hz_at_omega_e_over_eo_is_the_automatic_preload(engine_order):
    """``rotor_speed_hz`` is the rotor's revolutions per second: given at f / EO it is the speed
    the automatic law (Omega_R = Omega_E / EO, Eq. 3, 26) takes at the excitation frequency f, so
    F_CG, the seating loads and the one-harmonic residual at f are those of the automatic disk
    (only dF_CG / dOmega differs: a fixed speed does not follow the excitation); a speed in rpm
    (60 times too large) is flagged."""
    import warnings

    from bladedamp.validation import PlausibilityWarning

    f = 95.3
    auto = reference_disk("cylinder", 1e-3, engine_order=engine_order)
    fixed = reference_disk("cylinder", 1e-3, engine_order=engine_order, rotor_speed_hz=f / engine_order)
    assert fixed.centrifugal_force(f)[0] == pytest.approx(auto.centrifugal_force(f)[0], rel=1e-14)
    assert fixed.centrifugal_force(f)[1] == 0.0 and auto.centrifugal_force(f)[1] > 0
    assert fixed.centrifugal_force(1.5 * f)[0] == pytest.approx(fixed.centrifugal_force(f)[0], rel=1e-14)
    np.testing.assert_allclose(fixed.static_normal_loads(f), auto.static_normal_loads(f), rtol=1e-12)
    x = auto.initial_guess(auto.hbm_system((1,)), 2 * np.pi * f)
    R_auto = auto.hbm_system((1,)).residual(x, 2 * np.pi * f, False)[0]
    R_fixed = fixed.hbm_system((1,)).residual(x, 2 * np.pi * f, False)[0]
    np.testing.assert_allclose(R_fixed, R_auto, rtol=0, atol=1e-12 * np.abs(R_auto).max())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert dataclasses.replace(fixed, engine_order=1).rotor_speed_hz == fixed.rotor_speed_hz
    with pytest.warns(PlausibilityWarning, match="rotor_speed_hz"):
        reference_disk("cylinder", 1e-3, engine_order=0, rotor_speed_hz=60 * 95.0)      # rpm given as Hz


def test_a_failed_branch_says_what_the_damper_did_where_it_got_furthest():
    """A branch that does not reach the end (here: stopped by max_points) names the frequency it
    got furthest to and the contact points' stick / slip / separated shares there (which sum to
    100 %), read from the response's own point states; a successful branch has no such note."""
    disk = reference_disk("wedge", 0.3e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(93.0, 97.0, harmonics=(1,), max_step=0.05, max_points=12)
    assert not r.success
    k = r.furthest_index()
    assert k == int(np.argmax(r.omega))                       # an upward branch
    shares = r.contact_state_shares()
    assert shares.shape == (len(r.omega), 3) and np.allclose(shares.sum(axis=1), 1.0)
    stick, slip, separated = 100 * shares[k]
    assert (f"where the branch got furthest ({r.frequency_hz[k]:.4f} Hz" in r.message
            and f"stick {stick:.0f} %, slip {slip:.0f} %, are separated {separated:.0f} %" in r.message)
    assert "got furthest" not in frf("wedge", 0.3e-3, f_range=(93.0, 94.0)).message


def test_furthest_index_of_a_branch_that_turned_back():
    """The furthest point of a branch that went up to 10 and came back to 2 is the one at 10,
    of a downward branch the lowest frequency."""
    from bladedamp.disk import DiskResponse
    from bladedamp.hbm.fourier import HarmonicBasis

    def response(omega):
        return DiskResponse(np.asarray(omega, dtype=float), np.zeros((len(omega), 3, 1)), HarmonicBasis((1,)),
                            ("q",), False, "")
    assert response([1.0, 5.0, 10.0, 6.0, 2.0]).furthest_index() == 2
    assert response([10.0, 4.0, 3.0, 8.0]).furthest_index() == 2


def test_check_stop_keeps_the_time_integration_beyond_a_failed_branch_and_says_what_it_found(tmp_path):
    """``check_stop=True``: a branch that stops before the end (here cut by max_points, a 4-blade
    disk with the 1 g cylinder, (0, 1)) gets the full assembly's time integration 0.05 Hz beyond
    its furthest point as ``stop_check``; its verdict is in the message, and it is right: there
    the motion is periodic, with the first-harmonic tip amplitude of the complete HBM branch at
    that frequency (independent: the HBM's own answer, interpolated, within 1 %). It survives
    save / load. A branch that reaches the end, or is stopped by stop_above, runs no check."""
    from bladedamp import load
    from bladedamp.diskmodel import STOP_CHECK_OFFSET_HZ

    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cut = disk.frequency_response(90.0, 100.0, harmonics=(0, 1), max_points=15, check_stop=True)
        full = disk.frequency_response(90.0, 100.0, harmonics=(0, 1), check_stop=True)
        stopped = disk.frequency_response(90.0, 100.0, harmonics=(0, 1), stop_above=1e-5, check_stop=True)
    assert full.success and full.stop_check is None and stopped.stop_check is None
    check = cut.stop_check
    f = check.frequency_hz[0]
    assert not cut.success and f == pytest.approx(cut.frequency_hz.max() + STOP_CHECK_OFFSET_HZ, rel=1e-12)
    assert check.periodic[0] and "settles on a periodic motion" in cut.message and f"{f:.4f} Hz" in cut.message
    assert "check_stop=True) runs it" not in cut.message               # the verdict replaces how to tell
    hbm = np.interp(f, full.frequency_hz, full.tip_amplitude[:, 0])
    assert check.tip_amplitude[0, :, 0] == pytest.approx(hbm, rel=1e-2)
    back = load(cut.save(tmp_path / "cut"))
    assert back.message == cut.message and back.stop_check.periodic[0]
    np.testing.assert_array_equal(back.stop_check.tip_amplitude, check.tip_amplitude)
    with pytest.raises(ValueError, match="extra_couplings"):
        disk.frequency_response(90.0, 100.0, check_stop=True, extra_couplings=lambda basis: [])


def test_check_peak_estimates_the_harmonic_error_by_time_integration(monkeypatch):
    """``check_peak=True``: the full assembly integrated at the peak's frequency gives a direct
    harmonic error estimate, independent of the enriched set's. The 4-blade disk with the 1 g
    cylinder at its 102 Hz resonance, (0, 1): there the cylinder keeps rolling while the blades'
    vibration settles ("drifting", test_timedomain_disk.py), and the (0, 1) tip amplitudes are
    measured 4.1 % from the time integration's mean, against 4.0 % from (0, 1, 2, 3): the two
    estimates agree within a quarter; the larger is kept, above the 1 % tolerance, and the
    message says the damper drifts. The mistuned full assembly of the same disk gives the same.
    Without ``check_peak`` nothing is integrated; ``peak_check`` on demand integrates at the
    peak's frequency; bad input. (Unverified estimates and a peak without periodic motion:
    random disks 63 and 51 in test_random_designs.py.)"""
    from bladedamp.disk import DiskResponse, TunedDisk
    from bladedamp.hbm.fourier import HarmonicBasis
    from bladedamp.mistuned import MistunedDisk

    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = disk.frequency_response(97.0, 106.0, harmonics=(0, 1))
        checked = disk.frequency_response(97.0, 106.0, harmonics=(0, 1), check_peak=True)
        mistuned = MistunedDisk.from_tuned(disk).frequency_response(97.0, 106.0, harmonics=(0, 1), check_peak=True)
    assert plain.peak_check is None and 0.02 < plain.harmonic_error < 0.08
    check = checked.peak_check
    assert check.status[0] == "drifting" and checked.success and "keeps rolling or walking" in checked.message
    # its status: a drift, which a richer harmonic set does not remove, with the error it costs
    assert "keeps rolling at the peak" in checked.status_message
    assert f"to {100 * checked.harmonic_error:.2g} % only" in checked.status_message
    k = int(np.argmax(checked.tip_amplitude.max(axis=1)))
    assert check.frequency_hz[0] == checked.frequency_hz[k]
    direct = np.abs(check.tip_amplitude[0].max(axis=0) - checked.tip_amplitude[k]).max() / checked.tip_amplitude.max()
    assert direct == pytest.approx(plain.harmonic_error, rel=0.25)
    assert checked.harmonic_error == max(direct, plain.harmonic_error) and checked.harmonics_converged is False
    assert mistuned.harmonic_error == pytest.approx(checked.harmonic_error, rel=0.02)
    assert mistuned.peak_check.status[0] == "drifting"
    assert check.start[0] == mistuned.peak_check.start[0] == "HBM solution"      # both start on their branch
    monkeypatch.setattr(TunedDisk, "time_response", lambda *a, **k: pytest.fail("no time integration expected"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        again = disk.frequency_response(97.0, 106.0, harmonics=(0, 1))
    assert again.peak_check is None and again.message == plain.message
    asked = []
    monkeypatch.setattr(TunedDisk, "time_response", lambda self, f, **k: asked.append(f))
    disk.peak_check(plain)
    assert asked == [plain.frequency_hz[np.argmax(plain.tip_amplitude.max(axis=1))]]
    with pytest.raises(ValueError, match="at least one point"):
        disk.peak_check(DiskResponse(np.zeros(0), np.zeros((0, 3, 1)), HarmonicBasis((1,)), ("q",), False, ""))
    with pytest.raises(ValueError, match="check_peak .*extra_couplings"):
        disk.frequency_response(90.0, 100.0, check_peak=True, extra_couplings=lambda basis: [])
    with pytest.raises(ValueError, match="start must be"):
        disk.peak_check(plain, start="rest")


def test_check_peak_starts_on_the_hbm_solution(monkeypatch):
    """The peak check starts the time integration on the branch's own state at the peak
    (displacements and velocities from the Fourier series, the sliders from the contact's return
    map over one period: bladedamp.hbm.monodromy.orbit_state), so it tests that branch. The
    4-blade disk with the 1 g cylinder, (0, 1): the first period reproduces the branch's
    first-harmonic tip amplitudes to its one-period defect (measured 0.14 %), and the motion it
    settles on (the cylinder rolling, "drifting") lies within the stated truncation error of the
    branch (the enriched set's estimate, 4.0 %; measured 4.1 %), far inside the distance a motion
    on the branch may settle at (the defect / (1 - exp(-sigma T)), sigma the blades' slowest
    viscous decay): the same motion, no coexisting one; the message says which start it used.
    The integration from the static equilibrium reaches the same motion. A motion farther than
    that bound (the settled amplitudes replaced by half the branch's) is reported as a coexisting
    motion, a note that leaves the harmonic error estimate the enriched set's."""
    from bladedamp.disk import TunedDisk
    from bladedamp.diskmodel import orbit_departure

    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = disk.frequency_response(97.0, 106.0, harmonics=(0, 1))
        checked = disk.frequency_response(97.0, 106.0, harmonics=(0, 1), check_peak=True)
        rest = disk.peak_check(plain, start="static")
    check = checked.peak_check
    assert list(check.start) == ["HBM solution"] and list(rest.start) == ["static equilibrium"]
    assert "started on the HBM solution's state" in checked.message
    k = int(np.argmax(checked.tip_amplitude.max(axis=1)))
    branch, peak = checked.tip_amplitude[k], checked.tip_amplitude[k].max()
    first = np.abs(check.tip_history[0][0]).max(axis=0)
    defect = np.abs(first - branch).max() / peak
    settled = np.abs(check.tip_amplitude[0].max(axis=0) - branch).max() / peak
    sigma_t = check.decay_rate * 2 * np.pi / check.omega[0]
    assert sigma_t == pytest.approx(1e-3 * 95.0 / check.frequency_hz[0] * 2 * np.pi, rel=1e-6)
    assert defect < 0.01 and settled <= 1.25 * plain.harmonic_error and settled < defect / -np.expm1(-sigma_t)
    assert orbit_departure(disk, check, branch, peak, settled, 0.01) is None
    assert checked.harmonic_error == pytest.approx(max(settled, plain.harmonic_error), rel=1e-9)
    assert rest.status[0] == check.status[0] == "drifting"
    assert np.abs(rest.tip_amplitude[0] - check.tip_amplitude[0]).max() / peak < 2e-3
    # a motion that left the branch: half its amplitudes, beyond the bound
    far = dataclasses.replace(check, tip_amplitude=0.5 * check.tip_amplitude)
    note = orbit_departure(disk, far, branch, peak, 0.5, 0.01)
    assert note is not None and "beyond the" in note
    monkeypatch.setattr(TunedDisk, "peak_check", lambda self, response, **k: far)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        left = disk.frequency_response(97.0, 106.0, harmonics=(0, 1), check_peak=True)
    assert "leaves the branch for a coexisting periodic motion" in left.message
    assert left.harmonic_error == plain.harmonic_error and left.harmonics_converged is plain.harmonics_converged
    assert left.peak_check is far


def test_stop_check_bad_input():
    from bladedamp.disk import DiskResponse
    from bladedamp.hbm.fourier import HarmonicBasis

    disk = reference_disk("wedge", 0.3e-3)
    empty = DiskResponse(np.zeros(0), np.zeros((0, 3, 1)), HarmonicBasis((1,)), ("q",), False, "")
    with pytest.raises(ValueError, match="at least one point"):
        disk.stop_check(empty)
    with pytest.raises(ValueError, match="f_start_hz"):
        disk.stop_check(empty, f_start_hz=-1.0)
    one = DiskResponse(np.array([600.0]), np.zeros((1, 3, 1)), HarmonicBasis((1,)), ("q",), False, "")
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="offset_hz"):
            disk.stop_check(one, offset_hz=bad)


def test_stop_above_ends_the_branch_at_the_first_point_above_it_and_retries_nothing():
    """``stop_above`` (the mass search's branch and bound): the reference 1 g cylinder's branch
    stops at its first point above 0.3 mm (the peak is 0.489 mm), with the points of the full
    branch up to there, not success, no finer AFT, no error estimate and no stop-check note."""
    disk = reference_disk("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = disk.frequency_response(*F_RANGE, harmonics=(1,), max_step=MAX_STEP)
        cut = disk.frequency_response(*F_RANGE, harmonics=(1,), max_step=MAX_STEP, stop_above=3e-4)
    assert full.success and not full.stopped_by
    k = len(cut.omega)
    assert not cut.success and "above stop_above = 0.3 mm" in cut.stopped_by and cut.stopped_by in cut.message
    assert 1 < k < len(full.omega) and cut.tip_amplitude[-1, 0] > 3e-4 and np.all(cut.tip_amplitude[:-1, 0] <= 3e-4)
    np.testing.assert_array_equal(cut.omega, full.omega[:k])
    assert cut.basis.n_samples == full.basis.n_samples and "raised" not in cut.message
    assert np.isnan(cut.harmonic_error) and "stop_check" not in cut.message
    for bad, name in (({"stop_above": -1.0}, "stop_above"), ({"stop_direction": 3}, "stop_direction")):
        with pytest.raises(ValueError, match=name):
            disk.frequency_response(*F_RANGE, harmonics=(1,), **bad)


def test_a_response_without_the_harmonic_error_estimate_is_the_same_branch_and_says_so():
    """``estimate_harmonic_error=False`` (the mass searches, whose harmonic setting is reported
    once): the same branch, its estimate NaN and "not estimated" (harmonics_converged None);
    'auto' chooses by the estimate, so it refuses to go without."""
    disk = reference_disk("cylinder", 1e-3)
    full = frf("cylinder", 1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bare = disk.frequency_response(*F_RANGE, harmonics=(1,), max_step=MAX_STEP, estimate_harmonic_error=False)
    assert np.isfinite(full.harmonic_error) and np.isnan(bare.harmonic_error) and bare.harmonics_converged is None
    np.testing.assert_array_equal(bare.omega, full.omega)
    np.testing.assert_array_equal(bare.tip_amplitude, full.tip_amplitude)
    with pytest.raises(ValueError, match="estimate_harmonic_error"):
        disk.frequency_response(*F_RANGE, harmonics="auto", estimate_harmonic_error=False)


# ---------------------------------------------------------------------------------------
# 9. any engine order: nodal diameter from EO mod n, rotor speed from EO
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("eo, n, expected", [
    (0, 16, (0, "standing")), (1, 16, (1, "forward")), (7, 16, (7, "forward")), (8, 16, (8, "standing")),
    (9, 16, (7, "backward")), (15, 16, (1, "backward")), (16, 16, (0, "standing")), (17, 16, (1, "forward")),
    (41, 16, (7, "backward")), (2, 5, (2, "forward")), (3, 5, (2, "backward")), (10, 5, (0, "standing")),
])
def test_nodal_diameter_of_any_engine_order(eo, n, expected):
    """k = EO mod n, folded to n - k (backward) above n / 2; the interblade phase has
    e^{i dphi} = e^{i 2 pi EO / n} and lies in (-pi, pi], negative for a backward wave."""
    from bladedamp.diskmodel import interblade_phase, nodal_diameter
    assert nodal_diameter(eo, n) == expected
    dphi = interblade_phase(eo, n)
    assert -np.pi < dphi <= np.pi
    assert abs(np.exp(1j * dphi) - np.exp(2j * np.pi * eo / n)) < 1e-13
    assert dphi == (2 * np.pi * expected[0] / n) * (-1 if expected[1] == "backward" else 1)


def test_engine_order_sets_the_preload_and_the_nodal_diameter_only_its_phase():
    """16 blades, EO 9 (nodal diameter 7 backward) and EO 16 (nodal diameter 0): accepted; the
    centrifugal force is m R (Omega_E / EO)^2 with EO itself (Eq. 3, 26), written out here."""
    m, f = 1e-3, 95.0
    for eo in (9, 16, 25):
        disk = reference_disk("cylinder", m, engine_order=eo)
        force, dforce = disk.centrifugal_force(f)
        omega_e = 2 * np.pi * f
        assert force == pytest.approx(m * disk.damper_radius * (omega_e / eo) ** 2, rel=1e-14)
        assert dforce == pytest.approx(2 * m * disk.damper_radius * omega_e / eo ** 2, rel=1e-14)
    assert reference_disk("cylinder", m, engine_order=9).nodal_diameter == (7, "backward")
    assert reference_disk("cylinder", m, engine_order=16).interblade_phase == 0.0


def test_backward_wave_differs_from_forward_by_the_preload_only():
    """4 blades, EO 3 (nodal diameter 1 backward) against EO 1 (forward). Without the damper's
    inertia its mass enters only through the preload m R (Omega_E / EO)^2, so EO 3 with 9 times
    the mass has EO 1's preload at every frequency; the reference disk is mirror-symmetric
    (gamma_L = gamma_R, the beam blade symmetric about its axis), and the mirror image of a
    backward wave is the forward one: the two frequency responses are equal to rounding.
    With the same mass the preload differs (by 1/9) and so does the peak."""
    def tuned(eo, mass):
        return dataclasses.replace(reference_disk("cylinder", mass, engine_order=eo, damper_inertia=False),
                                   n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        forward = tuned(1, 1e-3).frequency_response(92.0, 104.0, harmonics=(1,), max_step=0.05)
        backward = tuned(3, 9e-3).frequency_response(92.0, 104.0, harmonics=(1,), max_step=0.05)
        lighter = tuned(3, 1e-3).frequency_response(92.0, 104.0, harmonics=(1,), max_step=0.05)
    assert forward.success and backward.success and lighter.success
    assert tuned(3, 9e-3).centrifugal_force(97.0) == pytest.approx(tuned(1, 1e-3).centrifugal_force(97.0), rel=1e-14)
    assert abs(backward.peak_amplitude - forward.peak_amplitude) < 1e-9 * forward.peak_amplitude
    on_forward = np.interp(forward.frequency_hz, backward.frequency_hz, backward.tip_amplitude[:, 0])
    assert np.abs(on_forward - forward.tip_amplitude[:, 0]).max() < 1e-6 * forward.peak_amplitude
    assert abs(lighter.peak_amplitude - forward.peak_amplitude) > 0.1 * forward.peak_amplitude
