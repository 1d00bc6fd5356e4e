"""Slider callbacks of the teaching notebooks: plain functions, parameter values in, data or
matplotlib figures out.

The notebooks wire these to ipywidgets (``interact``); the tests call them directly with values
and check the returned data, so nothing here needs a browser or a running kernel.

Two kinds of callbacks:

* the point contact and the friction oscillator (notebook 01): closed forms and cheap AFT
  evaluations (tens of milliseconds), the oscillator's FRF with time integration at a few
  frequencies (a few tenths of a second, memoised);
* the reference bladed disk (notebooks 02, 03): a frequency response per slider move, the
  library's own (:func:`bladedamp.studies.peak_response`, i.e. ``TunedDisk.frequency_response``
  with the studies' peak refinement), with a continuation step of 0.2 (0.4-1.2 s per new value
  on the loaded 2-core machine, 1-2 s at the studies' 0.05; :class:`DiskFRFCache`). Results are
  memoised, so moving a slider back is instant; the contact state at resonance (Eq. 27) is
  :func:`bladedamp.studies.contact_state` itself, memoised.

Units: SI inside; the arguments of the ``*_figure`` callbacks carry their slider units in their
names (``mass_g``, ``amplitude_mm``, ``gamma_right_deg``).
"""
from __future__ import annotations

import dataclasses
import time
import warnings
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from .. import palette
from ..contact.laws import LinearNormalLaw
from ..contact.patch import ContactPatch
from ..contact.point import SEPARATED, SLIP, STICK, point_contact_forces
from ..hbm.fourier import HarmonicBasis
from ..oscillator import FrictionOscillator
from ..plotting import place_legend, plain_log_ticks

__all__ = ["interactive_view", "interact_with_image", "hysteresis_loop", "hysteresis_figure", "describing_function", "describing_function_figure",
           "oscillator_comparison", "oscillator_figure", "DiskFRF", "DiskFRFCache", "DEFAULT_CACHE", "disk_frf",
           "undamped_frf", "disk_frf_figure", "mass_sweep_peaks", "mass_study_figure", "engine_order_figure", "engine_order_study_figure",
           "contact_state_at_peak", "platform_angle_figure", "closed_form_jenkins"]

# the slider callbacks set the slip force mu N; this splits it into mu and N (only the lift-off
# and normal-load plots see the split)
FRICTION_COEFFICIENT = 0.3
STATE_COLOURS = {state: palette.CONTACT_STATES[state] for state in (STICK, SLIP, SEPARATED)}
STATE_NAMES = {STICK: "stick", SLIP: "slip", SEPARATED: "lift-off"}


def interactive_view(callback):
    """Wrap a ``*_figure`` callback for ``ipywidgets.interact``: draw the figure, show it, return
    None (interact would otherwise display the returned figure a second time). The wrapper keeps
    the callback's signature, so ``interact`` finds its parameters and defaults."""
    import functools

    @functools.wraps(callback)
    def view(*args, **kwargs):
        import matplotlib.pyplot as plt

        callback(*args, **kwargs)
        plt.show()

    return view


def interact_with_image(callback, **controls):
    """``ipywidgets.interact(callback, **controls)`` whose saved output also holds a still image.

    The widget is displayed as one output whose MIME bundle carries the widget view and, beside
    it, the PNG of the figure ``callback`` drew at the controls' initial values (its first
    ``image/png`` display). A front end that draws the widget (a trusted notebook with a running
    or saved widget state) shows the live sliders; one that does not (an untrusted notebook,
    a static viewer) shows the PNG instead of the widget's ``interactive(children=...)`` text.
    The callback runs once, as with ``interact``; its outputs go to the widget's output area.
    Returns None (a returned widget would be displayed a second time)."""
    import functools

    from IPython.display import display
    from IPython.utils.capture import capture_output
    from ipywidgets import interactive

    first = []

    @functools.wraps(callback)
    def view(*args, **kwargs):
        if first:
            return callback(*args, **kwargs)
        with capture_output() as captured:
            result = callback(*args, **kwargs)
        first.append(captured)
        captured.show()             # inside the widget's output area, as interact would show it
        return result

    widget = interactive(view, **controls)
    bundle = widget._repr_mimebundle_()
    images = [out.data["image/png"] for out in (first[0].outputs if first else []) if "image/png" in out.data]
    if images:
        bundle["image/png"] = images[0]
    display(bundle, raw=True)


def _figure(*args, **kwargs):
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


# ---------------------------------------------------------------------------------------
# 1. the point contact: hysteresis loop, describing function
# ---------------------------------------------------------------------------------------
def closed_form_jenkins(k_t, slip_force, amplitude):
    """Closed form of the 1D elastic Coulomb (Jenkins) element under u = A cos(tau), constant N.

    Returns ``(k_eq, d_eq, energy)``: equivalent stiffness Re(F_1 / A) [N/m], equivalent damping
    stiffness Im(F_1 / A) [N/m] (the imaginary part of the complex stiffness of Eq. 10) and the
    energy dissipated per cycle [J]. Stick (k_T A <= mu N): k_T, 0, 0. Gross slip, with
    beta = arccos(1 - 2 mu N / (k_T A)):
    k_eq = k_T / pi (beta - sin(2 beta) / 2), d_eq = 4 mu N / (pi A) (1 - mu N / (k_T A)),
    energy = 4 mu N (A - mu N / k_T) = pi A^2 d_eq.
    """
    k_t, slip_force, A = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (k_t, slip_force, amplitude)))
    stick = k_t * A <= slip_force
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = np.arccos(np.clip(1.0 - 2.0 * slip_force / (k_t * A), -1.0, 1.0))
        k_eq = np.where(stick, k_t, k_t / np.pi * (beta - np.sin(2 * beta) / 2))
        d_eq = np.where(stick, 0.0, 4 * slip_force / (np.pi * A) * (1 - slip_force / (k_t * A)))
    energy = np.where(stick, 0.0, 4 * slip_force * (A - slip_force / k_t))
    return k_eq, d_eq, energy


def _normal_motion(normal_load, normal_variation, phase_deg, k_n):
    """First-harmonic normal displacement giving N(tau) = N0 (1 + v cos(tau - phase))."""
    z = normal_variation * normal_load / k_n
    ph = np.radians(phase_deg)
    return -z * np.cos(ph), -z * np.sin(ph)


def hysteresis_loop(amplitude, k_t, slip_force, normal_variation=0.0, phase_deg=0.0,
                    friction_coefficient=FRICTION_COEFFICIENT, n_samples=512) -> dict:
    """Steady hysteresis loop of one point contact (elastic Coulomb slider, Fig. 3) under
    u_xi = A cos(tau) and a normal load N(tau) = N0 (1 + v cos(tau - phase)) (lift-off when v > 1).

    Parameters: amplitude A [m] (>= 0), k_t [N/m], slip_force mu N0 [N], normal_variation v [-],
    phase_deg [deg] of the normal load against the tangential motion, friction_coefficient mu.

    Returns a dict of samples over one period: ``tau``, ``u`` [m], ``force`` (tangential force on
    the platform) [N], ``normal`` [N], ``state`` (0 stick, 1 slip, 2 separated), and
    ``energy`` = oint f du [J] (the loop area, the energy dissipated per cycle), ``slip_work`` [J]
    (the same from the slider's moves), ``energy_closed_form`` [J] (the Jenkins closed form for
    v = 0), ``share`` {stick, slip, lift-off: fraction of the period}.
    """
    if amplitude < 0 or k_t <= 0 or slip_force < 0 or friction_coefficient <= 0 or normal_variation < 0:
        raise ValueError("need amplitude >= 0, k_t > 0, slip_force >= 0, friction_coefficient > 0, "
                         "normal_variation >= 0")
    basis = HarmonicBasis((1,), n_samples)
    N0 = slip_force / friction_coefficient
    k_n = k_t
    coeffs = np.zeros((basis.n_coeffs, 1, 3))
    coeffs[0, 0, 0] = amplitude
    coeffs[0, 0, 2], coeffs[1, 0, 2] = _normal_motion(N0, normal_variation, phase_deg, k_n)
    pts = point_contact_forces(coeffs, basis, np.array([k_t]), np.array([friction_coefficient]),
                               LinearNormalLaw(k_n), np.array([1.0]), np.array([N0 / k_n]), jacobian=False)
    u, f = pts.displacement[0, :, 0], pts.force[0, :, 0]
    # loop area, trapezoid over the closed loop
    energy = float(np.sum(0.5 * (f + np.roll(f, -1)) * (np.roll(u, -1) - u)))
    _, _, e_closed = closed_form_jenkins(k_t, slip_force, amplitude)
    state = pts.state[0]
    share = {STATE_NAMES[s]: float(np.mean(state == s)) for s in (STICK, SLIP, SEPARATED)}
    return dict(tau=basis.tau, u=u, force=f, normal=pts.normal_load[0], state=state, energy=energy,
                slip_work=float(pts.slip_work[0]), energy_closed_form=float(e_closed), share=share)


def contact_point_title(k_t_kn_per_m, slip_force_n, normal_variation=0.0) -> str:
    """The suptitle of the contact point's figures: what the point is, with its parameters."""
    varies = f", normal load varying by +-{100 * normal_variation:g} %" if normal_variation else ""
    return f"friction contact point: k_T = {k_t_kn_per_m:g} kN/m, mu N_0 = {slip_force_n:g} N{varies}"


def hysteresis_figure(amplitude_mm=0.1, k_t_kn_per_m=10.0, slip_force_n=0.3, normal_variation=0.0, phase_deg=0.0):
    """Slider callback (notebook 01): the hysteresis loop f(u) coloured by stick / slip / lift-off,
    beside the time signals (the slip limits +-mu N(t) drawn as references). Returns the figure;
    ``fig.loop`` holds the :func:`hysteresis_loop` data."""
    from matplotlib.ticker import MaxNLocator


    A, k_t = 1e-3 * amplitude_mm, 1e3 * k_t_kn_per_m
    d = hysteresis_loop(A, k_t, slip_force_n, normal_variation, phase_deg)
    fig, (ax, ax2) = _figure(1, 2, figsize=(10, 4.2))
    u_mm = 1e3 * d["u"]
    for s in (STICK, SLIP, SEPARATED):
        sel = d["state"] == s
        if sel.any():
            ax.plot(u_mm[sel], d["force"][sel], "o", ms=2.5, color=STATE_COLOURS[s], label=STATE_NAMES[s])
    ax.plot(np.append(u_mm, u_mm[0]), np.append(d["force"], d["force"][0]), color=palette.UNDAMPED, lw=0.6)
    ax.axhline(slip_force_n, color=palette.SEPARATED, ls=":", lw=1)
    ax.axhline(-slip_force_n, color=palette.SEPARATED, ls=":", lw=1)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.set_xlabel("tangential displacement u [mm]")
    ax.set_ylabel("tangential contact force f_T [N]")
    ax.set_title(f"loop area = dissipated energy: {1e3 * d['energy']:.3g} mJ per cycle"
                 + ("" if normal_variation else f"\n(closed form {1e3 * d['energy_closed_form']:.3g} mJ)"), fontsize=9)
    ax.grid(True, alpha=0.3)
    ax2.plot(np.degrees(d["tau"]), d["force"], color=palette.series(0), label="f_T")
    for sign in (1, -1):
        ax2.plot(np.degrees(d["tau"]), sign * FRICTION_COEFFICIENT * d["normal"], color=palette.series(1), ls="--",
                 gid="reference", label="+-mu N(t)" if sign == 1 else None)
    ax2.set_xlabel("phase Omega t [deg]")
    ax2.set_ylabel("force [N]")
    ax2.set_xlim(0, 360)
    ax2.set_xticks([0, 90, 180, 270, 360])
    ax2.grid(True, alpha=0.3)
    fig.suptitle(contact_point_title(k_t_kn_per_m, slip_force_n, normal_variation)
                 + f", amplitude {amplitude_mm:g} mm", fontsize=10)
    place_legend(ax, loc="upper left", fontsize=8)
    place_legend(ax2, loc="upper right", fontsize=8)
    fig.loop = d
    return fig


def describing_function(k_t, slip_force, amplitudes, normal_variation=0.0, phase_deg=0.0,
                        friction_coefficient=FRICTION_COEFFICIENT, n_samples=256) -> dict:
    """Complex equivalent stiffness k_hat = F_1 / W_1 (Eq. 10) of a one-point contact patch
    (:meth:`bladedamp.contact.ContactPatch.equivalent_stiffness`) over tangential amplitudes [m],
    with the Jenkins closed form beside it.

    Returns a dict: ``amplitude`` [m], ``k_eq`` = Re k_hat, ``d_eq`` = Im k_hat [N/m],
    ``energy`` = pi A^2 Im k_hat [J per cycle], and ``k_eq_closed``, ``d_eq_closed``,
    ``energy_closed`` (constant normal load).
    """
    A = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    if np.any(A <= 0):
        raise ValueError("amplitudes must be > 0 m")
    N0 = slip_force / friction_coefficient
    k_n = k_t
    patch = ContactPatch(0.0, 1.0, k_t, friction_coefficient, LinearNormalLaw(k_n), n_xi=1, n_eta=1)
    basis = HarmonicBasis((1,), n_samples)
    offset = patch.approach_for_load(N0)
    za, zb = _normal_motion(N0, normal_variation, phase_deg, k_n)
    k_hat = np.empty(A.size, dtype=complex)
    for i, a in enumerate(A):
        w = np.zeros((basis.n_coeffs, 6))
        w[0, 0] = a
        w[0, 2], w[1, 2] = za, zb
        k_hat[i] = patch.equivalent_stiffness(w, basis, offset)[1][0]
    k_c, d_c, e_c = closed_form_jenkins(k_t, slip_force, A)
    return dict(amplitude=A, k_eq=k_hat.real, d_eq=k_hat.imag, energy=np.pi * A ** 2 * k_hat.imag,
                k_eq_closed=k_c, d_eq_closed=d_c, energy_closed=e_c)


def describing_function_figure(k_t_kn_per_m=10.0, slip_force_n=0.3, normal_variation=0.0, amplitude_mm=None,
                               n_points=60):
    """Slider callback (notebook 01): equivalent stiffness and damping over the amplitude
    (normalised by the slip amplitude mu N / k_T), AFT points on the closed form, and the energy
    per cycle (on the log axis from 1e-5 of its largest value: a contact that sticks dissipates
    nothing). ``fig.data`` holds the :func:`describing_function` result."""
    k_t = 1e3 * k_t_kn_per_m
    a_slip = slip_force_n / k_t
    A = a_slip * np.logspace(-1, 2, n_points)
    d = describing_function(k_t, slip_force_n, A, normal_variation)
    x = A / a_slip
    fig, (ax, ax2) = _figure(1, 2, figsize=(10, 4.6))
    k_colour, d_colour = palette.series(0), palette.series(1)
    ax.semilogx(x, d["k_eq_closed"] / k_t, "-", color=k_colour, label="k_eq / k_T, closed form")
    ax.semilogx(x, d["d_eq_closed"] / k_t, "-", color=d_colour, label="d_eq / k_T, closed form")
    ax.semilogx(x, d["k_eq"] / k_t, "o", color=k_colour, ms=3, label="k_eq / k_T, AFT (Eq. 10)")
    ax.semilogx(x, d["d_eq"] / k_t, "o", color=d_colour, ms=3, label="d_eq / k_T, AFT (Eq. 10)")
    ax.set_xlabel("amplitude A / (mu N / k_T) [-]")
    ax.set_ylabel("complex contact stiffness / k_T [-]")
    ax.grid(True, which="both", alpha=0.3)
    floor = 1e3 * max(d["energy_closed"].max(), 1e-30) * 1e-5
    shown = {key: np.where(1e3 * d[key] >= floor, 1e3 * d[key], np.nan) for key in ("energy_closed", "energy")}
    ax2.loglog(1e3 * A, shown["energy_closed"], "-", color=palette.UNDAMPED, label="closed form 4 mu N (A - mu N / k_T)")
    ax2.loglog(1e3 * A, shown["energy"], "o", color=palette.series(2), ms=3, label="AFT: pi A^2 Im k_hat")
    ax2.set_xlim(1e3 * A[0], 1e3 * A[-1])                  # the sticking amplitudes too (no energy)
    ax2.set_ylim(floor, None)
    ax2.set_xlabel("amplitude A [mm]")
    ax2.set_ylabel("energy dissipated per cycle [mJ]")
    ax2.grid(True, which="both", alpha=0.3)
    if amplitude_mm is not None:
        ax.axvline(1e-3 * amplitude_mm / a_slip, color=palette.UNDAMPED, ls=":")
        ax2.axvline(amplitude_mm, color=palette.UNDAMPED, ls=":")
    fig.suptitle(contact_point_title(k_t_kn_per_m, slip_force_n, normal_variation), fontsize=10)
    for a in (ax, ax2):      # below the axes: the amplitude's marker line moves with the slider
        a.legend(fontsize=8, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.2))
    fig.tight_layout()
    fig.data = d
    return fig


# ---------------------------------------------------------------------------------------
# 2. the friction oscillator: HBM beside time integration
# ---------------------------------------------------------------------------------------
_OSC_CACHE: "OrderedDict[tuple, dict]" = OrderedDict()


def oscillator_comparison(normal_load=3.0, forcing=2.0, damping=2.0, harmonics=(1, 3, 5), f_range_hz=(11.0, 32.0),
                          time_frequencies_hz=(14.0, 17.5, 20.5, 25.5), steps_per_period=512, max_step=0.05) -> dict:
    """FRF of the :class:`FrictionOscillator` (m = 1 kg, k = k_T = 1e4 N/m, mu = 0.3: the free
    natural frequency is 15.9 Hz) over ``f_range_hz`` [Hz] by HBM beside time integration at
    ``time_frequencies_hz`` [Hz], and the linear limits.

    Returns a dict: ``osc``, ``frf`` (FrequencyResponse), ``frequency_hz`` [Hz], ``hbm``
    (first-harmonic amplitude on the branch) [m], ``time_frequency_hz``, ``time_amplitude``
    (time integration), ``hbm_at_time`` (HBM interpolated there), ``energy`` (excitation,
    viscous, contact work per cycle on the branch), ``free``, ``stuck`` (linear amplitudes over
    ``frequency_hz``) and the same on a dense grid ``frequency_dense_hz``: ``free_dense``,
    ``stuck_dense``. Memoised.
    """
    key = (float(normal_load), float(forcing), float(damping), tuple(harmonics), tuple(f_range_hz),
           tuple(time_frequencies_hz), int(steps_per_period), float(max_step))
    if key in _OSC_CACHE:
        return _OSC_CACHE[key]
    osc = FrictionOscillator(damping=damping, normal_load=normal_load, forcing=forcing)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        frf = osc.frequency_response(*f_range_hz, harmonics=harmonics, max_step=max_step)
    amp = frf.harmonic_amplitude(0, 1)
    tf = np.asarray(time_frequencies_hz, dtype=float)
    tr = osc.time_response(tf, steps_per_period=steps_per_period) if tf.size else None
    f = frf.frequency_hz
    order = np.argsort(f)
    out = dict(osc=osc, frf=frf, frequency_hz=f, hbm=amp, time_frequency_hz=tf,
               time_amplitude=tr.amplitude if tr is not None else np.zeros(0),
               time_converged=tr.converged if tr is not None else np.zeros(0, bool),
               hbm_at_time=np.interp(tf, f[order], amp[order]),
               energy=osc.energy_balance(frf), free=osc.linear_amplitude(f, stuck=False),
               stuck=osc.linear_amplitude(f, stuck=True))
    dense = np.linspace(*f_range_hz, 600)
    out.update(frequency_dense_hz=dense, free_dense=osc.linear_amplitude(dense, stuck=False),
               stuck_dense=osc.linear_amplitude(dense, stuck=True))
    _OSC_CACHE[key] = out
    while len(_OSC_CACHE) > 32:
        _OSC_CACHE.popitem(last=False)
    return out


def oscillator_figure(normal_load=3.0, forcing=2.0, damping=2.0, **kwargs):
    """Slider callback (notebook 01): HBM FRF, time-integration points, the free and stuck linear
    limits. ``fig.data`` holds the :func:`oscillator_comparison` result."""
    d = oscillator_comparison(normal_load, forcing, damping, **kwargs)
    fig, ax = _figure(figsize=(7, 4))
    ax.semilogy(d["frequency_dense_hz"], 1e3 * d["free_dense"], color=palette.SEPARATED, ls="--", lw=1,
                label="linear, no contact (k)")
    ax.semilogy(d["frequency_dense_hz"], 1e3 * d["stuck_dense"], color=palette.SEPARATED, ls=":", lw=1,
                label="linear, stuck (k + k_T)")
    ax.semilogy(d["frequency_hz"], 1e3 * d["hbm"], "-", color=palette.series(0), label=f"HBM, harmonics {tuple(d['frf'].basis.harmonics)}")
    if d["time_frequency_hz"].size:
        ax.semilogy(d["time_frequency_hz"], 1e3 * d["time_amplitude"], "o", color=palette.series(1),
                    label="time integration")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("first-harmonic amplitude |x_1| [mm]")
    ax.set_title(f"friction oscillator: mu N = {d['osc'].slip_force:.3g} N, F = {forcing:.3g} N", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.data = d
    return fig


# ---------------------------------------------------------------------------------------
# 3. the reference disk: the library's frequency responses, memoised
# ---------------------------------------------------------------------------------------
@dataclass
class DiskFRF:
    """A frequency response of the reference disk, as a slider callback shows it.

    response : the :class:`~bladedamp.disk.DiskResponse` of ``TunedDisk.frequency_response`` (via
    :func:`bladedamp.studies.peak_response`); frequency_hz : (n,) [Hz] and tip_amplitude : (n, 3)
    first-harmonic tip amplitude u_x, u_y, u_z [m] along its branch; peak_amplitude [m] and
    peak_frequency_hz [Hz] of u_x (parabola-refined, as ``peak_response``); method : "linear"
    (no damper), "continuation", or "incomplete" (the branch stopped early, ``response.message``
    says why; the peak is the largest converged point, a lower bound); seconds : compute time [s];
    disk : the TunedDisk.
    """

    response: object
    peak_amplitude: float
    peak_frequency_hz: float
    method: str
    seconds: float
    disk: object

    @property
    def frequency_hz(self) -> np.ndarray:
        """(n,) excitation frequency of the branch's points [Hz]."""
        return self.response.frequency_hz

    @property
    def tip_amplitude(self) -> np.ndarray:
        """(n, 3) first-harmonic tip amplitude u_x, u_y, u_z [m] of the branch's points."""
        return self.response.tip_amplitude

    def reduction(self, undamped: "DiskFRF") -> float:
        """1 - peak / undamped peak."""
        return 1.0 - self.peak_amplitude / undamped.peak_amplitude


# half-width of the window of the contact state at resonance [Hz]: the coarse branch's peak is
# within 0.01 Hz of the fine one, and a narrower window is faster (benchmarks/README.md, 'Moved
# from the package's docstrings', viz/widgets.py)
CONTACT_STATE_WINDOW_HZ = 0.3


class DiskFRFCache:
    """Memoised frequency responses of reference disks (see the module docstring).

    Each response is the library's own: :func:`bladedamp.studies.peak_response` (the disk's
    ``frequency_response``, the range widened when the peak sits at an end, the peak refined
    by a parabola), so a slider shows exactly what a study computes.

    Parameters
    ----------
    f_range_hz : frequency window [Hz]
    max_step : the continuation's largest step (scaled units, the window is 1); at 0.2 the
        peaks agree with the studies' step 0.05 within 0.1 % in amplitude and 0.02 Hz
        (benchmarks/README.md, 'Moved from the package's docstrings', viz/widgets.py)
    max_entries : memoised responses kept (least recently used dropped)
    """

    def __init__(self, f_range_hz=(92.0, 100.0), max_step=0.2, max_entries=256):
        self.f_range_hz = tuple(float(f) for f in f_range_hz)
        self.max_step = float(max_step)
        self.max_entries = int(max_entries)
        self._memo: "OrderedDict[tuple, DiskFRF]" = OrderedDict()
        self._base_disks: dict = {}
        self._states: dict = {}
        self.stats = {"memo": 0, "linear": 0, "continuation": 0}

    # -- keys -------------------------------------------------------------------------
    @staticmethod
    def family(kind, engine_order=1, gamma_right_deg=35.0, excitation=None, harmonics=(1,),
               friction_coefficient=None):
        """Everything but the mass (the blade's beam modes are built once per family)."""
        exc = None if excitation is None else tuple(float(v) for v in excitation)
        mu = None if friction_coefficient is None or kind is None else round(float(friction_coefficient), 6)
        return (kind, int(engine_order), round(float(gamma_right_deg), 6), exc, tuple(harmonics), mu)

    def _disk(self, family, mass):
        """The family's reference disk with ``mass`` [kg]."""
        from ..reference import reference_disk

        if family not in self._base_disks:
            kind, eo, gamma_r, exc, _, mu = family
            kw = {}
            if exc is not None:
                kw["excitation"] = np.array(exc)
            if eo == 0:
                kw["rotor_speed_hz"] = 95.0      # EO = 0 needs a rotor speed: that of the EO = 1 resonance
            disk = reference_disk(kind, 1e-3, engine_order=eo, **kw)
            if gamma_r != 35.0:
                disk = dataclasses.replace(disk, gamma_right=np.radians(gamma_r))
            if mu is not None:
                contact = dataclasses.replace(disk.damper.contact, friction_coefficient=mu)
                disk = dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact=contact))
            self._base_disks[family] = disk
        base = self._base_disks[family]
        if base.damper is None:
            return base
        return dataclasses.replace(base, damper=dataclasses.replace(base.damper, mass=mass))

    # -- public -----------------------------------------------------------------------
    def response(self, kind="cylinder", mass=1e-3, engine_order=1, gamma_right_deg=35.0, excitation=None,
                 harmonics=(1,), friction_coefficient=None) -> DiskFRF:
        """Frequency response of the reference disk with a ``kind`` damper of ``mass`` [kg]
        (``kind=None``: no damper), at ``engine_order``, right platform angle [deg], tip
        ``excitation`` (6,) [N, N m] (None: the reference's), damper ``friction_coefficient``
        mu [-] (None: the reference's)."""
        from ..studies.mass import IncompleteResponse, peak_response

        if kind not in (None, "cylinder", "wedge"):
            raise ValueError(f"kind must be None, 'cylinder' or 'wedge' (got {kind!r})")
        if kind is not None and not mass > 0:
            raise ValueError(f"mass must be > 0 kg (got {mass!r})")
        if friction_coefficient is not None and not friction_coefficient >= 0:
            raise ValueError(f"friction_coefficient must be >= 0 (got {friction_coefficient!r})")
        fam = self.family(kind, engine_order, gamma_right_deg, excitation, harmonics, friction_coefficient)
        mass = 0.0 if kind is None else float(mass)
        key = fam + (float(f"{mass:.6g}"),)
        if key in self._memo:
            self._memo.move_to_end(key)
            self.stats["memo"] += 1
            return self._memo[key]
        t0 = time.perf_counter()
        disk = self._disk(fam, mass if kind is not None else 1e-3)
        method = "continuation" if disk.has_damper else "linear"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                peak, f_peak, r = peak_response(disk, self.f_range_hz, harmonics=tuple(harmonics),
                                                max_step=self.max_step)
            except IncompleteResponse as e:
                if e.response is None or not len(e.response.omega):
                    raise
                # the branch stopped early: show what converged, its largest point a lower bound
                r, method = e.response, "incomplete"
                i = int(np.argmax(r.tip_amplitude[:, 0]))
                peak, f_peak = float(r.tip_amplitude[i, 0]), float(r.frequency_hz[i])
        self.stats[method] = self.stats.get(method, 0) + 1
        result = DiskFRF(r, peak, f_peak, method, time.perf_counter() - t0, disk)
        self._memo[key] = result
        while len(self._memo) > self.max_entries:
            self._memo.popitem(last=False)
        return result

    def contact_state(self, frf: DiskFRF):
        """:func:`bladedamp.studies.contact_state` (Eq. 27 at the resonance) of ``frf``'s disk,
        memoised; solved on a window of +-``CONTACT_STATE_WINDOW_HZ`` around ``frf``'s peak (the
        study's resonance is the same peak, and a window that contains it gives it; the study's
        own step on the narrow window places points 0.03 Hz apart there)."""
        from ..studies.design import contact_state

        key = id(frf)
        if key not in self._states or self._states[key][0] is not frf:
            f = frf.peak_frequency_hz
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                window = (f - CONTACT_STATE_WINDOW_HZ, f + CONTACT_STATE_WINDOW_HZ)
                self._states[key] = (frf, contact_state(frf.disk, window))
        return self._states[key][1]

    def clear(self):
        self._memo.clear()
        self._states.clear()


DEFAULT_CACHE = DiskFRFCache()


def disk_frf(kind="cylinder", mass_g=1.0, engine_order=1, gamma_right_deg=35.0, excitation=None,
             cache: DiskFRFCache | None = None) -> DiskFRF:
    """Warm-started frequency response of the reference disk over the 1F window (mass in grams)."""
    cache = DEFAULT_CACHE if cache is None else cache
    return cache.response(kind, 1e-3 * mass_g, engine_order, gamma_right_deg, excitation)


def undamped_frf(engine_order=1, excitation=None, cache: DiskFRFCache | None = None) -> DiskFRF:
    """Frequency response of the reference disk without damper."""
    cache = DEFAULT_CACHE if cache is None else cache
    return cache.response(None, 0.0, engine_order, 35.0, excitation)


def disk_frf_figure(mass_g=1.0, kind="cylinder", engine_order=1, gamma_right_deg=35.0, cache=None):
    """Slider callback (notebooks 02, 03): tip amplitude over frequency with and without the
    damper; the title gives the peak and the reduction. ``fig.data = (damped, undamped)``."""
    damped = disk_frf(kind, mass_g, engine_order, gamma_right_deg, cache=cache)
    free = undamped_frf(engine_order, cache=cache)
    fig, ax = _figure(figsize=(7, 4))
    colour = palette.DAMPER.get(kind, palette.series(0))
    ax.plot(free.frequency_hz, 1e3 * free.tip_amplitude[:, 0], "--", color=palette.UNDAMPED, lw=1, label="no damper")
    ax.plot(damped.frequency_hz, 1e3 * damped.tip_amplitude[:, 0], "-", color=colour, label=f"{kind} {mass_g:.3g} g")
    ax.plot([damped.peak_frequency_hz], [1e3 * damped.peak_amplitude], "o", mfc="none", mec=colour, mew=1.4)
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("tip amplitude u_x [mm]")
    ax.set_xlim(damped.frequency_hz[0], damped.frequency_hz[-1])
    ax.set_title(f"reference disk, EO = {engine_order}, gamma_R = {gamma_right_deg:g} deg\n"
                 f"peak {1e3 * damped.peak_amplitude:.3f} mm at {damped.peak_frequency_hz:.2f} Hz, reduction "
                 f"{100 * damped.reduction(free):.1f} % ({damped.method}, {damped.seconds:.2f} s)", fontsize=9)
    ax.grid(True, alpha=0.3)
    place_legend(ax)
    fig.data = (damped, free)
    return fig


def mass_sweep_peaks(kind, masses_g, engine_order=1, gamma_right_deg=35.0, cache=None) -> dict:
    """Peak tip amplitude [m] and reduction over damper masses [g], one memoised FRF per mass.

    Returns a dict ``mass_g``, ``peak_amplitude``, ``peak_frequency_hz``, ``undamped_peak_amplitude``, ``reduction``,
    and the best grid point ``best_mass_g``, ``best_reduction``."""
    masses_g = np.atleast_1d(np.asarray(masses_g, dtype=float))
    rs = [disk_frf(kind, m, engine_order, gamma_right_deg, cache=cache) for m in masses_g]
    free = undamped_frf(engine_order, cache=cache)
    peaks = np.array([r.peak_amplitude for r in rs])
    red = 1 - peaks / free.peak_amplitude
    j = int(np.argmax(red))
    return dict(mass_g=masses_g, peak_amplitude=peaks, peak_frequency_hz=np.array([r.peak_frequency_hz for r in rs]),
                undamped_peak_amplitude=free.peak_amplitude, reduction=red, best_mass_g=float(masses_g[j]),
                best_reduction=float(red[j]))


def mass_study_figure(mass_g=1.0, kind="cylinder", sweeps=None, engine_order=1, cache=None):
    """Slider callback (notebook 03): left, the FRF at ``mass_g``; right, precomputed
    ``sweeps`` {kind: :func:`mass_sweep_peaks` result} with the current mass marked."""
    damped = disk_frf(kind, mass_g, engine_order, cache=cache)
    free = undamped_frf(engine_order, cache=cache)
    fig, (ax, ax2) = _figure(1, 2, figsize=(11, 4.3))
    ax.plot(free.frequency_hz, 1e3 * free.tip_amplitude[:, 0], "--", color=palette.UNDAMPED, lw=1, label="no damper")
    ax.plot(damped.frequency_hz, 1e3 * damped.tip_amplitude[:, 0], color=palette.DAMPER.get(kind, palette.series(0)),
            label=f"{kind} {mass_g:.3g} g")
    ax.set_xlim(damped.frequency_hz[0], damped.frequency_hz[-1])
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("tip amplitude u_x [mm]")
    ax.set_title(f"peak {1e3 * damped.peak_amplitude:.3f} mm, reduction {100 * damped.reduction(free):.1f} %", fontsize=9)
    ax.grid(True, alpha=0.3)
    for j, (k, sw) in enumerate((sweeps or {}).items()):
        ax2.semilogx(sw["mass_g"], 1e3 * sw["peak_amplitude"], "o-", color=palette.DAMPER.get(k, palette.series(j)),
                     label=k)
    ax2.axhline(1e3 * free.peak_amplitude, color=palette.UNDAMPED, ls="--", lw=1, label="no damper")
    ax2.plot([mass_g], [1e3 * damped.peak_amplitude], "*", color=palette.UNDAMPED, ms=14, label="this mass")
    ax2.set_xscale("log")
    plain_log_ticks(ax2.xaxis)
    ax2.set_xlabel("damper mass [g]")
    ax2.set_ylabel("resonance tip amplitude u_x [mm]")
    ax2.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"reference disk, {kind} damper, EO = {engine_order}", fontsize=10)
    place_legend(ax)
    place_legend(ax2, fontsize=8)
    fig.data = (damped, free)
    return fig


def engine_order_figure(engine_order=1, kind="cylinder", mass_g=1.0, cache=None):
    """Slider callback (notebook 03): FRF with and without the damper at one engine order."""
    return disk_frf_figure(mass_g, kind, engine_order, 35.0, cache)


def engine_order_study_figure(studies: dict, engine_orders):
    """The damping potential and the optimal mass over engine order (notebook 03, the paper's
    Figs. 7 and 8 on a coarse mass grid): ``studies`` {kind: [:func:`mass_sweep_peaks` result per
    engine order]}, ``engine_orders`` the engine orders of those results.

    Left: the lowest resonance amplitude of the mass grid as a share of the damper-free peak,
    1 - best_reduction [%] on a log axis (100 %: no mass damps). Right: the grid's best mass [g]
    (not drawn where no mass reduces the peak by 1 % or more: no optimum). Returns the figure."""
    engine_orders = [int(eo) for eo in engine_orders]
    if any(len(sweeps) != len(engine_orders) for sweeps in studies.values()):
        raise ValueError("studies: need one mass_sweep_peaks result per engine order for each damper")
    fig, (ax, ax2) = _figure(1, 2, figsize=(11, 4.3))
    for j, (kind, sweeps) in enumerate(studies.items()):
        style = dict(color=palette.DAMPER.get(kind, palette.series(j)), marker="os^v"[j % 4], ms=max(9 - 3 * j, 4),
                     label=kind)       # later kinds drawn smaller: equal points stay visible
        left = [100 * (1 - sw["best_reduction"]) for sw in sweeps]
        best = [sw["best_mass_g"] if sw["best_reduction"] >= 0.01 else np.nan for sw in sweeps]
        ax.plot(engine_orders, left, **style)
        ax2.plot(engine_orders, best, **style)
    ax.set_yscale("log")
    ax.set_ylabel("lowest resonance amplitude [% of no damper]")
    ax.set_title("damping potential (Fig. 7): lower is better", fontsize=10)
    ax2.set_yscale("log")
    ax2.set_ylabel("best mass of the grid [g]")
    ax2.set_title("optimal mass (Fig. 8)", fontsize=10)
    for a in (ax, ax2):
        plain_log_ticks(a.yaxis)
        a.set_xticks(engine_orders)
        a.set_xlabel("engine order EO [-]")
        a.grid(True, which="both", alpha=0.3)
        place_legend(a, fontsize=9)
    fig.suptitle("reference disk: the best damper of a coarse mass grid over engine order", fontsize=11)
    fig.tight_layout()
    return fig


def contact_state_at_peak(frf: DiskFRF, cache: DiskFRFCache | None = None):
    """Eq. 27 at the resonance of ``frf``: the :class:`bladedamp.studies.ContactState` of
    :func:`bladedamp.studies.contact_state` (normalised first-harmonic xi motion and force of both
    contacts) for ``frf``'s disk, memoised in ``cache``."""
    if not frf.disk.has_damper:
        raise ValueError("contact_state_at_peak needs a damped response")
    return (DEFAULT_CACHE if cache is None else cache).contact_state(frf)


def platform_angle_figure(gamma_right_deg=35.0, kind="cylinder", mass_g=1.0, cache=None):
    """Slider callback (notebook 03): FRF at the right platform angle gamma_R (gamma_L = 35 deg)
    and the complex-plane contact state at resonance (Eq. 27, Fig. 11).
    ``fig.data = (damped FRF, undamped FRF, ContactState)``."""
    damped = disk_frf(kind, mass_g, 1, gamma_right_deg, cache=cache)
    free = undamped_frf(1, cache=cache)
    state = contact_state_at_peak(damped, cache)
    fig, (ax, ax2) = _figure(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [1.4, 1]})
    ax.plot(free.frequency_hz, 1e3 * free.tip_amplitude[:, 0], "--", color=palette.UNDAMPED, lw=1, label="no damper")
    ax.plot(damped.frequency_hz, 1e3 * damped.tip_amplitude[:, 0], color=palette.DAMPER.get(kind, palette.series(0)),
            label=f"{kind} {mass_g:.3g} g, gamma_R = {gamma_right_deg:g} deg")
    ax.set_xlim(damped.frequency_hz[0], damped.frequency_hz[-1])
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("tip amplitude u_x [mm]")
    ax.set_title(f"peak {1e3 * damped.peak_amplitude:.3f} mm, reduction {100 * damped.reduction(free):.1f} %; "
                 f"N_OL = {state.normal_load[0]:.3g} N, N_OR = {state.normal_load[1]:.3g} N", fontsize=9)
    ax.grid(True, alpha=0.3)
    state.plot(ax=ax2)
    ax2.set_title("Eq. 27 at resonance: |w*| < 1 sticks", fontsize=9)
    fig.suptitle(f"reference disk, {kind} damper, gamma_L = 35 deg, EO = 1", fontsize=10)
    place_legend(ax, fontsize=8)
    fig.data = (damped, free, state)
    return fig


# ---------------------------------------------------------------------------------------
# 4. mistuning (notebook 05)
# ---------------------------------------------------------------------------------------
class MistuningExplorer:
    """Mistuned responses of one disk by pattern, memoised, and the slider figure of notebook 05.

    ``disk`` : the tuned reference (its damper at every position); ``tuned_response`` : its
    DiskResponse (drawn for comparison) and ``tuned_peak_amplitude`` [m] (amplification factors);
    ``max_step`` : continuation step of each FRF; ``name`` : the disk's name in the figure's
    title. The alternating pattern is solved as its exact two-blade cyclic sector (see
    :func:`bladedamp.studies.mistuning.mistuned_response`).
    """

    def __init__(self, disk, tuned_response, tuned_peak_amplitude: float, max_step: float = 0.05,
                 name: str = "reference disk"):
        self.disk = disk
        self.name = name
        self.tuned_response = tuned_response
        self.tuned_peak_amplitude = float(tuned_peak_amplitude)
        self.max_step = max_step
        self._responses = {}

    def kappa(self, pattern="random", seed=0, std=0.02) -> np.ndarray:
        from ..studies.mistuning import pattern_kappa

        return pattern_kappa(pattern, self.disk.n_blades, std, seed)

    def response(self, pattern="random", seed=0, std=0.02):
        """The MistunedResponse of a pattern (memoised by pattern, seed, std)."""
        from ..studies.mistuning import mistuned_response

        key = (pattern, int(seed), round(float(std), 5))
        if key not in self._responses:
            k = self.kappa(pattern, seed, std)
            sector = 2 if pattern == "alternating" else None
            self._responses[key] = mistuned_response(self.disk, k[:2] if sector else k, max_step=self.max_step,
                                                     tuned_peak_amplitude=self.tuned_peak_amplitude, n_sector=sector)
        return self._responses[key]

    def figure(self, pattern="random", seed=0, std_percent=2.0):
        """Slider callback: kappa pattern, all-blade FRF and amplification per blade.
        ``fig.amplification`` (n,) (None if the continuation failed; the message is drawn
        instead) and ``fig.kappa`` (n,) are the data behind it."""
        n = self.disk.n_blades
        blade_no = np.arange(1, n + 1)
        k = self.kappa(pattern, seed, std_percent / 100)
        t0 = time.perf_counter()
        try:
            r = self.response(pattern, seed, std_percent / 100)
        except RuntimeError as e:                         # the continuation did not cover the range
            fig, ax = _figure(figsize=(8, 1.5))
            ax.axis("off")
            ax.text(0, 0.5, f"no response for this pattern: {e}", fontsize=9, wrap=True)
            fig.amplification, fig.kappa = None, k
            return fig
        elapsed = time.perf_counter() - t0
        amp = np.resize(r.amplification(), n)            # a two-blade sector repeated around the disk
        fig, axes = _figure(1, 3, figsize=(15, 3.8), gridspec_kw={"width_ratios": [0.8, 1.5, 1]})
        axes[0].bar(blade_no, k - 1, color=palette.series(0))
        axes[0].set_xlabel("blade [-]")
        axes[0].set_ylabel("kappa - 1 [-]")
        axes[0].set_title(f"{pattern}" + ("" if pattern == "alternating" else f", seed {seed}")
                          + f", {std_percent:.1f} %", fontsize=9)
        r.plot(ax=axes[1], tuned=self.tuned_response)
        axes[1].set_yscale("log")          # the least responding blade stays visible beside the largest
        plain_log_ticks(axes[1].yaxis)
        model = "two-blade sector" if r.n_sector == 2 else f"{n} blades"
        axes[1].set_title(f"{model}: {len(r.omega)} points, " + ("cached" if elapsed < 0.05 else f"{elapsed:.1f} s"),
                          fontsize=9)
        marked = sorted({int(amp.argmax()), int(amp.argmin())})    # the colours of the blades drawn in the FRF
        colours = [palette.series(marked.index(b)) if b in marked else palette.SEPARATED for b in range(n)]
        axes[2].bar(blade_no, amp, color=colours)
        axes[2].axhline(1.0, color=palette.UNDAMPED, ls="--", lw=1)
        axes[2].set_xlabel("blade [-]")
        axes[2].set_ylabel("amplification [-]")
        axes[2].set_title(f"largest {amp.max():.3f} (blade {amp.argmax() + 1}), smallest {amp.min():.3f} "
                          f"(blade {amp.argmin() + 1})", fontsize=9)
        fig.suptitle(f"{self.name}, {n} blades, mistuned", fontsize=10)
        fig.tight_layout()
        fig.amplification, fig.kappa = amp, k
        return fig
