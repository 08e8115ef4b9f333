"""``puppetphone replay FILE [--verify] [--headless] [--screenshot PNG] [--frames N]``.

Rebuilds the recorded game's app from the header (``puppetphone.games.make_app``
with the recorded game and seed) around a replay hub, steps it once per recorded
frame as fast as it can, and with ``--verify`` compares every state hash: it prints
``replayed N frames, all N state hashes match`` or names the first frame that
differs and exits 1. A recording cut short replays up to its last complete frame,
with a warning.
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the replay arguments."""
    parser.add_argument("file", metavar="FILE", help="a recording made with play --record")
    parser.add_argument("--verify", action="store_true", help="compare every step's state hash with the recording")
    parser.add_argument("--headless", action="store_true", help="no window (replays always simulate headless here)")
    parser.add_argument("--screenshot", metavar="PNG", help="render the final state to a PNG")
    parser.add_argument("--frames", type=int, default=None, help="stop after N frames")


def run(args: argparse.Namespace) -> int:
    """Replay (and optionally verify) a recording; returns the exit code."""
    from input.recording import RecordingError, read_recording
    from input.replay import verify

    try:
        rec = read_recording(args.file)
    except (OSError, RecordingError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if not rec.complete:
        print(f"warning: {args.file}: {rec.problem}; replaying the {len(rec)} complete frames", file=sys.stderr)
    if args.frames is not None:
        rec.frames, rec.hashes = rec.frames[: args.frames], rec.hashes[: args.frames]
    h = rec.header
    try:
        from puppetphone.games import make_app
    except ImportError as exc:
        print(f"error: cannot rebuild game {h.game!r}: {exc}", file=sys.stderr)
        return 2

    def build(hub):  # type: ignore[no-untyped-def]
        app = make_app(h.game, h.seed, hub)
        if abs(app.world.dt - h.dt) > 1e-12:
            raise ValueError(f"recording steps at dt={h.dt}, game {h.game!r} at dt={app.world.dt}")
        return app

    apps = []
    try:
        result = verify(build, rec, on_step=lambda app, i: apps.append(app) if i == 0 else None)
    except (KeyError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.screenshot and apps:
        code = _screenshot(apps[0], args.screenshot)
        if code:
            return code
    if args.verify:
        print(result.message())
        return 0 if result.ok else 1
    print(f"replayed {result.frames} frames")
    return 0


def _screenshot(app, path: str) -> int:  # type: ignore[no-untyped-def]
    try:
        from puppetphone.games import screenshot
    except ImportError:
        print("error: --screenshot needs the renderer (puppetphone.games.screenshot), not available", file=sys.stderr)
        return 2
    screenshot(app, path)
    return 0
