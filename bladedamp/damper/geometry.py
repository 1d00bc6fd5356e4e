"""Damper geometry: contact frames, control points, contact patches and the maps G_D, G_P (Eq. 6-9).

Frames. Blade frame: x circumferential, y axial, z radial (outwards). A damper sits under
the platforms of two neighbouring blades, between blade i (its platform point "OL", on the
blade's -x side) and blade i+1 (point "OR", on its +x side; blade i+1 lies at -x). Seen from
the damper, the OL platform is at +x, the OR platform at -x; both lean over the damper,
their undersides inclined by the platform angles gamma_L, gamma_R to the circumferential
direction, so centrifugal force presses the damper up into the groove.

Contact frame of each contact (Fig. 2, 3): zeta = unit normal from the platform into the
damper, eta = y (damper axis, contact length l_C), xi = eta x zeta (across the contact
height h_C). Rows of the rotation matrix R_c are (xi, eta, zeta) in blade coordinates.

Kinematics (Eq. 6): relative motion damper - platform at the contact centre c,
    w_u   = R_c (u_D + phi_D x r_c - u_P,c - phi_P,c x dr_c)
    w_phi = R_c (phi_D - phi_P,c)
with r_c the contact centre seen from the damper's centre of gravity and dr_c the contact
centre seen from the blade model's platform point, i.e. w = G_D u_D - G_P u_P with
G_D (12 x 6) and G_P (12 x 12) block matrices. A rigid motion of damper and platforms
together gives w = 0 (tested).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import validation
from ..contact.laws import LinearNormalLaw, RoughnessNormalLaw
from ..contact.patch import ContactPatch

CONTACTS = ("OL", "OR")


def skew(r: np.ndarray) -> np.ndarray:
    """[r]x with [r]x v = r x v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def rigid_map(rotation: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """6x6 map of a body's (u, phi) at its reference point to (u, phi) of a point at ``offset``,
    expressed in the frame ``rotation``: [[R, -R [r]x], [0, R]] (u + phi x r = u - r x phi)."""
    G = np.zeros((6, 6))
    G[:3, :3] = rotation
    G[:3, 3:] = -rotation @ skew(offset)
    G[3:, 3:] = rotation
    return G


def rigid_map_derivative(rotation: np.ndarray, offset: np.ndarray, d_rotation: np.ndarray,
                         d_offset: np.ndarray) -> np.ndarray:
    """The derivative (6, 6) of :func:`rigid_map` (``rotation``, ``offset``) along (``d_rotation``,
    ``d_offset``): [[dR, -dR [r]x - R [dr]x], [0, dR]] (the map is bilinear)."""
    G = np.zeros((6, 6))
    G[:3, :3] = d_rotation
    G[:3, 3:] = -d_rotation @ skew(offset) - rotation @ skew(d_offset)
    G[3:, 3:] = d_rotation
    return G


def contact_normal_derivative(side: str, gamma: float) -> np.ndarray:
    """d :func:`contact_normal` / d gamma [1/rad]."""
    s, c = np.sin(gamma), np.cos(gamma)
    return np.array([-c, 0.0, s]) if side == "OL" else np.array([c, 0.0, s])


def contact_frame_derivative(d_normal: np.ndarray) -> np.ndarray:
    """The derivative of :func:`contact_frame` along ``d_normal`` (its rows xi = eta x zeta and
    zeta are linear in the normal, eta is fixed)."""
    eta = np.array([0.0, 1.0, 0.0])
    return np.array([np.cross(eta, d_normal), np.zeros(3), d_normal])


def contact_normal(side: str, gamma: float) -> np.ndarray:
    """Unit normal from the platform into the damper (blade frame) for platform angle gamma [rad]."""
    s, c = np.sin(gamma), np.cos(gamma)
    return np.array([-s, 0.0, -c]) if side == "OL" else np.array([s, 0.0, -c])


def contact_frame(normal: np.ndarray) -> np.ndarray:
    """Rotation matrix with rows (xi, eta, zeta): eta = y, zeta = normal, xi = eta x zeta."""
    eta = np.array([0.0, 1.0, 0.0])
    xi = np.cross(eta, normal)
    return np.array([xi, eta, normal])


# Contact stiffness per unit contact length [N/m per m] a damper contact can have; a value
# outside is refused (ValueError), not warned about: far outside, the model stops being a contact
# and the continuation finds no end (a tangential stiffness of 1e-6 N/m^2, with the default
# k_N / k_T, ran past 60 CPU s). Upper end: a line contact between steel bodies is about pi E*/4
# per unit length over a logarithmic factor, E* = 1.15e11 Pa for steel on steel, so 1e10-1e11; a
# stiffness two decades above E* is no contact (the normal and the tangential stiffness). Lower
# end (normal stiffness only): the reference contact (k_T 1.7e7, k_N 2.1e7 N/m^2) is soft because
# it lumps the platforms' local flexibility; at 1e5 N/m^2 the reference 1 g cylinder's
# centrifugal preload at 100 Hz (m R Omega^2 = 39 N over l_C = 20 mm) would press it 2 cm into
# the platform, ten times its radius. The tangential stiffness has no lower end: k_T -> 0 is the
# frictionless limit of a contact (its normal springs stay), which the nonlinear modes use.
CONTACT_STIFFNESS_PER_LENGTH_RANGE = (1.0e5, 1.0e13)       # N/m per m


@dataclass(frozen=True)
class ContactProperties:
    """Contact parameters shared by both contacts of a damper.

    Parameters
    ----------
    friction_coefficient : mu [-]
    tangential_stiffness_per_length : tangential contact stiffness per unit contact length
        along the damper axis [N/m per m]; a patch gets k_T = this * l_C
    normal_to_tangential_stiffness : k_N / k_T [-]
    roughness_exponent : 1 for a linear normal law, > 1 for the rough-surface power law
    roughness_reference_load : total load per contact [N] at which k_N holds (power law only)
    points_along_length : point contacts along l_C (eta)
    points_across_height : point contacts across h_C (xi) for flat faces (the wedge)
    """

    friction_coefficient: float = 0.3
    tangential_stiffness_per_length: float = 1.0e9
    normal_to_tangential_stiffness: float = 1.25
    roughness_exponent: float = 1.0
    roughness_reference_load: float = 10.0
    points_along_length: int = 5
    points_across_height: int = 5

    def __post_init__(self):
        validation.nonnegative("friction_coefficient (mu)", self.friction_coefficient)
        validation.positive("tangential_stiffness_per_length", self.tangential_stiffness_per_length)
        validation.positive("normal_to_tangential_stiffness", self.normal_to_tangential_stiffness)
        low, high = CONTACT_STIFFNESS_PER_LENGTH_RANGE
        if self.tangential_stiffness_per_length > high:
            raise ValueError(f"tangential_stiffness_per_length must be in (0, {high:g}] N/m per m of contact length "
                             f"(got {self.tangential_stiffness_per_length!r}; a steel line contact is 1e10-1e11)")
        normal = self.normal_to_tangential_stiffness * self.tangential_stiffness_per_length
        if not low <= normal <= high:
            raise ValueError(f"the normal contact stiffness per length, normal_to_tangential_stiffness x "
                             f"tangential_stiffness_per_length = {self.normal_to_tangential_stiffness!r} x "
                             f"{self.tangential_stiffness_per_length!r} = {normal:.3g} N/m per m, must be in the "
                             f"plausible range [{low:g}, {high:g}] N/m per m of contact length (a steel line contact "
                             f"is 1e10-1e11; softer values lump the platforms' flexibility; below {low:g} the "
                             f"centrifugal preload presses a damper centimetres into its platform)")
        validation.in_range("roughness_exponent", self.roughness_exponent, 1.0, 5.0)
        validation.positive("roughness_reference_load", self.roughness_reference_load)
        validation.integer("points_along_length", self.points_along_length, minimum=1)
        validation.integer("points_across_height", self.points_across_height, minimum=1)

    def patch(self, height: float, length: float, n_xi: int) -> ContactPatch:
        k_t = self.tangential_stiffness_per_length * length
        k_n = self.normal_to_tangential_stiffness * k_t
        if self.roughness_exponent == 1.0:
            law = LinearNormalLaw(k_n)
        else:
            law = RoughnessNormalLaw(k_n, self.roughness_reference_load, self.roughness_exponent)
        return ContactPatch(height, length, k_t, self.friction_coefficient, law, n_xi, self.points_along_length)


@dataclass
class DamperGeometry:
    """Everything the kinematics needs of a damper between two platforms.

    frames : (2, 3, 3) rows (xi, eta, zeta) of the OL and OR contacts
    centres : (2, 3) contact centres seen from the damper's centre of gravity [m]
    patches : (ContactPatch, ContactPatch) for OL, OR
    inertia : (6, 6) generalised mass matrix I_D about the centre of gravity [kg, kg m^2]
    section : (k, 2) cross-section polygon in (x, z) relative to the centre of gravity [m]
    """

    frames: np.ndarray
    centres: np.ndarray
    patches: tuple[ContactPatch, ContactPatch]
    inertia: np.ndarray
    section: np.ndarray
    gamma_left: float
    gamma_right: float

    @property
    def G_D(self) -> np.ndarray:
        """(12, 6): damper CG motion -> relative motion at OL', OR' (Eq. 6, 9)."""
        return np.vstack([rigid_map(R, r) for R, r in zip(self.frames, self.centres)])

    def G_P(self, platform_offsets) -> np.ndarray:
        """(12, 12): platform point motions (OL, OR; 6 each) -> relative motion (Eq. 6, 8).

        ``platform_offsets`` (2, 3): contact centres seen from the blade model's OL / OR points.
        """
        G = np.zeros((12, 12))
        for c, (R, dr) in enumerate(zip(self.frames, platform_offsets)):
            G[6 * c:6 * c + 6, 6 * c:6 * c + 6] = rigid_map(R, np.asarray(dr, dtype=float))
        return G

    def G_D_derivative(self, d_frames: np.ndarray, d_centres: np.ndarray) -> np.ndarray:
        """(12, 6) the derivative of :attr:`G_D` along frames and centres changing by ``d_frames``
        (2, 3, 3) and ``d_centres`` (2, 3) per unit of a parameter."""
        return np.vstack([rigid_map_derivative(R, r, dR, dr)
                          for R, r, dR, dr in zip(self.frames, self.centres, d_frames, d_centres)])

    def G_P_derivative(self, platform_offsets, d_frames: np.ndarray, d_offsets) -> np.ndarray:
        """(12, 12) the derivative of :meth:`G_P` (``platform_offsets`` (2, 3)) along the frames'
        and the offsets' changes ``d_frames`` (2, 3, 3), ``d_offsets`` (2, 3) per unit of a parameter."""
        G = np.zeros((12, 12))
        for c, (R, r, dR, dr) in enumerate(zip(self.frames, platform_offsets, d_frames, d_offsets)):
            G[6 * c:6 * c + 6, 6 * c:6 * c + 6] = rigid_map_derivative(R, np.asarray(r, dtype=float), dR,
                                                                       np.asarray(dr, dtype=float))
        return G

    def normal_load_log_derivatives(self, parameter: str) -> np.ndarray:
        """(d ln N_OL, d ln N_OR) / d ``parameter`` [1/rad] of :meth:`frictionless_normal_loads`:
        "gamma_left" or "gamma_right" (zeros for any other parameter: the loads depend on the
        angles only)."""
        gl, gr = self.gamma_left, self.gamma_right
        cot = 1 / np.tan(gl + gr)
        if parameter == "gamma_left":
            return np.array([-cot, 1 / np.tan(gl) - cot])
        if parameter == "gamma_right":
            return np.array([1 / np.tan(gr) - cot, -cot])
        return np.zeros(2)

    def frictionless_normal_loads(self, radial_force: float) -> np.ndarray:
        """Normal loads (N_OL, N_OR) [N] balancing a radial force on the damper, rigid platforms.

        N_L n_L + N_R n_R + F e_z = 0 in the x-z plane:
        N_L = F sin(gamma_R) / sin(gamma_L + gamma_R), N_R = F sin(gamma_L) / sin(gamma_L + gamma_R).
        """
        gl, gr = self.gamma_left, self.gamma_right
        return radial_force * np.array([np.sin(gr), np.sin(gl)]) / np.sin(gl + gr)


def _check_angles(gamma_left, gamma_right):
    validation.in_range("gamma_left (platform angle, rad)", gamma_left, 0.0, np.pi / 2, closed="neither")
    validation.in_range("gamma_right (platform angle, rad)", gamma_right, 0.0, np.pi / 2, closed="neither")


def polygon_inertia(poly: np.ndarray, mass: float, length: float, d_poly=None, d_length: float = 0.0):
    """Centroid (x, z) (2,) and 6x6 mass matrix of a uniform prism of ``mass`` [kg] and ``length``
    [m] along y with the cross-section ``poly`` (k, 2) (x, z) [m], and their derivatives along the
    section's change ``d_poly`` (k, 2) and the length's ``d_length`` (per unit of a parameter; zero
    when not given): ``(cg, M, d_cg, d_M)``. The moments are polynomials of the vertices, so each
    line carries its value and its tangent (forward differentiation by hand, exact)."""
    poly = np.asarray(poly, dtype=float)
    d_poly = np.zeros_like(poly) if d_poly is None else np.asarray(d_poly, dtype=float)
    x, z, dx, dz = poly[:, 0], poly[:, 1], d_poly[:, 0], d_poly[:, 1]
    x1, z1, dx1, dz1 = (np.roll(v, -1) for v in (x, z, dx, dz))
    cross = x * z1 - x1 * z
    d_cross = dx * z1 + x * dz1 - dx1 * z - x1 * dz
    area, d_area = cross.sum() / 2, d_cross.sum() / 2

    def moment(weight, d_weight):
        """(sum(weight cross), its tangent)."""
        return (weight * cross).sum(), (d_weight * cross + weight * d_cross).sum()

    sx, d_sx = moment(x + x1, dx + dx1)
    sz, d_sz = moment(z + z1, dz + dz1)
    cx, cz = sx / (6 * area), sz / (6 * area)
    d_cx, d_cz = d_sx / (6 * area) - cx * d_area / area, d_sz / (6 * area) - cz * d_area / area
    # second moments about the origin, then shifted to the centroid (per unit area)
    sxx, d_sxx = moment(z ** 2 + z * z1 + z1 ** 2, 2 * z * dz + dz * z1 + z * dz1 + 2 * z1 * dz1)
    szz, d_szz = moment(x ** 2 + x * x1 + x1 ** 2, 2 * x * dx + dx * x1 + x * dx1 + 2 * x1 * dx1)
    sxz, d_sxz = moment(x * z1 + 2 * x * z + 2 * x1 * z1 + x1 * z,
                        dx * z1 + x * dz1 + 2 * (dx * z + x * dz) + 2 * (dx1 * z1 + x1 * dz1) + dx1 * z + x1 * dz)
    ixx_a, izz_a, ixz_a = sxx / 12, szz / 12, sxz / 24           # int z^2 dA, int x^2 dA, int x z dA
    d_ixx, d_izz, d_ixz = d_sxx / 12, d_szz / 12, d_sxz / 24
    zz = ixx_a / area - cz ** 2   # mean z'^2
    xx = izz_a / area - cx ** 2   # mean x'^2
    xz = ixz_a / area - cx * cz
    d_zz = d_ixx / area - ixx_a * d_area / area ** 2 - 2 * cz * d_cz
    d_xx = d_izz / area - izz_a * d_area / area ** 2 - 2 * cx * d_cx
    d_xz = d_ixz / area - ixz_a * d_area / area ** 2 - d_cx * cz - cx * d_cz
    yy, d_yy = length ** 2 / 12, length * d_length / 6
    M, dM = np.zeros((6, 6)), np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = mass * np.array([[yy + zz, 0.0, -xz], [0.0, xx + zz, 0.0], [-xz, 0.0, xx + yy]])
    dM[3:, 3:] = mass * np.array([[d_yy + d_zz, 0.0, -d_xz], [0.0, d_xx + d_zz, 0.0], [-d_xz, 0.0, d_xx + d_yy]])
    return np.array([cx, cz]), M, np.array([d_cx, d_cz]), dM


# Plausible ranges of a damper's mass and dimensions (a PlausibilityWarning outside, not an
# error: the physics holds, the numbers most likely have the wrong unit). Underplatform dampers
# of turbine blades weigh from a fraction of a gram (small compressor / turbocharger blades,
# the reference wedge optimum 0.28 g) to tens of grams (large low-pressure turbine blades; the
# EO-8 optimum of the reference disk is 15 g): 1e-5..0.1 kg leaves a decade of margin on both
# sides, so "1.0" meant as 1 g (1 kg) and "1e-3" meant as 1 mg both warn. Their cross-section
# and length follow the platform gap and the blade chord: 0.1 mm..100 mm (the reference
# cylinder has r = 2 mm, l_C = 20 mm); 2.0 meant as 2 mm warns.
DAMPER_MASS_RANGE = (1.0e-5, 0.1)        # kg
DAMPER_LENGTH_RANGE = (1.0e-4, 0.1)      # m


# The lightest damper modelled [kg]; 0 means no damper. A damper's centrifugal preload
# m R Omega^2 (every force its contacts can carry) and its inertia vanish with its mass, so the
# limit of a vanishing mass is the disk without a damper (mass = 0), which the model gives
# exactly. Approaching that limit the contact forces sink below the solver's resolution (the
# default FRF of the reference disk with 1e-9 kg kept no point: Newton did not converge at the
# start), while the answer has long reached the limit: on the reference cylinder at EO 1
# (harmonics (1,)) 1e-6, 1e-7 and 1e-8 kg give peaks 0.13 %, 0.013 % and 0.0012 % below the
# damper-free 1.6996 mm, in proportion to the mass; the reference wedge (harmonics (0, 1))
# 0.49 % and 0.059 % at 1e-6 and 1e-7 kg. 1e-7 kg (0.1 mg), two decades below
# DAMPER_MASS_RANGE, is within 0.02 % (cylinder) and 0.1 % (wedge) of the limit there. (Without
# the static harmonic, the paper's (1,), the wedge's mean position is held at its seating, and a
# vanishing wedge still squeezes between the platforms: 9 % below the limit at 1e-7 kg, which its
# harmonic error estimate, 10 %, reports.)
MIN_DAMPER_MASS = 1.0e-7


def _check_mass(mass: float) -> None:
    """ValueError unless ``mass`` [kg] is 0 (no damper) or at least MIN_DAMPER_MASS."""
    validation.nonnegative("damper mass", mass)
    if 0 < mass < MIN_DAMPER_MASS:
        raise ValueError(f"damper mass must be 0 (no damper) or in [{MIN_DAMPER_MASS:g}, inf) kg (got {mass!r}): the "
                         "preload of a lighter damper, and every force its contacts carry, vanish with its mass; its "
                         "limit is the disk without a damper, mass = 0")


def _check_plausible_damper(mass: float, lengths: dict) -> None:
    validation.plausible("damper mass", mass, *DAMPER_MASS_RANGE, "kg", "underplatform dampers weigh 0.01 g to 100 g")
    for name, value in lengths.items():
        validation.plausible(name, value, *DAMPER_LENGTH_RANGE, "m", "damper dimensions are 0.1 mm to 100 mm")


@dataclass
class CylinderDamper:
    """Cylindrical damper (Fig. 1): curved surfaces, Hertzian line contacts, free to roll.

    Parameters
    ----------
    mass : m [kg] (0 means no damper)
    radius : cylinder radius [m]
    length : contact length l_C along the axis [m]
    contact : ContactProperties (line contact: one row of points along the length)
    """

    mass: float
    radius: float = 2.0e-3
    length: float = 20.0e-3
    contact: ContactProperties = field(default_factory=ContactProperties)

    def __post_init__(self):
        _check_mass(self.mass)
        validation.positive("cylinder radius", self.radius)
        validation.positive("damper length l_C", self.length)
        _check_plausible_damper(self.mass, {"cylinder radius": self.radius, "damper length l_C": self.length})

    kind = "cylinder"

    def geometry(self, gamma_left: float, gamma_right: float) -> DamperGeometry:
        """Contact frames, centres, patches and inertia for platform angles [rad]."""
        _check_angles(gamma_left, gamma_right)
        normals = [contact_normal("OL", gamma_left), contact_normal("OR", gamma_right)]
        frames = np.array([contact_frame(n) for n in normals])
        centres = np.array([-self.radius * n for n in normals])  # surface point facing each platform
        patches = tuple(self.contact.patch(0.0, self.length, 1) for _ in CONTACTS)
        M = np.zeros((6, 6))
        M[:3, :3] = self.mass * np.eye(3)
        transverse = self.mass * (3 * self.radius ** 2 + self.length ** 2) / 12
        M[3:, 3:] = np.diag([transverse, self.mass * self.radius ** 2 / 2, transverse])
        angle = np.linspace(0, 2 * np.pi, 49)[:-1]
        section = self.radius * np.column_stack([np.cos(angle), np.sin(angle)])
        return DamperGeometry(frames, centres, patches, M, section, gamma_left, gamma_right)

    def geometry_derivative(self, gamma_left: float, gamma_right: float, parameter: str):
        """(d frames (2, 3, 3), d centres (2, 3) [m], d inertia (6, 6)) of :meth:`geometry` per unit
        of ``parameter``: "gamma_left" or "gamma_right" [per rad], "radius" or "length" [per m]. The
        contact patches do not depend on the angles and the radius; with the length their points
        and stiffnesses change (:func:`bladedamp.diskmodel` differentiates them)."""
        normals = [contact_normal("OL", gamma_left), contact_normal("OR", gamma_right)]
        d_frames, d_centres, d_inertia = np.zeros((2, 3, 3)), np.zeros((2, 3)), np.zeros((6, 6))
        if parameter in ("gamma_left", "gamma_right"):
            c = 0 if parameter == "gamma_left" else 1
            dn = contact_normal_derivative(CONTACTS[c], (gamma_left, gamma_right)[c])
            d_frames[c] = contact_frame_derivative(dn)
            d_centres[c] = -self.radius * dn
        elif parameter == "radius":
            d_centres = -np.array(normals)
            d_inertia[3:, 3:] = np.diag([self.mass * self.radius / 2, self.mass * self.radius, self.mass * self.radius / 2])
        elif parameter == "length":                  # transverse m (3 r^2 + l^2) / 12
            d_inertia[3, 3] = d_inertia[5, 5] = self.mass * self.length / 6
        else:
            raise ValueError(f"a cylinder's geometry has no derivative in {parameter!r} "
                             "(gamma_left, gamma_right, radius, length)")
        return d_frames, d_centres, d_inertia


@dataclass
class WedgeDamper:
    """Wedge-shaped damper (Fig. 1): flat contact faces of height h_C and length l_C.

    The cross-section is the triangle whose two upper sides are the contact faces (each of
    height h_C, inclined like the platforms) meeting at the apex, closed by the base.

    Parameters
    ----------
    mass : m [kg] (0 means no damper)
    contact_height : h_C [m]
    length : l_C [m]
    contact : ContactProperties (``points_across_height`` x ``points_along_length`` points)
    """

    mass: float
    contact_height: float | None = 2.0e-3
    length: float = 20.0e-3
    contact: ContactProperties = field(default_factory=ContactProperties)

    kind = "wedge"

    def __post_init__(self):
        _check_mass(self.mass)
        if self.contact_height is None:
            raise ValueError("contact_height h_C of a wedge damper must be given, in (0, inf) m")
        validation.positive("contact_height h_C", self.contact_height)
        validation.positive("damper length l_C", self.length)
        _check_plausible_damper(self.mass, {"contact_height h_C": self.contact_height, "damper length l_C": self.length})

    def geometry(self, gamma_left: float, gamma_right: float) -> DamperGeometry:
        _check_angles(gamma_left, gamma_right)
        frames, centres, M, poly, cg = self.section(gamma_left, gamma_right)[:5]
        h = self.contact_height
        patches = tuple(self.contact.patch(h, self.length, self.contact.points_across_height) for _ in CONTACTS)
        return DamperGeometry(frames, centres, patches, M, poly - cg, gamma_left, gamma_right)

    def section(self, gamma_left: float, gamma_right: float, parameter: str | None = None):
        """(frames (2, 3, 3), contact centres (2, 3) [m], inertia (6, 6), cross-section polygon (3, 2)
        (x, z) [m], its centroid (2,), and the derivatives of the first three per unit of
        ``parameter``: "gamma_left", "gamma_right" [per rad], "contact_height", "length" [per m]
        (zeros for None)). The faces run from the apex down along each contact's xi, of height
        h_C; the polygon's orientation and the faces' sense are fixed by the values (the
        derivatives keep them)."""
        angles = (gamma_left, gamma_right)
        normals = [contact_normal(side, g) for side, g in zip(CONTACTS, angles)]
        frames = np.array([contact_frame(n) for n in normals])
        d_frames = np.zeros((2, 3, 3))
        if parameter in ("gamma_left", "gamma_right"):
            c = CONTACTS.index("OL" if parameter == "gamma_left" else "OR")
            d_frames[c] = contact_frame_derivative(contact_normal_derivative(CONTACTS[c], angles[c]))
        h = self.contact_height
        d_h = 1.0 if parameter == "contact_height" else 0.0
        d_length = 1.0 if parameter == "length" else 0.0
        # faces run from the apex (origin) downwards along -xi_OL ... check: xi points down the face
        sense = [-1.0 if h * frames[c, 0][2] > 0 else 1.0 for c in range(2)]      # make each face run down
        ends = [sense[c] * h * frames[c, 0] for c in range(2)]
        d_ends = [sense[c] * (d_h * frames[c, 0] + h * d_frames[c, 0]) for c in range(2)]
        order = [0, 1, 2]
        poly = np.array([[0.0, 0.0], [ends[1][0], ends[1][2]], [ends[0][0], ends[0][2]]])
        d_poly = np.array([[0.0, 0.0], [d_ends[1][0], d_ends[1][2]], [d_ends[0][0], d_ends[0][2]]])
        if (poly[1, 0] - poly[0, 0]) * (poly[2, 1] - poly[0, 1]) - (poly[2, 0] - poly[0, 0]) * (poly[1, 1] - poly[0, 1]) < 0:
            order = [0, 2, 1]
        poly, d_poly = poly[order], d_poly[order]
        cg, M, d_cg, d_M = polygon_inertia(poly, self.mass, self.length, d_poly, d_length)
        centres = np.array([np.array([e[0] / 2 - cg[0], 0.0, e[2] / 2 - cg[1]]) for e in ends])
        d_centres = np.array([np.array([de[0] / 2 - d_cg[0], 0.0, de[2] / 2 - d_cg[1]]) for de in d_ends])
        return frames, centres, M, poly, cg, d_frames, d_centres, d_M

    def geometry_derivative(self, gamma_left: float, gamma_right: float, parameter: str):
        """(d frames (2, 3, 3), d centres (2, 3) [m], d inertia (6, 6)) of :meth:`geometry` per unit
        of ``parameter``: "gamma_left" or "gamma_right" [per rad], "contact_height" or "length"
        [per m] (:meth:`section`). The contact patches' points move with the height and the
        length too (:meth:`ContactPatch` xi, eta): :func:`bladedamp.diskmodel` differentiates them."""
        if parameter not in ("gamma_left", "gamma_right", "contact_height", "length"):
            raise ValueError(f"a wedge's geometry has no derivative in {parameter!r} "
                             "(gamma_left, gamma_right, contact_height, length)")
        return self.section(gamma_left, gamma_right, parameter)[5:]
