"""The physics stage's walking-crowd path (:func:`engine.ragdoll.system._walking`): when every ragdoll
is animated, at its weights and held by nobody, the stage checks and drives the crowd in C-level
passes instead of its loop over rows. Stepped with that path and with it switched off (every step
on the loop), through a grab, a release, puppets going limp and one ramping back to animated, every
state hash must be the same, and the path must serve exactly the steps where the crowd only walks.
Broken once by leaving out the ``held`` check in ``_walking``: the grabbed steps were served and the
hashes differed from the loop's."""

from __future__ import annotations

import numpy as np
import pytest

import engine.ragdoll.system as system
from engine import quat
from engine.app import App
from engine.components import LocalPose, Puppet
from engine.hashing import state_hash
from engine.ragdoll import Ragdoll, RagdollMode, default_profile, install_physics
from engine.skeleton import Skeleton

N = 6
STEPS = 48


def _run(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch, walking: bool) -> tuple[list[str], list[int]]:
    served: list[int] = []
    original = system._walking

    def counted(*args: object) -> object:
        crowd = original(*args) if walking else None  # type: ignore[arg-type]  # the stage's own arguments
        if crowd is not None:
            served.append(step)
        return crowd

    monkeypatch.setattr(system, "_walking", counted)
    app = App(seed=3, plugins=[install_physics])
    world = app.world
    rng = np.random.default_rng(5)
    ents = [
        world.spawn(
            Puppet(skeleton),
            LocalPose(np.array([1.5 * i, 1.0, 0.0]), quat.identity(skeleton.num_joints)),
            Ragdoll(default_profile(skeleton)),
        )
        for i in range(N)
    ]
    hashes = []
    for step in range(STEPS):
        for i, e in enumerate(ents):  # the animation stage's new targets
            pose = world.get(e, LocalPose)
            pose.root = np.array([1.5 * i + 0.01 * step, 1.0, 0.0])
            pose.rotations = quat.normalize(
                quat.identity(skeleton.num_joints) + rng.normal(0, 0.02, (skeleton.num_joints, 4))
            )
        if step == 5:
            world.get(ents[1], Ragdoll).grab("chest", np.array([1.5, 1.6, 0.0]))
        elif step == 12:
            world.get(ents[1], Ragdoll).release()
        elif step == 18:
            world.get(ents[3], Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
        elif step == 28:
            world.get(ents[3], Ragdoll).set_mode(RagdollMode.ANIMATED)
        app.step()
        hashes.append(state_hash(world))
    return hashes, served


def test_a_walking_crowd_steps_as_the_loop_does(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    fast, served = _run(skeleton, monkeypatch, walking=True)
    loop, none = _run(skeleton, monkeypatch, walking=False)
    assert none == []
    assert fast == loop
    # held from 5 (the world lets go at the stage of step 12, so 13 is served), limp from 18, ramping
    # back to animated from 28 over its transition time (0.25 s: in float steps of dt / 0.25, the 16th lands)
    assert served == [*range(5), *range(13, 18), *range(28 + 16, STEPS)]
