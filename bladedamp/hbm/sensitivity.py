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
"""
from __future__ import annotations

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


def state_sensitivities(system, x: np.ndarray, omega: float, dR_dp: np.ndarray, solve=None) -> np.ndarray:
    """dx/dp (k, C*n_dof) at the converged point ``x`` (C*n_dof,) of ``system`` at ``omega``
    [rad/s] of the k parameters whose residual derivatives are the rows of ``dR_dp`` (k, C*n_dof)
    [N per unit of each parameter]: -J^-1 dR/dp with J = dR/dx factorised once (``solve``: a
    factorisation of J at ``x`` already at hand, e.g. the Newton's last, else one is made)."""
    if solve is None:
        _, J, _ = system.residual(x, omega)
        solve = system.factorize(J)
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
    a maximum (g- > 0 > g+)."""
    _, J, Rw = system.residual(x, omega)
    tangent = -system.factorize(J)(Rw)
    a = abs(complex(output @ x))

    def side(w):
        """[|u|, slope g, (x, solve, w) for da/dp] at the converged point at ``w`` [rad/s], or None."""
        r = newton(system.residual, x + tangent * (w - omega), w, x_scale, residual_scale, tol=tol,
                   factorize=system.factorize)
        if not r.converged:
            return None
        amplitude, (slope,) = output_sensitivities(output, r.x, -r.solve(r.dR_domega))
        return [amplitude, slope, (r.x, r.solve, w)]

    def derivatives(left, right, spacing):
        """The peak's derivatives from the two sides (their da/dp evaluated here, only for the pair used)."""
        (_, g_minus, (x_m, solve_m, w_m)), (_, g_plus, (x_p, solve_p, w_p)) = left, right
        s_minus = output_sensitivities(output, x_m, state_sensitivities(system, x_m, w_m, dR_dp(x_m, w_m), solve_m))[1]
        s_plus = output_sensitivities(output, x_p, state_sensitivities(system, x_p, w_p, dR_dp(x_p, w_p), solve_p))[1]
        d_omega = (s_plus - s_minus) / (g_minus - g_plus)
        d_amplitude = 0.5 * (s_minus + g_minus * d_omega + s_plus + g_plus * d_omega)
        return PeakSensitivity(a, omega, x, d_amplitude, d_omega, (g_minus, g_plus), spacing)

    spacing = PEAK_FIRST_SPACING * omega
    while spacing <= PEAK_LARGEST_SPACING * omega * (1 + 1e-9):
        left, right = side(omega - spacing), side(omega + spacing)
        if left is None or right is None:
            return None
        if left[1] > 0 > right[1]:
            break
        spacing *= 10
    else:
        return None
    # a kink at the maximum: where the two sides' tangent lines meet (to O(h^2)); the sides again
    # at +- PEAK_KINK_SPACING of it, their pieces' own variation over h being the first-order error
    kink = (right[0] - left[0] + left[1] * (omega - spacing) - right[1] * (omega + spacing)) / (left[1] - right[1])
    close = PEAK_KINK_SPACING * omega
    if abs(kink - omega) < spacing and close < spacing:
        near_left, near_right = side(kink - close), side(kink + close)
        if near_left is not None and near_right is not None and near_left[1] > 0 > near_right[1]:
            return derivatives(near_left, near_right, close)
    return derivatives(left, right, spacing)
