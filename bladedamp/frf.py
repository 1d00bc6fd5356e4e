"""The one frequency-response driver of every model (issue 34 item 3): the friction oscillator,
the tuned disk's cyclic sector and the mistuned ring solve their FRFs here.

:func:`branch_solver` validates the range and gives ``solve(harmonics)``: for each harmonic
set the convergence asks for (:func:`bladedamp.hbm.accuracy.converged_response` or the disks'
wrapper of it, which the model's ``frequency_response`` calls) and each AFT sample count
:func:`bladedamp.response.sampled_response` chooses, it builds the model's harmonic balance,
starts it robustly at the first frequency, follows it by pseudo-arclength continuation
(:func:`bladedamp.hbm.continuation.continuation`) and holds the branch to
:func:`bladedamp.response.physical_checks`. The models keep their public ``frequency_response``
signatures (their own options, the rest response, the time checks) and call it.

The model protocol (:class:`FrequencyResponseModel`): the harmonic balance and its scales,
the start, the response object and the energies the checks need. A model's methods take the
residual's angular frequency omega [rad/s]; the driver's public arguments are in Hz.
"""
from __future__ import annotations

from typing import Callable, Protocol

import numpy as np

from . import validation
from .hbm.continuation import DEFAULT_CPU_BUDGET_S, DEFAULT_MAX_STEP, DEFAULT_POINT_BUDGET, Budget, continuation
from .response import REFINE_SAMPLES_FACTOR, physical_checks, sampled_response, with_checks


class FrequencyResponseModel(Protocol):
    """What :func:`branch_solver` asks of a model (``system``: its
    :class:`~bladedamp.hbm.system.HarmonicBalanceSystem`; omega in rad/s)."""

    def check_bounded(self, f_start_hz: float, f_end_hz: float) -> None:
        """ValueError where no bounded periodic response exists in the range [Hz]."""

    def hbm_system(self, harmonics, n_samples=None):
        """The harmonic balance with ``harmonics`` and ``n_samples`` AFT samples per period."""

    def sample_plan(self, harmonics) -> tuple[int, int, int | None]:
        """(first, most, most_for_dissipation) AFT samples of :func:`~bladedamp.response.sampled_response`."""

    def unknown_scales(self, system, omega_start: float, omega_end: float):
        """The continuation's ``x_scale`` over the range."""

    def retry_scales(self, system, scales):
        """The continuation's ``retry_x_scale`` (None: no retry with other scales)."""

    def start_solution(self, system, omega: float, scales, out_of_time=None):
        """A solution (C * n_dof,) at ``omega``, robust in gross slip; ``out_of_time``: None or
        () -> bool, once True no further solve of the start is begun (its best iterate returned)."""

    def response_from_branch(self, system, branch):
        """The model's response object of a continuation ``branch``."""

    def branch_energies(self, system, branch, response):
        """(excitation work (n,), dissipation (n, m), work bound (n, m)) per period [J] of every
        point, for the m friction contacts (or contact points) :func:`~bladedamp.response.physical_checks` judges."""

    def refined_dissipation(self, system, branch):
        """(k, m) the dissipation of :meth:`branch_energies` of ``branch`` (k points) on ``system``."""

    def judges_solution_samples(self, n_samples: int) -> bool:
        """``physical_checks``' ``judge_solution_samples`` at ``n_samples``."""


def checked_range(model: FrequencyResponseModel, f_start_hz: float, f_end_hz: float) -> tuple[float, float]:
    """(omega_start, omega_end) [rad/s] of the range ``f_start_hz``..``f_end_hz`` [Hz], both > 0
    and different, where ``model.check_bounded`` finds a bounded response (ValueError otherwise)."""
    validation.positive("f_start_hz", f_start_hz)
    validation.positive("f_end_hz", f_end_hz)
    if f_start_hz == f_end_hz:
        raise ValueError("f_end_hz must differ from f_start_hz")
    model.check_bounded(f_start_hz, f_end_hz)
    return 2 * np.pi * f_start_hz, 2 * np.pi * f_end_hz


def branch_solver(model: FrequencyResponseModel, f_start_hz: float, f_end_hz: float, n_samples: int | None = None,
                  max_step: float | None = DEFAULT_MAX_STEP, stop_when_for: Callable | None = None,
                  cpu_budget_s: float = DEFAULT_CPU_BUDGET_S, point_budget: int = DEFAULT_POINT_BUDGET,
                  **continuation_options) -> Callable:
    """``solve(harmonics) -> response``: the branch of ``model`` from ``f_start_hz`` to
    ``f_end_hz`` [Hz] with ``harmonics`` by harmonic balance and continuation, its AFT samples
    chosen by :func:`~bladedamp.response.sampled_response` and every branch held to
    :func:`~bladedamp.response.physical_checks` (range, step, every contact's dissipation >= 0 to
    the AFT's sampling floor, re-evaluated with ``REFINE_SAMPLES_FACTOR`` times the samples where
    in doubt). A model's ``frequency_response`` gives it to its convergence in the harmonics
    (:func:`~bladedamp.hbm.accuracy.converged_response`, or the disks' wrapper of it), called
    from ``frequency_response`` itself so that the accuracy warnings point at its caller.

    ``n_samples``: given, or None for the model's :meth:`~FrequencyResponseModel.sample_plan`;
    ``stop_when_for``: ``basis -> the continuation's stop_when`` (or None; a ``stop_when`` of
    ``continuation_options`` is the same for every basis: give one or the other); ``max_step``
    (None: the continuation's default) and ``continuation_options`` go to
    :func:`~bladedamp.hbm.continuation.continuation`; ``cpu_budget_s`` [s] and ``point_budget``
    are the whole analysis' (:class:`~bladedamp.hbm.continuation.Budget`, shared by every
    ``solve``). The robust start is not begun once the budget has run out, nor any further solve
    of it (the continuation then keeps no point and says so), and the start at the end of the
    range is computed once for a branch and its retry."""
    w0, w1 = checked_range(model, f_start_hz, f_end_hz)
    if stop_when_for is not None and continuation_options.get("stop_when") is not None:
        raise ValueError("give stop_when or the model's own stop (stop_above), not both")
    given_stop = continuation_options.pop("stop_when", None)
    budget = Budget(cpu_budget_s, point_budget)
    step = DEFAULT_MAX_STEP if max_step is None else max_step

    def solve(H):
        first, most, most_for_dissipation = model.sample_plan(H)
        return sampled_response(lambda n: solve_sampled(H, n), n_samples, first, most, most_for_dissipation)

    def solve_sampled(H, n):
        system = model.hbm_system(H, n)
        scales = model.unknown_scales(system, w0, w1)

        def start(w):
            return (np.zeros(system.n_unknowns) if budget.exhausted(w) else
                    model.start_solution(system, w, scales, out_of_time=lambda: bool(budget.exhausted(w))))

        at_end = []

        def start_at_end():
            if not at_end:
                at_end.append(start(w1))
            return at_end[0].copy()

        branch = continuation(system.residual, start(w0), w0, w1, x_scale=scales, factorize=system.factorize,
                              max_step=step, start_at_end=start_at_end,
                              retry_x_scale=model.retry_scales(system, scales),
                              stop_when=given_stop if stop_when_for is None else stop_when_for(system.basis),
                              budget=budget,
                              **continuation_options)
        response = model.response_from_branch(system, branch)
        work, dissipation, bound = model.branch_energies(system, branch, response)
        T = system.basis.n_samples

        def refine(indices):
            fine = model.hbm_system(system.basis.harmonics, REFINE_SAMPLES_FACTOR * T)
            return model.refined_dissipation(fine, branch.take(indices))

        return with_checks(response, physical_checks(branch.omega, (w0, w1), dissipation, work, step, T, refine,
                                                     bound, judge_solution_samples=model.judges_solution_samples(T)))

    return solve
