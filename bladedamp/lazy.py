"""Public names of a package imported on first use (PEP 562), so that ``import bladedamp`` (the
CLI's ``--help``, worker start-up) and light submodules load numpy, scipy and numba only when
a model is first used."""
from __future__ import annotations

import importlib


def lazy_attributes(package: str, names: dict[str, str], namespace: dict):
    """``(__getattr__, __dir__)`` for the package ``package`` whose public ``names`` map to the
    submodule (relative to the package) that defines each; a name, once imported, is kept in
    the package's ``namespace`` (its ``globals()``)."""

    def __getattr__(name):
        if name in names:
            value = getattr(importlib.import_module(f".{names[name]}", package), name)
            namespace[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__
