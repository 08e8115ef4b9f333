"""Roles in the puppet's locomotion set, and what a clip must be to fill one.

A role names the slot a clip takes: the five cycles of the blend space (thesis Fig. 6.3:
idle, walk, run, crouch idle, crouch walk), the two one-shots the states play (get-up,
mid-jump), or a new name (an extra clip a state or a game may ask for by name). A clip
that cannot do its role's job is refused *with the reason*: a walk that does not travel
would make the lookup table promise speeds the feet never make; a cycle whose seam
jumps pops every loop; a crouch at standing height breaks the height axis.

:func:`conform` then puts an accepted clip into the conventions the blend space relies
on (the same as the built-in clips, see :mod:`engine.clips`): 60 fps; a cycle's travel
as smooth root motion along +Z with zero heading, the sway and bob left in the root;
heel-strike sync markers ``left_down``/``right_down`` found from the feet's contacts; a
travelling cycle's planted feet pinned (:mod:`engine.cliplib.plant`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from engine import quat
from engine.clip import Clip
from engine.clips.contacts import foot_contacts
from engine.skeleton import Skeleton

__all__ = [
    "ROLES",
    "CYCLIC",
    "TRAVELLING",
    "RoleError",
    "normalise_role",
    "check_role",
    "conform",
    "check_set",
    "RoleSpec",
]

_UP = np.array([0.0, 1.0, 0.0])
FPS = 60.0


class RoleError(ValueError):
    """A clip that cannot fill a role, or a role name that is not one; the message says why."""


@dataclass(frozen=True)
class RoleSpec:
    """What a role asks of a clip: a loop or not, its ground speed range (m/s), crouched or standing."""

    loop: bool | None
    speed: tuple[float, float] | None = None
    crouched: bool | None = None


ROLES: dict[str, RoleSpec] = {
    "idle": RoleSpec(True, (0.0, 0.15), False),
    "walk": RoleSpec(True, (0.5, 2.2), False),
    "run": RoleSpec(True, (1.8, 7.0), False),
    "crouch_idle": RoleSpec(True, (0.0, 0.15), True),
    "crouch_walk": RoleSpec(True, (0.2, 2.0), True),
    "get_up": RoleSpec(False),
    "mid_jump": RoleSpec(False),
}
"""The built-in roles (the keys of :func:`engine.clips.default_clips`)."""

CYCLIC = ("idle", "walk", "run", "crouch_idle", "crouch_walk")
TRAVELLING = ("walk", "run", "crouch_walk")
_NAME = re.compile(r"^[a-z][a-z0-9_]{0,39}$")
# Hips below this fraction of the skeleton's standing hips height count as crouched.
_CROUCH_FRACTION = 0.8
# A loop's seam may jump at most this many times the joint's usual step between frames (and 2°).
_SEAM_FACTOR = 3.0


def normalise_role(role: str) -> str:
    """``"crouch idle"``, ``"crouch-idle"`` and ``"crouch_idle"`` are one role; a new name must be an identifier."""
    name = re.sub(r"[\s-]+", "_", role.strip().lower())
    if not _NAME.match(name):
        raise RoleError(f"role {role!r} is not a name (letters, digits, _; roles: {', '.join(ROLES)} or a new one)")
    return name


def _seam_jump(clip: Clip) -> tuple[float, float, str]:
    """The loop seam's worst rotation jump against that joint's usual step (degrees), and the joint.

    The usual step is the 95th percentile of the joint's steps between frames, so one
    glitch inside the clip does not excuse the seam.
    """
    rot = clip.rotations
    step = np.degrees(2.0 * np.arccos(np.clip(np.abs(np.sum(rot[1:] * rot[:-1], axis=-1)), 0.0, 1.0)))  # [F-1, J]
    seam = np.degrees(2.0 * np.arccos(np.clip(np.abs(np.sum(rot[0] * rot[-1], axis=-1)), 0.0, 1.0)))
    usual = np.percentile(step, 95.0, axis=0) if len(step) else np.zeros_like(seam)
    excess = seam - np.maximum(_SEAM_FACTOR * usual, 2.0)
    excess[0] = -np.inf  # the root's heading may differ across the seam when the loop turns
    worst = int(np.argmax(excess))
    return float(seam[worst]), float(usual[worst]), clip.skeleton.names[worst]


def _ground_speed(clip: Clip) -> float:
    """Mean ground speed of the root (root motion or, if none, the root track itself) over the clip."""
    if clip.root_motion is not None:
        return clip.average_speed()
    travel = clip.root_travel() if clip.loop else clip.root[-1] - clip.root[0]
    return float(np.linalg.norm(travel[[0, 2]]) / clip.duration)


def _hips_height(clip: Clip) -> float:
    return float(clip.root[:, 1].mean())


def check_role(clip: Clip, role: str, skeleton: Skeleton) -> None:
    """Raise :class:`RoleError` saying why ``clip`` cannot be ``role`` for a puppet of ``skeleton``."""
    if tuple(clip.skeleton.names) != tuple(skeleton.names):
        raise RoleError(
            f"clip {clip.name!r} is on a {clip.skeleton.num_joints}-joint skeleton "
            f"({', '.join(clip.skeleton.names[:4])}…), not the puppet's {skeleton.num_joints} joints: "
            "retarget it (cycle --retarget puppet, or clips add does it for BVH/glTF sources)"
        )
    spec = ROLES.get(role)
    if spec is None:
        return
    if spec.loop is True and not clip.loop:
        raise RoleError(
            f"a {role} must be a loop and {clip.name!r} is not one: extract a cycle with `puppetphone cycle`"
        )
    if spec.loop is True:
        if clip.num_frames < 8:
            raise RoleError(f"{clip.name!r} has {clip.num_frames} frames; a {role} cycle needs at least 8")
        seam, step, joint = _seam_jump(clip)
        if seam > max(_SEAM_FACTOR * step, 2.0):
            raise RoleError(
                f"{clip.name!r} does not loop: its last frame jumps {seam:.0f}° at {joint} back to "
                f"the first (its steps inside are up to {step:.1f}°)"
            )
    if spec.speed is not None:
        lo, hi = spec.speed
        v = _ground_speed(clip)
        if not lo <= v <= hi:
            what = f"no forward speed ({v:.2f} m/s)" if v < 0.15 else f"a ground speed of {v:.2f} m/s"
            raise RoleError(f"a {role} moves at {lo:g}–{hi:g} m/s; {clip.name!r} has {what}")
    if spec.crouched is not None:
        stand = float(skeleton.offsets[0][1])
        h = _hips_height(clip)
        crouched = h < _CROUCH_FRACTION * stand
        if crouched != spec.crouched:
            pose = "crouched" if crouched else "standing"
            raise RoleError(
                f"a {role} is {'crouched' if spec.crouched else 'standing'} and {clip.name!r} is {pose}: "
                f"hips at {h:.2f} m of the puppet's {stand:.2f} m"
            )
    if role in TRAVELLING:
        contacts = foot_contacts(_with_travel_root_motion(_facing_travel(clip)), max_speed=0.6)
        if not contacts[:, 0].any() or not contacts[:, 1].any():
            raise RoleError(
                f"a {role} plants both feet in turn; in {clip.name!r} "
                f"{'the left' if not contacts[:, 0].any() else 'the right'} foot never touches the ground"
            )


def _yaw_quat(angle: float) -> np.ndarray:
    return quat.from_axis_angle(_UP, np.float64(angle))


def _turned(clip: Clip, angle: float, centre: np.ndarray) -> Clip:
    """The clip turned by ``angle`` about +Y around ``centre`` (root track and root rotation)."""
    q = _yaw_quat(angle)
    root = quat.rotate(q, clip.root - centre)
    rot = np.array(clip.rotations)
    rot[:, 0] = quat.mul(q, rot[:, 0])
    return replace(clip, root=root, rotations=rot)


def _facing_travel(clip: Clip) -> Clip:
    """A loop without root motion, turned so its travel goes along +Z from the ground origin."""
    if clip.root_motion is not None:
        return clip
    travel = clip.root_travel()
    angle = -float(np.arctan2(travel[0], travel[2]))
    centre = np.array([clip.root[0, 0], 0.0, clip.root[0, 2]])
    return _turned(clip, angle, centre)


def _with_travel_root_motion(clip: Clip) -> Clip:
    """A loop's travel along +Z as smooth root motion (constant speed); sway, bob and surge stay in the root."""
    if clip.root_motion is not None:
        return clip
    out = clip.travel_as_root_motion()
    root = np.array(out.root)
    root[:, 0] -= root[:, 0].mean()
    return replace(out, root=root)


def _facing_forward(clip: Clip) -> Clip:
    """An in-place clip centred over the origin with its mean heading along +Z."""
    fwd = quat.rotate(clip.rotations[:, 0], np.array([0.0, 0.0, 1.0]))
    mean = fwd.mean(axis=0)
    angle = -float(np.arctan2(mean[0], mean[2]))
    centre = np.array([clip.root[:, 0].mean(), 0.0, clip.root[:, 2].mean()])
    return _turned(clip, angle, centre)


def _heel_strikes(clip: Clip) -> dict[str, float]:
    """Normalised times of the first left and the following right heel strike (contact onsets)."""
    contacts = foot_contacts(clip, max_speed=0.6)
    n = len(contacts)
    onsets = []
    for side in (0, 1):
        c = contacts[:, side]
        rising = np.flatnonzero(c & ~np.roll(c, 1))
        if not len(rising):
            raise RoleError(f"{clip.name!r}: the {'left' if side == 0 else 'right'} foot never lands")
        # The longest contact's onset: short touches of a dragged toe are not the heel strike.
        lengths = [int(np.argmin(np.roll(c, -r))) or n for r in rising]
        onsets.append(int(rising[int(np.argmax(lengths))]))
    return {"left_down": onsets[0] / n, "right_down": onsets[1] / n}


def conform(clip: Clip, role: str) -> Clip:
    """``clip`` in the blend space's conventions for ``role``, named after it (see the module docstring)."""
    out = clip.resampled(FPS) if abs(clip.fps - FPS) > 1e-6 else clip
    if role in CYCLIC:  # a loop that came with root motion (a .ppclip) is turned and ramped like any other
        out = out.baked_root_motion()
    out = replace(out, name=role)
    if role in TRAVELLING:
        from engine.cliplib.plant import plant_feet

        out = plant_feet(_with_travel_root_motion(_facing_travel(out)))
        out = replace(out, markers=_heel_strikes(out))
    elif role in CYCLIC and out.root_motion is None:
        out = _facing_forward(out)
    return out


def check_set(clips: dict[str, Clip]) -> None:
    """The cycles together must order as the blend space places them: idle < walk < run, crouch idle < crouch walk."""
    speeds = {r: _ground_speed(clips[r]) for r in CYCLIC if r in clips}
    for slow, fast in (("idle", "walk"), ("walk", "run"), ("crouch_idle", "crouch_walk")):
        if slow in speeds and fast in speeds and not speeds[slow] < speeds[fast]:
            raise RoleError(
                f"the {slow} ({speeds[slow]:.2f} m/s) must be slower than the {fast} ({speeds[fast]:.2f} m/s)"
            )
