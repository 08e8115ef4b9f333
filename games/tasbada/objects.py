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
from games.tasbada.quest import Mark, Quest
from games.tasbada.view import QUEST_HALF_WIDTH, floor_depth, floor_point, to_image

__all__ = [
    "Creature",
    "Crystal",
    "Gate",
    "Layout",
    "layout",
    "spawn_objects",
    "despawn_objects",
    "avatar_position",
    "milestone_step",
    "follow_system",
    "CAGE_REACH",
    "CRYSTAL_REACH",
    "GATE_REACH",
    "GATE_DELAY",
    "CREATURE_COLORS",
]

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


def real_spots(marks: list[Mark], ground_v: float) -> NDArray[np.float64]:
    """Floor points ``[N,3]`` where marked real things stand (the bottom middle of each mark on the floor)."""
    pts = []
    for m in marks:
        u0, _, u1, v1 = m.bbox
        if v1 > ground_v:
            p = floor_point((u0 + u1) / 2, v1)
            if p is not None:
                pts.append(p)
    return np.array(pts).reshape(-1, 3)


def _clear_of(points: NDArray[np.float64], spots: NDArray[np.float64], room: float = 1.0) -> NDArray[np.float64]:
    """Push each point away from the real things (radially, in XZ) to at least ``room`` metres."""
    out = points.copy()
    for s in spots:
        d = out - s
        d[:, 1] = 0.0
        r = np.linalg.norm(d, axis=1)
        near = r < room
        away = np.where(r[:, None] > 1e-6, d / np.maximum(r, 1e-6)[:, None], np.array([1.0, 0.0, 0.0]))
        out[near] = s + away[near] * room
        out[near, 1] = 0.0
    out[:, 0] = np.clip(out[:, 0], -QUEST_HALF_WIDTH, QUEST_HALF_WIDTH)
    return out


def _overlap(gate: NDArray[np.float64], marks: list[Mark], half_width: float = 1.0, height: float = 1.75) -> float:
    """Image area a thing this big at ``gate`` shares with the marked things (hiding them or hidden by them)."""
    corners = gate + np.array([[-half_width, 0.0, 0.0], [half_width, height, 0.0]])
    uv = to_image(corners)
    gu0, gu1 = sorted(uv[:, 0])
    gv0, gv1 = sorted(uv[:, 1])
    total = 0.0
    for m in marks:
        u0, v0, u1, v1 = m.bbox
        total += max(0.0, min(u1, gu1) - max(u0, gu0)) * max(0.0, min(v1, gv1) - max(v0, gv0))
    return total


def layout(ground_v: float, marks: list[Mark] | None = None) -> Layout:
    """The quest's layout on the floor in front of the floor line at image row ``ground_v``,
    kept clear of the real things marked on the floor (``marks``)."""
    z0 = max(floor_depth(ground_v) + 0.7, -5.0)
    z1 = min(z0 + 3.6, 2.6)
    span = z1 - z0
    cages = np.array([[-2.2, 0.0, z0 + 0.45 * span], [2.3, 0.0, z0 + 0.35 * span], [-1.0, 0.0, z1 - 0.05 * span]])
    ang = np.array([0.3, 1.5, 2.6, 3.9, 5.1])
    rad = np.array([0.45, 0.42, 0.38, 0.4, 0.45])
    cx, cz = 0.3, z0 + 0.6 * span
    crystals = np.c_[cx + 2.3 * rad / 0.45 * np.cos(ang), np.zeros(5), cz + span * rad * np.sin(ang)]
    spots = real_spots(marks or [], ground_v)
    gates = np.array([[x, 0.0, z0 - 0.15] for x in (0.0, -1.3, 1.3, -2.2, 2.2)])
    gate = gates[int(np.argmin([_overlap(g, marks or []) for g in gates]))]  # first least hidden-behind
    # The avatar starts where no real prop hides it (props occlude what stands behind them).
    xs = sorted(np.linspace(-2.6, 2.6, 27), key=lambda x: (abs(x - 1.2), x))  # nearest the usual spot first
    starts = _clear_of(np.array([[x, 0.0, z1 - 0.1 * span] for x in xs]), spots)
    cages = _clear_of(cages, spots)
    away = np.array([min(_xz(p, c) for c in cages) > CAGE_REACH + 0.5 for p in starts])  # no cage opened by arriving
    starts = starts[away] if away.any() else starts
    start = starts[int(np.argmin([_overlap(p, marks or [], 0.35, 1.8) for p in starts]))]
    return Layout(cages, _clear_of(crystals, spots, 0.8), gate, start)


def spawn_objects(world: World, q: Quest) -> None:
    """Spawn creatures, crystals and the gate for ``q``'s floor line; reset their milestones."""
    lay = layout(q.ground_v, q.marks)
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
    for _, c, _ in world.query(Creature, Transform):
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
