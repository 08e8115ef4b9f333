"""The physics stage writes the falling ragdolls' blended poses into the local-pose columns
(:mod:`engine.columns`) their poses view, instead of assigning new arrays that the next reader
must take in and re-link one by one. The poses must be the very numbers the assignments gave, and
stay views of their rows. Broken once by writing the roots alone (the rotations kept the targets):
the poses differ from the assigning run's; once by assigning as before: the fields are no views."""

from __future__ import annotations

import numpy as np
import pytest

import engine.ragdoll.system as system
from engine import quat
from engine.app import App
from engine.columns import columns
from engine.components import LocalPose, Puppet
from engine.ragdoll import Ragdoll, RagdollMode, default_profile, install_physics
from engine.skeleton import Skeleton

N = 4
STEPS = 30


def _run(skeleton: Skeleton, rows: bool, monkeypatch: pytest.MonkeyPatch) -> list[tuple[np.ndarray, np.ndarray]]:
    if not rows:
        monkeypatch.setattr(system, "_write_rows", lambda *args: False)
    app = App(seed=3, plugins=[install_physics])
    world = app.world
    J = skeleton.num_joints
    ents = [
        world.spawn(
            Puppet(skeleton),
            LocalPose(np.array([1.2 * i, 1.0, 0.0]), quat.identity(J)),
            Ragdoll(default_profile(skeleton)),
        )
        for i in range(N)
    ]
    poses = tuple(world.get(e, LocalPose) for e in ents)
    rng = np.random.default_rng(5)
    out = []
    for step in range(STEPS):
        # the animation stage: every pose written through the columns, as the crowd's animation does
        cols = columns(world)
        cols.get(LocalPose, "root", J).write(poses, [[1.2 * i + 0.01 * step, 1.0, 0.0] for i in range(N)])
        cols.get(LocalPose, "rotations", J).write(
            poses, quat.normalize(quat.identity(N * J) + rng.normal(0, 0.02, (N * J, 4))).reshape(N, J, 4)
        )
        if step == 4:
            for e in ents[1:3]:
                world.get(e, Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
        app.step()
        if step > 4 and rows:  # the fallers' fields still view their rows
            root_col = cols.get(LocalPose, "root", J)
            assert root_col.linked(poses) is not None
            assert cols.get(LocalPose, "rotations", J).linked(poses) is not None
        out.extend((p.root.copy(), p.rotations.copy()) for p in poses)
    return out


def test_fallers_poses_are_written_into_their_column_rows(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    with monkeypatch.context() as m:
        assigned = _run(skeleton, False, m)
    written = _run(skeleton, True, monkeypatch)
    for (ra, qa), (rb, qb) in zip(assigned, written, strict=True):
        np.testing.assert_array_equal(ra, rb)
        np.testing.assert_array_equal(qa, qb)
