"""Linear blade: modal description (paper Eq. 1-5) and a beam finite-element builder.

Frames and conventions (the rest of bladedamp relies on them)
-------------------------------------------------------------
Blade frame: x = circumferential (flatwise bending direction of 1F, tip excitation F_x),
y = axial, z = radial along the span (root at z = 0, tip at z = L_total).
Every 6-vector is ordered (u_x, u_y, u_z, phi_x, phi_y, phi_z): three translations [m]
then three small rotations [rad].  A point rigidly attached at offset r from a node moves
by u + phi x r and rotates by phi (the rigid-body kinematics used for the platform contact
control points OL, OR, paper section "Contact Kinematics").

Platform contact control points: OL lies at x = -platform_half_width, OR at
x = +platform_half_width (both at y = 0, on the platform underside).  So the damper that
touches OL of one blade touches OR of its neighbour on the -x side.

Units: SI everywhere (m, kg, s, rad, N).  Mass-normalised mode shapes have units
m/sqrt(kg) (translations) and rad/sqrt(kg) (rotations); modal coordinates sqrt(kg)*m.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from bladedamp import _validate as check

# Points every ModalBlade must carry.
REQUIRED_POINTS = ("OL", "OR", "tip", "excitation")
# Ordering of the paper's four modes (Table 1).
PAPER_MODE_ORDER = ("1F", "2F", "1T", "1E")
# The paper's Table 1: natural frequencies [Hz] and modal damping ratios [-].
TABLE1_FREQUENCIES_HZ = (95.0, 423.0, 783.0, 1065.0)
TABLE1_DAMPING_RATIOS = (0.001, 0.001, 0.001, 0.001)

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


# --------------------------------------------------------------------------------------
# Modal blade (paper Eq. 1-5)
# --------------------------------------------------------------------------------------
@dataclass(eq=False)
class ModalBlade:
    """Modal blade model (paper Eq. 1-5).

    The blade's FE equations M u'' + D u' + K u = p_E + p_C (Eq. 1) are reduced with
    u = Phi q (Eq. 2) onto n_m mass-normalised modes; in the frequency domain the modal
    equations are S(Omega) q = Phi^T (p_E + p_C) (Eq. 4) with the diagonal dynamic
    stiffness S_j = omega_0j^2 - Omega^2 + 2 i D_j omega_0j Omega (Eq. 5).

    Attributes
    ----------
    natural_frequencies_hz : (n_m,) natural frequencies f_0j [Hz], > 0.
    damping_ratios : (n_m,) modal viscous damping ratios D_j [-], >= 0
        (a scalar is broadcast to all modes).
    mode_shapes : point name -> (6, n_m) mass-normalised mode-shape values at that point,
        rows (u_x, u_y, u_z [m/sqrt(kg)], phi_x, phi_y, phi_z [rad/sqrt(kg)]).
    points : point name -> (3,) position in the blade frame [m].
    mode_names : e.g. ("1F", "2F", "1T", "1E"); empty or one name per mode.

    Required points: "OL", "OR" (platform contact control points, OL at -x, OR at +x),
    "tip" and "excitation".
    """

    natural_frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    mode_shapes: dict[str, np.ndarray]
    points: dict[str, np.ndarray]
    mode_names: tuple[str, ...] = ()

    def __post_init__(self):
        freqs = np.array(self.natural_frequencies_hz, dtype=float, ndmin=1)
        if freqs.ndim != 1 or freqs.size == 0:
            raise ValueError(
                f"natural_frequencies_hz must be a non-empty 1-D array (got shape {freqs.shape})")
        self.natural_frequencies_hz = np.array(check.positive("natural_frequencies_hz", freqs), ndmin=1)
        n_m = freqs.size

        damping = np.array(self.damping_ratios, dtype=float)
        if damping.ndim == 0:
            damping = np.full(n_m, float(damping))
        if damping.shape != (n_m,):
            raise ValueError(
                f"damping_ratios must have shape ({n_m},) to match natural_frequencies_hz "
                f"(got {damping.shape})")
        self.damping_ratios = np.array(check.nonnegative("damping_ratios", damping), ndmin=1)

        if not isinstance(self.mode_shapes, dict) or not isinstance(self.points, dict):
            raise ValueError("mode_shapes and points must be dicts keyed by point name")
        missing = [p for p in REQUIRED_POINTS if p not in self.mode_shapes or p not in self.points]
        if missing:
            raise ValueError(
                f"points/mode_shapes must contain the required points {REQUIRED_POINTS}; "
                f"missing: {missing}")
        if set(self.mode_shapes) != set(self.points):
            raise ValueError(
                "mode_shapes and points must have the same point names (mismatched: "
                f"{sorted(set(self.mode_shapes) ^ set(self.points))})")

        shapes = {}
        for name, shape in self.mode_shapes.items():
            arr = np.array(shape, dtype=float)
            if arr.shape != (6, n_m):
                raise ValueError(
                    f"mode_shapes[{name!r}] must have shape (6, {n_m}) = (6 DOF, n_modes) "
                    f"(got {arr.shape})")
            shapes[name] = check.finite(f"mode_shapes[{name!r}]", arr)
        self.mode_shapes = shapes

        positions = {}
        for name, pos in self.points.items():
            arr = np.array(pos, dtype=float)
            if arr.shape != (3,):
                raise ValueError(f"points[{name!r}] must have shape (3,) [m] (got {arr.shape})")
            positions[name] = check.finite(f"points[{name!r}]", arr)
        self.points = positions

        names = tuple(self.mode_names or ())
        if names and len(names) != n_m:
            raise ValueError(
                f"mode_names must be empty or have {n_m} entries (got {len(names)})")
        self.mode_names = names

    # -- basic properties --------------------------------------------------------------
    @property
    def n_modes(self) -> int:
        """Number of retained modes n_m."""
        return int(self.natural_frequencies_hz.size)

    @property
    def natural_angular_frequencies(self) -> np.ndarray:
        """omega_0j = 2 pi f_0j [rad/s], shape (n_m,)."""
        return 2.0 * np.pi * self.natural_frequencies_hz

    def dynamic_stiffness(self, omega: float) -> np.ndarray:
        """Diagonal of the modal dynamic stiffness S(Omega) [1/s^2], Eq. 5.

        S_j = omega_0j^2 - Omega^2 + 2 i D_j omega_0j Omega, shape (n_m,), complex.
        ``omega`` is the excitation angular frequency Omega_E [rad/s].
        """
        omega = check.finite("omega", omega)
        w0 = self.natural_angular_frequencies
        return w0**2 - omega**2 + 2j * self.damping_ratios * w0 * omega

    def shape(self, point: str) -> np.ndarray:
        """(6, n_m) mode-shape matrix Phi_point at a named point (a copy)."""
        if point not in self.mode_shapes:
            raise ValueError(f"point must be one of {sorted(self.mode_shapes)} (got {point!r})")
        return self.mode_shapes[point].copy()

    def modal_force(self, force: np.ndarray, at: str = "excitation") -> np.ndarray:
        """Modal force Phi_at^T f [N/sqrt(kg)], right-hand side of Eq. 4.

        ``force`` is a (6,) load (F_x, F_y, F_z [N], M_x, M_y, M_z [N m]) at point ``at``.
        """
        f = np.asarray(force)
        if f.shape != (6,):
            raise ValueError(f"force must have shape (6,) = (Fx, Fy, Fz, Mx, My, Mz) (got {f.shape})")
        return self.shape(at).T @ f

    # -- variants (mistuning) ------------------------------------------------------------
    def with_frequencies(self, natural_frequencies_hz) -> "ModalBlade":
        """Same mode shapes and damping, new natural frequencies [Hz] (e.g. f_i = kappa_i f)."""
        return dataclasses.replace(self, natural_frequencies_hz=natural_frequencies_hz)

    def scaled(self, kappa: float) -> "ModalBlade":
        """Frequency mistuning of the paper: f_0j -> kappa * f_0j for every mode (kappa > 0)."""
        kappa = check.positive("kappa", kappa)
        return self.with_frequencies(kappa * self.natural_frequencies_hz)

    # -- builders ----------------------------------------------------------------------
    @classmethod
    def from_arrays(cls, natural_frequencies_hz, damping_ratios, mode_shapes, points,
                    mode_names=()) -> "ModalBlade":
        """Build from any FE export: frequencies [Hz], damping ratios, (6, n_m) shapes per point
        (mass-normalised), (3,) point positions [m]."""
        return cls(natural_frequencies_hz=natural_frequencies_hz, damping_ratios=damping_ratios,
                   mode_shapes=dict(mode_shapes), points=dict(points),
                   mode_names=tuple(mode_names or ()))

    @classmethod
    def from_beam(cls, geometry: "BeamBladeGeometry", n_modes: int = 4,
                  natural_frequencies_hz=None, damping_ratios=0.001,
                  mode_names=None) -> "ModalBlade":
        """Build from the beam FE model of ``geometry`` (see :func:`beam_modes`).

        n_modes = 4 returns the paper's modes in the order ("1F", "2F", "1T", "1E");
        any other n_modes returns the lowest n_modes by FE frequency, named by
        classification ("1F", "1E", "1T", "1A", "2F", ...).
        If ``natural_frequencies_hz`` is given, the FE shapes are kept and the frequencies
        replaced (the reference blade uses the paper's Table 1).
        ``damping_ratios``: scalar or (n_modes,) modal damping ratios D_j [-].
        ``mode_names``: optional override of the classified names.
        """
        n_modes = check.integer("n_modes", n_modes, minimum=1)
        modes = beam_modes(geometry)
        if n_modes > modes.frequencies_hz.size:
            raise ValueError(
                f"n_modes must be in [1, {modes.frequencies_hz.size}] for this mesh (got {n_modes})")
        if n_modes == 4:
            missing = [n for n in PAPER_MODE_ORDER if n not in modes.mode_names]
            if missing:
                raise ValueError(f"beam model has no modes {missing}; refine the mesh")
            idx = [modes.mode_names.index(n) for n in PAPER_MODE_ORDER]
        else:
            idx = list(range(n_modes))  # modes are sorted by frequency
        names = tuple(modes.mode_names[i] for i in idx)
        if mode_names is not None:
            names = tuple(mode_names)
        if natural_frequencies_hz is None:
            freqs = modes.frequencies_hz[idx]
        else:
            freqs = np.asarray(natural_frequencies_hz, dtype=float)
            if freqs.shape != (n_modes,):
                raise ValueError(
                    f"natural_frequencies_hz must have n_modes = {n_modes} entries "
                    f"(got shape {freqs.shape})")
        points = geometry.points()
        shapes = {name: modes.point_shapes(pos, node)[:, idx]
                  for name, (pos, node) in modes.point_attachment(points).items()}
        return cls(natural_frequencies_hz=freqs, damping_ratios=damping_ratios,
                   mode_shapes=shapes, points=points, mode_names=names)

    # -- linear reference solution -----------------------------------------------------
    def linear_frf(self, omega: np.ndarray, force: np.ndarray, at: str = "excitation",
                   response_at: str = "tip") -> np.ndarray:
        """Linear (no damper) harmonic response, closed-form modal superposition (Eq. 4-5).

        u(Omega) = Phi_resp S(Omega)^-1 Phi_at^T f.

        Parameters
        ----------
        omega : excitation angular frequencies Omega_E [rad/s], scalar or (n,).
        force : (6,) complex amplitude (F_x, F_y, F_z [N], M_x, M_y, M_z [N m]) at ``at``.
        at, response_at : point names.

        Returns
        -------
        (n, 6) complex response amplitudes (u [m], phi [rad]) at ``response_at``.
        """
        omega = np.atleast_1d(check.finite("omega", omega))
        if omega.ndim != 1:
            raise ValueError(f"omega must be a scalar or 1-D array [rad/s] (got shape {omega.shape})")
        modal_force = self.modal_force(force, at)                       # (n_m,)
        w0 = self.natural_angular_frequencies
        S = w0**2 - omega[:, None]**2 + 2j * self.damping_ratios * w0 * omega[:, None]  # Eq. 5
        q = modal_force[None, :] / S                                     # Eq. 4, (n, n_m)
        return q @ self.shape(response_at).T                            # Eq. 2


# --------------------------------------------------------------------------------------
# Beam blade geometry and FE model
# --------------------------------------------------------------------------------------
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
    def mass(self) -> float:
        """Total blade mass (shank + airfoil + platform) [kg]."""
        return (self.density * (self.shank_section.area * self.shank_length
                                + self.airfoil_section.area * self.airfoil_length)
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
    free_dofs : (n_free,) indices of the free DOF in the full 6 * n_nodes vector.
    frequencies_hz : (n_all,) natural frequencies [Hz], ascending.
    vectors : (n_free, n_all) mass-normalised eigenvectors (vectors.T @ mass @ vectors = I).
    mode_names : (n_all,) classification, e.g. "1F", "2F", "1E", "1T", "1A".
    family_fractions : (n_all, 4) share of modal kinetic energy in families F, E, T, A.
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

    @property
    def n_nodes(self) -> int:
        return int(self.node_z.size)

    def full_vectors(self) -> np.ndarray:
        """(6 * n_nodes, n_all) eigenvectors including the zero root DOF."""
        full = np.zeros((6 * self.n_nodes, self.vectors.shape[1]))
        full[self.free_dofs] = self.vectors
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


def _frame_element(section: RectangularSection, E: float, G: float, rho: float, h: float):
    """12 x 12 stiffness and consistent mass of a straight 3D frame element along z.

    DOF per node (u_x, u_y, u_z, phi_x, phi_y, phi_z).  Bending in x uses slope
    du_x/dz = +phi_y, bending in y uses du_y/dz = -phi_x (right-handed small rotations,
    consistent with u + phi x r).  Rotary inertia of bending is neglected (Euler-Bernoulli).
    """
    K = np.zeros((12, 12))
    M = np.zeros((12, 12))

    def scatter(k, m, dofs, signs):
        T = np.zeros((len(dofs), 12))
        for row, (d, s) in enumerate(zip(dofs, signs)):
            T[row, d] = s
        K[:] += T.T @ k @ T
        M[:] += T.T @ m @ T

    A = section.area
    # flatwise bending in x: (u_x, phi_y)
    k, m = _bending_matrices(E * section.second_moment_flatwise, rho * A, h)
    scatter(k, m, (UX, PHIY, 6 + UX, 6 + PHIY), (1, 1, 1, 1))
    # edgewise bending in y: (u_y, -phi_x)
    k, m = _bending_matrices(E * section.second_moment_edgewise, rho * A, h)
    scatter(k, m, (UY, PHIX, 6 + UY, 6 + PHIX), (1, -1, 1, -1))
    # axial
    k, m = _bar_matrices(E * A, rho * A, h)
    scatter(k, m, (UZ, 6 + UZ), (1, 1))
    # St. Venant torsion with torsional inertia rho * I_p
    k, m = _bar_matrices(G * section.torsion_constant, rho * section.polar_moment, h)
    scatter(k, m, (PHIZ, 6 + PHIZ), (1, 1))
    return K, M


def assemble_beam(geometry: BeamBladeGeometry):
    """Assemble the full (6 n_nodes)^2 stiffness and mass matrices of the beam blade.

    Returns (node_z, platform_node, K_full, M_full); the root (node 0) is not yet clamped.
    """
    g = geometry
    z_shank = np.linspace(0.0, g.shank_length, g.n_elements_shank + 1)
    z_air = np.linspace(g.shank_length, g.total_length, g.n_elements_airfoil + 1)
    node_z = np.concatenate([z_shank, z_air[1:]])
    platform_node = g.n_elements_shank
    n_dof = 6 * node_z.size
    K = np.zeros((n_dof, n_dof))
    M = np.zeros((n_dof, n_dof))
    E, G, rho = g.youngs_modulus, g.shear_modulus, g.density
    for e in range(node_z.size - 1):
        section = g.shank_section if e < g.n_elements_shank else g.airfoil_section
        ke, me = _frame_element(section, E, G, rho, node_z[e + 1] - node_z[e])
        sl = slice(6 * e, 6 * e + 12)
        K[sl, sl] += ke
        M[sl, sl] += me
    # rigid platform: lumped mass and rotary inertia on the platform node
    p = 6 * platform_node
    M[p:p + 3, p:p + 3] += g.platform_mass * np.eye(3)
    M[p + 3:p + 6, p + 3:p + 6] += np.diag(g.platform_rotary_inertia)
    return node_z, platform_node, K, M


def _classify(vectors_full: np.ndarray, mass_full: np.ndarray, n_nodes: int):
    """Family (F, E, T, A) of every mode by its share of modal kinetic energy v^T M v."""
    families = tuple(_FAMILY_DOFS)
    energy_density = vectors_full * (mass_full @ vectors_full)   # per-DOF share, sums to 1
    fractions = np.zeros((vectors_full.shape[1], len(families)))
    for col, fam in enumerate(families):
        rows = [6 * n + d for n in range(n_nodes) for d in _FAMILY_DOFS[fam]]
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
    free = np.arange(6, 6 * n_nodes)  # node 0 (root) clamped
    K = K_full[np.ix_(free, free)]
    M = M_full[np.ix_(free, free)]
    eigvals, vecs = scipy.linalg.eigh(K, M)   # eigh returns M-orthonormal vectors
    eigvals = np.clip(eigvals, 0.0, None)
    freqs = np.sqrt(eigvals) / (2.0 * np.pi)

    full = np.zeros((6 * n_nodes, vecs.shape[1]))
    full[free] = vecs
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
                     family_fractions=fractions)


# --------------------------------------------------------------------------------------
# Reference blade (paper's tuned system, Table 1)
# --------------------------------------------------------------------------------------
def reference_blade_geometry() -> BeamBladeGeometry:
    """Simplified steel model blade used for the paper's reference configuration.

    The paper gives no dimensions; these are chosen physically and calibrated so that, with
    the Table 1 frequencies and D = 0.001 substituted, F_x = 0.1 N at the tip gives the
    paper's no-damper 1F resonance tip amplitude 1.7 mm.
    """
    # Material: generic blade steel (12 % Cr steels are within a few % of these values).
    youngs_modulus = 210e9        # [Pa]
    poisson_ratio = 0.3           # [-]
    density = 7850.0              # [kg/m^3]

    # Span 0.20 m (small turbine blade, "beam-like" model blade of the paper's Fig. 4);
    # the platform sits at 30 % of the span above the clamped root (shank below it).
    shank_length = 0.060          # [m] root -> platform (30 % of 0.20 m)
    airfoil_length = 0.140        # [m] platform -> tip

    # The paper's blade has a constant rectangular cross-section, so shank and airfoil
    # share one section.
    # thickness_x = 4.57 mm: sets the FE flatwise frequency 1F = 95.0 Hz (Table 1).
    # chord_y = 45.5 mm: sets the blade mass (0.367 kg incl. platform) so that the 1F tip
    # mode-shape value is 3.48 /sqrt(kg) and the no-damper 1F resonance tip amplitude
    # under F_x = 0.1 N (Table 1 frequencies, D = 0.001) is 1.70 mm (paper, m = 0 g).
    thickness_x = 4.57e-3         # [m]
    chord_y = 45.5e-3             # [m]

    # Platform: a steel plate centred on the platform node, 30 mm (x, circumferential)
    # x 50 mm (y, axial, longer than the chord) x 4 mm (z).  Its volume inside the beam
    # section is already counted by the beam, so it is subtracted.
    plate_x, plate_y, plate_z = 0.030, 0.050, 0.004
    platform_mass = density * (plate_x * plate_y - thickness_x * chord_y) * plate_z  # ~40.6 g
    platform_rotary_inertia = (  # solid plate about its centre [kg m^2]
        platform_mass * (plate_y**2 + plate_z**2) / 12.0,
        platform_mass * (plate_x**2 + plate_z**2) / 12.0,
        platform_mass * (plate_x**2 + plate_y**2) / 12.0,
    )
    # Contact control points OL/OR at x = -/+ 12 mm: centre of the inclined contact faces,
    # 3 mm inside the plate edge; 2 mm below the node = on the platform underside where
    # the damper sits.
    platform_half_width = 0.012   # [m]
    platform_contact_z_offset = 0.002  # [m]

    # Mesh: 10 mm elements (6 + 14); the four FE frequencies change < 0.05 % and the
    # calibrated amplitude < 0.01 % when the element size is halved.
    #
    # FE frequencies vs the paper's Table 1 (FE only provides the shapes; the Table 1
    # values are substituted by reference_blade()):
    #   1F  95.0 Hz vs  95 Hz (tuned),   2F 559 Hz vs 423 Hz (+32 %),
    #   1T 743 Hz vs 783 Hz (-5 %),      1E 945 Hz vs 1065 Hz (-11 %).
    # A uniform rectangular beam cannot match all four ratios with a ~0.37 kg mass
    # (2F/1F = 6.27 for a plain cantilever; the platform mass lowers it to 5.9).
    return BeamBladeGeometry(
        shank_length=shank_length,
        shank_thickness_x=thickness_x,
        shank_chord_y=chord_y,
        airfoil_length=airfoil_length,
        airfoil_thickness_x=thickness_x,
        airfoil_chord_y=chord_y,
        platform_half_width=platform_half_width,
        platform_contact_z_offset=platform_contact_z_offset,
        platform_mass=platform_mass,
        platform_rotary_inertia=platform_rotary_inertia,
        youngs_modulus=youngs_modulus,
        poisson_ratio=poisson_ratio,
        density=density,
        n_elements_shank=6,
        n_elements_airfoil=14,
        tip_point=None,        # on the axis at the tip, z = 0.20 m
        excitation_point=None,  # = tip (paper: F_x, F_y, M_z at the blade tip)
    )


def reference_blade() -> ModalBlade:
    """Reference blade: FE shapes of :func:`reference_blade_geometry`, paper Table 1
    frequencies (95, 423, 783, 1065 Hz) and D = 0.001, modes ("1F", "2F", "1T", "1E")."""
    return ModalBlade.from_beam(reference_blade_geometry(), n_modes=4,
                                natural_frequencies_hz=TABLE1_FREQUENCIES_HZ,
                                damping_ratios=TABLE1_DAMPING_RATIOS)
