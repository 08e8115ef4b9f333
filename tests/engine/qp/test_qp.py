"""The shared QP core: answers checked against an independent KKT solve, failures reported, lifted form equal."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.qp import DenseQP, LeastSquaresQP, QPStatus


def _random_problem(rng: np.random.Generator, n: int, m: int):  # type: ignore[no-untyped-def]
    a = rng.normal(size=(n, n))
    h = a @ a.T + n * np.eye(n)
    return h, rng.normal(size=n), rng.normal(size=(m, n)), rng.normal(size=m)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 12), st.integers(1, 4))
def test_equality_constrained_answer_is_the_kkt_solution(seed, n, m):
    rng = np.random.default_rng(seed)
    h, f, a, b = _random_problem(rng, n, min(m, n - 1))
    kkt = np.block([[h, a.T], [a, np.zeros((a.shape[0], a.shape[0]))]])
    ref = np.linalg.solve(kkt, np.concatenate([-f, b]))[:n]
    res = DenseQP(n, a.shape[0]).solve(h, f, a=a, blo=b, bhi=b)
    assert res.status is QPStatus.SOLVED
    assert np.allclose(res.x, ref, atol=1e-8)


def test_bounds_hold_and_warm_start_repeats_the_answer():
    rng = np.random.default_rng(3)
    h, f, a, _ = _random_problem(rng, 8, 2)
    qp = DenseQP(8, 2)
    lo, hi = -0.1 * np.ones(8), 0.1 * np.ones(8)
    first = qp.solve(h, 10 * f, lo, hi, a, -np.ones(2), np.ones(2))
    again = qp.solve(h, 10 * f, lo, hi, a, -np.ones(2), np.ones(2))
    assert first.ok and np.all(first.x >= lo - 1e-12) and np.all(first.x <= hi + 1e-12)
    assert np.any(np.isclose(np.abs(first.x), 0.1))  # some bounds are active
    assert np.allclose(first.x, again.x, atol=1e-12) and again.iterations <= first.iterations


def test_failures_are_reported_not_raised():
    qp = DenseQP(2, 1)
    h = np.eye(2)
    infeasible = qp.solve(h, np.zeros(2), [-1, -1], [1, 1], [[1.0, 1.0]], [5.0], [6.0])
    assert infeasible.status is QPStatus.INFEASIBLE and infeasible.x is None
    crossed = qp.solve(h, np.zeros(2), [1, 0], [0, 1], [[1.0, 0.0]], [0.0], [1.0])
    assert crossed.status is QPStatus.INFEASIBLE
    nan = qp.solve(h, [np.nan, 0.0], None, None, [[1.0, 0.0]], [0.0], [1.0])
    assert nan.status is QPStatus.FAILED
    # An iteration cap too small for the active set the answer needs.
    rng = np.random.default_rng(0)
    hh, ff, _, _ = _random_problem(rng, 30, 1)
    capped = DenseQP(30, 0, iter_limit=2).solve(hh, 100 * ff, -0.01 * np.ones(30), 0.01 * np.ones(30))
    assert capped.status is QPStatus.ITERATION_LIMIT and not capped.ok
    assert qp.solve(h, np.ones(2), [-1, -1], [1, 1], [[1.0, 1.0]], [-1.0], [1.0]).ok  # usable again after failures


def test_lifted_least_squares_equals_the_dense_form():
    rng = np.random.default_rng(7)
    n, r, m = 40, 3, 6
    d = rng.uniform(0.1, 2.0, n)
    g, b = rng.normal(size=(r, n)), rng.normal(size=r)
    a, c = rng.normal(size=(m, n)), rng.normal(size=m) * 0.1
    e = rng.normal(size=n) * 0.1
    w = 50.0
    lo, hi = -0.2 * np.ones(n), 0.2 * np.ones(n)
    lifted = LeastSquaresQP(n, r, m).solve(d, g, b, w, lo, hi, a, c - 0.01, c + 0.01, linear=e)
    dense = DenseQP(n, m).solve(2 * (w * g.T @ g + np.diag(d)), -2 * w * g.T @ b + e, lo, hi, a, c - 0.01, c + 0.01)
    assert lifted.ok and dense.ok
    assert np.allclose(lifted.x, dense.x, atol=1e-7)
