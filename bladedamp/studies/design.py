"""Damper design studies (paper sections "Optimization of the Damper Mass" and "Improvement of
the Damper Design", Fig. 7-11, Eq. 26, 27).

* :func:`engine_order_sweep` -- the optimal damper mass and the resonance amplitude it gives
  for each engine order (Fig. 7, 8);
* :func:`platform_angle_study` -- the same for asymmetric platforms, gamma_R varied (Fig. 10);
* :func:`design_map`, :func:`liftoff_onset` -- mass x platform angle grids, the wedge's lift-off
  over contact height and excitation;
* :func:`contact_state` -- the normalised first-harmonic xi-motion and xi-force of both
  contacts at resonance (Eq. 27, Fig. 11);
* :func:`wedge_liftoff_map` -- the ratio of normal vibration amplitude to static approach of
  every patch point at resonance (Fig. 9): r > 1 means the point lifts off once per period.

Every study takes a model, a :class:`~bladedamp.disk.TunedDisk` with a damper (the reference
disk, ``bladedamp.reference_disk(...)``, or a design's ``load_design(path).disk``), and varies
only what it studies; the rest of the disk stays as given.

SI units throughout: masses [kg], amplitudes [m], frequencies [Hz] where the name says so,
angles [deg] where the name says so.
"""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import palette, validation
from ..damper.kinetics import seat
from ..disk import TunedDisk
from ..io import Saveable
from ..plotting import place_legend, plain_log_ticks, reference_level
from ..progress import progress_callback
from .parallel import parallel_map
from .mass import optimal_mass, peak_response, with_mass

ROLLING_TOLERANCE = 0.01   # an optimum less than 1 % below the undamped peak counts as "no damping"


# ---------------------------------------------------------------------------------------
# input checks
# ---------------------------------------------------------------------------------------
def _check_f_range(f_range_hz):
    return validation.interval("f_range_hz", f_range_hz, "Hz")


def _check_mass_bounds(mass_bounds):
    return validation.interval("mass_bounds", mass_bounds, "kg")


def _check_disk(disk):
    if not isinstance(disk, TunedDisk):
        raise ValueError(f"disk must be a TunedDisk (got {type(disk).__name__})")
    if not disk.has_damper:
        raise ValueError("disk must have a damper of mass in (0, inf) kg")


# ---------------------------------------------------------------------------------------
# 1. engine orders (Fig. 7, 8)
# ---------------------------------------------------------------------------------------
@dataclass
class EngineOrderSweep(Saveable):
    """Optimal damper mass per engine order.

    kind : damper type
    engine_orders : (k,) EO
    optimal_mass : (k,) optimal damper mass [kg]; NaN where no mass lowers the peak by more
        than 1 % (the rolling cylinder at EO = 0) or where the response failed
    optimal_peak_amplitude : (k,) peak first-harmonic tip amplitude u_x at the optimum [m] (the
        undamped peak where no mass helps)
    undamped_peak_amplitude : (k,) peak tip amplitude without damper [m]
    reduction : (k,) 1 - optimal / undamped [-]
    failures : {EO: message} of engine orders whose frequency response failed (their entries NaN)
    certified : (k,) bool, the optimum is global over the mass bounds (``MassOptimum.success``:
        every mass the optimiser could not solve has a partial branch above the optimum peak)
    messages : {EO: MassOptimum.message}, how each optimum was found and which masses failed
    """

    kind: str
    engine_orders: np.ndarray
    optimal_mass: np.ndarray
    optimal_peak_amplitude: np.ndarray
    undamped_peak_amplitude: np.ndarray
    reduction: np.ndarray
    failures: dict = field(default_factory=dict)
    certified: np.ndarray = None
    messages: dict = field(default_factory=dict)

    def plot(self, ax=None, **kwargs):
        """Resonance amplitude [mm] (and optimal mass [g], right axis, log) over engine order;
        the damper-free peaks dashed."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        colour = palette.DAMPER.get(self.kind, palette.series(0))
        kwargs.setdefault("label", f"{self.kind}: peak at the optimal mass")
        kwargs.setdefault("color", colour)
        ax.plot(self.engine_orders, 1e3 * self.optimal_peak_amplitude, marker="o", **kwargs)
        undamped = 1e3 * np.asarray(self.undamped_peak_amplitude, dtype=float)
        if np.ptp(undamped) <= 0.01 * np.max(undamped):        # the same at every EO: one level
            reference_level(ax, float(np.mean(undamped)), "no damper")
        else:
            ax.plot(self.engine_orders, undamped, color=palette.UNDAMPED, ls="--", lw=1, label="no damper",
                    gid="reference")
        ax.set_xlabel("engine order EO [-]")
        ax.set_ylabel("resonance tip amplitude u_x [mm]")
        ax.xaxis.set_major_locator(plt.MaxNLocator(integer=True))
        ax.grid(True, alpha=0.3)
        ax2 = ax.twinx()
        ok = np.isfinite(self.optimal_mass)
        ax2.semilogy(self.engine_orders[ok], 1e3 * self.optimal_mass[ok], marker="s", ls=":", color="0.35",
                     label="optimal mass (right axis)")
        ax2.set_ylabel("optimal damper mass [g]", color="0.35")
        plain_log_ticks(ax2.yaxis)
        handles = [h for a in (ax, ax2) for h in a.get_legend_handles_labels()[0]]
        # below the axes: the twin axes' points would lie under a legend inside them
        ax2.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=len(handles), fontsize=8,
                   frameon=False)
        return ax


def at_engine_order(disk: TunedDisk, engine_order: int, rotor_speed_eo0_hz: float) -> TunedDisk:
    """``disk`` at another engine order; at EO = 0 with the rotor speed ``rotor_speed_eo0_hz``
    [Hz, revolutions per second] unless the disk has its own (the excitation does not fix the
    speed there)."""
    speed = disk.rotor_speed_hz if disk.rotor_speed_hz is not None or engine_order != 0 else rotor_speed_eo0_hz
    return dataclasses.replace(disk, engine_order=int(engine_order), rotor_speed_hz=speed)


def _engine_order_case(case):
    """Optimal mass of one disk at one EO; the RuntimeError text if the response fails."""
    disk, bounds, f_range, xatol, harmonics = case
    try:
        return optimal_mass(disk, bounds, f_range, harmonics, xatol=xatol)
    except RuntimeError as exc:
        return str(exc)


def engine_order_sweep(disk: TunedDisk, engine_orders=range(0, 9), mass_bounds=(1e-5, 2e-2),
                       rotor_speed_eo0_hz: float = 95.0, f_range_hz=(90.0, 105.0), xatol: float = 0.02,
                       harmonics=(1,), progress=None, processes: int | None = 1, known=None) -> EngineOrderSweep:
    """Re-optimise the damper mass of ``disk`` for each engine order (Fig. 7, 8).

    Parameters
    ----------
    disk : TunedDisk with a damper (its mass is the one thing not used: it is optimised)
    engine_orders : EOs >= 0 (non-empty; above n/2 the backward waves, :func:`bladedamp.diskmodel.nodal_diameter`)
    mass_bounds : (low, high) [kg], 0 < low < high
    rotor_speed_eo0_hz : rotor speed at EO = 0 [Hz] (> 0) if the disk has none; otherwise
        Omega_R = Omega_E / EO (or the disk's fixed rotor speed)
    f_range_hz : (low, high) [Hz] around the resonance; ``peak_response`` widens it when
        the peak sits at an end
    xatol : tolerance of the optimiser in log(mass)
    harmonics : of every peak search (default the paper's (1,))
    progress : True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
        (done, total) called as the engine orders finish
    processes : worker processes over the engine orders (None: every core)
    known : {EO: MassOptimum} optima already found by :func:`optimal_mass` for this disk at those
        EOs with the same bounds, range, ``xatol`` and harmonics: used as given, not recomputed
    """
    return engine_order_sweeps([disk], engine_orders, mass_bounds, rotor_speed_eo0_hz, f_range_hz, xatol, harmonics,
                               progress, processes, None if known is None else [known])[0]


def engine_order_sweeps(disks, engine_orders=range(0, 9), mass_bounds=(1e-5, 2e-2),
                        rotor_speed_eo0_hz: float = 95.0, f_range_hz=(90.0, 105.0), xatol: float = 0.02,
                        harmonics=(1,), progress=None, processes: int | None = 1, known=None) -> list[EngineOrderSweep]:
    """:func:`engine_order_sweep` of each disk of ``disks`` (non-empty sequence), every
    (disk, EO) optimisation one case of a single pool of ``processes`` workers (the costly
    high EOs first, so that no worker is left with a long case at the end). ``known``: one
    {EO: MassOptimum} (or None) per disk. Returns one EngineOrderSweep per disk."""
    progress = progress_callback(progress, "engine orders")
    disks = list(disks)
    if not disks:
        raise ValueError("disks must be a non-empty sequence of TunedDisk with a damper")
    for disk in disks:
        _check_disk(disk)
    eos = np.atleast_1d(np.asarray(list(engine_orders) if not np.isscalar(engine_orders) else [engine_orders]))
    if eos.size == 0:
        raise ValueError("engine_orders must be a non-empty range of integers >= 0")
    for eo in eos:
        validation.integer("engine_orders", eo, minimum=0)
    bounds = _check_mass_bounds(mass_bounds)
    validation.positive("rotor_speed_eo0_hz", rotor_speed_eo0_hz)
    f_range = _check_f_range(f_range_hz)
    validation.positive("xatol", xatol)
    known = [dict(k or {}) for k in (known if known is not None else [None] * len(disks))]
    if len(known) != len(disks):
        raise ValueError(f"known must give one dict of optima per disk ({len(disks)}), got {len(known)}")

    results = [dict(k) for k in known]
    todo = sorted(((d, int(eo)) for d in range(len(disks)) for eo in eos if int(eo) not in known[d]),
                  key=lambda de: -de[1])
    cases = [(at_engine_order(disks[d], eo, rotor_speed_eo0_hz), bounds, f_range, xatol, tuple(harmonics)) for d, eo in todo]
    for (d, eo), result in zip(todo, parallel_map(_engine_order_case, cases, processes, progress)):
        results[d][eo] = result
    return [_sweep_of(disk.damper.kind, eos, res) for disk, res in zip(disks, results)]


def _sweep_of(kind: str, eos, results: dict) -> EngineOrderSweep:
    """The EngineOrderSweep of ``results`` {EO: MassOptimum or the failure's text}."""
    k = eos.size
    m_opt, p_opt, p_und = np.full(k, np.nan), np.full(k, np.nan), np.full(k, np.nan)
    certified, messages, failures = np.zeros(k, dtype=bool), {}, {}
    for j, eo in enumerate(eos):
        result = results[int(eo)]
        if isinstance(result, str):
            failures[int(eo)] = result
            warnings.warn(f"engine order {eo}: {result}", RuntimeWarning, stacklevel=3)
            continue
        p_und[j] = result.undamped_peak_amplitude
        certified[j], messages[int(eo)] = result.success, result.message
        if result.peak_amplitude >= (1 - ROLLING_TOLERANCE) * result.undamped_peak_amplitude:
            p_opt[j] = result.undamped_peak_amplitude          # no mass helps (the rolling cylinder)
        else:
            m_opt[j], p_opt[j] = result.mass, result.peak_amplitude
    return EngineOrderSweep(kind, eos.astype(int), m_opt, p_opt, p_und, 1 - p_opt / p_und, failures,
                            certified, messages)


# tolerances of the EO trend verdicts ("reduction / optimal mass grow with EO"): a value may
# fall below its predecessor by no more than this before the trend counts as broken
REDUCTION_TREND_TOLERANCE = 0.005   # 0.5 percentage points of reduction: the optimiser's xatol
                                    # = 0.02 in log(mass) moves the optimum's peak by far less (a
                                    # parabola, ~ curvature * xatol^2), so a larger dip is physics
MASS_TREND_TOLERANCE = 0.10         # 10 % of the optimal mass: at high EO the valley is flat;
                                    # +-10 % of the optimal mass changes the reduction by a few
                                    # hundredths of a percentage point there, so the mass is no
                                    # better defined (benchmarks/README.md, 'Moved from the
                                    # package's docstrings', studies/design.py)


def eo_trend(values, tolerance: float, relative: bool = False) -> dict:
    """Does ``values`` (over consecutive engine orders) grow, within ``tolerance``?

    Grows: no NaN, the last value above the first, and no step down by more than
    ``tolerance`` (absolute, or a fraction of the previous value when ``relative``).
    Returns {'grows': bool, 'dips': [(index, drop)] of the steps down beyond the tolerance,
    'missing': [indices of NaN]}.
    """
    v = np.asarray(values, dtype=float)
    missing = [int(i) for i in np.flatnonzero(~np.isfinite(v))]
    drops = v[:-1] - v[1:]
    if relative:
        drops = drops / np.abs(v[:-1])
    dips = [(int(i + 1), float(d)) for i, d in enumerate(drops) if np.isfinite(d) and d > tolerance]
    grows = not missing and not dips and len(v) > 1 and v[-1] > v[0]
    return {"grows": bool(grows), "dips": dips, "missing": missing}


# ---------------------------------------------------------------------------------------
# 2. asymmetric platforms (Fig. 10)
# ---------------------------------------------------------------------------------------
@dataclass
class PlatformAngleStudy(Saveable):
    """Optimal damper mass over the right platform angle (gamma_L fixed).

    kind : damper type; gamma_left_deg : [deg]; fixed_mass : [kg]
    gamma_right_deg : (k,) [deg]
    optimal_mass : (k,) [kg] (NaN when not optimised)
    optimal_peak_amplitude : (k,) peak tip amplitude u_x at the optimal mass [m]
    peak_amplitude_at_fixed_mass : (k,) peak tip amplitude at ``fixed_mass`` [m]
    undamped_peak_amplitude : peak without damper [m]
    """

    kind: str
    gamma_left_deg: float
    fixed_mass: float
    gamma_right_deg: np.ndarray
    optimal_mass: np.ndarray
    optimal_peak_amplitude: np.ndarray
    peak_amplitude_at_fixed_mass: np.ndarray
    undamped_peak_amplitude: float

    def plot(self, ax=None, **kwargs):
        """Resonance amplitude [mm] over gamma_R [deg], optimal and fixed mass."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        colour = palette.DAMPER.get(self.kind, palette.series(0))
        ax.plot(self.gamma_right_deg, 1e3 * self.optimal_peak_amplitude, marker="o", color=colour,
                label="optimal mass", **kwargs)
        ax.plot(self.gamma_right_deg, 1e3 * self.peak_amplitude_at_fixed_mass, marker="s", ls=":", color=colour,
                label=f"m = {1e3 * self.fixed_mass:g} g", **kwargs)
        reference_level(ax, 1e3 * self.undamped_peak_amplitude, "no damper")
        ax.set_xlabel(f"platform angle gamma_R [deg] (gamma_L = {self.gamma_left_deg:g} deg)")
        ax.set_ylabel("resonance tip amplitude u_x [mm]")
        ax.grid(True, alpha=0.3)
        place_legend(ax, fontsize=8)
        return ax


def with_platform_angles(disk: TunedDisk, gamma_left_deg: float, gamma_right_deg: float) -> TunedDisk:
    """``disk`` with other platform angles [deg]."""
    return dataclasses.replace(disk, gamma_left=np.radians(gamma_left_deg), gamma_right=np.radians(gamma_right_deg))


def _platform_angle_case(case):
    """(peak at the fixed mass, optimal mass, optimal peak) of one gamma_R [m, kg, m]."""
    disk, bounds, f_range, optimise, xatol, harmonics = case
    p_fix = peak_response(disk, f_range, harmonics)[0]
    if not optimise:
        return p_fix, np.nan, np.nan
    opt = optimal_mass(disk, bounds, f_range, harmonics, xatol=xatol)
    return p_fix, opt.mass, opt.peak_amplitude


def platform_angle_study(disk: TunedDisk, gamma_right_deg, gamma_left_deg: float | None = None,
                         fixed_mass: float | None = None, mass_bounds=(1e-5, 2e-2), f_range_hz=(90.0, 105.0),
                         optimise: bool = True, xatol: float = 0.02, harmonics=(1,), progress=None,
                         processes: int | None = 1, known=None) -> PlatformAngleStudy:
    """Peak tip amplitude of ``disk`` over the right platform angle gamma_R (Fig. 10).

    Parameters
    ----------
    disk : TunedDisk with a damper
    gamma_right_deg : right platform angles [deg], each in (0, 90) (non-empty)
    gamma_left_deg : left platform angle [deg] in (0, 90) (default: the disk's)
    fixed_mass : damper mass of the comparison at constant mass [kg] (> 0; default: the disk's)
    mass_bounds : (low, high) [kg] of the mass optimisation, 0 < low < high
    optimise : False skips the mass optimisation (optimal_* are NaN)
    harmonics : of every peak search (default the paper's (1,))
    progress : True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
        (done, total); processes : worker processes (None: every core)
    known : {gamma_R [deg]: (peak at ``fixed_mass`` [m], MassOptimum)} already found for some of
        the angles (same disk, bounds, range, ``xatol``, harmonics): used as given, not recomputed
    """
    progress = progress_callback(progress, "platform angles")
    _check_disk(disk)
    gl = float(np.degrees(disk.gamma_left)) if gamma_left_deg is None else gamma_left_deg
    fixed_mass = disk.damper.mass if fixed_mass is None else fixed_mass
    gr = np.atleast_1d(np.asarray(gamma_right_deg, dtype=float))
    if gr.size == 0:
        raise ValueError("gamma_right_deg must be a non-empty array of angles in (0, 90) deg")
    validation.in_range("gamma_right_deg", gr, 0.0, 90.0, closed="neither")
    validation.in_range("gamma_left_deg", gl, 0.0, 90.0, closed="neither")
    validation.positive("fixed_mass (kg)", fixed_mass)
    bounds = _check_mass_bounds(mass_bounds)
    f_range = _check_f_range(f_range_hz)

    harmonics = tuple(harmonics)
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range, harmonics)
    base = with_mass(disk, fixed_mass)
    known = {float(g): (p, opt.mass, opt.peak_amplitude) if optimise else (p, np.nan, np.nan)
             for g, (p, opt) in (known or {}).items()}
    todo = [float(g) for g in gr if float(g) not in known]
    cases = [(with_platform_angles(base, gl, g), bounds, f_range, optimise, xatol, harmonics) for g in todo]
    known.update(zip(todo, parallel_map(_platform_angle_case, cases, processes, progress)))
    p_fix, m_opt, p_opt = np.array([known[float(g)] for g in gr], dtype=float).T
    return PlatformAngleStudy(disk.damper.kind, float(gl), float(fixed_mass), gr, m_opt, p_opt, p_fix, undamped)


# ---------------------------------------------------------------------------------------
# 3. contact state at resonance (Eq. 27, Fig. 11)
# ---------------------------------------------------------------------------------------
@dataclass
class ContactState(Saveable):
    """Normalised first-harmonic xi-components at resonance, OL then OR (Eq. 27).

    w_star : (2,) complex, w_xi,1 c_T / (mu F_N) [-]  (|w*| < 1: the whole contact sticks)
    F_star : (2,) complex, F_xi,1 / (mu F_N) [-]       (force on the platform)
    w_xi : (2,) complex first-harmonic relative xi-displacement [m]
    F_xi : (2,) complex first-harmonic xi contact force [N]
    normal_load : (2,) static normal loads F_N [N]; tangential_stiffness : (2,) c_T [N/m]
    friction_coefficient : (2,) mu [-]
    peak_frequency_hz : frequency of the largest tip amplitude [Hz]; peak_amplitude : that amplitude [m]
    """

    w_star: np.ndarray
    F_star: np.ndarray
    w_xi: np.ndarray
    F_xi: np.ndarray
    normal_load: np.ndarray
    tangential_stiffness: np.ndarray
    friction_coefficient: np.ndarray
    peak_frequency_hz: float
    peak_amplitude: float

    def plot(self, ax=None, **kwargs):
        """w* and F* of OL and OR as arrows in the complex plane, with the unit circle (Fig. 11)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(5, 5))
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(np.cos(t), np.sin(t), color="gray", lw=0.8, ls="--")
        for c, name in enumerate(("OL", "OR")):
            for z, label, style in ((self.w_star[c], f"w*_xi,{name}", "-"), (self.F_star[c], f"F*_xi,{name}", ":")):
                ax.annotate("", xy=(z.real, z.imag), xytext=(0, 0),
                            arrowprops=dict(arrowstyle="->", color=palette.series(c), ls=style))
                # F* hollow and w* on top: where the two nearly coincide (OL at gamma_R = 85 deg) both show
                marker = dict(marker="o", color=palette.series(c), zorder=4) if style == "-" else \
                    dict(marker="s", mfc="none", mec=palette.series(c), ms=9, mew=1.5, zorder=3)
                ax.plot([z.real], [z.imag], ls="none", label=label, **marker, **kwargs)
        lim = 1.1 * max(1.0, np.abs(self.w_star).max(), np.abs(self.F_star).max())
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.axhline(0, color="k", lw=0.5)
        ax.axvline(0, color="k", lw=0.5)
        ax.set_xlabel("real part of w*, F* [-]")
        ax.set_ylabel("imaginary part of w*, F* [-]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        return ax


def _resonance(disk, f_range_hz):
    """(response at max_step 0.05, index of the largest tip amplitude on the branch)."""
    _, _, r = peak_response(disk, _check_f_range(f_range_hz), max_step=0.05)
    return r, int(np.argmax(r.tip_amplitude[:, 0]))


def contact_state(disk: TunedDisk, f_range_hz=(90.0, 105.0)) -> ContactState:
    """Eq. 27 at the resonance (largest first-harmonic tip amplitude) of ``disk`` in ``f_range_hz`` [Hz].

    c_T is each patch's total tangential stiffness, F_N the static normal load of frictionless
    seating under F_CG (``disk.static_normal_loads``), mu the patch's friction coefficient.
    """
    _check_disk(disk)
    r, i = _resonance(disk, f_range_hz)
    basis = r.basis
    w1 = basis.to_complex(r.relative_motion[i])[1]      # (12,)
    f1 = basis.to_complex(r.contact_force[i])[1]
    w_xi, F_xi = w1[[0, 6]], f1[[0, 6]]
    patches = disk.damper_geometry().patches
    c_t = np.array([p.tangential_stiffness for p in patches])
    mu = np.array([p.friction_coefficient for p in patches])
    F_N = np.asarray(disk.static_normal_loads(r.frequency_hz[i]), dtype=float)
    return ContactState(w_xi * c_t / (mu * F_N), F_xi / (mu * F_N), w_xi, F_xi, F_N, c_t, mu,
                        float(r.frequency_hz[i]), float(r.tip_amplitude[i, 0]))


# ---------------------------------------------------------------------------------------
# 4. lift-off map (Fig. 9)
# ---------------------------------------------------------------------------------------
@dataclass
class LiftoffMap(Saveable):
    """Normal vibration amplitude over static approach of every patch point, at resonance.

    xi_star, eta_star : (P,) normalised coordinates xi / h_C, eta / l_C [-] (same for OL, OR)
    ratio : (2, P) r = |w_zeta,1| / a_static (first-harmonic normal amplitude over the static
        approach of frictionless seating under F_CG); r > 1: the point lifts off
    ratio_time : (2, P) the same from the AFT time samples, (a_static - min_t a(t)) / a_static
    min_approach : (2, P) min over the period of the approach a(t) = a_static - u_zeta(t) [m]
        (< 0 iff the point lifts off)
    static_approach : (2, P) a_static [m]
    normal_amplitude : (2, P) |w_zeta,1| [m]
    peak_frequency_hz : [Hz]; peak_amplitude : [m]; n_samples : time samples per period of the AFT
    harmonic_error : the one-harmonic response's harmonic error estimate at its peak [-] (relative
        change of the tip amplitude with the static term and more harmonics; NaN if not estimated)
    """

    xi_star: np.ndarray
    eta_star: np.ndarray
    ratio: np.ndarray
    ratio_time: np.ndarray
    min_approach: np.ndarray
    static_approach: np.ndarray
    normal_amplitude: np.ndarray
    peak_frequency_hz: float
    peak_amplitude: float
    n_samples: int
    harmonic_error: float = float("nan")

    @property
    def lifts_off(self) -> np.ndarray:
        """(2, P) bool, r > 1."""
        return self.ratio > 1

    def plot(self, ax=None, *, contact: int = 0, **kwargs):
        """r over (xi*, eta*) of one contact (0: OL, 1: OR) as a scatter map (Fig. 9)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        kwargs.setdefault("cmap", "viridis")
        sc = ax.scatter(self.xi_star, self.eta_star, c=self.ratio[contact], s=80, **kwargs)
        lift = self.lifts_off[contact]
        ax.scatter(self.xi_star[lift], self.eta_star[lift], s=160, facecolors="none", edgecolors=palette.SLIP,
                   label="r > 1 (lift-off)")
        ax.figure.colorbar(sc, ax=ax, label="r = |w_zeta| / w_zeta,static [-]")
        ax.set_xlabel("xi* = xi / h_C [-]")
        ax.set_ylabel("eta* = eta / l_C [-]")
        ax.set_title(f"{('OL', 'OR')[contact]} at {self.peak_frequency_hz:.2f} Hz")
        if lift.any():
            place_legend(ax, loc="upper center", fontsize=8)     # above the points, none hidden
        return ax


def wedge_liftoff_map(disk: TunedDisk, f_range_hz=(90.0, 105.0)) -> LiftoffMap:
    """Lift-off ratio of every patch point at the resonance of ``disk`` in ``f_range_hz`` [Hz].

    The static approach is that of the one-harmonic model (``harmonics=(1,)``): frictionless
    seating of the damper under F_CG = m R Omega_R^2 at the resonance frequency (the same
    seating TunedDisk uses as preload).
    """
    _check_disk(disk)
    r, i = _resonance(disk, f_range_hz)
    basis = r.basis
    geometry = disk.damper_geometry()
    F_cg = disk.centrifugal_force(r.frequency_hz[i])[0]
    _, a_static, _ = seat(geometry, F_cg)                   # (2, P)
    coeffs = r.point_displacement[i][..., 2]                # (C, 2, P) normal displacement
    amplitude = np.abs(basis.to_complex(coeffs)[1])
    u_t = basis.to_time(coeffs)                             # (T, 2, P)
    a_t = a_static[None] - u_t
    min_a = a_t.min(axis=0)
    xi_s, eta_s = geometry.patches[0].normalised_coordinates
    return LiftoffMap(xi_s, eta_s, amplitude / a_static, (a_static - min_a) / a_static, min_a, a_static,
                      amplitude, float(r.frequency_hz[i]), float(r.tip_amplitude[i, 0]), basis.n_samples,
                      float(r.harmonic_error))


# ---------------------------------------------------------------------------------------
# 5. design search beyond the paper: damper mass x platform angle (x wedge contact height)
# ---------------------------------------------------------------------------------------
@dataclass
class DesignMap(Saveable):
    """Peak tip amplitude over a grid of damper mass and right platform angle.

    kind : damper type; contact_height : wedge h_C [m] (None for the cylinder)
    mass : (m,) [kg]; gamma_right_deg : (g,) [deg]; peak_amplitude : (g, m) [m]
    undamped_peak_amplitude : [m]
    """

    kind: str
    contact_height: float | None
    mass: np.ndarray
    gamma_right_deg: np.ndarray
    peak_amplitude: np.ndarray
    undamped_peak_amplitude: float

    @property
    def optimum(self) -> dict:
        """Best grid point: {'mass_g', 'gamma_right_deg', 'peak_tip_mm', 'reduction_pct'}."""
        g, m = np.unravel_index(np.nanargmin(self.peak_amplitude), self.peak_amplitude.shape)
        p = self.peak_amplitude[g, m]
        return {"mass_g": 1e3 * float(self.mass[m]), "gamma_right_deg": float(self.gamma_right_deg[g]),
                "peak_tip_mm": 1e3 * float(p), "reduction_pct": 100 * float(1 - p / self.undamped_peak_amplitude)}

    def plot(self, ax=None, **kwargs):
        """Contours of the peak amplitude [mm] over mass [g] (log) and gamma_R [deg], optimum marked."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4.5))
        M, G = np.meshgrid(1e3 * self.mass, self.gamma_right_deg)
        cs = ax.contourf(M, G, 1e3 * self.peak_amplitude, levels=15, cmap="viridis_r", **kwargs)
        plt.colorbar(cs, ax=ax, label="resonance tip amplitude u_x [mm]")
        from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter, NullLocator

        opt = self.optimum
        # the best point may lie on the grid's edge: drawn unclipped, on top, so the star shows whole
        ax.plot(opt["mass_g"], opt["gamma_right_deg"], "r*", ms=14, mec="k", mew=0.6, clip_on=False, zorder=5)
        ax.set_xscale("log")
        # ticks at the computed masses only, labelled plainly (no overlapping 10^x minor labels)
        ticks = 1e3 * np.asarray(self.mass)
        ax.xaxis.set_major_locator(FixedLocator(ticks[::max(1, int(np.ceil(len(ticks) / 8)))]))   # at most 8
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("damper mass [g]")
        ax.set_ylabel("platform angle gamma_R [deg]")
        extra = f", h_C = {1e3 * self.contact_height:g} mm" if self.contact_height else ""
        ax.set_title(f"{self.kind}{extra}: design map\nbest (star): {opt['mass_g']:.3g} g, gamma_R "
                     f"{opt['gamma_right_deg']:g} deg, {opt['peak_tip_mm']:.3f} mm", fontsize=10, pad=10)
        return ax


def _design_case(case):
    disk, f_range, harmonics = case
    try:
        return peak_response(disk, f_range, harmonics)[0]
    except RuntimeError:
        return np.nan


def with_contact_height(disk: TunedDisk, contact_height: float) -> TunedDisk:
    """``disk`` with another wedge contact height h_C [m]."""
    return dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact_height=contact_height))


def design_map(disk: TunedDisk, masses, gamma_right_deg, contact_height: float | None = None,
               gamma_left_deg: float | None = None, f_range_hz=(90.0, 105.0), harmonics=(1,), progress=None,
               processes: int | None = 1) -> DesignMap:
    """Peak tip amplitude of ``disk`` over damper mass x right platform angle (and a wedge's
    contact height).

    masses [kg] (> 0, non-empty), gamma_right_deg [deg] in (0, 90) (non-empty), contact_height [m]
    (wedge only; default the disk's), gamma_left_deg [deg] (default the disk's). Grid points
    whose response fails are NaN (never a number that was not solved). ``progress``: True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
    (done, total).
    """
    progress = progress_callback(progress, "design map")
    _check_disk(disk)
    masses = np.atleast_1d(np.asarray(masses, dtype=float))
    gr = np.atleast_1d(np.asarray(gamma_right_deg, dtype=float))
    if masses.size == 0 or gr.size == 0:
        raise ValueError("masses and gamma_right_deg must be non-empty (masses in (0, inf) kg, angles in (0, 90) deg)")
    validation.positive("masses", masses)
    validation.in_range("gamma_right_deg", gr, 0.0, 90.0, closed="neither")
    gl = float(np.degrees(disk.gamma_left)) if gamma_left_deg is None else gamma_left_deg
    if contact_height is not None:
        if disk.damper.kind != "wedge":
            raise ValueError("contact_height applies to a wedge damper only (the disk's is a "
                             f"{disk.damper.kind})")
        validation.positive("contact_height h_C", contact_height)
        disk = with_contact_height(disk, contact_height)
    f_range = _check_f_range(f_range_hz)
    harmonics = tuple(harmonics)
    cases = [(with_platform_angles(with_mass(disk, float(m)), gl, float(g)), f_range, harmonics)
             for g in gr for m in masses]
    peaks = np.array(parallel_map(_design_case, cases, processes, progress)).reshape(gr.size, masses.size)
    undamped, _, _ = peak_response(dataclasses.replace(disk, damper=None), f_range, harmonics)
    return DesignMap(disk.damper.kind, contact_height, masses, gr, peaks, undamped)


def _liftoff_case(case):
    disk, f_range = case
    try:
        return float(wedge_liftoff_map(disk, f_range).ratio.max())
    except RuntimeError:
        return np.nan


def liftoff_onset(disk: TunedDisk, contact_heights, forces, f_range_hz=(90.0, 105.0), progress=None,
                  processes: int | None = 1) -> dict:
    """Largest lift-off ratio r of the wedge damper of ``disk`` over contact height [m] x tip
    excitation F_x [N] (the other excitation components stay the disk's).

    Returns {'contact_height_mm': [...], 'force_n': [...], 'max_ratio': [[...]] (heights x forces),
    'mass_g'}; r > 1 means some point separates during the cycle. ``progress``: True (a progress bar, tqdm.auto: a widget in Jupyter, a bar in a terminal), False / None (none) or a callable
    (done, total).
    """
    progress = progress_callback(progress, "lift-off onset")
    _check_disk(disk)
    if disk.damper.kind != "wedge":
        raise ValueError(f"liftoff_onset needs a wedge damper (the disk's is a {disk.damper.kind})")
    hs = np.atleast_1d(np.asarray(contact_heights, dtype=float))
    fs = np.atleast_1d(np.asarray(forces, dtype=float))
    if hs.size == 0 or fs.size == 0:
        raise ValueError("contact_heights (m, > 0) and forces (N, > 0) must be non-empty")
    validation.positive("contact_heights", hs)
    validation.positive("forces", fs)
    f_range = _check_f_range(f_range_hz)

    def excited(d, force):
        excitation = d.excitation.copy()
        excitation[0] = force
        return dataclasses.replace(d, excitation=excitation)

    cases = [(excited(with_contact_height(disk, float(h)), float(f)), f_range) for h in hs for f in fs]
    r = np.array(parallel_map(_liftoff_case, cases, processes, progress)).reshape(hs.size, fs.size)
    return {"contact_height_mm": list(1e3 * hs), "force_n": list(fs), "max_ratio": r.tolist(),
            "mass_g": 1e3 * disk.damper.mass}


def tip_dof_amplitude(response, dof: int) -> np.ndarray:
    """(n,) first-harmonic amplitude of tip DOF ``dof`` (0..5: u_x, u_y, u_z [m], phi_x, phi_y,
    phi_z [rad]) along a :class:`~bladedamp.disk.DiskResponse`."""
    disk, basis = response.disk, response.basis
    nm = disk.blade.n_modes
    j = basis.cos_index(1)
    q = response.coefficients[:, j, :nm] - 1j * response.coefficients[:, j + 1, :nm]
    return np.abs(q @ disk.blade.shape("tip")[dof])


def mode_window(disk: TunedDisk, f0_hz: float, dof: int, width=(0.97, 1.06), harmonics=(1,)):
    """FRF around one mode, ``f0_hz * width`` [Hz] (the paper's one harmonic by default, as its
    Table 1), and the peak of tip DOF ``dof``: ``(response, peak amplitude [m or rad], peak
    frequency [Hz])``. Raises RuntimeError if the branch is incomplete."""
    lo, hi = f0_hz * width[0], f0_hz * width[1]
    r = disk.frequency_response(lo, hi, harmonics=harmonics, max_step=0.05)
    if not r.success:
        raise RuntimeError(f"FRF around {f0_hz} Hz incomplete: {r.message}")
    a = tip_dof_amplitude(r, dof)
    i = int(np.argmax(a))
    return r, float(a[i]), float(r.frequency_hz[i])
