"""Mistuned full assembly: cost of an FRF point against the number of blades n, with the old
linear solver (damper condensation + dense LU of the blades' Schur complement for dense
Jacobians, sparse LU above ``AssemblySystem.dense_limit`` unknowns) and the O(n) ring solver
(:class:`bladedamp.hbm.linsolve.BlockRing`), in one run (issue 15, item 1).

Run from the repository root::

    python benchmarks/bench_mistuned_scaling.py                # ~4-5 minutes on 2 cores
    python benchmarks/bench_mistuned_scaling.py --blades 8 16 32 --old-full-max 32

The disk: the reference cylinder damper (1 g), EO = 1, 2 % random mistuning (seed 0) on n
blades, harmonics (1,) with the default samples (64 at every n; each damper on its own shifted grid),
88-102 Hz, max_step 0.05. Timed: the continuation alone (start solution and scales before the
clock), ms per branch point = wall time / points; "solver" is the part of it spent in
factorize and its solves. Up to ``--old-full-max`` blades both solvers run the whole range
``--repeat`` times in alternating order, the best run of each is kept and the branches are
compared point by point; above it the old solver's whole range would take
minutes per n, so old and new both run the first ``--capped-points`` points from 88 Hz
(off resonance: fewer corrector iterations than the average point) and the ratio is taken
there. Before the timed runs at each n, both solvers run 3 points (warm-up at that matrix
size). Then the factorisation of the bordered Jacobian alone at small n (the crossover).
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import os
import platform
import sys
import time
import warnings

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import numpy as np  # noqa: E402

from bladedamp.hbm.continuation import bordered_matrix, continuation  # noqa: E402
from bladedamp.hbm.linsolve import one_blas_thread  # noqa: E402
from bladedamp.mistuned import MistunedDisk  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402
from bladedamp.studies import mistuning as mt  # noqa: E402

F_RANGE = (88.0, 102.0)
MAX_STEP = 0.05
HARMONICS = (1,)
OLD, NEW = "condensation", "ring"


def disk_of(n):
    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=n)
    return MistunedDisk.from_tuned(disk, mt.random_kappa(n, 0.02, seed=0))


def timed_factorize(factorize, clock):
    """``factorize`` whose factorisations and solves add their wall time to clock[0]."""
    def wrapped(A):
        t = time.perf_counter()
        inner = factorize(A)
        clock[0] += time.perf_counter() - t

        def solve(b):
            t = time.perf_counter()
            y = inner(b)
            clock[0] += time.perf_counter() - t
            return y

        solve.__dict__.update(getattr(inner, "__dict__", {}))     # sign, logabsdet, method
        return solve
    return wrapped


@one_blas_thread
def run(md, solver, max_points=5000, sparse=False):
    """(wall time [s], time in the linear solver [s], branch, system) of the continuation;
    ``sparse``: sparse Jacobians at every size (the continuation then computes no det sign)."""
    system = md.hbm_system(HARMONICS, linear_solver=solver)
    if sparse:
        system.dense = False
    w0, w1 = 2 * np.pi * F_RANGE[0], 2 * np.pi * F_RANGE[1]
    scales = md.scales(system, w0, w1)
    x0 = md.start_solution(system, w0, scales)
    clock = [0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        branch = continuation(system.residual, x0, w0, w1, x_scale=scales, max_step=MAX_STEP,
                              factorize=timed_factorize(system.factorize, clock), max_points=max_points)
        wall = time.perf_counter() - t
    return wall, clock[0], branch, system


def scaling(blades, old_full_max, capped_points, new_sparse=False, repeat=2):
    print(f"{'n':>4} {'unknowns':>8} {'J':>6} {'T':>4} {'points':>6} | {'old ms/pt':>9} {'new ms/pt':>9} "
          f"{'old/new':>7} | {'old solver':>10} {'new solver':>10} | note")
    rows = {}
    for n in blades:
        md = disk_of(n)
        for solver in (OLD, NEW):
            # warm-up at this size: the first run at a new matrix size pays for fresh pages
            # (glibc raises its mmap threshold only after freeing a larger block; measured at 32
            # blades: ~1900 minor page faults per point, +25 % wall time, then ~15)
            run(md, solver, 3, sparse=new_sparse and solver == NEW)
        if n <= old_full_max:
            # best of ``repeat`` whole-range runs of each, in alternating order
            best = {}
            for r in range(repeat):
                for solver in ((OLD, NEW) if r % 2 == 0 else (NEW, OLD)):
                    out = run(md, solver, sparse=new_sparse and solver == NEW)
                    if solver not in best or out[0] < best[solver][0]:
                        best[solver] = out
            t_new, s_new, b_new, system = best[NEW]
            t_old, s_old, b_old, _ = best[OLD]
        else:
            t_new, s_new, b_new, system = run(md, NEW, sparse=new_sparse)
        J = "dense" if system.dense else "sparse"
        points = len(b_new.omega)
        if n <= old_full_max:
            same = len(b_old.omega) == points
            diff = (np.abs(b_old.x - b_new.x).max() / np.abs(b_old.x).max()) if same else np.inf
            note = f"whole range; branches {'equal to ' + format(diff, '.0e') if same else 'DIFFER'}"
            old_pp, new_pp, sold_pp, snew_pp = t_old / len(b_old.omega), t_new / points, s_old / len(b_old.omega), s_new / points
            ratio = old_pp / new_pp
        else:
            t_oc, s_oc, b_oc, _ = run(md, OLD, capped_points)
            t_nc, s_nc, b_nc, _ = run(md, NEW, capped_points)
            k = len(b_oc.omega)
            note = f"old: first {k} points only; old/new over those {k} points"
            old_pp, new_pp, sold_pp, snew_pp = t_oc / k, t_new / points, s_oc / k, s_new / points
            ratio = (t_oc / k) / (t_nc / len(b_nc.omega))
        rows[n] = new_pp, old_pp
        ok = "" if b_new.success else f"; new branch FAILED: {b_new.message}"
        print(f"{n:4d} {system.n_unknowns:8d} {J:>6} {system.basis.n_samples:4d} {points:6d} | {1e3 * old_pp:9.2f} "
              f"{1e3 * new_pp:9.2f} {ratio:7.1f} | {1e3 * sold_pp:10.2f} {1e3 * snew_pp:10.2f} | {note}{ok}", flush=True)
    if 16 in rows:
        ref_new, ref_old = rows[16]
        print("\ntime per point relative to n = 16 (new solver; old solver, capped where marked above):")
        for n, (new_pp, old_pp) in rows.items():
            print(f"  n = {n:3d}: new {new_pp / ref_new:6.2f}x   old {old_pp / ref_old:6.2f}x")
        if 128 in rows:
            r = rows[128][0] / ref_new
            print(f"issue target, new solver: t(128) / t(16) = {r:.2f} (<= 10: {'met' if r <= 10 else 'NOT met'})")


def crossover(blades, repeat=20):
    """Factorise + one solve of the bordered Jacobian at 95 Hz, best of 5 x ``repeat``."""
    print("\nbordered Jacobian, factorise + solve [ms] (best of 5 x %d):" % repeat)
    print(f"{'n':>4} {'unknowns':>8} {'condensation':>12} {'ring':>8} {'ratio':>6}")
    for n in blades:
        md = disk_of(n)
        system = md.hbm_system(HARMONICS)
        w = 2 * np.pi * 95.0
        R, J, Rw = system.residual(md.initial_guess(system, w), w)
        A = bordered_matrix(J, Rw, np.random.default_rng(0).standard_normal(J.shape[0] + 1), np.ones(J.shape[0]), 1.0)
        rhs = np.ones(A.shape[0])
        best = {}
        for solver in (OLD, NEW):
            system.linear_solver = solver
            system.factorize(A)(rhs)
            t = []
            for _ in range(5):
                t0 = time.perf_counter()
                for _ in range(repeat):
                    system.factorize(A)(rhs)
                t.append((time.perf_counter() - t0) / repeat)
            best[solver] = min(t)
        print(f"{n:4d} {system.n_unknowns:8d} {1e3 * best[OLD]:12.3f} {1e3 * best[NEW]:8.3f} "
              f"{best[OLD] / best[NEW]:6.2f}", flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--blades", type=int, nargs="+", default=[8, 16, 32, 64, 128, 256])
    parser.add_argument("--old-full-max", type=int, default=64,
                        help="largest n at which the old solver runs the whole range")
    parser.add_argument("--capped-points", type=int, default=15,
                        help="points of the old/new comparison above --old-full-max")
    parser.add_argument("--repeat", type=int, default=2,
                        help="whole-range runs of each solver up to --old-full-max blades (best taken)")
    parser.add_argument("--new-sparse", action="store_true",
                        help="the new solver with sparse Jacobians at every n (what the continuation could do "
                             "once it takes the det sign from solve.sign; it computes none for sparse J today)")
    parser.add_argument("--crossover", type=int, nargs="*", default=[2, 4, 8, 16],
                        help="blades of the factorisation-only comparison (none: skip)")
    args = parser.parse_args(argv)
    print(f"# bench_mistuned_scaling {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"# cylinder 1 g, EO 1, 2 % mistuning (seed 0), harmonics {HARMONICS}, {F_RANGE[0]}-{F_RANGE[1]} Hz, "
          f"max_step {MAX_STEP}; old = {OLD!r} (sparse LU for sparse J), new = {NEW!r}")
    run(disk_of(4), NEW, 5)                     # warm-up: imports, numba caches
    run(disk_of(4), OLD, 5)
    if args.new_sparse:
        print("# --new-sparse: the new solver's Jacobians are sparse at every n (no det sign in the continuation)")
    scaling(args.blades, args.old_full_max, args.capped_points, args.new_sparse, args.repeat)
    if args.crossover:
        crossover(args.crossover)
    print(f"# done, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
