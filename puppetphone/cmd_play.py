"""``puppetphone play GAME``: play a game with a MotionStick source; record; screenshot.

A window needs a display; ``--headless`` runs without one (paced to real time with a
live source, as fast as it can with a replay). Game options: ``--set key=value``
(``puppetphone play GAME --set help`` lists them).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from authoring.session import Session
    from engine.runner import RunOptions, RunResult
    from input.hub import InputHub

__all__ = ["configure", "run", "run_activity"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the play arguments."""
    from input.factory import add_source_arguments
    from puppetphone.argtypes import int_range, output_file
    from puppetphone.registry import GAMES
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("game", help=", ".join(GAMES))
    add_source_arguments(parser)
    add_run_arguments(parser)
    parser.add_argument(
        "--view",
        choices=("orbit", "phone", "none"),
        default="orbit",
        help="phone: see the scene from the held controller (web, OSC or SpaceMouse); V switches; "
        "none: no desktop window at all (with --source web the phones are the only views)",
    )
    parser.add_argument(
        "--record",
        type=output_file,
        default=None,
        help="record the session's input and state hashes (an existing file is replaced)",
    )
    parser.add_argument("--seed", type=int_range(0, 2**63 - 1), default=0, help="the world's random seed (default 0)")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        dest="settings",
        help="a game option, repeatable; --set help lists every game's options with their types, ranges and defaults",
    )
    parser.add_argument(
        "--clips",
        type=Path,
        default=None,
        metavar="DIR",
        help="play the authored clips of this library (default: $XDG_DATA_HOME/puppetphone/clips "
        "when live; an empty or missing library means the built-in clips)",
    )
    parser.add_argument(
        "--puppets",
        type=int,
        default=None,
        metavar="N",
        help="sandbox: a crowd of N puppets wandering the field (same as --set puppets=N)",
    )
    parser.add_argument(
        "--flow",
        default=None,
        metavar="FILE",
        help="snowman: start in the field as a flow file bent it (puppetphone author flow; same as --set flow=FILE)",
    )
    parser.add_argument(
        "--character",
        default=None,
        metavar="FILE.glb",
        help="the player's puppet is this rigged humanoid (.glb), the puppet's clips retargeted to it",
    )
    parser.add_argument(
        "--joint-map",
        default=None,
        metavar="FILE",
        help='with --character: JSON {"file joint": "puppet role"} when its names and shape do not tell',
    )
    parser.epilog = (
        "exit codes: 0 the session ran; 2 a bad option value, no display for a window, an input "
        "that cannot be opened, or a recording of another game"
    )


def resolve_source(source: str, game: str) -> str:
    """``replay:demo`` means the demo recording shipped with the game."""
    kind, _, arg = source.partition(":")
    if kind == "replay" and arg == "demo":
        from puppetphone.registry import load_game

        module_file = __import__(f"games.{load_game(game).name}", fromlist=["x"]).__file__
        demo = Path(str(module_file)).parent / "demo.rec"
        return f"replay:{demo}"
    return source


def announce_web(hub: InputHub) -> None:
    """Print a web controller's link, fingerprint and QR code, and publish it for ``devices``."""
    from puppetphone.web_pairing import web_sources

    for source in web_sources(hub):
        import atexit

        from input.pairing import qr_ascii
        from input.web.pairing import publish, unpublish, web_link

        link = web_link(source)
        print("\n".join(link.lines()), file=sys.stderr)
        print(qr_ascii(link.urls[0]), file=sys.stderr)
        publish(link)
        atexit.register(unpublish)


def run_activity(activity: Session, options: RunOptions) -> tuple[int, RunResult | None]:
    """Run a game's session through the runner; ``(exit code, run result)``."""
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from puppetphone.session import GameSimulation

    game = activity.simulation
    assert isinstance(game, GameSimulation)  # build_activity's sessions run a game
    runner = Runner(options, clock=game.app.clock)
    runner.push_handlers(activity)
    game.fps = lambda: runner.fps
    activity.hub.start()
    try:
        result = runner.run(activity)
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2, None
    finally:
        activity.close()
        runner.close()
    if result.screenshot is not None:
        print(f"screenshot: {result.screenshot}")
    if activity.recorder is not None:
        print(f"recorded {activity.recorder.frames} frames to {activity.recorder.path}", file=sys.stderr)
    return 0, result


def print_option_help() -> None:
    """``--set help``: every game's options with their types, ranges and defaults."""
    from games.base import describe_options
    from puppetphone.registry import GAMES, load_game

    print("game options (--set KEY=VALUE, repeatable):")
    for name in GAMES:
        print("\n".join(describe_options(load_game(name))))


def run(args: argparse.Namespace) -> int:
    """Build the session and run it."""
    if "help" in args.settings:
        print_option_help()
        return 0
    from games.base import GameOptionError, parse_settings
    from input.factory import make_hub
    from input.recording import RecordingError
    from puppetphone.registry import load_game
    from puppetphone.runargs import run_options
    from puppetphone.session import build_activity

    try:
        game = load_game(args.game)
        settings = args.settings + ([f"puppets={args.puppets}"] if args.puppets is not None else [])
        settings += [f"flow={args.flow}"] if args.flow is not None else []
        options = parse_settings(settings, game.options, game.name)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.view == "none":
        if args.screenshot is not None:
            print("error: --view none draws nothing: drop --screenshot or choose another view", file=sys.stderr)
            return 2
        args.headless = True  # no window, no GL: the session runs paced by its live source
    if not args.headless:
        from engine.render.window import NoDisplayError
        from engine.runner import check_display

        try:
            check_display()
        except NoDisplayError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
    if args.record is not None and args.record.exists():
        print(f"--record: replacing the existing {args.record}", file=sys.stderr)
    source = resolve_source(args.source, args.game)
    try:
        hub = make_hub(
            source,
            args.osc_host,
            args.osc_port,
            args.osc_senders,
            args.serial_port,
            args.baud,
            args.web_host,
            args.web_port,
            args.silent_after,
        )
    except (ValueError, OSError, RecordingError) as exc:
        print(f"cannot open input {source!r}: {exc}", file=sys.stderr)
        return 2
    announce_web(hub)
    seed, setup = args.seed, None
    if hub.replay is not None:
        from input.replay import ReplaySource

        assert isinstance(hub.replay, ReplaySource)  # make_hub's only frame source
        recording = hub.replay.recording
        if recording.header.game != args.game:
            hub.close()
            print(f"the recording is of {recording.header.game!r}, not {args.game!r}", file=sys.stderr)
            return 2
        if not recording.complete:
            print(f"warning: {recording.problem}", file=sys.stderr)
    try:
        if hub.replay is not None:  # the recorded set-up, checked by the game like any outside input
            seed, setup = recording.header.seed, game.replay_setup(recording.header.setup)
        from puppetphone.cmd_clips import library_setup

        clips = library_setup(args.clips, replay=hub.replay is not None)
        if hub.replay is None:  # --character, else the clip library's character (engine.cliplib.character)
            from engine.character.setup import character_setup
            from engine.cliplib.character import library_character
            from engine.cliplib.library import ClipLibrary, default_library_dir

            character = (
                character_setup(args.character, args.joint_map)
                if args.character is not None
                else library_character(ClipLibrary(args.clips or default_library_dir()))
            )
            if character is not None:
                setup = {**game.prepare(options), "character": character}
        activity = build_activity(
            args.game,
            seed,
            hub,
            setup=setup,
            options=options,
            record=args.record,
            source_label=source,
            clips=clips,
            view=args.view,
        )
    except (GameOptionError, OSError, ValueError) as exc:
        hub.close()
        print(f"error: {exc}", file=sys.stderr)
        return 2
    code, result = run_activity(activity, run_options(args, f"PuppetPhone — {args.game}", pace=hub.live))
    if result is not None:
        print(f"ran {result.steps} steps of {args.game}")
    return code
