"""``App``: plugins nest and install once, a system is never scheduled twice."""

import pytest

from engine.app import App, configured
from engine.blend import animate, install_blend
from engine.posing import fk_system, install_fk
from engine.ragdoll import PhysicsWorld, install_physics
from engine.statemachine.puppet import install_puppets


def _all_systems(app):
    return [
        s
        for stage in ("input", "stick", "statemachine", "animation", "ik", "physics", "fk", "rules", "hash")
        for s in app.systems(stage)
    ]


def test_plugins_that_install_each_other_run_each_system_once():
    app = App(plugins=[install_puppets, install_blend, install_fk])
    assert app.systems("animation").count(animate) == 1
    assert app.systems("fk") == [fk_system]
    systems = _all_systems(app)
    assert len(systems) == len(set(systems))
    assert app.plugins == [
        "engine.statemachine.puppet.plugin.install_puppets",
        "engine.blend.puppet.install_puppet_locomotion",
        "engine.blend.locomotion.install_blend",
        "engine.ik.system.install_ik",
        "engine.ragdoll.system.install_physics",
        "engine.posing.install_fk",
    ]


def test_a_plugin_asked_for_twice_installs_once():
    calls = []

    def counting(app):
        calls.append(app)
        app.add_plugin(counting)  # a cycle stops at the plugin being installed

    app = App(plugins=[counting])
    app.add_plugin(counting)
    assert calls == [app]


def test_add_system_refuses_a_duplicate_in_any_stage():
    app = App()
    app.add_system("fk", fk_system)
    with pytest.raises(ValueError, match="fk_system is already in stage 'fk'"):
        app.add_system("fk", fk_system)
    with pytest.raises(ValueError, match="already in stage 'fk'"):
        app.add_system("rules", fk_system)
    with pytest.raises(ValueError, match="unknown stage"):
        app.add_system("render", animate)


def test_a_configured_plugin_meets_a_dependency_on_its_bare_function():
    app = App(plugins=[configured(install_physics, substeps=4), install_puppets])
    assert app.world.resource(PhysicsWorld).substeps == 4
    assert app.plugins.count("engine.ragdoll.system.install_physics") == 1
    app.add_plugin(configured(install_physics, substeps=4))  # the same configuration again: nothing to do
    with pytest.raises(ValueError, match="already installed"):
        app.add_plugin(configured(install_physics, substeps=2))
