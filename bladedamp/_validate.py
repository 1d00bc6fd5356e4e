"""Input checks shared by every model: each raises ValueError naming the parameter and its allowed range."""
from __future__ import annotations

import numpy as np


def _as_finite(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {value!r})")
    return arr


def positive(name: str, value, allow_zero: bool = False):
    """Check ``value`` > 0 (or >= 0); returns it as float or array."""
    arr = _as_finite(name, value)
    bad = arr < 0 if allow_zero else arr <= 0
    if np.any(bad):
        rng = "[0, inf)" if allow_zero else "(0, inf)"
        raise ValueError(f"{name} must be in {rng} (got {value!r})")
    return float(arr) if arr.ndim == 0 else arr


def nonnegative(name: str, value):
    """Check ``value`` >= 0."""
    return positive(name, value, allow_zero=True)


def in_range(name: str, value, low: float, high: float, closed: str = "both"):
    """Check low <= value <= high; ``closed`` in {'both', 'neither', 'left', 'right'}."""
    arr = _as_finite(name, value)
    lo_ok = arr >= low if closed in ("both", "left") else arr > low
    hi_ok = arr <= high if closed in ("both", "right") else arr < high
    if not np.all(lo_ok & hi_ok):
        lb = "[" if closed in ("both", "left") else "("
        rb = "]" if closed in ("both", "right") else ")"
        raise ValueError(f"{name} must be in {lb}{low}, {high}{rb} (got {value!r})")
    return float(arr) if arr.ndim == 0 else arr


def finite(name: str, value):
    """Check that every entry of ``value`` is finite."""
    arr = _as_finite(name, value)
    return float(arr) if arr.ndim == 0 else arr


def integer(name: str, value, minimum: int = 0, maximum: int | None = None) -> int:
    """Check an integer in [minimum, maximum]."""
    hi = "inf)" if maximum is None else f"{maximum}]"
    try:
        ok = not isinstance(value, bool) and float(value) == int(value)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise ValueError(f"{name} must be an integer in [{minimum}, {hi} (got {value!r})")
    value = int(value)
    if value < minimum or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be an integer in [{minimum}, {hi} (got {value!r})")
    return value


def interval(name: str, value, unit: str = "") -> tuple[float, float]:
    """Check a pair (low, high) with 0 < low < high, both finite; returns it as floats."""
    unit = f" {unit}" if unit else ""
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair (low, high) with 0 < low < high{unit} (got {value!r})") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"{name} must satisfy 0 < low < high{unit} (got {value!r})")
    return lo, hi
