"""The Panda3D animate+FK peer: its characters are our skeleton, pose as our FK does, blend, and update when forced."""

import tempfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("panda3d.core", reason="Panda3D (the [peers] extra) is not installed")


def test_panda3d_characters_pose_our_clips_as_our_fk_does_and_blend_them() -> None:
    """Each clip alone gives our FK's joint positions for the same frame (float32 tolerance); a 50/50
    blend gives the nlerp of the two frames' rotations. So the peer computes what our stages compute.

    Broken once by writing the joints' offsets with their y and z swapped in the egg: fails.
    """
    from engine import quat
    from engine.blend.puppet import puppet_locomotion
    from engine.fk import forward_kinematics
    from engine.humanoid import humanoid_skeleton
    from puppetphone.bench.anim_panda import ANIMS, joint_positions, load_characters

    sk = humanoid_skeleton()
    space = puppet_locomotion().space
    walk_clip, run_clip = (space.clips[space.names.index(n)] for n in ANIMS)
    with tempfile.TemporaryDirectory() as tmp:
        bundles, controls = load_characters(1, Path(tmp))
    bundle, (walk, run) = bundles[0], controls[0]
    root = np.asarray(sk.offsets[0], dtype=np.float64)
    for f in (7, 30):
        walk.pose(f)
        run.pose(f)
        a, b = walk_clip.rotations[f], run_clip.rotations[f]
        b = b * np.where(np.sum(a * b, axis=-1, keepdims=True) < 0.0, -1.0, 1.0)  # the shorter way round
        for w, rots in ((1.0, a), (0.0, b), (0.5, quat.normalize(0.5 * (a + b)))):
            bundle.set_control_effect(walk, w)
            bundle.set_control_effect(run, 1.0 - w)
            bundle.force_update()
            ours, _ = forward_kinematics(sk, root, rots)
            assert np.abs(joint_positions(bundle, sk.names) - ours).max() < 1e-5, (f, w)


def test_the_timed_frame_moves_the_joints_every_frame() -> None:
    """The frame :func:`measure` times (:func:`advance`) changes the joints each frame (nothing is skipped or cached), and it
    reports a positive CPU time.

    Broken once by dropping the ``force_update`` call from the timed frame: the joints keep their
    pose and this fails.
    """
    from panda3d.core import ClockObject

    from puppetphone.bench.anim_panda import advance, joint_positions, load_characters, measure

    assert measure(characters=2, frames=3, repeats=3) > 0.0
    clock = ClockObject.get_global_clock()
    clock.set_mode(ClockObject.M_non_real_time)
    clock.set_frame_rate(60.0)
    with tempfile.TemporaryDirectory() as tmp:
        bundles, controls = load_characters(2, Path(tmp))
    seen = []
    for tick in range(3):
        advance(clock, bundles, controls, tick)
        seen.append(joint_positions(bundles[1], ("l_hand", "r_foot")))
    assert all(not np.allclose(seen[k], seen[k + 1]) for k in range(2))


def test_without_panda3d_the_animation_peer_is_skipped_with_a_line(monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib.util

    from puppetphone.bench.peers import panda_animate_fk_ms

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "panda3d" else real(name, *a))
    line = panda_animate_fk_ms()
    assert isinstance(line, str) and "Panda3D not installed" in line
