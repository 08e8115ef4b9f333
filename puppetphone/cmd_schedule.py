"""``puppetphone schedule GAME``: the frame schedule of a game, as its app is assembled.

Prints every stage of :data:`engine.app.STAGES` in run order with its systems (qualified
names, in the order they run), then the installed plugins in the order their installs
began. The app is built as ``play`` builds it (:func:`puppetphone.games.make_app`) with
an input hub of no sources, and never stepped; it answers "what runs, in what order"
without reading the code of every plugin.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from engine.app import App

__all__ = ["configure", "run", "schedule_lines"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the schedule arguments."""
    from puppetphone.registry import GAMES

    parser.add_argument("game", help=f"the game whose schedule to print: {', '.join(GAMES)}")
    parser.add_argument("--seed", type=int, default=0, help="world seed of the assembled app (default 0)")


def schedule_lines(app: App) -> list[str]:
    """The printed schedule of an app: stages and systems, then plugins."""
    from engine.app import STAGES, system_name

    lines = ["stages (run in this order each step; systems in run order):"]
    for number, stage in enumerate(STAGES, start=1):
        lines.append(f"{number}. {stage}")
        lines += [f"     {system_name(system)}" for system in app.systems(stage)]
    lines.append("then world.frame += 1 and the on_step_end callbacks (the recorder)")
    lines.append("plugins (in the order their installs began):")
    lines += [f"  {name}" for name in app.plugins]
    return lines


def run(args: argparse.Namespace) -> int:
    """Assemble the game's app and print its schedule."""
    import sys

    from input.hub import InputHub
    from puppetphone.games import make_app
    from puppetphone.registry import load_game

    try:
        load_game(args.game)
    except ValueError as exc:
        print(f"puppetphone schedule: {exc}", file=sys.stderr)
        return 2
    app = make_app(args.game, args.seed, InputHub())
    print("\n".join(schedule_lines(app)))
    return 0
