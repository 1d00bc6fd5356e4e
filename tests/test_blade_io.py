"""Blade data from FE: modal data files (npz, CSV) and reduced FE matrices (ModalBlade.from_matrices)."""
import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse

import bladedamp
from bladedamp.blade import MODAL_CSV_COLUMNS, ModalBlade, assemble_beam, beam_modes
from bladedamp.reference import reference_blade, reference_blade_geometry


def assert_same_blade(a: ModalBlade, b: ModalBlade, rtol=0.0, atol=0.0):
    np.testing.assert_allclose(a.natural_frequencies_hz, b.natural_frequencies_hz, rtol=rtol)
    np.testing.assert_allclose(a.damping_ratios, b.damping_ratios, rtol=rtol)
    assert a.mode_names == b.mode_names
    assert list(a.points) == list(b.points)
    for p in a.points:
        np.testing.assert_allclose(a.points[p], b.points[p], rtol=rtol, atol=atol)
        np.testing.assert_allclose(a.mode_shapes[p], b.mode_shapes[p], rtol=rtol, atol=atol)


# ---------------------------------------------------------------------------------------
# files: round trips
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", ["npz", "csv", "CSV", "NPZ"])
def test_reference_blade_round_trips_exactly(tmp_path, suffix):
    blade = reference_blade()
    path = blade.save(tmp_path / f"blade.{suffix}")
    assert path.is_file()
    assert_same_blade(ModalBlade.from_file(path), blade)          # bit for bit, extra point "platform" kept


def test_npz_loads_without_pickle(tmp_path):
    path = reference_blade().save(tmp_path / "blade.npz")
    with np.load(path, allow_pickle=False) as data:
        assert data["mode_shapes"].shape == (5, 6, 4)              # (points, DOF, modes)
        assert list(data["point_names"]) == ["OL", "OR", "platform", "tip", "excitation"]
    assert_same_blade(bladedamp.load(path), reference_blade())     # the generic loader reads blades too


@pytest.mark.filterwarnings("ignore::bladedamp.hbm.accuracy.AccuracyWarning")
def test_saved_and_read_blade_gives_the_same_disk_frf(tmp_path):
    disk = bladedamp.reference_disk("cylinder", 1e-3)
    direct = disk.frequency_response(93.0, 97.0, harmonics=(1,))
    assert direct.success
    for suffix in ("npz", "csv"):
        blade = ModalBlade.from_file(disk.blade.save(tmp_path / f"b.{suffix}"))
        again = dataclasses.replace(disk, blade=blade).frequency_response(93.0, 97.0, harmonics=(1,))
        assert again.success
        np.testing.assert_allclose(again.omega, direct.omega, rtol=1e-12)
        np.testing.assert_allclose(again.coefficients, direct.coefficients, rtol=1e-9,
                                   atol=1e-12 * np.abs(direct.coefficients).max())


def test_hand_written_csv_with_comments_any_column_order_and_no_mode_names(tmp_path):
    rows = ["# my blade, units as in bladedamp.blade", "",
            "point,mode,frequency_hz,damping_ratio,x,y,z,ux,uy,uz,phix,phiy,phiz"]
    pos = {"OL": (-0.01, 0, 0.05), "OR": (0.01, 0, 0.05), "tip": (0, 0, 0.2), "excitation": (0, 0, 0.2)}
    for mode, f in ((1, 100.0), (2, 400.0)):
        for p, xyz in pos.items():
            shape = [mode * 1.0, 0, 0, 0, 2.0 * mode, 0] if p != "OL" else [0.5, 0, 0.1, 0, 3.0, -1e-3]
            rows.append(",".join([p, str(mode), repr(f), " 0.002 "] + [str(v) for v in xyz] + [str(v) for v in shape]))
    path = tmp_path / "hand.csv"
    path.write_text("\n".join(rows) + "\n")
    blade = ModalBlade.from_file(path)
    np.testing.assert_array_equal(blade.natural_frequencies_hz, [100.0, 400.0])
    np.testing.assert_array_equal(blade.damping_ratios, [0.002, 0.002])
    assert blade.mode_names == ()
    np.testing.assert_array_equal(blade.shape("tip")[:, 1], [2, 0, 0, 0, 4, 0])
    np.testing.assert_array_equal(blade.shape("OL")[:, 0], [0.5, 0, 0.1, 0, 3.0, -1e-3])
    np.testing.assert_array_equal(blade.points["OR"], [0.01, 0, 0.05])


# ---------------------------------------------------------------------------------------
# files: bad files name the file, the key or column and what was expected
# ---------------------------------------------------------------------------------------
def reference_csv_lines(tmp_path):
    path = reference_blade().save(tmp_path / "good.csv")
    return path.read_text().splitlines()


def write(tmp_path, lines, name="bad.csv"):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def header_index(lines):
    return next(i for i, line in enumerate(lines) if line.startswith("mode,"))


def replace_cell(line, column, value):
    cells = line.split(",")
    cells[MODAL_CSV_COLUMNS.index(column)] = value
    return ",".join(cells)


@pytest.mark.parametrize("edit, expected", [
    (lambda L, h: L[:h] + [L[h].replace(",phiz", "")] + [r.rsplit(",", 1)[0] for r in L[h + 1:]],
     r"line \d+ \(header\).*missing: \['phiz'\]"),
    (lambda L, h: L[:h] + [L[h].replace("ux,", "u_x,")] + L[h + 1:], r"unknown: \['u_x'\]"),
    (lambda L, h: L[:h] + [L[h].replace(",", ";")] + [r.replace(",", ";") for r in L[h + 1:]],
     "separated by commas"),
    (lambda L, h: L[:h + 1] + [replace_cell(L[h + 1], "uy", "abc")] + L[h + 2:],
     r"line \d+: column 'uy' must be a finite number \[m/sqrt\(kg\)\] \(got 'abc'\)"),
    (lambda L, h: L[:h + 1] + [replace_cell(L[h + 1], "frequency_hz", "nan")] + L[h + 2:],
     r"column 'frequency_hz' must be a finite number \[Hz\]"),
    (lambda L, h: L[:h + 1] + [replace_cell(L[h + 1], "frequency_hz", "96.0")] + L[h + 2:],
     "the same on every row of a mode"),
    (lambda L, h: L[:h + 1] + [replace_cell(L[h + 1], "mode", "0")] + L[h + 2:],
     "column 'mode' must be a mode number"),
    (lambda L, h: L[:h + 1] + [replace_cell(L[h + 1], "x", "-0.013")] + L[h + 2:],
     "a point has one position"),
    (lambda L, h: L[:h + 1] + L[h + 2:], r"no row for \(mode, point\) \[\(1, 'OL'\)\]"),
    (lambda L, h: L + [L[h + 1]], "given twice"),
    (lambda L, h: [r for r in L if not r.startswith("2,")], r"without gaps \(missing \[2\]\)"),
    (lambda L, h: L[:h + 1] + [L[h + 1] + ",1.0"] + L[h + 2:], "expected 14 comma-separated values"),
    (lambda L, h: [r for r in L if ",tip," not in r], r"required points .*missing: \['tip'\]"),
    (lambda L, h: L[:h + 1] + [replace_cell(r, "damping_ratio", "-0.001") if r.startswith("1,") else r
                               for r in L[h + 1:]], r"damping_ratios must be in \[0, inf\)"),
    (lambda L, h: L[:h + 1], "no data rows"),
    (lambda L, h: L[:h], "no header line"),
])
def test_bad_csv_names_file_line_column_and_what_was_expected(tmp_path, edit, expected):
    lines = reference_csv_lines(tmp_path)
    path = write(tmp_path, edit(lines, header_index(lines)))
    with pytest.raises(ValueError, match=expected) as info:
        ModalBlade.from_file(path)
    assert str(path) in str(info.value)


def npz_fields(tmp_path):
    with np.load(reference_blade().save(tmp_path / "good.npz")) as data:
        return {k: data[k] for k in data.files}


@pytest.mark.parametrize("edit, expected", [
    (lambda d: d.pop("mode_shapes"), r"missing: \['mode_shapes'\]"),
    (lambda d: d.update(shapes=d["mode_shapes"]), r"unknown: \['shapes'\]"),
    (lambda d: d.update(mode_shapes=d["mode_shapes"][:, :3]), r"key 'mode_shapes' must have shape \(5, 6, 4\)"),
    (lambda d: d.update(point_positions=d["point_positions"][:, :2]), r"key 'point_positions' must have shape \(5, 3\)"),
    (lambda d: d.update(damping_ratios=np.zeros(3)), r"key 'damping_ratios' must have shape \(4,\)"),
    (lambda d: d.update(natural_frequencies_hz=np.array(["a", "b", "c", "d"])), "key 'natural_frequencies_hz' must hold numbers"),
    (lambda d: d.update(point_names=np.array(["OL", "OR", "OL", "tip", "excitation"])), "must not repeat a name"),
    (lambda d: d.update(format=np.array("something else")), "key 'format' must be 'bladedamp.ModalBlade/1'"),
    (lambda d: d.update(point_names=np.array(["OL", "OR", "platform", "top", "excitation"])),
     r"missing: \['tip'\]"),
])
def test_bad_npz_names_file_key_and_what_was_expected(tmp_path, edit, expected):
    fields = npz_fields(tmp_path)
    edit(fields)
    path = tmp_path / "bad.npz"
    np.savez(path, **fields)
    with pytest.raises(ValueError, match=expected) as info:
        ModalBlade.from_file(path)
    assert str(path) in str(info.value)


def test_object_array_in_npz_is_refused_without_pickle(tmp_path):
    fields = npz_fields(tmp_path)
    fields["point_names"] = np.array(["OL", "OR", "platform", "tip", "excitation"], dtype=object)
    path = tmp_path / "pickled.npz"
    np.savez(path, **fields)
    with pytest.raises(ValueError, match="key 'point_names' must be a plain string array"):
        ModalBlade.from_file(path)


def test_file_suffix_and_existence(tmp_path):
    with pytest.raises(ValueError, match=r"must end in .npz or .csv \(got '.txt'\)"):
        reference_blade().save(tmp_path / "blade.txt")
    with pytest.raises(ValueError, match=r"must end in .npz or .csv"):
        ModalBlade.from_file(tmp_path / "blade")
    with pytest.raises(FileNotFoundError, match="no such modal data file"):
        ModalBlade.from_file(tmp_path / "absent.csv")
    garbage = tmp_path / "garbage.npz"
    garbage.write_text("not a zip")
    with pytest.raises(ValueError, match="garbage.npz: not a readable .npz file"):
        ModalBlade.from_file(garbage)


# ---------------------------------------------------------------------------------------
# from_matrices on the beam model's own FE matrices
# ---------------------------------------------------------------------------------------
def beam_dof_map(modes, offset=6):
    """dof_map of the platform and tip nodes: offset 6 for the clamped matrices of beam_modes
    (root DOF removed), 0 for the full matrices of assemble_beam."""
    def node(n):
        return list(range(6 * n - offset, 6 * n - offset + 6))
    tip = modes.n_nodes - 1
    return {"platform": node(modes.platform_node), "tip": node(tip), "excitation": node(tip)}


LINKS = {"OL": "platform", "OR": "platform"}


def matched_up_to_sign(blade, expected):
    """Largest relative difference of the point shapes after flipping each mode's sign to match."""
    worst = 0.0
    for j in range(expected.n_modes):
        a = np.concatenate([blade.mode_shapes[p][:, j] for p in expected.points])
        b = np.concatenate([expected.mode_shapes[p][:, j] for p in expected.points])
        s = np.sign(a @ b)
        worst = max(worst, np.abs(s * a - b).max() / np.abs(b).max())
    return worst


@pytest.mark.parametrize("solver, to_matrix", [("dense", np.asarray), ("sparse", scipy.sparse.csr_matrix),
                                               ("auto", scipy.sparse.csc_matrix)])
def test_from_matrices_reproduces_from_beam(solver, to_matrix):
    g = reference_blade_geometry()
    modes = beam_modes(g)
    expected = ModalBlade.from_beam(g, n_modes=6)              # the 6 lowest, by frequency
    blade = ModalBlade.from_matrices(to_matrix(modes.mass), to_matrix(modes.stiffness), beam_dof_map(modes),
                                     points=g.points(), n_modes=6, damping_ratios=0.001, rigid_links=LINKS,
                                     mode_names=expected.mode_names, solver=solver)
    np.testing.assert_allclose(blade.natural_frequencies_hz, expected.natural_frequencies_hz, rtol=1e-8)
    assert matched_up_to_sign(blade, expected) < 1e-8
    assert blade.mode_names == expected.mode_names
    assert list(blade.points) == list(expected.points)
    # the signs follow the stated rule: the tip's largest translation (1F, 2F, 1E) or rotation (1T) > 0
    tip = blade.shape("tip")
    for j in range(6):
        part = tip[:3, j] if np.abs(tip[:3, j]).max() > 1e-6 * np.abs(tip[:3]).max() else tip[3:, j]
        assert part[np.argmax(np.abs(part))] > 0


def test_from_matrices_reproduces_the_refined_beam_with_its_warping_dof():
    """The beam of the solid's geometry (platform block, Timoshenko, Vlasov: 7 DOF per node, the
    rates of twist after the 6 n_nodes node DOF): its clamped matrices keep node n's DOF at
    6 n - 6 ... 6 n - 1, so the same dof_map reproduces from_beam."""
    from bladedamp.blade import solid_platform_beam
    g = solid_platform_beam()
    modes = beam_modes(g)
    assert modes.n_dofs == 7 * modes.n_nodes and modes.stiffness.shape[0] == modes.n_dofs - 7 - 2  # root, 2 tied
    expected = ModalBlade.from_beam(g, n_modes=6)
    blade = ModalBlade.from_matrices(modes.mass, modes.stiffness, beam_dof_map(modes), points=g.points(), n_modes=6,
                                     damping_ratios=0.001, rigid_links=LINKS, mode_names=expected.mode_names)
    np.testing.assert_allclose(blade.natural_frequencies_hz, expected.natural_frequencies_hz, rtol=1e-8)
    assert matched_up_to_sign(blade, expected) < 1e-8


def test_from_matrices_keeps_per_mode_damping_and_refines_nothing_else():
    g = reference_blade_geometry()
    modes = beam_modes(g)
    blade = ModalBlade.from_matrices(modes.mass, modes.stiffness, beam_dof_map(modes), points=g.points(),
                                     n_modes=4, damping_ratios=(0.001, 0.002, 0.003, 0.004), rigid_links=LINKS)
    np.testing.assert_array_equal(blade.damping_ratios, [0.001, 0.002, 0.003, 0.004])
    np.testing.assert_allclose(blade.natural_frequencies_hz, modes.frequencies_hz[:4], rtol=1e-8)


def test_unclamped_matrices_are_refused_and_fixed_dofs_clamp_the_root():
    g = reference_blade_geometry()
    modes = beam_modes(g)
    _, _, K_full, M_full = assemble_beam(g)
    dof_map = beam_dof_map(modes, offset=0)                    # full numbering, root node 0 included
    for solver in ("dense", "sparse"):
        with pytest.raises(ValueError, match=r"have 6 rigid-body .* among the 8 lowest.* pass the root DOF as fixed_dofs"):
            ModalBlade.from_matrices(M_full, K_full, dof_map, points=g.points(), n_modes=8,
                                     damping_ratios=0.001, rigid_links=LINKS, solver=solver)
    clamped = ModalBlade.from_matrices(M_full, K_full, dof_map, points=g.points(), n_modes=6,
                                       damping_ratios=0.001, rigid_links=LINKS, fixed_dofs=range(6))
    expected = ModalBlade.from_beam(g, n_modes=6)
    np.testing.assert_allclose(clamped.natural_frequencies_hz, expected.natural_frequencies_hz, rtol=1e-8)
    assert matched_up_to_sign(clamped, expected) < 1e-8


def test_translation_only_points_get_zero_rotations():
    g = reference_blade_geometry()
    modes = beam_modes(g)
    dof_map = beam_dof_map(modes)
    full = ModalBlade.from_matrices(modes.mass, modes.stiffness, dof_map, points=g.points(), n_modes=4,
                                    damping_ratios=0.001, rigid_links=LINKS)
    blade = ModalBlade.from_matrices(modes.mass, modes.stiffness, dict(dof_map, tip=dof_map["tip"][:3]),
                                     points=g.points(), n_modes=4, damping_ratios=0.001, rigid_links=LINKS)
    np.testing.assert_array_equal(blade.shape("tip")[3:], 0.0)
    np.testing.assert_allclose(np.abs(blade.shape("tip")[:3]), np.abs(full.shape("tip")[:3]), rtol=1e-12)
    with pytest.warns(UserWarning, match=r"dof_map\['OL'\] has translations only"):
        ModalBlade.from_matrices(modes.mass, modes.stiffness, dict(dof_map, OL=dof_map["platform"][:3]),
                                 points=g.points(), n_modes=2, damping_ratios=0.001,
                                 rigid_links={"OR": "platform"})


def small_matrices():
    """Two masses on a clamped spring chain, every DOF d of a node with its own stiffness scale
    (d + 1): distinct frequencies omega^2 = (d + 1) * 1e6 * (2 -+ sqrt(2)). OL, OR on node 0,
    tip and excitation on node 1."""
    K = 1e6 * np.array([[2.0, -1.0], [-1.0, 1.0]])
    M = np.diag([1.0, 0.5])
    K6, M6 = np.kron(K, np.diag(np.arange(1.0, 7.0))), np.kron(M, np.eye(6))
    dof_map = {"OL": range(0, 6), "OR": range(0, 6), "tip": range(6, 12), "excitation": range(6, 12)}
    points = {"OL": (-0.01, 0, 0.05), "OR": (0.01, 0, 0.05), "tip": (0, 0, 0.2), "excitation": (0, 0, 0.2)}
    return M6, K6, dof_map, points


def test_small_chain_matches_its_closed_form_and_is_mass_normalised():
    M, K, dof_map, points = small_matrices()
    blade = ModalBlade.from_matrices(M, K, dof_map, points=points, n_modes=3, damping_ratios=0.01)
    lam = 1e6 * (2 - np.sqrt(2)) * np.array([1.0, 2.0, 3.0])          # ux, uy, uz of the lower chain mode
    np.testing.assert_allclose(blade.natural_frequencies_hz, np.sqrt(lam) / (2 * np.pi), rtol=1e-12)
    V = np.vstack([blade.shape("OL"), blade.shape("tip")])            # every DOF is a point DOF here
    np.testing.assert_allclose(V.T @ M @ V, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(V.T @ K @ V, np.diag(lam), rtol=1e-12, atol=1e-6)
    assert np.all(np.diag(blade.shape("tip")[:3]) > 0)                # sign rule: tip translation > 0


def test_large_sparse_chain_uses_shift_invert_and_matches_its_closed_form():
    """Fixed-free chain of N equal masses m and springs k, each of the 6 DOF of a node with its
    own stiffness scale s = 1..6: omega^2 = s 4 k / m sin^2((2 j - 1) pi / (2 (2 N + 1)))."""
    N, k, m = 100, 1e6, 0.01
    chain = scipy.sparse.diags([-np.ones(N - 1), np.r_[2 * np.ones(N - 1), 1.0], -np.ones(N - 1)], [-1, 0, 1]) * k
    K = scipy.sparse.kron(chain, scipy.sparse.diags(np.arange(1.0, 7.0))).tocsr()
    M = scipy.sparse.eye(6 * N, format="csr") * m
    tip = range(6 * N - 6, 6 * N)
    dof_map = {"OL": range(6), "OR": range(6), "tip": tip, "excitation": tip}
    points = {"OL": (-0.01, 0, 0.0), "OR": (0.01, 0, 0.0), "tip": (0, 0, 1.0), "excitation": (0, 0, 1.0)}
    blade = ModalBlade.from_matrices(M, K, dof_map, points=points, n_modes=8, damping_ratios=0.001)
    j = np.arange(1, N + 1)
    lam = np.sort(np.outer(np.arange(1.0, 7.0), 4 * k / m * np.sin((2 * j - 1) * np.pi / (2 * (2 * N + 1))) ** 2).ravel())
    np.testing.assert_allclose(blade.natural_frequencies_hz, np.sqrt(lam[:8]) / (2 * np.pi), rtol=1e-10)
    assert 6 * N > bladedamp.blade.DENSE_SOLVER_MAX_DOF                 # "auto" took the sparse path


@pytest.mark.parametrize("change, expected", [
    (dict(stiffness=lambda K: K + np.triu(np.full(K.shape, 1.0), 1)), "stiffness must be symmetric"),
    (dict(mass=lambda M: M[:6, :6]), r"stiffness must have the shape of mass \(6, 6\)"),
    (dict(mass=lambda M: M - np.diag(np.r_[np.ones(6), np.zeros(6)])), r"mass must be positive definite .* M\[0, 0\] = 0"),
    (dict(mass=lambda M: M + 5 * np.kron([[0, 1], [1, 0]], np.eye(6))), "mass must be positive definite"),
    (dict(stiffness=lambda K: -K), "stiffness must be positive semi-definite"),
    (dict(stiffness=lambda K: K * np.nan), "stiffness must be finite"),
    (dict(mass=lambda M: np.ones(5)), r"mass must be a square \(n, n\) matrix"),
    (dict(dof_map=lambda d: dict(d, tip=range(6, 10))), r"dof_map\['tip'\] must list 6 DOF indices .* or 3"),
    (dict(dof_map=lambda d: dict(d, tip=range(8, 14))), r"dof_map\['tip'\] must hold DOF indices in \[0, 11\]"),
    (dict(dof_map=lambda d: {k: v for k, v in d.items() if k != "excitation"},
          points=lambda p: {k: v for k, v in p.items() if k != "excitation"}), r"required points .*missing: \['excitation'\]"),
    (dict(points=lambda p: {k: v for k, v in p.items() if k != "OL"}), r"points must give .*missing: \['OL'\]"),
    (dict(n_modes=13), r"n_modes must be an integer in \[1, 12\]"),
    (dict(solver="eigs"), "solver must be 'auto', 'dense' or 'sparse'"),
    (dict(rigid_links={"OL": "hub"}), "point 'OL' is in both dof_map and rigid_links"),
    (dict(fixed_dofs=[0, 0]), "fixed_dofs must not repeat an index"),
    (dict(fixed_dofs=[12]), r"fixed_dofs must hold DOF indices in \[0, 11\]"),
    (dict(damping_ratios=-0.1), r"damping_ratios must be in \[0, inf\)"),
    (dict(damping_ratios=(0.01, 0.01, 0.01)), r"damping_ratios must be a scalar or have shape \(2,\)"),
    (dict(mode_names=("1F",)), "mode_names must be empty or have n_modes = 2 entries"),
    (dict(points=lambda p: dict(p, tip=(0, 0))), r"points\['tip'\] must be a \(3,\) position \[m\]"),
])
def test_from_matrices_errors_name_the_parameter(change, expected):
    M, K, dof_map, points = small_matrices()
    args = dict(mass=M, stiffness=K, dof_map=dof_map, points=points, n_modes=2, damping_ratios=0.01)
    for key, value in change.items():
        args[key] = value(args[key]) if callable(value) else value
    with pytest.raises(ValueError, match=expected):
        ModalBlade.from_matrices(args.pop("mass"), args.pop("stiffness"), args.pop("dof_map"), **args)


def test_rigid_link_needs_a_six_dof_master():
    M, K, dof_map, points = small_matrices()
    dof_map = dict(dof_map, hub=[6, 7, 8])
    dof_map.pop("OL")
    with pytest.raises(ValueError, match=r"rigid_links\['OL'\] must name a point of dof_map with 6 DOF"):
        ModalBlade.from_matrices(M, K, dof_map, points=dict(points, hub=(0, 0, 0.1)), n_modes=2,
                                 damping_ratios=0.01, rigid_links={"OL": "hub"})


# ---------------------------------------------------------------------------------------
# the calibration lives in bladedamp.reference; the old names still work
# ---------------------------------------------------------------------------------------
def test_reference_blade_is_importable_from_blade_and_the_package():
    import bladedamp.blade as blade_module
    import bladedamp.reference as reference
    assert blade_module.reference_blade is reference.reference_blade is bladedamp.reference_blade
    assert blade_module.reference_blade_geometry is reference.reference_blade_geometry
    assert blade_module.TABLE1_FREQUENCIES_HZ == reference.TABLE1_FREQUENCIES_HZ == (95.0, 423.0, 783.0, 1065.0)
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        blade_module.no_such_name  # noqa: B018


def test_no_warning_for_six_dof_contact_points():
    M, K, dof_map, points = small_matrices()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ModalBlade.from_matrices(M, K, dof_map, points=points, n_modes=2, damping_ratios=0.01)


# ---------------------------------------------------------------------------------------
# blade files saved by earlier versions (tests/data/blades, README there) still load
# ---------------------------------------------------------------------------------------
BLADE_DATA = Path(__file__).parent / "data" / "blades"


@pytest.mark.parametrize("name", ["reference_blade_v1.npz", "reference_blade_v1.csv"])
def test_reference_blade_files_saved_before_the_blade_package_load(name):
    """Files written by ``reference_blade().save`` before the blade package (format
    bladedamp.ModalBlade/1, and the CSV) give today's reference blade (computed again by the beam
    model: the same numbers to rounding), through ModalBlade.from_file and bladedamp.load."""
    path = BLADE_DATA / name
    readers = [ModalBlade.from_file] + ([bladedamp.load] if name.endswith(".npz") else [])
    for read in readers:
        blade = read(path)
        assert type(blade) is ModalBlade
        # the beam model's eigenvectors differ between LAPACK builds: significant entries by 1e-9
        # of their value, entries that are zero by symmetry (a flapwise mode's torsion) by noise
        # up to 5e-8 of the shapes' largest (seen: 1e-8 on one machine, 5e-8 on another); a bound
        # of 1e-6 of the largest leaves them a factor 20 and still catches a wrong shape
        assert_same_blade(blade, reference_blade(), rtol=1e-9, atol=1e-6 * np.abs(blade.mode_shapes["tip"]).max())


def test_solid_blade_file_saved_before_the_blade_package_loads():
    """A solid FE blade saved before the blade package (format bladedamp.SolidModalBlade/2, the
    reference solid at 12 mm, 4 modes) is read back as a solid blade with flexible platforms that
    matches the same blade computed again: frequencies, rigid-point shapes and the FE field at
    the contact faces."""
    pytest.importorskip("gmsh")
    pytest.importorskip("skfem")
    from bladedamp import solid

    path = BLADE_DATA / "solid_blade_v2.npz"
    fresh = solid.solid_blade(None, 12e-3, 4)
    for read in (ModalBlade.from_file, bladedamp.load):
        blade = read(path)
        assert isinstance(blade, solid.SolidModalBlade) and blade.flexible_platform
        scale = np.abs(fresh.mode_shapes["tip"]).max()
        assert_same_blade(blade, fresh, rtol=1e-6, atol=1e-6 * scale)
        for side in ("OL", "OR"):
            points = fresh.contact_faces[side].points[::7]                 # (P, 3) samples on the face
            np.testing.assert_allclose(blade.platform_displacements(side, points),
                                       fresh.platform_displacements(side, points), rtol=1e-6, atol=1e-6 * scale)


def test_a_blade_file_names_its_class_as_every_saved_result_and_untagged_files_still_read(tmp_path):
    """One save/load for results and blades: ``blade.save`` writes the bladedamp entry naming the
    class (read back by bladedamp.load and ModalBlade.from_file); a modal .npz without it and
    without a format (written by hand) is a ModalBlade for from_file, not a result for load; a
    saved result is not a blade (WrongKindError, a ValueError, naming the file)."""
    import json

    from bladedamp.io import META_KEY, WrongKindError

    path = reference_blade().save(tmp_path / "blade.npz")
    with np.load(path, allow_pickle=False) as data:
        meta = json.loads(str(data[META_KEY]))
        arrays = {k: data[k] for k in data.files if k not in (META_KEY, "format")}
    assert meta["class"] == f"{ModalBlade.__module__}:ModalBlade" and meta["layout"] == "arrays"
    hand = tmp_path / "hand.npz"
    np.savez(hand, **arrays)
    assert_same_blade(ModalBlade.from_file(hand), reference_blade())
    with pytest.raises(ValueError, match="hand.npz is not a saved bladedamp result"):
        bladedamp.load(hand)
    result = BLADE_DATA.parent / "oscillator_response_v1.npz"
    with pytest.raises(WrongKindError, match="oscillator_response_v1.npz: holds a FrequencyResponse, not a ModalBlade"):
        ModalBlade.from_file(result)
