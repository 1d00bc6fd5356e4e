"""HBM against time integration of the same bladed disk: time per frequency point and error.

Run from the repository root::

    python benchmarks/bench_timedomain.py            # ~4 minutes on 2 cores (load 6)
    python benchmarks/bench_timedomain.py --quick    # 3 frequencies per damper, one HBM repetition

Cases: the reference disk (16 blades, EO = 1, F_x = 0.1 N) with the 1 g cylinder and the
0.3 g wedge, at the validation frequencies of tests/test_timedomain_disk.py (92-98 Hz across
the 1F resonance).

* Time integration: ``TunedDisk.time_response`` (the full 16-blade assembly by explicit central
  differences, default settings: tol 1e-5 per period, 512 steps per period), one run per
  frequency from the static equilibrium; time per frequency = total / frequencies.
* HBM: the tuned cyclic sector by continuation over 91-99 Hz (max_step 0.02, the FRF setting
  of ``hbm_tip_at``), harmonics (1,) and (0, 1, 2, 3); time per frequency point = FRF time /
  branch points, best of ``--repeat`` after a warm-up (numba caches). ``frequency_response``
  also checks the harmonics it is given against a richer set at a few points
  (``bladedamp.hbm.accuracy.harmonic_error``); that check is timed alone too, and the ratio
  is given with and without it. The HBM amplitude at each
  time-integration frequency comes from ``hbm_tip_at`` (branch interpolated, Newton there).
* Error: |HBM / time - 1| of the tip amplitude u_x (blade mean of the time integration), at the
  frequencies where the time integration is periodic; frequencies where it is not (the rolling
  cylinder) are listed apart.

Ratio = (time integration per frequency) / (HBM per frequency point), measured in this run.
Issue target: >= 1000x at <= 2 % error.
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys
import time
import warnings

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from _timing import best_of, solved_response  # noqa: E402

from bladedamp.hbm.accuracy import harmonic_error  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402
from bladedamp.timedomain import hbm_tip_at  # noqa: E402

FREQUENCIES = np.array([92.0, 94.0, 95.1, 95.4, 95.7, 96.1, 98.0])
QUICK_FREQUENCIES = np.array([92.0, 95.4, 96.1])
CASES = [("cylinder", 1e-3), ("wedge", 3e-4)]
HARMONICS = [(1,), (0, 1, 2, 3)]
F_RANGE = (91.0, 99.0)
MAX_STEP = 0.02


def hbm_per_point(disk, harmonics, repeat):
    """(s per branch point, points, FRF time [s], of which the harmonic-error check [s])."""
    def run():
        return solved_response(disk, F_RANGE, MAX_STEP, harmonics)
    run()
    t, r = best_of(run, repeat)
    with warnings.catch_warnings():     # frequency_response checks the harmonics it was given
        warnings.simplefilter("ignore")
        t_check, _ = best_of(lambda: harmonic_error(disk, r), repeat)
    return t / len(r.omega), len(r.omega), t, t_check


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 frequencies per damper, one HBM repetition")
    ap.add_argument("--repeat", type=int, default=3, help="HBM repetitions (best of)")
    args = ap.parse_args(argv)
    freqs = QUICK_FREQUENCIES if args.quick else FREQUENCIES
    repeat = 1 if args.quick else args.repeat
    print(f"bench_timedomain {datetime.datetime.now():%Y-%m-%d %H:%M}, {platform.machine()}, "
          f"Python {platform.python_version()}, numpy {np.__version__}, load {os.getloadavg()[0]:.1f}")
    rows = []
    for kind, mass in CASES:
        disk = reference_disk(kind, mass=mass)
        disk.time_response(95.0, max_periods=20)                  # warm-up: numba caches
        t0 = time.perf_counter()
        tr = disk.time_response(freqs)
        t_td = (time.perf_counter() - t0) / len(freqs)
        td = tr.tip_amplitude[:, :, 0].mean(axis=1)
        print(f"\n{kind} {1e3 * mass:g} g: time integration {t_td:.2f} s per frequency "
              f"({tr.steps_per_period} steps per period, periods {list(tr.periods)})")
        for i, f in enumerate(freqs):
            print(f"  {f:6.2f} Hz  {1e3 * td[i]:.5f} mm  {tr.message[i]}")
        for h in HARMONICS:
            t_pt, n_pt, t_frf, t_check = hbm_per_point(disk, h, repeat)
            t_pt_bare = (t_frf - t_check) / n_pt
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                hbm = hbm_tip_at(disk, freqs, h)[:, 0]
            err = np.abs(hbm / td - 1)
            per = tr.periodic
            worst = err[per].max() if per.any() else np.nan
            rows.append((kind, mass, h, t_td, t_pt, t_pt_bare, worst, err, per))
            print(f"  HBM {h}: FRF {t_frf:.2f} s (harmonic-error check {t_check:.2f} s of it) / {n_pt} points = "
                  f"{1e3 * t_pt:.2f} ms per point ({1e3 * t_pt_bare:.2f} without the check); ratio "
                  f"{t_td / t_pt:,.0f}x ({t_td / t_pt_bare:,.0f}x); error: "
                  f"{', '.join(f'{f:g}: {100 * e:.2f} %' for f, e in zip(freqs, err))}")
    print(f"\n{'case':<16}{'HBM':>14}{'TI s/freq':>11}{'HBM ms/pt':>11}{'ratio':>9}{'(no check)':>11}"
          f"{'max err, periodic':>19}{'  not periodic: error'}")
    for kind, mass, h, t_td, t_pt, t_pt_bare, worst, err, per in rows:
        bad = ", ".join(f"{f:g} Hz {100 * e:.1f} %" for f, e, p in zip(freqs, err, per) if not p)
        print(f"{kind + f' {1e3 * mass:g} g':<16}{str(h):>14}{t_td:>11.2f}{1e3 * t_pt:>11.2f}{t_td / t_pt:>9,.0f}"
              f"{t_td / t_pt_bare:>11,.0f}{100 * worst:>18.2f}%  {bad}")


if __name__ == "__main__":
    main()
