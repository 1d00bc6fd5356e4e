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
    return mv.ods_scene(cylinder_frf, n_frames=N_FRAMES)


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
    _, _, frf = peak_response(disk, (90.0, 105.0))      # the response wedge_liftoff_map evaluates
    data = mv.cycle_data(frf)
    assert data.frequency_hz == pytest.approx(reference.peak_frequency_hz, rel=1e-9)
    np.testing.assert_allclose(data.liftoff_ratio, reference.ratio_time, rtol=1e-6, atol=1e-9)


def test_static_html_is_standalone_and_starts_no_server(cylinder_frf, tmp_path):
    scene = mv.contact_map_scene(cylinder_frf, n_frames=4)
    path = scene.save_html(tmp_path / "map.html")
    html = open(path, encoding="utf-8").read()
    assert "MeshCat.Viewer" in html and html.count("handle_command_bytearray") > 10
    assert scene._window.server_proc is None
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
    empty.vis["/Grid"].set_property("visible", False)
    empty.vis["/Axes"].set_property("visible", False)
    shots = {}
    scenes = {"empty": empty,
              "phase0": mv.ods_scene(cylinder_frf, animate=False, phase=0.5 * np.pi, n_frames=N_FRAMES),
              "phase1": mv.ods_scene(cylinder_frf, animate=False, phase=1.5 * np.pi, n_frames=N_FRAMES)}
    animated = mv.ods_scene(cylinder_frf, n_frames=N_FRAMES, period_s=2.0)
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
    # the maps and their legend lie right of the blade tips' circle: they cross no blade
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
