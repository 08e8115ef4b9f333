"""Physics ragdolls and props on MuJoCo, and animation ⇄ ragdoll blending.

- :mod:`~engine.ragdoll.profile` — the asset: capsules, masses, limits, muscle gains from any skeleton.
- :mod:`~engine.ragdoll.mjcf` — the MuJoCo model (Y up, body frames = joint frames).
- :mod:`~engine.ragdoll.physics` — :class:`PhysicsWorld`, the resource holding every body.
- :mod:`~engine.ragdoll.components` — :class:`Ragdoll` (modes and weights) and :class:`Prop`.
- :mod:`~engine.ragdoll.blend` — :func:`blend_poses`, :func:`max_rotation_jump`.
- :mod:`~engine.ragdoll.getup` — settle detection, lying orientation, :class:`GetUpBlend`.
- :mod:`~engine.ragdoll.system` — :func:`physics_step` and the :func:`install_physics` plugin.
"""

from engine.ragdoll.blend import blend_poses, max_rotation_jump
from engine.ragdoll.components import SNOW_DENSITY, Prop, Ragdoll, RagdollMode
from engine.ragdoll.getup import (
    GetUpBlend,
    LyingOrientation,
    lying_heading,
    lying_orientation,
    pick_get_up_clip,
    settled,
    update_settle,
)
from engine.ragdoll.mjcf import build_mjcf
from engine.ragdoll.physics import PhysicsWorld
from engine.ragdoll.profile import RagdollProfile, default_profile
from engine.ragdoll.system import install_physics, physics_step, spawn_snowball

install = install_physics

__all__ = [
    "RagdollProfile",
    "default_profile",
    "build_mjcf",
    "PhysicsWorld",
    "Ragdoll",
    "RagdollMode",
    "Prop",
    "SNOW_DENSITY",
    "blend_poses",
    "max_rotation_jump",
    "GetUpBlend",
    "LyingOrientation",
    "lying_orientation",
    "lying_heading",
    "settled",
    "update_settle",
    "pick_get_up_clip",
    "physics_step",
    "install_physics",
    "install",
    "spawn_snowball",
]
