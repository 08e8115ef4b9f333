"""The package's public surface is what ``__all__`` says, and every name resolves."""

from __future__ import annotations

import engine.ragdoll as ragdoll


def test_public_surface() -> None:
    expected = {
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
    }
    assert set(ragdoll.__all__) == expected
    for name in ragdoll.__all__:
        assert getattr(ragdoll, name) is not None
    assert ragdoll.install is ragdoll.install_physics
    assert not any(n.startswith("_") for n in ragdoll.__all__)
