"""The ``puppetphone`` command line: one module per sub-command.

Each command module has ``configure(parser)`` and ``run(args) -> int``; heavy
imports happen inside ``run`` so ``puppetphone --help`` stays instant.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

__all__ = ["COMMANDS", "main"]

COMMANDS: dict[str, tuple[str, str]] = {
    "play": ("puppetphone.cmd_play", "play a game (snowman, tasbada or sandbox)"),
    "replay": ("puppetphone.cmd_replay", "replay a recording, optionally verifying every state hash"),
    "author": ("puppetphone.cmd_author", "authoring scenes: record cycles by acting, edit them with MoCurves"),
    "cycle": ("puppetphone.cmd_cycle", "extract one clean loop from a performed motion"),
    "clips": ("puppetphone.cmd_clips", "the clip library games play: add (retargeted, role-checked), list, remove"),
    "cycles": ("puppetphone.cmd_cycles", "extract every loop of a mocap library into a clip library with an index"),
    "devices": ("puppetphone.cmd_devices", "list input devices and where a phone should send"),
    "bench": ("puppetphone.cmd_bench", "run benchmarks and print figures against baselines"),
    "blendspace": ("puppetphone.cmd_blendspace", "inspect the puppet's blend space and IDW lookup"),
    "schedule": ("puppetphone.cmd_schedule", "print a game's frame schedule: stages, systems, plugins"),
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every available sub-command."""
    parser = argparse.ArgumentParser(prog="puppetphone", description="Bring virtual puppets to life by hand.")
    parser.add_argument("--version", action=_VersionAction, nargs=0, help="show the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            continue
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.set_defaults(_run=module.run, _parser=p)
        module.configure(p)
    return parser


class _VersionAction(argparse.Action):
    """``--version``: the installed distribution's version, looked up only when asked (importlib.metadata is slow)."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print(f"puppetphone {_version()}")
        parser.exit()


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("puppetphone")
    except PackageNotFoundError:
        return "(not installed)"


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the process exit code."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")  # pygame's banner is not our output
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # reported with the usage of the sub-command that was typed, not the top level's
        getattr(args, "_parser", parser).error(f"unrecognized arguments: {' '.join(unknown)}")
    if not hasattr(args, "_run"):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
