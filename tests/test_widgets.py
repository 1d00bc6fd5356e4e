"""Slider callbacks of the notebooks (bladedamp.viz.widgets), called with values, no browser.

The reference values are closed forms (Jenkins element) or the library's own solvers
(continuation, ``contact_state``), which the warm-started callbacks must reproduce.
"""
import inspect
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import bladedamp as bd  # noqa: E402
from bladedamp.studies import contact_state, peak_response  # noqa: E402
from bladedamp.viz import widgets as W  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# ----- point contact ---------------------------------------------------------------------
def test_hysteresis_loop_area_is_the_closed_form_energy():
    k_t, slip, A = 1e4, 0.3, 1e-4             # slip amplitude 30 um, A = 3.3 of it
    d = W.hysteresis_loop(A, k_t, slip)
    exact = 4 * slip * (A - slip / k_t)
    assert d["energy_closed_form"] == pytest.approx(exact)
    assert d["energy"] == pytest.approx(exact, rel=1e-3)
    assert d["slip_work"] == pytest.approx(exact, rel=1e-3)
    assert np.abs(d["force"]).max() == pytest.approx(slip, rel=1e-9)   # Coulomb limit
    assert d["share"]["lift-off"] == 0 and 0 < d["share"]["slip"] < 1


def test_hysteresis_loop_sticks_below_the_slip_amplitude():
    d = W.hysteresis_loop(2e-5, 1e4, 0.3)     # k_T A = 0.2 N < mu N = 0.3 N
    assert d["share"]["stick"] == 1.0
    assert d["energy"] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(d["force"], 1e4 * d["u"], atol=1e-12)


def test_hysteresis_loop_with_normal_load_variation_lifts_off():
    d = W.hysteresis_loop(1e-4, 1e4, 0.3, normal_variation=1.3)
    assert d["share"]["lift-off"] > 0.1
    assert np.all(d["force"][d["state"] == 2] == 0)
    assert d["normal"].min() == 0.0
    assert d["energy"] == pytest.approx(d["slip_work"], rel=1e-3)   # loop area = slider work
    # the Coulomb limit follows the normal load
    assert np.all(np.abs(d["force"]) <= 0.3 * d["normal"] + 1e-12)


def test_hysteresis_figure_draws_the_loop():
    fig = W.hysteresis_figure(amplitude_mm=0.1, k_t_kn_per_m=10.0, slip_force_n=0.3)
    ax = fig.axes[0]
    x = np.concatenate([line.get_xdata() for line in ax.get_lines() if len(line.get_xdata()) > 2])
    assert x.max() == pytest.approx(0.1, rel=1e-6) and x.min() == pytest.approx(-0.1, rel=1e-2)
    assert "mJ" in ax.get_title()
    assert fig.loop["energy"] == pytest.approx(4 * 0.3 * (1e-4 - 0.3e-4), rel=1e-3)


def test_describing_function_matches_the_closed_form():
    k_t, slip = 1e4, 0.3
    A = slip / k_t * np.logspace(-1, 2, 25)
    d = W.describing_function(k_t, slip, A)
    np.testing.assert_allclose(d["k_eq"], d["k_eq_closed"], atol=1e-3 * k_t)
    np.testing.assert_allclose(d["d_eq"], d["d_eq_closed"], atol=1e-3 * k_t)
    stuck = A < slip / k_t
    np.testing.assert_allclose(d["k_eq"][stuck], k_t, rtol=1e-9)
    np.testing.assert_allclose(d["d_eq"][stuck], 0.0, atol=1e-9 * k_t)
    # largest damping at twice the slip amplitude: d_eq = k_T / pi
    x = np.array([2.0])
    assert W.closed_form_jenkins(k_t, slip, x * slip / k_t)[1][0] == pytest.approx(k_t / np.pi)
    with pytest.raises(ValueError):
        W.describing_function(k_t, slip, [0.0])


def test_describing_function_figure_data():
    fig = W.describing_function_figure(k_t_kn_per_m=10.0, slip_force_n=0.3, amplitude_mm=0.1)
    assert len(fig.axes) == 2
    d = fig.data
    np.testing.assert_allclose(d["energy"], d["energy_closed"], atol=1e-3 * d["energy_closed"].max())


def test_interactive_view_keeps_the_signature_and_returns_none():
    view = W.interactive_view(W.hysteresis_figure)
    assert list(inspect.signature(view).parameters) == list(inspect.signature(W.hysteresis_figure).parameters)
    assert view(amplitude_mm=0.05) is None


# ----- friction oscillator ---------------------------------------------------------------
def test_oscillator_hbm_matches_time_integration_and_balances_energy():
    d = W.oscillator_comparison(normal_load=3.0, forcing=2.0)
    assert d["frf"].success and np.all(d["time_converged"])
    np.testing.assert_allclose(d["hbm_at_time"], d["time_amplitude"], rtol=0.01)
    e = d["energy"]
    assert np.abs(e[:, 0] - e[:, 1] - e[:, 2]).max() <= 1e-6 * np.abs(e[:, 0]).max()
    # friction dissipates: the contact's work per cycle is never negative
    assert e[:, 2].min() >= -1e-9 * np.abs(e[:, 0]).max()


def test_oscillator_stuck_limit_is_linear():
    d = W.oscillator_comparison(normal_load=1000.0, forcing=2.0, time_frequencies_hz=())
    np.testing.assert_allclose(d["hbm"], d["stuck"], rtol=1e-6)


def test_oscillator_figure_memoised():
    fig = W.oscillator_figure(normal_load=3.0, forcing=2.0)
    assert fig.data is W.oscillator_comparison(3.0, 2.0)
    assert fig.axes[0].get_yscale() == "log"


# ----- reference disk ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def cache():
    return W.DiskFRFCache()


def test_disk_frf_is_the_library_response_and_memoised(cache):
    """The slider's FRF is TunedDisk.frequency_response's own branch (through peak_response, at the
    widget's coarser step): its peak within 0.1 % / 0.02 Hz of the studies' default step."""
    from bladedamp.disk import DiskResponse

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref_peak, ref_f, _ = peak_response(bd.reference_disk("cylinder", 1e-3))
    r = W.disk_frf("cylinder", 1.0, cache=cache)
    assert r.method == "continuation" and isinstance(r.response, DiskResponse) and r.response.success
    assert r.peak_amplitude == pytest.approx(ref_peak, rel=1e-3)
    assert r.peak_frequency_hz == pytest.approx(ref_f, abs=0.02)
    np.testing.assert_array_equal(r.tip_amplitude, r.response.tip_amplitude)
    again = W.disk_frf("cylinder", 1.0, cache=cache)
    assert again is r and cache.stats["memo"] >= 1
    nb = W.disk_frf("cylinder", 1.2, cache=cache)
    assert nb.seconds < 5.0          # 0.4-1.2 s on the loaded 2-core machine; generous on a loaded CI
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref12 = peak_response(bd.reference_disk("cylinder", 1.2e-3))[0]
    assert nb.peak_amplitude == pytest.approx(ref12, rel=1e-3)


def test_disk_frf_of_a_branch_that_stops_early_shows_what_converged(monkeypatch):
    """A continuation that stops early (here: max_points=6) is not an exception in a slider: the
    converged part is shown, method "incomplete", its largest point as the (lower-bound) peak."""
    import bladedamp.studies.mass as sm

    def stops_early(disk, f_range_hz, harmonics=(1,), max_step=0.05, **options):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = disk.frequency_response(*f_range_hz, harmonics=harmonics, max_step=max_step, max_points=6)
        assert not r.success
        raise sm.IncompleteResponse(f"frequency response incomplete: {r.message}", r)

    monkeypatch.setattr(sm, "peak_response", stops_early)
    r = W.DiskFRFCache().response("cylinder", 1e-3)
    assert r.method == "incomplete" and len(r.frequency_hz) == 6 and not r.response.success
    assert r.peak_amplitude == r.tip_amplitude[:, 0].max()


def test_undamped_frf_is_the_calibrated_peak(cache):
    r = W.undamped_frf(cache=cache)
    assert r.method == "linear"
    assert r.peak_amplitude == pytest.approx(1.6996e-3, rel=1e-3)
    assert r.peak_frequency_hz == pytest.approx(95.0, abs=0.02)


def test_disk_frf_figure_and_reduction(cache):
    fig = W.disk_frf_figure(1.0, "cylinder", cache=cache)
    damped, free = fig.data
    assert damped.reduction(free) == pytest.approx(0.712, abs=0.01)      # calibrated ~71 %
    line = fig.axes[0].get_lines()[1]
    np.testing.assert_allclose(line.get_ydata(), 1e3 * damped.tip_amplitude[:, 0])
    assert "reduction" in fig.axes[0].get_title()
    with pytest.raises(ValueError):
        W.disk_frf("plate", 1.0, cache=cache)
    with pytest.raises(ValueError):
        W.disk_frf("cylinder", 0.0, cache=cache)


def test_mass_sweep_peaks_has_an_interior_optimum(cache):
    sw = W.mass_sweep_peaks("cylinder", [0.3, 1.0, 5.0], cache=cache)
    assert sw["best_mass_g"] == 1.0
    assert sw["reduction"][0] < sw["best_reduction"] and sw["reduction"][-1] < sw["best_reduction"]
    fig = W.mass_study_figure(1.0, "cylinder", sweeps={"cylinder": sw}, cache=cache)
    assert len(fig.axes) == 2


def test_contact_state_at_peak_matches_the_study(cache):
    frf = W.disk_frf("cylinder", 1.0, cache=cache)
    ours = W.contact_state_at_peak(frf, cache)
    assert W.contact_state_at_peak(frf, cache) is ours                 # memoised
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = contact_state(bd.reference_disk("cylinder", 1e-3))
    np.testing.assert_allclose(ours.normal_load, ref.normal_load, rtol=1e-3)
    np.testing.assert_allclose(ours.w_star, ref.w_star, atol=0.05 * np.abs(ref.w_star).max())
    np.testing.assert_allclose(ours.F_star, ref.F_star, atol=0.03 * np.abs(ref.F_star).max())
    # symmetric platforms: the two contacts slide in antiphase
    assert np.all(np.abs(ours.w_star) > 1)
    assert ours.F_star[0] == pytest.approx(-ours.F_star[1], abs=0.05)
    with pytest.raises(ValueError):
        W.contact_state_at_peak(W.undamped_frf(cache=cache))


def test_platform_angle_figure_asymmetric_contact_sticks_on_one_side(cache):
    fig = W.platform_angle_figure(85.0, "cylinder", 1.0, cache=cache)
    damped, free, state = fig.data
    assert abs(state.w_star[0]) < 1 < abs(state.w_star[1])     # paper Fig. 11: OL sticks, OR slides
    assert state.normal_load[0] > state.normal_load[1]
    assert len(fig.axes) == 2


def test_engine_order_zero_cylinder_rolls(cache):
    fig = W.engine_order_figure(0, "cylinder", 1.0, cache=cache)
    damped, free = fig.data
    assert damped.reduction(free) < 0.01        # no relative motion: no friction damping


def test_platform_angle_frf_matches_the_study(cache):
    r = W.disk_frf("cylinder", 1.0, gamma_right_deg=45.0, cache=cache)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import dataclasses
        disk = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), gamma_right=np.radians(45.0))
        ref = peak_response(disk)[0]
    assert r.peak_amplitude == pytest.approx(ref, rel=1e-3)


# ---------------------------------------------------------------------------------------
# notebook 05: the mistuning explorer
# ---------------------------------------------------------------------------------------
def test_mistuning_explorer_figure_matches_the_study_and_memoises():
    """A 4-blade disk (EO = 1): the figure's amplification is the study's mistuned response over
    the tuned peak; alternating mistuning repeats its two blades; a second call is cached; a bad
    pattern is a ValueError naming the allowed patterns."""
    import dataclasses

    from bladedamp.studies import mistuning as mt

    disk = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    tuned_peak_amplitude, _, tuned = mt.tuned_peak(disk, mt.auto_range(disk, [1.0], 0.05))
    ex = W.MistuningExplorer(disk, tuned, tuned_peak_amplitude, max_step=0.05)
    fig = ex.figure("random", seed=3, std_percent=2.0)
    kappa = mt.random_kappa(4, 0.02, seed=3)
    ref = mt.mistuned_response(disk, kappa, max_step=0.05)
    assert np.array_equal(fig.kappa, kappa)
    assert np.allclose(fig.amplification, ref.blade_peak_amplitudes / tuned_peak_amplitude, rtol=1e-12)
    plt.close(fig)
    assert ex.response("random", 3, 0.02) is ex.response("random", 3, 0.02 + 1e-9)   # memoised
    fig = ex.figure("alternating", std_percent=2.0)
    assert np.allclose(fig.amplification[0::2], fig.amplification[0]) and np.allclose(fig.amplification[1::2],
                                                                                       fig.amplification[1])
    assert abs(fig.amplification[0] - fig.amplification[1]) > 1e-3
    plt.close(fig)
    with pytest.raises(ValueError, match="pattern must be one of"):
        ex.figure("sorted")


# ----- the saved still of an interactive figure ---------------------------------------------
def test_interact_with_image_saves_the_first_figure_beside_the_widget():
    """The displayed bundle holds the widget view and the PNG the callback showed at the
    controls' initial values; the callback runs once, with those values."""
    import io

    pytest.importorskip("ipywidgets")
    from IPython.core.interactiveshell import InteractiveShell
    from IPython.display import Image, display
    from IPython.utils.capture import capture_output
    from ipywidgets import FloatSlider

    InteractiveShell.instance()
    calls = []

    def callback(amplitude_mm=0.1):
        calls.append(amplitude_mm)
        fig, ax = plt.subplots(figsize=(2, 1))
        ax.plot([0, amplitude_mm])
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        plt.close(fig)
        display(Image(data=buf.getvalue(), format="png"))

    with capture_output() as shown:
        assert W.interact_with_image(callback, amplitude_mm=FloatSlider(value=0.3, min=0.1, max=1.0)) is None
    assert calls == [0.3]
    bundles = [out.data for out in shown.outputs if "application/vnd.jupyter.widget-view+json" in out.data]
    assert len(bundles) == 1
    png = bundles[0].get("image/png")
    assert png is not None
    import base64

    drawn = base64.b64decode(png) if isinstance(png, str) else png
    assert drawn[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_notebook_with_an_interactive_figure_executes_headless(tmp_path):
    """A notebook whose cell calls interact_with_image runs headless through nbclient (what
    ``jupyter nbconvert --execute`` and nbval drive; tests/notebook_client.py) without waiting for
    a front end: the whole notebook within a 60 s timeout per cell and 90 s in all, and the saved
    cell output holds the widget view and its still PNG."""
    import time

    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("nbclient")
    pytest.importorskip("ipywidgets")
    from notebook_client import execute_notebook

    cells = ["%matplotlib inline\nimport matplotlib.pyplot as plt\nfrom ipywidgets import FloatSlider\n"
             "from bladedamp.viz import widgets as W",
             "W.interact_with_image(W.interactive_view(W.hysteresis_figure),\n"
             "                      amplitude_mm=FloatSlider(value=0.1, min=0.01, max=0.5, step=0.01))",
             "print('after the interactive figure')"]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    t0 = time.perf_counter()
    execute_notebook(nb, tmp_path, timeout=60)
    elapsed = time.perf_counter() - t0
    assert elapsed < 90, elapsed
    widget_outputs = [out for out in nb.cells[1].outputs if "application/vnd.jupyter.widget-view+json" in out.get("data", {})]
    assert len(widget_outputs) == 1 and "image/png" in widget_outputs[0]["data"]
    assert not any(out.get("name") == "stderr" for cell in nb.cells for out in cell.outputs)
    assert nb.cells[2].outputs[0]["text"] == "after the interactive figure\n"
