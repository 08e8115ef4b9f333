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

import operator
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import I64 as _Idx
from engine.batches import batch
from engine.columns import Columns
from engine.components import Puppet, Transform, WorldPose
from engine.ecs import World
from engine.render.components import Appearance, Shape
from engine.render.scene import RenderScene
from engine.skeleton import Skeleton

__all__ = ["scene_from_world", "puppet_capsules", "pose_arrays", "DrawnRuns"]

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


class DrawnRuns:
    """Resource: the runs :func:`_puppet_runs` found last, and the skeleton objects they were found for. Only
    how the drawing groups the puppets: never hashed."""

    SIM_STATE = False

    def __init__(self) -> None:
        self.skeletons: list[Skeleton] = []
        self.bounds: list[tuple[int, int]] = []


_SKELETON = operator.attrgetter("skeleton")
_VISIBLE = operator.attrgetter("visible")


def _look(appearance: Appearance | None) -> Appearance:
    return _DEFAULT_PUPPET if appearance is None else appearance


def _skeleton_key(sk: Skeleton) -> bytes:
    return b"|".join((sk.parents.tobytes(), sk.tips.tobytes(), sk.radii.tobytes()))


def _puppet_runs(world: World) -> list[tuple[Skeleton, list[WorldPose], list[Appearance]]]:
    """The visible puppets in entity order, in runs of consecutive ones whose skeletons have the same bones and
    radii (each puppet may hold its own copy): each run is drawn in one call.

    The puppets are a kept batch (:mod:`engine.batches`), and their runs are kept with the skeleton objects they
    were found for (:class:`DrawnRuns`): while every puppet holds the same skeleton and all are visible, a frame
    finds them in a few C-level passes, where comparing the bytes of each puppet's skeleton, a thousand
    puppets' every frame, cost more than their interpolation."""
    kept = batch(world, "drawn puppets", (Puppet, WorldPose), (Appearance,))
    puppets, poses, appearances = kept.lists
    looks = list(map(_look, appearances))
    if not all(map(_VISIBLE, looks)):
        shown = [i for i, look in enumerate(looks) if look.visible]
        skeletons = [puppets[i].skeleton for i in shown]
        return [
            (skeletons[a], [poses[shown[i]] for i in range(a, b)], [looks[shown[i]] for i in range(a, b)])
            for a, b in _bounds(skeletons)
        ]
    skeletons = list(map(_SKELETON, puppets))
    memo = world.try_resource(DrawnRuns)
    if memo is None:
        memo = DrawnRuns()
        world.insert_resource(memo)
    if len(memo.skeletons) != len(skeletons) or not all(map(operator.is_, memo.skeletons, skeletons)):
        memo.skeletons, memo.bounds = skeletons, _bounds(skeletons)
    return [(skeletons[a], list(poses[a:b]), looks[a:b]) for a, b in memo.bounds]


def _bounds(skeletons: Sequence[Skeleton]) -> list[tuple[int, int]]:
    """``[start, end)`` of each run of consecutive skeletons with the same bones and radii."""
    keys = [_skeleton_key(sk) for sk in skeletons]
    starts = [i for i in range(len(keys)) if i == 0 or keys[i] != keys[i - 1]]
    return list(zip(starts, starts[1:] + [len(keys)] if keys else [], strict=True))


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
    for skeleton, poses, looks in _puppet_runs(world):
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
