"""The studies' peak searches: one peak, and whole mass optimisations (issue 15, item 6).

    python benchmarks/bench_peak_search.py                                # this checkout
    python benchmarks/bench_peak_search.py --compare /path/to/other/checkout   # the same cases there too

Each case runs in a fresh ``python`` subprocess per checkout (``PYTHONPATH`` set to it), after a
warm-up response that loads its compiled kernels, so both checkouts are timed alike; with
``--compare`` the two run case by case, alternating, in one run of this script (the machine's
load is shared alike). Reports the wall time of each case, its result (peak [mm] at [Hz], or the
optimal mass [g] and its peak [mm]) and the ratio.

The cases: ``peak_response`` of the reference cylinder (1 g) and wedge (0.28 g), and
``optimal_mass`` (the reproduce settings: bounds 0.01-20 g, 90-105 Hz, one harmonic, xatol
0.02) of the cylinder at EO 1 and 7 and the wedge at EO 1 and 4.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CASES = {
    "peak, cylinder 1 g": "peak_response(reference_disk('cylinder'), (90.0, 105.0))",
    "peak, wedge 0.28 g": "peak_response(reference_disk('wedge', 0.28e-3), (90.0, 105.0))",
    "optimal mass, cylinder EO 1": "optimal_mass(at_engine_order(reference_disk('cylinder'), 1, 95.0), (1e-5, 2e-2))",
    "optimal mass, cylinder EO 7": "optimal_mass(at_engine_order(reference_disk('cylinder'), 7, 95.0), (1e-5, 2e-2))",
    "optimal mass, wedge EO 1": "optimal_mass(at_engine_order(reference_disk('wedge'), 1, 95.0), (1e-5, 2e-2))",
    "optimal mass, wedge EO 4": "optimal_mass(at_engine_order(reference_disk('wedge'), 4, 95.0), (1e-5, 2e-2))",
}

PROGRAM = """
import json, time, warnings
warnings.simplefilter("ignore")
from bladedamp.reference import reference_disk
from bladedamp.studies.design import at_engine_order
from bladedamp.studies.mass import optimal_mass, peak_response
reference_disk("cylinder").frequency_response(94.0, 96.0, harmonics=(1,), max_step=0.2)   # load the kernels
t = time.perf_counter()
out = {expr}
t = time.perf_counter() - t
result = (1e3 * out[0], out[1]) if isinstance(out, tuple) else (1e3 * out.mass, 1e3 * out.peak_amplitude)
print(json.dumps(dict(seconds=t, result=result)))
"""


def run(case: str, root: str) -> dict:
    env = dict(os.environ, PYTHONPATH=root)
    out = subprocess.run([sys.executable, "-c", PROGRAM.format(expr=CASES[case])], capture_output=True, text=True,
                         env=env, cwd=tempfile.gettempdir())
    if out.returncode:
        raise RuntimeError(f"{case} in {root} failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", metavar="CHECKOUT", default=None, help="another checkout to time alike")
    args = parser.parse_args(argv)
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    head = f"{'case':<30}{'this [s]':>10}{'result':>24}"
    if args.compare:
        head += f"{'other [s]':>11}{'result':>24}{'other/this':>11}"
    print(head)
    for case in CASES:
        if args.compare:
            other = run(case, args.compare)
        this = run(case, ROOT)
        line = f"{case:<30}{this['seconds']:>10.2f}{'%.6g, %.6g' % tuple(this['result']):>24}"
        if args.compare:
            line += (f"{other['seconds']:>11.2f}{'%.6g, %.6g' % tuple(other['result']):>24}"
                     f"{other['seconds'] / this['seconds']:>11.2f}")
        print(line, flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}  (results: peak [mm], frequency [Hz]; "
          "or optimal mass [g], its peak [mm])")


if __name__ == "__main__":
    main()
