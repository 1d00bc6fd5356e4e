"""Hill's method (bladedamp.hbm.stability) against closed forms and time integration.

* linear oscillator: the Floquet exponents are its eigenvalues -zeta w0 +- i w_d (modulo the
  excitation frequency), for any harmonic set;
* Duffing oscillator (FrictionOscillator with a cubic spring and no friction): the branch
  between the two folds is unstable, outside it stable; the upper fold (the peak) lies on the
  closed-form backbone w^2 = w0^2 + 3/4 k3 A^2 / m with A = F / (c w);
* time integration (scipy's DOP853, independent of bladedamp's integrators) started on the HBM
  solution with a small perturbation stays on it at stable points and leaves it at unstable ones.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bladedamp import FrictionOscillator
from bladedamp.hbm.stability import branch_stability, floquet_exponents

W0 = 2 * np.pi          # natural frequency 1 Hz
DAMPING = 0.2           # c [N s/m], zeta = 0.016
K3 = 20.0               # [N/m^3]
FORCE = 1.0             # [N]


def duffing():
    return FrictionOscillator(mass=1.0, stiffness=W0 ** 2, damping=DAMPING, contact_stiffness=1.0,
                              friction_coefficient=0.0, normal_load=0.0, forcing=FORCE, cubic_stiffness=K3)


@pytest.fixture(scope="module")
def duffing_branch():
    osc = duffing()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(0.8, 1.4, harmonics=(1,), max_step=0.004)
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    return osc, r, system, branch_stability(system, r.coefficients, r.omega)


@pytest.mark.parametrize("harmonics", [(1,), (0, 1, 2, 3), (1, 3, 5)])
def test_linear_oscillator_exponents_are_its_eigenvalues(harmonics):
    osc = FrictionOscillator(mass=1.0, stiffness=W0 ** 2, damping=DAMPING, contact_stiffness=1.0,
                             friction_coefficient=0.0, normal_load=0.0, forcing=FORCE)
    r = osc.frequency_response(0.9, 1.1, harmonics=harmonics)
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    zeta = DAMPING / (2 * W0)
    wd = W0 * np.sqrt(1 - zeta ** 2)
    for i in (0, len(r.omega) // 2, len(r.omega) - 1):
        w = float(r.omega[i])
        f = floquet_exponents(system, r.coefficients[i].ravel(), w)
        assert f.exponents.size == 2 and f.stable
        np.testing.assert_allclose(f.exponents.real, -zeta * W0, rtol=1e-8)
        # imaginary parts equal +-w_d modulo the excitation frequency
        im = np.sort(np.mod(f.exponents.imag, w))
        np.testing.assert_allclose(im, np.sort(np.mod([wd, -wd], w)), rtol=1e-8, atol=1e-9 * w)


def test_duffing_unstable_exactly_between_the_folds(duffing_branch):
    _, r, _, st = duffing_branch
    tp = np.asarray(r.turning_points)
    assert tp.size == 2, "the Duffing branch must have two folds in this range"
    lo, hi = int(tp.min()), int(tp.max())
    # stability changes at the folds (within one point) and nowhere else
    assert st.changes.size == 2 and set(st.kinds) == {"fold"}
    assert abs(int(st.changes[0]) - lo) <= 1 and abs(int(st.changes[1]) - hi) <= 1
    assert st.stable[:lo - 1].all() and st.stable[hi + 2:].all()
    assert not st.stable[lo + 2:hi - 1].any()
    # on the unstable segment one real exponent is positive
    assert np.all(st.max_real[lo + 2:hi - 1] > 0)


def test_duffing_peak_fold_on_the_backbone(duffing_branch):
    _, r, _, st = duffing_branch
    a = r.harmonic_amplitude(0, 1)
    i = int(np.argmax(a))
    w, A = float(r.omega[i]), float(a[i])
    # closed-form one-harmonic backbone and the resonance amplitude of viscous damping
    assert w ** 2 == pytest.approx(W0 ** 2 + 0.75 * K3 * A ** 2, rel=2e-3)
    assert A == pytest.approx(FORCE / (DAMPING * w), rel=2e-3)
    # the upper fold, where the stability changes, follows the peak closely (the largest
    # amplitude is at phase quadrature, on the backbone; the fold just after it)
    upper = int(min(r.turning_points))
    assert i <= upper and r.omega[upper] == pytest.approx(w, rel=5e-3)
    assert abs(int(st.changes[0]) - upper) <= 1


def _integrate(osc, x0, v0, omega, periods):
    """Duffing ODE from (x0, v0) at t = 0 by DOP853; returns the samples of the last period."""
    m, c, k, k3, F = osc.mass, osc.damping, osc.stiffness, osc.cubic_stiffness, osc.forcing

    def rhs(t, y):
        return [y[1], (F * np.cos(omega * t) - c * y[1] - k * y[0] - k3 * y[0] ** 3) / m]

    T = 2 * np.pi / omega
    t_eval = np.linspace((periods - 1) * T, periods * T, 257)[:-1]
    sol = solve_ivp(rhs, (0.0, periods * T), [x0, v0], method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    return sol.y[0]


@pytest.mark.parametrize("where", ["upper stable", "unstable", "lower stable"])
def test_duffing_stability_confirmed_by_time_integration(duffing_branch, where):
    osc, r, _, st = duffing_branch
    lo, hi = sorted(int(t) for t in r.turning_points)
    i = {"upper stable": lo - 15, "unstable": (lo + hi) // 2, "lower stable": hi + 15}[where]
    assert st.stable[i] == (where != "unstable")
    w = float(r.omega[i])
    x = r.time_samples(0)[i]                                   # x(tau) over a period, tau = w t
    v = w * (r.coefficients[i, :, 0] @ r.basis.derivative.T @ r.basis.synthesis.T)
    A_hbm = float(r.harmonic_amplitude(0, 1)[i])
    delta = 1e-3 * A_hbm
    last = _integrate(osc, x[0] + delta, v[0], w, periods=300)
    spec = np.fft.rfft(last) / last.size
    A_time = 2 * abs(spec[1])
    if where == "unstable":
        # the motion leaves the unstable solution for a stable one of the same frequency
        a = r.harmonic_amplitude(0, 1)
        near = st.stable & (np.abs(r.omega - w) < 1e-3 * w)
        assert abs(A_time / A_hbm - 1) > 0.03, "an unstable solution must not be kept by the time integration"
        assert np.min(np.abs(a[near] / A_time - 1)) < 1e-2
    else:
        assert A_time == pytest.approx(A_hbm, rel=2e-2), "a stable solution must attract the perturbed motion"


# ----- hysteretic elements: the determinant sign ------------------------------------------

def jenkins():
    return FrictionOscillator(mass=1.0, stiffness=W0 ** 2, damping=0.05, contact_stiffness=W0 ** 2,
                              friction_coefficient=0.3, normal_load=1.0, forcing=0.5)


def test_hill_on_the_aft_jacobian_of_friction_is_not_valid_so_the_determinant_decides():
    """The 1-DOF Jenkins oscillator is stable (time integration from rest reaches the HBM
    solution); Hill's method on the AFT Jacobian of its friction contact does not give its
    exponents (the memory of the last reversal is not in it), so friction systems are decided by
    the sign of det J, positive all along this fold-free branch, or by the monodromy matrix."""
    osc = jenkins()
    r = osc.frequency_response(0.7, 1.8, harmonics=(0, 1, 2, 3, 4, 5))
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    auto = branch_stability(system, r.coefficients, r.omega)
    assert auto.method == "determinant sign" and auto.stable.all() and auto.changes.size == 0
    # Hill's method on the AFT Jacobian: the viscous decay -c / 2m alone at a point below the
    # resonance where the monodromy matrix (memory included) shows the friction damping the
    # perturbation 40 times faster
    i = len(r.omega) // 12
    w = float(r.omega[i])
    forced = floquet_exponents(system, r.coefficients[i].ravel(), w, method="hill")
    exact = floquet_exponents(system, r.coefficients[i].ravel(), w, method="monodromy", model=osc)
    assert exact.method == "monodromy" and exact.stable
    assert forced.max_real == pytest.approx(-osc.damping / (2 * osc.mass), rel=1e-3)
    assert exact.max_real < 20 * forced.max_real, "the AFT Jacobian misses the friction's damping of perturbations"
    f = np.array([0.75, 1.0, 1.2, 1.6])
    td = osc.time_response(f)
    hbm = np.interp(2 * np.pi * f, r.omega, r.harmonic_amplitude(0, 1))
    np.testing.assert_allclose(td.amplitude, hbm, rtol=2e-2)


def duffing_with_friction():
    return FrictionOscillator(mass=1.0, stiffness=W0 ** 2, damping=0.1, contact_stiffness=0.5 * W0 ** 2,
                              friction_coefficient=0.1, normal_load=0.5, forcing=1.0, cubic_stiffness=20.0)


def _integrate_with_friction(osc, x_tau, v0, omega, periods, steps=2000):
    """Central differences of m x'' + c x' + k x + k3 x^3 + f_J = F cos(omega t), f_J a Jenkins
    element (k_T, mu N0), from x_tau[0] (+ a perturbation of 1e-3 of the amplitude) and v0, the
    slider in the state of the periodic HBM motion x_tau; first-harmonic amplitude of the last
    period. Independent of bladedamp's integrators."""
    m, c, k, k3, F = osc.mass, osc.damping, osc.stiffness, osc.cubic_stiffness, osc.forcing
    kt, slip = osc.contact_stiffness, osc.friction_coefficient * osc.normal_load
    s = 0.0
    for xs in np.concatenate([x_tau, x_tau]):          # slider state of the periodic motion at t = 0
        if abs(kt * (xs - s)) > slip:
            s = xs - np.sign(kt * (xs - s)) * slip / kt
    dt = 2 * np.pi / omega / steps
    x = x_tau[0] + 1e-3 * np.abs(x_tau).max()
    x_prev = x - v0 * dt
    last = np.zeros(steps)
    for n in range(periods * steps):
        f = kt * (x - s)
        if abs(f) > slip:
            s = x - np.sign(f) * slip / kt
            f = np.sign(f) * slip
        acc = (F * np.cos(omega * n * dt) - k * x - k3 * x ** 3 - f - c * (x - x_prev) / dt) / m
        x_prev, x = x, 2 * x - x_prev + dt * dt * acc
        if n >= (periods - 1) * steps:
            last[n - (periods - 1) * steps] = x_prev
    return 2 * abs(np.fft.rfft(last)[1]) / steps


@pytest.fixture(scope="module")
def friction_fold_branch():
    osc = duffing_with_friction()
    r = osc.frequency_response(0.8, 1.5, harmonics=(1, 3, 5), max_step=0.004)
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    return osc, r, branch_stability(system, r.coefficients, r.omega)


def test_friction_oscillator_with_folds_changes_stability_at_them(friction_fold_branch):
    _, r, st = friction_fold_branch
    assert st.method == "determinant sign"
    tp = sorted(int(t) for t in r.turning_points)
    assert len(tp) == 2 and st.changes.size == 2
    assert all(abs(int(c) - t) <= 1 for c, t in zip(st.changes, tp))
    assert st.kinds == ("fold", "fold") and st.branch_points.size == 0


@pytest.mark.parametrize("where", ["upper stable", "unstable", "lower stable"])
def test_friction_fold_stability_confirmed_by_time_integration(friction_fold_branch, where):
    osc, r, st = friction_fold_branch
    lo, hi = sorted(int(t) for t in r.turning_points)
    i = {"upper stable": lo - 30, "unstable": (lo + hi) // 2, "lower stable": hi + 30}[where]
    assert st.stable[i] == (where != "unstable")
    w = float(r.omega[i])
    x = r.time_samples(0)[i]
    v = w * (r.coefficients[i, :, 0] @ r.basis.derivative.T @ r.basis.synthesis.T)
    a = r.harmonic_amplitude(0, 1)
    A_time = _integrate_with_friction(osc, x, v[0], w, periods=200)
    near = st.stable & (np.abs(r.omega - w) < 1e-3 * w)
    assert np.min(np.abs(a[near] / A_time - 1)) < 5e-3      # it ends on a stable solution
    if where == "unstable":
        assert abs(A_time / a[i] - 1) > 2e-2, "the motion must leave the unstable solution"
    else:
        assert A_time == pytest.approx(a[i], rel=5e-3)


def test_with_stability_fills_the_response_and_the_plot_dashes_the_unstable_part(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from bladedamp.hbm.stability import with_stability

    osc = duffing()
    r = with_stability(osc, osc.frequency_response(0.8, 1.4, harmonics=(1,), max_step=0.01))
    assert r.stability_method == "hill" and r.stable is not None and not r.stable.all()
    assert len(r.bifurcations["fold"]) == 2 and r.bifurcations["branch point"] == []
    ax = r.plot()
    styles = [line.get_linestyle() for line in ax.get_lines()]
    assert "--" in styles and "-" in styles
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [ax.get_lines()[0].get_label()]
    import bladedamp as bd

    r.save(tmp_path / "duffing.npz")
    back = bd.load(tmp_path / "duffing.npz")
    np.testing.assert_array_equal(back.stable, r.stable)
    np.testing.assert_array_equal(back.floquet_exponents, r.floquet_exponents)
    assert back.bifurcations["fold"] == r.bifurcations["fold"] and back.stability_method == "hill"


def test_reference_disk_has_no_fold_and_keeps_det_j_positive():
    """The reference disk's FRF (the paper's 1 g cylinder, one harmonic) has no real exponent
    crossing anywhere in 90-105 Hz: det J > 0 all along, no fold, no branch point. (That is all
    the determinant can show for friction: a Neimark-Sacker bifurcation would need the
    monodromy matrix.)"""
    import bladedamp as bd

    r = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (90.0, 105.0), harmonics=(1,), stability=True)
    assert r.stability_method == "determinant sign" and r.stable.all()
    assert r.bifurcations["branch point"] == [] and len(r.turning_points) == 0
    assert r.bifurcations["seconds"] > 0


# ----- the monodromy matrix of the time integration ----------------------------------------

def test_monodromy_multipliers_are_hills_on_the_duffing_oscillator():
    """Smooth system: the eigenvalues of the monodromy matrix (finite differences of one period
    of the central-difference integration started on the HBM solution) equal Hill's multipliers
    exp(lambda T), on both stable parts and between the folds; both put the folds at the same
    points."""
    osc = duffing()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(0.8, 1.4, harmonics=(1, 3, 5), max_step=0.02)
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    lo, hi = sorted(int(t) for t in r.turning_points)
    points = sorted(set(range(0, len(r.omega), 9)) | {lo - 5, (lo + hi) // 2, hi + 5})
    unstable_seen = 0
    for i in points:
        w, x = float(r.omega[i]), r.coefficients[i].ravel()
        hill = floquet_exponents(system, x, w)
        mono = floquet_exponents(system, x, w, method="monodromy", model=osc)
        assert hill.method == "hill" and mono.method == "monodromy"
        assert mono.periodicity_error < 1e-4
        # the slider of the frictionless contact is always separated: it forgets (multiplier 0)
        assert abs(mono.multipliers[2]) < 1e-9
        pairs = [min(abs(a - b) for b in mono.multipliers[:2]) for a in hill.multipliers]
        assert len(pairs) == 2 and max(pairs) < 1e-4, (i, hill.multipliers, mono.multipliers)
        assert mono.stable == hill.stable
        unstable_seen += not mono.stable
    assert unstable_seen >= 3
    st = branch_stability(system, r.coefficients[lo - 6:hi + 6], r.omega[lo - 6:hi + 6], method="monodromy", model=osc)
    assert st.method == "monodromy" and st.kinds == ("fold", "fold")
    assert [int(c) + lo - 6 for c in st.changes] in ([lo - 1, hi - 1], [lo, hi - 1], [lo - 1, hi], [lo, hi])


def test_monodromy_of_a_stuck_contact_is_the_stuck_linear_system():
    """A contact that never slips: the multipliers are those of the linear oscillator with the
    contact stiffness added, exp((-zeta w0 +- i w_d) T), plus exactly 1 for the slider (a stuck
    contact holds any offset: a neutral family of orbits, counted as stable)."""
    k, kt, c = W0 ** 2, 0.5 * W0 ** 2, 0.2
    osc = FrictionOscillator(mass=1.0, stiffness=k, damping=c, contact_stiffness=kt, friction_coefficient=0.5,
                             normal_load=100.0, forcing=0.1)
    r = osc.frequency_response(0.9, 1.1, harmonics=(0, 1, 2, 3))
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    i = len(r.omega) // 2
    w = float(r.omega[i])
    mono = floquet_exponents(system, r.coefficients[i].ravel(), w, method="monodromy", model=osc)
    w0 = np.sqrt(k + kt)
    lam = -c / 2 + 1j * np.sqrt(w0 ** 2 - c ** 2 / 4)
    T = 2 * np.pi / w
    expected = np.exp(np.array([lam, lam.conjugate()]) * T)
    mu = mono.multipliers
    one = np.argmin(np.abs(mu - 1))
    assert abs(mu[one] - 1) < 1e-9 and mono.stable
    rest = np.delete(mu, one)
    # second order in the step: (w0 dt)^2 / 24 of the phase per step
    assert max(min(abs(a - b) for b in rest) for a in expected) < 2e-4


def test_monodromy_finds_the_friction_folds_and_the_time_integration_agrees(friction_fold_branch):
    """Friction oscillator with a hardening spring: the monodromy matrix, with the slider
    position in the state, puts the loss of stability at the folds (within a point of the
    determinant sign's change) and calls the segment between them unstable through a real
    multiplier > 1; the perturbed time integrations of test_friction_fold_stability_confirmed_by_
    time_integration confirm the same three verdicts."""
    osc, r, st = friction_fold_branch
    lo, hi = sorted(int(t) for t in r.turning_points)
    idx = np.array(sorted(set(range(0, len(r.omega), 20)) | set(range(lo - 3, lo + 4)) | set(range(hi - 3, hi + 4))))
    system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
    mono = branch_stability(system, r.coefficients[idx], r.omega[idx], method="monodromy", model=osc)
    assert mono.method == "monodromy"
    far = np.abs(idx[:, None] - np.array([lo, hi])[None, :]).min(axis=1) > 1
    np.testing.assert_array_equal(mono.stable[far], st.stable[idx][far])
    changes = idx[mono.changes]
    assert len(changes) == 2 and abs(changes[0] - lo) <= 2 and abs(changes[1] - hi) <= 2
    assert mono.kinds == ("fold", "fold")
    mid = int(np.argmin(np.abs(idx - (lo + hi) // 2)))
    lead = floquet_exponents(system, r.coefficients[idx[mid]].ravel(), float(r.omega[idx[mid]]),
                             method="monodromy", model=osc)
    assert lead.unstable_kind() == "real" and lead.multipliers[0].real > 1.05 and lead.multipliers[0].imag == 0
    for where, i in {"upper stable": lo - 30, "unstable": (lo + hi) // 2, "lower stable": hi + 30}.items():
        point = floquet_exponents(system, r.coefficients[i].ravel(), float(r.omega[i]), method="monodromy", model=osc)
        assert point.stable == (where != "unstable"), where
        # started on the HBM orbit with the AFT's periodic slider: one period returns to it
        assert point.periodicity_error < 3e-4, (where, point.periodicity_error)


def test_multiplier_crossing_kinds():
    from bladedamp.hbm.stability import multiplier_crossing

    assert multiplier_crossing(np.array([0.3, 1.02 + 0j])) == "fold"
    assert multiplier_crossing(np.array([-1.01 + 0j, 0.2])) == "period doubling"
    assert multiplier_crossing(np.array([0.6 + 0.8j, 0.6 - 0.8j, 0.1])) == "neimark-sacker"


def test_monodromy_refuses_models_without_a_period_map():
    import bladedamp as bd

    osc = duffing()
    system = osc.hbm_system((1,))
    x = np.zeros(system.n_unknowns)
    with pytest.raises(ValueError, match="method"):
        floquet_exponents(system, x, W0, method="monodromy")                  # no model
    with pytest.raises(ValueError, match="FrictionOscillator"):
        # a cyclic sector of several blades: no period map (the tuned disk and the full assembly have one)
        floquet_exponents(system, x, W0, method="monodromy",
                          model=bd.MistunedDisk.from_tuned(bd.reference_disk("cylinder"), n_sector=2))
    with pytest.raises(ValueError, match="method must be one of"):
        floquet_exponents(system, x, W0, method="shooting")
