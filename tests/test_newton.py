"""The one Newton of the engine (bladedamp.hbm.newton): closed-form roots, the line search, the
result type, the equilibrated solver."""
import numpy as np
import pytest

from bladedamp.hbm.newton import LineSearch, NewtonResult, equilibrated, newton


def arctan(x, p, jacobian=True):
    """R(x) = atan(x) - p: one root, x = tan(p); plain Newton diverges from |x0| > 1.3917."""
    return np.arctan(x) - p, np.array([[1.0 / (1.0 + x[0] ** 2)]])


def test_plain_newton_finds_the_closed_form_root_and_returns_one_result():
    r = newton(arctan, np.array([0.5]), 0.3, 1.0, 1.0, tol=1e-12)
    assert isinstance(r, NewtonResult) and r.converged
    assert r.x[0] == pytest.approx(np.tan(0.3), rel=1e-12)
    assert 2 <= r.iterations <= 8 and r.residual_norm < 1e-12
    # the factorisation of the last iterate evaluated: solve(b) = J^-1 b with J = 1 / (1 + x^2)
    x_last = r.x[0] - r.step[0]
    assert r.solve(np.array([1.0]))[0] == pytest.approx(1 + x_last ** 2, rel=1e-12)


def test_line_search_reaches_the_root_where_plain_newton_diverges():
    x0 = np.array([3.0])                        # |x0| > 1.3917: plain Newton's iterates grow without end
    plain = newton(arctan, x0, 0.0, 1.0, 1.0, tol=1e-12, max_iter=3)     # 3 -> -9.5 -> 124 -> -2.4e4
    assert not plain.converged and abs(plain.x[0]) > 1e4
    damped = newton(arctan, x0, 0.0, 1.0, 1.0, tol=1e-12, max_iter=30, line_search=LineSearch())
    assert damped.converged and abs(damped.x[0]) < 1e-12


def test_two_unknowns_and_the_third_item_of_the_residual():
    """x^2 + y^2 = 4 and x = y (root (sqrt 2, sqrt 2)); the residual's third item is dR/dp for
    R = (x^2 + y^2 - p, x - y): dR/dp = (-1, 0), kept on convergence."""
    def fun(z, p, jacobian=True):
        x, y = z
        return (np.array([x * x + y * y - p, x - y]), np.array([[2 * x, 2 * y], [1.0, -1.0]]),
                np.array([-1.0, 0.0]))
    r = newton(fun, np.array([1.0, 2.0]), 4.0, 1.0, 4.0, tol=1e-13)
    assert r.converged
    np.testing.assert_allclose(r.x, [np.sqrt(2), np.sqrt(2)], rtol=1e-12)
    np.testing.assert_array_equal(r.dR_domega, [-1.0, 0.0])
    # tangent dz/dp = -J^-1 dR/dp against the closed form: x = y = sqrt(p / 2), dx/dp = 1 / (4 x)
    np.testing.assert_allclose(-r.solve(r.dR_domega), 1 / (4 * np.sqrt(2)), rtol=1e-6)


def test_equilibrated_solver_equals_the_plain_solve():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(4, 4)) * np.array([1e6, 1.0, 1e-3, 1.0])[:, None]
    b = rng.normal(size=4)
    solve = equilibrated(np.array([1e-6, 1.0, 1e3, 2.0]), np.array([1e6, 1e6, 1.0, 1.0]))(J)
    np.testing.assert_allclose(solve(b), np.linalg.solve(J, b), rtol=1e-10)


def test_admissible_points_and_failures_are_reported():
    # R = x^2 - 1 from x0 = -3 goes to the root -1, which is not admissible (x > 0)
    fun = lambda x, p, jacobian=True: (x ** 2 - 1, np.diag(2 * x))      # noqa: E731
    r = newton(fun, np.array([-3.0]), None, 1.0, 1.0, admissible=lambda x: x[0] > 0)
    assert not r.converged and r.x[0] == pytest.approx(-1.0)
    # a singular Jacobian: not converged, at the first iteration
    r = newton(fun, np.array([0.0]), None, 1.0, 1.0)
    assert not r.converged and r.iterations == 1 and r.solve is None
    # a residual that is not finite
    r = newton(lambda x, p, jacobian=True: (x * np.nan, np.eye(1)), np.array([1.0]), None, 1.0, 1.0)
    assert not r.converged and r.residual_norm == np.inf


def test_the_norm_is_checked():
    with pytest.raises(ValueError, match="norm"):
        newton(arctan, np.array([0.5]), 0.3, 1.0, 1.0, norm=1)


def test_the_evaluated_iterate_is_one_step_before_the_result():
    """On convergence ``evaluated`` is the iterate whose factorisation ``solve`` is: x = evaluated
    + step, and solve(R(evaluated)) = -step."""
    def fun(x, p):
        return np.array([x[0] ** 3 - p, x[1] - 2.0]), np.array([[3 * x[0] ** 2, 0.0], [0.0, 1.0]]), np.zeros(2)

    r = newton(fun, np.array([1.0, 0.0]), 8.0, 1.0, 1.0, tol=1e-12)
    assert r.converged and np.array_equal(r.evaluated + r.step, r.x)
    assert np.array_equal(-r.solve(fun(r.evaluated, 8.0)[0]), r.step)
