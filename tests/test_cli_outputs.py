"""Nothing lost: a command never replaces results a user already has. A non-empty --out is
refused (one line naming the folder and --overwrite, exit code 2, before computing) unless
--overwrite is given; without --out a command writes into results/<design file name>/<command>;
init keeps an existing design file; a design file that sets no key says so before it runs."""
import pathlib
import shlex
import subprocess
import sys
import time

import pytest

import bladedamp.reproduce
from bladedamp.cli import build_parser, main, output_folder

ROOT = pathlib.Path(__file__).resolve().parent.parent
# a design that solves in seconds: a narrow range around the 1F resonance, the paper's one harmonic
FAST = "[analysis]\nfrequency_range_hz = [92.0, 99.0]\nharmonics = [1]\nmass_range_g = [0.5, 2.0]\n"


def one_error_line(err, *needles):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


@pytest.mark.parametrize("args, folder", [
    (["frf", "designs/wing.toml"], "results/wing/frf"),
    (["frf", "other/wing_v2.toml"], "results/wing_v2/frf"),
    (["optimize", "wing.toml"], "results/wing/optimize"),
    (["eo-sweep", "wing.toml"], "results/wing/eo-sweep"),
    (["show", "wing.toml"], "results/wing/show"),
    (["montecarlo", "wing.toml"], "results/wing/montecarlo"),
    (["montecarlo"], "results/montecarlo"),                   # the reference disk: a fixed name
    (["reproduce"], "results"),                               # the reference configuration: a fixed name
    (["frf", "wing.toml", "--out", "mine"], "mine"),
])
def test_the_default_output_folder_is_named_after_the_design_file(args, folder):
    assert output_folder(build_parser().parse_args(args)) == pathlib.Path(folder)


@pytest.fixture
def design(tmp_path):
    path = tmp_path / "wing.toml"
    path.write_text(FAST)
    return path


@pytest.mark.parametrize("args", [["frf", "{design}"], ["optimize", "{design}"], ["eo-sweep", "{design}"],
                                  ["montecarlo", "{design}", "--scheduler", "serial"],
                                  ["montecarlo", "--scheduler", "serial"], ["show", "{design}"], ["reproduce"]],
                         ids=lambda a: " ".join(a).replace("{design}", "design"))
def test_a_non_empty_out_is_refused_before_computing(tmp_path, capsys, design, args):
    out = tmp_path / "earlier"
    out.mkdir()
    (out / "summary.md").write_text("the results of an earlier run")
    t0 = time.perf_counter()
    assert main([a.format(design=design) for a in args] + ["--out", str(out)]) == 2
    assert time.perf_counter() - t0 < 10              # nothing was computed
    one_error_line(capsys.readouterr().err, f"--out {out}", "not empty", "summary.md", "--overwrite")
    assert [p.name for p in out.iterdir()] == ["summary.md"]
    assert (out / "summary.md").read_text() == "the results of an earlier run"


def test_frf_writes_its_default_folder_refuses_it_the_second_time_and_replaces_it_with_overwrite(
        tmp_path, capsys, design, monkeypatch):
    monkeypatch.chdir(tmp_path)
    fast = ["frf", design.name, "--no-stop-check", "--no-peak-check"]
    assert main(fast) == 0
    folder = pathlib.Path("results/wing/frf")
    first = (folder / "summary.md").read_bytes()
    assert {"frf.png", "frf_EO1.npz", "results.json", "summary.md"} <= {p.name for p in folder.iterdir()}
    capsys.readouterr()
    assert main(fast) == 2                                   # the same design again: its results are kept
    one_error_line(capsys.readouterr().err, f"--out {folder}", "--overwrite")
    assert (folder / "summary.md").read_bytes() == first
    (folder / "notes.txt").write_text("mine")
    (folder / "summary.md").write_text("stale")
    assert main(fast + ["--overwrite"]) == 0
    assert (folder / "summary.md").read_bytes() == first      # replaced by the same run's summary
    assert (folder / "notes.txt").read_text() == "mine"      # a file the run does not write stays


def test_init_keeps_an_existing_design_file_unless_overwrite(tmp_path, capsys):
    from bladedamp.design import template

    path = tmp_path / "design.toml"
    path.write_text("[damper]\nmass_g = 2.0\n")
    assert main(["init", str(path)]) == 2
    one_error_line(capsys.readouterr().err, str(path), "exists already", "--overwrite")
    assert path.read_text() == "[damper]\nmass_g = 2.0\n"
    assert main(["init", str(path), "--overwrite"]) == 0 and path.read_text() == template()
    path.write_text("")
    assert main(["init", str(path), "--force"]) == 0 and path.read_text() == template()


@pytest.mark.parametrize("content", ["", "# my design, to do\n", "[damper]\n# mass_g = 2.0\n"],
                         ids=["empty", "comments", "a table header only"])
@pytest.mark.parametrize("command", ["frf", "montecarlo"])
def test_a_design_that_sets_no_key_says_so_in_one_line_before_it_runs(tmp_path, capsys, content, command):
    """The notice comes before anything else the command does (here: the refusal of a non-empty
    --out, so that nothing is computed)."""
    path = tmp_path / "empty.toml"
    path.write_text(content)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep").write_text("")
    assert main([command, str(path), "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 2, lines
    assert lines[0] == (f"bladedamp {command}: note: {path} sets no key: running the reference design "
                        "(bladedamp init writes it with every key)")
    assert "--overwrite" in lines[1]


def test_a_design_that_sets_a_key_gives_no_notice(tmp_path, capsys, design):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep").write_text("")
    assert main(["frf", str(design), "--out", str(out)]) == 2
    assert "note" not in capsys.readouterr().err


def test_the_readme_quick_start_runs_twice_in_the_same_clone(tmp_path, monkeypatch):
    """The README's first command (CI runs it once, in a fresh clone) can be run again in the same
    folder: it names --overwrite, so the second run replaces the first's files instead of stopping.
    The pipeline itself (minutes, :func:`bladedamp.reproduce.reproduce`) is replaced here by one
    file; the command's output-folder step stays."""
    quick = subprocess.run([sys.executable, str(ROOT / ".ci" / "quickstart.py")], capture_output=True, text=True,
                           check=True).stdout.splitlines()[0]
    command = shlex.split(quick.split("&&")[-1])
    assert command[:2] == ["bladedamp", "reproduce"], quick

    def reproduce(out, processes=None, progress=None):
        (out / "summary.json").write_text("{}")
        return {"timings_s": {"total_s": 0.0}}

    monkeypatch.setattr(bladedamp.reproduce, "reproduce", reproduce)
    monkeypatch.chdir(tmp_path)
    assert main(command[1:]) == 0 and main(command[1:]) == 0
    assert main([a for a in command[1:] if a != "--overwrite"]) == 2     # without it, the rule holds
