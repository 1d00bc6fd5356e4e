"""Several designs side by side: their frequency responses in one figure and a table of peaks,
resonance frequencies and reductions (``bladedamp compare``), and the saved results of
``bladedamp frf`` read back instead of computed again (``bladedamp compare`` and ``bladedamp show``
with ``--from``).

A design enters as a :class:`Compared`: its name (the design file's stem), its tuned responses
{"EO<n>": DiskResponse} and, where known, its :class:`~bladedamp.design.Design` (the damper-free
reference is computed from it). :func:`saved_frf` reads a folder written by ``bladedamp frf``
(results.json and one ``frf_EO<n>.npz`` per engine order, :func:`bladedamp.load`).

Amplitudes are the first-harmonic tip amplitude u_x, shown in mm; frequencies in Hz.
"""
from __future__ import annotations

import dataclasses
import json
import re
import warnings
from pathlib import Path

import numpy as np

from .report import fmt_number, plain, save_figure, write_json

#: the label of a tuned response in a ``bladedamp frf`` folder: results.json key and frf_<label>.npz
TUNED_LABEL = re.compile(r"^EO(\d+)$")


@dataclasses.dataclass
class Compared:
    """One design of a comparison.

    name : shown in the legend and the table (the design file's stem); source : the design file
    or the results folder it came from; responses : {"EO<n>": DiskResponse} (tuned responses
    only); design : the Design (None: a folder whose design file is missing or changed since);
    files : the saved result files read (empty when computed); note : why there is no design
    """
    name: str
    source: Path
    responses: dict
    design: object = None
    files: list = dataclasses.field(default_factory=list)
    note: str = ""


def saved_frf(folder) -> tuple[dict, Path | None, list]:
    """The tuned responses saved by ``bladedamp frf`` in ``folder``: ({"EO<n>": DiskResponse
    (``disk=None``)}, the design file named in its results.json (None if absent), [the npz files
    read]). Raises ValueError naming the folder or file when there are no such results."""
    from . import load

    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder}: no such results folder (write one with: bladedamp frf design.toml --out {folder})")
    index = folder / "results.json"
    try:
        summary = json.loads(index.read_text())
    except FileNotFoundError:
        raise ValueError(f"{folder}: no results of bladedamp frf (results.json is missing; write them with: "
                         f"bladedamp frf design.toml --out {folder})") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{index}: not a readable results.json ({exc})") from None
    labels = [k for k in (summary.get("responses") or {}) if TUNED_LABEL.match(str(k))] \
        if isinstance(summary, dict) else []
    if not labels:
        raise ValueError(f"{index}: holds no tuned frequency response of bladedamp frf (no 'responses' -> 'EO<n>')")
    responses, files = {}, []
    for label in sorted(labels, key=lambda k: int(TUNED_LABEL.match(k).group(1))):
        path = folder / f"frf_{label}.npz"
        try:
            r = load(path)
        except FileNotFoundError:
            raise ValueError(f"{folder}: results.json lists {label} but {path.name} is missing") from None
        except (OSError, ValueError, KeyError) as exc:
            raise ValueError(f"{path}: not a readable saved response ({exc})") from None
        if getattr(r, "tip_amplitude", None) is None or np.ndim(r.tip_amplitude) != 2:
            raise ValueError(f"{path}: not a tuned disk's frequency response (no tip amplitude per point)")
        responses[label] = r
        files.append(path)
    design = summary.get("design")
    return responses, (Path(design) if design else None), files


def design_of_saved(folder, design_path: Path | None):
    """(Design, "") of a results folder's design file if it still exists and is not newer than the
    results (so it is the design they were computed from), else (None, the reason in words)."""
    from .design import DesignError, load_design

    folder = Path(folder)
    if design_path is None:
        return None, f"{folder}: its results.json names no design file"
    if not design_path.is_file():
        return None, f"{folder}: its design file {design_path} no longer exists"
    if design_path.stat().st_mtime > (folder / "results.json").stat().st_mtime:
        return None, f"{folder}: its design file {design_path} was changed after the results were saved"
    try:
        return load_design(design_path), ""
    except DesignError as exc:
        return None, f"{folder}: its design file cannot be read ({exc})"


def tip_peak(response) -> tuple[float, float]:
    """(peak tip amplitude u_x [m], its frequency [Hz]) on a tuned response's branch, the
    largest point of :attr:`tip_amplitude` [:, 0] (nan, nan for an empty branch)."""
    tip = np.asarray(response.tip_amplitude)[:, 0]
    if not len(tip):
        return float("nan"), float("nan")
    i = int(np.argmax(tip))
    return float(tip[i]), float(response.frequency_hz[i])


def damper_free_key(design) -> str:
    """What the damper-free response of ``design`` depends on, as a comparable string: every
    table of its file but [damper] and [mistuning] (blade, disk, excitation, analysis range).
    Two designs with the same key have the same undamped response."""
    values = {t: v for t, v in design.values.items() if t.split(".")[0] not in ("damper", "mistuning")}
    return json.dumps(plain(values), sort_keys=True, default=str)


def undamped_responses(design, labels) -> dict:
    """{label: the damper-free DiskResponse} of ``design`` at each "EO<n>" of ``labels``: one
    harmonic (linear, exact) over the design's frequency range, widened until its resonance peak
    is inside (:func:`bladedamp.studies.mass.peak_response`; a damper shifts the resonance, so the
    damper-free peak may lie outside the damped design's range). A label whose damper-free disk
    has no bounded response in the range (:func:`bounded_without_damper`) is left out."""
    from .studies.mass import peak_response

    a = design.analysis
    out = {}
    for label in labels:
        eo = int(TUNED_LABEL.match(label).group(1))
        disk = dataclasses.replace(design.disk_at(eo), damper=None)
        if bounded_without_damper(disk, *a.f_range_hz):      # else no reference (a note says why)
            out[label] = peak_response(disk, a.f_range_hz, harmonics=(1,), max_step=a.max_step)[2]
    return out


def comparison_table(entries: list, undamped: dict) -> list[dict]:
    """One row per design and engine order: peak tip amplitude u_x [mm], resonance frequency
    [Hz], the damper-free peak [mm] of that design and the reduction 1 - peak / undamped peak
    [%] (None where the design has no damper-free reference). ``undamped``: {(name, label):
    damper-free response}."""
    rows = []
    for e in entries:
        for label, r in e.responses.items():
            peak, f_peak = tip_peak(r)
            free = undamped.get((e.name, label))
            free_peak = tip_peak(free)[0] if free is not None else float("nan")
            reduction = 1 - peak / free_peak if np.isfinite(free_peak) and free_peak > 0 else float("nan")
            rows.append({"design": e.name, "source": str(e.source), "response": label,
                         "engine_order": int(TUNED_LABEL.match(label).group(1)),
                         "damper": e.design.disk.damper.kind if e.design is not None and e.design.disk.has_damper
                         else ("none" if e.design is not None else None),
                         "damper_mass_g": 1e3 * e.design.disk.damper.mass if e.design is not None
                         and e.design.disk.has_damper else None,
                         "peak_amplitude_mm": 1e3 * peak, "peak_frequency_hz": f_peak,
                         "peak_at_range_end": bool(r.peak_at_range_end),
                         "undamped_peak_amplitude_mm": 1e3 * free_peak, "reduction_pct": 100 * reduction,
                         "status": r.status.value, "status_message": r.status_message,
                         "read_from": [str(p) for p in e.files if p.name == f"frf_{label}.npz"] or None})
    return rows


def compare_outputs(out: Path, entries: list, undamped: dict, shared: bool) -> dict:
    """compare.png, compare.csv, compare.json and summary.md of ``bladedamp compare``.
    ``entries``: [Compared]; ``undamped``: {(name, label): damper-free response}; ``shared``: the
    designs share one damper-free response (drawn once, dashed). Returns compare.json's content."""
    import csv

    import matplotlib.pyplot as plt

    from . import palette

    rows = comparison_table(entries, undamped)
    many_labels = len({label for e in entries for label in e.responses}) > 1
    fig, ax = plt.subplots(figsize=(8, 4.8))
    curves, free_curves, damped_top, free_top = [], [], 0.0, 0.0
    for k, e in enumerate(entries):
        colour = palette.series(k)
        for j, (label, r) in enumerate(e.responses.items()):
            shown = e.name + (f", EO = {label[2:]}" if many_labels else "")
            tip = 1e3 * np.asarray(r.tip_amplitude)[:, 0]
            ax.plot(r.frequency_hz, tip, color=colour, lw=1.6, ls=("-", "-.", ":")[j % 3], label=shown)
            if len(tip):
                i = int(np.argmax(tip))
                ax.plot(r.frequency_hz[i], tip[i], "o", ms=6, mfc="none", mec=colour, mew=1.4, label="_peak")
                damped_top = max(damped_top, float(tip[i]))
            curves.append({"design": e.name, "response": label, "frequency_hz": r.frequency_hz, "tip_amplitude_x_mm": tip})
            free = undamped.get((e.name, label))
            if shared and free is not None and label not in {c["response"] for c in free_curves}:
                free_curves.append({"design": "no damper", "response": label, "frequency_hz": free.frequency_hz,
                                    "tip_amplitude_x_mm": 1e3 * np.asarray(free.tip_amplitude)[:, 0]})
    for c in free_curves:            # the shared damper-free reference, dashed, once per engine order
        ax.plot(c["frequency_hz"], c["tip_amplitude_x_mm"], color=palette.UNDAMPED, ls="--", lw=1.2, zorder=1.5,
                label="no damper" + (f", EO = {c['response'][2:]}" if many_labels else ""))
        free_top = max(free_top, float(np.max(c["tip_amplitude_x_mm"], initial=0.0)))
    curves += free_curves
    if damped_top > 0 and damped_top < 0.25 * free_top:   # both readable: the damped peaks far below
        ax.set_yscale("log")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("tip amplitude u_x [mm]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("frequency responses compared: " + ", ".join(e.name for e in entries))
    from .plotting import place_legend

    place_legend(ax, fontsize=8)
    figures = save_figure(fig, out / "compare.png")

    columns = ["design", "response", "damper", "damper_mass_g", "peak_amplitude_mm", "peak_frequency_hz",
               "peak_at_range_end",
               "undamped_peak_amplitude_mm", "reduction_pct", "status", "source"]
    with open(out / "compare.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(columns)
        for row in rows:
            writer.writerow(["" if plain(row[c]) is None else plain(row[c]) for c in columns])
    summary = {"designs": rows, "curves": curves, "undamped_shared": bool(shared),
               "notes": [e.note for e in entries if e.note]}
    write_json(out / "compare.json", summary)

    lines = [f"# bladedamp compare: {', '.join(e.name for e in entries)}", "",
             "| design | response | damper | peak u_x [mm] | resonance [Hz] | without damper [mm] | reduction | from |",
             "|---|---|---|---|---|---|---|---|"]
    for row in rows:
        damper = "-" if row["damper"] is None else row["damper"] if row["damper_mass_g"] is None else \
            f"{row['damper']} {row['damper_mass_g']:.4g} g"
        at_end = " (largest amplitude at the range end, not a peak)" if row["peak_at_range_end"] else ""
        lines.append(f"| {row['design']} | {row['response']} | {damper} | {fmt_number(row['peak_amplitude_mm'], '.4f')}"
                     f"{at_end} | "
                     f"{fmt_number(row['peak_frequency_hz'], '.3f')} | "
                     f"{fmt_number(row['undamped_peak_amplitude_mm'], '.4f', 'no reference')} | "
                     f"{fmt_number(row['reduction_pct'], '.1f', 'no reference')}"
                     f"{'' if row['reduction_pct'] is None or not np.isfinite(row['reduction_pct']) else ' %'} | "
                     f"`{row['source']}` |")
    lines += ["", *[f"- **{row['design']} {row['response']}**: {row['status_message']}" for row in rows]]
    lines += ["", "Peaks: the largest first-harmonic tip amplitude u_x on each computed branch; reduction: "
              "1 - peak / the peak of the same design without its damper."]
    if shared:
        lines.append("The designs share their blade, disk and excitation: one damper-free response, drawn dashed.")
    else:
        lines.append("The designs differ beyond their dampers: no common damper-free response is drawn; each "
                     "reduction is against the design's own.")
    lines += [f"- {e.note}; no damper-free reference for {e.name}." for e in entries if e.note]
    lines += ["", "Files: " + ", ".join(f"`{f}`" for f in [*figures, "compare.csv", "compare.json"]) + ".", ""]
    (out / "summary.md").write_text("\n".join(lines))
    return summary


def bounded_without_damper(free, f_start_hz: float, f_end_hz: float) -> bool:
    """Whether the damper-free disk ``free`` has a bounded response over the range
    (:meth:`bladedamp.disk.TunedDisk.check_bounded`); where it has not (a blade mode without
    viscous damping inside the range), a note says the reference is left out."""
    try:
        free.check_bounded(f_start_hz, f_end_hz)
    except ValueError:
        warnings.warn(f"no damper-free reference: without the damper a blade mode with damping_ratio = 0 lies in "
                      f"{f_start_hz:g}-{f_end_hz:g} Hz, where its amplitude has no bound", UserWarning, stacklevel=2)
        return False
    return True
