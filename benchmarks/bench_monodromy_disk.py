"""Time per point of the disk's monodromy matrix against the HBM solve (issue 14).

For the reference disk ("cylinder", 1 g) with 4 and 16 blades (TunedDisk, harmonics
(0, 1, 2, 3)): the FRF 90-100 Hz by continuation (its time per point: the HBM solve), then
the monodromy multipliers (:func:`bladedamp.hbm.monodromy.monodromy_multipliers`: the full
assembly's period map, 2 m + 1 trajectories, m = 2 N + 2 P) at three points, the first call
excluded (numba compile). Run: ``nice python benchmarks/bench_monodromy_disk.py [n_blades ...]``.
"""
import dataclasses
import sys
import time
import warnings

import numpy as np

import bladedamp as bd
from bladedamp.hbm.monodromy import disk_monodromy, monodromy_multipliers


def main(blades=(4, 16)):
    ref = bd.reference_disk("cylinder", 1e-3)
    for n in blades:
        disk = dataclasses.replace(ref, n_blades=n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            disk.frequency_response(94.0, 94.2, harmonics=(0, 1, 2, 3))          # compile
            t = time.perf_counter()
            r = disk.frequency_response(90.0, 100.0, harmonics=(0, 1, 2, 3))
            t_hbm = (time.perf_counter() - t) / len(r.omega)
        idx = [int(np.argmin(abs(r.frequency_hz - f))) for f in (92.0, 95.3, 98.0)]
        monodromy_multipliers(disk, r.coefficients[idx[0]], r.basis, float(r.omega[idx[0]]))   # compile, cache
        times = []
        for i in idx:
            t = time.perf_counter()
            mu, err = monodromy_multipliers(disk, r.coefficients[i], r.basis, float(r.omega[i]))
            times.append(time.perf_counter() - t)
            print(f"  {n} blades {r.frequency_hz[i]:.2f} Hz: max |mu| {abs(mu[0]):.9f}, periodicity error {err:.2e}, "
                  f"{times[-1]:.2f} s")
        mono, z, err, steps, _ = disk_monodromy(disk, r.coefficients[idx[1]], r.basis, float(r.omega[idx[1]]))
        print(f"{n} blades: state m = {z.size}, {steps} steps per period; HBM {t_hbm * 1e3:.1f} ms per point "
              f"({len(r.omega)} points), monodromy {np.mean(times):.2f} s per point = {np.mean(times) / t_hbm:.0f} x")


if __name__ == "__main__":
    main(tuple(int(a) for a in sys.argv[1:]) or (4, 16))
