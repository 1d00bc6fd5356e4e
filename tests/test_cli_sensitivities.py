"""``bladedamp sensitivities`` and ``bladedamp fit`` on a design file: their outputs, their
numbers against the library's, and their one-line errors (exit code 2)."""
import json

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.cli import main
from bladedamp.design import load_design
from bladedamp.fit import model_points
from test_cli_outputs import one_error_line      # one line, no traceback, naming what is wrong

FAST = "[analysis]\nfrequency_range_hz = [92.0, 99.0]\nharmonics = [1]\n"


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")
def test_sensitivities_writes_the_peak_derivatives_of_the_library(tmp_path, capsys):
    design = tmp_path / "wing.toml"
    design.write_text(FAST)
    out = tmp_path / "sens"
    assert main(["sensitivities", str(design), "--parameters", "mass_g", "friction_coefficient", "--out", str(out)]) == 0
    result = json.loads((out / "results.json").read_text())
    assert [r["parameter"] for r in result["sensitivities"]] == ["damper.mass_g", "damper.friction_coefficient"]
    d = load_design(design)
    peak = d.disk.frequency_response(92.0, 99.0, **d.analysis.options()).peak_sensitivities(
        ["damper.mass_g", "damper.friction_coefficient"])
    assert result["sensitivities"][0]["d_peak_amplitude_mm_per_unit"] == pytest.approx(1e3 * peak.d_peak_amplitude[0],
                                                                                      rel=1e-9)
    assert {"sensitivities.png", "summary.md", "peak_sensitivities.npz"} <= {p.name for p in out.iterdir()}
    assert bd.load(out / "peak_sensitivities.npz").parameters == peak.parameters


MISTUNED = ("[analysis]\nfrequency_range_hz = [97.0, 106.0]\nharmonics = [1]\n[disk]\nn_blades = 4\n"
            "[mistuning]\nkappa = [1.0, 1.02, 0.99, 1.01]\n")


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")
def test_sensitivities_of_the_mistuned_assembly_are_the_library_s(tmp_path, capsys):
    """``--mistuned``: the peak derivatives of the design's mistuned full assembly (4 blades), the
    keys with a blade's mistuning factor, as the Python API gives them (the same solves: to 1e-9,
    the JSON's rounding being 1e-16); a design without a [mistuning] table: frf --mistuned's error."""
    design = tmp_path / "ring.toml"
    design.write_text(MISTUNED)
    out = tmp_path / "sens"
    keys = ["damper.mass_g", "damper.friction_coefficient", "mistuning.kappa[1]", "mistuning.kappa[3]"]
    assert main(["sensitivities", str(design), "--mistuned", "--parameters", "mass_g", "friction_coefficient",
                 "kappa[1]", "kappa[3]", "--out", str(out)]) == 0
    result = json.loads((out / "results.json").read_text())
    d = load_design(design)
    peak = d.mistuned_disk().frequency_response(97.0, 106.0, **d.analysis.options()).peak_sensitivities(keys)
    assert result["model"] == "mistuned full assembly" and result["mistuning_kappa"] == [1.0, 1.02, 0.99, 1.01]
    assert [r["parameter"] for r in result["sensitivities"]] == keys
    assert result["blade"] == peak.blade and result["peak_amplitude_mm"] == pytest.approx(1e3 * peak.peak_amplitude,
                                                                                        rel=1e-9)
    for row, da, df in zip(result["sensitivities"], peak.d_peak_amplitude, peak.d_peak_frequency_hz):
        assert row["d_peak_amplitude_mm_per_unit"] == pytest.approx(1e3 * da, rel=1e-9), row["parameter"]
        assert row["d_peak_frequency_hz_per_unit"] == pytest.approx(df, rel=1e-9), row["parameter"]
    assert "Mistuned full assembly" in (out / "summary.md").read_text()
    capsys.readouterr()
    # without a [mistuning] table, and a kappa key without --mistuned (the tuned sector has none)
    tuned = tmp_path / "tuned.toml"
    tuned.write_text(MISTUNED.split("[mistuning]")[0])
    assert main(["sensitivities", str(tuned), "--mistuned", "--parameters", "mass_g", "--out", str(tmp_path / "o")]) == 2
    one_error_line(capsys.readouterr().err, "--mistuned needs a [mistuning] table")
    assert main(["sensitivities", str(design), "--parameters", "kappa[1]", "--out", str(tmp_path / "t")]) == 2
    one_error_line(capsys.readouterr().err, "--parameters", "MistunedDisk")


def test_fit_recovers_the_friction_coefficient_from_csv_files(tmp_path, capsys):
    truth = bd.reference_disk("cylinder", 1e-3)
    f = np.linspace(92.0, 99.0, 20)
    files = []
    for force in (0.05, 0.2):
        u, _ = model_points(truth.with_parameters({"disk.excitation_n_nm[0]": force}), f, ("damper.mass_g",), (1,),
                            None, 0.05)
        path = tmp_path / f"rig_{force}.csv"
        path.write_text("frequency [Hz], amplitude [mm]\n" + "".join(f"{x:.6f}, {1e3 * abs(y):.10g}\n"
                                                                     for x, y in zip(f, u)))
        files.append(str(path))
    design = tmp_path / "start.toml"
    design.write_text(FAST + "[damper]\nfriction_coefficient = 0.2\n")
    out = tmp_path / "fit"
    assert main(["fit", str(design), *files, "--parameters", "friction_coefficient", "--excitation-n", "0.05", "0.2",
                 "--out", str(out)]) == 0
    result = json.loads((out / "results.json").read_text())
    assert result["parameters"][0]["estimate"] == pytest.approx(0.3, rel=1e-4)      # noise-free data
    assert {"fit.png", "summary.md", "fit.npz"} <= {p.name for p in out.iterdir()}


@pytest.mark.parametrize("argv, needles", [
    (["sensitivities", "{d}", "--parameters", "n_blades"], ["--parameters", "n_blades"]),
    (["sensitivities", "{d}", "--parameters", "rotor_speed_rpm"], ["rotor_speed_rpm", "fixed rotor speed"]),
    (["fit", "{d}", "{m}", "--excitation-n", "0.1", "0.2"], ["--excitation-n", "one force per measured file"]),
    (["fit", "{d}", "{d}"], ["{d}"]),
    (["optimize", "{d}", "--mistuning-std", "0.02"], ["--mistuning-std", "--parameters"]),
    (["optimize", "{d}", "--parameters", "mass_g", "--mistuning-std", "0.3"], ["--mistuning-std 0.3", "(0, 0.2)"]),
    (["optimize", "{d}", "--parameters", "mass_g", "--mistuning-std", "0.02", "--statistic", "median"],
     ["--statistic median", "quantile in (0, 1)"]),
    (["optimize", "{d}", "--parameters", "mass_g", "--mistuning-std", "0.02", "--disks", "1"], ["--disks 1", "at least 2"]),
])
def test_bad_options_and_files_end_in_one_line(tmp_path, capsys, argv, needles):
    design = tmp_path / "wing.toml"
    design.write_text(FAST)
    measured = tmp_path / "m.csv"
    measured.write_text("frequency [Hz], amplitude [mm]\n95.0, 0.3\n")
    argv = [a.format(d=design, m=measured) for a in argv] + ["--out", str(tmp_path / "o")]
    assert main(argv) == 2
    one_error_line(capsys.readouterr().err, *[n.format(d=design) for n in needles])


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")
def test_optimize_robust_to_mistuning_writes_the_librarys_optimum(tmp_path, capsys):
    """``optimize --parameters mass_g --mistuning-std`` is :func:`bladedamp.studies.robust.robust_design`
    with the design's bounds: the same optimum (bit for bit: the same copies and searches), named as
    the statistic over mistuned disks in its outputs."""
    from bladedamp.studies.robust import robust_design

    design = tmp_path / "wing.toml"
    design.write_text(FAST + "mass_range_g = [0.4, 1.2]\n")
    out = tmp_path / "robust"
    assert main(["optimize", str(design), "--parameters", "mass_g", "--mistuning-std", "0.02", "--disks", "2",
                 "--starts", "1", "--processes", "1", "--out", str(out)]) == 0
    result = json.loads((out / "results.json").read_text())
    d = load_design(design)
    optimum = robust_design(d.disk, ["damper.mass_g"], [[0.4, 1.2]], std=0.02, n_disks=2, seed=0, n_starts=1,
                            harmonics=(1,))
    assert result["parameters"][0]["optimum"] == pytest.approx(optimum["damper.mass_g"], rel=1e-12)
    assert "mistuned disks" in result["objective"]
    assert "mistuned disks" in (out / "summary.md").read_text()
