"""The typed status of every frequency response (bladedamp.response.Status), derived from the
fields a result has, and the flag of a largest amplitude at an end of the range
(``peak_at_range_end``) with the linear systems' estimate of where the resonance lies."""
import dataclasses
import inspect
import warnings
from pathlib import Path

import numpy as np
import pytest

import bladedamp as bd
from bladedamp.mistuned import MistunedResponse
from bladedamp.blade import reference_blade
from bladedamp.hbm.fourier import HarmonicBasis
from bladedamp.response import (PLAUSIBLE_TIP_DEFLECTION, REFINE_SAMPLES_FACTOR, STATUS_EXPLANATIONS, Note, NoteKind,
                                Status, notes_of, physical_checks, range_end_of_largest, response_status,
                                sampled_response, with_checks, with_note)

DATA = Path(__file__).parent / "data"
# issue 33: a result's status in one plain sentence (aimed at 140 characters; the numbers of the
# case in it), a second one when the largest amplitude lies at an end of the range
SENTENCE_MAX = 160


def sentences(text: str) -> list[str]:
    """The sentences of ``text``, each checked to be plain: one line, at most SENTENCE_MAX characters."""
    assert "\n" not in text and text.endswith(".")
    parts = [p.strip() for p in text[:-1].split(". ")]
    assert all(0 < len(p) <= SENTENCE_MAX for p in parts), [len(p) for p in parts]
    return parts


def oscillator_response(**options):
    """The default friction oscillator over 12-20 Hz, one harmonic (its resonance, near 16-17 Hz,
    lies inside): 0.1 s once compiled."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bd.FrictionOscillator().frequency_response(12.0, 20.0, harmonics=(1,), **options)


@pytest.fixture(scope="module")
def complete():
    return oscillator_response()


# ----- one status for each case, from real solves ------------------------------------------
def test_a_complete_branch_with_its_error_within_the_tolerance_is_verified(complete):
    r = complete
    assert r.reached_range_end and not r.failed_checks and np.isfinite(r.harmonic_error)
    assert r.harmonic_error <= r.harmonic_tolerance
    assert r.status is Status.COMPLETE_VERIFIED and r.success and not r.peak_at_range_end
    first, = sentences(r.status_message)
    assert first.startswith("complete, verified: ") and "(1,)" not in first and "one-harmonic" in first
    assert f"{100 * r.harmonic_error:.2g} %" in first and "tolerance 1 %" in first


def test_a_complete_branch_with_its_error_above_the_tolerance_is_said_so():
    # the same branch held to a tolerance below its estimate (about 3e-4: the one-harmonic
    # oscillator's error against richer sets)
    r = oscillator_response(harmonic_tolerance=1e-6)
    assert r.harmonic_error > 1e-6 and r.harmonics_converged is False
    assert r.status is Status.COMPLETE_ABOVE_TOLERANCE and r.success        # success keeps its meaning
    first, = sentences(r.status_message)
    assert first.startswith("complete, above tolerance: one-harmonic curve")
    assert f"up to {100 * r.harmonic_error:.2g} %" in first and "harmonics='auto' or (0, 1, 2, 3)" in first


def test_a_complete_branch_without_an_estimate_is_unverified():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = bd.reference_disk().frequency_response(92.0, 99.0, harmonics=(1,), max_step=0.05,
                                                   estimate_harmonic_error=False)
    assert r.success and r.harmonics_converged is None and np.isnan(r.harmonic_error)
    assert r.status is Status.COMPLETE_UNVERIFIED and not r.peak_at_range_end
    first, = sentences(r.status_message)
    assert "not estimated" in first and "harmonics='auto'" in first


def test_an_estimate_the_enriched_solve_could_not_verify_is_unverified(complete):
    # what annotate records when the enriched set's Newton fails at the peak: NaN, not converged
    r = dataclasses.replace(complete, harmonic_error=float("nan"), harmonics_converged=False)
    assert r.status is Status.COMPLETE_UNVERIFIED and r.success
    first, = sentences(r.status_message)
    assert "could not be checked" in first and "(0, 1, 2, 3) did not converge" in first


def test_a_complete_branch_that_failed_a_physical_check_is_not_complete(complete):
    r = with_checks(complete, {"dissipation": "negative friction dissipation at 3 points"})
    assert r.reached_range_end and not r.success
    assert r.status is Status.CHECK_FAILED and not r.status.complete
    first, = sentences(r.status_message)
    assert "negative friction dissipation at 3 points" in first and "n_samples" in first


def test_a_branch_stopped_by_the_callers_condition_is_stopped_with_its_reason():
    def stop_when(x, omega):
        return "stopped above 14 Hz" if omega > 2 * np.pi * 14.0 else ""
    r = oscillator_response(stop_when=stop_when)
    assert r.stopped_by == "stopped above 14 Hz" and not r.success
    assert r.status is Status.STOPPED
    first = sentences(r.status_message)[0]
    assert first.startswith("stopped: ") and "stopped above 14 Hz" in first


def test_a_branch_that_runs_out_of_points_is_stopped():
    r = oscillator_response(max_points=5)
    assert not r.reached_range_end and not r.stopped_by
    assert r.status is Status.STOPPED and not r.success
    first, = sentences(r.status_message)
    assert f"ends at {r.frequency_hz[r.furthest_index()]:.2f} Hz" in first
    # the stop is read from the continuation's note, its values, not from its text
    assert notes_of(r, NoteKind.CONTINUATION)[0].values == {"max_points": 5} and len(r.omega) == 5
    assert "all its max_points = 5 points used: raise max_points" in first
    # the same text without the value (a retry's "first try: stopped after max_points"): not said
    plain = dataclasses.replace(r, notes=tuple(Note(n.kind, n.text) for n in r.notes))
    assert "stopped after max_points" in plain.message and "raise max_points" not in plain.status_message


def test_a_budget_stop_is_out_of_budget():
    count = []

    def budget(x, omega):                 # as a budget would: a stop whose reason starts with "budget"
        count.append(omega)
        return "budget: 20 points used" if len(count) >= 20 else ""
    r = oscillator_response(stop_when=budget)
    assert r.stopped_by.startswith("budget") and not r.success and len(r.omega) == 20
    assert r.status is Status.OUT_OF_BUDGET
    first = sentences(r.status_message)[0]
    assert first.startswith("out of budget: 20 points used") and "a partial curve" in first


def test_a_budget_that_runs_out_on_a_richer_set_keeps_the_complete_curve_and_says_so():
    """'auto' with a tolerance (1e-6) that (0, 1) misses (its estimate about 3e-4): (0, 1) reaches
    the end in about 425 points, then the budget of 470 runs out on (0, 1, 2, 3). The complete
    (0, 1) curve is kept, and its status says that, not that it covers part of the range."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = bd.FrictionOscillator().frequency_response(12.0, 20.0, harmonic_tolerance=1e-6, point_budget=470)
    assert r.status is Status.OUT_OF_BUDGET and not r.success and r.stopped_by.startswith("budget")
    assert r.basis.harmonics == (0, 1) and r.reached_range_end
    assert r.frequency_hz.min() == pytest.approx(12.0) and r.frequency_hz.max() == pytest.approx(20.0)
    first, = sentences(r.status_message)
    assert "complete curve of harmonics (0, 1) is kept" in first and "partial" not in first
    assert f"error {100 * r.harmonic_error:.2g} %" in first and "tolerance 0.0001 %" in first


def test_an_empty_branch_is_stopped(complete):
    empty = dataclasses.replace(complete, omega=complete.omega[:0], coefficients=complete.coefficients[:0],
                                success=False, reached_end=False)
    assert empty.status is Status.STOPPED and not empty.peak_at_range_end


# ----- the derivation ---------------------------------------------------------------------
@pytest.mark.parametrize("fields, expected", [
    (dict(success=True, harmonic_error=0.005, harmonic_tolerance=0.01), Status.COMPLETE_VERIFIED),
    (dict(success=True, harmonic_error=0.01, harmonic_tolerance=0.01), Status.COMPLETE_VERIFIED),
    (dict(success=True, harmonic_error=0.02, harmonic_tolerance=0.01), Status.COMPLETE_ABOVE_TOLERANCE),
    (dict(success=True, harmonic_error=float("nan"), harmonic_tolerance=0.01), Status.COMPLETE_UNVERIFIED),
    (dict(success=True, harmonic_error=0.005, harmonic_tolerance=float("nan")), Status.COMPLETE_UNVERIFIED),
    (dict(success=False, reached_end=True, failed_checks={"step": "x"}), Status.CHECK_FAILED),
    (dict(success=False, reached_end=None), Status.STOPPED),
    (dict(success=False, reached_end=False, failed_checks={"dissipation": "x"}), Status.STOPPED),
    (dict(success=False, stopped_by="peak above 0.1 mm"), Status.STOPPED),
    (dict(success=False, stopped_by="budget: 120 CPU s"), Status.OUT_OF_BUDGET),
])
def test_the_status_follows_from_the_fields(complete, fields, expected):
    r = dataclasses.replace(complete, **fields)
    assert response_status(r) is expected and r.status is expected
    assert r.status.complete == r.success                     # success is exactly the complete statuses
    assert r.status_message.startswith(expected.value + ": ")
    sentences(r.status_message)


def test_every_status_explains_itself_in_one_sentence():
    assert set(STATUS_EXPLANATIONS) == set(Status)
    texts = [s.explanation for s in Status]
    assert len(set(texts)) == len(texts)
    assert all(t and "." not in t.replace("e.g.", "") and "\n" not in t and len(t) <= SENTENCE_MAX for t in texts)
    assert all(any(w in t for w in ("run", "raise", "trust", "need not")) for t in texts)
    assert bd.Status is Status


@pytest.mark.parametrize("cls", [bd.FrequencyResponse, bd.DiskResponse, MistunedResponse], ids=lambda c: c.__name__)
def test_every_response_has_the_status_and_the_range_end_flag(cls):
    for name in ("status", "status_message", "peak_at_range_end"):
        assert isinstance(inspect.getattr_static(cls, name), property), (cls, name)
    assert "linear_natural_frequencies_hz" in {f.name for f in dataclasses.fields(cls)}


# ----- saved results ------------------------------------------------------------------------
def test_results_saved_before_the_status_load_with_one():
    """Files written by bladedamp before the status and the range-end flag existed (main 427345c):
    an oscillator over 12-20 Hz (harmonics (1,)) and the 1 kg cylinder disk over 90-105 Hz."""
    old = bd.load(DATA / "oscillator_response_v1.npz")
    assert old.linear_natural_frequencies_hz == ()
    assert old.status is Status.COMPLETE_VERIFIED and not old.peak_at_range_end
    disk = bd.load(DATA / "disk_response_v1.npz")
    assert disk.status is Status.COMPLETE_VERIFIED and disk.peak_at_range_end
    # the estimate of where needs the model, which the file does not hold: the side is still said
    status, end = sentences(disk.status_message)
    assert "the range end (105 Hz), no resonance" in end and "may lie above" in end
    assert "stuck" not in end


def test_save_and_load_keep_the_status_and_the_estimate(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = bd.FrictionOscillator().frequency_response(12.0, 14.0, harmonics=(1,))
    loaded = bd.load(r.save(tmp_path / "r"))
    assert loaded.linear_natural_frequencies_hz == r.linear_natural_frequencies_hz and len(r.linear_natural_frequencies_hz) == 2
    assert loaded.status is r.status and loaded.status_message == r.status_message and loaded.peak_at_range_end


# ----- the largest amplitude at an end of the range -------------------------------------------
def test_range_end_of_largest_on_known_curves():
    f = np.linspace(90.0, 105.0, 31)
    assert range_end_of_largest(f, np.exp(-(f - 97.0) ** 2)) is None            # a peak inside
    assert range_end_of_largest(f, f) == 105.0                                   # rising to the end
    assert range_end_of_largest(f, 200.0 - f) == 90.0                            # falling from the start
    assert range_end_of_largest(f[::-1], f[::-1]) == 105.0                       # a downward sweep
    flat = np.where(f > 100.0, 1.0, 0.5)
    flat[-2] = 1.0 + 1e-10                                                       # a flat top: unresolved
    assert range_end_of_largest(f, flat) == 105.0
    flat[-2] = 1.0 + 1e-6
    assert range_end_of_largest(f, flat) is None
    # a fold: the branch goes back before the end, its largest at the end's frequency
    folded = np.array([90.0, 95.0, 100.0, 105.0, 104.0, 105.0])
    assert range_end_of_largest(folded, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) == 105.0
    # several curves (blades): any curve whose largest lies at an end
    two = np.stack([np.exp(-(f - 97.0) ** 2), 0.1 * f], axis=1)
    assert range_end_of_largest(f, two) == 105.0
    assert range_end_of_largest(f[:0], f[:0]) is None


def test_a_oscillator_peak_beyond_the_range_is_flagged_and_bracketed():
    """The oscillator's resonance lies between its linear frequencies without the contact and with
    it stuck, sqrt(k / m) and sqrt((k + k_T) / m); over 12-14 Hz the curve still rises at 14 Hz."""
    osc = bd.FrictionOscillator()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        short = osc.frequency_response(12.0, 14.0, harmonics=(1,))
        wide = osc.frequency_response(12.0, 26.0, harmonics=(1,))
    free, stuck = short.linear_natural_frequencies_hz
    assert free == pytest.approx(np.sqrt(1e4 / 1.0) / (2 * np.pi), rel=1e-14)
    assert stuck == pytest.approx(np.sqrt(2e4 / 1.0) / (2 * np.pi), rel=1e-14)
    assert short.peak_at_range_end and short.status is Status.COMPLETE_VERIFIED
    assert not wide.peak_at_range_end and wide.linear_natural_frequencies_hz == ()
    assert 14.0 < wide.peak_frequency_hz and free < wide.peak_frequency_hz < stuck
    for text in (short.message, sentences(short.status_message)[1]):
        assert "range end (14 Hz), no resonance: one may lie above" in text
        assert f"between {free:.4g} Hz (no contacts) and {stuck:.4g} Hz (stuck)" in text


@pytest.fixture(scope="module")
def heavy_cylinder():
    """The reference disk with a 1 kg cylinder (implausible on purpose: it sticks, and its
    resonance moves from 95 Hz to 109.65 Hz, out of the usual range)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bd.reference_disk("cylinder", 1.0)


def test_a_disk_peak_beyond_the_range_is_flagged_and_bracketed(heavy_cylinder):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        short = heavy_cylinder.frequency_response(90.0, 105.0)
        beyond = heavy_cylinder.frequency_response(105.0, 115.0)
    assert short.success and short.peak_at_range_end and short.peak_frequency_hz == pytest.approx(105.0, abs=1e-9)
    # the true resonance, solved on the branch by the peak condition: 1.603 mm at 109.65 Hz
    amplitude, f_res = heavy_cylinder.solve_peak(beyond)
    assert not beyond.peak_at_range_end
    assert 1e3 * amplitude == pytest.approx(1.603, abs=5e-4) and f_res == pytest.approx(109.65, abs=5e-3)
    free, stuck = short.linear_natural_frequencies_hz
    assert free == pytest.approx(95.0, rel=1e-9)             # the blade's 1F (Table 1) without dampers
    assert free <= f_res <= stuck                             # friction softens: at most the stuck frequency
    assert stuck - f_res < 0.01                               # a 1 kg damper nearly sticks
    for text in (short.message, sentences(short.status_message)[1]):
        assert "range end (105 Hz), no resonance: one may lie above" in text
        assert f"between {free:.4g} Hz (no contacts) and {stuck:.4g} Hz (stuck)" in text


def test_the_reference_disk_over_its_range_is_not_flagged():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = bd.reference_disk().frequency_response(92.0, 99.0, harmonics=(1,), max_step=0.05)
    assert r.success and not r.peak_at_range_end and r.linear_natural_frequencies_hz == ()
    assert "range end" not in r.status_message and "range end" not in r.message


def test_a_mistuned_response_has_a_status_a_stop_reason_and_one_range_end_flag():
    """Four blades, 1 g cylinders, 2 % mistuning: over 92-99 Hz every blade's peak lies inside
    (tests/test_api.py); stopped by the caller at 95 Hz the curves still rise at the stop."""
    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    disk = bd.MistunedDisk.from_tuned(td, [1.01, 0.99, 1.02, 1.0])

    def stop_when(x, omega):
        return "budget: stopped at 95 Hz" if omega > 2 * np.pi * 95.0 else ""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = disk.frequency_response(92.0, 99.0, harmonics=(1,), max_step=0.1)
        part = disk.frequency_response(92.0, 99.0, harmonics=(1,), max_step=0.1, stop_when=stop_when)
    assert full.status is Status.COMPLETE_VERIFIED and full.peak_at_range_end is False
    assert part.stopped_by == "budget: stopped at 95 Hz" and part.status is Status.OUT_OF_BUDGET
    assert part.peak_at_range_end is True and part.linear_natural_frequencies_hz == ()
    first, = sentences(part.status_message)                 # its last point is no range end
    assert "stopped at 95 Hz" in first and "a partial curve" in first and "need not be the resonance" in first


# ----- an amplitude the model cannot have (issue 32) -----------------------------------------
def test_the_plausible_deflection_is_where_the_linear_cantilever_is_one_percent_off():
    """PLAUSIBLE_TIP_DEFLECTION's reason, independently: the elastica of an end-loaded cantilever
    (EI theta'' = -P cos theta, theta(0) = 0, theta'(L) = 0; Bisshopp & Drucker 1945) against the
    linear theory's tip deflection P L^3 / (3 EI): 1 % apart at a deflection of 10 % of L."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    def tip(alpha):                                    # alpha = P L^2 / EI, L = 1
        def rhs(_, y):
            return [y[1], -alpha * np.cos(y[0]), np.sin(y[0])]

        def end(k0):
            return solve_ivp(rhs, (0, 1), [0, k0, 0], rtol=1e-11, atol=1e-13).y[:, -1]
        k0 = brentq(lambda k: end(k)[1], 0, 1.01 * alpha)
        return end(k0)[2]
    alpha = brentq(lambda a: tip(a) - PLAUSIBLE_TIP_DEFLECTION, 0.1, 1.0)
    linear = alpha / 3
    assert linear / PLAUSIBLE_TIP_DEFLECTION - 1 == pytest.approx(0.01, abs=0.001)


@pytest.fixture(scope="module")
def undamped_light_cylinder():
    """issue 32: a 0.05 g cylinder on blades without viscous damping, one harmonic: its friction
    cannot hold the resonance, and the branch reaches the end with a 1.69 m tip amplitude."""
    blade = dataclasses.replace(reference_blade(), damping_ratios=np.zeros(4))
    disk = dataclasses.replace(bd.reference_disk("cylinder", 5e-5), blade=blade)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return disk.frequency_response(90.0, 105.0, harmonics=(1,))


def test_an_amplitude_beyond_small_deformations_is_no_success(undamped_light_cylinder):
    r = undamped_light_cylinder
    span = 0.2                                                   # the reference blade: root to tip [m]
    assert r.reached_range_end and r.peak_amplitude > 1.0        # 1.69 m
    assert r.status is Status.CHECK_FAILED and not r.success and set(r.failed_checks) == {"amplitude"}
    first, = sentences(r.status_message)
    assert f"{1e3 * r.peak_amplitude:.4g} mm" in first and f"{100 * r.peak_amplitude / span:.0f} %" in first
    assert "small-deformation" in first and "add damping" in first


def test_the_span_is_the_blades_root_to_tip():
    from bladedamp.diskmodel import blade_span

    td = dataclasses.replace(bd.reference_disk("cylinder", 1e-3), n_blades=4)
    assert blade_span(td) == pytest.approx(0.2, rel=1e-12)                    # Table 1's 60 + 140 mm
    assert blade_span(bd.MistunedDisk.from_tuned(td, [1.01, 0.99, 1.02, 1.0])) == pytest.approx(0.2, rel=1e-12)


def test_the_amplitude_check_passes_the_reference_designs(complete):
    """The reference disk's 1 g cylinder (0.49 mm) and its damper-free blade (1.7 mm, 0.85 % of the
    span) lie far inside the bound; the largest random design (excitation x10, no damper) 8.5 %."""
    from bladedamp.response import amplitude_check

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        free = bd.reference_disk(None).frequency_response(92.0, 99.0, harmonics=(1,), max_step=0.05)
    assert free.success and free.peak_amplitude == pytest.approx(1.7e-3, rel=0.01)
    assert amplitude_check(free, 0.2) == {} and amplitude_check(complete, 0.2) == {}
    assert amplitude_check(free, free.peak_amplitude / (PLAUSIBLE_TIP_DEFLECTION * 1.001))   # just beyond: fails


# ----- the AFT's energy error where the dissipation check fails at the most samples ---------
def test_a_failed_dissipation_check_states_the_aft_energy_error(complete):
    w = np.linspace(10.0, 20.0, 11)
    d = np.zeros((11, 1))
    d[5] = -0.01                                            # -1 % at the solve's samples
    failed = physical_checks(w, (10.0, 20.0), d, np.ones(11), None, 4096,
                             refine=lambda i: np.full((len(i), 1), -1e-4))   # -0.01 % with 16 x the samples
    assert f"AFT energy error -1 % with the solve's 4096" in failed["dissipation"]
    assert f"-0.01 % of the excitation work there with {REFINE_SAMPLES_FACTOR * 4096}" in failed["dissipation"]
    r = with_checks(complete, failed)
    first, = sentences(r.status_message)
    assert r.status is Status.CHECK_FAILED and "AFT energy error -1 %" in first and "n_samples" in first

    def solve(n):                 # a branch whose dissipation fails at every sample count
        return with_checks(dataclasses.replace(complete, basis=HarmonicBasis((1,), n)), failed)
    r = sampled_response(solve, None, 256, 4096)
    assert r.basis.n_samples == 4096 and "raised to 4096 (the most)" in r.message
    assert "AFT energy error -1 %" in r.status_message


# ----- notes: the result's message as typed notes (issue 34 item 5) ----------------------------
def test_notes_keep_their_order_and_the_message_is_the_old_concatenation(complete):
    """A branch that fails its dissipation check with 256 AFT samples and passes with 1024, then
    fails a step check: its notes in the order the steps added them, and its message the string
    the steps built before notes existed (each appended "; " and its text to the message)."""
    failed = {"dissipation": "negative friction dissipation at 1 points"}

    def solve(n):
        r = dataclasses.replace(complete, basis=HarmonicBasis((1,), n))
        return r if n >= 1024 else with_checks(r, failed)
    r = with_checks(sampled_response(solve, None, 256, 4096), {"step": "a step of 1 Hz"})
    assert [n.kind for n in r.notes] == [NoteKind.CONTINUATION, NoteKind.AFT_SAMPLES, NoteKind.FAILED_CHECKS]
    old = complete.message
    old = old + "; AFT samples per period raised to 1024 (the branch failed with 256)"     # sampled_response's
    old = old + "; failed checks: " + "; ".join(f"{k}: {v}" for k, v in {"step": "a step of 1 Hz"}.items())
    assert r.message == old and complete.message == "reached the end of the frequency range"
    assert r.notes[0] == complete.notes[0] and r.status is Status.CHECK_FAILED
    # the harmonic estimate above the tolerance: the continuation's note, then the estimate's
    above = oscillator_response(harmonic_tolerance=1e-6)
    assert [n.kind for n in above.notes] == [NoteKind.CONTINUATION, NoteKind.HARMONIC_ESTIMATE]
    assert above.message == f"{above.notes[0].text}; {above.notes[1].text}"
    assert above.notes[1].text.startswith(f"harmonic error estimate {100 * above.harmonic_error:.2g} % exceeds")


def test_a_message_given_as_text_is_one_continuation_note(complete):
    """The compatible path: a message passed to the constructor (from a branch, a file saved
    before notes existed, ``dataclasses.replace(r, message=...)``) is the whole message, one note;
    ``replace`` without one keeps the notes; ``with_note`` appends."""
    r = with_note(complete, Note(NoteKind.RANGE_END, "the largest amplitude is at the range end"))
    assert dataclasses.replace(r, success=False).notes == r.notes
    told = dataclasses.replace(r, message="as told")
    assert told.message == "as told" and told.notes == (Note(NoteKind.CONTINUATION, "as told"),)
    built = bd.FrequencyResponse(r.omega, r.coefficients, r.basis, r.dof_names, True, "reached the end")
    assert built.notes == (Note(NoteKind.CONTINUATION, "reached the end"),)
    again = bd.FrequencyResponse(r.omega, r.coefficients, r.basis, r.dof_names, True, r.message)   # its text
    assert again.message == r.message and again.notes == (Note(NoteKind.CONTINUATION, r.message),)
    with pytest.raises(AttributeError):
        r.message = "x"                                          # derived: read only
    with pytest.raises(ValueError, match="kind"):
        Note("range end", "text")
    with pytest.raises(ValueError, match="notes"):
        dataclasses.replace(r, notes=("text",))
