"""Replay: recorded ``InputFrame``s fed back through the hub, and hash verification.

A :class:`ReplaySource` is just another input backend (STYLE: replay is an input
backend): the hub asks it for the frame of each step index. :func:`verify` rebuilds
the app through a factory, steps it once per recorded frame and compares every
``state_hash``; the first frame that differs is named.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from engine.app import App
from engine.ecs import World
from engine.hashing import part_digests
from input.hub import InputHub
from input.recording import Recording, read_recording
from input.sample import InputFrame, SourceStatus

__all__ = ["ReplaySource", "HashCheck", "verify", "replay_hub", "differing_parts"]


class ReplaySource:
    """Supplies the recorded frame for each step index (``None`` past the end)."""

    threaded = False

    def __init__(self, recording: Recording | str | Path) -> None:
        self.recording = recording if isinstance(recording, Recording) else read_recording(recording)
        self.name = "replay"
        self._by_index = {f.frame: f for f in self.recording.frames}
        self.served = 0

    @property
    def last_frame(self) -> int:
        """Index of the last recorded frame (−1 for an empty recording)."""
        return max(self._by_index, default=-1)

    def frame_at(self, index: int) -> InputFrame | None:
        """The recorded frame for step ``index``."""
        f = self._by_index.get(index)
        if f is not None:
            self.served += 1
        return f

    def status(self) -> SourceStatus:
        """Replay progress, for the overlay."""
        return SourceStatus(name=self.name, connected=True, packets=self.served)


def replay_hub(recording: Recording | str | Path) -> InputHub:
    """A hub that feeds a recording (``--source replay:FILE``)."""
    return InputHub(replay=ReplaySource(recording))


def differing_parts(recorded: dict[str, bytes], replayed: dict[str, bytes]) -> list[str]:
    """Names of the state parts whose digests differ (or exist on one side only), recorded order first."""
    names = list(recorded) + [n for n in replayed if n not in recorded]
    return [n for n in names if recorded.get(n) != replayed.get(n)]


@dataclass
class HashCheck:
    """Compares each finished step's state hash with a recording's (an ``App.on_step_end`` observer).

    At the first difference it keeps the frame, both hashes and the names of the state
    parts (component types, resources) whose digests differ, and checks nothing more.
    """

    recording: Recording
    frames: int = 0
    matched: int = 0
    first_mismatch: int | None = None
    expected: str = ""
    got: str = ""
    differing: list[str] = field(default_factory=list)

    def __call__(self, world: World) -> None:
        index = world.frame - 1
        if self.first_mismatch is None and index < len(self.recording.hashes):
            self.check(index, *part_digests(world))

    def check(self, index: int, digest: str, parts: dict[str, bytes]) -> None:
        """Compare step ``index``'s hash and parts (for states that are not a world: the authoring scenes)."""
        if self.first_mismatch is not None or index >= len(self.recording.hashes):
            return
        self.frames += 1
        if digest == self.recording.hashes[index]:
            self.matched += 1
            return
        self.first_mismatch, self.expected, self.got = index, self.recording.hashes[index], digest
        if index < len(self.recording.parts):
            self.differing = differing_parts(self.recording.parts[index], parts)

    @property
    def ok(self) -> bool:
        """Whether every hash checked so far matched."""
        return self.first_mismatch is None

    def message(self) -> str:
        """The verification line: all matched, or the frame, what differs there and both hashes."""
        if self.ok:
            return f"replayed {self.frames} frames, all {self.matched} state hashes match"
        what = f" in {', '.join(self.differing)}" if self.differing else ""
        return (
            f"state hash differs at frame {self.first_mismatch}{what} (after {self.matched} matching): "
            f"expected {self.expected}, got {self.got}"
        )


def verify(
    make_app: Callable[[InputHub], App], recording: Recording, on_step: Callable[[App, int], None] | None = None
) -> HashCheck:
    """Rebuild the app with a replay hub, step it once per recorded frame, compare every hash.

    Args:
        make_app: builds the app from the hub (same game, seed and dt as recorded).
        recording: what to replay.
        on_step: called after each step (rendering a screenshot, progress).
    """
    app = make_app(InputHub(replay=ReplaySource(recording)))
    check = HashCheck(recording)
    app.on_step_end.append(check)
    for i, frame in enumerate(recording.frames):
        if app.world.frame != frame.frame:
            check.first_mismatch, check.expected = frame.frame, recording.hashes[i]
            check.got = f"world at frame {app.world.frame}"
            break
        app.step()
        if on_step is not None:
            on_step(app, i)
        if not check.ok:
            break
    return check
