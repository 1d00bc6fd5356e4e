"""meshcat views of a DiskResponse: operating deflection shape, contact maps, standalone HTML.

Scenes are *recorded* in-process (:class:`Scene`): every meshcat command goes to a local scene
tree instead of a server, and :meth:`Scene.html` packs the tree into the same standalone HTML that
meshcat's server returns for ``Visualizer.static_html()`` (meshcat's own viewer JavaScript plus
the commands), so exporting starts no process at all. :meth:`Scene.serve` starts a meshcat server
bound to 127.0.0.1 only (web and zmq), replays the scene into it and returns a :class:`LiveView`
that must be closed (``with scene.serve() as view: ...``); meshcat 0.3.2 has no
``Visualizer.close()``, so :meth:`LiveView.close` kills and reaps the server process itself.

What is drawn (blade frame: x circumferential, y axial, z radial):

* blades from :func:`bladedamp.geometry.blade_mesh`; the blade's deflection is only known at its
  named points (platform or OL, tip), so the span is interpolated (:func:`blade_deflection`):
  cubic Hermite in bending from the clamped root (zero displacement and slope) to the platform
  node and from the platform node to the tip, with the slopes given by the rotations there
  (du_x/dz = phi_y, du_y/dz = -phi_x); torsion and axial motion linear between root, platform
  and tip. This is a plausible cantilever-like shape matching the modal values at those points,
  not the FE shape between them. Each span segment moves rigidly with the interpolated motion
  at its middle, the platform with the platform node, the root not at all;
* a solid FE blade (:class:`bladedamp.blade.solid.SolidModalBlade`, which keeps its boundary surface
  and the mode shapes at its vertices, ``blade.surface``) is drawn as that surface instead: sent
  once per blade as a mesh with the scaled mode shapes as relative morph targets
  (:class:`MorphMeshGeometry`), and the animation sets the morph weights to the modal
  coordinates q_j(tau), so each frame is the exact mode superposition x + scale sum_j q_j phi_j(x)
  (a still frame draws the displaced vertices themselves);
* dampers: rigid-body motion u_D (6 DOF) about their centre of gravity;
* blade k moves with x_0(tau + k dphi) (cyclic symmetry, Eq. 25); displacements are multiplied
  by ``scale`` (default: the tip amplitude shown as 8 % of the blade length);
* the contact painted on the faces: at every point contact's position on the platforms' and the
  damper's contact faces (:meth:`bladedamp.geometry.SectorLayout.contact_points`) a tile in the
  colour of its state (stick / slip / separated, :mod:`bladedamp.palette`) or of its normal
  pressure, one mesh per frame of the cycle (from the AFT time samples of the contact model at
  the chosen frequency; damper k shows damper 0's samples at tau + k dphi); platform tiles move
  with their platform, damper tiles with the damper;
* the damper solid, transparent or exploded (moved radially inwards) so that the faces show; the
  first camera on damper 0 between its two platforms, or on the whole sector / disk;
* an HTML overlay on the standalone page (:func:`overlay_html`): the design, the frequency, the
  legend, play / pause, a phase scrubber and the camera and damper buttons; the page reads
  ``?phase=DEG&paused&view=...&damper=...`` when it opens (the live server of
  :meth:`Scene.serve` shows the scene without it);
* optionally (``contact_maps=True``) flat contact maps of the reference damper's OL and OR
  patches, enlarged beside the model: the state of every point at each frame and the lift-off
  ratio r = (mean(a) - min(a)) / mean(a) of the approach a(t) = a_static - u_zeta(t) (r > 1: the
  point lifts off during the cycle; with one harmonic this is Fig. 9's ratio of
  ``wedge_liftoff_map``), with a legend (a textured plane drawn with matplotlib).
"""
from __future__ import annotations

import atexit
import base64
import io
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field

import numpy as np

import meshcat
import meshcat.animation
import meshcat.geometry as mg
import umsgpack
from meshcat.servers.tree import SceneTree, find_node, walk
from meshcat.servers.zmqserver import VIEWER_ROOT

from .. import geometry as bgeo
from .. import palette
from ..damper.kinetics import seat

STATE_NAMES = palette.CONTACT_STATE_NAMES
STATE_COLORS = np.array([palette.rgb(c) for c in palette.CONTACT_STATES])   # stick, slip, separated
BLADE_COLOR = 0xb8c2cc
PLATFORM_COLOR = 0x8796a6
DAMPER_COLOR = 0xd4a017
BACKGROUND_TOP = (0.97, 0.97, 0.97)      # rgb in [0, 1]: a neutral light grey
BACKGROUND_BOTTOM = (0.82, 0.82, 0.82)
ROOT = "bladedamp"
_REPETITIONS = 100000   # set_animation(repetitions=0) never plays in meshcat 0.3.2: a large positive count


# --------------------------------------------------------------------------------------
# recording window, scene, live server
# --------------------------------------------------------------------------------------
class _RecordingWindow:
    """Stands in for meshcat's ViewerWindow: keeps the commands instead of sending them."""

    def __init__(self):
        self.tree = SceneTree()
        self.commands = []
        self.server_proc = None
        self.overlay = ""           # extra HTML (and scripts) after the viewer's, see Scene.overlay

    def send(self, command):
        self.commands.append(command)
        lowered = command.lower()
        data = umsgpack.packb(lowered)
        path = [p for p in lowered["path"].split("/") if p]
        node = find_node(self.tree, path)
        kind = lowered["type"]
        if kind == "set_object":
            node.object = data
            node.properties = []
        elif kind == "set_transform":
            node.transform = data
        elif kind == "set_property":
            node.properties.append(data)
        elif kind == "set_animation":
            node.animation = data
        elif kind == "delete":
            if path:
                parent = find_node(self.tree, path[:-1])
                if path[-1] in parent:
                    del parent[path[-1]]
            else:
                self.tree = SceneTree()

    def get_scene(self) -> str:
        """Standalone HTML, as meshcat's server builds it for ``static_html()``."""
        commands, animations = [], []
        for node in walk(self.tree):
            if node.object is not None:
                commands.append(node.object)
            commands += list(node.properties)
            if node.transform is not None:
                commands.append(node.transform)
            if node.animation is not None:
                animations.append(node.animation)
        # animations last: the viewer binds each track to the object at its path when the
        # animation loads, so a track on an object itself (".../<object>", e.g. its morph target
        # influences) needs that object set first. The commands are fetched from data URLs
        # (asynchronous) and handled in this order once all have arrived; then the page sets
        # ``window.bladedampLoaded = true`` (the overlay's controls wait for it).
        commands = ",\n".join('fetch("data:application/octet-binary;base64,%s").then(res => res.arrayBuffer())'
                               % base64.b64encode(c).decode("ascii") for c in commands + animations)
        commands = ("Promise.all([\n" + commands + "\n]).then(buffers => {\n"
                    "  buffers.forEach(b => viewer.handle_command_bytearray(new Uint8Array(b)));\n"
                    "  window.bladedampLoaded = true;\n});\n")
        with open(os.path.join(VIEWER_ROOT, "main.min.js")) as f:
            js = f.read()
        return ("<!DOCTYPE html>\n<html>\n<head><meta charset=utf-8><title>bladedamp</title></head>\n<body>\n"
                "<div id=\"meshcat-pane\"></div>\n<script>\n" + js + "\n</script>\n<script>\n"
                "var viewer = new MeshCat.Viewer(document.getElementById(\"meshcat-pane\"));\n"
                + commands +
                "\n</script>\n<style>body {margin: 0;} #meshcat-pane {width: 100vw; height: 100vh; overflow: hidden;}"
                "</style>\n" + self.overlay + "</body>\n</html>\n")

    def close(self):
        pass


class Scene:
    """A recorded meshcat scene.

    vis : meshcat.Visualizer writing into this scene (use it like any meshcat visualizer)
    commands : the meshcat command objects in order (for inspection and replay)
    info : what the builder drew (paths, frame count, per-frame contact states and colours, ...)
    """

    def __init__(self):
        self._window = _RecordingWindow()
        self.vis = meshcat.Visualizer(window=self._window)
        self.info: dict = {}

    @property
    def commands(self) -> list:
        return self._window.commands

    @property
    def overlay(self) -> str:
        """HTML written into the standalone page after meshcat's viewer (the global ``viewer``
        exists when its scripts run); empty by default."""
        return self._window.overlay

    @overlay.setter
    def overlay(self, html: str):
        self._window.overlay = str(html)

    def paths(self) -> set:
        """Paths of all objects set in the scene (strings like "/meshcat/bladedamp/...")."""
        return {c.path.lower() for c in self.commands if type(c).__name__ == "SetObject"}

    def object(self, path: str):
        """The last meshcat Object set at ``path`` (the "/meshcat/" prefix may be left out)."""
        full = path if path.startswith("/meshcat") else "/meshcat/" + path.lstrip("/")
        for c in reversed(self.commands):
            if type(c).__name__ == "SetObject" and c.path.lower() == full:
                return c.object
        raise KeyError(path)

    def animation(self):
        """The last meshcat Animation set, or None."""
        for c in reversed(self.commands):
            if type(c).__name__ == "SetAnimation":
                return c.animation
        return None

    def html(self) -> str:
        """Standalone HTML (opens in a browser from a file, no server)."""
        return self.vis.static_html()

    def save_html(self, path) -> str:
        """Write :meth:`html` to ``path``; returns the path."""
        path = os.fspath(path)
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.html())
        return path

    def serve(self, open_browser: bool = False) -> "LiveView":
        """Start a meshcat server on 127.0.0.1, replay the scene into it; close the returned view."""
        view = LiveView()
        try:
            for command in self.commands:
                view.vis.window.send(command)
            if open_browser:
                view.vis.open()
        except Exception:
            view.close()
            raise
        return view


#: the LiveView objects whose server process is running (each closed at interpreter exit)
LIVE_VIEWS: set = set()


class LiveView:
    """A meshcat server process bound to localhost and a Visualizer connected to it.

    ``url`` is the page to open. ``close()`` (or leaving a ``with`` block, or interpreter exit)
    kills the server and waits for it, and closes the zmq socket.
    """

    def __init__(self, timeout: float = 30.0):
        args = [sys.executable, "-u", "-m", "bladedamp.viz.meshcat_view", "--serve"]
        env = dict(os.environ)
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
        self.server_proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env,
                                            start_new_session=True)
        LIVE_VIEWS.add(self)
        self.vis = None
        try:
            zmq_url = web_url = None
            while zmq_url is None or web_url is None:
                line = self.server_proc.stdout.readline().decode("utf-8").strip()
                if not line and self.server_proc.poll() is not None:
                    raise RuntimeError(f"meshcat server exited with code {self.server_proc.returncode}")
                if line.startswith("zmq_url="):
                    zmq_url = line.split("=", 1)[1]
                elif line.startswith("web_url="):
                    web_url = line.split("=", 1)[1]
            self.zmq_url, self.url = zmq_url, web_url
            window = meshcat.visualizer.ViewerWindow.__new__(meshcat.visualizer.ViewerWindow)
            window.server_proc, window.zmq_url, window.web_url = self.server_proc, zmq_url, web_url
            window.connect_zmq()
            window.zmq_socket.setsockopt(__import__("zmq").RCVTIMEO, int(timeout * 1000))
            window.zmq_socket.setsockopt(__import__("zmq").LINGER, 0)
            self.vis = meshcat.Visualizer(window=window)
        except Exception:
            self.close()
            raise

    @property
    def pid(self) -> int:
        return self.server_proc.pid

    def close(self):
        """Kill the server process, wait for it, close the socket (idempotent)."""
        if self.vis is not None:
            try:
                self.vis.window.zmq_socket.close(linger=0)
            except Exception:
                pass
        if self.server_proc.poll() is None:
            self.server_proc.kill()
        self.server_proc.wait()
        if self.server_proc.stdout is not None:
            self.server_proc.stdout.close()
        LIVE_VIEWS.discard(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@atexit.register
def _close_all():
    for view in list(LIVE_VIEWS):
        view.close()


def _serve():
    """Entry point of the server subprocess: meshcat's bridge with the web server on 127.0.0.1 only."""
    from meshcat.servers import zmqserver

    class LocalBridge(zmqserver.ZMQWebSocketBridge):
        def make_app(self):
            app = super().make_app()
            listen = app.listen

            def listen_localhost(port, **kwargs):
                kwargs.setdefault("address", "127.0.0.1")
                return listen(port, **kwargs)

            app.listen = listen_localhost
            return app

    bridge = LocalBridge(host="127.0.0.1")
    print(f"zmq_url={bridge.zmq_url}")
    print(f"web_url={bridge.web_url}")
    sys.stdout.flush()
    bridge.run()


# --------------------------------------------------------------------------------------
# data of one vibration cycle
# --------------------------------------------------------------------------------------
def _synthesis(basis, tau: np.ndarray) -> np.ndarray:
    """(len(tau), C) synthesis matrix at arbitrary phases."""
    cols = []
    for h in basis.harmonics:
        if h == 0:
            cols.append(np.ones_like(tau))
        else:
            cols += [np.cos(h * tau), np.sin(h * tau)]
    return np.array(cols).T


def _pick(result, index, frequency_hz):
    if index is not None:
        return int(index)
    if frequency_hz is not None:
        return int(np.argmin(np.abs(result.frequency_hz - frequency_hz)))
    return int(np.argmax(result.tip_amplitude[:, 0]))


@dataclass
class CycleData:
    """One point of a DiskResponse over a vibration cycle.

    index, frequency_hz : branch point and its excitation frequency
    coefficients : (C, n_dof) harmonic coefficients of the reference sector
    states : (T, 2, P) contact state of every point of OL / OR at the T AFT samples (0 stick,
        1 slip, 2 separated); None without damper
    liftoff_ratio : (2, P) r = (mean a - min a) / mean a, a(t) = a_static - u_zeta(t)
    tip_amplitude : first-harmonic tip amplitude u_x [m]
    normal_load : (T, 2, P) normal force of every point [N] (>= 0), None without damper
    displacement : (T, 2, P, 3) relative displacement damper - platform of every point in its
        contact frame (xi, eta, zeta) [m], None without damper
    force : (T, 2, P, 3) contact force of every point on the platform, same axes [N]
    slip_work : (2, P) energy dissipated by friction at every point over the cycle [J]
    """

    index: int
    frequency_hz: float
    coefficients: np.ndarray
    basis: object
    states: np.ndarray | None
    liftoff_ratio: np.ndarray | None
    tip_amplitude: float
    patches: tuple = field(default=(), repr=False)
    normal_load: np.ndarray | None = field(default=None, repr=False)
    displacement: np.ndarray | None = field(default=None, repr=False)
    force: np.ndarray | None = field(default=None, repr=False)
    slip_work: np.ndarray | None = field(default=None, repr=False)

    def sample(self, frame: int, n_frames: int) -> int:
        """The AFT time sample shown at animation frame ``frame`` of ``n_frames`` per cycle (the
        nearest sample to the frame's phase 2 pi frame / n_frames)."""
        T = self.states.shape[0]
        return int(round(frame / n_frames * T)) % T


def cycle_data(result, index: int | None = None, frequency_hz: float | None = None) -> CycleData:
    """Contact states over the cycle and lift-off ratios at one point of ``result`` (default: the
    resonance, the largest tip amplitude; or the point nearest ``frequency_hz``)."""
    i = _pick(result, index, frequency_hz)
    disk, basis = result.disk, result.basis
    X = result.coefficients[i]
    states = ratio = normal = disp = force = work = None
    patches = ()
    if disk is not None and disk.has_damper:
        system = disk.hbm_system(basis.harmonics, basis.n_samples)
        coupling = system.couplings[0]
        local = (coupling.matrix @ X.ravel()).reshape(basis.n_coeffs, coupling.element.n_local)   # 12, or more with flexible platforms
        evs = coupling.element.evaluate(local, basis, result.omega[i], jacobian=False)
        states = np.stack([ev.points.state.T for ev in evs], axis=1)               # (T, 2, P)
        normal = np.stack([ev.points.normal_load.T for ev in evs], axis=1)         # (T, 2, P)
        disp = np.stack([ev.points.displacement.transpose(1, 0, 2) for ev in evs], axis=1)   # (T, 2, P, 3)
        force = np.stack([ev.points.force.transpose(1, 0, 2) for ev in evs], axis=1)
        work = np.array([ev.points.slip_work for ev in evs])                         # (2, P)
        patches = coupling.element.geometry.patches
        if basis.has_static:
            a_static = np.zeros((2, patches[0].n_points))
        else:
            a_static = seat(disk.damper_geometry(), disk.centrifugal_force(result.frequency_hz[i])[0])[1]
        u = basis.to_time(result.point_displacement[i][..., 2])                       # (T, 2, P)
        a = a_static[None] - u
        mean = a.mean(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(mean > 0, (mean - a.min(axis=0)) / mean, np.inf)
    return CycleData(i, float(result.frequency_hz[i]), X, basis, states, ratio,
                     float(result.tip_amplitude[i, 0]), patches, normal, disp, force, work)


# --------------------------------------------------------------------------------------
# blade deflection along the span
# --------------------------------------------------------------------------------------
def _hermite(z, z0, z1, w0, s0, w1, s1):
    h = z1 - z0
    t = (z - z0) / h
    h00, h10, h01, h11 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2
    d00, d10, d01, d11 = (6 * t**2 - 6 * t) / h, 3 * t**2 - 4 * t + 1, (-6 * t**2 + 6 * t) / h, 3 * t**2 - 2 * t
    return h00 * w0 + h10 * h * s0 + h01 * w1 + h11 * h * s1, d00 * w0 + d10 * s0 + d01 * w1 + d11 * s1


def blade_deflection(blade, q: np.ndarray, z: np.ndarray):
    """Interpolated beam-axis motion at heights ``z`` for modal coordinates ``q`` (n_m,).

    Known: the clamped root (z = 0), the platform node and the tip (6-vectors Phi q). Without a
    "platform" point the platform node motion follows from OL (rigid platform). Bending: cubic
    Hermite per span part with slopes du_x/dz = phi_y, du_y/dz = -phi_x; torsion phi_z and axial
    u_z linear. Returns (u (len(z), 3), phi (len(z), 3)).
    """
    z = np.atleast_1d(np.asarray(z, float))
    q = np.asarray(q, float)
    if "platform" in blade.points:
        zp = blade.points["platform"][2]
        mp = blade.shape("platform") @ q
    else:
        p_ol = blade.points["OL"]
        zp = p_ol[2]
        m_ol = blade.shape("OL") @ q
        r = p_ol - np.array([0.0, 0.0, zp])
        mp = np.concatenate([m_ol[:3] - np.cross(m_ol[3:], r), m_ol[3:]])
    zt = blade.points["tip"][2]
    mt = blade.shape("tip") @ q
    u = np.zeros((z.size, 3))
    phi = np.zeros((z.size, 3))
    lower = z <= zp
    zl, zu = np.clip(z[lower], 0, zp), np.clip(z[~lower], zp, zt)
    # bending x: (u_x, slope phi_y); bending y: (u_y, slope -phi_x)
    for comp, rot, sign in ((0, 1, 1.0), (1, 0, -1.0)):
        w, s = _hermite(zl, 0.0, zp, 0.0, 0.0, mp[comp], sign * mp[3 + rot])
        u[lower, comp], phi[lower, rot] = w, sign * s
        w, s = _hermite(zu, zp, zt, mp[comp], sign * mp[3 + rot], mt[comp], sign * mt[3 + rot])
        u[~lower, comp], phi[~lower, rot] = w, sign * s
    for arr, k, vp, vt in ((u, 2, mp[2], mt[2]), (phi, 2, mp[5], mt[5])):
        arr[lower, k] = vp * zl / zp
        arr[~lower, k] = vp + (vt - vp) * (zu - zp) / (zt - zp)
    return u, phi


def _rotation(vec) -> np.ndarray:
    """Rotation matrix of a rotation vector (Rodrigues)."""
    vec = np.asarray(vec, float)
    angle = np.linalg.norm(vec)
    if angle < 1e-15:
        return np.eye(3)
    k = vec / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _rigid(u, phi, about) -> np.ndarray:
    """4x4 transform of a rigid motion (translation u, rotation vector phi about point ``about``)."""
    R = _rotation(phi)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = np.asarray(about) + np.asarray(u) - R @ np.asarray(about)
    return T


# --------------------------------------------------------------------------------------
# scene builders
# --------------------------------------------------------------------------------------
def plain_stage(vis) -> None:
    """No grid, no axes, and a light grey background instead of meshcat's blue gradient (a blue
    behind the blades would read as the stick colour)."""
    vis["/Grid"].set_property("visible", False)
    vis["/Axes"].set_property("visible", False)
    vis["/Background"].set_property("top_color", list(BACKGROUND_TOP))
    vis["/Background"].set_property("bottom_color", list(BACKGROUND_BOTTOM))


def _mesh_geometry(mesh, color=None):
    return mg.TriangularMeshGeometry(mesh.vertices, mesh.faces, color)


class MorphMeshGeometry(mg.TriangularMeshGeometry):
    """A triangle mesh with relative morph targets (three.js ``morphAttributes.position``): drawn
    at ``vertices + sum_j w_j targets[j]`` for the object's ``morphTargetInfluences`` w, which an
    animation track ``morphTargetInfluences[j]`` (number) sets per frame. The FE blade's surface
    is drawn so: targets = the (scaled) mode shapes at its vertices, w = the modal coordinates, so
    every frame is the exact mode superposition and the scene holds the surface once.

    vertices (n_v, 3) [m], faces (n_f, 3), targets (n_t, n_v, 3) [m].
    """

    __slots__ = ["targets"]

    def __init__(self, vertices, faces, targets):
        super().__init__(vertices, faces)
        self.targets = np.asarray(targets, dtype=np.float32)
        if self.targets.ndim != 3 or self.targets.shape[1:] != self.vertices.shape:
            raise ValueError(f"targets must have shape (n_t, {self.vertices.shape[0]}, 3) (got {self.targets.shape})")

    def lower(self, object_data):
        out = super().lower(object_data)
        out["data"]["morphAttributes"] = {"position": [mg.pack_numpy_array(t.T) for t in self.targets]}
        out["data"]["morphTargetsRelative"] = True
        return out


def _legend_png(title: str, ratio_max: float) -> bytes:
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = Figure(figsize=(4.0, 2.4), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_xlim(0, 4)
    ax.set_ylim(0, 2.4)
    ax.axis("off")
    fig.patch.set_facecolor("white")
    ax.text(0.1, 2.15, title, fontsize=10, va="center")
    for k, name in enumerate(STATE_NAMES):
        ax.add_patch(matplotlib.patches.Rectangle((0.1 + 1.3 * k, 1.6), 0.35, 0.3, color=STATE_COLORS[k]))
        ax.text(0.52 + 1.3 * k, 1.75, name, fontsize=10, va="center")
    cmap = matplotlib.colormaps["viridis"]
    for k in range(100):
        ax.add_patch(matplotlib.patches.Rectangle((0.1 + 3.6 * k / 100, 0.75), 3.6 / 100 + 0.005, 0.35,
                                                  color=cmap(k / 99)))
    ax.text(0.1, 0.55, "0", fontsize=9, va="center")
    ax.text(0.1 + 3.6 / ratio_max, 0.55, "1", fontsize=9, va="center", ha="center")
    ax.text(3.7, 0.55, f"{ratio_max:g}", fontsize=9, va="center", ha="right")
    ax.text(0.1, 1.3, "contact state: row 1 now, rows 3-4 over the cycle (OL, OR)", fontsize=8, va="center")
    ax.text(0.1, 0.25, "lift-off ratio r: row 2 (r > 1: lifts off)", fontsize=8, va="center")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", facecolor="white")
    return buf.getvalue()


def _tile_mesh(xi_n, eta_n, n_xi, n_eta, width, height, origin, colors):
    """Quads (one per point) in the x-z plane: eta -> x (width), xi -> z (height); vertex colours."""
    dx, dz = width / n_eta, height / n_xi
    verts, faces, cols = [], [], []
    for p, (a, b) in enumerate(zip(xi_n, eta_n)):
        cx = origin[0] + (b + 0.5) * width
        cz = origin[2] + (0.5 - a) * height if n_xi > 1 else origin[2] + 0.5 * height
        corners = [[cx - 0.45 * dx, origin[1], cz - 0.45 * dz], [cx + 0.45 * dx, origin[1], cz - 0.45 * dz],
                   [cx + 0.45 * dx, origin[1], cz + 0.45 * dz], [cx - 0.45 * dx, origin[1], cz + 0.45 * dz]]
        base = len(verts)
        verts += corners
        faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
        cols += [colors[p]] * 4
    return mg.TriangularMeshGeometry(np.array(verts), np.array(faces), np.array(cols))


def _camera_values(target, position):
    """(column-major 4x4 transform of /meshcat/bladedamp, camera position in its rotated frame) of
    :func:`_set_camera`, as the page's commands take them."""
    T = np.eye(4)
    T[:3, 3] = -np.asarray(target, float)
    x, y, z = map(float, position)
    return list(map(float, T.T.ravel())), [x, z, -y]


def _set_camera(vis, target, position):
    """Look at ``target`` from ``target + position`` (meshcat frame, z up). meshcat's orbit camera
    looks at the world origin, so the drawing (everything under /meshcat/bladedamp) is shifted by
    -target and the camera put at ``position``."""
    T = np.eye(4)
    T[:3, 3] = -np.asarray(target, float)
    vis[ROOT].set_transform(T)
    vis["/Cameras/default/rotated/<object>"].set_property("position", _camera_values(target, position)[1])


def project(point, target, position, size, fov_deg: float = 75.0) -> np.ndarray:
    """Pixel (x right, y down) of a blade-frame ``point`` [m] in a ``size`` = (width, height) page
    whose camera :func:`_set_camera` set: meshcat's perspective camera (vertical field of view
    75 deg) at ``target + position`` looking at ``target``, z up."""
    point = np.asarray(point, float)
    eye = np.asarray(target, float) + np.asarray(position, float)
    forward = (np.asarray(target, float) - eye) / np.linalg.norm(np.asarray(position, float))
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = point - eye
    depth = d @ forward
    t = np.tan(np.radians(fov_deg) / 2)
    w, h = size
    x_ndc = (d @ right) / (depth * t * w / h)
    y_ndc = (d @ up) / (depth * t)
    return np.stack([(x_ndc + 1) / 2 * w, (1 - y_ndc) / 2 * h], axis=-1)


def _add_contact_maps(scene, data, origin, n_frames, width=0.05, gap=0.008):
    """Contact-state maps (animated, one mesh per frame) and lift-off ratio maps of OL / OR."""
    vis = scene.vis[ROOT]["contact_map"]
    patch = data.patches[0]
    n_xi, n_eta = patch.n_xi, patch.n_eta
    xi_n, eta_n = patch.normalised_coordinates
    height = width * (max(patch.height, patch.length / n_eta * n_xi) / patch.length) if patch.height > 0 \
        else width / n_eta
    height = max(height, width / n_eta)
    samples = [data.sample(f, n_frames) for f in range(n_frames)]
    colors = np.zeros((n_frames, 2, patch.n_points, 3))
    rows = {}
    for c, name in enumerate(("OL", "OR")):
        rows[name] = np.array(origin) + np.array([c * (width + gap), 0.0, 0.0])
    for f, s in enumerate(samples):
        for c, name in enumerate(("OL", "OR")):
            colors[f, c] = STATE_COLORS[data.states[s, c]]
            vis["state"][name][f"frame_{f:03d}"].set_object(
                _tile_mesh(xi_n, eta_n, n_xi, n_eta, width, height, rows[name], colors[f, c]),
                mg.MeshBasicMaterial(vertexColors=True))
    import matplotlib
    cmap = matplotlib.colormaps["viridis"]
    ratio_max = 2.0
    ratio_colors = cmap(np.clip(data.liftoff_ratio / ratio_max, 0, 1))[..., :3]
    for c, name in enumerate(("OL", "OR")):
        o = rows[name] - np.array([0.0, 0.0, height + gap])
        vis["liftoff"][name].set_object(_tile_mesh(xi_n, eta_n, n_xi, n_eta, width, height, o, ratio_colors[c]),
                                        mg.MeshBasicMaterial(vertexColors=True))
    # the whole cycle at a glance: per contact a strip, columns = frames, rows = points (static),
    # with an animated cursor on the current frame
    lw = 2 * width + gap
    strip_h = 0.3 * width
    top = np.array(origin) - np.array([0.0, 0.0, 2 * (height + gap)])
    P = patch.n_points
    for c, name in enumerate(("OL", "OR")):
        o = top - np.array([0.0, 0.0, c * (strip_h + gap)])
        col = np.repeat(np.arange(n_frames), P)
        row = np.tile(np.arange(P), n_frames)
        strip = _tile_mesh((row + 0.5) / P - 0.5, (col + 0.5) / n_frames - 0.5, P, n_frames, lw, strip_h,
                           o,
                           colors[col, c, row])
        vis["cycle"][name].set_object(strip, mg.MeshBasicMaterial(vertexColors=True))
    cursor_h = 2 * strip_h + 2 * gap
    vis["cycle"]["cursor"].set_object(mg.Box([0.15 * lw / n_frames, 2e-4, cursor_h]),
                                      mg.MeshBasicMaterial(color=0x000000))
    cursor_z = top[2] + strip_h - cursor_h / 2 + gap / 2
    scene.info["cursor"] = lambda f: np.array([top[0] + (f % n_frames + 0.5) / n_frames * lw, -1e-3, cursor_z])
    vis["cycle"]["cursor"].set_transform(bgeo.homogeneous(translation=scene.info["cursor"](0)))
    title = f"{data.frequency_hz:.2f} Hz      rows 1-2: OL left, OR right"
    png = mg.PngImage(_legend_png(title, ratio_max))
    legend = mg.MeshBasicMaterial(map=mg.ImageTexture(image=png, wrap=[1001, 1001], repeat=[1, 1]))
    lo = np.array(origin) + np.array([lw / 2, 0.0, -2 * height - 2 * strip_h - 5 * gap - 0.3 * lw])
    scene.vis[ROOT]["legend"].set_object(mg.Box([lw, 1e-4, 0.6 * lw]), legend)
    scene.vis[ROOT]["legend"].set_transform(bgeo.homogeneous(translation=lo))   # texture upright on the -y face
    scene.info.update(state_colors=colors, state_samples=samples, liftoff_colors=ratio_colors,
                      map_origin=np.array(origin), map_size=(lw, 2 * height + 2 * strip_h + 5 * gap + 0.6 * lw),
                      first_row_height=height)
    return samples


def _map_frames(scene, anim, n_frames, phase):
    """Show one state map per frame (visibility) and move the cycle cursor; still frame at ``phase``
    when ``anim`` is None."""
    vis = scene.vis
    names = [f"frame_{f:03d}" for f in range(n_frames)]
    cursor = scene.info["cursor"]

    def pose(target, f, animated):
        maps = target[ROOT]["contact_map"]
        for c in ("OL", "OR"):
            for m, name in enumerate(names):
                if animated:
                    maps["state"][c][name].set_property("visible", "boolean", bool(m == f % n_frames))
                else:
                    maps["state"][c][name].set_property("visible", bool(m == f % n_frames))
        maps["cycle"]["cursor"].set_transform(bgeo.homogeneous(translation=cursor(f)))

    if anim is None:
        pose(vis, int(round(phase / (2 * np.pi) * n_frames)) % n_frames, False)
        return
    for f in range(n_frames + 1):
        with anim.at_frame(vis, f) as frame:
            pose(frame, f, True)


PAINTS = ("state", "pressure")
DAMPER_VIEWS = ("solid", "transparent", "exploded")
VIEWS = ("damper", "whole")
DAMPER_OPACITY = 0.3          # the transparent damper
PAINT_OFFSET = 5e-5           # [m] painted tiles stand this far off their face (no z-fighting)


def ods_scene(result, index: int | None = None, frequency_hz: float | None = None, scale: float | None = None,
              layout: str = "sector", n_frames: int = 36, period_s: float = 2.0, animate: bool = True,
              phase: float = 0.0, contact_maps: bool = False, blade_geometry=None, camera=None,
              paint: str | None = "state", damper_view: str = "transparent", view: str = "damper",
              title: str | None = None, painted_dampers=None, overlay: bool = True) -> Scene:
    """Operating deflection shape of ``result`` (a DiskResponse) over one vibration cycle, with the
    contact painted on the contact faces.

    index / frequency_hz : branch point (default: resonance, the largest tip amplitude)
    scale : displacement magnification (default: tip amplitude drawn as 8 % of the blade length)
    layout : "sector" (blades 0, 1, 2 and dampers 0, 1, unrolled as in the contact model) or
        "disk" (all n blades wrapped around the axis, see :func:`bladedamp.geometry.disk_placements`)
    n_frames, period_s : frames per cycle and the cycle's duration in the viewer [s]
    animate : False draws one still frame at ``phase`` [rad] (no animation)
    paint : what is painted at every point contact's position on the damper's and the platforms'
        contact faces (:meth:`bladedamp.geometry.SectorLayout.contact_points`), per frame:
        "state" (stick / slip / separated in the colours of :mod:`bladedamp.palette`),
        "pressure" (the normal load of the point over its cell: MPa for an area contact, N/mm
        along a line contact, viridis from 0 to the largest over the cycle) or None
    painted_dampers : indices of the dampers painted (default: every damper of the sector layout,
        damper 0 of the disk)
    damper_view : "solid", "transparent" (opacity 0.3: the faces under it show) or "exploded"
        (the damper and its painted faces moved radially inwards by 2.5 times its height: the
        platforms' faces show from below, the damper's from above)
    view : the first camera: "damper" (damper 0 between its two platforms, seen from the front
        and below) or "whole" (the sector or the whole disk)
    camera : (target (3,), camera position relative to the target (3,)) in the blade frame [m];
        replaces the first camera of ``view``
    contact_maps : also draw the flat contact-state and lift-off maps beside the model, and their
        legend (see :func:`contact_map_scene`)
    blade_geometry : BeamBladeGeometry for the shapes (default the reference blade, or the solid
        blade's own parametric geometry; a solid blade is drawn as its deformed FE surface, and
        the platforms' painted faces then stay at rest)
    title : the design's name in the overlay (default: damper type, mass, blades and engine order)
    overlay : write the HTML overlay into the standalone page (:func:`overlay_html`): title,
        frequency, legend, play / pause, phase scrubber, camera and damper buttons

    ``scene.info["paint"]`` holds what was painted: for each painted damper, the platform and
    damper tile paths, the point positions (world, at rest) and the colours per frame.
    """
    disk = result.disk
    if disk is None:
        raise ValueError("result must be a DiskResponse with its disk")
    if paint not in PAINTS + (None,):
        raise ValueError(f'paint must be one of {PAINTS} or None (got {paint!r})')
    if damper_view not in DAMPER_VIEWS:
        raise ValueError(f"damper_view must be one of {DAMPER_VIEWS} (got {damper_view!r})")
    if view not in VIEWS:
        raise ValueError(f"view must be one of {VIEWS} (got {view!r})")
    if int(n_frames) < 1:
        raise ValueError(f"n_frames must be an integer >= 1 (got {n_frames!r})")
    n_frames = int(n_frames)
    data = cycle_data(result, index, frequency_hz)
    blade = disk.blade
    nm = blade.n_modes
    has_damper = disk.has_damper and data.states is not None
    scene = Scene()
    vis = scene.vis
    plain_stage(vis)

    # a solid FE blade (bladedamp.blade.solid.SolidModalBlade) brings its boundary surface and the
    # mode shapes there: drawn deformed (exact superposition) instead of the beam's segments
    surface = getattr(blade, "surface", None)
    if blade_geometry is None:
        fe_geometry = getattr(getattr(blade, "modes", None), "geometry", None)
        blade_geometry = getattr(fe_geometry, "beam", None)     # the parametric solid's beam
    g = bgeo.reference_blade_geometry() if blade_geometry is None else blade_geometry
    points = g.points() if surface is None else dict(blade.points)
    if has_damper:
        lay = bgeo.sector_layout(points, disk.damper, disk.gamma_left, disk.gamma_right)
        centres = lay.own_contact_centres(points)
        pitch = lay.pitch
    else:
        lay, centres, pitch = None, None, 2.5 * g.platform_half_width
    bm = bgeo.blade_mesh(g, disk.gamma_left, disk.gamma_right, centres) if surface is None else None
    n = disk.n_blades
    if layout == "disk":
        if lay is None:
            raise ValueError('layout="disk" needs a damper')
        B, D, ks, r_root = bgeo.disk_placements(lay, n, points)
    elif layout == "sector":
        ks = np.arange(3)
        B = np.array([bgeo.homogeneous(translation=(-k * pitch, 0, 0)) for k in ks])
        cg = lay.damper_cg if lay is not None else 0.0
        D = np.array([bgeo.homogeneous(translation=cg - np.array([k * pitch, 0, 0])) for k in ks])
        r_root = None
    else:
        raise ValueError('layout must be "sector" or "disk"')
    n_dampers = len(ks) if layout == "disk" else len(ks) - 1

    # amplitude scale
    tip_amp = max(data.tip_amplitude, 1e-15)
    blade_length = g.total_length if surface is None else float(blade.points["tip"][2])
    if scale is None:
        scale = 0.08 * blade_length / tip_amp
    scale = float(scale)

    dphi = disk.interblade_phase
    taus = [2 * np.pi * f / n_frames for f in range(n_frames + 1)] if animate else [phase]
    if surface is None:
        z_seg = np.array([zm for _, zm in bm.segments])
        z_p = bm.platform_node_z
    else:
        z_p = float(blade.points["OL"][2])
    p_platform = np.array([0.0, 0.0, z_p])
    targets = None if surface is None else scale * surface.shapes.transpose(2, 0, 1)    # (n_m, n_v, 3)
    synth = {}

    def sector_state_at(k, tau):
        """State of blade k at phase tau: x_0(tau + k dphi) (cyclic symmetry, Eq. 25)."""
        key = (k, tau)
        if key not in synth:
            S = _synthesis(data.basis, np.array([tau + k * dphi]))[0]
            synth[key] = S @ data.coefficients
        return synth[key]

    # static geometry
    for j, k in enumerate(ks):
        bp = vis[ROOT]["blades"][f"blade_{k:02d}"]
        bp.set_transform(B[j])
        if surface is not None:
            if animate:
                fe = MorphMeshGeometry(surface.vertices, surface.faces, targets)
            else:                              # one still frame: the deformed surface itself
                q = sector_state_at(k, phase)[:nm]
                fe = mg.TriangularMeshGeometry(surface.vertices + np.tensordot(q, targets, axes=1), surface.faces)
            bp["fe_surface"].set_object(fe, mg.MeshLambertMaterial(color=BLADE_COLOR))
            continue
        bp["root"].set_object(_mesh_geometry(bm.root), mg.MeshLambertMaterial(color=PLATFORM_COLOR))
        bp["platform"]["mesh"].set_object(_mesh_geometry(bm.platform), mg.MeshLambertMaterial(color=PLATFORM_COLOR))
        for s, (mesh, _) in enumerate(bm.segments):
            bp[f"segment_{s:02d}"]["mesh"].set_object(_mesh_geometry(mesh), mg.MeshLambertMaterial(color=BLADE_COLOR))
    explode = np.eye(4)
    if has_damper:
        dmesh = bgeo.damper_mesh(disk.damper, disk.gamma_left, disk.gamma_right)
        explode = bgeo.homogeneous(translation=(0.0, 0.0, -2.5 * float(np.ptp(dmesh.vertices[:, 2]))))
        opacity = DAMPER_OPACITY if damper_view == "transparent" else 1.0
        for j in range(n_dampers):
            dp = vis[ROOT]["dampers"][f"damper_{ks[j]:02d}"]
            dp.set_transform(D[j])
            dp["body"]["mesh"].set_object(_mesh_geometry(dmesh), mg.MeshLambertMaterial(
                color=DAMPER_COLOR, transparent=opacity < 1, opacity=opacity))
            if damper_view == "exploded":
                dp["body"]["mesh"].set_transform(explode)

    # motion per frame
    def pose(frame_vis, tau, animated):
        for j, k in enumerate(ks):
            x = sector_state_at(k, tau)
            q = x[:nm]
            if surface is not None:            # a still frame has the deformed surface already
                if animated:                   # the morph influences are the modal coordinates
                    obj = frame_vis[ROOT]["blades"][f"blade_{k:02d}"]["fe_surface"]["<object>"]
                    for m in range(nm):
                        obj.set_property(f"morphTargetInfluences[{m}]", "number", float(q[m]))
                continue
            u, phi = blade_deflection(blade, q, z_seg)
            bp = frame_vis[ROOT]["blades"][f"blade_{k:02d}"]
            for s in range(len(z_seg)):
                bp[f"segment_{s:02d}"].set_transform(_rigid(scale * u[s], scale * phi[s], [0.0, 0.0, z_seg[s]]))
            up, pp = blade_deflection(blade, q, [z_p])
            bp["platform"].set_transform(_rigid(scale * up[0], scale * pp[0], p_platform))
        if has_damper:
            for j in range(n_dampers):
                x = sector_state_at(ks[j], tau)
                uD = x[nm:nm + 6]
                frame_vis[ROOT]["dampers"][f"damper_{ks[j]:02d}"]["body"].set_transform(
                    _rigid(scale * uD[:3], scale * uD[3:], np.zeros(3)))

    anim = None
    if animate:
        fps = n_frames / period_s
        anim = meshcat.animation.Animation(default_framerate=fps)
        for f, tau in enumerate(taus):
            with anim.at_frame(vis, f) as frame:
                pose(frame, tau, True)
    else:
        pose(vis, phase, False)

    # the contact painted on the faces
    legend = None
    if paint is not None and has_damper:
        if painted_dampers is None:
            painted_dampers = list(ks[:n_dampers]) if layout == "sector" else [ks[0]]
        painted = [int(k) for k in painted_dampers]
        drawn = [int(k) for k in ks[:n_dampers]]
        if not set(painted) <= set(drawn):
            raise ValueError(f"painted_dampers must be among the dampers drawn, {drawn} (got {painted})")
        legend = _paint_faces(scene, data, lay, paint, painted, drawn, list(ks), B, D, n, dphi, anim,
                              n_frames, phase, explode if damper_view == "exploded" else None)

    # contact maps
    map_origin = np.array([0.04, 0.0, z_p + 0.06])
    r_tip = None
    if layout == "disk":
        # beside the disk, right of the blade tips' circle (centre (0, 0, -r_root)), in front of
        # the blades: the maps and the legend cross no blade
        r_tip = r_root + blade_length
        map_origin = np.array([r_tip + 0.03, -0.02, -r_root + 0.09])
    if contact_maps and has_damper:
        samples = _add_contact_maps(scene, data, map_origin, n_frames)
        _map_frames(scene, anim, n_frames, phase)
        scene.info["state_frames"] = [data.states[s] for s in samples]
    if anim is not None:
        _discrete_visibility(anim)
        vis.set_animation(anim, play=True, repetitions=_REPETITIONS)

    # cameras: the whole sector / disk, and damper 0 between its platforms
    if layout == "disk":
        # the whole disk (and the maps beside it), seen from the front and a little from the side
        # and above so that the dampers between the platforms show
        whole = ((np.array([0.06, 0.0, -r_root]), np.array([0.02, -0.42, 0.04])) if contact_maps and has_damper
                 else (np.array([0.0, 0.0, -r_root]), np.array([0.0, -0.36, 0.04])))
    else:
        whole = (np.array([0.01, 0.0, 0.5 * g.total_length - 0.01]), np.array([0.05, -0.245, 0.04]))
    cameras = {"whole": whole}
    if has_damper:
        # front and below: the platforms' inclined faces and the damper between them
        R0 = D[0][:3, :3]
        cameras["damper"] = (D[0][:3, 3].copy(), R0 @ np.array([0.0, -0.036, -0.018]))
    first = camera if camera is not None else cameras.get(view, whole)
    _set_camera(vis, *first)
    scene.info.update(index=data.index, frequency_hz=data.frequency_hz, scale=scale, n_frames=n_frames,
                      layout=layout, blades=list(ks), tip_amplitude=data.tip_amplitude, animate=animate,
                      liftoff_ratio=data.liftoff_ratio, root_radius=r_root, cycle=data, cameras=cameras,
                      camera=first, damper_view=damper_view, period_s=float(period_s), phase=float(phase),
                      explode=explode, dampers=[int(k) for k in ks[:n_dampers]] if has_damper else [])
    if title is None:
        title = _design_title(disk)
    scene.info["title"] = title
    if overlay:
        scene.overlay = overlay_html(scene, title, legend)
    return scene


def _design_title(disk) -> str:
    """'cylinder damper 1 g, 16 blades, EO 1' (or 'no damper, ...')."""
    damper = f"{disk.damper.kind} damper {1e3 * disk.damper.mass:.3g} g" if disk.has_damper else "no damper"
    return f"{damper}, {disk.n_blades} blades, EO {disk.engine_order}"


def _face_tiles(points, frame, half_xi, half_eta, offset, colors):
    """One quad per point contact in its contact plane: centred ``offset`` [m] along the normal
    (frame rows xi, eta, zeta) off ``points`` (P, 3), half sizes ``half_xi``, ``half_eta`` [m];
    vertex colours ``colors`` (P, 3)."""
    e_xi, e_eta, e_zeta = frame
    verts, faces, cols = [], [], []
    for p, c in zip(points, colors):
        o = p + offset * e_zeta
        base = len(verts)
        verts += [o - half_xi * e_xi - half_eta * e_eta, o + half_xi * e_xi - half_eta * e_eta,
                  o + half_xi * e_xi + half_eta * e_eta, o - half_xi * e_xi + half_eta * e_eta]
        faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
        cols += [c] * 4
    return mg.TriangularMeshGeometry(np.array(verts), np.array(faces), np.array(cols))


def point_pressure(data) -> tuple[np.ndarray, str]:
    """Normal pressure of every point contact over the cycle, (T, 2, P), and its unit: the normal
    load over the point's cell, h_C l_C / P [m^2] in MPa for an area contact, l_C / n_eta [m]
    in N/mm along a line contact (h_C = 0). ``data``: a :class:`CycleData` with a damper."""
    patch = data.patches[0]
    if patch.height > 0:
        return data.normal_load / (patch.height * patch.length / patch.n_points) / 1e6, "MPa"
    return data.normal_load / (patch.length / patch.n_eta) / 1e3, "N/mm"


def _paint_faces(scene, data, lay, paint, painted, drawn, ks, B, D, n_blades, dphi, anim, n_frames, phase,
                 explode):
    """Tiles coloured by ``paint`` at every point contact on the platforms' and the damper's contact
    faces of the dampers ``painted``; one mesh per frame and face, shown one frame at a time.
    Returns the legend (dict) for the overlay."""
    import matplotlib

    vis = scene.vis[ROOT]
    patches = data.patches
    pts = lay.contact_points()                                       # (2, P, 3) blade 0 frame
    frames = lay.frames
    half = []
    for p in patches:
        cell_eta = p.length / p.n_eta
        half.append((0.45 * (p.height / p.n_xi if p.height > 0 else 0.6 * cell_eta), 0.45 * cell_eta))
    if paint == "state":
        values = data.states
        colour_of = lambda v: STATE_COLORS[v]                        # noqa: E731
        legend = {"kind": "state", "names": list(STATE_NAMES), "colors": list(palette.CONTACT_STATES)}
    else:
        values, unit = point_pressure(data)
        vmax = float(values.max()) if values.max() > 0 else 1.0
        cmap = matplotlib.colormaps["viridis"]
        colour_of = lambda v: cmap(np.clip(v / vmax, 0, 1))[..., :3]   # noqa: E731
        legend = {"kind": "pressure", "unit": unit, "max": vmax,
                  "colors": [matplotlib.colors.to_hex(cmap(x)) for x in np.linspace(0, 1, 9)]}
    T = values.shape[0]
    n_shown = n_frames if anim is not None else 1
    info = {"kind": paint, "dampers": {}}
    blade_index = {int(k): j for j, k in enumerate(ks)}
    for k in painted:
        j = drawn.index(k)
        left, right = int(k), (int(k) + 1) % n_blades                 # OL on blade k, OR on blade k + 1
        if right not in blade_index:
            raise ValueError(f"damper {k}: blade {right} is not drawn")
        own = [pts[0], pts[1] + np.array([lay.pitch, 0.0, 0.0])]     # each face in its blade's own frame
        damper_pts = pts - lay.damper_cg
        entry = {"platform_paths": [], "damper_paths": [], "samples": [], "colors": [], "values": [],
                 "world": [], "damper_world": []}
        for c, (name, b) in enumerate((("OL", left), ("OR", right))):
            Bb = B[blade_index[b]]
            entry["world"].append(own[c] @ Bb[:3, :3].T + Bb[:3, 3])
            Dj = D[j] @ (explode if explode is not None else np.eye(4))
            entry["damper_world"].append(damper_pts[c] @ Dj[:3, :3].T + Dj[:3, 3])
        for f in range(n_shown):
            tau = 2 * np.pi * f / n_frames if anim is not None else phase
            s = int(round((tau + k * dphi) / (2 * np.pi) * T)) % T    # damper k: damper 0 at tau + k dphi
            colors = np.array([colour_of(values[s, c]) for c in range(2)])       # (2, P, 3)
            entry["samples"].append(s)
            entry["colors"].append(colors)
            entry["values"].append(values[s])
            tag = f"frame_{f:03d}"
            for c, (name, b) in enumerate((("OL", left), ("OR", right))):
                hx, he = half[c]
                pp = vis["blades"][f"blade_{b:02d}"]["platform"]["paint"][f"damper_{k:02d}_{name}"][tag]
                pp.set_object(_face_tiles(own[c], frames[c], hx, he, PAINT_OFFSET, colors[c]),
                              mg.MeshBasicMaterial(vertexColors=True))
                dp = vis["dampers"][f"damper_{k:02d}"]["body"]["paint"][name][tag]
                dp.set_object(_face_tiles(damper_pts[c], frames[c], hx, he, -PAINT_OFFSET, colors[c]),
                              mg.MeshBasicMaterial(vertexColors=True))
                if f == 0:
                    entry["platform_paths"].append(pp.path.lower().rsplit("/", 1)[0])
                    entry["damper_paths"].append(dp.path.lower().rsplit("/", 1)[0])
        if explode is not None:
            vis["dampers"][f"damper_{k:02d}"]["body"]["paint"].set_transform(explode)
        entry["colors"] = np.array(entry["colors"])
        entry["world"] = np.array(entry["world"])
        entry["damper_world"] = np.array(entry["damper_world"])
        info["dampers"][k] = entry
    if anim is not None:
        for f in range(n_frames + 1):
            with anim.at_frame(scene.vis, f) as frame:
                for k, entry in info["dampers"].items():
                    for path in entry["platform_paths"] + entry["damper_paths"]:
                        node = frame[path.replace("/meshcat/", "", 1)]
                        for m in range(n_frames):
                            node[f"frame_{m:03d}"].set_property("visible", "boolean", bool(m == f % n_frames))
    scene.info["paint"] = info
    return legend


def overlay_html(scene, title: str, legend: dict | None) -> str:
    """The page's overlay (top left, text 14 px): the design ``title``, frequency and drawn
    magnification, the legend of what is painted, and the controls: play / pause and a phase
    scrubber (animated scenes), the camera (damper 0 / whole) and the damper (solid /
    transparent / exploded). The page reads ``?phase=DEG&paused&view=damper|whole&damper=...``
    (or the same after ``#``) when it opens."""
    import html as _html
    import json

    info = scene.info
    T0 = {}
    for name, (target, position) in info["cameras"].items():
        root, cam = _camera_values(target, position)
        T0[name] = {"root": root, "camera": cam}
    damper_nodes = []
    for k in info["dampers"]:
        base = f"/meshcat/{ROOT}/dampers/damper_{k:02d}/body"
        damper_nodes.append({"mesh": base + "/mesh", "paint": base + "/paint"})
    explode = info["explode"]
    config = {"period": info["period_s"] if info["animate"] else 0.0, "animate": bool(info["animate"]),
              "cameras": T0, "dampers": damper_nodes, "explode": list(map(float, explode.T.ravel())),
              "identity": list(map(float, np.eye(4).ravel())), "damper_color": list(palette.rgb("#%06x" % DAMPER_COLOR)),
              "opacity": DAMPER_OPACITY, "damper_view": info["damper_view"],
              "view": next((k for k, v in info["cameras"].items() if v is info["camera"]), "custom")}
    rows = []
    if legend is not None and legend["kind"] == "state":
        items = "".join(f'<span class="bd-item"><span class="bd-swatch" style="background:{c}"></span>{_html.escape(nm)}</span>'
                        for nm, c in zip(legend["names"], legend["colors"]))
        rows.append(f'<div id="bd-legend">contact: {items}</div>')
    elif legend is not None:
        grad = ", ".join(legend["colors"])
        rows.append(f'<div id="bd-legend">normal pressure [{_html.escape(legend["unit"])}]: 0 '
                    f'<span class="bd-bar" style="background: linear-gradient(to right, {grad})"></span> '
                    f'{legend["max"]:.3g}</div>')
    whole_name = "whole disk" if info["layout"] == "disk" else "whole sector"
    controls = []
    if info["animate"]:
        controls.append('<div><button id="bd-play" type="button">pause</button> '
                        '<input id="bd-phase" type="range" min="0" max="360" step="1" value="0" aria-label="phase"> '
                        '<span id="bd-phase-value">0&deg;</span></div>')
    else:
        controls.append(f'<div>phase {np.degrees(info.get("phase", 0.0)) % 360:.0f}&deg; (still frame)</div>')
    buttons = []
    if "damper" in info["cameras"]:
        buttons.append('<button id="bd-view-damper" type="button">one damper</button>')
    buttons.append(f'<button id="bd-view-whole" type="button">{whole_name}</button>')
    if info["dampers"]:
        buttons.append('damper: ' + " ".join(f'<button id="bd-damper-{v}" type="button">{v}</button>'
                                             for v in DAMPER_VIEWS))
    controls.append('<div>' + " ".join(buttons) + '</div>')
    style = ("#bd-overlay {position: absolute; top: 8px; left: 8px; z-index: 10; max-width: 580px; "
             "font: 14px/1.5 system-ui, sans-serif; color: #111; background: rgba(255, 255, 255, 0.9); "
             "padding: 8px 12px; border-radius: 6px; box-shadow: 0 1px 4px rgba(0, 0, 0, 0.3);} "
             "#bd-overlay div {margin: 2px 0;} #bd-title {font-size: 16px; font-weight: 600;} "
             "#bd-overlay button {font: 14px system-ui, sans-serif; margin: 2px 2px 2px 0;} "
             "#bd-overlay button.bd-on {background: #333; color: #fff;} "
             "#bd-phase {width: 180px; vertical-align: middle;} "
             ".bd-item {margin-right: 10px; white-space: nowrap;} "
             ".bd-swatch {display: inline-block; width: 14px; height: 14px; margin: 0 4px -2px 4px; "
             "border: 1px solid #555;} .bd-bar {display: inline-block; width: 140px; height: 12px; "
             "vertical-align: middle; border: 1px solid #555;}")
    text = (f'<div id="bd-title">{_html.escape(title)}</div>'
            f'<div id="bd-frequency">{info["frequency_hz"]:.2f} Hz, tip amplitude '
            f'{1e3 * info["tip_amplitude"]:.3g} mm, motion drawn {info["scale"]:.3g} x</div>')
    return ("<style>" + style + "</style>\n<div id=\"bd-overlay\">" + text + "".join(rows) + "".join(controls)
            + "</div>\n<script>\nvar bladedampView = " + json.dumps(config) + ";\n" + _OVERLAY_JS + "</script>\n")


_OVERLAY_JS = r"""
(function () {
  var cfg = bladedampView, anim = viewer.animator;
  var play = document.getElementById("bd-play"), scrub = document.getElementById("bd-phase");
  var shown = document.getElementById("bd-phase-value");
  function send(type, path, key, value) {
    var c = {type: type, path: path};
    if (type === "set_transform") { c.matrix = value; } else { c.property = key; c.value = value; }
    viewer.handle_command(c);
  }
  function mark(prefix, which) {
    document.querySelectorAll("button[id^='" + prefix + "']").forEach(function (b) {
      b.classList.toggle("bd-on", b.id === prefix + which);
    });
  }
  function setView(name) {
    var c = cfg.cameras[name];
    if (!c) { return; }
    send("set_transform", "/meshcat/bladedamp", null, c.root);
    send("set_property", "/Cameras/default/rotated/<object>", "position", c.camera);
    if (viewer.controls) { viewer.controls.target.set(0, 0, 0); viewer.controls.update(); }
    cfg.view = name; mark("bd-view-", name); viewer.set_dirty();
  }
  function setDamper(mode) {
    var col = cfg.damper_color.concat([mode === "transparent" ? cfg.opacity : 1.0]);
    cfg.dampers.forEach(function (d) {
      send("set_property", d.mesh, "color", col);
      var m = mode === "exploded" ? cfg.explode : cfg.identity;
      send("set_transform", d.mesh, null, m);
      send("set_transform", d.paint, null, m);
    });
    cfg.damper_view = mode; mark("bd-damper-", mode); viewer.set_dirty();
  }
  function phaseDeg() {
    if (!anim.actions.length || !cfg.period) { return 0; }
    var t = anim.actions[0].time % cfg.period;
    return 360 * t / cfg.period;
  }
  function showPhase() {
    if (!scrub) { return; }
    var d = phaseDeg();
    scrub.value = Math.round(d) % 360; shown.textContent = Math.round(d) % 360 + "\u00b0";
  }
  function seek(deg) { anim.seek(cfg.period * (((deg % 360) + 360) % 360) / 360); showPhase(); }
  function setPlaying(on) {
    if (on) { anim.play(); } else { anim.pause(); }
    if (play) { play.textContent = on ? "pause" : "play"; }
  }
  document.querySelectorAll("button[id^='bd-view-']").forEach(function (b) {
    b.addEventListener("click", function () { setView(b.id.slice(8)); });
  });
  document.querySelectorAll("button[id^='bd-damper-']").forEach(function (b) {
    b.addEventListener("click", function () { setDamper(b.id.slice(10)); });
  });
  mark("bd-view-", cfg.view); mark("bd-damper-", cfg.damper_view);
  var params = new URLSearchParams(location.search + "&" + location.hash.replace(/^#/, ""));
  window.bladedampControls = {setView: setView, setDamper: setDamper, seek: seek, setPlaying: setPlaying,
                              phase: phaseDeg};
  function start() {                     // once the scene's commands are handled
    if (!window.bladedampLoaded || (cfg.animate && !anim.actions.length)) { setTimeout(start, 20); return; }
    if (params.get("view")) { setView(params.get("view")); }
    if (params.get("damper")) { setDamper(params.get("damper")); }
    if (cfg.animate) {
      play.addEventListener("click", function () { setPlaying(!anim.playing); });
      scrub.addEventListener("input", function () { setPlaying(false); seek(parseFloat(scrub.value)); });
      if (params.has("phase")) { setPlaying(false); seek(parseFloat(params.get("phase")) || 0); }
      if (params.has("paused")) { setPlaying(false); }
      setInterval(function () { if (anim.playing) { showPhase(); } }, 100);
    }
    document.body.setAttribute("data-bd-ready", "1");
  }
  start();
})();
"""


def _discrete_visibility(anim):
    """Boolean (visible) tracks step from frame to frame (three.js InterpolateDiscrete = 2300)."""
    for clip in anim.clips.values():
        for name, track in list(clip.tracks.items()):
            if track.jstype == "boolean" and not isinstance(track, _DiscreteTrack):
                clip.tracks[name] = _DiscreteTrack(track.name, track.jstype, track.frames, track.values)


class _DiscreteTrack(meshcat.animation.AnimationTrack):
    __slots__ = ()

    def lower(self):
        out = super().lower()
        out["interpolation"] = 2300
        return out


def contact_map_scene(result, index: int | None = None, frequency_hz: float | None = None, n_frames: int = 36,
                      period_s: float = 2.0, animate: bool = True, phase: float = 0.0) -> Scene:
    """Only the contact maps and the legend, seen face-on (the contact map picture)."""
    disk = result.disk
    if disk is None or not disk.has_damper:
        raise ValueError("result must be a DiskResponse of a disk with a damper")
    data = cycle_data(result, index, frequency_hz)
    scene = Scene()
    vis = scene.vis
    plain_stage(vis)
    origin = np.zeros(3)
    samples = _add_contact_maps(scene, data, origin, n_frames)
    anim = meshcat.animation.Animation(default_framerate=n_frames / period_s) if animate else None
    _map_frames(scene, anim, n_frames, phase)
    if anim is not None:
        _discrete_visibility(anim)
        vis.set_animation(anim, play=True, repetitions=_REPETITIONS)
    w, h = scene.info["map_size"]
    first_row = scene.info["first_row_height"]
    target = np.array([w / 2, 0.0, first_row - h / 2])
    _set_camera(vis, target, np.array([0.0, -max(h / 1.3, w / 1.6), 0.0]))
    scene.info.update(index=data.index, frequency_hz=data.frequency_hz, n_frames=n_frames, animate=animate,
                      liftoff_ratio=data.liftoff_ratio, state_frames=[data.states[s] for s in samples], cycle=data)
    return scene


def show(result, path=None, live: bool = False, open_browser: bool = False, **options):
    """Build :func:`ods_scene` for ``result``; write it to ``path`` (standalone HTML) if given; with
    ``live=True`` also start a localhost meshcat server and return ``(scene, view)`` (close the view).
    Returns the Scene otherwise. Default layout: the whole disk ("disk", every blade and damper,
    damper 0's contact painted on its faces, the camera on it) for a damped disk, the sector
    without damper."""
    disk = getattr(result, "disk", None)
    options.setdefault("layout", "disk" if disk is not None and disk.has_damper else "sector")
    scene = ods_scene(result, **options)
    if path is not None:
        scene.save_html(path)
    if live:
        return scene, scene.serve(open_browser=open_browser)
    return scene


# --------------------------------------------------------------------------------------
# headless browser screenshot
# --------------------------------------------------------------------------------------
def chromium_executable() -> str | None:
    """Path of a Chromium/Chrome executable, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def screenshot(html_path, png_path, size=(800, 600), virtual_time_ms: int = 5000, timeout: float = 180.0) -> str:
    """Render a standalone HTML file in headless Chromium (software WebGL) into a PNG."""
    exe = chromium_executable()
    if exe is None:
        raise RuntimeError("no chromium executable found")
    with tempfile.TemporaryDirectory() as profile:
        args = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                "--disable-background-networking", "--disable-component-update", "--no-first-run",
                f"--user-data-dir={profile}", f"--screenshot={os.path.abspath(png_path)}",
                f"--window-size={size[0]},{size[1]}", f"--virtual-time-budget={int(virtual_time_ms)}",
                "file://" + os.path.abspath(html_path)]
        subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=timeout, check=True)
    if not os.path.exists(png_path):
        raise RuntimeError("chromium wrote no screenshot")
    return os.fspath(png_path)


def readme_images(out_dir="assets", size=(900, 650)) -> list:
    """The README pictures: the reference cylinder (1 g) at its 1F resonance, a still frame of the
    3D view (``ods_3d.png``) and of the contact maps (``contact_map.png``), rendered by headless
    Chromium from the standalone HTML. Returns the paths."""
    import bladedamp as bd

    frf = bd.frequency_response(bd.reference_disk("cylinder", 1e-3), (90.0, 105.0))
    phase = 2 * np.pi * 10 / 36
    os.makedirs(out_dir, exist_ok=True)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene in (("ods_3d", ods_scene(frf, animate=False, phase=phase)),
                            ("contact_map", contact_map_scene(frf, animate=False, phase=phase))):
            html = scene.save_html(os.path.join(tmp, name + ".html"))
            out.append(screenshot(html, os.path.join(out_dir, name + ".png"), size=size, virtual_time_ms=2000))
    return out


if __name__ == "__main__":
    if "--serve" in sys.argv:
        _serve()
    elif "--readme-images" in sys.argv:
        print(readme_images(*sys.argv[sys.argv.index("--readme-images") + 1:][:1]))
