"""Issue 37, items 1 and 2 (tuned half): the automatic harmonic choice against a sweep given the
final harmonics, and the reference tuned FRF against its kernel limit, in CPU time.

Run from the repository root::

    python benchmarks/bench_auto_harmonics.py              # 3 rounds, about 1 minute on 2 cores
    python benchmarks/bench_auto_harmonics.py --rounds 5

Cases: the reference tuned FRF, ``bd.frequency_response(bd.reference_disk('cylinder', 1e-3),
(90.0, 105.0))`` (default options: the automatic harmonics), and the same with the harmonics it
ends on and their samples given directly (``harmonics=(0, 1, 2, 3, 4, 5), n_samples=80``; the
harmonic error estimate against (0..7) included in both). After one call of each (compilation,
caches), ``--rounds`` rounds alternate the two in this process; CPU time (``time.process_time``)
of each call, the median of the per-round ratios printed (issue 37 item 1: at most 1.3).

The kernel limit (issue 37 item 2): one more direct call with the kernels wrapped in CPU-time
counters: the fused contact kernel with its Jacobian (``damper_contact_forces``), the projection
T^T J T (``Coupling.add_jacobian``) and the dense LU (``DenseLU``), counted inside the final set's
continuation only (its Jacobians a point printed). The limit is that many Jacobians a point times
one Jacobian's kernels (their CPU per call in that run), times the points; the achieved CPU per
point of the default FRF (and of the direct sweep) is printed beside it (item 2: at most 1.5x).
The wrappers cost about 10 us a call, which the per-call figures include.
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
import subprocess
import sys
import time
import warnings

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import bladedamp as bd  # noqa: E402

RANGE_HZ = (90.0, 105.0)
DIRECT = dict(harmonics=(0, 1, 2, 3, 4, 5), n_samples=80)
RATIO_TARGET = 1.3          # issue 37 item 1
LIMIT_TARGET = 1.5          # issue 37 item 2


def uptime() -> str:
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return f"load average {os.getloadavg()[0]:.2f}"


def cpu_call(fun):
    """(CPU seconds, result) of ``fun()``."""
    t0 = time.process_time()
    out = fun()
    return time.process_time() - t0, out


class KernelCounters:
    """CPU time and calls of the contact kernel with Jacobian, the projection and the LU while
    ``active`` (set inside the final set's continuation)."""

    def __init__(self):
        import bladedamp.diskmodel as diskmodel
        import bladedamp.frf as frf
        import bladedamp.hbm.linsolve as linsolve
        from bladedamp.hbm.system import Coupling

        self.active = False
        self.cpu = {"contact kernel (with J)": 0.0, "projection T^T J T": 0.0, "LU": 0.0}
        self.calls = dict.fromkeys(self.cpu, 0)
        self._restore = []

        def wrap(owner, name, key, counts=lambda *a, **k: True):
            original = getattr(owner, name)

            def wrapped(*args, **kwargs):
                if not (self.active and counts(*args, **kwargs)):
                    return original(*args, **kwargs)
                t0 = time.process_time()
                out = original(*args, **kwargs)
                self.cpu[key] += time.process_time() - t0
                self.calls[key] += 1
                return out

            setattr(owner, name, wrapped)
            self._restore.append((owner, name, original))

        # damper_contact_forces(..., jacobian, force, blocks, closed_form): jacobian is the 14th
        wrap(diskmodel, "damper_contact_forces", "contact kernel (with J)", lambda *a: bool(a[13]))
        wrap(Coupling, "add_jacobian", "projection T^T J T")
        wrap(linsolve.DenseLU, "__init__", "LU")
        original = frf.continuation

        def continuation(*args, **kwargs):
            self.active = True
            try:
                return original(*args, **kwargs)
            finally:
                self.active = False

        frf.continuation = continuation
        self._restore.append((frf, "continuation", original))

    def restore(self):
        for owner, name, original in reversed(self._restore):
            setattr(owner, name, original)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds after the first calls")
    args = ap.parse_args(argv)
    print(f"bench_auto_harmonics  {datetime.datetime.now():%Y-%m-%d %H:%M}  python {platform.python_version()}  "
          f"numpy {np.__version__}  {platform.machine()}  cpus {os.cpu_count()}  "
          f"BLAS threads {os.environ['OPENBLAS_NUM_THREADS']}  tree {os.path.dirname(bd.__file__)}")
    print("start:", uptime())
    disk = bd.reference_disk("cylinder", 1e-3)
    warnings.simplefilter("ignore")
    cases = {"automatic": lambda: bd.frequency_response(disk, RANGE_HZ),
             "direct": lambda: bd.frequency_response(disk, RANGE_HZ, **DIRECT)}
    first = {name: f() for name, f in cases.items()}         # compilation, caches
    auto, direct = first["automatic"], first["direct"]
    same = (auto.basis.harmonics == direct.basis.harmonics and auto.basis.n_samples == direct.basis.n_samples
            and np.array_equal(auto.coefficients, direct.coefficients) and auto.harmonic_error == direct.harmonic_error)
    print(f"automatic: harmonics {auto.basis.harmonics}, {auto.basis.n_samples} samples, {len(auto.omega)} points, "
          f"estimate {100 * auto.harmonic_error:.3g} %, peak {1e3 * auto.peak_amplitude:.6f} mm at "
          f"{auto.peak_frequency_hz:.4f} Hz; the direct sweep's branch and estimate "
          + ("identical" if same else "DIFFER"))
    cpu = {name: [] for name in cases}
    for _ in range(args.rounds):
        for name, f in cases.items():
            cpu[name].append(cpu_call(f)[0])
    ratios = np.array(cpu["automatic"]) / np.array(cpu["direct"])
    print(f"\nCPU s per call, {args.rounds} alternating rounds:")
    for name in cases:
        print(f"  {name:<10}" + "  ".join(f"{t:6.3f}" for t in cpu[name]))
    ratio = float(np.median(ratios))
    print("  automatic / direct per round: " + "  ".join(f"{r:.3f}" for r in ratios)
          + f"; median {ratio:.3f} (target <= {RATIO_TARGET}: {'met' if ratio <= RATIO_TARGET else 'NOT met'})")

    counters = KernelCounters()
    try:
        t_counted, counted = cpu_call(cases["direct"])
    finally:
        counters.restore()
    n = len(counted.omega)
    jac_calls = counters.calls["contact kernel (with J)"]
    per_jacobian = sum(counters.cpu[k] / max(counters.calls[k], 1) for k in counters.cpu)
    per_point_jacobians = jac_calls / n
    limit = per_jacobian * per_point_jacobians            # s a point
    print(f"\nkernels inside the final set's continuation ({n} points; a counted direct call, {t_counted:.3f} s):")
    for k in counters.cpu:
        c = counters.calls[k]
        print(f"  {k:<26}{c:>6d} calls  {counters.cpu[k]:7.3f} s  {1e6 * counters.cpu[k] / max(c, 1):7.1f} us a call")
    print(f"  Jacobians a point {per_point_jacobians:.2f}; one Jacobian's kernels {1e3 * per_jacobian:.3f} ms; "
          f"kernel limit {1e3 * limit:.3f} ms a point ({limit * n:.3f} s for the {n} points)")
    achieved = {name: float(np.median(cpu[name])) / n for name in cases}
    for name in cases:
        print(f"  {name:<10} achieved {1e3 * achieved[name]:.3f} ms a point = {achieved[name] / limit:.2f} x the limit"
              + (f" (target <= {LIMIT_TARGET}: {'met' if achieved[name] / limit <= LIMIT_TARGET else 'NOT met'})"
                 if name == "automatic" else ""))
    print("end:  ", uptime())
    return dict(ratio=ratio, cpu=cpu, limit=limit, achieved=achieved)


if __name__ == "__main__":
    main()
