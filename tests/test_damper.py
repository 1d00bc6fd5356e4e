"""Damper geometry and kinetics (paper: Contact Kinematics Eq. 6-9, Damper Kinetics Eq. 12, Eq. 26).

Every reference value is built here from the physics, not read from the code under test:
point kinematics of rigid bodies written with cross products, the frictionless equilibrium of
a body between two inclined planes, the mass properties of a solid cylinder and of a uniform
triangular prism by direct integration on a grid, Eq. 26 by hand.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from bladedamp.damper import (ContactProperties, CylinderDamper, WedgeDamper, centrifugal_force, retention_stiffness,
                              seat)
from bladedamp.reference import reference_damper, reference_disk

# (gamma_L, gamma_R) [deg]: symmetric (the paper's reference), and asymmetric both ways
ANGLES = [(35.0, 35.0), (35.0, 55.0), (60.0, 20.0), (35.0, 85.0)]
KINDS = ["cylinder", "wedge"]


def disk_with_angles(kind, left_deg, right_deg, mass=1e-3):
    return dataclasses.replace(reference_disk(kind, mass), gamma_left=np.radians(left_deg),
                               gamma_right=np.radians(right_deg))


def normal_into_damper(side, gamma):
    """Unit normal from the platform into the damper. Seen from the damper the OL platform is at
    +x, the OR platform at -x; both lie above the damper (radially outwards, +z), their undersides
    inclined by gamma to the circumferential direction x."""
    s, c = np.sin(gamma), np.cos(gamma)
    return np.array([-s, 0.0, -c]) if side == "OL" else np.array([s, 0.0, -c])


def placement(disk, geometry):
    """Positions (blade i frame) of the damper CG, the two contact centres and the two platform
    points the contacts are attached to (blade i's OL point, blade i+1's OR point)."""
    offsets = disk.platform_offsets(geometry)
    p_ol = disk.blade.points["OL"]
    centre_ol = p_ol + offsets[0]
    cg = centre_ol - geometry.centres[0]
    centre_or = cg + geometry.centres[1]
    p_or_neighbour = centre_or - offsets[1]
    return cg, np.array([centre_ol, centre_or]), np.array([p_ol, p_or_neighbour])


# ---------------------------------------------------------------------------------------
# contact frames and patches
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("angles", ANGLES)
def test_contact_frames_are_the_platform_normals(kind, angles):
    """Rows (xi, eta, zeta): zeta = normal from the platform into the damper (Fig. 2), eta = the
    damper axis y, xi = eta x zeta, orthonormal and right-handed."""
    gl, gr = np.radians(angles)
    g = reference_damper(kind, 1e-3).geometry(gl, gr)
    for c, (side, gamma) in enumerate([("OL", gl), ("OR", gr)]):
        R = g.frames[c]
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-14) and np.isclose(np.linalg.det(R), 1.0)
        assert np.allclose(R[2], normal_into_damper(side, gamma), atol=1e-14), f"{side}: zeta = {R[2]}"
        assert np.allclose(R[1], [0.0, 1.0, 0.0], atol=1e-14)


def test_cylinder_patch_is_a_line_and_wedge_patch_is_hc_by_lc():
    """The cylinder touches along a Hertzian line (all points at xi = 0, spread over l_C); the
    wedge's flat face is an h_C x l_C rectangle of equal cells (points at the cell midpoints)."""
    cyl = reference_damper("cylinder", 1e-3)
    wedge = reference_damper("wedge", 1e-3)
    gl = np.radians(35.0)
    for patch in cyl.geometry(gl, gl).patches:
        n = patch.n_points
        expected_eta = ((np.arange(n) + 0.5) / n - 0.5) * cyl.length
        assert patch.n_xi == 1 and np.all(patch.xi == 0.0), f"cylinder xi = {patch.xi}"
        assert np.allclose(np.sort(patch.eta), expected_eta, rtol=0, atol=1e-15)
        assert np.isclose(patch.weights.sum(), 1.0)
    for patch in wedge.geometry(gl, gl).patches:
        nx, ne = patch.n_xi, patch.n_eta
        assert nx > 1 and ne > 1
        xs = np.unique(np.round(patch.xi, 15))
        es = np.unique(np.round(patch.eta, 15))
        assert np.allclose(xs, ((np.arange(nx) + 0.5) / nx - 0.5) * wedge.contact_height, atol=1e-15)
        assert np.allclose(es, ((np.arange(ne) + 0.5) / ne - 0.5) * wedge.length, atol=1e-15)
        # cell extent: n cells of h_C / n and l_C / n cover exactly h_C x l_C
        extent_xi = xs.max() - xs.min() + wedge.contact_height / nx
        extent_eta = es.max() - es.min() + wedge.length / ne
        assert np.isclose(extent_xi, wedge.contact_height) and np.isclose(extent_eta, wedge.length), \
            f"wedge patch extent {extent_xi * 1e3:.4f} x {extent_eta * 1e3:.4f} mm"


@pytest.mark.parametrize("angles", ANGLES)
def test_cylinder_contact_centres_on_its_surface(angles):
    """The contact centre is the cylinder surface point facing each platform: -radius * normal."""
    gl, gr = np.radians(angles)
    cyl = reference_damper("cylinder", 1e-3)
    g = cyl.geometry(gl, gr)
    for c, (side, gamma) in enumerate([("OL", gl), ("OR", gr)]):
        assert np.allclose(g.centres[c], -cyl.radius * normal_into_damper(side, gamma), atol=1e-15)


@pytest.mark.parametrize("angles", ANGLES)
def test_wedge_faces_are_the_upper_sides_of_its_section(angles):
    """Each wedge contact patch spans one upper side of the triangular section: its ends
    (centre -/+ h_C/2 along xi) are the apex and a base vertex, the section is a triangle of two
    faces of length h_C inclined like the platforms, and the CG is the triangle's centroid."""
    gl, gr = np.radians(angles)
    wedge = reference_damper("wedge", 1e-3)
    g = wedge.geometry(gl, gr)
    h = wedge.contact_height
    verts = {tuple(np.round(v, 15)) for v in g.section}
    assert len(g.section) == 3
    assert np.allclose(g.section.mean(axis=0), 0.0, atol=1e-15), "CG is not the section's centroid"
    ends_all = []
    for c in range(2):
        xi = g.frames[c, 0]
        ends = [g.centres[c] + s * h / 2 * xi for s in (-1, 1)]
        for e in ends:
            assert abs(e[1]) < 1e-15
            assert tuple(np.round(e[[0, 2]], 15)) in verts, f"face end {e} is not a section vertex {g.section}"
        ends_all.append(ends)
        # the face lies in the platform plane: perpendicular to the contact normal
        assert abs((ends[1] - ends[0]) @ g.frames[c, 2]) < 1e-15
    # the two faces share the apex, the highest vertex (the groove between the platforms)
    shared = {tuple(np.round(e, 15)) for e in ends_all[0]} & {tuple(np.round(e, 15)) for e in ends_all[1]}
    assert len(shared) == 1
    apex = np.array(shared.pop())
    assert np.isclose(apex[2], g.section[:, 1].max())


# ---------------------------------------------------------------------------------------
# mass properties (I_D of Eq. 12)
# ---------------------------------------------------------------------------------------
def test_cylinder_inertia_closed_form():
    """Solid cylinder about its CG: m, m r^2 / 2 about its axis (y), m (3 r^2 + l^2) / 12 across."""
    m, r, l = 2.5e-3, 2e-3, 20e-3
    g = CylinderDamper(m, r, l).geometry(np.radians(35.0), np.radians(35.0))
    expected = np.diag([m, m, m, m * (3 * r ** 2 + l ** 2) / 12, m * r ** 2 / 2, m * (3 * r ** 2 + l ** 2) / 12])
    assert np.allclose(g.inertia, expected, rtol=1e-14, atol=0)


@pytest.mark.parametrize("angles", ANGLES)
def test_wedge_inertia_by_direct_integration(angles):
    """Uniform triangular prism: mass matrix about the CG by integration over a fine grid of
    the section (x, z) and the length (y) (midpoint rule; the grid converges as 1/n^2)."""
    gl, gr = np.radians(angles)
    wedge = reference_damper("wedge", 3e-3)
    g = wedge.geometry(gl, gr)
    tri = g.section
    n = 1200
    lo, hi = tri.min(axis=0), tri.max(axis=0)
    xs = lo[0] + (np.arange(n) + 0.5) / n * (hi[0] - lo[0])
    zs = lo[1] + (np.arange(n) + 0.5) / n * (hi[1] - lo[1])
    X, Z = np.meshgrid(xs, zs, indexing="ij")

    def side(a, b):
        return (b[0] - a[0]) * (Z - a[1]) - (b[1] - a[1]) * (X - a[0])

    s = [side(tri[i], tri[(i + 1) % 3]) for i in range(3)]
    inside = (s[0] >= 0) & (s[1] >= 0) & (s[2] >= 0) | (s[0] <= 0) & (s[1] <= 0) & (s[2] <= 0)
    x, z = X[inside], Z[inside]
    area = inside.sum() * (xs[1] - xs[0]) * (zs[1] - zs[0])
    (ax, az), (bx, bz) = tri[1] - tri[0], tri[2] - tri[0]
    exact_area = 0.5 * abs(ax * bz - az * bx)
    assert abs(area / exact_area - 1) < 5e-3
    assert abs(x.mean()) < 1e-3 * wedge.contact_height and abs(z.mean()) < 1e-3 * wedge.contact_height
    m, l = wedge.mass, wedge.length
    xx, zz, xz = (x ** 2).mean(), (z ** 2).mean(), (x * z).mean()
    yy = l ** 2 / 12
    expected = m * np.array([[yy + zz, 0, -xz], [0, xx + zz, 0], [-xz, 0, xx + yy]])
    rel = np.abs(g.inertia[3:, 3:] - expected).max() / np.abs(expected).max()
    assert rel < 5e-3, f"rotary inertia differs from direct integration by {rel:.2e}"
    assert np.allclose(g.inertia[:3, :3], m * np.eye(3)) and np.all(g.inertia[:3, 3:] == 0)


# ---------------------------------------------------------------------------------------
# kinematics: G_D, G_P and the patch points (Eq. 6-9)
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("angles", ANGLES)
def test_rigid_motion_of_blades_and_damper_gives_no_relative_displacement(kind, angles):
    """Blade i, blade i+1 (a rigid translation of blade i along -x, the unrolled pitch) and the
    damper moving together as one rigid body: w = G_D u_D - G_P u_P = 0 and every patch point
    has zero relative displacement (w_phi = 0 too)."""
    disk = disk_with_angles(kind, *angles)
    g = disk.damper_geometry()
    cg, centres, platform_points = placement(disk, g)
    # the neighbour's OR point must be blade i's OR point shifted along x only
    p_or = disk.blade.points["OR"]
    assert np.allclose(platform_points[1][1:], p_or[1:], atol=1e-15), \
        f"OR contact attached at {platform_points[1]}, not on the neighbour's OR point line {p_or}"
    pitch = p_or[0] - platform_points[1][0]
    assert pitch > 0, f"neighbour blade must be at -x (pitch {pitch})"
    rng = np.random.default_rng(7)
    for _ in range(5):
        u, phi = rng.normal(size=3) * 1e-5, rng.normal(size=3) * 1e-3

        def motion(point):
            return np.concatenate([u + np.cross(phi, point), phi])

        u_D = motion(cg)
        u_P = np.concatenate([motion(platform_points[0]), motion(platform_points[1])])
        w = g.G_D @ u_D - g.G_P(disk.platform_offsets(g)) @ u_P
        scale = np.abs(u).max() + np.abs(phi).max() * 0.1
        assert np.abs(w).max() < 1e-12 * scale, f"rigid motion gives w = {w}"
        for c, patch in enumerate(g.patches):
            pts = patch.point_map @ w[6 * c:6 * c + 6]
            assert np.abs(pts).max() < 1e-12 * scale


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("angles", ANGLES)
def test_point_relative_displacement_from_rigid_body_kinematics(kind, angles):
    """Arbitrary damper and platform motions: the relative displacement of every patch point
    (damper minus platform, in the contact frame) computed directly with u + phi x r from the
    point's position equals point_map (G_D u_D - G_P u_P)."""
    disk = disk_with_angles(kind, *angles)
    g = disk.damper_geometry()
    cg, centres, platform_points = placement(disk, g)
    G_P = g.G_P(disk.platform_offsets(g))
    rng = np.random.default_rng(11)
    for _ in range(5):
        u_D = np.concatenate([rng.normal(size=3) * 1e-5, rng.normal(size=3) * 1e-3])
        u_P = np.concatenate([rng.normal(size=3) * 1e-5, rng.normal(size=3) * 1e-3,
                              rng.normal(size=3) * 1e-5, rng.normal(size=3) * 1e-3])
        w = g.G_D @ u_D - G_P @ u_P
        for c, patch in enumerate(g.patches):
            R = g.frames[c]
            ref = []
            for xi, eta in zip(patch.xi, patch.eta):
                X = centres[c] + R.T @ np.array([xi, eta, 0.0])
                damper = u_D[:3] + np.cross(u_D[3:], X - cg)
                up = u_P[6 * c:6 * c + 6]
                platform = up[:3] + np.cross(up[3:], X - platform_points[c])
                ref.append(R @ (damper - platform))
            ref = np.array(ref)
            got = patch.point_map @ w[6 * c:6 * c + 6]
            err = np.abs(got - ref).max() / np.abs(ref).max()
            assert err < 1e-12, f"{kind} {angles} contact {c}: point kinematics differ by {err:.2e}"
            # rotations: w_phi = R (phi_D - phi_P)
            assert np.allclose(w[6 * c + 3:6 * c + 6], R @ (u_D[3:] - u_P[6 * c + 3:6 * c + 6]), rtol=1e-13, atol=0)


@pytest.mark.parametrize("kind", KINDS)
def test_symmetric_platforms_put_both_contacts_on_the_platform_points(kind):
    """gamma_L = gamma_R: no radial mismatch, the contact centres are the blades' OL / OR points."""
    disk = reference_disk(kind, 1e-3)
    assert np.abs(disk.platform_offsets(disk.damper_geometry())).max() < 1e-16


@pytest.mark.parametrize("kind", KINDS)
def test_exchanged_angles_give_the_mirror_image_placement(kind):
    """Mirror x -> -x of the (gamma_L, gamma_R) assembly is the (gamma_R, gamma_L) assembly: OL and
    OR offsets exchange (the blade is symmetric, its OL / OR points are mirror images)."""
    a = disk_with_angles(kind, 35.0, 55.0)
    b = disk_with_angles(kind, 55.0, 35.0)
    oa, ob = a.platform_offsets(a.damper_geometry()), b.platform_offsets(b.damper_geometry())
    mirror = np.array([-1.0, 1.0, 1.0])
    assert np.allclose(oa[0], mirror * ob[1], atol=1e-16) and np.allclose(oa[1], mirror * ob[0], atol=1e-16), \
        f"offsets (35, 55) {oa.tolist()} vs (55, 35) {ob.tolist()}"
    assert np.abs(oa).max() > 1e-5  # a real mismatch is there to be split


# ---------------------------------------------------------------------------------------
# preload: Eq. 26 and the static seating
# ---------------------------------------------------------------------------------------
def test_centrifugal_force_eq26():
    """F_CG = m R Omega_E^2 / EO^2 (Eq. 26): quadratic in Omega_E, 1/EO^2, linear in m and R;
    the derivative in Omega_E is 2 F / Omega_E."""
    m, R, f = 1.3e-3, 0.05, 95.0
    w = 2 * np.pi * f
    for eo in (1, 2, 3, 8):
        F, dF = centrifugal_force(m, R, f, eo)
        assert F == pytest.approx(m * R * w ** 2 / eo ** 2, rel=1e-15)
        assert dF == pytest.approx(2 * F / w, rel=1e-14)             # per rad/s of Omega_E
        h = 1e-6 * f
        fd = (centrifugal_force(m, R, f + h, eo)[0] - centrifugal_force(m, R, f - h, eo)[0]) / (2 * h)
        assert dF == pytest.approx(fd / (2 * np.pi), rel=1e-8)
    assert centrifugal_force(m, R, 2 * f, 1)[0] == pytest.approx(4 * centrifugal_force(m, R, f, 1)[0], rel=1e-15)
    assert centrifugal_force(m, R, f, 2)[0] == pytest.approx(centrifugal_force(m, R, f, 1)[0] / 4, rel=1e-15)
    assert centrifugal_force(2 * m, 3 * R, f, 1)[0] == pytest.approx(6 * centrifugal_force(m, R, f, 1)[0], rel=1e-15)
    # EO = 0: the rotor speed is given, the force does not follow Omega_E
    F0, dF0 = centrifugal_force(m, R, f, 0, rotor_speed_hz=50.0)
    assert F0 == pytest.approx(m * R * (2 * np.pi * 50) ** 2, rel=1e-15) and dF0 == 0.0
    # the disk uses the same law with its own m and R
    disk = reference_disk("cylinder", 1e-3, engine_order=2)
    assert disk.centrifugal_force(w / (2 * np.pi))[0] == pytest.approx(1e-3 * disk.damper_radius * w ** 2 / 4, rel=1e-15)


def frictionless_loads(F, gl, gr):
    """Two frictionless inclined planes holding a body against F e_z:
    N_L n_L + N_R n_R + F e_z = 0, n = (-/+ sin g, 0, -cos g)
    -> x: N_L sin gL = N_R sin gR; z: N_L cos gL + N_R cos gR = F
    -> N_L = F sin gR / sin(gL + gR), N_R = F sin gL / sin(gL + gR)."""
    return F * np.array([np.sin(gr), np.sin(gl)]) / np.sin(gl + gr)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("angles", ANGLES)
@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_seating_loads_equal_the_frictionless_closed_form(kind, angles, exponent):
    """``seat`` (6-DOF static equilibrium with the normal laws of all points, lift-off allowed)
    carries F_CG with N_L = F sin gR / sin(gL + gR), N_R = F sin gL / sin(gL + gR); the point
    forces are in force and moment equilibrium with F_CG applied at the CG."""
    gl, gr = np.radians(angles)
    damper = reference_damper(kind, 1e-3, roughness_exponent=exponent)
    g = damper.geometry(gl, gr)
    F = 7.5
    u, approach, loads = seat(g, F)
    expected = frictionless_loads(F, gl, gr)
    rel = np.abs(loads - expected).max() / F
    assert rel < 1e-9, f"seated loads {loads} vs closed form {expected} (rel {rel:.1e})"
    # equilibrium of the point forces on the damper (normal = +N along zeta into the damper)
    total_f, total_m = np.array([0.0, 0.0, F]), np.zeros(3)
    for c, patch in enumerate(g.patches):
        N, _ = patch.normal_law.force(approach[c], patch.weights)
        R = g.frames[c]
        for xi, eta, n in zip(patch.xi, patch.eta, N):
            r = g.centres[c] + R.T @ np.array([xi, eta, 0.0])
            f = n * R[2]
            total_f += f
            total_m += np.cross(r, f)
    assert np.abs(total_f).max() < 1e-9 * F, f"force imbalance {total_f}"
    assert np.abs(total_m).max() < 1e-9 * F * 1e-2, f"moment imbalance {total_m}"


def test_seating_scales_with_the_preload():
    """Linear law: the static approach is proportional to F; power law p: to F^(1/p) (what the
    one-harmonic disk uses to rescale one seating to any Omega)."""
    gl = np.radians(35.0)
    for exponent in (1.0, 1.5):
        g = reference_damper("wedge", 1e-3, roughness_exponent=exponent).geometry(gl, np.radians(50.0))
        _, a1, _ = seat(g, 1.0)
        _, a4, _ = seat(g, 4.0)
        assert np.allclose(a4, a1 * 4.0 ** (1 / exponent), rtol=1e-8, atol=0), f"exponent {exponent}"


# ---------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("call, match", [
    (lambda: CylinderDamper(-1e-3), "damper mass"),
    (lambda: WedgeDamper(-1e-3), "damper mass"),
    (lambda: reference_damper("wedge", -1e-3), "damper mass"),
    (lambda: WedgeDamper(1e-3, contact_height=None), "contact_height"),
    (lambda: WedgeDamper(1e-3, contact_height=0.0), "contact_height"),
    (lambda: CylinderDamper(1e-3).geometry(0.0, 0.5), "gamma_left"),
    (lambda: CylinderDamper(1e-3).geometry(0.5, np.pi / 2), "gamma_right"),
    (lambda: WedgeDamper(1e-3).geometry(-0.1, 0.5), "gamma_left"),
    (lambda: centrifugal_force(1e-3, 0.1, 95.0, 0), "rotor_speed_hz"),
    (lambda: centrifugal_force(-1e-3, 0.1, 95.0, 1), "damper mass"),
    (lambda: seat(CylinderDamper(1e-3).geometry(0.5, 0.5), -1.0), "radial_force"),
    (lambda: ContactProperties(friction_coefficient=-0.1), "friction_coefficient"),
    (lambda: retention_stiffness(-1e-4, 1e6), "static_retention"),
    (lambda: retention_stiffness(1e-4, -1e6), "normal_stiffness"),
])
def test_bad_damper_input_raises_value_error_naming_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_retention_spring_holds_a_rotation_as_the_translation_at_10_mm():
    """The retention spring's restoring force and moment on a rigid displacement u [m] and
    rotation theta [rad] of the damper, written by hand: F = -r k_N u, M = -r k_N l^2 theta with
    l = 10 mm (the same spring pulling on a point 10 mm from the centre, transverse to the
    rotation axis), r the retention fraction and k_N the damper's normal contact stiffness."""
    r, k_n, lever = 1e-4, 3.7e6, 0.01
    u, theta = np.array([1e-6, -2e-6, 3e-6]), np.array([4e-4, -5e-4, 6e-4])
    K = retention_stiffness(r, k_n)
    restoring = -K @ np.concatenate([u, theta])
    np.testing.assert_allclose(restoring[:3], -r * k_n * u, rtol=1e-15)
    for axis in range(3):
        # a point at `lever` from the centre, perpendicular to the axis, moves by theta x rho
        rho = lever * np.eye(3)[(axis + 1) % 3]
        rotation = np.zeros(3)
        rotation[axis] = theta[axis]
        moment = np.cross(rho, -r * k_n * np.cross(rotation, rho))
        np.testing.assert_allclose(restoring[3 + axis], moment[axis], rtol=1e-12)
    assert np.array_equal(K, K.T) and np.all(K == np.diag(np.diag(K)))


def test_seated_state_is_the_rigid_seating_of_every_damper_in_the_static_harmonic():
    """One static seating (DiskModel.static_state) serves the tuned sector and the mistuned assembly: each damper's
    static harmonic is its frictionless rigid-platform seating under F_CG, whose normal loads
    carry F_CG radially; everything else (and every harmonic without a static one) is at rest."""
    from bladedamp.damper.kinetics import seat
    from bladedamp.mistuned import MistunedDisk

    # a numpy mass (as the studies pass): has_damper is a numpy bool
    tuned = dataclasses.replace(reference_disk("wedge", np.float64(0.3e-3)), n_blades=3)
    full = MistunedDisk.from_tuned(tuned)
    w = 2 * np.pi * 97.0
    F = tuned.centrifugal_force(97.0)[0]
    geometry = tuned.damper_geometry()
    u, _, loads = seat(geometry, F)
    # the seating's normal loads balance F_CG along the radius (frictionless contacts)
    assert np.dot(loads, geometry.frames[:, 2, 2]) == pytest.approx(-F, rel=1e-9)
    for model, columns in ((tuned, [slice(tuned.blade.n_modes, None)]),
                           (full, [full.damper_slice(d) for d in range(3)])):
        system = model.hbm_system((0, 1))
        X = model.static_state(system, w).reshape(system.basis.n_coeffs, system.n_dof)
        expected = np.zeros_like(X)
        for c in columns:
            expected[system.basis.cos_index(0), c] = u
        np.testing.assert_array_equal(X, expected)
        assert not model.static_state(model.hbm_system((1,)), w).any()
