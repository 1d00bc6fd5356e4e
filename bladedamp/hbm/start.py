"""The solution at the first frequency of a continuation, robust in gross slip and lift-off.

One place for every model (:class:`~bladedamp.disk.TunedDisk`,
:class:`~bladedamp.mistuned.MistunedDisk`, :class:`~bladedamp.oscillator.FrictionOscillator`):

1. damped Newton (backtracking line search on the residual norm) from each initial guess in
   turn (e.g. the stuck and the free linear solution);
2. if none converges, an excitation homotopy from the best guess: the excitation is ramped up
   from a small level at which the stuck linear solution is exact (no point slips), each level
   started from the previous solution; a level that does not converge is approached in smaller
   increments.

The residual of a harmonic balance is ``R(x) = A x + f_nl(x) - f``; the level-``s`` problem is
``R(x) + (1 - s) f = 0``, so only the excitation vector ``f`` is needed, not the model.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .linsolve import factorize as lu_factorize
from .newton import LineSearch, newton


@dataclass
class StartResult:
    """x: the best iterate found; converged: whether it solves R(x, omega) = 0 to ``tol``;
    residual_norm: its scaled residual; how: which guess or the homotopy gave it."""

    x: np.ndarray
    converged: bool
    residual_norm: float
    how: str


#: the line search of the start (:class:`bladedamp.hbm.newton.LineSearch`'s defaults: halving
#: down to 1e-4, the stagnation guard)
START_LINE_SEARCH = LineSearch()


def _shifted(residual, shift):
    """``residual`` with ``shift`` added to R (the homotopy's ``(1 - s) f``)."""
    def fun(x, omega, jacobian=True):
        R, J = residual(x, omega, jacobian)[:2]
        return R + shift, J
    return fun


def robust_start(residual, guesses, omega, x_scale, forcing, base=None, residual_scale=None, tol=1e-10,
                 factorize=lu_factorize, first_level=0.05, max_levels=80, out_of_time=None) -> StartResult:
    """Solve R(x, omega) = 0 robustly; returns a :class:`StartResult` (the best iterate if none converged).

    Parameters
    ----------
    residual : (x, omega[, jacobian]) -> (R, dR/dx, dR/domega), ``R = A x + f_nl(x) - f``
    guesses : initial guesses (name -> x, or a sequence), tried in order by damped Newton
    omega : the frequency [rad/s]
    x_scale : scale of the unknowns (scalar or array)
    forcing : the dynamic excitation vector f at ``omega``, the part the homotopy ramps up
        (leave static loads such as a centrifugal preload out: they set the contact state)
    base : the state without dynamic excitation from which each homotopy level starts by one
        Newton step (its stuck linear solution; default zeros, e.g. the seated damper)
    residual_scale : default |f|
    tol : scaled residual tolerance (as :func:`bladedamp.hbm.continuation.continuation`'s)
    first_level : the homotopy's first excitation level (a fraction of f)
    max_levels : most homotopy levels tried (the increment halves on failure, grows on success)
    out_of_time : None, or a function () -> bool, asked before each damped Newton solve (a guess
        or a homotopy level): once it says True no further solve is begun and the best iterate
        so far is returned (not converged; the zero-excitation ``base`` if none was tried), so an
        analysis' CPU budget also bounds its start (issue 32 item 2)
    """
    if not isinstance(guesses, dict):
        guesses = {f"guess {k}": g for k, g in enumerate(guesses)}
    forcing = np.asarray(forcing, dtype=float)
    x_scale = np.broadcast_to(np.asarray(x_scale, dtype=float), forcing.shape)
    if residual_scale is None:
        residual_scale = max(np.linalg.norm(forcing), 1e-300)

    def damped_newton(x0, shift):
        return newton(_shifted(residual, shift), x0, omega, x_scale, residual_scale, tol, max_iter=60,
                      factorize=factorize, line_search=START_LINE_SEARCH)

    def timed_out():
        return out_of_time is not None and out_of_time()

    best = None
    for name, x0 in guesses.items():
        if timed_out():
            break
        sol = damped_newton(x0, 0.0)
        if sol.converged:
            return StartResult(sol.x, True, sol.residual_norm, name)
        if best is None or sol.residual_norm < best.residual_norm:
            best = StartResult(sol.x, False, sol.residual_norm, name)
    # excitation homotopy: level s solves R(x) + (1 - s) f = 0, from the stuck state at small s
    base = np.zeros_like(forcing) if base is None else np.asarray(base, dtype=float)
    if best is None and timed_out():  # out of time before any guess
        return StartResult(base.copy(), False, np.inf, "none (out of time)")
    done, x_done = 0.0, None          # the last level solved and its solution
    previous = None                   # (level, x) solved before it, for the secant predictor
    increment = first_level
    for _ in range(max_levels):
        if timed_out():
            break
        trial = min(done + increment, 1.0)
        shift = (1.0 - trial) * forcing
        if x_done is None:
            R, J = residual(base, omega)[:2]
            try:
                guess = base - factorize(J)(R + shift)
            except (np.linalg.LinAlgError, RuntimeError):
                break
        elif previous is None:
            guess = x_done
        else:
            guess = x_done + (x_done - previous[1]) * (trial - done) / (done - previous[0])
        sol = damped_newton(guess, shift)
        if not sol.converged and x_done is not None and previous is not None:
            sol = damped_newton(x_done, shift)
        if sol.converged:
            xs = sol.x
            if trial == 1.0:
                return StartResult(xs, True, sol.residual_norm, "excitation homotopy")
            if x_done is not None:
                previous = (done, x_done)
            done, x_done = trial, xs
            increment *= 1.5
        else:
            increment /= 2
            if increment < 1e-4:
                break
    return best
