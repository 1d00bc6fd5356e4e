"""Triangle meshes (trimesh) of the blade, the dampers and the disk, and contact patches derived from them.

Frames as everywhere in bladedamp (see :mod:`bladedamp.blade`, :mod:`bladedamp.damper.geometry`):
blade frame x circumferential, y axial, z radial (root at z = 0); a damper sits between blade i
(its platform point OL, at +x of the damper) and blade i + 1 (point OR, at -x). The *sector* is
laid out "unrolled" exactly as the contact model assumes it (:meth:`TunedDisk.platform_offsets`):
blade i + 1 is blade i translated by ``-pitch`` along x. The whole disk (:func:`disk_placements`)
wraps the blades around the rotor axis for pictures only.

Meshes
------
:func:`blade_mesh` builds the blade of a :class:`~bladedamp.blade.BeamBladeGeometry`: a root block
below z = 0, the shank and the airfoil (split into span segments so a viewer can move them
rigidly with the beam's deflection), and the platform, whose undersides are planes through the
contact centres inclined by gamma_L (OL side, -x) and gamma_R (OR side, +x).
:func:`cylinder_mesh` and :func:`wedge_mesh` build the dampers about their centre of gravity.

Contact patches from the meshes
-------------------------------
:func:`derive_patch` casts lines along the contact normal zeta through a grid on the plane
(xi, eta) at the contact centre and measures, along each line, the gap from the platform surface
(last crossing out of the platform) to the damper surface (first crossing into the damper). The
contact region is where gap <= ``tolerance``; its bounding rectangle (edges refined by bisection)
is sampled into the grid the contact model uses (cell midpoints, n_xi x n_eta, as
:class:`~bladedamp.contact.patch.ContactPatch`), with each point's initial gap and the platform's
surface normal there. Only numpy and trimesh are used (the line/triangle test is a vectorised
Moller-Trumbore, no rtree or embree).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh

from .blade import PLATFORM_ANGLE, BeamBladeGeometry, platform_section, reference_blade_geometry
from .damper.geometry import CylinderDamper, DamperGeometry, WedgeDamper

__all__ = ["prism", "BladeMesh", "blade_mesh", "cylinder_mesh", "wedge_mesh", "damper_mesh", "SectorLayout",
           "sector_layout", "sector_meshes", "DerivedPatch", "surface_gaps", "derive_patch", "derive_patches",
           "seat_damper_mesh", "disk_placements", "rotation_y", "homogeneous"]


# --------------------------------------------------------------------------------------
# primitives
# --------------------------------------------------------------------------------------
def prism(section_xz, y0: float, y1: float) -> trimesh.Trimesh:
    """Closed prism of a convex polygon ``section_xz`` (k, 2) in the (x, z) plane, from y0 to y1.

    Outward-facing triangles (positive volume), caps fan-triangulated.
    """
    poly = np.asarray(section_xz, dtype=float)
    # drop repeated consecutive points
    keep = np.r_[True, np.linalg.norm(np.diff(poly, axis=0), axis=1) > 1e-12]
    poly = poly[keep]
    if np.linalg.norm(poly[0] - poly[-1]) <= 1e-12:
        poly = poly[:-1]
    k = len(poly)
    if k < 3:
        raise ValueError("section_xz needs at least 3 distinct points")
    v0 = np.column_stack([poly[:, 0], np.full(k, y0), poly[:, 1]])
    v1 = np.column_stack([poly[:, 0], np.full(k, y1), poly[:, 1]])
    vertices = np.vstack([v0, v1])
    faces = []
    for i in range(1, k - 1):
        faces.append([0, i + 1, i])
        faces.append([k, k + i, k + i + 1])
    for i in range(k):
        j = (i + 1) % k
        faces.append([i, j, k + j])
        faces.append([i, k + j, k + i])
    mesh = trimesh.Trimesh(vertices, np.array(faces), process=False)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def rotation_y(angle: float) -> np.ndarray:
    """3x3 rotation about +y by ``angle`` [rad] (x' = x cos + z sin, z' = -x sin + z cos)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def homogeneous(rotation=np.eye(3), translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(4, 4) homogeneous transform x -> rotation @ x + translation (rotation (3, 3), translation (3,) [m])."""
    T = np.eye(4)
    T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


# --------------------------------------------------------------------------------------
# sector layout (same arithmetic as TunedDisk.platform_offsets)
# --------------------------------------------------------------------------------------
@dataclass
class SectorLayout:
    """Where the damper and the neighbour blade sit in blade i's frame (unrolled sector).

    pitch : blade i + 1 is blade i translated by -pitch along x [m]
    damper_cg : (3,) damper centre of gravity [m]
    contact_centres : (2, 3) OL centre (on blade i) and OR centre (on blade i + 1), blade i frame [m]
    platform_offsets : (2, 3) contact centres seen from OL (blade i) and OR (blade i + 1), each in
        its own blade's frame (= TunedDisk.platform_offsets)
    frames : (2, 3, 3) rows (xi, eta, zeta) of the OL and OR contacts
    geometry : DamperGeometry
    """

    pitch: float
    damper_cg: np.ndarray
    contact_centres: np.ndarray
    platform_offsets: np.ndarray
    frames: np.ndarray
    geometry: DamperGeometry

    def own_contact_centres(self, points) -> np.ndarray:
        """(2, 3) contact centres on one blade in its own frame: its OL face centre and its OR face centre."""
        return np.array([points["OL"] + self.platform_offsets[0], points["OR"] + self.platform_offsets[1]])

    def contact_points(self) -> np.ndarray:
        """(2, P, 3) positions of the point contacts of the OL and OR patches in blade i's frame [m]:
        the contact centre plus xi e_xi + eta e_eta of every point (the patch's own coordinates,
        e_xi and e_eta the rows of its contact frame); subtract ``damper_cg`` for the damper's
        frame, add (pitch, 0, 0) to the OR points for blade i + 1's own frame."""
        return np.array([c + np.outer(p.xi, R[0]) + np.outer(p.eta, R[1])
                         for c, R, p in zip(self.contact_centres, self.frames, self.geometry.patches)])


def sector_layout(points, damper, gamma_left: float, gamma_right: float) -> SectorLayout:
    """Layout of the unrolled sector from the blade's named points (OL, OR) and the damper."""
    geometry = damper.geometry(gamma_left, gamma_right)
    p_ol, p_or = np.asarray(points["OL"], float), np.asarray(points["OR"], float)
    cg = p_ol - geometry.centres[0]
    or_centre = cg + geometry.centres[1]
    pitch = p_or[0] - or_centre[0]
    mismatch = or_centre + np.array([pitch, 0.0, 0.0]) - p_or
    half = np.array([0.0, 0.0, mismatch[2] / 2])
    offsets = np.array([-half, mismatch - half])
    cg = cg - half
    centres = np.array([cg + geometry.centres[0], cg + geometry.centres[1]])
    return SectorLayout(float(pitch), cg, centres, offsets, geometry.frames.copy(), geometry)


# --------------------------------------------------------------------------------------
# blade
# --------------------------------------------------------------------------------------
@dataclass
class BladeMesh:
    """Parts of one blade in its own frame.

    root, platform : trimesh.Trimesh (rigid: root fixed, platform moves with the platform node)
    segments : list of (trimesh.Trimesh, z_mid) span segments of shank and airfoil, root to tip
    platform_node_z : z of the platform node [m]
    """

    root: trimesh.Trimesh
    platform: trimesh.Trimesh
    segments: list
    platform_node_z: float
    total_length: float

    def combined(self) -> trimesh.Trimesh:
        """All parts in one mesh."""
        return trimesh.util.concatenate([self.root, self.platform] + [m for m, _ in self.segments])


def _airfoil_section(thickness: float, chord: float, n: int) -> np.ndarray:
    """Symmetric lens profile (x thickness, y chord) with the beam's thickness and chord, (n, 2) in (x, y)."""
    s = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    y = 0.5 * chord * np.cos(s)
    x = 0.5 * thickness * np.sin(s) * (1.0 - 0.15 * np.cos(s))   # slightly thicker toward the leading edge
    return np.column_stack([x, y])


def _prism_z(section_xy, z0: float, z1: float) -> trimesh.Trimesh:
    """Prism of a convex (x, y) polygon from z0 to z1 (built along y, then rotated y -> z)."""
    poly = np.asarray(section_xy, dtype=float)
    mesh = prism(poly, z0, z1)   # (x, z) -> poly, extruded along y
    v = mesh.vertices.copy()
    mesh = trimesh.Trimesh(np.column_stack([v[:, 0], v[:, 2], v[:, 1]]), mesh.faces[:, ::-1], process=False)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def blade_mesh(geometry: BeamBladeGeometry | None = None, gamma_left: float = PLATFORM_ANGLE,
               gamma_right: float = PLATFORM_ANGLE, contact_centres=None, *, platform_edge: float | None = None,
               platform_length: float | None = None, face_inner_length: float = 2.5e-3, root_height: float = 10e-3,
               profile_points: int = 16) -> BladeMesh:
    """Blade of ``geometry`` (default: :func:`~bladedamp.blade.reference_blade_geometry`) in its own frame.

    Parameters
    ----------
    gamma_left, gamma_right : platform angles at OL and OR [rad]
    contact_centres : (2, 3) points the platform undersides pass through (OL face, OR face);
        default the OL and OR points (:meth:`SectorLayout.own_contact_centres` gives the ones of a disk)
    platform_edge : |x| of the platform edges [m] (default 1.25 x platform_half_width: 15 mm for
        the reference blade, whose platform plate is 30 mm wide)
    platform_length : axial (y) length of the platform [m] (default 1.1 x airfoil chord: 50 mm)
    face_inner_length : how far each inclined underside continues past the contact centre toward
        the blade axis [m]
    root_height : height of the root block below z = 0 [m]
    profile_points : points of the airfoil profile (a lens with the beam's thickness and chord)

    The beam model's sections are rectangles; the airfoil gets a lens profile of the same
    thickness and chord for the picture (the shank stays rectangular).
    """
    g = reference_blade_geometry() if geometry is None else geometry
    pts = g.points()
    centres = np.array([pts["OL"], pts["OR"]]) if contact_centres is None else np.asarray(contact_centres, float)
    edge = 1.25 * g.platform_half_width if platform_edge is None else float(platform_edge)
    length = 1.1 * max(g.airfoil_chord_y, g.shank_chord_y) if platform_length is None else float(platform_length)
    z_p = g.shank_length
    top = z_p + max(g.platform_contact_z_offset, 1e-3)
    section = platform_section(centres, gamma_left, gamma_right, edge, top, face_inner_length, 0.3e-3)
    platform = prism(section, -length / 2, length / 2)

    tx, cy = g.shank_thickness_x, g.shank_chord_y
    root_section = np.array([[-0.8 * tx, -root_height], [0.8 * tx, -root_height], [0.5 * tx, 0.0], [-0.5 * tx, 0.0]])
    root_section[:, 0] *= 1.6
    root = prism(root_section, -cy / 2, cy / 2)

    segments = []
    shank_rect = np.array([[-tx / 2, -cy / 2], [tx / 2, -cy / 2], [tx / 2, cy / 2], [-tx / 2, cy / 2]])
    z_shank = np.linspace(0.0, z_p, g.n_elements_shank + 1)
    for a, b in zip(z_shank[:-1], z_shank[1:]):
        segments.append((_prism_z(shank_rect, a, b), 0.5 * (a + b)))
    airfoil = _airfoil_section(g.airfoil_thickness_x, g.airfoil_chord_y, profile_points)
    z_air = np.linspace(z_p, g.total_length, g.n_elements_airfoil + 1)
    for a, b in zip(z_air[:-1], z_air[1:]):
        segments.append((_prism_z(airfoil, a, b), 0.5 * (a + b)))
    return BladeMesh(root, platform, segments, z_p, g.total_length)


# --------------------------------------------------------------------------------------
# dampers (about their centre of gravity, axis along y)
# --------------------------------------------------------------------------------------
def cylinder_mesh(damper: CylinderDamper, segments: int = 96, contact_directions=None) -> trimesh.Trimesh:
    """Cylinder of ``damper.radius`` and ``damper.length`` along y, centred on its CG.

    ``contact_directions``: (k, 3) directions (from the axis) at which the section polygon gets a
    vertex, so that the faceted surface touches a tangent plane there along a line (default none).
    """
    angles = list(np.linspace(0.0, 2 * np.pi, segments, endpoint=False))
    if contact_directions is not None:
        for d in np.atleast_2d(contact_directions):
            a = np.arctan2(d[2], d[0]) % (2 * np.pi)
            angles = [x for x in angles if abs((x - a + np.pi) % (2 * np.pi) - np.pi) > 0.3 * 2 * np.pi / segments]
            angles.append(a)
    angles = np.sort(np.array(angles))
    section = damper.radius * np.column_stack([np.cos(angles), np.sin(angles)])
    return prism(section, -damper.length / 2, damper.length / 2)


def wedge_mesh(damper: WedgeDamper, gamma_left: float, gamma_right: float) -> trimesh.Trimesh:
    """Wedge (triangular prism of ``damper.geometry(...).section``) along y, centred on its CG."""
    section = damper.geometry(gamma_left, gamma_right).section
    return prism(section, -damper.length / 2, damper.length / 2)


def damper_mesh(damper, gamma_left: float, gamma_right: float, **options) -> trimesh.Trimesh:
    """Mesh of a CylinderDamper (line-contact vertices at both contact directions) or a WedgeDamper."""
    if isinstance(damper, CylinderDamper):
        geometry = damper.geometry(gamma_left, gamma_right)
        options.setdefault("contact_directions", geometry.centres)
        return cylinder_mesh(damper, **options)
    if isinstance(damper, WedgeDamper):
        return wedge_mesh(damper, gamma_left, gamma_right)
    raise ValueError(f"damper must be a CylinderDamper or WedgeDamper (got {type(damper).__name__})")


def sector_meshes(blade_geometry: BeamBladeGeometry | None, damper, gamma_left: float, gamma_right: float,
                  **blade_options) -> dict:
    """Unrolled sector in blade i's frame: "blade" (i), "neighbour" (i + 1, at -pitch), "damper" (at its
    CG), plus "layout" (:class:`SectorLayout`) and "blade_mesh" (:class:`BladeMesh` of one blade)."""
    g = reference_blade_geometry() if blade_geometry is None else blade_geometry
    layout = sector_layout(g.points(), damper, gamma_left, gamma_right)
    blade = blade_mesh(g, gamma_left, gamma_right, layout.own_contact_centres(g.points()), **blade_options)
    whole = blade.combined()
    neighbour = whole.copy()
    neighbour.apply_translation([-layout.pitch, 0.0, 0.0])
    platform_next = blade.platform.copy()
    platform_next.apply_translation([-layout.pitch, 0.0, 0.0])
    dmesh = damper_mesh(damper, gamma_left, gamma_right)
    dmesh.apply_translation(layout.damper_cg)
    return {"blade": whole, "neighbour": neighbour, "damper": dmesh, "platform_ol": blade.platform.copy(),
            "platform_or": platform_next, "layout": layout, "blade_mesh": blade}


# --------------------------------------------------------------------------------------
# line / mesh crossings and gaps
# --------------------------------------------------------------------------------------
def _line_crossings(origins: np.ndarray, direction: np.ndarray, mesh: trimesh.Trimesh, facing: float,
                    min_cos: float = 1e-9, chunk: int = 2048, edge_tol: float = 1e-9):
    """For lines o + t d: parameters t of crossings with triangles whose normal n has facing * (n . d) > min_cos.

    Returns (t (R, F) with NaN where no crossing, triangle normals (F, 3)).
    """
    tri = mesh.triangles
    normals = mesh.face_normals
    sel = np.flatnonzero(facing * (normals @ direction) > min_cos)
    tri, normals = tri[sel], normals[sel]
    v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(direction, e2)                       # (F, 3)
    det = np.einsum("fi,fi->f", e1, p)
    inv = 1.0 / det
    out = np.full((len(origins), len(sel)), np.nan)
    for a in range(0, len(origins), chunk):
        o = origins[a:a + chunk]
        s = o[:, None, :] - v0[None]                  # (r, F, 3)
        u = np.einsum("rfi,fi->rf", s, p) * inv
        q = np.cross(s, e1[None])
        v = (q @ direction) * inv
        t = np.einsum("rfi,fi->rf", q, e2) * inv
        hit = (u >= -edge_tol) & (v >= -edge_tol) & (u + v <= 1 + edge_tol)
        out[a:a + chunk] = np.where(hit, t, np.nan)
    return out, normals


def surface_gaps(damper: trimesh.Trimesh, platform: trimesh.Trimesh, frame, origin, xi, eta,
                 max_angle: float = np.radians(45.0)):
    """Gap [m] along zeta from the platform surface to the damper surface at points (xi, eta).

    frame : (3, 3) rows (xi, eta, zeta), zeta the normal from the platform into the damper
    origin : (3,) contact centre (the plane xi, eta passes through it)

    Returns (gap (P,), platform normal (P, 3)): gap = t_damper - t_platform with t_platform the last
    crossing out of the platform (faces with n . zeta > 0) and t_damper the first crossing into the
    damper along +zeta, through damper faces that face the platform (outward normal within
    ``max_angle`` of -zeta; so a wedge's other face near the apex does not count); NaN where a line
    misses either surface.
    """
    frame = np.asarray(frame, float)
    xi, eta = np.atleast_1d(np.asarray(xi, float)), np.atleast_1d(np.asarray(eta, float))
    zeta = frame[2]
    origins = np.asarray(origin, float)[None] + xi[:, None] * frame[0] + eta[:, None] * frame[1]
    tp, n_p = _line_crossings(origins, zeta, platform, +1.0)
    td, _ = _line_crossings(origins, zeta, damper, -1.0, np.cos(max_angle))
    with np.errstate(invalid="ignore"):
        has_p = np.any(np.isfinite(tp), axis=1)
        has_d = np.any(np.isfinite(td), axis=1)
        t_platform = np.where(has_p, np.nanmax(np.where(np.isfinite(tp), tp, -np.inf), axis=1), np.nan)
        t_damper = np.where(has_d, np.nanmin(np.where(np.isfinite(td), td, np.inf), axis=1), np.nan)
    idx = np.argmax(np.where(np.isfinite(tp), tp, -np.inf), axis=1)
    normals = np.where(has_p[:, None], n_p[idx] if len(n_p) else np.nan, np.nan)
    return t_damper - t_platform, normals


@dataclass
class DerivedPatch:
    """Contact patch derived from the meshes.

    xi, eta : (P,) point coordinates in the contact frame, relative to ``origin`` [m] (ordered
        like ContactPatch: xi-major, i.e. index = i_xi * n_eta + i_eta)
    gap : (P,) initial gap platform -> damper along zeta at each point [m] (0: touching)
    normal : (P, 3) unit normal of the platform surface at each point (blade frame)
    frame : (3, 3) rows (xi, eta, zeta); origin : (3,) contact centre [m]
    xi_range, eta_range : bounds of the contact region (gap <= tolerance) [m]
    n_xi, n_eta : grid; tolerance : gap tolerance [m]
    scan : dict of the scan grid ("xi", "eta", "gap" 2-D arrays)
    """

    xi: np.ndarray
    eta: np.ndarray
    gap: np.ndarray
    normal: np.ndarray
    frame: np.ndarray
    origin: np.ndarray
    xi_range: tuple
    eta_range: tuple
    n_xi: int
    n_eta: int
    tolerance: float
    scan: dict = field(default_factory=dict, repr=False)

    @property
    def height(self) -> float:
        """Extent of the contact region along xi (h_C) [m]."""
        return float(self.xi_range[1] - self.xi_range[0])

    @property
    def length(self) -> float:
        """Extent of the contact region along eta (l_C) [m]."""
        return float(self.eta_range[1] - self.eta_range[0])

    @property
    def centre_offset(self) -> np.ndarray:
        """(xi, eta) of the region's centre relative to ``origin`` [m]."""
        return np.array([np.mean(self.xi_range), np.mean(self.eta_range)])

    def points(self) -> np.ndarray:
        """(P, 3) grid points on the contact plane (xi, eta) through ``origin`` (blade frame) [m] (the platform
        underside of :func:`blade_mesh` lies in this plane)."""
        return self.origin + self.xi[:, None] * self.frame[0] + self.eta[:, None] * self.frame[1]


def _bisect(inside, a_in: float, b_out: float, tol: float) -> float:
    """Boundary between a (inside) and b (outside) of a 1-D indicator."""
    for _ in range(200):
        if abs(b_out - a_in) <= tol:
            break
        m = 0.5 * (a_in + b_out)
        if inside(m):
            a_in = m
        else:
            b_out = m
    return a_in


def derive_patch(damper: trimesh.Trimesh, platform: trimesh.Trimesh, frame, origin, tolerance: float = 1e-6,
                 n_xi: int = 5, n_eta: int = 5, scan_points: tuple = (161, 81), refine_tol: float = 1e-10) -> DerivedPatch:
    """Contact patch where the damper surface lies within ``tolerance`` of the platform surface.

    Parameters
    ----------
    damper, platform : placed meshes (same frame)
    frame : (3, 3) rows (xi, eta, zeta) of the contact, zeta from the platform into the damper
    origin : (3,) contact centre (the grid's reference point)
    tolerance : gap tolerance [m]: points with gap <= tolerance form the contact region
    n_xi, n_eta : points of the sampled grid (cell midpoints of the region's bounding rectangle;
        n_xi = 1 gives one row, the line contact of a cylinder)
    scan_points : (n, m) scan resolution over the damper's footprint before the edges are refined
    refine_tol : bisection tolerance of the region's edges [m]

    Raises ValueError if no point of the damper is within ``tolerance`` of the platform.
    """
    frame = np.asarray(frame, float)
    origin = np.asarray(origin, float)
    rel = damper.vertices - origin
    fx, fe = rel @ frame[0], rel @ frame[1]
    pad = 1e-9
    xs = np.linspace(fx.min() - pad, fx.max() + pad, scan_points[0])
    es = np.linspace(fe.min() - pad, fe.max() + pad, scan_points[1])
    X, E = np.meshgrid(xs, es, indexing="ij")
    gap, _ = surface_gaps(damper, platform, frame, origin, X.ravel(), E.ravel())
    gap = gap.reshape(X.shape)
    with np.errstate(invalid="ignore"):
        region = np.isfinite(gap) & (gap <= tolerance)
    if not region.any():
        finite = gap[np.isfinite(gap)]
        closest = finite.min() if finite.size else np.nan
        raise ValueError(f"no contact within tolerance {tolerance:g} m (smallest gap {closest:g} m)")

    def inside(x, e):
        g, _ = surface_gaps(damper, platform, frame, origin, [x], [e])
        return bool(np.isfinite(g[0]) and g[0] <= tolerance)

    ii, jj = np.nonzero(region)
    bounds = []
    # xi edges: at the row (eta) of the extreme scan point, bisect toward the next scan point outside
    for pick, step in ((np.argmin(ii), -1), (np.argmax(ii), +1)):
        i, j = ii[pick], jj[pick]
        out = xs[i + step] if 0 <= i + step < len(xs) else xs[i] + step * (xs[1] - xs[0])
        bounds.append(_bisect(lambda x: inside(x, es[j]), xs[i], out, refine_tol))
    for pick, step in ((np.argmin(jj), -1), (np.argmax(jj), +1)):
        i, j = ii[pick], jj[pick]
        out = es[j + step] if 0 <= j + step < len(es) else es[j] + step * (es[1] - es[0])
        bounds.append(_bisect(lambda e: inside(xs[i], e), es[j], out, refine_tol))
    x0, x1, e0, e1 = bounds
    cx = (np.arange(n_xi) + 0.5) / n_xi
    ce = (np.arange(n_eta) + 0.5) / n_eta
    PX, PE = np.meshgrid(x0 + cx * (x1 - x0), e0 + ce * (e1 - e0), indexing="ij")
    g, normals = surface_gaps(damper, platform, frame, origin, PX.ravel(), PE.ravel())
    return DerivedPatch(PX.ravel(), PE.ravel(), g, normals, frame, origin, (x0, x1), (e0, e1), int(n_xi), int(n_eta),
                        float(tolerance), {"xi": X, "eta": E, "gap": gap})


def seat_damper_mesh(damper: trimesh.Trimesh, frames, origins, max_angle: float = np.radians(45.0)) -> np.ndarray:
    """Translation (3,) in the x-z plane that brings a rigid damper mesh into contact with both
    platform planes (through ``origins`` with normals zeta = ``frames[c, 2]``): smallest gap 0 on each
    side, no penetration. The rigid "drop" of a damper whose faces need not fit the platforms (e.g. a
    wedge with a wrong angle). Exact for planar platform faces: the gap of a damper vertex on a face
    facing platform c (outward normal within ``max_angle`` of -zeta_c) is zeta_c . (v - origin_c)."""
    frames = np.asarray(frames, float)
    mins = []
    for frame, origin in zip(frames, origins):
        facing = damper.face_normals @ frame[2] < -np.cos(max_angle)
        v = damper.vertices[np.unique(damper.faces[facing])]
        mins.append(np.min((v - np.asarray(origin, float)) @ frame[2]))
    A = np.array([[frames[c, 2, 0], frames[c, 2, 2]] for c in range(2)])
    dx, dz = np.linalg.solve(A, -np.array(mins))
    return np.array([dx, 0.0, dz])


def derive_patches(disk=None, *, blade_geometry: BeamBladeGeometry | None = None, damper=None,
                   gamma_left: float | None = None, gamma_right: float | None = None,
                   damper_shape: trimesh.Trimesh | None = None, tolerance: float = 1e-6, n_xi: int | None = None,
                   n_eta: int | None = None, seat: bool = False) -> tuple[DerivedPatch, DerivedPatch]:
    """Patches (OL, OR) of a sector derived from its meshes.

    ``disk`` (a TunedDisk) gives the damper and the platform angles; or give ``damper``,
    ``gamma_left``, ``gamma_right``. ``blade_geometry`` defaults to the reference blade (the
    ModalBlade of a disk carries no shape). ``damper_shape``: a damper mesh about its CG to use
    instead of the nominal one (e.g. a wedge whose angle does not fit); with ``seat=True`` it is
    first dropped rigidly into contact (:func:`seat_damper_mesh`). Grid: the damper's contact model
    (cylinder: 1 x points_along_length, wedge: points_across_height x points_along_length) unless
    n_xi / n_eta are given.
    """
    if disk is not None:
        damper = disk.damper if damper is None else damper
        gamma_left = disk.gamma_left if gamma_left is None else gamma_left
        gamma_right = disk.gamma_right if gamma_right is None else gamma_right
    if damper is None or gamma_left is None or gamma_right is None:
        raise ValueError("give a disk, or damper, gamma_left and gamma_right")
    parts = sector_meshes(blade_geometry, damper, gamma_left, gamma_right)
    layout = parts["layout"]
    mesh = parts["damper"]
    if damper_shape is not None:
        mesh = damper_shape.copy()
        mesh.apply_translation(layout.damper_cg)
    platforms = (parts["platform_ol"], parts["platform_or"])
    if seat:
        mesh.apply_translation(seat_damper_mesh(mesh, layout.frames, layout.contact_centres))
    if n_xi is None:
        n_xi = 1 if isinstance(damper, CylinderDamper) else damper.contact.points_across_height
    if n_eta is None:
        n_eta = damper.contact.points_along_length
    return tuple(derive_patch(mesh, platforms[c], layout.frames[c], layout.contact_centres[c], tolerance, n_xi, n_eta)
                 for c in range(2))


def misfit_gaps(disk, damper_shape: trimesh.Trimesh, blade_geometry: BeamBladeGeometry | None = None) -> np.ndarray:
    """Initial gaps (2, P) [m] of the contact model's points for a damper that does not fit.

    The damper mesh ``damper_shape`` (about its CG, e.g. a wedge with a wrong face angle) is
    dropped rigidly into the groove of ``disk`` (a TunedDisk), and the gap from each platform to
    the damper is measured at the points of the disk's own contact patches (their xi, eta grid
    on the nominal faces). Pass the result as ``TunedDisk(initial_gaps=...)``: the solver then
    seats the damper on the touching part of its faces only.
    """
    geometry = disk.damper.geometry(disk.gamma_left, disk.gamma_right)
    parts = sector_meshes(blade_geometry, disk.damper, disk.gamma_left, disk.gamma_right)
    layout = parts["layout"]
    mesh = damper_shape.copy()
    mesh.apply_translation(layout.damper_cg)
    mesh.apply_translation(seat_damper_mesh(mesh, layout.frames, layout.contact_centres))
    platforms = (parts["platform_ol"], parts["platform_or"])
    gaps = []
    for c, patch in enumerate(geometry.patches):
        gap, _ = surface_gaps(mesh, platforms[c], layout.frames[c], layout.contact_centres[c], patch.xi, patch.eta)
        if not np.all(np.isfinite(gap)):
            raise ValueError("damper_shape does not face the platform at every contact point "
                             "(the misfit is too large for the nominal patch)")
        gaps.append(gap)
    return np.array(gaps)


# --------------------------------------------------------------------------------------
# whole disk (pictures)
# --------------------------------------------------------------------------------------
def disk_placements(layout: SectorLayout, n_blades: int, blade_points, sectors=None, damper_radius: float | None = None):
    """Blade and damper placements of a wrapped disk (for pictures).

    The root radius R_root is chosen so that the chord between neighbouring blades at the damper's
    radius equals the unrolled pitch: rho = pitch / (2 sin(pi / n)) at the damper CG, R_root =
    rho - z_CG; or from ``damper_radius`` (distance of the damper CG to the axis) if given and
    larger than z_CG. The rotor axis is the y axis through (0, 0, -R_root) of blade 0's frame;
    blade k is blade 0 rotated by -2 pi k / n about it (blade k + 1 lies at -x of blade k).
    Dampers are rotated to the angle of their CG (about half-way between the blades) at its radius;
    the contact model itself uses the unrolled sector.

    Returns (blade transforms (m, 4, 4), damper transforms (m, 4, 4) of the damper CG frame,
    blade indices (m,), root radius [m]); ``sectors``: iterable of blade indices (default all).
    """
    n = int(n_blades)
    cg = layout.damper_cg
    rho = layout.pitch / (2 * np.sin(np.pi / n))
    if damper_radius is not None and damper_radius > cg[2]:
        rho = float(damper_radius)
    r_root = float(rho - cg[2])
    axis = np.array([0.0, 0.0, -r_root])
    beta = np.arctan2(cg[0], cg[2] + r_root)            # angle of the damper CG (negative: -x side)
    radius_cg = np.hypot(cg[0], cg[2] + r_root)
    idx = list(range(n) if sectors is None else sectors)
    blades, dampers = [], []
    for k in idx:
        R = rotation_y(-2 * np.pi * k / n)
        blades.append(homogeneous(R, axis - R @ axis))
        Rd = rotation_y(-2 * np.pi * k / n + beta)
        dampers.append(homogeneous(Rd, axis + Rd @ np.array([0.0, cg[1], radius_cg])))
    return np.array(blades), np.array(dampers), np.array(idx), r_root
