"""No private name of bladedamp is used outside the module that defines it (issue 34, item 7).

A name with one leading underscore (not a dunder ``__x__``, not IPython's ``_x_`` protocol
names) is private to the module that defines it: a ``def``/``class`` of that name, a module or
class-body assignment, or an attribute assigned on ``self``/``cls`` there. An ast scan of
bladedamp/, tests/ and benchmarks/ fails, naming file:line, on

* ``from bladedamp... import _name`` (or a relative import of a private name inside the package),
  ``import bladedamp._module``;
* ``obj._name`` with ``obj`` not ``self``/``cls``, where ``_name`` is a private name of bladedamp
  and the file is not a module that defines it (tests and benchmarks define none);
* ``getattr/setattr/hasattr/delattr(obj, "_name")`` (``monkeypatch.setattr`` too) likewise.

Private names of Python, the standard library and third-party packages are not bladedamp's and
are not reported, unless one coincides with a bladedamp name: :data:`ALLOWED` lists those uses.
"""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("bladedamp", "tests", "benchmarks")

#: (file relative to the repository, attribute) -> why the use is not a bladedamp private name
ALLOWED: dict[tuple[str, str], str] = {
    ("bladedamp/__init__.py", "_numba_cache"): "the package's own private submodule (numba's cache location), "
                                               "set up by the package when it is imported",
}


def is_private(name: str) -> bool:
    """One leading underscore, not a dunder (__x__) and not an IPython sunder (_x_) name."""
    return name.startswith("_") and not name.startswith("__") and not (len(name) > 2 and name.endswith("_"))


def defined_private(tree: ast.AST) -> set[str]:
    """Private names a module defines: defs, classes, assigned names and self/cls attributes."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) and \
                isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            names.add(node.attr)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "setattr" and \
                len(node.args) >= 2 and isinstance(node.args[0], ast.Name) and node.args[0].id in ("self", "cls") \
                and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str):
            names.add(node.args[1].value)
        elif isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Store) and \
                isinstance(node.slice, ast.Constant) and isinstance(node.slice.value, str):   # self.__dict__["_x"]
            names.add(node.slice.value)
    return {n for n in names if is_private(n)}


def violations(tree: ast.AST, path: str, in_package: bool, private: dict[str, set[str]]) -> list[str]:
    """file:line messages for the uses of bladedamp private names in ``tree`` (the file ``path``);
    ``private``: each bladedamp private name -> the files that define it."""
    out = []

    def foreign(name):
        return is_private(name) and name in private and path not in private[name] and \
            (path, name) not in ALLOWED

    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if (module == "bladedamp" or module.startswith("bladedamp.")) or (in_package and node.level > 0):
                for alias in node.names:
                    if is_private(alias.name) and (path, alias.name) not in ALLOWED:
                        out.append(f"{path}:{node.lineno}: imports the private name {alias.name} from {module or '.'}")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "bladedamp" and any(is_private(p) for p in parts[1:]) and \
                        (path, parts[-1]) not in ALLOWED:
                    out.append(f"{path}:{node.lineno}: imports the private module {alias.name}")
        elif isinstance(node, ast.Attribute):
            if isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
                continue
            if foreign(node.attr):
                out.append(f"{path}:{node.lineno}: uses the private attribute {ast.unparse(node)}")
        elif isinstance(node, ast.Call):
            func = node.func
            fname = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if fname in ("getattr", "setattr", "hasattr", "delattr", "delitem") and len(node.args) >= 2:
                target, name = node.args[0], node.args[1]
                if isinstance(target, ast.Name) and target.id in ("self", "cls"):
                    continue
                if isinstance(name, ast.Constant) and isinstance(name.value, str) and foreign(name.value):
                    out.append(f"{path}:{node.lineno}: {fname} of the private attribute {name.value!r}")
    return out


def scan(root: Path = ROOT) -> list[str]:
    trees = {}
    for top in SCANNED:
        for file in sorted((root / top).rglob("*.py")):
            trees[file.relative_to(root).as_posix()] = ast.parse(file.read_text(encoding="utf-8"), str(file))
    private: dict[str, set[str]] = {}
    for path, tree in trees.items():
        if path.startswith("bladedamp/"):
            for name in defined_private(tree):
                private.setdefault(name, set()).add(path)
    out = []
    for path, tree in trees.items():
        out += violations(tree, path, path.startswith("bladedamp/"), private)
    return out


def test_no_private_bladedamp_name_is_used_outside_its_module():
    found = scan()
    assert not found, "private names used across modules (make them public with a contract, or use " \
                      "the public API):\n" + "\n".join(found)


def test_the_scan_reports_each_kind_of_use():
    """The checker fails on a deliberately bad snippet and passes its good twin."""
    private = {"_kernel": {"bladedamp/a.py"}, "_batch": {"bladedamp/a.py"}}
    bad = ast.parse("from bladedamp.a import _kernel\n"
                    "from . import _kernel as k\n"
                    "element._batch = (False,)\n"
                    "x = element.stacked()._batch\n"
                    "monkeypatch.setattr(mod, '_kernel', None)\n"
                    "getattr(element, '_batch')\n"
                    "import bladedamp._numba_cache\n")
    found = violations(bad, "bladedamp/b.py", True, private)
    assert sorted(int(f.split(":")[1]) for f in found) == [1, 2, 3, 4, 5, 6, 7], found
    assert all(f.startswith("bladedamp/b.py:") for f in found)
    good = ast.parse("from bladedamp.a import kernel\n"
                     "self._batch = (False,)\n"
                     "cls._kernel\n"
                     "parser._actions\n"                  # not a bladedamp name
                     "widget._repr_mimebundle_()\n"       # IPython's display protocol
                     "getattr(self, '_batch')\n")
    assert violations(good, "tests/test_x.py", False, private) == []
    # within the defining module the name is the module's own
    assert violations(ast.parse("other._batch = None\n"), "bladedamp/a.py", True, private) == []
    assert len(violations(ast.parse("other._batch = None\n"), "bladedamp/b.py", True, private)) == 1
