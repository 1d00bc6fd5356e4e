"""Peaks of a response curve solved by the peak condition d|u|/dOmega = 0.

A branch from continuation only has to bracket a resonance peak: the peak itself is solved
between two converged points from the amplitude and its slope there (dx/dOmega = -J^-1 dR/dOmega)
by a cubic Hermite interpolant and Newton at fixed Omega. The continuation may then take long
steps (the studies' :data:`bladedamp.studies.mass.PEAK_SEARCH_MAX_STEP`, the Monte Carlo's
:data:`bladedamp.studies.mistuning.MONTE_CARLO_MAX_STEP`) without losing the peak's accuracy.

``u = output @ x`` is a first-harmonic complex output of the unknowns x (C * n_dof,), e.g. a
blade tip's displacement (:func:`first_harmonic_output`).
"""
from __future__ import annotations

import numpy as np

from .continuation import newton
from .fourier import HarmonicBasis

#: iterations of :meth:`PeakSolver.solve` (each a Newton solve at fixed Omega); it stops earlier
#: once the frequency settles (usually after a few)
PEAK_MAX_ITERATIONS = 12


def hermite_maximum(a0, g0, a1, g1, h) -> float:
    """Where in [0, 1] the cubic Hermite interpolant of values a0, a1 and slopes g0 > 0 (per unit
    of the abscissa) over an interval of length h has its first local maximum: the first root of
    its derivative, a quadratic positive at 0 (one root between if g1 < 0; two if g1 > 0 and a1 <
    a0, the integral of a derivative positive at both ends being negative)."""
    c2 = 6 * a0 + 3 * h * g0 - 6 * a1 + 3 * h * g1
    c1 = -6 * a0 - 4 * h * g0 + 6 * a1 - 2 * h * g1
    c0 = h * g0
    if abs(c2) < 1e-14 * (abs(c1) + abs(c0)):
        return float(np.clip(-c0 / c1, 0.0, 1.0))
    roots = np.roots([c2, c1, c0])
    roots = roots[np.isreal(roots)].real
    inside = roots[(roots >= 0) & (roots <= 1)]
    return float(inside.min()) if inside.size else 0.5


def first_harmonic_output(basis: HarmonicBasis, n_dof: int, columns, weights) -> np.ndarray:
    """Complex (C * n_dof,) row w with ``w @ x`` = sum_k weights[k] (a_1 - i b_1) of DOF
    ``columns[k]``: the first-harmonic complex amplitude of a linear output of those DOFs (e.g.
    a tip displacement from the modal coordinates and the mode shapes' tip row)."""
    j1 = basis.cos_index(1)
    w = np.zeros((basis.n_coeffs, n_dof), dtype=complex)
    w[j1, columns] = weights
    w[j1 + 1, columns] = -1j * np.asarray(weights)
    return w.ravel()


class PeakSolver:
    """Solves local peaks of outputs on one converged branch of ``system`` (its ``residual(x,
    omega)`` -> (R, J, dR/dOmega) and ``factorize``): ``omega`` (n,) [rad/s], ``X`` (n, C * n_dof).
    The tangents dx/dOmega at the branch's points are computed once each and shared by every
    output solved (the blades of a mistuned disk)."""

    def __init__(self, system, omega, X, tol: float = 1e-10, max_iter: int = PEAK_MAX_ITERATIONS):
        self.system, self.omega, self.tol, self.max_iter = system, np.asarray(omega, dtype=float), tol, max_iter
        self.X = np.asarray(X, dtype=float).reshape(len(self.omega), -1)
        scale = np.abs(self.X).max(axis=0)
        self.x_scale = np.maximum(scale, 1e-3 * scale.max() + 1e-300)
        self._tangents = {}
        self._residual_scale = None

    def _tangent(self, x, w):
        """dx/dOmega (C * n_dof,) at the converged point x, w [rad/s]."""
        _, J, Rw = self.system.residual(x, w)
        return -self.system.factorize(J)(Rw)

    def _sample(self, k):
        if k not in self._tangents:
            self._tangents[k] = self._tangent(self.X[k], float(self.omega[k]))
        return float(self.omega[k]), self.X[k], self._tangents[k]

    @staticmethod
    def _slope(output, x, dx):
        """(|u|, d|u|/dOmega) of u = output @ x with dx/dOmega = dx."""
        u, du = output @ x, output @ dx
        return abs(u), float(np.real(np.conj(u) * du) / max(abs(u), 1e-300))

    def solve(self, index: int, output) -> tuple[float, float] | None:
        """(peak |u|, its frequency [rad/s]) of :meth:`solve_state`, or None."""
        solved = self.solve_state(index, output)
        return None if solved is None else solved[:2]

    def solve_state(self, index: int, output) -> tuple[float, float, np.ndarray] | None:
        """(peak |u|, its frequency [rad/s], the solution x (C * n_dof,) there) of a local maximum
        of |u| = |output @ x| next to branch point ``index`` (a local maximum of the sampled curve), or None where it is not
        solved: at an end of the branch, a fold next to the sample, or a Newton solve that does
        not converge.

        A bracket [w0, w1] holds a local maximum as long as |u| rises at w0 (slope g0 > 0) and
        either falls at w1 (g1 < 0) or is lower there (a1 < a0: the curve has turned down in
        between, e.g. at a kink where a contact point starts to slip, with the slopes of both
        sides positive), or, mirrored, falls at w1 and is higher there than at w0 (a1 > a0 with
        g0 <= 0: the curve turned up and down again in between, two maxima of the AFT's kinks a
        few mHz apart, the sample the higher one's side). It starts between the sample and the
        neighbour on the side where |u| still rises (or falls less steeply), else where the
        mirrored form holds. The maximum of the cubic Hermite interpolant of the ends (the first
        from w0, mirrored the last before w1) is the next frequency (the bisection where the same
        end moved twice running), solved there by Newton from the Taylor predictor of the nearer
        end (tolerance ``tol``, scaled as the continuation's); the end it replaces keeps a form
        of the invariant. It stops when the frequency moves by less than 1e-9 relative (2-3
        iterations on a smooth peak)."""
        omega, n = self.omega, len(self.omega)
        if not 0 < index < n - 1 or not (omega[index - 1] < omega[index] < omega[index + 1]):
            return None
        if self._residual_scale is None:
            R0 = self.system.residual(np.zeros(self.X.shape[1]), omega[index], False)[0]
            self._residual_scale = max(np.linalg.norm(R0), 1e-300)
        ends = [(*self._sample(k), *self._slope(output, self._sample(k)[1], self._sample(k)[2]))
                for k in (index - 1, index, index + 1)]                          # (w, x, dx, a, g)
        left, middle, right = ends
        pairs = ((middle, right), (left, middle))
        bracket = [(l, r) for l, r in pairs if self._brackets(l, r)] + \
                  [(l, r) for l, r in pairs if self._brackets_mirrored(l, r)]
        if not bracket:
            return None
        (w0, x0, d0, a0, g0), (w1, x1, d1, a1, g1) = bracket[0]
        best, w_prev, moved = max((a0, w0, 0), (a1, w1, 1)), None, None
        best = best[:2] + ((x0, x1)[best[2]],)
        for _ in range(self.max_iter):
            mirrored = not g0 > 0                      # then g1 < 0 < a1 - a0 (_brackets_mirrored)
            if moved is not None and moved[0] == moved[1]:
                t = 0.5
            elif mirrored:
                t = 1.0 - hermite_maximum(a1, -g1, a0, -g0, w1 - w0)
            else:
                t = hermite_maximum(a0, g0, a1, g1, w1 - w0)
            w = w0 + (w1 - w0) * t
            xp = x0 + d0 * (w - w0) if w - w0 <= w1 - w else x1 + d1 * (w - w1)
            r = newton(self.system.residual, xp, w, self.x_scale, self._residual_scale, tol=self.tol,
                       factorize=self.system.factorize)
            if not r.converged:
                return None
            # the tangent from the Newton's last factorisation (its iterate met the tolerance):
            # one Jacobian less per iteration
            d = -r.solve(r.dR_domega)
            a, g = self._slope(output, r.x, d)
            if (a, w) > best[:2]:
                best = (a, w, r.x)
            if w_prev is not None and abs(w - w_prev) <= 1e-9 * w:
                break
            w_prev = w
            if mirrored:
                side = "right" if g < 0 and a >= a1 else "left"
            else:
                side = "left" if g > 0 and a >= a0 else "right"
            moved = (moved[1] if moved else None, side)
            if side == "left":
                w0, x0, a0, g0, d0 = w, r.x, a, g, d
            else:
                w1, x1, a1, g1, d1 = w, r.x, a, g, d
        return float(best[0]), float(best[1]), best[2]

    @staticmethod
    def _brackets(left, right) -> bool:
        """Whether the ends (w, x, dx, a, g) hold a local maximum between them, rising at the left."""
        return left[4] > 0 and (right[4] < 0 or right[3] < left[3])

    @staticmethod
    def _brackets_mirrored(left, right) -> bool:
        """Whether the ends (w, x, dx, a, g) hold a local maximum between them, the mirrored form:
        falling at the right end and higher there."""
        return right[4] < 0 and right[3] > left[3]
