"""glTF 2.0 reading: the container (.glb, or .gltf with external or data-URI buffers),
typed accessors, and the node / skin / animation structure, with numpy and json only.

:func:`read_gltf` returns a :class:`GltfAsset` holding what a motion importer needs —
nodes with their rest TRS and parents, skins with joints and inverse bind matrices, and
animation channels as raw keyframes — without meshes or materials. Building a
:class:`~engine.skeleton.Skeleton` and resampled :class:`~engine.clip.Clip` from it lives in
:mod:`engine.io.gltf_clip`. glTF quaternions are ``x, y, z, w``; they are converted to the
engine's ``w, x, y, z`` here, once.
"""

from __future__ import annotations

import base64
import json
import os
import struct
import urllib.parse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.errors import FormatError
from engine.npz_safe import read_bounded

__all__ = ["GltfError", "GltfAsset", "GltfSkin", "GltfChannel", "GltfAnimation", "read_gltf", "parse_glb", "accessor"]

_COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_NORM = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_GLB_MAGIC, _JSON_CHUNK, _BIN_CHUNK = b"glTF", 0x4E4F534A, 0x004E4942
# Limits a character file is far inside; checked before anything is allocated.
MAX_FILE = 512 << 20
MAX_NODES = 65536
MAX_ELEMENTS = 1 << 24  # numbers in one accessor (128 MB as float64)
MAX_TIME = 1e5  # seconds of animation
# Anything a malformed document (wrong types, missing keys) makes the walk below raise.
_MALFORMED = (KeyError, TypeError, IndexError, AttributeError, ValueError, OverflowError)


class GltfError(FormatError):
    """A glTF file that cannot be read; the message names the file and the broken part."""


@dataclass(frozen=True)
class GltfSkin:
    """A skin: its joint node indices, ``[K,4,4]`` inverse bind matrices, and optional root node."""

    name: str
    joints: tuple[int, ...]
    inverse_bind: NDArray[np.float64]
    skeleton: int | None


@dataclass(frozen=True)
class GltfChannel:
    """One animated property: keyframe ``times [K]`` and ``values`` (``[K,n]``, or ``[3K,n]`` for cubic)."""

    node: int
    path: str  # "translation" | "rotation" (w,x,y,z) | "scale" | "weights"
    interpolation: str  # "LINEAR" | "STEP" | "CUBICSPLINE"
    times: NDArray[np.float64]
    values: NDArray[np.float64]


@dataclass(frozen=True)
class GltfAnimation:
    """A named animation: its channels and the time span its keyframes cover."""

    name: str
    channels: tuple[GltfChannel, ...]
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def start(self) -> float:
        """Earliest keyframe time in seconds."""
        return min((float(c.times[0]) for c in self.channels if len(c.times)), default=0.0)

    @property
    def end(self) -> float:
        """Latest keyframe time in seconds."""
        return max((float(c.times[-1]) for c in self.channels if len(c.times)), default=0.0)

    @property
    def duration(self) -> float:
        """``end - start``."""
        return self.end - self.start


@dataclass(frozen=True)
class GltfAsset:
    """The motion-relevant content of a glTF file.

    Attributes:
        names: node names (``node<i>`` where unnamed).
        parents: ``[N]`` parent node index, ``-1`` for scene roots.
        translation, rotation, scale: rest TRS per node (``[N,3]``, ``[N,4]`` w-first, ``[N,3]``);
            nodes given as a ``matrix`` are decomposed.
        extras: each node's ``extras`` object (our writer keeps bone tips and radii there).
        skins, animations: as in the file.
        source: the path read, for messages.
    """

    names: tuple[str, ...]
    parents: NDArray[np.int64]
    translation: NDArray[np.float64]
    rotation: NDArray[np.float64]
    scale: NDArray[np.float64]
    extras: tuple[dict[str, Any], ...]
    skins: tuple[GltfSkin, ...]
    animations: tuple[GltfAnimation, ...]
    source: str = ""

    @property
    def num_nodes(self) -> int:
        """Number of nodes."""
        return len(self.names)


def parse_glb(data: bytes, source: str = "<glb>") -> tuple[dict[str, Any], bytes | None]:
    """The JSON document and the BIN chunk (if any) of a binary glTF."""
    if len(data) < 20 or data[:4] != _GLB_MAGIC:
        raise GltfError(f"{source}: not a GLB file (bad magic)")
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2:
        raise GltfError(f"{source}: GLB version {version}, only 2 is supported")
    if length > len(data):
        raise GltfError(f"{source}: truncated: header says {length} bytes, file has {len(data)}")
    doc, binary, pos = None, None, 12
    while pos + 8 <= length:
        size, kind = struct.unpack_from("<II", data, pos)
        chunk = data[pos + 8 : pos + 8 + size]
        if len(chunk) != size:
            raise GltfError(f"{source}: truncated chunk at byte {pos}")
        if kind == _JSON_CHUNK and doc is None:
            try:
                doc = json.loads(chunk.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
                raise GltfError(f"{source}: bad JSON chunk: {type(exc).__name__}") from None
        elif kind == _BIN_CHUNK and binary is None:
            binary = chunk
        pos += 8 + size
    if doc is None:
        raise GltfError(f"{source}: no JSON chunk")
    return doc, binary


def _beside(base: Path, uri: Any, what: str) -> Path:
    """The file a relative buffer URI names, refused unless it lies in the glTF file's own folder.

    A glTF from anywhere must not make the reader open any file on disk: an absolute path,
    a ``file:`` or other scheme, ``..`` or a link leading out of the folder is a :class:`GltfError`.
    """
    name = urllib.parse.unquote(uri) if isinstance(uri, str) else ""
    parts = Path(name).parts
    if not name or Path(name).is_absolute() or ".." in parts or urllib.parse.urlsplit(uri).scheme or "\\" in name:
        raise GltfError(
            f"{what}: uri {str(uri)[:60]!r} is not a file beside the glTF (no absolute paths, schemes or ..)"
        )
    path = base / name
    try:
        inside = path.resolve().is_relative_to(base.resolve())
    except (OSError, RuntimeError):
        inside = False
    if not inside:
        raise GltfError(f"{what}: uri {str(uri)[:60]!r} leads out of the glTF's folder")
    return path


def _buffers(doc: dict[str, Any], glb_bin: bytes | None, base: Path, source: str) -> list[bytes]:
    out = []
    for i, buf in enumerate(doc.get("buffers", [])):
        uri = buf.get("uri")
        if uri is None:
            if glb_bin is None:
                raise GltfError(f"{source}: buffer {i} has no uri and there is no GLB binary chunk")
            data = glb_bin
        elif uri.startswith("data:"):
            head, _, payload = uri.partition(",")
            data = base64.b64decode(payload) if head.endswith(";base64") else urllib.parse.unquote_to_bytes(payload)
        else:
            path = _beside(base, uri, f"{source}: buffer {i}")
            try:
                data = read_bounded(path, MAX_FILE)
            except OSError as exc:
                raise GltfError(f"{source}: buffer {i}: cannot read {path}: {exc.strerror}") from None
            except ValueError as exc:
                raise GltfError(f"{source}: buffer {i}: {exc}") from None
        if len(data) < buf.get("byteLength", 0):
            raise GltfError(f"{source}: buffer {i} holds {len(data)} bytes, byteLength says {buf['byteLength']}")
        out.append(data)
    return out


def _view(doc: dict[str, Any], buffers: list[bytes], index: int, source: str) -> tuple[bytes, int | None]:
    try:
        bv = doc["bufferViews"][index]
        data = buffers[bv["buffer"]]
    except (KeyError, IndexError):
        raise GltfError(f"{source}: bufferView {index} or its buffer does not exist") from None
    start = bv.get("byteOffset", 0)
    end = start + bv["byteLength"]
    if end > len(data):
        raise GltfError(f"{source}: bufferView {index} runs past its buffer")
    return data[start:end], bv.get("byteStride")


def accessor(doc: dict[str, Any], buffers: list[bytes], index: int, source: str = "<gltf>") -> NDArray[np.float64]:
    """Accessor ``index`` as float64 ``[count, width]`` (normalised integers scaled to [0,1]/[-1,1])."""
    try:
        acc = doc["accessors"][index]
        ctype, width, count = acc["componentType"], _WIDTH[acc["type"]], acc["count"]
        dtype = np.dtype(_COMPONENT[ctype]).newbyteorder("<")
    except (KeyError, IndexError, TypeError):
        raise GltfError(f"{source}: accessor {index} is missing or malformed") from None
    if not isinstance(count, int) or isinstance(count, bool) or not 0 <= count * width <= MAX_ELEMENTS:
        raise GltfError(f"{source}: accessor {index} count {repr(count)[:20]} is not 0..{MAX_ELEMENTS // width}")
    out = np.zeros((count, width))
    if "bufferView" in acc:
        raw, stride = _view(doc, buffers, acc["bufferView"], source)
        item = dtype.itemsize * width
        stride = stride or item
        offset = acc.get("byteOffset", 0)
        if count and offset + stride * (count - 1) + item > len(raw):
            raise GltfError(f"{source}: accessor {index} reads past its bufferView")
        if count:
            rows = np.ndarray((count,), dtype=np.dtype((np.void, item)), buffer=raw, offset=offset, strides=(stride,))
            with np.errstate(invalid="ignore"):  # a signalling NaN warns as it widens; it is refused below
                out = np.frombuffer(rows.tobytes(), dtype=dtype).reshape(count, width).astype(np.float64)
    sparse = acc.get("sparse")
    if sparse:
        n = sparse["count"]
        if not isinstance(n, int) or not 0 < n <= count:
            raise GltfError(f"{source}: accessor {index} has a sparse count outside 1..{count}")
        iraw, _ = _view(doc, buffers, sparse["indices"]["bufferView"], source)
        idt = np.dtype(_COMPONENT[sparse["indices"]["componentType"]]).newbyteorder("<")
        idx = np.frombuffer(iraw, dtype=idt, count=n, offset=sparse["indices"].get("byteOffset", 0)).astype(np.int64)
        if (idx < 0).any() or (idx >= count).any():
            raise GltfError(f"{source}: accessor {index} has sparse indices outside 0..{count - 1}")
        vraw, _ = _view(doc, buffers, sparse["values"]["bufferView"], source)
        vals = np.frombuffer(vraw, dtype=dtype, count=n * width, offset=sparse["values"].get("byteOffset", 0))
        with np.errstate(invalid="ignore"):
            out[idx] = vals.reshape(n, width)
    if acc.get("normalized") and ctype in _NORM:
        out = np.maximum(out / _NORM[ctype], -1.0)
    if not np.isfinite(out).all() or (out.size and np.abs(out).max() > 1e12):
        raise GltfError(f"{source}: accessor {index} holds NaN, infinite or absurd values")
    return out


def _decompose(m: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """TRS of a column-major glTF ``matrix`` (16 numbers)."""
    mat = np.asarray(m, dtype=np.float64).reshape(4, 4).T
    t = mat[:3, 3].copy()
    s = np.linalg.norm(mat[:3, :3], axis=0)
    r = mat[:3, :3] / np.where(s > 1e-12, s, 1.0)
    if np.linalg.det(r) < 0:
        s[0], r[:, 0] = -s[0], -r[:, 0]
    return t, quat.from_matrix(r), s


def _document(path: Path) -> tuple[dict[str, Any], list[bytes]]:
    source = str(path)
    try:
        data = read_bounded(path, MAX_FILE)
    except OSError as exc:
        raise GltfError(f"{source}: cannot read: {exc.strerror}") from None
    except ValueError as exc:
        raise GltfError(str(exc)) from None
    if data[:4] == _GLB_MAGIC:
        doc, glb_bin = parse_glb(data, source)
    else:
        try:
            doc, glb_bin = json.loads(data.decode("utf-8")), None
        except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
            raise GltfError(f"{source}: neither GLB nor glTF JSON: {type(exc).__name__}") from None
    if not isinstance(doc, dict) or not str(doc.get("asset", {}).get("version", "")).startswith("2"):
        raise GltfError(f"{source}: not a glTF 2.0 document (asset.version)")
    return doc, _buffers(doc, glb_bin, path.parent, source)


def read_gltf(path: str | os.PathLike[str]) -> GltfAsset:
    """Read nodes, skins and animations of a ``.glb`` or ``.gltf`` file.

    Raises:
        GltfError: whatever is wrong with the file: not glTF 2.0, truncated, too big (sizes
            and counts are checked before allocation), a node hierarchy with a cycle, NaN
            or absurd numbers, key times that are not finite and increasing, or a document
            whose parts have the wrong types.
    """
    p = Path(path)
    source = str(p)
    try:
        doc, buffers = _document(p)
        return _asset(doc, buffers, source)
    except GltfError:
        raise
    except _MALFORMED as exc:  # binascii.Error of a bad data URI is a ValueError too
        raise GltfError(f"{source}: malformed document ({type(exc).__name__}: {exc})"[:300]) from None


def _check_tree(parents: NDArray[np.int64], source: str) -> None:
    """Every node must hang from a scene root: a node that is its own (grand)child never does."""
    children: dict[int, list[int]] = {}
    for c, p in enumerate(parents.tolist()):
        children.setdefault(p, []).append(c)
    reached, todo = 0, list(children.get(-1, []))
    while todo:
        reached += 1
        todo.extend(children.get(todo.pop(), []))
    if reached != len(parents):
        raise GltfError(f"{source}: the node hierarchy has a cycle (a node is its own ancestor)")


def _asset(doc: dict[str, Any], buffers: list[bytes], source: str) -> GltfAsset:
    nodes = doc.get("nodes", [])
    n = len(nodes)
    if n > MAX_NODES:
        raise GltfError(f"{source}: {n} nodes; the limit is {MAX_NODES}")
    parents = np.full(n, -1, dtype=np.int64)
    trans, rot, scale = np.zeros((n, 3)), quat.identity(n), np.ones((n, 3))
    for i, node in enumerate(nodes):
        for c in node.get("children", []):
            if not 0 <= c < n or parents[c] != -1:
                raise GltfError(f"{source}: node {i} has a bad or shared child {c}")
            parents[c] = i
        if "matrix" in node:
            trans[i], rot[i], scale[i] = _decompose(node["matrix"])
        else:
            trans[i] = node.get("translation", (0.0, 0.0, 0.0))
            rot[i] = quat.normalize(quat.from_xyzw(node.get("rotation", (0.0, 0.0, 0.0, 1.0))))
            scale[i] = node.get("scale", (1.0, 1.0, 1.0))
    _check_tree(parents, source)
    if not (np.isfinite(trans).all() and np.isfinite(rot).all() and np.isfinite(scale).all()):
        raise GltfError(f"{source}: a node's translation, rotation or scale is not finite")
    skins = []
    for k, sk in enumerate(doc.get("skins", [])):
        joints = tuple(int(j) for j in sk.get("joints", []))
        if any(not 0 <= j < n for j in joints):
            raise GltfError(f"{source}: skin {k} names a joint node that does not exist")
        if "inverseBindMatrices" in sk:
            ibm = accessor(doc, buffers, sk["inverseBindMatrices"], source).reshape(-1, 4, 4).transpose(0, 2, 1)
        else:
            ibm = np.broadcast_to(np.eye(4), (len(joints), 4, 4)).copy()
        skins.append(GltfSkin(sk.get("name", f"skin{k}"), joints, ibm, sk.get("skeleton")))
    anims = []
    for a, anim in enumerate(doc.get("animations", [])):
        chans = []
        for ch in anim.get("channels", []):
            target = ch.get("target", {})
            if "node" not in target:
                continue  # targets of extensions (KHR_animation_pointer) are not ours
            try:
                sampler = anim["samplers"][ch["sampler"]]
            except (KeyError, IndexError):
                raise GltfError(f"{source}: animation {a} channel names a missing sampler") from None
            times = accessor(doc, buffers, sampler["input"], source)[:, 0]
            if len(times) and (np.abs(times).max() > MAX_TIME or (np.diff(times) < 0).any()):
                raise GltfError(f"{source}: animation {a}: key times must increase and stay within ±{MAX_TIME:g} s")
            values = accessor(doc, buffers, sampler["output"], source)
            interp = sampler.get("interpolation", "LINEAR")
            width = {"translation": 3, "scale": 3, "rotation": 4}.get(target["path"])
            if width is not None and values.shape[1] != width:
                raise GltfError(
                    f"{source}: animation {a}: {target['path']} keys have {values.shape[1]} numbers, not {width}"
                )
            if target["path"] == "rotation":
                values = quat.from_xyzw(values)
            if interp not in ("LINEAR", "STEP", "CUBICSPLINE"):
                raise GltfError(f"{source}: animation {a}: unknown interpolation {interp!r}")
            expected = len(times) * (3 if interp == "CUBICSPLINE" else 1)
            if target["path"] != "weights" and len(values) != expected:
                raise GltfError(f"{source}: animation {a}: {len(times)} keys but {len(values)} values")
            chans.append(GltfChannel(int(target["node"]), target["path"], interp, times, values))
        extra = anim.get("extras")
        anims.append(
            GltfAnimation(
                anim.get("name", f"animation{a}"), tuple(chans), dict(extra) if isinstance(extra, dict) else {}
            )
        )
    names = tuple(node.get("name") or f"node{i}" for i, node in enumerate(nodes))
    extras = tuple(dict(node.get("extras", {})) if isinstance(node.get("extras"), dict) else {} for node in nodes)
    return GltfAsset(names, parents, trans, rot, scale, extras, tuple(skins), tuple(anims), source)
