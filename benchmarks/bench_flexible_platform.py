"""Flexible-platform benchmark: the cost of the solid blade's per-point platform kinematics
(bladedamp.diskmodel.contact_point_maps) against rigid platforms at OL / OR, same modes.

Run from the repository root (needs the fe extra, ``pip install -e '.[fe]'``)::

    python benchmarks/bench_flexible_platform.py                 # 9 mm solid, best of 3
    python benchmarks/bench_flexible_platform.py --element-size 6e-3 --repeat 1

Cases: the tuned reference disk (EO = 1) with the 1 g cylinder (1 x 5 points per contact) and
the 0.3 g wedge (5 x 5), the solid blade with its flexible platforms (12 + 2 n_m = 20 local
coordinates per damper with the 4 modes) and the same blade with rigid platforms
(``rigid_platform_blade``, 12). Timed, each the best of ``--repeat``: one residual with its
Jacobian of the sector at harmonics (0, 1, 2, 3), with one BLAS thread (as the continuation
runs), and the FRF over 92-106 Hz with harmonics (1,) and (0, 1, 2, 3).
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import os
import platform
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import numpy as np  # noqa: E402
from _timing import best_of, solved_response  # noqa: E402

import bladedamp as bd  # noqa: E402
from bladedamp.hbm.linsolve import one_blas_thread  # noqa: E402

F_RANGE = (92.0, 106.0)
DAMPERS = {"cylinder": 1e-3, "wedge": 0.3e-3}


@one_blas_thread
def residual_time(disk, repeat):
    """Best time [s] of one residual + Jacobian of the sector at (0, 1, 2, 3), 50 calls each."""
    system = disk.hbm_system((0, 1, 2, 3))
    omega = 2 * np.pi * 97.0
    x = 3.0 * disk.initial_guess(system, omega)
    system.residual(x, omega)
    t, _ = best_of(lambda: [system.residual(x, omega) for _ in range(50)], repeat)
    return t / 50


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--element-size", type=float, default=9e-3, help="gmsh element size [m]")
    parser.add_argument("--repeat", type=int, default=3, help="timed repetitions (best is reported)")
    args = parser.parse_args(argv)
    print(f"bench_flexible_platform {datetime.date.today()}  {platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, load average {os.getloadavg()[0]:.1f}")
    blade = bd.solid.solid_blade(element_size=args.element_size)
    print(f"solid blade: {blade.solid_info['n_dofs']} DOF, element size {1e3 * args.element_size:g} mm")
    print(f"{'damper':9s} {'platform':9s} {'n_local':>7s} {'residual+J [ms]':>16s} {'FRF H=(1,) [s]':>15s} "
          f"{'FRF H=(0..3) [s]':>17s} {'peak (0..3) [mm]':>17s}")
    for kind, mass in DAMPERS.items():
        for name, b in (("flexible", blade), ("rigid", blade.rigid_platform_blade())):
            disk = dataclasses.replace(bd.reference_disk(kind, mass), blade=b)
            n_local = disk.hbm_system((1,)).couplings[0].element.n_local
            t_res = residual_time(disk, args.repeat)
            t1, _ = best_of(lambda: solved_response(disk, F_RANGE, 0.02), args.repeat)
            t3, r = best_of(lambda: solved_response(disk, F_RANGE, 0.02, (0, 1, 2, 3)), args.repeat)
            print(f"{kind:9s} {name:9s} {n_local:7d} {1e3 * t_res:16.2f} {t1:15.2f} {t3:17.2f} "
                  f"{1e3 * r.peak_amplitude:17.5f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
