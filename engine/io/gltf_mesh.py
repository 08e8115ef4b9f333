"""glTF skinned meshes: the triangles, skin weights and base colour a character is drawn with.

:mod:`engine.io.gltf` reads what motion needs (nodes, skins, animations); this module reads
what drawing a character needs from the same document: every primitive of every mesh that a
skinned node uses (POSITION, NORMAL, TEXCOORD_0, JOINTS_0, WEIGHTS_0, indices) and its
material's base colour factor and texture. Every count is checked against a limit before any
array is made, every index against what it indexes, and the weights are renormalised to sum
to one (exporters round them) — a file that breaks a rule is refused in one line.

Morph targets and second UV or weight sets are not drawn: :func:`read_skinned_meshes` says so
once in :attr:`SkinnedMeshes.ignored` rather than failing, as engines do.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.io.gltf import _MALFORMED, GltfError, _document, _view, accessor

__all__ = ["SkinnedPrimitive", "SkinnedMeshes", "read_skinned_meshes", "MAX_VERTICES", "MAX_TEXTURE_SIDE"]

MAX_VERTICES = 1 << 20  # per primitive; a film-quality character has ~100,000
MAX_TRIANGLES = 1 << 21
MAX_TEXTURE_SIDE = 8192
MAX_PRIMITIVES = 256
_TRIANGLES = 4


@dataclass(frozen=True)
class SkinnedPrimitive:
    """One drawable piece of a skinned mesh, in the skin's bind space.

    Attributes:
        positions, normals: ``[V,3]`` float32.
        uv: ``[V,2]`` float32 (zeros when the file has none).
        joints: ``[V,4]`` uint16 indices into the skin's joint list.
        weights: ``[V,4]`` float32, each row summing to one.
        indices: ``[3T]`` uint32 triangle corners.
        color: base colour factor, linear RGBA.
        texture: ``[H,W,4]`` uint8 sRGB base colour image, or None.
    """

    positions: NDArray[np.float32]
    normals: NDArray[np.float32]
    uv: NDArray[np.float32]
    joints: NDArray[np.uint16]
    weights: NDArray[np.float32]
    indices: NDArray[np.uint32]
    color: tuple[float, float, float, float]
    texture: NDArray[np.uint8] | None


@dataclass(frozen=True)
class SkinnedMeshes:
    """The skinned primitives of one skin, and what of the file was left out (for one warning)."""

    skin: int
    primitives: tuple[SkinnedPrimitive, ...]
    ignored: tuple[str, ...]


def _int(value: Any, what: str, limit: int, source: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < limit:
        raise GltfError(f"{source}: {what} {repr(value)[:20]} is not 0..{limit - 1}")
    return value


def _texture(
    doc: dict[str, Any], buffers: list[bytes], material: dict[str, Any], source: str
) -> NDArray[np.uint8] | None:
    """The base colour image of ``material``, decoded, or None when it has none or it lives outside the file."""
    info = material.get("pbrMetallicRoughness", {}).get("baseColorTexture")
    if info is None:
        return None
    textures = doc.get("textures", [])
    tex = textures[_int(info.get("index"), "texture index", len(textures), source)]
    images = doc.get("images", [])
    image = images[_int(tex.get("source"), "image index", len(images), source)]
    if "bufferView" not in image:
        return None  # an image beside the file: drawn in its base colour factor instead (said as ignored)
    raw, _ = _view(doc, buffers, image["bufferView"], source)
    from PIL import Image  # here: a puppet without textures (every start of the built-in one) never loads Pillow

    try:
        with Image.open(io.BytesIO(raw)) as img:
            w, h = img.size
            if not (0 < w <= MAX_TEXTURE_SIDE and 0 < h <= MAX_TEXTURE_SIDE):
                raise GltfError(f"{source}: a texture of {w}x{h}; the limit is {MAX_TEXTURE_SIDE} a side")
            return np.asarray(img.convert("RGBA"), dtype=np.uint8).copy()
    except (OSError, Image.DecompressionBombError) as exc:
        raise GltfError(f"{source}: a base colour texture cannot be decoded: {exc}") from None


def _primitive(
    doc: dict[str, Any], buffers: list[bytes], prim: dict[str, Any], joints: int, source: str
) -> SkinnedPrimitive:
    attrs = prim.get("attributes", {})
    pos = accessor(doc, buffers, attrs["POSITION"], source)
    v = len(pos)
    if not 0 < v <= MAX_VERTICES or pos.shape[1] != 3:
        raise GltfError(f"{source}: a primitive has {v} positions; 1..{MAX_VERTICES} of 3 numbers are allowed")

    def per_vertex(name: str, width: int) -> NDArray[np.float64] | None:
        if name not in attrs:
            return None
        a = accessor(doc, buffers, attrs[name], source)
        if a.shape != (v, width):
            raise GltfError(f"{source}: {name} has shape {a.shape}, not ({v}, {width})")
        return a

    joint_idx, weights = per_vertex("JOINTS_0", 4), per_vertex("WEIGHTS_0", 4)
    if joint_idx is None or weights is None:
        raise GltfError(f"{source}: a skinned primitive has no JOINTS_0/WEIGHTS_0")
    if (joint_idx < 0).any() or (joint_idx >= joints).any() or (joint_idx != np.round(joint_idx)).any():
        raise GltfError(f"{source}: JOINTS_0 names joints outside the skin's 0..{joints - 1}")
    weights = np.where(weights > 0.0, weights, 0.0)
    total = weights.sum(axis=1)
    if (total <= 1e-6).any():
        raise GltfError(f"{source}: {int((total <= 1e-6).sum())} vertices have no skin weight")
    weights = weights / total[:, None]
    normals = per_vertex("NORMAL", 3)
    idx = accessor(doc, buffers, prim["indices"], source)[:, 0] if "indices" in prim else np.arange(v, dtype=np.float64)
    if len(idx) % 3 or len(idx) > 3 * MAX_TRIANGLES or (idx < 0).any() or (idx >= v).any():
        raise GltfError(f"{source}: a primitive's indices are not whole triangles within its {v} vertices")
    if normals is None:
        normals = _face_normals(pos, idx.astype(np.int64))
    uv = per_vertex("TEXCOORD_0", 2)
    materials = doc.get("materials", [])
    material = materials[_int(prim["material"], "material", len(materials), source)] if "material" in prim else {}
    factor = material.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])
    color = np.clip(np.asarray(factor, dtype=np.float64).reshape(4), 0.0, 1.0)
    return SkinnedPrimitive(
        positions=pos.astype(np.float32),
        normals=normals.astype(np.float32),
        uv=(uv if uv is not None else np.zeros((v, 2))).astype(np.float32),
        joints=joint_idx.astype(np.uint16),
        weights=weights.astype(np.float32),
        indices=idx.astype(np.uint32),
        color=(float(color[0]), float(color[1]), float(color[2]), float(color[3])),
        texture=_texture(doc, buffers, material, source),
    )


def _face_normals(pos: NDArray[np.float64], idx: NDArray[np.int64]) -> NDArray[np.float64]:
    """Area-weighted vertex normals, for files that leave NORMAL out (the spec asks for flat ones)."""
    tri = idx.reshape(-1, 3)
    face = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
    out = np.zeros_like(pos)
    for k in range(3):
        np.add.at(out, tri[:, k], face)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)


def _has_texture(doc: dict[str, Any], prim: dict[str, Any]) -> bool:
    materials = doc.get("materials", [])
    m = prim.get("material")
    return (
        isinstance(m, int)
        and 0 <= m < len(materials)
        and "baseColorTexture" in materials[m].get("pbrMetallicRoughness", {})
    )


def read_skinned_meshes(path: str | os.PathLike[str], skin: int = 0) -> SkinnedMeshes:
    """The triangle primitives of every node skinned by ``skin`` in a ``.glb``/``.gltf`` file.

    Raises:
        GltfError: no such skin, no mesh uses it, or any count, index or value out of range.
    """
    p = Path(path)
    source = str(p)
    try:
        doc, buffers = _document(p)
        skins = doc.get("skins", [])
        _int(skin, "skin", max(len(skins), 1), source)
        if not skins:
            raise GltfError(f"{source}: has no skin: nothing to draw a character with")
        joints = len(skins[skin].get("joints", []))
        meshes = doc.get("meshes", [])
        ignored: set[str] = set()
        prims: list[SkinnedPrimitive] = []
        for node in doc.get("nodes", []):
            if node.get("skin") != skin or "mesh" not in node:
                continue
            mesh = meshes[_int(node["mesh"], "mesh", len(meshes), source)]
            for prim in mesh.get("primitives", []):
                if prim.get("mode", _TRIANGLES) != _TRIANGLES:
                    ignored.add("primitives that are not triangles")
                    continue
                if prim.get("targets"):
                    ignored.add("morph targets")
                if {"JOINTS_1", "WEIGHTS_1"} & set(prim.get("attributes", {})):
                    ignored.add("more than 4 weights per vertex")
                if len(prims) >= MAX_PRIMITIVES:
                    raise GltfError(f"{source}: more than {MAX_PRIMITIVES} skinned primitives")
                built = _primitive(doc, buffers, prim, joints, source)
                if built.texture is None and _has_texture(doc, prim):
                    ignored.add("base colour textures kept outside the file")
                prims.append(built)
        if not prims:
            raise GltfError(f"{source}: no mesh is skinned by skin {skin}")
        return SkinnedMeshes(skin, tuple(prims), tuple(sorted(ignored)))
    except GltfError:
        raise
    except _MALFORMED as exc:
        raise GltfError(f"{source}: malformed mesh data ({type(exc).__name__}: {str(exc)[:80]})") from None
