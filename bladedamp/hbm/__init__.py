"""Harmonic balance: Fourier basis and AFT (fourier), the residual of a structure with nonlinear
elements (system), the element contract and the base class for your own (elements), Newton and
arc-length continuation (continuation).

The public names below are imported on first use (PEP 562), so that importing a light submodule
(``bladedamp.hbm.fourier``) does not load the solver (scipy.sparse, numba).
"""
import importlib

_LAZY = {
    "HarmonicBasis": "fourier",
    "Coupling": "system", "HarmonicBalanceSystem": "system", "NonlinearElement": "system",
    "with_element": "system",
    "TimeDomainElement": "elements", "CubicSpring": "elements", "GapSpring": "elements",
}
__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'bladedamp.hbm' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
