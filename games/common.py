"""Drawing and setup shared by the games: puppets, props, the stick, focus outlines, notices."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from engine.components import Puppet, Stick, Transform, WorldPose
from engine.ecs import Entity, World
from engine.ragdoll.components import Prop
from engine.render.components import Appearance
from engine.render.extract import pose_arrays, scene_from_world
from engine.render.scene import RenderScene
from input.motionstick import StickState

if TYPE_CHECKING:
    from engine.character.load import Character

__all__ = [
    "draw_world",
    "spawn_player",
    "player_character",
    "PlayerCharacter",
    "draw_sticks",
    "draw_height_cues",
    "draw_walk_target",
    "height_cues",
    "CUE_COLOR",
    "Notice",
    "post_notice",
    "NOTICE_SECONDS",
]

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


@dataclass
class PlayerCharacter:
    """Resource: the character the set-up's ``"character"`` value (``play --character``) was decoded into.

    An asset kept so the set-up's file is read and checked once per world; not simulation state."""

    SIM_STATE = False

    value: object
    character: Character


def player_character(world: World) -> Character | None:
    """The player's character of the game's set-up, or ``None`` for the mannequin.

    Raises:
        engine.character.load.CharacterError: the set-up's character is unusable (one line why).
    """
    from games.base import GameSetup

    setup = world.try_resource(GameSetup)
    value = setup.get("character") if setup is not None else None
    if value is None:
        return None
    held = world.try_resource(PlayerCharacter)
    if held is None or held.value is not value:
        from engine.character.setup import decode

        held = PlayerCharacter(value, decode(value))
        world.insert_resource(held)
    return held.character


def spawn_player(
    world: World,
    position: np.ndarray | tuple[float, float, float] = (0.0, 0.0, 0.0),
    heading: float = 0.0,
    *,
    name: str = "puppet",
    color: tuple[float, float, float] = (0.85, 0.35, 0.25),
) -> Entity:
    """The player's puppet: the set-up's character (``play --character``) when it has one, else the mannequin
    in ``color``. A character plays the clips the mannequin would (the library's authored ones over
    the built-in ones), retargeted to it."""
    from engine.statemachine.puppet import spawn_puppet

    character = player_character(world)
    if character is None:
        return spawn_puppet(world, position, heading, name=name, extra=(Appearance(color=color),))
    from engine.character.puppet import spawn_character
    from engine.cliplib.authored import AuthoredClips, merged_clips
    from engine.clips import default_clips

    authored = world.try_resource(AuthoredClips)
    clips = merged_clips(authored.clips) if authored is not None and authored.clips else default_clips()
    return spawn_character(
        world, character, clips, position, heading, name=name, extra=(Appearance(color=color, visible=False),)
    )


def draw_sticks(world: World, scene: RenderScene) -> None:
    """The MotionStick: a faint line from the controller to the tip while held, and the tip."""
    for _, stick, state in world.query(Stick, StickState):
        if not stick.connected or not state.source:
            continue  # no sample yet: the stick has no pose to draw
        color = (1.0, 0.55, 0.15) if stick.grabbed is not None else (0.3, 0.5, 0.9)
        start = stick.pivot + stick.direction * max(stick.length - 1.5, 0.0)
        scene.add_lines(start[None], stick.tip[None], color=color)
        scene.add_points(stick.tip[None], size=0.05, color=color)


CUE_COLOR = (0.12, 0.16, 0.3)
_PROP_LIFT = 0.05
"""A ball whose bottom is this far (metres) above what is under it counts as lifted."""
_PUPPET_LIFT = 0.2
"""A puppet whose lowest joint is this high counts as lifted (an ankle stays below it while walking)."""
_PUPPET_FOOTPRINT = 0.25
_RING = np.linspace(0.0, 2.0 * np.pi, 33)


def _surface_below(x: float, z: float, below: float, props: list[tuple[np.ndarray, float]]) -> float:
    """Height of the first thing under ``(x, z)`` lower than ``below``: the top of a ball, else the ground (0)."""
    top = 0.0
    for centre, radius in props:
        d2 = (x - centre[0]) ** 2 + (z - centre[2]) ** 2
        if d2 < radius * radius:
            h = float(centre[1] + np.sqrt(radius * radius - d2))
            if h < below + 1e-6:
                top = max(top, h)
    return top


def height_cues(world: World, alpha: float) -> list[tuple[np.ndarray, float, float]]:
    """What is lifted: ``(lowest point [3], height of the surface under it, footprint radius)`` each.

    A ball counts when its bottom is clear of whatever is under it (the ground, or the
    top of another ball: a ball packed onto a stack does not), a puppet when even its
    lowest joint is off the ground (held up by the stick, in the air).
    """
    props = [(tr.position, float(prop.radius)) for _, prop, tr in world.query(Prop, Transform)]
    cues = []
    for i, (centre, radius) in enumerate(props):
        bottom = centre - np.array([0.0, radius, 0.0])
        surface = _surface_below(bottom[0], bottom[2], bottom[1], props[:i] + props[i + 1 :])
        if bottom[1] - surface > _PROP_LIFT:
            cues.append((bottom, surface, radius))
    # A crowd's joints in one array per run of puppets with as many joints (its columns, when FK keeps them):
    # a thousand interpolations one puppet at a time cost more than drawing the crowd.
    poses = [wp for _, _puppet, wp in world.query(Puppet, WorldPose)]
    start = 0
    while start < len(poses):
        joints = len(poses[start].positions)
        end = start + 1
        while end < len(poses) and len(poses[end].positions) == joints:
            end += 1
        now, _, before, _ = pose_arrays(world, poses[start:end], joints)
        lows = (before[:, :, 1] + alpha * (now[:, :, 1] - before[:, :, 1])).min(axis=1)
        for k in np.nonzero(lows > _PUPPET_LIFT)[0]:
            root = before[k, 0] + alpha * (now[k, 0] - before[k, 0])
            low = float(lows[k])
            point = np.array([root[0], low, root[2]])
            cues.append((point, _surface_below(point[0], point[2], low, props), _PUPPET_FOOTPRINT))
        start = end
    return cues


def draw_height_cues(world: World, scene: RenderScene, alpha: float) -> None:
    """Under each lifted thing, a drop line to the surface below and a ring where it would land.

    Without them a ball held in the air over a flat white field gives no clue how
    high or where it is, and stacking one ball on another by hand is guesswork; the
    ring lands on the top of a ball beneath when the held one is right above it.
    """
    for point, surface, radius in height_cues(world, alpha):
        foot = np.array([point[0], surface + 0.01, point[2]])
        scene.add_line(point, foot, CUE_COLOR, width=3.0)
        r = 0.6 * radius
        ring = foot + np.c_[r * np.cos(_RING), np.zeros_like(_RING), r * np.sin(_RING)]
        scene.add_polyline(ring, CUE_COLOR, width=3.0)
        scene.add_points(foot[None], size=0.08, color=CUE_COLOR)


def draw_walk_target(world: World, scene: RenderScene, alpha: float) -> None:
    """Under each held puppet, a line on the floor from its feet to where the stick leads it and a ring there.

    On a photo's floor, dragging the cursor down walks the avatar toward the camera, and how far
    it is from a cage is hard to judge from its size alone; the ring on the floor shows it.
    """
    from engine.statemachine.puppet.body import PuppetBody

    for _e, body, tr in world.query(PuppetBody, Transform):
        if body.held_by is None:
            continue
        feet = np.array([tr.position[0], 0.015, tr.position[2]])
        goal = np.array([body.target[0], 0.015, body.target[2]])
        scene.add_line(feet, goal, CUE_COLOR, width=2.0)
        scene.add_polyline(
            goal + np.c_[0.25 * np.cos(_RING), np.zeros_like(_RING), 0.25 * np.sin(_RING)], CUE_COLOR, width=3.0
        )


def draw_world(world: World, scene: RenderScene, alpha: float) -> None:
    """Puppets as capsules (characters as their skinned mesh), snowballs as spheres, the focused thing outlined, the stick, height cues."""
    focus = {s.focus for _, s in world.query(Stick) if s.focus is not None and s.grabbed is None}
    held = {s.grabbed for _, s in world.query(Stick) if s.grabbed is not None}
    for e, app in world.query(Appearance):
        app.outline = e in focus or e in held
    scene_from_world(world, alpha, scene)
    from engine.character.puppet import skinned_instances

    scene.skinned.extend(skinned_instances(world, alpha, focus | held))
    rows = [(prop.radius, tr.position, world.try_get(e, Appearance)) for e, prop, tr in world.query(Prop, Transform)]
    if rows:
        centers = np.array([r[1] for r in rows])
        radii = np.array([r[0] for r in rows])
        scene.add_spheres(centers, radii, color=(0.96, 0.97, 1.0))
        outlined = [i for i, (e, _, _) in enumerate(world.query(Prop, Transform)) if e in focus or e in held]
        if outlined:
            scene.add_spheres(centers[outlined], radii[outlined] * 1.04, color=(1.0, 0.8, 0.2))
    draw_sticks(world, scene)
    draw_height_cues(world, scene, alpha)
