"""Measured data beside predictions: frequency response functions and mode shapes from test files.

Readers
-------
* :func:`load_measurement` reads one measured response (an FRF, or a response spectrum) from a
  Universal File Format (UFF) file, dataset 58 (ASCII) or 58b (binary), or from a CSV file; it
  returns a :class:`MeasuredResponse` in SI units.
* :func:`load_modes` reads measured (or computed) normal modes, UFF dataset 55 or 2414, and
  returns :class:`MeasuredModes` in SI units;
  :meth:`bladedamp.blade.ModalBlade.from_test` builds a blade from them.
* :func:`draw_measurement` draws a measurement on the axes of a predicted tip-amplitude plot,
  converted to the plotted quantity (displacement amplitude); every frequency response's
  ``.plot(measured=...)`` calls it.

Units
-----
A UFF 58 record states what its ordinate is by its specific data types (8 displacement, 11
velocity, 12 acceleration, 13 excitation force) and, usually, by a units label ("m/s^2",
"g", "N"); the unit system is in dataset 164 of the same file (its factors f_L, f_F convert the
file's length and force to SI by division). The unit is taken from the labels when they are
given, else from the data types and dataset 164; where neither tells it, a ValueError names the
file and the record, and the caller states it (``unit="m/s^2/N"``). Units are written as
``<response>[/<force>]``: response ``m``, ``mm``, ``um``, ``in`` (displacement), the same over
``s`` (velocity), over ``s^2`` or ``g`` (acceleration); force ``N``, ``kN``, ``lbf``.

A CSV file has a header row naming its columns with the unit in brackets: ``frequency [Hz]``
and either ``re [m/N], im [m/N]`` (complex) or ``amplitude [mm]`` (amplitude); lines starting
with ``#`` are comments.
"""
from __future__ import annotations

import csv
import io as _stdio
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import palette
from .io import Saveable, reading
from .plotting import place_legend

#: file suffixes read as Universal File Format (a design file's [blade] modal_file of measured modes)
UFF_SUFFIXES = ("uff", "unv", "uf")
G_STANDARD = 9.80665                     #: standard gravity [m/s^2], the unit "g"

#: response quantity by its time derivative order: 0 displacement, 1 velocity, 2 acceleration
QUANTITIES = ("displacement", "velocity", "acceleration")
SI_RESPONSE_UNITS = ("m", "m/s", "m/s^2")
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6, "in": 0.0254, "ft": 0.3048}
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "lbf": 4.4482216152605}
#: UFF specific data type -> derivative order of a motion (8, 11, 12) or "force" (9, 13)
UFF_MOTION_TYPES = {8: 0, 11: 1, 12: 2}
UFF_FORCE_TYPES = (9, 13)
UFF_FUNCTION_TYPES = {0: "general or unknown function", 1: "time response", 2: "auto spectrum",
                      3: "cross spectrum", 4: "frequency response function", 5: "transmissibility",
                      6: "coherence", 7: "auto correlation", 8: "cross correlation",
                      9: "power spectral density", 10: "energy spectral density",
                      11: "probability density function", 12: "spectrum"}
#: function types read: an FRF (response over force) and a spectrum (response amplitude)
UFF_READ_FUNCTIONS = (4, 12)
DIRECTIONS = {0: "scalar", 1: "+x", 2: "+y", 3: "+z", 4: "+rx", 5: "+ry", 6: "+rz",
              -1: "-x", -2: "-y", -3: "-z", -4: "-rx", -5: "-ry", -6: "-rz"}


# ----- units --------------------------------------------------------------------------------
_UNIT = re.compile(r"^\s*(?P<len>[a-zµ]+)(?P<time>/s(\^?2|²)?)?(/(?P<force>[a-zA-Z]+))?\s*$")


def parse_unit(text: str) -> tuple[int, bool, float]:
    """(derivative order 0/1/2 of the response, whether it is per unit force, the factor to SI)
    of a unit such as "m/N", "mm", "m/s^2/N", "g/N", "in/s/lbf". ValueError for any other."""
    m = _UNIT.match(str(text).replace(" ", ""))
    if m:
        length, time, force = m["len"], m["time"], m["force"]
        if length == "g" and not time:
            order, factor = 2, G_STANDARD
        elif length in LENGTH_UNITS:
            order, factor = (0 if not time else 1 if time == "/s" else 2), LENGTH_UNITS[length]
        else:
            order = None
        if order is not None and (force is None or force in FORCE_UNITS):
            return order, force is not None, factor / (FORCE_UNITS[force] if force else 1.0)
    raise ValueError(f"unit {text!r} is not a response unit (expected e.g. 'm', 'mm', 'm/s', 'm/s^2', 'g', each "
                     f"optionally per force: 'm/N', 'm/s^2/N', 'mm/kN')")


def si_unit(order: int, per_force: bool) -> str:
    """The SI unit of a response of derivative ``order`` (0, 1, 2), per newton if ``per_force``."""
    return SI_RESPONSE_UNITS[order] + ("/N" if per_force else "")


# ----- the results --------------------------------------------------------------------------
@dataclass
class MeasuredResponse(Saveable):
    """One measured response over frequency, in SI units.

    Attributes
    ----------
    frequency_hz : (n,) frequencies [Hz]
    response : (n,) complex response (or real amplitudes, when the file gives amplitudes only)
        in ``unit``
    unit : SI unit of ``response``: "m", "m/s", "m/s^2" (a response spectrum) or the same per
        newton ("m/N", "m/s/N", "m/s^2/N": an FRF)
    point, direction : the response point (node number or name) and direction ("+x", "-z", ...;
        "" when the file does not say)
    reference_point, reference_direction : the excitation's point and direction of an FRF ("" if none)
    source : the file and record read (for labels)
    """

    frequency_hz: np.ndarray
    response: np.ndarray
    unit: str
    point: str = ""
    direction: str = ""
    reference_point: str = ""
    reference_direction: str = ""
    source: str = ""

    def __post_init__(self):
        self.frequency_hz = np.asarray(self.frequency_hz, dtype=float)
        self.response = np.asarray(self.response)
        if self.frequency_hz.ndim != 1 or self.response.shape != self.frequency_hz.shape:
            raise ValueError(f"frequency_hz and response must be (n,) arrays of one length (got shapes "
                             f"{self.frequency_hz.shape} and {self.response.shape})")
        if self.unit not in [si_unit(o, f) for o in range(3) for f in (False, True)]:
            raise ValueError(f"unit must be an SI response unit (m, m/s, m/s^2, each optionally /N) (got {self.unit!r})")

    @property
    def is_complex(self) -> bool:
        """Whether ``response`` holds complex values (amplitude and phase), not amplitudes only."""
        return np.iscomplexobj(self.response)

    @property
    def order(self) -> int:
        """Derivative order of the response: 0 displacement, 1 velocity, 2 acceleration."""
        return SI_RESPONSE_UNITS.index(self.unit.removesuffix("/N"))

    @property
    def per_force(self) -> bool:
        """Whether the response is per unit excitation force (an FRF)."""
        return self.unit.endswith("/N")

    @property
    def amplitude(self) -> np.ndarray:
        """(n,) |response| in ``unit``."""
        return np.abs(self.response)

    def as_displacement(self) -> "MeasuredResponse":
        """The same measurement as a displacement (m or m/N): velocity divided by i omega,
        acceleration by -omega^2 (amplitudes by omega and omega^2); nan at 0 Hz."""
        if self.order == 0:
            return self
        omega = 2 * np.pi * self.frequency_hz
        with np.errstate(divide="ignore", invalid="ignore"):
            div = (1j * omega) ** self.order if self.is_complex else omega ** self.order
            response = np.where(omega > 0, self.response / np.where(omega > 0, div, 1), np.nan)
        return MeasuredResponse(self.frequency_hz, response, si_unit(0, self.per_force), self.point, self.direction,
                                self.reference_point, self.reference_direction, self.source)

    def at_force(self, force_n: float) -> "MeasuredResponse":
        """An FRF times the excitation force amplitude ``force_n`` [N] (> 0): the response to it."""
        if not self.per_force:
            raise ValueError(f"at_force applies to an FRF (a unit per N); this response is in {self.unit}")
        if not (math.isfinite(force_n) and force_n > 0):
            raise ValueError(f"force_n must be a finite force amplitude > 0 N (got {force_n!r})")
        return MeasuredResponse(self.frequency_hz, self.response * force_n, self.unit[:-2], self.point, self.direction,
                                self.reference_point, self.reference_direction, self.source)

    @property
    def label(self) -> str:
        """A legend label: "measured", the point and direction."""
        point = f"node {self.point}" if self.point.isdigit() else self.point
        where = " ".join(s for s in (point, self.direction) if s)
        return f"measured{' ' + where if where else ''}"

    def plot(self, ax=None, **kwargs):
        """|response| over frequency [Hz] (log scale), in the plotted unit (mm for metres);
        returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        scale, unit = (1e3, "mm" + self.unit[1:]) if self.order == 0 else (1.0, self.unit)
        kwargs.setdefault("label", self.label)
        ax.semilogy(self.frequency_hz, scale * self.amplitude, color=palette.MEASURED, marker="o", ms=2.5,
                    lw=0.8, **kwargs)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"|response| [{unit}]")
        ax.grid(True, alpha=0.3)
        ax.legend()
        return ax


@dataclass
class MeasuredModes(Saveable):
    """Normal modes at the nodes of a test (or FE) model, in SI units.

    Attributes
    ----------
    natural_frequencies_hz : (n_m,) [Hz]
    damping_ratios : (n_m,) modal viscous damping ratios [-] (0 where the file gives none)
    modal_masses : (n_m,) modal masses [kg] of the shapes as stored, nan where the file gives none
    nodes : (n_nodes,) node numbers
    shapes : (n_nodes, 6, n_m) shape values (u_x, u_y, u_z, phi_x, phi_y, phi_z) per node and mode,
        in m and rad per the file's scaling: for unit modal mass (mass-normalised shapes) in
        m/sqrt(kg) and rad/sqrt(kg); rotations zero where the file gives translations only
    coordinates : (n_nodes, 3) node positions [m] from the file's nodes (dataset 15 or 2411),
        nan where it has none
    source : the file read
    """

    natural_frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    modal_masses: np.ndarray
    nodes: np.ndarray
    shapes: np.ndarray
    coordinates: np.ndarray
    source: str = ""

    def node_index(self, node: int) -> int:
        """Row of ``node`` in ``nodes``; ValueError naming the file if it has no such node."""
        hits = np.flatnonzero(self.nodes == int(node))
        if not hits.size:
            raise ValueError(f"{self.source}: no node {node} in the mode shapes (nodes {_few(self.nodes)})")
        return int(hits[0])

    def mass_normalised(self, modal_masses=None) -> np.ndarray:
        """(n_nodes, 6, n_m) shapes scaled to unit modal mass: divided by sqrt(m_j), m_j from
        ``modal_masses`` [kg] (scalar or (n_m,); 1 for shapes mass-normalised in kg, 1000 for
        shapes mass-normalised in tonnes, a file in mm, N, s) or else from the file; ValueError
        naming the file and the mode where neither gives it."""
        m = self.modal_masses if modal_masses is None else np.broadcast_to(
            np.asarray(modal_masses, dtype=float), self.natural_frequencies_hz.shape)
        bad = np.flatnonzero(~(np.isfinite(m) & (m > 0)))
        if bad.size:
            j = int(bad[0])
            raise ValueError(f"{self.source}: mode {j + 1} ({self.natural_frequencies_hz[j]:.6g} Hz) has no modal mass "
                             f"(the scaling of its shape cannot be told): give modal_masses [kg] > 0 per mode, or 1.0 "
                             f"for mass-normalised shapes")
        return self.shapes / np.sqrt(m)


# ----- reading UFF ---------------------------------------------------------------------------
def _uff_sets(path: Path) -> list[dict]:
    """Every dataset of the UFF file ``path`` as pyuff's dicts (inside a :func:`reading` block)."""
    import pyuff

    with open(path, "rb") as fh:
        lines = fh.read().split(b"\n")
    first = next((line.strip() for line in lines if line.strip()), b"")
    if first != b"-1":
        raise ValueError(f"{path}: not a Universal File Format file (it must begin with a '    -1' line)")
    opened = None                                # (line number, dataset type) of an unclosed block
    for number, line in enumerate(lines, start=1):
        # a binary 58b block's data run into its closing '    -1' without a line break
        binary_end = opened is not None and opened[1] == "58b" and line.rstrip().endswith(b"    -1")
        if line.strip() == b"-1" or binary_end:
            if opened is None:
                kind = lines[number].split()[:1] if number < len(lines) else []
                opened = (number, kind[0].decode("ascii", "replace") if kind else "?")
            else:
                opened = None
    if opened is not None:
        raise ValueError(f"{path}: line {opened[0]}: dataset {opened[1]} starting there has no closing -1 line "
                         "(the file is truncated); expected a complete UFF file")
    sets = pyuff.UFF(str(path)).read_sets()
    return [sets] if isinstance(sets, dict) else list(sets)


def _unit_factors(path: Path, sets: list[dict]) -> tuple[float, float] | None:
    """(f_L, f_F) of the file's dataset 164 (SI = file value / factor), or None without one."""
    units = [s for s in sets if s.get("type") == 164]
    if not units:
        return None
    length, force = float(units[0]["length"]), float(units[0]["force"])
    if not (length > 0 and force > 0):
        raise ValueError(f"{path}: dataset 164 (units) has length and force factors {length}, {force}; expected > 0")
    return length, force


def _label(s: dict, key: str) -> str:
    text = str(s.get(key, "") or "").strip()
    return "" if text.upper() == "NONE" else text


def _record_unit(path: Path, where: str, s: dict, factors) -> tuple[int, bool, float]:
    """(order, per force, factor to SI) of a dataset 58 record's ordinate."""
    num, den = _label(s, "ordinate_axis_units_lab"), _label(s, "orddenom_axis_units_lab")
    per_force = s["func_type"] == 4
    if num and (den or not per_force):
        text = f"{num}/{den}" if per_force else num
        try:
            return parse_unit(text)
        except ValueError as exc:
            raise ValueError(f"{path}: {where}: units label {text!r} cannot be read: {exc}") from None
    order = UFF_MOTION_TYPES.get(int(s.get("ordinate_spec_data_type", 0)))
    den_ok = not per_force or int(s.get("orddenom_spec_data_type", 0)) in UFF_FORCE_TYPES
    if order is None or not den_ok:
        raise ValueError(f"{path}: {where}: the ordinate is not a motion over a force (specific data types "
                         f"{s.get('ordinate_spec_data_type')} over {s.get('orddenom_spec_data_type')}; expected 8, 11 "
                         f"or 12 (displacement, velocity, acceleration) over 13 (excitation force))")
    if factors is None:
        raise ValueError(f"{path}: {where}: the unit cannot be told (no units label and no dataset 164 with "
                         f"the unit system): give it, e.g. unit='{si_unit(order, per_force)}'")
    length, force = factors
    return order, per_force, (1.0 / length) / (1.0 / force if per_force else 1.0)


def _read_uff58(path: Path, node, direction, record, unit, as_displacement) -> MeasuredResponse:
    sets = _uff_sets(path)
    records = [(k, s) for k, s in enumerate(sets) if s.get("type") == 58]
    if record is not None:
        if not (isinstance(record, int) and 0 <= record < len(records)):
            raise ValueError(f"{path}: record={record!r}: expected an index in [0, {len(records) - 1}] of the "
                             f"file's {len(records)} dataset 58 records")
        records = [records[record]]
    if not records:
        kinds = sorted({int(s.get("type", -1)) for s in sets})
        raise ValueError(f"{path}: no dataset 58 (a measured function) in the file (it holds datasets {kinds}); "
                         "expected a UFF 58 FRF export")
    if node is not None:
        records = [(k, s) for k, s in records if int(s.get("rsp_node", -1)) == int(node)]
    if direction is not None:
        records = [(k, s) for k, s in records if DIRECTIONS.get(int(s.get("rsp_dir", 0))) == direction]
    if len(records) != 1:
        have = [f"{s.get('rsp_node')} {DIRECTIONS.get(int(s.get('rsp_dir', 0)), '?')}" for _, s in
                ((k, s) for k, s in enumerate(sets) if s.get("type") == 58)]
        raise ValueError(f"{path}: {len(records)} dataset 58 records match node={node}, direction={direction}; "
                         f"expected one (the file's responses: {_few(have)}): choose with node= and direction=, or record=")
    k, s = records[0]
    where = f"dataset {k + 1} (UFF 58, response node {s.get('rsp_node')})"
    func = int(s.get("func_type", 0))
    if func not in UFF_READ_FUNCTIONS:
        raise ValueError(f"{path}: {where} holds a {UFF_FUNCTION_TYPES.get(func, f'function of type {func}')}; "
                         "expected a frequency response function (type 4) or a spectrum (type 12)")
    abscissa = _label(s, "abscissa_axis_units_lab")
    if abscissa.lower() != "hz" and (abscissa or int(s.get("abscissa_spec_data_type", 18)) not in (0, 18)):
        raise ValueError(f"{path}: {where}: the abscissa is not a frequency in Hz (specific data type "
                         f"{s.get('abscissa_spec_data_type')}, label {abscissa!r}); expected 18 / 'Hz'")
    if unit is not None:
        order, per_force, factor = parse_unit(unit)
    else:
        order, per_force, factor = _record_unit(path, where, s, _unit_factors(path, sets))
    if per_force != (func == 4):
        raise ValueError(f"{path}: {where}: unit {unit!r} does not fit a "
                         f"{UFF_FUNCTION_TYPES[func]}; expected a unit {'per force' if func == 4 else 'without a force'}")
    x, data = np.asarray(s["x"], dtype=float), np.asarray(s["data"])
    if x.shape != data.shape or x.size != int(s.get("num_pts", x.size)):
        raise ValueError(f"{path}: {where}: {data.size} values of {s.get('num_pts')} announced (truncated?)")
    out = MeasuredResponse(x, factor * data, si_unit(order, per_force), str(s.get("rsp_node", "")),
                           DIRECTIONS.get(int(s.get("rsp_dir", 0)), ""),
                           str(s.get("ref_node", "")) if func == 4 else "",
                           DIRECTIONS.get(int(s.get("ref_dir", 0)), "") if func == 4 else "", f"{path.name}, {where}")
    return out.as_displacement() if as_displacement else out


# ----- reading CSV ---------------------------------------------------------------------------
_HEADER = re.compile(r"^\s*(?P<name>[A-Za-z_ ]+?)\s*\[(?P<unit>[^\]]+)\]\s*$")


def _read_csv(path: Path, point, direction, unit, as_displacement) -> MeasuredResponse:
    text = path.read_text(encoding="utf-8")
    rows = [r for r in csv.reader(_stdio.StringIO(text)) if r and not r[0].lstrip().startswith("#")]
    if len(rows) < 2:
        raise ValueError(f"{path}: line 1: expected a header row (frequency [Hz], re [m/N], im [m/N] or "
                         "frequency [Hz], amplitude [mm]) and at least one row of numbers")
    columns = []
    for cell in rows[0]:
        m = _HEADER.match(cell)
        columns.append((m["name"].strip().lower(), m["unit"].strip()) if m else (cell.strip().lower(), ""))
    names = [c[0] for c in columns]
    layouts = (["frequency", "re", "im"], ["frequency", "amplitude"])
    if names not in layouts:
        raise ValueError(f"{path}: header {rows[0]!r}: expected the columns 'frequency [Hz], re [unit], im [unit]' "
                         "or 'frequency [Hz], amplitude [unit]'")
    if columns[0][1].lower() != "hz":
        raise ValueError(f"{path}: header: the frequency column must be in [Hz] (got {columns[0][1]!r})")
    units = {c[1] for c in columns[1:]}
    if len(units) != 1:
        raise ValueError(f"{path}: header: re and im must have one unit (got {sorted(units)})")
    stated = units.pop() or unit
    if not stated:
        raise ValueError(f"{path}: header: the unit cannot be told: write it in brackets (e.g. 're [m/N]') or give unit=")
    try:
        order, per_force, factor = parse_unit(stated)
    except ValueError as exc:
        raise ValueError(f"{path}: header: {exc}") from None
    values = np.empty((len(rows) - 1, len(names)))
    for i, row in enumerate(rows[1:]):
        try:
            if len(row) != len(names):
                raise ValueError(f"{len(row)} columns; expected {len(names)}")
            values[i] = [float(c) for c in row]
        except ValueError as exc:
            raise ValueError(f"{path}: data row {i + 1}: {exc}") from None
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{path}: data row {int(np.argmax(~np.all(np.isfinite(values), axis=1))) + 1}: not a finite number")
    response = values[:, 1] + 1j * values[:, 2] if names[1] == "re" else values[:, 1]
    out = MeasuredResponse(values[:, 0], factor * response, si_unit(order, per_force), str(point or ""),
                           str(direction or ""), source=path.name)
    return out.as_displacement() if as_displacement else out


# ----- the public functions -----------------------------------------------------------------
def load_measurement(path, *, node=None, direction=None, record: int | None = None, unit: str | None = None,
                     as_displacement: bool = False) -> MeasuredResponse:
    """Read one measured response from ``path``: a UFF file (dataset 58 or 58b: an FRF or a
    spectrum, ``.uff`` / ``.unv`` / ``.uf``) or a CSV file (``.csv``: see the module docstring).

    ``node``, ``direction`` ("+x", "-z", ...): choose the response of a UFF file holding several
    (or name the point of a CSV file); ``unit``: the unit of the file's values when the file does
    not tell it (a unit given here is taken over the file's) (e.g. "m/s^2/N", "g"); ``record``: the index (from 0) of the dataset 58 record
    among the file's; ``as_displacement``: convert a velocity or acceleration to
    displacement (divided by i omega or -omega^2). Returns a :class:`MeasuredResponse` in SI.
    Raises a :class:`~bladedamp.io.FileReadError` (a ValueError) naming the file, the place in it
    and what was expected: a missing, truncated or broken file, no dataset 58, a function that is
    not an FRF or spectrum, a unit that cannot be told."""
    path = Path(path)
    with reading(path, "measured response file (UFF 58 or CSV)"):
        if path.suffix.lower() == ".csv":
            return _read_csv(path, node, direction, unit, as_displacement)
        return _read_uff58(path, node, direction, record, unit, as_displacement)


def load_modes(path, *, units: str | None = None) -> MeasuredModes:
    """Read the normal modes of a UFF file (dataset 55 or 2414, analysis type 2: normal modes),
    with the node positions of its datasets 15 or 2411 where present. The unit system is the
    file's dataset 164; ``units="SI"`` states it for a file without one. Returns
    :class:`MeasuredModes` in SI. Raises a :class:`~bladedamp.io.FileReadError` naming the file
    and the dataset for a missing or broken file, no normal modes, complex modes, modes over
    different nodes, or units that cannot be told."""
    path = Path(path)
    with reading(path, "mode-shape file (UFF 55 or 2414)"):
        sets = _uff_sets(path)
        factors = _unit_factors(path, sets)
        if factors is None:
            if units not in ("SI", "si"):
                raise ValueError(f"{path}: no dataset 164 (the unit system): the units cannot be told; "
                                 "give units='SI' if the file is in m, kg, N")
            factors = (1.0, 1.0)
        f_len, f_force = factors
        f_mass = f_force / f_len                  # mass unit: force / (length / s^2)
        modes = []
        for k, s in enumerate(sets):
            kind = s.get("type")
            if kind not in (55, 2414):
                continue
            where = f"dataset {k + 1} (UFF {kind})"
            if int(s.get("analysis_type", -1)) != 2:
                raise ValueError(f"{path}: {where}: analysis type {s.get('analysis_type')}; expected 2 (normal modes: "
                                 "real shapes; complex modes are not read)")
            if kind == 55:
                nodes = np.asarray(s["node_nums"], dtype=int)
                cols = [np.asarray(s.get(f"r{i}", np.zeros(nodes.size)), dtype=float) for i in range(1, 7)]
                values = np.column_stack(cols)
                if int(s.get("data_ch", 2)) == 2:
                    values[:, 3:] = 0.0
                freq, mass, damp = s["freq"], s.get("modal_m", 0.0), s.get("modal_damp_vis", 0.0)
            else:
                if int(s.get("dataset_location", 1)) != 1:
                    raise ValueError(f"{path}: {where}: data at elements; expected data at nodes (location 1)")
                nodes = np.asarray(s["node_nums"], dtype=int)
                data = np.asarray(s["data_at_node"], dtype=float).reshape(nodes.size, -1)
                if data.shape[1] not in (3, 6):
                    raise ValueError(f"{path}: {where}: {data.shape[1]} values per node; expected 3 (translations) "
                                     "or 6 (translations and rotations)")
                values = np.zeros((nodes.size, 6))
                values[:, :data.shape[1]] = data
                # record 12 of a normal mode: time, frequency, eigenvalue, modal mass, viscous, hysteretic damping
                freq, mass, damp = (s.get(k, s.get(f"record12_field{i}", 0.0)) for k, i in
                                    (("frequency", 2), ("modal_mass", 4), ("viscous_damping", 5)))
            if values.shape[0] != nodes.size or not np.all(np.isfinite(values)):
                raise ValueError(f"{path}: {where}: {values.shape[0]} shape rows for {nodes.size} nodes, or values "
                                 "that are not finite numbers (truncated?)")
            if modes and not np.array_equal(nodes, modes[0][0]):
                raise ValueError(f"{path}: {where}: its nodes differ from the first mode's; expected every mode "
                                 "at the same nodes")
            modes.append((nodes, values, float(freq), float(mass), float(damp)))
        if not modes:
            raise ValueError(f"{path}: no dataset 55 or 2414 (mode shapes) in the file (it holds datasets "
                             f"{sorted({int(s.get('type', -1)) for s in sets})}); expected a UFF 55 or 2414 mode export")
        nodes = modes[0][0]
        shapes = np.stack([m[1] for m in modes], axis=-1)
        # lengths to m; a shape stored for modal mass m_j keeps its scaling (m_j converted below)
        shapes[:, :3] /= f_len
        masses = np.array([m[3] / f_mass if m[3] > 0 else np.nan for m in modes])
        coordinates = np.full((nodes.size, 3), np.nan)
        for s in sets:
            if s.get("type") in (15, 2411) and "x" in s:
                at = {int(n): i for i, n in enumerate(np.asarray(s["node_nums"], dtype=int))}
                for i, n in enumerate(nodes):
                    if int(n) in at:
                        j = at[int(n)]
                        coordinates[i] = np.array([s["x"][j], s["y"][j], s["z"][j]], dtype=float) / f_len
        return MeasuredModes(np.array([m[2] for m in modes]), np.array([m[4] for m in modes]), masses, nodes,
                             shapes, coordinates, str(path))


# ----- drawing beside a prediction -----------------------------------------------------------
def as_measurement(measured) -> MeasuredResponse:
    """``measured`` as a :class:`MeasuredResponse`: one given, or the file it names (:func:`load_measurement`)."""
    if isinstance(measured, MeasuredResponse):
        return measured
    if isinstance(measured, (str, Path)):
        return load_measurement(measured)
    raise TypeError(f"measured must be a MeasuredResponse or the path of a measurement file "
                    f"(got {type(measured).__name__})")


def draw_measurement(ax, measured, *, scale: float = 1e3, force_n: float | None = None, model=None):
    """Draw ``measured`` (a :class:`MeasuredResponse` or its file) on ``ax`` as the plotted
    quantity, a displacement amplitude times ``scale`` (1e3: mm): a velocity or acceleration is
    converted to displacement, an FRF multiplied by the force amplitude ``force_n`` [N] (or the
    excitation force |F| of ``model``, an object with ``excitation`` (6,)). Only the points
    inside the axes' frequency range are drawn when it holds data. Markers in
    :data:`bladedamp.palette.MEASURED`; the legend is placed clear of the data. Returns the line; ValueError for an FRF without a force."""
    m = as_measurement(measured).as_displacement()
    if m.per_force:
        if force_n is None and model is not None and getattr(model, "excitation", None) is not None:
            force_n = float(np.linalg.norm(np.asarray(model.excitation, dtype=float)[:3]))
        if force_n is None:
            raise ValueError(f"measured {m.source or 'response'} is an FRF ({m.unit}): its force amplitude is needed "
                             "to draw it beside a response: give measured.at_force(F [N])")
        m = m.at_force(force_n)
    f, y = m.frequency_hz, scale * m.amplitude
    if ax.has_data():
        lo, hi = ax.dataLim.intervalx
        keep = (f >= lo) & (f <= hi)
        f, y = f[keep], y[keep]
    (line,) = ax.plot(f, y, linestyle="none", marker="o", ms=3.5, mfc="none", color=palette.MEASURED,
                      label=m.label + (f", FRF x {force_n:g} N" if force_n else ""))
    old = ax.get_legend()
    size = old.get_texts()[0].get_fontsize() if old is not None and old.get_texts() else None
    place_legend(ax, **({"fontsize": size} if size else {}))     # clear of the peak and the markers
    return line


def _few(items, n: int = 8) -> str:
    items = [str(i) for i in items]
    return ", ".join(items[:n]) + (f", ... ({len(items)} in all)" if len(items) > n else "")


__all__ = ["MeasuredResponse", "MeasuredModes", "load_measurement", "load_modes", "draw_measurement",
           "parse_unit"]
