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


class PlausibilityWarning(UserWarning):
    """A value that is allowed but outside the range a real design has: most often a unit slip
    (1 kg meant as 1 g, 20 m meant as 20 mm). The computation goes on; the warning names the
    parameter, its value and unit, and the plausible range."""


def _outside_caller_level() -> int:
    """The ``stacklevel`` of the first frame outside bladedamp and outside the dataclasses module
    (its ``replace`` and the ``__init__`` it generates), so that a warning points at the user's line."""
    import os
    import sys

    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None:
        filename = frame.f_code.co_filename
        generated = filename.startswith("<") and frame.f_code.co_name == "__init__"    # a dataclass's __init__
        dataclasses = frame.f_globals.get("__name__") == "dataclasses"                # dataclasses.replace
        if not (filename.startswith(package) or generated or dataclasses):
            return level
        frame, level = frame.f_back, level + 1
    return 1


def plausible(name: str, value, low: float, high: float, unit: str, reason: str = ""):
    """Warn (:class:`PlausibilityWarning`) if ``value`` lies outside [low, high] ``unit``; zero
    is exempt (it means "absent" for a damper mass). Returns ``value`` unchanged.

    ``reason`` says where the range comes from; the message reads e.g. "damper mass = 1 kg is
    outside the plausible range 1e-05-0.1 kg (...): check its unit (SI: kg, m)", one sentence."""
    import warnings

    arr = np.asarray(value, dtype=float)
    outside = (arr != 0) & ((arr < low) | (arr > high))
    if np.any(outside):
        why = f" ({reason})" if reason else ""
        warnings.warn(f"{name} = {value!r} {unit} is outside the plausible range {low:g}-{high:g} {unit}{why}: "
                      "check its unit (SI: kg, m)",
                      PlausibilityWarning, stacklevel=_outside_caller_level())
    return value
