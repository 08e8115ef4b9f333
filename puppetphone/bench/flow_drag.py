"""Flow Curves: dragging the centre-point over the snowman field (thesis §3.4.2, Eq. 3.7–3.8).

``flow_drag_update_ms`` is one update of the editor while the centre-point is dragged along
the path of ``author flow --script centre`` (there and back): the network re-bent from the
previous position's curves (:func:`~authoring.flowcurves.network.rebend`), correspondence,
the refactorisation when the constrained samples change, and the ARAP solve; median of the
moves. Its baseline is the same update with the network rebuilt cold at the same points
(averaged curves, then a BFGS bend of each from its average). ``flow_drag_network_ms`` is the
network's part alone (warm re-bend against a cold :meth:`FlowNetwork.build`).
``flow_drag_update_cpu_ms`` is the update in process CPU time: the cores are shared by several
sessions, and wall time includes waiting for one. The goal is an interactive drag: under 50 ms
an update.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial

import numpy as np

from authoring.flowcurves.network import FlowNetwork
from authoring.flowcurves.scene import FlowScene
from authoring.flowcurves.securves import SECurve
from authoring.flowcurves.session import FlowSession
from puppetphone.bench.figures import Figure

__all__ = ["DRAG", "drag_figures"]

#: The editor's scripted drag (``author flow --script centre``): right and down, 12 px then 3 px a move.
DRAG = [(640.0 + 4.0 * k, 120.0 + 1.0 * k) for k in range(0, 31, 3)]


def _timed(fn: Callable[[], object]) -> tuple[float, float]:
    """Wall and process-CPU milliseconds of one call."""
    w0, c0 = time.perf_counter(), time.process_time()
    fn()
    return (time.perf_counter() - w0) * 1e3, (time.process_time() - c0) * 1e3


def drag_figures(scene: FlowScene, securves: list[SECurve] | None) -> list[Figure]:
    """Warm drag updates against cold rebuilds at the same points (whole update, and network alone)."""
    session = FlowSession(scene, securves=securves)
    session.add("centre", [DRAG[0]])
    path = DRAG[1:] + DRAG[-2::-1]
    warm = [_timed(partial(session.move_centre, p)) for p in path]
    edit = session.edits[-1]
    cold = []
    for p in path:
        edit.points = np.asarray(p, dtype=np.float64).reshape(1, 2)
        cold.append(_timed(lambda: session.update(warm=False)))
    spines = [s.points for s in session.spines()]
    width = scene.size[0]
    network = FlowNetwork.build(spines, DRAG[0], width)
    net_warm = [_timed(partial(network.move, p, warm=True)) for p in path]
    net_cold = [_timed(partial(FlowNetwork.build, spines, p, width)) for p in path]
    warm_ms, cold_ms = np.median(warm, axis=0), np.median(cold, axis=0)  # [wall, cpu]
    return [
        Figure(
            "flow",
            "flow_drag_update_ms",
            float(warm_ms[0]),
            "ms",
            "the same update, network rebuilt cold",
            float(cold_ms[0]),
        ),
        Figure(
            "flow",
            "flow_drag_update_cpu_ms",
            float(warm_ms[1]),
            "ms",
            "the same update, network rebuilt cold (CPU)",
            float(cold_ms[1]),
        ),
        Figure(
            "flow",
            "flow_drag_network_ms",
            float(np.median(net_warm, axis=0)[0]),
            "ms",
            "a cold network build at the same points",
            float(np.median(net_cold, axis=0)[0]),
        ),
    ]
