"""Cost of the default frequency response of random disks (tests/test_random_designs.py's generator).

    python benchmarks/bench_random_cost.py --seeds 1014,1027 [--budget 60] [--profile out.prof]
    python benchmarks/bench_random_cost.py --list 1000:1080      # EO >= 6 wedges among those seeds, no solve

Each seed is drawn by ``disk_design`` of the random suite (same ranges; the suite's own seeds are
0-159) and solved as ``default_answer`` of the suite solves it, without its two time integrations:
harmonics 'auto', automatic AFT samples, the design's max_step and range, MAX_POINTS, and
``cpu_budget_s=--budget``. Printed per design: the CPU seconds, the status, the peak, and every
continuation branch the analysis computed (harmonic set, AFT samples, direction, points kept,
corrector calls and how many of them failed, residual evaluations, CPU seconds, where it ended).
Run from the repository root; one design at a time (about --budget CPU seconds each at most).
"""
from __future__ import annotations

import argparse
import cProfile
import os
import sys
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]

import numpy as np  # noqa: E402

import bladedamp.hbm.continuation as continuation  # noqa: E402
from test_random_designs import MAX_POINTS, disk_design, make_disk  # noqa: E402

BRANCHES = []


def instrument():
    """Record every ArcLengthContinuation run: its size, points, corrector calls, residuals, CPU."""
    cls = continuation.ArcLengthContinuation
    run, corrector = cls.run, cls.corrector

    def counted_corrector(self, y, tangent, h):
        out = corrector(self, y, tangent, h)
        self.stats["correctors"] += 1
        self.stats["failed"] += not out[0]
        return out

    def counted_run(self):
        self.stats = dict(correctors=0, failed=0, residuals=0)
        fun = self.fun

        def counted(*args):
            self.stats["residuals"] += 1
            return fun(*args)

        self.fun = counted
        t = time.process_time()
        branch = run(self)
        BRANCHES.append(dict(self.stats, n=self.n, points=len(branch.omega), success=branch.success,
                             cpu=time.process_time() - t,
                             f0=self.omega_start / (2 * np.pi), f1=self.omega_end / (2 * np.pi),
                             reach=(branch.omega[-1] / (2 * np.pi) if len(branch.omega) else np.nan),
                             turning=len(branch.turning_points), message=branch.message[:90],
                             omega=branch.omega, scaled=branch.x / self.x_scale, iterations=branch.iterations))
        return branch

    cls.run, cls.corrector = counted_run, counted_corrector


def describe(d):
    return (f"{d['damper']} {d['mass'] * 1e3:.3g} g EO {d['engine_order']} mu {d['mu']:.2f} "
            f"excitation x{d['excitation_scale']:.2f} roughness {d['roughness_exponent']:.2f} "
            f"{d['f_start']:.1f}-{d['f_end']:.1f} Hz")


def profiled_response(disk, d, budget, profile=None):
    """(response, CPU s) of the suite's default FRF of random design ``d`` on ``disk`` within
    ``budget`` CPU s; with ``profile`` (a path) its cProfile statistics are written there.
    BRANCHES is cleared first, so it holds this run's branches after."""
    BRANCHES.clear()
    prof = cProfile.Profile() if profile else None
    t = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if prof:
            prof.enable()
        r = disk.frequency_response(d["f_start"], d["f_end"], max_step=d["max_step"], max_points=MAX_POINTS,
                                    cpu_budget_s=budget)
        if prof:
            prof.disable()
            prof.dump_stats(profile)
    return r, time.process_time() - t


def solve(seed, budget, profile=None):
    d = disk_design(seed)
    disk = make_disk(d)
    r, cpu = profiled_response(disk, d, budget, profile)
    f, a = r.peak() if len(r.omega) else (np.nan, np.nan)
    print(f"seed {seed}: {describe(d)}")
    print(f"  {cpu:.1f} CPU s, status {r.status.name}, harmonics {r.basis.harmonics}, samples {r.basis.n_samples}, "
          f"{len(r.omega)} points, peak {a * 1e3:.5g} mm at {f:.4f} Hz, harmonic error {r.harmonic_error:.3g}")
    print(f"  {r.message}")
    print("  branches: unknowns  points correctors(failed) residuals  CPU s  from->reached Hz  folds  message")
    for b in BRANCHES:
        print(f"   {b['n']:6d} {b['points']:6d} {b['correctors']:7d}({b['failed']:5d}) {b['residuals']:7d} "
              f"{b['cpu']:7.1f}  {b['f0']:.2f}->{b['reach']:.2f} {b['turning']:4d}  {b['message']}")
    sys.stdout.flush()
    return cpu


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", help="comma-separated design seeds (disk_design(i))")
    p.add_argument("--list", help="a:b: print the EO >= 6 wedges among seeds a..b-1 (no solve)")
    p.add_argument("--budget", type=float, default=60.0, help="cpu_budget_s of each frequency_response [s]")
    p.add_argument("--profile", help="write a cProfile of the (single) seed to this file")
    p.add_argument("--dump", help="save every branch's omega, scaled unknowns and iterations of the (single) seed "
                                  "to this .npz file")
    args = p.parse_args()
    if args.list:
        a, b = (int(s) for s in args.list.split(":"))
        for i in range(a, b):
            d = disk_design(i)
            if d["engine_order"] >= 6 and d["damper"] == "wedge":
                print(i, describe(d))
        return
    instrument()
    for seed in (int(s) for s in args.seeds.split(",")):
        solve(seed, args.budget, args.profile)
        if args.dump:
            np.savez(args.dump, **{f"{k}{j}": b[k] for j, b in enumerate(BRANCHES)
                                   for k in ("omega", "scaled", "iterations")})


if __name__ == "__main__":
    main()
