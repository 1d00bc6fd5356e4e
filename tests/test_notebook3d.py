"""Helpers of notebook 04 (contact in 3D): scene embedding without a server, the memoised wedge
lift-off callback, the misfit wedge, the flat cycle picture and Eq. 27's |w*|."""
import html
import time

import numpy as np
import pytest

pytest.importorskip("meshcat")
pytest.importorskip("trimesh")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import bladedamp as bd  # noqa: E402
from bladedamp.viz import meshcat_view as mv  # noqa: E402
from bladedamp.viz import notebook3d as nb3  # noqa: E402


@pytest.fixture(scope="module")
def cylinder_frf():
    frf = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (94.0, 97.0), harmonics=(1,))
    assert frf.success
    return frf


def test_embedding_and_saving_start_no_server(cylinder_frf, tmp_path):
    scene = mv.contact_map_scene(cylinder_frf, n_frames=6)
    out = nb3.scene_iframe(scene, height=300)
    assert out.count("<iframe srcdoc=") == 1 and "height: 300px" in out
    doc = out.split('srcdoc="', 1)[1].split('" style=', 1)[0]
    assert '"' not in doc                                          # attribute safely quoted
    assert html.unescape(doc) == scene.html()
    assert nb3.embed_scene(scene, height=300).data == out
    link = nb3.save_scene(scene, tmp_path / "views" / "maps.html")
    assert (tmp_path / "views" / "maps.html").read_text(encoding="utf-8") == scene.html()
    assert "maps.html" in link.data and "<a href=" in link.data
    assert not mv.LIVE_VIEWS and scene.vis.window.server_proc is None


def test_liftoff_callback_is_memoised_and_follows_the_physics():
    low = nb3.liftoff_case(2.0, 0.05)
    t = time.perf_counter()
    assert nb3.liftoff_case(2.0, 0.05 + 1e-9) is low                 # same key after rounding: cached
    assert time.perf_counter() - t < 0.01
    ref = nb3.liftoff_case(2.0, 0.1)
    # Fig. 9: the reference wedge (1 g, 0.1 N) lifts off at its edges; half the load does not
    assert not low.lifts_off.any() and ref.lifts_off.any()
    assert ref.ratio.max() > low.ratio.max()
    # the time-sample ratio is the first-harmonic one up to the sampling of the peak
    c = np.cos(np.pi / ref.n_samples)
    assert np.all(ref.ratio_time <= ref.ratio * (1 + 1e-9)) and np.all(ref.ratio_time >= c * ref.ratio * (1 - 1e-9))
    fig = nb3.liftoff_figure(2.0, 0.1)
    try:
        assert len(fig.axes) == 3                                  # OL, OR, colour bar
        assert "max r = %.2f" % ref.ratio[0].max() in fig.axes[0].get_title()
        np.testing.assert_allclose(fig.axes[0].collections[0].get_array(), ref.ratio[0])
        # the one-harmonic map says so, with its own harmonic error estimate, and no warning text
        assert np.isfinite(ref.harmonic_error) and ref.harmonic_error > 0
        label, suptitle = nb3.one_harmonic_label(ref.harmonic_error), fig.get_suptitle()
        assert " ".join(label.split()) in " ".join(suptitle.split())     # wrapped to fit the figure
    finally:
        plt.close(fig)


def test_one_harmonic_label_states_the_error_and_what_to_do():
    from bladedamp.hbm.accuracy import HARMONIC_TOLERANCE

    assert "not estimated" in nb3.one_harmonic_label(float("nan"))
    within = nb3.one_harmonic_label(0.5 * HARMONIC_TOLERANCE)
    assert within.startswith("one-harmonic approximation") and "within 1 %" in within
    above = nb3.one_harmonic_label(0.3)
    assert "up to about 30 %" in above and "harmonics='auto'" in above
    assert "Warning" not in above + within


def _png_size(png: bytes):
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")


@pytest.mark.skipif(mv.chromium_executable() is None, reason="no chromium")
def test_show_scene_leaves_a_still_and_says_how_to_go_live(cylinder_frf):
    from IPython.core.interactiveshell import InteractiveShell
    from IPython.utils.capture import capture_output

    InteractiveShell.instance()
    scene = mv.ods_scene(cylinder_frf, n_frames=6)
    png = nb3.scene_snapshot(scene, size=(640, 360))
    assert _png_size(png) == (640, 360)
    image = plt.imread(__import__("io").BytesIO(png))
    assert image[..., :3].reshape(-1, 3).std(axis=0).max() > 0.05        # something drawn, not a blank page
    with capture_output() as shown:
        live = nb3.show_scene(scene, height=360)
    kinds = [list(out.data) for out in shown.outputs]
    assert "image/png" in kinds[0] and "text/markdown" in kinds[1]
    assert shown.outputs[1].data["text/markdown"] == nb3.LIVE_VIEW_HINT
    assert "Trust Notebook" in nb3.LIVE_VIEW_HINT and "jupyter trust" in nb3.LIVE_VIEW_HINT
    assert live.data == nb3.scene_iframe(scene, 360)


def test_misfit_wedge_has_an_open_edge():
    disk, gaps = nb3.misfit_wedge_disk(2.0)
    n_xi = disk.damper.contact.points_across_height
    assert gaps.shape == (2, n_xi * disk.damper.contact.points_along_length)
    assert gaps[0].max() > 1e-5 and np.abs(gaps[1]).max() < 1e-9
    np.testing.assert_array_equal(disk.initial_gaps, gaps)


def test_cycle_figure_and_tangential_ratio(cylinder_frf):
    data = mv.cycle_data(cylinder_frf)
    fig = nb3.cycle_figure(data)
    try:
        mesh = fig.axes[0].collections[0]
        np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(data.states.shape[2], -1),
                                      data.states[:, 0, :].T)
    finally:
        plt.close(fig)
    w = nb3.tangential_ratio(cylinder_frf)
    # the 1 g cylinder at resonance slips (|w*| > 1) and its points stick on part of the cycle
    assert np.all(np.abs(w) > 1)
    share = cylinder_frf.point_state[data.index]
    assert np.all(share[..., 0] > 0) and np.all(share[..., 1] > 0)


# --------------------------------------------------------------------------------------
# the 3D view with a point's hysteresis loop beside it
# --------------------------------------------------------------------------------------
def test_hysteresis_loop_is_the_points_friction_cycle(cylinder_frf):
    """The loop's area (both tangential directions, trapezoidal rule over the samples) is the
    energy the point's slider dissipates (the contact model's backward-Euler sum), to within the
    two rules' difference 1/2 |sum dF . du|; on sticking samples its slope is the point's
    tangential stiffness k_T w_p (the elastic slider of the friction law)."""
    data = mv.cycle_data(cylinder_frf)
    u, f = data.displacement[..., :2], data.force[..., :2]
    du, df = np.roll(u, -1, axis=0) - u, np.roll(f, -1, axis=0) - f
    area = (0.5 * (np.roll(f, -1, axis=0) + f) * du).sum(axis=(0, 3))
    bound = 0.5 * np.abs((df * du).sum(axis=(0, 3)))
    assert np.all(np.abs(area - data.slip_work) <= bound) and np.all(data.slip_work > 0)
    direction, slip, force = nb3.hysteresis_loops(data)
    np.testing.assert_allclose(np.linalg.norm(direction, axis=-1), 1.0, rtol=1e-12)
    # the cylinder's points move along xi (the damper's axis eta sees no motion in 1F)
    np.testing.assert_allclose(np.abs(direction[..., 0]), 1.0, atol=1e-6)
    patch = data.patches[0]
    k_point = patch.tangential_stiffness * patch.weights                     # (P,)
    st = data.states
    both = (st == 0) & (np.roll(st, -1, axis=0) == 0)
    ds, dF = np.roll(slip, -1, axis=0) - slip, np.roll(force, -1, axis=0) - force
    moving = both & (np.abs(ds) > 1e-3 * np.abs(slip).max())
    assert moving.sum() > 10
    slope = (dF / np.where(moving, ds, 1.0))[moving]
    np.testing.assert_allclose(np.abs(slope), np.broadcast_to(k_point, st.shape)[moving], rtol=1e-6)
    # the panel draws these numbers: its pixels map back to slip and force
    panel = nb3.loop_panel(data, 12, point=("OR", 2))
    assert panel["point"] == "OR 3" and len(panel["loops"]) == 2 * patch.n_points
    xy = panel["loops"]["OR 3"]["xy"]
    x, y = panel["to_px"](slip[:, 1, 2], force[:, 1, 2])
    np.testing.assert_allclose(xy, np.column_stack([x, y]))
    np.testing.assert_array_equal(panel["loops"]["OR 3"]["states"], st[:, 1, 2])
    with pytest.raises(ValueError, match="point"):
        nb3.loop_panel(data, 12, point=("OX", 0))


def test_contact_view_marker_follows_the_animation_in_the_browser(cylinder_frf, tmp_path):
    """Headless Chromium: with the animation paused and sought to a phase, the panel's marker sits on
    the sample the 3D view paints there; the picker redraws the loop of the point picked."""
    import json
    import re
    import subprocess
    import tempfile

    exe = mv.chromium_executable()
    if exe is None:
        pytest.skip("no chromium on this machine (.ci/run installs the Debian package)")
    n_frames = 12
    scene = nb3.contact_view_scene(cylinder_frf, n_frames=n_frames, layout="sector")
    panel = scene.info["loop_panel"]
    data = scene.info["cycle"]
    probe = r"""<script>(function wait() {
      if (document.body.getAttribute('data-bd-ready') !== '1') { setTimeout(wait, 20); return; }
      var C = window.bladedampControls, m = document.getElementById('bd-loop-marker'), out = {};
      C.setPlaying(false); C.seek(90);
      setTimeout(function () {
        out.at90 = [parseFloat(m.getAttribute('cx')), parseFloat(m.getAttribute('cy')), parseInt(m.getAttribute('data-sample'))];
        C.seek(240);
        setTimeout(function () {
          out.at240 = [parseFloat(m.getAttribute('cx')), parseFloat(m.getAttribute('cy')), parseInt(m.getAttribute('data-sample'))];
          var pick = document.getElementById('bd-point'); pick.value = 'OR 3'; pick.dispatchEvent(new Event('change'));
          out.loop = document.getElementById('bd-loop').getAttribute('points');
          out.dots = document.getElementById('bd-loop-samples').children.length;
          out.panelFont = parseFloat(getComputedStyle(document.getElementById('bd-panel')).fontSize);
          document.title = 'REPORT' + JSON.stringify(out);
        }, 300);
      }, 300);
    })();</script></body>"""
    page = tmp_path / "view.html"
    page.write_text(scene.html().replace("</body>", probe), encoding="utf-8")
    with tempfile.TemporaryDirectory() as profile:
        out = subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                              f"--user-data-dir={profile}", "--virtual-time-budget=5000", "--window-size=1000,650",
                              "--dump-dom", "file://" + str(page)], capture_output=True, text=True, timeout=180).stdout
    found = re.search(r"<title>REPORT(\{.*?\})</title>", out)
    assert found, "the page did not report"
    r = json.loads(found.group(1))
    T = data.states.shape[0]
    for key, deg in (("at90", 90), ("at240", 240)):
        s = data.sample(int(np.floor(deg / 360 * n_frames + 1e-6)), n_frames)   # the frame painted
        assert r[key][2] == s
        np.testing.assert_allclose(r[key][:2], panel["loops"]["OL 1"]["xy"][s], atol=0.01)
    assert r["at90"][2] != r["at240"][2]
    drawn = np.array([[float(v) for v in p.split(",")] for p in r["loop"].split()])
    np.testing.assert_allclose(drawn[:-1], panel["loops"]["OR 3"]["xy"], atol=0.01)   # closed polyline
    assert r["dots"] == T and r["panelFont"] >= 12
