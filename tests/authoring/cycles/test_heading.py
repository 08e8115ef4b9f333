"""Heading-normalised extraction (issue 24 item 7): a walk that turns still loops; other input is untouched."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import CycleError, extract_cycle
from authoring.cycles.formats import load_performance, loop_clip, save_loop
from authoring.cycles.heading import normalise, restore, yaw
from authoring.cycles.trajectory import Item, Trajectory
from engine import quat
from engine.io.bvh import read_bvh
from tests.engine.io.synthetic_bvh import human_bvh


def _raw(perf) -> Trajectory:  # type: ignore[no-untyped-def]
    """The heading-dependent trajectory extraction used before: world root and every joint's rotation."""
    c = perf.clip
    cols = [c.root] + [c.rotations[:, j] for j in range(c.skeleton.num_joints)]
    its = [Item("root", "position", 0, 3, travel=True)]
    its += [Item(f"j{j}", "rotation", 3 + 4 * j, 7 + 4 * j) for j in range(c.skeleton.num_joints)]
    return Trajectory.uniform(np.concatenate(cols, axis=1), c.fps, its)


def test_a_weaving_walk_loops_once_the_heading_is_taken_out(tmp_path: Path) -> None:
    path = tmp_path / "eight.bvh"
    path.write_text(human_bvh(turn=180.0, turn_period=8.0, frames=270, period=1.0))  # ±180°: left and right arcs
    perf = load_performance(path)
    with pytest.raises(CycleError, match="cycles too different"):
        extract_cycle(_raw(perf), np.random.default_rng(0))  # the wall: measured on the heading-dependent pose
    r = extract_cycle(perf.trajectory, np.random.default_rng(0))
    assert r.period == pytest.approx(1.0, abs=0.02) and r.cycles >= 6
    assert r.spread < 0.3
    # The loop walks forward in its own frame at the take's speed (1.2 m/s), in world terms again.
    clip = loop_clip(r, perf)
    pos = clip.root
    assert np.linalg.norm(pos[-1, [0, 2]] - pos[0, [0, 2]]) == pytest.approx(
        1.2 * clip.duration * (1 - 1 / len(pos)), rel=0.1
    )
    save_loop(r, perf, tmp_path / "loop.bvh")
    assert read_bvh(tmp_path / "loop.bvh").num_frames == round(r.period * 30) + 1


def test_normalise_and_restore_are_inverse_on_a_curving_path() -> None:
    t = np.linspace(0.0, 2.0, 81)
    heading = 0.8 * t + 0.3
    root = np.stack(
        [-np.cos(heading) * 3.0, 0.9 + 0.02 * np.cos(9 * t), np.sin(heading) * 3.0], axis=1
    )  # walks forward
    rot = quat.mul(
        quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), heading),
        quat.from_axis_angle(np.array([1.0, 0, 0]), 0.1 * np.sin(5 * t)),
    )
    local, level, head = normalise(root, rot)
    assert np.allclose(yaw(level), 0.0, atol=1e-9) and np.allclose(head, heading)
    # On a circle the body-frame path is a straight line of the arc's length.
    assert np.allclose(local[:, 0], 0.0, atol=1e-2) and local[-1, 2] == pytest.approx(3.0 * 0.8 * 2.0, rel=1e-3)
    back, rot_back, _ = restore(local[:-1], level[:-1], head[:-1], local[-1] - local[0], float(head[-1] - head[0]))
    assert np.abs((back - back[0]) - (root[:-1] - root[0])).max() < 1e-3
    assert np.allclose(np.abs(np.sum(rot_back * rot[:-1], axis=-1)), 1.0, atol=1e-9)


def test_non_skeletal_input_keeps_the_paper_path(tmp_path: Path) -> None:
    t = np.arange(200) / 50.0
    csv = tmp_path / "x.csv"
    csv.write_text("time,a,b\n" + "\n".join(f"{x},{np.sin(2 * np.pi * x)},{np.cos(2 * np.pi * x)}" for x in t))
    perf = load_performance(csv)
    assert perf.heading is None and perf.trajectory.dims == 2
