"""One session shape for every game and authoring tool: the runner's activity.

A :class:`Session` holds a :class:`Simulation` (a game's app, or a tool beside its scene
in ``authoring/``) and does the same thing for all of them, each fixed step:

1. the window's events, turned into operations by :mod:`authoring.bindings` (or a script's
   operations), go into the input hub as tool events;
2. the hub gives this step's :class:`~input.sample.InputFrame` (live, or recorded in a replay);
3. its tool events are decoded in one place (:func:`authoring.operations.decode`) and applied;
4. the simulation steps with the frame;
5. the step is recorded (``--record``) or checked against a recording (``replay --verify``) with
   its state hash (computed only then: hashing every component of a big world costs more than
   stepping it);
6. the session says when it ends: a replay ran out, a hash differed, or the simulation ended.

So every session records and replays alike, with no special case: a tool is one module
(its :class:`Simulation` and a :class:`ToolKind` that opens it from options or from a
recording's set-up) plus its registration (``puppetphone.registry``).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol

from authoring.bindings import Bindings
from authoring.operations import Key, Operation, decode, encode
from engine.camera import Camera
from engine.render.scene import RenderScene
from input.hub import InputHub
from input.recording import Recorder, Recording, RecordingHeader
from input.replay import HashCheck, ReplaySource
from input.sample import InputFrame

__all__ = [
    "Ending",
    "KeyUse",
    "Opened",
    "Script",
    "Session",
    "Simulation",
    "ToolKind",
    "ToolSimulation",
    "tool_session",
]

#: What a simulation does with a key (:meth:`Simulation.on_key`).
KeyUse = Literal["queue", "done", "pass"]
#: A script: the operations of each step, as recorded tuples (``["press", x, y, False]``).
Script = Iterator[list[list[object]]]


class Simulation(Protocol):
    """What a session steps: a game's app or a tool's scene."""

    dt: float

    @property
    def camera(self) -> Camera:
        """The camera the runner draws with."""
        ...

    def on_key(self, key: Key, hub: InputHub) -> KeyUse:
        """A key: ``queue`` it as a recorded operation, ``done`` (handled now: a game's command goes
        into the hub, a help toggle is not simulation), or ``pass`` it to the runner (P pauses, G quality)."""
        ...

    def apply(self, op: Operation) -> None:
        """One recorded operation of this step (``ValueError``: it does not fit)."""
        ...

    def advance(self, frame: InputFrame) -> None:
        """One fixed step with this step's input."""
        ...

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """The state hash after the step and its named parts."""
        ...

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """Fill ``scene`` with the current state."""
        ...

    def ready(self) -> bool:
        """Whether it can step (a tool may still be building; its input waits in the hub)."""
        ...

    def ended(self) -> bool:
        """Whether it has ended on its own (a build failed)."""
        ...

    def close(self) -> None:
        """Release what it holds (devices are the hub's)."""
        ...


@dataclass
class Ending:
    """What a live tool session leaves: lines for the terminal and the exit code."""

    lines: list[str] = field(default_factory=list)
    code: int = 0


@dataclass
class Opened:
    """A live tool session just opened: its simulation, the set-up a recording keeps, its script."""

    simulation: Any
    setup: dict[str, object]
    script: Script | None = None
    conclude: Callable[[], Ending] = Ending


@dataclass(frozen=True)
class ToolKind:
    """An authoring tool as the registry knows it.

    Args:
        name: the name a recording gives as its game (``author-edit``).
        title: the window title.
        open: a live session from the tool's options and the window size (``ValueError``/``OSError``: say it).
        reopen: the recorded session from its header's set-up alone (never a file it names).
        dt: the fixed step.
    """

    name: str
    title: str
    open: Callable[[Mapping[str, Any], tuple[int, int]], Opened]
    reopen: Callable[[object], Any]
    dt: float = 1.0 / 60.0


class Session:
    """One session of a game or a tool (see the module docstring); the runner's activity and event layer.

    Args:
        simulation: what steps.
        hub: the input (live sources, or a replay's recorded frames).
        pointer_acts: whether the left button and the wheel are the simulation's operations (a
            tool) or the mouse source's (a game: they drive the stick).
        recorder: writes every step (``--record``).
        check: compares every step's hash with a recording's (a replay).
        script: operations per step instead of a hand (the window's pointer and keys are then ignored).
    """

    def __init__(
        self,
        simulation: Any,
        hub: InputHub,
        *,
        pointer_acts: bool = True,
        recorder: Recorder | None = None,
        check: HashCheck | None = None,
        script: Script | None = None,
    ) -> None:
        self.simulation = simulation
        self.hub = hub
        self.recorder = recorder
        self.check = check
        self.script = script
        self.bindings = Bindings(pointer_acts)
        self.frame = 0
        self.dt: float = simulation.dt

    @property
    def camera(self) -> Camera:
        """The simulation's camera."""
        return self.simulation.camera

    @property
    def input_wake(self) -> threading.Event | None:
        """Set when a live reading arrives: the paced runner starts the step early for it (none in a replay)."""
        return self.hub.arrived if self.hub.replay is None else None

    def record(self, path: Path, name: str, seed: int, setup: dict[str, object], source: str) -> Recorder:
        """Record from now on to ``path`` (an existing file is replaced); the header names the game or tool."""
        self.recorder = Recorder(path, RecordingHeader(game=name, seed=seed, dt=self.dt, sources=[source], setup=setup))
        return self.recorder

    def verify(self, recording: Recording) -> HashCheck:
        """Check every step against ``recording``."""
        self.check = HashCheck(recording)
        return self.check

    def on_event(self, ev: Any, runner: Any) -> bool:
        """A window event: an operation queued for the next step (true), or left to the layers below."""
        import pygame

        size = runner.size if runner is not None else (0, 0)
        if (
            self.script is not None
            and ev.type
            in (pygame.MOUSEBUTTONDOWN, pygame.MOUSEBUTTONUP, pygame.MOUSEMOTION, pygame.MOUSEWHEEL, pygame.KEYDOWN)
            and getattr(ev, "key", None) != pygame.K_ESCAPE
        ):
            return True  # a script is the hand: the real pointer (a window opening under it) must not join in
        op = self.bindings.operation(ev, size)
        if op is None:
            return self._to_sources(ev, runner)
        if isinstance(op, Key):
            use = self.simulation.on_key(op, self.hub)
            if use != "queue":
                return use == "done"
        if self.hub.replay is None:
            self.bindings.queue(op)
        return True

    def _to_sources(self, ev: Any, runner: Any) -> bool:
        """A game: the left button and the wheel go to the sources that read the pointer (the mouse)."""
        used = False
        for source in self.hub.sources:
            handle = getattr(source, "handle_event", None)
            if handle is not None and runner is not None:
                used = bool(handle(ev, self.camera, runner.size)) or used
        return used

    def step(self) -> None:
        """One fixed step (see the module docstring)."""
        sim = self.simulation
        if not sim.ready():
            return  # still building: what was typed stays queued for the first real step
        if self.script is not None:
            for scripted in next(self.script, []):
                self.bindings.queue(decode(scripted))
        for op in self.bindings.take():
            self.hub.tool(*encode(op))
        frame = self.hub.drain(self.frame)
        for raw in frame.tool_operations():
            sim.apply(decode(raw))
        sim.advance(frame)
        if self.recorder is not None or self.check is not None:
            # Hashed only for a recording or a check: 2.3 ms a step in play snowman, 55 ms with 1000 puppets.
            digest, parts = sim.digest()
            if self.recorder is not None:
                self.recorder.write(frame, digest, parts)
            if self.check is not None:
                self.check.check(self.frame, digest, parts)
        self.frame += 1

    def finished(self) -> bool:
        """A replay ends after its last recorded step or at the first differing hash; a simulation may end itself."""
        if self.check is not None and not self.check.ok:
            return True
        if self.simulation.ended():
            return True
        replay = self.hub.replay
        return isinstance(replay, ReplaySource) and self.frame > replay.last_frame  # (the hub's only frame source)

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The simulation's drawing."""
        self.simulation.draw(scene, alpha, size)

    def close(self) -> None:
        """Stop the devices, let the simulation release what it holds, close the recording (already flushed)."""
        self.hub.close()
        self.simulation.close()
        if self.recorder is not None:
            self.recorder.close()


def tool_session(kind: ToolKind, recording: Recording, hub: InputHub) -> Session:
    """The recorded session of a tool, rebuilt from the recording alone and checked at every step."""
    session = Session(kind.reopen(recording.header.setup), hub)
    session.verify(recording)
    return session


class ToolSimulation:
    """Defaults a tool's simulation shares: 60 Hz, every key but P (the runner's pause), always ready."""

    dt = 1.0 / 60.0

    def on_key(self, key: Key, hub: InputHub) -> KeyUse:
        """Every key is the tool's but a plain P (pause)."""
        return "pass" if key.name == "p" and not key.ctrl else "queue"

    def ready(self) -> bool:
        """A tool is ready at once unless it says otherwise."""
        return True

    def ended(self) -> bool:
        """A tool ends when its window closes, unless it says otherwise."""
        return False

    def close(self) -> None:
        """Nothing held by default."""
