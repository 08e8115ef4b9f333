"""World: entity order, cached queries, deferred structural changes, resources."""

from dataclasses import dataclass

import pytest

from engine.app import STAGES, App
from engine.ecs import World


@dataclass
class Pos:
    x: float


@dataclass
class Vel:
    v: float


def test_query_in_entity_order_and_cache_invalidation():
    w = World()
    a = w.spawn(Pos(1), Vel(1))
    b = w.spawn(Pos(2))
    c = w.spawn(Pos(3), Vel(3))
    assert [r[0] for r in w.query(Pos, Vel)] == [a, c]
    first = w.query(Pos, Vel)
    assert w.query(Pos, Vel) is first  # cached
    w.add(b, Vel(2))
    assert [r[0] for r in w.query(Pos, Vel)] == [a, b, c]
    w.remove(a, Vel)
    assert [r[0] for r in w.query(Pos, Vel)] == [b, c]
    w.despawn(c)
    assert [r[0] for r in w.query(Pos)] == [a, b]
    assert not w.alive(c)


def test_deferred_changes_wait_for_flush():
    w = World()
    a = w.spawn(Pos(1))
    spawned = []
    for e, p in w.query(Pos):
        w.queue_spawn(Pos(p.x + 10), on_spawn=spawned.append)
        w.queue_despawn(e)
    assert [r[0] for r in w.query(Pos)] == [a]
    assert w.flush() == 2
    assert [r[0] for r in w.query(Pos)] == spawned
    assert w.get(spawned[0], Pos).x == 11


def test_entity_ids_never_reused():
    w = World()
    a = w.spawn()
    w.despawn(a)
    assert w.spawn() > a


def test_missing_component_and_resource_errors_are_clear():
    w = World()
    e = w.spawn()
    with pytest.raises(KeyError, match="has no Pos"):
        w.get(e, Pos)
    with pytest.raises(KeyError, match="plugin"):
        w.resource(Vel)
    w.insert_resource(Vel(4))
    assert w.resource(Vel).v == 4


def test_app_runs_stages_in_schedule_order_and_flushes_between():
    order = []
    app = App()
    for stage in reversed(STAGES):
        app.add_system(stage, lambda world, s=stage: order.append(s))

    def spawner(world):
        world.queue_spawn(Pos(0))

    def counter(world):
        order.append(("seen", len(world.query(Pos))))

    app.add_system("input", spawner)
    app.add_system("stick", counter)
    app.step()
    assert [o for o in order if isinstance(o, str)] == list(STAGES)
    assert ("seen", 1) in order  # the spawn from "input" was flushed before "stick"
    assert app.world.frame == 1


def test_unknown_stage_is_refused():
    with pytest.raises(ValueError, match="unknown stage"):
        App().add_system("render", lambda w: None)


def test_plugin_installed_once():
    calls = []

    def plugin(app):
        calls.append(1)

    app = App(plugins=[plugin])
    app.add_plugin(plugin)
    assert calls == [1]


def test_component_types_are_the_ones_in_use_by_name():
    w = World()
    e = w.spawn(Vel(1), Pos(2))
    assert w.component_types() == [Pos, Vel]
    w.remove(e, Pos)
    assert w.component_types() == [Vel]


def test_components_is_a_live_read_only_view_of_one_type() -> None:
    """``World.components`` sees adds and removals and cannot be written through."""
    world = World()
    seen = world.components(int)
    e = world.spawn(5)
    assert seen.get(e) == 5 and len(seen) == 1
    world.remove(e, int)
    assert seen.get(e) is None
    with pytest.raises(TypeError):
        seen[e] = 3  # type: ignore[index]  # the view is read-only: this is what is tested
