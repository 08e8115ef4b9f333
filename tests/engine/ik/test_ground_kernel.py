"""The compiled grounding (:mod:`engine.ik._ground_kernel`) against its numpy twin.

Both paths of :func:`~engine.ik.grounding.ground_feet_batch` run on the same crowd (random
leg poses, per-puppet bone lengths and weights, bumpy ground, foot locks advanced over
several steps with changing contacts) and must agree to 1e-9 (m and quaternion units):
same formulas, only numpy's reductions may round differently. Broken once by dropping the
reach term of the pelvis shift in ``legs_solve`` (the roots then differ by centimetres).
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit, quat
from engine.humanoid import humanoid_skeleton
from engine.ik.foot_lock import FootLock
from engine.ik.grounding import HeightfieldGround, PlaneGround, ground_feet_batch

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: only the numpy path exists")


def _crowd(seed: int, n: int):  # type: ignore[no-untyped-def]
    sk = humanoid_skeleton()
    rng = np.random.default_rng(seed)
    rots = quat.normalize(np.tile(quat.identity(sk.num_joints), (n, 1, 1)) + rng.normal(0, 0.1, (n, sk.num_joints, 4)))
    roots = np.column_stack([rng.uniform(-2, 2, n), np.full(n, 0.95), rng.uniform(-2, 2, n)])
    offsets = sk.offsets * rng.uniform(0.8, 1.2, (n, 1, 1))
    return sk, rng, rots, roots, offsets


@pytest.mark.parametrize(
    "ground",
    [
        HeightfieldGround(np.random.default_rng(9).uniform(-0.1, 0.1, (12, 12)), 0.5, -3, -3),
        PlaneGround(normal=(0.1, 1.0, -0.05)),
    ],
)
def test_compiled_grounding_agrees_with_numpy_over_steps_with_locks(ground) -> None:  # type: ignore[no-untyped-def]
    sk, rng, rots, roots, offsets = _crowd(3, 25)
    weights = rng.uniform(0, 1, len(roots))
    weights[:5] = 1.0
    runs = {}
    for compiled in (False, True):
        locks = [FootLock() for _ in roots]
        out = []
        walk = np.random.default_rng(11)
        for _step in range(12):
            contacts = walk.uniform(0, 1, (len(roots), 2))
            for lock, c, settle in zip(locks, contacts, walk.uniform(0, 1, len(roots)) < 0.3, strict=True):
                lock.contacts, lock.settle = c, bool(settle)
            moved = roots + walk.normal(0, 0.01, roots.shape)
            r, q = moved.copy(), rots.copy()
            with jit.use(compiled):
                shift = ground_feet_batch(sk, r, q, ground, offsets=offsets, weight=weights, locks=locks, dt=1 / 60)
            out.append((shift, r, q, [(lk.points.copy(), lk.weights.copy(), lk.planted.copy()) for lk in locks]))
        runs[compiled] = out
    for (s0, r0, q0, l0), (s1, r1, q1, l1) in zip(runs[False], runs[True], strict=True):
        np.testing.assert_allclose(s1, s0, atol=1e-9)
        np.testing.assert_allclose(r1, r0, atol=1e-9)
        np.testing.assert_allclose(q1, q0, atol=1e-9)
        for (p0, w0, k0), (p1, w1, k1) in zip(l0, l1, strict=True):
            np.testing.assert_allclose(p1, p0, atol=1e-9)
            np.testing.assert_allclose(w1, w0, atol=1e-9)
            np.testing.assert_array_equal(k1, k0)


def test_compiled_grounding_plants_the_soles_and_rejects_bad_ground() -> None:
    """Not only equal to numpy: the soles of fully weighted puppets end on the plane (heights ≈ 0 there)."""
    from engine.fk import forward_kinematics

    sk, _rng, rots, roots, offsets = _crowd(5, 20)
    rots[:, [sk.index("l_upper_leg"), sk.index("r_upper_leg")]] = quat.identity(20, 2)
    r, q = roots.copy(), rots.copy()
    with jit.use(True):
        ground_feet_batch(sk, r, q, PlaneGround(point=(0.0, 0.1, 0.0)), offsets=offsets)
    pos, wrot = forward_kinematics(sk, r, q, offsets)
    for foot in ("l_foot", "r_foot"):
        f = sk.index(foot)
        sole = pos[:, f] + quat.rotate(wrot[:, f], np.array([0.0, -0.05, 0.075]))
        assert np.all(sole[:, 1] >= 0.1 - 1e-6)
    with jit.use(True), pytest.raises(ValueError, match="non-finite"):
        ground_feet_batch(
            sk, roots.copy(), rots.copy(), lambda x, z: (np.full_like(x, np.nan), np.zeros(x.shape + (3,)))
        )


def test_compiled_grounding_writes_back_into_strided_inputs() -> None:
    """Views (every other puppet of a bigger array) are grounded in place as the numpy path does them."""
    sk, _rng, rots, roots, offsets = _crowd(6, 20)
    ground = PlaneGround(point=(0.0, 0.05, 0.0))
    results = []
    for compiled in (False, True):
        r, q = roots.copy(), rots.copy()
        with jit.use(compiled):
            ground_feet_batch(sk, r[::2], q[::2], ground, offsets=offsets[::2])
        results.append((r, q))
    np.testing.assert_allclose(results[1][0], results[0][0], atol=1e-9)
    np.testing.assert_allclose(results[1][1], results[0][1], atol=1e-9)
    assert not np.allclose(results[1][0][::2], roots[::2])  # something was written
