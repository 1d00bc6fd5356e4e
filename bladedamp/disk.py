"""The tuned bladed disk by cyclic symmetry (Eq. 21-25): one sector, one blade and one damper.

Unknowns of one sector: the blade's modal coordinates q (Eq. 2) and the six rigid-body
coordinates u_D of its damper (the damper between this blade, at its OL platform, and the
next blade, at that blade's OR platform). Harmonic h of the next blade is this blade's
times e^{i h dphi}, dphi = 2 pi EO / n (Eq. 25; :func:`~bladedamp.diskmodel.nodal_diameter`), so
the relative motion at the contacts is

    w_h = G_D u_D,h - G_P [Phi_OL ; e^{i h dphi} Phi_OR] q_h          (Eq. 6, 24)

and the contact forces go back to the sector through the transpose of the same (complex) map.
What the tuned disk shares with the full ring (the damper position, the contact element, the
start, the checks) is :mod:`bladedamp.diskmodel`'s; its full assembly, every blade written out,
is a :class:`~bladedamp.mistuned.MistunedDisk` (:meth:`TunedDisk.full_assembly`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from . import validation
from .blade import PLATFORM_ANGLE, ModalBlade
from .damper.geometry import CylinderDamper, DamperGeometry, WedgeDamper
from .damper.kinetics import seat
from .diskmodel import (DAMPER_DOFS, DEFAULT_DAMPER_RADIUS, DamperPosition, DiskModel, DiskModelResponse,
                        WithCouplings, check_blade_bounded, contact_point_field, contact_rows, nodal_diameter,
                        peak_checked_response, rest_response, rotor_speed_in_hz, with_stop_check)
from .frf import branch_solver, checked_range
from .hbm.accuracy import HARMONIC_TOLERANCE
from .hbm.continuation import DEFAULT_CPU_BUDGET_S, DEFAULT_MAX_STEP, DEFAULT_POINT_BUDGET
from .hbm.fourier import HarmonicBasis
from .hbm.nonlinear_modes import linear_stuck_mode
from .hbm.peaks import PeakSolver, first_harmonic_output
from .hbm.system import Coupling, HarmonicBalanceSystem
from .mistuned import MistunedDisk
from .response import continuation_note, nearest_to_range, plot_branch, with_range_end_estimate


@dataclass
class TunedDisk(DiskModel):
    """Tuned bladed disk with one damper per blade pair (cyclic symmetry, Eq. 21-25).

    Parameters
    ----------
    blade : ModalBlade (points OL, OR, tip, excitation)
    damper : CylinderDamper, WedgeDamper or None (mass 0 or None: no damper)
    n_blades : n >= 2
    engine_order : EO >= 0; the nodal diameter and travelling direction follow from EO mod n
        (:func:`nodal_diameter`), the rotor speed Omega_E / EO from EO itself
    gamma_left, gamma_right : platform angles at OL and OR [rad], in (0, pi/2)
    damper_radius : R, distance of the damper's centre of gravity to the rotor axis [m]
    excitation : (6,) harmonic tip load (F_x, F_y, F_z, M_x, M_y, M_z) at the blade's
        "excitation" point [N, N m] (cosine amplitude)
    rotor_speed_hz : rotor speed [Hz, revolutions per second] (rpm / 60), required when EO = 0;
        None (default): Omega_R = Omega_E / EO follows the excitation frequency (Eq. 3, 26)
    damper_inertia : include the damper's mass and rotary inertia in Eq. 12
    initial_gaps : (2, P) gaps of the OL and OR patch points before loading [m] (default: a
        perfect fit), e.g. :func:`bladedamp.geometry.misfit_gaps` of a damper that does not fit
    """

    blade: ModalBlade
    damper: CylinderDamper | WedgeDamper | None
    n_blades: int = 16
    engine_order: int = 1
    gamma_left: float = PLATFORM_ANGLE
    gamma_right: float = PLATFORM_ANGLE
    damper_radius: float = DEFAULT_DAMPER_RADIUS
    excitation: np.ndarray = field(default_factory=lambda: np.array([0.1, 0, 0, 0, 0, 0]))
    rotor_speed_hz: float | None = None
    damper_inertia: bool = True
    initial_gaps: np.ndarray | None = None

    def __post_init__(self):
        self.rotor_speed_hz = rotor_speed_in_hz(self.rotor_speed_hz)
        validation.integer("n_blades", self.n_blades, minimum=2)
        self.engine_order = validation.integer("engine_order (EO)", self.engine_order, minimum=0)
        self.position.validate()
        self.validate_parameters(self.has_damper)

    # ----- geometry --------------------------------------------------------------------
    @property
    def has_damper(self) -> bool:
        return self.damper is not None and self.damper.mass > 0

    @property
    def nodal_diameter(self) -> tuple[int, str]:
        """(nodal diameter k, "forward" / "backward" / "standing") of the engine order (:func:`nodal_diameter`)."""
        return nodal_diameter(self.engine_order, self.n_blades)

    @property
    def dof_names(self) -> tuple[str, ...]:
        modes = self.blade.mode_names or tuple(f"q{j + 1}" for j in range(self.blade.n_modes))
        return tuple(f"q_{m}" for m in modes) + (DAMPER_DOFS if self.has_damper else ())

    # ----- the layout of DiskModel: one blade, one damper ------------------------------
    @property
    def position(self) -> DamperPosition:
        """The damper position of every sector (:class:`DamperPosition`; built from the fields on
        each call, so that a field set after construction is seen)."""
        return DamperPosition(self.damper, self.gamma_left, self.gamma_right, self.initial_gaps, self.damper_radius,
                              self.engine_order, self.rotor_speed_hz)

    def with_dampers(self, change) -> "TunedDisk":
        """This disk with its damper replaced by ``change(damper)`` (a new disk; none without a damper)."""
        return self if self.damper is None else dataclasses.replace(self, damper=change(self.damper))

    def with_blades(self, change) -> "TunedDisk":
        """This disk with its blade replaced by ``change(0, blade)`` (a new disk)."""
        return dataclasses.replace(self, blade=change(0, self.blade))

    def position_of(self, k: int) -> DamperPosition:
        """The damper position of every sector (:attr:`position`; ``k``: 0)."""
        return self.position

    @property
    def model_blades(self) -> list[ModalBlade]:
        """[blade]: the reference sector's blade, the one blade written out (:class:`DiskModel`)."""
        return [self.blade]

    @property
    def active_positions(self) -> list[int]:
        """[0] with a damper (it has a mass), else []."""
        return [0] if self.has_damper else []

    def damper_unknowns(self, d: int = 0) -> slice:
        """The damper's six coordinates among the n_m + 6 unknowns per coefficient (after the
        blade's modal coordinates)."""
        nm = self.blade.n_modes
        return slice(nm, nm + 6)

    def seated_damper(self, k: int, omega: float) -> np.ndarray:
        """(6,) the damper seated frictionlessly under F_CG at ``omega`` [rad/s] (``seat``; ``k``: 0)."""
        return self.position.seated(omega)

    def damper_geometry(self) -> DamperGeometry:
        """The damper's contact frames and patches (:meth:`DamperPosition.damper_geometry`)."""
        return self.position.damper_geometry()

    def platform_offsets(self, geometry: DamperGeometry) -> np.ndarray:
        """(2, 3) contact centres seen from the blade's OL / OR points (in each blade's frame;
        :meth:`DamperPosition.platform_offsets`)."""
        return self.position.platform_offsets(geometry, self.blade.points)

    def centrifugal_force(self, f_hz: float):
        """(F_CG [N], dF_CG / dOmega_E [N s/rad]) at the excitation frequency ``f_hz`` [Hz] (Eq. 26;
        Omega_E = 2 pi f_hz, the rotor speed Omega_E / EO unless ``rotor_speed_hz`` is given)."""
        return self._centrifugal_force(2 * np.pi * f_hz)

    def _centrifugal_force(self, omega: float):
        """:meth:`centrifugal_force` at the angular excitation frequency ``omega`` [rad/s] (the residual's)."""
        return self.position.centrifugal_force(omega)

    # ----- harmonic balance --------------------------------------------------------------
    def hbm_system(self, harmonics=(1,), n_samples=None, static_retention: float = 1e-4) -> HarmonicBalanceSystem:
        """The harmonic balance of one sector.

        ``static_retention``: with a static harmonic, frictionless seating leaves the damper's
        axial position (and the cylinder's roll angle) free; a spring of this fraction of the
        normal contact stiffness on the static harmonic of the damper fixes them
        (:func:`bladedamp.damper.retention_stiffness`). It must not
        be too weak: the mean tangential force left by slip onset (frictional shakedown) is
        independent of the mean position, so only this spring balances it; at 1e-6 the
        reference cylinder's (0, 1, 2, 3) continuation stalls at slip onset (~95.0 Hz, Newton
        2-cycles in the static axial position). 1e-4 keeps the reference peaks within ~0.01 % of
        the weak-spring limit (benchmarks/README.md, 'Moved from the package's docstrings',
        disk.py, 'static_retention').
        """
        basis = HarmonicBasis(tuple(harmonics), n_samples)
        C, nm = basis.n_coeffs, self.blade.n_modes
        n = nm + (6 if self.has_damper else 0)
        omega0 = self.blade.natural_angular_frequencies
        M, D, K = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
        M[:nm, :nm] = np.eye(nm)
        K[:nm, :nm] = np.diag(omega0 ** 2)
        D[:nm, :nm] = np.diag(2 * self.blade.damping_ratios * omega0)  # Eq. 5
        modal_force = self.blade.shape("excitation").T @ self.excitation
        j1 = basis.cos_index(1)
        couplings, static_stiffness = [], None
        if self.has_damper:
            geometry = self.damper_geometry()
            if self.damper_inertia:
                M[nm:, nm:] = geometry.inertia
            contacts, G_D, G_P = self.position.contacts(geometry, self.approach_function(geometry, basis), self.blade,
                                                        self.blade)
            couplings.append(Coupling(contacts, self.contact_coupling(basis, [(G_D, G_P)], contacts.n_local,
                                                                      contacts.flexible), "damper contacts"))
            if basis.has_static:
                static_stiffness = np.zeros((n, n))
                static_stiffness[nm:, nm:] = DamperPosition.retention(geometry, static_retention)

        centrifugal = self._centrifugal_law() if self.has_damper and basis.has_static else None
        j0 = basis.cos_index(0) * n + nm + 2 if centrifugal is not None else None   # F_CG's entry
        dynamic = np.zeros(C * n)
        dynamic[j1 * n:j1 * n + nm] = modal_force

        def excitation(omega):
            f, df = dynamic.copy(), np.zeros(C * n)
            if centrifugal is not None:
                f[j0], df[j0] = centrifugal(omega)      # radially outwards on the damper
            return f, df

        return HarmonicBalanceSystem(basis, M, D, K, excitation, couplings, static_stiffness)

    def contact_coupling(self, basis: HarmonicBasis, kinematics, n_local: int, flexible: bool) -> np.ndarray:
        """The real-form map (C n_local, C n) from the sector's unknowns to its damper's local
        coordinates (Eq. 6, 24): w = G_D u_D - G_P [Phi_OL; e^{i h dphi} Phi_OR] q for the rigid
        kinematics ``kinematics`` = [(G_D (12, 6), G_P (12, 12))] (one damper), and with
        ``flexible`` platforms the platforms' modal coordinates (OL on this blade, OR on the
        next). Linear in (G_D, G_P): with their derivatives and ``flexible`` False it is the map's
        derivative (:meth:`~bladedamp.diskmodel.DiskModel.parameter_effect`)."""
        (G_D, G_P), = kinematics
        nm = self.blade.n_modes
        n = nm + 6
        phi = np.vstack([self.blade.shape("OL"), self.blade.shape("OR")])  # (12, nm)
        dphi = self.interblade_phase
        w_rows, left_rows, right_rows = contact_rows(n_local // 2, nm)

        def sector_map(h):
            phase = np.ones(12, dtype=complex)
            phase[6:] = np.exp(1j * h * dphi)          # Eq. 24: the OR platform is the next blade's
            out = np.zeros((n_local, n), dtype=complex)
            out[w_rows, :nm] = -G_P @ (phase[:, None] * phi)
            out[w_rows, nm:] = G_D
            if flexible:                               # the platforms' modal coordinates:
                out[left_rows, :nm] = np.eye(nm)       # OL on this blade, OR on the next
                out[right_rows, :nm] = phase[-1] * np.eye(nm)
            return out

        return basis.real_form(sector_map)

    def _centrifugal_law(self):
        """:meth:`DamperPosition.centrifugal_law` of the damper."""
        return self.position.centrifugal_law()

    def centrifugal_law(self):
        """A function omega [rad/s, the excitation frequency] -> (F_CG [N], dF_CG / dOmega_E
        [N s/rad]) of Eq. 26 whose parameters are validated once, here: for a residual that
        evaluates it at every call (:meth:`centrifugal_force` validates its arguments at each)."""
        return self._centrifugal_law()

    def approach_function(self, geometry: DamperGeometry, basis: HarmonicBasis):
        """The static approach of ``geometry``'s contact points under this disk's F_CG (Eq. 26):
        :meth:`DamperPosition.approach_function` (omega [rad/s] -> (approach (2, P) [m], its
        omega-derivative [m s/rad]))."""
        return self.position.approach_function(geometry, basis)

    def check_bounded(self, f_start_hz: float, f_end_hz: float) -> None:
        """ValueError where no bounded periodic response exists in ``f_start_hz``..``f_end_hz``
        [Hz] (:func:`check_blade_bounded` of the blade, with this disk's damper)."""
        check_blade_bounded(self.blade, self.excitation, self.has_damper, f_start_hz, f_end_hz)

    def static_normal_loads(self, f_hz: float) -> np.ndarray:
        """Static normal loads (N_OL, N_OR) [N] from frictionless seating under F_CG at the
        excitation frequency ``f_hz`` [Hz]."""
        if not self.has_damper:
            return np.zeros(2)
        return seat(self.damper_geometry(), self.centrifugal_force(f_hz)[0])[2]

    def frequency_response(self, f_start_hz: float, f_end_hz: float, harmonics="auto", n_samples=None,
                           max_step: float = DEFAULT_MAX_STEP, harmonic_tolerance: float = HARMONIC_TOLERANCE,
                           max_harmonic: int = 7, extra_couplings=None, stop_above: float | None = None,
                           stop_direction: int = 0, estimate_harmonic_error: bool = True,
                           check_stop: bool = False, check_peak: bool = False,
                           cpu_budget_s: float = DEFAULT_CPU_BUDGET_S, point_budget: int = DEFAULT_POINT_BUDGET,
                           **continuation_options) -> "DiskResponse":
        """Forced response from ``f_start_hz`` to ``f_end_hz`` [Hz] by continuation.

        ``harmonics``: ``"auto"`` (default) chooses the harmonic set whose first-harmonic tip
        amplitudes are converged to ``harmonic_tolerance`` (relative to the peak; see
        :mod:`bladedamp.hbm.accuracy`); a tuple such as ``(1,)`` (the paper's setting) or
        ``(0, 1, 2, 3)`` is used as given, and its error estimate is reported. ``max_harmonic``
        caps the automatic choice (default 7: the smallest cap at which both reference disks meet
        1 %; the cost grows with the harmonics (benchmarks/README.md, 'Moved from the package's
        docstrings', disk.py, 'max_harmonic'); a result above the tolerance says so). After a
        complete branch above the tolerance, the sets that point solves at its checked points find
        above it too are skipped (:func:`bladedamp.hbm.accuracy.predicted_set`): the answer is
        the first set whose own branch meets the tolerance, as set by set, or a richer one.
        ``max_step`` is the largest arc-length step in scaled units (the frequency range is 1;
        smaller: more points). The result is ``success`` only if the branch reached the end and
        passed :func:`bladedamp.response.physical_checks` and
        :func:`bladedamp.response.amplitude_check` (a tip amplitude beyond small deformations,
        10 % of the blade's span, fails it: status CHECK_FAILED); a range where no bounded response
        exists (:meth:`check_bounded`) is refused with a ValueError before any solve. Without
        dynamic excitation (``excitation`` zero, no ``extra_couplings``) the response is rest,
        exactly (:func:`rest_response`).
        ``n_samples``: AFT samples per period;
        None (default): the basis default, and once four times more if that branch fails
        (:func:`bladedamp.response.sampled_response`; ``AUTO_SAMPLES_GROWTH``), once more again
        if it reached the end and failed only the dissipation check (``AUTO_SAMPLES_GROWTH_DISSIPATION``).
        ``extra_couplings``: your own nonlinear elements, a callable ``basis -> sequence of
        Coupling`` (called for every harmonic set, the solved ones and the enriched one of the
        error estimate; ``self.point_map(basis, "tip")`` gives a blade point's map), added to
        the sector with :meth:`HarmonicBalanceSystem.add` (README, "Your own nonlinear element").
        ``stop_above`` [m]: end the branch at the first point whose first-harmonic tip amplitude in
        ``stop_direction`` (0, 1, 2: x, y, z) exceeds it (None: never). The response is then not
        ``success``, its ``stopped_by`` says so, and nothing is retried (no branch from the end, no
        finer AFT, no richer harmonics, no error estimate): the peak is known to be above the
        bound, which is all a search for the lowest peak needs (:func:`bladedamp.studies.optimal_mass`).
        ``estimate_harmonic_error=False`` (given harmonics only) skips the error estimate (5
        enriched Newton solves: 0.04-0.16 s of the reference disks' 0.5-0.75 s one-harmonic FRFs); the result then says "not
        estimated". For studies of many FRFs at one harmonic setting whose accuracy is reported
        once (the mass searches: ``reproduce``'s harmonic-accuracy section).
        ``check_stop``: where the branch ends before the end of the range (not by ``stop_above``),
        integrate the full assembly in time just beyond where it got furthest (:meth:`stop_check`;
        at ``f_start_hz`` when no point was kept) and put the verdict in the result (its
        ``stop_check`` and message, :func:`stop_verdict`): either the motion reached from the static
        equilibrium there is not periodic (the damper hops on the platforms or keeps rolling: no
        harmonic-balance branch represents it, and the time integration's amplitude is the answer
        there) or it is periodic, and the branch did not reach it. One time integration (20-230 s
        for 16 blades on 2 cores), and only for a branch that stopped before the end of its range;
        rigid platforms and no ``extra_couplings`` (what ``time_response`` models).
        ``check_peak``: for a branch that reached the end of the range, integrate the full
        assembly in time at the peak's frequency, started on the branch's own state there
        (:meth:`peak_check`): where that motion is
        periodic (or the blades settle while a damper keeps rolling), its difference from the
        branch is a direct harmonic error estimate (the only one where the enriched set's Newton
        fails at the peak, typically with the damper separated most of the period); where the
        vibration does not settle, the response fails (:func:`with_peak_check`; its
        ``peak_check`` keeps the integration). One time integration (1-3 s for 4 blades, 5-31 s
        for 16 on 2 cores); the same restrictions as ``check_stop``.
        ``cpu_budget_s`` [s] and ``point_budget``: the CPU time (``time.process_time``) and the
        continuation points this whole analysis may spend, the time integrations of
        ``check_stop`` and ``check_peak`` excepted (:class:`bladedamp.hbm.continuation.Budget`;
        defaults ``DEFAULT_CPU_BUDGET_S``, ``DEFAULT_POINT_BUDGET``). Where it runs out the branch
        ends there with every point it has, status ``OUT_OF_BUDGET`` (not ``success``), and
        ``stopped_by`` and the message say what ran out and at which frequency.
        """
        w0, w1 = checked_range(self, f_start_hz, f_end_hz)
        if stop_above is not None:
            validation.positive("stop_above", stop_above)
        validation.integer("stop_direction", stop_direction, minimum=0, maximum=2)

        for name, on in (("check_stop", check_stop), ("check_peak", check_peak)):
            if on and extra_couplings is not None:
                raise ValueError(f"{name} integrates the disk in time, which has no extra_couplings: "
                                 "give one or the other")
            if on and self.blade.flexible_platform:
                raise ValueError(f"{name} integrates the disk in time, which models rigid platforms only: "
                                 f"use blade.rigid_platform_blade() or {name}=False")
        model = self if extra_couplings is None else WithCouplings(self, extra_couplings)
        if not np.any(self.excitation) and extra_couplings is None:
            return rest_response(self, w0, w1, max_step, harmonic_tolerance,
                                 lambda system, branch: DiskResponse.from_branch(self, system, branch))
        can_check = extra_couplings is None and not self.blade.flexible_platform
        solve = branch_solver(model, f_start_hz, f_end_hz, n_samples, max_step, None if stop_above is None else
                              lambda basis: self.amplitude_stop(basis, stop_above, stop_direction),
                              cpu_budget_s, point_budget, **continuation_options)
        response = peak_checked_response(self, model, solve, harmonics, harmonic_tolerance, max_harmonic,
                                         estimate_harmonic_error, check_peak, can_check, predict=True)
        return with_range_end_estimate(self, with_stop_check(self, response, f_start_hz, check_stop))

    # ----- the protocol of bladedamp.frf (the FRF driver) ----------------------------------
    def response_from_branch(self, system: HarmonicBalanceSystem, branch) -> "DiskResponse":
        """:meth:`DiskResponse.from_branch` of this disk."""
        return DiskResponse.from_branch(self, system, branch)

    def branch_energies(self, system: HarmonicBalanceSystem, branch, response: "DiskResponse"):
        """(excitation work (n,), every contact point's dissipation (n, 2 P), its work bound (n, 2 P))
        per period [J] of ``response`` (no damper: (n, 0))."""
        return (response.excitation_work, contact_point_field(self, response, "point_dissipation"),
                contact_point_field(self, response, "point_work_bound"))

    def refined_dissipation(self, system: HarmonicBalanceSystem, branch) -> np.ndarray:
        """(k, 2 P) every contact point's dissipation per period [J] of ``branch`` on ``system``."""
        return contact_point_field(self, DiskResponse.from_branch(self, system, branch), "point_dissipation")

    def linear_natural_frequencies_hz(self, f_low_hz: float, f_high_hz: float) -> tuple[float, float]:
        """(without dampers, dampers stuck): the natural frequency [Hz] of each linear sector
        model (engine order ``engine_order``) nearest the range [``f_low_hz``, ``f_high_hz``]
        (:func:`bladedamp.response.nearest_to_range`). Without dampers: the generalised eigenvalues
        of the blade's stiffness and mass; stuck: the zero-amplitude linearisation at the static
        state, each mode at its own frequency when the preload follows the rotor speed
        (:func:`bladedamp.hbm.nonlinear_modes.linear_stuck_mode`), nan where it cannot be
        computed. A friction-damped resonance lies between them (up to the damper's inertia);
        used to say where a resonance outside the range may lie (:func:`with_range_end_estimate`)."""
        free, stuck = self.linear_natural_frequencies_up_to_hz(f_high_hz)
        free = nearest_to_range(free, f_low_hz, f_high_hz)
        return (free, free) if not self.has_damper else (free, nearest_to_range(stuck, f_low_hz, f_high_hz))

    def linear_natural_frequencies_up_to_hz(self, f_max_hz: float) -> tuple[np.ndarray, np.ndarray]:
        """(without dampers, dampers stuck): the natural frequencies [Hz], ascending, of the two
        linear sector models of :meth:`linear_natural_frequencies_hz`: every one without dampers
        (the blade's), and the stuck ones from the lowest up to the first above ``f_max_hz`` (the
        stuck system depends on the nodal diameter of the engine order, its preload on the rotor
        speed; empty without a damper; a repeated stuck mode ends the list)."""
        free_system = dataclasses.replace(self, damper=None).hbm_system((1,))
        M, K = (np.atleast_2d(m.toarray() if hasattr(m, "toarray") else np.asarray(m, dtype=float))
                for m in (free_system.mass, free_system.stiffness))
        lam = scipy.linalg.eigvals(K, M)
        lam = np.real(lam[np.isfinite(lam) & (np.real(lam) > 0)])
        free = np.sort(np.sqrt(lam) / (2 * np.pi))
        if not self.has_damper:
            return free, np.zeros(0)
        system, stuck = self.hbm_system((1,)), []
        for mode in range(system.n_dof):          # upwards until a mode lies above f_max_hz
            try:
                omega = linear_stuck_mode(self, system, mode)[0]
            except (ValueError, np.linalg.LinAlgError):   # no such mode, or a repeated one
                break
            stuck.append(omega / (2 * np.pi))
            if stuck[-1] > f_max_hz:
                break
        return free, np.array(stuck)

    def amplitude_stop(self, basis: HarmonicBasis, stop_above: float | None, direction: int = 0):
        """The continuation's ``stop_when`` for ``stop_above`` [m] (None: None): a message once the
        first-harmonic tip amplitude in ``direction`` of the unknowns x (C * n_dof,) exceeds it."""
        if stop_above is None:
            return None
        shape = (1, basis.n_coeffs, -1)

        def stop_when(x, omega):
            a = self.output_amplitudes(x.reshape(shape), basis)[0, direction]
            return f"tip amplitude {1e3 * a:.4g} mm above stop_above = {1e3 * stop_above:.4g} mm" \
                if a > stop_above else None
        return stop_when

    def solve_peak(self, response: "DiskResponse", index: int | None = None, direction: int = 0,
                   extra_couplings=None) -> tuple[float, float] | None:
        """(peak first-harmonic tip amplitude u_``direction`` [m], its frequency [Hz]) of the local
        maximum next to point ``index`` of ``response`` (default its largest amplitude), solved on
        the response curve by the peak condition (:class:`bladedamp.hbm.peaks.PeakSolver`); None
        where it is not solved (at an end of the branch, a fold next to the sample, a Newton solve
        that does not converge). ``extra_couplings``: those the response was computed with (see
        :meth:`frequency_response`). The branch only has to bracket the peak
        (:data:`bladedamp.studies.mass.PEAK_SEARCH_MAX_STEP`)."""
        validation.integer("direction", direction, minimum=0, maximum=2)
        basis = response.basis
        if index is None:
            index = int(np.argmax(response.tip_amplitude[:, direction]))
        model = self if extra_couplings is None else WithCouplings(self, extra_couplings)
        system = model.hbm_system(basis.harmonics, basis.n_samples)
        nm = self.blade.n_modes
        tip = first_harmonic_output(basis, system.n_dof, np.arange(nm), self.blade.shape("tip")[direction])
        solved = PeakSolver(system, response.omega, response.coefficients).solve(index, tip)
        return None if solved is None else (solved[0], solved[1] / (2 * np.pi))

    # ----- the protocol of bladedamp.hbm.accuracy ----------------------------------------
    def output_amplitudes(self, coefficients: np.ndarray, basis: HarmonicBasis) -> np.ndarray:
        """(n, 3) first-harmonic tip amplitudes [m] of coefficients (n, C, n_dof)."""
        j1, nm = basis.cos_index(1), self.blade.n_modes
        q1 = coefficients[:, j1, :nm] - 1j * coefficients[:, j1 + 1, :nm]
        return np.abs(q1 @ self.blade.shape("tip")[:3].T)

    def full_assembly(self):
        """The full assembly, every blade and damper written out, no cyclic reduction:
        ``MistunedDisk.from_tuned(self)`` (:class:`bladedamp.hbm.monodromy.AssemblyModel`)."""
        return MistunedDisk.from_tuned(self)

    def assembly_coefficients(self, full, coefficients, basis) -> np.ndarray:
        """The harmonic coefficients (C, N) on the full assembly ``full`` (:meth:`full_assembly`)
        of this sector's solution ``coefficients`` (C * n,) or (C, n) (n = n_m blade modes + 6
        damper coordinates): blade k's and damper k's harmonic h are the sector's turned by
        e^{i h k dphi} (X = a - i b; the static term the same), Eq. 24-25."""
        C = basis.n_coeffs
        X = np.asarray(coefficients, dtype=float).reshape(C, -1)
        nm = full.n_modes
        out = np.zeros((C, full.n_dof))
        blocks = [(full.blade_slice(k), slice(0, nm), k) for k in range(full.n_sector)]
        if self.has_damper:
            blocks += [(full.damper_slice(d), slice(nm, nm + 6), k) for d, k in enumerate(full.active_dampers)]
        for target, source, k in blocks:
            for h in basis.harmonics:
                j = basis.cos_index(h)
                if h == 0:
                    out[j, target] = X[j, source]
                    continue
                z = (X[j, source] - 1j * X[j + 1, source]) * np.exp(1j * h * k * full.interblade_phase)
                out[j, target], out[j + 1, target] = z.real, -z.imag
        return out

    @property
    def has_period_map(self) -> bool:
        """True: the monodromy method has this model's period map, that of its full assembly
        (:class:`bladedamp.hbm.monodromy.PeriodMapModel`)."""
        return True

    @staticmethod
    def time_output_amplitudes(check) -> np.ndarray:
        """(n_f, 3) first-harmonic tip amplitudes [m] of a :meth:`time_response` ``check``, the
        largest over the blades: what :meth:`output_amplitudes` gives for the reference sector."""
        return check.tip_amplitude.max(axis=1)


@dataclass
class DiskResponse(DiskModelResponse):
    """Frequency response of a tuned disk (reference sector): the attributes of
    :class:`DiskModelResponse` (``tip_amplitude`` (n, 3) [m]; ``dissipated_energy`` all contacts
    of one sector [J]; ``stop_check``, ``peak_check``) and (n points along the branch, C
    coefficients, P points per patch):

    modal_amplitude : (n, n_m) first-harmonic modal amplitudes [sqrt(kg) m]
    contact_force : (n, C, 12) generalised contact forces on the platforms, OL then OR (Eq. 11;
        forces and moments of the point forces about the control points)
    relative_motion : (n, C, 12) generalised relative motions w, OL then OR (Eq. 7; with a
        flexible platform those of its rigid-body fit, the blade's OL / OR shapes)
    point_displacement : (n, C, 2, P, 3) relative displacement coefficients of every patch point
    point_state : (n, 2, P, 3) fraction of the period each point sticks, slips, is separated
    point_dissipation : (n, 2, P) energy dissipated per period at each point [J]
    point_work_bound : (n, 2, P) each point's energy scale per period, the largest work its force
        and motion harmonics could do (HarmonicBasis.work_bound) [J]
    normal_load : (n, 2) mean normal load of OL, OR [N]

    ``peak_amplitude`` (float) is the largest sampled |u_x| of the reference blade;
    :attr:`~DiskModelResponse.blade_peak_amplitudes` is it as a (1,) array.
    """

    modal_amplitude: np.ndarray = None
    contact_force: np.ndarray = None
    relative_motion: np.ndarray = None
    point_displacement: np.ndarray = None
    point_state: np.ndarray = None
    point_dissipation: np.ndarray = None
    point_work_bound: np.ndarray = None
    normal_load: np.ndarray = None

    @classmethod
    def from_branch(cls, disk: TunedDisk, system: HarmonicBalanceSystem, branch) -> "DiskResponse":
        basis = system.basis
        C, n_dof, nm = basis.n_coeffs, system.n_dof, disk.blade.n_modes
        X = branch.x.reshape(-1, C, n_dof)
        npts = len(branch.omega)
        j1 = basis.cos_index(1)
        q1 = X[:, j1, :nm] - 1j * X[:, j1 + 1, :nm]
        work, viscous = cls.linear_energies(system, branch)
        out = dict(tip_amplitude=disk.output_amplitudes(X, basis), modal_amplitude=np.abs(q1), excitation_work=work,
                   viscous_dissipation=viscous)
        if disk.has_damper and npts:
            coupling = system.couplings[0]
            element = coupling.element
            P, T, m = element.geometry.patches[0].n_points, basis.n_samples, element.contact_local
            local = (coupling.matrix @ X.reshape(npts, -1).T).T.reshape(npts, C, element.n_local)
            force, pts = element.evaluate_states(local, basis, branch.omega)
            cf = force.reshape(npts, C, 2, m)[..., :6].reshape(npts, C, 12)
            rm = local.reshape(npts, C, 2, m)[..., :6].reshape(npts, C, 12)             # Eq. 7
            disp = basis.to_coeffs(np.moveaxis(pts.displacement, 1, 0)).reshape(C, npts, 2, P, 3)
            fcoef = basis.to_coeffs(np.moveaxis(pts.force, 1, 0)).reshape(C, npts, 2, P, 3)
            pdisp = np.moveaxis(disp, 0, 1)
            pstate = np.stack([(pts.state == s).mean(axis=1) for s in range(3)], axis=-1).reshape(npts, 2, P, 3)
            pdiss = basis.work_per_cycle(fcoef, disp).sum(axis=-1)
            pbound = basis.work_bound(fcoef, disp).sum(axis=-1)
            load = pts.normal_load.reshape(npts, 2, P, T).sum(axis=2).mean(axis=-1)
            out.update(contact_force=cf, relative_motion=rm, point_displacement=pdisp, point_state=pstate,
                       point_dissipation=pdiss, point_work_bound=pbound, dissipated_energy=pdiss.sum(axis=(1, 2)),
                       normal_load=load)
        else:
            out.update(dissipated_energy=np.zeros(npts))
        return cls(branch.omega, X, basis, disk.dof_names, branch.success, "", branch.iterations,
                   branch.turning_points, disk=disk, stopped_by=branch.stopped_by, notes=(continuation_note(branch),),
                   **out)

    def contact_state_shares(self) -> np.ndarray:
        """(n, 3) share of the period the damper's contact points stick, slip, are separated, the
        mean over every point of both contacts (zeros without a damper)."""
        if self.point_state is None:
            return np.zeros((len(self.omega), 3))
        return self.point_state.mean(axis=(1, 2))

    @property
    def peak_amplitude(self) -> float:
        """Largest first-harmonic tip amplitude |u_x| on the branch [m] (nan for an empty branch)."""
        return float(self.tip_amplitude[:, 0].max()) if len(self.omega) else float("nan")

    @property
    def peak_frequency_hz(self) -> float:
        """Frequency of the largest |u_x,tip| (the resonance) [Hz] (nan for an empty branch)."""
        return float(self.frequency_hz[np.argmax(self.tip_amplitude[:, 0])]) if len(self.omega) else float("nan")

    def peak_curve(self) -> np.ndarray:
        """(n,) first-harmonic tip amplitude |u_x| at every point [m] (its largest is the peak)."""
        return self.tip_amplitude[:, 0]

    def plot(self, ax=None, *, direction: int = 0, label: str | None = None, measured=None, **kwargs):
        """Tip amplitude [mm] over frequency [Hz] (the paper's Fig. 4-6 style). ``measured``: a
        measurement or its file drawn beside it in mm (:func:`bladedamp.measurement.draw_measurement`;
        an FRF times the disk's excitation force)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        if label is None:
            d = self.disk
            if d is None:                      # a loaded result (bladedamp.load): the model is not saved
                label = f"tuned disk, H={self.basis.harmonics}"
            else:
                label = f"{d.damper.kind} {1e3 * d.damper.mass:g} g" if d.has_damper else "no damper"
        plot_branch(ax, self.frequency_hz, 1e3 * self.tip_amplitude[:, direction], self.stable, label=label, **kwargs)
        return self.finish_plot(ax, direction, measured)
