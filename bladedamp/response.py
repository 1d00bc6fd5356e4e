"""Result objects of frequency responses: named arrays and ``.plot()``."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from .hbm.fourier import HarmonicBasis


@dataclass
class FrequencyResponse:
    """Harmonic balance frequency response of a system with named degrees of freedom.

    Attributes
    ----------
    omega : (n,) excitation angular frequency of each point [rad/s]
    coefficients : (n, C, n_dof) harmonic coefficients (see :class:`HarmonicBasis`) [SI]
    basis : HarmonicBasis used
    dof_names : names of the degrees of freedom
    success : whether the continuation reached the end of the range
    message : why it stopped
    iterations : (n,) Newton iterations per point
    turning_points : indices of the points where d omega / ds changed sign (folds)
    """

    omega: np.ndarray
    coefficients: np.ndarray
    basis: HarmonicBasis
    dof_names: tuple[str, ...]
    success: bool
    message: str
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    turning_points: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def reversed(self):
        """The same branch in the opposite order (a downward sweep as rising frequency): every
        per-point array is flipped, turning points renumbered."""
        n = len(self.omega)
        changes = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "turning_points":
                changes[f.name] = np.sort(n - 1 - np.asarray(value, dtype=int))
            elif isinstance(value, np.ndarray) and value.ndim and value.shape[0] == n:
                changes[f.name] = value[::-1].copy()
        return dataclasses.replace(self, **changes)

    @property
    def frequency_hz(self) -> np.ndarray:
        """Excitation frequency [Hz]."""
        return self.omega / (2 * np.pi)

    def _dof(self, dof) -> int:
        return self.dof_names.index(dof) if isinstance(dof, str) else int(dof)

    def harmonic_amplitude(self, dof=0, harmonic: int = 1) -> np.ndarray:
        """|X_h| of one DOF at every point (for h = 0 the signed static value)."""
        j = self.basis.cos_index(harmonic)
        c = self.coefficients[:, :, self._dof(dof)]
        return c[:, j] if harmonic == 0 else np.hypot(c[:, j], c[:, j + 1])

    def time_samples(self, dof=0) -> np.ndarray:
        """(n, T) samples of one DOF over a period at every point."""
        return self.coefficients[:, :, self._dof(dof)] @ self.basis.synthesis.T

    def max_amplitude(self, dof=0) -> np.ndarray:
        """max_t |x(t)| over a period at every point (all harmonics)."""
        return np.abs(self.time_samples(dof)).max(axis=1)

    def peak(self, dof=0, harmonic: int = 1):
        """(omega [rad/s], amplitude) of the largest |X_h| on the branch."""
        a = self.harmonic_amplitude(dof, harmonic)
        i = int(np.argmax(a))
        return float(self.omega[i]), float(a[i])

    def plot(self, dof=0, ax=None, harmonic: int = 1, scale: float = 1.0, unit: str = "", **kwargs):
        """Plot |X_h| of ``dof`` over frequency [Hz]; returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        label = kwargs.pop("label", f"{self.dof_names[self._dof(dof)]}, H={self.basis.harmonics}")
        ax.plot(self.frequency_hz, scale * self.harmonic_amplitude(dof, harmonic), label=label, **kwargs)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel(f"|{self.dof_names[self._dof(dof)]}| harmonic {harmonic} {unit}".strip())
        ax.grid(True, alpha=0.3)
        if not self.success:
            ax.set_title(f"incomplete: {self.message}", fontsize=8)
        ax.legend()
        return ax
