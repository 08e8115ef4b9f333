"""``python -m tools.regen TARGET...`` (from the repository checkout): what it regenerates, and in which order.

After a change to the simulation the shipped recordings' state hashes no longer match;
after a change to the look the screenshots are stale. Each target rebuilds one kind of
artefact from its script: ``demos`` (the games' ``demo.rec``), ``recordings`` (the
puppet sessions in ``tests/data``), ``screenshots`` (``docs/screenshots``, from the snowman
demo) and ``assets`` (tasbada's drawn room). ``all`` runs them in dependency
order: assets first (the demo plays over them), screenshots last (they replay the demo).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

__all__ = ["TARGETS", "ORDER", "main", "regenerate"]


def _assets() -> None:
    from tools.tasbada_assets import main

    main()


def _demos() -> None:
    from tools.snowman_demo import build_demo
    from tools.tasbada_demo import make_demo

    build_demo()
    make_demo()


def _recordings() -> None:
    from tools.recordings import main

    if main([]) != 0:
        raise RuntimeError("the puppet sessions could not be recorded")


def _screenshots() -> None:
    from tools.snowman_screenshots import take_screenshots

    for path in take_screenshots():
        print(f"wrote {path}")


TARGETS: dict[str, Callable[[], None]] = {
    "assets": _assets,
    "demos": _demos,
    "recordings": _recordings,
    "screenshots": _screenshots,
}
ORDER = ("assets", "demos", "recordings", "screenshots")


def regenerate(names: list[str]) -> None:
    """Run the named targets (``all`` = every one) in dependency order."""
    wanted = set(ORDER) if "all" in names else set(names)
    unknown = wanted - set(ORDER)
    if unknown:
        raise ValueError(f"unknown target(s) {', '.join(sorted(unknown))}; targets are {', '.join(ORDER)}, all")
    for name in ORDER:
        if name in wanted:
            print(f"== regen {name}")
            TARGETS[name]()


def main(argv: list[str] | None = None) -> int:
    """The developer command: parse the targets and regenerate them (exit 2 on an unknown one).

    It lives in the repository, not in the installed package: it writes ``tests/data`` and
    ``docs/``, which only a checkout has.
    """
    parser = argparse.ArgumentParser(
        prog="python -m tools.regen", description="rebuild the shipped recordings, demos, screenshots and assets"
    )
    parser.add_argument(
        "targets", nargs="+", metavar="TARGET", choices=(*ORDER, "all"), help=f"{', '.join(ORDER)} or all"
    )
    args = parser.parse_args(argv)
    regenerate(args.targets)
    return 0


if __name__ == "__main__":
    sys.exit(main())
