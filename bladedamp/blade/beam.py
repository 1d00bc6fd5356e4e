"""The beam blade: rectangular sections, the platform, the beam finite-element model and its modes.

Frames and conventions: the blade package's (:mod:`bladedamp.blade`): x circumferential
(flatwise bending, 1F), y axial, z radial along the span (root at z = 0); 6-vectors
(u_x, u_y, u_z, phi_x, phi_y, phi_z) [m, rad]; SI units.

:class:`BeamBladeGeometry` is a straight blade of two rectangular sections (shank below the
platform node, airfoil above it) with the platform as a lumped rigid plate (or a stiff block of
its own section, :class:`PlatformBlock`), clamped at the root. :func:`assemble_beam` builds its
Euler-Bernoulli or Timoshenko bending and St. Venant or Vlasov torsion frame elements,
:func:`beam_modes` its clamped modes, named by family ("1F", "1E", "1T", "1A", ...);
:meth:`bladedamp.blade.modal.ModalBlade.from_beam` turns them into a modal blade.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from bladedamp import validation as check


# DOF indices inside a 6-vector.
UX, UY, UZ, PHIX, PHIY, PHIZ = range(6)
# Mode families of a straight beam with a doubly symmetric section (uncoupled):
# F = flatwise bending in x (u_x, phi_y), E = edgewise bending in y (u_y, phi_x),
# T = torsion (phi_z), A = axial (u_z).
_FAMILY_DOFS = {"F": (UX, PHIY), "E": (UY, PHIX), "T": (PHIZ,), "A": (UZ,)}
# DOF whose tip value is made positive (sign convention of the returned shapes).
_FAMILY_SIGN_DOF = {"F": UX, "E": UY, "T": PHIZ, "A": UZ}


# --------------------------------------------------------------------------------------
# Small kinematic / section helpers
# --------------------------------------------------------------------------------------
def rigid_offset_motion(node_motion: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """Motion of a point rigidly attached to a node (small rotations).

    Parameters
    ----------
    node_motion : (6,) or (6, n) array
        Node 6-vector(s) (u_x, u_y, u_z [m], phi_x, phi_y, phi_z [rad]); real or complex.
    offset : (3,) array
        Position of the point minus position of the node [m].

    Returns
    -------
    (6,) or (6, n) array: translations u + phi x r, rotations phi.
    """
    node_motion = np.asarray(node_motion)
    r = np.asarray(offset, dtype=float)
    if node_motion.shape[0] != 6:
        raise ValueError(f"node_motion must have 6 rows (got shape {node_motion.shape})")
    if r.shape != (3,):
        raise ValueError(f"offset must have shape (3,) (got {r.shape})")
    u, phi = node_motion[:3], node_motion[3:]
    # phi x r, written out so it works for (3,) and (3, n) alike
    phi_cross_r = np.stack([
        phi[1] * r[2] - phi[2] * r[1],
        phi[2] * r[0] - phi[0] * r[2],
        phi[0] * r[1] - phi[1] * r[0],
    ])
    return np.concatenate([u + phi_cross_r, phi], axis=0)


def torsion_constant_rectangle(side_a: float, side_b: float, n_terms: int = 50) -> float:
    """St. Venant torsion constant J [m^4] of a solid rectangle (series solution).

    J = a b^3 / 3 * [1 - 192/pi^5 * (b/a) * sum_{n odd} tanh(n pi a / (2 b)) / n^5],
    with a >= b the long and short sides (Timoshenko & Goodier).  Square: J = 0.1406 a^4.
    """
    a = check.positive("side_a", side_a)
    b = check.positive("side_b", side_b)
    a, b = max(a, b), min(a, b)
    n = np.arange(1, 2 * n_terms, 2, dtype=float)
    series = np.sum(np.tanh(n * np.pi * a / (2.0 * b)) / n**5)
    return a * b**3 / 3.0 * (1.0 - 192.0 / np.pi**5 * (b / a) * series)


def torsion_constant_polygon(polygon, n_cells: int = 40) -> float:
    """St. Venant torsion constant J [m^4] of a simple polygonal section (n, 2) [m] (any
    orientation), from Prandtl's stress function: laplace(Phi) = -2 inside, Phi = 0 on the
    boundary, J = 2 int Phi dA (Timoshenko & Goodier, Theory of Elasticity, torsion).

    Finite differences (5-point Laplacian) on square cells, ``n_cells`` and 2 ``n_cells``
    across the smaller side of the bounding box, a cell inside if its centre is; the staircase
    boundary makes the error O(h), removed by Richardson extrapolation 2 J(h/2) - J(h); about
    0.1 % at the default (checked against :func:`torsion_constant_rectangle`).
    """
    poly = np.asarray(polygon, dtype=float)
    if poly.ndim != 2 or poly.shape[1] != 2 or poly.shape[0] < 3:
        raise ValueError(f"polygon must be an (n >= 3, 2) array of vertices [m] (got shape {poly.shape})")
    n_cells = check.integer("n_cells", n_cells, minimum=4)
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    check.positive("polygon extent", float((hi - lo).min()))

    def solve(n):
        h = float((hi - lo).min()) / n
        X, Y = np.meshgrid(np.arange(lo[0] + h / 2, hi[0], h), np.arange(lo[1] + h / 2, hi[1], h), indexing="ij")
        inside = np.zeros(X.shape, dtype=bool)            # ray casting, edge by edge
        for (x0, y0), (x1, y1) in zip(poly, np.roll(poly, -1, axis=0)):
            if y0 != y1:
                crosses = (y0 > Y) != (y1 > Y)
                inside ^= crosses & (X < x0 + (Y - y0) * (x1 - x0) / (y1 - y0))
        index = -np.ones(X.shape, dtype=int)
        index[inside] = np.arange(inside.sum())
        I, K = np.nonzero(inside)
        rows, cols, vals = [index[I, K]], [index[I, K]], [np.full(I.size, 4.0)]
        for di, dk in ((1, 0), (-1, 0), (0, 1), (0, -1)):   # neighbours outside are Phi = 0
            i, k = I + di, K + dk
            ok = (i >= 0) & (i < X.shape[0]) & (k >= 0) & (k < X.shape[1])
            ok[ok] = inside[i[ok], k[ok]]
            rows.append(index[I[ok], K[ok]])
            cols.append(index[i[ok], k[ok]])
            vals.append(-np.ones(int(ok.sum())))
        A = scipy.sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                    shape=(I.size, I.size))
        phi = scipy.sparse.linalg.spsolve(A.tocsc(), np.full(I.size, 2.0 * h * h))
        return 2.0 * phi.sum() * h * h

    return 2.0 * solve(2 * n_cells) - solve(n_cells)


def warping_constant_rectangle(side_a: float, side_b: float, n_terms: int = 50) -> float:
    """Warping constant C_w = int psi^2 dA [m^6] of a solid rectangle with sides ``side_a``,
    ``side_b`` [m], psi the exact St. Venant warping function [m^2] about the centroid (the shear
    centre of the doubly symmetric section).

    With t <= c the short and long sides, x across t, y along c, h = t / 2 and k_n = n pi / t, the
    series solution of the rectangle's torsion (Timoshenko & Goodier, Theory of Elasticity, torsion
    of rectangular bars) is
    psi = x y - sum_{n odd} C_n (-1)^((n-1)/2) sin(k_n x) sinh(k_n y) / cosh(k_n c / 2),
    C_n = 32 h^2 / (pi^3 n^3). The sines are orthogonal on |x| <= h, so term by term
    C_w = t^3 c^3 / 144 - 2 sum C_n X_n Y_n + h sum C_n^2 S_n with X_n = 2 / k_n^2,
    Y_n = 2 (c / (2 k_n) - tanh(k_n c / 2) / k_n^2), S_n = tanh(k_n c / 2) / k_n - (c / 2) / cosh^2(k_n c / 2).

    Thin rectangle: C_w -> t^3 c^3 / 144 (psi -> x y, the sectorial coordinate of a thin strip,
    the thin-walled value), expanded C_w = t^3 c^3 / 144 (1 - 4.8 (t/c)^2 + 4.58 (t/c)^3 + ...);
    the reference airfoil (4.57 x 45.5 mm, c / t = 9.96) has 0.956 of it, 5.9700e-14 m^6. Both that
    and a square's 1.3440e-4 a^6 are the values of sectionproperties' finite-element warping analysis
    (version 3.10, Pilkey's method: Pilkey, Analysis and Design of Elastic Beams, 2002) to 1e-8 and
    2e-6. A solid rectangle is not thin-walled: Vlasov's torsion with this C_w is an approximation
    (checked on the solid plain plate).
    """
    a = check.positive("side_a", side_a)
    b = check.positive("side_b", side_b)
    t, c = min(a, b), max(a, b)
    h, half_c = t / 2.0, c / 2.0
    n = np.arange(1, 2 * check.integer("n_terms", n_terms, minimum=1), 2, dtype=float)
    k = n * np.pi / t
    C = 32.0 * h**2 / (np.pi**3 * n**3)
    X = 2.0 / k**2
    th = np.tanh(k * half_c)
    Y = 2.0 * (half_c / k - th / k**2)
    sech2 = np.where(k * half_c < 350.0, 1.0 / np.cosh(np.minimum(k * half_c, 350.0))**2, 0.0)
    S = th / k - half_c * sech2
    return float(t**3 * c**3 / 144.0 - 2.0 * np.sum(C * X * Y) + h * np.sum(C**2 * S))



@dataclass(eq=False)
class RectangularSection:
    """Section properties of a solid rectangle: thickness along x, chord along y [m]."""

    thickness_x: float
    chord_y: float

    @property
    def area(self) -> float:
        """Cross-section area A [m^2]."""
        return self.thickness_x * self.chord_y

    @property
    def second_moment_flatwise(self) -> float:
        """I_yy [m^4], governs bending in x (u_x, phi_y): chord * thickness^3 / 12."""
        return self.chord_y * self.thickness_x**3 / 12.0

    @property
    def second_moment_edgewise(self) -> float:
        """I_xx [m^4], governs bending in y (u_y, phi_x): thickness * chord^3 / 12."""
        return self.thickness_x * self.chord_y**3 / 12.0

    @property
    def polar_moment(self) -> float:
        """I_p = I_xx + I_yy [m^4] (torsional inertia per unit length is rho * I_p)."""
        return self.second_moment_flatwise + self.second_moment_edgewise

    @property
    def torsion_constant(self) -> float:
        """St. Venant torsion constant J [m^4]."""
        return torsion_constant_rectangle(self.thickness_x, self.chord_y)

    @property
    def warping_constant(self) -> float:
        """Warping constant C_w = int psi^2 dA [m^6] of the solid rectangle (exact St. Venant warping
        function psi: :func:`warping_constant_rectangle`)."""
        return warping_constant_rectangle(self.thickness_x, self.chord_y)

    @staticmethod
    def shear_coefficient(poisson_ratio: float) -> float:
        """Cowper's Timoshenko shear coefficient of a rectangle, kappa = 10 (1 + nu) / (12 + 11 nu)
        [-] (Cowper 1966, J. Appl. Mech. 33, 335; 5/6 at nu = 0, 0.850 at nu = 0.3)."""
        return 10.0 * (1.0 + poisson_ratio) / (12.0 + 11.0 * poisson_ratio)


# --------------------------------------------------------------------------------------
# Beam blade geometry and FE model
# --------------------------------------------------------------------------------------
def platform_section(centres, gamma_left: float, gamma_right: float, edge: float, top: float,
                     face_inner_length: float, min_edge_thickness: float) -> np.ndarray:
    """(6, 2) (x, z) section of the platform prism [m], of the 3D view
    (:func:`bladedamp.geometry.blade_mesh`) and the solid FE blade (:mod:`bladedamp.blade.solid`):
    ``l_in, r_in, r_out, r_top, l_top, l_out``: top at z = top, edges at x = -/+ edge, undersides
    through the contact centres inclined by gamma_L (OL, -x side) and gamma_R (OR, +x side), a
    flat bottom between them. The undersides run from
    ``*_in`` (``face_inner_length`` toward the axis from the contact centre) to ``*_out`` (at the
    edge x = -/+ edge, or where they come within ``min_edge_thickness`` of the top z = top)."""
    sides = []
    for side, (centre, gamma) in enumerate(zip(centres, (gamma_left, gamma_right))):
        sign = -1.0 if side == 0 else 1.0                      # OL face on -x, OR face on +x
        c = np.array([centre[0], centre[2]])
        t = np.array([sign * np.cos(gamma), np.sin(gamma)])    # along the face, outward and up
        s_edge = (edge - sign * c[0]) / np.cos(gamma)
        s_top = (top - min_edge_thickness - c[1]) / np.sin(gamma)
        s_out = max(min(s_edge, s_top), 1e-6)
        inner, outer = c - face_inner_length * t, c + s_out * t
        sides.append((inner, outer, np.array([outer[0], top])))
    (l_in, l_out, l_top), (r_in, r_out, r_top) = sides
    return np.array([l_in, r_in, r_out, r_top, l_top, l_out])


BENDING_THEORIES = ("euler-bernoulli", "timoshenko")
TORSION_THEORIES = ("st-venant", "vlasov")


@dataclass(frozen=True)
class PlatformBlock:
    """The platform as a stiff beam segment of its own section (option ``platform_block`` of
    :class:`BeamBladeGeometry`), instead of a rigid lumped mass on one node.

    Over z_bottom <= z <= z_top the beam's elements have the block's rectangular section
    (thickness_x along x, chord_y along y, centred on the blade axis) instead of the blade's:
    its bending stiffness (per the geometry's bending theory), St. Venant torsion stiffness and
    its mass rho A and inertia replace the blade section's there, so the blade's own volume
    inside the block is counted once. The block must hold the platform node,
    0 < z_bottom <= shank_length <= z_top < total_length; z_bottom = z_top is no block (the
    plain beam). The platform node stays where OL, OR and "platform" are attached: the block is
    stiff, so they move with it.

    Warping (the geometry's torsion_theory "vlasov"): the blade's warping where it enters the
    block, u_z = -psi phi_z' with psi ~ x y for the thin section, is the block twisting about its
    own y axis at the rate theta = phi_z' (its (x, z) sections rotating by theta y, so u_z =
    -theta x y). So the shank's phi_z' at z_bottom and the airfoil's at z_top are one DOF theta,
    resisted by the block's St. Venant stiffness about y, a bimoment spring k_w = G J_xz chord_y
    [N m^3], J_xz the torsion constant of the block's (x, z) section. The block's own elements
    carry St. Venant torsion about z only. J_xz = inf: the block holds the warping at both faces
    (a rigid platform; it is also what phi_z' continuity through a block of large G J gives).
    Left out: the y-twist's inertia (its own frequency sqrt(k_w / (rho chord_y^3 / 12 I_p,xz)),
    12.6 kHz for the reference prism, 15 times 1T) and the local deformation where the thin
    blade enters the block (the coupling is not a rigid spine, and the block's y-twist also
    shears the blade's section at the faces). With k_w the beam's 1T is within a few per cent
    of the solid blade's (benchmarks/README.md, 'Moved from the package's docstrings', blade.py).

    Attributes
    ----------
    z_bottom, z_top : z range of the block [m].
    thickness_x, chord_y : sides of its section along x and y [m], > 0.
    n_elements : beam elements below and above the platform node each (>= 1).
    torsion_constant_xz : J_xz [m^4], > 0 or math.inf; None (default): the rectangle
        thickness_x x height (:func:`torsion_constant_rectangle`).
    """

    z_bottom: float
    z_top: float
    thickness_x: float
    chord_y: float
    n_elements: int = 1
    torsion_constant_xz: float | None = None

    def __post_init__(self):
        for name in ("z_bottom", "z_top", "thickness_x", "chord_y"):
            object.__setattr__(self, name, check.finite(name, getattr(self, name)))
        check.positive("thickness_x", self.thickness_x)
        check.positive("chord_y", self.chord_y)
        if self.z_top < self.z_bottom:
            raise ValueError(f"platform_block: z_top = {self.z_top:g} m must be >= z_bottom = "
                             f"{self.z_bottom:g} m")
        object.__setattr__(self, "n_elements", check.integer("n_elements", self.n_elements, minimum=1))
        if self.torsion_constant_xz is not None:
            J = float(self.torsion_constant_xz)
            if not (J > 0.0):                                     # inf allowed: rigid against warping
                raise ValueError(f"platform_block: torsion_constant_xz must be > 0 [m^4] or inf (got {J!r})")
            object.__setattr__(self, "torsion_constant_xz", J)

    @property
    def height(self) -> float:
        """z_top - z_bottom [m]."""
        return self.z_top - self.z_bottom

    @property
    def warping_torsion_constant(self) -> float:
        """J_xz [m^4] that resists the blade's warping at the block (inf: rigid)."""
        if self.torsion_constant_xz is not None:
            return self.torsion_constant_xz
        return torsion_constant_rectangle(self.thickness_x, self.height) if self.height > 0 else math.inf

    def warping_stiffness(self, shear_modulus: float) -> float:
        """Bimoment spring k_w = G J_xz chord_y [N m^3] at the block (inf: warping held)."""
        return shear_modulus * self.warping_torsion_constant * self.chord_y

    @property
    def section(self) -> RectangularSection:
        return RectangularSection(self.thickness_x, self.chord_y)

    @classmethod
    def from_polygon(cls, polygon_xz, length_y: float, n_elements: int = 1) -> "PlatformBlock":
        """The block of a prism: the (x, z) polygon ``polygon_xz`` (n, 2) [m] extruded over
        ``length_y`` [m] along y (the solid blade's platform: ``SolidBladeGeometry.platform_polygon()``
        and ``platform_length``). z range: the polygon's; chord_y = length_y; thickness_x = polygon
        area / height, so the block has the prism's volume and mass; torsion_constant_xz: the
        polygon's (:func:`torsion_constant_polygon`), which resists the blade's warping. Left out:
        how the prism's width varies over its height (its centre of gravity and rotary inertia
        differ from the block's by a fraction of its 5 mm height in the reference) and any x
        offset of its centroid (gamma_L != gamma_R)."""
        poly = np.asarray(polygon_xz, dtype=float)
        if poly.ndim != 2 or poly.shape[1] != 2 or poly.shape[0] < 3:
            raise ValueError(f"polygon_xz must be an (n >= 3, 2) array of (x, z) [m] (got shape {poly.shape})")
        x, z = poly[:, 0], poly[:, 1]
        area = 0.5 * abs(np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1)))   # shoelace
        height = float(z.max() - z.min())
        check.positive("polygon_xz height", height)
        return cls(float(z.min()), float(z.max()), area / height, check.positive("length_y", length_y),
                   n_elements, torsion_constant_polygon(poly))


@dataclass(eq=False)
class BeamBladeGeometry:
    """Simplified blade of the paper's Fig. 4: clamped root, shank, platform, airfoil.

    Straight beam along z with constant rectangular sections (thickness along x, chord
    along y): shank z in [0, shank_length], airfoil z in [shank_length, shank_length +
    airfoil_length].  The platform is a rigid body on the node at z = shank_length
    (platform height = top of shank) carrying a lumped mass and rotary inertia (its centre
    of gravity is taken at that node).  The contact control points are rigidly attached to
    the platform node: OL at (-platform_half_width, 0, shank_length -
    platform_contact_z_offset), OR at (+platform_half_width, 0, same z).

    Options beyond the plain beam (defaults: the plain beam, which the reference blade's
    calibration used):

    * ``bending_theory``: "euler-bernoulli" (default; Hermite element, no rotary inertia) or
      "timoshenko" (shear deformation with Cowper's kappa and the rotary inertia rho I of both
      bending planes; :func:`_timoshenko_matrices`).
    * ``torsion_theory``: "st-venant" (default; uniform torsion G J, linear element) or "vlasov"
      (non-uniform torsion with the section's warping stiffness E C_w, C_w of the solid rectangle:
      a 7th DOF per node, the rate of twist phi_z' that scales the warping, held at the clamped
      root and continuous across nodes; :func:`_vlasov_matrices`). The clamp holds phi_z' = 0 over
      the first element, so elements much longer than the warping decay length
      sqrt(E C_w / (G J)) are too stiff near it (a 4 mm square bar, decay length 0.2 mm, 10 mm
      elements: 1T +0.5 %); the reference section's is 10.7 mm, and its 10 mm elements are within
      2e-5 of the closed form.
    * ``platform_block``: the platform as a stiff beam segment of its own section
      (:class:`PlatformBlock`, e.g. :meth:`PlatformBlock.from_polygon` of the solid blade's
      prism; :func:`solid_platform_beam`). ``platform_mass`` and ``platform_rotary_inertia`` are
      still added on the platform node: set them to what the block does not hold (0 when it is
      the whole platform), so nothing is counted twice.

    Attributes (SI units)
    ----------
    shank_length : shank length = platform height above the clamped root [m], > 0.
    shank_thickness_x, shank_chord_y : shank section sides along x and y [m], > 0.
    airfoil_length : airfoil length from platform to tip [m], > 0.
    airfoil_thickness_x, airfoil_chord_y : airfoil section sides along x and y [m], > 0.
    platform_half_width : x distance from the blade axis to OL / OR [m], > 0.
    platform_contact_z_offset : contact points lie this far below the platform node [m],
        in [0, shank_length].
    platform_mass : lumped platform mass [kg], >= 0.
    platform_rotary_inertia : (I_xx, I_yy, I_zz) of the platform about its CG [kg m^2], >= 0.
    youngs_modulus : E [Pa], > 0.
    poisson_ratio : nu [-], in (-1, 0.5); shear modulus G = E / (2 (1 + nu)).
    density : rho [kg/m^3], > 0.
    n_elements_shank, n_elements_airfoil : number of beam elements, >= 1.
    tip_point : (3,) [m] or None (= on the axis at the tip, (0, 0, L_total)).
    excitation_point : (3,) [m] or None (= tip_point).
    bending_theory : one of :data:`BENDING_THEORIES` (default "euler-bernoulli").
    torsion_theory : one of :data:`TORSION_THEORIES` (default "st-venant").
    platform_block : :class:`PlatformBlock` or None (default: the lumped rigid platform only).
    """

    shank_length: float
    shank_thickness_x: float
    shank_chord_y: float
    airfoil_length: float
    airfoil_thickness_x: float
    airfoil_chord_y: float
    platform_half_width: float
    platform_contact_z_offset: float = 0.0
    platform_mass: float = 0.0
    platform_rotary_inertia: tuple[float, float, float] = (0.0, 0.0, 0.0)
    youngs_modulus: float = 210e9
    poisson_ratio: float = 0.3
    density: float = 7850.0
    n_elements_shank: int = 6
    n_elements_airfoil: int = 20
    tip_point: np.ndarray | None = None
    excitation_point: np.ndarray | None = None
    bending_theory: str = "euler-bernoulli"
    torsion_theory: str = "st-venant"
    platform_block: PlatformBlock | None = None

    def __post_init__(self):
        for name in ("shank_length", "shank_thickness_x", "shank_chord_y", "airfoil_length",
                     "airfoil_thickness_x", "airfoil_chord_y", "platform_half_width",
                     "youngs_modulus", "density"):
            setattr(self, name, check.positive(name, getattr(self, name)))
        self.platform_contact_z_offset = check.in_range(
            "platform_contact_z_offset", self.platform_contact_z_offset, 0.0, self.shank_length)
        self.platform_mass = check.nonnegative("platform_mass", self.platform_mass)
        inertia = np.asarray(self.platform_rotary_inertia, dtype=float)
        if inertia.shape != (3,):
            raise ValueError(
                f"platform_rotary_inertia must be (I_xx, I_yy, I_zz) [kg m^2], shape (3,) "
                f"(got {inertia.shape})")
        self.platform_rotary_inertia = tuple(
            float(v) for v in check.nonnegative("platform_rotary_inertia", inertia))
        self.poisson_ratio = check.in_range("poisson_ratio", self.poisson_ratio, -1.0, 0.5,
                                            closed="neither")
        self.n_elements_shank = check.integer("n_elements_shank", self.n_elements_shank, minimum=1)
        self.n_elements_airfoil = check.integer("n_elements_airfoil", self.n_elements_airfoil,
                                                minimum=1)
        for name in ("tip_point", "excitation_point"):
            value = getattr(self, name)
            if value is None:
                continue
            arr = np.array(value, dtype=float)
            if arr.shape != (3,):
                raise ValueError(f"{name} must be None or a (3,) position [m] (got shape {arr.shape})")
            check.finite(name, arr)
            check.in_range(f"{name} z", arr[2], 0.0, self.total_length)
            setattr(self, name, arr)
        if self.bending_theory not in BENDING_THEORIES:
            raise ValueError(f"bending_theory must be one of {BENDING_THEORIES} (got {self.bending_theory!r})")
        if self.torsion_theory not in TORSION_THEORIES:
            raise ValueError(f"torsion_theory must be one of {TORSION_THEORIES} (got {self.torsion_theory!r})")
        block = self.platform_block
        if block is not None:
            if not isinstance(block, PlatformBlock):
                raise ValueError(f"platform_block must be None or a PlatformBlock (got {type(block).__name__})")
            if not 0.0 < block.z_bottom <= self.shank_length <= block.z_top < self.total_length:
                raise ValueError(
                    f"platform_block must hold the platform node and lie inside the blade: 0 < z_bottom "
                    f"<= shank_length <= z_top < total_length (got z_bottom = {block.z_bottom:g} m, "
                    f"shank_length = {self.shank_length:g} m, z_top = {block.z_top:g} m, total_length = "
                    f"{self.total_length:g} m)")

    @property
    def total_length(self) -> float:
        """L_total = shank_length + airfoil_length [m] (z of the tip)."""
        return self.shank_length + self.airfoil_length

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def shank_section(self) -> RectangularSection:
        return RectangularSection(self.shank_thickness_x, self.shank_chord_y)

    @property
    def airfoil_section(self) -> RectangularSection:
        return RectangularSection(self.airfoil_thickness_x, self.airfoil_chord_y)

    @property
    def block(self) -> PlatformBlock | None:
        """The platform block if it has a height, else None (the plain beam)."""
        b = self.platform_block
        return b if b is not None and b.height > 0 else None

    @property
    def mass(self) -> float:
        """Total blade mass (shank + airfoil + platform block + lumped platform) [kg]."""
        b = self.block
        z_lo, z_hi = (b.z_bottom, b.z_top) if b is not None else (self.shank_length,) * 2
        return (self.density * (self.shank_section.area * z_lo
                                + self.airfoil_section.area * (self.total_length - z_hi)
                                + (b.section.area * b.height if b is not None else 0.0))
                + self.platform_mass)

    def points(self) -> dict[str, np.ndarray]:
        """Named points [m]: "OL", "OR", "platform" (node on the axis), "tip", "excitation"."""
        z_contact = self.shank_length - self.platform_contact_z_offset
        tip = (np.array([0.0, 0.0, self.total_length]) if self.tip_point is None
               else np.array(self.tip_point, dtype=float))
        exc = tip.copy() if self.excitation_point is None else np.array(self.excitation_point, dtype=float)
        return {
            "OL": np.array([-self.platform_half_width, 0.0, z_contact]),
            "OR": np.array([+self.platform_half_width, 0.0, z_contact]),
            "platform": np.array([0.0, 0.0, self.shank_length]),
            "tip": tip,
            "excitation": exc,
        }


@dataclass(eq=False)
class BeamModes:
    """Eigen-solution of the beam FE model (root clamped; all modes, sorted by frequency).

    Attributes
    ----------
    node_z : (n_nodes,) node heights [m]; node 0 is the clamped root.
    platform_node : index of the node carrying the platform.
    stiffness, mass : (n_free, n_free) FE matrices of the free DOF [N/m ...], [kg ...].
    free_dofs : (n_free,) indices of the free DOF in the full vector (6 per node, node after
        node; with Vlasov torsion then the n_nodes rates of twist phi_z' [rad/m]: :func:`n_beam_dofs`).
    frequencies_hz : (n_all,) natural frequencies [Hz], ascending.
    vectors : (n_free, n_all) mass-normalised eigenvectors (vectors.T @ mass @ vectors = I).
    mode_names : (n_all,) classification, e.g. "1F", "2F", "1E", "1T", "1A".
    family_fractions : (n_all, 4) share of modal kinetic energy in families F, E, T, A.
    tied_dofs : (k, 2) full-vector indices (slave, master): slave DOF not solved for, equal to
        the master (the platform block's shared rate of twist; empty otherwise).
    n_dofs : size of the full DOF vector (:func:`n_beam_dofs`).
    """

    node_z: np.ndarray
    platform_node: int
    stiffness: np.ndarray
    mass: np.ndarray
    free_dofs: np.ndarray
    frequencies_hz: np.ndarray
    vectors: np.ndarray
    mode_names: tuple[str, ...]
    family_fractions: np.ndarray = field(repr=False)
    tied_dofs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int), repr=False)
    n_dofs: int | None = None

    def __post_init__(self):
        if self.n_dofs is None:
            self.n_dofs = 6 * self.n_nodes

    @property
    def n_nodes(self) -> int:
        return int(self.node_z.size)

    def full_vectors(self) -> np.ndarray:
        """(n_dofs, n_all) eigenvectors including the zero root DOF (rows 6 node + d: the six
        DOF of each node; with Vlasov torsion rows 6 n_nodes + node: phi_z' [rad/m/sqrt(kg)])."""
        full = np.zeros((self.n_dofs, self.vectors.shape[1]))
        full[self.free_dofs] = self.vectors
        full[self.tied_dofs[:, 0]] = full[self.tied_dofs[:, 1]]
        return full

    def node_shapes(self, node: int) -> np.ndarray:
        """(6, n_all) mode-shape values at a node."""
        return self.full_vectors()[6 * node:6 * node + 6]

    def point_shapes(self, position: np.ndarray, node: int) -> np.ndarray:
        """(6, n_all) mode shapes of a point rigidly attached to ``node`` (u + phi x r)."""
        r = np.asarray(position, dtype=float) - np.array([0.0, 0.0, self.node_z[node]])
        return rigid_offset_motion(self.node_shapes(node), r)

    def point_attachment(self, points: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, int]]:
        """Node each point is attached to: OL, OR, platform -> platform node (rigid platform);
        any other point -> the node nearest in z (exact for points in that node's section)."""
        out = {}
        for name, pos in points.items():
            if name in ("OL", "OR", "platform"):
                node = self.platform_node
            else:
                node = int(np.argmin(np.abs(self.node_z - pos[2])))
            out[name] = (np.asarray(pos, dtype=float), node)
        return out


def _bending_matrices(EI: float, rhoA: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Euler-Bernoulli Hermite element in (w1, theta1, w2, theta2), theta = dw/dz."""
    k = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h],
                              [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                              [-12, -6 * h, 12, -6 * h],
                              [6 * h, 2 * h**2, -6 * h, 4 * h**2]])
    m = rhoA * h / 420.0 * np.array([[156, 22 * h, 54, -13 * h],
                                     [22 * h, 4 * h**2, 13 * h, -3 * h**2],
                                     [54, 13 * h, 156, -22 * h],
                                     [-13 * h, -3 * h**2, -22 * h, 4 * h**2]])
    return k, m


def _bar_matrices(stiffness: float, inertia: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Linear two-node element (axial bar or St. Venant torsion): k/h, consistent mass."""
    k = stiffness / h * np.array([[1.0, -1.0], [-1.0, 1.0]])
    m = inertia * h / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    return k, m


def _hermite_gradient_matrix(h: float) -> np.ndarray:
    """int_0^h N'^T N' dz of the cubic Hermite shape functions N in (w1, w1', w2, w2'):
    1 / (30 h) [[36, 3h, -36, 3h], [3h, 4h^2, -3h, -h^2], [-36, -3h, 36, -3h], [3h, -h^2, -3h, 4h^2]]
    (the rotary-inertia matrix of a Rayleigh beam, the geometric stiffness of a bar)."""
    return 1.0 / (30.0 * h) * np.array([[36, 3 * h, -36, 3 * h],
                                        [3 * h, 4 * h**2, -3 * h, -h**2],
                                        [-36, -3 * h, 36, -3 * h],
                                        [3 * h, -h**2, -3 * h, 4 * h**2]])


def _timoshenko_matrices(EI: float, kGA: float, rhoA: float, rhoI: float, h: float):
    """Two-node Timoshenko element in (w1, psi1, w2, psi2), psi the section rotation (= dw/dz
    without shear), with the interdependent interpolation that is exact for the static beam
    (Friedman & Kosmatka 1993, "An improved two-node Timoshenko beam finite element", Comput.
    Struct. 47, 473; Przemieniecki 1968, Theory of Matrix Structural Analysis): Phi = 12 E I /
    (kappa G A h^2), stiffness E I / ((1 + Phi) h^3) [[12, 6h, -12, 6h], [6h, (4 + Phi) h^2, -6h,
    (2 - Phi) h^2], ...]; consistent mass of the translation rho A and of the rotary inertia rho I.
    Phi = 0, rho I = 0 is the Euler-Bernoulli element (:func:`_bending_matrices`)."""
    P = 12.0 * EI / (kGA * h**2)
    k = EI / ((1.0 + P) * h**3) * np.array([[12, 6 * h, -12, 6 * h],
                                            [6 * h, (4 + P) * h**2, -6 * h, (2 - P) * h**2],
                                            [-12, -6 * h, 12, -6 * h],
                                            [6 * h, (2 - P) * h**2, -6 * h, (4 + P) * h**2]])
    a1, a2 = 70 * P**2 + 147 * P + 78, (35 * P**2 + 77 * P + 44) * h / 4
    a3, a4 = 35 * P**2 + 63 * P + 27, (35 * P**2 + 63 * P + 26) * h / 4
    a5, a6 = (7 * P**2 + 14 * P + 8) * h**2 / 4, (7 * P**2 + 14 * P + 6) * h**2 / 4
    m_t = rhoA * h / (210.0 * (1.0 + P) ** 2) * np.array([[a1, a2, a3, -a4],
                                                          [a2, a5, a4, -a6],
                                                          [a3, a4, a1, -a2],
                                                          [-a4, -a6, -a2, a5]])
    b1, b2 = (15 * P - 3) * h, (10 * P**2 + 5 * P + 4) * h**2
    b3 = (5 * P**2 - 5 * P - 1) * h**2
    m_r = rhoI / (30.0 * (1.0 + P) ** 2 * h) * np.array([[36, -b1, -36, -b1],
                                                         [-b1, b2, b1, b3],
                                                         [-36, b1, 36, b1],
                                                         [-b1, b3, b1, b2]])
    return k, m_t + m_r


def _vlasov_matrices(GJ: float, ECw: float, rhoIp: float, rhoCw: float, h: float):
    """Two-node element of non-uniform (Vlasov) torsion in (phi1, phi1', phi2, phi2'), cubic
    Hermite twist phi: strain energy 1/2 int (G J phi'^2 + E C_w phi''^2) dz, kinetic energy
    1/2 int (rho I_p phi_t^2 + rho C_w phi_t'^2) dz (the warping displacement u_z = -psi phi' and
    its inertia; Vlasov 1961, Thin-Walled Elastic Beams; the element: Barsoum & Gallagher 1970,
    Int. J. Numer. Meth. Eng. 2, 335). E C_w -> 0: St. Venant torsion with a cubic twist."""
    kb, mb = _bending_matrices(ECw, rhoIp, h)
    g = _hermite_gradient_matrix(h)
    return kb + GJ * g, mb + rhoCw * g


def _frame_element(section: RectangularSection, E: float, G: float, rho: float, h: float,
                   nu: float = 0.3, bending_theory: str = "euler-bernoulli",
                   torsion_theory: str = "st-venant"):
    """Stiffness and consistent mass of a straight 3D frame element along z [SI].

    DOF per node (u_x, u_y, u_z, phi_x, phi_y, phi_z): 12 x 12; with torsion_theory "vlasov"
    14 x 14, local DOF 12 and 13 the rate of twist phi_z' [rad/m] of nodes 1 and 2.  Bending in
    x uses slope du_x/dz = +phi_y, bending in y uses du_y/dz = -phi_x (right-handed small
    rotations, consistent with u + phi x r).  bending_theory "euler-bernoulli": Hermite element,
    no rotary inertia; "timoshenko": :func:`_timoshenko_matrices` with Cowper's kappa(nu).
    """
    warping = torsion_theory == "vlasov"
    n = 14 if warping else 12
    K = np.zeros((n, n))
    M = np.zeros((n, n))

    def scatter(k, m, dofs, signs):
        T = np.zeros((len(dofs), n))
        for row, (d, s) in enumerate(zip(dofs, signs)):
            T[row, d] = s
        K[:] += T.T @ k @ T
        M[:] += T.T @ m @ T

    A = section.area
    kGA = section.shear_coefficient(nu) * G * A
    for I, dofs, signs in ((section.second_moment_flatwise, (UX, PHIY, 6 + UX, 6 + PHIY), (1, 1, 1, 1)),
                           (section.second_moment_edgewise, (UY, PHIX, 6 + UY, 6 + PHIX), (1, -1, 1, -1))):
        # flatwise bending in x: (u_x, phi_y); edgewise bending in y: (u_y, -phi_x)
        if bending_theory == "timoshenko":
            k, m = _timoshenko_matrices(E * I, kGA, rho * A, rho * I, h)
        else:
            k, m = _bending_matrices(E * I, rho * A, h)
        scatter(k, m, dofs, signs)
    # axial
    k, m = _bar_matrices(E * A, rho * A, h)
    scatter(k, m, (UZ, 6 + UZ), (1, 1))
    if warping:   # Vlasov torsion: (phi_z, phi_z') at both nodes
        Cw = section.warping_constant
        k, m = _vlasov_matrices(G * section.torsion_constant, E * Cw, rho * section.polar_moment, rho * Cw, h)
        scatter(k, m, (PHIZ, 12, 6 + PHIZ, 13), (1, 1, 1, 1))
    else:         # St. Venant torsion with torsional inertia rho * I_p
        k, m = _bar_matrices(G * section.torsion_constant, rho * section.polar_moment, h)
        scatter(k, m, (PHIZ, 6 + PHIZ), (1, 1))
    return K, M


def beam_mesh(geometry: BeamBladeGeometry):
    """Nodes and elements of the beam blade: (node_z (n_nodes,) [m], platform_node, sections
    (n_nodes - 1,) list of RectangularSection, block_nodes (indices of the nodes in the platform
    block, z_bottom..z_top; empty without block)).  Shank [0, z_lo] with n_elements_shank
    elements, the platform block [z_lo, shank_length] and [shank_length, z_top] with
    block.n_elements each (if it has a height; else z_lo = z_top = shank_length), airfoil
    [z_top, L_total] with n_elements_airfoil."""
    g = geometry
    b = g.block
    z_p = g.shank_length
    z_lo, z_hi = (b.z_bottom, b.z_top) if b is not None else (z_p, z_p)
    pieces = [(0.0, z_lo, g.n_elements_shank, g.shank_section, False)]
    if b is not None:
        pieces += [(z_lo, z_p, b.n_elements, b.section, True), (z_p, z_hi, b.n_elements, b.section, True)]
    pieces.append((z_hi, g.total_length, g.n_elements_airfoil, g.airfoil_section, False))
    node_z, sections, platform_node, block_nodes = [0.0], [], 0, set()
    for z0, z1, n_el, section, in_block in pieces:
        if z1 <= z0:          # a block flush with the platform node on one side
            continue
        first = len(node_z) - 1
        node_z += list(np.linspace(z0, z1, n_el + 1)[1:])
        sections += [section] * n_el
        if in_block:
            block_nodes |= set(range(first, len(node_z)))
        if z1 == z_p:
            platform_node = len(node_z) - 1
    return np.array(node_z), platform_node, sections, np.array(sorted(block_nodes), dtype=int)


def _warping_constraints(geometry: BeamBladeGeometry, n_nodes: int, platform_node: int, block_nodes):
    """(warping DOF index of every node (n_nodes,), tied (k, 2) pairs (slave, master), held
    DOF indices) of Vlasov torsion: the block's nodes share the platform node's phi_z' (the
    block's y-twist, :class:`PlatformBlock`), which is held if J_xz = inf; the root's is held
    (the clamp)."""
    wdof = 6 * n_nodes + np.arange(n_nodes)
    held = [int(wdof[0])]
    if len(block_nodes) == 0:
        return wdof, np.zeros((0, 2), dtype=int), held
    master = int(wdof[platform_node])
    slaves = [int(wdof[n]) for n in block_nodes if n != platform_node]
    wdof[block_nodes] = master
    if not np.isfinite(geometry.block.warping_stiffness(geometry.shear_modulus)):
        held.append(master)
    return wdof, np.array([(sl, master) for sl in slaves], dtype=int).reshape(-1, 2), held


def n_beam_dofs(geometry: BeamBladeGeometry, n_nodes: int) -> int:
    """Size of the full DOF vector: 6 per node (u_x, u_y, u_z, phi_x, phi_y, phi_z, node after
    node), then with Vlasov torsion one rate of twist phi_z' per node (index 6 n_nodes + node)."""
    return (7 if geometry.torsion_theory == "vlasov" else 6) * n_nodes


def assemble_beam(geometry: BeamBladeGeometry):
    """Assemble the full stiffness and mass matrices of the beam blade (:func:`n_beam_dofs`
    square: (6 n_nodes)^2, with Vlasov torsion (7 n_nodes)^2).

    Returns (node_z, platform_node, K_full, M_full); the root (node 0) is not yet clamped.
    With Vlasov torsion and a platform block, the block nodes' phi_z' are merged into the
    platform node's (their own rows and columns are zero; :class:`PlatformBlock`), which carries
    the bimoment spring k_w.
    """
    g = geometry
    node_z, platform_node, sections, block_nodes = beam_mesh(g)
    n_nodes = node_z.size
    n_dof = n_beam_dofs(g, n_nodes)
    warping = g.torsion_theory == "vlasov"
    if warping:
        wdof, _, _ = _warping_constraints(g, n_nodes, platform_node, block_nodes)
    block_elements = {e for e in range(n_nodes - 1) if e in block_nodes and e + 1 in block_nodes}
    K = np.zeros((n_dof, n_dof))
    M = np.zeros((n_dof, n_dof))
    E, G, rho = g.youngs_modulus, g.shear_modulus, g.density
    for e, section in enumerate(sections):
        torsion = "st-venant" if e in block_elements else g.torsion_theory   # block: twist about z only
        ke, me = _frame_element(section, E, G, rho, node_z[e + 1] - node_z[e], g.poisson_ratio,
                                g.bending_theory, torsion)
        idx = np.arange(6 * e, 6 * e + 12)
        if ke.shape[0] == 14:
            idx = np.r_[idx, wdof[e], wdof[e + 1]]
        K[np.ix_(idx, idx)] += ke
        M[np.ix_(idx, idx)] += me
    if warping and len(block_nodes):
        k_w = g.block.warping_stiffness(G)
        if np.isfinite(k_w):                   # the block's y-twist resists the blade's warping
            K[wdof[platform_node], wdof[platform_node]] += k_w
    # rigid platform: lumped mass and rotary inertia on the platform node
    p = 6 * platform_node
    M[p:p + 3, p:p + 3] += g.platform_mass * np.eye(3)
    M[p + 3:p + 6, p + 3:p + 6] += np.diag(g.platform_rotary_inertia)
    return node_z, platform_node, K, M


def _classify(vectors_full: np.ndarray, mass_full: np.ndarray, n_nodes: int):
    """Family (F, E, T, A) of every mode by its share of modal kinetic energy v^T M v (the
    rates of twist phi_z' of Vlasov torsion, rows from 6 n_nodes on, count as T)."""
    families = tuple(_FAMILY_DOFS)
    energy_density = vectors_full * (mass_full @ vectors_full)   # per-DOF share, sums to 1
    fractions = np.zeros((vectors_full.shape[1], len(families)))
    for col, fam in enumerate(families):
        rows = [6 * n + d for n in range(n_nodes) for d in _FAMILY_DOFS[fam]]
        if fam == "T":
            rows += list(range(6 * n_nodes, vectors_full.shape[0]))
        fractions[:, col] = energy_density[rows].sum(axis=0)
    family_of_mode = [families[i] for i in np.argmax(fractions, axis=1)]
    counters = dict.fromkeys(families, 0)
    names = []
    for fam in family_of_mode:
        counters[fam] += 1
        names.append(f"{counters[fam]}{fam}")
    return tuple(names), family_of_mode, fractions


def beam_modes(geometry: BeamBladeGeometry) -> BeamModes:
    """Clamp the root, solve K v = omega^2 M v (scipy.linalg.eigh, dense), mass-normalise
    (v^T M v = I), classify modes and fix signs (tip u_x > 0 for F, u_y > 0 for E,
    phi_z > 0 for T, u_z > 0 for A)."""
    node_z, platform_node, K_full, M_full = assemble_beam(geometry)
    n_nodes = node_z.size
    clamped = [0, 1, 2, 3, 4, 5]                 # node 0 (root) clamped ...
    tied = np.zeros((0, 2), dtype=int)
    if geometry.torsion_theory == "vlasov":      # ... its warping held, the block's tied
        _, _, _, block_nodes = beam_mesh(geometry)
        _, tied, held = _warping_constraints(geometry, n_nodes, platform_node, block_nodes)
        clamped += held + list(tied[:, 0])
    free = np.setdiff1d(np.arange(K_full.shape[0]), clamped)
    K = K_full[np.ix_(free, free)]
    M = M_full[np.ix_(free, free)]
    eigvals, vecs = scipy.linalg.eigh(K, M)   # eigh returns M-orthonormal vectors
    eigvals = np.clip(eigvals, 0.0, None)
    freqs = np.sqrt(eigvals) / (2.0 * np.pi)

    full = np.zeros((K_full.shape[0], vecs.shape[1]))
    full[free] = vecs
    full[tied[:, 0]] = full[tied[:, 1]]
    names, family_of_mode, fractions = _classify(full, M_full, n_nodes)

    tip = 6 * (n_nodes - 1)
    for j, fam in enumerate(family_of_mode):
        value = full[tip + _FAMILY_SIGN_DOF[fam], j]
        if abs(value) < 1e-9 * np.max(np.abs(full[:, j])):
            value = full[np.argmax(np.abs(full[:, j])), j]
        if value < 0:
            vecs[:, j] *= -1.0
    return BeamModes(node_z=node_z, platform_node=platform_node, stiffness=K, mass=M,
                     free_dofs=free, frequencies_hz=freqs, vectors=vecs, mode_names=names,
                     family_fractions=fractions, tied_dofs=tied, n_dofs=K_full.shape[0])
