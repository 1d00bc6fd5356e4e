"""Harmonic accuracy control: how far a harmonic balance answer is from its converged limit.

The HBM truncates the Fourier series of the response. With friction and a varying normal load
(lift-off, the wedge's inclined contacts) the nonlinear forces are not smooth, their spectrum
decays slowly, and the paper's one-harmonic setting can miss the first-harmonic amplitude by
tens of per cent while the energy balance still holds to rounding (it holds for any truncation).
So every answer is checked against an enriched harmonic set:

* **estimate** (:func:`harmonic_error`): at a few points of a computed branch (the peak and
  points spread along it) the solution is lifted into the enriched set ``H+`` (the static term
  and the next two harmonics added) and solved again at the same frequency by Newton (and, where
  the plain Newton does not converge, by the damped Newton with a line search of the robust
  start, which converges at peak points the plain Newton cannot solve (benchmarks/README.md,
  'Moved from the package's docstrings', accuracy.py); where neither converges, once more with
  :data:`ENRICHED_SAMPLES_GROWTH` x the AFT samples). The
  largest change of the first-harmonic output amplitudes (the blade tips, the oscillator's x),
  relative to the branch's peak amplitude, is the error estimate of ``H``. It is an
  a-posteriori estimate of the truncation error, not a bound: the first-harmonic amplitude of a
  non-smooth system converges in steps that need not shrink monotonically.
* **choice** (:func:`converged_response`): ``harmonics="auto"`` computes the branch with the
  sets of :data:`AUTO_HARMONIC_SETS` in turn, each checked against the next richer one, and keeps
  the first whose estimate meets the tolerance. The static term is in every set: it carries the
  mean normal loads, which move when the normal loads vary (lift-off, inclined contacts).
  When no set meets the tolerance, the richest is returned and says so (``harmonics_converged``
  False, and the message).
* **prediction** (:func:`predicted_set`, the tuned disk's choice): after a complete branch above
  the tolerance, the richer sets are first solved at its checked points only, each lifted from
  the last one's solutions there, and the sets whose points change by more than the tolerance
  are not computed as branches; the first set without such a point is, and decides as above.

A model takes part by giving ``hbm_system(harmonics, n_samples)``, ``output_amplitudes
(coefficients, basis) -> (n, k)``, ``static_state(system, omega) -> x`` (rest, or the dampers
seated under F_CG: the static term of a lifted solution whose set had none) and
``unknown_scales(system, omega_start, omega_end)``.
"""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np

from ..response import BUDGET_PREFIX, Note, NoteKind, harmonic_sentence, with_note
from .continuation import newton, stall_guard
from .fourier import HarmonicBasis, enriched
from .linsolve import one_blas_thread
from .start import START_LINE_SEARCH

#: default tolerance on the first-harmonic output amplitudes, relative to the peak amplitude
HARMONIC_TOLERANCE = 0.01
#: the harmonic sets ``harmonics="auto"`` may try, cheapest first (see :func:`auto_sets`)
AUTO_HARMONIC_SETS = ((0, 1), (0, 1, 2, 3), (0, 1, 2, 3, 4, 5), tuple(range(8)), tuple(range(10)))
#: AFT samples of the enriched set's second try at a point where its Newton fails, per sample
#: of the first (see :func:`harmonic_error`)
ENRICHED_SAMPLES_GROWTH = 4
#: the paper's setting: the first harmonic only, static approach from frictionless seating
PAPER_HARMONICS = (1,)


def auto_sets(max_harmonic: int) -> tuple[tuple[int, ...], ...]:
    """The sets of :data:`AUTO_HARMONIC_SETS` up to ``max_harmonic`` (an odd integer >= 1)."""
    if not (isinstance(max_harmonic, (int, np.integer)) and max_harmonic >= 1):
        raise ValueError(f"max_harmonic must be an integer >= 1 (got {max_harmonic!r})")
    return tuple(s for s in AUTO_HARMONIC_SETS if max(s) <= max_harmonic)


class AccuracyWarning(UserWarning):
    """A harmonic balance answer whose harmonic error estimate exceeds the tolerance."""


@dataclass
class HarmonicCheck:
    """Result of checking a branch against an enriched harmonic set.

    Attributes
    ----------
    harmonics : the branch's harmonics
    enriched : the set it was checked against
    error : largest |change of a first-harmonic output amplitude| / peak amplitude over the
        checked points (nan when no point could be checked)
    omega : (k,) frequencies of the checked points [rad/s]
    errors : (k,) the same measure at each point (nan where the enriched solve failed)
    index : (k,) indices of the checked points on the branch
    """

    harmonics: tuple
    enriched: tuple
    error: float
    omega: np.ndarray
    errors: np.ndarray
    index: np.ndarray

    @property
    def verified(self) -> bool:
        """Whether the peak point (the first checked) was solved in the enriched set."""
        return bool(self.errors.size and np.isfinite(self.errors[0]))


def check_points(amplitude: np.ndarray, turning_points=(), n_points: int = 5) -> np.ndarray:
    """Indices to check: the peak of ``amplitude`` (n,) first, then points spread along the
    branch, away from its turning points (where a fixed-frequency Newton is ill-posed)."""
    n = len(amplitude)
    if n == 0:
        return np.zeros(0, dtype=int)
    peak = int(np.argmax(amplitude))
    near_fold = np.zeros(n, dtype=bool)
    for t in np.asarray(turning_points, dtype=int):
        near_fold[max(t - 2, 0):t + 3] = True
    spread = np.unique(np.linspace(0, n - 1, n_points + 1).round().astype(int)[1:])
    others = [int(i) for i in spread if i != peak and not near_fold[i]]
    return np.array([peak] + others[:n_points - 1], dtype=int)


def lift(model, coefficients: np.ndarray, basis, system, omega: float) -> np.ndarray:
    """A solution (C, n_dof) of ``basis`` as the initial guess in ``system``'s basis: the same
    harmonics (:meth:`HarmonicBasis.embed`); a static term ``basis`` lacks from the model's
    ``static_state`` (e.g. the damper seated under F_CG, Eq. 26)."""
    X = basis.embed(coefficients, system.basis)
    if system.basis.has_static and not basis.has_static:
        j0 = system.basis.cos_index(0)
        X[j0] = model.static_state(system, omega).reshape(system.basis.n_coeffs, system.n_dof)[j0]
    return X.ravel()


def enriched_solution(model, coefficients, basis, system, omega, scales, tol):
    """The solution (C', n_dof) of the enriched ``system`` at ``omega`` [rad/s] from
    ``coefficients`` (C, n_dof) of ``basis`` lifted into it, or None if neither the plain nor the
    damped Newton converges."""
    x0 = lift(model, coefficients, basis, system, omega)
    rs = max(np.linalg.norm(system.residual(np.zeros_like(x0), omega, False)[0]), 1e-300)
    sol = newton(system.residual, x0, omega, scales, rs, tol=tol, max_iter=20, factorize=system.factorize)
    x, converged = sol.x, sol.converged
    if not converged:               # the plain Newton overshoots on a corner of the force map
        sol = newton(system.residual, x0, omega, scales, rs, tol=tol, max_iter=60, factorize=system.factorize,
                     line_search=START_LINE_SEARCH)
        x, converged = sol.x, sol.converged
    if not converged:
        return None
    return x.reshape(system.basis.n_coeffs, -1)


class EnrichedSet:
    """Point solves of ``model`` in the harmonic set ``target`` (at least ``n_samples`` AFT
    samples, the unknowns scaled over ``omega_range`` [rad/s]), each lifted from a solution of a
    poorer set: :meth:`solve` (the one solver of the estimate and of the prediction)."""

    def __init__(self, model, target, n_samples: int, omega_range, tol: float):
        self.model, self.target, self.tol = model, tuple(target), tol
        self.n_samples = max(HarmonicBasis(self.target).n_samples, int(n_samples))
        self.system = model.hbm_system(self.target, self.n_samples)
        self.scales = model.unknown_scales(self.system, *omega_range)
        self.finer = None

    def solve(self, coefficients, basis, omega: float):
        """(solution (C', n_dof), its basis) of the enriched set at ``omega`` [rad/s] from
        ``coefficients`` (C, n_dof) of ``basis``, or None where the Newton fails also with
        :data:`ENRICHED_SAMPLES_GROWTH` x the samples."""
        x = enriched_solution(self.model, coefficients, basis, self.system, omega, self.scales, self.tol)
        if x is not None:
            return x, self.system.basis
        # Newton may fail on the AFT's sampling of a contact event (a lift-off instant between
        # samples), not on the harmonics: once more with ENRICHED_SAMPLES_GROWTH x the samples
        # (the change then includes the branch's own sampling error too)
        if self.finer is None:
            self.finer = self.model.hbm_system(self.target, ENRICHED_SAMPLES_GROWTH * self.n_samples)
        x = enriched_solution(self.model, coefficients, basis, self.finer, omega, self.scales, self.tol)
        return None if x is None else (x, self.finer.basis)

    def amplitudes(self, solved) -> np.ndarray:
        """The first-harmonic output amplitudes (k,) of a :meth:`solve` result."""
        x, basis = solved
        return self.model.output_amplitudes(x[None], basis)[0]


def checked_solutions(model, response, harmonics=None, n_points: int = 5, tol: float = 1e-10):
    """(:class:`HarmonicCheck`, the enriched solutions): :func:`harmonic_error` with, for each
    checked point, the :meth:`EnrichedSet.solve` result (None where it failed)."""
    basis = response.basis
    target = tuple(harmonics) if harmonics is not None else enriched(basis.harmonics)
    amp = model.output_amplitudes(response.coefficients, basis)          # (n, k)
    idx = check_points(amp.max(axis=1) if amp.size else np.zeros(0), response.turning_points, n_points)
    errors = np.full(idx.size, np.nan)
    solutions = [None] * idx.size
    if idx.size:
        # the enriched set with at least the response's AFT samples (the sampling is not the
        # question here: with fewer, a sampling error would pass for a harmonic one)
        w = response.omega
        richer = EnrichedSet(model, target, basis.n_samples, (float(w.min()), float(w.max())), tol)
        peak = max(float(amp.max()), 1e-300)
        for k, i in enumerate(idx):
            solutions[k] = richer.solve(response.coefficients[i], basis, float(w[i]))
            if solutions[k] is not None:
                errors[k] = np.abs(richer.amplitudes(solutions[k]) - amp[i]).max() / peak
    finite = errors[np.isfinite(errors)]
    error = float(finite.max()) if finite.size and np.isfinite(errors[0]) else float("nan")
    return HarmonicCheck(basis.harmonics, target, error, response.omega[idx], errors, idx), solutions


@one_blas_thread
def harmonic_error(model, response, harmonics=None, n_points: int = 5, tol: float = 1e-10) -> HarmonicCheck:
    """Error estimate of ``response`` (computed by ``model``) against the enriched set
    ``harmonics`` (default :func:`enriched` of the response's), see the module docstring."""
    return checked_solutions(model, response, harmonics, n_points, tol)[0]


def predicted_set(model, response, check: HarmonicCheck, solutions, sets, tolerance: float,
                  tol: float = 1e-10) -> int:
    """The index in ``sets`` of the first set the automatic choice computes after ``response``'s
    (the branch of ``sets[i]``; ``check`` its estimate against ``sets[i + 1]`` and ``solutions``
    the enriched points of :func:`checked_solutions`). Instead of whole branches, the richer sets
    are solved at those points only, each lifted from the previous set's solution there
    (:class:`EnrichedSet`): a set is skipped where one of its points changes by more than
    ``tolerance`` (relative to ``response``'s peak amplitude) in the next set, the points whose last
    change was the largest solved first (one such point is enough). The first set without one is
    computed, and its branch and its own estimate decide as for any set. A skipped set would fail
    its own estimate at that frequency, so the prediction can make the answer richer than a
    set-by-set search, not poorer."""
    k = sets.index(tuple(response.basis.harmonics)) + 1
    if k >= len(sets) or tuple(check.enriched) != sets[k]:
        return k                      # solutions of another set than the next: nothing to lift on
    amp = model.output_amplitudes(response.coefficients, response.basis)
    peak = max(float(amp.max()), 1e-300)
    omega_range = (float(response.omega.min()), float(response.omega.max()))
    points = [(float(w), s, e) for w, s, e in zip(check.omega, solutions, check.errors) if s is not None]
    while k < len(sets) - 1 and points:
        richer = EnrichedSet(model, sets[k + 1], max(s[1].n_samples for _, s, _ in points), omega_range, tol)
        changed, solved = False, []
        for w, s, last in sorted(points, key=lambda p: -p[2]):
            solution = richer.solve(s[0], s[1], w)
            if solution is not None:
                e = float(np.abs(richer.amplitudes(solution) - richer.amplitudes(s)).max() / peak)
                solved.append((w, solution, e))
                if e > tolerance:
                    changed = True
                    break
        if not changed:
            return k
        k, points = k + 1, solved
    return k


def annotate(response, check: HarmonicCheck, tolerance: float):
    """``response`` with its harmonic error estimate; the message says when it is above the
    tolerance or could not be checked (``success`` is left as the solver and the sanity checks
    set it: an explicit harmonic set is the user's choice, the estimate tells its cost), and, for
    a complete branch, an AccuracyWarning says it in the sentence its status gives
    (:func:`bladedamp.response.harmonic_sentence`)."""
    met = bool(np.isfinite(check.error) and check.error <= tolerance)
    note = ""
    if not np.isfinite(check.error):
        note = f"harmonic error not verified: the peak point did not converge with harmonics {check.enriched}"
    elif not met:
        note = (f"harmonic error estimate {100 * check.error:.2g} % exceeds the tolerance "
                f"{100 * tolerance:.2g} % (harmonics {check.harmonics} against {check.enriched})")
    if note and response.success:   # the sentence the status gives (bladedamp.response.status_message); a
        # branch that stopped or failed a check is said so by its status, whose advice is not the harmonics
        warnings.warn(harmonic_sentence(check.harmonics, check.error, tolerance, estimated=True), AccuracyWarning,
                      stacklevel=5)   # annotate, converged_response, its BLAS wrapper, the model, the caller
    changes = dict(harmonic_error=check.error, harmonic_tolerance=tolerance, harmonics_converged=met)
    if note:
        return with_note(response, Note(NoteKind.HARMONIC_ESTIMATE, note), **changes)
    return dataclasses.replace(response, **changes)


@one_blas_thread
def converged_response(model, solve, harmonics="auto", tolerance: float = HARMONIC_TOLERANCE,
                       max_harmonic: int = 3, n_points: int = 5, estimate: bool = True, guard_stalls: bool = False,
                       predict: bool = False):
    """The branch of ``solve(harmonics) -> response`` with its harmonic error estimate.

    ``harmonics="auto"``: the sets of :func:`auto_sets` (``max_harmonic``) in turn until one meets
    ``tolerance``; otherwise the given set, checked once. A set whose branch fails (does not reach the end of the range) is
    followed by the next richer one in the automatic choice. Where a budget
    (:class:`~bladedamp.hbm.continuation.Budget`) stops a richer set's branch after a poorer
    set's reached the end, or a stop leaves a richer set without a point, the poorer set's
    branch is returned with its estimate, not ``success``, its ``stopped_by`` the stop's and its
    message naming the set not finished. ``estimate=False`` (a given set
    only): no estimate (``harmonic_error`` NaN, ``harmonics_converged`` None: "not estimated"),
    for a study that estimates it on a representative case instead (the Monte Carlo's first disk).
    ``guard_stalls``: a richer set's branches, once a poorer set's reached the end, are computed
    within :func:`~bladedamp.hbm.continuation.stall_guard` (a stalled branch ends early). Not for
    the oscillator: a lightly damped oscillator's richer branch may reach the end only past a
    stretch the guard ends (benchmarks/README.md, 'Moved from the package's docstrings',
    accuracy.py).
    ``predict`` (the tuned disk's): after a complete branch above the tolerance, the sets whose
    points :func:`predicted_set` finds above it too are not computed (their branches cost about as
    much as the answer's: benchmarks/README.md, 'Automatic harmonics at the cost of the answer');
    where the first branch computed after a skip is not ``success`` (and no stop or budget ended
    it), the skipped sets are computed in turn as without the prediction."""
    if isinstance(harmonics, str):
        if harmonics != "auto":
            raise ValueError(f"harmonics must be 'auto' or a tuple of integers >= 0 (got {harmonics!r})")
        if not estimate:
            raise ValueError("harmonics='auto' chooses the harmonics by their error estimate: it needs "
                             "estimate_harmonic_error=True (or give the harmonics, e.g. (1,))")
        if not (np.isfinite(tolerance) and tolerance > 0):
            raise ValueError(f"harmonic_tolerance must be a finite number > 0 (got {tolerance!r})")
        sets = auto_sets(max_harmonic)
        best, k, skipped, computed = None, 0, None, {}
        while k < len(sets):
            H = sets[k]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", AccuracyWarning)
                guarded = guard_stalls and best is not None and best[0].success
                if (H, guarded) in computed:      # the set a skip went to, computed again after a fallback
                    response = computed[H, guarded]
                elif guarded:
                    # a poorer set's branch reached the end: a stalled branch of this set ends early
                    # (it could change the answer only by reaching the end)
                    with stall_guard():
                        response = solve(tuple(H))
                else:
                    response = solve(tuple(H))
                computed[H, guarded] = response
                ran_out = response.stopped_by.startswith(BUDGET_PREFIX)
                if response.stopped_by and best is not None and (not len(response.omega)
                                                                 or (ran_out and best[0].success)):
                    # stopped before its first point, or a budget that ran out on a richer set's
                    # branch after a poorer set's reached the end: the branch of the poorer set is
                    # kept (a complete branch is never replaced by a partial one), its status
                    # saying the search was stopped
                    kept = annotate(best[0], best[1], tolerance)
                    what = (f"not computed: {response.stopped_by}" if not len(response.omega) else
                            f"stopped before the end of the range: {response.stopped_by}")
                    return with_note(kept, Note(NoteKind.HARMONIC_SEARCH, f"harmonics {tuple(H)} {what}"),
                                     success=False, reached_end=kept.reached_range_end, stopped_by=response.stopped_by)
                if response.stopped_by:
                    return response           # stopped as the caller asked: no estimate, no richer set
                if skipped is not None and not response.success:
                    # the set a skip went to failed: the skipped sets in turn, without prediction
                    k, skipped, predict = skipped, None, False
                    continue
                if best is not None and best[0].success and not response.reached_range_end:
                    # a richer set whose every branch (both ends, retry, finer samples) failed short
                    # of the end where a poorer set's reached it: the richer sets after it are not
                    # tried (they fail the same way, at the same stall, for most of the analysis'
                    # time: benchmarks/README.md, 'Cost of the default FRF on random disks'); the poorer
                    # set's complete branch is the answer, its estimate saying how far it is
                    kept = annotate(best[0], best[1], tolerance)
                    where = (f"its branch got no further than {response.frequency_hz[response.furthest_index()]:.6g} Hz"
                             if len(response.omega) else "its branch kept no point")
                    return with_note(kept, Note(NoteKind.HARMONIC_SEARCH, (
                        f"harmonics {tuple(H)} did not converge to the end of the range ({where}), "
                        f"so no richer set was tried")))
                check, solutions = None, None
                if len(response.omega):
                    if predict:
                        check, solutions = checked_solutions(model, response, n_points=n_points)
                    else:
                        check = harmonic_error(model, response, n_points=n_points)
            k, skipped = k + 1, None
            if check is None:
                continue
            if response.success or best is None or not best[0].success:
                best = (response, check)     # a complete branch is never replaced by a failed one
            if response.success and np.isfinite(check.error) and check.error <= tolerance:
                break
            if predict and response.success and k < len(sets):
                ahead = predicted_set(model, response, check, solutions, sets, tolerance)
                k, skipped = ahead, (k if ahead > k else None)
        if best is None:
            return response
        return annotate(best[0], best[1], tolerance)
    response = solve(tuple(harmonics))
    if not estimate or not len(response.omega) or response.stopped_by:
        return response
    return annotate(response, harmonic_error(model, response, n_points=n_points), tolerance)
