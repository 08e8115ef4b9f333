"""Human BVH files made in the test, in any naming, unit and frame count (no files shipped).

Also the built-in walk as a take (:func:`walk_take`) and written as Blender's exporter
writes it, Z up (:func:`blender_bvh`).

The figure is an adult in metres (leg 0.82 m from hip joint to ankle) scaled to the file
unit; it walks on the spot with swinging legs and arms while the root moves forward, so
cycle extraction, units and retargeting all have something real to measure.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from engine import quat
from engine.clip import Clip
from engine.clips import default_clips
from engine.io.bvh import write_bvh
from engine.io.bvh_convert import clip_to_bvh

# role -> (parent role, offset in metres)
_BONES = {
    "hips": (None, (0.0, 0.95, 0.0)),
    "spine": ("hips", (0.0, 0.12, 0.0)),
    "chest": ("spine", (0.0, 0.2, 0.0)),
    "neck": ("chest", (0.0, 0.2, 0.0)),
    "head": ("neck", (0.0, 0.1, 0.0)),
    "l_upper_arm": ("chest", (0.18, 0.15, 0.0)),
    "l_lower_arm": ("l_upper_arm", (0.0, -0.28, 0.0)),
    "l_hand": ("l_lower_arm", (0.0, -0.25, 0.0)),
    "r_upper_arm": ("chest", (-0.18, 0.15, 0.0)),
    "r_lower_arm": ("r_upper_arm", (0.0, -0.28, 0.0)),
    "r_hand": ("r_lower_arm", (0.0, -0.25, 0.0)),
    "l_upper_leg": ("hips", (0.1, -0.05, 0.0)),
    "l_lower_leg": ("l_upper_leg", (0.0, -0.42, 0.0)),
    "l_foot": ("l_lower_leg", (0.0, -0.40, 0.0)),
    "r_upper_leg": ("hips", (-0.1, -0.05, 0.0)),
    "r_lower_leg": ("r_upper_leg", (0.0, -0.42, 0.0)),
    "r_foot": ("r_lower_leg", (0.0, -0.40, 0.0)),
}
_TIPS = {
    "head": (0.0, 0.12, 0.0),
    "l_hand": (0.0, -0.08, 0.0),
    "r_hand": (0.0, -0.08, 0.0),
    "l_foot": (0.0, -0.05, 0.14),
    "r_foot": (0.0, -0.05, 0.14),
}

MIXAMO = {
    "hips": "Hips",
    "spine": "Spine",
    "chest": "Spine1",
    "neck": "Neck",
    "head": "Head",
    **{
        f"{s}_{b}": f"{w}{n}"
        for s, w in (("l", "Left"), ("r", "Right"))
        for b, n in (
            ("upper_arm", "Arm"),
            ("lower_arm", "ForeArm"),
            ("hand", "Hand"),
            ("upper_leg", "UpLeg"),
            ("lower_leg", "Leg"),
            ("foot", "Foot"),
        )
    },
}
BIOVISION = {
    "hips": "Hips",
    "spine": "Chest",
    "chest": "Chest2",
    "neck": "Neck",
    "head": "Head",
    **{
        f"{s}_{b}": f"{w}{n}"
        for s, w in (("l", "Left"), ("r", "Right"))
        for b, n in (
            ("upper_arm", "Shoulder"),
            ("lower_arm", "Elbow"),
            ("hand", "Wrist"),
            ("upper_leg", "Hip"),
            ("lower_leg", "Knee"),
            ("foot", "Ankle"),
        )
    },
}
LOWERCASE = {
    "hips": "hip",
    "spine": "abdomen",
    "chest": "chest",
    "neck": "neck",
    "head": "head",
    **{
        f"{s}_{b}": f"{s}{n}"
        for s in ("l", "r")
        for b, n in (
            ("upper_arm", "shoulder"),
            ("lower_arm", "elbow"),
            ("hand", "wrist"),
            ("upper_leg", "hip"),
            ("lower_leg", "knee"),
            ("foot", "foot"),
        )
    },
}
ODD = {role: f"bone_{k:02d}" for k, role in enumerate(_BONES)}


def human_bvh(
    names: dict[str, str] = MIXAMO,
    unit: float = 100.0,
    frames: int = 120,
    fps: float = 30.0,
    period: float = 1.0,
    stretch: float = 0.0,
    frames_header: int | None = None,
    zero_end_site: bool = False,
    turn: float = 0.0,
    turn_period: float = 8.0,
) -> str:
    """BVH text of the walking figure.

    Args:
        names: role -> joint name.
        unit: file units per metre (100: cm; 1 / 0.05644: CMU's ASF unit).
        frames, fps, period: the take's length, rate and stride period in seconds.
        stretch: share by which the left shin stretches and shrinks over the stride (its
            position channels move; 0: no position channels below the root).
        frames_header: the ``Frames:`` count written (default: the true count).
        zero_end_site: give the head an End Site with a zero OFFSET.
        turn: amplitude in degrees of the heading, ``turn · sin(2πt / turn_period)``: the
            walker weaves (a figure eight's left and right arcs) instead of going straight.
    """
    roles = list(_BONES)
    kids: dict[str | None, list[str]] = {}
    for r in roles:
        kids.setdefault(_BONES[r][0], []).append(r)
    lines = ["HIERARCHY"]
    order: list[str] = []

    def emit(role: str, depth: int) -> None:
        pad = "  " * depth
        order.append(role)
        lines.append(f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {names[role]}")
        lines.append(pad + "{")
        off = np.array(_BONES[role][1]) * unit
        lines.append(f"{pad}  OFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        pos = depth == 0 or (stretch and role == "l_lower_leg")
        chans = "Xposition Yposition Zposition " if pos else ""
        lines.append(f"{pad}  CHANNELS {6 if pos else 3} {chans}Zrotation Xrotation Yrotation")
        for k in kids.get(role, []):
            emit(k, depth + 1)
        tip = (0.0, 0.0, 0.0) if zero_end_site and role == "head" else _TIPS.get(role)
        if tip is not None and not kids.get(role):
            t = np.array(tip) * unit
            lines.extend(
                [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {t[0]:.6f} {t[1]:.6f} {t[2]:.6f}", f"{pad}  }}"]
            )
        lines.append(pad + "}")

    emit("hips", 0)
    t = np.arange(frames) / fps
    ph = 2 * np.pi * t / period
    heading = np.radians(turn) * np.sin(2 * np.pi * t / turn_period)
    step = 1.2 / fps * np.stack([np.sin(heading), np.cos(heading)], axis=1)
    ground = np.concatenate([np.zeros((1, 2)), np.cumsum(step[:-1], axis=0)])
    rows = []
    for f in range(frames):
        row: list[float] = []
        for role in order:
            if role == "hips":
                row += [ground[f, 0] * unit, (0.95 + 0.02 * np.cos(2 * ph[f])) * unit, ground[f, 1] * unit]
            elif stretch and role == "l_lower_leg":
                row += [0.0, -0.42 * (1 + stretch * np.sin(ph[f])) * unit, 0.0]
            swing = {"l_upper_leg": 25, "r_upper_leg": -25, "l_upper_arm": -20, "r_upper_arm": 20}.get(role, 0.0)
            knee = {"l_lower_leg": 1.0, "r_lower_leg": -1.0}.get(role, 0.0)
            x = swing * np.sin(ph[f]) + (20 * (1 + knee * np.sin(ph[f])) if knee else 0.0)
            y = 5 * np.sin(ph[f]) if role in ("hips", "chest") else 0.0
            y += float(np.degrees(heading[f])) if role == "hips" else 0.0
            row += [0.0, x, y]
        rows.append(" ".join(f"{v:.6f}" for v in row))
    count = frames if frames_header is None else frames_header
    lines += ["MOTION", f"Frames: {count}", f"Frame Time: {1.0 / fps:.7f}", *rows]
    return "\n".join(lines) + "\n"


Y_TO_Z = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.float64(np.pi / 2))  # Blender: (x, y, z) -> (x, -z, y)


def walk_take(cycles: float = 3, fps: float = 30.0, role: str = "walk") -> Clip:
    """A built-in cycle (the walk) performed ``cycles`` times at ``fps``, travelling in the root track (Y up, metres)."""
    walk = default_clips()[role]
    t = np.arange(round(cycles * walk.duration * fps)) / fps
    pose = walk.sample(t)
    travel = np.array([walk.sample_root_motion(float(x))[0] for x in t])
    return Clip(role, walk.skeleton, fps, pose.root + travel, pose.rotations)


def blender_bvh(path: Path, clip: Clip) -> Path:
    """``clip`` as Blender's BVH exporter writes it: Z up, metres, XYZ Euler, %.6f, six channels on unconnected bones.

    Blender keeps its own axes (Z up, -Y forward) and gives bones not connected to their
    parent (the root, the thighs, the upper arms) position channels holding their local
    translation, which repeats the OFFSET.
    """
    sk = clip.skeleton
    zup = Clip(
        clip.name,
        replace(sk, offsets=quat.rotate(Y_TO_Z, sk.offsets), tips=quat.rotate(Y_TO_Z, sk.tips)),
        clip.fps,
        quat.rotate(Y_TO_Z, clip.root),
        quat.mul(quat.mul(Y_TO_Z, clip.rotations), quat.conjugate(Y_TO_Z)),
    )
    bvh = clip_to_bvh(zup, order="XYZ", unit=1.0)
    loose = {"l_upper_leg", "r_upper_leg", "l_upper_arm", "r_upper_arm"}
    channels, columns, start = [], [], 0
    for j, chans in enumerate(bvh.channels):
        width = len(chans)
        block = bvh.data[:, start : start + width]
        if bvh.names[j] in loose:
            chans = ("Xposition", "Yposition", "Zposition", *chans)
            block = np.concatenate([np.tile(bvh.offsets[j], (bvh.num_frames, 1)), block], axis=1)
        channels.append(chans)
        columns.append(block)
        start += width
    data = np.round(np.concatenate(columns, axis=1), 6)
    ends = {j: np.round(e, 6) for j, e in bvh.end_sites.items()}
    return write_bvh(
        path, replace(bvh, channels=tuple(channels), data=data, offsets=np.round(bvh.offsets, 6), end_sites=ends)
    )


# finger -> (knuckle offset from the wrist, three phalanx lengths), metres; the middle finger's tip is 0.19 m out
_HAND = {
    "Thumb": ((0.025, 0.02, 0.0), (0.04, 0.032, 0.028)),
    "Index": ((0.02, 0.09, 0.0), (0.043, 0.026, 0.022)),
    "Middle": ((0.0, 0.092, 0.0), (0.046, 0.028, 0.024)),
    "Ring": ((-0.018, 0.088, 0.0), (0.042, 0.027, 0.022)),
    "Pinky": ((-0.034, 0.08, 0.0), (0.033, 0.02, 0.02)),
}


def hand_bvh(unit: float = 100.0, frames: int = 90, fps: float = 30.0, period: float = 1.0) -> str:
    """BVH text of a right hand alone (a hand-tracking capture): a wrist and five three-joint fingers that curl.

    An adult's hand, 0.19 m from the wrist to the middle fingertip, in ``unit`` file units per
    metre; the fingers close and open every ``period`` seconds.
    """
    lines = [
        "HIERARCHY",
        "ROOT RightHand",
        "{",
        "  OFFSET 0 0 0",
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
    ]
    for finger, (knuckle, bones) in _HAND.items():
        offsets = [knuckle, *((0.0, b, 0.0) for b in bones[:-1])]
        for k, off in enumerate(offsets):
            pad = "  " * (k + 1)
            o = np.array(off) * unit
            lines += [
                f"{pad}JOINT RightHand{finger}{k + 1}",
                pad + "{",
                f"{pad}  OFFSET {o[0]:.6f} {o[1]:.6f} {o[2]:.6f}",
                f"{pad}  CHANNELS 3 Zrotation Xrotation Yrotation",
            ]
        pad = "  " * (len(offsets) + 1)
        lines += [f"{pad}End Site", pad + "{", f"{pad}  OFFSET 0 {bones[-1] * unit:.6f} 0", pad + "}"]
        lines += ["  " * k + "}" for k in range(len(offsets), 0, -1)]
    lines.append("}")
    rows = []
    for f in range(frames):
        curl = 30.0 * (1 - np.cos(2 * np.pi * f / (fps * period)))
        rows.append(" ".join(["0 0 0 0 0 0"] + [f"0 {curl:.4f} 0"] * 15))
    lines += ["MOTION", f"Frames: {frames}", f"Frame Time: {1.0 / fps:.7f}", *rows]
    return "\n".join(lines) + "\n"
