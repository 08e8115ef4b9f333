"""Index arrays over *all* ragdolls of a compiled model, so control and readback are batched.

Every ragdoll's joints are laid end to end in one flat joint list (ragdolls in key
order, joints in skeleton order). The layout maps that flat list to MuJoCo addresses:
ball joints (qpos/dof/ctrl addresses, twist axes and limits), hinges (axes), servo
actuators with their full-strength gains, bodies, geoms, pins and holds. Setting the
targets of ten ragdolls is then a handful of numpy calls, not ten Python loops.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as F
from engine.arrays import I64 as I
from engine.ragdoll.mjcf import RagdollFragment, RagdollSpec, rd_name

__all__ = ["Layout", "bone_axes", "build_layout"]


@dataclass
class Layout:
    """Flat index arrays; ``*_owner`` gives the ragdoll ordinal, ``*_src`` the flat joint index."""

    keys: list[int]
    starts: I  # [P+1] flat joint offset of each ragdoll
    root_q: I
    root_d: I
    dofs: I  # [P,2] dof range per ragdoll
    ball_src: I
    ball_owner: I
    ball_q: I
    ball_d: I
    ball_c: I
    ball_axis: F  # bone direction (twist axis) in the joint frame
    ball_twist: F
    ball_cone: F
    hinge_src: I
    hinge_owner: I
    hinge_q: I
    hinge_d: I
    hinge_c: I
    hinge_axis: F
    hinge_range: F
    act: I  # actuator ids, balls then hinges
    act_owner: I
    act_kp: F
    act_kv: F
    body: I  # [ΣJ] body id per flat joint
    body_owner: I
    geom: I
    geom_owner: I
    pin_eq: I
    pin_mocap: I
    hold_mocap: I
    ball_lead: F  # kv/kp at full muscle: how far each servo trails a moving target (s)
    hinge_lead: F
    hold_eqs: I  # every hold constraint's id, ragdoll by ragdoll (switched off together, the held one back on)
    hold_eqs_owner: I
    hold_eq: list[dict[str, int]]
    hold_joint: list[dict[str, int]]  # holdable joint name -> its index in the ragdoll's skeleton
    # per owner group (``_GROUPS``), each ragdoll's rows: what :func:`select` gathers (a pool's layout
    # only; ``None`` in a selected one, which nothing selects from)
    rows_of: dict[str, list[I]] | None = field(default=None, init=False, repr=False)

    def ordinal(self, key: int) -> int:
        """Position of ragdoll ``key`` in the flat layout."""
        return self.keys.index(key)

    @property
    def num_ragdolls(self) -> int:
        """Number of ragdolls ``P``."""
        return len(self.keys)


def bone_axes(spec: RagdollSpec) -> F:
    """Unit bone direction of every joint in its own frame (to the first child or the tip)."""
    sk = spec.skeleton
    ends = np.array(sk.tips, dtype=np.float64)
    for j in range(sk.num_joints):
        kids = sk.children(j)
        if kids:
            ends[j] = spec.offsets[kids[0]]
    n = np.linalg.norm(ends, axis=1, keepdims=True)
    return np.where(n > 1e-9, ends / np.where(n > 1e-9, n, 1.0), [0.0, 1.0, 0.0])


def build_layout(m: mujoco.MjModel, fragments: list[RagdollFragment]) -> Layout:
    """The flat layout of the rendered ragdolls (in the order given) inside compiled model ``m``."""
    acc: dict[str, list[np.ndarray]] = {}

    def put(name: str, value: np.ndarray | list[float] | list[int] | float) -> None:
        acc.setdefault(name, []).append(np.atleast_1d(np.asarray(value)))

    starts = [0]
    hold_eq = []
    hold_joint = []
    for p, frag in enumerate(fragments):
        spec = frag.spec
        sk, pr, k = spec.skeleton, spec.profile, spec.key
        names = [rd_name(k, n) for n in sk.names]
        jid = np.array([m.joint(n).id for n in names])
        kinds = np.array(pr.kinds)
        ball, hinge = np.nonzero(kinds == "ball")[0], np.nonzero(kinds == "hinge")[0]
        base = starts[-1]
        axes = bone_axes(spec)
        kp, kv = frag.kp, frag.kv
        act = np.array([m.actuator(names[j]).id for j in np.concatenate([ball, hinge])], dtype=np.int64)
        rq, rd = int(m.jnt_qposadr[jid[0]]), int(m.jnt_dofadr[jid[0]])
        put("root_q", rq)
        put("root_d", rd)
        put("dofs", np.array([[rd, rd + 6 + 3 * len(ball) + len(hinge)]]))
        put("ball_src", base + ball)
        put("ball_owner", np.full(len(ball), p))
        put("ball_q", m.jnt_qposadr[jid[ball]])
        put("ball_d", m.jnt_dofadr[jid[ball]])
        put("ball_c", m.actuator_ctrladr[act[: len(ball)]])
        put("ball_axis", axes[ball].reshape(-1, 3))
        put("ball_twist", pr.twist[ball])
        put("ball_cone", pr.cone[ball])
        put("hinge_src", base + hinge)
        put("hinge_owner", np.full(len(hinge), p))
        put("hinge_q", m.jnt_qposadr[jid[hinge]])
        put("hinge_d", m.jnt_dofadr[jid[hinge]])
        put("hinge_c", m.actuator_ctrladr[act[len(ball) :]])
        put("hinge_axis", pr.hinge_axis[hinge].reshape(-1, 3))
        put("hinge_range", pr.hinge_range[hinge].reshape(-1, 2))
        put("act", act)
        put("act_owner", np.full(len(act), p))
        put("act_kp", kp[np.concatenate([ball, hinge])])
        put("act_kv", kv[np.concatenate([ball, hinge])])
        put("body", np.array([m.body(n).id for n in names]))
        put("body_owner", np.full(len(names), p))
        put("geom", np.array([m.geom(n).id for n in names]))
        put("geom_owner", np.full(len(names), p))
        put("pin_eq", m.eq(rd_name(k, "pin")).id)
        put("pin_mocap", int(m.body_mocapid[m.body(rd_name(k, "pin")).id]))
        put("hold_mocap", int(m.body_mocapid[m.body(rd_name(k, "hold")).id]))
        lead = kv / np.where(kp > 0, kp, 1.0)
        put("ball_lead", lead[ball])
        put("hinge_lead", lead[hinge])
        hold_eq.append({h: m.eq(rd_name(k, h) + "_hold").id for h in pr.holdable})
        put("hold_eqs", np.array(list(hold_eq[-1].values()), dtype=np.int64))
        put("hold_eqs_owner", np.full(len(hold_eq[-1]), p))
        hold_joint.append({h: sk.index(h) for h in pr.holdable})
        starts.append(base + sk.num_joints)

    def cat(name: str, dtype: type, shape: tuple[int, ...] = ()) -> np.ndarray:
        parts = acc.get(name, [])
        if not parts:
            return np.zeros((0, *shape), dtype=dtype)
        return np.concatenate(parts).astype(dtype).reshape(-1, *shape) if shape else np.concatenate(parts).astype(dtype)

    ints = (
        "root_q",
        "root_d",
        "ball_src",
        "ball_owner",
        "ball_q",
        "ball_d",
        "ball_c",
        "hinge_src",
        "hinge_owner",
        "hinge_q",
        "hinge_d",
        "hinge_c",
        "act",
        "act_owner",
        "body",
        "body_owner",
        "geom",
        "geom_owner",
        "pin_eq",
        "pin_mocap",
        "hold_mocap",
        "hold_eqs",
        "hold_eqs_owner",
    )
    floats = ("ball_twist", "ball_cone", "act_kp", "act_kv", "ball_lead", "hinge_lead")
    layout = Layout(
        keys=[f.spec.key for f in fragments],
        starts=np.array(starts, dtype=np.int64),
        dofs=cat("dofs", np.int64, (2,)),
        ball_axis=cat("ball_axis", np.float64, (3,)),
        hinge_axis=cat("hinge_axis", np.float64, (3,)),
        hinge_range=cat("hinge_range", np.float64, (2,)),
        hold_eq=hold_eq,
        hold_joint=hold_joint,
        **{n: cat(n, np.int64) for n in ints},
        **{n: cat(n, np.float64) for n in floats},
    )
    ragdolls = np.arange(len(fragments))
    layout.rows_of = {}
    for owner in _GROUPS:
        own = getattr(layout, owner)
        lo, hi = np.searchsorted(own, ragdolls, "left"), np.searchsorted(own, ragdolls, "right")
        layout.rows_of[owner] = [np.arange(a, b, dtype=np.int64) for a, b in zip(lo.tolist(), hi.tolist(), strict=True)]
    return layout


_PER_RAGDOLL = ("root_q", "root_d", "dofs", "pin_eq", "pin_mocap", "hold_mocap")
_GROUPS = {  # owner array -> the arrays laid out by it (and which of them index flat joints)
    "ball_owner": ("ball_src", "ball_q", "ball_d", "ball_c", "ball_axis", "ball_twist", "ball_cone", "ball_lead"),
    "hinge_owner": ("hinge_src", "hinge_q", "hinge_d", "hinge_c", "hinge_axis", "hinge_range", "hinge_lead"),
    "act_owner": ("act", "act_kp", "act_kv"),
    "body_owner": ("body",),
    "geom_owner": ("geom",),
    "hold_eqs_owner": ("hold_eqs",),
}


def select(pool: Layout, slots: list[int], keys: list[int]) -> Layout:
    """The layout of some ragdolls of a pool (``slots``, lent to puppets ``keys`` in that order):
    the same flat arrays restricted to them, owners and flat joint indices renumbered."""
    idx = np.asarray(slots, dtype=np.int64)
    sizes = np.diff(pool.starts)[idx]
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    fields: dict[str, NDArray[Any]] = {n: getattr(pool, n)[idx] for n in _PER_RAGDOLL}  # int and float arrays
    assert pool.rows_of is not None, "select from a pool's layout (build_layout), not a selected one"
    for owner, names in _GROUPS.items():
        parts = [pool.rows_of[owner][s] for s in slots]
        rows = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
        new_owner = np.repeat(np.arange(len(idx)), list(map(len, parts)))
        fields[owner] = new_owner
        for n in names:
            fields[n] = getattr(pool, n)[rows]
        if owner in ("ball_owner", "hinge_owner"):
            src = names[0]
            fields[src] = fields[src] - pool.starts[idx][new_owner] + starts[new_owner]
    return Layout(
        keys=list(keys),
        starts=starts,
        hold_eq=[pool.hold_eq[i] for i in slots],
        hold_joint=[pool.hold_joint[i] for i in slots],
        **fields,
    )
