"""The compiled blend playback (:mod:`engine.blend._kernel`) against the numpy blend-space methods.

A crowd of walkers (the sandbox: puppets at different paces, some crouching, the built-in
humanoid set with contact tracks) steps on the numpy path and on the compiled one from the
same seed; after every whole step (animation, grounding and FK all switch path together) their local poses, transforms, phases
and foot-lock votes must agree to 1e-9 (same formulas; only the order of sums differs).
Broken once by dropping the hemisphere flip in ``_frame_rotations`` (poses differ by a
whole joint turn).
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend import _kernel
from engine.blend.locomotion import LocomotionPlayer
from engine.blend.puppet import puppet_locomotion
from engine.components import LocalPose, Transform
from engine.ik.system import IKRequest

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: only the numpy path exists")


def _crowd(compiled: bool, steps: int):  # type: ignore[no-untyped-def]
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("sandbox", 3, InputHub(), {"puppets": 24})
    out = []
    with jit.use(compiled):
        for _ in range(steps):
            app.step()
            rows = sorted(app.world.query(LocalPose, Transform, LocomotionPlayer, IKRequest), key=lambda r: r[0])
            out.append(
                [
                    (
                        lp.root.copy(),
                        lp.rotations.copy(),
                        tr.position.copy(),
                        tr.rotation.copy(),
                        pl.phase,
                        None if ik.foot_lock.contacts is None else np.array(ik.foot_lock.contacts),
                    )
                    for _e, lp, tr, pl, ik in rows
                ]
            )
    return out


@pytest.mark.slow  # 24 puppets stepped 40 times on each path
def test_the_compiled_animation_agrees_with_numpy_step_by_step() -> None:
    a, b = _crowd(False, 40), _crowd(True, 40)
    for step_a, step_b in zip(a, b, strict=True):
        assert len(step_a) == len(step_b) > 10
        for ra, rb in zip(step_a, step_b, strict=True):
            for x, y in zip(ra, rb, strict=True):
                if x is None or y is None:
                    assert x is None and y is None
                else:
                    np.testing.assert_allclose(y, x, atol=1e-9)


def test_the_kernel_pose_is_the_blend_space_sample() -> None:
    """One call of :func:`_kernel.play` against ``weights``/``advance``/``sample`` on random blends."""
    from engine.blend.locomotion import BlendLibrary, _play_compiled
    from engine.blend.measure import contact_votes

    loco = puppet_locomotion()
    library = BlendLibrary()
    library.add("humanoid", loco)
    tracks = library.tracks("humanoid")
    pk = _kernel.packed(loco.space, tracks)
    assert pk is not None
    rng = np.random.default_rng(2)
    points = rng.uniform(-0.1, 1.1, (50, loco.space.dims))
    phase = rng.uniform(0, 3, 50)
    rates = rng.uniform(0.5, 2, 50)
    root, rots, new_phase, travel, turn, votes = _play_compiled(pk, points, phase, rates, 1 / 60)
    w = loco.space.weights(points)
    ref_phase, ref_travel, ref_turn = loco.space.advance(phase, w, 1 / 60, rates)
    pose = loco.space.sample(w, ref_phase)
    np.testing.assert_allclose(new_phase, ref_phase, atol=1e-12)
    np.testing.assert_allclose(travel, ref_travel, atol=1e-12)
    np.testing.assert_allclose(turn, ref_turn, atol=1e-12)
    np.testing.assert_allclose(root, pose.root, atol=1e-12)
    np.testing.assert_allclose(rots, pose.rotations, atol=1e-12)
    assert votes is not None
    np.testing.assert_allclose(votes, contact_votes(loco.space, w, ref_phase, tracks), atol=1e-12)


@pytest.mark.parametrize("gradients", [True, False])
def test_the_compiled_lookup_agrees_with_numpy(gradients: bool) -> None:
    """IDW over the k nearest probes on both paths: random requests, exact probe hits, one request and a batch.
    Broken once by leaving the probe slopes out of the compiled sum (answers move by 1e-2)."""
    from engine.blend.lookup import LookupTable

    table = puppet_locomotion().table
    if not gradients:
        table = LookupTable(table.probes, table.values, table.properties, table.grid_shape, gradients=False)
    rng = np.random.default_rng(8)
    lo, hi = table.values.min(axis=0), table.values.max(axis=0)
    u = lo + rng.random((4, 60, 2)) * (hi - lo)
    u[0, :6] = table.values[:6]
    for request in (u, u[1, 3]):
        with jit.use(True):
            a = table.query(request)
        with jit.use(False):
            b = table.query(request)
        assert a.shape == b.shape
        np.testing.assert_allclose(a, b, atol=1e-12)
    with jit.use(True):
        np.testing.assert_allclose(table.query(table.values[:6]), np.clip(table.probes[:6], 0, 1), atol=1e-12)
