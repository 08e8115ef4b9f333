"""The snowy field: obstacles (rocks and conifers) and the falling snow.

Obstacles are entities with an ``Obstacle`` (the MotionStick stops at them) and a
render ``Shape``. The snowfall is drawn only — flakes are placed from a fixed seed
and fall with the frame time — so it never touches the simulation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from engine.components import Obstacle, Transform
from engine.ecs import World
from engine.render.components import Appearance, Shape
from engine.render.scene import RenderScene
from engine.render.snowfall import Snowfall

if TYPE_CHECKING:
    from games.snowman.bent_scenery import BentScenery

__all__ = ["build_scenery", "draw_snowfall", "SNOWFALL", "draw_trees", "conifer_tiers", "TREES", "ROCKS"]

TREES = ((-5.0, -4.5, 1.0), (6.0, -5.5, 1.2), (-7.5, 3.0, 0.9), (7.0, 4.5, 1.1), (-2.5, -8.0, 1.3), (3.5, 8.0, 1.0))
ROCKS = ((3.2, -2.4, 0.45), (-3.8, 2.6, 0.35), (1.0, 5.5, 0.4))

#: The field's falling snow (drawn by the desktop, described to the phone once).
SNOWFALL = Snowfall(
    np.random.default_rng(20171105).uniform([-12, 0, -12], [12, 9, 12], size=(900, 3)),
    np.random.default_rng(7).uniform(0, 2 * np.pi, size=900),
)


def build_scenery(world: World) -> None:
    """Spawn the rocks and trees (where a flow file bent them, if the game's setup has one)."""
    from games.base import GameSetup
    from games.snowman.bent_scenery import bent_scenery

    setup = world.try_resource(GameSetup)
    flow = setup.get("flow") if setup is not None else None
    trunks = [np.array([x, 0.0, z]) for x, z, _ in TREES]
    rocks = [np.array([x, 0.6 * r, z]) for x, z, r in ROCKS]
    if flow:
        bent, trunks, rocks = bent_scenery(flow)
        world.insert_resource(bent)
    for (_x, _z, s), base in zip(TREES, trunks):
        world.spawn(Transform(np.array(base, dtype=np.float64), scale=s), Obstacle(radius=0.9 * s, height=3.2 * s))
    for (_x, _z, r), centre in zip(ROCKS, rocks):
        world.spawn(
            Transform(np.array(centre, dtype=np.float64)),
            Obstacle(radius=r, height=1.2 * r),
            Shape("sphere", np.array([r])),
            Appearance(color=(0.48, 0.5, 0.54)),
        )


def _tree_primitives() -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """Every tree's trunk and three snowy tiers as capsule rows (a, b, radius, colour) and
    their snow caps as sphere rows (centre, radius). Trees never move: built once."""
    caps, snow = [], []
    for x, z, s in TREES:
        base = np.array([x, 0.0, z])
        caps.append((base, base + [0, 1.2 * s, 0], 0.12 * s, (0.36, 0.25, 0.17)))
        for k, (h, r) in enumerate(((1.0, 1.0), (1.9, 0.75), (2.7, 0.5))):
            c = base + [0, h * s, 0]
            caps.append((c - [0, 0.05 * s, 0], c + [0, 0.35 * s, 0], r * s * 0.9, (0.16, 0.36 - 0.03 * k, 0.24)))
            snow.append((c + [0, 0.45 * s, 0], 0.35 * r * s))
    ends_a, ends_b, radii, colours = (np.array(v) for v in zip(*caps, strict=True))
    centre, radius = (np.array(v) for v in zip(*snow, strict=True))
    return (ends_a, ends_b, radii, colours), (centre, radius)


_TREE_CAPSULES, _TREE_SNOW = _tree_primitives()


def conifer_tiers(a: np.ndarray, b: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cones ``(base, apex, radius)`` drawn for tier capsules ``a → b`` of radius ``r``.

    The capsule is the tier's body (what the flow editor bends); the cone hangs a skirt
    below it and rises to a point well above it, so consecutive tiers overlap like the
    whorls of a spruce, and a bent tier leans along its bent axis.
    """
    axis = b - a
    length = np.linalg.norm(axis, axis=1, keepdims=True)
    up = np.where(length > 1e-9, axis / np.maximum(length, 1e-9), [0.0, 1.0, 0.0])
    return a - 0.25 * r[:, None] * up, b + 1.6 * r[:, None] * up, 1.15 * r


def draw_trees(scene: RenderScene, bent: BentScenery | None = None) -> None:
    """Conifers: a trunk and three snowy tiers each (``bent``: as a flow file deformed them).

    The rows come four to a tree, trunk first (:func:`_tree_primitives`, and a bent
    field's parts in :func:`~games.snowman.bent_scenery.scenery_objects` order); the snow
    caps of the field's data are drawn as the snow on the tiers, not as balls.
    """
    a, b, r, col = _TREE_CAPSULES if bent is None else bent.capsules
    trunk = np.arange(len(a)) % 4 == 0
    scene.add_capsules(a[trunk], b[trunk], r[trunk], color=col[trunk])
    base, apex, radius = conifer_tiers(a[~trunk], b[~trunk], r[~trunk])
    tier = (np.arange(len(a)) % 4)[~trunk] - 1
    scene.add_cones(base, apex, radius, color=col[~trunk], snow=0.45 + 0.15 * tier)


def draw_snowfall(scene: RenderScene, time: float) -> None:
    """Flakes drifting down; they wrap around the top when they reach the ground."""
    SNOWFALL.draw(scene, time)
