"""Thesis Tables 4.3 and 4.1 like for like (4.1: :mod:`puppetphone.bench.curves_keys`, the keys to reach a motion).

Table 4.3: tangent-space solves by degrees of freedom, interpolation length and constraints.

Grid: 24/72/120/168 degrees of freedom × 2/7/20-frame interpolations × the six constraint
configurations of Table 4.3, in the order of its six tables: no constraint; one pin high
in the hierarchy; one pin low in it; two pins; a contact; a pin and a contact (the
table's figures of the configurations are missing from our copy of the text, so the
order of "high" and "low" is our reading of §4.3.5 and of the costs: the second table is
cheaper than the third). Each figure is the median time of ``SOLVES`` (100) drags, with
the thesis' value for the same cell (Mosek on an i7-4930K) as its baseline.

Degrees of freedom are the optimised tangent components, as in the thesis ("2 × number
of tangents"): four per channel (θ^X, θ^Y of θ_{k+} and θ_{k+1−}). A rig is a tree of ball
joints (10 cm links, limits ±1.5 rad, root translation frozen): a trunk, the dragged
branch A, and for the holds a branch B (and C) hanging off the trunk's end, so held
points share the trunk's channels with the effector (the thesis' case 3 of §4.2.3). Where
the tree has more channels than the cell's count, surplus ones are frozen (joints with
fewer axes), so exactly ``dof/4`` channels are optimised. Pins hold a joint on its
trajectory over the whole clip; a contact holds B's tip where it stands over the
segment (its keys are set equal so it does stand). Keys sit every ``frames`` frames at
30 fps; the drag is at the middle of the second segment. Targets are reachable by
construction: random changes of the dragged branch's tangents give the target.
"""

from __future__ import annotations

import time

import numpy as np

from authoring.keyframe_curves import CurveSettings, Drag, Hold, TangentSolver
from engine.ik import IKRig
from engine.keyframes import BezierCurves, KeyframedClip
from engine.skeleton import Skeleton
from puppetphone.bench.figures import Figure

__all__ = ["run", "CONFIGS", "THESIS_MS", "build_case"]

DOFS = (24, 72, 120, 168)
FRAMES = (2, 7, 20)
CONFIGS = ("none", "pin_high", "pin_low", "two_pins", "contact", "pin_contact")
SOLVES = 100
FPS = 30.0
LINK = 0.1
LIMIT = 1.5
TIP = np.array([0.0, LINK, 0.0])  # points are a link past their joint, so a joint's own rotation moves them
# Table 4.3, ms: per configuration, rows 2/7/20 frames, columns 24/72/120/168 dof.
THESIS_MS = {
    "none": ((10, 12, 16, 21), (10, 13, 16, 21), (10, 12, 16, 20)),
    "pin_high": ((52, 54, 57, 63), (59, 68, 81, 101), (63, 103, 144, 200)),
    "pin_low": ((52, 57, 69, 86), (58, 80, 94, 130), (67, 106, 158, 227)),
    "two_pins": ((55, 57, 59, 64), (60, 67, 77, 92), (60, 99, 137, 167)),
    "contact": ((53, 59, 63, 68), (63, 80, 91, 113), (65, 103, 144, 187)),
    "pin_contact": ((56, 59, 61, 66), (61, 76, 89, 99), (63, 101, 162, 191)),
}


def _tree(config: str, n: int) -> tuple[Skeleton, int, list[tuple[int, bool]], list[int], list[int]]:
    """Skeleton, effector, holds ``(joint, contact)``, the dragged branch's joints and the still joints."""
    branches = {"pin_high": 1, "pin_low": max(1, round(n / 3)), "contact": max(1, round(n / 3))}
    if config == "none":
        t, a, bs = n, 0, []
    elif config in branches:
        b = branches[config]
        t = max(1, (n - b) // 2)
        a, bs = max(1, n - b - t), [b]
    else:
        b = max(1, round(n / 6))
        t = max(1, (n - 2 * b) // 2)
        a, bs = max(1, n - 2 * b - t), [b, b]
    parents, offsets = [-1], [np.zeros(3)]
    for i in range(1, t):
        parents.append(i - 1)
        offsets.append(np.array([0.0, LINK, 0.0]))
    branch_a = list(range(t, t + a))
    for i, j in enumerate(branch_a):
        parents.append(t - 1 if i == 0 else j - 1)
        offsets.append(np.array([LINK, LINK, 0.0]) / np.sqrt(2) if i == 0 else np.array([0.0, LINK, 0.0]))
    tips, start = [], t + a
    for k, b in enumerate(bs):
        side = -1.0 if k == 0 else 0.0
        for i in range(b):
            parents.append(t - 1 if i == 0 else start + i - 1)
            offsets.append(
                np.array([side * LINK, LINK, LINK * k]) / np.sqrt(2) if i == 0 else np.array([0.0, LINK, 0.0])
            )
        tips.append((start, start + b - 1))
        start += b
    j_count = len(parents)
    eff = branch_a[-1] if branch_a else t - 1
    holds: list[tuple[int, bool]] = []
    if config == "pin_high":
        holds = [(tips[0][0], False)]
    elif config in ("pin_low", "contact"):
        holds = [(tips[0][1], config == "contact")]
    elif config == "two_pins":
        holds = [(tips[0][1], False), (tips[1][1], False)]
    elif config == "pin_contact":
        holds = [(tips[0][1], True), (tips[1][1], False)]
    sk = Skeleton(tuple(f"j{i}" for i in range(j_count)), np.array(parents), np.array(offsets), np.zeros((j_count, 3)))
    moving = branch_a if branch_a else list(range(t))
    still = [j for j in range(j_count) if j not in moving]
    return sk, eff, holds, moving, still


def build_case(
    config: str, dof: int, frames: int, seed: int = 0
) -> tuple[TangentSolver, Drag, list[Hold], list[np.ndarray]]:
    """The solver, a template drag, the holds and ``SOLVES`` reachable targets for one cell."""
    rng = np.random.default_rng(seed + 1000 * dof + 10 * frames + CONFIGS.index(config))
    sk, eff, holds, moving, still = _tree(config, dof // 12)
    j_count = sk.num_joints
    channels = 3 + 3 * j_count
    # Freeze the root translation and surplus channels (z, then y axes, from the root down).
    frozen = [0, 1, 2]
    surplus = 3 * j_count - dof // 4
    order = [3 + 3 * j + s for s in (2, 1) for j in range(j_count)]
    frozen += order[:surplus]
    keys = 4
    times = np.arange(keys) * frames / FPS
    values = rng.uniform(-0.3, 0.3, (keys, channels))
    values[:, :3] = 0.0
    gap = frames / FPS
    ox, ix = np.full((keys, channels), gap / 3), np.full((keys, channels), gap / 3)
    oy, iy = rng.uniform(-0.1, 0.1, (keys, channels)), rng.uniform(-0.1, 0.1, (keys, channels))
    if config in ("contact", "pin_contact"):
        for j in still:  # the contact's chain stands over the segment: equal keys, flat tangents
            cs = slice(3 + 3 * j, 6 + 3 * j)
            values[2, cs] = values[1, cs]
            oy[1, cs] = 0.0
            iy[2, cs] = 0.0
    values[:, frozen] = 0.0
    oy[:, frozen] = 0.0
    iy[:, frozen] = 0.0
    clip = KeyframedClip("bench", sk, BezierCurves(times, values, ox, oy, ix, iy), fps=FPS)
    rig = IKRig.build(sk, limits=dict.fromkeys(sk.names, (-LIMIT, LIMIT)), root_translation=True)
    # One segment's tangents, as Table 4.3 times them (every tangent broken: none linked to a neighbour).
    solver = TangentSolver(clip, rig, CurveSettings(linked_tangents=False), frozen=frozen)
    t = (1.5 * frames) / FPS
    # Pins over the whole clip; a contact between the two keys of the dragged segment (§4.2.2).
    hold_list = [Hold(j, frames, 2 * frames, contact=True, point=TIP) if c else Hold(j, 0, 3 * frames, point=TIP)
                 for j, c in holds]  # fmt: skip
    free = np.ones(channels, dtype=bool)
    free[frozen] = False
    mov = np.zeros(channels, dtype=bool)
    for j in moving:
        mov[3 + 3 * j : 6 + 3 * j] = True
    mov &= free
    targets = []
    for _ in range(SOLVES):
        oy2, iy2 = np.array(oy), np.array(iy)
        oy2[1, mov] += rng.uniform(-0.15, 0.15, int(mov.sum()))
        iy2[2, mov] += rng.uniform(-0.15, 0.15, int(mov.sum()))
        moved = KeyframedClip("t", sk, clip.curves.with_tangents(ox, oy2, ix, iy2), fps=FPS)
        targets.append(solver.points(np.array([t]), eff, TIP, moved)[0])
    return solver, Drag(eff, t, position=targets[0], point=TIP), hold_list, targets


def _cell(config: str, dof: int, frames: int) -> tuple[float, float, float, float, int]:
    """``(median ms, reached %, median error mm, median hold error mm, variables)`` of one cell."""
    solver, drag, holds, targets = build_case(config, dof, frames)
    solver.drag(drag, holds)  # warm imports and workspaces
    times, reached, errors, hold_errors, n, iters = [], 0, [], [], 0, []
    for target in targets:
        t0 = time.perf_counter()
        res = solver.drag(Drag(drag.joint, drag.time, position=target, point=TIP), holds)
        times.append(time.perf_counter() - t0)
        reached += res.reached
        errors.append(res.error)
        hold_errors.append(res.hold_error)
        n = res.variables
        iters.append(res.iterations)
    return (float(np.median(times)) * 1e3, 100.0 * reached / len(targets), float(np.median(errors)) * 1e3,
            float(np.median(hold_errors)) * 1e3, n)  # fmt: skip


def run() -> list[Figure]:
    """Every Table 4.3 cell (72 of them) with the thesis value as baseline; reach and accuracy per configuration."""
    figures = []
    for config in CONFIGS:
        reach, err, held = [], [], []
        for r, frames in enumerate(FRAMES):
            for c, dof in enumerate(DOFS):
                ms, pct, e_mm, h_mm, n = _cell(config, dof, frames)
                assert n == dof, f"{config} {dof}: {n} variables optimised"
                name = f"curves_ms_{config}_{dof}dof_{frames}f"
                figures.append(Figure("curves", name, ms, "ms", "thesis Table 4.3 (Mosek, i7-4930K, 2013: straw man)",
                                      float(THESIS_MS[config][r][c])))  # fmt: skip
                reach.append(pct)
                err.append(e_mm)
                held.append(h_mm)
        figures.append(Figure("curves", f"curves_reached_pct_{config}", float(np.min(reach)), "%", "all drags", 100.0))
        figures.append(Figure("curves", f"curves_error_mm_{config}", float(np.max(err)), "mm", "tolerance", 0.1))
        if config != "none":
            figures.append(
                Figure("curves", f"curves_hold_error_mm_{config}", float(np.max(held)), "mm", "epsilon", 0.1)
            )
    from puppetphone.bench import curves_keys

    return figures + curves_keys.run()  # Table 4.1 like for like: keys to reach a motion
