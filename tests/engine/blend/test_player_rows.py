"""The players' per-step fields kept in rows (:mod:`engine.rows`): the same steps as plain objects, to the bit.

The animation stage reads each player's set name, phase and override, and writes its inside flag,
rate, phase and finished clip, as arrays of the players' row block. Where the block is unusable
(a value it cannot hold) it takes the players one by one. Both paths must leave the same state.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.blend import BlendLibrary, LocomotionPlayer, LocomotionSet, build_locomotion, install_blend
from engine.blend import locomotion as stage
from engine.clip import Clip
from engine.components import Puppet, Transform
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton
from engine.ik.system import IKRequest
from engine.rows import RowBlock, row_store


@pytest.fixture(scope="module")
def loco(clips: dict[str, Clip]) -> LocomotionSet:
    one_shot = replace(clips["walk"], name="wave", loop=False, root_motion=None)
    return build_locomotion({**clips, "wave": one_shot}, density=21)


class _Plain:
    """A row store whose blocks are all unusable: the stage takes every player one by one."""

    def block(self, ctype: type, owners: tuple[Any, ...]) -> RowBlock:
        block = RowBlock()
        block.stale = True
        return block


def _crowd(loco: LocomotionSet) -> tuple[App, list[int]]:
    """Six puppets in two sets (every other one in a second set: the stage's groups are rows of the block)."""
    app = App(seed=1, plugins=[install_blend])
    library = app.world.resource(BlendLibrary)
    library.add("humanoid", loco)
    library.add("small", loco)
    up = np.array([0.0, 1.0, 0.0])
    es = []
    for i in range(6):
        tr = Transform(rotation=quat.from_axis_angle(up, 0.4 * i))
        player = LocomotionPlayer(library_key="small" if i % 2 else "humanoid", speed=0.3 * i, scale=0.8 + 0.1 * i)
        es.append(app.world.spawn(tr, Puppet(humanoid_skeleton()), player))
    return app, es


def _trace(loco: LocomotionSet, plain: bool, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """State hashes of a crowd that walks, plays a one-shot to its end and changes a request."""
    with monkeypatch.context() as patch:
        if plain:
            patch.setattr(stage, "row_store", lambda world: _Plain())
        app, es = _crowd(loco)
        out = []
        wave = int(loco.clips["wave"].duration * 60) + 20
        for i in range(wave + 10):
            if i == 3:
                app.world.get(es[1], LocomotionPlayer).play("wave", fade=0.1)
                app.world.get(es[4], LocomotionPlayer).play("wave", fade=0.1)
            if i == 20:
                app.world.get(es[2], LocomotionPlayer).speed = 1.4
            app.step()
            out.append(state_hash(app.world))
        finished = [app.world.get(e, LocomotionPlayer).finished for e in es]
        assert finished == [None] * 6  # the one-shots ended and their names were cleared the step after
        return out


def test_players_in_rows_step_as_plain_players_bit_for_bit(
    loco: LocomotionSet, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every step's state hash is the same whether the stage reads and writes the players' row arrays or the
    players one by one. Broken once by not clearing ``finished`` in the rows path (a one-shot's name stayed
    after it ended): it failed."""
    rowed = _trace(loco, False, monkeypatch)
    plain = _trace(loco, True, monkeypatch)
    assert len(rowed) > 60
    assert rowed == plain


def test_a_phase_the_rows_cannot_hold_is_taken_in_and_played_on(loco: LocomotionSet) -> None:
    """An ``int`` assigned to a linked player's phase unlinks the batch (the row block cannot hold it as it is)
    and the stage plays that player on from there, the others as before. Broken once by leaving the phase unwritten on the
    one-by-one path: it failed (the phase stayed the ``int`` 0)."""
    app, es = _crowd(loco)
    app.run_steps(5)
    players = [app.world.get(e, LocomotionPlayer) for e in es]
    assert row_store(app.world).rows(LocomotionPlayer, tuple(players)) is not None  # linked
    before = [p.phase for p in players]
    players[3].phase = 0
    assert row_store(app.world).rows(LocomotionPlayer, tuple(players)) is None  # unlinked
    app.step()
    after = [p.phase for p in players]
    assert all(type(x) is float and 0.0 <= x < 1.0 for x in after)
    assert 0.0 < after[3] < 0.05  # played on from 0
    assert after[0] != before[0] and abs(after[0] - before[0]) < 0.05


def test_a_scale_assigned_is_read_again_and_a_kept_one_is_not(loco: LocomotionSet) -> None:
    """The stage keeps the players' scales while no scale is assigned, and reads them again after one is.
    Broken once by keeping them whatever was assigned: it failed."""
    app, es = _crowd(loco)
    app.run_steps(2)
    group = app.world.resource(BlendLibrary).groups.of(stage.batch(app.world, "locomotion", *_LOCOMOTION))[0]
    kept = stage._scales(group)
    assert stage._scales(group) is kept and kept.tolist() == [0.8 + 0.1 * i for i in (0, 2, 4)]
    app.world.get(es[2], LocomotionPlayer).scale = 1.5
    assert stage._scales(group).tolist() == [0.8, 1.5, 0.8 + 0.4]


_LOCOMOTION = ((Transform, Puppet, LocomotionPlayer), (stage.LocalPose, IKRequest))


def test_settle_flags_are_written_where_they_changed_or_someone_else_wrote_one(loco: LocomotionSet) -> None:
    """Each foot lock's ``settle`` says whether its puppet is asked to stand (speed under 0.05 m/s); a flag
    assigned by other code is set right again the next step. Broken once by writing only the flags that changed
    since the stage's last write, whatever was assigned since: it failed."""
    app, es = _crowd(loco)
    for e in es:
        app.world.add(e, IKRequest())
    app.run_steps(3)
    locks = [app.world.get(e, IKRequest).foot_lock for e in es]
    assert [lock.settle for lock in locks] == [True] + [False] * 5
    locks[2].settle = True
    app.world.get(es[1], LocomotionPlayer).speed = 0.0
    app.step()
    assert [lock.settle for lock in locks] == [True, True] + [False] * 4
