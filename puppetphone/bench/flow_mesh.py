"""Flow Curves on a mesh: one crystal tree bent along a stroke (thesis §3.5.1, Eq. 3.9 on mesh vertices).

The problem (:func:`mesh_tree_problem`) is tasbada's crystal tree — one triangle mesh, a
tube of 12 rings under an octahedron — planted on the ground, seen from the side, with
its principal curve as the SEcurve (§3.3.1) and a stroke up its right side that leans
further right as it rises (:func:`lean_stroke`). After the solve:

- ``flow_mesh_contact_error_px``: the largest screen distance any of the mesh's ground
  vertices moved (they rest on the ground, which never deforms; the goal is under 1 px);
- ``flow_mesh_base_tilt_deg_max``: the rotation of the lowest third of the bent mesh,
  fitted rigidly in 3D (:func:`~authoring.flowcurves.tilt.base_tilt_deg`), against the
  stated limit :data:`~authoring.flowcurves.tilt.MAX_BASE_TILT_DEG`;
- ``flow_mesh_bend_px``: how far the tree's top moved on screen (that it bent at all; its
  lowest ring, on the ground, moved by ``flow_mesh_contact_error_px``);
- ``flow_shape_residual_p90_px``: the 90th percentile distance of the constrained SEcurve
  samples from their places on the flow curve with the soft weight ``W_SHAPE`` of Eq. 3.12,
  against the same solve with the constraints made hard (weight 10⁵: the residual that
  remains is the 15-pixel grid's, it cannot take every 2-pixel sample exactly).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from puppetphone.bench.figures import Figure

if TYPE_CHECKING:
    from authoring.flowcurves.scene import FlowObject, FlowScene
    from authoring.flowcurves.securves import SECurve
    from authoring.flowcurves.session import FlowSession

__all__ = ["HARD_WEIGHT", "bend", "lean_stroke", "mesh_tree_problem", "run"]

from engine.arrays import F64 as F

HARD_WEIGHT = 1e5


def mesh_tree_problem(size: tuple[int, int] = (640, 480)) -> tuple[FlowScene, list[SECurve]]:
    """``(scene, securves)``: one crystal tree (a mesh) seen from the side, and its principal curve."""
    from authoring.flowcurves.adapters import scene_from_data
    from authoring.flowcurves.principal import principal_curve
    from authoring.flowcurves.scene import rasterize
    from authoring.flowcurves.securves import SECurve
    from engine.camera import OrbitCamera
    from games.tasbada.flow_scene import crystal_tree

    data = [{"name": "tree", "group": "tree", "primitives": [], "mesh": crystal_tree([0.0, 0.0, 0.0], 2.2, 0.4, 0)}]
    scene = scene_from_data(
        "mesh-tree", data, OrbitCamera(target=np.array([0.0, 1.25, 0.0]), yaw=0.0, pitch=0.05, distance=4.2), size
    )
    spine = principal_curve(rasterize(scene.objects[0], scene.camera, scene.size).pixels()).sample(48)
    return scene, [SECurve(spine, False, "principal", [0], spine)]


def lean_stroke(spine: F, gap: float = 14.0, lean: float = 0.0012) -> F:
    """A stroke from the foot of ``spine`` to above its top, ``gap`` px to its right, leaning right as it rises."""
    y = np.linspace(spine[:, 1].max(), spine[:, 1].min() - 15.0, 40)
    return np.c_[spine[:, 0].max() + gap + lean * (y.max() - y) ** 2, y]


def bend(weight: float | None = None, lean: float = 0.0012) -> tuple[FlowScene, FlowSession]:
    """The tree bent along :func:`lean_stroke`: ``(scene, session)`` (``weight``: the shape weight, default ``W_SHAPE``)."""
    from authoring.flowcurves import arap
    from authoring.flowcurves.session import FlowSession

    scene, securves = mesh_tree_problem()
    session = FlowSession(scene, securves=securves)
    if weight is not None:
        session.deformer.shape_weight = weight
    session.add("stroke", lean_stroke(securves[0].points, lean=lean))
    assert session.deformer.shape_weight == (arap.W_SHAPE if weight is None else weight)
    return scene, session


def contact_error_px(scene: FlowScene, bent: list[FlowObject]) -> float:
    """The largest screen move of a ground vertex of any mesh (rest ``scene`` against ``bent`` objects)."""
    from authoring.flowcurves.contacts import GROUND_TOLERANCE

    worst = 0.0
    for rest, moved in zip(scene.objects, bent):
        if rest.mesh is None or moved.mesh is None:
            continue
        low = rest.mesh.vertices[:, 1] <= GROUND_TOLERANCE
        a = scene.camera.project(rest.mesh.vertices[low], *scene.size)
        b = scene.camera.project(moved.mesh.vertices[low], *scene.size)
        worst = max(worst, float(np.linalg.norm(a - b, axis=1).max(initial=0.0)))
    return worst


def shape_residuals(session: FlowSession) -> F:
    """Distances (px) of every constrained SEcurve sample from its target on the flow curve."""
    from authoring.flowcurves.session import dense

    d, r = session.deformer, session.result
    out = []
    for seg, owners, target in d.segments([dense(f) for f in session.flows], session.all_securves()):
        for o, c, t in zip(owners, seg.c, target):
            out.append(float(np.linalg.norm((d.embeddings[o].grid.rows(c[None]) @ r.vertices[o])[0] - t)))
    return np.array(out)


def run() -> list[Figure]:
    """Contacts, base tilt and bend of the mesh tree; shape residual soft against hard."""
    from authoring.flowcurves.tilt import MAX_BASE_TILT_DEG, base_tilt_deg

    scene, session = bend()
    rest, moved = scene.objects[0].mesh, session.objects[0].mesh
    assert rest is not None and moved is not None  # the crystal tree is one mesh
    up = np.array([0.0, 1.0, 0.0])
    tilt = max(
        base_tilt_deg(o.mesh.vertices, b.mesh.vertices, up)
        for o, b in zip(scene.objects, session.objects)
        if o.mesh is not None and b.mesh is not None
    )
    shift = np.linalg.norm(
        scene.camera.project(moved.vertices, *scene.size) - scene.camera.project(rest.vertices, *scene.size), axis=1
    )
    top = float(shift[int(np.argmax(rest.vertices[:, 1]))])
    _, hard = bend(HARD_WEIGHT)
    return [
        Figure(
            "flow", "flow_mesh_contact_error_px", contact_error_px(scene, session.objects), "px", "the goal: 1 px", 1.0
        ),
        Figure("flow", "flow_mesh_base_tilt_deg_max", tilt, "deg", "the stated limit", MAX_BASE_TILT_DEG),
        Figure("flow", "flow_mesh_bend_px", top, "px"),
        Figure(
            "flow",
            "flow_shape_residual_p90_px",
            float(np.percentile(shape_residuals(session), 90)),
            "px",
            "the constraints made hard",
            float(np.percentile(shape_residuals(hard), 90)),
        ),
    ]
