"""The input plugin: the hub drain in the ``input`` stage, the MotionStick in ``stick``.

Usage::

    hub = InputHub([OscSource(port=9000)]).start()
    app = App(seed=1, plugins=[engine_plugins..., input_plugin(hub)])

or ``app.add_plugin(input_plugin(hub))``. It inserts the :class:`InputFrame`
resource (hashed: it is what recordings store), a :class:`StickConfig`, and one
controller entity per stick (``sticks`` bindings, default one stick bound to the
first source that speaks).
"""

from __future__ import annotations

from collections.abc import Sequence

from engine.app import App, Configured, configured
from engine.ecs import World
from input.hub import InputHub
from input.motionstick import StickConfig, motionstick_system, spawn_stick
from input.sample import InputFrame

__all__ = ["install_input", "input_plugin", "HubResource"]


class HubResource:
    """Holds the hub in the world so systems can reach it; not simulation state."""

    SIM_STATE = False

    def __init__(self, hub: InputHub) -> None:
        self.hub = hub


def _drain_system(world: World) -> None:
    """The ``input`` stage: this step's frame from the hub becomes the ``InputFrame`` resource."""
    world.insert_resource(world.resource(HubResource).hub.drain(world.frame))


def install_input(app: App, hub: InputHub, sticks: Sequence[str] = ("*",), config: StickConfig | None = None) -> None:
    """Add the hub drain, the MotionStick system, their resources and the stick entities."""
    world = app.world
    world.insert_resource(HubResource(hub))
    world.insert_resource(InputFrame(frame=world.frame))
    world.insert_resource(config or StickConfig())
    for binding in sticks:
        spawn_stick(world, binding)
    app.add_system("input", _drain_system)
    app.add_system("stick", motionstick_system)


def input_plugin(hub: InputHub, sticks: Sequence[str] = ("*",), config: StickConfig | None = None) -> Configured:
    """``install_input`` bound to its hub, as a plugin for ``App(plugins=[...])`` or ``app.add_plugin``.

    Its name is ``input.plugin.install_input``: an app has one input hub.
    """
    return configured(install_input, hub=hub, sticks=tuple(sticks), config=config)
