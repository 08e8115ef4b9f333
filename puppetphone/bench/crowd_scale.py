"""Crowds at scale: 300 and 1000 walking puppets, and ten of a hundred falling at once.

The scene is ``play sandbox --puppets N`` (see :mod:`puppetphone.bench.crowd`), warmed up for a second.
Every figure is thread CPU time, the median of :data:`REPEATS` runs (each run's own median
step for the step figures, its worst step for the fall), against the 60 Hz frame budget:

- ``crowd_step_ms_300`` / ``crowd_step_ms_1000``: one simulation step of the whole crowd.
- ``crowd_fall_worst_step_ms_100``: ten puppets of a hundred go limp in the same step with no
  warning (their ragdolls join the physics from the pool); the worst of that step and the
  next :data:`AFTER` steps.
- ``crowd_fall_physics_ms_100``: the physics stage during that fall, against the best peer —
  raw ``mj_step`` (as many substeps as the stage took, no Python around it) on a copy of the same MuJoCo model
  and state, i.e. what our layer costs over MuJoCo itself. ``copy.copy`` of an ``MjData`` does not
  carry MuJoCo's awake lists (the copy would simulate every parked pool slot), so they are
  rebuilt from its ``tree_asleep`` first.
- ``crowd_start_s_1000``: building the 1000-puppet sandbox and its first step (process CPU).
"""

from __future__ import annotations

import copy
import time

import mujoco
import numpy as np

from engine.app import App
from engine.ecs import Entity
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode
from engine.ragdoll._pool import update_sleep
from puppetphone.bench.crowd import BUDGET_MS, crowd_app, timed_steps
from puppetphone.bench.figures import Figure

__all__ = ["AFTER", "FALLERS", "REPEATS", "fall_run", "run"]

REPEATS = 3
STEPS = 20  # steps timed per run of a big crowd
AFTER = 60  # steps after the fall that count for its worst step
FALLERS = 10
_BENCH = "crowd-scale"


def _ragdolls(app: App) -> list[Entity]:
    return [e for e, _ in app.world.query(Ragdoll)]


def fall_run(puppets: int = 100, fallers: int = FALLERS, seed: int = 1) -> tuple[np.ndarray, np.ndarray, float]:
    """Drop ``fallers`` of ``puppets`` at once; thread CPU seconds of that step and the next
    :data:`AFTER` (total and physics stage), and raw ``mj_step`` seconds for the same physics step."""
    app = crowd_app(puppets, seed=seed)
    keys = _ragdolls(app)
    rng = np.random.default_rng(seed)
    for e in sorted(rng.choice(keys, size=fallers, replace=False).tolist()):
        app.world.get(int(e), Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
    total, stages = timed_steps(app, AFTER + 1)
    pw = app.world.resource(PhysicsWorld)
    assert pw.model is not None and pw.data is not None
    d = copy.copy(pw.data)
    update_sleep(pw.model, d)  # a copy loses MuJoCo's awake lists: it would step every parked pool slot
    raw = []
    for _ in range(5):
        t0 = time.thread_time()
        for _ in range(pw.detail.current):  # the resolution the stage stepped at (engine.ragdoll._detail)
            mujoco.mj_step(pw.model, d)
        raw.append(time.thread_time() - t0)
    return total, stages["physics"], float(np.median(raw))


def _start_s(puppets: int) -> float:
    from input.hub import InputHub
    from puppetphone.games import make_app

    t0 = time.process_time()
    app = make_app("sandbox", 1, InputHub(), {"puppets": puppets})
    app.step()
    return time.process_time() - t0


def run() -> list[Figure]:
    """The crowd-scale figures (see the module docstring)."""
    figures = []
    for n in (300, 1000):
        runs = [float(np.median(timed_steps(crowd_app(n, seed=s), STEPS)[0])) for s in range(1, REPEATS + 1)]
        figures.append(
            Figure(_BENCH, f"crowd_step_ms_{n}", float(np.median(runs)) * 1e3, "ms", "60 Hz budget", BUDGET_MS)
        )
    worst, physics, raw = [], [], []
    for s in range(1, REPEATS + 1):
        total, phys, r = fall_run(seed=s)
        worst.append(float(total.max()))
        physics.append(float(np.median(phys)))
        raw.append(r)
    figures.append(
        Figure(_BENCH, "crowd_fall_worst_step_ms_100", float(np.median(worst)) * 1e3, "ms", "60 Hz budget", BUDGET_MS)
    )
    figures.append(
        Figure(
            _BENCH,
            "crowd_fall_physics_ms_100",
            float(np.median(physics)) * 1e3,
            "ms",
            "raw mj_step, same model and state",
            float(np.median(raw)) * 1e3,
        )
    )
    figures.append(
        Figure(
            _BENCH,
            "crowd_start_s_1000",
            float(np.median([_start_s(1000) for _ in range(REPEATS)])),
            "s",
            "issue target",
            3.0,
        )
    )
    return figures
