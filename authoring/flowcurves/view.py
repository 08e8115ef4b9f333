"""Drawing a flow session: the (deformed) objects, their SEcurves and the flow curves.

Curves live on the screen; to draw them with the scene's line renderer they are put on
a plane just in front of the camera (their pixels unchanged), so they show over the
objects they belong to. SEcurves are drawn where the bent objects carry them. Meshes go
through :class:`~authoring.flowcurves.meshdraw.MeshDrawer`, one per process: the renderer
keeps a GPU copy per mesh object it is given, so the rest meshes are given, once each.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from authoring.flowcurves.meshdraw import MeshDrawer
from authoring.flowcurves.scene import FlowObject, FlowScene, pixel_rays
from engine.render.scene import RenderScene

if TYPE_CHECKING:
    from authoring.flowcurves.session import FlowSession

__all__ = ["draw_objects", "draw_screen_polyline", "draw_session", "SECURVE_COLOR", "FLOW_COLOR"]

SECURVE_COLOR = (0.15, 0.45, 1.0)
FLOW_COLOR = (0.75, 0.2, 0.85)
CENTRE_COLOR = (1.0, 0.85, 0.1)
_NEAR = 0.5  # metres in front of the eye where screen curves are drawn
_MESHES = MeshDrawer()


def draw_objects(scene: RenderScene, objects: list[FlowObject], rest: list[FlowObject] | None = None) -> None:
    """Spheres, capsules and meshes of every object; ``rest`` (same order, default ``objects``) are
    the undeformed objects whose meshes the bent ones are drawn as."""
    for bent, still in zip(objects, rest if rest is not None else objects):
        if bent.mesh is not None and still.mesh is not None:
            scene.skinned.append(_MESHES.instance(still.mesh, bent.mesh))
    caps = [(p.a, p.b, p.radius, p.color) for o in objects for p in o.primitives if not p.is_sphere]
    balls = [(p.a, p.radius, p.color) for o in objects for p in o.primitives if p.is_sphere]
    if caps:
        a, b, r, c = (np.array(v) for v in zip(*caps))
        scene.add_capsules(a, b, r, color=c)
    if balls:
        a, r, c = (np.array(v) for v in zip(*balls))
        scene.add_spheres(a, r, color=c)


def draw_screen_polyline(
    scene: RenderScene,
    flow: FlowScene,
    xy: NDArray[np.float64],
    color: tuple[float, float, float],
    width: float = 3.0,
    closed: bool = False,
) -> None:
    """A pixel polyline drawn over everything."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if len(xy) < 2:
        return
    pts = flow.camera.eye + _NEAR * pixel_rays(flow.camera, xy, flow.size)
    scene.add_polyline(pts, color=color, width=width, closed=closed)


def draw_session(
    scene: RenderScene,
    session: FlowSession,
    show_securves: bool = True,
    pending: Sequence[tuple[float, float]] | None = None,
) -> None:
    """The deformed scene, its SEcurves (blue), flow curves (purple), centre-point and a stroke in progress."""
    from authoring.flowcurves.session import dense

    flow = session.scene
    draw_objects(scene, session.objects, flow.objects)
    if show_securves:
        curves, segments = session.bent_curves()
        for s, pts in zip(session.all_securves(), curves):
            draw_screen_polyline(scene, flow, pts, SECURVE_COLOR, 2.0, s.closed)
        for pts in segments:
            draw_screen_polyline(scene, flow, pts, (0.1, 0.9, 0.9), 4.0)
    for f in session.flows:
        draw_screen_polyline(scene, flow, dense(f), FLOW_COLOR, 4.0)
    for e in session.edits:
        if e.kind == "centre":
            t = np.linspace(0, 2 * np.pi, 25)
            draw_screen_polyline(scene, flow, e.points[0] + 10 * np.c_[np.cos(t), np.sin(t)], CENTRE_COLOR, 4.0)
    if pending is not None and len(pending) > 1:
        draw_screen_polyline(scene, flow, np.asarray(pending), (1.0, 1.0, 1.0), 2.0)
