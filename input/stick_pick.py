"""What the MotionStick points at: grab spheres, and the bodies of posed puppets.

A puppet's :class:`~engine.components.Grabbable` sphere sits at its hips, so a press on its
feet or its head missed it although the cursor was on the puppet: a person points at what
they see. A grabbable that is also a posed skeleton (``Puppet`` + ``WorldPose``) is therefore
picked by the capsules it is drawn with (:func:`~engine.render.extract.puppet_capsules`),
widened by :data:`PICK_MARGIN` so thin limbs are not a needle to thread, as well as by its
sphere. A lying ragdoll is picked where it lies, not where its hips stood.

Whatever part is hit, the stick holds the grabbable's anchor (the hips): which thing is
grabbed depends on the part pointed at, how it hangs does not.

Bodies are first tested as a whole against the sphere round their root that holds every
bone in any pose (the longest chain from the root plus the widest bone), so only the puppets
the ray passes near pay for their capsules.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from engine.arrays import F64 as F
from engine.arrays import Bool
from engine.components import Grabbable, Puppet, Transform, WorldPose
from engine.ecs import Entity, World
from engine.render.extract import puppet_capsules
from engine.skeleton import Skeleton
from input.stick_geometry import pick, pick_capsules

__all__ = ["PICK_MARGIN", "stick_target"]

PICK_MARGIN = 0.04
"""Metres added to every bone's radius for picking (a forearm is ~5 cm thick on screen)."""


def stick_target(
    world: World,
    grabbables: Sequence[tuple[Entity, Grabbable, Transform]],
    origin: F,
    direction: F,
    max_distance: float,
    skip: Entity | None = None,
) -> tuple[Entity, float] | None:
    """The grabbable the ray ``origin + t·direction`` meets first (``skip`` aside), and its ``t``."""
    rows = [(g, gr, tr) for g, gr, tr in grabbables if g != skip]
    if not rows:
        return None
    best: tuple[Entity, float] | None = None
    hit = pick(
        origin,
        direction,
        np.array([gr.anchor(tr) for _, gr, tr in rows]),
        np.array([gr.radius for _, gr, _ in rows]),
        max_distance,
    )
    if hit is not None:
        best = (rows[hit[0]][0], hit[1])
    for entity, t in _body_hits(world, [g for g, _, _ in rows], origin, direction, max_distance):
        if best is None or t < best[1]:
            best = (entity, t)
    return best


def _body_hits(
    world: World, entities: list[Entity], origin: F, direction: F, max_distance: float
) -> list[tuple[Entity, float]]:
    """The first hit on each posed body the ray passes through."""
    poses = world.components(WorldPose)
    puppets = world.components(Puppet)
    groups: dict[int, tuple[Skeleton, list[Entity], list[WorldPose]]] = {}
    for g in entities:
        pose, puppet = poses.get(g), puppets.get(g)
        if pose is None or puppet is None:
            continue
        group = groups.setdefault(id(puppet.skeleton), (puppet.skeleton, [], []))
        group[1].append(g)
        group[2].append(pose)
    hits: list[tuple[Entity, float]] = []
    for skeleton, members, member_poses in groups.values():
        positions = np.stack([p.positions for p in member_poses])
        rotations = np.stack([p.rotations for p in member_poses])
        if positions.shape[1] != skeleton.num_joints:
            continue  # a pose not of this skeleton is not drawn as it either
        roots = positions[:, 0]
        reach = np.max(np.linalg.norm(positions - roots[:, None], axis=-1), axis=1) + _bone_extent(skeleton)
        near = _ray_meets_spheres(origin, direction, roots, reach, max_distance)
        for k in np.nonzero(near)[0]:
            a, b, radius, _ = puppet_capsules(skeleton, positions[k], rotations[k])
            hit = pick_capsules(origin, direction, a, b, radius + PICK_MARGIN, max_distance)
            if hit is not None:
                hits.append((members[k], hit[1]))
    return hits


def _bone_extent(skeleton: Skeleton) -> float:
    """How far past its joint a bone's surface reaches: the longest leaf tip plus the widest bone and the margin."""
    tips = np.linalg.norm(skeleton.tips, axis=1)
    return float((tips.max() if len(tips) else 0.0) + skeleton.radii.max() + PICK_MARGIN)


def _ray_meets_spheres(origin: F, direction: F, centers: F, radii: F, max_distance: float) -> Bool:
    """Which spheres the ray segment ``[0, max_distance]`` touches (a broad phase: no ordering)."""
    oc = centers - origin
    along = np.clip(oc @ direction, 0.0, max_distance)
    gap = oc - along[:, None] * direction
    result: Bool = np.einsum("ij,ij->i", gap, gap) <= radii * radii
    return result
