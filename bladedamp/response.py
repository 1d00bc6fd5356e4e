"""Result objects of frequency responses: named arrays and ``.plot()``."""
from __future__ import annotations

import dataclasses
import enum
import re
import textwrap
from dataclasses import dataclass, field

import numpy as np

from .hbm.continuation import branch_checks
from .hbm.peaks import PeakSolver
from .hbm.sensitivity import output_sensitivities, peak_sensitivities, state_sensitivities
from .hbm.fourier import HarmonicBasis, enriched
from .io import Saveable


# The AFT samples of the refined re-evaluation of a suspect dissipation, per sample of the solve
REFINE_SAMPLES_FACTOR = 16
# Negative dissipation beyond this fraction of the excitation work is not rounding: re-evaluated
ROUNDING = 1e-9
# ... and beyond this fraction once re-evaluated, an AFT sampling error too large to accept
SAMPLING_FLOOR = 1e-6


def physical_checks(omega, omega_range, dissipation, excitation_work, max_step=None,
                    n_samples: int = 64, refine=None, work_bound=None,
                    judge_solution_samples: bool = False) -> dict[str, str]:
    """Sanity of a branch beyond the energy balance (which holds for any harmonic truncation).

    ``omega`` (n,) [rad/s]; ``omega_range`` (start, end) [rad/s]; ``dissipation`` (n, m) energy
    absorbed per period by each of m friction contacts or contact points [J];
    ``excitation_work`` (n,) [J]; ``max_step``: largest allowed frequency step as a fraction of
    the range (None: unchecked); ``n_samples``: the AFT's time samples per period T;
    ``refine``: ``indices -> (k, m)`` the same dissipation at those points re-evaluated (same
    harmonic coefficients) with ``REFINE_SAMPLES_FACTOR`` times the AFT samples, or None;
    ``work_bound`` (n, m): each contact's energy scale, the largest work its force and motion
    harmonics could do (:meth:`bladedamp.hbm.fourier.HarmonicBasis.work_bound`) [J], or None.
    Returns {check: what was found} for every failed check (empty: all pass):

    * ``range``: every point inside the requested range (no negative frequency, no point
      beyond the ends);
    * ``dissipation``: each contact's dissipation >= 0 at every point. A Jenkins contact driven
      by any periodic motion, band-limited or not, absorbs oint T du = oint T dw >= 0 whatever
      its normal load does (T = 0 while separated, T dw >= 0 while slipping, oint T dT = 0), and
      by Parseval that is the work of its retained harmonics on a harmonic-balance motion: so a
      negative value is never the harmonic truncation but always the AFT's time sampling (a
      stick-slip or lift-off event between two of the T samples), or a non-passive element.
      A point below -``ROUNDING`` of the excitation work is re-evaluated with ``refine``
      (``REFINE_SAMPLES_FACTOR`` T samples, same coefficients) and fails if it is still below
      -``SAMPLING_FLOOR`` there: an energy error four orders below the 1 % accuracy target is
      accepted, a larger one is not. Both are fractions of the point's energy scale: the larger
      of the excitation work and the contact's own ``work_bound``. A force-harmonic error eps
      (the sampling's) shifts the contact's work by up to eps times its bound, so off resonance,
      where the excitation work nearly vanishes but a stuck or elastic contact still stores
      energy, the excitation work alone would judge a rounding-sized force error as a failure
      (an error of either sign that converges to >= 0 with the samples; examples:
      benchmarks/README.md, 'Moved from the package's docstrings', response.py).
      Without ``refine`` the floor is the sampling error's order, -(2 pi / T)^2 of the
      excitation work. With ``judge_solution_samples`` the dissipation at the solve's own T
      samples, which the result reports, is held to the same floor: a point below
      -``SAMPLING_FLOOR`` of its energy scale there fails even where the refined value passes
      (the AFT's energy error on the contact's own scale is then larger than the floor; more
      samples cure it: :func:`sampled_response`), so a result that passes reports no
      dissipation below -``SAMPLING_FLOOR`` of its energy scale;
    * ``step``: no step between neighbouring points longer in frequency than ``max_step``
      allows. Range and step are :func:`bladedamp.hbm.continuation.branch_checks`, the
      continuation's own contract, checked again on the result.
    """
    omega = np.asarray(omega, dtype=float)
    failed = {}
    if omega.size == 0:
        return failed
    lo, hi = min(omega_range), max(omega_range)
    contract = branch_checks(omega, lo, hi, np.inf if max_step is None else max_step)   # the continuation's own
    if not contract["inside_range"]:
        outside = (omega < lo) | (omega > hi)
        failed["range"] = (f"{int(outside.sum())} points outside {lo / (2 * np.pi):.6g}-{hi / (2 * np.pi):.6g} Hz "
                           f"(down to {omega.min() / (2 * np.pi):.6g} Hz, up to {omega.max() / (2 * np.pi):.6g} Hz)")
    d = np.atleast_2d(np.asarray(dissipation, dtype=float).reshape(omega.size, -1))
    scale = np.maximum(np.abs(np.asarray(excitation_work, dtype=float)), 1e-300)[:, None] * np.ones(d.shape[1])
    if work_bound is not None:
        scale = np.maximum(scale, np.asarray(work_bound, dtype=float).reshape(d.shape))
    relative = (d / scale).min(axis=1, initial=0.0)       # each contact against its own scale
    if refine is None:
        bad, how = relative < -(2 * np.pi / n_samples) ** 2, ""
    else:
        own = relative.copy()
        suspect = np.flatnonzero(relative < -ROUNDING)
        if suspect.size:
            fine = np.atleast_2d(np.asarray(refine(suspect), dtype=float).reshape(suspect.size, -1))
            relative[suspect] = (fine / scale[suspect]).min(axis=1, initial=0.0)
        bad = relative < -SAMPLING_FLOOR
        how = f", confirmed with {REFINE_SAMPLES_FACTOR * n_samples} AFT samples per period"
        if bad.any():         # the AFT's energy error of the result itself, at the solve's own samples
            how = (f" with {REFINE_SAMPLES_FACTOR * n_samples} AFT samples per period; AFT energy error "
                   f"{100 * own[bad].min():.3g} % with the solve's {n_samples}")
        if judge_solution_samples and not bad.any() and (own < -SAMPLING_FLOOR).any():
            bad, relative = own < -SAMPLING_FLOOR, own
            how = (f" with {n_samples} AFT samples per period: the AFT's energy error, since with "
                   f"{REFINE_SAMPLES_FACTOR * n_samples} on the same coefficients it is above -{SAMPLING_FLOOR:g} of "
                   f"that scale; more samples per period cure it")
    if bad.any():
        of = "the excitation work" if work_bound is None else "the energy scale (excitation work or the contact's)"
        failed["dissipation"] = (f"negative friction dissipation at {int(bad.sum())} points "
                                 f"(down to {100 * relative[bad].min():.3g} % of {of} there{how})")
    if not contract["step_within_max_step"]:
        failed["step"] = (f"a step of {np.abs(np.diff(omega)).max() / (2 * np.pi):.4g} Hz, longer than max_step = "
                          f"{max_step:g} of the range allows ({max_step * (hi - lo) / (2 * np.pi):.4g} Hz)")
    return failed


# Automatic AFT sampling (sampled_response): the samples per period grow by this factor while
# the dissipation check fails
SAMPLES_GROWTH = 4


def sampled_response(solve, n_samples, first: int, most: int, most_for_dissipation: int | None = None):
    """``solve(n) -> response`` (a branch computed with n AFT samples per period and checked by
    :func:`physical_checks`) with the samples chosen: ``n_samples`` given, once; None
    (automatic), from ``first`` samples, ``SAMPLES_GROWTH`` times more while the branch is not
    ``success`` (it failed the dissipation check, or did not reach the end: the start and the
    continuation too may fail on a coarse AFT), up to ``most``.

    A negative dissipation is the AFT's sampling error (see :func:`physical_checks`), and the
    forces' harmonics carry an error of the same order, which a lightly damped resonance
    amplifies until the branch turns back or stalls (examples: benchmarks/README.md, 'Moved from
    the package's docstrings', response.py).
    ``most_for_dissipation`` (default ``most``): a branch that reached the end of its range and
    failed only the dissipation check may grow up to this many samples. Its failure is the AFT's
    sampling error, which more samples cure at the cost of one more branch, whereas a branch
    that stalled with 4x the samples seldom reaches the end with 16x.
    The finer branch replaces the coarser unless it keeps no point; the message says how the
    samples were chosen."""
    if n_samples is not None:
        return solve(n_samples)
    n, tried, response, empty, stopped_by = int(first), [], None, None, ""
    while True:
        finer = solve(n)
        if response is not None and not len(finer.omega):
            empty, stopped_by = n, finer.stopped_by   # the coarser branch is kept (and the stop, e.g. a budget)
            break
        response = finer
        if response.stopped_by:                       # stopped as the caller asked: no retry
            break
        limit = most if most_for_dissipation is None or not only_sampling_failed(response) else most_for_dissipation
        if response.success or n * SAMPLES_GROWTH > limit:
            break
        tried.append(n)
        n *= SAMPLES_GROWTH
    n_used = response.basis.n_samples
    failed_with = [str(t) for t in tried if t != n_used]
    notes = []
    most = not response.success and n_used * SAMPLES_GROWTH > (
        most if most_for_dissipation is None or not only_sampling_failed(response) else most_for_dissipation)
    if failed_with:
        notes.append(f"AFT samples per period raised to {n_used}{' (the most)' if most else ''} (the branch failed "
                     f"with {', '.join(failed_with)})")
    if empty is not None:
        notes.append(f"with {empty} AFT samples per period the branch kept no point"
                     + (f": {stopped_by}" if stopped_by else ""))
    changes = dict(success=False, stopped_by=stopped_by) if stopped_by else {}
    if notes or changes:
        notes = tuple(Note(NoteKind.AFT_SAMPLES, text) for text in notes)
        return dataclasses.replace(response, notes=(*response.notes, *notes), **changes)
    return response


def refined_peak(frequency_hz, amplitude, i: int | None = None) -> tuple[float, float]:
    """(peak, frequency [Hz]) of the samples ``amplitude`` (n,) at ``frequency_hz`` (n,): sample
    ``i`` (default the largest) refined by the parabola through it and its two neighbours, when
    they rise to it from both sides and the vertex lies between them; else the sample itself."""
    f, a = np.asarray(frequency_hz, dtype=float), np.asarray(amplitude, dtype=float)
    i = int(np.argmax(a)) if i is None else int(i)
    peak, fp = float(a[i]), float(f[i])
    if 0 < i < len(a) - 1:
        x, y = f[i - 1:i + 2], a[i - 1:i + 2]
        if np.all(np.diff(x) > 0):
            c = np.polyfit(x - x[1], y, 2)
            if c[0] < 0:
                fv = -c[1] / (2 * c[0])
                if x[0] - x[1] <= fv <= x[2] - x[1]:
                    peak, fp = max(peak, float(np.polyval(c, fv))), float(x[1] + fv)
    return peak, fp


def only_sampling_failed(response) -> bool:
    """Whether ``response`` reached the end of its range and failed only the dissipation check
    (the AFT's sampling error, see :func:`physical_checks`)."""
    return set(response.failed_checks) == {"dissipation"} and bool(response.reached_end)


def with_checks(response, failed: dict):
    """``response`` with its failed checks recorded (added to those it had): not ``success``, the
    message says why."""
    if not failed:
        return response
    note = Note(NoteKind.FAILED_CHECKS, "failed checks: " + "; ".join(f"{k}: {v}" for k, v in failed.items()))
    return with_note(response, note, success=False, failed_checks={**(response.failed_checks or {}), **failed},
                     reached_end=response.reached_range_end)


class NoteKind(enum.Enum):
    """What a :class:`Note` of a frequency response says: the closed set of notes the package
    adds to a result, in the order a computation adds them (the value is a short name)."""

    CONTINUATION = "continuation"           # the continuation's own message: how the branch ended
    AFT_SAMPLES = "AFT samples"             # sampled_response: how the AFT samples were chosen
    FAILED_CHECKS = "failed checks"         # with_checks: the physical checks that failed
    HARMONIC_ESTIMATE = "harmonic estimate"  # the estimate above the tolerance or not verified
    HARMONIC_SEARCH = "harmonic search"     # harmonics='auto': a richer set not finished or not tried
    RETENTION = "retention"                 # a peak held by the static retention spring: not verified
    PEAK_CHECK = "peak check"               # the time integration at the peak, or how to run it
    STOP_CHECK = "stop check"               # where and why the branch stopped, the time integration beyond
    RANGE_END = "range end"                 # the largest amplitude at an end of the range


@dataclass(frozen=True)
class Note:
    """One note of a frequency response (:attr:`FrequencyResponse.notes`): its ``kind`` (a
    :class:`NoteKind`), the sentence ``text`` a user reads, and ``values``: {name: number} a
    program reads instead of parsing the text (e.g. ``{"max_points": 5000}`` on the
    CONTINUATION note of a branch that used up its points, :func:`continuation_note`)."""

    kind: NoteKind
    text: str
    values: dict = field(default_factory=dict, hash=False)

    def __post_init__(self):
        if not isinstance(self.kind, NoteKind):
            raise ValueError(f"kind must be a bladedamp.response.NoteKind (got {self.kind!r})")
        if not isinstance(self.text, str):
            raise ValueError(f"text must be a str (got {type(self.text).__name__})")


#: what separates the notes in a response's message
NOTE_SEPARATOR = "; "


class NotesText(str):
    """The text of a response's notes joined by ``NOTE_SEPARATOR`` (its :attr:`~FrequencyResponse.message`),
    a str. A constructor given one with notes keeps the notes (``dataclasses.replace`` passes the
    message it reads back), whereas a plain str given as ``message`` is the whole message."""


def notes_text(notes) -> NotesText:
    """The message of ``notes`` (a sequence of :class:`Note`): their texts joined in order."""
    return NotesText(NOTE_SEPARATOR.join(n.text for n in notes))


def with_note(response, note: Note, **changes):
    """``response`` with ``note`` added after its notes (and the field ``changes``, as
    ``dataclasses.replace``): the one way a result's message grows."""
    return dataclasses.replace(response, notes=(*response.notes, note), **changes)


def continuation_note(branch) -> Note:
    """The CONTINUATION note of a :class:`~bladedamp.hbm.continuation.Branch`: its message, and
    ``values`` {"max_points": n} where it used up its n points before the end of its range."""
    return Note(NoteKind.CONTINUATION, str(branch.message),
                {"max_points": int(branch.out_of_points)} if branch.out_of_points else {})


def notes_of(response, kind: NoteKind) -> tuple:
    """The notes of ``response`` of ``kind``, in order (none for a response without notes)."""
    return tuple(n for n in getattr(response, "notes", ()) if n.kind is kind)


class Status(enum.Enum):
    """What a frequency response can be trusted for: one value per result, derived from its
    fields by :func:`response_status` (:attr:`FrequencyResponse.status`). The value is the
    short name; :attr:`explanation` says in one sentence what it means and what to do."""

    COMPLETE_VERIFIED = "complete, verified"
    COMPLETE_UNVERIFIED = "complete, unverified"
    COMPLETE_ABOVE_TOLERANCE = "complete, above tolerance"
    CHECK_FAILED = "check failed"
    STOPPED = "stopped"
    OUT_OF_BUDGET = "out of budget"

    @property
    def complete(self) -> bool:
        """Whether the branch reached the end of its range with every check passing: the
        statuses of a ``success`` response."""
        return self in (Status.COMPLETE_VERIFIED, Status.COMPLETE_UNVERIFIED, Status.COMPLETE_ABOVE_TOLERANCE)

    @property
    def explanation(self) -> str:
        """What the status means and what to do, one sentence."""
        return STATUS_EXPLANATIONS[self]


STATUS_EXPLANATIONS = {
    Status.COMPLETE_VERIFIED: "the whole range is computed and its harmonic error is within the tolerance: "
                              "trust the curve to that tolerance",
    Status.COMPLETE_UNVERIFIED: "the whole range is computed but its harmonic error is unknown: run with "
                                "harmonics='auto' or check the peak (check_peak=True)",
    Status.COMPLETE_ABOVE_TOLERANCE: "the whole range is computed but its amplitudes may be off by the error "
                                     "estimate: run with a richer harmonic set",
    Status.CHECK_FAILED: "the whole range is computed but a physical check failed (failed_checks): do not "
                         "trust its numbers",
    Status.STOPPED: "the branch stopped before the end of the range: its largest amplitude need not be the "
                    "resonance",
    Status.OUT_OF_BUDGET: "the CPU or point budget ran out: raise it (cpu_budget_s, point_budget) or narrow "
                          "the range",
}

#: a response whose ``stopped_by`` starts with this word ran out of its point or CPU budget
BUDGET_PREFIX = "budget"
# An end point's amplitude within this fraction of the largest counts as the largest (the
# continuation solves each point to a scaled tolerance of 1e-10: two points that differ by
# less than 1e-8 of the peak are not told apart)
END_AMPLITUDE_RESOLUTION = 1e-8


def response_status(response) -> Status:
    """The :class:`Status` of ``response`` (any frequency response) from the fields it has:

    * ``stopped_by`` starting with ``"budget"``: OUT_OF_BUDGET;
    * no point, another ``stopped_by``, or the end of the range not reached
      (:attr:`FrequencyResponse.reached_range_end`): STOPPED;
    * the end reached, not ``success`` (a physical check failed): CHECK_FAILED;
    * else, from ``harmonic_error`` e and ``harmonic_tolerance`` tol: e or tol not finite (not
      estimated, or the enriched solve failed: not verified) COMPLETE_UNVERIFIED; e <= tol
      COMPLETE_VERIFIED; e > tol COMPLETE_ABOVE_TOLERANCE.

    ``success`` is True exactly for the three COMPLETE statuses (:attr:`Status.complete`)."""
    stopped_by = response.stopped_by or ""
    if stopped_by.startswith(BUDGET_PREFIX):
        return Status.OUT_OF_BUDGET
    if not len(response.omega) or stopped_by or not response.reached_range_end:
        return Status.STOPPED
    if not response.success:
        return Status.CHECK_FAILED
    error, tolerance = float(response.harmonic_error), float(response.harmonic_tolerance)
    if not (np.isfinite(error) and np.isfinite(tolerance)):
        return Status.COMPLETE_UNVERIFIED
    return Status.COMPLETE_VERIFIED if error <= tolerance else Status.COMPLETE_ABOVE_TOLERANCE


def range_end_of_largest(frequency_hz, amplitude) -> float | None:
    """The end of the computed range [Hz] (the lowest or highest of ``frequency_hz`` (n,)) at
    which the largest of ``amplitude`` (n,) lies, or None when it lies inside: a point at an end
    whose amplitude is within ``END_AMPLITUDE_RESOLUTION`` of the largest counts as holding it
    (both ends: the one with the larger amplitude). There the range holds no maximum: the curve
    still rises towards that end. ``amplitude`` (n, k): k curves (e.g. one per blade), the end
    of the largest curve whose largest lies at an end. None for an empty branch, and for curves
    that are zero everywhere (at rest: no resonance to miss)."""
    f, a = np.asarray(frequency_hz, dtype=float), np.asarray(amplitude, dtype=float)
    if not f.size:
        return None
    a = a.reshape(f.size, -1)
    same = 1e-12 * max(float(np.abs(f).max()), 1e-300)          # the same frequency, to rounding
    low, high = f <= f.min() + same, f >= f.max() - same
    found = []
    for curve in a.T:
        if not curve.max() > 0:
            continue                     # no motion at all (a response at rest): no resonance anywhere
        best, end = max((float(curve[low].max()), float(f.min())), (float(curve[high].max()), float(f.max())))
        if best >= (1 - END_AMPLITUDE_RESOLUTION) * curve.max():
            found.append((best, end))
    return max(found)[1] if found else None


def range_end_note(response) -> str:
    """The sentence of a response whose largest amplitude lies at an end of its range
    (:attr:`FrequencyResponse.peak_at_range_end`; '' otherwise): not a resonance, which may lie
    outside the range, and where, from ``linear_natural_frequencies_hz`` (the natural
    frequencies nearest the range of the linear systems without the friction contacts and with
    them stuck) when the model gave them. A friction contact's tangential stiffness lies between
    none and the stuck one, so its resonance lies between these two frequencies (up to the shift
    of the contact's own inertia)."""
    f = response.frequency_hz
    end = range_end_of_largest(f, response.peak_curve())
    if end is None:
        return ""
    side = "above" if end == f.max() and f.max() > f.min() else "below"
    where = f"one may lie {side}"
    bounds = tuple(response.linear_natural_frequencies_hz or ())
    if len(bounds) == 2 and all(np.isfinite(bounds)):
        free, stuck = bounds
        where += f", between {free:.4g} Hz (no contacts) and {stuck:.4g} Hz (stuck)"
    return f"the largest amplitude is at the range end ({end:.6g} Hz), no resonance: {where}; widen the range"


def percent(x: float) -> str:
    """``x`` (a fraction) in percent for a sentence: two significant digits, whole numbers from 10 %."""
    return f"{100 * x:.0f} %" if abs(100 * x) >= 10 else f"{100 * x:.2g} %"


def harmonic_sentence(harmonics, error: float, tolerance: float, drifting: bool = False, estimated: bool = False,
                      checkable: bool = False) -> str:
    """One sentence on the harmonic accuracy of a curve computed with ``harmonics``, its error
    estimate ``error`` (a fraction of the peak) held to ``tolerance``: what it means and what to
    do. ``error`` nan: not estimated, or with ``estimated`` estimated but not verified (the
    richer set did not converge at the peak; ``checkable``: the model's ``check_peak`` can check
    it). ``drifting``: the time integration at the peak found a damper that keeps rolling or
    walking (its mean compared), an error that a richer harmonic set does not remove."""
    H = tuple(int(h) for h in harmonics)
    one = H == (1,)
    curve = "one-harmonic curve" if one else f"harmonics {H}"
    if not np.isfinite(error) and estimated:
        subject = "the one-harmonic curve's error" if one else f"the error of harmonics {H}"
        return (f"{subject} could not be checked: {enriched(H)} did not converge at the peak; "
                + ("check the peak with check_peak=True" if checkable else "run with harmonics='auto'"))
    if not np.isfinite(error):
        unknown = "its peak may be off by tens of %" if one else "its accuracy is unknown"
        return f"{curve}, error not estimated: {unknown}; run with harmonics='auto'"
    if error <= tolerance:
        return f"{curve}, good to {percent(error)} (tolerance {percent(tolerance)})"
    if drifting:
        return (f"a damper keeps rolling at the peak, which no periodic curve holds: trust the curve to "
                f"{percent(error)} only (tolerance {percent(tolerance)})")
    if one:
        return (f"one-harmonic curve: its peak may be off by up to {percent(error)}; run with harmonics='auto' or "
                f"{enriched(H)}")
    return (f"{curve}: the curve may be off by up to {percent(error)} (tolerance {percent(tolerance)}); "
            f"run with harmonics {enriched(H)} or a larger max_harmonic")


# A first-harmonic tip amplitude above this fraction of the blade's span (root to tip point) is
# beyond the linear theory of small deformations the blade's modes rest on: the linear theory
# overestimates the tip deflection of an end-loaded cantilever, against the elastica (Bisshopp &
# Drucker 1945), by 1.0 % at a deflection of 10 % of its length, the product's 1 % accuracy target
# (0.26 % at 5 %, 4 % at 20 %)
PLAUSIBLE_TIP_DEFLECTION = 0.1


def amplitude_check(response, span: float) -> dict[str, str]:
    """{"amplitude": what was found} when the largest first-harmonic tip amplitude of
    ``response`` (:meth:`FrequencyResponse.peak_curve`) [m] exceeds ``PLAUSIBLE_TIP_DEFLECTION``
    of the blade's ``span`` [m] (the tip point's distance from the blade frame's origin, the
    root); {} otherwise (and for an empty branch)."""
    if not len(response.omega) or not (np.isfinite(span) and span > 0):
        return {}
    peak = float(np.max(response.peak_curve()))
    if not peak > PLAUSIBLE_TIP_DEFLECTION * span:      # nan too: not plausible
        if np.isfinite(peak):
            return {}
    return {"amplitude": (f"a tip amplitude of {1e3 * peak:.4g} mm is {percent(peak / span)} of the "
                          f"{1e3 * span:.4g} mm blade, beyond small-deformation theory "
                          f"({percent(PLAUSIBLE_TIP_DEFLECTION)})")}


def with_amplitude_check(response, span: float):
    """``response`` with :func:`amplitude_check`'s failure recorded (:func:`with_checks`: not
    ``success``, status CHECK_FAILED where it reached the end of its range); unchanged where the
    amplitude is plausible."""
    return with_checks(response, amplitude_check(response, span))


# what to do about each physical check that failed (:func:`status_message`), in this order
CHECK_ADVICE = {
    "amplitude": "add damping or check the excitation",
    "peak_time_check": "the peak is not a motion the disk keeps; the time integration is the answer there",
    "dissipation": "raise the AFT samples (n_samples)",
    "step": "shorten max_step",
    "range": "report it: the continuation left its range",
}


def check_sentence(failed: dict) -> str:
    """One sentence on the physical checks ``failed`` ({check: what was found}): the first by
    ``CHECK_ADVICE``'s order, what was found and what to do, and how many more."""
    names = sorted(failed, key=lambda k: list(CHECK_ADVICE).index(k) if k in CHECK_ADVICE else len(CHECK_ADVICE))
    first = names[0]
    found = str(failed[first])
    if first == "peak_time_check":
        found = "the time integration at the peak finds no periodic motion" + (
            " (the branch is unstable there)" if "the branch is unstable at the peak" in found else "")
    elif first == "dissipation":      # the AFT's energy error at the solve's samples where stated, else the least
        error = re.search(r"AFT energy error (\S+ %)", found) or re.search(r"down to (\S+ %)", found)
        found = found.split(" (")[0] + (f", AFT energy error {error.group(1)}" if error else "")
    more = f" (and {len(names) - 1} more: failed_checks)" if len(names) > 1 else ""
    return f"{found}{more}: {CHECK_ADVICE.get(first, 'see failed_checks')}"


def stop_sentence(response) -> str:
    """One sentence on a branch that stopped before the end of its range: where, and why or
    what to do, from its time integration beyond the stop (``stop_check``) when it has one."""
    check = getattr(response, "stop_check", None)
    if not len(response.omega):
        where = "no point computed: the start failed"
    else:
        where = f"the branch ends at {response.frequency_hz[response.furthest_index()]:.2f} Hz"
    if check is not None and len(getattr(check, "periodic", ())):
        if not check.periodic[0]:
            return (f"{where}; the time integration beyond finds no periodic motion (the damper hops or rolls): "
                    "no curve exists there, use the time integration")
        return f"{where}; a periodic motion exists beyond, which a richer set (harmonics='auto') may follow"
    if response.failed_checks:
        return f"{where}; {check_sentence(response.failed_checks)}"
    if any("max_points" in n.values for n in notes_of(response, NoteKind.CONTINUATION)):
        return f"{where}, all its max_points = {len(response.omega)} points used: raise max_points"
    more = "check_stop=True tells whether a periodic motion exists beyond" if hasattr(response, "stop_check") \
        else "shorten max_step or run with harmonics='auto'"
    return f"{where}; {more}"


def status_message(response) -> str:
    """What a response's report leads with, one plain sentence (and a second one when its
    largest amplitude lies at an end of the range, :func:`range_end_note`): its :class:`Status`
    (the short name), then what it means for this result, with its numbers (the error estimate
    and the harmonic set, where the branch stopped and why, the failed check), and what to do."""
    status = response_status(response)
    error, tolerance = float(response.harmonic_error), float(response.harmonic_tolerance)
    H = tuple(response.basis.harmonics)
    check = getattr(response, "peak_check", None)
    drifting = check is not None and str(check.status[0]) == "drifting"
    reason = getattr(response, "unverified_reason", "")
    if status is Status.COMPLETE_UNVERIFIED and reason:
        detail = f"{reason}: not a verified motion of the disk; check the peak by time integration (check_peak=True)"
    elif status is Status.COMPLETE_ABOVE_TOLERANCE and reason:
        detail = (f"{reason}: the time integration at the peak settles {percent(error)} from the curve (tolerance "
                  f"{percent(tolerance)}); a richer harmonic set does not change that, the time integration is the "
                  "answer there")
    elif status.complete:
        detail = harmonic_sentence(H, error if np.isfinite(tolerance) else float("nan"), tolerance, drifting,
                                   estimated=response.harmonics_converged is not None,
                                   checkable=hasattr(response, "peak_check"))
    elif status is Status.CHECK_FAILED:
        detail = check_sentence(response.failed_checks)
    elif status is Status.OUT_OF_BUDGET:
        budget = response.stopped_by.removeprefix(BUDGET_PREFIX).lstrip(": ")
        if response.reached_range_end and len(response.omega):
            detail = (f"{budget} on a richer set; the complete curve of harmonics {H} is kept, "
                      + (f"error {percent(error)} (tolerance {percent(tolerance)})" if np.isfinite(error)
                         else "its error unknown"))
        else:
            detail = (f"{budget}: a partial curve, whose largest amplitude need not be the resonance; raise "
                      "cpu_budget_s or point_budget")
    elif response.stopped_by:
        detail = f"ended by the stop condition ({response.stopped_by}): a partial curve"
    else:
        detail = stop_sentence(response)
    # where the branch covers part of the range, its last point is no range end: the sentence says so
    note = range_end_note(response) if response.reached_range_end else ""
    if "amplitude" in response.failed_checks:
        implausible = check_sentence({"amplitude": response.failed_checks["amplitude"]})
        detail += "" if implausible in detail else "; " + implausible
    sentence = f"{status.value}: {detail}."
    return f"{sentence} {note[0].upper()}{note[1:]}." if note else sentence


def with_range_end_estimate(model, response):
    """``response`` with, when its largest amplitude lies at an end of its range, the model's
    linear natural frequencies nearest the range (``model.linear_natural_frequencies_hz(f_low,
    f_high) -> (without contacts, contacts stuck)`` [Hz]) stored as
    ``linear_natural_frequencies_hz`` and :func:`range_end_note` added to the message; any other
    response (and one that did not reach the end of its range: its status says so) unchanged."""
    if not (response.peak_at_range_end and response.reached_range_end):
        return response
    f = response.frequency_hz
    bounds = tuple(float(b) for b in model.linear_natural_frequencies_hz(float(f.min()), float(f.max())))
    response = dataclasses.replace(response, linear_natural_frequencies_hz=bounds)
    return with_note(response, Note(NoteKind.RANGE_END, range_end_note(response)))


def nearest_to_range(frequencies_hz, f_low: float, f_high: float) -> float:
    """The one of ``frequencies_hz`` nearest the interval [``f_low``, ``f_high``] [Hz] (inside
    it: distance 0, the lowest of those); nan if there is none."""
    f = np.asarray(frequencies_hz, dtype=float).ravel()
    f = f[np.isfinite(f)]
    if not f.size:
        return float("nan")
    distance = np.maximum(f_low - f, 0.0) + np.maximum(f - f_high, 0.0)
    return float(f[np.lexsort((f, distance))[0]])


def plot_branch(ax, x, y, stable=None, **kwargs):
    """Draw a branch ``y`` (n,) over ``x`` (n,): solid where stable (or when ``stable`` is
    None), dashed in the same colour where unstable, one legend entry; returns the lines."""
    stable = None if stable is None else np.asarray(stable, dtype=bool)
    if stable is None or stable.all():
        return ax.plot(x, y, **kwargs)
    solid = np.where(stable, y, np.nan)
    # extend each unstable run by one point on either side so the two styles join
    join = np.convolve(~stable, [1, 1, 1], mode="same") > 0
    dashed = np.where(join, y, np.nan)
    lines = ax.plot(x, solid, **kwargs)
    kwargs.pop("label", None)
    kwargs.pop("linestyle", None)
    kwargs.pop("ls", None)
    kwargs["color"] = lines[0].get_color()
    lines += ax.plot(x, dashed, linestyle="--", label="_unstable", **kwargs)
    return lines


@dataclass
class FrequencyResponse(Saveable):
    """Harmonic balance frequency response of a system with named degrees of freedom.

    Attributes
    ----------
    omega : (n,) excitation angular frequency of each point [rad/s]
    coefficients : (n, C, n_dof) harmonic coefficients (see :class:`HarmonicBasis`) [SI]
    basis : HarmonicBasis used
    dof_names : names of the degrees of freedom
    success : whether the continuation reached the end of the range
    message : init only, and a read-only property: the text of ``notes`` joined by
        ``NOTE_SEPARATOR`` in order (what a user reads: how the branch ended, then what each
        later step found). Given as a plain str to the constructor (``from_branch``, a file
        saved before notes existed, ``dataclasses.replace(r, message=...)``) it is the whole
        message: one note of kind CONTINUATION, replacing ``notes``
    iterations : (n,) Newton iterations per point
    turning_points : indices of the points where d omega / ds changed sign (folds)
    harmonic_error : estimated error of the first-harmonic output amplitudes from the harmonic
        truncation, relative to the peak amplitude (see :mod:`bladedamp.hbm.accuracy`); nan if
        not estimated
    harmonic_tolerance : the tolerance it was held to
    harmonics_converged : whether the estimate met the tolerance (None: not estimated)
    failed_checks : physical sanity checks the branch failed (name -> what was found); a
        branch that fails one is not ``success``
    reached_end : whether the continuation reached the end of the range (its own checks
        passing) before the physical checks were applied; None: as ``success`` (no check failed)
    stable : (n,) bool per point, or None when not computed (see
        :func:`bladedamp.hbm.stability.with_stability`); plots draw unstable parts dashed
    floquet_exponents : (n, k) resolved Floquet exponents per point [1/s] (Hill's method; width
        0 when decided by the determinant sign, for friction), or None
    bifurcations : {"fold": [...], "branch point": [...], "neimark-sacker": [...], ...}: indices
        i where the kind happens between points i and i + 1
    stability_method : "hill", "determinant sign", "monodromy" or "" (not computed)
    stopped_by : why a stop condition the caller gave ended the branch (e.g. ``stop_above`` of
        :meth:`TunedDisk.frequency_response`), '' if none did; such a response is not
        ``success``, and is not retried or enriched
    linear_natural_frequencies_hz : (without the friction contacts, with them stuck): the natural
        frequencies [Hz] nearest the range of the model's two linear systems, given when the
        largest amplitude lies at an end of the range (:func:`with_range_end_estimate`), else ()
    unverified_reason : what keeps a complete response from being verified whatever its harmonic
        set (e.g. a disk's peak held by the harmonic balance's static retention spring,
        :func:`bladedamp.diskmodel.retention_check`), '' if nothing; with one, ``harmonic_error`` is
        nan (status COMPLETE_UNVERIFIED) until a time integration of the peak gives an estimate
    notes : the :class:`Note` s of the result in the order they were added (:func:`with_note`):
        the continuation's message first (kind CONTINUATION, :func:`continuation_note`), then
        each later step's (the AFT samples, failed checks, harmonic estimate, peak and stop
        checks, range end: :class:`NoteKind`); a program reads their ``kind`` and ``values``

    Derived, for every response (saved ones too): :attr:`status` (a :class:`Status`),
    :attr:`status_message` and :attr:`peak_at_range_end`.
    """

    omega: np.ndarray
    coefficients: np.ndarray
    basis: HarmonicBasis
    dof_names: tuple[str, ...]
    success: bool
    message: dataclasses.InitVar[str] = ""
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    turning_points: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    harmonic_error: float = float("nan")
    harmonic_tolerance: float = float("nan")
    harmonics_converged: bool | None = None
    failed_checks: dict = field(default_factory=dict)
    reached_end: bool | None = None
    stable: np.ndarray | None = None
    floquet_exponents: np.ndarray | None = None
    bifurcations: dict = field(default_factory=dict)
    stability_method: str = ""
    stopped_by: str = ""
    linear_natural_frequencies_hz: tuple = ()
    unverified_reason: str = ""
    notes: tuple = ()

    def __post_init__(self, message):
        # a plain str is the whole message; the NotesText that dataclasses.replace passes back keeps the notes
        if message and (not isinstance(message, NotesText) or not self.notes):
            self.notes = (Note(NoteKind.CONTINUATION, str(message)),)
        self.notes = tuple(self.notes)
        for note in self.notes:
            if not isinstance(note, Note):
                raise ValueError(f"notes must be bladedamp.response.Note objects (got {note!r})")

    @property
    def status(self) -> Status:
        """What the response can be trusted for (:func:`response_status`)."""
        return response_status(self)

    @property
    def status_message(self) -> str:
        """The sentence that leads the response's report (:func:`status_message`)."""
        return status_message(self)

    @property
    def peak_at_range_end(self) -> bool:
        """Whether the largest first-harmonic output amplitude (:meth:`peak_curve`)
        lies at the first or last frequency of the range (:func:`range_end_of_largest`): then it
        is no resonance, and :attr:`status_message` says where the resonance may lie."""
        return range_end_of_largest(self.frequency_hz, self.peak_curve()) is not None

    def peak_curve(self) -> np.ndarray:
        """(n,) the output's first-harmonic amplitude at every point, whose largest is the peak:
        here |X_1| of the first DOF [SI]; the disks' the tip amplitude u_x [m] ((n, s), one
        column per blade, for a mistuned disk)."""
        return self.harmonic_amplitude(0, 1)

    @property
    def reached_range_end(self) -> bool:
        """Whether the continuation reached the end of the range (``reached_end``, or ``success``
        where no physical check failed)."""
        return bool(self.success if self.reached_end is None else self.reached_end)

    def furthest_index(self) -> int:
        """Index of the point furthest from the branch's first point in frequency (where a branch
        from the start of its range got furthest, also if it then turned back)."""
        o = self.omega
        direction = np.sign(o[np.argmax(np.abs(o - o[0]))] - o[0])
        return int(np.argmax(direction * (o - o[0])))

    def reversed(self):
        """The same branch in the opposite order (a downward sweep as rising frequency): every
        per-point array is flipped, turning points renumbered."""
        n = len(self.omega)
        changes = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "turning_points":
                changes[f.name] = np.sort(n - 1 - np.asarray(value, dtype=int))
            elif isinstance(value, np.ndarray) and value.ndim and value.shape[0] == n:
                changes[f.name] = value[::-1].copy()
        return dataclasses.replace(self, **changes)

    @property
    def frequency_hz(self) -> np.ndarray:
        """Excitation frequency [Hz]."""
        return self.omega / (2 * np.pi)

    def _dof(self, dof) -> int:
        return self.dof_names.index(dof) if isinstance(dof, str) else int(dof)

    def harmonic_amplitude(self, dof=0, harmonic: int = 1) -> np.ndarray:
        """|X_h| of one DOF at every point (for h = 0 the signed static value)."""
        j = self.basis.cos_index(harmonic)
        c = self.coefficients[:, :, self._dof(dof)]
        return c[:, j] if harmonic == 0 else np.hypot(c[:, j], c[:, j + 1])

    def time_samples(self, dof=0) -> np.ndarray:
        """(n, T) samples of one DOF over a period at every point."""
        return self.coefficients[:, :, self._dof(dof)] @ self.basis.synthesis.T

    def max_amplitude(self, dof=0) -> np.ndarray:
        """max_t |x(t)| over a period at every point (all harmonics)."""
        return np.abs(self.time_samples(dof)).max(axis=1)

    def peak(self, dof=0, harmonic: int = 1) -> tuple[float, float]:
        """(frequency [Hz], amplitude [SI]) of the largest |X_h| of ``dof`` on the branch
        (nan, nan for an empty branch)."""
        if not len(self.omega):
            return float("nan"), float("nan")
        a = self.harmonic_amplitude(dof, harmonic)
        i = int(np.argmax(a))
        return float(self.frequency_hz[i]), float(a[i])

    @property
    def peak_amplitude(self) -> float:
        """Largest first-harmonic amplitude of the first DOF on the branch [SI: m for a
        displacement] (nan for an empty branch). Every response class has it: the disks' is
        the largest tip amplitude u_x [m]."""
        return self.peak()[1]

    @property
    def peak_frequency_hz(self) -> float:
        """Excitation frequency of :attr:`peak_amplitude` [Hz] (the resonance)."""
        return self.peak()[0]

    def plot(self, ax=None, *, dof=0, harmonic: int = 1, scale: float = 1.0, unit: str = "m", measured=None,
             **kwargs):
        """Plot ``scale`` |X_h| of ``dof`` over frequency [Hz] into ``ax`` (a new figure if None);
        ``unit``: the unit of the plotted values, shown in brackets on the axis (default m, the
        SI unit of a displacement DOF at ``scale`` 1; e.g. ``scale=1e3, unit="mm"``). Returns
        the axes. Every response class's ``plot`` takes ``ax`` first, options by keyword.
        ``measured``: a measured displacement (or velocity, acceleration) response or its file,
        drawn times ``scale`` beside it (:func:`bladedamp.measurement.draw_measurement`; an FRF
        needs its force: ``measured.at_force(F)``)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        label = kwargs.pop("label", f"{self.dof_names[self._dof(dof)]}, H={self.basis.harmonics}")
        plot_branch(ax, self.frequency_hz, scale * self.harmonic_amplitude(dof, harmonic), self.stable,
                    label=label, **kwargs)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel(f"|{self.dof_names[self._dof(dof)]}| harmonic {harmonic} [{unit}]")
        ax.grid(True, alpha=0.3)
        if not self.success:
            ax.set_title(textwrap.fill(self.status_message, 100), fontsize=8)   # what it means, not the log
        ax.legend()
        if measured is not None:
            from .measurement import draw_measurement

            draw_measurement(ax, measured, scale=scale)
        return ax


# the message, derived from the notes (set after the class: ``message`` is also the init-only
# argument of the constructor, whose default the dataclass reads from the class body)
FrequencyResponse.message = property(lambda self: notes_text(self.notes),
                                     doc="The text of :attr:`notes` joined in order (:func:`notes_text`), read only.")


@dataclass
class Sensitivities(Saveable):
    """Derivatives of every point of a frequency response in design parameters, at fixed
    frequency (``response.sensitivities(parameters)``; :mod:`bladedamp.hbm.sensitivity`).

    parameters : (k,) the design-file keys; units : (k,) their units (per unit of which the
        derivatives are); values : (k,) their values in the model [the key's unit]
    frequency_hz : (n,) the branch's frequencies [Hz]
    tip_amplitude : (n, s) each blade's first-harmonic tip amplitude [m] (s = 1: the tuned sector)
    d_tip_amplitude : (n, k, s) its derivatives [m per unit of each key] (where the amplitude is 0,
        rest under a zero excitation, the one-sided derivative as the key grows, |du/dp|)
    d_coefficients : (n, k, C, n_dof) the derivatives of the harmonic coefficients [SI per unit]
    """

    parameters: tuple
    units: tuple
    values: np.ndarray
    frequency_hz: np.ndarray
    tip_amplitude: np.ndarray
    d_tip_amplitude: np.ndarray
    d_coefficients: np.ndarray

    def elasticities(self) -> np.ndarray:
        """(n, k, s) relative sensitivities p / a da/dp [-]: the relative change of each blade's tip
        amplitude per relative change of each parameter (nan where a = 0 or p = 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.asarray(self.values)[None, :, None] * self.d_tip_amplitude / self.tip_amplitude[:, None, :]

    def plot(self, ax=None, *, blade: int = 0):
        """The elasticity p / a da/dp of blade ``blade``'s tip amplitude in each parameter over the
        frequency (one curve per parameter) under the amplitude (mm); returns the figure."""
        import matplotlib.pyplot as plt

        if ax is None:
            fig, (top, ax) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 5.5), constrained_layout=True)
        else:
            fig, top = ax.figure, None
        f = self.frequency_hz
        if top is not None:
            top.plot(f, 1e3 * self.tip_amplitude[:, blade], color="k")
            top.set_ylabel("tip amplitude [mm]")
            top.grid(alpha=0.3)
        elasticity = self.elasticities()[:, :, blade]
        for j, key in enumerate(self.parameters):
            ax.plot(f, elasticity[:, j], label=key)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel("p / a  da/dp  [-]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
        return fig


class PeakDerivative(tuple):
    """(peak_amplitude [m per unit], peak_frequency_hz [Hz per unit]) of one parameter."""

    __slots__ = ()

    def __new__(cls, peak_amplitude: float, peak_frequency_hz: float):
        return super().__new__(cls, (float(peak_amplitude), float(peak_frequency_hz)))

    @property
    def peak_amplitude(self) -> float:
        return self[0]

    @property
    def peak_frequency_hz(self) -> float:
        return self[1]


@dataclass
class PeakSensitivities(Saveable):
    """Derivatives of a resonance peak in design parameters (``bladedamp.peak_sensitivities``):
    a mapping from each design-file key to its :class:`PeakDerivative` (``result[key].peak_amplitude``
    [m per unit of the key], ``.peak_frequency_hz`` [Hz per unit]).

    parameters, units, values : (k,) the keys, their units and values [the key's unit]
    peak_amplitude : the peak's tip amplitude [m]; peak_frequency_hz : its frequency [Hz]
    blade : the blade whose peak it is (0 for the tuned sector)
    d_peak_amplitude : (k,) [m per unit]; d_peak_frequency_hz : (k,) [Hz per unit]
    """

    parameters: tuple
    units: tuple
    values: np.ndarray
    peak_amplitude: float
    peak_frequency_hz: float
    blade: int
    d_peak_amplitude: np.ndarray
    d_peak_frequency_hz: np.ndarray

    def __getitem__(self, key: str) -> PeakDerivative:
        if key not in self.parameters:
            raise KeyError(f"{key!r} (the parameters are {', '.join(self.parameters)})")
        j = self.parameters.index(key)
        return PeakDerivative(self.d_peak_amplitude[j], self.d_peak_frequency_hz[j])

    def __iter__(self):
        return iter(self.parameters)

    def __len__(self) -> int:
        return len(self.parameters)

    def keys(self):
        return self.parameters

    def items(self):
        return [(k, self[k]) for k in self.parameters]

    def elasticities(self) -> tuple[np.ndarray, np.ndarray]:
        """(k,) and (k,): p / A dA/dp and p / f df/dp [-], the relative change of the peak amplitude
        and frequency per relative change of each parameter."""
        values = np.asarray(self.values, dtype=float)
        return (values * self.d_peak_amplitude / self.peak_amplitude,
                values * self.d_peak_frequency_hz / self.peak_frequency_hz)

    def table(self) -> str:
        """The derivatives as a text table (mm and Hz per unit of each key, and the elasticities)."""
        ea, ef = self.elasticities()
        width = max(len(k) for k in self.parameters) if self.parameters else 9
        lines = [f"peak {1e3 * self.peak_amplitude:.4g} mm at {self.peak_frequency_hz:.5g} Hz (blade {self.blade})",
                 f"{'parameter':<{width}}  {'value':>10}  {'dA/dp [mm/unit]':>16}  {'df/dp [Hz/unit]':>16}  "
                 f"{'p/A dA/dp':>10}  {'p/f df/dp':>10}"]
        for j, key in enumerate(self.parameters):
            lines.append(f"{key:<{width}}  {self.values[j]:>10.4g}  {1e3 * self.d_peak_amplitude[j]:>16.4g}  "
                         f"{self.d_peak_frequency_hz[j]:>16.4g}  {ea[j]:>10.3g}  {ef[j]:>10.3g}  "
                         f"(per {self.units[j]})")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Bars of the elasticities p / A dA/dp and p / f df/dp of each parameter; returns the figure."""
        import matplotlib.pyplot as plt

        ea, ef = self.elasticities()
        if ax is None:
            fig, ax = plt.subplots(figsize=(9.0, 0.5 * len(self.parameters) + 2.2), constrained_layout=True)
        else:
            fig = ax.figure
        y = np.arange(len(self.parameters))
        ax.barh(y - 0.2, ea, height=0.4, label="peak amplitude", color="C0")
        ax.barh(y + 0.2, ef, height=0.4, label="peak frequency", color="C1")
        ax.set_yticks(y, self.parameters)
        ax.invert_yaxis()
        ax.axvline(0.0, color="0.4", lw=0.8)
        ax.set_xlabel("relative sensitivity  p / y  dy/dp  [-]")
        ax.set_ylabel("design parameter p [-]")
        ax.set_title(f"peak {1e3 * self.peak_amplitude:.3g} mm at {self.peak_frequency_hz:.4g} Hz", fontsize="medium")
        ax.grid(axis="x", alpha=0.3)
        ax.legend(fontsize="small")
        return fig


def branch_sensitivities(system, omega, coefficients, outputs, dR_dp, keys, units, values) -> Sensitivities:
    """The :class:`Sensitivities` of a branch of ``system`` (``omega`` (n,) [rad/s], ``coefficients``
    (n, C * n_dof)) in k parameters (``keys``, their ``units`` and ``values``): at every point
    dx/dp = -J^-1 dR/dp with one factorisation for all (``dR_dp(x, omega) -> (k, C * n_dof)``, the
    model's analytic derivatives; :mod:`bladedamp.hbm.sensitivity`) and the amplitudes of the s
    complex ``outputs`` (s, C * n_dof) and their derivatives."""
    outputs = np.atleast_2d(outputs)
    n, N = len(omega), system.n_unknowns
    X = np.asarray(coefficients, dtype=float).reshape(n, N)
    dx = np.zeros((n, len(keys), N))
    amplitude, d_amplitude = np.zeros((n, len(outputs))), np.zeros((n, len(keys), len(outputs)))
    for i, (x, w) in enumerate(zip(X, omega)):
        dx[i] = state_sensitivities(system, x, float(w), dR_dp)
        for b, output in enumerate(outputs):
            amplitude[i, b], d_amplitude[i, :, b] = output_sensitivities(output, x, dx[i])
    return Sensitivities(tuple(keys), tuple(units), np.asarray(values, dtype=float), np.asarray(omega) / (2 * np.pi),
                         amplitude, d_amplitude, dx.reshape(n, len(keys), system.basis.n_coeffs, -1))


def solved_peak_sensitivities(system, omega, coefficients, outputs, dR_dp, keys, units, values) -> PeakSensitivities:
    """The :class:`PeakSensitivities` of the largest amplitude of the s complex ``outputs`` (s,
    C * n_dof) on a branch of ``system`` (as :func:`branch_sensitivities`): the peak solved by
    d|u|/dOmega = 0 (:class:`~bladedamp.hbm.peaks.PeakSolver`) next to the largest sample, then
    differentiated (:func:`bladedamp.hbm.sensitivity.peak_sensitivities`). ValueError where the
    response is rest at every point (a zero excitation: no peak), where the peak cannot be solved
    (at an end of the range, next to a fold) or no pair of points beside it brackets a maximum."""
    outputs = np.atleast_2d(outputs)
    n = len(omega)
    X = np.asarray(coefficients, dtype=float).reshape(n, -1)
    curves = np.abs(X @ outputs.T)                                      # (n, s)
    if n and not curves.any():
        raise ValueError("the excitation is zero: the response is rest and has no peak (no peak derivatives; "
                         "response.sensitivities gives each frequency's)")
    blade = int(np.argmax(curves.max(axis=0)))
    index = int(np.argmax(curves[:, blade]))
    solver = PeakSolver(system, omega, X)
    solved = solver.solve_state(index, outputs[blade])
    where = f"at {omega[index] / (2 * np.pi):.6g} Hz"
    if solved is None:
        raise ValueError(f"the peak {where} could not be solved (at an end of the range or next to a fold): "
                         "no peak derivatives")
    _, w, x = solved
    scale = max(np.linalg.norm(system.residual(np.zeros_like(x), w, False)[0]), 1e-300)
    peak = peak_sensitivities(system, x, w, outputs[blade], dR_dp, solver.x_scale, scale)
    if peak is None:
        raise ValueError(f"the peak {where}: a solve beside it did not converge or no pair of points beside it "
                         "brackets a maximum: no peak derivatives")
    return PeakSensitivities(tuple(keys), tuple(units), np.asarray(values, dtype=float), peak.amplitude,
                             peak.omega / (2 * np.pi), blade, peak.d_amplitude, peak.d_omega / (2 * np.pi))
