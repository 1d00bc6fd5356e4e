"""Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015).

A damped nonlinear mode is the periodic motion of the *autonomous* system with an artificial
negative modal damping term that makes up for the dissipation of the friction contacts and the
viscous damping over a period::

    M x'' + (D - 2 zeta omega M) x' + K x + f_nl(x) = f_static

(the excitation's dynamic part is dropped; a static load, the damper's centrifugal preload
F_CG with a static harmonic, is kept). The unknowns are the harmonic coefficients of x,
omega and zeta, at a prescribed modal amplitude ``a``: with a harmonic basis (see
:mod:`bladedamp.hbm.fourier`), x = x_0 + a * phi (the static harmonic x_0 is not scaled by a).
Two equations close the problem:

* amplitude: phi_1^H M phi_1 = 1 (first harmonic, complex X = a_1 - i b_1): for a linear system
  ``a`` is the modal coordinate of the mass-normalised mode;
* phase: the sine coefficient of the first harmonic of a reference DOF is zero (default: the
  DOF of the largest mass-weighted amplitude of the stuck linear mode).

The residual is :meth:`HarmonicBalanceSystem.residual` plus the dynamic excitation (so it is
zero) minus 2 zeta omega^2 (d/dtau (x) M) x, with every derivative analytic: dR/dx from the
system, dR/domega from the system plus the excitation's and the EPMC term's, dR/dzeta =
-2 omega^2 (d/dtau (x) M) x. Newton (the system's linear solver on the bordered, column-scaled
Jacobian) at each amplitude, sequential continuation in log(a) with a secant predictor and
step halving, from the stuck linear mode (the generalised eigenproblem of the first-harmonic
block of the Jacobian at the static state; for a preload that follows omega it is iterated in
omega to a fixed point).

Energy: dotting the residual with x' over a period gives exactly
2 zeta omega oint x'^T M x' dt = dissipated energy per cycle (viscous + contacts), for any
harmonic truncation (``NonlinearModeResponse.dissipated_energy`` holds the right-hand side).

Single-nonlinear-mode synthesis of the forced response (Krack 2014/2015): for a first-harmonic
force F, (omega(a)^2 - Omega^2 + 2 i zeta(a) omega(a) Omega) a = phi_1^H F; its largest
amplitude (the resonance) solves 2 zeta omega^2 sqrt(1 - zeta^2) a = |phi_1^H F| at
Omega = omega sqrt(1 - 2 zeta^2) (:meth:`NonlinearModeResponse.forced_peak`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from .. import validation
from ..io import Saveable
from .fourier import HarmonicBasis
from .newton import LineSearch, NewtonResult, equilibrated, newton


# ----- the EPMC residual ------------------------------------------------------------------
class EPMCProblem:
    """The EPMC residual of one model's harmonic balance system, in the unknowns
    u = (x_static, phi_dynamic) (C*n), omega, zeta at a given modal amplitude."""

    def __init__(self, system, reference_dof: int):
        self.system = system
        basis = system.basis
        self.basis = basis
        self.C, self.n = basis.n_coeffs, system.n_dof
        self.N = self.C * self.n
        mass = system.mass.toarray() if hasattr(system.mass, "toarray") else np.atleast_2d(np.asarray(system.mass, float))
        self.M = mass
        # (d/dtau (x) M): x' = omega * E_M-less derivative; the EPMC term is -2 zeta omega^2 E x
        self.E = np.kron(basis.derivative, mass)
        static = np.zeros(self.N, dtype=bool)
        if basis.has_static:
            j0 = basis.cos_index(0)
            static[j0 * self.n:(j0 + 1) * self.n] = True
        self.static = static
        j1 = basis.cos_index(1)
        self.i_cos = slice(j1 * self.n, (j1 + 1) * self.n)
        self.i_sin = slice((j1 + 1) * self.n, (j1 + 2) * self.n)
        self.phase_index = (j1 + 1) * self.n + reference_dof
        self.reference_dof = reference_dof
        self.last_worst = -1          # unknown of the largest update of the last Newton iteration

    def describe(self, index: int, dof_names) -> str:
        """Name of unknown ``index``: 'omega', 'zeta' or '<harmonic term> of <dof>'."""
        if index == self.N:
            return "omega"
        if index == self.N + 1:
            return "zeta"
        j, d = divmod(index, self.n)
        h = int(self.basis.order[j])
        term = "static term" if h == 0 else f"{'cos' if self.basis.cos_index(h) == j else 'sin'} {h}"
        return f"the {term} of {dof_names[d] if d < len(dof_names) else d}"

    def scaling(self, a: float) -> np.ndarray:
        """x = S u: 1 on the static rows, a on the dynamic ones."""
        return np.where(self.static, 1.0, a)

    def state(self, u: np.ndarray, a: float) -> np.ndarray:
        return self.scaling(a) * u

    def dynamic_excitation(self, omega: float):
        f, df = self.system.excitation(omega)
        f, df = np.array(f, dtype=float), np.array(df, dtype=float)
        f[self.static] = 0.0
        df[self.static] = 0.0
        return f, df

    def residual(self, y: np.ndarray, a: float, jacobian: bool = True):
        """R (N + 2,) and dR/dy (N + 2, N + 2) for y = (u, omega, zeta)."""
        N = self.N
        u, omega, zeta = y[:N], float(y[N]), float(y[N + 1])
        S = self.scaling(a)
        x = S * u
        R, J, Rw = self.system.residual(x, omega, jacobian)
        f, df = self.dynamic_excitation(omega)
        Ex = self.E @ x
        R = R + f - 2 * zeta * omega ** 2 * Ex
        phi_c, phi_s = u[self.i_cos], u[self.i_sin]
        norm = phi_c @ self.M @ phi_c + phi_s @ self.M @ phi_s
        out = np.concatenate([R, [u[self.phase_index], norm - 1.0]])
        if not jacobian:
            return out, None
        J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
        Jfull = np.zeros((N + 2, N + 2))
        Jfull[:N, :N] = (J - 2 * zeta * omega ** 2 * self.E) * S[None, :]
        Jfull[:N, N] = Rw + df - 4 * zeta * omega * Ex
        Jfull[:N, N + 1] = -2 * omega ** 2 * Ex
        Jfull[N, self.phase_index] = 1.0
        Jfull[N + 1, self.i_cos] = 2 * self.M @ phi_c
        Jfull[N + 1, self.i_sin] = 2 * self.M @ phi_s
        return out, Jfull


#: the EPMC Newton's line search: the step fraction is halved down to 1/32 (the AFT's friction
#: forces are piecewise smooth: a full step can 2-cycle across a kink, a stick-slip switch of a
#: time sample; halving the step breaks the cycle), without a stagnation guard
EPMC_LINE_SEARCH = LineSearch(min_step=1 / 32, stagnation_window=None)


def _solve(problem: EPMCProblem, y0, a, y_scale, r_scale, tol=1e-10, max_iter=25) -> NewtonResult:
    """The EPMC residual solved at modal amplitude ``a`` by :func:`bladedamp.hbm.newton.newton`:
    the bordered Jacobian equilibrated by ``y_scale`` (N + 2,) and the residual scale
    ``r_scale`` [N] of the N force rows (the two closing equations unscaled), the convergence
    test in the max norm, a line search (EPMC_LINE_SEARCH) that keeps omega > 0 (a converged
    point with omega <= 0 is not converged). Sets ``problem.last_worst`` (the unknown of the
    largest scaled last update)."""
    N = problem.N
    residual_scale = np.concatenate([np.full(N, float(r_scale)), [1.0, 1.0]])
    sol = newton(problem.residual, y0, a, y_scale, residual_scale, tol=tol, max_iter=max_iter,
                 factorize=equilibrated(y_scale, residual_scale), line_search=EPMC_LINE_SEARCH, norm=np.inf,
                 admissible=lambda y: y[N] > 0)
    if sol.step is not None:
        problem.last_worst = int(np.argmax(np.abs(sol.step / y_scale)))
    return sol


# ----- the linear stuck mode ----------------------------------------------------------------
def _static_equilibrium(model, system, omega, tol=1e-12):
    """The static state (no dynamic motion): the model's (``static_state``: the dampers seated on
    rigid platforms), refined by :func:`bladedamp.hbm.newton.newton` on the static harmonic when
    the basis has one (the damper seated under F_CG on the flexible blades, with the harmonic
    balance's own contact law and retention spring), to the scaled residual ``tol`` (its scale:
    the static load). The model's state if that Newton does not converge."""
    x = np.array(model.static_state(system, omega), dtype=float) if hasattr(model, "static_state") \
        else np.zeros(system.n_unknowns)
    basis = system.basis
    if not basis.has_static:
        return x
    n = system.n_dof
    j0 = basis.cos_index(0)
    rows = slice(j0 * n, (j0 + 1) * n)

    def static_rows(x_static, w, jacobian=True):
        y = x.copy()
        y[rows] = x_static
        R, J, _ = system.residual(y, w, jacobian)
        if not jacobian:
            return R[rows], None
        J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
        return R[rows], J[rows, rows]

    load = max(np.linalg.norm(system.excitation(omega)[0][rows]), 1e-300)
    sol = newton(static_rows, x[rows], omega, max(np.abs(x[rows]).max(), 1e-300), load, tol=tol, max_iter=50,
                 factorize=lambda J: lambda b: np.linalg.solve(J, b))
    if sol.converged:
        x[rows] = sol.x
    return x


def linear_stuck_mode(model, system, mode: int = 0, omega_guess: float | None = None, max_iter: int = 30):
    """The linear mode ``mode`` of the stuck (zero-amplitude) linearisation.

    Returns (omega [rad/s], zeta, phi (n,) complex mass-normalised first-harmonic shape, x_static
    (C*n,), number of modes). The stiffness is the first-harmonic block of dR/dx at the static
    state without the inertia and viscous parts; a preload that depends on omega (F_CG(Omega_E))
    is followed to the fixed point omega = omega_mode(omega). zeta = Re(phi^H D phi) / (2 omega)."""
    basis = system.basis
    n = system.n_dof
    M = np.atleast_2d(np.asarray(system.mass.toarray() if hasattr(system.mass, "toarray") else system.mass, float))
    D = np.atleast_2d(np.asarray(system.damping.toarray() if hasattr(system.damping, "toarray") else system.damping, float))
    K = np.atleast_2d(np.asarray(system.stiffness.toarray() if hasattr(system.stiffness, "toarray") else system.stiffness, float))
    j1 = basis.cos_index(1)
    ca, cb = slice(j1 * n, (j1 + 1) * n), slice((j1 + 1) * n, (j1 + 2) * n)
    if omega_guess is None:
        w2 = scipy.linalg.eigvals(K, M)
        w2 = np.sort(np.real(w2[np.isfinite(w2) & (np.real(w2) > 0)]))
        omega_guess = float(np.sqrt(w2[min(mode, len(w2) - 1)])) if len(w2) else 1.0
    omega = omega_guess
    for _ in range(max_iter):
        xs = _static_equilibrium(model, system, omega)
        _, J, _ = system.residual(xs, omega)
        J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
        A, _ = system.dynamic_stiffness(omega)
        A = A.toarray() if hasattr(A, "toarray") else np.asarray(A)
        Jnl = J - A
        K1 = K + Jnl[ca, ca] + 1j * Jnl[ca, cb]
        K1 = 0.5 * (K1 + K1.conj().T)              # Hermitian to rounding (stuck contacts: symmetric)
        lam, vec = scipy.linalg.eig(K1, M)
        ok = np.isfinite(lam) & (np.real(lam) > 0)
        lam, vec = lam[ok], vec[:, ok]
        order = np.argsort(np.real(lam))
        if mode >= len(order):
            raise ValueError(f"mode must be an integer in [0, {len(order) - 1}] (the stuck system's "
                             f"modes of positive frequency; got {mode})")
        k = order[mode]
        new = float(np.sqrt(np.real(lam[k])))
        phi = vec[:, k]
        converged = abs(new - omega) <= 1e-13 * new
        omega = new
        if converged:
            break
    w_all = np.sqrt(np.real(lam[order]))
    gap = np.min(np.abs(np.delete(w_all, mode) - omega)) / omega if len(w_all) > 1 else np.inf
    if gap < 1e-6:
        raise ValueError(f"mode {mode} ({omega / (2 * np.pi):.6g} Hz) is a repeated mode of the stuck system "
                         f"(another within {gap:.1e} relative): one phase condition does not fix its shape; "
                         "for a tuned assembly use the TunedDisk (cyclic symmetry: one nodal diameter, "
                         "the engine order) or mistune it")
    phi = phi / np.sqrt(np.real(phi.conj() @ M @ phi))
    zeta = float(np.real(phi.conj() @ D @ phi)) / (2 * omega)
    return omega, zeta, phi, xs, len(order)


# ----- single-nonlinear-mode synthesis ------------------------------------------------------
def peak_function(a, omega, zeta, phi1, force) -> np.ndarray:
    """h(a) (n,) = 2 zeta omega^2 sqrt(1 - zeta^2) a - |phi_1^H F| [N per modal amplitude unit]
    at the mode's points: amplitudes ``a`` (n,), omega (n,) [rad/s], zeta (n,), first-harmonic
    shapes ``phi1`` (n, n_dof) complex and the first-harmonic force ``force`` (n_dof,) [N]. The
    resonance of the single-mode synthesis is its largest root (Krack 2014)."""
    zeta = np.asarray(zeta, dtype=float)
    return 2 * zeta * np.asarray(omega) ** 2 * np.sqrt(np.clip(1 - zeta ** 2, 0, None)) * np.asarray(a) \
        - np.abs(np.asarray(phi1).conj() @ force)


def peak_bracket(h) -> int:
    """Index i of the interval [a_i, a_i+1] holding the resonance: the last point with h <= 0,
    if h starts <= 0 and some later point has h > 0; -1 otherwise (the peak is below or above
    the computed range)."""
    h = np.asarray(h)
    below = np.flatnonzero(h <= 0)
    if h[0] > 0 or not below.size or below[-1] == h.size - 1:
        return -1
    return int(below[-1])


def _peak_record(a: float, omega: float, zeta: float, output_amplitude) -> dict:
    """:meth:`NonlinearModeResponse.forced_peak`'s record of the resonance at modal amplitude
    ``a``, where the mode has omega [rad/s] and zeta: the excitation frequency of the peak is
    Omega = omega sqrt(1 - 2 zeta^2); ``output_amplitude`` (k,) [m]."""
    return {"modal_amplitude": a, "frequency_hz": omega * np.sqrt(max(1 - 2 * zeta ** 2, 0.0)) / (2 * np.pi),
            "damping_ratio": zeta, "output_amplitude": output_amplitude, "found": True, "message": "peak found"}


# ----- the result -------------------------------------------------------------------------
@dataclass
class NonlinearModeResponse(Saveable):
    """A damped nonlinear mode (EPMC) over modal amplitude.

    Attributes (n amplitudes, C coefficients, n_dof degrees of freedom)
    ----------
    modal_amplitude : (n,) modal amplitude a [sqrt(kg) m for a mass-normalised shape]
    frequency_hz : (n,) natural frequency omega(a) / 2 pi [Hz]
    damping_ratio : (n,) modal damping ratio zeta(a) [-]
    coefficients : (n, C, n_dof) mode shape harmonics phi(a) (x = x_0 + a phi; the static
        harmonic's row holds x_0 itself, not scaled by a) [SI per modal amplitude]
    basis : HarmonicBasis
    dof_names : names of the degrees of freedom
    success : whether every requested amplitude converged
    message : why it stopped
    iterations : (n,) Newton iterations per point
    dissipated_energy : (n,) energy dissipated per cycle (viscous + contacts) [J]
    output_amplitude : (n, k) the model's first-harmonic output amplitudes at each point
        (``model.output_amplitudes``: the oscillator's |x|, the disk's tip u_x, u_y, u_z) [m]
    excitation : (n_dof,) complex first-harmonic excitation of the model at the first point's
        frequency (X = a_1 - i b_1), the default force of :meth:`forced_peak` [N]
    linear_frequency_hz, linear_damping_ratio : the stuck linear mode's (the start) [Hz], [-]
    reference_dof : the DOF whose first-harmonic sine coefficient is zero (phase)
    mode : the mode number (0: the first of the stuck system)
    gaps : [(a_lo, a_hi), ...] amplitude intervals the continuation jumped over: Newton did not
        converge at any point close to a non-smooth point there (both ends are solutions)
    """

    modal_amplitude: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    coefficients: np.ndarray
    basis: HarmonicBasis
    dof_names: tuple = ()
    success: bool = True
    message: str = ""
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    dissipated_energy: np.ndarray = field(default_factory=lambda: np.zeros(0))
    output_amplitude: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    excitation: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=complex))
    linear_frequency_hz: float = float("nan")
    linear_damping_ratio: float = float("nan")
    reference_dof: int = 0
    mode: int = 0
    gaps: list = field(default_factory=list)

    @property
    def omega(self) -> np.ndarray:
        """Natural angular frequency omega(a) [rad/s]."""
        return 2 * np.pi * np.asarray(self.frequency_hz)

    def shape(self, harmonic: int = 1) -> np.ndarray:
        """(n, n_dof) complex harmonic ``harmonic`` of phi (X = a_h - i b_h)."""
        j = self.basis.cos_index(harmonic)
        c = np.asarray(self.coefficients)
        return c[:, j] + 0j if harmonic == 0 else c[:, j] - 1j * c[:, j + 1]

    def forced_peak(self, force=None, scale: float = 1.0) -> dict:
        """Resonance of the forced response by single-nonlinear-mode synthesis.

        ``force``: (n_dof,) first-harmonic force amplitude (real: a cosine load; complex X = a - i b),
        default the model's own ``excitation``; ``scale`` multiplies it (excitation levels).
        The peak amplitude is the largest root a on the computed range of
        h(a) = 2 zeta(a) omega(a)^2 sqrt(1 - zeta^2) a - |phi_1(a)^H F|, at the excitation
        frequency Omega = omega sqrt(1 - 2 zeta^2).

        Between the computed amplitudes zeta, omega, |phi_1^H F| and log(output / a) are
        interpolated by not-a-knot cubic splines in log a (exact at the computed points). The
        mode's zeta(a) has kinks (a time sample of the AFT switching stick / slip), so any
        interpolation errs by up to ~1e-3 of the peak with 60 points per mode, and that error
        jumps as the points move with a design parameter (a damper mass). A peak computed with
        ``nonlinear_mode(..., resolve_peaks=...)`` for this force has an EPMC solution at its root
        (h zero there to ~1e-12 of |phi^H F|): the spline passes through it, so the peak is the
        EPMC's to its Newton tolerance, not interpolated.

        Returns {"modal_amplitude", "frequency_hz", "output_amplitude" (k,) [m],
        "damping_ratio", "found" (bool), "message"}; nan values when the peak is beyond the
        computed range (the message says which end)."""
        from scipy.interpolate import CubicSpline
        from scipy.optimize import brentq

        F = self.excitation if force is None else np.asarray(force)
        F = np.asarray(F, dtype=complex).ravel() * float(validation.finite("scale", scale))
        n_dof = self.coefficients.shape[2]
        if F.shape != (n_dof,):
            raise ValueError(f"force must have shape ({n_dof},) (one first-harmonic amplitude per DOF; got {F.shape})")
        a = np.asarray(self.modal_amplitude, dtype=float)
        out = np.asarray(self.output_amplitude, dtype=float)
        nan = {"modal_amplitude": np.nan, "frequency_hz": np.nan, "damping_ratio": np.nan,
               "output_amplitude": np.full(np.shape(out)[1:], np.nan), "found": False}
        if a.size < 2:
            return {**nan, "message": "need at least two amplitudes"}
        h = peak_function(a, self.omega, self.damping_ratio, self.shape(1), F)
        i = peak_bracket(h)
        if i < 0:
            where = "below the smallest" if h[0] > 0 else "above the largest"
            return {**nan, "message": f"the peak lies {where} amplitude {a[0 if h[0] > 0 else -1]:.4g}"}
        la = np.log(a)
        z = np.asarray(self.damping_ratio, dtype=float)
        fz, fw = CubicSpline(la, z), CubicSpline(la, self.omega)
        fg = CubicSpline(la, np.abs(self.shape(1).conj() @ F))

        def hfun(s):
            zz, ww = float(fz(s)), float(fw(s))
            return 2 * zz * ww ** 2 * np.sqrt(max(1 - zz ** 2, 0.0)) * np.exp(s) - float(fg(s))

        s = brentq(hfun, la[i], la[i + 1], xtol=1e-14, rtol=1e-14) if h[i] < 0 else la[i]
        ap, zp, wp = float(np.exp(s)), float(fz(s)), float(fw(s))
        if out.size:
            out_amp = np.exp(CubicSpline(la, np.log(np.maximum(out / a[:, None], 1e-300)), axis=0)(s)) * ap
        else:
            out_amp = np.zeros(0)
        return _peak_record(ap, wp, zp, out_amp)

    def plot(self, ax=None, *, label: str | None = None, **kwargs):
        """Frequency [Hz] (top) and damping ratio [%] (bottom) over the modal amplitude (log x).
        ``ax``: a pair of axes (a new figure if None); returns the pair."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
        ax_f, ax_z = ax
        label = label or f"mode {self.mode}, H={self.basis.harmonics}"
        ax_f.semilogx(self.modal_amplitude, self.frequency_hz, label=label, **kwargs)
        ax_z.semilogx(self.modal_amplitude, 100 * np.asarray(self.damping_ratio), label=label, **kwargs)
        ax_f.set_ylabel("natural frequency [Hz]")
        ax_z.set_ylabel("damping ratio [%]")
        ax_z.set_xlabel("modal amplitude a [sqrt(kg) m]")
        for a_ in (ax_f, ax_z):
            a_.grid(True, which="both", alpha=0.3)
        ax_f.legend()
        if not self.success:
            ax_f.set_title(f"incomplete: {self.message}", fontsize=8)
        return ax


# ----- the driver --------------------------------------------------------------------------
# the peak tracked from a neighbouring design (tracked_forced_peaks): the offset of the secant's
# second point in log a (its first step is a difference quotient of h; _resolve_peaks takes 1e-3
# of its bracket, 3.4e-4 for the cylinder's 30 points over 4.2 decades, and h is smooth at that
# scale: 1e-3 serves), and the secant steps before giving up (the full mode then): 12 steps
# (14 solves) leave a margin over the solves a peak takes (benchmarks/README.md, 'Moved from the
# package's docstrings', hbm/nonlinear_modes.py)
TRACK_FIRST_STEP = 1e-3
TRACK_MAXITER = 12
def _local_force_norm(system, x, omega) -> float:
    """Norm of every element's local forces at ``x`` (e.g. the contacts' normal preload): the
    level of the rounding in the residual's element forces."""
    C = system.basis.n_coeffs
    total = 0.0
    for c in system.couplings:
        local = (c.matrix @ x).reshape(C, c.element.n_local)
        force, _, _ = c.element.harmonic_forces(local, system.basis, omega, False)
        total += float(np.linalg.norm(force))
    return total


def _default_amplitudes(problem: EPMCProblem, x_static, phi_u, omega, n_points=60):
    """Modal amplitudes from fully stuck to gross slip: along the stuck linear mode, the
    nonlinear forces' relative deviation from their stuck linearisation g(a) is scanned on a log
    grid (1e-12..1e6, 4 per decade); onset: the first a with g > 1e-6 where the rounding of the
    element forces (1e2 eps times their norm, e.g. the normal preload) is below 1e-9 of the
    linear force, gross slip: the first a with g within 0.5 % of its value at 1e6. Returns ``n_points`` log-spaced from
    onset / 10 to 10 x gross slip."""
    system = problem.system
    _, J, _ = system.residual(x_static, omega)
    A, _ = system.dynamic_stiffness(omega)
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    A = A.toarray() if hasattr(A, "toarray") else np.asarray(A)
    Jnl = J - A
    f = system.excitation(omega)[0]

    def nonlinear_force(x):
        R, _, _ = system.residual(x, omega, False)
        return R - A @ x + f

    f0 = nonlinear_force(x_static)
    dyn = np.where(problem.static, 0.0, phi_u)
    lin = Jnl @ dyn
    if np.linalg.norm(lin) == 0:
        raise ValueError("the mode has no amplitude-dependent element to follow (no contact or nonlinear "
                         "force along it); pass amplitudes explicitly")
    grid = np.logspace(-12, 6, 73)
    g = np.array([np.linalg.norm(nonlinear_force(x_static + a * dyn) - f0 - a * lin) / (a * np.linalg.norm(lin))
                  for a in grid])
    noise = 1e2 * np.finfo(float).eps * (_local_force_norm(system, x_static, omega) + np.linalg.norm(f0)) \
        / (grid * np.linalg.norm(lin))
    onset = np.flatnonzero((g > 1e-6) & (noise < 1e-9))
    if not onset.size:
        raise ValueError("the nonlinear forces stay linear along the mode for modal amplitudes 1e-12..1e6; "
                         "pass amplitudes explicitly")
    a_on = grid[onset[0]]
    # gross slip: g within 0.5 % of its large-amplitude limit (1 for a contact whose every force
    # saturates; below 1 when the normal springs stay linear along the mode, e.g. the wedge: 0.51)
    gross = np.flatnonzero((np.abs(g - g[-1]) <= 5e-3 * g[-1]) & (grid > a_on))
    a_gross = grid[gross[0]] if gross.size else grid[-1]
    return np.logspace(np.log10(a_on) - 1, np.log10(max(a_gross, 10 * a_on)) + 1, n_points)


class _EPMCStart:
    """What the EPMC solves of one model share: its harmonic balance ``system``, the stuck linear
    mode (``omega_lin`` [rad/s], ``zeta_lin``, static state ``x_static`` (C*n,), the unknowns
    ``u0`` (C*n,) of its mass-normalised shape), the ``problem`` with its phase condition on
    ``reference_dof`` (default: the largest mass-weighted amplitude of the stuck mode) and the
    Newton scales (:meth:`scales`)."""

    def __init__(self, model, mode: int, harmonics, n_samples, reference_dof: int | None):
        system = model.hbm_system(harmonics, n_samples)
        basis = system.basis
        C, n = basis.n_coeffs, system.n_dof
        omega_lin, zeta_lin, phi, x_static, _ = linear_stuck_mode(model, system, mode)
        M = np.atleast_2d(np.asarray(system.mass.toarray() if hasattr(system.mass, "toarray") else system.mass, float))
        if reference_dof is None:
            weight = np.abs(phi) * np.sqrt(np.clip(np.diag(M), 0, None))
            reference_dof = int(np.argmax(weight))
        reference_dof = validation.integer("reference_dof", reference_dof, minimum=0, maximum=n - 1)
        if abs(phi[reference_dof]) < 1e-12 * np.abs(phi).max():
            raise ValueError(f"reference_dof {reference_dof} does not move in mode {mode}; choose a DOF in "
                             f"[0, {n - 1}] that does (default: the largest)")
        phi = phi * np.exp(-1j * np.angle(phi[reference_dof]))
        problem = EPMCProblem(system, reference_dof)
        j1 = basis.cos_index(1)
        u0 = np.array(x_static, dtype=float)
        U = u0.reshape(C, n)
        U[j1] = phi.real
        U[j1 + 1] = -phi.imag
        u0[problem.phase_index] = 0.0
        self.system, self.problem = system, problem
        self.omega_lin, self.zeta_lin, self.x_static, self.u0 = omega_lin, zeta_lin, x_static, u0

        # scales of the unknowns: per DOF, the stuck shape (floored), the static state, omega, zeta
        dof_scale = np.abs(phi)
        self._dof_scale = np.maximum(dof_scale, 1e-6 * dof_scale.max())
        self._y_scale_base = np.tile(self._dof_scale, C)
        self._static_scale = np.abs(x_static)
        self._zeta_scale = max(abs(zeta_lin), 1e-3)
        self._r_base = omega_lin ** 2 * np.linalg.norm(np.tile(M @ self._dof_scale, C))
        f_static = system.excitation(omega_lin)[0][problem.static]
        # residual scale: the linear forces of the mode, the static load, and a floor of 1e-4 of the
        # element forces (the contacts' preload: their rounding would stall Newton at tiny amplitudes)
        self._f_static_norm = (np.linalg.norm(f_static) if f_static.size else 0.0) \
            + 1e-4 * _local_force_norm(system, x_static, omega_lin)

    def scales(self, a: float):
        """(scale of the unknowns y (N + 2,), scale of the residual [N]) at modal amplitude ``a``."""
        problem = self.problem
        ys = self._y_scale_base.copy()
        if problem.static.any():
            ys[problem.static] = np.maximum(self._static_scale[problem.static],
                                            1e-3 * max(self._static_scale.max(), a * self._dof_scale.max()) + 1e-300)
        return np.concatenate([ys, [self.omega_lin, self._zeta_scale]]), a * self._r_base + self._f_static_norm


def nonlinear_mode(model, mode: int = 0, amplitudes=None, harmonics=(1,), n_samples=None,
                   reference_dof: int | None = None, tol: float = 1e-10, max_log_step: float = 0.25,
                   n_points: int = 60, resolve_peaks=()) -> NonlinearModeResponse:
    """Damped nonlinear mode ``mode`` of ``model`` by EPMC (see the module docstring).

    Parameters
    ----------
    model : anything with ``hbm_system(harmonics, n_samples)``; validated for the
        FrictionOscillator and the TunedDisk (one sector by cyclic symmetry, the engine order as
        nodal diameter, both damper types). A MistunedDisk runs through the same code but is not
        validated (dense Jacobian of the whole assembly: slow; a tuned assembly's double modes
        are refused)
    mode : mode number of the stuck linear system (0: the lowest frequency)
    amplitudes : modal amplitudes a (> 0; computed in ascending order); default ``n_points``
        log-spaced from fully stuck to gross slip, derived from the model along its stuck mode
    harmonics : harmonic set, must contain 1 (the normalisation's harmonic); 0 adds the static term
    reference_dof : DOF of the phase condition (default: the largest mass-weighted amplitude of
        the stuck mode)
    tol : Newton tolerance (scaled residual; scaled update sqrt(tol))
    max_log_step : largest continuation step in log10(a) [decades], (0, 2]
    resolve_peaks : excitation scales (multiples of the model's first-harmonic excitation, > 0)
        whose single-mode synthesis resonance (:meth:`NonlinearModeResponse.forced_peak`) is
        solved for, not interpolated: after the continuation, a root search in log a on the
        interval that brackets the root of h(a) (a secant from the spline's root, Brent on the
        interval as the fallback), each evaluation an EPMC Newton solve from the interpolated
        neighbours, to 1e-7 in log a, and one more solve at the secant's root (h zero there to
        ~1e-12 of |phi^H F|); the solution at the root is added to the
        points (so ``modal_amplitude`` holds these amplitudes besides ``amplitudes``). A peak
        outside the computed range, or a Newton failure in the interval, leaves it interpolated

    Continuation starts at the stuck linear mode at min(amplitudes[0], onset / 10) and steps in
    log(a) (secant predictor, step halving down to 1e-3 decades on failure, then a jump of up to
    0.3 decades over a non-smooth point, recorded in ``gaps``). A failure stops it: the result
    holds the converged amplitudes, ``success`` False, and the message says where and which
    unknown did not settle.
    """
    if not hasattr(model, "hbm_system"):
        raise TypeError(f"model must provide hbm_system(harmonics, n_samples) (got {type(model).__qualname__})")
    mode = validation.integer("mode", mode, minimum=0)
    try:
        harmonics = tuple(int(h) for h in (harmonics if np.ndim(harmonics) else (harmonics,)))
    except (TypeError, ValueError):
        raise ValueError(f"harmonics must be a tuple of integers >= 0 containing 1 (got {harmonics!r})") from None
    if 1 not in harmonics:
        raise ValueError(f"harmonics must contain 1, the harmonic of the amplitude and phase normalisation "
                         f"(got {harmonics!r})")
    validation.in_range("tol", tol, 0.0, 1e-3, closed="right")
    validation.in_range("max_log_step (decades)", max_log_step, 0.0, 2.0, closed="right")
    n_points = validation.integer("n_points", n_points, minimum=2)
    resolve_peaks = np.atleast_1d(np.asarray(resolve_peaks, dtype=float))
    if resolve_peaks.ndim != 1:
        raise ValueError(f"resolve_peaks must be a 1-D sequence of excitation scales in (0, inf) "
                         f"(got shape {resolve_peaks.shape})")
    if resolve_peaks.size:
        validation.positive("resolve_peaks (excitation scales)", resolve_peaks)
    if amplitudes is not None:
        amps = np.atleast_1d(np.asarray(amplitudes, dtype=float))
        if amps.ndim != 1 or amps.size == 0:
            raise ValueError(f"amplitudes must be a non-empty 1-D array of modal amplitudes in (0, inf) (got shape {amps.shape})")
        validation.positive("amplitudes (modal amplitudes)", amps)
        amps = np.unique(amps)

    start = _EPMCStart(model, mode, harmonics, n_samples, reference_dof)
    system, problem, scales = start.system, start.problem, start.scales
    omega_lin, zeta_lin, x_static, u0 = start.omega_lin, start.zeta_lin, start.x_static, start.u0

    if amplitudes is None:
        amps = _default_amplitudes(problem, x_static, u0, omega_lin, n_points)

    y_prev = np.concatenate([u0, [omega_lin, zeta_lin]])
    la_prev = None
    y_prev2, la_prev2 = None, None
    # internal start in the stuck limit
    if amplitudes is None:
        a_start = amps[0]
    else:
        try:
            a_start = min(amps[0], _default_amplitudes(problem, x_static, u0, omega_lin, 2)[0])
        except ValueError:        # nothing nonlinear along the mode: start where asked
            a_start = amps[0]
    sol = _solve(problem, y_prev, a_start, *scales(a_start), tol=tol)
    y, ok, it = sol.x, sol.converged, sol.iterations
    if not ok and a_start < amps[0]:
        # a start below the first amplitude asked for can lie under the rounding of the preload
        # forces (a vanishing friction coefficient: slip from the first micrometre, "onset" at
        # 1e-13, where Newton stalls at 5e-8 of the scaled residual); start there instead
        a_start = amps[0]
        sol = _solve(problem, y_prev, a_start, *scales(a_start), tol=tol)
        y, ok, it = sol.x, sol.converged, sol.iterations
    if not ok:
        return _result(model, system, problem, [], [], [], False,
                       f"no EPMC solution at the start amplitude {a_start:.4g} from the stuck linear mode "
                       f"({omega_lin / (2 * np.pi):.6g} Hz)", omega_lin, zeta_lin, mode)
    y_prev, la_prev, it_prev = y, np.log10(a_start), it

    keep_a, keep_y, keep_it = [], [], []
    message = f"all {amps.size} amplitudes converged"
    success = True
    gaps = []
    step = max_log_step
    for target in amps:
        lt = np.log10(target)
        while True:
            if la_prev >= lt - 1e-14:
                if abs(la_prev - lt) <= 1e-14:
                    y_t, it_t = y_prev, it_prev
                    break
            s = min(step, lt - la_prev)
            la_new = la_prev + s
            if abs(la_new - lt) < 1e-12:
                la_new = lt
            if y_prev2 is not None and la_prev != la_prev2:
                guess = y_prev + (y_prev - y_prev2) * (la_new - la_prev) / (la_prev - la_prev2)
            else:
                guess = y_prev
            a_new = 10.0 ** la_new
            sol = _solve(problem, guess, a_new, *scales(a_new), tol=tol)
            y, ok, it = sol.x, sol.converged, sol.iterations
            if not ok and y_prev2 is not None:
                sol = _solve(problem, y_prev, a_new, *scales(a_new), tol=tol)
                y, ok, it = sol.x, sol.converged, sol.iterations
            if ok:
                y_prev2, la_prev2 = y_prev, la_prev
                y_prev, la_prev, it_prev = y, la_new, it
                step = min(max_log_step, 1.5 * step)
                if la_new == lt:
                    y_t, it_t = y, it
                    break
            else:
                step /= 2
                if step < 1e-3:
                    # a non-smooth point (a time sample switching stick / slip, the static damper
                    # position jumping): Newton 2-cycles at any step onto it; jump over it
                    jumped = False
                    for jump in (0.01, 0.03, 0.1, 0.3):
                        la_j = min(la_prev + jump, lt)
                        a_j = 10.0 ** la_j
                        for start in (guess, y_prev):
                            sol = _solve(problem, start, a_j, *scales(a_j), tol=tol)
                            y, ok, it = sol.x, sol.converged, sol.iterations
                            if ok:
                                break
                        if ok:
                            gaps.append((float(10.0 ** la_prev), float(a_j)))
                            y_prev2, la_prev2 = None, None
                            y_prev, la_prev, it_prev = y, la_j, it
                            step = min(max_log_step, 0.05)
                            jumped = True
                            break
                        if la_j == lt:
                            break
                    if jumped:
                        if la_prev == lt:
                            y_t, it_t = y_prev, it_prev
                            break
                        continue
                    success = False
                    names = tuple(getattr(model, "dof_names", ()))
                    worst = problem.describe(problem.last_worst, names) if problem.last_worst >= 0 else "?"
                    message = (f"Newton failed at modal amplitude {a_new:.6g} (step below 1e-3 decades, "
                               f"no jump of up to 0.3 decades converged; largest last update: {worst}"
                               + ("; the mean damper rotation is held only by the weak static retention "
                                  "spring of TunedDisk.hbm_system once the contacts slip, and does not settle"
                                  if "static" in worst and "phi" in worst else "")
                               + f"); {len(keep_a)} of {amps.size} amplitudes converged")
                    break
        if not success:
            break
        keep_a.append(target)
        keep_y.append(y_t)
        keep_it.append(it_t)
    if len(resolve_peaks) and keep_a:
        keep_a, keep_y, keep_it, unresolved = _resolve_peaks(problem, system, resolve_peaks, keep_a, keep_y, keep_it,
                                                             scales, tol)
        message += f"; {len(resolve_peaks) - unresolved} of {len(resolve_peaks)} forced peaks resolved"
    if gaps:
        message += ("; passed " + ", ".join(f"{lo:.5g}..{hi:.5g}" for lo, hi in gaps)
                    + " by a jump (non-smooth point: Newton 2-cycles onto it)")
    result = _result(model, system, problem, keep_a, keep_y, keep_it, success, message,
                     omega_lin, zeta_lin, mode)
    result.gaps = gaps
    return result


def _first_harmonic_force(problem: EPMCProblem, omega: float) -> np.ndarray:
    """(n,) complex first-harmonic excitation X = a_1 - i b_1 of the problem's system at
    ``omega`` [N] (the result's ``excitation``, the default force of the synthesis)."""
    f = np.asarray(problem.system.excitation(omega)[0], dtype=float).reshape(problem.C, problem.n)
    j1 = problem.basis.cos_index(1)
    return f[j1] - 1j * f[j1 + 1]


def _synthesis_h(problem: EPMCProblem, a: float, y: np.ndarray, force: np.ndarray) -> float:
    """h(a) of :func:`peak_function` at one EPMC solution y = (u, omega, zeta) at modal amplitude
    ``a`` for the first-harmonic force ``force`` (n,) [N]."""
    N = problem.N
    u = y[:N]
    return float(peak_function(a, y[N], y[N + 1], (u[problem.i_cos] - 1j * u[problem.i_sin])[None, :], force)[0])


def _synthesis_root(problem: EPMCProblem, force, solve, la_start: float, first_step: float, bracket=None,
                    maxiter: int = 8):
    """The EPMC solution at the resonance of the single-mode synthesis under ``force`` (n,) [N]:
    the root in log a of h(a) (:func:`peak_function`), each evaluation an EPMC Newton solve.

    ``solve(la, found)`` -> (a, y, iterations): the EPMC solution at a = exp(la), ``found`` the
    solutions so far ({la: (a, y, iterations)}, for its first guess); it raises _PeakNotResolved
    where Newton does not converge. A secant from ``la_start``, ``la_start + first_step`` to 1e-7
    in log a, and a last solve at its root (h there is zero to ~1e-12 of |phi^H F|); with
    ``bracket`` ((la0, h0), (la1, h1)), h0 < 0 < h1 at known solutions, Brent on it where the
    secant leaves it or stalls. Returns (a, y, iterations) at the root, None where the root is an
    end of the bracket (h there is zero to rounding); raises _PeakNotResolved where Newton fails or
    the secant does not converge without a bracket."""
    from scipy.optimize import brentq, root_scalar

    found = {}
    ends = dict(bracket) if bracket is not None else {}

    def fun(la):
        if la in ends:
            return ends[la]
        a, y, it = solve(la, found)
        found[la] = (a, y, it)
        return _synthesis_h(problem, a, y, force)

    sec = root_scalar(fun, method="secant", x0=la_start, x1=la_start + first_step, xtol=1e-7, maxiter=maxiter)
    inside = bracket is None or bracket[0][0] <= sec.root <= bracket[1][0]
    if sec.converged and inside and found:
        # the secant's root is closer to the true one than its last solve (up to xtol away, where
        # h is up to ~1e-7 of |phi^H F|: the spline of forced_peak through that point can then
        # cross zero up to a few 1e-6 away): one more solve there
        try:
            fun(sec.root)
            root = sec.root
        except _PeakNotResolved:
            root = min(found, key=lambda x: abs(x - sec.root))
    elif bracket is not None:
        root = brentq(fun, bracket[0][0], bracket[1][0], xtol=1e-7, rtol=1e-12)
    else:
        raise _PeakNotResolved
    return found.get(root)


def _resolve_peaks(problem, system, peak_scales, amps, ys, its, scales, tol):
    """The EPMC solution at the resonance of each excitation scale (see ``resolve_peaks`` of
    :func:`nonlinear_mode`), inserted into the points ``amps``, ``ys``, ``its`` (ascending a).
    Returns (amps, ys, its, number of scales left interpolated)."""
    from scipy.interpolate import CubicSpline
    from scipy.optimize import brentq

    N = problem.N
    amps, ys, its = list(amps), list(ys), list(its)
    force = _first_harmonic_force(problem, float(ys[0][N]))

    failed = 0
    for scale in peak_scales:
        h = np.array([_synthesis_h(problem, a, y, scale * force) for a, y in zip(amps, ys)])
        i = peak_bracket(h)
        if i < 0 or h[i] == 0:
            failed += i < 0
            continue
        la0, la1 = np.log(amps[i]), np.log(amps[i + 1])
        y0, y1 = ys[i], ys[i + 1]

        def solve(la, found):
            a = float(np.exp(la))
            guess = y0 + (y1 - y0) * (la - la0) / (la1 - la0)
            sol = _solve(problem, guess, a, *scales(a), tol=tol)
            y, ok, it = sol.x, sol.converged, sol.iterations
            if not ok:
                raise _PeakNotResolved
            return a, y, it

        # secant from the spline's root (within ~1e-3 of the true one: 2-3 solves), Brent on the
        # bracket if it leaves it or stalls
        spline = CubicSpline(np.log(np.asarray(amps)), h)
        start = brentq(lambda x: float(spline(x)), la0, la1, xtol=1e-12)
        try:
            sol = _synthesis_root(problem, scale * force, solve, start, 1e-3 * (la1 - la0),
                                  bracket=((la0, h[i]), (la1, h[i + 1])))
        except _PeakNotResolved:
            failed += 1
            continue
        if sol is None:
            continue
        a, y, it = sol
        k = int(np.searchsorted(amps, a))
        if (k > 0 and np.log(a / amps[k - 1]) < 1e-9) or (k < len(amps) and np.log(amps[k] / a) < 1e-9):
            continue
        amps.insert(k, a)
        ys.insert(k, y)
        its.insert(k, it)
    return amps, ys, its, failed


class _PeakNotResolved(Exception):
    """Newton did not converge inside a peak's bracket (the peak stays interpolated)."""


def tracked_forced_peaks(model, starts, scales, amplitudes=None, tol: float = 1e-10,
                         maxiter: int = TRACK_MAXITER) -> list:
    """The resonances of ``model`` under each of ``scales`` times its own excitation by
    single-nonlinear-mode synthesis, each solved from a neighbouring design's EPMC solution
    instead of a continuation from the stuck mode (a design parameter changed: the damper mass).

    ``starts``: per scale (or one for all), a nonlinear mode of a model with the same degrees of
    freedom and harmonics (e.g. the same disk with another damper mass): its point nearest the
    scale's entry of ``amplitudes`` (default: its own forced peak at that scale, or its only
    point) is the first guess of an EPMC Newton solve of ``model`` at that modal amplitude, with
    the start's mode number and phase DOF. From there the root of the synthesis condition h(a)
    (:func:`peak_function`) is found as ``nonlinear_mode(..., resolve_peaks=...)`` finds it (the
    same secant in log a, each step an EPMC Newton solve, here from the secant line through the
    two nearest solutions, and the last at its root), but without a bracket: a Newton solve that does not
    converge, or no convergence in ``maxiter`` secant steps, gives ``found`` False (compute the
    full :func:`nonlinear_mode` then). ``tol``: Newton tolerance. The secant finds the root
    nearest the start, the full mode's (its largest) where h has one root near the neighbour's
    peak, as it has along the damper-mass family of the reference cylinder (0.1-10 g, 0.05-0.2 N).
    The model's system and stuck mode are set up once for all scales.

    The peak is the EPMC solution at the root, as the resolved peak of the full mode is: the two
    agree to 7e-9 in the tip amplitude and 1.4e-11 in frequency (the reference cylinder, each
    grid mass of 0.1-5.6 g tracked from both neighbours 0.25 decades away at 0.05 / 0.1 / 0.2 N;
    2 of 42 did not converge), at a fraction of the cost: no amplitude range, no continuation,
    4-11 EPMC solves and ~10 ms per peak against 70-90 ms for a full mode with three resolved peaks.

    Returns per scale the record of :meth:`NonlinearModeResponse.forced_peak` ("modal_amplitude",
    "frequency_hz", "output_amplitude" (k,) [m], "damping_ratio", "found", "message") and "mode":
    the NonlinearModeResponse of the one solution at the root (a start for the next design; None
    if not found), "solves": the number of EPMC Newton solves."""
    scales = np.atleast_1d(np.asarray(scales, dtype=float))
    if scales.ndim != 1:
        raise ValueError(f"scales must be a 1-D sequence of excitation scales in (0, inf) (got shape {scales.shape})")
    validation.positive("scales", scales)
    starts = [starts] * scales.size if isinstance(starts, NonlinearModeResponse) else list(starts)
    amplitudes = [None] * scales.size if amplitudes is None else list(np.atleast_1d(amplitudes))
    if len(starts) != scales.size or len(amplitudes) != scales.size:
        raise ValueError(f"starts and amplitudes must have one entry per scale ({scales.size}; got "
                         f"{len(starts)} and {len(amplitudes)})")
    for start in starts:
        if not isinstance(start, NonlinearModeResponse):
            raise TypeError(f"starts must be NonlinearModeResponse objects (got {type(start).__qualname__})")
    maxiter = validation.integer("maxiter", maxiter, minimum=1)
    setups = {}
    out = []
    for start, scale, amplitude in zip(starts, scales, amplitudes):
        key = (start.mode, start.basis.harmonics, start.basis.n_samples, start.reference_dof)
        if key not in setups:
            setups[key] = _EPMCStart(model, *key)
            problem = setups[key].problem
            if np.shape(start.coefficients)[1:] != (problem.C, problem.n):
                raise ValueError(f"a start has harmonic coefficients of shape {np.shape(start.coefficients)[1:]}, "
                                 f"the model ({problem.C}, {problem.n}): not a mode of a neighbouring design")
        out.append(_tracked_peak(model, setups[key], start, float(scale), amplitude, tol, maxiter))
    return out


def _tracked_peak(model, setup: _EPMCStart, start: NonlinearModeResponse, scale: float, amplitude, tol: float,
                  maxiter: int) -> dict:
    """One peak of :func:`tracked_forced_peaks` on the model's ``setup``."""
    a_start = np.asarray(start.modal_amplitude, dtype=float)
    nan = {"modal_amplitude": np.nan, "frequency_hz": np.nan, "damping_ratio": np.nan,
           "output_amplitude": np.full(np.shape(start.output_amplitude)[1:], np.nan), "found": False,
           "mode": None, "solves": 0}
    if a_start.size == 0:
        return {**nan, "message": "the start mode has no points"}
    if amplitude is None:
        amplitude = a_start[0] if a_start.size == 1 else start.forced_peak(scale=scale)["modal_amplitude"]
        if not np.isfinite(amplitude):
            return {**nan, "message": "the start mode has no peak at this scale to start from"}
    validation.positive("amplitudes", amplitude)
    i0 = int(np.argmin(np.abs(np.log(a_start / amplitude))))
    problem = setup.problem
    N = problem.N
    y_start = np.concatenate([np.ravel(start.coefficients[i0]), [start.omega[i0], start.damping_ratio[i0]]])
    calls = []

    def solve(la, found):
        calls.append(la)
        a = float(np.exp(la))
        near = sorted(found, key=lambda x: abs(x - la))[:2]          # the secant line's solutions
        if len(near) == 2:
            l0, l1 = near
            guess = found[l0][1] + (found[l1][1] - found[l0][1]) * (la - l0) / (l1 - l0)
        else:
            guess = found[near[0]][1] if near else y_start
        sol = _solve(problem, guess, a, *setup.scales(a), tol=tol)
        y, ok, it = sol.x, sol.converged, sol.iterations
        if not ok:
            raise _PeakNotResolved
        return a, y, it

    force = scale * _first_harmonic_force(problem, setup.omega_lin)
    try:
        a, y, it = _synthesis_root(problem, force, solve, float(np.log(amplitude)), TRACK_FIRST_STEP, maxiter=maxiter)
    except _PeakNotResolved:
        return {**nan, "solves": len(calls),
                "message": f"no EPMC root of the synthesis condition from modal amplitude {amplitude:.6g} "
                           f"({len(calls)} Newton solves; Newton failed or the secant did not converge)"}
    mode = _result(model, setup.system, problem, [a], [y], [it], True,
                   f"forced peak at scale {scale:g} tracked from modal amplitude {amplitude:.6g} of a neighbouring "
                   f"design ({len(calls)} EPMC solves)", setup.omega_lin, setup.zeta_lin, start.mode)
    return {**_peak_record(a, y[N], y[N + 1], mode.output_amplitude[0]), "mode": mode, "solves": len(calls)}


def _result(model, system, problem, amps, ys, its, success, message, omega_lin, zeta_lin, mode):
    basis = system.basis
    C, n, N = basis.n_coeffs, system.n_dof, problem.N
    amps = np.asarray(amps, dtype=float)
    ys = np.asarray(ys, dtype=float).reshape(len(amps), N + 2)
    coeffs = ys[:, :N].reshape(-1, C, n)
    omega = ys[:, N]
    zeta = ys[:, N + 1]
    energy = np.zeros(len(amps))
    outputs = []
    for i, (a, y) in enumerate(zip(amps, ys)):
        x = problem.state(y[:N], a)
        energy[i] = system.viscous_dissipation(x, omega[i]) + sum(system.element_dissipation(x, omega[i]))
        if hasattr(model, "output_amplitudes"):
            outputs.append(np.asarray(model.output_amplitudes(x.reshape(1, C, n), basis))[0])
    outputs = np.array(outputs) if outputs else np.zeros((len(amps), 0))
    excitation = _first_harmonic_force(problem, omega[0] if len(omega) else omega_lin)
    names = tuple(getattr(model, "dof_names", ())) or tuple(f"x{d}" for d in range(n))
    if len(names) != n:
        names = tuple(f"x{d}" for d in range(n))
    return NonlinearModeResponse(amps, omega / (2 * np.pi), zeta, coeffs, basis, names, bool(success), message,
                                 np.asarray(its, dtype=int), energy, outputs, excitation,
                                 omega_lin / (2 * np.pi), zeta_lin, int(problem.reference_dof), int(mode))
