"""The normal contact law of one point, written once: N(a) and dN/da from the local approach a.

Every evaluation of a normal law goes through :func:`normal_force` (numba, one point): the
fused AFT kernels of :mod:`bladedamp.contact.point`, the explicit time integration of
:mod:`bladedamp.timedomain` (both call it from their own numba kernels) and, through
:func:`normal_forces` (the same function over arrays), the law classes of
:mod:`bladedamp.contact.laws` and the static seatings.

A law is a kind code and three parameters (p0, p1, p2) [``normal_law_parameters`` in
:mod:`bladedamp.contact.laws` gives them for a law object]; a point carries the share
``weight`` [-] of its contact area (weights sum to 1 over a patch). With the approach
a [m] (positive when the bodies press into each other; a = offset - u_zeta, u_zeta the
normal relative displacement):

* ``LAW_LINEAR``, (k_N, -, -):       N = w k_N a,                dN/da = w k_N
* ``LAW_POWER``,  (N_ref, a_ref, p): N = w N_ref (a / a_ref)^p,  dN/da = w N_ref p / a_ref (a / a_ref)^(p - 1)

and N = dN/da = 0 when a is not positive (lift-off; also for a NaN approach). Units: N [N],
dN/da [N/m]. A caller working in u_zeta takes dN/du_zeta = -dN/da.
"""
from __future__ import annotations

import numpy as np
from numba import guvectorize, njit

LAW_LINEAR, LAW_POWER = 0, 1
"""Kind codes of the normal laws (:func:`normal_force`)."""


# numba's on-disk cache of a kernel is keyed on its own source file: after editing this
# function, clear the cache (or touch contact/point.py and timedomain.py), or their cached
# kernels keep the old law.
@njit(cache=True)
def normal_force(law_kind, p0, p1, p2, weight, approach):
    """(N [N], dN/da [N/m]) of one point: ``law_kind`` LAW_LINEAR (p0 = k_N [N/m]) or
    LAW_POWER (p0 = N_ref [N], p1 = a_ref [m], p2 = p [-]), ``weight`` [-], ``approach`` a [m];
    the equations in the module docstring. Any kind other than LAW_LINEAR is the power law
    (checked by :func:`normal_forces` and ``normal_law_parameters``, not here)."""
    if not approach > 0.0:
        return 0.0, 0.0
    if law_kind == LAW_LINEAR:
        k = p0 * weight
        return k * approach, k
    ratio = approach / p1
    n_ref = p0 * weight
    return n_ref * ratio ** p2, n_ref * p2 / p1 * ratio ** (p2 - 1.0)


def _normal_force_into(kind, p0, p1, p2, weight, approach, normal, stiffness):
    normal[0], stiffness[0] = normal_force(kind, p0, p1, p2, weight, approach)


_GUFUNC = []


def _normal_force_gufunc():
    """:func:`normal_force` as a numpy gufunc (numpy broadcasts), built at the first call, not
    at import (building it starts numba's compiler, which importing the package does not)."""
    if not _GUFUNC:
        _GUFUNC.append(guvectorize(["void(int64, float64, float64, float64, float64, float64, float64[:], float64[:])"],
                                   "(),(),(),(),(),()->(),()", cache=True)(_normal_force_into))
    return _GUFUNC[0]


def normal_forces(law_kind, law_params, weight, approach):
    """:func:`normal_force` over arrays: (N [N], dN/da [N/m]), each of the broadcast shape of
    ``law_kind`` (int, LAW_LINEAR or LAW_POWER), ``law_params`` (..., 3) (p0, p1, p2 on the last
    axis), ``weight`` [-] and ``approach`` a [m]."""
    if isinstance(law_kind, (int, np.integer)):         # one law (the law classes): no array test
        kind = law_kind
        known = law_kind in (LAW_LINEAR, LAW_POWER)
    else:
        kind = np.asarray(law_kind, dtype=np.int64)
        known = np.all((kind == LAW_LINEAR) | (kind == LAW_POWER))
    if not known:
        raise ValueError(f"law_kind must be LAW_LINEAR ({LAW_LINEAR}) or LAW_POWER ({LAW_POWER})")
    params = np.asarray(law_params, dtype=float)
    if params.ndim == 0 or params.shape[-1] != 3:
        raise ValueError(f"law_params must have 3 entries on its last axis (got shape {params.shape})")
    return _normal_force_gufunc()(kind, params[..., 0], params[..., 1], params[..., 2], weight, approach)
