"""The crowd bench's timer: per-step and per-stage thread CPU times of a small crowd."""

from __future__ import annotations

from engine.app import STAGES
from puppetphone.bench.crowd import crowd_app, timed_steps


def test_timed_steps_cover_every_stage_and_the_old_path_runs() -> None:
    for old in (False, True):
        app = crowd_app(3, old=old)
        frame = app.world.frame
        total, stages = timed_steps(app, 5)
        assert app.world.frame == frame + 5
        assert set(stages) == set(STAGES)
        assert (total > 0).all()
        assert (sum(stages.values()) <= total + 1e-9).all()
