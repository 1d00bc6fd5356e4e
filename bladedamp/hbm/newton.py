"""Newton's method at a fixed parameter, the one solver of R(x, p) = 0 of the engine.

:func:`newton` serves the continuation's corrector and the peak solver (plain Newton, the
factorisation of the last Jacobian kept for a tangent), the first point of a continuation
(:func:`bladedamp.hbm.start.robust_start`: backtracking line search, stagnation guard) and the
nonlinear modes (:mod:`bladedamp.hbm.nonlinear_modes`: line search on the equilibrated,
bordered system, omega > 0 kept). It returns a :class:`NewtonResult` in every case.

Scaling: the unknowns are measured by ``x_scale`` (a scalar or (n,)), the residual by
``residual_scale`` (a scalar or (n,)); the tolerance applies to the scaled residual and the
scaled update.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .linsolve import factorize as lu_factorize

#: the line search's stagnation guard gives up once the scaled residual has not fallen below
#: STAGNATION_FACTOR of its value STAGNATION_WINDOW iterations before: a failing damped Newton
#: holds |R| for all its iterations, while those that converge need about as many as this in
#: all (benchmarks/README.md, 'Moved from the package's docstrings', hbm/start.py)
STAGNATION_WINDOW = 10
STAGNATION_FACTOR = 0.5


@dataclass
class NewtonResult:
    """What :func:`newton` returns.

    x : (n,) the last iterate (on convergence the last update applied: one step beyond the
        last residual evaluated)
    converged : whether the scaled residual and update met the tolerance (and x is admissible)
    iterations : Newton iterations (Jacobian factorisations) made
    residual_norm : the scaled residual norm (in the norm of the convergence test) of the last
        iterate evaluated; inf where that residual was not finite
    solve, dR_domega : on convergence the factorised dR/dx (``solve(b) = J^-1 b``) of the last
        iterate evaluated and the third item of its residual call (dR/dOmega of a harmonic
        balance residual), for a tangent dx/dOmega = -solve(dR_domega) without another
        Jacobian; None if the solve did not converge
    step : (n,) the last Newton update computed (None if none was)
    evaluated : on convergence the iterate whose residual and Jacobian gave ``solve`` and
        ``dR_domega`` (x is it plus ``step``), else None
    """

    x: np.ndarray
    converged: bool
    iterations: int
    residual_norm: float
    solve: object = None
    dR_domega: np.ndarray | None = None
    step: np.ndarray | None = None
    evaluated: np.ndarray | None = None


@dataclass(frozen=True)
class LineSearch:
    """Backtracking (Armijo) on the 2-norm of the scaled residual: of the fractions t = 1, 1/2,
    1/4, ... of the Newton update the first with |R(x + t dx)| < (1 - sufficient_decrease t)
    |R(x)| is taken, or the first t <= ``min_step`` whatever its residual (a residual that is
    not finite there ends the solve unconverged). ``stagnation_window`` (None: no guard): stop
    unconverged once |R| has not fallen below ``stagnation_factor`` of its value that many
    iterations before. The solve also stops (unconverged) once a step taken is shorter than
    1e-14 (scaled)."""

    min_step: float = 1e-4
    sufficient_decrease: float = 1e-4
    stagnation_window: int | None = STAGNATION_WINDOW
    stagnation_factor: float = STAGNATION_FACTOR


def euclidean(v):
    """The Euclidean norm of a real vector, the number np.linalg.norm gives (sqrt(v . v)), without
    its dispatch (~5 us: several per corrector iteration)."""
    return np.sqrt(v.dot(v))


def _scaled_norms(R, residual_scale, order):
    """(norm of the convergence test, 2-norm) of R / residual_scale; a scalar scale divides the
    norm (the number the continuation has always used), an array scale each component."""
    if np.ndim(residual_scale) == 0:
        two = euclidean(R) / residual_scale
        return (two if order == 2 else np.abs(R).max() / residual_scale), two
    r = R / residual_scale
    two = euclidean(r)
    return (two if order == 2 else np.abs(r).max()), two


def equilibrated(x_scale, residual_scale, solve=np.linalg.solve):
    """A ``factorize`` for :func:`newton` that solves the equilibrated dense system
    (diag(1 / residual_scale) J diag(x_scale)) z = R / residual_scale and returns x_scale z
    (= J^-1 R): for a Jacobian whose rows and columns differ by orders of magnitude (a
    bordered system with frequency and damping unknowns). ``x_scale``, ``residual_scale``
    (n,) arrays; ``solve(A, b)`` the dense solver."""
    x_scale = np.asarray(x_scale, dtype=float)
    residual_scale = np.asarray(residual_scale, dtype=float)

    def factorize(J):
        Js = J * x_scale[None, :]
        Js /= residual_scale[:, None]
        return lambda b: x_scale * solve(Js, b / residual_scale)
    return factorize


def newton(fun, x0, parameter, x_scale, residual_scale, tol=1e-10, max_iter=30, factorize=lu_factorize,
           line_search: LineSearch | None = None, norm=2, admissible=None) -> NewtonResult:
    """Solve R(x, parameter) = 0 at a fixed ``parameter`` (e.g. the angular frequency) by Newton.

    ``fun(x, parameter) -> (R, dR/dx[, dR/dparameter])`` (n,), (n, n); with ``line_search``
    also ``fun(x, parameter, False) -> (R, ...)`` (the residual without the Jacobian).
    ``factorize(J) -> solve`` with ``solve(b) = J^-1 b``: the linear solver (default: dense or
    sparse LU, :func:`bladedamp.hbm.linsolve.factorize`; :func:`equilibrated` for a badly
    scaled dense J). ``x_scale``, ``residual_scale``: scalars or (n,) arrays (see the module
    docstring). Each iteration evaluates R and J at x and the update dx = -J^-1 R.

    Converged when the scaled residual ``norm`` (2 or ``np.inf``) is below ``tol`` and the
    scaled update computed there is below sqrt(tol) in the same norm; that update is applied,
    so the returned point is one step beyond the last residual evaluated. Without
    ``line_search`` the full update is taken each iteration; with it, a fraction of it
    (:class:`LineSearch`). ``admissible(x) -> bool`` (optional): a trial point that is not
    counts as one of infinite residual, and a converged one that is not is reported as not
    converged. Not converged: a residual that is not finite, a singular J, ``max_iter``
    iterations, or the line search's stops.

    With ``line_search`` the first full trial step, and each after a full step was taken (the
    rule near a solution), is evaluated with the Jacobian: taken, its residual and Jacobian are
    the next iteration's, instead of one residual for the line search and both again at the
    same point. Other trials are residuals only (while the line search shortens the steps, a
    Jacobian at the full step would mostly be thrown away); the iteration after a shortened
    step evaluates both at the point taken. Evaluation counts: benchmarks/README.md, 'Moved
    from the package's docstrings', hbm/start.py."""
    if not (norm == 2 or norm == np.inf):
        raise ValueError(f"norm must be 2 or np.inf (the norm of the convergence test), got {norm!r}")
    x = np.array(x0, dtype=float)
    rnorm = np.inf
    dx = None
    history = []
    evaluated = None        # fun(x, parameter) at x: the full step just taken, with the Jacobian
    full = True             # the last step was a full one (or none yet): try the next with the Jacobian
    it = 0
    for it in range(1, max_iter + 1):
        R, J, *more = fun(x, parameter) if evaluated is None else evaluated
        if not np.all(np.isfinite(R)):
            return NewtonResult(x, False, it, np.inf, step=dx)
        rnorm, r2 = _scaled_norms(R, residual_scale, norm)
        if line_search is not None and line_search.stagnation_window is not None:
            history.append(r2)
            window = line_search.stagnation_window
            if len(history) > window and r2 > line_search.stagnation_factor * history[-1 - window]:
                return NewtonResult(x, False, it, rnorm, step=dx)     # no further progress to expect
        try:
            solve = factorize(J)
            dx = -solve(R)
        except (np.linalg.LinAlgError, RuntimeError):   # singular (RuntimeError: splu)
            return NewtonResult(x, False, it, rnorm, step=dx)
        if not np.all(np.isfinite(dx)):
            return NewtonResult(x, False, it, rnorm, step=dx)
        scaled_dx = dx / x_scale
        step = euclidean(scaled_dx) if norm == 2 else np.abs(scaled_dx).max()
        if rnorm < tol and step < np.sqrt(tol):
            last, x = x, x + dx
            if admissible is not None and not admissible(x):
                return NewtonResult(x, False, it, rnorm, step=dx)
            return NewtonResult(x, True, it, rnorm, solve, more[0] if more else None, step=dx, evaluated=last)
        if line_search is None:
            x = x + dx
            continue
        t = 1.0
        while True:
            x_new = x + t * dx
            trial = None
            if admissible is None or admissible(x_new):
                trial = fun(x_new, parameter) if full and t == 1.0 else fun(x_new, parameter, False)
                r_new = _scaled_norms(trial[0], residual_scale, norm)
            else:
                r_new = (np.inf, np.inf)
            if r_new[1] < (1 - line_search.sufficient_decrease * t) * r2 or t <= line_search.min_step:
                break
            t /= 2
        if not np.isfinite(r_new[1]):
            return NewtonResult(x, False, it, rnorm, step=dx)
        x, rnorm = x_new, r_new[0]
        evaluated = trial if full and t == 1.0 else None
        full = t == 1.0
        if t * (step if norm == 2 else euclidean(scaled_dx)) < 1e-14:
            break
    return NewtonResult(x, False, it, rnorm, step=dx)
