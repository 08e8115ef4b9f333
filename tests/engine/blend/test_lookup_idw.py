"""The lookup table's IDW on small hand-made tables, on the compiled and the numpy path alike.

Each expected value is computed here from Eq. 6.1–6.2 (``wₖ = (d₀/dₖ)^q`` over the ``k`` nearest
probes in range-scaled units), independently of the module; the tables are tiny, so these run in
milliseconds and reach every branch of ``LookupTable`` that the locomotion-set tests of
``test_lookup.py`` leave to a single 441-probe table. Both paths of ``_idw`` are checked
(``jit.use``): with numba installed the numpy one only runs when switched to, so without these a
mutant of it survives every test. Shown to fail (mutation run, docs/mutation.md): e.g. the weight
``(d₀/d)^q`` taken with ``q + 1``, the nearest-probe shortcut threshold, ``k`` nearest made all probes,
the slope term's sign.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from engine import jit
from engine.blend.lookup import LinearMapping, LookupTable, probe_grid

F = np.ndarray
PATHS = [False, True] if jit.AVAILABLE else [False]


@pytest.fixture(params=PATHS, ids=lambda c: "compiled" if c else "numpy")
def path(request: pytest.FixtureRequest) -> Iterator[bool]:
    with jit.use(request.param):
        yield request.param


def idw_by_hand(probes: F, scaled: F, x: F, k: int, power: float, slopes: F | None = None) -> F:
    """Eq. 6.1–6.2 over the k nearest probes, written as loops (and the slope term of ``query``)."""
    d = np.sqrt(((scaled - x) ** 2).sum(axis=1))
    order = np.argsort(d, kind="stable")[:k]
    if d[order[0]] <= 1e-12:
        return np.clip(probes[order[0]], 0.0, 1.0)
    num, den = np.zeros(probes.shape[1]), 0.0
    for j in order:
        w = (d[order[0]] / d[j]) ** power
        v = probes[j] + (0.0 if slopes is None else slopes[j] @ (x - scaled[j]))
        num, den = num + w * v, den + w
    return np.clip(num / den, 0.0, 1.0)


def table_1d(power: float = 7.0, neighbours: int = 16) -> LookupTable:
    """Four probes on one axis measuring a non-linear property (0, 1, 2.5, 4 m/s)."""
    probes = np.array([[0.0], [1 / 3], [2 / 3], [1.0]])
    return LookupTable(probes, np.array([[0.0], [1.0], [2.5], [4.0]]), ("speed",), power=power, neighbours=neighbours)


def test_range_scaling_of_the_properties() -> None:
    t = LookupTable(
        np.array([[0.0, 0.0], [1.0, 1.0], [0.5, 0.2]]),
        np.array([[1.0, 5.0], [3.0, 5.0], [2.0, 5.0]]),
        ("speed", "height"),
    )
    np.testing.assert_array_equal(t.offset, [1.0, 5.0])
    np.testing.assert_array_equal(t.scale, [2.0, 1.0])  # a constant property keeps scale 1, not 0
    np.testing.assert_allclose(t._scaled([2.0, 6.0]), [0.5, 1.0])
    assert t.slopes is None and t.feasible is None  # no grid: plain IDW, no border
    assert not t.probes.flags.writeable and not t.values.flags.writeable


@pytest.mark.parametrize("power,k", [(7.0, 16), (2.0, 4), (3.0, 2), (1.5, 1)])
def test_plain_idw_matches_the_formula(path: bool, power: float, k: int) -> None:
    t = table_1d(power=power, neighbours=k)
    u = np.array([[0.3], [1.7], [2.0], [3.99], [0.01]])
    x = (u - 0.0) / 4.0
    want = np.stack([idw_by_hand(t.probes, t.values / 4.0, xi, min(k, 4), power) for xi in x])
    np.testing.assert_allclose(t.query(u), want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        t.query_brute(u), np.stack([idw_by_hand(t.probes, t.values / 4.0, xi, 4, power) for xi in x]), atol=1e-12
    )


def test_only_the_k_nearest_probes_count(path: bool) -> None:
    """A probe beyond the k nearest changes nothing; brought into the k it does."""
    near = table_1d(power=1.0, neighbours=2)
    u = np.array([[1.2]])
    two = idw_by_hand(near.probes, near.values / 4.0, u[0] / 4.0, 2, 1.0)
    three = idw_by_hand(near.probes, near.values / 4.0, u[0] / 4.0, 3, 1.0)
    assert abs(two[0] - three[0]) > 1e-3
    np.testing.assert_allclose(near.query(u)[0], two, atol=1e-12)
    np.testing.assert_allclose(table_1d(power=1.0, neighbours=3).query(u)[0], three, atol=1e-12)


def test_a_request_on_a_probe_returns_that_probe(path: bool) -> None:
    t = table_1d(power=2.0)
    np.testing.assert_array_equal(t.query(t.values), t.probes)
    # 1e-12 scaled units off a probe still counts as on it; 1e-9 off is blended (by a hair)
    assert t.query(np.array([1.0 + 4e-12]))[0] == t.probes[1, 0]
    assert t.query(np.array([1.0 + 4e-7]))[0] != t.probes[1, 0]


def test_the_answer_is_clamped_to_the_blend_space(path: bool) -> None:
    """Probe slopes extrapolate past the grid's edge; the answer stays inside [0, 1]."""
    t = LookupTable(np.array([[0.0], [0.5], [1.0]]), np.array([[0.0], [1.0], [2.0]]), ("speed",), (3,), power=2.0)
    np.testing.assert_array_equal(t.query(np.array([[-1.0], [3.0]])), [[0.0], [1.0]])
    np.testing.assert_allclose(t.query(np.array([[0.5], [1.5]])), [[0.25], [0.75]], atol=1e-12)


def test_probe_slopes_reproduce_a_linear_measurement(path: bool) -> None:
    """u = A p + b measured on a grid: with slopes the map inverts it exactly, without it does not."""
    probes, shape = probe_grid(2, (4, 5))
    a = np.array([[2.0, 0.3], [-0.2, 0.5]])
    values = probes @ a.T + [0.1, 0.4]
    t = LookupTable(probes, values, ("speed", "height"), shape, power=3.0, neighbours=6)
    plain = LookupTable(probes, values, ("speed", "height"), shape, power=3.0, neighbours=6, gradients=False)
    assert plain.slopes is None and t.slopes is not None and t.slopes.shape == (20, 2, 2)
    # the slope of scaled u -> p is the inverse of A scaled by the property ranges
    np.testing.assert_allclose(t.slopes[7], np.linalg.inv(a / t.scale[:, None]), atol=1e-9)
    rng = np.random.default_rng(3)
    p = rng.uniform(0.05, 0.95, (25, 2))
    u = p @ a.T + [0.1, 0.4]
    np.testing.assert_allclose(t.query(u), p, atol=1e-9)
    x = (u - t.offset) / t.scale
    want = np.stack([idw_by_hand(t.probes, t._scaled_values, xi, 6, 3.0) for xi in x])
    np.testing.assert_allclose(plain.query(u), want, atol=1e-12)
    assert np.abs(plain.query(u) - p).max() > 0.01


def test_slopes_drop_out_where_the_measurement_folds() -> None:
    """A property that does not change along an axis has no inverse there: those probes get zero slope."""
    probes, shape = probe_grid(2, 3)
    flat = np.stack([probes[:, 0], np.full(9, 0.5)], axis=-1)  # height constant
    t = LookupTable(probes, flat, ("speed", "height"), shape)
    assert t.slopes is not None and not t.slopes.any()
    fold = np.stack([probes[:, 0], probes[:, 0] + 1e-5 * probes[:, 1]], axis=-1)  # nearly singular
    fold_slopes = LookupTable(probes, fold, ("speed", "height"), shape).slopes
    assert fold_slopes is not None and not fold_slopes.any()
    fine = np.stack([probes[:, 0], probes[:, 0] + 0.5 * probes[:, 1]], axis=-1)
    fine_slopes = LookupTable(probes, fine, ("speed", "height"), shape).slopes
    assert fine_slopes is not None
    np.testing.assert_allclose(fine_slopes, np.broadcast_to([[1.0, 0.0], [-2.0, 3.0]], (9, 2, 2)), atol=1e-9)
    one = LookupTable(probes, probes[:, :1] * 2.0, ("speed",), shape)  # fewer properties than axes
    assert one.slopes is not None and one.slopes.shape == (9, 2, 1) and not one.slopes.any() and one.feasible is None


def test_bad_tables_and_requests_name_what_is_wrong() -> None:
    p, u = np.array([[0.0], [1.0]]), np.array([[0.0], [1.0]])
    with pytest.raises(ValueError, match=r"^values have 1 columns but 2 property names$"):
        LookupTable(p, u, ("a", "b"))
    with pytest.raises(ValueError, match="one row per probe"):
        LookupTable(p[:0], u[:0], ("a",))
    with pytest.raises(ValueError, match="one row per probe"):
        LookupTable(p[:, 0], u, ("a",))
    with pytest.raises(ValueError, match="one row per probe"):
        LookupTable(p, u[:, 0], ("a",))
    for bad in (np.array([[0.0], [np.inf]]), np.array([[np.nan], [1.0]])):
        with pytest.raises(ValueError, match="^probes or measured values contain NaN or infinite values$"):
            LookupTable(bad, u, ("a",))
        with pytest.raises(ValueError, match="^probes or measured values contain NaN or infinite values$"):
            LookupTable(p, bad, ("a",))
    with pytest.raises(ValueError, match="^the IDW power q must be positive$"):
        LookupTable(p, u, ("a",), power=-1.0)
    assert LookupTable(p, u, ("a",), power=1e-3).power == 1e-3
    t = LookupTable(p, np.array([[0.0, 2.0], [1.0, 3.0]]), ("speed", "height"))
    with pytest.raises(ValueError, match=r"^a request needs 2 values \(speed, height\), got \(3,\)$"):
        t.query([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="^request contains NaN or infinite values$"):
        t.query([np.inf, 2.0])
    with pytest.raises(ValueError, match="^this table has no feasible border$"):
        t.extent_many(np.zeros((1, 2)), 0)
    assert t.extent([0.5, 2.5], 1) is None


def test_probe_grid_orders_points_c_style_and_refuses_thin_grids() -> None:
    pts, shape = probe_grid(2, (2, 3))
    assert shape == (2, 3)
    np.testing.assert_allclose(pts, np.array([[0, 0], [0, 0.5], [0, 1], [1, 0], [1, 0.5], [1, 1]]))
    assert probe_grid(3, np.int64(2))[1] == (2, 2, 2)  # type: ignore[arg-type]  # numpy integers are accepted at run time
    for dims, density in ((2, (2,)), (2, (2, 1)), (1, 1)):
        with pytest.raises(ValueError, match=f"on each of the {dims} axes"):
            probe_grid(dims, density)


def test_measure_builds_the_table_from_the_grid() -> None:
    seen: list[F] = []

    def measure(p: F) -> F:
        seen.append(p)
        return p * [2.0, 1.0] + [0.0, 0.5]

    t = LookupTable.measure(2, 3, measure, ["speed", "height"], power=5.0)
    assert len(seen) == 1 and seen[0].shape == (9, 2)
    assert t.grid_shape == (3, 3) and t.properties == ("speed", "height") and t.power == 5.0
    assert t.feasible is not None and t.slopes is not None


def test_linear_mapping_maps_its_two_points_and_clamps() -> None:
    m = LinearMapping(1.0, 3.0, 10.0, 20.0)
    np.testing.assert_allclose(m([0.0, 1.0, 1.5, 3.0, 9.0]), [10.0, 10.0, 12.5, 20.0, 20.0])
    down = LinearMapping(3.0, 1.0, 10.0, 20.0)  # a falling map: a ↦ lo still
    np.testing.assert_allclose(down([3.0, 2.0, 1.0]), [10.0, 15.0, 20.0])
    with pytest.raises(ValueError, match="^a linear mapping needs two distinct input values$"):
        LinearMapping(2.0, 2.0, 0.0, 1.0)


def square_table(rate_property: int | None = 0) -> LookupTable:
    """A 2-D grid measuring speed = 2·p₀ (0..2 m/s) and height = 0.5 + 0.4·p₁: feasible set [0,2]×[0.5,0.9]."""
    probes, shape = probe_grid(2, 5)
    values = np.stack([2.0 * probes[:, 0], 0.5 + 0.4 * probes[:, 1]], axis=-1)
    return LookupTable(probes, values, ("speed", "height"), shape, rate_property=rate_property)


def test_projection_prefers_changing_the_speed_within_the_rate_limit() -> None:
    t = square_table()
    u, inside = t.project([1.0, 0.7])
    assert inside and np.allclose(u, [1.0, 0.7])
    u, inside = t.project([3.0, 0.7])  # too fast: keep the height, play sped up
    assert not inside and np.allclose(u, [2.0, 0.7], atol=1e-9)
    u, inside = t.project([1.0, 0.2])  # too low: crouch as low as it goes at this speed
    assert not inside and np.allclose(u, [1.0, 0.5], atol=1e-9)
    u, inside = t.project([7.0, 0.7])  # 3.5x: beyond max_rate, so slowing is the last resort
    assert not inside and np.allclose(u, [2.0, 0.7], atol=1e-9)
    res = t.resolve([3.0, 0.7])
    assert not res.inside and res.rate == pytest.approx(1.5) and np.allclose(res.point, [1.0, 0.5])
    assert t.resolve([7.0, 0.7]).rate == pytest.approx(3.0)  # clamped to max_rate
    kept = t.resolve([1.0, 0.7])
    assert kept.inside and kept.rate == 1.0 and np.allclose(kept.point, [0.5, 0.5])
    nearest = square_table(rate_property=None)
    u, inside = nearest.project([3.0, 0.7])
    assert not inside and np.allclose(u, [2.0, 0.7], atol=1e-9)
    assert nearest.resolve([3.0, 0.7]).rate == 1.0  # no rate property: never sped up


def test_extent_and_batched_resolution_agree_with_one_by_one() -> None:
    t = square_table()
    lo, hi = t.extent([1.0, 0.7], 1)  # type: ignore[misc]  # inside the set: a range
    assert lo == pytest.approx(0.5) and hi == pytest.approx(0.9)
    assert t.extent([5.0, 0.7], 1) is None  # a vertical line beyond the fastest speed misses
    reqs = np.array([[1.0, 0.7], [3.0, 0.7], [1.0, 0.2], [0.4, 0.95]])
    points, feasible, inside, rate = t.resolve_many(reqs)
    assert inside.tolist() == [True, False, False, False]
    for i, r in enumerate(reqs):
        one = t.resolve(r)
        np.testing.assert_allclose(points[i], one.point, atol=1e-12)
        np.testing.assert_allclose(feasible[i], one.feasible, atol=1e-12)
        assert rate[i] == pytest.approx(one.rate)
    lo_b, hi_b = t.extent_many(np.array([[1.0, 0.7], [5.0, 0.7]]), 1)
    assert lo_b[0] == pytest.approx(0.5) and hi_b[0] == pytest.approx(0.9) and np.isnan(lo_b[1])
    free = LookupTable(t.probes, t.values, t.properties)  # no border: every request is played as asked
    points, feasible, inside, rate = free.resolve_many(reqs)
    assert inside.all() and (rate == 1.0).all() and np.array_equal(feasible, reqs)
    res = free.resolve(reqs[1])
    assert res.inside and res.rate == 1.0 and np.array_equal(res.feasible, reqs[1])
