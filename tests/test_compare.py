"""`bladedamp compare` and the saved results read back (`compare` / `show` with `--from`).

Two small designs (the init template on a 4-blade disk, the paper's one harmonic, 97-106 Hz)
differ only in their cylinder's mass (1 g and 3 g), so they share one damper-free response.
"""
import csv
import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import one_error_line

import bladedamp
from bladedamp.cli import main
from bladedamp.report import CALIBRATION_TOLERANCE, PAPER

SMALL = {"n_blades = 16": "n_blades = 4", "frequency_range_hz = [90.0, 105.0]": "frequency_range_hz = [97.0, 106.0]",
         'harmonics = "auto"': "harmonics = [1]"}


def _design(folder, name, mass_g):
    path = folder / f"{name}.toml"
    assert main(["init", str(path)]) == 0
    text = path.read_text()
    for old, new in {**SMALL, "\nmass_g = 1.0\n": f"\nmass_g = {mass_g}\n"}.items():
        assert old in text, old
        text = text.replace(old, new)
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """Two designs (light.toml 1 g, heavy.toml 3 g) and their `bladedamp frf` folders."""
    root = tmp_path_factory.mktemp("compare")
    designs = {"light": _design(root, "light", 1.0), "heavy": _design(root, "heavy", 3.0)}
    folders = {}
    for name, path in designs.items():
        folders[name] = root / f"frf_{name}"
        assert main(["frf", str(path), "--no-stop-check", "--no-peak-check", "--out", str(folders[name])]) == 0
    return root, designs, folders


def _curves(out):
    data = json.loads((out / "compare.json").read_text())
    return {(c["design"], c["response"]): (np.array(c["frequency_hz"]), np.array(c["tip_amplitude_x_mm"]))
            for c in data["curves"]}, data


def test_compare_two_designs_tabulates_each_designs_own_result(saved, tmp_path):
    root, designs, folders = saved
    out = tmp_path / "cmp"
    assert main(["compare", str(designs["light"]), str(designs["heavy"]), "--out", str(out)]) == 0
    curves, data = _curves(out)
    rows = {r["design"]: r for r in data["designs"]}
    assert list(rows) == ["light", "heavy"] and data["undamped_shared"]
    with open(out / "compare.csv", newline="") as fh:
        table = {r["design"]: r for r in csv.DictReader(fh)}
    for name in ("light", "heavy"):
        own = json.loads((folders[name] / "results.json").read_text())["responses"]["EO1"]
        # the same design solved by `bladedamp frf`: the same branch, so the same peak to rounding
        assert rows[name]["peak_amplitude_mm"] == pytest.approx(own["peak_amplitude_mm"], rel=1e-9)
        assert rows[name]["peak_frequency_hz"] == pytest.approx(own["peak_frequency_hz"], rel=1e-12)
        assert float(table[name]["peak_amplitude_mm"]) == pytest.approx(rows[name]["peak_amplitude_mm"], rel=1e-12)
        f, tip = curves[name, "EO1"]
        assert np.allclose(tip, own["tip_amplitude_x_mm"], rtol=1e-9) and np.allclose(f, own["frequency_hz"], rtol=1e-12)
        # the damper-free peak: the calibrated undamped 1F tip peak of the reference blade (a disk of
        # uncoupled identical blades without damper is the blade alone), to the calibration's 1 %
        free = rows[name]["undamped_peak_amplitude_mm"]
        assert free == pytest.approx(PAPER["no_damper_peak_tip_mm"], rel=CALIBRATION_TOLERANCE["undamped_peak"])
        assert rows[name]["reduction_pct"] == pytest.approx(100 * (1 - rows[name]["peak_amplitude_mm"] / free), rel=1e-12)
        assert not rows[name]["peak_at_range_end"]
    # a damper damps: both peaks below the damper-free one; the damper-free curve is drawn once,
    # and its resonance (no damper, about 95 Hz) lies below the damped ones (the damper stiffens)
    assert 0 < rows["light"]["reduction_pct"] < 100 and 0 < rows["heavy"]["reduction_pct"] < 100
    free_f, free_tip = curves["no damper", "EO1"]
    assert sum(1 for k in curves if k[0] == "no damper") == 1
    assert free_f[np.argmax(free_tip)] < min(rows[n]["peak_frequency_hz"] for n in rows)
    summary = (out / "summary.md").read_text()
    assert "| light | EO1 | cylinder 1 g |" in summary and "| heavy | EO1 | cylinder 3 g |" in summary
    assert (out / "compare.png").stat().st_size > 10_000


def test_compare_from_saved_results_draws_the_same_data_read_from_the_files(saved, tmp_path):
    root, designs, folders = saved
    computed, read = tmp_path / "computed", tmp_path / "read"
    assert main(["compare", str(designs["light"]), str(designs["heavy"]), "--out", str(computed)]) == 0
    assert main(["compare", "--from", str(folders["light"]), "--from", str(folders["heavy"]), "--out", str(read)]) == 0
    a, data_a = _curves(computed)
    b, data_b = _curves(read)
    assert a.keys() == b.keys()
    for key in a:
        assert np.array_equal(a[key][0], b[key][0]) and np.array_equal(a[key][1], b[key][1]), key
    assert [r["read_from"] for r in data_b["designs"]] == [[str(folders[n] / "frf_EO1.npz")] for n in ("light", "heavy")]
    # evidence that the folder's file is what is drawn, not a solve of its design: a saved result
    # with its amplitudes halved comes back halved
    edited = tmp_path / "edited"
    shutil.copytree(folders["heavy"], edited)
    r = bladedamp.load(edited / "frf_EO1.npz")
    dataclasses.replace(r, tip_amplitude=0.5 * r.tip_amplitude).save(edited / "frf_EO1.npz")
    (edited / "results.json").touch()          # saved after its design file, as a frf run leaves it
    out = tmp_path / "halved"
    assert main(["compare", str(folders["light"]), str(edited), "--out", str(out)]) == 0
    c, _ = _curves(out)
    assert np.array_equal(c["heavy", "EO1"][1], 0.5 * a["heavy", "EO1"][1])


def test_show_from_saved_results_uses_the_saved_response(saved, tmp_path, capsys):
    import importlib.util

    if importlib.util.find_spec("meshcat") is None or importlib.util.find_spec("trimesh") is None:
        pytest.skip("the 3D view needs the viz extra")
    root, designs, folders = saved
    edited = tmp_path / "edited"
    shutil.copytree(folders["light"], edited)
    r = bladedamp.load(edited / "frf_EO1.npz")
    dataclasses.replace(r, tip_amplitude=0.5 * r.tip_amplitude).save(edited / "frf_EO1.npz")
    (edited / "results.json").touch()
    out = tmp_path / "show"
    assert main(["show", str(designs["light"]), "--from", str(edited), "--out", str(out)]) == 0
    assert (out / "ods.html").stat().st_size > 10_000
    shown = bladedamp.load(out / "frf.npz")
    assert np.array_equal(shown.tip_amplitude, 0.5 * r.tip_amplitude)
    capsys.readouterr()
    assert main(["show", str(designs["heavy"]), "--from", str(folders["light"]), "--out", str(tmp_path / "x")]) == 2
    one_error_line(capsys, "--from", "light.toml", "not of", "heavy.toml")


@pytest.mark.parametrize("case, needles", [
    ("empty", ("no results of bladedamp frf", "results.json is missing")),
    ("no_npz", ("results.json lists EO1", "frf_EO1.npz is missing")),
    ("bad_json", ("not a readable results.json",)),
    ("one", ("at least two designs", "got 1")),
    ("missing", ("neither a design file", "nor a folder")),
])
def test_compare_bad_inputs_one_line_exit_2(saved, tmp_path, capsys, case, needles):
    root, designs, folders = saved
    bad = tmp_path / "bad"
    if case == "no_npz":
        shutil.copytree(folders["light"], bad)
        (bad / "frf_EO1.npz").unlink()
    elif case in ("empty", "bad_json"):
        bad.mkdir()
        if case == "bad_json":
            (bad / "results.json").write_text("{not json")
    args = {"one": [str(designs["light"])], "missing": [str(designs["light"]), str(tmp_path / "nothere")]}.get(
        case, [str(designs["light"]), str(bad)])
    out = tmp_path / "out"
    capsys.readouterr()
    assert main(["compare", *args, "--out", str(out)]) == 2
    one_error_line(capsys, *needles)
    assert not out.exists()                    # checked before anything is computed or written


def test_a_folder_whose_design_changed_since_has_no_damper_free_reference(saved, tmp_path):
    """The damper-free reference of a saved result is computed from its design file only if that
    file is not newer than the results: an edited design may no longer be the one solved."""
    import os

    root, designs, folders = saved
    moved = tmp_path / "heavy_results"
    shutil.copytree(folders["heavy"], moved)
    edited = tmp_path / "heavy.toml"
    edited.write_text(designs["heavy"].read_text())
    summary = json.loads((moved / "results.json").read_text())
    summary["design"] = str(edited)
    (moved / "results.json").write_text(json.dumps(summary))
    later = (moved / "results.json").stat().st_mtime + 60
    os.utime(edited, (later, later))
    out = tmp_path / "out"
    assert main(["compare", str(folders["light"]), str(moved), "--out", str(out)]) == 0
    rows = {r["design"]: r for r in json.loads((out / "compare.json").read_text())["designs"]}
    assert rows["light"]["reduction_pct"] is not None and rows["heavy"]["reduction_pct"] is None
    text = (out / "summary.md").read_text()
    assert "was changed after the results were saved" in text and "no damper-free reference for heavy" in text
    assert "no common damper-free response is drawn" in text


def test_compare_keeps_earlier_results_and_writes_results_compare_by_default(saved, tmp_path, capsys):
    from bladedamp.cli import build_parser, output_folder

    root, designs, folders = saved
    assert output_folder(build_parser().parse_args(["compare", "a.toml", "b.toml"])) == Path("results/compare")
    out = tmp_path / "earlier"
    out.mkdir()
    (out / "summary.md").write_text("the results of an earlier run")
    capsys.readouterr()
    assert main(["compare", str(designs["light"]), str(designs["heavy"]), "--out", str(out)]) == 2
    one_error_line(capsys, f"--out {out}", "not empty", "--overwrite")
    assert (out / "summary.md").read_text() == "the results of an earlier run"


def test_compare_figure_passes_the_slide_checks_and_the_summary_lists_the_files_written(saved, tmp_path, saved_figures):
    """compare.png obeys tests/figure_checks.py (its title names the designs compared); with
    --format pdf,svg summary.md names the PDF and SVG written, no PNG."""
    root, designs, folders = saved
    out = tmp_path / "cmp"
    assert main(["compare", str(designs["light"]), str(designs["heavy"]), "--format", "pdf,svg",
                 "--out", str(out)]) == 0
    saved_figures.check("light", "compare")
    saved_figures.check("heavy", "compare")
    assert (out / "compare.pdf").is_file() and (out / "compare.svg").is_file() and not (out / "compare.png").exists()
    summary = (out / "summary.md").read_text()
    assert "`compare.pdf`" in summary and "`compare.svg`" in summary and "compare.png" not in summary
