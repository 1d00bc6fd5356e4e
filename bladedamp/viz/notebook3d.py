"""Helpers of notebook 04 (contact in 3D): plain functions, values in, data or figures out.

* :func:`show_scene` (a PNG still, then the live view), :func:`embed_scene` / :func:`save_scene`: show a recorded meshcat :class:`~bladedamp.viz.Scene`
  in a notebook cell (an ``<iframe srcdoc>`` of its standalone HTML) or write it to a file and
  link it. Neither starts a meshcat server: the scene is recorded in-process.
* :func:`wedge_disk`, :func:`liftoff_case`, :func:`liftoff_figure`: the reference wedge's
  lift-off map (Fig. 9), labelled as the one-harmonic approximation it is (:func:`one_harmonic_label`) for a contact height and tip excitation, memoised, so a slider moved
  back answers at once (a new value costs one continuation run over a narrow window, ~1 s).
* :func:`misfit_wedge_disk`: the wedge with one face angle off by a few degrees
  (:func:`bladedamp.geometry.misfit_gaps` -> ``TunedDisk(initial_gaps=...)``).
* :func:`cycle_figure`: the contact state of every patch point over one vibration cycle and its
  lift-off ratio, from :func:`bladedamp.viz.meshcat_view.cycle_data` (a flat picture of what the
  3D contact maps animate).
* :func:`tangential_ratio`: Eq. 27's normalised first-harmonic tangential amplitude
  |w*| = |w_xi,1| c_T / (mu F_N) of OL and OR at one point of a response (Fig. 11).
* :func:`contact_view`: the 3D contact view (state painted on the faces, overlay with play /
  pause and phase scrubber) with the hysteresis loop of a picked point contact beside it, whose
  marker follows the animation (:func:`hysteresis_loops`, :func:`loop_panel`).

Units: SI inside; arguments named ``*_mm``, ``*_g``, ``*_deg``, ``*_n`` carry slider units.
"""
from __future__ import annotations

import dataclasses
import html as _html
import os
import subprocess
import textwrap
from functools import lru_cache

import numpy as np

from .. import palette
from ..palette import CONTACT_STATE_NAMES as STATE_NAMES
from ..palette import CONTACT_STATES as STATE_COLORS

# --------------------------------------------------------------------------------------
# showing recorded meshcat scenes
# --------------------------------------------------------------------------------------
def scene_iframe(scene, height: int = 480) -> str:
    """HTML of an iframe whose ``srcdoc`` is the scene's standalone page (no server)."""
    return ('<div style="height: {h}px; width: 100%; resize: both; overflow: hidden">'
            '<iframe srcdoc="{doc}" style="width: 100%; height: 100%; border: none"></iframe></div>'
            .format(h=int(height), doc=_html.escape(scene.html(), quote=True)))


def embed_scene(scene, height: int = 480):
    """``IPython.display.HTML`` showing ``scene`` in the cell (about 1.5 MB of output). Saved with
    the notebook, it shows before anything runs wherever HTML outputs are shown: JupyterLab once
    the notebook is trusted (``jupyter trust``: JupyterLab strips iframes, and draws no widget,
    in a notebook it does not trust), VS Code, nbviewer."""
    from IPython.display import HTML

    return HTML(scene_iframe(scene, height))


#: what the still of a 3D view says under it, in a notebook
LIVE_VIEW_HINT = ("A still of the 3D view. The live view below (drag to turn, scroll to zoom, the cycle "
                  "animates) shows once the notebook is trusted: in JupyterLab File > Trust Notebook, or "
                  "`jupyter trust` on the file; running the cell rebuilds it.")


def scene_snapshot(scene, size=(900, 520)) -> bytes | None:
    """PNG bytes of ``scene`` rendered by headless Chromium (software WebGL) at ``size`` (width,
    height) [px], or None when no Chromium is installed or it drew nothing."""
    import tempfile

    from .meshcat_view import chromium_executable, screenshot

    if chromium_executable() is None:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        page = scene.save_html(os.path.join(tmp, "scene.html"))
        try:
            png = screenshot(page, os.path.join(tmp, "scene.png"), size=size, virtual_time_ms=2000)
        except (RuntimeError, OSError, subprocess.SubprocessError):
            return None
        with open(png, "rb") as f:
            return f.read()


def show_scene(scene, height: int = 480):
    """Display a PNG still of ``scene`` (:func:`scene_snapshot`) with :data:`LIVE_VIEW_HINT` under
    it, then return :func:`embed_scene`'s live view. The still is what a notebook shows where the
    live view cannot be drawn (an untrusted notebook, a static viewer); without Chromium the
    line says that no still was made."""
    from IPython.display import Image, Markdown, display

    png = scene_snapshot(scene, size=(900, height))
    if png is not None:
        display(Image(data=png, format="png"))
        display(Markdown(LIVE_VIEW_HINT))
    else:
        display(Markdown("No still of the 3D view (it needs Chromium). " + LIVE_VIEW_HINT.split(". ", 1)[1]))
    return embed_scene(scene, height)


def save_scene(scene, path, text: str | None = None):
    """Write ``scene`` as standalone HTML to ``path`` and return an ``IPython.display.HTML`` link
    to it (relative to the notebook's folder, opens in a new tab)."""
    from IPython.display import HTML

    path = os.fspath(path)
    directory = os.path.dirname(path)
    if directory:
        os.makedirs(directory, exist_ok=True)
    scene.save_html(path)
    link = path.replace(os.sep, "/")
    label = _html.escape(text or f"open {os.path.basename(path)}")
    return HTML(f'<a href="{_html.escape(link, quote=True)}" target="_blank">{label}</a> '
                f'(standalone page, {os.path.getsize(path) / 1e6:.1f} MB)')


# --------------------------------------------------------------------------------------
# wedge lift-off (Fig. 9)
# --------------------------------------------------------------------------------------
def wedge_disk(contact_height_mm: float = 2.0, force_n: float = 0.1, mass_g: float = 1.0):
    """The reference disk with a wedge of contact height h_C and tip excitation F_x."""
    from ..reference import reference_disk

    disk = reference_disk("wedge", 1e-3 * mass_g, excitation=np.array([force_n, 0, 0, 0, 0, 0], dtype=float))
    return dataclasses.replace(disk, damper=dataclasses.replace(disk.damper, contact_height=1e-3 * contact_height_mm))


@lru_cache(maxsize=256)
def _liftoff_case(contact_height_mm, force_n, mass_g, f_range_hz):
    from ..studies.design import wedge_liftoff_map

    return wedge_liftoff_map(wedge_disk(contact_height_mm, force_n, mass_g), f_range_hz)


def liftoff_case(contact_height_mm: float = 2.0, force_n: float = 0.1, mass_g: float = 1.0,
                 f_range_hz=(94.0, 98.0)):
    """:class:`~bladedamp.studies.design.LiftoffMap` of the wedge at its 1F resonance (memoised on
    the values rounded to 1e-6; the window widens by itself if the peak leaves it)."""
    key = (round(float(contact_height_mm), 6), round(float(force_n), 6), round(float(mass_g), 6),
           tuple(round(float(f), 6) for f in f_range_hz))
    return _liftoff_case(*key)


def liftoff_figure(contact_height_mm: float = 2.0, force_n: float = 0.1, mass_g: float = 1.0,
                   f_range_hz=(94.0, 98.0)):
    """Slider callback: the lift-off ratio r of every point of OL and OR (Fig. 9) as two maps."""
    import matplotlib.pyplot as plt

    m = liftoff_case(contact_height_mm, force_n, mass_g, f_range_hz)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True, constrained_layout=True)
    vmax = max(2.0, float(np.ceil(m.ratio.max())))
    for c, ax in enumerate(axes):
        sc = ax.scatter(m.eta_star, m.xi_star, c=m.ratio[c], s=140, cmap="viridis", vmin=0, vmax=vmax,
                        marker="s")
        lift = m.lifts_off[c]
        ax.scatter(m.eta_star[lift], m.xi_star[lift], s=260, facecolors="none", edgecolors=palette.SLIP, lw=1.5,
                   gid="reference")          # rings on the map's cells, not a series of their own
        ax.set_xlabel("eta* = eta / l_C [-] (along the damper)")
        ax.set_title(f"{('OL', 'OR')[c]}: max r = {m.ratio[c].max():.2f}")
        ax.set_xlim(-0.65, 0.65)
        ax.set_ylim(-0.65, 0.65)
    axes[0].set_ylabel("xi* = xi / h_C [-] (across the height)")
    fig.colorbar(sc, ax=axes, label="lift-off ratio r [-] (ring: r > 1)")
    fig.suptitle(f"wedge {mass_g:g} g, h_C = {contact_height_mm:g} mm, F_x = {force_n:g} N: "
                 f"resonance {m.peak_frequency_hz:.2f} Hz, tip {1e3 * m.peak_amplitude:.3f} mm\n"
                 + textwrap.fill(one_harmonic_label(m.harmonic_error), 110), fontsize=10)
    return fig


def one_harmonic_label(harmonic_error: float) -> str:
    """One plain line naming a result of the one-harmonic model (the paper's) as the approximation
    it is: how far its amplitudes may be off by the harmonic error estimate [-], and what to do."""
    from ..hbm.accuracy import HARMONIC_TOLERANCE

    if not np.isfinite(harmonic_error):
        return "one-harmonic approximation (as in the paper); its error was not estimated"
    if harmonic_error <= HARMONIC_TOLERANCE:
        return f"one-harmonic approximation (as in the paper), within {100 * HARMONIC_TOLERANCE:g} % of the converged one"
    return (f"one-harmonic approximation (as in the paper): amplitudes may be off by up to about "
            f"{100 * harmonic_error:.0f} %; harmonics='auto' computes the converged ones")


# --------------------------------------------------------------------------------------
# a wedge that does not fit
# --------------------------------------------------------------------------------------
def misfit_wedge_disk(misfit_deg: float = 2.0, force_n: float = 0.05, mass_g: float = 1.0,
                      contact_height_mm: float = 2.0):
    """The wedge whose OL face angle is ``misfit_deg`` larger than the platform's, with the initial
    gaps of the mesh dropped into the groove (:func:`bladedamp.geometry.misfit_gaps`).
    Returns (disk, gaps (2, P) [m])."""
    from .. import geometry as bgeo

    disk = wedge_disk(contact_height_mm, force_n, mass_g)
    shape = bgeo.wedge_mesh(disk.damper, disk.gamma_left + np.radians(misfit_deg), disk.gamma_right)
    gaps = bgeo.misfit_gaps(disk, shape)
    return dataclasses.replace(disk, initial_gaps=gaps), gaps


# --------------------------------------------------------------------------------------
# one cycle, flat
# --------------------------------------------------------------------------------------
def cycle_figure(data, title: str = ""):
    """Contact state of every point over the cycle (OL, OR: rows = points numbered along the
    rows of the patch grid, columns = time samples) and the lift-off ratio per point.
    ``data``: a :class:`~bladedamp.viz.meshcat_view.CycleData`; ``title``: the suptitle, which
    should name the design (``data`` does not know it; default: the frequency and tip amplitude)."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    states = data.states                                  # (T, 2, P)
    T, _, P = states.shape
    ratio = np.where(np.isfinite(data.liftoff_ratio), data.liftoff_ratio, np.nan)
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.2), gridspec_kw=dict(width_ratios=(1, 1, 0.8)),
                             constrained_layout=True)
    cmap = ListedColormap(STATE_COLORS)
    phase = np.linspace(0, 360, T + 1)
    for c, ax in enumerate(axes[:2]):
        ax.pcolormesh(phase, np.arange(P + 1) + 0.5, states[:, c, :].T, cmap=cmap, vmin=-0.5, vmax=2.5)
        ax.set_xlabel("phase in the cycle [deg]")
        ax.set_title(("OL", "OR")[c])
        ax.set_xticks([0, 90, 180, 270, 360])
    axes[0].set_ylabel("point [-]")
    axes[1].tick_params(labelleft=False)                  # the same points as OL's
    axes[1].legend(handles=[Patch(color=STATE_COLORS[k], label=STATE_NAMES[k]) for k in range(3)],
                   fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))   # the maps' key, beside them
    for c in range(2):
        finite = np.isfinite(ratio[c])
        axes[2].plot(np.arange(1, P + 1)[finite], ratio[c][finite], "o", color=palette.series(c), ms=5,
                     label=("OL", "OR")[c])    # one value per point: markers (equal values are no flat curve)
        opened = ~finite
        if opened.any():   # a_static <= 0: r is infinite, marked at the top of the axis
            top = max(2.0, 1.1 * np.nanmax(np.where(np.isfinite(ratio), ratio, np.nan)))
            axes[2].plot(np.arange(1, P + 1)[opened], np.full(opened.sum(), top), "x", color=palette.series(c), ms=10,
                         label=f"{('OL', 'OR')[c]}: open at rest (r = inf)")
    axes[2].axhline(1.0, color=palette.SEPARATED, lw=0.8, ls="--")
    axes[2].set_xlabel("point [-]")
    axes[2].set_ylabel("lift-off ratio r [-]")
    axes[2].grid(True, alpha=0.3)
    axes[2].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))   # beside the points, hiding none
    fig.suptitle(title or f"{data.frequency_hz:.2f} Hz, tip {1e3 * data.tip_amplitude:.3f} mm", fontsize=10)
    return fig


def tangential_ratio(result, index: int | None = None) -> np.ndarray:
    """(2,) complex w* = w_xi,1 c_T / (mu F_N) of OL and OR (Eq. 27, Fig. 11) at ``index`` of
    ``result`` (default: the largest tip amplitude). |w*| > 1: the contact slips on part of the
    cycle; |w*| < 1: it sticks throughout."""
    i = int(np.argmax(result.tip_amplitude[:, 0])) if index is None else int(index)
    disk = result.disk
    w1 = result.basis.to_complex(result.relative_motion[i])[1]
    patches = disk.damper_geometry().patches
    c_t = np.array([p.tangential_stiffness for p in patches])
    mu = np.array([p.friction_coefficient for p in patches])
    F_N = np.asarray(disk.static_normal_loads(result.frequency_hz[i]), dtype=float)
    return w1[[0, 6]] * c_t / (mu * F_N)


# --------------------------------------------------------------------------------------
# the 3D view with a point's hysteresis loop beside it
# --------------------------------------------------------------------------------------
CONTACTS = ("OL", "OR")
PANEL_WIDTH = 380             # [px] the loop's panel at the right of the page
_PLOT = dict(width=360, height=270, left=62, right=10, top=12, bottom=44)   # SVG box and margins [px]


def hysteresis_loops(data):
    """Tangential force over the relative tangential displacement of every point contact over the
    cycle, along each point's slip direction (the principal axis of its tangential motion).

    ``data``: a :class:`~bladedamp.viz.meshcat_view.CycleData` with a damper. Returns
    (direction (2, P, 2) unit vectors in the contact plane (xi, eta), slip (T, 2, P) [m], force
    (T, 2, P) [N]): slip = u_t . d of the damper relative to the platform, force = f_t . d of the
    contact force on the platform. The loop's area over both tangential directions is the energy
    the point dissipates per cycle (``data.slip_work``)."""
    u = data.displacement[..., :2]                                   # (T, 2, P, 2)
    f = data.force[..., :2]
    T, C, P, _ = u.shape
    direction = np.zeros((C, P, 2))
    for c in range(C):
        for p in range(P):
            x = u[:, c, p] - u[:, c, p].mean(axis=0)
            _, _, vt = np.linalg.svd(x, full_matrices=False)
            d = vt[0]
            direction[c, p] = d if d[np.argmax(np.abs(d))] > 0 else -d     # sign: its larger component positive
    slip = np.einsum("tcpi,cpi->tcp", u, direction)
    force = np.einsum("tcpi,cpi->tcp", f, direction)
    return direction, slip, force


def _ticks(limit: float) -> np.ndarray:
    """Symmetric round ticks covering [-limit, limit]."""
    step = 10 ** np.floor(np.log10(limit))
    for m in (1, 2, 5, 10):
        if limit / (m * step) <= 3:
            step *= m
            break
    k = np.floor(limit / step)
    return np.arange(-k, k + 1) * step


def loop_panel(data, n_frames: int, point=("OL", 0)) -> dict:
    """SVG coordinates of every point's loop (:func:`hysteresis_loops`) on one shared scale.

    Returns {"loops": {"OL 1": {"xy": (T, 2) px, "states": (T,)}, ...}, "x_limit" [m],
    "y_limit" [N], "to_px": function (slip [m], force [N]) -> (x, y) px, "point": the first
    key shown, "n_frames", "n_samples"}. Points are numbered from 1 along the patch's rows."""
    _, slip, force = hysteresis_loops(data)
    T, C, P = slip.shape
    x_lim = 1.1 * max(np.abs(slip).max(), 1e-12)
    y_lim = 1.1 * max(np.abs(force).max(), 1e-12)
    w, h = _PLOT["width"], _PLOT["height"]
    x0, x1, y0, y1 = _PLOT["left"], w - _PLOT["right"], _PLOT["top"], h - _PLOT["bottom"]

    def to_px(s, f):
        return (x0 + (np.asarray(s) + x_lim) / (2 * x_lim) * (x1 - x0),
                y1 - (np.asarray(f) + y_lim) / (2 * y_lim) * (y1 - y0))

    loops = {}
    for c in range(C):
        for p in range(P):
            x, y = to_px(slip[:, c, p], force[:, c, p])
            loops[f"{CONTACTS[c]} {p + 1}"] = {"xy": np.column_stack([x, y]), "states": data.states[:, c, p]}
    name, p = point
    if name not in CONTACTS or not 0 <= int(p) < P:
        raise ValueError(f"point must be (contact in {CONTACTS}, index in 0..{P - 1}) (got {point!r})")
    return {"loops": loops, "x_limit": x_lim, "y_limit": y_lim, "to_px": to_px, "point": f"{name} {int(p) + 1}",
            "n_frames": int(n_frames), "n_samples": T}


def loop_panel_html(panel: dict) -> str:
    """The panel (HTML, SVG and script) for a page of :func:`bladedamp.viz.meshcat_view.ods_scene`:
    a point picker, the picked point's loop with its samples coloured by contact state, and a
    marker on the sample the 3D view paints now (it follows the page's animation phase)."""
    import json

    from ..palette import CONTACT_STATES

    w, h = _PLOT["width"], _PLOT["height"]
    x0, x1, y0, y1 = _PLOT["left"], w - _PLOT["right"], _PLOT["top"], h - _PLOT["bottom"]
    to_px = panel["to_px"]
    parts = [f'<rect x="{x0}" y="{y0}" width="{x1 - x0}" height="{y1 - y0}" fill="white" stroke="#444"/>']
    for t in _ticks(panel["x_limit"]):
        x = float(to_px(t, 0.0)[0])
        parts.append(f'<line x1="{x:.1f}" y1="{y1}" x2="{x:.1f}" y2="{y1 + 4}" stroke="#444"/>'
                     f'<text x="{x:.1f}" y="{y1 + 17}" text-anchor="middle">{1e6 * t:g}</text>')
    for t in _ticks(panel["y_limit"]):
        y = float(to_px(0.0, t)[1])
        parts.append(f'<line x1="{x0 - 4}" y1="{y:.1f}" x2="{x0}" y2="{y:.1f}" stroke="#444"/>'
                     f'<text x="{x0 - 6}" y="{y + 4:.1f}" text-anchor="end">{t:.3g}</text>')
    parts.append(f'<text x="{(x0 + x1) / 2}" y="{h - 6}" text-anchor="middle">relative tangential displacement [&#181;m]</text>'
                 f'<text transform="translate(14 {(y0 + y1) / 2}) rotate(-90)" text-anchor="middle">tangential force [N]</text>'
                 '<polyline id="bd-loop" fill="none" stroke="#222" stroke-width="1.2" points=""/>'
                 '<g id="bd-loop-samples"></g>'
                 '<circle id="bd-loop-marker" r="7" fill="none" stroke="#000" stroke-width="2.5" cx="0" cy="0"/>')
    options = "".join(f'<option value="{_html.escape(k)}"{" selected" if k == panel["point"] else ""}>{_html.escape(k)}</option>'
                      for k in panel["loops"])
    loops = {k: {"xy": np.round(v["xy"], 2).tolist(), "states": v["states"].tolist()} for k, v in panel["loops"].items()}
    config = {"loops": loops, "colors": list(CONTACT_STATES), "n_frames": panel["n_frames"],
              "n_samples": panel["n_samples"]}
    style = (f"#meshcat-pane {{width: calc(100vw - {PANEL_WIDTH}px) !important;}} "
             f"#bd-panel {{position: absolute; top: 0; right: 0; width: {PANEL_WIDTH}px; height: 100vh; "
             "box-sizing: border-box; padding: 10px; background: #fafafa; border-left: 1px solid #ccc; "
             "font: 14px/1.5 system-ui, sans-serif; color: #111;} #bd-panel svg {font: 12px system-ui, sans-serif;} "
             "#bd-panel select {font: 14px system-ui, sans-serif;} "
             f"#bd-overlay {{max-width: calc(100vw - {PANEL_WIDTH + 40}px) !important;}}")
    return (f"<style>{style}</style>\n<div id=\"bd-panel\"><div><b>hysteresis loop</b> of point "
            f"<select id=\"bd-point\" aria-label=\"contact point\">{options}</select></div>"
            f"<svg id=\"bd-loop-plot\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">{''.join(parts)}</svg>"
            "<div>dots: the samples of the cycle in their contact state; ring: the phase shown in 3D. "
            "Steep: sticking (the contact's elastic stiffness); flat: slipping at the friction limit.</div></div>\n"
            "<script>\nvar bladedampLoops = " + json.dumps(config) + ";\n" + _PANEL_JS + "</script>\n")


_PANEL_JS = r"""
(function () {
  var cfg = bladedampLoops, pick = document.getElementById("bd-point"), ns = "http://www.w3.org/2000/svg";
  var line = document.getElementById("bd-loop"), dots = document.getElementById("bd-loop-samples");
  var marker = document.getElementById("bd-loop-marker");
  function draw() {
    var loop = cfg.loops[pick.value];
    line.setAttribute("points", loop.xy.concat([loop.xy[0]]).map(function (p) { return p[0] + "," + p[1]; }).join(" "));
    while (dots.firstChild) { dots.removeChild(dots.firstChild); }
    loop.xy.forEach(function (p, s) {
      var c = document.createElementNS(ns, "circle");
      c.setAttribute("cx", p[0]); c.setAttribute("cy", p[1]); c.setAttribute("r", 3);
      c.setAttribute("fill", cfg.colors[loop.states[s]]); dots.appendChild(c);
    });
    follow();
  }
  function sample() {                       // the sample the 3D view paints at the current phase
    var deg = window.bladedampControls ? window.bladedampControls.phase() : 0;
    var f = Math.floor(deg / 360 * cfg.n_frames + 1e-6) % cfg.n_frames;
    return Math.round(f / cfg.n_frames * cfg.n_samples) % cfg.n_samples;
  }
  function follow() {
    var s = sample(), p = cfg.loops[pick.value].xy[s];
    marker.setAttribute("cx", p[0]); marker.setAttribute("cy", p[1]); marker.setAttribute("data-sample", s);
  }
  pick.addEventListener("change", draw);
  draw();
  setInterval(follow, 50);
})();
"""


def contact_view(result, index: int | None = None, point=("OL", 0), height: int = 560, n_frames: int = 36,
                 **scene_options):
    """The 3D contact view of ``result`` (:func:`bladedamp.viz.meshcat_view.ods_scene`: the
    contact state painted on the faces, overlay with play / pause and phase scrubber) with, beside
    it, the hysteresis loop of one point contact (``point`` = (contact "OL" or "OR", index from 0);
    the page's picker chooses another) and a marker that follows the animation. Returns an
    ``IPython.display.HTML`` (an iframe of the standalone page, as :func:`embed_scene`)."""
    from IPython.display import HTML

    return HTML(scene_iframe(contact_view_scene(result, index, point, n_frames, **scene_options), height))


def contact_view_scene(result, index: int | None = None, point=("OL", 0), n_frames: int = 36, **scene_options):
    """The :class:`~bladedamp.viz.Scene` of :func:`contact_view` (save it with ``save_html``)."""
    from .meshcat_view import ods_scene

    if result.disk is None or not result.disk.has_damper:
        raise ValueError("result must be a DiskResponse of a disk with a damper")
    scene = ods_scene(result, index=index, n_frames=n_frames, **scene_options)
    panel = loop_panel(scene.info["cycle"], n_frames, point)
    scene.overlay = scene.overlay + loop_panel_html(panel)
    scene.info["loop_panel"] = panel
    return scene
