"""Selecting some slots of the pool's layout gives the layout those ragdolls would have on their own:
the same MuJoCo addresses, owners renumbered in the order asked, flat joint indices renumbered."""

from __future__ import annotations

import dataclasses

import numpy as np

from engine import quat
from engine.ragdoll import default_profile
from engine.ragdoll._layout import build_layout, select
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton


def test_select_is_the_layout_of_the_slots_alone(skeleton: Skeleton) -> None:
    """Broken once by gathering each group's rows from the slot before the one asked: every group's
    arrays then differ; once by numbering the owners in slot order instead of the order asked: the
    owner arrays differ."""
    pw = PhysicsWorld()
    for k in range(6):
        pw.add_ragdoll(
            k + 1, skeleton, default_profile(skeleton), [6.0 * k, 1.0, 0.0], quat.identity(skeleton.num_joints)
        )
    pw.drive(1, np.array([0.0, 1.0, 0.0]), quat.identity(skeleton.num_joints), 0.0, 0.0)
    pw.step()  # compiles the pool (6 ragdolls: 8 slots)
    m, pool = pw.model, pw._pool_layout
    assert m is not None and pool is not None and len(pool.keys) == 8
    fragments = [s.fragment for s in pw._pool.slots]
    for slots in ([5, 1, 6], [0], list(range(8)), [7, 2]):
        keys = [100 + s for s in slots]
        got = select(pool, slots, keys)
        alone = build_layout(m, [fragments[s] for s in slots])
        assert got.keys == keys
        for f in dataclasses.fields(alone):
            if f.name in ("keys", "rows_of"):
                continue
            a, b = getattr(got, f.name), getattr(alone, f.name)
            if isinstance(b, np.ndarray):
                assert a.dtype == b.dtype and np.array_equal(a, b), (slots, f.name)
            else:
                assert a == b, (slots, f.name)
