"""Small matplotlib helpers shared by the result plots and the report's figures.

:func:`place_legend` draws a legend that hides no data: where every location of the axes
would cover a point (a resonance peak, a marker), it makes room above the data by raising the
upper y limit until the legend is clear. :func:`legend_covers` counts the data points and the
filled data areas (bars, histogram bins, colour-map cells, images) under a legend (the tests use it
on every figure of the report and of the notebooks).

:func:`save_figure` writes every figure the product saves, in the formats and resolution set by
:func:`figure_output` (the command line's ``--format`` and ``--dpi``; PNG at 120 dpi otherwise).
"""
from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np

#: the file formats a figure can be written in (matplotlib's Agg, SVG and PDF backends)
FIGURE_FORMATS = ("png", "svg", "pdf")
DEFAULT_DPI = 120
_output = {"formats": ("png",), "dpi": DEFAULT_DPI}


def check_figure_output(formats, dpi) -> tuple[tuple[str, ...], int]:
    """(formats, dpi) checked: ``formats`` a non-empty sequence of :data:`FIGURE_FORMATS` (or a
    comma-separated string of them), ``dpi`` an integer in [10, 2400]; ValueError naming the
    parameter otherwise."""
    if isinstance(formats, str):
        formats = [f.strip().lower() for f in formats.split(",") if f.strip()]
    formats = tuple(dict.fromkeys(formats))
    bad = [repr(f) for f in formats if f not in FIGURE_FORMATS]
    if not formats or bad:
        raise ValueError(f"format {', '.join(bad) or 'empty'}: must be one or more of {', '.join(FIGURE_FORMATS)}, "
                         "comma-separated")
    if isinstance(dpi, bool) or not isinstance(dpi, (int, np.integer)) or not 10 <= dpi <= 2400:
        raise ValueError(f"dpi {dpi!r}: must be an integer in [10, 2400]")
    return formats, int(dpi)


@contextlib.contextmanager
def figure_output(formats=("png",), dpi: int = DEFAULT_DPI):
    """Within the block, :func:`save_figure` writes each figure in every format of ``formats``
    (see :func:`check_figure_output`) at ``dpi`` dots per inch (the pixel size of PNG; SVG and
    PDF are vector formats)."""
    formats, dpi = check_figure_output(formats, dpi)
    before = dict(_output)
    _output.update(formats=formats, dpi=dpi)
    try:
        yield
    finally:
        _output.update(before)


def save_figure(fig, path) -> list[str]:
    """Lay out ``fig`` (tight layout unless it has its own layout engine), write it at ``path``
    with the suffix of each format of :func:`figure_output` (``path``'s own suffix replaced)
    and close it; returns the names of the files written."""
    import matplotlib.pyplot as plt

    engine = fig.get_layout_engine()
    if engine is None or type(engine).__name__ in ("PlaceHolderLayoutEngine", "TightLayoutEngine"):
        fig.tight_layout()
    path = Path(path)
    names = []
    for fmt in _output["formats"]:
        target = path.with_suffix(f".{fmt}")
        fig.savefig(target, dpi=_output["dpi"], format=fmt)
        names.append(target.name)
    plt.close(fig)
    return names


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


def _data_areas(ax, renderer) -> np.ndarray:
    """(k, 4) boxes [x0, y0, x1, y1] in display coordinates [px] of the filled data areas of
    ``ax`` as drawn (clipped to the axes): bars and histogram bins (rectangles in data
    coordinates; an ``axvspan`` is not one), every unmasked cell of a colour mesh
    (``pcolormesh``) and every image (``imshow``)."""
    from matplotlib.collections import QuadMesh
    from matplotlib.image import AxesImage
    from matplotlib.patches import Rectangle

    boxes = []
    for patch in ax.patches:
        if isinstance(patch, Rectangle) and patch.get_visible() and patch.get_data_transform() is ax.transData:
            b = patch.get_window_extent(renderer)
            boxes.append([[b.x0, b.y0, b.x1, b.y1]])
    for coll in ax.collections:
        if isinstance(coll, QuadMesh) and coll.get_visible():
            xy = np.asarray(coll.get_coordinates(), dtype=float)           # (rows + 1, columns + 1, 2)
            xy = coll.get_transform().transform(xy.reshape(-1, 2)).reshape(xy.shape)
            corners = np.stack([xy[:-1, :-1], xy[:-1, 1:], xy[1:, :-1], xy[1:, 1:]])   # (4, rows, columns, 2)
            cells = np.concatenate([corners.min(axis=0), corners.max(axis=0)], axis=-1).reshape(-1, 4)
            values = coll.get_array()
            if values is not None and np.ma.getmaskarray(values).size == len(cells):
                cells = cells[~np.ma.getmaskarray(values).ravel()]
            boxes.append(cells)
    for image in ax.images:
        if isinstance(image, AxesImage) and image.get_visible():
            b = image.get_window_extent(renderer)
            boxes.append([[b.x0, b.y0, b.x1, b.y1]])
    if not boxes:
        return np.zeros((0, 4))
    out = np.concatenate([np.asarray(b, dtype=float) for b in boxes])
    a = ax.bbox
    return np.column_stack([np.maximum(out[:, 0], a.x0), np.maximum(out[:, 1], a.y0),
                            np.minimum(out[:, 2], a.x1), np.minimum(out[:, 3], a.y1)])


def legend_covers(ax, legend=None) -> int:
    """Number of data points of ``ax`` (line vertices, markers, scatter points, with their
    marker size) and of its filled data areas (bars, histogram bins, colour-map cells, images;
    each one that the legend overlaps by more than a pixel both ways) that lie under its legend
    (0: the legend hides nothing)."""
    legend = legend if legend is not None else ax.get_legend()
    if legend is None:
        return 0
    renderer = ax.figure.canvas.get_renderer()
    box = legend.get_window_extent(renderer)
    inside = 0
    for xy, r in _data_points(ax):
        inside += int(np.sum((xy[:, 0] >= box.x0 - r) & (xy[:, 0] <= box.x1 + r)
                             & (xy[:, 1] >= box.y0 - r) & (xy[:, 1] <= box.y1 + r)))
    areas = _data_areas(ax, renderer)
    overlap_x = np.minimum(areas[:, 2], box.x1) - np.maximum(areas[:, 0], box.x0)
    overlap_y = np.minimum(areas[:, 3], box.y1) - np.maximum(areas[:, 1], box.y0)
    inside += int(np.sum((overlap_x > 1.0) & (overlap_y > 1.0)))
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


def plain_log_ticks(axis) -> None:
    """Ticks of a logarithmic ``axis`` (``ax.xaxis`` or ``ax.yaxis``) at 1, 2, 5 per decade
    (labelled at the powers of ten only when the axis spans more than three decades), written as
    plain numbers ('0.5', '2', '10', not '5 x 10^-1'), no minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    def label(value, _):
        low, high = sorted(axis.get_view_interval())
        mantissa = value / 10.0 ** np.floor(np.log10(value) + 1e-9)
        if low > 0 and high / low > 1e3 and not np.isclose(mantissa, 1.0):
            return ""
        return f"{value:g}"
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(label))
    axis.set_minor_formatter(NullFormatter())


def reference_level(ax, value: float, label: str, unit: str = "mm", min_share: float = 1 / 3) -> None:
    """A damper-free reference level ``value`` (in the axes' y units) on ``ax``: a dashed
    horizontal line in the palette's UNDAMPED colour when each curve already drawn (a line of two
    or more points; markers alone do not count) keeps at least ``min_share`` of the y range with it; else (it would flatten them) no line, and a legend
    entry that gives the value and says it lies above the axes. Call after the series, before
    the legend."""
    from . import palette

    series = [np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()       # curves, not markers
              if line.get_transform() is ax.transData and line.get_gid() != "reference"
              and line.get_linestyle() not in ("None", "", " ")]
    series = [v[np.isfinite(v)] for v in series if np.sum(np.isfinite(v)) >= 2]
    text = f"{label} {value:.3g} {unit}"
    if series:
        low, high = min(min(v.min() for v in series), value), max(max(v.max() for v in series), value)
    if series and min(np.ptp(v) for v in series) < min_share * (high - low):
        ax.plot([], [], ls="--", lw=1, color=palette.UNDAMPED, label=f"{text} (above the axes)")
        return
    ax.axhline(value, ls="--", lw=1, color=palette.UNDAMPED, label=text, gid="reference")
