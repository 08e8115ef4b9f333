"""The MoCurves edit session: the cycle being refined, its edits as an undoable stack.

The session is the UI-independent model behind ``puppetphone author edit``. Its state is
a frozen snapshot — the clip (an immutable asset), the per-joint scale tracks and the
pinned keypoints — so every edit is "replace the snapshot", undo puts the previous one
back *as the same arrays*, bit for bit, and redo does the reverse.

A clip that comes with the extractor's fitted root curve (:class:`~engine.root_curve.RootCurve`,
stored in ``.ppclip`` files written by ``cycle``) is edited from those control points, as the
paper's MoCurves start from the extracted spline: a control-point drag moves them exactly,
and an edit that moves the root another way (a retime, a contact) re-fits them with the same
count. Other items, and clips without a curve, get MoCurves' own fit. Rotations have no
curve to start from: they are edited with the per-keypoint arrows.

Continuous gestures (dragging a keypoint along its curve) preview live without touching
the stack: :meth:`EditSession.begin_retime` returns a :class:`RetimeDrag` whose every move
re-solves the warm-started time-warp QP from the gesture's start state and shows the
result; ``commit`` makes the whole gesture one undo step, ``cancel`` drops it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike

from authoring.mocurves import spatial
from authoring.mocurves.contact import ContactPlane, ContactResult, solve_contacts
from authoring.mocurves.curves import MoCurve, layer_joints, mocurves
from authoring.mocurves.resample import retime_clip
from authoring.mocurves.timewarp import TimeWarp
from engine.clip import Clip
from engine.root_curve import RootCurve

__all__ = ["EditSession", "EditState", "RetimeDrag"]

from engine.arrays import F64 as F


@dataclass(frozen=True)
class EditState:
    """One undoable snapshot: clip, ``[F,J]`` scales, pinned keypoints per item, a label, the root curve."""

    clip: Clip
    scales: F
    pins: Mapping[str, frozenset[int]] = field(default_factory=dict)
    label: str = "open"
    root_curve: RootCurve | None = None


def _synced(old: EditState, new: EditState) -> EditState:
    """``new`` with its root curve re-fitted when the edit moved the root but left the curve as it was."""
    if new.root_curve is None or new.root_curve is not old.root_curve or new.clip.root is old.clip.root:
        return new
    if np.array_equal(new.clip.root, old.clip.root):
        return new
    return replace(new, root_curve=new.root_curve.refit(new.clip.root))


class EditSession:
    """A looping clip under MoCurve editing, with undo/redo.

    Args:
        clip: the cycle to edit (must loop).
        scales: optional ``[F,J]`` scale tracks (default: the clip's scale channel, else ones).
            The scale arrows edit them; :attr:`clip` carries them as its scale channel, so a
            scale edit reaches the character, the saved ``.ppclip`` and the glTF export.
        tau: falloff range τ (keypoints) of arrow edits.
        sigma: falloff sharpness σ of arrow edits.
        root_curve: the extractor's fitted root curve, when the clip came with one.
    """

    def __init__(self, clip: Clip, scales: ArrayLike | None = None, *, tau: int = 6, sigma: float = 0.08,
                 pins: Mapping[str, Iterable[int]] | None = None, root_curve: RootCurve | None = None) -> None:  # fmt: skip
        if not clip.loop:
            raise ValueError(f"clip {clip.name!r} is not a loop; MoCurves edit motion cycles")
        if clip.num_frames < 4:
            raise ValueError(f"clip {clip.name!r} has {clip.num_frames} frames; a cycle needs at least 4")
        if scales is None:
            scales = clip.scales
        s = (
            np.ones((clip.num_frames, clip.skeleton.num_joints))
            if scales is None
            else np.array(scales, dtype=np.float64)
        )
        if s.shape != (clip.num_frames, clip.skeleton.num_joints) or not np.all(s > 0):
            raise ValueError(f"scales must be positive [{clip.num_frames},{clip.skeleton.num_joints}]")
        s.setflags(write=False)
        frozen = {k: frozenset(int(i) for i in v) for k, v in (pins or {}).items()}
        if root_curve is not None and root_curve.count > clip.num_frames:
            raise ValueError(
                f"a root curve of {root_curve.count} control points does not fit {clip.num_frames} keypoints"
            )
        self._state = EditState(clip, s, frozen, root_curve=root_curve)
        self._undo: list[EditState] = []
        self._redo: list[EditState] = []
        self._preview: EditState | None = None
        self._warps: dict[tuple[int, float], TimeWarp] = {}
        self._curves: tuple[EditState, dict[str, MoCurve]] | None = None
        self._channel: tuple[EditState, Clip] | None = None
        self.tau = int(tau)
        self.sigma = float(sigma)
        self.revision = 0
        """Bumped on every change the viewport must redraw (edit, preview, undo, redo)."""

    # -- state ----------------------------------------------------------------------------
    @property
    def state(self) -> EditState:
        """What is shown: the live preview during a gesture, the committed state otherwise."""
        return self._preview if self._preview is not None else self._state

    @property
    def clip(self) -> Clip:
        """The edited clip as currently shown, its scale tracks as its scale channel (none while all are 1)."""
        st = self.state
        if self._channel is None or self._channel[0] is not st:
            unit = bool(np.all(st.scales == 1.0))
            clip = st.clip if unit and st.clip.scales is None else replace(st.clip, scales=None if unit else st.scales)
            self._channel = (st, clip)
        return self._channel[1]

    @property
    def root_curve(self) -> RootCurve | None:
        """The root's curve as currently shown (None when MoCurves fit their own)."""
        return self.state.root_curve

    @property
    def scales(self) -> F:
        """``[F,J]`` scale tracks as currently shown."""
        return self.state.scales

    def pins(self, item: str) -> frozenset[int]:
        """Keypoints of ``item`` held in time by later warps (the red points of Fig. 4)."""
        return self.state.pins.get(item, frozenset())

    def curves(self) -> dict[str, MoCurve]:
        """Every item's MoCurve of the shown state (cached until it changes)."""
        st = self.state
        if self._curves is None or self._curves[0] is not st:
            self._curves = (st, mocurves(st.clip, st.scales))
        return self._curves[1]

    def joint(self, item: str) -> int:
        """Joint index of ``item`` (a clear error for unknown names)."""
        try:
            return self.clip.skeleton.index(item)
        except (KeyError, ValueError) as exc:
            raise ValueError(f"no item {item!r} in clip {self.clip.name!r}") from exc

    def _push(self, new: EditState) -> EditState:
        if self._preview is not None:
            raise RuntimeError("finish the current drag (commit or cancel) before another edit")
        new = _synced(self._state, new)
        self._undo.append(self._state)
        self._redo.clear()
        self._state = new
        self.revision += 1
        return new

    # -- undo / redo -----------------------------------------------------------------------
    @property
    def history(self) -> list[str]:
        """Labels of the undoable edits, oldest first."""
        return [s.label for s in self._undo[1:]] + ([self._state.label] if self._undo else [])

    def can_undo(self) -> bool:
        """Whether there is an edit to undo."""
        return bool(self._undo)

    def can_redo(self) -> bool:
        """Whether there is an undone edit to redo."""
        return bool(self._redo)

    def undo(self) -> bool:
        """Restore the snapshot before the last edit exactly; False when there is none."""
        if self._preview is not None or not self._undo:
            return False
        self._redo.append(self._state)
        self._state = self._undo.pop()
        self.revision += 1
        return True

    def redo(self) -> bool:
        """Re-apply the last undone edit; False when there is none."""
        if self._preview is not None or not self._redo:
            return False
        self._undo.append(self._state)
        self._state = self._redo.pop()
        self.revision += 1
        return True

    # -- spatial edits -----------------------------------------------------------------------
    def falloff(self, i: int) -> F:
        """``[F]`` Gaussian weights around keypoint ``i`` with the session's τ and σ (the red arrows)."""
        return spatial.gaussian_weights(self.clip.num_frames, i, self.tau, self.sigma)

    def rotate_arrow(self, item: str, i: int, dtheta: ArrayLike) -> EditState:
        """Turn ``item``'s arrows at keypoint ``i`` by world rotation vector ``dθ``, neighbours by the falloff."""
        st = self._state
        clip = spatial.rotate_arrow(st.clip, self.joint(item), i, dtheta, self.tau, self.sigma)
        return self._push(replace(st, clip=clip, label=f"rotate {item}@{i}"))

    def scale_arrow(self, item: str, i: int, ds: float) -> EditState:
        """Scale ``item``'s arrows at keypoint ``i`` by ``exp(ds)``, neighbours by the falloff."""
        st = self._state
        s = spatial.scale_arrow(st.scales, self.joint(item), i, ds, self.tau, self.sigma)
        s.setflags(write=False)
        return self._push(replace(st, scales=s, label=f"scale {item}@{i}"))

    def _root_curve(self, item: str) -> RootCurve | None:
        return self.state.root_curve if self.joint(item) == 0 else None

    def control_count(self, item: str) -> int:
        """How many control points ``item``'s γ_P shows: the root curve's, else about one per five keypoints (≥ 4)."""
        curve = self._root_curve(item)
        if curve is not None:
            return curve.count
        return int(min(self.clip.num_frames, max(4, self.clip.num_frames // 5)))

    def control_points(self, item: str) -> F:
        """``[K,3]`` control points of ``item``'s γ_P (the root curve's, drawn on its travel: :meth:`RootCurve.shown`)."""
        curve = self._root_curve(item)
        if curve is not None:
            return curve.shown()
        return spatial.control_points(self.curves()[item].positions, self.control_count(item))

    def move_control_point(self, item: str, index: int, delta: ArrayLike) -> EditState:
        """Drag control point ``index`` of ``item``'s γ_P by ``delta`` (metres, character space)."""
        st = self._state
        curve = mocurves(st.clip, st.scales)[item]
        clip = spatial.move_control_point(st.clip, curve.joint, curve.positions, self.control_count(item), index, delta)
        root_curve = (
            st.root_curve.moved(index, delta) if curve.joint == 0 and st.root_curve is not None else st.root_curve
        )
        return self._push(replace(st, clip=clip, root_curve=root_curve, label=f"move {item} control {index}"))

    # -- temporal edits ---------------------------------------------------------------------
    def time_warp(self) -> TimeWarp:
        """The warm-started QP for this clip's keypoint count (kept across drags)."""
        key = (self.clip.num_frames, self.clip.duration)
        if key not in self._warps:
            self._warps[key] = TimeWarp(*key)
        return self._warps[key]

    def begin_retime(self, item: str, layer: str = "all") -> RetimeDrag:
        """Start dragging keypoints of ``item`` along its curve; the warp retimes ``layer``'s joints."""
        if self._preview is not None:
            raise RuntimeError("a drag is already in progress")
        joints = layer_joints(self.clip.skeleton, self.joint(item), layer)
        return RetimeDrag(self, item, joints)

    def retime(self, item: str, constraints: Mapping[int, float], layer: str = "all") -> EditState:
        """One-shot time warp: keypoint → wanted original time (seconds), pins held; one undo step."""
        drag = self.begin_retime(item, layer)
        for k, t in constraints.items():
            drag.set_time(int(k), float(t))
        return drag.commit()

    def set_pins(self, item: str, keypoints: Iterable[int]) -> EditState:
        """Replace ``item``'s pinned keypoints (an undoable edit)."""
        st = self._state
        n = st.clip.num_frames
        ks = frozenset(int(k) for k in keypoints)
        if any(not 0 <= k < n for k in ks):
            raise ValueError(f"pinned keypoints must be in 0…{n - 1}")
        return self._push(replace(st, pins={**st.pins, item: ks}, label=f"pins {item}"))

    # -- contacts -------------------------------------------------------------------------------
    def add_contact(self, items: Sequence[str], plane: ContactPlane) -> ContactResult:
        """Plant ``items`` on ``plane`` without sliding (paper §5.3); one undo step."""
        st = self._state
        result = solve_contacts(st.clip, [self.joint(i) for i in items], plane)
        self._push(replace(st, clip=result.clip, label=f"contact {'+'.join(items)}"))
        return result

    # used by RetimeDrag
    def _set_preview(self, state: EditState | None) -> None:
        self._preview = None if state is None else _synced(self._state, state)
        self.revision += 1


class RetimeDrag:
    """A live keypoint drag: each move re-solves the time warp from the gesture's start state."""

    def __init__(self, session: EditSession, item: str, joints: Sequence[int]) -> None:
        self.session = session
        self.item = item
        self.joints = tuple(joints)
        self.base = session.state
        self.curve = session.curves()[item]
        self.constraints: dict[int, float] = {k: k / self.base.clip.fps for k in session.pins(item)}
        self.times: F = np.arange(self.base.clip.num_frames + 1) / self.base.clip.fps

    def set_time(self, keypoint: int, t: float) -> Clip:
        """Ask keypoint ``keypoint`` to show the motion of original time ``t``; returns the preview clip."""
        n = self.base.clip.num_frames
        if not 0 <= keypoint < n:
            raise ValueError(f"keypoint {keypoint} is outside 0…{n - 1}")
        self.constraints[int(keypoint)] = float(t)
        self.times = self.session.time_warp().solve(self.constraints)
        clip, scales = retime_clip(self.base.clip, self.times, self.joints, self.base.scales)
        assert scales is not None
        scales.setflags(write=False)
        pins = {**self.base.pins, self.item: frozenset(self.constraints)}
        self.session._set_preview(EditState(clip, scales, pins, f"retime {self.item}", self.base.root_curve))
        return clip

    def drag_to(self, keypoint: int, point: ArrayLike) -> Clip:
        """Move ``keypoint`` to the curve point nearest ``point`` (world, character space): φ of it."""
        return self.set_time(keypoint, self.curve.time_at(point))

    def commit(self) -> EditState:
        """Make the gesture one undo step (nothing happens if it never moved)."""
        preview = self.session._preview
        self.session._set_preview(None)
        if preview is None:
            return self.session.state
        return self.session._push(preview)

    def cancel(self) -> None:
        """Drop the gesture; the state before it is shown again."""
        self.session._set_preview(None)
