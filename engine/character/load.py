"""Open a rigged ``.glb`` humanoid as a puppet character: roles, rig, skin binding, one warning.

The one validation boundary for ``--character FILE``: the file is read by the glTF readers
(every count and index checked there), its skin's joints are given the puppet's roles — by a
user's ``--joint-map``, else by their names (:func:`engine.io.joint_maps.guess_joint_map`),
else by the figure's shape (:func:`engine.io.joint_shape.guess_roles_by_shape`) — and anything
that keeps it from standing in for the puppet is refused in one line that names the roles
missing and how to give them. What is only not drawn (morph targets, a second weight set)
comes back in :attr:`Character.ignored` for the caller to say once.

A character is built from its bytes alone (:func:`character_from_bytes`), so a recording that
carries them rebuilds the same puppet wherever the file went.
"""

from __future__ import annotations

import hashlib
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64
from engine.character.rig import CharacterRig, RigError, build_rig
from engine.fk import forward_kinematics
from engine.humanoid import JOINTS
from engine.io.gltf import GltfAsset, GltfError, read_gltf
from engine.io.gltf_mesh import SkinnedMeshes, read_skinned_meshes
from engine.io.joint_maps import JOINT_MAPS, guess_joint_map, resolve_joint_map
from engine.io.joint_shape import guess_roles_by_shape
from engine.skinning import SkinBinding, blend_skin, node_world_matrices, rigid_matrices, skin_matrices

__all__ = ["Character", "CharacterError", "character_from_bytes", "read_character", "MAX_CHARACTER"]

MAX_CHARACTER = 8 << 20
"""Bytes of a character file a recording carries (CesiumMan is 0.5 MB; its header's limit is 16 MB)."""

_HOW = (
    'map its joints to the puppet\'s roles in a JSON file {"file joint": "puppet role", …} and pass '
    f"--joint-map FILE (roles: {', '.join(JOINTS)})"
)


class CharacterError(ValueError):
    """A file that cannot be the puppet: not a skinned glTF, or no humanoid the roles fit."""


@dataclass(frozen=True)
class Character:
    """A skinned humanoid ready to be a puppet.

    Attributes:
        name: the file's name without its suffix.
        digest: SHA-256 of the file's bytes (the key of its measured lookup table).
        rig: the puppet skeleton with the character's proportions (:mod:`engine.character.rig`).
        binding: the skin driven by that skeleton's FK (``binding.matrices(pos, rot)``).
        roles: puppet role → the file's joint name.
        ignored: what of the file is not drawn (morph targets…), for one warning.
    """

    name: str
    digest: str
    rig: CharacterRig
    binding: SkinBinding
    roles: dict[str, str]
    ignored: tuple[str, ...]

    @property
    def library_key(self) -> str:
        """The name of its locomotion set in the :class:`~engine.blend.locomotion.BlendLibrary`."""
        return f"character:{self.digest[:16]}"


def read_character(path: str | Path, joint_map: dict[str, str] | None = None) -> tuple[Character, bytes]:
    """The character of a ``.glb`` file and the bytes it was built from (what a recording carries).

    Args:
        joint_map: puppet role → file joint name (``engine.io.motion_file.load_joint_map``).

    Raises:
        CharacterError: not a ``.glb``, too big to carry, or refused by :func:`character_from_bytes`.
    """
    path = Path(path)
    if path.suffix.lower() != ".glb":
        raise CharacterError(
            f"{path}: a character is one .glb file (a .gltf's outside buffers and "
            f"images cannot travel in a recording); export it as .glb"
        )
    try:
        size = path.stat().st_size
        if size > MAX_CHARACTER:
            raise CharacterError(f"{path}: {size >> 20} MB; a character is at most {MAX_CHARACTER >> 20} MB")
        data = path.read_bytes()
    except OSError as exc:
        raise CharacterError(f"{path}: cannot read: {exc.strerror}") from None
    return character_from_bytes(data, path.stem, joint_map), data


def character_from_bytes(data: bytes, name: str, joint_map: dict[str, str] | None = None) -> Character:
    """Build the character from a ``.glb``'s bytes (see the module docstring).

    Raises:
        CharacterError: in one line, naming the file ``name``.
    """
    if len(data) > MAX_CHARACTER:
        raise CharacterError(f"{name}: {len(data) >> 20} MB; a character is at most {MAX_CHARACTER >> 20} MB")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "character.glb"
        path.write_bytes(data)
        try:
            asset, meshes = read_gltf(path), read_skinned_meshes(path)
        except GltfError as exc:
            raise CharacterError(f"{name}: {str(exc).replace(str(path), 'the file')}") from None
    try:
        return _build(asset, meshes, name, hashlib.sha256(data).hexdigest(), joint_map)
    except (RigError, ValueError) as exc:
        if isinstance(exc, CharacterError):
            raise
        raise CharacterError(f"{name}: {exc}") from None


def _roles(
    asset: GltfAsset,
    names: list[str],
    parents: NDArray[np.int64],
    rest: F64,
    joint_map: dict[str, str] | None,
    name: str,
) -> dict[str, str]:
    """Puppet role → joint name, all 17 of them, or a refusal saying which are missing and how to map them."""
    if joint_map is not None:
        unknown = sorted(set(joint_map.values()) - set(names))
        if unknown:
            raise CharacterError(f"{name}: the joint map names joints the skin does not have: {', '.join(unknown)}")
        roles = dict(joint_map)
    else:
        try:
            _, roles, _ = guess_joint_map(names)
        except ValueError:
            try:
                roles = guess_roles_by_shape(names, parents, rest)
            except ValueError as by_shape:
                best = max((resolve_joint_map(c, names) for c in JOINT_MAPS.values()), key=len)
                missing = [r for r in JOINTS if r not in best]
                shown = ", ".join(names[:4]) + (", …" if len(names) > 4 else "")
                raise CharacterError(
                    f"{name}: not a humanoid the puppet can be: its joint names ({shown}) follow none of the "
                    f"known families ({', '.join(JOINT_MAPS)}), leaving {_count(missing)} without a joint, and by "
                    f"its shape {by_shape}; if it is a humanoid, {_HOW}"
                ) from None
    missing = [r for r in JOINTS if r not in roles]
    if missing:
        raise CharacterError(f"{name}: {_count(missing)} without a joint; {_HOW}")
    return roles


def _count(missing: list[str]) -> str:
    """``"all 17 roles"`` or ``"the roles neck, head"``."""
    return f"all {len(JOINTS)} roles" if len(missing) == len(JOINTS) else f"the roles {', '.join(missing)}"


def _skin_tree(asset: GltfAsset, nodes: list[int]) -> NDArray[np.int64]:
    """Parent of each skin joint among the skin's joints (``-1`` above them)."""
    out = []
    for n in nodes:
        p = int(asset.parents[n])
        while p >= 0 and p not in nodes:
            p = int(asset.parents[p])
        out.append(nodes.index(p) if p >= 0 else -1)
    return np.array(out, dtype=np.int64)


def _drivers(tree: NDArray[np.int64], role_of: dict[int, int]) -> NDArray[np.int64]:
    """The puppet joint moving each skin joint: its own role, else its nearest ancestor's, else the hips."""
    out = np.zeros(len(tree), dtype=np.int64)
    for k in range(len(tree)):
        j = k
        while j >= 0 and j not in role_of:
            j = int(tree[j])
        out[k] = role_of[j] if j >= 0 else 0
    return out


def _segment_distance(points: F64, a: F64, b: F64) -> F64:
    ab = b - a
    t = np.clip((points - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def _build(
    asset: GltfAsset, meshes: SkinnedMeshes, name: str, digest: str, joint_map: dict[str, str] | None
) -> Character:
    skin = asset.skins[meshes.skin]
    nodes = list(skin.joints)
    names = [asset.names[n] for n in nodes]
    world = node_world_matrices(asset)
    rest = world[nodes, :3, 3]
    tree = _skin_tree(asset, nodes)
    roles = _roles(asset, names, tree, rest, joint_map, name)
    row_of = {names[k]: k for k in range(len(nodes))}
    role_of = {row_of[roles[r]]: JOINTS.index(r) for r in JOINTS}
    drivers = _drivers(tree, role_of)
    # The mesh in the file's rest pose, and which puppet joint mostly moves each vertex.
    mats = skin_matrices(asset, world, meshes.skin)
    verts = np.concatenate([blend_skin(p.positions, p.joints, p.weights, mats) for p in meshes.primitives])
    owner = np.concatenate(
        [drivers[p.joints[np.arange(len(p.joints)), np.argmax(p.weights, axis=1)]] for p in meshes.primitives]
    )
    positions = {r: rest[row_of[roles[r]]] for r in JOINTS}
    floor = float(verts[:, 1].min())
    rig0 = build_rig(positions, floor)
    v = verts @ rig0.to_engine[:3, :3].T + rig0.to_engine[:3, 3]
    p = rig0.rest_positions
    sizes = {"head": float(v[:, 1].max() - p[JOINTS.index("head"), 1])}
    hands = [v[owner == JOINTS.index(f"{s}_hand")] for s in "lr"]
    if all(len(h) for h in hands):
        sizes["hand"] = float(
            np.mean([np.linalg.norm(h - p[JOINTS.index(f"{s}_hand")], axis=1).max() for h, s in zip(hands, "lr")])
        )
    feet = [v[owner == JOINTS.index(f"{s}_foot")] for s in "lr"]
    if all(len(f) for f in feet):
        sizes["toe"] = 0.9 * float(
            np.mean([(f[:, 2] - p[JOINTS.index(f"{s}_foot"), 2]).max() for f, s in zip(feet, "lr")])
        )
    radii = {}
    base = rig0.skeleton
    for j, role in enumerate(JOINTS):
        mine = v[owner == j]
        if len(mine) < 8:
            continue
        kids = base.children(j)
        end = p[kids[0]] if kids else p[j] + quat.rotate(quat.IDENTITY, base.tips[j])
        r = float(np.median(_segment_distance(mine, p[j], end)))
        radii[role] = float(np.clip(r, 0.4 * base.radii[j], 2.5 * base.radii[j]))
    rig = build_rig(positions, floor, sizes, radii)
    pos, rot = forward_kinematics(rig.skeleton, rig.skeleton.offsets[0], rig.rest_local)
    engine_rest = rigid_matrices(pos, rot)
    offsets = np.linalg.inv(engine_rest[drivers]) @ rig.to_engine @ world[nodes] @ skin.inverse_bind
    binding = SkinBinding(meshes, drivers, offsets)
    return Character(name, digest, rig, binding, dict(roles), meshes.ignored)
