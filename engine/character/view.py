"""A character standing in for the mannequin in the editors: a pose of the puppet's skeleton, drawn skinned.

``author record --character`` and ``author curves --character`` edit clips of the puppet's own
skeleton (the clips every puppet plays); only the drawing changes. The pose's local rotations
carry over as they are (the character keeps the puppet's rest convention, :mod:`engine.character.rig`),
its root is scaled to the character's hips height, and the posed skin is then scaled back up by
the same factor about the origin, so the character stands where the mannequin's joints are —
its hips exactly, its hands and feet within its proportions — and the editors' trajectories and
handles stay on it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine.character.load import Character
from engine.fk import forward_kinematics
from engine.render.scene import SkinnedInstance
from engine.skeleton import Skeleton

__all__ = ["character_instance"]


def character_instance(
    character: Character, skeleton: Skeleton, root: ArrayLike, rotations: ArrayLike, outline: bool = False
) -> SkinnedInstance:
    """``character`` in the pose ``(root [3], rotations [J,4])`` of ``skeleton`` (the puppet's), at its size.

    Raises:
        ValueError: ``skeleton`` has other joints than the character's roles.
    """
    own = character.rig.skeleton
    if skeleton.names != own.names:
        raise ValueError("the pose is not of the puppet's skeleton: the character cannot play it")
    s = float(skeleton.offsets[0, 1] / own.offsets[0, 1])
    pos, rot = forward_kinematics(own, np.asarray(root, dtype=np.float64) / s, rotations)
    grow = np.diag([s, s, s, 1.0])
    return SkinnedInstance(character.binding.meshes, grow @ character.binding.matrices(pos, rot), outline=outline)
