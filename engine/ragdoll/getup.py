"""Getting up: settle detection, which way the body lies, and a pop-free blend into a clip.

The state machine calls these (STYLE: tools on top of plain functions):

1. :func:`update_settle` each step while limp; :func:`settled` turns true once the body's
   kinetic energy and root speed stay under thresholds for ``SETTLE_FRAMES`` frames.
2. :func:`lying_orientation` reads face-up / face-down / side from the pelvis: the
   direction the hips face (+Z in the joint frame) against world up.
3. :class:`GetUpBlend` aligns the chosen get-up clip with the body's heading (the
   direction from pelvis to head, on the ground) and position, blends from the
   ragdoll's pose into the clip's first frame, then plays the clip to its end (the idle
   pose). The blend length is chosen from the largest joint rotation it has to cover, so
   its per-frame rotation never exceeds 90 % of the clip's own largest per-frame jump:
   no pop, by construction, measured in the tests.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.clip import Clip
from engine.pose import Pose
from engine.ragdoll.blend import max_rotation_jump
from engine.ragdoll.components import Ragdoll

__all__ = [
    "LyingOrientation",
    "lying_orientation",
    "lying_heading",
    "update_settle",
    "settled",
    "GetUpBlend",
    "SETTLE_FRAMES",
    "SETTLE_ENERGY_PER_KG",
    "SETTLE_SPEED",
    "pick_get_up_clip",
]

SETTLE_FRAMES = 15
SETTLE_ENERGY_PER_KG = 0.01  # J/kg: about 0.14 m/s of average body speed
SETTLE_SPEED = 0.1  # m/s at the root
_UP = np.array([0.0, 1.0, 0.0])


class LyingOrientation(enum.Enum):
    """How a fallen body lies, from its pelvis."""

    FACE_UP = "face_up"
    FACE_DOWN = "face_down"
    SIDE = "side"


def update_settle(ragdoll: Ragdoll, kinetic_energy: float, root_speed: float, mass: float) -> bool:
    """Count still frames and set ``ragdoll.settled``; returns it.

    Still means kinetic energy under ``SETTLE_ENERGY_PER_KG × mass`` and root speed under
    ``SETTLE_SPEED``. Any motion resets the count.
    """
    ragdoll.kinetic_energy = float(kinetic_energy)
    still = kinetic_energy < SETTLE_ENERGY_PER_KG * mass and root_speed < SETTLE_SPEED
    ragdoll.still_frames = ragdoll.still_frames + 1 if still else 0
    ragdoll.settled = ragdoll.still_frames >= SETTLE_FRAMES
    return ragdoll.settled


def settled(ragdoll: Ragdoll) -> bool:
    """Whether the ragdoll has come to rest (see :func:`update_settle`)."""
    return ragdoll.settled


def lying_orientation(
    pelvis_rotation: ArrayLike, forward: ArrayLike = (0.0, 0.0, 1.0), threshold: float = 0.5
) -> LyingOrientation:
    """Face-up when the pelvis' forward axis points up (cosine above ``threshold``), face-down
    when it points down, otherwise on the side."""
    f = quat.rotate(np.asarray(pelvis_rotation, dtype=np.float64), np.asarray(forward, dtype=np.float64))
    c = float(f @ _UP)
    if c > threshold:
        return LyingOrientation.FACE_UP
    if c < -threshold:
        return LyingOrientation.FACE_DOWN
    return LyingOrientation.SIDE


def lying_heading(
    pelvis_rotation: ArrayLike, spine: ArrayLike = (0.0, 1.0, 0.0), forward: ArrayLike = (0.0, 0.0, 1.0)
) -> float:
    """Yaw (rad about +Y, 0 = +Z) of a lying body: where its spine points on the ground.

    Falls back to the facing direction when the spine is nearly vertical (sitting, standing).
    """
    q = np.asarray(pelvis_rotation, dtype=np.float64)
    d = quat.rotate(q, np.asarray(spine, dtype=np.float64))
    if math.hypot(d[0], d[2]) < 0.3:
        d = quat.rotate(q, np.asarray(forward, dtype=np.float64))
    return math.atan2(d[0], d[2])


def pick_get_up_clip(clips: Mapping[str, Clip], orientation: LyingOrientation) -> Clip:
    """The get-up clip for how the body lies: ``get_up_face_up`` / ``get_up_face_down`` /
    ``get_up_side`` when the library has them, else ``get_up``."""
    for name in (f"get_up_{orientation.value}", "get_up"):
        if name in clips:
            return clips[name]
    raise KeyError(f"no get-up clip for {orientation.value}: need 'get_up_{orientation.value}' or 'get_up'")


class GetUpBlend:
    """Produces the get-up pose frame by frame, from a ragdoll pose to the clip's end.

    Args:
        start: the settled ragdoll's pose (root position, local rotations).
        clip: the get-up clip for how the body lies (its first frame lies, its last stands).
        dt: the simulation step.
        min_frames, max_frames: bounds on the blend into the clip's first frame.
        margin: the blend's per-frame rotation is kept under ``margin`` × the clip's own largest jump.
    """

    def __init__(
        self, start: Pose, clip: Clip, dt: float, min_frames: int = 6, max_frames: int = 120, margin: float = 0.9
    ) -> None:
        if start.rotations.shape != clip.rotations.shape[1:]:
            raise ValueError(f"start pose has {start.rotations.shape[0]} joints, clip {clip.rotations.shape[1]}")
        if not start.is_finite():
            raise ValueError("get-up start pose has NaN or infinite values")
        self.clip, self.dt = clip, dt
        self.start = start.copy()
        yaw = lying_heading(start.rotations[0]) - lying_heading(clip.rotations[0, 0])
        self.align = quat.from_axis_angle(_UP, yaw)
        c0 = clip.root[0]
        self.offset = np.array([start.root[0], c0[1], start.root[2]])
        self._c0 = c0
        times = np.arange(0.0, clip.duration + 0.5 * dt, dt)
        self.clip_jump = max(max_rotation_jump(clip.sample(times).rotations), 1e-6)
        first = self._clip_pose(0.0)
        span = float(np.max(quat.angle_between(start.rotations, first.rotations)))
        # smoothstep's steepest slope is 1.5 / frames
        need = math.ceil(1.5 * span / (margin * self.clip_jump))
        self.blend_frames = int(min(max(need, min_frames), max_frames))
        self.frame = 0
        self.total_frames = self.blend_frames + len(times) - 1

    def _clip_pose(self, t: float) -> Pose:
        p = self.clip.sample(t)
        root = quat.rotate(self.align, p.root - self._c0) + self.offset
        rot = p.rotations.copy()
        rot[0] = quat.mul(self.align, rot[0])
        return Pose(root, rot)

    @property
    def done(self) -> bool:
        """True once the clip's last frame has been produced."""
        return self.frame > self.total_frames

    @property
    def blend_weight(self) -> float:
        """Current weight of the clip against the ragdoll start pose (0..1)."""
        s = min(self.frame / self.blend_frames, 1.0)
        return s * s * (3.0 - 2.0 * s)

    def pose(self) -> Pose:
        """The pose for the current frame (does not advance)."""
        if self.frame <= self.blend_frames:
            target = self._clip_pose(0.0)
            w = self.blend_weight
            root = self.start.root + w * (target.root - self.start.root)
            return Pose(root, quat.normalize(quat.slerp(self.start.rotations, target.rotations, w)))
        t = min((self.frame - self.blend_frames) * self.dt, self.clip.duration)
        return self._clip_pose(t)

    def advance(self) -> Pose:
        """The current frame's pose, then move one step on."""
        p = self.pose()
        self.frame += 1
        return p

    def heading(self) -> NDArray[np.float64]:
        """The rotation (about +Y) applied to the clip to match the body's heading."""
        return self.align.copy()
