"""``puppetphone clips add FILE --role R | list | remove ROLE [--clips DIR]``: the clip library games play.

``add`` reads a ``.ppclip``, ``.bvh`` or glTF file, retargets it to the puppet when it is
on another skeleton, conforms it to its role (root motion, sync markers, planted feet)
and refuses it with the reason when it cannot do the role's job (no forward speed for a
walk, not a loop, a walk faster than the run…). ``play GAME --clips DIR`` then plays
the library; without ``--clips`` a live game plays the user's default library
(``$XDG_DATA_HOME/puppetphone/clips``), and an empty or missing library means the
built-in clips.

Also the launcher's side of a library in a game (see :mod:`engine.cliplib.embed`):
:func:`library_setup` reads the library once for ``play``, :func:`authored_resource`
turns a set-up's clips back into the resource the puppet plugin builds its set from.

Exit codes: 0 done, 2 a file or library that cannot be read or a clip refused (one line
on standard error saying why).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from engine.cliplib.authored import AuthoredClips
    from engine.cliplib.library import ClipLibrary

__all__ = ["configure", "run", "library_setup", "authored_resource"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the clips sub-commands."""
    from puppetphone.motion_args import add_motion_options

    parser.add_argument(
        "--clips",
        type=Path,
        default=None,
        metavar="DIR",
        help="the library folder (default $XDG_DATA_HOME/puppetphone/clips)",
    )
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    add = sub.add_parser("add", help="add a clip (.ppclip, .bvh, .glb/.gltf) in a role, retargeted to the puppet")
    add.add_argument("file", type=Path, metavar="FILE")
    add.add_argument(
        "--role",
        required=True,
        help="idle, walk, run, crouch_idle, crouch_walk, get_up, mid_jump, a new name, or character "
        "(a rigged humanoid .glb that plays the library's clips)",
    )
    add.add_argument("--clips", type=Path, default=argparse.SUPPRESS, metavar="DIR", help="the library folder")
    add_motion_options(add)
    ls = sub.add_parser("list", help="the library's roles: clip, frames, speed, hips height, source")
    ls.add_argument("--clips", type=Path, default=argparse.SUPPRESS, metavar="DIR", help="the library folder")
    rm = sub.add_parser("remove", help="remove a role's clip (the built-in clip plays it again)")
    rm.add_argument("role")
    rm.add_argument("--clips", type=Path, default=argparse.SUPPRESS, metavar="DIR", help="the library folder")
    parser.epilog = "exit codes: 0 done; 2 an unreadable file or library, or a clip refused for its role (with why)"


def _add(library: ClipLibrary, args: argparse.Namespace) -> int:
    from engine.cliplib.roles import RoleError, check_role, conform, normalise_role
    from engine.cliplib.source import read_source, to_puppet
    from engine.clips import default_clips
    from engine.humanoid import humanoid_skeleton
    from puppetphone.motion_args import motion_options

    skeleton = humanoid_skeleton()
    try:
        role = normalise_role(args.role)
        options = motion_options(args)
        source, size_note = read_source(args.file, **options)
        clip, joint_map = to_puppet(source, skeleton, options["joint_map"])
        check_role(clip, role, skeleton)
        before = library.entries().get(role)
        entry = library.add(conform(clip, role), role, skeleton, default_clips(), source=args.file.name)
    except RoleError as exc:
        print(f"clips: {args.file.name} refused as the {args.role}: {exc}", file=sys.stderr)
        return 2
    if size_note:
        print(f"note: {args.file.name}: {size_note}")
    stored = library.load()[entry.role]
    how = f"retargeted to the puppet by the {joint_map} joint map, " if joint_map else ""
    print(
        f"added {args.file.name} as the {entry.role} ({how}{stored.num_frames} frames at {stored.fps:g} fps, "
        f"{stored.average_speed():.2f} m/s) -> {library.root / entry.file}"
    )
    if before is not None:
        print(f"replaced the {entry.role} that came from {before.source or before.file}")
    return 0


def _list(library: ClipLibrary) -> int:
    clips = library.load()
    entries = library.entries()
    if not clips:
        print(f"{library.root}: no clips; the built-in clips play")
        return 0
    print(f"{library.root}:")
    for role, clip in clips.items():
        kind = "loop" if clip.loop else "one-shot"
        print(
            f"  {role:<12} {clip.num_frames:4d} frames {kind:<8} {clip.average_speed():5.2f} m/s  "
            f"hips {float(clip.root[:, 1].mean()):.2f} m  from {entries[role].source or '?'}"
        )
    return 0


def run(args: argparse.Namespace) -> int:
    """Add, list or remove."""
    from engine.cliplib.library import ClipLibrary, ClipLibraryError, default_library_dir

    library = ClipLibrary(args.clips or default_library_dir())
    try:
        from engine.cliplib import character as lib_character

        if args.action == "add" and args.role == lib_character.CHARACTER_ROLE:
            from engine.io.motion_file import load_joint_map

            chosen = lib_character.set_character(
                library, args.file, load_joint_map(args.joint_map) if args.joint_map else None
            )
            print(f"{chosen.name} is the library's character: play without --character plays it")
            return 0
        if args.action == "add":
            return _add(library, args)
        if args.action == "list":
            return _list(library)
        if args.role == lib_character.CHARACTER_ROLE and lib_character.remove_character(library):
            print("removed the library's character; the mannequin plays again")
            return 0
        entry = library.remove(args.role)
        print(f"removed the {entry.role} ({entry.file}); the built-in {entry.role} plays it")
        return 0
    except (ClipLibraryError, OSError, ValueError) as exc:
        from puppetphone.motion_args import about

        name = getattr(args, "file", None)
        print(f"clips: {about(name.name, exc) if name else exc}", file=sys.stderr)
        return 2


def library_setup(folder: Path | None, replay: bool) -> dict[str, Any] | None:
    """The set-up value of the clips a ``play`` session plays, or ``None`` for what it would play anyway.

    A live session plays ``folder`` or, without one, the user's default library; a
    replayed one plays what its recording carries unless ``--clips`` names a folder
    (then the recorded stick drives other clips, and its state hashes no longer apply).
    The user's default library never reaches a replay. An empty library gives ``None``.

    Raises:
        engine.cliplib.library.ClipLibraryError: the library cannot be used (one line why).
    """
    from engine.cliplib.embed import encode
    from engine.cliplib.library import ClipLibrary, default_library_dir

    if replay and folder is None:
        return None
    clips = ClipLibrary(folder or default_library_dir()).load()
    if not clips:
        if folder is not None:
            print(f"note: the clip library {folder} is empty or missing; the built-in clips play", file=sys.stderr)
        return None
    if replay:
        print("note: --clips replaces the recording's clips; its state hashes no longer apply", file=sys.stderr)
    return encode(clips)


def authored_resource(value: Any) -> AuthoredClips:
    """The :class:`~engine.cliplib.authored.AuthoredClips` of a set-up's ``"clips"`` (checked, see ``decode``)."""
    from engine.cliplib.authored import AuthoredClips
    from engine.cliplib.cache import default_cache_dir
    from engine.cliplib.embed import decode
    from engine.humanoid import humanoid_skeleton

    return AuthoredClips(decode(value, humanoid_skeleton()), default_cache_dir())
