"""Contact parameters identified from measured responses (issue 36 item 4).

Rig tests of friction dampers are run at several excitation levels: the response's dependence
on the level is what tells friction (mu, the slip limit) from stiffness (k_T, the stuck
frequency). :func:`fit_contact` chooses the design-file keys ``parameters`` of a disk model so
that its first-harmonic tip response in x matches one or more measured responses, by least
squares with the analytic Jacobian (the derivatives of every solved point in the parameters,
:mod:`bladedamp.hbm.sensitivity`, one factorisation a point), and reports each estimate with its
confidence interval, the correlations, and whether the data identify it at all.

The residual at each measured frequency is the model's response minus the measured one,
relative to the measured amplitude there (complex measurements: real and imaginary parts, the
model's phase that of the displacement to the cosine excitation, x = Re(X e^{i Omega t});
amplitude-only measurements: the moduli): a noise proportional to the signal (a few per cent,
as a rig's) weighs every point alike, which the intervals below assume. The parameters are scaled by
their initial values. With J the Jacobian of the residual r (m,) in the scaled parameters at the
optimum and s^2 = |r|^2 / (m - k), the covariance is s^2 (J^T J)^-1 and the interval
estimate +- t_{(1+c)/2, m-k} x standard error (c the confidence). A parameter is reported as not
identified where J^T J is singular in its direction (its singular value below
:data:`IDENTIFIABLE_CONDITION` of the largest) or its standard error exceeds
:data:`IDENTIFIABLE_RELATIVE_ERROR` of its estimate: its interval is then infinite, not a
confident number. A parameter whose Jacobian column at the start is (near) zero, its norm below
:data:`IDENTIFIABLE_CONDITION` of the largest column's (a direction J cannot see, whatever the
others do: J's smallest singular value is at most that column's norm), is held at its start value
and the others are fitted without it (a least squares over a direction without effect only spends
its evaluations); it is reported as not identified, its interval unbounded.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation
from .diskmodel import DiskModel, parameter_unit
from .hbm.newton import newton
from .hbm.sensitivity import state_sensitivities
from .io import Saveable
from .measurement import as_measurement
from .plotting import place_legend

#: a direction of the scaled parameters whose singular value of J is below this fraction of the
#: largest is not identified by the data (its estimate moves without changing the fit)
IDENTIFIABLE_CONDITION = 1e-6
#: a standard error above this fraction of its estimate: not identified
IDENTIFIABLE_RELATIVE_ERROR = 0.5
#: the measured band is extended by this fraction of its width on both sides for the branch
BAND_MARGIN = 0.02


@dataclass
class ContactFit(Saveable):
    """The parameters of a model fitted to measured responses (:func:`fit_contact`).

    parameters, units : (k,) the design-file keys and their units
    initial, estimate : (k,) the start and the least-squares estimate [the key's unit]
    standard_error : (k,) [the key's unit]; interval : (k, 2) the confidence interval
        (inf where not identified); confidence : its level (0.95)
    correlation : (k, k) the estimates' correlation matrix
    identified : (k,) whether the data identify each parameter (see the module docstring; one
        without effect at the start is held at its start value, its estimate that value)
    residual_rms : the root mean square of the relative residual at the estimate [-] (the
        measurement's relative noise, where the model fits)
    n_responses : frequency responses solved (every level at every evaluation)
    success, message : whether the least squares converged, and what it says
    frequency_hz, measured, fitted, initial_fit : (m,) every measured frequency [Hz], the measured
        response, the model's at the estimate and at the start [m] (complex where measured complex)
    level : (m,) the measurement each belongs to; excitations : (L, 6) each measurement's
        excitation [N, N m]
    curve_frequency_hz, curve_amplitude, curve_level : the model's whole branch at the estimate,
        every measurement's band in turn (its points, tip amplitude in x [m], measurement index)
    """

    parameters: tuple
    units: tuple
    initial: np.ndarray
    estimate: np.ndarray
    standard_error: np.ndarray
    interval: np.ndarray
    confidence: float
    correlation: np.ndarray
    identified: np.ndarray
    residual_rms: float
    n_responses: int
    success: bool
    message: str
    frequency_hz: np.ndarray
    measured: np.ndarray
    fitted: np.ndarray
    initial_fit: np.ndarray
    level: np.ndarray
    excitations: np.ndarray
    curve_frequency_hz: np.ndarray
    curve_amplitude: np.ndarray
    curve_level: np.ndarray

    def __getitem__(self, key: str) -> float:
        if key not in self.parameters:
            raise KeyError(f"{key!r} (the parameters are {', '.join(self.parameters)})")
        return float(self.estimate[self.parameters.index(key)])

    def table(self) -> str:
        """The estimates, intervals and identifiability as a text table."""
        width = max(len(k) for k in self.parameters)
        pct = int(round(100 * self.confidence))
        lines = [f"{'parameter':<{width}}  {'start':>11}  {'estimate':>11}  {'std error':>10}  "
                 f"{f'{pct} % interval':>25}"]
        for j, key in enumerate(self.parameters):
            low, high = self.interval[j]
            span = "not identified" if not self.identified[j] else f"[{low:.5g}, {high:.5g}]"
            lines.append(f"{key:<{width}}  {self.initial[j]:>11.5g}  {self.estimate[j]:>11.5g}  "
                         f"{self.standard_error[j]:>10.3g}  {span:>25}  ({self.units[j]})")
        off = np.abs(self.correlation - np.eye(len(self.parameters)))
        if len(self.parameters) > 1 and np.isfinite(off).any():
            i, j = np.unravel_index(np.nanargmax(off), off.shape)
            lines.append(f"largest correlation {self.correlation[i, j]:+.3f} ({self.parameters[i]}, "
                         f"{self.parameters[j]})")
        lines.append(f"relative residual rms {self.residual_rms:.3g}; {self.n_responses} frequency responses solved; "
                     f"{self.message}")
        return "\n".join(lines)

    def plot(self, ax=None):
        """The measured responses (markers) and the model's at the estimate (lines) and at the
        start (dashed), one colour per measurement, in one figure (mm, logarithmic: the levels'
        responses differ by their forces); returns the figure."""
        import matplotlib.pyplot as plt

        if ax is None:
            fig, ax = plt.subplots(figsize=(7.5, 4.5), constrained_layout=True)
        else:
            fig = ax.figure
        for l, excitation in enumerate(self.excitations):
            on = self.level == l
            f = self.frequency_hz[on]
            order = np.argsort(f)
            label = f"F = {np.linalg.norm(excitation[:3]):.3g} N"
            ax.plot(f[order], 1e3 * np.abs(self.measured[on])[order], "o", ms=3, color=f"C{l}",
                    label=f"measured, {label}")
            curve = self.curve_level == l
            ax.plot(self.curve_frequency_hz[curve], 1e3 * self.curve_amplitude[curve], "-", color=f"C{l}",
                    label=f"fitted, {label}")
            ax.plot(f[order], 1e3 * np.abs(self.initial_fit[on])[order], "--", lw=0.8, color=f"C{l}", alpha=0.6,
                    label="start" if l == len(self.excitations) - 1 else None)
        ax.set_yscale("log")                   # the levels' responses differ by their forces
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel("tip amplitude [mm]")
        ax.set_title("fit: " + ", ".join(f"{k.split('.')[-1]} = {v:.4g}" for k, v in zip(self.parameters, self.estimate)),
                     fontsize="medium")
        ax.grid(alpha=0.3)
        place_legend(ax, fontsize="small", ncol=2)
        return fig


def model_points(model: DiskModel, f_hz: np.ndarray, keys, harmonics, n_samples, max_step: float):
    """(u (m,) complex, du/dp (m, k) complex): the reference blade's first-harmonic tip
    displacement in x [m] of ``model`` at the frequencies ``f_hz`` [Hz] and its derivatives in the
    design-file ``keys``: the branch over the band, then at each frequency Newton from the branch
    (its first crossing, sweeping up) and dx/dp with that Newton's factorisation. ValueError where
    the branch does not cover a frequency."""
    f_hz = np.asarray(f_hz, dtype=float)
    low, high = f_hz.min(), f_hz.max()
    margin = BAND_MARGIN * max(high - low, 1e-3 * high)
    response = model.frequency_response(low - margin, high + margin, harmonics=harmonics, n_samples=n_samples,
                                        max_step=max_step, estimate_harmonic_error=False)
    system = response.model_system()
    dR_dp = model.parameter_derivatives(system, keys)
    output = response.blade_outputs(0)[0]
    X = np.asarray(response.coefficients, dtype=float).reshape(len(response.omega), -1)
    omega = np.asarray(response.omega)
    scale = np.maximum(np.abs(X).max(axis=0), 1e-3 * np.abs(X).max() + 1e-300)
    u, du = np.zeros(len(f_hz), complex), np.zeros((len(f_hz), len(keys)), complex)
    for i, f in enumerate(f_hz):
        w = 2 * np.pi * f
        k = np.flatnonzero((omega[:-1] - w) * (omega[1:] - w) <= 0)
        if not k.size:
            raise ValueError(f"the branch ({response.status_message}) does not reach {f:.6g} Hz")
        k = k[0]
        t = (w - omega[k]) / (omega[k + 1] - omega[k]) if omega[k + 1] != omega[k] else 0.0
        solved = newton(system.residual, (1 - t) * X[k] + t * X[k + 1], w, scale, 1.0, tol=1e-12,
                        factorize=system.factorize)
        if not solved.converged:
            raise ValueError(f"Newton did not converge at {f:.6g} Hz")
        u[i] = output @ solved.x
        du[i] = state_sensitivities(system, solved.x, w, dR_dp(solved.x, w), solved.solve) @ output
    return u, du


def fit_contact(model: DiskModel, measured, parameters=("damper.friction_coefficient",
                                                        "damper.tangential_stiffness_per_length_n_per_m2"),
                excitations=None, harmonics=(1,), n_samples=None, max_step: float = 0.05,
                confidence: float = 0.95, max_evaluations: int = 40) -> ContactFit:
    """Fit the design-file keys ``parameters`` of ``model`` (a TunedDisk or MistunedDisk; its
    values are the start) to measured responses (see the module docstring for the method).

    measured : a MeasuredResponse (:func:`bladedamp.load_measurement`; displacement, velocity or
        acceleration, an amplitude or complex, a response or an FRF) or a list of them, one per
        excitation level; the reference blade's tip in x is what they are compared with
    excitations : None (the model's excitation for every measurement) or one per measurement:
        a (6,) excitation (F_x, F_y, F_z, M_x, M_y, M_z) [N, N m] or a number, the force amplitude
        [N] along the model's excitation direction (an FRF is scaled by this force)
    harmonics, n_samples, max_step : the frequency responses' (``frequency_response``; the paper's
        one harmonic by default: a fit solves many)
    confidence : the intervals' level in (0, 1); max_evaluations : of the least squares

    Returns a :class:`ContactFit`. ValueError for a bad argument (naming it) or a branch that does
    not cover the measured band."""
    import scipy.optimize
    import scipy.stats

    if not isinstance(model, DiskModel):
        raise TypeError(f"model must be a TunedDisk or MistunedDisk (got {type(model).__qualname__})")
    keys = tuple(str(p) for p in parameters)
    if not keys or len(set(keys)) != len(keys):
        raise ValueError(f"parameters must name one or more different design-file keys (got {parameters!r})")
    validation.in_range("confidence", confidence, 0.0, 1.0, closed="neither")
    validation.integer("max_evaluations", max_evaluations, minimum=1)
    measured = [as_measurement(m) for m in (measured if isinstance(measured, (list, tuple)) else [measured])]
    direction = np.asarray(model.excitation, dtype=float)
    force = np.linalg.norm(direction[:3])
    if excitations is None:
        excitations = [direction] * len(measured)
    if len(excitations) != len(measured):
        raise ValueError(f"excitations must give one excitation per measurement ({len(measured)}; got {len(excitations)})")
    levels = []
    for e in excitations:
        if np.ndim(e) == 0:
            if force == 0:
                raise ValueError("excitations given as force amplitudes need a model with a force in its excitation")
            e = direction * (validation.positive("excitation force amplitude [N]", e) / force)
        e = np.asarray(validation.finite("excitations", e), dtype=float)
        if e.shape != (6,):
            raise ValueError("each excitation must be a number [N] or a 6-vector (F_x, F_y, F_z, M_x, M_y, M_z)")
        levels.append(e)
    data = []
    for m, e in zip(measured, levels):
        m = m.as_displacement()
        if m.per_force:
            m = m.at_force(np.linalg.norm(e[:3]))
        keep = np.isfinite(m.response) & (m.frequency_hz > 0)
        data.append((m.frequency_hz[keep], m.response[keep], m.is_complex))
    initial = np.array([model.parameter_value(k) for k in keys])
    if not np.all(np.isfinite(initial)) or np.any(initial == 0):
        raise ValueError(f"the start values must be finite and non-zero (the model's: {dict(zip(keys, initial))})")
    scales = [np.maximum(np.abs(v), 1e-300) for _, v, _ in data]
    count = [0]
    cache = {}

    def evaluate(z):
        key = tuple(np.round(z, 15))
        if key not in cache:
            values = dict(zip(keys, z * initial))
            rows, jac, curves = [], [], []
            for (f, v, is_complex), e, s in zip(data, levels, scales):
                m = model.with_parameters(values)
                m = m.with_parameters({f"disk.excitation_n_nm[{i}]": e[i] for i in range(6)})
                u, du = model_points(m, f, keys, harmonics, n_samples, max_step)
                count[0] += 1
                du = du * initial[None, :]
                if is_complex:
                    rows += [(u - v).real / s, (u - v).imag / s]
                    jac += [du.real / s[:, None], du.imag / s[:, None]]
                else:
                    a = np.abs(u)
                    rows.append((a - np.abs(v)) / s)
                    jac.append(np.real(np.conj(u)[:, None] * du) / (np.maximum(a, 1e-300) * s)[:, None])
                curves.append(u)
            cache.clear()
            cache[key] = (np.concatenate(rows), np.vstack(jac), np.concatenate(curves))
        return cache[key]

    _, J0, start_curve = evaluate(np.ones(len(keys)))
    columns = np.linalg.norm(J0, axis=0)
    free = columns > IDENTIFIABLE_CONDITION * columns.max() if columns.max() > 0 else np.zeros(len(keys), bool)

    def full(z_free):
        z = np.ones(len(keys))
        z[free] = z_free
        return z

    if free.any():
        solution = scipy.optimize.least_squares(lambda z: evaluate(full(z))[0], np.ones(int(free.sum())),
                                                jac=lambda z: evaluate(full(z))[1][:, free], bounds=(1e-3, 1e3),
                                                x_scale="jac", max_nfev=max_evaluations)
        z_fit, success, said = full(solution.x), bool(solution.success), str(solution.message).rstrip(".")
    else:
        z_fit, success, said = np.ones(len(keys)), False, "no parameter changes the response at the start: nothing fitted"
    r, J, fitted = evaluate(z_fit)
    m_rows, k = len(r), int(free.sum())
    dof = max(m_rows - k, 1)
    variance = float(r @ r) / dof
    _, sv, vt = np.linalg.svd(J[:, free], full_matrices=False)
    good = sv > IDENTIFIABLE_CONDITION * sv.max() if sv.size and sv.max() > 0 else np.zeros(k, bool)
    inverse = np.zeros((len(keys), len(keys)))
    inverse[np.ix_(free, free)] = (vt[good].T / sv[good] ** 2) @ vt[good]
    covariance = variance * inverse * np.outer(initial, initial)
    standard_error = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    estimate = z_fit * initial
    weak = ~free
    if (~good).any():
        weak[free] = np.abs(vt[~good]).max(axis=0) > 1e-3
    identified = ~weak & (standard_error <= IDENTIFIABLE_RELATIVE_ERROR * np.abs(estimate))
    standard_error = np.where(weak, np.inf, standard_error)
    t = scipy.stats.t.ppf(0.5 + confidence / 2, dof)
    interval = np.column_stack([estimate - t * standard_error, estimate + t * standard_error])
    interval[~identified] = [-np.inf, np.inf]
    with np.errstate(invalid="ignore", divide="ignore"):
        se = np.sqrt(np.diag(covariance))
        correlation = covariance / np.outer(se, se)
    correlation[~np.isfinite(correlation)] = np.nan
    frequency = np.concatenate([f for f, _, _ in data])
    values = np.concatenate([v for _, v, _ in data])
    level = np.concatenate([np.full(len(f), l) for l, (f, _, _) in enumerate(data)])
    curves = []
    for l, ((f, _, _), e) in enumerate(zip(data, levels)):
        m = model.with_parameters(dict(zip(keys, estimate)))
        m = m.with_parameters({f"disk.excitation_n_nm[{i}]": e[i] for i in range(6)})
        margin = BAND_MARGIN * max(f.max() - f.min(), 1e-3 * f.max())
        branch = m.frequency_response(f.min() - margin, f.max() + margin, harmonics=harmonics, n_samples=n_samples,
                                      max_step=max_step, estimate_harmonic_error=False)
        curves.append((branch.frequency_hz, branch.tip_amplitude[:, 0] if branch.tip_amplitude.ndim == 2
                       else branch.tip_amplitude[:, 0, 0], np.full(len(branch.omega), l)))
    message = said if success else f"not converged: {said}"
    if not identified.all():
        message += "; not identified by these data: " + ", ".join(
            k + ("" if f else " (no effect on the response at the start: held at its start value)")
            for k, i, f in zip(keys, identified, free) if not i)
    return ContactFit(keys, tuple(parameter_unit(k) for k in keys), initial, estimate, standard_error, interval,
                      float(confidence), correlation, identified, float(np.sqrt(np.mean(r ** 2))), count[0],
                      success, message, frequency, values, fitted, start_curve, level,
                      np.array(levels), *(np.concatenate(c) for c in zip(*curves)))

