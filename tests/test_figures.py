"""Every figure the product draws outside the notebooks and the 3D view, checked by
tests/figure_checks.py (units, no overlapping or cut text, every series visible, a title naming
the design): the result classes' ``.plot()`` and the report's figures, on small results built
from closed forms (no solve), and the figure helpers of bladedamp.plotting."""
import dataclasses
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from figure_checks import check_figure  # noqa: E402

from bladedamp import report  # noqa: E402
from bladedamp.plotting import DEFAULT_DPI, figure_output, save_figure  # noqa: E402
from bladedamp.studies.design import ContactState, DesignMap, EngineOrderSweep, LiftoffMap, PlatformAngleStudy  # noqa: E402
from bladedamp.studies.mass import MassOptimum, MassSweep  # noqa: E402
from bladedamp.studies.mistuning import MonteCarloResult  # noqa: E402

UNDAMPED = 1.7e-3


def valley(mass, best=1e-3, depth=0.71):
    """A resonance amplitude [m] over damper mass [kg] with its minimum at ``best``: the
    undamped peak far from it on both sides (a light damper slips freely, a heavy one sticks)."""
    return UNDAMPED * (1 - depth * np.exp(-(np.log10(mass / best) / 0.8) ** 2))


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def one(draw, figsize=(6.5, 4.5)):
    fig, ax = plt.subplots(figsize=figsize)
    draw(ax)
    fig.tight_layout()
    return fig, ax


# ---------------------------------------------------------------------------------------
# the result classes' plot()
# ---------------------------------------------------------------------------------------
def mass_sweep(kind="cylinder", best=1e-3):
    m = np.logspace(-5, 0, 12)
    return MassSweep(m, valley(m, best), np.full(12, 95.0), kind, UNDAMPED)


def test_mass_sweep_plot():
    fig, _ = one(mass_sweep().plot)
    check_figure(fig, None)


def engine_order_sweep():
    eo = np.arange(0, 9)
    mass = np.array([np.nan, 1.0, 1.5, 2.2, 3.0, 4.0, 5.2, 6.5, 8.0]) * 1e-3
    undamped = np.full(9, UNDAMPED)
    peak = np.where(np.isfinite(mass), 0.3 * UNDAMPED + 0.05e-3 * eo, UNDAMPED)
    return EngineOrderSweep("cylinder", eo, mass, peak, undamped, 1 - peak / undamped, certified=np.ones(9, bool))


def test_engine_order_sweep_plot():
    fig, _ = one(engine_order_sweep().plot)
    check_figure(fig, None)


def platform_angle_study():
    g = np.array([15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0])
    return PlatformAngleStudy("cylinder", 35.0, 1e-3, g, 1e-3 * (1 + g / 90), 1e-3 * (0.3 + 0.004 * g),
                              1e-3 * (0.35 + 0.006 * g), UNDAMPED)


def test_platform_angle_plot():
    fig, _ = one(platform_angle_study().plot)
    check_figure(fig, None)


def contact_state(angle=35.0):
    w = np.array([1.8 * np.exp(-0.6j), 0.6 * np.exp(-0.2j) * angle / 35])
    f = np.array([0.9 * np.exp(-0.3j), 0.55 * np.exp(-0.1j)])
    return ContactState(w, f, 1e-6 * w, 0.1 * f, np.array([1.0, 1.0]), np.array([1e5, 1e5]),
                        np.array([0.5, 0.5]), 95.3, 0.5e-3)


def test_contact_state_plot():
    fig, _ = one(contact_state().plot, figsize=(5, 5))
    check_figure(fig, None)


def liftoff_map():
    xi, eta = np.meshgrid([-0.4, -0.2, 0.0, 0.2, 0.4], [-0.4, -0.2, 0.0, 0.2, 0.4])
    xi, eta = xi.ravel(), eta.ravel()
    r = np.vstack([0.3 + 2.5 * np.abs(xi), 0.3 + 2.5 * np.abs(xi)])
    P = xi.size
    return LiftoffMap(xi, eta, r, r, np.zeros((2, P)), np.ones((2, P)), r, 95.5, 3e-4, 64)


def test_liftoff_plot():
    fig, _ = one(liftoff_map().plot)
    check_figure(fig, None)


def design_map(kind="cylinder", height=None):
    masses = np.array([0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0]) * 1e-3
    gammas = np.array([15.0, 35.0, 55.0, 85.0])
    peaks = 1e-3 * (0.5 + 0.1 * np.log(masses / 5e-4)[None, :] ** 2 + 0.002 * (85 - gammas)[:, None])
    return DesignMap(kind, height, masses, gammas, peaks, UNDAMPED)


def test_design_map_plot():
    fig, _ = one(design_map().plot)
    check_figure(fig, None)


def monte_carlo():
    rng = np.random.default_rng(0)
    kappa = 1 + 0.02 * rng.standard_normal((40, 16))
    peaks = 0.5e-3 * (1 + 0.15 * rng.random((40, 16)))
    return MonteCarloResult(kappa, peaks, np.full((40, 16), 95.0), 0.5e-3, [""] * 40, {"std": 0.02, "seed": 0})


def test_monte_carlo_plot():
    fig, _ = one(monte_carlo().plot)
    check_figure(fig, None)



def test_peak_sensitivities_plot():
    """The bars of the peak's relative sensitivities (built by hand: no solve), the categorical
    parameter axis labelled too; the title names the design once the caller adds it."""
    from bladedamp.response import PeakSensitivities

    peak = PeakSensitivities(("damper.mass_g", "damper.friction_coefficient", "disk.excitation_n_nm[0]"),
                             ("g", "-", "N or N m"), np.array([1.0, 0.3, 0.1]), 4.9e-4, 95.3, 0,
                             np.array([3.5e-6, 6.9e-6, 4.8e-3]), np.array([0.44, 1.6, -4.6]))
    fig = peak.plot()
    fig.suptitle("reference disk, 1 g cylinder")
    check_figure(fig, "reference disk")

# ---------------------------------------------------------------------------------------
# the report's figures (bladedamp reproduce), written to files and checked as saved
# ---------------------------------------------------------------------------------------
def test_reproduce_study_figures(tmp_path, saved_figures):
    sweeps = {"cylinder": mass_sweep(), "wedge": mass_sweep("wedge", 0.3e-3)}
    optima = {k: MassOptimum(best, float(valley(np.array(best), best)), UNDAMPED, 20)
              for k, best in (("cylinder", 1e-3), ("wedge", 0.3e-3))}
    report.plot_mass_optimisation(sweeps, optima, tmp_path / "fig6.png")
    report.plot_engine_orders({"cylinder": engine_order_sweep(),
                               "wedge": dataclasses.replace(engine_order_sweep(), kind="wedge")},
                              tmp_path / "fig7_8.png")
    report.plot_platform_angles(platform_angle_study(), tmp_path / "fig10.png")
    report.plot_contact_states({35.0: contact_state(), 85.0: contact_state(85.0)}, tmp_path / "fig11.png")
    report.plot_liftoff(liftoff_map(), tmp_path / "fig9.png")
    report.plot_design_maps([design_map(), design_map("wedge", 1e-3), design_map("wedge", 4e-3)],
                            tmp_path / "design_map.png")
    saved_figures.check("reference")


def test_design_command_study_figures(tmp_path, saved_figures):
    from bladedamp.design import reference_design

    design = reference_design()
    report.eo_sweep_outputs(tmp_path, design, engine_order_sweep())
    report.montecarlo_outputs(tmp_path, design, monte_carlo(), ["montecarlo.npz"])
    saved_figures.check("reference design")


# ---------------------------------------------------------------------------------------
# figure output: formats and resolution
# ---------------------------------------------------------------------------------------
def test_save_figure_writes_each_format_at_the_dpi(tmp_path):
    import matplotlib.image

    fig, _ = one(mass_sweep().plot, figsize=(4, 3))
    with figure_output("png,svg,pdf", 50):
        assert save_figure(fig, tmp_path / "a.png") == ["a.png", "a.svg", "a.pdf"]
    assert matplotlib.image.imread(tmp_path / "a.png").shape[:2] == (150, 200)
    assert (tmp_path / "a.pdf").read_bytes().startswith(b"%PDF") and b"<svg" in (tmp_path / "a.svg").read_bytes()
    fig, _ = one(mass_sweep().plot, figsize=(4, 3))       # outside the block: PNG at the default dpi again
    assert save_figure(fig, tmp_path / "b.png") == ["b.png"]
    assert matplotlib.image.imread(tmp_path / "b.png").shape[:2] == (3 * DEFAULT_DPI, 4 * DEFAULT_DPI)


@pytest.mark.parametrize("formats, dpi, needle", [("png,gif", 100, "'gif'"), ("", 100, "empty"),
                                                  ("png", 0, "dpi 0"), ("png", 99.5, "dpi 99.5")])
def test_figure_output_rejects_a_bad_format_or_dpi(formats, dpi, needle):
    with pytest.raises(ValueError, match=needle):
        with figure_output(formats, dpi):
            pass


# ---------------------------------------------------------------------------------------
# figures of frequency responses: one small solve of the reference disk (one harmonic)
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def responses():
    """(damped 1 g cylinder, damper-free) responses of the reference disk, 92-99 Hz, one harmonic."""
    from bladedamp.reference import reference_disk

    options = dict(harmonics=(1,), max_step=0.05, estimate_harmonic_error=False)
    return (reference_disk("cylinder", 1e-3).frequency_response(92.0, 99.0, **options),
            reference_disk(None).frequency_response(92.0, 99.0, **options))


def test_disk_response_plot(responses):
    damped, free = responses
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    free.plot(ax=ax)
    damped.plot(ax=ax)
    fig.tight_layout()
    check_figure(fig, None)


def test_frequency_response_plot_names_its_unit(responses):
    from bladedamp.response import FrequencyResponse

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    FrequencyResponse.plot(responses[0], ax=ax, scale=1e3, unit="mm")
    fig.tight_layout()
    check_figure(fig, None)
    assert ax.get_ylabel().endswith("[mm]")


def test_reproduce_response_figures(responses, tmp_path, saved_figures):
    damped, free = responses
    report.plot_four_modes([(name, 0, free, damped) for name, *_ in report.PAPER["table1"]], tmp_path / "fig4.png")
    report.plot_mass_variation(free, [(1e-3, damped)], tmp_path / "fig5.png")
    saved_figures.check("reference")


def test_backbone_design_plot():
    from bladedamp.studies.backbone import BackboneDesign

    m = np.logspace(-4, -2, 9)
    levels = np.array([0.05, 0.1, 0.2])
    best = 1e-3 * levels / 0.1                                         # the optimum grows with the level
    peaks = np.stack([valley(m, b) * f / 0.1 for b, f in zip(best, levels)], axis=1)
    undamped = UNDAMPED * levels / 0.1
    study = BackboneDesign("cylinder", m, levels, peaks, np.full_like(peaks, 95.0), best,
                           valley(best, best) * levels / 0.1, undamped, np.stack([best / 2, best * 2], axis=1), m)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    study.plot(axes=axes)
    fig.tight_layout()
    check_figure(fig, None)


@pytest.fixture(scope="module")
def mistuned():
    """(mistuned 4-blade response, its tuned response), reference disk with the 1 g cylinder, one harmonic."""
    from bladedamp.mistuned import MistunedDisk
    from bladedamp.reference import reference_disk

    tuned = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    options = dict(harmonics=(1,), max_step=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the one-harmonic accuracy is not what is tested here
        r = MistunedDisk.from_tuned(tuned, [1.03, 0.97, 1.02, 1.0]).frequency_response(97.0, 106.0, **options)
        return r, tuned.frequency_response(97.0, 106.0, **options)


def test_mistuned_response_plot(mistuned):
    r, tuned = mistuned
    fig, ax = plt.subplots(figsize=(7, 4.5))
    r.plot(ax=ax, tuned=tuned, title="4 blades")
    fig.tight_layout()
    check_figure(fig, None)


def test_mistuning_cases_figure(mistuned, tmp_path, saved_figures):
    from bladedamp.studies.mistuning import MistuningCase, plot_cases

    r, tuned = mistuned
    kappa = np.array([1.03, 0.97, 1.02, 1.0])
    cases = {key: MistuningCase(key, 1e-3, kappa, r, float(tuned.peak_amplitude), tuned)
             for key in ("random_1g", "reordered_1g", "alternating_1g", "random_5g", "reordered_5g")}
    plot_cases(cases, tmp_path / "fig13_17.png")
    saved_figures.check("reference")


def test_stability_and_backbone_figure(tmp_path, saved_figures):
    from bladedamp.hbm.nonlinear_modes import nonlinear_mode
    from bladedamp.hbm.stability import with_stability
    from bladedamp.reference import reference_disk

    disk = reference_disk("cylinder", 1e-3)
    r = disk.frequency_response(90.0, 100.0, harmonics=(1,), max_step=0.05, estimate_harmonic_error=False)
    report.plot_stability_backbones({"cylinder": with_stability(disk, r)}, {},
                                    {"cylinder": nonlinear_mode(disk, harmonics=(1,))}, tmp_path / "stability.png")
    saved_figures.check("reference")


def test_optimize_figure_with_platform_angles_and_contact_heights(tmp_path, saved_figures):
    from bladedamp.design import reference_design

    grid = np.logspace(-5, np.log10(2e-2), 15)
    search = np.array([0.8e-3, 1.0e-3, 1.2e-3])
    evaluated = np.sort(np.concatenate([grid, search]))
    optimum = MassOptimum(1e-3, float(valley(np.array(1e-3))), UNDAMPED, 18, grid_mass=grid,
                          grid_peak_amplitude=valley(grid), bracket=(0.6e-3, 1.6e-3), evaluated_mass=evaluated,
                          evaluated_peak_amplitude=valley(evaluated))
    heights = [(h, dataclasses.replace(optimum, peak_amplitude=optimum.peak_amplitude * (1 + 200 * h)))
               for h in (1e-3, 2e-3, 4e-3)]
    summary = report.optimize_outputs(tmp_path, reference_design(), optimum, platform_angle_study(), heights)
    saved_figures.check("reference design")
    fig = saved_figures["optimize"][2]
    curve = next(line for line in fig.axes[0].get_lines() if "every mass evaluated" in line.get_label())
    np.testing.assert_allclose(curve.get_xdata(), 1e3 * evaluated)             # every mass, the search's too
    assert summary["mass"]["optimal_mass_g"] == pytest.approx(1.0)


def test_reference_level_is_a_line_unless_it_would_flatten_a_curve():
    from bladedamp.plotting import reference_level

    fig, ax = plt.subplots()
    ax.plot([1.0, 2.0, 3.0], [0.5, 1.0, 1.5])
    ax.plot(2.0, 0.5, "*")                                  # a marker alone never decides
    reference_level(ax, 1.7, "no damper")
    assert [line.get_label() for line in ax.get_lines()][-1] == "no damper 1.7 mm"
    fig, ax = plt.subplots()
    ax.plot([1.0, 2.0, 3.0], [0.50, 0.52, 0.55])
    reference_level(ax, 1.7, "no damper")
    last = ax.get_lines()[-1]
    assert last.get_label() == "no damper 1.7 mm (above the axes)" and len(last.get_xdata()) == 0
    assert ax.get_ylim()[1] < 1.0
