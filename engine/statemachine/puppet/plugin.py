"""The puppet plugin: everything a living puppet needs, and how to spawn one.

``install_puppets(app)`` installs, in schedule order: the brain (``statemachine``
stage), locomotion blending and the pose overrides (``animation``), IK (``ik``),
the MuJoCo physics (``physics``) and batched FK (``fk``). ``spawn_puppet`` creates a
puppet entity with every component those systems read.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine.app import App
from engine.batches import Batch, batch
from engine.blend.locomotion import BlendLibrary, LocomotionPlayer
from engine.blend.puppet import install_puppet_locomotion
from engine.columns import Mark, assignment_mark, unassigned_since
from engine.components import Grabbable, LocalPose, Name, Puppet, Transform
from engine.ecs import Entity, World
from engine.humanoid import humanoid_skeleton
from engine.ik.system import IKRequest, install_ik
from engine.posing import install_fk
from engine.ragdoll.components import Ragdoll, RagdollMode
from engine.ragdoll.profile import RagdollProfile, default_profile
from engine.ragdoll.system import install_physics
from engine.rows import row_store
from engine.skeleton import Skeleton
from engine.statemachine.machine import Brain, StateMachine, step_machines
from engine.statemachine.puppet.body import PUPPET_COMPONENTS, Handling, PoseOverride, PuppetBody, PuppetTuning
from engine.statemachine.puppet.machine import puppet_machine
from engine.statemachine.puppet.props import held_props_system
from engine.statemachine.puppet.senses import sense_all, yaw_rotation
from engine.statemachine.puppet.spec import PuppetColumns

__all__ = ["PuppetMachine", "apply_pose_overrides", "brain_system", "install_puppets", "puppet_batch", "spawn_puppet"]


class PuppetMachine:
    """Resource: the one state-machine asset all puppets share (insert one built with
    ``puppet_machine(extra=...)`` before installing the puppets to add a state)."""

    SIM_STATE = False

    def __init__(self, machine: StateMachine[PuppetColumns] | None = None) -> None:
        self.machine = machine or puppet_machine()
        self.overriding: tuple[tuple[PoseOverride, ...], Mark | None, list[int]] | None = None
        """The pose overrides' batch, where their fields' assignment logs stood, and which rows of it had an
        override to apply then (see :func:`apply_pose_overrides`)."""


def brain_system(world: World) -> None:
    """The ``statemachine`` stage: sense the sticks, then step every puppet's machine.

    Sensing is one pass over all puppets; the machines are stepped by
    :func:`~engine.statemachine.machine.step_machines`: the puppets walking free in
    Locomotion over arrays, the others (held, jumping, fallen…) one by one in entity order.
    The puppets' component lists are kept between structural changes (:mod:`engine.batches`)."""
    kept = puppet_batch(world)
    bodies, brains, transforms, players, handling, ik = kept.lists
    columns = sense_all(world, kept.entities, bodies, None if kept.missing[2] else transforms)
    columns.players, columns.handling, columns.ik = players, handling, ik
    if players and not kept.missing[3]:
        columns.player_rows = row_store(world).rows(LocomotionPlayer, players)
    if handling and not kept.missing[4]:
        columns.handling_block = row_store(world).block(Handling, handling)
    step_machines(world, kept.entities, brains, columns)


def puppet_batch(world: World) -> Batch:
    """The kept batch the brain stage steps (:mod:`engine.batches`): the puppets' bodies and brains, with their
    transforms, locomotion players, handling and IK requests beside them (row ``i`` of each for one puppet).
    Its bodies are the row block of :class:`PuppetBody` once the brain stage ran (:mod:`engine.rows`)."""
    return batch(world, "puppet brains", (PuppetBody, Brain), (Transform, LocomotionPlayer, Handling, IKRequest))


def apply_pose_overrides(world: World) -> None:
    """After blending: a state's pose override (get-up) replaces the animated pose.

    Which puppets have one is decided by their ``weight`` and ``pose`` fields, which only a getting-up puppet's
    states assign: the rows that had one are kept (in the :class:`PuppetMachine` resource) with where those fields'
    assignment logs stood (:func:`engine.columns.assignment_mark`), so a crowd in which nobody gets up costs no pass
    over its overrides; the kept rows' poses are copied every step, since the blend wrote over them."""
    kept = batch(world, "pose overrides", (PoseOverride, LocalPose))
    overrides, poses = kept.lists
    machine = world.try_resource(PuppetMachine)
    memo = None if machine is None else machine.overriding
    if memo is not None and memo[0] is overrides and unassigned_since(memo[1]):
        rows = memo[2]
    else:
        mark = assignment_mark(PoseOverride, _OVERRIDE_FIELDS)
        rows = [i for i, o in enumerate(overrides) if o.weight > 0.0 and o.pose is not None]
        if machine is not None:
            machine.overriding = (overrides, mark, rows)
    for i in rows:
        held, pose = overrides[i].pose, poses[i]
        assert held is not None  # a row is kept only while its pose is set (assigning it moves the mark)
        pose.root = np.array(held.root)
        pose.rotations = np.array(held.rotations)


_OVERRIDE_FIELDS = ("weight", "pose")


def install_puppets(app: App) -> None:
    """Plugin: brain, blending, pose overrides, IK, physics and FK, in schedule order."""
    world = app.world
    if world.try_resource(PuppetMachine) is None:
        world.insert_resource(PuppetMachine())
    app.add_system("statemachine", held_props_system)
    app.add_system("statemachine", brain_system)
    app.add_plugin(install_puppet_locomotion)
    app.add_system("animation", apply_pose_overrides)
    app.add_plugin(install_ik)
    app.add_plugin(install_physics)
    app.add_plugin(install_fk)


_PROFILES: dict[tuple[object, ...], RagdollProfile] = {}


def _profile(sk: Skeleton) -> RagdollProfile:
    """The default ragdoll profile of a skeleton, made once per skeleton shape: a profile is
    immutable, and a crowd of a thousand would otherwise build a thousand equal ones (~2 ms each)."""
    key = (sk.names, *(np.asarray(a, dtype=np.float64).tobytes() for a in (sk.parents, sk.offsets, sk.radii, sk.tips)))
    if key not in _PROFILES:
        _PROFILES[key] = default_profile(sk)
    return _PROFILES[key]


def spawn_puppet(
    world: World,
    position: ArrayLike = (0.0, 0.0, 0.0),
    heading: float = 0.0,
    *,
    skeleton: Skeleton | None = None,
    library_key: str = "humanoid",
    scale: float = 1.0,
    tuning: PuppetTuning | None = None,
    name: str = "puppet",
    extra: tuple[object, ...] = (),
) -> Entity:
    """Create a puppet standing at ``position`` facing ``heading`` (radians about +Y, 0 = +Z),
    playing the locomotion set ``library_key`` at ``scale`` (see :class:`LocomotionPlayer`)."""
    sk = skeleton or humanoid_skeleton()
    tuning = tuning or PuppetTuning(stand_height=float(sk.offsets[0][1]))
    library = world.try_resource(BlendLibrary)
    if library is not None and library_key not in library:
        raise KeyError(f"no locomotion set {library_key!r}: install it before spawning")
    pos = np.asarray(position, dtype=np.float64).reshape(3).copy()
    machine = world.resource(PuppetMachine).machine
    rest_root = pos + sk.offsets[0]
    rotations = np.zeros((sk.num_joints, 4))
    rotations[:, 0] = 1.0
    rotations[0] = yaw_rotation(heading)
    return world.spawn(
        Name(name),
        Transform(pos, yaw_rotation(heading)),
        Puppet(sk),
        LocalPose(rest_root, rotations),
        LocomotionPlayer(library_key=library_key, scale=scale),
        IKRequest(grounding=True),
        Ragdoll(_profile(sk), mode=RagdollMode.ANIMATED),
        PoseOverride(),
        PuppetBody(tuning=tuning, heading=float(heading), target=pos.copy(), target_height=tuning.stand_height),
        *(component() for component in PUPPET_COMPONENTS),
        Grabbable(radius=0.45 * tuning.stand_height, kind="puppet", offset=np.array([0.0, tuning.stand_height, 0.0])),
        machine.new_brain(),
        *extra,
    )
