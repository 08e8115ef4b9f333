"""Synthetic performances with a known answer, for tests and benchmarks.

A performance here is a smooth periodic curve ``f(φ)`` (φ the phase in cycles) acted
out imperfectly, as the issue specifies: every cycle lasts ``T·(1+u)`` with ``u`` up to
±``jitter`` (rescaled to average exactly ``T`` so the true period is known), the phase
inside each cycle is warped a little, Gaussian noise is added to every value, and a
slow drift (zero mean over the take) moves the whole curve. ``truth(φ)`` returns the
noise-free loop, so an extracted cycle can be scored against ground truth.

Curves of thousands of dimensions are low-rank mixes of a few harmonic signals (like
cloth vertices driven by one handle), which keeps generation cheap and realistic.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.trajectory import Item, Trajectory
from engine import quat

__all__ = ["Performance", "loop_error", "make_performance", "mixed_take", "repeat_loop"]


@dataclass(frozen=True)
class Performance:
    """A synthetic take and its ground truth.

    Attributes:
        trajectory: the noisy performance.
        period: the true mean cycle duration in seconds.
        truth: noise-free values at phases ``φ`` (cycles; periodic with period 1): ``[len(φ), N]``.
        cycle_starts: the time each performed cycle began.
    """

    trajectory: Trajectory
    period: float
    truth: Callable[[NDArray[np.float64]], NDArray[np.float64]]
    cycle_starts: NDArray[np.float64]


def _durations(cycles: int, jitter: float, rng: np.random.Generator, steady_ends: bool = True) -> NDArray[np.float64]:
    """Cycle lengths ``1+u``, ``|u| ≤ jitter``, averaging exactly 1.

    The first and last cycles run at the nominal tempo (the performer settling in and
    out): an extractor can only see whole repetitions between its matches, which cover
    parts of the two end cycles, and with them at ``u = 0`` the mean over what it can see
    is the true period too. With ``steady_ends=False`` every cycle jitters (the period is
    still the mean of all of them, which no method can see exactly).
    """
    u = np.zeros(cycles)
    if not steady_ends:
        u = rng.uniform(-jitter, jitter, cycles)
        u -= u.mean()
        peak = np.max(np.abs(u))
        return 1.0 + (u * jitter / peak if peak > jitter else u)
    if cycles > 2:
        inner = rng.uniform(-jitter, jitter, cycles - 2)
        inner -= inner.mean()
        peak = np.max(np.abs(inner))
        if peak > jitter:
            inner *= jitter / peak
        u[1:-1] = inner
    return 1.0 + u


def make_performance(
    dims: int,
    rng: np.random.Generator,
    *,
    cycles: int = 8,
    period: float = 1.0,
    fps: float = 60.0,
    jitter: float = 0.15,
    noise: float = 0.02,
    drift: float = 0.1,
    rotations: int = 0,
    uneven: float = 0.0,
    harmonics: int = 4,
    steady_ends: bool = True,
) -> Performance:
    """A noisy performance of ``dims`` scalar columns (plus ``rotations`` quaternion items).

    Args:
        dims: scalar dimensions.
        rng: seeded generator (everything random comes from it).
        cycles: cycles performed.
        period: mean cycle length in seconds.
        fps: nominal sampling rate.
        jitter: each cycle's duration varies by up to ±``jitter`` (share of the period).
        noise: Gaussian noise, as a share of each column's amplitude.
        drift: slow drift amplitude, as a share of each column's amplitude.
        rotations: extra quaternion items, each a periodic swing of up to ~60°.
        uneven: sampling-time jitter as a share of the frame interval (0 = even).
        harmonics: harmonics in the latent signals.
        steady_ends: first and last cycles at the nominal tempo (see :func:`_durations`).
    """
    latent = 6
    amp = rng.normal(size=(latent, harmonics)) / (1.0 + np.arange(harmonics))
    phase = rng.uniform(0, 2 * np.pi, size=(latent, harmonics))
    mix = rng.normal(size=(latent, dims)) / np.sqrt(latent)
    rot_axis = rng.normal(size=(rotations, 3))
    rot_mix = rng.normal(size=(rotations, latent, 3)) * 0.35

    def latent_at(phi: NDArray[np.float64]) -> NDArray[np.float64]:
        h = np.arange(1, harmonics + 1)
        arg = 2 * np.pi * phi[:, None, None] * h[None, None, :] + phase[None]
        return np.sum(amp[None] * np.sin(arg), axis=2)  # [F, latent]

    def truth(phi: NDArray[np.float64]) -> NDArray[np.float64]:
        phi = np.asarray(phi, dtype=np.float64)
        z = latent_at(phi)
        parts = [z @ mix]
        for r in range(rotations):
            base = quat.from_axis_angle(rot_axis[r], 0.4)
            vec = z @ rot_mix[r]
            parts.append(quat.align_hemisphere(quat.mul(base, quat.exp(vec))))
        return np.concatenate(parts, axis=1)

    dur = _durations(cycles, jitter, rng, steady_ends) * period
    starts = np.concatenate([[0.0], np.cumsum(dur)])
    total = starts[-1]
    dt = 1.0 / fps
    t = np.arange(0.0, total, dt)
    if uneven > 0:
        t = t + rng.uniform(-uneven, uneven, len(t)) * dt * 0.5
        t[0] = 0.0
        t = np.sort(t)
    c = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, cycles - 1)
    local = (t - starts[c]) / dur[c]
    # A gentle per-cycle warp of the timing inside the cycle (monotone, fixed ends).
    wobble = rng.uniform(-0.08, 0.08, cycles)
    local = local + wobble[c] * np.sin(2 * np.pi * local) / (2 * np.pi)
    values = truth(c + local)
    n_vec = dims
    scale = np.maximum(np.std(values[:, :n_vec], axis=0), 1e-9)
    ramp = (t / total - 0.5)[:, None] * 2.0
    values[:, :n_vec] += drift * scale * ramp + noise * scale * rng.normal(size=(len(t), n_vec))
    items = [Item("signal", "scalar", 0, n_vec)] if n_vec else []
    for r in range(rotations):
        col = n_vec + 4 * r
        q = values[:, col : col + 4]
        wobble_q = quat.exp(rng.normal(size=(len(t), 3)) * noise * 0.2 + ramp * drift * 0.1)
        values[:, col : col + 4] = quat.mul(wobble_q, q)
        items.append(Item(f"rot{r}", "rotation", col, col + 4))
    return Performance(Trajectory(t, values, tuple(items)), float(period), truth, starts)


def repeat_loop(
    loop: NDArray[np.float64], times: int, rng: np.random.Generator, noise: float = 0.01
) -> NDArray[np.float64]:
    """A seamless loop ``[F, N]`` played ``times`` times with Gaussian noise (share of each column's std)."""
    rep = np.tile(loop, (times, 1))
    scale = np.maximum(np.std(loop, axis=0), 1e-9)
    return rep + noise * scale * rng.normal(size=rep.shape)


def loop_error(
    loop: NDArray[np.float64], truth: Callable[[NDArray[np.float64]], NDArray[np.float64]], offsets: int = 720
) -> tuple[float, float]:
    """How far an extracted loop ``[S, N]`` is from the ground truth, whatever phase it starts at.

    Returns ``(relative_rms, phase)``: the RMS difference over the RMS variation of the
    truth, at the start phase (in cycles) that fits best. The phase is searched on a
    grid of ``offsets`` and refined on a finer one, using at most 64 of the strongest
    columns (the search would otherwise hold offsets × S × N numbers); the error is
    then measured on every column.
    """
    s = len(loop)
    base = np.arange(s) / s
    var = truth(base)
    cols = np.argsort(np.var(var, axis=0))[::-1][:64]
    # One dense table of the truth's strongest columns, interpolated for every trial phase.
    m = 2048
    table = truth(np.arange(m + 1) / m)[:, cols]

    def errors(phases: NDArray[np.float64]) -> NDArray[np.float64]:
        x = np.mod(base[None, :] + phases[:, None], 1.0) * m
        i = np.minimum(np.floor(x).astype(np.int64), m - 1)
        w = (x - i)[..., None]
        ref = table[i] * (1.0 - w) + table[i + 1] * w
        return np.sqrt(np.mean((ref - loop[None][:, :, cols]) ** 2, axis=(1, 2)))

    grid = np.arange(offsets) / offsets
    best = grid[int(np.argmin(errors(grid)))]
    fine = best + np.linspace(-1.0 / offsets, 1.0 / offsets, 41)
    phase = float(np.mod(fine[int(np.argmin(errors(fine)))], 1.0))
    ref = truth(np.mod(base + phase, 1.0))
    scale = float(np.sqrt(np.mean((var - var.mean(axis=0)) ** 2)))
    return float(np.sqrt(np.mean((ref - loop) ** 2)) / scale), phase


def mixed_take(
    dims: int,
    rng: np.random.Generator,
    activities: tuple[tuple[float, int], ...] = ((1.0, 6), (1.6, 5), (0.7, 7)),
    fps: float = 60.0,
    fade: float = 0.3,
) -> tuple[Trajectory, list[Performance], NDArray[np.float64]]:
    """One long take of several activities in a row (jumping jacks, then twists, then squats).

    Each ``(period, cycles)`` is a :func:`make_performance` of its own shape; each activity
    fades in from where the previous one ended over ``fade`` seconds, as a performer moves
    from one to the next. Returns the take, the activities (their truths and periods) and
    the time each activity starts, with the end time last.
    """
    parts = [make_performance(dims, rng, cycles=c, period=p, fps=fps) for p, c in activities]
    blocks: list[NDArray[np.float64]] = []
    n_fade = max(1, int(fade * fps))
    for part in parts:
        v = part.trajectory.values.copy()
        if blocks:
            w = np.linspace(0.0, 1.0, n_fade)[:, None]
            v[:n_fade] = blocks[-1][-1] * (1.0 - w) + v[:n_fade] * w
        blocks.append(v)
    bounds = np.cumsum([0] + [len(b) for b in blocks]) / fps
    return Trajectory.uniform(np.concatenate(blocks), fps), parts, bounds
