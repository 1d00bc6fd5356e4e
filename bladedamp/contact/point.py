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
through the return map), which gives the exact Jacobian of the AFT forces. Within one period
the slider derivative is affine in its value at the period start, with a 2x2 transfer Phi
common to all coefficients, so its periodic value is solved for in closed form from one
pass (the limit of infinitely many passes) instead of repeating passes until it settles; the
same 2x2 solve is a Newton step making the slider start periodic (see
:func:`_point_return_map`).

:func:`point_contact_forces` works on given point coefficients; :func:`damper_contact_forces`
is the same computation fused for the two patches of many dampers (point motion from the
damper coordinates, normal law, return map, AFT and the projection back, in one numba call),
used by :class:`bladedamp.diskmodel.AssemblyContacts`. Both run the per-point return map
:func:`_point_return_map`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .laws import normal_law_parameters
from .normal import normal_force

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


# Periodic slider derivative in closed form (see _point_return_map), Phi the 2x2 transfer of
# the slider derivative over one period: the closed form is used when |det(I - Phi)| >=
# SINGULAR_DET, else the derivative is iterated pass by pass as before (_iterate_passes).
# det(I - Phi) = 1 - lambda, lambda the eigenvalue of the rank-1 Phi (|lambda| <= product of
# g = mu N / |trial| over the slip samples). On slipping points it is either of order 1e-3 or
# more, or of rounding size (Phi = I, or a "slip" by rounding at the friction limit: a stuck
# slider, whose periodic position is not unique); the threshold sits in that gap
# (benchmarks/README.md, 'Moved from the package's docstrings', contact/point.py). The
# closed form loses about eps / det of relative accuracy (2e-10 at the threshold); below it the
# previous iteration, which keeps the initial slider and its derivative convention, defines it.
SINGULAR_DET = 1e-6
# Largest Newton step of the periodic slider start position, relative to mu max N / k_T,
# applied to the forces and slip work as a linear correction (see _point_return_map): after
# the position test the step is ~tol / det; a larger one is no small correction.
NEWTON_STEP_MAX = 1e-6
# the return map's defaults: at most MAX_PASSES periods, repeated until the slider position at
# the period end repeats to PERIODIC_TOL of mu max N / k_T (point_contact_forces, PointContactElement)
MAX_PASSES = 20
PERIODIC_TOL = 1e-10


@njit(cache=True)
def touchdown_seats(approach, seat, seat_rate):
    """Where a separated point closes between two samples, for the slider's seat.

    approach (P, T) samples of the normal approach a of P points (contact where a > 0,
    periodic). Writes seat[p, t] = theta = -a_t / (a_{t+1} - a_t) in [0, 1) and
    seat_rate[p, t] = 1 / (a_{t+1} - a_t) [1/m] at every separated sample t followed by a
    closed one (the linear interpolation of the approach crosses zero at t + theta), zero
    elsewhere (all points in one call: a call per point cost 1 us each).

    A separated slider follows the displacement and is seated where the contact closes: at
    u_t + theta (u_{t+1} - u_t), not at the last separated sample u_t. Seating it at the
    sample makes an error of order (dt du/dt) k_T in the tangential force over the whole
    following stick phase, and so of order dt in the forces' harmonics; seated here, the error
    is of second order, with no spurious slip at touchdown (benchmarks/README.md, 'Moved from
    the package's docstrings', contact/point.py). The closing instant is interpolated
    linearly in the approach, a smooth function of time, so the seat is exact to second order. With the static term
    (theta, the approach) depend on the normal coefficients: d theta / d a_t = -(1 - theta) /
    da, d theta / d a_{t+1} = -theta / da, da = a_{t+1} - a_t, and a = offset - u_zeta, so
    d theta / d c_zeta = ((1 - theta) E_t + theta E_{t+1}) * seat_rate (E the synthesis rows).
    """
    P, T = approach.shape
    for p in range(P):
        for t in range(T):
            a0 = approach[p, t]
            a1 = approach[p, (t + 1) % T]
            if a0 <= 0.0 < a1:
                seat[p, t] = -a0 / (a1 - a0)
                seat_rate[p, t] = 1.0 / (a1 - a0)
            else:
                seat[p, t] = 0.0
                seat_rate[p, t] = 0.0


@njit(cache=True)
def _slider_pass(ut, normal, seat, kt, mu, s0, s1, f_out, state_out):
    """One period of the slider without derivatives: (s0, s1 at the end, moved, slip work);
    writes f_out[:, 0:2] and state_out. ``seat`` (T,): see :func:`touchdown_seats`."""
    moved = False
    work = 0.0
    T = ut.shape[0]
    for t in range(T):
        n = normal[t]
        f0, f1, n_s0, n_s1, st = slider_step(ut[t, 0], ut[t, 1], s0, s1, kt, mu * n, n > 0.0)
        if st == SEPARATED and seat[t] != 0.0:
            # the contact closes before the next sample: seat the slider where it closes
            t1 = (t + 1) % T
            n_s0 += seat[t] * (ut[t1, 0] - ut[t, 0])
            n_s1 += seat[t] * (ut[t1, 1] - ut[t, 1])
        f_out[t, 0] = f0
        f_out[t, 1] = f1
        state_out[t] = st
        if st != STICK:
            moved = True
            work += f0 * (n_s0 - s0) + f1 * (n_s1 - s1)
        s0 = n_s0
        s1 = n_s1
    return s0, s1, moved, work


@njit(cache=True)
def _derivative_pass(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, f_out, df_out,
                     state_out, ds, transfer, track):
    """One period of the slider carrying its derivative ds (2, 3C) (updated in place) and
    writing df_out (see :func:`_point_return_map`); returns (s0, s1, moved, slip work, gw0, gw1).

    With ``track``, transfer[t] = (M00, M01, M10, M11) of M_t = A_t ... A_0, the transfer
    d ds_t / d ds_begin up to sample t (A = I in stick, A = g (I - e e^T) in slip, A = 0
    when separated), which is also d s_t / d s_begin, d f_t / d s_begin = -k_T M_t; and
    (gw0, gw1) = d (slip work) / d s_begin. Without ``track`` transfer is not touched and
    gw = 0; the pass itself is the same arithmetic either way. (df_out is indexed, not
    sliced into row views: a view per sample costs atomic reference counting.)
    """
    T = ut.shape[0]
    C = synthesis.shape[1]
    n3 = 3 * C
    ds0 = ds[0]
    ds1 = ds[1]
    m00 = 1.0
    m01 = 0.0
    m10 = 0.0
    m11 = 1.0
    gw0 = 0.0
    gw1 = 0.0
    moved = False
    work = 0.0
    for t in range(T):
        u0 = ut[t, 0]
        u1 = ut[t, 1]
        sp0 = s0
        sp1 = s1
        n = normal[t]
        f0, f1, n_s0, n_s1, st = slider_step(u0, u1, s0, s1, kt, mu * n, n > 0.0)
        theta = seat[t] if st == SEPARATED else 0.0
        t1 = (t + 1) % T
        if theta != 0.0:
            # seated where the contact closes, u + theta (u_next - u) (see touchdown_seats)
            n_s0 += theta * (ut[t1, 0] - u0)
            n_s1 += theta * (ut[t1, 1] - u1)
        f_out[t, 0] = f0
        f_out[t, 1] = f1
        state_out[t] = st
        if st != STICK:
            moved = True
            work += f0 * (n_s0 - s0) + f1 * (n_s1 - s1)
        s0 = n_s0
        s1 = n_s1
        if st == SEPARATED:
            # no force; the slider follows the displacement, at the closing instant before a
            # touchdown: d s = E_theta (own block) + (u_next - u) d theta, d theta / d c_zeta =
            # E_theta * seat_rate, E_theta = (1 - theta) E_t + theta E_next
            for j in range(n3):
                df_out[t, 0, j] = 0.0
                df_out[t, 1, j] = 0.0
            r0 = (ut[t1, 0] - u0) * seat_rate[t]
            r1 = (ut[t1, 1] - u1) * seat_rate[t]
            for j in range(C):
                E = synthesis[t, j] + theta * (synthesis[t1, j] - synthesis[t, j])
                ds0[j] = E
                ds1[j] = 0.0
                ds0[C + j] = 0.0
                ds1[C + j] = E
                ds0[2 * C + j] = r0 * E
                ds1[2 * C + j] = r1 * E
            if track:
                m00 = 0.0
                m01 = 0.0
                m10 = 0.0
                m11 = 0.0
                transfer[t, 0] = 0.0
                transfer[t, 1] = 0.0
                transfer[t, 2] = 0.0
                transfer[t, 3] = 0.0
            continue
        if st == STICK:
            # d(trial)/dc with trial = k_T (u - s_previous); the slider stays
            for j in range(C):
                kE = kt * synthesis[t, j]
                df_out[t, 0, j] = -kt * ds0[j] + kE
                df_out[t, 1, j] = -kt * ds1[j]
                df_out[t, 0, C + j] = -kt * ds0[C + j]
                df_out[t, 1, C + j] = -kt * ds1[C + j] + kE
                df_out[t, 0, 2 * C + j] = -kt * ds0[2 * C + j]
                df_out[t, 1, 2 * C + j] = -kt * ds1[2 * C + j]
            if track:
                transfer[t, 0] = m00
                transfer[t, 1] = m01
                transfer[t, 2] = m10
                transfer[t, 3] = m11
            continue
        # slip: f = mu N e, e = trial/|trial|: df = e mu dN + mu N (I - e e^T) dtrial / |trial|
        radius = mu * n
        stretch = np.sqrt((u0 - sp0) ** 2 + (u1 - sp1) ** 2)
        e0 = (u0 - sp0) / stretch
        e1 = (u1 - sp1) / stretch
        g = radius / (kt * stretch)
        mdn = mu * dnormal[t]
        for j in range(C):
            E = synthesis[t, j]
            kE = kt * E
            # xi block
            d0 = -kt * ds0[j] + kE
            d1 = -kt * ds1[j]
            proj = e0 * d0 + e1 * d1
            h0 = g * (d0 - e0 * proj)
            h1 = g * (d1 - e1 * proj)
            df_out[t, 0, j] = h0
            df_out[t, 1, j] = h1
            ds0[j] = -h0 / kt + E
            ds1[j] = -h1 / kt
            # eta block
            jj = C + j
            d0 = -kt * ds0[jj]
            d1 = -kt * ds1[jj] + kE
            proj = e0 * d0 + e1 * d1
            h0 = g * (d0 - e0 * proj)
            h1 = g * (d1 - e1 * proj)
            df_out[t, 0, jj] = h0
            df_out[t, 1, jj] = h1
            ds0[jj] = -h0 / kt
            ds1[jj] = -h1 / kt + E
            # zeta block (through the normal load)
            jj = 2 * C + j
            d0 = -kt * ds0[jj]
            d1 = -kt * ds1[jj]
            proj = e0 * d0 + e1 * d1
            dr = mdn * E
            h0 = g * (d0 - e0 * proj) + e0 * dr
            h1 = g * (d1 - e1 * proj) + e1 * dr
            df_out[t, 0, jj] = h0
            df_out[t, 1, jj] = h1
            ds0[jj] = -h0 / kt
            ds1[jj] = -h1 / kt
        if track:
            # M <- g (I - e e^T) M
            a00 = g * e1 * e1
            a01 = -g * e0 * e1
            a11 = g * e0 * e0
            n00 = a00 * m00 + a01 * m10
            n01 = a00 * m01 + a01 * m11
            n10 = a01 * m00 + a11 * m10
            n11 = a01 * m01 + a11 * m11
            if abs(n00) + abs(n01) + abs(n10) + abs(n11) < 1e-200:
                n00 = 0.0       # negligible (and no subnormal arithmetic)
                n01 = 0.0
                n10 = 0.0
                n11 = 0.0
            # slip work f . (s_t - s_{t-1}): gradient wrt the start position,
            # df_t = -k_T M_t, d s_t = M_t, d s_{t-1} = M_{t-1}
            q0 = s0 - sp0
            q1 = s1 - sp1
            gw0 += -kt * (n00 * q0 + n10 * q1) + (n00 - m00) * f0 + (n10 - m10) * f1
            gw1 += -kt * (n01 * q0 + n11 * q1) + (n01 - m01) * f0 + (n11 - m11) * f1
            m00 = n00
            m01 = n01
            m10 = n10
            m11 = n11
            transfer[t, 0] = m00
            transfer[t, 1] = m01
            transfer[t, 2] = m10
            transfer[t, 3] = m11
    return s0, s1, moved, work, gw0, gw1


@njit(cache=True)
def _initial_derivative(ds, C, static_index):
    """The slider derivative at the first pass: zero, or seated at the mean (d s / d c_mean = I)."""
    ds[:, :] = 0.0
    if static_index >= 0:
        ds[0, static_index] = 1.0
        ds[1, C + static_index] = 1.0


@njit(cache=True)
def _slip_scale(normal, kt, mu):
    """mu max N / k_T: the slider position scale of the periodicity test."""
    nmax = 0.0
    for t in range(normal.shape[0]):
        if normal[t] > nmax:
            nmax = normal[t]
    return mu * nmax / kt + 1e-300


@njit(cache=True)
def _iterate_passes(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, static_index, max_passes, tol,
                    want_jac, f_out, df_out, state_out, ds, ds_begin):
    """Repeat the period until the slider position repeats (and, with the Jacobian, its
    derivative too: ``abs(ds - ds_begin) <= tol``), at most ``max_passes`` times.
    Returns (slip work, passes)."""
    C = synthesis.shape[1]
    n3 = 3 * C
    _initial_derivative(ds, C, static_index)
    scale = _slip_scale(normal, kt, mu)
    work = 0.0
    passes = 0
    for it in range(max_passes):
        b0 = s0
        b1 = s1
        passes += 1
        if want_jac:
            for j in range(n3):
                ds_begin[0, j] = ds[0, j]
                ds_begin[1, j] = ds[1, j]
            # (no transfer tracking: ds_begin only stands in for the unused transfer array)
            s0, s1, moved, work, _, _ = _derivative_pass(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, f_out,
                                                         df_out, state_out, ds, ds_begin, np.bool_(False))
        else:
            s0, s1, moved, work = _slider_pass(ut, normal, seat, kt, mu, s0, s1, f_out, state_out)
        if not moved:
            break  # no slip, no separation: this period is already periodic
        if it >= 1 and abs(s0 - b0) <= tol * scale and abs(s1 - b1) <= tol * scale:
            # periodic slider; with the Jacobian its derivative must have settled too
            # (in near-1D slip the cross-direction derivative needs many more passes)
            if not want_jac:
                break
            settled = True
            for j in range(n3):
                if not (abs(ds[0, j] - ds_begin[0, j]) <= tol and abs(ds[1, j] - ds_begin[1, j]) <= tol):
                    settled = False
                    break
            if settled:
                break
    return work, passes


@njit(cache=True)
def _point_return_map(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, static_index, max_passes, tol,
                      want_jac, f_out, df_out, state_out, ds, ds_begin, transfer, closed_form, stuck_rows):
    """Periodic return map of one point (see :func:`return_map`).

    ut (T,2); normal, dnormal (T,); s0, s1 the initial slider position; outputs f_out (T,>=2),
    df_out (T,>=2,3C) (rows 0, 1 written; untouched without the Jacobian), state_out (T,);
    ds, ds_begin: (2,3C) and transfer: (T,4) work arrays. Returns (slip work, passes without
    the derivative, passes with it). ``stuck_rows`` False: when the last pass neither slips nor
    separates, df_out is left unwritten (its rows would all be -k_T ds + k_T E_t, ds the constant
    slider derivative left in ``ds``: :func:`point_harmonics` forms their AFT from ds).

    Slider: the period is repeated until the slider position at its end repeats (to ``tol``
    of mu max N / k_T, at least two passes) or a pass neither slips nor separates, at most
    ``max_passes`` times; forces, states and work are those of the last pass.

    Jacobian: the slider derivative ds = d s / d c (2, 3C) is carried through the samples,
    column by column (blocks xi | eta | zeta of C columns each); E = synthesis[t]:
    trial derivative dtr = -k_T ds + k_T E (xi row: xi block, eta row: eta block); stick:
    df = dtr; slip: df = g (I - e e^T) dtr + e mu dN/du_zeta E (zeta block), ds = -df / k_T
    + E (own block), g = mu N / |trial|; separated: df = 0, ds = E (own block). So per sample
    ds_new = A_t ds + (terms independent of ds), A_t = I (stick), g (I - e e^T) (slip), 0
    (separated), and over a period ds_end = Phi ds_begin + psi, Phi = A_{T-1} ... A_0 (2x2,
    the same for all 3C columns; rank 1 if anything slips or separates).

    ``closed_form`` False (the previous method): the passes carry the derivative, from 0 (or,
    with a static harmonic, d s / d c_mean = I: the slider seated at the mean), and repeat
    until the derivative repeats to ``tol`` too; in near-1D slip (an eigenvalue of Phi near
    1) that may take many more passes than the position, or never end within max_passes.

    ``closed_form`` True (the callers' default): the passes carry no derivative. When the
    position repeated, one more pass carries it from ds_begin = 0 with the transfers
    M_t = A_t ... A_0 (Phi = M_{T-1}, psi = ds_end), and the periodic derivative, the fixed
    point (and the infinitely-many-pass limit) of the iteration above, is
    ds* = (I - Phi)^{-1} psi; df_t(ds*) = df_t(0) - k_T M_t ds*. Phi is also the derivative
    of the end position with respect to the start position, so the same 2x2 solve gives the
    Newton step dp = (I - Phi)^{-1} (s_end - s_begin) to the periodic start; the forces
    (f_t - k_T M_t dp) and the slip work are corrected to first order, leaving them periodic
    to second order in the ~tol-sized step (states unchanged; skipped if |dp| > NEWTON_STEP_MAX
    mu max N / k_T). The result does not depend on the initial slider or its derivative
    convention. Where that is not so, the previous method is used and its numbers are
    reproduced exactly:
    * a last pass without slip or separation (Phi = I: any stuck slider is periodic): the
      derivative is the initial one, or the one carried through the earlier passes;
    * the position did not repeat within max_passes (no periodic state to linearise about);
    * |det(I - Phi)| < SINGULAR_DET (a barely attracting periodic state; see there).
    """
    if not (want_jac and closed_form):
        work, passes = _iterate_passes(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, static_index, max_passes,
                                       tol, want_jac, f_out, df_out, state_out, ds, ds_begin)
        return work, (0 if want_jac else passes), (passes if want_jac else 0)
    T = ut.shape[0]
    C = synthesis.shape[1]
    n3 = 3 * C
    start0 = s0
    start1 = s1
    scale = _slip_scale(normal, kt, mu)
    moved = False
    periodic = False
    passes = 0
    work = 0.0
    for it in range(max_passes):
        b0 = s0
        b1 = s1
        passes += 1
        s0, s1, moved, work = _slider_pass(ut, normal, seat, kt, mu, s0, s1, f_out, state_out)
        if not moved:
            break
        if it >= 1 and abs(s0 - b0) <= tol * scale and abs(s1 - b1) <= tol * scale:
            periodic = True
            break
    if not moved:
        # no slip and no separation in the last pass: the slider stays, ds is constant over
        # the period (Phi = I, no closed form): the initial derivative if it never moved,
        # else the derivative carried through the passes before, as _iterate_passes does
        # (it stops there too: no earlier pass repeated the position)
        _initial_derivative(ds, C, static_index)
        if passes > 1:
            s0 = start0
            s1 = start1
            for it in range(passes - 1):
                s0, s1, moved, work, _, _ = _derivative_pass(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, f_out,
                                                             df_out, state_out, ds, transfer, np.bool_(False))
            s0, s1, moved, work = _slider_pass(ut, normal, seat, kt, mu, s0, s1, f_out, state_out)
        if not stuck_rows:
            return work, passes + (1 if passes > 1 else 0), passes - 1
        ds0 = ds[0]
        ds1 = ds[1]
        for t in range(T):
            for j in range(C):
                kE = kt * synthesis[t, j]
                df_out[t, 0, j] = -kt * ds0[j] + kE
                df_out[t, 1, j] = -kt * ds1[j]
                df_out[t, 0, C + j] = -kt * ds0[C + j]
                df_out[t, 1, C + j] = -kt * ds1[C + j] + kE
                df_out[t, 0, 2 * C + j] = -kt * ds0[2 * C + j]
                df_out[t, 1, 2 * C + j] = -kt * ds1[2 * C + j]
        return work, passes + (1 if passes > 1 else 0), passes - 1
    if not periodic:
        # the slider position did not repeat within max_passes: no periodic state to
        # linearise about; the derivative of the passes made, as before
        work, jp = _iterate_passes(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, start0, start1, static_index,
                                   max_passes, tol, np.bool_(True), f_out, df_out, state_out, ds, ds_begin)
        return work, passes, jp
    # one more pass, with the derivative from ds_begin = 0 and the transfers M_t
    ds[:, :] = 0.0
    b0 = s0
    b1 = s1
    s0, s1, moved, work, gw0, gw1 = _derivative_pass(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, b0, b1, f_out,
                                                     df_out, state_out, ds, transfer, np.bool_(True))
    a = 1.0 - transfer[T - 1, 0]           # I - Phi = [[a, b], [c, d]]
    b = -transfer[T - 1, 1]
    c = -transfer[T - 1, 2]
    d = 1.0 - transfer[T - 1, 3]
    det = a * d - b * c
    if abs(det) < SINGULAR_DET:
        work, jp = _iterate_passes(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, start0, start1, static_index,
                                   max_passes, tol, np.bool_(True), f_out, df_out, state_out, ds, ds_begin)
        return work, passes, 1 + jp
    ia = a / det                           # (I - Phi)^{-1} = [[id_, -ib], [-ic, ia]]
    ib = b / det
    ic = c / det
    id_ = d / det
    # ds* = (I - Phi)^{-1} psi (psi = ds now), column by column
    for j in range(n3):
        p0 = ds[0, j]
        p1 = ds[1, j]
        ds[0, j] = id_ * p0 - ib * p1
        ds[1, j] = -ic * p0 + ia * p1
    # the same Newton step for the slider position: the periodic start is b + dp
    r0 = s0 - b0
    r1 = s1 - b1
    dp0 = id_ * r0 - ib * r1
    dp1 = -ic * r0 + ia * r1
    shift = abs(dp0) <= NEWTON_STEP_MAX * scale and abs(dp1) <= NEWTON_STEP_MAX * scale
    if shift:
        work += gw0 * dp0 + gw1 * dp1
    # df_t(ds*) = df_t(0) - k_T M_t ds*, f_t(b + dp) = f_t(b) - k_T M_t dp
    for t in range(T):
        m00 = transfer[t, 0]
        m01 = transfer[t, 1]
        m10 = transfer[t, 2]
        m11 = transfer[t, 3]
        if m00 == 0.0 and m01 == 0.0 and m10 == 0.0 and m11 == 0.0:
            continue
        for j in range(n3):
            x0 = ds[0, j]
            x1 = ds[1, j]
            df_out[t, 0, j] -= kt * (m00 * x0 + m01 * x1)
            df_out[t, 1, j] -= kt * (m10 * x0 + m11 * x1)
        if shift:
            f_out[t, 0] -= kt * (m00 * dp0 + m01 * dp1)
            f_out[t, 1] -= kt * (m10 * dp0 + m11 * dp1)
    return work, passes, 1


@njit(cache=True)
def return_map(ut, normal, dnormal, seat, seat_rate, synthesis, k_t, mu, s_start, static_index,
               max_passes, tol, want_jac, f_out, df_out, state_out, slip_work, passes, closed_form):
    """Tangential forces of P points over T samples (see module docstring).

    ut (P,T,2) tangential displacement samples; normal (P,T) normal load N >= 0;
    dnormal (P,T) dN/du_zeta; seat, seat_rate (P,T) (see :func:`touchdown_seats`); synthesis (T,C); k_t, mu (P,); s_start (P,2) initial slider;
    static_index: coefficient index of the mean (slider seated at the mean) or -1;
    closed_form: periodic slider derivative in closed form (see :func:`_point_return_map`).
    Outputs: f_out (P,T,2), df_out (P,T,2,3C) (d force / d point coefficients, blocks
    xi|eta|zeta), state_out (P,T), slip_work (P,) = sum f . ds over the last period,
    passes (P,2) int: passes without and with the derivative.
    """
    P, T = ut.shape[0], ut.shape[1]
    n3 = 3 * synthesis.shape[1]
    ds = np.zeros((2, n3))
    ds_begin = np.zeros((2, n3))
    transfer = np.zeros((T, 4))
    for p in range(P):
        dfp = df_out[p] if want_jac else df_out[0]
        w, n_plain, n_jac = _point_return_map(ut[p], normal[p], dnormal[p], seat[p], seat_rate[p], synthesis,
                                              k_t[p], mu[p],
                                              s_start[p, 0], s_start[p, 1], static_index, max_passes, tol,
                                              want_jac, f_out[p], dfp, state_out[p], ds, ds_begin, transfer,
                                              closed_form, np.bool_(True))
        slip_work[p] = w
        passes[p, 0] = n_plain
        passes[p, 1] = n_jac


@njit(cache=True)
def point_work(synthesis, analysis):
    """Work arrays of :func:`point_harmonics` for the synthesis (T, C) and analysis (C, T) of a
    basis (allocated once per kernel call, reused for every point), and the basis's column sums
    of the analysis, sum_t analysis[a, t] (C,), and its Gram matrix
    sum_t analysis[a, t] synthesis[t, b] (C, C) (the Jacobian of a point stuck all period)."""
    T, C = synthesis.shape[0], synthesis.shape[1]
    n3 = 3 * C
    n3p = (n3 + 3) // 4 * 4          # padded to whole SIMD vectors
    df = np.zeros((T, 2, n3p))       # d f_tangential / d c of the last pass; padding stays 0
    analysis_sums = np.zeros(C)
    gram = np.zeros((C, C))
    for a in range(C):
        for t in range(T):
            analysis_sums[a] += analysis[a, t]
            for b in range(C):
                gram[a, b] += analysis[a, t] * synthesis[t, b]
    return (np.empty((T, 2)), np.empty(T), np.empty(T), np.empty(T), np.empty((1, T)), np.empty((1, T)),
            np.empty((1, T)), np.empty((T, 2)), df, df.reshape((T, 2 * n3p)), np.empty(T, dtype=np.int8),
            np.zeros((2, n3)), np.zeros((2, n3)), np.zeros((T, 4)), analysis_sums, gram)


@njit(cache=True)
def point_harmonics(c, synthesis, analysis, kt, mu, w, off, law_kind, law_params, static_index, max_passes, tol,
                    want_jac, closed_form, work, fc, jt, jn):
    """AFT of one point contact from its harmonic coefficients: the per-point step of the fused
    kernels (:func:`damper_contact_forces`, :func:`point_contact_harmonics`).

    c (C, 3): coefficients of the relative displacement (xi, eta, zeta) [m]; synthesis (T, C),
    analysis (C, T); kt [N/m], mu [-], w (weight [-]), off (approach offset [m]) of the point;
    ``law_kind`` / ``law_params``: see :func:`normal_law_parameters`; the slider seated at the
    mean if ``static_index`` >= 0, the periodic slider of :func:`_point_return_map`; ``work``:
    :func:`point_work` (T, C). Writes fc (C, 3): the force coefficients on the platform
    (tangential, then the normal force -N) [N]; with ``want_jac`` also
    jt (C, 2 n3p), jt[a, i n3p + k C + b] = d fc[a, i] / d c[b, k] for the tangential rows
    i = 0, 1 (n3p: 3C rounded up to a multiple of 4, ``work[8].shape[2]``), and
    jn (C, C) = d fc[a, 2] / d c[b, 2] [N/m], the normal row (its xi and eta columns are zero).
    """
    (ut, uz, normal, dnormal, approach, seats, seat_rates, f_t, df, df_flat, state, ds, ds_begin, transfer,
     analysis_sums, gram) = work
    T, C = synthesis.shape[0], synthesis.shape[1]
    n3p = df.shape[2]
    seat = seats[0]
    seat_rate = seat_rates[0]
    for t in range(T):
        x0 = 0.0
        x1 = 0.0
        x2 = 0.0
        for a in range(C):
            sa = synthesis[t, a]
            x0 += sa * c[a, 0]
            x1 += sa * c[a, 1]
            x2 += sa * c[a, 2]
        ut[t, 0] = x0
        ut[t, 1] = x1
        uz[t] = x2
    # normal law N(a) (contact.normal), approach a = offset - u_zeta; this kernel's convention:
    # dnormal = dN/du_zeta = -dN/da
    p0 = law_params[0]
    p1 = law_params[1]
    p2 = law_params[2]
    for t in range(T):
        app = off - uz[t]
        approach[0, t] = app
        n_t, dn_da = normal_force(law_kind, p0, p1, p2, w, app)
        normal[t] = n_t
        dnormal[t] = 0.0 - dn_da         # (+0.0 at lift-off, not -0.0)
    touchdown_seats(approach, seats, seat_rates)
    if static_index >= 0:
        s0 = c[static_index, 0]
        s1 = c[static_index, 1]
    else:
        s0 = 0.0
        s1 = 0.0
    _point_return_map(ut, normal, dnormal, seat, seat_rate, synthesis, kt, mu, s0, s1, static_index,
                      max_passes, tol, want_jac, f_t, df, state, ds, ds_begin, transfer, closed_form, np.bool_(False))
    # force coefficients of the point (normal force -N)
    for a in range(C):
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for t in range(T):
            an = analysis[a, t]
            a0 += an * f_t[t, 0]
            a1 += an * f_t[t, 1]
            a2 -= an * normal[t]
        fc[a, 0] = a0
        fc[a, 1] = a1
        fc[a, 2] = a2
    if not want_jac:
        return
    _point_jacobian(synthesis, analysis, kt, dnormal, state, df_flat, ds, analysis_sums, gram, jt, jn)


@njit(cache=True)
def _point_jacobian(synthesis, analysis, kt, dnormal, state, df_flat, ds, analysis_sums, gram, jt, jn):
    """The AFT of a point's Jacobian (the last step of :func:`point_harmonics`; jt, jn, kt,
    synthesis, analysis as there): from the return map's states (T,), dN/du_zeta (T,) [N/m],
    df_flat (T, 2 n3p) (d f_tangential / d c per sample) or, for a point stuck all the last
    pass, its constant slider derivative ds (2, 3C) and the basis's analysis_sums (C,) and
    gram (C, C) (:func:`point_work`)."""
    T, C = synthesis.shape[0], synthesis.shape[1]
    n3p = df_flat.shape[1] // 2
    # jt[a, i n3p + k C + b] = sum_t analysis[a, t] df[t, i, k C + b] (tangential rows i);
    # jn[a, b] = sum_t analysis[a, t] dN/da E[t, b] (normal row, zeta columns only);
    # separated samples carry no force and no derivative
    jn[:, :] = 0.0
    for t in range(T):
        if state[t] == SEPARATED:
            continue
        dnda = -dnormal[t]
        for a in range(C):
            an = analysis[a, t]
            for b in range(C):
                jn[a, b] += an * (dnda * synthesis[t, b])
    stuck = True
    for t in range(T):
        if state[t] != STICK:
            stuck = False
            break
    if stuck:
        # stuck all the last pass: the slider derivative ds (2, 3C) stays what it was at the
        # pass start, df_t = -k_T ds + k_T E_t (own blocks) at every sample (as the return map
        # writes it), so jt = -k_T (sum_t analysis) ds + k_T gram (own blocks), with the basis's
        # sums (point_work) instead of T samples' (the same to rounding)
        for a in range(C):
            sa = -kt * analysis_sums[a]
            for i in range(2):
                for j in range(n3p):
                    jt[a, i * n3p + j] = sa * ds[i, j] if j < 3 * C else 0.0
            for b in range(C):
                g = kt * gram[a, b]
                jt[a, b] += g                   # xi row, xi block
                jt[a, n3p + C + b] += g         # eta row, eta block
        return
    jt[:, :] = 0.0
    for t in range(T):
        if state[t] == SEPARATED:
            continue
        for a in range(C):
            an = analysis[a, t]
            # (indexed, not row views: a view per sample costs reference counting)
            for r in range(2 * n3p):
                jt[a, r] += an * df_flat[t, r]


@njit(cache=True, inline="always")
def add_point_block(Bp, jt, jn, bj, acc):
    """acc[a, m, b, n] += sum_ik Bp[i, m] jp[a, i, k, b] Bp[k, n]: one point's Jacobian block
    projected with its rigid map Bp (3, 6) onto a patch's six local coordinates (C, 6, C, 6), jp
    the point block d f_coef[a, i] / d c[b, k] as :func:`point_harmonics` writes it (jt the
    tangential rows, jn the normal row, whose only column is zeta); bj (C, 6, 3, C) work array.
    (The six is a constant: the compiler unrolls the loops over it; inlined into both kernels,
    the arithmetic of the loops it replaced in damper_contact_forces, at their speed.)"""
    C = acc.shape[0]
    n3p = jt.shape[1] // 2
    for a in range(C):
        for m in range(6):
            B0 = Bp[0, m]
            B1 = Bp[1, m]
            B2 = Bp[2, m]
            for k in range(3):
                for b in range(C):
                    v = B0 * jt[a, k * C + b] + B1 * jt[a, n3p + k * C + b]
                    if k == 2:
                        v += B2 * jn[a, b]
                    bj[a, m, k, b] = v
    for a in range(C):
        for m in range(6):
            for b in range(C):
                v0 = bj[a, m, 0, b]
                v1 = bj[a, m, 1, b]
                v2 = bj[a, m, 2, b]
                for n in range(6):
                    acc[a, m, b, n] += v0 * Bp[0, n] + v1 * Bp[1, n] + v2 * Bp[2, n]


@njit(cache=True)
def damper_contact_forces(B, local, synthesis, analysis, k_t, mu, weight, approach_offset, law_kind,
                          law_params, static_index, max_passes, tol, want_jac, force, blocks, closed_form):
    """Fused AFT of the two contact patches of n_d dampers (the batched path of AssemblyContacts).

    Per point (d, q, p): coefficients c = B[d, q, p] @ local[:, d, 6q:6q+6], then
    :func:`point_harmonics` (samples, normal law with lift-off, periodic slider, AFT), the force
    coefficients projected back with B^T, and the Jacobian B^T (analysis @ df/dc) B: the same
    numbers as :func:`point_contact_forces` followed by those projections, without the
    (n_points, T, 3, 3C) intermediates.

    B (n_d,2,P,3,6); local (C,n_d,12); synthesis (T,C); analysis (C,T); k_t, mu, weight,
    approach_offset (n_d*2*P,) in (d, q, p) order; law_params float (3,). Outputs
    (overwritten): force (C,n_d,12); blocks (n_d,C,12,C,12) if ``want_jac`` (patch q of
    damper d fills [d, :, 6q:6q+6, :, 6q:6q+6], the rest is zero), any array otherwise.
    ``closed_form``: the periodic slider derivative in closed form (True, what the model
    passes; False: the previous pass iteration, see :func:`_point_return_map`). No default: an
    omitted argument is a numba literal, and the kernels it reaches (``point_harmonics``,
    ``_point_return_map`` and what they inline) were compiled a second time for it, besides the
    version ``point_contact_forces`` uses.
    """
    nd, P = B.shape[0], B.shape[2]
    T, C = synthesis.shape[0], synthesis.shape[1]
    work = point_work(synthesis, analysis)
    n3p = work[8].shape[2]
    c = np.empty((C, 3))
    fc = np.empty((C, 3))
    jt = np.empty((C, 2 * n3p))
    jn = np.empty((C, C))
    bj = np.empty((C, 6, 3, C))      # sum_i B[i, m] jp[a, i, k, b]
    acc = np.empty((C, 6, C, 6))     # one patch's block
    force[:, :, :] = 0.0
    if want_jac:
        blocks[:, :, :, :, :] = 0.0
    for d in range(nd):
        for q in range(2):
            col = 6 * q
            if want_jac:
                acc[:, :, :, :] = 0.0
            for p in range(P):
                g = (d * 2 + q) * P + p
                Bp = B[d, q, p]
                # point coefficients
                for a in range(C):
                    for i in range(3):
                        s = 0.0
                        for j in range(6):
                            s += Bp[i, j] * local[a, d, col + j]
                        c[a, i] = s
                point_harmonics(c, synthesis, analysis, k_t[g], mu[g], weight[g], approach_offset[g], law_kind,
                                law_params, static_index, max_passes, tol, want_jac, closed_form, work, fc, jt, jn)
                # force coefficients of the point projected with B^T
                for a in range(C):
                    a0 = fc[a, 0]
                    a1 = fc[a, 1]
                    a2 = fc[a, 2]
                    for j in range(6):
                        force[a, d, col + j] += a0 * Bp[0, j] + a1 * Bp[1, j] + a2 * Bp[2, j]
                if not want_jac:
                    continue
                add_point_block(Bp, jt, jn, bj, acc)
            if want_jac:
                for a in range(C):
                    for m in range(6):
                        for b in range(C):
                            for n in range(6):
                                blocks[d, a, col + m, b, col + n] = acc[a, m, b, n]


#: the contact directions of :func:`damper_parameter_forces`, in the order of its output's first axis
#: (then the forces themselves, then the maps' and the local directions' products)
PARAMETER_DIRECTIONS = ("tangential", "law", "friction", "approach", "approach_left", "approach_right")


@njit(cache=True)
def damper_parameter_forces(B, local, d_maps, moves, synthesis, analysis, k_t, mu, weight, approach_offset, law_kind,
                            law_params, degree, static_index, max_passes, tol, out, want_jac, blocks, closed_form):
    """Directional derivatives of the contact forces of the two patches of n_d dampers in the
    contact parameters (what :meth:`bladedamp.diskmodel.AssemblyContacts.parameter_forces`
    returns, its equations there), fused: per point (d, q, p) the coefficients
    c = B[d, q, p] @ local[:, d, q m:(q+1) m], :func:`point_harmonics` with the point's Jacobian
    (jt, jn: d force coefficients / d c), its products with c (J_t c_t from the xi and eta
    columns, J_z c_z from the zeta column) formed on the coefficients, the six directions
    (:data:`PARAMETER_DIRECTIONS`), the forces F, each map derivative's dB^T f + B^T J (dB c)
    and each local direction's B^T J (B v) (the Jacobian times v) projected with B^T, in one
    numba call: no point samples, no Jacobian blocks B^T J B.

    B (n_d, 2, P, 3, m) the point maps; local (C, n_d, 2 m) [m]; d_maps (n_maps, n_d, 2, P, 3, m)
    derivatives of the maps; moves (n_v, C, n_d, 2 m) directions v of the local coordinates
    (n_maps, n_v may be 0); synthesis (T, C), analysis (C, T); k_t, mu,
    weight, approach_offset (n_d 2 P,) in (d, q, p) order [N/m, -, -, m]; law_kind / law_params
    (:func:`normal_law_parameters`); ``degree`` the normal law's exponent p (1 for the linear
    law); static_index, max_passes, tol, closed_form as :func:`damper_contact_forces`.
    Output (overwritten): out (7 + n_maps + n_v, C, n_d, 2 m) [N, N m]: the logarithmic
    derivatives p dF/dp in the six directions, F, dF/dp of each map derivative, then J v of each
    direction v [N per unit of v]; with ``want_jac`` (rigid platforms, m = 6, else ValueError)
    also blocks (n_d, C, 12, C, 12), the Jacobian blocks of :func:`damper_contact_forces` (the
    same numbers: that kernel's projection, with its force in out[6]), else any array untouched:
    the Newton's Jacobian and the directions from one pass. The same numbers as the
    sampled computation (analysis of the samples' products) to rounding: the analysis is linear.
    """
    nd, P, m = B.shape[0], B.shape[2], B.shape[4]
    n_maps, n_v = d_maps.shape[0], moves.shape[0]
    first = 7 + n_maps              # the first row of the moves' products
    C = synthesis.shape[1]
    work = point_work(synthesis, analysis)
    n3p = work[8].shape[2]
    c = np.empty((C, 3))
    dc = np.empty((C, 3))
    fc = np.empty((C, 3))
    jt = np.empty((C, 2 * n3p))
    jn = np.empty((C, C))
    v = np.empty((first + n_v, C, 3))   # the point's directions (force coefficients, contact frame)
    if want_jac and m != 6:
        raise ValueError("the Jacobian blocks are formed for rigid platforms (point maps (3, 6)) only")
    bj = np.empty((C, 6, 3, C))
    acc = np.empty((C, 6, C, 6))        # one patch's Jacobian block
    out[:, :, :, :] = 0.0
    if want_jac:
        blocks[:, :, :, :, :] = 0.0
    for d in range(nd):
        for q in range(2):
            col = m * q
            if want_jac:
                acc[:, :, :, :] = 0.0
            for p in range(P):
                g = (d * 2 + q) * P + p
                Bp = B[d, q, p]
                for a in range(C):
                    for i in range(3):
                        s = 0.0
                        for j in range(m):
                            s += Bp[i, j] * local[a, d, col + j]
                        c[a, i] = s
                point_harmonics(c, synthesis, analysis, k_t[g], mu[g], weight[g], approach_offset[g], law_kind,
                                law_params, static_index, max_passes, tol, True, closed_form, work, fc, jt, jn)
                for a in range(C):
                    for i in range(2):
                        tangential = 0.0
                        normal = 0.0
                        row = i * n3p
                        for b in range(C):
                            tangential += jt[a, row + b] * c[b, 0] + jt[a, row + C + b] * c[b, 1]
                            normal += jt[a, row + 2 * C + b] * c[b, 2]
                        scale = fc[a, i] - tangential
                        v[0, a, i] = tangential                         # J_t c_t
                        v[1, a, i] = scale                              # F - J_t c_t
                        v[2, a, i] = scale                              # its tangential rows
                        v[3, a, i] = degree * scale - normal            # p (F - J_t c_t) - J_z c_z
                    normal = 0.0
                    for b in range(C):
                        normal += jn[a, b] * c[b, 2]
                    v[0, a, 2] = 0.0                                    # N does not depend on u_t
                    v[1, a, 2] = fc[a, 2]
                    v[2, a, 2] = 0.0
                    v[3, a, 2] = degree * fc[a, 2] - normal
                    for i in range(3):
                        v[4, a, i] = v[3, a, i] if q == 0 else 0.0
                        v[5, a, i] = v[3, a, i] if q == 1 else 0.0
                        v[6, a, i] = fc[a, i]
                for k in range(n_maps + n_v):
                    # the point's motion: dB c for a map, B v for a local direction
                    for a in range(C):
                        for i in range(3):
                            s = 0.0
                            if k < n_maps:
                                for j in range(m):
                                    s += d_maps[k, d, q, p, i, j] * local[a, d, col + j]
                            else:
                                for j in range(m):
                                    s += Bp[i, j] * moves[k - n_maps, a, d, col + j]
                            dc[a, i] = s
                    for a in range(C):
                        for i in range(2):
                            s = 0.0
                            row = i * n3p
                            for kk in range(3):
                                for b in range(C):
                                    s += jt[a, row + kk * C + b] * dc[b, kk]
                            v[7 + k, a, i] = s
                        s = 0.0
                        for b in range(C):
                            s += jn[a, b] * dc[b, 2]
                        v[7 + k, a, 2] = s
                # B^T of every direction, and dB^T f of the maps'
                for r in range(first + n_v):
                    for a in range(C):
                        a0 = v[r, a, 0]
                        a1 = v[r, a, 1]
                        a2 = v[r, a, 2]
                        for j in range(m):
                            out[r, a, d, col + j] += a0 * Bp[0, j] + a1 * Bp[1, j] + a2 * Bp[2, j]
                for k in range(n_maps):
                    dB = d_maps[k, d, q, p]
                    for a in range(C):
                        for j in range(m):
                            out[7 + k, a, d, col + j] += fc[a, 0] * dB[0, j] + fc[a, 1] * dB[1, j] + fc[a, 2] * dB[2, j]
                if want_jac:
                    add_point_block(Bp, jt, jn, bj, acc)
            if want_jac:
                for a in range(C):
                    for r in range(6):
                        for b in range(C):
                            for n in range(6):
                                blocks[d, a, col + r, b, col + n] = acc[a, r, b, n]


@njit(cache=True)
def point_contact_harmonics(local, synthesis, analysis, k_t, mu, weight, approach_offset, law_kind, law_params,
                            static_index, max_passes, tol, want_jac, closed_form, force, jac):
    """Fused AFT of P independent point contacts (the path of :class:`PointContactElement`).

    Per point p: :func:`point_harmonics` of its coefficients local[:, p, :] (samples, normal law
    with lift-off, periodic slider, AFT and the point's Jacobian block): the same numbers as
    :func:`point_contact_forces` followed by the analysis of its samples and Jacobian, to
    rounding, without the (P, T, 3, 3C) intermediates.

    local (C, P, 3) coefficients of the relative displacements [m]; synthesis (T, C), analysis
    (C, T); k_t, mu, weight, approach_offset (P,) [N/m, -, -, m]; law_kind / law_params (3,)
    see :func:`normal_law_parameters`; static_index: the mean's coefficient (slider seated at
    the mean) or -1. Outputs (overwritten): force (C, P, 3) [N]; jac (C, P, 3, C, P, 3)
    [N/m], d force / d local, block diagonal over the points, if ``want_jac`` (any array
    otherwise).
    """
    P = local.shape[1]
    T, C = synthesis.shape[0], synthesis.shape[1]
    work = point_work(synthesis, analysis)
    n3p = work[8].shape[2]
    c = np.empty((C, 3))
    fc = np.empty((C, 3))
    jt = np.empty((C, 2 * n3p))
    jn = np.empty((C, C))
    if want_jac:
        jac[:, :, :, :, :, :] = 0.0
    for p in range(P):
        for a in range(C):
            for i in range(3):
                c[a, i] = local[a, p, i]
        point_harmonics(c, synthesis, analysis, k_t[p], mu[p], weight[p], approach_offset[p], law_kind, law_params,
                        static_index, max_passes, tol, want_jac, closed_form, work, fc, jt, jn)
        for a in range(C):
            for i in range(3):
                force[a, p, i] = fc[a, i]
        if not want_jac:
            continue
        for a in range(C):
            for i in range(2):
                for k in range(3):
                    for b in range(C):
                        jac[a, p, i, b, p, k] = jt[a, i * n3p + k * C + b]
            for b in range(C):
                jac[a, p, 2, b, p, 2] = jn[a, b]


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
                         weight, approach_offset, jacobian=True, max_passes=MAX_PASSES, tol=PERIODIC_TOL,
                         closed_form=True):
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
    max_passes, tol : at most that many periods are repeated until the slider position at the
        period end repeats to ``tol`` of mu max N / k_T
    closed_form : the periodic slider derivative in closed form (default); False iterates the
        passes until the derivative repeats to ``tol`` as well (the previous method; with
        many passes, the reference of the closed form)
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
    seat, seat_rate = np.empty((P, T)), np.empty((P, T))
    touchdown_seats(np.ascontiguousarray(approach), seat, seat_rate)
    f_t = np.empty((P, T, 2))
    df = np.zeros((P, T, 3, 3 * C)) if jacobian else np.zeros((1, 1, 2, 1))
    state = np.empty((P, T), dtype=np.int8)
    slip_work = np.zeros(P)
    passes = np.zeros((P, 2), dtype=np.int64)
    return_map(np.ascontiguousarray(disp[:, :, :2]), np.ascontiguousarray(normal),
                np.ascontiguousarray(dnormal), seat, seat_rate, basis.synthesis, k_t, mu, s_start, static_index,
                max_passes, tol, jacobian, f_t, df, state, slip_work, passes, closed_form)
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
        from .. import validation
        self.tangential_stiffness = np.atleast_1d(validation.positive("tangential stiffness k_T", self.tangential_stiffness))
        P = self.tangential_stiffness.size
        self.friction_coefficient = np.broadcast_to(np.atleast_1d(
            validation.nonnegative("friction coefficient mu", self.friction_coefficient)), (P,)).copy()
        self.weight = np.broadcast_to(np.atleast_1d(validation.positive("weight", self.weight)), (P,)).copy()
        self.approach_offset = np.broadcast_to(np.atleast_1d(
            validation.finite("approach_offset", self.approach_offset)), (P,)).copy()

    @property
    def n_points(self) -> int:
        return self.tangential_stiffness.size

    @property
    def memoryless(self) -> bool:
        """Whether the force depends on the present displacement only: frictionless (mu = 0 at
        every point), so only the normal law acts (see :mod:`bladedamp.hbm.stability`)."""
        return bool(np.all(self.friction_coefficient == 0))

    @property
    def n_local(self) -> int:
        return 3 * self.n_points

    def samples(self, local, basis, jacobian=False) -> PointContactSamples:
        C = basis.n_coeffs
        return point_contact_forces(np.asarray(local).reshape(C, self.n_points, 3), basis,
                                    self.tangential_stiffness, self.friction_coefficient, self.normal_law,
                                    self.weight, self.approach_offset, jacobian=jacobian)

    def harmonic_forces(self, local, basis, omega=None, jacobian=True):
        """Force coefficients (C, 3P) [N], Jacobian (C*3P, C*3P) [N/m] (block diagonal over
        points) or None, and None (no explicit omega dependence), of ``local`` (C, 3P) [m].

        For the normal laws the kernel evaluates itself (:func:`normal_law_parameters`) one call
        of the fused kernel :func:`point_contact_harmonics`; otherwise (a subclassed law) the
        samples of :meth:`samples` are analysed here. The two agree to rounding (tested).
        """
        C, P = basis.n_coeffs, self.n_points
        law = normal_law_parameters(self.normal_law)
        if law is None:
            return self.harmonic_forces_from_samples(local, basis, jacobian)
        force = np.empty((C, P, 3))
        jac = np.empty((C, P, 3, C, P, 3)) if jacobian else np.empty((1, 1, 1, 1, 1, 1))
        point_contact_harmonics(np.ascontiguousarray(np.reshape(local, (C, P, 3)), dtype=float), basis.synthesis,
                                basis.analysis, self.tangential_stiffness, self.friction_coefficient, self.weight,
                                self.approach_offset, law[0], law[1], basis.cos_index(0) if basis.has_static else -1,
                                MAX_PASSES, PERIODIC_TOL, jacobian, True, force, jac)
        return force.reshape(C, 3 * P), (jac.reshape(C * 3 * P, C * 3 * P) if jacobian else None), None

    def harmonic_forces_from_samples(self, local, basis, jacobian):
        """:meth:`harmonic_forces` by the analysis of :meth:`samples` (any normal law): force
        coefficients (C, 3P) [N], Jacobian (C*3P, C*3P) [N/m] or None (``jacobian`` False), and
        None, of ``local`` (C, 3P) [m]; the reference of the fused kernel."""
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
