"""glTF ``CUBICSPLINE`` animation in and out for keyframed clips (their keys and tangents, not samples).

glTF's cubic spline is a Hermite curve per key interval in *linear* time ``s``, with each
key carrying ``(in-tangent a_k, value v_k, out-tangent b_k)`` as slopes per second. Our
Bézier segment with time tangents of a third of the spacing is exactly that curve, with
``b_k = θ^Y_{k+}/θ^X_{k+}`` and ``a_{k+1} = θ^Y_{k+1−}/θ^X_{k+1−}`` (the end slopes); with
other time tangents the exported curve keeps the keys and the slopes at them (C¹ at the
keys) and bends a little differently in between. Root translation goes out as such; a
joint's rotation vector becomes glTF's quaternion track, its slope mapped through
``exp`` (so values and slopes at the keys are exact, the in-between is glTF's
quaternion Hermite, normalised by the player). Reading takes such a file (all channels on
the same key times, as we write them) back to a :class:`~engine.keyframes.KeyframedClip`:
values through ``log``, slopes through its derivative, time tangents a third of the
spacing — so a clip whose time tangents are thirds round-trips its translations exactly
and its rotations at the keys exactly.

This module only adds to :mod:`engine.io.gltf_write` / :mod:`engine.io.gltf` (it writes
the same document, skeleton and skin, and replaces the animation's samplers); no hook
in them is needed.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from engine import quat
from engine.arrays import F64 as F
from engine.atomic import atomic_write_bytes
from engine.io.formats import FORMATS
from engine.keyframes import BezierCurves, KeyframedClip

__all__ = ["write_gltf_cubic", "read_gltf_cubic"]

_H = 1e-6  # step of the central differences through exp/log (their error is ~1e-12 here)


def _slopes(kc: KeyframedClip) -> tuple[F, F]:
    """``(out slope [K,C], in slope [K,C])`` of every channel at every key (per second)."""
    c = kc.curves
    floor = 1e-9 * float(np.min(np.diff(c.times)))
    return c.out_y / np.maximum(c.out_x, floor), c.in_y / np.maximum(c.in_x, floor)


def _quat_tracks(rv: F, slope: F) -> tuple[F, F]:
    """Quaternions ``[K,J,4]`` of rotation vectors and their time derivatives for ``dc/dt = slope``."""
    q = quat.exp(rv)
    dq = (quat.exp(rv + _H * slope) - quat.exp(rv - _H * slope)) / (2.0 * _H)
    return q, dq


def _log_slope(q: F, dq: F) -> F:
    """``d log(q)/dt`` for quaternions ``q`` moving at ``dq`` (central differences on the unit sphere)."""
    return (quat.log(quat.normalize(q + _H * dq)) - quat.log(quat.normalize(q - _H * dq))) / (2.0 * _H)


def write_gltf_cubic(path: str | os.PathLike[str], clip: KeyframedClip) -> Path:
    """Write ``clip``'s keys and tangents as a ``.glb``/``.gltf`` with CUBICSPLINE samplers, atomically."""
    from engine.io import gltf_write

    p = Path(path)
    if p.suffix.lower() not in FORMATS["gltf"].suffixes:
        raise ValueError(f"{p}: write_gltf_cubic needs a .glb or .gltf path")
    doc, blob = gltf_write._document(clip.bake())
    buf = gltf_write._Bin()
    buf.chunks, buf.size, buf.views, buf.accessors = [blob], len(blob), doc["bufferViews"], doc["accessors"]
    c = clip.curves
    j_count = clip.skeleton.num_joints
    k = c.times.size
    out_s, in_s = _slopes(clip)
    t_acc = buf.add(c.times - c.times[0], "SCALAR", minmax=True)
    # Root translation: (in, value, out) per key.
    root = np.stack([in_s[:, :3], c.values[:, :3], out_s[:, :3]], axis=1).reshape(3 * k, 3)
    samplers = [{"input": t_acc, "output": buf.add(root, "VEC3"), "interpolation": "CUBICSPLINE"}]
    channels = [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]
    rv = c.values[:, 3:].reshape(k, j_count, 3)
    q, dq_out = _quat_tracks(rv, out_s[:, 3:].reshape(k, j_count, 3))
    _, dq_in = _quat_tracks(rv, in_s[:, 3:].reshape(k, j_count, 3))
    for j in range(j_count):
        track = np.stack([quat.to_xyzw(dq_in[:, j]), quat.to_xyzw(q[:, j]), quat.to_xyzw(dq_out[:, j])], axis=1)
        samplers.append({"input": t_acc, "output": buf.add(track.reshape(3 * k, 4), "VEC4"),
                         "interpolation": "CUBICSPLINE"})  # fmt: skip
        channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": "rotation"}})
    anim = doc["animations"][0]
    anim["samplers"], anim["channels"] = samplers, channels
    anim["extras"]["keyframed"] = True
    blob = buf.blob()
    doc["buffers"] = [{"byteLength": len(blob)}]
    return atomic_write_bytes(p, gltf_write.container_bytes(doc, blob, p.suffix.lower() == ".glb"))


def read_gltf_cubic(path: str | os.PathLike[str], animation: int = 0, skin: int = 0) -> KeyframedClip:
    """A CUBICSPLINE animation (every joint channel on the same key times) as a keyframed clip.

    Raises:
        GltfError: not such an animation (other interpolations, channels on different key
            times, scale channels) — sample those with :func:`engine.io.gltf_clip.gltf_clip`.
    """
    from engine.io.gltf import GltfError, read_gltf
    from engine.io.gltf_clip import gltf_skeleton, skin_nodes

    asset = read_gltf(path)
    try:
        anim = asset.animations[animation]
    except IndexError:
        raise GltfError(f"{asset.source}: no animation {animation}") from None
    nodes = skin_nodes(asset, skin)
    sk = gltf_skeleton(asset, skin)
    index = {n: j for j, n in enumerate(nodes)}
    times = None
    j_count = sk.num_joints
    chans = [c for c in anim.channels if c.node in index and c.path in ("translation", "rotation")]
    if not chans or any(c.interpolation != "CUBICSPLINE" for c in chans):
        raise GltfError(f"{asset.source}: animation {anim.name!r} is not CUBICSPLINE throughout")
    for c in chans:
        if times is None:
            times = np.asarray(c.times, dtype=np.float64)
        elif c.times.shape != times.shape or not np.allclose(c.times, times, rtol=0, atol=1e-6):
            raise GltfError(f"{asset.source}: animation {anim.name!r}: channels on different key times")
    assert times is not None
    k = times.size
    if k < 2:
        raise GltfError(f"{asset.source}: animation {anim.name!r} needs two keys or more")
    values = np.zeros((k, 3 + 3 * j_count))
    slope_in, slope_out = np.zeros_like(values), np.zeros_like(values)
    rest_q = quat.identity(j_count)
    for c in chans:
        v = np.asarray(c.values, dtype=np.float64).reshape(k, 3, -1)
        j = index[c.node]
        if c.path == "translation" and j == 0:
            slope_in[:, :3], values[:, :3], slope_out[:, :3] = v[:, 0], v[:, 1], v[:, 2]
        elif c.path == "rotation":
            # the reader gives w-first quaternions; tangents are in the same component order
            q = quat.align_hemisphere(quat.normalize(v[:, 1]), rest_q[j])
            sign = np.sign(np.sum(q * v[:, 1], axis=-1, keepdims=True))
            d_in, d_out = v[:, 0] * sign, v[:, 2] * sign
            rv = quat.log(q)
            sl = slice(3 + 3 * j, 6 + 3 * j)
            values[:, sl] = rv
            slope_in[:, sl] = _log_slope(q, d_in)
            slope_out[:, sl] = _log_slope(q, d_out)
    gap = np.diff(times)
    x_out = np.zeros_like(values)
    x_in = np.zeros_like(values)
    x_out[:-1] = gap[:, None] / 3.0
    x_in[1:] = gap[:, None] / 3.0
    curves = BezierCurves(times - times[0], values, x_out, slope_out * x_out, x_in, slope_in * x_in)
    loop = bool(anim.extras.get("loop", False))
    fps = float(anim.extras.get("fps", 30.0))
    return KeyframedClip(str(anim.name), sk, curves, fps, loop)
