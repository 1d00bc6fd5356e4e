"""`bladedamp app`: the damper-design dashboard (bladedamp.app) and its Voila server.

The dashboard's controls are checked in-process (each control reaches the model; the response
shown is the library's own on an independently built disk; the damper-free response is linear in
the excitation; energy balance at the peak); the served app in headless Chromium (the page
shows the frequency response, a control moved redraws it with the right numbers, the 3D contact
view and its hysteresis loop appear when ticked).
"""
import base64
import importlib.util
import io
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import one_error_line

from bladedamp.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_app_without_voila_says_how_to_install(capsys, monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "voila" else real(name, *a))
    assert main(["app", "--no-browser"]) == 2
    one_error_line(capsys, "voila", "pip install 'bladedamp[app]'")


def test_app_bad_or_busy_port_one_line_exit_2(capsys):
    if importlib.util.find_spec("voila") is None:
        pytest.skip("voila is not installed (pip install 'bladedamp[app]')")
    assert main(["app", "--no-browser", "--port", "80"]) == 2
    one_error_line(capsys, "--port 80", "[1024, 65535]")
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        assert main(["app", "--no-browser", "--port", str(port)]) == 2
    one_error_line(capsys, f"--port {port}", "in use")


def test_the_dashboard_notebook_is_package_data():
    import tomllib

    from bladedamp.app import NOTEBOOK

    assert NOTEBOOK.is_file() and NOTEBOOK.parent.name == "app"
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "*.ipynb" in config["tool"]["setuptools"]["package-data"]["bladedamp.app"]
    assert any(d.startswith("voila") for d in config["project"]["optional-dependencies"]["app"])


@pytest.fixture(scope="module")
def board():
    pytest.importorskip("ipywidgets")
    import matplotlib

    matplotlib.use("Agg")
    from bladedamp.app import Dashboard

    return Dashboard()


def test_each_control_reaches_the_model_and_the_library_gives_the_shown_response(board):
    import dataclasses

    from bladedamp.app import DASHBOARD_MAX_STEP
    from bladedamp.reference import reference_damper, reference_disk
    from bladedamp.studies.mass import peak_response

    board.damper.value, board.mass.value, board.engine_order.value = "wedge", 2.0, 2
    board.friction.value, board.excitation.value = 0.5, 0.2
    damped, free = board.figure_data
    disk = damped.disk
    assert disk.damper.kind == "wedge" and disk.damper.mass == pytest.approx(2e-3, rel=1e-12)
    assert disk.engine_order == 2 and disk.damper.contact.friction_coefficient == 0.5
    assert np.array_equal(disk.excitation, [0.2, 0, 0, 0, 0, 0])
    # the same disk built on its own (the reference disk and damper of bladedamp.reference) and
    # the studies' peak search at the dashboard's step: the same peak
    own = dataclasses.replace(reference_disk("wedge", 2e-3, excitation=np.array([0.2, 0, 0, 0, 0, 0]), engine_order=2),
                              damper=reference_damper("wedge", 2e-3, friction_coefficient=0.5))
    peak, f_peak, _ = peak_response(own, (92.0, 100.0), harmonics=(1,), max_step=DASHBOARD_MAX_STEP)
    assert damped.peak_amplitude == pytest.approx(peak, rel=1e-9)
    assert damped.peak_frequency_hz == pytest.approx(f_peak, rel=1e-9)
    assert f"peak {1e3 * peak:.3f} mm at {f_peak:.2f} Hz" in board.status.value
    assert f"reduction {100 * (1 - peak / free.peak_amplitude):.1f} %" in board.status.value
    # energy balance per period at every point of the shown branch: the excitation's work is
    # dissipated by the blade's modal damping and by friction (the one-harmonic Galerkin balance
    # holds to the continuation's tolerance; 1e-6 of the work is far above it)
    r = damped.response
    assert np.allclose(r.excitation_work, r.viscous_dissipation + r.dissipated_energy,
                       rtol=1e-6, atol=1e-6 * np.max(np.abs(r.excitation_work)))
    assert np.max(r.dissipated_energy) > 0


def test_the_damper_free_response_is_linear_in_the_excitation(board):
    board.damper.value, board.engine_order.value = None, 1
    board.excitation.value = 0.1
    free_1 = board.figure_data[1]
    assert board.figure_data[0] is None and "no damper: peak" in board.status.value
    board.excitation.value = 0.3
    free_3 = board.figure_data[1]
    # linear: three times the load, three times the amplitude, same resonance
    assert free_3.peak_amplitude == pytest.approx(3 * free_1.peak_amplitude, rel=1e-9)
    assert free_3.peak_frequency_hz == pytest.approx(free_1.peak_frequency_hz, rel=1e-9)


# ---------------------------------------------------------------------------------------
# the served app in headless Chromium
# ---------------------------------------------------------------------------------------
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _png(src: str) -> np.ndarray:
    import matplotlib.image as mpimg

    assert src.startswith("data:image/png;base64,")
    return mpimg.imread(io.BytesIO(base64.b64decode(src.split(",", 1)[1])), format="png")


@pytest.mark.slow
@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed")
@pytest.mark.skipif(importlib.util.find_spec("voila") is None, reason="voila is not installed (pip install 'bladedamp[app]')")
@pytest.mark.skipif(importlib.util.find_spec("playwright") is None, reason="playwright is not installed")
def test_app_in_chromium_shows_the_frf_and_redraws_it_when_a_control_moves(tmp_path):
    from playwright.sync_api import sync_playwright

    from bladedamp.app import DASHBOARD_MAX_STEP, free_port, wait_for_port
    from bladedamp.viz.widgets import DiskFRFCache

    port = free_port()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    log = open(tmp_path / "server.log", "w")
    server = subprocess.Popen([sys.executable, "-m", "bladedamp.cli", "app", "--no-browser", "--port", str(port)],
                              stdout=log, stderr=subprocess.STDOUT, env=env, cwd=tmp_path)
    try:
        assert wait_for_port(port, 60.0, process=server), (tmp_path / "server.log").read_text()
        url = f"http://127.0.0.1:{port}/"
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--enable-unsafe-swiftshader", "--no-sandbox"])
            try:
                page = browser.new_page(viewport={"width": 1400, "height": 1200})
                page.goto(url, timeout=120_000)
                page.wait_for_selector(".bd-frf img", timeout=120_000)
                before = page.get_attribute(".bd-frf img", "src")
                assert "peak" in page.inner_text(".bd-status")
                page.locator("select").first.select_option(label="wedge")       # the damper type
                page.wait_for_function("s => { const i = document.querySelector('.bd-frf img'); "
                                       "return i && i.src !== s; }", arg=before, timeout=60_000)
                page.wait_for_function("() => document.querySelector('.bd-status').innerText.includes('peak')",
                                       timeout=60_000)
                after = page.get_attribute(".bd-frf img", "src")
                a, b = _png(before), _png(after)
                assert a.shape == b.shape and np.mean(np.any(a != b, axis=-1)) > 0.01   # the plot changed
                status = page.inner_text(".bd-status")
                # the numbers shown are the library's for the wedge at the controls' other values
                wedge = DiskFRFCache(max_step=DASHBOARD_MAX_STEP).response(
                    "wedge", 1e-3, 1, excitation=(0.1, 0, 0, 0, 0, 0), friction_coefficient=0.3)
                assert f"peak {1e3 * wedge.peak_amplitude:.3f} mm at {wedge.peak_frequency_hz:.2f} Hz" in status, status
                page.get_by_label("3D contact view and hysteresis loop").check()
                frame = page.wait_for_selector(".bd-contact iframe", timeout=60_000).content_frame()
                frame.wait_for_selector("#bd-loop-plot", timeout=30_000)
                assert "wedge damper 1 g" in frame.inner_text("#bd-overlay")
                page.screenshot(path=str(tmp_path / "app.png"), full_page=True)
            finally:
                browser.close()
    finally:
        server.send_signal(signal.SIGTERM)          # the command stops its Voila server
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait(10)
        log.close()
    assert server.returncode == 0
    with socket.socket() as s:                      # nothing listens there any more
        assert s.connect_ex(("127.0.0.1", port)) != 0
    assert re.search(rf"dashboard is at http://127\.0\.0\.1:{port}/", (tmp_path / "server.log").read_text())
