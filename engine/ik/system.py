"""The IK stage: per-puppet requests, the system that serves them, and the plugin.

A state writes an :class:`IKRequest` on its puppet (feet on the ground, hands on a
snowball, any effector targets with pins); :func:`ik_system` runs in the ``ik``
stage, after blending and before physics, and edits the puppet's
:class:`~engine.components.LocalPose` in place. Order within a puppet: the
optimisation IK's arbitrary targets first, then foot grounding (it moves the
pelvis), then the hands (they follow the shoulders wherever the pelvis went).
The largest group of puppets of one joint hierarchy that only need their feet planted is served
by the crowd pass (:mod:`engine.ik.crowd`) with no Python per puppet, from a single puppet up (bone
lengths may differ: the snowman game's puppet and its snowmen, each rigged to its balls, are one crowd): its
compiled kernel is the per-puppet float path operation for operation, so even one puppet
(the snowman game's) gains without changing a bit. What the pass cannot serve goes to the
general path: groups of :data:`BATCH` or more alike puppets are grounded together as arrays
(:func:`~engine.ik.grounding.ground_feet_batch`), smaller ones one puppet at a time.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numpy.typing import NDArray

from engine.columns import columns
from engine.components import LocalPose, Puppet
from engine.ecs import World
from engine.humanoid import JOINTS
from engine.ik.crowd import CrowdPlan, current_plan, ground_crowd
from engine.ik.foot_lock import FootLock
from engine.ik.grounding import GroundQuery, PlaneGround, ground_feet, ground_feet_batch
from engine.ik.hands import hands_on_sphere
from engine.ik.rig import IKRig, humanoid_rig
from engine.ik.solver import Effector, IKSettings, Pin, solve_ik
from engine.pose import Pose
from engine.skeleton import Skeleton

if TYPE_CHECKING:
    from engine.app import App

__all__ = ["IKRequest", "IKGround", "IKRigCache", "ik_system", "install_ik", "BATCH"]

BATCH = 20  # alike puppets from which batched grounding is faster (its numpy calls cost ~3 ms whatever P)


@dataclass
class IKRequest:
    """What a puppet's state asks of IK this step (all off by default).

    ``effectors``/``pins`` feed the optimisation IK; ``sphere_centre`` with a positive
    ``sphere_radius`` puts both hands on that sphere; ``grounding`` plants the feet.
    ``reached`` and ``pelvis_shift`` are written back by :func:`ik_system`. ``foot_lock``
    keeps planted toes where they landed while grounding (the animation stage writes its
    contact votes); it lets go when grounding stops (a jump, a fall).
    """

    grounding: bool = False
    grounding_weight: float = 1.0
    sphere_centre: NDArray[np.float64] | None = None
    sphere_radius: float = 0.0
    effectors: tuple[Effector, ...] = ()
    pins: tuple[Pin, ...] = ()
    keep_closest: bool = True
    reached: bool = True
    pelvis_shift: float = 0.0
    foot_lock: FootLock = field(default_factory=FootLock)


@dataclass
class IKGround:
    """The ground the feet stand on: ``query(x, z) -> (height, normal)`` (static scene data)."""

    SIM_STATE: ClassVar[bool] = False
    query: GroundQuery = field(default_factory=PlaneGround)


@dataclass
class IKRigCache:
    """IK rigs built per skeleton (the humanoid gets its limits and hinges), reused every step."""

    SIM_STATE: ClassVar[bool] = False
    settings: IKSettings = field(default_factory=IKSettings)
    rigs: dict[int, IKRig] = field(default_factory=dict)
    canonical: dict[int, Skeleton] = field(default_factory=dict)
    kindred: dict[int, Skeleton] = field(default_factory=dict)
    batch_from: int = BATCH  # alike puppets from which grounding is batched (benches raise it to compare)
    crowd_from: int = 1  # alike plain puppets from which the crowd pass serves them (benches raise it to compare)
    crowd: CrowdPlan | None = None  # who the crowd pass serves (engine.ik.crowd), remade when that changes

    def rig(self, skeleton: Skeleton) -> IKRig:
        """The rig of ``skeleton``: the humanoid preset for the default puppet, ball joints otherwise."""
        key = id(skeleton)
        cached = self.rigs.get(key)
        if cached is None or cached.skeleton is not skeleton:
            cached = humanoid_rig(skeleton) if skeleton.names == JOINTS else IKRig.build(skeleton)
            self.rigs[key] = cached
        return cached

    def same_as(self, skeleton: Skeleton) -> Skeleton:
        """The first skeleton seen equal to ``skeleton`` (puppets spawned alike share one batch)."""
        found = self.canonical.get(id(skeleton))
        if found is None:
            found = next((s for s in self.canonical.values() if _same(s, skeleton)), skeleton)
            self.canonical[id(skeleton)] = found
        return found

    def kin(self, skeleton: Skeleton) -> Skeleton:
        """The first skeleton seen with ``skeleton``'s joints and parents (bone lengths and tips may differ):
        the crowd pass takes offsets and tips per puppet, so these share it."""
        found = self.kindred.get(id(skeleton))
        if found is None:
            found = next((s for s in self.kindred.values() if _kin(s, skeleton)), skeleton)
            self.kindred[id(skeleton)] = found
        return found


def _kin(a: Skeleton, b: Skeleton) -> bool:
    return a.names == b.names and np.array_equal(a.parents, b.parents)


def _same(a: Skeleton, b: Skeleton) -> bool:
    return _kin(a, b) and np.array_equal(a.offsets, b.offsets) and np.array_equal(a.tips, b.tips)


def _ground_batches(world: World, rows: list[tuple[Puppet, LocalPose, IKRequest]], cache: IKRigCache) -> set[int]:
    """Plant the feet of every group of :data:`BATCH` or more alike puppets that only ask for
    grounding (and hands), as arrays; returns the ids of the requests served."""
    groups: dict[int, list[tuple[Puppet, LocalPose, IKRequest]]] = {}
    for row in rows:
        puppet, _, req = row
        if req.grounding and not req.effectors:
            groups.setdefault(id(cache.same_as(puppet.skeleton)), []).append(row)
    ground = world.try_resource(IKGround)
    query = ground.query if ground is not None else PlaneGround()
    done: set[int] = set()
    cols = columns(world)
    for group in groups.values():
        if len(group) < cache.batch_from:
            continue
        sk = cache.same_as(group[0][0].skeleton)
        poses = [local for _, local, _ in group]
        requests = [req for _, _, req in group]
        # The local poses are read and written through their columns (engine.columns): no gather, no
        # scatter. The solve works on copies, so a row that comes out non-finite keeps its animated pose.
        root_column = cols.get(LocalPose, "root", sk.num_joints)
        rotation_column = cols.get(LocalPose, "rotations", sk.num_joints)
        given_roots, given_rots = root_column.read(poses), rotation_column.read(poses)
        roots, rots = given_roots.copy(), given_rots.copy()
        offsets = cols.stacked(("ik-offsets", id(sk)))([p.joint_offsets() for p, _, _ in group])
        weights = np.array([req.grounding_weight for req in requests])
        shift = ground_feet_batch(
            sk,
            roots,
            rots,
            query,
            offsets=offsets,
            weight=weights,
            locks=[req.foot_lock for req in requests],
            dt=world.dt,
            lock_columns=cols,
        )
        done.update(map(id, requests))
        for req, value in zip(requests, shift.tolist(), strict=True):
            req.pelvis_shift = value
        finite = np.asarray(np.isfinite(roots).all(axis=1) & np.isfinite(rots).all(axis=(1, 2)))
        for i, (puppet, _, req) in enumerate(group):
            if req.sphere_centre is not None and req.sphere_radius > 0.0:
                pose = Pose(roots[i], rots[i])
                hands_on_sphere(puppet.skeleton, pose, req.sphere_centre, req.sphere_radius, offsets=puppet.offsets)
                finite[i] = pose.is_finite()
        if not finite.all():  # a bad target must not poison the puppet: keep the animated pose
            roots[~finite], rots[~finite] = given_roots[~finite], given_rots[~finite]
        root_column.write(poses, roots)
        rotation_column.write(poses, rots)
    return done


def ik_system(world: World) -> None:
    """Serve every puppet's :class:`IKRequest` on its :class:`LocalPose` (the ``ik`` stage)."""
    ground = world.try_resource(IKGround)
    cache = world.try_resource(IKRigCache)
    if cache is None:
        cache = IKRigCache()
        world.insert_resource(cache)
    table = world.query(Puppet, LocalPose, IKRequest)
    cache.crowd = plan = current_plan(cache.crowd, table, cache.kin, cache.same_as, cache.crowd_from)
    query = ground.query if ground is not None else PlaneGround()
    kept = ground_crowd(plan, columns(world), query, world.dt)
    if kept is not None:
        if kept.any():  # as the one-puppet path does, for a member that would not be batched
            for i in np.flatnonzero(kept & (plan.alike < cache.batch_from)).tolist():
                plan.requests[i].reached = False
        if len(plan.rows) == len(table):
            return
        crowd = set(plan.rows)
        rows = [(row[1], row[2], row[3]) for i, row in enumerate(table) if i not in crowd]
    else:
        rows = [(puppet, local, req) for _, puppet, local, req in table]
    done = _ground_batches(world, rows, cache)
    for puppet, local, req in rows:
        if id(req) in done:
            continue
        sk = puppet.skeleton
        offsets = puppet.offsets
        pose = Pose(np.array(local.root, dtype=np.float64), np.array(local.rotations, dtype=np.float64))
        if req.effectors:
            res = solve_ik(cache.rig(sk), pose.root, pose.rotations, req.effectors, req.pins,
                           offsets=offsets, settings=cache.settings)  # fmt: skip
            req.reached = res.reached
            if res.reached or req.keep_closest:
                pose.root[:] = res.root if res.reached else res.closest_root
                pose.rotations[:] = res.rotations if res.reached else res.closest_rotations
        if req.grounding:
            query = ground.query if ground is not None else PlaneGround()
            req.pelvis_shift = float(
                ground_feet(
                    sk, pose, query, offsets=offsets, weight=req.grounding_weight, lock=req.foot_lock, dt=world.dt
                )
            )
        else:
            req.foot_lock.weights = np.zeros_like(req.foot_lock.weights)
            req.foot_lock.planted = np.zeros_like(req.foot_lock.planted)
            req.foot_lock.stepping = np.zeros_like(req.foot_lock.stepping)
        if req.sphere_centre is not None and req.sphere_radius > 0.0:
            hands_on_sphere(sk, pose, req.sphere_centre, req.sphere_radius, offsets=offsets)
        if pose.is_finite():
            local.root = pose.root
            local.rotations = pose.rotations
        else:  # a bad target must not poison the puppet: keep the animated pose
            req.reached = False


def install_ik(app: App) -> None:
    """Plugin: the rig cache, a flat default ground, and :func:`ik_system` in the ``ik`` stage."""
    if app.world.try_resource(IKRigCache) is None:
        app.world.insert_resource(IKRigCache())
    if app.world.try_resource(IKGround) is None:
        app.world.insert_resource(IKGround())
    app.add_system("ik", ik_system)
