"""Gradient-based design against a dense grid (issue 36 item 2): the lowest peak of the reference
cylinder (from 3 g, (1,), 90-105 Hz) over mass and the platform angles, by
``bladedamp.studies.gradient.optimal_design`` and by the grid (mass log-spaced 0.1-20 g, angles
20-60 deg), the frequency responses each used and the peaks found, with the load.

    python benchmarks/bench_gradient_design.py --parameters 2 --points 16
    python benchmarks/bench_gradient_design.py --parameters 3 --points 8
"""
import argparse
import itertools
import os
import time
import warnings

import numpy as np

import bladedamp as bd
from bladedamp.studies.gradient import optimal_design

KEYS = ["damper.mass_g", "disk.gamma_left_deg", "disk.gamma_right_deg"]
BOUNDS = [[0.1, 20.0], [20.0, 60.0], [20.0, 60.0]]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--parameters", type=int, default=2, choices=(1, 2, 3))
    parser.add_argument("--points", type=int, default=16, help="grid points per parameter")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    keys, bounds = KEYS[:args.parameters], BOUNDS[:args.parameters]
    disk = bd.reference_disk("cylinder", 3e-3)
    t = time.process_time()
    optimum = optimal_design(disk, keys, bounds, (90.0, 105.0), harmonics=(1,))
    t_opt = time.process_time() - t
    axes = [np.geomspace(*bounds[0], args.points)] + [np.linspace(*b, args.points) for b in bounds[1:]]
    best, solves, t = (np.inf, None), 0, time.process_time()
    for point in itertools.product(*axes):
        solves += 1
        r = disk.with_parameters(dict(zip(keys, point))).frequency_response(90.0, 105.0, harmonics=(1,))
        if r.success and r.peak_amplitude < best[0]:
            best = (r.peak_amplitude, point)
    t_grid = time.process_time() - t
    load = os.getloadavg()
    print(f"{len(keys)} parameters; load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(optimum.table())
    print(f"optimiser: {1e3 * optimum.peak_amplitude:.4f} mm, {optimum.n_responses} responses, {t_opt:.1f} s CPU")
    print(f"grid {args.points}^{len(keys)}: {1e3 * best[0]:.4f} mm at {np.round(best[1], 3).tolist()}, {solves} responses, "
          f"{t_grid:.1f} s CPU; optimiser / grid responses {optimum.n_responses / solves:.3f}")


if __name__ == "__main__":
    main()
