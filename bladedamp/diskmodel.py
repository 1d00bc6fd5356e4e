"""What both disk models share: one damper position, one damper-contact element, the shared
disk behaviour and response, and the checks of a disk's answer.

A disk is assembled from blades (:class:`~bladedamp.blade.ModalBlade`) and damper positions
(:class:`DamperPosition`: the damper between blade k, at its OL platform, and blade k+1, at that
blade's OR platform; platform angles, initial gaps, the centrifugal preload law of Eq. 26). Two
assemblies use them: the tuned disk's cyclic sector (:class:`bladedamp.disk.TunedDisk`, Eq.
21-25) and the full ring (:class:`bladedamp.mistuned.MistunedDisk`). Both couple blades and
dampers through one element (:class:`AssemblyContacts`; the relative motion at the contacts
w = G_D u_D - G_P [Phi_OL q_k ; Phi_OR q_k+1], Eq. 6, and its transpose back), and both
inherit :class:`DiskModel` (static state, start, scales, point maps, time response, checks,
monodromy) and :class:`DiskModelResponse` (energy balance, peaks, plot).

A blade with per-point platform data (the solid FE blade: its platform face's own displacement
at every contact point) adds a flexible platform: each point's relative displacement is then
B_p w - R (u_FE - u_fit) q_c instead of B_p w (u_FE the face's FE motion at the point, u_fit the
rigid motion of the control point there; :func:`contact_point_maps`). The damper's equilibrium
(Eq. 12, with or without inertia) is part of the residual instead of being condensed (Eq.
13-15): same solution, exact sparse Jacobian.

Static preload: with the paper's one-harmonic setting ``harmonics=(1,)`` the damper is first
seated frictionlessly under the centrifugal force F_CG = m R Omega_E^2 / EO^2 (Eq. 26) and the
points keep that static approach; with a static harmonic (``0 in harmonics``) the centrifugal
force is a static load on the damper and the seating is part of the harmonic balance.

The checks of a disk's answer (module functions below :class:`DiskModel`): the stop check
(:func:`with_stop_note`), the peak check by time integration from the HBM state
(:func:`with_peak_check`), the retention-spring check (:func:`retention_check`) and the
stability note of an unsettled peak (:func:`peak_stability_note`).
"""
from __future__ import annotations

import contextlib
import dataclasses
import textwrap
import threading
import warnings

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from numba import njit

from . import validation
from .blade import PLATFORM_ANGLE, ModalBlade
from .contact.laws import LinearNormalLaw, RoughnessNormalLaw
from .contact.patch import dof_jacobian, rigid_point_map
from .contact.point import (MAX_PASSES, PARAMETER_DIRECTIONS, PERIODIC_TOL, PointContactSamples, damper_contact_forces,
                            damper_parameter_forces, normal_law_parameters, point_contact_forces)
from .damper.geometry import CylinderDamper, DamperGeometry, WedgeDamper
from .damper.kinetics import centrifugal_force, retention_stiffness, seat
from .hbm.accuracy import HARMONIC_TOLERANCE, AccuracyWarning, converged_response
from .hbm.continuation import Branch
from .hbm.start import robust_start
from .hbm.fourier import HarmonicBasis
from .hbm.monodromy import disk_monodromy
from .hbm.system import Coupling, HarmonicBalanceSystem, linear_forces
from .hbm.peaks import first_harmonic_output
from .response import (FrequencyResponse, Note, NoteKind, PeakSensitivities, Sensitivities, branch_sensitivities,
                       harmonic_sentence, percent, solved_peak_sensitivities, with_amplitude_check, with_checks,
                       with_note)

DAMPER_DOFS = ("uD_x", "uD_y", "uD_z", "phiD_x", "phiD_y", "phiD_z")
# the automatic AFT sampling of a disk's branch (TunedDisk and MistunedDisk) may grow the samples
# this much (one step of bladedamp.response.sampled_response): the smallest growth that cures the
# sampling failures of the random designs (benchmarks/README.md, 'Moved from the package's
# docstrings', disk.py, 'AFT sample growth')
AUTO_SAMPLES_GROWTH = 4
# ... and this much when the branch reached the end and failed only the dissipation check (an AFT
# sampling error, which needs more samples than a retrace does)
AUTO_SAMPLES_GROWTH_DISSIPATION = 16
# A disk's branch that fails (from either end of the range) is tried once more with the damper's
# unknowns weighing less in the arc length (their scale there DAMPER_ARC_SCALE x unknown_scales:
# the continuation's retry_x_scale), so that the arc length follows the blades' motion and the
# frequency. The damper is slaved to the platforms, and in gross slip a light damper's rotation
# is held by its inertia alone, so its rotation coefficients can take almost all of the arc
# length and the branch crawls. It is a retry, not the first try, because the weighted points
# follow the blades, fewer of them fall near a fold, and a peak taken from the points moves
# (benchmarks/README.md, 'Moved from the package's docstrings', disk.py, 'DAMPER_ARC_SCALE').
# The oscillator has no such unknown.
DAMPER_ARC_SCALE = 100.0

#: parameter_derivatives stacks the matrix derivatives of all keys (k n_dof, n_dof) dense up to
#: this many entries (a product with a few harmonics' coefficients: dense is the faster there), sparse above
DENSE_STACK_MAX = 2_000_000
#: the Jacobian evaluations whose parameter directions AssemblyContacts.keeping_directions keeps
#: (the two points either side of a peak, hbm.sensitivity.peak_sensitivities, and a spare)
KEPT_EVALUATIONS = 4
#: per thread, {id(element): [map derivatives, kept evaluations]} of the elements within
#: AssemblyContacts.keeping_directions (outside the elements: they stay plain, copyable data)
class KeptDirections(threading.local):
    """Per thread, {id(element): [map derivatives, kept evaluations]} of the elements within
    AssemblyContacts.keeping_directions, or None (a class default: no exception to look it up)."""

    requests: dict | None = None


KEPT_DIRECTIONS = KeptDirections()


def kept_request(element):
    """The request of :meth:`AssemblyContacts.keeping_directions` open on ``element`` in this
    thread ([map derivatives, [(local, omega, rows), ...]]), or None."""
    requests = KEPT_DIRECTIONS.requests
    return requests.get(id(element)) if requests else None

STOP_CHECK_OFFSET_HZ = 0.05   # [Hz] stop_check's frequency beyond the furthest point (0.3 rad/s; the
# offset at which the time integration tells the stopped random designs (benchmarks/README.md,
# 'Moved from the package's docstrings', disk.py, 'with_stop_note'))


def damper_weighted_scales(scales: np.ndarray, n_coeffs: int, damper_unknowns: slice) -> np.ndarray:
    """A disk's ``retry_x_scale`` for :func:`bladedamp.hbm.continuation.continuation`: ``scales``
    (n_coeffs * n_dof,) with the damper's unknowns (``damper_unknowns``, a slice of the n_dof per
    coefficient) times DAMPER_ARC_SCALE."""
    out = np.array(scales, dtype=float).reshape(n_coeffs, -1)
    out[:, damper_unknowns] *= DAMPER_ARC_SCALE
    return out.ravel()


def contact_point_maps(geometry: DamperGeometry, platform_offsets: np.ndarray, left: ModalBlade,
                       right: ModalBlade) -> np.ndarray | None:
    """Point maps of a flexible platform, (2, P, 3, 6 + n_m), or None for rigid platforms.

    The relative displacement of contact point p of contact c (OL: blade ``left``, the damper's
    blade i; OR: blade ``right``, blade i+1) is, in the contact frame (xi, eta, zeta) [m],

        d_p = B_p w_c - R_c (u_FE(x_p) - u_fit(x_p)) q_c      (Eq. 6, 24, the platform side per point)

    w_c (6) the relative motion of the control point (the rigid-platform kinematics of Eq. 6:
    w = G_D u_D - G_P [Phi_OL; Phi_OR] q), B_p (3, 6) the patch's rigid point map
    (:attr:`ContactPatch.point_map`), q_c the platform blade's modal coordinates (for OR with
    the interblade phase of Eq. 24), R_c the contact frame, u_FE(x_p) (3, n_m) the blade's own
    FE translation of its platform surface at the point x_p (its
    :meth:`~bladedamp.blade.ModalBlade.platform_displacements`) and u_fit(x_p) = u_c + phi_c x
    (x_p - x_c) that of the rigid motion of the control point (the blade's OL / OR shape
    (u_c, phi_c), the rigid fit of the face) there. So the map on the local coordinates
    (w_c, q_c) is [B_p, -R_c (u_FE - u_fit)]: the paper's rigid kinematics plus the platform's
    deformation relative to its rigid fit, exactly zero for a rigid platform.

    x_p: the patch's actual point positions, (OL or OR point x_c) + platform offset
    (:meth:`TunedDisk.platform_offsets`) + xi_p R_c[0] + eta_p R_c[1] (a cylinder's line at
    xi = 0, a wedge's rows across its height h_C), projected along the contact normal onto the
    face plane through x_c (the damper placement of ``platform_offsets`` puts a contact centre
    half the radial mismatch off the face when the two platform angles differ; the rigid part
    B_p w_c keeps that placement, so the rigid limit is the rigid kinematics for any angles).
    Returns None unless both blades carry per-point data (a beam blade has none).

    ``geometry``: the damper's contact frames and patches; ``platform_offsets`` (2, 3) [m].
    """
    faces = []
    for c, (side, blade) in enumerate((("OL", left), ("OR", right))):
        R, patch = geometry.frames[c], geometry.patches[c]
        x_c = blade.points[side]
        x = x_c + np.asarray(platform_offsets[c], dtype=float) + patch.xi[:, None] * R[0] + patch.eta[:, None] * R[1]
        x = x - ((x - x_c) @ R[2])[:, None] * R[2]                                  # (P, 3) on the face plane
        faces.append((x, blade.platform_displacements(side, x, R[2])))
    if any(u is None for _, u in faces):
        if any(u is not None for _, u in faces):
            raise ValueError("both blades of a damper must carry per-point platform data, or neither "
                             "(a solid and a beam blade next to each other)")
        return None
    maps = []
    for c, (side, blade, (x, u_fe)) in enumerate(zip(("OL", "OR"), (left, right), faces)):
        R, B = geometry.frames[c], geometry.patches[c].point_map                    # (3, 3), (P, 3, 6)
        phi = blade.shape(side)                                                     # (6, n_m) about x_c
        r = x - blade.points[side]                                                  # (P, 3)
        u_fit = phi[None, :3] - np.cross(r[:, None, :], phi[3:].T[None]).transpose(0, 2, 1)   # u + phi x r
        maps.append(np.concatenate([B, -np.einsum("ik,pkm->pim", R, u_fe - u_fit)], axis=-1))
    return np.stack(maps)


def point_map_forces(B, local, basis, k_t, mu, law, weights, offsets, jacobian, **options):
    """Generalised contact forces of the points of n_d dampers (Eq. 11 with the point maps).

    B (n_d, 2, P, 3, m): each contact's point map from its m local coordinates (the rigid
    ContactPatch.point_map, m = 6, or :func:`contact_point_maps`, m = 6 + n_m); local
    (C, n_d, 2, m) their harmonic coefficients; k_t, mu, weights (n_d * 2 * P,) per point
    (damper, contact, point order) [N/m, -, -]; law the shared normal law; offsets
    (n_d, 2, P) the static approach [m]; ``options`` go to
    :func:`~bladedamp.contact.point.point_contact_forces`. Returns (force (C, n_d, 2, m),
    Jacobian blocks (n_d, 2, C, m, C, m) or None, the point samples): every point in one call of
    the point-contact kernel, the forces B^T f, the Jacobian B^T (df/dc) B (exact).
    """
    C = basis.n_coeffs
    nd, _, P = B.shape[:3]
    coeffs = np.einsum("dqpij,cdqj->cdqpi", B, local).reshape(C, nd * 2 * P, 3)
    pts = point_contact_forces(coeffs, basis, k_t, mu, law, weights, np.ravel(offsets), jacobian=jacobian, **options)
    f_points = basis.to_coeffs(np.moveaxis(pts.force, 1, 0)).reshape(C, nd, 2, P, 3)
    force = np.einsum("cdqpi,dqpij->cdqj", f_points, B)
    blocks = None
    if jacobian:
        # d f_coef[a, p, i] / d c_p[b, k] (point coefficient blocks direction-major), as ContactPatch
        T = basis.n_samples
        jp = np.matmul(basis.analysis, pts.jacobian.reshape(nd * 2 * P, T, 9 * C)).reshape(nd, 2, P, C, 3, 3, C)
        blocks = dof_jacobian(B, jp)
    return force, blocks, pts


def fused_point_map_forces(B, local, basis, k_t, mu, law, weights, offsets, jacobian):
    """:func:`point_map_forces` of rigid platforms (m = 6) through the fused kernel
    :func:`~bladedamp.contact.point.damper_contact_forces` (one numba call: point motion, normal
    law, return map, AFT, the projections B^T f and B^T (df/dc) B, without the point samples).
    Returns (force (C, n_d, 12), Jacobian blocks (n_d, C, 12, C, 12) with patch q of damper d in
    [d, :, 6q:6q+6, :, 6q:6q+6], or None), or None where the kernel does not apply (flexible
    platforms' maps, a normal law it does not know). The same forces as :func:`point_map_forces`
    to rounding (timings: benchmarks/README.md, 'Moved from the package's docstrings', disk.py)."""
    params = normal_law_parameters(law)
    if B.shape[-1] != 6 or params is None:
        return None
    C, nd = basis.n_coeffs, B.shape[0]
    force = np.empty((C, nd, 12))
    blocks = np.empty((nd, C, 12, C, 12)) if jacobian else np.empty((1, 1, 1, 1, 1))
    static_index = basis.cos_index(0) if basis.has_static else -1
    damper_contact_forces(np.ascontiguousarray(B, dtype=float), np.ascontiguousarray(local, dtype=float),
                          basis.synthesis, basis.analysis, k_t, mu, weights,
                          np.ascontiguousarray(offsets, dtype=float).ravel(), params[0], params[1], static_index,
                          MAX_PASSES, PERIODIC_TOL, jacobian, force, blocks, True)
    return force, blocks if jacobian else None


def contact_rows(contact_local: int, n_modes: int):
    """Row indices of a damper's local coordinates (:class:`DamperContacts`, m = ``contact_local``
    per contact): (the 12 rows w of the OL and OR control points, the n_m rows of OL's blade's
    modal coordinates, the n_m rows of OR's); the last two are empty for rigid platforms (m = 6,
    the rows 0..11 of Eq. 6)."""
    m = contact_local
    if m not in (6, 6 + n_modes):
        raise ValueError(f"contact_local must be 6 or 6 + n_modes = {6 + n_modes} (got {m})")
    w = np.r_[0:6, m:m + 6]
    return w, np.arange(6, m), np.arange(m + 6, 2 * m)


#: Euler's identity needs the approach's omega-derivative to be kappa_d times the approach,
#: damper by damper, to this fraction of its largest entry (the seating is homogeneous in F_CG)
HOMOGENEOUS_TOL = 1e-12


@njit(cache=True)
def euler_rate(offsets, doffsets, blocks, local, force, domega):
    """d force / d omega (C, n_d, L) [N s/rad] into ``domega`` by Euler's identity for linear
    normal laws, when the static approach's omega-derivative is homogeneous: doffsets = kappa_d
    offsets (n_d, 2, P) [m, m s/rad] for every damper d to :data:`HOMOGENEOUS_TOL` of its
    largest entry (kappa_d = doffsets_d . offsets_d / |offsets_d|^2, 0 for a damper without
    approach). The forces (C, n_d, L) [N] are then homogeneous of degree 1 in (local, offsets),
    so d force / d omega = kappa_d (force - J local), J the Jacobian blocks (n_d, C, L, C, L)
    [N/m] and local (C, n_d, L) [m]. Returns False (domega not written) if the approach is not
    homogeneous.

    The one implementation for both disk models: the mistuned ring's dampers side by side
    (:meth:`~bladedamp.mistuned.AssemblyContacts.evaluate`, n_d dampers), and the tuned
    sector's single damper (:meth:`DamperContacts.harmonic_forces`, n_d = 1: its (C, L) force
    and local coordinates and its dense (C L, C L) Jacobian are the same memory viewed with a
    damper axis of length one, so no copy is made)."""
    nd = offsets.shape[0]
    kappa = np.empty(nd)
    for d in range(nd):
        norm = 0.0
        dot = 0.0
        for q in range(offsets.shape[1]):
            for p in range(offsets.shape[2]):
                norm += offsets[d, q, p] * offsets[d, q, p]
                dot += doffsets[d, q, p] * offsets[d, q, p]
        kappa[d] = dot / norm if norm > 0 else 0.0
    worst = 0.0
    largest = 0.0
    for d in range(nd):
        for q in range(offsets.shape[1]):
            for p in range(offsets.shape[2]):
                off = abs(doffsets[d, q, p] - kappa[d] * offsets[d, q, p])
                if not off <= worst:            # (a NaN stays)
                    worst = off
                largest = max(largest, abs(doffsets[d, q, p]))
    if not worst <= HOMOGENEOUS_TOL * largest:
        return False
    C, L = force.shape[0], force.shape[2]
    for a in range(C):
        for d in range(nd):
            for m in range(L):
                jw = 0.0
                for b in range(C):
                    for n in range(L):
                        jw += blocks[d, a, m, b, n] * local[b, d, n]
                domega[a, d, m] = (force[a, d, m] - jw) * kappa[d]
    return True



class PointBatch(NamedTuple):
    """The contact points of one damper (both patches) or of n_d dampers side by side as one
    batch of the point-contact kernel (what :meth:`DamperContacts.stacked_points` and
    :meth:`AssemblyContacts.stacked_points` give; P points per patch)."""

    #: point maps from the local coordinates, (2, P, 3, m) for one damper, (n_d, 2, P, 3, m) for n_d
    maps: np.ndarray
    #: (2 P,) or (2 n_d P,) tangential stiffness of each point: the patch's times the point's weight [N/m]
    tangential_stiffness: np.ndarray
    #: (2 P,) or (2 n_d P,) friction coefficient of each point [-]
    friction_coefficient: np.ndarray
    #: (2 P,) or (2 n_d P,) each point's weight [-]
    weights: np.ndarray
    #: the normal law every point shares
    normal_law: object


@dataclass
class DamperContacts:
    """Both contacts of one damper as a harmonic-balance element. Forces are those on the
    platforms (Eq. 11).

    Local coordinates, per contact (OL, then OR): the relative motion w of its control point
    (6, Eq. 7), and with a flexible platform (``point_maps`` given, :func:`contact_point_maps`)
    the n_m modal coordinates of that platform's blade (OR: with the interblade phase), so
    ``n_local`` = 12 (rigid platforms) or 12 + 2 n_m. :attr:`contact_local` = m per contact.

    ``approach(omega)`` gives the per-point static approach (2, P) and its omega-derivative.

    ``harmonic_forces`` is that of the one damper-contact element, :class:`AssemblyContacts`
    with this damper alone (:attr:`element`; a ring's element holds every damper's
    DamperContacts side by side): the points of both patches in one call of a kernel when the
    patches share their normal law and friction coefficient (always, for the dampers of
    :mod:`bladedamp.damper.geometry`): the fused kernel with rigid platforms
    (:func:`fused_point_map_forces`), else the point-contact kernel with numpy projections; the
    same numbers as two ``ContactPatch.evaluate`` calls to rounding (tested against ``evaluate``).
    With the one-harmonic preload and a linear normal law, d force / d omega comes from Euler's
    identity instead of a second AFT pass (:func:`euler_rate`).
    """

    geometry: DamperGeometry
    approach: callable
    point_maps: np.ndarray | None = None
    n_local: int = field(default=12, init=False)
    _stacked: tuple | None = field(default=None, init=False, repr=False)
    _element: object = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.point_maps is not None:
            P = self.geometry.patches[0].n_points
            B = np.asarray(self.point_maps, dtype=float)
            if B.ndim != 4 or B.shape[:3] != (2, P, 3) or B.shape[3] < 6 or \
                    self.geometry.patches[1].n_points != P:
                raise ValueError(f"point_maps must have shape (2, {P}, 3, m >= 6) (got {B.shape})")
            self.point_maps = B
        self.n_local = 2 * self.contact_local

    @property
    def flexible(self) -> bool:
        """Whether the platforms are flexible (per-point maps)."""
        return self.point_maps is not None

    @property
    def contact_local(self) -> int:
        """Local coordinates per contact m: 6, or 6 + n_m with a flexible platform."""
        return 6 if self.point_maps is None else self.point_maps.shape[-1]

    def relative_motion(self, local):
        """(C, 12) relative motions w of the OL and OR control points (Eq. 7) of ``local`` (C, n_local)."""
        local = np.asarray(local)
        return local.reshape(len(local), 2, self.contact_local)[:, :, :6].reshape(len(local), 12)

    def evaluate(self, local, basis, omega, jacobian=True):
        """Patch evaluations (OL, OR) at ``local`` (C, n_local); with a flexible platform each
        force is (C, 6 + n_m), its first 6 the forces and moments about the control point."""
        return self.evaluate_at(local, basis, self.approach(omega)[0], jacobian)

    def stacked_points(self) -> PointBatch | None:
        """The points of both patches as one :class:`PointBatch` (point maps (2, P, 3, m), per
        point (2P,): k_T [N/m, the patch's tangential stiffness times the point's weight], mu,
        weights; the normal law), or None if the patches differ in normal law, friction
        coefficient or point count (then they are evaluated one by one). Cached; the batch of
        :func:`point_map_forces` and of :class:`AssemblyContacts`."""
        if self._stacked is None:
            pa, pb = self.geometry.patches
            same = (pa.normal_law == pb.normal_law and pa.friction_coefficient == pb.friction_coefficient
                    and pa.n_points == pb.n_points)
            if not same:
                self._stacked = (False,)
            else:
                ps = (pa, pb)
                B = np.stack([p.point_map for p in ps]) if self.point_maps is None else self.point_maps
                self._stacked = (True, PointBatch(B, np.concatenate([p.tangential_stiffness * p.weights for p in ps]),
                                                  np.concatenate([np.full(p.n_points, p.friction_coefficient)
                                                                  for p in ps]),
                                                  np.concatenate([p.weights for p in ps]), pa.normal_law))
        return self._stacked[1] if self._stacked[0] else None

    def forces_at(self, local, basis, offsets, jacobian):
        """Forces (C, n_local) [N, N m] and Jacobian (C*n_local, C*n_local) or None of both patches
        at ``local`` (C, n_local) with the per-point static approach ``offsets`` (2, P) [m] (no
        omega: the approach is given), patch by patch (:meth:`evaluate_at`): the one element's
        (:class:`AssemblyContacts`) evaluation of a damper whose patches do not stack
        (:meth:`stacked_points` None); it evaluates stacked ones in one kernel call."""
        C, m = basis.n_coeffs, self.contact_local
        evs = self.evaluate_at(local, basis, offsets, jacobian)
        force = np.hstack([ev.force for ev in evs])
        if not jacobian:
            return force, None
        jac = np.zeros((C, 2 * m, C, 2 * m))
        for c, ev in enumerate(evs):
            jac[:, m * c:m * c + m, :, m * c:m * c + m] = ev.jacobian.reshape(C, m, C, m)
        return force, jac.reshape(C * 2 * m, C * 2 * m)

    def evaluate_at(self, local, basis, offsets, jacobian=True):
        """Patch evaluations (OL, OR) at ``local`` (C, n_local) with the static approach ``offsets`` (2, P)."""
        m = self.contact_local
        maps = (None, None) if self.point_maps is None else self.point_maps
        return [patch.evaluate(local[:, m * c:m * c + m], basis, offsets[c], jacobian, point_map=maps[c])
                for c, patch in enumerate(self.geometry.patches)]

    def evaluate_states(self, local, basis, omegas):
        """Forces (n, C, n_local) [N, N m] and the point samples (PointContactSamples, point axis
        (n, 2, P) flattened) of both patches at n states ``local`` (n, C, n_local) at ``omegas``
        (n,) [rad/s], without the Jacobian: every state in one call of the point-contact kernel
        when the patches stack (:meth:`stacked_points`; the points are independent), else patch
        by patch. The response's contact quantities at every point of a branch."""
        local = np.asarray(local, dtype=float)
        n, C, m = len(local), basis.n_coeffs, self.contact_local
        offsets = np.stack([self.approach(w)[0] for w in omegas])                 # (n, 2, P)
        stack = self.stacked_points()
        if stack is not None:
            B, k_t, mu, weights, law = stack
            f, _, pts = point_map_forces(np.broadcast_to(B, (n,) + B.shape), np.moveaxis(local.reshape(n, C, 2, m), 0, 1),
                                         basis, np.tile(k_t, n), np.tile(mu, n), law, np.tile(weights, n), offsets,
                                         False)
            return np.moveaxis(f, 1, 0).reshape(n, C, 2 * m), pts
        evs = [ev for x, o in zip(local, offsets) for ev in self.evaluate_at(x, basis, o, False)]
        force = np.stack([ev.force for ev in evs]).reshape(n, 2, C, m).transpose(0, 2, 1, 3).reshape(n, C, 2 * m)
        pts = PointContactSamples(*(None if getattr(evs[0].points, f.name) is None else
                                    np.concatenate([getattr(ev.points, f.name) for ev in evs])
                                    for f in dataclasses.fields(PointContactSamples)))
        return force, pts

    @property
    def element(self) -> "AssemblyContacts":
        """The one damper-contact element holding this damper alone, its Jacobian dense (built once)."""
        if self._element is None:
            self._element = AssemblyContacts([self], dense=True)
        return self._element

    def harmonic_forces(self, local, basis, omega, jacobian=True):
        """(force (C, n_local) [N, N m], dense Jacobian (C n_local, C n_local) or None, d force /
        d omega (C n_local,) [N s/rad] or None) at ``local`` (C, n_local) and ``omega`` [rad/s]:
        :meth:`AssemblyContacts.harmonic_forces` of :attr:`element`."""
        return self.element.harmonic_forces(local, basis, omega, jacobian)


@dataclass
class AssemblyContacts:
    """The contacts of all dampers of an assembly as one harmonic-balance element.

    Local coordinates: those of each damper's :class:`DamperContacts` in turn (the 12 relative
    motions of OL and OR, and with flexible platforms the platform blades' modal coordinates:
    ``n_local = L * n_dampers``, L = :attr:`damper_local`, the same for every damper).
    ``contacts[d]`` is damper d's :class:`DamperContacts` (built from its :class:`DamperPosition`
    as the tuned disk's). The one damper-contact element of both disk models: a ring's dampers
    side by side, and the tuned sector's damper alone (:attr:`DamperContacts.element`). Returns
    a sparse block-diagonal local Jacobian, or with ``dense`` a dense one (one damper: its block).
    """

    contacts: list[DamperContacts]
    n_local: int = 0
    #: (n_d,) phase [rad] of each damper's motion in a tuned travelling wave (k dphi for the
    #: damper on blade k), or None; damper d is sampled on a grid shifted by it (:meth:`grid_rotations`)
    grid_phase: np.ndarray | None = None
    #: return a dense local Jacobian (the tuned sector's one damper) instead of a sparse one
    dense: bool = False
    _batch: tuple | None = field(default=None, init=False, repr=False)
    _index: dict = field(default_factory=dict, init=False, repr=False)
    _rotations: dict = field(default_factory=dict, init=False, repr=False)
    _last_approach: tuple | None = field(default=None, init=False, repr=False)
    _direction_arguments: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self):
        sizes = {c.n_local for c in self.contacts}
        if len(sizes) > 1:
            raise ValueError("the dampers' contacts must all have flexible platforms or all rigid ones "
                             f"(local coordinates per damper: {sorted(sizes)})")
        self.n_local = sum(c.n_local for c in self.contacts)

    @property
    def n_dampers(self) -> int:
        return len(self.contacts)

    @property
    def damper_local(self) -> int:
        """Local coordinates per damper L: 12 (rigid platforms) or 12 + 2 n_m (flexible)."""
        return self.n_local // max(self.n_dampers, 1)

    def stacked_points(self) -> PointBatch | None:
        """The points of all dampers as one :class:`PointBatch` (point maps (n_d, 2, P, 3, m), per
        point (2 n_d P,): k_T [N/m], mu, weights; the shared normal law): each damper's
        :meth:`DamperContacts.stacked_points` stacked, or None if the dampers' batches differ in
        normal law or point-map shape or one damper has none. Cached."""
        if self._batch is None:
            stacks = [c.stacked_points() for c in self.contacts]
            ok = all(b is not None for b in stacks) and all(
                b.normal_law == stacks[0].normal_law and b.maps.shape == stacks[0].maps.shape for b in stacks)
            if not ok:
                self._batch = (False,)
            else:
                self._batch = (True, PointBatch(np.stack([b.maps for b in stacks]),
                                                *(np.concatenate([getattr(b, f) for b in stacks])
                                                  for f in ("tangential_stiffness", "friction_coefficient", "weights")),
                                                stacks[0].normal_law))
        return self._batch[1] if self._batch[0] else None

    def _block_index(self, C: int):
        """COO indices of the (n_d, C, L, C, L) per-damper blocks in the local Jacobian."""
        if C not in self._index:
            nd, L = self.n_dampers, self.damper_local
            d, a, m, b, k = np.meshgrid(np.arange(nd), np.arange(C), np.arange(L), np.arange(C), np.arange(L),
                                        indexing="ij")
            self._index[C] = ((a * L * nd + L * d + m).ravel(), (b * L * nd + L * d + k).ravel())
        return self._index[C]

    def grid_rotations(self, basis):
        """(n_d, C, C) rotations R_d of the harmonic coefficients that sample damper d on the
        grid omega t_j - grid_phase_d (coefficients R_d c on the common grid), or None when every
        phase is a whole number of samples (the common grid then serves every damper exactly).

        In a tuned travelling wave damper d's motion is the first damper's advanced by its phase
        theta_d: c_h,d = c_h,0 e^{i h theta_d} (complex c_h = a_h - i b_h). Sampled on the shifted
        grid, every damper of a tuned assembly sees the first's samples, so its discrete friction
        law (history-dependent through the return map) gives the first's forces shifted, and the
        tuned full assembly equals the cyclic sector to rounding at any sample count, not only
        at multiples of n / gcd(n, EO). The forces come back by R_d^T (R_d is orthogonal) and
        the Jacobian blocks as R_d^T J_d R_d. For a mistuned disk the shifted grids are an
        equally good discretisation as the common one."""
        if self.grid_phase is None:
            return None
        key = (basis.n_samples, basis.harmonics)
        if key not in self._rotations:
            phase = np.asarray(self.grid_phase)
            shift = phase * basis.n_samples / (2 * np.pi)                   # in samples
            R = None
            if np.any(np.abs(shift - np.round(shift)) >= 1e-9):
                R = np.zeros((len(phase), basis.n_coeffs, basis.n_coeffs))
                for h in basis.harmonics:
                    j = basis.cos_index(h)
                    if h == 0:
                        R[:, j, j] = 1.0
                        continue
                    c, sn = np.cos(-h * phase), np.sin(-h * phase)          # c~ = c e^{-i h phase}
                    R[:, j, j], R[:, j, j + 1], R[:, j + 1, j], R[:, j + 1, j + 1] = c, sn, -sn, c
            self._rotations[key] = R
        return self._rotations[key]

    def forces_at(self, local, basis, offsets, jacobian):
        """Forces (C, n_d, L) [N, N m] and Jacobian blocks (n_d, C, L, C, L) or None at the local
        coefficients ``local`` (C, n_d, L) with the static approach ``offsets`` (n_d, 2, P) [m]
        (no omega: the approach is given, :meth:`approach` gives it), each damper sampled
        on its own grid where the interblade shift is not a whole number of samples
        (:meth:`grid_rotations`), else all on the common grid (:meth:`_forces_on_grid`)."""
        R = self.grid_rotations(basis)
        if R is None:
            return self._forces_on_grid(local, basis, offsets, jacobian)
        force, blocks = self._forces_on_grid(_rotated(R, np.ascontiguousarray(local, dtype=float), False), basis,
                                             offsets, jacobian)
        return _rotated(R, force, True), None if blocks is None else _rotated_blocks(R, blocks)

    def _forces_on_grid(self, local, basis, offsets, jacobian):
        """Forces (C, n_d, L) and Jacobian blocks (n_d, C, L, C, L) or None on the common grid.

        Batched dampers with rigid platforms and a normal law the fused kernel knows go through
        :func:`fused_point_map_forces` (one numba call: point motion, normal
        law, return map, AFT and the projections); otherwise (flexible platforms too,
        whose point maps the fused kernel does not take) :meth:`forces_at_numpy`."""
        stack = self.stacked_points()
        fused = None if stack is None else fused_point_map_forces(stack.maps, local, basis, stack.tangential_stiffness,
                                                                  stack.friction_coefficient, stack.normal_law,
                                                                  stack.weights, offsets, jacobian)
        return self.forces_at_numpy(local, basis, offsets, jacobian) if fused is None else fused

    def forces_at_numpy(self, local, basis, offsets, jacobian):
        """:meth:`forces_at` through :func:`point_map_forces` (the point-contact
        kernel and numpy projections; the reference of the fused kernel; any normal law and
        flexible platforms)."""
        C, nd, L = basis.n_coeffs, self.n_dampers, self.damper_local
        stack = self.stacked_points()
        if stack is None:
            force = np.zeros((C, nd, L))
            blocks = np.zeros((nd, C, L, C, L)) if jacobian else None
            for d, c in enumerate(self.contacts):
                f, j = c.forces_at(local[:, d], basis, offsets[d], jacobian)
                force[:, d] = f
                if jacobian:
                    blocks[d] = j.reshape(C, L, C, L)
            return force, blocks
        B, k_t, mu, weights, law = stack                         # B (n_d, 2, P, 3, m)
        m = B.shape[-1]
        force, q_blocks, _ = point_map_forces(B, local.reshape(C, nd, 2, m), basis, k_t, mu, law, weights, offsets,
                                              jacobian, max_passes=MAX_PASSES, tol=PERIODIC_TOL)
        force = force.reshape(C, nd, L)
        if not jacobian:
            return force, None
        blocks = np.zeros((nd, C, 2, m, C, 2, m))
        for q in range(2):
            blocks[:, :, q, :, :, q, :] = q_blocks[:, q]
        return force, blocks.reshape(nd, C, L, C, L)

    def approach(self, omega):
        """Static approach (n_d, 2, P) [m] of every damper and its omega-derivative [m s/rad] at
        ``omega`` [rad/s], as ``(offsets, doffsets)`` (last omega cached;
        dampers that share their approach function, the same damper at every position, evaluate
        it once: 16 calls were 0.05 of a residual's 0.9 ms)."""
        last = self._last_approach            # one read: the element may be shared by threads
        if last is None or last[0] != omega:
            if "_approach_groups" not in self.__dict__:
                functions = {}
                index = [functions.setdefault(id(c.approach), (len(functions), c.approach))[0] for c in self.contacts]
                self._approach_groups = ([f for _, f in functions.values()], np.array(index))
            functions, index = self._approach_groups
            if len(index) == 1:                # one damper (the tuned sector's): its arrays viewed, not copied
                offsets, doffsets = functions[0](omega)
                last = (omega, offsets[None], doffsets[None])
            else:
                out = [f(omega) for f in functions]
                last = (omega, np.array([o[0] for o in out])[index], np.array([o[1] for o in out])[index])
            self._last_approach = last
        return last[1], last[2]

    @property
    def linear_normal_laws(self) -> bool:
        """Whether every patch of every damper has a linear normal law (computed once)."""
        if "_linear" not in self.__dict__:
            self._linear = all(isinstance(p.normal_law, LinearNormalLaw) for c in self.contacts
                               for p in c.geometry.patches)
        return self._linear

    def _sparse(self, blocks, C):
        rows, cols = self._block_index(C)
        n = C * self.n_local
        return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n, n))

    def evaluate(self, local, basis, omega, jacobian=True):
        """``(force (C, n_d, L), Jacobian blocks (n_d, C*L, C*L) or None, d force / d omega
        (C, n_d, L) or None)``; damper d's block in its own (coefficient, coordinate) order."""
        C, nd = basis.n_coeffs, len(self.contacts)
        L = self.n_local // nd
        local = np.asarray(local).reshape(C, nd, L)
        offsets, doffsets = self.approach(omega)
        request = kept_request(self) if jacobian else None
        if request is not None and self.fused_directions():
            # the directions of parameter_forces from the same kernel pass (keeping_directions)
            directions, blocks = self.directions_at(local, basis, offsets, request[0], (), True)
            force = directions[len(PARAMETER_DIRECTIONS)]
            request[1] = [(local.copy(), omega, directions)] + request[1][:KEPT_EVALUATIONS - 1]
        else:
            force, blocks = self.forces_at(local, basis, offsets, jacobian)
        if not jacobian:
            return force, None, None
        domega = None
        if doffsets.any():
            # as DamperContacts.harmonic_forces (the same kernel, disk.euler_rate): Euler's identity
            # for linear normal laws, else a central difference in omega of all dampers at once
            domega = np.empty(force.shape)
            if not (self.linear_normal_laws and euler_rate(offsets, doffsets, blocks, local, force, domega)):
                h = 1e-6 * omega
                fp, _ = self.forces_at(local, basis, offsets + h * doffsets, False)
                fm, _ = self.forces_at(local, basis, offsets - h * doffsets, False)
                domega = (fp - fm) / (2 * h)
        return force, blocks.reshape(nd, C * L, C * L), domega

    def parameter_forces(self, local, basis, omega, d_maps=(), moves=()) -> dict:
        """The logarithmic derivatives p dF/dp (C, n_local) [N, N m] of the forces at ``local``
        (C, n_local) and ``omega`` [rad/s] in the contact parameters shared by every point, all
        from one evaluation of the point-contact kernel with its exact Jacobian (no differences):

        * ``"tangential"``: in every point's k_T. Scaling the tangential displacements by lambda
          and k_T by 1 / lambda leaves the forces as they are (the trial force, the slip radius
          and the separation instants do not change, the slider positions scale), so
          k_T dF/dk_T = J_t c_t, the Jacobian's tangential columns times the tangential
          coefficients, point by point;
        * ``"law"``: in the normal law's scale c (N = c g(a): k_N for the linear law, N_ref (k_ref /
          (p N_ref))^p for the power law). Scaling k_T and c together scales every force (H2), so
          c dF/dc = F - J_t c_t;
        * ``"friction"``: in mu, which enters through mu N only: mu dF/dmu = the tangential rows of
          F - J_t c_t, zero on the normal rows;
        * ``"approach"``: in the static approach's scale (every point's offset times 1 + epsilon):
          the forces are homogeneous in (u_t, (u_zeta, offset)^(1/p)) of degree 1 for a law of
          degree p (linear: p = 1), so offset dF/doffset = p (F - J_t c_t) - J_zeta c_zeta;
          ``"approach_left"``, ``"approach_right"``: the same of the OL patch's points alone, of the OR's;
        * ``"point_maps"``: for each derivative dB (n_d, 2, P, 3, m) of the point maps in ``d_maps``
          (points that move on their patch), dB^T f + B^T J (dB local) (a list, in that order);
        * ``"force"``: the forces F themselves (as :meth:`harmonic_forces`), and
          ``"jacobian_times"``: for each direction v (C, n_local) [m] in ``moves`` the Jacobian's
          product J v [N] (a list; v = dT x for a parameter of the map T from the structure:
          the residual's T^T F(T x) changes by dT^T F + T^T J dT x).

        All in one call of the fused kernel :func:`~bladedamp.contact.point.damper_parameter_forces`
        (the directions formed on each point's force coefficients and Jacobian, projected with
        B^T there; no Jacobian blocks). Raises ValueError for dampers whose patches do not stack
        (:meth:`stacked_points`) or a normal law of another kind than LinearNormalLaw and
        RoughnessNormalLaw."""
        self.check_parameter_directions()
        forces = self.direction_rows(local, basis, omega, d_maps, moves)
        n = len(PARAMETER_DIRECTIONS) + 1
        out = dict(zip(PARAMETER_DIRECTIONS + ("force",), forces))
        out["point_maps"] = list(forces[n:n + len(d_maps)])
        out["jacobian_times"] = list(forces[n + len(d_maps):])
        return out

    def check_parameter_directions(self) -> None:
        """ValueError unless :meth:`parameter_forces` applies: dampers whose two patches share their
        normal law (LinearNormalLaw or RoughnessNormalLaw), friction coefficient and point count."""
        stack = self.stacked_points()
        if stack is None or type(stack.normal_law) not in (LinearNormalLaw, RoughnessNormalLaw):
            raise ValueError("contact parameter derivatives need dampers whose two patches share their normal law "
                             "(LinearNormalLaw or RoughnessNormalLaw), friction coefficient and point count")

    def direction_rows(self, local, basis, omega, d_maps=(), moves=()) -> np.ndarray:
        """The rows of :meth:`parameter_forces` as one array (7 + n_maps + n_v, C, n_local): the six
        directions (:data:`~bladedamp.contact.point.PARAMETER_DIRECTIONS`), F, the maps', the
        moves' products; taken from an evaluation kept by :meth:`keeping_directions` at the same
        point where there is one, else one call of the fused kernel (:meth:`directions_at`); the
        checks are :meth:`check_parameter_directions`'s (not repeated here)."""
        C, nd, L = basis.n_coeffs, self.n_dampers, self.damper_local
        local = np.asarray(local, dtype=float).reshape(C, nd, L)
        forces = None
        request = kept_request(self)
        if request is not None and not len(moves) and len(d_maps) == len(request[0]) and \
                all(a is b for a, b in zip(d_maps, request[0])):
            forces = next((f for kept, w, f in request[1] if w == omega and np.array_equal(kept, local)), None)
        if forces is None:
            forces, _ = self.directions_at(local, basis, self.approach(omega)[0], d_maps, moves, False)
        return forces.reshape(len(forces), C, self.n_local)

    def fused_directions(self) -> bool:
        """Whether a Jacobian evaluation can form the parameter directions in its own kernel pass
        (:meth:`keeping_directions`): rigid platforms and a normal law the kernel evaluates, where
        the kernel's Jacobian blocks are those of :func:`fused_point_map_forces`."""
        stack = self.stacked_points()
        return stack is not None and stack.maps.shape[-1] == 6 and type(stack.normal_law) in (LinearNormalLaw,
                                                                                             RoughnessNormalLaw)

    def directions_at(self, local, basis, offsets, d_maps, moves, jacobian):
        """(forces (7 + n_maps + n_v, C, n_d, L) [N, N m], Jacobian blocks (n_d, C, L, C, L) or None):
        the rows of :meth:`parameter_forces` (the six directions, F, the maps' and the moves'
        products) at ``local`` (C, n_d, L) with the static approach ``offsets`` (n_d, 2, P) [m],
        each damper on its own grid as :meth:`forces_at`; one call of the fused kernel
        :func:`~bladedamp.contact.point.damper_parameter_forces` (with ``jacobian`` its blocks,
        the same numbers as :meth:`forces_at`'s for rigid platforms)."""
        C, nd, L = basis.n_coeffs, self.n_dampers, self.damper_local
        R = self.grid_rotations(basis)
        key = (basis.n_samples, basis.harmonics, tuple(id(dB) for dB in d_maps))
        fixed = self._direction_arguments.get(key)
        if fixed is None:                   # the arguments that do not change from point to point, once
            B, k_t, mu, weights, law = self.stacked_points()
            kind, params = normal_law_parameters(law)
            maps = np.stack([np.broadcast_to(np.asarray(dB, dtype=float), B.shape) for dB in d_maps]) \
                if len(d_maps) else np.zeros((0,) + B.shape)
            static_index = basis.cos_index(0) if basis.has_static else -1
            fixed = ((np.ascontiguousarray(B, dtype=float), maps), (basis.synthesis, basis.analysis, k_t, mu, weights),
                     (kind, params, float(getattr(law, "exponent", 1.0)), static_index, MAX_PASSES, PERIODIC_TOL),
                     np.zeros((0, C, nd, L)), np.empty((1, 1, 1, 1, 1)), list(d_maps))
            self._direction_arguments[key] = fixed          # (d_maps kept: their ids stay theirs)
        (B, maps), basis_and_points, law_and_passes, no_moves, no_blocks, _ = fixed
        local = np.ascontiguousarray(local, dtype=float).reshape(C, nd, L)
        v = np.array([np.reshape(m, (C, nd, L)) for m in moves], dtype=float) if len(moves) else no_moves
        if R is not None:
            local = _rotated(R, local, False)
            v = np.array([_rotated(R, np.ascontiguousarray(m), False) for m in v]) if len(v) else v
        forces = np.empty((len(PARAMETER_DIRECTIONS) + 1 + len(maps) + len(v), C, nd, L))
        blocks = np.empty((nd, C, L, C, L)) if jacobian else no_blocks
        offsets = np.ascontiguousarray(offsets, dtype=float).ravel()
        damper_parameter_forces(B, local, maps, v, *basis_and_points, offsets, *law_and_passes, forces, jacobian,
                                blocks, True)
        if R is not None:
            forces = np.array([_rotated(R, f, True) for f in forces])
            blocks = _rotated_blocks(R, blocks) if jacobian else None
        return forces, blocks if jacobian else None

    @contextlib.contextmanager
    def keeping_directions(self, d_maps=()):
        """Within this context (in this thread) every Jacobian evaluation (:meth:`evaluate`) also
        forms the rows of :meth:`parameter_forces` with the map derivatives ``d_maps`` in its own
        kernel pass, where :meth:`fused_directions` allows (the forces and Jacobian the same
        numbers), and keeps the last :data:`KEPT_EVALUATIONS`; :meth:`parameter_forces` at one of
        those points (the same local coefficients, omega and ``d_maps``, no ``moves``) returns
        them instead of a kernel call of its own: dR/dp at a point whose Jacobian was just
        evaluated costs no second pass of the return map."""
        previous = kept_request(self)
        if previous is not None and len(previous[0]) == len(d_maps) and \
                all(a is b for a, b in zip(previous[0], d_maps)):
            yield                               # nested in the same request: its evaluations stay kept
            return
        if KEPT_DIRECTIONS.requests is None:
            KEPT_DIRECTIONS.requests = {}
        requests = KEPT_DIRECTIONS.requests
        requests[id(self)] = [list(d_maps), []]
        try:
            yield
        finally:
            if previous is None:
                del requests[id(self)]
                if not requests:
                    KEPT_DIRECTIONS.requests = None
            else:
                requests[id(self)] = previous

    def harmonic_forces(self, local, basis, omega, jacobian=True):
        C = basis.n_coeffs
        force, blocks, domega = self.evaluate(local, basis, omega, jacobian)
        if not jacobian:
            return force.reshape(C, self.n_local), None, None
        if not self.dense:
            jac = self._sparse(blocks, C)
        else:
            jac = blocks[0] if self.n_dampers == 1 else self._sparse(blocks, C).toarray()
        return force.reshape(C, self.n_local), jac, None if domega is None else domega.ravel()


@njit(cache=True)
def _rotated(R, values, transposed):
    """(C, n_d, L) coefficients rotated damper by damper: R_d values_d, or R_d^T values_d
    (``transposed``), R (n_d, C, C) (:meth:`AssemblyContacts.grid_rotations`)."""
    C, nd, L = values.shape
    out = np.zeros(values.shape)
    for d in range(nd):
        for a in range(C):
            for b in range(C):
                r = R[d, b, a] if transposed else R[d, a, b]
                if r != 0.0:
                    for m in range(L):
                        out[a, d, m] += r * values[b, d, m]
    return out


@njit(cache=True)
def _rotated_blocks(R, blocks):
    """Jacobian blocks (n_d, C, L, C, L) rotated damper by damper: R_d^T J_d R_d (the forces
    come back by R_d^T from coefficients that went in by R_d). As a numpy einsum it was 15 % of
    a 128-blade FRF point; R_d has 2 x 2 blocks, so the loops skip its zeros."""
    nd, C, L = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    out = np.zeros(blocks.shape)
    for d in range(nd):
        for a in range(C):
            for b in range(C):
                rba = R[d, b, a]
                if rba == 0.0:
                    continue
                for c in range(C):
                    for e in range(C):
                        w = rba * R[d, c, e]
                        if w == 0.0:
                            continue
                        for m in range(L):
                            for n in range(L):
                                out[d, a, m, e, n] += w * blocks[d, b, m, c, n]
    return out


def rotor_speed_in_hz(rotor_speed_hz):
    """The rotor speed [Hz, revolutions per second] of a disk, validated: None (the speed follows
    the excitation, Omega_E / EO), or > 0 with a :class:`~bladedamp.validation.PlausibilityWarning`
    outside 1-3000 Hz (60-180 000 rpm)."""
    if rotor_speed_hz is None:
        return None
    validation.positive("rotor_speed_hz (rotor revolutions per second)", rotor_speed_hz)
    # 60 rpm (a slow test rig) to 180 000 rpm (micro gas turbines); a value in rad/s is 2 pi times
    # too large, which only this range can catch at its top
    validation.plausible("rotor_speed_hz", rotor_speed_hz, 1.0, 3000.0, "Hz",
                        "rotor revolutions per second, 60 to 180 000 rpm; a speed in rad/s is 2 pi times larger")
    return float(rotor_speed_hz)


def nodal_diameter(engine_order, n_blades) -> tuple[int, str]:
    """The nodal diameter and travelling direction excited by engine order ``engine_order`` on a
    disk of ``n_blades`` blades (the one place this mapping is made; every EO >= 0 is valid).

    Blade j is excited with the phase j dphi, dphi = 2 pi EO / n (Eq. 25), which only depends on
    r = EO mod n. Returns (k, direction): k = r and ``"forward"`` for 0 < r < n / 2; k = n - r
    and ``"backward"`` for r > n / 2 (the same nodal diameter travelling against the rotation);
    ``"standing"`` for r = 0 (k = 0: EO = 0, n, 2n, ...) and r = n / 2 (even n), where the phase
    e^{i dphi} = +-1 is real. The excitation frequency and the rotor speed use the engine order
    itself (Omega_R = Omega_E / EO, Eq. 3, 26), not k.
    """
    n = validation.integer("n_blades", n_blades, minimum=2)
    eo = validation.integer("engine_order (EO)", engine_order, minimum=0)
    r = eo % n
    if r == 0 or 2 * r == n:
        return r, "standing"
    return (r, "forward") if 2 * r < n else (n - r, "backward")


def interblade_phase(engine_order, n_blades) -> float:
    """dphi [rad] in (-pi, pi] of engine order ``engine_order`` on ``n_blades`` blades (Eq. 25):
    2 pi k / n for the nodal diameter k of :func:`nodal_diameter`, negative for a backward wave
    (e^{i dphi} = e^{i 2 pi EO / n} exactly, with dphi = 0 at EO = 0, n, 2n, ...)."""
    k, direction = nodal_diameter(engine_order, n_blades)
    return (-2 if direction == "backward" else 2) * np.pi * k / int(n_blades)


# The default damper radius R of a disk model [m] (TunedDisk, MistunedDisk); the paper's
# calibrated reference value is bladedamp.reference.DAMPER_RADIUS (26.1 mm).
DEFAULT_DAMPER_RADIUS = 0.1


def check_blade_bounded(blade: ModalBlade, excitation, has_damper: bool, f_start_hz: float, f_end_hz: float) -> None:
    """ValueError where no bounded periodic response exists in ``f_start_hz``..``f_end_hz``
    [Hz] for ``blade`` under the tip load ``excitation`` (6,) [N, N m] with a damper on its
    platforms (``has_damper``) or not: a blade mode j with zero modal damping, a modal force
    phi_j^T F != 0, its natural frequency f_0j inside the range, and no damper acting on it (no
    damper, or rigid platforms that do not move at OL and OR in that mode). Its modal equation is then
    q_j'' + omega_0j^2 q_j = phi_j^T F cos(Omega t) alone, whose amplitude grows without
    bound at Omega = omega_0j. (With a damper on that mode the bound of its friction forces
    is no closed form: the normal loads vary with the motion.)"""
    force = blade.shape("excitation").T @ np.asarray(excitation, dtype=float)          # (nm,) modal forces [N]
    lo, hi = min(f_start_hz, f_end_hz), max(f_start_hz, f_end_hz)
    if has_damper:
        if blade.flexible_platform:
            return
        at_damper = np.abs(np.vstack([blade.shape("OL"), blade.shape("OR")])).max(axis=0) > 0
    else:
        at_damper = np.zeros(blade.n_modes, dtype=bool)
    f0 = np.asarray(blade.natural_frequencies_hz, dtype=float)
    free = (blade.damping_ratios == 0) & (force != 0) & ~at_damper & (f0 >= lo) & (f0 <= hi)
    if np.any(free):
        j = int(np.flatnonzero(free)[0])
        name = blade.mode_names[j] if len(blade.mode_names) else str(j + 1)
        why = "the disk has no damper" if not has_damper else "the damper's platforms do not move in it"
        raise ValueError(
            f"no bounded response: blade mode {name} has damping_ratios = 0, a modal force "
            f"{force[j]:.6g} N and its natural frequency {f0[j]:.6g} Hz inside the range {f_start_hz:g}-"
            f"{f_end_hz:g} Hz, and {why}: its amplitude grows without bound there; give the mode a damping "
            f"ratio > 0 or a range without {f0[j]:.6g} Hz")


@dataclass
class DamperPosition:
    """One damper position of a bladed disk, described once for both assemblies (the tuned
    disk's cyclic sector has one, a ring one per blade): the damper between blade k's OL platform
    and blade k+1's OR platform, its platform angles, the gaps of its contact points before
    loading and its preload law, the centrifugal force F_CG = m R Omega_R^2 on the damper at the
    radius R (Eq. 26; Omega_R = Omega_E / EO, or the given rotor speed). Its contacts as a
    harmonic-balance element: :meth:`contacts`.

    Parameters: as :class:`TunedDisk`'s of the same names (``damper``: CylinderDamper,
    WedgeDamper or None; ``gamma_left``, ``gamma_right`` [rad]; ``initial_gaps`` (2, P) [m] or
    None; ``damper_radius`` R [m]; ``engine_order``; ``rotor_speed_hz`` [Hz] or None). Frequencies
    are the residual's angular excitation frequency omega [rad/s]. :meth:`validate` checks the
    angles (the disk checks the rest).
    """

    damper: CylinderDamper | WedgeDamper | None
    gamma_left: float = PLATFORM_ANGLE
    gamma_right: float = PLATFORM_ANGLE
    initial_gaps: np.ndarray | None = None
    damper_radius: float = DEFAULT_DAMPER_RADIUS
    engine_order: int = 1
    rotor_speed_hz: float | None = None

    def validate(self) -> "DamperPosition":
        """ValueError unless both platform angles lie in (0, pi/2) [rad] and ``initial_gaps`` (if
        given, with a damper) is a finite (2, P) array [m] (OL, OR points); returns this position.
        Run when a disk is made (issue 34 item 6), not at each :meth:`damper_geometry`."""
        validation.in_range("gamma_left (platform angle, rad)", self.gamma_left, 0.0, np.pi / 2, closed="neither")
        validation.in_range("gamma_right (platform angle, rad)", self.gamma_right, 0.0, np.pi / 2, closed="neither")
        if self.initial_gaps is not None and self.damper is not None:
            gaps = np.asarray(validation.finite("initial_gaps", self.initial_gaps), dtype=float)
            P = self.damper.geometry(self.gamma_left, self.gamma_right).patches[0].n_points
            if gaps.shape != (2, P):
                raise ValueError(f"initial_gaps must have shape (2, {P}) (OL, OR points) in m")
        return self

    @property
    def has_damper(self) -> bool:
        """Whether a damper with a mass sits here."""
        return self.damper is not None and self.damper.mass > 0

    def damper_geometry(self) -> DamperGeometry:
        """The damper's contact frames and patches at these platform angles, with the initial gaps."""
        geometry = self.damper.geometry(self.gamma_left, self.gamma_right)
        if self.initial_gaps is not None:    # validated when the disk was made (validate)
            gaps = np.asarray(self.initial_gaps, dtype=float)
            geometry.patches = tuple(dataclasses.replace(p, initial_gap=g) for p, g in zip(geometry.patches, gaps))
        return geometry

    def platform_offsets(self, geometry: DamperGeometry, points) -> np.ndarray:
        """(2, 3) contact centres seen from the blades' OL / OR points ``points`` (a blade's
        ``points``: every blade of a disk has the same; in each blade's frame).

        The blade pitch at the platform (unrolled, neighbouring blade frames parallel) is chosen
        so that the OL and OR contact centres lie above or below the OL point of blade i and
        the OR point of blade i+1. For asymmetric platforms the two contact centres are at
        different heights (radial mismatch dz); the damper is placed half-way, so each rigid
        platform carries half of it (OL offset -dz/2, OR offset +dz/2, radially). This keeps
        the model mirror-symmetric: exchanging gamma_L and gamma_R gives the mirror image of
        the assembly (the paper: "the same results are obtained if the left and right platform
        angle are exchanged"); carrying all of dz on one side breaks that.
        """
        p_ol, p_or = points["OL"], points["OR"]
        cg = p_ol - geometry.centres[0]                      # damper CG in blade i's frame (OL centre on OL)
        or_centre = cg + geometry.centres[1]                 # in blade i's frame
        pitch = p_or[0] - or_centre[0]                       # blade i+1 frame = blade i frame - pitch x
        mismatch = or_centre + np.array([pitch, 0.0, 0.0]) - p_or   # (0, dy, dz) with OL centre on OL
        half = np.array([0.0, 0.0, mismatch[2] / 2])
        return np.array([-half, mismatch - half])

    def centrifugal_force(self, omega: float):
        """(F_CG [N], dF_CG / dOmega_E [N s/rad]) at the angular excitation frequency ``omega``
        [rad/s] (Eq. 26; the rotor speed omega / EO unless ``rotor_speed_hz`` is given)."""
        return centrifugal_force(self.damper.mass, self.damper_radius, engine_order=self.engine_order,
                                 f_hz=omega / (2 * np.pi), rotor_speed_hz=self.rotor_speed_hz)

    def centrifugal_law(self):
        """A function omega [rad/s, the excitation frequency] -> (F_CG [N], dF_CG / dOmega_E
        [N s/rad]) of Eq. 26 whose parameters are validated once, here (the residual calls it
        at every evaluation): F = c Omega_E^2, or constant at a given rotor speed."""
        c, _ = self.centrifugal_force(1.0)
        if self.rotor_speed_hz is not None:
            return lambda omega: (c, 0.0)
        return lambda omega: (c * omega ** 2, 2 * c * omega)

    def seated(self, omega: float) -> np.ndarray:
        """(6,) the damper seated frictionlessly under F_CG at ``omega`` [rad/s] (``seat``; the
        geometry built once for these fields: every start and scale of a branch seats the damper)."""
        key = (id(self.damper), self.gamma_left, self.gamma_right, id(self.initial_gaps))
        cached = self.__dict__.get("_seat_geometry")
        if cached is None or cached[0] != key:
            cached = self.__dict__["_seat_geometry"] = (key, self.damper_geometry())
        return seat(cached[1], self.centrifugal_force(omega)[0])[0]

    def contacts(self, geometry: DamperGeometry, approach, left: ModalBlade, right: ModalBlade):
        """(DamperContacts, G_D (12, 6), G_P (12, 12)) of the damper here between blade ``left``
        (its OL platform) and blade ``right`` (its OR platform), with ``geometry``
        (:meth:`damper_geometry`) and the static ``approach`` (:meth:`approach_function`): the
        contacts as a harmonic-balance element (flexible platforms' point maps where both blades
        carry per-point data, :func:`contact_point_maps`) and the rigid kinematics of Eq. 6,
        w = G_D u_D - G_P [Phi_OL; Phi_OR] q, at the contact centres :meth:`platform_offsets`."""
        offsets = self.platform_offsets(geometry, left.points)
        return (DamperContacts(geometry, approach, contact_point_maps(geometry, offsets, left, right)), geometry.G_D,
                geometry.G_P(offsets))

    @staticmethod
    def retention(geometry: DamperGeometry, static_retention: float) -> np.ndarray:
        """(6, 6) the static-harmonic retention spring of the damper [N/m, N m/rad]: the fraction
        ``static_retention`` of its patches' summed normal stiffness (:func:`~bladedamp.damper.retention_stiffness`)."""
        return retention_stiffness(static_retention, sum(p.normal_law.stiffness for p in geometry.patches))

    def approach_function(self, geometry: DamperGeometry, basis: HarmonicBasis):
        """The static approach of ``geometry``'s contact points under this position's F_CG (Eq. 26):
        a function omega [rad/s, the residual's excitation frequency] -> (per-point static
        approach (2, P) [m], its omega-derivative (2, P) [m s/rad]). With a static harmonic in
        ``basis`` the seating is part of the harmonic balance and the approach is the rest state
        (minus the initial gaps); otherwise the frictionless seating under F_CG (``seat``).
        The :attr:`DamperContacts.approach` of the damper here."""
        gaps = np.array([p.initial_gap for p in geometry.patches])
        if basis.has_static:
            rest = -gaps  # the seating is part of the harmonic balance
            zero = np.zeros_like(rest)
            return lambda omega: (rest, zero)
        if np.any(gaps != 0):
            # a misfit: the seating is not homogeneous in F_CG; seat at each load, d/dF by central
            # differences of the (smooth away from touch-down) seating; F_CG's law validated once, here
            cache = {}
            centrifugal = self.centrifugal_law()

            def approach(omega):
                if omega not in cache:
                    F, dF = centrifugal(omega)          # F >= 0: the law's constant is validated
                    a = seat(geometry, F, validate=False)[1]
                    h = 1e-6 * max(F, 1e-12)
                    da = (seat(geometry, F + h, validate=False)[1]
                          - seat(geometry, max(F - h, 0.0), validate=False)[1]) / (F + h - max(F - h, 0.0))
                    cache.clear()
                    cache[omega] = (a, da * dF)
                return cache[omega]

            return approach
        # perfect fit: seat once at a reference load; the laws are homogeneous, so the static
        # approach scales as F_CG^(1/p) (p = 1 for the linear law)
        exponent = getattr(geometry.patches[0].normal_law, "exponent", 1.0)
        F_ref = 1.0
        _, approach_ref, _ = seat(geometry, F_ref)
        centrifugal = self.centrifugal_law()

        def approach(omega):
            F, dF = centrifugal(omega)
            if F <= 0:
                return np.zeros_like(approach_ref), np.zeros_like(approach_ref)
            scale = (F / F_ref) ** (1 / exponent)
            return approach_ref * scale, approach_ref * scale / (exponent * F) * dF

        return approach


#: the design-file keys whose derivatives :meth:`DiskModel.parameter_derivatives` gives, with
#: their unit (the derivative is per this unit); ``[i]`` keys name one entry of a list
SENSITIVITY_KEYS = {
    "damper.mass_g": "g",
    "damper.friction_coefficient": "-",
    "damper.tangential_stiffness_per_length_n_per_m2": "N/m per m",
    "damper.normal_to_tangential_stiffness": "-",
    "damper.roughness_reference_load_n": "N",
    "disk.damper_radius_mm": "mm",
    "disk.rotor_speed_rpm": "rpm",
    "disk.excitation_n_nm[i]": "N or N m",
    "blade.natural_frequencies_hz[j]": "Hz",
    "blade.damping_ratio": "-",
    "blade.damping_ratio[j]": "-",
    "mistuning.kappa[k]": "-",
    "disk.gamma_left_deg": "deg",
    "disk.gamma_right_deg": "deg",
    "damper.cylinder_radius_mm": "mm",
    "damper.contact_height_mm": "mm",
    "damper.length_mm": "mm",
}
#: the geometry's keys: (the damper's geometry_derivative parameter, its SI unit per key unit)
GEOMETRY_KEYS = {"disk.gamma_left_deg": ("gamma_left", np.pi / 180), "disk.gamma_right_deg": ("gamma_right", np.pi / 180),
                 "damper.cylinder_radius_mm": ("radius", 1e-3), "damper.contact_height_mm": ("contact_height", 1e-3),
                 "damper.length_mm": ("length", 1e-3)}


#: the design-file keys of the contact properties and their ContactProperties fields
CONTACT_FIELDS = {"damper.friction_coefficient": "friction_coefficient",
                  "damper.tangential_stiffness_per_length_n_per_m2": "tangential_stiffness_per_length",
                  "damper.normal_to_tangential_stiffness": "normal_to_tangential_stiffness",
                  "damper.roughness_reference_load_n": "roughness_reference_load"}


def parameter_unit(key: str) -> str:
    """The unit of a design-file key (:data:`SENSITIVITY_KEYS`): per this unit its derivatives are given."""
    name, index = parse_parameter_key(key)
    return SENSITIVITY_KEYS.get(name) or SENSITIVITY_KEYS[next(k for k in SENSITIVITY_KEYS if k.split("[")[0] == name)]


def resolve_parameter_key(name: str) -> str:
    """The design-file key of ``name``: a whole key as given (``damper.mass_g``), or its last
    part alone where that names one key (``mass_g``, ``natural_frequencies_hz[0]``); ValueError
    naming it otherwise."""
    text = str(name).strip()
    if "." in text:
        parse_parameter_key(text)
        return text
    base, bracket, rest = text.partition("[")
    matches = [k.split("[")[0] for k in SENSITIVITY_KEYS if k.split("[")[0].split(".")[-1] == base]
    matches = list(dict.fromkeys(matches))
    if len(matches) != 1:
        raise ValueError(f"parameter {name!r}: {'ambiguous' if matches else 'unknown or not differentiable'}; the "
                         f"keys with derivatives are {', '.join(SENSITIVITY_KEYS)})")
    key = matches[0] + bracket + rest
    parse_parameter_key(key)
    return key


def parse_parameter_key(key: str) -> tuple[str, int | None]:
    """(name, index or None) of a design-file key such as ``damper.mass_g`` or
    ``blade.natural_frequencies_hz[0]``; ValueError for anything else."""
    text = str(key).strip()
    name, index = text, None
    if text.endswith("]") and "[" in text:
        name, _, inner = text[:-1].partition("[")
        if not inner.isdigit():
            raise ValueError(f"parameter {key!r}: the index in [] must be a whole number >= 0")
        index = int(inner)
    known = {k.split("[")[0] for k in SENSITIVITY_KEYS}
    if name not in known:
        raise ValueError(f"parameter {key!r}: unknown or not differentiable; the keys with derivatives are "
                         f"{', '.join(SENSITIVITY_KEYS)})")
    return name, index


@dataclass
class ParameterEffect:
    """How a residual depends on one parameter p, per unit of p (:meth:`DiskModel.parameter_effect`):

    matrices : {"mass" | "damping" | "stiffness" | "static_stiffness": dM/dp ...} (n_dof, n_dof)
        [kg, N s/m, N/m per unit], the linear part's (:func:`~bladedamp.hbm.system.linear_forces`)
    excitation : omega -> df/dp (C * n_dof,) [N per unit], or None
    contact : {direction: d ln q / dp}, the contacts' logarithmic derivatives
        (:meth:`AssemblyContacts.parameter_forces`) each weighted by the relative change of its
        quantity q per unit of p
    coupling : dT/dp, the derivative of the contacts' real-form map T (its shape), or None: the
        residual's T^T F(T x) changes by dT^T F + T^T J (dT x)
    point_maps : dB/dp (n_d, 2, P, 3, m), the derivative of the patches' point maps (points that
        move on their faces), or None
    """

    matrices: dict = field(default_factory=dict)
    excitation: object = None
    contact: dict = field(default_factory=dict)
    coupling: object = None
    point_maps: object = None


class ParameterDerivatives:
    """``dR_dp(x, omega) -> (k, C * n_dof)`` [N per unit of each key] of
    :meth:`DiskModel.parameter_derivatives`: the linear part's stacked matrix derivatives (one
    product per kind), the excitation's, and the contacts' directions (one call of the fused
    kernel, :meth:`AssemblyContacts.parameter_forces`) weighted per key and carried back through
    the contacts' map in one product. :meth:`reusing` gives the context in which the system's
    Jacobian evaluations keep the contact directions, so that a call at a point whose Jacobian
    was just evaluated (the same x and omega) takes them from that kernel pass."""

    def __init__(self, system, effects, coupling, element, stacked, weights, d_maps, moved):
        self.system, self.effects, self.coupling, self.element = system, effects, coupling, element
        self.stacked, self.weights, self.d_maps, self.moved = stacked, weights, d_maps, moved
        self.map_rows = [i for i, e in enumerate(effects) if e.point_maps is not None]
        self.move_rows = [i for i, e in enumerate(effects) if e.coupling is not None]
        self.needs_contacts = coupling is not None and any(
            e.contact or e.point_maps is not None or e.coupling is not None for e in effects)
        if self.needs_contacts:
            element.check_parameter_directions()

    def reusing(self):
        """A context (:meth:`AssemblyContacts.keeping_directions`) in which each Jacobian
        evaluation of the system also forms this object's contact directions in its kernel pass;
        a null context where there is nothing to keep (no contact directions, or a map derivative
        dT x that the element cannot know from its local coordinates)."""
        if not self.needs_contacts or self.moved:
            return contextlib.nullcontext()
        return self.element.keeping_directions(self.d_maps)

    def __call__(self, x, omega):
        system, basis, coupling, element = self.system, self.system.basis, self.coupling, self.element
        k, N = len(self.effects), system.n_unknowns
        out = np.zeros((k, N))
        if self.stacked:
            out += linear_forces(basis, x, omega, **self.stacked).reshape(basis.n_coeffs, k, -1) \
                .transpose(1, 0, 2).reshape(k, N)
        for row, e in zip(out, self.effects):
            if e.excitation is not None:
                row -= e.excitation(omega)
        if self.needs_contacts:
            local = coupling.matrix @ x
            rows = element.direction_rows(local, basis, omega, self.d_maps, [dT @ x for dT in self.moved])
            rows = rows.reshape(len(rows), -1)                                  # (7 + n_maps + n_v, C L)
            n = len(PARAMETER_DIRECTIONS)
            forces = self.weights @ rows[:n]                                    # (k, C L)
            if self.map_rows:
                forces[self.map_rows] += rows[n + 1:n + 1 + len(self.d_maps)]
            for i, dT, f in zip(self.move_rows, self.moved, rows[n + 1 + len(self.d_maps):]):
                out[i] += dT.T @ rows[n]
                forces[i] += f
            contact = np.zeros((N, k))
            coupling.add_forces(contact, forces.T)
            out += contact.T
        return out


class DiskModel:
    """The behaviour of a bladed disk with underplatform dampers that does not depend on how it
    is assembled: the tuned disk's cyclic sector (:class:`TunedDisk`, one blade and one damper,
    the next blade by the interblade phase) and the ring of individual blades and dampers
    (:class:`~bladedamp.mistuned.MistunedDisk`) are both one. It holds, once, the static state,
    the stuck linear start, the robust start, the unknowns' scales and the retry scales of the
    continuation, the FRF driver's sampling (:mod:`bladedamp.frf`), a blade point's map, the time
    integration and its checks (:meth:`stop_check`, :meth:`peak_check`) and the monodromy matrix.

    An assembly gives its layout (unknowns harmonic-major; per coefficient the blades' modal
    coordinates first, then the six coordinates of each damper with a mass):

    * ``engine_order``, ``n_blades``; :attr:`model_blades`: the blades written out (s);
    * :attr:`active_positions`: the positions whose damper has a mass (the d-th of them owns the
      unknowns :meth:`damper_unknowns` ``(d)``);
    * :meth:`seated_damper` ``(k, omega)``: the frictionless seat of position k's damper under
      F_CG at omega [rad/s] (Eq. 26);
    * ``hbm_system``, ``output_amplitudes`` (the protocol of :mod:`bladedamp.hbm.accuracy`) and
      ``full_assembly`` (every blade and damper written out, what the time integration integrates).
    """

    def validate_parameters(self, has_damper: bool) -> None:
        """The disk-wide parameters checked (ValueError naming the parameter) and normalised in
        place: ``damper_radius`` > 0 (a PlausibilityWarning outside 1 mm..5 m), ``excitation`` a
        finite 6-vector, and an explicit ``rotor_speed_hz`` where EO = 0 and a damper
        (``has_damper``) needs the preload of Eq. 26."""
        validation.positive("damper_radius R", self.damper_radius)
        # R from a small test rig (the reference disk: 26 mm) to the largest fan and low-pressure
        # turbine disks (~1.5 m): 1 mm..5 m; outside, most likely a unit slip (26 meant as 26 mm)
        validation.plausible("damper_radius R", self.damper_radius, 1e-3, 5.0, "m",
                            "the damper's distance to the rotor axis, 1 mm to 5 m")
        self.excitation = np.asarray(validation.finite("excitation", self.excitation), dtype=float)
        if self.excitation.shape != (6,):
            raise ValueError("excitation must be a 6-vector (F_x, F_y, F_z, M_x, M_y, M_z) in N and N m")
        if self.engine_order == 0 and has_damper and self.rotor_speed_hz is None:
            raise ValueError("engine_order = 0 needs an explicit rotor_speed_hz (rotor revolutions per second, "
                             "> 0; rpm / 60)")

    @property
    def interblade_phase(self) -> float:
        """dphi [rad] in (-pi, pi], e^{i dphi} = e^{i 2 pi EO / n} (Eq. 25; :func:`interblade_phase`)."""
        return interblade_phase(self.engine_order, self.n_blades)

    @property
    def n_modal_unknowns(self) -> int:
        """The blades' modal coordinates per harmonic coefficient, s n_m (the dampers' follow)."""
        return len(self.model_blades) * self.model_blades[0].n_modes

    # ----- the start and the scales of a branch --------------------------------------------
    def static_state(self, system: HarmonicBalanceSystem, omega: float) -> np.ndarray:
        """The state (C * n_dof,) without dynamic motion: rest, or with a static harmonic every
        damper seated frictionlessly under F_CG at ``omega`` [rad/s] (``seat``)."""
        x = np.zeros(system.n_unknowns)
        if system.basis.has_static:
            X = x.reshape(system.basis.n_coeffs, system.n_dof)
            for d, k in enumerate(self.active_positions):
                X[system.basis.cos_index(0), self.damper_unknowns(d)] = self.seated_damper(k, omega)
        return x

    def initial_guess(self, system: HarmonicBalanceSystem, omega: float) -> np.ndarray:
        """Stuck linear solution (C * n_dof,) of ``system`` at ``omega`` [rad/s, the residual's
        excitation frequency]: one Newton step from the static state, where every contact point
        sticks (without a damper: the linear solution itself).

        With a static harmonic the contacts have no preload at x = 0 (zero approach: every
        point is open and the Jacobian there has no contact stiffness at all), so the step
        starts from the dampers seated frictionlessly under F_CG (``seat``) instead of from rest.
        """
        x = self.static_state(system, omega)
        R, J, _ = system.residual(x, omega)
        return x - system.factorize(J)(R)

    def start_solution(self, system: HarmonicBalanceSystem, omega: float, scales, tol: float = 1e-10,
                       out_of_time=None) -> np.ndarray:
        """Solution (C * n_dof,) of ``system`` at the first frequency ``omega`` [rad/s], robust in
        gross slip (:func:`bladedamp.hbm.start.robust_start`); ``scales`` (C * n_dof,) from
        :meth:`unknown_scales`.

        Damped Newton from the stuck linear solution; if that fails (a light damper sliding far
        from its stuck state), an excitation homotopy on the dynamic excitation (the centrifugal
        preload stays), from the seated dampers. Returns the best iterate (the continuation then
        reports honestly if it is not a solution). ``out_of_time``: None or () -> bool (the
        analysis' budget), asked before each solve of the start (``robust_start``)."""
        f = system.excitation(omega)[0].reshape(system.basis.n_coeffs, system.n_dof).copy()
        if system.basis.has_static:
            f[system.basis.cos_index(0)] = 0.0          # the preload is not ramped
        base = self.static_state(system, omega)
        residual_scale = max(np.linalg.norm(system.residual(np.zeros(system.n_unknowns), omega, False)[0]), 1e-300)
        return robust_start(system.residual, {"stuck linear solution": self.initial_guess(system, omega)},
                            omega, scales, f.ravel(), base=base, residual_scale=residual_scale, tol=tol,
                            factorize=system.factorize, out_of_time=out_of_time).x

    def unknown_scales(self, system: HarmonicBalanceSystem, omega_start: float, omega_end: float) -> np.ndarray:
        """Scale (C * n_dof,) of each unknown of ``system`` over omega_start..omega_end [rad/s]
        (the continuation's ``x_scale``): its largest value in the stuck linear responses across the
        range (harmonic coefficients pooled per DOF, and over the blades for each mode and over
        the dampers for each damper DOF, so that every blade is measured alike), floored at 1e-3
        of the largest scale of its kind (modal / damper translation / damper rotation). A damper
        group that the stuck response leaves at exactly zero (e.g. no damper rotation in the
        symmetric EO = n/2 standing wave) is floored at 1e-3 of the platform motion of the same
        kind instead (a 1e-300 floor turned round-off in the Newton step into an overflow).
        Times sqrt(s) for s blades written out: the scaled norm of s blades equals that of one
        sector, so the arc-length steps (and the number of points) are those of the tuned cyclic
        model."""
        C, N = system.basis.n_coeffs, system.n_dof
        blades = self.model_blades
        s, nm = len(blades), blades[0].n_modes
        X = np.array([np.abs(self.initial_guess(system, w)).reshape(C, N).max(axis=0)
                      for w in np.linspace(omega_start, omega_end, 7)]).max(axis=0)
        q = X[:s * nm].reshape(s, nm).max(axis=0)
        q = np.maximum(q, 1e-3 * q.max() + 1e-300)
        out = [np.tile(q, s)]
        nd = len(self.active_positions)
        if nd:
            u = X[s * nm:].reshape(nd, 6).max(axis=0)
            phi = np.abs(np.stack([np.stack([b.shape("OL"), b.shape("OR")]) for b in blades]))
            for g, platform in ((slice(0, 3), phi[:, :, :3].max()), (slice(3, 6), phi[:, :, 3:].max())):
                u[g] = np.maximum(u[g], max(1e-3 * u[g].max(), 1e-3 * q.max() * platform) + 1e-300)
            out.append(np.tile(u, nd))
        return np.sqrt(s) * np.tile(np.concatenate(out), C)

    def retry_scales(self, system: HarmonicBalanceSystem, scales: np.ndarray) -> np.ndarray | None:
        """The continuation's ``retry_x_scale``: ``scales`` (from :meth:`unknown_scales`) with every
        damper's unknowns weighing less in the arc length (:func:`damper_weighted_scales`); None
        without a damper."""
        if not self.active_positions:
            return None
        return damper_weighted_scales(scales, system.basis.n_coeffs, slice(self.n_modal_unknowns, None))

    # ----- the protocol of bladedamp.frf (the FRF driver) ----------------------------------
    def sample_plan(self, harmonics) -> tuple[int, int, int]:
        """(first, most, most for a dissipation failure) AFT samples per period of the automatic
        sampling (:func:`bladedamp.response.sampled_response`): the basis default (each damper
        of a ring is sampled on its own grid, so no multiple of n / gcd(n, EO) is needed), then
        ``AUTO_SAMPLES_GROWTH`` and ``AUTO_SAMPLES_GROWTH_DISSIPATION`` times it."""
        first = HarmonicBasis(tuple(harmonics)).n_samples
        return first, AUTO_SAMPLES_GROWTH * first, AUTO_SAMPLES_GROWTH_DISSIPATION * first

    def judges_solution_samples(self, n_samples: int) -> bool:
        """False: the dissipation is judged re-evaluated with more samples
        (:func:`bladedamp.response.physical_checks`)."""
        return False

    # ----- derivatives in the design parameters ------------------------------------------
    def parameter_derivatives(self, system: HarmonicBalanceSystem, keys):
        """``dR_dp(x, omega) -> (k, C * n_dof)``: the analytic derivatives of ``system``'s residual
        (this model's :meth:`hbm_system`) at the unknowns x (C * n_dof,) and ``omega`` [rad/s] in
        the k design-file ``keys`` (:data:`SENSITIVITY_KEYS`; ``name[i]`` for one entry of a list),
        per unit of each key as the design file writes it (per g for ``damper.mass_g``, per Hz for
        ``blade.natural_frequencies_hz[j]``, per mm, per rpm, per N) [N per unit]. No differences:
        the linear part's matrices and the excitation are differentiated in closed form
        (:func:`~bladedamp.hbm.system.linear_forces`), the contacts by their homogeneity
        (:meth:`AssemblyContacts.parameter_forces`); a :class:`ParameterDerivatives`, whose
        ``reusing()`` lets it take the contacts' terms from the system's Jacobian evaluation at the
        same point. ValueError naming the key for an unknown key, an index out of range, or a
        parameter this model does not have or cannot differentiate (the list says which and why)."""
        effects = [self.parameter_effect(system, key) for key in keys]
        k = len(effects)
        coupling = next((c for c in system.couplings if isinstance(c.element, (DamperContacts, AssemblyContacts))),
                        None)
        element = None if coupling is None else getattr(coupling.element, "element", coupling.element)
        d_maps = [e.point_maps for e in effects if e.point_maps is not None]
        moved = [e.coupling for e in effects if e.coupling is not None]
        # built once per system: the linear part's matrix derivatives of every key stacked
        # ((k n_dof, n_dof) each, zero for a key without that matrix: one product per kind at a
        # point) and each key's contact directions as a row of weights
        stacked = {}
        for kind in sorted({kind for e in effects for kind in e.matrices}):
            blocks = [sp.csr_matrix(e.matrices[kind]) if kind in e.matrices else
                      sp.csr_matrix((system.n_dof, system.n_dof)) for e in effects]
            matrix = sp.vstack(blocks, format="csr")
            stacked[kind] = matrix.toarray() if matrix.shape[0] * matrix.shape[1] <= DENSE_STACK_MAX else matrix
        weights = np.array([[e.contact.get(name, 0.0) for name in PARAMETER_DIRECTIONS]
                            for e in effects]).reshape(k, len(PARAMETER_DIRECTIONS))      # k = 0 allowed
        return ParameterDerivatives(system, effects, coupling, element, stacked, weights, d_maps, moved)

    def parameter_effect(self, system: HarmonicBalanceSystem, key: str) -> "ParameterEffect":
        """How ``system``'s residual depends on the design-file ``key`` (see
        :meth:`parameter_derivatives`): its :class:`ParameterEffect` per unit of the key."""
        name, index = parse_parameter_key(key)
        basis = system.basis
        blades = self.model_blades
        nm = blades[0].n_modes
        positions = [self.position_of(k) for k in self.active_positions]
        damper = positions[0].damper if positions else None
        contact = getattr(damper, "contact", None)

        def need(condition, why):
            if not condition:
                raise ValueError(f"parameter {key!r}: {why}")

        if name in ("blade.natural_frequencies_hz", "blade.damping_ratio", "mistuning.kappa"):
            if name == "mistuning.kappa":
                need(len(blades) > 1, "a tuned disk has no per-blade mistuning factors (use a MistunedDisk)")
                need(index is not None and 0 <= index < len(blades),
                     f"give the blade as mistuning.kappa[k], k in 0..{len(blades) - 1}")
            elif name == "blade.natural_frequencies_hz":
                need(index is not None and 0 <= index < nm, f"give the mode as {name}[j], j in 0..{nm - 1}")
            else:
                need(index is None or 0 <= index < nm, f"the mode index must be in 0..{nm - 1}")
            kappa = self.mistuning_factors
            rows, d_stiffness, d_damping = [], [], []
            for k, blade in enumerate(blades):
                w0, zeta = blade.natural_angular_frequencies, blade.damping_ratios
                for j in range(nm):
                    if name == "mistuning.kappa":
                        if k != index:
                            continue
                        dw, dz = w0[j] / kappa[k], 0.0            # omega_kj = kappa_k omega_j
                    elif name == "blade.natural_frequencies_hz":
                        if j != index:
                            continue
                        dw, dz = 2 * np.pi * kappa[k], 0.0        # per Hz of the design blade's f_j
                    else:
                        if index is not None and j != index:
                            continue
                        dw, dz = 0.0, 1.0
                    rows.append(k * nm + j)
                    d_stiffness.append(2 * w0[j] * dw)                      # K = omega^2 (Eq. 5)
                    d_damping.append(2 * (zeta[j] * dw + dz * w0[j]))       # D = 2 zeta omega
            n = system.n_dof
            diag = (lambda v: sp.csr_matrix((np.asarray(v, dtype=float), (rows, rows)), shape=(n, n)))
            return ParameterEffect({"stiffness": diag(d_stiffness), "damping": diag(d_damping)})
        need(index is None or name == "disk.excitation_n_nm", "has no index")
        if name == "disk.excitation_n_nm":
            need(index is not None and 0 <= index < 6, f"give the component as {name}[i], i in 0..5 "
                                                         "(F_x, F_y, F_z, M_x, M_y, M_z)")
            unit = np.zeros(6)
            unit[index] = 1.0
            f = dataclasses.replace(self, excitation=unit).hbm_system(basis.harmonics, basis.n_samples) \
                .excitation(1.0)[0].reshape(basis.n_coeffs, -1)
            if basis.has_static:
                f[basis.cos_index(0)] = 0.0                 # the centrifugal preload is not the excitation's
            f = f.ravel()
            return ParameterEffect(excitation=lambda omega: f)
        if name in GEOMETRY_KEYS:
            return self.geometry_effect(system, key, name, positions)
        need(name in SENSITIVITY_KEYS, f"unknown or not differentiable; the keys with derivatives are "
                                       f"{', '.join(SENSITIVITY_KEYS)})")
        need(damper is not None, "the model has no damper")
        need(len({id(p.damper) for p in positions}) == 1, "the dampers differ from position to position")
        static = basis.has_static
        need(static or all(p.initial_gaps is None or not np.any(p.initial_gaps) for p in positions),
             "with initial gaps the seating without a static harmonic is not differentiated (include harmonic 0)")
        degree = contact.roughness_exponent
        mask = np.zeros((basis.n_coeffs, system.n_dof))
        if static:
            for d in range(len(positions)):
                mask[basis.cos_index(0), self.damper_unknowns(d)] = 1.0
        mask = mask.ravel()

        def centrifugal(relative):
            """F_CG times ``relative`` (d ln F_CG / dp): the static load, or the seating's approach."""
            if static:
                return ParameterEffect(excitation=lambda omega: relative * mask * system.excitation(omega)[0])
            return ParameterEffect(contact={"approach": relative / degree})

        def stiffness(relative_tangential, relative_normal):
            """k_T and k_N times the given d ln k / dp: the contacts, the retention spring, the seating."""
            law = {"law": degree * relative_normal, "tangential": relative_tangential}
            if static:
                return ParameterEffect({"static_stiffness": relative_normal * system.static_stiffness},
                                       contact=law)
            return ParameterEffect(contact={**law, "approach": -relative_normal})

        if name == "damper.mass_g":
            effect = centrifugal(1e-3 / damper.mass)
            if self.damper_inertia:                          # each damper's inertia is proportional to its mass
                mass = sp.csr_matrix(system.mass)
                effect.matrices["mass"] = self.damper_blocks(system, [
                    mass[self.damper_unknowns(d), self.damper_unknowns(d)].toarray() * (1e-3 / damper.mass)
                    for d in range(len(positions))])
            return effect
        if name == "disk.damper_radius_mm":
            return centrifugal(1e-3 / self.damper_radius)
        if name == "disk.rotor_speed_rpm":
            need(self.rotor_speed_hz is not None, "the rotor speed follows the excitation frequency here "
                                                  "(rotor_speed_rpm = 'auto'): give a fixed rotor speed")
            return centrifugal(2 / (60 * self.rotor_speed_hz))
        if name == "damper.friction_coefficient":
            need(contact.friction_coefficient > 0, "the derivative in mu is taken at mu > 0")
            return ParameterEffect(contact={"friction": 1 / contact.friction_coefficient})
        if name == "damper.tangential_stiffness_per_length_n_per_m2":
            k = contact.tangential_stiffness_per_length
            return stiffness(1 / k, 1 / k)
        if name == "damper.normal_to_tangential_stiffness":
            return stiffness(0.0, 1 / contact.normal_to_tangential_stiffness)
        # damper.roughness_reference_load_n: c = N_ref^(1-p) (k / p)^p, the seat a ~ c^(-1/p)
        load = contact.roughness_reference_load
        effect = ParameterEffect(contact={"law": (1 - degree) / load})
        if not static:
            effect.contact["approach"] = -(1 - degree) / (degree * load)
        return effect

    def geometry_effect(self, system: HarmonicBalanceSystem, key: str, name: str, positions) -> "ParameterEffect":
        """The :class:`ParameterEffect` of a geometry key (:data:`GEOMETRY_KEYS`) on ``system``: the
        contacts' map T through the rigid kinematics G_D, G_P (their frames, the contact centres and
        the platform offsets, the damper's ``geometry_derivative``), the damper's inertia, the
        patches' points (a wedge's height, the length) and stiffnesses (the length: k_T and k_N are
        per length), and without a static harmonic a cylinder's seating: each patch's approach
        follows its frictionless load (:meth:`~bladedamp.damper.geometry.DamperGeometry.normal_load_log_derivatives`)
        and k_N. A wedge's seating leaves a moment to its faces, so its geometry needs the static
        harmonic (the seating then is the harmonic balance's). Every position's dimension moves
        together; each position has its own kinematics and inertia derivative (its damper's mass,
        its angles), the dampers may differ in their mass only (ValueError otherwise)."""
        basis = system.basis
        damper = positions[0].damper if positions else None
        parameter, unit = GEOMETRY_KEYS[name]
        kind = getattr(damper, "kind", None)
        if kind is None or (parameter == "radius" and kind != "cylinder") or \
                (parameter == "contact_height" and kind != "wedge"):
            raise ValueError(f"parameter {key!r}: the model's damper ({kind or 'none'}) has no such dimension")
        if kind == "wedge" and not basis.has_static:
            raise ValueError(f"parameter {key!r}: a wedge's geometry is differentiated with the static harmonic "
                             "(harmonic 0) in the set, whose balance seats it")
        if any(p.initial_gaps is not None and np.any(p.initial_gaps) for p in positions):
            raise ValueError(f"parameter {key!r}: not with initial gaps (a misfit's seating is not differentiated)")
        if any(b.flexible_platform for b in self.model_blades):
            raise ValueError(f"parameter {key!r}: not with flexible platforms (their point maps follow the geometry)")
        # the patches' points, stiffnesses and seating below are position 0's: the dampers may differ
        # in their mass only (the inertia and the kinematics are each position's own)
        if any(dataclasses.replace(p.damper, mass=damper.mass) != damper for p in positions):
            raise ValueError(f"parameter {key!r}: the dampers differ from position to position in more than their mass")
        if not basis.has_static and parameter in ("gamma_left", "gamma_right") and \
                len({(p.gamma_left, p.gamma_right) for p in positions}) > 1:
            raise ValueError(f"parameter {key!r}: the platform angles differ from position to position: without the "
                             "static harmonic their seating is not differentiated (include harmonic 0)")
        kinematics, d_inertia = [], []
        blade = self.model_blades[0]
        zero_points = {"OL": np.zeros(3), "OR": np.zeros(3)}
        for position in positions:
            geometry = position.damper_geometry()
            d_frames, d_centres, d_position_inertia = position.damper.geometry_derivative(
                position.gamma_left, position.gamma_right, parameter)
            d_inertia.append(unit * d_position_inertia)        # each damper's own: its mass, its angles
            offsets = position.platform_offsets(geometry, blade.points)
            # the offsets are affine in the centres: their derivative is the map of the centres' alone
            d_offsets = position.platform_offsets(dataclasses.replace(geometry, centres=d_centres), zero_points)
            kinematics.append((unit * geometry.G_D_derivative(d_frames, d_centres),
                               unit * geometry.G_P_derivative(offsets, d_frames, d_offsets)))
        coupling = next(c for c in system.couplings if isinstance(c.element, (DamperContacts, AssemblyContacts)))
        n_local = coupling.matrix.shape[0] // basis.n_coeffs // len(positions)
        effect = ParameterEffect(coupling=self.contact_coupling(basis, kinematics, n_local, False))
        if self.damper_inertia and np.any(d_inertia):
            effect.matrices["mass"] = self.damper_blocks(system, d_inertia)
        degree = damper.contact.roughness_exponent
        geometry = positions[0].damper_geometry()
        if parameter in ("contact_height", "length"):          # the points move along xi (height), eta (length)
            size = damper.contact_height if parameter == "contact_height" else damper.length
            effect.point_maps = unit * np.stack([
                rigid_point_map(p.xi / size if parameter == "contact_height" else 0 * p.xi,
                                p.eta / size if parameter == "length" else 0 * p.eta)
                - rigid_point_map(0 * p.xi, 0 * p.eta) for p in geometry.patches])[None]
        if parameter == "length":                              # k_T, k_N per length (the retention spring's k_N)
            relative = unit / damper.length
            effect.contact.update({"tangential": relative, "law": degree * relative})
            if basis.has_static:
                effect.matrices["static_stiffness"] = relative * system.static_stiffness
            else:
                effect.contact["approach"] = -relative
        if not basis.has_static and parameter in ("gamma_left", "gamma_right"):
            loads = unit * geometry.normal_load_log_derivatives(parameter) / degree
            effect.contact.update({"approach_left": loads[0], "approach_right": loads[1]})
        return effect

    def damper_blocks(self, system: HarmonicBalanceSystem, blocks) -> sp.csr_matrix:
        """(n_dof, n_dof) sparse: damper d's (6, 6) ``blocks[d]`` on its own coordinates, zero
        elsewhere (the derivative of the dampers' part of a matrix)."""
        out = sp.lil_matrix((system.n_dof, system.n_dof))
        for d, block in enumerate(blocks):
            sl = self.damper_unknowns(d)
            out[sl, sl] = block
        return out.tocsr()

    def parameter_value(self, key: str) -> float:
        """The value of the design-file ``key`` (:meth:`parameter_derivatives`) in this model, in
        the key's unit (g, mm, rpm, Hz, N, -)."""
        name, index = parse_parameter_key(key)
        blade = self.model_blades[0]
        if name == "mistuning.kappa":
            return float(self.mistuning_factors[index])
        if name == "blade.natural_frequencies_hz":
            return float(blade.natural_frequencies_hz[index] / self.mistuning_factors[0])
        if name == "blade.damping_ratio":
            return float(blade.damping_ratios[0 if index is None else index])
        if name == "disk.excitation_n_nm":
            return float(self.excitation[index])
        if name == "disk.damper_radius_mm":
            return 1e3 * self.damper_radius
        if name in ("disk.gamma_left_deg", "disk.gamma_right_deg"):
            return float(np.degrees(getattr(self.position_of(0), name[5:-4])))
        if name == "disk.rotor_speed_rpm":
            return float("nan") if self.rotor_speed_hz is None else 60.0 * self.rotor_speed_hz
        positions = [self.position_of(k) for k in self.active_positions]
        if not positions:
            return float("nan")
        damper = positions[0].damper
        if name == "damper.mass_g":
            return 1e3 * damper.mass
        if name == "damper.cylinder_radius_mm":
            return 1e3 * damper.radius if hasattr(damper, "radius") else float("nan")
        if name == "damper.contact_height_mm":
            return 1e3 * damper.contact_height if hasattr(damper, "contact_height") else float("nan")
        if name == "damper.length_mm":
            return 1e3 * damper.length
        return float(getattr(damper.contact, CONTACT_FIELDS[name]))

    def with_parameters(self, values: dict) -> "DiskModel":
        """A copy of this model with the design-file keys of ``values`` ({key: value in the key's
        unit}, the keys of :meth:`parameter_derivatives`) set, built anew (validated as any model);
        this model is left as it is. ``blade.natural_frequencies_hz[j]`` sets the design blade's
        f_j (each blade's is kappa_k f_j), ``mistuning.kappa[k]`` blade k's factor."""
        out = self
        for key, value in values.items():
            name, index = parse_parameter_key(key)
            value = float(value)
            if name in CONTACT_FIELDS:
                out = out.with_dampers(lambda d: dataclasses.replace(
                    d, contact=dataclasses.replace(d.contact, **{CONTACT_FIELDS[name]: value})))
            elif name == "damper.mass_g":
                out = out.with_dampers(lambda d: dataclasses.replace(d, mass=1e-3 * value))
            elif name == "disk.damper_radius_mm":
                out = dataclasses.replace(out, damper_radius=1e-3 * value)
            elif name in ("disk.gamma_left_deg", "disk.gamma_right_deg"):
                out = dataclasses.replace(out, **{name[5:-4]: float(np.radians(value))})
            elif name in ("damper.cylinder_radius_mm", "damper.contact_height_mm", "damper.length_mm"):
                field_name = {"damper.cylinder_radius_mm": "radius", "damper.contact_height_mm": "contact_height",
                              "damper.length_mm": "length"}[name]
                out = out.with_dampers(lambda d, f=field_name: dataclasses.replace(d, **{f: 1e-3 * value}))
            elif name == "disk.rotor_speed_rpm":
                out = dataclasses.replace(out, rotor_speed_hz=value / 60.0)
            elif name == "disk.excitation_n_nm":
                excitation = np.array(out.excitation, dtype=float)
                excitation[index] = value
                out = dataclasses.replace(out, excitation=excitation)
            elif name == "blade.damping_ratio":
                def damped(k, blade, index=index, value=value):
                    zeta = np.array(blade.damping_ratios, dtype=float)
                    zeta[slice(None) if index is None else index] = value
                    return dataclasses.replace(blade, damping_ratios=zeta)
                out = out.with_blades(damped)
            elif name == "blade.natural_frequencies_hz":
                kappa = out.mistuning_factors

                def tuned_to(k, blade, index=index, value=value, kappa=kappa):
                    f = np.array(blade.natural_frequencies_hz, dtype=float)
                    f[index] = kappa[k] * value
                    return blade.with_frequencies(f)
                out = out.with_blades(tuned_to)
            else:                                           # mistuning.kappa[k]
                kappa = out.mistuning_factors.copy()
                if len(kappa) < 2 or not 0 <= index < len(kappa):
                    raise ValueError(f"parameter {key!r}: give the blade as mistuning.kappa[k], k in "
                                     f"0..{len(kappa) - 1} of a MistunedDisk")
                ratio, kappa[index] = value / kappa[index], value
                out = dataclasses.replace(out.with_blades(lambda k, b: b.scaled(ratio) if k == index else b),
                                          kappa=kappa)
        return out

    @property
    def mistuning_factors(self) -> np.ndarray:
        """(s,) each blade's mistuning factor kappa_k on the design blade's frequencies (ones: the
        blades as they are; a :class:`~bladedamp.mistuned.MistunedDisk` made by ``from_tuned`` or
        ``mistuned`` keeps its own)."""
        return np.ones(len(self.model_blades))

    def position_of(self, k: int) -> "DamperPosition":
        """The :class:`DamperPosition` of position k (the tuned disk has one, k = 0)."""
        return self.positions[k]

    # ----- outputs ---------------------------------------------------------------------------
    def point_map(self, basis: HarmonicBasis, point: str = "tip", directions=(0,), blade: int = 0) -> np.ndarray:
        """Real-form map (C*k, C*n_dof) from the unknowns of :meth:`hbm_system` (``basis``'s
        harmonics) to the motion of blade ``blade``'s ``point`` (the tuned disk: its reference
        blade, 0) in the k ``directions`` (0, 1, 2: x, y, z translation [m]; 3, 4, 5: rotations
        [rad], blade frame), through the blade's mode shapes (the damper's DOFs do not enter).
        The map of a :class:`~bladedamp.hbm.system.Coupling` from the model to an element at that
        point; add one with ``system.add(element, map, name)``."""
        blades = self.model_blades
        blade = validation.integer("blade", blade, minimum=0, maximum=len(blades) - 1)
        nm = blades[0].n_modes
        n_dof = self.n_modal_unknowns + 6 * len(self.active_positions)
        return blade_point_map(blades[blade], basis, point, directions, n_dof, slice(blade * nm, (blade + 1) * nm))

    # ----- time integration ------------------------------------------------------------------
    def time_response(self, f_hz, **options):
        """Steady state of every blade at each excitation frequency ``f_hz`` [Hz] (scalar or
        array) by time integration of the full assembly (:meth:`full_assembly`: every blade and
        damper written out, no cyclic reduction), from the static equilibrium under F_CG (Eq. 26)
        or a harmonic solution's state (``start_coefficients`` of the full assembly:
        :func:`bladedamp.hbm.monodromy.full_assembly_coefficients`); see
        :func:`bladedamp.timedomain.disk_time_response` for ``options``.
        Returns a :class:`bladedamp.timedomain.DiskTimeResponse` (tip amplitudes of every blade)."""
        from .timedomain import disk_time_response

        return disk_time_response(self.full_assembly(), f_hz, **options)

    def monodromy_matrix(self, coefficients, basis, omega: float, steps: int | None = None):
        """(monodromy matrix, periodicity error) of the HBM solution ``coefficients`` at
        ``omega`` [rad/s] on the full assembly (:func:`bladedamp.hbm.monodromy.disk_monodromy`)."""
        result = disk_monodromy(self, coefficients, basis, omega, steps)
        return result.matrix, result.periodicity_error

    def stop_check(self, response, offset_hz: float = STOP_CHECK_OFFSET_HZ, f_start_hz: float | None = None,
                   **options):
        """Whether a periodic motion exists just beyond where ``response`` (a failed branch of
        :meth:`frequency_response`) got furthest: :meth:`time_response` at that frequency plus
        ``offset_hz`` [Hz] in the branch's direction (``options`` go to it); for a response that
        kept no point, at ``f_start_hz`` [Hz], where its branch was to start. Its ``periodic``
        and ``status`` answer for the motion reached from the static equilibrium: "not settled" or
        "drifting" (the damper hops on the platforms or keeps rolling): not periodic, which no
        harmonic-balance branch represents; "periodic": the branch did not reach a periodic motion
        that exists (:func:`stop_verdict`).
        Costs one time integration of the full assembly (30-210 s for the reference disk on 2
        cores)."""
        return time_check_beyond(self, response, offset_hz, f_start_hz, **options)

    def peak_check(self, response, **options):
        """:meth:`time_response` at the frequency of ``response``'s peak (the point of the
        largest first-harmonic tip amplitude of any blade in any direction), started on the
        branch's state there (``start="hbm"``, default) or from the static equilibrium
        (``start="static"``; :func:`time_at_peak`), the other ``options`` going to it: what
        ``frequency_response(..., check_peak=True)`` runs (:func:`with_peak_check`)."""
        return time_at_peak(self, response, **options)


def peak_index(model, response) -> int:
    """Index of ``response``'s point of the largest first-harmonic output amplitude
    (``model.output_amplitudes``, any blade and direction): the peak the harmonic error estimate
    checks first (:func:`bladedamp.hbm.accuracy.check_points`)."""
    return int(np.argmax(model.output_amplitudes(response.coefficients, response.basis).max(axis=1)))


def time_at_peak(model, response, start: str = "hbm", **options):
    """``model.time_response`` at the frequency of ``response``'s peak (:func:`peak_index`): the
    ``peak_check`` of both models. ``start``: "hbm" (default) starts on the peak's harmonic
    solution (displacements and velocities from its Fourier series at t = 0, every friction
    slider from the contact's return map over one period of its motion:
    :func:`bladedamp.hbm.monodromy.orbit_state`), so the run tests that branch; a harmonic set
    without the static harmonic 0 (the dampers seated beforehand, not in the solution) starts
    from the static equilibrium instead. "static": from the static equilibrium under F_CG, the
    motion a run-up from rest reaches. The result's ``start`` says which."""
    from .hbm import monodromy

    if start not in ("hbm", "static"):
        raise ValueError(f"start must be 'hbm' (the HBM solution's state) or 'static' (the static equilibrium), "
                         f"got {start!r}")
    if not len(response.omega):
        raise ValueError("peak_check needs a response with at least one point")
    k = peak_index(model, response)
    if start == "hbm" and response.basis.has_static and monodromy.supports(model):
        X = monodromy.full_assembly_coefficients(model, response.coefficients[k], response.basis)
        options = dict(options, start_coefficients=X[None], start_basis=response.basis)
    return model.time_response(response.frequency_hz[k], **options)


def time_check_beyond(model, response, offset_hz: float = STOP_CHECK_OFFSET_HZ, f_start_hz: float | None = None,
                      **options):
    """``model.time_response`` (a :class:`TunedDisk` or :class:`~bladedamp.mistuned.MistunedDisk`)
    ``offset_hz`` [Hz] beyond where ``response`` got furthest, in its branch's direction, or at
    ``f_start_hz`` [Hz] for a response that kept no point: the ``stop_check`` of both models."""
    validation.positive("offset_hz", offset_hz)
    if not len(response.omega):
        if f_start_hz is None:
            raise ValueError("stop_check needs a response with at least one point, or f_start_hz "
                             "(where a branch that kept none was to start)")
        return model.time_response(validation.positive("f_start_hz", f_start_hz), **options)
    o = response.omega
    k = response.furthest_index()
    direction = np.sign(o[k] - o[0]) or 1.0
    return model.time_response(response.frequency_hz[k] + direction * offset_hz, **options)


def rest_response(model, omega_start: float, omega_end: float, max_step: float, tolerance: float, respond):
    """The exact response of a disk (``model``: a TunedDisk or MistunedDisk) without dynamic
    excitation over ``omega_start``..``omega_end`` [rad/s]: every blade and damper at rest (each
    harmonic of the motion zero; the preload holds the dampers on their platforms), at points
    ``max_step`` of the range apart. Zero motion solves the first-harmonic residual (the
    contacts' forces are then constant and have no first harmonic; to rounding), so the response
    is ``success`` with a harmonic error of 0 (no harmonic set moves), computed with harmonics
    (1,) whatever set was asked for. ``respond(system, branch)`` makes the model's response."""
    system = model.hbm_system((1,))
    n = int(np.ceil(1.0 / max_step)) + 1
    omega = np.linspace(omega_start, omega_end, n)
    branch = Branch(omega, np.zeros((n, system.n_unknowns)), np.zeros(n, dtype=int), True,
                    "no dynamic excitation (excitation is zero): every blade and damper at rest at every frequency")
    return dataclasses.replace(respond(system, branch), harmonic_error=0.0, harmonic_tolerance=tolerance,
                               harmonics_converged=True)


def blade_span(model) -> float:
    """The span of the blades of ``model`` (a :class:`TunedDisk` or
    :class:`~bladedamp.mistuned.MistunedDisk`) [m]: the tip point's distance from the blade
    frame's origin, the root, the shortest blade's (the scale of
    :func:`bladedamp.response.amplitude_check`)."""
    blades = getattr(model, "blades", None) or [model.blade]
    return min(float(np.linalg.norm(b.points["tip"])) for b in blades)


def with_stop_check(model, response, f_start_hz: float, check_stop: bool):
    """``response`` of ``model.frequency_response`` (a :class:`TunedDisk` or
    :class:`~bladedamp.mistuned.MistunedDisk`) with its stop note (:func:`with_stop_note`): with
    ``check_stop``, a branch that stopped before the end of its range (not by ``stop_above``)
    first gets ``model.stop_check``'s time integration, whose verdict the note gives."""
    stopped_early = not (response.stopped_by or response.reached_range_end)
    check = model.stop_check(response, f_start_hz=f_start_hz) if check_stop and stopped_early else None
    return with_stop_note(response, f_start_hz, check)


# A harmonic solution whose static retention spring (hbm_system's static_retention) keeps carrying,
# in the weak-spring limit, a load above this fraction of what the damper's own load can balance
# (F_CG on a force, F_CG l on a moment: :func:`retention_held`) is held by that regularisation,
# which the physical model does not have: no periodic motion of the model (the damper rolls or
# slides, then drifts or shakes down). The fraction is the harmonic tolerance's (1 %): the held
# load is a residual of the physical model's static balance at that solution. Measured at the
# peaks of the random mistuned designs (benchmarks/README.md, 'Four contradictions, two cured'):
# the 8 g cylinders of design 27, 7-15 % (its time integration shakes down to the stuck motion,
# 15 % from the branch); the wedges of designs 11, 14, 17 below 0.2 % (and the spring's whole
# load, held or not, on the reference 1 g cylinder in its slip range at most 0.13 %).
RETENTION_HELD_LIMIT = 0.01


def retention_held(model, coefficients, basis, omega: float) -> np.ndarray:
    """(n_d,) the load that the static retention spring of ``model.hbm_system`` (a TunedDisk's
    sector or a MistunedDisk; :func:`bladedamp.damper.retention_stiffness`, on the static harmonic
    of each damper's six rigid-body coordinates) still carries in the weak-spring limit at the
    harmonic solution ``coefficients`` (C, n) or (C * n,) of ``basis`` at ``omega`` [rad/s],
    relative to the damper's own load: the largest of its three forces over F_CG and its three
    moments over F_CG l (F_CG the damper's centrifugal load, the static excitation on its
    translations, Eq. 26; l [m] the largest distance of its contact centres from its centre of
    gravity, a cylinder's radius). 0 for every damper of a solution without the static harmonic.

    With the spring s K_0 the load is L = s K_0 x_0 (x_0 the static harmonic). Where the contacts
    hold the coordinate (a wedge's roll, pressed on two faces), x_0 does not grow as s falls and L
    vanishes with s; where nothing else holds it (a cylinder's roll when friction leaves a net
    mean moment, frictional shakedown) x_0 ~ 1 / s and L stays. To first order in s, from the
    solution's Jacobian J (R(x) = 0 with the spring): d x / d ln s = -J^-1 L (L in the static
    rows), so the load left at s -> 0 is L - d L / d ln s = -s K_0 (d x_0 / d ln s) =
    s K_0 [J^-1 L]_0: equal to L for a coordinate the spring alone holds, near 0 for one the
    contacts hold."""
    system = model.hbm_system(tuple(basis.harmonics), basis.n_samples)
    S = system.static_stiffness
    element = system.couplings[0].element if system.couplings else None
    contacts = getattr(element, "contacts", [element]) if element is not None else []
    if S is None or not basis.has_static or not contacts:
        return np.zeros(len(contacts))
    S = np.asarray(S.toarray() if hasattr(S, "toarray") else S)
    C, n = basis.n_coeffs, system.n_dof
    j0 = basis.cos_index(0)
    x = np.asarray(coefficients, dtype=float).reshape(C, n)
    load = np.zeros((C, n))
    load[j0] = S @ x[j0]
    _, J, _ = system.residual(x.ravel(), omega, True)
    dx = system.factorize(J)(load.ravel()).reshape(C, n)
    held = S @ dx[j0]
    f_static = system.excitation(omega)[0].reshape(C, n)[j0]
    dofs = np.flatnonzero(np.diag(S) != 0).reshape(-1, 6)       # each damper's six coordinates
    shares = np.zeros(len(dofs))
    for d, (rows, contact) in enumerate(zip(dofs, contacts)):
        f_cg = float(np.linalg.norm(f_static[rows[:3]]))
        lever = float(np.linalg.norm(contact.geometry.centres, axis=1).max())
        if f_cg > 0:
            shares[d] = max(np.abs(held[rows[:3]]).max() / f_cg, np.abs(held[rows[3:]]).max() / (f_cg * lever))
    return shares


def retention_check(model, response, limit: float = RETENTION_HELD_LIMIT) -> tuple[str, str]:
    """(what was found, the short reason) when, at ``response``'s peak (:func:`peak_index`), a
    damper's load held by the static retention spring (:func:`retention_held`) exceeds ``limit``:
    the peak is then a solution of the regularised harmonic balance only, not a periodic motion
    of the physical model (no spring there: the damper rolls or slides on, drifting or shaking
    down); ('', '') otherwise, and for an empty response or one without the static harmonic."""
    if not len(response.omega) or not response.basis.has_static:
        return "", ""
    k = peak_index(model, response)
    shares = retention_held(model, response.coefficients[k], response.basis, response.omega[k])
    if not shares.size or not shares.max() > limit:
        return "", ""
    d = int(np.argmax(shares))
    found = (f"at the peak, {response.frequency_hz[k]:.4f} Hz, the harmonic balance holds damper {d} with its static "
             f"retention spring, which the physical model does not have: in the weak-spring limit it carries "
             f"{percent(shares[d])} of the damper's load (F_CG on a force, F_CG times the contact lever on a moment; "
             f"above {percent(limit)}), a mean friction load nothing else balances, so the damper rolls or slides on "
             "and the peak need not be a motion of the disk")
    reason = (f"the peak ({response.frequency_hz[k]:.2f} Hz) is held by the harmonic balance's static retention "
              f"spring ({percent(shares[d])} of a damper's load), which the disk does not have")
    return found, reason


def with_retention_check(model, response, limit: float = RETENTION_HELD_LIMIT):
    """``response`` (``success``) unverified where :func:`retention_check` finds its peak held by
    the static retention spring: ``harmonic_error`` nan, ``harmonics_converged`` False (a richer
    harmonic set solves the same regularised balance: no estimate of it verifies the curve),
    ``unverified_reason`` the short reason (status COMPLETE_UNVERIFIED; the time integration of
    ``check_peak`` decides then), the message what was found; else unchanged."""
    if not response.success:
        return response
    found, reason = retention_check(model, response, limit)
    if not found:
        return response
    error = response.harmonic_error
    estimate = (f" (the enriched harmonic set's estimate, {percent(error)}, does not verify such a point)"
                if np.isfinite(error) else "")
    return with_note(response, Note(NoteKind.RETENTION, f"not verified: {found}{estimate}"),
                     harmonic_error=float("nan"), harmonics_converged=False, unverified_reason=reason)


def peak_checked_response(model, system_model, solve, harmonics, tolerance: float, max_harmonic: int, estimate: bool,
                          check_peak: bool, can_check: bool, predict: bool = False):
    """The response of ``model.frequency_response`` (a :class:`TunedDisk` or
    :class:`~bladedamp.mistuned.MistunedDisk`) before its stop check: the branches of ``solve``
    with their harmonic error estimate (:func:`~bladedamp.hbm.accuracy.converged_response` on
    ``system_model``, a richer set's stalled branches ended early once a poorer set's reached the
    end: ``guard_stalls``) and :func:`~bladedamp.response.amplitude_check`, then
    :func:`with_peak_check` (not run on an implausible amplitude). One accuracy warning per call: where the
    peak check runs, its verdict (which includes the estimate) replaces the estimate's
    AccuracyWarning, and an implausible amplitude (its status says so) has none; every other
    warning raised on the way is raised again at the caller of ``frequency_response``. A peak held
    by the static retention spring (:func:`with_retention_check`, where the time integration models
    the disk: ``can_check``) is not verified, and its warning replaces the estimate's. ``predict``:
    the automatic choice skips the sets its point solves find above the tolerance
    (:func:`~bladedamp.hbm.accuracy.predicted_set`)."""
    with warnings.catch_warnings(record=True) as raised:
        response = converged_response(system_model, solve, harmonics, tolerance, max_harmonic, estimate=estimate,
                                      guard_stalls=True, predict=predict)
    response = with_amplitude_check(response, blade_span(model))
    if can_check:
        response = with_retention_check(model, response)
    response = with_peak_check(model, response, check_peak, tolerance, can_check)
    said = response.peak_check is not None or "amplitude" in response.failed_checks   # the verdict, or beyond the model
    if response.peak_check is None and response.unverified_reason:       # no harmonic set verifies it
        said = True
        warnings.warn(f"{response.unverified_reason}: not a verified motion of the disk; check the peak by time "
                      "integration (check_peak=True)", AccuracyWarning, stacklevel=3)
    for w in raised:
        if not said or not issubclass(w.category, AccuracyWarning):
            warnings.warn(w.message, w.category, stacklevel=3)     # this function, frequency_response, its caller
    return response


def with_peak_check(model, response, check_peak: bool, tolerance: float = HARMONIC_TOLERANCE,
                    can_check: bool = True):
    """``response`` of ``model.frequency_response`` (a :class:`TunedDisk` or
    :class:`~bladedamp.mistuned.MistunedDisk`) with its peak checked by time integration, with
    ``check_peak`` and a branch that reached the end of its range: ``model.peak_check``, the full
    assembly integrated at the peak's frequency, started on the branch's own state there
    (:func:`time_at_peak`; from the static equilibrium for a harmonic set without the static
    term), so it tests that branch; the message says which start it used.

    * Periodic there: the largest difference of the first-harmonic tip amplitudes (every blade,
      x, y, z) relative to the branch's peak amplitude is a second harmonic error estimate, a
      direct one (the settle criterion leaves about 5e-4 of the amplitude at its defaults; the
      time step more: about 0.1 % where it was measured, benchmarks/README.md). Where it exceeds
      ``tolerance``, the same run with twice the steps a period gives its own error bar (the
      difference of the two), and the message states it: ``harmonic_error`` becomes
      :func:`peak_check_error`, the larger of it and the enriched set's, or it alone where the
      enriched set's Newton failed at the peak ("not verified"), except that a direct estimate
      above the tolerance by no more than its error bar does not contradict an enriched one
      within it; held to ``tolerance`` (``harmonics_converged``). A settled motion with every
      contact point stuck the whole period is named (the disk shakes down to the stuck motion),
      with its largest tip amplitude. This is the estimate where the enriched set cannot solve the
      peak (as for light wedges whose damper is separated most of the period: brief impacts).
    * "Drifting" there (the first harmonics settle while a damper keeps rolling or walking, as the
      reference 1 g cylinder in its slip range, 95.1-96.1 Hz): compared as above, with the time
      integration's mean tip amplitudes, and the message says the damper drifts.
    * Periodic or drifting, but farther from the branch than its one-period defect allows for a
      motion that stays on it (:func:`orbit_departure`): the motion left the branch for a
      coexisting one. A note, not a harmonic error estimate (``harmonic_error`` and
      ``harmonics_converged`` stay the enriched set's); ``peak_check(result, start='static')``
      gives the motion reached from rest.
    * Not settled or unstable there (the vibration does not settle): the branch's peak is not a
      motion the disk
      settles on, so the response is not ``success`` (its ``failed_checks`` has
      ``peak_time_check``), whatever the harmonic set; the finding names an unstable branch
      where the peak's Floquet multipliers say so (:func:`peak_stability_note`).
    * A peak held by the static retention spring (``unverified_reason``,
      :func:`with_retention_check`): the time integration's estimate replaces the void one;
      ``unverified_reason`` is cleared where it is within ``tolerance`` and kept otherwise (the
      status sentence then says a richer set does not help).

    The result keeps the time integration as its ``peak_check``. Without ``check_peak``, a
    response whose estimate could not be verified says how to check it (where the time integration
    models the disk: ``can_check``, rigid platforms and no extra couplings); a branch that
    stopped early is left to the stop check, and is returned unchanged, as is one stopped by
    ``stop_above``."""
    if not len(response.omega) or response.stopped_by or not response.reached_range_end \
            or "amplitude" in response.failed_checks:         # beyond the model: nothing to check in time
        return response
    enriched = response.harmonic_error
    if not check_peak:
        if not (can_check and response.harmonics_converged is False and not np.isfinite(enriched)):
            return response
        return with_note(response, Note(NoteKind.PEAK_CHECK, "frequency_response(..., check_peak=True) "
                                        "checks the peak by time integration"))
    k = peak_index(model, response)
    at_peak = model.output_amplitudes(response.coefficients[k:k + 1], response.basis)[0]
    check = model.peak_check(response)
    f, peak = check.frequency_hz[0], max(float(at_peak.max()), 1e-300)
    separated = 100 * check.point_state[0][..., 2].mean()
    on_orbit = check.start is not None and check.start[0] == "HBM solution"
    origin = ("started on the HBM solution's state: displacements, velocities and the sliders' states over one "
              "period of its motion" if on_orbit else "from the static equilibrium" +
              ("" if response.basis.has_static else ": the harmonic set has no static term to start on"))
    where = f"at the peak, {f:.4f} Hz, the time integration of the full assembly ({origin})"
    status = check.status[0]
    if status not in ("periodic", "drifting"):
        found = (f"{where} finds no periodic motion ({check.message[0]}; the damper's contact points separated "
                 f"{separated:.0f} % of the period): the branch's peak is not a motion the disk settles on"
                 + peak_stability_note(model, response, k))
        warnings.warn(f"at the peak, {f:.2f} Hz, the time integration finds no periodic motion: the curve's peak is "
                      "not a motion the disk keeps; the time integration is the answer there",
                      AccuracyWarning, stacklevel=4)   # with_peak_check, peak_checked_response, the model, the caller
        return dataclasses.replace(with_checks(response, {"peak_time_check": found}), peak_check=check)
    direct = float(np.abs(model.time_output_amplitudes(check)[0] - at_peak).max() / peak)
    if on_orbit:
        left = orbit_departure(model, check, at_peak, peak, direct, tolerance)
        if left is not None:
            note = (f"{where} leaves the branch for a coexisting periodic motion {left}; the branch's peak is not the "
                    "motion a disk started on it keeps (an unstable or coexisting solution): this is no harmonic error "
                    "estimate, peak_check(result, start='static') gives the motion reached from rest")
            warnings.warn(f"at the peak, {f:.2f} Hz, the time integration leaves the curve for another periodic motion "
                          f"{percent(direct)} away: peak_check(result, start='static') gives the motion from rest",
                          AccuracyWarning, stacklevel=3)
            return with_note(response, Note(NoteKind.PEAK_CHECK, note), peak_check=check)
    spread, doubled = 0.0, ""
    if direct > tolerance:           # a contradiction only beyond the check's own error bar: twice the steps
        finer = model.peak_check(response, steps_per_period=2 * int(check.steps_per_period))
        if str(finer.status[0]) == status:
            spread = abs(float(np.abs(model.time_output_amplitudes(finer)[0] - at_peak).max() / peak) - direct)
            doubled = (f", {100 * spread:.2g} % its own error bar (the same run with {2 * int(check.steps_per_period)} "
                       f"instead of {int(check.steps_per_period)} steps a period)")
        else:
            doubled = f" (with twice the steps a period it is {finer.status[0]}: no error bar)"
    error = peak_check_error(direct, spread, enriched, tolerance)
    met = error <= tolerance
    motion = ("settles on a periodic motion" if status == "periodic" else
              f"settles on a drifting vibration, a damper keeps rolling or walking ({check.message[0]}; its mean "
              "compared)")
    stuck = check.point_state[0][..., 0].min() >= 1.0 if check.point_state[0].size else False
    if stuck:
        motion += (f" with every contact point stuck the whole period, the stuck motion (largest tip amplitude "
                   f"{1e3 * check.tip_amplitude[0].max():.4g} mm): the disk shakes down to it")
    note = (f"{where} {motion}, {100 * direct:.3g} % from the branch's tip amplitudes{doubled} (contact points "
            f"separated {separated:.0f} % of the period): harmonic error estimate {100 * error:.2g} %, "
            + ("within" if met else "above") + f" the tolerance {100 * tolerance:.2g} %"
            + (" given the time integration's own error bar" if met and direct > tolerance else ""))
    if not met:      # the sentence the result's status gives (bladedamp.response.status_message)
        warnings.warn(harmonic_sentence(response.basis.harmonics, error, tolerance, status == "drifting"),
                      AccuracyWarning, stacklevel=4)
    return with_note(response, Note(NoteKind.PEAK_CHECK, note), harmonic_error=error, harmonic_tolerance=tolerance,
                     harmonics_converged=met, peak_check=check,
                     unverified_reason="" if met else response.unverified_reason)


# The Floquet multipliers of a peak whose HBM orbit is within this periodicity error of a periodic
# orbit of the time integration are read (:func:`peak_stability_note`): above the monodromy's warning
# limit (1e-2, the HBM's own truncation error a few 1e-3), below the order-one errors of orbits the
# time integration does not have (0.67-0.84 measured: a rolling cylinder, a hopping wedge)
UNSTABLE_PERIODICITY_LIMIT = 0.1
# a multiplier above 1 by more than this (a perturbation growing 1 % a period, e-fold in 100 of the
# time integration's up to 4000 periods) counts as unstable: beyond the finite-difference and
# discretisation scatter of the stuck sliders' multipliers 1 (1.004 measured where the motion is
# periodic)
UNSTABLE_MARGIN = 1e-2


def peak_stability_note(model, response, k: int) -> str:
    """What the monodromy matrix (:func:`bladedamp.hbm.monodromy.monodromy_multipliers`) of
    ``response``'s point ``k`` (the peak) says of a peak whose time integration did not settle:
    "; the branch is unstable at the peak (...)" with the largest Floquet multiplier's modulus and
    its kind (a complex pair: Neimark-Sacker, the motion turns quasi-periodic; real above 1: a fold
    or branch point; real below -1: period doubling) where it exceeds 1 + ``UNSTABLE_MARGIN`` on an
    HBM orbit within ``UNSTABLE_PERIODICITY_LIMIT`` of a periodic orbit of the time integration;
    a sentence saying the multipliers do not apply where the orbit is farther; '' where the
    model has no period map, the harmonic set no static term, or every multiplier is within
    the margin."""
    from .hbm import monodromy
    from .hbm.stability import multiplier_crossing

    if not (response.basis.has_static and monodromy.supports(model)):
        return ""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)       # the periodicity error is judged here
        mu, error = monodromy.monodromy_multipliers(model, response.coefficients[k], response.basis,
                                                    response.omega[k])
    if error > UNSTABLE_PERIODICITY_LIMIT:
        return (f"; its Floquet multipliers do not apply there (the HBM orbit is {percent(error)} from periodic over one "
                "period of the time integration: not a periodic orbit of the model, whose stability they would tell)")
    lead = float(np.abs(mu[0]))
    if lead <= 1 + UNSTABLE_MARGIN:
        return ""
    kind = {"fold": "a real multiplier above 1: a fold or branch point",
            "period doubling": "a real multiplier below -1: period doubling",
            "neimark-sacker": "a complex pair: Neimark-Sacker, the motion turns quasi-periodic"}[multiplier_crossing(mu)]
    return (f"; the branch is unstable at the peak (monodromy: largest Floquet multiplier |mu| = {lead:.3g}, {kind}; "
            f"the HBM orbit {percent(error)} from periodic)")


def peak_check_error(direct: float, spread: float, enriched: float, tolerance: float) -> float:
    """The harmonic error estimate of a peak checked by time integration (:func:`with_peak_check`):
    ``direct``, the settled motion's largest first-harmonic tip difference from the branch's
    (relative to the peak), ``spread`` >= 0 its own error bar (how much it moves when the run
    takes twice the steps a period), ``enriched`` the enriched harmonic set's estimate (nan where
    not verified), all fractions of the peak, held to ``tolerance``.

    The larger of ``direct`` and ``enriched`` (``direct`` alone where ``enriched`` is nan), except
    that a ``direct`` above the tolerance by no more than its own error bar does not contradict a
    finite ``enriched``: then max(``enriched``, ``direct`` - ``spread``), which is within the
    tolerance when ``enriched`` is. A contradiction is declared only where the difference exceeds
    the tolerance plus the check's own error bar."""
    if not np.isfinite(enriched):
        return direct
    if tolerance < direct <= tolerance + spread:
        return max(enriched, direct - spread)
    return max(direct, enriched)


def orbit_departure(model, check, at_peak, peak: float, direct: float, tolerance: float) -> str | None:
    """Whether the time integration ``check``, started on the HBM solution at the peak (tip
    amplitudes ``at_peak``, ``model.output_amplitudes``' order, largest ``peak`` [m]), left that
    branch for another periodic motion; its settled tip amplitudes differ from the branch's by
    ``direct`` (relative to ``peak``). A solution of truncation error e is a fixed point of the
    period map only to within its one-period defect d_1 (the first period's first harmonics'
    largest difference from the branch's, relative to ``peak``); where the period map contracts
    at least as fast as the slowest viscously damped blade mode decays, rho = exp(-sigma T) per
    period (``check.decay_rate`` = sigma; friction only adds dissipation), the motion it settles
    on lies within d_1 / (1 - rho) of the start (the contraction's fixed-point bound). A settled
    motion farther than that and than ``tolerance`` is another motion: returns what says so (the
    numbers), else None."""
    if not np.isfinite(check.decay_rate) or check.decay_rate <= 0 or not len(check.tip_history[0]):
        return None
    first = dataclasses.replace(check, tip_amplitude=np.abs(check.tip_history[0][:1]))
    defect = float(np.abs(model.time_output_amplitudes(first)[0] - at_peak).max() / peak)
    bound = defect / -np.expm1(-check.decay_rate * 2 * np.pi / check.omega[0])
    if direct <= max(bound, tolerance):
        return None
    return (f"{100 * direct:.3g} % from the branch's first-harmonic tip amplitudes, beyond the {100 * bound:.3g} % "
            f"that the branch's one-period defect ({100 * defect:.3g} % in the first period) allows for a motion "
            f"that stays on it (the blades' slowest viscous decay, {check.decay_rate:.3g} 1/s)")


def stop_verdict(check, harmonics) -> str:
    """What the time integration ``check`` (a one-frequency DiskTimeResponse of
    :meth:`TunedDisk.stop_check`) says of a branch with ``harmonics`` that stopped before it:
    the motion there is not periodic (no harmonic-balance branch represents it), or it is
    periodic, and the branch did not reach it (cut by max_points, or lost by the harmonic set: a
    richer set may follow it). It is the motion reached from the static equilibrium, what a test
    rig run up to that speed would see; a periodic solution may coexist with it."""
    f = check.frequency_hz[0]
    tip = 1e3 * check.tip_amplitude[0, :, 0].max()
    separated = 100 * check.point_state[0][..., 2].mean()
    if check.periodic[0]:
        return (f"the time integration of the full assembly at {f:.4f} Hz (from the static equilibrium) settles on a "
                f"periodic motion (largest tip amplitude {tip:.4g} mm, the damper's contact points separated "
                f"{separated:.0f} % of the period): "
                f"one exists there, which the branch with harmonics {tuple(harmonics)} did not reach (more points, "
                "max_points, or a richer set, harmonics='auto', may follow it; with the damper separated most of the "
                "period, brief impacts, only a richer set can)")
    return (f"the time integration of the full assembly at {f:.4f} Hz (from the static equilibrium) finds no periodic "
            f"motion ({check.message[0]}; largest tip amplitude {tip:.4g} mm over its last periods, the damper's "
            f"contact points separated {separated:.0f} % of the period): the damper hops on the platforms, keeps "
            "rolling or the vibration does not settle, a motion no harmonic-balance branch represents; the time "
            "integration is the answer there")


def with_stop_note(response, f_start_hz: float | None = None, check=None):
    """A failed ``response`` (a :class:`DiskResponse` or a
    :class:`~bladedamp.mistuned.MistunedResponse`) with what the damper did where its branch got furthest (the share
    of the period its contact points stick, slip and are separated there) and how to tell
    whether a periodic motion exists just beyond (:meth:`TunedDisk.stop_check`, at
    STOP_CHECK_OFFSET_HZ beyond the furthest point): where a branch stops, the damper hops,
    keeps rolling or makes brief impacts that the harmonic set cannot follow (benchmarks/README.md,
    'Moved from the package's docstrings', disk.py, 'with_stop_note'). A response that kept no
    point (the start failed) gets how to tell at the start ``f_start_hz`` [Hz]. ``check``: the
    time integration there
    (:meth:`TunedDisk.stop_check`), whose verdict (:func:`stop_verdict`) replaces how to tell, and
    which the result keeps as its ``stop_check``. A successful one is returned unchanged, and so
    is one that reached the end of its range (it failed a check, not stopped: the note would
    point past the end) and one without a damper."""
    if response.success or response.stopped_by or response.reached_range_end:
        return response
    if check is not None:
        where = "at the start" if not len(response.omega) else "beyond where the branch got furthest"
        note = f"{where}, {stop_verdict(check, response.basis.harmonics)}"
        return with_note(response, Note(NoteKind.STOP_CHECK, note), stop_check=check)
    model = type(response.disk).__name__ if response.disk is not None else "TunedDisk"
    if not len(response.omega):
        if f_start_hz is None:
            return response
        note = (f"{model}.time_response({f_start_hz:.6g}) tells by time integration whether a periodic motion "
                "exists at the start (where one does with the damper separated most of the period, brief impacts, "
                "a richer harmonic set may find it: harmonics='auto'; frequency_response(..., check_stop=True) "
                "runs it)")
        return with_note(response, Note(NoteKind.STOP_CHECK, note))
    states = getattr(response, "point_state", None)                 # DiskResponse's, else None
    dampers = getattr(response, "damper_dissipation", None)         # MistunedResponse's, else None
    if states is None and (dampers is None or not dampers.size):
        return response                                             # no damper: nothing to tell
    k = response.furthest_index()
    f = response.frequency_hz[k]
    tip = 1e3 * np.max(response.tip_amplitude[k][..., 0])
    where = f"where the branch got furthest ({f:.4f} Hz, largest tip amplitude {tip:.4g} mm)"
    if states is not None:
        stick, slip, separated = 100 * response.contact_state_shares()[k]
        where += (f" the damper's contact points stick {stick:.0f} %, slip {slip:.0f} %, are separated "
                  f"{separated:.0f} % of the period")
    note = (f"{where}; {model}.stop_check(result) tells by time integration whether a periodic motion exists just "
            "beyond (a light damper may hop on the platforms or keep rolling: then none does; "
            "frequency_response(..., check_stop=True) runs it)")
    return with_note(response, Note(NoteKind.STOP_CHECK, note))


def contact_point_field(disk, response, field: str) -> np.ndarray:
    """(n, 2 P) a per-point field (n, 2, P) of a :class:`DiskResponse` of ``disk`` flattened per
    point ((n, 0) without a damper or a point)."""
    n = len(response.omega)
    return getattr(response, field).reshape(n, -1) if disk.has_damper and n else np.zeros((n, 0))


def blade_point_map(blade, basis, point, directions, n_dof, modes):
    """Real-form map (C*k, C*n_dof) of ``basis`` to ``blade``'s ``point`` in ``directions`` (0..5), from
    its modal DOFs ``modes`` (a slice of the n_dof unknowns per coefficient)."""
    try:
        directions = tuple(int(d) for d in np.atleast_1d(directions))
    except (TypeError, ValueError):
        raise ValueError(f"directions must be integers in 0..5 (x, y, z, rx, ry, rz), got {directions!r}") from None
    if not directions or any(d < 0 or d > 5 for d in directions):
        raise ValueError(f"directions must be integers in 0..5 (x, y, z, rx, ry, rz), got {directions!r}")
    out = np.zeros((len(directions), n_dof))
    out[:, modes] = blade.shape(point)[list(directions)]      # ValueError naming the points
    return basis.real_form(lambda h: out)


class WithCouplings:
    """``model`` (a :class:`TunedDisk`) whose :meth:`hbm_system` has the extra couplings
    ``extra(basis)`` (a callable ``basis -> sequence of Coupling``); every other attribute is the
    model's. What ``frequency_response(..., extra_couplings=extra)`` solves, for the functions
    that rebuild a response's system from its model (``harmonic_error``, ``with_stability``)."""

    def __init__(self, model, extra):
        if not callable(extra):
            raise TypeError("extra_couplings must be a callable basis -> sequence of Coupling (it is called "
                            f"for every harmonic set), got {type(extra).__name__}")
        self._model, self._extra = model, extra

    #: no period map for the monodromy method: the time integration has not the extra couplings
    has_period_map = False

    def __getattr__(self, name):
        return getattr(self._model, name)

    def hbm_system(self, harmonics=(1,), n_samples=None, **options):
        system = self._model.hbm_system(harmonics, n_samples, **options)
        for c in self._extra(system.basis):
            if not isinstance(c, Coupling):
                raise TypeError(f"extra_couplings(basis) must give Coupling objects, got {type(c).__name__}")
            system = system.add(c.element, c.matrix, c.name)
        return system


@dataclass
class DiskModelResponse(FrequencyResponse):
    """What the frequency responses of both disk models share (:class:`DiskResponse` of the tuned
    disk's reference sector, :class:`~bladedamp.mistuned.MistunedResponse` of every blade of a
    ring): the same names for the same quantities, per point of the branch (n points):

    tip_amplitude : first-harmonic tip amplitude in x, y, z [m]: (n, 3) of the reference sector,
        (n, s, 3) of the s blades of a ring
    excitation_work, viscous_dissipation, dissipated_energy : (n,) per period, the whole model
        (one sector, or the s blades) [J]: the work of the excitation, the blades' modal damping
        dissipation and the friction dissipation of every damper
    stop_check : for a branch that stopped before the end of its range, computed with
        ``check_stop=True``: the time integration of the full assembly just beyond where it got
        furthest (a one-frequency :class:`bladedamp.timedomain.DiskTimeResponse`; its ``periodic``
        says whether a periodic motion exists there, :func:`stop_verdict`), else None
    peak_check : for a branch that reached the end of its range, computed with
        ``check_peak=True``: the time integration of the full assembly at its peak's frequency
        (a one-frequency DiskTimeResponse, :func:`with_peak_check`), else None
    disk : the model (None for a loaded result)

    The peaks, the same names and types for both models: :attr:`peak_amplitude` (float [m]) and
    :attr:`peak_frequency_hz` (float [Hz]) are the largest tip amplitude u_x of any blade and its
    frequency (on a :class:`DiskResponse` the reference sector's largest sample);
    :attr:`blade_peak_amplitudes` and :attr:`blade_peak_frequencies_hz` are (s,) arrays, one per
    blade written out ((1,) for the tuned disk; a MistunedResponse's parabola-refined, its
    ``peaks()``), whose largest is ``peak_amplitude``.
    """

    tip_amplitude: np.ndarray = None
    excitation_work: np.ndarray = None
    viscous_dissipation: np.ndarray = None
    dissipated_energy: np.ndarray = None
    stop_check: object = None
    peak_check: object = None
    disk: DiskModel = None

    def blade_outputs(self, direction: int = 0) -> np.ndarray:
        """(s, C * n_dof) complex rows: each blade's first-harmonic tip displacement in
        ``direction`` (0, 1, 2: x, y, z) from the unknowns (:func:`~bladedamp.hbm.peaks.first_harmonic_output`)."""
        blades = self.disk.model_blades
        nm, n_dof = blades[0].n_modes, np.asarray(self.coefficients).reshape(len(self.omega), self.basis.n_coeffs, -1).shape[-1]
        return np.array([first_harmonic_output(self.basis, n_dof, k * nm + np.arange(nm), b.shape("tip")[direction])
                         for k, b in enumerate(blades)])

    def model_system(self) -> HarmonicBalanceSystem:
        """The harmonic balance this response solved (its model's :meth:`hbm_system` at its basis);
        ValueError for a loaded result (no model)."""
        if self.disk is None:
            raise ValueError("this response has no model (a loaded result): compute it anew to differentiate it")
        return self.disk.hbm_system(self.basis.harmonics, self.basis.n_samples)

    def sensitivities(self, parameters, direction: int = 0) -> Sensitivities:
        """The derivatives of every point of the branch in the design-file keys ``parameters``
        (:meth:`DiskModel.parameter_derivatives`), at fixed frequency
        (:func:`~bladedamp.response.branch_sensitivities`): each blade's tip amplitude in
        ``direction`` and its derivatives, per unit of each key."""
        validation.integer("direction", direction, minimum=0, maximum=2)
        keys = tuple(str(p) for p in parameters)
        system = self.model_system()
        return branch_sensitivities(system, self.omega, self.coefficients, self.blade_outputs(direction),
                                    self.disk.parameter_derivatives(system, keys), keys,
                                    tuple(parameter_unit(k) for k in keys), [self.disk.parameter_value(k) for k in keys])

    def peak_sensitivities(self, parameters, direction: int = 0, blade: int | None = None) -> PeakSensitivities:
        """The derivatives of the resonance peak (the largest blade's largest tip amplitude in
        ``direction``, solved by the peak condition d|u|/dOmega = 0; ``blade`` k: blade k's own
        peak) in the design-file keys ``parameters``: d peak amplitude / dp [m per unit] and d peak
        frequency / dp [Hz per unit] (:func:`~bladedamp.response.solved_peak_sensitivities`).
        ValueError where the peak cannot be solved (at an end of the range, next to a fold)."""
        validation.integer("direction", direction, minimum=0, maximum=2)
        keys = tuple(str(p) for p in parameters)
        system = self.model_system()
        outputs = self.blade_outputs(direction)
        if blade is not None:
            blade = validation.integer("blade", blade, minimum=0, maximum=len(outputs) - 1)
            outputs = outputs[blade:blade + 1]
        result = solved_peak_sensitivities(system, self.omega, self.coefficients, outputs,
                                           self.disk.parameter_derivatives(system, keys), keys,
                                           tuple(parameter_unit(k) for k in keys),
                                           [self.disk.parameter_value(k) for k in keys])
        return result if blade is None else dataclasses.replace(result, blade=blade)

    @staticmethod
    def linear_energies(system: HarmonicBalanceSystem, branch) -> tuple[np.ndarray, np.ndarray]:
        """(excitation work (n,), viscous dissipation (n,)) per period [J] at the points of ``branch``."""
        return (np.array([system.excitation_work(x, w) for x, w in zip(branch.x, branch.omega)]),
                np.array([system.viscous_dissipation(x, w) for x, w in zip(branch.x, branch.omega)]))

    def energy_balance_error(self) -> np.ndarray:
        """|W_exc - W_visc - W_friction| / W_exc at every point (the whole model)."""
        return np.abs(self.excitation_work - self.viscous_dissipation - self.dissipated_energy) / np.abs(self.excitation_work)

    @property
    def blade_peak_amplitudes(self) -> np.ndarray:
        """(s,) peak first-harmonic tip amplitude u_x of each blade written out [m]: here (1,), the
        reference sector's :attr:`peak_amplitude` (a model of several blades overrides it)."""
        return np.atleast_1d(np.asarray(self.peak_amplitude, dtype=float))

    @property
    def blade_peak_frequencies_hz(self) -> np.ndarray:
        """(s,) frequency of each blade's peak [Hz], as :attr:`blade_peak_amplitudes`."""
        return np.atleast_1d(np.asarray(self.peak_frequency_hz, dtype=float))

    def finish_plot(self, ax, direction: int, measured=None, legend: dict | None = None):
        """The axes of a disk response's :meth:`plot` completed: labels, grid, legend, the status
        as the title of a failed response, and ``measured`` drawn beside it
        (:func:`bladedamp.measurement.draw_measurement`)."""
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel(f"tip amplitude u_{'xyz'[direction]} [mm]")
        ax.grid(True, alpha=0.3)
        ax.legend(**(legend or {}))
        if not self.success:
            ax.set_title(textwrap.fill(self.status_message, 100), fontsize=8)   # what it means, not the log
        if measured is not None:
            from .measurement import draw_measurement

            draw_measurement(ax, measured, model=self.disk)
        return ax
