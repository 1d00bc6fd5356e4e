"""Designs robust to mistuning (issue 36 item 3): the mistuned statistics' perturbation estimate
and an objective over mistuned disks with its gradient.

**Perturbation estimate.** On the tuned disk written out as a full assembly every blade has the
same peak A0. Blade j's peak in the mistuning factors kappa is, to first order,

    A_j(1 + d) = A0 + g . S_j d,     (S_j d)[m] = d[m + j mod n]

with g = dA_0/dkappa (n,) blade 0's analytic gradient (one peak and its derivatives in
``mistuning.kappa[k]``, :meth:`~bladedamp.diskmodel.DiskModelResponse.peak_sensitivities`):
rotating the disk by j sectors maps blade 0 onto blade j and shifts the travelling-wave excitation
by a phase only, so every blade's derivatives are blade 0's shifted (tested against blade 1's own).
The statistics of the largest blade peak max_j A_j for kappa ~ 1 + std N(0, I) are sampled from
this expansion (no solve), and its error is measured, not guessed: a few check disks are solved
in full, and the remainder (solved - first order) gives the stated error (its mean plus two
standard errors) and, used as a control variate, a corrected mean. A second-order term was tried
and dropped: the central differences of the analytic gradient in kappa are not symmetric
(max |H - H'| / max |H| = 0.72-0.93 at steps 3e-6-1e-5 on the reference disk) and change with the
step, because sampled friction puts kinks into the peak as a function of kappa (as in the
frequency, :mod:`bladedamp.hbm.sensitivity`).

Friction-damped disks are sensitive: on the reference cylinder of 1 g the largest blade peak
rises 5-12 % at a standard deviation of only 0.05 % (the tuned disk's double modes split by more
than the damping separates them), and the first-order estimate's remainder is then already a
third of the rise; the check disks say so.

**Robust objective.** A statistic (the mean, or a quantile) of the largest blade peak over
``n_disks`` mistuned copies of a design, the copies' factors drawn once (common random numbers:
``random_kappa(n, std, seed=[seed, i])``, the Monte Carlo's), so the objective is a smooth function
of the design between the switches of the largest blade, and its gradient is the same statistic
of each disk's peak derivatives (the analytic mistuned sensitivities). The disks run where the
Monte Carlo's do (:class:`~bladedamp.studies.mistuning.DiskWorkers`: serial, a local Dask cluster
or a scheduler).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import validation
from ..diskmodel import parameter_unit, parse_parameter_key
from ..io import Saveable
from ..mistuned import MistunedDisk
from .gradient import DesignOptimum, default_bounds, optimal_design
from .mistuning import (MONTE_CARLO_MAX_STEP, MONTE_CARLO_RANGE_MARGIN, MONTE_CARLO_TARGET_ITERATIONS, PAPER_STD,
                        DiskWorkers, disk_kappas, mistuned_response, random_kappa)

#: the continuation of each mistuned disk: the Monte Carlo's coarse branch (its peaks are solved
#: by the peak condition), tolerance 1e-8, chosen tighter than the Monte Carlo's 1e-6 as a margin
#: for the peak derivatives' Newton solves beside the peak; measured afterwards on 12 copies of the
#: reference cylinder at std 2 %: 1e-6 gives the same peaks and derivatives within 3e-4 and no
#: failure, at 25 % less CPU (benchmarks/README.md), a saving not yet taken
ROBUST_TOL = 1e-8
#: a copy whose peak cannot be differentiated on the coarse branch is solved again on the branch of
#: a full FRF (max_step 0.05 Hz, tolerance 1e-10): a random 8-blade wedge at EO 3 (std 2 %) had one
#: copy of three whose coarse branch (0.4 and 0.1 Hz) led the peak solve to a blade's local maximum
#: 0.1 Hz below the largest blade's peak, which the fine branch finds
FINE_SETTINGS = dict(max_step=0.05, tol=1e-10, chord=False, target_iterations=5)
#: check disks of the perturbation estimate: solved in full to measure its remainder (16: the
#: remainder's standard error falls as 1/4 of its spread, at the cost of 16 Monte Carlo disks)
N_CHECK_DISKS = 16
#: the stated error is the check disks' mean remainder plus this many of its standard errors
#: (about a 95 % interval for 16 disks)
ERROR_STANDARD_ERRORS = 2.0


def disk_settings(harmonics=(1,), max_step: float = MONTE_CARLO_MAX_STEP, tol: float = ROBUST_TOL) -> dict:
    """The per-disk continuation settings of this module's solves (:func:`mistuned_response`'s options)."""
    return dict(harmonics=tuple(harmonics), max_step=validation.positive("max_step", max_step),
                tol=validation.positive("tol", tol), chord=True, target_iterations=MONTE_CARLO_TARGET_ITERATIONS,
                range_margin=MONTE_CARLO_RANGE_MARGIN, estimate_harmonic_error=False)


def mistuned_peak(disk, assembly, kappa, parameters, f_range_hz, settings, blade=None):
    """The peak derivatives (:class:`~bladedamp.response.PeakSensitivities`) of ``disk`` with blade
    factors ``kappa`` (``assembly``: its tuned full assembly, shared) in the keys ``parameters``:
    of blade ``blade``'s peak, or of the largest blade's (None). Where the coarse branch of
    ``settings`` misleads the peak solve (close peaks of several blades), once more on the fine
    branch :data:`FINE_SETTINGS`. Runs on a worker: returns (result, '') or (None, the reasons it
    failed)."""
    reasons = []
    for options in (settings, dict(settings, **FINE_SETTINGS)):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                response = mistuned_response(disk, kappa, f_range_hz, assembly=assembly, **options)
                return response.peak_sensitivities(parameters, blade=blade), ""
        except (RuntimeError, ValueError) as exc:
            reasons.append(f"max_step {options['max_step']:g}: {exc}")
    return None, "; ".join(reasons)


@dataclass
class MistuningGradient(Saveable):
    """Blade 0's peak of the tuned disk and its analytic gradient in the mistuning factors
    (:func:`mistuning_gradient`); every blade's by the cyclic shift (module docstring).

    tuned_peak_amplitude : A0 [m]; tuned_peak_frequency_hz [Hz]; gradient : (n,) dA_0/dkappa_k [m]
    """

    tuned_peak_amplitude: float
    tuned_peak_frequency_hz: float
    gradient: np.ndarray
    meta: dict = field(default_factory=dict)

    @property
    def n_blades(self) -> int:
        return len(self.gradient)

    def blade_peaks(self, kappa) -> np.ndarray:
        """(N, n) every blade's first-order peak A0 + g . S_j (kappa - 1) [m] for the factors
        ``kappa`` (N, n) (or (n,))."""
        d = np.atleast_2d(np.asarray(kappa, dtype=float)) - 1.0
        if d.shape[1] != self.n_blades:
            raise ValueError(f"kappa must have {self.n_blades} columns, one per blade (got shape {d.shape})")
        return self.tuned_peak_amplitude + np.stack([np.roll(d, -j, axis=1) @ self.gradient
                                                     for j in range(self.n_blades)], axis=1)

    def largest_peaks(self, kappa) -> np.ndarray:
        """(N,) the largest blade's first-order peak [m] for the factors ``kappa`` (N, n)."""
        return self.blade_peaks(kappa).max(axis=1)


@dataclass
class PerturbationEstimate(Saveable):
    """Statistics of the largest blade peak of randomly mistuned disks, kappa ~ 1 + std N(0, I)
    (:func:`perturbation_estimate`).

    std : the standard deviation of kappa; quantile : the quantile reported (e.g. 0.95)
    tuned_peak_amplitude : A0 [m] (the expansion's, blade 0 of the tuned full assembly)
    mean : the mean largest blade peak of the first-order expansion [m] (``n_samples`` draws)
    quantile_value : its ``quantile`` [m]
    check_kappa : (m, n) the check disks' factors; check_peaks : (m,) their solved largest blade
        peaks [m]; check_first_order : (m,) the expansion's there [m]
    error : the first-order mean's stated error [m]: |mean remainder| + ERROR_STANDARD_ERRORS
        standard errors of it, the remainder (solved - first order) measured on the check disks
    corrected_mean : mean + the mean remainder (the check disks as a control variate) [m], whose
        standard error is ``corrected_error`` [m]
    """

    std: float
    quantile: float
    tuned_peak_amplitude: float
    mean: float
    quantile_value: float
    n_samples: int
    check_kappa: np.ndarray
    check_peaks: np.ndarray
    check_first_order: np.ndarray

    @property
    def remainder(self) -> np.ndarray:
        """(m,) solved minus first-order largest blade peak on the check disks [m]."""
        return self.check_peaks - self.check_first_order

    @property
    def corrected_error(self) -> float:
        r = self.remainder
        return float(r.std(ddof=1) / np.sqrt(len(r))) if len(r) > 1 else float("inf")

    @property
    def error(self) -> float:
        return float(abs(self.remainder.mean()) + ERROR_STANDARD_ERRORS * self.corrected_error)

    @property
    def corrected_mean(self) -> float:
        return float(self.mean + self.remainder.mean())

    def table(self) -> str:
        a0 = self.tuned_peak_amplitude
        return "\n".join([
            f"mistuning std {100 * self.std:.3g} %, tuned peak {1e3 * a0:.4f} mm ({self.n_samples} samples of the "
            f"first-order expansion, {len(self.check_peaks)} check disks solved)",
            f"mean largest blade peak, first order  {1e3 * self.mean:.4f} mm (amplification {self.mean / a0:.4f}) "
            f"+- {1e3 * self.error:.3g} mm",
            f"{100 * self.quantile:g} % quantile, first order      {1e3 * self.quantile_value:.4f} mm",
            f"mean with the check disks' remainder  {1e3 * self.corrected_mean:.4f} mm +- {1e3 * self.corrected_error:.3g} mm"])


def kappa_keys(n_blades: int) -> tuple:
    return tuple(f"mistuning.kappa[{k}]" for k in range(n_blades))


def mistuning_gradient(disk, f_range_hz=None, harmonics=(1,)) -> MistuningGradient:
    """Blade 0's peak of ``disk`` (a TunedDisk) written out as a full assembly and its analytic
    gradient in the n mistuning factors (one frequency response and its peak derivatives).
    ``f_range_hz``: default :func:`auto_range` (the Monte Carlo's margin). ValueError where the peak
    cannot be solved."""
    keys = kappa_keys(disk.n_blades)
    tuned, reason = mistuned_peak(disk, MistunedDisk.from_tuned(disk), np.ones(disk.n_blades), keys, f_range_hz,
                                  disk_settings(harmonics), blade=0)
    if tuned is None:
        raise ValueError(f"the tuned disk's peak of blade 0 could not be differentiated: {reason}")
    return MistuningGradient(float(tuned.peak_amplitude), float(tuned.peak_frequency_hz),
                             np.asarray(tuned.d_peak_amplitude, dtype=float),
                             {"harmonics": list(harmonics), "f_range_hz": None if f_range_hz is None else list(f_range_hz)})


def perturbation_estimate(disk, std: float = PAPER_STD, quantile: float = 0.95, n_check: int = N_CHECK_DISKS,
                          seed=0, n_samples: int = 200_000, f_range_hz=None, harmonics=(1,), gradient=None,
                          scheduler="serial", n_workers: int | None = None, progress=None) -> PerturbationEstimate:
    """The mean and ``quantile`` of the largest blade peak of ``disk`` (a TunedDisk) under random
    mistuning kappa ~ 1 + ``std`` N(0, I), from the first-order expansion (``gradient``: a
    :class:`MistuningGradient`, default :func:`mistuning_gradient`) sampled ``n_samples`` times, its
    error stated from ``n_check`` disks solved in full (their factors ``random_kappa(n, std,
    seed=[seed, i, 1])``: a stream of their own, on ``scheduler`` as :class:`DiskWorkers`).
    ValueError where a peak cannot be solved."""
    std = validation.nonnegative("std (standard deviation of kappa)", std)
    quantile = validation.in_range("quantile", quantile, 0.0, 1.0)
    n_samples = validation.integer("n_samples", n_samples, minimum=2)
    n_check = validation.integer("n_check (check disks)", n_check, minimum=2)
    if gradient is None:
        gradient = mistuning_gradient(disk, f_range_hz, harmonics)
    kappa = 1.0 + std * np.random.default_rng([int(seed), 0]).standard_normal((n_samples, disk.n_blades))
    first = gradient.largest_peaks(kappa)
    check = np.array([random_kappa(disk.n_blades, std, seed=[int(seed), i, 1]) for i in range(n_check)])
    assembly = MistunedDisk.from_tuned(disk)
    items = [(k, (), f_range_hz, disk_settings(harmonics)) for k in check]
    with DiskWorkers(scheduler, n_workers) as workers:
        results = workers.map(mistuned_peak, (disk, assembly), items, progress)
    failed = [reason for result, reason in results if result is None]
    if failed:
        raise ValueError(f"{len(failed)} of {n_check} check disks could not be solved ({failed[0]})")
    return PerturbationEstimate(std, quantile, gradient.tuned_peak_amplitude, float(first.mean()),
                                float(np.quantile(first, quantile)), n_samples, check,
                                np.array([result.peak_amplitude for result, _ in results]),
                                gradient.largest_peaks(check))


# ---------------------------------------------------------------------------------------
# the robust objective
# ---------------------------------------------------------------------------------------
def check_statistic(statistic):
    """``statistic``: "mean" or a quantile in [0, 1] (a float); ValueError naming it otherwise."""
    if isinstance(statistic, str) and statistic == "mean":
        return statistic
    if isinstance(statistic, (bool, str)) or not np.isscalar(statistic):
        raise ValueError(f"statistic must be \"mean\" or a quantile in [0, 1] (got {statistic!r})")
    return validation.in_range("statistic (a quantile)", statistic, 0.0, 1.0)


def statistic_weights(values: np.ndarray, statistic) -> np.ndarray:
    """(N,) weights w with the ``statistic`` of ``values`` = w . values: "mean", or a quantile in
    (0, 1) (numpy's linear interpolation between the two order statistics around it)."""
    n = len(values)
    if check_statistic(statistic) == "mean":
        return np.full(n, 1.0 / n)
    q = float(statistic)
    order = np.argsort(values, kind="stable")
    position = q * (n - 1)
    low = int(np.floor(position))
    high = min(low + 1, n - 1)
    w = np.zeros(n)
    w[order[low]] += 1.0 - (position - low)
    w[order[high]] += position - low
    return w


def design_values(disk, keys) -> np.ndarray:
    """(k,) the tuned ``disk``'s values of the design-file ``keys``, checked before any copy is
    solved: ValueError naming a key that is unknown, out of range, or a blade's mistuning factor
    (the copies' factors are drawn, not designed)."""
    values = []
    for key in keys:
        name, _ = parse_parameter_key(key)
        if name == "mistuning.kappa":
            raise ValueError(f"parameter {key!r}: the mistuned copies' factors are random, not a design parameter")
        try:
            values.append(disk.parameter_value(key))
        except IndexError:
            raise ValueError(f"parameter {key!r}: index out of range for this disk") from None
    return np.array(values, dtype=float)


@dataclass
class MistunedObjective(Saveable):
    """A statistic of the largest blade peak over mistuned copies of a design and its gradient
    (:func:`robust_objective`).

    parameters, units, values : (k,) the design-file keys, units and the design's values
    statistic : "mean" or the quantile; std, seed : the copies' mistuning (common random numbers)
    value : the statistic [m]; gradient : (k,) its derivatives [m per unit]
    kappa : (N, n) the copies' factors; disk_peaks : (N,) each copy's largest blade peak [m];
    disk_frequencies_hz : (N,); disk_gradients : (N, k) [m per unit]; errors : (N,) '' where solved
    """

    parameters: tuple
    units: tuple
    values: np.ndarray
    statistic: object
    std: float
    seed: int
    value: float
    gradient: np.ndarray
    kappa: np.ndarray
    disk_peaks: np.ndarray
    disk_frequencies_hz: np.ndarray
    disk_gradients: np.ndarray
    errors: list

    @property
    def frequency_hz(self) -> float:
        """The mean frequency of the copies' largest blade peaks [Hz]."""
        return float(np.nanmean(self.disk_frequencies_hz))


def robust_objective(disk, parameters, std: float = PAPER_STD, n_disks: int = 20, seed=0, statistic="mean",
                     f_range_hz=None, harmonics=(1,), scheduler="serial", n_workers: int | None = None,
                     workers: DiskWorkers | None = None, progress=None) -> MistunedObjective:
    """The ``statistic`` ("mean" or a quantile in (0, 1)) of the largest blade peak of ``n_disks``
    mistuned copies of ``disk`` (a TunedDisk; copy i's factors ``random_kappa(n, std, seed=[seed,
    i])``, as the Monte Carlo's) and its gradient in the design-file keys ``parameters`` (each
    copy's peak derivatives, weighted as the statistic weights the peaks). ``f_range_hz``: None ->
    each copy's :func:`auto_range`. The copies run on ``workers`` (an open :class:`DiskWorkers`) or
    on ``scheduler``. ValueError if a copy's peak cannot be solved or differentiated (its reason)."""
    keys = tuple(str(p) for p in parameters)
    n_disks = validation.integer("n_disks", n_disks, minimum=1)
    statistic = check_statistic(statistic)
    values = design_values(disk, keys)
    kappas = disk_kappas(disk.n_blades, n_disks, std, seed)
    settings = disk_settings(harmonics)
    assembly = MistunedDisk.from_tuned(disk)
    items = [(k, keys, f_range_hz, settings) for k in kappas]
    if workers is None:
        with DiskWorkers(scheduler, n_workers) as own:
            results = own.map(mistuned_peak, (disk, assembly), items, progress)
    else:
        results = workers.map(mistuned_peak, (disk, assembly), items, progress)
    errors = [reason for _, reason in results]
    failed = [e for e in errors if e]
    if failed:
        raise ValueError(f"{len(failed)} of {n_disks} mistuned copies could not be differentiated "
                         f"({failed[0]}): no robust objective")
    peaks = np.array([r.peak_amplitude for r, _ in results])
    gradients = np.array([r.d_peak_amplitude for r, _ in results]).reshape(n_disks, len(keys))
    w = statistic_weights(peaks, statistic)
    return MistunedObjective(keys, tuple(parameter_unit(k) for k in keys), values, statistic, float(std), int(seed),
                             float(w @ peaks), w @ gradients, kappas, peaks,
                             np.array([r.peak_frequency_hz for r, _ in results]), gradients, errors)


def robust_design(disk, parameters, bounds=None, std: float = PAPER_STD, n_disks: int = 20, seed=0,
                  statistic="mean", f_range_hz=None, harmonics=(1,), scheduler="serial",
                  n_workers: int | None = None, **options) -> DesignOptimum:
    """The design within ``bounds`` ((k, 2), default :func:`default_bounds`) whose
    :func:`robust_objective` is lowest: :func:`~bladedamp.studies.gradient.optimal_design`'s search
    (screening, then L-BFGS-B with the analytic gradient; ``options``: its n_starts, n_screen,
    max_iterations) on the objective instead of the tuned peak; the disks of every evaluation on
    one :class:`DiskWorkers`. The optimum's ``peak_amplitude`` is the statistic there [m]."""
    keys = tuple(str(p) for p in parameters)
    if bounds is None:
        bounds = [default_bounds(disk, k) for k in keys]
    with DiskWorkers(scheduler, n_workers) as workers:
        def evaluate(model):
            result = robust_objective(model, keys, std, n_disks, seed, statistic, f_range_hz, harmonics,
                                      workers=workers)
            return result.value, result.frequency_hz, result.gradient

        label = "mean" if statistic == "mean" else f"{100 * statistic:g} % quantile"
        return optimal_design(disk, keys, bounds, f_range_hz, harmonics, evaluate=evaluate,
                              objective=f"{label} of the largest blade peak of {n_disks} mistuned disks "
                                        f"(std {100 * std:g} %, seed {seed})", **options)
