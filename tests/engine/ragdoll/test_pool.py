"""The ragdoll pool: joining and leaving the simulation is a state copy and a sleep flag, never a compile."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from engine import quat
from engine.ragdoll import _building as building_module
from engine.ragdoll import default_profile
from engine.ragdoll import physics as physics_module
from engine.ragdoll._pool import RagdollPool, kind_of
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton


def _crowd(skeleton: Skeleton, n: int) -> PhysicsWorld:
    pw = PhysicsWorld()
    pr = default_profile(skeleton)
    for k in range(n):
        pw.add_ragdoll(k + 1, skeleton, pr, [6.0 * k, 1.0, 0.0], quat.identity(skeleton.num_joints))
    return pw


def _drive(pw: PhysicsWorld, skeleton: Skeleton, falling: set[int]) -> None:
    """Keys in ``falling`` go limp (simulated); the others stand, animated, too far apart to touch."""
    rot = quat.identity(skeleton.num_joints)
    for k in pw.ragdoll_keys:
        root = np.array([6.0 * (k - 1), 1.0, 0.0])
        if k in falling:
            pw.drive(k, root, rot, 0.0, 0.0)
        else:
            pw.drive(k, root, rot, 1.0, 1.0, kinematic=True)


def test_joining_and_leaving_compiles_nothing(skeleton: Skeleton) -> None:
    pw = _crowd(skeleton, 6)
    _drive(pw, skeleton, set())
    pw.step()
    assert pw.rebuilds == 1 and pw.model is not None and pw.data is not None
    assert pw.asleep() == 8 and pw.data.ntree_awake == 0  # 6 rounded up to a chunk, all parked
    for falling in ({1, 2}, {2, 3, 4}, set(), {1, 6}, {5}):
        _drive(pw, skeleton, falling)
        pw.step()
        assert {k for k in pw.ragdoll_keys if pw.in_model(k)} == falling
        assert pw.data.ntree_awake == len(falling)  # the parked slots cost no dynamics
    assert pw.rebuilds == 1


def test_a_parked_slot_stays_where_it_was_parked(skeleton: Skeleton) -> None:
    pw = _crowd(skeleton, 2)
    _drive(pw, skeleton, {1})
    for _ in range(30):
        pw.step()
    d = pw.data
    assert d is not None
    parked = np.asarray(d.tree_asleep) >= 0
    assert parked.sum() == 3
    before = d.qpos.copy()
    for _ in range(30):
        pw.step()
    m = pw.model
    assert m is not None
    for t in np.nonzero(parked)[0]:  # asleep: not one number of a parked ragdoll moved under gravity
        b0 = m.tree_bodyadr[t]
        j = np.nonzero(m.jnt_bodyid == b0)[0][0]
        q = m.jnt_qposadr[j]
        np.testing.assert_array_equal(d.qpos[q : q + 7], before[q : q + 7])


def test_the_pool_grows_once_when_more_fall_at_once(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(building_module, "INITIAL", 4)
    pw = _crowd(skeleton, 10)
    _drive(pw, skeleton, set())
    pw.step()
    assert pw.rebuilds == 1 and pw.asleep() == 4
    _drive(pw, skeleton, set(range(1, 7)))  # six at once: one growth, to 8 (six and a quarter, in chunks of 4)
    for _ in range(3):
        pw.step()
    assert pw.rebuilds == 2 and pw.model is not None
    assert pw.model.ntree == 8 and pw.asleep() == 2


def test_a_fall_replays_bit_for_bit(skeleton: Skeleton) -> None:
    def run() -> list[bytes]:
        pw = _crowd(skeleton, 4)
        out = []
        for step in range(40):
            _drive(pw, skeleton, {2, 3} if 5 <= step < 30 else set())
            pw.step()
            out.append(pw.state_bytes())
        return out

    a, b = run(), run()
    assert a == b
    assert len(set(a)) > 20  # the state did change: a fall, then the slots parked again


def test_a_joining_ragdoll_keeps_its_place_and_motion(skeleton: Skeleton) -> None:
    pw = _crowd(skeleton, 3)
    _drive(pw, skeleton, set())
    pw.step()
    _drive(pw, skeleton, {3})
    pw.step()
    root = pw.pose(3).root
    assert abs(root[0] - 12.0) < 0.01 and abs(root[1] - 1.0) < 0.05  # where its animation was, not parked
    m = pw.model
    assert m is not None
    tree = m.body_treeid[m.body(pw.mujoco_name(3, "hips")).id]  # lying still, it must still answer its muscles
    assert m.tree_sleep_policy[tree] == mujoco.mjtSleepPolicy.mjSLEEP_NEVER


def test_a_crowd_standing_steps_no_mujoco_at_all(skeleton: Skeleton) -> None:
    pw = _crowd(skeleton, 3)
    _drive(pw, skeleton, set())
    pw.step()
    assert pw.data is not None
    t = pw.data.time
    pw.step()
    assert pw.data.time == t  # every slot parked: the step skipped mj_step
    _drive(pw, skeleton, {2})
    pw.step()
    assert pw.data.time == pytest.approx(t + pw.dt)


def test_a_ragdoll_that_falls_again_lands_on_the_ground(skeleton: Skeleton) -> None:
    """MuJoCo's broad phase filters on ``body_contype``/``body_conaffinity`` (the OR of a body's
    geoms' bits), which it recomputes from the geoms only at some steps. In a recorded snowman
    session (a snowball in the field, the puppet lifted, put down, lifted again) it had recomputed
    them while the slot was parked, so they were zero when the slot joined again with only its geom
    bits rewritten, and the ragdoll fell through the ground (y = -30 m two seconds after the release).
    Here the parked slot's body bits are zeroed as that session had them; joining must restore them
    (:func:`~engine.ragdoll._contact_bits.set_contact_bits`). Broken once by writing the geom bits
    alone: the hips ended 19 m under the field."""
    pw = _crowd(skeleton, 2)
    for falling, steps in (({1}, 60), (set(), 10)):  # a fall, then parked again
        for _ in range(steps):
            _drive(pw, skeleton, falling)
            pw.step()
    m = pw.model
    assert m is not None and pw._pool_layout is not None
    pool = pw._pool_layout
    slot = pool.body[pool.body_owner == 0]
    m.body_contype[slot] = 0  # what MuJoCo's own recomputation left on the parked slot
    m.body_conaffinity[slot] = 0
    for _ in range(120):  # two seconds limp
        _drive(pw, skeleton, {1})
        pw.step()
    hips = pw.pose(1).root
    assert hips[1] > 0.0, f"the ragdoll fell through the ground: hips at y = {hips[1]:.2f} m"
    body = m.body(pw.mujoco_name(1, "hips")).id
    assert m.body_contype[body] != 0 and m.body_conaffinity[body] != 0


def test_a_step_where_one_leaves_assigns_slots_once(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    """A ragdoll that leaves the model gives its slot back inside the step's own assignment; reading
    the world after that step must not run a second one (it did: a whole select, settle and
    ``mj_forward`` more on every step where a ragdoll left). Broken by clearing ``_moved`` before the
    give-backs in ``Building._assign``: the reads below then assign again."""
    pw = _crowd(skeleton, 4)
    _drive(pw, skeleton, {1, 2})
    pw.step()
    calls: list[int] = []
    original = building_module.Building._assign

    def counted(self: PhysicsWorld) -> None:
        calls.append(1)
        original(self)

    monkeypatch.setattr(building_module.Building, "_assign", counted)
    _drive(pw, skeleton, {2})
    pw.step()
    assert len(calls) == 1 and not pw.in_model(1)
    pw.pose(2), pw.root_velocity(2), pw.kinetic_energy(2)
    assert len(calls) == 1


def test_membership_changes_run_no_forward(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    """Joining and leaving run MuJoCo's kinematics, not a whole ``mj_forward`` (the next ``mj_step``
    computes the rest): when that step starts, each joiner's root body is where its state puts it, not
    where its slot was parked. Broken by calling ``mj_forward`` at the end of ``Building._assign`` again
    (the count is then not zero), or by leaving out settle's kinematics (the bodies are still parked)."""
    pw = _crowd(skeleton, 4)
    _drive(pw, skeleton, set())
    pw.step()
    calls: list[int] = []
    forward = mujoco.mj_forward

    def counted(m: mujoco.MjModel, d: mujoco.MjData) -> None:
        calls.append(1)
        forward(m, d)

    monkeypatch.setattr(building_module.mujoco, "mj_forward", counted)
    gaps: list[float] = []
    step = physics_module.guarded_step

    def checked(
        m: mujoco.MjModel, d: mujoco.MjData, substeps: int, limit: np.ndarray, owners: np.ndarray
    ) -> str | None:
        L = pw.layout
        assert L is not None
        roots = L.body[L.starts[:-1]]
        gaps.append(float(np.abs(d.xpos[roots] - d.qpos[L.root_q[:, None] + np.arange(3)]).max()))
        return step(m, d, substeps, limit, owners)

    monkeypatch.setattr(physics_module, "guarded_step", checked)
    for falling in ({1, 2}, {2}, {3, 4}, {1, 3}):
        _drive(pw, skeleton, falling)
        pw.step()
    assert calls == [] and len(gaps) == 4 and max(gaps) < 1e-9


def test_a_slot_given_back_is_parked_at_rest_apart_and_inert(skeleton: Skeleton) -> None:
    """A ragdoll that leaves after a fall leaves its slot under the field at rest, 4 m from every
    other slot, with no contact bit, muscle, pin or hold left on, each joint checked one by one from
    MuJoCo's own joint list (not from the slot table that parking reads). Broken once by writing the
    parked roots without their slot's 4 m offset, once by a rest pose shifted by one qpos entry: both fail."""
    pw = _crowd(skeleton, 3)
    for _ in range(20):
        _drive(pw, skeleton, {2, 3})
        pw.step()
    slot = int(pw.commands.pool[pw.commands.rows([3])[0]])
    assert slot > 0  # (slot 0's offset is none)
    _drive(pw, skeleton, {2})  # 3 leaves, 2 stays in the model
    pw.step()
    m, d = pw.model, pw.data
    assert m is not None and d is not None and not pw.in_model(3) and pw.in_model(2)
    b0 = int(m.body(f"rd{slot}_{skeleton.names[0]}").id)
    t = int(m.body_treeid[b0])
    nb, v0, nv = int(m.tree_bodynum[t]), int(m.tree_dofadr[t]), int(m.tree_dofnum[t])
    assert int(d.tree_asleep[t]) >= 0  # asleep
    for j in np.nonzero((m.jnt_bodyid >= b0) & (m.jnt_bodyid < b0 + nb))[0]:
        q = int(m.jnt_qposadr[j])
        if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            np.testing.assert_array_equal(d.qpos[q : q + 7], [4.0 * slot, -50.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        elif m.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
            np.testing.assert_array_equal(d.qpos[q : q + 4], [1.0, 0.0, 0.0, 0.0])
        else:
            assert d.qpos[q] == 0.0
    assert not d.qvel[v0 : v0 + nv].any()
    geoms = np.nonzero((m.geom_bodyid >= b0) & (m.geom_bodyid < b0 + nb))[0]
    assert len(geoms) and not m.geom_contype[geoms].any() and not m.geom_conaffinity[geoms].any()
    joints = np.nonzero((m.jnt_bodyid >= b0) & (m.jnt_bodyid < b0 + nb))[0]
    acts = np.nonzero(np.isin(m.actuator_trnid[:, 0], joints))[0]
    assert len(acts) and not m.actuator_gainprm[acts, 0].any()
    eqs = [i for i in range(m.neq) if m.eq(i).name.startswith(f"rd{slot}_")]
    assert eqs and not d.eq_active[eqs].any()


def test_the_pool_lends_the_lowest_free_slot_and_counts_what_it_holds(skeleton: Skeleton) -> None:
    """The pool's counts and free slots are kept as slots are added, lent and given back (not
    searched for): lending gives the lowest free slot of the kind, and a slot given back twice is
    free once. Broken once by pushing a slot back on every release (the double one counted twice):
    it fails; once by lending the newest free slot instead of the lowest: it fails."""
    spec = _crowd(skeleton, 1)._ragdolls[1].spec
    kind = kind_of(spec)
    pool = RagdollPool()
    assert pool.grow_to(spec, 5) and pool.count(kind) == 8 and pool.free(kind) == 8
    assert [pool.take(kind, k) for k in (10, 11, 12)] == [0, 1, 2]
    pool.release(1)
    pool.release(1)
    assert pool.free(kind) == 6 and pool.free_slots() == [1, 3, 4, 5, 6, 7]
    assert pool.take(kind, 13) == 1 and pool.slots[1].owner == 13
    assert not pool.grow_to(spec, 8) and pool.grow_to(spec, 9) and pool.count(kind) == 12
    assert pool.free_slots() == list(range(3, 12)) and pool.take(kind, 14) == 3
    assert pool.take(b"another kind", 15) is None and pool.count(b"another kind") == 0


def test_a_membership_change_leaves_sleeping_slots_asleep(skeleton: Skeleton, monkeypatch: pytest.MonkeyPatch) -> None:
    """When a ragdoll leaves, settling runs kinematics over the ragdolls in the model and the slot
    just parked only: the slots parked earlier stay asleep (their poses already
    match their parked state), and afterwards every free slot is asleep again. Broken by waking every
    free slot before the kinematics again (as before): all 8 trees are awake there and it fails."""
    pw = _crowd(skeleton, 6)
    for _ in range(5):
        _drive(pw, skeleton, {1, 2})
        pw.step()
    d = pw.data
    assert d is not None and d.ntree_awake == 2
    awake_at_kinematics: list[int] = []
    kinematics = mujoco.mj_kinematics

    def counted(m: mujoco.MjModel, data: mujoco.MjData) -> None:
        awake_at_kinematics.append(int(data.ntree_awake))
        kinematics(m, data)

    monkeypatch.setattr(mujoco, "mj_kinematics", counted)
    _drive(pw, skeleton, {2})  # 1 leaves
    pw.step()
    assert awake_at_kinematics == [2]  # 2 in the model, 1's slot parked this step
    assert d.ntree_awake == 1 and pw.asleep() == 7
