"""Design files (bladedamp.design): the template is the reference disk, every field is
validated with a one-line message naming the file, key, value and allowed range, unknown keys
are errors, and partial files take the reference values for what they leave out."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

import bladedamp
from bladedamp.design import (Boolean, Choice, DesignError, Either, List, Number, Text, fields, load_design,
                              reference_design, template, write_template)
from bladedamp.reference import reference_disk


def _write(tmp_path, text: str, name: str = "design.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _same_disk(a, b):
    """Every model parameter of two TunedDisks is equal (the blade's shapes exactly)."""
    for name in ("n_blades", "engine_order", "gamma_left", "gamma_right", "damper_radius", "rotor_speed_hz",
                 "damper_inertia"):
        assert getattr(a, name) == getattr(b, name), name
    assert np.array_equal(a.excitation, b.excitation)
    assert a.damper == b.damper
    assert np.array_equal(a.blade.natural_frequencies_hz, b.blade.natural_frequencies_hz)
    assert np.array_equal(a.blade.damping_ratios, b.blade.damping_ratios)
    assert a.blade.mode_names == b.blade.mode_names
    assert set(a.blade.mode_shapes) == set(b.blade.mode_shapes)
    for point in b.blade.mode_shapes:
        assert np.array_equal(a.blade.mode_shapes[point], b.blade.mode_shapes[point]), point
        assert np.array_equal(a.blade.points[point], b.blade.points[point]), point


# ---------------------------------------------------------------------------------------
# the template is the reference design
# ---------------------------------------------------------------------------------------
def test_template_round_trip_is_the_reference_disk(tmp_path):
    path = write_template(tmp_path / "design.toml")
    design = bladedamp.load_design(path)             # exported from the package
    _same_disk(design.disk, reference_disk())
    assert design.engine_orders == (1,)
    assert design.analysis.f_range_hz == (90.0, 105.0) and design.analysis.harmonics == "auto"
    assert design.mistuning.std == 0.02 and design.mistuning.kappa is None
    _same_disk(reference_design().disk, reference_disk())


def test_template_same_frf_as_the_reference_disk(tmp_path):
    design = load_design(write_template(tmp_path / "design.toml"))
    a = design.disk.frequency_response(94.0, 97.0, harmonics=(1,), max_step=0.05)
    b = reference_disk().frequency_response(94.0, 97.0, harmonics=(1,), max_step=0.05)
    assert a.success and np.array_equal(a.tip_amplitude, b.tip_amplitude)


def test_template_comments_every_key_with_its_allowed_range_from_the_one_table():
    text = template()
    values = tomllib.loads(text)
    lines = text.splitlines()
    for f in fields():
        table = values
        for part in f.table.split("."):
            table = table[part]
        if f.value is None:                       # optional: shown commented out
            assert f"# {f.key} = " in text, f.key
            assert f.key not in table
        else:
            assert f.key in table, f.key
        start = lines.index(f"[{f.table}]")         # the key's line in its own table (keys repeat across tables)
        i = next(k for k, line in enumerate(lines) if k > start and line.startswith((f"{f.key} = ", f"# {f.key} = ")))
        comment = " ".join(line.lstrip("# ").strip() for line in lines[max(i - 4, 0):i] if line.startswith("#"))
        assert f"Allowed: {f.allowed}." in comment, (f.key, comment)
        assert f.reason in comment, f.key
        if f.unit != "-":
            assert f"Unit: {f.unit}." in comment, f.key


def test_init_refuses_to_overwrite(tmp_path):
    path = write_template(tmp_path / "design.toml")
    with pytest.raises(DesignError, match="exists"):
        write_template(path)
    write_template(path, overwrite=True)


# ---------------------------------------------------------------------------------------
# every field is validated
# ---------------------------------------------------------------------------------------
def _wrong_type(check):
    """A TOML value that ``check`` refuses."""
    return "[1]" if isinstance(check, Text) else '"nonsense"'


def _out_of_range(check):
    """A number just outside a Number's range (or None when it has none on that side)."""
    if isinstance(check, Number):
        return check.high + 1 if check.high < 1e6 else check.low - 1
    return None


@pytest.mark.parametrize("field", fields(), ids=lambda f: f"{f.table}.{f.key}")
def test_every_field_rejects_a_wrong_value_naming_file_key_value_and_range(tmp_path, field):
    bad = [_wrong_type(field.check)]
    if _out_of_range(field.check) is not None:
        bad.append(repr(_out_of_range(field.check)))
    for value in bad:
        path = _write(tmp_path, f"[{field.table}]\n{field.key} = {value}\n")
        with pytest.raises(DesignError) as err:
            load_design(path)
        msg = str(err.value)
        assert "\n" not in msg
        assert str(path) in msg and f"[{field.table}] {field.key} = " in msg, msg
        assert field.allowed in msg, msg


def test_every_check_describes_what_it_allows():
    for f in fields():
        assert isinstance(f.check, (Number, Choice, Boolean, Text, List, Either))
        assert f.allowed and "None" not in f.allowed, f.key


@pytest.mark.parametrize("text, match", [
    ("[damper]\nmas_g = 1.0\n", r"unknown key \[damper\] mas_g \(did you mean mass_g\?\)"),
    ("[dampr]\nmass_g = 1.0\n", r"unknown table or key 'dampr' \(did you mean damper\?\)"),
    ("n_blades = 16\n", "unknown table or key 'n_blades'"),
    ("damper = 3\n", r"damper must be a table \[damper\]"),
    ("[disk]\nengine_order = -1\n", r"\[disk\] engine_order = -1 .* \[0, 500\]"),
    ("[disk]\nengine_order = [2, 1]\n", r"\[disk\] engine_order = \[2, 1\] .* strictly increasing"),
    ("[disk]\nexcitation_n_nm = [0.1, 0.0]\n", r"\[disk\] excitation_n_nm = \[0.1, 0.0\] .* list of 6"),
    ("[analysis]\nharmonics = [0, 2]\n", r"harmonics = \[0, 2\] .* containing 1"),
    ("[analysis]\nfrequency_range_hz = [105.0, 90.0]\n", r"frequency_range_hz = \[105.0, 90.0\] .* increasing"),
    ("[blade]\nnatural_frequencies_hz = [95.0, 423.0]\n", r"natural_frequencies_hz = .* 4 numbers"),
    ("[blade.beam]\nplatform_contact_z_offset_mm = 70.0\n", r"\[0, shank_length_mm = 60\] mm"),
    ("[mistuning]\nkappa = [1.0, 1.01]\n", r"kappa = \[1.0, 1.01\] .* 16 numbers"),
    ("[mistuning]\nstd = 0.01\nkappa = " + str([1.0] * 16) + "\n", "kappa replaces std and seed"),
    ("[damper]\nmass_g = true\n", r"mass_g = true is not allowed: must be a number in \(0, 1000\] g"),
    ("[damper\nmass_g = 1\n", "not valid TOML"),
])
def test_bad_files_one_line_naming_the_problem(tmp_path, text, match):
    path = _write(tmp_path, text)
    with pytest.raises(DesignError, match=match) as err:
        load_design(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_missing_file_says_how_to_write_one(tmp_path):
    with pytest.raises(DesignError, match="no such design file .*bladedamp init"):
        load_design(tmp_path / "nothing.toml")


# ---------------------------------------------------------------------------------------
# partial designs take the reference values; the models follow the keys
# ---------------------------------------------------------------------------------------
def test_a_partial_file_is_the_reference_with_its_changes(tmp_path):
    design = load_design(_write(tmp_path, "[damper]\nmass_g = 2.5\n"))
    _same_disk(design.disk, reference_disk("cylinder", 2.5e-3))
    assert design.mistuning is None                  # no [mistuning] table: a tuned design
    with pytest.raises(DesignError, match="mistuning"):
        design.mistuned_disk()


def test_wedge_angles_speed_and_engine_orders_in_si(tmp_path):
    text = ("[damper]\nkind = \"wedge\"\nmass_g = 0.3\ncontact_height_mm = 3.0\nfriction_coefficient = 0.5\n"
            "[disk]\nengine_order = [0, 2, 4]\ngamma_left_deg = 30.0\ngamma_right_deg = 60.0\n"
            "damper_radius_mm = 100.0\nrotor_speed_eo0_rpm = 3000.0\n"
            "[analysis]\nharmonics = [0, 1, 3]\nmass_range_g = [0.1, 5.0]\n")
    design = load_design(_write(tmp_path, text))
    d = design.disk
    assert d.damper.kind == "wedge" and d.damper.contact_height == pytest.approx(3e-3)
    assert d.damper.mass == pytest.approx(3e-4) and d.damper.contact.friction_coefficient == 0.5
    assert d.gamma_left == pytest.approx(np.radians(30)) and d.gamma_right == pytest.approx(np.radians(60))
    assert d.damper_radius == pytest.approx(0.1)
    assert design.engine_orders == (0, 2, 4) and d.engine_order == 0
    assert d.rotor_speed_hz == pytest.approx(3000 / 60)               # EO = 0 needs a speed: rpm / 60 in Hz
    eo2 = design.disk_at(2)
    assert eo2.engine_order == 2 and eo2.rotor_speed_hz is None       # 'auto': Omega_E / EO
    assert design.analysis.harmonics == (0, 1, 3) and design.analysis.study_harmonics == (0, 1, 3)
    assert design.analysis.mass_bounds == pytest.approx((1e-4, 5e-3))


def test_engine_orders_above_half_the_blades(tmp_path):
    """16 blades, engine_order = [7, 9, 16, 17]: accepted; EO 9 is nodal diameter 7 backward
    with the preload of EO 9 (m R (Omega_E / 9)^2, not EO 7's), EO 16 nodal diameter 0 with a
    rotor speed Omega_E / 16, EO 17 nodal diameter 1 forward."""
    design = load_design(_write(tmp_path, "[disk]\nengine_order = [7, 9, 16, 17]\n"))
    assert design.engine_orders == (7, 9, 16, 17)
    expected = {7: (7, "forward"), 9: (7, "backward"), 16: (0, "standing"), 17: (1, "forward")}
    f = 97.0
    for eo, nd in expected.items():
        disk = design.disk_at(eo)
        assert disk.nodal_diameter == nd and disk.rotor_speed_hz is None
        force = disk.centrifugal_force(f)[0]
        assert force == pytest.approx(disk.damper.mass * disk.damper_radius * (2 * np.pi * f / eo) ** 2, rel=1e-14)
    assert design.disk_at(16).interblade_phase == 0.0
    assert design.disk_at(9).interblade_phase == pytest.approx(-design.disk_at(7).interblade_phase, rel=1e-15)


def test_no_damper_and_a_fixed_rotor_speed(tmp_path):
    design = load_design(_write(tmp_path, "[damper]\nkind = \"none\"\n[disk]\nrotor_speed_rpm = 6000.0\n"))
    assert not design.disk.has_damper
    assert design.disk.rotor_speed_hz == pytest.approx(100.0)       # 6000 rpm


def test_beam_overrides_change_the_blade(tmp_path):
    text = ("[blade]\nnatural_frequencies_hz = \"model\"\ndamping_ratio = [0.001, 0.002, 0.003, 0.004]\n"
            "[blade.beam]\nairfoil_length_mm = 120.0\nshank_length_mm = 60.0\n")
    blade = load_design(_write(tmp_path, text)).disk.blade
    # a shorter airfoil stiffens the blade: its own (FE) 1F frequency rises above the reference's 95 Hz
    assert blade.natural_frequencies_hz[0] > 100.0
    assert np.array_equal(blade.damping_ratios, [0.001, 0.002, 0.003, 0.004])
    assert blade.points["tip"][2] == pytest.approx(0.18)


def test_explicit_kappa_gives_the_mistuned_assembly(tmp_path):
    kappa = [1.0 + 0.01 * (-1) ** k for k in range(4)]
    design = load_design(_write(tmp_path, f"[disk]\nn_blades = 4\n[mistuning]\nkappa = {kappa}\n"))
    m = design.mistuned_disk()
    f1 = design.disk.blade.natural_frequencies_hz
    assert len(m.blades) == 4
    for b, k in zip(m.blades, kappa):
        assert np.allclose(b.natural_frequencies_hz, k * f1)


def test_random_mistuning_from_std_and_seed(tmp_path):
    from bladedamp.studies.mistuning import random_kappa

    design = load_design(_write(tmp_path, "[mistuning]\nstd = 0.03\nseed = 7\n"))
    assert np.array_equal(design.kappa, random_kappa(16, 0.03, 7))


def test_modal_file_blade(tmp_path):
    from bladedamp.blade import ModalBlade

    if not hasattr(ModalBlade, "save") or not hasattr(ModalBlade, "from_file"):
        pytest.skip("ModalBlade.save / from_file not in this version")
    ref = reference_disk()
    ref.blade.save(tmp_path / "blade.npz")
    design = load_design(_write(tmp_path, "[blade]\nmodal_file = \"blade.npz\"\n"))   # relative to the file
    _same_disk(design.disk, ref)
    # the beam keys do not apply to a file's blade: an error, not silently ignored
    with pytest.raises(DesignError, match=r"\[blade.beam\] airfoil_length_mm applies to the beam model only"):
        load_design(_write(tmp_path, "[blade]\nmodal_file = \"blade.npz\"\n[blade.beam]\nairfoil_length_mm = 1.0\n"))
    with pytest.raises(DesignError, match="modal_file"):
        load_design(_write(tmp_path, "[blade]\nmodal_file = \"missing.npz\"\n"))


# ---------------------------------------------------------------------------------------
# a user's blade as a surface mesh (STL): [blade] surface_file and [blade.regions.*]
# ---------------------------------------------------------------------------------------
SURFACE_ELEMENT_SIZE_MM = 12.0     # [mm] the STL blade's mesh here: 6 700 DOF, about 1.5 s per blade


def _mm(v) -> str:
    """A TOML list of numbers [mm] of a vector ``v`` [m]."""
    return str([1e3 * float(x) for x in v])


@pytest.fixture
def stl_folder(reference_stl_mm, tmp_path):
    """A folder with the reference solid's surface (blade.stl, mm) and its OL and OR faces as their
    own files (OL.stl, OR.stl, mm): the inputs of a surface_file design."""
    import shutil

    import trimesh
    from bladedamp.blade.solid import SurfaceBladeGeometry
    from conftest import reference_regions

    shutil.copy(reference_stl_mm, tmp_path / "blade.stl")
    ug = SurfaceBladeGeometry(reference_stl_mm, reference_regions(), scale=1e-3)
    for side in ("OL", "OR"):
        trimesh.Trimesh(ug.vertices / 1e-3, ug.faces[ug.region_faces[side]]).export(tmp_path / f"{side}.stl")
    return tmp_path


def _surface_text(regions=("clamp", "OL", "OR")) -> str:
    """A design with the reference solid's STL: [blade] model = "solid", surface_file = "blade.stl"
    in mm, and the ``regions`` of conftest.reference_regions as planes."""
    from conftest import reference_regions

    text = ('[blade]\nmodel = "solid"\nsurface_file = "blade.stl"\nsurface_units = "mm"\n'
            f'solid_element_size_mm = {SURFACE_ELEMENT_SIZE_MM}\n')
    for name, region in reference_regions().items():
        if name not in regions:
            continue
        text += (f"[blade.regions.{name}]\nplane_point_mm = {_mm(region.point)}\n"
                 f"plane_normal = {[float(x) for x in region.normal]}\n")
    return text


def test_surface_file_blade_is_the_direct_stl_blade(stl_folder):
    """The README's design-file example (section "Your own blade geometry (STL)"; its STL here the
    reference solid's surface in mm, its OR face as its own file, the mesh coarser) gives the blade of
    solid_blade(SurfaceBladeGeometry(...)) at the same element size: the same frequencies
    and shapes (the same mesh; rounding of the eigensolver only), flexible platforms, and the disk
    takes the platform angles of the STL's OL / OR faces (35 deg)."""
    from bladedamp.blade import ModalBlade
    from bladedamp.blade.solid import SolidModalBlade, SurfaceBladeGeometry, solid_blade
    from conftest import reference_regions

    import pathlib
    import shutil

    readme = (pathlib.Path(__file__).parents[1] / "README.md").read_text()
    section = readme[readme.index("### Your own blade geometry (STL)"):]
    example = section[section.index("```toml\n") + 8:section.index("```\n", section.index("```toml"))]
    example = example.replace('surface_units = "mm"',
                              f'surface_units = "mm"\nsolid_element_size_mm = {SURFACE_ELEMENT_SIZE_MM}')
    shutil.copy(stl_folder / "blade.stl", stl_folder / "my_blade.stl")
    shutil.copy(stl_folder / "OR.stl", stl_folder / "my_blade_OR.stl")
    design = load_design(_write(stl_folder, example))
    blade = design.disk.blade
    assert isinstance(blade, SolidModalBlade) and blade.flexible_platform and design.blade_geometry is None
    direct = solid_blade(SurfaceBladeGeometry(stl_folder / "blade.stl", reference_regions(), scale=1e-3),
                         1e-3 * SURFACE_ELEMENT_SIZE_MM)
    assert blade.solid_info["n_dofs"] == direct.solid_info["n_dofs"]
    np.testing.assert_allclose(blade.natural_frequencies_hz, direct.natural_frequencies_hz, rtol=1e-9)
    assert blade.mode_names == direct.mode_names == ("1F", "2F", "1T", "1E")
    for p in direct.points:
        np.testing.assert_allclose(blade.points[p], direct.points[p], rtol=0, atol=1e-12)
        scale = np.abs(direct.shape(p)).max(axis=0)
        np.testing.assert_allclose(blade.shape(p) / scale, direct.shape(p) / scale, rtol=0, atol=1e-7)
    for side, gamma in (("OL", design.disk.gamma_left), ("OR", design.disk.gamma_right)):
        assert gamma == pytest.approx(np.radians(35.0), abs=1e-6)
        np.testing.assert_allclose(blade.platform_displacements(side, blade.points[side][None],
                                                                blade.face_fields[side].frame[2]).shape, (1, 3, 4))
    assert design.values["disk"]["gamma_left_deg"] == pytest.approx(35.0, abs=1e-4)


@pytest.mark.parametrize("change, match", [
    (lambda t: t.replace('surface_units = "mm"', 'surface_units = "furlong"'),
     r"\[blade\] surface_units = \"furlong\" is not allowed: must be one of 'm', 'mm', 'cm', 'in'"),
    (lambda t: t.replace('surface_units = "mm"', 'surface_units = "m"'),
     r"\[blade\] surface_units = \"m\" \(1 m per unit\): scale: the surface spans 200 m"),
    (lambda t: t.replace('surface_units = "mm"\n', ""), r"\[blade\] surface_file needs surface_units.*'mm'"),
    (lambda t: t.replace('"blade.stl"', '"absent.stl"'), r"\[blade\] surface_file = \"absent.stl\": no file"),
    (lambda t: t.replace('"blade.stl"', '"holed.stl"'),
     r"\[blade\] surface_file = \"holed.stl\": surface must be a closed \(watertight\)"),
    (lambda t: t.split("[blade.regions.OR]")[0],
     r"\[blade\] surface_file needs the tables .* \(missing: \[blade.regions.OR\]\)"),
    (lambda t: t + "[blade.regions.hub]\nfile = \"OL.stl\"\n",
     r"unknown table \[blade.regions.hub\].*allowed tables: \[blade.regions.clamp\], \[blade.regions.OL\]"),
    (lambda t: t.replace("[blade.regions.OR]\n", "[blade.regions.OR]\nfile = \"OL.stl\"\n"),
     r"\[blade.regions.OR\] file replaces the plane: .*remove plane_normal, plane_point_mm"),
    (lambda t: t + "[blade.regions.tip]\ntolerance_mm = 0.1\n",
     r"\[blade.regions.tip\] needs plane_point_mm and plane_normal .*or file \(given: tolerance_mm\)"),
    (lambda t: t + "[blade.regions.tip]\nfile = \"tip.stl\"\n", r"\[blade.regions.tip\] file = \"tip.stl\": no file"),
    (lambda t: t + "[blade.regions.tip]\nplane_point_mm = [0, 0, 500]\nplane_normal = [0, 0, 1]\n",
     r"\[blade.regions.tip\]: regions\['tip'\] selects no triangle"),
    (lambda t: t + "[blade.regions.tip]\nplane_point_mm = [0, 0, 200]\nplane_normal = [0, 0, 0]\n",
     r"\[blade.regions.tip\] plane_normal = \[0.0, 0.0, 0.0\] is not allowed: must be 3 numbers, not all zero"),
    (lambda t: t + "[disk]\ngamma_left_deg = 40.0\n",
     r"\[disk\] gamma_left_deg = 40.0 is not the platform angle of the OL face of \[blade\] surface_file"),
    (lambda t: t + "[blade.beam]\nshank_length_mm = 50.0\n",
     r"\[blade.beam\] shank_length_mm is the built-in blade's geometry; with \[blade\] surface_file only"),
    (lambda t: t.replace('model = "solid"\n', ""), r"\[blade\] surface_file is meshed as a solid FE blade"),
    (lambda t: t.replace('model = "solid"\n', 'model = "solid"\nmodal_file = "blade.npz"\n'),
     r"\[blade\] surface_file and modal_file are two different blades: give one of them"),
    (lambda t: t.replace('surface_file = "blade.stl"\n', ""),
     r"\[blade\] surface_units applies to a surface_file blade only"),
], ids=["units-unknown", "units-wrong", "units-missing", "file-missing", "not-watertight", "region-missing",
        "region-unknown", "plane-and-file", "plane-incomplete", "region-file-missing", "plane-off-the-blade",
        "normal-zero", "gamma-differs", "beam-geometry-key", "model-beam", "and-modal-file",
        "units-without-file"])
def test_surface_file_bad_input_one_line_naming_the_key(stl_folder, change, match):
    """Each mistake stops before meshing with one line naming the file and the key."""
    import trimesh

    mesh = trimesh.load(stl_folder / "blade.stl", force="mesh")
    trimesh.Trimesh(mesh.vertices, mesh.faces[1:]).export(stl_folder / "holed.stl")     # one triangle missing
    path = _write(stl_folder, change(_surface_text()))
    with pytest.raises(DesignError, match=match) as err:
        load_design(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_modal_file_of_a_solid_blade_keeps_its_flexible_platforms(coarse_modes, tmp_path):
    """[blade] modal_file of a saved solid FE blade: the solid blade with its flexible platforms,
    its own frequencies, and the disk at its faces' platform angles (another angle is refused)."""
    from bladedamp.blade.solid import SolidModalBlade, solid_blade

    blade = solid_blade(modes=coarse_modes)
    blade.save(tmp_path / "solid.npz")
    design = load_design(_write(tmp_path, '[blade]\nmodal_file = "solid.npz"\n'))
    back = design.disk.blade
    assert isinstance(back, SolidModalBlade) and back.flexible_platform
    assert np.array_equal(back.natural_frequencies_hz, blade.natural_frequencies_hz)
    assert design.disk.gamma_left == pytest.approx(blade.face_fields["OL"].gamma, abs=1e-12)
    with pytest.raises(DesignError, match=r"\[disk\] gamma_right_deg = 50.0 is not the platform angle of the OR "
                                          r"face of \[blade\] modal_file = \"solid.npz\" \(35 deg\)"):
        load_design(_write(tmp_path, '[blade]\nmodal_file = "solid.npz"\n[disk]\ngamma_right_deg = 50.0\n'))


def test_surface_file_error_on_the_command_line(stl_folder, capsys):
    """bladedamp frf with a region missing: exit code 2, one line naming the file and the tables."""
    from bladedamp.cli import main

    path = _write(stl_folder, _surface_text(regions=("clamp", "OL")))
    assert main(["frf", str(path), "--out", str(stl_folder / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(path) in err and "(missing: [blade.regions.OR])" in err


@pytest.mark.parametrize("blade", ["modal_file", "surface_file", "parametric"])
def test_platform_angle_option_with_a_solid_blade_exits_2_before_computing(blade, coarse_modes, stl_folder, capsys):
    """bladedamp optimize --gamma-right-deg with a solid FE blade (its saved file, an STL, the
    parametric solid): exit code 2 and one line naming the option and why (the blade's geometry
    sets the platform angles), right after the design is read: no mass optimisation, no output
    folder (the platform-angle check of the flexible platforms used to stop the study's first FRF)."""
    import time

    from bladedamp.cli import main
    from bladedamp.blade.solid import solid_blade

    if blade == "modal_file":
        solid_blade(modes=coarse_modes).save(stl_folder / "solid.npz")
        text, source = '[blade]\nmodal_file = "solid.npz"\n', '[blade] modal_file = "solid.npz", its OR face at 35 deg'
    elif blade == "surface_file":
        text, source = _surface_text(), '[blade] surface_file = "blade.stl", its OR face at 35 deg'
    else:
        text = f'[blade]\nmodel = "solid"\nsolid_element_size_mm = {SURFACE_ELEMENT_SIZE_MM}\n'
        source = '[blade] model = "solid", meshed at [disk] gamma_right_deg = 35'
    path = _write(stl_folder, text)
    out = stl_folder / "out"
    t0 = time.perf_counter()
    assert main(["optimize", str(path), "--gamma-right-deg", "30", "40", "--out", str(out)]) == 2
    assert time.perf_counter() - t0 < 30                      # reading the design (meshing a solid) only
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert err.startswith("bladedamp optimize: error: --gamma-right-deg: a solid FE blade's platform angles come "
                          f"from its geometry ({path}: {source})"), err
    assert "remove --gamma-right-deg" in err
    assert not out.exists()
