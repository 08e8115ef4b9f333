"""The lookup table's public calls on the inputs their callers really pass: one request as a 1-D
vector, integer requests, a feasible set whose bounds move with the speed.

Small hand-made tables (milliseconds each), so the expected answers are worked out here. Shown to
fail by mutation (docs/mutation.md, sixth round): ``query_brute`` sorting along ``axis=+1`` (a
single request has one axis), ``extent``/``extent_many`` dividing by the property's range instead of
multiplying, ``extent`` taking the second hit or the one before last, ``resolve_many`` keeping an
integer request's dtype (a projected request is truncated to whole numbers) or answering float
``inside`` flags, ``resolve`` without a border answering no blend point or keeping an integer request, the
playback rate of a request slower than the slowest gait not slowed (``want · got > 1``, ``abs(got) > 1.000001``),
not clamped below (``clip(…, None, …)``, ``2 / max_rate``), or a standing or backwards request given one
(``or``, ``want · got >= 0``); the projection's cost taken on ``c + x``, with the speed change's cost
replaced or divided by ``keep_cost``, every speed change penalised (``or``), ``abs(want + got)`` for ``abs(want - got)``, the penalty's bounds
``want · got > 1``, ``max_rate <= u/u'``, ``2 / max_rate``, ``u·u'`` for ``u/u'``, the speed read back
without its offset, the penalty replacing the cost (``cost = 1e3``), and the refusal's message; the
probe slopes' fold test made absolute (``1e-3 / s₀``, ``max(s₀, 1.000000000001)``: a nearly flat but
well-conditioned stretch loses its slope); the probes kept as integers.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.blend.lookup import LookupTable, probe_grid

F = np.ndarray


def sheared_table() -> LookupTable:
    """speed = 2·p₀ (0..2 m/s), height = 0.5 + 0.2·p₀ + 0.4·p₁: at speed s the hips go from
    0.5 + 0.1·s to 0.9 + 0.1·s, so the lowest height is not the table's lowest."""
    probes, shape = probe_grid(2, 5)
    values = np.stack([2.0 * probes[:, 0], 0.5 + 0.2 * probes[:, 0] + 0.4 * probes[:, 1]], axis=-1)
    return LookupTable(probes, values, ("speed", "height"), shape)


def test_one_request_as_a_vector_gives_one_blend_point() -> None:
    """``query_brute`` and ``query`` take a single request ``[M]`` as well as a batch ``[B, M]``."""
    t = sheared_table()
    full = LookupTable(t.probes, t.values, t.properties, t.grid_shape, neighbours=len(t.probes))
    u = np.array([0.9, 0.75])
    one = t.query_brute(u)
    assert one.shape == (2,)
    np.testing.assert_allclose(one, full.query(u), atol=1e-12)
    np.testing.assert_allclose(one, t.query_brute(u[None])[0], atol=1e-12)
    np.testing.assert_allclose(one, [0.45, (0.75 - 0.5 - 0.09) / 0.4], atol=1e-9)  # the map is linear


@pytest.mark.parametrize("speed", [0.9, 1.3])
def test_extent_is_the_height_range_at_that_speed(speed: float) -> None:
    """At a speed between grid lines the vertical line crosses the border twice: the range is
    ``[0.5 + 0.1·s, 0.9 + 0.1·s]`` in metres, whatever the height asked."""
    t = sheared_table()
    for height in (0.55, 0.7, 1.2):
        got = t.extent([speed, height], 1)
        assert got is not None
        assert got == pytest.approx((0.5 + 0.1 * speed, 0.9 + 0.1 * speed), abs=1e-9)
    speed_range = t.extent([1.0, 0.7], 0)  # height 0.7: speed from 0 up to where 0.5 + 0.1·s = 0.7
    assert speed_range == pytest.approx((0.0, 2.0), abs=1e-9)
    assert t.extent([1.0, 1.0], 0) == pytest.approx((1.0, 2.0), abs=1e-9)  # 0.9 + 0.1·s ≥ 1 from s = 1
    lo, hi = t.extent_many(np.array([[speed, 0.7], [3.0, 0.7]]), 1)
    np.testing.assert_allclose([lo[0], hi[0]], [0.5 + 0.1 * speed, 0.9 + 0.1 * speed], atol=1e-9)
    assert np.isnan(lo[1]) and np.isnan(hi[1])


def test_integer_requests_resolve_like_float_ones() -> None:
    """A batch of whole-number requests (``[[3, 1]]``: 3 m/s, 1 m) is projected to the same point,
    with fractions, as the float request; nothing is rounded to the requests' integer dtype."""
    t = sheared_table()
    ints = np.array([[3, 1], [2, 1], [0, 0]])
    points, feasible, inside, rate = t.resolve_many(ints)
    assert inside.tolist() == [False, True, False]
    for i, r in enumerate(ints.astype(np.float64)):
        one = t.resolve(r)
        np.testing.assert_allclose(feasible[i], one.feasible, atol=1e-12)
        np.testing.assert_allclose(points[i], one.point, atol=1e-12)
        assert rate[i] == pytest.approx(one.rate)
    assert feasible[0, 1] == pytest.approx(1.0) and feasible[0, 0] == pytest.approx(2.0)  # kept 1 m, sped up
    assert feasible[2, 1] == pytest.approx(0.5)  # 0 m is below any crouch: as low as it goes, at 0 m/s
    assert feasible.dtype == np.float64 and points.dtype == np.float64


def test_inside_flags_are_booleans_with_and_without_a_border() -> None:
    """``inside`` is a boolean mask (callers index with it and negate it with ``~``)."""
    t = sheared_table()
    free = LookupTable(t.probes, t.values, t.properties)
    reqs = np.array([[1.0, 0.7], [3.0, 0.7]])
    for table in (t, free):
        _, _, inside, _ = table.resolve_many(reqs)
        assert inside.dtype == np.bool_
        assert (~inside).sum() == (0 if table is free else 1)


def test_a_table_without_a_border_plays_each_request_as_asked() -> None:
    """No border: ``resolve`` answers the blend point of the request itself, at rate 1, and the request
    it reports is a float copy (an integer request is not kept as integers, a caller's array is not shared)."""
    t = sheared_table()
    free = LookupTable(t.probes, t.values, t.properties)
    asked = np.array([3, 1])
    res = free.resolve(asked)
    assert res.inside and res.rate == 1.0
    np.testing.assert_array_equal(res.point, free.query(asked.astype(np.float64)))
    assert res.point.shape == (2,) and res.point.min() >= 0.0 and res.point.max() <= 1.0
    assert res.feasible.dtype == np.float64 and res.feasible.tolist() == [3.0, 1.0]
    res.feasible[0] = 0.5
    assert asked.tolist() == [3, 1]


def slow_floor_table() -> LookupTable:
    """speed = 0.5 + 1.5·p₀ (the slowest gait still moves at 0.5 m/s), height = 0.5 + 0.4·p₁."""
    probes, shape = probe_grid(2, 5)
    values = np.stack([0.5 + 1.5 * probes[:, 0], 0.5 + 0.4 * probes[:, 1]], axis=-1)
    return LookupTable(probes, values, ("speed", "height"), shape)


@pytest.mark.parametrize(
    "speed,rate",
    [
        (3.0, 1.5),  # faster than the run: sped up
        (0.4, 0.8),  # slower than the slowest gait: slowed down, u/u'
        (0.1, 1.0 / 3.0),  # far slower: slowed down no more than max_rate allows
        (0.0, 1.0),  # standing still asked: no rate to divide by the request, played as is
        (-1.0, 1.0),  # backwards: never a negative or reversed rate
    ],
)
def test_the_playback_rate_outside_follows_the_requested_speed(speed: float, rate: float) -> None:
    t = slow_floor_table()
    res = t.resolve([speed, 0.7])
    assert not res.inside
    assert res.feasible[1] == pytest.approx(0.7, abs=1e-9)  # the height is kept
    assert res.feasible[0] == pytest.approx(2.0 if speed > 2.0 else 0.5, abs=1e-9)
    assert res.rate == pytest.approx(rate, rel=1e-12)
    _, _, _, rates = t.resolve_many(np.array([[speed, 0.7]]))
    assert rates[0] == pytest.approx(rate, rel=1e-12)


def leaning_table() -> LookupTable:
    """speed = 0.5 + 1.5·p₀, height = 0.5 + 0.2·p₀ + 0.4·p₁: the feasible set is the parallelogram
    (0.5, 0.5), (2, 0.7), (2, 1.1), (0.5, 0.9) — faster gaits stand taller, the slowest still moves."""
    probes, shape = probe_grid(2, 5)
    values = np.stack([0.5 + 1.5 * probes[:, 0], 0.5 + 0.2 * probes[:, 0] + 0.4 * probes[:, 1]], axis=-1)
    return LookupTable(probes, values, ("speed", "height"), shape)


def nearest_on_the_parallelogram(u: F) -> F:
    """The border point nearest ``u`` when speed changes count a tenth (both properties scaled by
    their ranges, 1.5 m/s and 0.6 m), by projecting onto each of the four edges in those units."""
    corners = np.array([[0.5, 0.5], [2.0, 0.7], [2.0, 1.1], [0.5, 0.9]])
    units = np.array([0.1 / 1.5, 1.0 / 0.6])
    x, best, best_d = u * units, u, np.inf
    for i in range(4):
        p0, p1 = corners[i] * units, corners[(i + 1) % 4] * units
        s = np.clip(np.dot(x - p0, p1 - p0) / np.dot(p1 - p0, p1 - p0), 0.0, 1.0)
        q = p0 + s * (p1 - p0)
        if np.linalg.norm(q - x) < best_d:
            best, best_d = q / units, float(np.linalg.norm(q - x))
    return best


@pytest.mark.parametrize(
    "request_", [[1.0, 1.05], [0.6, 1.05], [1.0, 0.55], [1.6, 0.6], [2.5, 1.2], [0.05, 1.05], [-1.0, 0.9 + 0.1 / 1.5]]
)
def test_projection_is_the_cheapest_border_point_within_the_rate_limit(request_: list[float]) -> None:
    """Outside, the request moves to the border point nearest it with speed changes at a tenth of
        their cost, as long as the speed-up it then needs stays within ``[1/3, 3]`` — or when every way
        back needs more (``[0.05, 1.05]``: every gait is at least 10× faster; ``[-1, 0.967]``: backwards, where the
    crossing at 1 m/s, the mirrored speed, is refused like any other), still the cheapest."""
    t = leaning_table()
    u = np.array(request_)
    want = nearest_on_the_parallelogram(u)
    got, inside = t.project(u)
    assert not inside
    np.testing.assert_allclose(got, want, atol=1e-9)
    res = t.resolve(u)
    np.testing.assert_allclose(res.feasible, want, atol=1e-9)
    rate = float(np.clip(u[0] / want[0], 1.0 / 3.0, 3.0)) if u[0] > 0 else 1.0
    assert res.rate == pytest.approx(rate, rel=1e-9)


@pytest.mark.parametrize(
    "request_,lowered",
    [([0.5, 1.08], 0.9), ([0.55, 1.08], 0.9 + 0.2 * 0.05 / 1.5), ([0.6, 1.2], 0.9 + 0.2 * 0.1 / 1.5)],
)
def test_a_request_too_tall_for_a_slow_gait_is_lowered_not_sped_up_past_the_limit(
    request_: list[float], lowered: float
) -> None:
    """The nearest border point (speed changes are cheap) would need a gait more than three times faster
    than asked; the request keeps its speed and is lowered to the tallest height at that speed."""
    t = leaning_table()
    u = np.array(request_)
    near = nearest_on_the_parallelogram(u)
    assert u[0] / near[0] < 1.0 / 3.0  # beyond max_rate: the cheap move is refused
    got, inside = t.project(u)
    assert not inside
    np.testing.assert_allclose(got, [u[0], lowered], atol=1e-9)


def test_a_table_without_a_border_cannot_project() -> None:
    t = sheared_table()
    free = LookupTable(t.probes, t.values, t.properties)
    with pytest.raises(
        ValueError, match=r"^this table has no feasible border: it needs a probe grid with one property per axis$"
    ):
        free.project([1.0, 0.7])


def test_a_nearly_flat_stretch_of_the_measurement_is_still_inverted() -> None:
    """Speed rises by only 10⁻⁴ of its range over the first two probes, then normally: the slope there,
    small but well conditioned (a 1×1 Jacobian), still maps a request between them to its blend point —
    it is a fold only relative to the Jacobian's own largest singular value, not to an absolute 10⁻³."""
    probes = np.linspace(0.0, 1.0, 5)[:, None]
    values = np.array([[0.0], [1e-4], [2e-4], [0.5], [1.0]])
    t = LookupTable(probes, values, ("speed",), (5,), power=7.0)
    assert t.slopes is not None
    np.testing.assert_allclose(t.slopes[:2, 0, 0], [1.0 / 4e-4, 1.0 / 4e-4], rtol=1e-9)  # 0.25 / 1e-4
    assert t.query([4e-5])[0] == pytest.approx(0.1, abs=1e-3)  # on the line through the first two probes
    plain = LookupTable(probes, values, ("speed",), (5,), power=7.0, gradients=False)
    assert plain.query([4e-5])[0] < 0.02  # without the slope it sticks to the first probe


def test_integer_probes_and_measurements_are_taken_as_floats() -> None:
    """A table built from whole numbers (a 0/1 probe grid, speeds in whole m/s) stores floats and answers
    as the same table built from floats."""
    probes = np.array([[0, 0], [0, 1], [1, 0], [1, 1]])
    values = np.array([[0, 1], [0, 2], [2, 1], [2, 2]])
    t = LookupTable(probes, values, ("speed", "height"), (2, 2))
    f = LookupTable(probes.astype(np.float64), values.astype(np.float64), ("speed", "height"), (2, 2))
    assert t.probes.dtype == np.float64 and t.values.dtype == np.float64
    u = np.array([[1.0, 1.5], [0.5, 1.2], [2, 2]])
    np.testing.assert_array_equal(t.query(u), f.query(u))
    np.testing.assert_allclose(t.query(u), [[0.5, 0.5], [0.25, 0.2], [1.0, 1.0]], atol=1e-12)
