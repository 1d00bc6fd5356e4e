"""Damper mass: the peak tip amplitude as a function of the mass, and its minimum (Fig. 5, 6)."""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from .. import _validate
from ..disk import TunedDisk


def with_mass(disk: TunedDisk, mass: float) -> TunedDisk:
    """The same disk with another damper mass [kg]."""
    return dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, mass=mass))


def peak_response(disk: TunedDisk, f_range_hz=(90.0, 105.0), harmonics=(1,), max_step=0.05, direction: int = 0,
                  max_widenings: int = 4):
    """(peak first-harmonic tip amplitude [m], frequency [Hz], response) over ``f_range_hz``.

    ``direction`` is the tip DOF (0..2: u_x, u_y, u_z). If the largest amplitude sits at an end
    of the range, the range is widened by its own width on that side (at most
    ``max_widenings`` times) so that a reported peak is always a true interior maximum.
    The peak is refined by a parabola through the largest point and its neighbours.
    Raises RuntimeError if the continuation does not cover the range (never a silent number).
    """
    lo, hi = _validate.interval("f_range_hz", f_range_hz, "Hz")
    for _ in range(max_widenings + 1):
        r = disk.frequency_response(lo, hi, harmonics=harmonics, max_step=max_step)
        if not r.success:
            raise RuntimeError(f"frequency response incomplete: {r.message}")
        a = r.tip_amplitude[:, direction]
        i = int(np.argmax(a))
        if 0 < i < len(a) - 1:
            break
        width = hi - lo
        lo, hi = (max(lo - width, 0.5 * lo), hi) if i == 0 else (lo, hi + width)
    else:
        raise RuntimeError(f"no interior resonance peak found up to the range {lo:.4g}-{hi:.4g} Hz")
    peak, f = a[i], r.frequency_hz[i]
    x, y = r.frequency_hz[i - 1:i + 2], a[i - 1:i + 2]
    if np.all(np.diff(x) > 0):
        c = np.polyfit(x, y, 2)
        if c[0] < 0:
            f_v = -c[1] / (2 * c[0])
            if x[0] <= f_v <= x[2]:
                peak, f = max(peak, np.polyval(c, f_v)), f_v
    return float(peak), float(f), r


@dataclass
class MassSweep:
    """Peak tip amplitude over damper mass.

    mass : (k,) [kg]; peak_tip : (k,) [m]; resonance_hz : (k,) [Hz]; kind : damper type
    """

    mass: np.ndarray
    peak_tip: np.ndarray
    resonance_hz: np.ndarray
    kind: str
    undamped_peak_tip: float

    @property
    def reduction(self) -> np.ndarray:
        """1 - peak / undamped peak."""
        return 1 - self.peak_tip / self.undamped_peak_tip

    def plot(self, ax=None, **kwargs):
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        kwargs.setdefault("label", self.kind)
        ax.semilogx(1e3 * self.mass, 1e3 * self.peak_tip, marker="o", **kwargs)
        ax.axhline(1e3 * self.undamped_peak_tip, color="gray", ls="--", lw=1)
        ax.set_xlabel("damper mass [g]")
        ax.set_ylabel("resonance tip amplitude u_x [mm]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        return ax


def _peak_of(case):
    disk, f_range, harmonics = case
    p, f, _ = peak_response(disk, f_range, harmonics)
    return p, f


def mass_sweep(disk: TunedDisk, masses, f_range_hz=(90.0, 105.0), harmonics=(1,), progress=None,
               processes: int | None = 1) -> MassSweep:
    """Peak tip amplitude for each damper mass in ``masses`` [kg] (each > 0).

    ``processes``: worker processes over the masses (None: every core)."""
    from .parallel import parallel_map

    masses = np.atleast_1d(np.asarray(masses, dtype=float))
    if masses.size == 0:
        raise ValueError("masses must be a non-empty array of damper masses in (0, inf) kg")
    _validate.positive("masses", masses)
    cases = [(with_mass(disk, m), f_range_hz, harmonics) for m in masses]
    peaks, freqs = np.array(parallel_map(_peak_of, cases, processes, progress)).T
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range_hz, harmonics)
    return MassSweep(masses, peaks, freqs, disk.damper.kind, undamped)


@dataclass
class MassOptimum:
    """Optimal damper mass [kg], its peak tip amplitude [m], the undamped peak [m].

    ``failed_masses`` [kg]: masses whose response could not be computed (e.g. a very light
    damper bouncing off both platforms, beyond the harmonic balance's reach); the optimiser
    treats them as no better than the undamped blade and never returns one of them.
    """

    mass: float
    peak_tip: float
    undamped_peak_tip: float
    evaluations: int
    failed_masses: tuple = ()

    @property
    def reduction(self) -> float:
        return 1 - self.peak_tip / self.undamped_peak_tip


def optimal_mass(disk: TunedDisk, bounds=(1e-5, 1e-2), f_range_hz=(90.0, 105.0), harmonics=(1,),
                 xatol: float = 0.02) -> MassOptimum:
    """Mass minimising the peak tip amplitude: bounded scalar optimisation in log(mass).

    ``bounds`` [kg], 0 < low < high; ``xatol`` tolerance in log(mass).
    """
    lo, hi = _validate.interval("mass bounds", bounds, "kg")
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range_hz, harmonics)
    cache, failed = {}, []

    def objective(logm):
        m = float(np.exp(logm))
        if m not in cache:
            try:
                cache[m] = peak_response(with_mass(disk, m), f_range_hz, harmonics)[0]
            except RuntimeError:
                failed.append(m)
                cache[m] = 10 * undamped   # not computable: never the optimum
        return cache[m]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        minimize_scalar(objective, bounds=(np.log(lo), np.log(hi)), method="bounded",
                        options={"xatol": xatol})
    ok = {m: p for m, p in cache.items() if m not in failed}
    if not ok:
        raise RuntimeError(f"no damper mass in {bounds} kg gave a computable response")
    best = min(ok, key=ok.get)   # the best computed point (the optimiser's last one, or better)
    return MassOptimum(best, ok[best], undamped, len(cache), tuple(failed))
