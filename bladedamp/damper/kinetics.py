"""Damper kinetics: centrifugal preload (Eq. 26) and the static seating of the damper.

The dynamic equilibrium of the damper (Eq. 12) is not condensed here: the damper's six
rigid-body coordinates stay unknowns of the harmonic balance (see :mod:`bladedamp.disk`),
which keeps the Jacobian exact and lets the damper inertia be switched on or off.
"""
from __future__ import annotations

import numpy as np

from .. import validation
from .geometry import DamperGeometry


def centrifugal_force(mass: float, radius: float, f_hz: float | None = None, engine_order: int | None = None,
                      rotor_speed_hz: float | None = None) -> tuple[float, float]:
    """Centrifugal force on the damper and its derivative in the excitation frequency.

    F_CG = m R Omega_R^2 with Omega_R = Omega_E / EO (Eq. 3, 26): F = m R Omega_E^2 / EO^2, at
    the excitation frequency ``f_hz`` [Hz] (Omega_E = 2 pi f_hz). At EO = 0 the rotor speed
    cannot follow from the excitation frequency: give ``rotor_speed_hz`` [Hz, revolutions per
    second] explicitly (then dF/dOmega_E = 0). ``mass`` [kg], ``radius`` R [m].

    Returns (F [N], dF/dOmega_E [N s/rad]).
    """
    validation.nonnegative("damper mass", mass)
    validation.positive("damper radius R", radius)
    if engine_order is None:
        raise ValueError("engine_order must be given (an integer >= 0)")
    if rotor_speed_hz is not None:
        rotor_omega = 2 * np.pi * validation.positive("rotor_speed_hz", rotor_speed_hz)
        return mass * radius * rotor_omega ** 2, 0.0
    if engine_order == 0:
        raise ValueError("engine_order = 0 needs an explicit rotor_speed_hz (rotor revolutions per second, > 0): "
                         "Omega_R = Omega_E / EO is undefined")
    if f_hz is None:
        raise ValueError("give the excitation frequency f_hz [Hz]")
    omega_excitation = 2 * np.pi * float(f_hz)
    return mass * radius * omega_excitation ** 2 / engine_order ** 2, 2 * mass * radius * omega_excitation / engine_order ** 2


#: The retention spring's rotational stiffness per unit translational stiffness [m^2]: l^2 with
#: l = 10 mm, which turns N/m into N m/rad. The rotational spring is the translational one acting
#: at 10 mm from the damper's centre (the order of a damper's dimensions: the reference cylinder
#: is 2 mm in radius and 20 mm long), so a rotation theta is held as a displacement l theta is.
RETENTION_LEVER_ARM_SQUARED = 1e-4


def retention_stiffness(static_retention: float, normal_stiffness: float) -> np.ndarray:
    """The static retention spring of one damper: the (6, 6) stiffness on the static harmonic of
    its rigid-body coordinates (u_x, u_y, u_z [m], theta_x, theta_y, theta_z [rad]), diagonal,

        K_ret = r k_N diag(1, 1, 1, l^2, l^2, l^2),

    r = ``static_retention`` [-] (>= 0), k_N = ``normal_stiffness`` [N/m] (the sum of the normal
    contact stiffnesses of the damper's patches), l^2 = :data:`RETENTION_LEVER_ARM_SQUARED`
    [m^2]: N/m on the translations, N m/rad on the rotations.

    Frictionless seating leaves the damper's axial position (and a cylinder's roll angle)
    undetermined; this artificial spring fixes them. It must be weak against the contact (the
    response should be the weak-spring limit) but not vanishing: after slip onset only this
    spring balances the mean tangential force (frictional shakedown), which does not depend on
    the mean position (see ``TunedDisk.hbm_system``). The one definition for the tuned disk's
    sector and every damper of the mistuned assembly.
    """
    r = validation.nonnegative("static_retention (fraction of the normal contact stiffness)", static_retention)
    k_n = validation.nonnegative("normal_stiffness [N/m]", normal_stiffness)
    l2 = RETENTION_LEVER_ARM_SQUARED
    return r * k_n * np.diag([1, 1, 1, l2, l2, l2])


def seat(geometry: DamperGeometry, radial_force: float, tol: float = 1e-12, max_iter: int = 50, validate: bool = True):
    """Static seating of the damper under a radial force, frictionless, rigid platforms.

    Points with an initial gap (``ContactPatch.initial_gap``) touch only once the damper has
    moved by it: a damper that does not fit seats on part of its faces.

    Solves sum_c G_D,c^T f_c(G_D,c u_D) = (0, 0, F, 0, 0, 0) for the damper displacement
    u_D with the normal laws of both patches (lift-off included). Directions that no normal
    force fixes (the axial position, the cylinder's roll) are left at zero (least squares).

    Returns (u_D (6,), approach (2, P) per-point static approach [m], loads (2,) [N]).
    ``validate=False`` skips the check of ``radial_force`` (ValueError unless >= 0 [N]): for a
    caller whose force is non-negative by construction and that seats at every residual
    evaluation (a misfitting damper's static approach, :meth:`bladedamp.diskmodel.DamperPosition.approach_function`).
    """
    if validate:
        validation.nonnegative("radial_force", radial_force)
    G = geometry.G_D.reshape(2, 6, 6)
    if radial_force == 0:
        return np.zeros(6), -np.array([p.initial_gap for p in geometry.patches]), np.zeros(2)
    # start: uniform approach carrying the frictionless loads
    loads = geometry.frictionless_normal_loads(radial_force)
    approach = [geometry.patches[c].approach_for_load(loads[c]).mean() for c in range(2)]
    normals = geometry.frames[:, 2, :]
    A = np.array([[-normals[c, 0], -normals[c, 2]] for c in range(2)])
    dx, dz = np.linalg.solve(A, approach)
    u = np.array([dx, 0.0, dz, 0.0, 0.0, 0.0])
    load = np.array([0.0, 0.0, radial_force, 0.0, 0.0, 0.0])
    for _ in range(max_iter):
        R = -load.copy()
        K = np.zeros((6, 6))
        for c, patch in enumerate(geometry.patches):
            Bz = patch.point_map[:, 2, :]                    # (P, 6): u_zeta of each point
            a = -patch.initial_gap - Bz @ (G[c] @ u)
            N, dN = patch.normal_law.force(a, patch.weights)
            R += G[c].T @ (Bz.T @ (-N))
            K += G[c].T @ (Bz.T * dN) @ Bz @ G[c]
        du = -np.linalg.lstsq(K, R, rcond=None)[0]
        u = u + du
        if np.linalg.norm(du) <= tol * (np.linalg.norm(u) + 1e-30):
            break
    else:
        raise RuntimeError(f"static seating of the damper did not converge (radial force {radial_force} N)")
    approach = np.array([-p.initial_gap - p.point_map[:, 2, :] @ (G[c] @ u) for c, p in enumerate(geometry.patches)])
    loads = np.array([p.normal_law.force(approach[c], p.weights)[0].sum() for c, p in enumerate(geometry.patches)])
    return u, approach, loads


