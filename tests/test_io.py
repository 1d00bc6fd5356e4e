"""Results persist: every response and study result saves to one .npz (no pickle) and loads back
equal, field by field, with its named properties and .plot() working (issue 13, item 5).

The responses are computed (small and fast: an oscillator, a one-harmonic sector, a 4-blade
mistuned ring); the study results, whose computation takes minutes, are built from arrays of
the shapes the studies return, with the awkward values a real run produces (NaN, complex,
integer-keyed dicts, tuples, lists of arrays of different lengths, string arrays).
"""
import dataclasses
import json
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import bladedamp as bd  # noqa: E402
from bladedamp import io  # noqa: E402
from bladedamp.diskmodel import DiskModelResponse  # noqa: E402
from bladedamp.mistuned import MistunedDisk, MistunedResponse  # noqa: E402
from bladedamp.response import with_note  # noqa: E402
from bladedamp.studies import design as sd  # noqa: E402
from bladedamp.studies import mass as sm  # noqa: E402
from bladedamp.studies import mistuning as mt  # noqa: E402
from bladedamp.timedomain import DiskTimeResponse, TimeResponse  # noqa: E402

DATA = Path(__file__).parent / "data"


def assert_same(a, b, where="result"):
    """Field-by-field equality of two results (NaN equal to NaN); models (disk) are not saved."""
    assert type(a) is type(b), where
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        w = f"{where}.{f.name}"
        if f.name in io.MODEL_FIELDS:
            assert y is None, w
        elif dataclasses.is_dataclass(x):
            assert_same(x, y, w)
        elif isinstance(x, np.ndarray):
            assert isinstance(y, np.ndarray) and x.shape == y.shape and x.dtype == y.dtype, w
            if x.dtype.kind in "fc":
                np.testing.assert_array_equal(x, y, err_msg=w)
            else:
                assert np.array_equal(x, y), w
        elif isinstance(x, list) and x and isinstance(x[0], np.ndarray):
            assert len(x) == len(y), w
            for i, (u, v) in enumerate(zip(x, y)):
                np.testing.assert_array_equal(u, v, err_msg=f"{w}[{i}]")
        elif isinstance(x, float) and np.isnan(x):
            assert isinstance(y, float) and np.isnan(y), w
        elif isinstance(x, bd.HarmonicBasis):
            assert x.harmonics == y.harmonics and x.n_samples == y.n_samples, w
        else:
            assert same_value(x, y), (w, x, y)


def same_value(x, y) -> bool:
    """Equality of plain values, types included, NaN equal to NaN (inside tuples, lists, dicts)."""
    if type(x) is not type(y):
        return False
    if isinstance(x, (tuple, list)):
        return len(x) == len(y) and all(same_value(u, v) for u, v in zip(x, y))
    if isinstance(x, dict):
        return list(x) == list(y) and all(same_value(x[k], y[k]) for k in x)
    if isinstance(x, float) and np.isnan(x):
        return np.isnan(y)
    return x == y


def round_trip(result, tmp_path, name="r"):
    path = result.save(tmp_path / name)
    assert path.suffix == ".npz" and path.exists()
    with np.load(path, allow_pickle=False) as z:          # any npz reader, no pickle
        meta = json.loads(str(z[io.META_KEY][()]))
    assert meta["class"].endswith(type(result).__qualname__)
    back = bd.load(path)
    assert_same(result, back)
    assert type(result).load(path) is not None            # Class.load checks the class
    return back


# ----- responses (computed) --------------------------------------------------------------
@pytest.fixture(scope="module")
def oscillator_frf():
    osc = bd.FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0)
    return osc, osc.frequency_response(14.0, 25.0, harmonics=(1, 3))


@pytest.fixture(scope="module")
def disk_frf():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bd.reference_disk("cylinder", 1e-3).frequency_response(93.0, 97.0, harmonics=(1,), max_step=0.1)


@pytest.fixture(scope="module")
def mistuned_frf():
    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return MistunedDisk.from_tuned(td, [1.01, 0.99, 1.02, 1.0]).frequency_response(
            92.0, 99.0, harmonics=(1,), max_step=0.1, tuned_peak_amplitude=5e-4)


def test_frequency_response_round_trip(oscillator_frf, tmp_path):
    _, r = oscillator_frf
    back = round_trip(r, tmp_path)
    assert back.peak_amplitude == r.peak_amplitude and back.peak_frequency_hz == r.peak_frequency_hz
    np.testing.assert_array_equal(back.time_samples(), r.time_samples())     # the basis is rebuilt
    assert back.plot().get_lines()


def test_notes_round_trip_with_their_kinds_values_and_order(oscillator_frf, tmp_path):
    """A response's notes are saved (its message is not: it is derived from them) and loaded with
    their kinds, texts, values and order; a file saved before responses had notes (main 427345c)
    loads with the message it holds as its one note, of kind CONTINUATION."""
    _, r = oscillator_frf
    r = with_note(r, bd.Note(bd.NoteKind.STOP_CHECK, "beyond, a periodic motion"))
    r = with_note(r, bd.Note(bd.NoteKind.CONTINUATION, "second", {"max_points": 7}))
    back = round_trip(r, tmp_path)
    assert back.notes == r.notes and [n.kind for n in back.notes][1:] == [bd.NoteKind.STOP_CHECK,
                                                                          bd.NoteKind.CONTINUATION]
    assert back.notes[-1].values == {"max_points": 7} and type(back.notes[-1].values["max_points"]) is int
    assert back.message == r.message and back.status is r.status
    with np.load(tmp_path / "r.npz", allow_pickle=False) as z:
        fields = json.loads(str(z[io.META_KEY][()]))["fields"]
    assert "message" not in fields and "notes" in fields
    for name in ("oscillator_response_v1.npz", "disk_response_v1.npz"):
        with np.load(DATA / name, allow_pickle=False) as z:
            fields = json.loads(str(z[io.META_KEY][()]))["fields"]
        assert "notes" not in fields
        old = bd.load(DATA / name)
        assert old.notes == (bd.Note(bd.NoteKind.CONTINUATION, fields["message"]),)
        assert old.message == fields["message"] == "reached the end of the frequency range"


def test_disk_response_round_trip_without_the_model(disk_frf, tmp_path):
    back = round_trip(disk_frf, tmp_path)
    assert back.disk is None and back.peak_amplitude == disk_frf.peak_amplitude
    assert back.peak_frequency_hz == disk_frf.peak_frequency_hz
    np.testing.assert_array_equal(back.energy_balance_error(), disk_frf.energy_balance_error())
    ax = back.plot()
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), 1e3 * disk_frf.tip_amplitude[:, 0])
    with np.load(tmp_path / "r.npz", allow_pickle=False) as z:
        model = json.loads(str(z[io.META_KEY][()]))["models"]["disk"]
    assert model["damper"] == "cylinder" and model["damper_mass_kg"] == 1e-3    # described, not rebuilt


def test_mistuned_response_round_trip(mistuned_frf, tmp_path):
    back = round_trip(mistuned_frf, tmp_path)
    np.testing.assert_array_equal(back.blade_peak_amplitudes, mistuned_frf.blade_peak_amplitudes)
    assert back.peak_amplitude == mistuned_frf.peak_amplitude
    np.testing.assert_array_equal(back.amplification(), mistuned_frf.amplification())
    assert back.plot().get_lines()


def test_time_responses_round_trip(tmp_path):
    tr = bd.FrictionOscillator(damping=2.0, normal_load=3.0, forcing=2.0).time_response([15.0, 17.0],
                                                                                        steps_per_period=256)
    back = round_trip(tr, tmp_path, "osc")
    assert back.plot().get_lines()
    n, s, S, nd = 3, 4, 8, 2
    rng = np.random.default_rng(0)
    dtr = DiskTimeResponse(
        omega=2 * np.pi * np.array([94.0, 95.0, 96.0]), tip_amplitude=rng.random((n, s, 3)),
        tip_harmonic=rng.random((n, s, 3)) + 1j * rng.random((n, s, 3)), tip_samples=rng.random((n, s, 3, S)),
        dissipated_energy=rng.random(n), damper_dissipation=rng.random((n, nd)), excitation_work=rng.random(n),
        viscous_dissipation=rng.random(n), periods=np.array([20, 31, 4000]), periodic=np.array([True, True, False]),
        status=np.array(["periodic", "periodic", "drifting"], dtype=object),          # as disk_time_response
        message=np.array(["", "", "damper 1 rolls"], dtype=object),
        settling=np.array([1e-7, 1e-8, np.nan]), damper_mean=rng.random((n, nd, 6)),
        damper_drift=rng.random((n, nd, 6)), point_state=rng.random((n, 5, 3)), steps_per_period=S,
        time_step=np.full(n, 1e-5), static_state=rng.random((n, 10)),
        tip_history=[rng.random((k, s, 3)) + 0j for k in (20, 31, 4000)],
        damper_history=[rng.random((k, nd, 6)) for k in (20, 31, 4000)])
    back = round_trip(dtr, tmp_path, "disk")
    assert back.n_blades == s and back.plot().get_lines()


# ----- study results (built) -------------------------------------------------------------
def study_results(disk_frf, mistuned_frf):
    nan = float("nan")
    masses = np.array([1e-4, 1e-3, 1e-2])
    return {
        "PeakEvaluation": sm.PeakEvaluation(False, nan, nan, 3e-4, "continuation stalled", 3),
        "MassSweep": sm.MassSweep(masses, np.array([1e-3, 5e-4, nan]), np.array([95.0, 95.3, nan]), "cylinder", 1.7e-3),
        "MassOptimum": sm.MassOptimum(1e-3, 4.9e-4, 1.7e-3, 12, (2e-5,), (nan,), ("stalled at 94 Hz",), masses,
                                      np.array([1e-3, 5e-4, 9e-4]), (1e-4, 1e-2), False, "one mass failed"),
        "EngineOrderSweep": sd.EngineOrderSweep("cylinder", np.arange(3), np.array([nan, 1e-3, 2e-3]),
                                                np.array([1.7e-3, 5e-4, 3e-4]), np.full(3, 1.7e-3),
                                                np.array([0.0, 0.7, 0.8]), {0: "rolls"},
                                                np.array([False, True, True]), {1: "grid", 2: "grid"}),
        "PlatformAngleStudy": sd.PlatformAngleStudy("wedge", 35.0, 1e-3, np.array([25.0, 35.0, 45.0]),
                                                    np.array([3e-4, 2.8e-4, nan]), np.array([3e-4, 3.2e-4, 4e-4]),
                                                    np.array([4e-4, 5e-4, 6e-4]), 1.7e-3),
        "ContactState": sd.ContactState(np.array([0.7 + 0.1j, 3.3 - 1j]), np.array([0.5j, 1 + 0j]),
                                        np.array([1e-6 + 2e-7j, 3e-6j]), np.array([0.1 + 0j, 0.2 - 0.1j]),
                                        np.array([5.0, 6.0]), np.array([2e7, 2e7]), np.array([0.3, 0.3]), 95.3, 4.9e-4),
        "LiftoffMap": sd.LiftoffMap(np.linspace(0, 1, 6), np.linspace(-0.5, 0.5, 6), np.linspace(0.5, 1.5, 12).reshape(2, 6),
                                    np.ones((2, 6)), np.full((2, 6), -1e-8), np.full((2, 6), 1e-7),
                                    np.full((2, 6), 2e-7), 95.1, 3e-4, 64),
        "DesignMap": sd.DesignMap("wedge", 2e-3, masses, np.array([30.0, 40.0]), np.array([[3e-4, 2e-4, nan], [4e-4, 3e-4, 5e-4]]),
                                  1.7e-3),
        "MistuningCase": mt.MistuningCase("random_1g", 1e-3, np.array([1.01, 0.99, 1.02, 1.0]), mistuned_frf, 5e-4,
                                          disk_frf),
        "MonteCarloResult": mt.MonteCarloResult(np.zeros((2, 4)), np.full((2, 4), 5e-4), np.full((2, 4), 95.0), 5e-4,
                                                ["", ""], {"seed": 1, "f_range_hz": [90.0, 100.0], "disk": {"n_blades": 4}}),
        "Arrangement": mt.Arrangement(np.array([1.01, 0.99, 1.02, 1.0]), np.array([2, 0, 3, 1]), 5.1e-4,
                                      np.array([0, 2, 1, 3]), 5.3e-4, 5.6e-4, 5e-4, 17, [5.6e-4, 5.1e-4], mistuned_frf),
    }


@pytest.mark.parametrize("name", ["PeakEvaluation", "MassSweep", "MassOptimum", "EngineOrderSweep", "PlatformAngleStudy",
                                  "ContactState", "LiftoffMap", "DesignMap", "MistuningCase", "MonteCarloResult",
                                  "Arrangement"])
def test_study_result_round_trip(name, disk_frf, mistuned_frf, tmp_path):
    result = study_results(disk_frf, mistuned_frf)[name]
    back = round_trip(result, tmp_path)
    if hasattr(back, "plot"):
        back.plot()
        plt.close("all")
    for prop in ("reduction", "optimum", "lifts_off", "amplification", "gain_over_given", "gain_over_heuristic", "peak_amplitude", "peak_frequency_hz"):
        if hasattr(type(back), prop):
            a, b = getattr(result, prop), getattr(back, prop)
            assert np.array_equal(np.asarray(a, dtype=object) if isinstance(a, dict) else a,
                                  np.asarray(b, dtype=object) if isinstance(b, dict) else b, equal_nan=not isinstance(a, dict)), prop


def test_integer_keys_and_tuples_survive(disk_frf, mistuned_frf, tmp_path):
    back = round_trip(study_results(disk_frf, mistuned_frf)["EngineOrderSweep"], tmp_path)
    assert back.failures == {0: "rolls"} and list(back.messages) == [1, 2]
    opt = round_trip(study_results(disk_frf, mistuned_frf)["MassOptimum"], tmp_path, "opt")
    assert opt.bracket == (1e-4, 1e-2) and isinstance(opt.failure_messages, tuple)


# ----- Monte Carlo with failed disks (issue 13: save failed after writing the .npz, load lost the errors)
def test_monte_carlo_where_every_disk_failed_saves_and_loads_its_errors(tmp_path, monkeypatch):
    def fails(disk, kappa, f_range_hz, **settings):
        raise RuntimeError(f"continuation stalled (kappa[0] = {kappa[0]:.4f})")

    monkeypatch.setattr(mt, "mistuned_response", fails)
    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    res = mt.monte_carlo(td, 3, seed=2, f_range_hz=(90.0, 100.0), scheduler="serial", tuned_peak_amplitude=5e-4)
    assert not res.valid.any() and all(e.startswith("continuation stalled") for e in res.errors)
    path = res.save(tmp_path / "mc")
    back = mt.MonteCarloResult.load(path)
    assert back.errors == res.errors and len(back.errors) == 3
    assert np.isnan(back.peak_amplitude).all() and back.meta == json.loads(json.dumps(res.meta))
    summary = json.loads((tmp_path / "mc.json").read_text())          # strict JSON: no NaN
    assert summary["summary"]["n_failed"] == 3 and summary["summary"]["amplification_mean"] is None
    assert summary["errors"] == res.errors


def test_monte_carlo_where_some_disks_failed(tmp_path, monkeypatch):
    real = mt.mistuned_response
    calls = []

    def second_fails(disk, kappa, f_range_hz, **settings):
        calls.append(1)
        if len(calls) == 2:
            raise RuntimeError("no start point")
        return real(disk, kappa, f_range_hz, **settings)

    monkeypatch.setattr(mt, "mistuned_response", second_fails)
    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    res = mt.monte_carlo(td, 2, seed=2, f_range_hz=(90.0, 100.0), scheduler="serial", tuned_peak_amplitude=5e-4)
    back = bd.load(res.save(tmp_path / "mc"))
    assert back.errors == ["", "no start point"] and back.valid.tolist() == [True, False]
    np.testing.assert_array_equal(back.amplification, res.amplification)


# ----- the typed JSON values (io.encode_value / io.decode_value) ------------------------
def same_typed(x, y) -> bool:
    """same_value, with numpy arrays compared by type, dtype, shape and entries (NaN equal to NaN)."""
    if isinstance(x, np.ndarray):
        return (type(y) is np.ndarray and x.dtype == y.dtype and x.shape == y.shape
                and np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"))
    if type(x) is not type(y):
        return False
    if isinstance(x, (tuple, list)):
        return len(x) == len(y) and all(same_typed(u, v) for u, v in zip(x, y))
    if isinstance(x, dict):
        return list(x) == list(y) and all(same_typed(x[k], y[k]) for k in x)
    return same_value(x, y)


def test_encoded_values_round_trip_with_their_types():
    """Every type encode_value documents comes back from json text with its type, dtype and shape;
    numpy scalars come back as the Python scalar of their kind."""
    value = {"float": 0.1, "nan": float("nan"), "inf": -float("inf"), "zero": -0.0, "int": 2 ** 62, "neg": -3,
             "true": True, "false": False, "text": "1F", "none": None, "complex": 1 - 2j,
             "tuple": (1, 2.5, "x", None, (True, ())), "list": [1, [2.0, "a"], ()],
             "f64": np.array([[0.1, np.nan], [1e-300, -2.0]]), "f32": np.array([1.5, 2.25], dtype=np.float32),
             "i64": np.arange(6, dtype=np.int64).reshape(2, 3), "i32": np.array([-1, 7], dtype=np.int32),
             "u8": np.array([0, 255], dtype=np.uint8), "bool": np.array([True, False]),
             "c128": np.array([1 + 2j, -0.5j]), "names": np.array(["1F", "2F", "1T"]), "0d": np.array(3.5),
             "empty": np.zeros((0, 3)), "empty_c": np.zeros((2, 0), dtype=complex),
             "basis": bd.HarmonicBasis((0, 1, 3), 32), "kind": bd.NoteKind.RANGE_END,
             "note": (bd.Note(bd.NoteKind.CONTINUATION, "stopped", {"max_points": 5, "f_hz": 12.5}),),
             "nested": {1: {"a": (np.array([1, 2]),), (2, "b"): {"deep": [1.0]}}, None: 0.0}}
    back = io.decode_value(json.loads(json.dumps(io.encode_value(value))))
    basis = back.pop("basis")
    assert basis.harmonics == (0, 1, 3) and basis.n_samples == 32
    value.pop("basis")
    assert same_typed(value, back), back
    scalars = [np.float64(0.25), np.float32(0.5), np.int64(3), np.int8(-2), np.bool_(True), np.complex128(1j), np.str_("x")]
    assert same_typed([0.25, 0.5, 3, -2, True, 1j, "x"],
                      io.decode_value(json.loads(json.dumps(io.encode_value(scalars)))))
    # an object array is stored as the array numpy infers from its items
    assert same_typed(io.decode_value(io.encode_value(np.array(["ok", "failed"], dtype=object))),
                      np.array(["ok", "failed"]))


def test_encode_value_refuses_other_types_naming_the_value():
    with pytest.raises(TypeError, match=r"cannot save info\['k'\]\[1\]: a builtins.object"):
        io.encode_value({"k": [1, object()]}, "info")
    with pytest.raises(TypeError, match="cannot save a: an array of dtype"):
        io.encode_value(np.array([b"x"]), "a")
    with pytest.raises(ValueError, match="not an encoded value"):
        io.decode_value({"n_dofs": 3})                 # a plain JSON object is not an encoded dict
    with pytest.raises(TypeError, match="cannot save n: a pathlib"):
        io.encode_value(Path("x"), "n")                # neither an enum nor a dataclass of bladedamp
    with pytest.raises(ValueError, match="must come from bladedamp"):
        io.decode_value({"__record__": "os:stat_result", "fields": {}})


# ----- the file ------------------------------------------------------------------------
def test_load_rejects_what_is_not_a_result(tmp_path, oscillator_frf):
    np.savez(tmp_path / "plain.npz", x=np.zeros(3))
    with pytest.raises(ValueError, match="not a saved bladedamp result"):
        bd.load(tmp_path / "plain.npz")
    with pytest.raises(FileNotFoundError, match="missing"):
        bd.load(tmp_path / "missing.npz")
    path = oscillator_frf[1].save(tmp_path / "frf")
    with pytest.raises(TypeError, match="not a MassSweep"):
        sm.MassSweep.load(path)
    with pytest.raises(TypeError, match="cannot save HarmonicBalanceSystem.excitation: a builtins.function"):
        bd.save(oscillator_frf[0].hbm_system(), tmp_path / "system")       # names the field it cannot store
    with pytest.raises(TypeError, match="result dataclass"):
        bd.save({"peak": 1.0}, tmp_path / "dict")


def test_load_dispatches_on_the_stored_class_only_inside_bladedamp(tmp_path, oscillator_frf):
    path = oscillator_frf[1].save(tmp_path / "frf")
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays[io.META_KEY][()]))
    meta["class"] = "os:system"
    arrays[io.META_KEY] = np.array(json.dumps(meta))
    np.savez(tmp_path / "evil.npz", **arrays)
    with pytest.raises(ValueError, match="must come from bladedamp"):
        bd.load(tmp_path / "evil.npz")


def test_every_result_class_is_saveable():
    classes = [bd.FrequencyResponse, bd.DiskResponse, MistunedResponse, TimeResponse, DiskTimeResponse,
               sm.MassSweep, sm.MassOptimum, sd.EngineOrderSweep, sd.PlatformAngleStudy, sd.ContactState,
               sd.LiftoffMap, sd.DesignMap, mt.MistuningCase, mt.MonteCarloResult, mt.Arrangement]
    assert all(issubclass(c, io.Saveable) for c in classes)


# ----- files saved before the one disk model (issue 34 item 2) ---------------------------------
DATA = Path(__file__).parent / "data"


def test_disk_responses_saved_before_the_one_disk_model_load():
    """Files written by main 9e1a333, before DiskModel and DiskModelResponse: a tuned sector's
    DiskResponse (the 1 g cylinder disk over 90-105 Hz, saved by main 427345c) and a 4-blade
    MistunedResponse (kappa 1.01, 0.99, 1.02, 1.0 over 92-99 Hz, harmonics (1,), tuned peak
    5e-4 m) load as their classes, with the names both responses now share: the energy balance
    holds for their stored arrays, and ``peak_amplitude`` (a float on both) is the largest of the
    blades' peaks ``blade_peak_amplitudes`` (computed, not stored: the old files have neither)."""
    tuned = bd.load(DATA / "disk_response_v1.npz")
    ring = bd.load(DATA / "mistuned_response_v1.npz")
    assert type(tuned) is bd.DiskResponse and type(ring) is MistunedResponse
    assert ring.n_sector == 4 and ring.tuned_peak_amplitude == 5e-4 and ring.disk is None
    for r in (tuned, ring):
        assert isinstance(r, DiskModelResponse) and r.success
        assert r.energy_balance_error().max() < 1e-9          # W_exc = W_visc + W_friction, point by point
        assert isinstance(r.peak_amplitude, float) and isinstance(r.peak_frequency_hz, float)
        assert r.peak_amplitude == r.blade_peak_amplitudes.max()
        assert r.peak_frequency_hz == r.blade_peak_frequencies_hz[np.argmax(r.blade_peak_amplitudes)]
    assert tuned.blade_peak_amplitudes.shape == (1,)
    assert tuned.peak_amplitude == tuned.tip_amplitude[:, 0].max()
    assert ring.blade_peak_amplitudes.shape == ring.blade_peak_frequencies_hz.shape == (4,)
    np.testing.assert_array_equal(ring.blade_peak_amplitudes, ring.peaks()[0])
    assert np.all(ring.blade_peak_amplitudes >= ring.tip_amplitude[:, :, 0].max(axis=0))   # parabola-refined
    assert ring.tip_amplitude.shape == (len(ring.omega), 4, 3)
    np.testing.assert_array_equal(ring.amplification(), ring.blade_peak_amplitudes / 5e-4)
