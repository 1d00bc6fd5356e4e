"""The 16-blade mistuned FRF against the cost of its kernels (issue 37, item 2).

Run from the repository root (about 2 minutes on the quiet machine)::

    python benchmarks/bench_mistuned_kernel_limit.py
    python benchmarks/bench_mistuned_kernel_limit.py --range 90 97      # a shorter branch

The FRF: ``MistunedDisk.from_tuned(reference_disk("cylinder", 1e-3), random_kappa(16, std=0.02,
seed=1)).frequency_response(88, 102, harmonics=(0, 1, 2, 3), n_samples=64,
estimate_harmonic_error=False)`` (the harmonics the default path ends on), second call in the
process. Run once plain (the achieved CPU time, ``time.process_time``) and once under cProfile
with ``time.process_time`` as its clock (the kernels' own CPU time, found by their names in the
profile: the contact kernel ``damper_contact_forces`` and the ring solver's ``_ring_condense``,
``_ring_factor``, ``_ring_substitute``; the profile's overhead falls on the Python code around
them, not on them). The ring's gather is not counted as a kernel (it only moves values).

Kernel-limit estimates printed beside the achieved time per point:

* at this run's Jacobian count: the kernels' CPU time of the run per point, what the FRF would
  cost if everything around the kernels were free (residual assembly, Jacobian scatter, the
  ring's gather, the bordering, the continuation's Python);
* at one Jacobian a point: the kernels' cost of one Jacobian (a contact evaluation with its
  Jacobian and one ring factorisation, averaged over the run) times one Jacobian a point, the
  floor of a continuation that converges every point in one Newton step and rejects no step.
"""
from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import subprocess
import sys
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from bladedamp.mistuned import MistunedDisk  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402
from bladedamp.studies.mistuning import random_kappa  # noqa: E402

CONTACT = ("damper_contact_forces",)
RING = ("_ring_condense", "_ring_factor", "_ring_substitute")


def load() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def kernel_times(stats: pstats.Stats) -> dict:
    """{kernel name: (calls, CPU s)} of the profiled kernels."""
    out = {}
    for (_, _, name), (calls, _, tottime, _, _) in stats.stats.items():
        if name in CONTACT + RING:
            n, t = out.get(name, (0, 0.0))
            out[name] = (n + calls, t + tottime)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--range", type=float, nargs=2, default=(88.0, 102.0), metavar=("F0", "F1"))
    args = parser.parse_args()
    disk = MistunedDisk.from_tuned(reference_disk("cylinder", 1e-3), random_kappa(16, std=0.02, seed=1))
    options = dict(harmonics=(0, 1, 2, 3), n_samples=64, estimate_harmonic_error=False)

    def frf():
        return disk.frequency_response(*args.range, **options)

    print(load())
    frf()                                                   # warm-up: numba caches, the system
    t0 = time.process_time()
    r = frf()
    achieved = time.process_time() - t0
    n = len(r.omega)
    profile = cProfile.Profile(time.process_time)          # CPU time, as the achieved figure
    profile.enable()
    frf()
    profile.disable()
    k = kernel_times(pstats.Stats(profile))
    contact = sum(k.get(name, (0, 0.0))[1] for name in CONTACT)
    ring = sum(k.get(name, (0, 0.0))[1] for name in RING)
    factorisations = k.get("_ring_factor", (0, 0.0))[0]
    contact_calls = k.get("damper_contact_forces", (0, 0.0))[0]
    per_jacobian = (contact / max(contact_calls, 1) + (ring / max(factorisations, 1)))
    print(f"mistuned 16 blades, {args.range[0]:g}-{args.range[1]:g} Hz, harmonics (0, 1, 2, 3), 64 samples: "
          f"{n} points, success {r.success}, peak {1e3 * r.peak_amplitude:.6f} mm at {r.peak_frequency_hz:.4f} Hz")
    print(f"achieved                 : {achieved:7.2f} s CPU, {1e3 * achieved / n:6.2f} ms a point")
    print(f"kernels (profiled run)   : contact {contact:6.2f} s ({contact_calls} calls), ring {ring:6.2f} s "
          f"({factorisations} factorisations), {100 * (contact + ring) / achieved:4.1f} % of the achieved time; "
          f"{factorisations / n:.2f} Jacobians a point")
    limit_run = 1e3 * (contact + ring) / n
    limit_one = 1e3 * per_jacobian
    per_point = 1e3 * achieved / n
    print(f"kernel limit, this run's Jacobians : {limit_run:6.2f} ms a point -> achieved {per_point / limit_run:4.2f}x")
    print(f"kernel limit, one Jacobian a point : {limit_one:6.2f} ms a point -> achieved {per_point / limit_one:4.2f}x")
    print(load())


if __name__ == "__main__":
    main()
