"""The reproduce report's wording and verdicts, and the figures' legends and ticks.

The report is written from summary.json alone (``bladedamp.report.reproduce_report``), so it is
tested here on ``tests/data/reproduce_summary.json`` (the summary.json of a full ``bladedamp
reproduce`` on 2026-12-01, 2230 s under load; the run the README quotes), and on copies of it
with edge values put in: the verdicts must follow the tolerances the report states, whatever
the numbers.
"""
import copy
import json
import pathlib
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from bladedamp import report  # noqa: E402
from bladedamp.plotting import legend_covers, place_legend  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
RECORDED = json.loads((ROOT / "tests" / "data" / "reproduce_summary.json").read_text())
#: what a user should never have to decode: nan, a signed zero, exponent notation, development issue numbers
UNREADABLE = re.compile(r"\bnan\b|\binf\b|(?<![\d.])-0\.0+\b(?!\.)|\d[eE][+-]?\d|\bissue \d", re.IGNORECASE)
VERDICTS = {"calibrated", "calibration missed", "reproduced", "differs", "agrees"}


@pytest.fixture
def summary():
    return copy.deepcopy(RECORDED)


def unreadable(text):
    return [line for line in text.splitlines() if UNREADABLE.search(line)]


def rows_by(text, column, value):
    return [r for r in report.verdict_rows(text) if r.get(column, "").startswith(value)]


def test_recorded_report_is_readable_and_has_one_heading_per_section(summary):
    text = report.reproduce_report(summary)
    assert not unreadable(text), unreadable(text)
    headings = [line for line in text.splitlines() if line.startswith("#")]
    assert len(headings) == len(set(headings))
    assert sum(h.startswith("## Mistun") for h in headings) == 1, headings
    assert "## Design studies" in text and "## Stability" in text
    # no heading directly followed by another heading (two headings in a row)
    lines = [line for line in text.splitlines() if line.strip()]
    assert not any(a.startswith("#") and b.startswith("#") for a, b in zip(lines, lines[1:]))
    # markdown tables: no cell may hold a bare '|' (abs(w*) is written as abs)
    for line in text.splitlines():
        if line.startswith("|") and not set(line) <= set("|-: "):
            header_len = None
            for block in text.split("\n\n"):
                if line in block.splitlines():
                    header_len = block.splitlines()[0].count("|")
            assert line.count("|") == header_len, line


def test_report_states_every_study_time(summary):
    """Each study's wall-clock time is in the report, with its share of the run; a study whose
    time the run did not record is left out rather than shown as zero."""
    text = report.reproduce_report(summary)
    t = summary["timings_s"]
    rows = {line.split(" | ")[0].strip("| "): line for line in text.splitlines() if line.startswith("| ")}
    for key, name in report.STUDY_TIMES:
        assert f"| {name} | {t[key]:.1f} | {100 * t[key] / t['total_s']:.0f} % |" == rows[name], (key, rows.get(name))
    assert set(t) - {"total_s"} == {key for key, _ in report.STUDY_TIMES}     # no study unnamed
    assert f"Run time: {t['total_s']:.1f} s" in text
    del summary["timings_s"]["mistuning_s"]
    assert "| mistuning (Fig. 13-17) |" not in report.paper_section(summary, summary["table1"])


def test_every_verdict_names_its_tolerance(summary):
    text = report.reproduce_report(summary)
    rows = report.verdict_rows(text)
    assert len(rows) >= 25, len(rows)
    for r in rows:
        assert r["verdict"].split(":")[0] in VERDICTS, r
        assert r.get("tolerance", "").strip() not in ("", "-"), r
    assert "How the verdicts are decided" in text


def test_edge_values_are_written_in_words(summary):
    s = summary
    s["optimum"]["cylinder"]["0"].update(mass_g=None, reduction_pct=-1e-9)
    s["optimum"]["wedge"]["3"]["reduction_pct"] = float("nan")
    s["table1"][3]["reduction_pct"] = -1e-12
    s["harmonic_accuracy"]["wedge"]["converged"]["harmonic_error_pct"] = None
    s["design_map"][0]["optimum"]["reduction_pct"] = -0.0
    s["wedge_liftoff_onset"]["max_ratio"][0][0] = float("nan")
    text = report.reproduce_report(s)
    assert not unreadable(text), unreadable(text)
    assert "none (no mass damps)" in text


def test_a_harmonic_error_that_was_not_estimated_says_why(summary):
    converged = summary["harmonic_accuracy"]["cylinder"]["converged"]
    converged["harmonic_error_pct"] = None
    h = converged["harmonics"]
    text = report.accuracy_section(summary)
    row = next(line for line in text.splitlines() if line.startswith("| cylinder") and f"{h[0]}-{h[-1]}" in line)
    assert "not estimated" in row and row.rstrip(" |").endswith("unknown")
    assert f"harmonics {h[0]}-{h[-1] + 2}" in text and "did not converge" in text and "unknown" in text
    assert "not verified" not in text


@pytest.mark.parametrize("reduction, verdict", [(1.5 - 0.49, "reproduced"), (1.5 + 0.49, "reproduced"),
                                                (1.5 - 0.51, "differs: reduction"), (0.6, "differs: reduction")])
def test_table1_verdict_follows_its_stated_tolerance(summary, reduction, verdict):
    """2F: the paper's 1.5 % with the stated +- 0.5 % points (30 % of 1.5 is less than the floor)."""
    summary["table1"][1]["reduction_pct"] = reduction
    row = rows_by(report.reproduce_report(summary), "mode", "2F")[0]
    assert row["verdict"] == verdict
    assert "reduction +- 0.5 % points" in row["tolerance"]


def test_table1_frequency_shift_tolerance(summary):
    """1T: the paper's shift 16.5 Hz +- 30 % (4.95 Hz)."""
    for f, verdict in ((783 + 16.5 - 4.9, "reproduced"), (783 + 16.5 - 5.0, "differs")):
        summary["table1"][2].update(f_res_damped_hz=f, reduction_pct=5.0)
        row = rows_by(report.reproduce_report(summary), "mode", "1T")[0]
        assert row["verdict"].startswith(verdict), (f, row)


def test_calibration_and_comparison_verdicts_follow_their_tolerances(summary):
    summary["no_damper_peak_tip_mm"] = 1.7 * 1.011
    text = report.reproduce_report(summary)
    assert rows_by(text, "quantity", "undamped")[0]["verdict"] == "calibration missed"
    summary["no_damper_peak_tip_mm"] = 1.7 * 1.009
    summary["optimum"]["wedge"]["1"]["peak_tip_mm"] = 0.995 * summary["optimum"]["cylinder"]["1"]["peak_tip_mm"]
    text = report.reproduce_report(summary)
    assert rows_by(text, "quantity", "undamped")[0]["verdict"] == "calibrated"
    assert rows_by(text, "quantity", "wedge lower optimal amplitude")[0]["verdict"] == "differs"   # a 0.5 % tie


def test_mistuning_verdicts_follow_their_tolerances(summary):
    m = summary["mistuning"]["random_1g"]
    tuned = m["tuned_peak_tip_mm"]
    peaks = np.array(m["peak_tip_mm"])
    for ratio, verdict in ((1.019, "reproduced"), (1.021, "differs"), (0.86, "reproduced"), (0.84, "differs")):
        m["peak_tip_mm"] = list(peaks * ratio * tuned / peaks.max())
        row = rows_by(report.reproduce_report(summary), "case", "b, 1 g: largest")[0]
        assert row["verdict"] == verdict, (ratio, row)


def test_stability_section_says_where_and_what_it_costs(summary):
    text = report.stability_section(summary)
    assert "Hill's method" in text and "determinant sign" in text and "of the run" in text
    assert "Neimark-Sacker" in text
    st = summary["stability"]
    name = next(iter(st))
    st[name]["stable"] = [True] * len(st[name]["stable"])
    st[name]["stable"][3:6] = [False] * 3
    text = report.stability_section(summary)
    row = next(line for line in text.splitlines() if line.startswith(f"| {name} |"))
    f = st[name]["frequency_hz"]
    assert f"3: {min(f[3:6]):.3f}-{max(f[3:6]):.3f} Hz" in row, row
    # without the stability keys (an older summary.json) the section is left out, nothing breaks
    del summary["stability"], summary["backbone"]
    assert report.stability_section(summary) == ""
    assert not unreadable(report.reproduce_report(summary))


def test_readme_mirrors_the_report_verdicts():
    """The README's summary is the one written from the recorded run: every section's verdicts
    and every row that differs (regenerate with report.readme_summary when the run changes)."""
    readme = (ROOT / "README.md").read_text()
    assert report.README_BEGIN in readme and report.README_END in readme
    block = readme[readme.index(report.README_BEGIN):readme.index(report.README_END) + len(report.README_END)]
    assert block == report.readme_summary(RECORDED)
    text = report.reproduce_report(RECORDED)
    n_differ = sum(r["verdict"].startswith("differs") for r in report.verdict_rows(text))
    assert n_differ > 0 and block.count("(differs") == n_differ


# ---------------------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------------------
def test_place_legend_moves_clear_of_a_peak_the_default_legend_hides():
    fig, ax = plt.subplots(figsize=(5, 3.5))
    f = np.linspace(90, 100, 400)
    ax.plot(f, 1 / (1 + ((f - 91) / 0.2) ** 2), label="a sharp peak at the left")
    ax.plot(f, 0.9 / (1 + ((f - 99) / 0.2) ** 2), label="and one at the right")
    ax.plot(f, 0.95 / (1 + ((f - 95) / 0.2) ** 2), label="and one in the middle")
    legend = ax.legend(loc="upper left")
    fig.canvas.draw()
    assert legend_covers(ax, legend) > 0            # the checker sees the hidden peak
    legend = place_legend(ax, loc="upper left")
    fig.canvas.draw()
    assert legend_covers(ax, legend) == 0
    assert ax.get_ylim()[1] > 1.05                  # room was made above the peaks
    plt.close(fig)


def test_design_map_ticks_are_the_masses_and_the_star_is_not_clipped():
    from bladedamp.studies.design import DesignMap

    masses = np.array([0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0]) * 1e-3
    gammas = np.array([15.0, 35.0, 55.0, 85.0])
    peaks = 1e-3 * (0.5 + 0.1 * np.log(masses / 5e-4)[None, :] ** 2 + 0.002 * (85 - gammas)[:, None])
    fig, ax = plt.subplots()
    DesignMap("cylinder", None, masses, gammas, peaks, 1.7e-3).plot(ax=ax)
    fig.canvas.draw()
    assert [t.get_text() for t in ax.get_xticklabels()] == ["0.3", "0.5", "0.7", "1", "1.5", "2", "3"]
    assert not any(t.get_text() for t in ax.get_xticklabels(minor=True))
    labels = [t for t in ax.get_xticklabels() if t.get_text()]
    boxes = [t.get_window_extent() for t in labels]
    assert all(a.x1 < b.x0 for a, b in zip(boxes, boxes[1:]))      # no two labels overlap
    star = [line for line in ax.get_lines() if line.get_marker() == "*"]
    assert len(star) == 1 and not star[0].get_clip_on()
    assert star[0].get_ydata()[0] == 85.0 and "best (star): 0.5 g" in ax.get_title()
    plt.close(fig)


def test_mass_sweeps_share_one_no_damper_legend_entry_and_hide_nothing():
    from bladedamp.studies.mass import MassSweep

    m = np.logspace(-5, 0, 12)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for kind, scale in (("cylinder", 1.0), ("wedge", 0.6)):
        MassSweep(m, 1.7e-3 * (1 - scale * np.exp(-np.log10(m / 1e-3) ** 2)), np.full(12, 95.0), kind, 1.7e-3).plot(ax=ax)
    fig.canvas.draw()
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts.count("no damper") == 1 and {"cylinder", "wedge"} <= set(texts)
    assert legend_covers(ax) == 0
    plt.close(fig)


def test_liftoff_legend_hides_no_point():
    from bladedamp.studies.design import LiftoffMap

    xi, eta = np.meshgrid([-0.4, -0.2, 0.0, 0.2, 0.4], [-0.4, -0.2, 0.0, 0.2, 0.4])
    xi, eta = xi.ravel(), eta.ravel()
    r = np.vstack([0.3 + 2.5 * np.abs(xi), 0.3 + 2.5 * np.abs(xi)])
    P = xi.size
    lift = LiftoffMap(xi, eta, r, r, np.zeros((2, P)), np.ones((2, P)), r, 95.5, 3e-4, 64)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    lift.plot(ax=ax)
    fig.tight_layout()
    fig.canvas.draw()
    assert ax.get_legend() is not None and legend_covers(ax) == 0
    plt.close(fig)
