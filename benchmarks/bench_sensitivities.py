"""Cost of the derivatives of a peak (issue 36 item 1) against one Newton step of that point.

One Newton step at the solved peak: the residual with its Jacobian, the factorisation and one
solve. The pointwise derivatives of one point in k parameters: the Jacobian evaluated and
factorised, dR/dp for all k (whose contact terms come from that same kernel pass,
bladedamp.diskmodel.ParameterDerivatives.reusing), k back-substitutions; and the same with the
Newton's factorisation at hand (dR/dp and the k solves alone). The peak's derivatives: the points
either side of it, each a Newton solve from a tangent predictor, and dR/dp at the pair used, see
bladedamp.hbm.sensitivity; its count of residual + Jacobian evaluations and factorisations is
printed too (one untimed run). CPU time (time.process_time), the best of ``--repeat`` rounds (the
measurements interleaved in each), in one process, with the machine's load.

    python benchmarks/bench_sensitivities.py [--harmonics 0,1,2,3] [--repeat 5]
"""
import argparse
import os
import time
import warnings

import numpy as np

import bladedamp as bd
from bladedamp.hbm.peaks import PeakSolver
from bladedamp.hbm.sensitivity import peak_sensitivities, state_sensitivities

KEYS = ["damper.mass_g", "damper.friction_coefficient", "damper.tangential_stiffness_per_length_n_per_m2",
        "damper.normal_to_tangential_stiffness", "disk.damper_radius_mm", "disk.excitation_n_nm[0]",
        "blade.natural_frequencies_hz[0]", "blade.damping_ratio"]


def best(functions, repeat):
    """The least CPU time [s] of each of ``functions`` over ``repeat`` rounds, the functions
    interleaved in each round (so that every minimum is taken over the same spell of the
    machine's load)."""
    times = [[] for _ in functions]
    for _ in range(repeat):
        for f, out in zip(functions, times):
            t = time.process_time()
            f()
            out.append(time.process_time() - t)
    return [min(t) for t in times]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--harmonics", default="0,1,2,3")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    harmonics = tuple(int(h) for h in args.harmonics.split(","))
    warnings.simplefilter("ignore")
    disk = bd.reference_disk("cylinder", 1e-3)
    response = disk.frequency_response(90.0, 100.0, harmonics=harmonics, n_samples=args.samples,
                                       estimate_harmonic_error=False)
    system = response.model_system()
    output = response.blade_outputs(0)[0]
    X = response.coefficients.reshape(len(response.omega), -1)
    solver = PeakSolver(system, response.omega, X)
    a, w, x = solver.solve_state(int(np.argmax(np.abs(X @ output))), output)
    dR_dp = disk.parameter_derivatives(system, KEYS)

    def newton_step():
        R, J, _ = system.residual(x, w)
        system.factorize(J)(R)

    factorised = system.factorize(system.residual(x, w)[1])

    def point():
        state_sensitivities(system, x, w, dR_dp)

    def point_at_hand():
        state_sensitivities(system, x, w, dR_dp, factorised)

    def peak():
        peak_sensitivities(system, x, w, output, dR_dp, solver.x_scale, 1.0)

    step, one, at_hand, both = best((newton_step, point, point_at_hand, peak), args.repeat)
    counts = [0, 0]
    residual, factorize = system.residual, system.factorize

    def counted_residual(*a, **k):
        counts[0] += a[2] if len(a) > 2 else k.get("jacobian", True)
        return residual(*a, **k)

    def counted_factorize(J):
        counts[1] += 1
        return factorize(J)

    system.residual, system.factorize = counted_residual, counted_factorize
    peak()
    system.residual, system.factorize = residual, factorize
    load = os.getloadavg()
    print(f"reference 1 g cylinder, harmonics {harmonics}, {args.samples} samples, {len(KEYS)} parameters; "
          f"load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(f"one Newton step at the peak:               {1e3 * step:8.3f} ms CPU")
    print(f"derivatives of the point in {len(KEYS)} parameters: {1e3 * one:8.3f} ms CPU = {one / step:.2f} Newton steps")
    print(f"  with the Newton's factorisation at hand: {1e3 * at_hand:8.3f} ms CPU = {at_hand / step:.2f} Newton steps")
    print(f"derivatives of the peak in {len(KEYS)} parameters:  {1e3 * both:8.3f} ms CPU = "
          f"{both / step:.2f} Newton steps ({counts[0]} residual + Jacobian evaluations, {counts[1]} factorisations)")


if __name__ == "__main__":
    main()
