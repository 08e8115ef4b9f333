"""The animation stage's requests (:mod:`engine.blend._requests`): checked as arrays, answered per row.

A row asking what it asked last step keeps last step's answer; the others are resolved in one
batch. The answers must be those of resolving every row afresh, bit for bit (the state hashes
see every bit), whichever rows changed and however (speed, height, standing or not, scale).
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend import _requests
from engine.blend.locomotion import LocomotionPlayer, LocomotionSet
from engine.blend.puppet import puppet_locomotion


@pytest.fixture(scope="module")
def loco() -> LocomotionSet:
    return puppet_locomotion()


def _players(n: int, rng: np.random.Generator) -> list[LocomotionPlayer]:
    out = [LocomotionPlayer(speed=float(s)) for s in rng.uniform(0.0, 3.5, n)]
    for p in out[::3]:
        p.height = float(rng.uniform(0.6, 0.95))
    for p in out[::5]:
        p.scale = 0.6
    return out


def _same(a: _requests.Answers, b: _requests.Answers) -> None:
    for x, y in ((a.points, b.points), (a.feasible, b.feasible), (a.inside, b.inside), (a.rates, b.rates)):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("compiled", [False, True] if jit.AVAILABLE else [False])
def test_rows_kept_from_last_step_are_what_a_fresh_resolve_gives(loco: LocomotionSet, compiled: bool) -> None:
    """Changes of speed, of height alone, from standing to a height, of scale alone, and none.
    Broken once by leaving the height out of the change test (the row whose height alone moved keeps
    its stale answer)."""
    rng = np.random.default_rng(3)
    players = _players(40, rng)
    entities = list(range(1, 41))
    last: dict[str, _requests.LastAnswers] = {}
    with jit.use(compiled):
        _requests.resolve(last, "humanoid", loco, _requests.read(entities, players))
        players[1].speed += 0.3
        players[3].height = 0.7 if players[3].height != 0.7 else 0.72  # the height alone
        players[4].height = 0.8  # was standing
        players[7].scale = 0.8  # the scale alone
        players[9].speed = 4.5  # beyond the fastest blend: projected and sped up
        req = _requests.read(entities, players)
        kept = _requests.resolve(last, "humanoid", loco, req)
        fresh = _requests.resolve({}, "humanoid", loco, req)
        _same(kept, fresh)
        assert not kept.inside[9] and kept.rates[9] > 1.0
        assert _requests.resolve(last, "humanoid", loco, req) is kept  # nothing changed: last step's answers


@pytest.mark.parametrize("compiled", [False, True] if jit.AVAILABLE else [False])
@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("speed", float("nan"), "entity 8: locomotion request speed=nan"),
        ("speed", -0.5, "entity 8: locomotion request speed=-0.5"),
        ("height", float("inf"), "entity 8: locomotion request speed=.*height=inf"),
        ("scale", 0.0, "entity 8: locomotion scale 0.0 must be positive"),
    ],
)
def test_an_invalid_request_is_named_by_its_entity(compiled: bool, field: str, value: float, message: str) -> None:
    """Broken once by reporting the last invalid row instead of the first (entity 12 is bad too)."""
    players = _players(12, np.random.default_rng(1))
    setattr(players[7], field, value)
    setattr(players[11], field, value)
    with jit.use(compiled), pytest.raises(ValueError, match=message):
        _requests.read(list(range(1, 13)), players)
