"""Flow Curves: one interactive solve of the whole snowman field (thesis §3.5.3).

``flow_solve_ms_40_objects`` is what a stroke costs while it is dragged over the field:
the ARAP local/global iterations (:data:`~authoring.flowcurves.deform.ITERATIONS`) on
the grids of all 45 static objects (6 trees of 7 parts, 3 rocks) with every contact
kept, after the system was factorised once (``scipy.sparse.linalg.splu``). The goal is
a frame, 16 ms. The baseline solves the very same KKT system densely (``numpy.linalg.solve``)
in each iteration; ``flow_solve_cpu_ms_40_objects`` is the same solve in process CPU time
(these 2 cores are shared by several sessions: wall time includes waiting for a core; the
solve is single-threaded, so CPU time is what it costs). ``flow_factor_ms_40_objects`` is the one-off factorisation when the
constraint rows change (a new stroke: building the rows from the grids, then the LU),
against the solve it enables.

``flow_ops_*`` count the operations (pointer presses — each stroke, circle or drag is one —
and keys) of the thesis' edits reproduced as scripts in the editor (:data:`THESIS_EDITS`):

- ``flow_ops_fig3_6_grouping`` — Fig. 3.6: a centre-point sketched as a circle over the field,
  then its grouping radius d_Max widened twice (``]``), so the network groups more SEcurves;
- ``flow_ops_fig3_7_one_stroke`` — Fig. 3.7: one stroke up a crystal tree's SEcurve, and the
  tree (one mesh) bends along it (:mod:`puppetphone.bench.flow_mesh`);
- ``flow_ops_centre_point`` — Fig. 3.8: a centre-point sketched, then dragged, the field
  re-bending live (``author flow --script centre``);
- ``flow_ops_row_of_trees`` — Fig. 3.9's kind of edit: a row of trees bent along one stroke
  (``author flow --script row``).

They are stated alone, with no baseline: Table 3.1 counts the clicks of two artists matching
target scenes of their own design, in Maya and in the thesis' tool; no person and no
comparable task is involved here, so these are not compared with it.
``flow_update_ms_*`` is the editor's wall time for that edit's updates (correspondence,
network, factorisation when the rows change, solve), median, against one 60 Hz frame.
``flow_drag_*``: see :mod:`puppetphone.bench.flow_drag`; ``flow_mesh_*`` and ``flow_shape_residual_p90_px``:
see :mod:`puppetphone.bench.flow_mesh`.

Every object gets a flow curve: each group's principal curve, bent, so all 45 objects
and their 81 contacts are in the system; the repeats move the targets a little (a drag).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from authoring.flow_tool import FlowTool
from authoring.flowcurves.deform import ITERATIONS, SceneDeformer
from authoring.flowcurves.principal import principal_curve
from authoring.flowcurves.scene import FlowScene
from authoring.flowcurves.securves import SECurve
from games.snowman.bent_scenery import flow_scene
from puppetphone.bench.figures import Figure, median_time
from puppetphone.bench.flow_drag import drag_figures
from puppetphone.bench.flow_mesh import lean_stroke, mesh_tree_problem
from puppetphone.bench.flow_mesh import run as mesh_figures

__all__ = ["run", "field_problem", "THESIS_EDITS", "perform"]

Op = tuple


def _drag(points: list[tuple[float, float]]) -> list[list[Op]]:
    """A press, moves and a release, one a step."""
    return [[("press", *points[0], False)], *[[("move", *p)] for p in points[1:]], [("release", *points[-1])]]


def _circle(cx: float, cy: float, r: float) -> list[tuple[float, float]]:
    return [(cx + r * float(np.cos(a)), cy + r * float(np.sin(a))) for a in np.linspace(0.0, 2.0 * np.pi, 24)]


#: The thesis' edits as scripts of tool operations, one list per step (Fig. 3.6 and 3.8 on the snowman
#: field; Fig. 3.7 on the crystal tree, where the stroke is laid along its SEcurve when performed).
THESIS_EDITS: dict[str, list[list[Op]]] = {
    "fig3_6_grouping": _drag(_circle(640.0, 120.0, 22.0)) + [[("key", "]", False)], [("key", "]", False)]],
}


def field_problem() -> tuple[FlowScene, SceneDeformer, list[SECurve], Callable[[int], list[np.ndarray]]]:
    """The field's deformer, one SEcurve per group (principal curves) and a bend for each."""
    scene = flow_scene()
    deformer = SceneDeformer(scene)
    groups: dict[str, list[int]] = {}
    for i, o in enumerate(scene.objects):
        groups.setdefault(o.group, []).append(i)
    securves = []
    for members in groups.values():
        pts = np.vstack([deformer.rasters[i].pixels() for i in members])
        spine = principal_curve(pts).sample(48)
        securves.append(SECurve(spine, False, "principal", members, spine))

    def flows(step: int) -> list[np.ndarray]:
        out = []
        for s in securves:
            p = s.points
            u = np.linspace(0.0, 1.0, len(p))[:, None]
            out.append(p + (25.0 + step) * u**2 * np.array([[1.0, 0.0]]))
        return out

    return scene, deformer, securves, flows


def run() -> list[Figure]:
    """Prefactored solve vs dense solve of the same system; the factorisation itself."""
    scene, deformer, securves, flows = field_problem()
    first = deformer.solve([(flows(0), securves)])
    assert len(first.vertices) == len(scene.objects) >= 40
    system, offsets = first.system, first.offsets
    assert system is not None and offsets is not None
    hard = deformer.hard_targets(offsets)
    taken = [deformer.segments(flows(0), securves)]
    base = np.vstack([t[owners == o] for _, owners, t in taken[0] for o in sorted(set(owners.tolist()))])
    ramp = np.linspace(0.0, 1.0, len(base))[:, None]
    soft = [base + k * ramp * np.array([[1.5, -0.5]]) for k in range(8)]  # the drag moves targets, not rows
    steps = iter(range(10**9))
    solve = median_time(lambda: system.solve(hard, soft[next(steps) % 8], ITERATIONS), repeats=15) * 1e3
    dense = median_time(lambda: system.solve(hard, soft[0], ITERATIONS, dense=True), repeats=3, min_time=0.0) * 1e3
    cpu = _cpu_median(lambda: system.solve(hard, soft[next(steps) % 8], ITERATIONS))
    deformer._cache = None

    def factorise() -> None:
        deformer._cache = None
        deformer._system(
            list(offsets),
            [(o, seg.c[owners == o]) for seg, owners, _ in taken[0] for o in sorted(set(owners.tolist()))],
        )

    factor = median_time(factorise, repeats=5, min_time=0.0) * 1e3
    return [
        Figure("flow", "flow_solve_ms_40_objects", solve, "ms", "dense solve of the same system (straw man)", dense),
        Figure("flow", "flow_solve_cpu_ms_40_objects", cpu, "ms", "its wall time (shared cores)", solve),
        Figure("flow", "flow_factor_ms_40_objects", factor, "ms", "one prefactored solve", solve),
        *_scripted_edits(scene),
        *mesh_figures(),
    ]


def _cpu_median(fn: Callable[[], object], repeats: int = 15) -> float:
    """Median process CPU milliseconds per call: what the solve costs when the cores are shared."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return float(np.median(times)) * 1e3


def _scripted_edits(scene: FlowScene) -> list[Figure]:
    """Operations and update times of the editor's scripted row and centre-point edits."""
    from authoring.flowcurves.securves import compute_securves
    from authoring.flowcurves.session import FlowSession
    from authoring.session import Session
    from input.hub import InputHub

    securves = compute_securves(scene, SceneDeformer(scene).rasters)
    out = []
    for name, label in (("row", "row_of_trees"), ("centre", "centre_point")):
        activity = FlowTool(FlowSession(flow_scene(), securves=securves), None, name)
        session = Session(activity, InputHub(), script=activity.script_steps())
        while session.frame < activity.script_end:
            session.step()
        out.append(Figure("flow", f"flow_ops_{label}", activity.clicks, "operations per edit"))  # no human baseline
        out.append(
            Figure(
                "flow",
                f"flow_update_ms_{label}",
                float(np.median(activity.solve_ms)),
                "ms",
                "one frame at 60 Hz",
                1000.0 / 60.0,
            )
        )
    grouping = FlowTool(FlowSession(flow_scene(), securves=securves), None)
    out.append(
        Figure(
            "flow",
            "flow_ops_fig3_6_grouping",
            perform(grouping, THESIS_EDITS["fig3_6_grouping"]),
            "operations per edit",
        )
    )
    tree, tree_securves = mesh_tree_problem()
    stroke = FlowTool(FlowSession(tree, securves=tree_securves), None)
    ops = perform(stroke, _drag([(float(x), float(y)) for x, y in lean_stroke(tree_securves[0].points)]))
    assert stroke.session is not None and stroke.session.result.vertices, "the scripted stroke bent nothing"
    out.append(Figure("flow", "flow_ops_fig3_7_one_stroke", ops, "operations per edit"))
    return out + drag_figures(flow_scene(), securves)


def perform(tool: FlowTool, steps: list[list[Op]]) -> int:
    """Apply a scripted edit through the one session's hub, a step at a time, as a user's pointer would;
    the edit's operations (presses and keys)."""
    from authoring.session import Session
    from input.hub import InputHub

    session = Session(tool, InputHub())
    for ops in steps:
        for op in ops:
            session.hub.tool(*op)
        session.step()
    return sum(op[0] in ("press", "key") for ops in steps for op in ops)
