"""Mistuned-disk benchmark: full 16-blade assembly vs the tuned cyclic sector, the accuracy of
the Monte Carlo settings, and Monte Carlo throughput on Dask.

Run from the repository root::

    python benchmarks/bench_mistuned.py                 # ~3 minutes on 2 cores
    python benchmarks/bench_mistuned.py --quick         # cost ratio only
    python benchmarks/bench_mistuned.py --disks 24      # Monte Carlo disks per worker count

1. Cost ratio (issue target <= 25): the reference disk (cylinder 1 g, EO = 1, F_x = 0.1 N,
   harmonics (1,), 64 samples) over 92-104 Hz with max_step 0.05, as the cyclic TunedDisk and
   as the tuned full 16-blade MistunedDisk (same configuration, 16x the unknowns), best of
   ``--repeat`` runs after a warm-up, in the same process. Also a 2 % randomly mistuned
   assembly (seed 2) over its own range, for reference. Ratios per FRF and per branch point.
2. Accuracy of the Monte Carlo (its coarse branch, MONTE_CARLO_MAX_STEP, MONTE_CARLO_TOL, and
   the peaks solved within MONTE_CARLO_PEAK_MARGIN, run as ``monte_carlo(scheduler="serial")``)
   against fine FRFs (max_step 0.05, tol 1e-10) on ``--accuracy`` random disks (2 %, seed 11):
   the largest blade peak (what the amplification uses) and every blade's peak; time per disk.
   ``--compare TREE``: the same disks timed with another checkout's ``monte_carlo`` (e.g. a
   worktree of main) against this one, each in its own process (imports and numba caches warmed
   up first), alternately TREE, this, this, TREE so that a load that drifts weighs on both alike;
   per-disk times (serial, without the harmonic error estimate) and both trees' accuracy; then
   both trees' Monte Carlo of the ``--disks`` disks on 1 and 2 local workers, in the same order.
3. Monte Carlo throughput (target speed-up >= 1.7 on 2 cores): the same ``--disks`` random
   disks (2 %, seed 0) on a local Dask cluster with 1 and 2 worker processes (one thread each).
   Each cluster is started and its workers warmed up (one disk each: imports, numba caches)
   before the clock starts; the tuned peak is computed once beforehand. Disks per minute,
   speed-up, and the time extrapolated to 1000 disks (issue: < 10 min on 2 cores); the
   1000-disk run itself is ``bladedamp montecarlo --disks 1000`` (see README.md).
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import time

import numpy as np

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from _timing import best_of, solved_response  # noqa: E402
from bladedamp.mistuned import MistunedDisk  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402
from bladedamp.studies import mistuning as mt  # noqa: E402

F_RANGE = (92.0, 104.0)
MAX_STEP = 0.05


def timed(fun, repeat):
    fun()                                  # warm-up (numba caches, imports)
    return best_of(fun, repeat)


def frf(disk, f_range=F_RANGE):
    return lambda: solved_response(disk, f_range, MAX_STEP)


def cost_ratio(repeat):
    disk = reference_disk("cylinder", 1e-3)
    t_c, r_c = timed(frf(disk), repeat)
    t_f, r_f = timed(frf(MistunedDisk.from_tuned(disk)), repeat)
    kappa = mt.random_kappa(16, 0.02, seed=2)
    t_m, r_m = timed(frf(MistunedDisk.from_tuned(disk, kappa), mt.auto_range(disk, kappa)), 1)
    n_c, n_f, n_m = len(r_c.omega), len(r_f.omega), len(r_m.omega)
    print(f"cyclic tuned sector      : {t_c:7.3f} s, {n_c:4d} points, {1e3 * t_c / n_c:6.2f} ms/point, "
          f"peak {1e3 * r_c.peak_amplitude:.5f} mm")
    print(f"full tuned 16 blades     : {t_f:7.3f} s, {n_f:4d} points, {1e3 * t_f / n_f:6.2f} ms/point, "
          f"peak {1e3 * r_f.peak_amplitude:.5f} mm")
    print(f"full mistuned 16 (2 %)   : {t_m:7.3f} s, {n_m:4d} points, {1e3 * t_m / n_m:6.2f} ms/point "
          f"({mt.auto_range(disk, kappa)[0]:.1f}-{mt.auto_range(disk, kappa)[1]:.1f} Hz)")
    print(f"cost ratio full / cyclic : {t_f / t_c:6.1f} per FRF (target <= 25), "
          f"{(t_f / n_f) / (t_c / n_c):6.1f} per point")
    return t_f / t_c


def accuracy(n_disks):
    """The Monte Carlo's peaks (coarse branch + solved peaks, exactly as ``monte_carlo``) against
    fine FRFs (max_step 0.05, tol 1e-10, parabola-refined peaks) on the random disks of seed 11."""
    disk = reference_disk("cylinder", 1e-3)
    mt.monte_carlo(disk, 1, seed=99, scheduler="serial", tuned_peak_amplitude=1.0)         # warm-up
    t = time.perf_counter()
    fast = mt.monte_carlo(disk, n_disks, seed=11, scheduler="serial", tuned_peak_amplitude=1.0)
    t_fast = time.perf_counter() - t
    worst_max, worst_blade, worst_old, t_fine, t_old, t_new = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for i, kappa in enumerate(fast.kappa):
        t = time.perf_counter()
        fine = mt.mistuned_response(disk, kappa, max_step=0.05, tol=1e-10, estimate_harmonic_error=False)
        t_fine += time.perf_counter() - t
        # the same disk the way monte_carlo did it before issue 15 item 4 (Newton corrector,
        # max_step 0.1, 3 % range margin, parabola peaks), and the new way, both without the
        # harmonic error estimate (the study's disk 0 only)
        t = time.perf_counter()
        old = mt.mistuned_response(disk, kappa, max_step=0.1, tol=1e-6, estimate_harmonic_error=False).peaks()[0]
        t_old += time.perf_counter() - t
        t = time.perf_counter()
        mt.mistuned_response(disk, kappa, max_step=mt.MONTE_CARLO_MAX_STEP, tol=mt.MONTE_CARLO_TOL, chord=True,
                             target_iterations=mt.MONTE_CARLO_TARGET_ITERATIONS,
                             range_margin=mt.MONTE_CARLO_RANGE_MARGIN,
                             estimate_harmonic_error=False).peaks(solve_within=mt.MONTE_CARLO_PEAK_MARGIN)
        t_new += time.perf_counter() - t
        worst_old = max(worst_old, abs(old.max() / fine.peak_amplitude - 1))
        worst_max = max(worst_max, abs(fast.peak_amplitude[i].max() / fine.peak_amplitude - 1))
        worst_blade = max(worst_blade, np.abs(fast.peak_amplitude[i] / fine.blade_peak_amplitudes - 1).max())
    print(f"Monte Carlo settings (max_step {mt.MONTE_CARLO_MAX_STEP}, tol {mt.MONTE_CARLO_TOL:g}, peaks solved "
          f"within {mt.MONTE_CARLO_PEAK_MARGIN:g}) vs fine FRFs (0.05, 1e-10), {n_disks} disks, failed "
          f"{int((~fast.valid).sum())}: largest peak per disk within {worst_max:.1e}, every blade's peak within "
          f"{worst_blade:.1e}; {t_fast / n_disks:.3f} (disk 0 with the harmonic error estimate) vs "
          f"{t_fine / n_disks:.3f} s per disk (serial)")
    print(f"per disk, serial, same disks: before {t_old / n_disks:.3f} s (largest peak within {worst_old:.1e}), "
          f"now {t_new / n_disks:.3f} s: {t_old / t_new:.2f}x less")
    return worst_max


#: run in a fresh process with PYTHONPATH = the tree timed: argv (seed, disks); prints JSON with
#: the serial Monte Carlo's per-disk wall time (without disk 0's harmonic error estimate: every
#: disk the same path) and every disk's blade peaks
TIME_DISKS = '''
import json, sys, time
from bladedamp.reference import reference_disk
from bladedamp.studies import mistuning as mt
mt._disk_settings = lambda settings, i: dict(settings, estimate_harmonic_error=False)
disk = reference_disk("cylinder", 1e-3)
mt.monte_carlo(disk, 1, seed=99, scheduler="serial", tuned_peak_amplitude=1.0)      # warm-up
seed, n = int(sys.argv[1]), int(sys.argv[2])
cpu = time.process_time()
r = mt.monte_carlo(disk, n, seed=seed, scheduler="serial", tuned_peak_amplitude=1.0)
print(json.dumps({"per_disk_s": r.meta["elapsed_s"] / n, "cpu_per_disk_s": (time.process_time() - cpu) / n,
                  "peaks": r.peak_amplitude.tolist()}))
'''


def time_disks(tree, seed, n_disks):
    """(per-disk wall time [s], per-disk CPU time of the process [s], (n_disks, n) peaks [m]) of
    ``tree``'s serial Monte Carlo in a new process. The CPU time is the measure that holds on a
    loaded machine (the other processes' share of the cores is not in it)."""
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
    out = subprocess.run([sys.executable, "-c", TIME_DISKS, str(seed), str(n_disks)], env=env, check=True,
                         capture_output=True, text=True, cwd=os.path.abspath(tree)).stdout
    result = json.loads(out.strip().splitlines()[-1])
    return result["per_disk_s"], result["cpu_per_disk_s"], np.array(result["peaks"])


def compare(tree, n_disks, seed=11):
    """Per-disk time and accuracy of ``tree``'s Monte Carlo against this checkout's, the same
    disks (seed 11, as :func:`accuracy`), in the order tree, this, this, tree."""
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    times, cpu, peaks = {tree: [], here: []}, {tree: [], here: []}, {}
    for which in (tree, here, here, tree):
        t, c, p = time_disks(which, seed, n_disks)
        times[which].append(t)
        cpu[which].append(c)
        peaks[which] = p
    disk = reference_disk("cylinder", 1e-3)
    kappas = [mt.random_kappa(16, 0.02, seed=[seed, i]) for i in range(n_disks)]
    fine = np.array([mt.mistuned_response(disk, k, max_step=0.05, tol=1e-10, estimate_harmonic_error=False)
                     .blade_peak_amplitudes for k in kappas])
    for name, which in (("compared", tree), ("this tree", here)):
        worst = np.abs(peaks[which].max(axis=1) / fine.max(axis=1) - 1).max()
        print(f"{name:10s} ({os.path.abspath(which)}): wall {' / '.join(f'{t:.3f}' for t in times[which])}, CPU "
              f"{' / '.join(f'{t:.3f}' for t in cpu[which])} s per disk (serial, {n_disks} disks, two runs); "
              f"largest peak within {worst:.1e} of the fine FRF")
    same = np.abs(peaks[here].max(axis=1) / peaks[tree].max(axis=1) - 1).max()
    print(f"the two trees' largest peaks per disk differ by at most {same:.1e} (relative)")
    ratios = {}
    for name, measure in (("wall", times), ("CPU", cpu)):
        old, new = np.mean(measure[tree]), np.mean(measure[here])
        ratios[name] = old / new
        print(f"per disk, serial, same disks, one run ({name}): compared {old:.3f} s, this tree {new:.3f} s: "
              f"{old / new:.2f}x less (run by run: {measure[tree][0] / measure[here][0]:.2f}, "
              f"{measure[tree][1] / measure[here][1]:.2f})")
    return ratios


#: run in a fresh process with PYTHONPATH = the tree timed: argv (workers, disks); prints JSON
#: with the wall time of ``monte_carlo`` on a local cluster of that many workers (started with
#: monte_carlo's worker settings and warmed up, one disk each, before the clock starts) and the
#: CPU time its worker processes spent meanwhile (what holds on a loaded machine)
TIME_CLUSTER = '''
import json, sys, time
from dask.distributed import Client, LocalCluster
from bladedamp.reference import reference_disk
from bladedamp.studies import mistuning as mt
if __name__ == "__main__":
    workers, n = int(sys.argv[1]), int(sys.argv[2])
    disk = reference_disk("cylinder", 1e-3)
    with mt.local_worker_config():
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    with cluster, Client(cluster) as client:
        mt.monte_carlo(disk, workers, seed=99, scheduler=cluster.scheduler_address, tuned_peak_amplitude=1.0)
        cpu = sum(client.run(time.process_time).values())
        t = time.perf_counter()
        r = mt.monte_carlo(disk, n, seed=0, scheduler=cluster.scheduler_address, tuned_peak_amplitude=1.0)
        wall = time.perf_counter() - t
        cpu = sum(client.run(time.process_time).values()) - cpu
        print(json.dumps({"wall_s": wall, "worker_cpu_s": cpu, "amplification": r.amplification.tolist()}))
'''


def compare_throughput(tree, n_disks):
    """Wall time of ``tree``'s Monte Carlo against this checkout's on 1 and 2 local workers, the
    same ``n_disks`` disks (seed 0), each run in its own process, in the order tree, this, this,
    tree for each worker count."""
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    script = os.path.join(os.environ.get("TMPDIR", "/tmp"), "bench_mistuned_cluster.py")
    with open(script, "w") as f:
        f.write(TIME_CLUSTER)            # a file: the workers are spawned processes that import __main__
    for workers in (1, 2):
        walls, cpus, amplification = {tree: [], here: []}, {tree: [], here: []}, {}
        for which in (tree, here, here, tree):
            env = dict(os.environ, PYTHONPATH=os.path.abspath(which))
            out = subprocess.run([sys.executable, script, str(workers), str(n_disks)], env=env, check=True,
                                 capture_output=True, text=True, cwd=os.path.abspath(which)).stdout
            result = json.loads(out.strip().splitlines()[-1])
            walls[which].append(result["wall_s"])
            cpus[which].append(result["worker_cpu_s"] / n_disks)
            amplification[which] = np.array(result["amplification"])
        old, new = np.mean(walls[tree]), np.mean(walls[here])
        same = np.abs(amplification[here] / amplification[tree] - 1).max()
        print(f"Monte Carlo {n_disks} disks, {workers} worker(s), load {os.getloadavg()[0]:.1f}: wall compared "
              f"{' / '.join(f'{t:.1f}' for t in walls[tree])} s, this tree {' / '.join(f'{t:.1f}' for t in walls[here])} s: "
              f"{old / new:.2f}x less ({n_disks / new * 60:.0f} against {n_disks / old * 60:.0f} disks/min); workers' CPU "
              f"per disk {np.mean(cpus[tree]):.3f} against {np.mean(cpus[here]):.3f} s: "
              f"{np.mean(cpus[tree]) / np.mean(cpus[here]):.2f}x less; amplifications equal to {same:.1e}")


def throughput(n_disks):
    from dask.distributed import Client, LocalCluster

    disk = reference_disk("cylinder", 1e-3)
    tuned = mt.tuned_peak(disk, mt.auto_range(disk, [1.0], 0.05))[0]
    times = {}
    for workers in (1, 2):
        with mt.local_worker_config():      # the workers monte_carlo's own local cluster starts
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        with cluster, Client(cluster) as client:
            warm = [client.submit(mt.mistuned_response, disk, mt.random_kappa(16, 0.02, seed=[99, w]),
                                  max_step=mt.MONTE_CARLO_MAX_STEP, tol=mt.MONTE_CARLO_TOL, chord=True,
                                  estimate_harmonic_error=False, pure=False, workers=[addr])
                    for w, addr in enumerate(client.scheduler_info()["workers"])]
            client.gather(warm)
            t = time.perf_counter()
            res = mt.monte_carlo(disk, n_disks, seed=0, scheduler=cluster.scheduler_address, tuned_peak_amplitude=tuned)
            times[workers] = time.perf_counter() - t
        print(f"Monte Carlo {n_disks} disks, {workers} worker(s): {times[workers]:7.1f} s "
              f"({60 * n_disks / times[workers]:.1f} disks/min, {times[workers] / n_disks:.2f} s/disk), "
              f"mean amplification {res.amplification.mean():.4f}, failed {int((~res.valid).sum())}")
    speedup = times[1] / times[2]
    per_disk_2 = times[2] / n_disks
    print(f"speed-up 2 vs 1 worker   : {speedup:.2f} (target >= 1.7)")
    print(f"1000 disks on 2 workers  : ~{1000 * per_disk_2 / 60:.1f} min extrapolated (target < 10 min)")
    return speedup


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="cost ratio only, one repetition")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--disks", type=int, default=24, help="Monte Carlo disks per worker count")
    parser.add_argument("--accuracy", type=int, default=16, help="disks for the accuracy check (0: skip)")
    parser.add_argument("--compare", metavar="TREE", help="another checkout (e.g. a worktree of main): its "
                        "Monte Carlo's per-disk time and accuracy against this one's on the --accuracy disks")
    parser.add_argument("--compare-only", action="store_true", help="with --compare: only that comparison")
    args = parser.parse_args(argv)
    print(f"# bench_mistuned {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}")
    if args.compare:
        compare(args.compare, args.accuracy or 16)
        compare_throughput(args.compare, args.disks)
        if args.compare_only:
            return
    cost_ratio(1 if args.quick else args.repeat)
    if not args.quick:
        if args.accuracy:
            accuracy(args.accuracy)
        throughput(args.disks)


if __name__ == "__main__":
    main()
