"""Direct time integration: the independent check of the harmonic balance.

The friction oscillator is integrated with the explicit central-difference scheme (second
order), the contact force advanced by the same return-map step the AFT uses
(:func:`bladedamp.contact.point.slider_step`), from rest until the response is periodic.

The bladed disk (:func:`disk_time_response`, behind ``TunedDisk.time_response`` and
``MistunedDisk.time_response``) is integrated the same way as the full assembly of blades and
dampers, with the HBM model's own matrices, contact maps, patches and loads, from the static
equilibrium under the centrifugal load, until every blade's first harmonic is steady; a state
that is not periodic (a cylinder that keeps rolling, a damper that walks) is detected and
reported as such (:class:`DiskTimeResponse`). :func:`hbm_tip_at` gives the HBM at the same
frequencies for comparison.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple
from functools import cached_property

import numpy as np
from numba import njit

from .contact.laws import normal_law_parameters
from .contact.normal import normal_force, normal_forces
from .contact.point import SEPARATED, PointContactElement, slider_step
from .hbm.continuation import DEFAULT_MAX_STEP
from .hbm.newton import newton
from .io import Saveable


@njit(cache=True)
def oscillator_step(x, x_prev, s0, dt, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a, force):
    """One central-difference step of the friction oscillator
    m x'' + c x' + k x + k3 x^3 + f_C = F cos(omega t), step dt [s], ``force`` the excitation
    F cos(omega t) [N] at the step's time t: from x(t), x(t - dt) [m] and the slider
    position s0 [m] before the step, returns (x(t + dt), the slider position after the step).
    The contact of :class:`~bladedamp.oscillator.FrictionOscillator` (tangential x cos alpha,
    normal N0 + k_N x sin alpha, lifting off at zero) by the AFT's return-map step
    :func:`slider_step` (also the step of the monodromy matrix,
    :func:`bladedamp.hbm.monodromy.oscillator_period_map`)."""
    normal = n0 + k_n * sin_a * x
    if normal < 0.0:
        normal = 0.0
    f0, f1, s0, s1, st = slider_step(cos_a * x, 0.0, s0, 0.0, k_t, mu * normal, normal > 0.0)
    rhs = force - k * x - k3 * x ** 3 - (cos_a * f0 + sin_a * normal) \
        + m * (2 * x - x_prev) / dt ** 2 + c * x_prev / (2 * dt)
    return rhs / (m / dt ** 2 + c / (2 * dt)), s0


@njit(cache=True)
def oscillator_steady_state(omega, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a, force,
                            steps, max_periods, min_periods, tol, last_period, x0=0.0, v0=0.0):
    """Steady state of the friction oscillator (:class:`bladedamp.oscillator.FrictionOscillator`)
    at one excitation frequency by central-difference time integration, from x0 [m], v0 [m/s]
    (default rest; the slider relaxed at 0).

    ``omega`` [rad/s] (the integrator's own variable; the oscillator's ``time_response`` takes
    Hz); m [kg], c [N s/m], k [N/m], k3 [N/m^3], k_t [N/m], mu [-], n0 [N] (normal preload),
    k_n [N/m], sin_a, cos_a of the contact angle, force [N] (cosine amplitude); ``steps`` per
    period; at most ``max_periods`` and at least ``min_periods`` periods, until the
    first-harmonic amplitude changes by at most ``tol`` (relative) from one period to the next.
    Fills ``last_period`` (steps,) with the displacement [m] over the last period; returns
    (periods used, converged)."""
    dt = 2 * np.pi / omega / steps
    x_prev = x0 - v0 * dt
    x = x0
    s0 = 0.0
    amp_old = -1.0
    stable = 0
    step = 0
    for period in range(max_periods):
        cs = 0.0
        sn = 0.0
        for j in range(steps):
            x_next, s0 = oscillator_step(x, x_prev, s0, dt, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a,
                                         force * np.cos(omega * step * dt))
            last_period[j] = x
            cs += x * np.cos(2 * np.pi * j / steps)
            sn += x * np.sin(2 * np.pi * j / steps)
            x_prev = x
            x = x_next
            step += 1
        amp = 2.0 / steps * np.sqrt(cs * cs + sn * sn)
        if amp_old >= 0 and abs(amp - amp_old) <= tol * amp:
            stable += 1
        else:
            stable = 0
        amp_old = amp
        if period + 1 >= min_periods and stable >= 3:
            return period + 1, True
    return max_periods, False


@dataclass
class TimeResponse(Saveable):
    """Steady-state response by time integration, one run per frequency.

    Attributes
    ----------
    omega : (n,) [rad/s]
    amplitude : (n,) first-harmonic amplitude of the last period [m]
    max_displacement : (n,) max |x(t)| over the last period [m]
    samples : (n, steps) displacement over the last period [m]
    periods : (n,) periods integrated
    converged : (n,) whether the amplitude settled to ``tol`` per period
    """

    omega: np.ndarray
    amplitude: np.ndarray
    max_displacement: np.ndarray
    samples: np.ndarray
    periods: np.ndarray
    converged: np.ndarray

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.omega / (2 * np.pi)

    def harmonic_amplitude(self, harmonic: int = 1) -> np.ndarray:
        """|X_h| of the last period (DFT of the samples)."""
        spec = np.fft.rfft(self.samples, axis=1) / self.samples.shape[1]
        return (1 if harmonic == 0 else 2) * np.abs(spec[:, harmonic])

    def plot(self, ax=None, *, scale: float = 1.0, unit: str = "m", **kwargs):
        """Plot ``scale`` times the first-harmonic amplitude over frequency [Hz] as markers into
        ``ax`` (a new figure if None); ``unit``: the unit of the plotted values, shown in brackets
        on the axis (default m at ``scale`` 1; e.g. ``scale=1e3, unit="mm"``). Returns the axes."""
        import matplotlib.pyplot as plt

        own = ax is None
        if own:
            _, ax = plt.subplots(figsize=(6, 4))
        kwargs.setdefault("label", "time integration")
        kwargs.setdefault("marker", "o")
        kwargs.setdefault("linestyle", "none")
        ax.plot(self.frequency_hz, scale * self.amplitude, **kwargs)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel(f"first-harmonic amplitude [{unit}]")
        ax.grid(True, alpha=0.3)
        ax.legend()
        if own:
            ax.figure.tight_layout()
        return ax


# =========================================================================================
# The bladed disk in the time domain: the full assembly of blades and dampers
# =========================================================================================
#
# Scheme: explicit central differences (second order, no numerical damping), step from the
# highest natural frequency of the stuck linearised assembly. Why explicit: with modal blades
# (identity mass, diagonal modal damping and stiffness) and rigid dampers (6 x 6 inertia, no
# structural damping) the mass and damping matrices are block diagonal, so one step costs one
# evaluation of the point contacts and no solve; the contact law (elastic Coulomb slider by
# return map, normal law with lift-off) is then advanced exactly as in the HBM's AFT, with no
# Newton iteration on non-smooth stick / slip / lift-off transitions. An implicit scheme
# (Newmark, HHT) could take ~10x longer steps but each step needs a Newton solve of the whole
# assembly over a non-smooth contact law, which costs more than the 10 explicit steps it
# replaces (and adds numerical damping with HHT) - an estimate. The stiff
# direction (damper on its contacts: omega_max = 4.4e4 rad/s for the reference 1 g cylinder,
# 7.2e4 rad/s for the 0.3 g wedge) needs 290 / 480 steps per 1F period at 0.8 of the stability
# limit; accuracy asks for 512 (MIN_STEPS_PER_PERIOD). Cost per step: benchmarks/README.md,
# 'Moved from the package's docstrings', timedomain.py.

# Fewest steps per period by default (accuracy, not stability): the central differences shorten
# the modal mass by (Omega dt)^2 / 12, which moves a resonance and, on the steep flank of the
# lightly damped stuck 1F peak, changes the amplitude ~25x as much; 512 keeps the reference
# cylinder's stuck amplitude within ~0.1 % of the HBM's (benchmarks/README.md, 'Moved from the
# package's docstrings', timedomain.py, 'MIN_STEPS_PER_PERIOD').
MIN_STEPS_PER_PERIOD = 512


@njit(cache=True)
def disk_period(steps, dt, n_q, m_q, c_q, k_q, minv, f_static, f_cos, f_sin,
                 Tb, idx, pt_local, B, k_t, mu, weight, offset, law_kind, law_par, t_nnz, t_col, b_nnz, b_col,
                 tip, x, x_prev, slider,
                 tip_samples, tip_dft, damper_mean, damper_dft, damper_work, point_states, energies):
    """Integrate one excitation period of the assembly by central differences (in place).

    Unknowns x (N,): n_q modal coordinates of the blades (first), then 6 per damper. EOM
    M x'' + D x' + K x + T^T f_c(T x) = f_static + f_cos cos(Omega t) + f_sin sin(Omega t)
    (the HBM's residual written in time, Eq. 1-5, 12, 16-20): blades m_q, c_q, k_q diagonal
    (modal, Eq. 5), dampers by their inverse inertia minv (n_d, 6, 6). Contact map of damper d:
    w_d (12) = Tb[d] (12, m) @ x[idx[d]] (m,) (Eq. 6-9); point p of damper d's patch q
    (pt_local[p] = 12 d + 6 q) moves by u_p = B[p] (3, 6) @ w_d[6q:6q+6] (Eq. 7); the point
    force on the platform (f_xi, f_eta, -N) goes back by B^T and Tb^T (Eq. 11). The slider
    (slider (P, 2)) is advanced by :func:`slider_step`, the AFT's own return-map step. Both maps
    are applied through their nonzeros only: row r of Tb[d] has t_nnz[d, r] nonzero columns
    t_col[d, r, :t_nnz[d, r]], row i of B[p] b_nnz[p, i] nonzero columns b_col[p, i, :]
    (the rigid point map has 7 of 18).

    Outputs of the period (overwritten): tip_samples (s, 3, steps) tip displacement (tip (s,3,nm_blade)
    maps blade k's modal coordinates, assumed at x[k*nm:(k+1)*nm]); tip_dft (s, 3, 2) first-harmonic
    cosine / sine coefficients; damper_mean, damper_dft (n_d, 6) and (n_d, 6, 2); damper_work
    (n_d,) slip work; point_states (P, 3) samples in stick / slip / separated; energies (2,):
    excitation work of the harmonic load, viscous dissipation (all per period, J).
    """
    N = x.shape[0]
    nd = Tb.shape[0]
    P = B.shape[0]
    s_bl = tip.shape[0]
    nm = tip.shape[2]
    fc = np.zeros(N)
    w = np.zeros(12 * nd)
    fl = np.zeros(12 * nd)
    x_new = np.zeros(N)
    tip_dft[:, :, :] = 0.0
    damper_mean[:, :] = 0.0
    damper_dft[:, :, :] = 0.0
    damper_work[:] = 0.0
    point_states[:, :] = 0
    w_exc = 0.0
    w_visc = 0.0
    two_pi = 2.0 * np.pi
    inv_dt2 = 1.0 / (dt * dt)
    for j in range(steps):
        ph = two_pi * j / steps
        cj = np.cos(ph)
        sj = np.sin(ph)
        # relative motion at the contacts (Eq. 6)
        for d in range(nd):
            for r in range(12):
                acc = 0.0
                for e in range(t_nnz[d, r]):
                    c = t_col[d, r, e]
                    acc += Tb[d, r, c] * x[idx[d, c]]
                w[12 * d + r] = acc
        fl[:] = 0.0
        for p in range(P):
            base = pt_local[p]
            u0 = 0.0
            u1 = 0.0
            u2 = 0.0
            for e in range(b_nnz[p, 0]):
                c = b_col[p, 0, e]
                u0 += B[p, 0, c] * w[base + c]
            for e in range(b_nnz[p, 1]):
                c = b_col[p, 1, e]
                u1 += B[p, 1, c] * w[base + c]
            for e in range(b_nnz[p, 2]):
                c = b_col[p, 2, e]
                u2 += B[p, 2, c] * w[base + c]
            normal, _ = normal_force(law_kind[p], law_par[p, 0], law_par[p, 1], law_par[p, 2], weight[p],
                                     offset[p] - u2)             # approach a = offset - u_zeta
            s0 = slider[p, 0]
            s1 = slider[p, 1]
            f0, f1, n0, n1, st = slider_step(u0, u1, s0, s1, k_t[p], mu[p] * normal, normal > 0.0)
            if st == 1:
                damper_work[base // 12] += f0 * (n0 - s0) + f1 * (n1 - s1)
            slider[p, 0] = n0
            slider[p, 1] = n1
            point_states[p, st] += 1
            f2 = -normal
            for e in range(b_nnz[p, 0]):
                c = b_col[p, 0, e]
                fl[base + c] += B[p, 0, c] * f0
            for e in range(b_nnz[p, 1]):
                c = b_col[p, 1, e]
                fl[base + c] += B[p, 1, c] * f1
            for e in range(b_nnz[p, 2]):
                c = b_col[p, 2, e]
                fl[base + c] += B[p, 2, c] * f2
        fc[:] = 0.0
        for d in range(nd):
            for r in range(12):
                fr = fl[12 * d + r]
                for e in range(t_nnz[d, r]):
                    c = t_col[d, r, e]
                    fc[idx[d, c]] += Tb[d, r, c] * fr
        # blades: (M/dt^2 + D/(2 dt)) x+ = f - K x - T^T f_c + M (2x - x-)/dt^2 + D x- / (2 dt)
        for i in range(n_q):
            f = f_static[i] + f_cos[i] * cj + f_sin[i] * sj
            rhs = f - k_q[i] * x[i] - fc[i] + m_q[i] * (2.0 * x[i] - x_prev[i]) * inv_dt2 \
                + c_q[i] * x_prev[i] / (2.0 * dt)
            x_new[i] = rhs / (m_q[i] * inv_dt2 + c_q[i] / (2.0 * dt))
        # dampers: x+ = 2x - x- + dt^2 I_D^-1 (f - T^T f_c) (Eq. 12 with inertia)
        for d in range(nd):
            o = n_q + 6 * d
            for a in range(6):
                acc = 0.0
                for b in range(6):
                    acc += minv[d, a, b] * (f_static[o + b] + f_cos[o + b] * cj + f_sin[o + b] * sj - fc[o + b])
                x_new[o + a] = 2.0 * x[o + a] - x_prev[o + a] + dt * dt * acc
        # per-period statistics at sample j (x at t_j), velocities by central differences
        for i in range(N):
            v = (x_new[i] - x_prev[i]) / (2.0 * dt)
            if i < n_q:
                w_visc += c_q[i] * v * v * dt
            w_exc += (f_cos[i] * cj + f_sin[i] * sj) * v * dt
        for k in range(s_bl):
            for a in range(3):
                acc = 0.0
                for q in range(nm):
                    acc += tip[k, a, q] * x[k * nm + q]
                tip_samples[k, a, j] = acc
                tip_dft[k, a, 0] += acc * cj
                tip_dft[k, a, 1] += acc * sj
        for d in range(nd):
            o = n_q + 6 * d
            for a in range(6):
                damper_mean[d, a] += x[o + a]
                damper_dft[d, a, 0] += x[o + a] * cj
                damper_dft[d, a, 1] += x[o + a] * sj
        for i in range(N):
            x_prev[i] = x[i]
            x[i] = x_new[i]
    scale = 2.0 / steps
    for k in range(s_bl):
        for a in range(3):
            tip_dft[k, a, 0] *= scale
            tip_dft[k, a, 1] *= scale
    for d in range(nd):
        for a in range(6):
            damper_mean[d, a] /= steps
            damper_dft[d, a, 0] *= scale
            damper_dft[d, a, 1] *= scale
    energies[0] = w_exc
    energies[1] = w_visc


@dataclass
class AssemblyArrays:
    """The HBM model of a full assembly as arrays of the time integration (see
    :func:`assembly_arrays`): used by :func:`disk_time_response` and by the monodromy matrix of
    the disk (:mod:`bladedamp.hbm.monodromy`), which integrate the same :func:`disk_period`.

    n_q blade modal coordinates first (m_q, c_q, k_q (n_q,) modal mass, damping, stiffness), then
    6 per damper (minv (n_d, 6, 6) inverse inertia); the contact map per damper Tb (n_d, 12, m)
    on the columns idx (n_d, m); P contact points (pt_local (P,) the first local row of the
    point's patch, B (P, 3, 6) point maps, k_t [N/m], mu, weight, offset (approach at zero
    displacement, m), law_kind, law_par (P, 3) the normal law); tip (s, 3, n_m) each blade's tip
    translation shape; point_map (3P, N) sparse x -> point displacements (xi, eta, zeta)."""

    system: object
    n_q: int
    m_q: np.ndarray
    c_q: np.ndarray
    k_q: np.ndarray
    minv: np.ndarray
    Tb: np.ndarray
    idx: np.ndarray
    pt_local: np.ndarray
    B: np.ndarray
    k_t: np.ndarray
    mu: np.ndarray
    weight: np.ndarray
    offset: np.ndarray
    law_kind: np.ndarray
    law_par: np.ndarray
    tip: np.ndarray
    point_map: object          # scipy.sparse (3P, N): x -> point displacements (xi, eta, zeta)
    geometries: list
    stiffness: object          # scipy.sparse (N, N)
    mass: object               # scipy.sparse (N, N)

    @cached_property
    def sparsity(self):
        """(t_nnz, t_col, b_nnz, b_col): the nonzeros of the rows of ``Tb`` and ``B``
        (:func:`row_nonzeros`), the sparsity arguments of :func:`disk_period`."""
        return (*row_nonzeros(self.Tb), *row_nonzeros(self.B))


def assembly_arrays(disk) -> AssemblyArrays:
    """Arrays of the time integration, taken from the HBM model of ``disk`` (a full-assembly
    :class:`~bladedamp.mistuned.MistunedDisk`), so that both solve the same equations.

    ``disk.hbm_system((0, 1))`` gives M, D, K (Eq. 5, 12), the contact map T of every damper
    (its static block: in the full assembly the map is real and the same for every harmonic,
    Eq. 16-20, 6-9), the loads (static F_CG on each damper, Eq. 26; the first-harmonic
    excitation with the engine-order phase of each blade) and the contact patches (point maps,
    k_T, mu, weights, normal law, initial gaps) of :class:`~bladedamp.disk.AssemblyContacts`.
    """
    import scipy.sparse as sp

    if any(b.flexible_platform for b in disk.blades):
        raise ValueError("time_response models rigid platforms at the OL / OR control points only; the blades "
                         "carry flexible platforms (solid FE blades): use blade.rigid_platform_blade() for them")
    system = disk.hbm_system((0, 1))
    N = system.n_dof
    s, nm = disk.n_sector, disk.n_modes
    n_q = s * nm
    M = sp.csr_matrix(system.mass)
    D = sp.csr_matrix(system.damping)
    K = sp.csr_matrix(system.stiffness)
    blade = slice(0, n_q)
    # the explicit scheme relies on the structure of Eq. 5 and 12: diagonal modal blocks, one
    # inertia block per damper, no damper stiffness or damping, no coupling in M, D, K
    for name, A, diag_blades in (("mass", M, True), ("damping", D, True), ("stiffness", K, True)):
        Ab = A[blade, blade]
        off = Ab - sp.diags(Ab.diagonal())
        if diag_blades and abs(off).sum() > 0:
            raise ValueError(f"time_response needs diagonal modal {name} matrices of the blades")
        if abs(A[blade, n_q:]).sum() + abs(A[n_q:, blade]).sum() > 0:
            raise ValueError(f"time_response needs {name} matrices without blade-damper coupling")
    nd = (N - n_q) // 6
    minv = np.zeros((nd, 6, 6))
    for d in range(nd):
        sl = slice(n_q + 6 * d, n_q + 6 * d + 6)
        Md = M[sl, sl].toarray()
        if abs(D[sl, :]).sum() + abs(K[sl, :]).sum() > 0:
            raise ValueError("time_response needs dampers without structural stiffness or damping")
        if not np.all(np.linalg.eigvalsh(Md) > 0):
            raise ValueError("time_response needs the damper inertia (damper_inertia=True): the explicit "
                             "scheme integrates every damper as a rigid body with mass")
        minv[d] = np.linalg.inv(Md)
        rows = M[sl, :].toarray()
        rows[:, sl] = 0.0                  # the entries coupling this damper to any other unknown
        if np.any(rows != 0.0):
            raise ValueError("time_response needs damper inertia blocks without coupling")
    tip = np.stack([b.shape("tip")[:3] for b in disk.blades])          # (s, 3, nm)
    if nd == 0:
        e = np.zeros
        return AssemblyArrays(system, n_q, M.diagonal()[:n_q], D.diagonal()[:n_q], K.diagonal()[:n_q], minv,
                               e((0, 12, 1)), np.zeros((0, 1), dtype=np.int64), np.zeros(0, dtype=np.int64),
                               e((0, 3, 6)), e(0), e(0), e(0), e(0), np.zeros(0, dtype=np.int64), e((0, 3)), tip,
                               sp.csr_matrix((0, N)), [], K, M)
    coupling = system.couplings[0]
    element = coupling.element
    n_local = element.n_local
    T = sp.csr_matrix(coupling.matrix)[:n_local, :N]          # static block (cos_index(0) = 0)
    Tb_list, idx_list = [], []
    for d in range(nd):
        Td = T[12 * d:12 * d + 12]
        cols = np.unique(Td.indices)
        Tb_list.append(Td[:, cols].toarray())
        idx_list.append(cols)
    m = max(len(c) for c in idx_list)
    Tb = np.zeros((nd, 12, m))
    idx = np.zeros((nd, m), dtype=np.int64)
    for d, (tb, cols) in enumerate(zip(Tb_list, idx_list)):
        Tb[d, :, :len(cols)] = tb
        idx[d, :len(cols)] = cols
    pts = dict(pt_local=[], B=[], k_t=[], mu=[], weight=[], offset=[], law_kind=[], law_par=[])
    geometries = []
    for d, contact in enumerate(element.contacts):
        geometries.append(contact.geometry)
        for q, patch in enumerate(contact.geometry.patches):
            law = normal_law_parameters(patch.normal_law)
            if law is None:
                raise ValueError("time_response supports the LinearNormalLaw and RoughnessNormalLaw normal laws "
                                 f"(got {type(patch.normal_law).__name__})")
            P = patch.n_points
            pts["pt_local"].append(np.full(P, 12 * d + 6 * q))
            pts["B"].append(patch.point_map)
            pts["k_t"].append(patch.tangential_stiffness * patch.weights)     # as DamperContacts.stacked_points
            pts["mu"].append(np.full(P, patch.friction_coefficient))
            pts["weight"].append(patch.weights)
            pts["offset"].append(-patch.initial_gap)                          # approach at w = 0
            pts["law_kind"].append(np.full(P, law[0]))
            pts["law_par"].append(np.tile(law[1], (P, 1)))
    arr = {k: np.ascontiguousarray(np.concatenate(v)) for k, v in pts.items()}
    arr["pt_local"] = arr["pt_local"].astype(np.int64)
    arr["law_kind"] = arr["law_kind"].astype(np.int64)
    P = arr["B"].shape[0]
    rows = (3 * np.arange(P)[:, None, None] + np.arange(3)[None, :, None]) * np.ones((1, 1, 6))
    cols = arr["pt_local"][:, None, None] + np.arange(6)[None, None, :] * np.ones((1, 3, 1))
    Bs = sp.csr_matrix((arr["B"].ravel(), (rows.ravel().astype(int), cols.ravel().astype(int))), shape=(3 * P, n_local))
    return AssemblyArrays(system, n_q, M.diagonal()[:n_q].copy(), D.diagonal()[:n_q].copy(), K.diagonal()[:n_q].copy(),
                           minv, Tb, idx, tip=tip, point_map=(Bs @ T).tocsr(), geometries=geometries, stiffness=K,
                           mass=M, **arr)


def point_normal_forces(arrays: AssemblyArrays, approach: np.ndarray):
    """(N [N], dN/da [N/m]) (P,) of every contact point of the assembly at the approaches
    ``approach`` (P,) [m] (a = offset - u_zeta): :func:`bladedamp.contact.normal.normal_forces`
    with the points' law kinds, parameters and weights."""
    return normal_forces(arrays.law_kind, arrays.law_par, arrays.weight, approach)


def frictionless_static_state(arrays: AssemblyArrays, f_static: np.ndarray, tol: float = 1e-12, max_iter: int = 60):
    """Static equilibrium under the centrifugal load F_CG (Eq. 26) with frictionless contacts:
    K x - Z^T N(offset - Z x) = f_static, Z the normal displacement of every point.
    :func:`bladedamp.hbm.newton.newton` (max norm: residual below ``tol`` of max |f_static|,
    update below sqrt(tol) of the seated displacement) from every damper seated on rigid
    platforms (:func:`~bladedamp.damper.kinetics.seat`); the directions no normal force fixes
    (axial position, the cylinder's roll) stay at zero (minimum-norm steps). With friction this is the equilibrium with every slider at its
    point's tangential displacement (zero tangential force). Returns x (N,)."""
    from .damper.kinetics import seat

    N = arrays.stiffness.shape[0]
    x = np.zeros(N)
    for d, g in enumerate(arrays.geometries):
        o = arrays.n_q + 6 * d
        x[o:o + 6] = seat(g, max(float(f_static[o + 2]), 0.0))[0]
    if not arrays.geometries:
        return np.asarray(np.linalg.lstsq(arrays.stiffness.toarray(), f_static, rcond=None)[0])
    import scipy.sparse as sp

    Z = arrays.point_map[2::3]                            # (P, N) sparse: u_zeta of every point
    K = arrays.stiffness
    scale = np.abs(f_static).max() + 1e-300
    # the free directions (zero stiffness) get a spring 1e-12 of the contact stiffness: their
    # right-hand side is zero, so they stay at zero (to rounding), as minimum-norm steps would
    n_free = np.zeros(N)
    n_free[arrays.n_q:] = 1e-12 * (arrays.law_par[:, 0].max() + arrays.k_t.sum())
    def residual(x, _, jacobian=True):
        normal, dn = point_normal_forces(arrays, arrays.offset - Z @ x)
        R = K @ x - Z.T @ normal - f_static
        return R, ((K + Z.T @ sp.diags(dn) @ Z + sp.diags(n_free)).tocsc() if jacobian else None)

    sol = newton(residual, x, None, max(np.abs(x).max(), 1e-300), scale, tol=tol, max_iter=max_iter, norm=np.inf)
    if sol.converged:
        return sol.x
    R = residual(sol.x, None, False)[0]
    if np.abs(R).max() > 1e-8 * scale:
        raise RuntimeError(f"static equilibrium under the centrifugal load did not converge (residual {np.abs(R).max():.3g} N)")
    return sol.x


def highest_frequency(arrays: AssemblyArrays, x_static: np.ndarray) -> float:
    """Highest natural frequency omega_max [rad/s] of the assembly linearised about the static state with
    every contact point stuck (k_T tangential, dN/da normal; the power law's stiffness at twice
    the static approach): the stability limit of the central differences is dt < 2 / omega_max."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import eigsh

    K = arrays.stiffness
    if arrays.geometries:
        W = arrays.point_map
        approach = arrays.offset - W[2::3] @ x_static
        a_ref = np.where(approach > 0, 2.0 * approach, np.maximum(approach.max(), 0.0) * 2.0)
        _, kn = point_normal_forces(arrays, a_ref)
        if not np.any(kn > 0):
            kn = point_normal_forces(arrays, np.full_like(approach, 1e-9))[1]
        k = np.column_stack([arrays.k_t, arrays.k_t, kn]).ravel()
        K = K + W.T @ sp.diags(k) @ W
    # M^-1/2 K M^-1/2 (M block diagonal: modal masses, 6 x 6 damper inertias)
    N = K.shape[0]
    L = sp.lil_matrix((N, N))
    L[np.arange(arrays.n_q), np.arange(arrays.n_q)] = 1.0 / np.sqrt(arrays.m_q)
    for d in range(arrays.minv.shape[0]):
        lam, V = np.linalg.eigh(arrays.minv[d])
        o = arrays.n_q + 6 * d
        L[o:o + 6, o:o + 6] = (V * np.sqrt(lam)) @ V.T
    L = L.tocsr()
    A = (L @ K @ L).tocsc()
    if N <= 12:
        return float(np.sqrt(max(np.linalg.eigvalsh(A.toarray()).max(), 0.0)))
    lam = eigsh(A, k=1, which="LA", return_eigenvectors=False, tol=1e-6)
    return float(np.sqrt(max(lam.max(), 0.0)))


def series_value(X, basis, tau):
    """x (N,) of the harmonic coefficients X (C, N) in ``basis`` at the phase tau = Omega t [rad]:
    x = X_0 + sum_h (X_h^c cos(h tau) + X_h^s sin(h tau))."""
    x = np.zeros(X.shape[1])
    for h in basis.harmonics:
        j = basis.cos_index(h)
        x += X[j] if h == 0 else X[j] * np.cos(h * tau) + X[j + 1] * np.sin(h * tau)
    return x


def _disk_sliders(arrays, X, basis):
    """(sliders (P, 2) [m] at t = 0, the tangential point motion's amplitude [m]) of the
    assembly's solution X (C, N): each patch's points through the AFT's periodic return map
    (:meth:`~bladedamp.contact.point.PointContactElement.samples`, the patch's k_T x weight, mu,
    normal law, weights and approach -initial gap, as :func:`~bladedamp.timedomain.assembly_arrays`
    and the HBM with the static harmonic), s = u - f / k_T at the first sample (t = 0), u when
    separated."""
    C = basis.n_coeffs
    P = arrays.B.shape[0]
    coeffs = (arrays.point_map @ X.T).T.reshape(C, P, 3)
    sliders = np.zeros((P, 2))
    amplitude = 0.0
    start = 0
    for geometry in arrays.geometries:
        for patch in geometry.patches:
            sl = slice(start, start + patch.n_points)
            start += patch.n_points
            k_t = patch.tangential_stiffness * patch.weights
            element = PointContactElement(k_t, patch.friction_coefficient, patch.normal_law, patch.weights,
                                          -np.asarray(patch.initial_gap, dtype=float) * np.ones(patch.n_points))
            pts = element.samples(np.ascontiguousarray(coeffs[:, sl]).reshape(C, -1), basis)
            u, f = pts.displacement[:, 0, :2], pts.force[:, 0, :2]
            separated = pts.state[:, 0] == SEPARATED
            sliders[sl] = np.where(separated[:, None], u, u - f / k_t[:, None])
            ut = pts.displacement[:, :, :2]
            amplitude = max(amplitude, float(np.abs(ut - ut.mean(axis=1, keepdims=True)).max()))
    return sliders, amplitude


def orbit_state(arrays, X, basis, omega: float, dt: float):
    """(z (2 N + 2 P,), the tangential point motion's amplitude [m]) the state of the
    central-difference integration (:func:`bladedamp.timedomain.disk_period`, time step ``dt``
    [s]) on the periodic orbit of the full assembly's harmonic solution X (C, N) in ``basis``
    (with the static harmonic) at ``omega`` [rad/s], at t = 0: z = (x(0), x(-dt), slider
    positions (P, 2) row-major), x from the Fourier series and every friction slider from the
    contact's periodic return map over one period of that motion (the AFT's, see
    :mod:`bladedamp.hbm.monodromy`); ``arrays`` the assembly's :class:`~bladedamp.timedomain.AssemblyArrays`. The
    start of the monodromy's period map and of a time integration that tests the orbit
    (``disk_time_response(..., start_coefficients=...)``)."""
    sliders, slider_amp = _disk_sliders(arrays, X, basis)
    z = np.concatenate([series_value(X, basis, 0.0), series_value(X, basis, -omega * dt), sliders.ravel()])
    return z, slider_amp



@dataclass
class DiskTimeResponse(Saveable):
    """Steady state of a bladed disk by time integration of the full assembly, one run per
    excitation frequency (see :func:`disk_time_response`).

    Attributes (n frequencies, s blades, n_d dampers, P contact points, S steps per period)
    ----------
    omega : (n,) excitation frequency Omega_E [rad/s]
    tip_amplitude : (n, s, 3) first-harmonic tip amplitude of every blade in x, y, z [m]
        (last period; for a drifting state whose first harmonics fluctuate from period to
        period, their mean over the last 2 drift_periods periods)
    tip_harmonic : (n, s, 3) complex first harmonic X (tip = Re(X e^{i Omega t})) [m]
    tip_samples : (n, s, 3, S) tip displacement over the last period [m]
    dissipated_energy : (n,) friction dissipation per period, all contacts [J]
    damper_dissipation : (n, n_d) friction dissipation of each damper per period [J]
    excitation_work : (n,) work of the harmonic excitation per period [J]
    viscous_dissipation : (n,) modal damping dissipation of the blades per period [J]
        (these four: of the last period, or the mean over the same periods as the tip amplitudes
        where those are a mean of a fluctuating or drifting motion)
    periods : (n,) periods integrated
    periodic : (n,) a steady periodic state was reached
    status : (n,) "periodic", "drifting", "not settled" or "unstable"
    message : (n,) what was found, with the numbers
    settling : (n,) change of the first harmonics in the last period, relative to the largest
    damper_mean : (n, n_d, 6) mean damper displacement over the last period [m, rad]
    damper_drift : (n, n_d, 6) change of that mean in the last period [m, rad per period]
    point_state : (n, P, 3) share of the last period each point sticks, slips, is separated
    steps_per_period : S; time_step : (n,) [s]
    static_state : (n, N) static equilibrium under F_CG
    tip_history : n arrays (periods, s, 3) complex, the first harmonic of every period (settling)
    damper_history : n arrays (periods, n_d, 6), the period mean of the damper coordinates
    start : (n,) the state the run started from: "static equilibrium" (at rest under F_CG) or
        "HBM solution" (on the orbit of a harmonic solution, ``start_coefficients``)
    residual_drift : (n,) where the first harmonics had not settled to ``tol`` after
        ``max_periods``: the bound on the last block mean's distance from the limit of the
        period-to-period map, relative to the amplitude (:func:`map_convergence`; inf where it
        does not converge); NaN where not needed
    decay_rate : the slowest viscous decay rate of the blade modes, sigma = min c_q / (2 m_q) =
        min zeta omega_n [1/s] (0 if a mode is undamped): a transient of that mode decays as
        exp(-sigma t)
    """

    omega: np.ndarray
    tip_amplitude: np.ndarray
    tip_harmonic: np.ndarray
    tip_samples: np.ndarray
    dissipated_energy: np.ndarray
    damper_dissipation: np.ndarray
    excitation_work: np.ndarray
    viscous_dissipation: np.ndarray
    periods: np.ndarray
    periodic: np.ndarray
    status: np.ndarray
    message: np.ndarray
    settling: np.ndarray
    damper_mean: np.ndarray
    damper_drift: np.ndarray
    point_state: np.ndarray
    steps_per_period: int
    time_step: np.ndarray
    static_state: np.ndarray
    tip_history: list
    damper_history: list
    start: np.ndarray | None = None
    residual_drift: np.ndarray | None = None
    decay_rate: float = np.nan

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.omega / (2 * np.pi)

    @property
    def n_blades(self) -> int:
        return self.tip_amplitude.shape[1]

    def energy_balance_error(self) -> np.ndarray:
        """|W_exc - W_visc - W_friction| / W_exc per frequency (over the periods of the works)."""
        return np.abs(self.excitation_work - self.viscous_dissipation - self.dissipated_energy) / np.abs(self.excitation_work)

    def plot(self, ax=None, *, direction: int = 0, blades=None, **kwargs):
        """First-harmonic tip amplitude [mm] over frequency [Hz], one marker series per blade
        (``blades``: indices, default all; a tuned disk's blades coincide); points that are not
        periodic are drawn as open markers."""
        import matplotlib.pyplot as plt

        own = ax is None
        if own:
            _, ax = plt.subplots(figsize=(6, 4))
        blades = range(self.n_blades) if blades is None else blades
        kwargs.setdefault("marker", "o")
        kwargs.setdefault("linestyle", "none")
        label = kwargs.pop("label", "time integration")
        f = self.frequency_hz
        for i, k in enumerate(blades):
            a = 1e3 * self.tip_amplitude[:, k, direction]
            line, = ax.plot(f[self.periodic], a[self.periodic], label=label if i == 0 else None, **kwargs)
            if np.any(~self.periodic):
                kw = dict(kwargs, color=line.get_color(), markerfacecolor="none")
                ax.plot(f[~self.periodic], a[~self.periodic],
                        label="not periodic" if i == 0 else None, **kw)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel(f"tip amplitude u_{'xyz'[direction]} [mm]")
        ax.grid(True, alpha=0.3)
        ax.legend()
        if own:
            ax.figure.tight_layout()
        return ax


_DOF = ("u_x", "u_y", "u_z", "phi_x", "phi_y", "phi_z")


def drift_verdict(means, scale, tol):
    """(damper, coordinate, rate per period) if the period means (W+1, n_d, 6) of the damper
    coordinates move steadily: monotonic over the window (net change >= 0.9 x the sum of the
    per-period changes), at an undiminished rate (second half >= 0.8 x first half) that is
    well above the settling tolerance (> 10 tol x ``scale`` (6,), the vibration amplitude of
    that kind of coordinate). A transient of the mean oscillates or decays and fails one of
    these; a rolling cylinder or a damper walking axially passes all. Else None."""
    inc = np.diff(means, axis=0)                               # (W, n_d, 6)
    net = means[-1] - means[0]
    total = np.abs(inc).sum(axis=0)
    half = inc.shape[0] // 2
    first = np.abs(inc[:half].sum(axis=0))
    second = np.abs(inc[half:2 * half].sum(axis=0))
    rate = net / inc.shape[0]
    steady = (np.abs(net) >= 0.9 * total) & (second >= 0.8 * first) & (np.abs(rate) > 10 * tol * scale[None, :])
    if not np.any(steady):
        return None
    rel = np.where(steady, np.abs(rate) / scale[None, :], 0.0)
    d, a = np.unravel_index(np.argmax(rel), rel.shape)
    return int(d), int(a), float(rate[d, a])


class MapConvergence(NamedTuple):
    """The convergence of a time integration's period-to-period map (:func:`map_convergence`)."""
    converged: bool
    residual: float          # bound on the last block mean's distance from the limit, relative to the amplitude
    contraction: float       # q, per block
    block: int               # L, periods per block
    change: float            # c_2, the mean change per period over the last block, relative
    change_before: float     # c_1, the same over the block before


def map_convergence(history, decay_per_period: float, settle_tol: float, fluctuation_tol: float) -> MapConvergence:
    """Whether the period-to-period map of a time integration converges (a
    :class:`MapConvergence`) from ``history`` (p, ...) complex, the first
    harmonics of p consecutive periods. The means over the last three blocks of L = p // 4
    periods (a mean averages out a fluctuation from period to period) differ by D_1 (older) and
    D_2 (newer), relative to the largest first harmonic, and the mean change from one period to
    the next is c_1 over the middle block and c_2 over the last. A transient that decays at least
    geometrically by q per block leaves the newest mean at most D_2 q / (1 - q) from the limit
    (the geometric tail); q is the larger of the observed D_2 / D_1 and exp(-sigma T L), the
    decay over a block of the slowest viscously damped blade mode (``decay_per_period`` = sigma T,
    sigma = zeta omega_n [1/s] of that mode, T the period; friction only adds damping). The
    transient's share of the per-period change shrinks by q per block too, on top of a fluctuation
    that does not decay (the dampers ringing on their contact springs) of at most
    ``fluctuation_tol``: c_2 <= q c_1 + fluctuation_tol. A motion that is not periodic (a damper
    hopping) keeps changing from period to period by about as much in every block, c_2 about
    c_1 above the fluctuation, and fails it, whatever its block means do. Converged when q < 1,
    c_2 <= q c_1 + fluctuation_tol and the residual drift is at most ``settle_tol``."""
    p = len(history)
    L = p // 4
    if L < 1:
        return MapConvergence(False, np.inf, np.inf, L, np.inf, np.inf)
    means = [np.mean(history[p - (j + 1) * L:p - j * L], axis=0) for j in (2, 1, 0)]
    amp = max(np.abs(means[-1]).max(), 1e-300)
    d1 = np.abs(means[1] - means[0]).max() / amp
    d2 = np.abs(means[2] - means[1]).max() / amp
    steps = np.abs(np.diff(history[p - 2 * L - 1:], axis=0)).reshape(2 * L, -1).max(axis=1) / amp
    c1, c2 = steps[:L].mean(), steps[L:].mean()
    q = max(d2 / max(d1, 1e-300), float(np.exp(-decay_per_period * L)))
    residual = d2 * q / (1 - q) if q < 1 else np.inf
    return MapConvergence(bool(residual <= settle_tol and c2 <= q * c1 + fluctuation_tol), float(residual), float(q), L,
                          float(c2), float(c1))


def row_nonzeros(A):
    """(nnz (n, r) int64, columns (n, r, c) int64) of the rows of a stack of matrices (n, r, c):
    the sparsity arguments (t_nnz, t_col of ``Tb``; b_nnz, b_col of ``B``) of :func:`disk_period`."""
    nz = A != 0
    nnz = nz.sum(axis=2).astype(np.int64)
    cols = np.zeros(A.shape, dtype=np.int64)
    for idx in np.ndindex(A.shape[:2]):
        c = np.flatnonzero(nz[idx])
        cols[idx][:len(c)] = c
    return nnz, cols


def disk_time_response(disk, f_hz, tol: float = 1e-5, min_periods: int = 20, max_periods: int = 4000,
                       n_stable: int = 5, drift_periods: int = 40, steps_per_period: int | None = None,
                       stability_margin: float = 0.8, fluctuation_tol: float = 2e-4, settle_tol: float = 1e-3,
                       start_coefficients=None, start_basis=None) -> DiskTimeResponse:
    """Steady-state forced response of a full-assembly MistunedDisk by time integration.

    Each frequency f_hz [Hz] is a separate run: the assembly starts at rest in its static
    equilibrium under the centrifugal load F_CG = m R Omega_E^2 / EO^2 (Eq. 26, constant during
    the run; :func:`frictionless_static_state`: frictionless seating on the flexible blades, every slider
    at its point's tangential displacement, so no tangential force), then the harmonic
    excitation of the HBM (blade k's tip load f cos(Omega t + k dphi), dphi = 2 pi EO / n, as
    :meth:`MistunedDisk.hbm_system`) is switched on at t = 0. Or, with ``start_coefficients``
    (n, C, N) (one harmonic solution of the full assembly per frequency, in ``start_basis``,
    which has the static harmonic), each run starts on that solution's orbit
    (:func:`bladedamp.hbm.monodromy.orbit_state`: displacement and previous step from the
    Fourier series, every friction slider from the contact's periodic return map over one period
    of the motion), so it tests that branch: a motion that stays on it settles within the
    harmonic truncation error of it. Central differences
    (:func:`disk_period`), ``steps_per_period`` steps, the same for every frequency of the
    call (default: the more of MIN_STEPS_PER_PERIOD = 512, for accuracy, and the steps at
    ``stability_margin`` x the stability limit 2 / omega_max of the stuck linearised assembly;
    a given value below that limit is a ValueError).

    Parameters: f_hz scalar or (n,) [Hz]; tol relative change of the first harmonics per period
    in (0, 0.1]; min_periods, max_periods periods integrated at least / at most; n_stable
    consecutive settled periods; drift_periods window of the drift test; fluctuation_tol see
    below.

    Steady state: the complex first harmonic of every blade's tip (3 directions, DFT of each
    period) changes by at most ``tol`` x the largest of them for ``n_stable`` consecutive
    periods (after at least ``min_periods``), and the period mean of every damper coordinate
    changes by at most ``tol`` x the vibration amplitude of its kind (translations, rotations).
    The remaining transient is then about tol / (2 pi zeta_eff) of the amplitude (zeta_eff the
    effective damping ratio; ~5e-4 at the defaults for the reference dampers). If the first
    harmonics settle but a damper's mean keeps moving at an undiminished rate for
    ``drift_periods`` periods (a cylinder rolling along the platforms, a damper walking
    axially), the motion is not periodic: status "drifting", with the rate. First harmonics
    that keep fluctuating from period to period (by more than ``tol``; for example a period-2
    pattern, most likely the undamped ringing of the dampers on their contact springs, which
    the model does not damp, or the beat of a lightly damped transient) are judged by their
    mean over 2 ``drift_periods`` periods: "periodic
    within a fluctuation" when that mean settles (a trend <= tol per period) and the
    fluctuation is at most ``fluctuation_tol`` per period; the tip amplitudes are then that
    mean (a beat of the transient averages out of it).

    First harmonics still changing by more than ``tol`` after ``max_periods`` periods are judged
    by the convergence of the period-to-period map (:func:`map_convergence`): a lightly damped
    transient decays as exp(-zeta omega_n t), so its share left after max_periods may well
    exceed ``tol`` per period while the motion converges. When the means of the first harmonics
    over the last blocks of max_periods / 4 periods approach their limit geometrically and the
    residual drift (the distance of the last block's mean from that limit, bounded with the
    slowest contraction of the observed one and the blades' viscous decay) is at most
    ``settle_tol`` of the amplitude, the motion is periodic (or drifting, if a damper's mean
    moves steadily), its tip amplitudes the last block's mean; else status "not settled", with
    the residual drift in the message: no periodic motion within ``max_periods``. "unstable" if
    the integration diverges.

    Returns a :class:`DiskTimeResponse`.
    """
    from . import validation

    f_hz = np.atleast_1d(np.asarray(validation.positive("f_hz (excitation frequency, Hz)", f_hz), dtype=float))
    if f_hz.ndim != 1:
        raise ValueError("f_hz must be a scalar or a 1-D array of frequencies in Hz")
    validation.in_range("tol", tol, 0.0, 0.1, closed="right")
    min_periods = validation.integer("min_periods", min_periods, minimum=1)
    max_periods = validation.integer("max_periods", max_periods, minimum=min_periods)
    n_stable = validation.integer("n_stable", n_stable, minimum=1)
    drift_periods = validation.integer("drift_periods", drift_periods, minimum=2)
    validation.in_range("stability_margin", stability_margin, 0.0, 1.0, closed="right")
    validation.in_range("fluctuation_tol", fluctuation_tol, 0.0, 0.1, closed="right")
    validation.in_range("settle_tol", settle_tol, 0.0, 0.1, closed="right")
    if disk.n_sector != disk.n_blades:
        raise ValueError(f"time_response integrates the full assembly: len(blades) must equal n_blades "
                         f"({disk.n_blades}), got a cyclic sector of {disk.n_sector}")
    arrays = assembly_arrays(disk)
    system = arrays.system
    damped = arrays.c_q > 0
    decay_rate = float((arrays.c_q[damped] / (2 * arrays.m_q[damped])).min()) if damped.all() else 0.0
    N, C = system.n_dof, system.basis.n_coeffs
    omega = 2 * np.pi * f_hz
    if start_coefficients is not None:
        if start_basis is None or not start_basis.has_static:
            raise ValueError("start_basis must be the HarmonicBasis of start_coefficients, with the static harmonic 0 "
                             "(the time integration seats the dampers under F_CG)")
        start_coefficients = np.asarray(start_coefficients, dtype=float)
        if start_coefficients.shape != (f_hz.size, start_basis.n_coeffs, N):
            raise ValueError(f"start_coefficients must have the shape (n_f, C, N) = ({f_hz.size}, "
                             f"{start_basis.n_coeffs}, {N}) of the full assembly, got {start_coefficients.shape}")
    loads, statics = [], []
    w_max = 0.0
    for w in omega:
        f = system.excitation(w)[0].reshape(C, N)        # rows: static (F_CG), cos, sin (basis (0, 1))
        loads.append(f)
        x0 = frictionless_static_state(arrays, f[0])
        statics.append(x0)
        w_max = max(w_max, highest_frequency(arrays, x0))
    dt_limit = 2.0 / w_max
    needed = int(np.ceil(2 * np.pi / omega.min() / (stability_margin * dt_limit)))
    if steps_per_period is None:
        steps = max(MIN_STEPS_PER_PERIOD, needed)
    else:
        steps = validation.integer("steps_per_period", steps_per_period, minimum=16)
        if 2 * np.pi / omega.min() / steps > dt_limit:
            raise ValueError(f"steps_per_period must be at least {int(np.ceil(2 * np.pi / omega.min() / dt_limit))} "
                             f"(stability limit of the explicit scheme, omega_max = {w_max:.4g} rad/s; got {steps})")
    s, nd, P = disk.n_sector, arrays.minv.shape[0], arrays.B.shape[0]
    n = omega.size
    out = dict(tip_harmonic=np.zeros((n, s, 3), complex), tip_samples=np.zeros((n, s, 3, steps)),
               dissipated_energy=np.zeros(n), damper_dissipation=np.zeros((n, nd)), excitation_work=np.zeros(n),
               viscous_dissipation=np.zeros(n), periods=np.zeros(n, dtype=int), periodic=np.zeros(n, dtype=bool),
               status=np.empty(n, dtype=object), message=np.empty(n, dtype=object), settling=np.zeros(n),
               damper_mean=np.zeros((n, nd, 6)), damper_drift=np.zeros((n, nd, 6)), point_state=np.zeros((n, P, 3)),
               time_step=2 * np.pi / omega / steps, static_state=np.array(statics), tip_history=[],
               damper_history=[], start=np.array(["static equilibrium" if start_coefficients is None else
                                                  "HBM solution"] * n, dtype=object),
               residual_drift=np.full(n, np.nan), decay_rate=decay_rate)
    t_nnz, t_col, b_nnz, b_col = arrays.sparsity
    tip_dft = np.zeros((s, 3, 2))
    damper_mean = np.zeros((nd, 6))
    damper_dft = np.zeros((nd, 6, 2))
    damper_work = np.zeros(nd)
    point_states = np.zeros((P, 3), dtype=np.int64)
    energies = np.zeros(2)
    for i, w in enumerate(omega):
        f = loads[i]
        dt = 2 * np.pi / w / steps
        if start_coefficients is None:
            x = statics[i].copy()
            x_prev = x.copy()
            slider = np.ascontiguousarray((arrays.point_map @ x).reshape(P, 3)[:, :2]) if P else np.zeros((0, 2))
        else:
            z, _ = orbit_state(arrays, start_coefficients[i], start_basis, w, dt)
            x, x_prev = z[:N].copy(), z[N:2 * N].copy()
            slider = np.ascontiguousarray(z[2 * N:].reshape(P, 2))
        X_old, mean_old = None, None
        stable = 0
        changes = []
        status, message = "not settled", ""
        change = np.inf
        tip_hist, mean_hist, work_hist = [], [], []
        window = None                    # periods the reported values are the mean over (None: the last one)
        for period in range(max_periods):
            disk_period(steps, dt, arrays.n_q, arrays.m_q, arrays.c_q, arrays.k_q, arrays.minv, f[0], f[1], f[2],
                         arrays.Tb, arrays.idx, arrays.pt_local, arrays.B, arrays.k_t, arrays.mu, arrays.weight,
                         arrays.offset, arrays.law_kind, arrays.law_par, t_nnz, t_col, b_nnz, b_col, arrays.tip,
                         x, x_prev, slider,
                         out["tip_samples"][i], tip_dft, damper_mean, damper_dft, damper_work, point_states, energies)
            X = tip_dft[:, :, 0] - 1j * tip_dft[:, :, 1]
            tip_hist.append(X)
            mean_hist.append(damper_mean.copy())
            work_hist.append(np.concatenate([energies[:2], damper_work]))
            if not np.all(np.isfinite(X)) or not np.all(np.isfinite(x)):
                status = "unstable"
                message = (f"unstable: the explicit integration diverged in period {period + 1} "
                           f"({steps} steps per period); give more steps_per_period")
                break
            if X_old is not None:
                change = np.abs(X - X_old).max() / max(np.abs(X).max(), 1e-300)
                stable = stable + 1 if change <= tol else 0
            drift = damper_mean - mean_old if mean_old is not None else np.full((nd, 6), np.inf)
            X_old, mean_old = X, damper_mean.copy()
            amp = np.abs(damper_dft[:, :, 0] - 1j * damper_dft[:, :, 1])
            scale = np.array([amp[:, :3].max(initial=0.0), amp[:, 3:].max(initial=0.0)]) + 1e-300
            rel = np.abs(drift) / np.repeat(scale, 3)[None, :] if nd else np.zeros((0, 6))
            changes.append(change)
            p = period + 1
            if p < min_periods:
                continue
            settled = stable >= n_stable
            if settled and (nd == 0 or rel.max() <= tol):
                # the first harmonics are periodic, and so are the damper positions
                status = "periodic"
                message = f"periodic: first harmonics settled to {change:.1e} per period after {p} periods"
                break
            W = drift_periods
            if nd == 0 or p <= W or not (settled or p % max(W // 4, 1) == 0):
                continue
            verdict = drift_verdict(np.array(mean_hist[-W - 1:]), np.repeat(scale, 3), tol)
            trend = None
            if not settled and p >= 4 * W:
                # first harmonics that fluctuate from period to period (undamped ringing of the
                # dampers on their contact stiffness: the model has no contact damping) may
                # still settle on average: compare their means over the last 2 W periods and
                # the 2 W before (a trend of at most tol per period)
                recent = np.mean(tip_hist[-2 * W:], axis=0)
                before = np.mean(tip_hist[-4 * W:-2 * W], axis=0)
                trend = np.abs(recent - before).max() / max(np.abs(recent).max(), 1e-300) / (2 * W)
                jitter = float(np.mean(changes[-2 * W:]))
            if verdict is None:
                if stable >= W:
                    # the damper means fluctuate but do not drift over W periods: periodic
                    status = "periodic"
                    message = (f"periodic: first harmonics settled to {change:.1e} per period after {p} periods "
                               f"(damper means fluctuate by up to {rel.max():.1e} of the vibration amplitude "
                               f"per period, without drift over {W} periods)")
                    break
                if trend is not None and trend <= tol and jitter <= fluctuation_tol:
                    X, window = recent, 2 * W     # report the mean first harmonic (and works)
                    status = "periodic"
                    message = (f"periodic within a fluctuation: first harmonics fluctuate by {jitter:.1e} per period "
                               f"(mean over {2 * W}; <= fluctuation_tol {fluctuation_tol:g}) about a mean that settled "
                               f"to {trend:.1e} per period, after {p} periods (the tip amplitudes are that mean over "
                               f"the last {2 * W} periods); the dampers do not drift")
                    break
                continue
            if not settled:
                # a steady drift while the first harmonics still change: wait until their mean settles
                if trend is None or trend > tol:
                    continue
                X, window = recent, 2 * W         # not periodic: report the mean first harmonic
            d, a, rate = verdict
            kind = "rotation" if a >= 3 else "translation"
            unit = "rad" if a >= 3 else "m"
            status = "drifting"
            how = (f"settled to {change:.1e} per period" if settled else
                   f"fluctuate by {np.mean(changes[-2 * W:]):.1e} per period about a mean that settled to "
                   f"{trend:.1e} per period (the tip amplitudes are that mean over the last {2 * W} periods)")
            message = (f"drifting: damper {kind} {_DOF[a]} grows by {rate:.3g} {unit} per period "
                       f"(damper {disk.active_dampers[d]}, {100 * abs(rate) / scale[a // 3]:.3g} % of the dampers' "
                       f"{kind} amplitude, steadily over the last {W} periods) while the first harmonics {how}; "
                       f"after {p} periods")
            break
        else:
            # the period-to-period map after max_periods: converging (a lightly damped transient)
            # or not (no periodic motion)
            p = max_periods
            verdict = drift_verdict(np.array(mean_hist[-drift_periods - 1:]), np.repeat(scale, 3), tol) \
                if nd and p > drift_periods else None
            conv = map_convergence(np.array(tip_hist), decay_rate * 2 * np.pi / w, settle_tol, fluctuation_tol)
            converged, residual, q, L = conv.converged, conv.residual, conv.contraction, conv.block
            out["residual_drift"][i] = residual
            how = (f"the period-to-period map converges: the first harmonics' means over the last blocks of {L} "
                   f"periods approach their limit by a factor {q:.3g} per block (the slowest blade mode's viscous "
                   f"decay alone gives {np.exp(-decay_rate * 2 * np.pi / w * L):.3g}), a residual drift of "
                   f"{residual:.2g} of the amplitude, within settle_tol {settle_tol:g}; the first harmonics still "
                   f"change by {change:.2g} per period (tol {tol:g}) after {p} periods, and the tip amplitudes are "
                   f"the mean over the last {L} periods")
            if converged and verdict is None:
                X, window = np.mean(tip_hist[-L:], axis=0), L
                status = "periodic"
                message = f"periodic: {how}"
            elif converged:
                X, window = np.mean(tip_hist[-L:], axis=0), L
                d, a, rate = verdict
                kind = "rotation" if a >= 3 else "translation"
                status = "drifting"
                message = (f"drifting: damper {kind} {_DOF[a]} grows by {rate:.3g} {'rad' if a >= 3 else 'm'} per "
                           f"period (damper {disk.active_dampers[d]}, {100 * abs(rate) / scale[a // 3]:.3g} % of the "
                           f"dampers' {kind} amplitude, steadily over the last {drift_periods} periods) while {how}")
            else:
                message = (f"not settled: first harmonics changed by {change:.2g} per period (tol {tol:g}) after {p} "
                           f"periods, and the period-to-period map does not converge to settle_tol {settle_tol:g}: "
                           + (f"the means over the last blocks of {L} periods approach a limit by a factor {q:.3g} "
                              f"per block, a residual drift of {residual:.2g} of the amplitude, and the first "
                              f"harmonics change by {conv.change:.2g} per period over the last block against "
                              f"{conv.change_before:.2g} over the one before (a converging transient's change "
                              f"shrinks by that factor, on top of a fluctuation of at most fluctuation_tol "
                              f"{fluctuation_tol:g})"
                              if q < 1 else f"the means over the last blocks of {L} periods move apart (a factor "
                              f"{q:.3g} per block)"))
        out["tip_harmonic"][i] = X
        # the works of the last period, or their mean over the same periods as a mean first harmonic
        # (a fluctuating motion's last period stores or releases energy, which the mean over the
        # periods averages out)
        works = np.mean(work_hist[-window:], axis=0) if window else work_hist[-1]
        out["dissipated_energy"][i] = works[2:].sum()
        out["damper_dissipation"][i] = works[2:]
        out["excitation_work"][i] = works[0]
        out["viscous_dissipation"][i] = works[1]
        out["periods"][i] = period + 1
        out["periodic"][i] = status == "periodic"
        out["status"][i] = status
        out["message"][i] = message
        out["settling"][i] = change
        out["damper_mean"][i] = damper_mean
        out["damper_drift"][i] = drift if np.all(np.isfinite(drift)) else np.nan
        out["point_state"][i] = point_states / steps
        out["tip_history"].append(np.array(tip_hist))
        out["damper_history"].append(np.array(mean_hist).reshape(len(mean_hist), nd, 6))
    return DiskTimeResponse(omega, np.abs(out["tip_harmonic"]), steps_per_period=steps, **out)


def hbm_tip_at(disk, f_hz, harmonics=(0, 1, 2, 3), pad_hz: float = 1.0, max_step: float = DEFAULT_MAX_STEP,
               **continuation_options) -> np.ndarray:
    """First-harmonic tip amplitude of the harmonic balance at the exact frequencies ``f_hz``
    [Hz], to compare with a :class:`DiskTimeResponse`: the FRF by continuation over the range
    (``pad_hz`` beyond it at both ends), the branch interpolated linearly at each frequency and
    corrected there by Newton on the HBM residual (to 1e-12 of the solution).

    ``harmonics=None`` uses ``frequency_response``'s default. Returns (n, 3) [m] for a
    TunedDisk (the reference blade), (n, s, 3) for a model of s = ``disk.n_sector`` blades (a
    MistunedDisk: every blade).
    """
    import warnings

    from . import validation

    f_hz = np.atleast_1d(np.asarray(validation.positive("f_hz (excitation frequency, Hz)", f_hz), dtype=float))
    validation.positive("pad_hz", pad_hz)
    kw = {} if harmonics is None else {"harmonics": tuple(harmonics)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(f_hz.min() - pad_hz, f_hz.max() + pad_hz, max_step=max_step,
                                    **kw, **continuation_options)
    if not r.success:
        raise RuntimeError(f"HBM continuation failed: {r.message}")
    basis = r.basis
    system = disk.hbm_system(basis.harmonics, basis.n_samples)
    X = r.coefficients.reshape(len(r.omega), -1)
    scales = disk.unknown_scales(system, float(r.omega.min()), float(r.omega.max()))
    order = np.argsort(r.omega)
    om, Xs = r.omega[order], X[order]
    out = []
    for f in f_hz:
        w = 2 * np.pi * f
        i = int(np.clip(np.searchsorted(om, w), 1, len(om) - 1))
        t = (w - om[i - 1]) / (om[i] - om[i - 1])
        x = (1 - t) * Xs[i - 1] + t * Xs[i]
        rs = max(np.linalg.norm(system.residual(np.zeros_like(x), w, False)[0]), 1e-300)
        sol = newton(system.residual, x, w, scales, rs, tol=1e-12, max_iter=40, factorize=system.factorize)
        if not sol.converged:
            raise RuntimeError(f"HBM Newton did not converge at {f} Hz")
        out.append(disk.output_amplitudes(sol.x.reshape(1, basis.n_coeffs, -1), basis)[0])
    out = np.array(out)                                              # (n, 3 s)
    n_sector = getattr(disk, "n_sector", None)          # blades written out (MistunedDisk); a TunedDisk: its sector
    return out if n_sector is None else out.reshape(len(f_hz), n_sector, 3)

