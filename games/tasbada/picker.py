"""The pose picker: when the selfie gave no pose, the person drags a stick figure's joints.

Shown in stage 2 (while the narrator talks) in a panel at the left of the photo when no
pose estimator is installed or no person was found in the selfie. The figure starts in a
relaxed stance (:func:`games.tasbada.pose.default_keypoints`); pressing on an elbow, hand,
knee or foot grabs it, dragging moves it, and the avatar starts in the pose the figure
shows — lifted by the same IK as a found pose. The keypoints live in the hashed
:class:`~games.tasbada.quest.Quest`, driven by recorded pointer events, so a picked pose
replays exactly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from games.tasbada.quest import Quest

__all__ = ["PANEL", "HANDLES", "BONES", "to_panel", "from_panel", "picker_step", "panel_aspect"]

PANEL = (0.02, 0.26, 0.22, 0.86)
"""The picker's rectangle on the photo ``(u0, v0, u1, v1)``."""
HANDLES = ("l_elbow", "r_elbow", "l_wrist", "r_wrist", "l_knee", "r_knee", "l_ankle", "r_ankle")
BONES = (
    ("l_shoulder", "r_shoulder"),
    ("l_hip", "r_hip"),
    ("l_shoulder", "l_hip"),
    ("r_shoulder", "r_hip"),
    ("l_shoulder", "l_elbow"),
    ("l_elbow", "l_wrist"),
    ("r_shoulder", "r_elbow"),
    ("r_elbow", "r_wrist"),
    ("l_hip", "l_knee"),
    ("l_knee", "l_ankle"),
    ("r_hip", "r_knee"),
    ("r_knee", "r_ankle"),
)
_REACH = 0.025
"""How close (image units) a press must be to a handle to grab it."""


def panel_aspect() -> float:
    """Width / height of the panel on the 16:9 photo (the keypoints' picture aspect)."""
    u0, v0, u1, v1 = PANEL
    return (u1 - u0) * 16.0 / ((v1 - v0) * 9.0)


def to_panel(xy: list[float]) -> NDArray[np.float64]:
    """A keypoint (normalised in the panel) → photo coordinates."""
    u0, v0, u1, v1 = PANEL
    return np.array([u0 + xy[0] * (u1 - u0), v0 + xy[1] * (v1 - v0)])


def from_panel(p: NDArray[np.float64]) -> list[float]:
    """Photo coordinates → a keypoint normalised in the panel (kept inside it)."""
    u0, v0, u1, v1 = PANEL
    return [
        round(float(np.clip((p[0] - u0) / (u1 - u0), 0.02, 0.98)), 4),
        round(float(np.clip((p[1] - v0) / (v1 - v0), 0.02, 0.98)), 4),
    ]


def picker_step(q: Quest, pressed: bool, released: bool) -> bool:
    """Grab, drag and drop a handle; ``True`` when the pointer's press belongs to the picker."""
    u0, v0, u1, v1 = PANEL
    p = q.pointer
    inside = u0 <= p[0] <= u1 and v0 <= p[1] <= v1
    if pressed and inside:
        near = [(float(np.linalg.norm(to_panel(q.pose[h]) - p)), h) for h in HANDLES if h in q.pose]
        near.sort()
        q.gesture = "pose:" + near[0][1] if near and near[0][0] < _REACH else "pose:"
        q.down = True
    busy = q.gesture.startswith("pose:")
    if busy and q.down and q.gesture != "pose:":
        q.pose[q.gesture[5:]] = from_panel(p)
    if released and busy:
        q.gesture, q.down = "", False
    return (pressed and inside) or busy
