"""The modal blade (paper Eq. 1-5), its modal data files and reduced FE matrices.

Conventions (frames, 6-vectors, units): :mod:`bladedamp.blade`. Mass-normalised mode shapes have
units m/sqrt(kg) (translations) and rad/sqrt(kg) (rotations); modal coordinates sqrt(kg)*m.

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
``bladedamp.ModalBlade/1``).  A solid FE blade (:class:`bladedamp.blade.solid.SolidModalBlade`)
writes the format ``bladedamp.SolidModalBlade/2``: these arrays plus its flexible platforms'
FE field, surface and solid_info under ``solid/`` (:meth:`~bladedamp.blade.solid.SolidModalBlade.npz_arrays`);
it has no CSV form.  A file written by :meth:`ModalBlade.save` also has the entry
``__bladedamp__`` of every saved bladedamp object (:mod:`bladedamp.io`: JSON naming the class,
which :func:`bladedamp.io.load` reads it with); a file without it (a hand-written one, or one
saved before) is read by its ``format`` (none: a ModalBlade).  A bad file raises ValueError
naming the file, the key or column (and line) and what was expected.

Reduced FE matrices (:meth:`ModalBlade.from_matrices`): Craig-Bampton or Guyan exports with
the root clamped; the modes are computed and picked at the named points. :meth:`ModalBlade.from_file`
reads them from Nastran OUTPUT4 / punch DMIG, Abaqus, MATLAB and Ansys files
(:mod:`bladedamp.fe_formats`).

The solid FE blade is built by :func:`bladedamp.blade.solid.solid_blade` (a SolidModalBlade);
this module sits below it and does not import it.
"""
from __future__ import annotations

import csv
import dataclasses
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from bladedamp import validation as check
from bladedamp.io import (BLADE_FORMATS, META_KEY, MODAL_NPZ_FORMAT, SOLID_NPZ_FORMAT, WrongKindError, load_npz,
                          open_npz, reading, write_npz)

from .beam import BeamBladeGeometry, beam_modes, rigid_offset_motion

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
        with its own surface data (the solid FE blade, :class:`bladedamp.blade.solid.SolidModalBlade`)
        overrides this, and the contact kinematics then use those shapes at every contact point
        (:func:`bladedamp.diskmodel.contact_point_maps`)."""
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
        blade's ``.npz`` (format :data:`SOLID_NPZ_FORMAT`, :meth:`bladedamp.blade.solid.SolidModalBlade.save`)
        gives a :class:`bladedamp.blade.solid.SolidModalBlade` with its flexible platforms and surface.
        """
        path = Path(path)
        from bladedamp import fe_formats
        if path.suffix.lower().lstrip(".") in fe_formats.FE_SUFFIXES:
            return _blade_from_fe_file(cls, path, dof_map, points, n_modes, damping_ratios, rigid_links,
                                       fixed_dofs, mass, stiffness, matrix_options)
        given = [k for k, v in dict(dof_map=dof_map, points=points, n_modes=n_modes, damping_ratios=damping_ratios,
                                    rigid_links=rigid_links, mass=mass, stiffness=stiffness).items()
                 if v is not None] + (["fixed_dofs"] if tuple(fixed_dofs) else []) + list(matrix_options)
        if given:
            raise ValueError(f"{path}: {given} apply to FE matrix files only "
                             f"({sorted('.' + s for s in fe_formats.FE_SUFFIXES)}); a modal data file has its modes")
        if _modal_file_kind(path) == "npz":
            blade = load_npz(path, "modal data file", untagged=cls)   # a solid's file: SolidModalBlade.from_npz
            if not isinstance(blade, cls):
                raise WrongKindError(f"{path}: holds a {type(blade).__qualname__}, not a {cls.__qualname__}")
            return blade
        with reading(path, "modal data file"):
            fields = _read_modal_csv(path)
            try:
                return cls(**fields)
            except ValueError as err:
                raise ValueError(f"{path}: {err}") from None

    @classmethod
    def from_npz(cls, path, data) -> "ModalBlade":
        """The blade of the open modal data ``.npz`` file ``data`` (arrays by key, e.g. the
        ``np.load`` of ``path``; ``path`` for the messages): :func:`modal_npz_fields`. The reader of
        :func:`bladedamp.io.load_npz` for this class (use :meth:`from_file` or :func:`bladedamp.load`)."""
        fields, _, _ = modal_npz_fields(path, data, MODAL_NPZ_FORMAT)
        try:
            return cls(**fields)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None

    def save(self, path) -> Path:
        """Write this blade to ``path``: ``.npz`` or ``.csv`` by its suffix (formats: module
        docstring of :mod:`bladedamp.blade`). Every value is written exactly (the CSV holds
        the shortest decimal that reads back to the same float), so ``from_file`` gives the
        same arrays back (a solid FE blade: ``.npz`` only, :meth:`bladedamp.blade.solid.SolidModalBlade.save`).
        Returns the path."""
        path = Path(path)
        kind = _modal_file_kind(path)
        if kind == "npz":
            write_npz(self, path, self.npz_arrays(), compressed=True)
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
        from bladedamp.measurement import load_modes

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
    from bladedamp.fe_formats import read_fe_matrices
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
    """(ModalBlade fields, format tag, other arrays) of a modal data ``.npz`` file ``path``
    (:func:`modal_npz_fields` of the open file); :class:`bladedamp.io.FileReadError` (a
    ValueError) naming the file for one that is missing, empty, truncated, corrupted or not an
    ``.npz`` archive."""
    path = Path(path)
    with reading(path, "modal data file"), open_npz(path) as data:
        return modal_npz_fields(path, data)


def modal_npz_fields(path, data, expected_format: str | None = None) -> tuple[dict, str, dict]:
    """(ModalBlade fields, format tag, other arrays) of the open modal data ``.npz`` file ``data``
    (format: module docstring; ``path`` names it in the messages): the fields as keyword arguments
    of :class:`ModalBlade`; the tag is the file's ``format`` entry (:data:`MODAL_NPZ_FORMAT` when
    it has none, or a solid blade's); the other arrays (key -> array, read without pickle) are
    those beyond :data:`MODAL_NPZ_KEYS` (and the saved object's entry :data:`bladedamp.io.META_KEY`),
    which only the solid format may have. ``expected_format``: the format tag the reader expects (None: any
    blade format of :data:`bladedamp.io.BLADE_FORMATS`). ValueError naming the file and the key
    for a file that breaks the format."""
    keys = set(data.files) - {META_KEY}

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
    if tag not in BLADE_FORMATS or (expected_format is not None
                                    and BLADE_FORMATS[tag] != BLADE_FORMATS[expected_format]):
        expected = MODAL_NPZ_FORMAT if expected_format is None else expected_format
        raise ValueError(f"{path}: key 'format' must be {expected!r} (or {SOLID_NPZ_FORMAT!r}, "
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


