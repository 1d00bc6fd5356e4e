"""Process-level parallelism over independent study cases (each case its own continuation)."""
from __future__ import annotations

import multiprocessing
import os
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed

from .. import validation


def _quiet(fn, item):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(item)


def workers(processes: int | None, n: int) -> int:
    """The number of worker processes :func:`parallel_map` uses for ``n`` items (``processes``
    None: every core; at least 1)."""
    if processes is not None:
        processes = validation.integer("processes (worker processes; None: every core)", processes, minimum=1)
    return max(1, min(processes or os.cpu_count() or 1, n))


def parallel_map(fn, items, processes: int | None = None, progress=None) -> list:
    """``[fn(item) for item in items]``, in order, on ``processes`` worker processes.

    ``fn`` must be a module-level function (picklable). ``processes=None`` uses every core;
    1 runs in this process; anything else but an integer >= 1 raises ValueError. ``progress(done, total)`` is called as cases finish.
    """
    items = list(items)
    n = len(items)
    processes = workers(processes, n)
    if processes <= 1:
        out = []
        for k, item in enumerate(items):
            out.append(_quiet(fn, item))
            if progress:
                progress(k + 1, n)
        return out
    results = [None] * n
    with ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context("fork")) as pool:
        futures = {pool.submit(_quiet, fn, item): k for k, item in enumerate(items)}
        for done, future in enumerate(as_completed(futures), start=1):
            results[futures[future]] = future.result()
            if progress:
                progress(done, n)
    return results
