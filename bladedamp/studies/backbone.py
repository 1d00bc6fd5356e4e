"""Damper design by nonlinear modes: the optimal damper mass at many excitation levels from
EPMC backbones.

The resonance peak of a damper mass at an excitation level follows from its damped nonlinear
mode (EPMC, :func:`bladedamp.nonlinear_mode`) by single-nonlinear-mode synthesis
(:meth:`NonlinearModeResponse.forced_peak`): a root of the synthesis condition on the backbone,
no harmonic balance of the forced response. Each peak is an EPMC solution at that root
(``resolve_peaks``), not a spline value between the mode's points (the valley of the peak over
mass is flat, 0.1 % over +-5 % of mass at 0.1 N, so an interpolation error of 1e-3 that jumps
from one mass to the next moves the optimum by percents). The optimum over mass is found as in
:func:`bladedamp.studies.mass.optimal_mass`: a log grid over the bracket (every grid mass at
all levels), then per level a bounded Brent search in log(mass) in the grid interval around
the best grid point.

Only the first grid mass gets a full mode (the continuation from the stuck mode to gross slip,
with the peaks of every level resolved). A peak is one EPMC solution, so every other peak is
tracked in mass: solved at the new mass from the nearest evaluated mass's solution at that
level's peak, from the modal amplitude interpolated over log mass between the two nearest
(:func:`~bladedamp.hbm.nonlinear_modes.tracked_forced_peaks`: the same root to ~1e-8, 4-11
EPMC solves instead of a continuation of ~50); a mass whose tracking does not converge gets its
full mode. Every evaluation is cached.

The synthesis assumes one resonant mode, well separated (the 1F family of the tuned disk at one
engine order), and a first-harmonic excitation; its peaks are within about 0.1 % of the
one-harmonic FRF peaks of the reference disk (compared, with the optima of
:func:`~bladedamp.studies.mass.optimal_mass`, in the test suite).
"""
from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from .. import validation
from ..io import Saveable
from .mass import GRID_PER_DECADE, log_mass_grid, peak_response, with_mass


@dataclass
class BackboneDesign(Saveable):
    """Optimal damper mass over excitation levels, by nonlinear modes.

    Attributes (k masses evaluated, l excitation levels)
    ----------
    kind : damper type
    mass : (k,) every damper mass evaluated (a full nonlinear mode, or a peak tracked from a
        neighbouring mass), ascending [kg]
    excitation_levels : (l,) excitation levels: the norm of the disk's force vector (F_x for the
        reference disk) [N]
    peak_amplitude : (k, l) predicted resonance tip amplitude (first harmonic, ``direction``) [m];
        NaN where the mode failed, the peak lies outside its computed amplitude range, or the
        mass was evaluated for another level's refinement only (every grid mass has all levels)
    peak_frequency_hz : (k, l) frequency of that resonance [Hz]
    optimal_mass : (l,) the mass of the lowest peak per level [kg]
    optimal_peak_amplitude : (l,) its peak [m]
    undamped_peak_amplitude : (l,) the peak without damper (linear: proportional to the level) [m]
    bracket : (l, 2) the grid interval of each level's refinement [kg]
    grid_mass : (g,) the log grid of the first stage [kg]
    failed_masses : masses whose full nonlinear mode did not converge (never the optimum) [kg]
    at_bound : (l,) True where the optimum is a bound of the search (widen the bracket)
    tracked_masses : masses whose peaks were all tracked from the nearest masses' EPMC solutions
        (:func:`~bladedamp.hbm.nonlinear_modes.tracked_forced_peaks`), no full mode [kg]
    fallback_masses : masses where a tracking failed and the full mode was computed [kg]
    elapsed_s : wall time of the study [s]
    message : what was done
    """

    kind: str
    mass: np.ndarray
    excitation_levels: np.ndarray
    peak_amplitude: np.ndarray
    peak_frequency_hz: np.ndarray
    optimal_mass: np.ndarray
    optimal_peak_amplitude: np.ndarray
    undamped_peak_amplitude: np.ndarray
    bracket: np.ndarray
    grid_mass: np.ndarray
    failed_masses: tuple = ()
    at_bound: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    tracked_masses: tuple = ()
    fallback_masses: tuple = ()
    elapsed_s: float = float("nan")
    message: str = ""

    @property
    def reduction(self) -> np.ndarray:
        """(k, l) 1 - peak / undamped peak."""
        return 1 - self.peak_amplitude / self.undamped_peak_amplitude[None, :]

    @property
    def optimal_reduction(self) -> np.ndarray:
        """(l,) 1 - optimal peak / undamped peak."""
        return 1 - self.optimal_peak_amplitude / self.undamped_peak_amplitude

    def plot(self, axes=None):
        """Amplitude reduction [%] over mass [g] per level (left) and the optimal mass [g] over
        the level [N] (right). ``axes``: a pair of axes (a new figure if None); returns the pair."""
        import matplotlib.pyplot as plt

        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

        from ..plotting import place_legend

        if axes is None:
            _, axes = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
        ax, ax2 = axes
        for j, level in enumerate(self.excitation_levels):
            ok = np.isfinite(self.reduction[:, j])
            line, = ax.semilogx(1e3 * self.mass[ok], 100 * self.reduction[ok, j], ".-", label=f"F = {level:.3g} N")
            ax.plot(1e3 * self.optimal_mass[j], 100 * self.optimal_reduction[j], "o", color=line.get_color())
        ax.set_xlabel("damper mass [g]")
        ax.set_ylabel("reduction of the resonance tip amplitude [%]")
        ax.set_title(f"{self.kind}: peak by single nonlinear mode synthesis", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax2.loglog(self.excitation_levels, 1e3 * self.optimal_mass, "o-")
        ax2.set_xlabel("excitation level [N]")
        ax2.set_ylabel("optimal damper mass [g]")
        ax2.grid(True, which="both", alpha=0.3)
        for axis in (ax.xaxis, ax2.xaxis, ax2.yaxis):      # plain labels at 1, 2, 5 x 10^k, none between
            axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(NullFormatter())
        place_legend(ax, fontsize=8)                        # clear of every point (after the layout)
        return axes


def synthesised_peak(mode, scale: float = 1.0, direction: int = 0):
    """(tip amplitude [m], frequency [Hz]) of the resonance of ``mode`` under ``scale`` times its
    own excitation by single-nonlinear-mode synthesis: the ``direction`` component of
    :meth:`~bladedamp.hbm.nonlinear_modes.NonlinearModeResponse.forced_peak` (the one peak
    finder); NaN where it finds no peak on the computed range."""
    return _tip_peak(mode.forced_peak(scale=scale), direction)


def _tip_peak(peak: dict, direction: int):
    """(tip amplitude [m], frequency [Hz]) of a peak record of
    :meth:`~bladedamp.hbm.nonlinear_modes.NonlinearModeResponse.forced_peak` (or of
    :func:`~bladedamp.hbm.nonlinear_modes.tracked_forced_peaks`); NaN if not found."""
    out = np.asarray(peak["output_amplitude"], dtype=float)
    if not peak["found"] or out.size <= direction:
        return np.nan, np.nan
    return float(out[direction]), float(peak["frequency_hz"])


def _force_scale(disk) -> float:
    level = float(np.linalg.norm(disk.excitation[:3]))
    if level == 0:
        raise ValueError("the disk has no excitation force (excitation[:3] is zero): nothing to scale")
    return level


def optimal_mass_by_backbone(disk, excitation_levels, bracket=(1e-4, 1e-2), grid_per_decade: float = GRID_PER_DECADE,
                             xatol: float = 5e-3, direction: int = 0, harmonics=(1,), n_points: int = 30,
                             tol: float = 1e-9, f_range_hz=(90.0, 105.0), track: bool = True) -> BackboneDesign:
    """Damper mass minimising the resonance tip amplitude at each of ``excitation_levels`` [N].

    ``disk`` : a TunedDisk with a damper (its mass is replaced), or the damper kind ("cylinder",
    "wedge") for the reference disk; ``excitation_levels`` : force levels [N] (> 0): the disk's
    excitation vector scaled to that norm (F_x of the reference disk); ``bracket`` : (low, high)
    masses [kg]; ``grid_per_decade`` : density of the log grid (at least 5 points);
    ``xatol`` : tolerance of the Brent search in log(mass) (5e-3: 0.5 % in mass);
    ``direction`` : tip DOF of the amplitude (0..2: u_x, u_y, u_z); ``harmonics``, ``n_points``,
    ``tol`` : of :func:`bladedamp.nonlinear_mode` and the tracking (30 points: the peaks are resolved by EPMC
    solves at their roots, so they do not depend on the points, while interpolated ones
    would); ``f_range_hz`` : range of the undamped peak's FRF;
    ``track`` : a full mode for the first grid mass only; every other peak is tracked in mass
    from the nearest evaluated mass's EPMC solution at that level's peak
    (:func:`~bladedamp.hbm.nonlinear_modes.tracked_forced_peaks`: the same root of the synthesis
    condition to ~1e-8, at a fraction of a full mode's cost), with the full mode where that fails;
    False: a full mode for every mass.
    """
    from ..hbm.nonlinear_modes import nonlinear_mode, tracked_forced_peaks
    from ..reference import reference_disk

    t0 = time.perf_counter()
    if isinstance(disk, str):
        disk = reference_disk(disk)
    if getattr(disk, "damper", None) is None:
        raise ValueError("the disk must have a damper (its mass is the design variable)")
    levels = np.atleast_1d(np.asarray(excitation_levels, dtype=float))
    if levels.ndim != 1 or levels.size == 0:
        raise ValueError(f"excitation_levels must be a non-empty 1-D array of forces in (0, inf) N (got {excitation_levels!r})")
    validation.positive("excitation_levels", levels)
    lo, hi = validation.interval("bracket", bracket, "kg")
    validation.positive("bracket", np.array([lo, hi]))
    validation.positive("xatol", xatol)
    validation.positive("grid_per_decade", grid_per_decade)
    direction = validation.integer("direction", direction, minimum=0, maximum=2)
    ref = _force_scale(disk)
    scales = levels / ref

    modes, peaks, freqs, resolved = {}, {}, {}, {}
    roots = {}                  # (mass, level index): (mode holding the EPMC solution at the peak, its modal amplitude)
    fallbacks = set()

    def full_mode(m: float, wanted):
        """The nonlinear mode of mass m with the peaks of levels ``wanted`` resolved."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = nonlinear_mode(with_mass(disk, m), harmonics=harmonics, n_points=n_points, tol=tol,
                               resolve_peaks=scales[list(wanted)])
        modes[m] = r
        if len(r.modal_amplitude) >= 2:
            for j in wanted:
                peak = r.forced_peak(scale=scales[j])
                peaks[m][j], freqs[m][j] = _tip_peak(peak, direction)
                if peak["found"]:
                    roots[m, j] = (r, peak["modal_amplitude"])

    def tracked_peaks(m: float, wanted) -> list:
        """Track the peaks of levels ``wanted`` to mass m, each from the nearest mass (in log) with
        a peak at that level, starting at the modal amplitude interpolated (or extrapolated)
        linearly in log a over log m from the two nearest. Returns the levels left without a peak:
        no mass to start from, or no convergence (m is then a fallback)."""
        js, starts, amplitudes = [], [], []
        for j in wanted:
            near = sorted((mm for mm, jj in roots if jj == j), key=lambda mm: abs(np.log(m / mm)))[:2]
            if not near:
                continue
            start, amplitude = roots[near[0], j]
            if len(near) == 2:
                t = np.log(m / near[0]) / np.log(near[1] / near[0])
                amplitude *= (roots[near[1], j][1] / amplitude) ** t
            js.append(j)
            starts.append(start)
            amplitudes.append(amplitude)
        if js:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = tracked_forced_peaks(with_mass(disk, m), starts, scales[js], amplitudes, tol=tol)
            for j, peak in zip(js, found):
                if peak["found"]:
                    peaks[m][j], freqs[m][j] = _tip_peak(peak, direction)
                    roots[m, j] = (peak["mode"], peak["modal_amplitude"])
            if not all(peak["found"] for peak in found):
                fallbacks.add(m)
        return [j for j in wanted if (m, j) not in roots]

    def evaluate(m: float, level: int | None = None):
        """Peaks (l,) [m] of mass m (cached): at every level (``level`` None: the grid) or at level
        ``level`` only (a level's refinement: the other levels' peaks stay NaN). With ``track``
        each peak is tracked from the nearest mass with one; a full mode resolves the levels
        left (the first grid mass's, and where tracking fails)."""
        m = float(m)
        wanted = range(levels.size) if level is None else (level,)
        if m not in peaks:
            peaks[m], freqs[m] = np.full(levels.size, np.nan), np.full(levels.size, np.nan)
            resolved[m] = set()
        todo = [j for j in wanted if j not in resolved[m]]
        if todo:
            left = tracked_peaks(m, todo) if track else todo
            if left:
                full_mode(m, left)
            resolved[m] |= set(todo)
        return peaks[m]

    loggrid, grid = log_mass_grid((lo, hi), grid_per_decade)
    n = len(grid)
    grid_vals = np.array([evaluate(m) for m in grid])              # (n, l)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        undamped1, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range_hz, harmonics, direction=direction)
    undamped = undamped1 * scales

    best_m = np.full(levels.size, np.nan)
    best_p = np.full(levels.size, np.nan)
    brackets = np.full((levels.size, 2), np.nan)
    at_bound = np.zeros(levels.size, dtype=bool)
    for j in range(levels.size):
        col = grid_vals[:, j]
        if not np.any(np.isfinite(col)):
            continue
        i = int(np.nanargmin(col))
        a, b = loggrid[max(i - 1, 0)], loggrid[min(i + 1, n - 1)]
        brackets[j] = grid[max(i - 1, 0)], grid[min(i + 1, n - 1)]
        fail = 10 * undamped[j]

        def objective(logm, j=j, fail=fail):
            v = evaluate(np.exp(logm), j)[j]
            return v if np.isfinite(v) else fail

        minimize_scalar(objective, bounds=(a, b), method="bounded", options={"xatol": xatol})
        ok = [(m, v[j]) for m, v in peaks.items() if np.isfinite(v[j])]
        m_best, p_best = min(ok, key=lambda mv: mv[1])
        best_m[j], best_p[j] = m_best, p_best
        at_bound[j] = m_best in (grid[0], grid[-1])

    masses = np.array(sorted(peaks))
    failed = tuple(m for m in masses if m in modes and (len(modes[m].modal_amplitude) < 2 or not modes[m].success))
    tracked = tuple(m for m in masses if m not in modes)
    text = (f"{len(masses)} masses ({n}-point log grid {1e3 * lo:.4g}-{1e3 * hi:.4g} g and a bounded search per "
            f"level, xatol {xatol:g} in log mass), {levels.size} excitation level(s): {len(modes)} full nonlinear "
            f"mode(s)" + (f", {len(tracked)} masses by peaks tracked from the nearest mass" if track else ""))
    if fallbacks:
        text += f" ({len(fallbacks)} full mode(s) where the tracking failed)"
    if failed:
        text += f"; no mode for {', '.join(f'{1e3 * m:.4g}' for m in failed)} g"
    if at_bound.any():
        text += f"; optimum at a bound of the bracket for level(s) {', '.join(f'{x:.3g}' for x in levels[at_bound])} N"
    return BackboneDesign(disk.damper.kind, masses, levels, np.array([peaks[m] for m in masses]),
                          np.array([freqs[m] for m in masses]), best_m, best_p, undamped, brackets, grid,
                          failed, at_bound, tracked, tuple(sorted(fallbacks)), time.perf_counter() - t0, text)
