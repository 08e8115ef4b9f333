"""Ragdoll (the default state) and GetUp.

Ragdoll is where the puppet goes whenever no other state fits the input (thesis
§6.2.2): held in the air with no jump momentum, an invalid jump arc, yanked beyond
its stride. The body goes limp in the physics engine; if the stick still holds it,
its chest hangs from the stick tip on a spring and the rest dangles and swings.
Once released and settled, GetUp blends from the lying pose into the get-up clip
(face-up, face-down or side, aligned with the body's heading) without a pop, and
the puppet stands up where it fell.
"""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.blend.locomotion import BlendLibrary, LocomotionPlayer
from engine.components import LocalPose, Transform
from engine.ecs import Entity, World
from engine.ik.system import IKRequest
from engine.pose import Pose
from engine.ragdoll.components import Ragdoll, RagdollMode
from engine.ragdoll.getup import GetUpBlend, lying_orientation, pick_get_up_clip
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import GettingUp, PoseOverride, PuppetBody
from engine.statemachine.puppet.names import PuppetState
from engine.statemachine.puppet.senses import holder
from engine.statemachine.puppet.spec import PuppetStateDef, PuppetTransition, StateSpec

__all__ = [
    "enter_ragdoll",
    "update_ragdoll",
    "ragdoll_settled",
    "enter_getup",
    "update_getup",
    "exit_getup",
    "getup_done",
    "SPEC",
]

_HELD_JOINT = "chest"


def enter_ragdoll(world: World, entity: Entity, brain: Brain) -> None:
    """Go limp at once: the bodies already stand in the animated pose, so nothing pops."""
    world.get(entity, Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
    player = world.get(entity, LocomotionPlayer)
    player.speed, player.height = 0.0, None
    player.stop(0.1)
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.grounding, ik.sphere_centre, ik.sphere_radius = False, None, 0.0


def update_ragdoll(world: World, entity: Entity, brain: Brain) -> None:
    """Hang from the stick while held; keep the puppet's ground point under its pelvis."""
    rd = world.get(entity, Ragdoll)
    held = holder(world, entity)
    if held is not None:
        rd.grab(_HELD_JOINT, held[1].tip)
    elif rd.held is not None:
        rd.release()
    pose = world.try_get(entity, LocalPose)
    if pose is not None:
        tr = world.get(entity, Transform)
        tr.position = np.array([pose.root[0], 0.0, pose.root[2]])
    world.get(entity, PuppetBody).speed = 0.0


def ragdoll_settled(world: World, entity: Entity, brain: Brain) -> bool:
    """Released and at rest: time to get up."""
    rd = world.get(entity, Ragdoll)
    return holder(world, entity) is None and rd.settled and brain.time_in_state > 0.3


def enter_getup(world: World, entity: Entity, brain: Brain) -> None:
    """Pick the clip for how the body lies and start blending from the ragdoll pose into it."""
    rd = world.get(entity, Ragdoll)
    rd.release()
    lp = world.get(entity, LocalPose)
    up = world.get(entity, GettingUp)
    player = world.get(entity, LocomotionPlayer)
    start = Pose(np.array(lp.root), np.array(lp.rotations))
    lying = lying_orientation(start.rotations[0])
    clips = world.resource(BlendLibrary)[player.library_key].clips
    up.blend = GetUpBlend(start, pick_get_up_clip(clips, lying), world.dt)
    up.lying, up.frame = lying, 0.0
    rd.set_mode(RagdollMode.ANIMATED, immediate=True)
    world.get(entity, PoseOverride).weight = 1.0
    _write_getup_pose(world, entity, up, up.blend)


def _write_getup_pose(world: World, entity: Entity, up: GettingUp, blend: GetUpBlend) -> None:
    override = world.get(entity, PoseOverride)
    override.pose = blend.advance()
    up.frame = float(blend.frame)


def update_getup(world: World, entity: Entity, brain: Brain) -> None:
    """One frame of the get-up blend."""
    up = world.get(entity, GettingUp)
    player = world.get(entity, LocomotionPlayer)
    player.speed, player.height = 0.0, None
    if up.blend is not None and not up.blend.done:
        _write_getup_pose(world, entity, up, up.blend)


def getup_done(world: World, entity: Entity, brain: Brain) -> bool:
    """The get-up clip has played to its end."""
    blend = world.get(entity, GettingUp).blend
    return blend is not None and blend.done


def exit_getup(world: World, entity: Entity, brain: Brain) -> None:
    """Stand where the clip ended, facing where it faces; hand over to locomotion."""
    body = world.get(entity, PuppetBody)
    override = world.get(entity, PoseOverride)
    tr = world.get(entity, Transform)
    if override.pose is not None:
        root = override.pose.root
        fwd = quat.rotate(override.pose.rotations[0], np.array([0.0, 0.0, 1.0]))
        body.heading = float(np.arctan2(fwd[0], fwd[2]))
        tr.position = np.array([root[0], 0.0, root[2]])
        tr.rotation = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), body.heading)
    override.weight, override.pose = 0.0, None
    world.get(entity, GettingUp).blend = None
    world.get(entity, LocomotionPlayer).point = None


_RAGDOLL: PuppetStateDef = PuppetStateDef(
    PuppetState.RAGDOLL,
    enter=enter_ragdoll,
    update=update_ragdoll,
    description="default state: limp physics, hangs from the stick when held",
)
_GET_UP: PuppetStateDef = PuppetStateDef(
    PuppetState.GET_UP,
    enter=enter_getup,
    update=update_getup,
    exit=exit_getup,
    description="blend from the lying pose into the get-up clip",
)

SPEC = StateSpec(
    states=(_RAGDOLL, _GET_UP),
    transitions=(
        PuppetTransition(
            PuppetState.RAGDOLL, PuppetState.GET_UP, guard=ragdoll_settled, crossfade=0.0, label="settled"
        ),
        PuppetTransition(PuppetState.GET_UP, PuppetState.LOCOMOTION, guard=getup_done, crossfade=0.2, label="standing"),
    ),
)
"""Ragdoll and GetUp (the ways into the ragdoll are the other states' and the machine's default)."""
