"""A crowd of walking puppets: the simulation step's cost for 1, 10 and 100 puppets.

The scene is ``play sandbox --puppets N``: one puppet standing at the origin and N-1
wanderers walking the field at paces from 0.6 to 2.8 m/s, each turning toward its own
random goal, so their blend requests differ and the pose memos miss as they would in
play. Every figure is thread CPU time per simulation step (the machine is shared:
wall time would measure the neighbours), the median over :data:`STEPS` steps after a
second of warm-up, against the 60 Hz frame budget. ``crowd_step_ms_100_old`` is the
same crowd on the path from before animated puppets left the dynamics
(:attr:`PhysicsWorld.simulate_animated`) and before crowds were grounded in one batch
(:attr:`IKRigCache.batch_from`, :attr:`IKRigCache.crowd_from`), measured in the same run so the ratio is fair; the other
batching (animated drive, locomotion write-back) has no switch and is in both.
``crowd_system_ms_<stage>_100`` splits the 100-puppet step by schedule stage; the animation,
ik and fk stages, and the whole step (``crowd_step_ms_100_numpy``), are set against the same
crowd on the pure-numpy path of the same kernels (:mod:`engine.jit` switched off), measured in
the same run: what compiling the per-puppet loops with numba buys.
"""

from __future__ import annotations

import time

import numpy as np

from engine import jit
from engine.app import STAGES, App
from engine.ik.system import IKRigCache
from engine.ragdoll.physics import PhysicsWorld
from puppetphone.bench.figures import Figure

__all__ = ["run", "crowd_app", "timed_steps", "STEPS", "BUDGET_MS"]

STEPS = 300
BUDGET_MS = 1000.0 / 60.0
_BENCH = "crowd"


def crowd_app(puppets: int, *, old: bool = False, seed: int = 1) -> App:
    """The sandbox with ``puppets`` puppets, warmed up for one second (models built, memos filled)."""
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("sandbox", seed, InputHub(), {"puppets": puppets})
    app.world.resource(PhysicsWorld).simulate_animated = old
    if old:
        cache = app.world.resource(IKRigCache)
        cache.batch_from = cache.crowd_from = puppets + 1
    app.run_steps(60)
    return app


def timed_steps(app: App, steps: int = STEPS) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Thread CPU seconds of ``steps`` steps, in total and per stage.

    Runs the app's schedule stage by stage (as :meth:`App.step` does) to time each one.
    """
    world = app.world
    total = np.empty(steps)
    per_stage = {s: np.empty(steps) for s in STAGES}
    clock = time.thread_time
    for i in range(steps):
        t_start = clock()
        for stage in STAGES:
            t0 = clock()
            for system in app.systems(stage):
                system(world)
            world.flush()
            per_stage[stage][i] = clock() - t0
        world.frame += 1
        for callback in app.on_step_end:
            callback(world)
        total[i] = clock() - t_start
    return total, per_stage


_KERNEL_STAGES = ("animation", "ik", "fk")


def run() -> list[Figure]:
    """Median step time for 1, 10 and 100 walking puppets, the old path at 100, and the stages at 100."""
    figures = []
    stages: dict[str, np.ndarray] = {}
    for n in (1, 10, 100):
        total, stages = timed_steps(crowd_app(n))
        figures.append(
            Figure(_BENCH, f"crowd_step_ms_{n}", float(np.median(total)) * 1e3, "ms", "60 Hz budget", BUDGET_MS)
        )
    with jit.use(False):
        numpy_total, numpy_stages = timed_steps(crowd_app(100))
    for stage, t in stages.items():
        if stage in _KERNEL_STAGES and jit.enabled():
            figures.append(
                Figure(
                    _BENCH,
                    f"crowd_system_ms_{stage}_100",
                    float(np.median(t)) * 1e3,
                    "ms",
                    "numpy path, same run",
                    float(np.median(numpy_stages[stage])) * 1e3,
                )
            )
        else:
            figures.append(Figure(_BENCH, f"crowd_system_ms_{stage}_100", float(np.median(t)) * 1e3, "ms"))
    if jit.enabled():
        figures.append(
            Figure(
                _BENCH,
                "crowd_step_ms_100_numpy",
                float(np.median(numpy_total)) * 1e3,
                "ms",
                "this run's crowd_step_ms_100 (compiled)",
                figures[2].value,
            )
        )
    old, _ = timed_steps(crowd_app(100, old=True))
    new = figures[2].value
    figures.append(
        Figure(_BENCH, "crowd_step_ms_100_old", float(np.median(old)) * 1e3, "ms", "this run's crowd_step_ms_100", new)
    )
    return figures
