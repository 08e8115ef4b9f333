"""The default puppet's seven clips as authored intent (thesis §6.3's prototype set).

Numbers are the blocking an animator would do, in the units a person can check: metres,
degrees, fractions of a cycle. Timing follows human gait: a 1.3 m/s walk with a 1.1 s
stride (≈62 % stance), a 3 m/s run with a 0.7 s stride and a flight phase (≈36 % stance),
a 0.7 m/s crouch walk with the hips near 0.6 m. Phase 0 is the left heel strike.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from engine.clip import Clip
from engine.clips._gait import FootPlan, GaitSpec, build_gait, mirrored
from engine.clips._oneshot import PoseKey, build_one_shot, key_from_intent
from engine.clips._stance import StanceSpec, build_stance, stance_intent
from engine.skeleton import Skeleton

__all__ = ["WALK", "RUN", "CROUCH_WALK", "IDLE", "CROUCH_IDLE", "build_all"]

_SWAY = (-1.0,)
_YPR = (-1.0, 1.0, -1.0)
_SAME = (1.0,)

WALK = GaitSpec(
    name="walk",
    speed=1.3,
    period=1.1,
    foot=FootPlan(
        width=0.085,
        toe_out=5.0,
        front=0.38,
        strike_pitch=18.0,
        toeoff_pitch=45.0,
        flat_at=0.10,
        heel_off=0.32,
        duty=0.62,
        swing=((0.3, -0.36, 0.26, -32.0), (0.55, -0.04, 0.15, -4.0), (0.8, 0.38, 0.12, 10.0)),
    ),
    pelvis_height=mirrored(((0.05, 0.915), (0.30, 0.94)), _SAME),
    pelvis_sway=mirrored(((0.0, 0.004), (0.25, 0.022)), _SWAY),
    pelvis_ypr=mirrored(((0.0, (-5.0, 4.0, 0.0)), (0.15, (-3.0, 4.0, 3.5)), (0.3, (0.0, 4.0, 1.5))), _YPR),
    spine_ypr=mirrored(((0.0, (4.0, 2.0, 0.0)), (0.25, (0.0, 2.0, -2.0))), _YPR),
    chest_ypr=mirrored(((0.0, (5.0, 1.0, 0.0)), (0.25, (0.0, 1.0, -1.5))), _YPR),
    arm=((0.03, (-16.0, 6.0, 10.0)), (0.28, (0.0, 6.0, 15.0)), (0.53, (18.0, 6.0, 26.0)), (0.78, (0.0, 6.0, 17.0))),
    gaze=((0.0, 4.0),),
)

RUN = GaitSpec(
    name="run",
    speed=3.0,
    period=0.7,
    foot=FootPlan(
        width=0.06,
        toe_out=3.0,
        front=0.26,
        strike_pitch=8.0,
        toeoff_pitch=40.0,
        flat_at=0.05,
        heel_off=0.17,
        duty=0.36,
        swing=((0.2, -0.58, 0.30, -45.0), (0.45, -0.30, 0.38, -25.0), (0.7, 0.18, 0.28, 0.0), (0.84, 0.30, 0.15, 8.0)),
    ),
    pelvis_height=mirrored(((0.17, 0.865), (0.42, 0.935)), _SAME),
    pelvis_sway=mirrored(((0.0, 0.003), (0.17, 0.012)), _SWAY),
    pelvis_ypr=mirrored(((0.0, (-7.0, 9.0, 0.0)), (0.17, (-2.0, 9.0, 3.0)), (0.36, (2.0, 9.0, 0.0))), _YPR),
    spine_ypr=mirrored(((0.0, (6.0, 4.0, 0.0)), (0.25, (0.0, 4.0, -2.0))), _YPR),
    chest_ypr=mirrored(((0.0, (8.0, 3.0, 0.0)), (0.25, (0.0, 3.0, -1.0))), _YPR),
    arm=(
        (0.03, (-35.0, 10.0, 95.0)),
        (0.28, (0.0, 10.0, 80.0)),
        (0.53, (45.0, 10.0, 100.0)),
        (0.78, (5.0, 10.0, 80.0)),
    ),
    gaze=((0.0, 2.0),),
    hand_flex=15.0,
)

CROUCH_WALK = GaitSpec(
    name="crouch_walk",
    speed=0.7,
    period=1.2,
    foot=FootPlan(
        width=0.11,
        toe_out=8.0,
        front=0.36,
        strike_pitch=8.0,
        toeoff_pitch=25.0,
        flat_at=0.08,
        heel_off=0.45,
        duty=0.66,
        swing=((0.3, -0.05, 0.13, -10.0), (0.6, 0.22, 0.13, 0.0), (0.85, 0.33, 0.09, 6.0)),
    ),
    pelvis_height=mirrored(((0.05, 0.595), (0.30, 0.615)), _SAME),
    pelvis_sway=mirrored(((0.0, 0.005), (0.25, 0.03)), _SWAY),
    pelvis_ypr=mirrored(((0.0, (-6.0, 25.0, 0.0)), (0.25, (0.0, 25.0, 3.0))), _YPR),
    spine_ypr=mirrored(((0.0, (3.0, 8.0, 0.0)), (0.25, (0.0, 8.0, -2.0))), _YPR),
    chest_ypr=mirrored(((0.0, (4.0, 6.0, 0.0)), (0.25, (0.0, 6.0, -1.0))), _YPR),
    arm=(
        (0.03, (10.0, 14.0, 40.0)),
        (0.28, (22.0, 14.0, 45.0)),
        (0.53, (34.0, 14.0, 52.0)),
        (0.78, (22.0, 14.0, 45.0)),
    ),
    gaze=((0.0, 10.0),),
)

IDLE = StanceSpec(
    name="idle",
    period=4.0,
    feet=(0.11, 0.02),
    toe_out=8.0,
    pelvis_height=((0.0, 0.945),),
    pelvis_sway=((0.0, 0.0), (0.2, 0.018), (0.45, 0.012), (0.7, -0.016)),
    pelvis_ypr=((0.0, (0.0, 2.0, 0.0)), (0.2, (1.5, 2.0, 2.0)), (0.45, (1.0, 2.0, 1.5)), (0.7, (-1.5, 2.0, -2.0))),
    spine_ypr=((0.0, (0.0, 1.0, 0.0)), (0.2, (-1.0, 1.0, -1.5)), (0.7, (1.0, 1.0, 1.5))),
    chest_ypr=((0.0, (0.0, -1.0, 0.0)), (0.2, (-0.5, -1.0, -1.0)), (0.7, (0.5, -1.0, 1.0))),
    arm_left=((0.0, (3.0, 7.0, 10.0)), (0.5, (4.0, 8.0, 13.0))),
    arm_right=((0.25, (4.0, 7.0, 12.0)), (0.75, (2.0, 8.0, 9.0))),
    breath_cycles=1,
    breath_chest=2.0,
)

CROUCH_IDLE = StanceSpec(
    name="crouch_idle",
    period=3.0,
    feet=(0.14, 0.12),
    toe_out=12.0,
    pelvis_height=((0.0, 0.552), (0.25, 0.546), (0.5, 0.552), (0.75, 0.546)),
    pelvis_sway=((0.0, 0.0), (0.25, 0.012), (0.75, -0.012)),
    pelvis_ypr=((0.0, (0.0, 30.0, 0.0)), (0.25, (1.0, 30.0, 1.5)), (0.75, (-1.0, 30.0, -1.5))),
    spine_ypr=((0.0, (0.0, 10.0, 0.0)),),
    chest_ypr=((0.0, (0.0, 8.0, 0.0)), (0.25, (-1.0, 8.0, -1.0)), (0.75, (1.0, 8.0, 1.0))),
    arm_left=((0.0, (35.0, 12.0, 45.0)), (0.5, (37.0, 13.0, 48.0))),
    arm_right=((0.0, (33.0, 12.0, 48.0)), (0.5, (35.0, 13.0, 45.0))),
    gaze=((0.0, 12.0),),
    breath_cycles=2,
    breath_chest=1.5,
)


def _get_up_keys(skeleton: Skeleton) -> tuple[PoseKey, ...]:
    """Lying face-up (head towards −Z) to standing on feet planted ahead, ending on idle's first frame."""
    n = IDLE.frames
    stand = key_from_intent(stance_intent(skeleton, IDLE, np.arange(n) / n), 0, 2.1)
    forward = 0.42  # where the person stands up: over feet drawn in towards the hips
    px, py, pz = stand.pelvis
    (lx, ly, lz), (rx, ry, rz) = stand.ankles
    stand = replace(stand, pelvis=(px, py, pz + forward), ankles=((lx, ly, lz + forward), (rx, ry, rz + forward)))
    (lx, ly, lz), (rx, ry, rz) = stand.ankles
    plant = ((lx, ly, lz), (rx, ry, rz))
    arms_side = ((0.0, 8.0, 5.0), (0.0, 8.0, 5.0))
    return (
        PoseKey(
            0.0,
            (0.0, 0.11, 0.0),
            (0.0, -90.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            arms_side,
            ((0.10, 0.075, 0.88), (-0.10, 0.075, 0.88)),
            (70.0, 70.0),
        ),
        PoseKey(
            0.15,
            (0.0, 0.11, 0.0),
            (0.0, -90.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (0.0, 8.0, 0.0),
            (0.0, 6.0, 0.0),
            arms_side,
            ((0.10, 0.075, 0.88), (-0.10, 0.075, 0.88)),
            (70.0, 70.0),
        ),
        PoseKey(
            0.45,
            (0.0, 0.11, 0.0),
            (0.0, -86.0, 0.0),
            (0.0, 18.0, 0.0),
            (0.0, 16.0, 0.0),
            (0.0, 20.0, 0.0),
            (0.0, 10.0, 0.0),
            ((15.0, 15.0, 25.0), (15.0, 15.0, 25.0)),
            ((0.11, 0.08, 0.70), (-0.11, 0.08, 0.70)),
            (40.0, 40.0),
        ),
        PoseKey(
            0.85,
            (0.0, 0.13, 0.02),
            (0.0, -35.0, 0.0),
            (0.0, 12.0, 0.0),
            (0.0, 8.0, 0.0),
            (0.0, 10.0, 0.0),
            (0.0, 5.0, 0.0),
            ((-35.0, 22.0, 10.0), (-35.0, 22.0, 10.0)),
            plant,
            (0.0, 0.0),
        ),
        PoseKey(
            1.25,
            (0.0, 0.40, 0.26),
            (0.0, 35.0, 0.0),
            (0.0, 15.0, 0.0),
            (0.0, 10.0, 0.0),
            (0.0, -25.0, 0.0),
            (0.0, -20.0, 0.0),
            ((60.0, 10.0, 20.0), (60.0, 10.0, 20.0)),
            plant,
            (0.0, 0.0),
        ),
        PoseKey(
            1.65,
            (0.0, 0.74, 0.36),
            (0.0, 22.0, 0.0),
            (0.0, 8.0, 0.0),
            (0.0, 5.0, 0.0),
            (0.0, -12.0, 0.0),
            (0.0, -10.0, 0.0),
            ((25.0, 9.0, 20.0), (25.0, 9.0, 20.0)),
            plant,
            (0.0, 0.0),
        ),
        stand,
        stand.at(2.3),
    )


def _mid_jump_keys() -> tuple[PoseKey, ...]:
    """Airborne tuck: knees drawn up, toes pointed, arms thrown up; the jump state holds the end."""

    def pose(t: float, ankle_y: float, ankle_z: float, arm: float, tilt: float) -> PoseKey:
        return PoseKey(
            t,
            (0.0, 0.95, 0.0),
            (0.0, tilt, 0.0),
            (0.0, 4.0, 0.0),
            (0.0, -3.0, 0.0),
            (0.0, -0.5 * (tilt + 1.0), 0.0),
            (0.0, -0.5 * (tilt + 1.0), 0.0),
            ((arm, 18.0, 15.0), (arm, 18.0, 15.0)),
            ((0.11, ankle_y, ankle_z), (-0.11, ankle_y, ankle_z)),
            (-30.0, -30.0),
            (4.0, 4.0),
            (10.0, 10.0),
        )

    return (pose(0.0, 0.42, -0.04, 140.0, 6.0), pose(0.25, 0.55, 0.0, 155.0, 10.0), pose(0.4, 0.56, 0.01, 157.0, 10.0))


def build_all(skeleton: Skeleton) -> dict[str, tuple[Clip, float]]:
    """Every default clip with the largest leg reach its authoring needed (for checks)."""
    return {
        "idle": build_stance(skeleton, IDLE),
        "walk": build_gait(skeleton, WALK),
        "run": build_gait(skeleton, RUN),
        "crouch_idle": build_stance(skeleton, CROUCH_IDLE),
        "crouch_walk": build_gait(skeleton, CROUCH_WALK),
        "get_up": build_one_shot(skeleton, "get_up", _get_up_keys(skeleton), travel=True),
        "mid_jump": build_one_shot(skeleton, "mid_jump", _mid_jump_keys()),
    }
