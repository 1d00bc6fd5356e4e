"""Helpers shared by the benchmark scripts (run them as ``python benchmarks/bench_*.py``)."""
from __future__ import annotations

import time

import numpy as np


def best_of(fun, repeat):
    """(best wall time [s], result of the last call) over ``repeat`` calls."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t0)
    return best, out


def solved_response(disk, f_range, max_step, harmonics=(1,)):
    """The disk's FRF over ``f_range`` [Hz] (the paper's one-harmonic setting unless
    ``harmonics`` says otherwise); raises if the continuation did not cover it."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(*f_range, harmonics=harmonics, max_step=max_step)
    if not r.success:
        raise RuntimeError(r.message)
    return r
