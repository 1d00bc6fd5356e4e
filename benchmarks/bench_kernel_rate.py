"""Arithmetic rate of the contact kernels (issue 37, item 6): GFlop/s of a call.

The fused damper kernel ``contact.point.damper_contact_forces`` (the disks' contacts) and the
point-contact kernel ``contact.point.point_contact_harmonics`` (``PointContactElement``, the
same points taken one by one) are called with the arguments of the reference disk's sector
(1 g cylinder, harmonics 0..5, 80 samples, the default FRF's final set) at the FRF's peak, with
and without the Jacobian; CPU time per call (``time.process_time``, best of ``--repeat``).

Flops are counted per point from its states in the last period (stick / slip / separated, from
the public ``point_contact_forces`` at the same coefficients): the synthesis and analysis
(6 T C each), the normal law (3 T), two plain passes of the return map if the point slips or
separates (10 flops a stuck, 20 a slipping sample; the least the periodicity test allows, so the
count is a lower bound), and with the Jacobian the derivative pass (9 C a stuck, 54 C a slipping,
5 C a separated sample), the closed-form correction (24 C per non-separated sample), the AFT of
the Jacobian (jn: 3 C^2 per non-separated sample; jt: 4 C n3p per non-separated sample, n3p = 3C
rounded up to 4, or 6 C n3p for a point stuck all period) and, in the fused kernel, the
projections (point coefficients 36 C, forces 36 C, B^T jp 66 C^2, (B^T jp) B 216 C^2).
Multiply and add count one flop each (an FMA two); square roots and divisions one.

Run from the repository root::

    python benchmarks/bench_kernel_rate.py
"""
from __future__ import annotations

import argparse
import os
import subprocess
import time
import warnings

import numpy as np


def captured_call():
    """(kernel arguments of fused_point_map_forces at the reference FRF's peak, basis, law)."""
    import bladedamp as bd
    from bladedamp import diskmodel

    warnings.simplefilter("ignore")
    disk = bd.reference_disk("cylinder", 1e-3)
    harmonics = (0, 1, 2, 3, 4, 5)
    r = disk.frequency_response(94.0, 97.0, harmonics=harmonics, n_samples=80)
    i = int(np.argmax(np.abs(r.coefficients).reshape(len(r.coefficients), -1).max(axis=1)))     # the peak
    system = disk.hbm_system(harmonics, 80)
    seen = []
    original = diskmodel.fused_point_map_forces

    def spy(*args):
        seen.append(args)
        return original(*args)
    diskmodel.fused_point_map_forces = spy
    try:
        system.residual(r.coefficients[i].ravel(), float(r.omega[i]))
    finally:
        diskmodel.fused_point_map_forces = original
    if not seen:
        raise RuntimeError("the fused kernel was not called")
    return seen[-1]


def counted_flops(B, local, basis, k_t, mu, law, weights, offsets, jacobian, fused):
    """Flops of one kernel call by the model in the module docstring (a lower bound)."""
    from bladedamp.contact.point import SEPARATED, SLIP, STICK, point_contact_forces

    C, T = basis.n_coeffs, basis.n_samples
    n3p = (3 * C + 3) // 4 * 4
    nd, P = B.shape[0], B.shape[2]
    coeffs = np.einsum("dqpij,cdqj->cdqpi", B, local.reshape(C, nd, 2, 6)).reshape(C, nd * 2 * P, 3)
    pts = point_contact_forces(coeffs, basis, k_t, mu, law, weights, offsets.ravel(), jacobian=False)
    total = 0
    for state in pts.state:
        stick, slip, sep = (int(np.count_nonzero(state == s)) for s in (STICK, SLIP, SEPARATED))
        flops = 12 * T * C + 3 * T
        if slip or sep:
            flops += 2 * (10 * stick + 20 * slip)
        if jacobian:
            touching = stick + slip
            if slip or sep:
                flops += 9 * C * stick + 54 * C * slip + 5 * C * sep + 24 * C * touching
                flops += 3 * C * C * touching + 4 * C * n3p * touching
            else:
                flops += 3 * C * C * touching + 6 * C * n3p
        if fused:
            flops += 72 * C + (282 * C * C if jacobian else 0)
        total += flops
    return total, pts.state


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--label", default="", help="a name for this run (e.g. before / after)")
    args = parser.parse_args(argv)
    from bladedamp.contact.point import (MAX_PASSES, PERIODIC_TOL, damper_contact_forces, normal_law_parameters,
                                         point_contact_harmonics)

    B, local, basis, k_t, mu, law, weights, offsets, _ = captured_call()
    B, local = np.ascontiguousarray(B, dtype=float), np.ascontiguousarray(local, dtype=float)
    offsets = np.ascontiguousarray(offsets, dtype=float).ravel()
    params = normal_law_parameters(law)
    C, nd = basis.n_coeffs, B.shape[0]
    static_index = basis.cos_index(0) if basis.has_static else -1
    npts = nd * 2 * B.shape[2]
    point_local = np.ascontiguousarray(np.einsum("dqpij,cdqj->cdqpi", B, local.reshape(C, nd, 2, 6)).reshape(C, npts, 3))
    print(f"# bench_kernel_rate {args.label}, {os.cpu_count()} cores, "
          f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print(f"# {npts} points, C = {C}, T = {basis.n_samples}")
    for jac in (False, True):
        force = np.empty((C, nd, 12))
        blocks = np.empty((nd, C, 12, C, 12)) if jac else np.empty((1, 1, 1, 1, 1))
        pforce = np.empty((C, npts, 3))
        pjac = np.empty((C, npts, 3, C, npts, 3)) if jac else np.empty((1, 1, 1, 1, 1, 1))

        def fused():
            damper_contact_forces(B, local, basis.synthesis, basis.analysis, k_t, mu, weights, offsets, params[0],
                                  params[1], static_index, MAX_PASSES, PERIODIC_TOL, jac, force, blocks, True)

        def points():
            point_contact_harmonics(point_local, basis.synthesis, basis.analysis, k_t, mu, weights, offsets, params[0],
                                    params[1], static_index, MAX_PASSES, PERIODIC_TOL, jac, True, pforce, pjac)
        for name, call, is_fused in (("damper_contact_forces", fused, True), ("point_contact_harmonics", points, False)):
            flops, state = counted_flops(B, local, basis, k_t, mu, law, weights, offsets, jac, is_fused)
            call()
            best = np.inf
            for _ in range(args.repeat):
                t0, k = time.process_time(), 0
                while time.process_time() - t0 < 0.3:
                    call()
                    k += 1
                best = min(best, (time.process_time() - t0) / k)
            print(f"{name:24s} jacobian={jac!s:5}  {1e6 * best:9.1f} us/call  {flops / 1e6:7.3f} Mflop  "
                  f"{flops / best / 1e9:6.2f} GFlop/s", flush=True)
    counts = np.bincount(state.ravel(), minlength=3) / state.size
    print(f"# samples stick / slip / separated: {counts[0]:.2f} / {counts[1]:.2f} / {counts[2]:.2f}")


if __name__ == "__main__":
    main()
