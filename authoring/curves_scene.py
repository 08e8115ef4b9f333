"""The Motion Curves scene for keyframed clips (thesis ch. 4): drag a trajectory, its tangents change.

Over :class:`~authoring.keyframe_curves.session.CurveSession` (it owns no motion data), the
scene draws the puppet at the current frame, the selected joint's trajectory over the
whole key range (orange), the keys on it (large orange dots: they never move), every
frame (small dots: their spacing is the timing) and the held frames of pins (red) and
contacts (purple). Gestures, in pixels, like ``author edit``:

- drag a point of the trajectory: the frame under the cursor follows it on the plane
  facing the camera; the tangent solver re-solves on every move from the gesture's
  start, and the release is one undo step;
- Shift+drag along the curve, or drag the magenta spacing handle under the current frame
  sideways (Fig. 4.4 right): re-time there (Eq. 4.12; right = frames apart, faster; left =
  closer, slower), one undo step;
- the teal sticks along the curve are the joint's heading at every other frame (Fig. 4.4,
  middle); drag the grip at the current frame's stick to turn the joint there in place
  (the tangent solver between keys, the static IK at a key); the arrows turn it too (left/right
  about the vertical, up/down about the view's side axis), one undo step each;
- P / C: pin / contact the selected joint over the frames ±7 around the current one
  (again to remove); Shift+P: pin it over the whole clip; Tab/Shift+Tab: joint; , and .:
  frame; [ and ]: previous / next key; Ctrl+Z/Ctrl+Y: undo/redo.

Key poses (thesis §4.2.5, §4.3.1), on the timeline strip along the bottom
(:mod:`authoring.curves_timeline`): a click there picks the frame, a drag of a key's diamond
moves the key; K adds a key at the current frame (the motion does not change), Delete or X
removes the key there. At a key's frame, dragging a joint of the puppet (or the key's dot
on the trajectory) poses the key with the static IK: joints held at that frame stay put,
the rig's limits and stiffness apply, and a target out of reach keeps the closest pose with
its residual shown (§4.4).

It is independent of pygame: ``puppetphone author curves`` feeds it pixels and key
names, and the tests do the same.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.curves_handles import ORIENT_RGB, bone_axis, orientation_sticks, turn_towards
from authoring.curves_timeline import Timeline
from authoring.curves_view import framing_camera, panel_layout
from authoring.keyframe_curves.session import CurveSession
from authoring.screen_pick import pick_point, point_on_view_plane
from engine import quat
from engine.character.load import Character
from engine.character.view import character_instance
from engine.fk import forward_kinematics
from engine.keyframes import KeyframedClip
from engine.render.extract import puppet_capsules
from engine.render.scene import RenderScene

__all__ = ["CurvesScene"]

from engine.arrays import F64 as F

ORANGE = (0.95, 0.55, 0.1)
RED = (0.9, 0.1, 0.1)
PURPLE = (0.6, 0.15, 0.85)
JOINT_RGB = (0.1, 0.55, 0.95)
SPACING_RGB = (0.9, 0.2, 0.75)
SPACING_OFFSET_PX = 26.0
SPACING_PER_PX = 2e-4  # seconds of tangent length per pixel, as Shift+drag
HOLD_HALF = 7
TURN = 0.1  # radians per arrow press


@dataclass
class _Gesture:
    kind: str  # "drag", "retime", "pose" (a key's joint), "orient" (the grip), "key" (on the timeline) or "scrub"
    frame: int
    anchor: F
    start_px: tuple[float, float]
    key: int = -1
    moved: bool = False


class CurvesScene:
    """Viewport state and interaction for one :class:`CurveSession`."""

    def __init__(self, session: CurveSession, size: tuple[int, int] = (1280, 720), joint: str = "l_hand") -> None:
        self.session = session
        self.size = size
        names = session.clip.skeleton.names
        self.joint = joint if joint in names else names[-1]
        self.frame = 0
        self.gesture: _Gesture | None = None
        self.message = ""
        self._turn_from: tuple[F, F] = (quat.identity(), np.zeros(3))  # an orient gesture's start: rotation, base
        self.camera = framing_camera(self._all_joint_positions(), size)
        self.character: Character | None = None  # drawn instead of the mannequin (``author curves --character``)

    def _all_joint_positions(self) -> F:
        """``[N,3]`` the puppet's surface extremes over the clip (capsule ends ± radius): what the framing must show."""
        clip = self.session.clip
        roots, rots = clip.pose_arrays(clip.coordinates(self.frame_times()))
        out = []
        for f in range(0, len(roots), max(1, len(roots) // 24)):
            pos, wrot = forward_kinematics(clip.skeleton, roots[f], rots[f])
            a, b, r, _ = puppet_capsules(clip.skeleton, pos, wrot)
            for end in (a, b):
                out.append(end + r[:, None] * np.array([0.0, 1.0, 0.0]))
                out.append(end - r[:, None] * np.array([0.0, 1.0, 0.0]))
        return np.vstack(out)

    def timeline(self) -> Timeline:
        """The key strip's layout in the current window."""
        return Timeline(self.size, self.session.clip.num_frames)

    def key_index(self, frame: int | None = None) -> int | None:
        """Index of the key at ``frame`` (default the current one), or None between keys."""
        frames = self.session.key_frames()
        f = self.frame if frame is None else frame
        n = self.session.clip.num_frames
        for k, kf in enumerate(frames):
            if kf == f or (self.session.clip.loop and kf == n and f == 0):
                return k
        return None

    def joint_positions(self) -> F:
        """``[J,3]`` the puppet's joints at the current frame."""
        clip = self.session.clip
        root, rot = clip.pose_arrays(clip.coordinates([self.frame_times()[self.frame]]))
        pos, _ = forward_kinematics(clip.skeleton, root[0], rot[0])
        return np.asarray(pos)

    # -- geometry ---------------------------------------------------------------------------
    def frame_times(self) -> F:
        clip = self.session.clip
        n = clip.num_frames
        return clip.curves.times[0] + np.arange(n) / clip.fps

    def trajectory(self, clip: KeyframedClip | None = None) -> F:
        """``[F,3]`` the selected joint's position at every frame."""
        s = self.session
        j = s.clip.skeleton.index(self.joint)
        return s.solver.points(self.frame_times(), j, np.zeros(3), clip or s.clip)

    def _key_frames(self) -> NDArray[np.int64]:
        clip = self.session.clip
        return np.rint((clip.curves.times - clip.curves.times[0]) * clip.fps).astype(np.int64) % clip.num_frames

    # -- drawing ------------------------------------------------------------------------------
    def draw(self, scene: RenderScene) -> None:
        """The puppet, the trajectory with keys, frames and holds, and the panel."""
        s = self.session
        clip = s.clip
        scene.ground.snow = 0.0
        scene.ground.grid_spacing = 0.25
        c = clip.coordinates([self.frame_times()[self.frame]])
        root, rot = clip.pose_arrays(c)
        pos, wrot = forward_kinematics(clip.skeleton, root[0], rot[0])
        if self.character is not None:
            scene.skinned.append(character_instance(self.character, clip.skeleton, root[0], rot[0]))
        else:
            a, b, r, _ = puppet_capsules(clip.skeleton, pos, wrot)
            scene.add_capsules(a, b, r, color=(0.86, 0.86, 0.9))
        traj = self.trajectory()
        scene.add_polyline(traj, ORANGE, 3.0, closed=clip.loop)
        col = np.tile(np.array([0.2, 0.2, 0.25]), (len(traj), 1))
        sizes = np.full(len(traj), 6.0)
        for h in s.holds:
            joint = clip.skeleton.index(h.joint) if isinstance(h.joint, str) else int(h.joint)  # as the solver reads it
            held = s.solver.points((np.arange(h.first, h.last + 1) % clip.num_frames) / clip.fps, joint, np.zeros(3))
            scene.add_points(held, 9.0, PURPLE if h.contact else RED, pixels=True)
        keys = self._key_frames()
        col[keys] = ORANGE
        sizes[keys] = 13.0
        scene.add_points(traj, sizes, col, pixels=True)
        scene.add_points(traj[self.frame][None], 16.0, (1.0, 0.9, 0.1), pixels=True)
        base, tip, _ = orientation_sticks(s, self.frame_times(), clip.skeleton.index(self.joint))
        scene.add_lines(base[::2], tip[::2], ORIENT_RGB, 2.0)  # the joint's heading along the curve
        scene.add_lines(base[self.frame][None], tip[self.frame][None], ORIENT_RGB, 4.0)
        scene.add_points(tip[self.frame][None], 14.0, ORIENT_RGB, pixels=True)  # the grip that turns it
        if self.key_index() is None:  # the spacing handle (Fig. 4.4 right): sideways scales the timing here
            scene.add_points(self.spacing_handle()[None], 12.0, SPACING_RGB, pixels=True)
        if self.key_index() is not None:  # a key pose: its joints are handles for the static IK,
            toward = self.camera.eye - pos  # drawn just in front of the body so it never hides them
            lift = (clip.skeleton.radii + 0.02)[:, None] * toward / np.linalg.norm(toward, axis=1, keepdims=True)
            scene.add_points(pos + lift, 10.0, JOINT_RGB, pixels=True)
        img, rect = self.timeline().picture(s.key_frames(), self.frame)
        scene.add_overlay(img, rect)
        self._panel(scene)

    def _panel(self, scene: RenderScene) -> None:
        s = self.session
        clip = s.clip
        font, step = panel_layout(self.size)
        k = len(clip.curves.times)
        at = self.key_index()
        where = f"key {at}" if at is not None else "between keys"
        scene.add_text(f"Motion Curves — {clip.name}   {self.joint} [Tab]   frame {self.frame} ({where}) [, . [ ]]",
                       12, 10, font + 2)  # fmt: skip
        holds = (
            ", ".join(f"{'contact' if h.contact else 'pin'} {h.joint} {h.first}-{h.last}" for h in s.holds) or "none"
        )
        scene.add_text(f"{k} keys [K add, X delete]   holds: {holds} [P, C]", 12, 10 + step, font)
        tool = "drag a joint: pose the key" if at is not None else "drag the curve · Shift: re-time · arrows turn"
        scene.add_text(f"edits: {len(s.history)} ({s.history[-1] if s.history else 'none'})   {tool} · Ctrl+Z/Y/S",
                       12, 10 + 2 * step, font)  # fmt: skip
        if self.message:
            scene.add_text(self.message, 12, 10 + 3 * step, font, (1.0, 0.85, 0.4))

    # -- time ---------------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Nothing plays by itself: the scene shows one frame, chosen with , and . or on the timeline."""

    # -- mouse ----------------------------------------------------------------------------------
    def press(self, px: float, py: float, *, shift: bool = False) -> bool:
        """Button down: on the timeline (pick a frame, grab a key), on a key's joint (pose it), or on the trajectory."""
        p = (float(px), float(py))
        line = self.timeline()
        if line.contains(*p):
            k = line.key_at(p[0], self.session.key_frames())
            frames = self.session.key_frames()
            if k is not None and 0 < k < len(frames) - 1:
                self.frame = frames[k]
                self.gesture = _Gesture("key", frames[k], np.zeros(3), p, key=k)
            else:
                self.frame = line.frame_at(p[0])
                self.gesture = _Gesture("scrub", self.frame, np.zeros(3), p)
            return True
        if not shift and self._press_grip(p):
            return True
        if (
            not shift
            and self.key_index() is None
            and pick_point(self.camera, self.size, self.spacing_handle()[None], p) == 0
        ):
            self.gesture = _Gesture("space", self.frame, self.spacing_handle(), p)
            return True
        key = self.key_index()
        if key is not None and not shift:
            j = pick_point(self.camera, self.size, self.joint_positions(), p)
            if j is not None:
                self.joint = self.session.clip.skeleton.names[j]
                self.gesture = _Gesture("pose", self.frame, self.joint_positions()[j], p, key=key)
                return True
        traj = self.trajectory()
        f = pick_point(self.camera, self.size, traj, p)
        if f is None:
            return False
        self.frame = f
        key = self.key_index()
        if key is not None and not shift:  # a key's dot on the curve: pose that key by its joint
            self.gesture = _Gesture("pose", f, traj[f], p, key=key)
            return True
        self.gesture = _Gesture("retime" if shift else "drag", f, traj[f], p)
        return True

    def spacing_handle(self) -> F:
        """Where the spacing handle is drawn: :data:`SPACING_OFFSET_PX` below the current frame's point on screen."""
        at = self.trajectory()[self.frame]
        px = self.camera.project(at[None], *self.size)[0]
        return point_on_view_plane(self.camera, self.size, (float(px[0]), float(px[1]) + SPACING_OFFSET_PX), at)

    def _space(self, g: _Gesture, px: float, commit: bool) -> None:
        """Eq. 4.12 by the handle's sideways travel: right moves the frames apart here (faster), left closer."""
        sigma = (px - g.start_px[0]) * SPACING_PER_PX
        if sigma == 0.0:
            return
        try:
            self.session.retime(float(self.frame_times()[g.frame]), sigma, commit=commit)
        except ValueError as exc:
            self.message = str(exc)

    def _press_grip(self, p: tuple[float, float]) -> bool:
        """A press on the current frame's orientation grip starts turning the joint there."""
        j = self.session.clip.skeleton.index(self.joint)
        t = self.frame_times()[self.frame : self.frame + 1]
        _, tip, rot = orientation_sticks(self.session, t, j)
        if pick_point(self.camera, self.size, tip, p) is None:
            return False
        # Handles that overlap on screen: the nearer one wins (the curve's point, the joints at a key, the spacing handle).
        d_grip = float(np.linalg.norm(self.camera.project(tip, *self.size)[0] - np.asarray(p)))
        others = np.vstack([self.joint_positions() if self.key_index() is not None else self.spacing_handle()[None],
                            self.trajectory()[self.frame][None]])  # fmt: skip
        if np.nanmin(np.linalg.norm(self.camera.project(others, *self.size) - np.asarray(p), axis=1)) < d_grip:
            return False
        key = self.key_index()
        self.gesture = _Gesture("orient", self.frame, tip[0], p, key=-1 if key is None else key)
        self._turn_from = (rot[0], self.trajectory()[self.frame])
        return True

    def _orient(self, g: _Gesture, px: float, py: float) -> None:
        """Turn the joint so its bone points at the grip's place under the cursor (live preview)."""
        rot, base = self._turn_from
        grip = point_on_view_plane(self.camera, self.size, (px, py), g.anchor)
        axis = bone_axis(self.session.clip.skeleton, self.session.clip.skeleton.index(self.joint))
        goal = turn_towards(rot, axis, grip - base)
        if g.key >= 0:  # the joint stays where it is (in place) and turns
            res = self.session.pose(g.key, self.joint, base, commit=False, orientation=goal)
            self.message = "" if res.reached else f"turn out of reach: closest pose kept (residual {res.residual:.2f})"
            return
        out = self.session.drag(self.joint, self.frame_times()[g.frame], position=base, orientation=goal, commit=False)
        self.message = "" if out.reached else "that turn is out of reach: closest kept"

    def move(self, px: float, py: float) -> None:
        """While dragging: re-solve from the gesture's start state towards the cursor (live preview)."""
        g = self.gesture
        if g is None or g.kind == "retime":
            return
        g.moved = g.moved or (float(px), float(py)) != g.start_px
        if g.kind == "scrub":
            self.frame = self.timeline().frame_at(px)
            return
        if g.kind == "key":
            self._move_key(g, px, commit=False)
            return
        if g.kind == "orient":
            self._orient(g, float(px), float(py))
            return
        if g.kind == "space":
            self._space(g, float(px), commit=False)
            return
        target = point_on_view_plane(self.camera, self.size, (float(px), float(py)), g.anchor)
        if g.kind == "pose":
            res = self.session.pose(g.key, self.joint, target, commit=False)
            self.message = (
                "" if res.reached else f"out of reach: closest pose kept (residual {res.residual * 1e3:.0f} mm)"
            )
            return
        out = self.session.drag(self.joint, self.frame_times()[g.frame], position=target, commit=False)
        self.message = (
            ""
            if out.reached
            else (
                f"out of reach: closest kept (residual {out.closest_error * 1e3:.0f} mm)"
                if self.session.preview is not None
                else f"out of reach (miss {out.error * 1e3:.0f} mm): a pin would slip"
            )
        )

    def _move_key(self, g: _Gesture, px: float, commit: bool) -> None:
        frame = self.timeline().frame_at(px)
        if frame == g.frame:
            self.session.cancel_preview()
            return
        try:
            self.session.move_key(g.key, frame, commit=commit)
            self.frame = frame
        except ValueError as exc:
            self.message = str(exc)

    def release(self, px: float, py: float) -> None:
        """Button up: the gesture becomes one undo step."""
        g, self.gesture = self.gesture, None
        if g is None or g.kind == "scrub":
            return
        if g.kind == "key":
            self.session.cancel_preview()
            self._move_key(g, px, commit=True)
            return
        if g.kind == "space":
            self.session.cancel_preview()
            self._space(g, float(px), commit=True)
            return
        t = float(self.frame_times()[g.frame])
        if g.kind == "retime":
            sigma = (float(px) - g.start_px[0]) * 2e-4
            try:
                self.session.retime(t, sigma)
            except ValueError as exc:
                self.message = str(exc)
            return
        if not g.moved and (float(px), float(py)) == g.start_px:
            self.session.cancel_preview()  # a click: the joint is selected, nothing is posed
            return
        self.move(px, py)
        if g.kind == "orient":
            self.session.commit_preview(f"turn {self.joint}@{g.frame}")
        elif g.kind == "pose":
            self.session.commit_preview(f"pose {self.joint}@key {g.key}")
        else:
            self.session.commit_preview(f"drag {self.joint}@{g.frame}")

    def apply(self, op: list | tuple) -> None:
        """One recorded tool operation: ``press x y shift``, ``move x y``, ``release x y``, ``key name ctrl shift``,
        ``orbit dx dy`` (pixels) or ``zoom factor``."""
        kind = op[0]
        if kind == "press":
            self.press(float(op[1]), float(op[2]), shift=bool(op[3]))
        elif kind == "move":
            self.move(float(op[1]), float(op[2]))
        elif kind == "release":
            self.release(float(op[1]), float(op[2]))
        elif kind == "key":
            self.key(str(op[1]), ctrl=bool(op[2]), shift=bool(op[3]))
        elif kind == "orbit":  # middle-button drag, in pixels
            self.camera.orbit(-float(op[1]) * 0.01, float(op[2]) * 0.01)
        elif kind == "zoom":
            self.camera.zoom(float(op[1]))
        else:
            raise ValueError(f"unknown operation {kind!r}")

    # -- keys -----------------------------------------------------------------------------------
    def key(self, name: str, *, ctrl: bool = False, shift: bool = False) -> None:
        """A key by name: ``tab``, ``,``, ``.``, ``[``, ``]``, arrows, ``p``, ``c``, ``k``, ``x``/``delete``, ``z``/``y`` with Ctrl."""
        s = self.session
        clip = s.clip
        names = clip.skeleton.names
        n = clip.num_frames
        if ctrl and name == "z":
            s.undo()
        elif ctrl and name == "y":
            s.redo()
        elif name == "tab":
            self.joint = names[(names.index(self.joint) + (-1 if shift else 1)) % len(names)]
        elif name in (",", "."):
            self.frame = (self.frame + (1 if name == "." else -1)) % n
        elif name in ("[", "]"):
            frames = sorted({f % n for f in s.key_frames()})
            later = [f for f in frames if f > self.frame] or frames[:1]
            earlier = [f for f in frames if f < self.frame] or frames[-1:]
            self.frame = later[0] if name == "]" else earlier[-1]
        elif name == "k":
            self._key_edit(lambda: s.add_key(self.frame))
        elif name in ("x", "delete"):
            at = self.key_index()
            if at is None:
                self.message = "no key here to delete: [ and ] go to a key"
            else:
                self._key_edit(lambda: s.delete_key(at))
        elif name in ("left", "right", "up", "down"):
            self._turn(name)
        elif name in ("p", "c"):
            first, last = (0, n - 1) if shift else (max(0, self.frame - HOLD_HALF), min(n - 1, self.frame + HOLD_HALF))
            s.toggle_hold(self.joint, first, last, contact=name == "c")

    def _key_edit(self, edit: Callable[[], object]) -> None:
        try:
            edit()
            self.message = ""
        except ValueError as exc:
            self.message = str(exc)

    def _turn(self, arrow: str) -> None:
        s = self.session
        clip = s.clip
        t = float(self.frame_times()[self.frame])
        j = clip.skeleton.index(self.joint)
        root, rot = clip.pose_arrays(clip.coordinates([t]))
        _, wrot = forward_kinematics(clip.skeleton, root[0], rot[0])
        axis = (
            np.array([0.0, 1.0, 0.0]) if arrow in ("left", "right") else np.cross(self.camera.forward, [0.0, 1.0, 0.0])
        )
        angle = TURN if arrow in ("right", "up") else -TURN
        goal = quat.mul(quat.from_axis_angle(axis / np.linalg.norm(axis), angle), wrot[j])
        try:
            res = s.drag(self.joint, t, orientation=goal)
        except ValueError as exc:
            self.message = str(exc)
            return
        self.message = "" if res.reached else "that turn is out of reach"
