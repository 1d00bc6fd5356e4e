"""Harmonic balance: Fourier basis and AFT (fourier), the residual of a structure with nonlinear
elements (system), the element contract and the base class for your own (elements), Newton and
arc-length continuation (continuation).

The public names below are imported on first use (PEP 562), so that importing a light submodule
(``bladedamp.hbm.fourier``) does not load the solver (scipy.sparse, numba).
"""
from ..lazy import lazy_attributes

_LAZY = {
    "HarmonicBasis": "fourier",
    "Coupling": "system", "HarmonicBalanceSystem": "system", "NonlinearElement": "system",
    "with_element": "system",
    "TimeDomainElement": "elements", "CubicSpring": "elements", "GapSpring": "elements",
}
__all__ = sorted(_LAZY)


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, globals())
