"""Flow Curves (thesis ch. 3): deform a whole scene's flow with one sketched stroke.

The pipeline, module by module: a :class:`~authoring.flowcurves.scene.FlowScene` of
static objects (:mod:`.adapters` builds one from a game's plain description) is rasterised from its
camera; :mod:`.securves` finds its subjective curve elements — principal curves
(:mod:`.principal`, Eq. 3.1) and abstract contours (:mod:`.contours`, Eq. 3.2–3.5); a
stroke becomes a flow curve (:mod:`.hermite`, Eq. 3.6), a centre-point a network of them
(:mod:`.network`, Eq. 3.7–3.8); :mod:`.correspondence` pairs SEcurve segments with flow
curves (Eq. 3.10); :mod:`.deform` embeds each object in a screen grid (:mod:`.grid`,
Eq. 3.9), keeps contacts (:mod:`.contacts`) and solves the ARAP problem (:mod:`.arap`,
Eq. 3.12). :class:`~authoring.flowcurves.session.FlowSession` holds a user's edits with
undo/redo and :mod:`.storage` saves the edits and the deformed scenery.
"""

from authoring.flowcurves.adapters import scene_from_data
from authoring.flowcurves.deform import SceneDeformer
from authoring.flowcurves.hermite import Hermite, fit_stroke
from authoring.flowcurves.network import FlowNetwork
from authoring.flowcurves.scene import FlowObject, FlowScene, Primitive
from authoring.flowcurves.securves import SECurve, compute_securves
from authoring.flowcurves.session import FlowSession

__all__ = [
    "FlowObject",
    "FlowScene",
    "Primitive",
    "Hermite",
    "fit_stroke",
    "FlowNetwork",
    "SECurve",
    "compute_securves",
    "SceneDeformer",
    "FlowSession",
    "scene_from_data",
]
