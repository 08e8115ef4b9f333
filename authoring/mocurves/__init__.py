"""MoCurves: editing motion cycles in space and time from one viewport (SCA 2017 §5, thesis §5.4).

A UI-independent library; the interactive scene (``authoring/edit_scene.py``) sits on top.

- :mod:`~authoring.mocurves.curves` — one :class:`MoCurve` per item: keypoints, arrows, φ.
- :mod:`~authoring.mocurves.spatial` — control-point drags, arrow rotate/scale with the
  Gaussian falloff ``exp(−σ(i−j)²)`` over ``[i−τ, i+τ]``.
- :mod:`~authoring.mocurves.timewarp` — the periodic time-warp QP (E_C, E_T, E_V, E_S) on
  the shared QP core (engine.qp), warm-started between drags; :mod:`~authoring.mocurves.resample` reads the cycle at
  the new times.
- :mod:`~authoring.mocurves.contact` — a stroke's plane, projection, the λ spline,
  re-integration and the root moved by ``−λ``: feet planted without sliding.
- :class:`EditSession` — the edit state with undo/redo and live previews;
  :mod:`~authoring.mocurves.storage` — atomic save/load, export to ``.ppclip``/BVH/glTF.

Usage::

    session = EditSession(clip)
    drag = session.begin_retime("l_foot", layer="all")
    drag.drag_to(12, point_on_curve)      # live preview, warm-started QP
    drag.commit()                          # one undo step
    session.add_contact(["l_foot", "r_foot"], plane_from_stroke(a, b, view, root))
    save_session(session, "walk_edited.ppclip")
"""

from authoring.mocurves.contact import ContactPlane, ContactResult, contact_runs, plane_from_stroke, solve_contacts
from authoring.mocurves.curves import LAYERS, MoCurve, item_chain, layer_joints, mocurves
from authoring.mocurves.resample import periodic_cubic, periodic_slerp, retime_clip
from authoring.mocurves.session import EditSession, EditState, RetimeDrag
from authoring.mocurves.spatial import (
    control_basis,
    control_points,
    gaussian_weights,
    move_control_point,
    rotate_arrow,
    scale_arrow,
    set_positions,
)
from authoring.mocurves.storage import (
    EXPORT_SUFFIXES,
    SessionFileError,
    bake_root_motion,
    export_clip,
    load_session,
    save_session,
)
from authoring.mocurves.timewarp import W_SOFT, W_STRONG, TimeWarp, TimeWarpError

__all__ = [
    "ContactPlane",
    "ContactResult",
    "contact_runs",
    "plane_from_stroke",
    "solve_contacts",
    "LAYERS",
    "MoCurve",
    "item_chain",
    "layer_joints",
    "mocurves",
    "periodic_cubic",
    "periodic_slerp",
    "retime_clip",
    "EditSession",
    "EditState",
    "RetimeDrag",
    "control_basis",
    "control_points",
    "gaussian_weights",
    "move_control_point",
    "rotate_arrow",
    "scale_arrow",
    "set_positions",
    "EXPORT_SUFFIXES",
    "SessionFileError",
    "bake_root_motion",
    "export_clip",
    "load_session",
    "save_session",
    "W_SOFT",
    "W_STRONG",
    "TimeWarp",
    "TimeWarpError",
]
