"""Damper mass: the peak tip amplitude as a function of the mass, and its minimum (Fig. 5, 6)."""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from .. import palette, validation
from ..disk import TunedDisk
from ..io import Saveable
from ..plotting import place_legend, plain_log_ticks
from ..progress import progress_callback
from ..response import refined_peak


def with_mass(disk: TunedDisk, mass: float) -> TunedDisk:
    """The same disk with another damper mass [kg]."""
    return dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, mass=mass))


#: max_step of the peak searches' branches: the peak is solved on the branch by the peak condition
#: (:meth:`TunedDisk.solve_peak`), which needs only points bracketing it: 0.1 is the largest step
#: at which the solved peaks of the reference disks stay within 1e-5 of a dense branch's
#: (benchmarks/README.md, 'Moved from the package's docstrings', studies/mass.py). At
#: 0.2 the solve is up to 2e-4 off: the one-harmonic curves are jagged at the
#: 1e-4 level near the peak (a contact point entering slip puts a kink in them), and a bracket
#: that long can miss the highest of the humps.
PEAK_SEARCH_MAX_STEP = 0.1
#: max_step of the branch recomputed where the peak cannot be solved on the first (a fold next to
#: the largest point, or slopes that bracket no maximum): the parabola through its largest point
PEAK_FALLBACK_MAX_STEP = 0.05


def peak_response(disk: TunedDisk, f_range_hz=(90.0, 105.0), harmonics=(1,), max_step=PEAK_SEARCH_MAX_STEP,
                  direction: int = 0, max_widenings: int = 4, **continuation_options):
    """(peak first-harmonic tip amplitude [m], frequency [Hz], response) over ``f_range_hz``.

    ``direction`` is the tip DOF (0..2: u_x, u_y, u_z). If the largest amplitude sits at an end
    of the range, the range is widened by its own width on that side (at most
    ``max_widenings`` times) so that a reported peak is always a true interior maximum.
    The peak is solved on the response curve next to the largest point
    (:meth:`TunedDisk.solve_peak`); where it cannot be, the branch is recomputed at
    ``min(max_step, PEAK_FALLBACK_MAX_STEP)`` and the peak is the parabola through its largest
    point and their neighbours (the returned response is then that branch).
    ``continuation_options`` (e.g. ``max_points``) go to ``disk.frequency_response``.
    Raises RuntimeError if the continuation does not cover the range (never a silent number).
    """
    lo, hi = validation.interval("f_range_hz", f_range_hz, "Hz")

    def interior(max_step):
        nonlocal lo, hi
        for _ in range(max_widenings + 1):
            r = disk.frequency_response(lo, hi, harmonics=harmonics, max_step=max_step, **continuation_options)
            if not r.success:
                raise IncompleteResponse(f"frequency response incomplete: {r.message}", r, direction)
            i = int(np.argmax(r.tip_amplitude[:, direction]))
            if 0 < i < len(r.omega) - 1:
                return r, i
            width = hi - lo
            lo, hi = (max(lo - width, 0.5 * lo), hi) if i == 0 else (lo, hi + width)
        raise RuntimeError(f"no interior resonance peak found up to the range {lo:.4g}-{hi:.4g} Hz")

    r, i = interior(max_step)
    solved = disk.solve_peak(r, i, direction, continuation_options.get("extra_couplings"))
    if solved is not None:
        return solved[0], solved[1], r
    if max_step > PEAK_FALLBACK_MAX_STEP:
        r, i = interior(PEAK_FALLBACK_MAX_STEP)
    peak, f = refined_peak(r.frequency_hz, r.tip_amplitude[:, direction], i)
    return peak, f, r


class IncompleteResponse(RuntimeError):
    """A frequency response whose continuation stopped early; ``response`` keeps the converged
    part of the branch and ``lower_bound`` its largest tip amplitude [m] (every point of it
    is a solution, so the true peak is at least that; NaN if nothing converged)."""

    def __init__(self, message, response=None, direction: int = 0):
        super().__init__(message)
        self.response = response
        self.lower_bound = _lower_bound(response, direction)


def _checks(response) -> set:
    return set(getattr(response, "failed_checks", None) or ())


def _lower_bound(response, direction: int) -> float:
    """Largest tip amplitude of the converged points of a (partial) branch; NaN when it has none
    or when its points fail the dissipation check (then they are no physical solutions)."""
    if response is None or not len(response.frequency_hz) or "dissipation" in _checks(response):
        return np.nan
    return float(response.tip_amplitude[:, direction].max())


def _joinable(response) -> bool:
    """A partial branch whose points cover its frequencies without gaps and are physical."""
    return response is not None and len(response.frequency_hz) > 1 and not (_checks(response) - {"range"})


# -- robust peak: the continuation settings tried, in order, when a frequency response fails --
# Each run is capped at ROBUST_MAX_POINTS points: a complete branch at max_step 0.02 has about
# 600-1100 points on the reference disk, while a continuation trapped in a cycle runs to the
# default 5000 points before failing.
ROBUST_MAX_POINTS = 1500
ROBUST_ATTEMPTS = ({"max_step": PEAK_SEARCH_MAX_STEP}, {"max_step": 0.05}, {"max_step": 0.02})


@dataclass
class PeakEvaluation(Saveable):
    """Peak tip amplitude of one disk found by :func:`robust_peak`.

    success : the peak is the interior maximum of a frequency response that covers the range
    peak_amplitude : [m] (NaN if not success); peak_frequency_hz : [Hz] (NaN if not success)
    lower_bound : [m] if not success, the largest tip amplitude on the converged parts of the
        branches (the true peak is at least this; NaN when no part converged)
    message : how the peak was obtained, or why every attempt failed
    attempts : number of continuation runs
    stopped_above : the branch was stopped once above ``stop_above`` (not a failure: the peak is
        known to exceed that bound, ``lower_bound``)
    """

    success: bool
    peak_amplitude: float
    peak_frequency_hz: float
    lower_bound: float
    message: str
    attempts: int
    stopped_above: bool = False


def peak_search_options(harmonics) -> dict:
    """``TunedDisk.frequency_response`` options of the studies' peak searches: no harmonic error
    estimate of each response (the peak is all a search needs; the studies' harmonic setting is
    reported once, beside the converged one, in ``reproduce``'s harmonic accuracy), unless
    ``harmonics`` is "auto", which chooses by the estimate."""
    return {} if isinstance(harmonics, str) else {"estimate_harmonic_error": False}


def robust_peak(disk: TunedDisk, f_range_hz=(90.0, 105.0), harmonics=(1,), direction: int = 0,
                attempts=ROBUST_ATTEMPTS, max_points: int = ROBUST_MAX_POINTS, downward: bool = True,
                give_up_above: float = np.inf, stop_above: float = np.inf) -> PeakEvaluation:
    """:func:`peak_response` that retries a failed frequency response and never raises on one.

    Tries each settings dict of ``attempts`` (upward sweeps, ``peak_response`` options); if all
    fail, sweeps the range downwards from its upper end (finest ``max_step``) and joins the two
    partial branches: when the upward branch reaches above the frequency where the downward one
    stopped, every frequency of the range has a converged solution and the peak is the largest
    amplitude of both (it must be interior). Otherwise the evaluation fails and carries the
    largest amplitude met, a lower bound of the true peak.

    ``downward=False`` skips the downward sweep. ``give_up_above`` [m]: stop retrying as soon as
    a partial branch has reached above it (a minimiser that already has a lower peak needs no
    more of this mass than that bound). ``stop_above`` [m]: stop each branch itself at the first
    point above it (``TunedDisk.frequency_response(stop_above=...)``); with ``give_up_above`` at
    or below it, such a mass costs only the branch up to that point.
    """
    lo, hi = validation.interval("f_range_hz", f_range_hz, "Hz")
    frf_options = peak_search_options(harmonics)
    if np.isfinite(stop_above):
        frf_options.update(stop_above=float(stop_above), stop_direction=direction)
    messages, bound, up, runs = [], np.nan, None, 0
    for options in attempts:
        runs += 1
        try:
            p, f, _ = peak_response(disk, (lo, hi), harmonics, direction=direction, max_points=max_points,
                                    **frf_options, **options)
            note = "" if runs == 1 else f" (retry {options}; before: {'; '.join(messages)})"
            return PeakEvaluation(True, p, f, np.nan, "interior peak of a complete response" + note, runs)
        except IncompleteResponse as exc:
            messages.append(f"{options}: {exc}")
            bound = np.fmax(bound, exc.lower_bound)
            # stopped by stop_above (its amplitude passed the bound), not by the budget
            r = exc.response
            if r is not None and r.stopped_by and len(r.omega) and r.tip_amplitude[:, direction].max() > stop_above:
                return PeakEvaluation(False, np.nan, np.nan, float(bound), f"stopped above the bound: {exc}", runs,
                                      stopped_above=True)
            r = exc.response
            if _joinable(r) and r.frequency_hz[0] == lo and (up is None or r.frequency_hz.max() > up.frequency_hz.max()):
                up = r
        except RuntimeError as exc:
            messages.append(f"{options}: {exc}")
        if bound > give_up_above:
            return PeakEvaluation(False, np.nan, np.nan, float(bound),
                                  f"given up: a partial branch reached {1e3 * bound:.4g} mm, above "
                                  f"{1e3 * give_up_above:.4g} mm: " + "; ".join(messages), runs)
    if not downward:
        return PeakEvaluation(False, np.nan, np.nan, float(bound), "; ".join(messages), runs)
    # downward sweep, joined with the farthest-reaching upward branch
    runs += 1
    step = min((o.get("max_step", 0.05) for o in attempts), default=0.02)
    down = disk.frequency_response(hi, lo, harmonics=harmonics, max_step=step, max_points=max_points, **frf_options)
    bound = np.fmax(bound, _lower_bound(down, direction))
    if down.success:
        branches = [down]
    elif up is not None and _joinable(down) and up.frequency_hz.max() >= down.frequency_hz.min():
        branches = [up, down]
    else:
        messages.append(f"downward sweep, max_step {step}: {down.message}")
        reach = f"upward branch up to {up.frequency_hz.max():.4f} Hz" if up is not None else "no upward branch"
        stop = f"downward branch down to {down.frequency_hz.min():.4f} Hz" if len(down.frequency_hz) else \
            "no downward branch"
        return PeakEvaluation(False, np.nan, np.nan, float(bound),
                              f"range not covered ({reach}, {stop}): " + "; ".join(messages), runs)

    def inside(b):                            # amplitudes of the points within the range
        return np.where((b.frequency_hz >= lo) & (b.frequency_hz <= hi), b.tip_amplitude[:, direction], -np.inf)

    b, i = max(((b, int(np.argmax(inside(b)))) for b in branches), key=lambda bi: inside(bi[0])[bi[1]])
    f = b.frequency_hz
    if f[i] in (lo, hi):
        return PeakEvaluation(False, np.nan, np.nan, float(bound),
                              f"largest amplitude at the range end {f[i]:.4g} Hz: " + "; ".join(messages), runs)
    a = b.tip_amplitude[:, direction]
    if b is down:                             # runs from hi to lo: the parabola wants rising frequency
        f, a, i = f[::-1], a[::-1], len(f) - 1 - i
    p, fp = refined_peak(f, a, i)
    how = "downward sweep" if len(branches) == 1 else "upward and downward partial branches joined"
    return PeakEvaluation(True, p, fp, np.nan, f"{how} (before: {'; '.join(messages)})", runs)


@dataclass
class MassSweep(Saveable):
    """Peak tip amplitude over damper mass.

    mass : (k,) [kg]; peak_amplitude : (k,) [m]; peak_frequency_hz : (k,) [Hz]; kind : damper type
    """

    mass: np.ndarray
    peak_amplitude: np.ndarray
    peak_frequency_hz: np.ndarray
    kind: str
    undamped_peak_amplitude: float

    @property
    def reduction(self) -> np.ndarray:
        """1 - peak / undamped peak."""
        return 1 - self.peak_amplitude / self.undamped_peak_amplitude

    def plot(self, ax=None, **kwargs):
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        kwargs.setdefault("label", self.kind)
        if kwargs.get("color") is None:
            kwargs["color"] = palette.DAMPER.get(self.kind)
        ax.semilogx(1e3 * self.mass, 1e3 * self.peak_amplitude, marker="o", **kwargs)
        shown = any(line.get_label() == "no damper" for line in ax.get_lines())
        ax.axhline(1e3 * self.undamped_peak_amplitude, color=palette.UNDAMPED, ls="--", lw=1,
                   label="_no damper" if shown else "no damper")      # one legend entry per axes
        plain_log_ticks(ax.xaxis)
        ax.set_xlabel("damper mass [g]")
        ax.set_ylabel("resonance tip amplitude u_x [mm]")
        ax.grid(True, which="both", alpha=0.3)
        place_legend(ax)
        return ax


def _peak_of(case):
    disk, f_range, harmonics = case
    p, f, _ = peak_response(disk, f_range, harmonics, **peak_search_options(harmonics))
    return p, f


def mass_sweep(disk: TunedDisk, masses, f_range_hz=(90.0, 105.0), harmonics=(1,), progress=None,
               processes: int | None = 1) -> MassSweep:
    """Peak tip amplitude for each damper mass in ``masses`` [kg] (each > 0).

    ``processes``: worker processes over the masses (None: every core); ``progress``: True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
    (done, total)."""
    from .parallel import parallel_map

    progress = progress_callback(progress, "mass sweep")

    masses = np.atleast_1d(np.asarray(masses, dtype=float))
    if masses.size == 0:
        raise ValueError("masses must be a non-empty array of damper masses in (0, inf) kg")
    validation.positive("masses", masses)
    cases = [(with_mass(disk, m), f_range_hz, harmonics) for m in masses]
    peaks, freqs = np.array(parallel_map(_peak_of, cases, processes, progress)).T
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range_hz, harmonics)
    return MassSweep(masses, peaks, freqs, disk.damper.kind, undamped)


@dataclass
class MassOptimum(Saveable):
    """Optimal damper mass [kg], its peak tip amplitude [m], the undamped peak [m].

    Found by :func:`optimal_mass`: a log grid over the bounds, then a bounded local search in
    the bracket of the best grid point.

    mass, peak_amplitude : the best mass evaluated and its peak [kg, m]
    undamped_peak_amplitude : [m]; evaluations : number of masses evaluated
    failed_masses : (f,) [kg] masses whose response could not be computed even with the
        retries of :func:`robust_peak` (e.g. a very light cylinder whose continuation stalls
        just below the resonance); never returned as the optimum
    failed_lower_bounds : (f,) [m] the largest tip amplitude on their converged partial
        branches, a lower bound of their true peak (NaN: nothing converged)
    failure_messages : (f,) why each failed
    grid_mass : (g,) [kg] the bracketing grid; grid_peak_amplitude : (g,) [m] (NaN where failed)
    bracket : (low, high) [kg] the grid interval of the local search
    stopped_masses : (s,) [kg] grid masses whose branch was stopped once it was above the best
        peak found before them (branch and bound: their peak is above it, so none is the optimum;
        NaN in ``grid_peak_amplitude``); not counted as failed
    success : True when the optimum is certified global on the grid: every failed mass has a
        lower bound above the optimum peak (so it cannot hide a better mass)
    message : what was found, and which failed masses leave the claim open
    evaluated_mass : (e,) [kg] every mass evaluated (the grid and the bounded search's points),
        increasing; evaluated_peak_amplitude : (e,) [m] their peaks (NaN where failed or stopped)
    """

    mass: float
    peak_amplitude: float
    undamped_peak_amplitude: float
    evaluations: int
    failed_masses: tuple = ()
    failed_lower_bounds: tuple = ()
    failure_messages: tuple = ()
    grid_mass: np.ndarray = None
    grid_peak_amplitude: np.ndarray = None
    bracket: tuple = ()
    success: bool = True
    message: str = ""
    stopped_masses: tuple = ()
    evaluated_mass: np.ndarray = None
    evaluated_peak_amplitude: np.ndarray = None

    @property
    def reduction(self) -> float:
        return 1 - self.peak_amplitude / self.undamped_peak_amplitude


GRID_PER_DECADE = 4   # bracketing grid density: resolves a valley 0.2 decade wide, the narrowest
                      # found (benchmarks/README.md, 'Moved from the package's docstrings', studies/mass.py)


def log_mass_grid(bounds, grid_per_decade: float = GRID_PER_DECADE):
    """The bracketing grid of a mass optimisation over ``bounds`` = (low, high) [kg]:
    n = max(5, ceil(grid_per_decade * log10(high / low)) + 1) points evenly spaced in log(mass).
    Returns (log masses (n,), masses (n,) [kg]); the masses' ends are the bounds exactly
    (exp(log(1e-5)) is 9.999999999999997e-06 in floating point, below a bound of 1e-5 kg)."""
    lo, hi = bounds
    n = max(5, int(np.ceil(grid_per_decade * np.log10(hi / lo))) + 1)
    loggrid = np.linspace(np.log(lo), np.log(hi), n)
    masses = np.clip(np.exp(loggrid), lo, hi)
    masses[0], masses[-1] = lo, hi
    return loggrid, masses


def robust_peak_case(case):
    """:func:`robust_peak` of one case ``(disk, f_range_hz, harmonics, attempts, downward,
    give_up_above, stop_above)`` (the arguments of the same names, in this order): the unit of
    work :func:`optimal_mass` sends to :func:`~bladedamp.progress.parallel_map` (a module-level
    function, so that worker processes can pickle it)."""
    disk, f_range, harmonics, attempts, downward, give_up_above, stop_above = case
    return robust_peak(disk, f_range, harmonics, attempts=attempts, downward=downward, give_up_above=give_up_above,
                       stop_above=stop_above)


def bracket_minimum(fun, grid, xatol: float, fail_value: float, processes: int | None = 1, evaluate_grid=None):
    """Global minimum of ``fun`` over the interval of ``grid`` (increasing): evaluate every grid
    point, then a bounded Brent search in [grid[i-1], grid[i+1]] around the best one, i.

    ``fun(x) -> value`` (NaN: not computable, replaced by ``fail_value`` for the search and never
    the answer); ``evaluate_grid(grid) -> values`` evaluates the grid at once (e.g. on several
    processes), else ``fun`` is called on each point. Returns (x_best, f_best, cache {x: value},
    (low, high) bracket). This is the part that makes the search global: a local search from the
    whole interval stops in whichever valley its first golden-section points fall into.
    """
    grid = np.asarray(grid, dtype=float)
    values = np.asarray(evaluate_grid(grid) if evaluate_grid is not None else [fun(x) for x in grid], dtype=float)
    cache = dict(zip(map(float, grid), map(float, values)))
    if not np.any(np.isfinite(values)):
        return np.nan, np.nan, cache, (float(grid[0]), float(grid[-1]))
    i = int(np.nanargmin(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]

    def objective(x):
        x = float(x)
        if x not in cache:
            cache[x] = float(fun(x))
        v = cache[x]
        return fail_value if not np.isfinite(v) else v

    if b > a:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            minimize_scalar(objective, bounds=(a, b), method="bounded", options={"xatol": xatol})
    ok = {x: v for x, v in cache.items() if np.isfinite(v)}
    best = min(ok, key=ok.get)
    return best, ok[best], cache, (float(a), float(b))


def optimal_mass(disk: TunedDisk, bounds=(1e-5, 1e-2), f_range_hz=(90.0, 105.0), harmonics=(1,),
                 xatol: float = 0.02, grid_per_decade: float = GRID_PER_DECADE, processes: int | None = 1,
                 progress=None, complete_grid: bool = False) -> MassOptimum:
    """Mass minimising the peak tip amplitude, global over ``bounds`` [kg] (0 < low < high).

    A log grid of ``grid_per_decade`` points per decade (at least 5) brackets the best mass;
    a bounded Brent search in log(mass) (tolerance ``xatol``) refines it within the grid
    interval around the best grid point. Each mass is evaluated by :func:`robust_peak`
    (retries with a finer continuation and a downward sweep); masses that still fail are listed
    in the result with a lower bound of their peak, and ``success`` says whether they could
    hide a better optimum. ``processes``: worker processes over the grid (None: every core);
    ``progress``: True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable (done, total) over the grid.
    ``complete_grid``: afterwards, also solve the grid masses whose branch was stopped above the
    best peak (branch and bound), so ``grid_peak_amplitude`` is the whole curve around the
    optimum (for a figure; it costs those responses, and does not change the optimum).
    """
    from .parallel import parallel_map, workers

    progress = progress_callback(progress, "mass grid")

    lo, hi = validation.interval("mass bounds", bounds, "kg")
    validation.positive("xatol", xatol)
    validation.positive("grid_per_decade", grid_per_decade)
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range_hz, harmonics)
    evaluations = {}

    def record(m, ev):
        evaluations[m] = ev
        return ev.peak_amplitude if ev.success else np.nan

    def best_so_far():
        return min((ev.peak_amplitude for ev in evaluations.values() if ev.success), default=np.inf)

    loggrid, grid_m = log_mass_grid((lo, hi), grid_per_decade)
    n = len(loggrid)

    def mass_of(logm):          # the grid's own masses at its points (its ends: the bounds exactly)
        at = np.flatnonzero(loggrid == logm)
        return float(grid_m[at[0]]) if at.size else float(np.exp(logm))

    def fun(logm):
        m = mass_of(logm)
        return record(m, robust_peak(with_mass(disk, m), f_range_hz, harmonics, give_up_above=best_so_far()))

    def evaluate_grid(loggrid):
        # first the plain response of every grid mass, heaviest first, as many at a time as there
        # are workers, each branch stopped once it is above the best peak found before it (that
        # mass cannot be the optimum: branch and bound); then the retries of those that failed,
        # except where a partial branch is already above the best grid peak (no optimum there)
        masses = [mass_of(x) for x in loggrid]
        wave = workers(processes, len(masses))
        order = masses[::-1]
        for k in range(0, len(order), wave):
            chunk, best = order[k:k + wave], best_so_far()
            cases = [(with_mass(disk, m), f_range_hz, harmonics, ROBUST_ATTEMPTS[:1], False, best, best) for m in chunk]
            for m, ev in zip(chunk, parallel_map(robust_peak_case, cases, processes)):
                record(m, ev)
            if progress:
                progress(min(k + wave, len(order)), len(order))
        best = best_so_far()
        retry = [m for m in masses if not evaluations[m].success and not evaluations[m].lower_bound > best]
        cases = [(with_mass(disk, m), f_range_hz, harmonics, ROBUST_ATTEMPTS[1:], True, best, np.inf) for m in retry]
        for m, ev in zip(retry, parallel_map(robust_peak_case, cases, processes)):
            ev.attempts += evaluations[m].attempts
            record(m, ev)
        return [evaluations[m].peak_amplitude if evaluations[m].success else np.nan for m in masses]

    logm, peak, _, (a, b) = bracket_minimum(fun, loggrid, xatol, 10 * undamped, evaluate_grid=evaluate_grid)
    if complete_grid and np.isfinite(logm):
        rest = [float(m) for m in grid_m if evaluations[float(m)].stopped_above]
        cases = [(with_mass(disk, m), f_range_hz, harmonics, ROBUST_ATTEMPTS, True, np.inf, np.inf) for m in rest]
        for m, ev in zip(rest, parallel_map(robust_peak_case, cases, processes)):
            ev.attempts += evaluations[m].attempts
            record(m, ev)
    grid_p = np.array([evaluations[float(m)].peak_amplitude for m in grid_m])
    failed = sorted(m for m, ev in evaluations.items() if not ev.success and not ev.stopped_above)
    stopped = tuple(sorted(m for m, ev in evaluations.items() if ev.stopped_above))
    bounds_f = tuple(evaluations[m].lower_bound for m in failed)
    msgs = tuple(evaluations[m].message for m in failed)
    if not np.isfinite(logm):
        raise RuntimeError(f"no damper mass in {bounds} kg gave a computable response: " + msgs[0])
    best = mass_of(logm)
    open_ = [m for m, lb in zip(failed, bounds_f) if not lb > peak]
    where = "at a bound of the search" if logm in (loggrid[0], loggrid[-1]) else "interior"
    text = (f"optimum {1e3 * best:.4g} g ({where}), peak {1e3 * peak:.4g} mm, from a {n}-point log grid and a "
            f"bounded search in {1e3 * mass_of(a):.4g}-{1e3 * mass_of(b):.4g} g")
    if stopped:
        text += f"; {len(stopped)} grid mass(es) stopped once above the best peak found before them"
    if failed:
        text += (f"; {len(failed)} mass(es) not solved ({', '.join(f'{1e3 * m:.4g}' for m in failed)} g)")
        if open_:
            text += (f", of which {', '.join(f'{1e3 * m:.4g}' for m in open_)} g may hide a lower peak "
                     "(no partial branch above the optimum): global optimum not certified")
        else:
            text += ", each with a partial branch already above the optimum peak: they cannot be the optimum"
    evaluated = np.array(sorted(evaluations))
    return MassOptimum(best, peak, undamped, len(evaluations), tuple(failed), bounds_f, msgs, grid_m, grid_p,
                       (mass_of(a), mass_of(b)), not open_, text, stopped, evaluated,
                       np.array([evaluations[m].peak_amplitude if evaluations[m].success else np.nan
                                 for m in evaluated]))
