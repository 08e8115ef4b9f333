"""The snowman game under load: a simulation step and a rendered frame.

The loaded scene is the one the issue names: the game's own field (rocks, trees,
snow), its puppet, six snowmen of different proportions (each with its own rig,
playing the shared locomotion set at its leg scale) and twenty snowballs, some resting and some rolling
through each other. The baseline is the same game with nothing in the field (no
puppet, no snowman, no ball), measured in the same run: the fixed cost of the
schedule, the snow and the scenery.

The frame is drawn as ``play snowman`` draws it by default: the quality governor picks the
level from the frames' CPU times and stays in the loop while they are timed (the level is in
the figures' labels; the empty field is drawn at the same level). Times are process CPU, every
rasteriser thread counted.

The puppets stand idle (nobody holds a stick); their per-step work is the same as
walking — every puppet samples its blend space, animates, solves its leg IK and
drives its ragdoll every step — only the stick-following is skipped.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from puppetphone.bench.figures import Figure

if TYPE_CHECKING:
    from engine.app import App

__all__ = ["run", "loaded_app", "SNOWMEN", "SNOWBALLS"]

SNOWMEN = 6
SNOWBALLS = 20
REPEATS = 3  # the step time is the median of this many repeats, each on a fresh app
WIDTH, HEIGHT = 1280, 720


def loaded_app(snowmen: int = SNOWMEN, snowballs: int = SNOWBALLS, seed: int = 1) -> App:
    """The snowman game with its puppet, ``snowmen`` snowmen and ``snowballs`` balls (0, 0 and
    no puppet: the empty field), stepped for one second so every model is built."""
    from engine.ragdoll.components import Prop
    from engine.statemachine.puppet import PuppetBody
    from games.snowman.alive import bring_to_life
    from games.snowman.components import SnowmanStats
    from games.snowman.rig import SnowmanShape
    from games.snowman.rules import spawn_ball
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("snowman", seed, InputHub())
    world = app.world
    rng = np.random.default_rng(seed)
    if snowmen == 0 and snowballs == 0:
        for e, _ in world.query(PuppetBody):
            world.despawn(e)
    for i in range(snowmen):
        bottom = float(rng.uniform(0.3, 0.5))
        middle = float(rng.uniform(0.6, 0.8) * bottom) if i % 2 == 0 else None
        head = float(rng.uniform(0.4, 0.55) * bottom)
        angle = 2 * np.pi * i / max(snowmen, 1)
        world.resource(SnowmanStats).built += 1
        bring_to_life(
            world,
            SnowmanShape(bottom, middle, head),
            np.array([3.5 * np.cos(angle), 0.0, 3.5 * np.sin(angle)]),
            float(rng.uniform(-np.pi, np.pi)),
            i + 1,
        )
    for i in range(snowballs):
        r = float(rng.uniform(0.12, 0.35))
        ball = spawn_ball(world, np.array([rng.uniform(-6, 6), 0.0, rng.uniform(-5, 2)]), r)
        if i % 2:  # half of them rolling, into each other and the snowmen
            v = rng.normal(size=3) * [1.5, 0.0, 1.5]
            world.get(ball, Prop).velocity = np.concatenate([v, np.cross([0.0, 1.0, 0.0], v) / r])
    world.flush()
    for _ in range(60):
        app.step()
    return app


def _step_time(make: Callable[[], App], steps: int = 300, repeats: int = REPEATS) -> tuple[float, App]:
    """Median thread CPU seconds of one step, and the app of the last repeat (stepped on, for the frame).

    Each repeat builds a fresh app with ``make`` and times ``steps`` consecutive steps, each
    alone, in the thread's CPU time (other people's load on a shared machine does not count); a
    repeat's figure is the median of its steps, and the result the median of the repeats. The
    scene moves on as it is stepped (balls roll and slow down), so a fresh app per repeat makes
    every repeat time the same deterministic stretch of simulation.
    """
    medians: list[float] = []
    for _ in range(max(1, repeats)):
        app = make()
        times = np.empty(steps)
        for i in range(steps):
            t0 = time.thread_time()
            app.step()
            times[i] = time.thread_time() - t0
        medians.append(float(np.median(times)))
    return float(np.median(medians)), app


def _render_fps(app: App, level: str | None = None) -> tuple[float, float | None, str]:
    """Frames per second of the game's full frame (world, scenery, snow, overlay) at 1280x720, in
    process CPU time (the median of 3 repeats, :func:`~puppetphone.bench.render.cpu_frame_time`), the
    rate the same frames would run at with the cores free (see :mod:`puppetphone.bench.render`;
    ``None`` without ``/proc``), and the quality level drawn at.

    ``level=None`` draws as ``play snowman`` does by default: the quality governor chooses from the
    frames' CPU times and stays in the loop while they are timed
    (:class:`~puppetphone.bench.render.GovernedFrame`); a name draws at that level throughout."""
    from engine.render.quality import QUALITIES
    from engine.render.renderer import Renderer
    from engine.render.scene import RenderScene
    from engine.render.target import make_target
    from games.snowman.game import GAME
    from input.hub import InputHub
    from puppetphone.bench.render import GovernedFrame, cpu_frame_time, unloaded_frame_time
    from puppetphone.overlay import draw_overlay

    target = make_target(True, WIDTH, HEIGHT)
    renderer = Renderer(target.ctx)
    scene, camera, hub = RenderScene(), GAME.camera(), InputHub()
    try:

        def frame() -> None:
            scene.clear()
            GAME.draw(app.world, scene, 1.0)
            draw_overlay(scene, app.world, GAME, hub, 60.0, False)
            renderer.render(scene, camera, target.begin())
            target.end()
            target.ctx.finish()

        timed: Callable[[], object] = frame
        if level is None:
            timed = governed = GovernedFrame(renderer, frame)
            for _ in range(40):  # a player's first frames: the governor finds its level
                governed()
        else:
            renderer.set_quality(QUALITIES[level])
        fps = 1.0 / cpu_frame_time(timed)
        free = unloaded_frame_time(timed, frames=20)
        return fps, (1.0 / free if free else None), renderer.quality.name
    finally:
        renderer.release()
        target.close()


def run() -> list[Figure]:
    """Median step time (thread CPU) and frame rate, loaded and empty, from the same run."""
    t_loaded, loaded = _step_time(loaded_app)
    t_empty, empty = _step_time(lambda: loaded_app(0, 0))
    fps_loaded, free_loaded, level = _render_fps(loaded)
    fps_empty, free_empty, _ = _render_fps(empty, level)  # the empty field at the loaded field's level
    figures = [
        Figure(
            "snowman", "sim_step_ms", t_loaded * 1e3, "ms", "empty field (straw man: the fixed cost)", t_empty * 1e3
        ),
        Figure("snowman", "sim_step_ms_vs_goal", t_loaded * 1e3, "ms", "goal", 8.0),
        Figure("snowman", "render_fps", fps_loaded, "fps", f"empty field (auto: both at {level})", fps_empty),
        Figure("snowman", "render_fps_vs_goal", fps_loaded, "fps", f"goal (auto: {level})", 30.0),
    ]
    if free_loaded is not None:
        figures.append(
            Figure("snowman", "render_fps_unloaded", free_loaded, "fps", f"empty field, unloaded ({level})", free_empty)
        )
    return figures
