"""Animation blending: pose blends, phase-synchronised N-D blend spaces and the IDW lookup (thesis §6.2.3).

The pieces, bottom up:

- :mod:`~engine.blend.pose_blend` — ``blend(weights, poses)``, additive layers, cross-fades.
- :mod:`~engine.blend.sync` — one normalised phase drives every cycle of a blend.
- :mod:`~engine.blend.space` — clips at points of ``[0,1]^N``, gradient-band weights.
- :mod:`~engine.blend.measure` — play a blend like the runtime does and measure it.
- :mod:`~engine.blend.feasible` / :mod:`~engine.blend.lookup` — the measured probe grid,
  IDW ``u → p`` over a k-d tree, border projection and speed-up.
- :mod:`~engine.blend.locomotion` — the ``LocomotionPlayer`` component, the ``animate``
  system and the ``install_blend`` plugin.
- :mod:`~engine.blend.puppet` — the puppet's Fig. 6.3 space built from the default clips.
"""

from engine.blend.feasible import FeasibleSet
from engine.blend.locomotion import BlendLibrary, LocomotionPlayer, LocomotionSet, animate, install_blend
from engine.blend.lookup import LinearMapping, LookupTable, Resolution, probe_grid
from engine.blend.measure import Playback, blended_contacts, foot_slide, measure_locomotion, play
from engine.blend.pose_blend import (
    additive_delta,
    apply_additive,
    blend,
    blend_quaternions,
    blend_vectors,
    crossfade,
    fade_weight,
)
from engine.blend.puppet import (
    PUPPET_AXES,
    PUPPET_PLACEMENT,
    build_locomotion,
    height_mapping,
    install_puppet_locomotion,
    puppet_blend_space,
    puppet_locomotion,
)
from engine.blend.space import BlendSpace, gradient_band_weights
from engine.blend.sync import SyncGroup

__all__ = [
    "BlendLibrary",
    "BlendSpace",
    "FeasibleSet",
    "LinearMapping",
    "LocomotionPlayer",
    "LocomotionSet",
    "LookupTable",
    "PUPPET_AXES",
    "PUPPET_PLACEMENT",
    "Playback",
    "Resolution",
    "SyncGroup",
    "additive_delta",
    "animate",
    "apply_additive",
    "blend",
    "blend_quaternions",
    "blend_vectors",
    "blended_contacts",
    "build_locomotion",
    "crossfade",
    "fade_weight",
    "foot_slide",
    "gradient_band_weights",
    "height_mapping",
    "install_blend",
    "install_puppet_locomotion",
    "measure_locomotion",
    "play",
    "probe_grid",
    "puppet_blend_space",
    "puppet_locomotion",
]
