"""Direct time integration: the independent check of the harmonic balance.

The friction oscillator is integrated with the explicit central-difference scheme (second
order), the contact force advanced by the same return-map step the AFT uses
(:func:`bladedamp.contact.point.slider_step`), from rest until the response is periodic.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .contact.point import slider_step


@njit(cache=True)
def _oscillator_steady_state(omega, m, c, k, k3, k_t, mu, n0, k_n, sin_a, cos_a, force,
                             steps, max_periods, min_periods, tol, last_period):
    """Integrate one frequency from rest; returns (periods used, converged) and fills last_period."""
    dt = 2 * np.pi / omega / steps
    a_lhs = m / dt ** 2 + c / (2 * dt)
    x_prev = 0.0
    x = 0.0
    s0 = 0.0
    s1 = 0.0
    amp_old = -1.0
    stable = 0
    step = 0
    for period in range(max_periods):
        cs = 0.0
        sn = 0.0
        for j in range(steps):
            normal = n0 + k_n * sin_a * x
            if normal < 0.0:
                normal = 0.0
            f0, f1, s0, s1, st = slider_step(cos_a * x, 0.0, s0, s1, k_t, mu * normal, normal > 0.0)
            contact = cos_a * f0 + sin_a * normal
            rhs = force * np.cos(omega * step * dt) - k * x - k3 * x ** 3 - contact \
                + m * (2 * x - x_prev) / dt ** 2 + c * x_prev / (2 * dt)
            last_period[j] = x
            cs += x * np.cos(2 * np.pi * j / steps)
            sn += x * np.sin(2 * np.pi * j / steps)
            x_prev = x
            x = rhs / a_lhs
            step += 1
        amp = 2.0 / steps * np.sqrt(cs * cs + sn * sn)
        if amp_old >= 0 and abs(amp - amp_old) <= tol * amp:
            stable += 1
        else:
            stable = 0
        amp_old = amp
        if period + 1 >= min_periods and stable >= 3:
            return period + 1, True
    return max_periods, False


@dataclass
class TimeResponse:
    """Steady-state response by time integration, one run per frequency.

    Attributes
    ----------
    omega : (n,) [rad/s]
    amplitude : (n,) first-harmonic amplitude of the last period [m]
    max_displacement : (n,) max |x(t)| over the last period [m]
    samples : (n, steps) displacement over the last period [m]
    periods : (n,) periods integrated
    converged : (n,) whether the amplitude settled to ``tol`` per period
    """

    omega: np.ndarray
    amplitude: np.ndarray
    max_displacement: np.ndarray
    samples: np.ndarray
    periods: np.ndarray
    converged: np.ndarray

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.omega / (2 * np.pi)

    def harmonic_amplitude(self, harmonic: int = 1) -> np.ndarray:
        """|X_h| of the last period (DFT of the samples)."""
        spec = np.fft.rfft(self.samples, axis=1) / self.samples.shape[1]
        return (1 if harmonic == 0 else 2) * np.abs(spec[:, harmonic])

    def plot(self, ax=None, scale: float = 1.0, **kwargs):
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        kwargs.setdefault("label", "time integration")
        kwargs.setdefault("marker", "o")
        kwargs.setdefault("linestyle", "none")
        ax.plot(self.frequency_hz, scale * self.amplitude, **kwargs)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel("first-harmonic amplitude")
        ax.grid(True, alpha=0.3)
        ax.legend()
        return ax
