"""Linear blend skinning on the CPU: the reference the GPU skinning is checked against, and the
maths that carries an engine pose onto a glTF skin.

glTF's rule (spec §3.7.3): a vertex ``v`` of a skinned mesh lands at
``Σ_k w_k · G[j_k] · IBM[j_k] · v`` where ``G`` is the joint node's world matrix in the pose and
``IBM`` its inverse bind matrix. :func:`node_world_matrices` gives ``G`` for a file's own rest
pose or animation; :func:`bind_from_engine` gives per-joint constant matrices ``X`` such that
``E[j] · X[j]`` is the skinning matrix when the engine (FK of a clip made from the same file, in
metres, Y up, whatever units or up axis the file had) says joint ``j`` stands at ``E[j]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64
from engine.io.gltf import GltfAnimation, GltfAsset
from engine.io.gltf_clip import sample_channel
from engine.io.gltf_mesh import SkinnedMeshes
from engine.skeleton import Skeleton

__all__ = [
    "trs_matrices",
    "node_world_matrices",
    "skin_matrices",
    "blend_skin",
    "rigid_matrices",
    "fit_similarity",
    "bind_from_engine",
    "SkinBinding",
]


def trs_matrices(t: F64, r: F64, s: F64) -> F64:
    """``[N,4,4]`` matrices ``T·R·S`` from translations ``[N,3]``, w-first quaternions ``[N,4]``, scales ``[N,3]``."""
    n = len(t)
    m = np.zeros((n, 4, 4))
    m[:, :3, :3] = quat.to_matrix(r) * np.asarray(s, dtype=np.float64)[:, None, :]
    m[:, :3, 3] = t
    m[:, 3, 3] = 1.0
    return m


def rigid_matrices(positions: F64, rotations: F64) -> F64:
    """``[N,4,4]`` rigid transforms from world positions ``[N,3]`` and w-first rotations ``[N,4]``."""
    return trs_matrices(np.asarray(positions, dtype=np.float64), rotations, np.ones((len(positions), 3)))


def node_world_matrices(asset: GltfAsset, animation: GltfAnimation | None = None, time: float = 0.0) -> F64:
    """World matrix of every node ``[N,4,4]``, at rest or at ``time`` seconds of ``animation``."""
    t, r, s = asset.translation.copy(), asset.rotation.copy(), asset.scale.copy()
    if animation is not None:
        at = np.array([time], dtype=np.float64)
        for ch in animation.channels:
            target = {"translation": t, "rotation": r, "scale": s}.get(ch.path)
            if target is not None and 0 <= ch.node < asset.num_nodes:
                value = sample_channel(ch, at)[0]
                target[ch.node] = quat.normalize(value) if ch.path == "rotation" else value
    local = trs_matrices(t, r, s)
    world = np.empty_like(local)
    done = np.zeros(asset.num_nodes, dtype=bool)
    for start in range(asset.num_nodes):
        chain = []
        n = start
        while n >= 0 and not done[n]:
            chain.append(n)
            n = int(asset.parents[n])
        for node in reversed(chain):  # parents first
            p = int(asset.parents[node])
            world[node] = local[node] if p < 0 else world[p] @ local[node]
            done[node] = True
    return world


def skin_matrices(asset: GltfAsset, world: F64, skin: int = 0) -> F64:
    """The skin's joint matrices ``G[j] · IBM[j]``, ``[K,4,4]``."""
    sk = asset.skins[skin]
    return world[list(sk.joints)] @ sk.inverse_bind


def blend_skin(
    positions: NDArray[np.floating], joints: NDArray[np.integer], weights: NDArray[np.floating], matrices: F64
) -> F64:
    """Skinned positions ``[V,3]``: ``Σ_k w_k · M[j_k] · [p, 1]``, in double precision."""
    p = np.concatenate([np.asarray(positions, dtype=np.float64), np.ones((len(positions), 1))], axis=1)
    per_vertex = matrices[np.asarray(joints, dtype=np.int64)]
    blended = np.einsum("vk,vkij->vij", np.asarray(weights, dtype=np.float64), per_vertex)
    return np.einsum("vij,vj->vi", blended, p)[:, :3]


def fit_similarity(src: F64, dst: F64) -> F64:
    """The scale·rotation+translation ``[4,4]`` that best maps points ``src`` onto ``dst`` (Umeyama 1991).

    Used to find how the engine placed a file's skeleton (its unit and up axis) from the joint
    positions alone, so skinning does not depend on how the importer chose them.
    """
    src, dst = np.asarray(src, dtype=np.float64), np.asarray(dst, dtype=np.float64)
    mu_s, mu_d = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - mu_s, dst - mu_d
    var = float(np.sum(a * a)) / len(src)
    u, d, vt = np.linalg.svd(b.T @ a / len(src))
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    rot = u @ sign @ vt
    scale = float(np.trace(np.diag(d) @ sign)) / var if var > 0 else 1.0
    out = np.eye(4)
    out[:3, :3] = scale * rot
    out[:3, 3] = mu_d - scale * rot @ mu_s
    return out


def bind_from_engine(asset: GltfAsset, engine_rest: F64, joint_nodes: list[int], skin: int = 0) -> F64:
    """Constant ``X [K,4,4]`` with skinning matrix ``E[j] · X[j]`` for an engine pose ``E`` of the skin's joints.

    Args:
        engine_rest: ``[K,4,4]`` rigid world transforms the engine gives the skin's joints in the
            pose the file's nodes rest in (the same pose :func:`node_world_matrices` computes).
        joint_nodes: the node of each row of ``engine_rest`` — the skin's joints, in its order.

    ``C`` (glTF world → engine world: unit scale, up axis, placement) is fitted from the joints'
    rest positions; then ``X[j] = E_rest[j]⁻¹ · C · G_rest[j] · IBM[j]``, so at rest the skin
    lands exactly where the file's own skinning puts it, carried into the engine's world. A
    skin whose joints do not span a plane (fewer than three, or all in a line) cannot show its
    scale that way: ``C`` is then the rigid move of its first joint's frame.
    """
    g = node_world_matrices(asset)
    sk = asset.skins[skin]
    joints = list(sk.joints)
    if joints != list(joint_nodes):
        raise ValueError("engine_rest must list the skin's joints in the skin's order")
    points = g[joints, :3, 3]
    if len(joints) >= 3 and np.linalg.matrix_rank(points - points.mean(axis=0), tol=1e-9) >= 2:
        c = fit_similarity(points, engine_rest[:, :3, 3])
    else:
        first = g[joints[0]].copy()
        first[:3, :3] /= np.linalg.norm(first[:3, :3], axis=0)
        c = engine_rest[0] @ np.linalg.inv(first)
    return np.linalg.inv(engine_rest) @ c @ g[joints] @ sk.inverse_bind


@dataclass(frozen=True)
class SkinBinding:
    """A glTF skin driven by an engine skeleton made from the same file (matched by joint name).

    ``matrices(positions, rotations)`` turns the engine's FK output (world positions and
    rotations of its joints) into the skin's joint matrices. It rests on one property of
    the importers: an engine joint's world frame is the file's node frame turned by one
    rotation for the whole figure (the up axis), placed by one move, with lengths in one
    unit — so only the unit ``s`` and each node's own world scale stay between them:
    ``M[j] = E[j] · diag(s·S[j]) · IBM[j]`` (``S[j]`` the node's rest world scale). A skin
    joint the engine folded away (a static root) follows the nearest joint that stayed,
    rigidly, as it hangs from it in the file.
    """

    meshes: SkinnedMeshes
    drivers: NDArray[np.int64]
    offsets: F64

    @classmethod
    def bind(cls, asset: GltfAsset, meshes: SkinnedMeshes, skeleton: Skeleton) -> SkinBinding:
        """Match ``asset``'s skin to ``skeleton`` by joint names; ``ValueError`` naming what is missing."""
        skin = asset.skins[meshes.skin]
        nodes = list(skin.joints)
        index = {name: k for k, name in enumerate(skeleton.names)}
        engine = {n: index[asset.names[n]] for n in nodes if asset.names[n] in index}
        used = {nodes[int(j)] for p in meshes.primitives for j in np.unique(p.joints[p.weights > 0.0])}
        if 2 * len(used & set(engine)) < len(used):
            missing = sorted(asset.names[n] for n in used - set(engine))
            raise ValueError(
                f"the skeleton shares too few joints with the skin to drive it (missing: "
                f"{', '.join(missing[:6])}{'…' if len(missing) > 6 else ''})"
            )
        world = node_world_matrices(asset)
        rigid = world.copy()
        rigid[:, :3, :3] /= np.linalg.norm(world[:, :3, :3], axis=1, keepdims=True)
        unit = _unit(asset, skeleton, engine, world)
        drivers = np.empty(len(nodes), dtype=np.int64)
        offsets = np.empty((len(nodes), 4, 4))
        for row, node in enumerate(nodes):
            anchor = node if node in engine else _nearest(asset, node, set(engine))
            own = np.linalg.inv(rigid[node]) @ world[node]  # the node's world scale, [S 0; 0 1]
            own[:3, :3] *= unit
            hang = np.linalg.inv(rigid[anchor]) @ rigid[node]
            hang[:3, 3] *= unit
            drivers[row] = engine[anchor]
            offsets[row] = hang @ own @ skin.inverse_bind[row]
        return cls(meshes, drivers, offsets)

    def matrices(self, positions: F64, rotations: F64) -> F64:
        """Skin joint matrices ``[K,4,4]`` for engine world ``positions [J,3]`` and ``rotations [J,4]``."""
        return rigid_matrices(positions[self.drivers], rotations[self.drivers]) @ self.offsets


def _unit(asset: GltfAsset, skeleton: Skeleton, engine: dict[int, int], world: F64) -> float:
    """Engine length per file length: the median ratio of the bones both hold."""
    ratios = []
    node_of = {k: n for n, k in engine.items()}
    for k, parent in enumerate(skeleton.parents):
        if parent < 0 or k not in node_of or int(parent) not in node_of:
            continue
        in_file = float(np.linalg.norm(world[node_of[k], :3, 3] - world[node_of[int(parent)], :3, 3]))
        if in_file > 1e-9:
            ratios.append(float(np.linalg.norm(skeleton.offsets[k])) / in_file)
    if not ratios:
        raise ValueError("the skeleton and the skin share no bone to measure the unit by")
    return float(np.median(ratios))


def _nearest(asset: GltfAsset, node: int, kept: set[int]) -> int:
    """The closest node in ``kept`` up the parent chain, else the first found below ``node``."""
    n = int(asset.parents[node])
    while n >= 0:
        if n in kept:
            return n
        n = int(asset.parents[n])
    frontier = [node]
    while frontier:
        children = [c for c in range(asset.num_nodes) if int(asset.parents[c]) in frontier]
        for c in children:
            if c in kept:
                return c
        frontier = children
    raise ValueError(f"skin joint {asset.names[node]!r} has no driven joint above or below it")
