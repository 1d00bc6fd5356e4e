"""Engine benchmark: HBM against time integration at matched accuracy, and contact-patch throughput.

Run from the repository root::

    python benchmarks/bench_engine.py            # ~30 s on 2 cores
    python benchmarks/bench_engine.py --quick    # fewer repetitions

(a) FrictionOscillator(damping=2, normal_load=3, forcing=2), 11 frequencies in [90, 140] rad/s
    (gross slip around the resonance). Reference: time integration with 8192 steps per period,
    amplitude settled to 1e-11 per period (agrees with an HBM of 8 odd harmonics and 1024
    samples to ~1e-5). Both methods are then run at settings that reach ~1e-3 of the
    reference and timed per frequency point in the same run.
(b) ContactPatch.evaluate throughput (points x samples per second) with and without the
    analytic Jacobian for several patch sizes.
"""
from __future__ import annotations

import argparse
import cProfile
import datetime
import os
import platform
import pstats
import sys
import time
import warnings

# small matrices: BLAS threads only add synchronisation (2x slower patch Jacobians measured
# on a busy 2-core machine); set the variable yourself to measure with threads
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from _timing import best_of  # noqa: E402
from bladedamp import ContactPatch, FrictionOscillator, LinearNormalLaw  # noqa: E402
from bladedamp.hbm import HarmonicBasis  # noqa: E402
from bladedamp.hbm.continuation import newton  # noqa: E402

OSC = dict(damping=2.0, normal_load=3.0, forcing=2.0)
OMEGAS = np.linspace(90.0, 140.0, 11)
HBM_HARMONICS = (1, 3, 5, 7)
TI_SETTINGS = dict(steps_per_period=256, tol=1e-5, min_periods=5)



def hbm_newton_sweep(osc, omegas, harmonics):
    """HBM at prescribed frequencies, Newton warm-started from the previous frequency."""
    system = osc.hbm_system(harmonics)
    j = system.basis.cos_index(1)
    x = system.linear_solution(omegas[0])
    amps = []
    for w in omegas:
        res = newton(system.residual, x, w, x_scale=np.abs(x).max(), residual_scale=abs(osc.forcing))
        if not res.converged:
            raise RuntimeError(f"Newton did not converge at {w}")
        x = res.x
        amps.append(np.hypot(x[j], x[j + 1]))
    return np.array(amps)


def hbm_amplitudes_at(osc, omegas, harmonics, n_samples=None):
    frf = osc.frequency_response(0.98 * omegas.min() / (2 * np.pi), 1.02 * omegas.max() / (2 * np.pi), harmonics, n_samples)
    system = osc.hbm_system(harmonics, n_samples)
    j = system.basis.cos_index(1)
    out = []
    for w in omegas:
        x0 = frf.coefficients[np.argmin(np.abs(frf.omega - w))].ravel()
        res = newton(system.residual, x0, w, x_scale=np.abs(x0).max(), residual_scale=abs(osc.forcing))
        out.append(np.hypot(res.x[j], res.x[j + 1]))
    return np.array(out)


def part_a(repeat):
    osc = FrictionOscillator(**OSC)
    print("(a) FrictionOscillator(damping=2, normal_load=3, forcing=2), omega = 90..140 rad/s (11 points)")
    # warm-up (numba compilation / cache load)
    osc.time_response(OMEGAS[:1] / (2 * np.pi), steps_per_period=64)
    osc.frequency_response(90.0 / (2 * np.pi), 95.0 / (2 * np.pi), HBM_HARMONICS)

    t_ref = time.perf_counter()
    ref = osc.time_response(OMEGAS / (2 * np.pi), steps_per_period=8192, tol=1e-11).amplitude
    t_ref = time.perf_counter() - t_ref
    check = hbm_amplitudes_at(osc, OMEGAS, (1, 3, 5, 7, 9, 11, 13, 15), 1024)
    print(f"    reference: time integration 8192 steps/period, tol 1e-11 ({t_ref:.1f} s); "
          f"HBM H=1..15 odd, T=1024 agrees to {np.abs(check / ref - 1).max():.1e}")

    # accuracy of the benchmarked settings
    t_ti, ti = best_of(lambda: osc.time_response(OMEGAS / (2 * np.pi), **TI_SETTINGS), repeat)
    err_ti = np.abs(ti.amplitude / ref - 1).max()
    t_newton, amp_newton = best_of(lambda: hbm_newton_sweep(osc, OMEGAS, HBM_HARMONICS), repeat)
    err_hbm = np.abs(amp_newton / ref - 1).max()
    t_cont, frf = best_of(lambda: osc.frequency_response(90.0 / (2 * np.pi), 140.0 / (2 * np.pi), HBM_HARMONICS), repeat)
    n_cont = frf.omega.size

    rows = [
        ("time integration", f"{TI_SETTINGS['steps_per_period']} steps/period, tol {TI_SETTINGS['tol']:g}",
         f"{err_ti:.1e}", t_ti / OMEGAS.size, f"{ti.periods.mean():.0f} periods from rest"),
        ("HBM, Newton sweep", f"H={HBM_HARMONICS}, T={osc.hbm_system(HBM_HARMONICS).basis.n_samples}",
         f"{err_hbm:.1e}", t_newton / OMEGAS.size, "warm start from previous frequency"),
        ("HBM, continuation", f"H={HBM_HARMONICS}, default steps", "(same)", t_cont / n_cont,
         f"{n_cont} points on [90, 140]"),
    ]
    print(f"    {'method':<20} {'settings':<34} {'max err':>8} {'ms/point':>9}  note")
    for name, settings, err, t, note in rows:
        print(f"    {name:<20} {settings:<34} {err:>8} {1e3 * t:9.3f}  {note}")
    print(f"    speed-up of HBM per frequency point (time integration / HBM): "
          f"Newton sweep {t_ti / t_newton:.2f}x, continuation {t_ti / OMEGAS.size / (t_cont / n_cont):.2f}x "
          f"(issue target >= 1000x)")

    # where the HBM time goes
    system = osc.hbm_system(HBM_HARMONICS)
    x = frf.coefficients[n_cont // 2].ravel()
    w = frf.omega[n_cont // 2]
    coupling = system.couplings[0]
    local = (coupling.matrix @ x).reshape(system.basis.n_coeffs, 3)
    n = 300 * repeat

    def per_call(fun):
        fun()                   # warm: a kernel's first call loads it from numba's cache
        t0 = time.perf_counter()
        for _ in range(n):
            fun()
        return (time.perf_counter() - t0) / n * 1e6

    from bladedamp.contact.point import return_map
    basis = system.basis
    T, C = basis.n_samples, basis.n_coeffs
    ut = np.zeros((1, T, 2))
    ut[0, :, 0] = basis.synthesis @ local[:, 0]
    args = (ut, np.full((1, T), OSC["normal_load"]), np.zeros((1, T)), np.zeros((1, T)), np.zeros((1, T)),
            basis.synthesis, np.array([1e4]),
            np.array([0.3]), np.zeros((1, 2)), -1, 20, 1e-10, True, np.empty((1, T, 2)),
            np.zeros((1, T, 3, 3 * C)), np.empty((1, T), np.int8), np.zeros(1), np.zeros((1, 2), np.int64), True)
    timings = {
        "residual + Jacobian": per_call(lambda: system.residual(x, w)),
        "residual only": per_call(lambda: system.residual(x, w, jacobian=False)),
        "  contact harmonic_forces (AFT + Jacobian)": per_call(
            lambda: coupling.element.harmonic_forces(local, basis, w, True)),
        "    numba return map alone": per_call(lambda: return_map(*args)),
        "  dynamic stiffness A(Omega), dA/dOmega": per_call(lambda: system.dynamic_stiffness(w)),
        "  same, its Omega-independent parts built anew": per_call(
            lambda: basis.dynamic_stiffness(w, system.mass, system.damping, system.stiffness)),
        "  same via real_form (before the speed fix)": per_call(
            lambda: (basis.real_form(lambda h: system.stiffness - (h * w) ** 2 * np.asarray(system.mass)
                                     + 1j * h * w * np.asarray(system.damping)),
                     basis.real_form(lambda h: -2 * h ** 2 * w * np.asarray(system.mass)
                                     + 1j * h * np.asarray(system.damping)))),
        "linear solve (C x C)": per_call(lambda: np.linalg.solve(np.eye(C) + 1e-3, np.ones(C))),
    }
    print("    per call [us]:")
    for k, v in timings.items():
        print(f"      {k:<46} {v:8.1f}")
    prof = cProfile.Profile()
    prof.enable()
    osc.frequency_response(90.0 / (2 * np.pi), 140.0 / (2 * np.pi), HBM_HARMONICS)
    prof.disable()
    stats = pstats.Stats(prof)
    total = max(v[3] for v in stats.stats.values())

    def cum(names):
        return sum(v[3] for k, v in stats.stats.items() if k[2] in names.split("|"))

    print("    continuation profile (cProfile, inflates Python overhead): share of the run time")
    for label, name in [("residual evaluations", "residual"), ("  contact AFT (harmonic_forces)", "harmonic_forces"),
                        ("    fused numba contact kernel", "point_contact_harmonics"),
                        ("  dynamic stiffness", "dynamic_stiffness"),
                        ("tangent computations", "tangent_at"),
                        ("LU factorisations (factorize)", "factorize")]:
        print(f"      {label:<34} {100 * cum(name) / total:5.1f} %")
    return dict(err_ti=err_ti, err_hbm=err_hbm, t_ti=t_ti / OMEGAS.size, t_newton=t_newton / OMEGAS.size,
                t_cont=t_cont / n_cont)


def part_b(repeat):
    print("(b) ContactPatch.evaluate throughput, linear law, H=(0,1,2,3), T=256, stick/slip/lift-off mix")
    basis = HarmonicBasis((0, 1, 2, 3), 256)
    C = basis.n_coeffs
    print(f"    {'points':>6} {'states s/sl/sep':>18} {'no Jacobian':>22} {'with Jacobian':>22}")
    for n_xi, n_eta in [(1, 1), (3, 5), (5, 10), (10, 20)]:
        patch = ContactPatch(0.004, 0.02, 1e5, 0.4, LinearNormalLaw(2e5), n_xi, n_eta)
        offset = patch.approach_for_load(10.0)
        scale = np.array([1e-4, 1e-4, 0.8 * offset.mean(), 0.8 * offset.mean() / 0.02,
                          0.8 * offset.mean() / 0.004, 1e-4 / 0.02])
        w = np.random.default_rng(0).normal(size=(C, 6)) * scale / np.sqrt(C)
        patch.evaluate(w, basis, offset)  # warm-up
        ev = patch.evaluate(w, basis, offset, jacobian=False)
        counts = np.bincount(ev.points.state.ravel(), minlength=3) / ev.points.state.size
        work = patch.n_points * basis.n_samples
        out = []
        for jac in (False, True):
            reps = max(3, int(2000 / patch.n_points)) * repeat
            t0 = time.perf_counter()
            for _ in range(reps):
                patch.evaluate(w, basis, offset, jacobian=jac)
            t = (time.perf_counter() - t0) / reps
            out.append(f"{work / t / 1e6:6.2f} M/s ({1e3 * t:7.3f} ms)")
        states = "/".join(f"{100 * c:.0f}" for c in counts) + " %"
        print(f"    {patch.n_points:>6} {states:>18} {out[0]:>22} {out[1]:>22}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="one repetition instead of five")
    args = parser.parse_args()
    repeat = 1 if args.quick else 5
    print(f"bladedamp engine benchmark, {datetime.date.today()}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}, "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    if hasattr(os, "getloadavg"):
        print(f"load average before the run: {os.getloadavg()[0]:.2f} (other processes distort the timings)")
    with warnings.catch_warnings():
        warnings.simplefilter("error")      # a benchmark run must not hide a non-converged point
        part_a(repeat)
        part_b(repeat)


if __name__ == "__main__":
    main()
