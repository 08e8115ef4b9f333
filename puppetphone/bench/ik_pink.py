"""The ``pink`` + ``daqp`` side-by-side of the static IK figure (a ``[bench]`` extra).

pink (differential IK on pinocchio) solves one QP per Gauss-Newton step, like
:func:`engine.ik.solve_ik`. The chain is the bench's tentacle with each ball joint
written as three revolute joints X, Y, Z (pinocchio's spherical joint has no
position limits), limits ±1.5 rad, starting from the same pose (as intrinsic XYZ
angles). The tip is a position-only task; each pinned joint is a hard
position constraint (pink's ``constraints``), as our pins are within ε. Steps of
``dt = 1`` (full Gauss-Newton steps) repeat until the tip is within the same
0.1 mm tolerance, at most 60 steps like ours.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from engine import quat

__all__ = ["available", "pink_chain"]

TOLERANCE = 1e-4
MAX_STEPS = 60


def available() -> str | None:
    """``None`` when pink, pinocchio and daqp import, else why not."""
    try:
        import daqp  # noqa: F401
        import pink  # noqa: F401
        import pinocchio  # noqa: F401
    except ImportError as exc:  # the [bench] extra is optional
        return f"pink+daqp not installed ({exc.name}); pip install 'puppetphone[bench]'"
    return None


def _model(joints: int, link: float, tip: np.ndarray, limit: float) -> Any:  # a pinocchio Model (untyped)
    import pinocchio as pin

    model = pin.Model()
    parent = 0
    frames = []
    for j in range(joints):
        for k, jm in enumerate((pin.JointModelRX(), pin.JointModelRY(), pin.JointModelRZ())):
            offset = np.array([0.0, link if (j > 0 and k == 0) else 0.0, 0.0])
            parent = model.addJoint(parent, jm, pin.SE3(np.eye(3), offset), f"j{j}{'xyz'[k]}",
                                    np.array([100.0]), np.array([1e3]), np.array([-limit]), np.array([limit]))  # fmt: skip
        frames.append(model.addFrame(pin.Frame(f"f{j}", parent, pin.SE3.Identity(), pin.FrameType.OP_FRAME)))
    model.addFrame(pin.Frame("tip", parent, pin.SE3(np.eye(3), tip), pin.FrameType.OP_FRAME))
    return model


def pink_chain(
    joints: int,
    link: float,
    tip: np.ndarray,
    limit: float,
    pins: list[int],
    cases: list[tuple[np.ndarray, np.ndarray]],
    repeats: int = 1,
) -> tuple[float, float, float]:
    """``(median ms, median tip error mm, median worst pin drift mm)`` over ``cases``.

    Each case is timed ``repeats`` times and its fastest run kept (the same rule as ours); the
    model, limits, tasks and the pink ``Configuration`` (whose construction alone takes ~0.2 s
    here) are built outside the timing, as our rig is; a timed run starts at ``update(q0)``.
    """
    import pink
    import pinocchio as pin
    from pink.limits import ConfigurationLimit
    from pink.tasks import FrameTask

    model = _model(joints, link, tip, limit)
    data = model.createData()
    limits = [ConfigurationLimit(model)]  # built once, like our rig
    times: list[float] = []
    errors: list[float] = []
    drifts: list[float] = []
    for c0, target in cases:
        rot = quat.exp(c0.reshape(joints, 3))
        q0 = np.clip(quat.to_euler("xyz", rot).reshape(-1), -limit + 1e-6, limit - 1e-6)
        best = np.inf
        conf = pink.Configuration(model, data, q0.copy(), copy_data=False)
        task = FrameTask("tip", position_cost=1.0, orientation_cost=0.0)
        task.set_target(pin.SE3(np.eye(3), np.asarray(target, dtype=np.float64)))
        holds = []
        for j in pins:
            h = FrameTask(f"f{j}", position_cost=1.0, orientation_cost=0.0)
            h.set_target_from_configuration(conf)
            holds.append(h)
        for _ in range(repeats):
            t0 = time.process_time()
            conf.update(q0.copy())
            for _ in range(MAX_STEPS):
                err = np.linalg.norm(conf.get_transform_frame_to_world("tip").translation - target)
                if err < TOLERANCE:
                    break
                v = pink.solve_ik(conf, [task], 1.0, solver="daqp", damping=1e-6, limits=limits, constraints=holds,
                                  safety_break=False)  # fmt: skip
                conf.integrate_inplace(v, 1.0)
            best = min(best, time.process_time() - t0)
        errors.append(float(np.linalg.norm(conf.get_transform_frame_to_world("tip").translation - target)))
        drift = [np.linalg.norm(conf.get_transform_frame_to_world(f"f{j}").translation - h.transform_target_to_world.translation)
                 for j, h in zip(pins, holds, strict=True)]  # fmt: skip
        drifts.append(float(max(drift, default=0.0)))
        times.append(best)
    return float(np.median(times)) * 1e3, float(np.median(errors)) * 1e3, float(np.median(drifts)) * 1e3
