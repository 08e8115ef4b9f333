"""Drawing the snowman game: field, marks, balls, the default puppet and the snowmen.

A snowman is drawn from its puppet's interpolated joints: the bottom ball at the
hips, the head ball at the head, and the middle ball on the quadratic Bézier spine
between pelvis and chest (Eq. 6.4), so a bending snowman curves smoothly; twig arms
along the arm bones, coal eyes and buttons, a carrot nose.
"""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.components import Puppet, WorldPose
from engine.ecs import World
from engine.render.scene import GroundMarks, RenderScene
from engine.skeleton import Skeleton
from games.common import draw_world
from games.snowman.bent_scenery import BentScenery
from games.snowman.components import Snowman
from games.snowman.footprints import Footprints
from games.snowman.rig import bezier_spine, middle_ball_parameter
from games.snowman.scenery import draw_snowfall, draw_trees
from games.snowman.snow import SnowField

__all__ = ["draw_snowman_game", "draw_snowman_state", "draw_snowmen"]

_TWIG = (0.35, 0.22, 0.12)
_COAL = (0.08, 0.08, 0.09)
_CARROT = (0.95, 0.45, 0.1)
_SNOW = (0.97, 0.98, 1.0)


_LEG = ("upper_leg", "lower_leg", "foot")
_ARM = ("upper_arm", "lower_arm", "hand")
# Capsule rows per snowman, in the order _snowmen_rows fills them: two legs (thigh,
# shin, foot), two twig arms (three segments each), the nose.
_CAPSULE_COLORS = np.array([_SNOW] * 6 + [_TWIG] * 6 + [_CARROT])
_EYES = np.array([[0.35, 0.25, 0.88], [-0.35, 0.25, 0.88]])
_NOSE = np.array([[0.0, 0.0, 0.9], [0.0, -0.05, 1.6]])
_BUTTONS = np.array([[0.0, 0.45 * k, 0.95] for k in (-0.6, 0.0, 0.6)])
# The 16 joints gathered per snowman, in this order (columns of P and R in _snowmen_rows).
_LEGS, _ARMS = slice(0, 6), slice(6, 12)
_FEET, _HANDS, _HIPS, _CHEST, _HEAD = [2, 5], [8, 11], 12, 14, 15
# Which gathered joint turns each local offset: foot and hand tips, the spine's "up", eyes, nose, buttons.
_TURN = [*_FEET, *_HANDS, _HIPS, _HEAD, _HEAD, _HEAD, _HEAD, _CHEST, _CHEST, _CHEST]
# Sphere slots per snowman: bottom, middle, head, two eyes, three buttons; the first three are balls.
_BALL_SLOT = np.array([True, True, True, False, False, False, False, False])
_MIDDLE_SLOT = np.array([False, True, False, False, False, True, True, True])


def _joint_indices(sk: Skeleton) -> list[int]:
    """The 16 joints a snowman is drawn from (legs, arms, then hips, spine, chest, head)."""
    j = sk.index
    legs = [j(f"{side}_{bone}") for side in "lr" for bone in _LEG]
    arms = [j(f"{side}_{bone}") for side in "lr" for bone in _ARM]
    return [*legs, *arms, j("hips"), j("spine"), j("chest"), j("head")]


def _interpolated(poses: list[WorldPose], alpha: float) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """:meth:`WorldPose.interpolated` of every pose in one pass (the same numbers: both are elementwise)."""
    counts = np.cumsum([len(wp.positions) for wp in poses])[:-1]
    prev_p = np.concatenate([wp.prev_positions for wp in poses])
    pos = prev_p + alpha * (np.concatenate([wp.positions for wp in poses]) - prev_p)
    rot = quat.nlerp(
        np.concatenate([wp.prev_rotations for wp in poses]), np.concatenate([wp.rotations for wp in poses]), alpha
    )
    return np.split(pos, counts), np.split(rot, counts)


def _snowmen_rows(
    shapes: list[Snowman], skeletons: list[Skeleton], poses: list[np.ndarray], rotations: list[np.ndarray]
) -> tuple[np.ndarray, ...]:
    """Every snowman's capsules ``(a, b, radius)`` ``[S, 13, ...]`` and sphere slots ``(centre, radius, used)``
    ``[S, 8, ...]`` (slots of the middle ball and its buttons unused on a two-ball snowman), all at once.

    The per-snowman part is only gathering (joints, tips, radii); the geometry runs as
    array operations over all snowmen, since a snowman is ~20 primitives and computing
    them one snowman at a time cost a third of a millisecond each.
    """
    n = len(shapes)
    idx = [_joint_indices(sk) for sk in skeletons]
    P = np.stack([p[i] for p, i in zip(poses, idx, strict=True)])
    R = np.stack([r[i] for r, i in zip(rotations, idx, strict=True)])
    rh = np.array([sm.shape.head for sm in shapes])
    bottom = np.array([sm.shape.bottom for sm in shapes])
    has_middle = np.array([sm.shape.middle is not None for sm in shapes])
    middle = np.array([sm.shape.middle or 0.0 for sm in shapes])
    t_middle = np.array([middle_ball_parameter(sm.shape) for sm in shapes])
    rigs = list(zip(skeletons, idx, strict=True))
    tips = np.stack([sk.tips[[i[k] for k in (*_FEET, *_HANDS)]] for sk, i in rigs])
    spine_len = np.array([np.linalg.norm(sk.offsets[i[13]]) + np.linalg.norm(sk.offsets[i[14]]) for sk, i in rigs])
    leg_r = np.stack([sk.radii[i[_LEGS]] for sk, i in rigs])
    arm_r = np.array([sk.radii[i[6]] for sk, i in rigs])
    # Every offset that turns with a bone, rotated in one call: foot and hand tips, the
    # spine's "up" (Eq. 6.4's p_up), eyes and nose on the head, buttons on the chest.
    up = np.zeros((n, 1, 3))
    up[:, 0, 1] = spine_len
    local = np.concatenate(
        [tips, up, _EYES * rh[:, None, None], _NOSE * rh[:, None, None], _BUTTONS * middle[:, None, None]], axis=1
    )
    moved = quat.rotate(R[:, _TURN], local)
    foot_tips, hand_tips = P[:, _FEET] + moved[:, 0:2], P[:, _HANDS] + moved[:, 2:4]
    hips, chest, head = P[:, _HIPS], P[:, _CHEST], P[:, _HEAD]
    nose = head[:, None] + moved[:, 7:9]
    legs, arms = P[:, _LEGS], P[:, _ARMS]
    cap_a = np.concatenate([legs, arms, nose[:, 0:1]], axis=1)
    ends = [legs[:, 1:3], foot_tips[:, 0:1], legs[:, 4:6], foot_tips[:, 1:2]]
    ends += [arms[:, 1:3], hand_tips[:, 0:1], arms[:, 4:6], hand_tips[:, 1:2], nose[:, 1:2]]
    cap_b = np.concatenate(ends, axis=1)
    cap_r = np.concatenate([leg_r, np.repeat(arm_r[:, None], 6, axis=1), 0.07 * rh[:, None]], axis=1)
    mid = bezier_spine(hips, chest, hips + moved[:, 4], t_middle)[:, None]
    centres = np.concatenate(
        [hips[:, None], mid, head[:, None], head[:, None] + moved[:, 5:7], mid + moved[:, 9:12]], 1
    )
    radii = np.stack([bottom, middle, rh, 0.1 * rh, 0.1 * rh, *(3 * [0.08 * middle])], axis=1)
    used = ~_MIDDLE_SLOT | has_middle[:, None]
    return cap_a, cap_b, cap_r, centres, radii, used


def draw_snowmen(world: World, scene: RenderScene, alpha: float, outlined: set[int]) -> None:
    """Every living snowman, from its joints, added to the scene in one call per primitive.

    Gathering the rows first matters: a snowman is ~20 primitives, and adding them one
    call at a time cost more than a millisecond a frame with six snowmen on the field.
    """
    found = [(e, snowman, puppet.skeleton, wp) for e, snowman, puppet, wp in world.query(Snowman, Puppet, WorldPose)]
    if not found:
        return
    entities, shapes, skeletons, poses = (list(x) for x in zip(*found, strict=True))
    pos, rot = _interpolated(poses, alpha)
    cap_a, cap_b, cap_r, centres, radii, used = _snowmen_rows(shapes, skeletons, pos, rot)
    n = len(found)
    colors = np.tile(_CAPSULE_COLORS, (n, 1))
    scene.add_capsules(cap_a.reshape(-1, 3), cap_b.reshape(-1, 3), cap_r.reshape(-1), color=colors)
    is_ball = np.broadcast_to(_BALL_SLOT, used.shape)
    lit = is_ball & np.array([e in outlined for e in entities])[:, None]
    scene.add_spheres(
        centres[used], radii[used], color=np.where(is_ball[used][:, None], _SNOW, _COAL), outline=lit[used]
    )


def draw_snowman_state(world: World, scene: RenderScene, alpha: float) -> None:
    """Puppets, snowballs, snowmen, sticks, trees and the tracks and footprints in the snow: what the phone is
    streamed every step (everything but the falling snow, which the phone gets once as
    :data:`~games.snowman.scenery.SNOWFALL` and moves by the step it shows)."""
    from engine.components import Stick

    draw_world(world, scene, alpha)
    outlined = {s.focus for _, s in world.query(Stick) if s.focus is not None and s.grabbed is None}
    outlined |= {s.grabbed for _, s in world.query(Stick) if s.grabbed is not None}
    draw_snowmen(world, scene, alpha, outlined)
    draw_trees(scene, world.try_resource(BentScenery))
    scene.ground.grid = False  # a field of snow, not a floor
    field = world.try_resource(SnowField)
    if field is not None:
        taken = 1.0 - field.depth / field.initial_depth  # [x, z] → the marks' [z, x]
        scene.marks = GroundMarks(taken.T.astype(np.float32), -field.size / 2, -field.size / 2, field.cell)
    _draw_prints_in_place(world, scene)


def _draw_prints_in_place(world: World, scene: RenderScene) -> None:
    """Every footprint ever stamped, in its ring slot, a filled one at zero size.

    The same prints as :func:`~games.snowman.footprints.draw_footprints` draws, but rows
    that keep their place: when the oldest print fills, the phone's stream would
    otherwise see every later row move up one and resend them all.
    """
    prints = world.try_resource(Footprints)
    if prints is None or prints.count == 0:
        return
    used = np.nonzero(prints.frame >= 0)[0]
    age = (world.frame - prints.frame[used]) * world.dt
    strength = np.clip(1.0 - (age - prints.fade_start) / prints.fade_time, 0.0, 1.0)
    size = (strength > 0.0).astype(np.float64)
    start = len(scene.prints)
    scene.add_prints(prints.xz[used], prints.heading[used], strength=strength)
    scene.prints.data[start:, 4:6] *= size[:, None]


def draw_snowman_game(world: World, scene: RenderScene, alpha: float) -> None:
    """The whole game view: the state (tracks and footprints included), falling snow."""
    draw_snowman_state(world, scene, alpha)
    draw_snowfall(scene, (world.frame + alpha) * world.dt)
