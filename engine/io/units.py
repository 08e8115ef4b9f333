"""Length units of a motion file, judged by the figure it holds.

Neither BVH nor (in practice) glTF says reliably what its numbers measure: BVH has no unit
field, and a glTF exported by Blender from a centimetre BVH is a 150 m giant although glTF
means metres. A figure carries its own ruler, though, and which ruler depends on what it is:

- **a human figure** (a joint map finds its legs): the leg (hip joint to ankle) of an adult
  is about 0.82 m, so the unit that makes the leg closest to that (on a log scale) is the
  file's unit;
- **a hand alone** (finger joints, no legs: a hand-tracking capture): wrist to fingertip is
  about 0.19 m; a hand is never judged against a person's height (that made a 0.96 m hand);
- **anything else** (a fox, a cylinder): no leg is looked for; its overall rest extent is the
  only ruler. glTF keeps its metres unless that extent is absurd for any character (beyond
  0.02..50 m); BVH takes the first of the usual units (cm, m, in, mm, cmu) that makes it a
  character's size (0.1..10 m), and the decision says it was judged by extent.

The units are far apart (an inch is 2.54 cm, CMU's unit 2.22 inches), so a figure that no
unit makes a plausible size (a human of 1.12 m or 2.16 m in a set whose other files are
1.5 m tall) is no reason to pick the least bad one: its lengths are scaled *continuously*
to the stated size (an adult's 0.82 m leg, a 0.19 m hand, a 1.7 m figure), and the decision
says so (unit ``scaled``, :attr:`Units.target`). ``--height`` states the size outright: the
figure is scaled to stand that tall, whatever its file says.

``cmu`` is the unit of the CMU database's ASF skeletons as kept by the common BVH
conversion: ``length 0.45`` means 1 unit = 1/0.45 inch, so such files are neither inches
(a 0.6 m person) nor centimetres.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from engine import quat
from engine.fk import forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["UNITS", "Units", "given_height", "given_units", "judge_units"]

UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "cmu": 0.0254 / 0.45}
HUMAN_LEG = 0.82  # metres, hip joint to ankle of an adult
HUMAN_HEIGHT = 1.7
HUMAN_HAND = 0.19  # metres, wrist to the tip of the middle finger of an adult
FIT = 1.2  # a unit fits when it makes the leg 0.68..0.98 m (an adult of about 1.4..2.0 m), the hand 0.16..0.23 m
SCALED = "scaled"  # the unit's name when no unit fits: lengths scaled continuously to a stated size
_SANE_EXTENT = (0.02, 50.0)  # metres: from a mouse to a dinosaur (glTF keeps metres inside this)
_CHARACTER_EXTENT = (0.1, 10.0)  # metres: a BVH figure of unknown kind, from a cat to an elephant
_EXTENT_ORDER = ("cm", "m", "in", "mm", "cmu")  # BVH's usual units, the most common first
_FINGERS = re.compile(r"thumb|index|middle|mid\d|ring|pinky|little|finger", re.IGNORECASE)
_MIN_FINGERS = 3


@dataclass(frozen=True)
class Units:
    """A unit decision: its name (a key of :data:`UNITS`, or ``scaled``), metres per file unit, and why.

    ``target`` is the size a ``scaled`` figure was scaled to ("a 0.82 m leg"); ``None`` for a unit.
    """

    name: str
    scale: float
    basis: str
    target: str | None = None


def given_units(name: str) -> Units:
    """The unit the user named (``--units``); ``ValueError`` listing the known ones otherwise."""
    key = name.strip().lower()
    if key not in UNITS:
        raise ValueError(f"unknown unit {name!r}; use one of {', '.join(UNITS)}")
    return Units(key, UNITS[key], "given")


def given_height(height: float, measured: float) -> Units:
    """Lengths scaled so a figure ``measured`` file units tall stands ``height`` metres (``--height``)."""
    if not (np.isfinite(height) and height > 0):
        raise ValueError(f"--height must be a positive number of metres, got {height:g}")
    if not measured > 0:
        raise ValueError("--height: the figure has no height to scale (every joint at one level)")
    return Units(
        SCALED,
        height / measured,
        f"--height {height:g} m (the figure is {measured:.4g} file units tall)",
        target=f"a {height:g} m tall figure",
    )


def _nearest(value: float, target: float, among: tuple[str, ...] = tuple(UNITS)) -> str:
    return min(among, key=lambda u: abs(np.log(value * UNITS[u] / target)))


def _leg_length(skeleton: Skeleton, joint_map: dict[str, str] | None) -> float | None:
    """Mean rest length (file units) of the two legs, hip joint to ankle, when the map finds them."""
    from engine.io.joint_maps import guess_joint_map

    if joint_map is None:
        try:
            _, joint_map, _ = guess_joint_map(skeleton.names)
        except ValueError:
            return None
    lengths = []
    for side in ("l", "r"):
        upper, foot = joint_map.get(f"{side}_upper_leg"), joint_map.get(f"{side}_foot")
        if upper in skeleton.names and foot in skeleton.names:
            chain = skeleton.chain(upper, foot)
            lengths.append(float(np.linalg.norm(skeleton.offsets[chain[1:]], axis=1).sum()))
    good = [x for x in lengths if x > 0]
    return float(np.mean(good)) if good else None


def _rest_points(skeleton: Skeleton) -> np.ndarray:
    """``[2J, 3]`` rest positions of the joints and their bone tips, in file units."""
    wpos, wrot = forward_kinematics(skeleton, skeleton.offsets[0], quat.identity(skeleton.num_joints))
    return np.concatenate([wpos, wpos + quat.rotate(wrot, skeleton.tips)])


def rest_extent(skeleton: Skeleton) -> float:
    """Largest side of the rest figure's bounding box (joints and bone tips), in file units."""
    pts = _rest_points(skeleton)
    return float(np.max(pts.max(axis=0) - pts.min(axis=0)))


def hand_length(skeleton: Skeleton) -> float | None:
    """Wrist to farthest fingertip (file units) of a skeleton of fingers, or ``None`` when it has too few.

    The wrist is the fingers' nearest common ancestor; the length is the farthest finger
    joint or bone tip from it in the rest pose.
    """
    fingers = [j for j, name in enumerate(skeleton.names) if _FINGERS.search(name)]
    if len(fingers) < _MIN_FINGERS:
        return None
    lines = []
    for j in fingers:
        line = [j]
        while skeleton.parents[line[-1]] >= 0:
            line.append(int(skeleton.parents[line[-1]]))
        lines.append(line[::-1])
    wrist = 0
    for k in range(min(len(x) for x in lines)):
        if len({x[k] for x in lines}) > 1:
            break
        wrist = lines[0][k]
    pts = _rest_points(skeleton)
    n = skeleton.num_joints
    wpos = pts[wrist]
    reach = np.linalg.norm(pts[np.concatenate([fingers, np.asarray(fingers) + n])] - wpos, axis=1)
    length = float(reach.max())
    return length if length > 0 else None


def _fit_or_scale(measure: float, reference: float, part: str, prefix: str = "") -> Units:
    """The unit making the ``part`` (``measure`` file units) closest to ``reference`` metres if one fits, else a continuous scale."""
    name = _nearest(measure, reference)
    implied = measure * UNITS[name]
    said = f"{prefix}{part} length {measure:.4g} file units"
    if abs(np.log(implied / reference)) <= np.log(FIT):
        return Units(name, UNITS[name], said)
    return Units(
        SCALED,
        reference / measure,
        f"{said} fits no unit (in {name} a {implied:.3g} m {part}): scaled to a {reference:g} m {part}",
        target=f"a {reference:g} m {part}",
    )


def judge_units(skeleton: Skeleton, metric: bool = False, joint_map: dict[str, str] | None = None) -> Units:
    """The file's unit, judged by the figure (see the module docstring).

    Args:
        skeleton: the rest skeleton in file units.
        metric: the format means metres (glTF): a non-human figure keeps metres unless absurd.
        joint_map: puppet joint → source joint, when the caller knows it (``--joint-map``).
    """
    leg = _leg_length(skeleton, joint_map)
    if leg is not None:
        return _fit_or_scale(leg, HUMAN_LEG, "leg")
    hand = hand_length(skeleton)
    if hand is not None:
        return _fit_or_scale(hand, HUMAN_HAND, "hand", "no legs, fingers: ")
    extent = rest_extent(skeleton)
    if not extent > 0:
        return Units("m", 1.0, "no extent")
    if metric and _SANE_EXTENT[0] <= extent <= _SANE_EXTENT[1]:
        return Units("m", 1.0, f"glTF metres (no legs: figure extent {extent:.3g} m)")
    lo, hi = _CHARACTER_EXTENT
    for name in ("m", "cm", "mm") if metric else _EXTENT_ORDER:
        if lo <= extent * UNITS[name] <= hi:
            return Units(
                name,
                UNITS[name],
                f"no legs: figure extent {extent:.4g} file units, a {extent * UNITS[name]:.3g} m figure in {name}",
            )
    return Units(
        SCALED,
        HUMAN_HEIGHT / extent,
        f"no legs: figure extent {extent:.4g} file units fits no unit: scaled to {HUMAN_HEIGHT:g} m",
        target=f"a {HUMAN_HEIGHT:g} m figure",
    )
