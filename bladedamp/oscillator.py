"""The friction oscillator: one mass on a spring with one elastic Coulomb contact.

The teaching model of friction damping and the test bench of the HBM engine::

    m x'' + c x' + k x + k3 x^3 + f_C(x) = F cos(Omega t)

The contact is a point contact (stiffness k_T in series with a Coulomb slider, normal load
N) whose plane is inclined by ``contact_angle`` to the motion: the tangential displacement
is x cos(alpha) and the approach grows by x sin(alpha), so the normal load varies with the
displacement (N = N0 + k_N x sin(alpha), lifting off when it reaches zero).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import validation
from .contact.laws import LinearNormalLaw
from .contact.point import PointContactElement
from .frf import branch_solver
from .hbm.accuracy import HARMONIC_TOLERANCE, converged_response
from .hbm.continuation import DEFAULT_CPU_BUDGET_S, DEFAULT_MAX_STEP, DEFAULT_POINT_BUDGET
from .hbm.start import robust_start
from .hbm.elements import CubicSpring
from .hbm.fourier import HarmonicBasis
from .hbm.monodromy import STEPS_PER_PERIOD, oscillator_monodromy
from .hbm.peaks import first_harmonic_output
from .hbm.system import Coupling, HarmonicBalanceSystem, linear_forces
from .response import (FrequencyResponse, PeakSensitivities, Sensitivities, branch_sensitivities, continuation_note,
                       solved_peak_sensitivities, with_range_end_estimate)
from .timedomain import TimeResponse, oscillator_steady_state

# most AFT samples per period the automatic sampling may choose (sampled_response; one DOF:
# a branch with 4096 samples takes tens of seconds: benchmarks/README.md, 'Moved from the
# package's docstrings', oscillator.py)
MAX_AUTO_SAMPLES = 4096
# the automatic sampling's first choice for an inclined contact (its normal load varies and
# lifts off: the kink of the normal force is under-resolved by 64 samples; 256 is the smallest
# count tried at which the inclined random oscillators pass: benchmarks/README.md, 'Moved from
# the package's docstrings', oscillator.py)
INCLINED_FIRST_SAMPLES = 256


@dataclass
class FrictionOscillator:
    """Single-DOF friction oscillator.

    Parameters
    ----------
    mass : m [kg]
    stiffness : k [N/m]
    damping : c [N s/m]
    contact_stiffness : tangential contact stiffness k_T [N/m]
    friction_coefficient : mu [-]
    normal_load : static normal load N0 [N]
    forcing : excitation amplitude F [N]
    contact_angle : inclination alpha of the contact plane to the motion [rad], in [0, pi/2)
    normal_stiffness : k_N [N/m], needed when contact_angle > 0 (default: k_T)
    cubic_stiffness : k3 [N/m^3] (hardening spring, gives folds)
    """

    mass: float = 1.0
    stiffness: float = 1.0e4
    damping: float = 1.0
    contact_stiffness: float = 1.0e4
    friction_coefficient: float = 0.3
    normal_load: float = 1.0
    forcing: float = 1.0
    contact_angle: float = 0.0
    normal_stiffness: float | None = None
    cubic_stiffness: float = 0.0

    def __post_init__(self):
        validation.positive("mass", self.mass)
        validation.positive("stiffness", self.stiffness)
        validation.nonnegative("damping", self.damping)
        validation.positive("contact_stiffness (k_T)", self.contact_stiffness)
        validation.nonnegative("friction_coefficient (mu)", self.friction_coefficient)
        validation.nonnegative("normal_load", self.normal_load)
        validation.finite("forcing", self.forcing)
        validation.in_range("contact_angle", self.contact_angle, 0.0, np.pi / 2, closed="left")
        if self.normal_stiffness is None:
            self.normal_stiffness = self.contact_stiffness
        validation.positive("normal_stiffness (k_N)", self.normal_stiffness)
        validation.finite("cubic_stiffness", self.cubic_stiffness)

    # ----- closed forms ---------------------------------------------------------------
    @property
    def slip_force(self) -> float:
        """mu N0 [N]."""
        return self.friction_coefficient * self.normal_load

    @property
    def stuck_contact_stiffness(self) -> float:
        """The stuck contact's stiffness along the motion, k_T cos^2(alpha) + k_N sin^2(alpha) [N/m]."""
        return self.contact_stiffness * np.cos(self.contact_angle) ** 2 \
            + self.normal_stiffness * np.sin(self.contact_angle) ** 2

    def linear_natural_frequencies_hz(self, f_low_hz: float = 0.0, f_high_hz: float = 0.0) -> tuple[float, float]:
        """(without the contact, contact stuck): sqrt(k / m) / 2 pi and sqrt((k + k_stuck) / m) / 2 pi
        [Hz], the natural frequencies of the two linear systems (one each: the range is not
        needed); the friction-damped resonance lies between them."""
        return (float(np.sqrt(self.stiffness / self.mass) / (2 * np.pi)),
                float(np.sqrt((self.stiffness + self.stuck_contact_stiffness) / self.mass) / (2 * np.pi)))

    @property
    def friction_limit(self) -> float:
        """4 mu N0 / pi [N]: the largest first-harmonic amplitude of a contact force bounded by
        mu N0 (a square wave of height mu N0), the most forcing a constant normal load can hold."""
        return 4 * self.slip_force / np.pi

    def check_bounded(self, f_start_hz: float, f_end_hz: float) -> None:
        """ValueError where no bounded periodic response exists in ``f_start_hz``..``f_end_hz``
        [Hz]: no viscous damping, a constant normal load (contact_angle 0), a linear spring
        (cubic_stiffness 0), |F| above :attr:`friction_limit`, and the natural frequency without
        the contact, sqrt(k / m) / 2 pi (:meth:`linear_natural_frequencies_hz`), inside the range.
        At that frequency the mass and spring forces cancel in the first harmonic, so the contact
        force alone must balance F, and its first harmonic is at most 4 mu N0 / pi: no periodic
        motion exists there, and the amplitude grows without bound as the excitation frequency
        approaches it (Den Hartog's undamped friction oscillator)."""
        f_n = self.linear_natural_frequencies_hz()[0]
        if not (self.damping == 0.0 and self.contact_angle == 0.0 and self.cubic_stiffness == 0.0
                and abs(self.forcing) > self.friction_limit
                and min(f_start_hz, f_end_hz) <= f_n <= max(f_start_hz, f_end_hz)):
            return
        raise ValueError(
            f"no bounded response: with damping = 0 N s/m the forcing |F| = {abs(self.forcing):.6g} N exceeds the "
            f"friction limit 4 mu N0 / pi = {self.friction_limit:.6g} N (mu = {self.friction_coefficient:g}, "
            f"N0 = {self.normal_load:g} N), so the amplitude grows without bound at the natural frequency "
            f"sqrt(k / m) / (2 pi) = {f_n:.6g} Hz, inside the range {f_start_hz:g}-{f_end_hz:g} Hz; give damping > 0, "
            f"a forcing of at most {self.friction_limit:.6g} N, or a range without {f_n:.6g} Hz")

    def linear_amplitude(self, f_hz, stuck: bool) -> np.ndarray:
        """Amplitude of the linear system with the contact stuck or absent (k) [m] at the
        excitation frequencies ``f_hz`` [Hz] (scalar or array; same shape).

        Stuck (and never lifting off): k + k_T cos^2(alpha) + k_N sin^2(alpha).
        """
        return self._linear_amplitude(2 * np.pi * np.asarray(f_hz, dtype=float), stuck)

    def _linear_amplitude(self, omega, stuck: bool) -> np.ndarray:
        """:meth:`linear_amplitude` at angular frequencies ``omega`` [rad/s]."""
        omega = np.asarray(omega, dtype=float)
        k = self.stiffness + (self.stuck_contact_stiffness if stuck else 0.0)
        return np.abs(self.forcing / (k - self.mass * omega ** 2 + 1j * self.damping * omega))

    # ----- harmonic balance -----------------------------------------------------------
    def hbm_system(self, harmonics=(1,), n_samples=None) -> HarmonicBalanceSystem:
        """The harmonic balance residual of this oscillator."""
        basis = HarmonicBasis(tuple(harmonics), n_samples)
        C = basis.n_coeffs
        alpha = self.contact_angle
        contact = PointContactElement(self.contact_stiffness, self.friction_coefficient,
                                      LinearNormalLaw(self.normal_stiffness), 1.0,
                                      self.normal_load / self.normal_stiffness)
        direction = np.array([[np.cos(alpha)], [0.0], [-np.sin(alpha)]])  # x -> (u_xi, u_eta, u_zeta)
        couplings = [Coupling(contact, basis.real_form(lambda h: direction), "contact")]
        if self.cubic_stiffness != 0.0:
            couplings.append(Coupling(CubicSpring(self.cubic_stiffness), np.eye(C), "cubic spring"))
        f = np.zeros(C)
        f[basis.cos_index(1)] = self.forcing
        return HarmonicBalanceSystem(basis, [[self.mass]], [[self.damping]], [[self.stiffness]],
                                     lambda omega: (f, np.zeros(C)), couplings)

    # ----- derivatives in the parameters -------------------------------------------------
    #: the fields with derivatives (:meth:`parameter_derivatives`), in SI (contact_angle in rad)
    PARAMETERS = ("mass", "stiffness", "damping", "contact_stiffness", "friction_coefficient", "normal_load",
                  "normal_stiffness", "forcing", "cubic_stiffness", "contact_angle")

    def parameter_derivatives(self, system: HarmonicBalanceSystem, keys):
        """``dR_dp(x, omega) -> (k, C)``: the analytic derivatives of ``system`` (this oscillator's
        :meth:`hbm_system`) at x (C,) and omega [rad/s] in the fields ``keys`` (:attr:`PARAMETERS`,
        SI units) [N per unit]: the linear part and the forcing in closed form, the contact by its
        homogeneity (k_T dF/dk_T = J_t c_t, mu dF_t/dmu = F_t - J_tt c_t, k_N dF/dk_N = F - J_t c_t,
        the preload offset N0 / k_N: offset dF/doffset = F - J c, the law being linear), the cubic
        spring's force per k3, and the contact direction's angle through the map
        (dT^T F + T^T J dT x). ValueError naming an unknown key."""
        keys = tuple(str(k) for k in keys)
        for key in keys:
            if key not in self.PARAMETERS:
                raise ValueError(f"parameter {key!r}: an oscillator's parameters with derivatives are "
                                 f"{', '.join(self.PARAMETERS)}")
            if key == "friction_coefficient" and self.friction_coefficient == 0:
                raise ValueError("parameter 'friction_coefficient': the derivative in mu is taken at mu > 0")
        basis = system.basis
        C = basis.n_coeffs
        contact = system.couplings[0]
        tangential = np.array([i % 3 < 2 for i in range(contact.matrix.shape[0])])
        alpha = self.contact_angle
        d_map = basis.real_form(lambda h: np.array([[-np.sin(alpha)], [0.0], [-np.cos(alpha)]]))
        unit = np.zeros(C)
        unit[basis.cos_index(1)] = 1.0
        one = np.ones((1, 1))

        def dR_dp(x, omega):
            local = contact.matrix @ x
            force, jac, _ = contact.element.harmonic_forces(local.reshape(C, 3), basis, omega, True)
            force = force.ravel()
            j_t = jac[:, tangential] @ local[tangential]
            scale = force - j_t
            out = np.zeros((len(keys), C))
            for row, key in zip(out, keys):
                if key in ("mass", "damping", "stiffness"):
                    row += linear_forces(basis, x, omega, **{key: one})
                elif key == "forcing":
                    row -= unit
                elif key == "cubic_stiffness":
                    row += CubicSpring(1.0).harmonic_forces(x.reshape(C, 1), basis, omega, False)[0].ravel()
                elif key == "contact_angle":
                    row += d_map.T @ force + contact.matrix.T @ (jac @ (d_map @ x))
                else:
                    direction = {"contact_stiffness": j_t / self.contact_stiffness,
                                 "friction_coefficient": np.where(tangential, scale, 0.0) / self.friction_coefficient,
                                 "normal_stiffness": (scale - (force - jac @ local)) / self.normal_stiffness,
                                 "normal_load": (force - jac @ local) / max(self.normal_load, 1e-300)}[key]
                    contact.add_forces(row, direction)
            return out

        return dR_dp

    def parameter_value(self, key: str) -> float:
        """The value of field ``key`` (:attr:`PARAMETERS`) [SI]."""
        if key not in self.PARAMETERS:
            raise ValueError(f"parameter {key!r}: an oscillator's parameters with derivatives are "
                             f"{', '.join(self.PARAMETERS)}")
        return float(getattr(self, key))

    def output(self, basis: HarmonicBasis) -> np.ndarray:
        """(C,) complex: the first-harmonic displacement x_1 = a_1 - i b_1 of the unknowns."""
        return first_harmonic_output(basis, 1, [0], [1.0])

    def sensitivities(self, response: FrequencyResponse, parameters) -> Sensitivities:
        """The derivatives of every point of this oscillator's ``response`` in its fields
        ``parameters`` (:attr:`PARAMETERS`, per SI unit; :func:`~bladedamp.response.branch_sensitivities`)."""
        keys = tuple(str(p) for p in parameters)
        system = self.hbm_system(response.basis.harmonics, response.basis.n_samples)
        return branch_sensitivities(system, response.omega, response.coefficients, self.output(response.basis),
                                    self.parameter_derivatives(system, keys), keys, tuple("SI" for _ in keys),
                                    [self.parameter_value(k) for k in keys])

    def peak_sensitivities(self, response: FrequencyResponse, parameters) -> PeakSensitivities:
        """The derivatives of the peak of this oscillator's ``response`` in its fields ``parameters``
        (:func:`~bladedamp.response.solved_peak_sensitivities`): d peak amplitude / dp [m per SI
        unit], d peak frequency / dp [Hz per SI unit]."""
        keys = tuple(str(p) for p in parameters)
        system = self.hbm_system(response.basis.harmonics, response.basis.n_samples)
        return solved_peak_sensitivities(system, response.omega, response.coefficients, self.output(response.basis),
                                         self.parameter_derivatives(system, keys), keys, tuple("SI" for _ in keys),
                                         [self.parameter_value(k) for k in keys])

    def frequency_response(self, f_start_hz: float, f_end_hz: float, harmonics="auto", n_samples=None,
                           harmonic_tolerance: float = HARMONIC_TOLERANCE, max_harmonic: int = 9,
                           cpu_budget_s: float = DEFAULT_CPU_BUDGET_S, point_budget: int = DEFAULT_POINT_BUDGET,
                           **continuation_options) -> FrequencyResponse:
        """FRF by harmonic balance and pseudo-arclength continuation from ``f_start_hz`` to
        ``f_end_hz`` [Hz] (as :meth:`bladedamp.disk.TunedDisk.frequency_response`; the result's
        ``omega`` is the angular frequency [rad/s], ``frequency_hz`` the same in Hz).

        ``harmonics``: ``"auto"`` (default) chooses the set whose first-harmonic amplitude is
        converged to ``harmonic_tolerance`` (see :mod:`bladedamp.hbm.accuracy`; the static term
        is always in it: an inclined contact's normal load varies with the motion); a tuple is
        used as given, with its error estimate; ``max_harmonic`` caps the automatic choice
        (default 9: one DOF is cheap). ``n_samples``: AFT samples per period; None (default)
        chooses them (:func:`bladedamp.response.sampled_response`: the basis default, at least
        ``INCLINED_FIRST_SAMPLES`` for an inclined contact, four times more while the branch
        fails, up to ``MAX_AUTO_SAMPLES``). ``continuation_options`` go to
        :func:`bladedamp.hbm.continuation.continuation` (``max_step`` sets the point density).
        The result is ``success`` only if the branch reached the end and passed
        :func:`bladedamp.response.physical_checks`, with the contact's dissipation judged at the
        solve's own samples (``judge_solution_samples``) below ``MAX_AUTO_SAMPLES``: there a
        successful result's contact dissipation is at least -``SAMPLING_FLOOR``
        (:mod:`bladedamp.response`) of each point's energy scale, the larger of the excitation
        work and the contact's work bound (its AFT energy error); where it is not, the samples
        grow as above. At ``MAX_AUTO_SAMPLES`` the growth ends and the dissipation is judged as
        the disks' is, re-evaluated with ``REFINE_SAMPLES_FACTOR`` x the samples (a contact whose
        lift-off makes the AFT converge slowly would otherwise be refused its accurate harmonic
        set).
        A range where no bounded response exists (:meth:`check_bounded`) is refused with a
        ValueError before any solve.
        ``cpu_budget_s`` [s] and ``point_budget``: the CPU time (``time.process_time``) and the
        continuation points this whole analysis may spend (:class:`bladedamp.hbm.continuation.Budget`;
        defaults ``DEFAULT_CPU_BUDGET_S``, ``DEFAULT_POINT_BUDGET``). Where it runs out the branch
        ends there with every point it has, status ``OUT_OF_BUDGET`` (not ``success``), and
        ``stopped_by`` and the message say what ran out and at which frequency.
        """
        solve = branch_solver(self, f_start_hz, f_end_hz, n_samples, continuation_options.pop("max_step", DEFAULT_MAX_STEP),
                              None, cpu_budget_s, point_budget, **continuation_options)
        return with_range_end_estimate(self, converged_response(self, solve, harmonics, harmonic_tolerance,
                                                                max_harmonic))

    # ----- the protocol of bladedamp.frf (the FRF driver) ----------------------------------
    def sample_plan(self, harmonics) -> tuple[int, int, None]:
        """(first, most, None) AFT samples per period of the automatic sampling
        (:func:`bladedamp.response.sampled_response`): the basis default, at least
        ``INCLINED_FIRST_SAMPLES`` for an inclined contact, up to ``MAX_AUTO_SAMPLES``."""
        first = HarmonicBasis(tuple(harmonics)).n_samples
        if self.contact_angle != 0.0:
            first = max(first, INCLINED_FIRST_SAMPLES)
        return first, MAX_AUTO_SAMPLES, None

    def response_from_branch(self, system: HarmonicBalanceSystem, branch) -> FrequencyResponse:
        """The :class:`~bladedamp.response.FrequencyResponse` of a continuation ``branch`` (one DOF, x)."""
        return FrequencyResponse(branch.omega, branch.x.reshape(-1, system.basis.n_coeffs, 1), system.basis, ("x",),
                                 branch.success, "", branch.iterations, branch.turning_points,
                                 stopped_by=branch.stopped_by, notes=(continuation_note(branch),))

    def branch_energies(self, system: HarmonicBalanceSystem, branch, response: FrequencyResponse):
        """(excitation work (n,), the nonlinear elements' dissipation (n, 1), their work bound (n, 1))
        per period [J] at every point of ``branch`` (one AFT each)."""
        work = np.array([system.excitation_work(x, w) for x, w in zip(branch.x, branch.omega)])
        energies = np.array([[sum(e) for e in system.element_energies(x, w)]
                             for x, w in zip(branch.x, branch.omega)]).reshape(-1, 2)
        return work, energies[:, :1], energies[:, 1:]

    def refined_dissipation(self, system: HarmonicBalanceSystem, branch) -> np.ndarray:
        """(k, elements) each nonlinear element's dissipation per period [J] at the points of ``branch``."""
        return np.array([system.element_dissipation(x, w) for x, w in zip(branch.x, branch.omega)])

    def judges_solution_samples(self, n_samples: int) -> bool:
        """Below ``MAX_AUTO_SAMPLES`` the dissipation is judged at the solve's own samples too
        (:func:`bladedamp.response.physical_checks`; see :meth:`frequency_response`)."""
        return n_samples < MAX_AUTO_SAMPLES

    def retry_scales(self, system: HarmonicBalanceSystem, scales) -> None:
        """None: no retry with other scales (the oscillator has no damper unknowns)."""
        return None

    def start_solution(self, system: HarmonicBalanceSystem, omega: float, scale: float, out_of_time=None) -> np.ndarray:
        """Solution at the first frequency by :func:`bladedamp.hbm.start.robust_start`: damped
        Newton from the stuck linear solution (one Newton step from rest, where the contact
        sticks), then from the free one (no contact force), then the excitation homotopy;
        ``out_of_time``: None or () -> bool (the analysis' budget), asked before each solve."""
        R, J, _ = system.residual(np.zeros(system.n_unknowns), omega)
        stuck = -np.linalg.solve(J, R)
        free = system.linear_solution(omega)
        forcing = system.excitation(omega)[0]
        return robust_start(system.residual, {"stuck linear": stuck, "free linear": free}, omega, scale,
                            forcing, out_of_time=out_of_time).x

    # ----- the protocol of bladedamp.hbm.accuracy ----------------------------------------
    def output_amplitudes(self, coefficients: np.ndarray, basis: HarmonicBasis) -> np.ndarray:
        """(n, 1) first-harmonic amplitude of x [m] of coefficients (n, C, 1)."""
        j1 = basis.cos_index(1)
        return np.hypot(coefficients[:, j1], coefficients[:, j1 + 1])

    def static_state(self, system: HarmonicBalanceSystem, omega: float) -> np.ndarray:
        """The state without dynamic motion: rest (the contact's preload needs no static motion)."""
        return np.zeros(system.n_unknowns)

    def unknown_scales(self, system: HarmonicBalanceSystem | None, omega_start: float, omega_end: float):
        """Scale of the unknowns: the free linear amplitude over omega_start..omega_end [rad/s,
        the residual's Omega, as every solver-protocol method] [m] (the same for any harmonic
        set, so ``system`` is not needed)."""
        return max(self._linear_amplitude([omega_start, omega_end], stuck=False).max(),
                   abs(self.forcing) / self.stiffness, 1e-300)

    def energy_balance(self, response: FrequencyResponse):
        """Per point: (excitation work, viscous dissipation, contact dissipation) per cycle [J]."""
        system = self.hbm_system(response.basis.harmonics, response.basis.n_samples)
        rows = []
        for omega, X in zip(response.omega, response.coefficients):
            x = X.ravel()
            rows.append((system.excitation_work(x, omega), system.viscous_dissipation(x, omega),
                         sum(system.element_dissipation(x, omega))))
        return np.array(rows)

    # ----- time integration -----------------------------------------------------------
    @property
    def has_period_map(self) -> bool:
        """True: the monodromy method has this model's period map
        (:class:`bladedamp.hbm.monodromy.PeriodMapModel`)."""
        return True

    def monodromy_matrix(self, coefficients, basis, omega: float, steps: int | None = None):
        """(monodromy matrix (3, 3), periodicity error) of the HBM solution ``coefficients`` at
        ``omega`` [rad/s] (:func:`bladedamp.hbm.monodromy.oscillator_monodromy`; ``steps`` per
        period, None: ``STEPS_PER_PERIOD``)."""
        mono, _, error = oscillator_monodromy(self, coefficients, basis, omega,
                                              STEPS_PER_PERIOD if steps is None else steps)
        return mono, error

    def time_response(self, f_hz, steps_per_period: int = 2048, max_periods: int = 5000,
                      min_periods: int = 20, tol: float = 1e-9, initial_displacement: float = 0.0,
                      initial_velocity: float = 0.0) -> TimeResponse:
        """Steady state by central-difference integration at each excitation frequency ``f_hz``
        [Hz] (scalar or array), from ``initial_displacement`` [m] and ``initial_velocity`` [m/s]
        (default rest; started elsewhere, e.g. on an HBM solution, it shows which steady state
        that start leads to where several coexist); the result's ``omega`` is in rad/s.
        The cubic spring is integrated too: its stiffness 3 k3 x^2 grows with the amplitude, so
        the step bound checked here (from the linear stiffnesses) does not cover it; a run that
        blows up returns ``converged`` False."""
        f_hz = np.atleast_1d(np.asarray(f_hz, dtype=float))
        validation.positive("f_hz (excitation frequency, Hz)", f_hz)
        validation.integer("steps_per_period", steps_per_period, minimum=16)
        omega = 2 * np.pi * f_hz
        dt_max = 2.0 / np.sqrt((self.stiffness + self.contact_stiffness + self.normal_stiffness) / self.mass)
        if np.any(2 * np.pi / omega / steps_per_period > 0.5 * dt_max):
            lowest = float(f_hz.min())
            need = int(np.ceil(2 * np.pi / (2 * np.pi * lowest) / (0.5 * dt_max)))
            raise ValueError(f"steps_per_period must be >= {need} for the explicit scheme at the lowest "
                             f"frequency {lowest:.6g} Hz (got {steps_per_period})")
        validation.finite("initial_displacement", initial_displacement)
        validation.finite("initial_velocity", initial_velocity)
        samples = np.zeros((omega.size, steps_per_period))
        periods = np.zeros(omega.size, dtype=int)
        converged = np.zeros(omega.size, dtype=bool)
        sin_a, cos_a = np.sin(self.contact_angle), np.cos(self.contact_angle)
        for i, w in enumerate(omega):
            periods[i], converged[i] = oscillator_steady_state(
                w, self.mass, self.damping, self.stiffness, self.cubic_stiffness, self.contact_stiffness,
                self.friction_coefficient, self.normal_load, self.normal_stiffness, sin_a, cos_a,
                self.forcing, steps_per_period, max_periods, min_periods, tol, samples[i],
                float(initial_displacement), float(initial_velocity))
            converged[i] &= bool(np.all(np.isfinite(samples[i])))
        spec = np.fft.rfft(samples, axis=1) / steps_per_period
        return TimeResponse(omega, 2 * np.abs(spec[:, 1]), np.abs(samples).max(axis=1), samples, periods, converged)
