"""Save and load every result object: one ``.npz`` file, no pickle.

Every response and study result (:class:`~bladedamp.response.FrequencyResponse`,
:class:`~bladedamp.disk.DiskResponse`, :class:`~bladedamp.mistuned.MistunedResponse`, the
time-domain responses, the study results of :mod:`bladedamp.studies`) has ``.save(path)``
(from :class:`Saveable`), and :func:`load` reads any of them back::

    frf.save("results/frf")                 # writes results/frf.npz
    frf = bladedamp.load("results/frf.npz")

Blades are saved the same way (``blade.save("blade.npz")``, :mod:`bladedamp.blade.modal`): their own
arrays (the modal data file's documented keys) and the same ``__bladedamp__`` entry naming the class
(``"layout": "arrays"``: the class reads its arrays back with its ``from_npz``), so :func:`load` gives
a blade back (a solid FE blade's with its flexible platforms); blade files without that entry (saved
before, or written by hand) are read by their ``format`` string (:data:`BLADE_FORMATS`).

File layout (readable with ``np.load(path, allow_pickle=False)`` and any npz reader):

* each array field of the dataclass is one npz entry under its field name (an object array of
  strings as a unicode array, turned back into an object array on loading); a nested result
  (e.g. the ``response`` of a :class:`~bladedamp.studies.mistuning.MistuningCase`) has its
  arrays under ``<field>/<name>``, a list of arrays under ``<field>/<index>``;
* the entry ``__bladedamp__`` is a 0-d unicode array holding JSON: the format version, the
  class (``module:qualname``, on which :func:`load` dispatches), every scalar, string, tuple,
  list and dict field (dicts as key-value pairs, so integer keys stay integers; complex
  numbers as [re, im]; NaN as JSON's NaN), and the
  :class:`~bladedamp.hbm.fourier.HarmonicBasis` by its harmonics and n_samples: the typed
  JSON form of :func:`encode_value` / :func:`decode_value` (also used for a solid blade's
  ``solid_info``, :meth:`bladedamp.blade.solid.SolidModalBlade.npz_arrays`). A response's
  ``notes`` are such a tuple (of :class:`~bladedamp.response.Note`); a response file saved before
  responses had notes holds its ``message`` instead, which loads as its one note.

The model is not saved: a ``disk`` (TunedDisk or MistunedDisk) or ``system`` field is
stored as absent, and a loaded result has ``disk=None`` (``system=None``). Rebuilding a disk
would need its blade, damper and contact objects written out as well, which is what the design
file does; so the file keeps a short description of the model (class, damper kind and mass,
engine order, blades) under ``models`` -> ``disk`` in the JSON for the reader, and every named property and
``.plot()`` of a loaded result works without the model (3D views need it: compute again).
"""
from __future__ import annotations

import contextlib
import dataclasses
import enum
import importlib
import inspect
import json
import math
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

FORMAT_VERSION = 1
META_KEY = "__bladedamp__"

# Blade modal data files (bladedamp.blade.modal.ModalBlade.save): the blade's own arrays (format:
# bladedamp.blade.modal's docstring) with a ``format`` string naming the blade kind, and the
# META_KEY entry of every saved object (``"layout": "arrays"``, :func:`write_npz`).
MODAL_NPZ_FORMAT = "bladedamp.ModalBlade/1"
# A solid FE blade's file (bladedamp.blade.solid.SolidModalBlade.save): the ModalBlade keys plus its
# flexible platforms' FE field, contact-face samples, surface and solid_info.
SOLID_NPZ_FORMAT = "bladedamp.SolidModalBlade/2"
# /2 writes solid_info with encode_value (typed); /1 files (solid_info in plain JSON, types
# guessed on reading) are still read
SOLID_NPZ_FORMATS_READ = ("bladedamp.SolidModalBlade/1", SOLID_NPZ_FORMAT)
#: the class that reads a blade file without a META_KEY entry (one saved before blade files had
#: it, or written by hand), by its ``format`` string; resolved by name as every saved class (this
#: module imports no model or blade: it sits below them)
BLADE_FORMATS = {MODAL_NPZ_FORMAT: "bladedamp.blade.modal:ModalBlade",
                 **{tag: "bladedamp.blade.solid:SolidModalBlade" for tag in SOLID_NPZ_FORMATS_READ}}
#: fields that hold a model, not data: stored as absent, loaded as None (see the module docstring)
MODEL_FIELDS = ("disk", "system")


# ----- reading files: one error naming the file -------------------------------------------
class FileReadError(ValueError):
    """A file that cannot be read as what it should be: missing, a folder, unreadable, empty,
    truncated or corrupted, of another kind, not UTF-8 text, or with broken content. The message
    is one line that names the file and says what is wrong. Every reader of the package raises
    it (:func:`reading`)."""


class MissingFileError(FileReadError, FileNotFoundError):
    """A file that does not exist: a :class:`FileReadError` that is also a FileNotFoundError."""


class WrongKindError(FileReadError, TypeError):
    """A saved result of another class than the one asked for: a :class:`FileReadError` that is
    also a TypeError."""


#: what a reader raises on a file's bad content (a NameError or an ImportError is a bug, not the file's)
CONTENT_ERRORS = (OSError, ValueError, LookupError, TypeError, AttributeError, EOFError, RecursionError,
                  NotImplementedError, zipfile.BadZipFile, zlib.error, struct.error)


@contextlib.contextmanager
def reading(path, what: str, error: type = FileReadError):
    """The boundary of a file reader: whatever goes wrong in the ``with`` block while reading
    ``path`` (a ``what``, e.g. "saved bladedamp result") is raised as one ``error`` (a
    :class:`FileReadError` or a subclass) whose one-line message names the file and says what
    is wrong: no such file (:class:`MissingFileError` for the default ``error``), a folder, not
    readable (permissions), empty, not UTF-8 text, truncated or corrupted (a zip archive's bad
    CRC or lost end, a cut compressed stream), broken JSON, a missing entry, or the raw error's
    type and text. A ValueError whose message already names the file keeps its message; an
    ``error`` raised inside passes unchanged."""
    try:
        yield
    except error:
        raise
    except CONTENT_ERRORS as exc:
        path = Path(path)
        problem, known = _file_problem(path, what, exc)
        message = " ".join((problem if str(path) in problem else f"{path}: {problem}").split())   # one line
        kind = MissingFileError if error is FileReadError and problem.startswith("no such") else error
        if known:
            raise kind(message) from None
        raise kind(message) from exc


def _file_problem(path: Path, what: str, exc: BaseException) -> tuple[str, bool]:
    """(what is wrong with the file ``path`` that made a reader raise ``exc``, whether that is
    fully said without ``exc``'s traceback)."""
    if not path.exists():
        return f"no such {what}", True
    if path.is_dir():
        return f"is a folder, not a {what}", True
    if isinstance(exc, OSError) and not isinstance(exc, FileNotFoundError):
        return f"cannot read the {what} ({exc.strerror or exc})", True
    try:
        if path.stat().st_size == 0:
            return f"empty (0 bytes), not a {what}", True
    except OSError:
        pass
    if isinstance(exc, UnicodeDecodeError):
        return f"not a readable {what}: not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start})", True
    if isinstance(exc, ValueError) and not isinstance(exc, json.JSONDecodeError) and str(path) in str(exc):
        return str(exc), True
    if isinstance(exc, (zipfile.BadZipFile, zlib.error, EOFError, struct.error, NotImplementedError)):
        return f"truncated or corrupted, not a readable {what} ({exc})", True
    if isinstance(exc, json.JSONDecodeError):
        return f"not a readable {what}: broken JSON ({exc})", True
    if isinstance(exc, KeyError):
        return f"not a readable {what}: no entry {exc}", True
    if type(exc) is ValueError:                      # a reader's own check, without the file's name
        return f"not a readable {what}: {exc}", True
    return f"not a readable {what} ({type(exc).__name__}: {exc})", False


#: the first bytes of a zip archive (an .npz): a local file header, or the end record of an empty one
ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06")


def open_npz(path) -> "np.lib.npyio.NpzFile":
    """``np.load(path, allow_pickle=False)`` of an ``.npz`` archive (use it in a ``with`` block
    inside :func:`reading`, which reads its arrays lazily); ValueError naming the file for one
    that is not a zip archive (text, a single ``.npy`` array, any other bytes)."""
    path = Path(path)
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head not in ZIP_MAGIC:
        kind = "nothing" if not head else "a single .npy array" if head.startswith(b"\x93NUM") else \
            "text" if _is_text(path) else f"other bytes ({head!r}...)"
        raise ValueError(f"{path}: not a readable .npz file (it holds {kind}, not a zip archive of arrays)")
    return np.load(path, allow_pickle=False)       # a zip archive: np.load gives an NpzFile


def _is_text(path: Path) -> bool:
    """Whether the first kilobyte of ``path`` decodes as UTF-8 without control bytes (but tab, newlines)."""
    with open(path, "rb") as fh:
        chunk = fh.read(1024)
    try:
        text = chunk.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(chunk) - 3:         # not just a character cut at the end of the chunk
            return False
        text = chunk[:exc.start].decode("utf-8")
    return not any(ord(c) < 32 and c not in "\t\r\n" for c in text)


class Saveable:
    """Mixin of every result dataclass: ``.save(path)`` and ``Class.load(path)``."""

    def save(self, path) -> Path:
        """Write this result to ``path`` (``.npz`` appended if missing); returns the file's path.
        Loadable with :func:`bladedamp.load` and ``np.load(path, allow_pickle=False)``."""
        return save(self, path)

    @classmethod
    def load(cls, path):
        """Read a result saved by :meth:`save`: :func:`load`'s errors, and :class:`WrongKindError`
        (a ValueError and a TypeError) naming the file if it holds another class."""
        result = load(path)
        if not isinstance(result, cls):
            raise WrongKindError(f"{npz_path(path)}: holds a {type(result).__qualname__}, not a {cls.__qualname__}")
        return result


def npz_path(path) -> Path:
    """``path`` with the suffix ``.npz`` (added when it has another or none, ``.json`` replaced)."""
    path = Path(path)
    if path.suffix == ".npz":
        return path
    if path.suffix == ".json":
        return path.with_suffix(".npz")
    return path.with_name(path.name + ".npz")


# ----- JSON values ----------------------------------------------------------------------
def encode_value(value, where: str = "value"):
    """The JSON-able, typed form of ``value`` (``json.dumps`` of it, with NaN allowed, and
    :func:`decode_value` of ``json.loads`` give ``value`` back, types included).

    Round-trip exactly (value and type): None, bool, int, float (NaN and infinities too: dump
    with ``allow_nan=True``, json's default), complex and str; numpy arrays of bool, integer,
    unsigned, float, complex and unicode dtypes (dtype and shape kept, empty arrays included; an
    object array is stored as the array numpy infers from its items); tuples, lists and dicts
    (any hashable keys of these types: integer and tuple keys stay integers and tuples),
    nested to any depth; :class:`~bladedamp.hbm.fourier.HarmonicBasis`; and the members of
    bladedamp's enums and the dataclasses of bladedamp whose fields are of these types (e.g.
    a response's :class:`~bladedamp.response.Note` s), found again by their class's name. Numpy scalars come
    back as the Python scalar of their kind (``np.float64`` -> float, ``np.int64`` -> int,
    ``np.bool_`` -> bool, ``np.complex128`` -> complex).

    The form: None, bools, numbers and strings as themselves, lists as JSON lists, every other
    value as a JSON object with one tag: ``{"__tuple__": [...]}``, ``{"__dict__": [[key, value],
    ...]}``, ``{"__array__": nested lists, "dtype": str}`` (complex entries as [re, im] pairs;
    ``"shape"`` too when the array is empty), ``{"__complex__": [re, im]}``, ``{"__basis__":
    {"harmonics": [...], "n_samples": n}}``, ``{"__enum__": "module:qualname", "name": member}``,
    ``{"__record__": "module:qualname", "fields": {name: value, ...}}``. ``where`` names the value in the TypeError raised
    for any other type (e.g. ``"MassSweep.meta['x']"``)."""
    from .hbm.fourier import HarmonicBasis

    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, (complex, np.complexfloating)):
        return {"__complex__": [float(value.real), float(value.imag)]}
    if isinstance(value, HarmonicBasis):
        return {"__basis__": {"harmonics": [int(h) for h in value.harmonics], "n_samples": int(value.n_samples)}}
    if isinstance(value, enum.Enum) and _class_name(type(value)):
        return {"__enum__": _class_name(type(value)), "name": value.name}
    if dataclasses.is_dataclass(value) and not isinstance(value, type) and _class_name(type(value)):
        return {"__record__": _class_name(type(value)),
                "fields": {f.name: encode_value(getattr(value, f.name), f"{where}.{f.name}")
                           for f in dataclasses.fields(value)}}
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "O":
            value = np.asarray(value.tolist())
        if value.dtype.kind not in "biufcU":
            raise TypeError(f"cannot save {where}: an array of dtype {value.dtype}")
        data = np.stack([value.real, value.imag], axis=-1) if value.dtype.kind == "c" else value
        out = {"__array__": data.tolist(), "dtype": str(value.dtype)}
        if value.size == 0:                       # nested lists lose the shape of an empty array
            out["shape"] = list(value.shape)
        return out
    if isinstance(value, tuple):
        return {"__tuple__": [encode_value(v, f"{where}[{i}]") for i, v in enumerate(value)]}
    if isinstance(value, list):
        return [encode_value(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, dict):
        return {"__dict__": [[encode_value(k, where), encode_value(v, f"{where}[{k!r}]")] for k, v in value.items()]}
    raise TypeError(f"cannot save {where}: a {type(value).__module__}.{type(value).__qualname__} "
                    "(encode_value takes None, bools, numbers, strings, numpy arrays, tuples, lists, dicts, "
                    "HarmonicBasis, and bladedamp's enums and dataclasses)")


def _class_name(cls) -> str:
    """``module:qualname`` of a bladedamp class (found again by :func:`_resolve_name`), '' for another's."""
    module = cls.__module__
    return f"{module}:{cls.__qualname__}" if module == "bladedamp" or module.startswith("bladedamp.") else ""


def decode_value(value):
    """The value whose :func:`encode_value` form is ``value`` (as ``json.loads`` gives it back),
    with its type (see :func:`encode_value` for the types that round-trip). ValueError for a
    JSON object that carries none of encode_value's tags (a plain JSON object is not an encoded
    dict: dicts are encoded as ``{"__dict__": [[key, value], ...]}``)."""
    from .hbm.fourier import HarmonicBasis

    if isinstance(value, list):
        return [decode_value(v) for v in value]
    if not isinstance(value, dict):
        return value
    if "__complex__" in value:
        re, im = value["__complex__"]
        return complex(re, im)
    if "__basis__" in value:
        b = value["__basis__"]
        return HarmonicBasis(tuple(b["harmonics"]), b["n_samples"])
    if "__array__" in value:
        dtype = np.dtype(value["dtype"])
        if dtype.kind == "c":
            a = np.asarray(value["__array__"], dtype=float)
            a = (a[..., 0] + 1j * a[..., 1]).astype(dtype) if a.size else a.astype(dtype)
        else:
            a = np.asarray(value["__array__"], dtype=dtype)
        return a.reshape(value["shape"]) if "shape" in value else a
    if "__enum__" in value:
        cls = _resolve_name(value["__enum__"])
        if not (isinstance(cls, type) and issubclass(cls, enum.Enum)):
            raise ValueError(f"{value['__enum__']!r} is not an enum")
        return cls[value["name"]]
    if "__record__" in value:
        cls = _resolve_name(value["__record__"])
        if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
            raise ValueError(f"{value['__record__']!r} is not a dataclass")
        return cls(**{k: decode_value(v) for k, v in value["fields"].items()})
    if "__tuple__" in value:
        return tuple(decode_value(v) for v in value["__tuple__"])
    if "__dict__" in value:
        return {_hashable(decode_value(k)): decode_value(v) for k, v in value["__dict__"]}
    raise ValueError(f"not an encoded value (a JSON object without a bladedamp tag): {value!r}")


def _hashable(key):
    return tuple(key) if isinstance(key, list) else key


# ----- dataclasses to entries -------------------------------------------------------------
def _model_summary(model) -> dict:
    """A short description of a model for the reader of a file (not enough to rebuild it)."""
    out = {"class": f"{type(model).__module__}:{type(model).__qualname__}"}
    damper = getattr(model, "damper", None)
    if damper is not None and not isinstance(damper, (list, tuple)):
        out.update(damper=getattr(damper, "kind", None), damper_mass_kg=float(getattr(damper, "mass", math.nan)))
    for name in ("engine_order", "n_blades", "n_sector"):
        value = getattr(model, name, None)
        if isinstance(value, (int, float, np.integer, np.floating)):
            out[name] = value.item() if isinstance(value, np.generic) else value
    return out


def _flatten(result, prefix: str, arrays: dict) -> dict:
    """The JSON description of ``result`` (a dataclass); its arrays go into ``arrays``."""
    if not dataclasses.is_dataclass(result) or isinstance(result, type):
        raise TypeError(f"save takes a result dataclass (got {type(result).__qualname__})")
    cls = type(result)
    meta = {"class": f"{cls.__module__}:{cls.__qualname__}", "fields": {}, "arrays": [], "object_arrays": [],
            "array_lists": {}, "results": {}, "absent": [], "models": {}}
    for f in dataclasses.fields(result):
        value = getattr(result, f.name)
        key = f"{prefix}{f.name}"
        where = f"{cls.__qualname__}.{f.name}"
        if f.name in MODEL_FIELDS and value is not None and not isinstance(value, (np.ndarray, str, int, float)):
            meta["absent"].append(f.name)
            if f.name == "disk":
                meta["models"][f.name] = _model_summary(value)
        elif isinstance(value, np.ndarray):
            if value.dtype.kind == "O":                  # e.g. per-point status strings: stored as unicode
                meta["object_arrays"].append(f.name)
                value = np.asarray(value.tolist())
                if value.dtype.kind not in "UbifcS":
                    raise TypeError(f"cannot save {where}: an object array of {value.dtype} values")
            arrays[key] = value
            meta["arrays"].append(f.name)
        elif isinstance(value, list) and value and all(isinstance(v, np.ndarray) for v in value):
            for i, v in enumerate(value):
                arrays[f"{key}/{i}"] = v
            meta["array_lists"][f.name] = len(value)
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            meta["results"][f.name] = _flatten(value, f"{key}/", arrays)
        else:
            meta["fields"][f.name] = encode_value(value, where)
    return meta


def _rebuild(meta: dict, prefix: str, arrays):
    cls = _resolve(meta["class"])
    kwargs = {name: decode_value(v) for name, v in meta["fields"].items()}
    for name in meta["arrays"]:
        kwargs[name] = np.asarray(arrays[f"{prefix}{name}"])
        if name in meta.get("object_arrays", ()):
            kwargs[name] = kwargs[name].astype(object)
    for name, n in meta["array_lists"].items():
        kwargs[name] = [np.asarray(arrays[f"{prefix}{name}/{i}"]) for i in range(n)]
    for name, sub in meta["results"].items():
        kwargs[name] = _rebuild(sub, f"{prefix}{name}/", arrays)
    for name in meta["absent"]:
        kwargs[name] = None
    fields = {f.name: f for f in dataclasses.fields(cls)}
    # the constructor's arguments: the fields it takes and its init-only ones (e.g. a response's
    # message, which a file saved before the response had notes holds)
    takes = inspect.signature(cls).parameters
    init = {k: v for k, v in kwargs.items() if k in takes}
    obj = cls(**init)
    for k, v in kwargs.items():
        if k in fields and not fields[k].init:
            object.__setattr__(obj, k, v)
    return obj


def _resolve_name(name: str):
    """The bladedamp class named ``module:qualname``; ValueError for another's or none."""
    module, _, qualname = name.partition(":")
    if not (module == "bladedamp" or module.startswith("bladedamp.")):
        raise ValueError(f"a saved result's class must come from bladedamp (got {name!r})")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        raise ValueError(f"a saved result's class {name!r} does not exist in this bladedamp") from None
    return obj


def _resolve(name: str):
    obj = _resolve_name(name)
    if not (isinstance(obj, type) and dataclasses.is_dataclass(obj)):
        raise ValueError(f"{name!r} is not a result class")
    return obj


# ----- the public functions ---------------------------------------------------------------
def write_npz(obj, path, arrays: dict, *, meta: dict | None = None, compressed: bool = False) -> Path:
    """Write ``arrays`` (name -> array) to ``path`` (as given: no suffix is added; the folder is
    created) with the :data:`META_KEY` entry that names ``obj``'s class, the one writer of every
    saved object. ``meta``: the rest of that JSON (a result's fields, :func:`save`); None: an object
    with its own layout (``"layout": "arrays"``: ``arrays`` are its ``npz_arrays()``, read back by
    its classmethod ``from_npz(path, data)``, e.g. a blade). Returns ``path``."""
    path = Path(path)
    cls = type(obj)
    meta = {"format": FORMAT_VERSION, "library": "bladedamp", "class": f"{cls.__module__}:{cls.__qualname__}",
            **({"layout": "arrays"} if meta is None else meta)}
    if META_KEY in arrays:
        raise ValueError(f"cannot save {cls.__qualname__}: its arrays must not use the key {META_KEY!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as fh:    # a file object: np.savez would append .npz to a suffix ".NPZ"
        (np.savez_compressed if compressed else np.savez)(fh, **arrays, **{META_KEY: np.array(json.dumps(meta, allow_nan=True))})
    return path


def save(result, path) -> Path:
    """Write ``result`` (any response or study result) to ``path`` (``.npz`` appended if
    missing; the folder is created); returns the file's path. See the module docstring for
    the layout; the model (``disk``) is not saved."""
    arrays: dict[str, np.ndarray] = {}
    meta = _flatten(result, "", arrays)
    meta.pop("class")
    return write_npz(result, npz_path(path), arrays, meta=meta)


def load(path):
    """Read a result written by ``.save(path)`` / :func:`save` (``.npz``; ``path`` without the
    suffix works too); returns an object of the class stored in the file, with ``disk=None``.
    A blade's modal data file (``ModalBlade.save``, or a file with a ``format`` entry naming a blade
    format) gives the blade (a solid FE blade's a :class:`~bladedamp.blade.solid.SolidModalBlade`).
    Raises :class:`FileReadError` (a ValueError) naming the file for a file that is missing
    (:class:`MissingFileError`, also a FileNotFoundError), empty, truncated or corrupted, not an
    ``.npz``, not a saved result, or with broken metadata or a missing array (:func:`reading`)."""
    return load_npz(npz_path(path), "saved bladedamp result")


def load_npz(path, what: str, untagged: type | None = None):
    """The object saved in the ``.npz`` file ``path`` (:func:`load`; ``what`` names the kind of file
    in the errors, :func:`reading`): the class named by its :data:`META_KEY` entry, rebuilt from its fields or, for an object with
    its own layout, by its ``from_npz(path, data)`` (``data``: the open file, arrays by key). A file
    without that entry: a blade file by its ``format`` (:data:`BLADE_FORMATS`), else read by
    ``untagged.from_npz`` (e.g. a hand-written modal data file: ModalBlade), else ValueError."""
    path = Path(path)
    with reading(path, what):
        with open_npz(path) as z:
            files = set(z.files)
            if META_KEY in files:
                meta = json.loads(str(z[META_KEY][()]))
                if not isinstance(meta, dict):
                    raise ValueError(f"{path}: entry {META_KEY!r} must be a JSON object (got {type(meta).__name__})")
                if meta.get("format", 0) > FORMAT_VERSION:
                    raise ValueError(f"{path} has format {meta.get('format')}; this bladedamp reads up to "
                                     f"{FORMAT_VERSION}")
                if meta.get("layout") == "arrays":
                    return _resolve(meta["class"]).from_npz(path, z)
                arrays = {k: z[k] for k in z.files if k != META_KEY}
            else:
                cls = untagged
                if "format" in files:
                    try:
                        tag = z["format"]
                    except ValueError:                     # an object array: the reader says which key
                        tag = None
                    if tag is not None and tag.dtype.kind == "U" and str(tag) in BLADE_FORMATS:
                        cls = _resolve(BLADE_FORMATS[str(tag)])
                if cls is None:
                    raise ValueError(f"{path} is not a saved bladedamp result (no {META_KEY} entry)")
                return cls.from_npz(path, z)
        return _rebuild(meta, "", arrays)
