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
# Capsule rows per snowman, in the order _snowman_rows fills them: two legs (thigh,
# shin, foot), two twig arms (three segments each), the nose.
_CAPSULE_COLORS = np.array([_SNOW] * 6 + [_TWIG] * 6 + [_CARROT])
_EYES = np.array([[0.35, 0.25, 0.88], [-0.35, 0.25, 0.88]])
_NOSE = np.array([[0.0, 0.0, 0.9], [0.0, -0.05, 1.6]])
_BUTTONS = np.array([[0.0, 0.45 * k, 0.95] for k in (-0.6, 0.0, 0.6)])


def _joint_indices(sk: Skeleton) -> dict[str, list[int]]:
    """The joints a snowman is drawn from, looked up once per rig."""
    j = sk.index
    return {
        "legs": [j(f"{side}_{bone}") for side in "lr" for bone in _LEG],
        "arms": [j(f"{side}_{bone}") for side in "lr" for bone in _ARM],
        "body": [j("hips"), j("spine"), j("chest"), j("head")],
    }


def _snowman_rows(
    snowman: Snowman, sk: Skeleton, pos: np.ndarray, rot: np.ndarray, joints: dict[str, list[int]]
) -> tuple[np.ndarray, ...]:
    """One snowman's capsules (a, b, radius) and spheres (centre, radius, is-a-ball)."""
    shape = snowman.shape
    hips_i, spine_i, chest_i, head_i = joints["body"]
    legs, arms = joints["legs"], joints["arms"]
    hips, chest, head = pos[hips_i], pos[chest_i], pos[head_i]
    rh = shape.head
    spine_len = float(np.linalg.norm(sk.offsets[spine_i]) + np.linalg.norm(sk.offsets[chest_i]))
    feet, hands = [legs[2], legs[5]], [arms[2], arms[5]]
    # Every offset that turns with a bone, rotated in one call: foot and hand tips, the
    # spine's "up" (Eq. 6.4's p_up), eyes and nose on the head, buttons on the chest.
    local = np.vstack(
        [
            sk.tips[feet],
            sk.tips[hands],
            [[0.0, spine_len, 0.0]],
            _EYES * rh,
            _NOSE * rh,
            _BUTTONS * (shape.middle or 0.0),
        ]
    )
    turn = rot[feet + hands + [hips_i] + [head_i] * 4 + [chest_i] * 3]
    moved = quat.rotate(turn, local)
    foot_tips, hand_tips, up = pos[feet] + moved[0:2], pos[hands] + moved[2:4], hips + moved[4]
    eyes, nose = head + moved[5:7], head + moved[7:9]
    leg_a = np.vstack([pos[legs[0:3]], pos[legs[3:6]]])
    leg_b = np.vstack([pos[legs[1:3]], foot_tips[0:1], pos[legs[4:6]], foot_tips[1:2]])
    arm_pts = [np.vstack([pos[arms[k : k + 3]], hand_tips[k // 3]]) for k in (0, 3)]
    cap_a = np.vstack([leg_a, arm_pts[0][:-1], arm_pts[1][:-1], nose[0:1]])
    cap_b = np.vstack([leg_b, arm_pts[0][1:], arm_pts[1][1:], nose[1:2]])
    cap_r = np.concatenate([sk.radii[legs], np.full(6, sk.radii[arms[0]]), [0.07 * rh]])
    centres, radii = [hips], [shape.bottom]
    if shape.middle is not None:
        centres.append(bezier_spine(hips, chest, up, middle_ball_parameter(shape)))
        radii.append(shape.middle)
    centres.append(head)
    radii.append(rh)
    n_balls = len(centres)
    centres += list(eyes)
    radii += [0.1 * rh] * 2
    if shape.middle is not None:
        centres += list(centres[1] + moved[9:12])
        radii += [0.08 * shape.middle] * 3
    is_ball = np.arange(len(radii)) < n_balls
    return cap_a, cap_b, cap_r, np.array(centres), np.array(radii), is_ball


def draw_snowmen(world: World, scene: RenderScene, alpha: float, outlined: set[int]) -> None:
    """Every living snowman, from its joints, added to the scene in one call per primitive.

    Gathering the rows first matters: a snowman is ~20 primitives, and adding them one
    call at a time cost more than a millisecond a frame with six snowmen on the field.
    """
    caps: list[tuple[np.ndarray, ...]] = []
    spheres: list[tuple[np.ndarray, ...]] = []
    for e, snowman, puppet, wp in world.query(Snowman, Puppet, WorldPose):
        sk = puppet.skeleton
        pos, rot = wp.interpolated(alpha)
        cap_a, cap_b, cap_r, centres, radii, is_ball = _snowman_rows(snowman, sk, pos, rot, _joint_indices(sk))
        caps.append((cap_a, cap_b, cap_r, _CAPSULE_COLORS))
        colors = np.where(is_ball[:, None], _SNOW, _COAL)
        spheres.append((centres, radii, colors, is_ball & (e in outlined)))
    if caps:
        a, b, r, col = (np.concatenate(x) for x in zip(*caps))
        scene.add_capsules(a, b, r, color=col)
        c, r, col, out = (np.concatenate(x) for x in zip(*spheres))
        scene.add_spheres(c, r, color=col, outline=out)


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
