"""Small matplotlib helpers shared by the result plots and the report's figures.

:func:`place_legend` draws a legend that hides no data: where every location of the axes
would cover a point (a resonance peak, a marker), it makes room above the data by raising the
upper y limit until the legend is clear. :func:`legend_covers` counts the data points under a
legend (the tests use it on every figure of the report).
"""
from __future__ import annotations

import numpy as np


def _data_points(ax):
    """[(xy (k, 2) display coordinates, radius [px])] of every line and scatter of ``ax``."""
    dpi = ax.figure.dpi
    out = []
    for line in ax.get_lines():
        if not line.get_visible():
            continue
        xy = np.asarray(line.get_xydata(), dtype=float)
        if not xy.size:
            continue
        xy = line.get_transform().transform(xy)
        radius = 0.5 * line.get_markersize() * dpi / 72 if line.get_marker() not in (None, "None", "", " ") else 0.0
        if line.get_linestyle() not in ("None", "", " "):
            xy = _densified(xy)
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        if len(xy):
            out.append((xy, radius + 0.5 * line.get_linewidth() * dpi / 72))
    for coll in ax.collections:
        offsets = np.asarray(coll.get_offsets(), dtype=float)
        if not coll.get_visible() or offsets.ndim != 2 or not len(offsets):
            continue
        offsets = offsets[np.all(np.isfinite(offsets), axis=1)]
        sizes = np.atleast_1d(coll.get_sizes()) if hasattr(coll, "get_sizes") else np.zeros(1)
        radius = 0.5 * np.sqrt(float(np.max(sizes))) * dpi / 72 if sizes.size else 0.0
        out.append((coll.get_offset_transform().transform(offsets), radius))
    return out


def _densified(xy: np.ndarray, spacing: float = 2.0) -> np.ndarray:
    """The polyline ``xy`` (k, 2) [px] with points every ``spacing`` px along each segment (a
    segment with a NaN end is a gap and gets none)."""
    if len(xy) < 2:
        return xy
    seg = np.diff(xy, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    n = np.where(np.isfinite(length), np.ceil(np.nan_to_num(length) / spacing), 0).astype(int)
    n = np.minimum(n, 5000)
    pieces = [xy[:1]]
    for a, d, k in zip(xy[:-1], seg, n):
        if k > 1:
            pieces.append(a + d * (np.arange(1, k)[:, None] / k))
    pieces.append(xy[1:])
    return np.vstack(pieces)


def legend_covers(ax, legend=None) -> int:
    """Number of data points of ``ax`` (line vertices, markers, scatter points, with their
    marker size) that lie under its legend (0: the legend hides nothing)."""
    legend = legend if legend is not None else ax.get_legend()
    if legend is None:
        return 0
    renderer = ax.figure.canvas.get_renderer()
    box = legend.get_window_extent(renderer)
    inside = 0
    for xy, r in _data_points(ax):
        inside += int(np.sum((xy[:, 0] >= box.x0 - r) & (xy[:, 0] <= box.x1 + r)
                             & (xy[:, 1] >= box.y0 - r) & (xy[:, 1] <= box.y1 + r)))
    return inside


def place_legend(ax, loc: str = "best", max_tries: int = 8, **kwargs):
    """``ax.legend(loc=loc, **kwargs)`` moved clear of the data: if it covers a point, the upper
    y limit is raised (by 15 % of the span, or a factor on a log axis) and the legend placed
    again, up to ``max_tries`` times. Returns the legend."""
    fig = ax.figure
    engine = fig.get_layout_engine() if hasattr(fig, "get_layout_engine") else None
    if engine is None or type(engine).__name__ in ("PlaceHolderLayoutEngine", "TightLayoutEngine"):
        fig.tight_layout()           # settle the layout first (save_figure's tight_layout keeps it)
    else:
        fig.canvas.draw()            # a figure with its own layout engine (constrained) keeps it
    legend = ax.legend(loc=loc, **kwargs)
    for _ in range(max_tries):
        ax.figure.canvas.draw()
        if legend_covers(ax, legend) == 0:
            break
        lo, hi = ax.get_ylim()
        if ax.get_yscale() == "log":
            ax.set_ylim(lo, hi * (hi / lo) ** 0.15)
        else:
            ax.set_ylim(lo, hi + 0.15 * (hi - lo))
        legend = ax.legend(loc=loc, **kwargs)
    return legend
