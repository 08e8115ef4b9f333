"""The ``puppetphone`` command line: one module per sub-command.

Each command module has ``configure(parser)`` and ``run(args) -> int``; heavy
imports happen inside ``run`` so ``puppetphone --help`` stays instant.
"""

from __future__ import annotations

import argparse
import importlib
import sys

__all__ = ["main", "COMMANDS"]

COMMANDS: dict[str, tuple[str, str]] = {
    "play": ("puppetphone.cmd_play", "play a game (snowman or tasbada)"),
    "replay": ("puppetphone.cmd_replay", "replay a recording, optionally verifying every state hash"),
    "author": ("puppetphone.cmd_author", "authoring scenes: record cycles by acting, edit them with MoCurves"),
    "cycle": ("puppetphone.cmd_cycle", "extract one clean loop from a performed motion"),
    "devices": ("puppetphone.cmd_devices", "list input devices and where a phone should send"),
    "bench": ("puppetphone.cmd_bench", "run benchmarks and print figures against baselines"),
    "blendspace": ("puppetphone.cmd_blendspace", "inspect the puppet's blend space and IDW lookup"),
    "schedule": ("puppetphone.cmd_schedule", "print a game's frame schedule: stages, systems, plugins"),
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every available sub-command."""
    parser = argparse.ArgumentParser(prog="puppetphone", description="Bring virtual puppets to life by hand.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            continue
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.configure(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "_run"):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
