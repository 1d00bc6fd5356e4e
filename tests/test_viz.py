"""meshcat views: scene tree, standalone HTML, localhost server clean-up, headless-browser rendering."""
import os
import socket

import numpy as np
import pytest

pytest.importorskip("meshcat")
pytest.importorskip("trimesh")

import bladedamp as bd  # noqa: E402
from bladedamp.viz import meshcat_view as mv  # noqa: E402

N_FRAMES = 12


@pytest.fixture(scope="module")
def cylinder_frf():
    """The reference cylinder (1 g) through its 1F resonance, one harmonic."""
    frf = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (90.0, 105.0), harmonics=(1,))
    assert frf.success
    return frf


@pytest.fixture(scope="module")
def ods(cylinder_frf):
    return mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, contact_maps=True)


def test_blade_deflection_matches_the_mode_shapes_at_the_known_points():
    blade = bd.reference_blade()
    rng = np.random.default_rng(1)
    q = rng.normal(size=blade.n_modes)
    z = np.array([0.0, blade.points["platform"][2], blade.points["tip"][2]])
    u, phi = mv.blade_deflection(blade, q, z)
    np.testing.assert_allclose(u[0], 0.0, atol=1e-15)
    np.testing.assert_allclose(phi[0], 0.0, atol=1e-15)
    for k, name in ((1, "platform"), (2, "tip")):
        m = blade.shape(name) @ q
        np.testing.assert_allclose(u[k], m[:3], rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(phi[k], m[3:], rtol=1e-12, atol=1e-15)
    # the 1F mode alone: a monotone cantilever-like deflection in x
    zz = np.linspace(0, blade.points["tip"][2], 50)
    u1, _ = mv.blade_deflection(blade, np.eye(blade.n_modes)[0], zz)
    assert np.all(np.diff(u1[:, 0]) > 0)


def test_scene_tree(ods, cylinder_frf):
    info = ods.info
    assert info["frequency_hz"] == pytest.approx(cylinder_frf.peak_frequency_hz)
    paths = ods.paths()
    g = bd.blade.reference_blade_geometry()
    n_seg = g.n_elements_shank + g.n_elements_airfoil
    for k in range(3):
        base = f"/meshcat/bladedamp/blades/blade_{k:02d}"
        assert f"{base}/root" in paths and f"{base}/platform/mesh" in paths
        assert all(f"{base}/segment_{s:02d}/mesh" in paths for s in range(n_seg))
    for k in range(2):
        assert f"/meshcat/bladedamp/dampers/damper_{k:02d}/body/mesh" in paths
    for c in ("OL", "OR"):
        assert all(f"/meshcat/bladedamp/contact_map/state/{c}/frame_{f:03d}" in paths for f in range(N_FRAMES))
        assert f"/meshcat/bladedamp/contact_map/liftoff/{c}" in paths
    assert "/meshcat/bladedamp/legend" in paths
    # one cycle: N_FRAMES + 1 keys (the last repeats the first) on every animated path
    anim = ods.animation()
    assert anim is not None
    clips = {path.lower(): clip for path, clip in anim.clips.items()}
    assert "/meshcat/bladedamp/dampers/damper_00/body" in clips
    assert f"/meshcat/bladedamp/blades/blade_01/segment_{n_seg - 1:02d}" in clips
    for clip in clips.values():
        for track in clip.tracks.values():
            assert track.frames == list(range(N_FRAMES + 1))
    # the tip segment swings: positions half a period apart differ by about twice the drawn amplitude
    from meshcat.transformations import quaternion_matrix

    tracks = clips[f"/meshcat/bladedamp/blades/blade_00/segment_{n_seg - 1:02d}"].tracks
    z_mid = g.total_length - 0.5 * g.airfoil_length / g.n_elements_airfoil
    mid = []
    for p, (x, y, z, w) in zip(tracks["position"].values, tracks["quaternion"].values):
        mid.append(quaternion_matrix([w, x, y, z])[:3, :3] @ [0, 0, z_mid] + p)   # where the segment middle is
    mid = np.array(mid)
    swing = np.linalg.norm(mid[:N_FRAMES // 2] - mid[N_FRAMES // 2:N_FRAMES], axis=1).max()
    assert swing == pytest.approx(2 * info["scale"] * info["tip_amplitude"], rel=0.1)
    # state maps: exactly one frame visible at a time, discrete steps
    track = clips["/meshcat/bladedamp/contact_map/state/OL/frame_003"].tracks["visible"]
    assert track.values == [f % N_FRAMES == 3 for f in range(N_FRAMES + 1)]
    assert track.lower()["interpolation"] == 2300


def test_contact_colours_follow_the_states(ods):
    states = np.array(ods.info["state_frames"])            # (frames, 2, P)
    colors = ods.info["state_colors"]                      # (frames, 2, P, 3)
    assert states.shape[0] == N_FRAMES
    assert (states == 0).any() and (states == 1).any(), "resonance of the 1 g cylinder sticks and slips"
    np.testing.assert_allclose(colors, mv.STATE_COLORS[states])
    stick, slip = colors[states == 0], colors[states == 1]
    assert np.all(np.abs(stick[:, None, :] - slip[None, :, :]).max(axis=-1) > 0.3)
    # the colours really are in the scene: vertex colours of the recorded tile meshes
    f = int(np.flatnonzero((states[:, 0] == 1).any(axis=1))[0])
    geometry = ods.object(f"bladedamp/contact_map/state/OL/frame_{f:03d}").geometry
    P = states.shape[2]
    np.testing.assert_allclose(geometry.color[::4][:P], colors[f, 0], atol=1e-6)


def test_liftoff_ratio_is_that_of_the_wedge_liftoff_map():
    from bladedamp.studies.design import peak_response, wedge_liftoff_map

    disk = bd.reference_disk("wedge", 0.28e-3)
    reference = wedge_liftoff_map(disk)
    _, _, frf = peak_response(disk, (90.0, 105.0), max_step=0.05)      # the response wedge_liftoff_map evaluates
    data = mv.cycle_data(frf)
    assert data.frequency_hz == pytest.approx(reference.peak_frequency_hz, rel=1e-9)
    np.testing.assert_allclose(data.liftoff_ratio, reference.ratio_time, rtol=1e-6, atol=1e-9)


def test_static_html_is_standalone_and_starts_no_server(cylinder_frf, tmp_path):
    scene = mv.contact_map_scene(cylinder_frf, n_frames=4)
    path = scene.save_html(tmp_path / "map.html")
    html = open(path, encoding="utf-8").read()
    assert "MeshCat.Viewer" in html and html.count("fetch(\"data:application/octet-binary;base64,") > 10
    assert scene.vis.window.server_proc is None
    shown = mv.show(cylinder_frf, path=tmp_path / "ods.html", n_frames=4)
    assert isinstance(shown, mv.Scene) and (tmp_path / "ods.html").stat().st_size > len(html) // 2


def _listening_addresses(port):
    """Local addresses (hex, as in /proc/net/tcp*) listening on ``port``."""
    found = []
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(name):
            continue
        with open(name) as f:
            for line in f.readlines()[1:]:
                fields = line.split()
                addr, state = fields[1], fields[3]
                if state == "0A" and int(addr.split(":")[1], 16) == port:
                    found.append(addr.split(":")[0])
    return found


def test_live_server_binds_localhost_and_is_cleaned_up(cylinder_frf):
    scene = mv.contact_map_scene(cylinder_frf, n_frames=2, animate=False)
    with scene.serve() as view:
        proc = view.server_proc
        assert proc.poll() is None
        assert view.url.startswith("http://127.0.0.1:")
        assert view.zmq_url.startswith("tcp://127.0.0.1:")
        port = int(view.url.split(":")[2].split("/")[0])
        if os.path.exists("/proc/net/tcp"):
            addrs = _listening_addresses(port)
            assert addrs and all(a in ("0100007F", "00000000000000000000000001000000") for a in addrs), addrs
        # the server has the scene: its static HTML carries the replayed commands
        assert view.vis.static_html().count("handle_command_bytearray") >= len(scene.paths())
    assert proc.poll() is not None                 # killed and reaped
    with socket.socket() as s:
        assert s.connect_ex(("127.0.0.1", port)) != 0
    view.close()                                   # idempotent


def _pixels(path):
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=float)


@pytest.mark.slow
def test_browser_renders_the_scene_and_its_animation(cylinder_frf, tmp_path):
    if mv.chromium_executable() is None:
        pytest.skip("no chromium on this machine (.ci/run installs the Debian package)")
    empty = mv.Scene()
    mv.plain_stage(empty.vis)                                      # the scenes' own stage, nothing on it
    shots = {}
    # the whole sector in view (the close-up on a damper, the default, is checked in test_viz_contact.py)
    scenes = {"empty": empty,
              "phase0": mv.ods_scene(cylinder_frf, animate=False, phase=0.5 * np.pi, n_frames=N_FRAMES, view="whole"),
              "phase1": mv.ods_scene(cylinder_frf, animate=False, phase=1.5 * np.pi, n_frames=N_FRAMES, view="whole")}
    animated = mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, period_s=2.0, view="whole")
    for name, scene in scenes.items():
        html = scene.save_html(tmp_path / f"{name}.html")
        shots[name] = _pixels(mv.screenshot(html, tmp_path / f"{name}.png", virtual_time_ms=2000))
    html = animated.save_html(tmp_path / "animated.html")
    for budget in (2500, 3500):                    # a quarter and three quarters into a cycle
        shots[f"t{budget}"] = _pixels(mv.screenshot(html, tmp_path / f"t{budget}.png", virtual_time_ms=budget))

    def changed(a, b):
        return float((np.abs(a - b).sum(axis=-1) > 30).mean())

    for name in ("phase0", "t2500"):
        assert shots[name].std() > shots["empty"].std() + 1.0
        assert changed(shots[name], shots["empty"]) > 0.02          # the scene covers > 2 % of the picture
    assert changed(shots["phase0"], shots["phase1"]) > 0.005        # two frames of the cycle differ
    assert changed(shots["t2500"], shots["t3500"]) > 0.005          # the animation plays


def test_show_defaults_to_the_whole_disk_with_its_dampers_and_the_maps_beside_it(cylinder_frf, tmp_path):
    from bladedamp import geometry as bgeo

    scene = mv.show(cylinder_frf, path=tmp_path / "ods.html", n_frames=4)
    info = scene.info
    n = cylinder_frf.disk.n_blades
    assert info["layout"] == "disk" and len(info["blades"]) == n
    paths = scene.paths()
    assert all(f"/meshcat/bladedamp/dampers/damper_{k:02d}/body/mesh" in paths for k in range(n))
    # the contact is painted on damper 0's faces, not drawn beside the disk (no maps by default)
    assert list(info["paint"]["dampers"]) == [0] and not any("contact_map" in p for p in paths)
    # asked for, the maps and their legend lie right of the blade tips' circle: they cross no blade
    info = mv.show(cylinder_frf, n_frames=4, contact_maps=True).info
    r_tip = info["root_radius"] + bgeo.reference_blade_geometry().total_length
    x0 = info["map_origin"][0]
    assert x0 > r_tip
    # without a damper there is no disk layout to draw: the sector
    free = bd.frequency_response(bd.reference_disk(None), (90.0, 100.0), harmonics=(1,))
    assert mv.show(free, n_frames=4).info["layout"] == "sector"


def test_without_meshcat_the_3d_names_give_a_one_line_install_hint(monkeypatch):
    import sys

    import bladedamp.viz as viz

    monkeypatch.delitem(sys.modules, "bladedamp.viz.meshcat_view", raising=False)
    monkeypatch.delattr(viz, "meshcat_view", raising=False)
    monkeypatch.setitem(sys.modules, "meshcat", None)          # as if not installed
    with pytest.raises(ModuleNotFoundError) as err:
        viz.show
    message = str(err.value)
    assert "\n" not in message and "pip install 'bladedamp[viz]'" in message


# --------------------------------------------------------------------------------------
# the solid FE blade's deformed surface (issue 16)
# --------------------------------------------------------------------------------------
SOLID_ELEMENT_SIZE = 12e-3     # [m] coarse solid blade: ~340 surface vertices, 4 s


@pytest.fixture(scope="module")
def solid_frf():
    """The reference cylinder (1 g) with the solid FE blade, through its 1F resonance, one harmonic."""
    pytest.importorskip("gmsh")
    pytest.importorskip("skfem")
    import dataclasses
    from bladedamp import solid

    blade = solid.solid_blade(None, SOLID_ELEMENT_SIZE)
    disk = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), blade=blade)
    frf = bd.frequency_response(disk, (97.5, 100.5), harmonics=(1,), max_step=0.1)
    assert frf.success, frf.message
    return frf


def _html_commands(html: str) -> list:
    """The meshcat commands packed in a standalone HTML (base64 msgpack of every fetch)."""
    import base64
    import re
    import umsgpack

    return [umsgpack.unpackb(base64.b64decode(b))
            for b in re.findall(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"\)', html)]


def _array(packed, width=3) -> np.ndarray:
    return np.frombuffer(packed["array"].data, dtype=np.float32).reshape(-1, width).astype(float)


def _fe_surface_expected(frf, q) -> np.ndarray:
    """Vertices of the FE surface displaced by modal coordinates q, from the solid's own FE field
    (P2 interpolation at the points, not the stored surface shapes)."""
    blade = frf.disk.blade
    x = blade.surface.vertices
    u = blade.modes.displacements_at(x)[:, :, list(blade.mode_indices)]           # (n_v, 3, n_m)
    return x, u @ q


def test_solid_blade_view_draws_the_fe_surface_deformed_by_the_modes(solid_frf):
    """show() of a disk with the solid blade: every blade is the FE boundary surface (the
    tetrahedral mesh's outer triangles), drawn once with the scaled mode shapes as morph targets;
    the animation sets the morph influences to the modal coordinates, so the drawn vertices at a
    frame are the mode superposition x + scale sum_j q_j(tau) phi_j(x)."""
    blade = solid_frf.disk.blade
    scene = mv.show(solid_frf, n_frames=N_FRAMES)
    assert scene.info["layout"] == "disk"
    commands = _html_commands(scene.html())
    objects = {c["path"]: c["object"] for c in commands if c["type"] == "set_object"}
    base = "/meshcat/bladedamp/blades/blade_00/fe_surface"
    assert all(f"/meshcat/bladedamp/blades/blade_{k:02d}/fe_surface" in objects
               for k in range(solid_frf.disk.n_blades))
    assert not any("segment_" in p for p in objects)                    # no beam segments
    geometry = objects[base]["geometries"][0]["data"]
    vertices = _array(geometry["attributes"]["position"])
    faces = np.frombuffer(geometry["index"]["array"].data, dtype=np.uint32).reshape(-1, 3)
    np.testing.assert_allclose(vertices, blade.surface.vertices, rtol=0, atol=1e-7)
    np.testing.assert_array_equal(faces, blade.surface.faces)
    targets = np.array([_array(t) for t in geometry["morphAttributes"]["position"]])   # (n_m, n_v, 3)
    assert geometry["morphTargetsRelative"] is True and targets.shape == (blade.n_modes,) + vertices.shape
    # influences per frame from the recorded animation
    animation = next(c for c in commands if c["type"] == "set_animation")["animations"]
    clip = next(a["clip"] for a in animation if a["path"] == base + "/<object>")
    influences = np.array([[k["value"] for k in t["keys"]] for t in sorted(clip["tracks"], key=lambda t: t["name"])])
    assert [t["name"] for t in sorted(clip["tracks"], key=lambda t: t["name"])] == \
        [f".morphTargetInfluences[{j}]" for j in range(blade.n_modes)]
    assert influences.shape == (blade.n_modes, N_FRAMES + 1)
    # frame f (tau = 2 pi f / N): q = a cos(tau) + b sin(tau) of the first harmonic (harmonics (1,):
    # rows cos, sin) at the resonance point; the drawn displacement (morph part; the base vertices
    # are float32) against the solid's FE field there
    X = np.asarray(solid_frf.coefficients[scene.info["index"]])
    x, _ = _fe_surface_expected(solid_frf, np.zeros(blade.n_modes))
    drawn, expected = [], []
    for f in range(N_FRAMES):
        tau = 2 * np.pi * f / N_FRAMES
        q = X[0, :blade.n_modes] * np.cos(tau) + X[1, :blade.n_modes] * np.sin(tau)
        drawn.append(np.tensordot(influences[:, f], targets, axes=1))
        expected.append(scene.info["scale"] * _fe_surface_expected(solid_frf, q)[1])
    drawn, expected = np.array(drawn), np.array(expected)
    np.testing.assert_allclose(drawn, expected, rtol=0, atol=1e-5 * np.abs(expected).max())
    # over the cycle the tip face's centre swings by the drawn tip amplitude (8 % of the span)
    tip = np.argmin(np.linalg.norm(blade.surface.vertices - blade.points["tip"], axis=1))
    swing = np.array([vertices[tip] + np.tensordot(w, targets[:, tip], axes=1) for w in influences.T])[:, 0]
    assert 0.5 * np.ptp(swing) == pytest.approx(scene.info["scale"] * scene.info["tip_amplitude"], rel=0.05)


def test_solid_blade_still_frame_is_the_deformed_surface(solid_frf):
    blade = solid_frf.disk.blade
    phase = np.pi / 3
    scene = mv.ods_scene(solid_frf, animate=False, phase=phase, layout="sector")
    geometry = scene.object("bladedamp/blades/blade_00/fe_surface").geometry
    assert not isinstance(geometry, mv.MorphMeshGeometry)
    X = np.asarray(solid_frf.coefficients[scene.info["index"]])           # (cos, sin) x DOF
    q = X[0, :blade.n_modes] * np.cos(phase) + X[1, :blade.n_modes] * np.sin(phase)
    x, u = _fe_surface_expected(solid_frf, q)
    expected = x + scene.info["scale"] * u
    # float32 vertices: ~1e-8 m of rounding on displacements of up to 16 mm (8 % of the span)
    np.testing.assert_allclose(geometry.vertices, expected, rtol=0, atol=1e-5 * np.abs(expected - x).max())
    assert np.abs(expected - x).max() > 0.02 * scene.info["scale"] * scene.info["tip_amplitude"]


@pytest.mark.slow
def test_browser_applies_the_fe_surface_morph_animation(solid_frf, tmp_path):
    """Headless Chromium: the animation drives the FE surface's morph influences (the viewer binds
    the tracks to the mesh itself; the page reports them in its title). The page pauses the
    viewer's animator and seeks it to each key frame, so the result does not depend on how many
    frames a loaded machine renders in the virtual time."""
    import json
    import re
    import subprocess
    import tempfile

    exe = mv.chromium_executable()
    if exe is None:
        pytest.skip("no chromium on this machine (.ci/run installs the Debian package)")
    period_s = 2.0
    scene = mv.ods_scene(solid_frf, n_frames=N_FRAMES, layout="sector", contact_maps=False, period_s=period_s)
    probe = ("<script>setTimeout(() => {let o = viewer.scene_tree.find(['meshcat', 'bladedamp', 'blades', "
             "'blade_00', 'fe_surface', '<object>']).object; let a = viewer.animator; "
             "let running = a.actions.length > 0 && a.actions.every(x => x.isRunning()); a.pause(); "
             "let seen = []; for (let f = 0; f < " + str(N_FRAMES) + "; f++) {a.seek(f * "
             + repr(period_s / N_FRAMES) + "); seen.push(Array.from(o.morphTargetInfluences));} "
             "document.title = 'MORPH' + JSON.stringify({running: running, seen: seen});}, 200);</script></body>")
    html = tmp_path / "solid.html"
    html.write_text(scene.html().replace("</body>", probe), encoding="utf-8")
    with tempfile.TemporaryDirectory() as profile:
        out = subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                              f"--user-data-dir={profile}", "--virtual-time-budget=2500", "--dump-dom",
                              "file://" + str(html)], capture_output=True, text=True, timeout=180).stdout
    found = re.search(r"<title>MORPH(\{.*?\})</title>", out)
    assert found, "the page did not report the morph influences"
    report = json.loads(found.group(1))
    assert report["running"]                                                   # the clip plays on load
    w = np.array(report["seen"])                                               # (N_FRAMES, n_m)
    n_m = solid_frf.disk.blade.n_modes
    assert w.shape == (N_FRAMES, n_m)
    # key frame f holds q = a cos(tau) + b sin(tau), tau = 2 pi f / N (float32 keys)
    X = np.asarray(solid_frf.coefficients[scene.info["index"]])[:, :n_m]
    tau = 2 * np.pi * np.arange(N_FRAMES) / N_FRAMES
    q = np.outer(np.cos(tau), X[0]) + np.outer(np.sin(tau), X[1])
    np.testing.assert_allclose(w, q, rtol=0, atol=1e-5 * np.abs(q).max())
    assert np.ptp(w[:, 0]) > 1.9 * np.hypot(X[0, 0], X[1, 0]) * np.cos(np.pi / N_FRAMES)

