"""The FK stage (:mod:`engine.posing`): the compiled pass into the columns against the general path.

25 puppets of two hierarchies (humanoids, some with their own bone lengths, and a three-joint
chain) are stepped through :func:`fk_system` while their local poses change through the
columns, one puppet's local rotations and another's world positions are replaced by other
code (the pass takes them in), a puppet's offsets change, a puppet is spawned mid-run and the
local poses' columns are rewritten in another order than the FK groups' (the pass reads them
at their rows). With the compiled pass and
with it switched off, world poses and previous poses must be equal bit for bit; against the
pure-numpy path (numba off) to 1e-12. Broken once by copying the previous pose after the
kernel instead of before (``prev_*`` then equals this step's pose) and once by keeping the
plan when a puppet's offsets object changes (that puppet's positions differ).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import engine.posing as posing
from engine import jit, quat
from engine.app import App
from engine.columns import columns
from engine.components import LocalPose, Puppet, WorldPose
from engine.humanoid import humanoid_skeleton
from engine.skeleton import Skeleton

N = 24
STEPS = 8


def _run(mode: str, monkeypatch: pytest.MonkeyPatch) -> tuple[list[Any], list[int]]:
    """``mode``: ``compiled`` (the pass), ``general`` (pass off), ``numpy`` (numba off)."""
    served: list[int] = []
    original = posing._compiled

    def counted(*args: Any) -> bool:
        done = mode == "compiled" and original(*args)
        if done:
            served.append(len(out))
        return done

    monkeypatch.setattr(posing, "_compiled", counted)
    rng = np.random.default_rng(8)
    app = App(seed=1, plugins=[posing.install_fk])
    world = app.world
    sk = humanoid_skeleton()
    chain = Skeleton(("a", "b", "c"), np.array([-1, 0, 1]), np.array([[0, 1, 0], [0, 0.5, 0], [0.2, 0.3, 0]]))
    ents = []
    for i in range(N):
        skel = chain if i % 6 == 5 else sk
        offsets = skel.offsets * 1.1 if i % 4 == 0 else None
        pose = LocalPose(rng.normal(size=3), quat.identity(skel.num_joints))
        ents.append(world.spawn(Puppet(skel, offsets), pose))
    out: list[Any] = []
    with jit.use(mode != "numpy"):
        for step in range(STEPS):
            if step == 4:
                ents.append(world.spawn(Puppet(sk), LocalPose(np.zeros(3), quat.identity(17))))
            cols = columns(world)
            for skel in (sk, chain):
                mine = [world.get(e, LocalPose) for e in ents if world.get(e, Puppet).skeleton is skel]
                if step >= 4:  # the local poses' columns in another order than the FK group's: rows, not the whole
                    mine = mine[::-1]
                j = skel.num_joints
                cols.get(LocalPose, "root", j).write(mine, rng.normal(size=(len(mine), 3)))
                rots = quat.normalize(quat.identity(len(mine), j) + rng.normal(0, 0.2, (len(mine), j, 4)))
                cols.get(LocalPose, "rotations", j).write(mine, rots)
            if step == 2:
                world.get(ents[1], LocalPose).rotations = quat.exp(rng.normal(0, 0.3, (17, 3)))
                world.get(ents[2], WorldPose).positions = np.zeros((17, 3))
            if step == 6:
                world.get(ents[3], Puppet).offsets = sk.offsets * 0.9
            app.step()
            poses = [world.get(e, WorldPose) for e in ents]
            out.append([np.concatenate([getattr(p, f) for p in poses]) for f in posing._WORLD_FIELDS])
    return out, served


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there is no compiled pass")
def test_the_compiled_fk_pass_is_the_general_path_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    compiled, served = _run("compiled", monkeypatch)
    general, none = _run("general", monkeypatch)
    numpy_path, _ = _run("numpy", monkeypatch)
    # Two groups a step; none at step 0 (no world poses yet) or when a puppet is spawned (4: it
    # has none); a replaced field (2) is taken in, and the local poses' rows in reversed order
    # (relinked so at the spawn, 4, on) are read where they are.
    assert none == [] and served == [1, 1, 2, 2, 3, 3, 5, 5, 6, 6, 7, 7]
    for a, b, c in zip(compiled, general, numpy_path, strict=True):
        for x, y, z in zip(a, b, c, strict=True):
            np.testing.assert_array_equal(x, y)
            np.testing.assert_allclose(x, z, atol=1e-12)
    # The previous pose is last step's pose, not this one's.
    for step in (5, 6, 7):
        np.testing.assert_array_equal(compiled[step][2], compiled[step - 1][0])
        np.testing.assert_array_equal(compiled[step][3], compiled[step - 1][1])
        assert not np.array_equal(compiled[step][0], compiled[step][2])
