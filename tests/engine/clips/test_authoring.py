"""Authoring helpers: spec validation, mirrored keys, reach limiting and the contact sheet."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.clips import default_clips
from engine.clips._gait import FootPlan, build_gait, mirrored
from engine.clips._library import WALK
from engine.clips._reach import lower_to_reach
from engine.humanoid import humanoid_skeleton


def test_mirrored_keys_repeat_the_half_cycle_with_flipped_signs() -> None:
    keys = mirrored(((0.0, (1.0, 2.0, 3.0)), (0.25, (4.0, 5.0, 6.0))), (-1.0, 1.0, -1.0))
    assert keys == (
        (0.0, (1.0, 2.0, 3.0)),
        (0.25, (4.0, 5.0, 6.0)),
        (0.5, (-1.0, 2.0, -3.0)),
        (0.75, (-4.0, 5.0, -6.0)),
    )


def test_foot_plan_rejects_impossible_timing() -> None:
    good = {
        "width": 0.1,
        "toe_out": 0.0,
        "front": 0.3,
        "strike_pitch": 10.0,
        "toeoff_pitch": 30.0,
        "flat_at": 0.1,
        "heel_off": 0.3,
        "duty": 0.6,
        "swing": ((0.5, 0.0, 0.1, 0.0),),
    }
    FootPlan(**good)
    with pytest.raises(ValueError, match="duty"):
        FootPlan(**{**good, "heel_off": 0.7})
    with pytest.raises(ValueError, match="swing"):
        FootPlan(**{**good, "swing": ((0.99, 0.0, 0.1, 0.0),)})


def test_gait_spec_needs_an_even_number_of_frames() -> None:
    with pytest.raises(ValueError, match="even"):
        build_gait(humanoid_skeleton(), dataclasses.replace(WALK, period=1.05))  # 63 frames


def test_reach_limit_lowers_only_where_needed_and_never_raises() -> None:
    sk = humanoid_skeleton()
    n = 60
    pos = np.zeros((n, 3))
    pos[:, 1] = 0.93  # standing reach 0.976: only the stride needs lowering
    rot = quat.identity(n)
    ankles = np.zeros((n, 2, 3))
    ankles[:, 0] = (0.09, 0.06, 0.0)
    ankles[:, 1] = (-0.09, 0.06, 0.0)
    ankles[20:30, 0, 2] = 0.4  # one stride forward: this leg needs the pelvis down
    y = lower_to_reach(sk, pos, rot, ankles, 0.99, 3, loop=True)
    assert np.all(y <= 0.93 + 1e-12)
    hip = pos.copy()
    hip[:, 1] = y
    hip = hip + sk.offsets[sk.index("l_upper_leg")]
    reach = np.linalg.norm(ankles[:, 0] - hip, axis=1) / 0.84
    assert reach.max() <= 0.99 + 1e-9
    assert y[0] == pytest.approx(0.93) and y[25] < 0.9  # far frames untouched, the stride lowered
    with pytest.raises(ValueError, match="too far"):
        lower_to_reach(sk, pos, rot, ankles + np.array([0.0, 0.0, 2.0]), 0.99, 3, loop=True)


def test_contact_sheet_draws_a_png(tmp_path: Path) -> None:
    from PIL import Image

    from engine.clips.sheet import contact_sheet

    clips = default_clips()
    out = contact_sheet({"walk": clips["walk"], "get_up": clips["get_up"]}, tmp_path / "sheet.png", frames=3)
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size[0] > 300 and im.size[1] > 200
        pixels = np.asarray(im.convert("RGB")).reshape(-1, 3)
    assert len(np.unique(pixels, axis=0)) > 10  # something was drawn, in several colours
