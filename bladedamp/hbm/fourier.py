"""Harmonic <-> time-sample matrices for the alternating frequency/time (AFT) scheme.

A periodic signal is written with real coefficients in the order of ``harmonics``::

    x(tau) = c_0 + sum_h [a_h cos(h tau) + b_h sin(h tau)],   tau = Omega t

(``c_0`` only if 0 is among the harmonics). The paper's complex amplitudes
(Eq. 4: x = Re(X e^{i h tau})) are ``X_h = a_h - i b_h``. Vectors of several
degrees of freedom are stored *harmonic-major*: coefficient ``j`` of DOF ``d``
sits at ``j * n_dof + d``, so the linear dynamic stiffness is block diagonal.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import validation


@dataclass(frozen=True)
class HarmonicBasis:
    """Fourier basis of a harmonic balance: which harmonics, how many time samples.

    Parameters
    ----------
    harmonics : tuple of int
        Harmonic numbers, e.g. ``(1,)`` (the paper's setting) or ``(0, 1, 2, 3)``.
    n_samples : int, optional
        Time samples per period for the AFT; default ``max(64, 16 * max(harmonics))``.
        Must exceed ``2 * max(harmonics)``.
    """

    harmonics: tuple[int, ...]
    n_samples: int | None = None
    synthesis: np.ndarray = field(init=False, repr=False)   # (T, C): samples = synthesis @ coeffs
    analysis: np.ndarray = field(init=False, repr=False)    # (C, T): coeffs = analysis @ samples
    derivative: np.ndarray = field(init=False, repr=False)  # (C, C): d/dtau in coefficient space
    order: np.ndarray = field(init=False, repr=False)       # (C,): harmonic number of each coefficient

    def __post_init__(self):
        harmonics = tuple(self.harmonics) if np.ndim(self.harmonics) else (self.harmonics,)
        if len(harmonics) == 0:
            raise ValueError("harmonics must be a non-empty tuple of integers >= 0 (got ())")
        for h in harmonics:
            validation.integer("harmonics", h, minimum=0)
        harmonics = tuple(sorted(set(int(h) for h in harmonics)))
        if harmonics == (0,):
            raise ValueError("harmonics must contain at least one harmonic >= 1 (got (0,))")
        h_max = max(harmonics)
        n = self.n_samples if self.n_samples is not None else max(64, 16 * h_max)
        n = validation.integer("n_samples", n, minimum=2 * h_max + 1)
        object.__setattr__(self, "harmonics", harmonics)
        object.__setattr__(self, "n_samples", n)
        tau = 2 * np.pi * np.arange(n) / n
        cols, rows, order = [], [], []
        for h in harmonics:
            if h == 0:
                cols.append(np.ones(n))
                rows.append(np.full(n, 1.0 / n))
                order.append(0)
            else:
                cols += [np.cos(h * tau), np.sin(h * tau)]
                rows += [2.0 / n * np.cos(h * tau), 2.0 / n * np.sin(h * tau)]
                order += [h, h]
        object.__setattr__(self, "synthesis", np.ascontiguousarray(np.array(cols).T))
        object.__setattr__(self, "analysis", np.ascontiguousarray(np.array(rows)))
        order = np.array(order, dtype=int)
        object.__setattr__(self, "order", order)
        deriv = np.zeros((len(order), len(order)))
        for j, h in enumerate(order):
            if h > 0 and (j == 0 or order[j - 1] != h):  # j is a_h, j+1 is b_h
                deriv[j, j + 1] = h      # a' = h b
                deriv[j + 1, j] = -h     # b' = -h a
        object.__setattr__(self, "derivative", deriv)
        # the first coefficient of each harmonic (cos_index, asked at every residual evaluation)
        object.__setattr__(self, "_first_index", {h: int(np.flatnonzero(order == h)[0]) for h in harmonics})

    @property
    def n_coeffs(self) -> int:
        """Number of real coefficients per degree of freedom."""
        return len(self.order)

    @property
    def has_static(self) -> bool:
        return self.harmonics[0] == 0

    @property
    def tau(self) -> np.ndarray:
        """Sample phases Omega t in [0, 2 pi) [rad]."""
        return 2 * np.pi * np.arange(self.n_samples) / self.n_samples

    def cos_index(self, h: int) -> int:
        """Index of the coefficient a_h (or c_0 for h = 0); IndexError for a harmonic not in the basis."""
        try:
            return self._first_index[h]
        except KeyError:
            raise IndexError(f"harmonic {h!r} is not in the basis {self.harmonics}") from None

    # ----- signals -------------------------------------------------------------------
    def to_time(self, coeffs: np.ndarray) -> np.ndarray:
        """Samples (T, ...) from coefficients (C, ...)."""
        return np.tensordot(self.synthesis, coeffs, axes=(1, 0))

    def to_coeffs(self, samples: np.ndarray) -> np.ndarray:
        """Coefficients (C, ...) from samples (T, ...)."""
        return np.tensordot(self.analysis, samples, axes=(1, 0))

    def to_complex(self, coeffs: np.ndarray) -> dict[int, np.ndarray]:
        """Complex amplitudes {h: X_h} with x = Re(X_h e^{i h tau}) (paper's notation, Eq. 4)."""
        coeffs = np.asarray(coeffs)
        out = {}
        for h in self.harmonics:
            j = self.cos_index(h)
            out[h] = coeffs[j] + 0j if h == 0 else coeffs[j] - 1j * coeffs[j + 1]
        return out

    def from_complex(self, amplitudes: dict[int, np.ndarray]) -> np.ndarray:
        """Inverse of :meth:`to_complex`; missing harmonics are zero."""
        first = np.asarray(next(iter(amplitudes.values())))
        out = np.zeros((self.n_coeffs,) + first.shape)
        for h, value in amplitudes.items():
            if h not in self.harmonics:
                raise ValueError(f"harmonic {h} is not in harmonics={self.harmonics}")
            j = self.cos_index(h)
            value = np.asarray(value)
            out[j] = value.real
            if h > 0:
                out[j + 1] = -value.imag
        return out

    def embed(self, coeffs: np.ndarray, target: "HarmonicBasis") -> np.ndarray:
        """The coefficients (C, ...) of this basis written in ``target``'s (C', ...): harmonics
        ``target`` adds are zero, harmonics it lacks are dropped (the same signal, band-limited)."""
        coeffs = np.asarray(coeffs)
        out = np.zeros((target.n_coeffs,) + coeffs.shape[1:])
        for h in self.harmonics:
            if h in target.harmonics:
                j, k = self.cos_index(h), target.cos_index(h)
                width = 1 if h == 0 else 2
                out[k:k + width] = coeffs[j:j + width]
        return out

    def work_per_cycle(self, force: np.ndarray, displacement: np.ndarray) -> np.ndarray:
        """Work of ``force`` along ``displacement`` over one period, oint f dw [J].

        Both are coefficient arrays (C, ...); summed over the coefficient axis only.
        Exact for the sampled signals (discrete Parseval), so it is the energy the AFT sees.
        """
        # np.tensordot's own products (the same BLAS calls on the same 2-D views, without its
        # Python set-up: a branch's energies evaluate this at every point)
        displacement = np.asarray(displacement)
        C = self.n_coeffs
        velocity = np.dot(self.derivative, displacement.reshape(C, -1)).reshape(displacement.shape)  # dw/dtau
        product = np.asarray(force) * velocity
        weights = np.where(self.order == 0, 2 * np.pi, np.pi)
        return np.dot(weights.reshape(1, C), product.reshape(C, -1)).reshape(product.shape[1:])

    def work_bound(self, force: np.ndarray, displacement: np.ndarray) -> np.ndarray:
        """The largest work per period that harmonics of these amplitudes can do, pi sum_h h
        |F_h| |W_h| [J] (harmonic h does pi h |F_h| |W_h| sin(phase lag); the static term none).

        The energy scale of :meth:`work_per_cycle` on the same arrays (C, ...), summed over the
        coefficient axis only: an error eps |F_h| in the force harmonics (the AFT's time sampling)
        changes the work by at most eps times this bound.
        """
        force, displacement = np.asarray(force), np.asarray(displacement)
        out = np.zeros(np.broadcast_shapes(force.shape[1:], displacement.shape[1:]))
        for h in self.harmonics:
            if h > 0:
                j = self.cos_index(h)
                out = out + np.pi * h * np.hypot(force[j], force[j + 1]) * np.hypot(displacement[j], displacement[j + 1])
        return out

    # ----- matrices ------------------------------------------------------------------
    def real_form(self, per_harmonic) -> np.ndarray:
        """Real (C*n_out, C*n_in) matrix of a linear map given per harmonic as complex matrices.

        ``per_harmonic`` is a callable ``h -> complex (n_out, n_in)``. The harmonic-h block
        acting on (a_h, b_h) is [[Gr, Gi], [-Gi, Gr]] (multiplication of X = a - i b by G).
        The static block must be real.
        """
        blocks = {h: np.atleast_2d(np.asarray(per_harmonic(h))) for h in self.harmonics}
        n_out, n_in = blocks[self.harmonics[0]].shape
        C = self.n_coeffs
        out = np.zeros((C * n_out, C * n_in))
        for h, g in blocks.items():
            j = self.cos_index(h)
            if h == 0:
                if np.any(np.abs(np.imag(g)) > 1e-12 * (1 + np.abs(g).max())):
                    raise ValueError("the static (h = 0) block of a linear map must be real")
                out[j * n_out:(j + 1) * n_out, j * n_in:(j + 1) * n_in] = np.real(g)
                continue
            gr, gi = np.real(g), np.imag(g)
            a_o, b_o = slice(j * n_out, (j + 1) * n_out), slice((j + 1) * n_out, (j + 2) * n_out)
            a_i, b_i = slice(j * n_in, (j + 1) * n_in), slice((j + 1) * n_in, (j + 2) * n_in)
            out[a_o, a_i] = gr
            out[a_o, b_i] = gi
            out[b_o, a_i] = -gi
            out[b_o, b_i] = gr
        return out

    def dynamic_stiffness_parts(self, mass, damping, stiffness):
        """The parts of the real-form dynamic stiffness that do not depend on Omega:
        ``(K_0, M_2, G)``, each (C*n, C*n) [N/m, kg, N s/m], with
        ``A(Omega) = K_0 - Omega^2 M_2 + Omega G`` (:meth:`dynamic_stiffness`); a caller that
        evaluates A at many frequencies builds them once."""
        mass, damping, stiffness = (np.atleast_2d(np.asarray(m, dtype=float)) for m in (mass, damping, stiffness))
        # same as real_form(h -> K - (h Omega)^2 M + i h Omega D), assembled as Kronecker
        # products (harmonic-major): the block of i h is [[0, h], [-h, 0]], the derivative
        # matrix. Broadcasting instead of real_form's Python loop: ~6x faster per call.
        C, n = self.n_coeffs, stiffness.shape[0]

        def kron(coeff_matrix, dof_matrix):
            return (coeff_matrix[:, None, :, None] * dof_matrix[None, :, None, :]).reshape(C * n, C * n)

        return kron(np.eye(C), stiffness), kron(np.diag(self.order.astype(float) ** 2), mass), \
            kron(self.derivative, damping)

    @staticmethod
    def dynamic_stiffness_pattern(parts):
        """``(flat indices, K_0, M_2, G at them)`` of the entries of :meth:`dynamic_stiffness_parts`
        ``parts`` where any of them is nonzero (the harmonic blocks: A is block diagonal up to
        the cos/sin pairs), for :meth:`dynamic_stiffness` to fill those alone."""
        index = np.flatnonzero(np.logical_or.reduce([np.asarray(p) != 0 for p in parts]).ravel())
        return (index,) + tuple(np.asarray(p).ravel()[index] for p in parts)

    def dynamic_stiffness(self, omega: float, mass, damping, stiffness, parts=None, derivative=True, pattern=None):
        """Real-form dynamic stiffness and its derivative in omega.

        Harmonic h block: K - (h Omega)^2 M + i h Omega D (paper Eq. 5 in modal form).
        ``parts``: :meth:`dynamic_stiffness_parts` of the same matrices if already built;
        ``pattern``: :meth:`dynamic_stiffness_pattern` of them (the same numbers, only the nonzero
        entries computed: 4-5x fewer operations for a tuned sector).
        Returns ``(A, dA_domega)``, each (C*n, C*n) (``dA_domega`` None without ``derivative``).
        """
        stiffness_part, inertia, gyro = parts if parts is not None else \
            self.dynamic_stiffness_parts(mass, damping, stiffness)
        if pattern is not None:
            index, k0, m2, g = pattern
            A = np.zeros(stiffness_part.shape)
            A.reshape(-1)[index] = k0 - m2 * omega ** 2 + g * omega      # the operations below, in their order
            if not derivative:
                return A, None
            dA = np.zeros(stiffness_part.shape)
            dA.reshape(-1)[index] = -2 * omega * m2 + g
            return A, dA
        # A = K_0 - Omega^2 M_2 + Omega G, the same operations in place (two arrays instead of four)
        A = np.multiply(inertia, omega ** 2)
        np.subtract(stiffness_part, A, out=A)
        A += np.multiply(gyro, omega)
        dA = -2 * omega * inertia + gyro if derivative else None
        return A, dA


def enriched(harmonics) -> tuple[int, ...]:
    """The set a branch computed with ``harmonics`` is checked against: with the static term
    and the next two harmonics."""
    h = tuple(harmonics)
    return tuple(sorted(set(h) | {0, max(h) + 1, max(h) + 2}))
