"""The animation stage: a puppet walks at the requested speed, deterministically, with one-shots."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.blend import BlendLibrary, LocomotionPlayer, LocomotionSet, build_locomotion, install_blend
from engine.clip import Clip
from engine.components import LocalPose, Puppet, Transform
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton


@pytest.fixture(scope="module")
def loco(clips: dict[str, Clip]) -> LocomotionSet:
    one_shot = replace(clips["walk"], name="wave", loop=False, root_motion=None)
    return build_locomotion({**clips, "wave": one_shot}, density=21)


def _app(
    loco: LocomotionSet, speed: float, heading: float = 0.0, height: float | None = None, scale: float = 1.0
) -> tuple[App, int]:
    app = App(seed=1, plugins=[install_blend])
    app.world.resource(BlendLibrary).add("humanoid", loco)
    tr = Transform(rotation=quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), heading))
    e = app.world.spawn(tr, Puppet(humanoid_skeleton()), LocomotionPlayer(speed=speed, height=height, scale=scale))
    return app, e


@pytest.mark.parametrize("speed", [0.4, 1.0, 1.8])
def test_puppet_travels_at_the_requested_speed_along_its_heading(loco: LocomotionSet, speed: float) -> None:
    app, e = _app(loco, speed, heading=np.pi / 2)
    app.run_steps(30)  # let the blend point settle
    start = app.world.get(e, Transform).position.copy()
    app.run_steps(240)
    moved = app.world.get(e, Transform).position - start
    assert np.linalg.norm(moved) / 4.0 == pytest.approx(speed, rel=0.05)
    assert abs(moved[2]) < 0.05 * abs(moved[0]) and moved[0] > 0  # heading +90° about Y faces +X
    player = app.world.get(e, LocomotionPlayer)
    assert player.inside and player.rate == 1.0


def test_local_pose_has_world_root_and_heading(loco: LocomotionSet) -> None:
    app, e = _app(loco, 1.0, heading=np.pi / 2)
    app.run_steps(5)
    local = app.world.get(e, LocalPose)
    tr = app.world.get(e, Transform)
    assert np.isfinite(local.root).all() and np.isfinite(local.rotations).all()
    assert np.allclose(local.root[[0, 2]], tr.position[[0, 2]], atol=1e-9)
    assert 0.7 < local.root[1] < 1.0
    fwd = quat.rotate(local.rotations[0], np.array([0.0, 0.0, 1.0]))
    assert fwd[0] > 0.9  # the hips face the heading


def test_crouch_request_lowers_the_hips(loco: LocomotionSet) -> None:
    app, e = _app(loco, 0.3, height=0.85)
    app.run_steps(120)
    heights = []
    for _ in range(60):
        app.step()
        heights.append(app.world.get(e, LocalPose).root[1])
    assert np.mean(heights) == pytest.approx(0.85, abs=0.01)


def test_a_smaller_puppet_plays_the_set_scaled_same_rotations_shorter_root(loco: LocomotionSet) -> None:
    """A snowman with legs 0.6 as long asks for 0.6 m/s: it plays the clips the full-size
    puppet plays at 1 m/s, with the root 0.6 as high and 0.6 as far per step."""
    big, e_big = _app(loco, 1.0)
    small, e_small = _app(loco, 0.6, scale=0.6)
    for _ in range(90):
        big.step()
        small.step()
        a, b = big.world.get(e_big, LocalPose), small.world.get(e_small, LocalPose)
        assert np.allclose(a.rotations, b.rotations, atol=1e-12)
        assert b.root[1] == pytest.approx(0.6 * a.root[1], abs=1e-12)
    travel_big = big.world.get(e_big, Transform).position
    travel_small = small.world.get(e_small, Transform).position
    assert np.allclose(travel_small, 0.6 * travel_big, atol=1e-12)
    player = small.world.get(e_small, LocomotionPlayer)
    assert player.feasible[0] == pytest.approx(0.6)  # reported in the puppet's own units
    small.world.get(e_small, LocomotionPlayer).scale = 0.0
    with pytest.raises(ValueError, match="scale"):
        small.step()


def test_too_fast_is_sped_up_and_still_keeps_pace(loco: LocomotionSet) -> None:
    fastest = float(loco.table.values[:, 0].max())
    app, e = _app(loco, fastest * 1.6)
    app.run_steps(30)
    start = app.world.get(e, Transform).position.copy()
    app.run_steps(120)
    speed = np.linalg.norm(app.world.get(e, Transform).position - start) / 2.0
    player = app.world.get(e, LocomotionPlayer)
    assert not player.inside and player.rate > 1.4
    assert speed == pytest.approx(fastest * 1.6, rel=0.05)


def test_same_inputs_give_the_same_state_hashes(loco: LocomotionSet) -> None:
    hashes = []
    for _ in range(2):
        app, e = _app(loco, 0.9)
        trace = []
        for i in range(40):
            app.world.get(e, LocomotionPlayer).speed = 0.5 + 0.02 * i
            app.step()
            trace.append(state_hash(app.world))
        hashes.append(trace)
    assert hashes[0] == hashes[1]


def test_one_shot_fades_in_plays_and_hands_back(loco: LocomotionSet) -> None:
    app, e = _app(loco, 0.0)
    app.run_steps(5)
    player = app.world.get(e, LocomotionPlayer)
    player.play("wave", fade=0.1)
    app.run_steps(12)
    assert player.override == "wave" and player.override_weight == pytest.approx(1.0)
    finished = []
    for _ in range(int(loco.clips["wave"].duration * 60) + 10):
        app.step()
        if player.finished:
            finished.append(player.finished)
    assert finished == ["wave"] and player.override is None


def test_bad_requests_fail_clearly(loco: LocomotionSet) -> None:
    app, e = _app(loco, -1.0)
    with pytest.raises(ValueError, match="invalid"):
        app.step()
    app, e = _app(loco, 1.0)
    app.world.get(e, LocomotionPlayer).play("moonwalk")
    with pytest.raises(KeyError, match="moonwalk"):
        app.step()
    app, e = _app(loco, 1.0)
    app.world.get(e, LocomotionPlayer).library_key = "snowman"
    with pytest.raises(KeyError, match="snowman"):
        app.step()


def test_held_one_shot_waits_for_stop(loco: LocomotionSet) -> None:
    app, e = _app(loco, 0.0)
    player = app.world.get(e, LocomotionPlayer)
    player.play("wave", fade=0.1, hold=True)
    app.run_steps(int(loco.clips["wave"].duration * 60) + 30)
    assert player.override == "wave" and player.finished is None and player.override_weight == pytest.approx(1.0)
    player.stop(fade=0.1)
    seen = []
    for _ in range(10):
        app.step()
        seen.append(player.finished)
    assert "wave" in seen and player.override is None
