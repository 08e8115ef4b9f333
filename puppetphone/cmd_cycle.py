"""``puppetphone cycle INPUT -o OUTPUT [--json] [--plot PNG] [--items …] [--start T0 --end T1]``: one clean loop from a performance.

Input ``.bvh`` / ``.gltf`` / ``.glb`` (``--animation``, ``--units``, ``--joint-map``) / ``.csv`` /
``.npz`` / ``.rec`` (a recording), output ``.bvh`` / ``.ppclip`` / ``.glb`` / ``.gltf`` (skeletal input)
or ``.csv`` / ``.npz``. With ``--json`` the last line of standard output is::

    {"period_frames", "period_seconds", "cycles", "dims", "closure_error", "seconds", ...,
     "input": {"units", "unit_scale", "units_basis", "fps", "fps_basis", "animation", ...}}

(``input`` for BVH/glTF input: what was decided about the file).

When no cycle can be found the command exits with status 3 and says why on standard
error (and, with ``--json``, an ``{"error": …}`` line); nothing is written then. A take
refused as a whole is searched for a part that loops, and the message names the best
one ("frames 0–363 loop with period 1.00 s (5 cycles); try --start 0 --end 6.07").
"""

from __future__ import annotations

import argparse
import json
import sys
import time

__all__ = ["configure", "run"]

EXIT_NO_CYCLE = 3
EXIT_BAD_INPUT = 2
_PROGRESS_SAMPLES = 200_000  # values (T·N) from which a progress bar is worth showing


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the cycle arguments."""
    parser.add_argument(
        "input",
        metavar="INPUT",
        help="performance: .bvh, .gltf, .glb, .csv (time + columns), .npz or a recording (.rec)",
    )
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUTPUT", help="loop file: .bvh, .ppclip, .glb, .gltf, .csv or .npz"
    )
    from puppetphone.motion_args import add_export_options, add_motion_options

    add_motion_options(parser)
    add_export_options(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON summary as the last line")
    from puppetphone.argtypes import take_position
    from puppetphone.runargs import image_path

    parser.add_argument(
        "--plot",
        metavar="IMAGE",
        type=image_path,
        help="draw the performance, cuts, aligned cycles and the loop (.png or .jpg; needs "
        "matplotlib: the 'plot' extra)",
    )
    parser.add_argument(
        "--items", metavar="NAME", nargs="+", help="only these joints (BVH), items (CSV/npz) or sources (recording)"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the random probe points (default 0)")
    parser.add_argument(
        "--samples", type=int, help="samples in the output loop (default: the period at the input rate)"
    )
    parser.add_argument(
        "--retarget",
        choices=("puppet",),
        default=None,
        help="move a BVH performance onto the puppet's skeleton first (the loop is then the puppet's)",
    )
    parser.add_argument("--no-progress", action="store_true", help="never show the progress bar")
    parser.add_argument(
        "--start", metavar="T0", type=take_position, help="analyse from here: seconds (4.0, 4.0s) or a frame (480f)"
    )
    parser.add_argument(
        "--end", metavar="T1", type=take_position, help="analyse up to here (excluded): seconds or a frame"
    )
    parser.epilog = (
        f"exit codes: 0 the loop was written; {EXIT_BAD_INPUT} an unreadable input or output, or a bad "
        f"option; {EXIT_NO_CYCLE} no cycle in the take (why, and the part that loops if any, on "
        "standard error; nothing written)"
    )


class _Bar:
    """A one-line progress bar on standard error, only when it is a terminal or forced."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled

    def __call__(self, stage: str, done: float) -> None:
        if not self.enabled:
            return
        width = 30
        fill = round(done * width)
        sys.stderr.write(f"\r[{'#' * fill}{'.' * (width - fill)}] {done:4.0%} {stage:<12}")
        if done >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()


def run(args: argparse.Namespace) -> int:
    """Read, extract, write; report what was found or why nothing was."""
    import numpy as np

    from authoring.cycles.extract import CycleError, CycleOptions, extract_cycle
    from authoring.cycles.formats import OUTPUT_SUFFIXES, load_performance, save_loop
    from authoring.cycles.take_range import refusal_hint, select
    from authoring.cycles.trajectory import TrajectoryError
    from engine.io.formats import suffixes
    from puppetphone.motion_args import about, export_options, motion_options

    def fail(code: int, message: str) -> int:
        print(f"cycle: {message}", file=sys.stderr)
        if args.json:
            print(json.dumps({"error": message}))
        return code

    out_suffix = "." + args.output.rsplit(".", 1)[-1].lower() if "." in args.output else ""
    if out_suffix not in OUTPUT_SUFFIXES:
        return fail(
            EXIT_BAD_INPUT,
            f"unknown output type {out_suffix or args.output!r}; use one of {', '.join(OUTPUT_SUFFIXES)}",
        )
    if args.plot:
        import importlib.util

        if importlib.util.find_spec("matplotlib") is None:
            return fail(EXIT_BAD_INPUT, "--plot needs matplotlib: pip install 'puppetphone[plot]'")
    t0 = time.perf_counter()
    try:
        options = motion_options(args)
        whole = load_performance(args.input, args.items, **options)
        if args.retarget:
            from authoring.cycles.retarget_source import retarget_performance
            from engine.humanoid import humanoid_skeleton

            whole = retarget_performance(whole, humanoid_skeleton(), options["joint_map"])
        perf, offset = select(whole, args.start, args.end) if args.start or args.end else (whole, 0)
    except FileNotFoundError as exc:
        return fail(EXIT_BAD_INPUT, str(exc))
    except (TrajectoryError, ValueError) as exc:
        return fail(EXIT_BAD_INPUT, f"cannot read {about(args.input, exc)}")
    if perf.clip is None and out_suffix in suffixes(skeletal=True):
        return fail(
            EXIT_BAD_INPUT, f"{out_suffix} output needs skeletal input (BVH, glTF); write .csv or .npz for {args.input}"
        )
    for warning in perf.motion.warnings if perf.motion else ():
        print(f"cycle: warning: {warning}", file=sys.stderr)
    if perf.motion and perf.motion.unit_note:
        print(f"cycle: note: {perf.source.name}: {perf.motion.unit_note}", file=sys.stderr)
    traj = perf.trajectory
    big = traj.num_samples * traj.dims >= _PROGRESS_SAMPLES
    bar = _Bar(big and not args.no_progress and sys.stderr.isatty())
    opts = CycleOptions(samples=args.samples)
    t1 = time.perf_counter()
    try:
        result = extract_cycle(traj, np.random.default_rng(args.seed), opts, progress=bar)
    except CycleError as exc:
        bar.enabled = False
        hint = refusal_hint(whole, perf, offset, args.seed)
        return fail(EXIT_NO_CYCLE, f"{exc}" + (f"; {hint}" if hint else ""))
    seconds = time.perf_counter() - t1
    try:
        save_loop(result, perf, args.output, **export_options(args))
    except (TrajectoryError, ValueError, OSError) as exc:
        return fail(EXIT_BAD_INPUT, f"cannot write {args.output}: {exc}")
    if args.plot:
        from authoring.cycles.plot import plot_cycle

        plot_cycle(traj, result, args.plot, perf.names)
        if not args.json:
            print(f"wrote {args.plot}")
    summary = {
        "period_frames": round(result.period_samples, 3),
        "period_seconds": round(result.period, 6),
        "cycles": perf.performed or result.cycles,  # a one-cycle glTF loop is repeated to be measured
        "dims": traj.dims,
        "closure_error": result.closure_error,
        "seconds": round(seconds, 4),
        "total_seconds": round(time.perf_counter() - t0, 4),
        "spread": round(result.spread, 4),
        "samples": len(result.loop),
        "skipped_frames": perf.skipped,
        "bezier_segments": sum(c.segments for c in result.curves.values()),
        **({"input": perf.motion.summary()} if perf.motion else {}),
    }
    if not args.json:
        print(
            f"{perf.source.name}: period {result.period:.4f} s = {result.period_samples:.2f} frames, "
            f"{perf.performed or result.cycles} cycle(s) averaged, {traj.dims} dims, spread {result.spread:.1%}, "
            f"closure error {result.closure_error:.1e}, {seconds * 1000:.0f} ms -> {args.output}"
        )
    else:
        print(json.dumps(summary))
    return 0
