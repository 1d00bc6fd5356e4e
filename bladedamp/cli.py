"""bladedamp on the command line: the paper's reproduction and the commands on a design file.

  bladedamp init design.toml          write the reference design, every key commented
  bladedamp frf design.toml           frequency response of the design's disk
  bladedamp optimize design.toml      optimal damper mass (and platform angle or contact height)
  bladedamp sensitivities design.toml derivatives of the resonance peak in design parameters
  bladedamp fit design.toml m.csv     contact parameters fitted to measured responses
  bladedamp eo-sweep design.toml      optimal mass over engine orders
  bladedamp zzenf design.toml         interference (ZZENF) diagram: natural frequencies per nodal diameter
  bladedamp campbell design.toml      Campbell diagram: damped resonance at each engine order over rotor speed
  bladedamp montecarlo design.toml    Monte Carlo of randomly mistuned disks (Dask)
  bladedamp show design.toml          3D view of the resonance (standalone HTML)
  bladedamp compare a.toml b.toml     frequency responses of several designs in one figure
  bladedamp app                       the damper-design dashboard in the browser (Voila)
  bladedamp reproduce                 the paper's results on the reference configuration
  bladedamp precompile                compile every numba kernel once (after installing)

Each command on a design writes into --out (default: results/<design file name>/<command>):
results (npz and results.json), PNG figures and a short summary.md. A folder that holds files
already is refused unless --overwrite is given, and init keeps an existing design file. A bad
design field, an unreadable file or a bad option ends with exit code 2 and one line naming it.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

# Nothing heavy at module level: `bladedamp --help` must not import numpy, numba or the models.


class UsageError(ValueError):
    """A user error (an option, the output folder): one line, exit code 2."""


class Progress:
    """Progress of a command on stderr: one line per step with the elapsed time; ``bar(study)``
    gives a (done, total) callback drawn as a ``tqdm.auto`` bar (:class:`bladedamp.progress.ProgressBar`)
    in place on a terminal and none otherwise (logs, CI), and one line when the study is done."""

    def __init__(self, stream=None):
        self.start = time.perf_counter()
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __call__(self, what: str):
        print(f"{time.perf_counter() - self.start:7.1f} s  {what}", file=self.stream, flush=True)

    def compiling(self):
        """One line before a command's first computation when numba's cache holds no compiled
        kernel of bladedamp yet (:func:`bladedamp.compilation.cache_is_cold`)."""
        from .compilation import COLD_COMPILE_SECONDS, cache_is_cold

        if cache_is_cold():
            self(f"compiling kernels once, about {COLD_COMPILE_SECONDS} s; `bladedamp precompile` does it ahead")

    def bar(self, study: str):
        from .progress import ProgressBar

        bar = ProgressBar(study, file=self.stream, disable=not self.tty, leave=False)

        def tick(done, total):
            bar(done, total)
            if done >= total:
                self(f"{study} done ({total})")
        return tick


class Notes:
    """The warnings raised while a command runs (the library's AccuracyWarning and
    PlausibilityWarning, numpy's RuntimeWarning, numba's warnings, ...), collected instead of
    printed with their category and source line: each distinct message is one plain line,
    written to the command's summary.md and results.json (:meth:`write`) and printed at the end
    of the run (:meth:`show`). Python's developer categories (DeprecationWarning,
    PendingDeprecationWarning, ImportWarning, ResourceWarning) stay ignored, as they are by
    default. ``Notes.current`` is the collection of the running command (None outside one)."""

    current = None
    IGNORED = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)

    def __init__(self):
        self._catcher = warnings.catch_warnings(record=True)
        self._records = []
        self._printed = 0
        self._said = []

    def __enter__(self):
        self._records = self._catcher.__enter__()
        warnings.simplefilter("always")          # every occurrence: the duplicates are merged in lines()
        for category in self.IGNORED:
            warnings.simplefilter("ignore", category)
        Notes.current = self
        return self

    def __exit__(self, *exc_info):
        Notes.current = None
        return self._catcher.__exit__(*exc_info)

    def lines(self) -> list[str]:
        """The distinct messages in the order they were first raised, each on one line."""
        from .hbm.continuation import ConvergenceWarning

        records = [w for w in self._records if not (self._said and issubclass(w.category, ConvergenceWarning))]
        distinct = dict.fromkeys(" ".join(str(w.message).split()) for w in records)
        return [line for line in distinct if line and not any(line in text for text in self._said)]

    def write(self, out: Path) -> None:
        """Add the messages to ``out``/summary.md (a Notes section) and ``out``/results.json (key
        "notes"), where the command wrote those files; nothing without messages."""
        import json

        from .report import write_json

        lines = self.lines()
        if not lines:
            return
        summary, results = out / "summary.md", out / "results.json"
        if summary.exists():
            text = summary.read_text().rstrip("\n")
            summary.write_text(text + "\n\n## Notes\n\n" + "".join(f"- {line}\n" for line in lines))
        if results.exists():
            data = json.loads(results.read_text())
            data["notes"] = lines
            write_json(results, data)

    def said(self, text: str) -> None:
        """Record ``text`` as already told to the user (a result's status line): a message it
        contains is not repeated (:meth:`lines`, :meth:`write`, :meth:`show`), nor is a
        continuation's ConvergenceWarning (where and why a branch stopped: the status line says
        where, and what to do, for the branch the result kept)."""
        self._said.append(" ".join(text.split()))

    def show(self, stream=None) -> None:
        """Print the messages not printed yet, one plain line each ("note: ...")."""
        lines = self.lines()
        for line in lines[self._printed:]:
            print(f"note: {line}", file=stream if stream is not None else sys.stderr)
        self._printed = len(lines)


def output_dir(path: Path, overwrite: bool = False) -> Path:
    """``path`` created if needed and checked writable (before any computation); UsageError if
    it is a file, cannot be written, or already holds files or folders and ``overwrite`` is
    False (a run never replaces results a user has without being told to; with ``overwrite``
    the files of the same names are replaced and the others stay)."""
    import tempfile

    if path.exists() and not path.is_dir():
        raise UsageError(f"--out {path}: is a file, not a folder")
    held = sorted(p.name for p in path.iterdir()) if path.is_dir() else []
    if held and not overwrite:
        shown = ", ".join(held[:3]) + (f" and {len(held) - 3} more" if len(held) > 3 else "")
        raise UsageError(f"--out {path}: the folder is not empty ({shown}); choose another --out, or add "
                         "--overwrite to replace the files of the same names")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".bladedamp-write-test-"):
            pass
    except OSError as exc:
        raise UsageError(f"--out {path}: cannot write there ({exc.strerror or exc})") from None
    return path


#: the output folder of every command without --out: results/<design file stem>/<command>,
#: or this folder (the built-in reference configuration: reproduce, montecarlo without a design)
RESULTS = Path("results")


def output_folder(args) -> Path:
    """The folder a command writes into: ``--out``, else ``results/<design file stem>/<command>``
    (so that two designs never share one), ``results/<command>`` for montecarlo without a design
    file and ``results`` for reproduce (the built-in reference configuration)."""
    if args.out is not None:
        return args.out
    if args.command == "reproduce":
        return RESULTS
    design = getattr(args, "design", None)
    return RESULTS / args.command if design is None else RESULTS / design.stem / args.command


# ---------------------------------------------------------------------------------------
# the commands on a design file
# ---------------------------------------------------------------------------------------
def _load(args):
    """The design of ``args.design`` (figures drawn off-screen); a file that sets no key says so
    in one line on stderr (it is the reference design)."""
    import matplotlib

    matplotlib.use("Agg")
    from .design import load_design

    design = load_design(args.design)
    if not design.keys_given:
        print(f"bladedamp {args.command}: note: {args.design} sets no key: running the reference design "
              f"(bladedamp init writes it with every key)", file=sys.stderr)
    return design


def _damped(design, command: str):
    if not design.disk.has_damper:
        raise UsageError(f"{design.path}: [damper] kind = \"none\": {command} needs a damper (cylinder or wedge)")
    return design.disk


def _check_platform_angle_option(design, option: str, angles_deg) -> None:
    """UsageError for a platform-angle option (``option``, its values ``angles_deg``; None or
    empty: not given) with a blade whose flexible platforms fix the angles: a solid FE blade
    ([blade] model = "solid", surface_file, or a solid blade's modal_file) has its contact faces
    at its geometry's platform angles, and its FE field at a contact point holds only for the
    disk at those angles (:meth:`bladedamp.blade.solid.SolidModalBlade.platform_displacements`), so
    a study at other angles would stop at its first frequency response."""
    blade = design.disk.blade
    if not angles_deg or not getattr(blade, "flexible_platform", False):
        return
    import json

    import numpy as np

    b = design.values.get("blade", {})
    face = f"{np.degrees(blade.face_fields['OR'].gamma):.4g}"
    if b.get("surface_file") is not None:
        source = f"[blade] surface_file = {json.dumps(b['surface_file'])}, its OR face at {face} deg"
        remedy = "another angle needs another STL"
    elif b.get("modal_file") is not None:
        source = f"[blade] modal_file = {json.dumps(b['modal_file'])}, its OR face at {face} deg"
        remedy = "another angle needs another blade file"
    else:
        source = f"[blade] model = \"solid\", meshed at [disk] gamma_right_deg = {face}"
        remedy = "set [disk] gamma_right_deg for another angle"
    raise UsageError(f"{option}: a solid FE blade's platform angles come from its geometry ({design.path}: {source}), "
                     f"and its flexible platforms hold at those angles only; remove {option} ({remedy}), or study "
                     "the angles with the built-in beam blade")


def _done(out: Path, t0: float, what: str) -> int:
    """The last line of a command on a design (what it found, where it wrote), after the
    run's warnings were added to its summary.md and results.json (:class:`Notes`)."""
    if Notes.current is not None:
        Notes.current.write(out)
    print(f"{what}; wrote {out / 'summary.md'}, results and figures in {out} ({time.perf_counter() - t0:.1f} s)",
          file=sys.stderr)
    return 0


def init_command(args) -> int:
    """``bladedamp init``: the reference design, every key commented."""
    from .design import write_template

    path = write_template(args.design, overwrite=args.overwrite)
    print(f"wrote the reference design to {path}; edit it, then run: bladedamp frf {path}", file=sys.stderr)
    return 0


def precompile_command(args) -> int:
    """``bladedamp precompile``: every numba kernel compiled into the per-user cache."""
    from .compilation import precompile

    seconds = precompile(progress=lambda line: print(line, file=sys.stderr))
    from . import NUMBA_CACHE_DIR

    where = NUMBA_CACHE_DIR or "numba's cache folder (NUMBA_CACHE_DIR)"
    print(f"compiled kernels in {where} ({sum(seconds.values()):.1f} s); later processes only load them",
          file=sys.stderr)
    return 0


def _check_mistuning(args, design) -> None:
    """UsageError where ``--mistuned`` is given to a design without a [mistuning] table."""
    if args.mistuned and design.mistuning is None:
        raise UsageError(f"{design.path}: --mistuned needs a [mistuning] table (std and seed, or kappa)")


def frf_command(args) -> int:
    """``bladedamp frf``: the frequency response of the design at each of its engine orders."""
    import dataclasses

    from .compare import bounded_without_damper
    from .report import frf_outputs

    t0 = time.perf_counter()
    design = _load(args)
    _check_mistuning(args, design)
    measured = None
    if args.measured is not None:                 # read before the solve: a bad file stops at once
        from .measurement import load_measurement

        measured = load_measurement(args.measured, unit=args.measured_unit, record=args.measured_record)
    out = output_dir(output_folder(args), args.overwrite)
    progress, a = Progress(), design.analysis
    progress.compiling()
    responses = {}
    # a branch that stops early is checked by time integration just beyond its stop (a minute or
    # more): its result then says whether a periodic motion exists there (TunedDisk / MistunedDisk.stop_check)
    # and a complete branch's peak is checked by time integration at its frequency
    # (TunedDisk / MistunedDisk.peak_check)
    rigid = not design.disk.blade.flexible_platform
    checks = dict(check_stop=not args.no_stop_check and rigid, check_peak=not args.no_peak_check and rigid)
    for eo in design.engine_orders:
        progress(f"frequency response at EO = {eo}, {a.f_start_hz:g}-{a.f_end_hz:g} Hz")
        responses[f"EO{eo}"] = design.disk_at(eo).frequency_response(a.f_start_hz, a.f_end_hz, **checks,
                                                                    **a.options())
    if args.mistuned:
        progress(f"mistuned full assembly at EO = {design.disk.engine_order}")
        responses[f"mistuned_EO{design.disk.engine_order}"] = design.mistuned_disk().frequency_response(
            a.f_start_hz, a.f_end_hz, **checks, **a.options())
    undamped = {}
    if design.disk.has_damper:      # the damper-free reference of the figure: linear, one harmonic is exact
        progress("damper-free reference responses")
        for eo in design.engine_orders:
            free = dataclasses.replace(design.disk_at(eo), damper=None)
            if not bounded_without_damper(free, a.f_start_hz, a.f_end_hz):
                continue
            undamped[f"EO{eo}"] = free.frequency_response(a.f_start_hz, a.f_end_hz, harmonics=(1,), max_step=a.max_step,
                                                          estimate_harmonic_error=False)
    summary = frf_outputs(out, design, responses, undamped, measured=measured)
    for k, v in summary["responses"].items():      # each response's status first
        print(f"{k}: {v['status_message']}", file=sys.stderr)
        if Notes.current is not None:
            Notes.current.said(v["status_message"])
    peaks = ", ".join(f"{k} {'largest amplitude at the range end' if v['peak_at_range_end'] else 'peak'} "
                      f"{'(check failed) ' if v['status'] == 'check failed' else ''}"
                      f"{v['peak_amplitude_mm']:.4f} mm at {v['peak_frequency_hz']:.3f} Hz"
                      if v["peak_amplitude_mm"] is not None and math.isfinite(v["peak_amplitude_mm"])
                      else f"{k} no peak: no point computed (summary.md says why)"
                      for k, v in summary["responses"].items())
    return _done(out, t0, peaks)


def optimize_command(args) -> int:
    """``bladedamp optimize``: the optimal damper mass, optionally over platform angles or
    wedge contact heights."""
    from .report import fmt_percent, optimize_outputs
    from .studies.design import platform_angle_study, with_contact_height
    from .studies.mass import optimal_mass

    t0 = time.perf_counter()
    design = _load(args)
    disk, a = _damped(design, "optimize"), design.analysis
    if args.contact_height_mm and disk.damper.kind != "wedge":
        raise UsageError(f"--contact-height-mm applies to a wedge damper ({design.path}: [damper] kind = "
                         f"\"{disk.damper.kind}\")")
    for g in args.gamma_right_deg or ():
        if not 0 < g < 90:
            raise UsageError(f"--gamma-right-deg {g:g}: must be in (0, 90) deg")
    _check_platform_angle_option(design, "--gamma-right-deg", args.gamma_right_deg)
    for h in args.contact_height_mm or ():
        if not 0 < h <= 100:
            raise UsageError(f"--contact-height-mm {h:g}: must be in (0, 100] mm")
    if args.parameters:
        return optimize_parameters(args, design, disk, t0)
    if args.mistuning_std is not None:
        raise UsageError("--mistuning-std: a design robust to mistuning is searched over --parameters (e.g. --parameters mass_g)")
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    options = dict(f_range_hz=a.f_range_hz, harmonics=a.study_harmonics)
    progress(f"optimal mass in {1e3 * a.mass_bounds[0]:g}-{1e3 * a.mass_bounds[1]:g} g")
    optimum = optimal_mass(disk, a.mass_bounds, processes=args.processes, progress=progress.bar("mass grid"),
                           complete_grid=True, **options)      # the whole curve for optimize.png
    angles = heights = None
    if args.gamma_right_deg:
        angles = platform_angle_study(disk, args.gamma_right_deg, mass_bounds=a.mass_bounds, processes=args.processes,
                                      progress=progress.bar("platform angles"), **options)
    if args.contact_height_mm:
        heights = []
        for h in args.contact_height_mm:
            progress(f"optimal mass at h_C = {h:g} mm")
            heights.append((1e-3 * h, optimal_mass(with_contact_height(disk, 1e-3 * h), a.mass_bounds,
                                                   processes=args.processes,
                                                   progress=progress.bar(f"mass grid at h_C = {h:g} mm"), **options)))
    optimize_outputs(out, design, optimum, angles, heights)
    return _done(out, t0, f"optimal mass {1e3 * optimum.mass:.4g} g, peak {1e3 * optimum.peak_amplitude:.4f} mm, "
                          f"reduction {fmt_percent(optimum.reduction)}")


def _parameter_keys(args, disk) -> list:
    """The design-file keys of ``--parameters`` (whole keys or their last part), each one this
    disk can differentiate (checked on a small system before any solve); UsageError naming it."""
    from .diskmodel import resolve_parameter_key

    try:
        keys = [resolve_parameter_key(p) for p in args.parameters]
        if len(set(keys)) != len(keys):
            raise ValueError("a parameter is given twice")
        disk.parameter_derivatives(disk.hbm_system((0, 1), 16), keys)
    except ValueError as exc:
        raise UsageError(f"--parameters: {exc}") from None
    return keys


def sensitivities_command(args) -> int:
    """``bladedamp sensitivities``: the derivatives of the resonance peak in design parameters (of
    the design's tuned disk, or with ``--mistuned`` of its mistuned full assembly)."""
    from .report import sensitivity_outputs

    t0 = time.perf_counter()
    design = _load(args)
    _check_mistuning(args, design)
    disk, a = design.mistuned_disk() if args.mistuned else design.disk, design.analysis
    keys = _parameter_keys(args, disk)
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    progress(f"{'mistuned full assembly: ' if args.mistuned else ''}frequency response {a.f_start_hz:g}-{a.f_end_hz:g} Hz")
    response = disk.frequency_response(a.f_start_hz, a.f_end_hz, **a.options())
    if not response.success:
        print(f"bladedamp sensitivities: the frequency response is not a success, its peak is not differentiated: "
              f"{response.status_message}", file=sys.stderr)
        return 1
    progress(f"derivatives of the peak in {len(keys)} parameters")
    try:
        peak = response.peak_sensitivities(keys)
    except ValueError as exc:
        print(f"bladedamp sensitivities: {exc}", file=sys.stderr)
        return 1
    sensitivity_outputs(out, design, peak, mistuned=args.mistuned)
    print(peak.table())
    return _done(out, t0, f"peak {1e3 * peak.peak_amplitude:.4f} mm at {peak.peak_frequency_hz:.4f} Hz")


def fit_command(args) -> int:
    """``bladedamp fit``: contact parameters fitted to measured responses."""
    from .fit import fit_contact
    from .measurement import load_measurement
    from .report import fit_outputs

    t0 = time.perf_counter()
    design = _load(args)
    disk = _damped(design, "fit")
    keys = _parameter_keys(args, disk)
    measured = [load_measurement(m, unit=args.measured_unit) for m in args.measured]
    forces = args.excitation_n
    if forces is not None:
        if len(forces) != len(measured):
            raise UsageError(f"--excitation-n: give one force per measured file ({len(measured)}; got {len(forces)})")
        for f in forces:
            if not (math.isfinite(f) and f > 0):
                raise UsageError(f"--excitation-n {f:g}: must be a force amplitude > 0 N")
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    progress(f"least squares of {len(keys)} parameters on {len(measured)} measurement(s)")
    fit = fit_contact(disk, measured, keys, excitations=forces, harmonics=design.analysis.study_harmonics)
    fit_outputs(out, design, fit, [m.name for m in args.measured])
    print(fit.table())
    return _done(out, t0, f"fit {'converged' if fit.success else 'not converged'}, relative residual rms "
                          f"{fit.residual_rms:.3g}")


def optimize_parameters(args, design, disk, t0) -> int:
    """``bladedamp optimize --parameters``: the lowest peak over several parameters together, by
    L-BFGS-B with the analytic gradient (:func:`bladedamp.studies.gradient.optimal_design`)."""
    from .report import gradient_optimize_outputs
    from .studies.gradient import default_bounds, optimal_design

    if args.gamma_right_deg or args.contact_height_mm:
        raise UsageError("--parameters optimises the keys together: give gamma_right_deg as one of them instead of "
                         "--gamma-right-deg / --contact-height-mm")
    if args.mistuning_std is not None and not 0 < args.mistuning_std < 0.2:
        raise UsageError(f"--mistuning-std {args.mistuning_std:g}: must be in (0, 0.2)")
    if args.disks < 2:
        raise UsageError(f"--disks {args.disks}: must be at least 2")
    if args.statistic != "mean":
        try:
            args.statistic = float(args.statistic)
        except ValueError:
            raise UsageError(f"--statistic {args.statistic}: 'mean' or a quantile in (0, 1)") from None
        if not 0 < args.statistic < 1:
            raise UsageError(f"--statistic {args.statistic:g}: 'mean' or a quantile in (0, 1)")
    keys = _parameter_keys(args, disk)
    a = design.analysis
    mass_g = tuple(1e3 * m for m in a.mass_bounds)
    bounds = {k: default_bounds(disk, k, mass_g) for k in keys}
    for key, low, high in args.bound or ():
        try:
            from .diskmodel import resolve_parameter_key

            full = resolve_parameter_key(key)
            low, high = float(low), float(high)
        except ValueError as exc:
            raise UsageError(f"--bound {key} {low} {high}: {exc}") from None
        if full not in bounds:
            raise UsageError(f"--bound {key}: not one of --parameters ({', '.join(keys)})")
        if not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise UsageError(f"--bound {key} {low:g} {high:g}: must be finite with LOW < HIGH")
        bounds[full] = (low, high)
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    if args.starts is not None and args.starts < 1:
        raise UsageError(f"--starts {args.starts}: must be at least 1")
    if args.mistuning_std is None:
        progress(f"lowest peak over {', '.join(keys)} (screening, then L-BFGS-B with the analytic gradient)")
        optimum = optimal_design(disk, keys, [bounds[k] for k in keys], a.f_range_hz, harmonics=a.study_harmonics,
                                 n_starts=args.starts)
    else:
        from .studies.robust import robust_design

        progress(f"lowest {args.statistic} largest blade peak of {args.disks} mistuned disks (std "
                 f"{100 * args.mistuning_std:g} %) over {', '.join(keys)}, on "
                 + ("this process" if args.processes == 1 else "a local Dask cluster"))
        optimum = robust_design(disk, keys, [bounds[k] for k in keys], std=args.mistuning_std, n_disks=args.disks,
                                seed=design.mistuning.seed if design.mistuning else 0, statistic=args.statistic,
                                harmonics=a.study_harmonics, n_starts=args.starts,
                                scheduler="serial" if args.processes == 1 else None, n_workers=args.processes)
    gradient_optimize_outputs(out, design, optimum, a.study_harmonics)
    print(optimum.table())
    what = "peak" if args.mistuning_std is None else f"{args.statistic} largest blade peak of the mistuned disks"
    return _done(out, t0, f"{what} {1e3 * optimum.peak_amplitude:.4f} mm at the optimum "
                          f"({100 * optimum.reduction:.1f} % below the design's), {optimum.n_responses} evaluations")


def engine_orders(args, design) -> tuple:
    """The engine orders of ``--engine-orders`` (default: the design's), each checked >= 0."""
    eos = tuple(args.engine_orders or design.engine_orders)
    for eo in eos:
        if eo < 0:
            raise UsageError(f"--engine-orders {eo}: must be an integer >= 0")
    return eos


def eo_sweep_command(args) -> int:
    """``bladedamp eo-sweep``: the optimal damper mass at each engine order."""
    from .report import eo_sweep_outputs
    from .studies.design import engine_order_sweep

    t0 = time.perf_counter()
    design = _load(args)
    disk, a = _damped(design, "eo-sweep"), design.analysis
    eos = engine_orders(args, design)
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    sweep = engine_order_sweep(design.disk_at(1), sorted(set(eos)), a.mass_bounds, design.rotor_speed_eo0_hz, a.f_range_hz,
                               harmonics=a.study_harmonics, progress=progress.bar("engine orders"),
                               processes=args.processes)
    eo_sweep_outputs(out, design, sweep)
    return _done(out, t0, f"engine orders {', '.join(map(str, sweep.engine_orders))}: reductions "
                          f"{', '.join(f'{100 * r:.1f} %' for r in sweep.reduction)}")


def _rotor_speed_range_hz(design, args, engine_orders) -> tuple[float, float]:
    """The rotor-speed range [Hz] of zzenf and campbell: --speed-range-rpm, else the design's
    fixed rotor speed, else the speeds at which the engine orders > 0 excite [analysis]
    frequency_range_hz (f_start / largest EO to f_end / smallest EO), 10 % wider each side."""
    if args.speed_range_rpm is not None:
        lo, hi = args.speed_range_rpm
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
            raise UsageError(f"--speed-range-rpm {lo:g} {hi:g}: must be 0 < LOW <= HIGH rpm")
        return lo / 60, hi / 60
    if design.rotor_speed_hz is not None:
        return design.rotor_speed_hz, design.rotor_speed_hz
    moving = [eo for eo in engine_orders if eo > 0]
    if not moving:
        raise UsageError(f"{design.path}: [disk] engine_order holds EO = 0 only, whose excitation does not follow "
                         "the rotor speed: give --speed-range-rpm LOW HIGH or an engine order > 0")
    a = design.analysis
    return 0.9 * a.f_start_hz / max(moving), 1.1 * a.f_end_hz / min(moving)


def _top_frequency_hz(design, args) -> float:
    if args.f_max_hz is None:
        return 1.25 * design.analysis.f_end_hz
    if not (math.isfinite(args.f_max_hz) and args.f_max_hz > 0):
        raise UsageError(f"--f-max-hz {args.f_max_hz:g}: must be > 0 Hz")
    return args.f_max_hz


def zzenf_command(args) -> int:
    """``bladedamp zzenf``: the interference (ZZENF) diagram of the design's disk."""
    from .report import zzenf_outputs
    from .studies.interference import interference_diagram

    t0 = time.perf_counter()
    design = _load(args)
    speeds = _rotor_speed_range_hz(design, args, design.engine_orders)
    f_max = _top_frequency_hz(design, args)
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    progress.compiling()
    progress(f"natural frequencies of nodal diameters 0-{design.disk.n_blades // 2} at "
             f"{60 * speeds[0]:.0f}-{60 * speeds[1]:.0f} rpm")
    diagram = interference_diagram(design.disk, speeds, f_max, design.engine_orders)
    summary = zzenf_outputs(out, design, diagram)
    return _done(out, t0, f"{len(summary['crossings'])} possible resonances of engine orders "
                          f"{', '.join(map(str, design.engine_orders))} up to {f_max:g} Hz")


def campbell_command(args) -> int:
    """``bladedamp campbell``: resonance crossings over rotor speed with the damped peak at each."""
    import dataclasses

    from .report import campbell_outputs
    from .studies.interference import campbell_diagram

    t0 = time.perf_counter()
    design = _load(args)
    _damped(design, "campbell")
    if design.rotor_speed_hz is not None:
        raise UsageError(f"{design.path}: [disk] rotor_speed_rpm fixes the rotor speed; campbell follows each engine "
                         "order over rotor speed (set rotor_speed_rpm = \"auto\"; --speed-range-rpm sets the diagram's range)")
    eos = tuple(sorted(set(engine_orders(args, design))))
    speeds = _rotor_speed_range_hz(design, args, eos)
    f_max = _top_frequency_hz(design, args)
    out = output_dir(output_folder(args), args.overwrite)
    progress, a = Progress(), design.analysis
    progress.compiling()
    disk = dataclasses.replace(design.disk, engine_order=1, rotor_speed_hz=None)
    diagram = campbell_diagram(disk, eos, a.f_range_hz, speeds, f_max, harmonics=(1,), progress=progress,
                               max_step=a.max_step, harmonic_tolerance=a.harmonic_tolerance)
    summary = campbell_outputs(out, design, diagram)
    for c in summary["crossings"]:
        print(f"EO {c['engine_order']}: {c['status_message']}", file=sys.stderr)
        if Notes.current is not None:
            Notes.current.said(c["status_message"])
    return _done(out, t0, ", ".join(
        f"EO {c['engine_order']} peak {c['peak_amplitude_mm']:.4f} mm at {c['peak_frequency_hz']:.3f} Hz, "
        f"{c['rotor_speed_rpm']:.0f} rpm" + ("" if c["found"] else " (no resonance found in the range)")
        if c["peak_amplitude_mm"] is not None else f"EO {c['engine_order']} no point computed"
        for c in summary["crossings"]) or "no engine order > 0: no crossing")


def monte_carlo_command(args) -> int:
    """``bladedamp montecarlo``: peak amplification of N mistuned disks (the design's, or the
    reference disk) on Dask."""
    import dataclasses

    from .design import reference_design
    from .report import montecarlo_outputs
    from .studies.mistuning import MONTE_CARLO_MAX_STEP, MONTE_CARLO_TOL, PAPER_STD, monte_carlo

    t0 = time.perf_counter()
    if args.design is not None and (args.damper is not None or args.mass is not None):
        raise UsageError("--damper and --mass choose the reference disk's damper: with a design file, "
                         "set them in its [damper] table")
    if args.scheduler != "serial":
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise UsageError("the Monte Carlo runs on Dask: pip install 'bladedamp[distributed]' "
                             "(or use --scheduler serial)") from None
    import matplotlib

    matplotlib.use("Agg")
    if args.design is not None:
        design = _load(args)
    else:
        from .reference import reference_disk

        design = reference_design()
        design = dataclasses.replace(design, disk=reference_disk(args.damper or "cylinder",
                                                                 1e-3 * (1.0 if args.mass is None else args.mass)))
    disk = _damped(design, "montecarlo")
    out = output_dir(output_folder(args), args.overwrite)
    file_mistuning = design.mistuning if args.design is not None else None
    std = args.std if args.std is not None else (file_mistuning.std if file_mistuning else PAPER_STD)
    seed = args.seed if args.seed is not None else (file_mistuning.seed if file_mistuning else 0)
    progress = Progress()
    progress.compiling()
    result = monte_carlo(disk, args.disks, std=std, seed=seed, harmonics=design.analysis.study_harmonics,
                         scheduler=None if args.scheduler == "local" else args.scheduler, n_workers=args.workers,
                         progress=progress.bar("Monte Carlo disks"), out=None,
                         max_step=MONTE_CARLO_MAX_STEP if args.max_step is None else args.max_step,
                         tol=MONTE_CARLO_TOL if args.tol is None else args.tol)
    result.save(out / "montecarlo")
    saved = sorted(p.name for p in out.glob("montecarlo.*"))
    summary = montecarlo_outputs(out, design, result, saved)
    n, failed = summary["n_disks"], summary["n_failed"]
    what = f"{n - failed} of {n} disks solved"
    if n > failed:
        lo, hi = summary["amplification_mean_ci95"]
        what += (f": largest amplification per disk mean {summary['amplification_mean']:.4f} "
                 f"(95 % CI [{lo:.4f}, {hi:.4f}]), max {summary['amplification_max']:.4f}")
    return _done(out, t0, what)


def show_command(args) -> int:
    """``bladedamp show``: the resonance's operating deflection shape as standalone HTML."""
    import importlib.util

    missing = [m for m in ("meshcat", "trimesh") if importlib.util.find_spec(m) is None]
    if missing:
        raise UsageError(f"the 3D view needs {' and '.join(missing)}: pip install 'bladedamp[viz]'")
    from .report import show_outputs
    from .viz import show

    t0 = time.perf_counter()
    design = _load(args)
    out = output_dir(output_folder(args), args.overwrite)
    a = design.analysis
    progress = Progress()
    if args.saved is not None:
        response = saved_response(design, args.saved)
        progress(f"frequency response at EO = {design.disk.engine_order} read from {args.saved}")
    else:
        progress.compiling()
        progress(f"frequency response at EO = {design.disk.engine_order}, {a.f_start_hz:g}-{a.f_end_hz:g} Hz")
        response = design.disk.frequency_response(a.f_start_hz, a.f_end_hz, **a.options())
    options = {} if args.layout is None else {"layout": args.layout}
    if design.blade_geometry is not None:
        options["blade_geometry"] = design.blade_geometry
    html = out / "ods.html"
    show(response, path=html, **options)
    show_outputs(out, design, response, html)
    return _done(out, t0, f"3D view of the resonance at {response.peak_frequency_hz:.3f} Hz in {html}")


def compare_inputs(args) -> list:
    """The designs of ``bladedamp compare``: each positional input (a design file, or a folder of
    ``bladedamp frf`` results) and each ``--from`` folder, in that order, as
    :class:`bladedamp.compare.Compared`; a folder's responses are read, a design file's left
    empty (computed by :func:`compare_command` once every input is checked). UsageError for an
    input that is neither."""
    from .compare import Compared, design_of_saved, saved_frf
    from .design import load_design

    sources = [Path(p) for p in args.designs] + [Path(p) for p in (args.saved or ())]
    if len(sources) < 2:
        raise UsageError(f"give at least two designs to compare (design files or folders written by bladedamp frf; "
                         f"got {len(sources)})")
    entries = []
    for source in sources:
        if source.is_dir():
            try:
                responses, design_path, files = saved_frf(source)
            except ValueError as exc:
                raise UsageError(str(exc)) from None
            design, note = design_of_saved(source, design_path)
            name = design_path.stem if design_path is not None else source.name
            entries.append(Compared(name, source, responses, design, files, note))
        else:
            if source.suffix.lower() != ".toml" and not source.exists():
                raise UsageError(f"{source}: neither a design file (.toml) nor a folder of bladedamp frf results")
            entries.append(Compared(source.stem, source, {}, load_design(source)))
    names = [e.name for e in entries]
    for e in entries:                  # the same stem twice (a design and its saved results): say which
        if names.count(e.name) > 1:
            e.name = f"{e.name} ({e.source})"
    return entries


def compare_command(args) -> int:
    """``bladedamp compare``: the frequency responses of several designs in one figure and a
    table of their peaks, resonance frequencies and reductions."""
    import matplotlib

    matplotlib.use("Agg")
    from .compare import compare_outputs, damper_free_key, undamped_responses

    t0 = time.perf_counter()
    entries = compare_inputs(args)
    out = output_dir(output_folder(args), args.overwrite)
    progress = Progress()
    if any(not e.responses for e in entries):
        progress.compiling()
    for e in entries:
        if not e.responses:            # a design file: its tuned responses (no time integration checks)
            a = e.design.analysis
            for eo in e.design.engine_orders:
                progress(f"{e.name}: frequency response at EO = {eo}, {a.f_start_hz:g}-{a.f_end_hz:g} Hz")
                e.responses[f"EO{eo}"] = e.design.disk_at(eo).frequency_response(a.f_start_hz, a.f_end_hz,
                                                                                **a.options())
    known = [e for e in entries if e.design is not None]
    keys = {damper_free_key(e.design) for e in known}
    shared = len(known) == len(entries) and len(keys) == 1
    undamped, by_key = {}, {}
    for e in known:                    # one damper-free response per distinct blade, disk and excitation
        key = damper_free_key(e.design)
        if key not in by_key:
            progress(f"damper-free reference of {e.name}")
            by_key[key] = undamped_responses(e.design, list(e.responses))
        for label in e.responses:
            free = by_key[key][label] if label in by_key[key] else undamped_responses(e.design, [label]).get(label)
            if free is not None:       # None: no bounded damper-free response (a note says so)
                undamped[e.name, label] = free
    summary = compare_outputs(out, entries, undamped, shared)
    for row in summary["designs"]:                 # each response's status first, as frf
        print(f"{row['design']} {row['response']}: {row['status_message']}", file=sys.stderr)
        if Notes.current is not None:
            Notes.current.said(row["status_message"])
    what = "; ".join(f"{row['design']} {row['response']} peak {row['peak_amplitude_mm']:.4f} mm at "
                     f"{row['peak_frequency_hz']:.3f} Hz" for row in summary["designs"])
    return _done(out, t0, what)


def saved_response(design, folder: Path):
    """The response of ``design``'s first engine order saved by ``bladedamp frf`` in ``folder``,
    with the design's disk attached (for the 3D view). UsageError when the folder holds no such
    results or they are of another design, or of the design before it was changed."""
    import dataclasses

    from .compare import saved_frf

    try:
        responses, design_path, _ = saved_frf(folder)
    except ValueError as exc:
        raise UsageError(f"--from {exc}") from None
    if design_path is None or not design_path.exists() or design_path.resolve() != Path(design.path).resolve():
        raise UsageError(f"--from {folder}: its results are of {design_path or 'an unnamed design'}, not of "
                         f"{design.path}")
    if Path(design.path).stat().st_mtime > (folder / "results.json").stat().st_mtime:
        raise UsageError(f"--from {folder}: {design.path} was changed after the results were saved; run "
                         f"bladedamp frf {design.path} again")
    label = f"EO{design.disk.engine_order}"
    if label not in responses:
        raise UsageError(f"--from {folder}: no response at EO = {design.disk.engine_order} (holds "
                         f"{', '.join(responses)})")
    return dataclasses.replace(responses[label], disk=design.disk)


def app_command(args) -> int:
    """``bladedamp app``: the damper-design dashboard served by Voila on localhost until Ctrl+C."""
    import importlib.util
    import signal
    import subprocess

    if importlib.util.find_spec("voila") is None:
        raise UsageError("the app is served by voila, which is not installed: pip install 'bladedamp[app]'")
    from .app import free_port, port_in_use, voila_command, wait_for_port

    if args.port is not None:
        if not 1024 <= args.port <= 65535:
            raise UsageError(f"--port {args.port}: must be in [1024, 65535]")
        if port_in_use(args.port):
            raise UsageError(f"--port {args.port}: in use on 127.0.0.1; choose another or leave --port out")
    port = args.port if args.port is not None else free_port()
    url = f"http://127.0.0.1:{port}/"

    def stop(signum, frame):           # a terminated command stops its server too
        raise KeyboardInterrupt
    previous = signal.signal(signal.SIGTERM, stop)
    server = subprocess.Popen(voila_command(port))
    try:
        if not wait_for_port(port, 60.0, process=server):
            server.terminate()
            server.wait(10)
            raise UsageError(f"voila did not start on port {port} (exit code {server.returncode}); see its messages above")
        print(f"bladedamp app: the damper-design dashboard is at {url} (Ctrl+C stops it)", file=sys.stderr, flush=True)
        if not args.no_browser:
            import webbrowser

            webbrowser.open(url)
        server.wait()
    except KeyboardInterrupt:
        pass
    finally:
        if server.poll() is None:
            server.terminate()
            try:
                server.wait(10)
            except subprocess.TimeoutExpired:
                server.kill()
        signal.signal(signal.SIGTERM, previous)
    return 0


def reproduce_command(args) -> int:
    """``bladedamp reproduce``: the output folder checked, then the paper's pipeline
    (:func:`bladedamp.reproduce.reproduce`) with the figures drawn off-screen."""
    out = output_dir(output_folder(args), args.overwrite)
    import matplotlib

    matplotlib.use("Agg")
    from .reproduce import reproduce

    summary = reproduce(out, args.processes, progress=Progress())
    print(f"wrote {out / 'summary.json'}, {out / 'report.md'} and figures in {summary['timings_s']['total_s']:.1f} s",
          file=sys.stderr)
    return 0


# ---------------------------------------------------------------------------------------
# parsing
# ---------------------------------------------------------------------------------------
def _validate_flags(args) -> None:
    """UsageError naming the flag and its allowed range for zero, negative or NaN values."""
    from . import validation

    try:
        for flag in ("processes", "workers", "disks"):
            value = getattr(args, flag, None)
            if value is not None:
                validation.integer(f"--{flag}", value, minimum=1)
        if getattr(args, "max_step", None) is not None:
            validation.in_range("--max-step", args.max_step, 0.0, 1.0, closed="right")
        if getattr(args, "tol", None) is not None:
            validation.in_range("--tol", args.tol, 0.0, 1.0, closed="neither")
        if getattr(args, "std", None) is not None:
            validation.in_range("--std", args.std, 0.0, 0.2, closed="left")
        if getattr(args, "mass", None) is not None:
            validation.in_range("--mass (g)", args.mass, 0.0, 1000.0, closed="right")
        if getattr(args, "seed", None) is not None:
            validation.integer("--seed", args.seed, minimum=0)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if hasattr(args, "format"):
        from .plotting import check_figure_output

        try:
            args.format, args.dpi = check_figure_output(args.format, args.dpi)
        except ValueError as exc:
            raise UsageError(f"--{exc}") from None


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command (plain-text help)."""
    fmt = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(prog="bladedamp", description=__doc__, formatter_class=fmt)
    sub = parser.add_subparsers(dest="command", required=True, metavar="command")

    def command(name, run, summary, description):
        p = sub.add_parser(name, help=summary, description=f"{summary}.\n\n{description}", formatter_class=fmt)
        p.set_defaults(run=run)
        return p

    def design_arg(p):
        p.add_argument("design", type=Path, help="the design file (TOML; write one with: bladedamp init design.toml)")

    def parameters_arg(p, default=None):
        p.add_argument("--parameters", nargs="+", metavar="KEY", required=default is None, default=default,
                       help="design-file keys, whole (damper.mass_g) or their last part (mass_g); an entry of a list as\n"
                            "natural_frequencies_hz[0]. With derivatives: mass_g, friction_coefficient,\n"
                            "tangential_stiffness_per_length_n_per_m2, normal_to_tangential_stiffness,\n"
                            "roughness_reference_load_n, damper_radius_mm, rotor_speed_rpm (fixed speed),\n"
                            "excitation_n_nm[i], natural_frequencies_hz[j], damping_ratio (or [j]), gamma_left_deg,\n"
                            "gamma_right_deg, length_mm, cylinder_radius_mm, contact_height_mm")

    def out_arg(p, default):
        p.add_argument("--out", type=Path, default=None,
                       help=f"output folder, created if needed and checked before computing; one that holds files\n"
                            f"is refused unless --overwrite is given (default: {default})")
        p.add_argument("--overwrite", action="store_true",
                       help="write into an --out folder that holds files already, replacing the files of the same\n"
                            "names (the others stay)")

    def figure_args(p):
        p.add_argument("--format", default="png", metavar="FORMATS",
                       help="file formats of the figures, comma-separated from png, svg, pdf (default: png)")
        p.add_argument("--dpi", type=int, default=120,
                       help="resolution of the PNG figures in dots per inch, in [10, 2400] (default: 120)")

    def processes_arg(p):
        p.add_argument("--processes", type=int, default=None,
                       help="worker processes for independent cases (default: every core)")

    p = command("init", init_command, "write the reference design file, every key commented",
                "Writes the paper's reference disk as a TOML design file; each key has its unit, allowed range\n"
                "and the reason for its value beside it. Edit it, then run e.g.: bladedamp frf design.toml")
    p.add_argument("design", type=Path, nargs="?", default=Path("design.toml"),
                   help="the file to write (default: design.toml)")
    p.add_argument("--overwrite", "--force", action="store_true", help="replace the file if it exists")

    p = command("frf", frf_command, "frequency response of a design",
                "Harmonic balance and arc-length continuation over [analysis] frequency_range_hz at every\n"
                "engine order of [disk] engine_order. Writes frf.png, frf_<label>.npz, results.json, summary.md.")
    design_arg(p)
    p.add_argument("--mistuned", action="store_true",
                   help="also the mistuned full assembly of the [mistuning] table (about 4 times the cost)")
    p.add_argument("--no-stop-check", action="store_true",
                   help="skip the time integration beyond a branch (tuned or --mistuned) that stops before the end of\n"
                        "the range (by default it runs, 1-3 min, and the summary says whether a periodic motion exists there;\n"
                        "not for solid FE blades with flexible platforms)")
    p.add_argument("--no-peak-check", action="store_true",
                   help="skip the time integration at the peak of a complete branch (by default it runs, 5-31 s,\n"
                        "and gives a direct harmonic error estimate, or fails the branch where the vibration there does\n"
                        "not settle; not for solid FE blades with flexible platforms)")
    p.add_argument("--measured", type=Path, metavar="FILE",
                   help="a measured response drawn on frf.png: a UFF 58 FRF or spectrum (one record), or a CSV\n"
                        "(frequency [Hz], re [m/N], im [m/N] or amplitude [mm]); an FRF times the design's excitation force")
    p.add_argument("--measured-unit", metavar="UNIT", help="the unit of a --measured file that does not state it "
                   "(e.g. m/s^2/N, g/N, mm)")
    p.add_argument("--measured-record", metavar="K", type=int,
                   help="which dataset 58 record of a --measured UFF file holding several (from 0)")
    out_arg(p, "results/<design file name>/frf")
    figure_args(p)

    p = command("optimize", optimize_command, "optimal damper mass of a design",
                "The damper mass of the lowest resonance amplitude in [analysis] mass_range_g (global on a log\n"
                "grid, then a bounded search), optionally re-optimised at several right platform angles or wedge\n"
                "contact heights; or, with --parameters, the lowest peak over several keys together by L-BFGS-B\n"
                "with the analytic gradient, from several starts. Peak searches use [analysis] harmonics, or the\n"
                "paper's [1] where it is 'auto'.\n"
                "Writes optimize.png, results.json, summary.md and the results' npz files.")
    design_arg(p)
    p.add_argument("--gamma-right-deg", type=float, nargs="+", metavar="DEG",
                   help="also optimise the mass at each of these right platform angles [deg], in (0, 90)")
    p.add_argument("--contact-height-mm", type=float, nargs="+", metavar="MM",
                   help="also optimise the mass at each of these wedge contact heights [mm], in (0, 100]")
    parameters_arg(p, [])
    p.add_argument("--bound", nargs=3, action="append", metavar=("KEY", "LOW", "HIGH"),
                   help="with --parameters: the search range of one of them (default: mass_range_g for mass_g,\n"
                        "15-65 deg for the platform angles, 0.5-5 mm for cylinder_radius_mm, else -50 %%..+100 %%)")
    p.add_argument("--starts", type=int, default=None,
                   help="with --parameters: local searches, from the best of the design and 4 Sobol points per\n"
                        "parameter in the box (default: one per parameter)")
    p.add_argument("--mistuning-std", type=float, default=None, metavar="STD",
                   help="with --parameters: a design robust to mistuning: minimise a statistic of the largest blade\n"
                        "peak of --disks mistuned copies (blade frequencies times 1 + STD N(0, 1), the same copies for\n"
                        "every design; STD in (0, 0.2), e.g. 0.02), on a local Dask cluster (--processes workers)")
    p.add_argument("--disks", type=int, default=20, help="with --mistuning-std: mistuned copies (default 20)")
    p.add_argument("--statistic", default="mean",
                   help="with --mistuning-std: 'mean' (default) or a quantile in (0, 1), e.g. 0.95")
    processes_arg(p)
    out_arg(p, "results/<design file name>/optimize")
    figure_args(p)

    p = command("sensitivities", sensitivities_command, "derivatives of the resonance peak in design parameters",
                "The frequency response over [analysis] frequency_range_hz, its peak solved by d|u|/dOmega = 0 and\n"
                "differentiated in each --parameters key with the analytic dR/dp (the implicit function theorem):\n"
                "d peak / dp [mm per unit], d frequency / dp [Hz per unit] and the relative sensitivities.\n"
                "Writes sensitivities.png, peak_sensitivities.npz, results.json, summary.md.")
    design_arg(p)
    parameters_arg(p, ["mass_g", "friction_coefficient", "tangential_stiffness_per_length_n_per_m2",
                       "normal_to_tangential_stiffness", "damper_radius_mm", "excitation_n_nm[0]",
                       "natural_frequencies_hz[0]", "damping_ratio"])
    p.add_argument("--mistuned", action="store_true",
                   help="the mistuned full assembly of the [mistuning] table instead of the tuned sector (its largest\n"
                        "blade's peak; the keys may include kappa[k], blade k's mistuning factor)")
    out_arg(p, "results/<design file name>/sensitivities")
    figure_args(p)

    p = command("fit", fit_command, "contact parameters fitted to measured responses",
                "Least squares of the --parameters keys (the design's values the start) so that the reference blade's\n"
                "tip response in x matches the measured files (one per excitation level: UFF 58 or CSV, as frf\n"
                "--measured), with the analytic Jacobian; estimates with confidence intervals, correlations, and\n"
                "the parameters the data do not identify. Frequency responses with [analysis] harmonics (the\n"
                "paper's [1] where 'auto'). Writes fit.png, fit.npz, results.json, summary.md.")
    design_arg(p)
    p.add_argument("measured", type=Path, nargs="+", metavar="MEASURED", help="measured responses, one per excitation level")
    parameters_arg(p, ["friction_coefficient", "tangential_stiffness_per_length_n_per_m2"])
    p.add_argument("--excitation-n", type=float, nargs="+", metavar="N",
                   help="the force amplitude of each measurement [N], along the design's excitation (default: the\n"
                        "design's excitation for all); an FRF (a unit per N) is scaled by it")
    p.add_argument("--measured-unit", metavar="UNIT", help="the unit of measured files that do not state it "
                   "(e.g. m/s^2/N, g/N, mm)")
    out_arg(p, "results/<design file name>/fit")
    figure_args(p)

    def engine_orders_arg(p):
        p.add_argument("--engine-orders", type=int, nargs="+", metavar="EO",
                       help="engine orders >= 0 (default: the design's [disk] engine_order)")

    p = command("eo-sweep", eo_sweep_command, "optimal damper mass over engine orders",
                "At each engine order the mass is re-optimised in [analysis] mass_range_g (Fig. 7, 8 of the\n"
                "paper). EO = 0 runs at [disk] rotor_speed_eo0_rpm unless rotor_speed_rpm fixes the speed.\n"
                "Writes eo_sweep.png, eo_sweep.npz, results.json, summary.md.")
    design_arg(p)
    engine_orders_arg(p)
    processes_arg(p)
    out_arg(p, "results/<design file name>/eo-sweep")
    figure_args(p)

    def speed_args(p):
        p.add_argument("--speed-range-rpm", type=float, nargs=2, metavar=("LOW", "HIGH"), default=None,
                       help="rotor-speed range [rpm] (default: the design's fixed rotor_speed_rpm, else the speeds at\n"
                            "which its engine orders excite [analysis] frequency_range_hz, 10 %% wider)")
        p.add_argument("--f-max-hz", type=float, default=None,
                       help="top of the diagram [Hz] (default: 1.25 x the end of [analysis] frequency_range_hz)")

    p = command("zzenf", zzenf_command, "interference (ZZENF) diagram of a design",
                "The natural frequencies of the disk per nodal diameter 0..n_blades/2 without dampers and with\n"
                "the dampers stuck (at the lowest and highest rotor speed: the preload m R Omega^2 changes them),\n"
                "and each engine order's excitation EO x rotor speed at its nodal diameter (EO mod n, folded to\n"
                "n - (EO mod n) as a backward wave above n/2). Writes zzenf.png, results.json, summary.md.")
    design_arg(p)
    speed_args(p)
    out_arg(p, "results/<design file name>/zzenf")
    figure_args(p)

    p = command("campbell", campbell_command, "Campbell diagram with the damped resonance at each engine order",
                "Natural frequencies over rotor speed (without dampers; stuck at each engine order's nodal\n"
                "diameter), the lines f = EO x rotor speed, and at each engine order > 0 the damped resonance:\n"
                "the peak of its frequency response over [analysis] frequency_range_hz with the rotor speed\n"
                "following the excitation, one harmonic (the one-harmonic estimate). Needs a damper and\n"
                "rotor_speed_rpm = 'auto'. Writes campbell.png, results.json, summary.md.")
    design_arg(p)
    engine_orders_arg(p)
    speed_args(p)
    out_arg(p, "results/<design file name>/campbell")
    figure_args(p)

    p = command("montecarlo", monte_carlo_command, "Monte Carlo of randomly mistuned disks (Dask)",
                "Peak amplification (largest blade over the tuned peak) of N disks with Gaussian frequency\n"
                "mistuning, full assemblies. On a design file, its disk and [mistuning] std and seed; without\n"
                "one, the reference disk. Writes montecarlo.npz, montecarlo.json, montecarlo.png, summary.md.")
    p.add_argument("design", type=Path, nargs="?", default=None,
                   help="the design file (default: the reference disk, damper from --damper and --mass)")
    p.add_argument("--disks", type=int, default=100, help="number of mistuned disks (default 100)")
    p.add_argument("--std", type=float, default=None,
                   help="standard deviation of the mistuning factors kappa, in [0, 0.2) (default: the design's, "
                        "else 0.02)")
    p.add_argument("--seed", type=int, default=None,
                   help="random seed; disk i depends only on the seed and i (default: the design's, else 0)")
    p.add_argument("--damper", choices=("cylinder", "wedge"), default=None,
                   help="damper of the reference disk, without a design file (default cylinder)")
    p.add_argument("--mass", type=float, default=None,
                   help="damper mass of the reference disk in g, without a design file (default 1)")
    p.add_argument("--workers", type=int, default=None, help="local Dask workers (default: every core)")
    p.add_argument("--scheduler", default="local",
                   help="'local' (a local Dask cluster, no set-up), 'serial' (no Dask) or the address of a Dask "
                        "scheduler such as tcp://host:8786")
    p.add_argument("--max-step", type=float, default=None,
                   help="continuation step per disk, in (0, 1] (default: the Monte Carlo's peak-only setting, 0.1; "
                        "0.05 for full FRF accuracy)")
    p.add_argument("--tol", type=float, default=None,
                   help="continuation tolerance per disk, in (0, 1) (default 1e-6; 1e-10 for full FRF accuracy)")
    out_arg(p, "results/<design file name>/montecarlo, or results/montecarlo without a design")
    figure_args(p)

    p = command("show", show_command, "3D view of a design's resonance (standalone HTML)",
                "The operating deflection shape at the resonance with the contact states of every point, as an\n"
                "HTML file that opens in a browser without a server. Needs the viz extra:\n"
                "pip install 'bladedamp[viz]'. Writes ods.html, frf.npz, summary.md.")
    design_arg(p)
    p.add_argument("--layout", choices=("sector", "disk"), default=None,
                   help="sector (three blades) or disk (every blade); default: disk with a damper, sector without")
    p.add_argument("--from", dest="saved", type=Path, default=None, metavar="DIR",
                   help="read the frequency response that bladedamp frf saved in DIR (of this design file) instead of\n"
                        "computing it again")
    out_arg(p, "results/<design file name>/show")

    p = command("compare", compare_command, "frequency responses of several designs in one figure",
                "Overlays the tip responses of two or more designs (design files, computed; or folders written by\n"
                "bladedamp frf, read), the damper-free response dashed once when they share blade, disk and\n"
                "excitation. Writes compare.png, compare.csv and compare.json (peak, resonance frequency and\n"
                "reduction against the damper-free peak of every design) and summary.md.")
    p.add_argument("designs", type=Path, nargs="*", metavar="DESIGN",
                   help="design files (TOML) or folders of bladedamp frf results")
    p.add_argument("--from", dest="saved", type=Path, action="append", metavar="DIR",
                   help="a folder of bladedamp frf results to compare (repeatable)")
    out_arg(p, "results/compare")
    figure_args(p)

    p = command("app", app_command, "the damper-design dashboard in the browser (Voila)",
                "Serves a teaching dashboard on this machine (127.0.0.1 only): damper type, mass, engine order,\n"
                "friction coefficient and excitation as controls; the frequency response, the 3D contact view at\n"
                "the resonance and the hysteresis loop of a contact point as views. Needs the app extra:\n"
                "pip install 'bladedamp[app]'. Ctrl+C stops the server.")
    p.add_argument("--port", type=int, default=None, help="the port, in [1024, 65535] (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="print the address only, open no browser")

    p = command("reproduce", reproduce_command,
                "reproduce the paper on the built-in reference configuration",
                "Every result of the paper (Table 1, Figs. 4-17) computed on the reference configuration, beside\n"
                "the paper's numbers, with a verdict per row. Writes summary.json, report.md and the figures.\n"
                "About 2 min on two cores.")
    out_arg(p, "results")
    figure_args(p)
    processes_arg(p)

    from .compilation import COLD_COMPILE_SECONDS

    command("precompile", precompile_command, "compile every numba kernel once, ahead of the first run",
            f"numba compiles bladedamp's kernels on their first call (about {COLD_COMPILE_SECONDS} s once per machine and\n"
            "user) and keeps them in ~/.cache/bladedamp/numba. Run this once after installing (a lab machine, a\n"
            "Docker image) and no later run pays it; running it again only loads the cache.")
    return parser


def main(argv=None) -> int:
    """Run ``bladedamp`` with ``argv`` (default: the command line); returns the exit code
    (0 done, 2 a user error: a bad option or output folder, a design file or another file that
    cannot be read or has a bad value; printed as one line on stderr). The warnings raised on
    the way are printed last, one plain line each (:class:`Notes`)."""
    args = build_parser().parse_args(argv)
    from .io import FileReadError

    with Notes() as notes:
        try:
            _validate_flags(args)
            if not hasattr(args, "format"):
                code = args.run(args)
            else:
                from .plotting import figure_output

                with figure_output(args.format, args.dpi):
                    code = args.run(args)
        except (FileReadError, UsageError) as exc:     # a design file or another file, an option
            print(f"bladedamp {args.command}: error: {exc}", file=sys.stderr)
            code = 2
        notes.show()
    return code


if __name__ == "__main__":
    raise SystemExit(main())
