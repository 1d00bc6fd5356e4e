"""Cost of the default frequency response of random MISTUNED disks (issue 32, item 2).

    python benchmarks/bench_mistuned_random_cost.py --seeds 0:10 [--budget 60] [--blades 16] [--profile out.prof]

Design i: the random tuned disk ``disk_design(i)`` of tests/test_random_designs.py (same ranges,
``make_disk``), written out as a full assembly by ``MistunedDisk.from_tuned`` with blade k's
frequencies times kappa_k = 1 + sigma z_k, z_k standard normal and sigma uniform in 1-5 %, both
seeded by ``mistuned_design(i)`` of the suite (its ring size ``--blades``: the suite's own, or
the reference 16). Solved as a user gets it by default (harmonics 'auto', automatic AFT samples),
with the design's range, max_step, MAX_POINTS and ``cpu_budget_s=--budget``, no time check.
Printed per design: CPU seconds, status, points, harmonic set, and every continuation branch the
analysis computed (unknowns, points, corrector calls (failed), residual evaluations, CPU seconds,
where it ended). Run from the repository root; one design at a time.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "benchmarks"), os.path.join(ROOT, "tests")]

import numpy as np  # noqa: E402

from bench_random_cost import BRANCHES, describe, instrument, profiled_response  # noqa: E402
from test_random_designs import make_mistuned, mistuned_design  # noqa: E402


def seeds(text):
    if ":" in text:
        a, b = (int(s) for s in text.split(":"))
        return list(range(a, b))
    return [int(s) for s in text.split(",")]


def solve(seed, budget, blades, profile=None):
    d = mistuned_design(seed, blades)
    t = time.process_time()
    disk = make_mistuned(d)
    build = time.process_time() - t
    r, cpu = profiled_response(disk, d, budget, profile)
    peak = r.tip_amplitude[:, :, 0].max() if len(r.omega) else np.nan
    print(f"seed {seed}: {describe(d)}, {d['n_blades']} blades, mistuning std {100 * d['sigma']:.2f} %")
    print(f"  {cpu:.1f} CPU s (model built in {build:.2f} s), status {r.status.name}, harmonics {r.basis.harmonics}, "
          f"samples {r.basis.n_samples}, {len(r.omega)} points, {len(BRANCHES)} branches, largest blade peak "
          f"{peak * 1e3:.5g} mm, harmonic error {r.harmonic_error:.3g}")
    print(f"  {r.message[:300]}")
    print("  branches: unknowns  points correctors(failed) residuals  CPU s  from->reached Hz  folds  message")
    for b in BRANCHES:
        print(f"   {b['n']:6d} {b['points']:6d} {b['correctors']:7d}({b['failed']:5d}) {b['residuals']:7d} "
              f"{b['cpu']:7.1f}  {b['f0']:.2f}->{b['reach']:.2f} {b['turning']:4d}  {b['message']}")
    sys.stdout.flush()
    return cpu, r.status.name, len(r.omega), len(BRANCHES)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", default="0:10", help="a:b or comma-separated design seeds (mistuned_design(i))")
    p.add_argument("--budget", type=float, default=60.0, help="cpu_budget_s of each frequency_response [s]")
    p.add_argument("--blades", type=int, default=None, help="blades of the ring (default: the suite's own)")
    p.add_argument("--profile", help="write a cProfile of the (single) seed to this file")
    args = p.parse_args()
    instrument()
    rows = []
    for seed in seeds(args.seeds):
        rows.append((seed,) + solve(seed, args.budget, args.blades, args.profile))
    print("\nseed  CPU s  status  points  branches")
    for row in rows:
        print(f"{row[0]:4d} {row[1]:6.1f}  {row[2]}  {row[3]}  {row[4]}")
    cpu = np.array([r[1] for r in rows])
    print(f"CPU s: median {np.median(cpu):.1f}, max {cpu.max():.1f}, total {cpu.sum():.0f}; "
          f"within {args.budget:g} s: {int(np.sum([r[2] != 'OUT_OF_BUDGET' for r in rows]))} of {len(rows)}")


if __name__ == "__main__":
    main()
