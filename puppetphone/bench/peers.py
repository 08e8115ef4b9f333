"""Our kernels beside the best PyPI peer for the same job, in thread CPU time, same run.

- ``peer_fk_100_puppets_us``: batched FK of 100 humanoids (17 joints) against pinocchio's
  ``forwardKinematics`` on the same skeleton (a free-flyer root and spherical joints), one call per
  puppet since pinocchio has no batch call. Skipped with a line when pinocchio (the ``[peers]``
  extra) is absent. Ours is the compiled kernel when numba is installed (:mod:`engine.jit`);
  ``peer_fk_100_puppets_us_numpy`` is its pure-numpy twin against the same peer.
- ``peer_lookup_1_us`` / ``peer_lookup_100_us``: the puppet's IDW lookup (k-d tree + probe slopes),
  one request and a crowd's 100, against SciPy's ``cKDTree`` query plus textbook IDW (weights
  ``1/dᵖ`` over the same k neighbours) — the peer does less (no slopes, no exact-hit guard), so
  this is generous to it. Ours weights the neighbours in one compiled loop when numba is installed.
- ``peer_animate_fk_100_puppets_ms``: the animation and FK stages of the 100-puppet sandbox crowd
  (:func:`puppetphone.bench.crowd.crowd_app`, the step's own systems) against 100 Panda3D characters
  of our skeleton playing and blending our walk and run clips, every joint forced to update each
  frame (:mod:`puppetphone.bench.anim_panda`, in its own process). Each side: the median of
  :data:`REPEATS` repeats, each the mean thread CPU time of 60 frames. Skipped with a line when
  Panda3D (the ``[peers]`` extra) is absent.

Every figure is the median of :data:`REPEATS` samples, each sample the mean of enough calls to
run :data:`SAMPLE_S` seconds of thread CPU time.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from engine import jit, quat
from engine.blend.puppet import puppet_locomotion
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.skeleton import Skeleton
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run", "cpu_time", "pinocchio_model", "animate_fk_ms", "panda_animate_fk_ms", "REPEATS"]

REPEATS = 5
SAMPLE_S = 0.05
_BENCH = "peers"


def cpu_time(fn: Callable[[], Any], repeats: int = REPEATS) -> float:
    """Median thread CPU seconds per call of ``fn``."""
    return median_time(fn, repeats=repeats, min_time=SAMPLE_S, clock=time.thread_time)


def pinocchio_model(sk: Skeleton) -> Any:
    """The skeleton as a pinocchio model: a free-flyer root, a spherical joint per other joint."""
    import pinocchio as pin

    model = pin.Model()
    ids = [model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), sk.names[0])]
    for j in range(1, sk.num_joints):
        place = pin.SE3(np.eye(3), np.asarray(sk.offsets[j], dtype=np.float64))
        ids.append(model.addJoint(ids[int(sk.parents[j])], pin.JointModelSpherical(), place, sk.names[j]))
    return model


def _pin_configs(rots: np.ndarray, roots: np.ndarray) -> list[np.ndarray]:
    """Our ``[P,J,4]`` (w, x, y, z) poses as pinocchio configurations (x, y, z, w quaternions)."""
    xyzw = np.concatenate([rots[..., 1:], rots[..., :1]], axis=-1)
    return [np.concatenate([roots[i], xyzw[i].ravel()]) for i in range(len(roots))]


def animate_fk_ms(frames: int = 60, repeats: int = REPEATS) -> float:
    """Our animation + FK stages for the 100-puppet crowd: median over ``repeats`` of the mean thread
    CPU milliseconds per step."""
    from puppetphone.bench.crowd import crowd_app, timed_steps

    app = crowd_app(100)
    samples = []
    for _ in range(repeats):
        _, per = timed_steps(app, frames)
        samples.append(float(np.mean(per["animation"] + per["fk"])) * 1e3)
    return float(np.median(samples))


def panda_animate_fk_ms() -> float | str:
    """Panda3D's 100 characters (:mod:`puppetphone.bench.anim_panda`, its own process): milliseconds
    per frame, or the line saying why the peer was skipped."""
    import importlib.util
    import subprocess

    if importlib.util.find_spec("panda3d") is None:
        return "peers: Panda3D not installed (pip install '.[peers]'): animate+FK peer skipped"
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone.bench.anim_panda"], capture_output=True, text=True, timeout=600, check=False
    )
    if done.returncode != 0 or not done.stdout.split():
        return f"peers: the Panda3D animation peer failed ({done.returncode}): {done.stderr.strip()[-200:]}"
    return float(done.stdout.split()[-1]) * 1e3


def run() -> list[Figure]:
    """The peer figures (see the module docstring)."""
    sk = humanoid_skeleton()
    rng = np.random.default_rng(0)
    puppets = 100
    rots = quat.exp(rng.normal(scale=0.3, size=(puppets, sk.num_joints, 3)))
    roots = rng.normal(size=(puppets, 3))
    ours = cpu_time(lambda: forward_kinematics(sk, roots, rots))
    figures = []
    try:
        import pinocchio as pin
    except ImportError:
        print("peers: pinocchio not installed (pip install '.[peers]'): FK peer skipped", file=sys.stderr)
    else:
        model = pinocchio_model(sk)
        data = model.createData()
        qs = _pin_configs(rots, roots)
        pos, _ = forward_kinematics(sk, roots, rots)
        pin.forwardKinematics(model, data, qs[0])
        theirs = np.array([data.oMi[j + 1].translation for j in range(sk.num_joints)])
        if not np.allclose(theirs, pos[0], atol=1e-9):  # the same answer, or the race means nothing
            raise RuntimeError("pinocchio's FK disagrees with ours on the same pose")

        def pin_fk() -> None:
            for q in qs:
                pin.forwardKinematics(model, data, q)

        theirs_us = cpu_time(pin_fk) * 1e6
        figures.append(
            Figure(_BENCH, "peer_fk_100_puppets_us", ours * 1e6, "us", "pinocchio forwardKinematics x100", theirs_us)
        )
        if jit.enabled():  # the pure-numpy twin of our kernel beside the same peer
            with jit.use(False):
                ours_numpy = cpu_time(lambda: forward_kinematics(sk, roots, rots))
            figures.append(
                Figure(
                    _BENCH,
                    "peer_fk_100_puppets_us_numpy",
                    ours_numpy * 1e6,
                    "us",
                    "pinocchio forwardKinematics x100",
                    theirs_us,
                )
            )
    table = puppet_locomotion().table
    tree = cKDTree(table._scaled_values)
    k, power = min(table.neighbours, len(table.probes)), table.power

    def textbook(u: np.ndarray) -> np.ndarray:
        x = (u - table.offset) / table.scale
        dist, idx = tree.query(x, k=k)
        w = 1.0 / np.maximum(dist, 1e-12) ** power
        return np.einsum("...k,...kn->...n", w, table.probes[idx]) / w.sum(axis=-1, keepdims=True)

    theirs_ms = panda_animate_fk_ms()
    if isinstance(theirs_ms, str):
        print(theirs_ms, file=sys.stderr)
    else:
        figures.append(
            Figure(
                _BENCH,
                "peer_animate_fk_100_puppets_ms",
                animate_fk_ms(),
                "ms",
                "Panda3D, 100 characters blending 2 clips, forced update",
                theirs_ms,
            )
        )
    lo, hi = table.values.min(axis=0), table.values.max(axis=0)
    many = lo + rng.random((puppets, len(lo))) * (hi - lo)
    one = many[0]
    for name, u in (("peer_lookup_1_us", one), ("peer_lookup_100_us", many)):
        figures.append(
            Figure(
                _BENCH,
                name,
                cpu_time(partial(table.query, u)) * 1e6,
                "us",
                "SciPy cKDTree query + textbook IDW",
                cpu_time(partial(textbook, u)) * 1e6,
            )
        )
    return figures
