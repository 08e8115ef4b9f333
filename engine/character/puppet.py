"""A character as a living puppet: its locomotion set, its ragdoll, its skin on the puppet's FK.

:func:`spawn_character` is :func:`engine.statemachine.puppet.spawn_puppet` with the character's
skeleton: the state machine, the blend and the leg IK (whose foot locks hold the character's
toe tips) run on it unchanged. Two things are the character's own:

- its **locomotion set** (:mod:`engine.character.locomotion`), registered in the
  :class:`~engine.blend.locomotion.BlendLibrary` under :attr:`Character.library_key`;
- its **behaviour thresholds** (:func:`character_tuning`): crouch and stand heights, lift, reach,
  scaled to its hips height as a snowman's are;
- its **ragdoll**: capsules as thick as its mesh (the rig's radii), its body mass the
  mannequin's 70 kg scaled by the cube of their standing heights (a figure of the same
  build), spread over the bones by capsule volume — a stocky character's trunk weighs more
  of it, and a smaller character is lighter and tumbles like one.

:class:`CharacterSkin` (display only, not hashed) lets the games draw the mesh instead of
the capsules: :func:`skinned_instances`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from engine.blend.locomotion import BlendLibrary
from engine.character.load import Character
from engine.character.locomotion import character_locomotion
from engine.clip import Clip
from engine.clips.contacts import foot_contacts
from engine.components import WorldPose
from engine.ecs import Entity, World
from engine.humanoid import humanoid_skeleton
from engine.ragdoll.components import Ragdoll
from engine.ragdoll.profile import RagdollProfile, default_profile
from engine.render.scene import SkinnedInstance
from engine.skeleton import Skeleton
from engine.skinning import SkinBinding
from engine.statemachine.puppet.body import PuppetTuning

__all__ = [
    "CharacterSkin",
    "spawn_character",
    "character_profile",
    "skinned_instances",
    "standing_height",
    "character_tuning",
    "MANNEQUIN_MASS",
]

MANNEQUIN_MASS = 70.0
"""kg: the mannequin's body mass (``default_profile``'s), the reference a character's is scaled from."""


@dataclass
class CharacterSkin:
    """Component: the skin a puppet is drawn with instead of its capsules (display only)."""

    SIM_STATE: ClassVar[bool] = False

    binding: SkinBinding


def standing_height(sk: Skeleton) -> float:
    """Floor to the top of the head (the head joint's height plus its tip) in the rest pose."""
    from engine.fk import forward_kinematics

    pos, _ = forward_kinematics(sk, sk.offsets[0], np.tile([1.0, 0.0, 0.0, 0.0], (sk.num_joints, 1)))
    return float(max(pos[:, 1].max(), (pos[:, 1] + sk.tips[:, 1]).max()))


def character_profile(sk: Skeleton) -> RagdollProfile:
    """The ragdoll of a character's skeleton, its mass the mannequin's times the cube of their heights' ratio."""
    ratio = standing_height(sk) / standing_height(humanoid_skeleton())
    return default_profile(sk, total_mass=MANNEQUIN_MASS * ratio**3)


def character_tuning(sk: Skeleton) -> PuppetTuning:
    """The puppet's behaviour thresholds scaled to the character's hips height (as a snowman's are).

    The thresholds are hips heights in metres: unscaled, a character whose hips stand at 0.68 m
    would be below the mannequin's crouch threshold (0.80 m) while standing, and crouch-walk at
    every drag."""
    s = float(sk.offsets[0, 1]) / humanoid_skeleton().offsets[0, 1]
    base = PuppetTuning()
    return replace(
        base,
        stand_height=float(sk.offsets[0, 1]),
        crouch_height=base.crouch_height * s,
        crouch_enter=base.crouch_enter * s,
        crouch_exit=base.crouch_exit * s,
        lift_limit=base.lift_limit * max(s, 0.5),
        max_speed=base.max_speed * s,
        flick_launch_speed=base.flick_launch_speed * float(np.sqrt(s)),
        reach=base.reach * s,
        front=base.front * s,
    )


def spawn_character(
    world: World,
    character: Character,
    clips: Mapping[str, Clip],
    position: ArrayLike = (0.0, 0.0, 0.0),
    heading: float = 0.0,
    *,
    name: str = "puppet",
    extra: tuple[object, ...] = (),
) -> Entity:
    """A puppet that is ``character``: its set built (or found) from ``clips``, its ragdoll, its skin.

    Args:
        clips: the puppet's clips by role the character plays, retargeted (built-in or a library's).
    """
    from engine.statemachine.puppet.plugin import spawn_puppet

    library = world.resource(BlendLibrary)
    key = character.library_key
    if key not in library:
        library.add(key, character_locomotion(character, clips))
        # A retargeted clip plants its feet when its source does (same phases): its source's contact
        # labels, not ones re-read from the character's soles against the mannequin's heel and
        # clearance (a long, high-ankled foot reads as down late and up early, unlocked in between).
        by_name = {c.name: c for c in clips.values()}
        library.contact_tracks[key] = [foot_contacts(by_name[c.name]) for c in library[key].space.clips]
    sk = character.rig.skeleton
    e = spawn_puppet(
        world,
        position,
        heading,
        skeleton=sk,
        library_key=key,
        tuning=character_tuning(sk),
        name=name,
        extra=(*extra, CharacterSkin(character.binding)),
    )
    world.get(e, Ragdoll).profile = character_profile(sk)  # before any physics step builds the body
    return e


def skinned_instances(
    world: World, alpha: float, outlined: set[Entity] | frozenset[Entity] = frozenset()
) -> list[SkinnedInstance]:
    """Every skinned puppet posed as its FK last left it (interpolated by ``alpha``)."""
    out = []
    for e, skin, wpose in world.query(CharacterSkin, WorldPose):
        pos, rot = wpose.interpolated(alpha)
        out.append(SkinnedInstance(skin.binding.meshes, skin.binding.matrices(pos, rot), outline=e in outlined))
    return out
