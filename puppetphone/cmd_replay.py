"""``puppetphone replay FILE [--verify] [--headless] [--screenshot IMAGE [--screenshot-at N]] [--frames N]``.

Rebuilds the recorded session from the file alone — the game, the seed and the game's
setup (scene, saved field, saved progress) are in its header — and plays it through the
same runner as ``play``: in a window at the recorded speed, or ``--headless`` as fast as
it can. With ``--verify`` every step's state hash is compared with the recorded one; the
first frame that differs is named — with or without ``--verify``, a replay that does not
reproduce its recording is a failure. Exit codes: 0 every step replayed and matched;
1 a state hash differs, or the file is damaged or cut short after its header; 2 the file
cannot be replayed at all (not a regular file, not a recording, damaged header, unknown
game, no display). A recording cut short (a session killed mid-write) replays up to its
last complete frame with a warning and exit 0 only under ``--allow-truncated``. A recording
made with other versions of the numerical libraries says so in one line first ("recorded with
mujoco 4.0.0, running 3.17.0: hashes may differ"; :mod:`input.library_versions`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from input.recording import Recording
    from input.replay import HashCheck
    from puppetphone.registry import Entry

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the replay arguments."""
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("file", metavar="FILE", help="a recording made with play --record")
    parser.add_argument(
        "--verify", action="store_true", help="print the verification line (every step's state hash is always compared)"
    )
    parser.add_argument(
        "--allow-truncated",
        action="store_true",
        help="a recording cut short (killed mid-write) replays its complete frames with exit 0",
    )
    add_run_arguments(parser, screenshot_at=True)
    parser.add_argument(
        "--view",
        choices=("orbit", "phone"),
        default="orbit",
        help="phone: see the scene from the recorded controller; V switches",
    )
    parser.epilog = "exit codes: 0 replayed and matched; 1 a hash differs or the file is damaged/cut; 2 cannot replay"


def run(args: argparse.Namespace) -> int:
    """Replay (and optionally verify) a recording; returns the exit code."""
    from games.base import GameOptionError
    from input.hub import InputHub
    from input.library_versions import version_difference
    from input.recording import RecordingError, read_recording
    from input.replay import ReplaySource
    from puppetphone.cmd_play import run_activity
    from puppetphone.registry import load_game, lookup
    from puppetphone.runargs import run_options
    from puppetphone.session import build_activity

    path = Path(args.file)
    if path.exists() and not path.is_file():
        print(f"error: {path} is not a regular file (a device, pipe or folder cannot be replayed)", file=sys.stderr)
        return 2
    try:
        rec = read_recording(path)
    except (OSError, RecordingError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    cut_short = not rec.complete and rec.cut
    if not rec.complete:
        level = "warning" if cut_short and args.allow_truncated else "error"
        print(f"{level}: {args.file}: {rec.problem}; replaying the {len(rec)} complete frames", file=sys.stderr)
    h = rec.header
    if differ := version_difference(h.libraries):
        print(f"note: {differ}", file=sys.stderr)
    try:
        entry = lookup(h.game)
    except ValueError as exc:
        print(f"error: cannot rebuild the recorded session: {exc}", file=sys.stderr)
        return 2
    if entry.kind == "tool":
        return _replay_tool(entry, rec, args, cut_short)
    try:
        game = load_game(h.game)
        activity = build_activity(
            h.game,
            h.seed,
            InputHub(replay=ReplaySource(rec)),
            setup=game.replay_setup(h.setup),
            verify=rec,
            view=args.view,
        )
    except (GameOptionError, ValueError, KeyError, OSError) as exc:
        print(f"error: cannot rebuild the recorded {h.game!r} session: {exc}", file=sys.stderr)
        return 2
    if abs(activity.dt - h.dt) > 1e-12:
        print(f"error: the recording steps at dt={h.dt}, game {h.game!r} at dt={activity.dt}", file=sys.stderr)
        return 2
    code, result = run_activity(activity, run_options(args, f"PuppetPhone — replay of {args.file}"))
    if code:
        return code
    assert result is not None and activity.check is not None  # exit code 0: it ran, verifying ``rec``
    return _verdict(activity.check, result.steps, rec, args, cut_short)


def _replay_tool(entry: Entry, rec: Recording, args: argparse.Namespace, cut_short: bool) -> int:
    """A tool's session: reopened from the recording by its registered tool, fed the recorded input."""
    from authoring.session import tool_session
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from input.hub import InputHub
    from input.replay import ReplaySource
    from puppetphone.registry import load_tool
    from puppetphone.runargs import run_options

    try:
        session = tool_session(load_tool(entry), rec, InputHub(replay=ReplaySource(rec)))
    except (ValueError, KeyError, TypeError, OSError) as exc:  # (a flow file's own error is a ValueError)
        print(f"error: cannot reopen the recorded {rec.header.game} session: {exc}", file=sys.stderr)
        return 2
    runner = Runner(run_options(args, f"PuppetPhone — replay of {args.file}"))
    try:
        result = runner.run(session)
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:  # a tool operation the scene cannot take: the file was made to lie
        print(f"error: {args.file}: step {session.frame}: {exc}", file=sys.stderr)
        return 2
    finally:
        runner.close()
        session.close()
    if result.screenshot is not None:
        print(f"screenshot: {result.screenshot}")
    assert session.check is not None  # tool_session checks every step against ``rec``
    return _verdict(session.check, result.steps, rec, args, cut_short)


def _verdict(check: HashCheck, steps: int, rec: Recording, args: argparse.Namespace, cut_short: bool) -> int:
    """Print how the replay went; the exit code."""
    if not check.ok:
        print(check.message())
        return 1
    if args.verify:
        print(f"replayed {steps} frames, all {check.matched} state hashes match")
    else:
        print(f"replayed {steps} frames")
    if not rec.complete and not (cut_short and args.allow_truncated):
        return 1
    return 0
