"""`bladedamp reproduce` benchmark: the time of each study and of the whole run (one run).

Run from the repository root::

    python benchmarks/bench_reproduce.py                      # the full run, every core
    python benchmarks/bench_reproduce.py --processes 1        # one worker process
    python benchmarks/bench_reproduce.py --compare tests/data/reproduce_summary.json
    python benchmarks/bench_reproduce.py --summary OUT/summary.json --compare OLD/summary.json

It runs :func:`bladedamp.reproduce.reproduce` once into ``--out`` (default a temporary folder) and
prints the time of each study (summary.json's ``timings_s``, wall-clock seconds) with its share
of the total, and the load average before and after (the machine is shared: compare the times
of one run with each other, not with another run's). ``--summary`` reads the timings of an
existing run instead of running. ``--compare`` also lists every number of the summary that
differs from the given summary.json by more than ``--rtol`` (relative; default 1e-3) and every
verdict of the report that changed.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

SKIPPED_KEYS = {"timings_s", "message", "solve_s", "seconds"}   # run-dependent, not results


def numbers(tree, path=""):
    """{path: value} of every number (bool included) in a JSON tree, except ``SKIPPED_KEYS``."""
    out = {}
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k not in SKIPPED_KEYS:
                out.update(numbers(v, f"{path}/{k}"))
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            out.update(numbers(v, f"{path}[{i}]"))
    elif isinstance(tree, (bool, int, float)) or tree is None:
        out[path] = tree
    return out


def compare(new: dict, old: dict, rtol: float) -> list[str]:
    """Lines naming every number of ``new`` that differs from ``old`` beyond ``rtol`` (relative
    to the larger magnitude), missing on one side, or a bool that flipped, and every changed
    verdict of the report."""
    from bladedamp.report import reproduce_report, verdict_rows

    a, b = numbers(new), numbers(old)
    lines, worst = [], (0.0, "")
    for key in sorted(a.keys() | b.keys()):
        x, y = a.get(key, "missing"), b.get(key, "missing")
        if isinstance(x, bool) or isinstance(y, bool) or not all(isinstance(v, (int, float)) for v in (x, y)):
            if x != y:
                lines.append(f"  {key}: {y} -> {x}")
            continue
        d = abs(x - y) / max(abs(x), abs(y), 1e-300)
        if d > worst[0]:
            worst = (d, key)
        if d > rtol:
            lines.append(f"  {key}: {y:.6g} -> {x:.6g} (relative {d:.2e})")
    lines.append(f"  largest relative difference: {worst[0]:.2e} at {worst[1] or '-'}")
    va = [(r.get("quantity") or r.get("mode") or r.get("case") or r.get("trend") or "", r["verdict"])
          for r in verdict_rows(reproduce_report(new))]
    vb = [(r.get("quantity") or r.get("mode") or r.get("case") or r.get("trend") or "", r["verdict"])
          for r in verdict_rows(reproduce_report(old))]
    changed = [f"  verdict {n}: {v_old} -> {v_new}" for (n, v_new), (_, v_old) in zip(va, vb) if v_new != v_old]
    lines += changed or [f"  verdicts: all {len(va)} unchanged" if len(va) == len(vb) else
                         f"  verdicts: {len(vb)} rows before, {len(va)} now"]
    return lines


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, help="output folder (default: a temporary one)")
    p.add_argument("--overwrite", action="store_true", help="replace the files of the same names in a non-empty --out")
    p.add_argument("--processes", type=int, default=None, help="worker processes (default: every core)")
    p.add_argument("--summary", type=Path, help="report the timings of this summary.json instead of running")
    p.add_argument("--compare", type=Path, help="summary.json of another run to compare the numbers with")
    p.add_argument("--rtol", type=float, default=1e-3, help="relative difference reported by --compare")
    a = p.parse_args(argv)
    load0 = os.getloadavg()
    if a.summary:
        summary = json.loads(a.summary.read_text())
        wall = summary["timings_s"]["total_s"]
    else:
        from bladedamp.cli import Progress, UsageError, output_dir
        from bladedamp.reproduce import reproduce

        # a non-empty --out is refused (UsageError), as by `bladedamp reproduce`: never replace results
        try:
            out = output_dir(a.out, a.overwrite) if a.out else Path(tempfile.mkdtemp(prefix="bench_reproduce_"))
        except UsageError as exc:
            print(f"bench_reproduce: {exc}", file=sys.stderr)
            return 2
        t0 = time.perf_counter()
        summary = reproduce(out, processes=a.processes, progress=Progress())
        wall = time.perf_counter() - t0
        print(f"output in {out}")
    load1 = os.getloadavg()
    from bladedamp.report import STUDY_TIMES

    t = summary["timings_s"]
    print(f"# bladedamp reproduce, {datetime.date.today()}, {platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, processes {a.processes or 'all'}")
    print(f"load average (1, 5, 15 min) before {load0[0]:.1f} {load0[1]:.1f} {load0[2]:.1f}, "
          f"after {load1[0]:.1f} {load1[1]:.1f} {load1[2]:.1f}")
    print("| study | s | share |\n|---|---|---|")
    for key, name in STUDY_TIMES:
        if key in t:
            print(f"| {name} | {t[key]:.1f} | {100 * t[key] / t['total_s']:.0f} % |")
    print(f"| total (summary.json) | {t['total_s']:.1f} | 100 % |")
    if not a.summary:
        print(f"| total with import and writing | {wall:.1f} | |")
    if a.compare:
        print(f"numbers differing from {a.compare} beyond {a.rtol:g} (relative):")
        print("\n".join(compare(summary, json.loads(a.compare.read_text()), a.rtol)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
