"""End-to-end extraction on synthetic performances with a known answer (the issue's accuracy list)."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.cycles.extract import CycleError, CycleOptions, extract_cycle
from authoring.cycles.stitch import rotation_angle
from authoring.cycles.synthetic import loop_error, make_performance
from authoring.cycles.trajectory import Item, Trajectory


def _check(dims: int, seed: int, **kw: float) -> None:
    perf = make_performance(dims, np.random.default_rng(seed), cycles=8, jitter=0.15, noise=0.02, drift=0.1, **kw)  # type: ignore[arg-type]
    r = extract_cycle(perf.trajectory, np.random.default_rng(seed + 1))
    assert abs(r.period / perf.period - 1.0) < 0.02, f"period {r.period:.4f} vs {perf.period}"
    assert r.closure_error < 1e-9  # C0: the end meets the start exactly
    closed = r.closed()
    step = np.abs(np.diff(closed, axis=0)).max()
    assert np.abs(closed[-1] - closed[0]).max() < 1e-9 * max(step, 1.0)
    err, _ = loop_error(r.loop, perf.truth)
    assert err < 0.1, f"loop differs from ground truth by {err:.1%}"
    assert r.cycles >= 5


@pytest.mark.parametrize("dims", [1, 2, 60, 254])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_jittered_noisy_drifting_performances(dims: int, seed: int) -> None:
    _check(dims, seed)


@pytest.mark.parametrize("dims", [2611, 7804])
def test_high_dimensional_performances(dims: int) -> None:
    _check(dims, 5)


def test_uneven_sampling() -> None:
    _check(3, 7, uneven=0.4)


def test_rotations_are_averaged_on_the_sphere_and_closed() -> None:
    perf = make_performance(6, np.random.default_rng(11), cycles=8, rotations=3)
    r = extract_cycle(perf.trajectory, np.random.default_rng(0))
    assert abs(r.period / perf.period - 1.0) < 0.02
    _, phase = loop_error(r.loop[:, :6], lambda p: perf.truth(p)[:, :6])
    s = len(r.loop)
    truth = perf.truth(np.mod(np.arange(s) / s + phase, 1.0))
    for it in perf.trajectory.rotation_items():
        q = r.loop[:, it.columns]
        assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
        assert rotation_angle(q, truth[:, it.columns]) < np.radians(6.0)
        assert rotation_angle(r.closed()[0, it.columns], r.closed()[-1, it.columns]) < 1e-9
        assert r.curves[it.name].max_error <= 0.01 + 1e-12


def test_travelling_root_keeps_its_travel() -> None:
    rng = np.random.default_rng(4)
    perf = make_performance(4, rng, cycles=6, noise=0.01)
    t = perf.trajectory.times
    walk = np.stack([0.02 * np.sin(2 * np.pi * t), 0.9 + 0.03 * np.cos(4 * np.pi * t), 1.4 * t], axis=1)  # 1.4 m/s
    values = np.concatenate([walk, perf.trajectory.values], axis=1)
    items = (Item("root", "position", 0, 3, travel=True), Item("pose", "scalar", 3, 7))
    r = extract_cycle(Trajectory(t, values, items), np.random.default_rng(0))
    assert r.travel[2] == pytest.approx(1.4 * r.period, rel=0.02)
    assert r.travel[0] == 0.0 and r.travel[1] == 0.0  # no consistent sideways or vertical travel
    assert r.closure_error < 1e-9


def test_deterministic_for_a_seed() -> None:
    perf = make_performance(5, np.random.default_rng(2), cycles=6)
    a = extract_cycle(perf.trajectory, np.random.default_rng(42))
    b = extract_cycle(perf.trajectory, np.random.default_rng(42))
    assert a.period == b.period and np.array_equal(a.loop, b.loop)


def test_non_repeating_motion_is_refused_with_a_reason() -> None:
    t = np.arange(400) / 60.0
    v = np.stack([np.tanh((t - 3) * 2), (t - 3) ** 3 / 10, np.exp(-((t - 2) ** 2))], axis=1)
    with pytest.raises(CycleError, match="period|cycles"):
        extract_cycle(Trajectory(t, v), np.random.default_rng(0))


def test_random_walk_is_refused() -> None:
    v = np.cumsum(np.random.default_rng(9).normal(size=(600, 4)), axis=0)
    with pytest.raises(CycleError):
        extract_cycle(Trajectory.uniform(v, 60.0), np.random.default_rng(0))


def test_irregular_cycles_are_refused() -> None:
    """The paper's limitation: cycles that differ too much in shape are reported, not averaged."""
    rng = np.random.default_rng(5)
    t = np.arange(720) / 60.0
    phase = t / 1.0
    amp = np.repeat(rng.uniform(0.2, 2.0, 12), 60)  # every cycle a very different size
    shape = np.repeat(rng.uniform(0, 2 * np.pi, 12), 60)
    v = np.stack([amp * np.sin(2 * np.pi * phase), np.sin(4 * np.pi * phase + shape)], axis=1)
    with pytest.raises(CycleError, match="too different|period"):
        extract_cycle(Trajectory(t, v), np.random.default_rng(0))


def test_still_input_is_refused() -> None:
    with pytest.raises(CycleError, match="does not move"):
        extract_cycle(Trajectory.uniform(np.ones((200, 2)), 60.0))


def test_too_short_input_is_refused() -> None:
    with pytest.raises(CycleError, match="too few"):
        extract_cycle(Trajectory.uniform(np.sin(np.arange(10.0))[:, None], 60.0))


def test_progress_is_reported_in_order() -> None:
    perf = make_performance(3, np.random.default_rng(0), cycles=6)
    seen: list[float] = []
    extract_cycle(perf.trajectory, progress=lambda stage, done: seen.append(done), options=CycleOptions(fit=False))
    assert seen[0] == 0.0 and seen[-1] == 1.0 and seen == sorted(seen)


def test_sub_period_is_corrected() -> None:
    """A 1-D curve that nearly repeats at 2/3 of its cycle passes the minimal-period rule there;
    its cycles then spread widely and the multiple that aligns them wins."""
    perf = make_performance(1, np.random.default_rng(531), cycles=8)
    r = extract_cycle(perf.trajectory, np.random.default_rng(31))
    assert abs(r.period / perf.period - 1.0) < 0.02
    assert r.spread < 0.2
