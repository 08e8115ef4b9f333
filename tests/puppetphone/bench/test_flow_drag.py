"""The drag figures time a real drag over the field: warm updates against cold rebuilds at the same points."""

from __future__ import annotations

from authoring.flowcurves.securves import SECurve
from puppetphone.bench.flow import field_problem
from puppetphone.bench.flow_drag import DRAG, drag_figures


def test_drag_figures_have_their_cold_baselines() -> None:
    scene, _, securves, _ = field_problem()
    spines = [SECurve(s.points, False, "principal", s.objects, s.points) for s in securves]
    figures = {f.name: f for f in drag_figures(scene, spines)}
    assert set(figures) == {"flow_drag_update_ms", "flow_drag_update_cpu_ms", "flow_drag_network_ms"}
    for f in figures.values():
        assert f.unit == "ms" and f.value > 0.0 and f.baseline_value and f.baseline_value > 0.0
    assert len(DRAG) >= 8
