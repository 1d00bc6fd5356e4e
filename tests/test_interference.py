"""Interference (ZZENF) and Campbell diagrams over engine orders, and the commands that draw them.

Independent references: the blade's own natural frequencies (without dampers nothing couples
the blades), Rayleigh's monotonicity (stuck massless dampers only add stiffness), the complex
conjugate sector of a backward wave (same eigenvalues), and the closed-form modal FRF of the
blade (nodal diameter 0 with massless dampers: the platforms move in phase, the stuck dampers
carry no force).
"""
import dataclasses
import json

import numpy as np
import pytest

from bladedamp.cli import main
from bladedamp.reference import reference_disk
from bladedamp.studies.interference import interference_diagram


def four_blades(**kw):
    return dataclasses.replace(reference_disk("cylinder", 1e-3, **kw), n_blades=4)


def test_interference_diagram_frequencies_per_nodal_diameter():
    """4 blades, speeds 1200-6000 rpm: nodal diameters 0..2; without dampers the blade's own
    natural frequencies; without damper inertia the stuck 1F lies at or above the free one at
    every nodal diameter and speed (added stiffness only); a backward wave's stuck sector (the
    complex conjugate) has the forward one's frequencies."""
    disk = four_blades(damper_inertia=False)
    z = interference_diagram(disk, [20.0, 100.0], 130.0, engine_orders=(1, 3, 4))
    assert list(z.nodal_diameters) == [0, 1, 2]
    assert np.allclose(z.free_hz, np.sort(disk.blade.natural_frequencies_hz), rtol=1e-12)
    assert z.stuck_hz.shape[:2] == (3, 2)
    assert np.all(z.stuck_hz[:, :, 0] >= z.free_hz[0] * (1 - 1e-9)), z.stuck_hz[:, :, 0]
    assert z.stuck_hz[2, 1, 0] > z.stuck_hz[0, 1, 0] + 1.0      # the dampers stiffen the out-of-phase waves
    backward = dataclasses.replace(disk, engine_order=3, rotor_speed_hz=100.0)
    _, stuck_backward = backward.linear_natural_frequencies_up_to_hz(130.0)
    assert np.allclose(stuck_backward[:2], z.stuck_hz[1, 1, :2], rtol=1e-10)
    crossings = {(c["engine_order"], c["mode"]): c for c in z.crossings()}
    assert set(crossings) == {(1, 1), (3, 1), (4, 1)}
    c = crossings[(3, 1)]
    assert (c["nodal_diameter"], c["direction"]) == (1, "backward")
    assert c["free_speed_hz"] == pytest.approx(c["free_hz"] / 3, rel=1e-14)


@pytest.fixture(scope="module")
def small_design(tmp_path_factory):
    """The init design with 4 blades, engine orders 1, 3 (nodal diameter 1 backward) and 4
    (nodal diameter 0), one harmonic, 92-112 Hz."""
    path = tmp_path_factory.mktemp("eo") / "design.toml"
    assert main(["init", str(path)]) == 0
    text = path.read_text()
    for old, new in {"n_blades = 16": "n_blades = 4", "engine_order = 1\n": "engine_order = [1, 3, 4]\n",
                     "frequency_range_hz = [90.0, 105.0]": "frequency_range_hz = [92.0, 112.0]",
                     'harmonics = "auto"': "harmonics = [1]"}.items():
        assert old in text, old
        text = text.replace(old, new)
    path.write_text(text)
    return path


def test_zzenf_command(small_design, tmp_path):
    out = tmp_path / "zz"
    assert main(["zzenf", str(small_design), "--speed-range-rpm", "1500", "7000", "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    assert (out / "zzenf.png").stat().st_size > 10_000
    assert results["engine_orders"] == {"1": {"nodal_diameter": 1, "direction": "forward", "excitation_hz": [25.0, 700 / 6]},
                                        "3": {"nodal_diameter": 1, "direction": "backward", "excitation_hz": [75.0, 350.0]},
                                        "4": {"nodal_diameter": 0, "direction": "standing", "excitation_hz": [100.0, 7000 / 15]}}
    assert results["rotor_speeds_rpm"] == [1500.0, 7000.0]
    summary = (out / "summary.md").read_text()
    assert "| 3 | 1 (backward) |" in summary and "| 4 | 0 (standing) |" in summary


def test_campbell_command_nodal_diameter_zero_equals_the_blade_alone(small_design, tmp_path):
    """EO 3 (nodal diameter 1 backward) and EO 4 (nodal diameter 0) on 4 blades, one harmonic.
    Without damper inertia, EO 4's dampers move with in-phase platforms and carry no force: its
    peak is the blade's closed-form modal FRF peak (within the continuation's sampling of the
    peak, 1e-4 relative at max_step 0.02 around a peak of 0.5 % damping), at 95 Hz, 95 / 4 x 60
    rpm. EO 3's damped peak is below it; each crossing's speed is its peak frequency / EO."""
    design = small_design.parent / "massless.toml"
    design.write_text(small_design.read_text().replace("inertia = true", "inertia = false"))
    out = tmp_path / "cb"
    assert main(["campbell", str(design), "--engine-orders", "3", "4", "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    assert (out / "campbell.png").stat().st_size > 10_000
    summary = (out / "summary.md").read_text()
    assert "one-harmonic estimate" in summary
    c3, c4 = results["crossings"]
    assert (c3["engine_order"], c3["nodal_diameter"], c3["direction"]) == (3, 1, "backward")
    assert (c4["engine_order"], c4["nodal_diameter"], c4["direction"]) == (4, 0, "standing")
    blade = reference_disk("cylinder").blade
    f = np.linspace(94.0, 96.0, 200_001)
    linear = np.abs(blade.linear_frf(f, np.array([0.1, 0, 0, 0, 0, 0]))[:, 0])
    assert c4["found"] and c4["peak_amplitude_mm"] == pytest.approx(1e3 * linear.max(), rel=1e-4)
    assert c4["peak_frequency_hz"] == pytest.approx(f[np.argmax(linear)], abs=0.01)
    assert c3["found"] and c3["peak_amplitude_mm"] < 0.7 * c4["peak_amplitude_mm"]
    for c in (c3, c4):
        assert c["rotor_speed_rpm"] == pytest.approx(60 * c["peak_frequency_hz"] / c["engine_order"], rel=1e-12)
        assert c["harmonics"] == [1]


@pytest.mark.parametrize("argv, edit, needle", [
    (["campbell", "--speed-range-rpm", "7000", "1500"], {}, "--speed-range-rpm"),
    (["zzenf", "--f-max-hz", "-5"], {}, "--f-max-hz"),
    (["campbell", "--engine-orders", "-1"], {}, "--engine-orders"),
    (["campbell"], {'rotor_speed_rpm = "auto"': "rotor_speed_rpm = 6000.0"}, "rotor_speed_rpm"),
    (["campbell"], {'kind = "cylinder"': 'kind = "none"'}, "needs a damper"),
])
def test_bad_input_is_one_line_and_exit_2(small_design, tmp_path, capsys, argv, edit, needle):
    design = tmp_path / "design.toml"
    text = small_design.read_text()
    for old, new in edit.items():
        assert old in text, old
        text = text.replace(old, new)
    design.write_text(text)
    capsys.readouterr()
    assert main([argv[0], str(design), *argv[1:], "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err


@pytest.mark.parametrize("speeds_hz", [[100.0, 100.0], [20.0, 100.0]])
def test_interference_diagram_figure_at_one_speed_and_with_engine_orders_above_it(speeds_hz):
    """EO 0 (f = 0), engine orders whose range leaves the diagram's top (EO 7 from 140 Hz at
    20 rev/s, EO 9) and a single speed: the figure still passes tests/figure_checks.py."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from figure_checks import check_figure

    z = interference_diagram(four_blades(), speeds_hz, 130.0, engine_orders=(0, 1, 3, 4, 7, 9))
    fig, ax = plt.subplots(figsize=(9.5, 5))
    z.plot(ax=ax)
    fig.tight_layout()
    check_figure(fig, None)
    plt.close(fig)


def test_campbell_diagram_figure_with_engine_order_zero_and_one_above_it():
    """EO 0 (the static load, f = 0) and EO 9 (from 180 Hz, above the 130 Hz top: in the legend
    only) on a diagram without crossings (stuck frequencies of a linear stiffening): the figure
    passes tests/figure_checks.py."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from figure_checks import check_figure

    from bladedamp.studies.interference import CampbellDiagram

    speeds = np.linspace(20.0, 100.0, 7)
    stuck = {eo: np.column_stack([f0 + 0.01 * speeds]) for eo, f0 in ((0, 95.0), (3, 103.0), (4, 95.0), (9, 103.0))}
    diagram = CampbellDiagram(4, speeds, (0, 3, 4, 9), np.array([95.0, 300.0]), stuck, [], 130.0)
    fig, ax = plt.subplots(figsize=(9.5, 5))
    diagram.plot(ax=ax)
    fig.tight_layout()
    check_figure(fig, None)
    assert "EO 9 (k = 1, forward): above the diagram" in [t.get_text() for t in ax.get_legend().get_texts()]
    plt.close(fig)


def test_zzenf_and_campbell_figures_pass_the_slide_checks_and_summaries_list_the_files_written(
        small_design, tmp_path, saved_figures):
    """The figures of both commands obey tests/figure_checks.py with a title naming the design
    file; with --format svg no PNG is written and summary.md names the SVG instead."""
    zz, cb = tmp_path / "zz", tmp_path / "cb"
    assert main(["zzenf", str(small_design), "--speed-range-rpm", "1500", "7000", "--format", "svg",
                 "--out", str(zz)]) == 0
    assert main(["campbell", str(small_design), "--engine-orders", "1", "3", "4", "--format", "svg",
                 "--out", str(cb)]) == 0
    saved_figures.check(small_design.stem, "zzenf", "campbell")
    for out, name in ((zz, "zzenf"), (cb, "campbell")):
        assert (out / f"{name}.svg").is_file() and not (out / f"{name}.png").exists()
        summary = (out / "summary.md").read_text()
        assert f"`{name}.svg`" in summary and f"{name}.png" not in summary
