"""``puppetphone play GAME``: play a game with a MotionStick source; record; screenshot."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the play arguments."""
    from input.factory import add_source_arguments
    from puppetphone.argtypes import MAX_WINDOW, int_range, output_file, window_size

    parser.add_argument("game", help="snowman or tasbada")
    add_source_arguments(parser)
    parser.add_argument("--headless", action="store_true", help="no window: EGL rendering, for servers and tests")
    parser.add_argument("--frames", type=int_range(0), default=None, help="stop after N simulation steps")
    parser.add_argument("--screenshot", type=output_file, default=None, help="write the last frame as PNG")
    parser.add_argument("--record", type=output_file, default=None,
                        help="record the session's input and state hashes (an existing file is replaced)")
    parser.add_argument("--seed", type=int_range(0, 2**63 - 1), default=0, help="the world's random seed (default 0)")
    parser.add_argument("--size", type=window_size, default=(1280, 720),
                        help=f"window size WxH, sides up to {MAX_WINDOW} (default 1280x720)")
    parser.epilog = ("exit codes: 0 the session ran; 2 a bad option value, an input that cannot be opened, "
                     "or a recording of another game")


def resolve_source(source: str, game: str) -> str:
    """``replay:demo`` means the demo recording shipped with the game."""
    kind, _, arg = source.partition(":")
    if kind == "replay" and arg == "demo":
        from puppetphone.games import load_game

        demo = Path(__import__(f"games.{load_game(game).name}", fromlist=["x"]).__file__).parent / "demo.rec"
        return f"replay:{demo}"
    return source


def run(args: argparse.Namespace) -> int:
    """Build the session and run it."""
    from input.factory import make_hub
    from input.recording import RecordingError
    from puppetphone.session import Session, SessionOptions

    width, height = args.size
    if args.record is not None and args.record.exists():
        print(f"--record: replacing the existing {args.record}", file=sys.stderr)
    source = resolve_source(args.source, args.game)
    try:
        hub = make_hub(source, args.osc_host, args.osc_port, args.osc_senders, args.serial_port, args.baud)
    except (ValueError, OSError, RecordingError) as exc:
        print(f"cannot open input {source!r}: {exc}", file=sys.stderr)
        return 2
    seed = args.seed
    if hub.replay is not None:
        header = hub.replay.recording.header  # type: ignore[attr-defined]
        if header.game != args.game:
            print(f"the recording is of {header.game!r}, not {args.game!r}", file=sys.stderr)
            return 2
        seed = header.seed
        if not hub.replay.recording.complete:  # type: ignore[attr-defined]
            print(f"warning: {hub.replay.recording.problem}", file=sys.stderr)  # type: ignore[attr-defined]
    options = SessionOptions(game=args.game, seed=seed, headless=args.headless, frames=args.frames,
                             screenshot=args.screenshot, record=args.record, width=width, height=height,
                             source_label=source)
    try:
        session = Session(options, hub)
    except ValueError as exc:
        hub.close()
        print(str(exc), file=sys.stderr)
        return 2
    return session.run()
