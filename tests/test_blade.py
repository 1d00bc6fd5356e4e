"""Tests of the modal blade (paper Eq. 1-5) and its beam FE builder."""
import dataclasses

import numpy as np
import pytest
import scipy.optimize

from bladedamp import solid
from bladedamp.blade import (
    BeamBladeGeometry,
    ModalBlade,
    PlatformBlock,
    TABLE1_FREQUENCIES_HZ,
    beam_modes,
    reference_blade,
    reference_blade_geometry,
    rigid_offset_motion,
    torsion_constant_polygon,
    torsion_constant_rectangle,
    warping_constant_rectangle,
)

# Clamped-free Euler-Bernoulli beam: beta_k L.
BETA_L = (1.8751040687, 4.6940911330)


# ---------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------
def uniform_beam(length=0.3, thickness=0.005, chord=0.030, n_elements=20):
    """One section over the whole span, no platform mass: a plain cantilever."""
    shank = length / 3.0
    n_shank = max(1, n_elements // 3)
    return BeamBladeGeometry(
        shank_length=shank, shank_thickness_x=thickness, shank_chord_y=chord,
        airfoil_length=length - shank, airfoil_thickness_x=thickness, airfoil_chord_y=chord,
        platform_half_width=0.012, platform_contact_z_offset=0.0, platform_mass=0.0,
        platform_rotary_inertia=(0.0, 0.0, 0.0), youngs_modulus=210e9, poisson_ratio=0.3,
        density=7850.0, n_elements_shank=n_shank, n_elements_airfoil=n_elements - n_shank)


def bending_closed_form_hz(k, length, E, second_moment, rho, area):
    return BETA_L[k] ** 2 / (2 * np.pi * length**2) * np.sqrt(E * second_moment / (rho * area))


def fe_frequency(modes, name):
    return modes.frequencies_hz[modes.mode_names.index(name)]


def peak_amplitude(blade, force):
    """Finely searched maximum of |u_x,tip| around the 1F resonance."""
    w1 = blade.natural_angular_frequencies[0]
    res = scipy.optimize.minimize_scalar(
        lambda w: -abs(blade.linear_frf(w / (2 * np.pi), force)[0, 0]),
        bounds=(w1 * 0.995, w1 * 1.005), method="bounded", options={"xatol": 1e-10 * w1})
    return -res.fun, res.x


def simple_shapes(n_m=2, value=1.0):
    return {p: np.full((6, n_m), value) for p in ("OL", "OR", "tip", "excitation")}


def simple_points():
    return {"OL": [-0.01, 0, 0.05], "OR": [0.01, 0, 0.05], "tip": [0, 0, 0.2],
            "excitation": [0, 0, 0.2]}


# ---------------------------------------------------------------------------------------
# beam FE against closed forms
# ---------------------------------------------------------------------------------------
def test_uniform_cantilever_flatwise_frequencies_match_closed_form():
    g = uniform_beam()
    modes = beam_modes(g)
    A = g.airfoil_thickness_x * g.airfoil_chord_y
    I_flat = g.airfoil_chord_y * g.airfoil_thickness_x**3 / 12
    for k, name in enumerate(("1F", "2F")):
        expected = bending_closed_form_hz(k, g.total_length, g.youngs_modulus, I_flat, g.density, A)
        assert fe_frequency(modes, name) == pytest.approx(expected, rel=5e-3)


def test_uniform_cantilever_edgewise_frequency_uses_the_other_inertia():
    g = uniform_beam()
    modes = beam_modes(g)
    A = g.airfoil_thickness_x * g.airfoil_chord_y
    I_edge = g.airfoil_thickness_x * g.airfoil_chord_y**3 / 12
    expected = bending_closed_form_hz(0, g.total_length, g.youngs_modulus, I_edge, g.density, A)
    assert fe_frequency(modes, "1E") == pytest.approx(expected, rel=5e-3)
    # chord/thickness = 6 -> 1E/1F = 6 for a uniform beam
    assert fe_frequency(modes, "1E") / fe_frequency(modes, "1F") == pytest.approx(6.0, rel=5e-3)


@pytest.mark.parametrize("ratio, beta", [(1.0, 0.141), (2.0, 0.229), (4.0, 0.281), (10.0, 0.312)])
def test_torsion_constant_of_rectangle_matches_tables(ratio, beta):
    # J = beta * a * b^3 (Timoshenko & Goodier / Roark table, a = long side)
    b = 0.004
    assert torsion_constant_rectangle(ratio * b, b) == pytest.approx(beta * ratio * b * b**3, rel=4e-3)
    assert torsion_constant_rectangle(b, ratio * b) == torsion_constant_rectangle(ratio * b, b)


def test_uniform_cantilever_torsion_frequencies_match_closed_form():
    g = uniform_beam()
    modes = beam_modes(g)
    t, c = g.airfoil_thickness_x, g.airfoil_chord_y
    J = torsion_constant_rectangle(c, t)
    I_p = t * c**3 / 12 + c * t**3 / 12
    G = g.youngs_modulus / (2 * (1 + g.poisson_ratio))
    for k, name in ((1, "1T"), (2, "2T")):
        expected = (2 * k - 1) * np.pi / (2 * g.total_length) * np.sqrt(G * J / (g.density * I_p))
        assert fe_frequency(modes, name) == pytest.approx(expected / (2 * np.pi), rel=1e-2)


@pytest.mark.parametrize("mode, dof, field, index", [
    ("1F", 0, "platform_mass", None),                 # u_x
    ("1E", 1, "platform_mass", None),                 # u_y
    ("1E", 3, "platform_rotary_inertia", 0),          # phi_x  <- I_xx
    ("2F", 4, "platform_rotary_inertia", 1),          # phi_y  <- I_yy
    ("1T", 5, "platform_rotary_inertia", 2),          # phi_z  <- I_zz
])
def test_platform_lumped_inertia_acts_on_its_dof(mode, dof, field, index):
    """Rayleigh: a small added inertia dm on DOF d of the platform node gives
    omega'^2 = omega^2 / (1 + dm phi_d^2) to first order (phi mass-normalised)."""
    g = uniform_beam()
    modes = beam_modes(g)
    j = modes.mode_names.index(mode)
    phi = modes.node_shapes(modes.platform_node)[dof, j]
    eps = 1e-3
    dm = eps / phi**2
    if index is None:
        changed = dataclasses.replace(g, platform_mass=dm)
    else:
        inertia = [0.0, 0.0, 0.0]
        inertia[index] = dm
        changed = dataclasses.replace(g, platform_rotary_inertia=tuple(inertia))
    ratio2 = (fe_frequency(beam_modes(changed), mode) / modes.frequencies_hz[j]) ** 2
    assert 1.0 - ratio2 == pytest.approx(1.0 - 1.0 / (1.0 + eps), rel=1e-2)


def test_platform_mass_lowers_bending_frequencies():
    g = uniform_beam()
    heavy = dataclasses.replace(g, platform_mass=0.05)
    assert fe_frequency(beam_modes(heavy), "2F") < 0.99 * fe_frequency(beam_modes(g), "2F")
    assert fe_frequency(beam_modes(heavy), "1T") == pytest.approx(fe_frequency(beam_modes(g), "1T"))


# ---------------------------------------------------------------------------------------
# mass normalisation
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("geometry", [uniform_beam(), reference_blade_geometry()],
                         ids=["uniform", "reference"])
def test_eigenvectors_are_mass_normalised(geometry):
    modes = beam_modes(geometry)
    V = modes.vectors
    np.testing.assert_allclose(V.T @ modes.mass @ V, np.eye(V.shape[1]), atol=1e-10)
    # and K-orthogonal with omega^2 on the diagonal
    w2 = (2 * np.pi * modes.frequencies_hz) ** 2
    np.testing.assert_allclose(V.T @ modes.stiffness @ V, np.diag(w2), atol=1e-6 * w2.max())


def test_uniform_cantilever_tip_value_is_two_over_sqrt_mass():
    g = uniform_beam()
    blade = ModalBlade.from_beam(g)
    m_total = g.density * g.airfoil_thickness_x * g.airfoil_chord_y * g.total_length
    assert blade.mode_names[0] == "1F"
    assert blade.mode_shapes["tip"][0, 0] == pytest.approx(2.0 / np.sqrt(m_total), rel=5e-3)
    # mode 1E: same closed form in y
    assert blade.mode_shapes["tip"][1, 3] == pytest.approx(2.0 / np.sqrt(m_total), rel=5e-3)


# ---------------------------------------------------------------------------------------
# kinematics
# ---------------------------------------------------------------------------------------
def test_rigid_offset_motion_components():
    node = np.array([1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    r = np.array([0.5, -0.4, 0.25])
    out = rigid_offset_motion(node, r)
    px, py, pz = node[3:]
    expected_u = [1.0 + py * r[2] - pz * r[1], 2.0 + pz * r[0] - px * r[2], 3.0 + px * r[1] - py * r[0]]
    np.testing.assert_allclose(out, np.r_[expected_u, node[3:]])
    # pure twist phi_z about the axis moves a point at +x in +y
    np.testing.assert_allclose(rigid_offset_motion(np.r_[0, 0, 0, 0, 0, 0.01], [0.02, 0, 0]),
                               [0, 2e-4, 0, 0, 0, 0.01], atol=1e-15)


def test_contact_points_follow_the_platform_node_rigidly():
    g = reference_blade_geometry()
    modes = beam_modes(g)
    blade = ModalBlade.from_beam(g, n_modes=6)
    idx = [modes.mode_names.index(n) for n in blade.mode_names]
    node = modes.node_shapes(modes.platform_node)[:, idx]
    z_node = modes.node_z[modes.platform_node]
    for name, x_sign in (("OL", -1.0), ("OR", +1.0)):
        r = blade.points[name] - np.array([0.0, 0.0, z_node])
        assert r[0] == pytest.approx(x_sign * g.platform_half_width)
        assert r[2] == pytest.approx(-g.platform_contact_z_offset)
        ux, uy, uz, px, py, pz = node
        expected = np.array([ux + py * r[2] - pz * r[1], uy + pz * r[0] - px * r[2],
                             uz + px * r[1] - py * r[0], px, py, pz])
        np.testing.assert_allclose(blade.mode_shapes[name], expected, atol=1e-12)


def test_fe_rotations_are_consistent_with_u_plus_phi_cross_r():
    """Node slopes: du_x/dz = +phi_y (flatwise), du_y/dz = -phi_x (edgewise), as a rigid
    offset along z (u + phi x (0, 0, dz)) requires."""
    g = uniform_beam(n_elements=60)
    modes = beam_modes(g)
    V = modes.full_vectors().reshape(modes.n_nodes, 6, -1)
    z = modes.node_z
    mid = modes.n_nodes // 2
    for name, u_dof, phi_dof, sign in (("1F", 0, 4, +1.0), ("1E", 1, 3, -1.0)):
        j = modes.mode_names.index(name)
        slope = (V[mid + 1, u_dof, j] - V[mid - 1, u_dof, j]) / (z[mid + 1] - z[mid - 1])
        assert slope == pytest.approx(sign * V[mid, phi_dof, j], rel=1e-3)
        assert abs(slope) > 1.0


# ---------------------------------------------------------------------------------------
# reference blade
# ---------------------------------------------------------------------------------------
def test_reference_blade_modes_are_classified_and_carry_table1_frequencies():
    blade = reference_blade()
    assert blade.mode_names == ("1F", "2F", "1T", "1E")
    np.testing.assert_allclose(blade.natural_frequencies_hz, TABLE1_FREQUENCIES_HZ)
    np.testing.assert_allclose(blade.damping_ratios, 0.001)
    tip = blade.mode_shapes["tip"]
    # dominant tip DOF of each mode: u_x (1F, 2F), phi_z (1T), u_y (1E)
    assert tip[0, 0] > 0 and tip[0, 1] > 0 and tip[5, 2] > 0 and tip[1, 3] > 0
    assert abs(tip[1, 0]) < 1e-6 * tip[0, 0] and abs(tip[5, 0]) < 1e-6 * tip[0, 0]
    assert abs(tip[0, 3]) < 1e-6 * tip[1, 3] and abs(tip[0, 2]) < 1e-6 * tip[5, 2]
    # 2F has a node between platform and tip: platform and tip u_x have opposite signs
    assert blade.mode_shapes["OL"][0, 1] * tip[0, 1] < 0


def test_reference_blade_fe_frequencies_are_near_table1():
    modes = beam_modes(reference_blade_geometry())
    fe = {n: fe_frequency(modes, n) for n in ("1F", "2F", "1T", "1E")}
    assert fe["1F"] == pytest.approx(95.0, rel=0.01)
    assert fe["1F"] < fe["2F"] < fe["1T"] < fe["1E"]   # same order as Table 1
    assert fe["1T"] == pytest.approx(783.0, rel=0.10)


def test_other_n_modes_returns_lowest_by_frequency():
    blade = ModalBlade.from_beam(uniform_beam(), n_modes=3)
    # chord/thickness = 6: 1E = 6.0 f_1F lies below 2F = 6.27 f_1F
    assert blade.mode_names == ("1F", "1E", "2F")
    assert np.all(np.diff(blade.natural_frequencies_hz) > 0)
    four = ModalBlade.from_beam(uniform_beam())          # n_modes = 4: paper order
    assert four.mode_names == ("1F", "2F", "1T", "1E")
    assert four.natural_frequencies_hz[2] > four.natural_frequencies_hz[3]


def test_calibration_no_damper_1f_peak_is_1p7_mm():
    blade = reference_blade()
    amplitude, omega_peak = peak_amplitude(blade, np.array([0.1, 0, 0, 0, 0, 0]))
    assert amplitude == pytest.approx(1.70e-3, rel=1e-2)
    assert omega_peak / (2 * np.pi) == pytest.approx(95.0, abs=0.01)


def test_reference_blade_platform_symmetry():
    blade = reference_blade()
    OL, OR = blade.mode_shapes["OL"], blade.mode_shapes["OR"]
    i1F, i1T = blade.mode_names.index("1F"), blade.mode_names.index("1T")
    assert OL[0, i1F] == pytest.approx(OR[0, i1F], rel=1e-12) and OL[0, i1F] > 0
    assert OL[5, i1T] == pytest.approx(OR[5, i1T], rel=1e-12) and OL[5, i1T] > 0
    # mirror about the y-z plane: 1F lifts one contact point and lowers the other,
    # 1T moves them axially in opposite directions (rel 1e-8: eigen-solver round-off)
    assert OL[2, i1F] == pytest.approx(-OR[2, i1F], rel=1e-8) and abs(OL[2, i1F]) > 0
    assert OL[1, i1T] == pytest.approx(-OR[1, i1T], rel=1e-8) and abs(OL[1, i1T]) > 0
    np.testing.assert_allclose(blade.points["OL"] * [-1, 1, 1], blade.points["OR"])
    assert blade.points["OL"][0] < 0


# ---------------------------------------------------------------------------------------
# modal model (Eq. 4-5)
# ---------------------------------------------------------------------------------------
def test_dynamic_stiffness_is_eq5():
    blade = reference_blade()
    w0 = 2 * np.pi * np.array(TABLE1_FREQUENCIES_HZ)
    omega = 2 * np.pi * 100.0
    np.testing.assert_allclose(blade.dynamic_stiffness(omega / (2 * np.pi)),
                               w0**2 - omega**2 + 2j * 0.001 * w0 * omega)
    np.testing.assert_allclose(blade.natural_angular_frequencies, w0)
    assert blade.n_modes == 4


def test_linear_frf_equals_direct_fe_solution_with_all_modes():
    g = uniform_beam(n_elements=8)
    modes = beam_modes(g)
    n_all = modes.frequencies_hz.size
    blade = ModalBlade.from_beam(g, n_modes=n_all, damping_ratios=0.0)
    force = np.array([0.1, -0.1, 0.05, 0.0, 0.0, 0.001])
    omega = 2 * np.pi * np.array([30.0, 200.0, 1234.0])
    frf = blade.linear_frf(omega / (2 * np.pi), force)
    tip = slice(6 * (modes.n_nodes - 1) - 6, 6 * (modes.n_nodes - 1))   # free-DOF indices
    p = np.zeros(modes.stiffness.shape[0])
    p[tip] = force
    for i, w in enumerate(omega):
        u = np.linalg.solve(modes.stiffness - w**2 * modes.mass, p)
        np.testing.assert_allclose(frf[i], u[tip], rtol=1e-7, atol=1e-12 * np.abs(u).max())


def test_linear_frf_single_mode_resonance_value():
    blade = reference_blade()
    w1 = blade.natural_angular_frequencies[0]
    phi = blade.mode_shapes["tip"][0, 0]
    u = blade.linear_frf(w1 / (2 * np.pi), np.array([0.1, 0, 0, 0, 0, 0]))
    assert u.shape == (1, 6)
    # 1F term at omega = omega_1: F phi^2 / (2 i D omega_1^2); others are small
    assert u[0, 0].imag == pytest.approx(-0.1 * phi**2 / (2 * 0.001 * w1**2), rel=1e-3)


def test_with_frequencies_and_scaled_keep_shapes():
    blade = reference_blade()
    mistuned = blade.scaled(1.02)
    np.testing.assert_allclose(mistuned.natural_frequencies_hz, 1.02 * blade.natural_frequencies_hz)
    np.testing.assert_allclose(blade.natural_frequencies_hz, TABLE1_FREQUENCIES_HZ)  # unchanged
    for name in blade.mode_shapes:
        np.testing.assert_array_equal(mistuned.mode_shapes[name], blade.mode_shapes[name])
    assert mistuned.mode_names == blade.mode_names
    other = blade.with_frequencies([90.0, 400.0, 800.0, 1000.0])
    np.testing.assert_allclose(other.natural_frequencies_hz, [90, 400, 800, 1000])
    np.testing.assert_allclose(other.damping_ratios, blade.damping_ratios)


def test_from_arrays_round_trip():
    blade = reference_blade()
    copy = ModalBlade.from_arrays(blade.natural_frequencies_hz, blade.damping_ratios,
                                  blade.mode_shapes, blade.points, blade.mode_names)
    w = np.linspace(500, 700, 5)
    f = np.array([0.1, -0.1, 0, 0, 0, 0.001])
    np.testing.assert_allclose(copy.linear_frf(w, f), blade.linear_frf(w, f))


# ---------------------------------------------------------------------------------------
# input validation
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, word", [
    ({"natural_frequencies_hz": [-1.0, 100.0]}, "natural_frequencies_hz"),
    ({"natural_frequencies_hz": [np.nan, 100.0]}, "natural_frequencies_hz"),
    ({"damping_ratios": [0.001, -0.01]}, "damping_ratios"),
    ({"damping_ratios": [0.001, 0.001, 0.001]}, "damping_ratios"),
    ({"mode_shapes": {**simple_shapes(), "tip": np.ones((3, 2))}}, "mode_shapes"),
    ({"mode_shapes": {**simple_shapes(), "tip": np.full((6, 2), np.inf)}}, "mode_shapes"),
    ({"points": {**simple_points(), "tip": [0.0, 0.2]}}, "points"),
    ({"mode_names": ("1F",)}, "mode_names"),
])
def test_modal_blade_rejects_bad_input(kwargs, word):
    args = {"natural_frequencies_hz": [95.0, 423.0], "damping_ratios": [0.001, 0.001],
            "mode_shapes": simple_shapes(), "points": simple_points()}
    ModalBlade(**args)  # the unmodified arguments are valid
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        ModalBlade(**args)


def test_modal_blade_requires_point_OL():
    shapes, points = simple_shapes(), simple_points()
    del shapes["OL"], points["OL"]
    with pytest.raises(ValueError, match="OL"):
        ModalBlade([95.0, 423.0], [0.001, 0.001], shapes, points)


def test_scaled_rejects_nonpositive_kappa():
    with pytest.raises(ValueError, match="kappa"):
        reference_blade().scaled(0.0)


@pytest.mark.parametrize("field, value", [
    ("airfoil_length", -0.1), ("shank_thickness_x", 0.0), ("density", -1.0),
    ("poisson_ratio", 0.5), ("platform_mass", -0.01), ("platform_contact_z_offset", 1.0),
    ("n_elements_airfoil", 0), ("platform_rotary_inertia", (1.0, -1.0, 0.0)),
    ("tip_point", (0.0, 0.0, 5.0)), ("bending_theory", "rayleigh"), ("torsion_theory", "warping"),
    ("platform_block", PlatformBlock(0.07, 0.08, 0.03, 0.05)),      # above the platform node
    ("platform_block", PlatformBlock(0.0, 0.062, 0.03, 0.05)),      # down to the clamp
    ("platform_block", (0.056, 0.062, 0.03, 0.05)),                 # not a PlatformBlock
])
def test_geometry_rejects_bad_input(field, value):
    g = reference_blade_geometry()
    with pytest.raises(ValueError, match=field):
        dataclasses.replace(g, **{field: value})


def test_from_beam_rejects_wrong_number_of_frequencies():
    with pytest.raises(ValueError, match="natural_frequencies_hz"):
        ModalBlade.from_beam(reference_blade_geometry(), natural_frequencies_hz=(95.0, 423.0))


# ---------------------------------------------------------------------------------------
# refined beam options: Timoshenko bending, Vlasov torsion, the platform as a block
# ---------------------------------------------------------------------------------------
def plain_plate(nu=0.3, n_elements=20, **options):
    """The reference section over the whole 0.2 m span, no platform mass (the closed forms' beam)."""
    return dataclasses.replace(reference_blade_geometry(), platform_mass=0.0, platform_rotary_inertia=(0.0, 0.0, 0.0),
                               poisson_ratio=nu, n_elements_shank=3 * n_elements // 10,
                               n_elements_airfoil=n_elements - 3 * n_elements // 10, **options)


def by_name(modes):
    return dict(zip(modes.mode_names, modes.frequencies_hz))


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_timoshenko_and_vlasov_beam_against_their_closed_forms(nu):
    """The plain plate (4.57 x 45.5 mm over 0.2 m) with bending_theory "timoshenko" and
    torsion_theory "vlasov" against the exact solutions of the same equations
    (solid.cantilever_frequencies_hz(theory="refined"): Timoshenko with Cowper's kappa and rotary
    inertia, Vlasov with the solid rectangle's C_w, the clamp holding the warping). Measured with
    20 elements: 1F 2e-7, 2F 9e-6, 1E 2e-5; 1T -1.3e-5 (20), -5.1e-5 (40 elements): the element
    has the warping inertia rho C_w phi_t'^2, the closed form not (without it the element
    converges to the closed form as h^4, 3e-5 at 20 and 7e-9 at 160 elements). Against the
    Euler-Bernoulli / St. Venant forms they move 1E by -3.8 % and 1T by +6.0 %."""
    refined = solid.cantilever_frequencies_hz(plain_plate(nu), theory="refined")
    classical = solid.cantilever_frequencies_hz(plain_plate(nu))
    coarse = by_name(beam_modes(plain_plate(nu, bending_theory="timoshenko", torsion_theory="vlasov")))
    fine = by_name(beam_modes(plain_plate(nu, 40, bending_theory="timoshenko", torsion_theory="vlasov")))
    for name, tol in (("1F", 1e-6), ("2F", 3e-5), ("1E", 5e-5), ("1T", 1e-4)):
        assert coarse[name] / refined[name] == pytest.approx(1.0, abs=tol), name
        assert fine[name] / refined[name] == pytest.approx(1.0, abs=tol), name
    assert -1e-4 < fine["1T"] / refined["1T"] - 1 < -2e-5            # warping inertia lowers it
    assert coarse["1E"] / classical["1E"] < 0.97 and coarse["1T"] / classical["1T"] > 1.05
    # each option acts on its own modes only
    eb_vlasov = by_name(beam_modes(plain_plate(nu, torsion_theory="vlasov")))
    timo_sv = by_name(beam_modes(plain_plate(nu, bending_theory="timoshenko")))
    plain = by_name(beam_modes(plain_plate(nu)))
    assert eb_vlasov["1E"] == pytest.approx(plain["1E"], rel=1e-9) and eb_vlasov["1T"] == pytest.approx(coarse["1T"], rel=1e-9)
    assert timo_sv["1T"] == pytest.approx(plain["1T"], rel=1e-9) and timo_sv["1E"] == pytest.approx(coarse["1E"], rel=1e-9)


def test_timoshenko_without_shear_and_vlasov_without_warping_are_the_plain_beam():
    """Limits: a slender square bar (L / a = 50) has negligible shear deformation and rotary
    inertia: Timoshenko's 1F is Euler-Bernoulli's to 1e-3. Its warping is small too (C_w =
    1.3e-4 a^6, decay length sqrt(E C_w / (G J)) = 0.2 mm): the Vlasov closed form is 0.1 % above
    St. Venant's, and the Vlasov beam converges to it, but slowly when the elements are much
    longer than the decay length, since the clamp holds phi_z' = 0 over the whole first element
    (measured +0.60 % / +0.12 % against St. Venant with 20 / 160 elements)."""
    a, L = 4e-3, 0.2

    def bar(n, **options):
        return BeamBladeGeometry(shank_length=0.06, shank_thickness_x=a, shank_chord_y=a, airfoil_length=L - 0.06,
                                 airfoil_thickness_x=a, airfoil_chord_y=a, platform_half_width=0.012,
                                 n_elements_shank=3 * n // 10, n_elements_airfoil=n - 3 * n // 10, **options)
    g = bar(20)
    E, G, rho = g.youngs_modulus, g.shear_modulus, g.density
    J, Ip = torsion_constant_rectangle(a, a), a**4 / 6
    st_venant = 1 / (4 * L) * np.sqrt(G * J / (rho * Ip))
    vlasov = solid.vlasov_cantilever_frequency_hz(L, G * J, E * warping_constant_rectangle(a, a), rho * Ip)
    assert vlasov / st_venant - 1 == pytest.approx(1e-3, rel=0.01)
    coarse = by_name(beam_modes(bar(20, bending_theory="timoshenko", torsion_theory="vlasov")))
    fine = by_name(beam_modes(bar(160, torsion_theory="vlasov")))
    assert 0 < coarse["1T"] / vlasov - 1 < 6e-3 and 0 < fine["1T"] / vlasov - 1 < 3e-4
    plain = by_name(beam_modes(g))
    euler = bending_closed_form_hz(0, L, E, a**4 / 12, rho, a * a)
    assert coarse["1F"] / euler == pytest.approx(1.0, abs=1e-3) and coarse["1F"] < plain["1F"]
    assert plain["1T"] / st_venant == pytest.approx(1.0, abs=1e-3)


def test_platform_block_limits_give_the_plain_beam():
    """A block of zero height is no block (the same model, to the bit); a block with the blade's
    own section and the lumped plate kept is the plain beam on a mesh with two more nodes (1e-5 in
    bending, 1e-4 in torsion: the linear torsion element's discretisation error, 2.6e-4 on this
    mesh); with Vlasov torsion a block of zero height keeps the plain beam's warping continuous."""
    g = reference_blade_geometry()
    z_p = g.shank_length
    flat = dataclasses.replace(g, platform_block=PlatformBlock(z_p, z_p, 0.03, 0.05))
    old, same = beam_modes(g), beam_modes(flat)
    np.testing.assert_array_equal(same.frequencies_hz, old.frequencies_hz)
    np.testing.assert_array_equal(ModalBlade.from_beam(flat).shape("OL"), ModalBlade.from_beam(g).shape("OL"))
    blade_section = PlatformBlock(z_p - 3e-3, z_p + 2e-3, g.shank_thickness_x, g.shank_chord_y)
    own = dataclasses.replace(g, platform_block=blade_section)
    assert own.mass == pytest.approx(g.mass, rel=1e-12)
    np.testing.assert_allclose(beam_modes(own).frequencies_hz[:4], old.frequencies_hz[:4], rtol=2e-4)
    np.testing.assert_allclose(beam_modes(own).frequencies_hz[[0, 1, 3]], old.frequencies_hz[[0, 1, 3]], rtol=1e-5)
    np.testing.assert_allclose(ModalBlade.from_beam(own).shape("tip"), ModalBlade.from_beam(g).shape("tip"),
                               rtol=0, atol=5e-5 * 176.1)                 # 176 rad/sqrt(kg): 1T's phi_z
    vlasov = dataclasses.replace(g, torsion_theory="vlasov")
    np.testing.assert_array_equal(beam_modes(dataclasses.replace(vlasov, platform_block=flat.platform_block)).frequencies_hz,
                                  beam_modes(vlasov).frequencies_hz)


def test_platform_block_is_stiff_and_holds_the_warping_by_its_y_twist():
    """The reference geometry with its 30 x 50 x 4 mm plate as a block instead of the lumped mass:
    the same mass (the block replaces the blade's own 4 mm), the bending frequencies rise (the
    block stiffens the shank over its height). Vlasov torsion: the block's y-twist spring
    G J_xz chord_y lies between the free warping (J_xz -> 0) and the held warping (inf) at the
    block, and 1T rises with it; the modes stay mass-normalised."""
    g = dataclasses.replace(reference_blade_geometry(), bending_theory="timoshenko", torsion_theory="vlasov")
    z_p = g.shank_length
    block = PlatformBlock(z_p - 2e-3, z_p + 2e-3, 0.030, 0.050)
    blocked = dataclasses.replace(g, platform_block=block, platform_mass=0.0, platform_rotary_inertia=(0.0, 0.0, 0.0))
    assert blocked.mass == pytest.approx(g.mass, rel=1e-12)
    assert block.warping_stiffness(g.shear_modulus) == pytest.approx(
        g.shear_modulus * torsion_constant_rectangle(0.030, 0.004) * 0.050, rel=1e-12)
    lumped, f = by_name(beam_modes(g)), by_name(beam_modes(blocked))
    for name in ("1F", "2F", "1E"):
        assert f[name] > lumped[name], name
    f_free = by_name(beam_modes(dataclasses.replace(blocked, platform_block=dataclasses.replace(block, torsion_constant_xz=1e-30))))
    f_held = by_name(beam_modes(dataclasses.replace(blocked, platform_block=dataclasses.replace(block, torsion_constant_xz=np.inf))))
    assert f_free["1T"] < f["1T"] < f_held["1T"]
    assert f_held["1T"] / f_free["1T"] > 1.05 and f_free["1F"] == pytest.approx(f["1F"], rel=1e-9)
    modes = beam_modes(blocked)
    V = modes.vectors
    np.testing.assert_allclose(V.T @ modes.mass @ V, np.eye(V.shape[1]), atol=1e-9)
    full = modes.full_vectors()
    assert full.shape[0] == 7 * modes.n_nodes and modes.tied_dofs.shape == (2, 2)
    np.testing.assert_array_equal(full[modes.tied_dofs[:, 0]], full[modes.tied_dofs[:, 1]])


def test_torsion_constant_of_a_polygon():
    """Prandtl's stress function by finite differences: a rectangle against the series (0.1 %),
    the same for any vertex order and position; a thin strip approaches b t^3 / 3 (1 - 0.630 t / b)."""
    rect = np.array([[-15e-3, 0.0], [15e-3, 0.0], [15e-3, 5e-3], [-15e-3, 5e-3]])
    exact = torsion_constant_rectangle(30e-3, 5e-3)
    assert torsion_constant_polygon(rect) == pytest.approx(exact, rel=1e-3)
    assert torsion_constant_polygon(rect[::-1] + 0.1) == pytest.approx(torsion_constant_polygon(rect), rel=1e-9)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) * 1e-2
    assert torsion_constant_polygon(square) == pytest.approx(0.1406 * 1e-8, rel=2e-3)
    # a triangle (equilateral, side s): J = sqrt(3) s^4 / 80
    s3 = 0.02
    tri = np.array([[0, 0], [s3, 0], [s3 / 2, s3 * np.sqrt(3) / 2]])
    assert torsion_constant_polygon(tri, n_cells=80) == pytest.approx(np.sqrt(3) * s3**4 / 80, rel=5e-3)
    with pytest.raises(ValueError, match="polygon"):
        torsion_constant_polygon(np.zeros((2, 2)))


def test_platform_block_from_a_polygon_keeps_its_volume():
    poly = np.array([[-0.01, 0.056], [0.01, 0.056], [0.015, 0.060], [0.015, 0.062], [-0.015, 0.062], [-0.015, 0.060]])
    block = PlatformBlock.from_polygon(poly, 0.05)
    area = 0.03 * 0.006 - 2 * 0.5 * 0.005 * 0.004                  # (x, z) box minus the two cut corners
    assert (block.z_bottom, block.z_top, block.chord_y) == pytest.approx((0.056, 0.062, 0.05))
    assert block.section.area * block.height == pytest.approx(area * 0.05, rel=1e-12)
    assert block.torsion_constant_xz == pytest.approx(torsion_constant_polygon(poly), rel=1e-12)
    with pytest.raises(ValueError, match="z_top"):
        PlatformBlock(0.06, 0.05, 0.03, 0.05)
    with pytest.raises(ValueError, match="torsion_constant_xz"):
        PlatformBlock(0.05, 0.06, 0.03, 0.05, torsion_constant_xz=0.0)
