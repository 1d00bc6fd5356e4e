"""Meshes of blade, dampers and disk (trimesh), and contact patches derived from them."""
import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from bladedamp import geometry as G  # noqa: E402
from bladedamp.blade import reference_blade_geometry  # noqa: E402
from bladedamp.damper.geometry import contact_normal  # noqa: E402
from bladedamp.reference import reference_disk  # noqa: E402

DEG = np.pi / 180


@pytest.fixture(scope="module")
def wedge_disk():
    return reference_disk("wedge", 0.3e-3)


@pytest.fixture(scope="module")
def cylinder_disk():
    return reference_disk("cylinder", 1e-3)


def test_meshes_are_closed_solids(wedge_disk):
    parts = G.sector_meshes(None, wedge_disk.damper, wedge_disk.gamma_left, wedge_disk.gamma_right)
    bm = parts["blade_mesh"]
    for mesh in [bm.root, bm.platform, parts["damper"]] + [m for m, _ in bm.segments]:
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    g = reference_blade_geometry()
    assert len(bm.segments) == g.n_elements_shank + g.n_elements_airfoil
    assert np.isclose(parts["blade"].bounds[1, 2], g.total_length)
    # the wedge mesh is the damper's own section: volume = section area x length
    section = wedge_disk.damper_geometry().section
    x, z = section[:, 0], section[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1)))
    assert np.isclose(G.wedge_mesh(wedge_disk.damper, wedge_disk.gamma_left, wedge_disk.gamma_right).volume,
                      area * wedge_disk.damper.length, rtol=1e-12)


@pytest.mark.parametrize("angles_deg", [(35, 35), (35, 55)])
@pytest.mark.parametrize("kind", ["wedge", "cylinder"])
def test_sector_layout_matches_the_contact_model(kind, angles_deg):
    disk = reference_disk(kind, 1e-3)
    disk.gamma_left, disk.gamma_right = angles_deg[0] * DEG, angles_deg[1] * DEG
    layout = G.sector_layout(disk.blade.points, disk.damper, disk.gamma_left, disk.gamma_right)
    np.testing.assert_allclose(layout.platform_offsets, disk.platform_offsets(disk.damper_geometry()), atol=1e-15)
    # the damper's contact centres lie on blade i's OL and blade i+1's OR contact centres
    own = layout.own_contact_centres(disk.blade.points)
    np.testing.assert_allclose(layout.contact_centres[0], own[0], atol=1e-15)
    np.testing.assert_allclose(layout.contact_centres[1], own[1] - [layout.pitch, 0, 0], atol=1e-15)


@pytest.mark.parametrize("angles_deg", [(35, 35), (30, 50)])
def test_nominal_wedge_patch_is_the_analytic_rectangle(wedge_disk, angles_deg):
    gl, gr = angles_deg[0] * DEG, angles_deg[1] * DEG
    damper = wedge_disk.damper
    patches = G.derive_patches(damper=damper, gamma_left=gl, gamma_right=gr, tolerance=1e-9)
    analytic = damper.geometry(gl, gr).patches
    for derived, ref in zip(patches, analytic):
        assert derived.height == pytest.approx(damper.contact_height, abs=1e-9)
        assert derived.length == pytest.approx(damper.length, abs=1e-9)
        np.testing.assert_allclose(derived.centre_offset, 0.0, atol=1e-9)
        assert (derived.n_xi, derived.n_eta) == (ref.n_xi, ref.n_eta)
        np.testing.assert_allclose(derived.xi, ref.xi, atol=1e-9)
        np.testing.assert_allclose(derived.eta, ref.eta, atol=1e-9)
        np.testing.assert_allclose(derived.gap, 0.0, atol=1e-12)


@pytest.mark.parametrize("kind", ["wedge", "cylinder"])
def test_point_normals_equal_the_platform_normal(kind):
    disk = reference_disk(kind, 1e-3)
    for c, (side, gamma) in enumerate((("OL", disk.gamma_left), ("OR", disk.gamma_right))):
        patch = G.derive_patches(disk)[c]
        n = contact_normal(side, gamma)
        np.testing.assert_allclose(patch.normal, np.broadcast_to(n, patch.normal.shape), atol=1e-12)
        np.testing.assert_allclose(patch.frame[2], n, atol=1e-15)


def test_misfitting_wedge_touches_along_one_edge(wedge_disk):
    """Wedge face angle 1 deg off at OL: after a rigid drop into the groove the OL face touches the
    platform along one edge only, the gap opening linearly (slope tan 1 deg) across the face; the
    OR face (angle right) still touches over all of h_C x l_C."""
    d = wedge_disk.damper
    bad = G.wedge_mesh(d, wedge_disk.gamma_left + 1 * DEG, wedge_disk.gamma_right)
    tol = 1e-6
    ol, orr = G.derive_patches(wedge_disk, damper_shape=bad, seat=True, tolerance=tol)
    h = d.contact_height
    # OL: a band of width tol / tan(1 deg) at one edge of the face, over the whole length
    assert ol.height == pytest.approx(tol / np.tan(1 * DEG), rel=0.02)
    assert ol.height < 0.05 * h
    assert max(abs(ol.xi_range[0]), abs(ol.xi_range[1])) == pytest.approx(h / 2, abs=1e-8)
    assert ol.length == pytest.approx(d.length, abs=1e-9)
    assert orr.height == pytest.approx(h, abs=1e-8)
    np.testing.assert_allclose(orr.gap, 0.0, atol=1e-12)
    # with a capture tolerance larger than the misfit, the whole face with its initial gaps
    ol, _ = G.derive_patches(wedge_disk, damper_shape=bad, seat=True, tolerance=1e-4)
    gaps = ol.gap.reshape(ol.n_xi, ol.n_eta)
    xi = ol.xi.reshape(ol.n_xi, ol.n_eta)[:, 0]
    assert np.allclose(gaps, gaps[:, :1], atol=1e-12)            # uniform along the length
    slope = np.polyfit(xi, gaps[:, 0], 1)[0]
    assert abs(slope) == pytest.approx(np.tan(1 * DEG), rel=1e-6)
    edge_gap = np.polyval(np.polyfit(xi, gaps[:, 0], 1), ol.xi_range[int(slope < 0)])
    assert abs(edge_gap) < 1e-10                                 # touches at one edge ...
    assert gaps.max() > 0.8 * h * np.tan(1 * DEG)                # ... and is open at the other


def test_cylinder_gives_a_line_contact(cylinder_disk):
    d = cylinder_disk.damper
    for tol in (1e-7, 1e-6):
        for patch in G.derive_patches(cylinder_disk, tolerance=tol):
            assert patch.n_xi == 1 and patch.n_eta == d.contact.points_along_length
            assert patch.length == pytest.approx(d.length, abs=1e-9)
            assert patch.height < 0.01 * d.length                     # a line, not an area
            assert patch.height < 0.2 * d.radius
            assert np.all(np.abs(patch.gap) <= tol)
            np.testing.assert_allclose(patch.eta, d.geometry(cylinder_disk.gamma_left,
                                                             cylinder_disk.gamma_right).patches[0].eta, atol=1e-9)


def test_no_contact_is_reported(cylinder_disk):
    mesh = G.damper_mesh(cylinder_disk.damper, cylinder_disk.gamma_left, cylinder_disk.gamma_right)
    mesh.apply_translation([0, 0, -1e-3])         # 1 mm below its seat: open on both sides
    with pytest.raises(ValueError, match="no contact"):
        G.derive_patches(cylinder_disk, damper_shape=mesh, tolerance=1e-6)


def test_disk_placements_wrap_the_sector(cylinder_disk):
    layout = G.sector_layout(cylinder_disk.blade.points, cylinder_disk.damper, cylinder_disk.gamma_left,
                             cylinder_disk.gamma_right)
    n = cylinder_disk.n_blades
    B, D, ks, r_root = G.disk_placements(layout, n, cylinder_disk.blade.points)
    assert B.shape == (n, 4, 4) and D.shape == (n, 4, 4) and r_root > 0
    axis = np.array([0, 0, -r_root])
    cg = layout.damper_cg
    # the chord between neighbouring blades at the damper CG's radius is the unrolled pitch
    rho = cg[2] + r_root
    assert 2 * rho * np.sin(np.pi / n) == pytest.approx(layout.pitch, rel=1e-12)
    for k in range(n):
        # blade k: rotation by -2 pi k / n about the axis (blade k+1 at -x)
        tip = B[k, :3, :3] @ [0, 0, 0.2] + B[k, :3, 3]
        angle = np.arctan2(tip[0] - axis[0], tip[2] - axis[2])
        assert np.isclose((angle + 2 * np.pi * k / n + np.pi) % (2 * np.pi) - np.pi, 0.0, atol=1e-12)
        # damper CG at its radius from the axis
        assert np.linalg.norm(D[k, :3, 3] - axis) == pytest.approx(np.hypot(cg[0], cg[2] + r_root), rel=1e-12)


def test_homogeneous_transform_rotates_then_translates():
    from bladedamp.geometry import homogeneous, rotation_y
    R, t = rotation_y(0.3), np.array([1.0, -2.0, 0.5])
    T = homogeneous(R, t)
    x = np.array([0.2, 0.1, -0.4])
    np.testing.assert_allclose(T @ np.r_[x, 1.0], np.r_[R @ x + t, 1.0], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(homogeneous(), np.eye(4))
