"""Drawing snowmen and trees: every part where the rig puts it, outlines on the balls only."""

import numpy as np
import pytest

from engine import quat
from engine.components import Puppet, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics
from engine.render.scene import RenderScene
from games.snowman.components import Snowman
from games.snowman.draw import draw_snowmen
from games.snowman.rig import SnowmanShape, snowman_skeleton
from games.snowman.scenery import TREES, draw_trees


def spawn_standing(world, shape, heading, at):
    sk = snowman_skeleton(shape)
    rot = quat.identity(sk.num_joints)
    rot[0] = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), heading)
    pos, rot = forward_kinematics(sk, sk.offsets[0] + at, rot)
    e = world.spawn(Snowman(shape), Puppet(sk), WorldPose(pos, rot, pos.copy(), rot.copy()))
    world.flush()
    return e, sk, pos


def rows_with_color(rows, color):
    return rows[np.all(np.abs(rows[:, 7:10] - color) < 1e-6, axis=1)]


@pytest.mark.parametrize("shape", [SnowmanShape(0.5, 0.35, 0.22), SnowmanShape(0.4, None, 0.2)])
def test_a_snowman_is_drawn_on_its_joints(shape):
    world = World()
    e, sk, pos = spawn_standing(world, shape, np.pi / 2, np.array([2.0, 0.0, -1.0]))
    other, _, _ = spawn_standing(world, SnowmanShape(0.3, None, 0.15), 0.0, np.array([-3.0, 0.0, 0.0]))
    scene = RenderScene()
    draw_snowmen(world, scene, 1.0, {e})
    spheres, capsules = scene.spheres.data, scene.capsules.data
    snow = rows_with_color(spheres, (0.97, 0.98, 1.0))
    balls = 3 if shape.middle else 2
    assert len(snow) == balls + 2  # the other snowman's two balls
    mine = snow[snow[:, 10] > 0.5]  # outlined: only the grabbed snowman's balls
    assert len(mine) == balls
    assert np.allclose(mine[0, 0:3], pos[sk.index("hips")]) and mine[0, 6] == pytest.approx(shape.bottom)
    assert np.allclose(mine[-1, 0:3], pos[sk.index("head")], atol=1e-6) and mine[-1, 6] == pytest.approx(shape.head)
    if shape.middle:
        assert mine[1, 6] == pytest.approx(shape.middle)
        # Standing straight, the middle ball rests on the bottom one.
        assert np.linalg.norm(mine[1, 0:3] - mine[0, 0:3]) == pytest.approx(shape.bottom + shape.middle, rel=1e-3)
    coal = rows_with_color(spheres, (0.08, 0.08, 0.09))
    assert len(coal) == 2 + (3 if shape.middle else 0) + 2 and not np.any(coal[:, 10])
    # The carrot points the way the snowman faces (+x after a quarter turn about y).
    (nose,) = [
        r for r in rows_with_color(capsules, (0.95, 0.45, 0.1)) if np.linalg.norm(r[0:3] - pos[sk.index("head")]) < 1.0
    ]
    assert nose[3] - nose[0] > 0.5 * shape.head
    # Twig arms end beyond the hands; legs start at the thighs.
    twigs = rows_with_color(capsules, (0.35, 0.22, 0.12))
    assert len(twigs) == 12
    assert any(np.allclose(r[0:3], pos[sk.index("l_upper_arm")]) for r in twigs)
    assert any(np.allclose(r[0:3], pos[sk.index("r_upper_leg")]) for r in capsules)


def test_snowmen_drawn_together_get_the_rows_each_gets_alone():
    """The snowmen's rows are computed as arrays over all of them at once; each snowman's rows (in its
    place, outline included) must be the ones it gets when it is the only one, whatever the others'
    shapes and poses. (Taking the first snowman's middle radius for all of them fails this.)"""
    rng = np.random.default_rng(4)
    shapes = [SnowmanShape(0.5, 0.35, 0.22), SnowmanShape(0.4, None, 0.2), SnowmanShape(0.3, 0.2, 0.12)]
    poses = []
    for k, shape in enumerate(shapes):
        sk = snowman_skeleton(shape)
        rot = quat.exp(rng.normal(scale=0.3, size=(sk.num_joints, 3)))
        pos, rot = forward_kinematics(sk, sk.offsets[0] + np.array([1.5 * k, 0.0, -k]), rot)
        prev, prev_rot = forward_kinematics(
            sk, sk.offsets[0] + np.array([1.5 * k, 0.1, -k]), quat.identity(sk.num_joints)
        )
        poses.append((shape, sk, WorldPose(pos, rot, prev, prev_rot)))

    def draw(which, outlined):
        world = World()
        ents = [world.spawn(Snowman(shape), Puppet(sk), wp) for shape, sk, wp in which]
        world.flush()
        scene = RenderScene()
        draw_snowmen(world, scene, 0.4, {ents[i] for i in outlined})
        order = [ents.index(e) for e, _ in world.query(Snowman)]
        return scene.capsules.data, scene.spheres.data, order

    caps, spheres, order = draw(poses, {2})
    at_c = at_s = 0
    for k in order:
        alone_c, alone_s, _ = draw([poses[k]], {0} if k == 2 else set())
        assert np.array_equal(caps[at_c : at_c + len(alone_c)], alone_c)
        assert np.array_equal(spheres[at_s : at_s + len(alone_s)], alone_s)
        at_c, at_s = at_c + len(alone_c), at_s + len(alone_s)
    assert (at_c, at_s) == (len(caps), len(spheres)) == (39, 20)


def test_trees_are_a_trunk_and_three_overlapping_cone_tiers_each():
    scene = RenderScene()
    draw_trees(scene)
    assert len(scene.capsules) == len(TREES) and len(scene.cones) == 3 * len(TREES) and len(scene.spheres) == 0
    trunks = scene.capsules.data
    assert np.allclose(trunks[:, [0, 2]], [(x, z) for x, z, _ in TREES])
    tiers = scene.cones.data.reshape(len(TREES), 3, -1)
    base_y, apex_y, radius = tiers[..., 1], tiers[..., 4], tiers[..., 6]
    # Narrower going up, each tier's skirt below the apex of the one beneath (whorls, not a stack).
    assert np.all(np.diff(radius, axis=1) < 0) and np.all(base_y[:, 1:] < apex_y[:, :-1])
    assert np.all(base_y[:, 0] < trunks[:, 4])  # the lowest skirt hides the top of the trunk


def test_the_streamed_drawing_keeps_each_footprint_in_its_slot_and_a_filled_one_at_no_size():
    """The phone's stream sends rows that changed; a print that fills must not move every later row
    (``draw_footprints``' visible list would). The desktop sees the same prints: a filled one has no area.
    (Dropping the filled rows, as ``visible`` does, fails the slot check.)"""
    from games.snowman.draw import draw_snowman_state
    from games.snowman.footprints import Footprints, draw_footprints

    world = World()
    prints = Footprints()
    world.insert_resource(prints)
    for k in range(5):
        prints.stamp(np.array([0.3 * k, 0.0]), 0.1 * k, frame=k * 1500)  # 25 s apart: the oldest fill first
    world.frame = 4 * 1500 + 60
    now = RenderScene()
    draw_snowman_state(world, now, 1.0)
    shown = RenderScene()
    draw_footprints(world, shown)
    rows = now.prints.data
    assert len(rows) == 5 and np.allclose(rows[:, 0], [0.0, 0.3, 0.6, 0.9, 1.2]), "a print left its slot"
    sized = rows[:, 4] > 0
    assert sized.sum() == len(shown.prints) < 5, "the filled prints should be there at no size"
    assert np.allclose(rows[sized], shown.prints.data)
    assert np.all(rows[~sized, 4:6] == 0.0)
