"""Design files: a TOML description of a blade, damper, disk, mistuning and analysis, read into
the models (``load_design``) and written as the commented reference design (``template``).

One table of :class:`Field` rows holds every key: its reference value, unit, allowed range and
the reason for the value. The validator and the template are both generated from it, so they
cannot disagree. Human units are used where they are clearer (g, mm, deg, Hz, rpm); the unit
is part of every key's name. Every key is optional: a missing key takes the reference value,
so a file holding only ``[damper]`` / ``mass_g = 2.0`` is the reference disk with a 2 g damper.
Unknown tables and keys are errors (a typo must not pass silently).

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


class DesignError(ValueError):
    """A design file that cannot be read or has a bad field; the message is one line naming the
    file, the key, the value and the allowed range."""


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
    def describe(self, unit: str = "") -> str:
        return "a file path in quotes (relative to the design file)"

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
             "model (model = 'solid'), or modal data from a file (modal_file).",
    "blade.beam": "Geometry and material of the built-in blade (clamped root, shank, platform, airfoil), for the "
                  "beam and the solid model; each key overrides the reference blade's value. Ignored when [blade] "
                  "modal_file is given: remove this table then.",
    "damper": "The underplatform damper between neighbouring blades: kind, geometry, mass and contact.",
    "disk": "The tuned bladed disk: blades, engine order(s), platform angles, damper radius, excitation, speed.",
    "mistuning": "Blade frequency mistuning kappa (f_0 -> kappa f_0 for every mode of a blade); remove this table "
                 "for a tuned design. Used by `frf --mistuned` and `montecarlo`.",
    "analysis": "Harmonic balance and continuation settings of every command.",
}


def _fields() -> list[Field]:
    """Every key with its reference value, read from :mod:`bladedamp.reference` (the values the
    paper does not give carry their reasons there)."""
    from . import reference as ref
    from .hbm.accuracy import HARMONIC_TOLERANCE
    from .studies.mistuning import PAPER_SEED, PAPER_STD

    g = ref.reference_blade_geometry()
    freqs, damping = ref.TABLE1_FREQUENCIES_HZ, ref.TABLE1_DAMPING_RATIOS
    from .solid import DEFAULT_ELEMENT_SIZE as SOLID_ELEMENT_SIZE     # solid.py imports gmsh only when meshing
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
              "modal data at named points (npz or CSV, see ModalBlade.from_file) instead of the beam model; "
              "needs OL, OR, tip and excitation", example="my_blade.npz"),
        Field("blade", "model", "beam", Choice(("beam", "solid")), "-",
              "beam: the paper's beam FE model, rigid platforms at OL / OR; solid: 3D quadratic tetrahedra of the "
              "same geometry ([blade.beam] sections and material, the platform faces at [disk] gamma_left_deg / "
              "gamma_right_deg), flexible platforms at every contact point (needs the fe extra; 7-16 s at 6 mm "
              "on 2 cores)"),
        Field("blade", "solid_element_size_mm", _tidy(SOLID_ELEMENT_SIZE, 1e-3), Number(0.5, 100.0), "mm",
              "solid model only: gmsh's element size; 6 mm: 28 800 DOF, the damped 1F peak 0.06 % in amplitude "
              "and 0.11 % in frequency from the 4.5 mm mesh's (README, flexible platforms)"),
        Field("blade", "n_modes", 4, Number(1, 40, integer=True), "-",
              "beam or solid model: 4 gives the paper's modes 1F, 2F, 1T, 1E; otherwise the lowest n by frequency"),
        Field("blade", "natural_frequencies_hz", list(freqs), Either((Choice(("model",)), List(Number(0.0, 1e6, "right")))),
              "Hz", "the paper's Table 1 (the beam or solid FE gives the shapes); 'model' keeps the model's or the "
              "file's own frequencies; one per mode"),
        Field("blade", "damping_ratio", _tidy(damping[0]) if len(set(damping)) == 1 else list(damping),
              Either((Number(0.0, 0.5), List(Number(0.0, 0.5)))), "-",
              "modal viscous damping D of every mode (paper: 0.001), or one per mode"),
        *[Field("blade.beam", k, v, c, u, r) for k, v, c, u, r in beam],
        Field("blade.beam", "tip_point_mm", None, List(Number(-1e4, 1e4), 3), "mm",
              "where the tip amplitude is read; default on the axis at the tip", example=[0.0, 0.0, 200.0]),
        Field("blade.beam", "excitation_point_mm", None, List(Number(-1e4, 1e4), 3), "mm",
              "where the excitation acts; default the tip point", example=[0.0, 0.0, 200.0]),
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
              "EO in [0, n_blades / 2], or a list (frf and eo-sweep run each; the others the first)"),
        Field("disk", "gamma_left_deg", _tidy(np.degrees(ref.PLATFORM_ANGLE)), Number(0.0, 90.0, "neither"), "deg",
              "platform angle at OL (paper: 35 deg)"),
        Field("disk", "gamma_right_deg", _tidy(np.degrees(ref.PLATFORM_ANGLE)), Number(0.0, 90.0, "neither"), "deg",
              "platform angle at OR (paper: 35 deg)"),
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
        raise DesignError(f"{path}: exists already (choose another name, or overwrite it with --force)")
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
    beam blade (None for modal data from a file)
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

    def visit(prefix: str, table: dict):
        for key, value in table.items():
            name = f"{prefix}.{key}" if prefix else key
            if name in by_table:
                if not isinstance(value, dict):
                    raise DesignError(f"{path}: {name} must be a table [{name}] (got {key} = {_toml(value)})")
                visit(name, value)
                continue
            if not prefix:
                raise DesignError(f"{path}: unknown table or key {name!r}{_suggest(name, by_table)}; allowed "
                                  f"tables: {', '.join(f'[{t}]' for t in by_table)}")
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
    line naming the file, key, value and allowed range for a bad field, an unknown key, a file
    that is missing or not TOML."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            raw = tomllib.load(fh)
    except FileNotFoundError:
        raise DesignError(f"{path}: no such design file (write the reference design with: "
                          f"bladedamp init {path})") from None
    except IsADirectoryError:
        raise DesignError(f"{path}: is a folder, not a design file") from None
    except OSError as exc:
        raise DesignError(f"{path}: cannot read the design file ({exc.strerror or exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(f"{path}: not valid TOML ({exc})") from None
    values, given = _read_values(path, raw)
    return _build(path, values, given, "mistuning" in raw)


def _build(path: Path, v: dict, given: set, has_mistuning: bool) -> Design:
    """The models of checked values ``v``; the checks that involve two keys are made here."""
    from .damper.geometry import ContactProperties, CylinderDamper, WedgeDamper
    from .disk import TunedDisk

    blade, geometry = _build_blade(path, v, given)
    d, k = v["disk"], v["damper"]
    n = d["n_blades"]
    eos = (d["engine_order"],) if isinstance(d["engine_order"], int) else tuple(d["engine_order"])
    if max(eos) > n // 2:
        raise _bad(path, "disk", "engine_order", d["engine_order"],
                   f"an integer or a list of integers in [0, {n // 2}] (n_blades / 2)")
    damper = None
    if k["kind"] != "none":
        contact = ContactProperties(k["friction_coefficient"], k["tangential_stiffness_per_length_n_per_m2"],
                                    k["normal_to_tangential_stiffness"], k["roughness_exponent"],
                                    k["roughness_reference_load_n"], k["points_along_length"],
                                    k["points_across_height"])
        mass, length = 1e-3 * k["mass_g"], 1e-3 * k["length_mm"]
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
    """The solid FE blade (:meth:`ModalBlade.from_solid`) of [blade.beam]'s geometry with the
    platform faces at the disk's platform angles (the contact kinematics need them to agree)."""
    from .blade import ModalBlade
    from .solid import SolidBladeGeometry

    d = v["disk"]
    try:
        sg = SolidBladeGeometry(beam=geometry, gamma_left=np.radians(d["gamma_left_deg"]),
                                gamma_right=np.radians(d["gamma_right_deg"]))
        options = {} if damping is None else {"damping_ratios": damping}
        return ModalBlade.from_solid(sg, 1e-3 * v["blade"]["solid_element_size_mm"], n_modes,
                                     natural_frequencies_hz=freqs, **options)
    except (ImportError, ValueError, RuntimeError) as exc:     # ImportError: the fe extra's one-line hint
        raise DesignError(f"{path}: [blade] model = 'solid': {exc}") from None


def _build_blade(path: Path, v: dict, given: set):
    """(ModalBlade, BeamBladeGeometry or None) of [blade] and [blade.beam]."""
    from .blade import BeamBladeGeometry, ModalBlade

    b, beam = v["blade"], v["blade.beam"]
    freqs, damping = b["natural_frequencies_hz"], b["damping_ratio"]
    solid = b["model"] == "solid"
    if b["modal_file"] is not None:
        if solid:
            raise DesignError(f"{path}: [blade] model = 'solid' builds the blade from [blade.beam]; with "
                              "modal_file remove model (or modal_file)")
        beam_keys = sorted(k for t, k in given if t == "blade.beam")
        if beam_keys or ("blade", "n_modes") in given:
            key = f"[blade.beam] {beam_keys[0]}" if beam_keys else "[blade] n_modes"
            raise DesignError(f"{path}: {key} applies to the beam model only; with [blade] modal_file remove it")
        if not hasattr(ModalBlade, "from_file"):
            raise DesignError(f"{path}: [blade] modal_file needs ModalBlade.from_file, which this bladedamp "
                              "version does not have")
        file = Path(b["modal_file"])
        file = file if file.is_absolute() else path.parent / file
        try:
            blade = ModalBlade.from_file(file)
        except (OSError, ValueError, KeyError) as exc:
            raise DesignError(f"{path}: [blade] modal_file = {_toml(b['modal_file'])}: {exc}") from None
        n_modes = blade.n_modes
        if ("blade", "natural_frequencies_hz") not in given:
            freqs = "model"
        if ("blade", "damping_ratio") not in given:
            damping = None
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
