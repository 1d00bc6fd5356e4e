"""Checks that a matplotlib figure can go on a slide, for the tests of every figure bladedamp draws.

:func:`figure_problems` draws a figure with the Agg renderer and lists what breaks one of these
rules (:func:`check_figure` asserts the list is empty):

* units: every axis that shows tick labels (x and y, twin axes and colour bars too) has a label
  with its unit in brackets, e.g. "frequency [Hz]", "mass [g]", "reduction [%]", "engine order [-]";
* no overlap: no two drawn text boxes (tick labels, axis labels, offset texts, titles, annotations,
  figure texts, each legend as one box) overlap by more than :data:`OVERLAP_PX` in both
  directions, and every text box lies inside the figure (nothing cut at an edge);
* visible series: every plotted series (a line or scatter in data coordinates; lines drawn in
  axes coordinates such as ``axhline`` are references, not series, and a line without data is a
  legend entry's proxy) has a finite point inside the
  axes' limits; a series of two or more points spans at least :data:`MIN_SPAN` of the axes'
  height (not a flat line; markers without a line, such as the points of a search, and a
  reference drawn with ``gid="reference"``, such as the damper-free level over engine order,
  may be flat) and no point whose x is within the limits lies above or
  below the y limits (not clipped);
* legends: no legend hides a data point or a filled data area (bar, histogram bin, colour-map cell,
  image) of an axes it lies over (twin axes included);
* title: the figure's titles (suptitle, every axes' titles) together name the design.

The boxes are those of the texts actually drawn: :meth:`matplotlib.text.Text.draw` is watched
while the figure draws, so tick labels outside the view and empty texts do not count.
"""
from __future__ import annotations

import re
from unittest import mock

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PathCollection
from matplotlib.text import Text

UNIT = re.compile(r"\[[^\[\]]+\]")
OVERLAP_PX = 1.0       # boxes touching within antialiasing are not an overlap
MIN_SPAN = 0.2         # a series spans at least a fifth of its axes' height
EDGE_PX = 1.0          # a text box may reach this far past the figure's edge (antialiasing)


def drawn_texts(fig):
    """Draw ``fig`` with Agg; returns (renderer, [visible non-empty Text drawn])."""
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    drawn = []
    original = Text.draw

    def watch(self, renderer):
        original(self, renderer)
        if self.get_visible() and self.get_text().strip():
            drawn.append(self)
    with mock.patch.object(Text, "draw", watch):
        fig.canvas.draw()
    return fig.canvas.get_renderer(), drawn


def _axes_of(fig):
    return [ax for ax in fig.axes if ax.get_visible() and ax.axison]


def unit_problems(fig, drawn) -> list[str]:
    """Axes whose ticked axis has no '[unit]' in its label."""
    ticked = {id(t) for t in drawn}
    out = []
    for k, ax in enumerate(_axes_of(fig)):
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if not axis.get_visible():
                continue
            shows = any(id(t) in ticked for t in axis.get_ticklabels(which="both"))
            label = axis.get_label().get_text() if axis.get_label().get_visible() else ""
            if shows and not UNIT.search(label):
                out.append(f"axes {k} ({ax.get_title() or ax.get_label() or 'untitled'}): {name} label "
                           f"{label!r} has no unit in brackets")
    return out


def text_boxes(fig, renderer, drawn) -> list[tuple[str, object]]:
    """[(what, Bbox in pixels)] of every drawn text, each legend as one box."""
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)
    inside_legend = {id(t) for lg in legends for t in [*lg.get_texts(), lg.get_title()]}
    # Text's own box: an annotation's arrow is not text (Annotation.get_window_extent includes it)
    boxes = [(f"text {t.get_text()!r}", Text.get_window_extent(t, renderer)) for t in drawn if id(t) not in inside_legend]
    boxes += [(f"legend ({', '.join(t.get_text() for t in lg.get_texts())})", lg.get_window_extent(renderer))
              for lg in legends if lg.get_visible()]
    return boxes


def overlap_problems(fig, renderer, drawn) -> list[str]:
    """Pairs of overlapping text boxes, and text boxes cut by the figure's edge."""
    boxes = text_boxes(fig, renderer, drawn)
    out = []
    for i, (a, ba) in enumerate(boxes):
        for b, bb in boxes[i + 1:]:
            dx = min(ba.x1, bb.x1) - max(ba.x0, bb.x0)
            dy = min(ba.y1, bb.y1) - max(ba.y0, bb.y0)
            if dx > OVERLAP_PX and dy > OVERLAP_PX:
                out.append(f"{a} overlaps {b} ({dx:.0f} x {dy:.0f} px)")
    W, H = fig.bbox.width, fig.bbox.height
    for a, box in boxes:
        if box.x0 < -EDGE_PX or box.y0 < -EDGE_PX or box.x1 > W + EDGE_PX or box.y1 > H + EDGE_PX:
            out.append(f"{a} is cut by the figure's edge")
    return out


def _series(ax):
    """[(name, xy (k, 2) data, may be flat)] of the lines and scatters of ``ax`` drawn in data coordinates."""
    out = []
    for line in ax.get_lines():
        if line.get_visible() and line.get_transform() is ax.transData:
            flat_ok = line.get_gid() == "reference" or line.get_linestyle() in ("None", "", " ")
            out.append((f"line {line.get_label()!r}", np.asarray(line.get_xydata(), dtype=float), flat_ok))
    for coll in ax.collections:
        if isinstance(coll, PathCollection) and coll.get_visible() and coll.get_offset_transform() is ax.transData:
            out.append((f"scatter {coll.get_label()!r}", np.asarray(coll.get_offsets(), dtype=float),
                        coll.get_gid() == "reference"))
    return out


def series_problems(fig) -> list[str]:
    """Series outside the limits, flat (less than MIN_SPAN of the height) or clipped."""
    out = []
    for k, ax in enumerate(_axes_of(fig)):
        where = f"axes {k} ({ax.get_title() or 'untitled'})"
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        to_axes = ax.transData + ax.transAxes.inverted()
        for name, xy, flat_ok in _series(ax):
            if not len(xy):
                continue            # a legend entry's proxy, no data
            xy = xy[np.all(np.isfinite(xy), axis=1)]
            if ax.get_xscale() == "log":
                xy = xy[xy[:, 0] > 0]
            if ax.get_yscale() == "log":
                xy = xy[xy[:, 1] > 0]
            if not len(xy):
                out.append(f"{where}: {name} has no finite point")
                continue
            in_x = (xy[:, 0] >= x0) & (xy[:, 0] <= x1)
            in_y = (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
            if not np.any(in_x & in_y):
                out.append(f"{where}: {name} lies entirely outside the limits")
                continue
            if np.any(in_x & ~in_y):
                out.append(f"{where}: {name} is clipped ({int(np.sum(in_x & ~in_y))} points above or below "
                           f"the y limits {y0:.4g}-{y1:.4g})")
            shown = to_axes.transform(xy[in_x & in_y])
            if len(np.unique(xy, axis=0)) >= 2 and np.ptp(shown[:, 1]) < MIN_SPAN and not flat_ok:
                out.append(f"{where}: {name} spans {100 * np.ptp(shown[:, 1]):.0f} % of the axes' height "
                           f"(at least {100 * MIN_SPAN:.0f} %): flat")
    return out


def legend_problems(fig) -> list[str]:
    """Legends that hide data points or areas of any axes they lie over (twin axes included), counted
    by :func:`bladedamp.plotting.legend_covers`."""
    from bladedamp.plotting import legend_covers

    out = []
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None or not legend.get_visible():
            continue
        box = legend.get_window_extent()
        for other in _axes_of(fig):
            if other.bbox.overlaps(box):
                hidden = legend_covers(other, legend)
                if hidden:
                    out.append(f"the legend ({', '.join(t.get_text() for t in legend.get_texts())}) hides "
                               f"{hidden} data points or areas of axes {other.get_title() or other.get_ylabel()!r}")
    return out


def titles(fig) -> list[str]:
    """The suptitle and every axes' titles (left, centre, right) of ``fig``."""
    out = [fig.get_suptitle()] if fig.get_suptitle() else []
    for ax in fig.axes:
        out += [ax.get_title(loc) for loc in ("left", "center", "right") if ax.get_title(loc)]
    return out


def title_problems(fig, design: str) -> list[str]:
    if any(design.lower() in t.lower() for t in titles(fig)):
        return []
    return [f"no title names the design {design!r} (titles: {titles(fig)})"]


def figure_problems(fig, design: str | None) -> list[str]:
    """Every broken rule of the module's docstring, one line each; ``design``: the name a title
    must contain (None: the figure is part of a caller's, no title rule)."""
    renderer, drawn = drawn_texts(fig)
    out = unit_problems(fig, drawn) + overlap_problems(fig, renderer, drawn) + series_problems(fig) \
        + legend_problems(fig)
    if design is not None:
        out += title_problems(fig, design)
    return out


def check_figure(fig, design: str | None) -> None:
    """AssertionError listing every broken rule of ``fig`` (see :func:`figure_problems`)."""
    problems = figure_problems(fig, design)
    assert not problems, "figure breaks the slide rules:\n  " + "\n  ".join(problems)
