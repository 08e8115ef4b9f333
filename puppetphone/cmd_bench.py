"""``puppetphone bench [NAME…] [--json FILE]``: run benchmarks, print figures with baselines."""

from __future__ import annotations

import argparse
import importlib
import json
import sys

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the bench arguments (the bench package loads numpy: its names are checked when the command runs)."""
    parser.add_argument(
        "names", nargs="*", metavar="NAME", help="benches to run (default all; an unknown name lists the known ones)"
    )
    parser.add_argument("--json", metavar="FILE", help="write the figures as a JSON list")
    parser.add_argument("--plot", metavar="PNG", help="motion: draw foot height and speed over time for one case")
    parser.add_argument("--case", default="stop_and_go", help="motion: the case --plot draws (default stop_and_go)")


def run(args: argparse.Namespace) -> int:
    """Run the chosen benches in order and report every figure."""
    from puppetphone.bench import BENCHES

    names = args.names or list(BENCHES)
    unknown = [n for n in names if n not in BENCHES]
    if unknown:
        print(f"unknown bench {', '.join(unknown)}; known: {', '.join(BENCHES)}", file=sys.stderr)
        return 2
    figures = []
    failed = []
    for name in names:
        try:
            module = importlib.import_module(BENCHES[name])
        except ModuleNotFoundError as exc:
            print(f"{name}: not available ({exc})", file=sys.stderr)
            failed.append(name)
            continue
        print(f"# {name}", flush=True)
        for fig in module.run():
            print(fig.line(), flush=True)
            figures.append(fig)
    if args.plot and "motion" in names:
        from puppetphone.bench.motion import plot_case
        from puppetphone.bench.motion_play import CASES

        case = next((c for c in CASES if c.name == args.case), None)
        if case is None:
            print(f"unknown case {args.case!r}; cases: {', '.join(c.name for c in CASES)}", file=sys.stderr)
            return 2
        plot_case(case, args.plot)
        print(f"wrote {args.plot}")
    if args.json:
        from engine.atomic import atomic_write_bytes

        atomic_write_bytes(args.json, json.dumps([f.as_dict() for f in figures], indent=2).encode())
    return 1 if failed else 0
