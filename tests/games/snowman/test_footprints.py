"""Footprints: a print where a foot comes down, none for a foot tapping in place, none in the state hash."""

import numpy as np

from engine import quat
from engine.components import Puppet, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics
from engine.hashing import combine_parts, state_parts
from engine.humanoid import humanoid_skeleton
from engine.render.scene import RenderScene
from games.snowman.footprints import Footprints, draw_footprints, leave_footprints


def _walker():
    world = World()
    world.insert_resource(Footprints())
    sk = humanoid_skeleton()
    pos, rot = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    e = world.spawn(Puppet(sk), WorldPose(pos, rot, pos.copy(), rot.copy()))
    world.flush()
    return world, sk, world.get(e, WorldPose)


def _set_foot(sk, wp, name, x, height):
    j = sk.index(name)
    wp.positions[j] = [x, height, 0.1 if name == "l_foot" else -0.1]


def test_a_foot_coming_down_leaves_one_print_under_it_pointing_along_the_toes():
    world, sk, wp = _walker()
    r = float(sk.radii[sk.index("l_foot")])
    for _step, (x, up) in enumerate([(0.0, False), (0.2, True), (0.4, False), (0.4, False), (0.6, True), (0.8, False)]):
        _set_foot(sk, wp, "l_foot", x, (3.0 if up else 1.0) * r)
        _set_foot(sk, wp, "r_foot", 0.0, 5.0 * r)  # the other foot stays in the air
        leave_footprints(world)
        world.frame += 1
    prints = world.resource(Footprints)
    assert prints.count == 3  # down at 0.0, 0.4 and 0.8; staying down stamps nothing more
    xz, heading, strength = prints.visible(world.frame, world.dt)
    toe = sk.tips[sk.index("l_foot")]
    assert np.allclose(xz[:, 0], [0.0, 0.4, 0.8] + 0.5 * toe[0]) and np.allclose(heading, np.arctan2(toe[2], toe[0]))
    assert np.all(strength == 1.0)
    scene = RenderScene()
    draw_footprints(world, scene)
    assert len(scene.prints) == 3


def test_a_foot_tapping_in_place_does_not_pile_up_prints_and_old_prints_fade():
    world, sk, wp = _walker()
    r = float(sk.radii[sk.index("l_foot")])
    for k in range(10):
        _set_foot(sk, wp, "l_foot", 0.01 * k, (3.0 if k % 2 else 1.0) * r)  # shuffling 2 cm a step
        _set_foot(sk, wp, "r_foot", 0.0, 5.0 * r)
        leave_footprints(world)
        world.frame += 1
    prints = world.resource(Footprints)
    assert prints.count == 1
    later = world.frame + int((prints.fade_start + prints.fade_time + 1.0) / world.dt)
    assert len(prints.visible(later, world.dt)[0]) == 0


def test_footprints_are_not_simulation_state():
    stamped, sk, wp = _walker()
    untouched, _, _ = _walker()
    _set_foot(sk, wp, "l_foot", 0.0, 0.0)
    _set_foot(sk, untouched.get(next(e for e, _ in untouched.query(Puppet)), WorldPose), "l_foot", 0.0, 0.0)
    leave_footprints(stamped)
    assert stamped.resource(Footprints).count >= 1 and untouched.resource(Footprints).count == 0
    assert combine_parts(state_parts(stamped))[0] == combine_parts(state_parts(untouched))[0]
