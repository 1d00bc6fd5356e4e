"""Every file the package reads (saved results, modal blade files in npz and CSV, a solid FE
blade's npz, design files) gives, when it cannot be read as what it should be, one ValueError
(bladedamp.io.FileReadError) whose one-line message names the file and says what is wrong: no raw
UnicodeDecodeError, BadZipFile, EOFError, KeyError or JSONDecodeError, no "pickled data". On the
command line that is one line on stderr and exit code 2.

Each file is first written by the product's own writer and read back intact, then broken in
each way a file breaks: cut in half, a byte flipped, emptied, replaced by text, by random bytes,
by a file of another kind, deleted, replaced by a folder; text files also get a byte that is not
UTF-8, npz results broken metadata and a removed array.
"""
import json
import subprocess
import sys
import zipfile

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.cli import main
from bladedamp.design import write_template
from bladedamp.io import META_KEY, FileReadError, MissingFileError
from bladedamp.studies import mass as sm

RAW = (UnicodeDecodeError, json.JSONDecodeError, KeyError, EOFError, zipfile.BadZipFile)


# ---------------------------------------------------------------------------------------
# valid files, written by the package's own writers, and their readers
# ---------------------------------------------------------------------------------------
def write_result(path):
    sweep = sm.MassSweep(np.array([1e-4, 1e-3, 1e-2]), np.array([1.2e-3, 5e-4, np.nan]),
                         np.array([95.0, 95.3, np.nan]), "cylinder", 1.7e-3)
    return sweep.save(path / "sweep")


def write_blade_npz(path):
    return bd.reference_blade().save(path / "blade.npz")


def write_blade_csv(path):
    return bd.reference_blade().save(path / "blade.csv")


def write_design(path):
    return write_template(path / "design.toml")


WRITERS = {"result": (write_result, bd.load), "blade.npz": (write_blade_npz, bd.ModalBlade.from_file),
           "blade.csv": (write_blade_csv, bd.ModalBlade.from_file), "design": (write_design, bd.load_design)}
TEXT_KINDS = ("blade.csv", "design")


def npz_arrays(path):
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def rewrite_npz(path, arrays):
    with open(path, "wb") as fh:          # the same name (np.savez would append .npz to another)
        np.savez(fh, **arrays)


def cut_half(path, kind):
    """Cut at about half; a text file inside the value of its next line that has one (a text file
    cut at the end of a line or in a comment is a valid shorter file: a design then sets fewer
    keys, test_a_design_cut_inside_a_comment_or_empty_sets_no_key)."""
    data = path.read_bytes()
    at = len(data) // 2
    if kind in TEXT_KINDS:
        sep = b" = " if kind == "design" else b","
        start = data.index(b"\n", at) + 1
        for line in data[start:].split(b"\n"):
            if not line.startswith(b"#") and sep in line:
                at = start + line.index(sep) + 2
                break
            start += len(line) + 1
    path.write_bytes(data[:at])


def flip_middle_byte(path, kind):
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))


def empty(path, kind):
    path.write_bytes(b"")


def text(path, kind):
    path.write_text("these are notes, not the file that was meant\n")


def random_bytes(path, kind):
    path.write_bytes(np.random.default_rng(7).bytes(300))


def not_utf8(path, kind):              # a Latin-1 'e acute' in the first comment
    data = path.read_bytes()
    at = data.index(b"#") + 1
    path.write_bytes(data[:at] + b" caf\xe9" + data[at:])


def other_kind(path, kind):
    """A valid file of another kind: a single .npy array where a saved result is expected (a
    blade file is one: bd.load reads it), a saved result where a blade is expected, a design
    where a CSV blade is expected and the reverse."""
    if kind == "result":
        with open(path, "wb") as fh:
            np.save(fh, np.arange(4.0))
        return
    other = {"blade.npz": write_result, "blade.csv": write_design, "design": write_blade_csv}[kind]
    sub = path.parent / "other"
    sub.mkdir()
    path.write_bytes(other(sub).read_bytes())


def deleted(path, kind):
    path.unlink()


def folder(path, kind):
    path.unlink()
    path.mkdir()


def broken_metadata(path, kind):
    arrays = npz_arrays(path)
    arrays[META_KEY] = np.array(str(arrays[META_KEY][()])[:-7])       # JSON cut before its end
    rewrite_npz(path, arrays)


def removed_array(path, kind):
    arrays = npz_arrays(path)
    del arrays["mass" if kind == "result" else "mode_shapes"]
    rewrite_npz(path, arrays)


def plain_npz(path, kind):
    rewrite_npz(path, {"x": np.zeros(3)})


BREAKS = {"cut in half": cut_half, "a byte flipped": flip_middle_byte, "empty": empty, "text": text,
          "random bytes": random_bytes, "another kind": other_kind, "deleted": deleted, "a folder": folder}
TEXT_BREAKS = {"not UTF-8": not_utf8}
NPZ_BREAKS = {"removed array": removed_array, "plain npz": plain_npz}
CASES = [(kind, name) for kind in WRITERS for name in BREAKS
         if (kind, name) != ("design", "empty")]      # an empty design is the reference design (below)
CASES += [(kind, name) for kind in TEXT_KINDS for name in TEXT_BREAKS]
CASES += [(kind, name) for kind in ("result", "blade.npz") for name in NPZ_BREAKS]
CASES += [("result", "broken metadata")]
ALL_BREAKS = {**BREAKS, **TEXT_BREAKS, **NPZ_BREAKS, "broken metadata": broken_metadata}


def assert_one_clean_error(info, path):
    """One FileReadError (a ValueError), one line, naming the file; no raw exception type."""
    err = info.value
    message = str(err)
    assert isinstance(err, FileReadError) and isinstance(err, ValueError), (type(err), message)
    assert not isinstance(err, RAW), type(err)
    assert str(path) in message, message
    assert "\n" not in message and "pickled" not in message, message
    return message


def test_every_kind_of_file_reads_back_intact(tmp_path):
    """The baseline of the cases below: each writer's file reads back."""
    for kind, (write, read) in WRITERS.items():
        folder_ = tmp_path / kind
        folder_.mkdir()
        assert read(write(folder_)) is not None, kind


@pytest.mark.parametrize("kind, how", CASES, ids=[f"{k}-{h}" for k, h in CASES])
def test_a_broken_file_raises_one_value_error_naming_it(tmp_path, kind, how):
    write, read = WRITERS[kind]
    path = write(tmp_path)
    ALL_BREAKS[how](path, kind)
    with pytest.raises(ValueError) as info:
        read(path)
    message = assert_one_clean_error(info, path)
    expected = {"deleted": "no such", "a folder": "is a folder", "empty": "empty (0 bytes)",
                "not UTF-8": "not UTF-8 text (byte 0xe9", "broken metadata": "broken JSON",
                "removed array": "no entry 'mass'" if kind == "result" else "missing: ['mode_shapes']"}
    if how in expected:
        assert expected[how] in message, message
    if how == "deleted":
        # also a FileNotFoundError, as before (a missing design file is a DesignError with the init hint)
        assert kind == "design" or (isinstance(info.value, MissingFileError)
                                    and isinstance(info.value, FileNotFoundError)), type(info.value)
    if kind != "design" and how in ("cut in half", "a byte flipped") and not path.suffix == ".csv":
        assert "truncated or corrupted" in message, message


def test_flipped_bytes_and_cuts_all_over_an_npz_give_the_result_or_one_clean_error(tmp_path):
    """Over the whole of the two npz formats (a saved result: stored members; a blade file:
    compressed ones): every 5th byte flipped (about 900 files), and the file cut at every 17th
    length, either still reads (a zip header field no reader checks, such as a time stamp) or
    raises one FileReadError naming the file; never a raw exception."""
    for kind in ("result", "blade.npz"):
        write, read = WRITERS[kind]
        good = write(tmp_path).read_bytes()
        path = tmp_path / f"broken_{kind.replace('.npz', '')}.npz"
        variants = []
        for i in range(0, len(good), 5):
            flipped = bytearray(good)
            flipped[i] ^= 0xFF
            variants.append(bytes(flipped))
        variants += [good[:n] for n in range(0, len(good), 17)]
        failed = 0
        for data in variants:
            path.write_bytes(data)
            try:
                read(path)
            except FileReadError as err:
                assert str(path) in str(err) and "\n" not in str(err), str(err)
                failed += 1
        # most of the file is checked (CRC-32 of every member, the zip directory, the npy headers)
        assert failed > 0.8 * len(variants), (kind, failed, len(variants))


def test_a_solid_blade_file_broken_raises_one_value_error_naming_it(tmp_path, coarse_modes):
    """A solid FE blade's npz (SolidModalBlade.save): cut, a byte flipped, a removed entry."""
    from bladedamp import solid

    blade = solid.solid_blade(modes=coarse_modes)
    good = blade.save(tmp_path / "solid.npz").read_bytes()
    assert isinstance(bd.ModalBlade.from_file(tmp_path / "solid.npz"), solid.SolidModalBlade)
    path = tmp_path / "broken.npz"
    arrays = blade.npz_arrays()
    del arrays["solid/fit_residuals"]
    for data in (good[:len(good) // 2], good[:len(good) // 2] + bytes([good[len(good) // 2] ^ 0xFF])
                 + good[len(good) // 2 + 1:], None):
        if data is None:
            rewrite_npz(path, arrays)
        else:
            path.write_bytes(data)
        with pytest.raises(ValueError) as info:
            bd.ModalBlade.from_file(path)
        assert_one_clean_error(info, path)


def test_a_design_cut_inside_a_comment_or_empty_sets_no_key(tmp_path):
    """A design file that sets no key is the reference design, and says so: Design.keys_given
    is empty for an empty file, one with comments only, and the template cut inside its first
    comment; a file with one key has that key."""
    template = write_template(tmp_path / "full.toml").read_text()
    first_key = template.index("\n[")
    cut = template[:first_key // 2]
    assert cut.strip() and "=" not in cut.replace("# ", "").split("\n")[-1]
    for name, content in (("empty.toml", ""), ("comments.toml", "# my design\n\n# to do\n"),
                          ("cut.toml", cut), ("headers.toml", "[damper]\n# mass_g = 2.0\n")):
        path = tmp_path / name
        path.write_text(content)
        assert bd.load_design(path).keys_given == frozenset(), name
    path = tmp_path / "one.toml"
    path.write_text("[damper]\nmass_g = 2.0\n")
    assert bd.load_design(path).keys_given == {("damper", "mass_g")}


def test_a_design_with_a_byte_order_mark_reads(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf[damper]\nmass_g = 2.0\n")
    assert bd.load_design(path).disk.damper.mass == pytest.approx(2e-3)


def test_a_broken_modal_file_named_by_a_design_names_both(tmp_path):
    blade = write_blade_npz(tmp_path)
    cut_half(blade, "blade.npz")
    design = tmp_path / "design.toml"
    design.write_text('[blade]\nmodal_file = "blade.npz"\n')
    with pytest.raises(ValueError) as info:
        bd.load_design(design)
    message = assert_one_clean_error(info, design)
    assert str(blade) in message and "truncated or corrupted" in message, message


def test_saveable_load_of_another_class_is_a_value_error_naming_the_file(tmp_path):
    path = write_result(tmp_path)
    with pytest.raises(ValueError) as info:
        sm.MassOptimum.load(path)
    assert isinstance(info.value, TypeError)
    assert "holds a MassSweep, not a MassOptimum" in assert_one_clean_error(info, path)


# ---------------------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------------------
def test_cli_design_of_random_bytes_exits_2_with_one_line_no_traceback(tmp_path):
    path = tmp_path / "bad.toml"
    random_bytes(path, "design")
    run = subprocess.run([sys.executable, "-m", "bladedamp.cli", "frf", str(path), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert lines[0].startswith(f"bladedamp frf: error: {path}: not a readable design file (TOML): not UTF-8 text"), lines
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("how", ["cut in half", "text", "not UTF-8", "a folder"])
def test_cli_broken_design_or_blade_file_exits_2_with_one_line(tmp_path, capsys, how):
    design = write_design(tmp_path)
    if how == "cut in half":          # the design names a modal blade file that is broken
        blade = write_blade_npz(tmp_path)
        cut_half(blade, "blade.npz")
        design.write_text('[blade]\nmodal_file = "blade.npz"\n')
    else:
        ALL_BREAKS[how](design, "design")
    capsys.readouterr()
    assert main(["frf", str(design), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith(f"bladedamp frf: error: {design}: ")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("how", ["cut in half", "empty", "text", "random bytes", "deleted"])
def test_a_broken_surface_mesh_names_the_file(tmp_path, how):
    """A solid blade's surface (STL, read by trimesh; the package writes none, so a box exported by
    trimesh stands for it). An STL has no checksum: a flipped byte is another mesh, which the
    geometry's checks judge (closed, regions), so it is not among these cases."""
    trimesh = pytest.importorskip("trimesh")
    from bladedamp import solid

    path = tmp_path / "blade.stl"
    trimesh.creation.box((0.01, 0.01, 0.05)).export(path)
    ALL_BREAKS[how](path, "stl")
    with pytest.raises(ValueError) as info:
        solid.SurfaceBladeGeometry(str(path), {})
    message = str(info.value)
    assert str(path) in message and "\n" not in message, message
    assert isinstance(info.value, FileNotFoundError) == (how == "deleted"), type(info.value)
