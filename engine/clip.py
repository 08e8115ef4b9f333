"""Clips: joint tracks sampled at a fixed frame rate, with looping and root motion.

A clip stores ``root [F,3]`` and ``rotations [F,J,4]`` at ``fps``, and two optional channels
a source may animate: ``translations [F,J,3]`` (every joint's local offset per frame: bones
that stretch, prop bones, a hips joint under a skin with several roots) and ``scales [F,J]``
(per-joint uniform scale, what MoCurves' scale arrows edit). Both are ``None`` by default,
and then nothing below looks at them: the puppets' clips pay nothing for the channels.
Sampling at any time interpolates positions, translations and scales linearly and rotations
by slerp. A looping clip wraps time
and accumulates root motion across loops, so a walk played for ten seconds walks
ten seconds' worth of ground.

Root motion: :meth:`Clip.extract_root_motion` splits the root's travel (ground-plane
translation and heading about Y) out of the root track, leaving an in-place clip
plus a root-motion track; the animation system then moves the character by that
track's per-step delta, which is what keeps feet planted when playback speed varies.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = ["Clip", "RootMotion"]

_UP = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class RootMotion:
    """Ground-plane travel ``[F,3]`` (y = 0) and heading about Y ``[F]`` (radians), per frame."""

    translation: NDArray[np.float64]
    heading: NDArray[np.float64]


@dataclass(frozen=True)
class Clip:
    """An immutable animation asset.

    Attributes:
        name: clip name.
        skeleton: the skeleton it animates.
        fps: frames per second of the samples.
        root: ``[F,3]`` root position per frame.
        rotations: ``[F,J,4]`` local joint rotations per frame.
        loop: whether the clip is a cycle (its last frame flows into its first).
        root_motion: travel removed from ``root``/``rotations`` by extraction, if any.
        markers: named normalised times (e.g. ``{"left_down": 0.0, "right_down": 0.5}``) for
            phase synchronisation and contacts.
        translations: optional ``[F,J,3]`` local offset of every joint per frame (replacing
            the skeleton's offsets; joint 0's column is unused: ``root`` places it).
        scales: optional ``[F,J]`` uniform scale of every joint per frame (1 = rest); a joint's
            scale applies to its children's offsets and to everything below it.
    """

    name: str
    skeleton: Skeleton
    fps: float
    root: NDArray[np.float64]
    rotations: NDArray[np.float64]
    loop: bool = False
    root_motion: RootMotion | None = None
    markers: dict[str, float] = field(default_factory=dict)
    translations: NDArray[np.float64] | None = None
    scales: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        root = np.asarray(self.root, dtype=np.float64)
        rot = np.asarray(self.rotations, dtype=np.float64)
        if root.ndim != 2 or root.shape[1] != 3 or rot.shape != (len(root), self.skeleton.num_joints, 4):
            raise ValueError(f"clip {self.name!r}: root must be [F,3] and rotations [F,{self.skeleton.num_joints},4]")
        if len(root) < 1 or self.fps <= 0:
            raise ValueError(f"clip {self.name!r}: needs at least one frame and a positive fps")
        if not (np.isfinite(root).all() and np.isfinite(rot).all()):
            raise ValueError(f"clip {self.name!r}: contains NaN or infinite values")
        rot = quat.normalize(rot)
        # Make consecutive keys take the short way round, so slerp never spins.
        for f in range(1, len(rot)):
            rot[f] = quat.align_hemisphere(rot[f], rot[f - 1])
        root.setflags(write=False)
        rot.setflags(write=False)
        object.__setattr__(self, "root", root)
        object.__setattr__(self, "rotations", rot)
        j = self.skeleton.num_joints
        for attr, tail in (("translations", (j, 3)), ("scales", (j,))):
            value = getattr(self, attr)
            if value is None:
                continue
            arr = np.array(value, dtype=np.float64)
            if arr.shape != (len(root), *tail):
                raise ValueError(f"clip {self.name!r}: {attr} must be [F,{','.join(map(str, tail))}], got {arr.shape}")
            if not np.isfinite(arr).all() or (attr == "scales" and (arr <= 0).any()):
                raise ValueError(
                    f"clip {self.name!r}: {attr} hold NaN, infinite{' or non-positive' * (attr == 'scales')} values"
                )
            arr.setflags(write=False)
            object.__setattr__(self, attr, arr)

    @property
    def num_frames(self) -> int:
        """Number of stored frames ``F``."""
        return len(self.root)

    @property
    def duration(self) -> float:
        """Length in seconds; a loop's last frame joins the first, so it spans ``F`` frames."""
        return (self.num_frames if self.loop else self.num_frames - 1) / self.fps

    def frame_pair(
        self, t: float | NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
        """The two frames around time ``t`` (wrapped for loops, clamped otherwise) and the fraction between them."""
        f = np.asarray(t, dtype=np.float64) * self.fps
        n = self.num_frames
        if self.loop:
            f = np.mod(f, n)
            i0 = np.floor(f).astype(np.int64) % n
            i1 = (i0 + 1) % n
        else:
            f = np.clip(f, 0.0, n - 1)
            i0 = np.minimum(np.floor(f).astype(np.int64), n - 1)
            i1 = np.minimum(i0 + 1, n - 1)
        return i0, i1, f - np.floor(f)

    def sample(self, t: float | NDArray[np.float64]) -> Pose:
        """The pose at time ``t`` seconds (wrapped for loops, clamped otherwise); ``t`` may be an array."""
        i0, i1, a = self.frame_pair(t)
        root = self.root[i0] + a[..., None] * (self.root[i1] - self.root[i0])
        rot = quat.slerp(self.rotations[i0], self.rotations[i1], np.asarray(a)[..., None])
        offsets = scales = None
        if self.translations is not None:
            tr = self.translations
            offsets = tr[i0] + np.asarray(a)[..., None, None] * (tr[i1] - tr[i0])
        if self.scales is not None:
            sc = self.scales
            scales = sc[i0] + np.asarray(a)[..., None] * (sc[i1] - sc[i0])
        return Pose(root, rot, offsets, scales)

    def sample_root_motion(self, t: float) -> tuple[NDArray[np.float64], float]:
        """Accumulated root travel and heading at time ``t``, continuing across loops."""
        rm = self.root_motion
        if rm is None:
            return np.zeros(3), 0.0
        f0, f1, fa = self.frame_pair(t)
        i0, i1, a = int(f0), int(f1), float(fa)
        n = self.num_frames
        # The loop's closing segment runs from the last frame to the first frame of the
        # next cycle, whose travel is the per-cycle travel plus the first frame's.
        per_cycle_t, per_cycle_h = self.cycle_travel()
        end_t = rm.translation[i1] + (per_cycle_t if self.loop and i1 < i0 else 0.0)
        end_h = rm.heading[i1] + (per_cycle_h if self.loop and i1 < i0 else 0.0)
        trans = rm.translation[i0] + a * (end_t - rm.translation[i0])
        head = rm.heading[i0] + a * (end_h - rm.heading[i0])
        if self.loop:
            cycles = np.floor(t * self.fps / n)
            trans = trans + cycles * per_cycle_t
            head = head + cycles * per_cycle_h
        return trans, float(head)

    def cycle_travel(self) -> tuple[NDArray[np.float64], float]:
        """Root travel and heading change over one full cycle (a loop's last frame to its first included)."""
        rm = self.root_motion
        if rm is None:
            return np.zeros(3), 0.0
        f = self.num_frames
        if not self.loop or f < 3:
            return rm.translation[-1] - rm.translation[0], float(rm.heading[-1] - rm.heading[0])
        # Extrapolate the closing segment from the mean per-frame travel.
        step_t = (rm.translation[-1] - rm.translation[0]) / (f - 1)
        step_h = (rm.heading[-1] - rm.heading[0]) / (f - 1)
        return (rm.translation[-1] - rm.translation[0]) + step_t, float(rm.heading[-1] - rm.heading[0] + step_h)

    def average_speed(self) -> float:
        """Mean ground speed of the root motion in m/s (0 for an in-place clip without it)."""
        travel, _ = self.cycle_travel()
        return float(np.linalg.norm(travel) / self.duration) if self.duration > 0 else 0.0

    def extract_root_motion(self) -> Clip:
        """Split the ground-plane travel and Y heading out of the root into ``root_motion``.

        What stays in the clip is the vertical bob (``root = (0, y, 0)``) and the root
        rotation with its heading removed; the travel is expressed in the frame of the
        first frame's heading, so every clip starts at the origin facing +Z.
        """
        heading = np.unwrap(_yaw(self.rotations[:, 0]))
        h0 = heading[0]
        flat = self.root - self.root[0]
        flat[:, 1] = 0.0
        travel = quat.rotate(quat.from_axis_angle(_UP, -h0), flat)
        root = np.zeros_like(self.root)
        root[:, 1] = self.root[:, 1]
        rot = self.rotations.copy()
        rot[:, 0] = quat.mul(quat.from_axis_angle(_UP, -heading), rot[:, 0])
        return replace(self, root=root, rotations=rot, root_motion=RootMotion(travel, heading - h0))

    def root_travel(self) -> NDArray[np.float64]:
        """Travel ``[3]`` of the root track over one full cycle of a loop (zero for other clips).

        A loop that keeps its travel in the root track (what ``cycle`` writes, a glTF walk)
        does not say where its frame after the last stands: frame 0 moved on by one cycle's
        travel. Its closing step is judged as the mean of the last and the first step, which
        is exact to second order (a walk's surge changes speed slowly within one frame), and
        zero for an in-place loop (a sway's last and first steps cancel). A clip whose
        travel is root motion keeps its root track in place: no travel.
        """
        n = self.num_frames
        if not self.loop or self.root_motion is not None or n < 3:
            return np.zeros(3)
        closing = 0.5 * ((self.root[-1] - self.root[-2]) + (self.root[1] - self.root[0]))
        return self.root[-1] - self.root[0] + closing

    def travel_as_root_motion(self, travel: NDArray[np.float64] | None = None) -> Clip:
        """A loop whose root track travels, with that travel as root motion: a steady ramp on the ground.

        The ramp is ``(k/F)·travel`` (ground plane; ``travel`` defaults to :meth:`root_travel`)
        and it leaves the root track, which is also moved to start over the ground origin:
        what stays there is the loop's own sway, surge and bob, which close at the seam, so
        the loop plays in place and the game moves it by the ramp. The heading stays in the
        root rotation (root motion's heading is zero).
        """
        if not self.loop or self.root_motion is not None:
            raise ValueError(f"clip {self.name!r}: only a loop whose root track travels can move its travel out")
        step = (self.root_travel() if travel is None else np.asarray(travel, dtype=np.float64)[:3]) * [1.0, 0.0, 1.0]
        ramp = np.outer(np.arange(self.num_frames) / self.num_frames, step)
        root = self.root - ramp - self.root[0] * [1.0, 0.0, 1.0]
        return replace(self, root=root, root_motion=RootMotion(ramp, np.zeros(self.num_frames)))

    def baked_root_motion(self) -> Clip:
        """The root motion put back into the root track and root rotation (the inverse of extracting it)."""
        rm = self.root_motion
        if rm is None:
            return self
        yaw = quat.from_axis_angle(_UP, rm.heading)
        rot = np.array(self.rotations)
        rot[:, 0] = quat.mul(yaw, rot[:, 0])
        return replace(self, root=quat.rotate(yaw, self.root) + rm.translation, rotations=rot, root_motion=None)

    def resampled(self, fps: float) -> Clip:
        """The same motion sampled at another frame rate.

        A loop is sampled as one cycle closed by its first frame moved on by
        :meth:`root_travel`, so its last new frames keep walking forward instead of
        interpolating back to where the cycle started (which cut a 30 fps walk's speed
        in half and popped at the seam). :meth:`sample` itself still wraps: it is what
        play uses, and what the shipped recordings replay.
        """
        n = max(int(round(self.duration * fps)) + (0 if self.loop else 1), 1)
        t = np.arange(n) / fps
        pose = self._closed().sample(t) if self.loop else self.sample(t)
        rm = None
        if self.root_motion is not None:
            samples = [self.sample_root_motion(float(x)) for x in t]
            rm = RootMotion(np.array([s[0] for s in samples]), np.array([s[1] for s in samples]))
        return replace(
            self,
            fps=fps,
            root=pose.root,
            rotations=pose.rotations,
            root_motion=rm,
            translations=pose.offsets,
            scales=pose.scales,
        )

    def _closed(self) -> Clip:
        """A loop as a one-shot of ``F + 1`` frames: the first frame repeated, moved on by the cycle's travel."""

        def more(a: NDArray[np.float64] | None) -> NDArray[np.float64] | None:
            return None if a is None else np.concatenate([a, a[:1]])

        root = np.concatenate([self.root, self.root[:1] + self.root_travel()])
        rotations = np.concatenate([self.rotations, self.rotations[:1]])
        return replace(
            self,
            loop=False,
            root=root,
            rotations=rotations,
            root_motion=None,
            translations=more(self.translations),
            scales=more(self.scales),
        )

    def offsets(self) -> NDArray[np.float64]:
        """``[F,J,3]`` local offsets per frame: the translation channel, or the skeleton's offsets."""
        if self.translations is not None:
            return np.array(self.translations)
        return np.broadcast_to(self.skeleton.offsets, (self.num_frames, self.skeleton.num_joints, 3)).copy()


def _yaw(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Heading about +Y of rotations: the angle of their rotated +Z axis in the ground plane."""
    fwd = quat.rotate(q, np.array([0.0, 0.0, 1.0]))
    return np.arctan2(fwd[..., 0], fwd[..., 2])
