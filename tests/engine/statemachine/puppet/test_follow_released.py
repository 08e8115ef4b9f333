"""``follow_released``: a crowd's released puppets stepped over arrays, number for number as one by one.

``follow_velocity`` (speed scale 1) is the reference: each puppet of a mixed batch (at rest, nearly
stopped, still walking in several directions, one with its spring exactly at rest but a velocity
of ``-0.0``) is stepped by it alone, and the batch call must give every body, player and facing
the same bits, on plain bodies and on bodies linked to a row block (:mod:`engine.rows`), with the
rotations written one by one or as a column. ``stand`` stands every player tall in the same pass
and only then; without it a player's height is left as it was. Written for the seventh mutation
round (docs/mutation.md): each test was seen failing on the mutants it names.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from engine.blend.locomotion import LocomotionPlayer
from engine.columns import columns
from engine.components import Transform
from engine.ecs import World
from engine.rows import row_store
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.follow import follow_released, follow_velocity, set_requests, tuning_columns

DT = 1.0 / 60.0


class _Player:
    """Stands in for the LocomotionPlayer: the control writes its ``speed`` (and, standing, its ``height``)."""

    def __init__(self) -> None:
        self.speed = -1.0
        self.height: float | None = 0.7


def _walks() -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(heading, walk velocity, spring rate) of a mixed batch: more still than moving (the column write)."""
    z = np.zeros(3)
    return [
        (0.3, z, z),  # at rest
        (-2.0, np.array([1.2, 0.0, -0.4]), np.array([0.5, 0.0, 0.2])),  # walking, turned away
        (1.0, z, z),
        (0.0, np.array([2e-4, 0.0, 1e-4]), z),  # nearly stopped: below the turning speed after the step
        (2.5, z, np.array([0.0, 0.0, -0.3])),  # at rest but its spring still moving
        (-0.7, np.array([-0.6, 0.0, 0.9]), z),
        (0.0, np.array([0.0, -0.0, 0.0]), z),  # -0.0: not the exact rest, but nothing moves
    ]


def _world(walks: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[World, list[int]]:
    world = World(dt=DT)
    made = []
    for i, (heading, walk, rate) in enumerate(walks):
        body = PuppetBody(held_by=None, heading=heading, walk_velocity=walk.copy(), walk_rate=rate.copy())
        body.recent = np.arange(36, dtype=np.float64).reshape(12, 3) * (i + 1) * 0.01
        made.append(world.spawn(Transform(position=np.array([float(i), 0.9, 0.0])), body))
    return world, made


def _reference(walks: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[list[PuppetBody], list, list]:
    """Every puppet stepped alone by ``follow_velocity``."""
    world, made = _world(walks)
    players = [_Player() for _ in made]
    for e, p in zip(made, players, strict=True):
        follow_velocity(world, e, world.get(e, PuppetBody), p)  # type: ignore[arg-type]  # a stand-in player
    return [world.get(e, PuppetBody) for e in made], [world.get(e, Transform) for e in made], players


def _same(bodies: list[PuppetBody], ref: list[PuppetBody]) -> None:
    for b, r in zip(bodies, ref, strict=True):
        assert b.heading == r.heading
        for name in ("walk_velocity", "walk_rate", "recent"):
            got, want = getattr(b, name), getattr(r, name)
            assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want)), name


@pytest.mark.parametrize("stand", [False, True])
@pytest.mark.parametrize("linked", [False, True])
@pytest.mark.parametrize("as_column", [False, True])
def test_a_released_batch_steps_bit_for_bit_as_one_by_one(stand: bool, linked: bool, as_column: bool) -> None:
    walks = _walks()
    ref_bodies, ref_transforms, ref_players = _reference(walks)
    world, made = _world(walks)
    bodies = [world.get(e, PuppetBody) for e in made]
    transforms = [world.get(e, Transform) for e in made]
    for tr in transforms:
        tr.rotation = np.array([0.0, 0.0, 0.0, 1.0]) * 0.5  # anything but the answer
    players = [_Player() for _ in made]
    block_rows = None
    if linked:
        block = row_store(world).block(PuppetBody, tuple(bodies))
        assert not block.stale
        block_rows = (block, np.arange(len(bodies), dtype=np.intp))
    cols = columns(world) if as_column else None
    standing = {"stand": True} if stand else {}  # the default: not standing
    follow_released(DT, bodies, transforms, players, cols, block_rows, **standing)  # type: ignore[arg-type]  # a stand-in player
    _same(bodies, ref_bodies)
    for tr, ref in zip(transforms, ref_transforms, strict=True):
        assert np.array_equal(tr.rotation, ref.rotation)
    assert [p.speed for p in players] == [p.speed for p in ref_players]
    assert [p.height for p in players] == ([None] * len(players) if stand else [0.7] * len(players))
    assert ref_players[1].speed != ref_players[5].speed and ref_players[1].speed >= 0.0  # the batch did vary


def test_a_subset_of_a_block_steps_its_own_rows_only() -> None:
    """Rows given as indices: those puppets step, the block's other rows are left as they were."""
    walks = _walks()
    ref_bodies, ref_transforms, ref_players = _reference(walks)
    world, made = _world(walks)
    bodies = [world.get(e, PuppetBody) for e in made]
    block = row_store(world).block(PuppetBody, tuple(bodies))
    untouched = copy.deepcopy([(b.heading, b.walk_velocity, b.walk_rate, b.recent) for b in bodies])
    picked = [1, 3, 5]
    players = [_Player() for _ in picked]
    transforms = [world.get(made[i], Transform) for i in picked]
    follow_released(
        DT,
        [bodies[i] for i in picked],
        transforms,
        players,  # type: ignore[arg-type]  # a stand-in player
        None,
        (block, np.array(picked, dtype=np.intp)),
        True,
    )
    _same([bodies[i] for i in picked], [ref_bodies[i] for i in picked])
    assert [p.speed for p in players] == [ref_players[i].speed for i in picked]
    for i, b in enumerate(bodies):
        if i not in picked:
            h, v, r, rec = untouched[i]
            assert b.heading == h and np.array_equal(b.walk_velocity, v) and np.array_equal(b.walk_rate, r)
            assert np.array_equal(b.recent, rec)


def test_a_block_at_exact_rest_is_left_at_rest_standing_and_facing_its_heading() -> None:
    """Every number +0.0: nothing moves, every player is asked for 0 m/s, and each faces its heading."""
    walks = [(h, np.zeros(3), np.zeros(3)) for h in (0.0, 1.0, -2.0, 3.0)]
    ref_bodies, ref_transforms, ref_players = _reference(walks)
    world, made = _world(walks)
    bodies = [world.get(e, PuppetBody) for e in made]
    for b in bodies:
        b.recent = np.zeros((12, 3))
    for b in ref_bodies:
        b.recent = np.zeros((12, 3))
    transforms = [world.get(e, Transform) for e in made]
    players = [_Player() for _ in made]
    block = row_store(world).block(PuppetBody, tuple(bodies))
    follow_released(DT, bodies, transforms, players, columns(world), (block, slice(None)), stand=True)  # type: ignore[arg-type]  # a stand-in player
    assert [p.speed for p in players] == [0.0] * 4 and [p.height for p in players] == [None] * 4
    for tr, ref in zip(transforms, ref_transforms, strict=True):
        assert np.array_equal(tr.rotation, ref.rotation)
    for b in bodies:
        assert not b.walk_velocity.any() and not b.walk_rate.any() and not b.recent.any()


def test_an_empty_batch_is_nothing_to_do() -> None:
    follow_released(DT, [], [], [], None, None, stand=True)


def test_the_tuning_columns_follow_the_tunings_assigned() -> None:
    """Per row: legacy or not, and the stiffness; recomputed once a tuning is assigned, kept until then."""
    from dataclasses import replace

    world, made = _world(_walks()[:3])
    bodies = [world.get(e, PuppetBody) for e in made]
    soft = replace(bodies[0].tuning, follow_omega=3.5)
    bodies[2].tuning = replace(bodies[0].tuning, controller="legacy")
    block = row_store(world).block(PuppetBody, tuple(bodies))
    legacy, omega = tuning_columns(block)
    assert legacy.tolist() == [False, False, True] and legacy.dtype == np.bool_
    assert omega.tolist() == [b.tuning.follow_omega for b in bodies] and omega.dtype == np.float64
    assert tuning_columns(block)[1] is omega  # kept
    bodies[1].tuning = soft
    assert tuning_columns(block)[1].tolist() == [bodies[0].tuning.follow_omega, 3.5, bodies[2].tuning.follow_omega]


def test_the_rest_shortcut_takes_a_zero_step_but_not_an_infinite_one() -> None:
    """A step of 0 s changes nothing (rest); a step of ``inf`` is no step the spring can take (the full
    step gives NaN there, which the shortcut must not hide). Kills ``0.0 < dt`` and ``dt <= inf``."""
    from engine.statemachine.puppet.follow import _at_rest

    z, h, w = np.zeros((2, 3)), np.zeros((2, 12, 3)), np.full(2, 40.0)
    assert _at_rest(z, z, h, w, 0.0)
    assert not _at_rest(z, z, h, w, float("inf"))
    assert _at_rest(z, z, h, np.zeros(2), 1 / 60)  # a stiffness of 0 still leaves 0 at 0


@pytest.mark.parametrize("stand", [False, True])
def test_requests_written_in_the_players_rows_read_as_the_plain_ones(stand: bool) -> None:
    """With ``player_rows`` the speeds (and, standing, the heights) go straight into the players' row block
    (:mod:`engine.rows`): every player then reads what the one-by-one path gives, a Python float speed and
    ``None``, and no player left its block. Broken once by not clearing the heights' presence in the rows
    (the heights stayed 0.7), and once by writing the still puppets' speeds to the batch's first rows: both failed."""
    walks = _walks()
    _, _, ref_players = _reference(walks)
    world, made = _world(walks)
    bodies = [world.get(e, PuppetBody) for e in made]
    transforms = [world.get(e, Transform) for e in made]
    players = tuple(LocomotionPlayer(speed=-1.0, height=0.7) for _ in made)
    block = row_store(world).block(LocomotionPlayer, players)
    assert not block.stale
    standing = {"stand": True} if stand else {}
    follow_released(DT, bodies, transforms, players, None, None, **standing, player_rows=(block, slice(None)))
    assert not block.stale and all(p.__dict__.get("_row_link") is not None for p in players)
    assert [p.speed for p in players] == [p.speed for p in ref_players]
    assert all(type(p.speed) is float for p in players)
    assert [p.height for p in players] == ([None] * len(players) if stand else [0.7] * len(players))


def test_requests_go_player_by_player_once_the_rows_are_stale() -> None:
    """A block marked stale (a value its rows could not hold was assigned) is not written: the players are, one by
    one, the unlinked one included. Broken once by writing the stale block's arrays anyway: it failed."""
    players = tuple(LocomotionPlayer(speed=0.5) for _ in range(3))
    block = row_store(World()).block(LocomotionPlayer, players)
    players[1].speed = 2  # an int: player 1 leaves the block, which goes stale
    assert block.stale
    set_requests(players, (block, slice(None)), np.array([0.25, 0.5, 0.75]), stand=True)
    assert [p.speed for p in players] == [0.25, 0.5, 0.75] and [p.height for p in players] == [None] * 3
