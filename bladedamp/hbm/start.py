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


@dataclass
class StartResult:
    """x: the best iterate found; converged: whether it solves R(x, omega) = 0 to ``tol``;
    residual_norm: its scaled residual; how: which guess or the homotopy gave it."""

    x: np.ndarray
    converged: bool
    residual_norm: float
    how: str


#: damped Newton gives up once |R| has not halved over this many iterations: a failing damped
#: Newton holds |R| for all its iterations, while those that converge need about as many as this
#: in all (benchmarks/README.md, 'Moved from the package's docstrings', hbm/start.py)
STAGNATION_WINDOW = 10
STAGNATION_FACTOR = 0.5


def damped_newton(fun, x0, x_scale, residual_scale, tol=1e-10, max_iter=60, factorize=lu_factorize,
                  shift=None):
    """Newton with a backtracking (Armijo) line search on |R|, at fixed frequency.

    ``fun(x) -> (R, J)``; ``shift``: a vector added to R (the homotopy's ``(1 - s) f``).
    Converged when |R| / residual_scale < tol and the last full Newton update is below
    sqrt(tol) (scaled by ``x_scale``), the test of :func:`bladedamp.hbm.continuation.newton`;
    stopped as not converged when |R| has not fallen below STAGNATION_FACTOR of its value
    STAGNATION_WINDOW iterations before. Returns (x, converged, scaled residual norm).

    The first full Newton step, and each after a full step was taken (the rule near a
    solution), is tried with the Jacobian (``fun(x, True)``): taken, its residual and Jacobian
    are the next iteration's, instead of one residual for the line search and both again at
    the same point. Other trials are residuals only (while the line search shortens the steps,
    a Jacobian at the full step would mostly be thrown away). The iterates are those of
    residual-only trials (a residual with the Jacobian differs from one without by rounding at
    most: the point contacts' periodic-slider correction); evaluation counts:
    benchmarks/README.md, 'Moved from the package's docstrings', hbm/start.py."""
    x = np.array(x0, dtype=float)
    shift = 0.0 if shift is None else shift
    rnorm = np.inf
    history = []
    taken = None            # fun(x, True) of the full step just taken
    full = True             # the last step was a full one (or none yet): try the next with the Jacobian
    for _ in range(max_iter):
        R, J = fun(x, True) if taken is None else taken
        R = R + shift
        r0 = np.linalg.norm(R)
        rnorm = r0 / residual_scale
        if not np.isfinite(r0):
            return x, False, np.inf
        history.append(rnorm)
        if len(history) > STAGNATION_WINDOW and rnorm > STAGNATION_FACTOR * history[-1 - STAGNATION_WINDOW]:
            return x, False, rnorm            # stagnated: no further progress to expect
        try:
            dx = -factorize(J)(R)
        except (np.linalg.LinAlgError, RuntimeError):
            return x, False, rnorm
        if not np.all(np.isfinite(dx)):
            return x, False, rnorm
        step = np.linalg.norm(dx / x_scale)
        if rnorm < tol and step < np.sqrt(tol):
            return x + dx, True, rnorm
        t = 1.0
        while True:
            x_new = x + t * dx
            trial = fun(x_new, full and t == 1.0)
            r_new = np.linalg.norm(trial[0] + shift)
            if r_new < (1 - 1e-4 * t) * r0 or t <= 1e-4:
                break
            t /= 2
        if not np.isfinite(r_new):
            return x, False, rnorm
        x = x_new
        taken = trial if full and t == 1.0 else None
        full = t == 1.0
        if t * step < 1e-14:
            break
    R = fun(x, False)[0] + shift
    return x, False, np.linalg.norm(R) / residual_scale


def robust_start(residual, guesses, omega, x_scale, forcing, base=None, residual_scale=None, tol=1e-10,
                 factorize=lu_factorize, first_level=0.05, max_levels=80) -> StartResult:
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
    """
    if not isinstance(guesses, dict):
        guesses = {f"guess {k}": g for k, g in enumerate(guesses)}
    forcing = np.asarray(forcing, dtype=float)
    x_scale = np.broadcast_to(np.asarray(x_scale, dtype=float), forcing.shape)
    if residual_scale is None:
        residual_scale = max(np.linalg.norm(forcing), 1e-300)

    def call(x, jacobian):
        if jacobian:
            R, J, _ = residual(x, omega)
            return R, J
        return residual(x, omega, False)[0], None

    best = None
    for name, x0 in guesses.items():
        x, ok, rn = damped_newton(call, x0, x_scale, residual_scale, tol, factorize=factorize)
        if ok:
            return StartResult(x, True, rn, name)
        if best is None or rn < best.residual_norm:
            best = StartResult(x, False, rn, name)
    # excitation homotopy: level s solves R(x) + (1 - s) f = 0, from the stuck state at small s
    base = np.zeros_like(forcing) if base is None else np.asarray(base, dtype=float)
    done, x_done = 0.0, None          # the last level solved and its solution
    previous = None                   # (level, x) solved before it, for the secant predictor
    increment = first_level
    for _ in range(max_levels):
        trial = min(done + increment, 1.0)
        shift = (1.0 - trial) * forcing
        if x_done is None:
            R, J = call(base, True)
            try:
                guess = base - factorize(J)(R + shift)
            except (np.linalg.LinAlgError, RuntimeError):
                break
        elif previous is None:
            guess = x_done
        else:
            guess = x_done + (x_done - previous[1]) * (trial - done) / (done - previous[0])
        xs, ok, rn = damped_newton(call, guess, x_scale, residual_scale, tol, factorize=factorize, shift=shift)
        if not ok and x_done is not None and previous is not None:
            xs, ok, rn = damped_newton(call, x_done, x_scale, residual_scale, tol, factorize=factorize, shift=shift)
        if ok:
            if trial == 1.0:
                return StartResult(xs, True, rn, "excitation homotopy")
            if x_done is not None:
                previous = (done, x_done)
            done, x_done = trial, xs
            increment *= 1.5
        else:
            increment /= 2
            if increment < 1e-4:
                break
    return best
