"""Humanoid roles from a skeleton's shape, for rigs whose joint names follow no known family.

:func:`~engine.io.joint_maps.guess_joint_map` reads names (Mixamo, Biovision, …). Characters
from other tools (CesiumMan's ``leg_joint_L_2``, a scanned rig's ``joint17``) need what an
engine's humanoid auto-mapper does: find the roles by the figure's structure in a pose where
it stands.

- **Up** is Y, or Z when the figure is no standing humanoid with Y up; the height is the leaves'
  spread along it.
- **Legs** end in the lowest leaf and the lowest leaf of another branch beside it; the **hips**
  are where their two paths meet. **Arms** end in the two leaves furthest to the sides; the
  **chest** is where they meet. The **head** is the highest leaf's branch above the chest.
- Along a limb the upper and lower bones are the two consecutive bones that are longest
  together (a clavicle or a hip helper before them is short); the joint after them is the
  hand or the foot.
- **Left** is ``up × forward``, forward being where the planted foot's toes point (the figure's
  +Z, or -Y when Z is up, where a foot has no toe joint).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64
from engine.fk import forward_kinematics
from engine.io.joint_maps import guess_joint_map

if TYPE_CHECKING:
    from engine.clip import Clip

__all__ = ["guess_roles_by_shape", "guess_clip_joint_map"]


def _children(parents: NDArray[np.int64]) -> list[list[int]]:
    kids: list[list[int]] = [[] for _ in parents]
    for j, p in enumerate(parents):
        if p >= 0:
            kids[int(p)].append(j)
    return kids


def _path_up(parents: NDArray[np.int64], j: int) -> list[int]:
    """``j`` and its ancestors, up to the root."""
    out = [j]
    while parents[out[-1]] >= 0:
        out.append(int(parents[out[-1]]))
    return out


def _meet(parents: NDArray[np.int64], a: int, b: int) -> int:
    """The lowest common ancestor of ``a`` and ``b``."""
    above_a = set(_path_up(parents, a))
    return next(j for j in _path_up(parents, b) if j in above_a)


def _chain(parents: NDArray[np.int64], top: int, leaf: int) -> list[int]:
    """Joints from ``top``'s child towards ``leaf``, ``leaf`` included."""
    path = _path_up(parents, leaf)
    return list(reversed(path[: path.index(top)]))


def _limb(chain: list[int], pos: F64) -> tuple[int, int, int] | None:
    """(upper, lower, end) of a limb chain: the two consecutive bones longest together, and the joint after them."""
    if len(chain) < 3:
        return None
    seg = np.linalg.norm(np.diff(pos[chain], axis=0), axis=1)
    i = int(np.argmax(seg[:-1] + seg[1:]))
    return chain[i], chain[i + 1], chain[i + 2]


def guess_roles_by_shape(
    names: tuple[str, ...] | list[str], parents: NDArray[np.int64], positions: F64
) -> dict[str, str]:
    """Puppet role → joint name, from world ``positions [J,3]`` of a pose where the figure stands.

    Y up is tried first, then Z up; the first under which the shape is a standing humanoid wins.

    Raises:
        ValueError: under neither is it one (a hand, a tail, a four-legged animal), in one line.
    """
    parents = np.asarray(parents, dtype=np.int64)
    pos = np.asarray(positions, dtype=np.float64)
    kids = _children(parents)
    leaves = [j for j in range(len(parents)) if not kids[j]]
    if len(leaves) < 3:
        raise ValueError(f"a skeleton of {len(leaves)} branch ends has no two legs and a body to map")
    try:
        return _roles(names, parents, pos, kids, leaves, up_axis=1)
    except ValueError as y_up:
        try:
            return _roles(names, parents, pos, kids, leaves, up_axis=2)
        except ValueError:
            raise y_up from None


def _roles(
    names: tuple[str, ...] | list[str],
    parents: NDArray[np.int64],
    pos: F64,
    kids: list[list[int]],
    leaves: list[int],
    up_axis: int,
) -> dict[str, str]:
    height = float(np.ptp(pos[leaves, up_axis]))
    if height <= 0.0:
        raise ValueError("the skeleton is flat: no joint stands above another")
    across = max(float(np.ptp(pos[:, a])) for a in (0, 1, 2) if a != up_axis)
    if height < 0.6 * across:  # even arms spread in a T-pose span about the height
        raise ValueError(
            f"the figure is {across / height:.1f} times wider or longer than tall: not a standing humanoid"
        )
    h = pos[:, up_axis] - pos[leaves, up_axis].min()
    by_height = sorted(leaves, key=lambda j: h[j])
    first = by_height[0]
    # The other leg: the lowest leaf whose paths meet the first one's well above the ground.
    other = next((j for j in by_height[1:] if h[_meet(parents, first, j)] > 0.3 * height), None)
    if other is None or h[other] > 0.25 * height:  # a foot in a stride's swing rises, a tail hangs higher
        raise ValueError("no two legs stand on the ground and meet at hips: not a standing humanoid")
    hips = _meet(parents, first, other)
    leg0, leg1 = (_limb(_chain(parents, hips, leaf), pos) for leaf in (first, other))
    if leg0 is None or leg1 is None:
        raise ValueError("a leg has fewer than three joints below the hips (upper leg, lower leg, foot)")
    legs = [leg0, leg1]
    leg_roots = {_chain(parents, hips, leaf)[0] for leaf in (first, other)}
    on_ground = [j for j in by_height[2:] if h[j] < 0.15 * height and not leg_roots & set(_path_up(parents, j))]
    if on_ground:
        raise ValueError(
            f"{len(on_ground) + 2} limbs reach the ground ({names[on_ground[0]]!r} besides the legs): "
            f"not a standing humanoid"
        )
    if leg_roots & set(_path_up(parents, by_height[-1])):
        raise ValueError("the highest branch end is on a leg: not a standing humanoid")
    up = np.zeros(3)
    up[up_axis] = 1.0
    forward = _forward(pos, kids, [legs[0][2], legs[1][2]], up_axis)
    left = np.cross(up, forward)
    side = (pos - pos[hips]) @ left
    roles: dict[str, str] = {"hips": names[hips]}
    for leg in legs:
        prefix = "l" if side[leg[2]] > 0 else "r"
        for role, j in zip(("upper_leg", "lower_leg", "foot"), leg):
            roles[f"{prefix}_{role}"] = names[j]
    if "l_foot" not in roles or "r_foot" not in roles:
        raise ValueError("both legs lie on one side of the hips: left and right cannot be told apart")
    _upper_body(names, parents, pos, kids, hips, leg_roots, h, side, roles)
    return roles


def _forward(pos: F64, kids: list[list[int]], feet: list[int], up_axis: int) -> F64:
    """Where the planted (lower) foot's toes point, horizontally; else the file convention's front.

    Only the lower foot counts: a foot in the air is pitched, and in a walk's swing its toes
    can point back."""
    planted = min(feet, key=lambda f: pos[f, up_axis])
    direction = pos[kids[planted][0]] - pos[planted] if kids[planted] else np.zeros(3)
    direction[up_axis] = 0.0
    if np.linalg.norm(direction) < 1e-9:
        direction = np.array([0.0, 0.0, 1.0]) if up_axis == 1 else np.array([0.0, -1.0, 0.0])
    return direction / np.linalg.norm(direction)


def _upper_body(
    names: tuple[str, ...] | list[str],
    parents: NDArray[np.int64],
    pos: F64,
    kids: list[list[int]],
    hips: int,
    leg_roots: set[int],
    h: F64,
    side: F64,
    roles: dict[str, str],
) -> None:
    """Spine, chest, neck, head and arms, where the shape has them (a legs-only rig keeps the legs).

    The upper body's branch ends are every leaf under the hips but the legs' (hands hang below
    the hips in an A-pose, so height does not tell them)."""
    upper = []
    stack = [k for k in kids[hips] if k not in leg_roots]
    while stack:
        j = stack.pop()
        if kids[j]:
            stack.extend(kids[j])
        else:
            upper.append(j)
    if len(upper) < 3:
        return
    hands = (max(upper, key=lambda j: side[j]), min(upper, key=lambda j: side[j]))
    if side[hands[0]] <= 0 or side[hands[1]] >= 0:
        return
    chest = _meet(parents, *hands)
    if chest == hips:
        return
    roles["chest"] = names[chest]
    between = _chain(parents, hips, chest)[:-1]
    if between:
        roles["spine"] = names[between[len(between) // 2]]
    for prefix, leaf in zip(("l", "r"), hands):
        arm = _limb(_chain(parents, chest, leaf), pos)
        if arm is not None:
            for role, j in zip(("upper_arm", "lower_arm", "hand"), arm):
                roles[f"{prefix}_{role}"] = names[j]
    arm_joints = {j for leaf in hands for j in _chain(parents, chest, leaf)}
    above = [j for j in upper if j not in arm_joints and chest in _path_up(parents, j)]
    if above:
        top = max(above, key=lambda j: h[j])
        neck_chain = _chain(parents, chest, top)
        roles["neck"] = names[neck_chain[0]]
        roles["head"] = names[neck_chain[1] if len(neck_chain) > 1 else neck_chain[0]]


def guess_clip_joint_map(clip: Clip) -> tuple[str, dict[str, str], dict[str, str]]:
    """``(family, joint map, aims)`` of a clip's skeleton: by its names, else by its shape in frame 0.

    The family is ``"shape"`` when the names fit no family. ``ValueError`` says why both failed.
    """
    try:
        return guess_joint_map(clip.skeleton.names)
    except ValueError as by_name:
        offsets = None if clip.translations is None else clip.translations[0]
        first, _ = forward_kinematics(clip.skeleton, clip.root[0], clip.rotations[0], offsets)
        try:
            return "shape", guess_roles_by_shape(clip.skeleton.names, clip.skeleton.parents, first), {}
        except ValueError as by_shape:
            raise ValueError(f"{by_name}; nor by its shape: {by_shape}") from None
