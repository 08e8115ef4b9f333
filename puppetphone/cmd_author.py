"""``puppetphone author record|edit|curves|flow``: the authoring tools' command line (parsing and wiring only).

Every tool runs as one :class:`authoring.session.Session` of its simulation (its module,
beside its scene in ``authoring/``, registered in :mod:`puppetphone.registry`): the same
bindings (left-drag acts, right-drag orbits, wheel zooms: README "Controls"), ``--record
FILE`` for every tool and ``puppetphone replay FILE --verify`` with no special case.

- ``author record`` acts a motion cycle out (:mod:`authoring.record_tool`) with the mouse or
  a device (``--source``); R record, Space stop, Enter accept, Backspace retry, Ctrl+S save;
  ``--script loops`` is a scripted performer;
- ``author edit CLIP`` refines a cycle with MoCurves while it plays (:mod:`authoring.edit_tool`);
- ``author curves CLIP`` poses a keyframed clip's keys and shapes its curves (:mod:`authoring.curves_tool`);
- ``author flow [SCENE]`` bends a scene with Flow Curves (:mod:`authoring.flow_tool`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

__all__ = ["configure", "run"]

#: Scripted hands of the tools (the choices of ``--script``; each tool module checks its own).
RECORD_SCRIPTS = ("loops",)
CURVES_SCRIPTS = ("drag", "walk")
FLOW_SCRIPTS = ("row", "centre", "demo")


def configure(parser: argparse.ArgumentParser) -> None:
    """Add one sub-command per registered tool."""
    from puppetphone.registry import TOOLS

    sub = parser.add_subparsers(dest="scene", metavar="SCENE")
    for name in TOOLS:
        configure_tool, help_text = _PARSERS[name]
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.set_defaults(_parser=p)
        configure_tool(p)


def configure_record(rec: argparse.ArgumentParser) -> None:
    """Add the ``author record`` arguments."""
    from input.factory import add_source_arguments
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    rec.add_argument("--item", default="r_upper_arm", help="joint to drive (default r_upper_arm)")
    rec.add_argument(
        "--drive",
        default="rotation",
        choices=("rotation", "translation", "pose", "scale"),
        help="what to drive: a joint's rotation, the root's or a hand's/foot's translation (IK), "
        "or its pose (translation and rotation in one take, from a 6-DoF device)",
    )
    rec.add_argument(
        "--base", type=Path, default=None, help="a looping .ppclip whose layers play back while performing"
    )
    rec.add_argument(
        "-o", "--output", type=Path, default=Path("performed_cycle.ppclip"), help="where accepted cycles are saved"
    )
    rec.add_argument("--countdown", type=float, default=3.0, help="seconds of countdown (default 3)")
    rec.add_argument("--seconds", type=float, default=8.0, help="length of a take (default 8)")
    rec.add_argument(
        "--character",
        default=None,
        metavar="FILE.glb",
        help="draw this rigged humanoid (.glb) acting the take instead of the mannequin",
    )
    rec.add_argument("--script", choices=RECORD_SCRIPTS, default=None, help="a scripted performer instead of a hand")
    add_run_arguments(rec)
    rec.add_argument("--seed", type=int, default=0, help="seed of the extractor's probe points")
    rec.add_argument(
        "--record",
        type=output_file,
        default=None,
        help="record the take (pointer, keys or device, every step's state) to replay it later",
    )
    add_source_arguments(rec)


def configure_edit(parser: argparse.ArgumentParser) -> None:
    """Add the ``author edit`` arguments."""
    from puppetphone.argtypes import output_file, take_position
    from puppetphone.runargs import add_run_arguments

    parser.add_argument(
        "clip",
        help="a .ppclip cycle, a .bvh/.gltf/.glb motion (opened as its loop), "
        "or a default clip name (walk, run, crouch_walk, idle…)",
    )
    from puppetphone.motion_args import add_motion_options

    add_motion_options(parser)
    parser.add_argument("--retarget", action="store_true", help="a BVH/glTF motion: edit it on the puppet's skeleton")
    parser.add_argument(
        "--start",
        metavar="T0",
        type=take_position,
        help="a take: extract the loop from here (seconds, or a frame: 480f)",
    )
    parser.add_argument("--end", metavar="T1", type=take_position, help="a take: ...up to here (excluded)")
    parser.add_argument(
        "--items",
        metavar="JOINT",
        nargs="+",
        help="a take: extract the loop from these joints' "
        "motion only (the legs of a dance whose arms vary); the others keep their mean pose",
    )
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the edited cycle here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    parser.add_argument(
        "--record",
        type=output_file,
        default=None,
        help="record the session (pointer, keys, every step's state) to replay it later",
    )
    add_run_arguments(parser)


def configure_curves(parser: argparse.ArgumentParser) -> None:
    """Add the ``author curves`` arguments."""
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("clip", help="rest (a new clip), a default clip name (walk, run, …) or a .ppclip")
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip + .ppkeys)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the baked clip here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    parser.add_argument("--joint", default="l_hand", help="the joint whose trajectory is shown (default l_hand)")
    parser.add_argument("--every", type=int, default=None, help="key a clip without keys every N frames (N ≥ 3)")
    parser.add_argument("--duration", type=float, default=1.0, help="rest: the new clip's length in seconds")
    parser.add_argument("--script", choices=CURVES_SCRIPTS, default=None, help="a scripted animator instead of a hand")
    parser.add_argument(
        "--character",
        default=None,
        metavar="FILE.glb",
        help="draw this rigged humanoid (.glb) in the clip's poses instead of the mannequin",
    )
    parser.add_argument(
        "--record",
        type=output_file,
        default=None,
        help="record the session (pointer, keys, every step's state) to replay it later",
    )
    add_run_arguments(parser)


def configure_flow(parser: argparse.ArgumentParser) -> None:
    """Add the ``author flow`` arguments."""
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    parser.add_argument(
        "flow_scene",
        nargs="?",
        default="snowman",
        metavar="SCENE",
        help="snowman (default), tasbada, or a saved .flow.json file to go on editing",
    )
    parser.add_argument("-o", "--output", type=output_file, default=None, help="where Ctrl+S saves (.json)")
    parser.add_argument(
        "--script",
        choices=FLOW_SCRIPTS,
        default=None,
        help="a scripted pointer performs the edit (row: one stroke; centre: a centre-point "
        "sketched then dragged; demo: both) and the result is saved",
    )
    parser.add_argument(
        "--record",
        type=output_file,
        default=None,
        help="record the session (pointer, keys, every step's state) to replay it later",
    )
    add_run_arguments(parser, screenshot_at=True)


_PARSERS = {
    "record": (configure_record, "act a cycle out with the mouse or a device; layers stack into a clip"),
    "edit": (configure_edit, "refine a cycle with MoCurves while it plays"),
    "curves": (
        configure_curves,
        ("author a keyframed clip: pose its keys, shape its motion curves and their timing (thesis ch. 4)"),
    ),
    "flow": (configure_flow, "bend a scene's flow with sketched strokes and centre-points (Flow Curves)"),
}


def _motion_options(args: argparse.Namespace) -> dict[str, object]:
    from engine.io.motion_file import MOTION_SUFFIXES
    from puppetphone.motion_args import motion_options

    given = [
        f"--{k}"
        for k in ("animation", "units", "height", "joint_map", "retarget", "start", "end", "items")
        if getattr(args, k, None) is not None and getattr(args, k, None) is not False
    ]
    if given and Path(args.clip).suffix.lower() not in MOTION_SUFFIXES:
        raise ValueError(f"{', '.join(g.replace('_', '-') for g in given)} only apply to a BVH/glTF/GLB file")
    return {
        **motion_options(args),
        "retarget": bool(getattr(args, "retarget", False)),
        "start": getattr(args, "start", None),
        "end": getattr(args, "end", None),
        "items": getattr(args, "items", None),
    }


def _options(args: argparse.Namespace) -> dict[str, Any]:
    """The tool's options from its arguments (an edit's motion-file options resolved here)."""
    options = dict(vars(args))
    if args.scene == "edit":
        options["motion"] = _motion_options(args)
    if args.scene == "flow":
        options["progress"] = _progress
    return options


def _progress(k: int, n: int, name: str) -> None:
    print(f"SEcurves: {k + 1}/{n} {name}", file=sys.stderr, flush=True)


def _cannot_open(args: argparse.Namespace, exc: Exception) -> str:
    if args.scene == "edit":
        from puppetphone.motion_args import about

        return f"cannot open {about(args.clip, exc)}"
    what = getattr(args, "clip", None) or getattr(args, "flow_scene", None)
    return f"author {args.scene}: cannot open {what!r}: {exc}" if what else f"author {args.scene}: {exc}"


def run(args: argparse.Namespace) -> int:
    """Open the chosen tool's session, run it until the window closes (or ``--frames``), conclude it."""
    from authoring.flowcurves.storage import FlowFileError
    from authoring.session import Session
    from engine.clipfile import ClipFileError
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from input.hub import InputHub
    from puppetphone.registry import TOOLS, load_tool
    from puppetphone.runargs import run_options

    if args.scene not in TOOLS:
        print(f"choose a scene: puppetphone author {'|'.join(TOOLS)}", file=sys.stderr)
        return 2
    kind = load_tool(TOOLS[args.scene])
    source = getattr(args, "source", "mouse")
    hub = InputHub()
    if source != "mouse" and args.script is None:
        from input.factory import open_hub

        try:
            hub = open_hub(args)
        except (ValueError, OSError) as exc:
            print(f"author {args.scene}: cannot open {source}: {exc}", file=sys.stderr)
            return 2
    runner = Runner(run_options(args, kind.title, pace=hub.live and args.headless))
    try:
        runner.open()
        opened = kind.open(_options(args), runner.size)
    except NoDisplayError as exc:
        runner.close()
        hub.close()
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, OSError, ClipFileError, FlowFileError) as exc:
        runner.close()
        hub.close()
        print(_cannot_open(args, exc), file=sys.stderr)
        return 2
    session = Session(opened.simulation, hub.start(), script=opened.script)
    if args.record is not None:
        session.record(args.record, kind.name, int(getattr(args, "seed", 0)), opened.setup, source)
    _announce(hub)
    runner.push_handlers(session)
    try:
        result = runner.run(session)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        ending = opened.conclude()
        print("\n".join(line for line in ending.lines if line))
    finally:
        runner.close()
        session.close()
        if session.recorder is not None:
            print(f"recorded {session.recorder.frames} steps to {session.recorder.path}", file=sys.stderr)
    return ending.code


def _announce(hub: Any) -> None:
    from puppetphone.cmd_play import announce_web

    announce_web(hub)
