"""Gradient-based damper design over several parameters together (issue 36 item 2).

The objective is the resonance peak of the tuned disk's tip amplitude in x over a frequency
range; its gradient in the design-file keys comes with it from one frequency response
(:meth:`~bladedamp.diskmodel.DiskModelResponse.peak_sensitivities`: the analytic dR/dp and the
implicit function theorem). A damper's peak over its mass has one minimum, but over angles and
masses together it need not (the reference cylinder over mass and gamma_L has one near 27 deg and
a lower one on the bound 60 deg). So the search screens first: the peak at the design and at
``n_screen`` points of a scrambled Sobol sequence in the box (seeded; 4 per parameter by
default); then scipy's L-BFGS-B minimises within the bounds from the ``n_starts`` best of them
(one per parameter by default: one start from the best screened point ended in the 27 deg basin).
Parameters whose bounds span more than a decade (the mass) are searched in their logarithm.

Each evaluation is one frequency response and its peak's derivatives; a design whose response
fails or whose peak cannot be solved there (at an end of the range: the resonance left it) ends
that start, which keeps the best point it had.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import validation
from ..diskmodel import parameter_unit
from ..io import Saveable

#: bounds whose ratio high / low exceeds this are searched in the logarithm of the parameter
LOG_SCALE_RATIO = 10.0
#: a start ends once an iteration lowers the peak by less than this [mm] (L-BFGS-B's ftol on the
#: peak in mm): 0.1 um, below the harmonic balance's own accuracy of a peak (about 1 %); the AFT's
#: kinks keep the gradient from vanishing, so the gradient test alone would not end a start
PEAK_TOLERANCE_MM = 1e-4


@dataclass
class DesignOptimum(Saveable):
    """The lowest resonance peak found over several design parameters (:func:`optimal_design`).

    parameters, units : (k,) the design-file keys and their units
    bounds : (k, 2) the search box [the keys' units]
    initial : (k,) the design's values; optimum : (k,) the best design found
    peak_amplitude : its peak tip amplitude u_x [m]; peak_frequency_hz : its frequency [Hz]
    initial_peak_amplitude : the design's own peak [m]
    d_peak_amplitude : (k,) the peak's derivatives at the optimum [m per unit] (zero in a
        direction where the optimum is interior; of the sign that leaves the box where on a bound)
    at_bound : (k,) whether each optimal value lies on its bound
    starts : (s, k) the local searches' starting points (the best screened); start_peaks : (s,) the
        peak each ended on [m] (NaN: it failed)
    n_responses : objective evaluations in all (frequency responses of the tuned disk by default)
    success, message : whether a start converged (the optimiser's test), and what happened
    objective : what was minimised ("peak of the tuned disk", or a statistic over mistuned disks:
        :func:`bladedamp.studies.robust.robust_design`); ``peak_amplitude`` and its derivatives are its value
    """

    parameters: tuple
    units: tuple
    bounds: np.ndarray
    initial: np.ndarray
    optimum: np.ndarray
    peak_amplitude: float
    peak_frequency_hz: float
    initial_peak_amplitude: float
    d_peak_amplitude: np.ndarray
    at_bound: np.ndarray
    starts: np.ndarray
    start_peaks: np.ndarray
    n_responses: int
    success: bool
    message: str
    objective: str = "peak of the tuned disk"

    def __getitem__(self, key: str) -> float:
        if key not in self.parameters:
            raise KeyError(f"{key!r} (the parameters are {', '.join(self.parameters)})")
        return float(self.optimum[self.parameters.index(key)])

    @property
    def reduction(self) -> float:
        """1 - peak at the optimum / the design's own peak [-]."""
        return 1.0 - self.peak_amplitude / self.initial_peak_amplitude

    def table(self) -> str:
        """The optimum as text: each parameter's start, optimum and bounds, the peaks."""
        width = max(len(k) for k in self.parameters)
        lines = [f"{'parameter':<{width}}  {'design':>10}  {'optimum':>10}  {'bounds':>20}"]
        for j, key in enumerate(self.parameters):
            low, high = self.bounds[j]
            flag = "  (on a bound)" if self.at_bound[j] else ""
            lines.append(f"{key:<{width}}  {self.initial[j]:>10.5g}  {self.optimum[j]:>10.5g}  "
                         f"{f'[{low:.4g}, {high:.4g}]':>20}  {self.units[j]}{flag}")
        what = "peak" if self.objective == "peak of the tuned disk" else self.objective
        lines.append(f"{what} {1e3 * self.peak_amplitude:.4f} mm at {self.peak_frequency_hz:.3f} Hz against "
                     f"{1e3 * self.initial_peak_amplitude:.4f} mm of the design ({100 * self.reduction:.1f} % lower); "
                     f"{self.n_responses} {'frequency responses' if what == 'peak' else 'evaluations'}; {self.message}")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Each start's path is not kept; this draws the starts' final peaks against the optimum's
        (mm), one bar per start; returns the figure."""
        import matplotlib.pyplot as plt

        if ax is None:
            fig, ax = plt.subplots(figsize=(6.5, 3.8), constrained_layout=True)
        else:
            fig = ax.figure
        starts = np.arange(len(self.start_peaks))
        ax.bar(starts, 1e3 * np.nan_to_num(self.start_peaks, nan=0.0), color="C0")
        ax.axhline(1e3 * self.initial_peak_amplitude, color="0.4", ls="--", label="the design's peak")
        ax.axhline(1e3 * self.peak_amplitude, color="C1", label="optimum")
        ax.set_xticks(starts, [f"start {s + 1}" for s in starts])
        ax.set_ylabel("peak tip amplitude [mm]")
        ax.grid(axis="y", alpha=0.3)
        ax.legend(fontsize="small")
        return fig


#: the search box of a key without one given, in the key's unit (a chosen, practical range:
#: platform angles 15-65 deg as in the paper's studies, a cylinder radius 0.5-5 mm); any other
#: key: its value -50 % to +100 %
DEFAULT_BOUNDS = {"disk.gamma_left_deg": (15.0, 65.0), "disk.gamma_right_deg": (15.0, 65.0),
                  "damper.cylinder_radius_mm": (0.5, 5.0)}


def default_bounds(disk, key: str, mass_bounds_g=(0.01, 20.0)) -> tuple[float, float]:
    """The search box (low, high) of design-file ``key`` [its unit]: ``mass_bounds_g`` for
    ``damper.mass_g`` (the design's [analysis] mass_range_g), :data:`DEFAULT_BOUNDS`, else the
    value's -50 % to +100 %."""
    if key == "damper.mass_g":
        return tuple(float(m) for m in mass_bounds_g)
    if key in DEFAULT_BOUNDS:
        return DEFAULT_BOUNDS[key]
    value = disk.parameter_value(key)
    return tuple(sorted((0.5 * value, 2.0 * value)))


def sobol_starts(bounds: np.ndarray, n: int, seed: int, log: np.ndarray) -> np.ndarray:
    """(n, k) points of a scrambled Sobol sequence in the box ``bounds`` (k, 2) (logarithmic in
    the parameters ``log`` marks), seeded."""
    from scipy.stats import qmc

    if n <= 0:
        return np.zeros((0, len(bounds)))
    unit = qmc.Sobol(len(bounds), scramble=True, seed=seed).random(n)
    low, high = bounds[:, 0], bounds[:, 1]
    return np.where(log, np.exp(np.log(low) + unit * (np.log(high) - np.log(low))), low + unit * (high - low))


def optimal_design(disk, parameters, bounds, f_range_hz, harmonics=(1,), n_starts: int | None = None,
                   n_screen: int | None = None, seed: int = 0, max_iterations: int = 25, evaluate=None,
                   objective: str = "peak of the tuned disk", **options) -> DesignOptimum:
    """The lowest resonance peak of ``disk`` (a TunedDisk) over the design-file keys ``parameters``
    within ``bounds`` ((k, 2) [the keys' units]): the peak at the design and at ``n_screen`` Sobol
    points (``seed``; default 4 k), then L-BFGS-B with the analytic gradient from the ``n_starts``
    best of them (default k). Each evaluation solves the frequency response over ``f_range_hz``
    [Hz] with ``harmonics`` and ``options`` (``frequency_response``'s) and its peak's derivatives.
    ``max_iterations`` per start. ``evaluate(model) -> (value [m], frequency [Hz], gradient (k,) [m
    per unit])``: another objective of the model with the keys set (``objective`` names it), e.g.
    a statistic over mistuned disks (:func:`bladedamp.studies.robust.robust_design`); it raises
    ValueError where it cannot be evaluated. ValueError for bad arguments or a design whose own
    objective cannot be evaluated."""
    import scipy.optimize

    keys = tuple(str(p) for p in parameters)
    bounds = np.asarray(bounds, dtype=float).reshape(len(keys), 2)
    if not np.all(np.isfinite(bounds)) or np.any(bounds[:, 0] >= bounds[:, 1]):
        raise ValueError(f"bounds must be finite (low, high) pairs with low < high, one per parameter (got {bounds.tolist()})")
    n_starts = len(keys) if n_starts is None else validation.integer("n_starts", n_starts, minimum=1)
    n_screen = 4 * len(keys) if n_screen is None else validation.integer("n_screen", n_screen, minimum=0)
    validation.integer("max_iterations", max_iterations, minimum=1)
    log = (bounds[:, 0] > 0) & (bounds[:, 1] / np.where(bounds[:, 0] > 0, bounds[:, 0], 1) > LOG_SCALE_RATIO)
    initial = np.array([disk.parameter_value(k) for k in keys])
    count = [0]
    cache = {}

    def warp(p):                              # the logarithm of the wide-ranging parameters
        return np.where(log, np.log(np.where(log, p, 1.0)), p)

    low, span = warp(bounds[:, 0]), warp(bounds[:, 1]) - warp(bounds[:, 0])

    def to_z(p):                              # the box mapped to the unit cube: comparable variables
        return (warp(np.clip(p, bounds[:, 0], bounds[:, 1])) - low) / span

    def to_p(z):
        w = low + span * np.asarray(z)
        return np.where(log, np.exp(w), w)

    def tuned_peak(model):
        response = model.frequency_response(*f_range_hz, harmonics=harmonics, **options)
        if not response.success:
            raise ValueError(response.status_message)
        result = response.peak_sensitivities(keys)
        return result.peak_amplitude, result.peak_frequency_hz, result.d_peak_amplitude

    def peak(p):
        """(value [m], frequency [Hz], gradient (k,)) of the objective at the parameters p"""
        key = tuple(np.round(p, 14))
        if key not in cache:
            count[0] += 1
            try:
                cache[key] = (evaluate or tuned_peak)(disk.with_parameters(dict(zip(keys, p))))
            except ValueError as exc:
                raise ValueError(f"at {dict(zip(keys, p))}: {exc}") from None
        return cache[key]

    def objective_mm(z):
        p = to_p(z)
        value, _, gradient = peak(p)
        dp_dz = np.where(log, p, 1.0) * span
        return 1e3 * value, 1e3 * np.asarray(gradient) * dp_dz      # mm: a well-scaled value

    first = peak(np.clip(initial, bounds[:, 0], bounds[:, 1]))
    screened = []
    for point in np.vstack([np.clip(initial, bounds[:, 0], bounds[:, 1]), sobol_starts(bounds, n_screen, seed, log)]):
        try:
            screened.append((peak(point)[0], tuple(point)))
        except ValueError:                        # the response failed, or its peak left the range
            continue
    starts = np.array([p for _, p in sorted(screened)[:n_starts]])
    z_bounds = [(0.0, 1.0)] * len(keys)
    best, start_peaks, converged, messages = None, [], False, []
    for start in starts:
        try:
            solution = scipy.optimize.minimize(objective_mm, to_z(start), jac=True, method="L-BFGS-B", bounds=z_bounds,
                                               options={"maxiter": max_iterations, "ftol": PEAK_TOLERANCE_MM})
            p = to_p(solution.x)
            result = peak(p)
            converged |= bool(solution.success)
            messages.append(str(solution.message))
        except ValueError as exc:                 # the response failed or its peak left the range
            known = [(v[0], k) for k, v in cache.items()]
            start_peaks.append(np.nan)
            messages.append(str(exc))
            if best is None and known:
                a, k = min(known)
                best = (a, np.array(k), cache[k])
            continue
        start_peaks.append(result[0])
        if best is None or result[0] < best[0]:
            best = (result[0], p, result)
    a, p, result = best
    span = bounds[:, 1] - bounds[:, 0]
    at_bound = (np.abs(p - bounds[:, 0]) <= 1e-6 * span) | (np.abs(p - bounds[:, 1]) <= 1e-6 * span)
    message = "converged" if converged else f"no start converged ({messages[-1]})"
    return DesignOptimum(keys, tuple(parameter_unit(k) for k in keys), bounds, initial, p, float(a),
                         float(result[1]), float(first[0]), np.asarray(result[2], dtype=float),
                         at_bound, starts, np.array(start_peaks), count[0], converged, message, objective)
