"""Saving, restoring and resetting the snowman field.

What a field is: the snow left (the depth grid, tracks included), every snowball
(where, how big, which ball it is packed onto), every snowman (its balls, where it
stands, its number), the first puppet, and the counters. :func:`snapshot` turns it
into a small JSON-safe dict, :func:`restore` rebuilds the world from one.

Keys in the window (``F5`` save, ``F9`` restore, ``R`` reset) reach the simulation
as recorded input events (:data:`input.sample.SAVE` …), so a replay does exactly
what the player did; each posts a :class:`~games.common.Notice` ("field saved") that
the overlay shows for two seconds, besides the terminal line. A save is kept in the :class:`FieldSlot` (the simulation
restores from there) and written to disk atomically: the game option ``field``
(``--set field=PATH``) if given, else ``$XDG_DATA_HOME/puppetphone/snowman_field.json``.
:func:`prepare` reads that file before the game is built; the field it holds goes into
the game's setup (``F9`` brings it back), which the recording's header carries, so
replays restore the same field without reading anyone's disk; replays never write it.
An F5 that its file refuses (a full disk, a read-only folder, a folder in the way) writes
the field to the user's recovery folder instead and shows that path on screen
(:mod:`engine.recovery`); the game plays on either way.
"""

from __future__ import annotations

import base64
import json
import os
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from engine.app import App
from engine.atomic import WriteError, atomic_write_bytes, set_aside
from engine.components import Transform
from engine.ecs import World
from engine.errors import FormatError
from engine.npz_safe import read_bounded
from engine.ragdoll.components import Prop
from engine.recovery import Rescue
from engine.statemachine.puppet import PuppetBody
from games.common import post_notice
from games.snowman.alive import bring_to_life
from games.snowman.components import Snowball, Snowman, SnowmanStats, Stacked, StackWatch
from games.snowman.rig import SnowmanShape
from games.snowman.rules import spawn_ball
from games.snowman.snow import SnowField
from input.sample import RESET, RESTORE, SAVE, InputFrame

__all__ = [
    "FIELD_VERSION",
    "FieldError",
    "FieldSlot",
    "snapshot",
    "restore",
    "spawn_first_puppet",
    "field_commands",
    "default_field_path",
    "load_field",
    "install_field_slot",
    "prepare",
    "replay_setup",
]

FIELD_VERSION = 1
# Limits of a field file. Counts bound the step time (1,000 balls made a step take half a
# second); sizes bound memory (the snow grid is 240x240 cells; a zlib bomb must not inflate).
MAX_BALLS, MAX_SNOWMEN, MAX_PUPPETS = 64, 32, 8
MAX_GRID = 1024
MAX_DEPTH = 10.0  # m of snow
MAX_RADIUS = 5.0  # m
MAX_EXTENT = 1000.0  # m from the centre
MAX_HEADING = 1e4  # rad
MAX_FILE = 4 << 20
#: How every field file this program writes begins (``json.dumps`` of :func:`snapshot`): only
#: such a file is ever set aside or replaced, never a user's folder, device or other file.
FIELD_HEADS = (b'{"version": 1, "balls": ',)
PUPPET_COLOR = (0.85, 0.32, 0.24)


class FieldError(FormatError):
    """A saved field that cannot be read back."""


@dataclass
class FieldSlot:
    """Resource: the last saved field and where saves go on disk (``None``: nowhere)."""

    path: Path | None = None
    saved: dict[str, Any] | None = None
    rescue: Rescue | None = None  # F5 when ``path`` refuses the save: the recovery folder (engine.recovery)


def spawn_first_puppet(
    world: World, position: np.ndarray | tuple[float, float, float] = (0.0, 0.0, 0.0), heading: float = 0.0
) -> int:
    """The player's puppet (red), as at the start of a game."""
    from games.common import spawn_player

    return spawn_player(world, position, heading, name="puppet", color=PUPPET_COLOR)


def _encode_depth(depth: np.ndarray) -> dict[str, Any]:
    raw = np.ascontiguousarray(depth, dtype="<f8").tobytes()
    return {"shape": list(depth.shape), "zlib_f8": base64.b64encode(zlib.compress(raw, 6)).decode("ascii")}


def _decode_depth(data: Any, shape: tuple[int, ...] | None) -> np.ndarray:
    if (
        not isinstance(data, dict)
        or not isinstance(data.get("shape"), list)
        or not isinstance(data.get("zlib_f8"), str)
    ):
        raise FieldError("snow grid must be an object with a shape list and zlib_f8 text")
    grid = data["shape"]
    if len(grid) != 2 or not all(isinstance(n, int) and not isinstance(n, bool) and 0 < n <= MAX_GRID for n in grid):
        raise FieldError(f"snow grid shape must be two sides of 1..{MAX_GRID} cells")
    if shape is not None and tuple(grid) != shape:
        raise FieldError(f"snow grid is {grid}, this field's is {list(shape)}")
    size = grid[0] * grid[1] * 8
    if len(data["zlib_f8"]) > 4 * size:  # base64 of zlib never grows a grid of doubles this much
        raise FieldError("snow grid text is longer than any grid of its shape")
    try:
        # Never inflate past the grid's size: a zlib bomb stops here instead of taking gigabytes.
        raw = zlib.decompressobj().decompress(base64.b64decode(data["zlib_f8"], validate=True), size + 1)
    except (ValueError, zlib.error) as exc:
        raise FieldError(f"snow grid unreadable: {exc}") from None
    if len(raw) != size:
        raise FieldError(f"snow grid holds {len(raw)} bytes, its shape needs {size}")
    depth = np.frombuffer(raw, dtype="<f8").reshape(grid).copy()
    if not np.isfinite(depth).all() or (depth < 0).any() or (depth > MAX_DEPTH).any():
        raise FieldError(f"snow grid has depths that are negative, non-finite or over {MAX_DEPTH} m")
    return depth


def snapshot(world: World) -> dict[str, Any]:
    """The field as a JSON-safe dict (see the module docstring)."""
    balls = [(e, prop, tr, sb) for e, sb, prop, tr in world.query(Snowball, Prop, Transform)]
    index = {e: i for i, (e, *_rest) in enumerate(balls)}
    stats = world.resource(SnowmanStats)
    return {
        "version": FIELD_VERSION,
        "balls": [
            {
                "position": tr.position.tolist(),
                "radius": float(prop.radius),
                "snow": float(sb.snow),
                "on": index.get(world.get(e, Stacked).on) if world.has(e, Stacked) else None,
            }
            for e, prop, tr, sb in balls
        ],
        "snowmen": [
            {
                "number": s.number,
                "bottom": s.shape.bottom,
                "middle": s.shape.middle,
                "head": s.shape.head,
                "position": world.get(e, Transform).position.tolist(),
                "heading": float(world.get(e, PuppetBody).heading),
            }
            for e, s in world.query(Snowman)
        ],
        "puppets": [
            {"position": world.get(e, Transform).position.tolist(), "heading": float(body.heading)}
            for e, body in world.query(PuppetBody)
            if not world.has(e, Snowman)
        ],
        "snow": _encode_depth(world.resource(SnowField).depth),
        "stats": {"built": stats.built, "balls_started": stats.balls_started},
    }


def _vec(value: Any, what: str) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3 or not all(_is_number(x) for x in value):
        raise FieldError(f"{what} must be three numbers, got {repr(value)[:60]}")
    v = np.asarray(value, dtype=np.float64)
    if not np.isfinite(v).all() or np.abs(v).max() > MAX_EXTENT:
        raise FieldError(f"{what} must be finite and within {MAX_EXTENT:g} m, got {repr(value)[:60]}")
    return v


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _number(value: Any, what: str, lo: float, hi: float) -> float:
    if not _is_number(value) or not lo <= value <= hi:  # NaN fails both comparisons
        raise FieldError(f"{what} must be a number in [{lo:g}, {hi:g}], got {repr(value)[:40]}")
    return float(value)


def _count(value: Any, what: str, hi: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= hi:
        raise FieldError(f"{what} must be a whole number in 0..{hi}, got {repr(value)[:40]}")
    return value


def _list(snap: dict[str, Any], key: str, limit: int) -> list[dict[str, Any]]:
    items = snap.get(key)
    if not isinstance(items, list) or not all(isinstance(x, dict) for x in items):
        raise FieldError(f"{key} must be a list of objects")
    if len(items) > limit:
        raise FieldError(f"{len(items)} {key}; a field holds at most {limit}")
    return items


def _check(snap: Any, field_shape: tuple[int, ...] | None) -> np.ndarray | None:
    """Validate the whole snapshot before anything in the world changes; returns the decoded snow grid.

    Every value :func:`restore` reads is checked here (types, finiteness, ranges, counts,
    references between balls), so a restore either happens completely or not at all.
    ``field_shape`` is the snow grid's shape, ``None`` where it is not known yet (loading).
    """
    if not isinstance(snap, dict) or snap.get("version") != FIELD_VERSION:
        raise FieldError(f"not a snowman field of version {FIELD_VERSION}")
    balls = _list(snap, "balls", MAX_BALLS)
    for b in balls:
        _vec(b.get("position"), "ball position")
        _number(b.get("radius"), "ball radius", 1e-3, MAX_RADIUS)
        _number(b.get("snow"), "ball snow", 0.0, 1e4)
        on = b.get("on")
        if on is not None and (not isinstance(on, int) or isinstance(on, bool) or not 0 <= on < len(balls)):
            raise FieldError(f"ball packed onto missing ball {repr(on)[:20]}")
    _check_stacks(balls)
    for s in _list(snap, "snowmen", MAX_SNOWMEN):
        _vec(s.get("position"), "snowman position")
        _number(s.get("heading"), "snowman heading", -MAX_HEADING, MAX_HEADING)
        _count(s.get("number"), "snowman number", 1_000_000)
        middle = s.get("middle")
        try:
            SnowmanShape(
                _number(s.get("bottom"), "snowman bottom", 1e-3, MAX_RADIUS),
                None if middle is None else _number(middle, "snowman middle", 1e-3, MAX_RADIUS),
                _number(s.get("head"), "snowman head", 1e-3, MAX_RADIUS),
            )
        except ValueError as exc:
            raise FieldError(str(exc)) from None
    for p in _list(snap, "puppets", MAX_PUPPETS):
        _vec(p.get("position"), "puppet position")
        _number(p.get("heading"), "puppet heading", -MAX_HEADING, MAX_HEADING)
    stats = snap.get("stats")
    if not isinstance(stats, dict):
        raise FieldError("stats must be an object")
    _count(stats.get("built"), "built", 1_000_000)
    _count(stats.get("balls_started"), "balls_started", 1_000_000)
    return None if snap.get("snow") is None else _decode_depth(snap["snow"], field_shape)


def _check_stacks(balls: list[dict[str, Any]]) -> None:
    """Balls packed onto balls must end on the ground: a ball on itself, or a ring, is no stack."""
    for start in range(len(balls)):
        seen, i = {start}, balls[start].get("on")
        while i is not None:
            if i in seen:
                raise FieldError(f"ball {start} is packed onto a ring of balls")
            seen.add(i)
            i = balls[i].get("on")


def restore(world: World, snap: dict[str, Any]) -> None:
    """Replace the field by ``snap``: every ball, snowman and puppet is rebuilt; nothing is
    changed if the snapshot is damaged (:class:`FieldError`)."""
    snow = world.resource(SnowField)
    depth = _check(snap, snow.depth.shape)
    for e, _ in world.query(Snowball):
        world.despawn(e)
    for e, _ in world.query(PuppetBody):
        world.despawn(e)
    snow.depth = np.full_like(snow.depth, snow.initial_depth) if depth is None else depth
    stats = world.resource(SnowmanStats)
    stats.built, stats.balls_started = int(snap["stats"]["built"]), int(snap["stats"]["balls_started"])
    world.resource(StackWatch).frames.clear()
    for p in snap["puppets"]:
        spawn_first_puppet(world, _vec(p["position"], "puppet"), float(p["heading"]))
    for s in snap["snowmen"]:
        middle = s.get("middle")  # absent or null: a two-ball snowman (as _check reads it)
        shape = SnowmanShape(float(s["bottom"]), None if middle is None else float(middle), float(s["head"]))
        bring_to_life(world, shape, _vec(s["position"], "snowman"), float(s["heading"]), int(s["number"]))
    spawned = [spawn_ball(world, _vec(b["position"], "ball"), float(b["radius"])) for b in snap["balls"]]
    world.flush()
    for e, b in zip(spawned, snap["balls"], strict=True):
        world.get(e, Transform).position = _vec(b["position"], "ball")  # spawn_ball puts it on the ground
        world.get(e, Snowball).snow = float(b["snow"])
        if b.get("on") is not None:
            world.add(e, Stacked(on=spawned[int(b["on"])]))
            world.get(e, Prop).carried = True


def start_snapshot() -> dict[str, Any]:
    """A new game: untouched snow, the puppet at the centre, no balls, nothing built."""
    return {
        "version": FIELD_VERSION,
        "balls": [],
        "snowmen": [],
        "snow": None,
        "puppets": [{"position": [0.0, 0.0, 0.0], "heading": 0.0}],
        "stats": {"built": 0, "balls_started": 0},
    }


def default_field_path() -> Path:
    """``$SNOWMAN_FIELD``, else ``$XDG_DATA_HOME/puppetphone/snowman_field.json``."""
    explicit = os.environ.get("SNOWMAN_FIELD")
    if explicit:
        return Path(explicit)
    base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "puppetphone" / "snowman_field.json"


def load_field(path: Path) -> dict[str, Any] | None:
    """The field saved at ``path`` (``None`` if there is none), validated whole.

    Raises:
        FieldError: the file is damaged, too big (over :data:`MAX_FILE`), not a regular
            file, nested too deeply, or holds a field no game could have saved.
    """
    try:
        text = read_bounded(path, MAX_FILE).decode("utf-8")
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise FieldError(f"{path}: {exc.strerror}") from None
    except ValueError as exc:  # not a regular file, too big, not UTF-8
        raise FieldError(f"{path}: {exc}") from None
    try:
        snap = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FieldError(f"{path}: not JSON ({exc.msg} at line {exc.lineno})") from None
    except RecursionError:
        raise FieldError(f"{path}: JSON nested too deeply") from None
    try:
        _check(snap, None)
    except FieldError as exc:
        raise FieldError(f"{path}: {exc}") from None
    return snap


def prepare(options: dict[str, str]) -> dict[str, Any]:
    """Read the saved field into the game's setup; a damaged field file of ours is set aside as ``.bad``.

    Raises:
        GameOptionError: the path holds something this program did not write (a folder, a
            device, someone's text file): it is left untouched and no save would replace it.
    """
    from games.base import GameOptionError

    path = Path(options["field"]).expanduser() if options["field"] else default_field_path()
    try:
        saved = load_field(path)
    except FieldError as exc:
        try:
            bad = set_aside(path, FIELD_HEADS)
        except WriteError as move:
            print(f"snowman: {exc}; {move}, starting on a fresh field", file=sys.stderr)
            return {"field": None, "save_to": str(path)}
        if bad is None:
            raise GameOptionError(
                f"snowman field {path} is not a field this program saved ({exc}); "
                "it is left as it is: choose another file with --set field=PATH"
            ) from None
        print(f"snowman: {exc}; set aside as {bad}, starting on a fresh field", file=sys.stderr)
        saved = None
    return {"field": saved, "save_to": str(path)}


def replay_setup(recorded: dict[str, Any]) -> dict[str, Any]:
    """A replay restores the recorded field but saves nowhere; a recorded field that fails the
    checks (a recording made before fields were checked) is dropped, and F9 restores nothing."""
    field = recorded.get("field")
    if field is not None:
        try:
            _check(field, None)
        except FieldError as exc:
            print(f"snowman: the recording's saved field is unusable ({exc}); F9 will not restore it", file=sys.stderr)
            field = None
    return {**recorded, "field": field, "save_to": ""}


def install_field_slot(app: App) -> None:
    """The slot, from the game's setup: the field found on disk, and where saves go."""
    from games.base import GameSetup

    setup = app.world.try_resource(GameSetup) or GameSetup()
    save_to = setup.get("save_to", "")
    app.world.insert_resource(FieldSlot(saved=setup.get("field"), path=Path(save_to) if save_to else None))


def field_commands(world: World) -> None:
    """The ``rules`` stage, first: reset, save and restore from this step's input events."""
    frame = world.try_resource(InputFrame)
    if frame is None or not frame.events:
        return
    slot = world.resource(FieldSlot)
    for kind, _source in frame.events:
        if kind == RESET:
            restore(world, start_snapshot())
            _forget_prints(world)
            _tell(world, "new field")
        elif kind == SAVE:
            slot.saved = snapshot(world)
            if slot.path is None:
                _tell(world, "field saved")
                continue
            data = json.dumps(slot.saved).encode("utf-8")
            slot.rescue = slot.rescue or Rescue(slot.path)

            def write(path: Path, data: bytes = data) -> Path:
                return atomic_write_bytes(path, data, expect_head=FIELD_HEADS)

            saved = slot.rescue.save(write)
            if saved.recovered:  # the game goes on; the field is on disk all the same, and in the slot for F9
                _tell(
                    world,
                    f"field NOT saved to its file: kept in {saved.path}",
                    f" ({saved.why}; play it with --set field={saved.path})",
                )
            elif saved.path is None:  # nowhere at all: the field stays in the slot for F9, F5 tries again
                _tell(world, "field NOT saved to disk (F9 still restores it, F5 tries again)", f": {saved.why}")
            else:
                _tell(world, "field saved", f" to {slot.path}")
        elif kind == RESTORE:
            if slot.saved is None:
                _tell(world, "nothing saved to restore (F5 saves the field)")
                continue
            try:
                restore(world, slot.saved)
                _forget_prints(world)
                _tell(world, "field restored")
            except FieldError as exc:
                _tell(world, "cannot restore the saved field", f": {exc}")


def _forget_prints(world: World) -> None:
    """A new or restored field starts without footprints (they are drawn only, never saved)."""
    from games.snowman.footprints import Footprints

    if world.try_resource(Footprints) is not None:
        world.insert_resource(Footprints())


def _tell(world: World, message: str, detail: str = "") -> None:
    """On screen for the player (a :class:`~games.common.Notice`), and with its detail on the terminal."""
    post_notice(world, message)
    print(f"snowman: {message}{detail}")
