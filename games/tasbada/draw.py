"""The view of Tasbada: the composed photo behind, the virtual things among the real props, the dissolve.

Reads the world only. The photo layers come from :class:`~games.tasbada.reality.Reality`:
the backdrop behind everything, each living prop at the depth of its base (3-D things
behind it are hidden by its matte, those in front cover it), the interface on top;
the 3-D layer is the avatar (in the selfie's clothes colour, with a drop line and a
ring under it while it is lifted), the cages and creatures, crystals and the gate, all
standing on the invisible floor whose contact shadows the renderer draws over the photo.
In the virtual stage the photo fades out over :data:`DISSOLVE` seconds while the
ground, sky and the crystal forest of Tasbada grow in.
"""

from __future__ import annotations

import math

import numpy as np

from engine import quat
from engine.components import Puppet, Stick, Transform, WorldPose
from engine.ecs import World
from engine.render.extract import puppet_capsules
from engine.render.scene import RenderScene
from games.common import CUE_COLOR, draw_height_cues, draw_walk_target
from games.tasbada.objects import CREATURE_COLORS, Creature, Crystal, Gate, avatar_position
from games.tasbada.quest import MENU, MIXED, PROPS_ALIVE, REAL, VIRTUAL, Quest
from games.tasbada.reality import Reality
from games.tasbada.view import to_image

__all__ = ["draw", "DISSOLVE", "dissolve"]

DISSOLVE = 4.0
_RNG = np.random.default_rng(1234)  # display-only scenery layout, fixed
_TREES = np.c_[_RNG.uniform(-9, 9, 26), np.zeros(26), _RNG.uniform(-14, -2.5, 26)]
_TREES = _TREES[np.abs(_TREES[:, 0]) > 2.2]
_ISLANDS = np.c_[_RNG.uniform(-10, 10, 7), _RNG.uniform(3.5, 6.5, 7), _RNG.uniform(-18, -8, 7)]
_STARS = np.c_[_RNG.uniform(-30, 30, 120), _RNG.uniform(6, 22, 120), _RNG.uniform(-40, -15, 120)]
_CRYSTAL_ROT = quat.mul(
    quat.from_axis_angle([0.0, 0.0, 1.0], math.pi / 4), quat.from_axis_angle([1.0, 0.0, 0.0], math.pi / 4)
)


def dissolve(q: Quest, now: float) -> float:
    """How virtual the view is: 0 = photo, 1 = Tasbada."""
    if q.stage != VIRTUAL:
        return 0.0
    x = min(max((now - q.stage_t) / DISSOLVE, 0.0), 1.0)
    return x * x * (3 - 2 * x)


def _lerp(a: tuple[float, ...], b: tuple[float, ...], t: float) -> tuple[float, float, float]:
    if len(a) != 3 or len(b) != 3:
        raise ValueError(f"colours have three channels, got {len(a)} and {len(b)}")
    return (float(a[0] + (b[0] - a[0]) * t), float(a[1] + (b[1] - a[1]) * t), float(a[2] + (b[2] - a[2]) * t))


def _cage(scene: RenderScene, home: np.ndarray, sink: float) -> None:
    h = 0.75 * (1.0 - sink)
    if h <= 0.01:
        return
    ang = np.linspace(0, 2 * np.pi, 10, endpoint=False)
    base = home + np.c_[0.36 * np.cos(ang), np.zeros(10), 0.36 * np.sin(ang)]
    ring = np.linspace(0, 2 * np.pi, 33)  # the cage's footprint on the floor: where to lead the avatar
    scene.add_polyline(home + np.c_[0.5 * np.cos(ring), np.full(33, 0.015), 0.5 * np.sin(ring)], CUE_COLOR, width=3.0)
    top = base + np.array([0.0, h, 0.0])
    scene.add_capsules(base, top, 0.022, (0.35, 0.33, 0.38))
    scene.add_capsules(top, np.roll(top, 1, axis=0), 0.03, (0.45, 0.42, 0.5))
    scene.add_sphere(home + np.array([0.0, h + 0.06, 0.0]), 0.08, (0.8, 0.65, 0.25))


def _creature(scene: RenderScene, pos: np.ndarray, color: tuple[float, float, float], t: float, free: bool) -> None:
    hop = (0.16 if free else 0.05) * abs(math.sin(t * (7.0 if free else 4.0)))
    c = pos + np.array([0.0, 0.17 + hop, 0.0])
    scene.add_sphere(c, 0.17, color)
    for s in (-1.0, 1.0):
        scene.add_capsule(c + np.array([0.09 * s, 0.1, 0.0]), c + np.array([0.14 * s, 0.3, -0.02]), 0.035, color)
        eye = c + np.array([0.065 * s, 0.04, 0.14])
        scene.add_sphere(eye, 0.045, (1.0, 1.0, 1.0))
        scene.add_sphere(eye + np.array([0.0, 0.0, 0.035]), 0.022, (0.05, 0.05, 0.08))


def _gate(scene: RenderScene, pos: np.ndarray, q: Quest, now: float) -> None:
    stone = (0.55, 0.52, 0.62)
    for s in (-1.0, 1.0):
        scene.add_box(pos + np.array([0.75 * s, 0.75, 0.0]), (0.16, 0.75, 0.16), color=stone)
    scene.add_box(pos + np.array([0.0, 1.6, 0.0]), (0.98, 0.12, 0.2), color=stone)
    got = sum(t >= 0 for t in q.crystals) if q.crystals else 0
    n = max(len(q.crystals), 5)
    xs = np.linspace(-0.6, 0.6, n)
    for i, x in enumerate(xs):
        lit = i < got
        scene.add_sphere(pos + np.array([x, 1.6, 0.2]), 0.06, (0.55, 0.95, 1.0) if lit else (0.25, 0.25, 0.3))
    opening = 0.0 if q.gate_open_t < 0 else min((now - q.gate_open_t) / 1.2, 1.0)
    for s in (-1.0, 1.0):
        ang = s * opening * 1.9
        hinge = pos + np.array([0.59 * s, 0.74, 0.0])
        rot = quat.from_axis_angle([0.0, 1.0, 0.0], ang)
        center = hinge + quat.rotate(rot, np.array([-0.295 * s, 0.0, 0.0]))
        scene.add_box(center, (0.29, 0.72, 0.04), rot, color=(0.42, 0.28, 0.18))
    if got == n and n > 0:
        k = np.arange(40)
        a = k * 0.7 + now * 2.0
        r = 0.15 + 0.5 * ((k * 0.618) % 1.0)
        pts = pos + np.c_[r * np.cos(a), 0.75 + r * np.sin(a) * 1.3, np.full(40, 0.05 + 0.1 * opening)]
        scene.add_points(pts, 0.05 + 0.04 * opening, (0.7, 0.9, 1.0))


def _crystals(scene: RenderScene, world: World, q: Quest, now: float, gate: np.ndarray | None) -> None:
    if q.crystals_shown_t < 0:
        return
    grow = min((now - q.crystals_shown_t) / 0.8, 1.0)
    for _, cr, tf in world.query(Crystal, Transform):
        taken = q.crystals[cr.index]
        spin = quat.mul(quat.from_axis_angle([0.0, 1.0, 0.0], now * 1.5 + cr.index), _CRYSTAL_ROT)
        color = (0.45, 0.95, 1.0) if cr.index % 2 == 0 else (0.85, 0.55, 1.0)
        if taken < 0:
            s = 0.17 * grow
            p = tf.position + np.array([0.0, 0.25 + 0.05 * math.sin(now * 2.5 + cr.index), 0.0])
        else:
            k = (now - taken) / 1.0
            if k >= 1.0 or gate is None:
                continue
            s = 0.17 * (1.0 - k)
            p = (
                tf.position
                + (gate + np.array([0.0, 1.6, 0.0]) - tf.position) * k
                + np.array([0.0, math.sin(k * math.pi), 0.0])
            )
        if s > 0.005:
            scene.add_box(p, (s, s, s), spin, color)
            scene.add_points(p[None], 0.4 * s / 0.17, color)


def _virtual(scene: RenderScene, f: float, now: float) -> None:
    if f <= 0:
        return
    s = f
    for i, t in enumerate(_TREES):
        h = (1.2 + 0.5 * ((i * 0.37) % 1.0)) * s
        scene.add_capsule(t, t + np.array([0.0, h, 0.0]), 0.07 * s, (0.45, 0.35, 0.6))
        top = t + np.array([0.0, h + 0.3 * s, 0.0])
        rot = quat.mul(quat.from_axis_angle([0.0, 1.0, 0.0], now * 0.3 + i), _CRYSTAL_ROT)
        col = (0.5, 0.95, 0.9) if i % 3 else (1.0, 0.6, 0.85)
        scene.add_box(top, (0.32 * s, 0.32 * s, 0.32 * s), rot, col)
    for i, p in enumerate(_ISLANDS):
        q = p + np.array([0.0, 0.25 * math.sin(now * 0.6 + i), 0.0])
        scene.add_box(q, (1.1 * s, 0.25 * s, 0.9 * s), color=(0.35, 0.7, 0.5))
        scene.add_sphere(q - np.array([0.0, 0.5 * s, 0.0]), 0.6 * s, (0.5, 0.42, 0.6))
    scene.add_points(_STARS, 2.5 * s, (1.0, 0.97, 0.85), pixels=True)


def _gaze(world: World, q: Quest) -> float:
    """Where the narrator looks: at the avatar if there is one, else at the pointer."""
    target = q.pointer[0]
    pos = avatar_position(world, q.avatar)
    if pos is not None:
        uv = to_image(pos + np.array([0.0, 1.0, 0.0]))[0]
        if np.all(np.isfinite(uv)):
            target = uv[0]
    if not q.marks:
        return 0.0
    u0, _, u1, _ = q.marks[0].bbox
    return float(np.clip((target - (u0 + u1) / 2) * 4.0, -1.0, 1.0))


def draw(world: World, scene: RenderScene, alpha: float) -> None:
    """Fill ``scene`` for the current state (``alpha`` interpolates the puppet)."""
    q = world.resource(Quest)
    reality = world.resource(Reality)
    now = (world.frame - 1 + alpha) * world.dt if world.frame > 0 else 0.0
    f = dissolve(q, now)
    layers = reality.frame(q, now, _gaze(world, q), wait=scene.complete)
    scene.set_background(layers.background, f)
    for rgba, rect, at in layers.props:
        scene.add_overlay(rgba, rect, depth_at=at, photo=True, alpha=1.0 - f)
    scene.add_overlay(layers.ui)  # the interface: over the 3-D scene, always
    scene.ground.grid = f > 0.5
    scene.ground.snow = 0.15 * f
    scene.ground.color = _lerp((0.8, 0.8, 0.8), (0.42, 0.62, 0.5), f)
    scene.ground.grid_color = (0.6, 0.85, 0.75)
    scene.ground.grid_spacing = 2.0
    scene.ground.visible = q.stage in (MIXED, VIRTUAL)
    scene.sky_color = _lerp((0.30, 0.52, 0.86), (0.22, 0.16, 0.45), f)
    scene.horizon_color = _lerp((0.86, 0.9, 0.96), (0.95, 0.72, 0.78), f)
    scene.sun.shadows = q.stage in (MIXED, VIRTUAL)
    if q.stage in (REAL, PROPS_ALIVE, MENU, ""):
        return
    stick = world.query(Stick)
    focus = stick[0][1].focus if stick else None
    for e, puppet, wpose in world.query(Puppet, WorldPose):
        pos, rot = wpose.interpolated(alpha)
        a, b, r, _ = puppet_capsules(puppet.skeleton, pos, rot)
        scene.add_capsules(a, b, r, reality.color, outline=e == focus)
    draw_height_cues(world, scene, alpha)
    draw_walk_target(world, scene, alpha)
    gate_pos = None
    for _, _g, tf in world.query(Gate, Transform):
        gate_pos = tf.position
        _gate(scene, tf.position, q, now)
    for _, c, tf in world.query(Creature, Transform):
        freed = q.freed[c.index] if c.index < len(q.freed) else -1.0
        sink = 0.0 if freed < 0 else min((now - freed) / 0.6, 1.0)
        _cage(scene, c.home, sink)
        _creature(scene, tf.position, CREATURE_COLORS[c.index % 3], now + c.index * 0.4, freed >= 0)
    _crystals(scene, world, q, now, gate_pos)
    _virtual(scene, f, now)
