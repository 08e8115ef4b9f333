"""Shared game drawing: the height cue under lifted balls and puppets, on the ground or on a ball below.

The logic is checked on plain worlds; the pixels on the headless EGL context (skipped
without one): the drop line and the ring must show on bright snow.
"""

import numpy as np
import pytest

from engine import quat
from engine.camera import OrbitCamera
from engine.components import Puppet, Transform, WorldPose
from engine.ecs import World
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ragdoll.components import Prop
from engine.render.headless import egl_available
from engine.render.scene import RenderScene
from games.common import draw_height_cues, height_cues

W, H = 320, 240


def ball(world, centre, radius):
    e = world.spawn(Transform(np.array(centre, dtype=float)), Prop(radius=radius))
    world.flush()
    return e


def puppet(world, lift):
    sk = humanoid_skeleton()
    pos, rot = forward_kinematics(sk, sk.offsets[0] + np.array([2.0, lift, 0.0]), quat.identity(sk.num_joints))
    world.spawn(Puppet(sk), WorldPose(pos, rot, pos.copy(), rot.copy()))
    world.flush()


def test_lifted_things_get_a_cue_resting_ones_do_not():
    world = World()
    ball(world, [-3.0, 0.3, 0.0], 0.3)  # on the ground
    ball(world, [0.0, 0.4, 0.0], 0.4)  # a big one on the ground...
    ball(world, [0.0, 0.8 + 0.25, 0.0], 0.25)  # ...with one packed on top: resting
    ball(world, [0.1, 2.0, 0.05], 0.2)  # held above the stack: lands on the top ball
    ball(world, [3.0, 1.5, 1.0], 0.2)  # held over open snow
    puppet(world, 0.0)  # standing: no cue
    cues = height_cues(world, 1.0)
    assert len(cues) == 2
    over_stack, over_snow = sorted(cues, key=lambda c: c[0][0])
    assert np.allclose(over_snow[0], [3.0, 1.3, 1.0]) and over_snow[1] == 0.0
    top_ball_surface = 1.05 + np.sqrt(0.25**2 - 0.1**2 - 0.05**2)
    assert over_stack[1] == pytest.approx(top_ball_surface)  # the ring lands on the ball it would stack on
    puppet(world, 0.8)  # lifted by the stick
    lifted = [c for c in height_cues(world, 1.0) if c[0][0] == pytest.approx(2.0)]
    assert len(lifted) == 1 and lifted[0][0][1] > 0.8 and lifted[0][1] == 0.0


def test_the_cue_is_a_drop_line_a_ring_and_a_dot():
    world = World()
    ball(world, [0.0, 1.5, 0.0], 0.25)
    scene = RenderScene()
    draw_height_cues(world, scene, 1.0)
    lines = scene.lines.data
    drop = lines[0]
    assert np.allclose(drop[0:3], [0.0, 1.25, 0.0]) and np.allclose(drop[3:6], [0.0, 0.01, 0.0])
    ring = lines[1:]
    assert len(ring) >= 16 and np.allclose(ring[:, [1, 4]], 0.01)
    assert np.allclose(np.hypot(ring[:, 0], ring[:, 2]), 0.15, atol=1e-6)
    assert len(scene.points) == 1


_reason = egl_available()


@pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")
def test_the_cue_shows_dark_on_the_snow_under_a_lifted_ball():
    from engine.render import Viewer, make_target

    world = World()
    centre = np.array([0.0, 1.4, 0.0])
    ball(world, centre, 0.25)
    cam = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), yaw=0.4, pitch=0.45, distance=4.0)
    plain, cued = RenderScene(), RenderScene()
    for s in (plain, cued):
        s.sun.direction = (0.6, 0.75, -0.1)  # the ball's sun shadow falls away from the spot below it
        s.add_sphere(centre, 0.25)
    draw_height_cues(world, cued, 1.0)
    viewer = Viewer(make_target(True, W, H, samples=0), camera=cam)
    try:
        viewer.draw(plain)
        before = viewer.read_pixels().astype(int)
        viewer.draw(cued)
        after = viewer.read_pixels().astype(int)
    finally:
        viewer.close()
    below = np.array([0.0, 0.01, 0.0])
    ring = below + 0.15 * np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    mid = below + np.array([0.0, 0.6, 0.0])  # halfway up the drop line
    for point in [below, mid, *ring]:
        ((x, y),) = np.round(cam.project([point], W, H)).astype(int)
        # the snow there is bright without the cue, and the cue makes it clearly dark (and bluish)
        assert before[y, x].sum() > 3 * 170, (point, before[y, x])
        patch = after[y - 1 : y + 2, x - 1 : x + 2].reshape(-1, 3)
        darkest = patch[patch.sum(axis=1).argmin()]
        assert darkest.sum() < before[y, x].sum() - 300, (point, darkest, before[y, x])
        assert darkest[2] >= darkest[0]


def test_in_a_crowd_only_the_lifted_puppets_get_a_cue_where_they_are_drawn():
    """Cues read a crowd's joints as one array per run of puppets with as many joints; each lifted puppet's cue
    stands under its own root, interpolated like its drawing (a row mix-up or a missed interpolation fails)."""
    world = World()
    sk = humanoid_skeleton()
    for k in range(8):
        lift = 0.6 if k in (2, 5) else 0.0
        pos, rot = forward_kinematics(sk, sk.offsets[0] + np.array([k, lift, 0.0]), quat.identity(sk.num_joints))
        prev = pos - np.array([0.0, 0.0, 0.4])
        world.spawn(Puppet(sk), WorldPose(pos, rot, prev, rot.copy()))
    world.flush()
    cues = height_cues(world, 0.25)
    assert [round(float(c[0][0])) for c in cues] == [2, 5]
    for point, surface, _ in cues:
        assert point[2] == pytest.approx(-0.3) and surface == 0.0 and point[1] > 0.5
