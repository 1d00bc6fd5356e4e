"""The figure checker of tests/figure_checks.py: it passes a figure fit for a slide and reports
each rule broken by a figure built to break it (so the checks of the product's figures can fail)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from figure_checks import check_figure, figure_problems  # noqa: E402

F = np.linspace(90.0, 100.0, 200)
PEAK = 1.7 / np.sqrt(1 + ((F - 95.0) / 0.5) ** 2)


def good(design="rotor A"):
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(F, PEAK, label="damped")
    ax.axhline(1.0, ls="--", color="k", label="reference")       # axes-coordinate reference: no series
    ax.set(xlabel="frequency [Hz]", ylabel="tip amplitude [mm]", title=f"{design}: frequency response")
    twin = ax.twinx()
    twin.plot(F, 100 * PEAK / PEAK.max(), color="C1")
    twin.set_ylabel("relative amplitude [%]")
    ax.legend(loc="upper left")
    fig.tight_layout()
    return fig, ax, twin


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_a_figure_fit_for_a_slide_passes():
    fig, _, _ = good()
    assert figure_problems(fig, "rotor A") == []
    check_figure(fig, "rotor A")


@pytest.mark.parametrize("which", ["x", "y", "twin"])
def test_an_axis_without_unit_fails(which):
    fig, ax, twin = good()
    {"x": ax.set_xlabel, "y": ax.set_ylabel, "twin": twin.set_ylabel}[which]("amplitude")
    problems = figure_problems(fig, "rotor A")
    assert len(problems) == 1 and "no unit in brackets" in problems[0], problems
    with pytest.raises(AssertionError, match="no unit"):
        check_figure(fig, "rotor A")


def test_an_unlabelled_colour_bar_fails():
    fig, ax = plt.subplots()
    mesh = ax.pcolormesh(np.arange(4.0), np.arange(3.0), np.ones((2, 3)))
    ax.set(xlabel="mass [g]", ylabel="angle [deg]", title="rotor A")
    bar = fig.colorbar(mesh, ax=ax)
    assert any("no unit" in p for p in figure_problems(fig, "rotor A"))
    bar.set_label("peak [mm]")
    assert figure_problems(fig, "rotor A") == []


def test_overlapping_texts_fail():
    fig, ax, _ = good()
    ax.annotate("peak 1.7 mm at 95 Hz", (95.0, 1.7), xytext=(95.0, 1.7), ha="center")
    ax.text(95.0, 1.7, "a second note on the first", ha="center")
    problems = figure_problems(fig, "rotor A")
    assert any("overlaps" in p and "peak 1.7 mm" in p for p in problems), problems


def test_crowded_tick_labels_fail():
    fig, ax = plt.subplots(figsize=(2.5, 2.5))
    ax.plot(F, PEAK)
    ax.set_xticks(F[::20], [f"{f:.6f} Hz" for f in F[::20]])
    ax.set(xlabel="frequency [Hz]", ylabel="amplitude [mm]", title="rotor A")
    assert any("overlaps" in p for p in figure_problems(fig, "rotor A"))


def test_a_label_cut_at_the_edge_fails():
    fig, ax, _ = good()
    ax.set_title("rotor A: " + "a title far too long for its figure " * 3)
    assert any("cut by the figure's edge" in p for p in figure_problems(fig, "rotor A"))


def test_a_legend_over_a_label_fails():
    fig, ax, _ = good()
    ax.legend(loc="upper left", bbox_to_anchor=(-0.2, 1.1))     # over the y tick labels and the title
    assert any(p.startswith("legend") or "legend (" in p for p in figure_problems(fig, "rotor A"))


def test_a_flat_series_fails():
    fig, ax, _ = good()
    ax.plot(F, 1e-3 * PEAK, label="flattened by the other curve")
    problems = figure_problems(fig, "rotor A")
    assert len(problems) == 1 and "flat" in problems[0] and "flattened" in problems[0], problems


def test_a_series_outside_the_limits_fails():
    fig, ax, _ = good()
    ax.plot(F + 50.0, PEAK, label="elsewhere")
    ax.set_xlim(90.0, 100.0)
    problems = figure_problems(fig, "rotor A")
    assert len(problems) == 1 and "entirely outside" in problems[0], problems


def test_a_clipped_peak_fails():
    fig, ax, _ = good()
    ax.set_ylim(0.0, 1.2)
    problems = figure_problems(fig, "rotor A")
    assert any("clipped" in p for p in problems), problems


def test_a_scatter_outside_the_limits_fails():
    fig, ax, _ = good()
    ax.scatter([200.0, 210.0], [1.0, 1.5], label="far")
    ax.set_xlim(90.0, 100.0)
    assert any("scatter 'far'" in p and "outside" in p for p in figure_problems(fig, "rotor A"))


def test_a_title_without_the_design_fails():
    fig, _, _ = good(design="rotor B")
    problems = figure_problems(fig, "rotor A")
    assert len(problems) == 1 and "names the design" in problems[0], problems
    fig.suptitle("rotor A")
    fig.tight_layout()                          # room for the suptitle (else it overlaps the title)
    assert figure_problems(fig, "rotor A") == []


def test_log_axes_and_a_single_marker_pass():
    fig, ax = plt.subplots(figsize=(6, 4))
    m = np.logspace(-2, 1, 12)
    ax.semilogx(m, 0.5 + np.log10(m) ** 2, marker="o")
    ax.plot(1.0, 0.5, "*", ms=12)
    ax.set(xlabel="damper mass [g]", ylabel="peak [mm]", title="rotor A")
    fig.tight_layout()
    assert figure_problems(fig, "rotor A") == []


def test_a_flat_reference_or_markers_may_be_flat_but_must_be_inside():
    fig, ax, _ = good()
    ax.plot(F, np.full_like(F, 1.0), ls="--", gid="reference", label="no damper, over frequency")
    ax.plot([94.0, 95.0, 96.0], [1.5, 1.51, 1.5], "x", label="search points")
    assert figure_problems(fig, "rotor A") == []
    ax.plot(F, np.full_like(F, 1.0), ls="--", label="the same without its gid")
    assert any("without its gid" in p and "flat" in p for p in figure_problems(fig, "rotor A"))
    ax.plot([120.0], [1.0], "x", label="a marker outside")
    ax.set_xlim(90.0, 100.0)
    assert any("a marker outside" in p and "outside" in p for p in figure_problems(fig, "rotor A"))


def test_a_legend_over_the_twin_axes_points_fails():
    fig, ax, twin = good()
    twin.plot([90.5, 91.0], [95.0, 96.0], "s", label="under the legend")     # top left, where the legend is
    problems = figure_problems(fig, "rotor A")
    assert any("hides" in p for p in problems), problems


def bar_and_map_figure(legend_outside: bool):
    """Stacked bars filling the height (the shares of a period) beside a colour map, each with a
    legend inside its axes or beside it."""
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9, 3.5), constrained_layout=True)
    x = np.arange(5)
    ax.bar(x, np.full(5, 0.4), label="stick")
    ax.bar(x, np.full(5, 0.6), bottom=0.4, label="slip")
    ax.set(xlabel="point [-]", ylabel="share of the period [-]", title="rotor A: contact points")
    ax2.pcolormesh(np.arange(9), np.arange(6), np.arange(40).reshape(5, 8) % 3, vmin=0, vmax=2)
    ax2.plot([], [], "s", label="a key entry")        # a proxy of the map's key: no data of its own
    ax2.set(xlabel="phase [deg]", ylabel="point [-]", title="rotor A: state map")
    where = dict(loc="upper left", bbox_to_anchor=(1.02, 1.0)) if legend_outside else dict(loc="lower right")
    ax.legend(**where)
    ax2.legend(**where)
    return fig


def test_a_legend_over_bars_or_a_colour_map_fails_and_beside_them_passes():
    problems = figure_problems(bar_and_map_figure(legend_outside=False), "rotor A")
    assert any("(stick, slip) hides" in p and "contact points" in p for p in problems), problems
    assert any("(a key entry) hides" in p and "state map" in p for p in problems), problems
    assert figure_problems(bar_and_map_figure(legend_outside=True), "rotor A") == []


def test_a_legend_over_an_image_fails():
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.imshow(np.arange(16.0).reshape(4, 4), extent=(0, 4, 0, 4))
    ax.plot([], [], "s", label="a key entry")
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title="rotor A: an image")
    ax.legend(loc="center")
    assert any("(a key entry) hides 1 data points or areas" in p for p in figure_problems(fig, "rotor A"))
