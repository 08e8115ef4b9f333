"""Length units of a motion file, judged by the figure it holds.

Neither BVH nor (in practice) glTF says reliably what its numbers measure: BVH has no unit
field, and a glTF exported by Blender from a centimetre BVH is a 150 m giant although glTF
means metres. A human figure carries its own ruler, though: the leg (hip joint to ankle)
of an adult is about 0.82 m, so the unit that makes the leg closest to that (on a log
scale) is the file's unit. The units are far apart (an inch is 2.54 cm, CMU's unit 2.22
inches), so a figure no unit makes an adult (1.4..2.0 m) is no reason to pick the least
bad one (1.12 m and 2.16 m tall figures of one set): its lengths are scaled continuously
to an adult's 0.82 m leg instead, and the decision says so (unit ``scaled``). When no joint map finds the legs (a fox, a cylinder), the
figure's largest rest extent against a human height is the fallback for BVH, and glTF
keeps its metres unless that extent is absurd for any character (beyond 0.02..50 m), and
then picks among the metric units only (Fox.glb is a 95-unit fox: centimetres).

``cmu`` is the unit of the CMU database's ASF skeletons as kept by the common BVH
conversion: ``length 0.45`` means 1 unit = 1/0.45 inch, so such files are neither inches
(a 0.6 m person) nor centimetres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine import quat
from engine.fk import forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["UNITS", "Units", "judge_units", "given_units"]

UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "cmu": 0.0254 / 0.45}
HUMAN_LEG = 0.82  # metres, hip joint to ankle of an adult
HUMAN_HEIGHT = 1.7
FIT = 1.2  # a unit fits when it makes the leg 0.68..0.98 m (an adult of about 1.4..2.0 m)
SCALED = "scaled"  # the unit's name when no unit fits: lengths scaled to an adult's leg
_SANE_EXTENT = (0.02, 50.0)  # metres: from a mouse to a dinosaur


@dataclass(frozen=True)
class Units:
    """A unit decision: its name (a key of :data:`UNITS`), metres per file unit, and why."""

    name: str
    scale: float
    basis: str


def given_units(name: str) -> Units:
    """The unit the user named (``--units``); ``ValueError`` listing the known ones otherwise."""
    key = name.strip().lower()
    if key not in UNITS:
        raise ValueError(f"unknown unit {name!r}; use one of {', '.join(UNITS)}")
    return Units(key, UNITS[key], "given")


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


def rest_extent(skeleton: Skeleton) -> float:
    """Largest side of the rest figure's bounding box (joints and bone tips), in file units."""
    wpos, wrot = forward_kinematics(skeleton, skeleton.offsets[0], quat.identity(skeleton.num_joints))
    pts = np.concatenate([wpos, wpos + quat.rotate(wrot, skeleton.tips)])
    return float(np.max(pts.max(axis=0) - pts.min(axis=0)))


def judge_units(skeleton: Skeleton, metric: bool = False, joint_map: dict[str, str] | None = None) -> Units:
    """The file's unit, judged by the figure (see the module docstring).

    Args:
        skeleton: the rest skeleton in file units.
        metric: the format means metres (glTF): a non-human figure keeps metres unless absurd.
        joint_map: puppet joint → source joint, when the caller knows it (``--joint-map``).
    """
    leg = _leg_length(skeleton, joint_map)
    if leg is not None:
        name = _nearest(leg, HUMAN_LEG)
        implied = leg * UNITS[name]
        if abs(np.log(implied / HUMAN_LEG)) <= np.log(FIT):
            return Units(name, UNITS[name], f"leg length {leg:.4g} file units")
        return Units(SCALED, HUMAN_LEG / leg, f"leg length {leg:.4g} file units fits no unit (in {name} a "
                                             f"{implied:.2f} m leg): scaled to a {HUMAN_LEG:g} m leg")
    extent = rest_extent(skeleton)
    if not extent > 0:
        return Units("m", 1.0, "no extent")
    if metric and _SANE_EXTENT[0] <= extent <= _SANE_EXTENT[1]:
        return Units("m", 1.0, f"glTF metres (figure {extent:.3g} m, not human)")
    name = _nearest(extent, HUMAN_HEIGHT, ("m", "cm", "mm") if metric else tuple(UNITS))
    return Units(name, UNITS[name], f"figure extent {extent:.4g} file units")
