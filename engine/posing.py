"""The FK stage: turn every puppet's ``LocalPose`` into a ``WorldPose``, batched.

Puppets that share a hierarchy (the default humanoid, every snowman) are stacked
into one array and go through :func:`engine.fk.forward_kinematics` together, so a
hundred puppets cost one batched call per depth level, not a hundred FK passes.
The previous world pose is kept for render interpolation.
"""

from __future__ import annotations

from engine.app import App
from engine.columns import columns
from engine.components import LocalPose, Puppet, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics

__all__ = ["fk_system", "install_fk"]


def fk_system(world: World) -> None:
    """Compute world joint transforms for every puppet with a ``LocalPose``."""
    groups: dict[bytes, list[tuple[int, Puppet, LocalPose]]] = {}
    for e, puppet, local in world.query(Puppet, LocalPose):
        groups.setdefault(puppet.skeleton.parents.tobytes(), []).append((e, puppet, local))
    cols = columns(world)
    world_poses = world.components(WorldPose)
    for key, members in groups.items():
        skeleton = members[0][1].skeleton
        joints = skeleton.num_joints
        locals_ = [m[2] for m in members]
        roots = cols.get(LocalPose, "root", joints).read(locals_)
        rots = cols.get(LocalPose, "rotations", joints).read(locals_)
        offsets = cols.stacked(("offsets", key))([m[1].joint_offsets() for m in members])
        pos, rot = forward_kinematics(skeleton, roots, rots, offsets)
        poses = [world_poses.get(e) for e, _, _ in members]
        if None in poses:  # a puppet's first pose
            for k, (e, _, _) in enumerate(members):
                if poses[k] is None:
                    world.add(e, WorldPose(pos[k], rot[k], pos[k].copy(), rot[k].copy()))
            poses = [world_poses[e] for e, _, _ in members]
        # The previous step is kept for render interpolation: copied into its own columns, as
        # this step's values are written over the last step's in place.
        for field in ("positions", "rotations"):
            now = cols.get(WorldPose, field, joints)
            cols.get(WorldPose, f"prev_{field}", joints).write(poses, now.read(poses))
        cols.get(WorldPose, "positions", joints).write(poses, pos)
        cols.get(WorldPose, "rotations", joints).write(poses, rot)


def install_fk(app: App) -> None:
    """Plugin: the batched FK system in the ``fk`` stage."""
    app.add_system("fk", fk_system)
