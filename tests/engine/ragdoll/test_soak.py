"""A physics soak: thousands of seeded steps of rough play, invariants checked every step.

Puppets with their brains and a field of snowballs; every few steps the seeded generator
picks something a rough player does: yank a puppet sideways, lift one into the sky and
let go, throw one onto another, throw a ball at a puppet; half-way, thirty puppets are
dropped on one spot. After every step: every number finite, every puppet inside the field
(balls may roll on over the open plane), every body below a height, every speed bounded,
and no puppet stuck in one fallen state; over the run, no MuJoCo warning or error and at
most one undone step (:class:`PhysicsRecovery`) per 500. The player's own repros (a flick
into the sky, thirty puppets on one spot) are among these actions; the input path itself
is not driven.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from engine.app import App
from engine.components import LocalPose, Transform
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, spawn_snowball
from engine.ragdoll._guard import MAX_LINEAR, PhysicsRecovery
from engine.ragdoll.components import Prop
from engine.statemachine import Brain
from engine.statemachine.puppet import install_puppets, spawn_puppet

STEPS = 1200
PILE_AT = 500
FIELD = 40.0  # m from the origin
CEILING = 40.0  # m
STUCK = 20.0  # s in one state other than locomotion


def _rough_play(app: App, rng: np.random.Generator, puppets: list[int], balls: list[int]) -> None:
    w = app.world
    e = int(rng.choice(puppets))
    rd, tr = w.get(e, Ragdoll), w.get(e, Transform)
    act = rng.integers(4)
    if act == 0:  # a yank of the stick: the puppet is dragged far in one step
        tr.position = tr.position + np.array([rng.uniform(-3, 3), 0.0, rng.uniform(-3, 3)])
    elif act == 1:  # lifted into the sky by its chest, let go later
        rd.set_mode(RagdollMode.LIMP)
        rd.grab("chest", np.array([tr.position[0], rng.uniform(5, 25), tr.position[2]]))
    elif act == 2:  # thrown onto another puppet
        other = w.get(int(rng.choice(puppets)), Transform).position
        pose = w.get(e, LocalPose)
        pose.root = other + np.array([0.0, rng.uniform(0.5, 2.5), 0.0])
        rd.set_mode(RagdollMode.LIMP, immediate=True)
    else:  # a ball thrown at it
        b = int(rng.choice(balls))
        prop = w.get(b, Prop)
        aim = tr.position + [0.0, 0.8, 0.0] - w.get(b, Transform).position
        prop.velocity = np.concatenate([aim / max(np.linalg.norm(aim), 1e-6) * rng.uniform(4, 15), np.zeros(3)])
        prop.placed = True
    for p in puppets:
        r = w.get(p, Ragdoll)
        if r.held is not None and rng.random() < 0.05:
            r.release()


def _check(app: App, since: dict[int, tuple[str, float]]) -> None:
    w = app.world
    pw = w.resource(PhysicsWorld)
    for e, tr in w.query(Transform):
        assert np.isfinite(tr.position).all() and np.isfinite(tr.rotation).all(), e
        assert -1.0 < tr.position[1] < CEILING, (e, tr.position)
        # balls roll on over the open plane; puppets must stay in the field
        assert w.has(e, Prop) or np.hypot(tr.position[0], tr.position[2]) < FIELD, (e, tr.position)
    for e, pose in w.query(LocalPose):
        assert np.isfinite(pose.root).all() and np.isfinite(pose.rotations).all(), e
        assert np.hypot(pose.root[0], pose.root[2]) < FIELD and pose.root[1] < CEILING, (e, pose.root)
    for e, prop in w.query(Prop):
        assert np.linalg.norm(prop.velocity[:3]) <= MAX_LINEAR * np.sqrt(3) + 1e-9, e
    if pw.data is not None:
        assert np.isfinite(pw.data.qpos).all() and np.isfinite(pw.data.qvel).all()
    for e, brain in w.query(Brain):
        state, start = since.get(e, (brain.active, w.time))
        if brain.active != state:
            start = w.time
        since[e] = (brain.active, start)
        assert brain.active == "Locomotion" or w.time - start < STUCK, (e, brain.active)


@pytest.mark.slow  # the suite's longest: 700 steps of 34 ragdoll puppets after the pile (~0.2 s of CPU each)
def test_rough_play_never_breaks_the_physics() -> None:
    rng = np.random.default_rng(17)
    app = App(seed=17)
    install_puppets(app)
    w = app.world
    puppets = [spawn_puppet(w, (2.0 * i - 3.0, 0.0, 0.0), float(rng.uniform(-3, 3))) for i in range(4)]
    balls = [
        spawn_snowball(w, [rng.uniform(-5, 5), 0.3, rng.uniform(-5, 5)], float(rng.uniform(0.12, 0.35)))
        for _ in range(8)
    ]
    since: dict[int, tuple[str, float]] = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PhysicsRecovery)
        for step in range(STEPS):
            if step % 15 == 0:
                _rough_play(app, rng, puppets, balls)
            if step == PILE_AT:  # thirty puppets dropped on one spot
                for k in range(30):
                    p = spawn_puppet(w, (0.0, 0.0, 4.0), float(rng.uniform(-3, 3)))
                    w.get(p, LocalPose).root = np.array([0.0, 1.0 + 0.05 * k, 4.0])
                    w.get(p, Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
            app.step()
            _check(app, since)
    reasons = [str(c.message) for c in caught if issubclass(c.category, PhysicsRecovery)]
    assert not [r for r in reasons if "MuJoCo" in r or "non-finite" in r], reasons
    # a rare substep that still explodes (a puppet dropped into the pile) is undone, not shown
    assert len(reasons) <= STEPS // 500, reasons
    assert w.resource(PhysicsWorld).recoveries == len(reasons)
