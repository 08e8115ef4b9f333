"""Which solver a two-bone call takes: one pose goes to the float path, anything batched to numpy.

The float path (``engine.ik._limb.solve_limb``) is the per-frame case and some thirty times cheaper
on one limb; both agree to rounding (``test_two_bone.py``), so only the route tells them apart. Shown
to fail by mutation (docs/mutation.md): ``_single``'s ``or`` made ``and``, ``is None`` made
``is not None``, ``np.shape(None)``, ``==`` made ``!=`` each send one of these calls down the wrong path.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from engine.humanoid import humanoid_skeleton
from engine.ik import two_bone
from engine.pose import Pose

LEG = ("l_upper_leg", "l_lower_leg", "l_foot")


@pytest.mark.parametrize(
    "pole,end,offsets,batch,float_path",
    [
        (None, None, False, 0, True),
        ((0.0, 0.5, 1.0), None, False, 0, True),
        (None, (1.0, 0.0, 0.0, 0.0), True, 0, True),
        ((0.0, 0.5, 1.0), (1.0, 0.0, 0.0, 0.0), False, 0, True),
        (None, None, False, 2, False),
    ],
)
def test_one_pose_takes_the_float_path(
    monkeypatch: pytest.MonkeyPatch, pole: Any, end: Any, offsets: bool, batch: int, float_path: bool
) -> None:
    sk = humanoid_skeleton()
    pose = Pose.rest(sk, batch) if batch else Pose.rest(sk)
    calls: list[int] = []
    real = two_bone.solve_limb

    def spy(*args: Any, **kw: Any) -> Any:
        calls.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(two_bone, "solve_limb", spy)
    target = np.array([0.1, 0.3, 0.1])
    got = two_bone.two_bone_ik(
        sk, pose, LEG, target, pole, end_rotation=end, offsets=sk.offsets.copy() if offsets else None
    )
    assert len(calls) == (1 if float_path else 0)
    assert np.isfinite(got).all()


def test_a_broken_chain_or_a_non_finite_target_is_named() -> None:
    """Mutants: ``and`` for ``or`` (a chain with only its second link broken accepted); the names or the
    message text changed."""
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    with pytest.raises(ValueError, match="^l_upper_leg → l_lower_leg → l_hand is not a parent chain$"):
        two_bone.two_bone_ik(sk, pose, ("l_upper_leg", "l_lower_leg", "l_hand"), np.zeros(3))
    with pytest.raises(ValueError, match="^l_upper_arm → l_lower_leg → l_foot is not a parent chain$"):
        two_bone.two_bone_ik(sk, pose, ("l_upper_arm", "l_lower_leg", "l_foot"), np.zeros(3))
    with pytest.raises(ValueError, match="^two_bone_ik target must be finite$"):
        two_bone.two_bone_ik(sk, pose, LEG, [0.0, np.nan, 0.0])
