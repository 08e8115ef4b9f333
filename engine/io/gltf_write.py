"""glTF 2.0 export of a clip: the skeleton as a node hierarchy with a skin, and one animation.

Edited cycles leave the engine this way (issue 9) for Blender, three.js or any glTF
viewer. Each joint is a node whose rest translation is its bone offset and whose rest
rotation is the identity (the engine's rest pose); the skin's inverse bind matrices
match that rest pose, so a mesh bound later deforms correctly. The animation has the
root's translation and every joint's rotation, sampled once per clip frame (LINEAR), plus
the translation of every other joint whose translation channel moves and the scale of
every joint whose scale channel leaves 1 (uniform, written as ``(s, s, s)``).
A looping clip gets its first frame repeated at ``F / fps`` so any viewer loops it
seamlessly; ``extras`` remember the loop flag, markers and frame rate, and bone tips and
radii ride in node ``extras`` so :func:`engine.io.gltf_clip.gltf_clip` gets the clip back.

``.glb`` is written as one binary file; ``.gltf`` as JSON with the buffer as a base64
data URI, so either is a single file written atomically.
"""

from __future__ import annotations

import base64
import json
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from engine import quat
from engine.atomic import atomic_write_bytes
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.io.formats import FORMATS

__all__ = ["write_gltf", "gltf_bytes", "container_bytes"]


class _Bin:
    """Accumulates accessors into one little-endian float32 buffer, 4-byte aligned."""

    def __init__(self) -> None:
        self.chunks: list[bytes] = []
        self.size = 0
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []

    def add(self, array: np.ndarray, kind: str, minmax: bool = False) -> int:
        data = np.ascontiguousarray(array, dtype="<f4")
        raw = data.tobytes()
        self.views.append({"buffer": 0, "byteOffset": self.size, "byteLength": len(raw)})
        acc: dict[str, Any] = {
            "bufferView": len(self.views) - 1,
            "componentType": 5126,
            "count": int(len(data)),
            "type": kind,
        }
        if minmax:
            flat = data.reshape(len(data), -1)
            acc["min"] = flat.min(axis=0).astype(float).tolist()
            acc["max"] = flat.max(axis=0).astype(float).tolist()
        self.accessors.append(acc)
        pad = (-len(raw)) % 4
        self.chunks.append(raw + b"\0" * pad)
        self.size += len(raw) + pad
        return len(self.accessors) - 1

    def blob(self) -> bytes:
        return b"".join(self.chunks)


def _document(clip: Clip) -> tuple[dict[str, Any], bytes]:
    sk = clip.skeleton
    j_count = sk.num_joints
    root, rots = clip.root, clip.rotations
    times = np.arange(clip.num_frames) / clip.fps
    trans, scales = clip.translations, clip.scales
    if clip.loop:
        root = np.concatenate([root, root[:1]])
        rots = np.concatenate([rots, rots[:1]])
        trans = None if trans is None else np.concatenate([trans, trans[:1]])
        scales = None if scales is None else np.concatenate([scales, scales[:1]])
        times = np.append(times, clip.num_frames / clip.fps)
    nodes: list[dict[str, Any]] = []
    for j in range(j_count):
        node: dict[str, Any] = {"name": sk.names[j], "translation": sk.offsets[j].tolist()}
        kids = sk.children(j)
        if kids:
            node["children"] = kids
        node["extras"] = {"radius": float(sk.radii[j])}
        if np.any(sk.tips[j]):
            node["extras"]["tip"] = sk.tips[j].tolist()
        nodes.append(node)
    buf = _Bin()
    rest_pos, _ = forward_kinematics(sk, sk.offsets[0], quat.identity(j_count))
    ibm = np.broadcast_to(np.eye(4), (j_count, 4, 4)).copy()
    ibm[:, :3, 3] = -rest_pos
    ibm_acc = buf.add(ibm.transpose(0, 2, 1).reshape(j_count, 16), "MAT4")
    t_acc = buf.add(times, "SCALAR", minmax=True)
    samplers = [{"input": t_acc, "output": buf.add(root, "VEC3"), "interpolation": "LINEAR"}]
    channels = [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]
    for j in range(j_count):
        samplers.append(
            {"input": t_acc, "output": buf.add(quat.to_xyzw(rots[:, j]), "VEC4"), "interpolation": "LINEAR"}
        )
        channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": "rotation"}})
    for j in range(1, j_count):
        if trans is not None and np.ptp(trans[:, j], axis=0).max() > 1e-9:
            samplers.append({"input": t_acc, "output": buf.add(trans[:, j], "VEC3"), "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": "translation"}})
    for j in range(j_count):
        if scales is not None and np.abs(scales[:, j] - 1.0).max() > 1e-9:
            samplers.append(
                {
                    "input": t_acc,
                    "output": buf.add(np.repeat(scales[:, j, None], 3, axis=1), "VEC3"),
                    "interpolation": "LINEAR",
                }
            )
            channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": "scale"}})
    blob = buf.blob()
    doc: dict[str, Any] = {
        "asset": {"version": "2.0", "generator": "PuppetPhone engine.io.gltf_write"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "skins": [{"name": sk.names[0], "joints": list(range(j_count)), "skeleton": 0, "inverseBindMatrices": ibm_acc}],
        "animations": [
            {
                "name": clip.name,
                "channels": channels,
                "samplers": samplers,
                "extras": {"loop": bool(clip.loop), "fps": float(clip.fps), "markers": dict(clip.markers)},
            }
        ],
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": len(blob)}],
    }
    return doc, blob


def gltf_bytes(clip: Clip, binary: bool = True) -> bytes:
    """The file content: GLB when ``binary``, else glTF JSON with a data-URI buffer."""
    doc, blob = _document(clip)
    return container_bytes(doc, blob, binary)


def container_bytes(doc: dict, blob: bytes, binary: bool) -> bytes:
    """A glTF document and its buffer as a file: a GLB container, or JSON with the buffer as a data URI."""
    if not binary:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
        return json.dumps(doc, indent=1).encode("utf-8")
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * ((-len(js)) % 4)
    blob += b"\0" * ((-len(blob)) % 4)
    total = 12 + 8 + len(js) + 8 + len(blob)
    return b"".join(
        [
            struct.pack("<4sII", b"glTF", 2, total),
            struct.pack("<I4s", len(js), b"JSON"),
            js,
            struct.pack("<I4s", len(blob), b"BIN\0"),
            blob,
        ]
    )


def write_gltf(path: str | os.PathLike[str], clip: Clip) -> Path:
    """Write ``clip`` as ``.glb`` (binary) or ``.gltf`` (JSON, embedded buffer), atomically."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in FORMATS["gltf"].suffixes:
        raise ValueError(f"{p}: write_gltf needs a .glb or .gltf path")
    return atomic_write_bytes(p, gltf_bytes(clip, binary=suffix == ".glb"))
