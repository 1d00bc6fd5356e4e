"""Mistuning studies: patterns, the paper's cases (Figs. 12-17), Monte Carlo on Dask and
arrangement optimisation, all on the full assembly of :class:`bladedamp.mistuned.MistunedDisk`.

Patterns (mistuning factors kappa_i, f_0j^(i) = kappa_i f_0j for every mode j of blade i):

* :func:`random_kappa` -- Gaussian, mean 1, standard deviation ``std`` (paper: 2 %), seeded;
* :func:`reorder` -- an arrangement of given blades that avoids neighbours with similar
  frequencies (paper's case c): the low half and the high half of the sorted blades
  interleaved, then improved by pairwise swaps on (smallest neighbour difference, sum of
  neighbour differences), cyclic;
* :func:`alternating` -- 1 +- amplitude (paper's case d);
* :func:`check_kappa` -- validation of a user array.
"""
from __future__ import annotations

import json
import math
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import palette, validation
from ..disk import TunedDisk
from ..io import Saveable, npz_path
from ..plotting import place_legend, save_figure
from ..progress import progress_callback
from ..mistuned import MistunedDisk, MistunedResponse

PAPER_STD = 0.02
PAPER_SEED = 2                  # seed of the paper-case sample (any: the paper's sample is not given)
PAPER_MASSES = (1.0e-3, 5.0e-3)


# ---------------------------------------------------------------------------------------
# patterns
# ---------------------------------------------------------------------------------------
def check_kappa(kappa, n_blades: int | None = None) -> np.ndarray:
    """A user array of mistuning factors: 1-D, finite, > 0, and ``n_blades`` long if given."""
    k = np.asarray(kappa, dtype=float)
    if k.ndim != 1 or k.size == 0:
        raise ValueError(f"kappa (mistuning factors) must be a non-empty 1-D array (got shape {k.shape})")
    validation.positive("kappa (mistuning factors)", k)
    if n_blades is not None and k.size != n_blades:
        raise ValueError(f"kappa (mistuning factors) must have n_blades = {n_blades} entries (got {k.size})")
    return k


def random_kappa(n_blades: int, std: float = PAPER_STD, seed=None) -> np.ndarray:
    """Gaussian mistuning factors, mean 1, standard deviation ``std`` (paper: 0.02)."""
    n = validation.integer("n_blades", n_blades, minimum=1)
    std = validation.nonnegative("std (standard deviation of kappa)", std)
    if std >= 0.2:
        raise ValueError(f"std (standard deviation of kappa) must be in [0, 0.2) (got {std})")
    return 1.0 + std * np.random.default_rng(seed).standard_normal(n)


def disk_kappas(n_blades: int, n_disks: int, std: float = PAPER_STD, seed=0) -> np.ndarray:
    """(n_disks, n_blades) the factors of a study's mistuned disks: disk i's are
    ``random_kappa(n_blades, std, seed=[seed, i])`` (reproducible, independent of the scheduling;
    the Monte Carlo's and the robust objective's copies, the same for the same seed)."""
    return np.array([random_kappa(n_blades, std, seed=[int(seed), i]) for i in range(n_disks)])


def alternating(n_blades: int, amplitude: float = PAPER_STD) -> np.ndarray:
    """1 + amplitude, 1 - amplitude, ... (paper's case d); ``n_blades`` must be even."""
    n = validation.integer("n_blades", n_blades, minimum=2)
    if n % 2:
        raise ValueError(f"n_blades must be even for alternating mistuning (got {n})")
    a = validation.in_range("amplitude (alternating mistuning)", amplitude, 0.0, 1.0, closed="left")
    return 1.0 + a * np.tile([1.0, -1.0], n // 2)


def neighbour_contrast(kappa) -> tuple[float, float]:
    """(smallest, mean) |kappa_i - kappa_i+1| around the disk (cyclic)."""
    k = np.asarray(kappa, dtype=float)
    d = np.abs(k - np.roll(k, -1))
    return float(d.min()), float(d.mean())


def reorder(kappa) -> np.ndarray:
    """Blade order avoiding neighbours with similar frequencies (paper's case c).

    Returns the permutation ``order`` (blade ``order[i]`` at position i, i.e. ``kappa[order]``).
    Start: the sorted low half and high half interleaved (every neighbour pair is one low and one
    high blade); then pairwise swaps while they increase (smallest neighbour difference, sum of
    neighbour differences), lexicographically.
    """
    k = check_kappa(kappa)
    n = k.size
    s = np.argsort(k, kind="stable")
    half = (n + 1) // 2
    low, high = s[:half], s[half:]
    order = np.empty(n, dtype=int)
    order[0::2] = low
    order[1::2] = high

    def score(o):
        d = np.abs(k[o] - k[np.roll(o, -1)])
        return (round(float(d.min()), 15), float(d.sum()))

    best = score(order)
    improved = True
    while improved:
        improved = False
        for i in range(n):
            for j in range(i + 1, n):
                o = order.copy()
                o[i], o[j] = o[j], o[i]
                sc = score(o)
                if sc > best:
                    order, best, improved = o, sc, True
    return order


PATTERNS = ("tuned", "random", "reordered", "alternating")


def pattern_kappa(pattern: str, n_blades: int, std: float = PAPER_STD, seed=PAPER_SEED) -> np.ndarray:
    """The (n_blades,) mistuning factors of one of the paper's patterns (Fig. 12): "tuned" (all 1),
    "random" (Gaussian, ``std``, ``seed``), "reordered" (the same blades by :func:`reorder`) or
    "alternating" (+-``std``)."""
    if pattern not in PATTERNS:
        raise ValueError(f"pattern must be one of {PATTERNS} (got {pattern!r})")
    if pattern == "tuned":
        return np.ones(validation.integer("n_blades", n_blades, minimum=2))
    if pattern == "alternating":
        return alternating(n_blades, std)
    k = random_kappa(n_blades, std, seed=seed)
    return k[reorder(k)] if pattern == "reordered" else k


# ---------------------------------------------------------------------------------------
# peaks of a mistuned disk
# ---------------------------------------------------------------------------------------
def auto_range(disk: TunedDisk, kappa, margin: float = 0.03) -> tuple[float, float]:
    """Frequency range around the first mode of every blade: f_01 (min kappa (1 - margin),
    max kappa (1 + margin)) [Hz]."""
    k = check_kappa(kappa)
    f1 = float(disk.blade.natural_frequencies_hz[0])
    return f1 * k.min() * (1 - margin), f1 * k.max() * (1 + margin)


def mistuned_response(disk: TunedDisk, kappa, f_range_hz=None, harmonics=(1,), max_step: float = 0.05,
                      tuned_peak_amplitude: float | None = None, max_widenings: int = 3, n_sector: int | None = None,
                      n_samples: int | None = None, tol: float = 1e-10,
                      estimate_harmonic_error: bool = True, chord: bool = False,
                      target_iterations: int = 5, range_margin: float = 0.03,
                      assembly: MistunedDisk | None = None) -> MistunedResponse:
    """Full-assembly response of ``disk`` with blade frequencies times ``kappa``; while some
    blade's largest amplitude is at an end of the range (default :func:`auto_range`), the branch
    is continued beyond that end by half the range's width (:meth:`MistunedDisk.extend_response`);
    ``range_margin``: :func:`auto_range`'s margin.
    If the upward sweep fails (it can leave the response curve at a branch point), the range is
    swept downwards, then both ways at half the step; the first complete sweep is returned in
    rising frequency.
    ``n_sector``: a cyclic sector of that many blades (``kappa`` then has n_sector entries; e.g. 2
    for alternating mistuning, exact, see the tests). ``n_samples``, ``tol``: AFT samples and
    continuation tolerance (defaults: the model's and the continuation's);
    ``estimate_harmonic_error``: as :meth:`MistunedDisk.frequency_response`. ``chord``,
    ``target_iterations``: the continuation's corrector (:func:`bladedamp.hbm.continuation.continuation`).
    ``assembly``: None, or ``disk``'s tuned model ``MistunedDisk.from_tuned(disk, n_sector=n_sector)``
    built once, whose harmonic-balance set-up the mistuned disk then shares
    (:meth:`MistunedDisk.mistuned`, the same residuals; :func:`monte_carlo` passes one for all its disks).
    Raises RuntimeError if the continuation does not cover the range."""
    if assembly is None:
        md = MistunedDisk.from_tuned(disk, kappa, n_sector=n_sector)
    else:
        md = assembly.mistuned(kappa)
    if f_range_hz is None:
        f_range_hz = auto_range(disk, kappa, range_margin)
    lo, hi = (float(f) for f in f_range_hz)
    # a sweep that turns back and leaves the range by 5 % of its width has left the curve (below)
    common = dict(harmonics=harmonics, n_samples=n_samples, tuned_peak_amplitude=tuned_peak_amplitude, tol=tol,
                  leave_margin=0.05, estimate_harmonic_error=estimate_harmonic_error, chord=chord,
                  target_iterations=target_iterations)

    def sweep(lo, hi):
        # the upward sweep can leave the response curve at a branch point and follow another
        # branch back out of the range (as the cylinder's rolling branch can); the downward
        # sweep, then both at half the
        # step, are tried before giving up
        failures = []
        for start, end, step in ((lo, hi, max_step), (hi, lo, max_step), (lo, hi, max_step / 2),
                                 (hi, lo, max_step / 2)):
            r = md.frequency_response(start, end, max_step=step, **common)
            if r.success:
                return r if end > start else r.reversed()
            failures.append(f"{start:.4g} -> {end:.4g} Hz, max_step {step:g}: {r.message}")
        raise RuntimeError("mistuned frequency response incomplete: " + "; ".join(failures))

    def extend(r, f_end, lo, hi):
        # continue the branch; if that leaves the curve too (3 of 1000 disks), at half the step,
        # then a new sweep over the whole widened range
        for step in (max_step, max_step / 2):
            longer = md.extend_response(r, f_end, max_step=step, tol=tol, leave_margin=0.05, chord=chord,
                                        target_iterations=target_iterations)
            if longer.success:
                return longer
        return sweep(lo, hi)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # success is checked
        r = sweep(lo, hi)
        for widening in range(max_widenings + 1):
            i = np.argmax(r.tip_amplitude[:, :, 0], axis=0)
            at_lo, at_hi = np.any(i == 0), np.any(i == len(r.omega) - 1)
            if not (at_lo or at_hi):
                return r
            if widening == max_widenings:
                break
            width = hi - lo
            if at_lo:
                lo = max(lo - width / 2, 0.5 * lo)
                r = extend(r, lo, lo, hi)
            if at_hi:
                hi = hi + width / 2
                r = extend(r, hi, lo, hi)
    raise RuntimeError(f"no interior resonance peak for every blade up to {lo:.4g}-{hi:.4g} Hz")


def tuned_peak(disk: TunedDisk, f_range_hz=(88.0, 106.0), harmonics=(1,), max_step: float = 0.05):
    """(peak tip amplitude [m], frequency [Hz], DiskResponse) of the tuned disk."""
    from .mass import peak_response

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return peak_response(disk, f_range_hz, harmonics, max_step)


# ---------------------------------------------------------------------------------------
# the paper's cases
# ---------------------------------------------------------------------------------------
@dataclass
class MistuningCase(Saveable):
    name: str
    mass: float
    kappa: np.ndarray
    response: MistunedResponse
    tuned_peak_amplitude: float
    tuned_response: object = None

    @property
    def peak_amplitude(self) -> np.ndarray:
        """(16,) peak of every blade [m] (a sector model's blades repeated around the disk)."""
        return np.resize(self.response.blade_peak_amplitudes, len(self.kappa))

    @property
    def peak_frequency_hz(self) -> np.ndarray:
        return np.resize(self.response.blade_peak_frequencies_hz, len(self.kappa))

    def summary(self) -> dict:
        return {"kappa": [float(k) for k in self.kappa], "peak_tip_mm": [float(1e3 * p) for p in self.peak_amplitude],
                "tuned_peak_tip_mm": float(1e3 * self.tuned_peak_amplitude), "mass_g": 1e3 * self.mass,
                "peak_hz": [float(f) for f in self.peak_frequency_hz], "model": "full assembly" if self.response.n_sector == len(
                    self.kappa) else f"cyclic sector of {self.response.n_sector} blades"}


def paper_kappas(n_blades: int = 16, std: float = PAPER_STD, seed=PAPER_SEED) -> dict[str, np.ndarray]:
    """The paper's patterns (Fig. 12 b-d): random, reordered (the same blades), alternating."""
    k = random_kappa(n_blades, std, seed)
    return {"random": k, "reordered": k[reorder(k)], "alternating": alternating(n_blades, std)}


def _tuned_case(case):
    disk, f_range, max_step = case
    return tuned_peak(disk, f_range or auto_range(disk, [1.0], 0.05), max_step=max_step)


def _mistuned_case(case):
    disk, kappa, f_range, max_step, tuned_peak_amplitude, n_sector = case
    return mistuned_response(disk, kappa, f_range, max_step=max_step, tuned_peak_amplitude=tuned_peak_amplitude,
                             n_sector=n_sector)


def paper_cases(disk_factory=None, progress=None, f_range_hz=None, max_step: float = 0.05,
                seed=PAPER_SEED, processes: int | None = 1) -> dict[str, MistuningCase]:
    """Cases b (random), c (reordered), d (alternating) at m = 1 g and b, c at m = 5 g, each
    beside the tuned disk of the same mass (16 blades, EO = 1, F_x = 0.1 N): b and c as full
    16-blade assemblies, d as its exact two-blade cyclic sector (equal to the full assembly to
    1e-13 in the tests; 20x cheaper), expanded to 16 blades in the summary.
    ``f_range_hz``: None -> :func:`auto_range` of each case.

    ``disk_factory(mass) -> TunedDisk`` (default: the reference cylinder disk);
    ``progress``: True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable (done, total, message) called after
    every FRF; ``processes``: worker processes over the tuned, then the mistuned responses
    (None: every core).
    Keys: ``random_1g, reordered_1g, alternating_1g, random_5g, reordered_5g``."""
    from .parallel import parallel_map

    progress = progress_callback(progress, "mistuning cases")

    if disk_factory is None:
        from ..reference import reference_disk

        def disk_factory(mass):
            return reference_disk("cylinder", mass)

    kappas = paper_kappas(16, PAPER_STD, seed)
    plan = [(1e-3, "random"), (1e-3, "reordered"), (1e-3, "alternating"), (5e-3, "random"), (5e-3, "reordered")]
    masses = sorted({m for m, _ in plan})
    total, done = len(plan) + len(masses), 0
    disks = {m: disk_factory(m) for m in masses}

    def tick(message):
        nonlocal done
        done += 1
        if progress:
            progress(done, total, message)

    tuned = {}
    for m, (p, f, r) in zip(masses, parallel_map(_tuned_case, [(disks[m], f_range_hz, max_step) for m in masses],
                                                processes)):
        tuned[m] = (p, r)
        tick(f"tuned {1e3 * m:g} g: peak {1e3 * p:.4f} mm at {f:.2f} Hz")
    cases = []
    for mass, name in plan:
        sector = 2 if name == "alternating" else None
        kappa = kappas[name]
        cases.append((disks[mass], kappa[:sector] if sector else kappa, f_range_hz, max_step, tuned[mass][0], sector))
    out = {}
    for (mass, name), r in zip(plan, parallel_map(_mistuned_case, cases, processes)):
        key = f"{name}_{1e3 * mass:g}g"
        out[key] = MistuningCase(key, mass, kappas[name], r, tuned[mass][0], tuned[mass][1])
        tick(f"{key}: max peak {1e3 * r.peak_amplitude:.4f} mm (tuned {1e3 * tuned[mass][0]:.4f} mm), "
             f"{len(r.omega)} points")
    return out


def summary_dict(cases: dict[str, MistuningCase]) -> dict:
    """The ``mistuning`` key of summary.json: {case: {kappa: [16], peak_tip_mm: [16], tuned_peak_tip_mm, ...}}."""
    return {k: c.summary() for k, c in cases.items()}


def _relative_spread(values, reference) -> str:
    """Spread of ``values`` relative to ``reference`` in words: 'rounding' below 1e-12, else
    a percentage (no exponent notation: below 0.01 % it says so)."""
    spread = float(np.ptp(values) / reference)
    if spread < 1e-12:
        return "rounding (relative spread below 10^-12)"
    return "less than 0.01 %" if 100 * spread < 0.01 else f"{100 * spread:.2g} %"


#: How the mistuning verdicts are decided (stated in every row of the report): "close to, slightly
#: below the tuned" is a largest mistuned peak within -15 % .. +2 % of the tuned one; "the
#: lowest-amplitude blade has the most different neighbours" holds when its neighbour contrast
#: |k_i - k_i-1| + |k_i - k_i+1| ranks among the 3 largest of the 16; "several blades" is at least
#: 2; "lowers", "helps", "below", "above" need a difference of at least 1 % of the tuned peak (a
#: tie within the peak search's resolution proves nothing); the alternating case's numbers are
#: compared within 30 % of the paper's reductions, as Table 1's
CLOSE_TO_TUNED = (-0.15, 0.02)
CONTRAST_RANK = 3
SEVERAL_BLADES = 2
PEAK_MARGIN = 0.01
ALTERNATING_RELATIVE = 0.30
#: the paper's reductions of the alternating pattern, blades 1 and 2 (Fig. 17)
PAPER_ALTERNATING_PCT = (38.0, 15.0)


def report_lines(summary: dict) -> list[str]:
    """Markdown lines: the paper's statements beside ours, with the tolerance and the verdict of
    each row (the criteria above).

    ``summary`` is :func:`summary_dict`'s output (or summary.json's ``mistuning``)."""
    def peaks(k):
        return np.array(summary[k]["peak_tip_mm"], dtype=float)

    def verdict(ok):
        return "reproduced" if ok else "differs"

    m = 100 * PEAK_MARGIN
    lines = ["## Mistuned disk (16 blades, EO = 1, F_x = 0.1 N, cylinder; 2 % Gaussian kappa, "
             f"seed {PAPER_SEED}; full assembly)", "",
             "| case | paper | bladedamp | tolerance | verdict |", "|---|---|---|---|---|"]
    r1, t1 = peaks("random_1g"), summary["random_1g"]["tuned_peak_tip_mm"]
    lo, hi = CLOSE_TO_TUNED
    ok = 1 + lo <= r1.max() / t1 <= 1 + hi
    lines.append(f"| b, 1 g: largest mistuned vs tuned amplitude | close to, slightly below the tuned | "
                 f"{r1.max():.4f} vs {t1:.4f} mm ({100 * (r1.max() / t1 - 1):+.1f} %) | "
                 f"{100 * lo:+g} % to {100 * hi:+g} % of the tuned | {verdict(ok)} |")
    for key, paper_blade in (("random_1g", "No. 14"), ("reordered_1g", "No. 15")):
        k = np.array(summary[key]["kappa"])
        contrast = np.abs(k - np.roll(k, 1)) + np.abs(k - np.roll(k, -1))
        p = peaks(key)
        lowest, most = int(np.argmin(p)), int(np.argmax(contrast))
        rank = int(np.where(np.argsort(-contrast) == lowest)[0][0]) + 1
        lines.append(f"| {key.split('_')[0]}, 1 g: lowest-amplitude blade has the most different neighbours | "
                     f"yes (blade {paper_blade}) | lowest: blade {lowest + 1} ({p[lowest]:.4f} mm), its neighbour "
                     f"contrast ranks {rank} of {len(k)}; most different neighbours: blade {most + 1} | "
                     f"contrast among the {CONTRAST_RANK} largest | {verdict(rank <= CONTRAST_RANK)} |")
    re1 = peaks("reordered_1g")
    ok = re1.max() <= (1 - PEAK_MARGIN) * r1.max() and re1.max() <= (1 - PEAK_MARGIN) * t1
    lines.append(f"| c, 1 g: reordering gives slightly lower amplitudes, below tuned | yes | max {re1.max():.4f} "
                 f"vs random {r1.max():.4f} mm, tuned {t1:.4f} mm | lower than both by {m:g} % or more | "
                 f"{verdict(ok)} |")
    r5, t5 = peaks("random_5g"), summary["random_5g"]["tuned_peak_tip_mm"]
    n_above = int(np.sum(r5 > (1 + PEAK_MARGIN) * t5))
    lines.append(f"| b, 5 g: several blades exceed the tuned amplitude | yes | {n_above} of {len(r5)} above "
                 f"{t5:.4f} mm by {m:g} % or more (max {r5.max():.4f} mm) | at least {SEVERAL_BLADES} blades | "
                 f"{verdict(n_above >= SEVERAL_BLADES)} |")
    re5 = peaks("reordered_5g")
    ok = re5.max() <= (1 - PEAK_MARGIN) * r5.max() and re5.max() >= (1 + PEAK_MARGIN) * t5
    lines.append(f"| c, 5 g: reordering helps a little, still above tuned | yes | max {re5.max():.4f} vs random "
                 f"{r5.max():.4f} mm, tuned {t5:.4f} mm | below random and above tuned by {m:g} % or more | "
                 f"{verdict(ok)} |")
    al = peaks("alternating_1g")
    red = 100 * (1 - al[:2] / summary["alternating_1g"]["tuned_peak_tip_mm"])
    kap = summary["alternating_1g"]["kappa"]
    lines.append(f"| d, 1 g: alternating +-2 % lowers the amplitudes | yes (blades 1, 2) | "
                 f"{red[0]:.1f} % (blade 1, kappa {kap[0]:.2f}) and {red[1]:.1f} % (blade 2, kappa {kap[1]:.2f}); "
                 f"the odd blades' peaks agree to {_relative_spread(al[0::2], al.max())} | "
                 f"both lowered by {m:g} % or more | {verdict(min(red) >= m)} |")
    tol = [ALTERNATING_RELATIVE * p for p in PAPER_ALTERNATING_PCT]
    ok = all(abs(r - p) <= t for r, p, t in zip(red, PAPER_ALTERNATING_PCT, tol))
    lines.append(f"| d, 1 g: by how much | ~{PAPER_ALTERNATING_PCT[0]:g} % and ~{PAPER_ALTERNATING_PCT[1]:g} % "
                 f"(blades 1, 2) | {red[0]:.1f} % and {red[1]:.1f} % | "
                 f"+- {tol[0]:.2g} and +- {tol[1]:.2g} % points ({100 * ALTERNATING_RELATIVE:g} % of the paper's) | "
                 f"{verdict(ok)} |")
    lines += ["", "The paper's random sample is not given: ours is a 2 % Gaussian draw with the seed above, so "
              "the blade numbers differ; the statements are compared, not the numbers.", ""]
    return lines


def plot_cases(cases: dict[str, MistuningCase], path=None):
    """Figs. 13-17 in one figure (one panel per case)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 8))
    import re

    for ax, (key, c) in zip(axes.ravel(), cases.items()):
        c.response.plot(ax=ax, tuned=c.tuned_response, title=re.sub(r"_(\d+)g$", r", \1 g", key))
    axes.ravel()[-1].axis("off")
    fig.suptitle("Figs. 13-17: reference disk, mistuned blades (random, reordered, alternating)")
    fig.tight_layout()
    for ax, _ in zip(axes.ravel(), cases):
        place_legend(ax, fontsize=8)       # clear of every curve (the largest peak included)
    if path is not None:
        save_figure(fig, path)
    return fig


# ---------------------------------------------------------------------------------------
# Monte Carlo on Dask
# ---------------------------------------------------------------------------------------
#: Monte Carlo per-disk continuation: only the peaks are kept, so the branch is coarse (max_step
#: 0.4, tolerance 1e-6, chord corrector) and only brackets the peaks; the largest blade peaks are
#: then solved on the response curve by the peak condition d|u|/dOmega = 0 (Newton at 1e-10,
#: :meth:`bladedamp.MistunedDisk.solve_peaks`), every local maximum within
#: MONTE_CARLO_PEAK_MARGIN of the largest, which keeps the largest blade peak within 1e-3 of
#: a fine FRF's; above max_step 0.4 the points do not get fewer (the corrector's iterations
#: limit the step); the other blades' peaks are parabola-refined on the coarse branch, less
#: accurate for weak blades on sharp local modes (benchmarks/README.md, 'Moved from the
#: package's docstrings', studies/mistuning.py, 'MONTE_CARLO_MAX_STEP').
MONTE_CARLO_MAX_STEP = 0.4
MONTE_CARLO_TOL = 1e-6
#: local maxima solved by the peak condition: within this fraction of the largest blade peak
#: (parabola-refined): wider than the parabola's error on the largest peak on the coarse
#: branch, narrow enough to solve only a few maxima per disk (benchmarks/README.md, 'Moved from
#: the package's docstrings', studies/mistuning.py)
MONTE_CARLO_PEAK_MARGIN = 0.02
#: the chord corrector (continuation(chord=True)) and its step control: with chord steps a
#: corrector takes more, cheaper iterations, so the step is kept up to 10 of them (the fastest
#: of the counts tried: benchmarks/README.md, 'Moved from the package's docstrings',
#: studies/mistuning.py)
MONTE_CARLO_TARGET_ITERATIONS = 10
#: :func:`auto_range`'s margin for the Monte Carlo's disks: 1 % (FRFs: 3 %). The peaks lie above
#: f_01 min(kappa) (the damper stiffens the blades), so the wider range's first 3 Hz only cost
#: points; a blade whose largest amplitude is at an end still widens the range
MONTE_CARLO_RANGE_MARGIN = 0.01


def _one_disk(disk, assembly, kappa, f_range_hz, settings):
    """Peaks (n,) and their frequencies (n,) of one mistuned disk, the failure's message ('' if
    none) and the harmonic error estimate (NaN if not estimated) (runs on a worker). ``settings``:
    :func:`mistuned_response`'s options, and ``solve_within`` for :meth:`MistunedResponse.peaks`;
    ``assembly``: ``disk``'s tuned full assembly, shared by every disk of the worker (its set-up
    is built on the worker's first disk, :meth:`MistunedDisk.mistuned`)."""
    options = dict(settings)
    solve_within = options.pop("solve_within", None)
    try:
        r = mistuned_response(disk, kappa, f_range_hz, assembly=assembly, **options)
        p, f = r.peaks(solve_within=solve_within)
        return p, f, "", float(r.harmonic_error)
    except RuntimeError as e:  # keep the study going; the failure is recorded
        n = len(kappa)
        return np.full(n, np.nan), np.full(n, np.nan), str(e), float("nan")


def _disk_settings(settings: dict, i: int) -> dict:
    """Disk i's settings: only the first disk gets the harmonic error estimate (it costs about as
    much as the disk's FRF; the harmonics are the same for every disk of the study)."""
    return dict(settings, estimate_harmonic_error=i == 0)


@dataclass
class MonteCarloResult(Saveable):
    """Peaks of N mistuned disks.

    kappa : (N, n) mistuning factors; peak_amplitude : (N, n) peak u_x of every blade [m] (with the
    default Monte Carlo settings, accurate for the largest blade of each disk; see
    :data:`MONTE_CARLO_MAX_STEP` for the accuracy of the others);
    peak_frequency_hz : (N, n); tuned_peak_amplitude [m]; errors : per disk, '' if it converged.
    meta : the settings, the executor, ``elapsed_s`` and ``harmonic_error_first_disk``: the harmonic
        error estimate of disk 0 (relative to its peak; None if it could not be estimated), the one
        disk estimated, for cost (see :meth:`bladedamp.MistunedDisk.frequency_response`).
    """

    kappa: np.ndarray
    peak_amplitude: np.ndarray
    peak_frequency_hz: np.ndarray
    tuned_peak_amplitude: float
    errors: list = field(default_factory=list)
    meta: dict = field(default_factory=dict)

    @property
    def amplification(self) -> np.ndarray:
        """(N,) largest blade peak of each disk over the tuned peak."""
        return self.peak_amplitude.max(axis=1) / self.tuned_peak_amplitude

    @property
    def valid(self) -> np.ndarray:
        return np.all(np.isfinite(self.peak_amplitude), axis=1)

    def confidence_interval(self, level: float = 0.95) -> tuple[float, float]:
        """Confidence interval of the mean amplification (normal approximation)."""
        a = self.amplification[self.valid]
        if a.size < 2:
            return (float(a.mean()), float(a.mean())) if a.size else (float("nan"), float("nan"))
        from scipy.stats import t

        half = t.ppf(0.5 + level / 2, a.size - 1) * a.std(ddof=1) / math.sqrt(a.size)
        return float(a.mean() - half), float(a.mean() + half)

    def quantile_interval(self, q: float = 0.95, level: float = 0.95) -> tuple[float, float, float]:
        """(estimate, low, high) of the q-quantile of the amplification, distribution-free
        (order statistics, binomial)."""
        from scipy.stats import binom

        a = np.sort(self.amplification[self.valid])
        n = a.size
        lo = int(binom.ppf((1 - level) / 2, n, q))
        hi = int(binom.ppf(0.5 + level / 2, n, q))
        return float(np.quantile(a, q)), float(a[max(lo - 1, 0)]), float(a[min(hi, n - 1)])

    def summary(self) -> dict:
        """Amplification statistics of the disks that converged (JSON-able). With no disk
        converged the statistics are None (not NaN) and ``n_failed`` says why."""
        a = self.amplification[self.valid] if len(self.kappa) else np.zeros(0)
        lo, hi = self.confidence_interval() if a.size else (None, None)
        stats = dict(amplification_mean=float(a.mean()), amplification_mean_ci95=[lo, hi],
                     amplification_std=float(a.std(ddof=1)) if a.size > 1 else 0.0,
                     amplification_max=float(a.max()), amplification_min=float(a.min())) if a.size else \
            dict(amplification_mean=None, amplification_mean_ci95=[None, None], amplification_std=None,
                 amplification_max=None, amplification_min=None)
        return {"n_disks": int(len(self.kappa)), "n_failed": int((~self.valid).sum()),
                "tuned_peak_tip_mm": 1e3 * self.tuned_peak_amplitude, **stats, **self.meta}

    def save(self, path) -> Path:
        """``path``.npz: the result, with its errors and meta (:func:`bladedamp.io.save`,
        loads without pickle: :func:`bladedamp.load` or ``MonteCarloResult.load``), and beside
        it ``path``.json: the summary and the errors, for a reader. The summary is built before
        anything is written, so a failure leaves no half-written pair."""
        from ..io import save

        npz = npz_path(path)
        text = json.dumps({"summary": self.summary(), "errors": list(self.errors), "meta": self.meta}, indent=2)
        save(self, npz)
        npz.with_suffix(".json").write_text(text)
        return npz

    def plot(self, ax=None, *, bins: int = 30):
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        a = self.amplification[self.valid]
        ax.hist(a, bins=bins, color=palette.series(0), alpha=0.8)
        lo, hi = self.confidence_interval()
        ax.axvline(a.mean(), color="k", label=f"mean {a.mean():.3f} (95 % CI {lo:.3f}-{hi:.3f})")
        ax.axvline(1.0, color=palette.UNDAMPED, ls="--", lw=1, label="tuned")
        ax.set_xlabel("peak amplification, largest blade / tuned [-]")
        ax.set_ylabel("number of disks [-]")
        place_legend(ax, fontsize=8)
        return ax


#: glibc's mmap threshold of local Dask workers [bytes]: above the 16-blade assembly's dense
#: Jacobians and bordered matrices (321 x 321 doubles, 0.8 MB)
WORKER_MMAP_THRESHOLD = 16 * 2 ** 20


def local_worker_config():
    """Dask config context for local workers without Dask's MALLOC_TRIM_THRESHOLD_ (65536).

    With it glibc returns every freed large block to the system at once, so the dense Jacobians
    (~0.8 MB each, several per residual) are mapped and zero-filled anew each time, which
    slows a worker against a serial disk, more with two workers faulting pages at once. The
    other settings (one BLAS thread per worker) are kept. And with glibc's mmap threshold fixed
    at WORKER_MMAP_THRESHOLD those blocks always come from the heap (timings:
    benchmarks/README.md, 'Moved from the package's docstrings', studies/mistuning.py)."""
    import dask

    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    environ["MALLOC_MMAP_THRESHOLD_"] = str(WORKER_MMAP_THRESHOLD)
    return dask.config.set({"distributed.nanny.pre-spawn-environ": environ})


class DiskWorkers:
    """Where a study's independent disks run: ``with DiskWorkers(scheduler, n_workers) as w:
    w.map(function, shared, items)`` is ``[function(*shared, *item) for item in items]`` in order.

    scheduler : None -> a local Dask cluster (``n_workers`` processes, one thread each; default the
        CPU count; started without Dask's MALLOC_TRIM_THRESHOLD_, see :func:`local_worker_config`),
        no set-up needed, started once for every ``map`` of the block; an address
        ("tcp://host:8786") -> that Dask cluster; "serial" -> in this process, without Dask.
    ``shared`` (e.g. the disk and its tuned assembly) is scattered once per ``map`` to every
    worker, which keeps one copy for all its items; ``function`` must be a module-level function.
    ``progress(done, total)`` is called as items finish. ``description``: what ran them."""

    def __init__(self, scheduler=None, n_workers: int | None = None):
        if n_workers is not None:
            validation.integer("n_workers", n_workers, minimum=1)
        self.scheduler, self.n_workers = scheduler, n_workers
        self.client = self.cluster = None
        self.description = "serial"

    def __enter__(self) -> "DiskWorkers":
        if self.scheduler == "serial":
            return self
        from dask.distributed import Client, LocalCluster

        if self.scheduler is None:
            workers = self.n_workers or os.cpu_count() or 1
            with local_worker_config():
                self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                            dashboard_address=None)
            self.client = Client(self.cluster)
            self.description = f"local cluster, {workers} workers"
        else:
            self.client = Client(self.scheduler)
            self.description = f"scheduler {self.scheduler}"
        return self

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        self.client = self.cluster = None
        return False

    def map(self, function, shared: tuple, items: list, progress=None) -> list:
        items = list(items)
        results = [None] * len(items)
        if self.client is None:
            for i, item in enumerate(items):
                results[i] = function(*shared, *item)
                if progress:
                    progress(i + 1, len(items))
            return results
        from dask.distributed import as_completed

        # scattered once: each worker keeps one copy of the shared objects for all its items (the
        # harmonic-balance systems are built there, on its first item: they are not pickled)
        shared_futures = self.client.scatter(list(shared), broadcast=True)
        futures = [self.client.submit(function, *shared_futures, *item, pure=False) for item in items]
        index = {f.key: i for i, f in enumerate(futures)}
        for done, future in enumerate(as_completed(futures), 1):
            results[index[future.key]] = future.result()
            if progress:
                progress(done, len(items))
        return results


def monte_carlo(disk: TunedDisk, n_disks: int, std: float = PAPER_STD, seed=0, f_range_hz=None,
                harmonics=(1,), max_step: float = MONTE_CARLO_MAX_STEP, scheduler=None, n_workers: int | None = None,
                progress=None, out=None, tuned_peak_amplitude: float | None = None, tol: float = MONTE_CARLO_TOL,
                n_samples: int | None = None, peak_margin: float | None = MONTE_CARLO_PEAK_MARGIN,
                chord: bool = True, target_iterations: int = MONTE_CARLO_TARGET_ITERATIONS) -> MonteCarloResult:
    """Peak amplification of ``n_disks`` randomly mistuned copies of ``disk`` (full assemblies).

    max_step, tol, n_samples : continuation step, tolerance and AFT samples of each disk
        (see :data:`MONTE_CARLO_MAX_STEP`); the tuned peak (unless given) is an FRF at the
        default accuracy of :func:`tuned_peak`.
    peak_margin : local maxima within this fraction of each disk's largest blade peak are solved
        by the peak condition (:meth:`MistunedResponse.peaks` ``solve_within``; None: the
        parabola through the branch only). chord, target_iterations : the continuation's
        corrector (see :data:`MONTE_CARLO_TARGET_ITERATIONS`).

    scheduler : None -> a local Dask cluster (``n_workers`` processes, one thread each; default
        the CPU count; started without Dask's MALLOC_TRIM_THRESHOLD_, see
        :func:`local_worker_config`), no set-up needed; an address ("tcp://host:8786") -> that
        Dask cluster (start its workers with MALLOC_TRIM_THRESHOLD_ unset for the same speed);
        "serial" -> in this process, without Dask.
    progress : True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
        (done, total) after every disk.  out : path stem for npz/json results.
    Kappa of disk i is ``random_kappa(n, std, seed=[seed, i])`` (reproducible, independent of the
    scheduling).
    """
    n_disks = validation.integer("n_disks", n_disks, minimum=1)
    progress = progress_callback(progress, "Monte Carlo disks")
    n = disk.n_blades
    kappas = disk_kappas(n, n_disks, std, seed)
    settings = dict(harmonics=tuple(harmonics), max_step=validation.positive("max_step", max_step),
                    tol=validation.positive("tol", tol), n_samples=n_samples, chord=bool(chord),
                    target_iterations=validation.integer("target_iterations", target_iterations, minimum=1),
                    solve_within=peak_margin, range_margin=MONTE_CARLO_RANGE_MARGIN)
    if n_workers is not None:
        validation.integer("n_workers", n_workers, minimum=1)
    t0 = time.perf_counter()
    if tuned_peak_amplitude is None:
        tuned_peak_amplitude = tuned_peak(disk, f_range_hz or auto_range(disk, [1.0], 0.05), harmonics)[0]
    # the tuned full assembly, whose harmonic-balance set-up every disk shares (built once per
    # process, a noticeable share of a disk's time when each disk built its own)
    assembly = MistunedDisk.from_tuned(disk)
    with DiskWorkers(scheduler, n_workers) as workers:
        results = workers.map(_one_disk, (disk, assembly),
                              [(k, f_range_hz, _disk_settings(settings, i)) for i, k in enumerate(kappas)], progress)
        used = workers.description
    elapsed = time.perf_counter() - t0
    res = MonteCarloResult(kappas, np.array([r[0] for r in results]), np.array([r[1] for r in results]),
                           float(tuned_peak_amplitude), [r[2] for r in results],
                           {"std": std, "seed": int(seed), "f_range_hz": None if f_range_hz is None else list(f_range_hz), "harmonics": list(harmonics),
                            "max_step": max_step, "tol": tol, "n_samples": n_samples, "peak_margin": peak_margin,
                            "chord": bool(chord), "target_iterations": target_iterations,
                            "range_margin": None if f_range_hz is not None else MONTE_CARLO_RANGE_MARGIN, "executor": used,
                            "elapsed_s": elapsed, "harmonic_error_first_disk":
                                None if not np.isfinite(results[0][3]) else results[0][3],
                            "disk": {"n_blades": n, "engine_order": disk.engine_order,
                                     "damper": None if disk.damper is None else disk.damper.kind,
                                     "mass_g": None if disk.damper is None else 1e3 * disk.damper.mass}})
    if out is not None:
        res.save(out)
    return res


# ---------------------------------------------------------------------------------------
# arrangement optimisation
# ---------------------------------------------------------------------------------------
@dataclass
class Arrangement(Saveable):
    """Result of :func:`optimise_arrangement` (orders index the given blade set)."""

    kappa: np.ndarray
    order: np.ndarray
    max_peak_amplitude: float
    heuristic_order: np.ndarray
    heuristic_max_peak_amplitude: float
    given_max_peak_amplitude: float
    tuned_peak_amplitude: float
    evaluations: int
    history: list
    response: MistunedResponse = None

    @property
    def gain_over_given(self) -> float:
        """Relative reduction of the largest peak vs the given (random) order."""
        return 1 - self.max_peak_amplitude / self.given_max_peak_amplitude

    @property
    def gain_over_heuristic(self) -> float:
        return 1 - self.max_peak_amplitude / self.heuristic_max_peak_amplitude


def optimise_arrangement(disk: TunedDisk, kappa, max_evaluations: int = 30, candidates: int = 3,
                         f_range_hz=None, max_step: float = 0.05, progress=None,
                         tuned_peak_amplitude: float | None = None) -> Arrangement:
    """Blade order minimising the largest blade peak of the full assembly.

    Search: start from :func:`reorder` (the heuristic); at every step the blade with the largest
    peak is swapped with the ``candidates`` positions that most increase the frequency contrast
    to its new neighbours (cyclic); each candidate is verified by a full-assembly FRF and the best
    improving swap is kept (steepest descent on the true objective). Stops when no candidate
    improves or after ``max_evaluations`` FRFs. The given order and the heuristic are evaluated too.
    """
    k = check_kappa(kappa, disk.n_blades)
    max_evaluations = validation.integer("max_evaluations", max_evaluations, minimum=2)
    if tuned_peak_amplitude is None:
        tuned_peak_amplitude = tuned_peak(disk, f_range_hz or auto_range(disk, [1.0], 0.05), max_step=max_step)[0]
    cache = {}

    def evaluate(order):
        key = tuple(int(o) for o in order)
        if key not in cache:
            r = mistuned_response(disk, k[list(key)], f_range_hz, max_step=max_step, tuned_peak_amplitude=tuned_peak_amplitude)
            cache[key] = r
            if progress:
                progress(len(cache), max_evaluations, f"max peak {1e3 * r.peak_amplitude:.4f} mm")
        return cache[key]

    given = np.arange(k.size)
    r_given = evaluate(given)
    heuristic = reorder(k)
    r_best = evaluate(heuristic)
    best = heuristic.copy()
    history = [float(r_given.peak_amplitude), float(r_best.peak_amplitude)]
    n = k.size
    while len(cache) < max_evaluations:
        p = int(np.argmax(r_best.blade_peak_amplitudes))
        scores = []
        for j in range(n):
            if j == p:
                continue
            o = best.copy()
            o[p], o[j] = o[j], o[p]
            kk = k[o]
            c = sum(abs(kk[i] - kk[(i + 1) % n]) + abs(kk[i] - kk[i - 1]) for i in (p, j))
            scores.append((-c, j, o))
        scores.sort(key=lambda s: s[0])
        improved = None
        for _, _, o in scores[:candidates]:
            if len(cache) >= max_evaluations:
                break
            r = evaluate(o)
            if r.peak_amplitude < r_best.peak_amplitude and (improved is None or r.peak_amplitude < improved[1].peak_amplitude):
                improved = (o, r)
        if improved is None:
            break
        best, r_best = improved
        history.append(float(r_best.peak_amplitude))
    return Arrangement(k, best, float(r_best.peak_amplitude), heuristic, float(cache[tuple(heuristic)].peak_amplitude),
                       float(r_given.peak_amplitude), float(tuned_peak_amplitude), len(cache), history, r_best)
