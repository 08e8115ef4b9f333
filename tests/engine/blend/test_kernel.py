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
from engine.blend.locomotion import BlendLibrary, LocomotionPlayer, LocomotionSet, _Out, _play_compiled
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


def _play(
    pk: _kernel.Packed,
    points: np.ndarray,
    target: np.ndarray,
    ease: bool,
    phase: np.ndarray,
    rates: np.ndarray,
    scales: np.ndarray,
    feasible: np.ndarray,
) -> _Out:

    out = _Out(len(points), points.shape[1], len(pk.points), pk.rotations.shape[1], pk.contacts.shape[1])
    _play_compiled(pk, points, target, 0.3, ease, phase, rates, scales, feasible, 1 / 60, out)
    return out


def _packed() -> tuple[LocomotionSet, _kernel.Packed, list[np.ndarray]]:
    loco = puppet_locomotion()
    library = BlendLibrary()
    library.add("humanoid", loco)
    tracks = library.tracks("humanoid")
    assert tracks is not None
    pk = _kernel.packed(loco.space, tracks)
    assert pk is not None
    return loco, pk, tracks


def test_the_kernel_pose_is_the_blend_space_sample() -> None:
    """One call of :func:`_kernel.play` against ``weights``/``advance``/``sample`` on random blends."""
    from engine.blend.measure import contact_votes

    loco, pk, tracks = _packed()
    space = loco.space
    rng = np.random.default_rng(2)
    points = rng.uniform(-0.1, 1.1, (50, space.dims))
    phase = rng.uniform(0, 3, 50)
    rates = rng.uniform(0.5, 2, 50)
    ones = np.ones(50)
    out = _play(pk, points, points, False, phase, rates, ones, points)
    w = space.weights(points)
    ref_phase, ref_travel, ref_turn = space.advance(phase, w, 1 / 60, rates)
    pose = space.sample(w, ref_phase)
    np.testing.assert_allclose(out.phase, ref_phase, atol=1e-12)
    np.testing.assert_allclose(out.travel, ref_travel, atol=1e-12)
    np.testing.assert_allclose(out.turn, ref_turn, atol=1e-12)
    np.testing.assert_allclose(out.roots, pose.root, atol=1e-12)
    np.testing.assert_allclose(out.rotations, pose.rotations, atol=1e-12)
    np.testing.assert_allclose(out.votes, contact_votes(space, w, ref_phase, tracks), atol=1e-12)


def test_the_kernel_eases_scales_and_wraps_as_the_numpy_path_bit_for_bit() -> None:
    """The parts of the animation stage folded into :func:`_kernel.play` (the blend point's easing in place,
    the feasible request, root and travel times the puppet's scale, the phase wrapped to [0, 1)) against
    the numpy expressions they replaced, on random crowds: equal to the bit. Broken once by easing as
    ``(1 − α)·eased + α·target`` (the same point, other last bits): it failed."""
    _, pk, _ = _packed()
    rng = np.random.default_rng(9)
    n = 200
    eased = rng.uniform(-0.1, 1.1, (n, 2))
    target = rng.uniform(0.0, 1.0, (n, 2))
    phase = rng.uniform(0, 40, n)
    rates = rng.uniform(0.3, 3, n)
    scales = rng.uniform(0.3, 2.5, n)
    feasible = rng.uniform(0.0, 3.0, (n, 2))
    moved = eased.copy()
    big = _play(pk, moved, target, True, phase, rates, scales, feasible)
    assert np.array_equal(moved, eased + 0.3 * (target - eased))
    unit = _play(pk, moved.copy(), target, False, phase, rates, np.ones(n), feasible)
    assert np.array_equal(big.feasible, feasible * scales[:, None])
    assert np.array_equal(big.roots, unit.roots * scales[:, None])
    assert np.array_equal(big.travel, unit.travel * scales[:, None])
    assert np.array_equal(big.wrapped, big.phase % 1.0)
    for name in ("phase", "turn", "rotations", "votes", "weights"):
        assert np.array_equal(getattr(big, name), getattr(unit, name))


def test_one_interpolation_is_numbas_np_interp_bit_for_bit() -> None:
    """:func:`_kernel.interp` (the clip-time lookup without allocations) against ``np.interp`` compiled by
    numba, which the kernel called before: random knots (3 and 9, strictly increasing or with repeats),
    points inside, outside, on the knots and NaN. Broken once by taking the knot at or *above* ``x``
    as the segment's start (``x > xp[mid]`` in the bisection): it failed on the points on knots."""
    import numba

    @numba.njit
    def reference(x: float, xp: np.ndarray, fp: np.ndarray) -> float:
        return np.interp(x, xp, fp)

    rng = np.random.default_rng(11)
    for size in (1, 2, 3, 9):
        for repeats in (False, True):
            for _ in range(30):
                xp = np.sort(rng.uniform(0, 1, size))
                if repeats and size > 2:
                    xp[1] = xp[2]
                fp = rng.uniform(-2, 2, size)
                xs = np.concatenate([rng.uniform(-0.2, 1.2, 40), xp, [np.nan, -np.inf, np.inf]])
                for x in xs:
                    a, b = _kernel.interp(float(x), xp, fp), reference(float(x), xp, fp)
                    assert a == b or (np.isnan(a) and np.isnan(b)), (x, xp, fp)


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


def _unit(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def test_a_slerp_on_a_measured_arc_is_the_numpy_slerp_bit_for_bit() -> None:
    """:func:`engine.jit.qarc` then :func:`engine.jit.qslerp_arc` (the crowd's slerp, its arc measured once per
    clip; :func:`engine.jit.qslerp` is the two in a row) against the numpy path's :func:`engine.quat.slerp` on
    random, nearly equal and opposite pairs. Broken once by taking the sine of the arc as ``sqrt(1 - d²)``
    (differs in the last bits)."""
    from engine import quat

    rng = np.random.default_rng(4)
    a = _unit(rng, 400)
    b = _unit(rng, 400)
    b[:50] = a[:50] + 1e-9 * rng.normal(size=(50, 4))
    b[50:100] = -a[50:100]
    for qa, qb, t in zip(a, b, rng.uniform(0, 1, 400), strict=True):
        ta, tb = tuple(qa.tolist()), tuple(qb.tolist())
        far, theta, s = jit.qarc(ta, tb)
        assert np.array_equal(jit.qslerp_arc(ta, far, theta, s, t), quat.slerp(qa, qb, t))
        assert jit.qslerp(ta, tb, t) == jit.qslerp_arc(ta, far, theta, s, t)


def test_placing_the_crowd_compiled_is_the_numpy_sequence_bit_for_bit() -> None:
    """:func:`_kernel.place` against its numpy twin ``locomotion._place`` (the ``engine.quat`` calls it
    replaced) on random headings, travels, turns and poses: the state hashes depend on every bit.
    Broken once by composing the new heading as ``turn_q · hq`` (the same rotation, other last bits)."""
    from engine.blend.locomotion import _place

    rng = np.random.default_rng(6)
    n = 64
    rotation = _unit(rng, n)
    positions = rng.normal(size=(n, 3))
    travel = rng.normal(size=(n, 3)) * 0.02
    turn = rng.normal(size=n) * 0.05
    roots = rng.normal(size=(n, 3))
    rots = _unit(rng, n * 17).reshape(n, 17, 4)
    rots_a = rots.copy()
    moved_a, headings_a, world_a = _place(rotation, positions, travel, turn, roots, rots_a)
    moved_b, rots_b = positions.copy(), rots.copy()
    headings_b, world_b = np.empty_like(rotation), np.empty_like(roots)
    _kernel.place(rotation, moved_b, travel, turn, roots, rots_b, headings_b, world_b)
    for x, y in ((moved_a, moved_b), (headings_a, headings_b), (world_a, world_b), (rots_a, rots_b)):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("longest", [_kernel.SERIES_UP_TO, 1.5])
def test_the_kernels_slerp_between_frames_is_the_numpy_slerp_within_its_tolerance(longest: float) -> None:
    """The kernel's slerp (:func:`_kernel._arc_point`: the sines by a series on short arcs, no division by
    ``sin θ``) against :func:`engine.quat.slerp` on arcs up to the series' bound and on longer ones (``math.sin``),
    nearly equal pairs included: every component within :data:`_kernel.SLERP_TOLERANCE`. Broken once by stopping
    the series at ``x⁵`` (off by 1.7e-9 near the bound): it failed."""
    from engine import quat

    rng = np.random.default_rng(7)
    a = _unit(rng, 600)
    axis = rng.normal(size=(600, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    theta = rng.uniform(0.0, longest, 600)
    theta[:40] = longest  # the bound itself, where the series is least exact
    theta[40:80] = 1e-9 * rng.uniform(size=40)  # nearly equal: linear weights
    turn = np.concatenate([np.cos(theta)[:, None], axis * np.sin(theta)[:, None]], axis=1)  # b = turn · a: arc theta
    b = quat.mul(turn, a)
    worst = 0.0
    for qa, qb, t in zip(a, b, rng.uniform(0, 1, 600), strict=True):
        ta, tb = tuple(qa.tolist()), tuple(qb.tolist())
        far, arc, s = jit.qarc(ta, tb)
        worst = max(
            worst, float(np.abs(np.array(_kernel._arc_point(ta, far, arc, s, t)) - quat.slerp(qa, qb, t)).max())
        )
    assert worst <= _kernel.SLERP_TOLERANCE
