"""Compile every numba kernel of bladedamp ahead of the user's first call.

The kernels (the contact return map and its Jacobian, the ring solver of the full assembly, the
time integrators, the monodromy period map) are compiled by numba on their first call and kept
in the per-user cache (:mod:`bladedamp._numba_cache`). On a cold cache that compilation is most
of the first call (benchmarks/README.md, 'Start-up and the numba compile cost'). :func:`precompile`
moves it out of that first call: run it once after installing (``bladedamp precompile``, e.g.
in a Docker image or a lab machine's set-up), and every later process loads the compiled code.

It compiles by running the public paths on tiny problems, so the kernels get exactly the
argument types of real use (numba compiles one version per type signature): a flat and an
inclined friction oscillator (with and without the Jacobian, the closed-form and the iterated
slider derivative), the reference disk's residual, a 4-blade full assembly (the ring solver),
the time integration of both, and the monodromy of both. A kernel already in the cache is
only loaded. After it, in a new process, the reference disk's FRF, a mistuned FRF and the
time integrations compile nothing.
"""
from __future__ import annotations

import hashlib
import os
import sys
import time
import warnings

# [s] CPU time of bladedamp.precompile() on an empty cache, about (49 s measured on the 2-core
# machine, benchmarks/README.md, "`bladedamp precompile` from an empty cache (item 5)"); a command
# compiles the kernels it uses, at most that
COLD_COMPILE_SECONDS = 50


def kernel_cache_folders() -> list[str]:
    """The folders where numba keeps (or would keep) the compiled kernels of this copy of
    bladedamp, one per source folder of the package: inside numba's cache folder
    (``NUMBA_CACHE_DIR``, which bladedamp points at its per-user cache), a folder named as numba
    names it (the source folder's name, "_", the SHA-1 of its absolute path); without a cache
    folder, the source folders' ``__pycache__``."""
    numba_config = sys.modules.get("numba.core.config")
    cache_dir = getattr(numba_config, "CACHE_DIR", None) or os.environ.get("NUMBA_CACHE_DIR")
    package = os.path.dirname(os.path.abspath(__file__))
    sources = [root for root, dirs, files in os.walk(package)
               if "__pycache__" not in root.split(os.sep) and any(f.endswith(".py") for f in files)]
    if not cache_dir:
        return [os.path.join(source, "__pycache__") for source in sources]
    return [os.path.join(cache_dir, f"{os.path.basename(source)}_{hashlib.sha1(source.encode()).hexdigest()}")
            for source in sources]


def cache_is_cold() -> bool:
    """True when numba's cache holds no compiled kernel of this copy of bladedamp (no index
    file ``*.nbi`` in :func:`kernel_cache_folders`): the first kernel call of the process then
    compiles, about ``COLD_COMPILE_SECONDS`` in all. Does not import numba."""
    for folder in kernel_cache_folders():
        try:
            if any(name.endswith(".nbi") for name in os.listdir(folder)):
                return False
        except OSError:
            continue
    return True


def _oscillator_paths():
    from .hbm.stability import with_stability
    from .oscillator import FrictionOscillator

    flat = FrictionOscillator(mass=1.0, stiffness=1.0, damping=0.02, contact_stiffness=1.0,
                              friction_coefficient=1.0, normal_load=0.3, forcing=0.2)
    r = flat.frequency_response(0.12, 0.2, harmonics=(1, 3), max_step=0.2)
    with_stability(flat, r, method="monodromy")
    inclined = FrictionOscillator(mass=1.0, stiffness=1.0, damping=0.02, contact_stiffness=1.0,
                                  friction_coefficient=0.5, normal_load=0.05, forcing=0.1, contact_angle=0.5)
    inclined.frequency_response(0.12, 0.2, max_step=0.2)
    flat.time_response([0.15], max_periods=30)


def _disk_paths():
    import dataclasses

    import numpy as np

    from .hbm.linsolve import permutation_sign
    from .hbm.monodromy import monodromy_multipliers
    from .mistuned import AssemblySystem, MistunedDisk
    from .reference import reference_disk

    disk = reference_disk("cylinder", 1e-3)
    disk.frequency_response(94.0, 94.5, harmonics=(1,), max_step=0.5)
    def small():
        return MistunedDisk.from_tuned(dataclasses.replace(disk, n_blades=4, engine_order=1),
                                       kappa=np.array([1.0, 1.01, 0.99, 1.0]))

    small().frequency_response(94.0, 94.2, harmonics=(1,), max_step=0.5)
    small().frequency_response(94.0, 94.2, harmonics=(1,), max_step=0.5, n_samples=50)   # dampers' shifted grids
    small().time_response([94.0], max_periods=2, min_periods=1)
    four = dataclasses.replace(disk, n_blades=4, engine_order=1)      # the disk's monodromy (static term)
    r = four.frequency_response(92.0, 92.1, harmonics=(0, 1), max_step=0.5)
    monodromy_multipliers(four, r.coefficients[0], r.basis, float(r.omega[0]))
    dense_limit = AssemblySystem.dense_limit
    try:              # the sparse Jacobian of large assemblies (its ring gather and sparse LU's sign)
        AssemblySystem.dense_limit = 0
        small().frequency_response(94.0, 94.2, harmonics=(1,), max_step=0.5)
    finally:
        AssemblySystem.dense_limit = dense_limit
    # scipy's sparse LU permutations (int32) are passed as np.intp: one signature
    permutation_sign(np.arange(3, dtype=np.intp))


GROUPS = {"oscillator": _oscillator_paths, "disk": _disk_paths}


def precompile(progress=print) -> dict:
    """Compile (or load from the cache) every numba kernel of bladedamp; returns the seconds
    per group {"oscillator": s, "disk": s}. ``progress`` is called with one line per group
    (None: quiet). Harmless to run again: a second run only loads the cache (about 1-2 s)."""
    seconds = {}
    for name, run in GROUPS.items():
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")          # tiny problems: accuracy warnings are irrelevant
            run()
        seconds[name] = time.perf_counter() - start
        if progress is not None:
            progress(f"{name} kernels ready in {seconds[name]:.1f} s")
    return seconds
