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
9. ``hash``         — observers of the finished step (the recorder writes the frame
                      and ``state_hash``).

Rendering is not a stage: it runs as often as the window allows, reads the last two
simulated states and interpolates between them with the clock's ``alpha``; it never
writes simulation state. Plugins are plain callables ``install(app)`` that add
resources and systems (STYLE: a feature is a plugin).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from engine.clock import FixedStepClock
from engine.ecs import World

__all__ = ["App", "Plugin", "System", "STAGES"]

STAGES: tuple[str, ...] = ("input", "stick", "statemachine", "animation", "ik", "physics", "fk", "rules", "hash")

System = Callable[[World], None]
Plugin = Callable[["App"], None]


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
        self._installed: list[str] = []
        self.on_step_end: list[Callable[[World], None]] = []
        for plugin in plugins:
            self.add_plugin(plugin)

    def add_plugin(self, plugin: Plugin) -> App:
        """Install a plugin once (a second install of the same one is ignored)."""
        name = f"{plugin.__module__}.{getattr(plugin, '__qualname__', repr(plugin))}"
        if name not in self._installed:
            self._installed.append(name)
            plugin(self)
            self.world.flush()
        return self

    def add_system(self, stage: str, system: System, *, before: System | None = None) -> App:
        """Register a system in a named stage (optionally ahead of another one there)."""
        if stage not in self._systems:
            raise ValueError(f"unknown stage {stage!r}; stages are {', '.join(STAGES)}")
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
        """Installed plugin names, in install order."""
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

    def tick(self, elapsed: float) -> int:
        """Advance the clock by real ``elapsed`` seconds and run the steps it yields."""
        steps = self.clock.advance(elapsed)
        for _ in range(steps):
            self.step()
        return steps
