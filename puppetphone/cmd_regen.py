"""``puppetphone regen [demos|recordings|screenshots|assets|all]``: rebuild the shipped artefacts.

A developer command (it needs the repository checkout: ``tests/data`` and ``docs/``);
see :mod:`tools.regen` for what each target writes.
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the targets."""
    parser.add_argument("targets", nargs="+", metavar="TARGET",
                        choices=("demos", "recordings", "screenshots", "assets", "all"),
                        help="demos, recordings, screenshots, assets or all")


def run(args: argparse.Namespace) -> int:
    """Regenerate the chosen targets."""
    from tools import REPO
    from tools.regen import regenerate

    if not (REPO / "tests" / "data").is_dir():
        print(f"error: regen needs the repository checkout; {REPO} has no tests/data", file=sys.stderr)
        return 2
    regenerate(args.targets)
    return 0
