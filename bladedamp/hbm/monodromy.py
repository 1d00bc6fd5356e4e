"""Stability of harmonic balance solutions by the monodromy matrix of a time integration.

Hill's method needs a linearisation that is a linear time-periodic operator of the
perturbation; a friction contact's is not (the stick force remembers the last reversal, see
:mod:`bladedamp.hbm.stability`), which is why friction systems there are decided by the sign of
det J alone: it finds folds and branch points (a real multiplier through +1) but not a period
doubling (-1) or a Neimark-Sacker bifurcation (a complex pair through the unit circle). The
monodromy matrix sees all three, because it is the linearisation of the *exact* nonlinear map
over one period, hysteresis included:

* the periodic orbit: the HBM solution's state at t = 0 (displacement, and the previous time
  step of the central-difference scheme, from the Fourier series of x), and every friction
  slider's position at t = 0 from the AFT's periodic return map
  (``PointContactElement.samples``: s = u - f / k_T at the first time sample; s = u when the
  point is separated);
* the period map P: one period of the central-difference integration of the model with the
  contact force advanced by the same return-map step the AFT and
  :mod:`bladedamp.timedomain` use (:func:`bladedamp.contact.point.slider_step`), of the state
  z = (x_0, x_-1, s) (the slider positions are part of the state: they are the memory);
* the monodromy matrix: central finite differences of P at the orbit's state, step
  ``FD_STEP`` times the state's scale (P is continuous and piecewise smooth: the slider's
  stick-slip switches are continuous in the state, so the difference is the derivative except
  when a switch falls within the step, which is of probability FD_STEP);
* the Floquet multipliers mu: its eigenvalues; mu = exp(lambda T) with lambda the Floquet
  exponents of Hill's method for a smooth system.

Stable when every multiplier satisfies log|mu| / (2 pi) < ``tolerance`` (the same threshold as
Hill's Re lambda / Omega < tolerance, since |mu| = exp(2 pi Re lambda / Omega)). A slider that
sticks for the whole period has the multiplier 1 exactly (a stuck contact holds any offset: a
neutral family of orbits), which counts as not growing; one that slips forgets its start
(multiplier 0). A loss of stability is a fold or branch point when the multiplier leaving the
circle is real and positive, a period doubling when real and negative, a Neimark-Sacker
bifurcation when it is a complex pair.

The discrete map's multipliers converge to the continuous ones at second order in the step
(``steps`` per period; ``STEPS_PER_PERIOD`` = 2048 by default: a relative error of order
(2 pi / 2048)^2 = 1e-5 in the exponents). Models: :class:`~bladedamp.oscillator.FrictionOscillator`
(the period map below is its equation of motion, the same as
:meth:`FrictionOscillator.time_response`'s), and the bladed disk (:func:`disk_monodromy`).

The bladed disk. :class:`~bladedamp.mistuned.MistunedDisk` (a full assembly, every blade in
the model) and :class:`~bladedamp.disk.TunedDisk` (a cyclic sector: its solution is written
out on the full assembly, blade k's and damper k's harmonic h turned by e^{i h k dphi}, dphi =
2 pi EO / n, Eq. 24-25, so the perturbations are those of every nodal diameter, not only of
the engine order's travelling wave). The period map is one period of the time integration of
the whole assembly, :func:`bladedamp.timedomain.disk_period` (central differences, the AFT's
return-map step at every contact point, the HBM model's own M, D, K, contact maps, patches
and loads: :func:`bladedamp.timedomain.assembly_arrays`), of the state z = (x_0 (N,), x_-1
(N,), s (P, 2)): N unknowns (modal coordinates of the blades, 6 per damper), P contact points
of all dampers, state dimension m = 2 N + 2 P. The orbit's state: x(0), x(-dt) from the
Fourier series, every slider at t = 0 from the AFT's return map of its patch
(``PointContactElement.samples``, as the oscillator's). The solution must carry the static
harmonic (the time integration seats the dampers under F_CG; without h = 0 the HBM uses a
pre-computed rigid seating the time domain does not have). The finite-difference step of each
state component is ``FD_STEP`` x the vibration amplitude of its kind on the orbit (blade modal
coordinates, damper translations, damper rotations, slider positions: the pooled largest
|x_i(t) - mean x_i|), and the 2 m + 1 states are integrated as one batch
(:func:`disk_period_map`). Steps per period: the more of
:data:`bladedamp.timedomain.MIN_STEPS_PER_PERIOD` = 512 and 1 / 0.8 of the explicit scheme's
stability limit 2 / omega_max of the stuck linearised assembly (as
:func:`~bladedamp.timedomain.disk_time_response`); the exponents of a mode of frequency omega
are then off by (omega dt)^2 / 24 relative: ~6e-6 for 1F, but of order 1 for the stiff contact
modes near the stability limit (their multipliers are the discrete scheme's, with its own
frequency; their moduli stay those of a lightly damped mode).

Cost: 2 m + 1 trajectories of one period per point, m the state's size; about 120 x the HBM
solve per point for 4 blades and 1600 x for 16 (benchmarks/README.md, 'Moved from the package's
docstrings', hbm/monodromy.py). The cost grows as m^2 ~ n_blades^2 (m trajectories of a period
costing ~ m each), so on a real disk the
monodromy is for chosen points (near a suspected bifurcation), not for every point of an FRF;
a tuned disk does not get cheaper (the cyclic sector's solution is written out on the full
assembly to see every nodal diameter).

Where the HBM solution is not a periodic orbit of the time integration the multipliers mean
nothing: the 16-blade reference cylinder in slip (95.1-96.1 Hz) keeps rolling in the time
integration (:func:`~bladedamp.timedomain.disk_time_response` reports it drifting), its mean
roll angle held in the HBM only by the static retention spring of
:meth:`~bladedamp.disk.TunedDisk.hbm_system`; one period from the HBM state moves phi_y by
~0.01 rad (periodicity error 0.67 at 95.3 Hz, largest |mu| 8-28). Such points get an
AccuracyWarning (periodicity error above ``PERIODICITY_LIMIT``).
"""
from __future__ import annotations

from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np
from numba import njit

from .. import validation
from ..contact.point import SEPARATED, PointContactElement
from ..timedomain import (MIN_STEPS_PER_PERIOD, assembly_arrays, disk_period, highest_frequency, orbit_state,
                          oscillator_step, series_value)

STEPS_PER_PERIOD = 2048       # central-difference steps per period of the period map
FD_STEP = 1e-6                # finite-difference step of the monodromy matrix, relative to the state's scale
# A disk's periodicity error above this: the HBM solution is not a periodic orbit of the time
# integration (AccuracyWarning naming the coordinate). It lies between the errors of HBM orbits
# that are periodic orbits (a few 1e-3, most of it the HBM's static retention spring, absent in
# the time domain) and those of one that is not (order 1): benchmarks/README.md, 'Moved from
# the package's docstrings', hbm/monodromy.py.
PERIODICITY_LIMIT = 1e-2


@runtime_checkable
class PeriodMapModel(Protocol):
    """What the monodromy method asks of a model (this module imports no model; the models
    implement it: :class:`~bladedamp.oscillator.FrictionOscillator`,
    :class:`~bladedamp.disk.TunedDisk`, :class:`~bladedamp.mistuned.MistunedDisk`).

    ``has_period_map``: whether the model has a period map (a MistunedDisk only when every blade
    is in the model). ``monodromy_matrix(coefficients, basis, omega, steps)``: (the monodromy
    matrix (m, m), the periodicity error) of the HBM solution ``coefficients`` in ``basis`` at
    ``omega`` [rad/s], ``steps`` per period (None: the model's default), by
    :func:`oscillator_monodromy` or :func:`disk_monodromy`."""

    has_period_map: bool

    def monodromy_matrix(self, coefficients, basis, omega: float, steps: int | None = None): ...


@runtime_checkable
class AssemblyModel(Protocol):
    """What :func:`disk_monodromy` asks of a bladed disk: ``full_assembly()``, the model with
    every blade and damper written out (a full-assembly MistunedDisk: itself; a TunedDisk:
    ``MistunedDisk.from_tuned(self)``), and ``assembly_coefficients(full, coefficients, basis)``,
    the harmonic coefficients (C, N) on that assembly of the model's solution ``coefficients``
    (C * n,) or (C, n) (a TunedDisk's sector turned blade by blade, Eq. 24-25)."""

    def full_assembly(self): ...

    def assembly_coefficients(self, full, coefficients, basis) -> np.ndarray: ...


@njit(cache=True)
def oscillator_period_map(states, omega, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a, force, steps):
    """One period of the friction oscillator m x'' + c x' + k x + k3 x^3 + f_C = F cos(omega t)
    from t = 0 for each of B states (B, 3) = (x_0 [m], x_-1 [m] (one step dt = 2 pi / omega /
    steps before), s [m] (the slider position before the step at t = 0)); returns the states
    (B, 3) after ``steps`` steps (the same triple at t = T), by :func:`oscillator_step`."""
    dt = 2 * np.pi / omega / steps
    out = np.empty_like(states)
    for b in range(states.shape[0]):
        x, x_prev, s0 = states[b, 0], states[b, 1], states[b, 2]
        for n in range(steps):
            x_next, s0 = oscillator_step(x, x_prev, s0, dt, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a,
                                         force * np.cos(omega * n * dt))
            x_prev, x = x, x_next
        out[b, 0], out[b, 1], out[b, 2] = x, x_prev, s0
    return out


def _oscillator_orbit_state(osc, coefficients, basis, omega, steps):
    """(z (3,), scale) of the HBM solution ``coefficients`` (C*1,) of ``osc`` at ``omega``:
    x(0), x(-dt) from the Fourier series and the slider from the AFT's periodic return map at
    its first time sample, t = 0 (s = u - f_t / k_T; u when separated). That is the slider after
    the step at t = 0; as the input of the period map (the slider before that step) it gives the
    same trajectory: a stuck slider does not move in the step, a slipping or separated one
    forgets its previous position."""
    c = np.asarray(coefficients, dtype=float).ravel()
    dt = 2 * np.pi / omega / steps

    system = osc.hbm_system(basis.harmonics, basis.n_samples)
    contact = next(cp for cp in system.couplings if isinstance(cp.element, PointContactElement))
    pts = contact.element.samples(contact.matrix @ c, basis)
    u, f = pts.displacement[0, 0, 0], pts.force[0, 0, 0]
    s = u if pts.state[0, 0] == SEPARATED else u - f / osc.contact_stiffness
    scale = max(float(np.abs(basis.synthesis @ c).max()), 1e-300)
    X = c.reshape(-1, 1)
    return np.array([series_value(X, basis, 0.0)[0], series_value(X, basis, -omega * dt)[0], s]), scale


def oscillator_monodromy(osc, coefficients, basis, omega: float, steps: int = STEPS_PER_PERIOD):
    """Monodromy matrix (3, 3) of the friction oscillator ``osc`` about its HBM solution
    ``coefficients`` (C,) or (C, 1) in ``basis`` at ``omega`` [rad/s], in the state
    (x_0, x_-1, s) (see the module docstring); returns (monodromy, z (3,), periodicity error:
    |P(z) - z| over the displacements (x_0, x_-1) / the orbit's largest |x|, the HBM solution's
    distance from a periodic orbit of the discrete map)."""
    steps = validation.integer("steps (per period)", steps, minimum=16)
    dt_max = 2.0 / np.sqrt((osc.stiffness + osc.contact_stiffness + osc.normal_stiffness) / osc.mass)
    if 2 * np.pi / omega / steps > 0.5 * dt_max:
        need = int(np.ceil(2 * np.pi / omega / (0.5 * dt_max)))
        raise ValueError(f"steps (per period) must be >= {need} for the explicit scheme at "
                         f"{omega / (2 * np.pi):.6g} Hz (got {steps})")
    z, scale = _oscillator_orbit_state(osc, coefficients, basis, omega, steps)
    h = FD_STEP * scale
    batch = np.tile(z, (7, 1))
    for j in range(3):
        batch[1 + 2 * j, j] += h
        batch[2 + 2 * j, j] -= h
    a = np.sin(osc.contact_angle), np.cos(osc.contact_angle)
    out = oscillator_period_map(batch, float(omega), osc.mass, osc.damping, osc.stiffness, osc.cubic_stiffness,
                                osc.contact_stiffness, osc.friction_coefficient, osc.normal_load,
                                osc.normal_stiffness, a[0], a[1], osc.forcing, steps)
    mono = np.column_stack([(out[1 + 2 * j] - out[2 + 2 * j]) / (2 * h) for j in range(3)])
    return mono, z, float(np.linalg.norm(out[0, :2] - z[:2]) / scale)


# ----- the bladed disk ------------------------------------------------------------------

@njit(cache=True)
def disk_period_map(states, steps, dt, n_q, m_q, c_q, k_q, minv, f_static, f_cos, f_sin, Tb, idx, pt_local, B,
                    k_t, mu, weight, offset, law_kind, law_par, t_nnz, t_col, b_nnz, b_col, tip):
    """One period of the full assembly's central-difference integration
    (:func:`bladedamp.timedomain.disk_period`, its arguments those of
    :class:`~bladedamp.timedomain.AssemblyArrays`, ``steps`` steps of ``dt`` [s] from t = 0)
    for each of the B states ``states`` (B, 2 N + 2 P) = (x_0 (N,), x_-1 (N,), slider positions
    (P, 2) row-major) [modal coordinates, m, rad; sliders m]; returns the states (B, 2 N + 2 P)
    at t = T, the same triple."""
    n_b = states.shape[0]
    N = f_static.shape[0]
    P = B.shape[0]
    nd = Tb.shape[0]
    s_bl = tip.shape[0]
    out = np.empty_like(states)
    tip_samples = np.empty((s_bl, 3, steps))
    tip_dft = np.empty((s_bl, 3, 2))
    damper_mean = np.empty((nd, 6))
    damper_dft = np.empty((nd, 6, 2))
    damper_work = np.empty(nd)
    point_states = np.empty((P, 3), dtype=np.int64)
    energies = np.empty(2)
    for b in range(n_b):
        x = states[b, :N].copy()
        x_prev = states[b, N:2 * N].copy()
        slider = states[b, 2 * N:].copy().reshape(P, 2)
        disk_period(steps, dt, n_q, m_q, c_q, k_q, minv, f_static, f_cos, f_sin, Tb, idx, pt_local, B, k_t, mu,
                    weight, offset, law_kind, law_par, t_nnz, t_col, b_nnz, b_col, tip, x, x_prev, slider,
                    tip_samples, tip_dft, damper_mean, damper_dft, damper_work, point_states, energies)
        # element by element: an array assignment compiles numba's shape check and its error
        # message (about 4 s of a cold cache's CPU time; benchmarks/README.md, 'Start-up and the
        # numba compile cost')
        for i in range(N):
            out[b, i] = x[i]
            out[b, N + i] = x_prev[i]
        for p in range(P):
            out[b, 2 * N + 2 * p] = slider[p, 0]
            out[b, 2 * N + 2 * p + 1] = slider[p, 1]
    return out


_ASSEMBLY_CACHE = {}      # id(model) -> (weak reference to the model, full assembly, its arrays): the last model


def _disk_assembly(model):
    """(``model.full_assembly()``, its :class:`~bladedamp.timedomain.AssemblyArrays`), built once
    per model (a branch calls this at every point)."""
    import weakref

    hit = _ASSEMBLY_CACHE.get(id(model))
    if hit is not None and hit[0]() is model:
        return hit[1], hit[2]
    full = model.full_assembly()
    arrays = assembly_arrays(full)
    _ASSEMBLY_CACHE.clear()
    _ASSEMBLY_CACHE[id(model)] = (weakref.ref(model), full, arrays)
    return full, arrays


def assembly_coefficients(model, full, coefficients, basis) -> np.ndarray:
    """The harmonic coefficients (C, N) of the full assembly ``full`` of ``model``'s solution
    ``coefficients`` (C * n,) or (C, n): ``model.assembly_coefficients`` (:class:`AssemblyModel`;
    unchanged for a MistunedDisk, a TunedDisk's sector turned blade by blade, Eq. 24-25)."""
    return model.assembly_coefficients(full, coefficients, basis)


def full_assembly_coefficients(model, coefficients, basis) -> np.ndarray:
    """:func:`assembly_coefficients` of ``model`` (an :class:`AssemblyModel`: a TunedDisk or a
    full-assembly MistunedDisk) on its full assembly (``model.full_assembly()``): (C, N)."""
    full, _ = _disk_assembly(model)
    return assembly_coefficients(model, full, coefficients, basis)


class DiskMonodromy(NamedTuple):
    """The monodromy of a bladed disk's HBM orbit (:func:`disk_monodromy`); m = 2 N + 2 P."""
    matrix: np.ndarray               # (m, m) d P(z) / d z by central differences, state (x_0, x_-1, s)
    state: np.ndarray                # (m,) the orbit's state z at t = 0
    periodicity_error: float         # max |P(z) - z| over x_0 and x_-1, relative to each kind's amplitude
    steps: int                       # central-difference steps per period
    fd_step: np.ndarray              # (m,) the finite-difference step h of each state component


def disk_monodromy(model, coefficients, basis, omega: float, steps: int | None = None) -> DiskMonodromy:
    """Monodromy matrix (m, m), m = 2 N + 2 P, of a bladed disk's HBM solution (see the module
    docstring): ``model`` a TunedDisk (its sector solution written out on the full assembly) or
    a full-assembly MistunedDisk, ``coefficients`` (C * n,) or (C, n) in ``basis`` (with the
    static harmonic) at ``omega`` [rad/s]; ``steps`` per period (default: the more of
    MIN_STEPS_PER_PERIOD and 1 / 0.8 of the stability limit; fewer than the limit is a
    ValueError). Returns a :class:`DiskMonodromy`: the monodromy (m, m) in the state (x_0, x_-1,
    s) of the full assembly, z (m,), the periodicity error (max |P(z) - z| over x_0 and x_-1,
    each component relative to the orbit's vibration amplitude of its kind: blade modal
    coordinates, damper translations, damper rotations), the steps per period and the
    finite-difference steps h (m,) (a column's rounding error is about eps |P(z)| / h). An
    AccuracyWarning when the periodicity error exceeds ``PERIODICITY_LIMIT``."""
    if not basis.has_static:
        raise ValueError("method 'monodromy' of a bladed disk needs a solution with the static harmonic 0 "
                         f"(harmonics {tuple(basis.harmonics)}): the time integration seats the dampers under "
                         "F_CG, the HBM without h = 0 on a pre-computed rigid seating")
    full, arrays = _disk_assembly(model)
    t_nnz, t_col, b_nnz, b_col = arrays.sparsity
    X = assembly_coefficients(model, full, coefficients, basis)
    N, P, n_q = X.shape[1], arrays.B.shape[0], arrays.n_q
    T = 2 * np.pi / omega
    w_max = highest_frequency(arrays, X[basis.cos_index(0)])
    limit = int(np.ceil(T / (2.0 / w_max)))
    if steps is None:
        steps = max(MIN_STEPS_PER_PERIOD, int(np.ceil(T / (0.8 * 2.0 / w_max))))
    steps = validation.integer("steps (per period)", steps, minimum=16)
    if steps < limit:
        raise ValueError(f"steps (per period) must be >= {limit} for the explicit scheme at {omega / (2 * np.pi):.6g} Hz "
                         f"(omega_max = {w_max:.4g} rad/s; got {steps})")
    dt = T / steps
    z, slider_amp = orbit_state(arrays, X, basis, omega, dt)
    # the FD step of each component: FD_STEP x its kind's vibration amplitude on the orbit
    samples = basis.synthesis @ X                                   # (T, N)
    amp = np.abs(samples - samples.mean(axis=0)).max(axis=0)
    kinds = np.zeros(N, dtype=int)
    kinds[n_q:] = 1 + (np.arange(N - n_q) % 6 >= 3)                 # damper translations 1, rotations 2
    kind_amp = np.array([amp[kinds == k].max(initial=0.0) for k in range(3)])
    floor = 1e-6 * max(kind_amp.max(), slider_amp, 1e-300)
    kind_amp = np.maximum(kind_amp, floor)
    x_scale = kind_amp[kinds]
    scale = np.concatenate([x_scale, x_scale, np.full(2 * P, max(slider_amp, floor))])
    m = z.size
    h = FD_STEP * scale
    batch = np.tile(z, (2 * m + 1, 1))
    j = np.arange(m)
    batch[1 + 2 * j, j] += h
    batch[2 + 2 * j, j] -= h
    f = arrays.system.excitation(omega)[0].reshape(arrays.system.basis.n_coeffs, N)   # static, cos, sin
    out = disk_period_map(batch, steps, dt, arrays.n_q, arrays.m_q, arrays.c_q, arrays.k_q, arrays.minv,
                          np.ascontiguousarray(f[0]), np.ascontiguousarray(f[1]), np.ascontiguousarray(f[2]),
                          arrays.Tb, arrays.idx, arrays.pt_local, arrays.B, arrays.k_t, arrays.mu, arrays.weight,
                          arrays.offset, arrays.law_kind, arrays.law_par, t_nnz, t_col, b_nnz, b_col, arrays.tip)
    mono = ((out[1::2] - out[2::2]) / (2 * h[:, None])).T
    deviation = np.abs(out[0, :2 * N] - z[:2 * N]) / scale[:2 * N]
    error = float(deviation.max())
    if error > PERIODICITY_LIMIT:
        import warnings

        from .accuracy import AccuracyWarning

        worst = full.dof_names[int(np.argmax(deviation)) % N]
        warnings.warn(AccuracyWarning(
            f"monodromy at {omega / (2 * np.pi):.6g} Hz: the HBM solution is not a periodic orbit of the time "
            f"integration (periodicity error {error:.3g}, largest in {worst}; a rolling cylinder drifts in "
            f"phi_y, which only the HBM's static retention spring holds): the multipliers linearise a transient, "
            f"their stability verdict does not apply"), stacklevel=2)
    return DiskMonodromy(mono, z, error, steps, h)


def supports(model) -> bool:
    """Whether the monodromy method has a period map for ``model``: a :class:`PeriodMapModel`
    whose ``has_period_map`` is true (a FrictionOscillator, a TunedDisk or a full-assembly
    MistunedDisk, every blade in the model)."""
    return isinstance(model, PeriodMapModel) and bool(model.has_period_map)


def monodromy_multipliers(model, coefficients, basis, omega: float, steps: int | None = None):
    """(multipliers (m,) complex, largest modulus first; periodicity error) of ``model``'s HBM
    solution ``coefficients`` at ``omega`` [rad/s] (``model.monodromy_matrix``, a
    :class:`PeriodMapModel`: :func:`oscillator_monodromy`, m = 3, and :func:`disk_monodromy`,
    m = 2 N + 2 P); ``steps`` per period (default STEPS_PER_PERIOD for the oscillator, the
    disk's own rule for a disk)."""
    if not supports(model):
        raise ValueError("method 'monodromy' has a period map for the FrictionOscillator, the TunedDisk and the "
                         f"full-assembly MistunedDisk only (got {type(model).__qualname__}); use method 'auto' "
                         "(Hill or determinant sign)")
    mono, error = model.monodromy_matrix(coefficients, basis, omega, steps)
    mu = np.linalg.eigvals(mono).astype(complex)
    return mu[np.argsort(-np.abs(mu))], error
