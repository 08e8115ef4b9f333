"""The ``ik`` stage: requests on puppets are served in the app, deterministically, and exports are curated."""

from __future__ import annotations

import numpy as np

import engine.ik as ik
from engine import quat
from engine.app import App
from engine.components import LocalPose, Puppet
from engine.fk import forward_kinematics
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton
from engine.ik import Effector, IKGround, IKRequest, Pin, PlaneGround, install_ik


def _app(request: IKRequest, ground=None) -> tuple[App, int]:
    app = App(seed=1, plugins=[install_ik])
    if ground is not None:
        app.world.insert_resource(IKGround(ground))
    sk = humanoid_skeleton()
    e = app.world.spawn(Puppet(sk), LocalPose(np.array([0.0, 0.95, 0.0]), quat.identity(17)), request)
    return app, e


def test_grounding_and_hands_run_in_the_ik_stage():
    slope = PlaneGround(normal=(0.0, 1.0, -0.2))
    req = IKRequest(grounding=True, sphere_centre=np.array([0.0, 0.85, 0.45]), sphere_radius=0.2)
    app, e = _app(req, slope)
    assert ik.ik_system in app.systems("ik")
    app.step()
    local = app.world.get(e, LocalPose)
    sk = humanoid_skeleton()
    wp, wr = forward_kinematics(sk, local.root, local.rotations)
    for foot in ("l_foot", "r_foot"):
        f = sk.index(foot)
        toe = wp[f] + quat.rotate(wr[f], [0.0, -0.05, 0.15])
        assert abs(toe[1] - slope(toe[0], toe[2])[0]) < 0.02
    h = sk.index("l_hand")
    palm = wp[h] + quat.rotate(wr[h], [-0.02, -0.045, 0.0])
    assert abs(np.linalg.norm(palm - [0.0, 0.85, 0.45]) - 0.2) < 3e-3


def test_effector_requests_report_reach_and_hash_deterministically():
    def run(target):
        req = IKRequest(effectors=(Effector("r_hand", target),), pins=(Pin("l_foot"), Pin("r_foot")))
        app, e = _app(req)
        app.run_steps(2)
        return app, e

    a, ea = run((-0.3, 1.3, 0.3))
    b, _ = run((-0.3, 1.3, 0.3))
    assert a.world.get(ea, IKRequest).reached
    assert state_hash(a.world) == state_hash(b.world)
    far, ef = run((-3.0, 1.3, 0.3))
    assert not far.world.get(ef, IKRequest).reached
    assert far.world.get(ef, LocalPose).rotations.shape == (17, 4)


def test_public_surface_is_curated():
    for name in ik.__all__:
        assert hasattr(ik, name), name
    assert {"two_bone_ik", "solve_ik", "ground_feet", "hands_on_sphere", "install_ik", "IKRequest"} <= set(ik.__all__)


def test_a_crowd_is_grounded_in_one_batch_with_the_same_result(monkeypatch):
    import engine.ik.system as system

    rng = np.random.default_rng(2)
    n = system.BATCH + 2
    roots = np.column_stack([rng.uniform(-3, 3, n), np.full(n, 0.95), rng.uniform(-3, 3, n)])
    rots = quat.normalize(quat.identity(n, 17) + rng.normal(0, 0.05, (n, 17, 4)))

    def run(batch_from: int):
        app = App(seed=1, plugins=[install_ik])
        app.world.insert_resource(system.IKRigCache(batch_from=batch_from))
        app.world.insert_resource(IKGround(PlaneGround(normal=(0.1, 1.0, -0.2))))
        ents = []
        for i in range(n):  # separately built skeletons, alike: one batch
            req = IKRequest(grounding=True)
            if i == 0:
                req.sphere_centre, req.sphere_radius = roots[0] + [0.0, -0.1, 0.45], 0.2
            ents.append(app.world.spawn(Puppet(humanoid_skeleton()), LocalPose(roots[i].copy(), rots[i].copy()), req))
        app.step()
        return [app.world.get(e, LocalPose) for e in ents]

    calls = []
    real = system.ground_feet_batch
    monkeypatch.setattr(system, "ground_feet_batch", lambda *a, **k: calls.append(1) or real(*a, **k))
    batched = run(system.BATCH)
    assert calls == [1]
    single = run(10**9)
    assert calls == [1]
    for a, b in zip(batched, single, strict=True):
        np.testing.assert_allclose(a.root, b.root, atol=1e-12)
        np.testing.assert_allclose(a.rotations, b.rotations, atol=1e-12)
