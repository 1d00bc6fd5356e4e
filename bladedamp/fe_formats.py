"""Reduced mass and stiffness matrices from finite-element exports (:meth:`ModalBlade.from_file`).

Every reader returns an :class:`FEMatrices`: the two matrices and, where the file numbers
its rows by node and DOF, the (node, component) label of every row. The formats:

Nastran OUTPUT4 (``.op4``), text or binary: matrices by name (e.g. KAA, MAA of an external
superelement, ``EXTSEOUT(... MATOP4=...)`` or the ``OUTPUT4`` module). Text files: a header
line per matrix (NCOL, NROW, FORM, TYPE as 8-character integers, the 8-character name and the
Fortran format of the numbers, e.g. ``1P,3E23.16``), then per column a line ICOL, IROW, NW
and its numbers: dense columns (IROW > 0) hold NW numbers from row IROW on; sparse columns
(IROW = 0) hold NW words in strings, each led by IS = IROW + 65536 (L + 1) (L data words),
or, when NROW < 0 ("bigmat"), by a line L, IROW (L - 1 data words). A double-precision
number is two words. The column NCOL + 1 ends the matrix. A header whose format ends in
``|I16`` (a dimension over 8 digits) gives NCOL and NROW in 16 characters each. Binary files:
the same records as Fortran unformatted records (4-byte length markers, either byte order) of
4-byte words, or, written by Nastran's 64-bit integer build (e.g. ``mode=i8``), of 8-byte words:
the header record is then 48 bytes (NCOL, NROW, FORM, TYPE as 8-byte integers and the name as
two words of 4 characters each, not 24), every integer is 8 bytes and every real number,
single or double precision, is one 8-byte word (the string lengths L count these words).
A name written again (e.g. one QHH per Mach number) is read as NAME#2, NAME#3, ...
OUTPUT4 does not record the node and DOF of a row: rows are numbered 1, 2, ... (in Nastran's
a-set order: grid and scalar point IDs ascending, components 1-6 of a grid, one row per
scalar point).

Nastran punch DMIG (``.pch``, ``PARAM,EXTOUT,DMIGPCH``): the bulk-data cards
``DMIG NAME 0 IFO TIN TOUT POLAR - NCOL`` (header) and ``DMIG NAME GJ CJ - G1 C1 A1 B1 ...``
(one column: entries at rows (G_i, C_i)), in small (8-character), large (``DMIG*``, 16-character)
or free (comma) fields; IFO = 6 stores one triangle of a symmetric matrix; TIN = 1, 2 real
(3, 4 complex: refused). Rows are labelled (grid, component), a scalar point's component is 0.

Abaqus matrix output (``.mtx``, ``*MATRIX GENERATE`` / ``*SUBSTRUCTURE MATRIX OUTPUT``):
``FORMAT=MATRIX INPUT`` lines ``row node, row DOF, column node, column DOF, value`` (one
triangle of the symmetric matrix; negative node numbers are Abaqus' internal nodes) or
``FORMAT=COORDINATE`` lines ``row, column, value`` (equation numbers, no labels); ``**``
lines are comments. Stiffness and mass are separate files (``job_STIF1.mtx``,
``job_MASS1.mtx``).

MATLAB (``.mat``): v4 to v7 through :func:`scipy.io.loadmat`, v7.3 (HDF5) through h5py
(the ``matlab`` extra);
dense or sparse real variables, or fields of scalar structs named as MATLAB writes them
(``nas.kaa.k0`` is field ``k0`` of field ``kaa`` of struct ``nas``); rows numbered 1, 2, ... as
MATLAB indexes them.

Ansys (``.full``, the assembled matrices of a modal or substructure run): through
ansys-mapdl-reader (the ``ansys`` extra; it brings pyvista and vtk). The stiffness and mass of
the free DOF; the constrained DOF (zero rows in the file) are left out. Rows are labelled
(node, component) with component = the reader's DOF index + 1: 1-3 UX, UY, UZ and 4-6 ROTX,
ROTY, ROTZ for a structural model with rotations.

The OUTPUT4 and DMIG readers are written here from the formats' published descriptions:
pyNastran, the usual Python reader, pins numpy < 2 and cannot be a dependency. Abaqus matrix
output has no maintained Python reader.

A file that breaks its format raises ValueError naming the file, the place in it (line,
record or variable) and what was expected.
"""
from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse

from .io import MissingFileError, reading

# file suffix -> format name, for ModalBlade.from_file
FE_SUFFIXES = {"op4": "op4", "pch": "dmig", "mtx": "abaqus", "mat": "matlab", "full": "ansys"}

# default matrix names, in the order they are looked for (case-insensitive); KXX, MXX are the
# names NX Nastran's EXTSEOUT(MATOP4=...) gives the a-set matrices in the .op4
DEFAULT_MASS_NAMES = ("MAAX", "MAA", "MXX", "M", "MASS")
DEFAULT_STIFFNESS_NAMES = ("KAAX", "KAA", "KXX", "K", "STIFFNESS")

# relative tolerance of the symmetry check of entries given in both triangles: exports print
# 7 to 17 significant digits
SYMMETRY_TOLERANCE = 1e-6


@dataclass(eq=False)
class FEMatrices:
    """Mass and stiffness matrices read from an FE export.

    mass, stiffness : (n, n) real symmetric matrices (dense arrays or scipy.sparse CSR),
        in the units of the exporting model.
    labels : (n, 2) int array of the (node, component) of every row, or None where the
        file numbers rows only (then rows are 1 ... n).
    path : the file (for Abaqus, the stiffness file); names : (mass, stiffness) matrix
        names or files.
    """

    mass: object
    stiffness: object
    labels: np.ndarray | None
    path: Path
    names: tuple[str, str]

    @property
    def n(self) -> int:
        return self.mass.shape[0]

    def row_indices(self, name: str, value) -> np.ndarray:
        """0-based rows of one ``dof_map`` entry (or ``fixed_dofs`` entry).

        Files with labels: ``node`` (components 1-6), ``(node, components)`` with
        components a sequence of 1-6 (or 0 for a scalar point), or a list of such entries
        (``fixed_dofs``). Files without: a sequence of 1-based row numbers.
        """
        if self.labels is None:
            try:
                rows = np.asarray(value)
            except ValueError:                # ragged, e.g. a (node, dofs) pair
                rows = np.zeros(0)
            if rows.ndim != 1 or rows.size == 0 or not np.issubdtype(rows.dtype, np.integer) \
                    or rows.min() < 1 or rows.max() > self.n:
                raise ValueError(f"{self.path}: {name} must be a sequence of row numbers in [1, {self.n}] "
                                 f"(this file numbers rows only, it has no node labels; got {value!r})")
            return rows - 1
        lookup = {(int(a), int(b)): i for i, (a, b) in enumerate(self.labels)}
        rows = []
        for node, comps in _node_entries(name, value):
            for c in comps:
                if (node, c) not in lookup:
                    nodes = np.unique(self.labels[:, 0])
                    have = sorted(int(b) for a, b in self.labels if a == node)
                    raise ValueError(
                        f"{self.path}: {name} names node {node} component {c}, which is not in the file "
                        f"({'node ' + str(node) + ' has components ' + str(have) if have else 'nodes in the file: ' + _some(nodes)}); "
                        "expected a node and component of the file's rows")
                rows.append(lookup[(node, c)])
        return np.array(rows, dtype=int)

    def describe_row(self, i: int) -> str:
        if self.labels is None:
            return f"row {i + 1}"
        return f"row {i + 1} (node {self.labels[i, 0]}, component {self.labels[i, 1]})"


def _some(values, k=8) -> str:
    vals = [int(v) for v in values]
    return ", ".join(map(str, vals[:k])) + (", ..." if len(vals) > k else "")


def _node_entries(name: str, value):
    """[(node, components)] of a dof_map entry: node, (node, components) or a list of them."""
    def one(v):
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            return int(v), (1, 2, 3, 4, 5, 6)
        if isinstance(v, tuple) and len(v) == 2 and isinstance(v[0], (int, np.integer)):
            comps = v[1]
            comps = (comps,) if isinstance(comps, (int, np.integer)) else tuple(comps)
            if comps and all(isinstance(c, (int, np.integer)) and 0 <= c <= 6 for c in comps):
                return int(v[0]), tuple(int(c) for c in comps)
        return None

    single = one(value)
    if single is not None:
        return [single]
    if isinstance(value, (list, tuple)) and value and all(one(v) is not None for v in value):
        return [one(v) for v in value]
    raise ValueError(f"{name} must be a node number, a tuple (node, components) with components in 0-6 "
                     f"(e.g. (101, (1, 2, 3, 4, 5, 6))) or a list of those (got {value!r})")


# --------------------------------------------------------------------------------------
# Entry lists -> matrices (shared by the readers)
# --------------------------------------------------------------------------------------
class _Entries:
    """COO entries of one matrix with the place (line, record or column number) each came from."""

    def __init__(self, name: str, kind: str):
        self.name, self.kind = name, kind     # kind names the place: "line", "record", ...
        self.complex = False
        self._single = ([], [], [], [])       # rows, cols, values, places of single entries
        self._blocks = []                     # (rows, cols, values, places) arrays

    def add(self, r, c, v, place):
        for store, x in zip(self._single, (r, c, v, place)):
            store.append(x)

    def add_block(self, rows, cols, values, places):
        """Many entries at once (arrays; cols and places may be scalars)."""
        rows = np.asarray(rows, dtype=np.int64)
        self._blocks.append((rows, np.broadcast_to(np.asarray(cols, dtype=np.int64), rows.shape),
                             np.asarray(values), np.broadcast_to(np.asarray(places), rows.shape)))

    def arrays(self):
        """(rows, cols, values, places) as arrays."""
        r, c, v, p = self._single
        dtype = complex if self.complex else float
        parts = [(np.asarray(r, dtype=np.int64), np.asarray(c, dtype=np.int64), np.asarray(v, dtype=dtype),
                  np.asarray(p, dtype=np.int64))] + self._blocks
        return tuple(np.concatenate([part[k] for part in parts]) for k in range(4))

    def relabel(self, remap: np.ndarray) -> None:
        """Replace every row and column index i by remap[i]."""
        r, c, v, p = self.arrays()
        self._single = ([], [], [], [])
        self._blocks = [(remap[r], remap[c], v, p)] if r.size else []

    @property
    def rows(self):
        return self.arrays()[0]

    @property
    def cols(self):
        return self.arrays()[1]

    @property
    def vals(self):
        return self.arrays()[2]


def _assemble(path: Path, e: _Entries, n_rows: int, n_cols: int, one_triangle: bool):
    """Square real symmetric CSR matrix of the entries; an entry given twice, a transposed
    partner that disagrees, or a non-square shape raise ValueError with the place."""
    where = f"{path}: matrix {e.name}"
    if e.complex:
        raise ValueError(f"{where} is complex; expected a real mass or stiffness matrix")
    if n_rows != n_cols:
        raise ValueError(f"{where} is {n_rows} x {n_cols}; expected a square matrix")
    r, c, v, places = e.arrays()
    v = v.astype(float)
    if not np.all(np.isfinite(v)):
        k = int(np.flatnonzero(~np.isfinite(v))[0])
        raise ValueError(f"{where}: {e.kind} {places[k]}: value {v[k]} is not finite; expected a finite number")
    key = r * n_cols + c
    order = np.argsort(key, kind="stable")
    sorted_keys = key[order]
    dup = np.flatnonzero(np.diff(sorted_keys) == 0)
    if dup.size:
        a, b = order[dup[0]], order[dup[0] + 1]
        raise ValueError(f"{where}: {e.kind} {places[b]}: entry ({r[b] + 1}, {c[b] + 1}) is given again "
                         f"(first at {e.kind} {places[a]}); expected each entry once")
    tkey = c * n_cols + r
    at = np.minimum(np.searchsorted(sorted_keys, tkey), max(key.size - 1, 0))
    found = key.size > 0
    partner = np.where(found & (sorted_keys[at] == tkey), order[at], -1) if key.size else np.zeros(0, np.int64)
    scale = np.abs(v).max() if v.size else 0.0
    both = np.flatnonzero((partner >= 0) & (r != c))
    if both.size:
        gap = np.abs(v[both] - v[partner[both]])
        worst = int(np.argmax(gap))
        if gap[worst] > SYMMETRY_TOLERANCE * scale:
            k = both[worst]
            raise ValueError(
                f"{where}: {e.kind} {places[k]}: entry ({r[k] + 1}, {c[k] + 1}) = {v[k]:.9g} but its "
                f"transpose at {e.kind} {places[partner[k]]} is {v[partner[k]]:.9g}; expected a symmetric "
                f"matrix (relative difference <= {SYMMETRY_TOLERANCE:g})")
    lonely = np.flatnonzero((partner < 0) & (r != c))
    if lonely.size and not one_triangle:
        # a full-storage matrix with an entry whose transpose is absent (zero) is unsymmetric
        gap = np.abs(v[lonely])
        worst = int(np.argmax(gap))
        if gap[worst] > SYMMETRY_TOLERANCE * scale:
            k = lonely[worst]
            raise ValueError(
                f"{where}: {e.kind} {places[k]}: entry ({r[k] + 1}, {c[k] + 1}) = {v[k]:.9g} has no "
                f"transposed entry ({c[k] + 1}, {r[k] + 1}); expected a symmetric matrix")
    rr = np.concatenate([r, c[lonely]])
    cc = np.concatenate([c, r[lonely]])
    vv = np.concatenate([v, v[lonely]])
    A = scipy.sparse.csr_matrix((vv, (rr, cc)), shape=(n_rows, n_cols))
    return (A + A.T) * 0.5


# --------------------------------------------------------------------------------------
# Nastran OUTPUT4
# --------------------------------------------------------------------------------------
_OP4_FORMAT = re.compile(r"(\d+)\s*[EDG](\d+)\.(\d+)", re.IGNORECASE)


def _op4_words_per_number(ntype: int) -> int:
    return 2 if ntype in (2, 4) else 1


def _unique_name(existing: dict, name: str) -> str:
    """``name``, or ``name#2``, ``name#3``, ... for its second, third matrix of that name."""
    k, key = 1, name
    while key in existing:
        k += 1
        key = f"{name}#{k}"
    return key


def read_op4(path) -> dict:
    """All matrices of an OUTPUT4 file (text or binary) by name: name -> (entries, nrow, ncol, form).
    A name that occurs again (e.g. one QHH per Mach number) is ``name#2``, ``name#3``, ..."""
    path = Path(path)
    data = path.read_bytes()
    if not data:
        raise ValueError(f"{path}: the file is empty; expected Nastran OUTPUT4 matrices")
    if _op4_binary_layout(data) is not None:
        return _read_op4_binary(path, data)
    return _read_op4_text(path, data)


def _read_op4_text(path: Path, data: bytes) -> dict:
    try:
        lines = data.decode("ascii").splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: neither a text nor a binary OUTPUT4 file (a binary file starts with a "
                         "24-byte header record)") from None
    matrices = {}
    i = 0
    n_lines = len(lines)

    def ints(k, count, what, free=False):
        """count integers of line k: 8-character fields (free: separated by blanks)."""
        line = lines[k] if k < n_lines else None
        if line is None:
            raise ValueError(f"{path}: line {k + 1}: the file ends; expected {what}")
        fields = line.split() if free else [line[8 * j:8 * j + 8] for j in range(count)]
        try:
            if len(fields) < count:
                raise ValueError
            return [int(f) for f in fields[:count]]
        except ValueError:
            raise ValueError(f"{path}: line {k + 1}: expected {what} as {count} 8-character integers "
                             f"(got {line.rstrip()!r})") from None

    while i < n_lines:
        if not lines[i].strip():
            i += 1
            continue
        # NCOL and NROW in 16 characters where the format ends in |I16 (a dimension over 8 digits)
        wide = lines[i].rstrip().upper().endswith("|I16")
        if wide:
            head = lines[i]
            try:
                ncol, nrow, form, ntype = (int(head[a:b]) for a, b in ((0, 16), (16, 32), (32, 40), (40, 48)))
            except ValueError:
                raise ValueError(f"{path}: line {i + 1}: expected a matrix header NCOL, NROW (16 characters each: "
                                 f"the format ends in |I16), FORM, TYPE, NAME, format (got {head.rstrip()!r})") from None
        else:
            ncol, nrow, form, ntype = ints(i, 4, "a matrix header NCOL, NROW, FORM, TYPE, NAME, format")
        name = lines[i][48:56].strip() if wide else lines[i][32:40].strip()
        fmt = _OP4_FORMAT.search(lines[i][56:] if wide else lines[i][40:])
        if not name or fmt is None or ntype not in (1, 2, 3, 4) or ncol < 0:
            raise ValueError(f"{path}: line {i + 1}: expected a matrix header NCOL, NROW, FORM, TYPE (1-4), "
                             f"NAME, format such as 1P,3E23.16 (got {lines[i].rstrip()!r})")
        per_line, width = int(fmt.group(1)), int(fmt.group(2))
        bigmat = nrow < 0
        nrow = abs(nrow)
        wpn = _op4_words_per_number(ntype)
        e = _Entries(name, "line")
        e.complex = ntype in (3, 4)
        header_line = i + 1
        i += 1

        def numbers(k, count):
            """count numbers from line k on (per_line per line, fixed width); returns (values, next line)."""
            values = []
            while len(values) < count:
                if k >= n_lines:
                    raise ValueError(f"{path}: line {k + 1}: the file ends inside matrix {name} (header at "
                                     f"line {header_line}); expected {count - len(values)} more numbers")
                line = lines[k]
                take = min(per_line, count - len(values))
                for j in range(take):
                    field = line[width * j:width * (j + 1)]
                    try:
                        values.append(float(field.replace("D", "E").replace("d", "e")))
                    except ValueError:
                        raise ValueError(f"{path}: line {k + 1}: expected a number in columns "
                                         f"{width * j + 1}-{width * (j + 1)} (got {field!r})") from None
                k += 1
            return values, k

        def store(col, row0, values, line_no):
            values = np.array(values)
            if e.complex:
                values = values[0::2] + 1j * values[1::2]
            if row0 < 1 or row0 - 1 + values.size > nrow:
                raise ValueError(f"{path}: line {line_no}: rows {row0}..{row0 + values.size - 1} of column {col} "
                                 f"fall outside the {nrow} rows of matrix {name}")
            nz = np.flatnonzero(values)
            e.add_block(row0 - 1 + nz, col - 1, values[nz], line_no)

        while True:
            icol, irow, nw = ints(i, 3, f"a column record ICOL, IROW, NW of matrix {name}")
            rec_line = i + 1
            i += 1
            if icol == ncol + 1:             # end of the matrix: one dummy column
                _, i = numbers(i, max(nw, 1) if irow else 0)
                break
            if not 1 <= icol <= ncol:
                raise ValueError(f"{path}: line {rec_line}: column {icol} of matrix {name} is outside 1..{ncol + 1}")
            if irow > 0:                     # dense column: NW numbers from row IROW
                values, i = numbers(i, nw)
                store(icol, irow, values, rec_line)
                continue
            used = 0                          # sparse column: NW words in strings
            while used < nw:
                if bigmat:
                    length, row0 = ints(i, 2, f"a string header L, IROW of matrix {name}", free=True)
                    n_words, used = length - 1, used + length + 1
                else:
                    (packed,) = ints(i, 1, f"a string header IS = IROW + 65536 (L + 1) of matrix {name}",
                                     free=True)
                    n_words = packed // 65536 - 1
                    row0 = packed - 65536 * (n_words + 1)
                    used += n_words + 1
                string_line = i + 1
                i += 1
                if n_words < 0 or n_words % wpn:
                    raise ValueError(f"{path}: line {string_line}: string of {n_words} words in matrix {name}; "
                                     f"expected a multiple of {wpn} words (TYPE {ntype})")
                values, i = numbers(i, n_words // wpn)
                store(icol, row0, values, string_line)
            if used != nw:
                raise ValueError(f"{path}: line {rec_line}: column {icol} of matrix {name} has strings of "
                                 f"{used} words; expected NW = {nw}")
        matrices[_unique_name(matrices, name)] = (e, nrow, ncol, form)
    if not matrices:
        raise ValueError(f"{path}: no matrix found; expected Nastran OUTPUT4 matrices")
    return matrices


def _op4_binary_layout(data: bytes):
    """(byte order, word size in bytes) of a binary OUTPUT4 file from its first record's
    length marker: 24 (4-byte words: NCOL, NROW, FORM, TYPE and an 8-character name) or 48
    (8-byte words, Nastran's 64-bit integer build: the four integers in 8 bytes each and the
    name as two 8-byte words of 4 characters each); None for neither."""
    if len(data) < 4:
        return None
    for order in ("<", ">"):
        marker = struct.unpack(order + "i", data[:4])[0]
        if marker in (24, 48):
            return order, marker // 6
    return None


def _read_op4_binary(path: Path, data: bytes) -> dict:
    """Binary OUTPUT4: Fortran unformatted records (4-byte length markers) of words of 4 bytes
    (a single-precision real is one word, a double-precision real two) or, from Nastran's 64-bit
    integer build, of 8 bytes (every integer and every real, single or double, one word)."""
    order, word = _op4_binary_layout(data)
    integer = order + ("i" if word == 4 else "q")
    header_bytes = 6 * word
    matrices = {}
    pos, record = 0, 0

    def read_record():
        nonlocal pos, record
        record += 1
        if pos + 4 > len(data):
            raise ValueError(f"{path}: record {record} (byte {pos}): the file ends; expected a Fortran record")
        (size,) = struct.unpack(order + "i", data[pos:pos + 4])
        end = pos + 4 + size
        if size < 0 or end + 4 > len(data) or struct.unpack(order + "i", data[end:end + 4])[0] != size:
            raise ValueError(f"{path}: record {record} (byte {pos}): length marker {size} does not match; "
                             "expected a complete Fortran unformatted record (is the file truncated?)")
        body = data[pos + 4:end]
        pos = end + 4
        return body

    def ints(body, count, at=0):
        return struct.unpack(order + f"{count}{integer[-1]}", body[at * word:(at + count) * word])

    while pos < len(data):
        body = read_record()
        if len(body) != header_bytes:
            raise ValueError(f"{path}: record {record}: {len(body)} bytes; expected a {header_bytes}-byte matrix "
                             f"header (NCOL, NROW, FORM, TYPE, NAME in {word}-byte words, as the file's first record)")
        ncol, nrow, form, ntype = ints(body, 4)
        raw_name = body[4 * word:]
        if word == 8:                         # two words of 4 characters each
            raw_name = raw_name[:4] + raw_name[8:12]
        name = raw_name.decode("ascii", "replace").strip()
        if ntype not in (1, 2, 3, 4):
            raise ValueError(f"{path}: record {record}: matrix {name!r} has TYPE {ntype}; expected 1-4")
        bigmat = nrow < 0
        nrow = abs(nrow)
        # words per real number: 4-byte words hold a single (TYPE 1, 3) or half a double (2, 4)
        wpn = _op4_words_per_number(ntype) if word == 4 else 1
        real_fmt = "f" if word == 4 and wpn == 1 else "d"
        e = _Entries(name, "record")
        e.complex = ntype in (3, 4)
        while True:
            body = read_record()
            if len(body) < 3 * word:
                raise ValueError(f"{path}: record {record}: {len(body)} bytes; expected a column record of matrix {name}")
            icol, irow, nw = ints(body, 3)
            words = body[3 * word:]
            if icol == ncol + 1:              # end of the matrix: one dummy column
                break
            if len(words) != word * nw:
                raise ValueError(f"{path}: record {record}: {len(words) // word} data words; expected NW = {nw} "
                                 f"(column {icol} of matrix {name}, {word}-byte words)")
            if not 1 <= icol <= ncol:
                raise ValueError(f"{path}: record {record}: column {icol} of matrix {name} is outside 1..{ncol + 1}")

            def store(row0, chunk):
                values = np.frombuffer(chunk, dtype=order + real_fmt).astype(float)
                if e.complex:
                    values = values[0::2] + 1j * values[1::2]
                if row0 < 1 or row0 - 1 + values.size > nrow:
                    raise ValueError(f"{path}: record {record}: rows {row0}..{row0 + values.size - 1} of column "
                                     f"{icol} fall outside the {nrow} rows of matrix {name}")
                nz = np.flatnonzero(values)
                e.add_block(row0 - 1 + nz, icol - 1, values[nz], record)

            if irow > 0:
                if nw % (wpn * (2 if e.complex else 1)):
                    raise ValueError(f"{path}: record {record}: {nw} data words in column {icol} of matrix {name}; "
                                     f"expected whole numbers of {wpn} word(s) each (TYPE {ntype})")
                store(irow, words)
                continue
            w = 0
            while w < nw:
                if bigmat:
                    if w + 2 > nw:
                        raise ValueError(f"{path}: record {record}: a string header L, IROW at word {w} runs past "
                                         f"the column's {nw} words")
                    length, row0 = ints(words, 2, w)
                    n_words, start = length - 1, w + 2
                else:
                    (packed,) = ints(words, 1, w)
                    n_words = packed // 65536 - 1
                    row0, start = packed - 65536 * (n_words + 1), w + 1
                per = wpn * (2 if e.complex else 1)
                if n_words < 0 or n_words % per or start + n_words > nw:
                    raise ValueError(f"{path}: record {record}: a string of {n_words} words at word {w}; "
                                     f"expected a multiple of {per} inside the column's {nw} words")
                store(row0, words[word * start:word * (start + n_words)])
                w = start + n_words
        matrices[_unique_name(matrices, name)] = (e, nrow, ncol, form)
    return matrices


# --------------------------------------------------------------------------------------
# Nastran punch DMIG
# --------------------------------------------------------------------------------------
def _nastran_float(text: str) -> float:
    try:
        return float(text)                    # the common case: 1.234E+05
    except ValueError:
        pass
    s = text.strip().upper().replace("D", "E")
    if not s:
        return 0.0
    if "E" not in s:                          # Nastran's implicit exponent: 1.5-3 = 1.5E-3
        s = re.sub(r"(?<=[0-9.])([+-])(\d+)$", r"E\1\2", s)
    return float(s)


def _bulk_cards(path: Path, text: str):
    """Yield (first line number, card name, data fields) of every bulk card, continuations joined.
    A ``$`` comment line ends a card (a punch file's result sections start with ``$`` headers),
    and data lines with no card before them (such result lines) are skipped."""
    card, start, card_name = None, 0, ""
    for number, raw in enumerate(text.splitlines(), start=1):
        if raw.startswith("$"):
            if card is not None:
                yield start, card_name, card
            card = None
            continue
        line = raw.split("$", 1)[0].rstrip()
        if not line.strip():
            continue
        if "," in line:
            fields = [f.strip() for f in line.split(",")]
            head, data = fields[0], fields[1:]
            large = head.endswith("*")
        else:
            head = line[:8].strip()
            large = head.endswith("*") or (head.startswith("*") and card is not None)
            width = 16 if large else 8
            data = [line[8 + width * j:8 + width * (j + 1)].strip() for j in range(4 if large else 8)]
        is_continuation = head == "" or head.startswith("+") or (head.startswith("*") and len(head) <= 8
                                                                 and not head.rstrip("*").isalpha())
        if is_continuation:
            if card is not None:
                card.extend(data)
            continue
        if card is not None:
            yield start, card_name, card
        card_name, card, start = head.rstrip("*").upper(), list(data), number
    if card is not None:
        yield start, card_name, card


def read_dmig(path) -> dict:
    """All real DMIG matrices of a punch (or bulk data) file: name -> (entries, labels, ifo)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="ascii")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file; expected Nastran punch DMIG cards") from None
    headers, columns = {}, {}
    for line, name, f in _bulk_cards(path, text):
        if name != "DMIG":
            continue
        f = f + [""] * (8 - len(f)) if len(f) < 8 else f
        mname = f[0].upper()
        if not mname:
            raise ValueError(f"{path}: line {line}: DMIG card without a matrix name")
        try:
            if f[1] == "0":                  # header: NAME 0 IFO TIN TOUT POLAR - NCOL
                headers[mname] = (int(f[2]), int(f[3]), line)
                columns.setdefault(mname, [])
                continue
            gj, cj = int(f[1]), int(f[2] or 0)
        except ValueError:
            raise ValueError(f"{path}: line {line}: DMIG {mname}: expected integers (GJ, CJ or IFO, TIN) in "
                             f"fields 2-4 (got {f[1:4]})") from None
        if mname not in headers:
            raise ValueError(f"{path}: line {line}: DMIG {mname} column before its header card "
                             "(DMIG NAME 0 IFO TIN ...); expected the header first")
        entries = f[4:]
        if len(entries) % 4:
            entries = entries + [""] * (4 - len(entries) % 4)
        for k in range(0, len(entries), 4):
            g, c, a, b = entries[k:k + 4]
            if not g and not a:
                continue
            try:
                columns[mname].append((gj, cj, int(g), int(c or 0), _nastran_float(a), _nastran_float(b), line))
            except ValueError:
                raise ValueError(f"{path}: line {line}: DMIG {mname} column ({gj}, {cj}): expected G, C, A "
                                 f"(integer, integer, number) (got {g!r}, {c!r}, {a!r})") from None
    if not headers:
        raise ValueError(f"{path}: no DMIG card found; expected Nastran punch DMIG matrices "
                         "(DMIG NAME 0 IFO TIN ... header and column cards)")
    result = {}
    for mname, (ifo, tin, hline) in headers.items():
        cols = columns[mname]
        labels = sorted({(r[0], r[1]) for r in cols} | {(r[2], r[3]) for r in cols})
        index = {lab: k for k, lab in enumerate(labels)}
        e = _Entries(mname, "line")
        e.complex = tin in (3, 4)
        if tin not in (1, 2, 3, 4):
            raise ValueError(f"{path}: line {hline}: DMIG {mname} has TIN = {tin}; expected 1-4")
        for gj, cj, g, c, a, b, line in cols:
            e.add(index[(g, c)], index[(gj, cj)], complex(a, b) if e.complex else a, line)
        result[mname] = (e, np.array(labels, dtype=np.int64).reshape(-1, 2), ifo)
    return result


# --------------------------------------------------------------------------------------
# Abaqus matrix output
# --------------------------------------------------------------------------------------
def read_abaqus_mtx(path):
    """(entries, labels or None) of one Abaqus .mtx file (MATRIX INPUT or COORDINATE format)."""
    path = Path(path)
    if not path.is_file():
        raise MissingFileError(f"{path}: no such Abaqus matrix file (the {'mass' if '_MASS' in path.name.upper() else 'other'} "
                               "matrix beside the one given; name it with mass= or stiffness=)")
    try:
        text = path.read_text(encoding="ascii")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file; expected Abaqus matrix output lines "
                         "'node, dof, node, dof, value'") from None
    lines = text.splitlines()
    fast = _abaqus_fast(lines)
    if fast is not None:
        ints, values, numbers = fast
        return _abaqus_entries(path, ints, values, numbers)
    records, n_fields = [], None
    for number, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        parts = [p.strip() for p in line.split(",")]
        if parts and parts[-1] == "":
            parts = parts[:-1]
        if n_fields is None:
            n_fields = len(parts)
            if n_fields not in (3, 5):
                raise ValueError(f"{path}: line {number}: {len(parts)} comma-separated fields; expected 5 "
                                 "(node, dof, node, dof, value: FORMAT=MATRIX INPUT) or 3 (row, column, value: "
                                 "FORMAT=COORDINATE)")
        if len(parts) != n_fields:
            raise ValueError(f"{path}: line {number}: {len(parts)} comma-separated fields; expected {n_fields} "
                             "as on the first data line")
        try:
            ints = [int(p) for p in parts[:-1]]
            value = float(parts[-1].replace("D", "E").replace("d", "e"))
        except ValueError:
            what = "node, dof, node, dof, value" if n_fields == 5 else "row, column, value"
            raise ValueError(f"{path}: line {number}: expected {what} (integers, then a number); got {line!r}") from None
        records.append((ints, value, number))
    if not records:
        raise ValueError(f"{path}: no matrix entries; expected Abaqus matrix output lines 'node, dof, node, dof, value'")
    return _abaqus_entries(path, np.array([r[0] for r in records], dtype=np.int64),
                           np.array([r[1] for r in records]), np.array([r[2] for r in records]))


def _abaqus_fast(lines):
    """(integer columns, values, line numbers) of a well-formed .mtx file by numpy, or None
    (then the line-by-line reading finds and names the bad line)."""
    numbered = [(k, line) for k, line in enumerate(lines, start=1)
                if line.strip() and not line.lstrip().startswith("**")]
    if not numbered:
        return None
    try:
        table = np.loadtxt([line.rstrip().rstrip(",") for _, line in numbered], delimiter=",", ndmin=2)
    except ValueError:
        return None
    if table.shape[1] not in (3, 5):
        return None
    ints = table[:, :-1]
    if np.any(ints != np.round(ints)) or np.abs(ints).max() > 2**31:
        return None
    return ints.astype(np.int64), table[:, -1], np.array([k for k, _ in numbered], dtype=np.int64)


def _abaqus_entries(path: Path, ints: np.ndarray, values: np.ndarray, numbers: np.ndarray):
    """(entries, labels or None, n) of the integer columns and values of an .mtx file."""
    e = _Entries(path.name, "line")
    if ints.shape[1] == 4:
        pairs = np.vstack([ints[:, :2], ints[:, 2:]])
        labels, inverse = np.unique(pairs, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
        m = ints.shape[0]
        e.add_block(inverse[:m], inverse[m:], values, numbers)
        return e, labels.astype(np.int64), len(labels)
    bad = np.flatnonzero((ints < 1).any(axis=1))
    if bad.size:
        k = bad[0]
        raise ValueError(f"{path}: line {numbers[k]}: equation numbers must be >= 1 (got {ints[k, 0]}, {ints[k, 1]})")
    e.add_block(ints[:, 0] - 1, ints[:, 1] - 1, values, numbers)
    return e, None, int(ints.max())


# --------------------------------------------------------------------------------------
# MATLAB
# --------------------------------------------------------------------------------------
def read_matlab(path) -> dict:
    """Variables of a .mat file (v4-v7 or v7.3): name -> dense array or CSR matrix; the fields of
    a scalar struct (at any depth) as ``struct.field``, the struct itself not listed."""
    path = Path(path)
    import scipy.io
    try:
        data = scipy.io.loadmat(path)
    except NotImplementedError:              # v7.3: an HDF5 file
        return _read_matlab_hdf5(path)
    except (ValueError, TypeError, OSError, scipy.io.matlab.MatReadError) as err:
        if _is_hdf5(path):                   # an HDF5 .mat without MATLAB's text header
            return _read_matlab_hdf5(path)
        raise ValueError(f"{path}: not a readable MATLAB .mat file ({err}); expected a MAT-file v4-v7.3") from None
    out = {}

    def add(name, value):
        if isinstance(value, np.ndarray) and value.dtype.names and value.size == 1:    # a scalar struct
            for field in value.dtype.names:
                add(f"{name}.{field}", value.flat[0][field])
        else:
            out[name] = value

    for k, v in data.items():
        if not k.startswith("__"):
            add(k, v)
    return out


def _is_hdf5(path: Path) -> bool:
    """Whether the file carries the HDF5 signature at offset 0, 512, 1024, ... (a user block)."""
    signature = b"\x89HDF\r\n\x1a\n"
    with open(path, "rb") as fh:
        data = fh.read(1 << 16)
    return any(data[k:k + 8] == signature for k in [0] + [512 << j for j in range(7)])


def _read_matlab_hdf5(path: Path) -> dict:
    try:
        import h5py
    except ImportError:
        raise ValueError(f"{path}: a MATLAB v7.3 (HDF5) file needs h5py: pip install bladedamp[matlab]") from None
    out = {}
    with h5py.File(path, "r") as f:
        items = list(f.items())
        while items:
            name, item = items.pop(0)
            if name.split(".")[-1].startswith("#"):
                continue
            if isinstance(item, h5py.Group) and "MATLAB_sparse" not in item.attrs:    # a struct
                items[:0] = [(f"{name}.{k}", v) for k, v in item.items()]
            elif isinstance(item, h5py.Group) and "MATLAB_sparse" in item.attrs:
                n_rows = int(item.attrs["MATLAB_sparse"])
                jc = item["jc"][()]
                data = item["data"][()] if "data" in item else np.zeros(0)
                ir = item["ir"][()] if "ir" in item else np.zeros(0, dtype=np.int64)
                out[name] = scipy.sparse.csc_matrix((data, ir, jc), shape=(n_rows, jc.size - 1)).tocsr()
            elif isinstance(item, h5py.Dataset):
                arr = item[()]
                if arr.dtype.names and {"real", "imag"} <= set(arr.dtype.names):
                    arr = arr["real"] + 1j * arr["imag"]
                out[name] = np.asarray(arr).T     # MATLAB stores column-major
    return out


# --------------------------------------------------------------------------------------
# Ansys
# --------------------------------------------------------------------------------------
def read_ansys_full(path) -> FEMatrices:
    """Stiffness and mass of the free DOF of an Ansys .full file (through ansys-mapdl-reader)."""
    path = Path(path)
    try:
        from ansys.mapdl import reader as mapdl_reader
    except ImportError:
        raise ValueError(f"{path}: reading an Ansys .full file needs ansys-mapdl-reader: "
                         "pip install bladedamp[ansys]") from None
    try:
        full = mapdl_reader.read_binary(str(path))
        if type(full).__name__ != "FullFile":
            raise ValueError(f"a {type(full).__name__}")
        dof_ref, K, M = full.load_km(as_sparse=True, sort=True)
    except Exception as err:    # the library raises many types on a bad file; report its words
        raise ValueError(f"{path}: not a readable Ansys .full file ({type(err).__name__}: {err}); "
                         "expected the .full file of a modal or substructure run (WRFULL or a solve)") from None
    labels = np.asarray(dof_ref, dtype=np.int64) + np.array([0, 1])
    K, M = scipy.sparse.csr_matrix(K), scipy.sparse.csr_matrix(M)
    free = np.flatnonzero((abs(K).sum(axis=1).A1 != 0) | (abs(M).sum(axis=1).A1 != 0))
    out = []
    for name, A in (("mass", M), ("stiffness", K)):
        A = A[free][:, free]
        upper = scipy.sparse.triu(A, 1)
        lower = scipy.sparse.tril(A, -1)
        if lower.nnz and upper.nnz and abs(upper - lower.T).max() > SYMMETRY_TOLERANCE * abs(A).max():
            raise ValueError(f"{path}: the {name} matrix is unsymmetric; expected a symmetric matrix")
        if not lower.nnz:                    # the file stores one triangle
            A = A + upper.T
        out.append(scipy.sparse.csr_matrix(A))
    return FEMatrices(mass=out[0], stiffness=out[1], labels=labels[free], path=path, names=("mass", "stiffness"))


# --------------------------------------------------------------------------------------
# Front end
# --------------------------------------------------------------------------------------
def _pick(path: Path, available, wanted, defaults, role: str) -> str:
    names = list(available)
    upper = {n.upper(): n for n in names}
    if wanted is not None:
        if wanted in available:
            return wanted
        if str(wanted).upper() in upper:
            return upper[str(wanted).upper()]
        raise ValueError(f"{path}: no matrix named {wanted!r} ({role}); the file holds {names}")
    found = [upper[d] for d in defaults if d in upper]
    if len(found) != 1:
        raise ValueError(f"{path}: {'no' if not found else 'more than one'} {role} matrix among the default "
                         f"names {list(defaults)} (the file holds {names}); name it with {role}=")
    return found[0]


def _matlab_matrix(path: Path, name: str, value):
    if scipy.sparse.issparse(value):
        A = scipy.sparse.csr_matrix(value)
        dense = False
    else:
        A = np.asarray(value)
        dense = True
    if A.ndim != 2 or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise ValueError(f"{path}: variable {name!r} is {A.dtype} of shape {A.shape}; expected a real 2-D matrix")
    e = _Entries(name, f"variable {name}, column")
    if dense:
        r, c = np.nonzero(A)
        v = A[r, c]
    else:
        C = A.tocoo()
        r, c, v = C.row, C.col, C.data
    e.add_block(r, c, v.astype(float), c + 1)
    return e, A.shape


def read_fe_matrices(path, *, mass=None, stiffness=None) -> FEMatrices:
    """Mass and stiffness matrices of an FE export, format by the suffix of ``path``
    (``.op4``, ``.pch``, ``.mtx``, ``.mat``, ``.full``: see the module docstring).

    ``mass``, ``stiffness``: the matrix (or MATLAB variable) names in the file; by default the
    one of :data:`DEFAULT_MASS_NAMES` / :data:`DEFAULT_STIFFNESS_NAMES` the file holds. For
    Abaqus, whose matrices are separate files, ``path`` is either file and ``mass`` /
    ``stiffness`` name the other file (default: ``_STIF`` <-> ``_MASS`` in the name, e.g.
    ``job_STIF1.mtx`` and ``job_MASS1.mtx``), relative to the folder of ``path``.
    """
    path = Path(path)
    kind = FE_SUFFIXES.get(path.suffix.lower().lstrip("."))
    if kind is None:
        raise ValueError(f"{path}: an FE matrix file must end in {sorted('.' + s for s in FE_SUFFIXES)}")
    with reading(path, "finite-element matrix file"):     # missing, empty, a folder ...: one FileReadError
        return _read_fe_matrices(path, kind, mass, stiffness)


def _read_fe_matrices(path: Path, kind: str, mass, stiffness) -> FEMatrices:
    if kind == "abaqus":
        return _read_abaqus_pair(path, mass, stiffness)
    if kind == "ansys":
        if mass is not None or stiffness is not None:
            raise ValueError(f"{path}: an Ansys .full file holds one stiffness and one mass matrix; "
                             "remove mass= and stiffness=")
        return read_ansys_full(path)
    if kind == "matlab":
        variables = read_matlab(path)
        pair = []
        for wanted, defaults, role in ((mass, DEFAULT_MASS_NAMES, "mass"),
                                       (stiffness, DEFAULT_STIFFNESS_NAMES, "stiffness")):
            name = _pick(path, variables, wanted, defaults, role)
            e, shape = _matlab_matrix(path, name, variables[name])
            pair.append((name, _assemble(path, e, *shape, one_triangle=False)))
        labels = None
    elif kind == "op4":
        mats = read_op4(path)
        pair = []
        for wanted, defaults, role in ((mass, DEFAULT_MASS_NAMES, "mass"),
                                       (stiffness, DEFAULT_STIFFNESS_NAMES, "stiffness")):
            name = _pick(path, mats, wanted, defaults, role)
            e, nrow, ncol, _ = mats[name]
            pair.append((name, _assemble(path, e, nrow, ncol, one_triangle=False)))
        labels = None
    else:
        mats = read_dmig(path)
        pair, label_sets = [], []
        for wanted, defaults, role in ((mass, DEFAULT_MASS_NAMES, "mass"),
                                       (stiffness, DEFAULT_STIFFNESS_NAMES, "stiffness")):
            name = _pick(path, mats, wanted, defaults, role)
            e, labs, ifo = mats[name]
            label_sets.append(labs)
            pair.append((name, e, ifo))
        labels = np.unique(np.vstack(label_sets), axis=0)       # sorted (node, component)
        index = {tuple(lab): k for k, lab in enumerate(labels.tolist())}
        built = []
        for (name, e, ifo), labs in zip(pair, label_sets):
            e.relabel(np.array([index[tuple(lab)] for lab in labs.tolist()], dtype=np.int64))
            built.append((name, _assemble(path, e, len(labels), len(labels), one_triangle=ifo == 6)))
        pair = built
    (mname, M), (kname, K) = pair
    if M.shape != K.shape:
        raise ValueError(f"{path}: mass {mname} is {M.shape[0]} x {M.shape[1]} but stiffness {kname} is "
                         f"{K.shape[0]} x {K.shape[1]}; expected the same size")
    return FEMatrices(mass=M, stiffness=K, labels=labels, path=path, names=(mname, kname))


def _read_abaqus_pair(path: Path, mass, stiffness) -> FEMatrices:
    if not path.is_file():
        raise OSError(f"{path}: not a file")   # reading() says: no such file, or a folder
    name = path.name
    if mass is None and stiffness is None:
        if "_STIF" in name.upper():
            k = name.upper().index("_STIF")
            stiffness, mass = name, name[:k] + "_MASS" + name[k + 5:]
        elif "_MASS" in name.upper():
            k = name.upper().index("_MASS")
            mass, stiffness = name, name[:k] + "_STIF" + name[k + 5:]
        else:
            raise ValueError(f"{path}: name the Abaqus mass and stiffness files with mass= and stiffness= "
                             "(the name holds neither _STIF nor _MASS)")
    mass = mass if mass is not None else name
    stiffness = stiffness if stiffness is not None else name
    files = [path.parent / mass, path.parent / stiffness]
    read = [read_abaqus_mtx(f) for f in files]
    labelled = [labs is not None for _, labs, _ in read]
    if labelled[0] != labelled[1]:
        raise ValueError(f"{files[0]} and {files[1]}: one is in MATRIX INPUT, the other in COORDINATE format; "
                         "expected the same format")
    if labelled[0]:
        labels = np.unique(np.vstack([labs for _, labs, _ in read]), axis=0)
        index = {tuple(lab): k for k, lab in enumerate(labels.tolist())}
        mats = []
        for (e, labs, _), f in zip(read, files):
            e.relabel(np.array([index[tuple(lab)] for lab in labs.tolist()], dtype=np.int64))
            mats.append(_assemble(f, e, len(labels), len(labels), one_triangle=True))
    else:
        labels = None
        n = max(r[2] for r in read)
        mats = [_assemble(f, e, n, n, one_triangle=True) for (e, _, _), f in zip(read, files)]
    return FEMatrices(mass=mats[0], stiffness=mats[1], labels=labels, path=files[1], names=(mass, stiffness))
