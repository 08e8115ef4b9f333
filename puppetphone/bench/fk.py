"""Batched FK for 100 puppets against a per-joint Python loop (a straw man: the peer that counts,
pinocchio, is in :mod:`puppetphone.bench.peers`), and the compiled kernel against its numpy twin."""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import ArrayLike

from engine import jit, quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.skeleton import Skeleton
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run", "per_joint_fk"]


def per_joint_fk(skeleton: Skeleton, root: ArrayLike, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference FK written the obvious way: one puppet, one joint at a time."""
    n = skeleton.num_joints
    pos = np.zeros((n, 3))
    rot = np.zeros((n, 4))
    pos[0], rot[0] = root, rotations[0]
    for j in range(1, n):
        p = skeleton.parents[j]
        pos[j] = pos[p] + quat.rotate(rot[p], skeleton.offsets[j])
        rot[j] = quat.mul(rot[p], rotations[j])
    return pos, rot


def run() -> list[Figure]:
    """FK time for 100 puppets, batched vs looped."""
    sk = humanoid_skeleton()
    rng = np.random.default_rng(0)
    puppets = 100
    rots = quat.exp(rng.normal(scale=0.3, size=(puppets, sk.num_joints, 3)))
    roots = rng.normal(size=(puppets, 3))
    clock = time.thread_time  # CPU time: the neighbours' load on a shared machine does not count
    batched = median_time(lambda: forward_kinematics(sk, roots, rots), clock=clock)
    looped = median_time(lambda: [per_joint_fk(sk, roots[i], rots[i]) for i in range(puppets)], repeats=5, clock=clock)
    one = median_time(lambda: forward_kinematics(sk, roots[0], rots[0]), clock=clock)
    figures = [
        Figure("fk", "fk_100_puppets_ms", batched * 1e3, "ms", "per-joint python loop (straw man)", looped * 1e3),
        Figure("fk", "fk_1_puppet_us", one * 1e6, "us", None, None),
    ]
    if jit.enabled():
        with jit.use(False):
            numpy_path = median_time(lambda: forward_kinematics(sk, roots, rots), clock=clock)
        figures.append(
            Figure("fk", "fk_100_puppets_ms_compiled", batched * 1e3, "ms", "numpy levels, same run", numpy_path * 1e3)
        )
    return figures
