"""Derivatives of harmonic balance solutions in parameters, by the implicit function theorem.

On a converged point R(x, Omega, p) = 0 of a branch, at fixed Omega,

    dx/dp = -J^-1 dR/dp,     J = dR/dx (the Newton's Jacobian, factorised once for all p),

so the derivative of the solution in every parameter costs one residual derivative dR/dp
(the model's, analytic: :meth:`bladedamp.diskmodel.DiskModel.parameter_derivatives`) and one
back-substitution each. An output u = w @ x (a first-harmonic complex amplitude,
:func:`~bladedamp.hbm.peaks.first_harmonic_output`) then has d|u|/dp = Re(conj(u) w @ dx/dp) / |u|.

A resonance peak, the local maximum of a(Omega, p) = |u| (:class:`~bladedamp.hbm.peaks.PeakSolver`),
moves with p. With friction sampled in time (AFT) the curve a(Omega) is smooth only piecewise: a
contact point changing state at a sample instant leaves a kink, and the maximum itself often
sits on one (the slope g = da/dOmega jumps from + to - there, without a zero). Both kinds of
peak are differentiated by one formula, from the analytic first derivatives at two converged
points Omega* -+ h either side of it: the slopes g-, g+ and the parameter derivatives s-, s+ of
a at fixed Omega. Each side is linear in (Omega, p) to first order, and the peak is where the
two sides meet:

    d Omega* / dp = (s+ - s-) / (g- - g+),      d a* / dp = s- + g- d Omega* / dp  (= s+ + g+ d Omega*/dp)

On a smooth peak (g- = a'' h, g+ = -a'' h to O(h^2)) this is d Omega*/dp = -(d^2 a/dOmega dp) /
(d^2 a / dOmega^2), the peak condition g = 0 differentiated, and d a*/dp = da/dp at Omega* (the
envelope theorem); on a kink it is the exact first-order motion of the kink, where a one-sided
envelope theorem would be wrong. h starts at :data:`PEAK_FIRST_SPACING` of Omega* (the peak
solver stops within about 1e-8 of it) and grows tenfold until g- > 0 > g+ brackets the maximum.
The error is O(h^2) on a smooth peak but O(h) on a kink (each side's pieces vary over h), so a
second pair at +- :data:`PEAK_KINK_SPACING` of the kink located by the first pair's tangent lines
(where they meet) is used where it brackets the maximum (on a smooth peak it does not, and the
first pair's second-order result stands). Several kinks can lie within 1e-11 of one another (a
patch's points switch together); the pairs straddle such a cluster.

Cost (benchmarks/bench_sensitivities.py, benchmarks/README.md): each point either side is a
Newton solve from the tangent predictor of the nearest point already solved on its piece of the
curve, and the solved peak is itself one side of a kink at the maximum, so the kink is first
located from the peak's own tangent line and the far side's alone (one side searched instead of
two); the symmetric pairs are solved only where that does not give a bracketing pair at the
kink. dR/dp at a side is taken where the Newton's last Jacobian was evaluated, from that same
evaluation where the model allows (:func:`reusing`). A kinked peak needs at least the Jacobians
at the peak (its slope, its tangent), at the far side and at the two points at the kink, each
point's Newton one more to converge from its predictor to 1e-12: 5-9 Jacobian evaluations.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np

from .newton import newton

#: the first half-spacing h of the two points either side of a peak, relative to Omega*
#: (:func:`peak_sensitivities`): above the peak solver's 1e-9, so that a kink at the maximum lies
#: between them, and small against the spacing of the AFT's kinks on the curve (1e-7 of Omega
#: and more on the reference disks) and against a smooth peak's width (O(h^2) error)
PEAK_FIRST_SPACING = 1e-8
#: the half-spacing, relative to Omega*, of the second pair of points, either side of the kink
#: located by the first (a kink's formula is first-order in h: 1e-10 of Omega* gives ~1e-6)
PEAK_KINK_SPACING = 1e-10
#: the largest half-spacing tried, relative to Omega*, before the maximum is given up as not bracketed
PEAK_LARGEST_SPACING = 1e-4


def reusing(dR_dp):
    """The context in which the system's Jacobian evaluations keep what ``dR_dp`` needs at the
    same point (its ``reusing()``, e.g. a disk model's :class:`~bladedamp.diskmodel.ParameterDerivatives`:
    the contact directions from the same kernel pass), or a null context."""
    return getattr(dR_dp, "reusing", contextlib.nullcontext)()


def state_sensitivities(system, x: np.ndarray, omega: float, dR_dp, solve=None) -> np.ndarray:
    """dx/dp (k, C*n_dof) at the converged point ``x`` (C*n_dof,) of ``system`` at ``omega``
    [rad/s] of the k parameters whose residual derivatives are ``dR_dp``: the rows (k, C*n_dof)
    [N per unit of each parameter], or the function ``dR_dp(x, omega)`` giving them (then
    evaluated after the Jacobian, within :func:`reusing`: a model's derivatives may take their
    contact terms from that evaluation). -J^-1 dR/dp with J = dR/dx factorised once (``solve``: a
    factorisation of J at ``x`` already at hand, e.g. the Newton's last, else one is made); one
    back-substitution per parameter (one of k columns at once is no faster with the BLAS held to
    one thread, and far slower with a threaded BLAS: benchmarks/README.md)."""
    with reusing(dR_dp) if callable(dR_dp) else contextlib.nullcontext():
        if solve is None:
            _, J, _ = system.residual(x, omega)
            solve = system.factorize(J)
        if callable(dR_dp):
            dR_dp = dR_dp(x, omega)
    dR_dp = np.asarray(dR_dp, dtype=float).reshape(-1, len(x))         # (k, C*n_dof), k = 0 allowed
    return -np.array([solve(r) for r in dR_dp]).reshape(dR_dp.shape)


def output_sensitivities(output: np.ndarray, x: np.ndarray, dx: np.ndarray) -> tuple[float, np.ndarray]:
    """(|u|, d|u|/dp (k,)) of the complex output u = ``output`` @ x with the state derivatives
    ``dx`` (k, C*n_dof). Where u = 0 (rest: a zero excitation) the modulus has no two-sided
    derivative; the one given is the one-sided one as p increases, |du/dp| (|u(p + h)| = h |du/dp|
    + O(h^2) for h > 0): the receptance times the unit force for an excitation key, 0 for a key
    that does not move rest."""
    u = complex(output @ x)
    du = np.atleast_2d(dx) @ output
    a = abs(u)
    return a, (np.real(np.conj(u) * du) / a if a > 0 else np.abs(du))


@dataclass
class PeakSensitivity:
    """The derivatives of one resonance peak in k parameters.

    amplitude : |u*| at the peak [the output's unit, m]
    omega : Omega* [rad/s]
    x : (C*n_dof,) the solution at the peak
    d_amplitude : (k,) d|u*|/dp [output unit per unit of p]
    d_omega : (k,) dOmega*/dp [rad/s per unit of p]
    slopes : (g-, g+) the slopes d|u|/dOmega either side [unit s/rad] (g- > 0 > g+)
    spacing : the half-spacing h [rad/s] of the points either side of the peak
    """

    amplitude: float
    omega: float
    x: np.ndarray
    d_amplitude: np.ndarray
    d_omega: np.ndarray
    slopes: tuple
    spacing: float


def peak_sensitivities(system, x: np.ndarray, omega: float, output: np.ndarray, dR_dp, x_scale,
                       residual_scale: float, tol: float = 1e-12) -> PeakSensitivity | None:
    """The derivatives of the peak of |u| = |``output`` @ x| at the solved peak (``x``, ``omega``
    [rad/s]) of ``system`` (:meth:`~bladedamp.hbm.peaks.PeakSolver.solve_state`) in k parameters
    (the equations: the module docstring). ``dR_dp(x, omega) -> (k, C*n_dof)`` gives the
    residual's parameter derivatives at a converged point; ``x_scale`` and ``residual_scale``
    scale the Newton solves of the points either side (tolerance ``tol``). Returns None where a
    solve either side does not converge or no spacing up to :data:`PEAK_LARGEST_SPACING` brackets
    a maximum (g- > 0 > g+).

    The points either side, in the order that needs the fewest solves (each a Newton solve from
    the tangent predictor of the nearest point already solved on the same piece of the curve):
    the peak's own point is one side of a kink at the maximum (its slope g* tells which), so
    the far side alone is searched first (spacings as below) and the kink located from the
    peak's and the far side's tangent lines; where the pair at +- :data:`PEAK_KINK_SPACING` of
    it brackets the maximum, that pair gives the derivatives (the near point on the peak's side
    predicted from the peak, the other from the far side). Otherwise (a smooth peak, a cluster
    of kinks the shortcut does not straddle) the symmetric pairs Omega* -+ h as described in
    the module docstring, reusing the points already solved."""
    with reusing(dR_dp):
        return _peak_sensitivities(system, x, omega, output, dR_dp, x_scale, residual_scale, tol)


def _peak_sensitivities(system, x, omega, output, dR_dp, x_scale, residual_scale, tol):
    """:func:`peak_sensitivities` (within :func:`reusing`)."""
    _, J, Rw = system.residual(x, omega)
    solve = system.factorize(J)
    tangent = -solve(Rw)
    a, (g,) = output_sensitivities(output, x, tangent[None])
    peak = [a, g, (x, solve, omega), tangent, x]
    solved = {}

    def side(w, start):
        """[|u|, slope g, (x, solve, w) for da/dp, dx/dOmega, x] at the converged point at ``w``
        [rad/s], predicted from ``start`` (a point as this returns), or None; da/dp is taken at
        the Newton's last iterate evaluated, where its factorisation ``solve`` was made."""
        if w in solved:
            return solved[w]
        _, _, (_, _, w0), t0, x0 = start
        r = newton(system.residual, x0 + t0 * (w - w0), w, x_scale, residual_scale, tol=tol,
                   factorize=system.factorize)
        out = None
        if r.converged:
            d = -r.solve(r.dR_domega)
            amplitude, (slope,) = output_sensitivities(output, r.x, d)
            out = [amplitude, slope, (r.evaluated, r.solve, w), d, r.x]
        solved[w] = out
        return out

    def derivatives(left, right, spacing):
        """The peak's derivatives from the two sides (their da/dp evaluated here, only for the pair used)."""
        (_, g_minus, (x_m, solve_m, w_m), *_), (_, g_plus, (x_p, solve_p, w_p), *_) = left, right
        s_minus = output_sensitivities(output, x_m, state_sensitivities(system, x_m, w_m, dR_dp, solve_m))[1]
        s_plus = output_sensitivities(output, x_p, state_sensitivities(system, x_p, w_p, dR_dp, solve_p))[1]
        d_omega = (s_plus - s_minus) / (g_minus - g_plus)
        d_amplitude = 0.5 * (s_minus + g_minus * d_omega + s_plus + g_plus * d_omega)
        return PeakSensitivity(a, omega, x, d_amplitude, d_omega, (g_minus, g_plus), spacing)

    def near_pair(left, right, spacing):
        """The derivatives from the pair at +- PEAK_KINK_SPACING of the kink where the tangent
        lines of ``left`` and ``right`` meet (to O(h^2)), each side predicted from the point
        given on its piece, or None where that kink is not within ``spacing`` of Omega* or the
        pair does not bracket the maximum (a smooth peak)."""
        (a_m, g_m, (_, _, w_m), *_), (a_p, g_p, (_, _, w_p), *_) = left, right
        kink = (a_p - a_m + g_m * w_m - g_p * w_p) / (g_m - g_p)
        close = PEAK_KINK_SPACING * omega
        if abs(kink - omega) < spacing and close < spacing:
            # each predicted from the nearest point solved on its side's piece (the peak's own
            # point where its slope puts it there)
            near_left = side(kink - close, peak if g > 0 and abs(omega - kink) < abs(w_m - kink) else left)
            near_right = side(kink + close, peak if g < 0 and abs(omega - kink) < abs(w_p - kink) else right)
            if near_left is not None and near_right is not None and near_left[1] > 0 > near_right[1]:
                return derivatives(near_left, near_right, close)
        return None

    # the shortcut: the far side of the peak's own point, then the pair at the kink
    sign = -1.0 if g > 0 else 1.0 if g < 0 else 0.0
    spacing = PEAK_FIRST_SPACING * omega
    while sign and spacing <= PEAK_LARGEST_SPACING * omega * (1 + 1e-9):
        far = side(omega - sign * spacing, peak)
        if far is None:
            return None
        if far[1] * sign > 0:
            found = near_pair(*((peak, far) if sign < 0 else (far, peak)), spacing)
            if found is not None:
                return found
            break
        spacing *= 10
    # the symmetric pairs (module docstring)
    spacing = PEAK_FIRST_SPACING * omega
    while spacing <= PEAK_LARGEST_SPACING * omega * (1 + 1e-9):
        left, right = side(omega - spacing, peak), side(omega + spacing, peak)
        if left is None or right is None:
            return None
        if left[1] > 0 > right[1]:
            break
        spacing *= 10
    else:
        return None
    # a kink at the maximum: where the two sides' tangent lines meet (to O(h^2)); the sides again
    # at +- PEAK_KINK_SPACING of it, their pieces' own variation over h being the first-order error
    return near_pair(left, right, spacing) or derivatives(left, right, spacing)
