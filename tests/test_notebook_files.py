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
        if cell["cell_type"] == "code" and "embed_scene(" in "".join(cell["source"]):
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
