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
  exponents of Hill's method for a smooth system (tests/test_stability.py checks both on the
  Duffing oscillator).

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
:meth:`FrictionOscillator.time_response`'s).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import validation
from ..contact.point import SEPARATED
from ..timedomain import oscillator_step

STEPS_PER_PERIOD = 2048       # central-difference steps per period of the period map
FD_STEP = 1e-6                # finite-difference step of the monodromy matrix, relative to the state's scale


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
    from ..contact.point import PointContactElement

    c = np.asarray(coefficients, dtype=float).ravel()
    dt = 2 * np.pi / omega / steps

    def x_at(t):
        tau = omega * t
        value = 0.0
        for h in basis.harmonics:
            j = basis.cos_index(h)
            value += c[j] if h == 0 else c[j] * np.cos(h * tau) + c[j + 1] * np.sin(h * tau)
        return value

    system = osc.hbm_system(basis.harmonics, basis.n_samples)
    contact = next(cp for cp in system.couplings if isinstance(cp.element, PointContactElement))
    pts = contact.element.samples(contact.matrix @ c, basis)
    u, f = pts.displacement[0, 0, 0], pts.force[0, 0, 0]
    s = u if pts.state[0, 0] == SEPARATED else u - f / osc.contact_stiffness
    scale = max(float(np.abs(basis.synthesis @ c).max()), 1e-300)
    return np.array([x_at(0.0), x_at(-dt), s]), scale


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


def supports(model) -> bool:
    """Whether the monodromy method has a period map for ``model``."""
    from ..oscillator import FrictionOscillator

    return isinstance(model, FrictionOscillator)


def monodromy_multipliers(model, coefficients, basis, omega: float, steps: int = STEPS_PER_PERIOD):
    """(multipliers (3,) complex, largest modulus first; periodicity error) of ``model``'s HBM
    solution ``coefficients`` at ``omega`` [rad/s] (see :func:`oscillator_monodromy`)."""
    if not supports(model):
        raise ValueError(f"method 'monodromy' has a period map for the FrictionOscillator only (got "
                         f"{type(model).__qualname__}); use method 'auto' (Hill or determinant sign)")
    mono, _, error = oscillator_monodromy(model, coefficients, basis, omega, steps)
    mu = np.linalg.eigvals(mono).astype(complex)
    return mu[np.argsort(-np.abs(mu))], error
