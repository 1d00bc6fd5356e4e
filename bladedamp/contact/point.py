"""Vectorised 3D point contacts over one period: normal law with lift-off, 2D elastic Coulomb slider.

Each point has local axes (xi, eta, zeta): zeta is the contact normal pointing from the
platform into the damper, (xi, eta) the tangent plane. The relative displacement ``u`` of a
point is damper minus platform. The returned force is the force *on the platform*
(conjugate to ``u``; positive stiffness, as the paper's K_C of Eq. 10-11):

* normal:   f_zeta = -N,  N = law(a_offset - u_zeta) >= 0 (lift-off when the approach a <= 0)
* tangent:  f_t = k_T (u_t - s),  |f_t| <= mu N, s the slider position (2D Masing element,
  Fig. 3): stick while the trial force is inside the friction circle, otherwise slip with
  the radial return f_t = mu N * trial / |trial|.  A separated point carries no force and
  its slider follows (s = u_t).

The steady periodic state is found by repeating the period (return map) until the slider
position at the period end repeats. The derivative of the sampled forces with respect to
each point's own harmonic coefficients is propagated through the same steps (chain rule
through the return map), which gives the exact Jacobian of the AFT forces.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

STICK, SLIP, SEPARATED = 0, 1, 2


@njit(cache=True)
def slider_step(u0, u1, s0, s1, k_t, radius, in_contact):
    """One return-map step of the 2D elastic Coulomb slider (the Masing element of Fig. 3).

    u: tangential displacement, s: slider position before the step, radius = mu N >= 0,
    in_contact: N > 0. Returns (f0, f1, s0_new, s1_new, state): force on the platform,
    new slider position, STICK / SLIP / SEPARATED.
    """
    if not in_contact:
        return 0.0, 0.0, u0, u1, SEPARATED
    tr0 = k_t * (u0 - s0)
    tr1 = k_t * (u1 - s1)
    norm = np.sqrt(tr0 * tr0 + tr1 * tr1)
    if norm <= radius:
        return tr0, tr1, s0, s1, STICK
    f0 = radius * tr0 / norm
    f1 = radius * tr1 / norm
    return f0, f1, u0 - f0 / k_t, u1 - f1 / k_t, SLIP


@njit(cache=True)
def _return_map(ut, normal, dnormal, synthesis, k_t, mu, s_start, static_index,
                max_passes, tol, want_jac, f_out, df_out, state_out, slip_work):
    """Tangential forces of P points over T samples (see module docstring).

    ut (P,T,2) tangential displacement samples; normal (P,T) normal load N >= 0;
    dnormal (P,T) dN/du_zeta; synthesis (T,C); k_t, mu (P,); s_start (P,2) initial slider;
    static_index: coefficient index of the mean (slider seated at the mean) or -1.
    Outputs: f_out (P,T,2), df_out (P,T,2,3C) (d force / d point coefficients, blocks
    xi|eta|zeta), state_out (P,T), slip_work (P,) = sum f . ds over the last period.
    """
    P, T = ut.shape[0], ut.shape[1]
    C = synthesis.shape[1]
    n3 = 3 * C
    ds = np.zeros((2, n3))
    dtr = np.zeros((2, n3))
    dfs = np.zeros((2, n3))
    ds_begin = np.zeros((2, n3))
    for p in range(P):
        kt = k_t[p]
        s0 = s_start[p, 0]
        s1 = s_start[p, 1]
        ds[:, :] = 0.0
        if static_index >= 0:
            ds[0, static_index] = 1.0
            ds[1, C + static_index] = 1.0
        nmax = 0.0
        for t in range(T):
            if normal[p, t] > nmax:
                nmax = normal[p, t]
        scale = mu[p] * nmax / kt + 1e-300
        for it in range(max_passes):
            b0 = s0
            b1 = s1
            if want_jac:
                ds_begin[:, :] = ds
            moved = False
            work = 0.0
            for t in range(T):
                u0 = ut[p, t, 0]
                u1 = ut[p, t, 1]
                sp0 = s0
                sp1 = s1
                n = normal[p, t]
                f0, f1, n_s0, n_s1, st = slider_step(u0, u1, s0, s1, kt, mu[p] * n, n > 0.0)
                f_out[p, t, 0] = f0
                f_out[p, t, 1] = f1
                state_out[p, t] = st
                if st != STICK:
                    moved = True
                    work += f0 * (n_s0 - s0) + f1 * (n_s1 - s1)
                s0 = n_s0
                s1 = n_s1
                if not want_jac:
                    continue
                if st == SEPARATED:
                    # no force; the slider follows the displacement
                    for j in range(n3):
                        df_out[p, t, 0, j] = 0.0
                        df_out[p, t, 1, j] = 0.0
                        ds[0, j] = 0.0
                        ds[1, j] = 0.0
                    for j in range(C):
                        ds[0, j] = synthesis[t, j]
                        ds[1, C + j] = synthesis[t, j]
                    continue
                # d(trial)/dc with trial = k_T (u - s_previous)
                for j in range(n3):
                    dtr[0, j] = -kt * ds[0, j]
                    dtr[1, j] = -kt * ds[1, j]
                for j in range(C):
                    dtr[0, j] += kt * synthesis[t, j]
                    dtr[1, C + j] += kt * synthesis[t, j]
                if st == STICK:
                    for j in range(n3):
                        df_out[p, t, 0, j] = dtr[0, j]
                        df_out[p, t, 1, j] = dtr[1, j]
                    continue
                # slip: f = mu N e, e = trial/|trial|: df = e mu dN + mu N (I - e e^T) dtrial / |trial|
                radius = mu[p] * n
                stretch = np.sqrt((u0 - sp0) ** 2 + (u1 - sp1) ** 2)
                e0 = (u0 - sp0) / stretch
                e1 = (u1 - sp1) / stretch
                g = radius / (kt * stretch)
                for j in range(n3):
                    proj = e0 * dtr[0, j] + e1 * dtr[1, j]
                    dfs[0, j] = g * (dtr[0, j] - e0 * proj)
                    dfs[1, j] = g * (dtr[1, j] - e1 * proj)
                for j in range(C):
                    dr = mu[p] * dnormal[p, t] * synthesis[t, j]
                    dfs[0, 2 * C + j] += e0 * dr
                    dfs[1, 2 * C + j] += e1 * dr
                for j in range(n3):
                    df_out[p, t, 0, j] = dfs[0, j]
                    df_out[p, t, 1, j] = dfs[1, j]
                    ds[0, j] = -dfs[0, j] / kt
                    ds[1, j] = -dfs[1, j] / kt
                for j in range(C):
                    ds[0, j] += synthesis[t, j]
                    ds[1, C + j] += synthesis[t, j]
            slip_work[p] = work
            if not moved:
                break  # no slip, no separation: this period is already periodic
            if it >= 1 and abs(s0 - b0) <= tol * scale and abs(s1 - b1) <= tol * scale:
                # periodic slider; with the Jacobian its derivative must have settled too
                # (in near-1D slip the cross-direction derivative needs more passes)
                if not want_jac or np.abs(ds - ds_begin).max() <= tol:
                    break


@dataclass
class PointContactSamples:
    """Forces of P point contacts over one period (time samples T).

    Attributes
    ----------
    displacement : (P, T, 3) relative displacement damper - platform [m], axes (xi, eta, zeta)
    force : (P, T, 3) force on the platform [N]
    jacobian : (P, T, 3, 3C) or None, d force / d (point coefficients, blocks xi|eta|zeta)
    state : (P, T) int8, 0 stick, 1 slip, 2 separated
    normal_load : (P, T) N >= 0 [N]
    slip_work : (P,) energy dissipated in the sliders over the period [J] (backward-Euler sum)
    """

    displacement: np.ndarray
    force: np.ndarray
    jacobian: np.ndarray | None
    state: np.ndarray
    normal_load: np.ndarray
    slip_work: np.ndarray


def point_contact_forces(coeffs, basis, tangential_stiffness, friction_coefficient, normal_law,
                         weight, approach_offset, jacobian=True, max_passes=20, tol=1e-10):
    """Periodic forces of P point contacts from their harmonic displacement coefficients.

    Parameters
    ----------
    coeffs : (C, P, 3) harmonic coefficients of the relative displacement [m]
    basis : HarmonicBasis
    tangential_stiffness : (P,) k_T of each point [N/m]
    friction_coefficient : (P,) mu [-]
    normal_law : LinearNormalLaw or RoughnessNormalLaw (for the whole area)
    weight : (P,) share of each point in the area (sums to 1 over a patch)
    approach_offset : (P,) approach [m] at zero normal displacement (static preload; with a
        static harmonic it is minus the initial gap and the preload comes from the solution)
    jacobian : bool, also return d force / d coefficients
    """
    coeffs = np.asarray(coeffs, dtype=float)
    disp = np.ascontiguousarray(np.einsum("tc,cpi->pti", basis.synthesis, coeffs))
    P, T = disp.shape[0], disp.shape[1]
    C = basis.n_coeffs
    approach = np.asarray(approach_offset, dtype=float)[:, None] - disp[:, :, 2]
    normal, dnormal_da = normal_law.force(approach, np.asarray(weight, dtype=float)[:, None])
    dnormal = -dnormal_da  # dN/du_zeta
    k_t = np.broadcast_to(np.asarray(tangential_stiffness, dtype=float), (P,)).copy()
    mu = np.broadcast_to(np.asarray(friction_coefficient, dtype=float), (P,)).copy()
    if basis.has_static:
        static_index = basis.cos_index(0)
        s_start = np.ascontiguousarray(coeffs[static_index, :, :2])
    else:
        static_index = -1
        s_start = np.zeros((P, 2))
    f_t = np.empty((P, T, 2))
    df = np.zeros((P, T, 3, 3 * C)) if jacobian else np.zeros((1, 1, 2, 1))
    state = np.empty((P, T), dtype=np.int8)
    slip_work = np.zeros(P)
    _return_map(np.ascontiguousarray(disp[:, :, :2]), np.ascontiguousarray(normal),
                np.ascontiguousarray(dnormal), basis.synthesis, k_t, mu, s_start, static_index,
                max_passes, tol, jacobian, f_t, df, state, slip_work)
    force = np.empty((P, T, 3))
    force[:, :, :2] = f_t
    force[:, :, 2] = -normal
    if jacobian:
        # normal: f_zeta = -N(a_off - u_zeta) -> d f_zeta / d c_zeta = (dN/da) E
        df[:, :, 2, 2 * C:] = dnormal_da[:, :, None] * basis.synthesis[None, :, :]
    return PointContactSamples(disp, force, df if jacobian else None, state, normal, slip_work)


@dataclass
class PointContactElement:
    """P independent point contacts as a harmonic-balance element.

    Local coordinates: 3 per point, (u_xi, u_eta, u_zeta) of each point, point-major.
    All arrays are per point (P,); see :func:`point_contact_forces` for their meaning.
    """

    tangential_stiffness: np.ndarray
    friction_coefficient: np.ndarray
    normal_law: object
    weight: np.ndarray
    approach_offset: np.ndarray

    def __post_init__(self):
        from .. import _validate
        self.tangential_stiffness = np.atleast_1d(_validate.positive("tangential stiffness k_T", self.tangential_stiffness))
        P = self.tangential_stiffness.size
        self.friction_coefficient = np.broadcast_to(np.atleast_1d(
            _validate.nonnegative("friction coefficient mu", self.friction_coefficient)), (P,)).copy()
        self.weight = np.broadcast_to(np.atleast_1d(_validate.positive("weight", self.weight)), (P,)).copy()
        self.approach_offset = np.broadcast_to(np.atleast_1d(
            _validate.finite("approach_offset", self.approach_offset)), (P,)).copy()

    @property
    def n_points(self) -> int:
        return self.tangential_stiffness.size

    @property
    def n_local(self) -> int:
        return 3 * self.n_points

    def samples(self, local, basis, jacobian=False) -> PointContactSamples:
        C = basis.n_coeffs
        return point_contact_forces(np.asarray(local).reshape(C, self.n_points, 3), basis,
                                    self.tangential_stiffness, self.friction_coefficient, self.normal_law,
                                    self.weight, self.approach_offset, jacobian=jacobian)

    def harmonic_forces(self, local, basis, omega=None, jacobian=True):
        """Force coefficients (C, 3P), Jacobian (C*3P, C*3P) (block diagonal over points), None."""
        C, P = basis.n_coeffs, self.n_points
        pts = self.samples(local, basis, jacobian)
        force = basis.to_coeffs(np.moveaxis(pts.force, 1, 0)).reshape(C, 3 * P)
        if not jacobian:
            return force, None, None
        jp = np.matmul(basis.analysis, pts.jacobian.reshape(P, basis.n_samples, 9 * C)).reshape(P, C, 3, 3, C)
        jac = np.zeros((C, P, 3, C, P, 3))
        for p in range(P):
            jac[:, p, :, :, p, :] = np.transpose(jp[p], (0, 1, 3, 2))
        return force, jac.reshape(C * 3 * P, C * 3 * P), None
