"""The IK stage's crowd pass (:mod:`engine.ik.crowd`) against the general path it stands in for.

A crowd of 24 puppets is stepped through the ``ik`` stage while its poses and contact votes
change as the animation stage would write them (through the columns), and while members
leave and rejoin (a jump), have a lock field replaced, get hands on a sphere or lose their
contacts. With the crowd pass and with it switched off (every step on the general path that
:func:`~engine.ik.grounding.ground_feet_batch` serves) every pose, lock state, pelvis shift
and state hash must be equal bit for bit; against the pure-numpy path (numba off) to 1e-9.
Broken once by skipping the foot locks in ``_ground_kernel.ground_crowd``: the rotations
then differ from the general path's at the first served step. A replaced pose field (step 9)
and a lock column relinked by another batch's read (step 13) must be taken in as well. A
member's offsets replaced (step 7) or its lock retuned (step 4) must make the plan be checked
again although nothing else changed: broken once by leaving the puppets' fields out of the
plan's assignment marks (step 7 then differs), once by leaving the locks' tuning out (step 4).
Puppets of one hierarchy with bones and toe tips of their own (the snowman game's snowmen) are
one crowd, bit for bit the one-puppet path each took before: broken once by handing the kernel
the first member's tips for all (the toes' lock state differs at the first served step).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import engine.ik.system as system
from engine import jit, quat
from engine.app import App
from engine.columns import columns
from engine.components import LocalPose, Puppet
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton
from engine.ik import IKGround, IKRequest, PlaneGround, install_ik
from engine.ik.foot_lock import FootLock
from engine.skeleton import Skeleton

N = 24
STEPS = 14


def _own_rig(sk: Skeleton, scale: float) -> Skeleton:
    """``sk``'s hierarchy with every bone and tip ``scale`` times as long (a snowman's fitted rig)."""
    return Skeleton(sk.names, sk.parents, sk.offsets * scale, sk.tips * scale, sk.radii)


def _run(
    mode: str, ground: Any, monkeypatch: pytest.MonkeyPatch, n: int = N, own_rigs: bool = False
) -> tuple[list[Any], list[int]]:
    """Step ``n`` puppets; ``mode``: ``crowd`` (the pass), ``general`` (pass off), ``numpy`` (numba off).
    With ``own_rigs`` every odd puppet has a skeleton of its own, bones and tips scaled (0.55 to 0.95).
    Returns each step's state and the steps the crowd pass served all the plain puppets in one plan."""
    served: list[int] = []
    original = system.ground_crowd

    def counted(*args: Any) -> Any:
        kept = original(*args) if mode == "crowd" else None
        if kept is not None and len(args[0].rows) + len(args[0].outsiders) == sum(r.grounding for r in reqs):
            served.append(len(out))
        return kept

    monkeypatch.setattr(system, "ground_crowd", counted)
    rng = np.random.default_rng(4)
    app = App(seed=1, plugins=[install_ik])
    app.world.insert_resource(IKGround(ground))
    sk = humanoid_skeleton()
    ents = []
    for i in range(n):
        offsets = sk.offsets * (1.0 + 0.1 * (i % 3)) if i % 4 == 0 else None
        pose = LocalPose(np.array([rng.uniform(-3, 3), 0.95, rng.uniform(-3, 3)]), quat.identity(17))
        rig = _own_rig(sk, 0.55 + 0.4 * i / n) if own_rigs and i % 2 else sk
        ents.append(app.world.spawn(Puppet(rig, offsets), pose, IKRequest(grounding=True)))
    world = app.world
    reqs = [world.get(e, IKRequest) for e in ents]
    puppets = [world.get(e, Puppet) for e in ents]
    poses = [world.get(e, LocalPose) for e in ents]
    out: list[Any] = []
    with jit.use(mode != "numpy"):
        for step in range(STEPS):
            cols = columns(world)
            roots = np.array([p.root for p in poses]) + rng.normal(0, 0.01, (n, 3))
            rots = quat.normalize(quat.identity(n, 17) + rng.normal(0, 0.08, (n, 17, 4)))
            cols.get(LocalPose, "root", 17).write(poses, roots)
            cols.get(LocalPose, "rotations", 17).write(poses, rots)
            contacts = rng.uniform(0, 1, (n, 2))
            locks = [r.foot_lock for r in reqs]
            for lock, settle in zip(locks, rng.uniform(0, 1, n) < 0.3, strict=True):
                lock.settle = bool(settle)
            cols.get(FootLock, "contacts", 2).write(locks, contacts)
            if n < 10:  # one puppet (the snowman game's): no events
                pass
            elif step == 3:
                reqs[5].grounding = False  # a jump: the crowd goes on without it
            elif step == 4:  # a member's lock retuned: it leaves the crowd's one tuning
                reqs[3].foot_lock.max_stretch, reqs[3].foot_lock.release_time = 0.0, 0.02
            elif step == 6:
                reqs[5].grounding = True
            elif step == 7:  # a member's bone lengths replaced: the plan's stacked offsets are out of date
                puppets[6].offsets = sk.offsets * 1.05
            elif step == 8:
                reqs[7].foot_lock.yaw = np.array([0.3, -0.2])  # other code replaced a lock field
            elif step == 9:  # other code replaced a member's pose field after the animation wrote it
                poses[4].rotations = quat.normalize(poses[4].rotations + 0.05)
            elif step == 10:
                reqs[9].sphere_centre, reqs[9].sphere_radius = np.array([0.0, 0.85, 0.45]), 0.2
            elif step == 11:
                reqs[9].sphere_centre = None
                reqs[2].foot_lock.contacts = None
            elif step == 13:  # another batch's read relinks a lock column: members past the tenth keep old views
                cols.get(FootLock, "points", 2).read([*locks[:10], FootLock(points=np.ones((2, 3)))])
            app.step()
            out.append(
                (
                    np.array([p.root for p in poses]),
                    np.array([p.rotations for p in poses]),
                    np.array([r.pelvis_shift for r in reqs]),
                    np.array([r.foot_lock.points for r in reqs]),
                    np.array([r.foot_lock.weights for r in reqs]),
                    np.array([r.foot_lock.planted for r in reqs]),
                    state_hash(world),
                )
            )
    return out, served


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there is no crowd pass")
@pytest.mark.parametrize(
    "ground",
    [PlaneGround(normal=(0.1, 1.0, -0.2)), PlaneGround(), None],
    ids=["slope", "flat", "heightfield"],
)
def test_the_crowd_pass_is_the_general_path_bit_for_bit(ground: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    if ground is None:
        from engine.ik.grounding import HeightfieldGround

        ground = HeightfieldGround(np.random.default_rng(9).uniform(-0.1, 0.1, (16, 16)), 0.5, -4, -4)
    crowd, served = _run("crowd", ground, monkeypatch)
    general, none = _run("general", ground, monkeypatch)
    numpy_path, _ = _run("numpy", ground, monkeypatch)
    # Served but where it must stand aside: at the start (no lock state in columns yet), while
    # one puppet is in the air (3-5: the crowd is not the animation's whole batch), when the
    # jumper rejoins with its reset lock (6), a lock field was replaced (8), a member has hands
    # on a sphere (10) or no contact votes (11 on). The step after each, it serves again. Once
    # a member left for its own lock tuning (4), the lock column relinked by another batch's read
    # at 13 holds the members at rows other than the rest of their lock state: step 13 goes to the
    # general path (as it did before plans were kept on assignment marks).
    assert none == [] and served == list(range(1, STEPS - 1))
    for a, b, c in zip(crowd, general, numpy_path, strict=True):
        for x, y in zip(a[:-1], b[:-1], strict=True):
            np.testing.assert_array_equal(x, y)
        assert a[-1] == b[-1]
        for x, z in zip(a[:-2], c[:-2], strict=True):
            np.testing.assert_allclose(x, z, atol=1e-9)
        np.testing.assert_array_equal(a[-2], c[-2])


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there is no crowd pass")
@pytest.mark.parametrize("n", [1, 12])
def test_a_small_crowd_is_served_as_the_one_puppet_path_did_bit_for_bit(
    n: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Fewer than :data:`~engine.ik.system.BATCH` puppets (one: the snowman game's) took the one-puppet
    float path (:func:`~engine.ik.grounding.ground_feet`) and now the crowd pass: every pose, lock state,
    pelvis shift and state hash is the same bit for bit, through the same jump, replaced lock field,
    sphere and lost contacts (12 puppets). Broken once by skipping ``_lock_puppet`` in the kernel."""
    assert n < system.BATCH
    ground = PlaneGround(normal=(0.1, 1.0, -0.2))
    crowd, served = _run("crowd", ground, monkeypatch, n)
    one_by_one, none = _run("general", ground, monkeypatch, n)
    assert none == [] and served == list(range(1, STEPS if n < 10 else STEPS - 1))  # 13: as in the test above
    for a, b in zip(crowd, one_by_one, strict=True):
        for x, y in zip(a[:-1], b[:-1], strict=True):
            np.testing.assert_array_equal(x, y)
        assert a[-1] == b[-1]


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there is no crowd pass")
@pytest.mark.parametrize("n", [7, 24])
def test_puppets_with_rigs_of_their_own_are_one_crowd_bit_for_bit(n: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every odd puppet has its own skeleton of the humanoid hierarchy, bones and toe tips scaled (7: the snowman
    bench's puppet and six snowmen). They took the one-puppet path one by one; now the crowd pass serves them all
    in one plan with the rest, and every pose, lock state, pelvis shift and state hash is the same bit for bit."""
    ground = PlaneGround(normal=(0.1, 1.0, -0.2))
    crowd, served = _run("crowd", ground, monkeypatch, n, own_rigs=True)
    one_by_one, none = _run("general", ground, monkeypatch, n, own_rigs=True)
    # As in the tests above: the first step has no lock state in columns yet; with 24, step 13's relinked column.
    assert none == [] and served == list(range(1, STEPS if n < 10 else STEPS - 1))
    for a, b in zip(crowd, one_by_one, strict=True):
        for x, y in zip(a[:-1], b[:-1], strict=True):
            np.testing.assert_array_equal(x, y)
        assert a[-1] == b[-1]
