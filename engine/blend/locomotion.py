"""The animation stage for locomotion: requests in user units in, local poses and root motion out.

Per frame, for every puppet with a :class:`LocomotionPlayer` (written by the state
machine: requested root speed in m/s and hips height in m):

1. the request is resolved by the set's lookup table — projected onto the feasible
   border when out of reach, with the playback speed-up ``u/u'`` (thesis §6.2.3);
2. the blend point eases toward the answer (time constant ``smoothing``), so a state
   switch never pops the pose;
3. the shared phase advances by ``dt·rate / Σ wᵢTᵢ`` and the blended root motion over
   that phase interval moves the puppet's ``Transform`` (turned into its heading);
4. the blended pose (cross-faded with a one-shot or override clip, if one plays)
   is written to ``LocalPose`` with the root in world space and the heading folded
   into joint 0, ready for IK and FK;
5. the blend's foot-contact votes (each clip's contact labels, weighted) go to the
   puppet's ``IKRequest.foot_lock``, so the leg IK holds planted feet where they landed.

Puppets sharing a locomotion set are evaluated together, batched over puppets:
one inside test and one k-d tree query for all their requests, one sample per
active clip for all their phases; with numba (:mod:`engine.jit`) steps 3–5's blend
(weights, phase, root motion, pose, votes) is one compiled pass over the group
(:mod:`engine.blend._kernel`). A puppet asking what it asked last step is answered
from last step (:mod:`engine.blend._requests`): only the changed requests are resolved.
Assets (spaces, tables, clips) live in the :class:`BlendLibrary` resource; the
component holds only what changes per frame. Time is ``world.dt`` steps only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import repeat
from operator import attrgetter, is_, itemgetter

import numpy as np
from numpy.typing import NDArray

from engine import jit, quat
from engine.app import App
from engine.blend import _kernel, _requests
from engine.blend.lookup import LookupTable
from engine.blend.measure import contact_votes
from engine.blend.pose_blend import crossfade, fade_weight
from engine.blend.space import BlendSpace
from engine.clip import Clip
from engine.clips.contacts import foot_contacts
from engine.columns import columns
from engine.components import LocalPose, Puppet, Transform
from engine.ecs import Entity, World
from engine.ik.foot_lock import FootLock
from engine.ik.system import IKRequest
from engine.pose import Pose

__all__ = ["LocomotionSet", "BlendLibrary", "LocomotionPlayer", "animate", "install_blend"]

from engine.arrays import F64 as F

_UP = np.array([0.0, 1.0, 0.0])
_SETTLE_SPEED = 0.05  # m/s: asked for less, a puppet is coming to stand (its feet shuffle into place)


@dataclass(frozen=True)
class LocomotionSet:
    """One character's locomotion assets: the blend space, its measured lookup and extra clips.

    Args:
        space: the cyclic blend space.
        table: its lookup table, properties ``(speed m/s, hips height m)``.
        clips: clips a state may play over the blend by name (get-up, mid-jump…).
        smoothing: time constant (s) of the blend point's easing toward each answer.
    """

    space: BlendSpace
    table: LookupTable
    clips: dict[str, Clip] = field(default_factory=dict)
    smoothing: float = 0.04

    def standing_heights(self, speeds: F) -> F:
        """What ``height=None`` requests: the tallest blend at each speed (beyond the fastest, at the fastest)."""
        s = np.minimum(np.asarray(speeds, dtype=np.float64), self.table.values[:, 0].max())
        _, hi = self.table.extent_many(np.stack([s, np.full_like(s, self.table.values[0, 1])], axis=-1), 1)
        return np.where(np.isnan(hi), self.table.values[:, 1].max(), hi)


class BlendLibrary:
    """Resource: locomotion sets by name (``"humanoid"``, ``"snowman"``…). An asset store, not sim state."""

    SIM_STATE = False

    def __init__(self) -> None:
        self.sets: dict[str, LocomotionSet] = {}
        self.last_answers: dict[str, _requests.LastAnswers] = {}
        self.contact_tracks: dict[str, list[NDArray[np.bool_]] | None] = {}

    def add(self, name: str, locomotion: LocomotionSet) -> None:
        """Register (or replace) a set."""
        self.sets[name] = locomotion
        self.last_answers.pop(name, None)
        self.contact_tracks.pop(name, None)

    def tracks(self, name: str) -> list[NDArray[np.bool_]] | None:
        """Each clip's per-frame foot contacts ``[frames, 2]`` of set ``name`` (``None`` for a
        skeleton without ``l_foot``/``r_foot``): what the leg IK's foot locks follow."""
        if name not in self.contact_tracks:
            clips = self[name].space.clips
            feet = all({"l_foot", "r_foot"} <= set(c.skeleton.names) for c in clips)
            self.contact_tracks[name] = [foot_contacts(c) for c in clips] if feet else None
        return self.contact_tracks[name]

    def __getitem__(self, name: str) -> LocomotionSet:
        try:
            return self.sets[name]
        except KeyError:
            raise KeyError(f"no locomotion set {name!r}; loaded: {sorted(self.sets)}") from None

    def __contains__(self, name: object) -> bool:
        return name in self.sets


@dataclass
class LocomotionPlayer:
    """Per-puppet playback state. The state machine writes ``speed``/``height`` and calls :meth:`play`.

    Attributes:
        library_key: which :class:`LocomotionSet` drives this puppet.
        scale: the puppet's size relative to the set's clips. Requests are divided by it
            and the root's height and travel multiplied by it (rotations are kept), so a
            snowman with legs 0.6 as long plays the puppet's set at 0.6 with planted feet,
            and every puppet of a set is posed in one batch whatever its size.
        speed: requested ground speed (m/s, ≥ 0) along the puppet's heading.
        height: requested hips height (m); ``None`` stands tall.
        point: the blend point in use (eased), ``None`` until the first step.
        feasible: the request actually played (after projection), in the puppet's units.
        inside: whether the last request was feasible.
        rate: playback speed-up applied (1 inside the feasible set).
        phase: shared normalised phase in ``[0, 1)``.
        override: name of a clip playing over the blend, if any.
        override_time: seconds into the override clip.
        override_fade: cross-fade duration in and out (s).
        override_weight: linear fade progress in ``[0, 1]``.
        override_stopping: fading the override out.
        override_hold: a non-looping override holds its last frame until :meth:`stop`.
        override_scrub: the state sets ``override_time`` itself each step (a jump's pose
            follows its place on the arc) instead of the clip playing on by ``dt``.
        finished: name of a one-shot that ended this step (cleared next step).
    """

    library_key: str = "humanoid"
    scale: float = 1.0
    speed: float = 0.0
    height: float | None = None
    point: F | None = None
    feasible: F | None = None
    inside: bool = True
    rate: float = 1.0
    phase: float = 0.0
    override: str | None = None
    override_time: float = 0.0
    override_fade: float = 0.2
    override_weight: float = 0.0
    override_stopping: bool = False
    override_hold: bool = False
    override_scrub: bool = False
    finished: str | None = None

    def play(self, clip: str, fade: float = 0.2, hold: bool = False) -> None:
        """Cross-fade a named clip in over the blend.

        A non-looping clip fades out by itself at its end, unless ``hold`` (a jump's
        mid-air pose held until landing), which keeps its last frame until :meth:`stop`.
        """
        if fade < 0:
            raise ValueError("fade time must be non-negative")
        if self.override != clip:
            self.override_time = 0.0
            self.override_weight = 0.0 if self.override is None else self.override_weight
        self.override, self.override_fade, self.override_stopping = clip, fade, False
        self.override_hold, self.override_scrub = hold, False

    def stop(self, fade: float = 0.2) -> None:
        """Fade the override clip out, back to the blend."""
        if self.override is not None:
            self.override_fade, self.override_stopping = fade, True


def _override(player: LocomotionPlayer, loco: LocomotionSet, dt: float) -> tuple[Clip | None, float, F]:
    """Advance the override clip: (clip, eased weight, its root travel this step in clip frame)."""
    if player.override is None:
        return None, 0.0, np.zeros(3)
    clip = loco.clips.get(player.override)
    if clip is None:
        raise KeyError(f"clip {player.override!r} is not in the locomotion set; available: {sorted(loco.clips)}")
    t0, t1 = player.override_time, player.override_time + (0.0 if player.override_scrub else dt)
    fade = player.override_fade
    if (
        not clip.loop
        and not player.override_hold
        and not player.override_scrub
        and not player.override_stopping
        and t1 >= clip.duration - fade
    ):
        player.override_stopping = True
    step = dt / fade if fade > 0 else 1.0
    step = -step if player.override_stopping else step
    player.override_weight = float(np.clip(player.override_weight + step, 0.0, 1.0))
    player.override_time = t1
    travel = clip.sample_root_motion(t1)[0] - clip.sample_root_motion(t0)[0]
    if player.override_stopping and player.override_weight <= 0.0:
        player.finished = player.override
        player.override, player.override_stopping, player.override_time = None, False, 0.0
        return None, 0.0, np.zeros(3)
    return clip, fade_weight(player.override_weight, 1.0), travel


def _yaw(rotation: F) -> F:
    """Heading angles ``[B]`` about +Y of rotations ``[B, 4]`` (their +Z axis in the ground plane)."""
    w, x, y, z = rotation[:, 0], rotation[:, 1], rotation[:, 2], rotation[:, 3]
    return np.arctan2(2.0 * (x * z + w * y), 1.0 - 2.0 * (x * x + y * y))


_Row = tuple[int, Transform, Puppet, "LocomotionPlayer"]


def _play_compiled(pk: _kernel.Packed, points: F, phase: F, rates: F, dt: float) -> tuple[F, F, F, F, F, F | None]:
    """:meth:`BlendSpace.advance`, :meth:`~BlendSpace.sample` and :func:`contact_votes` of a group in one
    compiled pass: (root, rotations, new phase, travel, turn, votes or ``None``)."""
    count, joints, legs = len(points), pk.rotations.shape[1], pk.contacts.shape[1]
    w, new_phase, travel, turn = (
        np.empty((count, len(pk.points))),
        np.empty(count),
        np.empty((count, 3)),
        np.empty(count),
    )
    root, rots, votes = np.empty((count, 3)), np.empty((count, joints, 4)), np.empty((count, legs))
    _kernel.play(
        pk.points,
        pk.durations,
        pk.fps,
        pk.frames,
        pk.start,
        pk.knot_x,
        pk.knot_y,
        pk.roots,
        pk.rotations,
        pk.tables,
        pk.cycles,
        pk.contacts,
        pk.arc_next,
        pk.arc_angle,
        pk.arc_sin,
        np.ascontiguousarray(points, dtype=np.float64),
        phase,
        np.ascontiguousarray(rates, dtype=np.float64),
        dt,
        w,
        new_phase,
        travel,
        turn,
        root,
        rots,
        votes,
    )
    return root, rots, new_phase, travel, turn, (votes if legs else None)


def animate(world: World) -> None:
    """The animation-stage system: resolve, advance and pose every locomotion puppet (batched per set)."""
    library = world.try_resource(BlendLibrary)
    if library is None:
        return
    rows = world.query(Transform, Puppet, LocomotionPlayer)
    if not rows:
        return
    keys = list(map(_KEY, map(itemgetter(3), rows)))
    if keys.count(keys[0]) == len(keys):  # one set for the whole crowd: the query's rows are the batch
        groups: dict[str, list[_Row]] = {keys[0]: rows}
    else:
        groups = {}
        for key, row in zip(keys, rows, strict=True):
            groups.setdefault(key, []).append(row)
    dt = world.dt
    for key, members in groups.items():
        _animate_group(world, library, key, members, dt)


_KEY = attrgetter("library_key")


def _animate_group(world: World, library: BlendLibrary, key: str, members: list[_Row], dt: float) -> None:
    """One locomotion set's puppets: array passes, and per-puppet Python only to write the players'
    scalar fields and for a puppet playing an override clip. The array fields (blend point, feasible
    request, position, local pose, foot-contact votes) are written through the world's
    :mod:`engine.columns`."""
    loco = library[key]
    space = loco.space
    cols = columns(world)
    entities: list[Entity] = list(map(itemgetter(0), members))
    transforms: list[Transform] = list(map(itemgetter(1), members))
    players: list[LocomotionPlayer] = list(map(itemgetter(3), members))
    alpha = 1.0 if loco.smoothing <= 0 else 1.0 - np.exp(-dt / loco.smoothing)
    req = _requests.read(entities, players)
    answers = _requests.resolve(library.last_answers, key, loco, req)
    target = answers.points
    point_column = cols.get(LocomotionPlayer, "point", key)
    if req.any_fresh():
        eased = np.array([t if p is None else p for p, t in zip(req.points, target, strict=True)])
        fresh = np.fromiter(map(is_, req.points, repeat(None)), dtype=np.bool_, count=len(players))
        points = np.where(fresh[:, None], target, eased + alpha * (target - eased))
    else:
        eased = point_column.read(players)
        points = eased + alpha * (target - eased)
    scale = req.scales
    rates = answers.rates
    feasible = answers.feasible * scale[:, None]
    point_column.write(players, points)
    cols.get(LocomotionPlayer, "feasible", key).write(players, feasible)
    phase = req.phases
    tracks = library.tracks(key)
    packed = _kernel.packed(space, tracks) if jit.enabled() else None
    if packed is None:
        w = space.weights(points)
        # Scaling the phase step by the rate already scales the root travel: feet keep pace with the ground.
        new_phase, travel, turn = space.advance(phase, w, dt, rates)
        pose = space.sample(w, new_phase)
        blended, rots = pose.root, pose.rotations.copy()
        votes = None if tracks is None else contact_votes(space, w, new_phase, tracks)
    else:
        blended, rots, new_phase, travel, turn, votes = _play_compiled(packed, points, phase, rates, dt)
    roots = blended * scale[:, None]
    travel = travel * scale[:, None]
    keep_turn = np.ones(len(members))
    faded = np.zeros(len(members))  # the override clip's weight, where one plays
    wrapped = (new_phase % 1.0).tolist()
    for player, inside, rate, ph in zip(players, answers.inside.tolist(), rates.tolist(), wrapped, strict=True):
        player.finished, player.inside, player.rate, player.phase = None, inside, rate, ph
    for i, player in enumerate(players) if req.any_override() else ():
        if player.override is None:  # the unusual puppet: a one-shot or a held pose over its blend
            continue
        clip, weight, clip_travel = _override(player, loco, dt)
        if clip is not None:
            over = clip.sample(player.override_time)
            local = crossfade(Pose(roots[i], rots[i]), Pose(over.root * scale[i], over.rotations), weight)
            roots[i], rots[i] = local.root, local.rotations
            travel[i] = (1.0 - weight) * travel[i] + weight * clip_travel * scale[i]
            keep_turn[i] = 1.0 - weight
            faded[i] = weight
    _contacts(world, entities, req.speeds, votes, faded)
    # Heading, travel and the world root for the whole group at once.
    rotation_column, position_column = cols.get(Transform, "rotation"), cols.get(Transform, "position")
    rotation = rotation_column.read(transforms)
    if req.any_override():
        turn = turn * keep_turn
    if jit.enabled():
        positions = position_column.read(transforms)  # moved in place
        headings, world_roots = np.empty_like(rotation), np.empty_like(roots)
        _kernel.place(rotation, positions, travel, turn, roots, rots, headings, world_roots)
    else:
        positions, headings, world_roots = _place(rotation, position_column.read(transforms), travel, turn, roots, rots)
    position_column.write(transforms, positions)
    rotation_column.write(transforms, headings)
    poses = list(map(world.components(LocalPose).get, entities))
    if any(map(is_, poses, repeat(None))):  # a puppet's first pose
        for i, e in enumerate(entities):
            if poses[i] is None:
                world.queue_add(e, LocalPose(world_roots[i], rots[i]))
        return
    joints = rots.shape[1]
    cols.get(LocalPose, "root", joints).write(poses, world_roots)
    cols.get(LocalPose, "rotations", joints).write(poses, rots)


def _place(rotation: F, positions: F, travel: F, turn: F, roots: F, rots: F) -> tuple[F, F, F]:
    """Numpy twin of :func:`engine.blend._kernel.place`: new positions, headings and world roots; the
    heading is folded into joint 0 of ``rots`` (in place)."""
    yaw = _yaw(rotation)
    step = quat.rotate(quat.from_axis_angle(_UP, yaw), travel)
    turn_q = quat.from_axis_angle(_UP, turn)
    hq_new = quat.from_axis_angle(_UP, yaw + turn)
    rots[:, 0] = quat.mul(hq_new, rots[:, 0])
    moved = positions + step
    return moved, quat.normalize(quat.mul(turn_q, rotation)), moved + quat.rotate(hq_new, roots)


def _contacts(world: World, entities: list[Entity], speeds: F, votes: F | None, faded: F) -> None:
    """The blend's foot-contact votes (less an override clip's weight) and the settle flag to each
    puppet's foot lock, so the leg IK holds planted feet where they landed."""
    requests = list(map(world.components(IKRequest).get, entities))
    settle = (speeds < _SETTLE_SPEED).tolist()
    has = None if not any(map(is_, requests, repeat(None))) else [r is not None for r in requests]
    if has is not None:  # puppets without leg IK take no votes
        settle = [flag for flag, ok in zip(settle, has, strict=True) if ok]
        requests = [r for r in requests if r is not None]
    locks: list[FootLock] = list(map(_FOOT_LOCK, requests))
    for lock, flag in zip(locks, settle, strict=True):
        lock.settle = flag
    if votes is None:
        for lock in locks:
            lock.contacts = None
        return
    contacts = votes * (1.0 - faded)[:, None]
    if has is not None:
        contacts = contacts[np.array(has)]
    columns(world).get(FootLock, "contacts", contacts.shape[1]).write(locks, contacts)


_FOOT_LOCK = attrgetter("foot_lock")


def install_blend(app: App) -> None:
    """Plugin: the :class:`BlendLibrary` resource (if absent) and :func:`animate` in the animation stage."""
    if app.world.try_resource(BlendLibrary) is None:
        app.world.insert_resource(BlendLibrary())
    app.add_system("animation", animate)
