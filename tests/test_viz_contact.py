"""The 3D view teaches contact: the contact state (or the normal pressure) painted at every point
contact's position on the damper's and the platforms' faces, animated over the cycle; the page's
overlay (design, frequency, legend, play / pause, phase scrubber, camera and damper buttons),
checked in headless Chromium from screenshots and from the page's DOM."""
import json
import re
import subprocess
import tempfile

import numpy as np
import pytest

pytest.importorskip("meshcat")
pytest.importorskip("trimesh")

import bladedamp as bd  # noqa: E402
from bladedamp import geometry as bgeo  # noqa: E402
from bladedamp import palette  # noqa: E402
from bladedamp.viz import meshcat_view as mv  # noqa: E402

N_FRAMES = 16          # the reference disk's interblade phase (EO 1 of 16 blades) is one frame
SIZE = (900, 650)      # browser window [px]


@pytest.fixture(scope="module")
def cylinder_frf():
    """The reference cylinder (1 g) through its 1F resonance, one harmonic."""
    frf = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (94.0, 97.0), harmonics=(1,))
    assert frf.success
    return frf


def _on_surface(points, mesh, tol):
    """Distance of each point to the nearest triangle of ``mesh`` whose plane it lies in and
    inside which it projects (np.inf when there is none)."""
    tri = mesh.vertices[mesh.faces]                                   # (F, 3, 3)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    out = []
    for p in np.atleast_2d(points):
        d = np.einsum("fi,fi->f", p - a, n)
        q = p - d[:, None] * n
        # barycentric coordinates of q
        v0, v1, v2 = b - a, c - a, q - a
        d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
        d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
        den = d00 * d11 - d01 * d01
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        inside = (v >= -tol) & (w >= -tol) & (v + w <= 1 + tol)
        out.append(np.abs(d[inside]).min() if inside.any() else np.inf)
    return np.array(out)


@pytest.mark.parametrize("kind", ["cylinder", "wedge"])
def test_contact_points_lie_on_the_damper_and_on_the_platform_faces(kind):
    """The painted positions are the patch points on the drawn surfaces: each lies on the damper
    mesh (about its CG) and on its platform's mesh (each blade in its own frame), meshes built by
    :mod:`bladedamp.geometry` independently of the points; the points fill l_C (and h_C)."""
    disk = bd.reference_disk(kind, 1e-3)
    g = bgeo.reference_blade_geometry()
    points = g.points()
    lay = bgeo.sector_layout(points, disk.damper, disk.gamma_left, disk.gamma_right)
    pts = lay.contact_points()
    patches = lay.geometry.patches
    assert pts.shape == (2, patches[0].n_points, 3)
    damper = bgeo.damper_mesh(disk.damper, disk.gamma_left, disk.gamma_right)
    platform = bgeo.blade_mesh(g, disk.gamma_left, disk.gamma_right, lay.own_contact_centres(points)).platform
    own = [pts[0], pts[1] + np.array([lay.pitch, 0.0, 0.0])]            # OL on blade i, OR on blade i + 1
    tol = 1e-9
    for c in range(2):
        assert np.all(_on_surface(pts[c] - lay.damper_cg, damper, tol) < 1e-9)
        assert np.all(_on_surface(own[c], platform, tol) < 1e-9)
        # cells of equal size: the points' centroid is the contact centre, their spread along the
        # damper axis (y) (n_eta - 1) / n_eta of l_C
        np.testing.assert_allclose(pts[c].mean(axis=0), lay.contact_centres[c], atol=1e-15)
        p = patches[c]
        assert np.ptp(pts[c][:, 1]) == pytest.approx(p.length * (p.n_eta - 1) / p.n_eta, rel=1e-12)
        across = np.ptp(pts[c] @ lay.frames[c][0])
        assert across == pytest.approx(p.height * (p.n_xi - 1) / p.n_xi, abs=1e-15)


def _tile_centres(scene, path):
    geometry = scene.object(path).geometry
    v = np.asarray(geometry.vertices, float).reshape(-1, 4, 3)
    return v.mean(axis=1), np.asarray(geometry.color, float).reshape(-1, 4, 3)


def test_painted_faces_carry_the_contact_states_over_the_cycle(cylinder_frf):
    scene = mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, layout="sector")
    data = scene.info["cycle"]
    disk = cylinder_frf.disk
    lay = bgeo.sector_layout(bgeo.reference_blade_geometry().points(), disk.damper, disk.gamma_left,
                             disk.gamma_right)
    pts = lay.contact_points()
    paint = scene.info["paint"]
    assert paint["kind"] == "state" and sorted(paint["dampers"]) == [0, 1]
    for k in (0, 1):
        blades = (k, k + 1)
        for f in range(N_FRAMES):
            s = data.sample(f + k, N_FRAMES)      # damper k: damper 0 one interblade phase later
            for c, name in enumerate(("OL", "OR")):
                expected = np.array([palette.rgb(palette.CONTACT_STATES[v]) for v in data.states[s, c]])
                zeta = lay.frames[c][2]
                shift = np.array([c * lay.pitch, 0.0, 0.0])
                centres, colours = _tile_centres(
                    scene, f"bladedamp/blades/blade_{blades[c]:02d}/platform/paint/damper_{k:02d}_{name}/frame_{f:03d}")
                np.testing.assert_allclose(centres, pts[c] + shift + mv.PAINT_OFFSET * zeta, atol=1e-7)
                np.testing.assert_allclose(colours, np.repeat(expected[:, None], 4, axis=1), atol=1e-6)
                centres, colours = _tile_centres(
                    scene, f"bladedamp/dampers/damper_{k:02d}/body/paint/{name}/frame_{f:03d}")
                np.testing.assert_allclose(centres, pts[c] - lay.damper_cg - mv.PAINT_OFFSET * zeta, atol=1e-7)
                np.testing.assert_allclose(colours, np.repeat(expected[:, None], 4, axis=1), atol=1e-6)
    # the cylinder at resonance sticks and slips on the cycle: the painted colours change
    colours = paint["dampers"][0]["colors"]
    assert len({tuple(np.round(x, 6)) for x in colours.reshape(-1, 3)}) == 2
    # one frame shown at a time, in discrete steps
    clips = {p.lower(): clip for p, clip in scene.animation().clips.items()}
    track = clips["/meshcat/bladedamp/blades/blade_00/platform/paint/damper_00_OL/frame_003"].tracks["visible"]
    assert track.values == [f % N_FRAMES == 3 for f in range(N_FRAMES + 1)]
    assert track.lower()["interpolation"] == 2300


def test_pressure_paint_is_the_normal_load_over_the_cell(cylinder_frf):
    """Line contact: N/mm = the point's normal load over its length l_C / n_eta. Summed over the
    points and averaged over the cycle it is the static normal load (one harmonic, linear normal
    law, no separation at this resonance: the first harmonic averages to zero)."""
    scene = mv.ods_scene(cylinder_frf, n_frames=8, layout="sector", paint="pressure")
    data = scene.info["cycle"]
    p, unit = mv.point_pressure(data)
    patch = data.patches[0]
    assert unit == "N/mm" and patch.height == 0
    assert not (data.states == 2).any()
    load = p * 1e3 * patch.length / patch.n_eta                         # (T, 2, P) [N]
    np.testing.assert_allclose(load.sum(axis=2).mean(axis=0),
                               cylinder_frf.disk.static_normal_loads(data.frequency_hz), rtol=1e-9)
    import matplotlib

    entry = scene.info["paint"]["dampers"][0]
    vmax = p.max()
    f = 5
    expected = matplotlib.colormaps["viridis"](p[entry["samples"][f]] / vmax)[..., :3]
    np.testing.assert_allclose(entry["colors"][f], expected, atol=1e-12)
    assert 'normal pressure [N/mm]: 0' in scene.overlay and f"{vmax:.3g}</div>" in scene.overlay


def test_bad_view_options_name_the_parameter(cylinder_frf):
    for options, name in ((dict(paint="heat"), "paint"), (dict(damper_view="ghost"), "damper_view"),
                          (dict(view="top"), "view"), (dict(painted_dampers=[5]), "painted_dampers")):
        with pytest.raises(ValueError, match=name):
            mv.ods_scene(cylinder_frf, n_frames=2, layout="sector", **options)


# --------------------------------------------------------------------------------------
# in the browser
# --------------------------------------------------------------------------------------
def _chromium(args, timeout=180):
    exe = mv.chromium_executable()
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                               "--no-first-run", "--disable-background-networking", f"--user-data-dir={profile}"]
                              + args, capture_output=True, text=True, timeout=timeout)


def _screenshot(url, png):
    _chromium([f"--screenshot={png}", f"--window-size={SIZE[0]},{SIZE[1]}", "--virtual-time-budget=3000", url])
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGB"), dtype=float)


def test_browser_shows_the_state_colours_at_the_projected_contact_points(cylinder_frf, tmp_path):
    """Headless Chromium, default camera (damper 0 between its platforms), exploded damper, motion
    drawn true to scale (the platforms move by well under a pixel, the tiles span tens): at two
    phases of the cycle, the pixel at the projection of every contact point of damper 0 (on the
    platforms' faces) has the palette colour of that point's state then; the two phases are
    picked where the states differ, and so do the pixels."""
    if mv.chromium_executable() is None:
        pytest.skip("no chromium on this machine (.ci/run installs the Debian package)")
    scene = mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, layout="sector", scale=1.0, damper_view="exploded")
    html = scene.save_html(tmp_path / "view.html")
    entry = scene.info["paint"]["dampers"][0]
    target, position = scene.info["camera"]
    px = mv.project(entry["world"].reshape(-1, 3), target, position, SIZE)
    assert np.all((px > 0) & (px < np.array(SIZE)))
    # the tiles are larger on the screen than the platforms' motion: the smallest half-extent of a
    # projected tile against a bound of the OL point's motion (sum of its harmonic amplitudes)
    # times the largest projected length of 1 m at the points
    lay = bgeo.sector_layout(bgeo.reference_blade_geometry().points(), cylinder_frf.disk.damper,
                             cylinder_frf.disk.gamma_left, cylinder_frf.disk.gamma_right)
    half = []
    for c, name in enumerate(("OL", "OR")):
        v = np.asarray(scene.object(f"bladedamp/blades/blade_{c:02d}/platform/paint/damper_00_{name}/frame_000")
                       .geometry.vertices, float).reshape(-1, 4, 3) - np.array([c * lay.pitch, 0.0, 0.0])
        corners = mv.project(v.reshape(-1, 3), target, position, SIZE).reshape(-1, 4, 2)
        centre = corners.mean(axis=1, keepdims=True)
        half.append(np.linalg.norm(0.5 * (corners[:, [0, 1]] + corners[:, [3, 2]]) - centre, axis=2).min())
        half.append(np.linalg.norm(0.5 * (corners[:, [0, 3]] + corners[:, [1, 2]]) - centre, axis=2).min())
    blade = cylinder_frf.disk.blade
    X = np.asarray(cylinder_frf.coefficients[scene.info["index"]])[:, :blade.n_modes]
    motion = np.abs(X @ blade.shape("OL")[:3].T).sum(axis=0).max() + 0.012 * np.abs(X @ blade.shape("OL")[3:].T).sum(axis=0).max()
    p0 = entry["world"].reshape(-1, 3)
    px_per_m = max(np.linalg.norm(mv.project(p0 + 1e-4 * e, target, position, SIZE) - px, axis=1).max() / 1e-4
                   for e in np.eye(3))
    assert motion * px_per_m + 1.0 < min(half), (motion * px_per_m, min(half))
    colours = entry["colors"].reshape(N_FRAMES, -1, 3)
    slip = [f for f in range(N_FRAMES) if (colours[f] == palette.rgb(palette.SLIP)).all(axis=1).any()]
    stick = [f for f in range(N_FRAMES) if (colours[f] == palette.rgb(palette.STICK)).all(axis=1).any()]
    assert slip and stick
    f1, f2 = slip[0], next(f for f in stick if (colours[f] != colours[slip[0]]).any())
    shots = {}
    for f in (f1, f2):
        phase_deg = 360.0 * f / N_FRAMES
        img = _screenshot(f"file://{html}?phase={phase_deg}&paused", tmp_path / f"phase_{f}.png")
        shots[f] = np.array([img[int(round(y)), int(round(x))] for x, y in px])
        np.testing.assert_allclose(shots[f], 255 * colours[f], atol=3.0)      # 8-bit rounding
    changed = np.abs(colours[f1] - colours[f2]).max(axis=1) > 0.3
    assert changed.any()
    assert np.all(np.abs(shots[f1] - shots[f2]).max(axis=1)[changed] > 60)


def _dom_report(html_path, probe_js, tmp_path, budget_ms=4000):
    """Run ``probe_js`` (sets document.title to 'REPORT' + JSON) in the page once it is ready."""
    page = tmp_path / "probe.html"
    text = open(html_path, encoding="utf-8").read()
    probe = ("<script>(function wait() {if (document.body.getAttribute('data-bd-ready') !== '1') "
             "{setTimeout(wait, 20); return;} " + probe_js + "})();</script></body>")
    page.write_text(text.replace("</body>", probe), encoding="utf-8")
    out = _chromium([f"--virtual-time-budget={budget_ms}", f"--window-size={SIZE[0]},{SIZE[1]}", "--dump-dom",
                     "file://" + str(page)]).stdout
    found = re.search(r"<title>REPORT(\{.*?\})</title>", out)
    assert found, "the page did not report"
    return json.loads(found.group(1).replace("&amp;", "&"))


def test_browser_overlay_text_size_and_controls(cylinder_frf, tmp_path):
    """The overlay's text is rendered at 12 px or more (computed style of every element that holds
    text), names the design and the frequency, and its controls act on the viewer: play / pause
    stops and starts the animator, the scrubber seeks it to its phase, the camera buttons put the
    camera where the scene's presets say, the damper buttons make it transparent (opacity 0.3)
    and explode it (moved radially inwards)."""
    if mv.chromium_executable() is None:
        pytest.skip("no chromium on this machine (.ci/run installs the Debian package)")
    scene = mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, layout="sector", damper_view="solid", title="test design")
    html = scene.save_html(tmp_path / "view.html")
    probe = r"""
      var out = {}, a = viewer.animator, C = window.bladedampControls;
      var texts = Array.from(document.querySelectorAll('#bd-overlay *')).filter(function (e) {
        return Array.from(e.childNodes).some(function (n) { return n.nodeType === 3 && n.textContent.trim(); });
      });
      out.sizes = texts.map(function (e) { return parseFloat(getComputedStyle(e).fontSize); });
      out.heights = texts.map(function (e) { return e.getBoundingClientRect().height; });
      out.title = document.getElementById('bd-title').textContent;
      out.frequency = document.getElementById('bd-frequency').textContent;
      out.legend = document.getElementById('bd-legend').textContent;
      out.playing0 = a.playing;
      document.getElementById('bd-play').click();
      out.playing1 = a.playing; out.label1 = document.getElementById('bd-play').textContent;
      document.getElementById('bd-play').click();
      out.playing2 = a.playing; out.label2 = document.getElementById('bd-play').textContent;
      var s = document.getElementById('bd-phase'); s.value = '90'; s.dispatchEvent(new Event('input'));
      out.playing3 = a.playing; out.time3 = a.actions[0].time; out.phase3 = C.phase();
      out.shown3 = document.getElementById('bd-phase-value').textContent;
      var cam = function () { var p = viewer.camera.position; return [p.x, p.y, p.z]; };
      out.camera0 = cam();
      document.getElementById('bd-view-whole').click(); out.camera1 = cam();
      out.root1 = Array.from(viewer.scene_tree.find(['meshcat', 'bladedamp']).object.position.toArray());
      document.getElementById('bd-view-damper').click(); out.camera2 = cam();
      var mesh = viewer.scene_tree.find(['meshcat', 'bladedamp', 'dampers', 'damper_00', 'body', 'mesh']).object;
      var material = function () { var m = null; mesh.traverse(function (o) { if (o.material) { m = o.material; } });
                                   return [m.opacity, m.transparent]; };
      out.opacity0 = material();
      document.getElementById('bd-damper-transparent').click(); out.opacity1 = material();
      document.getElementById('bd-damper-exploded').click();
      out.opacity2 = material(); out.mesh2 = mesh.position.toArray();
      out.paint2 = viewer.scene_tree.find(['meshcat', 'bladedamp', 'dampers', 'damper_00', 'body', 'paint'])
                     .object.position.toArray();
      document.getElementById('bd-damper-solid').click(); out.mesh3 = mesh.position.toArray();
      document.title = 'REPORT' + JSON.stringify(out);
    """
    r = _dom_report(html, probe, tmp_path)
    assert len(r["sizes"]) >= 10 and min(r["sizes"]) >= 12.0, r["sizes"]
    assert min(r["heights"]) >= 12.0
    assert r["title"] == "test design"
    assert f"{scene.info['frequency_hz']:.2f} Hz" in r["frequency"]
    assert all(name in r["legend"] for name in ("stick", "slip", "separated"))
    # play / pause
    assert r["playing0"] and not r["playing1"] and r["label1"] == "play"
    assert r["playing2"] and r["label2"] == "pause"
    # the scrubber pauses and seeks: 90 deg is a quarter of the period
    assert not r["playing3"] and r["time3"] == pytest.approx(0.25 * scene.info["period_s"], abs=1e-9)
    assert r["phase3"] == pytest.approx(90.0, abs=1e-6) and r["shown3"] == "90\u00b0"
    # the camera presets: three.js position = blade-frame offset (x, z, -y)
    whole, damper = scene.info["cameras"]["whole"], scene.info["cameras"]["damper"]

    def three(offset):
        return [offset[0], offset[2], -offset[1]]
    np.testing.assert_allclose(r["camera0"], three(damper[1]), atol=1e-6)
    np.testing.assert_allclose(r["camera1"], three(whole[1]), atol=1e-6)
    np.testing.assert_allclose(r["camera2"], three(damper[1]), atol=1e-6)
    np.testing.assert_allclose(r["root1"], -whole[0], atol=1e-6)
    # the damper: solid, transparent, exploded (along -z of its frame), solid again
    assert r["opacity0"] == [1, False] and r["opacity1"] == [pytest.approx(mv.DAMPER_OPACITY), True]
    assert r["opacity2"] == [1, False]
    drop = scene.info["explode"][:3, 3]
    assert drop[2] < 0 and drop[0] == drop[1] == 0
    np.testing.assert_allclose(r["mesh2"], drop, atol=1e-7)
    np.testing.assert_allclose(r["paint2"], drop, atol=1e-7)
    np.testing.assert_allclose(r["mesh3"], 0.0, atol=1e-12)
