"""The MoCurves edit scene: one viewport where a cycle is refined while it plays (SCA 2017 §5).

The scene is the interface over :class:`~authoring.mocurves.EditSession`; it owns no
motion data. It draws the looping puppet, every item's MoCurve (faint) and the selected
one (bold) with its keypoints — their spacing shows speed — and an overlay panel; it turns
mouse gestures, in pixels, into session edits. Four modes (keys 1–4):

- **points** — drag a control point of γ_P (the white balls);
- **arrows** — each keypoint as two orthogonal arrows (orientation, length = scale);
  drag one sideways to turn it about the view axis, with Shift (or the right button)
  up/down to scale it; the arrows the Gaussian falloff reaches are red;
- **timing** — drag a keypoint along its curve: the warm-started time-warp QP re-solves on
  every move and the loop shows the result live; held keypoints are red;
- **contact** — draw a straight stroke under the curves: the feet are planted on its plane
  (the view is levelled on entering, since the plane contains the view direction).

Keys: Tab/Shift+Tab item, L layer, [ ] τ, - = σ, Space play/pause, Ctrl+Z/Ctrl+Y undo/redo,
Ctrl+S save. It is independent of pygame: the loop (``puppetphone author edit``) feeds it
pixels and key names, and the headless test does the same.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from authoring.mocurves import LAYERS, EditSession, RetimeDrag, item_chain, plane_from_stroke
from authoring.mocurves.curves import MoCurve
from authoring.screen_pick import pick_point, point_on_view_plane
from engine.camera import OrbitCamera
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.render.extract import puppet_capsules
from engine.render.scene import RenderScene, SkinnedInstance
from engine.skinning import SkinBinding

__all__ = ["EditScene", "MODES", "speed_lines"]

from engine.arrays import F64 as F

MODES = ("points", "arrows", "timing", "contact")
CURVE = (0.95, 0.55, 0.1)
FAINT = (0.55, 0.6, 0.7)
RED = (0.9, 0.1, 0.1)
PURPLE = (0.6, 0.15, 0.85)
WHITE = (1.0, 1.0, 1.0)


def speed_lines(clip: Clip, curve: MoCurve) -> list[str]:
    """The two speeds an animator reads, apart: how fast the character travels, how fast the item moves.

    One range "0.41–4.84 m/s" for a walk mixed them up; the root's is the cycle's travel over
    its period, the item's is along its curve in the character's frame (the body carried along).
    """
    travel = clip.average_speed()
    root = (
        f"root: travels {travel:.2f} m/s (the cycle's travel ÷ its {clip.duration:.2f} s)"
        if travel > 1e-3
        else "root: stays in place (no travel over the cycle)"
    )
    speeds = curve.speeds()
    item = (
        f"{curve.item}: {speeds.min():.2f}–{speeds.max():.2f} m/s along its curve, relative to the body "
        "(a planted foot slides back at about the root's speed; fastest mid-swing)"
    )
    return [root, item]


@dataclass
class _Gesture:
    kind: str  # "control", "arrow", "retime", "stroke"
    index: int
    start_px: tuple[float, float]
    anchor: F
    last_px: tuple[float, float]
    scale: bool = False
    retime: RetimeDrag | None = None


class EditScene:
    """Viewport state and interaction of the edit scene for one session.

    Args:
        session: the edit session (undo stack, save) this scene drives.
        size: viewport size in pixels (picking needs it).
        contact_items: items a contact stroke plants (the feet by default).
    """

    def __init__(self, session: EditSession, size: tuple[int, int] = (1280, 720),
                 contact_items: tuple[str, ...] = ("l_foot", "r_foot"),
                 character: SkinBinding | None = None) -> None:  # fmt: skip
        self.session = session
        self.character = character
        """The file's own skinned character, drawn in place of the mannequin when the clip came with one."""
        self.size = size
        names = session.clip.skeleton.names
        self.items = tuple(n for j, n in enumerate(names) if j == 0 or item_chain(session.clip.skeleton, j))
        self.item = "l_foot" if "l_foot" in self.items else self.items[0]
        self.layer = "all"
        self.mode = "timing"
        self.contact_items = tuple(i for i in contact_items if i in names)
        self.time = 0.0
        self.playing = True
        self.focus = 0
        """Keypoint under the cursor or last edited: the centre of the red falloff."""
        self.camera = OrbitCamera(target=np.array([0.0, 0.6, 0.1]), yaw=1.25, pitch=0.2, distance=2.7)
        self.gesture: _Gesture | None = None
        self.message = ""

    # -- time ------------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Advance the loop by ``dt`` seconds when playing (edits never stop it)."""
        if self.playing:
            self.time = float(np.mod(self.time + dt, self.session.clip.duration))

    # -- drawing -----------------------------------------------------------------------------
    def draw(self, scene: RenderScene) -> None:
        """Fill ``scene`` with the puppet, the curves of the current mode and the panel."""
        s = self.session
        clip, curves = s.clip, s.curves()
        scene.ground.snow = 0.0  # a flat floor: curves and arrows read better on it
        scene.ground.grid_spacing = 0.25
        pose = clip.sample(self.time)
        pos, rot = forward_kinematics(clip.skeleton, pose.root, pose.rotations, pose.offsets, pose.scales)
        if self.character is not None:
            scene.skinned.append(SkinnedInstance(self.character.meshes, self.character.matrices(pos, rot)))
        else:
            a, b, r, _ = puppet_capsules(clip.skeleton, pos, rot)
            scene.add_capsules(a, b, r, color=(0.86, 0.86, 0.9))
        for name in self.items:
            if name != self.item:
                scene.add_polyline(curves[name].positions, FAINT, 1.5, closed=True)
        curve = curves[self.item]
        scene.add_polyline(curve.positions, CURVE, 3.0, closed=True)
        frame = int(np.floor(self.time * clip.fps)) % clip.num_frames
        if self.mode == "arrows":
            tips, base = curve.arrows(0.07)
            w = s.falloff(self.focus)
            col = np.where(w[:, None] > 0, np.array(RED), np.array([0.15, 0.35, 0.95]))
            scene.add_lines(base, tips[:, 0], col, 2.0)
            scene.add_lines(base, tips[:, 1], np.where(w[:, None] > 0, np.array(RED), np.array([0.1, 0.7, 0.3])), 2.0)
        else:
            pins = s.pins(self.item)
            col = np.tile(np.array([0.2, 0.2, 0.25]), (curve.num_keypoints, 1))
            if pins:
                col[sorted(pins)] = RED
            sizes = np.where(np.isin(np.arange(curve.num_keypoints), sorted(pins)), 11.0, 7.0)
            scene.add_points(curve.positions, sizes, col, pixels=True)
        if self.mode == "points":
            scene.add_spheres(s.control_points(self.item), 0.018, WHITE)
        scene.add_points(curve.positions[frame][None], 16.0, (1.0, 0.9, 0.1), pixels=True)
        g = self.gesture
        if g is not None and g.kind == "stroke":
            scene.add_line(g.anchor, point_on_view_plane(self.camera, self.size, g.last_px, g.anchor), PURPLE, 4.0)
        self._panel(scene)

    def _panel(self, scene: RenderScene) -> None:
        s = self.session
        curve = s.curves()[self.item]
        scene.add_text(f"MoCurves — {s.clip.name}   mode: {self.mode.upper()}   [1-4]", 12, 10, 20)
        scene.add_text(
            f"item: {self.item} [Tab]   layer: {self.layer} [L]   τ = {s.tau} [ ]   σ = {s.sigma:.3g} [- =]", 12, 36
        )
        scene.add_text(
            f"t = {self.time:5.2f} / {s.clip.duration:.2f} s {'playing' if self.playing else 'paused'} [Space]", 12, 60
        )
        for k, line in enumerate(speed_lines(s.state.clip, curve)):
            scene.add_text(line, 12, 84 + 22 * k)
        hist = s.history[-3:]
        scene.add_text(f"edits: {len(s.history)}  {' · '.join(hist)}   undo Ctrl+Z  redo Ctrl+Y  save Ctrl+S", 12, 128)
        if self.message:
            scene.add_text(self.message, 12, 152, 18, (1.0, 0.85, 0.4))

    # -- mouse ------------------------------------------------------------------------------------
    def press(self, px: float, py: float, *, shift: bool = False) -> bool:
        """Mouse button down at pixel ``(px, py)``; True when it started a gesture."""
        s, p = self.session, (float(px), float(py))
        curve = s.curves()[self.item]
        if self.mode == "contact":
            centre = np.mean([s.curves()[i].positions.mean(axis=0) for i in self.contact_items], axis=0)
            self.gesture = _Gesture("stroke", -1, p, point_on_view_plane(self.camera, self.size, p, centre), p)
            return True
        if self.mode == "points":
            ctrl = s.control_points(self.item)
            k = pick_point(self.camera, self.size, ctrl, p)
            if k is not None:
                self.gesture = _Gesture("control", k, p, ctrl[k], p)
            return k is not None
        k = pick_point(self.camera, self.size, curve.positions, p)
        if k is None:
            return False
        self.focus = k
        if self.mode == "arrows":
            self.gesture = _Gesture("arrow", k, p, curve.positions[k], p, scale=shift)
        else:
            drag = s.begin_retime(self.item, self.layer)
            self.gesture = _Gesture("retime", k, p, curve.positions[k], p, retime=drag)
        return True

    def move(self, px: float, py: float) -> None:
        """Mouse moved (button held or not): drags update live; hovering moves the falloff focus."""
        g, p = self.gesture, (float(px), float(py))
        if g is None:
            if self.mode == "arrows":
                k = pick_point(self.camera, self.size, self.session.curves()[self.item].positions, p)
                self.focus = self.focus if k is None else k
            return
        g.last_px = p
        if g.kind == "retime" and g.retime is not None:
            g.retime.drag_to(g.index, point_on_view_plane(self.camera, self.size, p, g.anchor))

    def release(self, px: float, py: float) -> None:
        """Mouse button up: the gesture becomes one undoable edit (or a clear message)."""
        g, p = self.gesture, (float(px), float(py))
        self.gesture = None
        if g is None:
            return
        s = self.session
        try:
            if g.kind == "retime" and g.retime is not None:
                g.retime.drag_to(g.index, point_on_view_plane(self.camera, self.size, p, g.anchor))
                g.retime.commit()
            elif g.kind == "control":
                moved = point_on_view_plane(self.camera, self.size, p, g.anchor) - g.anchor
                s.move_control_point(self.item, g.index, moved)
            elif g.kind == "arrow":
                dx, dy = p[0] - g.start_px[0], p[1] - g.start_px[1]
                if g.scale:
                    s.scale_arrow(self.item, g.index, -dy * 0.01)
                else:
                    s.rotate_arrow(self.item, g.index, self.camera.forward * (dx * 0.01))
            elif g.kind == "stroke":
                end = point_on_view_plane(self.camera, self.size, p, g.anchor)
                root = s.curves()[s.clip.skeleton.names[0]].positions.mean(axis=0)
                plane = plane_from_stroke(g.anchor, end, self.camera.forward, root)
                result = s.add_contact(list(self.contact_items), plane)
                travel = float(np.linalg.norm(result.clip.cycle_travel()[0]))
                self.message = (
                    f"contact: {int(result.contacts.sum())} keypoints planted, root travels {travel:.2f} m per cycle"
                )
        except ValueError as exc:
            if g.retime is not None:
                g.retime.cancel()
            self.message = str(exc)

    # -- keys ---------------------------------------------------------------------------------------
    def key(self, name: str, *, ctrl: bool = False, shift: bool = False) -> None:
        """A key press by name (``"1"``, ``"tab"``, ``"z"``, ``"space"``, ``"["`` …)."""
        s = self.session
        if ctrl and name == "z":
            s.undo()
        elif ctrl and name == "y":
            s.redo()
        elif name in ("1", "2", "3", "4"):
            self.mode = MODES[int(name) - 1]
            if self.mode == "contact":
                # The stroke's plane holds the view direction: level the view so that a
                # level stroke gives a level ground plane (the paper's side view).
                self.camera.pitch = 0.0
        elif name == "tab":
            i = self.items.index(self.item) + (-1 if shift else 1)
            self.item = self.items[i % len(self.items)]
        elif name == "l":
            self.layer = LAYERS[(LAYERS.index(self.layer) + 1) % len(LAYERS)]
        elif name == "[":
            s.tau = max(0, s.tau - 1)
        elif name == "]":
            s.tau += 1
        elif name == "-":
            s.sigma = max(0.0, s.sigma / 1.5)
        elif name == "=":
            s.sigma = s.sigma * 1.5 if s.sigma > 0 else 0.01
        elif name == "space":
            self.playing = not self.playing
