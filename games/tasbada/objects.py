"""The virtual things of the quest and the milestones they unlock (stage 3, thesis Fig. 6.12).

Three caged creatures, five crystals and a gate, laid out on the floor in front of
the floor line the person set. Milestones are unlocked by what the avatar *does*,
read from its position each step:

1. walk the avatar up to a cage — the cage opens and the creature follows you;
2. when all three are free, crystals sprout — walk over each one to gather it;
3. when all crystals are gathered, the gate glows — walk through it to open it,
   and two seconds later the journey moves on to the virtual world.

All state is hashed components and the :class:`~games.tasbada.quest.Quest`
resource; times are simulation times.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine.components import Transform, WorldPose
from engine.ecs import Entity, World
from games.tasbada.quest import Quest
from games.tasbada.view import floor_depth

__all__ = ["Creature", "Crystal", "Gate", "Layout", "layout", "spawn_objects", "despawn_objects",
           "avatar_position", "milestone_step", "follow_system", "CAGE_REACH", "CRYSTAL_REACH", "GATE_REACH",
           "GATE_DELAY", "CREATURE_COLORS"]

CAGE_REACH = 0.8
CRYSTAL_REACH = 0.6
GATE_REACH = 0.9
GATE_DELAY = 2.0
"""Seconds between the gate opening and the virtual world."""
CREATURE_COLORS = ((0.98, 0.55, 0.25), (0.45, 0.85, 0.4), (0.55, 0.6, 1.0))


@dataclass
class Creature:
    """A little creature: ``home`` is its cage; it follows the avatar once freed."""

    index: int
    home: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))


@dataclass
class Crystal:
    """A crystal to gather; ``index`` into ``Quest.crystals``."""

    index: int


@dataclass
class Gate:
    """The gate to Tasbada, at the back of the floor."""


@dataclass(frozen=True)
class Layout:
    """Where things go for a given floor line: cages, crystals, gate and the avatar's start."""

    cages: NDArray[np.float64]
    crystals: NDArray[np.float64]
    gate: NDArray[np.float64]
    start: NDArray[np.float64]


def layout(ground_v: float) -> Layout:
    """The quest's layout on the floor in front of the floor line at image row ``ground_v``."""
    z0 = max(floor_depth(ground_v) + 0.7, -5.0)
    z1 = min(z0 + 3.6, 2.6)
    span = z1 - z0
    cages = np.array([[-2.2, 0.0, z0 + 0.45 * span], [2.3, 0.0, z0 + 0.35 * span], [-1.0, 0.0, z1 - 0.05 * span]])
    ang = np.array([0.3, 1.5, 2.6, 3.9, 5.1])
    rad = np.array([0.45, 0.42, 0.38, 0.4, 0.45])
    cx, cz = 0.3, z0 + 0.6 * span
    crystals = np.c_[cx + 2.3 * rad / 0.45 * np.cos(ang), np.zeros(5), cz + span * rad * np.sin(ang)]
    return Layout(cages, crystals, np.array([0.0, 0.0, z0 - 0.15]), np.array([1.2, 0.0, z1 - 0.1 * span]))


def spawn_objects(world: World, q: Quest) -> None:
    """Spawn creatures, crystals and the gate for ``q``'s floor line; reset their milestones."""
    lay = layout(q.ground_v)
    for i, home in enumerate(lay.cages):
        world.spawn(Creature(i, home.copy()), Transform(home.copy()))
    for i, pos in enumerate(lay.crystals):
        world.spawn(Crystal(i), Transform(pos.copy()))
    world.spawn(Gate(), Transform(lay.gate.copy()))
    q.freed = [-1.0] * len(lay.cages)
    q.crystals = [-1.0] * len(lay.crystals)
    q.crystals_shown_t = q.gate_open_t = -1.0


def despawn_objects(world: World) -> None:
    """Remove every quest object (a restart)."""
    for ctype in (Creature, Crystal, Gate):
        for row in world.query(ctype):
            world.despawn(row[0])


def avatar_position(world: World, avatar: Entity | None) -> NDArray[np.float64] | None:
    """Where the avatar stands: its hips over the floor (``WorldPose``), else its ``Transform``."""
    if avatar is None or not world.alive(avatar):
        return None
    wp = world.try_get(avatar, WorldPose)
    if wp is not None:
        p = np.asarray(wp.positions[0], dtype=np.float64).copy()
        p[1] = 0.0
        return p
    tf = world.try_get(avatar, Transform)
    return None if tf is None else tf.position.copy()


def _xz(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    return float(np.hypot(a[0] - b[0], a[2] - b[2]))


def milestone_step(world: World, q: Quest) -> list[str]:
    """Unlock what the avatar did this step; returns the milestone names reached now."""
    now = world.time
    pos = avatar_position(world, q.avatar)
    if pos is None:
        return []
    hits: list[str] = []
    for _, c, tf in world.query(Creature, Transform):
        if q.freed[c.index] < 0 and _xz(pos, c.home) < CAGE_REACH:
            q.freed[c.index] = now
            hits.append(f"freed {sum(t >= 0 for t in q.freed)}")
    if q.freed and all(t >= 0 for t in q.freed) and q.crystals_shown_t < 0:
        q.crystals_shown_t = now
        hits.append("creatures free")
    if q.crystals_shown_t >= 0 and now - q.crystals_shown_t > 0.8:
        for _, cr, tf in world.query(Crystal, Transform):
            if q.crystals[cr.index] < 0 and _xz(pos, tf.position) < CRYSTAL_REACH:
                q.crystals[cr.index] = now
                hits.append(f"crystal {sum(t >= 0 for t in q.crystals)}")
                if all(t >= 0 for t in q.crystals):
                    hits.append("crystals gathered")
    if q.crystals and all(t >= 0 for t in q.crystals) and q.gate_open_t < 0:
        for _, _g, tf in world.query(Gate, Transform):
            if _xz(pos, tf.position) < GATE_REACH:
                q.gate_open_t = now
                hits.append("gate open")
    q.milestones.extend(hits)
    return hits


def follow_system(world: World) -> None:
    """Freed creatures trot after the avatar, each to its own place around it (rules stage)."""
    q = world.try_resource(Quest)
    if q is None or not q.freed:
        return
    pos = avatar_position(world, q.avatar)
    if pos is None:
        return
    dt = world.dt
    for _, c, tf in world.query(Creature, Transform):
        if q.freed[c.index] < 0:
            continue
        ang = 2.0 * np.pi * c.index / 3.0 + 0.6
        target = pos + 0.85 * np.array([np.cos(ang), 0.0, np.sin(ang)])
        step = target - tf.position
        step[1] = 0.0
        dist = float(np.linalg.norm(step))
        if dist > 1e-6:
            tf.position = tf.position + step * min(1.0, min(2.8 * dt, 3.0 * dt / dist))
