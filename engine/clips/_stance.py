"""Standing-still cycles (idle, crouch idle): planted feet, breathing, a slow weight shift.

A stance is a loop where both feet stay flat on their plants the whole time and the body
above them moves: the pelvis sways over one foot then the other, the chest rises with each
breath, the arms hang and drift a little. Keeping the feet fixed in the world and solving
the legs for every frame is what makes the weight shift read as weight, not as a drift.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.arrays import F64 as F
from engine.clip import Clip
from engine.clips import _keys
from engine.clips._body import BodyIntent, assemble, pelvis_rotation
from engine.clips._gait import ANKLE_HEIGHT, column_intent
from engine.clips._keys import Keys
from engine.clips._reach import lower_to_reach
from engine.skeleton import Skeleton

__all__ = ["StanceSpec", "stance_intent", "build_stance"]


@dataclass(frozen=True)
class StanceSpec:
    """A standing loop's intent. Keys are ``(phase, value)``; angles in degrees.

    Attributes:
        feet: ankle ``(x, z)`` of the left foot relative to the pelvis's ground point; the
            right foot mirrors it.
        toe_out: outward yaw of both feet.
        arm_left, arm_right: ``(flexion, abduction, elbow)`` keys per arm.
        breath_cycles: breaths per loop; ``breath_chest`` and ``breath_shoulder`` are the
            chest pitch and arm abduction each breath adds.
    """

    name: str
    period: float
    feet: tuple[float, float]
    toe_out: float
    pelvis_height: Keys
    pelvis_sway: Keys
    pelvis_ypr: Keys
    spine_ypr: Keys
    chest_ypr: Keys
    arm_left: Keys
    arm_right: Keys
    gaze: Keys = ((0.0, 0.0),)
    breath_cycles: int = 1
    breath_chest: float = 1.5
    breath_shoulder: float = 1.0
    hand_flex: float = 8.0
    fps: float = 60.0
    max_reach: float = 0.997

    @property
    def frames(self) -> int:
        """Frames per loop."""
        n = self.period * self.fps
        if abs(n - round(n)) > 1e-9:
            raise ValueError(f"{self.name}: period × fps must be a whole number of frames")
        return int(round(n))


def stance_intent(skeleton: Skeleton, spec: StanceSpec, phase: F) -> BodyIntent:
    """The body intent of ``spec`` at cycle ``phase`` ``[N]`` (legs still to be solved)."""
    n = len(phase)
    breath = 0.5 - 0.5 * np.cos(2 * np.pi * spec.breath_cycles * phase)
    pos = np.zeros((n, 3))
    pos[:, 0] = _keys.periodic(spec.pelvis_sway, phase)[:, 0]
    pos[:, 1] = _keys.periodic(spec.pelvis_height, phase)[:, 0]
    pelvis = _keys.periodic(spec.pelvis_ypr, phase)
    x, z = spec.feet
    ankles = np.empty((n, 2, 3))
    ankles[:, 0] = (x, ANKLE_HEIGHT, z)
    ankles[:, 1] = (-x, ANKLE_HEIGHT, z)
    pos[:, 1] = lower_to_reach(skeleton, pos, pelvis_rotation(pelvis), ankles, spec.max_reach, 6, loop=True)
    spine = _keys.periodic(spec.spine_ypr, phase)
    chest = _keys.periodic(spec.chest_ypr, phase)
    chest[:, 1] -= spec.breath_chest * breath  # the chest lifts (leans back) as it fills
    neck, head = column_intent(pelvis, spine, chest, _keys.periodic(spec.gaze, phase)[:, 0])
    arms = np.stack([_keys.periodic(spec.arm_left, phase), _keys.periodic(spec.arm_right, phase)], axis=1)
    arms[:, :, 1] += spec.breath_shoulder * breath[:, None]
    return BodyIntent(
        pelvis_pos=pos,
        pelvis_ypr=pelvis,
        spine_ypr=spine,
        chest_ypr=chest,
        neck_ypr=neck,
        head_ypr=head,
        arms=arms,
        ankle=ankles,
        foot_pitch=np.zeros((n, 2)),
        foot_yaw=np.full((n, 2), spec.toe_out),
        travel=None,
        hand_flex=np.full((n, 2), spec.hand_flex),
    )


def build_stance(skeleton: Skeleton, spec: StanceSpec) -> tuple[Clip, float]:
    """Sample ``spec`` into a looping in-place clip; also return the largest leg reach used."""
    n = spec.frames
    intent = stance_intent(skeleton, spec, np.arange(n) / n)
    clip, legs = assemble(skeleton, intent, spec.name, spec.fps, True)
    return clip, float(max(legs[0].reach.max(), legs[1].reach.max()))
