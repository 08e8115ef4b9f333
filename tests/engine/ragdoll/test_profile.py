"""Profiles and the generated MuJoCo model: bodies from any skeleton, limits, contact filtering."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from engine.ragdoll import build_mjcf, default_profile
from engine.ragdoll.mjcf import RagdollSpec, self_collision_excludes
from engine.ragdoll.profile import bone_segments, servo_gains
from engine.skeleton import Skeleton


def test_default_profile_kinds_and_masses(skeleton: Skeleton) -> None:
    pr = default_profile(skeleton, total_mass=80.0)
    kinds = dict(zip(skeleton.names, pr.kinds))
    assert kinds["hips"] == "free"
    assert {kinds[n] for n in ("l_lower_leg", "r_lower_leg", "l_lower_arm", "r_lower_arm")} == {"hinge"}
    assert kinds["l_upper_arm"] == kinds["chest"] == kinds["head"] == "ball"
    assert pr.masses.sum() == pytest.approx(80.0)
    assert pr.masses[skeleton.index("chest")] > pr.masses[skeleton.index("l_hand")] * 10
    assert pr.holdable == ("chest", "head")


def test_configurable_radii_and_masses(skeleton: Skeleton) -> None:
    masses = np.linspace(1, 2, skeleton.num_joints)
    pr = default_profile(skeleton, masses=masses).with_radii(np.full(skeleton.num_joints, 0.03))
    np.testing.assert_allclose(pr.masses, masses)
    m = mujoco.MjModel.from_xml_string(build_mjcf([RagdollSpec(1, skeleton, pr, skeleton.offsets)], [], 1 / 480))
    np.testing.assert_allclose(m.body_mass[1 : 1 + skeleton.num_joints], masses)
    assert np.allclose(m.geom_size[1:, 0], 0.03)


def test_bad_profiles_are_rejected(skeleton: Skeleton) -> None:
    pr = default_profile(skeleton)
    with pytest.raises(ValueError, match="positive"):
        pr.with_masses(np.zeros(skeleton.num_joints))
    with pytest.raises(KeyError, match="no joint"):
        default_profile(skeleton, holdable=("tail",))


def test_capsules_end_at_the_bone_ends(skeleton: Skeleton) -> None:
    p0, p1, r = bone_segments(skeleton, skeleton.radii)
    j = skeleton.index("l_upper_arm")
    # capsule caps reach the joint and the elbow exactly
    assert np.linalg.norm(p0[j]) == pytest.approx(r[j])
    assert np.linalg.norm(p1[j] - skeleton.offsets[skeleton.index("l_lower_arm")]) == pytest.approx(r[j])
    foot = skeleton.index("l_foot")
    assert np.linalg.norm(p1[foot] - skeleton.tips[foot]) == pytest.approx(r[foot])


def test_gains_share_one_natural_frequency(skeleton: Skeleton) -> None:
    pr = default_profile(skeleton, frequency=25.0)
    kp, kv = servo_gains(skeleton, pr)
    assert kp[0] == 0.0 and np.all(kp[1:] > 0)
    leaf = np.array([not skeleton.children(j) for j in range(skeleton.num_joints)])
    omega = 2 * pr.damping_ratio * kp[1:] / kv[1:]
    np.testing.assert_allclose(omega, np.where(leaf[1:], 25.0 * pr.leaf_boost, 25.0))
    assert kp[skeleton.index("l_upper_leg")] > 50 * kp[skeleton.index("l_hand")]


def test_self_collision_only_where_it_helps(skeleton: Skeleton) -> None:
    pr = default_profile(skeleton)
    ex = {(skeleton.names[a], skeleton.names[b]) for a, b in self_collision_excludes(skeleton, pr, skeleton.offsets)}
    assert ("hips", "spine") in ex and ("l_upper_arm", "l_lower_arm") in ex
    assert ("spine", "l_upper_leg") in ex  # overlapping at rest: would push the legs apart forever
    assert ("hips", "l_hand") not in ex and ("l_lower_leg", "r_lower_leg") not in ex
    assert ("chest", "l_lower_arm") in ex and ("spine", "l_lower_arm") not in ex


def test_two_ragdolls_collide_with_each_other(skeleton: Skeleton) -> None:
    pr = default_profile(skeleton)
    xml = build_mjcf(
        [RagdollSpec(1, skeleton, pr, skeleton.offsets), RagdollSpec(2, skeleton, pr, skeleton.offsets)], [], 1 / 480
    )
    m = mujoco.MjModel.from_xml_string(xml)
    pairs = {(int(a), int(b)) for a, b in zip(m.exclude_signature >> 16, m.exclude_signature & 0xFFFF)}
    hips1, hips2 = m.body("rd1_hips").id, m.body("rd2_hips").id
    assert (min(hips1, hips2), max(hips1, hips2)) not in pairs
    assert m.opt.gravity[1] == pytest.approx(-9.81) and m.opt.gravity[2] == 0.0


def test_any_skeleton_becomes_a_stable_ragdoll() -> None:
    from engine import quat
    from engine.ragdoll import PhysicsWorld

    chain = Skeleton(
        ("root", "a", "b", "c"),
        np.array([-1, 0, 1, 2]),
        np.array([[0, 1.5, 0], [0, 0.3, 0], [0.2, 0.2, 0], [0, 0.25, 0]]),
        np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0.15, 0]]),
        np.full(4, 0.06),
    )
    pr = default_profile(chain, total_mass=5.0)
    assert pr.kinds == ("free", "ball", "ball", "ball") and pr.holdable == ("root",)
    pw = PhysicsWorld()
    pw.add_ragdoll(7, chain, pr, [0.0, 1.5, 0.0], quat.identity(4), offsets=chain.offsets * 1.5)
    for _ in range(180):
        pw.step()
    assert np.isfinite(pw.data.qpos).all()
    assert pw.kinetic_energy(7) < 0.05
    assert pw.body_positions(7)[:, 1].min() > -0.01
    assert pw.joint_limit_violation(7) < np.radians(1.0)
