"""The Motion Curves scene for keyframed clips (thesis ch. 4): drag a trajectory, its tangents change.

Over :class:`~authoring.keyframe_curves.session.CurveSession` (it owns no motion data), the
scene draws the puppet at the current frame, the selected joint's trajectory over the
whole key range (orange), the keys on it (large orange dots: they never move), every
frame (small dots: their spacing is the timing) and the held frames of pins (red) and
contacts (purple). Gestures, in pixels, like ``author edit``:

- drag a point of the trajectory: the frame under the cursor follows it on the plane
  facing the camera; the tangent solver re-solves on every move from the gesture's
  start, and the release is one undo step;
- Shift+drag along the curve: re-time there (Eq. 4.12; right = faster, left = slower);
- arrows: turn the selected joint at the current frame (left/right about the vertical,
  up/down about the view's side axis), one undo step each;
- P / C: pin / contact the selected joint over the frames ±7 around the current one
  (again to remove); Tab/Shift+Tab: joint; , and .: frame; Ctrl+Z/Ctrl+Y: undo/redo.

It is independent of pygame: ``puppetphone author curves`` feeds it pixels and key
names, and the tests do the same.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.keyframe_curves.session import CurveSession
from authoring.screen_pick import pick_point, point_on_view_plane
from engine import quat
from engine.camera import OrbitCamera
from engine.fk import forward_kinematics
from engine.render.extract import puppet_capsules
from engine.render.scene import RenderScene

__all__ = ["CurvesScene"]

F = NDArray[np.float64]
ORANGE = (0.95, 0.55, 0.1)
RED = (0.9, 0.1, 0.1)
PURPLE = (0.6, 0.15, 0.85)
HOLD_HALF = 7
TURN = 0.1  # radians per arrow press


@dataclass
class _Gesture:
    kind: str  # "drag" or "retime"
    frame: int
    anchor: F
    start_px: tuple[float, float]


class CurvesScene:
    """Viewport state and interaction for one :class:`CurveSession`."""

    def __init__(self, session: CurveSession, size: tuple[int, int] = (1280, 720), joint: str = "l_hand") -> None:
        self.session = session
        self.size = size
        names = session.clip.skeleton.names
        self.joint = joint if joint in names else names[-1]
        self.frame = 0
        self.camera = OrbitCamera(target=np.array([0.0, 0.8, 0.0]), yaw=1.1, pitch=0.15, distance=2.4)
        self.gesture: _Gesture | None = None
        self.message = ""

    # -- geometry ---------------------------------------------------------------------------
    def frame_times(self) -> F:
        clip = self.session.clip
        n = clip.num_frames
        return clip.curves.times[0] + np.arange(n) / clip.fps

    def trajectory(self, clip=None) -> F:  # type: ignore[no-untyped-def]
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
        a, b, r, _ = puppet_capsules(clip.skeleton, pos, wrot)
        scene.add_capsules(a, b, r, color=(0.86, 0.86, 0.9))
        traj = self.trajectory()
        scene.add_polyline(traj, ORANGE, 3.0, closed=clip.loop)
        col = np.tile(np.array([0.2, 0.2, 0.25]), (len(traj), 1))
        sizes = np.full(len(traj), 6.0)
        for h in s.holds:
            held = s.solver.points((np.arange(h.first, h.last + 1) % clip.num_frames) / clip.fps,
                                   clip.skeleton.index(h.joint), np.zeros(3))  # fmt: skip
            scene.add_points(held, 9.0, PURPLE if h.contact else RED, pixels=True)
        keys = self._key_frames()
        col[keys] = ORANGE
        sizes[keys] = 13.0
        scene.add_points(traj, sizes, col, pixels=True)
        scene.add_points(traj[self.frame][None], 16.0, (1.0, 0.9, 0.1), pixels=True)
        self._panel(scene)

    def _panel(self, scene: RenderScene) -> None:
        s = self.session
        clip = s.clip
        k = len(clip.curves.times)
        scene.add_text(f"Motion Curves — {clip.name}   joint: {self.joint} [Tab]   frame {self.frame} [, .]", 12, 10, 20)
        holds = ", ".join(f"{'contact' if h.contact else 'pin'} {h.joint} {h.first}-{h.last}" for h in s.holds) or "none"
        scene.add_text(f"{k} keys (orange, fixed)   holds: {holds}   [P pin, C contact]", 12, 36)
        scene.add_text(f"edits: {len(s.history)}  {' · '.join(s.history[-3:])}   drag the curve · Shift+drag re-time · "
                       "arrows turn · Ctrl+Z/Y · Ctrl+S save", 12, 60)  # fmt: skip
        if self.message:
            scene.add_text(self.message, 12, 84, 18, (1.0, 0.85, 0.4))

    # -- time ---------------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Nothing plays by itself: the scene shows one frame, chosen with , and . or by dragging."""

    # -- mouse ----------------------------------------------------------------------------------
    def press(self, px: float, py: float, *, shift: bool = False) -> bool:
        """Button down on the trajectory: start a drag (or a re-time with Shift)."""
        p = (float(px), float(py))
        traj = self.trajectory()
        f = pick_point(self.camera, self.size, traj, p)
        if f is None:
            return False
        if f in set(self._key_frames().tolist()) and not shift:
            self.message = "a key cannot move: drag a frame between keys"
            return False
        self.frame = f
        self.gesture = _Gesture("retime" if shift else "drag", f, traj[f], p)
        return True

    def move(self, px: float, py: float) -> None:
        """While dragging: re-solve from the gesture's start state towards the cursor (live preview)."""
        g = self.gesture
        if g is None or g.kind != "drag":
            return
        target = point_on_view_plane(self.camera, self.size, (float(px), float(py)), g.anchor)
        res = self.session.drag(self.joint, self.frame_times()[g.frame], position=target, commit=False)
        self.message = "" if res.reached else f"out of reach (miss {res.error * 1e3:.0f} mm): kept the last pose"

    def release(self, px: float, py: float) -> None:
        """Button up: the gesture becomes one undo step."""
        g, self.gesture = self.gesture, None
        if g is None:
            return
        t = float(self.frame_times()[g.frame])
        if g.kind == "retime":
            sigma = (float(px) - g.start_px[0]) * 2e-4
            try:
                self.session.retime(t, sigma)
            except ValueError as exc:
                self.message = str(exc)
            return
        self.move(px, py)
        self.session.commit_preview(f"drag {self.joint}@{g.frame}")

    # -- keys -----------------------------------------------------------------------------------
    def key(self, name: str, *, ctrl: bool = False, shift: bool = False) -> None:
        """A key by name: ``tab``, ``,``, ``.``, ``left``/``right``/``up``/``down``, ``p``, ``c``, ``z``/``y`` with Ctrl."""
        s = self.session
        clip = s.clip
        names = clip.skeleton.names
        if ctrl and name == "z":
            s.undo()
        elif ctrl and name == "y":
            s.redo()
        elif name == "tab":
            self.joint = names[(names.index(self.joint) + (-1 if shift else 1)) % len(names)]
        elif name in (",", "."):
            self.frame = (self.frame + (1 if name == "." else -1)) % clip.num_frames
        elif name in ("left", "right", "up", "down"):
            self._turn(name)
        elif name in ("p", "c"):
            first = max(0, self.frame - HOLD_HALF)
            s.toggle_hold(self.joint, first, min(clip.num_frames - 1, self.frame + HOLD_HALF), contact=name == "c")

    def _turn(self, arrow: str) -> None:
        s = self.session
        clip = s.clip
        t = float(self.frame_times()[self.frame])
        j = clip.skeleton.index(self.joint)
        root, rot = clip.pose_arrays(clip.coordinates([t]))
        _, wrot = forward_kinematics(clip.skeleton, root[0], rot[0])
        axis = np.array([0.0, 1.0, 0.0]) if arrow in ("left", "right") else np.cross(self.camera.forward, [0.0, 1.0, 0.0])
        angle = TURN if arrow in ("right", "up") else -TURN
        goal = quat.mul(quat.from_axis_angle(axis / np.linalg.norm(axis), angle), wrot[j])
        try:
            res = s.drag(self.joint, t, orientation=goal)
        except ValueError as exc:
            self.message = str(exc)
            return
        self.message = "" if res.reached else "that turn is out of reach"
