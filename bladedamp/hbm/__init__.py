"""Harmonic balance: Fourier basis and AFT (fourier), Newton and arc-length continuation (continuation)."""
from .fourier import HarmonicBasis

__all__ = ["HarmonicBasis"]
