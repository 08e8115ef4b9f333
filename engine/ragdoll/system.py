"""The ``physics`` stage: sync entities into MuJoCo, drive ragdolls, step, write poses back.

Per step, for every puppet with a :class:`Ragdoll`, the ``LocalPose`` written by
animation and IK is the *target*:

- ``ANIMATED``: the pose passes through; the bodies are placed on it (with its velocity) only
  while something simulated is near (:mod:`engine.ragdoll._islands`), and the whole crowd
  of animated puppets is driven in one batched call;
- otherwise the muscles and the root pin track it with the current weights, and the
  pose written back is ``blend_poses(target, simulated, blend_weight)``.

Props (:class:`Prop` + ``Transform``) are added, resized and removed to match their
components; physics writes their ``Transform`` back unless the prop is ``carried``.
Ragdolls and props that appear in the same step are added in one rebuild.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import repeat
from operator import attrgetter, ne
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.app import App
from engine.arrays import I64
from engine.columns import columns
from engine.components import LocalPose, Puppet, Transform
from engine.ecs import Entity, World
from engine.ragdoll.blend import blend_rows
from engine.ragdoll.components import Prop, Ragdoll, RagdollMode
from engine.ragdoll.getup import update_settle
from engine.ragdoll.physics import PhysicsWorld

__all__ = ["physics_step", "install_physics", "spawn_snowball"]


def _sync(world: World, pw: PhysicsWorld) -> None:
    rows = world.query(Ragdoll, Puppet, LocalPose)
    # the world hands out the same query list until a Ragdoll, Puppet or LocalPose comes or goes:
    # then, with no ragdoll added or removed here since, the crowd is the one last synced
    if pw.synced is None or pw.synced[0] is not rows or pw.synced[1] != pw.ragdoll_changes:
        present = {e for e, *_ in rows}
        known = set(pw.ragdoll_keys)
        for key in sorted(known - present):
            pw.remove(key)
        for e, rd, puppet, pose in rows:
            if e not in known:
                pw.add_ragdoll(e, puppet.skeleton, rd.profile, pose.root, pose.rotations, puppet.joint_offsets())
        pw.synced = (rows, pw.ragdoll_changes)
    props = world.query(Prop, Transform)
    present = {e for e, *_ in props}
    for key in pw.prop_keys:
        if key not in present:
            pw.remove(key)
    for e, prop, tr in props:
        if not pw.has_prop(e):
            pw.add_prop(e, prop.radius, prop.current_mass(), tr.position, tr.rotation, prop.velocity, prop.friction)
    pw.ensure_built()
    for e, prop, _ in props:
        if prop.radius != pw.prop_radius(e):
            pw.set_prop_radius(e, prop.radius, prop.current_mass())


def physics_step(world: World) -> None:
    """The physics-stage system (needs the :class:`PhysicsWorld` resource)."""
    pw = world.resource(PhysicsWorld)
    if abs(pw.dt - world.dt) > 1e-9:
        raise ValueError(
            f"physics steps {pw.dt:.6f} s but the world steps {world.dt:.6f} s: "
            "set PhysicsWorld(timestep=world.dt / substeps)"
        )
    _sync(world, pw)
    holding = set(pw.holding())  # a crowd holds nothing: one call per held puppet, not per puppet
    animated: list[tuple[Entity, Ragdoll, Puppet, LocalPose]] = []
    simulated: list[tuple[Entity, Ragdoll, LocalPose]] = []
    held: list[tuple[Entity, Ragdoll]] = []
    dt, anim = world.dt, RagdollMode.ANIMATED
    table = world.query(Ragdoll, Puppet, LocalPose)
    crowd = None if holding else _walking(world, table)
    if crowd is not None:  # every ragdoll animated, at its weights, held by nobody: no Python per puppet
        for name, value in _AT_REST:
            deque(map(setattr, crowd.ragdolls, repeat(name), repeat(value)), maxlen=0)
        keys, poses = crowd.keys, crowd.poses
    else:
        for row in table:  # the one pass over the crowd
            e, rd, _, pose = row
            if rd.mode is anim:
                animated.append(row)
                if (
                    rd.muscle_weight != rd.muscle_target
                    or rd.pin_weight != rd.pin_target
                    or rd.blend_weight != rd.blend_target
                ):
                    rd.ramp(dt)  # (at its targets a ragdoll's ramp changes nothing)
                # not simulated: the body is its animation (no energy of its own, nothing to settle)
                rd.kinetic_energy, rd.settled, rd.still_frames = 0.0, False, 0
            else:
                simulated.append((e, rd, pose))
            if rd.held is not None or e in holding:
                held.append((e, rd))
        keys = np.array([row[0] for row in animated], dtype=np.int64)
        poses = tuple(row[3] for row in animated)
    refused = pw.drive_animated(keys, *_animated_targets(world, pw, keys, poses))
    targets = _drive_simulated(world, pw, simulated, refused) if simulated else None  # (a walking crowd: none)
    for e in refused:  # a NaN pose from upstream: count it, keep the last good target
        pw.recoveries += 1
        pose = world.get(e, LocalPose)
        pose.root, pose.rotations = pw.target(e).root, pw.target(e).rotations
    for e, rd in held:
        pw.hold(e, rd.held, rd.hold_target if rd.held is not None else None)
    for e, prop, tr in world.query(Prop, Transform):
        if prop.carried or prop.placed:
            pw.set_prop_kinematic(e, tr.position, tr.rotation, prop.velocity)
            prop.placed = False
    pw.step()
    if targets is not None:
        _write_simulated(pw, simulated, *targets)
    for e, prop, tr in world.query(Prop, Transform):
        if not prop.carried:
            pos, rot, vel = pw.prop_state(e)
            tr.position, tr.rotation, prop.velocity = pos, rot, vel


def _drive_simulated(
    world: World, pw: PhysicsWorld, simulated: list[tuple[Entity, Ragdoll, LocalPose]], refused: list[Entity]
) -> tuple[NDArray[np.float64], NDArray[np.float64], I64]:
    """Ramp the simulated ragdolls' weights and drive them to their local poses in one batched call
    (a pose with NaN or infinite values is refused: that ragdoll keeps its last target, and its key is
    added to ``refused``); their targets, as driven: roots ``[n,3]``, rotations end to end ``[ΣJ,4]``
    and joints per ragdoll ``[n]``."""
    roots, rots = [], []
    for e, rd, pose in simulated:
        rd.ramp(world.dt)
        root, rot = np.array(pose.root, dtype=np.float64), np.array(pose.rotations, dtype=np.float64)
        if not (np.isfinite(root).all() and np.isfinite(rot).all()):
            refused.append(e)
            target = pw.target(e)
            root, rot = target.root, target.rotations
        roots.append(root)
        rots.append(rot)
    sizes = np.array([len(r) for r in rots], dtype=np.int64)
    root_t = np.array(roots).reshape(-1, 3)
    rot_t = quat.normalize(np.concatenate(rots)) if rots else np.zeros((0, 4))
    muscle = np.array([rd.muscle_weight for _, rd, _ in simulated], dtype=np.float64)
    pin = np.array([rd.pin_weight for _, rd, _ in simulated], dtype=np.float64)
    pw.drive_simulated([e for e, _, _ in simulated], root_t, rot_t, muscle, pin, muscle * pin)
    return root_t, rot_t, sizes


def _write_simulated(
    pw: PhysicsWorld,
    simulated: list[tuple[Entity, Ragdoll, LocalPose]],
    root: NDArray[np.float64],
    rot: NDArray[np.float64],
    sizes: I64,
) -> None:
    """After the step: each simulated ragdoll's settle state, and its local pose blended from its
    target (``root``, ``rot``, ``sizes`` from :func:`_drive_simulated`) to the simulated one."""
    sim_root, sim_rot, vel, ke = pw.simulated_state([e for e, _, _ in simulated])
    for k, (_, rd, _) in enumerate(simulated):
        update_settle(rd, float(ke[k]), float(np.linalg.norm(vel[k, :3])), float(rd.profile.masses.sum()))
    weights = np.array([rd.blend_weight for _, rd, _ in simulated], dtype=np.float64)
    out_root, out_rot = blend_rows(root, rot, sim_root, sim_rot, weights, sizes)
    ends = np.cumsum(sizes).tolist()
    for k, (_, _, pose) in enumerate(simulated):
        pose.root, pose.rotations = out_root[k].copy(), out_rot[ends[k] - int(sizes[k]) : ends[k]].copy()


#: An animated ragdoll's settle state: not simulated, the body is its animation (no energy, nothing to settle).
_AT_REST = (("kinetic_energy", 0.0), ("settled", False), ("still_frames", 0))
_MODE_HELD = attrgetter("mode", "held")
_WEIGHTS = (
    (attrgetter("muscle_weight"), attrgetter("muscle_target")),
    (attrgetter("pin_weight"), attrgetter("pin_target")),
    (attrgetter("blend_weight"), attrgetter("blend_target")),
)


@dataclass
class WalkingCrowd:
    """The physics stage's view of its query list (remade when the ECS hands out another list): the
    ragdolls, keys and local poses in row order, so a crowd that only walks is checked and driven
    in C-level passes. Not simulation state (the rows of a query, cached)."""

    SIM_STATE: ClassVar[bool] = False
    table: list[tuple[Entity, Ragdoll, Puppet, LocalPose]]
    ragdolls: tuple[Ragdoll, ...]
    keys: I64
    poses: tuple[LocalPose, ...]


def _walking(world: World, table: list[tuple[Entity, Ragdoll, Puppet, LocalPose]]) -> WalkingCrowd | None:
    """The crowd of ``table`` if every ragdoll is animated, at its weights' targets and not held
    (what the stage's loop would find row by row, found in C-level passes); ``None`` otherwise."""
    crowd = world.try_resource(WalkingCrowd)
    if crowd is None or crowd.table is not table:
        crowd = WalkingCrowd(
            table,
            tuple(r[1] for r in table),
            np.array([r[0] for r in table], dtype=np.int64),
            tuple(r[3] for r in table),
        )
        world.insert_resource(crowd)
    rds = crowd.ragdolls
    if list(map(_MODE_HELD, rds)).count((RagdollMode.ANIMATED, None)) != len(rds):
        return None
    if any(any(map(ne, map(now, rds), map(target, rds))) for now, target in _WEIGHTS):
        return None  # some ramp: the loop does it
    return crowd


def _animated_targets(
    world: World, pw: PhysicsWorld, keys: I64, poses: Sequence[LocalPose]
) -> tuple[NDArray[np.float64] | list[NDArray[np.float64]], NDArray[np.float64] | list[NDArray[np.float64]]]:
    """The animated ragdolls' targets: their local poses' roots ``[P, 3]`` and rotations ``[P, J, 4]``
    read from the pose columns (:mod:`engine.columns`) when all have ``J`` joints, else as lists."""
    cmds = pw.commands
    joints = cmds.joints if cmds.whole(keys) else cmds.joints[cmds.rows(keys)]
    if not len(joints) or (joints != joints[0]).any():
        return [p.root for p in poses], [p.rotations for p in poses]
    cols, count = columns(world), int(joints[0])
    return cols.get(LocalPose, "root", count).read(poses), cols.get(LocalPose, "rotations", count).read(poses)


def install_physics(app: App, timestep: float | None = None, substeps: int = 8) -> None:
    """Plugin: the :class:`PhysicsWorld` resource and :func:`physics_step` in the physics stage.

    Other than the defaults, install it as ``app.add_plugin(configured(install_physics, substeps=4))``
    (:func:`engine.app.configured`) before anything that depends on it.
    """
    if app.world.try_resource(PhysicsWorld) is None:
        step = app.world.dt / substeps if timestep is None else timestep
        app.world.insert_resource(PhysicsWorld(timestep=step, substeps=substeps))
    app.add_system("physics", physics_step)


def spawn_snowball(
    world: World,
    position: ArrayLike,
    radius: float = 0.15,
    mass: float | None = None,
    velocity: ArrayLike | None = None,
) -> Entity:
    """Spawn a snowball prop now (position of its centre; velocity linear ``[3]`` or full ``[6]``)."""
    vel = np.zeros(6)
    if velocity is not None:
        v = np.asarray(velocity, dtype=np.float64).ravel()
        vel[: len(v)] = v
    return world.spawn(Transform(np.asarray(position, dtype=np.float64).copy()), Prop(radius, mass, velocity=vel))
