"""Anderson acceleration of a fixed point (:mod:`ngcontact.solvers.anderson`)."""
import numpy as np
import pytest

from ngcontact.solvers.anderson import Anderson


def _steps(depth, tol=1e-10):
    rng = np.random.default_rng(3)
    Q, _ = np.linalg.qr(rng.standard_normal((40, 40)))
    # a contraction by 0.97 through a few slow modes, the rest fast (the friction threshold's kind)
    A = Q @ np.diag(np.concatenate([[0.97, 0.95, -0.9], np.linspace(-0.3, 0.3, 37)])) @ Q.T
    c = rng.standard_normal(40)
    exact = np.linalg.solve(np.eye(40) - A, c)
    acc, x = Anderson(depth, lower=None), np.zeros(40)
    for k in range(1, 2000):
        x = acc.next(x, A @ x + c)
        if np.max(np.abs(x - exact)) <= tol:
            return k
    return 2000


def test_anderson_reaches_a_linear_fixed_point_in_far_fewer_steps_than_the_plain_iteration():
    plain, accelerated = _steps(0), _steps(5)
    assert plain > 300
    assert accelerated < plain / 4, (accelerated, plain)


def test_the_iterate_respects_its_lower_bound_and_the_first_step_is_the_image():
    acc = Anderson(3, lower=0.0)
    first = acc.next(np.array([1.0, 2.0]), np.array([0.5, -1.0]))
    assert first.tolist() == [0.5, 0.0]
    second = acc.next(first, np.array([-3.0, 4.0]))
    assert np.all(second >= 0.0)


def test_a_negative_depth_is_refused():
    with pytest.raises(ValueError, match="depth"):
        Anderson(-1)
