"""glTF skins and animations as engine skeletons and clips.

A skin's joints become a :class:`~engine.skeleton.Skeleton` in topological order. The rest
transform of the nodes above the skin's root (Khronos samples put a ``Z_UP`` matrix and an
``Armature`` there) is baked into joint 0, so the clip is in glTF world space: Y up,
metres. Rest scales are baked into the bone offsets; *animated* scale has no place in a
rotation clip and is dropped. Each animation is sampled (LINEAR by slerp/lerp, STEP,
CUBICSPLINE by Hermite) at a fixed frame rate; a static root above moving hips (Fox's
``_rootJoint``/``b_Root_00``) is folded so the hips' travel moves the clip.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.clip import Clip
from engine.io._tracks import fold_root
from engine.io.gltf import GltfAnimation, GltfAsset, GltfChannel, GltfError, read_gltf
from engine.skeleton import Skeleton

__all__ = ["sample_channel", "skin_nodes", "gltf_skeleton", "gltf_clip", "load_gltf_clips"]

MAX_FPS = 1000.0
MAX_SAMPLES = 4_000_000  # frames x nodes: an hour at 60 fps of an 18-node skeleton

F64 = NDArray[np.float64]


def sample_channel(channel: GltfChannel, t: NDArray[np.float64]) -> F64:
    """Values of ``channel`` at times ``t`` (clamped outside the keys), ``[T, n]``."""
    times, k = channel.times, len(channel.times)
    vals = channel.values.reshape(k, 3, -1) if channel.interpolation == "CUBICSPLINE" else channel.values
    point = vals[:, 1] if channel.interpolation == "CUBICSPLINE" else vals
    t = np.asarray(t, dtype=np.float64)
    if k == 1:
        return np.repeat(point[:1], len(t), axis=0)
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, k - 2)
    dt = times[i + 1] - times[i]
    u = np.clip((t - times[i]) / np.where(dt > 0, dt, 1.0), 0.0, 1.0)
    rotation = channel.path == "rotation"
    if channel.interpolation == "STEP":
        out = point[np.where(u >= 1.0, i + 1, i)]
    elif channel.interpolation == "CUBICSPLINE":
        u2, u3 = u * u, u * u * u
        h = [2 * u3 - 3 * u2 + 1, (u3 - 2 * u2 + u) * dt, -2 * u3 + 3 * u2, (u3 - u2) * dt]
        out = (h[0][:, None] * vals[i, 1] + h[1][:, None] * vals[i, 2]
               + h[2][:, None] * vals[i + 1, 1] + h[3][:, None] * vals[i + 1, 0])
    elif rotation:
        out = quat.slerp(point[i], point[i + 1], u)
    else:
        out = point[i] + u[:, None] * (point[i + 1] - point[i])
    return quat.normalize(out) if rotation else out


def skin_nodes(asset: GltfAsset, skin: int = 0) -> list[int]:
    """Node indices of a skin's joints in depth-first order under one root.

    Joints whose nearest joint ancestor is missing are roots; when there are several, the
    nodes on the way up to their lowest common ancestor join the skeleton.
    """
    try:
        joints = set(asset.skins[skin].joints)
    except IndexError:
        raise GltfError(f"{asset.source}: no skin {skin} (the file has {len(asset.skins)})") from None
    if not joints:
        raise GltfError(f"{asset.source}: skin {skin} has no joints")

    def ancestors(n: int) -> list[int]:
        out = []
        while n >= 0:
            out.append(n)
            n = int(asset.parents[n])
        return out

    roots = [j for j in joints if not any(a in joints for a in ancestors(j)[1:])]
    if len(roots) > 1:
        common = set(ancestors(roots[0]))
        for r in roots[1:]:
            common &= set(ancestors(r))
        if not common:
            raise GltfError(f"{asset.source}: skin {skin}'s joints have no common ancestor node")
        lca = max(common, key=lambda n: len(ancestors(n)))
        for r in roots:
            while r != lca:
                joints.add(r)
                r = int(asset.parents[r])
        joints.add(lca)
        roots = [lca]
    order: list[int] = []
    stack = [roots[0]]
    children = {n: [c for c in range(asset.num_nodes) if asset.parents[c] == n and c in joints] for n in joints}
    while stack:
        n = stack.pop()
        order.append(n)
        stack.extend(reversed(children[n]))
    return order


def _world_rest(asset: GltfAsset, node: int) -> tuple[F64, F64, float]:
    """Rest world position, rotation and uniform scale of ``node``'s *parent* chain (identity above scene roots)."""
    pos, rot, scl = np.zeros(3), quat.identity(), 1.0
    chain = []
    n = int(asset.parents[node])
    while n >= 0:
        chain.append(n)
        n = int(asset.parents[n])
    for n in reversed(chain):
        pos = pos + quat.rotate(rot, scl * asset.translation[n])
        rot = quat.mul(rot, asset.rotation[n])
        scl *= float(np.mean(np.abs(asset.scale[n])))
    return pos, rot, scl


def _tracks(asset: GltfAsset, nodes: list[int], anim: GltfAnimation | None, t: F64) -> tuple[F64, F64, NDArray[np.bool_]]:
    """Local translations ``[T,J,3]``, rotations ``[T,J,4]`` and which joints' translation is animated."""
    col = {n: k for k, n in enumerate(nodes)}
    trans = np.broadcast_to(asset.translation[nodes], (len(t), len(nodes), 3)).copy()
    rots = np.broadcast_to(asset.rotation[nodes], (len(t), len(nodes), 4)).copy()
    moves = np.zeros(len(nodes), dtype=bool)
    for ch in anim.channels if anim else ():
        k = col.get(ch.node)
        if k is None or ch.path not in ("translation", "rotation") or not len(ch.times):
            continue
        values = sample_channel(ch, t)
        if ch.path == "rotation":
            rots[:, k] = values
        else:
            trans[:, k] = values
            # float32 keys jitter in their last bits; only real travel counts as movement
            moves[k] = bool(np.ptp(values, axis=0).max() > 1e-5 * max(1.0, float(np.abs(values).max())))
    return trans, rots, moves


def _build(asset: GltfAsset, skin: int, anim: GltfAnimation | None, t: F64, scale: float) -> tuple[Skeleton, F64, F64]:
    nodes = skin_nodes(asset, skin)
    trans, rots, _ = _tracks(asset, nodes, anim, t)
    # Fold by what *any* animation moves, so every clip of one asset shares one skeleton.
    moves = np.zeros(len(nodes), dtype=bool)
    for other in asset.animations:
        moves |= _tracks(asset, nodes, other, np.array([other.start, 0.5 * (other.start + other.end), other.end]))[2]
    pos0, rot0, s0 = _world_rest(asset, nodes[0])
    wscale = np.ones(len(nodes))
    parents = np.array([-1] + [nodes.index(int(asset.parents[n])) for n in nodes[1:]], dtype=np.int64)
    for k, n in enumerate(nodes):
        own = float(np.mean(np.abs(asset.scale[n])))
        wscale[k] = (s0 if k == 0 else wscale[parents[k]]) * own
    trans[:, 0] = pos0 + quat.rotate(rot0, s0 * trans[:, 0])
    rots[:, 0] = quat.mul(rot0, rots[:, 0])
    trans[:, 1:] *= wscale[parents[1:]][None, :, None]
    tips = np.array([asset.extras[n].get("tip", (0.0, 0.0, 0.0)) for n in nodes], dtype=np.float64) * wscale[:, None]
    radii = [asset.extras[n].get("radius") for n in nodes]
    names, parents, trans, rots, _, tips = fold_root([asset.names[n] for n in nodes], parents, trans, rots, moves, tips)
    if len(set(names)) != len(names):
        names = [f"{nm}#{k}" if names.count(nm) > 1 else nm for k, nm in enumerate(names)]
    radii = radii[len(radii) - len(names):]
    r = np.array(radii, dtype=np.float64) * scale if all(isinstance(x, (int, float)) for x in radii) else None
    skeleton = Skeleton(tuple(names), parents, trans[0] * scale, tips * scale, r)
    return skeleton, trans[:, 0] * scale, rots


def gltf_skeleton(asset: GltfAsset, skin: int = 0, scale: float = 1.0) -> Skeleton:
    """The rest skeleton of a skin (the same one every :func:`gltf_clip` of this asset uses)."""
    return _build(asset, skin, None, np.zeros(1), scale)[0]


def gltf_clip(
    asset: GltfAsset, animation: int | str = 0, skin: int = 0, fps: float | None = None, scale: float = 1.0
) -> Clip:
    """One animation as a clip, sampled at ``fps`` from its first key to its last.

    Args:
        asset: from :func:`~engine.io.gltf.read_gltf`.
        animation: index or name.
        skin: which skin's joints form the skeleton.
        fps: sampling rate of the clip; default: the rate our writer recorded, else 30.
        scale: metres per file unit (glTF is metres: 1).

    Files written by :func:`engine.io.gltf_write.write_gltf` come back with their loop flag
    and markers (the repeated closing frame of a loop is dropped again).
    """
    names = [a.name for a in asset.animations]
    try:
        anim = asset.animations[names.index(animation) if isinstance(animation, str) else animation]
    except (ValueError, IndexError):
        raise GltfError(f"{asset.source}: no animation {animation!r}; it has {names}") from None
    given = fps if fps is not None else anim.extras.get("fps", 30.0)
    if isinstance(given, bool) or not isinstance(given, (int, float)) or not 0 < given <= MAX_FPS:
        raise GltfError(f"{asset.source}: fps must be a number in (0, {MAX_FPS:g}], got {repr(given)[:20]}")
    rate = float(given)
    frames = anim.duration * rate
    if frames * max(asset.num_nodes, 1) > MAX_SAMPLES:  # key times far apart must not allocate gigabytes
        raise GltfError(f"{asset.source}: animation {anim.name!r} would be {frames:.3g} frames of "
                        f"{asset.num_nodes} nodes at {rate:g} fps; the limit is {MAX_SAMPLES} node-frames")
    n = int(round(anim.duration * rate)) + 1
    t = np.minimum(anim.start + np.arange(n) / rate, anim.end)
    try:
        skeleton, root, rots = _build(asset, skin, anim, t, scale)
        rest = gltf_skeleton(asset, skin, scale)
        skeleton = Skeleton(skeleton.names, skeleton.parents, rest.offsets, rest.tips, rest.radii)
        loop = bool(anim.extras.get("loop", False))
        if loop and n > 1:
            root, rots = root[:-1], rots[:-1]
        markers = anim.extras.get("markers", {})
        markers = {str(k): float(v) for k, v in markers.items()
                   if isinstance(v, (int, float)) and math.isfinite(v)} if isinstance(markers, dict) else {}
        return Clip(str(anim.name), skeleton, rate, root, rots, loop=loop, markers=markers)
    except GltfError:
        raise
    except (ValueError, IndexError, KeyError, TypeError) as exc:  # a skin or tracks that make no skeleton or clip
        raise GltfError(f"{asset.source}: animation {anim.name!r} does not make a clip "
                        f"({type(exc).__name__}: {exc})"[:300]) from None


def load_gltf_clips(path: str | os.PathLike[str], fps: float | None = None, skin: int = 0, scale: float = 1.0) -> list[Clip]:
    """Every animation of a ``.glb``/``.gltf`` file as a clip on the file's skin."""
    asset = read_gltf(path)
    return [gltf_clip(asset, k, skin, fps, scale) for k in range(len(asset.animations))]
