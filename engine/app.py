"""The app: a world, the plugins that fill it, and the one frame schedule.

Frame schedule
==============
The simulation advances in fixed steps (60 Hz by default, see
:class:`engine.clock.FixedStepClock`). Each step runs these stages in order; every
stage's systems run in the order they were added, and deferred spawns/despawns are
applied (``World.flush``) between stages:

1. ``input``        — the input hub drains device queues into one ``InputFrame``; the
                      only non-deterministic boundary, so it is what recordings store.
2. ``stick``        — the MotionStick turns controller poses into a ``Stick``: tip,
                      grab/release, filtered velocity, shortening at the ground.
3. ``statemachine`` — each puppet's active state reads the stick and surroundings and
                      writes an animation request (blend parameters, IK targets,
                      ragdoll weight); events switch states.
4. ``animation``    — blend spaces and clips give each puppet a local pose and root motion.
5. ``ik``           — feet on the ground, hands on a snowball, any target a state asked for.
6. ``physics``      — ragdolls and props step in the physics engine; active ragdolls
                      track the animated pose; animated and simulated poses blend.
7. ``fk``           — world transforms for every joint, batched over puppets.
8. ``rules``        — game rules: snowball growth, snowman assembly, quest milestones.
9. ``hash``         — systems that observe the finished step before the frame counter
                      moves on (a game's save of its progress, say).

After the last stage ``world.frame`` is incremented, then the ``on_step_end``
callbacks run: the recorder (:meth:`input.recording.Recorder.attach`) writes the
step's ``InputFrame`` and its ``state_hash`` there, so a recorded hash covers the
whole step including the new frame number.

Rendering is not a stage: it runs as often as the window allows, reads the last two
simulated states and interpolates between them with the clock's ``alpha``; it never
writes simulation state.

Plugins
=======
A plugin is a callable ``install(app)`` that adds resources and systems (STYLE: a
feature is a plugin). A plugin that needs another one asks for it with
:meth:`App.add_plugin`, never by calling it: each plugin is installed once, known by
its name (:func:`plugin_name`), so plugins nest and a system is never registered
twice. A plugin that takes parameters is wrapped with :func:`configured`; its name
is its install function's, so a dependency on the bare function is met by any
configuration of it, while two different configurations of one plugin conflict.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from engine.clock import FixedStepClock
from engine.ecs import World

__all__ = ["App", "Configured", "Plugin", "System", "STAGES", "configured", "plugin_name", "system_name"]

STAGES: tuple[str, ...] = ("input", "stick", "statemachine", "animation", "ik", "physics", "fk", "rules", "hash")

System = Callable[[World], None]
Plugin = Callable[["App"], None]


def _qualified(obj: Any) -> str:
    return f"{getattr(obj, '__module__', type(obj).__module__)}.{getattr(obj, '__qualname__', type(obj).__qualname__)}"


def plugin_name(plugin: Plugin) -> str:
    """A plugin's identity: its ``name`` if it has one (:class:`Configured`), else its qualified name."""
    name = getattr(plugin, "name", None)
    return name if isinstance(name, str) else _qualified(plugin)


def system_name(system: System) -> str:
    """A system's qualified name (``module.function``), as ``puppetphone schedule`` prints it."""
    return _qualified(system)


@dataclass(frozen=True)
class Configured:
    """A plugin with parameters: calls ``install(app, **params)``.

    Its name is ``install``'s, so a plugin that only needs the feature (asks for the
    bare function) is satisfied by whichever configuration came first.
    """

    install: Callable[..., None]
    params: tuple[tuple[str, Any], ...]

    @property
    def name(self) -> str:
        """The install function's qualified name."""
        return _qualified(self.install)

    def __call__(self, app: App) -> None:
        self.install(app, **dict(self.params))


def configured(install: Callable[..., None], **params: Any) -> Configured:
    """``install`` bound to keyword parameters, as a plugin (``configured(install_physics, substeps=4)``)."""
    return Configured(install, tuple(sorted(params.items())))


class App:
    """Owns the world, the schedule and the clock; games are lists of plugins.

    Args:
        seed: the world's RNG seed.
        dt: fixed step in seconds.
        plugins: installed in order.
    """

    def __init__(self, seed: int = 0, dt: float = 1.0 / 60.0, plugins: Iterable[Plugin] = ()) -> None:
        self.world = World(seed=seed, dt=dt)
        self.clock = FixedStepClock(dt=dt)
        self.world.insert_resource(self.clock)
        self._systems: dict[str, list[System]] = {s: [] for s in STAGES}
        self._installed: dict[str, Plugin] = {}
        self.on_step_end: list[Callable[[World], None]] = []
        for plugin in plugins:
            self.add_plugin(plugin)

    def add_plugin(self, plugin: Plugin) -> App:
        """Install a plugin unless one of that name is installed (or being installed).

        Plugins nest: an install may call ``app.add_plugin`` for what it depends on.
        Asking again for an installed plugin, or for the bare function of an installed
        :class:`Configured` one, does nothing.

        Raises:
            ValueError: a :class:`Configured` plugin whose name is installed with other parameters.
        """
        name = plugin_name(plugin)
        installed = self._installed.get(name)
        if installed is None:
            self._installed[name] = plugin  # before installing, so a cycle stops here
            plugin(self)
            self.world.flush()
        elif isinstance(plugin, Configured) and plugin != installed:
            raise ValueError(f"plugin {name} is already installed as {installed!r}, not {plugin!r}")
        return self

    def add_system(self, stage: str, system: System, *, before: System | None = None) -> App:
        """Register a system in a named stage (optionally ahead of another one there).

        Raises:
            ValueError: an unknown stage, or a system already in the schedule (it would run twice a step).
        """
        if stage not in self._systems:
            raise ValueError(f"unknown stage {stage!r}; stages are {', '.join(STAGES)}")
        for other, registered in self._systems.items():
            if system in registered:
                raise ValueError(f"system {system_name(system)} is already in stage {other!r}")
        systems = self._systems[stage]
        if before is not None and before in systems:
            systems.insert(systems.index(before), system)
        else:
            systems.append(system)
        return self

    def systems(self, stage: str) -> list[System]:
        """The systems of a stage, in run order."""
        return list(self._systems[stage])

    @property
    def plugins(self) -> list[str]:
        """Installed plugin names, in the order their installs began (a plugin before its dependencies)."""
        return list(self._installed)

    def step(self) -> None:
        """Run one fixed simulation step through every stage."""
        world = self.world
        for stage in STAGES:
            for system in self._systems[stage]:
                system(world)
            world.flush()
        world.frame += 1
        for callback in self.on_step_end:
            callback(world)

    def run_steps(self, n: int) -> None:
        """Run ``n`` steps back to back (tests, headless replays)."""
        for _ in range(n):
            self.step()
