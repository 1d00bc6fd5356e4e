"""Solid (3D finite-element) blade from geometry: the parametric blade or a user's closed surface
mesh (STL), gmsh tetrahedra, quadratic linear elasticity (scikit-fem), clamped-root modes, and a
:class:`~bladedamp.blade.ModalBlade` with the beam blade's named points.

Needs the ``fe`` extra (``pip install 'bladedamp[fe]'``: gmsh and scikit-fem); without it every
entry point raises an ImportError saying so.

The blade
---------
The same blade as the beam model (:class:`~bladedamp.blade.BeamBladeGeometry`, default
:func:`~bladedamp.reference.reference_blade_geometry`) and the 3D view
(:func:`bladedamp.geometry.blade_mesh`), in the blade frame (x circumferential, y axial,
z radial, root at z = 0):

* shank: box of the beam's shank section (thickness_x x chord_y) from z = 0 to the platform
  node z_p = shank_length; airfoil: box of the airfoil section from z_p to the tip
  z = L_total, optionally twisted about z (``twist``, linear from the platform top to the
  tip). The beam's sections are rectangles, so the solid's are too (geometry.py's lens profile
  is for the picture only: it has other section constants).
* platform: geometry.py's platform prism (its (x, z) section, extruded along y over
  ``platform_length``): top at z_p + platform_contact_z_offset, edges at x = -/+ platform_edge,
  and the two underside contact faces, planes through the contact control points OL, OR
  inclined by gamma_L, gamma_R (default the reference 35 deg), with a flat bottom between them.
  The beam model has this platform as a rigid lumped plate (30 x 50 x 4 mm, 40.6 g) on its node;
  the prism here has the faces the damper touches (mass: :attr:`SolidModes.mass`).
* root: clamped over the face z = 0 (the beam's clamp) by default; ``root_height > 0`` adds
  geometry.py's root block below z = 0 and clamps its bottom face instead (root flexibility).

Material: the beam geometry's E, nu, rho (the reference: steel, 210 GPa, 0.3, 7850 kg/m^3,
reference.py); ``platform_youngs_modulus`` can stiffen the platform prism alone (the
rigid-platform limit of the beam model, used by the tests).

FE model
--------
gmsh (OpenCASCADE kernel) builds the volumes, fragments them into one conformal mesh and
meshes it with linear tetrahedra of size ``element_size`` (by default the quarter x, y >= 0,
mirrored twice, so the modes have the blade's symmetries exactly: :func:`mesh_blade` says why
that matters); scikit-fem assembles the stiffness
K and consistent mass M of quadratic tetrahedra (ElementTetP2, 10 nodes, 30 DOF, straight
edges), the root face's DOF are removed (clamped), and scipy's eigsh in shift-invert mode
(sigma = :data:`bladedamp.blade.SHIFT_INVERT_SIGMA`, below every blade frequency, so
K - sigma M is positive definite and factorised once by SuperLU in symmetric mode) gives the
lowest modes; a Rayleigh-Ritz step makes them exactly M-orthonormal (Phi^T M Phi = I).

Modes are named by their tip motion (:func:`classify_tip_motion`): the rigid-body fit of the
tip face's displacement, split into flatwise F (u_x, phi_y), edgewise E (u_y, phi_x), torsion
T (phi_z) and axial A (u_z) shares of its fitted motion; counted per family ("1F", "2F", "1E",
...). A mode whose tip face deforms more than it moves rigidly is named "nP" (plate / local).

A user's blade (STL)
--------------------
:class:`SurfaceBladeGeometry` takes a closed, consistently oriented triangle surface (an STL path
or a trimesh.Trimesh) in the blade frame, with ``scale`` converting its units to metres (1 for
metres, 1e-3 for a millimetre file; a surface larger than :data:`MAX_SURFACE_EXTENT` after
scaling is refused as a units mistake). STL has no face names, so the named regions are given
beside it as selectors, each picking triangles of the surface:

* :class:`PlaneRegion` (point, outward normal, tolerance [m], optional box): the triangles on
  that plane facing that way, e.g. ``PlaneRegion((0, 0, 0), (0, 0, -1))`` for a root at z = 0;
* :class:`SurfacePatch` (an STL path or mesh): the region exported as its own file from the
  same model; the triangles within tolerance of it.

Regions: "clamp" (the root faces, clamped), "OL" and "OR" (the platform's underside contact
faces; each planar with its normal in the x-z plane: the platform angles gamma_left /
gamma_right are read from them, the control points default to the faces' centroids), "tip"
(optional: default the flat top at the largest z). Missing or empty regions, a non-watertight
surface, a face on the wrong side raise ValueError naming the region. :func:`mesh_surface` hands
the triangles to gmsh, which splits them into faces at sharp edges, reparametrises and remeshes
them at ``element_size`` and fills the volume with tetrahedra; the regions are picked again on
the new boundary. The modal pipeline is then the parametric blade's (:func:`solid_modes`,
:func:`solid_blade`, ``ModalBlade.from_solid(SurfaceBladeGeometry(...))``); points other than
OL, OR and the tip are fitted over the elements within one element size of them. Checked
against the parametric path (the reference solid's surface written to STL in mm and read back:
frequencies within the mesh tolerance, the same contact faces and shapes).

Named points (the beam blade's: "OL", "OR", "platform", "tip", "excitation")
-----------------------------------------------------------------------------
Each point's 6-DOF motion (u_x, u_y, u_z [m/sqrt(kg)], phi_x, phi_y, phi_z [rad/sqrt(kg)]) is
the weighted least-squares rigid-body fit u(x) ~ u_P + phi x (x - x_P) of the FE displacement
over a region, with the point P as reference (so u_P is the fitted translation at P):

* OL, OR: over the platform's contact face on that side (area-weighted, exact facet
  quadrature): the shapes every rigid-point use of the blade takes (``blade.shape("OL")``); the
  fit's residual (share of the face motion the rigid fit misses) says how flexible the platform
  is, and the raw FE displacements of the face at a grid of points are kept in
  :attr:`SolidModalBlade.contact_faces`. The contact kinematics of the disks do not use a rigid
  platform: :meth:`SolidModalBlade.platform_displacements` gives the FE field at every contact
  point of the damper's patches (:func:`bladedamp.diskmodel.contact_point_maps`, flexible
  platforms; :meth:`SolidModalBlade.rigid_platform_blade` for the rigid ones).
* platform: over the platform prism's volume.
* tip (and excitation, and any point at the tip height): over the tip face; another height:
  over the blade's cross-section there (Gauss-Legendre grid, interpolated).

For pictures the blade keeps its FE boundary surface compactly (:class:`BladeSurface`: the outer
triangles' corner vertices, and the mode shapes there), which the 3D view draws deformed.

Saved blades
------------
:meth:`SolidModalBlade.save` writes an ``.npz`` (format :data:`SOLID_NPZ_FORMAT`) with all the
disks and the 3D view use: the ModalBlade part, the exact FE field at the two contact faces
(:class:`ContactFaceField`: the quadratic tetrahedra touching each face, 106 per face at 9 mm),
the surface, the contact-face samples, the fit residuals and ``solid_info``; not the whole FE
model (``modes``). Read back (:meth:`~bladedamp.blade.ModalBlade.from_file`) it is a
SolidModalBlade with the same flexible platforms: the tuned disk's FRF is the same to the bit.
The file (compressed) is a few hundred kB for the reference blade, a tenth of the whole model's
mode vectors (benchmarks/README.md, 'Moved from the package's docstrings', solid.py). There is no
CSV form (a CSV blade has rigid platforms): ``save`` refuses ``.csv``.
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from bladedamp import validation as check
from bladedamp.io import SOLID_NPZ_FORMAT, MissingFileError, decode_value, encode_value

from .beam import BeamBladeGeometry, PlatformBlock, RectangularSection, platform_section, warping_constant_rectangle
from .modal import PAPER_MODE_ORDER, SHIFT_INVERT_SIGMA, ModalBlade, modal_npz_fields
from .reference import PLATFORM_ANGLE, reference_blade_geometry

__all__ = ["FE_HINT", "SOLID_NPZ_FORMAT", "SolidBladeGeometry", "SurfaceBladeGeometry", "PlaneRegion", "SurfacePatch",
           "SolidMesh", "SolidModes", "ContactFaceModes", "ContactFaceField", "BladeSurface", "SolidModalBlade",
           "mesh_blade", "mesh_surface", "boundary_faces", "point_triangle_distances", "solid_modes", "solid_blade",
           "rigid_fit", "classify_tip_motion", "cantilever_frequencies_hz", "CANTILEVER_THEORIES",
           "solid_platform_beam", "vlasov_cantilever_frequency_hz", "timoshenko_cantilever_frequency_hz"]

FE_HINT = "the solid blade needs the fe extra: pip install 'bladedamp[fe]'"

# Mode families (same letters as the beam model, bladedamp.blade._FAMILY_DOFS).
FAMILIES = ("F", "E", "T", "A")
# A mode whose tip face deformation (the part its rigid-body fit misses) exceeds this share of
# the face's motion is not a beam-like mode of the blade: named "nP" (plate / local mode).
# Beam-like modes of the reference solid have < 1e-2 (their tip face moves rigidly).
PLATE_MODE_RESIDUAL = 0.5
# Default element size [m]: 6 mm, 28 800 DOF for the reference blade (the mirrored quarter mesh
# has at least one element through the half thickness 2.3 mm). At 6 mm 1F is 0.2 % and 1T 0.5 %
# above the 3 mm values, below what the contact model resolves (convergence and cost:
# benchmarks/README.md, 'Moved from the package's docstrings', solid.py).
DEFAULT_ELEMENT_SIZE = 6e-3
# Samples of the raw contact-face displacement: cell midpoints of an (n_xi, n_eta) grid over the
# face (xi across the face, up the slope for OL; eta = y along the damper axis), like
# bladedamp.contact.patch.ContactPatch.
DEFAULT_FACE_SAMPLES = (5, 21)
# Modes computed before picking: 1F, 2F, 1T, 1E of the reference lie among the lowest 6; a few
# more so a changed geometry still has them (2E, 3F, 2T, 1A, chordwise plate modes follow).
DEFAULT_SEARCH_MODES = 10


def _require_fe():
    """(gmsh, skfem) modules, or ImportError with the install hint."""
    try:
        import gmsh
        import skfem
    except ImportError as err:
        raise ImportError(FE_HINT) from err
    except OSError as err:       # gmsh installed, but its shared library (or one it needs) does not load
        raise ImportError(f"{FE_HINT} (gmsh is installed but does not load: {err})") from err
    return gmsh, skfem


# --------------------------------------------------------------------------------------
# geometry
# --------------------------------------------------------------------------------------


@dataclass(eq=False)
class SolidBladeGeometry:
    """The parametric solid blade: a beam blade's dimensions and material plus what a solid
    needs beyond them (defaults: those of :func:`bladedamp.geometry.blade_mesh`).

    Attributes (SI units)
    ----------
    beam : BeamBladeGeometry (default the reference blade): sections, lengths, OL/OR, E, nu, rho.
        Its platform_mass / platform_rotary_inertia (the beam's lumped plate) are not used: the
        solid has the platform prism itself. Its element counts are not used either.
    gamma_left, gamma_right : platform angles of the OL and OR contact faces [rad], in
        (0, pi/2); default the reference 35 deg (bladedamp.blade.PLATFORM_ANGLE).
    platform_edge : |x| of the platform edges [m] (None: 1.25 x platform_half_width, 15 mm).
    platform_length : axial (y) length of the platform [m] (None: 1.1 x the larger chord, 50 mm).
    face_inner_length : how far each underside continues past its contact point toward the
        blade axis [m] (geometry.py's 2.5 mm).
    min_edge_thickness : thinnest platform edge above an underside [m] (geometry.py's 0.3 mm).
    root_height : 0 (default): clamp the face z = 0, as the beam does; > 0: add geometry.py's
        root block of this height below z = 0 (a trapezoid in (x, z), 1.6 shank thicknesses wide
        at z = 0 and 2.56 at the bottom, over the shank chord: :meth:`root_section`) and clamp its
        bottom face [m].
    twist : airfoil twist about z, linear from :attr:`twist_start` (the platform top) to the tip
        [rad], in [-pi/2, pi/2] (0: prismatic, as the beam). A twisted blade is meshed whole
        (no mirror symmetry).
    platform : False leaves the platform out (a plain cantilever plate: the closed-form check;
        such a model has no OL/OR faces and gives no ModalBlade).
    platform_youngs_modulus : E of the platform prism [Pa] (None: the beam's E). A large value
        is the rigid-platform limit.
    """

    beam: BeamBladeGeometry | None = None
    gamma_left: float | None = None
    gamma_right: float | None = None
    platform_edge: float | None = None
    platform_length: float | None = None
    face_inner_length: float = 2.5e-3
    min_edge_thickness: float = 0.3e-3
    root_height: float = 0.0
    twist: float = 0.0
    platform: bool = True
    platform_youngs_modulus: float | None = None

    def __post_init__(self):
        if self.beam is None:
            self.beam = reference_blade_geometry()
        if not isinstance(self.beam, BeamBladeGeometry):
            raise ValueError(f"beam must be a BeamBladeGeometry (got {type(self.beam).__name__})")
        for name in ("gamma_left", "gamma_right"):
            value = PLATFORM_ANGLE if getattr(self, name) is None else getattr(self, name)
            setattr(self, name, check.in_range(name, value, 0.0, np.pi / 2, closed="neither"))
        g = self.beam
        if self.platform_edge is None:
            self.platform_edge = 1.25 * g.platform_half_width
        if self.platform_length is None:
            self.platform_length = 1.1 * max(g.airfoil_chord_y, g.shank_chord_y)
        for name in ("platform_edge", "platform_length", "face_inner_length", "min_edge_thickness"):
            setattr(self, name, check.positive(name, getattr(self, name)))
        if self.platform_edge <= g.platform_half_width:
            raise ValueError(f"platform_edge must exceed platform_half_width = {g.platform_half_width:g} m "
                             f"(got {self.platform_edge:g} m)")
        if self.platform_length < max(g.airfoil_chord_y, g.shank_chord_y):
            raise ValueError("platform_length must be at least the blade's chord "
                             f"{max(g.airfoil_chord_y, g.shank_chord_y):g} m (got {self.platform_length:g} m)")
        self.root_height = check.nonnegative("root_height", self.root_height)
        self.twist = check.in_range("twist", self.twist, -np.pi / 2, np.pi / 2)
        if self.platform_youngs_modulus is not None:
            self.platform_youngs_modulus = check.positive("platform_youngs_modulus",
                                                          self.platform_youngs_modulus)
        self.platform = bool(self.platform)

    @property
    def total_length(self) -> float:
        """z of the tip [m]."""
        return self.beam.total_length

    # the interface solid_modes / solid_blade use (shared with SurfaceBladeGeometry): the material
    youngs_modulus = property(lambda self: self.beam.youngs_modulus, doc="E [Pa] (the beam geometry's).")
    poisson_ratio = property(lambda self: self.beam.poisson_ratio, doc="nu [-] (the beam geometry's).")
    density = property(lambda self: self.beam.density, doc="rho [kg/m^3] (the beam geometry's).")

    def points(self) -> dict:
        """Named points [m]: the beam geometry's ("OL", "OR", "platform", "tip", "excitation")."""
        return self.beam.points()

    def fit_region(self, name: str, position) -> tuple:
        """Where the rigid-body fit of point ``name`` at ``position`` (3,) [m] is taken: ("face",
        "OL" / "OR" / "tip"), ("platform",) the platform prism's volume, or ("section", z) the
        cross-section at the point's height (module docstring)."""
        if name in ("OL", "OR"):
            return ("face", name)
        if name == "platform" and self.platform:
            return ("platform",)
        if abs(position[2] - self.total_length) <= 1e-9 * self.total_length:
            return ("face", "tip")
        return ("section", float(position[2]))

    @property
    def platform_top(self) -> float:
        """z of the platform's top face [m] (geometry.py: z_p + max(contact offset, 1 mm))."""
        g = self.beam
        return g.shank_length + max(g.platform_contact_z_offset, 1e-3)

    @property
    def twist_start(self) -> float:
        """z where the airfoil's twist starts [m]: the platform top (the shank top without platform)."""
        return self.platform_top if self.platform else self.beam.shank_length

    @property
    def clamp_z(self) -> float:
        """z of the clamped face [m]: 0, or -root_height with a root block."""
        return -self.root_height

    def platform_polygon(self) -> np.ndarray:
        """(6, 2) (x, z) section of the platform prism [m] (:func:`platform_section`)."""
        pts = self.beam.points()
        return platform_section(np.array([pts["OL"], pts["OR"]]), self.gamma_left, self.gamma_right,
                                self.platform_edge, self.platform_top, self.face_inner_length,
                                self.min_edge_thickness)

    def root_section(self) -> np.ndarray:
        """(4, 2) (x, z) section of geometry.py's root block [m] (extruded over the shank chord)."""
        tx = self.beam.shank_thickness_x
        sec = np.array([[-0.8 * tx, -self.root_height], [0.8 * tx, -self.root_height],
                        [0.5 * tx, 0.0], [-0.5 * tx, 0.0]])
        sec[:, 0] *= 1.6
        return sec

    def contact_face(self, side: str):
        """The underside face on ``side`` ("OL" or "OR"): (centre (3,) = the control point,
        frame (3, 3) rows (xi, eta, zeta) as bladedamp.damper.geometry.contact_frame (zeta the
        face's outward normal, from the platform into the damper), xi_range (2,) and
        eta_range (2,) of the face rectangle in that frame, relative to the centre [m])."""
        from bladedamp.damper.geometry import contact_frame, contact_normal
        if side not in ("OL", "OR"):
            raise ValueError(f"side must be 'OL' or 'OR' (got {side!r})")
        poly = self.platform_polygon()
        inner, outer = (poly[0], poly[5]) if side == "OL" else (poly[1], poly[2])
        centre = self.beam.points()[side]
        frame = contact_frame(contact_normal(side, self.gamma_left if side == "OL" else self.gamma_right))
        ends = [np.array([p[0], 0.0, p[1]]) - centre for p in (inner, outer)]
        xi = sorted(float(e @ frame[0]) for e in ends)
        half = 0.5 * self.platform_length
        return centre, frame, np.array(xi), np.array([-half, half])


# --------------------------------------------------------------------------------------
# mesh (gmsh)
# --------------------------------------------------------------------------------------
@dataclass(eq=False)
class SolidMesh:
    """Linear tetrahedral mesh of the solid blade (the P2 nodes are added by scikit-fem).

    vertices : (3, n_v) [m]; tets : (4, n_e) vertex indices; platform : (n_e,) bool, True for
    the platform prism's elements; faces : name -> (3, n_f) vertex indices of the boundary
    triangles of "clamp", "tip", "OL", "OR" (the contact faces; absent without platform);
    element_size [m]; seconds : meshing wall time [s].
    """

    vertices: np.ndarray
    tets: np.ndarray
    platform: np.ndarray
    faces: dict
    element_size: float
    seconds: float = 0.0


def _polygon_surface(occ, section_xz, y0: float):
    """Plane surface of an (x, z) polygon at y = y0 (OCC tag)."""
    pts = [occ.addPoint(x, y0, z) for x, z in section_xz]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    return occ.addPlaneSurface([occ.addCurveLoop(lines)])


def _extrude_y(occ, section_xz, y0: float, length: float) -> int:
    """Volume of an (x, z) polygon extruded along +y from y0 by length (OCC tag)."""
    surface = _polygon_surface(occ, section_xz, y0)
    out = occ.extrude([(2, surface)], 0.0, length, 0.0)
    return next(tag for dim, tag in out if dim == 3)


def mesh_blade(geometry: SolidBladeGeometry | BeamBladeGeometry | None = None,
               element_size: float = DEFAULT_ELEMENT_SIZE, *, symmetric: bool = True, algorithm: int = 1,
               optimize: bool = True) -> SolidMesh:
    """Tetrahedral mesh of the solid blade by gmsh (OpenCASCADE), element size ``element_size`` [m].

    ``symmetric`` (default): mesh only the part x >= 0, y >= 0 the geometry's mirror symmetries
    allow (y -> -y: every untwisted blade; x -> -x: also gamma_L = gamma_R) and mirror it, so the
    mesh, and so the modes, are exactly symmetric. An unsymmetric tetrahedral mesh gives the
    modes components the symmetry forbids (about 1e-5 of the mode's largest, e.g. phi_z at OL in
    1F), and the tuned disk's continuation with a static harmonic crawls on them (with (0, 1):
    several times the points of the symmetric mesh's).
    ``algorithm`` is gmsh's Mesh.Algorithm3D (1 Delaunay); ``optimize`` runs gmsh's
    tetrahedron quality optimisation. gmsh runs on one thread, so the same arguments give the
    same mesh.
    """
    gmsh, _ = _require_fe()
    sg = _solid_geometry(geometry)
    h = check.positive("element_size", element_size)
    g = sg.beam
    mirror_y = bool(symmetric) and sg.twist == 0.0
    mirror_x = mirror_y and (not sg.platform or sg.gamma_left == sg.gamma_right)
    start = time.perf_counter()
    with _gmsh_model(gmsh, "bladedamp_solid_blade"):
        occ = gmsh.model.occ
        z_p, L = g.shank_length, g.total_length
        volumes = [occ.addBox(-g.shank_thickness_x / 2, -g.shank_chord_y / 2, 0.0,
                              g.shank_thickness_x, g.shank_chord_y, z_p)]
        tx, cy = g.airfoil_thickness_x, g.airfoil_chord_y
        if sg.twist == 0.0:
            volumes.append(occ.addBox(-tx / 2, -cy / 2, z_p, tx, cy, L - z_p))
        else:   # straight up to the twist start, twisted above it
            z0 = sg.twist_start
            if z0 > z_p:
                volumes.append(occ.addBox(-tx / 2, -cy / 2, z_p, tx, cy, z0 - z_p))
            # a smooth loft through 9 rotated rectangles (gmsh's OCC kernel has no twisted
            # extrusion); at 30 deg the reference solid's volume differs from the untwisted one's
            # (which twisting keeps) by 0.04 %
            loops = []
            for z, angle in zip(np.linspace(z0, L, 9), np.linspace(0.0, sg.twist, 9)):
                c, s = np.cos(angle), np.sin(angle)
                corners = [(c * x - s * y, s * x + c * y) for x, y in
                           ((-tx / 2, -cy / 2), (tx / 2, -cy / 2), (tx / 2, cy / 2), (-tx / 2, cy / 2))]
                pts = [occ.addPoint(x, y, z) for x, y in corners]
                loops.append(occ.addWire([occ.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]))
            out = occ.addThruSections(loops, makeSolid=True, makeRuled=False)
            volumes.append(next(tag for dim, tag in out if dim == 3))
        platform_inputs = []
        if sg.platform:
            platform_inputs = [_extrude_y(occ, sg.platform_polygon(), -sg.platform_length / 2,
                                          sg.platform_length)]
            volumes += platform_inputs
        if sg.root_height > 0:
            volumes.append(_extrude_y(occ, sg.root_section(), -g.shank_chord_y / 2, g.shank_chord_y))
        n_solid = len(volumes)
        if mirror_y:   # keep x >= 0 (with mirror_x), y >= 0
            big = 10.0 * (L + sg.root_height + sg.platform_length + sg.platform_edge)
            x0 = 0.0 if mirror_x else -big
            volumes.append(occ.addBox(x0, 0.0, -big, big - x0, big, 2 * big))
        _, children = occ.fragment([(3, v) for v in volumes[:1]], [(3, v) for v in volumes[1:]])
        occ.synchronize()
        solid_pieces = set().union(*({tag for dim, tag in kids if dim == 3} for kids in children[:n_solid]))
        platform_volumes = set()
        for parent, kids in zip(volumes, children):
            if parent in platform_inputs:
                platform_volumes |= {tag for dim, tag in kids if dim == 3}
        if mirror_y:
            drop = []
            for _, tag in gmsh.model.getEntities(3):
                com = occ.getCenterOfMass(3, tag)
                if tag not in solid_pieces or com[1] < 0 or (mirror_x and com[0] < 0):
                    drop.append((3, tag))
            occ.remove(drop, recursive=True)
            occ.synchronize()

        # boundary surfaces by their geometry (plane tests on their corner points)
        def corners(tag):
            pts = gmsh.model.getBoundary([(2, tag)], combined=False, oriented=False, recursive=True)
            return np.array([gmsh.model.getValue(0, p, []) for _, p in pts])

        tol = 1e-6 * L
        planes = {"clamp": (np.array([0.0, 0.0, sg.clamp_z]), np.array([0.0, 0.0, 1.0])),
                  "tip": (np.array([0.0, 0.0, L]), np.array([0.0, 0.0, 1.0]))}
        if sg.platform:
            for side in (("OR",) if mirror_x else ("OL", "OR")):
                centre, frame, _, _ = sg.contact_face(side)
                planes[side] = (centre, frame[2])
        surface_groups = {name: [] for name in planes}
        for _, tag in gmsh.model.getEntities(2):
            c = corners(tag)
            for name, (origin, normal) in planes.items():
                if np.all(np.abs((c - origin) @ normal) < tol):
                    if name in ("OL", "OR"):   # only the underside rectangle, not a coplanar edge
                        _, frame, xi_r, _ = sg.contact_face(name)
                        xi = (c - origin) @ frame[0]
                        if xi.min() < xi_r[0] - tol or xi.max() > xi_r[1] + tol:
                            continue
                    surface_groups[name].append(tag)
        empty = [n for n, tags in surface_groups.items() if not tags]
        if empty:
            raise RuntimeError(f"gmsh geometry: no surface found for {empty} (geometry {sg})")

        _gmsh_generate(gmsh, h, algorithm, optimize)
        vertices, tets, is_platform, index = _gmsh_tetrahedra(gmsh, platform_volumes)
        faces = {name: _gmsh_triangles(gmsh, tags, index) for name, tags in surface_groups.items()}
    platform = is_platform
    if mirror_x:
        vertices, tets, platform, faces = _mirrored(vertices, tets, platform, faces, 0, tol, {"OR": "OL"})
    if mirror_y:
        vertices, tets, platform, faces = _mirrored(vertices, tets, platform, faces, 1, tol, {})
    return SolidMesh(vertices=vertices, tets=tets, platform=platform, faces=faces, element_size=h,
                     seconds=time.perf_counter() - start)


@contextlib.contextmanager
def _gmsh_model(gmsh, name: str):
    """A fresh gmsh model ``name`` (quiet, one thread, so the same input gives the same mesh),
    removed on exit; gmsh is initialised for it and finalised after it unless it already ran."""
    was_initialised = gmsh.isInitialized()
    if not was_initialised:
        gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add(name)
        try:
            yield
        finally:
            gmsh.model.remove()
    finally:
        if not was_initialised:
            gmsh.finalize()


def _gmsh_generate(gmsh, element_size: float, algorithm: int, optimize: bool):
    """Mesh the current model with tetrahedra of largest size ``element_size`` [m] (gmsh's
    Mesh.Algorithm3D ``algorithm``, quality optimisation if ``optimize``)."""
    gmsh.option.setNumber("Mesh.MeshSizeMax", element_size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm3D", int(algorithm))
    gmsh.option.setNumber("Mesh.Optimize", 1 if optimize else 0)
    gmsh.model.mesh.generate(3)


def _gmsh_tetrahedra(gmsh, platform_volumes=frozenset()):
    """The current gmsh model's volume mesh: vertices (3, n_v) [m] (the nodes the tetrahedra
    use), tets (4, n_e) vertex indices, platform (n_e,) bool (elements of ``platform_volumes``
    tags), and index (max node tag + 1,) node tag -> vertex index (-1: unused)."""
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    tets, is_platform = [], []
    for _, vtag in gmsh.model.getEntities(3):
        types, _, nodes = gmsh.model.mesh.getElements(3, vtag)
        for etype, enodes in zip(types, nodes):
            if etype != 4:   # 4-node tetrahedron
                raise RuntimeError(f"gmsh produced volume elements of type {etype}, expected tetrahedra (4)")
            tets.append(enodes.reshape(-1, 4).astype(np.int64))
            is_platform.append(np.full(len(tets[-1]), vtag in platform_volumes))
    if not tets:
        raise RuntimeError("gmsh produced no tetrahedra")
    tets = np.vstack(tets)
    used = np.unique(tets)
    index[used] = np.arange(used.size)
    position = np.full(index.size, -1, dtype=np.int64)
    position[node_tags.astype(np.int64)] = np.arange(node_tags.size)
    vertices = coords.reshape(-1, 3)[position[used]].T.copy()
    return vertices, index[tets].T.copy(), np.concatenate(is_platform), index


def _gmsh_triangles(gmsh, surface_tags, index) -> np.ndarray:
    """(3, n_f) vertex indices (``index`` of :func:`_gmsh_tetrahedra`) of the 3-node triangles
    of the gmsh surfaces ``surface_tags``."""
    tri = [np.zeros((0, 3), dtype=np.int64)]
    for tag in surface_tags:
        types, _, nodes = gmsh.model.mesh.getElements(2, tag)
        for etype, enodes in zip(types, nodes):
            if etype == 2:   # 3-node triangle
                tri.append(index[enodes.reshape(-1, 3).astype(np.int64)])
    return np.vstack(tri).T


def _mirrored(vertices, tets, platform, faces, axis: int, tol: float, renamed: dict):
    """A mesh of coordinate ``axis`` >= 0 and its mirror image, joined on the plane axis = 0
    (its vertices shared, set exactly to 0). ``faces`` of the mirrored half: the same names, or
    ``renamed[name]`` (a face whose mirror is another named face: OR -> OL)."""
    on_plane = np.abs(vertices[axis]) <= tol
    v = vertices.copy()
    v[axis, on_plane] = 0.0
    image = np.where(on_plane, np.arange(v.shape[1]), v.shape[1] + np.cumsum(~on_plane) - 1)
    new = v[:, ~on_plane].copy()
    new[axis] *= -1.0
    vertices = np.hstack([v, new])
    mirrored_tets = image[tets][[1, 0, 2, 3]]          # a mirror flips the orientation: swap two
    out_faces = {}
    for name, tri in faces.items():
        out_faces.setdefault(name, []).append(tri)
        out_faces.setdefault(renamed.get(name, name), []).append(image[tri][[1, 0, 2]])
    return (vertices, np.hstack([tets, mirrored_tets]), np.concatenate([platform, platform]),
            {name: np.hstack(tris) for name, tris in out_faces.items()})


def _solid_geometry(geometry):
    """SolidBladeGeometry or SurfaceBladeGeometry from the accepted forms."""
    if geometry is None:
        return SolidBladeGeometry()
    if isinstance(geometry, (SolidBladeGeometry, SurfaceBladeGeometry)):
        return geometry
    if isinstance(geometry, BeamBladeGeometry):
        return SolidBladeGeometry(beam=geometry)
    raise ValueError(f"geometry must be None, a SolidBladeGeometry, a SurfaceBladeGeometry or a BeamBladeGeometry "
                     f"(got {type(geometry).__name__})")


# --------------------------------------------------------------------------------------
# a user's geometry: a closed surface mesh (STL) with named regions
# --------------------------------------------------------------------------------------
# Largest extent [m] a blade surface may have: a surface larger than this is taken to be in the
# wrong units (a millimetre STL read as metres spans 200 m for the reference blade).
MAX_SURFACE_EXTENT = 2.0
# Outward normals of a region's triangles may deviate from the selector's normal by this [rad].
REGION_ANGLE_TOLERANCE = np.radians(1.0)
# gmsh's feature angle [rad] splitting the STL into faces before it remeshes them: below the
# reference platform's 35 deg between a contact face and the flat bottom, so that edge stays sharp.
DEFAULT_FEATURE_ANGLE = np.radians(20.0)


@dataclass(frozen=True)
class PlaneRegion:
    """A named region of a surface mesh selected by a plane: the triangles whose three vertices lie
    within ``tolerance`` [m] of the plane through ``point`` (3,) [m] normal to ``normal`` (3,),
    whose outward normal points along ``normal`` (within :data:`REGION_ANGLE_TOLERANCE`), and, if
    ``bounds`` ((2, 3) lower and upper corner [m]) is given, whose vertices lie in that box.

    The plane is in the blade frame after ``scale`` (metres). Example: the root face of a blade
    with its root at z = 0 is ``PlaneRegion((0, 0, 0), (0, 0, -1))`` (outward = -z).
    """

    point: tuple
    normal: tuple
    tolerance: float = 1e-5
    bounds: tuple | None = None

    def select(self, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """(n_f,) bool: the triangles ``faces`` (n_f, 3) of ``vertices`` (n_v, 3) [m] in the region."""
        p = np.asarray(self.point, dtype=float)
        n = np.asarray(self.normal, dtype=float)
        if p.shape != (3,) or n.shape != (3,) or not np.linalg.norm(n) > 0:
            raise ValueError(f"PlaneRegion: point and normal must be 3-vectors, normal nonzero (got {self.point!r}, "
                             f"{self.normal!r})")
        n = n / np.linalg.norm(n)
        tol = check.positive("tolerance", self.tolerance)
        tri = vertices[faces]                                           # (n_f, 3, 3)
        on_plane = np.all(np.abs((tri - p) @ n) <= tol, axis=1)
        facing = _triangle_normals(vertices, faces) @ n >= np.cos(REGION_ANGLE_TOLERANCE)
        mask = on_plane & facing
        if self.bounds is not None:
            lo, hi = np.asarray(self.bounds, dtype=float)
            mask &= np.all((tri >= lo - tol) & (tri <= hi + tol), axis=(1, 2))
        return mask


@dataclass(frozen=True)
class SurfacePatch:
    """A named region of a surface mesh given as its own surface: ``surface`` (an STL path or a
    trimesh.Trimesh, in the same units as the blade's STL: the blade's ``scale`` applies to it) is
    the region exported separately from the same CAD model; a triangle of the blade surface is in
    the region when its three vertices lie within ``tolerance`` [m] of the patch's triangles."""

    surface: object
    tolerance: float = 1e-5

    def select(self, vertices: np.ndarray, faces: np.ndarray, patch_vertices: np.ndarray,
               patch_faces: np.ndarray) -> np.ndarray:
        """(n_f,) bool: the triangles ``faces`` (n_f, 3) of ``vertices`` (n_v, 3) [m] on the patch
        (``patch_vertices`` (m_v, 3) [m], ``patch_faces`` (m_f, 3), already scaled)."""
        tol = check.positive("tolerance", self.tolerance)
        used = np.unique(faces)
        near = np.zeros(vertices.shape[0], dtype=bool)
        near[used] = point_triangle_distances(vertices[used], patch_vertices[patch_faces]) <= tol
        return np.all(near[faces], axis=1)


def point_triangle_distances(points: np.ndarray, triangles: np.ndarray, chunk: int = 256) -> np.ndarray:
    """(P,) distance [m] of each point (P, 3) to the nearest of ``triangles`` (T, 3, 3) [m]: the
    projection on the triangle's plane if it falls inside the triangle, else the nearest edge."""
    points = np.asarray(points, dtype=float)
    tri = np.asarray(triangles, dtype=float)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n2 = np.einsum("ij,ij->i", n, n)
    keep = n2 > 0                                   # degenerate triangles: their edges still count
    out = np.empty(points.shape[0])

    def segment(p, s0, s1):                         # (p, T) distance to the segments s0 s1 (T, 3)
        d = s1 - s0
        t = np.clip(np.einsum("ptk,tk->pt", p[:, None, :] - s0[None], d) / np.maximum(np.einsum("tk,tk->t", d, d),
                                                                                          1e-300), 0.0, 1.0)
        return np.linalg.norm(p[:, None, :] - (s0[None] + t[..., None] * d[None]), axis=2)

    for start in range(0, points.shape[0], chunk):
        p = points[start:start + chunk]
        best = np.minimum(np.minimum(segment(p, a, b), segment(p, b, c)), segment(p, c, a))
        if keep.any():
            nk, ak, bk, ck = n[keep], a[keep], b[keep], c[keep]
            rel = p[:, None, :] - ak[None]
            height = np.einsum("ptk,tk->pt", rel, nk) / n2[keep]
            q = p[:, None, :] - height[..., None] * nk[None]       # projection on the plane
            inside = np.ones(height.shape, dtype=bool)
            for s0, s1 in ((ak, bk), (bk, ck), (ck, ak)):
                inside &= np.einsum("ptk,tk->pt", np.cross(s1 - s0, q - s0[None]), nk) >= 0
            plane = np.where(inside, np.abs(height) * np.sqrt(n2[keep]), np.inf)
            best[:, keep] = np.minimum(best[:, keep], plane)
        out[start:start + chunk] = best.min(axis=1)
    return out


def _triangle_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(n_f, 3) unit normals of triangles (n_f, 3) (right-hand rule; zero for a degenerate one)."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def boundary_faces(tets: np.ndarray, vertices: np.ndarray | None = None) -> np.ndarray:
    """(3, n_b) vertex indices of the boundary triangles of a tetrahedral mesh (the faces that
    belong to one tetrahedron only) of ``tets`` (4, n_e); with ``vertices`` (3, n_v) [m] oriented
    outward (right-hand normal away from the tetrahedron's fourth vertex)."""
    t = np.asarray(tets, dtype=np.int64)
    local = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
    opposite = np.array([0, 1, 2, 3])
    tri = np.concatenate([t[local[k]] for k in range(4)], axis=1)              # (3, 4 n_e)
    opp = np.concatenate([t[opposite[k]] for k in range(4)])
    key = np.sort(tri, axis=0)
    _, first, counts = np.unique(key.T, axis=0, return_index=True, return_counts=True)
    single = first[counts == 1]
    tri, opp = tri[:, single], opp[single]
    if vertices is not None:
        v = np.asarray(vertices, dtype=float)
        n = np.cross(v[:, tri[1]] - v[:, tri[0]], v[:, tri[2]] - v[:, tri[0]], axis=0)
        inward = np.einsum("ki,ki->i", n, v[:, opp] - v[:, tri[0]]) > 0
        tri[:, inward] = tri[[1, 0, 2]][:, inward]
    return tri


@dataclass(eq=False)
class SurfaceBladeGeometry:
    """A user's blade: a closed surface mesh (STL, or any mesh trimesh reads) with named regions.

    STL has no face names, so the regions are given beside the file, each as a selector
    (:class:`PlaneRegion`: a plane with a tolerance, optionally a box; :class:`SurfacePatch`: the
    region as its own STL file exported from the same model):

    * ``"clamp"`` (required): the root faces clamped in the disk;
    * ``"OL"``, ``"OR"`` (required): the platform's underside contact faces the damper touches
      (OL on the -x side of the blade, OR on +x). Each must be planar, contain the damper axis
      direction y (its outward normal in the x-z plane: the contact model's platform angle gamma,
      :func:`bladedamp.damper.geometry.contact_normal`, is read from it: gamma_left from OL,
      gamma_right from OR, each in (0, 90) deg) and be a rectangle in its (xi, eta) frame as far as
      the damper's contact patch reaches (the patch must lie on the face);
    * ``"tip"`` (optional): the tip face (the mode names and the tip point's fit); default the
      triangles at the surface's largest z facing +z (a flat tip).

    The surface must be in the blade frame (x circumferential, y axial along the damper, z radial
    outward), closed and consistently oriented (watertight: ValueError otherwise). Units: the
    coordinates times ``scale`` are metres: 1 (default) for a file in metres, ``scale=1e-3`` for
    a file in millimetres (a surface spanning more than :data:`MAX_SURFACE_EXTENT` after scaling
    is refused as a units mistake). Selectors, ``points_given`` and tolerances are in metres.

    Attributes
    ----------
    surface : path of the STL (or trimesh.Trimesh) of the blade's closed surface.
    regions : name -> PlaneRegion or SurfacePatch ("clamp", "OL", "OR", optionally "tip").
    scale : file units -> metres factor [m per unit] (> 0).
    youngs_modulus [Pa], poisson_ratio [-], density [kg/m^3] : the material (default the
        reference steel, bladedamp.reference).
    points_given : optional positions [m] of "OL", "OR" (each on its face: the contact control point;
        default the face's area centroid), "tip" (default the tip face's centroid) and
        "excitation" (default the tip point); other names add points, fitted over the elements
        around them (:meth:`fit_region`).
    feature_angle : gmsh's angle [rad] between facets above which the surface is split into
        faces before it is remeshed (:data:`DEFAULT_FEATURE_ANGLE`); keep it below the sharpest
        edge of a named region.

    After construction: vertices (n_v, 3) [m] and faces (n_f, 3) of the scaled, outward
    surface, region_faces name -> (k,) indices of the faces in each region.
    """

    surface: object
    regions: dict
    scale: float = 1.0
    youngs_modulus: float | None = None
    poisson_ratio: float | None = None
    density: float | None = None
    points_given: dict | None = None
    feature_angle: float = DEFAULT_FEATURE_ANGLE

    #: the solid is all one material (no platform prism of its own), the platform is present
    platform = True
    platform_youngs_modulus = None
    twist = 0.0

    def __post_init__(self):
        try:
            import trimesh
        except ImportError as err:
            raise ImportError(f"{FE_HINT} (a surface blade reads its mesh with trimesh)") from err
        self.scale = check.positive("scale", self.scale)
        self.feature_angle = check.in_range("feature_angle", self.feature_angle, 0.0, np.pi / 2, closed="neither")
        ref = reference_blade_geometry()
        for name in ("youngs_modulus", "density"):
            setattr(self, name, check.positive(name, getattr(ref, name) if getattr(self, name) is None
                                               else getattr(self, name)))
        nu = ref.poisson_ratio if self.poisson_ratio is None else self.poisson_ratio
        self.poisson_ratio = check.in_range("poisson_ratio", nu, 0.0, 0.5, closed="left")
        mesh = _load_surface("surface", self.surface)
        if not (mesh.is_watertight and mesh.is_winding_consistent):
            raise ValueError(f"surface must be a closed (watertight), consistently oriented triangle mesh: "
                             f"{len(mesh.faces)} faces, watertight {mesh.is_watertight}, winding consistent "
                             f"{mesh.is_winding_consistent} (repair it, e.g. trimesh.repair.fill_holes)")
        vertices = np.asarray(mesh.vertices, dtype=float) * self.scale
        faces = np.asarray(mesh.faces, dtype=np.int64)
        if trimesh.Trimesh(vertices, faces, process=False).volume < 0:
            faces = faces[:, ::-1].copy()                    # outward normals
        extent = float(np.ptp(vertices, axis=0).max())
        if extent > MAX_SURFACE_EXTENT:
            raise ValueError(f"scale: the surface spans {extent:.4g} m after scale = {self.scale:g}, more than "
                             f"{MAX_SURFACE_EXTENT:g} m; coordinates times scale must be metres (a file in mm "
                             "needs scale=1e-3)")
        self.vertices, self.faces = vertices, faces
        if not isinstance(self.regions, dict):
            raise ValueError(f"regions must be a dict name -> PlaneRegion or SurfacePatch (got "
                             f"{type(self.regions).__name__})")
        unknown = set(self.regions) - {"clamp", "OL", "OR", "tip"}
        if unknown:
            raise ValueError(f"regions: unknown names {sorted(unknown)} (allowed: 'clamp', 'OL', 'OR', 'tip')")
        regions = dict(self.regions)
        if "tip" not in regions:
            regions["tip"] = PlaneRegion((0.0, 0.0, float(vertices[:, 2].max())), (0.0, 0.0, 1.0),
                                         tolerance=1e-6 * extent)
        self._selectors = regions
        self.region_faces = {}
        for name in ("clamp", "tip", "OL", "OR"):
            if name not in regions:
                raise ValueError(f"regions: the {name!r} region is missing (required: 'clamp', 'OL', 'OR')")
            picked = np.flatnonzero(self.select(name, vertices, faces))
            if picked.size == 0:
                hint = (" (the default tip region is the flat top face at the largest z: give a 'tip' region)"
                        if name == "tip" and "tip" not in self.regions else "")
                raise ValueError(f"regions[{name!r}] selects no triangle of the surface{hint}: check its plane, "
                                 "normal (outward), tolerance and the surface's units (scale)")
            self.region_faces[name] = picked
        given = {} if self.points_given is None else dict(self.points_given)
        self._points = {}
        self._faces = {side: self._contact_face_geometry(side, given.get(side)) for side in ("OL", "OR")}
        tri = vertices[faces[self.region_faces["tip"]]]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        tip = (area @ tri.mean(axis=1)) / area.sum()
        self._points.update(OL=self._faces["OL"][0], OR=self._faces["OR"][0], tip=tip, excitation=tip)
        for name, value in given.items():
            if name in ("OL", "OR"):
                continue
            pos = np.asarray(value, dtype=float)
            if pos.shape != (3,) or not np.all(np.isfinite(pos)):
                raise ValueError(f"points_given[{name!r}] must be a finite 3-vector [m] (got {value!r})")
            self._points[name] = pos
        if "excitation" not in given:
            self._points["excitation"] = self._points["tip"].copy()

    def select(self, name: str, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """(n_f,) bool: the triangles ``faces`` (n_f, 3) of ``vertices`` (n_v, 3) [m] in region ``name``."""
        selector = self._selectors[name]
        if isinstance(selector, PlaneRegion):
            return selector.select(vertices, faces)
        if isinstance(selector, SurfacePatch):
            patch = _load_surface(f"regions[{name!r}]", selector.surface)
            return selector.select(vertices, faces, np.asarray(patch.vertices, dtype=float) * self.scale,
                                   np.asarray(patch.faces, dtype=np.int64))
        raise ValueError(f"regions[{name!r}] must be a PlaneRegion or a SurfacePatch (got {type(selector).__name__})")

    def _contact_face_geometry(self, side: str, given):
        """(centre, frame, xi_range, eta_range, gamma) of a contact face from its triangles."""
        from bladedamp.damper.geometry import contact_frame, contact_normal
        tri = self.vertices[self.faces[self.region_faces[side]]]
        normals = _triangle_normals(self.vertices, self.faces[self.region_faces[side]])
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        n = area @ normals
        n /= np.linalg.norm(n)
        if abs(n[1]) > np.sin(REGION_ANGLE_TOLERANCE):
            raise ValueError(f"regions[{side!r}]: the contact face's outward normal {np.round(n, 4)} has a y "
                             "component; it must lie in the x-z plane (the damper axis is y)")
        gamma = float(np.arctan2(-n[0] if side == "OL" else n[0], -n[2]))
        if not 0.0 < gamma < np.pi / 2:
            raise ValueError(f"regions[{side!r}]: the contact face's platform angle is {np.degrees(gamma):.4g} deg, "
                             f"outside (0, 90) deg (its outward normal {np.round(n, 4)} must point down and "
                             f"{'-x' if side == 'OL' else '+x'}: is the face on the right side of the blade?)")
        frame = contact_frame(contact_normal(side, gamma))
        centre = (area @ tri.mean(axis=1)) / area.sum() if given is None else np.asarray(given, dtype=float)
        if centre.shape != (3,):
            raise ValueError(f"points_given[{side!r}] must be a 3-vector [m] (got {given!r})")
        local = (tri.reshape(-1, 3) - centre) @ frame.T
        size = np.ptp(local[:, :2], axis=0).max()
        if np.abs(local[:, 2]).max() > 1e-3 * size:
            raise ValueError(f"regions[{side!r}]: the contact face is not planar (or points_given[{side!r}] is off it: "
                             f"{np.abs(local[:, 2]).max():.3g} m from its plane)")
        xi_r, eta_r = np.array([local[:, 0].min(), local[:, 0].max()]), np.array([local[:, 1].min(), local[:, 1].max()])
        if not (xi_r[0] <= 0 <= xi_r[1] and eta_r[0] <= 0 <= eta_r[1]):
            raise ValueError(f"points_given[{side!r}] must lie on the {side} contact face")
        return centre, frame, xi_r, eta_r, gamma

    @property
    def gamma_left(self) -> float:
        """Platform angle of the OL face [rad] (from its normal)."""
        return self._faces["OL"][4]

    @property
    def gamma_right(self) -> float:
        """Platform angle of the OR face [rad] (from its normal)."""
        return self._faces["OR"][4]

    @property
    def total_length(self) -> float:
        """z of the tip point [m]."""
        return float(self._points["tip"][2])

    def contact_face(self, side: str):
        """(centre (3,), frame (3, 3), xi_range (2,), eta_range (2,)) of the ``side`` contact face,
        as :meth:`SolidBladeGeometry.contact_face` (the face's bounding rectangle in its frame)."""
        if side not in ("OL", "OR"):
            raise ValueError(f"side must be 'OL' or 'OR' (got {side!r})")
        centre, frame, xi_r, eta_r, _ = self._faces[side]
        return centre.copy(), frame.copy(), xi_r.copy(), eta_r.copy()

    def points(self) -> dict:
        """Named points [m]: "OL", "OR", "tip", "excitation" and any others of ``points_given``."""
        return {name: p.copy() for name, p in self._points.items()}

    def fit_region(self, name: str, position) -> tuple:
        """Where point ``name``'s rigid-body fit is taken: ("face", "OL" / "OR") its contact face,
        ("face", "tip") the tip face for the tip point (and any point there), else ("ball", None)
        the elements within one element size of the point."""
        if name in ("OL", "OR"):
            return ("face", name)
        if np.linalg.norm(np.asarray(position) - self._points["tip"]) <= 1e-9 * max(self.total_length, 1.0):
            return ("face", "tip")
        return ("ball", None)


def _load_surface(name: str, surface):
    """A trimesh.Trimesh from a path or a Trimesh: ValueError naming ``name`` and the file for a
    file trimesh cannot read or that holds no triangles (:class:`bladedamp.io.MissingFileError`,
    a ValueError and a FileNotFoundError, for a missing file)."""
    import trimesh
    if isinstance(surface, trimesh.Trimesh):
        return surface
    import os
    if not isinstance(surface, (str, os.PathLike)):
        raise ValueError(f"{name} must be a path of an STL file or a trimesh.Trimesh (got {type(surface).__name__})")
    if not os.path.exists(surface):
        raise MissingFileError(f"{name}: no file {os.fspath(surface)!r}")
    try:
        mesh = trimesh.load(surface, force="mesh")
    except Exception as err:          # trimesh raises many kinds on a broken file
        raise ValueError(f"{name}: {os.fspath(surface)!r} is not a surface mesh trimesh reads ({err})") from err
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ValueError(f"{name}: {os.fspath(surface)!r} holds no triangles")
    return mesh


def mesh_surface(geometry: SurfaceBladeGeometry, element_size: float = DEFAULT_ELEMENT_SIZE, *,
                 algorithm: int = 1, optimize: bool = True) -> SolidMesh:
    """Tetrahedral mesh of a user's closed surface (:class:`SurfaceBladeGeometry`) by gmsh.

    The STL's triangles become a discrete gmsh surface; gmsh splits it into faces at edges
    sharper than ``geometry.feature_angle`` and builds a parametrisation of each
    (``classifySurfaces`` / ``createGeometry``), so the faces are remeshed with triangles of size
    ``element_size`` [m] whatever the STL's triangles are; the closed faces bound one volume,
    meshed with tetrahedra. The named regions are then picked on the new boundary triangles by
    the same selectors. No mirror symmetry is used (the modes carry the mesh's asymmetry,
    about 1e-5: :func:`mesh_blade`).
    """
    gmsh, _ = _require_fe()
    if not isinstance(geometry, SurfaceBladeGeometry):
        raise ValueError(f"geometry must be a SurfaceBladeGeometry (got {type(geometry).__name__})")
    h = check.positive("element_size", element_size)
    start = time.perf_counter()
    with _gmsh_model(gmsh, "bladedamp_surface_blade"):
        surface = gmsh.model.addDiscreteEntity(2)
        n_v = geometry.vertices.shape[0]
        gmsh.model.mesh.addNodes(2, surface, np.arange(1, n_v + 1), geometry.vertices.ravel())
        gmsh.model.mesh.addElementsByType(surface, 2, [], (geometry.faces + 1).ravel())
        gmsh.model.mesh.classifySurfaces(geometry.feature_angle, True, True, np.pi)
        gmsh.model.mesh.createGeometry()
        faces_2d = [tag for _, tag in gmsh.model.getEntities(2)]
        loop = gmsh.model.geo.addSurfaceLoop(faces_2d)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        try:
            _gmsh_generate(gmsh, h, algorithm, optimize)
        except Exception as err:      # gmsh raises a bare Exception with its log line
            raise RuntimeError(f"gmsh could not mesh the surface's volume ({err}); try another element_size "
                               "or feature_angle") from err
        vertices, tets, platform, index = _gmsh_tetrahedra(gmsh)
        boundary = _gmsh_triangles(gmsh, faces_2d, index)
    # orient the boundary outward by the tetrahedra, then pick the regions on it
    outer = boundary_faces(tets, vertices)
    if np.unique(np.sort(outer, axis=0), axis=1).shape[1] != np.unique(np.sort(boundary, axis=0), axis=1).shape[1]:
        raise RuntimeError("gmsh's volume mesh does not fill the surface (its boundary is not the remeshed surface)")
    faces = {}
    for name in ("clamp", "tip", "OL", "OR"):
        picked = geometry.select(name, vertices.T, outer.T)
        if not picked.any():
            raise RuntimeError(f"the remeshed surface has no triangle in region {name!r}: lower feature_angle "
                               f"(now {np.degrees(geometry.feature_angle):g} deg) or raise the region's tolerance")
        faces[name] = outer[:, picked]
    return SolidMesh(vertices=vertices, tets=tets, platform=platform, faces=faces, element_size=h,
                     seconds=time.perf_counter() - start)


# --------------------------------------------------------------------------------------
# rigid-body fit and mode names
# --------------------------------------------------------------------------------------
def rigid_fit(points: np.ndarray, weights: np.ndarray, displacements: np.ndarray, reference) -> tuple:
    """Weighted least-squares rigid-body motion of a displacement field.

    Minimises sum_i w_i |u_i - (a + phi x (x_i - x_P))|^2 over the translation a at the reference
    point x_P and the small rotation phi (for a quadrature rule this is the integral over the
    region).

    Parameters
    ----------
    points : (N, 3) positions x_i [m]; weights : (N,) w_i >= 0 (areas, volumes) [m^2 or m^3].
    displacements : (N, 3, n) displacements u_i of n fields (modes) [m, or m/sqrt(kg)].
    reference : (3,) x_P [m].

    Returns
    -------
    motion : (6, n) (a, phi) [m, rad] (or per sqrt(kg)), ordered (u_x, u_y, u_z, phi_x, phi_y,
        phi_z) as every 6-vector of bladedamp.
    residual : (n,) sqrt(sum w |u - fit|^2 / sum w |u|^2) [-]: 0 for a rigid motion.
    normal_matrix : (6, 6) sum_i w_i G_i^T G_i, G_i = [I, -[r_i]x] (u = G q).
    """
    x = np.asarray(points, dtype=float)
    w = np.asarray(weights, dtype=float)
    u = np.asarray(displacements, dtype=float)
    r = x - np.asarray(reference, dtype=float)
    G = np.zeros((x.shape[0], 3, 6))
    G[:, [0, 1, 2], [0, 1, 2]] = 1.0
    # phi x r = -[r]x phi:  [r]x = [[0, -rz, ry], [rz, 0, -rx], [-ry, rx, 0]]
    G[:, 0, 4], G[:, 0, 5] = r[:, 2], -r[:, 1]
    G[:, 1, 3], G[:, 1, 5] = -r[:, 2], r[:, 0]
    G[:, 2, 3], G[:, 2, 4] = r[:, 1], -r[:, 0]
    N = np.einsum("i,iak,ial->kl", w, G, G)
    rhs = np.einsum("i,iak,ian->kn", w, G, u)
    motion = scipy.linalg.solve(N, rhs, assume_a="pos")
    miss = u - np.einsum("iak,kn->ian", G, motion)
    total = np.einsum("i,ian,ian->n", w, u, u)
    residual = np.sqrt(np.einsum("i,ian,ian->n", w, miss, miss) / np.where(total > 0, total, 1.0))
    return motion, residual, N


def classify_tip_motion(motion: np.ndarray, normal_matrix: np.ndarray, residual: np.ndarray):
    """Mode names from the tip face's rigid-body fit about its centroid.

    ``motion`` (6, n) and ``normal_matrix`` (6, 6) from :func:`rigid_fit` with the face centroid as
    reference (translation and rotation then decouple); the fitted motion's quadratic measure
    q^T N q is split into F = N_00 u_x^2 + N_44 phi_y^2, E = N_11 u_y^2 + N_33 phi_x^2,
    T = N_55 phi_z^2, A = N_22 u_z^2. Returns (names (n,) counted per family, "1F", "2F", "1E",
    ..., or "1P", ... where ``residual`` > :data:`PLATE_MODE_RESIDUAL`; families (n,) one of
    "F", "E", "T", "A", "P"; fractions (n, 4) shares of F, E, T, A).
    """
    d = np.diag(normal_matrix)
    q2 = np.asarray(motion) ** 2
    shares = np.stack([d[0] * q2[0] + d[4] * q2[4], d[1] * q2[1] + d[3] * q2[3], d[5] * q2[5], d[2] * q2[2]],
                      axis=1)
    fractions = shares / shares.sum(axis=1, keepdims=True)
    families = [("P" if res > PLATE_MODE_RESIDUAL else FAMILIES[int(np.argmax(f))])
                for f, res in zip(fractions, residual)]
    counters = dict.fromkeys(FAMILIES + ("P",), 0)
    names = []
    for fam in families:
        counters[fam] += 1
        names.append(f"{counters[fam]}{fam}")
    return tuple(names), tuple(families), fractions


def solid_platform_beam(solid_geometry=None, bending_theory: str = "timoshenko",
                        torsion_theory: str = "vlasov", n_elements: int = 1) -> BeamBladeGeometry:
    """The beam model of the parametric solid blade's geometry (:class:`SolidBladeGeometry`,
    None: the reference's): its beam geometry with the solid's platform prism as the platform block
    (:meth:`bladedamp.blade.beam.PlatformBlock.from_polygon` of ``platform_polygon()`` over ``platform_length``, with
    ``n_elements`` elements on each side of the platform node), no lumped platform mass or
    inertia (the block is the whole platform), and the given bending and torsion theories
    (default the refined ones, which the solid has). Refused (ValueError): what the beam does not
    represent, a twisted airfoil, a root block, a platform of another Young's modulus, no platform."""
    if solid_geometry is None:
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


CANTILEVER_THEORIES = ("euler-bernoulli", "refined")


def cantilever_frequencies_hz(geometry: BeamBladeGeometry | None = None, theory: str = "euler-bernoulli",
                              plate: bool = False) -> dict:
    """Closed-form first frequencies [Hz] "1F", "2F", "1E", "1T" of a uniform clamped-free beam
    with the airfoil section of ``geometry`` (a rectangle: chord c along y, thickness t along x)
    over its whole length L = L_total, no platform. For the reference blade (shank and
    airfoil have one section) it is the solid blade without its platform.

    theory : "euler-bernoulli" (default): Euler-Bernoulli bending, 1F = 1.8751^2 / (2 pi L^2)
        sqrt(E I_yy / (rho A)), 2F with 4.6941^2, 1E with I_xx; St. Venant torsion,
        1T = 1 / (4 L) sqrt(G J / (rho I_p)).
        "refined": the exact solutions of the refined beam equations. Bending (1F, 2F, 1E) after
        Timoshenko (:func:`timoshenko_cantilever_frequency_hz`): shear deformation with Cowper's
        coefficient of a rectangle, kappa = 10 (1 + nu) / (12 + 11 nu) (Cowper 1966, J. Appl.
        Mech. 33, 335), and rotary inertia rho I. Torsion (1T) after Vlasov
        (:func:`vlasov_cantilever_frequency_hz`): the clamped root holds the section's warping,
        warping stiffness E C_w with the solid rectangle's C_w (:func:`warping_constant_rectangle`).
    plate : flatwise bending (1F, 2F) with the plate modulus E / (1 - nu^2) instead of E: a section
        that cannot curve anticlastically (the bound a wide section approaches; +4.8 % in frequency
        at nu = 0.3), with either theory; 1E and 1T keep E.
    """
    if theory not in CANTILEVER_THEORIES:
        raise ValueError(f"theory must be one of {CANTILEVER_THEORIES} (got {theory!r})")
    if geometry is None:
        geometry = reference_blade_geometry()
    g = geometry
    sec = RectangularSection(g.airfoil_thickness_x, g.airfoil_chord_y)
    L, E, rho = g.total_length, g.youngs_modulus, g.density
    E_flat = E / (1.0 - g.poisson_ratio**2) if plate else E
    rhoA = rho * sec.area
    if theory == "refined":
        nu, G = g.poisson_ratio, g.shear_modulus
        kGA = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu) * G * sec.area        # Cowper's kappa G A [N]
        I_f, I_e = sec.second_moment_flatwise, sec.second_moment_edgewise
        return {"1F": timoshenko_cantilever_frequency_hz(L, E_flat * I_f, kGA, rhoA, rho * I_f, mode=1),
                "2F": timoshenko_cantilever_frequency_hz(L, E_flat * I_f, kGA, rhoA, rho * I_f, mode=2),
                "1E": timoshenko_cantilever_frequency_hz(L, E * I_e, kGA, rhoA, rho * I_e, mode=1),
                "1T": vlasov_cantilever_frequency_hz(
                    L, G * sec.torsion_constant,
                    E * warping_constant_rectangle(g.airfoil_thickness_x, g.airfoil_chord_y),
                    rho * sec.polar_moment)}

    def bending(beta, modulus, second_moment):
        return beta**2 / (2 * np.pi * L**2) * np.sqrt(modulus * second_moment / rhoA)

    return {"1F": bending(1.875104, E_flat, sec.second_moment_flatwise),
            "2F": bending(4.694091, E_flat, sec.second_moment_flatwise),
            "1E": bending(1.875104, E, sec.second_moment_edgewise),
            "1T": 1.0 / (4 * L) * np.sqrt(g.shear_modulus * sec.torsion_constant / (rho * sec.polar_moment))}


def _nth_root_on_grid(determinant, frequencies_hz: np.ndarray, n: int):
    """The ``n``-th sign change of ``determinant(omega)`` (vectorised over omega [rad/s]) on the
    ascending grid ``frequencies_hz`` [Hz], refined by Brent's method [Hz]; None if it has fewer."""
    from scipy.optimize import brentq
    d = determinant(2 * np.pi * frequencies_hz)
    changes = np.nonzero(np.sign(d[1:]) * np.sign(d[:-1]) < 0)[0]
    if changes.size < n:
        return None
    i = changes[n - 1]
    return float(brentq(lambda f: float(determinant(2 * np.pi * np.array([f]))[0]),
                        frequencies_hz[i], frequencies_hz[i + 1], xtol=1e-13 * frequencies_hz[i], rtol=1e-13))


def vlasov_cantilever_frequency_hz(length: float, torsion_stiffness: float, warping_stiffness: float,
                                   polar_inertia: float) -> float:
    """Lowest torsion frequency [Hz] of a uniform clamped-free bar whose clamp holds the warping
    (non-uniform torsion: Vlasov; Timoshenko & Gere, Theory of Elastic Stability, torsion with
    warping restraint).

    length L [m]; torsion_stiffness G J [N m^2]; warping_stiffness E C_w [N m^4], > 0;
    polar_inertia rho I_p [kg m] (rotary inertia per unit length).

    E C_w phi'''' - G J phi'' - rho I_p omega^2 phi = 0 on 0 <= z <= L (Vlasov equation), clamp
    phi = phi' = 0 (twist and warping held), free end phi'' = 0 (no bimoment) and
    G J phi' - E C_w phi''' = 0 (no torque). phi = exp(lambda z) gives lambda^2 = alpha^2 > 0 or
    -beta^2 < 0, (alpha^2, -beta^2) = (G J +- sqrt((G J)^2 + 4 E C_w rho I_p omega^2)) / (2 E C_w);
    on the basis exp(-alpha z), exp(-alpha (L - z)), cos(beta z), sin(beta z) (bounded for any
    alpha L) the four conditions are a 4 x 4 determinant D(omega), here with its rows scaled by
    positive factors (the torque row with E C_w alpha^4 - G J alpha^2 = rho I_p omega^2). Warping
    restraint only stiffens, so the lowest root lies above St. Venant's 1 / (4 L) sqrt(G J /
    (rho I_p)): bracketed on a 0.5 % grid upward from just below it, refined by Brent's method.
    Limits: C_w -> 0 gives St. Venant's value, G J -> 0 the Euler-Bernoulli cantilever
    1.8751^2 / (2 pi L^2) sqrt(E C_w / (rho I_p)).
    """
    L = check.positive("length", length)
    GJ = check.nonnegative("torsion_stiffness", torsion_stiffness)
    ECw = check.positive("warping_stiffness", warping_stiffness)
    rhoIp = check.positive("polar_inertia", polar_inertia)

    def determinant(omega):
        q = np.sqrt(GJ**2 + 4.0 * ECw * rhoIp * omega**2)
        alpha = np.sqrt((GJ + q) / (2.0 * ECw))
        beta = np.sqrt(2.0 * rhoIp * omega**2 / (GJ + q))
        e, c, s, r = np.exp(-alpha * L), np.cos(beta * L), np.sin(beta * L), beta / alpha
        one, zero = np.ones_like(e), np.zeros_like(e)
        rows = [[one, e, one, zero],                      # phi(0)
                [-one, e, zero, r],                       # phi'(0) / alpha
                [e, one, -r**2 * c, -r**2 * s],           # phi''(L) / alpha^2
                [e, -one, -s / r, c / r]]                 # torque(L) alpha / (rho I_p omega^2)
        return np.linalg.det(np.moveaxis(np.array(rows), -1, 0))

    st_venant = np.sqrt(GJ / rhoIp) / (4 * L)
    warping = 1.875104**2 / (2 * np.pi * L**2) * np.sqrt(ECw / rhoIp)
    start = 0.99 * st_venant if st_venant > 0 else 0.5 * warping
    grid = start * 1.005 ** np.arange(int(np.log(10.0 * (st_venant + warping) / start) / np.log(1.005)) + 2)
    root = _nth_root_on_grid(determinant, grid, 1)
    if root is None:                                      # not expected: the bound is a Rayleigh quotient's
        raise RuntimeError("no torsion root found below 10 x (St. Venant + warping) frequency")
    return root


def timoshenko_cantilever_frequency_hz(length: float, bending_stiffness: float, shear_stiffness: float,
                                       mass_per_length: float, rotary_inertia: float, mode: int = 1) -> float:
    """The ``mode``-th bending frequency [Hz] of a uniform clamped-free Timoshenko beam.

    length L [m]; bending_stiffness E I [N m^2]; shear_stiffness kappa G A [N] (np.inf: no shear
    deformation); mass_per_length rho A [kg/m]; rotary_inertia rho I [kg m] (0: none);
    mode : 1, 2, ... (1F / 1E is 1, 2F is 2).

    Timoshenko beam (deflection w, section rotation psi): kappa G A (w'' - psi') + rho A omega^2 w
    = 0, E I psi'' + kappa G A (w' - psi) + rho I omega^2 psi = 0; clamp w = psi = 0, free end
    moment E I psi' = 0 and shear kappa G A (w' - psi) = -(E I psi'' + rho I omega^2 psi) = 0.
    w = exp(lambda z): E I lambda^4 + (rho I + rho A E I / (kappa G A)) omega^2 lambda^2
    + rho A omega^2 (rho I omega^2 / (kappa G A) - 1) = 0, below the cutoff
    omega_c^2 = kappa G A / (rho I) with roots alpha^2 > 0 and -beta^2 < 0, and
    psi' = w'' + rho A omega^2 / (kappa G A) w. On the basis exp(-alpha z), exp(-alpha (L - z)),
    cos(beta z), sin(beta z) the four conditions are a 4 x 4 determinant D(omega); its ``mode``-th
    root is bracketed on a 0.2 % grid from far below (1 % of the lower of the Euler-Bernoulli and
    the shear-beam first frequencies) up to the Euler-Bernoulli bound (shear and rotary inertia
    only lower each frequency), refined by Brent's method. kappa G A -> inf with rho I = 0 gives
    Euler-Bernoulli's beta_n^2 / (2 pi L^2) sqrt(E I / (rho A)) (beta_1 = 1.8751, beta_2 = 4.6941).
    """
    L = check.positive("length", length)
    EI = check.positive("bending_stiffness", bending_stiffness)
    kGA = np.inf if shear_stiffness == np.inf else check.positive("shear_stiffness", shear_stiffness)
    rhoA = check.positive("mass_per_length", mass_per_length)
    Jr = check.nonnegative("rotary_inertia", rotary_inertia)
    mode = check.integer("mode", mode, minimum=1)
    compliance = 1.0 / kGA                                          # 1 / (kappa G A) [1/N], 0 if inf

    def determinant(omega):
        w2 = omega**2
        s = rhoA * w2 * compliance                                 # rho omega^2 / (kappa G)
        p = (Jr + rhoA * EI * compliance) * w2 / EI
        r = rhoA * w2 * (1.0 - Jr * w2 * compliance) / EI           # > 0 below the cutoff
        root = np.sqrt(p**2 + 4.0 * r)
        alpha2, beta2 = 2.0 * r / (root + p), (root + p) / 2.0
        alpha, beta = np.sqrt(alpha2), np.sqrt(beta2)
        g, h = (alpha2 + s) / alpha, (s - beta2) / beta           # psi of exp(+-alpha z), of cos / sin
        e, c, sn = np.exp(-alpha * L), np.cos(beta * L), np.sin(beta * L)
        one, zero = np.ones_like(e), np.zeros_like(e)
        ma, mb = g * (alpha2 + Jr * w2 / EI), h * (beta2 - Jr * w2 / EI)   # shear row / E I
        rows = [[one, e, one, zero],                              # w(0)
                [-g, g * e, zero, -h],                            # psi(0)
                [g * alpha * e, g * alpha, h * beta * c, h * beta * sn],   # psi'(L)
                [-ma * e, ma, -mb * sn, mb * c]]                  # (E I psi'' + rho I omega^2 psi)(L) / E I
        return np.linalg.det(np.moveaxis(np.array(rows), -1, 0))

    f_eb1 = 1.875104**2 / (2 * np.pi * L**2) * np.sqrt(EI / rhoA)
    f_shear1 = np.sqrt(kGA / rhoA) / (4 * L)                       # shear beam, inf without shear
    f_hi = ((mode - 0.5) * np.pi + 0.31)**2 / (2 * np.pi * L**2) * np.sqrt(EI / rhoA)   # > beta_n^2 / ...
    if Jr > 0 and compliance > 0:
        f_hi = min(f_hi, (1.0 - 1e-9) * np.sqrt(kGA / Jr) / (2 * np.pi))            # the cutoff
    f_lo = 0.01 * min(f_eb1, f_shear1)
    grid = f_lo * 1.002 ** np.arange(int(np.log(f_hi / f_lo) / np.log(1.002)) + 2)
    root = _nth_root_on_grid(determinant, grid[grid <= f_hi], mode)
    if root is None:
        raise ValueError(f"bending mode {mode} lies above the cutoff frequency sqrt(kappa G A / (rho I)) "
                         "(Timoshenko's second spectrum); not handled")
    return root


# --------------------------------------------------------------------------------------
# FE model and modes (scikit-fem)
# --------------------------------------------------------------------------------------
@dataclass(eq=False)
class SolidModes:
    """Clamped-root modes of the solid blade (quadratic tetrahedra).

    Attributes
    ----------
    geometry : SolidBladeGeometry; mesh : SolidMesh.
    n_dofs : all DOF (3 per P2 node); n_free : DOF left after clamping.
    frequencies_hz : (n,) natural frequencies [Hz], ascending.
    vectors : (n_dofs, n) mass-normalised displacement vectors (vectors.T M vectors = I, zero on
        the clamped face) [m/sqrt(kg)].
    mode_names, families : (n,) from the tip motion (:func:`classify_tip_motion`).
    family_fractions : (n, 4) shares of F, E, T, A in the tip face's rigid motion.
    tip_residual : (n,) share of the tip face motion its rigid-body fit misses [-].
    stiffness, mass_matrix : (n_dofs, n_dofs) scipy.sparse CSR K [N/m] and M [kg] (unclamped).
    mass : the blade's total mass [kg] (property).
    free_dofs : (n_free,) indices of the free DOF.
    seconds : wall times [s] of "mesh", "assemble", "solve".
    rotor_speed_hz [Hz], hub_radius [m] : the centrifugal prestress (0: at rest; :func:`solid_modes`);
        with it, static_displacement (property) is the centrifugal static displacement (n_dofs,) [m].
    fe_model : the scikit-fem model the modes were computed on, by name: "mesh" (skfem MeshTet),
        "element" (the vector P2 element), "basis_k", "basis_m" (its bases), "facets" (face name ->
        facet indices), "mu", "lam" (Lame constants [Pa]), "mass" [kg] and, with a prestress,
        "static_displacement" (what :meth:`face_quadrature`, :meth:`displacements_at` and
        :meth:`ContactFaceField.from_modes` evaluate).
    """

    geometry: SolidBladeGeometry
    mesh: SolidMesh
    n_dofs: int
    n_free: int
    frequencies_hz: np.ndarray
    vectors: np.ndarray = field(repr=False)
    mode_names: tuple
    families: tuple
    family_fractions: np.ndarray = field(repr=False)
    tip_residual: np.ndarray = field(repr=False)
    stiffness: object = field(repr=False)
    mass_matrix: object = field(repr=False)
    free_dofs: np.ndarray = field(repr=False)
    seconds: dict = field(default_factory=dict)
    fe_model: dict = field(default_factory=dict, repr=False)
    rotor_speed_hz: float = 0.0
    hub_radius: float = 0.0

    @property
    def mass(self) -> float:
        """Total blade mass [kg] (above the clamp)."""
        return float(self.fe_model["mass"])

    @property
    def static_displacement(self) -> np.ndarray | None:
        """(n_dofs,) displacement of the centrifugal static step [m] (None at rest)."""
        return self.fe_model.get("static_displacement")

    @property
    def vertex_dofs(self) -> np.ndarray:
        """(3, n_vertices) int: the index in :attr:`vectors`' rows and :attr:`static_displacement`
        of the x, y, z displacement of each mesh vertex (the P2 elements' vertex DOFs)."""
        return self.fe_model["basis_k"].nodal_dofs

    # -- evaluation ----------------------------------------------------------------------
    def face_quadrature(self, name: str):
        """Quadrature (order 4) of the boundary face ``name`` (a named facet set of the mesh, e.g.
        "tip"; ValueError naming the faces otherwise): points (N, 3) [m], weights (N,) [m^2] and
        the n columns of :attr:`vectors` (mode shapes, in their units) at the points (N, 3, n)."""
        from skfem import FacetBasis
        fe = self.fe_model
        if name not in fe["facets"]:
            raise ValueError(f"face must be one of {sorted(fe['facets'])} (got {name!r})")
        fb = FacetBasis(fe["mesh"], fe["element"], facets=fe["facets"][name], intorder=4)
        x = np.asarray(fb.global_coordinates())              # (3, nf, nq)
        w = np.asarray(fb.dx)                                # (nf, nq)
        u = np.stack([np.asarray(fb.interpolate(self.vectors[:, j])) for j in range(self.vectors.shape[1])],
                     axis=-1)                                # (3, nf, nq, n)
        return (x.reshape(3, -1).T, w.ravel(), u.reshape(3, -1, u.shape[-1]).transpose(1, 0, 2))

    def _volume_quadrature(self, elements):
        """Quadrature of the volume of ``elements`` (tetrahedron indices): points (N, 3), weights
        (N,) [m^3], values (N, 3, n)."""
        from skfem import Basis
        fe = self.fe_model
        elements = np.asarray(elements, dtype=np.int64)
        if elements.size == 0:
            raise ValueError("no elements to fit over (this solid has no platform)")
        cb = Basis(fe["mesh"], fe["element"], elements=elements, intorder=4)
        x = np.asarray(cb.global_coordinates())
        w = np.asarray(cb.dx)
        u = np.stack([np.asarray(cb.interpolate(self.vectors[:, j])) for j in range(self.vectors.shape[1])], axis=-1)
        return (x.reshape(3, -1).T, w.ravel(), u.reshape(3, -1, u.shape[-1]).transpose(1, 0, 2))

    def _elements_near(self, position, radius: float | None = None) -> np.ndarray:
        """Indices of the tetrahedra whose centroid lies within ``radius`` [m] (None: the element
        size) of ``position`` (3,); at least the 8 nearest."""
        centroids = self.mesh.vertices[:, self.mesh.tets].mean(axis=1).T        # (n_e, 3)
        distance = np.linalg.norm(centroids - np.asarray(position, dtype=float), axis=1)
        r = self.mesh.element_size if radius is None else radius
        inside = np.flatnonzero(distance <= r)
        return inside if inside.size >= 8 else np.argsort(distance)[:8]

    def displacements_at(self, points: np.ndarray) -> np.ndarray:
        """(P, 3, n) FE displacements of every mode at points (P, 3) inside the solid [m/sqrt(kg)]
        (interpolated by the P2 shape functions; a point on the surface may need a nudge inward)."""
        x = np.atleast_2d(np.asarray(points, dtype=float))
        probe = self.fe_model["basis_m"].probes(x.T)              # (3 P, n_dofs), rows component-major
        values = probe @ self.vectors                         # (3 P, n)
        return values.reshape(3, x.shape[0], -1).transpose(1, 0, 2)

    def _section_quadrature(self, z: float, n_thickness: int = 4, n_chord: int = 8):
        """Gauss-Legendre grid over the blade's cross-section at height z (shank or airfoil
        rectangle, twisted as the airfoil): points (N, 3), weights (N,) [m^2], values (N, 3, n)."""
        sg = self.geometry
        g = sg.beam
        z = float(np.clip(z, sg.clamp_z, g.total_length))
        shank = z < g.shank_length
        tx, cy = (g.shank_thickness_x, g.shank_chord_y) if shank else (g.airfoil_thickness_x, g.airfoil_chord_y)
        a, wa = np.polynomial.legendre.leggauss(n_thickness)
        b, wb = np.polynomial.legendre.leggauss(n_chord)
        X, Y = np.meshgrid(0.5 * tx * a, 0.5 * cy * b, indexing="ij")
        W = np.outer(0.5 * tx * wa, 0.5 * cy * wb)     # area weights, sum = tx * cy
        angle = 0.0
        if sg.twist and z > sg.twist_start:
            angle = sg.twist * (z - sg.twist_start) / (g.total_length - sg.twist_start)
        c, s = np.cos(angle), np.sin(angle)
        pts = np.column_stack([c * X.ravel() - s * Y.ravel(), s * X.ravel() + c * Y.ravel(), np.full(X.size, z)])
        return pts, W.ravel(), self.displacements_at(pts)

    def point_shapes(self, points: dict) -> tuple[dict, dict]:
        """6-DOF rigid-fit mode shapes (6, n) [m/sqrt(kg), rad/sqrt(kg)] of named points, and the
        fit residuals (n,): OL and OR over their contact face, "platform" over the platform
        prism, a point at the tip height over the tip face, any other over the cross-section at
        its height (module docstring)."""
        shapes, residuals = {}, {}
        for name, pos in points.items():
            pos = np.asarray(pos, dtype=float)
            region = self.geometry.fit_region(name, pos)
            if region[0] == "face":
                quad = self.face_quadrature(region[1])
            elif region[0] == "platform":
                quad = self._volume_quadrature(np.flatnonzero(self.mesh.platform))
            elif region[0] == "section":
                quad = self._section_quadrature(region[1])
            else:                         # ("ball", radius): the elements around the point
                quad = self._volume_quadrature(self._elements_near(pos, region[1]))
            x, w, u = quad
            motion, residual, _ = rigid_fit(x, w, u, pos)
            shapes[name], residuals[name] = motion, residual
        return shapes, residuals

    def contact_face(self, side: str, samples=DEFAULT_FACE_SAMPLES) -> "ContactFaceModes":
        """Raw FE displacements of the ``side`` ("OL", "OR") contact face at an (n_xi, n_eta)
        grid of cell midpoints over the face rectangle (:class:`ContactFaceModes`)."""
        n_xi, n_eta = (check.integer("samples", s, minimum=1) for s in samples)
        centre, frame, xi_r, eta_r = self.geometry.contact_face(side)
        xi = xi_r[0] + (np.arange(n_xi) + 0.5) / n_xi * (xi_r[1] - xi_r[0])
        eta = eta_r[0] + (np.arange(n_eta) + 0.5) / n_eta * (eta_r[1] - eta_r[0])
        XI, ETA = np.meshgrid(xi, eta, indexing="ij")          # xi-major, as ContactPatch
        pts = centre + XI.ravel()[:, None] * frame[0] + ETA.ravel()[:, None] * frame[1]
        # evaluate 0.1 um inside the platform (a point exactly on the face may miss every
        # element by rounding); the displacement changes by ~1e-4 of itself over that
        inside = pts - 1e-7 * frame[2]
        x, w, u = self.face_quadrature(side)
        motion, residual, _ = rigid_fit(x, w, u, centre)
        return ContactFaceModes(side=side, centre=centre, frame=frame, xi=XI.ravel(), eta=ETA.ravel(),
                                points=pts, shapes=self.displacements_at(inside), rigid_motion=motion,
                                rigid_residual=residual)

    def orthogonality(self) -> np.ndarray:
        """(n, n) Phi^T M Phi (the identity for mass-normalised modes)."""
        return self.vectors.T @ (self.mass_matrix @ self.vectors)


def _assemble(mesh: SolidMesh, sg: SolidBladeGeometry):
    """K, M (sparse, unclamped), skfem objects, total mass."""
    from skfem import Basis, BilinearForm, ElementTetP2, ElementVector, Functional, MeshTet, asm
    from skfem.helpers import ddot, dot, sym_grad, trace
    skmesh = MeshTet(mesh.vertices, mesh.tets)
    element = ElementVector(ElementTetP2())
    # intorder 2 integrates the P2 stiffness exactly on straight-edged tetrahedra (grad P2 is
    # linear), 4 the consistent mass (P2 x P2)
    basis_k = Basis(skmesh, element, intorder=2)
    basis_m = Basis(skmesh, element, intorder=4)
    E = np.where(mesh.platform, sg.platform_youngs_modulus or sg.youngs_modulus, sg.youngs_modulus)
    nu = sg.poisson_ratio
    lam_e = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu_e = E / (2 * (1 + nu))
    nq = basis_k.X.shape[1]

    @BilinearForm
    def stiffness(u, v, w):
        eu, ev = sym_grad(u), sym_grad(v)
        return 2.0 * w.mu * ddot(eu, ev) + w.lam * trace(eu) * trace(ev)

    @BilinearForm
    def mass(u, v, w):
        return sg.density * dot(u, v)

    @Functional
    def volume(w):
        return sg.density + 0.0 * w.x[0]

    lam_q, mu_q = np.repeat(lam_e[:, None], nq, axis=1), np.repeat(mu_e[:, None], nq, axis=1)
    K = asm(stiffness, basis_k, lam=lam_q, mu=mu_q).tocsr()
    M = asm(mass, basis_m).tocsr()
    total_mass = asm(volume, basis_k)
    facets = _facet_indices(skmesh, mesh.faces)
    return K, M, {"mesh": skmesh, "element": element, "basis_k": basis_k, "basis_m": basis_m,
                  "facets": facets, "mass": total_mass, "lam": lam_q, "mu": mu_q}


def _facet_indices(skmesh, faces: dict) -> dict:
    """skfem facet indices of gmsh's boundary triangles (name -> (n_f,) int)."""
    n = np.int64(skmesh.p.shape[1])
    f = np.sort(skmesh.facets.astype(np.int64), axis=0)
    keys = (f[0] * n + f[1]) * n + f[2]
    order = np.argsort(keys)
    out = {}
    for name, tri in faces.items():
        t = np.sort(tri.astype(np.int64), axis=0)
        k = (t[0] * n + t[1]) * n + t[2]
        pos = np.searchsorted(keys, k, sorter=order)
        pos = np.clip(pos, 0, keys.size - 1)
        idx = order[pos]
        if not np.all(keys[idx] == k):
            raise RuntimeError(f"face {name!r}: {int(np.sum(keys[idx] != k))} gmsh triangles are no tetrahedron facets")
        out[name] = idx.astype(np.int32)
    return out


def _eigen(K, M, free: np.ndarray, n_modes: int):
    """Lowest n_modes of K v = lambda M v on the free DOF by shift-invert; (lambda, V), V^T M V = I."""
    Kf = K[free][:, free].tocsc()
    Mf = M[free][:, free].tocsc()
    # K - sigma M with sigma < 0 is symmetric positive definite: SuperLU in symmetric mode
    # (minimum degree on A^T + A, diagonal pivots) fills in far less than its default COLAMD.
    # (Fill-in and timings: benchmarks/README.md, 'Moved from the package's docstrings', solid.py.)
    lu = scipy.sparse.linalg.splu((Kf - SHIFT_INVERT_SIGMA * Mf).tocsc(), permc_spec="MMD_AT_PLUS_A",
                                  diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    op = scipy.sparse.linalg.LinearOperator(Kf.shape, matvec=lu.solve, dtype=float)
    n_found = min(n_modes, free.size - 2)
    _, V = scipy.sparse.linalg.eigsh(Kf, k=n_found, M=Mf, sigma=SHIFT_INVERT_SIGMA, which="LM", OPinv=op)
    # Rayleigh-Ritz on the found subspace: exact M-orthonormality, ascending order
    lam, Q = scipy.linalg.eigh(V.T @ (Kf @ V), V.T @ (Mf @ V))
    V = V @ Q
    V = V / np.sqrt(np.einsum("ij,ij->j", V, Mf @ V))
    return lam, V


def _centrifugal_prestress(K, fe, sg, free: np.ndarray, omega: float, hub_radius: float):
    """Stiffness of the spinning blade (rotor axis y through z = -hub_radius, speed omega [rad/s]):
    K + K_sigma - omega^2 M_perp. The centrifugal body force rho omega^2 (x, 0, z + R) is applied
    in a linear static step (K - omega^2 M_perp) u0 = F on the clamped blade; its stress sigma0
    gives the geometric (stress) stiffness K_sigma = int sigma0_ij (d_i v_k)(d_j u_k) dV, and
    M_perp = int rho (u_x v_x + u_z v_z) dV is the spin softening of motion in the plane of
    rotation. Coriolis coupling is left out (the modes stay real)."""
    from skfem import BilinearForm, LinearForm, asm
    basis = fe["basis_k"]

    @BilinearForm
    def in_plane_mass(u, v, w):
        return sg.density * (u[0] * v[0] + u[2] * v[2])

    @LinearForm
    def body_force(v, w):
        return sg.density * omega**2 * (w.x[0] * v[0] + (w.x[2] + hub_radius) * v[2])

    M_perp = asm(in_plane_mass, fe["basis_m"]).tocsr()
    F = asm(body_force, fe["basis_m"])
    A = (K - omega**2 * M_perp)[free][:, free].tocsc()
    u0 = np.zeros(K.shape[0])
    u0[free] = scipy.sparse.linalg.spsolve(A, F[free])
    grad = basis.interpolate(u0).grad                               # (3, 3, n_e, n_q)
    eps = 0.5 * (grad + np.swapaxes(grad, 0, 1))
    tr = np.einsum("iien->en", eps)
    sigma = 2.0 * fe["mu"] * eps + fe["lam"] * tr * np.eye(3)[:, :, None, None]   # Hooke, per element

    @BilinearForm
    def stress_stiffness(u, v, w):
        return np.einsum("ijen,kien,kjen->en", w.s, v.grad, u.grad)

    K_sigma = asm(stress_stiffness, basis, s=sigma).tocsr()
    return (K + K_sigma - omega**2 * M_perp).tocsr(), u0


def solid_modes(geometry: SolidBladeGeometry | BeamBladeGeometry | None = None,
                element_size: float = DEFAULT_ELEMENT_SIZE, n_modes: int = DEFAULT_SEARCH_MODES,
                mesh: SolidMesh | None = None, symmetric: bool = True, rotor_speed_hz: float = 0.0,
                hub_radius: float = 0.0) -> SolidModes:
    """The ``n_modes`` lowest clamped-root modes of the solid blade (module docstring).

    geometry : SolidBladeGeometry, or a BeamBladeGeometry (its solid with the default platform),
        a SurfaceBladeGeometry (a user's STL), or None (the reference blade).
    element_size : gmsh's largest element size [m] (ignored if ``mesh`` is given).
    mesh : an existing :func:`mesh_blade` mesh of the same geometry.
    symmetric : mesh the symmetric part and mirror it (:func:`mesh_blade`).
    rotor_speed_hz : rotor speed [Hz] (rev/s, >= 0): > 0 gives the modes of the spinning blade,
        prestressed by the centrifugal load of a linear static step (stress stiffening and spin
        softening, no Coriolis; the rotor axis is y through z = -``hub_radius`` [m], >= 0: the
        radius of the blade frame's z = 0); ``stiffness`` is then that of the spinning blade.
    """
    _require_fe()
    sg = _solid_geometry(geometry)
    n_modes = check.integer("n_modes", n_modes, minimum=1)
    rotor_speed_hz = check.nonnegative("rotor_speed_hz", rotor_speed_hz)
    hub_radius = check.nonnegative("hub_radius", hub_radius)
    if mesh is None:
        mesh = (mesh_surface(sg, element_size) if isinstance(sg, SurfaceBladeGeometry)
                else mesh_blade(sg, element_size, symmetric=symmetric))
    t0 = time.perf_counter()
    K, M, fe = _assemble(mesh, sg)
    clamp_dofs = fe["basis_k"].get_dofs(facets=fe["facets"]["clamp"]).all()
    free = np.setdiff1d(np.arange(K.shape[0]), clamp_dofs)
    if rotor_speed_hz > 0:
        K, fe["static_displacement"] = _centrifugal_prestress(K, fe, sg, free, 2 * np.pi * rotor_speed_hz,
                                                              hub_radius)
    t1 = time.perf_counter()
    lam, V = _eigen(K, M, free, n_modes)
    t2 = time.perf_counter()
    vectors = np.zeros((K.shape[0], V.shape[1]))
    vectors[free] = V
    modes = SolidModes(geometry=sg, mesh=mesh, n_dofs=int(K.shape[0]), n_free=int(free.size),
                       frequencies_hz=np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi), vectors=vectors,
                       mode_names=(), families=(), family_fractions=np.zeros((V.shape[1], 4)),
                       tip_residual=np.zeros(V.shape[1]), stiffness=K, mass_matrix=M, free_dofs=free,
                       seconds={"mesh": mesh.seconds, "assemble": t1 - t0, "solve": t2 - t1}, fe_model=fe,
                       rotor_speed_hz=rotor_speed_hz, hub_radius=hub_radius)
    # names from the tip motion, signs: tip u_x > 0 (F), u_y > 0 (E), phi_z > 0 (T), u_z > 0 (A)
    x, w, u = modes.face_quadrature("tip")
    centroid = (w @ x) / w.sum()
    motion, residual, N = rigid_fit(x, w, u, centroid)
    names, families, fractions = classify_tip_motion(motion, N, residual)
    sign_dof = {"F": 0, "E": 1, "T": 5, "A": 2}
    for j, fam in enumerate(families):
        value = motion[sign_dof[fam], j] if fam in sign_dof else u[:, :, j].ravel()[np.argmax(np.abs(u[:, :, j]))]
        if value < 0:
            vectors[:, j] *= -1.0
    modes.mode_names, modes.families = names, families
    modes.family_fractions, modes.tip_residual = fractions, residual
    return modes


# --------------------------------------------------------------------------------------
# ModalBlade
# --------------------------------------------------------------------------------------
@dataclass(eq=False)
class ContactFaceModes:
    """Raw FE motion of one platform contact face, per mode (for a flexible-platform contact).

    side : "OL" or "OR"; centre : (3,) the control point [m] (on the face);
    frame : (3, 3) rows (xi, eta, zeta) of the contact (bladedamp.damper.geometry.contact_frame;
        zeta the face's outward normal, into the damper);
    xi, eta : (P,) sample coordinates in that frame relative to the centre [m] (xi-major grid of
        cell midpoints over the face rectangle, as ContactPatch orders its points);
    points : (P, 3) sample positions in the blade frame [m];
    shapes : (P, 3, n_m) FE translations of the mass-normalised modes there [m/sqrt(kg)];
    rigid_motion : (6, n_m) the face's rigid-body fit about the centre (= the ModalBlade's OL / OR
        shape) [m/sqrt(kg), rad/sqrt(kg)];
    rigid_residual : (n_m,) share of the face motion the rigid fit misses (area-weighted RMS) [-].
    """

    side: str
    centre: np.ndarray
    frame: np.ndarray
    xi: np.ndarray
    eta: np.ndarray
    points: np.ndarray
    shapes: np.ndarray
    rigid_motion: np.ndarray
    rigid_residual: np.ndarray

    def rigid_shapes(self) -> np.ndarray:
        """(P, 3, n_m) translations of the sample points under the rigid fit: u_P + phi x r."""
        r = self.points - self.centre
        u, phi = self.rigid_motion[:3], self.rigid_motion[3:]
        return u[None] + np.cross(phi.T[None], r[:, None, :]).transpose(0, 2, 1)

    def select(self, modes) -> "ContactFaceModes":
        """The same face with the modes ``modes`` (indices) only."""
        idx = list(modes)
        return dataclasses.replace(self, shapes=self.shapes[:, :, idx], rigid_motion=self.rigid_motion[:, idx],
                                   rigid_residual=self.rigid_residual[idx])


# Local nodes of a quadratic tetrahedron in ContactFaceField.tets: the corners 0-3, then the
# midpoints of these edges (corner pairs).
TET_P2_EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


@dataclass(eq=False)
class ContactFaceField:
    """The exact FE displacement field of a blade's modes at one platform contact face: the
    quadratic tetrahedra with a vertex on the face, their P2 nodes and the mode shapes there (what
    :meth:`SolidModalBlade.platform_displacements` evaluates at the contact points; it is all the
    flexible-platform kinematics need of the FE model, so a saved blade keeps it).

    side : "OL" or "OR"; centre : (3,) the control point [m]; frame : (3, 3) rows (xi, eta, zeta)
        of the contact (zeta the face's outward normal, into the damper); xi_range, eta_range :
        (2,) the face rectangle in that frame relative to the centre [m]; gamma : the face's
        platform angle [rad];
    nodes : (n_n, 3) positions of the P2 nodes [m] (blade frame);
    tets : (n_t, 10) node indices of each tetrahedron: its corners, then the midpoints of the
        edges :data:`TET_P2_EDGES`;
    shapes : (n_n, 3, n_m) FE translations of the mass-normalised modes at the nodes [m/sqrt(kg)].
    """

    side: str
    centre: np.ndarray
    frame: np.ndarray
    xi_range: np.ndarray
    eta_range: np.ndarray
    gamma: float
    nodes: np.ndarray
    tets: np.ndarray
    shapes: np.ndarray

    def __post_init__(self):
        if self.side not in ("OL", "OR"):
            raise ValueError(f"side must be 'OL' or 'OR' (got {self.side!r})")
        n_n = np.shape(self.nodes)[0] if np.ndim(self.nodes) == 2 else -1
        tets = np.asarray(self.tets)
        if (np.shape(self.nodes) != (n_n, 3) or tets.ndim != 2 or tets.shape[1] != 10 or tets.shape[0] == 0
                or tets.dtype.kind not in "iu" or tets.min() < 0 or tets.max() >= n_n
                or np.ndim(self.shapes) != 3 or np.shape(self.shapes)[:2] != (n_n, 3)):
            raise ValueError(f"ContactFaceField {self.side}: nodes must be (n_n, 3), tets (n_t >= 1, 10) node "
                             f"indices and shapes (n_n, 3, n_m) (got {np.shape(self.nodes)}, {tets.shape} "
                             f"{tets.dtype}, {np.shape(self.shapes)})")
        if (np.shape(self.centre) != (3,) or np.shape(self.frame) != (3, 3) or np.shape(self.xi_range) != (2,)
                or np.shape(self.eta_range) != (2,)):
            raise ValueError(f"ContactFaceField {self.side}: centre must be (3,), frame (3, 3), xi_range and "
                             f"eta_range (2,) (got {np.shape(self.centre)}, {np.shape(self.frame)}, "
                             f"{np.shape(self.xi_range)}, {np.shape(self.eta_range)})")
        self.tets = tets.astype(np.int64, copy=False)
        self.gamma = float(self.gamma)

    @property
    def n_modes(self) -> int:
        """Number of modes n_m."""
        return int(self.shapes.shape[2])

    def displacements_at(self, points) -> np.ndarray:
        """(P, 3, n_m) FE translations [m/sqrt(kg)] at ``points`` (P, 3) [m] inside the
        tetrahedra (P2 shape functions: the same field as :meth:`SolidModes.displacements_at`).
        Each point is evaluated in the tetrahedron whose smallest barycentric coordinate there is
        largest (the one holding it; for a point outside all of them by rounding, the nearest,
        extrapolated)."""
        x = np.atleast_2d(np.asarray(points, dtype=float))
        corners = self.nodes[self.tets[:, :4]]                                   # (n_t, 4, 3)
        edges = np.linalg.inv((corners[:, 1:] - corners[:, :1]).transpose(0, 2, 1))   # (n_t, 3, 3)
        lam123 = np.einsum("tij,ptj->pti", edges, x[:, None, :] - corners[None, :, 0])  # (P, n_t, 3)
        lam = np.concatenate([1.0 - lam123.sum(axis=2, keepdims=True), lam123], axis=2)  # (P, n_t, 4)
        best = np.argmax(lam.min(axis=2), axis=1)                                 # (P,)
        b = lam[np.arange(x.shape[0]), best]                                      # (P, 4)
        N = np.concatenate([b * (2.0 * b - 1.0)] + [4.0 * b[:, i:i + 1] * b[:, j:j + 1] for i, j in TET_P2_EDGES],
                           axis=1)                                                # (P, 10)
        return np.einsum("pk,pkcm->pcm", N, self.shapes[self.tets[best]])

    @classmethod
    def from_modes(cls, modes: "SolidModes", side: str, mode_indices) -> "ContactFaceField":
        """The field of ``modes`` (the columns ``mode_indices``) at its ``side`` contact face."""
        fe = modes.fe_model
        basis = fe["basis_k"]
        t = np.asarray(fe["mesh"].t)                                              # (4, n_e), = mesh.tets
        on_face = np.zeros(modes.mesh.vertices.shape[1], dtype=bool)
        on_face[np.unique(modes.mesh.faces[side])] = True
        elements = np.flatnonzero(on_face[t].any(axis=0))
        # skfem's local scalar nodes (reference coordinates) -> this class's order
        ref = np.asarray(fe["element"].elem.doflocs)                              # (10, 3)
        bary = np.column_stack([1.0 - ref.sum(axis=1), ref])                      # (10, 4)
        wanted = np.vstack([np.eye(4)] + [0.5 * (np.eye(4)[i] + np.eye(4)[j]) for i, j in TET_P2_EDGES])
        order = [int(np.flatnonzero(np.all(np.abs(bary - w) < 1e-12, axis=1))[0]) for w in wanted]
        dofs = np.asarray(basis.element_dofs)[:, elements]          # (30, n_t): node k, component c at row 3 k + c
        node_dofs = dofs.reshape(10, 3, -1)[order]                                # (10, 3, n_t)
        _, tets = np.unique(node_dofs[:, 0].T, return_inverse=True)
        tets = tets.reshape(-1, 10)
        first = np.unique(tets.ravel(), return_index=True)[1]
        per_node = node_dofs.transpose(2, 0, 1).reshape(-1, 3)[first]             # (n_n, 3) DOF of each node
        p = modes.mesh.vertices[:, t[:, elements]].T                              # (n_t, 4, 3) corners
        positions = np.concatenate([p] + [0.5 * (p[:, i:i + 1] + p[:, j:j + 1]) for i, j in TET_P2_EDGES], axis=1)
        nodes = positions.reshape(-1, 3)[first]
        shapes = modes.vectors[per_node][:, :, list(mode_indices)]                # (n_n, 3, n_m)
        centre, frame, xi_r, eta_r = modes.geometry.contact_face(side)
        gamma = modes.geometry.gamma_left if side == "OL" else modes.geometry.gamma_right
        return cls(side=side, centre=centre, frame=frame, xi_range=np.asarray(xi_r, dtype=float),
                   eta_range=np.asarray(eta_r, dtype=float), gamma=float(gamma), nodes=nodes,
                   tets=tets.astype(np.int64), shapes=shapes)


@dataclass(eq=False)
class BladeSurface:
    """The FE blade's boundary surface and its mode shapes there, for pictures (compact: the
    corner vertices of the outer triangles of the tetrahedral mesh only).

    vertices : (n_v, 3) positions [m] in the blade frame; faces : (n_f, 3) vertex indices of
        the outward triangles; shapes : (n_v, 3, n_m) FE translations of the blade's
        mass-normalised modes at the vertices [m/sqrt(kg)] (the displacement of the surface for
        modal coordinates q (n_m,) [sqrt(kg) m] is ``shapes @ q``).
    """

    vertices: np.ndarray
    faces: np.ndarray
    shapes: np.ndarray

    def displaced(self, q) -> np.ndarray:
        """(n_v, 3) vertex positions [m] displaced by the modal coordinates ``q`` (n_m,)."""
        return self.vertices + self.shapes @ np.asarray(q, dtype=float)

    @classmethod
    def from_modes(cls, modes: "SolidModes", mode_indices) -> "BladeSurface":
        """The boundary of ``modes``'s mesh with the modes ``mode_indices`` (columns of modes.vectors)."""
        mesh = modes.mesh
        tri = boundary_faces(mesh.tets, mesh.vertices)
        used, faces = np.unique(tri.T, return_inverse=True)
        dofs = modes.vertex_dofs[:, used]                       # (3, n_v) P2 vertex DOF
        shapes = modes.vectors[dofs.T][:, :, list(mode_indices)]              # (n_v, 3, n_m)
        return cls(vertices=mesh.vertices[:, used].T.copy(), faces=faces.reshape(-1, 3).astype(np.int64),
                   shapes=shapes)


@dataclass(eq=False)
class SolidModalBlade(ModalBlade):
    """A :class:`~bladedamp.blade.ModalBlade` from the solid FE blade (:func:`solid_blade`): every
    ModalBlade field and use, plus

    contact_faces : "OL", "OR" -> :class:`ContactFaceModes`, the raw FE displacements of the
        platform contact faces at sampled points (the OL / OR shapes are their rigid fits).
    fit_residuals : point name -> (n_m,) share of the region's motion the point's rigid fit misses.
    solid_info : n_dofs, element_size [m], mass [kg], all computed frequencies [Hz] and names,
        the rotor speed [Hz] and hub radius [m] of the prestress (0: at rest), and the wall times [s]
        of meshing, assembly and eigen-solution.
    modes : the :class:`SolidModes` the blade was built from (the whole FE model; None in a blade
        read from a file); mode_indices : (n_m,) the columns of ``modes`` (and of
        ``solid_info["frequencies_hz"]``) that are this blade's modes.
    face_fields : "OL", "OR" -> :class:`ContactFaceField`, the exact FE field of the modes at the
        platform contact faces (default: taken from ``modes``; empty: rigid platforms in the
        contact kinematics).
    surface : :class:`BladeSurface`, the FE boundary surface with the mode shapes at its
        vertices (the 3D view draws it deformed: :func:`bladedamp.viz.show`), or None.

    With ``face_fields``, :meth:`platform_displacements` gives the FE displacement of the
    platform's contact faces at any point of them, and the disks (:class:`~bladedamp.disk.TunedDisk`,
    :class:`~bladedamp.mistuned.MistunedDisk`) use it at every contact point: a flexible
    platform (:func:`bladedamp.diskmodel.contact_point_maps`). :meth:`rigid_platform_blade` is the
    same blade with rigid platforms at OL / OR (the beam model's contact kinematics).

    Saved files (:meth:`save`, ``.npz`` only, format :data:`SOLID_NPZ_FORMAT`) hold everything but
    ``modes``: the ModalBlade part, ``face_fields``, ``contact_faces``, ``fit_residuals``,
    ``solid_info``, ``mode_indices`` and ``surface``; :meth:`~bladedamp.blade.ModalBlade.from_file`
    reads them back into a SolidModalBlade with the same flexible platforms (the same disk FRF).
    """

    contact_faces: dict = field(default_factory=dict, repr=False)
    fit_residuals: dict = field(default_factory=dict, repr=False)
    solid_info: dict = field(default_factory=dict, repr=False)
    modes: SolidModes | None = field(default=None, repr=False)
    mode_indices: tuple = ()
    surface: BladeSurface | None = field(default=None, repr=False)
    face_fields: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        super().__post_init__()
        for side, face in self.contact_faces.items():
            if not isinstance(face, ContactFaceModes) or face.shapes.shape[2] != self.n_modes:
                raise ValueError(f"contact_faces[{side!r}] must be ContactFaceModes with {self.n_modes} modes")
        self.mode_indices = tuple(int(i) for i in self.mode_indices)
        if self.modes is not None:
            if not isinstance(self.modes, SolidModes):
                raise ValueError(f"modes must be a SolidModes or None (got {type(self.modes).__name__})")
            idx = self.mode_indices
            if len(idx) != self.n_modes or min(idx) < 0 or max(idx) >= self.modes.vectors.shape[1]:
                raise ValueError(f"mode_indices must name {self.n_modes} of the {self.modes.vectors.shape[1]} "
                                 f"columns of modes (got {self.mode_indices!r})")
            if not self.face_fields:
                self.face_fields = {side: ContactFaceField.from_modes(self.modes, side, idx) for side in ("OL", "OR")}
        self.face_fields = dict(self.face_fields)
        if self.face_fields and (set(self.face_fields) != {"OL", "OR"} or not all(
                isinstance(f, ContactFaceField) and f.side == s and f.n_modes == self.n_modes
                for s, f in self.face_fields.items())):
            raise ValueError(f"face_fields must be empty or map 'OL' and 'OR' to their ContactFaceField with "
                             f"{self.n_modes} modes (got {sorted(self.face_fields)})")
        if self.surface is not None and (not isinstance(self.surface, BladeSurface)
                                         or self.surface.shapes.shape[2] != self.n_modes):
            raise ValueError(f"surface must be None or a BladeSurface with {self.n_modes} modes")

    #: how far a contact point may lie off its face (along the normal, or past the face's edge)
    #: relative to the face's size before it is refused [-]
    FACE_TOLERANCE = 1e-6

    @property
    def flexible_platform(self) -> bool:
        """True when the contact faces' FE field is kept (``face_fields``): the platform is
        flexible at the contacts."""
        return bool(self.face_fields)

    def platform_displacements(self, side: str, points, normal=None) -> np.ndarray | None:
        """FE translations (P, 3, n_m) [m/sqrt(kg)] of the ``side`` ("OL", "OR") contact face at
        ``points`` (P, 3) [m, blade frame], interpolated by the P2 shape functions (exact FE
        field, :meth:`ContactFaceField.displacements_at`) of the mass-normalised modes; None
        without ``face_fields`` (rigid platforms). ``normal`` (3,): the
        contact normal the caller's kinematics assume (from the platform into the damper, i.e.
        the platform angle); ValueError if the face's differs by more than 1e-6 rad (a disk whose
        gamma_left / gamma_right are not the solid's).

        Each point is projected onto the face plane along its normal (the damper placement of
        :meth:`~bladedamp.disk.TunedDisk.platform_offsets` puts a contact centre off the face by
        half the radial mismatch when the two platform angles differ) and evaluated 0.1 um inside
        the platform (as :meth:`SolidModes.contact_face`). Raises ValueError if a point lies
        outside the face rectangle (a damper patch longer or higher than the face) or off its
        plane by more than 5 % of the face's height.
        """
        if side not in ("OL", "OR"):
            raise ValueError(f"side must be 'OL' or 'OR' (got {side!r})")
        face = self.face_fields.get(side)
        if face is None:
            return None
        x = np.asarray(points, dtype=float)
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"points must have shape (P, 3) [m] (got {x.shape})")
        centre, frame, xi_r, eta_r = face.centre, face.frame, face.xi_range, face.eta_range
        if normal is not None:
            n = np.asarray(normal, dtype=float)
            angle = np.arccos(np.clip(n @ frame[2] / np.linalg.norm(n), -1.0, 1.0))
            if n.shape != (3,) or angle > 1e-6:
                raise ValueError(f"normal: the {side} contact normal {np.round(n, 6)} is {np.degrees(angle):.4g} deg "
                                 f"off the solid blade's {side} face (its platform angle is "
                                 f"{np.degrees(face.gamma):.6g} deg): give the disk the solid's "
                                 f"{'gamma_left' if side == 'OL' else 'gamma_right'}, or build the solid "
                                 "(SolidBladeGeometry gamma_left / gamma_right) with the disk's")
        local = (x - centre) @ frame.T                                    # (xi, eta, zeta)
        size = max(xi_r[1] - xi_r[0], eta_r[1] - eta_r[0])
        tol = self.FACE_TOLERANCE * size
        for k, (name, lo, hi) in enumerate((("xi (across the face)", *xi_r), ("eta (along y)", *eta_r))):
            outside = (local[:, k] < lo - tol) | (local[:, k] > hi + tol)
            if np.any(outside):
                raise ValueError(f"points: contact point {np.flatnonzero(outside)[0]} lies outside the {side} "
                                 f"platform contact face ({name} {local[outside, k][0]:.4g} m, the face spans "
                                 f"{lo:.4g}..{hi:.4g} m): the damper's contact patch is larger than the face")
        if np.abs(local[:, 2]).max() > 0.05 * (xi_r[1] - xi_r[0]):
            raise ValueError(f"points lie {np.abs(local[:, 2]).max():.3g} m off the {side} contact face's plane "
                             f"(more than 5 % of its height {xi_r[1] - xi_r[0]:.3g} m)")
        on_face = centre + local[:, :1] * frame[0] + local[:, 1:2] * frame[1] - 1e-7 * frame[2]
        return face.displacements_at(on_face)

    def rigid_platform_blade(self) -> ModalBlade:
        """This blade as a plain :class:`~bladedamp.blade.ModalBlade` (same frequencies, damping,
        named points and shapes): rigid platforms at the OL / OR control points in the contact
        kinematics (the beam model's, Eq. 6)."""
        return ModalBlade(natural_frequencies_hz=self.natural_frequencies_hz, damping_ratios=self.damping_ratios,
                          mode_shapes=dict(self.mode_shapes), points=dict(self.points), mode_names=self.mode_names)

    # -- files -----------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write this blade to ``path``, an ``.npz`` file of format :data:`SOLID_NPZ_FORMAT`
        (:meth:`npz_arrays`; read back by :meth:`~bladedamp.blade.ModalBlade.from_file` as a
        SolidModalBlade with the same flexible platforms and surface). Returns the path.
        ValueError for ``.csv``: the CSV modal format holds the 6-DOF shapes at named points only
        (a blade read from it would have rigid platforms and give another FRF)."""
        path = Path(path)
        if path.suffix.lower() == ".csv":
            raise ValueError(f"{path}: a solid FE blade cannot be saved as .csv (the CSV modal format holds "
                             "the shapes at named points only: its platforms would be rigid when read back); "
                             "save it as .npz, or save blade.rigid_platform_blade() to .csv for the rigid-platform "
                             "blade")
        return super().save(path)

    def npz_arrays(self) -> dict:
        """The arrays of this blade's ``.npz`` file by key: the ModalBlade's
        (:meth:`bladedamp.blade.ModalBlade.npz_arrays`, with ``format`` = :data:`SOLID_NPZ_FORMAT`)
        and, under ``solid/``: ``mode_indices`` (n_m,), ``info`` (``solid_info`` as JSON, typed by
        :func:`bladedamp.io.encode_value`: arrays keep their dtype, tuples stay tuples),
        ``fit_residual_names`` (k,) and ``fit_residuals`` (k, n_m), and the fields of
        ``face_fields["OL" / "OR"]`` (:class:`ContactFaceField`), ``contact_faces["OL" / "OR"]``
        (:class:`ContactFaceModes`) and ``surface`` (:class:`BladeSurface`) as
        ``solid/face_fields/OL/nodes``, ..., ``solid/surface/vertices``, ... (SI units). ``modes``
        is not written (the whole FE model; the disks need only the face fields)."""
        out = super().npz_arrays()
        out["format"] = np.array(SOLID_NPZ_FORMAT)
        names = list(self.fit_residuals)
        out.update({"solid/mode_indices": np.array(self.mode_indices, dtype=np.int64),
                    "solid/info": np.array(json.dumps(encode_value(dict(self.solid_info), "solid_info"))),
                    "solid/fit_residual_names": np.array(names, dtype=str),
                    "solid/fit_residuals": np.array([self.fit_residuals[n] for n in names], dtype=float)
                    .reshape(len(names), self.n_modes)})
        parts = [(f"solid/{group}/{side}", obj) for group in ("face_fields", "contact_faces")
                 for side, obj in getattr(self, group).items()]
        parts += [("solid/surface", self.surface)] if self.surface is not None else []
        for prefix, obj in parts:
            out.update({f"{prefix}/{f.name}": np.asarray(getattr(obj, f.name)) for f in dataclasses.fields(obj)
                        if f.name != "side"})
        return out

    @classmethod
    def from_npz(cls, path, data) -> "SolidModalBlade":
        """The blade of the open ``.npz`` file ``data`` of a solid FE blade (format
        :data:`SOLID_NPZ_FORMAT` or its /1; ``path`` for the messages): the reader of
        :func:`bladedamp.io.load_npz` for this class (use :meth:`~bladedamp.blade.modal.ModalBlade.from_file`
        or :func:`bladedamp.load`)."""
        fields, _, arrays = modal_npz_fields(path, data, SOLID_NPZ_FORMAT)
        return cls.from_npz_arrays(path, fields, arrays)

    @classmethod
    def from_npz_arrays(cls, path, fields: dict, arrays: dict) -> "SolidModalBlade":
        """The blade of a :data:`SOLID_NPZ_FORMAT` file ``path`` (for the messages) from its
        ModalBlade ``fields`` and its other ``arrays`` (:func:`bladedamp.blade.modal.modal_npz_fields`);
        ValueError naming the file and the key for a missing or malformed entry."""
        def get(key):
            if key not in arrays:
                raise ValueError(f"{path}: key {key!r} missing (a {SOLID_NPZ_FORMAT} file needs it)")
            return arrays[key]

        def build(what, kind, **values):
            try:
                return kind(**values)
            except (ValueError, TypeError, IndexError) as err:
                raise ValueError(f"{path}: {what}: {err}") from None

        def part(kind, prefix, **side):
            values = {f.name: get(f"{prefix}/{f.name}") for f in dataclasses.fields(kind) if f.name != "side"}
            for n, v in values.items():
                if v.dtype.kind not in "iuf":
                    raise ValueError(f"{path}: key '{prefix}/{n}' must hold numbers (got dtype {v.dtype})")
            return build(f"keys '{prefix}/...'", kind, **side, **{n: float(v) if v.ndim == 0 else v
                                                                 for n, v in values.items()})

        try:
            info = json.loads(str(get("solid/info")))
        except json.JSONDecodeError as err:
            raise ValueError(f"{path}: key 'solid/info' must be JSON ({err})") from None
        if not isinstance(info, dict):
            raise ValueError(f"{path}: key 'solid/info' must be a JSON object (got {type(info).__name__})")
        # Format /2 (bladedamp.blade.SOLID_NPZ_FORMAT) writes the typed form of
        # bladedamp.io.encode_value, an object with the one key "__dict__"; a /1 file (plain JSON,
        # commit 402db23) has solid_blade's keys and goes through the old reading.
        if "__dict__" in info:
            try:
                info = decode_value(info)
            except (ValueError, TypeError, KeyError) as err:
                raise ValueError(f"{path}: key 'solid/info': {err}") from None
        else:
            info = _legacy_solid_info(info)
        sides = {g: sorted({k.split("/")[2] for k in arrays if k.startswith(f"solid/{g}/")})
                 for g in ("face_fields", "contact_faces")}
        names = [str(n) for n in get("solid/fit_residual_names")]
        residuals = get("solid/fit_residuals")
        if residuals.dtype.kind not in "iuf" or residuals.shape != (len(names), fields["natural_frequencies_hz"].size):
            raise ValueError(f"{path}: key 'solid/fit_residuals' must be ({len(names)}, n_modes) numbers (got "
                             f"{residuals.shape} {residuals.dtype})")
        return build("the solid blade", cls, **fields, solid_info=info,
                     mode_indices=tuple(int(i) for i in get("solid/mode_indices")),
                     fit_residuals=dict(zip(names, residuals.astype(float))),
                     face_fields={s: part(ContactFaceField, f"solid/face_fields/{s}", side=s)
                                  for s in sides["face_fields"]},
                     contact_faces={s: part(ContactFaceModes, f"solid/contact_faces/{s}", side=s)
                                    for s in sides["contact_faces"]},
                     surface=part(BladeSurface, "solid/surface") if "solid/surface/vertices" in arrays else None)


def _legacy_solid_info(info: dict) -> dict:
    """``solid_info`` of a file written before it was stored typed (plain JSON: arrays and tuples as
    lists, numpy scalars as numbers), as :func:`solid_blade` made it: a list of numbers becomes a
    float array, any other list a tuple; numbers, strings and objects (``seconds``) stay."""
    return {k: (np.array(v, dtype=float) if isinstance(v, list) and all(isinstance(x, (int, float)) for x in v)
                else tuple(v) if isinstance(v, list) else v) for k, v in info.items()}


def solid_blade(geometry: SolidBladeGeometry | BeamBladeGeometry | None = None,
                element_size: float | None = None, n_modes: int = 4, *,
                natural_frequencies_hz=None, damping_ratios=0.001, mode_names=None,
                face_samples=DEFAULT_FACE_SAMPLES, search_modes: int | None = None,
                symmetric: bool = True, modes: SolidModes | None = None, rotor_speed_hz: float = 0.0,
                hub_radius: float = 0.0) -> SolidModalBlade:
    """The solid blade as a ModalBlade (:meth:`bladedamp.blade.ModalBlade.from_solid`).

    n_modes = 4 returns the paper's modes in the order ("1F", "2F", "1T", "1E") (named by the
    tip motion); any other n_modes the lowest n_modes. ``natural_frequencies_hz`` replaces the
    FE frequencies (as ``from_beam``), ``damping_ratios`` scalar or (n_modes,) [-],
    ``mode_names`` overrides the names, ``face_samples`` (n_xi, n_eta) is the raw contact-face
    grid, ``search_modes`` how many modes are computed before picking (default
    max(10, n_modes + 4)), ``symmetric`` the mirrored mesh (:func:`mesh_blade`), ``modes`` an
    existing :func:`solid_modes` result to use (then geometry and element_size are ignored),
    ``rotor_speed_hz`` [Hz] and ``hub_radius`` [m] the spinning blade's centrifugal prestress
    (:func:`solid_modes`; 0: the blade at rest).
    The points are the beam geometry's (OL, OR, platform, tip, excitation), each with its
    rigid-fit 6-DOF shape (module docstring).
    """
    n_modes = check.integer("n_modes", n_modes, minimum=1)
    if modes is None:
        search = max(DEFAULT_SEARCH_MODES, n_modes + 4) if search_modes is None else search_modes
        size = DEFAULT_ELEMENT_SIZE if element_size is None else element_size
        modes = solid_modes(geometry, size, search, symmetric=symmetric, rotor_speed_hz=rotor_speed_hz,
                            hub_radius=hub_radius)
    if not modes.geometry.platform:
        raise ValueError("a ModalBlade needs the platform (its OL / OR contact faces); "
                         "the geometry has platform=False")
    if n_modes == 4:
        missing = [n for n in PAPER_MODE_ORDER if n not in modes.mode_names]
        if missing:
            raise ValueError(f"the solid's lowest {len(modes.mode_names)} modes {modes.mode_names} have no "
                             f"{missing}; raise search_modes")
        idx = [modes.mode_names.index(n) for n in PAPER_MODE_ORDER]
    else:
        if n_modes > modes.frequencies_hz.size:
            raise ValueError(f"n_modes must be at most the {modes.frequencies_hz.size} computed modes "
                             f"(got {n_modes}); raise search_modes")
        idx = list(range(n_modes))
    names = tuple(modes.mode_names[i] for i in idx) if mode_names is None else tuple(mode_names)
    if natural_frequencies_hz is None:
        freqs = modes.frequencies_hz[idx]
    else:
        freqs = np.asarray(natural_frequencies_hz, dtype=float)
        if freqs.shape != (n_modes,):
            raise ValueError(f"natural_frequencies_hz must have n_modes = {n_modes} entries "
                             f"(got shape {freqs.shape})")
    points = modes.geometry.points()
    shapes, residuals = modes.point_shapes(points)
    faces = {side: modes.contact_face(side, face_samples).select(idx) for side in ("OL", "OR")}
    info = {"n_dofs": modes.n_dofs, "n_free": modes.n_free, "n_elements": int(modes.mesh.tets.shape[1]),
            "element_size": modes.mesh.element_size, "mass": modes.mass,
            "frequencies_hz": modes.frequencies_hz.copy(), "mode_names": modes.mode_names,
            "rotor_speed_hz": modes.rotor_speed_hz, "hub_radius": modes.hub_radius,
            "seconds": dict(modes.seconds)}
    return SolidModalBlade(natural_frequencies_hz=freqs, damping_ratios=damping_ratios,
                           mode_shapes={p: s[:, idx] for p, s in shapes.items()}, points=points,
                           mode_names=names, contact_faces=faces,
                           fit_residuals={p: r[idx] for p, r in residuals.items()}, solid_info=info,
                           modes=modes, mode_indices=tuple(idx), surface=BladeSurface.from_modes(modes, idx))
