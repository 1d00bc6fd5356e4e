"""Tuned-disk benchmark: the reference FRF over the 1F resonance for both dampers.

Run from the repository root::

    python benchmarks/bench_disk.py              # ~1 minute on 2 cores
    python benchmarks/bench_disk.py --quick      # one repetition, no profile
    python benchmarks/bench_disk.py --profile 25 # also print the 25 top cProfile entries

Cases (reference disk, EO = 1, F_x = 0.1 N, default patch resolution: cylinder 5 points,
wedge 5 x 5 points per contact, harmonics (1,), 64 time samples):

* cylinder 1 g (the paper's optimum), wedge 0.28 g (near the wedge's optimum);
* the same blade without a damper (linear) over the same range.

Each FRF runs 92-104 Hz by arc-length continuation with ``max_step`` chosen so that the branch
has at least 200 points; the point count is reported. Times are the best of ``--repeat`` runs
after a warm-up (numba functions compiled and cached). The ratio to the linear FRF is taken
per point (the linear branch has its own point count; its time is scaled to the damper's
count), all measured in the same run. Issue targets: cylinder < 1 s, wedge < 3 s (issue 4); cylinder < 0.5 s, wedge < 1 s (issue 15, item 2).
"""
from __future__ import annotations

import argparse
import cProfile
import datetime
import os
import platform
import pstats
import sys

# small dense matrices: BLAS threads only add synchronisation (same setting as bench_engine.py)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from _timing import best_of, solved_response  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402

F_RANGE = (92.0, 104.0)
MIN_POINTS = 200
TARGETS = {"cylinder": 0.5, "wedge": 1.0}      # issue 15, item 2 (issue 4 had 1 s and 3 s)
CASES = [("linear", None, 0.0), ("cylinder", "cylinder", 1.0e-3), ("wedge", "wedge", 0.28e-3)]


def run(disk, max_step):
    return solved_response(disk, F_RANGE, max_step)


def step_for(disk, min_points):
    """Largest max_step (from 0.05 down by factors 0.8) giving at least ``min_points`` points."""
    step = 0.05
    while True:
        n = len(run(disk, step).omega)
        if n >= min_points:
            return step, n
        step *= 0.8



def profile(disk, max_step, top):
    pr = cProfile.Profile()
    pr.enable()
    run(disk, max_step)
    pr.disable()
    stats = pstats.Stats(pr)
    total = stats.total_tt
    rows = sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:top]   # by own time
    out = []
    for (fname, line, func), (cc, nc, tt, ct, _) in rows:
        where = f"{os.path.relpath(fname, os.getcwd()) if fname.startswith('/') else fname}:{line}({func})"
        out.append((where, nc, tt, ct, tt / total))
    return total, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one repetition, no profile")
    ap.add_argument("--profile", type=int, default=12, help="top entries of the cProfile (0: none)")
    args = ap.parse_args(argv)
    repeat = 1 if args.quick else args.repeat

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"bench_disk  {datetime.datetime.now():%Y-%m-%d %H:%M}  python {platform.python_version()}  "
          f"numpy {np.__version__}  {platform.machine()}  cpus {os.cpu_count()}  "
          f"BLAS threads {os.environ['OPENBLAS_NUM_THREADS']}  load {load:.2f}")
    disks = {name: reference_disk(kind, mass) for name, kind, mass in CASES}
    run(disks["wedge"], 0.05)   # warm-up: numba cache load, imports
    results = {}
    for name, kind, mass in CASES:
        step, _ = step_for(disks[name], MIN_POINTS)
        t, r = best_of(lambda: run(disks[name], step), repeat)
        results[name] = dict(step=step, n=len(r.omega), t=t, peak=r.peak_amplitude,
                             f=r.peak_frequency_hz, iters=float(np.mean(r.iterations)))
    lin = results["linear"]
    per_point_lin = lin["t"] / lin["n"]
    header = f"{'case':<24}{'max_step':>9}{'points':>8}{'Newton it':>10}{'time [s]':>10}{'ms/point':>10}" \
             f"{'x linear':>10}{'target [s]':>11}{'peak [mm]':>11}{'f_res [Hz]':>11}"
    print()
    print(header)
    print("-" * len(header))
    for name, kind, mass in CASES:
        res = results[name]
        label = "no damper (linear)" if kind is None else f"{kind} {mass * 1e3:g} g"
        ratio = res["t"] / (per_point_lin * res["n"])
        target = TARGETS.get(name)
        tgt = "" if target is None else f"{target:.1f} {'ok' if res['t'] < target else 'MISS'}"
        print(f"{label:<24}{res['step']:>9.4f}{res['n']:>8d}{res['iters']:>10.2f}{res['t']:>10.3f}"
              f"{1e3 * res['t'] / res['n']:>10.2f}{ratio:>10.1f}{tgt:>11}{1e3 * res['peak']:>11.5f}{res['f']:>11.3f}")
    if args.quick or args.profile <= 0:
        return results
    for name in ("cylinder", "wedge"):
        total, rows = profile(disks[name], results[name]["step"], args.profile)
        print(f"\ncProfile {name} ({results[name]['n']} points, {total:.2f} s under the profiler), by own time:")
        print(f"{'own [s]':>9}{'share':>7}{'cum [s]':>9}{'calls':>9}  function")
        for where, nc, tt, ct, share in rows:
            print(f"{tt:>9.3f}{share:>7.1%}{ct:>9.3f}{nc:>9d}  {where}")
    return results


if __name__ == "__main__":
    main()
