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

Modal data files (:meth:`ModalBlade.from_file`, :meth:`ModalBlade.save`)
-------------------------------------------------------------------------
A blade is its modes at named points: natural frequencies f_0j [Hz], modal viscous damping
ratios D_j [-] and, at every point, its position (x, y, z) [m] in the blade frame and the six
mass-normalised mode-shape values (ux, uy, uz [m/sqrt(kg)], phix, phiy, phiz [rad/sqrt(kg)])
of every mode, normalised so that Phi^T M Phi = I (kg-based units, not mm or tonnes).  The
points OL, OR (platform contact control points, OL at -x, OR at +x), tip (where the tip
amplitude is read) and excitation (where the excitation acts) are required; any other named
point (e.g. "platform") is kept.  The suffix chooses the format:

``.csv``: comma-separated text, one row per (mode, point); write it by hand or from an FE
export.  Lines starting with ``#`` and blank lines are ignored; the first other line is the
header.  Columns, in any order (names are case-sensitive):

    mode           mode number 1, 2, ..., n_m (no gaps; the order of the modes)
    mode_name      optional, e.g. 1F; the same on every row of a mode
    frequency_hz   natural frequency f_0j [Hz], > 0; the same on every row of a mode
    damping_ratio  modal damping ratio D_j [-], >= 0; the same on every row of a mode
    point          point name: OL, OR, tip, excitation, or an extra name
    x, y, z        point position [m]; the same on every row of the point
    ux, uy, uz     translations of the mass-normalised mode shape [m/sqrt(kg)]
    phix .. phiz   small rotations of the mass-normalised mode shape [rad/sqrt(kg)]

Every mode lists the same points, each once.  For example (two of the four required points)::

    mode,mode_name,frequency_hz,damping_ratio,point,x,y,z,ux,uy,uz,phix,phiy,phiz
    1,1F,95.0,0.001,tip,0,0,0.2,3.480,0,0,0,23.91,0
    1,1F,95.0,0.001,OL,-0.012,0,0.058,0.4484,0,0.1755,0,14.62,0

``.npz`` (numpy, read with ``allow_pickle=False``): arrays ``natural_frequencies_hz`` (n_m,)
[Hz], ``damping_ratios`` (n_m,) [-], ``point_names`` (n_p,) str, ``point_positions``
(n_p, 3) [m], ``mode_shapes`` (n_p, 6, n_m) [m/sqrt(kg), rad/sqrt(kg)], rows (ux, uy, uz,
phix, phiy, phiz); optional ``mode_names`` (n_m,) str and ``format`` (the string
``bladedamp.ModalBlade/1``).  A solid FE blade (:class:`bladedamp.solid.SolidModalBlade`)
writes the format ``bladedamp.SolidModalBlade/1``: these arrays plus its flexible platforms'
FE field, surface and solid_info under ``solid/`` (:meth:`~bladedamp.solid.SolidModalBlade.npz_arrays`);
it has no CSV form.  A bad file raises ValueError naming the file, the key or
column (and line) and what was expected.

Reduced FE matrices (:meth:`ModalBlade.from_matrices`): Craig-Bampton or Guyan exports with
the root clamped; the modes are computed and picked at the named points. :meth:`ModalBlade.from_file`
reads them from Nastran OUTPUT4 / punch DMIG, Abaqus, MATLAB and Ansys files
(:mod:`bladedamp.fe_formats`).

The reference blade (:func:`reference_blade`, :func:`reference_blade_geometry`, calibrated on
the paper: see :mod:`bladedamp.reference`) and the paper's Table 1 values and platform angle
are defined here; :mod:`bladedamp.reference` gives the same objects.
"""
from __future__ import annotations

import csv
import dataclasses
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from bladedamp import validation as check
from bladedamp.io import MODAL_NPZ_FORMAT, SOLID_NPZ_FORMAT, SOLID_NPZ_FORMATS_READ, open_npz, reading

# Points every ModalBlade must carry.
REQUIRED_POINTS = ("OL", "OR", "tip", "excitation")
# Ordering of the paper's four modes (Table 1).
PAPER_MODE_ORDER = ("1F", "2F", "1T", "1E")

# Modal data files (format: module docstring): the tags MODAL_NPZ_FORMAT, SOLID_NPZ_FORMAT and
# SOLID_NPZ_FORMATS_READ are defined in bladedamp.io, whose load() reads blade files too.
MODAL_NPZ_KEYS = ("format", "natural_frequencies_hz", "damping_ratios", "mode_names", "point_names",
                  "point_positions", "mode_shapes")
MODAL_CSV_COLUMNS = ("mode", "mode_name", "frequency_hz", "damping_ratio", "point", "x", "y", "z",
                     "ux", "uy", "uz", "phix", "phiy", "phiz")
# ModalBlade.from_matrices: a mode v is a rigid-body mode if K v vanishes to rounding,
# max|K v| <= RIGID_MODE_TOLERANCE * max(|K| |v|) (|.| entry-wise). Scale-free, unlike a
# threshold on omega^2 (the beam model's max K_ii / M_ii is 2e14 1/s^2, 5e8 times its 1F
# omega^2, and grows as h^-4 with refinement). It lies between the beam model's rigid modes
# (rounding) and its clamped 1F at any useful refinement (benchmarks/README.md, 'Moved from the
# package's docstrings', blade.py).
RIGID_MODE_TOLERANCE = 1e-11
# ModalBlade.from_matrices(solver="sparse"): shift-invert about omega^2 = -(2 pi 1 Hz)^2, just
# below every blade frequency, so the nearest eigenvalues are the lowest and K - sigma M is
# regular even when K has rigid-body modes (which are then found and refused).
SHIFT_INVERT_SIGMA = -(2.0 * np.pi * 1.0) ** 2
# ModalBlade.from_matrices(solver="auto"): dense eigh (all modes) up to this many free DOF,
# shift-invert above (dense eigh grows as n^3; timings: benchmarks/README.md, 'Moved from the
# package's docstrings', blade.py). Craig-Bampton blades have tens to hundreds of DOF: dense,
# the most robust.
DENSE_SOLVER_MAX_DOF = 500

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
        function psi: :func:`bladedamp.solid.warping_constant_rectangle`)."""
        from .solid import warping_constant_rectangle   # solid.py imports this module
        return warping_constant_rectangle(self.thickness_x, self.chord_y)

    @staticmethod
    def shear_coefficient(poisson_ratio: float) -> float:
        """Cowper's Timoshenko shear coefficient of a rectangle, kappa = 10 (1 + nu) / (12 + 11 nu)
        [-] (Cowper 1966, J. Appl. Mech. 33, 335; 5/6 at nu = 0, 0.850 at nu = 0.3)."""
        return 10.0 * (1.0 + poisson_ratio) / (12.0 + 11.0 * poisson_ratio)


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

    def dynamic_stiffness(self, f_hz: float) -> np.ndarray:
        """Diagonal of the modal dynamic stiffness S(Omega) [1/s^2], Eq. 5, at the excitation
        frequency ``f_hz`` [Hz] (Omega = 2 pi f_hz).

        S_j = omega_0j^2 - Omega^2 + 2 i D_j omega_0j Omega, shape (n_m,), complex.
        """
        omega = 2.0 * np.pi * check.finite("f_hz", f_hz)
        w0 = self.natural_angular_frequencies
        return w0**2 - omega**2 + 2j * self.damping_ratios * w0 * omega

    def shape(self, point: str) -> np.ndarray:
        """(6, n_m) mode-shape matrix Phi_point at a named point (a copy)."""
        if point not in self.mode_shapes:
            raise ValueError(f"point must be one of {sorted(self.mode_shapes)} (got {point!r})")
        return self.mode_shapes[point].copy()

    @property
    def flexible_platform(self) -> bool:
        """Whether the blade carries per-point platform shapes (:meth:`platform_displacements`)."""
        return False

    def platform_displacements(self, side: str, points, normal=None) -> np.ndarray | None:
        """Per-point platform shapes: the blade's own translations (P, 3, n_m) [m/sqrt(kg)] of its
        ``side`` ("OL" or "OR") platform contact surface at ``points`` (P, 3) [m, blade frame],
        or None; ``normal`` (3,) is the contact normal the caller assumes there (a blade with
        surface data checks it against its own surface). None here: the modal blade has one
        6-DOF shape per control point, so the platform moves rigidly with it (Eq. 6). A blade
        with its own surface data (the solid FE blade, :class:`bladedamp.solid.SolidModalBlade`)
        overrides this, and the contact kinematics then use those shapes at every contact point
        (:func:`bladedamp.disk.contact_point_maps`)."""
        if side not in ("OL", "OR"):
            raise ValueError(f"side must be 'OL' or 'OR' (got {side!r})")
        return None

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
        """Build from arrays of any FE export: frequencies [Hz], damping ratios, (6, n_m) shapes
        per point (mass-normalised), (3,) point positions [m]. Files: :meth:`from_file`;
        reduced FE matrices: :meth:`from_matrices`."""
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

    @classmethod
    def from_solid(cls, geometry=None, element_size: float | None = None, n_modes: int = 4,
                   **options) -> "ModalBlade":
        """Build from a solid (3D, quadratic tetrahedra) FE model of the parametric blade.

        ``geometry``: None (the reference blade), a :class:`BeamBladeGeometry` (its solid, with
        geometry.py's platform and contact faces) or a :class:`bladedamp.solid.SolidBladeGeometry`;
        ``element_size`` [m] gmsh's element size (None: :data:`bladedamp.solid.DEFAULT_ELEMENT_SIZE`,
        6 mm, about 29 000 DOF for the reference blade); ``n_modes`` = 4 gives ("1F", "2F", "1T", "1E").
        The same named points as :meth:`from_beam`, each a least-squares rigid-body fit of the
        FE displacement (OL, OR over their platform contact face); the raw contact-face
        displacements are kept in ``contact_faces``. ``options``: see
        :func:`bladedamp.solid.solid_blade`. Needs the ``fe`` extra (gmsh, scikit-fem).
        Returns a :class:`bladedamp.solid.SolidModalBlade` (a ModalBlade).
        """
        from . import solid   # gmsh / scikit-fem are imported only here
        return solid.solid_blade(geometry, element_size, n_modes, **options)

    # -- files and FE matrices ---------------------------------------------------------
    @classmethod
    def from_file(cls, path, *, dof_map: dict | None = None, points: dict | None = None,
                  n_modes: int | None = None, damping_ratios=None, rigid_links: dict | None = None,
                  fixed_dofs=(), mass: str | None = None, stiffness: str | None = None,
                  **matrix_options) -> "ModalBlade":
        """Read a modal data file (``.npz``, ``.csv``) or the reduced mass and stiffness
        matrices of an FE export (``.op4``, ``.pch``, ``.mtx``, ``.mat``, ``.full``), by the suffix of ``path``.

        FE exports (formats: :mod:`bladedamp.fe_formats`): Nastran OUTPUT4 text or binary
        (``.op4``), Nastran punch DMIG (``.pch``), Abaqus matrix output (``.mtx``: ``path`` is the
        ``_STIF`` or the ``_MASS`` file, the other is found beside it), MATLAB v4-v7.3 (``.mat``),
        Ansys ``.full`` (needs the ``ansys`` extra; its constrained DOF are left out).
        The matrices go to :meth:`from_matrices`, whose arguments ``points``, ``n_modes`` and
        ``damping_ratios`` are then required, and ``rigid_links``, ``mode_names``, ``solver``,
        ``symmetry_tolerance`` may be given. The matrices must be in SI units.

        ``dof_map`` and ``fixed_dofs`` name rows as the exporting code numbers them:

        - files that label rows by node and DOF (DMIG: grid and component 1-6, 0 for a scalar
          point; Abaqus MATRIX INPUT: node and DOF 1-6; Ansys: node and 1-6 for UX .. ROTZ): a point is ``node`` (its DOF 1-6, i.e.
          ux, uy, uz, phix, phiy, phiz) or ``(node, dofs)`` with 6 or 3 DOF numbers in that
          order, e.g. ``{"OL": 101, "tip": (250, (1, 2, 3)), ...}``; ``fixed_dofs`` is a list of
          such entries, e.g. ``[1, 2, 3]`` clamps nodes 1-3.
        - files that number rows only (OUTPUT4, MATLAB, Abaqus COORDINATE): 1-based row
          numbers, e.g. ``{"OL": range(1, 7), ...}``, ``fixed_dofs=range(1, 73)``.

        ``mass``, ``stiffness``: the matrix names in the file (default: the one of
        :data:`bladedamp.fe_formats.DEFAULT_MASS_NAMES` / ``DEFAULT_STIFFNESS_NAMES`` present,
        e.g. MAAX / KAAX, MAA / KAA, M / K); for Abaqus the other file's name.

        A dof_map naming a node or row not in the file, a file that breaks its format, or
        matrices that are unsymmetric, not positive (semi-)definite or have rigid-body modes
        raise ValueError naming the file, the place (line, record, matrix) and what was expected.

        Modal data files (``.npz``, ``.csv``):

        The formats (natural frequencies [Hz], damping ratios [-], point positions [m] and
        mass-normalised 6-DOF shapes [m/sqrt(kg), rad/sqrt(kg)] at OL, OR, tip, excitation
        and any extra points) are described in the module docstring of :mod:`bladedamp.blade`.
        A file that breaks them raises ValueError naming the file, the key or column (and
        the line) and what was expected; a file that is missing (:class:`bladedamp.io.MissingFileError`,
        also a FileNotFoundError), empty, truncated, corrupted, not an ``.npz`` archive or not
        UTF-8 text raises one :class:`bladedamp.io.FileReadError` (a ValueError) naming the file
        and what is wrong (:func:`bladedamp.io.reading`). A solid FE
        blade's ``.npz`` (format :data:`SOLID_NPZ_FORMAT`, :meth:`bladedamp.solid.SolidModalBlade.save`)
        gives a :class:`bladedamp.solid.SolidModalBlade` with its flexible platforms and surface.
        """
        path = Path(path)
        from . import fe_formats
        if path.suffix.lower().lstrip(".") in fe_formats.FE_SUFFIXES:
            return _blade_from_fe_file(cls, path, dof_map, points, n_modes, damping_ratios, rigid_links,
                                       fixed_dofs, mass, stiffness, matrix_options)
        given = [k for k, v in dict(dof_map=dof_map, points=points, n_modes=n_modes, damping_ratios=damping_ratios,
                                    rigid_links=rigid_links, mass=mass, stiffness=stiffness).items()
                 if v is not None] + (["fixed_dofs"] if tuple(fixed_dofs) else []) + list(matrix_options)
        if given:
            raise ValueError(f"{path}: {given} apply to FE matrix files only "
                             f"({sorted('.' + s for s in fe_formats.FE_SUFFIXES)}); a modal data file has its modes")
        kind = _modal_file_kind(path)
        with reading(path, "modal data file"):
            if kind == "npz":
                fields, tag, extra = read_modal_npz(path)
                if tag in SOLID_NPZ_FORMATS_READ:
                    from .solid import SolidModalBlade
                    return SolidModalBlade.from_npz_arrays(path, fields, extra)
            else:
                fields = _read_modal_csv(path)
            try:
                return cls(**fields)
            except ValueError as err:
                raise ValueError(f"{path}: {err}") from None

    def save(self, path) -> Path:
        """Write this blade to ``path``: ``.npz`` or ``.csv`` by its suffix (formats: module
        docstring of :mod:`bladedamp.blade`). Every value is written exactly (the CSV holds
        the shortest decimal that reads back to the same float), so ``from_file`` gives the
        same arrays back (a solid FE blade: ``.npz`` only, :meth:`bladedamp.solid.SolidModalBlade.save`).
        Returns the path."""
        path = Path(path)
        kind = _modal_file_kind(path)
        if kind == "npz":
            with open(path, "wb") as fh:   # a file object: np.savez_compressed would append .npz to ".NPZ"
                np.savez_compressed(fh, **self.npz_arrays())
        else:
            _write_modal_csv(self, path)
        return path

    def npz_arrays(self) -> dict:
        """The arrays of this blade's ``.npz`` file by key (the format of the module docstring:
        ``format``, ``natural_frequencies_hz``, ``damping_ratios``, ``mode_names``,
        ``point_names``, ``point_positions`` (n_p, 3), ``mode_shapes`` (n_p, 6, n_m))."""
        names = list(self.points)
        return dict(format=np.array(MODAL_NPZ_FORMAT), natural_frequencies_hz=self.natural_frequencies_hz,
                    damping_ratios=self.damping_ratios, mode_names=np.array(self.mode_names, dtype=str),
                    point_names=np.array(names, dtype=str),
                    point_positions=np.array([self.points[p] for p in names]),
                    mode_shapes=np.array([self.mode_shapes[p] for p in names]))

    @classmethod
    def from_matrices(cls, mass, stiffness, dof_map: dict, *, points: dict, n_modes: int,
                      damping_ratios, rigid_links: dict | None = None, fixed_dofs=(),
                      mode_names=(), solver: str = "auto",
                      symmetry_tolerance: float = 1e-8) -> "ModalBlade":
        """Modes of reduced FE matrices (a Craig-Bampton or Guyan export) at named points.

        Solves K v = omega^2 M v for the ``n_modes`` lowest modes, mass-normalises them
        (v^T M v = 1, so the shapes are in m/sqrt(kg) and rad/sqrt(kg)) and picks their
        values at the points of ``dof_map`` and ``rigid_links``.

        Parameters
        ----------
        mass, stiffness : (n, n) arrays or scipy.sparse matrices in SI units (kg and kg m^2;
            N/m and N m/rad; Craig-Bampton modal coordinates as exported). M must be positive
            definite and K positive semi-definite on the free DOF, both symmetric to
            ``symmetry_tolerance`` (their symmetric parts are used).
        dof_map : point name -> indices (rows of M and K as given) of the point's six DOF
            (ux, uy, uz, phix, phiy, phiz) or of its three translations (ux, uy, uz). A point
            given by translations only gets zero rotations: right where only a force acts or a
            translation is read (tip, excitation of a solid model), but OL and OR rotate the
            damper contact, so give them 6 DOF (e.g. an RBE2/RBE3 master node) or a rigid link
            (a warning says so otherwise).
        points : point name -> (3,) position [m] in the blade frame, for every point of
            ``dof_map`` and ``rigid_links`` (and no other).
        n_modes : number of modes kept (the lowest), in [1, number of free DOF].
        damping_ratios : modal damping ratio(s) D_j [-], >= 0, scalar or (n_modes,): FE
            matrices carry no damping.
        rigid_links : point name -> name of a 6-DOF point of ``dof_map`` it is rigidly
            attached to: it moves by u + phi x r, r = its position minus the master's
            (e.g. ``{"OL": "platform", "OR": "platform"}`` on a beam model).
        fixed_dofs : indices of clamped DOF (e.g. the root interface of a model exported
            with it free); they are removed before solving and have zero shape.
        mode_names : empty or ``n_modes`` names, lowest mode first.
        solver : "dense" (scipy.linalg.eigh, all modes), "sparse" (scipy.sparse.linalg.eigsh,
            shift-invert about :data:`SHIFT_INVERT_SIGMA`, then Rayleigh-Ritz) or "auto"
            (sparse above :data:`DENSE_SOLVER_MAX_DOF` free DOF). Both work on the
            equilibrated matrices D M D, D K D with D = diag(M)^-1/2.
        symmetry_tolerance : largest allowed max|A - A^T| / max|A| of M and K, >= 0 (FE
            exports print a limited number of digits).

        Rigid-body modes are refused: the blade of a bladed disk is clamped at its root, and a
        Craig-Bampton model with its root interface fixed has none. A mode v counts as rigid
        when K v vanishes to rounding, max|K v| <= :data:`RIGID_MODE_TOLERANCE` * max(|K| |v|);
        clamp the root with ``fixed_dofs`` (or export the model clamped).

        Signs: in every mode the tip's translation of largest magnitude is positive (its
        largest rotation if the tip does not translate).
        """
        M = _fe_matrix("mass", mass, symmetry_tolerance)
        K = _fe_matrix("stiffness", stiffness, symmetry_tolerance)
        if K.shape != M.shape:
            raise ValueError(f"stiffness must have the shape of mass {M.shape} (got {K.shape})")
        n = M.shape[0]
        fixed = _dof_indices("fixed_dofs", fixed_dofs, n, allow_empty=True)
        if np.unique(fixed).size != fixed.size:
            raise ValueError(f"fixed_dofs must not repeat an index (got {list(fixed)})")
        free = np.setdiff1d(np.arange(n), fixed)
        if free.size == 0:
            raise ValueError("fixed_dofs must leave at least one free DOF")
        n_modes = check.integer("n_modes", n_modes, minimum=1, maximum=int(free.size))

        # point maps, checked before the (possibly long) eigen-solution
        if not isinstance(dof_map, dict) or not dof_map:
            raise ValueError("dof_map must be a non-empty dict: point name -> 6 or 3 DOF indices")
        links = dict(rigid_links or {})
        maps = {}
        for name, dofs in dof_map.items():
            idx = _dof_indices(f"dof_map[{name!r}]", dofs, n)
            if idx.size not in (3, 6):
                raise ValueError(
                    f"dof_map[{name!r}] must list 6 DOF indices (ux, uy, uz, phix, phiy, phiz) "
                    f"or 3 (ux, uy, uz) (got {idx.size})")
            maps[name] = idx
        for name, master in links.items():
            if name in maps:
                raise ValueError(f"point {name!r} is in both dof_map and rigid_links; give it in one")
            if master not in maps or maps[master].size != 6:
                raise ValueError(
                    f"rigid_links[{name!r}] must name a point of dof_map with 6 DOF "
                    f"(got {master!r}; 6-DOF points: {[p for p in maps if maps[p].size == 6]})")
        named = set(maps) | set(links)
        if not isinstance(points, dict) or set(points) != named:
            given = set(points) if isinstance(points, dict) else set()
            raise ValueError(
                "points must give the (3,) position [m] of every point of dof_map and "
                f"rigid_links and no other (missing: {sorted(named - given)}, "
                f"extra: {sorted(given - named)})")
        missing = [p for p in REQUIRED_POINTS if p not in named]
        if missing:
            raise ValueError(f"dof_map and rigid_links must give the required points "
                             f"{REQUIRED_POINTS}; missing: {missing}")
        positions = {}
        for name, pos in points.items():
            positions[name] = check.finite(f"points[{name!r}]", np.asarray(pos, dtype=float))
            if np.shape(positions[name]) != (3,):
                raise ValueError(f"points[{name!r}] must be a (3,) position [m] (got shape "
                                 f"{np.shape(positions[name])})")
        damping = np.asarray(check.nonnegative("damping_ratios", damping_ratios))
        if damping.shape not in ((), (n_modes,)):
            raise ValueError(f"damping_ratios must be a scalar or have shape ({n_modes},) = (n_modes,) "
                             f"(got {damping.shape})")
        mode_names = tuple(mode_names or ())
        if mode_names and len(mode_names) != n_modes:
            raise ValueError(f"mode_names must be empty or have n_modes = {n_modes} entries "
                             f"(got {len(mode_names)})")
        for name in ("OL", "OR"):
            if name in maps and maps[name].size == 3:
                warnings.warn(f"dof_map[{name!r}] has translations only: its rotations are taken "
                              "as zero, which leaves out the platform rotation at the damper "
                              "contact; give 6 DOF or a rigid link", stacklevel=2)

        lam, vecs = _lowest_modes(M, K, free, n_modes, solver)
        full = np.zeros((n, n_modes))
        full[free] = vecs
        shapes = {}
        for name, idx in maps.items():
            shapes[name] = full[idx] if idx.size == 6 else np.vstack([full[idx], np.zeros((3, n_modes))])
        for name, master in links.items():
            shapes[name] = rigid_offset_motion(shapes[master], positions[name] - positions[master])
        flip = _tip_sign(shapes["tip"], shapes)
        shapes = {name: s * flip for name, s in shapes.items()}
        return cls(natural_frequencies_hz=np.sqrt(lam) / (2.0 * np.pi), damping_ratios=damping,
                   mode_shapes=shapes, points=positions, mode_names=mode_names)

    @classmethod
    def from_test(cls, path, points: dict, *, positions: dict | None = None, damping_ratios=None,
                  modal_masses=None, units: str | None = None, mode_names=()) -> "ModalBlade":
        """A blade from measured (or exported) normal modes, UFF dataset 55 or 2414
        (:func:`bladedamp.measurement.load_modes`), at named nodes.

        points : point name -> node number of the file, for "OL", "OR", "tip", "excitation" (and any
            other). Each point takes the node's six shape values (rotations zero where the file
            gives translations only: then OL and OR do not rotate the damper contact).
        positions : point name -> (3,) position [m] in the blade frame; default: the node's
            coordinates from the file's dataset 15 or 2411 (ValueError if it has none).
        damping_ratios : modal damping ratios [-] (scalar or (n_m,)); default: the file's viscous
            damping ratios (ValueError if all are 0).
        modal_masses : modal mass [kg] of each stored shape (scalar or (n_m,); 1.0 for shapes
            mass-normalised in kg, 1000.0 for shapes mass-normalised in a file in mm, N, s and
            tonnes); default: the file's (ValueError naming the mode where it gives none). The
            shapes are divided by sqrt(modal mass): mass-normalised, Eq. 2.
        units : "SI" for a file without a dataset 164 (unit system); default: the file's.
        """
        from .measurement import load_modes

        if not isinstance(points, dict) or any(p not in points for p in REQUIRED_POINTS):
            raise ValueError(f"points must map the names {REQUIRED_POINTS} (and any others) to node numbers "
                             f"(got {points!r})")
        modes = load_modes(path, units=units)
        normalised = modes.mass_normalised(modal_masses)
        shapes, where = {}, {}
        for name, node in points.items():
            i = modes.node_index(node)
            shapes[name] = normalised[i]
            given = None if positions is None else positions.get(name)
            where[name] = np.asarray(given, dtype=float) if given is not None else modes.coordinates[i]
            if not np.all(np.isfinite(where[name])):
                raise ValueError(f"{modes.source}: no position of node {node} (point {name!r}) in the file: give "
                                 f"positions={{{name!r}: (x, y, z) in m, ...}}")
        if damping_ratios is None and not np.any(modes.damping_ratios > 0):
            raise ValueError(f"{modes.source}: the modes carry no damping (all ratios 0): give damping_ratios")
        damping = modes.damping_ratios if damping_ratios is None else damping_ratios
        return cls(natural_frequencies_hz=modes.natural_frequencies_hz, damping_ratios=damping,
                   mode_shapes=shapes, points=where, mode_names=tuple(mode_names or ()))

    # -- linear reference solution -----------------------------------------------------
    def linear_frf(self, f_hz: np.ndarray, force: np.ndarray, at: str = "excitation",
                   response_at: str = "tip") -> np.ndarray:
        """Linear (no damper) harmonic response, closed-form modal superposition (Eq. 4-5).

        u(Omega) = Phi_resp S(Omega)^-1 Phi_at^T f.

        Parameters
        ----------
        f_hz : excitation frequencies [Hz], scalar or (n,).
        force : (6,) complex amplitude (F_x, F_y, F_z [N], M_x, M_y, M_z [N m]) at ``at``.
        at, response_at : point names.

        Returns
        -------
        (n, 6) complex response amplitudes (u [m], phi [rad]) at ``response_at``.
        """
        omega = 2.0 * np.pi * np.atleast_1d(check.finite("f_hz", f_hz))
        if omega.ndim != 1:
            raise ValueError(f"f_hz must be a scalar or 1-D array [Hz] (got shape {omega.shape})")
        modal_force = self.modal_force(force, at)                       # (n_m,)
        w0 = self.natural_angular_frequencies
        S = w0**2 - omega[:, None]**2 + 2j * self.damping_ratios * w0 * omega[:, None]  # Eq. 5
        q = modal_force[None, :] / S                                     # Eq. 4, (n, n_m)
        return q @ self.shape(response_at).T                            # Eq. 2


# --------------------------------------------------------------------------------------
# Modal data files and FE matrices (helpers of ModalBlade.from_file / save / from_matrices)
# --------------------------------------------------------------------------------------
def _blade_from_fe_file(cls, path: Path, dof_map, points, n_modes, damping_ratios, rigid_links,
                        fixed_dofs, mass, stiffness, matrix_options) -> "ModalBlade":
    """ModalBlade.from_file for FE exports: read the matrices, turn the node/DOF names of
    dof_map and fixed_dofs into rows, then from_matrices; errors name the file."""
    from .fe_formats import read_fe_matrices
    missing = [k for k, v in dict(dof_map=dof_map, points=points, n_modes=n_modes,
                                  damping_ratios=damping_ratios).items() if v is None]
    if missing:
        raise ValueError(f"{path}: an FE matrix file needs {missing} (see ModalBlade.from_file)")
    unknown = sorted(set(matrix_options) - {"mode_names", "solver", "symmetry_tolerance"})
    if unknown:
        raise ValueError(f"{path}: unknown options {unknown}; expected mode_names, solver, symmetry_tolerance")
    fe = read_fe_matrices(path, mass=mass, stiffness=stiffness)
    if not isinstance(dof_map, dict) or not dof_map:
        raise ValueError(f"{path}: dof_map must be a non-empty dict: point name -> node/DOF (see ModalBlade.from_file)")
    rows = {name: fe.row_indices(f"dof_map[{name!r}]", value) for name, value in dof_map.items()}
    fixed_given = list(fixed_dofs) if not isinstance(fixed_dofs, range) else fixed_dofs
    fixed = fe.row_indices("fixed_dofs", fixed_given) if len(fixed_given) else np.zeros(0, dtype=int)
    m_diag = fe.mass.diagonal()
    free = np.setdiff1d(np.arange(fe.n), fixed)
    bad = free[m_diag[free] <= 0]
    if bad.size:
        raise ValueError(f"{path}: mass matrix {fe.names[0]}: {fe.describe_row(int(bad[0]))} has M = "
                         f"{m_diag[bad[0]]:g}; expected a positive diagonal on the free DOF (clamp the row with "
                         "fixed_dofs or condense it out)")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            blade = cls.from_matrices(fe.mass, fe.stiffness, rows, points=points, n_modes=n_modes,
                                      damping_ratios=damping_ratios, rigid_links=rigid_links, fixed_dofs=fixed,
                                      **matrix_options)
    except ValueError as err:
        raise ValueError(f"{path}: matrices {fe.names[0]} (mass), {fe.names[1]} (stiffness): {err}") from None
    for w in caught:                  # point the warnings at the caller of from_file
        warnings.warn(f"{path}: {w.message}", w.category, stacklevel=3)
    return blade


def _modal_file_kind(path: Path) -> str:
    kind = path.suffix.lower().lstrip(".")
    if kind not in ("npz", "csv"):
        raise ValueError(f"{path}: a modal data file must end in .npz or .csv (got {path.suffix!r})")
    return kind


def read_modal_npz(path) -> tuple[dict, str, dict]:
    """(ModalBlade fields, format tag, other arrays) of a modal data ``.npz`` file (format:
    module docstring): the fields as keyword arguments of :class:`ModalBlade`; the tag is the
    file's ``format`` entry (:data:`MODAL_NPZ_FORMAT` when it has none, or
    :data:`SOLID_NPZ_FORMAT`); the other arrays (key -> array, read without pickle) are those
    beyond :data:`MODAL_NPZ_KEYS`, which only the solid format may have. ValueError naming the
    file and the key for a file that breaks the format, :class:`bladedamp.io.FileReadError` (a
    ValueError) naming the file for one that is missing, empty, truncated, corrupted or not an
    ``.npz`` archive."""
    path = Path(path)
    with reading(path, "modal data file"), open_npz(path) as data:
        keys = set(data.files)

        def array(key, kind):
            try:
                arr = data[key]
            except ValueError as err:   # object arrays need pickle
                raise ValueError(f"{path}: key {key!r} must be a plain {kind} array ({err})") from None
            if kind == "string" and arr.size and arr.dtype.kind != "U":
                raise ValueError(f"{path}: key {key!r} must hold strings (got dtype {arr.dtype})")
            if kind == "float":
                if arr.dtype.kind not in "iuf":
                    raise ValueError(f"{path}: key {key!r} must hold numbers (got dtype {arr.dtype})")
                arr = arr.astype(float)
            return arr

        tag = str(array("format", "string")) if "format" in keys else MODAL_NPZ_FORMAT
        if tag not in (MODAL_NPZ_FORMAT, *SOLID_NPZ_FORMATS_READ):
            raise ValueError(f"{path}: key 'format' must be {MODAL_NPZ_FORMAT!r} (or {SOLID_NPZ_FORMAT!r}, "
                             f"a solid FE blade's) (got {tag!r})")
        unknown = sorted(keys - set(MODAL_NPZ_KEYS)) if tag == MODAL_NPZ_FORMAT else []
        missing = [k for k in MODAL_NPZ_KEYS if k not in keys and k not in ("mode_names", "format")]
        if unknown or missing:
            raise ValueError(f"{path}: keys {MODAL_NPZ_KEYS} expected ('mode_names', 'format' "
                             f"optional); missing: {missing}, unknown: {unknown}")
        extra = {k: array(k, "numeric or string") for k in sorted(keys - set(MODAL_NPZ_KEYS))}
        freqs = array("natural_frequencies_hz", "float")
        if freqs.ndim != 1 or freqs.size == 0:
            raise ValueError(f"{path}: key 'natural_frequencies_hz' must be a non-empty (n_modes,) "
                             f"array [Hz] (got shape {freqs.shape})")
        n_m = freqs.size
        names = array("point_names", "string")
        n_p = names.size
        expected = {"damping_ratios": (n_m,), "point_names": (n_p,), "point_positions": (n_p, 3),
                    "mode_shapes": (n_p, 6, n_m)}
        arrays = {"point_names": names}
        for key in ("damping_ratios", "point_positions", "mode_shapes"):
            arrays[key] = array(key, "float")
        mode_names = array("mode_names", "string") if "mode_names" in keys else np.array([], dtype=str)
        if mode_names.shape not in ((0,), (n_m,)):
            raise ValueError(f"{path}: key 'mode_names' must have shape (0,) or ({n_m},) = (n_modes,) "
                             f"(got {mode_names.shape})")
        for key, shape in expected.items():
            if arrays[key].shape != shape:
                raise ValueError(f"{path}: key {key!r} must have shape {shape} (n_points = {n_p}, "
                                 f"n_modes = {n_m}) (got {arrays[key].shape})")
        names = [str(p) for p in names]
        if len(set(names)) != len(names):
            raise ValueError(f"{path}: key 'point_names' must not repeat a name (got {names})")
        fields = dict(natural_frequencies_hz=freqs, damping_ratios=arrays["damping_ratios"],
                      mode_shapes=dict(zip(names, arrays["mode_shapes"])),
                      points=dict(zip(names, arrays["point_positions"])),
                      mode_names=tuple(str(m) for m in mode_names))
    return fields, tag, extra


def _read_modal_csv(path: Path) -> dict:
    """ModalBlade fields from a .csv file, one row per (mode, point) (format: module docstring);
    :class:`bladedamp.io.FileReadError` naming the file if it cannot be read as UTF-8 text."""
    with reading(path, "modal data file"), open(path, newline="", encoding="utf-8-sig") as fh:
        numbered = [(n, line) for n, line in enumerate(fh, start=1)
                    if line.strip() and not line.lstrip().startswith("#")]
    if not numbered:
        raise ValueError(f"{path}: no header line; expected the columns {MODAL_CSV_COLUMNS}")
    rows = list(csv.reader(line for _, line in numbered))
    line_of = [n for n, _ in numbered]
    header = [c.strip() for c in rows[0]]
    where = f"{path}: line {line_of[0]} (header)"
    if len(header) == 1 and any(sep in header[0] for sep in ";\t"):
        raise ValueError(f"{where}: columns must be separated by commas (got {header[0]!r})")
    optional = ("mode_name",)
    unknown = [c for c in header if c not in MODAL_CSV_COLUMNS]
    missing = [c for c in MODAL_CSV_COLUMNS if c not in header and c not in optional]
    repeated = sorted({c for c in header if header.count(c) > 1})
    if unknown or missing or repeated:
        raise ValueError(f"{where}: expected the columns {MODAL_CSV_COLUMNS} ('mode_name' optional), "
                         f"in any order; missing: {missing}, unknown: {unknown}, repeated: {repeated}")
    col = {c: header.index(c) for c in header}
    units = {"frequency_hz": "Hz", "damping_ratio": "-", "x": "m", "y": "m", "z": "m"}

    modes: dict[int, tuple] = {}        # mode -> (frequency, damping, name, line)
    positions: dict[str, tuple] = {}    # point -> (position, line)
    shapes: dict[tuple, list] = {}      # (mode, point) -> 6 values
    for row, line in zip(rows[1:], line_of[1:]):
        where = f"{path}: line {line}"
        if len(row) != len(header):
            raise ValueError(f"{where}: expected {len(header)} comma-separated values, one per "
                             f"column of the header (got {len(row)})")
        cell = {c: row[i].strip() for c, i in col.items()}

        def number(c):
            try:
                value = float(cell[c])
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                unit = units.get(c, "m/sqrt(kg)" if c.startswith("u") else "rad/sqrt(kg)")
                raise ValueError(f"{where}: column {c!r} must be a finite number [{unit}] "
                                 f"(got {cell[c]!r})") from None
            return value

        try:
            mode = int(cell["mode"])
        except ValueError:
            mode = 0
        if mode < 1:
            raise ValueError(f"{where}: column 'mode' must be a mode number 1, 2, ... (got {cell['mode']!r})")
        point = cell["point"]
        if not point:
            raise ValueError(f"{where}: column 'point' must name the point (e.g. OL, OR, tip, excitation)")
        per_mode = (number("frequency_hz"), number("damping_ratio"), cell.get("mode_name", ""))
        if mode in modes and modes[mode][:3] != per_mode:
            raise ValueError(
                f"{where}: mode {mode} has frequency_hz, damping_ratio, mode_name = {per_mode}, but "
                f"{modes[mode][:3]} on line {modes[mode][3]}; they must be the same on every row of a mode")
        modes.setdefault(mode, per_mode + (line,))
        xyz = (number("x"), number("y"), number("z"))
        if point in positions and positions[point][0] != xyz:
            raise ValueError(f"{where}: point {point!r} is at x, y, z = {xyz} [m], but at "
                             f"{positions[point][0]} on line {positions[point][1]}; a point has one position")
        positions.setdefault(point, (xyz, line))
        if (mode, point) in shapes:
            raise ValueError(f"{where}: mode {mode} at point {point!r} is given twice; once expected")
        shapes[(mode, point)] = [number(c) for c in MODAL_CSV_COLUMNS[-6:]]
    if not shapes:
        raise ValueError(f"{path}: no data rows after the header; one row per (mode, point) expected")
    n_m = max(modes)
    gaps = sorted(set(range(1, n_m + 1)) - set(modes))
    if gaps:
        raise ValueError(f"{path}: column 'mode' must number the modes 1..{n_m} without gaps (missing {gaps})")
    absent = [(m, p) for m in range(1, n_m + 1) for p in positions if (m, p) not in shapes]
    if absent:
        raise ValueError(f"{path}: every mode must list every point; no row for (mode, point) "
                         f"{absent[:5]}{' ...' if len(absent) > 5 else ''}")
    names = [modes[m][2] for m in range(1, n_m + 1)]
    if any(names) and not all(names):
        raise ValueError(f"{path}: column 'mode_name' must name every mode or none "
                         f"(unnamed: modes {[m + 1 for m, s in enumerate(names) if not s]})")
    return dict(natural_frequencies_hz=[modes[m][0] for m in range(1, n_m + 1)],
                damping_ratios=[modes[m][1] for m in range(1, n_m + 1)],
                mode_shapes={p: np.array([shapes[(m, p)] for m in range(1, n_m + 1)]).T for p in positions},
                points={p: np.array(xyz) for p, (xyz, _) in positions.items()},
                mode_names=tuple(names) if all(names) else ())


def _write_modal_csv(blade: "ModalBlade", path: Path) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        fh.write("# bladedamp modal blade: one row per (mode, point); format in the docstring of "
                 "bladedamp.blade\n"
                 "# units: frequency_hz [Hz], damping_ratio [-], x y z [m] (blade frame: x "
                 "circumferential, y axial, z radial),\n"
                 "#        ux uy uz [m/sqrt(kg)], phix phiy phiz [rad/sqrt(kg)]: mass-normalised "
                 "mode shapes (Phi^T M Phi = I)\n")
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(MODAL_CSV_COLUMNS)
        for j in range(blade.n_modes):
            name = blade.mode_names[j] if blade.mode_names else ""
            for point, pos in blade.points.items():
                writer.writerow([j + 1, name, repr(float(blade.natural_frequencies_hz[j])),
                                 repr(float(blade.damping_ratios[j])), point]
                                + [repr(float(v)) for v in pos]
                                + [repr(float(v)) for v in blade.mode_shapes[point][:, j]])


def _fe_matrix(name: str, value, symmetry_tolerance: float):
    """Square, finite, symmetric (to the tolerance) FE matrix; returns its symmetric part
    (dense float array, or CSR for a scipy.sparse input)."""
    tol = check.nonnegative("symmetry_tolerance", symmetry_tolerance)
    sparse = scipy.sparse.issparse(value)
    A = scipy.sparse.csr_matrix(value, dtype=float) if sparse else np.array(value, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or A.shape[0] == 0:
        raise ValueError(f"{name} must be a square (n, n) matrix (got shape {A.shape})")
    if not np.all(np.isfinite(A.data if sparse else A)):
        raise ValueError(f"{name} must be finite (it has NaN or inf entries)")
    scale = abs(A).max()
    if scale == 0:
        raise ValueError(f"{name} must not be zero")
    asymmetry = abs(A - A.T).max() / scale
    if asymmetry > tol:
        raise ValueError(f"{name} must be symmetric: max|A - A^T| / max|A| = {asymmetry:.3g} exceeds "
                         f"symmetry_tolerance = {tol:g}")
    return (A + A.T) * 0.5


def _dof_indices(name: str, value, n: int, allow_empty: bool = False) -> np.ndarray:
    """Integer DOF indices in [0, n)."""
    arr = np.asarray(value)
    if arr.ndim != 1 or (arr.size == 0 and not allow_empty) or (
            arr.size and not np.all(np.mod(arr.astype(float), 1) == 0)):
        raise ValueError(f"{name} must be a sequence of integer DOF indices in [0, {n - 1}] (got {value!r})")
    arr = arr.astype(int)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise ValueError(f"{name} must hold DOF indices in [0, {n - 1}] (got {value!r})")
    return arr


def _lowest_modes(M, K, free: np.ndarray, n_modes: int, solver: str):
    """The n_modes lowest eigenpairs of K v = lambda M v on the free DOF: (lambda, V) with
    V^T M V = I; refuses an indefinite M or K and rigid-body modes (see from_matrices)."""
    if solver not in ("auto", "dense", "sparse"):
        raise ValueError(f"solver must be 'auto', 'dense' or 'sparse' (got {solver!r})")
    sparse_input = scipy.sparse.issparse(M) or scipy.sparse.issparse(K)
    Mf = M[free][:, free]
    Kf = K[free][:, free]
    m_diag, k_diag = Mf.diagonal(), Kf.diagonal()
    bad = np.flatnonzero(m_diag <= 0)
    if bad.size:
        raise ValueError(f"mass must be positive definite on the free DOF: M[{free[bad[0]]}, "
                         f"{free[bad[0]]}] = {m_diag[bad[0]]:g} (a massless DOF must be condensed out, "
                         "e.g. by a Guyan reduction, or clamped with fixed_dofs)")
    if not np.any(k_diag):
        raise ValueError("stiffness must not be zero on the free DOF")
    # Equilibrate (D M D has unit diagonal, D = diag(M)^-1/2): same eigenvalues, vectors D v.
    # FE matrices mix translations and rotations of very different mass; equilibrating
    # takes the beam model's cond(M) from 2.6e7 to 29.
    d = 1.0 / np.sqrt(m_diag)
    if sparse_input:
        D = scipy.sparse.diags(d)
        Me, Ke = scipy.sparse.csc_matrix(D @ Mf @ D), scipy.sparse.csc_matrix(D @ Kf @ D)
    else:
        Me, Ke = Mf * d[:, None] * d[None, :], Kf * d[:, None] * d[None, :]
    use_sparse = solver == "sparse" or (solver == "auto" and free.size > DENSE_SOLVER_MAX_DOF)
    if use_sparse and n_modes >= free.size - 1:
        use_sparse = False                      # ARPACK needs n_modes < n - 1
    try:
        if use_sparse:   # eigsh factorises K - sigma M: SuperLU for sparse input, LAPACK for dense
            _, V = scipy.sparse.linalg.eigsh(Ke, k=n_modes, M=Me, sigma=SHIFT_INVERT_SIGMA, which="LM")
            # Rayleigh-Ritz on the found subspace: exact M-orthonormality, ascending order
            lam, Q = scipy.linalg.eigh(V.T @ (Ke @ V), V.T @ (Me @ V))
            V = V @ Q
        else:
            if scipy.sparse.issparse(Me):
                Me, Ke = Me.toarray(), Ke.toarray()
            # all eigenpairs: the subset driver (gvx) loses 3e-7 of the beam's 1F omega^2
            lam, V = scipy.linalg.eigh(Ke, Me)
            lam, V = lam[:n_modes], V[:, :n_modes]
    except (np.linalg.LinAlgError, RuntimeError) as err:   # Cholesky of M, or ARPACK / the factorisation
        raise ValueError(f"mass must be positive definite on the free DOF and stiffness positive "
                         f"semi-definite (the eigen-solver failed: {err})") from None
    V = V / np.sqrt(np.einsum("ij,ij->j", V, Me @ V))   # v^T M v = 1 (kept exact after Ritz)
    V = V * d[:, None]
    residual = np.abs(Kf @ V).max(axis=0) / (abs(Kf) @ np.abs(V)).max(axis=0)
    rigid = residual <= RIGID_MODE_TOLERANCE
    if rigid.any():
        raise ValueError(
            f"the matrices have {int(rigid.sum())} rigid-body (zero-frequency) mode(s) among the "
            f"{n_modes} lowest: a blade must be clamped at its root; pass the root DOF as fixed_dofs "
            "(or export the Craig-Bampton model with its root interface fixed)")
    if np.any(lam <= 0):
        raise ValueError(f"stiffness must be positive semi-definite on the free DOF (an eigenvalue "
                         f"omega^2 = {lam.min():.4g} 1/s^2 <= 0 that is no rigid-body mode)")
    return lam, V


def _tip_sign(tip: np.ndarray, shapes: dict) -> np.ndarray:
    """(n_m,) +-1 that makes each mode's largest tip translation positive (or its largest tip
    rotation, if the tip does not translate in that mode)."""
    reach = np.max([np.abs(s[:3]).max(axis=0) for s in shapes.values()], axis=0)   # (n_m,)
    sign = np.ones(tip.shape[1])
    for j in range(tip.shape[1]):
        translates = np.abs(tip[:3, j]).max() > 1e-6 * reach[j]
        part = tip[:3, j] if translates else tip[3:, j]
        value = part[np.argmax(np.abs(part))]
        sign[j] = -1.0 if value < 0 else 1.0
    return sign


# --------------------------------------------------------------------------------------
# Beam blade geometry and FE model
# --------------------------------------------------------------------------------------
def platform_section(centres, gamma_left: float, gamma_right: float, edge: float, top: float,
                     face_inner_length: float, min_edge_thickness: float) -> np.ndarray:
    """(6, 2) (x, z) section of the platform prism [m], of the 3D view
    (:func:`bladedamp.geometry.blade_mesh`) and the solid FE blade (:mod:`bladedamp.solid`):
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


def solid_platform_beam(solid_geometry=None, bending_theory: str = "timoshenko",
                        torsion_theory: str = "vlasov", n_elements: int = 1) -> BeamBladeGeometry:
    """The beam model of the parametric solid blade's geometry (:class:`bladedamp.solid.SolidBladeGeometry`,
    None: the reference's): its beam geometry with the solid's platform prism as the platform block
    (:meth:`PlatformBlock.from_polygon` of ``platform_polygon()`` over ``platform_length``, with
    ``n_elements`` elements on each side of the platform node), no lumped platform mass or
    inertia (the block is the whole platform), and the given bending and torsion theories
    (default the refined ones, which the solid has). Refused (ValueError): what the beam does not
    represent, a twisted airfoil, a root block, a platform of another Young's modulus, no platform."""
    if solid_geometry is None:
        from .solid import SolidBladeGeometry   # solid.py imports this module
        solid_geometry = SolidBladeGeometry()
    sg = solid_geometry
    unsupported = [name for name, bad in (("twist", sg.twist != 0.0), ("root_height", sg.root_height > 0.0),
                                          ("platform", not sg.platform),
                                          ("platform_youngs_modulus", sg.platform_youngs_modulus is not None
                                           and sg.platform_youngs_modulus != sg.beam.youngs_modulus)) if bad]
    if unsupported:
        raise ValueError(f"solid_platform_beam: the beam model does not represent {unsupported} of the solid geometry")
    block = PlatformBlock.from_polygon(sg.platform_polygon(), sg.platform_length, n_elements)
    return dataclasses.replace(sg.beam, platform_block=block, platform_mass=0.0,
                               platform_rotary_inertia=(0.0, 0.0, 0.0), bending_theory=bending_theory,
                               torsion_theory=torsion_theory)


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


# --------------------------------------------------------------------------------------
# The paper's reference values of the blade (bladedamp.reference builds the reference disk on them)
# --------------------------------------------------------------------------------------
# The paper's Table 1: natural frequencies [Hz] and modal damping ratios [-] of 1F, 2F, 1T, 1E
# (the order of bladedamp.blade.PAPER_MODE_ORDER). The beam model gives the mode shapes only;
# reference_blade() substitutes these frequencies and ratios.
TABLE1_FREQUENCIES_HZ = (95.0, 423.0, 783.0, 1065.0)
TABLE1_DAMPING_RATIOS = (0.001, 0.001, 0.001, 0.001)
# The platform angle of the contact faces, gamma_L = gamma_R (paper: 35 deg) [rad]: the default
# of every model with platforms (TunedDisk, MistunedDisk, the solid blade, the 3D geometry).
PLATFORM_ANGLE = np.radians(35.0)


# --------------------------------------------------------------------------------------
# The reference blade (paper's tuned system, Table 1): calibration (1)
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
    # CALIBRATED (1): chord_y = 45.5 mm: sets the blade mass (0.367 kg incl. platform) so
    # that the 1F tip mode-shape value is 3.48 /sqrt(kg) and the no-damper 1F resonance tip
    # amplitude under F_x = 0.1 N (Table 1 frequencies, D = 0.001) is 1.70 mm (paper, m = 0 g).
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
