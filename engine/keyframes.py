"""Keyframed clips: per-channel cubic Bézier curves between keys, as the thesis parametrises them (ch. 4).

A :class:`KeyframedClip` animates a skeleton through *channels* ``c``: the root
translation (3) then one rotation vector per joint (3 each; ``q = exp(c)``) — the same
coordinates :class:`engine.ik.IKRig` uses with ``root_translation=True`` and every joint
a ball, so the tangent solver reuses the static IK's Jacobians. All channels share the
key times ``t_k``; between two keys each channel is one cubic Bézier segment whose
control points are the keys and the tangents (thesis Appendix A)::

    P0 = (t_k, c(t_k)),  P1 = P0 + θ_{k+},  P2 = P3 − θ_{k+1−},  P3 = (t_{k+1}, c(t_{k+1}))

with ``θ = (θ^X, θ^Y)``: ``θ^X`` (time) sets the easing, ``θ^Y`` (value) the shape. With
``0 ≤ θ^X ≤ t_{k+1} − t_k`` (Eq. 4.7) the segment is a function of time; sampling finds
the curve parameter ``λ`` with ``B^X(λ) = t`` by safeguarded Newton to machine precision
(exactly ``λ = (t − t_k)/Δt`` when both ``θ^X`` are a third of the spacing), then
evaluates ``B^Y(λ)``. Everything that plays gets :meth:`KeyframedClip.bake`: an
ordinary :class:`engine.clip.Clip` at a frame rate.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.arrays import F64 as F
from engine.clip import Clip, RootMotion
from engine.skeleton import Skeleton

__all__ = [
    "BezierCurves",
    "KeyframedClip",
    "keyframe_clip",
    "default_keyframed_clips",
    "bezier_basis",
    "bezier_basis_slope",
]


def bezier_basis(lam: ArrayLike) -> tuple[F, F, F, F]:
    """``(H0, T+, H1, T−)`` weights of ``c(t_k)``, ``θ_{k+}``, ``c(t_{k+1})``, ``θ_{k+1−}`` at ``λ`` (Appendix A)."""
    lam = np.asarray(lam, dtype=np.float64)
    one = 1.0 - lam
    return (2.0 * lam**3 - 3.0 * lam**2 + 1.0, 3.0 * lam * one**2, 3.0 * lam**2 - 2.0 * lam**3, -3.0 * lam**2 * one)


def bezier_basis_slope(lam: F) -> tuple[F, F, F, F]:
    """``d/dλ`` of :func:`bezier_basis`."""
    return (6.0 * lam**2 - 6.0 * lam, 3.0 * (1.0 - lam) * (1.0 - 3.0 * lam), 6.0 * lam - 6.0 * lam**2,
            -3.0 * lam * (2.0 - 3.0 * lam))  # fmt: skip


def _solve_time(a: F, b: F, gap: F, u: F) -> F:
    """``λ`` with ``B^X(λ) = u`` per entry (time tangents ``a``, ``b`` within ``[0, gap]``: monotone).

    Newton from the linear guess converges in a few steps; entries it leaves unsettled
    (a flat spot at an end) finish with Newton safeguarded by bisection.
    """

    def x_and_slope(lam: F) -> tuple[F, F]:
        one = 1.0 - lam
        x = 3.0 * lam * one**2 * a + (3.0 * lam**2 - 2.0 * lam**3) * gap - 3.0 * lam**2 * one * b - u
        dx = 3.0 * one * (1.0 - 3.0 * lam) * a + 6.0 * lam * one * gap - 3.0 * lam * (2.0 - 3.0 * lam) * b
        return x, dx

    lam = u / gap
    for _ in range(6):
        x, dx = x_and_slope(lam)
        lam = np.clip(lam - x / np.where(dx > 1e-300, dx, 1e-300), 0.0, 1.0)
    x, _ = x_and_slope(lam)
    bad = np.abs(x) > 4e-16 * gap
    if bad.any():
        lo, hi, lb = np.zeros(int(bad.sum())), np.ones(int(bad.sum())), lam[bad]
        a_, b_, g_, u_ = a[bad], b[bad], gap[bad], u[bad]
        for _ in range(200):
            one = 1.0 - lb
            x = 3.0 * lb * one**2 * a_ + (3.0 * lb**2 - 2.0 * lb**3) * g_ - 3.0 * lb**2 * one * b_ - u_
            dx = 3.0 * one * (1.0 - 3.0 * lb) * a_ + 6.0 * lb * one * g_ - 3.0 * lb * (2.0 - 3.0 * lb) * b_
            hi = np.where(x > 0, lb, hi)
            lo = np.where(x <= 0, lb, lo)
            if np.all((np.abs(x) <= 4e-16 * g_) | (hi - lo <= 1e-16)):
                break
            newton = lb - x / np.where(dx > 0, dx, 1.0)
            lb = np.where((dx > 0) & (newton > lo) & (newton < hi), newton, 0.5 * (lo + hi))
        lam[bad] = lb
    return lam


@dataclass(frozen=True)
class BezierCurves:
    """``C`` animation curves over shared keys: values and in/out tangents per key and channel.

    Attributes:
        times: ``[K]`` strictly increasing key times (seconds).
        values: ``[K,C]`` channel values at the keys.
        out_x, out_y: ``[K,C]`` ``θ_{k+}`` (unused at the last key).
        in_x, in_y: ``[K,C]`` ``θ_{k−}`` (unused at the first key).
    """

    times: F
    values: F
    out_x: F
    out_y: F
    in_x: F
    in_y: F

    def __post_init__(self) -> None:
        t = np.asarray(self.times, dtype=np.float64).reshape(-1)
        k = t.size
        if k < 2 or not np.all(np.diff(t) > 0) or not np.isfinite(t).all():
            raise ValueError("key times must be at least two, finite and strictly increasing")
        arrays = {}
        for name in ("values", "out_x", "out_y", "in_x", "in_y"):
            a = np.array(getattr(self, name), dtype=np.float64)
            if a.ndim != 2 or a.shape[0] != k or a.shape[1] != np.shape(self.values)[1]:
                raise ValueError(f"{name} must be [K={k}, C]")
            if not np.isfinite(a).all():
                raise ValueError(f"{name} has NaN or infinite values")
            a.setflags(write=False)
            arrays[name] = a
        gap = np.diff(t)[:, None]
        if np.any(arrays["out_x"][:-1] < 0) or np.any(arrays["out_x"][:-1] > gap * (1 + 1e-12)):
            raise ValueError("out tangents' time components must lie in [0, key spacing] (Eq. 4.7)")
        if np.any(arrays["in_x"][1:] < 0) or np.any(arrays["in_x"][1:] > gap * (1 + 1e-12)):
            raise ValueError("in tangents' time components must lie in [0, key spacing] (Eq. 4.7)")
        t.setflags(write=False)
        object.__setattr__(self, "times", t)
        for name, a in arrays.items():
            object.__setattr__(self, name, a)

    @property
    def num_channels(self) -> int:
        """``C``."""
        return int(self.values.shape[1])

    def segment_of(self, t: ArrayLike) -> NDArray[np.int64]:
        """Index ``k`` of the segment ``[t_k, t_{k+1}]`` holding each time (clamped to the ends)."""
        k = np.searchsorted(self.times, np.asarray(t, dtype=np.float64), side="right") - 1
        return np.clip(k, 0, self.times.size - 2)

    def parameter(self, t: ArrayLike, channels: ArrayLike | None = None) -> tuple[NDArray[np.int64], F]:
        """``(segment [T], λ [T,C'])``: the Bézier parameter of each time on each channel's curve."""
        t = np.clip(np.asarray(t, dtype=np.float64).reshape(-1), self.times[0], self.times[-1])
        ch = np.arange(self.num_channels) if channels is None else np.asarray(channels, dtype=np.int64)
        k = self.segment_of(t)
        gap = (self.times[k + 1] - self.times[k])[:, None]
        u = (t - self.times[k])[:, None]
        a = self.out_x[k][:, ch]
        b = self.in_x[k + 1][:, ch]
        lam = np.broadcast_to(u / gap, a.shape).copy()
        third = gap / 3.0
        todo = (np.abs(a - third) > 1e-15) | (np.abs(b - third) > 1e-15)  # else B^X is linear in λ
        if todo.any():
            lam[todo] = _solve_time(a[todo], b[todo], np.broadcast_to(gap, a.shape)[todo],
                                    np.broadcast_to(u, a.shape)[todo])  # fmt: skip
        return k, lam

    def sample(self, t: ArrayLike) -> F:
        """``[T,C]`` channel values at times ``t`` (clamped to the key range)."""
        return self.evaluate(*self.parameter(t))

    def evaluate(self, k: NDArray[np.int64], lam: F) -> F:
        """``[T,C]`` channel values at segment ``k [T]`` and curve parameters ``λ [T,C]``."""
        h0, tp, h1, tm = bezier_basis(lam)
        return h0 * self.values[k] + tp * self.out_y[k] + h1 * self.values[k + 1] + tm * self.in_y[k + 1]

    def with_tangents(self, out_x: F, out_y: F, in_x: F, in_y: F) -> BezierCurves:
        """The same keys with new tangents (keys are never added or moved by an edit)."""
        return replace(self, out_x=out_x, out_y=out_y, in_x=in_x, in_y=in_y)


@dataclass(frozen=True)
class KeyframedClip:
    """A keyframed animation asset: Bézier channel curves of one skeleton, baked to a :class:`Clip` to play.

    Channels are ``[root x, y, z, joint 0 rotation vector, joint 1 …]`` (``3 + 3J``). A
    looping clip's last key is its first one a period later (same values).
    """

    name: str
    skeleton: Skeleton
    curves: BezierCurves
    fps: float = 60.0
    loop: bool = False
    root_motion: RootMotion | None = None
    markers: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.curves.num_channels != 3 + 3 * self.skeleton.num_joints:
            raise ValueError(f"clip {self.name!r}: needs {3 + 3 * self.skeleton.num_joints} channels")
        if not self.fps > 0:
            raise ValueError(f"clip {self.name!r}: fps must be positive")

    @property
    def duration(self) -> float:
        """Seconds from the first key to the last (the period of a loop)."""
        return float(self.curves.times[-1] - self.curves.times[0])

    @property
    def num_frames(self) -> int:
        """Frames of the baked clip."""
        n = int(round(self.duration * self.fps))
        return max(n if self.loop else n + 1, 1)

    def coordinates(self, t: ArrayLike) -> F:
        """``[T,C]`` channels at times ``t`` (a loop wraps time)."""
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        if self.loop:
            t = self.curves.times[0] + np.mod(t - self.curves.times[0], self.duration)
        return self.curves.sample(t)

    def pose_arrays(self, c: F) -> tuple[F, F]:
        """``(root [T,3], rotations [T,J,4])`` of channel rows ``c [T,C]``."""
        c = np.asarray(c, dtype=np.float64).reshape(-1, self.curves.num_channels)
        return c[:, :3].copy(), quat.exp(c[:, 3:].reshape(len(c), self.skeleton.num_joints, 3))

    def bake(self, fps: float | None = None) -> Clip:
        """The ordinary clip every player uses: the curves sampled at ``fps`` (default the clip's)."""
        rate = float(self.fps if fps is None else fps)
        n = int(round(self.duration * rate))
        n = max(n if self.loop else n + 1, 1)
        root, rot = self.pose_arrays(self.coordinates(self.curves.times[0] + np.arange(n) / rate))
        return Clip(self.name, self.skeleton, rate, root, rot, loop=self.loop, root_motion=self.root_motion,
                    markers=dict(self.markers))  # fmt: skip


def _clip_channels(clip: Clip) -> F:
    """``[F,C]`` channels of every frame, rotation vectors kept continuous from frame to frame."""
    rot = np.array(clip.rotations)
    for f in range(1, len(rot)):
        rot[f] = quat.align_hemisphere(rot[f], rot[f - 1])
    rot = quat.align_hemisphere(rot)  # the short way from the identity, so |c| ≤ π
    return np.concatenate([clip.root, quat.log(rot).reshape(len(rot), -1)], axis=1)


def keyframe_clip(clip: Clip, every: int = 6) -> KeyframedClip:
    """Keys every ``every`` frames of ``clip`` (and on its last frame / the loop seam), tangents fitted.

    Each segment's tangents are the least-squares fit of its Bézier curve (time
    tangents a third of the spacing, so sampling is a cubic in time) to the clip's
    frames inside it — the keyframed form of a baked clip, which bakes back close to it
    (see :func:`bake`; the tests bound the difference).
    """
    if every < 3:
        raise ValueError("keys need at least 3 frames between them to fit tangents")
    c = _clip_channels(clip)
    n = clip.num_frames
    if clip.loop:
        c = np.vstack([c, c[:1]])  # the seam: frame n is frame 0 one period later
        last = n
    else:
        last = n - 1
    keys = list(range(0, last, every))
    if last - keys[-1] < 3 and len(keys) > 1:
        keys.pop()
    keys.append(last)
    kf = np.array(keys)
    times = kf / clip.fps
    values = c[kf]
    cch = c.shape[1]
    out_x, out_y = np.zeros((len(kf), cch)), np.zeros((len(kf), cch))
    in_x, in_y = np.zeros((len(kf), cch)), np.zeros((len(kf), cch))
    for s in range(len(kf) - 1):
        f0, f1 = kf[s], kf[s + 1]
        gap = times[s + 1] - times[s]
        lam = (np.arange(f0, f1 + 1) - f0) / (f1 - f0)
        h0, tp, h1, tm = bezier_basis(lam)
        resid = c[f0 : f1 + 1] - h0[:, None] * values[s] - h1[:, None] * values[s + 1]
        sol, *_ = np.linalg.lstsq(np.stack([tp, tm], axis=1), resid, rcond=None)
        out_x[s], in_x[s + 1] = gap / 3.0, gap / 3.0
        out_y[s], in_y[s + 1] = sol[0], sol[1]
    curves = BezierCurves(times, values, out_x, out_y, in_x, in_y)
    return KeyframedClip(clip.name, clip.skeleton, curves, clip.fps, clip.loop, clip.root_motion, dict(clip.markers))


def default_keyframed_clips(every: int = 3) -> dict[str, KeyframedClip]:
    """The built-in clips as keyframed clips: keys every ``every`` frames, tangents fitted.

    With the default 3 a segment's cubic meets all four frames it spans, so each bakes
    back to the built-in clip's frames (to 1e-6 m in joint positions): the same look,
    now with tangents to edit. Play still uses the baked built-ins, so no simulation
    number changes.
    """
    from engine.clips import default_clips

    return {name: keyframe_clip(clip, every=every) for name, clip in default_clips().items()}
