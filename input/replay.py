"""Replay: recorded ``InputFrame``s fed back through the hub, and hash verification.

A :class:`ReplaySource` is just another input backend (STYLE: replay is an input
backend): the hub asks it for the frame of each step index. :func:`verify` rebuilds
the app through a factory, steps it once per recorded frame and compares every
``state_hash``; the first frame that differs is named.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from engine.app import App
from engine.hashing import state_hash
from input.hub import InputHub
from input.recording import Recording, read_recording
from input.sample import InputFrame, SourceStatus

__all__ = ["ReplaySource", "ReplayResult", "verify", "replay_hub"]


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


@dataclass
class ReplayResult:
    """Outcome of :func:`verify`."""

    frames: int
    matched: int
    first_mismatch: int | None = None
    expected: str = ""
    got: str = ""

    @property
    def ok(self) -> bool:
        """Whether every replayed hash matched."""
        return self.first_mismatch is None

    def message(self) -> str:
        """The line the replay command prints."""
        if self.ok:
            return f"replayed {self.frames} frames, all {self.matched} state hashes match"
        return (f"state hash differs at frame {self.first_mismatch} (after {self.matched} matching): "
                f"expected {self.expected}, got {self.got}")


def verify(make_app: Callable[[InputHub], App], recording: Recording,
           on_step: Callable[[App, int], None] | None = None) -> ReplayResult:
    """Rebuild the app with a replay hub and compare every step's state hash.

    Args:
        make_app: builds the app from the hub (same game, seed and dt as recorded).
        recording: what to replay.
        on_step: called after each step (rendering a screenshot, progress).
    """
    app = make_app(InputHub(replay=ReplaySource(recording)))
    matched = 0
    for i, (frame, expected) in enumerate(zip(recording.frames, recording.hashes, strict=True)):
        if app.world.frame != frame.frame:
            return ReplayResult(i, matched, frame.frame, expected, f"world at frame {app.world.frame}")
        app.step()
        if on_step is not None:
            on_step(app, i)
        got = state_hash(app.world)
        if got != expected:
            return ReplayResult(i + 1, matched, frame.frame, expected, got)
        matched += 1
    return ReplayResult(len(recording.frames), matched)
