"""Motion Curves for keyframed animation (thesis ch. 4): edit trajectories through Bézier tangents.

- :mod:`~authoring.keyframe_curves.solver` — the tangent-space QP of Eq. 4.10 (drags of a
  trajectory point or orientation, pins and contacts over frame ranges as ε bands).
- :mod:`~authoring.keyframe_curves.limits` — tangent limits Eq. 4.7–4.9 (Appendix A) and the
  timing edit Eq. 4.12.

Not to be confused with ch. 5's :mod:`authoring.mocurves` (cycles of performed motion).
"""

from authoring.keyframe_curves.limits import retime_segment, segment_bounds
from authoring.keyframe_curves.solver import CurveEdit, CurveSettings, Drag, Hold, TangentSolver, curve_rig

__all__ = [
    "CurveEdit",
    "CurveSettings",
    "Drag",
    "Hold",
    "TangentSolver",
    "curve_rig",
    "retime_segment",
    "segment_bounds",
]
