"""The notebooks as saved files: what JupyterLab and static viewers see before anything runs.

* saved in the form JupyterLab writes (nbformat 4.5, cell ids, one-space JSON) with the kernel
  spec JupyterLab sets for this venv's kernel, so that opening one changes nothing to save;
* every widget output has its saved widget state and notebook 04's 3D views are saved in it, so
  that sliders and 3D views show before anything runs (in JupyterLab once the notebook is
  trusted: untrusted, JupyterLab draws no widget and strips iframes);
* no link to a file that git ignores (it would be dead in a fresh clone).
"""
import json
import pathlib
import re
import subprocess

import pytest

nbformat = pytest.importorskip("nbformat")

ROOT = pathlib.Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
KERNELSPEC = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
WIDGET_STATE = "application/vnd.jupyter.widget-state+json"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_saved_as_jupyterlab_writes_it(path):
    raw = path.read_text(encoding="utf-8")
    nb = nbformat.reads(raw, as_version=4)
    nbformat.validate(nb)
    assert (nb.nbformat, nb.nbformat_minor) >= (4, 5)
    assert all("id" in cell for cell in nb.cells)
    assert nbformat.writes(nb) + "\n" == raw, "not in nbformat's canonical form: JupyterLab would rewrite it"
    assert nb.metadata["kernelspec"] == KERNELSPEC


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_widgets_and_3d_views_are_saved(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    state = nb["metadata"].get("widgets", {}).get(WIDGET_STATE, {}).get("state", {})
    views = 0
    for cell in nb["cells"]:
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            if WIDGET_VIEW in data:
                assert data[WIDGET_VIEW]["model_id"] in state, (path.name, cell["source"][:2])
            views += "".join(data.get("text/html", "")).count("<iframe srcdoc=")
        if cell["cell_type"] == "code" and re.search(r"(embed|show)_scene\(", "".join(cell["source"])):
            assert cell.get("outputs"), f"{path.name}: a 3D view cell saved without its view"
    if path.name.startswith("04_"):
        assert views == 2, views           # the cylinder at resonance and the misfit wedge


def _links(nb):
    for cell in nb["cells"]:
        texts = ["".join(cell["source"])] if cell["cell_type"] == "markdown" else []
        for out in cell.get("outputs", []):
            texts += ["".join(v) for k, v in out.get("data", {}).items() if k in ("text/html", "text/markdown")]
        for text in texts:
            text = re.sub(r'srcdoc="[^"]*"', "", text)         # an embedded page's own contents
            yield from re.findall(r'href="([^"]+)"|\]\(([^)\s]+)\)', text)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_no_link_to_an_ignored_file(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    local = [a or b for a, b in _links(nb)]
    local = [link.split("#")[0] for link in local if link and not re.match(r"[a-z]+:|#", link)]
    for link in local:
        target = (path.parent / link).resolve()
        ignored = subprocess.run(["git", "check-ignore", "-q", str(target)], cwd=ROOT).returncode == 0
        assert not ignored, f"{path.name} links to {link}, which git ignores"
        assert target.exists(), f"{path.name} links to {link}, which does not exist"


# ---------------------------------------------------------------------------------------
# what a reader sees: no noise, no machine, no project history
# ---------------------------------------------------------------------------------------
#: an absolute path of some machine (POSIX home, work and temporary folders, a Windows drive)
MACHINE_PATH = re.compile(r"(?<![\w.~])(/root|/home|/Users|/work|/tmp|/var/folders)(?=[/\s'\"]|$)|\b[A-Za-z]:\\",
                          re.MULTILINE)
#: Python warning and error text: a category name, ``warnings.warn`` echo, a traceback
WARNING_TEXT = re.compile(r"\b[A-Z]\w*(Warning|Error)\b|warnings\.warn\(|Traceback \(most recent call last\)")
#: words about the project's own development rather than about the physics
DEVELOPMENT_WORDS = re.compile(r"\bissues?\s*#?\d+|#\d{1,4}\b|\bsessions?\b|\bhelpers?\b", re.IGNORECASE)


def _outputs(nb):
    """(cell index, output) of every saved output, the widgets' own output areas included."""
    for i, cell in enumerate(nb["cells"]):
        for out in cell.get("outputs", []):
            yield i, out
    state = nb["metadata"].get("widgets", {}).get(WIDGET_STATE, {}).get("state", {})
    for model in state.values():
        for out in model.get("state", {}).get("outputs", []) or []:
            yield "widget", out


def _output_texts(out):
    if out.get("output_type") == "stream":
        yield out.get("name", "stream"), "".join(out["text"])
    if out.get("output_type") == "error":
        yield "error", "\n".join([out.get("ename", ""), out.get("evalue", "")] + out.get("traceback", []))
    for kind, value in out.get("data", {}).items():
        if kind.startswith("text/"):
            text = "".join(value) if isinstance(value, list) else str(value)
            yield kind, re.sub(r'srcdoc="[^"]*"', "", text)       # an embedded 3D page's own script


def noise_in_notebook(nb) -> list[str]:
    """Every stderr or error output, warning text, machine path and development word a reader
    would see in ``nb`` (a notebook as JSON), as ``"cell N: what"`` lines."""
    found = []
    for i, out in _outputs(nb):
        if out.get("output_type") == "error" or out.get("name") == "stderr":
            found.append(f"cell {i}: {out.get('output_type')} {out.get('name', out.get('ename', ''))} output")
        for kind, text in _output_texts(out):
            for pattern, what in ((WARNING_TEXT, "warning text"), (MACHINE_PATH, "machine path"),
                                  (DEVELOPMENT_WORDS, "development word")):
                match = pattern.search(text)
                if match:
                    found.append(f"cell {i}: {what} {match.group(0)!r} in {kind}")
    for i, cell in enumerate(nb["cells"]):
        source = "".join(cell["source"])
        for pattern, what in ((MACHINE_PATH, "machine path"), (DEVELOPMENT_WORDS, "development word")):
            match = pattern.search(source)
            if match:
                found.append(f"cell {i}: {what} {match.group(0)!r} in its {cell['cell_type']} source")
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_saved_outputs_carry_no_noise(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    assert noise_in_notebook(nb) == [], path.name


def _noisy_notebook():
    stderr = {"output_type": "stream", "name": "stderr",
              "text": ["/work/main/bladedamp/__init__.py:62: AccuracyWarning: harmonic error estimate 3.4 %\n"]}
    cells = [{"cell_type": "markdown", "source": ["Solid blades (issue 16)."], "metadata": {}},
             {"cell_type": "code", "source": ["x = 1"], "outputs": [stderr], "metadata": {}},
             {"cell_type": "code", "source": ["print(folder)"], "metadata": {},
              "outputs": [{"output_type": "stream", "name": "stdout", "text": ["C:\\Users\\me\\blade.stl\n"]}]}]
    return {"cells": cells, "metadata": {}}


def test_the_noise_scan_finds_what_it_looks_for():
    found = noise_in_notebook(_noisy_notebook())
    assert any("stderr" in f for f in found)
    assert any("warning text 'AccuracyWarning'" in f for f in found)
    assert any("machine path '/work'" in f for f in found)
    assert any("machine path 'C:\\\\'" in f for f in found)
    assert any("development word 'issue 16'" in f for f in found)
    clean = {"cells": [{"cell_type": "markdown", "source": ["The wedge lifts off; a path: notebooks/04.ipynb, ~/tmp."],
                        "metadata": {}}], "metadata": {}}
    assert noise_in_notebook(clean) == []


# ---------------------------------------------------------------------------------------
# the first open: before anything runs, and untrusted
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_first_cell_says_how_to_run_and_trust(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    first = nb["cells"][0]
    text = "".join(first["source"])
    assert first["cell_type"] == "markdown"
    for needed in ('pip install -e ".[notebooks]"', "Run All", "File > Trust Notebook", "jupyter trust"):
        assert needed in text, f"{path.name}'s first cell does not say {needed!r}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_widget_and_3d_view_has_a_still_image(path):
    """An untrusted notebook draws no widget and strips iframes: the image in the saved outputs
    is what its reader sees. A widget's image travels in the widget's own output bundle (the
    front end picks the widget where it can draw it, the image elsewhere); a 3D view's still
    is an output of its own, with a line saying how to make the view live."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    for i, cell in enumerate(nb["cells"]):
        outputs = cell.get("outputs", [])
        for out in outputs:
            if WIDGET_VIEW in out.get("data", {}):
                assert "image/png" in out["data"], f"{path.name} cell {i}: a widget without a still image"
        live_3d = any("<iframe srcdoc=" in "".join(out.get("data", {}).get("text/html", "")) for out in outputs)
        if live_3d:
            assert any("image/png" in out.get("data", {}) for out in outputs), f"{path.name} cell {i}: no still"
            hints = "".join("".join(out.get("data", {}).get("text/markdown", "")) for out in outputs)
            assert "Trust Notebook" in hints, f"{path.name} cell {i}: no line on how to make the view live"


# ---------------------------------------------------------------------------------------
# pip install -e ".[notebooks]" brings what the notebooks import
# ---------------------------------------------------------------------------------------
def _requirement_name(requirement: str) -> str:
    return re.split(r"[\s<>=!~;\[]", requirement.strip(), maxsplit=1)[0].lower().replace("_", "-")


def _notebook_imports(path) -> set:
    import ast

    nb = json.loads(path.read_text(encoding="utf-8"))
    modules = set()
    for cell in nb["cells"]:
        if cell["cell_type"] != "code":
            continue
        lines = "".join(cell["source"]).splitlines()
        code = "\n".join(line for line in lines if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(code)):
            if isinstance(node, ast.Import):
                modules |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                modules.add(node.module.split(".")[0])
    return modules


def test_notebooks_extra_installs_every_notebook_import():
    """Every third-party module a notebook imports comes with the project's dependencies and its
    ``notebooks`` extra (directly or as their requirement); the extra also holds the ``viz``
    extra (the meshcat views of notebooks 04 and 07) and the ``fe`` extra (notebook 07's solid
    blade, which ``bladedamp`` imports gmsh and scikit-fem for)."""
    import importlib.metadata as md
    import sys
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    notebooks = {_requirement_name(r) for r in extras["notebooks"]}
    for extra in ("viz", "fe"):
        missing = {_requirement_name(r) for r in extras[extra]} - notebooks
        assert not missing, f"the notebooks extra lacks {sorted(missing)} of the {extra} extra"
    direct = notebooks | {_requirement_name(r) for r in project["dependencies"]}
    installed, todo = set(), list(direct)
    while todo:                     # what pip brings with them: their unconditional requirements
        name = todo.pop()
        if name in installed:
            continue
        installed.add(name)
        try:
            requires = md.requires(name) or []
        except md.PackageNotFoundError:
            continue
        todo += [_requirement_name(r) for r in requires if "extra ==" not in r]
    owners = md.packages_distributions()
    for path in NOTEBOOKS:
        for module in sorted(_notebook_imports(path)):
            if module in sys.stdlib_module_names or module == "bladedamp":
                continue
            dists = {_requirement_name(d) for d in owners.get(module, [module])}
            assert dists & installed, f"{path.name} imports {module} ({sorted(dists)}), not in the notebooks extra"


def test_readme_gives_the_reading_order_and_run_time_of_every_notebook():
    text = (ROOT / "notebooks" / "README.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (\d+) \| (\w+) \| ([^|]+) \|", text, flags=re.MULTILINE)
    assert [name for _, name, _ in rows] == [p.stem for p in NOTEBOOKS]
    assert [int(order) for order, _, _ in rows] == list(range(1, len(NOTEBOOKS) + 1))
    for _, name, time in rows:
        assert re.fullmatch(r"(\d+ min )?\d+ s|\d+ min", time.strip()), (name, time)


# ---------------------------------------------------------------------------------------
# pip install -e ".[notebooks]" brings what every notebook imports
# ---------------------------------------------------------------------------------------
def _requirement_names(requirements) -> set[str]:
    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name

    return {canonicalize_name(Requirement(r).name) for r in requirements}


def _installed_closure(names: set[str]) -> set[str]:
    """``names`` and, through the installed distributions' own requirements (not their extras),
    every distribution they pull in."""
    from importlib import metadata

    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name

    todo, seen = list(names), set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        try:
            requires = metadata.distribution(name).requires or []
        except metadata.PackageNotFoundError:
            continue
        for spec in requires:
            req = Requirement(spec)
            if req.marker is None or req.marker.evaluate({"extra": ""}):
                todo.append(canonicalize_name(req.name))
    return seen


def test_the_notebooks_extra_brings_every_notebook_import():
    """Every module a notebook imports is the standard library's, bladedamp's or a distribution
    that bladedamp's dependencies with the ``notebooks`` extra install; the extra holds the
    ``viz`` (3D views, notebooks 04 and 07) and ``fe`` (the solid blade, notebook 07) extras,
    which bladedamp imports lazily inside the functions those notebooks call."""
    import sys
    import tomllib
    from importlib import metadata

    from packaging.utils import canonicalize_name

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    wanted = _requirement_names(project["dependencies"]) | _requirement_names(extras["notebooks"])
    for extra in ("viz", "fe"):
        assert _requirement_names(extras[extra]) <= wanted, extra
    installed = _installed_closure(wanted)
    provided = metadata.packages_distributions()
    missing = []
    for path in NOTEBOOKS:
        for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
            if cell["cell_type"] != "code":
                continue
            for module in re.findall(r"^\s*(?:from|import)\s+(\w+)", "".join(cell["source"]), re.MULTILINE):
                if module in sys.stdlib_module_names or module == "bladedamp":
                    continue
                dists = {canonicalize_name(d) for d in provided.get(module, [])}
                if not dists & installed:
                    missing.append(f"{path.name}: {module} ({', '.join(sorted(dists)) or 'not installed'})")
    assert not missing, missing
