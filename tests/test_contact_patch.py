"""Contact patch (grid of point contacts driven by the control point, paper Eq. 7 and 11).

Closed forms: micro-slip under translation = sum of the points' Jenkins loops; uniform
translation = one point carrying the whole law; stuck rotation and tilt = sums of the point
stiffnesses times r^2; lift-off under rocking starts at the extreme xi. The analytic
Jacobian is compared with central finite differences of the forces.
"""
import zlib

import numpy as np
import pytest
from conftest import central_difference, jenkins_first_harmonic, relative_matrix_error

from bladedamp.contact import (SEPARATED, SLIP, STICK, ContactPatch, LinearNormalLaw, RoughnessNormalLaw,
                               point_contact_forces)
from bladedamp.hbm import HarmonicBasis

K_T = 1.0e5        # total tangential stiffness of the area [N/m]
K_N = 2.0e5        # total normal stiffness [N/m]
MU = 0.4
N0 = 10.0          # total normal preload [N]
HEIGHT, LENGTH = 0.004, 0.02


def patch(law=None, n_xi=3, n_eta=5, weights=None, mu=MU):
    return ContactPatch(HEIGHT, LENGTH, K_T, mu, law or LinearNormalLaw(K_N), n_xi, n_eta, weights)


def control_motion(basis, dof, amplitude, harmonic=1):
    """w with a single control-point DOF moving as amplitude * cos(harmonic tau)."""
    w = np.zeros((basis.n_coeffs, 6))
    w[basis.cos_index(harmonic), dof] = amplitude
    return w


# ---------------------------------------------------------------------------------------
# micro-slip: sum of Jenkins loops
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("law_name", ["linear", "roughness"])
def test_microslip_translation_is_the_sum_of_point_loops(law_name):
    """Points with different normal loads (per-point approach offsets, non-uniform weights)
    under u_xi = A cos tau: some points stick, some slip; the patch's F_xi and M_zeta
    equal the sums of the points' Jenkins closed forms to 1e-10 (T = 2**20)."""
    law = LinearNormalLaw(K_N) if law_name == "linear" else RoughnessNormalLaw(K_N, N0, 1.5)
    n_xi, n_eta = 2, 4
    P = n_xi * n_eta
    weights = np.linspace(1.0, 3.0, P)
    weights /= weights.sum()
    pt = patch(law, n_xi, n_eta, weights)
    loads = N0 * weights * np.linspace(0.2, 1.8, P)            # point loads [N], not proportional to weights
    offset = law.approach_for_load(loads, weights)              # per-point approach giving those loads
    k_p = K_T * weights
    u_stick = MU * loads / k_p                                  # per-point stick limit amplitude
    A = np.median(u_stick)
    basis = HarmonicBasis((1,), 2 ** 20)
    ev = pt.evaluate(control_motion(basis, 0, A), basis, offset, jacobian=False)
    assert np.allclose(ev.points.normal_load[:, 0], loads, rtol=1e-12)
    a1, b1 = jenkins_first_harmonic(k_p, MU * loads, A)
    stuck = k_p * A <= MU * loads
    assert 0 < stuck.sum() < P, f"need a mix of stuck ({stuck.sum()}) and slipping points"
    assert np.all((ev.points.state == SLIP).any(axis=1) == ~stuck)
    j = basis.cos_index(1)
    F = ev.force
    ref = np.array([a1.sum(), b1.sum()])
    err_f = np.hypot(*(F[j:j + 2, 0] - ref)) / np.hypot(*ref)
    ref_m = np.array([(-pt.eta * a1).sum(), (-pt.eta * b1).sum()])   # M_zeta = sum(xi f_eta - eta f_xi)
    err_m = np.hypot(*(F[j:j + 2, 5] - ref_m)) / np.hypot(*ref)
    print(f"F_xi rel err {err_f:.2e}")
    assert err_f < 1e-10, f"F_xi rel err {err_f:.2e}"
    print(f"M_zeta rel err {err_m:.2e}")
    assert err_m < 1e-10 / LENGTH, f"M_zeta rel err {err_m:.2e}"
    # energy: dissipation of the patch = sum of the point dissipations
    W = float(np.sum(basis.work_per_cycle(F, control_motion(basis, 0, A))))
    W_ref = -np.pi * A * b1.sum()
    print(f"dissipation rel err {abs(W / W_ref - 1):.2e}")
    assert abs(W / W_ref - 1) < 1e-10, f"dissipation rel err {abs(W / W_ref - 1):.2e}"


# ---------------------------------------------------------------------------------------
# uniform translation: patch == one point with the whole law
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("law", [LinearNormalLaw(K_N), RoughnessNormalLaw(K_N, N0, 1.5)],
                         ids=["linear", "roughness"])
def test_uniform_translation_equals_single_point(law):
    """With uniform weights, a P-point patch under a translation carries P times the force of
    each of its points and equals one point with the whole law (k_T, weight 1): forces and
    the translational block of the Jacobian, with stick, slip and lift-off."""
    basis = HarmonicBasis((0, 1, 2, 3), 512)
    C = basis.n_coeffs
    pt = patch(law, 3, 5)
    P = pt.n_points
    a0 = law.approach_for_load(N0, 1.0)
    u_star = MU * N0 / K_T
    w = np.zeros((C, 6))
    w[basis.cos_index(1), 0] = 1.0 * u_star
    w[basis.cos_index(1) + 1, 1] = 0.7 * u_star
    w[basis.cos_index(2), 0] = 0.2 * u_star
    w[basis.cos_index(1), 2] = 1.2 * a0          # normal stroke larger than the approach: lift-off
    w[basis.cos_index(0), 2] = 0.1 * a0
    ev = pt.evaluate(w, basis, pt.approach_for_load(N0))
    states = set(np.unique(ev.points.state))
    assert states == {STICK, SLIP, SEPARATED}, f"states {states}"
    # every patch point carries the same force, 1/P of the total
    pf = basis.to_coeffs(np.moveaxis(ev.points.force, 1, 0))   # (C, P, 3)
    assert np.allclose(P * pf, ev.force[:, None, :3], rtol=1e-12, atol=1e-12 * N0)
    single = point_contact_forces(w[:, None, :3], basis, np.array([K_T]), np.array([MU]), law,
                                  np.array([1.0]), np.array([a0]), jacobian=True)
    f1 = basis.to_coeffs(single.force[0])                       # (C, 3)
    err_f = np.abs(ev.force[:, :3] - f1).max() / np.abs(f1).max()
    J1 = np.einsum("at,tik->aik", basis.analysis, single.jacobian[0]).reshape(C, 3, 3, C)  # [a, i, k, b]
    Jp = ev.jacobian.reshape(C, 6, C, 6)[:, :3, :, :3]                                     # [a, i, b, k]
    err_j = relative_matrix_error(Jp, np.transpose(J1, (0, 1, 3, 2)))
    print(f"force rel err {err_f:.2e}, Jacobian rel err {err_j:.2e}")
    assert err_f < 1e-12 and err_j < 1e-12, f"force rel err {err_f:.2e}, Jacobian rel err {err_j:.2e}"
    # symmetric grid: a translation produces no moment about zeta and no tilt moments
    # (to rounding: the point forces are equal and sum(xi) = sum(eta) = 0)
    assert np.abs(ev.force[:, 3:]).max() < 1e-12 * N0 * LENGTH


# ---------------------------------------------------------------------------------------
# rotations and tilts
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("uniform", [True, False], ids=["uniform", "weighted"])
def test_stuck_torsion_moment(uniform):
    """phi_zeta = Phi cos tau, all points stuck: M_zeta = Phi sum(k_T w_p r_p^2), no net force."""
    n_xi, n_eta = 3, 5
    weights = None if uniform else np.linspace(0.5, 1.5, n_xi * n_eta) / (n_xi * n_eta)
    pt = patch(n_xi=n_xi, n_eta=n_eta, weights=weights)
    k_p = K_T * pt.weights
    r2 = pt.xi ** 2 + pt.eta ** 2
    N_p = N0 * pt.weights
    r = np.sqrt(r2)
    Phi = 0.9 * np.min(MU * N_p[r > 0] / (k_p[r > 0] * r[r > 0]))   # every point below its stick limit
    basis = HarmonicBasis((1,), 64)
    ev = pt.evaluate(control_motion(basis, 5, Phi), basis, pt.approach_for_load(N0))
    assert np.all(ev.points.state == STICK)
    M_ref = Phi * np.sum(k_p * r2)
    j = basis.cos_index(1)
    err = abs(ev.force[j, 5] / M_ref - 1)
    print(f"M_zeta rel err {err:.2e}")
    assert err < 1e-12, f"M_zeta rel err {err:.2e}"
    assert abs(ev.force[j + 1, 5]) < 1e-12 * M_ref, "a stuck patch must not dissipate"
    net = np.abs(ev.force[:, :2]).max()
    expected_net = Phi * np.abs([np.sum(k_p * pt.eta), np.sum(k_p * pt.xi)]).max()  # 0 for uniform weights
    assert abs(net - expected_net) < 1e-12 * M_ref / LENGTH
    # beyond the stick limit the torsional stiffness drops (softening, the paper's Fig. 10 trend)
    ev2 = pt.evaluate(control_motion(basis, 5, 5 * Phi), basis, pt.approach_for_load(N0))
    k_eq2 = ev2.force[j, 5] / (5 * Phi)
    assert k_eq2 < 0.99 * np.sum(k_p * r2) and ev2.force[j + 1, 5] < 0


def test_tilt_normal_moment_linear_law():
    """phi_xi = Phi cos tau below lift-off, linear law: M_xi = k_N,p sum(eta^2) Phi (first harmonic)."""
    pt = patch(n_xi=3, n_eta=5)
    offset = pt.approach_for_load(N0)
    Phi = 0.95 * offset[0] / np.abs(pt.eta).max()            # no point separates
    basis = HarmonicBasis((0, 1), 64)
    ev = pt.evaluate(control_motion(basis, 3, Phi), basis, offset)
    assert not np.any(ev.points.state == SEPARATED)
    k_np = K_N * pt.weights
    M_ref = Phi * np.sum(k_np * pt.eta ** 2)
    j = basis.cos_index(1)
    err = abs(ev.force[j, 3] / M_ref - 1)
    print(f"M_xi rel err {err:.2e}")
    assert err < 1e-12, f"M_xi rel err {err:.2e}"
    # the static normal force is the preload (on the platform: -N0), no static moment
    assert abs(ev.force[basis.cos_index(0), 2] / -N0 - 1) < 1e-12
    assert abs(ev.force[basis.cos_index(0), 3]) < 1e-12 * N0 * LENGTH
    assert np.abs(ev.force[:, :2]).max() == 0.0, "no tangential motion, no tangential force"


def test_rocking_lifts_off_at_the_edges_first():
    """phi_eta = Phi cos tau: u_zeta = -phi_eta xi. No point separates below Phi* = a / max|xi|;
    just above, the separated points are exactly those at the extreme xi (both edges, in
    opposite half periods); further up the separated time grows with |xi|."""
    pt = patch(n_xi=5, n_eta=3)
    offset = pt.approach_for_load(N0)
    a = offset[0]
    xi_max = np.abs(pt.xi).max()
    Phi_star = a / xi_max
    basis = HarmonicBasis((1,), 256)
    below = pt.evaluate(control_motion(basis, 4, 0.999 * Phi_star), basis, offset, jacobian=False)
    assert not np.any(below.points.state == SEPARATED)
    above = pt.evaluate(control_motion(basis, 4, 1.001 * Phi_star), basis, offset, jacobian=False)
    sep = (above.points.state == SEPARATED).any(axis=1)
    assert sep.any(), "no lift-off above the closed-form threshold"
    assert np.all(np.isclose(np.abs(pt.xi[sep]), xi_max)), f"separated points at xi = {pt.xi[sep]}"
    assert np.all(sep[np.isclose(np.abs(pt.xi), xi_max)]), "both edges should lift off"
    far = pt.evaluate(control_motion(basis, 4, 3 * Phi_star), basis, offset, jacobian=False)
    fraction = (far.points.state == SEPARATED).mean(axis=1)
    order = np.argsort(np.abs(pt.xi))
    assert np.all(np.diff(fraction[order]) >= -1e-12), "separation time must grow with |xi|"
    assert fraction[np.isclose(pt.xi, 0)].max() == 0.0, "the centre row (xi = 0) never lifts off"


# ---------------------------------------------------------------------------------------
# analytic Jacobian against finite differences
# ---------------------------------------------------------------------------------------
LAWS = {
    "linear": LinearNormalLaw(K_N),
    "rough_p1.5": RoughnessNormalLaw(K_N, N0, 1.5),
    "rough_p1": RoughnessNormalLaw(K_N, N0, 1.0),     # p = 1: zero stiffness after lift-off too
    "rough_p2.5": RoughnessNormalLaw(K_N, N0, 2.5),
}


@pytest.mark.parametrize("harmonics", [(1,), (0, 1, 2, 3), (1, 3, 5)], ids=str)
@pytest.mark.parametrize("law_name", list(LAWS))
def test_patch_jacobian_matches_finite_differences(law_name, harmonics):
    """The analytic Jacobian equals central differences column by column. The force map has a
    kink wherever a sample changes state (stick/slip/lift-off); a column whose central difference
    straddles one (about 1 random point in 1000 at the step 1e-6: the two one-sided differences
    then differ, and the analytic Jacobian equals one of them) is compared again at steps 10,
    100 and 1000 times smaller. The seed is fixed (crc32, not hash(), which changes from run to run)."""
    law = LAWS[law_name]
    pt = patch(law, 3, 4)
    basis = HarmonicBasis(harmonics)
    C = basis.n_coeffs
    offset = pt.approach_for_load(N0)
    a = offset[0]
    u_star = MU * N0 / K_T
    # typical size of each control DOF: a few stick limits tangentially, ~the approach normally
    scale = np.array([3 * u_star, 3 * u_star, 0.8 * a, 0.8 * a / LENGTH, 0.8 * a / HEIGHT,
                      3 * u_star / LENGTH])
    rng = np.random.default_rng(zlib.crc32(f"{law_name} {harmonics}".encode()))
    for attempt in range(50):
        w = rng.normal(size=(C, 6)) * scale / np.sqrt(C)
        ev = pt.evaluate(w, basis, offset)
        counts = np.bincount(ev.points.state.ravel(), minlength=3)
        if np.all(counts > 0):
            break
    assert np.all(counts > 0), f"could not get a stick/slip/lift-off mix: {counts}"
    col = np.tile(scale, C)
    J = ev.jacobian.reshape(-1, col.size) * col     # compared in scaled columns (translations
    force = lambda x: pt.evaluate(x.reshape(C, 6), basis, offset, jacobian=False).force  # and rotations)
    J_fd = central_difference(force, w.ravel(), 1e-6 * col) * col
    denominator = np.abs(J_fd).max()
    column_error = np.abs(J - J_fd).max(axis=0) / denominator
    for j in np.flatnonzero(column_error >= 1e-6):   # a kink within the step: smaller steps
        for step in (1e-7, 1e-8, 1e-9):
            e = np.zeros(col.size)
            e[j] = step * col[j]
            fine = (force(w.ravel() + e).ravel() - force(w.ravel() - e).ravel()) / (2 * step)
            column_error[j] = min(column_error[j], np.abs(J[:, j] - fine).max() / denominator)
    err = column_error.max()
    print(f"states stick/slip/separated = {counts.tolist()}: rel err {err:.2e}")
    assert err < 1e-6, f"states stick/slip/separated = {counts.tolist()}: rel err {err:.2e}"
