"""The crowd-scale, start-up and peer benches measure what they say (small sizes, no timing asserted)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from puppetphone.bench.crowd_scale import AFTER, fall_run
from puppetphone.bench.startup import child_cpu_s


def test_the_fall_run_times_the_fall_and_raw_mujoco_on_the_same_model() -> None:
    total, physics, raw = fall_run(puppets=6, fallers=2)
    assert total.shape == physics.shape == (AFTER + 1,)
    assert (physics <= total + 1e-9).all() and (physics > 0).all()
    assert raw > 0  # something was simulated: the two fallers


def test_child_cpu_counts_the_child_and_reports_its_failure() -> None:
    assert child_cpu_s([sys.executable, "-c", "sum(range(3_000_000))"]) > 0.01
    with pytest.raises(RuntimeError, match="failed"):
        child_cpu_s([sys.executable, "-c", "raise SystemExit(3)"])


def test_the_pinocchio_peer_computes_our_fk() -> None:
    pin = pytest.importorskip("pinocchio", reason="the [peers] extra (pinocchio) is not installed")
    from puppetphone.bench.peers import _pin_configs, pinocchio_model

    sk = humanoid_skeleton()
    rng = np.random.default_rng(3)
    rots = quat.exp(rng.normal(scale=0.4, size=(2, sk.num_joints, 3)))
    roots = rng.normal(size=(2, 3))
    model = pinocchio_model(sk)
    data = model.createData()
    ours, _ = forward_kinematics(sk, roots, rots)
    for i, q in enumerate(_pin_configs(rots, roots)):
        pin.forwardKinematics(model, data, q)
        theirs = np.array([data.oMi[j + 1].translation for j in range(sk.num_joints)])
        np.testing.assert_allclose(theirs, ours[i], atol=1e-9)
