"""The MotionStick: pick, grab keeping length and rotation, shortening, release, calibration, flick."""

import numpy as np

from engine import quat
from engine.components import Obstacle, Stick, Transform
from input.hub import InputHub
from input.motionstick import StickConfig, StickState
from input.sample import PoseSample
from input.source import PoseSource
from input.stick_geometry import pick, shorten


class Fed(PoseSource):
    threaded = False


def world_sample(direction, touch=None, pivot=(0.0, 1.5, -4.0), **kw):
    d = np.asarray(direction, float)
    return PoseSample(
        time=0.0,
        source="m",
        orientation=quat.between([0, 0, 1], d / np.linalg.norm(d)),
        position=pivot,
        touch=touch,
        mode="world",
        **kw,
    )


def setup(make_app):
    src = Fed("m")
    app = make_app(InputHub([src]))
    return src, app, app.world.query(Stick)[0][0]


def test_pick_and_shorten_geometry():
    c = np.array([[0.0, 0, 5], [0.0, 0, 3], [3.0, 0, 3]])
    assert pick(np.zeros(3), np.array([0, 0, 1.0]), c, np.array([1.0, 0.5, 0.5])) == (1, 2.5)
    assert pick(np.zeros(3), np.array([0, 0, -1.0]), c, np.ones(3)) is None
    down = np.array([0.0, -1.0, 1.0]) / np.sqrt(2)
    assert np.isclose(shorten(np.array([0, 1.0, 0]), down, 5.0), np.sqrt(2))  # hits the ground
    assert shorten(np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), 5.0) == 5.0
    post = {"bases": np.array([[0.0, 0, 3]]), "radii": np.array([0.5]), "heights": np.array([2.0])}
    assert np.isclose(shorten(np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), 5.0, **post), 2.5)  # side wall
    assert shorten(np.array([0, 3.0, 0]), np.array([0, 0, 1.0]), 5.0, **post) == 5.0  # passes over it
    assert np.isclose(shorten(np.array([0, 4.0, 3]), np.array([0, -1.0, 0]), 5.0, **post), 2.0)  # top cap


def test_grab_keeps_length_and_relative_rotation_then_release(make_app):
    src, app, e = setup(make_app)
    target = np.array([0.0, 0.95, 0.0]) - np.array([0.0, 1.5, -4.0])
    src.push(world_sample(target))
    app.step()
    stick = app.world.get(e, Stick)
    assert stick.focus is not None and stick.grabbed is None
    puppet = stick.focus
    src.push(world_sample(target, touch=True))
    app.step()
    assert stick.grabbed == puppet and stick.just_grabbed and stick.touching
    length = stick.length
    assert np.isclose(length, np.linalg.norm(target))
    rel = stick.grab_rotation.copy()
    # Swing the stick sideways: the same length, the tip moves, and the rules system carried the puppet.
    src.push(world_sample(target + [1.0, 0.0, 0.0]))
    app.step()
    assert not stick.just_grabbed and np.isclose(stick.length, length)
    assert np.allclose(app.world.get(puppet, Transform).position, stick.tip, atol=0.01)
    assert np.allclose(stick.grab_rotation, rel)
    src.push(world_sample(target, touch=False))
    app.step()
    assert stick.grabbed is None and stick.released == puppet and not stick.touching


def test_tip_stops_at_the_ground_and_at_obstacles(make_app):
    src, app, e = setup(make_app)
    src.push(world_sample([0, 0.95 - 1.5, 4.0], touch=True))
    app.step()
    stick = app.world.get(e, Stick)
    held = stick.length
    src.push(world_sample([0.0, -1.0, 0.3]))  # point steeply down: the ground cuts the stick short
    app.step()
    assert stick.length < held and np.isclose(stick.tip[1], 0.0)
    app.world.spawn(Transform(position=np.array([1.0, 0.0, -1.0])), Obstacle(radius=0.3, height=1.5))
    src.push(world_sample(np.array([1.0, 0.9, -1.0]) - [0, 1.5, -4.0]))  # aim at a post nearer than the puppet
    app.step()
    assert stick.length < held - 0.2 and np.isclose(np.hypot(stick.tip[0] - 1.0, stick.tip[2] + 1.0), 0.3)


def test_disconnect_releases_and_despawned_target_releases(make_app):
    src, app, e = setup(make_app)
    src.push(world_sample([0, 0.95 - 1.5, 4.0], touch=True))
    app.step()
    stick = app.world.get(e, Stick)
    held = stick.grabbed
    assert held is not None
    src.disconnected("m")
    app.step()
    assert stick.grabbed is None and stick.released == held and not stick.connected
    src.push(world_sample([0, 0.95 - 1.5, 4.0], touch=True))
    app.step()
    assert stick.connected and stick.grabbed is not None
    app.world.despawn(stick.grabbed)
    app.step()
    assert stick.grabbed is None and stick.released is not None
    app.step()
    assert stick.released is None  # for one step only


def test_device_calibration_makes_the_pointing_direction_forward(make_app):
    src, app, e = setup(make_app)
    sideways = quat.from_axis_angle([0, 1, 0], 1.2)  # pointing off to one side, level
    src.push(PoseSample(time=0, source="m", orientation=sideways, touch=True))
    app.step()
    stick = app.world.get(e, Stick)
    assert np.allclose(stick.direction, [0, 0, 1]) and stick.grabbed is None  # the tap calibrated, no grab
    assert np.allclose(stick.pivot, StickConfig().virtual_pivot)
    turn = quat.mul(quat.from_axis_angle([0, 1, 0], 0.3), sideways)
    src.push(PoseSample(time=0, source="m", orientation=turn, position=[0.0, 0.5, 0.0], touch=False))
    app.step()
    assert np.isclose(np.arctan2(stick.direction[0], stick.direction[2]), 0.3)
    assert np.allclose(stick.pivot, StickConfig().virtual_pivot + [0, 0.5, 0])  # 6-DoF moves the pivot


def test_velocity_is_filtered_and_an_upward_flick_fires_once(make_app):
    src, app, e = setup(make_app)
    aim = np.array([0.0, 0.95, 0.0]) - [0, 1.5, -4.0]
    src.push(world_sample(aim, touch=True))
    app.step()
    stick = app.world.get(e, Stick)
    flicks, speeds = 0, []
    for i in range(20):
        src.push(world_sample(aim + [0, 0.08 * i, 0]))  # ~4.8 m/s upwards at 60 Hz
        app.step()
        flicks += stick.flick
        speeds.append(stick.velocity[1])
    # A world-mode source (the mouse) flicks only by its own flag: its tip also jumps with
    # wheel notches, which are not gestures.
    assert flicks == 0
    assert speeds[0] == 0.0 and 0 < speeds[1] < speeds[-1] and 3.0 < speeds[-1] < 5.5  # smoothed, converging
    flagged = world_sample(aim + [0, 0.08 * 20, 0])
    flagged.flick = True
    src.push(flagged)
    app.step()
    assert stick.flick


def test_a_poisoned_velocity_filter_starts_again_at_rest(make_app):
    src, app, e = setup(make_app)
    aim = np.array([0.0, 0.95, 0.0]) - [0, 1.5, -4.0]
    src.push(world_sample(aim))
    app.step()
    st = app.world.get(e, StickState)
    st.filt_dx = np.array([np.nan, 0.0, 0.0])  # what one 1e308 datagram used to leave behind for good
    src.push(world_sample(aim))
    app.step()
    stick = app.world.get(e, Stick)
    assert np.all(np.isfinite(stick.velocity)) and np.all(np.isfinite(st.filt_x))
    src.push(world_sample(aim + [0, 0.08, 0]))
    app.step()
    assert np.all(np.isfinite(stick.velocity)) and stick.velocity[1] > 0


def test_a_huge_osc_double_is_dropped_and_the_stick_stays_finite(make_app):
    from pythonosc.osc_message_builder import OscMessageBuilder

    from input.osc import OscSource

    def pose(x):
        b = OscMessageBuilder("/puppetphone/pose")
        for v in (x, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0):
            b.add_arg(v, "d")
        return b.build().dgram

    osc = OscSource(port=0, admit_after=1)
    try:
        app = make_app(InputHub([osc]))
        e = app.world.query(Stick)[0][0]
        for i, x in enumerate([0.0, 0.01, 1e308, 5000.0, 0.02, 0.03]):
            osc.handle_datagram(pose(x), "osc:10.0.0.2", 1.0 + i / 60)
            app.step()
            stick = app.world.get(e, Stick)
            assert np.all(np.isfinite(stick.velocity)) and np.all(np.isfinite(stick.tip))
            assert abs(stick.pivot[0] - StickConfig().virtual_pivot[0]) < 1.0
    finally:
        osc.stop()
    reasons = osc.status().drop_reasons
    assert reasons == {"value out of range": 1, "invalid sample": 1}
