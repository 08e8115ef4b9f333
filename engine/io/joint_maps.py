"""Joint-name maps from common mocap skeletons onto the puppet (``engine.humanoid``).

Each map gives, per puppet joint, the source joint names to try in order (the first one
present wins), so one map covers the variants of a family (Mixamo's three spine bones,
CMU's ``Spine1``). Names are compared without a namespace prefix (``mixamorig:Hips``,
``mixamorig1:Hips``) and case-insensitively. ``AIMS`` optionally name, for a puppet leaf
joint, the source joint its bone points at when the source joint has no End Site and
no End Site (iClone and Bandai feet end in toe joints, not End Sites).

Sources: the joint lists of the files in ``shared/data/mocap`` (CMU/DAZ ``hip``/``lThigh``,
iClone ``CC_Base_*``, Bandai ``UpperLeg_L``), the published Mixamo and CMU (cgspeed
MotionBuilder-friendly) naming, the classic Biovision/MotionBuilder naming (``LeftHip``,
``LeftKnee``, ``LeftAnkle``, ``LeftCollar``/``LeftShoulder``/``LeftElbow``/``LeftWrist``) and
the lowercase naming of pose estimators (``lhip``/``lknee``/``lfoot``). Any other skeleton
takes a map from the user (``--joint-map FILE``, :func:`engine.io.motion_file.load_joint_map`).
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["JOINT_MAPS", "AIMS", "resolve_joint_map", "guess_joint_map", "strip_namespace"]

_SIDES = ("l", "r")


def _limbs(fmt: dict[str, tuple[str, ...]], left: str, right: str) -> dict[str, tuple[str, ...]]:
    out = {}
    for side, word in zip(_SIDES, (left, right)):
        for joint, names in fmt.items():
            out[f"{side}_{joint}"] = tuple(n.format(s=word) for n in names)
    return out


JOINT_MAPS: dict[str, dict[str, tuple[str, ...]]] = {
    "puppetphone": {  # our own exports: the puppet's joint names
        **{j: (j,) for j in ("hips", "spine", "chest", "neck", "head")},
        **_limbs(
            {b: (f"{{s}}_{b}",) for b in ("upper_arm", "lower_arm", "hand", "upper_leg", "lower_leg", "foot")}, "l", "r"
        ),
    },
    "cmu_daz": {
        "hips": ("hip",),
        "spine": ("abdomen",),
        "chest": ("chest",),
        "neck": ("neck",),
        "head": ("head",),
        **_limbs(
            {
                "upper_arm": ("{s}Shldr",),
                "lower_arm": ("{s}ForeArm",),
                "hand": ("{s}Hand",),
                "upper_leg": ("{s}Thigh",),
                "lower_leg": ("{s}Shin",),
                "foot": ("{s}Foot",),
            },
            "l",
            "r",
        ),
    },
    "cmu_mixamo": {
        "hips": ("Hips",),
        "spine": ("Spine", "LowerBack"),
        "chest": ("Spine2", "Spine1", "Chest"),
        "neck": ("Neck", "Neck1"),
        "head": ("Head",),
        **_limbs(
            {
                "upper_arm": ("{s}Arm",),
                "lower_arm": ("{s}ForeArm",),
                "hand": ("{s}Hand",),
                "upper_leg": ("{s}UpLeg",),
                "lower_leg": ("{s}Leg",),
                "foot": ("{s}Foot",),
            },
            "Left",
            "Right",
        ),
    },
    "cc_base": {
        "hips": ("CC_Base_Hip",),
        "spine": ("CC_Base_Waist", "CC_Base_Spine01"),
        "chest": ("CC_Base_Spine02",),
        "neck": ("CC_Base_NeckTwist01",),
        "head": ("CC_Base_Head",),
        **_limbs(
            {
                "upper_arm": ("CC_Base_{s}_Upperarm",),
                "lower_arm": ("CC_Base_{s}_Forearm",),
                "hand": ("CC_Base_{s}_Hand",),
                "upper_leg": ("CC_Base_{s}_Thigh",),
                "lower_leg": ("CC_Base_{s}_Calf",),
                "foot": ("CC_Base_{s}_Foot",),
            },
            "L",
            "R",
        ),
    },
    "biovision": {  # classic Biovision / MotionBuilder: LeftHip/LeftKnee/LeftAnkle, LeftShoulder/LeftElbow/LeftWrist
        "hips": ("Hips", "Hip", "Pelvis"),
        "spine": ("Spine", "Chest"),
        "chest": ("Chest2", "Spine1", "UpperChest"),
        "neck": ("Neck",),
        "head": ("Head",),
        **_limbs(
            {
                "upper_arm": ("{s}Shoulder", "{s}UpArm"),
                "lower_arm": ("{s}Elbow", "{s}LowArm"),
                "hand": ("{s}Wrist", "{s}Hand"),
                "upper_leg": ("{s}Hip", "{s}UpLeg"),
                "lower_leg": ("{s}Knee", "{s}LowLeg"),
                "foot": ("{s}Ankle", "{s}Foot"),
            },
            "Left",
            "Right",
        ),
    },
    "lowercase": {  # pose estimators (lhip/lknee/lfoot, lshoulder/lelbow/lwrist)
        "hips": ("hip", "hips", "pelvis", "root"),
        "spine": ("spine", "abdomen", "torso"),
        "chest": ("chest", "thorax", "spine1"),
        "neck": ("neck",),
        "head": ("head",),
        **_limbs(
            {
                "upper_arm": ("{s}shoulder", "{s}shldr"),
                "lower_arm": ("{s}elbow", "{s}forearm"),
                "hand": ("{s}wrist", "{s}hand"),
                "upper_leg": ("{s}hip", "{s}thigh"),
                "lower_leg": ("{s}knee", "{s}shin"),
                "foot": ("{s}foot", "{s}ankle"),
            },
            "l",
            "r",
        ),
    },
    "bandai": {
        "hips": ("Hips",),
        "spine": ("Spine",),
        "chest": ("Chest",),
        "neck": ("Neck",),
        "head": ("Head",),
        **_limbs(
            {
                "upper_arm": ("UpperArm_{s}",),
                "lower_arm": ("LowerArm_{s}",),
                "hand": ("Hand_{s}",),
                "upper_leg": ("UpperLeg_{s}",),
                "lower_leg": ("LowerLeg_{s}",),
                "foot": ("Foot_{s}",),
            },
            "L",
            "R",
        ),
    },
}

AIMS: dict[str, dict[str, tuple[str, ...]]] = {
    "cc_base": {"l_foot": ("CC_Base_L_ToeBase",), "r_foot": ("CC_Base_R_ToeBase",)},
    "cmu_mixamo": {"l_foot": ("LeftToeBase", "LeftToe"), "r_foot": ("RightToeBase", "RightToe")},
    "bandai": {"l_foot": ("Toes_L",), "r_foot": ("Toes_R",)},
}

_REQUIRED = ("hips", "l_upper_leg", "l_lower_leg", "l_foot", "r_upper_leg", "r_lower_leg", "r_foot")


def strip_namespace(name: str) -> str:
    """``mixamorig:Hips`` → ``hips``: the part after the last ``:`` or ``|``, lower-cased."""
    return name.replace("|", ":").rsplit(":", 1)[-1].lower()


def resolve_joint_map(candidates: dict[str, tuple[str, ...]], names: Iterable[str]) -> dict[str, str]:
    """Puppet joint → the actual source joint name, for every puppet joint whose candidates are present."""
    by_key: dict[str, str] = {}
    for n in names:
        by_key.setdefault(strip_namespace(n), n)
    out = {}
    for target, options in candidates.items():
        for option in options:
            found = by_key.get(strip_namespace(option))
            if found is not None:
                out[target] = found
                break
    return out


def guess_joint_map(names: Iterable[str]) -> tuple[str, dict[str, str], dict[str, str]]:
    """The best-matching family for a skeleton's joint names: ``(family, joint map, aims)``.

    Raises ``ValueError`` naming the families tried when none maps the hips and both legs.
    """
    names = list(names)
    scored = []
    for family, cands in JOINT_MAPS.items():
        mapping = resolve_joint_map(cands, names)
        scored.append((len(mapping), family, mapping))
    scored.sort(key=lambda s: -s[0])
    count, family, mapping = scored[0]
    missing = [j for j in _REQUIRED if j not in mapping]
    if missing:
        raise ValueError(
            f"no joint map fits these joints (best: {family!r}, missing {missing}); "
            f"known families: {', '.join(JOINT_MAPS)}; joints start {names[:8]}"
        )
    return family, mapping, resolve_joint_map(AIMS.get(family, {}), names)
