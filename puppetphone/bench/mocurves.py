"""MoCurves: time-warp QP solve time at 30–240 keypoints, cold and warm, and the contact solve.

``timewarp_ms_N`` is a cold solve (the QP core's workspace set up and solved for one drag); the goal
(DESIGN.md) is under 5 ms at 120 keypoints, and at 120 it is also compared with scipy's
SLSQP on the same problem — the general-purpose solver a real QP solver replaces.
``timewarp_warm_ms_N`` is the interactive case: the next move of a drag, re-solved by the
same workspace from its last active set. ``contact_solve_ms`` is one stroke under the
default walk (projection, λ fit, re-integration and the leg IK of both feet).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from functools import partial

import numpy as np
from scipy.optimize import minimize

from authoring.mocurves.contact import plane_from_stroke, solve_contacts
from authoring.mocurves.timewarp import W_SOFT, W_STRONG, TimeWarp, _energy_rows
from engine.clips import default_clips
from engine.fk import forward_kinematics
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run", "slsqp_timewarp"]

SIZES = (30, 60, 120, 240)
GOAL_MS = 5.0


def _drag(n: int, step: int = 0) -> dict[int, float]:
    """A two-keypoint drag like Fig. 4: one moved later by a tenth of the cycle, one held."""
    return {n // 4: (n // 4) / n + 0.1 + 0.002 * step, (3 * n) // 4: ((3 * n) // 4) / n}


def slsqp_timewarp(n: int, constraints: dict[int, float]) -> np.ndarray:
    """The same QP handed to scipy's SLSQP (the baseline)."""
    times = np.arange(n + 1) / n
    pr, vel, speed = (m.toarray() for m in _energy_rows(n))
    idx = np.array(sorted(constraints))
    tgt = np.array([constraints[i] for i in idx])

    def f(t: np.ndarray) -> float:
        return float(W_STRONG * np.sum((t[idx] - tgt) ** 2) + W_STRONG * (pr[0] @ t - 1.0) ** 2
                     + W_SOFT * np.sum((vel @ t - np.diff(times)) ** 2) + W_SOFT * np.sum((speed @ t) ** 2))  # fmt: skip

    cons = {"type": "ineq", "fun": lambda t: np.diff(t), "jac": lambda t: vel}
    return np.asarray(minimize(f, times, method="SLSQP", constraints=[cons], options={"maxiter": 500}).x)


def _cold_solve(n: int) -> None:
    """A fresh workspace's first solve (``timewarp_ms_N``)."""
    TimeWarp(n, 1.0).solve(_drag(n))


def _warm_solve(n: int, warp: TimeWarp, steps: Iterator[int]) -> None:
    """The drag's next move re-solved by a warm workspace (``timewarp_warm_ms_N``)."""
    warp.solve(_drag(n, next(steps) % 20))


def run() -> list[Figure]:
    """Time-warp cold/warm solve times per size and the contact solve time."""
    figures = []
    slsqp_ms = median_time(lambda: slsqp_timewarp(120, _drag(120)), repeats=3, min_time=0.0) * 1e3
    for n in SIZES:
        cold = median_time(partial(_cold_solve, n), repeats=9) * 1e3
        warp = TimeWarp(n, 1.0)
        warp.solve(_drag(n))
        warm = median_time(partial(_warm_solve, n, warp, iter(range(1, 10**9))), repeats=9) * 1e3
        base, base_value = ("scipy SLSQP, same QP", slsqp_ms) if n == 120 else ("goal at 120 keypoints", GOAL_MS)
        figures.append(Figure("mocurves", f"timewarp_ms_{n}", cold, "ms", base, base_value))
        figures.append(Figure("mocurves", f"timewarp_warm_ms_{n}", warm, "ms", "cold solve", cold))
    walk = replace(default_clips()["walk"], root_motion=None)
    sk = walk.skeleton
    feet = [sk.index("l_foot"), sk.index("r_foot")]
    pos, _ = forward_kinematics(sk, walk.root, walk.rotations)
    h = float(pos[:, feet, 1].min()) + 0.02
    plane = plane_from_stroke([-1.0, h, 0.0], [1.0, h, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0])
    contact = median_time(lambda: solve_contacts(walk, feet, plane), repeats=9) * 1e3
    fk_ms = median_time(lambda: forward_kinematics(sk, walk.root, walk.rotations), repeats=9) * 1e3
    figures.append(Figure("mocurves", "contact_solve_ms", contact, "ms", "one FK of the 66-frame walk", fk_ms))
    return figures
