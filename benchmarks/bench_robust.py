"""Designs robust to mistuning (issue 36 item 3): the perturbation estimate's cost and accuracy
against a Monte Carlo of the same statistic, and the robust objective over the damper mass.

    python benchmarks/bench_robust.py [--std 1e-4] [--disks 200] [--masses 0.4,0.6,0.8,1.0,1.4] [--copies 20]

1. The first-order estimate of the mean largest blade peak of the reference cylinder (1 g) at
   ``--std`` (blade 0's gradient: one peak with its derivatives; 16 check disks solved in full)
   and a serial Monte Carlo of ``--disks`` disks at the same settings: CPU seconds of each and
   their means (the Monte Carlo's standard error beside it).
2. The robust objective (mean largest blade peak of ``--copies`` copies, std 2 %, common random
   numbers) and its mass derivative, with the tuned peak, at each of ``--masses`` [g].
CPU time (time.process_time), one process, with the machine's load (os.getloadavg).
"""
import argparse
import os
import time
import warnings

import numpy as np

import bladedamp as bd
from bladedamp.studies.mistuning import monte_carlo, tuned_peak
from bladedamp.studies.robust import mistuning_gradient, perturbation_estimate, robust_objective


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--std", type=float, default=1e-4)
    parser.add_argument("--disks", type=int, default=200)
    parser.add_argument("--masses", default="0.4,0.6,0.8,1.0,1.4")
    parser.add_argument("--copies", type=int, default=20)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print(f"load {os.getloadavg()[0]:.1f}")
    disk = bd.reference_disk("cylinder", 1e-3)
    t = time.process_time()
    gradient = mistuning_gradient(disk)
    t_gradient = time.process_time() - t
    estimate = perturbation_estimate(disk, args.std, gradient=gradient)
    t_estimate = time.process_time() - t
    print(f"perturbation estimate, std {args.std:g}: gradient {t_gradient:.1f} CPU s, with the 16 check disks "
          f"{t_estimate:.1f} CPU s")
    print(estimate.table())
    t = time.process_time()
    mc = monte_carlo(disk, args.disks, std=args.std, seed=1, scheduler="serial", tol=1e-8,
                     tuned_peak_amplitude=estimate.tuned_peak_amplitude)
    t_mc = time.process_time() - t
    peaks = mc.peak_amplitude.max(axis=1)
    print(f"Monte Carlo {args.disks} disks: {t_mc:.1f} CPU s ({t_mc / args.disks:.2f} s a disk; 1000 disks "
          f"~{1000 * t_mc / args.disks:.0f} CPU s = {1000 * t_mc / args.disks / t_estimate:.0f} x the estimate): mean "
          f"{1e3 * peaks.mean():.5f} mm +- {1e3 * peaks.std(ddof=1) / np.sqrt(len(peaks)):.3g}; estimate "
          f"{1e3 * estimate.mean:.5f} mm +- {1e3 * estimate.error:.3g}; load {os.getloadavg()[0]:.1f}")
    print(f"robust objective: mean largest blade peak of {args.copies} copies, std 2 %")
    print("  mass [g]  tuned peak [mm]  robust mean [mm]  amplification  d mean / dm [mm/g]  CPU s")
    for m in (float(v) for v in args.masses.split(",")):
        model = disk.with_parameters({"damper.mass_g": m})
        t = time.process_time()
        a0 = tuned_peak(model, (85.0, 110.0))[0]
        objective = robust_objective(model, ["damper.mass_g"], 0.02, args.copies, seed=0)
        print(f"  {m:8.3g}  {1e3 * a0:15.4f}  {1e3 * objective.value:16.4f}  {objective.value / a0:13.3f}  "
              f"{1e3 * objective.gradient[0]:18.4f}  {time.process_time() - t:5.1f}")
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
