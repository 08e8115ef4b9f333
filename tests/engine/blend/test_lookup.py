"""The §6.2.3 lookup table: measured probes, IDW, the feasible border and the speed-up."""

from __future__ import annotations

import numpy as np
import pytest

from engine.blend import LinearMapping, LocomotionSet, LookupTable, build_locomotion, measure_locomotion, probe_grid
from engine.blend.feasible import FeasibleSet, border_facets, closest_point_on_simplices, kuhn_simplices
from engine.clip import Clip


@pytest.fixture(scope="module")
def loco(clips: dict[str, Clip]) -> LocomotionSet:
    return build_locomotion(clips, density=21)


def test_probe_grid_and_kuhn_triangulation_tile_the_cube() -> None:
    pts, shape = probe_grid(3, (3, 4, 2))
    assert pts.shape == (24, 3) and shape == (3, 4, 2)
    simp = kuhn_simplices(shape)
    assert len(simp) == 6 * 2 * 3 * 1
    vol = [abs(np.linalg.det(pts[s[1:]] - pts[s[0]])) / 6 for s in simp]
    assert sum(vol) == pytest.approx(1.0)
    assert len(border_facets((5, 5), kuhn_simplices((5, 5)))) == 16
    with pytest.raises(ValueError):
        probe_grid(2, 1)


def test_closest_point_on_a_triangle() -> None:
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    cases = [
        ((0.2, 0.2, 1.0), (0.2, 0.2, 0.0)),
        ((2.0, -1.0, 0.0), (1.0, 0.0, 0.0)),
        ((1.0, 1.0, 0.0), (0.5, 0.5, 0.0)),
    ]
    for x, want in cases:
        pt, _ = closest_point_on_simplices(tri, np.array(x))
        assert np.allclose(pt[0], want)


def test_idw_is_exact_at_probes_and_matches_brute_force(loco: LocomotionSet) -> None:
    t = loco.table
    assert np.allclose(t.query(t.values), t.probes)
    full = LookupTable(t.probes, t.values, t.properties, t.grid_shape, neighbours=len(t.probes))
    rng = np.random.default_rng(1)
    u = t.values[rng.integers(len(t.values), size=50)] + rng.normal(scale=0.02, size=(50, 2))
    assert np.allclose(full.query(u), full.query_brute(u), atol=1e-12)
    # the 16 nearest carry all but a sliver of the weight at q = 7
    assert np.abs(t.query(u) - full.query(u)).max() < 5e-3


def test_idw_is_continuous_and_inverts_the_measurement(loco: LocomotionSet) -> None:
    t = loco.table
    u = np.stack([np.linspace(0.05, 1.5, 2000), np.full(2000, 0.9)], axis=-1)
    p = t.query(u)
    assert np.abs(np.diff(p, axis=0)).max() < 0.02
    # blend points off the grid: measure them, look them up, get them back
    rng = np.random.default_rng(2)
    p_true = rng.uniform(0.1, 0.9, size=(30, 2))
    u_meas = measure_locomotion(loco.space, p_true)
    assert np.abs(t.query(u_meas) - p_true).max() < 0.05  # within a grid step
    again = measure_locomotion(loco.space, t.query(u_meas))
    assert np.abs(again[:, 0] / u_meas[:, 0] - 1).max() < 0.05


def test_requests_outside_are_projected_and_sped_up(loco: LocomotionSet) -> None:
    t = loco.table
    top = t.values[t.probes[:, 0] == 1.0]  # the p_vel = 1 border of Fig. 6.4
    fastest = top[:, 0].max()
    u = np.array([2.0 * fastest, 0.9])
    res = t.resolve(u)
    assert not res.inside
    assert res.feasible[1] == pytest.approx(0.9, abs=0.01)  # keeps the height
    assert res.point[0] == pytest.approx(1.0, abs=0.02)  # on the p_vel = 1 border
    assert res.rate == pytest.approx(u[0] / res.feasible[0])
    assert res.rate > 1.5
    # playing the projected blend at that rate moves at the requested speed
    played = np.linalg.norm(loco.space.average_velocity(loco.space.weights(res.point))) * res.rate
    assert played == pytest.approx(u[0], rel=0.05)


def test_too_low_a_crouch_keeps_walking(loco: LocomotionSet) -> None:
    t = loco.table
    res = t.resolve(np.array([0.3, 0.2]))
    assert not res.inside
    assert res.feasible[0] == pytest.approx(0.3)
    assert res.rate == pytest.approx(1.0)
    assert res.feasible[1] == pytest.approx(t.values[:, 1].min(), abs=0.05)


def test_inside_requests_are_kept(loco: LocomotionSet) -> None:
    res = loco.table.resolve(np.array([0.6, 0.9]))
    assert res.inside and res.rate == 1.0 and np.allclose(res.feasible, [0.6, 0.9])


def test_linear_mapping_clamps() -> None:
    m = LinearMapping(0.2, 1.2, 0.6, 0.95)
    assert np.allclose(m(np.array([0.0, 0.2, 0.7, 1.2, 5.0])), [0.6, 0.6, 0.775, 0.95, 0.95])
    with pytest.raises(ValueError):
        LinearMapping(1.0, 1.0, 0.0, 1.0)


def test_bad_requests_and_tables_are_rejected(loco: LocomotionSet) -> None:
    t = loco.table
    with pytest.raises(ValueError, match="NaN"):
        t.query(np.array([np.nan, 0.9]))
    with pytest.raises(ValueError, match="needs 2 values"):
        t.query(np.array([1.0]))
    with pytest.raises(ValueError, match="one row per probe"):
        LookupTable(t.probes[:3], t.values, t.properties)
    with pytest.raises(ValueError, match="power"):
        LookupTable(t.probes, t.values, t.properties, power=0.0)
    no_border = LookupTable(t.probes, t.values, t.properties)
    with pytest.raises(ValueError, match="border"):
        no_border.project(np.array([0.1, 0.9]))
    with pytest.raises(ValueError, match="one row per probe"):
        FeasibleSet((3, 3), np.zeros((8, 2)))


def test_probe_slopes_remove_the_flat_spots_of_plain_idw(loco: LocomotionSet) -> None:
    t = loco.table
    plain = LookupTable(t.probes, t.values, t.properties, t.grid_shape, gradients=False)
    rng = np.random.default_rng(4)
    p_true = rng.uniform(0.1, 0.9, size=(40, 2))
    u = measure_locomotion(loco.space, p_true)
    err_slopes = np.abs(t.query(u) - p_true).mean()
    err_plain = np.abs(plain.query(u) - p_true).mean()
    assert err_slopes < 0.3 * err_plain
    assert np.allclose(plain.query(t.values), t.probes)  # both are exact at the probes
