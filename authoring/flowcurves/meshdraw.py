"""Drawing a flow scene's (bent) meshes with the renderer's skinned-mesh path.

The renderer keeps a GPU copy of every mesh it is given, once, and moves it by joint
matrices; a bent mesh must not become a new upload at every solve. So a flow mesh is
uploaded once, at rest, with **one joint per vertex** (weight 1), and drawn bent by
translation matrices ``v'_i − v_i`` — the displacement Eq. 3.9 gave that vertex. The
normals stay those of the rest mesh (a translation does not turn them): lighting on a
strongly bent part is the rest shape's, which is what a screen-space edit expects
(§3.5.1: "movement edits are screen-space refinements"). Faces are split by colour into
primitives that share the vertices' joints.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from authoring.flowcurves.mesh import TriMesh
from engine.io.gltf_mesh import SkinnedMeshes, SkinnedPrimitive
from engine.render.scene import SkinnedInstance

__all__ = ["MeshDrawer", "vertex_normals"]

from engine.arrays import F64 as F


def vertex_normals(vertices: F, faces: NDArray[np.int64]) -> F:
    """Area-weighted vertex normals (unit; ``+y`` where no face touches a vertex)."""
    fn = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    n = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(n, faces[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 1e-12, n / np.maximum(length, 1e-12), [0.0, 1.0, 0.0])


def _skinned(mesh: TriMesh) -> SkinnedMeshes:
    v = len(mesh.vertices)
    joints = np.zeros((v, 4), dtype=np.uint16)
    joints[:, 0] = np.arange(v)
    weights = np.zeros((v, 4), dtype=np.float32)
    weights[:, 0] = 1.0
    positions = mesh.vertices.astype(np.float32)
    normals = vertex_normals(mesh.vertices, mesh.faces).astype(np.float32)
    uv = np.zeros((v, 2), dtype=np.float32)
    colors = mesh.colors()
    prims = []
    for c in np.unique(colors, axis=0):
        faces = mesh.faces[(colors == c).all(axis=1)]
        r, g, b = (float(x) for x in np.asarray(c) ** 2.2)
        prims.append(
            SkinnedPrimitive(
                positions,
                normals,
                uv,
                joints,
                weights,
                np.ascontiguousarray(faces.ravel(), dtype=np.uint32),
                (r, g, b, 1.0),
                None,
            )
        )
    return SkinnedMeshes(0, tuple(prims), ())


class MeshDrawer:
    """The skinned copy of each rest mesh (made once, keyed by the rest mesh) and its bent instances."""

    def __init__(self) -> None:
        self._meshes: dict[int, tuple[TriMesh, SkinnedMeshes]] = {}

    def instance(self, rest: TriMesh, bent: TriMesh) -> SkinnedInstance:
        """``bent`` (the same triangles as ``rest``) as translations of ``rest``'s uploaded vertices."""
        key = id(rest)
        if key not in self._meshes:  # the rest mesh is kept with its copy, so its id stays its own
            self._meshes[key] = (rest, _skinned(rest))
        matrices = np.tile(np.eye(4), (len(rest.vertices), 1, 1))
        matrices[:, :3, 3] = bent.vertices - rest.vertices
        return SkinnedInstance(self._meshes[key][1], matrices)
