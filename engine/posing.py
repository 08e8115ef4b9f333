"""The FK stage: turn every puppet's ``LocalPose`` into a ``WorldPose``, batched.

Puppets that share a hierarchy (the default humanoid, every snowman) are stacked
into one array and go through :func:`engine.fk.forward_kinematics` together, so a
hundred puppets cost one batched call per depth level, not a hundred FK passes.
The previous world pose is kept for render interpolation.
"""

from __future__ import annotations

import numpy as np

from engine.app import App
from engine.components import LocalPose, Puppet, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics

__all__ = ["fk_system", "install_fk"]


def fk_system(world: World) -> None:
    """Compute world joint transforms for every puppet with a ``LocalPose``."""
    groups: dict[bytes, list[tuple[int, Puppet, LocalPose]]] = {}
    for e, puppet, local in world.query(Puppet, LocalPose):
        groups.setdefault(puppet.skeleton.parents.tobytes(), []).append((e, puppet, local))
    for members in groups.values():
        skeleton = members[0][1].skeleton
        roots = np.array([m[2].root for m in members], dtype=np.float64)
        rots = np.array([m[2].rotations for m in members], dtype=np.float64)
        offsets = np.array([m[1].joint_offsets() for m in members], dtype=np.float64)
        pos, rot = forward_kinematics(skeleton, roots, rots, offsets)
        for k, (e, _, _) in enumerate(members):
            wp = world.try_get(e, WorldPose)
            if wp is None:
                world.add(e, WorldPose(pos[k], rot[k], pos[k].copy(), rot[k].copy()))
            else:
                wp.prev_positions, wp.prev_rotations = wp.positions, wp.rotations
                wp.positions, wp.rotations = pos[k], rot[k]


def install_fk(app: App) -> None:
    """Plugin: the batched FK system in the ``fk`` stage."""
    app.add_system("fk", fk_system)
