"""Start-up benchmark (issue 15, item 5): import time and the numba compile cost of the first call.

Run from the repository root::

    python benchmarks/bench_startup.py            # about 1 minute on 2 cores
    python benchmarks/bench_startup.py --repeat 3
    python benchmarks/bench_startup.py --compare /path/to/other/checkout   # the same cases there too

Every case is a fresh ``python`` subprocess (so nothing is loaded or compiled in this one), with
``NUMBA_CACHE_DIR`` pointing at a folder of this run, all in the same run:

* ``import bladedamp`` (the package is lazy: numpy, scipy and numba come with the first model);
* the reference disk's FRF (1 g cylinder, 90-102 Hz, the default harmonics) as the first call of
  a process, on an empty cache (numba compiles the kernels it needs), and again in a new process
  on the filled cache (numba only loads them), and the same FRF a second time in that process
  (everything loaded: the FRF's own cost);
* ``bladedamp.precompile()`` on an empty cache (every kernel compiled), then the first FRF in a
  new process on that cache.

The compile cost of the first call is (cold first call) - (warm first call); the load cost is
(warm first call) - (second call). Reported as seconds and as ratios to the FRF's own cost.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

IMPORT = "import time; t = time.perf_counter(); import bladedamp; print(time.perf_counter() - t)"
FRF = """
import json, time, warnings
t0 = time.perf_counter()
import bladedamp as bd
warnings.simplefilter("ignore")
disk = bd.reference_disk("cylinder", 1e-3)
t1 = time.perf_counter()
r = disk.frequency_response(90, 102)
t2 = time.perf_counter()
r2 = disk.frequency_response(90, 102)
t3 = time.perf_counter()
assert r.success and r2.success, (r.message, r2.message)
print(json.dumps({"first": t2 - t1, "second": t3 - t2, "process": t2 - t0,
                  "peak_mm": 1e3 * r.peak_amplitude, "points": len(r.omega)}))
"""
PRECOMPILE = "import time; t = time.perf_counter(); import bladedamp; bladedamp.precompile(None); " \
             "print(time.perf_counter() - t)"


CPU = []      # CPU time [s] (user + system) of each subprocess run, in order


def run(code: str, cache: str, root: str = ROOT):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=root)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    if out.returncode:
        raise RuntimeError(out.stderr[-2000:])
    text = out.stdout.strip().splitlines()[-1]
    return json.loads(text) if text.startswith("{") else float(text)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="repetitions of each case (best kept)")
    parser.add_argument("--compare", metavar="CHECKOUT", default=None,
                        help="also the first call on an empty and on a filled cache of another checkout of "
                             "bladedamp (e.g. a git worktree of an earlier commit), in the same run")
    parser.add_argument("--precompile-only", action="store_true",
                        help="only `bladedamp.precompile()` on an empty cache (and in the --compare checkout, "
                             "alternated), with the process's CPU time")
    args = parser.parse_args(argv)
    if args.precompile_only:
        return precompile_only(args)
    print(f"# bench_startup {datetime.datetime.now():%Y-%m-%d %H:%M}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}")
    rows = {"import": [], "cold": [], "warm": [], "precompile": [], "after": []}
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as cold, tempfile.TemporaryDirectory() as pre:
            rows["import"].append(run(IMPORT, cold))
            rows["cold"].append(run(FRF, cold))               # empty cache: compiles
            rows["warm"].append(run(FRF, cold))               # filled by the run before
            rows["precompile"].append(run(PRECOMPILE, pre))   # empty cache: compiles every kernel
            rows.setdefault("precompile cpu", []).append(CPU[-1])
            rows["after"].append(run(FRF, pre))
        if args.compare:
            with tempfile.TemporaryDirectory() as other:
                rows.setdefault("other cold", []).append(run(FRF, other, args.compare))
                rows.setdefault("other warm", []).append(run(FRF, other, args.compare))
    cold = min(r["first"] for r in rows["cold"])
    warm = min(r["first"] for r in rows["warm"])
    after = min(r["first"] for r in rows["after"])
    own = min(r["second"] for r in rows["warm"] + rows["after"])
    print(f"import bladedamp                         {min(rows['import']):7.3f} s")
    print(f"reference FRF, its own cost (2nd call)  {own:7.2f} s   ({rows['warm'][0]['points']} points, "
          f"peak {rows['warm'][0]['peak_mm']:.4f} mm)")
    print(f"first call, empty cache                 {cold:7.2f} s   = {cold / own:.2f} x its own cost")
    print(f"first call, filled cache                {warm:7.2f} s   = {warm / own:.2f} x")
    print(f"  compile cost of the first call        {cold - warm:7.2f} s")
    print(f"  load cost (cache, scipy, first use)   {warm - own:7.2f} s")
    print(f"bladedamp.precompile(), empty cache     {min(rows['precompile']):7.2f} s   "
          f"({min(rows['precompile cpu']):.2f} s CPU, the whole process)")
    print(f"first call after precompile            {after:7.2f} s   = {after / own:.2f} x")
    if args.compare:
        o_cold = min(r["first"] for r in rows["other cold"])
        o_warm = min(r["first"] for r in rows["other warm"])
        o_own = min(r["second"] for r in rows["other warm"])
        print(f"{args.compare}: first call empty cache {o_cold:.2f} s, filled {o_warm:.2f} s, own cost {o_own:.2f} s; "
              f"compile cost {o_cold - o_warm:.2f} s against {cold - warm:.2f} s here")


def precompile_only(args):
    """`bladedamp.precompile()` on an empty cache, here and (alternated) in the --compare checkout:
    wall time inside the process and the process's CPU time (import, compilation, the tiny runs)."""
    print(f"# bench_startup --precompile-only {datetime.datetime.now():%Y-%m-%d %H:%M}, "
          f"{os.cpu_count()} cores, uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    roots = [("this checkout", ROOT)] + ([("compare", args.compare)] if args.compare else [])
    cpu = {name: [] for name, _ in roots}
    for _ in range(args.repeat):
        for name, root in roots:
            with tempfile.TemporaryDirectory() as cache:
                wall = run(PRECOMPILE, cache, root)
            cpu[name].append(CPU[-1])
            print(f"{name:14s} precompile, empty cache: {wall:6.2f} s wall, {CPU[-1]:6.2f} s CPU", flush=True)
    for name, _ in roots:
        print(f"{name:14s} best {min(cpu[name]):6.2f} s CPU, median {sorted(cpu[name])[len(cpu[name]) // 2]:6.2f} s")
    if args.compare:
        print(f"ratio this / compare (best CPU): {min(cpu['this checkout']) / min(cpu['compare']):.2f}")
    print(f"# uptime at the end: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")


if __name__ == "__main__":
    main()
