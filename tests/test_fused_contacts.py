"""The fused contact kernel of the mistuned assembly (contact.point.damper_contact_forces).

AssemblyContacts.forces_at evaluates all contact points of all dampers in one numba call
(point motion, normal law, return map, AFT, projection to the dampers' 12 relative
coordinates and the Jacobian blocks). The reference is the previous numpy path,
AssemblyContacts.forces_at_numpy (point_contact_forces plus einsum projections), on the
16-blade reference disks with random mistuning: cylinder and wedge dampers, linear and
rough (power-law) normal contact, one harmonic and a static term with harmonics 0, 1, 2,
at converged Newton points (stick and slip) and at random large motions (stick, slip and
lift-off). The Jacobian is also checked against central differences of the forces, and
(closed-form periodic slider derivative) against the previous pass iteration run to its limit.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from bladedamp.contact.laws import LinearNormalLaw
from bladedamp.contact.point import (SEPARATED, SLIP, STICK, damper_contact_forces, normal_law_parameters,
                                    point_contact_forces)
from bladedamp.hbm.continuation import newton
from bladedamp.mistuned import MistunedDisk
from bladedamp.reference import reference_damper, reference_disk
from bladedamp.studies.mistuning import random_kappa

HARMONICS = [(1,), (0, 1, 2)]
# frequencies [Hz] walked by Newton from the stuck linear guess to a converged point with
# stick and slip (measured with random_kappa(16, 0.02, seed=2))
CONVERGED_PATH = {"cylinder": (97.0,), "wedge": (93.0, 94.0, 94.5, 95.0, 95.5)}


def mistuned(kind, exponent=1.0):
    disk = reference_disk(kind, 1e-3)
    if exponent != 1.0:
        disk = dataclasses.replace(disk, damper=reference_damper(kind, 1e-3, roughness_exponent=exponent))
    return MistunedDisk.from_tuned(disk, random_kappa(16, 0.02, seed=2))


def contact_state(system, x, omega):
    """(AssemblyContacts, local coefficients (C, n_d, 12), approach offsets (n_d, 2, P))."""
    c = system.couplings[0]
    element = c.element
    local = (c.matrix @ x).reshape(system.basis.n_coeffs, element.n_dampers, 12)
    return element, local, element.approach(omega)[0]


def state_counts(element, local, basis, offsets):
    """Samples in stick, slip and lift-off over all points (from point_contact_forces)."""
    B, k_t, mu, weights, law = element.stacked_points()          # a PointBatch
    C, nd = basis.n_coeffs, element.n_dampers
    coeffs = np.einsum("dqpij,cdqj->cdqpi", B, local.reshape(C, nd, 2, 6)).reshape(C, -1, 3)
    pts = point_contact_forces(coeffs, basis, k_t, mu, law, weights, np.ravel(offsets), jacobian=False)
    return np.bincount(pts.state.ravel(), minlength=3)


def converged_point(md, system, frequencies):
    x = None
    for f in frequencies:
        w = 2 * np.pi * f
        x0 = md.initial_guess(system, w) if x is None else x
        scale = np.maximum(np.abs(x0), 1e-3 * np.abs(x0).max())
        res = newton(system.residual, x0, w, scale, np.linalg.norm(system.excitation(w)[0]), tol=1e-10, max_iter=40)
        assert res.converged, f"Newton did not converge at {f} Hz"
        x = res.x
    return x, w


def relative(a, b):
    return float(np.abs(a - b).max() / np.abs(b).max())


def compare(element, local, basis, offsets):
    """Largest relative difference fused - numpy of (forces, Jacobian blocks, forces without Jacobian)."""
    f_new, j_new = element.forces_at(local, basis, offsets, True)
    f_old, j_old = element.forces_at_numpy(local, basis, offsets, True)
    g_new, none = element.forces_at(local, basis, offsets, False)
    g_old, _ = element.forces_at_numpy(local, basis, offsets, False)
    assert none is None and j_new.shape == j_old.shape == (element.n_dampers,) + (basis.n_coeffs, 12) * 2
    return relative(f_new, f_old), relative(j_new, j_old), relative(g_new, g_old)


def states(kind, harmonics, spreads):
    """(system, omega, {label: unknowns}): the converged point of the mistuned disk's FRF and the
    stuck initial guess there scaled by 1 + a N(0, 1) for each a in ``spreads`` (seed 7)."""
    md = mistuned(kind)
    system = md.hbm_system(harmonics)
    x, w = converged_point(md, system, CONVERGED_PATH[kind])
    x0 = md.initial_guess(system, w)
    rng = np.random.default_rng(7)
    cases = {"converged": x}
    for a in spreads:
        cases[f"random x{a}"] = x0 * (1 + a * rng.standard_normal(x0.size))
    return system, w, cases


@pytest.mark.parametrize("harmonics", HARMONICS, ids=["h1", "h012"])
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_fused_kernel_equals_numpy_path(kind, harmonics):
    system, w, cases = states(kind, harmonics, (3, 30))
    basis = system.basis
    seen = np.zeros(3, dtype=int)
    for label, xc in cases.items():
        element, local, offsets = contact_state(system, xc, w)
        counts = state_counts(element, local, basis, offsets)
        seen += counts
        if label == "converged":
            assert counts[STICK] > 0 and counts[SLIP] > 0, f"converged point without stick and slip: {counts}"
        e_f, e_j, e_g = compare(element, local, basis, offsets)
        print(f"\n[fused {kind} {harmonics} {label}] stick/slip/lift-off {counts}: forces {e_f:.1e}, "
              f"Jacobian {e_j:.1e}, forces without Jacobian {e_g:.1e}")
        assert e_f < 1e-12 and e_g < 1e-12, f"{label}: forces differ from the numpy path by {max(e_f, e_g):.2e}"
        assert e_j < 1e-12, f"{label}: Jacobian blocks differ from the numpy path by {e_j:.2e}"
    assert np.all(seen[[STICK, SLIP, SEPARATED]] > 0), f"not all contact states covered: {seen}"


@pytest.mark.parametrize("harmonics", HARMONICS, ids=["h1", "h012"])
def test_fused_kernel_power_law(harmonics):
    """Rough-surface normal law N ~ a^1.5 evaluated inside the kernel."""
    md = mistuned("cylinder", exponent=1.5)
    system = md.hbm_system(harmonics)
    w = 2 * np.pi * 97.0
    x0 = md.initial_guess(system, w)
    rng = np.random.default_rng(3)
    basis = system.basis
    element = system.couplings[0].element
    assert normal_law_parameters(element.stacked_points().normal_law) is not None
    for scale in (0.0, 3.0):
        element, local, offsets = contact_state(system, x0 * (1 + scale * rng.standard_normal(x0.size)), w)
        e_f, e_j, e_g = compare(element, local, basis, offsets)
        print(f"\n[fused power law {harmonics} x{scale}] {state_counts(element, local, basis, offsets)}: "
              f"forces {e_f:.1e}, Jacobian {e_j:.1e}")
        assert max(e_f, e_j, e_g) < 1e-12


def test_unknown_normal_law_falls_back_to_the_numpy_path():
    class OtherLaw(LinearNormalLaw):
        """A law the kernel does not know (a subclass may change ``force``)."""

    md = mistuned("cylinder")
    system = md.hbm_system((1,))
    w = 2 * np.pi * 97.0
    x0 = md.initial_guess(system, w)
    element, local, offsets = contact_state(system, 2 * x0, w)
    f_ref, j_ref = element.forces_at(local, system.basis, offsets, True)
    law = element.stacked_points().normal_law
    # the same dampers with every patch's law an OtherLaw of the same stiffness, built anew
    contacts = [dataclasses.replace(c, geometry=dataclasses.replace(c.geometry, patches=tuple(
        dataclasses.replace(p, normal_law=OtherLaw(law.stiffness)) for p in c.geometry.patches)))
        for c in element.contacts]
    other = dataclasses.replace(element, contacts=contacts)
    assert normal_law_parameters(other.stacked_points().normal_law) is None
    f, j = other.forces_at(local, system.basis, offsets, True)
    assert relative(f, f_ref) < 1e-12 and relative(j, j_ref) < 1e-12


def test_fused_jacobian_against_central_differences():
    """Cylinder disk, harmonics (0, 1, 2), at a converged point with stick and slip: the Jacobian
    blocks equal central differences of the forces (step 1e-7 of each coordinate's size)."""
    md = mistuned("cylinder")
    system = md.hbm_system((0, 1, 2))
    basis = system.basis
    x, w = converged_point(md, system, CONVERGED_PATH["cylinder"])
    element, local, offsets = contact_state(system, x, w)
    C = basis.n_coeffs
    _, blocks = element.forces_at(local, basis, offsets, True)
    size = np.maximum(np.abs(local).max(axis=0), 1e-3 * np.abs(local).max())   # (n_d, 12)
    fd = np.zeros_like(blocks)
    for a in range(C):
        for m in range(12):
            h = 1e-7 * size[:, m]
            lp, lm = local.copy(), local.copy()
            lp[a, :, m] += h
            lm[a, :, m] -= h
            # each damper's forces depend on its own coordinates only: all dampers at once
            diff = (element.forces_at(lp, basis, offsets, True)[0] - element.forces_at(lm, basis, offsets, True)[0])
            fd[:, :, :, a, m] = np.moveaxis(diff / (2 * h[None, :, None]), 1, 0)
    err = relative(blocks * size[:, None, None, None, :], fd * size[:, None, None, None, :])
    print(f"\n[fused Jacobian vs central differences] {state_counts(element, local, basis, offsets)}: {err:.1e}")
    assert err < 1e-6, f"Jacobian blocks differ from central differences by {err:.2e}"


def kernel(element, local, basis, offsets, max_passes=20, tol=1e-10, closed_form=True):
    """(forces, Jacobian blocks) of damper_contact_forces with the given return-map settings."""
    B, k_t, mu, weights, law = element.stacked_points()          # a PointBatch
    kind, params = normal_law_parameters(law)
    C, nd = basis.n_coeffs, element.n_dampers
    force, blocks = np.empty((C, nd, 12)), np.empty((nd, C, 12, C, 12))
    damper_contact_forces(B, np.ascontiguousarray(local, dtype=float), basis.synthesis, basis.analysis, k_t, mu,
                          weights, np.ascontiguousarray(offsets, dtype=float).ravel(), kind, params,
                          basis.cos_index(0) if basis.has_static else -1, max_passes, tol, True, force, blocks,
                          closed_form)
    return force, blocks


@pytest.mark.parametrize("harmonics", HARMONICS, ids=["h1", "h012"])
@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_fused_closed_form_jacobian_is_the_many_pass_limit(kind, harmonics):
    """The kernel's Jacobian blocks (closed-form periodic slider derivative, what
    AssemblyContacts uses) equal those of the previous pass iteration run to its limit (5000
    passes, tol 1e-14), at the converged point (where 20 passes leave near-1D slip derivatives
    unsettled) and at a random motion; the forces equal the limit's too."""
    system, w, cases = states(kind, harmonics, (3,))
    basis = system.basis
    for label, xc in cases.items():
        element, local, offsets = contact_state(system, xc, w)
        f_new, j_new = kernel(element, local, basis, offsets)
        f_ref, j_ref = kernel(element, local, basis, offsets, 5000, 1e-14, closed_form=False)
        f_old, j_old = kernel(element, local, basis, offsets, closed_form=False)
        f_used, j_used = element.forces_at(local, basis, offsets, True)
        assert np.array_equal(f_used, f_new) and np.array_equal(j_used, j_new)
        e_j, e_old, e_f = relative(j_new, j_ref), relative(j_old, j_ref), relative(f_new, f_ref)
        print(f"\n[{kind} {harmonics} {label}] {state_counts(element, local, basis, offsets)}: Jacobian vs 5000 "
              f"passes: closed form {e_j:.1e}, 20 passes {e_old:.1e}; forces {e_f:.1e} (20 passes "
              f"{relative(f_old, f_ref):.1e})")
        # (the closed form linearises about the slider start of the last pass, within ~tol / det(I - Phi)
        # of the periodic one: 5e-9 at the wedge's converged point with harmonics 0, 1, 2)
        assert e_j < 1e-7, f"{label}: Jacobian blocks differ from the many-pass limit by {e_j:.2e}"
        assert e_f < 1e-12, f"{label}: forces differ from the many-pass limit by {e_f:.2e}"


def frictionless_element(kind, exponent, harmonics):
    """The contact element of :func:`mistuned` with every patch's friction coefficient 0."""
    disk = reference_disk(kind, 1e-3)
    damper = disk.damper if exponent == 1.0 else reference_damper(kind, 1e-3, roughness_exponent=exponent)
    contact = dataclasses.replace(damper.contact, friction_coefficient=0.0)
    disk = dataclasses.replace(disk, damper=dataclasses.replace(damper, contact=contact))
    return MistunedDisk.from_tuned(disk, random_kappa(16, 0.02, seed=2)).hbm_system(harmonics).couplings[0].element


@pytest.mark.parametrize("harmonics", HARMONICS, ids=["h1", "h012"])
@pytest.mark.parametrize("kind, exponent", [("cylinder", 1.0), ("wedge", 1.0), ("cylinder", 1.5)])
def test_parameter_directions_against_the_newton_kernel(kind, exponent, harmonics):
    """The contact parameter directions of the fused kernel (contact.point.damper_parameter_forces,
    AssemblyContacts.directions_at) against the forces and Jacobian blocks of the Newton's kernel
    (damper_contact_forces, forces_at) and the frictionless model, by the identities they obey:
    k_T dF/dk_T + c dF/dc = J_t c_t + (F - J_t c_t) = F; J local = J_t c_t + p (F - J_t c_t) -
    (p (F - J_t c_t) - J_z c_z) (p the law's degree); the OL and OR parts of the approach add up;
    J v for v = local; the map derivative dB = B gives B^T f + B^T J (B local) = F + J local; and
    the normal part F - J_t c_t less its tangential rows is the force with mu = 0 (the normal law
    does not see mu). Rigid platforms: the forces and blocks the kernel forms alongside are the
    Newton kernel's (the same arithmetic). Tolerance 1e-12 of the largest force: the identities
    hold exactly, the sums over points, samples and coefficients (~1e3 terms) in another order
    differ by ~1e-13."""
    md = mistuned(kind, exponent)
    system = md.hbm_system(harmonics)
    basis = system.basis
    w = 2 * np.pi * 97.0
    x0 = md.initial_guess(system, w)
    frictionless = frictionless_element(kind, exponent, harmonics)
    rng = np.random.default_rng(5)
    for scale in (0.0, 3.0, 30.0):
        element, local, offsets = contact_state(system, x0 * (1 + scale * rng.standard_normal(x0.size)), w)
        B = element.stacked_points().maps
        rows, blocks = element.directions_at(local, basis, offsets, [B], [local], True)
        force, jac = element.forces_at(local, basis, offsets, True)
        assert np.array_equal(rows[6], force) and np.array_equal(blocks, jac)
        tangential, law, friction, approach, left, right = rows[:6]
        J_local = np.einsum("dambn,bdn->adm", jac, local)
        bound = 1e-12 * np.abs(force).max()
        errors = {"F": tangential + law - force, "J local": tangential + exponent * law - approach - J_local,
                  "OL + OR": left + right - approach, "J v": rows[8] - J_local, "dB = B": rows[7] - force - J_local,
                  "mu = 0": law - friction - frictionless.forces_at(local, basis, offsets, False)[0]}
        worst = {name: float(np.abs(e).max() / np.abs(force).max()) for name, e in errors.items()}
        print(f"\n[directions {kind} p={exponent} {harmonics} x{scale}] "
              f"{state_counts(element, local, basis, offsets)}: {worst}")
        assert all(np.abs(e).max() <= bound for e in errors.values()), worst


def test_kept_directions_are_those_of_a_call_of_their_own():
    """Within keeping_directions a Jacobian evaluation forms the directions in its own kernel pass:
    the forces, Jacobian and d force / d omega are the evaluation's without it, and the model's
    dR/dp at that point (taken from it) equals dR/dp evaluated afresh, to the last bit."""
    md = mistuned("cylinder")
    system = md.hbm_system((0, 1, 2))
    w = 2 * np.pi * 97.0
    x = md.initial_guess(system, w) * 3.0
    keys = ["damper.mass_g", "damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2",
            "damper.normal_to_tangential_stiffness"]
    dR_dp = md.parameter_derivatives(system, keys)
    fresh = dR_dp(x, w)
    plain = system.residual(x, w)
    element = system.couplings[0].element
    calls = []
    with dR_dp.reusing():
        kept = system.residual(x, w)
        original = element.directions_at
        element.directions_at = lambda *args: calls.append(args) or original(*args)
        try:
            reused = dR_dp(x, w)
        finally:
            del element.directions_at
    assert not calls, "dR/dp evaluated the kernel again"
    assert np.array_equal(reused, fresh)
    for a, b in zip(plain, kept):
        assert np.array_equal(a.toarray() if hasattr(a, "toarray") else a, b.toarray() if hasattr(b, "toarray") else b)
