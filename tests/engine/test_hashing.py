"""``state_hash``: identical runs agree frame by frame; any state change shows."""

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.components import LocalPose, Puppet, Transform
from engine.hashing import state_hash
from engine.humanoid import humanoid_skeleton
from engine.posing import install_fk


@dataclass
class Wander:
    """A toy behaviour: random-walk the root and joints with the world's RNG."""

    speed: float = 1.0


@dataclass
class DisplayOnly:
    SIM_STATE = False
    value: float = 0.0


@dataclass
class Tagged:
    kept: float = 0.0
    skipped: float = field(default=0.0, metadata={"hash": False})


def wander(world):
    for _e, w, lp, tr in world.query(Wander, LocalPose, Transform):
        tr.position = tr.position + world.rng.normal(scale=0.01 * w.speed, size=3)
        lp.root = tr.position + [0, 0.95, 0]
        lp.rotations = quat.normalize(lp.rotations + world.rng.normal(scale=0.01, size=lp.rotations.shape))
    if world.frame % 100 == 50:
        world.queue_spawn(Wander(), Transform(), Puppet(humanoid_skeleton()), LocalPose(np.zeros(3), quat.identity(17)))


def run(seed, frames=600):
    app = App(seed=seed, plugins=[install_fk])
    app.add_system("animation", wander)
    sk = humanoid_skeleton()
    for k in range(3):
        app.world.spawn(
            Wander(1.0 + k), Transform(np.array([k, 0.0, 0])), Puppet(sk), LocalPose(np.zeros(3), quat.identity(17))
        )
    hashes = []
    for _ in range(frames):
        app.step()
        hashes.append(state_hash(app.world))
    return hashes, app


def test_same_inputs_same_hashes_over_600_frames():
    a, _ = run(seed=5)
    b, _ = run(seed=5)
    assert a == b
    assert len(set(a)) == len(a)  # the state changes every frame


def test_other_seed_diverges():
    a, _ = run(seed=5, frames=10)
    c, _ = run(seed=6, frames=10)
    assert a[0] != c[0]


def test_hash_sees_components_and_skips_display_state():
    _, app = run(seed=1, frames=2)
    w = app.world
    e = w.spawn(DisplayOnly(), Tagged())
    h0 = state_hash(w)
    w.get(e, DisplayOnly).value = 3.0
    w.get(e, Tagged).skipped = 3.0
    assert state_hash(w) == h0
    w.get(e, Tagged).kept = 1e-300
    assert state_hash(w) != h0


def test_unhashable_component_is_named():
    _, app = run(seed=1, frames=1)
    app.world.spawn(object())
    with pytest.raises(TypeError, match="object"):
        state_hash(app.world)


def _nudged(value):
    """The smallest change of a value, or ``None`` when the test does not nudge that kind."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, float):
        return float(np.nextafter(value, np.inf))
    if isinstance(value, int):
        return value + 1
    if isinstance(value, str):
        return value + "x"
    if isinstance(value, np.ndarray) and value.dtype.kind == "f" and value.size:
        out = value.copy()
        out.flat[-1] = np.nextafter(out.flat[-1], np.inf)
        return out
    return None


@pytest.fixture(scope="module")
def crowd():
    from puppetphone.bench.state_hash import crowd_app

    return crowd_app(puppets=3, steps=30).world


def test_packed_hash_sees_every_change_the_field_by_field_one_sees(crowd):
    """Every hashed scalar or float-array field of every component, nudged by one ulp (or one),
    changes both hashes; put back, both return to what they were."""
    from puppetphone.bench.state_hash import field_by_field_hash

    w = crowd
    h0, r0 = state_hash(w), field_by_field_hash(w)
    nudged = 0
    for e in w.entities():
        for comp in w.components_of(e):
            if not getattr(comp, "SIM_STATE", True) or not dataclasses.is_dataclass(comp):
                continue
            for f in dataclasses.fields(comp):
                old = getattr(comp, f.name)
                new = _nudged(old)
                if new is None:
                    continue
                setattr(comp, f.name, new)
                changed = (state_hash(w) != h0, field_by_field_hash(w) != r0)
                setattr(comp, f.name, old)
                assert changed[0] == changed[1] == f.metadata.get("hash", True), (type(comp).__name__, f.name)
                nudged += 1
    assert nudged > 100
    assert (state_hash(w), field_by_field_hash(w)) == (h0, r0)


def test_packed_hash_keeps_exact_bits_and_mixed_columns(crowd):
    w = crowd
    before = state_hash(w)
    e = w.spawn(Tagged(kept=0.0), Wander())
    h0 = state_hash(w)
    w.get(e, Tagged).kept = -0.0  # equal as a number, other bits
    assert state_hash(w) != h0
    w.get(e, Tagged).kept = 0.0
    assert state_hash(w) == h0
    w.get(e, Wander).speed = np.array([1.0])  # a column of floats and one array: hashed value by value
    h1 = state_hash(w)
    w.get(e, Wander).speed = np.array([2.0])
    assert len({h0, h1, state_hash(w)}) == 3
    w.despawn(e)
    assert state_hash(w) == before
    empty = w.spawn()  # an entity with no component still counts
    assert state_hash(w) != before
    w.despawn(empty)
