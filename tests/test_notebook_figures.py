"""The figures of the notebooks' helpers (bladedamp.viz.widgets, bladedamp.viz.notebook3d) and
the ``.plot()`` of the time-integration results and of the nonlinear modes, checked by
tests/figure_checks.py (units, no overlapping or cut text, every series visible, a title naming
the design), on small results built from closed forms where the figure needs no solve."""
import dataclasses

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from figure_checks import check_figure  # noqa: E402

from bladedamp.hbm.fourier import HarmonicBasis  # noqa: E402
from bladedamp.hbm.nonlinear_modes import NonlinearModeResponse  # noqa: E402
from bladedamp.studies.design import LiftoffMap  # noqa: E402
from bladedamp.timedomain import DiskTimeResponse, TimeResponse  # noqa: E402
from bladedamp.viz import notebook3d, widgets  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


# ---------------------------------------------------------------------------------------
# notebook 01: the friction contact point and the friction oscillator
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("amplitude_mm, normal_variation", [(0.1, 0.0), (0.1, 0.5), (0.3, 1.5)])   # 1.5: lift-off
def test_hysteresis_figure(amplitude_mm, normal_variation):
    check_figure(widgets.hysteresis_figure(amplitude_mm, normal_variation=normal_variation), "friction contact point")


@pytest.mark.parametrize("amplitude_mm", [None, 0.005, 0.1, 2.5])     # the slider's marker line anywhere
def test_describing_function_figure(amplitude_mm):
    check_figure(widgets.describing_function_figure(amplitude_mm=amplitude_mm), "friction contact point")


def test_oscillator_figure():
    check_figure(widgets.oscillator_figure(time_frequencies_hz=(14.0, 20.5)), "friction oscillator")


# ---------------------------------------------------------------------------------------
# the time-integration results and the nonlinear modes
# ---------------------------------------------------------------------------------------
def oscillator_amplitude(f_hz, f_n=15.9, zeta=0.02, static=2e-4):
    """Amplitude [m] of a linear oscillator of natural frequency f_n, damping ratio zeta and
    static deflection ``static`` at excitation f_hz [Hz] (closed form)."""
    r = np.asarray(f_hz) / f_n
    return static / np.sqrt((1 - r ** 2) ** 2 + (2 * zeta * r) ** 2)


def test_time_response_plot():
    f = np.array([12.0, 14.0, 15.0, 15.9, 17.0, 19.0])
    a = oscillator_amplitude(f)
    n = f.size
    r = TimeResponse(2 * np.pi * f, a, a, np.zeros((n, 8)), np.full(n, 40), np.ones(n, bool))
    _, ax = plt.subplots(figsize=(6, 4))
    r.plot(ax=ax, scale=1e3, unit="mm")
    ax.set_title("friction oscillator")
    ax.figure.tight_layout()
    check_figure(ax.figure, "friction oscillator")
    assert ax.get_ylabel() == "first-harmonic amplitude [mm]"
    check_figure(r.plot().figure, None)              # its own figure, laid out, in m by default


def disk_time_response(f, tip):
    """A DiskTimeResponse with tip amplitudes ``tip`` (n, s) [m] in x at ``f`` [Hz], the last
    point not periodic; the fields the plot does not read left empty."""
    n, s = tip.shape
    amplitude = np.zeros((n, s, 3))
    amplitude[:, :, 0] = tip
    empty = {fld.name: None for fld in dataclasses.fields(DiskTimeResponse)
             if fld.default is dataclasses.MISSING and fld.default_factory is dataclasses.MISSING}
    periodic = np.ones(n, bool)
    periodic[-1] = False
    return DiskTimeResponse(**{**empty, "omega": 2 * np.pi * f, "tip_amplitude": amplitude, "periodic": periodic})


def test_disk_time_response_plot():
    f = np.linspace(92.0, 100.0, 7)
    tip = np.column_stack([oscillator_amplitude(f, 95.5, 0.01, 1e-5), oscillator_amplitude(f, 96.0, 0.01, 1e-5)])
    _, ax = plt.subplots(figsize=(6, 4))
    disk_time_response(f, tip).plot(ax=ax)
    ax.set_title("reference disk")
    ax.figure.tight_layout()
    check_figure(ax.figure, "reference disk")
    check_figure(disk_time_response(f, tip).plot().figure, None)     # its own figure, laid out


def jenkins_mode(n=40, mass=1.0, k=1e4, k_t=1e4, slip_force=0.9, success=True):
    """The nonlinear mode of a mass on a spring k beside a Jenkins contact (k_t, slip force) by
    the closed-form describing function: omega^2 = (k + k_eq) / m, zeta = d_eq / (2 (k + k_eq))."""
    a = (slip_force / k_t) * np.logspace(-1, 2, n)
    k_eq, d_eq, _ = widgets.closed_form_jenkins(k_t, slip_force, a)
    basis = HarmonicBasis((1,), 16)
    return NonlinearModeResponse(a * np.sqrt(mass), np.sqrt((k + k_eq) / mass) / (2 * np.pi), d_eq / (2 * (k + k_eq)),
                                 np.zeros((n, basis.n_coeffs, 1)), basis, ("x",), success=success,
                                 message="" if success else "Newton did not converge at a = 0.01")


@pytest.mark.parametrize("success", [True, False])
def test_nonlinear_mode_plot(success):
    axes = jenkins_mode(success=success).plot()
    fig = axes[0].figure
    fig.suptitle("friction oscillator")
    fig.tight_layout()
    check_figure(fig, "friction oscillator")


# ---------------------------------------------------------------------------------------
# notebook 04: the contact over one cycle and the wedge's lift-off map
# ---------------------------------------------------------------------------------------
def cycle_data(T=48, P=6):
    """A CycleData whose points stick, then slip, the last two lifting off over part of the cycle."""
    from bladedamp.viz.meshcat_view import CycleData

    phase = np.linspace(0, 2 * np.pi, T, endpoint=False)
    states = np.zeros((T, 2, P), dtype=int)
    for p in range(P):
        states[np.sin(phase - 0.3 * p) > 0.6, :, p] = 1
        if p >= P - 2:
            states[np.sin(phase) < -0.8, :, p] = 2
    ratio = np.vstack([np.linspace(0.2, 1.4, P), np.linspace(0.1, 1.2, P)])
    return CycleData(3, 96.2, np.zeros((3, 1)), HarmonicBasis((1,), T), states, ratio, 2.1e-4)


def test_cycle_figure():
    check_figure(notebook3d.cycle_figure(cycle_data(), "1 g cylinder at resonance"), "cylinder")


def test_liftoff_figure(monkeypatch):
    xi, eta = np.meshgrid([-0.4, -0.2, 0.0, 0.2, 0.4], [-0.4, -0.2, 0.0, 0.2, 0.4])
    xi, eta = xi.ravel(), eta.ravel()
    r = np.vstack([0.3 + 2.5 * np.abs(xi), 0.2 + 2.0 * np.abs(eta)])
    P = xi.size
    m = LiftoffMap(xi, eta, r, r, np.zeros((2, P)), np.ones((2, P)), r, 95.5, 3e-4, 64)
    monkeypatch.setattr(notebook3d, "liftoff_case", lambda *args, **kwargs: m)
    check_figure(notebook3d.liftoff_figure(2.0, 0.1), "wedge")


# ---------------------------------------------------------------------------------------
# notebooks 02, 03: the reference disk's frequency responses (one harmonic, 92-100 Hz)
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def disk_cache():
    return widgets.DiskFRFCache()


def test_disk_frf_figure(disk_cache):
    check_figure(widgets.disk_frf_figure(1.0, cache=disk_cache), "reference disk")


def test_mass_study_figure(disk_cache):
    sweeps = {"cylinder": widgets.mass_sweep_peaks("cylinder", [0.3, 1.0, 3.0], cache=disk_cache)}
    check_figure(widgets.mass_study_figure(1.0, sweeps=sweeps, cache=disk_cache), "reference disk")


def test_engine_order_study_figure():
    """Figs. 7 and 8 over engine order from the best points of mass sweeps (the figure reads
    only those: built by hand, the values notebook 03 finds; the cylinder rolls at EO 0)."""
    def sweep(best_reduction, best_mass_g):
        return {"best_reduction": best_reduction, "best_mass_g": best_mass_g}
    studies = {"cylinder": [sweep(0.0, 0.3), sweep(0.71, 1.0), sweep(0.90, 3.0), sweep(0.96, 10.0)],
               "wedge": [sweep(0.80, 0.3), sweep(0.82, 0.3), sweep(0.90, 3.0), sweep(0.96, 10.0)]}
    fig = widgets.engine_order_study_figure(studies, (0, 1, 2, 8))
    check_figure(fig, "reference disk")
    left, right = fig.axes[:2]
    np.testing.assert_allclose(left.get_lines()[0].get_ydata(), [100, 29, 10, 4])    # 1 - best reduction [%]
    assert np.isnan(right.get_lines()[0].get_ydata()[0])         # no optimum where no mass damps
    with pytest.raises(ValueError, match="studies"):
        widgets.engine_order_study_figure(studies, (0, 1))


def test_platform_angle_figure(disk_cache):
    check_figure(widgets.platform_angle_figure(35.0, cache=disk_cache), "reference disk")


# ---------------------------------------------------------------------------------------
# notebook 05: the mistuning explorer (a 4-blade reference disk, one harmonic)
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def explorer():
    from bladedamp.reference import reference_disk

    disk = dataclasses.replace(reference_disk("cylinder", 1e-3), n_blades=4)
    tuned = disk.frequency_response(92.0, 100.0, harmonics=(1,), max_step=0.2)
    return widgets.MistuningExplorer(disk, tuned, tuned.peak_amplitude, max_step=0.2)


@pytest.mark.parametrize("pattern", ["random", "alternating"])
def test_mistuning_explorer_figure(explorer, pattern):
    fig = explorer.figure(pattern, 0, 2.0)
    assert fig.amplification is not None
    check_figure(fig, "reference disk")


# ---------------------------------------------------------------------------------------
# every notebook executed, and every figure it shows checked, their own cells' figures
# included (slow: the one run of each notebook in the tests)
# ---------------------------------------------------------------------------------------
#: what a notebook figure's title may name as its design: the contact point and the oscillator of
#: notebook 01, the reference disk and its dampers, the blades of notebook 07
NOTEBOOK_DESIGNS = ("friction contact point", "friction oscillator", "reference disk", "cylinder", "wedge", "blade")

#: run first in the notebook's kernel (not saved): checks, with tests/figure_checks.py, every
#: figure as it is shown (``plt.show`` and the inline backend's end-of-cell display, slider
#: callbacks included) and keeps the problems with the first line of the cell that showed it
FIGURE_WATCH = '''
import sys as _sys
_sys.path.insert(0, {tests!r})
import matplotlib.pyplot as _plt
from IPython import get_ipython as _get_ipython
from figure_checks import figure_problems as _figure_problems, titles as _titles

_figure_watch = {{"problems": [], "checked": set(), "count": 0, "cell": ""}}


def _note_cell(info):
    _figure_watch["cell"] = info.raw_cell.strip().splitlines()[0][:60] if info.raw_cell.strip() else ""


def _check_open_figures(*args, **kwargs):
    for _num in _plt.get_fignums():
        _fig = _plt.figure(_num)
        if id(_fig) in _figure_watch["checked"]:
            continue
        _figure_watch["checked"].add(id(_fig))
        _figure_watch["count"] += 1
        _found = _figure_problems(_fig, None)
        if not any(d in t.lower() for t in _titles(_fig) for d in {designs!r}):
            _found.append(f"no title names the design (titles: {{_titles(_fig)}})")
        _figure_watch["problems"] += [f"cell {{_figure_watch['cell']!r}}: {{p}}" for p in _found]


_show = _plt.show
def _checked_show(*args, **kwargs):
    _check_open_figures()
    return _show(*args, **kwargs)
_plt.show = _checked_show
_get_ipython().events.register("pre_run_cell", _note_cell)
_get_ipython().events.callbacks["post_execute"].insert(0, _check_open_figures)
'''

#: run last: the problems found, as JSON on stdout
FIGURE_REPORT = 'import json as _json\nprint(_json.dumps({"count": _figure_watch["count"], "problems": _figure_watch["problems"]}))'


def notebook_figure_problems(path, timeout=600) -> tuple[int, list[str]]:
    """Executes the notebook at ``path`` (its folder the kernel's working directory) with
    :data:`FIGURE_WATCH` run first; returns (figures checked, problems). A cell that raises
    (one of the notebook's own physics checks, say) or runs longer than ``timeout`` [s] raises
    nbclient's CellExecutionError or a TimeoutError here, naming the cell."""
    import json
    import pathlib

    import nbformat        # test dependencies (the test extra): missing, the test fails rather than skips

    from notebook_client import execute_notebook
    nb = nbformat.read(path, as_version=4)
    tests = str(pathlib.Path(__file__).resolve().parent)
    nb.cells.insert(0, nbformat.v4.new_code_cell(FIGURE_WATCH.format(tests=tests, designs=NOTEBOOK_DESIGNS)))
    nb.cells.append(nbformat.v4.new_code_cell(FIGURE_REPORT))
    execute_notebook(nb, pathlib.Path(path).parent, timeout=timeout)
    text = "".join(out["text"] for out in nb.cells[-1].outputs if out.get("name") == "stdout")
    report = json.loads(text)
    return report["count"], report["problems"]


NOTEBOOK_PATHS = sorted((__import__("pathlib").Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))


def test_the_slow_run_finds_the_notebooks():
    """The parametrisation below is not empty (an empty one would execute nothing, unnoticed);
    tests/test_notebook_files.py checks that notebooks/README.md lists exactly these."""
    assert len(NOTEBOOK_PATHS) > 0


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOK_PATHS, ids=lambda p: p.name[:2])
def test_notebook_runs_and_every_figure_it_shows_keeps_the_rules(path):
    """The notebook runs top to bottom without an error in any cell (its cells assert physical
    facts) and every figure it shows -- its helpers' and those its own cells draw -- keeps the
    slide rules of tests/figure_checks.py, with a title naming the design shown."""
    count, problems = notebook_figure_problems(path)
    assert count > 0
    assert not problems, f"{path.name}: {count} figures, problems:\n  " + "\n  ".join(problems)
