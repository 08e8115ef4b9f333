"""Drawing and setup shared by the games: puppets, props, the stick, focus outlines, notices."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.components import Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.render.components import Appearance
from engine.render.extract import scene_from_world
from engine.render.scene import RenderScene
from input.motionstick import StickState

__all__ = ["draw_world", "draw_sticks", "Notice", "post_notice", "NOTICE_SECONDS"]

NOTICE_SECONDS = 2.0
"""How long a notice stays on screen (the last quarter of it fading out)."""


@dataclass
class Notice:
    """Resource: a short message for the player ("field saved"), and the frame it was posted.

    Display only, like a toast: not simulation state, so it is not hashed
    (``SIM_STATE = False``) and a replay that shows it or not verifies the same. Its
    age is counted in simulation frames, not wall time, so a paused game keeps it up
    and a replay shows it for as long as the live game did.
    """

    text: str
    frame: int
    SIM_STATE = False

    def opacity(self, frame: int, dt: float) -> float:
        """1 while fresh, fading to 0 over the last quarter of :data:`NOTICE_SECONDS`; 0 once expired."""
        shown = NOTICE_SECONDS / dt
        left = shown - (frame - self.frame)
        if frame < self.frame or left <= 0:
            return 0.0
        return float(min(1.0, left / (0.25 * shown)))


def post_notice(world: World, text: str) -> None:
    """Show ``text`` to the player from this frame on (a newer notice replaces an older one)."""
    world.insert_resource(Notice(text, world.frame))


def draw_sticks(world: World, scene: RenderScene) -> None:
    """The MotionStick: a faint line from the controller to the tip while held, and the tip."""
    for _, stick, state in world.query(Stick, StickState):
        if not stick.connected or not state.source:
            continue  # no sample yet: the stick has no pose to draw
        color = (1.0, 0.55, 0.15) if stick.grabbed is not None else (0.3, 0.5, 0.9)
        start = stick.pivot + stick.direction * max(stick.length - 1.5, 0.0)
        scene.add_lines(start[None], stick.tip[None], color=color)
        scene.add_points(stick.tip[None], size=0.05, color=color)


def draw_world(world: World, scene: RenderScene, alpha: float) -> None:
    """Puppets as capsules, snowballs as spheres, the focused thing outlined, the stick."""
    focus = {s.focus for _, s in world.query(Stick) if s.focus is not None and s.grabbed is None}
    held = {s.grabbed for _, s in world.query(Stick) if s.grabbed is not None}
    for e, app in world.query(Appearance):
        app.outline = e in focus or e in held
    scene_from_world(world, alpha, scene)
    rows = [(prop.radius, tr.position, world.try_get(e, Appearance)) for e, prop, tr in world.query(Prop, Transform)]
    if rows:
        centers = np.array([r[1] for r in rows])
        radii = np.array([r[0] for r in rows])
        scene.add_spheres(centers, radii, color=(0.96, 0.97, 1.0))
        outlined = [i for i, (e, _, _) in enumerate(world.query(Prop, Transform)) if e in focus or e in held]
        if outlined:
            scene.add_spheres(centers[outlined], radii[outlined] * 1.04, color=(1.0, 0.8, 0.2))
    draw_sticks(world, scene)
