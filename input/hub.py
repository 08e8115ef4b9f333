"""The input hub: once per fixed step, every source's queue becomes one :class:`InputFrame`.

The hub is where the non-deterministic world (threads, sockets, wall time) meets
the deterministic one. It

- drains each source in registration order, keeping samples in arrival order;
- coalesces floods: per source at most ``max_samples`` samples per step survive
  (the newest, plus any sample that changes touch, flicks or asks to calibrate), the
  rest are counted as coalesced, so a burst never costs the step more than a bounded
  time; what adds up is kept: their wheel notches move to the next kept sample;
- turns touch transitions into ``touch_down`` / ``touch_up`` events;
- round-trips the frame through :mod:`input.codec`, so the live simulation reads
  exactly the bits a recording stores and a replay will feed back.

With a *frame source* (a :class:`input.replay.ReplaySource`) the hub returns the
recorded frame for each index instead of draining live sources.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from dataclasses import replace
from typing import Protocol

from input.codec import decode_frame, encode_frame
from input.sample import COMMANDS, LIMITS, TOOL, TOUCH_DOWN, TOUCH_UP, InputFrame, PoseSample, SourceStatus, encode_tool
from input.source import PoseSource

__all__ = ["InputHub", "FrameSource"]

_MAX_FRAME = 0xFFFFFFFF  # the codec stores a frame number as u32


class FrameSource(Protocol):
    """A source that supplies whole recorded frames by index (replay)."""

    name: str

    def frame_at(self, index: int) -> InputFrame | None: ...

    def status(self) -> SourceStatus: ...


class InputHub:
    """Collects sources and produces one :class:`InputFrame` per step.

    Args:
        sources: live sources (started by :meth:`start`).
        replay: a frame source; when given, live sources are ignored.
        max_samples: per source and step, how many pose samples are kept.
    """

    def __init__(
        self, sources: Iterable[PoseSource] = (), replay: FrameSource | None = None, max_samples: int = 8
    ) -> None:
        self.sources: list[PoseSource] = list(sources)
        # Set whenever a live source queues a reading: a paced loop may start the step early for it.
        self.arrived = threading.Event()
        for source in self.sources:
            source.arrived = self.arrived
        self.replay = replay
        self.max_samples = max_samples
        self.coalesced = 0
        self._touch: dict[str, bool] = {}
        self._commands: list[str] = []
        self._tools: list[str] = []
        self.last_frame = InputFrame()

    def tool(self, *operation: str | int | float | bool) -> None:
        """Queue an authoring tool's operation (a name and its arguments) for the next step's frame.

        Ignored while replaying: the recording has its own."""
        text = encode_tool(operation)
        if self.replay is None:
            self._tools.append(text)

    def command(self, kind: str) -> None:
        """Queue a keyboard command (:data:`~input.sample.COMMANDS`) for the next step's frame,
        where it is recorded like any input. Ignored while replaying: the recording has its own."""
        if kind not in COMMANDS:
            raise ValueError(f"unknown command {kind!r}; commands are {', '.join(COMMANDS)}")
        if self.replay is None:
            self._commands.append(kind)

    @property
    def live(self) -> bool:
        """Whether frames come from live devices or a person's mouse (the game loop then paces to real time).

        A source fed by a script from the main thread (a test's, a bench's) is not live: it runs flat out.
        """
        return self.replay is None and any(s.threaded or s.person for s in self.sources)

    def add(self, source: PoseSource) -> PoseSource:
        """Register another live source."""
        self.sources.append(source)
        source.arrived = self.arrived
        return source

    def start(self) -> InputHub:
        """Start every live source's device thread."""
        for s in self.sources:
            s.start()
        return self

    def close(self) -> None:
        """Stop every source."""
        for s in self.sources:
            s.stop()

    def statuses(self) -> list[SourceStatus]:
        """Status of every source, for the overlay."""
        out = [s.status() for s in self.sources]
        if self.replay is not None:
            out.insert(0, self.replay.status())
        return out

    def drain(self, frame: int) -> InputFrame:
        """The input for step ``frame``."""
        if self.replay is not None:
            recorded = self.replay.frame_at(frame)
            self.last_frame = recorded if recorded is not None else InputFrame(frame=frame)
            return self.last_frame
        samples: list[PoseSample] = []
        events: list[tuple[str, str]] = []
        for source in self.sources:
            items = source.drain()
            pose = [i for i in items if isinstance(i, PoseSample)]
            events += [i for i in items if not isinstance(i, PoseSample)]
            samples += self._coalesce(pose)
        for s in samples:
            if s.touch is not None and s.touch != self._touch.get(s.source, False):
                events.append((TOUCH_DOWN if s.touch else TOUCH_UP, s.source))
                self._touch[s.source] = s.touch
        for kind, src in events:
            if kind == "disconnect" and self._touch.pop(src, False):
                events.append((TOUCH_UP, src))
        events += [(kind, "keys") for kind in self._commands]
        events += [(TOOL, operation) for operation in self._tools]
        self._commands.clear()
        self._tools.clear()
        if not samples and not events and type(frame) is int and 0 <= frame <= _MAX_FRAME:
            # A step with no input (every step of a crowd nobody holds): the codec would give back
            # this very frame, so the round trip is skipped (a frame number it cannot store still takes it).
            self.last_frame = InputFrame(frame=frame)
            return self.last_frame
        live = InputFrame(frame=frame, samples=tuple(samples), events=tuple(events))
        self.last_frame = decode_frame(encode_frame(live))
        return self.last_frame

    def _coalesce(self, pose: list[PoseSample]) -> list[PoseSample]:
        """At most ``max_samples`` per source and step, losing nothing that adds up: dropped
        samples' wheel notches (``depth_delta``) move to the next kept sample of their source."""
        if len(pose) <= self.max_samples:
            return pose
        keep = set(range(len(pose) - self.max_samples, len(pose)))
        last_touch: dict[str, bool | None] = {}
        for i, s in enumerate(pose):
            if s.calibrate or s.flick or (s.touch is not None and s.touch != last_touch.get(s.source)):
                keep.add(i)
            if s.touch is not None:
                last_touch[s.source] = s.touch
        self.coalesced += len(pose) - len(keep)
        out: list[PoseSample] = []
        carried: dict[str, float] = {}
        for i, s in enumerate(pose):
            if i not in keep:
                carried[s.source] = carried.get(s.source, 0.0) + s.depth_delta
                continue
            extra = carried.pop(s.source, 0.0)
            total = min(max(s.depth_delta + extra, -LIMITS["depth_delta"]), LIMITS["depth_delta"])
            out.append(replace(s, depth_delta=total) if extra else s)
        return out
