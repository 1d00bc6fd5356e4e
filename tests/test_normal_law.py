"""The one normal contact law (bladedamp.contact.normal) against its closed form."""
import numpy as np
import pytest

from bladedamp.contact.laws import LinearNormalLaw, RoughnessNormalLaw, normal_law_parameters
from bladedamp.contact.normal import LAW_LINEAR, LAW_POWER, normal_force, normal_forces

K_N, N_REF, WEIGHT = 2.0e7, 40.0, 0.3


def closed_form(law, a):
    """N [N] and dN/da [N/m] of a point of WEIGHT, written out from the equations."""
    if isinstance(law, RoughnessNormalLaw):
        p, a_ref = law.exponent, law.exponent * law.reference_load / law.stiffness
        n = WEIGHT * law.reference_load * (np.maximum(a, 0) / a_ref) ** p
        return n, np.where(a > 0, WEIGHT * law.reference_load * p / a_ref * (np.maximum(a, 0) / a_ref) ** (p - 1), 0.0)
    return WEIGHT * law.stiffness * np.maximum(a, 0), np.where(a > 0, WEIGHT * law.stiffness, 0.0)


LAWS = [LinearNormalLaw(K_N)] + [RoughnessNormalLaw(K_N, N_REF, p) for p in (1.0, 1.5, 3.0)]


@pytest.mark.parametrize("law", LAWS, ids=["linear", "power1", "power1.5", "power3"])
def test_normal_law_is_its_closed_form(law):
    """N and dN/da of the scalar numba law, its array version and the law object equal the
    closed form to 1e-14 relative (the same few roundings and one pow: a few ulp) at approaches
    on both sides of a = 0 and at a = 0, where N = dN/da = 0 exactly (lift-off; for p = 1
    0**0 = 1 must not leak in); dN/da equals the central difference (N(a + h) - N(a - h)) / 2h,
    h = 1e-6 a_s (a_s = the approach scale: N_ref / k_N), for a >= 0.1 a_s to 1e-8 relative:
    truncation (h / a)^2 |(p - 1)(p - 2)| / 6 <= 1e-10 plus rounding eps N / (h N') =
    eps a / (p h) <= 2.2e-16 * 3 / 1e-6 < 1e-9."""
    kind, params = normal_law_parameters(law)
    assert kind == (LAW_LINEAR if isinstance(law, LinearNormalLaw) else LAW_POWER)
    a_s = N_REF / K_N
    a = a_s * np.concatenate([-np.logspace(-3, 1, 9), [0.0], np.logspace(-3, 0.5, 12)])
    n_ref, k_ref = closed_form(law, a)
    n_arr, k_arr = normal_forces(kind, params, WEIGHT, a)
    n_obj, k_obj = law.force(a, np.full_like(a, WEIGHT))
    n_sc = np.array([normal_force(kind, *params, WEIGHT, x)[0] for x in a])
    k_sc = np.array([normal_force(kind, *params, WEIGHT, x)[1] for x in a])
    for n, k in ((n_arr, k_arr), (n_obj, k_obj), (n_sc, k_sc)):
        np.testing.assert_allclose(n, n_ref, rtol=1e-14, atol=0)
        np.testing.assert_allclose(k, k_ref, rtol=1e-14, atol=0)
        assert np.all(n[a <= 0] == 0) and np.all(k[a <= 0] == 0) and np.all(n[a > 0] > 0)
    pressed = a >= 0.1 * a_s
    h = 1e-6 * a_s
    fd = (normal_forces(kind, params, WEIGHT, a + h)[0] - normal_forces(kind, params, WEIGHT, a - h)[0]) / (2 * h)
    np.testing.assert_allclose(k_arr[pressed], fd[pressed], rtol=1e-8, atol=0)


def test_normal_forces_broadcasts_and_checks_the_kind():
    """Per-point kinds and parameters (the time integration's layout) give each point its own
    law; an unknown kind or a parameter array without 3 entries is a ValueError."""
    lin, pw = LAWS[0], LAWS[2]
    a = np.array([[1e-6, -1e-6], [2e-6, 3e-6]])
    kinds = np.array([LAW_LINEAR, LAW_POWER])
    params = np.stack([lin.parameters, pw.parameters])
    n, k = normal_forces(kinds, params, WEIGHT, a)
    for j, law in enumerate((lin, pw)):
        n_j, k_j = closed_form(law, a[:, j])
        np.testing.assert_allclose(n[:, j], n_j, rtol=1e-14, atol=0)
        np.testing.assert_allclose(k[:, j], k_j, rtol=1e-14, atol=0)
    with pytest.raises(ValueError, match="law_kind"):
        normal_forces(2, lin.parameters, WEIGHT, a)
    with pytest.raises(ValueError, match="law_params"):
        normal_forces(LAW_LINEAR, [1.0, 0.0], WEIGHT, a)
