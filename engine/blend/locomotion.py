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

from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import repeat
from operator import is_

import numpy as np
from numpy.typing import NDArray

from engine import jit, quat
from engine.app import App
from engine.batches import batch
from engine.blend import _groups, _kernel, _requests
from engine.blend.lookup import LookupTable
from engine.blend.measure import contact_votes
from engine.blend.pose_blend import crossfade, fade_weight
from engine.blend.space import BlendSpace
from engine.clip import Clip
from engine.clips.contacts import foot_contacts
from engine.columns import Column, Columns, assignment_mark, columns, unassigned_since
from engine.components import LocalPose, Puppet, Transform
from engine.ecs import World
from engine.ik.foot_lock import FootLock
from engine.ik.system import IKRequest
from engine.pose import Pose
from engine.rows import RowBlock, keep_in_rows, row_store

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
        self.groups = _groups.Groups()

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


# What the stage reads or writes of every player every step, kept in rows (:mod:`engine.rows`): one array
# each over the crowd, so neither the requests (written by the state machine as arrays too), the set names,
# the phases and overrides read nor the four results written cost a pass over a thousand player objects. A
# value a row cannot hold exactly (an ``int`` phase) unlinks the batch back to plain objects, and the stage
# then takes them one by one, as before.
keep_in_rows(
    LocomotionPlayer,
    speed=("float", (), False),
    height=("float", (), True),
    library_key=("object", (), False),
    inside=("object", (), False),
    rate=("float", (), False),
    phase=("float", (), False),
    override=("object", (), False),
    finished=("object", (), False),
)


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


def _scales(group: _groups.Group) -> F:
    """The group's players' scales: read from every player once, then kept (in the group) while no player's scale
    was assigned (:func:`engine.columns.assignment_mark`; a puppet's size is set when it is made). Shared: read it,
    never change it."""
    kept = group.scaled
    if kept is not None and unassigned_since(kept[1]):
        return kept[0]
    mark = assignment_mark(LocomotionPlayer, ("scale",))
    scales = np.array([p.scale for p in group.players], dtype=np.float64)
    group.scaled = (scales, mark)
    return scales


def _yaw(rotation: F) -> F:
    """Heading angles ``[B]`` about +Y of rotations ``[B, 4]`` (their +Z axis in the ground plane)."""
    w, x, y, z = rotation[:, 0], rotation[:, 1], rotation[:, 2], rotation[:, 3]
    return np.arctan2(2.0 * (x * z + w * y), 1.0 - 2.0 * (x * x + y * y))


def _play_compiled(
    pk: _kernel.Packed,
    eased: F,
    target: F,
    alpha: float,
    ease: bool,
    phases: F,
    rates: F,
    scales: F,
    feasible: F,
    dt: float,
    out: _Out,
) -> None:
    """Easing, :meth:`BlendSpace.advance`, :meth:`~BlendSpace.sample`, :func:`contact_votes` and the scalings
    of a group in one compiled pass (:func:`engine.blend._kernel.play`), into ``out``'s arrays."""
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
        eased,
        target,
        alpha,
        ease,
        phases,
        rates,
        scales,
        feasible,
        dt,
        out.feasible,
        out.weights,
        out.phase,
        out.wrapped,
        out.travel,
        out.turn,
        out.roots,
        out.rotations,
        out.votes,
    )


def animate(world: World) -> None:
    """The animation-stage system: resolve, advance and pose every locomotion puppet (batched per set)."""
    library = world.try_resource(BlendLibrary)
    if library is None:
        return
    kept = batch(world, "locomotion", (Transform, Puppet, LocomotionPlayer), (LocalPose, IKRequest))
    if not kept.entities:
        return
    dt = world.dt
    store = row_store(world)
    block = store.block(LocomotionPlayer, kept.lists[2])
    rowed = None if block.stale else block
    for group in library.groups.of(kept, rowed):
        at = None if rowed is None else store.rows(LocomotionPlayer, group.players)
        _animate_group(world, library, group, dt, at)


class _Out:
    """The compiled pass's outputs for a group of ``count`` puppets (blend points of ``dims``, ``weights`` clips,
    ``joints``, ``legs``): fresh arrays, some replaced by the columns themselves where the components' fields
    all view them (written in place, nothing to copy after)."""

    def __init__(self, count: int, dims: int, weights: int, joints: int, legs: int) -> None:
        self.feasible = np.empty((count, dims))
        self.weights = np.empty((count, weights))
        self.phase, self.wrapped, self.turn = np.empty(count), np.empty(count), np.empty(count)
        self.travel, self.roots = np.empty((count, 3)), np.empty((count, 3))
        self.rotations = np.empty((count, joints, 4))
        self.votes = np.empty((count, legs))


def _linked(column: Column, owners: Sequence[object], shape: tuple[int, ...]) -> F | None:
    """The column of ``owners`` when their fields all view it and it has ``shape`` (to write in place)."""
    base = column.linked(owners)
    return base if base is not None and base.shape == shape and base.dtype == np.float64 else None


def _animate_group(
    world: World,
    library: BlendLibrary,
    group: _groups.Group,
    dt: float,
    at: tuple[RowBlock, slice | NDArray[np.intp]] | None,
) -> None:
    """One locomotion set's puppets: array passes, and per-puppet Python only to read the requests and for a
    puppet playing an override clip. The players' row fields are read and written in their block's arrays
    (rows ``at``; one by one when ``None``). The array fields (blend point, feasible request, position, local
    pose, foot-contact votes) are written through the world's :mod:`engine.columns`; on the compiled path
    straight into them, when every component views its row."""
    key = group.key
    loco = library[key]
    space = loco.space
    cols = columns(world)
    entities, players = group.entities, group.players
    count = len(players)
    alpha = 1.0 if loco.smoothing <= 0 else 1.0 - np.exp(-dt / loco.smoothing)
    req = _requests.read(entities, players, at, _scales(group))
    answers = _requests.resolve(library.last_answers, key, loco, req)
    target = answers.points
    scale = req.scales
    overrides = req.override_rows()
    locks = group.foot_locks()
    tracks = library.tracks(key)
    packed = _kernel.packed(space, tracks) if jit.enabled() else None
    point_column, feasible_column = (
        cols.get(LocomotionPlayer, "point", key),
        cols.get(LocomotionPlayer, "feasible", key),
    )
    eased = _linked(point_column, players, target.shape)  # every player has a point: eased in place
    if eased is None:
        now = [p.point for p in players]
        fresh = np.fromiter(map(is_, now, repeat(None)), dtype=np.bool_, count=count)
        start = np.array([t if p is None else p for p, t in zip(now, target, strict=True)])
        eased = np.where(fresh[:, None], target, start + alpha * (target - start))
    elif packed is None:
        eased = eased + alpha * (target - eased)
    if packed is None:
        point_column.write(players, eased)
        feasible_column.write(players, answers.feasible * scale[:, None])
        w = space.weights(eased)
        # Scaling the phase step by the rate already scales the root travel: feet keep pace with the ground.
        new_phase, travel, turn = space.advance(req.phases, w, dt, answers.rates)
        pose = space.sample(w, new_phase)
        roots, rots = pose.root * scale[:, None], pose.rotations.copy()
        travel = travel * scale[:, None]
        votes = None if tracks is None else contact_votes(space, w, new_phase, tracks)
        wrapped = new_phase % 1.0
    else:
        joints, legs = packed.rotations.shape[1], packed.contacts.shape[1]
        out = _Out(count, target.shape[1], len(packed.points), joints, legs)
        if group.poses is not None:  # posed straight into the local poses' column when they all view it
            linked = _linked(cols.get(LocalPose, "rotations", joints), group.poses, out.rotations.shape)
            if linked is not None:
                out.rotations = linked
        if legs and not overrides and group.ik_rows is None:  # votes straight into the foot locks' column
            linked = _linked(cols.get(FootLock, "contacts", legs), locks, out.votes.shape)
            if linked is not None:
                out.votes = linked
        feasible_in = _linked(feasible_column, players, out.feasible.shape)
        if feasible_in is not None:
            out.feasible = feasible_in
        in_place = eased is point_column.base
        _play_compiled(
            packed, eased, target, float(alpha), in_place, req.phases, answers.rates, scale, answers.feasible, dt, out
        )
        if not in_place:
            point_column.write(players, eased)
        if feasible_in is None:
            feasible_column.write(players, out.feasible)
        roots, rots, travel, turn, wrapped = out.roots, out.rotations, out.travel, out.turn, out.wrapped
        votes = out.votes if legs else None
    if at is None:
        for player, inside, rate, ph in zip(
            players, answers.inside.tolist(), answers.rates.tolist(), wrapped.tolist(), strict=True
        ):
            player.finished, player.inside, player.rate, player.phase = None, inside, rate, ph
    else:  # the same values: an object row of a bool array holds Python bools, a float row reads as a float
        arrays, rows = at[0].arrays, at[1]
        arrays["finished"][rows] = None
        arrays["inside"][rows] = answers.inside
        arrays["rate"][rows] = answers.rates
        arrays["phase"][rows] = wrapped
    faded = None  # the override clips' weights, where one plays
    if overrides:
        keep_turn, faded = np.ones(count), np.zeros(count)
        for i in overrides:  # the unusual puppets: a one-shot or a held pose over the blend
            player = players[i]
            clip, weight, clip_travel = _override(player, loco, dt)
            if clip is not None:
                over = clip.sample(player.override_time)
                local = crossfade(Pose(roots[i], rots[i]), Pose(over.root * scale[i], over.rotations), weight)
                roots[i], rots[i] = local.root, local.rotations
                travel[i] = (1.0 - weight) * travel[i] + weight * clip_travel * scale[i]
                keep_turn[i] = 1.0 - weight
                faded[i] = weight
        turn = turn * keep_turn
    _contacts(group, locks, req.speeds, votes, faded, cols)
    _move(world, cols, group, travel, turn, roots, rots)


def _move(world: World, cols: Columns, group: _groups.Group, travel: F, turn: F, roots: F, rots: F) -> None:
    """Heading, travel and the world root for the whole group at once; the local poses written (on the
    compiled path ``rots`` may be the local poses' column already)."""
    transforms = group.transforms
    rotation_column, position_column = cols.get(Transform, "rotation"), cols.get(Transform, "position")
    rotation = rotation_column.read(transforms)
    poses = group.poses
    root_column = None if poses is None else cols.get(LocalPose, "root", rots.shape[1])
    if jit.enabled():
        positions = position_column.read(transforms)  # moved in place
        headings = rotation if rotation is rotation_column.base else np.empty_like(rotation)  # turned in place
        world_roots = None if root_column is None or poses is None else _linked(root_column, poses, roots.shape)
        if world_roots is None:
            world_roots = np.empty_like(roots)
        _kernel.place(rotation, positions, travel, turn, roots, rots, headings, world_roots)
    else:
        positions, headings, world_roots = _place(rotation, position_column.read(transforms), travel, turn, roots, rots)
    position_column.write(transforms, positions)
    rotation_column.write(transforms, headings)
    if root_column is None or poses is None:  # a puppet's first pose (the others wait for the next step)
        have = world.components(LocalPose)
        for i, e in enumerate(group.entities):
            if e not in have:
                world.queue_add(e, LocalPose(world_roots[i], rots[i]))
        return
    root_column.write(poses, world_roots)
    cols.get(LocalPose, "rotations", rots.shape[1]).write(poses, rots)


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


def _contacts(
    group: _groups.Group, locks: tuple[FootLock, ...], speeds: F, votes: F | None, faded: F | None, cols: Columns
) -> None:
    """The blend's foot-contact votes (less an override clip's weight ``faded``) and the settle flag to each
    puppet's foot lock (``locks``, the group's as handed out this step), so the leg IK holds planted feet
    where they landed."""
    settle = speeds < _SETTLE_SPEED
    rows = group.ik_rows
    flags = settle if rows is None else settle[rows]
    kept = group.settled
    if kept is not None and kept[0] is locks and unassigned_since(kept[2]):
        # The flags written last step are still in place (nobody assigned one since): only the changed are written.
        for i in np.flatnonzero(flags != kept[1]).tolist():
            locks[i].settle = bool(flags[i])
    else:
        for lock, flag in zip(locks, flags.tolist(), strict=True):
            lock.settle = flag
    group.settled = (locks, flags, assignment_mark(FootLock, ("settle",)))
    if votes is None:
        for lock in locks:
            lock.contacts = None
        return
    contacts = votes if faded is None else votes * (1.0 - faded)[:, None]
    if rows is not None:  # puppets without leg IK take no votes
        contacts = contacts[rows]
    cols.get(FootLock, "contacts", contacts.shape[1]).write(locks, contacts)


def install_blend(app: App) -> None:
    """Plugin: the :class:`BlendLibrary` resource (if absent) and :func:`animate` in the animation stage."""
    if app.world.try_resource(BlendLibrary) is None:
        app.world.insert_resource(BlendLibrary())
    app.add_system("animation", animate)
