"""The paper's pipeline: every study of ``bladedamp reproduce`` on the reference configuration,
its summary.json, its report.md and its figures (:func:`reproduce`).

The studies themselves are in :mod:`bladedamp.studies`; this module runs them with the paper's
settings, gathers their results into the summary and writes the report and the figures through
:mod:`bladedamp.report` (so it sits above both; the command line only parses and calls it).
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import re
import time
import warnings
from pathlib import Path

import numpy as np

from . import report
from .hbm.accuracy import PAPER_HARMONICS
from .hbm.nonlinear_modes import nonlinear_mode
from .hbm.stability import with_stability
from .reference import EXCITATION_TABLE1, reference_disk
from .studies.design import (contact_state, design_map, engine_order_sweeps, liftoff_onset, mode_window,
                             platform_angle_study, wedge_liftoff_map)
from .studies.mass import mass_sweep, optimal_mass, peak_response
from .studies.mistuning import paper_cases, plot_cases, summary_dict
from .studies.parallel import parallel_map
from .validation import PlausibilityWarning


#: the heaviest damper of the paper's mass sweep (Fig. 6) and of Fig. 5 [kg]: the limit where the
#: damper sticks and damps nothing, above the plausible range of a real damper on purpose
STUCK_LIMIT_MASS = 1.0


@contextlib.contextmanager
def stuck_limit_expected():
    """A block in which the damper mass :data:`STUCK_LIMIT_MASS` (1 kg) raises no
    :class:`~bladedamp.validation.PlausibilityWarning`: for a user's design that warning means a
    unit slip (1 kg meant as 1 g), in the paper's studies the mass is chosen. Only that message
    for that value is ignored; any other warning of the block (another implausible mass
    included) goes on to the caller."""
    value = re.escape(repr(STUCK_LIMIT_MASS))
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=rf"damper mass = (np\.float64\()?{value}\)? kg is outside "
                                                  "the plausible range", category=PlausibilityWarning)
        yield


class _Silent:
    """The ``progress`` of :func:`reproduce` when none is given: says nothing."""

    def __call__(self, line: str) -> None:
        pass

    def bar(self, study: str):
        return None

    def compiling(self) -> None:
        pass


def reproduce(out: Path, processes: int | None = None, progress=None) -> dict:
    """The paper's results on the reference configuration (Panning, Sextro & Popp; Table 1,
    Figs. 4-17 and the studies beyond the paper): writes ``out``/summary.json, ``out``/report.md
    (:func:`bladedamp.report.reproduce_report`) and the figures into the folder ``out`` (created
    if needed; files of the same names are replaced: the command line refuses a folder that
    holds files unless --overwrite is given, :func:`bladedamp.cli.output_dir`) and returns the
    summary (the dict written to summary.json; lengths in mm, masses in g, frequencies in Hz,
    times in s). ``processes``: worker processes of the studies (None: every core);
    ``progress``: the steps' report, an object called with one line per step and whose
    ``bar(study)`` gives a study's ``(done, total)`` callback and ``compiling()`` says when
    numba's first compilation is ahead (:class:`bladedamp.cli.Progress`; None: nothing)."""
    progress = _Silent() if progress is None else progress
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    masses = np.array([0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 100.0, 1000.0]) * 1e-3
    progress.compiling()
    timings = {}

    # -- undamped reference (calibration target 1) --
    t0 = time.perf_counter()
    undamped_peak, undamped_f, _ = peak_response(reference_disk(None))
    progress(f"no damper: peak {1e3 * undamped_peak:.4f} mm at {undamped_f:.3f} Hz")

    # -- Table 1 / Fig. 4: four modes, cylinder 1 g, spatial excitation --
    free = reference_disk(None, excitation=EXCITATION_TABLE1)
    damped = reference_disk("cylinder", 1e-3, excitation=EXCITATION_TABLE1)
    progress("Table 1: four modes with and without the 1 g cylinder")
    modes = [(name, f0, report.MODE_TIP_DOF[name]) for name, f0, _, _ in report.PAPER["table1"]]
    windows_of = parallel_map(_call, [(mode_window, d, f0, dof) for _, f0, dof in modes for d in (free, damped)],
                              processes)
    table1, windows = [], []
    for k, (name, f0, dof) in enumerate(modes):
        (r_free, a_free, _), (r_damp, a_damp, f_damp) = windows_of[2 * k], windows_of[2 * k + 1]
        table1.append({"mode": name, "f0_hz": f0, "f_res_damped_hz": f_damp,
                       "reduction_pct": 100 * (1 - a_damp / a_free), "tip_dof": "xyz"[dof] if dof < 3 else "phi_z",
                       "peak_free": a_free, "peak_damped": a_damp})
        windows.append((name, dof, r_free, r_damp))
        progress(f"  {name}: damped resonance {f_damp:.2f} Hz, reduction {report.fmt_number(table1[-1]['reduction_pct'], '.1f')} %")
    timings["table1_s"] = time.perf_counter() - t0

    # -- mass sweep and optimum, both dampers at EO = 1 (Fig. 5, 6) --
    t0 = time.perf_counter()
    sweeps, optima = {}, {}
    for kind in ("cylinder", "wedge"):
        disk = reference_disk(kind)
        with stuck_limit_expected():                                        # up to 1 kg
            sweeps[kind] = mass_sweep(disk, masses, progress=progress.bar(f"mass sweep {kind}"), processes=processes)
        opt = optimal_mass(disk, bounds=(1e-5, 2e-2), processes=processes)   # EO 1, also the EO study's
        optima[kind] = opt
        progress(f"optimum {kind}: {1e3 * opt.mass:.3f} g, peak {1e3 * opt.peak_amplitude:.4f} mm, "
                 f"reduction {report.fmt_percent(opt.reduction)}")
    fig5_masses = (0.1e-3, 1e-3, 10e-3, STUCK_LIMIT_MASS)
    with stuck_limit_expected():                                            # 1 kg
        fig5_disks = [reference_disk("cylinder", m) for m in fig5_masses]
    fig5 = parallel_map(_timed_frf, [(reference_disk(None), 85.0, 115.0, PAPER_HARMONICS)]
                        + [(d, 85.0, 115.0, None) for d in fig5_disks], processes)
    (free_r, free_s), frfs_fig5 = fig5[0], [(m, r) for m, (r, _) in zip(fig5_masses, fig5[1:])]
    solve_s = {("none", "paper"): free_s}
    timings["mass_studies_s"] = time.perf_counter() - t0

    report.plot_four_modes(windows, out / "fig4_frf_four_modes.png")
    report.plot_mass_variation(free_r, frfs_fig5, out / "fig5_mass_variation.png")
    report.plot_mass_optimisation(sweeps, optima, out / "fig6_mass_optimisation.png")
    progress("figures of Fig. 4-6 written")

    # -- the paper's one-harmonic setting beside the converged harmonic balance, at both optima --
    t0 = time.perf_counter()
    accuracy, frfs = {}, {}
    settings = [(kind, label, H) for kind in optima for label, H in (("paper", PAPER_HARMONICS), ("converged", "auto"))]
    solved = parallel_map(_timed_frf, [(reference_disk(kind, optima[kind].mass), 90.0, 100.0, H)
                                       for kind, _, H in settings], processes)
    for (kind, label, _), (r, seconds) in zip(settings, solved):
        solve_s[kind, label] = seconds
        frfs[kind, label] = r
        accuracy.setdefault(kind, {"mass_g": 1e3 * optima[kind].mass})[label] = {
            "harmonics": list(r.basis.harmonics), "peak_tip_mm": 1e3 * r.peak_amplitude,
            "resonance_hz": r.peak_frequency_hz, "harmonic_error_pct": report.plain(100 * r.harmonic_error),
            "converged": bool(r.harmonics_converged), "success": bool(r.success)}
    for kind, rows in accuracy.items():
        progress(f"harmonic accuracy {kind}: paper {rows['paper']['peak_tip_mm']:.4f} mm, "
                 f"converged {rows['converged']['peak_tip_mm']:.4f} mm with harmonics {tuple(rows['converged']['harmonics'])}")
    timings["harmonic_accuracy_s"] = time.perf_counter() - t0

    # -- the stability of those responses and the 1F nonlinear modes of both dampers --
    stability, backbone = stability_and_backbones(out, free_r, frfs, solve_s, {k: o.mass for k, o in optima.items()},
                                                  progress, timings, processes)

    design = _design_studies(out, progress, processes, timings, optima, sweeps)

    # -- mistuned disk: the paper's cases (Figs. 13-17) --
    t0 = time.perf_counter()
    cases = paper_cases(progress=lambda i, n, msg: progress(f"mistuning {i}/{n}: {msg}"), processes=processes)
    mistuning = summary_dict(cases)
    plot_cases(cases, out / "fig13_17_mistuning.png")
    timings["mistuning_s"] = time.perf_counter() - t0

    total = time.perf_counter() - t_start
    timings["total_s"] = total
    summary = {
        "no_damper_peak_tip_mm": 1e3 * undamped_peak,
        "table1": [{k: row[k] for k in ("mode", "f0_hz", "f_res_damped_hz", "reduction_pct")} for row in table1],
        "mass_sweep": {kind: {"mass_g": list(1e3 * sw.mass), "peak_tip_mm": list(1e3 * sw.peak_amplitude),
                              "resonance_hz": list(sw.peak_frequency_hz)} for kind, sw in sweeps.items()},
        "optimum": {kind: {"1": {"mass_g": 1e3 * o.mass, "peak_tip_mm": 1e3 * o.peak_amplitude,
                                 "reduction_pct": 100 * o.reduction, "certified": bool(o.success),
                                 "message": o.message}} for kind, o in optima.items()},
        "timings_s": timings,
    }
    for kind, opt in design.pop("optimum").items():
        summary["optimum"][kind].update(opt)
    summary.update(design)
    summary["mistuning"] = mistuning
    summary["harmonic_accuracy"] = accuracy
    summary["stability"] = stability
    summary["backbone"] = backbone
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    (out / "report.md").write_text(report.reproduce_report(summary, table1))
    return summary


def _call(case):
    """``fn(*args)`` of ``case = (fn, *args)`` (``fn`` module-level): one case of ``parallel_map``."""
    fn, *args = case
    return fn(*args)


def _timed_frf(case):
    """(response, solve time [s]) of one (disk, f_start [Hz], f_end [Hz], harmonics) at max_step
    0.05; harmonics None: :func:`bladedamp.studies.mass.peak_response`'s (peak searched, range
    widened until the peak is interior)."""
    disk, lo, hi, harmonics = case
    t = time.perf_counter()
    r = peak_response(disk, (lo, hi), max_step=0.05)[2] if harmonics is None else \
        disk.frequency_response(lo, hi, harmonics=harmonics, max_step=0.05)
    return r, time.perf_counter() - t


def stability_and_backbones(out: Path, free, frfs: dict, solve_s: dict, masses: dict, progress, timings: dict,
                            processes: int | None = 1):
    """The stability of the reference responses (``free``: the disk without damper; ``frfs``:
    {(kind, "paper" | "converged"): response at the optimal mass ``masses[kind]`` [kg]}) and the
    1F nonlinear modes (EPMC, one harmonic) of both dampers at those masses; writes
    ``stability_backbones.png``. ``solve_s``: the solve time of each response [s], to report the
    stability's cost beside it; ``processes``: worker processes over the responses (None: every
    core). Returns the summary's ``stability`` and ``backbone`` entries."""
    t0 = time.perf_counter()
    stability, checked = {}, {}
    entries = [("no damper", "none", "paper", reference_disk(None), free)]
    entries += [(f"{kind} {1e3 * masses[kind]:.3g} g, {'one harmonic' if label == 'paper' else 'converged'}",
                 kind, label, reference_disk(kind, masses[kind]), r) for (kind, label), r in frfs.items()]
    checks = parallel_map(_call, [(with_stability, model, r) for _, _, _, model, r in entries], processes)
    for (name, kind, label, model, r), s in zip(entries, checks):
        checked[kind, label] = s
        stable = np.ones(len(s.omega), bool) if s.stable is None else np.asarray(s.stable, bool)
        stability[name] = {
            "harmonics": list(s.basis.harmonics), "method": s.stability_method or "not computed",
            "frequency_hz": s.frequency_hz.tolist(), "tip_amplitude_mm": (1e3 * s.tip_amplitude[:, 0]).tolist(),
            "stable": stable.tolist(),
            "folds": [int(i) for i in s.turning_points],
            "branch_points": [int(i) for i in s.bifurcations.get("branch point", [])],
            "stability_changes": {k: [int(i) for i in v] for k, v in s.bifurcations.items()
                                  if k not in ("branch point", "seconds")},
            "seconds": float(s.bifurcations.get("seconds", 0.0)), "solve_s": solve_s.get((kind, label))}
        progress(f"stability {name}: {int((~stable).sum())} of {len(stable)} points unstable ({s.stability_method})")
    timings["stability_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    backbone, modes = {}, {}
    for kind, mass in masses.items():
        mode = nonlinear_mode(reference_disk(kind, mass), harmonics=(1,))
        modes[kind] = mode
        peak = mode.forced_peak()
        r = frfs[kind, "paper"]
        backbone[kind] = {
            "mass_g": 1e3 * mass, "harmonics": list(mode.basis.harmonics), "success": bool(mode.success),
            "message": mode.message, "modal_amplitude": np.asarray(mode.modal_amplitude).tolist(),
            "frequency_hz": np.asarray(mode.frequency_hz).tolist(),
            "damping_ratio": np.asarray(mode.damping_ratio).tolist(),
            "tip_amplitude_mm": (1e3 * np.asarray(mode.output_amplitude)[:, 0]).tolist(),
            "synthesised_peak_mm": report.plain(1e3 * peak["output_amplitude"][0]) if peak["found"] else None,
            "synthesised_peak_hz": report.plain(peak["frequency_hz"]) if peak["found"] else None,
            "frf_peak_mm": 1e3 * r.peak_amplitude, "frf_peak_hz": r.peak_frequency_hz}
        progress(f"1F nonlinear mode {kind}: {len(mode.modal_amplitude)} amplitudes, "
                 f"{mode.frequency_hz[0]:.2f} -> {mode.frequency_hz[-1]:.2f} Hz")
    timings["backbone_s"] = time.perf_counter() - t0
    report.plot_stability_backbones({k: checked[k, "paper"] for k in masses},
                                    {k: checked[k, "converged"] for k in masses if (k, "converged") in checked},
                                    modes, out / "stability_backbones.png")
    return stability, backbone


def _design_studies(out: Path, progress, processes, timings, optima: dict, sweeps_eo1: dict) -> dict:
    """The paper's design studies (Fig. 7-11) and the design map beyond the paper, on the
    reference disk. The mass study's results at EO 1 on the reference disk are not recomputed:
    ``optima`` {kind: MassOptimum}, ``sweeps_eo1`` {kind: MassSweep} (the 1 g cylinder's peak)."""
    result = {}
    # -- engine orders 0..8, mass re-optimised (Fig. 7, 8) --
    t0 = time.perf_counter()
    kinds = ("cylinder", "wedge")
    sweeps = dict(zip(kinds, engine_order_sweeps([reference_disk(kind) for kind in kinds], range(0, 9),
                                                 progress=progress.bar("engine orders"), processes=processes,
                                                 known=[{1: optima[kind]} for kind in kinds])))
    result["optimum"] = {kind: {str(eo): {"mass_g": report.plain(1e3 * m), "peak_tip_mm": report.plain(1e3 * p),
                                          "reduction_pct": report.plain(100 * r), "certified": bool(c),
                                          "message": sw.messages.get(int(eo), sw.failures.get(int(eo), ""))}
                                for eo, m, p, r, c in zip(sw.engine_orders, sw.optimal_mass, sw.optimal_peak_amplitude,
                                                          sw.reduction, sw.certified) if eo != 1}
                         for kind, sw in sweeps.items()}
    result["engine_order_failures"] = {kind: sw.failures for kind, sw in sweeps.items() if sw.failures}
    timings["engine_orders_s"] = time.perf_counter() - t0
    report.plot_engine_orders(sweeps, out / "fig7_8_engine_orders.png")

    # -- asymmetric platforms (Fig. 10) --
    t0 = time.perf_counter()
    angles = np.array([15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0])
    at_1g = float(sweeps_eo1["cylinder"].peak_amplitude[np.isclose(sweeps_eo1["cylinder"].mass, 1e-3)][0])
    pa = platform_angle_study(reference_disk("cylinder", 1e-3), angles, progress=progress.bar("platform angles"),
                              processes=processes, known={35.0: (at_1g, optima["cylinder"])})   # the reference angle
    result["platform_angle"] = {"gamma_r_deg": list(angles), "opt_mass_g": list(1e3 * pa.optimal_mass),
                                "opt_peak_tip_mm": list(1e3 * pa.optimal_peak_amplitude),
                                "peak_tip_mm_at_1g": list(1e3 * pa.peak_amplitude_at_fixed_mass)}
    timings["platform_angles_s"] = time.perf_counter() - t0
    report.plot_platform_angles(pa, out / "fig10_platform_angles.png")

    # -- contact state in the complex plane (Fig. 11, Eq. 27) --
    t0 = time.perf_counter()
    state_angles = (35.0, 85.0)
    *states, lift = parallel_map(_call, [(contact_state, dataclasses.replace(reference_disk("cylinder", 1e-3),
                                                                            gamma_right=np.radians(g)))
                                         for g in state_angles] + [(wedge_liftoff_map, reference_disk("wedge", 1e-3))],
                                 processes)
    states = dict(zip(state_angles, states))
    progress("contact states at gamma_R = 35, 85 deg")
    for g, state in states.items():  # complex as [re, im] (Eq. 27)
        result[f"contact_state_{g:g}deg"] = {name: {"w_star": [float(state.w_star[c].real), float(state.w_star[c].imag)],
                                                    "f_star": [float(state.F_star[c].real), float(state.F_star[c].imag)]}
                                             for c, name in enumerate(("OL", "OR"))}
    report.plot_contact_states(states, out / "fig11_contact_state.png")

    # -- wedge lift-off (Fig. 9) and its onset over contact height and excitation --
    result["wedge_liftoff"] = {"xi_star": list(map(float, lift.xi_star)), "eta_star": list(map(float, lift.eta_star)),
                               "r": lift.ratio.tolist(), "mass_g": 1.0, "force_n": 0.1}
    result["wedge_liftoff_onset"] = liftoff_onset(reference_disk("wedge", 1e-3), [1e-3, 2e-3, 3e-3, 4e-3],
                                                  [0.02, 0.05, 0.1, 0.2], progress=progress.bar("lift-off onset"),
                                                  processes=processes)
    report.plot_liftoff(lift, out / "fig9_wedge_liftoff.png")
    timings["contact_state_liftoff_s"] = time.perf_counter() - t0

    # -- design map beyond the paper --
    t0 = time.perf_counter()
    maps = [design_map(reference_disk("cylinder"), np.array([0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0]) * 1e-3, angles,
                       progress=progress.bar("design map cylinder"), processes=processes)]
    for h in (1e-3, 4e-3):
        maps.append(design_map(reference_disk("wedge"), np.array([0.1, 0.2, 0.3, 0.5, 1.0]) * 1e-3,
                               [15.0, 35.0, 55.0, 85.0], contact_height=h,
                               progress=progress.bar(f"design map wedge h_C={1e3 * h:g} mm"), processes=processes))
    result["design_map"] = [{"kind": m.kind, "contact_height_mm": None if m.contact_height is None else 1e3 * m.contact_height,
                             "mass_g": list(1e3 * m.mass), "gamma_r_deg": list(map(float, m.gamma_right_deg)),
                             "peak_tip_mm": (1e3 * m.peak_amplitude).tolist(), "optimum": m.optimum} for m in maps]
    report.plot_design_maps(maps, out / "design_map.png")
    timings["design_map_s"] = time.perf_counter() - t0
    return result


