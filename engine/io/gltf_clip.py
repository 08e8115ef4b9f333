"""glTF skins and animations as engine skeletons and clips.

A skin's joints become a :class:`~engine.skeleton.Skeleton` in topological order. The rest
transform of the nodes above the skin's root (Khronos samples put a ``Z_UP`` matrix and an
``Armature`` there) is baked into joint 0, so the clip is in glTF world space: Y up,
metres. Rest scales are baked into the bone offsets; an *animated* scale becomes the clip's
scale channel (uniform: the mean of the three factors, relative to the rest scale), and an
animated translation of any joint below the root its translation channel. Each animation is
sampled (LINEAR by slerp/lerp, STEP, CUBICSPLINE by Hermite) at a fixed frame rate — by
default the rate its keys are spaced at, when they are regular; a static root above
moving hips (Fox's ``_rootJoint``/``b_Root_00``) is folded so the hips' travel moves the clip.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64
from engine.clip import Clip
from engine.io._tracks import fold_root
from engine.io.gltf import GltfAnimation, GltfAsset, GltfChannel, GltfError, read_gltf
from engine.skeleton import Skeleton

__all__ = ["sample_channel", "skin_nodes", "gltf_skeleton", "gltf_clip", "load_gltf_clips", "key_rate", "DEFAULT_FPS"]

DEFAULT_FPS = 30.0

MAX_FPS = 1000.0
MAX_SAMPLES = 4_000_000  # frames x nodes: an hour at 60 fps of an 18-node skeleton


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
        out = (
            h[0][:, None] * vals[i, 1]
            + h[1][:, None] * vals[i, 2]
            + h[2][:, None] * vals[i + 1, 1]
            + h[3][:, None] * vals[i + 1, 0]
        )
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


def _tracks(
    asset: GltfAsset, nodes: list[int], anim: GltfAnimation | None, t: F64
) -> tuple[F64, F64, NDArray[np.bool_], F64 | None]:
    """Local translations ``[T,J,3]``, rotations ``[T,J,4]``, which joints' translation is animated,
    and the animated uniform scale relative to the rest scale ``[T,J]`` (``None`` when none is)."""
    col = {n: k for k, n in enumerate(nodes)}
    trans = np.broadcast_to(asset.translation[nodes], (len(t), len(nodes), 3)).copy()
    rots = np.broadcast_to(asset.rotation[nodes], (len(t), len(nodes), 4)).copy()
    moves = np.zeros(len(nodes), dtype=bool)
    scales = None
    for ch in anim.channels if anim else ():
        k = col.get(ch.node)
        if k is None or ch.path not in ("translation", "rotation", "scale") or not len(ch.times):
            continue
        values = sample_channel(ch, t)
        if ch.path == "rotation":
            rots[:, k] = values
        elif ch.path == "scale":
            rest = float(np.mean(np.abs(asset.scale[ch.node])))
            ratio = np.mean(np.abs(values), axis=1) / (rest if rest > 0 else 1.0)
            if np.ptp(ratio) > 1e-5 or abs(float(ratio[0]) - 1.0) > 1e-5:
                scales = np.ones((len(t), len(nodes))) if scales is None else scales
                scales[:, k] = np.maximum(ratio, 1e-6)
        else:
            trans[:, k] = values
            # float32 keys jitter in their last bits; only real travel counts as movement
            moves[k] = bool(np.ptp(values, axis=0).max() > 1e-5 * max(1.0, float(np.abs(values).max())))
    return trans, rots, moves, scales


def _build(
    asset: GltfAsset, skin: int, anim: GltfAnimation | None, t: F64, scale: float
) -> tuple[Skeleton, F64, F64, F64 | None, F64 | None]:
    nodes = skin_nodes(asset, skin)
    trans, rots, own_moves, scales = _tracks(asset, nodes, anim, t)
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
    before = len(nodes)
    names, parents, trans, rots, moves, tips = fold_root(
        [asset.names[n] for n in nodes], parents, trans, rots, moves, tips
    )
    folded = before - len(names)
    if scales is not None:
        if folded and np.abs(scales[:, :folded] - 1.0).max() > 1e-5:
            raise GltfError(f"{asset.source}: an animated scale on a folded root joint is not supported")
        scales = scales[:, folded:]
    if len(set(names)) != len(names):
        names = [f"{nm}#{k}" if names.count(nm) > 1 else nm for k, nm in enumerate(names)]
    radii = radii[len(radii) - len(names) :]
    r = np.array(radii, dtype=np.float64) * scale if all(isinstance(x, (int, float)) for x in radii) else None
    skeleton = Skeleton(tuple(names), parents, trans[0] * scale, tips * scale, r)  # type: ignore[arg-type]  # None: derived
    own_moves = own_moves[folded:]
    translations = trans * scale if own_moves[1:].any() else None
    return skeleton, trans[:, 0] * scale, rots, translations, scales


def key_rate(anim: GltfAnimation) -> float | None:
    """Frames per second of an animation whose keys are spaced regularly, else ``None``.

    The spacing is the median gap between distinct key times; the keys count as regular
    when at least three quarters of the gaps equal it within 1 % (exporters that drop
    redundant keys leave a few longer gaps: Fox's Run is 24 fps with one 4.8-frame gap). A
    rate within 0.1 % of a whole number is rounded to it (float32 times make 24 fps read as 23.9999).
    """
    keys = np.unique(np.concatenate([c.times for c in anim.channels if len(c.times)] or [np.zeros(0)]))
    if len(keys) < 3:
        return None
    gaps = np.diff(keys)
    step = float(np.median(gaps))
    if not step > 0 or np.mean(np.abs(gaps - step) <= 0.01 * step) < 0.75:
        return None
    rate = 1.0 / step
    whole = round(rate)
    if whole > 0 and abs(rate - whole) <= 1e-3 * rate:
        rate = float(whole)
    return rate if 0 < rate <= MAX_FPS else None


def gltf_skeleton(asset: GltfAsset, skin: int = 0, scale: float = 1.0) -> Skeleton:
    """The rest skeleton of a skin (the same one every :func:`gltf_clip` of this asset uses)."""
    return _build(asset, skin, None, np.zeros(1), scale)[0]


def animation_rate(anim: GltfAnimation, fps: float | None = None) -> tuple[float, str]:
    """The sampling rate of ``anim`` and where it comes from: given, our writer's, the keys' spacing, or the default."""
    if fps is not None:
        return fps, "given"
    if "fps" in anim.extras:
        return anim.extras["fps"], "recorded by PuppetPhone"
    rate = key_rate(anim)
    if rate is not None:
        return rate, "key spacing"
    return DEFAULT_FPS, f"default {DEFAULT_FPS:g} (keys not evenly spaced)"


def find_animation(asset: GltfAsset, animation: int | str = 0) -> GltfAnimation:
    """An animation by name, or by index (a string of digits that is no animation's name counts as an index)."""
    names = [a.name for a in asset.animations]
    if not names:
        raise GltfError(f"{asset.source}: the file has no animations")
    if isinstance(animation, str) and animation not in names and animation.strip().isdigit():
        animation = int(animation)
    try:
        return asset.animations[names.index(animation) if isinstance(animation, str) else animation]
    except (ValueError, IndexError):
        listed = ", ".join(f"{k}: {n!r}" for k, n in enumerate(names))
        raise GltfError(f"{asset.source}: no animation {animation!r}; it has {listed}") from None


def gltf_clip(
    asset: GltfAsset, animation: int | str = 0, skin: int = 0, fps: float | None = None, scale: float = 1.0
) -> Clip:
    """One animation as a clip, sampled at ``fps`` from its first key to its last.

    Args:
        asset: from :func:`~engine.io.gltf.read_gltf`.
        animation: index or name.
        skin: which skin's joints form the skeleton.
        fps: sampling rate of the clip; default: the rate our writer recorded, else the
            keys' regular spacing (:func:`key_rate`), else 30.
        scale: metres per file unit (glTF is metres: 1).

    Files written by :func:`engine.io.gltf_write.write_gltf` come back with their loop flag
    and markers (the repeated closing frame of a loop is dropped again).
    """
    anim = find_animation(asset, animation)
    given, _ = animation_rate(anim, fps)
    if isinstance(given, bool) or not isinstance(given, (int, float)) or not 0 < given <= MAX_FPS:
        raise GltfError(f"{asset.source}: fps must be a number in (0, {MAX_FPS:g}], got {repr(given)[:20]}")
    rate = float(given)
    frames = anim.duration * rate
    if frames * max(asset.num_nodes, 1) > MAX_SAMPLES:  # key times far apart must not allocate gigabytes
        raise GltfError(
            f"{asset.source}: animation {anim.name!r} would be {frames:.3g} frames of "
            f"{asset.num_nodes} nodes at {rate:g} fps; the limit is {MAX_SAMPLES} node-frames"
        )
    n = int(round(anim.duration * rate)) + 1
    t = np.minimum(anim.start + np.arange(n) / rate, anim.end)
    try:
        skeleton, root, rots, translations, scales = _build(asset, skin, anim, t, scale)
        rest = gltf_skeleton(asset, skin, scale)
        skeleton = Skeleton(skeleton.names, skeleton.parents, rest.offsets, rest.tips, rest.radii)
        loop = bool(anim.extras.get("loop", False))
        if loop and n > 1:
            root, rots = root[:-1], rots[:-1]
            translations = None if translations is None else translations[:-1]
            scales = None if scales is None else scales[:-1]
        markers = anim.extras.get("markers", {})
        markers = (
            {str(k): float(v) for k, v in markers.items() if isinstance(v, (int, float)) and math.isfinite(v)}
            if isinstance(markers, dict)
            else {}
        )
        return Clip(
            str(anim.name),
            skeleton,
            rate,
            root,
            rots,
            loop=loop,
            markers=markers,
            translations=translations,
            scales=scales,
        )
    except GltfError:
        raise
    except (ValueError, IndexError, KeyError, TypeError) as exc:  # a skin or tracks that make no skeleton or clip
        raise GltfError(
            f"{asset.source}: animation {anim.name!r} does not make a clip ({type(exc).__name__}: {exc})"[:300]
        ) from None


def load_gltf_clips(
    path: str | os.PathLike[str], fps: float | None = None, skin: int = 0, scale: float = 1.0
) -> list[Clip]:
    """Every animation of a ``.glb``/``.gltf`` file as a clip on the file's skin."""
    asset = read_gltf(path)
    return [gltf_clip(asset, k, skin, fps, scale) for k in range(len(asset.animations))]
