"""Resonances of a tuned damped disk over engine orders: the interference (ZZENF) and Campbell diagrams.

* :func:`interference_diagram` -- the natural frequencies of the linear sector models per nodal
  diameter 0..n/2 (without dampers; dampers stuck, at the ends of a rotor-speed range), with the
  engine-order excitation f = EO Omega_R over that range at each engine order's nodal diameter
  (:func:`bladedamp.diskmodel.nodal_diameter`: EO mod n, folded to n - (EO mod n) above n / 2).
* :func:`campbell_diagram` -- the same natural frequencies over rotor speed at the nodal diameter
  of each named engine order, the lines f = EO Omega_R, and at each engine order the damped
  resonance: the peak of the frequency response of the disk at that engine order, whose rotor
  speed follows the excitation (Omega_R = Omega_E / EO, Eq. 3, 26), so the response runs along
  the engine-order line and its peak is the crossing.

A friction-damped resonance lies between the natural frequency without dampers and the one with
the dampers stuck (up to the damper's inertia): the two linear models bound where an engine-order
line can meet a resonance of a nodal diameter.
"""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import palette, validation
from ..disk import TunedDisk
from ..diskmodel import nodal_diameter

#: rotor speeds at which a Campbell diagram's stuck natural frequencies are computed (the preload
#: m R Omega_R^2 changes them smoothly: a line through this many speeds)
CAMPBELL_SPEEDS = 7


def _natural_frequencies(disk: TunedDisk, k: int, rotor_speed_hz: float, f_max_hz: float):
    """(free, stuck) natural frequencies [Hz] of ``disk`` at nodal diameter ``k`` (forward, the
    engine order k) with the preload of ``rotor_speed_hz``."""
    at = dataclasses.replace(disk, engine_order=k, rotor_speed_hz=rotor_speed_hz)
    return at.linear_natural_frequencies_up_to_hz(f_max_hz)


def _padded(rows, width=None) -> np.ndarray:
    width = max((len(r) for r in rows), default=0) if width is None else width
    out = np.full((len(rows), width), np.nan)
    for i, r in enumerate(rows):
        out[i, :min(len(r), width)] = np.asarray(r)[:width]
    return out


def _speed_range(rotor_speeds_hz) -> np.ndarray:
    speeds = np.atleast_1d(np.asarray(validation.positive("rotor_speeds_hz (rotor revolutions per second)",
                                                          rotor_speeds_hz), dtype=float))
    if speeds.ndim != 1 or np.any(np.diff(speeds) < 0):
        raise ValueError("rotor_speeds_hz must be one speed or a non-decreasing sequence [Hz, revolutions per second]")
    return speeds


def _below(x, y, top: float):
    """The polyline (x, y) with ascending ``y`` cut where it reaches ``top``: the points up to
    ``top`` and the point on the segment that crosses it (arrays, possibly empty)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    n = int(np.searchsorted(y, top, side="right"))
    if n == 0 or n == len(y):
        return x[:n], y[:n]
    t = (top - y[n - 1]) / (y[n] - y[n - 1])
    return np.append(x[:n], x[n - 1] + t * (x[n] - x[n - 1])), np.append(y[:n], top)


def _engine_orders(engine_orders) -> tuple[int, ...]:
    eos = tuple(validation.integer("engine_orders", e, minimum=0) for e in np.atleast_1d(engine_orders))
    if not eos:
        raise ValueError("engine_orders must be a non-empty sequence of integers >= 0")
    return eos


@dataclass
class InterferenceDiagram:
    """Natural frequencies per nodal diameter and the engine-order excitation (ZZENF diagram).

    nodal_diameters : (K,) 0..n/2
    rotor_speeds_hz : (S,) rotor speeds [Hz, revolutions per second] of the stuck models and of
        the excitation range (the first and the last bound it)
    free_hz : (M,) natural frequencies without dampers [Hz] (the blade's: the same at every nodal
        diameter, no coupling is left between the blades)
    stuck_hz : (K, S, M') natural frequencies with the dampers stuck [Hz], NaN-padded (none
        without a damper: M' = 0)
    engine_orders : the engine orders of the design (drawn in colour)
    f_max_hz : top of the diagram [Hz]
    """

    n_blades: int
    nodal_diameters: np.ndarray
    rotor_speeds_hz: np.ndarray
    free_hz: np.ndarray
    stuck_hz: np.ndarray
    engine_orders: tuple
    f_max_hz: float

    def excitation_hz(self, engine_order: int) -> tuple[float, float]:
        """(lowest, highest) excitation frequency EO Omega_R [Hz] of ``engine_order`` over the speed range."""
        return engine_order * self.rotor_speeds_hz[0], engine_order * self.rotor_speeds_hz[-1]

    def crossings(self) -> list[dict]:
        """Per engine order of the design and natural frequency of its nodal diameter up to
        ``f_max_hz`` that its excitation range can reach (free or stuck at either end of the
        speed range; a stuck frequency above ``f_max_hz`` is NaN): the nodal
        diameter and direction, the free and stuck frequencies [Hz] and the rotor speeds [Hz] at
        which EO Omega_R meets them (f / EO; the stuck one at the preload of the top speed)."""
        out = []
        lo_speed, hi_speed = self.rotor_speeds_hz[0], self.rotor_speeds_hz[-1]
        for eo in self.engine_orders:
            k, direction = nodal_diameter(eo, self.n_blades)
            if eo == 0:
                continue
            lo, hi = self.excitation_hz(eo)
            stuck = self.stuck_hz[k, -1] if self.stuck_hz.shape[-1] else np.full(len(self.free_hz), np.nan)
            stuck_low = self.stuck_hz[k, 0] if self.stuck_hz.shape[-1] else stuck
            for j, free in enumerate(self.free_hz[self.free_hz <= self.f_max_hz]):
                s_hi = stuck[j] if j < len(stuck) else np.nan
                s_lo = stuck_low[j] if j < len(stuck_low) else np.nan
                band = np.array([free, s_hi, s_lo])
                band = band[np.isfinite(band)]
                if band.max() < lo or band.min() > hi:
                    continue
                out.append({"engine_order": eo, "nodal_diameter": k, "direction": direction, "mode": j + 1,
                            "free_hz": free, "stuck_hz": s_hi, "free_speed_hz": free / eo,
                            "stuck_speed_hz": s_hi / eo, "speed_range_hz": [lo_speed, hi_speed]})
        return out

    def plot(self, ax=None):
        """Draw the diagram: frequency [Hz] over nodal diameter; free natural frequencies dashed
        black, stuck ones solid (top speed) and dotted (lowest speed) with the band between,
        every engine order's excitation range as a bar at its nodal diameter (the design's in
        colour, labelled with the whole range, drawn up to ``f_max_hz``), and the zig-zag of
        EO Omega_R at the top speed up to ``f_max_hz``. The natural frequencies and the bars are
        levels and ranges set by the model and the speed range (drawn as references, ``gid``
        "reference": they may be flat or short)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(9.5, 5))
        nd = self.nodal_diameters
        for j, f in enumerate(self.free_hz[self.free_hz <= self.f_max_hz]):
            ax.axhline(f, color=palette.UNDAMPED, ls="--", lw=1, label="no dampers" if j == 0 else None)
        if self.stuck_hz.shape[-1]:
            speeds_rpm = 60 * self.rotor_speeds_hz
            for j in range(self.stuck_hz.shape[-1]):
                top, low = self.stuck_hz[:, -1, j], self.stuck_hz[:, 0, j]
                if np.nanmin(np.minimum(top, low)) > self.f_max_hz:
                    continue
                first = j == 0
                ax.plot(nd, top, color=palette.STICK, lw=1.8, marker="o", ms=3, gid="reference",
                        label=f"dampers stuck, {speeds_rpm[-1]:.0f} rpm" if first else None)
                if len(speeds_rpm) > 1 and speeds_rpm[0] != speeds_rpm[-1]:
                    ax.plot(nd, low, color=palette.STICK, lw=1, ls=":", gid="reference",
                            label=f"dampers stuck, {speeds_rpm[0]:.0f} rpm" if first else None)
                    ax.fill_between(nd, low, top, color=palette.STICK, alpha=0.12, lw=0)
        # every engine order up to the top of the diagram: its range at its nodal diameter
        e_max = int(min(np.ceil(self.f_max_hz / self.rotor_speeds_hz[0]), 4 * self.n_blades))
        zig = []
        for e in range(0, e_max + 1):
            k, _ = nodal_diameter(e, self.n_blades)
            lo, hi = self.excitation_hz(e)
            zig.append((k, hi))
            if e in self.engine_orders and lo <= self.f_max_hz:       # (an engine order above the diagram: not drawn)
                i = self.engine_orders.index(e)
                c = palette.series(i)
                same = [f for f in self.engine_orders if nodal_diameter(f, self.n_blades)[0] == k]
                x = k + 0.14 * (same.index(e) - (len(same) - 1) / 2)      # side by side on one nodal diameter
                ax.plot([x, x], [lo, min(hi, self.f_max_hz)], color=c, lw=6, alpha=0.8, solid_capstyle="butt",
                        gid="reference",
                        label=f"EO {e}: {lo:.4g}-{hi:.4g} Hz" if lo != hi else f"EO {e}: {hi:.4g} Hz")
                if lo == hi and hi <= self.f_max_hz:
                    ax.plot(x, hi, "s", color=c, ms=8)
            if hi <= self.f_max_hz:
                ax.annotate(f"{e}", (k, hi), textcoords="offset points", xytext=(4, 2), fontsize=7,
                            color="0.3")
        zk, zf = _below(*np.array(zig).T, self.f_max_hz)
        ax.plot(zk, zf, color="0.55", lw=0.9, ls="-.", label=f"EO x {60 * self.rotor_speeds_hz[-1]:.0f} rpm (zig-zag)")
        ax.set_xlim(-0.3, nd[-1] + 0.5)
        ax.set_ylim(0, self.f_max_hz)
        ax.set_xticks(nd)
        ax.set_xlabel("nodal diameter k [-] (EO mod n; n - (EO mod n) backward)")
        ax.set_ylabel("frequency [Hz]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        return ax


def interference_diagram(disk: TunedDisk, rotor_speeds_hz, f_max_hz: float, engine_orders=(1,)) -> InterferenceDiagram:
    """The interference (ZZENF) diagram of ``disk``.

    Parameters
    ----------
    disk : TunedDisk (with or without a damper; its engine order and rotor speed are not used)
    rotor_speeds_hz : one rotor speed or an ascending range [Hz, revolutions per second]; the
        stuck models are computed at its first and last speed (the preload m R Omega_R^2, Eq. 26)
    f_max_hz : top of the diagram [Hz] (> 0): stuck modes are computed up to the first above it
    engine_orders : the engine orders to mark (integers >= 0)
    """
    if not isinstance(disk, TunedDisk):
        raise ValueError("disk must be a TunedDisk")
    speeds = _speed_range(rotor_speeds_hz)
    speeds = np.unique(speeds[[0, -1]])
    f_max = validation.positive("f_max_hz", f_max_hz)
    eos = _engine_orders(engine_orders)
    nds = np.arange(disk.n_blades // 2 + 1)
    free, stuck = None, []
    for k in nds:
        row = []
        for speed in speeds:
            free, s = _natural_frequencies(disk, int(k), float(speed), f_max)
            row.append(s)
        stuck.append(row)
    width = min((len(s) for row in stuck for s in row), default=0)
    stuck_hz = np.stack([_padded(row, width) for row in stuck]) if disk.has_damper else np.zeros((len(nds), len(speeds), 0))
    return InterferenceDiagram(disk.n_blades, nds, speeds, np.asarray(free), stuck_hz, eos, f_max)


@dataclass
class CampbellCrossing:
    """The damped resonance where engine order ``engine_order`` meets a mode of its nodal
    diameter: the peak of the disk's frequency response at that engine order over ``f_range_hz``
    (the rotor speed following the excitation, so the response runs along the line f = EO Omega_R).

    peak_frequency_hz [Hz], peak_amplitude [m] (first-harmonic tip u_x), rotor_speed_hz =
    peak_frequency_hz / EO [Hz, revolutions per second]; free_hz, stuck_hz: the linear models'
    natural frequencies nearest the range [Hz] (the stuck one at the crossing's preload);
    harmonics: those of the response; status, complete, status_message: the response's
    (:attr:`bladedamp.response.FrequencyResponse.status`, its ``complete``, and
    :attr:`~bladedamp.response.FrequencyResponse.status_message`); peak_at_range_end: the
    largest amplitude lies at an end of ``f_range_hz`` (then no crossing was found in it)."""

    engine_order: int
    nodal_diameter: int
    direction: str
    f_range_hz: tuple
    harmonics: tuple
    peak_frequency_hz: float
    peak_amplitude: float
    rotor_speed_hz: float
    free_hz: float
    stuck_hz: float
    status: str
    complete: bool
    status_message: str
    peak_at_range_end: bool
    response: object = field(default=None, repr=False)

    @property
    def found(self) -> bool:
        """A resonance inside the range, on a branch that reached the end of the range with
        every check passing (its truncation error may still be unverified: see ``status``)."""
        return self.complete and not self.peak_at_range_end and bool(np.isfinite(self.peak_amplitude))


@dataclass
class CampbellDiagram:
    """Resonance crossings over rotor speed.

    rotor_speeds_hz : (S,) speeds of the stuck natural frequencies [Hz, revolutions per second]
    engine_orders : the engine orders drawn
    free_hz : (M,) natural frequencies without dampers [Hz]
    stuck_hz : {EO: (S, M') stuck natural frequencies at EO's nodal diameter and each speed [Hz]}
    crossings : [CampbellCrossing] one per engine order > 0
    f_max_hz : top of the diagram [Hz]
    """

    n_blades: int
    rotor_speeds_hz: np.ndarray
    engine_orders: tuple
    free_hz: np.ndarray
    stuck_hz: dict
    crossings: list
    f_max_hz: float

    def plot(self, ax=None):
        """Draw the diagram: frequency [Hz] over rotor speed [rpm]; free natural frequencies
        dashed black, the stuck ones of each nodal diameter of the engine orders thin (one line
        style per nodal diameter; levels of the model, drawn as references, ``gid`` "reference"),
        the engine-order lines f = EO Omega_R up to ``f_max_hz`` (one that starts above it only in
        the legend; EO 0, the static load at f = 0, as a reference), and each damped resonance as a
        marker with its peak amplitude [mm] (hollow where no resonance was found:
        :attr:`CampbellCrossing.found`)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(9.5, 5))
        rpm = 60 * self.rotor_speeds_hz
        for j, f in enumerate(self.free_hz[self.free_hz <= self.f_max_hz]):
            ax.axhline(f, color=palette.UNDAMPED, ls="--", lw=1, label="no dampers" if j == 0 else None)
        drawn = set()
        for i, eo in enumerate(self.engine_orders):
            k, direction = nodal_diameter(eo, self.n_blades)
            stuck = self.stuck_hz.get(eo)
            if k in drawn or stuck is None or not stuck.size:
                continue
            drawn.add(k)
            styles = (":", "-.", (0, (5, 2)), (0, (1, 3)))
            for j in range(stuck.shape[1]):
                if np.nanmin(stuck[:, j]) <= self.f_max_hz:
                    ax.plot(rpm, stuck[:, j], color=palette.STICK, lw=1.1, ls=styles[len(drawn) % len(styles)],
                            gid="reference",
                            label=f"dampers stuck, nodal diameter {k}" if j == 0 else None)
        for i, eo in enumerate(self.engine_orders):
            k, direction = nodal_diameter(eo, self.n_blades)
            x, f = _below(rpm, eo * self.rotor_speeds_hz, self.f_max_hz)
            ax.plot(x, f, color=palette.series(i), lw=1.6, gid="reference" if eo == 0 else None,     # EO 0: f = 0
                    label=f"EO {eo} (k = {k}, {direction})" + ("" if len(f) else ": above the diagram"))
        for i, c in enumerate(self.crossings):
            colour = palette.series(self.engine_orders.index(c.engine_order))
            if not np.isfinite(c.peak_amplitude):
                continue
            ax.plot(60 * c.rotor_speed_hz, c.peak_frequency_hz, "o", ms=9, mec=colour,
                    mfc=colour if c.found else "white", mew=1.5)
            note = f"{1e3 * c.peak_amplitude:.3g} mm" + ("" if c.found else f" ({c.status})")
            ax.annotate(note, (60 * c.rotor_speed_hz, c.peak_frequency_hz), textcoords="offset points",
                        xytext=(7, -11), fontsize=8, color=colour)
        ax.set_xlim(rpm[0], rpm[-1])
        ax.set_ylim(0, self.f_max_hz)
        ax.set_xlabel("rotor speed [rpm]")
        ax.set_ylabel("frequency [Hz]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        return ax


def campbell_diagram(disk: TunedDisk, engine_orders, f_range_hz, rotor_speeds_hz, f_max_hz: float,
                     harmonics=(1,), progress=None, **response_options) -> CampbellDiagram:
    """The Campbell diagram of ``disk`` with the damped resonance at each engine order.

    Parameters
    ----------
    disk : TunedDisk with a damper and ``rotor_speed_hz = None`` (the speed follows the
        excitation); its own engine order is not used
    engine_orders : integers >= 0; EO = 0 is drawn (f = 0) but has no crossing
    f_range_hz : (low, high) [Hz] of each engine order's frequency response (the window of the
        crossing: Omega_R from low / EO to high / EO)
    rotor_speeds_hz : ascending rotor speeds [Hz, revolutions per second] of the diagram
    f_max_hz : top of the diagram [Hz]
    harmonics : of each frequency response (the default (1,) is the one-harmonic estimate)
    progress : callable(str) or None, told before each response
    response_options : passed on to :meth:`TunedDisk.frequency_response`
    """
    if not isinstance(disk, TunedDisk) or not disk.has_damper:
        raise ValueError("disk must be a TunedDisk with a damper")
    if disk.rotor_speed_hz is not None:
        raise ValueError("disk.rotor_speed_hz must be None: a Campbell diagram follows each engine order over "
                         "rotor speed (Omega_R = Omega_E / EO)")
    eos = _engine_orders(engine_orders)
    lo, hi = validation.interval("f_range_hz", f_range_hz, "Hz")
    speeds = _speed_range(rotor_speeds_hz)
    f_max = validation.positive("f_max_hz", f_max_hz)
    samples = np.linspace(speeds[0], speeds[-1], CAMPBELL_SPEEDS) if speeds[-1] > speeds[0] else speeds[:1]
    free, stuck = None, {}
    for eo in eos:
        k, _ = nodal_diameter(eo, disk.n_blades)
        rows = []
        for speed in samples:
            free, s = _natural_frequencies(disk, k, float(speed), f_max)
            rows.append(s)
        stuck[eo] = _padded(rows, min(len(r) for r in rows))
    crossings = []
    for eo in eos:
        if eo == 0:
            continue
        k, direction = nodal_diameter(eo, disk.n_blades)
        at = dataclasses.replace(disk, engine_order=eo)
        if progress is not None:
            progress(f"frequency response at EO = {eo} (nodal diameter {k}, {direction}), {lo:g}-{hi:g} Hz, "
                     f"harmonics {tuple(harmonics)}")
        r = at.frequency_response(lo, hi, harmonics=tuple(harmonics), **response_options)
        f_peak, a_peak = r.peak_frequency_hz, r.peak_amplitude
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f_free, f_stuck = at.linear_natural_frequencies_hz(lo, hi)
        crossings.append(CampbellCrossing(eo, k, direction, (lo, hi), tuple(harmonics), f_peak, a_peak, f_peak / eo,
                                          f_free, f_stuck, r.status.value, r.status.complete, r.status_message,
                                          bool(len(r.omega) and r.peak_at_range_end), r))
    return CampbellDiagram(disk.n_blades, samples, eos, np.asarray(free), stuck, crossings, f_max)
