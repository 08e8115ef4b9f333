"""A hundred of a thousand puppets fall at once, with no warning: the physics takes them all.

A thousand ragdolls stand on the sandbox's 1.6 m grid, animated; then a hundred picked by a
seeded generator go limp in the same step. Each one needs dynamics, and so does every
animated neighbour its bodies come near: the pool grows once, the fallen are served first,
nothing crashes, and no later step compiles. The short
run (every test run) checks the fall's first steps; ``pytest -m soak`` follows it for four
seconds, until the fallen lie on the ground.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.ragdoll import default_profile
from engine.ragdoll._pool import MAX_SLOTS
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton

PUPPETS = 1000
FALLERS = 100
SPACING = 1.6  # m, as games.sandbox spreads a crowd


@pytest.mark.soak
def test_a_hundred_of_a_thousand_fall_at_once(skeleton: Skeleton, request: pytest.FixtureRequest) -> None:
    long = "soak" in (request.config.option.markexpr or "")
    steps = 240 if long else 8
    pw = PhysicsWorld()
    pr = default_profile(skeleton)
    rot = quat.identity(skeleton.num_joints)
    side = int(np.ceil(np.sqrt(PUPPETS)))
    hips = float(skeleton.offsets[0][1])
    roots = np.array([[SPACING * (k % side), hips, SPACING * (k // side)] for k in range(PUPPETS)])
    keys = list(range(1, PUPPETS + 1))
    for k in keys:
        pw.add_ragdoll(k, skeleton, pr, roots[k - 1], rot)
    fallen = set(np.random.default_rng(7).choice(keys, FALLERS, replace=False).tolist())
    standing = [k for k in keys if k not in fallen]

    def drive(falling: set[int]) -> None:
        up = [k for k in keys if k not in falling]
        pw.drive_animated(up, [roots[k - 1] for k in up], [rot] * len(up))
        for k in falling:
            pw.drive(k, roots[k - 1], rot, 0.0, 0.0)

    drive(set())
    pw.step()
    assert pw.rebuilds == 1 and pw.data is not None and pw.data.ntree_awake == 0  # a crowd standing costs no dynamics
    drive(fallen)
    pw.step()
    grown = pw.rebuilds
    assert grown <= 2  # one growth for the whole fall, never one per join
    assert all(pw.in_model(k) for k in fallen)  # the fallen first; only animated neighbours wait outside
    # neighbours standing 1.6 m apart do not touch a faller's capsules yet (boxes, not reach
    # spheres, decide: engine.ragdoll._islands); those that would wait outside past the cap
    assert sum(pw.in_model(k) for k in standing) <= MAX_SLOTS - FALLERS
    for _ in range(steps):
        drive(fallen)
        pw.step()
    assert pw.rebuilds == grown and pw.recoveries == 0
    assert np.isfinite(pw.data.qpos).all() and np.isfinite(pw.data.qvel).all()
    lowest = min(float(pw.body_positions(k)[:, 1].min()) for k in fallen)
    assert lowest > -0.05  # nobody sank through the ground
    if long:  # four seconds on: every fallen puppet lies on the ground
        assert max(float(pw.pose(k).root[1]) for k in fallen) < 0.5
