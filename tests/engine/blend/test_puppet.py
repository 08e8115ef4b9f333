"""The puppet's Fig. 6.3 space on the authored default clips, and the public surface."""

from __future__ import annotations

import numpy as np
import pytest

import engine.blend as blend
from engine.app import App
from engine.blend import (
    PUPPET_PLACEMENT,
    BlendLibrary,
    LocomotionPlayer,
    LocomotionSet,
    build_locomotion,
    height_mapping,
    measure_locomotion,
)
from engine.components import Puppet, Transform
from engine.humanoid import humanoid_skeleton


@pytest.fixture(scope="module")
def real() -> LocomotionSet:
    clips = pytest.importorskip("engine.clips").default_clips()
    return build_locomotion(clips, density=21)


def test_public_surface_is_exported() -> None:
    for name in blend.__all__:
        assert hasattr(blend, name), name
    assert {"blend", "BlendSpace", "LookupTable", "LocomotionPlayer", "animate", "install_blend"} <= set(blend.__all__)


def test_default_clips_fill_figure_6_3(real: LocomotionSet) -> None:
    assert real.space.names == tuple(PUPPET_PLACEMENT)
    assert {"get_up", "mid_jump"} <= set(real.clips)
    speeds = measure_locomotion(real.space, np.stack([np.linspace(0, 1, 21), np.ones(21)], axis=-1))[:, 0]
    assert speeds[0] == pytest.approx(0.0, abs=1e-9)
    assert np.all(np.diff(speeds) > 0.0)
    # the mapping is non-linear (the thesis's point): halfway in p is not halfway in speed
    assert abs(speeds[10] / speeds[-1] - 0.5) > 0.05


def test_requests_play_at_their_speed_on_the_real_clips(real: LocomotionSet) -> None:
    u = np.array([[0.5, 0.85], [1.3, 0.87], [2.0, 0.85], [0.4, 0.65]])
    assert all(real.table.resolve(x).inside for x in u)
    played = measure_locomotion(real.space, real.table.query(u))
    assert np.allclose(played[:, 0], u[:, 0], rtol=0.05)
    assert np.allclose(played[:, 1], u[:, 1], atol=0.01)


def test_phone_height_maps_linearly_onto_the_crouch(real: LocomotionSet) -> None:
    m = height_mapping(real.table, 0.3, 1.2)
    lo, hi = real.table.values[:, 1].min(), real.table.values[:, 1].max()
    assert m(np.array(0.0)) == pytest.approx(lo) and m(np.array(2.0)) == pytest.approx(hi)


def test_get_up_one_shot_on_the_puppet(real: LocomotionSet) -> None:
    app = App(seed=0, plugins=[blend.install_blend])
    app.world.resource(BlendLibrary).add("humanoid", real)
    e = app.world.spawn(Transform(), Puppet(humanoid_skeleton()), LocomotionPlayer(speed=0.0))
    player = app.world.get(e, LocomotionPlayer)
    player.play("get_up")
    seen = None
    for _ in range(int(real.clips["get_up"].duration * 60) + 5):
        app.step()
        seen = seen or player.finished
    assert seen == "get_up"


def test_install_puppet_locomotion_registers_the_humanoid_set() -> None:
    pytest.importorskip("engine.clips")
    app = App(seed=0, plugins=[blend.install_puppet_locomotion])
    assert "humanoid" in app.world.resource(BlendLibrary)
    assert blend.animate in app.systems("animation")
    e = app.world.spawn(Transform(), Puppet(humanoid_skeleton()), LocomotionPlayer(speed=1.0))
    app.run_steps(3)
    assert app.world.get(e, Transform).position[2] > 0.0


def test_sync_aligns_the_real_walk_and_run_heel_strikes(real: LocomotionSet) -> None:
    contacts = pytest.importorskip("engine.clips").foot_contacts
    space = real.space
    walk, run = space.names.index("walk"), space.names.index("run")
    phases = np.concatenate([np.linspace(0.0, 0.05, 6), np.linspace(0.5, 0.55, 6)])
    times = space.sync.clip_times(phases)
    for k in (walk, run):
        clip = space.clips[k]
        labels = contacts(clip)[np.round(times[:, k] * clip.fps).astype(int) % clip.num_frames]
        assert labels[:6, 0].all(), clip.name  # left foot down right after phase 0
        assert labels[6:, 1].all(), clip.name  # right foot down right after phase 0.5
