"""Shared closed forms and independent numerical helpers of the engine tests, and the shared
solid-blade inputs.

Nothing here calls the code under test to produce a reference value: the closed forms are
written from the physics (Jenkins element, unilateral spring, Duffing + Jenkins describing
function), and the finite differences only call the function whose derivative is checked. The
solid-blade fixtures (the coarse reference solid, its surface as an STL in millimetres and that
STL's named regions) are inputs of tests/test_solid_blade.py and tests/test_design_file.py, built
once per session.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import pytest

FE_REASON = "the solid blade needs the fe extra: pip install 'bladedamp[fe]'"
COARSE_SOLID = 9e-3    # [m] element size of the coarse reference solid: 14 400 DOF, 1F 0.4 % above the 3 mm value


# ---------------------------------------------------------------------------------------
# closed forms
# ---------------------------------------------------------------------------------------
def jenkins_first_harmonic(k, slip_force, amplitude):
    """First-harmonic force (a1, b1) of a 1D Jenkins element (spring k, Coulomb limit
    ``slip_force``) driven by u = A cos(tau), in steady state: f ~ a1 cos + b1 sin.

    stick (k A <= mu N): a1 = k A, b1 = 0.
    gross slip: beta = arccos(1 - 2 mu N / (k A)),
        a1 = k A / pi (beta - sin(2 beta) / 2),  b1 = -(4 mu N / pi)(1 - mu N / (k A)).
    """
    k, slip_force, A = (np.asarray(v, dtype=float) for v in (k, slip_force, amplitude))
    k, slip_force, A = np.broadcast_arrays(k, slip_force, A)
    stick = k * A <= slip_force
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = np.arccos(np.clip(1.0 - 2.0 * slip_force / (k * A), -1.0, 1.0))
        a1 = np.where(stick, k * A, k * A / np.pi * (beta - np.sin(2 * beta) / 2))
        b1 = np.where(stick, 0.0, -(4 * slip_force / np.pi) * (1 - slip_force / (k * A)))
    return a1, b1


def jenkins_dissipation(k, slip_force, amplitude):
    """Energy dissipated per cycle by a Jenkins element, 4 mu N (A - mu N / k) in slip, 0 in stick."""
    return np.where(k * amplitude <= slip_force, 0.0, 4 * slip_force * (amplitude - slip_force / k))


def unilateral_spring_harmonics(k, approach, amplitude):
    """Static and first-harmonic normal force f_zeta = -k max(a - Z cos tau, 0) (Z >= a > 0).

    Contact while cos tau < a / Z, i.e. tau in (theta0, 2 pi - theta0), theta0 = arccos(a / Z):
        c0 = -(k / 2 pi) [2 a (pi - theta0) + 2 Z sin theta0]
        a1 = (k Z / pi) [pi - theta0 + sin theta0 cos theta0],  b1 = 0.
    """
    theta0 = np.arccos(np.clip(approach / amplitude, -1.0, 1.0))
    c0 = -(k / (2 * np.pi)) * (2 * approach * (np.pi - theta0) + 2 * amplitude * np.sin(theta0))
    a1 = (k * amplitude / np.pi) * (np.pi - theta0 + np.sin(theta0) * np.cos(theta0))
    return c0, a1


def duffing_jenkins_residual(A, omega, osc):
    """G(A, Omega) = |Z(A, Omega)|^2 - (F/A)^2 for the single-harmonic describing-function model
    of the FrictionOscillator with contact_angle = 0:
        Z = k + 3/4 k3 A^2 + a1(A)/A - m Omega^2 + i (c Omega - b1(A)/A).
    G = 0 is the single-harmonic frequency response, independent of the AFT and continuation.
    """
    a1, b1 = jenkins_first_harmonic(osc.contact_stiffness, osc.slip_force, A)
    kr = osc.stiffness + 0.75 * osc.cubic_stiffness * A ** 2 + a1 / A - osc.mass * omega ** 2
    ki = osc.damping * omega - b1 / A
    return kr ** 2 + ki ** 2 - (osc.forcing / A) ** 2


# ---------------------------------------------------------------------------------------
# numerical helpers
# ---------------------------------------------------------------------------------------
def one_error_line(capsys, *needles) -> str:
    """The one line a command printed on stderr (no traceback), holding every one of ``needles``."""
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def scale_columns(J, s):
    """J diag(s) for dense or sparse J (sparse: a CSC copy). With :func:`border`, the reference
    of bladedamp.hbm.continuation.bordered_matrix (the bordered continuation matrix in one pass)."""
    if sp.issparse(J):
        J = sp.csc_matrix(J, copy=True)
        J.data *= np.repeat(s, np.diff(J.indptr))
        return J
    return J * s[None, :]


def border(J, column=None, row=None):
    """[J column; row 0] for dense or sparse J (either border may be None; sparse: CSC, one
    insertion per column, each column's row entry last)."""
    if sp.issparse(J):
        J = J if sp.isspmatrix_csc(J) else sp.csc_matrix(J)
        m, n = J.shape
        data, indices, indptr = J.data, J.indices, J.indptr
        if column is not None:
            column = np.asarray(column, dtype=float)
            data = np.concatenate([data, column])
            indices = np.concatenate([indices, np.arange(m, dtype=indices.dtype)])
            indptr = np.append(indptr, indptr[-1] + m)
            n += 1
        if row is not None:
            row = np.asarray(row, dtype=float)
            ends = indptr[1:]
            data = np.insert(data, ends, row)
            indices = np.insert(indices, ends, m)
            indptr = indptr + np.arange(n + 1, dtype=indptr.dtype)
            m += 1
        return sp.csc_matrix((data, indices, indptr), shape=(m, n))
    out = J
    if column is not None:
        out = np.hstack([out, column[:, None]])
    if row is not None:
        out = np.vstack([out, row[None, :]])
    return out


def central_difference(fun, x, step):
    """Jacobian of a vector function by central differences, column by column.

    ``step`` is a scalar or an array of per-entry steps.
    """
    x = np.asarray(x, dtype=float)
    steps = np.broadcast_to(np.asarray(step, dtype=float), x.shape)
    f0 = np.asarray(fun(x)).ravel()
    J = np.zeros((f0.size, x.size))
    for i in range(x.size):
        e = np.zeros_like(x)
        e.flat[i] = steps.flat[i]
        J[:, i] = (np.asarray(fun(x + e)).ravel() - np.asarray(fun(x - e)).ravel()) / (2 * steps.flat[i])
    return J


def relative_matrix_error(J, J_ref):
    """max |J - J_ref| / max |J_ref| (the Jacobians compared have entries of very different sizes)."""
    return float(np.abs(J - J_ref).max() / np.abs(J_ref).max())


def hbm_amplitudes(osc, omegas, harmonics, n_samples=None, return_solutions=False):
    """First-harmonic amplitude of the HBM solution of ``osc`` at exactly the given frequencies.

    Continuation over a range slightly wider than ``omegas`` (no folds here), then Newton at
    each requested frequency from the nearest branch point.
    """
    from bladedamp.hbm.continuation import newton

    system = osc.hbm_system(harmonics, n_samples)
    frf = osc.frequency_response(0.98 * min(omegas) / (2 * np.pi), 1.02 * max(omegas) / (2 * np.pi), harmonics, n_samples)
    assert frf.success, frf.message
    j = system.basis.cos_index(1)
    amps, sols = [], []
    for w in omegas:
        x0 = frf.coefficients[np.argmin(np.abs(frf.omega - w))].ravel()
        res = newton(system.residual, x0, w, x_scale=np.abs(x0).max(), residual_scale=abs(osc.forcing))
        assert res.converged, f"Newton did not converge at omega = {w}"
        amps.append(np.hypot(res.x[j], res.x[j + 1]))
        sols.append(res.x)
    if return_solutions:
        return np.array(amps), np.array(sols), system
    return np.array(amps)


# ---------------------------------------------------------------------------------------
# shared solid-blade inputs
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def coarse_modes():
    """The reference solid's clamped-root modes on the coarse mesh (COARSE_SOLID)."""
    pytest.importorskip("gmsh", reason=FE_REASON)
    pytest.importorskip("skfem", reason=FE_REASON)
    from bladedamp import solid
    return solid.solid_modes(None, COARSE_SOLID)


@pytest.fixture(scope="session")
def reference_stl_mm(coarse_modes, tmp_path_factory):
    """The parametric reference solid's boundary (the 9 mm tetrahedral mesh's outer triangles)
    written as an STL in millimetres: an independent path to the same blade."""
    trimesh = pytest.importorskip("trimesh")
    from bladedamp import solid
    m = coarse_modes.mesh
    tri = solid.boundary_faces(m.tets, m.vertices)
    path = tmp_path_factory.mktemp("stl") / "reference_mm.stl"
    trimesh.Trimesh(1e3 * m.vertices.T, tri.T).export(path)
    return path


def reference_regions():
    """Selectors [m] of the reference solid's named faces: the root plane z = 0 (outward -z) and the
    platform undersides (planes through OL / OR, outward along the contact normals)."""
    from bladedamp import solid
    from bladedamp.damper.geometry import contact_normal
    sg = solid.SolidBladeGeometry()
    pts = sg.points()
    return {"clamp": solid.PlaneRegion((0.0, 0.0, 0.0), (0.0, 0.0, -1.0)),
            "OL": solid.PlaneRegion(pts["OL"], contact_normal("OL", sg.gamma_left)),
            "OR": solid.PlaneRegion(pts["OR"], contact_normal("OR", sg.gamma_right))}


# ---------------------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------------------
class SavedFigures(dict):
    """{file stem: (figure problems of tests/figure_checks.py without the title rule, titles,
    the Figure)} of every figure saved while the fixture is active (checked once per figure, at
    its first file)."""

    def check(self, design: str | None, *stems) -> None:
        """AssertionError listing every figure (``stems``, default all) that breaks a rule, the
        title rule with ``design`` (None: no title rule)."""
        from figure_checks import title_problems

        assert self, "no figure was saved"
        bad = []
        for stem in stems or self:
            assert stem in self, f"{stem}: not saved (saved: {sorted(self)})"
            problems, _, fig = self[stem]
            problems = problems + (title_problems(fig, design) if design is not None else [])
            bad += [f"{stem}: {p}" for p in problems]
        assert not bad, "figures break the slide rules:\n  " + "\n  ".join(bad)


@pytest.fixture
def saved_figures(monkeypatch):
    """Every figure saved with ``Figure.savefig`` to a file during the test, checked by
    tests/figure_checks.py as it is saved (a :class:`SavedFigures`)."""
    import os
    from pathlib import Path

    import matplotlib.figure
    from figure_checks import figure_problems, titles

    saved = SavedFigures()
    original = matplotlib.figure.Figure.savefig

    def checked(self, fname, *args, **kwargs):
        if isinstance(fname, (str, os.PathLike)):
            stem = Path(fname).stem
            if stem not in saved:
                saved[stem] = (figure_problems(self, None), titles(self), self)
        return original(self, fname, *args, **kwargs)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", checked)
    return saved
