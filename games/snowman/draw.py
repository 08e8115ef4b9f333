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
from engine.render.scene import RenderScene
from games.common import draw_world
from games.snowman.components import Snowman
from games.snowman.rig import bezier_spine, middle_ball_parameter
from games.snowman.scenery import draw_snowfall, draw_trees
from games.snowman.snow import SnowField

__all__ = ["draw_snowman_game", "draw_snowmen"]

_TWIG = (0.35, 0.22, 0.12)
_COAL = (0.08, 0.08, 0.09)
_CARROT = (0.95, 0.45, 0.1)
_SNOW = (0.97, 0.98, 1.0)


def draw_snowmen(world: World, scene: RenderScene, alpha: float, outlined: set[int]) -> None:
    """Every living snowman, from its joints."""
    for e, snowman, puppet, wp in world.query(Snowman, Puppet, WorldPose):
        sk = puppet.skeleton
        pos, rot = wp.interpolated(alpha)
        j = sk.index
        shape = snowman.shape
        hips, chest, head = pos[j("hips")], pos[j("chest")], pos[j("head")]
        spine_len = float(np.linalg.norm(sk.offsets[j("spine")]) + np.linalg.norm(sk.offsets[j("chest")]))
        up = hips + quat.rotate(rot[j("hips")], np.array([0.0, spine_len, 0.0]))
        balls = [(hips, shape.bottom)]
        if shape.middle is not None:
            balls.append((bezier_spine(hips, chest, up, middle_ball_parameter(shape)), shape.middle))
        balls.append((head, shape.head))
        centers = np.array([b[0] for b in balls])
        radii = np.array([b[1] for b in balls])
        scene.add_spheres(centers, radii, color=_SNOW, outline=e in outlined)
        # Legs peek out under the bottom ball.
        for side in ("l", "r"):
            chain = [j(f"{side}_upper_leg"), j(f"{side}_lower_leg"), j(f"{side}_foot")]
            scene.add_capsules(pos[chain[:-1]], pos[chain[1:]], sk.radii[chain[:-1]], color=_SNOW)
            foot_tip = pos[chain[-1]] + quat.rotate(rot[chain[-1]], sk.tips[chain[-1]])
            scene.add_capsule(pos[chain[-1]], foot_tip, float(sk.radii[chain[-1]]), color=_SNOW)
            arm = [j(f"{side}_upper_arm"), j(f"{side}_lower_arm"), j(f"{side}_hand")]
            hand_tip = pos[arm[-1]] + quat.rotate(rot[arm[-1]], sk.tips[arm[-1]])
            pts = np.vstack([pos[arm], hand_tip[None]])
            scene.add_capsules(pts[:-1], pts[1:], np.full(3, sk.radii[arm[0]]), color=_TWIG)
        hr = rot[j("head")]
        rh = shape.head
        eyes = head + quat.rotate(np.broadcast_to(hr, (2, 4)), np.array([[0.35 * rh, 0.25 * rh, 0.88 * rh], [-0.35 * rh, 0.25 * rh, 0.88 * rh]]))
        scene.add_spheres(eyes, np.full(2, 0.1 * rh), color=_COAL)
        nose_base = head + quat.rotate(hr, np.array([0.0, 0.0, 0.9 * rh]))
        nose_tip = head + quat.rotate(hr, np.array([0.0, -0.05 * rh, 1.6 * rh]))
        scene.add_capsule(nose_base, nose_tip, 0.07 * rh, color=_CARROT)
        if shape.middle is not None:
            mid = centers[1]
            fr = rot[j("chest")]
            buttons = mid + quat.rotate(np.broadcast_to(fr, (3, 4)), np.array([[0.0, 0.45 * k, 0.95] for k in (-0.6, 0.0, 0.6)]) * shape.middle)
            scene.add_spheres(buttons, np.full(3, 0.08 * shape.middle), color=_COAL)


def draw_snowman_game(world: World, scene: RenderScene, alpha: float) -> None:
    """The whole game view."""
    from engine.components import Stick

    draw_world(world, scene, alpha)
    outlined = {s.focus for _, s in world.query(Stick) if s.focus is not None and s.grabbed is None}
    outlined |= {s.grabbed for _, s in world.query(Stick) if s.grabbed is not None}
    draw_snowmen(world, scene, alpha, outlined)
    draw_trees(world, scene)
    field = world.try_resource(SnowField)
    if field is not None:
        marks = field.marks()
        if len(marks):
            marks[:, 1] = 0.004
            scene.add_points(marks, size=field.cell * 1.4, color=(0.74, 0.8, 0.88))
    draw_snowfall(scene, (world.frame + alpha) * world.dt)
