"""Measured data: UFF 58 / CSV responses, UFF 55 / 2414 modes, ModalBlade.from_test, overlays."""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

pyuff = pytest.importorskip("pyuff")

import bladedamp as bd  # noqa: E402
from bladedamp import palette  # noqa: E402
from bladedamp.cli import main  # noqa: E402
from bladedamp.io import FileReadError  # noqa: E402
from bladedamp.measurement import (G_STANDARD, MeasuredResponse, draw_measurement, load_measurement,  # noqa: E402
                                   load_modes, parse_unit)

DATA = Path(__file__).parent / "data" / "measured"
F = np.linspace(0.0, 200.0, 201)
H = 1e-3 / (100.0**2 - F**2 + 2j * 0.02 * 100.0 * F)          # an accelerance-like complex FRF
# pyuff writes ASCII dataset 58 values as %20.11e: 12 significant digits, half an ulp of the last
ASCII_58_RTOL = 0.5e-11


def write_58(path, data, x=F, binary=0, num="m/s^2", den="N", num_type=12, func_type=4, node=3, direction=1, **extra):
    d = pyuff.prepare_58(binary=binary, func_type=func_type, rsp_node=node, rsp_dir=direction, ref_node=7, ref_dir=3,
                         data=data, x=x, id1="test", rsp_ent_name="blade", ref_ent_name="blade", abscissa_spacing=1,
                         abscissa_spec_data_type=18, ordinate_spec_data_type=num_type, orddenom_spec_data_type=13,
                         abscissa_axis_units_lab="Hz", ordinate_axis_units_lab=num, orddenom_axis_units_lab=den,
                         **extra)
    pyuff.UFF(str(path)).write_sets(d, mode="add")
    return path


def write_164(path, length=1.0, force=1.0):
    pyuff.UFF(str(path)).write_sets(pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1,
                                                      length=length, force=force, temp=1.0, temp_offset=273.15),
                                    mode="add")


# ----- UFF 58 written by pyuff from known data ------------------------------------------------
def test_binary_58b_complex_frf_reads_back_exactly(tmp_path):
    m = load_measurement(write_58(tmp_path / "b.uff", H, binary=1))
    assert np.array_equal(m.frequency_hz, F) and np.array_equal(m.response, H)
    assert (m.unit, m.point, m.direction, m.reference_point, m.reference_direction) == ("m/s^2/N", "3", "+x", "7", "+z")


def test_ascii_58_complex_frf_reads_back_to_its_printed_digits(tmp_path):
    m = load_measurement(write_58(tmp_path / "a.uff", H))
    assert m.is_complex and np.array_equal(m.frequency_hz, F)
    np.testing.assert_allclose(m.response.real, H.real, rtol=ASCII_58_RTOL, atol=0)
    np.testing.assert_allclose(m.response.imag, H.imag, rtol=ASCII_58_RTOL, atol=0)


def test_units_convert_to_si(tmp_path):
    """mm/N -> m/N by 1e-3, g/N -> m/s^2/N by 9.80665, per kN by 1e-3; binary so exact up to one product."""
    for k, (num, den, unit, factor) in enumerate([("mm", "N", "m/N", 1e-3), ("g", "N", "m/s^2/N", G_STANDARD),
                                                   ("m/s", "kN", "m/s/N", 1e-3)]):
        m = load_measurement(write_58(tmp_path / f"u{k}.uff", H, binary=1, num=num, den=den))
        assert m.unit == unit
        np.testing.assert_allclose(m.response, factor * H, rtol=1e-15, atol=0)


def test_amplitude_frf_and_the_unit_from_dataset_164(tmp_path):
    """An FRF of real amplitudes without units labels, displacement over force: the unit system
    of dataset 164 (length factor 1000, force factor 1: the file is in mm and N) gives m/N."""
    path = tmp_path / "s.uff"
    write_164(path, length=1000.0)
    amp = np.abs(H) * 1e6
    write_58(path, amp.astype(float), num="NONE", den="NONE", num_type=8)
    m = load_measurement(path)
    assert m.unit == "m/N" and not m.is_complex and m.per_force
    np.testing.assert_allclose(m.response, amp / 1000.0, rtol=ASCII_58_RTOL + 1e-15, atol=0)


def test_acceleration_to_displacement_only_when_asked(tmp_path):
    """a = -omega^2 x: the accelerance divided by -omega^2 is the receptance; nan at 0 Hz."""
    path = write_58(tmp_path / "b.uff", H, binary=1)
    assert load_measurement(path).unit == "m/s^2/N"
    x = load_measurement(path, as_displacement=True)
    omega = 2 * np.pi * F
    assert x.unit == "m/N" and np.isnan(x.response[0])
    np.testing.assert_allclose(x.response[1:], H[1:] / -omega[1:] ** 2, rtol=1e-14, atol=0)


def test_parse_unit():
    assert parse_unit("m/N") == (0, True, 1.0)
    assert parse_unit("mm/s^2") == (2, False, 1e-3)
    assert parse_unit("in/s/lbf")[:2] == (1, True)
    for bad in ("Pa", "m/s^3", "V/N", "m/N/N"):
        with pytest.raises(ValueError, match="not a response unit"):
            parse_unit(bad)


# ----- CSV ------------------------------------------------------------------------------------
def test_csv_complex_and_amplitude(tmp_path):
    path = tmp_path / "frf.csv"
    path.write_text("# rig test, blade 3 tip\nfrequency [Hz],re [mm/N],im [mm/N]\n"
                    + "".join(f"{float(f)!r},{float(h.real)!r},{float(h.imag)!r}\n" for f, h in zip(F, 1e3 * H)))
    m = load_measurement(path, node="tip", direction="+x")
    assert (m.unit, m.point, m.direction) == ("m/N", "tip", "+x")
    np.testing.assert_allclose(m.response, H, rtol=1e-15, atol=0)      # repr round-trips; one product by 1e-3
    amp = tmp_path / "amp.csv"
    amp.write_text("frequency [Hz],amplitude [mm]\n10,0.5\n20,1.5\n")
    a = load_measurement(amp)
    assert a.unit == "m" and np.array_equal(a.response, [0.5e-3, 1.5e-3]) and not a.is_complex


# ----- a public UFF file of a modal-test package ------------------------------------------------
def test_public_pyuff_frf_file():
    """tests/data/measured/pyuff_measurement.uff (ladisk/pyuff, see the README there): three
    accelerance FRFs (function 4, acceleration over excitation force) with no units labels and
    no dataset 164: the unit cannot be told, so it is refused until the caller states it."""
    path = DATA / "pyuff_measurement.uff"
    with pytest.raises(FileReadError, match=r"dataset 1 \(UFF 58, response node 1\): the unit cannot be told"):
        load_measurement(path, record=0)
    m = load_measurement(path, record=2, unit="m/s^2/N")
    raw = pyuff.UFF(str(path)).read_sets(2)
    assert m.unit == "m/s^2/N" and m.frequency_hz.shape == (1001,)
    assert np.array_equal(m.response, raw["data"]) and np.array_equal(m.frequency_hz, raw["x"])
    assert m.frequency_hz[0] == 0.0 and m.frequency_hz[-1] == 1000.0


def test_public_pyuff_mode_file():
    """tests/data/measured/pyuff_uff55_translation_rotation.uff: one normal mode (97.013 Hz) at
    43 nodes with 6 values each, no modal mass and no unit system."""
    path = DATA / "pyuff_uff55_translation_rotation.uff"
    with pytest.raises(FileReadError, match="no dataset 164"):
        load_modes(path)
    modes = load_modes(path, units="SI")
    assert modes.natural_frequencies_hz.tolist() == [97.013] and modes.shapes.shape == (43, 6, 1)
    assert modes.shapes[0, :3, 0].tolist() == [5.3569e-02, 2.0271e-02, 4.6623e-03]
    with pytest.raises(ValueError, match="mode 1 .* has no modal mass"):
        modes.mass_normalised()


def test_public_permas_2414_modes():
    """tests/data/measured/pyuff_2411_and_2414_permas.uff (ladisk/pyuff; written by Permas 18):
    ten normal modes (dataset 2414, 6 values at 441 nodes) and the nodes (dataset 2411), no
    modal masses, no unit system. The frequencies are those the file prints in record 12."""
    path = DATA / "pyuff_2411_and_2414_permas.uff"
    modes = load_modes(path, units="SI")
    assert modes.natural_frequencies_hz.tolist() == [0.956363, 2.34163, 5.88075, 7.50675, 8.54122, 14.9563,
                                                     17.0424, 17.818, 19.7208, 25.7643]
    assert modes.shapes.shape == (441, 6, 10) and np.all(np.isfinite(modes.coordinates))
    raw = [s for s in pyuff.UFF(str(path)).read_sets() if s["type"] == 2414]
    assert np.array_equal(modes.shapes[:, :, 3], np.asarray(raw[3]["data_at_node"]))
    nodes = [s for s in pyuff.UFF(str(path)).read_sets() if s["type"] == 2411][0]
    i = modes.node_index(int(nodes["node_nums"][5]))
    assert modes.coordinates[i].tolist() == [nodes["x"][5], nodes["y"][5], nodes["z"][5]]
    with pytest.raises(ValueError, match=r"mode 1 \(0.956363 Hz\) has no modal mass"):
        modes.mass_normalised()


# ----- ModalBlade.from_test -------------------------------------------------------------------
NODES = {"OL": 11, "OR": 12, "tip": 13, "excitation": 14}


def rounded(x):
    """``x`` as pyuff prints a dataset 55 value (%13.5e: 6 significant digits)."""
    return np.vectorize(lambda v: float(f"{v:.5e}"))(np.asarray(x, dtype=float))


def write_blade_modes(path, blade, modal_mass=1.0, length=1.0):
    """``blade``'s modes as UFF 55 normal modes with shapes scaled to ``modal_mass`` [kg], node
    coordinates (dataset 15) and the unit system (dataset 164) of ``length`` file units per metre
    and newtons (1000: mm, N, s and tonnes)."""
    write_164(path, length=length)
    names = list(NODES)
    xyz = np.array([blade.points[n] for n in names]) * length
    pyuff.UFF(str(path)).write_sets(pyuff.prepare_15(node_nums=[NODES[n] for n in names], def_cs=[0] * 4,
                                                     disp_cs=[0] * 4, color=[0] * 4, x=xyz[:, 0], y=xyz[:, 1],
                                                     z=xyz[:, 2]), mode="add")
    for j in range(blade.n_modes):
        shape = np.array([blade.mode_shapes[n][:, j] for n in names]) * np.sqrt(modal_mass)
        shape[:, :3] *= length
        d = pyuff.prepare_55(model_type=1, analysis_type=2, data_ch=3, spec_data_type=8, data_type=2,
                             n_data_per_node=6, load_case=1, mode_n=j + 1, freq=float(blade.natural_frequencies_hz[j]),
                             modal_m=modal_mass / length, modal_damp_vis=float(blade.damping_ratios[j]),
                             modal_damp_his=0.0, node_nums=[NODES[n] for n in names],
                             **{f"r{i + 1}": shape[:, i] for i in range(6)})
        pyuff.UFF(str(path)).write_sets(d, mode="add")
    return path


def rounded_blade(blade, modal_mass=1.0, length=1.0):
    """``blade`` as :func:`write_blade_modes` stores it (6 digits in the file's units), in SI."""
    in_file = np.array([length] * 3 + [1.0] * 3)[:, None]
    mass = rounded(modal_mass / length) * length
    shapes = {n: rounded(s * np.sqrt(modal_mass) * in_file) / in_file / np.sqrt(mass)
              for n, s in blade.mode_shapes.items()}
    return bd.ModalBlade(rounded(blade.natural_frequencies_hz), rounded(blade.damping_ratios), shapes,
                         {n: rounded(p * length) / length for n, p in blade.points.items()}, blade.mode_names)


@pytest.mark.parametrize("modal_mass, length", [(1.0, 1.0), (0.37, 1.0), (0.37, 1000.0)])
def test_from_test_gives_the_blade_of_its_modes(tmp_path, modal_mass, length):
    """The reference blade's modes written to UFF 55 (mass-normalised, or scaled to a modal mass
    of 0.37 kg that the file states; in m, N, kg or in mm, N, tonnes) give back the blade with its
    values rounded to the file's 6 digits: the same tip FRF to rounding of the arithmetic."""
    blade = bd.reference_blade()
    path = write_blade_modes(tmp_path / "modes.uff", blade, modal_mass, length)
    got = bd.ModalBlade.from_test(path, NODES, mode_names=blade.mode_names)
    want = rounded_blade(blade, modal_mass, length)
    f = np.linspace(50.0, 1500.0, 400)
    force = np.array([0.1, 0, 0, 0, 0, 0])
    a, b = got.linear_frf(f, force), want.linear_frf(f, force)
    # components zero by symmetry carry the blade's eigenvector noise, up to 5e-8 of the largest
    # (LAPACK builds differ: test_blade_io): a bound of 1e-6 of the largest
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-6 * np.abs(b).max())
    for n in NODES:
        np.testing.assert_allclose(got.points[n], want.points[n], rtol=1e-14, atol=1e-15)
    # the rounding to 6 digits is all that separates it from the reference blade
    np.testing.assert_allclose(got.natural_frequencies_hz, blade.natural_frequencies_hz, rtol=5e-6)
    np.testing.assert_allclose(got.mode_shapes["tip"], blade.mode_shapes["tip"], rtol=1e-5,
                               atol=1e-5 * np.abs(blade.mode_shapes["tip"]).max())


def test_from_test_errors_name_the_file(tmp_path):
    blade = bd.reference_blade()
    path = write_blade_modes(tmp_path / "modes.uff", blade, 1.0)
    with pytest.raises(ValueError, match=f"{path}: no node 99"):
        bd.ModalBlade.from_test(path, {**NODES, "tip": 99})
    with pytest.raises(ValueError, match="points must map"):
        bd.ModalBlade.from_test(path, {"tip": 13})


def test_from_test_of_the_public_mode_file_needs_what_it_lacks():
    """pyuff's UFF 55 file has no node coordinates, no modal mass and no damping: each is asked
    for by name; given them, its one mode at four of its nodes makes a blade."""
    path = DATA / "pyuff_uff55_translation_rotation.uff"
    points = {"OL": 1, "OR": 2, "tip": 10, "excitation": 9}
    where = {name: (0.01 * k, 0.0, 0.1) for k, name in enumerate(points)}
    with pytest.raises(ValueError, match="no position of node 1 .point 'OL'"):
        bd.ModalBlade.from_test(path, points, units="SI", modal_masses=1.0)
    with pytest.raises(ValueError, match="no modal mass"):
        bd.ModalBlade.from_test(path, points, units="SI", positions=where)
    with pytest.raises(ValueError, match="carry no damping"):
        bd.ModalBlade.from_test(path, points, units="SI", positions=where, modal_masses=2.0)
    blade = bd.ModalBlade.from_test(path, points, units="SI", positions=where, modal_masses=4.0, damping_ratios=0.01)
    modes = load_modes(path, units="SI")
    assert blade.natural_frequencies_hz.tolist() == [97.013]
    np.testing.assert_array_equal(blade.mode_shapes["tip"][:, 0], modes.shapes[modes.node_index(10), :, 0] / 2.0)


# ----- the design file: [blade] modal_file of measured modes with [blade.test] ----------------
TEST_DESIGN = """[blade]
modal_file = "modes.uff"
{extra}
[blade.test.OL]
node = 11

[blade.test.OR]
node = 12

[blade.test.tip]
node = 13

[blade.test.excitation]
node = 14
{points}"""


def write_test_design(tmp_path, extra="", points="", modes=None):
    (tmp_path / "modes.uff").write_bytes((modes or DATA / "reference_blade_modes.uff").read_bytes())
    path = tmp_path / "design.toml"
    path.write_text(TEST_DESIGN.format(extra=extra, points=points))
    return path


def test_design_file_measured_modes_blade_is_from_test_with_the_same_arguments(tmp_path):
    """[blade] modal_file = a UFF 55 file with the node tables [blade.test.*] builds the blade that
    ModalBlade.from_test builds from the same file and nodes; [blade.test] modal_mass_kg, a
    position_mm and [blade] damping_ratio reach it as modal_masses, positions and damping_ratios."""
    from bladedamp.design import load_design
    design = load_design(write_test_design(tmp_path))
    want = bd.ModalBlade.from_test(DATA / "reference_blade_modes.uff", NODES)
    got = design.disk.blade
    np.testing.assert_array_equal(got.natural_frequencies_hz, want.natural_frequencies_hz)
    np.testing.assert_array_equal(got.damping_ratios, want.damping_ratios)
    for n in NODES:
        np.testing.assert_array_equal(got.mode_shapes[n], want.mode_shapes[n])
        np.testing.assert_array_equal(got.points[n], want.points[n])

    design = load_design(write_test_design(tmp_path, extra="damping_ratio = 0.003\n\n[blade.test]\nmodal_mass_kg = 4.0\n",
                                           points="position_mm = [1.0, 2.0, 3.0]\n"))
    want = bd.ModalBlade.from_test(DATA / "reference_blade_modes.uff", NODES, modal_masses=4.0, damping_ratios=0.003,
                                   positions={"excitation": (1e-3, 2e-3, 3e-3)})
    got = design.disk.blade
    np.testing.assert_array_equal(got.damping_ratios, want.damping_ratios)
    np.testing.assert_array_equal(got.mode_shapes["tip"], want.mode_shapes["tip"])
    np.testing.assert_allclose(got.points["excitation"], (1e-3, 2e-3, 3e-3), rtol=1e-15)
    assert got.damping_ratios.tolist() == [0.003] * got.n_modes


@pytest.mark.parametrize("extra, points, expected", [
    ("", "\n[blade.test.platform]\nposition_mm = [0.0, 0.0, 1.0]\n", r"\[blade\.test\.platform\] node is required"),
    ("n_modes = 2\n", "", r"\[blade\] n_modes applies to the beam model only"),
    ("\n[blade.test]\nmodal_mass_kg = -1.0\n", "", r"\[blade\.test\] modal_mass_kg = -1\.0"),
    ("\n[blade.test]\nunits = \"mm\"\n", "", r"\[blade\.test\] units = \"mm\""),
])
def test_design_file_measured_modes_errors_are_one_line_naming_the_key(tmp_path, extra, points, expected):
    from bladedamp.design import DesignError, load_design
    with pytest.raises(DesignError, match=expected) as info:
        load_design(write_test_design(tmp_path, extra, points))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("old, new, modes, modes_chars, expected", [
    ("[blade.test.excitation]\nnode = 14\n", "", None, None,
     r"\[blade\.test\.excitation\] is required with a measured mode file"),
    ("node = 13", "node = 99", None, None,
     r"modal_file = \"modes\.uff\": .*modes\.uff: no node 99 in the mode shapes .*\[blade\.test\.<point>\] position_mm"),
    ("", "", "pyuff_uff55_translation_rotation.uff", None,
     r"modes\.uff: no dataset 164 .*give units='SI'.*\(the design file's keys: \[blade\.test\] modal_mass_kg and units"),
    ('modal_file = "modes.uff"', 'modal_file = "blade.npz"', None, None,
     r"\[blade\.test\.OL\] node applies to a measured mode file as \[blade\] modal_file \(ending in \.uff, \.unv, \.uf\)"),
    ("", "", None, 2000,
     r"modal_file = \"modes\.uff\": .*modes\.uff: line \d+: dataset .* has no closing -1 line"),
], ids=["no excitation node", "unknown node", "no dataset 164", "node without a mode file", "truncated mode file"])
def test_design_file_measured_modes_bad_nodes_files_and_keys(tmp_path, old, new, modes, modes_chars, expected):
    """The design file's text edited (``old`` -> ``new``), another mode file (``modes``, in
    tests/data) or the mode file cut after ``modes_chars`` characters: one DesignError each."""
    from bladedamp.design import DesignError, load_design
    path = write_test_design(tmp_path, modes=DATA / modes if modes else None)
    if old:
        assert old in path.read_text()
        path.write_text(path.read_text().replace(old, new))
    if modes_chars:
        (tmp_path / "modes.uff").write_text((DATA / "reference_blade_modes.uff").read_text()[:modes_chars])
    with pytest.raises(DesignError, match=expected):
        load_design(path)


def test_cli_measured_modes_design_error_is_one_line_with_exit_code_2(tmp_path, capsys):
    from conftest import one_error_line
    path = write_test_design(tmp_path)
    path.write_text(path.read_text().replace("node = 13", "node = 99"))
    assert main(["frf", str(path), "--out", str(tmp_path / "o")]) == 2
    one_error_line(capsys, "modes.uff", "no node 99")


# ----- bad files ------------------------------------------------------------------------------
def test_bad_files_give_one_error_naming_the_file(tmp_path):
    good = write_58(tmp_path / "a.uff", H)
    text = good.read_text()
    cut = tmp_path / "cut.uff"
    cut.write_text(text[: len(text) // 2])
    binary = write_58(tmp_path / "b.uff", H, binary=1).read_bytes()
    cut_binary = tmp_path / "cut_binary.uff"
    cut_binary.write_bytes(binary[: len(binary) // 2])
    truncated = "line 1: dataset {} starting there has no closing -1 line (the file is truncated)"
    cases = {cut: truncated.format("58"), cut_binary: truncated.format("58b"), tmp_path / "none.uff": "no such", DATA / "pyuff_uff55_translation_rotation.uff":
             "no dataset 58", tmp_path / "text.uff": "not a Universal File Format file"}
    (tmp_path / "text.uff").write_text("frequency,re,im\n1,2,3\n")
    for path, what in cases.items():
        with pytest.raises(FileReadError) as info:
            load_measurement(path)
        msg = str(info.value)
        assert str(path) in msg and "\n" not in msg and what in msg, msg
    time = tmp_path / "time.uff"
    write_58(time, H.real.copy(), func_type=1)
    with pytest.raises(FileReadError, match=r"time.uff: dataset 1 \(UFF 58, response node 3\) holds a time "
                                            r"response; expected a frequency response function"):
        load_measurement(time)
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("frequency [Hz],re,im\n1,2,3\n")
    with pytest.raises(FileReadError, match="bad.csv: header: the unit cannot be told"):
        load_measurement(bad_csv)


def test_cli_bad_measured_file_is_one_line_exit_2(tmp_path, capsys):
    from bladedamp.design import write_template

    design = write_template(tmp_path / "design.toml")
    bad = tmp_path / "rig.uff"
    bad.write_text("    -1\n    58\nbroken\n")
    assert main(["frf", str(design), "--measured", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"bladedamp frf: error: {bad}"), err
    public = DATA / "pyuff_measurement.uff"          # three records, no units
    for extra, what in ([[], "3 dataset 58 records match"], [["--measured-record", "1"], "the unit cannot be told"],
                        [["--measured-record", "1", "--measured-unit", "m/s^3"], "not a response unit"]):
        assert main(["frf", str(design), "--measured", str(public), *extra, "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"bladedamp frf: error: {public}") and what in err[0], err
    assert not (tmp_path / "o").exists()


# ----- drawing beside a prediction ------------------------------------------------------------
def test_draw_measurement_converts_to_the_plotted_displacement(tmp_path):
    """An accelerance drawn on a tip-amplitude axes in mm: |H| / omega^2 * F * 1e3, inside the
    axes' frequency range, in the measured colour."""
    m = MeasuredResponse(F, H, "m/s^2/N", "3", "+x")
    fig, ax = plt.subplots()
    ax.plot([90.0, 110.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="force amplitude is needed"):
        draw_measurement(ax, m)
    line = draw_measurement(ax, m, force_n=0.1)
    f, y = line.get_xdata(), line.get_ydata()
    keep = (F >= 90) & (F <= 110)
    assert np.array_equal(f, F[keep])
    np.testing.assert_allclose(y, 1e3 * 0.1 * np.abs(H[keep]) / (2 * np.pi * F[keep]) ** 2, rtol=1e-14)
    assert line.get_color() == palette.MEASURED
    plt.close(fig)


def test_cli_frf_draws_the_measurement(tmp_path, monkeypatch):
    """``bladedamp frf --measured`` draws the file on frf.png: a receptance CSV in mm/N times the
    design's excitation force |F| [N], in mm, inside the computed range."""
    import bladedamp.measurement as measurement
    from bladedamp.design import load_design, write_template

    design = write_template(tmp_path / "design.toml")
    text = design.read_text()
    for old, new in {'frequency_range_hz = [90.0, 105.0]': 'frequency_range_hz = [92.0, 99.0]',
                     'harmonics = "auto"': 'harmonics = [1]'}.items():
        assert old in text
        text = text.replace(old, new)
    design.write_text(text)
    force = float(np.linalg.norm(load_design(design).disk.excitation[:3]))
    rig = tmp_path / "rig.csv"
    f = np.linspace(80.0, 110.0, 61)
    receptance_mm = 1e3 * bd.reference_blade().linear_frf(f, np.array([1.0, 0, 0, 0, 0, 0]))[:, 0]
    rig.write_text("frequency [Hz],re [mm/N],im [mm/N]\n"
                   + "".join(f"{a!r},{b.real!r},{b.imag!r}\n" for a, b in zip(f.tolist(), receptance_mm.tolist())))
    drawn = []
    draw = measurement.draw_measurement
    monkeypatch.setattr(measurement, "draw_measurement", lambda ax, m, **kw: drawn.append(draw(ax, m, **kw)) or drawn[-1])
    out = tmp_path / "out"
    assert main(["frf", str(design), "--measured", str(rig), "--no-stop-check", "--no-peak-check",
                 "--out", str(out)]) == 0
    assert (out / "frf.png").is_file() and len(drawn) == 1
    x, y = drawn[0].get_xdata(), drawn[0].get_ydata()
    keep = (f >= 92.0) & (f <= 99.0)
    assert np.array_equal(x, f[keep])
    np.testing.assert_allclose(y, force * np.abs(receptance_mm[keep]), rtol=1e-13)
    # a saved response has no model, hence no force: the FRF is refused until given one
    saved = bd.load(out / "frf_EO1.npz")
    with pytest.raises(ValueError, match=r"force amplitude is needed .* measured.at_force"):
        saved.plot(measured=rig)
    ax = saved.plot(measured=load_measurement(rig).at_force(force))
    np.testing.assert_allclose(drawn[-1].get_ydata(), force * np.abs(receptance_mm[keep]), rtol=1e-13)
    assert drawn[-1].axes is ax
    plt.close("all")


def test_the_readme_example_files_hold_the_reference_blade():
    """tests/data/measured/reference_blade_*.uff (written by make_reference_files.py there): the
    receptance reads as the reference blade's linear FRF to the file's 12 digits per part (and the
    blade's reproducibility across LAPACK builds), and
    the modes give the reference blade rounded to the file's 6 digits."""
    blade = bd.reference_blade()
    m = load_measurement(DATA / "reference_blade_tip_frf.uff")
    assert (m.unit, m.point, m.direction, m.reference_point) == ("m/N", "13", "+x", "14")
    h = blade.linear_frf(m.frequency_hz, np.array([1.0, 0, 0, 0, 0, 0]))[:, 0]
    # the file's 12 digits, and the blade computed again here: its shapes agree across LAPACK
    # builds to 1e-9 of their value (test_blade_io), so the receptance (their products) to 2e-9
    rtol = ASCII_58_RTOL + 2e-9
    np.testing.assert_allclose(m.response.real, h.real, rtol=rtol, atol=0)
    np.testing.assert_allclose(m.response.imag, h.imag, rtol=rtol, atol=0)
    got = bd.ModalBlade.from_test(DATA / "reference_blade_modes.uff", NODES)
    want = rounded_blade(blade)
    f = np.linspace(50.0, 1500.0, 400)
    a, b = (x.linear_frf(f, np.array([0.1, 0, 0, 0, 0, 0])) for x in (got, want))
    # components zero by symmetry carry the blade's eigenvector noise, up to 5e-8 of the largest
    # (LAPACK builds differ: test_blade_io): a bound of 1e-6 of the largest
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-6 * np.abs(b).max())


def test_measurement_and_modes_save_and_load(tmp_path):
    m = load_measurement(DATA / "reference_blade_tip_frf.uff")
    back = bd.load(m.save(tmp_path / "m"))
    assert isinstance(back, MeasuredResponse) and back.unit == m.unit and back.point == m.point
    assert np.array_equal(back.response, m.response) and np.array_equal(back.frequency_hz, m.frequency_hz)
    modes = load_modes(DATA / "reference_blade_modes.uff")
    again = bd.load(modes.save(tmp_path / "modes"))
    assert np.array_equal(again.shapes, modes.shapes) and np.array_equal(again.nodes, modes.nodes)
    assert back.plot().get_lines()
    plt.close("all")
