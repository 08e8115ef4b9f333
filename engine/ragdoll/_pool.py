"""The ragdoll pool: MuJoCo bodies compiled once and lent to puppets, so joining costs no compile.

Compiling MJCF is the slow part of physics (a 17-body ragdoll costs ~8 ms, 400 of them 33 s and
1000 run out of memory), and a crowd changes who is simulated every time a ball rolls by or a
puppet falls. So the model holds a *pool* of ragdoll slots per kind of ragdoll (same skeleton,
profile and bone offsets render the same bodies), each under its own stable names
(``rd<slot>_…``). A puppet that must be simulated borrows a free slot of its kind: its pose and
velocity are copied in and the slot is woken; a puppet that leaves gives the slot back, which is
*parked*: no contacts (``contype = conaffinity = 0``), no muscles, no constraints, at rest, and
put to sleep with MuJoCo's sleeping (``mjENBL_SLEEP``), so its bodies cost almost nothing per
step (MuJoCo skips sleeping trees in every stage; ~2-3 µs per parked ragdoll per substep here).

Parked slots are not free, though: MuJoCo's kinematics and constraint making still walk every
body and joint of the model, about 0.45 ms per substep for 96 parked slots (with one ragdoll awake,
a 96-slot model stepped 8 substeps in ~4 ms where one ragdoll alone costs well under 1). So the first
build is no bigger than a crowd's falls need: ten of a hundred falling pull 30-38 ragdolls into the
model (the fallers and the walking neighbours their capsules come near), hence :data:`INITIAL` 48.

Slots are added in chunks (:func:`grow_to`): the first build of a crowd holds enough for
``min(ragdolls of the kind, INITIAL)``, and only when more are needed at once than the pool holds
does it grow, to what is needed and a quarter more (one compile, carrying every state by name;
compiling is superlinear in the pool's size, so doubling cost more than it saved), never once per join, up to
:data:`MAX_SLOTS`; past that the simulated ragdolls are served first and the animated ones that
would only be pushed by them wait outside (:attr:`PhysicsWorld.left_out`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import heapq
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine.ragdoll._contact_bits import set_contact_bits
from engine.ragdoll._layout import Layout
from engine.ragdoll.mjcf import RagdollFragment, RagdollSpec, ragdoll_fragment, rd_name

__all__ = [
    "CHUNK",
    "INITIAL",
    "MAX_SLOTS",
    "PoolSlot",
    "RagdollPool",
    "SlotTable",
    "kind_of",
    "park",
    "settle",
    "slot_table",
    "update_sleep",
    "wake",
]

CHUNK = 4  # slots: the pool grows in multiples of this
INITIAL = 48  # slots of a kind compiled at a crowd's first build at most (see below)
MAX_SLOTS = 128  # slots of a kind at most: compiling 128 costs ~1.4 s, 256 ~7 s, ~1000 cannot be allocated
_TEMPLATE = -1  # the key a kind's template is rendered under before its names are replaced
_AWAKE = -(1 + mujoco.mjMINAWAKE)
_PARK = np.array([0.0, -50.0, 0.0])  # m: under the field, out of every contact


def kind_of(spec: RagdollSpec) -> bytes:
    """What makes two ragdolls' bodies identical: skeleton, profile and bone offsets."""
    sk, pr = spec.skeleton, spec.profile
    h = hashlib.blake2b(digest_size=16)
    h.update("\0".join(sk.names).encode())
    parts = [
        np.asarray(sk.parents),
        np.asarray(sk.tips, dtype=np.float64),
        spec.offsets,
        pr.radii,
        pr.masses,
        pr.hinge_axis,
        pr.hinge_range,
        pr.cone,
        pr.twist,
    ]
    for a in parts:
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(repr((pr.kinds, pr.holdable, pr.frequency, pr.damping_ratio, pr.joint_damping, pr.friction)).encode())
    return h.digest()


@dataclass
class PoolSlot:
    """One compiled ragdoll in the model, free or lent to puppet ``owner``."""

    kind: bytes
    fragment: RagdollFragment
    owner: int | None = None


class RagdollPool:
    """The slots in compile order (slot ``i`` is named ``rd<i>_…`` in MuJoCo), with each kind's
    slot count and free slots kept as they change (a fall asks for them once per joiner)."""

    def __init__(self) -> None:
        self.slots: list[PoolSlot] = []
        self._templates: dict[bytes, RagdollFragment] = {}
        self._count: dict[bytes, int] = {}
        self._free: dict[bytes, list[int]] = {}  # a heap per kind: the lowest free slot first

    def count(self, kind: bytes) -> int:
        """Slots of a kind."""
        return self._count.get(kind, 0)

    def free(self, kind: bytes) -> int:
        """Free slots of a kind."""
        return len(self._free.get(kind, ()))

    def free_slots(self) -> list[int]:
        """Every free slot, ascending."""
        return sorted(i for free in self._free.values() for i in free)

    def grow_to(self, spec: RagdollSpec, size: int) -> bool:
        """Make room for ``size`` slots of ``spec``'s kind (rounded up to :data:`CHUNK`); whether it grew."""
        kind = kind_of(spec)
        have = self.count(kind)
        want = -(-size // CHUNK) * CHUNK
        if have >= want:
            return False
        if kind not in self._templates:  # rendered once per kind: only names differ between slots
            self._templates[kind] = ragdoll_fragment(dataclasses.replace(spec, key=_TEMPLATE))
        tpl = self._templates[kind]
        old = rd_name(_TEMPLATE, "")
        for _ in range(want - have):
            i = len(self.slots)
            new = rd_name(i, "")
            body, contact, equality, actuator = (
                tuple(line.replace(old, new) for line in lines)
                for lines in (tpl.body, tpl.contact, tpl.equality, tpl.actuator)
            )
            frag = RagdollFragment(
                dataclasses.replace(tpl.spec, key=i), body, contact, equality, actuator, tpl.kp, tpl.kv
            )
            self.slots.append(PoolSlot(kind, frag))
            heapq.heappush(self._free.setdefault(kind, []), i)
        self._count[kind] = want
        return True

    def take(self, kind: bytes, owner: int) -> int | None:
        """Lend the lowest free slot of a kind to ``owner`` (``None`` when the kind has none free)."""
        free = self._free.get(kind)
        if not free:
            return None
        i = heapq.heappop(free)
        self.slots[i].owner = owner
        return i

    def release(self, i: int) -> None:
        """Give slot ``i`` back."""
        s = self.slots[i]
        if s.owner is not None:
            s.owner = None
            heapq.heappush(self._free[s.kind], i)


def update_sleep(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """Recompute MuJoCo's awake arrays from ``d.tree_asleep`` (its ``mj_updateSleep``, which the
    bindings do not expose): without it a tree put to sleep by hand is simulated anyway and woken
    at the next step as "perturbed"."""
    awake = np.asarray(d.tree_asleep) < 0
    d.tree_awake[:] = awake
    d.ntree_awake = int(awake.sum())
    tree = m.body_treeid
    mocap = m.body_mocapid[m.body_rootid] >= 0
    state = np.where(
        tree < 0,
        np.where(mocap, int(mujoco.mjtSleepState.mjS_AWAKE), int(mujoco.mjtSleepState.mjS_STATIC)),
        awake[np.maximum(tree, 0)].astype(np.int32),
    )
    d.body_awake[:] = state
    ind = np.nonzero(state != 0)[0]
    d.body_awake_ind[: len(ind)] = ind
    d.nbody_awake = len(ind)
    par = np.nonzero(state[m.body_parentid] != 0)[0]
    par = par[par > 0]
    d.parent_awake_ind[: len(par)] = par
    d.nparent_awake = len(par)
    b = m.dof_bodyid
    dofs = np.nonzero((tree[b] >= 0) & (state[b] == 1))[0]
    d.dof_awake_ind[: len(dofs)] = dofs
    d.nv_awake = len(dofs)


@dataclass(frozen=True)
class SlotTable:
    """What parking and waking touch of each pool slot in one compiled model, found once per compile
    (:func:`slot_table`), so that a slot leaving costs array writes, not searches over every body,
    geom and joint of the model and a Python pass over its joints."""

    tree: NDArray[np.int64]  # [S] MuJoCo tree of each slot
    bodies: NDArray[np.int64]  # [S,2] body id range
    dofs: NDArray[np.int64]  # [S,2] dof range
    qpos: NDArray[np.int64]  # [S,2] qpos range (a tree's joints are contiguous)
    rest: NDArray[np.float64]  # [nq] each slot's parked pose at its qpos range (elsewhere unused)
    geoms: list[NDArray[np.int64]]  # per slot: its geoms
    acts: list[NDArray[np.int64]]  # per slot: its actuators
    eqs: list[NDArray[np.int64]]  # per slot: its pin and hold constraints


def slot_table(m: mujoco.MjModel, pool: Layout) -> SlotTable:
    """The :class:`SlotTable` of model ``m`` whose pool slots are laid out by ``pool``."""
    slots = len(pool.keys)
    tree = np.asarray(m.body_treeid)[pool.body[pool.starts[:slots]]].astype(np.int64)
    b0 = np.asarray(m.tree_bodyadr)[tree].astype(np.int64)
    v0 = np.asarray(m.tree_dofadr)[tree].astype(np.int64)
    bodies = np.stack([b0, b0 + np.asarray(m.tree_bodynum)[tree]], axis=1)
    dofs = np.stack([v0, v0 + np.asarray(m.tree_dofnum)[tree]], axis=1)
    slot_of_tree = np.full(m.ntree, -1, dtype=np.int64)
    slot_of_tree[tree] = np.arange(slots)
    jtype, qadr = np.asarray(m.jnt_type), np.asarray(m.jnt_qposadr).astype(np.int64)
    jslot = np.where(m.body_treeid[m.jnt_bodyid] >= 0, slot_of_tree[m.body_treeid[m.jnt_bodyid]], -1)
    width = np.select([jtype == mujoco.mjtJoint.mjJNT_FREE, jtype == mujoco.mjtJoint.mjJNT_BALL], [7, 4], 1)
    rest = np.zeros(m.nq)
    free = np.nonzero((jtype == mujoco.mjtJoint.mjJNT_FREE) & (jslot >= 0))[0]
    for k in range(3):  # under the field at rest, each slot apart from every other one
        rest[qadr[free] + k] = _PARK[k] + (4.0 * jslot[free] if k == 0 else 0.0)
    rest[qadr[free] + 3] = 1.0
    rest[qadr[(jtype == mujoco.mjtJoint.mjJNT_BALL) & (jslot >= 0)]] = 1.0
    qpos = np.zeros((slots, 2), dtype=np.int64)
    for s in range(slots):
        own = np.nonzero(jslot == s)[0]
        qpos[s] = qadr[own].min(), qadr[own].max() + width[own[np.argmax(qadr[own])]]
        assert qpos[s, 1] - qpos[s, 0] == width[own].sum(), "a pool slot's joints are not contiguous in qpos"
    gbody = np.asarray(m.geom_bodyid)
    geoms = [np.nonzero((gbody >= a) & (gbody < b))[0].astype(np.int64) for a, b in bodies]
    acts = [pool.act[pool.act_owner == s] for s in range(slots)]
    eqs = [np.array([int(pool.pin_eq[s]), *pool.hold_eq[s].values()], dtype=np.int64) for s in range(slots)]
    return SlotTable(tree, bodies, dofs, qpos, rest, geoms, acts, eqs)


def park(m: mujoco.MjModel, d: mujoco.MjData, table: SlotTable, slot: int) -> None:
    """Take slot ``slot`` out of the simulation: under the field at rest, nothing touching it,
    no muscle or constraint (:func:`settle` then puts it to sleep)."""
    tree = int(table.tree[slot])
    (b0, b1), (v0, v1), (q0, q1) = table.bodies[slot].tolist(), table.dofs[slot].tolist(), table.qpos[slot].tolist()
    set_contact_bits(m, table.geoms[slot], 0, 0)
    acts = table.acts[slot]
    m.actuator_gainprm[acts, 0] = 0.0
    m.actuator_biasprm[acts, :3] = 0.0
    d.eq_active[table.eqs[slot]] = 0
    d.xfrc_applied[b0:b1] = 0.0
    d.qfrc_applied[v0:v1] = 0.0
    d.qpos[q0:q1] = table.rest[q0:q1]  # the rest pose, parked apart from every other slot
    d.qvel[v0:v1] = 0.0
    d.qacc_warmstart[v0:v1] = 0.0
    m.tree_sleep_policy[tree] = int(mujoco.mjtSleepPolicy.mjSLEEP_ALLOWED)
    d.tree_asleep[tree] = _AWAKE  # until :func:`settle` puts it to sleep where it now is


def wake(m: mujoco.MjModel, d: mujoco.MjData, table: SlotTable, slot: int) -> None:
    """Put slot ``slot`` back into the simulation (it never falls asleep by itself: a ragdoll lying
    still must still answer its muscles; :func:`settle` applies it)."""
    tree = int(table.tree[slot])
    m.tree_sleep_policy[tree] = int(mujoco.mjtSleepPolicy.mjSLEEP_NEVER)
    d.tree_asleep[tree] = _AWAKE


def settle(m: mujoco.MjModel, d: mujoco.MjData, free: list[int], table: SlotTable) -> None:
    """Put the free slots ``free`` to sleep where :func:`park` left them, everything else awake.

    MuJoCo wakes a sleeping tree whose body poses do not match its ``qpos`` (it takes that for a
    push from outside), so the poses of the slots parked since the last settle go through kinematics
    awake first, then sleep. A slot already asleep stays asleep: its poses were made from the parked
    state it still has, so waking it would only recompute the same numbers.
    """
    trees = table.tree[np.asarray(free, dtype=np.int64)]
    trees = trees[np.asarray(d.tree_asleep)[trees] < 0]
    update_sleep(m, d)
    mujoco.mj_kinematics(m, d)
    d.tree_asleep[trees] = trees  # each a sleep cycle of one tree
    update_sleep(m, d)
