"""Scale is a real channel (issue 18 item 3): a MoCurves scale edit reaches the clip, the character,
the saved ``.ppclip`` and the exported glTF; BVH says it drops it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.mocurves import EditSession
from authoring.mocurves.storage import export_clip, load_session, save_session
from engine.clipfile import load_clip
from engine.clips import default_clips
from engine.fk import forward_kinematics
from engine.io.bvh import BvhWarning
from engine.io.gltf_clip import load_gltf_clips


def _edited() -> tuple[EditSession, int, int]:
    session = EditSession(default_clips()["walk"])
    assert session.clip.scales is None  # nothing edited: no channel, the hot path pays nothing
    j = session.joint("head")
    frame = session.clip.num_frames // 2
    session.scale_arrow("head", frame, float(np.log(1.5)))
    return session, j, frame


def test_a_scale_edit_becomes_the_clips_scale_channel_and_shows_on_the_character() -> None:
    """The head has no children, so its scale is checked on the clip; what the character shows is
    checked on a joint *with* children (the left forearm: its hand bone grows by the scale).

    Repaired: this used to guard its only FK assertion with ``if kids:`` on the head, a leaf, so it
    never ran. Shown to fail when ``Clip.sample`` drops the sampled scales (``pose.scales``) or FK
    scales each offset by the joint's own scale instead of its parent's.
    """
    session, j, frame = _edited()
    clip = session.clip
    assert clip.scales is not None and clip.scales[frame, j] == pytest.approx(1.5)
    assert np.all(np.delete(clip.scales, j, axis=1) == 1.0)
    session.undo()
    assert session.clip.scales is None
    # What the editor draws: FK of the sampled pose with its scales; the forearm's bone tip moves out.
    arm = session.joint("l_lower_arm")
    session.scale_arrow("l_lower_arm", frame, float(np.log(1.5)))
    clip = session.clip
    pose = clip.sample(frame / clip.fps)
    assert pose.scales is not None and pose.scales[arm] == pytest.approx(1.5)
    sk = clip.skeleton
    kids = sk.children(arm)
    assert kids, "the forearm has the hand below it"
    pos, _ = forward_kinematics(sk, pose.root, pose.rotations, scales=pose.scales)
    plain, _ = forward_kinematics(sk, pose.root, pose.rotations)
    assert np.linalg.norm(pos[kids[0]] - pos[arm]) == pytest.approx(1.5 * np.linalg.norm(plain[kids[0]] - plain[arm]))
    assert np.linalg.norm(pos[arm] - pos[sk.parents[arm]]) == pytest.approx(
        np.linalg.norm(plain[arm] - plain[sk.parents[arm]])
    )  # the forearm's own bone is its parent's to scale
    session.undo()
    assert session.clip.scales is None


def test_a_scale_edit_reaches_the_exported_gltf_and_the_ppclip(tmp_path: Path) -> None:
    session, j, frame = _edited()
    export_clip(session.clip, tmp_path / "walk.glb")
    back = load_gltf_clips(tmp_path / "walk.glb")[0]
    assert back.scales is not None
    assert back.scales[frame, j] == pytest.approx(1.5, abs=1e-5)
    assert np.abs(back.scales - session.clip.scales).max() < 1e-5
    save_session(session, tmp_path / "walk.ppclip")
    assert np.allclose(load_clip(tmp_path / "walk.ppclip").scales, session.clip.scales)
    again = load_session(tmp_path / "walk.ppclip")
    assert np.allclose(again.scales, session.scales)


def test_bvh_export_says_it_drops_the_scale(tmp_path: Path) -> None:
    session, _, _ = _edited()
    with pytest.warns(BvhWarning, match="BVH has no scale channels"):
        export_clip(session.clip, tmp_path / "walk.bvh")
    assert (tmp_path / "walk.bvh").exists()
