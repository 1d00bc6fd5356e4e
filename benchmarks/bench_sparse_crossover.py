"""Dense or sparse Jacobian for a user-built full assembly (issue 37, item 4): the crossover.

A :class:`~bladedamp.hbm.system.HarmonicBalanceSystem` built by hand from a full assembly of
``n`` sectors with point contacts between neighbouring sectors (the matrices, excitation and
damper contacts of ``MistunedDisk.hbm_system``, handed to the generic residual) is timed per
Newton iteration (residual with its Jacobian, LU, one solve; CPU time, ``time.process_time``)
with a dense and with a sparse Jacobian, alternated in one process, at a response near
resonance (the linear solution at 95 Hz scaled to a 20 um tip amplitude, where the contacts
slip). Printed per n: unknowns N, the fill nnz(J) / N^2, the CPU time of each path, their
ratio, and the path ``storage="auto"`` takes (where the package has it).

Run from the repository root::

    python benchmarks/bench_sparse_crossover.py                    # n = 4 8 12 16 24 32 64, (0, 1, 2, 3)
    python benchmarks/bench_sparse_crossover.py --sectors 8 64 --harmonics 1
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import subprocess
import time
import warnings

import numpy as np
import scipy.sparse as sp


def ring_systems(n, harmonics, nodes=2):
    """A ring of ``n`` sectors built by hand: each sector a chain of ``nodes`` 3D point masses
    (1 kg, springs 1e6 N/m between nodes and to ground from the first, 0.2 % proportional
    damping), its last node (the tip) tied to the next sector's tip by a point contact (k_T
    1e5 N/m, mu 0.3, linear normal law 1e5 N/m, preload approach 1e-5 m), the tips forced at
    1 N with engine order 1. Returns ``build(storage_dense)``: the HarmonicBalanceSystem with
    dense (numpy) or sparse (scipy) matrices and contact map."""
    from bladedamp.contact.laws import LinearNormalLaw
    from bladedamp.contact.point import PointContactElement
    from bladedamp.hbm.fourier import HarmonicBasis
    from bladedamp.hbm.system import Coupling, HarmonicBalanceSystem

    basis = HarmonicBasis(tuple(harmonics), 64)
    C = basis.n_coeffs
    per = 3 * nodes
    N = n * per
    chain = 2.0 * np.eye(nodes) - np.eye(nodes, k=1) - np.eye(nodes, k=-1)
    chain[-1, -1] = 1.0
    k_sector = sp.kron(sp.csr_matrix(1e6 * chain), sp.identity(3))
    K = sp.kron(sp.identity(n), k_sector, format="csr")
    M = sp.identity(N, format="csr")
    D = (2e-3 / 1e3) * K + 2e-3 * 1e3 * M
    tip = np.arange(n) * per + per - 3
    T0 = sp.lil_matrix((3 * n, N))
    for k in range(n):
        for i in range(3):
            T0[3 * k + i, tip[(k + 1) % n] + i] = 1.0
            T0[3 * k + i, tip[k] + i] = -1.0
    T = sp.kron(sp.identity(C), T0.tocsr(), format="csr")
    f = np.zeros((C, N))
    j = basis.cos_index(1)
    phase = 2 * np.pi * np.arange(n) / n
    f[j, tip] = np.cos(phase)
    f[j + 1, tip] = -np.sin(phase)
    f[j, tip + 1] = 0.5
    f = f.ravel()

    def excitation(omega):
        return f, np.zeros_like(f)

    element = PointContactElement(np.full(n, 1e5), 0.3, LinearNormalLaw(1e5), np.ones(n), np.full(n, 1e-5))

    def build(dense):
        conv = (lambda m: m.toarray()) if dense else (lambda m: m)
        system = HarmonicBalanceSystem(basis, conv(M), conv(D), conv(K), excitation,
                                       [Coupling(element, conv(T), "tips")])
        if hasattr(system, "storage"):
            system.storage = "dense" if dense else "sparse"
        return system
    return build


def disk_systems(n, harmonics):
    """The full assembly of the reference disk (1 g cylinder dampers) with ``n`` blades, 2 %
    cosine mistuning: the matrices, excitation and damper contacts of ``MistunedDisk.hbm_system``
    handed to the generic residual. Returns ``build(storage_dense)`` as :func:`ring_systems`."""
    import bladedamp as bd
    from bladedamp.hbm.system import Coupling, HarmonicBalanceSystem
    from bladedamp.mistuned import MistunedDisk

    disk = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=n, engine_order=1)
    kappa = 1.0 + 0.02 * np.cos(np.arange(n) * 2.1)
    s = MistunedDisk.from_tuned(disk, kappa).hbm_system(harmonics)

    def build(dense):
        conv = (lambda m: None if m is None else (m.toarray() if sp.issparse(m) else m)) if dense else (lambda m: m)
        couplings = [Coupling(c.element, conv(c.matrix), c.name) for c in s.couplings]
        system = HarmonicBalanceSystem(s.basis, conv(s.mass), conv(s.damping), conv(s.stiffness), s.excitation,
                                       couplings, conv(s.static_stiffness))
        if hasattr(system, "storage"):
            system.storage = "dense" if dense else "sparse"
        return system
    return build


def newton_step(system, x, w):
    R, J, _ = system.residual(x, w)
    solve = system.factorize(J)
    return solve(R), J


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sectors", type=int, nargs="+", default=[4, 8, 12, 16, 24, 32, 64])
    parser.add_argument("--harmonics", type=int, nargs="+", default=[0, 1, 2, 3])
    parser.add_argument("--model", choices=("ring", "disk"), default="ring",
                        help="ring: sectors of point masses tied by point contacts (built here); disk: the "
                             "reference disk's full assembly handed to the generic residual")
    parser.add_argument("--repeat", type=int, default=3, help="alternations per n (the best kept per path)")
    args = parser.parse_args(argv)
    from bladedamp.hbm import linsolve

    warnings.simplefilter("ignore")
    print(f"# bench_sparse_crossover, model {args.model}, harmonics {tuple(args.harmonics)}, {os.cpu_count()} cores, "
          f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print(f"{'n':>4} {'N':>6} {'fill':>7} {'dense ms':>9} {'sparse ms':>10} {'sparse/dense':>12} {'auto':>7}")
    step = linsolve.one_blas_thread(newton_step)
    for n in args.sectors:
        if args.model == "ring":
            build = ring_systems(n, tuple(args.harmonics))
            w = 0.9 * np.sqrt(1e6 * (2 - 2 * np.cos(np.pi / 5)))      # below the chain's first mode
        else:
            build = disk_systems(n, tuple(args.harmonics))
            w = 2 * np.pi * 95.0
        dense, sparse = build(True), build(False)
        x = sparse.linear_solution(w)
        x *= 2e-5 / np.abs(x).max()
        (yd, Jd), (ys, Js) = step(dense, x, w), step(sparse, x, w)    # compiles, warms caches
        N = x.size
        fill = Js.count_nonzero() / N ** 2
        agree = np.abs(yd - ys).max() / np.abs(yd).max()
        best = {"dense": np.inf, "sparse": np.inf}
        steps = {}
        for _ in range(args.repeat):
            for name, system in (("dense", dense), ("sparse", sparse)):
                t0, k = time.process_time(), 0
                while k < steps.get(name, 3) or (name not in steps and time.process_time() - t0 < 0.5):
                    step(system, x, w)
                    k += 1
                steps[name] = k
                best[name] = min(best[name], (time.process_time() - t0) / k)
        k = steps["dense"]
        auto = build(False)
        if hasattr(auto, "storage"):
            auto.storage = "auto"
            auto.residual(x, w)
            chosen = "sparse" if auto.sparse else "dense"
        else:
            chosen = "-"
        print(f"{n:4d} {N:6d} {fill:7.4f} {1e3 * best['dense']:9.2f} {1e3 * best['sparse']:10.2f} "
              f"{best['sparse'] / best['dense']:12.2f} {chosen:>7}   (steps agree to {agree:.1e}, {k} steps)", flush=True)


if __name__ == "__main__":
    main()
