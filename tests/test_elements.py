"""The open element API: TimeDomainElement (AFT written once), GapSpring, HarmonicBalanceSystem.add,
TunedDisk.point_map and frequency_response(extra_couplings=...), a user's element added to a disk."""
import dataclasses

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.hbm import (Coupling, CubicSpring, GapSpring, HarmonicBalanceSystem, HarmonicBasis,
                           TimeDomainElement, with_element)


class UserSpring(TimeDomainElement):
    """A user's element, defined outside the package: two coupled coordinates,
    f = (k1 u0 + k3 u0^3 + c u0 u1^2, k1 u1 + c u0^2 u1) (the gradient of a potential)."""

    n_local = 2

    def __init__(self, k1=2.0, k3=5.0, c=3.0):
        self.k1, self.k3, self.c = k1, k3, c

    def forces_in_time(self, u, omega):
        u0, u1 = u[:, 0], u[:, 1]
        f = np.stack([self.k1 * u0 + self.k3 * u0 ** 3 + self.c * u0 * u1 ** 2,
                      self.k1 * u1 + self.c * u0 ** 2 * u1], axis=1)
        d = np.empty((len(u), 2, 2))
        d[:, 0, 0] = self.k1 + 3 * self.k3 * u0 ** 2 + self.c * u1 ** 2
        d[:, 0, 1] = d[:, 1, 0] = 2 * self.c * u0 * u1
        d[:, 1, 1] = self.k1 + self.c * u0 ** 2
        return f, d


def _fd_jacobian(element, local, basis, h=1e-7):
    n = local.size
    jac = np.zeros((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        fp = element.harmonic_forces((local.ravel() + e).reshape(local.shape), basis, 1.0, False)[0].ravel()
        fm = element.harmonic_forces((local.ravel() - e).reshape(local.shape), basis, 1.0, False)[0].ravel()
        jac[:, k] = (fp - fm) / (2 * h)
    return jac


@pytest.mark.parametrize("element, n_local", [(UserSpring(), 2), (CubicSpring(7.0), 1),
                                              (GapSpring(stiffness=3.0, gap=0.2), 1)])
def test_base_class_jacobian_against_finite_differences(element, n_local):
    basis = HarmonicBasis((0, 1, 2, 3), 64)
    rng = np.random.default_rng(3)
    local = 0.5 * rng.standard_normal((basis.n_coeffs, n_local))
    force, jac, domega = element.harmonic_forces(local, basis, 1.0)
    assert force.shape == (basis.n_coeffs, n_local) and domega is None
    fd = _fd_jacobian(element, local, basis)
    assert np.abs(jac - fd).max() < 1e-6 * max(np.abs(jac).max(), 1.0)
    assert element.memoryless


def test_cubic_spring_on_the_base_class_is_the_hand_written_aft():
    basis = HarmonicBasis((1, 3, 5), 48)
    local = np.random.default_rng(0).standard_normal((basis.n_coeffs, 1))
    k3 = 2.5e4
    u = basis.synthesis @ local[:, 0]
    force = basis.analysis @ (k3 * u ** 3)
    jac = basis.analysis @ ((3 * k3 * u ** 2)[:, None] * basis.synthesis)
    f, J, _ = CubicSpring(k3).harmonic_forces(local, basis, 1.0)
    np.testing.assert_allclose(f[:, 0], force, rtol=1e-13, atol=1e-13 * np.abs(force).max())
    np.testing.assert_allclose(J, jac, rtol=1e-13, atol=1e-13 * np.abs(jac).max())


def test_gap_spring_forces_and_validation():
    g = GapSpring(stiffness=10.0, gap=0.5)
    f, d = g.forces_in_time(np.array([[0.0], [0.5], [1.5]]), 1.0)
    np.testing.assert_array_equal(f[:, 0], [0.0, 0.0, 10.0])
    np.testing.assert_array_equal(d[:, 0, 0], [0.0, 0.0, 10.0])
    with pytest.raises(ValueError, match=r"stiffness.*\(0, inf\)"):
        GapSpring(stiffness=0.0)
    with pytest.raises(ValueError, match=r"gap.*\[0, inf\)"):
        GapSpring(stiffness=1.0, gap=-1e-3)
    with pytest.raises(ValueError, match="gap.*finite"):
        GapSpring(stiffness=1.0, gap=float("nan"))
    with pytest.raises(ValueError, match="cubic_stiffness"):
        CubicSpring(float("inf"))


def test_a_wrong_forces_in_time_is_named():
    class Bad(TimeDomainElement):
        def forces_in_time(self, u, omega):
            return u[:, 0], u

    with pytest.raises(ValueError, match=r"Bad.forces_in_time must return f \(64, 1\)"):
        Bad().harmonic_forces(np.zeros((2, 1)), HarmonicBasis((1,), 64), 1.0)


def _free_disk():
    return dataclasses.replace(bd.reference_disk("cylinder", 1e-3), damper=None)


def test_add_returns_a_new_system_and_checks_the_map():
    disk = _free_disk()
    system = disk.hbm_system((1,))
    T = disk.point_map(system.basis, "tip", (0, 1))
    assert T.shape == (2 * 2, system.n_unknowns)
    # the map reads the tip motion through the mode shapes
    x = np.random.default_rng(1).standard_normal(system.n_unknowns)
    q = x.reshape(2, -1)
    np.testing.assert_allclose((T @ x).reshape(2, 2), q @ disk.blade.shape("tip")[:2].T, rtol=1e-13)
    bigger = system.add(GapSpring(1e4), disk.point_map(system.basis), "tip stop")
    assert isinstance(bigger, HarmonicBalanceSystem) and len(bigger.couplings) == 1 and not system.couplings
    assert bigger.couplings[0].name == "tip stop"
    with pytest.raises(ValueError, match=r"= \(2, 8\) for this system.*got \(2, 5\)"):
        with_element(system, GapSpring(1e4), np.zeros((2, 5)), "tip stop")
    with pytest.raises(ValueError, match="directions"):
        disk.point_map(system.basis, "tip", (6,))
    with pytest.raises(ValueError, match="point"):
        disk.point_map(system.basis, "shroud")
    with pytest.raises(TypeError, match="harmonic_forces"):
        system.add(object(), T)


def test_mistuned_point_map_picks_the_blade():
    from bladedamp.mistuned import MistunedDisk

    disk = bd.reference_disk("cylinder", 1e-3)
    mistuned = MistunedDisk.from_tuned(disk, np.ones(4), n_sector=4)
    system = mistuned.hbm_system((1,))
    T = mistuned.point_map(system.basis, "tip", (0,), blade=2)
    C, n = system.basis.n_coeffs, system.n_dof
    assert T.shape == (C, system.n_unknowns)
    blocks = np.asarray(T.todense() if hasattr(T, "todense") else T).reshape(C, C, n)
    inside = np.zeros(n, bool)
    inside[mistuned.blade_slice(2)] = True
    assert np.all(blocks[:, :, ~inside] == 0)
    np.testing.assert_array_equal(blocks[0, 0, inside], disk.blade.shape("tip")[0])
    with pytest.raises(ValueError, match="blade"):
        mistuned.point_map(system.basis, blade=4)
    x = np.random.default_rng(2).standard_normal(system.n_unknowns) * 1e-6
    spring = GapSpring(1e4)
    extended = system.add(spring, T, "tip stop")        # the generic residual, the assembly's plus the spring's
    R0, J0, _ = system.residual(x, 600.0)
    R, J, _ = extended.residual(x, 600.0)
    force, jac, _ = spring.harmonic_forces((T @ x).reshape(C, 1), system.basis, 600.0)
    np.testing.assert_allclose(R, R0 + T.T @ force.ravel(), rtol=1e-12, atol=1e-12 * np.abs(R0).max())
    dense = lambda A: np.asarray(A.todense()) if hasattr(A, "todense") else A
    np.testing.assert_allclose(dense(J), dense(J0) + T.T @ jac @ T, rtol=1e-12, atol=1e-12 * np.abs(dense(J0)).max())


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")   # one harmonic, on purpose
def test_zero_gap_spring_at_the_tip_raises_the_resonance_as_the_closed_form():
    """With one harmonic and no static term the tip moves as a cos(Omega t + phi); the fundamental
    of k max(0, u) is then exactly k u / 2 (an even number of samples, no aliasing): the
    first-harmonic balance is linear with the spring k/2 at the tip. 1F alone:
    omega^2 = omega_1^2 + (k/2) phi_tip,x^2; all modes: the eigenvalues of diag(omega^2) + (k/2) phi phi^T."""
    disk, k = _free_disk(), 1e4
    tip_stop = lambda basis: [Coupling(GapSpring(stiffness=k), disk.point_map(basis, "tip", (0,)), "tip stop")]
    free = disk.frequency_response(90.0, 110.0, harmonics=(1,))
    frf = disk.frequency_response(90.0, 110.0, harmonics=(1,), extra_couplings=tip_stop)
    assert frf.success, frf.message
    w = disk.blade.natural_angular_frequencies
    phi = disk.blade.shape("tip")[0]
    one_mode = np.sqrt(w[0] ** 2 + 0.5 * k * phi[0] ** 2) / (2 * np.pi)
    all_modes = np.sqrt(np.linalg.eigvalsh(np.diag(w ** 2) + 0.5 * k * np.outer(phi, phi))[0]) / (2 * np.pi)
    assert frf.peak_frequency_hz > 1.05 * free.peak_frequency_hz          # the stop is felt: +8 %
    assert abs(frf.peak_frequency_hz / one_mode - 1) < 1e-2
    assert abs(frf.peak_frequency_hz / all_modes - 1) < 1e-3


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")   # one harmonic, on purpose
def test_a_gap_larger_than_the_amplitude_leaves_the_frf_unchanged():
    disk = bd.reference_disk("cylinder", 1e-3)                        # with the friction damper
    ref = disk.frequency_response(90.0, 105.0, harmonics=(1,))
    far = lambda basis: [Coupling(GapSpring(stiffness=1e5, gap=1e-3), disk.point_map(basis), "far stop")]
    frf = bd.frequency_response(disk, (90.0, 105.0), harmonics=(1,), extra_couplings=far)
    assert ref.peak_amplitude < 0.6e-3 and frf.success
    assert frf.omega.shape == ref.omega.shape
    np.testing.assert_allclose(frf.tip_amplitude, ref.tip_amplitude, rtol=1e-12, atol=1e-12 * ref.peak_amplitude)
    np.testing.assert_allclose(frf.omega, ref.omega, rtol=1e-13)


def test_extra_couplings_reach_the_stability_and_the_error_estimate():
    """A hardening cubic spring at the tip of the bare blade: Hill's method (every element
    memoryless) on the system with the spring, and the error estimate of the enriched set."""
    disk = _free_disk()
    cubic = lambda basis: [Coupling(CubicSpring(1e8), disk.point_map(basis), "tip cubic")]
    frf = bd.frequency_response(disk, (90.0, 100.0), harmonics=(1,), stability=True, extra_couplings=cubic,
                                max_step=0.05)
    plain = disk.frequency_response(90.0, 100.0, harmonics=(1,), max_step=0.05)
    assert frf.stability_method == "hill"
    assert frf.peak_frequency_hz > plain.peak_frequency_hz + 0.1        # hardening
    assert np.isfinite(frf.harmonic_error)
    with pytest.raises(TypeError, match="callable"):
        disk.frequency_response(90.0, 100.0, harmonics=(1,), extra_couplings=[cubic(HarmonicBasis((1,)))[0]])


def test_exported_names():
    import bladedamp.hbm as hbm
    from bladedamp.hbm import elements, system

    assert bd.HarmonicBalanceSystem is system.HarmonicBalanceSystem is hbm.HarmonicBalanceSystem
    assert bd.Coupling is system.Coupling and bd.with_element is system.with_element
    assert bd.TimeDomainElement is elements.TimeDomainElement
    assert bd.CubicSpring is elements.CubicSpring and bd.GapSpring is elements.GapSpring
    assert {"HarmonicBalanceSystem", "Coupling", "TimeDomainElement", "GapSpring"} <= set(bd.__all__)


def test_readme_example_runs_and_gives_its_numbers():
    """The README section "Your own nonlinear element", run as written: a user's element (defined
    in the snippet, not in the package) at the tip of the reference disk; the numbers it quotes."""
    import pathlib
    import warnings

    from bladedamp.hbm.accuracy import AccuracyWarning   # bd.hbm loads its submodules lazily

    text = (pathlib.Path(__file__).parents[1] / "README.md").read_text()
    section = text.split("## Your own nonlinear element", 1)[1]
    code = section.split("```python", 1)[1].split("```", 1)[0]
    scope = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)
        exec(compile(code, "README.md", "exec"), scope)
    frf, system = scope["frf"], scope["system"]
    assert [c.name for c in system.couplings] == ["damper contacts", "tip stop"]
    assert frf.success, frf.message
    assert abs(frf.peak_frequency_hz - 97.29) < 0.01 and abs(frf.peak_amplitude - 0.484e-3) < 0.5e-6
