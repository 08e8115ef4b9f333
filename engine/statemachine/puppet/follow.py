"""Locomotion control: how a held puppet's requested velocity follows the stick.

Game engines do not feed a character's raw input to its blend: a *critically damped
spring* on the requested velocity (Unity's ``SmoothDamp``, Unreal's "velocity
smoothing") turns a jittery or stepped input into a request that is smooth (no pose
pops, so no foot sliding from sudden blend changes) yet fast (no overshoot, 90 % of a
step in ``3.89 / ω`` seconds). What it tracks here is the stick's own ground velocity
(feed-forward: a puppet dragged at 1.2 m/s is asked for 1.2 m/s, whatever its lag)
plus a catch-up proportional to the remaining distance, faded in smoothly over the
dead band instead of switched at a hard radius (a switch made the request jump
between a walk and a stroll several times a second, and each jump skated the feet).

The request is not clamped to the fastest clip: the lookup table projects an
out-of-reach speed onto its border and plays the animation faster (thesis §6.2.3,
``u/u'``), so a fast drag makes the puppet sprint rather than fall behind and drop.
The puppet turns toward the direction of its smoothed velocity at a bounded rate and
walks only as fast as its facing allows, so a reversal turns it around. The drag
limit grows with the puppet's own speed (a running puppet reaches further), never with
the stick's (a yank stays a yank).

Everything is arrays over the ground plane, one puppet at a time; a crowd's released
puppets (no stick, the spring settling to rest) go through :func:`follow_released` in one
pass, with the same numbers. Time is ``world.dt``.
"""

from __future__ import annotations

import operator
from collections.abc import Sequence
from itertools import repeat

import numpy as np
from numpy.typing import NDArray

from engine.arrays import Intp as Rows
from engine.batches import assign
from engine.blend.locomotion import LocomotionPlayer
from engine.columns import Columns
from engine.components import Transform
from engine.ecs import Entity, World
from engine.rows import RowBlock
from engine.statemachine.puppet.body import PuppetBody, PuppetTuning
from engine.statemachine.puppet.senses import heading_vector, yaw_rotation

__all__ = ["spring_step", "wanted_velocity", "follow_velocity", "follow_released", "drag_reach", "tuning_columns"]

from engine.arrays import F64 as F

_TURN_FROM = 0.1  # m/s: a request slower than this turns nothing; twice this turns at the full rate


def spring_step(value: F, rate: F, goal: F, omega: float | F, dt: float) -> tuple[F, F]:
    """One exact step of a critically damped spring pulling ``value`` toward ``goal``.

    The closed form of ``x'' = -2ωx' - ω²x`` (``x = value - goal``) over ``dt``, so it is
    stable for any step and does not overshoot a step change. Returns ``(value, rate)``.
    ``omega`` may be a column (``[n, 1]``) for ``n`` springs at once.
    """
    x = value - goal
    decay = np.exp(-omega * dt)
    k = rate + omega * x
    return goal + (x + k * dt) * decay, (rate - omega * k * dt) * decay


def wanted_velocity(error: F, lead: F, tuning: PuppetTuning, lead_band: float = 0.02) -> F:
    """The ground velocity the puppet should have: the stick's, plus a catch-up on ``error``.

    The catch-up gain fades in as ``d² / (d² + deadband²)`` of the distance ``d``, so a
    puppet standing at its stick does not creep toward every tremor of the hand, and
    nothing switches at a radius; the stick's velocity counts in full once the stick leads
    the puppet by ``lead_band`` along it, and not at all once the puppet has caught up. The result is capped at ``tuning.top_speed``.
    """
    d2 = float(error @ error)
    band2 = tuning.follow_deadband**2
    pace = float(np.linalg.norm(lead))
    # The feed-forward needs the stick to be ahead of the puppet along the lead: it fades in over
    # the first ``lead_band`` metres and is gone once the puppet has caught up. A puppet never strides past a
    # hand that stopped (its filtered velocity still trails), and a hand that jerks the stick
    # out and back (a wheel notch's slide, a twitch) does not drag a standing puppet about.
    behind = float(error @ lead) / pace if pace > 1e-9 else 0.0
    gate = float(np.clip(behind / lead_band, 0.0, 1.0))
    wanted = gate * lead + tuning.catch_up_gain * (d2 / (d2 + band2) if d2 > 0.0 else 0.0) * error
    speed = float(np.linalg.norm(wanted))
    return wanted * (tuning.top_speed / speed) if speed > tuning.top_speed else wanted


def drag_reach(body: PuppetBody) -> float:
    """How far the stick may run ahead before the puppet counts as yanked: more for a faster puppet."""
    t = body.tuning
    return t.drag_limit + t.drag_lead_time * float(np.linalg.norm(body.walk_velocity))


def _wrap(angle: float) -> float:
    return float((angle + np.pi) % (2 * np.pi) - np.pi)


def follow_velocity(
    world: World,
    entity: Entity,
    body: PuppetBody,
    player: LocomotionPlayer,
    speed_scale: float = 1.0,
    lead_band: float = 0.02,
) -> None:
    """Steer toward the stick: smooth the wanted velocity, turn toward it, request its speed.

    ``lead_band`` (m): how far the stick must lead before its velocity counts in full (see
    :func:`wanted_velocity`); a crouched puppet asks for more, as its stick is being lowered."""
    tr = world.get(entity, Transform)
    t = body.tuning
    if body.held_by is None:
        goal = np.zeros(3)
    else:
        error = (body.target - tr.position) * np.array([1.0, 0.0, 1.0])
        goal = wanted_velocity(error, body.lead * np.array([1.0, 0.0, 1.0]), t, lead_band)
    # Braking is quicker than speeding up (people stop within a step): twice the stiffness.
    braking = float(np.linalg.norm(goal)) < float(np.linalg.norm(body.walk_velocity))
    omega = t.follow_omega * (2.0 if braking else 1.0)
    body.walk_velocity, body.walk_rate = spring_step(body.walk_velocity, body.walk_rate, goal, omega, world.dt)
    v = body.walk_velocity
    _face(tr, body, player, float(np.hypot(v[0], v[2])), world.dt, speed_scale)
    body.recent = np.vstack([body.recent[1:], body.walk_velocity])


def _face(
    tr: Transform, body: PuppetBody, player: LocomotionPlayer, speed: float, dt: float, speed_scale: float
) -> None:
    """Turn toward the smoothed velocity at a bounded rate; ask the clip for the speed the facing allows."""
    t = body.tuning
    v = body.walk_velocity
    facing = 1.0
    if speed > 1e-3:
        turn = _wrap(float(np.arctan2(v[0], v[2])) - body.heading)
        # A slow puppet pivots on the spot faster than a running one can swing round; one
        # coming to rest stops turning (the fading request's direction is noise, and a few
        # centimetres past the hand are not worth turning round for).
        rate = t.turn_rate * (1.0 + 1.0 / (1.0 + speed)) * float(np.clip((speed - _TURN_FROM) / _TURN_FROM, 0.0, 1.0))
        body.heading = _wrap(body.heading + float(np.clip(turn, -rate * dt, rate * dt)))
        facing = max(float(heading_vector(body.heading) @ (v / speed)), 0.0)
    tr.rotation = yaw_rotation(body.heading)
    player.speed = speed * facing * speed_scale


def follow_released(
    dt: float,
    bodies: Sequence[PuppetBody],
    transforms: Sequence[Transform],
    players: Sequence[LocomotionPlayer],
    cols: Columns | None = None,
    block_rows: tuple[RowBlock, Rows | slice] | None = None,
    stand: bool = False,
    player_rows: tuple[RowBlock, Rows | slice] | None = None,
) -> None:
    """:func:`follow_velocity` (``speed_scale`` 1) for puppets no stick holds, over arrays.

    Unheld, the spring pulls the request to rest; the spring step, the speed and the
    facing rotation are computed for all at once with the very operations of the
    single-puppet path (elementwise, so the numbers are the same), and only a puppet
    still moving fast enough to turn is turned one by one. With ``block_rows`` (the row
    block the bodies are linked to and their rows in it, :mod:`engine.rows`) the bodies'
    spring state, heading and stiffness are read and written in the block's arrays, no
    body touched; with ``cols`` the rotations of the puppets that stand are written as a
    column of :mod:`engine.columns`. ``stand`` also sets every player's ``height`` to ``None``
    (standing tall) in the pass that sets its speed: one visit of each player. With ``player_rows``
    (the players' rows in their row block) the speeds and heights are written there whole (see
    :func:`set_requests`)."""
    n = len(bodies)
    if n == 0:
        return
    if block_rows is None:
        value = np.array([b.walk_velocity for b in bodies], dtype=np.float64).reshape(n, 3)
        rate = np.array([b.walk_rate for b in bodies], dtype=np.float64).reshape(n, 3)
        recent = np.array([b.recent for b in bodies], dtype=np.float64).reshape(n, -1, 3)
        follow_omega = np.fromiter(map(_OMEGA, bodies), np.float64, n)
        heading = np.fromiter(map(_HEADING, bodies), np.float64, n)
    else:
        block, rows = block_rows
        a = block.arrays
        value, rate, recent, heading = (
            a["walk_velocity"][rows],
            a["walk_rate"][rows],
            a["recent"][rows],
            a["heading"][rows],
        )
        follow_omega = tuning_columns(block)[1][rows]
    rotation = yaw_rotation(heading)
    if block_rows is not None and _at_rest(value, rate, recent, follow_omega, dt):
        speed = np.zeros(n)  # the spring's exact rest is a fixed point: nothing to step, nothing to write
    else:
        goal = np.zeros((n, 3))
        # The single path brakes when |goal| = 0 < |v|, i.e. when v·v > 0 (a sum of squares is
        # positive exactly when one of them is).
        braking = (value * value).sum(axis=1) > 0.0
        omega = (follow_omega * np.where(braking, 2.0, 1.0))[:, None]
        value, rate = spring_step(value, rate, goal, omega, dt)
        speed = np.hypot(value[:, 0], value[:, 2])
        recent = np.concatenate([recent[:, 1:], value[:, None]], axis=1)
        if block_rows is None:
            for i, body in enumerate(bodies):
                body.walk_velocity, body.walk_rate, body.recent = value[i], rate[i], recent[i]
        else:
            a["walk_velocity"][rows], a["walk_rate"][rows], a["recent"][rows] = value, rate, recent
    moving = speed > 1e-3
    turning = np.flatnonzero(moving).tolist()
    if stand:  # every player's speed now; a turning puppet's is set again by _face below
        set_requests(players, player_rows, speed, stand=True)
    for i in turning:
        _face(transforms[i], bodies[i], players[i], float(speed[i]), dt, 1.0)
    if turning:
        still = np.flatnonzero(~moving)
        players = [players[i] for i in still.tolist()]
        speed = speed[still]
        player_rows = rows_of(player_rows, still)
        transforms = [transforms[i] for i in still.tolist()]
        rotation = rotation[still]
    if not stand:
        set_requests(players, player_rows, speed)
    if cols is None or len(transforms) < n // 2:
        for tr, q in zip(transforms, rotation, strict=True):
            tr.rotation = q
    else:
        cols.get(Transform, "rotation").write(transforms, rotation)


def set_requests(
    players: Sequence[LocomotionPlayer], at: tuple[RowBlock, Rows | slice] | None, speeds: F, stand: bool = False
) -> None:
    """``players[i].speed = speeds[i]`` (a Python float, as ``tolist`` makes it) and, with ``stand``, ``height = None``.

    ``at``: the players' rows in the row block they are linked to (:mod:`engine.rows`), where a crowd's requests are
    written whole, no player touched; while that block is intact (an assignment the rows could not hold marks it
    stale), else player by player (the loop in C, :func:`engine.batches.assign`)."""
    if at is not None and not at[0].stale:
        block, rows = at
        if stand:
            block.present["height"][rows] = False
        block.arrays["speed"][rows] = speeds
        return
    if stand:
        assign(players, "height", repeat(None))
    assign(players, "speed", speeds.tolist())


def rows_of(at: tuple[RowBlock, Rows | slice] | None, picked: Rows) -> tuple[RowBlock, Rows] | None:
    """The rows ``picked`` of a batch at rows ``at`` of a row block (``picked`` indexes the batch)."""
    if at is None:
        return None
    block, rows = at
    return block, (picked if isinstance(rows, slice) and rows == _ALL else np.asarray(rows)[picked])


_ALL = slice(None)


def tuning_columns(block: RowBlock) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Per row of a block of bodies: whether its tuning asks for the legacy controller, and its ``follow_omega``.

    Derived from the tuning objects once and kept with the block while no tuning is assigned
    (``RowBlock.objects_set``; a tuning is frozen), so a crowd's step reads no tuning."""
    kept = block.memo.get("tuning")
    if kept is None or kept[0] != block.objects_set:
        tunings = block.arrays["tuning"]
        n = len(tunings)
        legacy = np.fromiter((t.controller == "legacy" for t in tunings), np.bool_, n)
        omega = np.fromiter((t.follow_omega for t in tunings), np.float64, n)
        kept = block.memo["tuning"] = (block.objects_set, legacy, omega)
    return kept[1], kept[2]


def _at_rest(value: F, rate: F, recent: F, omega: F, dt: float) -> bool:
    """Whether every spring is exactly at rest (all its numbers +0.0; stiffness and step finite, ≥ 0).

    Then :func:`spring_step` toward a goal of 0 gives +0.0 again to the last bit (``0 · ω = 0``,
    ``(0 + 0·dt) · e^{-ωdt} = 0`` with ``e^{-ωdt}`` in ``[0, 1]``) and the history shifts in
    zeros: the step changes nothing. A crowd nobody has held is in this state all the time."""
    if not (0.0 <= dt < np.inf and np.isfinite(omega).all() and (omega >= 0.0).all()):
        return False
    return not any(np.ascontiguousarray(a).view(np.uint64).any() for a in (value, rate, recent))


_OMEGA = operator.attrgetter("tuning.follow_omega")
_HEADING = operator.attrgetter("heading")
