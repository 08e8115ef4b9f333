"""A scripted animator for ``author curves``: block a walk cycle from four key poses, then one curve drag.

The script works the editor as a person does — clicks on the timeline, joints dragged in
pixels, keys pressed — one operation per step, so ``author curves --script walk`` shows
and records exactly what a hand would (a recording replays without the script). The
operations are those of :meth:`CurvesScene.apply`: ``press x y shift``, ``move x y``,
``release x y`` and ``key name ctrl shift``.

The walk (+z forward, in place, 60 frames): keys at frames 0, 15, 30, 45 (and the seam).
Each key: feet placed, both feet pinned there, hips dropped (contacts) or raised
(passing), pins lifted, hands swung against the legs. Then both feet are pinned over the
whole cycle and the left hand's path is pulled up at frame 22 with one drag.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from authoring.curves_scene import CurvesScene

from authoring.bindings import ORBIT_RADIANS_PER_PIXEL

__all__ = ["walk_script", "goto_frame", "WALK_KEYS", "HAND_DRAG_FRAME", "Op"]

Op = list[Any]  # ["press", x, y, shift] | ["move", x, y] | ["release", x, y] | ["key", name, ctrl, shift]

WALK_KEYS = (0, 15, 30, 45)
HAND_DRAG_FRAME = 22
DRAG_MOVES = 6
SIDE_YAW = float(np.pi / 2)  # the camera on +x, looking at the puppet's left side
# Per key: joint → world target (metres), in the order they are posed; "pin" pins both feet.
_CONTACT_L = {"l_foot": (0.09, 0.08, 0.30), "r_foot": (-0.09, 0.10, -0.28), "pin": (), "hips": (0.0, 0.85, 0.0),
              "unpin": (), "l_hand": (0.24, 0.80, -0.14), "r_hand": (-0.24, 0.82, 0.20)}  # fmt: skip
_PASS_R = {"r_foot": (-0.09, 0.22, -0.12), "l_foot": (0.09, 0.06, 0.0), "pin": (), "hips": (0.0, 0.90, 0.0),
           "unpin": (), "l_hand": (0.24, 0.82, 0.02), "r_hand": (-0.24, 0.82, 0.02)}  # fmt: skip


def _mirror(pose: dict) -> dict:
    swap = {"l_foot": "r_foot", "r_foot": "l_foot", "l_hand": "r_hand", "r_hand": "l_hand"}
    out = {}
    for name, target in pose.items():
        out[swap.get(name, name)] = target if not target else (-target[0], target[1], target[2])
    return {name: out[name] for name in (swap.get(n, n) for n in pose)}


WALK_POSES = (_CONTACT_L, _PASS_R, _mirror(_CONTACT_L), _mirror(_PASS_R))


def _screen(scene: CurvesScene, point: ArrayLike) -> tuple[float, float]:
    x, y = scene.camera.project(np.asarray(point, dtype=np.float64)[None], *scene.size)[0]
    return round(float(x), 2), round(float(y), 2)


def _drag(scene: CurvesScene, start: tuple[float, float], end: tuple[float, float]) -> Iterator[list[Op]]:
    yield [["press", *start, False]]
    for i in range(1, DRAG_MOVES + 1):
        a = i / DRAG_MOVES
        yield [["move", round(start[0] + a * (end[0] - start[0]), 2), round(start[1] + a * (end[1] - start[1]), 2)]]
    yield [["release", *end]]


def goto_frame(scene: CurvesScene, frame: int) -> Iterator[list[Op]]:
    """A click on the timeline at ``frame``."""
    line = scene.timeline()
    x, y = round(line.x_of(frame), 2), round(line.top + line.height / 2, 2)
    yield [["press", x, y, False]]
    yield [["release", x, y]]


def _select(scene: CurvesScene, joint: str) -> Iterator[list[Op]]:
    """Click a joint of the key pose shown (a click without a move poses nothing)."""
    at = _screen(scene, scene.joint_positions()[scene.session.clip.skeleton.index(joint)])
    yield [["press", *at, False]]
    yield [["release", *at]]


def _pin_feet(scene: CurvesScene, whole: bool) -> Iterator[list[Op]]:
    for foot in ("l_foot", "r_foot"):
        yield from _select(scene, foot)
        yield [["key", "p", False, whole]]


def walk_script(scene: CurvesScene) -> Iterator[list[Op]]:
    """The operations of each step, computed from the scene as it is when their turn comes."""
    for frame in WALK_KEYS[1:]:
        yield from goto_frame(scene, frame)
        yield [["key", "k", False, False]]
    # Pose from the side: the drags run on the view plane, which is then the walk's own plane.
    side = round((scene.camera.yaw - SIDE_YAW) / ORBIT_RADIANS_PER_PIXEL, 2)
    yield [["orbit", side, 0.0]]
    for frame, pose in zip(WALK_KEYS, WALK_POSES, strict=True):
        yield from goto_frame(scene, frame)
        for joint, target in pose.items():
            if joint in ("pin", "unpin"):
                yield from _pin_feet(scene, whole=False)
                continue
            j = scene.session.clip.skeleton.index(joint)
            start = _screen(scene, scene.joint_positions()[j])
            # The drag runs on the view plane through the joint: aim at the target's place on it.
            yield from _drag(scene, start, _screen(scene, target))
    yield [["orbit", -side, 0.0]]
    yield from goto_frame(scene, WALK_KEYS[0])
    yield from _pin_feet(scene, whole=True)
    yield from _select(scene, "l_hand")
    yield from goto_frame(scene, HAND_DRAG_FRAME)
    start = _screen(scene, scene.trajectory()[HAND_DRAG_FRAME])
    yield from _drag(scene, start, (start[0], round(start[1] - 30.0, 2)))
