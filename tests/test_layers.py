"""The package's layers (issue 34 item 1): every import points down, checked by import-linter
against the contracts in pyproject.toml ([tool.importlinter]), and no two modules of bladedamp
import each other, directly or through others.

The import graph is grimp's (the graph import-linter checks): every ``import`` statement of the
package's source, at module level or inside a function alike.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parents[1]


def contracts() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)["tool"]["importlinter"]


def known_back_arrows() -> set[tuple[str, str]]:
    """The back arrows the layers contract still ignores (each left to a later step of issue 34)."""
    layers = next(c for c in contracts()["contracts"] if c["type"] == "layers")
    arrows = set()
    for entry in layers.get("ignore_imports", ()):
        importer, imported = (part.strip() for part in entry.split("->"))
        arrows.add((importer, imported))
    return arrows


def import_graph() -> dict[str, set[str]]:
    """{module: the bladedamp modules it imports} of this checkout's bladedamp."""
    graph = grimp.build_graph("bladedamp", cache_dir=None)
    return {m: set(graph.find_modules_directly_imported_by(m)) for m in graph.modules}


def strongly_connected_components(edges: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components of the directed graph ``edges``; a component of
    more than one module is a cycle of imports."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components = []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            components.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return components


def test_import_linter_contracts_are_kept():
    """``lint-imports`` (import-linter) on pyproject.toml's contracts: the layers, the engine
    that imports no model, the engine core that imports only validation outside hbm."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports_command; "
                          "lint_imports_command()", "--no-cache"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"import-linter found a broken contract:\n{run.stdout}\n{run.stderr}"
    assert "0 broken" in run.stdout


def test_strongly_connected_components_finds_a_cycle_and_nothing_else():
    """The cycle finder on a small graph whose answer is known by hand."""
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"d"}}
    assert sorted(strongly_connected_components(edges)) == [["a", "b", "c"], ["d"], ["e"]]


def test_no_import_cycles_among_bladedamp_modules():
    """No cycle in bladedamp's module import graph once the known back arrows of the layers
    contract are taken out; and each of those is still there (remove it from ignore_imports in
    pyproject.toml when its step of issue 34 is done)."""
    edges = import_graph()
    assert "bladedamp.hbm.monodromy" in edges and "bladedamp.timedomain" in edges["bladedamp.hbm.monodromy"]
    known = known_back_arrows()
    for importer, imported in sorted(known):
        assert imported in edges.get(importer, set()), (
            f"{importer} no longer imports {imported}: remove it from ignore_imports in pyproject.toml")
        edges[importer] = edges[importer] - {imported}
    cycles = [c for c in strongly_connected_components(edges) if len(c) > 1]
    assert not cycles, f"import cycles among bladedamp modules: {cycles}"


def test_the_monodromy_reaches_a_model_through_its_protocol():
    """hbm.monodromy imports no model: the oscillator, the tuned disk and the full-assembly
    mistuned disk implement PeriodMapModel (and the disks AssemblyModel); a mistuned sector model
    (not every blade) and a model with extra couplings (the time integration has not got them)
    have no period map, as when the method dispatched on the model's class."""
    import bladedamp as bd
    from bladedamp.diskmodel import WithCouplings
    from bladedamp.hbm.monodromy import AssemblyModel, PeriodMapModel, supports
    from bladedamp.mistuned import MistunedDisk

    osc = bd.FrictionOscillator()
    disk = bd.reference_disk("cylinder", 1e-3)
    full = MistunedDisk.from_tuned(disk)
    sector = MistunedDisk.from_tuned(disk, n_sector=4)
    for model in (osc, disk, full):
        assert isinstance(model, PeriodMapModel) and supports(model)
    for model in (disk, full):
        assert isinstance(model, AssemblyModel)
    assert full.full_assembly() is full and disk.full_assembly().n_sector == disk.n_blades
    assert not supports(sector)
    assert not supports(WithCouplings(disk, lambda basis: []))
    assert not supports(object())
