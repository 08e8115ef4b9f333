"""The mesh figures of ``bench flow``: a crystal tree bent along a stroke holds its foot within 1 px and its
base within the tilt limit; the scripted Fig. 3.7 edit is one operation through the editor and bends it."""

from __future__ import annotations

import numpy as np

from authoring.flowcurves.tilt import MAX_BASE_TILT_DEG
from puppetphone.bench.flow import perform
from puppetphone.bench.flow_mesh import lean_stroke, mesh_tree_problem, run


def test_the_mesh_figures_meet_their_goals() -> None:
    figures = {f.name: f for f in run()}
    assert figures["flow_mesh_contact_error_px"].value < 1.0
    assert figures["flow_mesh_base_tilt_deg_max"].value <= MAX_BASE_TILT_DEG
    assert figures["flow_mesh_bend_px"].value > 40.0
    soft, hard = figures["flow_shape_residual_p90_px"].value, figures["flow_shape_residual_p90_px"].baseline_value
    assert hard is not None and hard < soft < 2.0


def test_the_fig_3_7_script_is_one_operation_that_bends_the_tree() -> None:
    from authoring.flow_tool import FlowTool
    from authoring.flowcurves.session import FlowSession

    scene, securves = mesh_tree_problem()
    activity = FlowTool(FlowSession(scene, securves=securves), None)
    pts = [(float(x), float(y)) for x, y in lean_stroke(securves[0].points)]
    steps = [[("press", *pts[0], False)], *[[("move", *p)] for p in pts[1:]], [("release", *pts[-1])]]
    assert perform(activity, steps) == 1
    assert activity.session is not None
    moved = activity.session.objects[0].mesh
    assert moved is not None and scene.objects[0].mesh is not None
    assert np.abs(moved.vertices - scene.objects[0].mesh.vertices).max() > 0.1
