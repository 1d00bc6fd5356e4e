"""Design files: a TOML description of a blade, damper, disk, mistuning and analysis, read into
the models (``load_design``) and written as the commented reference design (``template``).

One table of :class:`Field` rows holds every key: its reference value, unit, allowed range and
the reason for the value. The validator and the template are both generated from it, so they
cannot disagree. Human units are used where they are clearer (g, mm, deg, Hz, rpm); the unit
is part of every key's name. Every key is optional: a missing key takes the reference value,
so a file holding only ``[damper]`` / ``mass_g = 2.0`` is the reference disk with a 2 g damper.
Unknown tables and keys are errors (a typo must not pass silently).

A blade of your own is modal data (``[blade] modal_file``), reduced FE matrices (``modal_file``
an ``.op4``, ``.pch``, ``.mtx``, ``.mat`` or ``.full`` file with ``[blade.fe]`` and the point tables
``[blade.fe.OL]``, ``[blade.fe.OR]``, ``[blade.fe.tip]``, ``[blade.fe.excitation]``, optionally
``[blade.fe.platform]``; :meth:`bladedamp.blade.ModalBlade.from_file`), measured modes (``modal_file`` a
UFF file, ``.uff``, ``.unv`` or ``.uf``, of dataset 55 or 2414 normal modes, with ``[blade.test]`` and the
node tables ``[blade.test.OL]``, ``[blade.test.OR]``, ``[blade.test.tip]``, ``[blade.test.excitation]``;
:meth:`bladedamp.blade.ModalBlade.from_test`) or a closed surface mesh meshed as a
solid FE blade (``[blade] model = "solid"``, ``surface_file``, ``surface_units`` and the named
regions ``[blade.regions.clamp]``, ``[blade.regions.OL]``, ``[blade.regions.OR]``, optionally
``[blade.regions.tip]``, each a plane or its own surface file; :class:`bladedamp.blade.solid.SurfaceBladeGeometry`);
its OL / OR faces then set the disk's platform angles.

Inside, everything is SI (m, kg, s, rad, N), as in the rest of the package.
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import textwrap
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .fe_formats import FE_SUFFIXES
from .io import FileReadError, reading
from .measurement import UFF_SUFFIXES


class DesignError(FileReadError):
    """A design file that cannot be read or has a bad field; the message is one line naming the
    file and what is wrong (the key, the value and the allowed range for a bad field)."""


class _Bad(Exception):
    """A value outside the allowed range (internal to the checks of this module)."""


# ---------------------------------------------------------------------------------------
# checks: each is called on a TOML value, returns it normalised or raises _Bad;
# ``allowed`` says in words what passes
# ---------------------------------------------------------------------------------------
def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


@dataclass(frozen=True)
class Number:
    low: float
    high: float
    closed: str = "both"          # which ends belong to the range: both, neither, left, right
    integer: bool = False

    def describe(self, unit: str = "", plural: bool = False) -> str:
        lb = "[" if self.closed in ("both", "left") else "("
        rb = "]" if self.closed in ("both", "right") else ")"
        what = ("integers" if plural else "an integer") if self.integer else ("numbers" if plural else "a number")
        return f"{what} in {lb}{_num(self.low)}, {_num(self.high)}{rb}{unit}"

    def __call__(self, v):
        if not _is_number(v) or (self.integer and not isinstance(v, int)):
            raise _Bad
        lo_ok = v >= self.low if self.closed in ("both", "left") else v > self.low
        hi_ok = v <= self.high if self.closed in ("both", "right") else v < self.high
        if not (lo_ok and hi_ok):
            raise _Bad
        return int(v) if self.integer else float(v)


@dataclass(frozen=True)
class Choice:
    options: tuple

    def describe(self, unit: str = "") -> str:
        names = [repr(o) for o in self.options]
        return names[0] if len(names) == 1 else "one of " + ", ".join(names)

    def __call__(self, v):
        if not isinstance(v, str) or v not in self.options:
            raise _Bad
        return v


@dataclass(frozen=True)
class Boolean:
    def describe(self, unit: str = "") -> str:
        return "true or false"

    def __call__(self, v):
        if not isinstance(v, bool):
            raise _Bad
        return v


@dataclass(frozen=True)
class Text:
    what: str = "a file path in quotes (relative to the design file)"

    def describe(self, unit: str = "") -> str:
        return self.what

    def __call__(self, v):
        if not isinstance(v, str) or not v.strip():
            raise _Bad
        return v


@dataclass(frozen=True)
class List:
    item: Number
    length: int | None = None      # exact length, or None (any length >= 1)
    increasing: bool = False       # strictly increasing (ranges, distinct harmonics)

    def describe(self, unit: str = "") -> str:
        n = f"a list of {self.length} " if self.length else "a non-empty list of "
        order = ", strictly increasing" if self.increasing else ""
        return f"{n}{self.item.describe(unit, plural=True)}{order}"

    def __call__(self, v):
        if not isinstance(v, list) or not v or (self.length and len(v) != self.length):
            raise _Bad
        out = tuple(self.item(x) for x in v)
        if self.increasing and any(b <= a for a, b in zip(out, out[1:])):
            raise _Bad
        return out


@dataclass(frozen=True)
class Either:
    """The first alternative that accepts the value."""
    alternatives: tuple

    def describe(self, unit: str = "") -> str:
        return " or ".join(a.describe(unit) for a in self.alternatives)

    def __call__(self, v):
        for a in self.alternatives:
            try:
                return a(v)
            except _Bad:
                pass
        raise _Bad


# ---------------------------------------------------------------------------------------
# the table of fields
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Field:
    """One key of a design file.

    table, key : where it lives ("damper", "mass_g"); value : the reference value in the file's
    unit (None: no value by default; the template shows ``example`` commented out);
    check : what is allowed; unit : written in the comment; reason : why the reference value.
    """
    table: str
    key: str
    value: object
    check: object
    unit: str
    reason: str
    example: object = None

    @property
    def allowed(self) -> str:
        """The allowed values in words, with the unit."""
        return self.check.describe(f" {self.unit}" if self.unit != "-" else "")


TABLES = {
    "blade": "The blade: the built-in beam model of the paper's blade (geometry in [blade.beam]), its solid FE "
             "model (model = 'solid'), the solid FE model of your own surface mesh (model = 'solid' with "
             "surface_file, surface_units and the [blade.regions.*] tables), or modal data from a file (modal_file).",
    "blade.beam": "Geometry and material of the built-in blade (clamped root, shank, platform, airfoil), for the "
                  "beam and the solid model; each key overrides the reference blade's value. Ignored when [blade] "
                  "modal_file is given: remove this table then. With [blade] surface_file only the material "
                  "(youngs_modulus_gpa, poisson_ratio, density_kg_m3) and tip_point_mm / excitation_point_mm apply.",
    "blade.regions.clamp": "surface_file only, required: the root faces clamped in the disk, as a plane "
                           "(plane_point_mm, plane_normal, optionally box_mm) or as their own surface file (file). "
                           "The examples are the reference blade's (its root plane z = 0).",
    "blade.regions.OL": "surface_file only, required: the platform's underside contact face on the -x side (the "
                        "damper's left contact), as a plane or a file; planar, its outward normal in the x-z plane "
                        "(the disk's gamma_left_deg is read from it). The examples are the reference blade's.",
    "blade.regions.OR": "surface_file only, required: the platform's underside contact face on the +x side, as a "
                        "plane or a file; planar, its outward normal in the x-z plane (gamma_right_deg is read from "
                        "it). The examples are the reference blade's.",
    "blade.regions.tip": "surface_file only, optional: the tip face (mode names, the tip point), as a plane or a "
                         "file; default the flat top face at the surface's largest z.",
    "blade.fe": "FE matrix files only ([blade] modal_file ending in .op4, .pch, .mtx, .mat or .full; see "
                "ModalBlade.from_file and the README): which matrices, which DOF are clamped. The point tables "
                "[blade.fe.OL], [blade.fe.OR], [blade.fe.tip] and [blade.fe.excitation] are then required, "
                "[blade.fe.platform] optional.",
    **{f"blade.fe.{name}": f"FE matrix files only: the point {name} by node and DOF as the exporting program numbers "
                           "them (node, dofs) or by row numbers (rows), or rigidly linked to another point (link), "
                           "and its position."
       for name in ("OL", "OR", "tip", "excitation", "platform")},
    "blade.test": "Measured mode files only ([blade] modal_file ending in .uff, .unv or .uf: UFF dataset 55 or 2414 "
                  "normal modes; see ModalBlade.from_test and the README): the modal masses and units where the file "
                  "does not give them. The node tables [blade.test.OL], [blade.test.OR], [blade.test.tip] and "
                  "[blade.test.excitation] are then required, [blade.test.platform] optional. The frequencies and "
                  "damping are the file's unless [blade] natural_frequencies_hz or damping_ratio is given.",
    **{f"blade.test.{name}": f"Measured mode files only: the point {name} as a node of the file and, optionally, its "
                             "position (default the node's coordinates in the file, dataset 15 or 2411)."
       for name in ("OL", "OR", "tip", "excitation", "platform")},
    "damper": "The underplatform damper between neighbouring blades: kind, geometry, mass and contact.",
    "disk": "The tuned bladed disk: blades, engine order(s), platform angles, damper radius, excitation, speed.",
    "mistuning": "Blade frequency mistuning kappa (f_0 -> kappa f_0 for every mode of a blade); remove this table "
                 "for a tuned design. Used by `frf --mistuned` and `montecarlo`.",
    "analysis": "Harmonic balance and continuation settings of every command.",
}


# [blade] surface_units -> metres per unit of the surface files' coordinates
SURFACE_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254}
# The named regions of a surface_file blade (tables [blade.regions.<name>]) and the required ones
REGIONS = ("clamp", "OL", "OR", "tip")
REQUIRED_REGIONS = ("clamp", "OL", "OR")
# [disk] gamma_left_deg / gamma_right_deg given with a surface_file blade may differ from its faces'
# platform angles by this much [deg] (the faces' then count); a float32 STL in mm fixes them to ~1e-4 deg
SURFACE_GAMMA_TOLERANCE_DEG = 0.01
# [blade.regions.*] tolerance_mm when not given [mm] (bladedamp.blade.solid.PlaneRegion's default, 1e-5 m)
REGION_TOLERANCE_MM = 0.01
# [blade.beam] keys that apply to a surface_file blade (the others are the built-in blade's geometry)
SURFACE_BEAM_KEYS = ("youngs_modulus_gpa", "poisson_ratio", "density_kg_m3", "tip_point_mm", "excitation_point_mm")


# the points of an FE matrix blade (tables [blade.fe.<name>]); platform is optional
FE_POINTS = ("OL", "OR", "tip", "excitation", "platform")
# what [blade.fe] mass / stiffness allow
MATRIX_NAME = "a name in quotes (Abaqus: a file name beside modal_file)"


def _fe_fields(g) -> list[Field]:
    """The keys of [blade.fe] and [blade.fe.<point>] (an FE matrix file as [blade] modal_file;
    examples from the reference blade ``g``, a BeamBladeGeometry)."""
    pts = {k: [round(1e3 * float(x), 6) + 0.0 for x in p] for k, p in g.points().items()}      # [mm]
    index = Number(-1e9, 1e9, integer=True)
    row = Number(1, 1e9, integer=True)
    rows = [
        Field("blade.fe", "mass", None, Text(MATRIX_NAME), "-",
              "the mass matrix's name in the file (Abaqus: the mass file); default MAAX, MAA, MXX, M or MASS, whichever "
              "the file holds (Abaqus: the _MASS file beside the _STIF one)", example="MAA"),
        Field("blade.fe", "stiffness", None, Text(MATRIX_NAME), "-",
              "the stiffness matrix's name in the file (Abaqus: the stiffness file); default KAAX, KAA, KXX, K or "
              "STIFFNESS", example="KAA"),
        Field("blade.fe", "fixed_nodes", None, List(index), "-",
              "files that label rows by node (DMIG, Abaqus, Ansys): nodes clamped, all their DOF (e.g. the root "
              "of a model exported free)", example=[1]),
        Field("blade.fe", "fixed_rows", None, List(row), "-",
              "files that number rows only (OUTPUT4, MATLAB): 1-based rows clamped", example=[1, 2, 3, 4, 5, 6]),
    ]
    for name in FE_POINTS:
        table = f"blade.fe.{name}"
        example = pts["platform"] if name == "platform" else pts[name]
        rows += [
            Field(table, "node", None, index, "-", "the point's node (grid) number in the file", example=101),
            Field(table, "dofs", None, List(Number(0, 6, integer=True)), "-",
                  "with node: its DOF numbers in the order ux, uy, uz, phix, phiy, phiz (1-6) or ux, uy, uz "
                  "(1-3); default 1-6", example=[1, 2, 3, 4, 5, 6]),
            Field(table, "rows", None, List(row), "-", "instead of node: the 1-based rows of its 6 or 3 DOF",
                  example=[1, 2, 3, 4, 5, 6]),
            Field(table, "link", None, Choice(FE_POINTS), "-",
                  "instead of node or rows: rigidly attached to this 6-DOF point (e.g. OL and OR to platform)",
                  example="platform"),
            Field(table, "position_mm", None, List(Number(-1e4, 1e4), 3), "mm",
                  "the point's position in the blade frame (x circumferential, y axial, z radial); required",
                  example=example),
        ]
    return rows


# the points of a measured-modes blade (tables [blade.test.<name>]); platform is optional
TEST_POINTS = ("OL", "OR", "tip", "excitation", "platform")


def _test_fields(g) -> list[Field]:
    """The keys of [blade.test] and [blade.test.<point>] (a UFF mode file as [blade] modal_file;
    examples from the reference blade ``g``, a BeamBladeGeometry)."""
    pts = {k: [round(1e3 * float(x), 6) + 0.0 for x in p] for k, p in g.points().items()}      # [mm]
    rows = [
        Field("blade.test", "modal_mass_kg", None,
              Either((Number(0.0, 1e9, "right"), List(Number(0.0, 1e9, "right")))), "kg",
              "the modal mass of each stored shape, one number or one per mode: 1.0 for mass-normalised shapes "
              "(SI), 1000.0 for shapes mass-normalised in a file in mm, N, s and tonnes; default the file's (dataset "
              "55 or 2414 record 12)", example=1.0),
        Field("blade.test", "units", None, Choice(("SI",)), "-",
              "for a file without a dataset 164 (its unit system): 'SI' states that it is in m, kg, N; default the "
              "file's", example="SI"),
    ]
    for k, name in enumerate(TEST_POINTS):
        table = f"blade.test.{name}"
        rows += [
            Field(table, "node", None, Number(-1e9, 1e9, integer=True), "-",
                  "the point's node number in the file's mode shapes; required", example=11 + k),
            Field(table, "position_mm", None, List(Number(-1e4, 1e4), 3), "mm",
                  "the point's position in the blade frame (x circumferential, y axial, z radial); default the "
                  "node's coordinates in the file", example=pts[name]),
        ]
    return rows


def _region_fields(g) -> list[Field]:
    """The keys of the [blade.regions.<name>] tables (one set per region of :data:`REGIONS`, the same
    keys, checks and reasons; examples from the reference blade ``g``, a BeamBladeGeometry)."""
    from .damper.geometry import contact_normal
    from .reference import PLATFORM_ANGLE

    pts = {k: [round(1e3 * float(x), 6) + 0.0 for x in p] for k, p in g.points().items()}      # [mm]
    examples = {"clamp": ([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]), "tip": (pts["tip"], [0.0, 0.0, 1.0]),
                **{side: (pts[side], [round(float(x), 9) + 0.0 for x in contact_normal(side, PLATFORM_ANGLE)])
                   for side in ("OL", "OR")}}
    point = List(Number(-1e4, 1e4), 3)
    rows = []
    for name in REGIONS:
        table = f"blade.regions.{name}"
        rows += [
            Field(table, "plane_point_mm", None, point, "mm",
                  "a point of the region's plane in the blade frame (with plane_normal: the surface's triangles on "
                  "that plane facing that way)", example=examples[name][0]),
            Field(table, "plane_normal", None, List(Number(-1e6, 1e6), 3), "-",
                  "the region's outward normal (out of the blade, any length, not zero): its triangles face within "
                  "1 deg of it", example=examples[name][1]),
            Field(table, "box_mm", None, List(Number(-1e4, 1e4), 6), "mm",
                  "optional with a plane: only the triangles inside this box (x_min, y_min, z_min, x_max, y_max, "
                  "z_max), for a plane other faces share",
                  example=[x - 100.0 for x in examples[name][0]] + [x + 100.0 for x in examples[name][0]]),
            Field(table, "file", None, Text(), "-",
                  "instead of a plane: the region as its own surface file exported from the same model, in "
                  "surface_units; the triangles within tolerance_mm of it", example=f"{name}.stl"),
            Field(table, "tolerance_mm", None, Number(0.0, 1e3, "right"), "mm",
                  f"how far the region's triangle vertices may lie from its plane or file; default "
                  f"{_num(REGION_TOLERANCE_MM)} mm (an STL stores float32 coordinates: 1e-5 mm at 200 mm)",
                  example=REGION_TOLERANCE_MM),
        ]
        if name in ("OL", "OR"):
            rows.append(Field(table, "control_point_mm", None, point, "mm",
                              "the contact control point on the face (the damper's contact centre); default the "
                              "face's area centroid", example=pts[name]))
    return rows


def _fields() -> list[Field]:
    """Every key with its reference value, read from :mod:`bladedamp.reference` (the values the
    paper does not give carry their reasons there)."""
    from . import reference as ref
    from .hbm.accuracy import HARMONIC_TOLERANCE
    from .studies.mistuning import PAPER_SEED, PAPER_STD

    g = ref.reference_blade_geometry()
    freqs, damping = ref.TABLE1_FREQUENCIES_HZ, ref.TABLE1_DAMPING_RATIOS
    from .blade.solid import DEFAULT_ELEMENT_SIZE as SOLID_ELEMENT_SIZE     # solid.py imports gmsh only when meshing
    mm, pos = (lambda v: _tidy(v, 1e-3)), Number(0.0, 1e4, "right")
    beam = [
        ("shank_length_mm", mm(g.shank_length), pos, "mm", "root to platform (30 % of the 0.2 m span)"),
        ("shank_thickness_x_mm", mm(g.shank_thickness_x), pos, "mm", "shank section along x (circumferential)"),
        ("shank_chord_y_mm", mm(g.shank_chord_y), pos, "mm", "shank section along y (axial)"),
        ("airfoil_length_mm", mm(g.airfoil_length), pos, "mm", "platform to tip"),
        ("airfoil_thickness_x_mm", mm(g.airfoil_thickness_x), pos, "mm",
         "sets the 1F frequency of the FE model to 95 Hz"),
        ("airfoil_chord_y_mm", mm(g.airfoil_chord_y), pos, "mm",
         "sets the blade mass, calibrated on the paper's 1.7 mm undamped 1F tip peak"),
        ("platform_half_width_mm", mm(g.platform_half_width), pos, "mm",
         "x distance of the contact points OL, OR from the blade axis"),
        ("platform_contact_z_offset_mm", mm(g.platform_contact_z_offset), Number(0.0, 1e4), "mm",
         "contact points below the platform node (on the platform's underside); at most shank_length_mm"),
        ("platform_mass_g", _tidy(g.platform_mass, 1e-3), Number(0.0, 1e5), "g",
         "a 30 x 50 x 4 mm steel plate less the blade section inside it"),
        ("platform_rotary_inertia_kg_m2", [float(v) for v in g.platform_rotary_inertia],
         List(Number(0.0, 1e3), 3), "kg m^2", "(I_xx, I_yy, I_zz) of that plate about its centre"),
        ("youngs_modulus_gpa", _tidy(g.youngs_modulus, 1e9), Number(0.0, 1e4, "right"), "GPa", "blade steel"),
        ("poisson_ratio", _tidy(g.poisson_ratio), Number(-1.0, 0.5, "neither"), "-", "blade steel"),
        ("density_kg_m3", _tidy(g.density), Number(0.0, 1e5, "right"), "kg/m^3", "blade steel"),
        ("n_elements_shank", g.n_elements_shank, Number(1, 1000, integer=True), "-",
         "10 mm elements: halving them changes the frequencies by < 0.05 %"),
        ("n_elements_airfoil", g.n_elements_airfoil, Number(1, 1000, integer=True), "-", "10 mm elements, as above"),
    ]
    exc_item = Number(-1e6, 1e6)
    rows = [
        Field("blade", "modal_file", None, Text(), "-",
              "instead of the beam model: modal data at OL, OR, tip, excitation (npz, CSV), reduced FE matrices "
              "(.op4, .pch, .mtx, .mat, .full; [blade.fe]) or measured modes (UFF 55/2414 .uff, .unv, .uf; "
              "[blade.test])", example="my_blade.npz"),
        Field("blade", "model", "beam", Choice(("beam", "solid")), "-",
              "beam: the paper's beam FE model, rigid platforms at OL / OR; solid: 3D quadratic tetrahedra of the "
              "same geometry ([blade.beam] sections and material, the platform faces at [disk] gamma_left_deg / "
              "gamma_right_deg) or of surface_file, flexible platforms at every contact point (needs the fe "
              "extra; 7-16 s at 6 mm on 2 cores)"),
        Field("blade", "surface_file", None, Text(), "-",
              "solid model only: your blade, a closed surface mesh (STL) in the blade frame (x circumferential, "
              "y axial, z radial); needs surface_units, [blade.regions.clamp], [blade.regions.OL] and "
              "[blade.regions.OR]",
              example="my_blade.stl"),
        Field("blade", "surface_units", None, Choice(tuple(SURFACE_UNITS)), "-",
              "surface_file only (then required): the unit of the coordinates in surface_file and in the regions' "
              "files (CAD exports are often mm)", example="mm"),
        Field("blade", "solid_element_size_mm", _tidy(SOLID_ELEMENT_SIZE, 1e-3), Number(0.5, 100.0), "mm",
              "solid model only: gmsh's element size; 6 mm: 28 800 DOF, the damped 1F peak 0.06 % in amplitude "
              "and 0.11 % in frequency from the 4.5 mm mesh's (README, flexible platforms)"),
        Field("blade", "n_modes", 4, Number(1, 40, integer=True), "-",
              "beam or solid model: 4 gives the paper's modes 1F, 2F, 1T, 1E; otherwise (and for FE matrix files) "
              "the lowest n by frequency"),
        Field("blade", "natural_frequencies_hz", list(freqs), Either((Choice(("model",)), List(Number(0.0, 1e6, "right")))),
              "Hz", "the paper's Table 1 (the beam or solid FE gives the shapes); 'model' keeps the model's or the "
              "file's own frequencies (the default with modal_file or surface_file); one per mode"),
        Field("blade", "damping_ratio", _tidy(damping[0]) if len(set(damping)) == 1 else list(damping),
              Either((Number(0.0, 0.5), List(Number(0.0, 0.5)))), "-",
              "modal viscous damping D of every mode (paper: 0.001), or one per mode"),
        *[Field("blade.beam", k, v, c, u, r) for k, v, c, u, r in beam],
        Field("blade.beam", "tip_point_mm", None, List(Number(-1e4, 1e4), 3), "mm",
              "where the tip amplitude is read; default on the axis at the tip", example=[0.0, 0.0, 200.0]),
        Field("blade.beam", "excitation_point_mm", None, List(Number(-1e4, 1e4), 3), "mm",
              "where the excitation acts; default the tip point", example=[0.0, 0.0, 200.0]),
        *_region_fields(g),
        *_fe_fields(g),
        *_test_fields(g),
        Field("damper", "kind", "cylinder", Choice(("cylinder", "wedge", "none")), "-",
              "cylinder (rolls at EO = 0) or wedge (flat faces of height h_C); none: no damper"),
        Field("damper", "mass_g", 1.0, Number(0.0, 1000.0, "right"), "g",
              "the paper's cylinder optimum at EO = 1 (optimize finds a design's own)"),
        Field("damper", "cylinder_radius_mm", mm(ref.CYLINDER_RADIUS), Number(0.0, 100.0, "right"), "mm",
              "cylinder only: a small underplatform pin"),
        Field("damper", "contact_height_mm", mm(ref.WEDGE_CONTACT_HEIGHT), Number(0.0, 100.0, "right"), "mm",
              "wedge only: the height h_C of its flat contact faces (paper: 2 mm)"),
        Field("damper", "length_mm", mm(ref.DAMPER_LENGTH), Number(0.0, 1000.0, "right"), "mm",
              "contact length l_C along the damper's axis"),
        Field("damper", "friction_coefficient", ref.FRICTION_COEFFICIENT, Number(0.0, 2.0), "-",
              "dry steel on steel at turbine temperatures is 0.2-0.5"),
        Field("damper", "tangential_stiffness_per_length_n_per_m2", ref.TANGENTIAL_STIFFNESS_PER_LENGTH,
              Number(0.0, 1e14, "right"), "N/m per m of contact length",
              "calibrated on the paper's 71 % reduction of the 1 g cylinder"),
        Field("damper", "normal_to_tangential_stiffness", ref.NORMAL_TO_TANGENTIAL, Number(0.0, 100.0, "right"),
              "-", "Mindlin's ratio for steel is 1.21"),
        Field("damper", "roughness_exponent", ref.ROUGHNESS_EXPONENT, Number(1.0, 5.0), "-",
              "1: linear normal law; > 1: rough-surface power law (e.g. 1.5)"),
        Field("damper", "roughness_reference_load_n", 10.0, Number(0.0, 1e8, "right"), "N",
              "power law only: the load per contact at which the normal stiffness holds"),
        Field("damper", "points_along_length", ref.POINTS_ALONG_LENGTH, Number(1, 100, integer=True), "-",
              "point contacts along l_C; doubling them changes the reference peaks by < 1 %"),
        Field("damper", "points_across_height", ref.POINTS_ACROSS_HEIGHT, Number(1, 100, integer=True), "-",
              "wedge only: point contacts across h_C"),
        Field("damper", "inertia", True, Boolean(), "-", "include the damper's mass and rotary inertia"),
        Field("disk", "n_blades", ref.N_BLADES, Number(2, 1000, integer=True), "-", "the paper's disk"),
        Field("disk", "engine_order", ref.ENGINE_ORDER,
              Either((Number(0, 500, integer=True), List(Number(0, 500, integer=True), increasing=True))), "-",
              "EO >= 0, or a list (frf, eo-sweep, zzenf and campbell use each; the others the first); EO mod n_blades sets "
              "the nodal diameter (forward, or backward above n_blades / 2), EO itself the rotor speed"),
        Field("disk", "gamma_left_deg", _tidy(np.degrees(ref.PLATFORM_ANGLE)), Number(0.0, 90.0, "neither"), "deg",
              "platform angle at OL (paper: 35 deg); a surface_file blade's OL face sets it"),
        Field("disk", "gamma_right_deg", _tidy(np.degrees(ref.PLATFORM_ANGLE)), Number(0.0, 90.0, "neither"), "deg",
              "platform angle at OR (paper: 35 deg); a surface_file blade's OR face sets it"),
        Field("disk", "damper_radius_mm", mm(ref.DAMPER_RADIUS), Number(0.0, 1e5, "right"), "mm",
              "distance of the damper's centre of gravity to the rotor axis; calibrated on the 1 g optimum"),
        Field("disk", "excitation_n_nm", [_tidy(v) for v in ref.EXCITATION_FX], List(exc_item, 6), "N and N m",
              "(F_x, F_y, F_z, M_x, M_y, M_z) at the excitation point, cosine amplitude (paper: F_x = 0.1 N)"),
        Field("disk", "rotor_speed_rpm", "auto", Either((Choice(("auto",)), Number(0.0, 1e6, "right"))), "rpm",
              "'auto': the speed at which the engine order excites each frequency (Omega_E / EO); a number "
              "fixes the preload m R Omega_R^2 for every EO"),
        Field("disk", "rotor_speed_eo0_rpm", 5700.0, Number(0.0, 1e6, "right"), "rpm",
              "EO = 0 only, with rotor_speed_rpm = 'auto' (the excitation does not fix it there): 95 Hz x 60"),
        Field("mistuning", "std", PAPER_STD, Number(0.0, 0.2, "left"), "-",
              "standard deviation of the Gaussian kappa (paper: 2 % frequency mistuning)"),
        Field("mistuning", "seed", PAPER_SEED, Number(0, 2 ** 32 - 1, integer=True), "-",
              "random seed of the draw (the paper's sample is not given)"),
        Field("mistuning", "kappa", None, List(Number(0.5, 1.5)), "-",
              "explicit factors, one per blade (replaces std and seed)", example=[1.02, 0.98]),
        Field("analysis", "frequency_range_hz", [90.0, 105.0], List(Number(0.0, 1e6, "right"), 2, increasing=True),
              "Hz", "around the reference's 1F resonance (95 Hz)"),
        Field("analysis", "harmonics", "auto",
              Either((Choice(("auto",)), List(Number(0, 50, integer=True), increasing=True))), "-",
              "'auto' chooses them to harmonic_tolerance; [1] is the paper's one-harmonic setting (fast); "
              "a list must contain 1"),
        Field("analysis", "harmonic_tolerance", HARMONIC_TOLERANCE, Number(0.0, 1.0, "neither"), "-",
              "error estimate of the first-harmonic tip amplitudes, relative to the peak (1 %)"),
        Field("analysis", "max_harmonic", 3, Number(1, 50, integer=True), "-",
              "cap of the 'auto' choice (a sector's cost grows steeply with the harmonics)"),
        Field("analysis", "max_step", 0.02, Number(0.0, 1.0, "right"), "-",
              "largest continuation step, the frequency range being 1 (smaller: more points)"),
        Field("analysis", "mass_range_g", [0.01, 20.0], List(Number(0.0, 1e4, "right"), 2, increasing=True), "g",
              "search range of optimize and eo-sweep (the paper's optima lie within 0.3-15 g)"),
    ]
    return rows


def _num(x) -> str:
    """A range bound for people: 16, 0.5, 1e6."""
    if float(x).is_integer():
        text = str(int(x))
        digits = text.lstrip("-").rstrip("0")
        zeros = len(text.lstrip("-")) - len(digits)
        return text if zeros < 5 else f"{'-' if x < 0 else ''}{digits}e{zeros}"
    return f"{x:g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


def _tidy(v: float, scale: float = 1.0) -> float:
    """``v`` [SI] in a file unit (``v / scale``), short where that loses nothing: 4.57 instead of
    4.5700000000000003 when 4.57 * scale gives back ``v`` exactly (the reader multiplies by
    ``scale``), the full digits otherwise (so the template is exactly the reference)."""
    full = float(v) / scale
    short = float(f"{full:.12g}")
    return short if short * scale == float(v) else full


_FIELDS = None


def fields() -> list[Field]:
    """The table of every design-file key (built once)."""
    global _FIELDS
    if _FIELDS is None:
        _FIELDS = _fields()
    return _FIELDS


# ---------------------------------------------------------------------------------------
# the template
# ---------------------------------------------------------------------------------------
def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return repr(v)


def template() -> str:
    """The reference design as TOML, every key commented with unit, allowed range and reason."""
    lines = ["# bladedamp design file: the paper's reference disk (Panning, Sextro & Popp).",
             "# Edit any value; a missing key takes the reference value written here. Units are in the key names",
             "# (g, mm, deg, Hz, rpm); inside, bladedamp works in SI. Read it in Python with",
             "# bladedamp.load_design(path); run it with: bladedamp frf <this file> (see bladedamp --help).", ""]
    table = None
    for f in fields():
        if f.table != table:
            table = f.table
            lines += ["", f"[{table}]", *textwrap.wrap(TABLES[table], 100, initial_indent="# ",
                                                        subsequent_indent="# "), ""]
        unit = "" if f.unit == "-" else f" Unit: {f.unit}."
        lines += textwrap.wrap(f"{f.reason}.{unit} Allowed: {f.allowed}.", 100, initial_indent="# ",
                               subsequent_indent="#   ")
        if f.value is None:
            lines.append(f"# {f.key} = {_toml(f.example)}")
        else:
            lines.append(f"{f.key} = {_toml(f.value)}")
    return "\n".join(lines).lstrip("\n") + "\n"


def write_template(path, overwrite: bool = False) -> Path:
    """Write :func:`template` to ``path``; DesignError if it exists (unless ``overwrite``) or
    cannot be written."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise DesignError(f"{path}: exists already (choose another name, or replace it with --overwrite)")
    try:
        path.write_text(template())
    except OSError as exc:
        raise DesignError(f"{path}: cannot write the design file ({exc.strerror or exc})") from None
    return path


# ---------------------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------------------
@dataclass
class Analysis:
    """The analysis settings of a design (SI / Hz).

    f_start_hz, f_end_hz : frequency range [Hz]; harmonics : "auto" or a tuple of harmonics;
    harmonic_tolerance, max_harmonic, max_step : as :meth:`bladedamp.TunedDisk.frequency_response`;
    mass_bounds : (low, high) damper mass search range [kg]
    """
    f_start_hz: float
    f_end_hz: float
    harmonics: object
    harmonic_tolerance: float
    max_harmonic: int
    max_step: float
    mass_bounds: tuple

    @property
    def f_range_hz(self) -> tuple[float, float]:
        return self.f_start_hz, self.f_end_hz

    def options(self) -> dict:
        """Keyword arguments of ``frequency_response`` (TunedDisk or MistunedDisk)."""
        return dict(harmonics=self.harmonics, max_step=self.max_step, harmonic_tolerance=self.harmonic_tolerance,
                    max_harmonic=self.max_harmonic)

    @property
    def study_harmonics(self) -> tuple:
        """Harmonics of the peak searches of the studies: the design's list, or the paper's (1,)
        when it is "auto" (each study solves tens of responses)."""
        return (1,) if self.harmonics == "auto" else tuple(self.harmonics)


@dataclass
class Mistuning:
    """std [-], seed, kappa : explicit factors (n_blades,) or None (drawn from std and seed)."""
    std: float
    seed: int
    kappa: np.ndarray | None = None

    def factors(self, n_blades: int) -> np.ndarray:
        """The (n_blades,) mistuning factors kappa."""
        from .studies.mistuning import random_kappa

        return np.array(self.kappa, dtype=float) if self.kappa is not None else random_kappa(n_blades, self.std, self.seed)


@dataclass
class Design:
    """A design read from a file.

    disk : TunedDisk at the first engine order; engine_orders : every EO of the file;
    analysis : :class:`Analysis`; mistuning : :class:`Mistuning` or None;
    rotor_speed_eo0_hz : rotor speed used at EO = 0 when the file's rotor speed is 'auto' [Hz,
    revolutions per second: the file's rpm / 60]; rotor_speed_hz : the file's fixed rotor speed
    [Hz], None for 'auto' (Omega_E / EO);
    values : {table: {key: value}} in the file's units, every key (defaults filled in);
    path : the file (None: the reference design); blade_geometry : the BeamBladeGeometry of a
    beam or parametric solid blade (None for modal data from a file and a surface_file blade);
    keys_given : the (table, key) pairs the file sets (empty: the file is the reference design)
    """
    disk: object
    engine_orders: tuple
    analysis: Analysis
    mistuning: Mistuning | None
    rotor_speed_eo0_hz: float
    rotor_speed_hz: float | None = None
    values: dict = field(repr=False, default_factory=dict)
    path: Path | None = None
    blade_geometry: object = None
    keys_given: frozenset = frozenset()

    def disk_at(self, engine_order: int):
        """The design's disk at another engine order (at EO = 0 with the speed rotor_speed_eo0_hz
        if the file's rotor speed is 'auto')."""
        from .studies.design import at_engine_order

        base = dataclasses.replace(self.disk, engine_order=1, rotor_speed_hz=self.rotor_speed_hz)   # valid for n >= 2
        return at_engine_order(base, engine_order, self.rotor_speed_eo0_hz)

    def mistuned_disk(self):
        """The full assembly with the design's mistuning (:class:`bladedamp.mistuned.MistunedDisk`)."""
        from .mistuned import MistunedDisk

        if self.mistuning is None:
            raise DesignError(f"{self.path or 'design'}: no [mistuning] table: add one (std, seed or kappa)")
        return MistunedDisk.from_tuned(self.disk, self.mistuning.factors(self.disk.n_blades))

    @property
    def kappa(self) -> np.ndarray | None:
        return None if self.mistuning is None else self.mistuning.factors(self.disk.n_blades)


def _suggest(word: str, options) -> str:
    close = difflib.get_close_matches(word, list(options), n=1)
    return f" (did you mean {close[0]}?)" if close else ""


def _read_values(path: Path, raw: dict) -> tuple[dict, set]:
    """{table: {key: checked value}} with defaults, and the set of (table, key) given in the file."""
    by_table = {}
    for f in fields():
        by_table.setdefault(f.table, {})[f.key] = f
    given = set()
    values = {t: {k: None if f.value is None else f.check(f.value) for k, f in keys.items()}
              for t, keys in by_table.items()}
    # tables that only hold tables (blade.regions holds blade.regions.clamp, ...)
    containers = {t.rsplit(".", 1)[0] for t in by_table if "." in t} - set(by_table)

    def visit(prefix: str, table: dict):
        for key, value in table.items():
            name = f"{prefix}.{key}" if prefix else key
            if name in by_table or name in containers:
                if not isinstance(value, dict):
                    raise DesignError(f"{path}: {name} must be a table [{name}] (got {key} = {_toml(value)})")
                visit(name, value)
                continue
            if not prefix:
                raise DesignError(f"{path}: unknown table or key {name!r}{_suggest(name, by_table)}; allowed "
                                  f"tables: {', '.join(f'[{t}]' for t in by_table)}")
            if prefix in containers:
                inside = [t for t in by_table if t.startswith(f"{prefix}.")]
                raise DesignError(f"{path}: unknown table [{name}]{_suggest(name, inside)}; allowed tables: "
                                  f"{', '.join(f'[{t}]' for t in inside)}")
            if key not in by_table[prefix]:
                raise DesignError(f"{path}: unknown key [{prefix}] {key}{_suggest(key, by_table[prefix])}; "
                                  f"allowed keys: {', '.join(by_table[prefix])}")
            f = by_table[prefix][key]
            try:
                values[prefix][key] = f.check(value)
            except _Bad:
                raise _bad(path, prefix, key, value, f.allowed) from None
            given.add((prefix, key))

    visit("", raw)
    return values, given


def _bad(path, table, key, value, allowed) -> DesignError:
    """The one-line error of a value outside its allowed range."""
    return DesignError(f"{path}: [{table}] {key} = {_toml(value)} is not allowed: must be {allowed}")


def load_design(path) -> Design:
    """Read a design file (TOML) into the models: a :class:`Design` with ``.disk`` (TunedDisk),
    ``.mistuned_disk()`` and ``.analysis``. Raises :class:`DesignError` (a ValueError) with one
    line naming the file, key, value and allowed range for a bad field or an unknown key, and
    naming the file and what is wrong for a file that is missing, a folder, unreadable, not UTF-8
    text (a byte-order mark is allowed) or not TOML (:func:`bladedamp.io.reading`). A file that
    sets no key (empty, only comments or table headers) is the reference design:
    ``Design.keys_given`` is then empty."""
    path = Path(path)
    if not path.exists():
        raise DesignError(f"{path}: no such design file (write the reference design with: "
                          f"bladedamp init {path})")
    with reading(path, "design file (TOML)", DesignError):
        try:
            raw = tomllib.loads(path.read_bytes().decode("utf-8-sig"))
        except tomllib.TOMLDecodeError as exc:
            raise DesignError(f"{path}: not valid TOML ({exc})") from None
    values, given = _read_values(path, raw)
    design = _build(path, values, given, "mistuning" in raw)
    design.keys_given = frozenset(given)
    return design


def _build(path: Path, v: dict, given: set, has_mistuning: bool) -> Design:
    """The models of checked values ``v``; the checks that involve two keys are made here."""
    from .damper.geometry import MIN_DAMPER_MASS, ContactProperties, CylinderDamper, WedgeDamper
    from .disk import TunedDisk

    blade, geometry = _build_blade(path, v, given)
    d, k = v["disk"], v["damper"]
    n = d["n_blades"]
    eos = (d["engine_order"],) if isinstance(d["engine_order"], int) else tuple(d["engine_order"])
    damper = None
    if k["kind"] != "none":
        try:
            contact = ContactProperties(k["friction_coefficient"], k["tangential_stiffness_per_length_n_per_m2"],
                                        k["normal_to_tangential_stiffness"], k["roughness_exponent"],
                                        k["roughness_reference_load_n"], k["points_along_length"],
                                        k["points_across_height"])
        except ValueError as exc:       # a combination of keys (each in its own range) that is no contact
            raise DesignError(f"{path}: [damper]: {exc}") from None
        mass, length = 1e-3 * k["mass_g"], 1e-3 * k["length_mm"]
        if mass < MIN_DAMPER_MASS:
            raise _bad(path, "damper", "mass_g", k["mass_g"],
                       f"in [{1e3 * MIN_DAMPER_MASS:g}, 1000] g (a lighter damper's limit is the disk without one: "
                       f"kind = \"none\")")
        damper = (CylinderDamper(mass, 1e-3 * k["cylinder_radius_mm"], length, contact) if k["kind"] == "cylinder"
                  else WedgeDamper(mass, 1e-3 * k["contact_height_mm"], length, contact))
    speed = None if d["rotor_speed_rpm"] == "auto" else d["rotor_speed_rpm"] / 60.0      # rpm -> Hz
    speed_eo0 = d["rotor_speed_eo0_rpm"] / 60.0
    disk = TunedDisk(blade, damper, n, 1, np.radians(d["gamma_left_deg"]), np.radians(d["gamma_right_deg"]),
                     1e-3 * d["damper_radius_mm"], np.array(d["excitation_n_nm"], dtype=float), speed,
                     bool(k["inertia"]))
    a = v["analysis"]
    if a["harmonics"] != "auto" and 1 not in a["harmonics"]:
        raise _bad(path, "analysis", "harmonics", list(a["harmonics"]), "'auto' or a list of harmonics containing 1")
    analysis = Analysis(*a["frequency_range_hz"], a["harmonics"], a["harmonic_tolerance"], a["max_harmonic"],
                        a["max_step"], tuple(1e-3 * m for m in a["mass_range_g"]))
    mistuning = None
    if has_mistuning:
        m = v["mistuning"]
        kappa = m["kappa"]
        if kappa is not None and len(kappa) != n:
            raise _bad(path, "mistuning", "kappa", list(kappa), f"{n} numbers in [0.5, 1.5] (one per blade, n_blades)")
        if kappa is not None and {("mistuning", "std"), ("mistuning", "seed")} & given:
            raise DesignError(f"{path}: [mistuning] kappa replaces std and seed: give either kappa or std and seed")
        mistuning = Mistuning(m["std"], m["seed"], None if kappa is None else np.array(kappa))
    design = Design(disk, eos, analysis, mistuning, speed_eo0, speed, v, path, geometry)
    design.disk = design.disk_at(eos[0])
    return design


def reference_design() -> Design:
    """The design of :func:`template` without a file: the reference disk and settings."""
    values, given = _read_values(Path("reference design"), {})
    design = _build(Path("reference design"), values, given, True)
    design.path = None
    return design


def _solid_blade(path: Path, geometry, v: dict, n_modes: int, freqs, damping):
    """The solid FE blade (:func:`bladedamp.blade.solid.solid_blade`) of ``geometry``: a BeamBladeGeometry
    ([blade.beam]: the parametric solid with its platform faces at the disk's platform angles, which
    the contact kinematics need to agree) or a SurfaceBladeGeometry ([blade] surface_file, whose
    faces set the disk's angles: :func:`_surface_geometry`)."""
    from .blade import BeamBladeGeometry
    from .blade.solid import SolidBladeGeometry, solid_blade

    d = v["disk"]
    parametric = isinstance(geometry, BeamBladeGeometry)
    where = "[blade] model = 'solid'" if parametric else f"[blade] surface_file = {_toml(v['blade']['surface_file'])}"
    try:
        sg = (SolidBladeGeometry(beam=geometry, gamma_left=np.radians(d["gamma_left_deg"]),
                                 gamma_right=np.radians(d["gamma_right_deg"])) if parametric else geometry)
        options = {} if damping is None else {"damping_ratios": damping}
        return solid_blade(sg, 1e-3 * v["blade"]["solid_element_size_mm"], n_modes,
                           natural_frequencies_hz=freqs, **options)
    except (ImportError, ValueError, RuntimeError) as exc:     # ImportError: the fe extra's one-line hint
        raise DesignError(f"{path}: {where}: {exc}") from None


def _relative(path: Path, file: str) -> Path:
    """``file`` (a key's value) as a path: relative to the design file ``path``'s folder unless absolute."""
    f = Path(file)
    return f if f.is_absolute() else path.parent / f


def _surface_error_key(message: str, v: dict) -> str:
    """The design key a :class:`~bladedamp.blade.solid.SurfaceBladeGeometry` error ``message`` is about
    (its messages start with the parameter's name)."""
    import re

    b = v["blade"]
    m = re.match(r"(regions|points_given)\[['\"](\w+)['\"]\]", message)
    if m and m.group(1) == "regions":
        return f"[blade.regions.{m.group(2)}]"
    if m:
        return {"OL": "[blade.regions.OL] control_point_mm", "OR": "[blade.regions.OR] control_point_mm",
                "tip": "[blade.beam] tip_point_mm", "excitation": "[blade.beam] excitation_point_mm"}.get(
            m.group(2), "[blade.beam]")
    if message.startswith("scale"):
        return f"[blade] surface_units = {_toml(b['surface_units'])} ({SURFACE_UNITS[b['surface_units']]:g} m per unit)"
    for name, key in (("youngs_modulus", "youngs_modulus_gpa"), ("poisson_ratio", "poisson_ratio"),
                      ("density", "density_kg_m3")):
        if message.startswith(name):
            return f"[blade.beam] {key}"
    return f"[blade] surface_file = {_toml(b['surface_file'])}"


def _surface_geometry(path: Path, v: dict, given: set):
    """The :class:`~bladedamp.blade.solid.SurfaceBladeGeometry` of [blade] surface_file, surface_units, the
    [blade.regions.*] tables and [blade.beam]'s material and points; DesignError naming the key."""
    b, beam = v["blade"], v["blade.beam"]
    if b["surface_units"] is None:
        raise DesignError(f"{path}: [blade] surface_file needs surface_units, the unit of its coordinates: "
                          f"{Choice(tuple(SURFACE_UNITS)).describe()}")
    file = _relative(path, b["surface_file"])
    if not file.is_file():
        raise DesignError(f"{path}: [blade] surface_file = {_toml(b['surface_file'])}: no file {str(file)!r}")
    tables = {name: sorted(k for t, k in given if t == f"blade.regions.{name}") for name in REGIONS}
    missing = [f"[blade.regions.{name}]" for name in REQUIRED_REGIONS if not tables[name]]
    if missing:
        required = ", ".join(f"[blade.regions.{n}]" for n in REQUIRED_REGIONS)
        raise DesignError(f"{path}: [blade] surface_file needs the tables {required} (missing: {', '.join(missing)}), "
                          "each with plane_point_mm and plane_normal, or file")
    try:
        from .blade.solid import PlaneRegion, SurfaceBladeGeometry, SurfacePatch
    except ImportError as exc:
        raise DesignError(f"{path}: [blade] surface_file: {exc}") from None
    regions, points = {}, {}
    for name, keys in tables.items():
        if not keys:
            continue
        table, r = f"blade.regions.{name}", v[f"blade.regions.{name}"]
        plane = sorted({"plane_point_mm", "plane_normal", "box_mm"} & set(keys))
        tolerance = REGION_TOLERANCE_MM if r["tolerance_mm"] is None else r["tolerance_mm"]
        if "file" in keys:
            if plane:
                raise DesignError(f"{path}: [{table}] file replaces the plane: give file or plane_point_mm and "
                                  f"plane_normal, not both (remove {', '.join(plane)} or file)")
            patch = _relative(path, r["file"])
            if not patch.is_file():
                raise DesignError(f"{path}: [{table}] file = {_toml(r['file'])}: no file {str(patch)!r}")
            regions[name] = SurfacePatch(str(patch), tolerance=1e-3 * tolerance)
        else:
            if r["plane_point_mm"] is None or r["plane_normal"] is None:
                raise DesignError(f"{path}: [{table}] needs plane_point_mm and plane_normal (the region's plane), "
                                  f"or file (given: {', '.join(keys)})")
            if not any(r["plane_normal"]):
                raise _bad(path, table, "plane_normal", list(r["plane_normal"]),
                           "3 numbers, not all zero (the region's outward normal)")
            box = None
            if r["box_mm"] is not None:
                low, high = np.array(r["box_mm"][:3]), np.array(r["box_mm"][3:])
                if np.any(low > high):
                    raise _bad(path, table, "box_mm", list(r["box_mm"]),
                               "6 numbers x_min, y_min, z_min, x_max, y_max, z_max with each min <= its max, in mm")
                box = (tuple(1e-3 * low), tuple(1e-3 * high))
            regions[name] = PlaneRegion(tuple(1e-3 * np.array(r["plane_point_mm"])), tuple(r["plane_normal"]),
                                        1e-3 * tolerance, box)
        if r.get("control_point_mm") is not None:
            points[name] = 1e-3 * np.array(r["control_point_mm"])
    for key, name in (("tip_point_mm", "tip"), ("excitation_point_mm", "excitation")):
        if beam[key] is not None:
            points[name] = 1e-3 * np.array(beam[key])
    try:
        return SurfaceBladeGeometry(str(file), regions, SURFACE_UNITS[b["surface_units"]],
                                    youngs_modulus=1e9 * beam["youngs_modulus_gpa"],
                                    poisson_ratio=beam["poisson_ratio"], density=beam["density_kg_m3"],
                                    points_given=points or None)
    except ImportError as exc:
        raise DesignError(f"{path}: [blade] surface_file: {exc}") from None
    except (ValueError, OSError) as exc:
        units = str(exc).startswith("scale")
        hint = ' (in a design file: surface_units = "mm" for a file in millimetres)' if units else ""
        raise DesignError(f"{path}: {_surface_error_key(str(exc), v)}: {exc}{hint}") from None


def _platform_angles_of(path: Path, v: dict, given: set, gammas: dict, what: str) -> None:
    """A blade with its own platform faces (a surface_file blade, a solid blade's modal file; their
    platform angles ``gammas`` "OL", "OR" -> [rad]) sets the disk's: v["disk"] gamma_left_deg /
    gamma_right_deg become the faces' angles [deg]; DesignError if the file gives one that differs
    by more than :data:`SURFACE_GAMMA_TOLERANCE_DEG` (``what`` names the blade's key)."""
    for side, key in (("OL", "gamma_left_deg"), ("OR", "gamma_right_deg")):
        face = float(np.degrees(gammas[side]))
        if ("disk", key) in given and abs(v["disk"][key] - face) > SURFACE_GAMMA_TOLERANCE_DEG:
            raise DesignError(f"{path}: [disk] {key} = {_toml(v['disk'][key])} is not the platform angle of the {side} "
                              f"face of {what} ({face:.6g} deg): remove {key} (the disk takes the face's) or give "
                              f"{face:.6g}")
        v["disk"][key] = face


def _fe_options(path: Path, v: dict, given: set, n_modes: int, damping) -> dict:
    """ModalBlade.from_file's options for an FE matrix file of [blade.fe] and [blade.fe.<point>]."""
    fe = v["blade.fe"]
    dof_map, points, links = {}, {}, {}
    for name in FE_POINTS:
        table = f"blade.fe.{name}"
        p = v[table]
        keys = [k for k in ("node", "rows", "link") if (table, k) in given]
        if not any(t == table for t, _ in given):
            if name == "platform":
                continue
            raise DesignError(f"{path}: [{table}] is required with an FE matrix file as [blade] modal_file: give "
                              "node (or rows, or link) and position_mm")
        if len(keys) != 1:
            raise DesignError(f"{path}: [{table}] needs exactly one of node, rows or link (got "
                              f"{', '.join(keys) or 'none'})")
        if (table, "dofs") in given and keys != ["node"]:
            raise DesignError(f"{path}: [{table}] dofs applies with node only: remove it")
        if p["position_mm"] is None:
            raise DesignError(f"{path}: [{table}] position_mm is required: the point's position [mm]")
        points[name] = 1e-3 * np.array(p["position_mm"])
        if keys == ["node"]:
            dof_map[name] = (p["node"], tuple(p["dofs"] or (1, 2, 3, 4, 5, 6)))
        elif keys == ["rows"]:
            dof_map[name] = list(p["rows"])
        else:
            links[name] = p["link"]
    fixed = list(fe["fixed_nodes"] or ()) + list(fe["fixed_rows"] or ())
    return dict(dof_map=dof_map, points=points, rigid_links=links or None, n_modes=n_modes,
                damping_ratios=damping, fixed_dofs=fixed,
                mass=fe["mass"], stiffness=fe["stiffness"])


def _test_options(path: Path, v: dict, given: set) -> dict:
    """ModalBlade.from_test's options for a measured mode file of [blade.test] and [blade.test.<point>]."""
    t = v["blade.test"]
    points, positions = {}, {}
    for name in TEST_POINTS:
        table = f"blade.test.{name}"
        if not any(tt == table for tt, _ in given):
            if name == "platform":
                continue
            raise DesignError(f"{path}: [{table}] is required with a measured mode file as [blade] modal_file: give "
                              "node (the point's node number in the file) and, optionally, position_mm")
        p = v[table]
        if p["node"] is None:
            raise DesignError(f"{path}: [{table}] node is required: the point's node number in the file")
        points[name] = p["node"]
        if p["position_mm"] is not None:
            positions[name] = 1e-3 * np.array(p["position_mm"])
    mass = t["modal_mass_kg"]
    return dict(points=points, positions=positions or None,
                damping_ratios=v["blade"]["damping_ratio"] if ("blade", "damping_ratio") in given else None,
                modal_masses=None if mass is None else (mass if isinstance(mass, float) else list(mass)),
                units=t["units"])


def _build_blade(path: Path, v: dict, given: set):
    """(ModalBlade, BeamBladeGeometry or None) of [blade] and [blade.beam] (and [blade.regions.*]
    for a surface_file blade). A blade with its own platform faces sets v["disk"]'s platform angles
    (:func:`_platform_angles_of`)."""
    from .blade import BeamBladeGeometry, ModalBlade

    b, beam = v["blade"], v["blade.beam"]
    freqs, damping = b["natural_frequencies_hz"], b["damping_ratio"]
    solid = b["model"] == "solid"
    surface = b["surface_file"] is not None
    if surface and b["modal_file"] is not None:
        raise DesignError(f"{path}: [blade] surface_file and modal_file are two different blades: give one of them")
    fe_keys = sorted((t, k) for t, k in given if t == "blade.fe" or t.startswith("blade.fe."))
    if fe_keys and (b["modal_file"] is None
                    or Path(b["modal_file"]).suffix.lower().lstrip(".") not in FE_SUFFIXES):
        raise DesignError(f"{path}: [{fe_keys[0][0]}] {fe_keys[0][1]} applies to an FE matrix file as [blade] "
                          f"modal_file (ending in {', '.join('.' + x for x in FE_SUFFIXES)}): add it or remove the key")
    test_keys = sorted((t, k) for t, k in given if t == "blade.test" or t.startswith("blade.test."))
    if test_keys and (b["modal_file"] is None
                      or Path(b["modal_file"]).suffix.lower().lstrip(".") not in UFF_SUFFIXES):
        raise DesignError(f"{path}: [{test_keys[0][0]}] {test_keys[0][1]} applies to a measured mode file as [blade] "
                          f"modal_file (ending in {', '.join('.' + x for x in UFF_SUFFIXES)}): add it or remove the key")
    if surface and not solid:
        raise DesignError(f"{path}: [blade] surface_file is meshed as a solid FE blade: add model = \"solid\" to "
                          "[blade] (or remove surface_file)")
    surface_keys = sorted((t, k) for t, k in given
                          if t.startswith("blade.regions.") or (t, k) == ("blade", "surface_units"))
    if surface_keys and not surface:
        t, k = surface_keys[0]
        raise DesignError(f"{path}: [{t}] {k} applies to a surface_file blade only: add [blade] surface_file "
                          "(or remove it)")
    geometry = None
    if b["modal_file"] is not None:
        if solid:
            raise DesignError(f"{path}: [blade] model = 'solid' builds the blade from [blade.beam]; with "
                              "modal_file remove model (or modal_file)")
        fe_file = Path(b["modal_file"]).suffix.lower().lstrip(".") in FE_SUFFIXES
        beam_keys = sorted(k for t, k in given if t == "blade.beam")
        if beam_keys or (("blade", "n_modes") in given and not fe_file):
            key = f"[blade.beam] {beam_keys[0]}" if beam_keys else "[blade] n_modes"
            raise DesignError(f"{path}: {key} applies to the beam model only; with [blade] modal_file remove it")
        if not hasattr(ModalBlade, "from_file"):
            raise DesignError(f"{path}: [blade] modal_file needs ModalBlade.from_file, which this bladedamp "
                              "version does not have")
        file = _relative(path, b["modal_file"])
        test_file = Path(b["modal_file"]).suffix.lower().lstrip(".") in UFF_SUFFIXES
        if test_file:
            options, load = _test_options(path, v, given), ModalBlade.from_test
            keys = (" (the design file's keys: [blade.test] modal_mass_kg and units, [blade.test.<point>] position_mm, "
                    "[blade] damping_ratio)")
        else:
            options = _fe_options(path, v, given, b["n_modes"], damping) if fe_file else {}
            load, keys = ModalBlade.from_file, ""
        try:
            blade = load(file, **options)
        except (OSError, ValueError, KeyError) as exc:
            raise DesignError(f"{path}: [blade] modal_file = {_toml(b['modal_file'])}: {exc}{keys}") from None
        faces = getattr(blade, "face_fields", {})        # a solid blade's file: its flexible platforms
        if faces:
            _platform_angles_of(path, v, given, {side: f.gamma for side, f in faces.items()},
                                f"[blade] modal_file = {_toml(b['modal_file'])}")
        n_modes = blade.n_modes
        if ("blade", "natural_frequencies_hz") not in given:
            freqs = "model"
        if ("blade", "damping_ratio") not in given:
            damping = None
    elif surface:
        n_modes = b["n_modes"]
        if ("blade", "natural_frequencies_hz") not in given:
            freqs = "model"                  # your own blade's: Table 1 is the paper's blade
        shape_keys = sorted(k for t, k in given if t == "blade.beam" and k not in SURFACE_BEAM_KEYS)
        if shape_keys:
            raise DesignError(f"{path}: [blade.beam] {shape_keys[0]} is the built-in blade's geometry; with [blade] "
                              f"surface_file only {', '.join(SURFACE_BEAM_KEYS)} apply: remove it")
    else:
        n_modes = b["n_modes"]
        if beam["platform_contact_z_offset_mm"] > beam["shank_length_mm"]:
            raise _bad(path, "blade.beam", "platform_contact_z_offset_mm", beam["platform_contact_z_offset_mm"],
                       f"a number in [0, shank_length_mm = {beam['shank_length_mm']:g}] mm")
        mm = {k: 1e-3 * beam[f"{k}_mm"] for k in ("shank_length", "shank_thickness_x", "shank_chord_y",
                                                  "airfoil_length", "airfoil_thickness_x", "airfoil_chord_y",
                                                  "platform_half_width", "platform_contact_z_offset")}
        points = {k: None if beam[f"{k}_mm"] is None else 1e-3 * np.array(beam[f"{k}_mm"])
                  for k in ("tip_point", "excitation_point")}
        try:
            geometry = BeamBladeGeometry(**mm, platform_mass=1e-3 * beam["platform_mass_g"],
                                         platform_rotary_inertia=tuple(beam["platform_rotary_inertia_kg_m2"]),
                                         youngs_modulus=1e9 * beam["youngs_modulus_gpa"],
                                         poisson_ratio=beam["poisson_ratio"], density=beam["density_kg_m3"],
                                         n_elements_shank=beam["n_elements_shank"],
                                         n_elements_airfoil=beam["n_elements_airfoil"], **points)
        except ValueError as exc:
            raise DesignError(f"{path}: [blade.beam]: {exc}") from None
    if freqs != "model" and len(freqs) != n_modes:
        raise _bad(path, "blade", "natural_frequencies_hz", list(freqs),
                   f"'model' or {n_modes} numbers in (0, 1e6] Hz (one per mode, n_modes = {n_modes})")
    if not isinstance(damping, (float, type(None))) and len(damping) != n_modes:
        raise _bad(path, "blade", "damping_ratio", list(damping), f"a number or {n_modes} numbers in [0, 0.5]")
    if surface:
        sg = _surface_geometry(path, v, given)
        _platform_angles_of(path, v, given, {"OL": sg.gamma_left, "OR": sg.gamma_right},
                            f"[blade] surface_file = {_toml(b['surface_file'])}")
        return _solid_blade(path, sg, v, n_modes, None if freqs == "model" else freqs, damping), None
    if solid:
        return _solid_blade(path, geometry, v, n_modes, None if freqs == "model" else freqs, damping), geometry
    if b["modal_file"] is None:
        try:
            return ModalBlade.from_beam(geometry, n_modes, None if freqs == "model" else freqs, damping), geometry
        except ValueError as exc:
            raise DesignError(f"{path}: [blade] n_modes = {n_modes}: {exc}") from None
    if freqs != "model":
        blade = blade.with_frequencies(freqs)
    if damping is not None:
        blade = dataclasses.replace(blade, damping_ratios=damping)
    return blade, None
