"""Building the physics model and lending its pool slots: the half of
:class:`~engine.ragdoll.physics.PhysicsWorld` that changes what MuJoCo holds.

A mixin, apart because it is the one place that compiles: :meth:`Building._compile` renders the
pool (:mod:`engine.ragdoll._pool`) and the props into one model, carrying every state by name;
:meth:`Building._assign` lends slots to ragdolls that joined the simulation, parks those that
left, and grows the pool (by what is needed and a quarter more) when more need it at once than it holds.
"""

from __future__ import annotations

import hashlib

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as _F
from engine.ragdoll._carry import restore, snapshot
from engine.ragdoll._commands import Commands
from engine.ragdoll._detail import Detail
from engine.ragdoll._guard import velocity_limits
from engine.ragdoll._layout import Layout, build_layout, select
from engine.ragdoll._pool import CHUNK, INITIAL, MAX_SLOTS, RagdollPool, SlotTable, park, settle, slot_table, wake
from engine.ragdoll._slots import PropSlot, RagdollSlot
from engine.ragdoll.mjcf import build_mjcf, prop_name

__all__ = ["Building"]


class Building:
    """Compiling the pool and props, and lending pool slots (state lives on the physics world)."""

    model: mujoco.MjModel | None
    data: mujoco.MjData | None
    layout: Layout | None
    timestep: float
    ground_friction: float
    rebuilds: int
    left_out: int
    _ragdolls: dict[int, RagdollSlot]
    _cmds: Commands
    _props: dict[int, PropSlot]
    _pool: RagdollPool
    _pool_layout: Layout | None
    _slot_table: SlotTable | None = None  # what park and wake touch of each slot (with _pool_layout)
    _dirty: bool
    _sized: bool
    _moved: bool
    _new_data: bool  # a compiled MjData that no mj_forward has run on yet
    _digest: bytes
    _ke: _F | None
    _read: tuple[_F, _F] | None
    _limit: _F
    _owners: NDArray[np.int64]
    detail: Detail

    def _place_rows(self, rows: NDArray[np.int64]) -> None:
        raise NotImplementedError

    def _size_pool(self) -> None:
        """At first sight of a crowd of a kind, room for ``min(its ragdolls, INITIAL)`` at once
        (see :mod:`._pool`), so that its first falls compile nothing."""
        self._sized = True
        counts: dict[bytes, int] = {}
        first: dict[bytes, RagdollSlot] = {}
        for k in sorted(self._ragdolls):
            s = self._ragdolls[k]
            counts[s.kind] = counts.get(s.kind, 0) + 1
            first.setdefault(s.kind, s)
        for kind, n in counts.items():  # a lone ragdoll gets its slot at its first fall (one compile)
            if n > 1 and self._pool.count(kind) == 0 and self._pool.grow_to(first[kind].spec, min(n, INITIAL)):
                self._dirty = True

    def _compile(self) -> None:
        """Compile the pool and the props into a new model, carrying every state over by name."""
        self._dirty = False
        self._moved = True
        old = snapshot(self.model, self.data)
        self._ke = self._read = None
        if not self._pool.slots and not self._props:
            self.model = self.data = self.layout = self._pool_layout = self._slot_table = None
            return
        rd = [s.fragment for s in self._pool.slots]
        pr = [self._props[k].spec for k in sorted(self._props)]
        xml = build_mjcf(rd, pr, self.timestep, self.ground_friction, sleep=bool(rd))
        m = self.model = mujoco.MjModel.from_xml_string(xml)
        d = self.data = mujoco.MjData(m)
        self._new_data = True
        self._digest = hashlib.blake2b(xml.encode(), digest_size=16).digest()
        self.rebuilds += 1
        pool = self._pool_layout = build_layout(m, rd)
        table = self._slot_table = slot_table(m, pool)
        for key, ps in self._props.items():
            n = prop_name(key)
            j = m.joint(n).id
            ps.qadr, ps.dadr = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
            ps.geom, ps.body = m.geom(n).id, m.body(n).id
        self._limit = velocity_limits(m)
        self.detail.compiled(m)
        self._owners = np.full(m.nv, -1, dtype=np.int64)
        for p, (a, b) in enumerate(pool.dofs):
            self._owners[a:b] = p
        for k, ps in enumerate(self._props.values()):
            self._owners[ps.dadr : ps.dadr + 6] = len(pool.keys) + k
        restore(m, d, old)
        m.tree_sleep_policy[:] = int(mujoco.mjtSleepPolicy.mjSLEEP_NEVER)  # props and borrowed slots
        for i, ps_ in enumerate(self._pool.slots):
            if ps_.owner is None:
                park(m, d, table, i)
            else:
                wake(m, d, table, i)
        for ps in self._props.values():
            if ps.init is not None:
                pos, rot, vel = ps.init
                d.qpos[ps.qadr : ps.qadr + 7] = np.concatenate([pos, rot])
                d.qvel[ps.dadr : ps.dadr + 6] = vel
                ps.init = None

    def _assign(self) -> None:
        """Park the slots of ragdolls that left, lend slots to those that joined (growing the pool
        when a kind has too few: to what is needed and a quarter more), and place the newcomers (see :mod:`._pool`)."""
        C = self._cmds
        C.sync()
        for i in np.nonzero(~C.in_model & (C.pool >= 0))[0].tolist():
            self._give_back(i)
        self._moved = False  # (after the give-backs, which mark it: else the next reader assigns all over again)
        # simulated ragdolls first, then the animated ones near them; past MAX_SLOTS of a kind the
        # rest stay out this step (an animated one then passes through, it does not crash the game)
        new = np.nonzero(C.in_model & (C.pool < 0))[0]
        joining = new[np.argsort(C.kinematic[new], kind="stable")].tolist()  # rows are in key order
        kind_of_row = {i: self._ragdolls[int(C.keys[i])].kind for i in joining}
        short: dict[bytes, int] = {}
        for i in joining:
            short[kind_of_row[i]] = short.get(kind_of_row[i], 0) + 1
        for i in joining:
            slot = self._ragdolls[int(C.keys[i])]
            need = short.pop(slot.kind, 0)
            free, have = self._pool.free(slot.kind), self._pool.count(slot.kind)
            if need > free and have < MAX_SLOTS:
                # a quarter of headroom over what is needed now (more joiners usually follow a fall):
                # compiling is superlinear in the pool's size, so doubling would cost more than it saves
                self._pool.grow_to(slot.spec, min(MAX_SLOTS, max(have + CHUNK, -(-5 * (have - free + need) // 4))))
                self._dirty = True
        room = dict.fromkeys(set(kind_of_row.values()), 0)
        self.left_out = 0
        for i in joining:
            kind = kind_of_row[i]
            if room[kind] >= self._pool.free(kind):
                C.in_model[i] = False
                self.left_out += 1
            else:
                room[kind] += 1
        if self._dirty:
            self._compile()
            self._moved = False
        self._ke = self._read = None
        if self.model is None or self.data is None or self._pool_layout is None or self._slot_table is None:
            self.layout = None
            return
        m, d, pool, table = self.model, self.data, self._pool_layout, self._slot_table
        for i in np.nonzero(C.in_model & (C.pool < 0))[0].tolist():
            key = int(C.keys[i])
            taken = self._pool.take(kind_of_row[i], key)
            assert taken is not None
            C.pool[i] = taken
            wake(m, d, table, taken)
        rows = np.nonzero(C.pool >= 0)[0]
        keys = C.keys[rows].tolist()
        self.layout = select(pool, C.pool[rows].tolist(), keys)
        joined = rows[~C.placed[rows]]
        if len(joined):  # joining from outside: where its animation was a step ago, moving as it moved then
            self._place_rows(joined)
            C.placed[joined] = True
        settle(m, d, self._pool.free_slots(), table)
        # settle's kinematics (body and geom poses) is all that is read before the next step, whose
        # mj_step computes the rest from the state; a new MjData has no mass matrix yet (a kinetic
        # energy read before the first step): only then a whole mj_forward. (b32f saw the snowman demo
        # differ without it: that was the second, post-step _assign that 6626a36 removed, whose
        # mj_forward refreshed the mass matrix the kinetic energy after that step is read from.)
        if self._new_data:
            self._new_data = False
            mujoco.mj_forward(m, d)

    def _give_back(self, row: int) -> None:
        """Return a ragdoll's pool slot (command row ``row``): parked, asleep, free for the next one of its kind."""
        C = self._cmds
        if self.model is not None and self.data is not None and self._slot_table is not None:
            park(self.model, self.data, self._slot_table, int(C.pool[row]))
        self._pool.release(int(C.pool[row]))
        C.pool[row] = -1
        self._moved = True
