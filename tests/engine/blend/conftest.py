"""Synthetic gait clips on the default humanoid: small, exact and independent of the authored clips.

A gait swings the thighs by ``±amp`` (left heel strike at phase 0, right at
``right_down``), bends the knee in swing, and travels at the speed a planted
stance foot implies (``4·L·sin(amp)/T``); a crouch bends hips and knees and lowers
the root. Every clip has root motion extracted and sync markers, like the
authored ``engine.clips`` ones.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip, RootMotion
from engine.humanoid import humanoid_skeleton

LEG = 0.84
_X = np.array([1.0, 0.0, 0.0])


def gait_clip(
    name: str,
    period: float,
    amp: float,
    crouch: float = 0.0,
    fps: float = 30.0,
    right_down: float = 0.5,
    speed: float | None = None,
) -> Clip:
    """A looping gait (``amp = 0``: an idle that breathes) with root motion and sync markers."""
    sk = humanoid_skeleton()
    n = int(round(period * fps))
    t = np.arange(n) / fps
    ph = t / period
    # Piecewise-linear warp so the right heel strike lands at ``right_down``.
    ph_r = np.interp(ph, [0.0, right_down, 1.0], [0.0, 0.5, 1.0])
    left = -amp * np.cos(2 * np.pi * ph_r)
    right = amp * np.cos(2 * np.pi * ph_r)
    knee_l = 1.2 * amp * np.maximum(0.0, -np.sin(2 * np.pi * ph_r))
    knee_r = 1.2 * amp * np.maximum(0.0, np.sin(2 * np.pi * ph_r))
    rot = quat.identity(n, sk.num_joints)
    rot[:, sk.index("l_upper_leg")] = quat.from_axis_angle(_X, left - crouch)
    rot[:, sk.index("r_upper_leg")] = quat.from_axis_angle(_X, right - crouch)
    rot[:, sk.index("l_lower_leg")] = quat.from_axis_angle(_X, knee_l + 2 * crouch)
    rot[:, sk.index("r_lower_leg")] = quat.from_axis_angle(_X, knee_r + 2 * crouch)
    rot[:, sk.index("l_foot")] = quat.from_axis_angle(_X, -crouch + 0 * t)
    rot[:, sk.index("r_foot")] = quat.from_axis_angle(_X, -crouch + 0 * t)
    rot[:, sk.index("chest")] = quat.from_axis_angle(_X, 0.03 * np.sin(2 * np.pi * ph))
    hip_y = 0.95 - LEG * (1 - np.cos(crouch)) - 0.02 * amp * np.cos(4 * np.pi * ph_r)
    root = np.zeros((n, 3))
    root[:, 1] = hip_y
    v = 4 * LEG * np.sin(amp) / period if speed is None else speed
    travel = np.zeros((n, 3))
    travel[:, 2] = v * t
    return Clip(
        name,
        sk,
        fps,
        root,
        rot,
        loop=True,
        root_motion=RootMotion(travel, np.zeros(n)),
        markers={"left_down": 0.0, "right_down": right_down},
    )


def synthetic_clips() -> dict[str, Clip]:
    """The five locomotion clips of Fig. 6.3, made up procedurally."""
    return {
        "idle": gait_clip("idle", 2.0, 0.0),
        "walk": gait_clip("walk", 1.1, 0.35),
        "run": gait_clip("run", 0.72, 0.6, right_down=0.46),
        "crouch_idle": gait_clip("crouch_idle", 2.0, 0.0, crouch=0.6),
        "crouch_walk": gait_clip("crouch_walk", 1.3, 0.3, crouch=0.6),
    }


@pytest.fixture(scope="session")
def clips() -> dict[str, Clip]:
    """Synthetic locomotion clips keyed like ``engine.clips.default_clips()``."""
    return synthetic_clips()
