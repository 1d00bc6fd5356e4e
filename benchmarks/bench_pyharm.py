"""bladedamp against pyHarm, side by side on shared problems (issue 15, item 3).

pyHarm (PyPI ``pyharm-os``, Safran's open harmonic-balance code) is optional: it is no
dependency of bladedamp, nor of its tests. Run this with a Python that has both::

    python3 -m venv /tmp/pyharm-venv
    /tmp/pyharm-venv/bin/pip install pyharm-os
    /tmp/pyharm-venv/bin/pip install -e .                            # this checkout
    /tmp/pyharm-venv/bin/python benchmarks/bench_pyharm.py           # ~1.5-2 minutes on 2 cores
    /tmp/pyharm-venv/bin/python benchmarks/bench_pyharm.py --quick   # one repetition per timing

Two problems, defined once here and built in each code from the same numbers (SI inside, rad/s
for omega; bladedamp's public frequency arguments are Hz):

* ``oscillator``: the 1-DOF Jenkins oscillator m x'' + c x' + k x + f_J = F cos(Omega t),
  m = 1 kg, k = 1e4 N/m, c = 2 N s/m, Jenkins k_t = 1e4 N/m, mu = 0.3, N = 3 N, F = 2 N,
  Omega = 90..140 rad/s (the engine benchmark's; gross slip at the peak). bladedamp:
  ``FrictionOscillator``; pyHarm: a 1-node substructure, ``CosinusForcing`` and a ``Jenkins``
  connector to ground.
* ``chain``: a lumped bladed disk (pyHarm's documentation has one, but neither its wheel nor
  its sdist ships the tutorials, and its site is out of reach here: built from scratch), 8
  sectors of 2 DOF (blade tip m_b = 0.2 kg on k_b = 2e5 N/m to a disk mass m_d = 1 kg,
  k_d = 5e6 N/m to ground, neighbouring disk masses coupled by k_c = 2e5 N/m), a Jenkins damper between neighbouring blade tips (k_t = 5e4 N/m, mu = 0.3,
  N = 5 N), damping C = 1e-5 K, engine-order 2 excitation F = 1 N on every blade tip (phase
  2 pi EO i / n), 150..210 Hz (the ND 2 blade mode: 159 Hz free, 195 Hz stuck, peak 181.7 Hz).
  bladedamp: a ``HarmonicBalanceSystem`` of M, D, K with ``.add(PointContactElement(8 points),
  map)`` (normal load constant, no lift-off: the Jenkins element); pyHarm: one 16-node
  substructure, 8 ``GOForcing`` and 8 ``Jenkins`` connectors.

Both codes get the same harmonics (1, 3, 5, 7) and time samples (128), and build the same
discrete equations (their residuals at a common point agree to rounding, which the script
checks). Continuation in both: the arc length measured with x / X (X = 4 mm, 30 um: about the
peak amplitude) and Omega / (range width), first step 0.01, longest 0.02, shortest 1e-7, each
code's own predictor, corrector, step control and Newton tolerances (bladedamp
``continuation``'s defaults; pyHarm's defaults: tangent predictor, arc-length corrector,
``scipyroot`` (MINPACK hybr), step doubling after 5 accepted points), except that pyHarm also
accepts hybr's status 5 at |R| <= 1e-10 |f| (see ``ph_common``: its default rejects points
hybr has solved to rounding, and a fixed-frequency sweep then never ends).

Measured, all in one process (warm: numba caches loaded, one untimed run of each first):

* continuation over the range: wall time / points (building the system and the start solution
  included), and the continuation's residual / Jacobian evaluations per point;
* Newton at fixed frequencies (11 or 13 equally spaced), warm-started from the previous one
  (bladedamp: ``hbm.start.damped_newton``; pyHarm: its FRF analysis with the
  ``nocontinuation`` corrector, ``previous`` predictor and a constant frequency step, hybr);
* one residual + Jacobian evaluation at the same state;
* accuracy of the first-harmonic amplitude of x (oscillator) / of blade 0's tip (chain)
  against a reference at the fixed frequencies: the Newton amplitudes, and each continuation
  branch interpolated there (cubic spline in Omega; adds the interpolation error of its point
  density). Reference: oscillator, time integration (``FrictionOscillator.time_response``,
  8192 steps per period, settled to 1e-11 per period); chain, a fine HBM (bladedamp, odd
  harmonics 1..31, 1024 samples), its error estimated by the change from odd 1..15, 512 samples;
* whole process: a fresh ``python -c`` subprocess per code that imports it, builds the problem
  and computes the FRF (the continuation above), wall time from launch to exit; for the
  oscillator also bladedamp's public ``FrictionOscillator.frequency_response`` (which adds its
  start, physical checks and harmonic-error estimate).
"""
from __future__ import annotations

import argparse
import cProfile
import datetime
import json
import os
import platform
import pstats
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass

# small matrices: BLAS threads only add synchronisation (see bench_engine.py)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# pyHarm records its running kernels in ./.pyHarm/context.json at import (cwd: the checkout)
# unless this variable names another file; keep that out of the work tree (it also writes its
# settings to ~/.pyHarm/settings.json)
os.environ.setdefault("PYHARM_CONTEXT_FILE", os.path.join(tempfile.gettempdir(), "bench_pyharm", "context.json"))

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402

from _timing import best_of  # noqa: E402

# nothing of bladedamp or pyHarm is imported at module level: the whole-process runs import
# this module and then only the code they time

HARMONICS = (1, 3, 5, 7)
SAMPLES = 128
FIRST_STEP, MAX_STEP, MIN_STEP = 0.01, 0.02, 1e-7


@dataclass(frozen=True)
class Problem:
    name: str
    omega_range: tuple       # [rad/s]
    x_scale: float           # X of the arc length [m]
    n_fixed: int             # fixed frequencies of the Newton sweeps


OSCILLATOR = Problem("oscillator", (90.0, 140.0), 4e-3, 11)
CHAIN = Problem("chain", (2 * np.pi * 150.0, 2 * np.pi * 210.0), 3e-5, 13)
PROBLEMS = {p.name: p for p in (OSCILLATOR, CHAIN)}

OSC = dict(mass=1.0, stiffness=1e4, damping=2.0, contact_stiffness=1e4, friction_coefficient=0.3,
           normal_load=3.0, forcing=2.0)
# chain: blades, engine order, masses [kg], stiffnesses [N/m], friction, normal load [N],
# forcing [N], stiffness-proportional damping [s]
CH = dict(n=8, eo=2, m_blade=0.2, m_disk=1.0, k_blade=2e5, k_disk=5e6, k_coupling=2e5, k_t=5e4, mu=0.3,
          normal_load=5.0, forcing=1.0, beta=1e-5)


def fixed_omegas(problem: Problem) -> np.ndarray:
    return np.linspace(*problem.omega_range, problem.n_fixed)


# ----- the chain's matrices (shared by both codes) -------------------------------------------
def chain_matrices():
    """M, K (2n x 2n) of the lumped disk; DOF 2i is blade i's tip, 2i + 1 its disk mass."""
    n = CH["n"]
    N = 2 * n
    M, K = np.zeros((N, N)), np.zeros((N, N))

    def spring(i, j, k):
        K[i, i] += k
        K[j, j] += k
        K[i, j] -= k
        K[j, i] -= k

    for i in range(n):
        b, d = 2 * i, 2 * i + 1
        M[b, b], M[d, d] = CH["m_blade"], CH["m_disk"]
        spring(b, d, CH["k_blade"])
        K[d, d] += CH["k_disk"]
        spring(d, 2 * ((i + 1) % n) + 1, CH["k_coupling"])
    return M, K


def chain_phases():
    n = CH["n"]
    return 2 * np.pi * CH["eo"] * np.arange(n) / n


# ----- bladedamp ---------------------------------------------------------------------------
def bd_system(problem: Problem, harmonics=HARMONICS, n_samples=SAMPLES):
    """bladedamp's HarmonicBalanceSystem of the problem, and the index of the response DOF."""
    if problem.name == "oscillator":
        from bladedamp import FrictionOscillator
        return FrictionOscillator(**OSC).hbm_system(harmonics, n_samples), 0
    from bladedamp.contact.laws import LinearNormalLaw
    from bladedamp.contact.point import PointContactElement
    from bladedamp.hbm.fourier import HarmonicBasis
    from bladedamp.hbm.system import HarmonicBalanceSystem

    basis = HarmonicBasis(tuple(harmonics), n_samples)
    C, n = basis.n_coeffs, CH["n"]
    N = 2 * n
    M, K = chain_matrices()
    f = np.zeros(C * N)
    j = basis.cos_index(1)
    phi = chain_phases()
    f[j * N + 2 * np.arange(n)] = CH["forcing"] * np.cos(phi)        # F cos(Omega t - phi_i)
    f[(j + 1) * N + 2 * np.arange(n)] = CH["forcing"] * np.sin(phi)
    zero = np.zeros(C * N)
    linear = HarmonicBalanceSystem(basis, M, CH["beta"] * K, K, lambda omega: (f, zero))
    # damper p: relative tangential displacement of tips p and p + 1 (xi); eta, zeta stay 0, so
    # the normal load stays N (k_N is then irrelevant) and the point contact is a Jenkins element
    T0 = np.zeros((3 * n, N))
    for p in range(n):
        T0[3 * p, 2 * p], T0[3 * p, 2 * ((p + 1) % n)] = 1.0, -1.0
    contact = PointContactElement(np.full(n, CH["k_t"]), np.full(n, CH["mu"]), LinearNormalLaw(CH["k_t"]),
                                  np.ones(n), np.full(n, CH["normal_load"] / CH["k_t"]))
    return linear.add(contact, np.kron(np.eye(C), T0), "dampers"), 0


def bd_amplitude(system, x, dof):
    """First-harmonic amplitude of DOF ``dof`` of (..., N) unknowns [m]."""
    N, j = system.n_dof, system.basis.cos_index(1)
    x = np.atleast_2d(x)
    return np.hypot(x[:, j * N + dof], x[:, (j + 1) * N + dof])


def bd_start(system, omega, x_scale):
    """The first point as bladedamp's models get it: robust_start from the stuck and the free
    linear solutions (FrictionOscillator does the same)."""
    from bladedamp.hbm.start import robust_start
    R, J, _ = system.residual(np.zeros(system.n_unknowns), omega)
    guesses = {"stuck linear": -np.linalg.solve(J, R), "free linear": system.linear_solution(omega)}
    return robust_start(system.residual, guesses, omega, x_scale, system.excitation(omega)[0]).x


class Counted:
    """A residual (x, omega[, jacobian]) that counts its calls with and without the Jacobian."""

    def __init__(self, fun):
        self.fun, self.jac, self.res = fun, 0, 0

    def __call__(self, x, omega, jacobian=True):
        if jacobian:
            self.jac += 1
        else:
            self.res += 1
        return self.fun(x, omega, jacobian)


def bd_frf(problem: Problem, harmonics=HARMONICS, n_samples=SAMPLES):
    """bladedamp: build, start, continuation over the range. (branch, system, dof, counter)."""
    from bladedamp.hbm.continuation import continuation
    system, dof = bd_system(problem, harmonics, n_samples)
    w0, w1 = problem.omega_range
    fun = Counted(system.residual)
    x0 = bd_start(system, w0, problem.x_scale)
    branch = continuation(fun, x0, w0, w1, x_scale=problem.x_scale, step=FIRST_STEP, max_step=MAX_STEP,
                          min_step=MIN_STEP)
    if not branch.success:
        raise RuntimeError(f"bladedamp continuation failed on {problem.name}: {branch.message}")
    return branch, system, dof, fun


def bd_newton_sweep(problem: Problem, omegas, harmonics=HARMONICS, n_samples=SAMPLES, x0=None, max_iter=60):
    """Newton at each frequency, started from the previous solution (the first from ``x0`` or
    the stuck linear solution); (amplitudes, solutions). bladedamp's damped Newton
    (``hbm.start.damped_newton``, backtracking on |R|): the plain one (``continuation.newton``,
    the corrector's) cycles at 180 Hz on the chain's 5 Hz steps."""
    from bladedamp.hbm.start import damped_newton
    system, dof = bd_system(problem, harmonics, n_samples)
    if x0 is None:
        R, J, _ = system.residual(np.zeros(system.n_unknowns), omegas[0])
        x0 = -np.linalg.solve(J, R)
    scale = np.linalg.norm(system.excitation(omegas[0])[0])
    x, out = np.asarray(x0, dtype=float), []
    for w in omegas:
        x, converged, _ = damped_newton(lambda y, jac, w=w: system.residual(y, w, jac)[:2], x, problem.x_scale,
                                        scale, max_iter=max_iter)
        if not converged:
            raise RuntimeError(f"bladedamp Newton did not converge at {w:.6g} rad/s ({problem.name})")
        out.append(x)
    out = np.array(out)
    return bd_amplitude(system, out, dof), out


# ----- pyHarm ------------------------------------------------------------------------------
PYHARM_SUB = {"oscillator": "osc", "chain": "chain"}


def ph_input(problem: Problem, analysis: dict, harmonics=HARMONICS, n_samples=SAMPLES) -> dict:
    """pyHarm's input dictionary of the problem (``adim``: x / X and Omega / range width, the
    same arc-length measure as bladedamp's)."""
    w0, w1 = problem.omega_range
    system = {"type": "Base", "nh": list(harmonics), "nti": n_samples,
              "adim": {"status": True, "lc": problem.x_scale, "wc": w1 - w0}}
    if problem.name == "oscillator":
        matrix = {"M": np.array([[OSC["mass"]]]), "K": np.array([[OSC["stiffness"]]]),
                  "C": np.array([[OSC["damping"]]])}
        connectors = {
            "forcing": {"type": "CosinusForcing", "connect": {"osc": [0]}, "dirs": [0], "amp": OSC["forcing"]},
            "jenkins": {"type": "Jenkins", "connect": {"osc": [0]}, "dirs": [0], "mu": OSC["friction_coefficient"],
                        "N0": OSC["normal_load"], "k": OSC["contact_stiffness"]},
        }
        sub = "osc"
    else:
        M, K = chain_matrices()
        matrix = {"M": M, "K": K, "C": CH["beta"] * K}
        n, phi = CH["n"], chain_phases()
        connectors = {}
        for i in range(n):
            # load vector (cos phi, sin phi) on (cos, sin) of harmonic 1: F cos(Omega t - phi_i)
            connectors[f"forcing {i}"] = {"type": "GOForcing", "connect": {"chain": [2 * i]}, "dirs": [0],
                                          "dto": 0, "ho": 1, "phi": float(phi[i]), "amp": CH["forcing"]}
            connectors[f"damper {i}"] = {"type": "Jenkins", "connect": [("chain", [2 * i]),
                                                                         ("chain", [2 * ((i + 1) % n)])],
                                         "dirs": [0], "mu": CH["mu"], "N0": CH["normal_load"], "k": CH["k_t"]}
        sub = "chain"
    return {"system": system,
            "substructures": {sub: {"type": "substructure", "ndofs": 1, "matrix": matrix}},
            "connectors": connectors,
            "analysis": {"frf": analysis}}


def forcing_norm(problem: Problem) -> float:
    """|f| of the harmonic excitation vector [N] (bladedamp's default residual scale)."""
    return OSC["forcing"] if problem.name == "oscillator" else CH["forcing"] * np.sqrt(CH["n"])


def ph_common(problem: Problem) -> dict:
    """Options of both pyHarm analyses. MINPACK's hybr ends with status 5 ("not making good
    progress") when it starts next to the solution and the residual is already at rounding
    (measured: |R| = 6.5e-16 N), which pyHarm's default (accept status 1 only) rejects: the
    fixed-frequency sweep of the chain then retried the same point until its 1 h timeout. So
    status 5 is accepted where |R| <= 1e-10 |f|, bladedamp's Newton tolerance (``tol`` 1e-10 on
    |R| / |f|); the timeout is cut to 10 min."""
    return {"verbose": False,
            "solver_options": {"end_status_accepted": [1, 5], "residual_tolerance": 1e-10 * forcing_norm(problem)},
            "stopper_options": {"timeout": {"status": True, "timeout": "00:00:10:00"}}}


def ph_continuation_analysis(problem: Problem) -> dict:
    w0, w1 = problem.omega_range
    return {"study": "frf", "puls_inf": w0, "puls_sup": w1, **ph_common(problem),
            "ds0": FIRST_STEP, "ds_max": MAX_STEP, "ds_min": MIN_STEP}


def ph_sweep_analysis(problem: Problem, omegas) -> dict:
    """Fixed frequencies: no continuation, previous solution as predictor, constant step in
    Omega; the bound just below the last frequency stops it there. The fold detection is off
    (it would reverse a fixed-frequency sweep at a sign change of det J)."""
    w0, w1 = problem.omega_range
    dw = (omegas[1] - omegas[0]) / (w1 - w0)         # adimensional step
    return {"study": "frf", "puls_inf": omegas[0], "puls_sup": omegas[-1] - 0.5 * (omegas[1] - omegas[0]),
            **ph_common(problem), "corrector": "nocontinuation", "predictor": "previous",
            "predictor_options": {"bifurcation_detect": False}, "stepsizer": "constant",
            "ds0": dw, "ds_max": dw, "ds_min": 1e-3 * dw}


def _quiet_pyharm():
    import logging
    logging.disable(logging.CRITICAL)          # pyHarm logs a banner and every point
    try:
        from numba.core.errors import NumbaPerformanceWarning
        warnings.simplefilter("ignore", NumbaPerformanceWarning)   # printed when its kernels compile
    except ImportError:
        pass


def ph_layout(edf, basis, dof_of_node):
    """Index into bladedamp's unknowns of each of pyHarm's (its rows: sub, harm, cs, node)."""
    N = max(dof_of_node.values()) + 1
    out = np.empty(len(edf), dtype=int)
    for r, (h, cs, node) in enumerate(zip(edf["harm"], edf["cs"], edf["node_num"])):
        out[r] = (basis.cos_index(int(h)) + (cs == "s")) * N + dof_of_node[int(node)]
    return out


def ph_amplitude_index(edf, problem: Problem, node=0):
    rows = edf.reset_index(drop=True)
    sel = (rows["sub"] == PYHARM_SUB[problem.name]) & (rows["node_num"] == node) & (rows["harm"] == 1)
    return int(rows.index[sel & (rows["cs"] == "c")][0]), int(rows.index[sel & (rows["cs"] == "s")][0])


def ph_run(problem: Problem, analysis: dict, count=False):
    """pyHarm: build (Maestro) and solve. (omega [rad/s], amplitude [m], accepted, solves,
    x (points, ndof) [m], maestro, counts)."""
    from pyHarm.Maestro import Maestro
    _quiet_pyharm()
    m = Maestro(ph_input(problem, analysis))
    counts = {"res": 0, "jac": 0}
    if count:
        res, jac = m.system.Residual, m.system.Jacobian

        def counted_res(q):
            counts["res"] += 1
            return res(q)

        def counted_jac(q):
            counts["jac"] += 1
            return jac(q)

        m.system.Residual, m.system.Jacobian = counted_res, counted_jac
    m.operate()
    sols = m.nls["frf"].SolList
    ok = [s for s in sols if s.flag_accepted]
    lc, wc = m.system.lc, m.system.wc
    x = np.array([s.x[:-1] for s in ok]) * lc
    omega = np.array([s.x[-1] for s in ok]) * wc
    ic, is_ = ph_amplitude_index(m.system.expl_dofs, problem)
    return omega, np.hypot(x[:, ic], x[:, is_]), len(ok), len(sols), x, m, counts


def ph_frf(problem: Problem, count=False):
    out = ph_run(problem, ph_continuation_analysis(problem), count)
    if out[0].max() < problem.omega_range[1] * (1 - 1e-6):
        raise RuntimeError(f"pyHarm continuation stopped at {out[0].max():.6g} rad/s ({problem.name})")
    return out


def ph_newton_sweep(problem: Problem, omegas):
    omega, amp, accepted, solves, x, m, _ = ph_run(problem, ph_sweep_analysis(problem, omegas))
    if accepted != len(omegas) or not np.allclose(omega, omegas, rtol=1e-9):
        raise RuntimeError(f"pyHarm fixed-frequency sweep: {accepted} of {solves} solves accepted at "
                           f"{np.round(omega, 3)} rad/s, expected {np.round(omegas, 3)} ({problem.name})")
    return amp, x, m


# ----- whole process -----------------------------------------------------------------------
def process(code: str, problem_name: str):
    """What the whole-process subprocess runs: import the code, build the problem, the FRF;
    prints one JSON line (import and solve times, points)."""
    t0 = time.perf_counter()
    problem = PROBLEMS[problem_name]
    if code == "pyharm":
        import importlib
        importlib.import_module("pyHarm.Maestro")
        t1 = time.perf_counter()
        points = ph_frf(problem)[2]
    elif code == "bladedamp":
        import bladedamp  # noqa: F401
        t1 = time.perf_counter()
        points = bd_frf(problem)[0].omega.size
    elif code == "bladedamp-public":      # FrictionOscillator.frequency_response, Hz at the API
        import bladedamp
        t1 = time.perf_counter()
        w0, w1 = problem.omega_range
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            frf = bladedamp.FrictionOscillator(**OSC).frequency_response(
                w0 / (2 * np.pi), w1 / (2 * np.pi), harmonics=HARMONICS, n_samples=SAMPLES, max_step=MAX_STEP)
        if not frf.success:
            raise RuntimeError(frf.message)
        points = frf.omega.size
    else:
        raise ValueError(code)
    print(json.dumps({"import": t1 - t0, "solve": time.perf_counter() - t1, "points": int(points)}))


def whole_process(code: str, problem: Problem, repeat: int):
    """(best wall time [s] of a fresh interpreter from launch to exit, its JSON report)."""
    cmd = [sys.executable, "-c", f"import sys; sys.path.insert(0, {HERE!r}); import bench_pyharm as b; "
                                 f"b.process({code!r}, {problem.name!r})"]
    best, report = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy())
        t = time.perf_counter() - t0
        if out.returncode != 0:
            raise RuntimeError(f"whole-process run of {code} on {problem.name} failed:\n{out.stderr[-2000:]}")
        if t < best:
            best, report = t, json.loads(out.stdout.strip().splitlines()[-1])
    return best, report


# ----- references --------------------------------------------------------------------------
def reference(problem: Problem, omegas, start):
    """(amplitudes, description, estimated error) of the reference at ``omegas``."""
    if problem.name == "oscillator":
        from bladedamp import FrictionOscillator
        osc = FrictionOscillator(**OSC)
        ti = osc.time_response(omegas / (2 * np.pi), steps_per_period=8192, tol=1e-11)
        if not ti.converged.all():
            raise RuntimeError("reference time integration did not settle")
        hbm = bd_newton_sweep(problem, omegas, tuple(range(1, 32, 2)), 1024)[0]
        return ti.amplitude, "time integration, 8192 steps/period, settled to 1e-11", \
            float(np.abs(hbm / ti.amplitude - 1).max()), "vs HBM odd 1..31, T = 1024"
    # chain: fine HBM from the H = (1, 3, 5, 7) Newton solutions, harmonics added as zeros
    from bladedamp.hbm.fourier import HarmonicBasis
    levels = [(tuple(range(1, 16, 2)), 512), (tuple(range(1, 32, 2)), 1024)]
    amps = []
    coarse = HarmonicBasis(HARMONICS, SAMPLES)
    N = 2 * CH["n"]
    for H, T in levels:
        fine = HarmonicBasis(H, T)
        x0 = np.zeros(fine.n_coeffs * N)
        for j, h in enumerate(coarse.order):
            k = fine.cos_index(h) + (j != coarse.cos_index(h))
            x0[k * N:(k + 1) * N] = start[0][j * N:(j + 1) * N]
        amps.append(bd_newton_sweep(problem, omegas, H, T, x0=x0)[0])
    return amps[-1], "HBM (bladedamp) odd harmonics 1..31, T = 1024", \
        float(np.abs(amps[0] / amps[-1] - 1).max()), "change from odd 1..15, T = 512"


def interpolated(omega, amp, at):
    """Cubic spline of a branch's amplitude at ``at`` (NaN if the branch is not monotone in omega)."""
    from scipy.interpolate import CubicSpline
    order = np.argsort(omega)
    omega, amp = omega[order], amp[order]
    if np.any(np.diff(omega) <= 0):
        return np.full(len(at), np.nan)
    return CubicSpline(omega, amp)(at)


# ----- one problem -------------------------------------------------------------------------
def per_call_us(fun, seconds=0.3):
    fun()
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        fun()
        n += 1
    return (time.perf_counter() - t0) / n * 1e6


def run_problem(problem: Problem, repeat: int, process_repeat: int):
    omegas = fixed_omegas(problem)
    print(f"\n## {problem.name}: Omega = {problem.omega_range[0]:.2f}..{problem.omega_range[1]:.2f} rad/s "
          f"({problem.omega_range[0] / 2 / np.pi:.3f}..{problem.omega_range[1] / 2 / np.pi:.3f} Hz), "
          f"harmonics {HARMONICS}, {SAMPLES} samples, X = {problem.x_scale:g} m")
    # warm-up (numba caches, first-call costs) of both
    bd_frf(problem)
    ph_frf(problem)

    # continuation
    t_bd, (branch, system, dof, counter) = best_of(lambda: bd_frf(problem), repeat)
    t_ph, (ph_om, ph_amp, ph_acc, ph_solves, ph_x, m, ph_counts) = best_of(lambda: ph_frf(problem, True), repeat)
    n_bd = branch.omega.size
    bd_amp = bd_amplitude(system, branch.x, dof)

    # fixed frequencies
    t_bd_n, (bd_sweep, bd_sweep_x) = best_of(lambda: bd_newton_sweep(problem, omegas), repeat)
    t_ph_n, (ph_sweep, ph_sweep_x, _) = best_of(lambda: ph_newton_sweep(problem, omegas), repeat)

    # the same discrete equations: pyHarm's residual at bladedamp's solutions, and the reverse
    layout = ph_layout(m.system.expl_dofs, system.basis, {k: k for k in range(system.n_dof)})
    lc, wc = m.system.lc, m.system.wc
    f_norm = np.linalg.norm(system.excitation(omegas[0])[0])
    r_ph = max(np.linalg.norm(m.system.Residual(np.append(x[layout] / lc, w / wc))) for x, w in
               zip(bd_sweep_x, omegas)) / f_norm
    inverse = np.empty_like(layout)
    inverse[layout] = np.arange(layout.size)
    r_bd = max(np.linalg.norm(system.residual(x[inverse], w, False)[0]) for x, w in
               zip(ph_sweep_x, omegas)) / f_norm
    sweep_diff = float(np.abs(ph_sweep / bd_sweep - 1).max())

    # one residual + Jacobian at the same state (the middle fixed frequency)
    k = len(omegas) // 2
    xk, wk = bd_sweep_x[k], omegas[k]
    us_bd = per_call_us(lambda: system.residual(xk, wk))
    qk = np.append(xk[layout] / lc, wk / wc)
    us_ph = per_call_us(lambda: (m.system.Residual(qk), m.system.Jacobian(qk)))

    # accuracy
    t_ref = time.perf_counter()
    ref, ref_name, ref_err, ref_check = reference(problem, omegas, bd_sweep_x)
    t_ref = time.perf_counter() - t_ref
    err = {
        "bd newton": np.abs(bd_sweep / ref - 1).max(),
        "ph newton": np.abs(ph_sweep / ref - 1).max(),
        "bd cont": np.abs(interpolated(branch.omega, bd_amp, omegas) / ref - 1).max(),
        "ph cont": np.abs(interpolated(ph_om, ph_amp, omegas) / ref - 1).max(),
    }
    print(f"reference: {ref_name} ({t_ref:.1f} s); its estimated error {ref_err:.1e} ({ref_check})")
    print(f"same equations: |R_pyHarm(bladedamp's Newton solutions)| / |f| <= {r_ph:.1e}, "
          f"|R_bladedamp(pyHarm's)| / |f| <= {r_bd:.1e}; the two Newton sweeps' amplitudes differ by "
          f"{sweep_diff:.1e} at most")
    i = np.argmax(bd_amp)
    print(f"peak (bladedamp branch): {bd_amp[i]:.4e} m at {branch.omega[i]:.3f} rad/s")

    # whole process
    procs = {}
    if process_repeat:
        codes = ["bladedamp", "pyharm"] + (["bladedamp-public"] if problem.name == "oscillator" else [])
        for code in codes:
            procs[code] = whole_process(code, problem, process_repeat)

    rows = [
        ("continuation: points on the range", f"{n_bd}", f"{ph_acc} ({ph_solves} solves)", None),
        ("  total [s]", f"{t_bd:.3f}", f"{t_ph:.3f}", t_ph / t_bd),
        ("  ms / point", f"{1e3 * t_bd / n_bd:.3f}", f"{1e3 * t_ph / ph_acc:.3f}", (t_ph / ph_acc) / (t_bd / n_bd)),
        ("  residual + Jacobian evals / point", f"{counter.jac / n_bd:.1f}",
         f"{ph_counts['jac'] / ph_acc:.1f} J + {ph_counts['res'] / ph_acc:.1f} R", None),
        ("  max error, interpolated", f"{err['bd cont']:.1e}", f"{err['ph cont']:.1e}", None),
        (f"Newton, {len(omegas)} fixed frequencies: ms / point", f"{1e3 * t_bd_n / len(omegas):.3f}",
         f"{1e3 * t_ph_n / len(omegas):.3f}", t_ph_n / t_bd_n),
        ("  max error", f"{err['bd newton']:.1e}", f"{err['ph newton']:.1e}", None),
        ("one residual + Jacobian [us]", f"{us_bd:.0f}", f"{us_ph:.0f}", us_ph / us_bd),
    ]
    for code, (t, rep) in procs.items():
        if code == "pyharm":
            continue
        label = "whole process [s] (import + FRF)" if code == "bladedamp" else \
            "  same, bladedamp frequency_response"
        tp, rp = procs["pyharm"]
        rows.append((label, f"{t:.2f} ({rep['import']:.2f} + {rep['solve']:.2f}, {rep['points']} pts)",
                     f"{tp:.2f} ({rp['import']:.2f} + {rp['solve']:.2f}, {rp['points']} pts)", tp / t))
    print(f"{'':<40} {'bladedamp':>30} {'pyHarm':>30} {'pyHarm / bladedamp':>19}")
    for name, a, b, ratio in rows:
        r = f"{ratio:.1f}x" if ratio is not None else ""
        print(f"{name:<40} {a:>30} {b:>30} {r:>19}")
    return dict(t_bd=t_bd / n_bd, t_ph=t_ph / ph_acc, procs=procs)


def profile(problem: Problem):
    """Where each code's continuation spends its time (cProfile, which inflates Python overhead)."""
    print(f"\n## profile of one continuation, {problem.name} (cProfile: shares of the run time)")

    def shares(fun, names):
        prof = cProfile.Profile()
        prof.enable()
        fun()
        prof.disable()
        stats = pstats.Stats(prof).stats
        total = max(v[3] for v in stats.values())
        for label, pattern in names:
            keys = pattern.split("|")
            cum = max([v[3] for kk, v in stats.items() if kk[2] in keys or f"{os.path.basename(kk[0])}:{kk[2]}" in keys]
                      or [0.0])
            print(f"    {label:<58} {100 * cum / total:5.1f} %")

    print("  bladedamp")
    shares(lambda: bd_frf(problem), [
        ("residual + Jacobian (HarmonicBalanceSystem.residual)", "system.py:residual"),
        ("  contact AFT + Jacobian (PointContactElement.harmonic_forces)", "harmonic_forces"),
        ("    fused numba contact kernel (point_contact_harmonics)", "point_contact_harmonics"),
        ("  dynamic stiffness", "dynamic_stiffness"),
        ("linear solves (factorize)", "linsolve.py:factorize"),
    ])
    print("  pyHarm")
    shares(lambda: ph_frf(problem), [
        ("System.Residual", "System.py:Residual"),
        ("  element residuals (ABCSystem._residual)", "_residual"),
        ("    JenkinsResidual (numba)", "JenkinsResidual"),
        ("System.Jacobian", "System.py:Jacobian"),
        ("  element Jacobians (ABCSystem._jacobian)", "_jacobian"),
        ("    JenkinsJacobian (numba)", "JenkinsJacobian"),
        ("scipy.optimize.root (hybr)", "root"),
        ("predictor (QR of J, 2 determinants)", "PredictorTangent.py:predict"),
        ("reductor update (one more Jacobian at the prediction)", "_update_reductor"),
        ("CompleteSolution (R and J again at the solution)", "CompleteSolution"),
    ])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="one repetition per timing")
    parser.add_argument("--problems", nargs="*", default=list(PROBLEMS), choices=list(PROBLEMS))
    parser.add_argument("--no-process", action="store_true", help="skip the whole-process runs")
    parser.add_argument("--profile", action="store_true", help="also profile one continuation of each code")
    args = parser.parse_args(argv)
    try:
        import pyHarm
    except ImportError as exc:
        sys.exit(f"bench_pyharm: pyHarm is not importable ({exc}); it is optional: run this with a venv that has "
                 f"it (pip install pyharm-os) and bladedamp, see the docstring")
    _quiet_pyharm()
    import bladedamp
    import numba
    import scipy
    repeat = 1 if args.quick else 2
    print(f"bench_pyharm {datetime.date.today()}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"numba {numba.__version__}, pyHarm {pyHarm.__version__}, bladedamp {bladedamp.__version__}, "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    print(f"load average before the run: {' '.join(f'{x:.2f}' for x in os.getloadavg())} "
          f"(other processes distort the timings)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        for name in args.problems:
            run_problem(PROBLEMS[name], repeat, 0 if args.no_process else (1 if args.quick else 2))
            if args.profile:
                profile(PROBLEMS[name])
    print(f"\nload average after the run: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
