"""Newton with analytic Jacobian and predictor-corrector pseudo-arclength continuation.

Both work on a residual ``fun(x, omega) -> (R, dR/dx, dR/domega)`` (see
:class:`bladedamp.hbm.system.HarmonicBalanceSystem`). Unknowns are scaled (``x / x_scale``,
``omega / omega_scale``) so that tolerances mean the same for every problem. A solver
that does not converge says so and keeps what it has: the returned :class:`Branch` carries
every converged point, ``success`` and a ``message`` naming the frequency where it stopped.

``fun`` may return ``dR/dx`` dense or as a ``scipy.sparse`` matrix. Each Newton step and
bordered arc-length system is factorised once by ``factorize`` (default: dense LU, or
``scipy.sparse.linalg.splu`` whose cost grows about linearly for a sparsely coupled problem;
a structured solver such as :class:`~bladedamp.hbm.linsolve.BlockCondensation` for assemblies),
and the same factorisation gives the corrector's update and the next tangent.
"""
from __future__ import annotations

import contextlib
import contextvars
import copy
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numba import njit

from .. import validation
from .linsolve import factorize as lu_factorize
from .newton import NewtonResult, euclidean, newton  # noqa: F401  (newton, NewtonResult: the names callers know)


class _BorderedPattern:
    """Where :func:`bordered_matrix` puts a CSC matrix's entries, its border's and their row indices,
    for one sparsity pattern (n, indices, indptr), and the bordered matrix to copy (its index
    arrays shared). Kept for the last pattern seen (:func:`_bordered_pattern`): a system's
    Jacobians share theirs (:class:`~bladedamp.mistuned.AssemblySystem` returns the same index
    arrays every time), so the indices are not formed anew at every corrector iteration."""

    def __init__(self, n, indices, indptr):
        self.key = (indices, indptr)          # kept alive: the identity test below stays valid
        self.counts = np.diff(indptr)
        shift = np.arange(n + 1, dtype=indptr.dtype)          # column j moves down by j entries
        self.moved = np.arange(indices.size) + np.repeat(shift[:-1], self.counts)
        self.ends = indptr[1:] + shift[:-1]                   # the row's entry of column j
        self.start = start = indptr[n] + n                    # the last column: column, then row[n]
        out_indices = np.empty(start + n + 1, dtype=indices.dtype)
        out_indices[self.moved], out_indices[self.ends] = indices, n
        out_indices[start:start + n], out_indices[-1] = np.arange(n), n
        self.matrix = sp.csc_matrix((np.zeros(start + n + 1), out_indices, np.append(indptr + shift, start + n + 1)),
                                    shape=(n + 1, n + 1))


_last_bordered_pattern = None


def _bordered_pattern(n, indices, indptr):
    """The :class:`_BorderedPattern` of these index arrays (the same objects as the last call's:
    reused; else built and kept). One read and one write of the module's slot: threads that
    border different patterns at once only rebuild more often."""
    global _last_bordered_pattern
    last = _last_bordered_pattern
    if last is None or last.key[0] is not indices or last.key[1] is not indptr or last.matrix.shape[0] != n + 1:
        last = _last_bordered_pattern = _BorderedPattern(n, indices, indptr)
    return last


def bordered_matrix(J, column, row, column_scale, factor):
    """[[J diag(column_scale), column] factor; row] (J square, dense or sparse); in one pass
    either way (sparse: CSC, each column's row entry last; equal to bordering
    ``scale_columns``' result). The sparse bordered matrix's indices are those of
    :func:`_bordered_pattern`, formed once per pattern (timings: benchmarks/README.md, 'Moved
    from the package's docstrings', continuation.py)."""
    n = J.shape[0]
    if sp.issparse(J):
        J = J if sp.isspmatrix_csc(J) else sp.csc_matrix(J)
        pattern = _bordered_pattern(n, J.indices, J.indptr)
        start = pattern.start
        out = np.empty(start + n + 1)
        bordered_columns(np.asarray(J.data, dtype=float), J.indptr,
                         np.ascontiguousarray(column_scale * factor, dtype=float), np.ascontiguousarray(row, dtype=float),
                         out)
        out[start:start + n] = column * factor
        out[-1] = row[n]
        bordered = copy.copy(pattern.matrix)
        bordered.data = out
        return bordered
    A = np.empty((n + 1, n + 1))
    np.multiply(J, column_scale * factor, out=A[:n, :n])
    A[:n, n] = column * factor
    A[n] = row
    return A


@njit(cache=True)
def bordered_columns(data, indptr, scale, row, out):
    """The first n columns of :func:`bordered_matrix`'s CSC values: column j of J (CSC ``data``,
    ``indptr``, n columns) times ``scale[j]``, then the border row's ``row[j]``, column after
    column (entry p of column j lands at p + j; :class:`_BorderedPattern`'s ``moved`` and
    ``ends``). The same products as ``J.data * np.repeat(scale, counts)``, so the same numbers."""
    for j in range(indptr.size - 1):
        s = scale[j]
        for p in range(indptr[j], indptr[j + 1]):
            out[p + j] = data[p] * s
        out[indptr[j + 1] + j] = row[j]


def _unit_last(n: int) -> np.ndarray:
    """e_{n+1} of length n + 1: the right-hand side of the bordered tangent systems."""
    e = np.zeros(n + 1)
    e[n] = 1.0
    return e


def _det_sign(A, solve=None) -> int:
    """Sign of det A: from the factorisation ``solve`` if it carries one (``solve.sign``, e.g.
    :class:`~bladedamp.hbm.linsolve.BlockRing`'s, at no extra cost), else by slogdet for a
    dense matrix, else 0 (not computed: a sparse matrix without a signed factorisation)."""
    sign = getattr(solve, "sign", None)
    if sign is not None:
        return int(sign)
    if sp.issparse(A) or not isinstance(A, np.ndarray):
        return 0
    sign, _ = np.linalg.slogdet(A)
    return int(sign)


# returns of a branch to its own earlier points after which it is taken to be in a loop: a
# corner may send the corrector back over a few points before it passes, a loop returns at
# every step
MAX_REVISITS = 200


# The stall guard (:func:`stall_guard`): a branch whose furthest frequency has not grown by
# STALL_PROGRESS of its range over its last STALL_POINTS points kept has stalled: a branch that
# folds every few points with omega moving back and forth by a small fraction of the range would
# otherwise run for hundreds of points before the retrace guard or max_points ends it
# (benchmarks/README.md, 'Cost of the default FRF on random disks').
STALL_POINTS = 100
STALL_PROGRESS = 1e-4
_STALL_GUARD = contextvars.ContextVar("stall_guard", default=False)


@contextlib.contextmanager
def stall_guard():
    """Within this context every :func:`continuation` branch also ends where it has stalled: no
    point of its last STALL_POINTS got further into the range than STALL_PROGRESS x its width
    beyond the furthest point before them. The branch is then unsuccessful, its message says it
    stalled (a failure like the retrace guard's, not a ``stopped_by``: the branch from the end and
    the retry follow as for any failed branch). Used by the disks' automatic harmonic choice
    (:func:`bladedamp.hbm.accuracy.converged_response` with ``guard_stalls``) for a richer set's
    branches once a poorer set's reached the end, where a branch that stalls costs time and cannot change the answer
    unless it reaches the end: outside this context no branch is ended by it."""
    token = _STALL_GUARD.set(True)
    try:
        yield
    finally:
        _STALL_GUARD.reset(token)


# The default budget of one analysis (a model's frequency_response): CPU seconds
# (time.process_time, every thread of the process) and continuation points kept, summed over
# every branch it computes (both ends, retries, finer samples, richer harmonic sets). A budget is
# a guard against a run without end, not a cost target. CPU: random tuned disks that reach their
# end took up to 108 CPU s with the default frequency_response (median 1.4 s); 600 s leaves a
# margin of more than five. Points: the per-branch cap max_points (5000, a quarter for the
# retry) times the branches of the automatic choices (at most 5 harmonic sets x 4 sample counts
# x 4 branches) stays below 10^6, so the default point budget binds only where max_points is
# raised; a smaller one caps an analysis by its points.
DEFAULT_CPU_BUDGET_S = 600.0
DEFAULT_POINT_BUDGET = 1_000_000
# The largest arc-length step [scaled units, the omega range is 1]: the default of continuation()
# and of every model's frequency_response.
DEFAULT_MAX_STEP = 0.02


class Budget:
    """What one analysis may spend: ``cpu_seconds`` of CPU time (``time.process_time``, counted
    from when the budget is made) and ``max_points`` continuation points kept, over every
    :func:`continuation` it is passed to. :meth:`spend` counts a point and says when the budget
    has run out; the continuation then ends its branch there, keeping its points, with the
    message as ``Branch.stopped_by`` (a terminal stop: no retry)."""

    def __init__(self, cpu_seconds: float = DEFAULT_CPU_BUDGET_S, max_points: int = DEFAULT_POINT_BUDGET):
        self.cpu_seconds = validation.positive("cpu_budget_s (CPU seconds)", cpu_seconds)
        self.max_points = validation.integer("point_budget (continuation points)", max_points, minimum=1)
        self.started = time.process_time()
        self.points = 0

    def cpu_used(self) -> float:
        """CPU seconds spent since the budget was made."""
        return time.process_time() - self.started

    def exhausted(self, omega: float) -> str:
        """'' while the budget lasts; otherwise what ran out, at the angular frequency ``omega``
        [rad/s] (reported in Hz), starting with "budget" (the word by which
        :func:`bladedamp.response.response_status` tells it from a caller's stop): "budget: 300
        CPU s ran out at 97.3 Hz" or "budget: 5000 continuation points ran out at 97.3 Hz"."""
        where = f"{omega / (2 * np.pi):.6g} Hz"
        if self.points >= self.max_points:
            return f"budget: {self.max_points} continuation points ran out at {where}"
        if self.cpu_used() > self.cpu_seconds:
            return f"budget: {self.cpu_seconds:g} CPU s ran out at {where}"
        return ""

    def spend(self, omega: float) -> str:
        """Count one point kept at ``omega`` [rad/s]; :meth:`exhausted` after it."""
        self.points += 1
        return self.exhausted(omega)


class ConvergenceWarning(UserWarning):
    """A Newton or continuation run stopped without converging."""


@dataclass
class Branch:
    """A solution branch x(omega) from continuation.

    Attributes
    ----------
    omega : (n,) angular frequencies of the converged points [rad/s]
    x : (n, N) unknowns at each point
    iterations : (n,) Newton iterations of each corrector
    success : bool, whether the branch reached the end of the requested range with every check passing
    message : str, why it stopped
    turning_points : indices of the folds
    checks : {name: bool} of :func:`branch_checks` (empty for a branch not made by :func:`continuation`)
    stopped_by : what ``stop_when`` said when it ended the branch ('' if it did not): the branch
        is then not ``success`` but not a failure of the method either, and is never retried
    out_of_points : the ``max_points`` a branch used up before the end of its range (it stopped
        there, its message says so); 0 if it did not
    """

    omega: np.ndarray
    x: np.ndarray
    iterations: np.ndarray
    success: bool
    message: str
    turning_points: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # indices of folds
    checks: dict = field(default_factory=dict)   # name -> bool, see branch_checks
    stopped_by: str = ""
    out_of_points: int = 0

    def reversed(self, message: str) -> "Branch":
        """This branch in the opposite order (a branch computed from the end of its range,
        returned from the start), with ``message``; its turning points renumbered."""
        n = len(self.omega)
        return Branch(self.omega[::-1].copy(), self.x[::-1].copy(), self.iterations[::-1].copy(), self.success,
                      message, np.sort(n - 1 - np.asarray(self.turning_points, dtype=int)), dict(self.checks),
                      self.stopped_by, self.out_of_points)

    def take(self, indices) -> "Branch":
        """The points ``indices`` of this branch (for re-evaluating them, e.g. with a finer AFT)."""
        indices = np.asarray(indices, dtype=int)
        return Branch(self.omega[indices], self.x[indices], self.iterations[indices], self.success, self.message,
                      stopped_by=self.stopped_by, out_of_points=self.out_of_points)


def branch_checks(omega, omega_start, omega_end, max_step) -> dict:
    """The contract of every branch :func:`continuation` returns, each check True if it holds:

    ``inside_range``: every kept omega in [min(omega_start, omega_end), max(...)] (no point
    beyond either end, no negative frequency); ``step_within_max_step``: no step between
    consecutive points longer in omega than ``max_step`` times the range's width (max_step is
    in scaled arc-length units, where the omega range is 1)."""
    omega = np.asarray(omega, dtype=float)
    lo, hi = min(omega_start, omega_end), max(omega_start, omega_end)
    width = hi - lo
    slack = 1e-12 * max(abs(lo), abs(hi))
    inside = bool(np.all((omega >= lo - slack) & (omega <= hi + slack)))
    steps = np.abs(np.diff(omega))
    short = bool(steps.size == 0 or steps.max() <= max_step * width * (1 + 1e-9) + slack)
    return {"inside_range": inside, "step_within_max_step": short}


def _validate_options(step, max_step, min_step, max_points, tol, max_corrector, target_iterations, leave_margin):
    """ValueError naming the option and its allowed range for zero, negative or NaN values."""
    validation.in_range("max_step", max_step, 0.0, 1.0, closed="right")
    validation.in_range("step", step, 0.0, max_step, closed="right")
    validation.in_range("min_step", min_step, 0.0, step, closed="right")
    validation.in_range("tol (Newton tolerance)", tol, 0.0, 1.0, closed="neither")
    validation.integer("max_points", max_points, minimum=2)
    validation.integer("max_corrector", max_corrector, minimum=1)
    validation.integer("target_iterations", target_iterations, minimum=1)
    validation.nonnegative("leave_margin", leave_margin)


# continuation(chord=True): a chord iteration whose update is larger than this fraction of the
# previous one is followed by a fresh Jacobian; a chord iteration costs a fraction of a Newton
# iteration (benchmarks/README.md, 'Moved from the package's docstrings', continuation.py)
CHORD_CONTRACTION = 0.25

# The retry of continuation(retry_x_scale=...) gets this fraction of max_points. Where the
# re-weighting is the cure, the branch it follows is much shorter than the first try's; where
# it is not, a full retry would double the cost of each failed branch (benchmarks/README.md,
# 'Moved from the package's docstrings', continuation.py).
RETRY_POINTS_FRACTION = 4


def continuation(fun, x0, omega_start, omega_end, x_scale=None, residual_scale=None,
                 step=None, max_step=None, min_step=None, max_points=5000, tol=1e-10,
                 max_corrector=12, target_iterations=5, factorize=lu_factorize, leave_margin=0.0,
                 start_at_end=None, retry_x_scale=None, stop_when=None, chord=False, budget=None):
    """Pseudo-arclength continuation of R(x, omega) = 0 from ``omega_start`` to ``omega_end``.

    Every branch it returns keeps the contract of :func:`branch_checks` (``Branch.checks``):
    no point outside the range (a branch that turns back stops where it reaches ``omega_start``,
    unsuccessful, its message saying it turned back; a point landing beyond ``omega_end`` is
    replaced by the solution at ``omega_end``) and no step longer in omega than ``max_step``
    times the range's width (a longer step is rejected and retried shorter).

    Parameters
    ----------
    fun : callable (x, omega) -> (R, dR/dx, dR/domega)
    x0 : initial guess at ``omega_start``
    omega_start, omega_end : range [rad/s] (either direction)
    x_scale : scale of the unknowns (scalar or array); default max |x0|
    residual_scale : scale of the residual norm; default |R(0, omega_start)| (the excitation)
    step, max_step, min_step : arc-length steps in scaled units (the scaled omega range is 1):
        0 < min_step <= step <= max_step <= 1 (defaults 1e-7, 0.01 or max_step, 0.02)
    max_points : stop after this many points (an integer >= 2)
    tol : Newton tolerance on the scaled step and residual, in (0, 1)
    max_corrector : corrector iterations per step (>= 1)
    target_iterations : corrector iterations for which the step is kept; fewer -> grow, more -> shrink
    factorize : ``factorize(A) -> solve``, the linear solver for Newton and the bordered systems
        (default: dense or sparse LU; a structured one such as
        :class:`~bladedamp.hbm.linsolve.BlockCondensation` for assemblies)
    leave_margin : kept for compatibility (>= 0), without effect: a branch that turns back now
        always stops at ``omega_start`` (it used to run on until it passed ``omega_start`` by
        this fraction of the range's width, keeping points outside the range)
    start_at_end : callable () -> initial guess at ``omega_end``, or None. If the branch from
        ``omega_start`` fails (it stalls, retraces itself or turns back to the start), the branch
        from ``omega_end`` down to ``omega_start`` is computed from that guess; if it reaches the
        start with every check passing it is returned, ordered from ``omega_start`` to
        ``omega_end``, its message saying what the branch from the start did (where that one
        turned back there is a second solution at the same frequencies). Otherwise the branch
        from the start is returned, with its warnings.
    retry_x_scale : scale of the unknowns (as ``x_scale``) for a second try where the first
        (from the start, then from the end) fails, or None: the same continuation with the arc
        length measured by these scales (e.g. a disk's with the damper's unknowns weighing less,
        :func:`bladedamp.diskmodel.damper_weighted_scales`), and with 1 / RETRY_POINTS_FRACTION of
        ``max_points``. Its branch is returned if it succeeds, its message saying so; otherwise
        the one of the two failed branches that got further into the range (the first on a tie),
        with its warnings. A branch that succeeds at the first try is never recomputed, so the
        second try changes no such result.
    stop_when : callable (x, omega) -> str or None, or None: called at every point kept (the
        first included); a non-empty string ends the branch there, unsuccessful, with that
        string as ``Branch.stopped_by`` and in the message (a terminal event, like
        ``solve_ivp``'s). Such a branch is not retried from the end or with ``retry_x_scale``:
        the caller asked for it to stop (e.g. a mass search that only needs to know a peak is
        above the best one found, :func:`bladedamp.studies.mass.optimal_mass`).
    chord : False (default): every corrector iteration evaluates and factorises the Jacobian
        (Newton). True: the corrector keeps the factorisation of its last Jacobian while its
        updates contract by at least CHORD_CONTRACTION per iteration (chord iterations, each one
        residual without the Jacobian, ``fun(x, omega, False)[0]``, and a back-substitution),
        and evaluates a new one where they do not. The points meet the same tolerance; the
        next tangent comes from the last factorisation (at an earlier iterate of the same
        corrector). ``fun`` must then accept a third argument ``jacobian``.
    budget : :class:`Budget` or None (default: no budget beyond ``max_points`` per branch): the
        CPU time and points the caller's whole analysis may spend, shared by every branch it
        computes. Checked at every point kept (the first included); where it has run out the
        branch ends there, unsuccessful, its points kept, with what ran out and where as
        ``Branch.stopped_by`` and in the message (a terminal event like ``stop_when``: no branch
        from the end, no retry). A branch started after the budget ran out keeps no point. The
        point that lands on ``omega_end`` completes the branch whatever the budget.

    The steps are the methods of :class:`ArcLengthContinuation`, in the order they are tried
    from each point: the predictor-corrector along the tangent with shorter steps
    (``step_along``), the turn at a Newton 2-cycle (``turn_at_cycle``), the hop at fixed omega
    (``hop``), the point past a corner (``past_corner``), the sphere around the point
    (``corner_escape``); then the landing at either end of the range (``land_at_start``,
    ``land_at_end``) and the retrace guard (``retraced``).
    """
    validation.finite("omega_start", omega_start)
    validation.finite("omega_end", omega_end)
    if omega_start == omega_end:
        raise ValueError("omega_end must differ from omega_start")
    max_step = DEFAULT_MAX_STEP if max_step is None else max_step
    validation.in_range("max_step", max_step, 0.0, 1.0, closed="right")
    step = min(0.01, max_step) if step is None else step
    min_step = min(1e-7, step) if min_step is None else min_step
    _validate_options(step, max_step, min_step, max_points, tol, max_corrector, target_iterations, leave_margin)
    x0 = np.asarray(x0, dtype=float)
    if not np.all(np.isfinite(x0)):
        raise ValueError("x0 (initial guess) must be finite")
    if stop_when is not None and not callable(stop_when):
        raise ValueError(f"stop_when must be a callable (x, omega) -> str or None, or None (got {stop_when!r})")
    if budget is not None and not isinstance(budget, Budget):
        raise ValueError(f"budget must be a bladedamp.hbm.continuation.Budget or None (got {budget!r})")
    options = (step, max_step, min_step, max_points, tol, max_corrector, target_iterations, factorize, stop_when,
               bool(chord), budget)
    if start_at_end is None and retry_x_scale is None:
        return ArcLengthContinuation(fun, x0, omega_start, omega_end, x_scale, residual_scale, *options).run()
    with warnings.catch_warnings(record=True) as first_warnings:
        warnings.simplefilter("always", ConvergenceWarning)
        first = _both_ends(fun, x0, omega_start, omega_end, x_scale, residual_scale, options, start_at_end)
    if first.success or first.stopped_by:
        return first
    if retry_x_scale is not None:
        with warnings.catch_warnings(record=True) as retry_warnings:
            warnings.simplefilter("always", ConvergenceWarning)
            retry_options = (step, max_step, min_step, max(2, max_points // RETRY_POINTS_FRACTION), tol, max_corrector,
                             target_iterations, factorize, stop_when, bool(chord), budget)
            retried = _both_ends(fun, x0, omega_start, omega_end, retry_x_scale, residual_scale, retry_options,
                                 start_at_end)
            if retried.success:
                retried.message += f" (second try, with the arc length weighted by retry_x_scale; first try: " \
                                   f"{first.message})"
                return retried
        # both failed: the branch that got further into the range is the better account of where
        # the solutions end (the first try may retrace itself from a fold the second passes)
        if _reach(retried, omega_start, omega_end) > _reach(first, omega_start, omega_end):
            retried.message += f" (second try, with the arc length weighted by retry_x_scale, which got further " \
                               f"than the first; first try: {first.message})"
            first, first_warnings = retried, retry_warnings
    for w in first_warnings:
        _warn(w.message, 2)
    return first


def _reach(branch, omega_start, omega_end) -> float:
    """How far ``branch`` got from ``omega_start`` towards ``omega_end`` [rad/s] (-inf: no point)."""
    if not len(branch.omega):
        return -np.inf
    return float(np.max(np.sign(omega_end - omega_start) * (branch.omega - omega_start)))


def _both_ends(fun, x0, omega_start, omega_end, x_scale, residual_scale, options, start_at_end):
    """The branch from ``omega_start``; if it fails and ``start_at_end`` is given, the one from
    ``omega_end`` where that one succeeds (see :func:`continuation`). The branch from the start
    warns as it stops; the one from the end does not (it is returned only if it succeeds)."""
    forward = ArcLengthContinuation(fun, x0, omega_start, omega_end, x_scale, residual_scale, *options).run()
    if forward.success or forward.stopped_by or start_at_end is None:
        return forward
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always", ConvergenceWarning)
        x_end = np.asarray(start_at_end(), dtype=float)
        backward = ArcLengthContinuation(fun, x_end, omega_end, omega_start, x_scale, residual_scale,
                                         *options).run() if np.all(np.isfinite(x_end)) else None
    if backward is not None and backward.success:
        return backward.reversed(f"reached the end of the frequency range, computed from its end down to its "
                                 f"start (from the start, the {forward.message})")
    return forward


def _warn(message, depth):
    """A ConvergenceWarning shown at the caller of :func:`continuation` (``depth`` frames up)."""
    warnings.warn(message, ConvergenceWarning, stacklevel=depth + 1)


@dataclass
class _Attempt:
    """What the predictor-corrector found from one point (see :meth:`ArcLengthContinuation.step_along`)."""

    tangent: np.ndarray            # the (scaled, unit) tangent of the last try
    h: float                       # the step reached
    h_first: float                 # the step it started from
    accepted: bool = False
    point: np.ndarray | None = None          # the accepted point (scaled)
    iterations: int = 0
    next_tangent: np.ndarray | None = None   # the tangent there, if known (scaled)
    hopped: bool = False
    # (h, iterates) of every corrector that did not converge, largest h first; a converged one
    # rejected as off the tangent adds (h, (point,)) while fewer than 4 are recorded
    cycles: list = field(default_factory=list)
    corner: tuple | None = None    # (point, iterations, h): the first converged corrector rejected as off the tangent


class ArcLengthContinuation:
    """One run of :func:`continuation` (which validates the options and calls :meth:`run`), its
    steps as methods. Unknowns are scaled by ``x_scale`` (which grows to the largest |x| met on
    the branch, so the arc length weighs every unknown by its own size) and omega by the
    range's width: ``y = (x / x_scale, omega / w_scale)``."""

    def __init__(self, fun, x0, omega_start, omega_end, x_scale, residual_scale, step, max_step, min_step,
                 max_points, tol, max_corrector, target_iterations, factorize, stop_when=None, chord=False,
                 budget=None):
        self.fun, self.factorize, self.stop_when, self.chord = fun, factorize, stop_when, chord
        self.budget = budget
        self.omega_start, self.omega_end = omega_start, omega_end
        self.step, self.max_step, self.min_step, self.max_points = step, max_step, min_step, max_points
        self.tol, self.max_corrector, self.target_iterations = tol, max_corrector, target_iterations
        self.x0 = x0
        self.direction = np.sign(omega_end - omega_start)
        self.w_scale = abs(omega_end - omega_start)
        if x_scale is None:
            x_scale = max(np.abs(x0).max(), 1e-300)
        self.x_scale = np.broadcast_to(np.asarray(x_scale, dtype=float), x0.shape).copy()
        if residual_scale is None:
            residual_scale = max(np.linalg.norm(fun(np.zeros_like(x0), omega_start)[0]), 1e-300)
        self.residual_scale = residual_scale
        self.n = x0.size
        self.max_dw = max_step * self.w_scale          # the longest step in omega (item 2 of issue 12)
        self.points, self.its = [], []
        self._omegas = []          # omega of points[:len(_omegas)] (see point_omegas)
        self.stopped_by = ""       # what stop_when said when it ended the branch
        # Orientation of the branch (Allgower & Georg): the sense of the tangent t keeps the sign of
        # det [dR/dy; t^T], which changes at no fold and no corner of a piecewise-smooth branch.
        # "t . previous tangent > 0" picks the wrong sense once the branch turns by more than 90
        # degrees (scaled) between two points: the branch then retraces itself, and a
        # corner the corrector cannot pass (below) may leave at any angle. With t solving
        # [dR/dy; r^T] t = e (r . t = 1), det [dR/dy; t^T] = det [dR/dy; r^T] |t|^2: the sign comes
        # from the bordered matrix already factorised (dense only; 0, not used, otherwise).
        # The sign also changes at a bifurcation off the branch (e.g. symmetry breaking at EO = n/2,
        # where the mirror-odd damper DOFs are at zero with almost no stiffness, and their noise
        # flipped it at every step: the branch went back and forth between two points). So a
        # reversal the sign asks for on a tangent that has hardly turned (within 18 degrees of the
        # previous one; the bifurcation's flips turn it by a few degrees, folds and corners by
        # 75-90 degrees) is not taken, and the sign is re-recorded instead.
        self.orientation = 0
        self.stall_guard = _STALL_GUARD.get()
        self._scale = (None, None)      # (x_scale, scale()) of the last x_scale asked for
        self._e_last = _unit_last(self.n)

    # ----- the scaled problem ------------------------------------------------------------
    def scale(self):
        """(x_scale, w_scale) (n + 1,), rebuilt only when x_scale is replaced (new array)."""
        if self._scale[0] is not self.x_scale:
            self._scale = (self.x_scale, np.append(self.x_scale, self.w_scale))
        return self._scale[1]

    def scaled_system(self, y, row):
        """Scaled residual and the bordered scaled Jacobian [[dR/dy, dR/dw]; row]."""
        n = self.n
        x, w = y[:n] * self.x_scale, y[n] * self.w_scale
        R, J, Rw = self.fun(x, w)
        return R / self.residual_scale, bordered_matrix(J, Rw * self.w_scale, row, self.x_scale, 1.0 / self.residual_scale)

    def solve_at(self, w, x_from):
        """Newton at fixed omega = w from the point(s) x_from (tried in turn)."""
        for x in x_from:
            r = newton(self.fun, x, w, self.x_scale, self.residual_scale, tol=self.tol, factorize=self.factorize)
            if r.converged:
                return r
        return None

    # ----- tangents ----------------------------------------------------------------------
    def oriented(self, t, sign, reference, corner=False):
        """t (solving [dR/dy; r^T] t = e_{n+1}, r = ``reference``) normalised, in the sense of
        the branch orientation (recorded from the start sense); ``corner``: at a corner the
        corrector could not pass, where the sign is taken whatever the angle."""
        t = t / euclidean(t)
        if sign == 0:
            return t
        if self.orientation == 0 or (sign != self.orientation and not corner
                                     and t @ reference > 0.95 * euclidean(reference)):
            self.orientation = sign
            return t
        return t * sign * self.orientation

    def bordered_tangent(self, y, row):
        """(t, sign of det) solving [dR/dy; row^T] t = e_{n+1} at y (scaled, unnormalised), the
        bordered matrix factorised once; None if it is singular or t is not finite."""
        try:
            A = self.scaled_system(y, row)[1]
            solve = self.factorize(A)
            t = solve(self._e_last.copy())
        except (np.linalg.LinAlgError, RuntimeError):   # singular (RuntimeError: splu)
            return None
        return (t, _det_sign(A, solve)) if np.all(np.isfinite(t)) else None

    def tangent_at(self, y, prev):
        """The oriented unit tangent at y (scaled); ``prev``: the previous tangent (unscaled) or None."""
        n = self.n
        if prev is None:
            prev = np.zeros(n + 1)
            prev[n] = self.direction
        else:
            prev = prev / self.scale()
            prev /= euclidean(prev)
        A = self.scaled_system(y, prev)[1]
        solve = self.factorize(A)        # a singular matrix raises here, as the callers expect
        return self.oriented(solve(self._e_last.copy()), _det_sign(A, solve), prev)

    # ----- the predictor-corrector -------------------------------------------------------
    def corrector(self, y, tangent, h):
        """Newton on the hyperplane through the predictor y + h tangent, normal to the tangent.
        Returns (converged, point, iterations, bordered solve, bordered matrix, previous iterate)."""
        yp = y + h * tangent
        yc = yp.copy()
        ok = False
        step_norm = np.inf
        previous_iterate = yc
        bordered = A = None
        fresh = True         # this iteration evaluates and factorises the Jacobian (always without chord)
        for it in range(1, self.max_corrector + 1):
            if fresh:
                R, A = self.scaled_system(yc, tangent)
            else:
                R = self.fun(yc[:self.n] * self.x_scale, yc[self.n] * self.w_scale, False)[0] / self.residual_scale
            if not np.all(np.isfinite(R)):
                break
            G = np.empty(self.n + 1)
            G[:self.n] = R
            G[self.n] = tangent @ (yc - yp)
            if fresh:
                try:
                    bordered = self.factorize(A)
                except (np.linalg.LinAlgError, RuntimeError):   # singular (RuntimeError: splu)
                    break
            dy = -bordered(G)
            previous_iterate, yc = yc, yc + dy
            previous_norm, step_norm = step_norm, euclidean(dy)
            # converged: residual at the noise level and the update computed there small
            if euclidean(R) < self.tol and step_norm < np.sqrt(self.tol):
                ok = True
                break
            if not fresh:
                # a chord step: a Jacobian of an earlier iterate. Where it did not contract, the
                # step is undone and the Jacobian renewed; where it contracted slowly, renewed
                if step_norm >= previous_norm:
                    yc, step_norm, fresh = previous_iterate, previous_norm, True
                else:
                    fresh = step_norm > CHORD_CONTRACTION * previous_norm
                continue
            if step_norm >= previous_norm:
                # Newton updates that do not contract: the corrector diverges or cycles
                # (such runs go on to |omega| of hundreds of Hz); halve the step
                break
            fresh = not self.chord
        return ok, yc, it, bordered, A, previous_iterate

    def step_along(self, y, tangent, h):
        """Steps from y along ``tangent``, halved down to min_step, then once more along the
        tangent of the adjacent piece where the corrector ended in a Newton 2-cycle
        (:meth:`turn_at_cycle`). Returns an :class:`_Attempt`."""
        n = self.n
        attempt = _Attempt(tangent, h, h)
        cycle, turned, old_tangent = (), False, tangent
        while True:
            while h >= self.min_step:
                ok, yc, it, bordered, A, previous_iterate = self.corrector(y, tangent, h)
                # reject corrector results that jump back along the branch, that end farther from
                # the predictor than the predictor is from the last point (more than 45 degrees off
                # the tangent: another branch), or that step farther in omega than max_step allows
                forward = ok and (yc - y) @ tangent > 0 and abs(yc[n] - y[n]) * self.w_scale <= self.max_dw
                if forward and euclidean(yc - (y + h * tangent)) <= h:
                    attempt.accepted, attempt.point, attempt.iterations = True, yc, it
                    # the next tangent solves [J; tangent] t = e_{n+1}: the matrix just factorised
                    # at the converged point (to the last update), so it costs one back-substitution
                    attempt.next_tangent = self.oriented(bordered(self._e_last.copy()),
                                                         _det_sign(A, bordered), tangent)
                    break
                if forward and attempt.corner is None:
                    attempt.corner = (yc, it, h)     # a last resort, see past_corner
                if not ok:
                    cycle = (previous_iterate, yc)
                    attempt.cycles.append((h, cycle))
                elif len(attempt.cycles) < 4:
                    attempt.cycles.append((h, (yc,)))      # converged, rejected: its chord is a direction to try
                h /= 2
            if attempt.accepted or turned or self.orientation == 0:
                break
            turned, old_tangent = True, tangent
            tangent = self.turn_at_cycle(tangent, cycle)
            if tangent is old_tangent:
                break
            h = attempt.h_first
        attempt.h = h
        attempt.tangent = tangent if attempt.accepted or not turned else old_tangent
        return attempt

    def turn_at_cycle(self, tangent, cycle):
        """The tangent of the piece the corrector's last 2-cycle ``cycle`` lies on (oriented as
        the branch), or ``tangent`` itself if none differs from it.

        Corner of a piecewise-smooth branch the corrector cannot pass along the tangent of the
        piece it leaves: its last iterates (a Newton 2-cycle) lie on the adjacent piece.
        Continue along that piece's tangent, oriented as the branch (det rule, see __init__):
        it may leave the corner at any angle, beyond 90 degrees at a non-smooth fold, where no
        point exists on the hyperplane of the old tangent nor at a fixed omega beyond; the
        corrector along the adjacent piece converges quadratically where the old one cycles at
        every step."""
        for z in cycle:
            found = self.bordered_tangent(z, tangent)
            if found is None or found[1] == 0:
                continue
            t_z = self.oriented(found[0], found[1], tangent, corner=True)
            if t_z @ tangent < 0.999:
                return t_z
        return tangent

    # ----- past corners ------------------------------------------------------------------
    def hop(self, attempt):
        """Corner of a piecewise-smooth branch (e.g. birth of a slip phase): the corrector
        cycles between the two pieces at any step size; hop over it at fixed omega. On success
        fills ``attempt`` (accepted, hopped; its tangent the new piece's, or None)."""
        n = self.n
        last = self.points[-1]
        w_last = last[n]
        saved_orientation = self.orientation      # a rejected hop tangent must not re-orient the branch
        for frac in (1e-3, 1e-2, 1e-1):
            w_try = w_last + self.direction * frac * self.max_dw
            jump = newton(self.fun, last[:n], w_try, self.x_scale, self.residual_scale, tol=self.tol,
                          factorize=self.factorize)
            if not jump.converged:
                continue
            # only a hop along the same branch, never a jump to another one: short, or along
            # the branch that leaves the corner (the chord within ~25 degrees of the tangent
            # at the point reached). The second covers a corner beyond which an unknown with
            # a small scale moves fast, e.g. the mean roll of a cylinder damper held only by
            # the weak static retention once slip begins (the chord is then long in scaled
            # units, yet it runs along the new piece of the branch)
            chord = np.append(jump.x - last[:n], w_try - w_last) / self.scale()
            if np.linalg.norm(chord[:n]) < 2 * self.max_step:
                hop_tangent = None
                break
            try:
                hop_tangent = self.tangent_at(np.append(jump.x, w_try) / self.scale(), chord * self.scale())
            except (np.linalg.LinAlgError, RuntimeError):
                continue
            if hop_tangent @ chord > 0.9 * np.linalg.norm(chord):
                break
            self.orientation = saved_orientation
        else:
            return
        attempt.point = np.append(jump.x, w_try) / self.scale()
        attempt.iterations = jump.iterations
        attempt.accepted = attempt.hopped = True
        attempt.next_tangent = None
        attempt.tangent = hop_tangent    # go on along the new piece (scaled), or None

    def past_corner(self, y, attempt):
        """The old paths (shorter steps, the turn at a 2-cycle, the hop) all failed: accept the
        first converged corrector point rejected as off the tangent (``attempt.corner``) if the
        chord to it runs along its own branch (:meth:`corner_tangent`)."""
        if attempt.corner is None:
            return
        t_corner = self.corner_tangent(y, attempt.corner[0], attempt.corner[2])
        if t_corner is not None:
            attempt.point, attempt.iterations = attempt.corner[0], attempt.corner[1]
            attempt.next_tangent, attempt.accepted = t_corner, True

    def corner_tangent(self, y, yc, h):
        """The oriented tangent at ``yc`` if ``yc`` (a converged corrector point more than 45
        degrees off the predictor's tangent) lies past a corner on the piece of the branch that
        leaves ``y``, else None.

        At a corner of a piecewise-smooth branch (a stick-slip transition, a contact opening)
        the corrector converges on the adjacent piece at a distance proportional to the step:
        no step, however short, passes the 45-degree test. The point is
        accepted when the chord from ``y`` runs along the branch through ``yc`` (within 25
        degrees of its tangent, which excludes a jump to another branch crossing the
        hyperplane) and stays short (at most 10 steps and 2 max_step)."""
        chord = yc - y
        length = np.linalg.norm(chord)
        if not (0 < length <= min(10 * h, 2 * self.max_step)):
            return None
        chord = chord / length
        found = self.bordered_tangent(yc, chord)
        if found is None:
            return None
        t_z, sign = found
        if sign == 0:                       # sparse: no orientation, the chord gives the sense
            t_z = np.sign(t_z @ chord) * t_z / np.linalg.norm(t_z)
        else:
            t_z = self.oriented(t_z, sign, chord, corner=True)
        return t_z if t_z @ chord > 0.9 else None

    def sphere_solution(self, y, v, radius):
        """Newton on R = 0, |y_c - y| = radius from y + radius v (scaled); (point, iterations) or None."""
        yc = y + radius * v
        for it in range(1, self.max_corrector + 1):
            d = yc - y
            R, A = self.scaled_system(yc, 2 * d / radius)     # bordered by the row of (|d|^2 - radius^2) / radius
            if not np.all(np.isfinite(R)):
                return None
            G = np.append(R, (d @ d - radius ** 2) / radius)
            try:
                dy = -self.factorize(A)(G)
            except (np.linalg.LinAlgError, RuntimeError):
                return None
            yc = yc + dy
            if np.linalg.norm(R) < self.tol and np.linalg.norm(dy) < np.sqrt(self.tol):
                return yc, it
        return None

    def corner_escape(self, y, tangent, cycles, h_first):
        """The branch's next point past a sharp corner or a non-smooth fold at ``y``, found on a
        sphere around ``y``: (point, next tangent (scaled), iterations) or None.

        Where the branch turns by more than 90 degrees at a corner, the hyperplane corrector
        finds no point near its predictor at any step (the residual there is proportional to
        the step: a Newton 2-cycle at every step), and the tangents of its 2-cycle iterates at
        the smallest steps are those of the point itself. On a sphere of radius r around ``y``
        the branch has two points, the one it came from (direction -tangent) and the one it
        leaves by (possibly more than 90 degrees off the tangent, omega turning back). Newton on
        the sphere from the directions of the cycles' tangents (both senses, largest steps
        first) finds it; the one leaving (not within 60 degrees of -tangent) and turning least
        is taken, and the orientation is re-recorded on the new piece (the branch has one only
        where the factorisation gives det signs: dense, or
        :class:`~bladedamp.hbm.linsolve.BlockRing`)."""
        n = self.n
        directions = [tangent]
        for _, iterates in cycles[:4]:
            for z in iterates:
                found = self.bordered_tangent(z, tangent)
                if found is None:
                    continue
                t_z = found[0] / np.linalg.norm(found[0])
                directions += [t_z, -t_z]
                chord = z - y
                if np.linalg.norm(chord) > 0:
                    directions.append(chord / np.linalg.norm(chord))
        best = None
        r0 = max(h_first, min(self.step, 1e-3))
        for radius in (r0, 0.1 * r0, 0.01 * r0):
            for v in directions:
                found = self.sphere_solution(y, v, radius)
                if found is None:
                    continue
                yc, it = found
                d = (yc - y) / np.linalg.norm(yc - y)
                if d @ tangent < -0.5 or abs(yc[n] - y[n]) * self.w_scale > self.max_dw:
                    continue          # the piece it came from, or too long a step
                if best is None or d @ tangent > best[1] @ tangent:
                    best = (yc, d, it)
            if best is not None:
                break
        if best is None:
            return None
        yc, d, it = best
        found = self.bordered_tangent(yc, d)
        if found is None:
            return None
        t, sign = found                 # d . t = 1 > 0: t points along d
        self.orientation = sign or self.orientation
        return yc, t / np.linalg.norm(t), it

    def point_omegas(self) -> list:
        """omega of every point kept so far [rad/s], in order: read once per point (the list grows
        with ``points``; gathering it afresh at every step made the retrace guard quadratic in the
        points: 0.3 ms per point at 500 points)."""
        known, n = self._omegas, self.n
        if len(known) < len(self.points):
            known.extend(float(p[n]) for p in self.points[len(known):])
        return known

    def retraced(self, new, h):
        """Index of an earlier point (not among the last 5) that ``new`` comes back to, within
        1 % of the step ``h`` (scaled), or None. An FRF branch never passes through one of its
        own points again; one that does is going back and forth past a non-smooth fold. The
        caller stops after MAX_REVISITS returns (a corner may send a branch back over a
        few points before it passes)."""
        n, points = self.n, self.points
        if len(points) < 6:
            return None
        radius = 1e-2 * h
        w = np.array(self.point_omegas()[:-5])
        near = np.flatnonzero(np.abs(w - new[n]) < radius * self.w_scale)   # |d omega| bounds the distance
        if near.size == 0:
            return None
        d = np.linalg.norm((np.array([points[j] for j in near]) - new) / self.scale(), axis=1)
        k = int(np.argmin(d))
        return int(near[k]) if d[k] < radius else None

    # ----- the ends of the range ---------------------------------------------------------
    def land_at_start(self, new):
        """The branch turned back and reached the start of the range: it stops there (never a
        point outside the range; an FRF never runs to zero or negative frequency). Returns the
        message: a turn back at a fold (a second solution at the start), or a retrace if the
        point reached there is the branch's first."""
        n, points, omega_start, direction = self.n, self.points, self.omega_start, self.direction
        last = points[-1]
        a = (last[n] - omega_start) / (last[n] - new[n])
        land = self.solve_at(omega_start, (last[:n] + a * (new[:n] - last[:n]), last[:n], new[:n]))
        if land is not None:
            points.append(np.append(land.x, omega_start))
            self.its.append(land.iterations)
            # back on its own first point (within the Newton's resolution, 10 sqrt(tol) scaled):
            # the branch reversed onto itself, there is no second solution at the start (random
            # disk 127: 1.5e-13 after a reversal at 89.0 Hz, past a fold at 89.9 Hz)
            if np.linalg.norm((land.x - points[0][:n]) / self.x_scale) < 10 * np.sqrt(self.tol):
                return f"continuation retraced its own path back to the start of the range, omega = " \
                       f"{omega_start:.6g} rad/s, where it came back to its first point (it reversed onto itself " \
                       f"after getting up to omega = {max(p[n] * direction for p in points) * direction:.6g} rad/s: " \
                       f"not a second solution); branch kept up to there"
        return f"continuation turned back (fold at omega = {max(p[n] * direction for p in points) * direction:.6g}" \
               f" rad/s) and returned to the start of the range, omega = {omega_start:.6g} rad/s; " \
               f"branch kept up to there"

    def land_at_end(self, new):
        """Land exactly on omega_end, from the point interpolated there; True if it did."""
        n, omega_end = self.n, self.omega_end
        last = self.points[-1]
        a = (omega_end - last[n]) / (new[n] - last[n]) if new[n] != last[n] else 1.0
        land = self.solve_at(omega_end, (last[:n] + a * (new[:n] - last[:n]), new[:n], last[:n]))
        if land is None:
            return False
        self.points.append(np.append(land.x, omega_end))
        self.its.append(land.iterations)
        return True

    def finish(self, success, message, out_of_points: int = 0):
        n = self.n
        Y = np.array(self.points) if self.points else np.zeros((0, n + 1))
        checks = branch_checks(Y[:, n], self.omega_start, self.omega_end, self.max_step)
        if success and not all(checks.values()):
            success = False
            message += "; branch checks failed: " + ", ".join(k for k, v in checks.items() if not v)
            _warn(message, 4)
        # turning points: where omega stops growing along the branch and turns back
        d = np.sign(np.diff(Y[:, n]))
        turning = np.flatnonzero(d[1:] * d[:-1] < 0) + 1
        return Branch(Y[:, n], Y[:, :n], np.array(self.its, dtype=int), success, message, turning, checks,
                      self.stopped_by, out_of_points)

    def stop_event(self, at_end: bool = False) -> str:
        """``stop_when`` at the last point kept, then the budget (which it charges one point; it
        does not stop the point at the end of the range, ``at_end``); '' if neither stops the
        branch. Records it as ``stopped_by``."""
        if not self.points:
            return ""
        last = self.points[-1]
        if self.stop_when is not None:
            self.stopped_by = str(self.stop_when(last[:self.n].copy(), float(last[self.n])) or "")
        if not self.stopped_by and self.budget is not None:
            spent = self.budget.spend(float(last[self.n]))
            self.stopped_by = "" if at_end else spent
        return self.stopped_by

    # ----- the run -----------------------------------------------------------------------
    def run(self) -> Branch:
        n = self.n
        ran_out = self.budget.exhausted(self.omega_start) if self.budget is not None else ""
        if ran_out:
            self.stopped_by = ran_out
            return self.finish(False, f"not started at omega = {self.omega_start:.6g} rad/s: {ran_out}")
        first = newton(self.fun, self.x0, self.omega_start, self.x_scale, self.residual_scale, tol=self.tol,
                       factorize=self.factorize)
        if not first.converged:
            msg = f"Newton did not converge at the start, omega = {self.omega_start:.6g} rad/s " \
                  f"(scaled residual {first.residual_norm:.3g})"
            _warn(msg, 3)
            return self.finish(False, msg)
        points = self.points
        points.append(np.append(first.x, self.omega_start))
        self.its.append(first.iterations)
        if self.stop_event():
            return self.finish(False, f"stopped at the start, omega = {self.omega_start:.6g} rad/s: {self.stopped_by}")
        tangent_prev = None  # in unscaled units
        message, success = "", False
        h = self.step
        hops = 0  # consecutive fixed-omega hops over corners
        revisits = 0  # returns to an earlier point (see retraced)
        furthest, furthest_at = 0.0, 0  # progress into the range (scaled) and the point that made it (stall_guard)
        end_retries = 0  # steps past omega_end whose landing on omega_end failed
        next_tangent = None  # from the last corrector's factorisation (scaled, then unscaled)
        while len(points) < self.max_points:
            y = points[-1] / self.scale()
            if next_tangent is None:
                tangent = self.tangent_at(y, tangent_prev)
            else:
                tangent = next_tangent / self.scale()      # unscaled -> scaled by the current x_scale
                tangent /= euclidean(tangent)
            attempt = self.step_along(y, tangent, h)
            h, tangent, next_tangent = attempt.h, attempt.tangent, attempt.next_tangent
            if not attempt.accepted and h < self.step and hops < 5:
                hops += 1
                self.hop(attempt)
                if attempt.accepted:
                    tangent, next_tangent = attempt.tangent, None
            else:
                hops = 0 if attempt.accepted else hops
            if not attempt.accepted:
                self.past_corner(y, attempt)
                if attempt.accepted:
                    next_tangent, hops = attempt.next_tangent, 0
            if not attempt.accepted and self.orientation != 0:
                escaped = self.corner_escape(y, tangent, attempt.cycles, attempt.h_first)
                if escaped is not None:
                    attempt.point, next_tangent, attempt.iterations = escaped
                    attempt.accepted, hops = True, 0
            if not attempt.accepted:
                w_stop = points[-1][n]
                message = f"continuation did not converge after omega = {w_stop:.6g} rad/s " \
                          f"({w_stop / (2 * np.pi):.6g} Hz), step fell below {self.min_step:g}; branch kept up to there"
                _warn(message, 3)
                break
            yc, it = attempt.point, attempt.iterations
            new = yc * self.scale()
            if self.direction * (self.omega_start - new[n]) > 0:
                message = self.land_at_start(new)
                _warn(message, 3)
                break
            if self.direction * (new[n] - self.omega_end) >= 0:
                if not self.land_at_end(new):
                    end_retries += 1
                    if end_retries <= 8:
                        h /= 2
                        tangent_prev = None if tangent is None else tangent * self.scale()
                        next_tangent = None
                        continue
                    message = f"continuation could not land on omega_end = {self.omega_end:.6g} rad/s; " \
                              f"branch kept up to omega = {points[-1][n]:.6g} rad/s"
                    _warn(message, 3)
                    break
                success, message = True, "reached the end of the frequency range"
                if self.stop_event(at_end=True):
                    success, message = False, f"stopped at omega_end = {self.omega_end:.6g} rad/s: {self.stopped_by}"
                break
            tangent_prev = None if tangent is None else tangent * self.scale()
            next_tangent = None if next_tangent is None else next_tangent * self.scale()
            h = max(h, self.step) if attempt.hopped else h
            revisited = self.retraced(new, h)
            points.append(new)
            self.its.append(it)
            if self.stop_event():
                message = f"stopped at omega = {new[n]:.6g} rad/s ({new[n] / (2 * np.pi):.6g} Hz): {self.stopped_by}"
                break
            if revisited is not None:
                revisits += 1
                if revisits >= MAX_REVISITS:
                    message = f"continuation retraced its own path at omega = {new[n]:.6g} rad/s " \
                              f"({new[n] / (2 * np.pi):.6g} Hz; {revisits} returns to earlier points, the last to point " \
                              f"{revisited} of {len(points)}: a loop or a back-and-forth between corners it cannot " \
                              f"leave); branch kept up to there"
                    _warn(message, 3)
                    break
            if self.stall_guard:
                progress = self.direction * (new[n] - self.omega_start) / self.w_scale
                if progress > furthest + STALL_PROGRESS:
                    furthest, furthest_at = progress, len(points) - 1
                elif len(points) - 1 - furthest_at >= STALL_POINTS:
                    w_far = self.omega_start + self.direction * furthest * self.w_scale
                    message = f"continuation stalled at omega = {new[n]:.6g} rad/s ({new[n] / (2 * np.pi):.6g} Hz): " \
                              f"its last {STALL_POINTS} points got no further than {STALL_PROGRESS:g} of the range " \
                              f"beyond omega = {w_far:.6g} rad/s ({w_far / (2 * np.pi):.6g} Hz); branch kept up to there"
                    _warn(message, 3)
                    break
            self.x_scale = np.maximum(self.x_scale, np.abs(points[-1][:n]))
            if it <= self.target_iterations - 1:
                h = min(h * 1.5, self.max_step)
            elif it > self.target_iterations + 1:
                h = max(h / 1.5, self.min_step)
        else:
            message = f"stopped after max_points = {self.max_points} points at omega = {points[-1][n]:.6g} rad/s"
            _warn(message, 3)
            return self.finish(success, message, self.max_points)
        return self.finish(success, message)
