"""Real motion capture (../shared/data/mocap): periods against foot contacts, loops closed, the jump refused.

The gait period is measured independently of the extractor: forward kinematics on the
BVH clip gives each foot's height; every time a foot comes down through (touchdown)
or leaves (lift-off) 30 % of its height range is an event, and the median interval
between successive events of the same kind on the same foot is the stride period.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import CycleError, CycleOptions, extract_cycle
from authoring.cycles.formats import load_performance
from authoring.cycles.synthetic import repeat_loop
from authoring.cycles.trajectory import Item, Trajectory
from engine.fk import forward_kinematics

FEET = {"lfoot", "rfoot", "foot_l", "foot_r", "cc_base_l_foot", "cc_base_r_foot"}


def gait_period_frames(path: Path) -> float:
    """Median same-foot interval between touchdowns and between lift-offs, in file frames."""
    perf = load_performance(path)
    clip = perf.clip
    assert clip is not None
    sk = clip.skeleton
    wpos, _ = forward_kinematics(sk, clip.root, clip.rotations)
    intervals: list[float] = []
    for j, name in enumerate(sk.names):
        if name.lower() not in FEET:
            continue
        y = wpos[:, j, 1]
        thr = y.min() + 0.3 * (y.max() - y.min())
        below = y < thr
        for edges in (np.flatnonzero(~below[:-1] & below[1:]), np.flatnonzero(below[:-1] & ~below[1:])):
            times = [e + (y[e] - thr) / (y[e] - y[e + 1]) for e in edges]
            intervals += list(np.diff(times))
    assert len(intervals) >= 2, f"{path.name}: too few foot contacts to measure a stride"
    return float(np.median(intervals))


@pytest.mark.parametrize(
    ("name", "min_cycles"),
    [
        ("cmu_16_15_walk_daz.bvh", 2),
        ("cmu_02_01_walk_ccbase.bvh", 2),
        ("bandai1_walk_normal_001.bvh", 2),
        ("bandai1_run_happy_001.bvh", 2),
        # Two strides only: one whole cycle can be cut, so the loop is closed but not averaged.
        ("cmu_16_36_runjog_daz.bvh", 1),
    ],
)
def test_gait_period_matches_foot_contacts(mocap_dir: Path, name: str, min_cycles: int) -> None:
    path = mocap_dir / name
    truth = gait_period_frames(path)
    r = extract_cycle(load_performance(path).trajectory, np.random.default_rng(0), CycleOptions(min_cycles=min_cycles))
    assert abs(r.period_samples / truth - 1.0) < 0.03, (
        f"{name}: {r.period_samples:.1f} frames vs foot contacts {truth:.1f}"
    )
    assert r.closure_error < 1e-9


def test_short_run_is_not_averaged_by_default(mocap_dir: Path) -> None:
    with pytest.raises(CycleError, match="too few cycles"):
        extract_cycle(load_performance(mocap_dir / "cmu_16_36_runjog_daz.bvh").trajectory, np.random.default_rng(0))


@pytest.mark.parametrize(("name", "period"), [("bandai1_punch_normal_001.bvh", 42), ("cmu_02_05_punch_ccbase.bvh", 89)])
def test_punches(mocap_dir: Path, name: str, period: float) -> None:
    """Hand motions have no foot contacts: the README's autocorrelation estimates (±2–3 frames) are the reference."""
    r = extract_cycle(load_performance(mocap_dir / name).trajectory, np.random.default_rng(0))
    assert abs(r.period_samples - period) <= 3.0
    assert r.cycles >= 4 and r.closure_error < 1e-9


def test_forward_jump_is_refused(mocap_dir: Path) -> None:
    with pytest.raises(CycleError, match="period|cycles"):
        extract_cycle(
            load_performance(mocap_dir / "cmu_13_32_forward_jump_NEGATIVE_daz.bvh").trajectory, np.random.default_rng(0)
        )


def test_t_pose_lead_in_is_skipped(mocap_dir: Path) -> None:
    perf = load_performance(mocap_dir / "cmu_16_15_walk_daz.bvh")
    assert perf.skipped >= 1
    assert perf.trajectory.num_samples == 472 - perf.skipped


@pytest.mark.parametrize(("animation", "duration"), [("Walk", 0.708), ("Run", 1.158)])
def test_fox_cycles_repeated_with_noise(mocap_dir: Path, animation: str, duration: float) -> None:
    """Fox.glb's Walk and Run are exact seamless loops: repeated with noise they give exact ground truth."""
    from engine.io.gltf import read_gltf
    from engine.io.gltf_clip import sample_channel

    asset = read_gltf(mocap_dir / "Fox.glb")
    anim = next(a for a in asset.animations if a.name == animation)
    assert anim.duration == pytest.approx(duration, abs=2e-3)
    fps = 60.0
    rng = np.random.default_rng(1)
    # Each repetition slightly slower or faster (±10 %), then noise on every value.
    speeds = 1.0 + np.array([0.0, 0.08, -0.1, 0.05, -0.04, 0.1, -0.09, 0.0])
    speeds = speeds / speeds.mean()
    starts = np.concatenate([[0.0], np.cumsum(duration * speeds)])
    t = np.arange(0.0, starts[-1], 1.0 / fps)
    c = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(speeds) - 1)
    local = anim.start + (t - starts[c]) / speeds[c]
    cols, items = [], []
    for ch in anim.channels:
        if ch.path not in ("translation", "rotation"):
            continue
        v = sample_channel(ch, local)
        if np.ptp(v, axis=0).max() < 1e-6:
            continue
        kind = "rotation" if ch.path == "rotation" else "position"
        start = sum(x.shape[1] for x in cols)
        cols.append(v)
        items.append(Item(f"node{ch.node}.{ch.path}", kind, start, start + v.shape[1]))
    values = np.concatenate(cols, axis=1)
    noisy = repeat_loop(values, 1, rng, noise=0.01)
    for it in items:  # keep quaternions unit after the noise
        if it.kind == "rotation":
            noisy[:, it.columns] /= np.linalg.norm(noisy[:, it.columns], axis=1, keepdims=True)
    r = extract_cycle(Trajectory(t, noisy, tuple(items)), np.random.default_rng(0))
    assert r.period == pytest.approx(duration, rel=0.02)
    assert r.closure_error < 1e-9
