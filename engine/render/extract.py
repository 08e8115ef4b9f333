"""From the world to a :class:`RenderScene`: what the render step reads each frame.

Rendering runs between simulation steps and interpolates: every puppet is drawn at
``WorldPose.interpolated(alpha)``, ``alpha`` being how far the wall clock is between the
previous and the current step. Nothing here writes the world.

- Puppets (``Puppet`` + ``WorldPose``): one capsule per bone, from each parent joint to
  its child (the parent's radius along a chain, the child's on a side branch such as a
  collar bone), and for leaf joints (those with a ``tips``
  offset: head, hands, feet) from the joint towards its tip, ending at the tip.
- Props (``Transform`` + ``Shape``): a sphere, capsule or box.

Colours and outlines come from an optional ``Appearance``; entities whose appearance is
not ``visible`` are skipped.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import I64 as _Idx
from engine.columns import Columns
from engine.components import Puppet, Transform, WorldPose
from engine.ecs import World
from engine.render.components import Appearance, Shape
from engine.render.scene import RenderScene
from engine.skeleton import Skeleton

__all__ = ["scene_from_world", "puppet_capsules", "pose_arrays"]

_DEFAULT_PUPPET = Appearance()
_DEFAULT_PROP = Appearance(color=(0.95, 0.96, 0.98))


@lru_cache(maxsize=64)
def _bones(parents: bytes, tips: bytes) -> tuple[_Idx, _Idx, _Idx, _Idx]:
    """Per bone: parent joint, child joint, the joint whose radius it takes; and the leaf joints."""
    par = np.frombuffer(parents, dtype=np.int64)
    tip = np.frombuffer(tips, dtype=np.float64).reshape(-1, 3)
    child = np.arange(1, len(par))
    # The first child continues the parent's chain (spine, neck, arm, leg) and takes the
    # parent's thickness; side branches (collar bones, hip sockets) take the child's.
    first = np.array([par[c] >= 0 and np.nonzero(par == par[c])[0][0] == c for c in child], dtype=bool)
    owner = np.where(first, par[child], child)
    leaves = np.nonzero(np.linalg.norm(tip, axis=1) > 1e-9)[0]
    return par[child], child, owner, leaves


def puppet_capsules(
    skeleton: Skeleton, positions: NDArray[np.float64], rotations: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Capsules ``(a [B,3], b [B,3], radius [B], joint [B])`` of one posed puppet.

    ``joint`` is the joint whose radius (and per-joint colour) each capsule takes.
    Several puppets of one skeleton at once: ``positions [P,J,3]``, ``rotations [P,J,4]``
    give ``a``, ``b`` as ``[P,B,3]`` and ``radius`` as ``[P,B]`` (``joint`` stays ``[B]``).
    """
    leaves = _bones(skeleton.parents.tobytes(), skeleton.tips.tobytes())[3]
    return _capsules(skeleton, np.asarray(positions, dtype=np.float64), np.asarray(rotations)[..., leaves, :])


def _capsules(
    skeleton: Skeleton, pos: NDArray[np.float64], leaf_rotations: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """:func:`puppet_capsules` given only the leaf joints' rotations (the only ones a capsule reads)."""
    parent, child, bone_owner, leaves = _bones(skeleton.parents.tobytes(), skeleton.tips.tobytes())
    lead = pos.shape[:-2]
    a = [pos[..., parent, :]]
    b = [pos[..., child, :]]
    r = [np.broadcast_to(skeleton.radii[bone_owner], (*lead, len(bone_owner)))]
    owner = [bone_owner]
    if len(leaves):
        start = pos[..., leaves, :]
        tip = quat.rotate(np.asarray(leaf_rotations, dtype=np.float64), skeleton.tips[leaves])
        length = np.linalg.norm(tip, axis=-1, keepdims=True)
        rad = skeleton.radii[leaves]
        # End the capsule's surface at the tip rather than its core segment.
        keep = np.maximum(length - rad[:, None], 0.0) / np.maximum(length, 1e-12)
        a.append(start)
        b.append(start + tip * keep)
        r.append(np.broadcast_to(rad, (*lead, len(leaves))))
        owner.append(leaves)
    return (np.concatenate(a, axis=-2), np.concatenate(b, axis=-2), np.concatenate(r, axis=-1), np.concatenate(owner))


_WORLD_FIELDS = ("positions", "rotations", "prev_positions", "prev_rotations")


def pose_arrays(world: World, poses: Sequence[WorldPose], joints: int) -> tuple[NDArray[np.float64], ...]:
    """``positions, rotations, prev_positions, prev_rotations`` of ``poses`` (all of ``joints`` joints) as
    ``[P,J,...]`` arrays, in that order. Read only: never change them.

    When the poses are exactly a crowd's batch as FK keeps it (:mod:`engine.columns`, the same poses in
    the same order, no field replaced since), these are the columns themselves: no per-puppet Python.
    Otherwise (a puppet hidden, a skeleton of its own, a pose assigned by other code) they are stacked
    from the components, as before."""
    cols = world.try_resource(Columns)
    linked = [] if cols is None else [cols.get(WorldPose, name, joints).linked(poses) for name in _WORLD_FIELDS]
    if linked and all(base is not None and len(base) == len(poses) for base in linked):
        return tuple(base for base in linked if base is not None)
    return tuple(np.stack([getattr(w, name) for w in poses]) for name in _WORLD_FIELDS)


def _add_puppets(
    scene: RenderScene, world: World, skeleton: Skeleton, poses: list[WorldPose], looks: list[Appearance], alpha: float
) -> None:
    """Capsules of puppets sharing ``skeleton``, posed and interpolated together, in one call.

    A crowd of a thousand cost half a second a frame puppet by puppet (an interpolation
    and a capsule fill each, in small numpy calls); stacked, it is a few dozen calls, and a
    crowd's poses are read straight from its columns (:func:`pose_arrays`). Rotations are
    interpolated only at the leaf joints, the only ones a capsule reads (its tip's direction).
    """
    positions, rotations, prev_positions, prev_rotations = pose_arrays(world, poses, skeleton.num_joints)
    leaves = _bones(skeleton.parents.tobytes(), skeleton.tips.tobytes())[3]
    pos = prev_positions + alpha * (positions - prev_positions)
    rot = quat.nlerp(prev_rotations[:, leaves], rotations[:, leaves], alpha)
    a, b, r, owner = _capsules(skeleton, pos, rot)
    bones = len(owner)
    if all(look.joint_colors is None for look in looks):
        color = np.broadcast_to(np.array([look.color for look in looks])[:, None, :], (len(poses), bones, 3))
    else:
        color = np.empty((len(poses), bones, 3))
        for i, look in enumerate(looks):
            color[i] = look.color if look.joint_colors is None else np.asarray(look.joint_colors)[owner]
    outline = np.repeat([float(look.outline) for look in looks], bones)
    scene.add_capsules(a.reshape(-1, 3), b.reshape(-1, 3), r.reshape(-1), color.reshape(-1, 3), outline)


def scene_from_world(world: World, alpha: float, scene: RenderScene | None = None) -> RenderScene:
    """Append every visible puppet and prop of ``world`` to ``scene`` (a new one if ``None``).

    Args:
        world: the simulation world (read only).
        alpha: interpolation in ``[0, 1]`` between the previous and the current step.
        scene: the scene to append to; call ``scene.clear()`` first to reuse one per frame.
    """
    if not 0.0 <= alpha <= 1.0:
        raise ValueError(f"alpha must be in [0, 1], got {alpha}")
    scene = RenderScene() if scene is None else scene
    # Runs of consecutive puppets whose skeletons have the same bones and radii (each puppet may hold
    # its own copy) are drawn together; the order of the rows is kept.
    runs: list[tuple[Skeleton, list[WorldPose], list[Appearance]]] = []
    run_key = b""
    for e, puppet, wpose in world.query(Puppet, WorldPose):
        look = world.try_get(e, Appearance) or _DEFAULT_PUPPET
        if not look.visible:
            continue
        sk = puppet.skeleton
        key = b"|".join((sk.parents.tobytes(), sk.tips.tobytes(), sk.radii.tobytes()))
        if not runs or key != run_key:
            runs.append((sk, [], []))
            run_key = key
        runs[-1][1].append(wpose)
        runs[-1][2].append(look)
    for skeleton, poses, looks in runs:
        _add_puppets(scene, world, skeleton, poses, looks, alpha)
    for e, tf, shape in world.query(Transform, Shape):
        look = world.try_get(e, Appearance) or _DEFAULT_PROP
        if not look.visible:
            continue
        s = float(tf.scale)
        if shape.kind == "sphere":
            scene.add_sphere(tf.position, shape.size[0] * s, look.color, look.outline)
        elif shape.kind == "capsule":
            axis = quat.rotate(tf.rotation, np.array([0.0, shape.size[1] * s, 0.0]))
            scene.add_capsule(tf.position - axis, tf.position + axis, shape.size[0] * s, look.color, look.outline)
        else:
            scene.add_box(tf.position, shape.size * s, tf.rotation, look.color, look.outline)
    return scene
