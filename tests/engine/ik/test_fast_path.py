"""The float per-frame IK gives the same poses as the numpy formulation it replaced.

``_ref_ground`` and ``_ref_hands`` are the previous implementations of
:func:`ground_feet` and :func:`hands_on_sphere`, written on numpy with
:func:`engine.fk.forward_kinematics` and the *batched* two-bone solver (a batch of
one pose), so they share no arithmetic with the float path under test.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import (
    HUMANOID_ARMS,
    HUMANOID_LEGS,
    HeightfieldGround,
    PlaneGround,
    ground_feet,
    hands_on_sphere,
    two_bone_ik,
)
from engine.pose import Pose

UP = np.array([0.0, 1.0, 0.0])


def _unit(v):
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _frame(a, b):
    a = _unit(a)
    b = _unit(b - np.sum(a * b, axis=-1, keepdims=True) * a)
    return np.stack([a, b, np.cross(a, b)], axis=-1)


def _batched_limb(sk, pose, joints, target, pole, end_rotation):
    one = Pose(pose.root[None].copy(), pose.rotations[None].copy())
    target, pole = np.asarray(target)[None], np.asarray(pole)[None]
    end = two_bone_ik(sk, one, joints, target, pole, end_rotation=end_rotation[None])
    pose.rotations[:] = one.rotations[0]
    return end[0]


def _ref_ground(sk, pose, ground, weight, align_height=0.25, contact_height=0.03, max_shift=0.5):
    idx = [(sk.index(g.upper), sk.index(g.lower), sk.index(g.foot)) for g in HUMANOID_LEGS]
    sole_local = np.array([g.sole for g in HUMANOID_LEGS])
    wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
    feet = [f for _, _, f in idx]
    ankle, qfoot = wp[feet], wr[feet]
    sole = ankle + quat.rotate(qfoot, sole_local)
    clip_height = sole[:, 1]
    height, normal = ground(sole[:, 0], sole[:, 2])
    planted = np.clip((align_height - clip_height) / (align_height - contact_height), 0.0, 1.0) * weight
    new_rot = quat.mul(quat.slerp(quat.identity(2), quat.between(UP, normal), planted), qfoot)
    new_sole = np.stack([sole[:, 0], height * weight + clip_height, sole[:, 2]], axis=-1)
    targets = new_sole - quat.rotate(new_rot, sole_local)
    # No toe tip or heel below the ground: the foot is raised by the deepest one.
    toes = targets + quat.rotate(new_rot, sk.tips[feet])
    heels = targets + quat.rotate(new_rot, np.array([g.heel for g in HUMANOID_LEGS]))
    n = (1 - weight) * UP + weight * normal
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    floor = np.stack([sole[:, 0], height * weight, sole[:, 2]], axis=-1)
    depth = np.minimum(((toes - floor) * n).sum(-1), ((heels - floor) * n).sum(-1))
    targets[:, 1] += np.maximum(-depth, 0.0) / n[:, 1]
    shift = float(np.clip(np.min(targets[:, 1] - ankle[:, 1]), -max_shift, max_shift))
    # Lower further where a target is out of the leg's reach from its hip (knees bend).
    for (u, lo, f), tgt in zip(idx, targets, strict=True):
        reach = np.linalg.norm(sk.offsets[lo]) + np.linalg.norm(sk.offsets[f]) - 1e-4
        dxz = np.hypot(*(tgt - wp[u])[[0, 2]])
        if dxz < reach:
            shift = max(min(shift, tgt[1] + np.sqrt(reach**2 - dxz**2) - wp[u][1]), -max_shift)
    pose.root[1] += shift
    for leg, (u, lo, f), tgt, frot in zip(HUMANOID_LEGS, idx, targets, new_rot, strict=True):
        wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
        pole = wp[lo] + quat.rotate(wr[sk.parents[u]], leg.knee_forward)
        _batched_limb(sk, pose, (u, lo, f), tgt, pole, frot)
    return shift


def _ref_hands(sk, pose, centre, radius, lean_joint="spine", max_lean=0.9, spread=0.7, elevation=0.35):
    arms = HUMANOID_ARMS
    ids = [(sk.index(a.upper), sk.index(a.lower), sk.index(a.hand)) for a in arms]
    upper_len = np.array([np.linalg.norm(sk.offsets[lo]) + np.linalg.norm(sk.offsets[h]) for _, lo, h in ids])

    def targets():
        wp, _ = forward_kinematics(sk, pose.root, pose.rotations)
        chest = wp[sk.parents[ids[0][0]]]
        left, fwd = quat.rotate(pose.rotations[0], [1.0, 0.0, 0.0]), quat.rotate(pose.rotations[0], [0.0, 0.0, 1.0])
        toward = chest - centre
        toward[1] = 0.0
        lft = _unit(left * [1.0, 0.0, 1.0])
        toward = _unit(toward if np.linalg.norm(toward) >= 1e-6 else np.cross(lft, UP))
        horiz = _unit(np.cos(spread) * toward[None] + np.sin(spread) * np.array([[1.0], [-1.0]]) * lft[None])
        normals = np.cos(elevation) * horiz + np.sin(elevation) * UP[None]
        contacts = centre[None] + radius * normals
        shoulders = wp[[u for u, _, _ in ids]]
        rots = []
        for arm, n, sh, ct in zip(arms, normals, shoulders, contacts, strict=True):
            fingers = (ct - sh) - np.dot(ct - sh, n) * n
            if np.linalg.norm(fingers) < 1e-6:
                fingers = fwd - np.dot(fwd, n) * n
            local = _frame(np.array(arm.palm_normal), np.array(arm.fingers))
            rots.append(quat.from_matrix(_frame(-n, fingers) @ local.T))
        hand_rot = np.array(rots)
        wrists = contacts - quat.rotate(hand_rot, np.array([a.palm for a in arms]))
        return wrists, hand_rot, shoulders, fwd

    wrists, hand_rot, shoulders, fwd = targets()
    if lean_joint is not None:
        lj, leaned = sk.index(lean_joint), 0.0
        for _ in range(6):
            short = np.max(np.linalg.norm(wrists - shoulders, axis=-1) - 0.97 * upper_len)
            if short <= 1e-4:
                break
            wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
            torso = float(np.linalg.norm(shoulders.mean(axis=0) - wp[lj]))
            toward = (centre - wp[lj]) * [1.0, 0.0, 1.0]
            axis = np.cross(UP, _unit(toward) if np.linalg.norm(toward) > 1e-6 else fwd)
            angle = min(short / max(torso, 1e-3), max_lean - leaned)
            if angle <= 1e-6:
                break
            leaned += angle
            turn = quat.from_axis_angle(axis, angle)
            pose.rotations[lj] = quat.mul(quat.conjugate(wr[sk.parents[lj]]), quat.mul(turn, wr[lj]))
            wrists, hand_rot, shoulders, fwd = targets()
    reached = []
    for arm, limb, tgt, hr, sh in zip(arms, ids, wrists, hand_rot, shoulders, strict=True):
        out = quat.rotate(pose.rotations[0], [arm.side, 0.0, 0.0])
        wrist = _batched_limb(sk, pose, limb, tgt, sh + 0.5 * out - 0.8 * fwd - 0.3 * UP, hr)
        reached.append(wrist + quat.rotate(hr, arm.palm))
    return np.array(reached)


def _cases(count):
    """Perturbed, turned, crouched poses with a ball somewhere in front: near, far, low (leaning) and high."""
    rng = np.random.default_rng(17)
    sk = humanoid_skeleton()
    grounds = (
        PlaneGround(),
        PlaneGround(normal=(0.15, 1.0, -0.3)),
        HeightfieldGround(rng.uniform(-0.1, 0.1, (30, 30)), cell=0.15, x0=-2.2, z0=-2.2),
    )
    out = []
    for i in range(count):
        rot = quat.exp(rng.uniform(-0.35, 0.35, (17, 3)))
        yaw = rng.uniform(-np.pi, np.pi)
        rot[0] = quat.from_axis_angle(UP, yaw)
        root = np.array([rng.uniform(-1.5, 1.5), rng.uniform(0.75, 0.97), rng.uniform(-1.5, 1.5)])
        fwd = np.array([np.sin(yaw), 0.0, np.cos(yaw)])
        radius = rng.uniform(0.12, 0.5)
        centre = root * [1, 0, 1] + fwd * (radius + rng.uniform(0.15, 0.8)) + [rng.uniform(-0.15, 0.15), 0.0, 0.0]
        centre[1] = radius + rng.uniform(-0.05, 0.8)
        out.append((sk, Pose(root, rot), grounds[i % 3], rng.uniform(0.3, 1.0), centre, radius))
    return out


@pytest.mark.parametrize("case", range(24))
def test_stage_matches_the_numpy_formulation(case):
    sk, pose, ground, weight, centre, radius = _cases(24)[case]
    fast, ref = pose.copy(), pose.copy()
    shift = ground_feet(sk, fast, ground, weight=weight)
    assert shift == pytest.approx(_ref_ground(sk, ref, ground, weight), abs=1e-12)
    assert np.allclose(fast.root, ref.root, atol=1e-12)
    assert np.allclose(fast.rotations, ref.rotations, atol=1e-9)
    for lean in ("spine", None):
        f, r = fast.copy(), ref.copy()
        palms = hands_on_sphere(sk, f, centre, radius, lean_joint=lean)
        assert np.allclose(palms, _ref_hands(sk, r, centre, radius, lean_joint=lean), atol=1e-9)
        assert np.allclose(f.rotations, r.rotations, atol=1e-9)


def test_cases_cover_leaning():
    """The comparison above is only meaningful if the balls make the spine lean (the re-measure loop runs)."""
    leaned = 0
    for sk, pose, ground, weight, centre, radius in _cases(24):
        p = pose.copy()
        ground_feet(sk, p, ground, weight=weight)
        q = p.copy()
        hands_on_sphere(sk, q, centre, radius)
        leaned += not np.allclose(q.rotations[sk.index("spine")], p.rotations[sk.index("spine")])
    assert leaned >= 12
