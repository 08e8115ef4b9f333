"""The scene a phone gets once, on connect: a GLB of the field and of everything on it.

Written with the project's glTF container (:func:`engine.io.gltf_write.container_bytes`),
so any glTF tool can open it: the ground is a real mesh (a square of the field's size
with its snow colour as material), and the primitives of the step the phone joined
at ride in ``SHORT`` accessors, one per kind, quantised as
:mod:`input.web.scene_stream` does (the first delta frame builds on exactly these
rows). Scene extras carry what the page lights and clears with: sun, sky, horizon,
the column scales and the frame version; and the falling snow, if the game has one
(:class:`~engine.render.snowfall.Snowfall`: the flakes' start positions and phases in
a ``FLOAT VEC4`` accessor and the rule that moves them, which the page applies to the
step it shows, ``step_seconds`` each).
"""

from __future__ import annotations

import json
import struct
from dataclasses import asdict

import numpy as np

from engine.io.gltf_write import container_bytes
from engine.render.scene import RenderScene
from engine.render.snowfall import Snowfall
from input.web.scene_stream import FRAME_VERSION, KINDS, SCALES, MarksGrid, SceneState

__all__ = ["scene_glb", "read_scene_glb", "FIELD_HALF_SIZE"]

#: Half the side of the ground square the page draws (metres); the desktop's ground is unbounded.
FIELD_HALF_SIZE = 40.0


def _ground_mesh(half: float, height: float) -> tuple[bytes, bytes]:
    pos = np.array(
        [[-half, height, -half], [half, height, -half], [half, height, half], [-half, height, half]], dtype="<f4"
    )
    idx = np.array([0, 2, 1, 0, 3, 2], dtype="<u2")
    return pos.tobytes(), idx.tobytes()


def scene_glb(state: SceneState, scene: RenderScene, snowfall: Snowfall | None = None, dt: float = 1 / 60) -> bytes:
    """The GLB a phone starts from: ground mesh, ``state``'s rows, lighting and ``snowfall`` (moved by
    ``dt`` seconds a step) in the scene's extras."""
    chunks: list[bytes] = []
    views: list[dict] = []
    accessors: list[dict] = []

    def add(raw: bytes, component: int, count: int, kind: str, **extra: object) -> int:
        offset = sum(len(c) for c in chunks)
        chunks.append(raw + b"\0" * ((-len(raw)) % 4))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(raw)})
        accessors.append(
            {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": kind, **extra}
        )
        return len(accessors) - 1

    g = scene.ground
    pos, idx = _ground_mesh(FIELD_HALF_SIZE, g.height)
    p_acc = add(
        pos,
        5126,
        4,
        "VEC3",
        min=[-FIELD_HALF_SIZE, g.height, -FIELD_HALF_SIZE],
        max=[FIELD_HALF_SIZE, g.height, FIELD_HALF_SIZE],
    )
    i_acc = add(idx, 5123, 6, "SCALAR")
    rows = {}
    for kind in KINDS:
        data = state.rows[kind]
        rows[kind] = {
            "accessor": add(data.astype("<i2").tobytes(), 5122, int(data.size) or 1, "SCALAR") if data.size else None,
            "rows": int(len(data)),
            "columns": len(SCALES[kind]),
            "scales": list(SCALES[kind]),
        }
    marks = None
    if state.marks is not None:
        m = state.marks
        nz, nx = m.cells.shape
        marks = {
            "accessor": add(m.cells.tobytes(), 5121, int(m.cells.size), "SCALAR"),
            "nx": nx,
            "nz": nz,
            "x0": m.x0,
            "z0": m.z0,
            "cell": m.cell,
        }
    flakes = None
    if snowfall is not None:
        raw = np.column_stack([snowfall.start, snowfall.phase]).astype("<f4")
        flakes = {
            "accessor": add(raw.tobytes(), 5126, len(raw), "VEC4"),
            "count": len(raw),
            "speed": snowfall.speed,
            "height": snowfall.height,
            "sway": snowfall.sway,
            "sway_rates": list(snowfall.sway_rates),
            "size": snowfall.size,
            "color": list(snowfall.color),
            "step_seconds": dt,
        }
    blob = b"".join(chunks)
    cam = state.camera
    doc = {
        "asset": {"version": "2.0", "generator": "PuppetPhone scene stream"},
        "scene": 0,
        "scenes": [
            {
                "name": "field",
                "nodes": [0],
                "extras": {
                    "puppetphone": {
                        "version": FRAME_VERSION,
                        "step": state.step,
                        "rows": rows,
                        "marks": marks,
                        "snowfall": flakes,
                        "ground": asdict(g),
                        "sun": asdict(scene.sun),
                        "sky": list(scene.sky_color),
                        "horizon": list(scene.horizon_color),
                        "outline": list(scene.outline_color),
                        "camera": {"position": list(cam.position), "rotation": list(cam.rotation), "fov_y": cam.fov_y},
                    }
                },
            }
        ],
        "nodes": [{"name": "ground", "mesh": 0}],
        "meshes": [
            {"name": "ground", "primitives": [{"attributes": {"POSITION": p_acc}, "indices": i_acc, "material": 0}]}
        ],
        "materials": [
            {
                "name": "snow",
                "pbrMetallicRoughness": {
                    "baseColorFactor": [*g.color, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 0.9,
                },
            }
        ],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    return container_bytes(doc, blob, binary=True)


def read_scene_glb(data: bytes) -> tuple[dict, SceneState]:
    """The scene extras and the starting :class:`SceneState` of a GLB from :func:`scene_glb` (tests, bench)."""
    from input.web.scene_stream import CameraPose

    magic, _version, total = struct.unpack_from("<4sII", data)
    if magic != b"glTF" or total != len(data):
        raise ValueError("not a whole GLB")
    js_len, _ = struct.unpack_from("<I4s", data, 12)
    doc = json.loads(data[20 : 20 + js_len])
    blob = data[20 + js_len + 8 :]
    extras = doc["scenes"][0]["extras"]["puppetphone"]
    rows = {}
    for kind in KINDS:
        info = extras["rows"][kind]
        if info["accessor"] is None:
            rows[kind] = np.zeros((0, info["columns"]), dtype=np.int16)
            continue
        view = doc["bufferViews"][doc["accessors"][info["accessor"]]["bufferView"]]
        raw = np.frombuffer(blob, "<i2", view["byteLength"] // 2, view["byteOffset"])
        rows[kind] = raw.reshape(info["rows"], info["columns"]).astype(np.int16)
    marks = None
    if extras["marks"] is not None:
        info = extras["marks"]
        view = doc["bufferViews"][doc["accessors"][info["accessor"]]["bufferView"]]
        cells = np.frombuffer(blob, np.uint8, view["byteLength"], view["byteOffset"]).reshape(info["nz"], info["nx"])
        marks = MarksGrid(cells.copy(), info["x0"], info["z0"], info["cell"])
    cam = extras["camera"]
    state = SceneState(
        extras["step"], 0.0, CameraPose(tuple(cam["position"]), tuple(cam["rotation"]), cam["fov_y"]), rows, marks
    )
    return extras, state
