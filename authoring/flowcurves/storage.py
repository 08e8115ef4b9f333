"""Flow files: the edits of a flow session and the deformed scenery, as one JSON document.

::

    {"format": "puppetphone-flow", "version": 1, "scene": "snowman", "size": [1280, 720],
     "camera": {"target": [x, y, z], "yaw": .., "pitch": .., "distance": ..},
     "edits": [{"kind": "stroke" | "centre" | "securve", "points": [[x, y], ...], "d_max": 60}],
     "objects": [{"name": "tree0.trunk", "group": "tree0",
                  "primitives": [{"a": [x, y, z], "b": [x, y, z], "radius": r, "color": [r, g, b]}],
                  "mesh": {"vertices": [[x, y, z], ...], "faces": [[i, j, k], ...], "color": [r, g, b],
                           "face_colors": [[r, g, b], ...]}}]}

An object has primitives, a mesh, or both (``mesh`` and ``face_colors`` may be left out).

The edits reopen the session in the editor; ``objects`` is the deformed static scenery a
game starts in (``puppetphone play snowman --flow FILE``), so a game needs no solver.
:func:`parse_flow` is the one validation boundary: sizes are bounded before anything
is built, every number is checked finite and in range, and any fault is one
:class:`FlowFileError` line. Files are written atomically (temporary file + rename).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from engine.atomic import atomic_write_bytes
from engine.errors import FormatError
from engine.npz_safe import read_bounded

if TYPE_CHECKING:
    from authoring.flowcurves.session import FlowSession

__all__ = [
    "FlowFileError",
    "parse_flow",
    "parse_objects",
    "load_flow",
    "save_flow",
    "flow_document",
    "FORMAT",
    "VERSION",
    "MAX_FILE",
]

FORMAT, VERSION = "puppetphone-flow", 1
MAX_FILE = 8 * 1024 * 1024
MAX_EDITS, MAX_POINTS, MAX_OBJECTS, MAX_PRIMITIVES = 1000, 20000, 5000, 64
MAX_COORD = 1e6
MAX_TOTAL_VERTICES = 200000
KINDS = ("stroke", "centre", "securve")


class FlowFileError(FormatError):
    """A flow file that cannot be used (one line says why)."""


def _num(v: Any, what: str, lo: float = -MAX_COORD, hi: float = MAX_COORD) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
        raise FlowFileError(f"{what} must be a number in [{lo:g}, {hi:g}], not {v!r}"[:200])
    return float(v)


def _vec(v: Any, n: int, what: str, lo: float = -MAX_COORD, hi: float = MAX_COORD) -> list[float]:
    if not isinstance(v, list) or len(v) != n:
        raise FlowFileError(f"{what} must be a list of {n} numbers")
    return [_num(x, what, lo, hi) for x in v]


def _list(d: dict[str, Any], key: str, limit: int, what: str) -> list[Any]:
    v = d.get(key)
    if not isinstance(v, list):
        raise FlowFileError(f"{what} must be a list")
    if len(v) > limit:
        raise FlowFileError(f"{what}: {len(v)} entries, more than {limit}")
    return v


def _dict(v: Any, what: str) -> dict[str, Any]:
    if not isinstance(v, dict):
        raise FlowFileError(f"{what} must be an object")
    return v


def parse_objects(value: Any) -> list[dict[str, Any]]:
    """Validate the deformed objects of a flow document (also as a recording's set-up carries them)."""
    objects = []
    names = set()
    budget = [MAX_TOTAL_VERTICES]
    for o in _list({"objects": value}, "objects", MAX_OBJECTS, "objects"):
        o = _dict(o, "an object")
        name, group = o.get("name"), o.get("group")
        if not isinstance(name, str) or not isinstance(group, str) or not 0 < len(name) <= 200 or len(group) > 200:
            raise FlowFileError("an object needs a name and a group")
        if name in names:
            raise FlowFileError(f"object {name!r} appears twice"[:200])
        names.add(name)
        prims = []
        for p in _list(
            {"primitives": o.get("primitives", [])}, "primitives", MAX_PRIMITIVES, f"primitives of {name!r}"[:200]
        ):
            p = _dict(p, "a primitive")
            prims.append(
                {
                    "a": _vec(p.get("a"), 3, "a primitive end"),
                    "b": _vec(p.get("b"), 3, "a primitive end"),
                    "radius": _num(p.get("radius"), "a primitive radius", 1e-4, 1e3),
                    "color": _vec(p.get("color"), 3, "a primitive colour", 0.0, 1.0),
                }
            )
        entry: dict[str, Any] = {"name": name, "group": group, "primitives": prims}
        if o.get("mesh") is not None:
            entry["mesh"] = _mesh(o["mesh"], f"the mesh of {name!r}"[:200], budget)
        if not prims and "mesh" not in entry:
            raise FlowFileError(f"object {name!r} has no primitives and no mesh"[:200])
        objects.append(entry)
    return objects


def _mesh(value: Any, what: str, budget: list[int]) -> dict[str, Any]:
    """A mesh's vertices, triangles and colours, bounded (``budget``: vertices left for the whole file)."""
    from authoring.flowcurves.mesh import MAX_MESH_TRIANGLES, MAX_MESH_VERTICES

    m = _dict(value, what)
    verts = _list(m, "vertices", MAX_MESH_VERTICES, f"{what}: vertices")
    budget[0] -= len(verts)
    if budget[0] < 0:
        raise FlowFileError(f"more than {MAX_TOTAL_VERTICES} mesh vertices in all")
    if len(verts) < 3:
        raise FlowFileError(f"{what} needs at least 3 vertices")
    faces = _list(m, "faces", MAX_MESH_TRIANGLES, f"{what}: faces")
    if not faces:
        raise FlowFileError(f"{what} has no triangle")
    out: dict[str, Any] = {
        "vertices": [_vec(v, 3, "a mesh vertex") for v in verts],
        "faces": [[int(_num(i, "a triangle corner", 0, len(verts) - 1)) for i in _ints(f)] for f in faces],
        "color": _vec(m.get("color", [0.6, 0.6, 0.6]), 3, "a mesh colour", 0.0, 1.0),
    }
    if m.get("face_colors") is not None:
        colors = _list(m, "face_colors", MAX_MESH_TRIANGLES, f"{what}: face colours")
        if len(colors) != len(faces):
            raise FlowFileError(f"{what}: one face colour per triangle")
        out["face_colors"] = [_vec(c, 3, "a face colour", 0.0, 1.0) for c in colors]
    return out


def _ints(v: Any) -> list[Any]:
    if not isinstance(v, list) or len(v) != 3 or not all(isinstance(i, int) and not isinstance(i, bool) for i in v):
        raise FlowFileError("a triangle must be three whole vertex indices")
    return v


def parse_flow(doc: Any) -> dict[str, Any]:
    """Validate a decoded flow document; returns it normalised (floats, known keys only)."""
    d = _dict(doc, "a flow file")
    if d.get("format") != FORMAT or d.get("version") != VERSION:
        raise FlowFileError(f"not a {FORMAT} file of version {VERSION}")
    scene = d.get("scene")
    if not isinstance(scene, str) or not 0 < len(scene) <= 200:
        raise FlowFileError("scene must be a name")
    size = [int(_num(x, "size", 1, 8192)) for x in _vec(d.get("size"), 2, "size", 1, 8192)]
    cam = _dict(d.get("camera"), "camera")
    camera = {
        "target": _vec(cam.get("target"), 3, "camera target"),
        "yaw": _num(cam.get("yaw"), "camera yaw"),
        "pitch": _num(cam.get("pitch"), "camera pitch", -1.6, 1.6),
        "distance": _num(cam.get("distance"), "camera distance", 1e-3, 1e4),
    }
    edits = []
    total = 0
    for e in _list(d, "edits", MAX_EDITS, "edits"):
        e = _dict(e, "an edit")
        if e.get("kind") not in KINDS:
            raise FlowFileError(f"edit kind must be one of {', '.join(KINDS)}, not {e.get('kind')!r}"[:200])
        pts = _list(e, "points", MAX_POINTS, "edit points")
        total += len(pts)
        if total > MAX_POINTS:
            raise FlowFileError(f"more than {MAX_POINTS} edit points in all")
        if not pts or (e["kind"] != "centre" and len(pts) < 2):
            raise FlowFileError(f"a {e['kind']} edit needs {'a point' if e['kind'] == 'centre' else 'two points'}")
        edits.append(
            {
                "kind": e["kind"],
                "points": [_vec(p, 2, "an edit point") for p in pts],
                "d_max": _num(e.get("d_max", 60.0), "d_max", 1.0, 10000.0),
            }
        )
    objects = parse_objects(d.get("objects"))
    return {
        "format": FORMAT,
        "version": VERSION,
        "scene": scene,
        "size": size,
        "camera": camera,
        "edits": edits,
        "objects": objects,
    }


def load_flow(path: Path) -> dict[str, Any]:
    """Read and validate a flow file (:class:`FlowFileError` for anything wrong, missing included)."""
    try:
        raw = read_bounded(Path(path), MAX_FILE)
    except FileNotFoundError:
        raise FlowFileError(f"{path}: no such file") from None
    except (OSError, ValueError) as exc:
        raise FlowFileError(f"{path}: {exc}") from None
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise FlowFileError(f"{path}: not JSON ({str(exc)[:80]})") from None
    return parse_flow(doc)


def flow_document(session: FlowSession) -> dict[str, Any]:
    """A session's edits and deformed objects as a flow document."""
    from authoring.flowcurves.adapters import mesh_data
    from engine.camera import OrbitCamera

    cam = session.scene.camera
    assert isinstance(cam, OrbitCamera)  # a flow file keeps an orbit view (its scenes are seen through one)

    objects = [
        {
            "name": o.name,
            "group": o.group,
            "primitives": [
                {
                    "a": [round(float(v), 6) for v in p.a],
                    "b": [round(float(v), 6) for v in p.b],
                    "radius": float(p.radius),
                    "color": [float(c) for c in p.color],
                }
                for p in o.primitives
            ],
            **({"mesh": mesh_data(o.mesh)} if o.mesh is not None else {}),
        }
        for o in session.objects
    ]
    return {
        "format": FORMAT,
        "version": VERSION,
        "scene": session.scene.name,
        "size": list(session.scene.size),
        "camera": {
            "target": [float(v) for v in cam.target],
            "yaw": float(cam.yaw),
            "pitch": float(cam.pitch),
            "distance": float(cam.distance),
        },
        "edits": [e.as_json() for e in session.edits],
        "objects": objects,
    }


def save_flow(session: FlowSession, path: Path) -> None:
    """Write the session atomically (checked by the same parser a reader uses)."""
    doc = parse_flow(flow_document(session))
    atomic_write_bytes(Path(path), json.dumps(doc, separators=(",", ":")).encode("utf-8"))
