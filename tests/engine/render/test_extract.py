"""World -> RenderScene: bones as capsules, interpolation, shapes, and what the state hash sees."""

import numpy as np
import pytest

from engine import quat
from engine.components import Puppet, Transform, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics, world_points
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton
from engine.render import Appearance, Shape, puppet_capsules, scene_from_world


def spawn_puppet(world, root=(0.0, 0.95, 0.0), shift=(0.0, 0.0, 0.0), **look):
    sk = humanoid_skeleton()
    pos, rot = forward_kinematics(sk, np.array(root), quat.identity(sk.num_joints))
    wp = WorldPose(pos + np.array(shift), rot, prev_positions=pos.copy(), prev_rotations=rot.copy())
    comps = [Puppet(sk), wp]
    if look:
        comps.append(Appearance(**look))
    return world.spawn(*comps), sk, pos, rot


def test_puppet_bones_and_leaf_tips():
    sk = humanoid_skeleton()
    pos, rot = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    a, b, r, owner = puppet_capsules(sk, pos, rot)
    leaves = [sk.index(n) for n in ("head", "l_hand", "r_hand", "l_foot", "r_foot")]
    assert len(a) == (sk.num_joints - 1) + len(leaves)
    # upper arm bone: from the shoulder joint to the elbow, with the upper arm's radius
    ua, la = sk.index("l_upper_arm"), sk.index("l_lower_arm")
    k = np.nonzero(np.all(np.isclose(b, pos[la]), axis=1))[0][0]
    assert np.allclose(a[k], pos[ua]) and r[k] == sk.radii[ua] and owner[k] == ua
    # head capsule's surface ends at the head tip
    tips = world_points(sk, pos, rot)
    h = sk.index("head")
    kh = np.nonzero((owner == h) & np.all(np.isclose(a, pos[h]), axis=1))[0][0]
    assert np.isclose(b[kh][1] + r[kh], tips[h][1])


def test_scene_from_world_interpolates_and_colours():
    world = World()
    _, sk, pos, _ = spawn_puppet(world, shift=(1.0, 0.0, 0.0), color=(0.2, 0.4, 0.6), outline=True)
    scene = scene_from_world(world, 0.5)
    d = scene.capsules.data
    hips_bones = np.all(np.isclose(d[:, 0:3], pos[0] + [0.5, 0, 0], atol=1e-6), axis=1)
    assert hips_bones.sum() == 3  # hips -> spine, l_upper_leg, r_upper_leg, half way across
    assert np.allclose(d[:, 7:10], [0.2, 0.4, 0.6]) and np.all(d[:, 10] == 1.0)
    at_end = scene_from_world(world, 1.0).capsules.data
    assert np.allclose(at_end[:, 0:3].mean(0) - d[:, 0:3].mean(0), [0.5, 0, 0], atol=1e-5)
    with pytest.raises(ValueError):
        scene_from_world(world, 1.5)


def test_invisible_and_joint_colours():
    world = World()
    spawn_puppet(world, visible=False)
    assert len(scene_from_world(world, 1.0).capsules) == 0
    world2 = World()
    sk = humanoid_skeleton()
    jc = np.tile([0.1, 0.1, 0.1], (sk.num_joints, 1))
    jc[sk.index("head")] = [1.0, 0.0, 0.0]
    spawn_puppet(world2, joint_colors=jc)
    d = scene_from_world(world2, 1.0).capsules.data
    assert np.sum(np.all(np.isclose(d[:, 7:10], [1, 0, 0]), axis=1)) == 1


def test_props_by_shape():
    world = World()
    world.spawn(Transform(position=np.array([1.0, 0.3, 0.0]), scale=2.0), Shape.sphere(0.25))
    rot = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    world.spawn(
        Transform(position=np.array([0.0, 1.0, 0.0]), rotation=rot),
        Shape.capsule(0.1, 0.5),
        Appearance(color=(0.0, 1.0, 0.0)),
    )
    world.spawn(Transform(position=np.array([0.0, 0.5, 2.0])), Shape.box([0.2, 0.5, 0.3]))
    scene = scene_from_world(world, 1.0)
    sph = scene.spheres.data
    assert len(sph) == 1 and np.isclose(sph[0, 6], 0.5)
    cap = scene.capsules.data[0]
    assert np.allclose(sorted([cap[0], cap[3]]), [-0.5, 0.5], atol=1e-6)  # rotated onto X
    assert np.allclose(cap[7:10], [0, 1, 0])
    assert np.allclose(scene.boxes.data[0, 3:6], [0.2, 0.5, 0.3])


def test_shape_is_hashed_and_appearance_is_not():
    world = World()
    e = world.spawn(Transform(), Shape.sphere(0.2), Appearance())
    h0 = state_hash(world)
    world.get(e, Appearance).outline = True
    world.get(e, Appearance).color = (0.0, 0.0, 0.0)
    assert state_hash(world) == h0
    world.get(e, Shape).radius = 0.3
    assert state_hash(world) != h0


def test_shape_and_appearance_validation():
    with pytest.raises(ValueError):
        Shape("cone", np.array([1.0]))
    with pytest.raises(ValueError):
        Shape("capsule", np.array([1.0]))
    with pytest.raises(ValueError):
        Shape.sphere(-1.0)
    with pytest.raises(AttributeError):
        Shape.box([1, 1, 1]).radius  # noqa: B018  # the access itself must raise
    with pytest.raises(ValueError):
        Appearance(color=(2.0, 0.0, 0.0))
    s = Shape.sphere(0.2)
    with pytest.raises(ValueError):
        s.radius = float("inf")
    assert s.radius == 0.2


def _posed_crowd(n):
    """``n`` puppets posed twice by the FK system, so their world poses live in its columns."""
    from engine.components import LocalPose
    from engine.posing import fk_system

    world = World()
    rng = np.random.default_rng(3)
    locals_ = []
    for k in range(n):
        sk = humanoid_skeleton()  # each its own copy, as a crowd's puppets hold
        rot = quat.normalize(quat.identity(sk.num_joints) + 0.2 * rng.normal(size=(sk.num_joints, 4)))
        look = {"color": (0.1 * k, 0.5, 0.2)} if k % 2 else {}
        lp = LocalPose(np.array([1.5 * k, 0.95, 0.0]), rot)
        world.spawn(Puppet(sk), lp, *([Appearance(**look)] if look else []))
        locals_.append(lp)
    world.flush()
    fk_system(world)
    for lp in locals_:
        lp.root = lp.root + np.array([0.0, 0.0, 0.3])
    fk_system(world)
    return world


def _one_by_one(world, alpha):
    """The capsules of every puppet drawn on its own, from its own interpolated pose (the old per-puppet way)."""
    parts = [puppet_capsules(p.skeleton, *wp.interpolated(alpha)) for _, p, wp in world.query(Puppet, WorldPose)]
    return np.concatenate([a for a, _, _, _ in parts]), np.concatenate([b for _, b, _, _ in parts])


def test_a_crowd_is_drawn_from_its_columns_as_each_puppet_alone_would_be():
    """The crowd's poses are the FK columns themselves (no gather), and the capsules match drawing each puppet
    on its own. A pose some code replaced is not in the column: it must be read from the component (breaking
    :func:`pose_arrays` to hand out the column without the ``linked`` check draws puppet 2 where it was)."""
    from engine.columns import Columns
    from engine.render.extract import pose_arrays

    world = _posed_crowd(6)
    poses = [wp for _, _, wp in world.query(Puppet, WorldPose)]
    arrays = pose_arrays(world, poses, 17)
    assert arrays[0] is world.resource(Columns).get(WorldPose, "positions", 17).base
    assert all(np.shares_memory(a, getattr(poses[1], name)) for a, name in zip(arrays, ("positions", "rotations")))
    a, b = _one_by_one(world, 0.3)
    d = scene_from_world(world, 0.3).capsules.data
    assert np.allclose(d[:, 0:3], a, atol=1e-6) and np.allclose(d[:, 3:6], b, atol=1e-6)
    assert np.allclose(d[:21, 7:10], Appearance().color) and np.allclose(d[21:42, 7:10], (0.1, 0.5, 0.2))
    before = d.copy()
    poses[2].positions = poses[2].positions + np.array([0.0, 2.0, 0.0])  # other code replaced the field
    a, b = _one_by_one(world, 0.3)
    d = scene_from_world(world, 0.3).capsules.data
    assert np.allclose(d[:, 0:3], a, atol=1e-6) and np.allclose(d[:, 3:6], b, atol=1e-6)
    assert np.allclose(d[42:63, 1] - before[42:63, 1], 0.6, atol=1e-5)  # puppet 2 drawn raised, 0.3 of the way
    assert np.array_equal(np.delete(d, np.s_[42:63], axis=0), np.delete(before, np.s_[42:63], axis=0))


def test_a_puppet_given_another_skeleton_is_drawn_with_it_on_the_next_frame():
    """The crowd's runs of like skeletons are kept between frames (:class:`engine.render.extract.DrawnRuns`);
    a skeleton assigned to one puppet, without any structural change, is seen on the next frame. Broken once
    by keeping the runs whatever the skeletons: puppet 1 kept its old radii and it failed."""
    import dataclasses

    world = _posed_crowd(3)
    before = scene_from_world(world, 0.5).capsules.data.copy()
    puppet = world.query(Puppet, WorldPose)[1][1]
    puppet.skeleton = dataclasses.replace(puppet.skeleton, radii=2.0 * puppet.skeleton.radii)
    after = scene_from_world(world, 0.5).capsules.data
    assert np.allclose(after[21:42, 6], 2.0 * before[21:42, 6])
    assert np.array_equal(np.delete(after, np.s_[21:42], axis=0), np.delete(before, np.s_[21:42], axis=0))
