"""Random valid designs: every one must reach the end of its range with every branch check passing.

Issue 12: random tuned disks (cylinder or wedge, 0.02-50 g, EO 0-8, platform angles 15-85 deg,
mu 0.05-1, excitation x0.1-x10, linear or rough normal law, harmonics (1,) or (0, 1, 2, 3)) and
random friction oscillators (forcing / slip force 0.1-10, k_T / k 0.1-10, damping ratio
1e-3-5e-2, flat and inclined contacts). The generator is seeded; design i depends only on
SEED and i. The slow part runs all of them and prints two shares: those that reach the end with
every check passing, and those answered rightly, which adds the disks whose branch stops where
the product's own time integration (``check_stop``) finds no periodic motion and whose result
says so (the motion reached from rest is not periodic, so no harmonic-balance branch describes it). The fast part runs a few of each kind; a subset of
oscillators is checked against time integration.

Run the whole suite by hand with ``python tests/test_random_designs.py [processes]``.
"""
from __future__ import annotations

import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import bladedamp as bd
from bladedamp import FrictionOscillator
from bladedamp.blade import reference_blade
from bladedamp.damper.geometry import ContactProperties, CylinderDamper, WedgeDamper
from bladedamp.damper.kinetics import centrifugal_force
from bladedamp.disk import DiskResponse, TunedDisk
from bladedamp.diskmodel import RETENTION_HELD_LIMIT, retention_held, with_peak_check
from bladedamp.mistuned import MistunedDisk
from bladedamp.hbm.continuation import Branch, newton
from bladedamp.hbm.monodromy import full_assembly_coefficients
from bladedamp import reference as ref
from bladedamp.response import Status

SEED = 20261201
N_DISKS = 160
N_OSCILLATORS = 160
# issue 12's target is 0.99; measured 303 of 320 = 0.947 on 2026-12-06 (disks 143 of 160, oscillators
# 160 of 160; the 17 disks left all use (0, 1, 2, 3) at EO 3-8 and stop near 1F: 13 where no periodic
# motion exists, 4 on periodic motions with brief impacts, see ANSWERED_REQUIRED); 302 of 320 = 0.944
# on 2026-12-03, tenth session (disks 143
# of 160, oscillators 159 of 160: each contact's dissipation judged against its own energy scale,
# max(excitation work, pi sum_h h |F_h||W_h|), so an off-resonance branch whose tiny negative
# dissipation is AFT rounding no longer fails; inclined and time-checked oscillators run with
# harmonics 'auto' and count only when harmonics_converged; the 17 disks left: 14 retrace, stall
# or turn back near 94-95 Hz where the damper hops or rolls, 1 turns back at 90 Hz, 1 does not
# start, 1 misses the harmonic tolerance); 301 of 320 = 0.941 on 2026-12-02, sixth session (disks 143 of
# 160 with the retry of a failed branch with the damper's unknowns weighing less in the arc length,
# bladedamp.diskmodel.DAMPER_ARC_SCALE: random disks 16, 102 and 124; oscillators 158 of 160; the floor
# leaves 3 designs for rounding: disk 55 failed in the fifth session's venv and passes in this
# one); 296 of 320 = 0.925 on 2026-12-01, fourth session (disks
# 138 of 160, oscillators 158 of 160: the interpolated touchdown seat, the automatic AFT sampling
# and the branch from the end of the range where the one from the start fails); 277 = 0.866 in
# the third (271 = 0.847 before the corner fallbacks of the continuation and the refined
# dissipation check; 268 = 0.838 before the continuation's det orientation and its turn at
# non-smooth folds; 0.716 before the shared robust start, the hop acceptance and the range
# clip). Until the target is met this is a regression floor, not the target: the share is
# printed, and the failing designs with it.
SHARE_TARGET = 0.99
SHARE_REQUIRED = 0.93
# answered rightly: reached the end with every check passing, or stopped where the product's own
# time integration (check_stop) finds no periodic motion and the result says so. Measured 316 of
# 320 = 0.9875 on 2026-12-06 (the 4 others: periodic motions with brief impacts that (0, 1, 2, 3)
# cannot follow, disks 63, 67, 154, 105). Since the settle verdict judges the convergence of the
# period-to-period map, disk 120's stop check finds a periodic motion beyond its stop (1.92 mm,
# the damper separated all the period) that it called "not settled" before: 315 of 320 = 0.984375
# (2026-12-07), exactly that day's machine. On another machine (2026-12-07, fourth session) the same
# code answers 314: disk 35 (stops at max_points with an estimate of 8.2 %) and oscillator 95 (2.5 %
# against 1 %) both fail there, the same on main and on the branch; one of them passed on the first
# machine. A design at a non-smooth fold or a tolerance's edge flips with the BLAS kernel's rounding,
# and a verdict must not depend on the kernel: the floor allows that one flip and no other
ANSWERED_REQUIRED = 0.98
# Harmonics of the oscillators cross-checked by time integration, and of the random inclined
# oscillators (normal load varying with the motion, lifting off): the frequency_response default,
# "auto" (the harmonics chosen by their error estimate, static term included; (0, 1, 2, 3) was
# set here by hand before). A design run with "auto" that ends with harmonics_converged False
# (the tolerance not met) is not counted as accurate. Their AFT samples are the product's
# automatic choice too (None: at least 256 for an inclined contact, four times more while the
# branch fails, see bladedamp.response.sampled_response).
TIME_CHECK_HARMONICS = "auto"
INCLINED_HARMONICS = "auto"
INCLINED_N_SAMPLES = None
# a branch that needs more points than this at the suite's max_step has stalled
MAX_POINTS = 2000
N_TIME_CHECKS = 10
# The mistuned section (issue 32 item 7): N_MISTUNED random mistuned disks, random disk i of this
# generator written out as a full ring of MISTUNED_BLADES blades (not the reference 16: the default
# FRF of a 16-blade random mistuned disk took 43-103 CPU s, 7 of 10 over 90 s, and a ring's cost
# grows about as its blades^1.5 (points ~ sqrt(s) for s separate blade resonances, each point ~ s);
# benchmarks/README.md has the numbers), blade mistuning 1-5 % std, each run by default
# (harmonics 'auto') with a CPU budget of MISTUNED_CPU_BUDGET_S; every answer that reads as
# complete and verified is cross-checked by the library's own time integration at its peak
# (bladedamp.diskmodel.with_peak_check, started on the HBM state).
# Budget 30 CPU s, not the 60: measured on the 40 designs at 4 blades with 60 s, each
# finished within 28 CPU s or ran past 60, so the shares are the same and the section's CPU time
# falls from 1236 to about 800 CPU s (about 7 min of wall time on 2 cores; benchmarks/README.md).
# A start or an error estimate begun before the budget ran out is finished: the overrun measured
# was at most 16 CPU s (printed by the slow section, not asserted).
N_MISTUNED = 40
MISTUNED_BLADES = 4
MISTUNED_CPU_BUDGET_S = 30.0
# Complete-and-verified answers that the time integration at their peak contradicts (measured
# 2026-12-07, 4 of the 13 complete-verified: 11, 14, 17, 27; the slow test fails on any other and
# prints those of these it did not see): issue 32 item 1's work. Diagnosed on branch contradict
# (benchmarks/README.md, "Why the time integration contradicts four complete-and-verified
# answers"); branch trust cured two (benchmarks/README.md, "Four contradictions, two cured"):
# 27's peak is held by the HBM's static retention spring (15 % of the cylinder's F_CG R in the
# weak-spring limit, bladedamp.diskmodel.retention_held), so its default answer is COMPLETE_UNVERIFIED
# and says why; 17's direct estimate, 1.03 %, is within the tolerance plus the time integration's
# own error bar (0.12 %, the same run with twice the steps: bladedamp.diskmodel.peak_check_error);
# measured after (2026-12-07, branch trust): 9 of 40 complete-verified, contradicted 11 and 14. The
# two left need a time integration or the monodromy at the peak to be seen, which the default
# answer does not run (the monodromy costs 5-9 CPU s at 4 blades, about 13 times more at 16);
# their checked answers now say why:
KNOWN_MISTUNED_CONTRADICTIONS = {
    11: "(0, 1, 2, 3) verified by (0..5); at the peak, 98.78 Hz, the time integration from the HBM state does not "
        "settle (the first harmonics change by 4e-4 per period after 4000 periods): the peak lies on an unstable "
        "part of the branch, which the checked answer names (CHECK_FAILED, peak_stability_note: a complex pair "
        "|mu| 1.15, Neimark-Sacker, the HBM orbit 1.6 % from periodic); the default answer runs no monodromy",
    14: "(0, 1, 2, 3) verified by (0..5); at the peak, 94.80 Hz, the time integration from the HBM state does not "
        "settle (a residual drift of 0.0023 of the amplitude, the damper separated 21 % of the period), growing to "
        "+49 % while (0..7) agrees within 0.7 %; the HBM orbit is 73 % from periodic in the time integration's one "
        "period (the wedge's roll: its Floquet multipliers do not apply, which the checked answer says): a "
        "coexisting hopping motion or an instability, not resolved; the checked answer is CHECK_FAILED",
}
ROTOR_SPEED_95_HZ = 95.0   # EO = 0: the rotor speed of the EO = 1 resonance [Hz]


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def disk_design(i: int) -> dict:
    """Parameters of random disk i (a dict of plain values, picklable and printable)."""
    rng = np.random.default_rng([SEED, 0, i])
    return dict(kind=("disk", i),
                damper=str(rng.choice(["cylinder", "wedge"])),
                mass=_log_uniform(rng, 0.02e-3, 50e-3),
                engine_order=int(rng.integers(0, 9)),
                gamma_left=float(np.radians(rng.uniform(15, 85))),
                gamma_right=float(np.radians(rng.uniform(15, 85))),
                mu=float(rng.uniform(0.05, 1.0)),
                excitation_scale=_log_uniform(rng, 0.1, 10.0),
                table1=bool(rng.random() < 0.3),
                roughness_exponent=float(1.0 if rng.random() < 0.5 else rng.uniform(1.2, 2.0)),
                harmonics=(1,) if rng.random() < 0.5 else (0, 1, 2, 3),
                f_start=float(rng.uniform(80.0, 90.0)),
                f_end=float(rng.uniform(100.0, 120.0)),
                max_step=0.05)


def oscillator_design(i: int) -> dict:
    """Parameters of random friction oscillator i (m = k = 1: omega in units of the free frequency)."""
    rng = np.random.default_rng([SEED, 1, i])
    kt = _log_uniform(rng, 0.1, 10.0)
    zeta = _log_uniform(rng, 1e-3, 5e-2)
    mu = float(rng.uniform(0.05, 1.0))
    normal_load = _log_uniform(rng, 0.01, 1.0)
    ratio = _log_uniform(rng, 0.1, 10.0)                     # forcing / slip force
    angle = 0.0 if rng.random() < 0.5 else float(rng.uniform(0.05, 1.2))
    kn = kt * _log_uniform(rng, 0.5, 2.0)
    stuck = np.sqrt(1.0 + kt * np.cos(angle) ** 2 + kn * np.sin(angle) ** 2)
    draw = rng.random()
    return dict(kind=("oscillator", i),
                params=dict(mass=1.0, stiffness=1.0, damping=2 * zeta, contact_stiffness=kt,
                            friction_coefficient=mu, normal_load=normal_load,
                            forcing=ratio * mu * normal_load, contact_angle=angle, normal_stiffness=kn),
                harmonics=INCLINED_HARMONICS if angle > 0 else ((1,) if draw < 0.5 else (0, 1, 2, 3)),
                n_samples=INCLINED_N_SAMPLES if angle > 0 else None,
                omega_start=float(rng.uniform(0.3, 0.9)),
                omega_end=float(stuck * rng.uniform(1.2, 1.6)),
                max_step=0.05)


def make_disk(d: dict) -> TunedDisk:
    contact = ContactProperties(d["mu"], ref.TANGENTIAL_STIFFNESS_PER_LENGTH, ref.NORMAL_TO_TANGENTIAL,
                                d["roughness_exponent"], 10.0, ref.POINTS_ALONG_LENGTH, ref.POINTS_ACROSS_HEIGHT)
    damper = (CylinderDamper(d["mass"], ref.CYLINDER_RADIUS, ref.DAMPER_LENGTH, contact) if d["damper"] == "cylinder"
              else WedgeDamper(d["mass"], ref.WEDGE_CONTACT_HEIGHT, ref.DAMPER_LENGTH, contact))
    base = ref.EXCITATION_TABLE1 if d["table1"] else ref.EXCITATION_FX
    return TunedDisk(reference_blade(), damper, d.get("n_blades", ref.N_BLADES), d["engine_order"], d["gamma_left"],
                     d["gamma_right"],
                     ref.DAMPER_RADIUS, d["excitation_scale"] * base,
                     rotor_speed_hz=ROTOR_SPEED_95_HZ if d["engine_order"] == 0 else None)


def mistuned_design(i: int, n_blades: int | None = None) -> dict:
    """Parameters of random mistuned disk i: random disk i (:func:`disk_design`) on a ring of
    ``n_blades`` blades (default MISTUNED_BLADES), blade k's frequencies times
    kappa_k = 1 + sigma z_k, z_k standard normal, sigma uniform in 1-5 %."""
    rng = np.random.default_rng([SEED, 2, i])
    sigma = float(rng.uniform(0.01, 0.05))
    n = MISTUNED_BLADES if n_blades is None else int(n_blades)
    return dict(disk_design(i), kind=("mistuned", i), n_blades=n, sigma=sigma,
                kappa=tuple(1.0 + sigma * rng.standard_normal(n)))


def make_mistuned(d: dict) -> MistunedDisk:
    """The full assembly of random mistuned disk ``d`` (:func:`mistuned_design`)."""
    return MistunedDisk.from_tuned(make_disk(d), np.array(d["kappa"]))


def disk_response(disk: TunedDisk, d: dict, check_stop: bool = True) -> DiskResponse:
    """The frequency response of random disk ``d`` (``disk`` = make_disk(d)) over its range, as the
    suite runs it: a branch that stops before the end is checked by time integration just beyond
    its stop (``check_stop``, the product's own: whether a periodic motion exists there)."""
    return disk.frequency_response(d["f_start"], d["f_end"], harmonics=d["harmonics"], max_step=d["max_step"],
                                   max_points=MAX_POINTS, check_stop=check_stop)


def branch_checks(omega, lo, hi, max_step) -> list[str]:
    """Violations of the branch contract (item 2 of issue 12), empty if none."""
    bad = []
    omega = np.asarray(omega)
    if np.any(omega < lo * (1 - 1e-12)) or np.any(omega > hi * (1 + 1e-12)):
        bad.append(f"omega outside [{lo:.6g}, {hi:.6g}]: {omega.min():.6g}..{omega.max():.6g}")
    if len(omega) > 1 and np.abs(np.diff(omega)).max() > max_step * (hi - lo) * (1 + 1e-9):
        bad.append(f"step {np.abs(np.diff(omega)).max():.4g} rad/s longer than max_step x range")
    return bad


FINE_FACTOR = 16   # the re-evaluation of a suspect negative dissipation: 16 x the AFT samples


def resolved_dissipation(d, r, indices):
    """(k, m) dissipation at the points ``indices`` of response ``r`` of design ``d``, re-evaluated
    from the same harmonic coefficients with FINE_FACTOR x the AFT samples per period: every contact
    point of a disk's dampers, the contact of an oscillator. The suite's own check, written
    independently of the product's (bladedamp.response.physical_checks)."""
    H, fine_samples = r.basis.harmonics, FINE_FACTOR * r.basis.n_samples
    if d["kind"][0] == "disk":
        disk = make_disk(d)
        fine = disk.hbm_system(H, fine_samples)
        branch = Branch(r.omega[indices], r.coefficients[indices].reshape(len(indices), -1),
                        np.zeros(len(indices), dtype=int), True, "")
        return DiskResponse.from_branch(disk, fine, branch).point_dissipation.reshape(len(indices), -1)
    fine = FrictionOscillator(**d["params"]).hbm_system(H, fine_samples)
    return np.array([fine.element_dissipation(r.coefficients[i].ravel(), r.omega[i]) for i in indices])


def run_design(d: dict) -> dict:
    """Run one design; returns success, message, the violated checks and the time taken."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if d["kind"][0] == "disk":
            r = disk_response(make_disk(d), d)
            lo, hi = sorted((2 * np.pi * d["f_start"], 2 * np.pi * d["f_end"]))
            work = np.abs(r.excitation_work)[:, None]
            points = np.zeros((len(r.omega), 0)) if r.point_dissipation is None \
                else r.point_dissipation.reshape(len(r.omega), -1)
            bound = np.zeros_like(points) if r.point_work_bound is None else r.point_work_bound.reshape(points.shape)
        else:
            osc = FrictionOscillator(**d["params"])
            r = osc.frequency_response(d["omega_start"] / (2 * np.pi), d["omega_end"] / (2 * np.pi), harmonics=d["harmonics"],
                                       n_samples=d["n_samples"], max_step=d["max_step"], max_points=MAX_POINTS)
            lo, hi = sorted((d["omega_start"], d["omega_end"]))
            e = osc.energy_balance(r) if len(r.omega) else np.zeros((0, 3))
            work, points = np.abs(e[:, :1]), e[:, 2:]
            system = osc.hbm_system(r.basis.harmonics, r.basis.n_samples)
            bound = np.array([sum(system.element_work_bound(x.ravel(), w)) for x, w in zip(r.coefficients, r.omega)])
            bound = bound.reshape(-1, 1)
        bad = branch_checks(r.omega, lo, hi, d["max_step"])
        # a friction contact cannot give energy back over a period, whatever the harmonic
        # truncation (bladedamp.response.physical_checks has the argument): a value below
        # rounding (1e-9 of the energy scale: the larger of the excitation work and the contact's
        # work bound pi sum_h h |F_h||W_h|) is the AFT's sampling error, re-evaluated with
        # FINE_FACTOR x the samples, and fails if still below 1e-6 of that scale there
        if len(r.omega):
            scale = np.maximum(np.maximum(work, 1e-300), bound)
            relative = (points / scale).min(axis=1, initial=0.0)
            suspect = np.flatnonzero(relative < -1e-9)
            if suspect.size:
                relative[suspect] = (resolved_dissipation(d, r, suspect) / scale[suspect]).min(axis=1, initial=0.0)
            if np.any(relative < -1e-6):
                bad.append(f"negative dissipation {relative.min():.3g} of the energy scale "
                           f"(with {FINE_FACTOR} x the AFT samples)")
    omega_end = 2 * np.pi * d["f_end"] if d["kind"][0] == "disk" else d["omega_end"]
    reached = bool(len(r.omega)) and abs(r.omega[-1] - omega_end) <= 1e-9 * abs(omega_end)
    # a design whose harmonics were chosen automatically must meet the harmonic tolerance too
    inaccurate = d["harmonics"] == "auto" and r.harmonics_converged is False
    # a disk whose branch stopped where its time integration finds no periodic motion, and whose
    # result says so (check_stop): the right answer for the motion reached from rest, which no periodic
    # branch describes
    check = getattr(r, "stop_check", None)
    no_periodic_motion = (not reached and check is not None and not check.periodic[0]
                          and "finds no periodic motion" in r.message)
    return dict(kind=d["kind"], success=bool(r.success), reached=reached, message=r.message, bad=bad,
                harmonics=r.basis.harmonics, inaccurate=inaccurate, points=len(r.omega),
                no_periodic_motion=no_periodic_motion, seconds=time.perf_counter() - t0)


def run_mistuned(d: dict, time_check: bool = True) -> dict:
    """The default frequency response of random mistuned disk ``d`` (:func:`mistuned_design`)
    within MISTUNED_CPU_BUDGET_S, its status and CPU seconds; an answer whose status is
    COMPLETE_VERIFIED is checked by the time integration at its peak (``time_check``:
    :func:`bladedamp.diskmodel.with_peak_check`, the library's check_peak): ``contradicted`` holds the
    message where that check no longer finds the answer complete and verified (a periodic motion
    farther from the branch's peak than the harmonic tolerance, or none)."""
    disk = make_mistuned(d)
    t0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(d["f_start"], d["f_end"], max_step=d["max_step"], max_points=MAX_POINTS,
                                    cpu_budget_s=MISTUNED_CPU_BUDGET_S)
        cpu = time.process_time() - t0
        contradicted, checked_cpu = None, 0.0
        if time_check and r.status is Status.COMPLETE_VERIFIED:
            t1 = time.process_time()
            checked = with_peak_check(disk, r, True, r.harmonic_tolerance)
            checked_cpu = time.process_time() - t1
            if checked.status is not Status.COMPLETE_VERIFIED:
                contradicted = checked.message
    return dict(kind=d["kind"], status=r.status, message=r.message, cpu=cpu, check_cpu=checked_cpu,
                points=len(r.omega), harmonics=r.basis.harmonics, contradicted=contradicted)


def mistuned_summary(results) -> str:
    """The shares of complete-verified, complete-unverified (or above its tolerance),
    stopped-with-reason and out-of-budget answers, and every design's line."""
    n = len(results)
    groups = {"complete, verified": [Status.COMPLETE_VERIFIED],
              "complete, unverified or above tolerance": [Status.COMPLETE_UNVERIFIED, Status.COMPLETE_ABOVE_TOLERANCE],
              "stopped with a reason": [Status.STOPPED, Status.CHECK_FAILED],
              "out of budget": [Status.OUT_OF_BUDGET]}
    counts = {k: sum(r["status"] in v for r in results) for k, v in groups.items()}
    cpu = np.array([r["cpu"] for r in results])
    lines = [f"random mistuned disks ({MISTUNED_BLADES} blades, budget {MISTUNED_CPU_BUDGET_S:g} CPU s): "
             + "; ".join(f"{k} {c} of {n} ({100 * c / n:.0f} %)" for k, c in counts.items())
             + f"; CPU s median {np.median(cpu):.1f}, max {cpu.max():.1f}, {cpu.sum():.0f} in all, time checks "
               f"{sum(r['check_cpu'] for r in results):.0f} s"]
    for r in results:
        lines.append(f"  {r['kind']}: {r['status'].name}, {r['cpu']:.1f} CPU s, {r['points']} points, harmonics "
                     f"{r['harmonics']}" + (f", CONTRADICTED: {r['contradicted']}" if r["contradicted"] else ""))
    return "\n".join(lines)


def all_designs():
    return [disk_design(i) for i in range(N_DISKS)] + [oscillator_design(i) for i in range(N_OSCILLATORS)]


def run_all(designs, processes=None, run=None):
    """``run`` (default run_design; run_mistuned for the mistuned section) of every design, on
    ``processes`` processes (default: up to 2)."""
    run = run or run_design
    processes = processes or min(2, os.cpu_count() or 1)
    if processes <= 1:
        return [run(d) for d in designs]
    with ProcessPoolExecutor(processes) as pool:
        return list(pool.map(run, designs, chunksize=1))


def summary(results) -> tuple[float, float, str]:
    """(share that reaches the end with every check passing, share answered rightly, the text).
    Answered rightly: reached the end with every check passing, or stopped where the time
    integration finds no periodic motion, which the result says (no periodic branch exists
    there: reaching the end would be the wrong answer)."""
    good = [r for r in results if r["success"] and r["reached"] and not r["bad"] and not r["inaccurate"]]
    none = [r for r in results if r not in good and r.get("no_periodic_motion")]
    n = len(results)
    lines = [f"random designs: {len(good)} of {n} reach the end with every check passing ({100 * len(good) / n:.1f} %); "
             f"{len(none)} stop where the time integration finds no periodic motion and say so; answered rightly "
             f"{len(good) + len(none)} of {n} ({100 * (len(good) + len(none)) / n:.1f} %)"]
    for kind in ("disk", "oscillator"):
        rs = [r for r in results if r["kind"][0] == kind]
        if rs:
            ok = sum(r in good for r in rs)
            lines.append(f"  {kind}s: {ok} of {len(rs)} reach the end, {sum(r in none for r in rs)} no periodic motion, "
                         f"{sum(r['seconds'] for r in rs):.0f} s in all")
    for r in results:
        if r not in good:
            why = " (harmonic tolerance not met)" if r["inaccurate"] else ""
            head = "NO PERIODIC MOTION" if r in none else "FAILED"
            lines.append(f"  {head} {r['kind']}{why}: harmonics {r['harmonics']}: {r['message']} {r['bad']}")
    return len(good) / n, (len(good) + len(none)) / n, "\n".join(lines)


# ----- the fast part: a few designs of each kind ---------------------------------------------
# disk 1 stalled at a corner near 99.62 Hz before the corner hop could follow a fast-moving
# mean roll angle (see bladedamp.hbm.continuation); oscillators 8 and 11 did not start
FAST = [disk_design(i) for i in (0, 1, 3)] + [oscillator_design(i) for i in (0, 1, 2, 3, 5, 6, 8, 11)]


@pytest.mark.parametrize("design", FAST, ids=[f"{d['kind'][0]}{d['kind'][1]}" for d in FAST])
def test_random_design_reaches_the_end(design):
    r = run_design(design)
    assert r["success"] and r["reached"], r["message"]
    assert not r["bad"], r["bad"]


def test_oscillator_started_below_the_resonance_reaches_the_end():
    """Issue 12's example: started at 0.9 rad/s the plain Newton from the free linear solution
    did not converge (no point kept); the robust start must find the solution."""
    osc = FrictionOscillator(mass=1, stiffness=1, damping=0.01, contact_stiffness=1, friction_coefficient=1,
                             normal_load=0.1, forcing=0.05)
    r = osc.frequency_response(0.9 / (2 * np.pi), 2.2 / (2 * np.pi))       # 0.9..2.2 rad/s
    assert r.success, r.message
    assert r.omega[0] == pytest.approx(0.9, rel=1e-14) and r.omega[-1] == pytest.approx(2.2, rel=1e-14)
    assert not branch_checks(r.omega, 0.9, 2.2, 0.02)


# ----- the slow part: every design --------------------------------------------------------------
@pytest.mark.slow
def test_random_designs_share():
    results = run_all(all_designs())
    share, answered, text = summary(results)
    print("\n" + text)
    assert share >= SHARE_REQUIRED and answered >= ANSWERED_REQUIRED, text


# ----- the mistuned section ----------------------------------------------------------------------
# fast: random mistuned disk 4 on a ring of 3 blades (a 0.088 g cylinder at EO 7, mistuning 3.7 %)
FAST_MISTUNED = 4


def test_random_mistuned_disk_ends_with_a_status_within_its_budget():
    """One small random mistuned disk by default (about 4 CPU s, its budget 30 s): it ends with a
    status, and a complete answer covers its range. The CPU time is reported by the slow section,
    not asserted: a verdict must not depend on the machine's speed."""
    d = mistuned_design(FAST_MISTUNED, 3)
    r = run_mistuned(d, time_check=False)
    assert isinstance(r["status"], Status), r
    assert r["status"].complete and r["points"] > 1, mistuned_summary([r])


@pytest.mark.slow
def test_random_mistuned_designs():
    """Issue 32 item 7: N_MISTUNED random mistuned disks; prints the shares of each status and
    fails on any complete-and-verified answer that the time integration at its peak contradicts
    (but those of KNOWN_MISTUNED_CONTRADICTIONS). CPU times are printed, not asserted."""
    results = run_all([mistuned_design(i) for i in range(N_MISTUNED)], run=run_mistuned)
    text = mistuned_summary(results)
    print("\n" + text)
    contradicted = {r["kind"][1] for r in results if r["contradicted"]}
    assert contradicted <= set(KNOWN_MISTUNED_CONTRADICTIONS), f"new contradictions {contradicted - set(KNOWN_MISTUNED_CONTRADICTIONS)}\n{text}"
    # a known contradiction that no longer shows is printed, not failed: whether a design reaches the
    # end within its CPU budget (and so is checked at all) depends on the machine's speed
    print("known contradictions not seen in this run:", sorted(set(KNOWN_MISTUNED_CONTRADICTIONS) - contradicted))


@pytest.mark.slow
def test_ring_27_held_by_the_retention_spring_shakes_down_to_the_stuck_motion():
    """Random mistuned disk 27 (8.3 g cylinders at EO 1, 4 blades): its default answer (a CPU
    budget of 150 s, so a loaded machine reaches (0, 1, 2, 3) too) is not verified, its peak held by
    the static retention spring; the time integration at the peak, started on that branch, settles
    with every contact point stuck: the stuck linear response (the model's own stuck linear
    solution at that frequency, MistunedDisk.initial_guess with (0, 1), exact for a motion without
    slip), which the checked answer names, 15 % from the branch."""
    d = mistuned_design(27)
    disk = make_mistuned(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk.frequency_response(d["f_start"], d["f_end"], max_step=d["max_step"], max_points=MAX_POINTS,
                                    cpu_budget_s=150.0)
        assert r.status is Status.COMPLETE_UNVERIFIED and "static retention spring" in r.status_message, r.message
        checked = with_peak_check(disk, r, True, r.harmonic_tolerance)
    assert "every contact point stuck the whole period" in checked.message, checked.message
    assert checked.status is Status.COMPLETE_ABOVE_TOLERANCE and checked.harmonic_error > 0.1
    system = disk.hbm_system((0, 1))
    w = checked.peak_check.omega[0]
    stuck = disk.output_amplitudes(disk.initial_guess(system, w).reshape(1, system.basis.n_coeffs, -1), system.basis)[0]
    settled = disk.time_output_amplitudes(checked.peak_check)[0]
    assert np.abs(settled - stuck).max() <= 5e-3 * stuck.max(), (settled, stuck)


def stopped_disk(i: int):
    """(design, response, stop check) of random disk i: its branch as the suite runs it and
    the response's stop_check, the time integration just beyond where it got furthest."""
    d = disk_design(i)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk_response(make_disk(d), d)
    return d, r, r.stop_check


@pytest.mark.slow
def test_a_failing_disk_has_no_periodic_motion_beyond_its_stop():
    """Random disk 51 (a 7.1 g cylinder at EO 7, (0, 1, 2, 3)) does not reach the end: its branch
    retraces near 94.68 Hz. The failure says what the damper did there, and TunedDisk.stop_check
    (time integration of the full assembly 0.05 Hz beyond) finds no periodic motion: measured
    "not settled" after 4000 periods, separated 69 % of the period, the first harmonics still
    changing by 0.33 % per period. So no harmonic-balance branch can go on there (13 of the 17
    failing random disks are like this one: bladedamp.diskmodel.with_stop_note), and the result, with
    check_stop, says so: the suite counts it as answered rightly (``run_design``)."""
    d, r, check = stopped_disk(51)
    assert not r.success and "stop_check(result) tells" not in r.message, r.message     # the verdict, not the hint
    assert check.omega[0] > r.omega.max()
    assert not check.periodic[0] and check.status[0] in ("not settled", "drifting"), check.message[0]
    assert "beyond where the branch got furthest, the time integration" in r.message
    assert "finds no periodic motion" in r.message and check.message[0] in r.message


@pytest.mark.slow
def test_random_disk_127_reports_the_branch_that_got_furthest():
    """Random disk 127 (a 1.1 g wedge at EO 5, excitation x8.8, (0, 1, 2, 3)) was reported as
    turning back at a fold at 89.9 Hz with a second solution at its start: its first try had
    reversed onto itself at 89.0 Hz, past that fold, and come back to its own first point. The
    second try (damper unknowns weighing less) passes there and stops at 94.10 Hz, where the damper
    is separated 37 % of the period; that branch is now the result, the first try's message says
    it retraced itself, and the time integration 0.05 Hz beyond finds no periodic motion (measured:
    "not settled" after 4000 periods, separated 74 % of the period, the first harmonics changing
    by 0.1 % per period), as for disk 51."""
    d, r, check = stopped_disk(127)
    assert not r.success and "which got further than the first" in r.message, r.message
    assert "retraced its own path back to the start" in r.message and "turned back (fold" not in r.message
    assert r.frequency_hz.max() > 94.0 and r.frequency_hz[0] == pytest.approx(d["f_start"], rel=1e-12)
    assert not check.periodic[0] and check.status[0] in ("not settled", "drifting"), check.message[0]


@pytest.mark.slow
def test_random_disk_105_start_needs_more_harmonics():
    """Random disk 105 (a 0.025 g wedge at EO 8, (0, 1, 2, 3)) keeps no point: from 89.31 Hz the
    robust start's excitation homotopy stops at 68 % of the excitation, where the damper's
    out-of-plane unknowns come into play. The time integration there is periodic (measured:
    within a 2e-4 fluctuation per period after 1010 periods, the damper separated 80 % of the
    period: brief impacts), and the start with (0, ..., 7) converges: the truncation to (0, 1, 2, 3)
    lacks that solution. Without check_stop the message says how to tell and what to try; with it,
    what the time integration at the start found. (With (0, ..., 7) the branch then retraces itself
    at 93.80 Hz, the damper separated 78 % of the period: measured, not tested.)"""
    d = disk_design(105)
    disk = make_disk(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = disk_response(disk, d, check_stop=False)
        checked = disk_response(disk, d)
    assert not r.success and not len(r.omega) and r.stop_check is None
    assert f"TunedDisk.time_response({d['f_start']:.6g})" in r.message and "harmonics='auto'" in r.message
    assert checked.stop_check.periodic[0] and checked.stop_check.frequency_hz[0] == pytest.approx(d["f_start"])
    assert "at the start, the time integration" in checked.message and "settles on a periodic motion" in checked.message
    w = 2 * np.pi * d["f_start"]
    for harmonics, solved in (((0, 1, 2, 3), False), (tuple(range(8)), True)):
        system = disk.hbm_system(harmonics)
        x = disk.start_solution(system, w, disk.unknown_scales(system, w, 2 * np.pi * d["f_end"]))
        residual = np.linalg.norm(system.residual(x, w, False)[0])
        excitation = np.linalg.norm(system.residual(np.zeros_like(x), w, False)[0])
        assert (residual < 1e-9 * excitation) == solved, (harmonics, residual / excitation)


def spring_load_at_peak(disk, r, static_retention: float):
    """(the static retention spring's load on the damper's six coordinates [N, N m], its static
    coordinates [m, rad]) of random disk response ``r``'s peak solved again by Newton at that
    frequency in the system with ``static_retention``, from the branch's solution."""
    k = int(np.argmax(r.tip_amplitude.max(axis=1)))
    system = disk.hbm_system(r.basis.harmonics, r.basis.n_samples, static_retention=static_retention)
    x = r.coefficients[k].ravel()
    # unknowns below a millionth of the largest are rounding noise of the branch's solve: a floor of
    # 1e-12 held them to updates of 1e-23, which the rounding of some BLAS kernels exceeds (the
    # Newton then did not converge on one machine and did on another: a verdict of the kernel)
    scale = np.maximum(np.abs(x), 1e-6 * np.abs(x).max())
    excitation = np.linalg.norm(system.residual(np.zeros_like(x), r.omega[k], False)[0])
    sol = newton(system.residual, x, r.omega[k], scale, excitation, max_iter=40, factorize=system.factorize)
    assert sol.converged, static_retention
    S = np.asarray(system.static_stiffness)
    dofs = np.flatnonzero(np.diag(S))
    x0 = sol.x.reshape(r.basis.n_coeffs, -1)[r.basis.cos_index(0)]
    return (S @ x0)[dofs], x0[dofs]


def test_a_peak_held_by_the_retention_spring_is_not_verified():
    """Random disk 8 (a cylinder at EO 5 with (0, 1, 2, 3)): at its peak the friction leaves a
    net mean roll moment on the cylinder that only the HBM's static retention spring balances.
    Solved again at the peak with a spring ten times weaker, the moment stays (within 1 %) while
    the roll angle grows tenfold: the spring, not the contact, holds it. retention_held (from the
    solution's Jacobian, to first order in the spring) gives that moment over F_CG R (closed form:
    the centrifugal force m R_D Omega^2 / EO^2 times the cylinder's radius, the lever of its
    contact centres) within 1 %, above the limit, so the default answer is not verified and says
    why."""
    d = disk_design(8)
    assert d["damper"] == "cylinder" and d["harmonics"] == (0, 1, 2, 3)
    disk = make_disk(d)
    r = disk_response(disk, d, check_stop=False)
    assert r.success and r.status is Status.COMPLETE_UNVERIFIED and np.isnan(r.harmonic_error), r.message
    assert "static retention spring" in r.unverified_reason and "static retention spring" in r.status_message
    k = int(np.argmax(r.tip_amplitude.max(axis=1)))
    held = retention_held(disk, r.coefficients[k], r.basis, r.omega[k])
    (load, angle), (weaker, angle_weaker) = (spring_load_at_peak(disk, r, s) for s in (1e-4, 1e-5))
    roll = 4                                                   # phiD_y, the cylinder's axis
    assert np.argmax(np.abs(load[3:])) + 3 == roll
    assert weaker[roll] == pytest.approx(load[roll], rel=1e-2)
    assert angle_weaker[roll] == pytest.approx(10 * angle[roll], rel=1e-2)
    f_cg = centrifugal_force(d["mass"], ref.DAMPER_RADIUS, r.frequency_hz[k], d["engine_order"])[0]
    assert held[0] == pytest.approx(abs(load[roll]) / (f_cg * ref.CYLINDER_RADIUS), rel=1e-2)
    assert held[0] > RETENTION_HELD_LIMIT


def test_a_peak_the_contacts_hold_is_left_alone():
    """Random disk 3 (a wedge with (0, 1, 2, 3)): the two flat faces hold the wedge's roll, so
    the spring's load falls tenfold with the spring (the weak-spring limit the spring is meant
    for) and retention_held is below a fifth of the limit: the check leaves the answer alone."""
    d = disk_design(3)
    assert d["damper"] == "wedge" and d["harmonics"] == (0, 1, 2, 3)
    disk = make_disk(d)
    r = disk_response(disk, d, check_stop=False)
    assert r.reached_range_end and r.unverified_reason == "", r.message
    k = int(np.argmax(r.tip_amplitude.max(axis=1)))
    held = retention_held(disk, r.coefficients[k], r.basis, r.omega[k])
    (load, _), (weaker, _) = (spring_load_at_peak(disk, r, s) for s in (1e-4, 1e-5))
    largest = int(np.argmax(np.abs(load[3:]))) + 3
    assert weaker[largest] == pytest.approx(0.1 * load[largest], rel=0.1)
    assert held[0] < 0.2 * RETENTION_HELD_LIMIT


def peak_checked_disk(i: int, check_peak: bool = True):
    """Random disk i with harmonics (0, 1) (what harmonics='auto' ends on for it: the enriched
    (0, 1, 2, 3) fails at the peak, so the estimate is "not verified") over its range."""
    d = disk_design(i)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return make_disk(d).frequency_response(d["f_start"], d["f_end"], harmonics=(0, 1), max_step=d["max_step"],
                                               max_points=MAX_POINTS, check_peak=check_peak)


@pytest.mark.slow
def test_an_unverified_peak_is_verified_by_time_integration(tmp_path):
    """Random disk 63 (a 0.039 g wedge at EO 7; harmonics='auto' ends on (0, 1)): the enriched
    (0, 1, 2, 3) cannot solve its peak (the damper separated 96 % of the period: brief impacts),
    so the estimate is "not verified". With check_peak the full assembly's time integration at the
    peak's frequency, started on the branch's own state there, settles on a periodic motion 0.66 %
    from the branch's tip amplitudes (measured; 0.83 % when started from rest), which becomes the
    estimate, within the 1 % tolerance. Checked against the time integration run here on its own
    from the same state; the result keeps it through save and load."""
    plain, checked = peak_checked_disk(63, False), peak_checked_disk(63)
    assert plain.success and plain.harmonics_converged is False and np.isnan(plain.harmonic_error)
    assert plain.peak_check is None and "not verified" in plain.message and "check_peak=True" in plain.message
    assert checked.success and checked.harmonics_converged, checked.message
    assert 0 < checked.harmonic_error <= 0.01 and "settles on a periodic motion" in checked.message
    # the estimate is the difference from an independent run of the time integration at the peak
    k = int(np.argmax(checked.tip_amplitude.max(axis=1)))
    disk = make_disk(disk_design(63))
    start = full_assembly_coefficients(disk, checked.coefficients[k], checked.basis)
    alone = disk.time_response(checked.frequency_hz[k], start_coefficients=start[None], start_basis=checked.basis)
    assert alone.periodic[0] and checked.peak_check.start[0] == alone.start[0] == "HBM solution"
    own = np.abs(alone.tip_amplitude[0].max(axis=0) - checked.tip_amplitude[k]).max() / checked.tip_amplitude.max()
    assert checked.harmonic_error == pytest.approx(own, rel=1e-9)
    checked.save(tmp_path / "r.npz")
    loaded = bd.load(tmp_path / "r.npz")
    assert loaded.peak_check.periodic[0] and loaded.harmonic_error == pytest.approx(checked.harmonic_error)


@pytest.mark.slow
def test_a_peak_without_periodic_motion_fails_the_response():
    """Random disk 51 (a 7.1 g cylinder at EO 7; harmonics='auto' ends on (0, 1), "not
    verified"): its (0, 1) branch reaches the end, but at its peak's frequency the time
    integration does not settle (measured: "not settled" after 4000 periods, the first harmonics
    changing by 0.72 % per period, the damper separated 87 % of the period): the branch's peak is
    not a motion the disk settles on, so with check_peak the response is not success and says
    why, and no stop note is added (the branch did reach the end)."""
    r = peak_checked_disk(51)
    assert not r.success and r.reached_range_end and not r.peak_check.periodic[0]
    assert set(r.failed_checks) == {"peak_time_check"} and "finds no periodic motion" in r.message
    assert "stop_check(result)" not in r.message and r.stop_check is None


def time_check_designs():
    """The oscillators cross-checked by time integration: the first N_TIME_CHECKS designs,
    alternately flat and inclined."""
    picked, i = [], 0
    while len(picked) < N_TIME_CHECKS:
        d = oscillator_design(i)
        if (d["params"]["contact_angle"] > 0) == (len(picked) % 2 == 1):
            picked.append(d)
        i += 1
    return picked


# Oscillator 4 (inclined contact with lift-off, gross slip) was a known failure with (0, 1, 2, 3)
# set by hand: negative contact dissipation from the AFT's sampling at the lift-off kink (-14 % /
# +1.6 % / +0.1 % at 64 / 256 / 1024 samples) and a continuation that ran out of points. With the
# default (automatic harmonics and samples) it passes, within 2 % of the time integration.
KNOWN_TIME_CHECK_FAILURES = {}


def _time_check_param(d):
    i = d["kind"][1]
    marks = [pytest.mark.xfail(strict=True, reason=KNOWN_TIME_CHECK_FAILURES[i])] if i in KNOWN_TIME_CHECK_FAILURES else []
    return pytest.param(d, id=f"oscillator{i}", marks=marks)


@pytest.mark.slow
@pytest.mark.parametrize("design", [_time_check_param(d) for d in time_check_designs()])
def test_random_oscillator_peak_against_time_integration(design):
    """HBM first-harmonic amplitude at the HBM peak against the time integration there."""
    osc = FrictionOscillator(**design["params"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(design["omega_start"] / (2 * np.pi), design["omega_end"] / (2 * np.pi), harmonics=TIME_CHECK_HARMONICS,
                                   n_samples=design["n_samples"], max_step=0.02)
    assert r.success and r.harmonics_converged is not False, r.message
    j1 = r.basis.cos_index(1)
    a = np.hypot(r.coefficients[:, j1, 0], r.coefficients[:, j1 + 1, 0])
    k = int(np.argmax(a))
    td = osc.time_response([r.frequency_hz[k]], steps_per_period=2048)
    assert td.converged[0]
    assert td.amplitude[0] == pytest.approx(a[k], rel=2e-2), (design["params"], r.omega[k])


@pytest.mark.slow
def test_random_oscillator_154_meets_the_harmonic_tolerance():
    """Random oscillator 154 (inclined contact, separated most of the period, damping ratio 2.6e-3)
    ended "auto" on (0..9) with 1024 AFT samples and "not verified": at its peak the enriched
    Newton failed on the sampling of the lift-off instant, not on the harmonics (it converged with
    4096 samples, 0.18 % off; the full (0..11) branch's peak is 0.007 % off). The estimate retries
    such a point with ENRICHED_SAMPLES_GROWTH x the samples: "auto" meets 1 % with (0..7). The
    time integration started on the HBM peak state settles within 1 % of it (measured 0.1 %)."""
    d = oscillator_design(154)
    osc = FrictionOscillator(**d["params"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = osc.frequency_response(d["omega_start"] / (2 * np.pi), d["omega_end"] / (2 * np.pi), harmonics="auto",
                                   n_samples=d["n_samples"], max_step=d["max_step"], max_points=MAX_POINTS)
    assert r.success and r.harmonics_converged, r.message
    assert r.harmonic_error <= r.harmonic_tolerance
    f, a = r.peak()
    k = int(np.argmax(r.harmonic_amplitude(0, 1)))
    x = r.time_samples(0)[k]
    v = r.omega[k] * (r.coefficients[k, :, 0] @ r.basis.derivative.T @ r.basis.synthesis.T)
    td = osc.time_response([f], steps_per_period=4096, max_periods=5000, initial_displacement=x[0],
                           initial_velocity=v[0])
    assert td.converged[0] and td.amplitude[0] == pytest.approx(a, rel=1e-2)


def default_answer(i: int) -> dict:
    """Random disk i as a user gets it by default, plus both time checks: harmonics 'auto' (up to
    (0, ..., 7)), ``check_stop`` and ``check_peak``, and what the answer is: "accurate" (success,
    the harmonic tolerance met, by the enriched set or the time integration at the peak), "says
    how far" (success, an estimate above the tolerance), "no periodic motion" (the time
    integration at the peak or beyond the stop finds none, and the result says so), "not answered"
    (anything else: a periodic motion the branch did not reach, an unverified estimate)."""
    d = disk_design(i)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = make_disk(d).frequency_response(d["f_start"], d["f_end"], max_step=d["max_step"], max_points=MAX_POINTS,
                                            check_stop=True, check_peak=True)
    no_motion = ("peak_time_check" in r.failed_checks
                 or (r.stop_check is not None and not r.stop_check.periodic[0] and "finds no periodic motion" in r.message))
    if r.success and r.harmonics_converged:
        answer = "accurate"
    elif r.success and np.isfinite(r.harmonic_error):
        answer = "says how far"
    else:
        answer = "no periodic motion" if no_motion else "not answered"
    checks = [f"{name} {c.status[0]}" for name, c in (("peak", r.peak_check), ("stop", r.stop_check)) if c is not None]
    return dict(i=i, answer=answer, harmonics=r.basis.harmonics, error=r.harmonic_error, checks=checks,
                seconds=time.perf_counter() - t0, message=r.message)


if __name__ == "__main__":
    # python tests/test_random_designs.py [processes]: the shares, and every design that does not
    # reach the end with its message (a stopped disk's: the time integration beyond its stop, 30-210 s each)
    # python tests/test_random_designs.py [processes] --default 2,9,41: those disks as a user gets them
    # by default, with both time checks (default_answer; 1-6 min each)
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    procs = int(args[0]) if args else None
    t = time.perf_counter()
    if "--mistuned" in sys.argv:
        # python tests/test_random_designs.py [processes] --mistuned: the mistuned section's shares
        print(mistuned_summary(run_all([mistuned_design(i) for i in range(N_MISTUNED)], procs, run=run_mistuned)))
    elif "--default" in sys.argv:
        indices = [int(i) for i in sys.argv[sys.argv.index("--default") + 1].split(",")]
        with ProcessPoolExecutor(procs or 2) as pool:
            answers = list(pool.map(default_answer, indices, chunksize=1))
        for a in answers:
            print(f"disk {a['i']}: {a['answer']}: harmonics {a['harmonics']}, harmonic error {100 * a['error']:.3g} %, "
                  f"time checks {a['checks']}, {a['seconds']:.0f} s\n    {a['message']}")
        kinds = ("accurate", "says how far", "no periodic motion", "not answered")
        print("; ".join(f"{k}: {sum(a['answer'] == k for a in answers)}" for k in kinds), f"of {len(answers)}")
    else:
        print(summary(run_all(all_designs(), procs))[2])
    print(f"{time.perf_counter() - t:.0f} s wall")
