"""The journey's rules: the pointer, the stage flow, the narration clock, the menu.

One system, :func:`quest_system`, runs in the ``rules`` stage. It reads the
MotionStick (where it points on the photo; touch presses and releases from the
recorded ``InputFrame``) and moves the quest along:

- **real** — gestures mark objects and move the floor line (:mod:`games.tasbada.marking`);
  *Done* with at least one mark wakes the props;
- **props alive** — the narrator tells the quest line by line (a touch skips ahead),
  then counts down for the selfie;
- **mixed** — the avatar appears in the person's colours among the quest objects;
  milestones (:mod:`games.tasbada.objects`) change what the narrator says;
- **virtual** — reached when the gate has been open for a moment.

Each stage change prints ``stage: <name>`` (output only) and marks the progress for
saving; the save itself happens in :func:`save_system` outside the hashed state. A save
that its file refuses (a full disk, a read-only folder) goes to the user's recovery folder
instead, with one line naming it (:mod:`engine.recovery`); the journey goes on either way.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from engine.components import Stick
from engine.ecs import World
from engine.recovery import Rescue
from engine.render.components import Appearance
from games.common import post_notice
from games.tasbada import marking, narrator, objects
from games.tasbada.picker import picker_step
from games.tasbada.pose import lift
from games.tasbada.posing import SelfiePose
from games.tasbada.quest import MENU, MIXED, PROPS_ALIVE, REAL, STAGES, VIRTUAL, Quest
from games.tasbada.view import to_image
from input.sample import TOUCH_DOWN, TOUCH_UP, InputFrame

__all__ = ["SaveSlot", "AvatarLook", "quest_system", "save_system", "enter_stage", "restart_from"]


class SaveSlot:
    """Where progress goes (``None``: nowhere) and whether it changed; not simulation state."""

    SIM_STATE = False

    def __init__(self, path: str | os.PathLike[str] | None = None, photo: str = "") -> None:
        self.path = path
        self.photo = photo
        self.dirty = False
        self.error = ""
        self.rescue: Rescue | None = None  # where progress goes when ``path`` refuses it (engine.recovery)


class AvatarLook:
    """The avatar's colour from the selfie at setup (display only; the webcam may replace it)."""

    SIM_STATE = False

    def __init__(self, color: tuple[float, float, float] = (0.2, 0.55, 0.6)) -> None:
        self.color = color


def _slot_dirty(world: World) -> None:
    slot = world.try_resource(SaveSlot)
    if slot is not None:
        slot.dirty = True


def enter_stage(world: World, q: Quest, stage: str) -> None:
    """Switch to ``stage`` now: print it, start its narration, spawn what it needs."""
    now = world.time
    q.stage, q.stage_t, q.menu_open = stage, now, False
    if stage in STAGES and stage not in q.reached:
        q.reached.append(stage)
    if stage == PROPS_ALIVE or (stage in (MIXED, VIRTUAL) and q.alive_t < 0):
        q.alive_t = now
    if stage == PROPS_ALIVE:
        _say(q, "wake", now)
    elif stage == MIXED:
        _spawn_mixed(world, q)
        _say(q, "mixed", now)
    elif stage == VIRTUAL:
        _say(q, "virtual", now)
    if stage != MENU:
        print(f"stage: {stage}", flush=True)
        _slot_dirty(world)


def _say(q: Quest, script: str, now: float) -> None:
    q.script, q.line, q.line_t = script, 0, now


def _spawn_mixed(world: World, q: Quest) -> None:
    from engine.statemachine.puppet import spawn_puppet

    objects.despawn_objects(world)
    if q.avatar is not None and world.alive(q.avatar):
        world.despawn(q.avatar)
    objects.spawn_objects(world, q)
    look = world.try_resource(AvatarLook) or AvatarLook()
    start = objects.layout(q.ground_v, q.marks).start
    extra: tuple[object, ...] = (Appearance(color=look.color),)
    if q.pose:
        rotations, posed = lift(q.pose, q.pose_aspect)
        extra += (SelfiePose(rotations, posed, world.time),)
    # Facing the camera, as the person did for the selfie (grabbing it turns it where it walks).
    q.avatar = spawn_puppet(world, start, heading=0.0, name="avatar", extra=extra)


def restart_from(world: World, q: Quest, stage: str) -> None:
    """The menu's restart: back to the start of ``stage`` (``"new"``: a fresh journey)."""
    if stage == "new":
        q.marks.clear()
        q.saved_reached.clear()
        q.reached = [REAL]
        stage = REAL
    if stage == REAL:
        q.marks.clear()
        q.undo.clear()
    q.alive_t = -1.0
    q.script, q.line, q.selfie_t = "", -1, -1.0
    q.gesture, q.path = "", []
    if stage in (REAL, PROPS_ALIVE):
        objects.despawn_objects(world)
        if q.avatar is not None and world.alive(q.avatar):
            world.despawn(q.avatar)
        q.avatar, q.freed, q.crystals = None, [], []
    enter_stage(world, q, stage)
    if stage == VIRTUAL:
        _spawn_mixed(world, q)
        now = world.time
        q.freed = [now] * len(q.freed)
        q.crystals = [now] * len(q.crystals)
        q.crystals_shown_t = q.gate_open_t = now
        _say(q, "virtual", now)


def _pointer(world: World, q: Quest) -> tuple[bool, bool]:
    """Update ``q.pointer`` from the stick; ``(pressed, released)`` this step."""
    rows = world.query(Stick)
    if not rows:
        return False, False
    stick = rows[0][1]
    uv = to_image(stick.tip)[0]
    if np.all(np.isfinite(uv)):
        q.pointer = np.clip(uv, -0.5, 1.5)
    frame = world.try_resource(InputFrame)
    if frame is None:
        return False, False
    src = stick.source if stick.source not in ("", "*") else None
    return frame.has_event(TOUCH_DOWN, src), frame.has_event(TOUCH_UP, src)


def _menu(world: World, q: Quest, pressed: bool) -> None:
    reached = [s for s in STAGES if s in q.reached or s in q.saved_reached]
    if not pressed:
        return
    b = marking.hit_button(marking.menu_buttons(reached, q.stage == MENU), q.pointer)
    if b is None:
        return
    if b.action == "close":
        if q.stage == MENU:
            restart_from(world, q, reached[-1] if reached else REAL)
        q.menu_open = False
    else:
        restart_from(world, q, b.action.split(":", 1)[1])


def _real(world: World, q: Quest, pressed: bool, released: bool) -> None:
    p = q.pointer
    if pressed:
        b = marking.hit_button(marking.REAL_BUTTONS, p)
        if b is not None:
            q.gesture = "button:" + b.action
        elif marking.on_ground_handle(p, q.ground_v):
            q.gesture = "ground"
            q.undo.append(["ground", q.ground_v])
        else:
            q.gesture, q.path = "draw", [(float(p[0]), float(p[1]))]
        q.down = True
    if q.down and q.gesture == "ground":
        q.ground_v = marking.clamp_ground(float(p[1]))
    elif q.down and q.gesture == "draw":
        last = q.path[-1]
        if np.hypot(p[0] - last[0], p[1] - last[1]) > 0.004:
            q.path.append((float(np.clip(p[0], 0, 1)), float(np.clip(p[1], 0, 1))))
    if released and q.down:
        q.down = False
        gesture, q.gesture = q.gesture, ""
        if gesture == "draw":
            q.path.append((float(np.clip(p[0], 0, 1)), float(np.clip(p[1], 0, 1))))
            mark = marking.classify_path(q.path)
            if mark is not None and len(q.marks) < marking.MAX_MARKS:
                q.marks.append(mark)
                q.undo.append(["mark", float(len(q.marks))])
            q.path = []
        elif gesture == "ground" and q.undo and q.undo[-1] == ["ground", q.ground_v]:
            q.undo.pop()  # the line did not move: nothing to undo
        elif gesture.startswith("button:"):
            b = marking.hit_button(marking.REAL_BUTTONS, p)
            if b is not None and gesture == "button:" + b.action:
                if b.action == "undo":
                    _undo(q)
                elif b.action == "done" and q.marks:
                    enter_stage(world, q, PROPS_ALIVE)


def _undo(q: Quest) -> None:
    """Take back the last set-up action: a mark, or a move of the floor line."""
    while q.undo:
        kind, value = q.undo.pop()
        if kind == "ground":
            q.ground_v = float(value)
            return
        if kind == "mark" and len(q.marks) == int(value):
            q.marks.pop()
            return
    if q.marks:  # marks restored from a save have no history: take the last one
        q.marks.pop()


def _advance_line(world: World, q: Quest, pressed: bool) -> None:
    """Narration clock: the line ends after its reading time, or at a touch."""
    text = narrator.script_line(q.script, q.line)
    if not text:
        return
    now = world.time
    beat = narrator.SELFIE_BEAT if q.script == "selfie" else narrator.line_duration(text)
    skip = pressed and q.script not in ("selfie",) and now - q.line_t > 0.3
    if now - q.line_t >= beat or skip:
        q.line, q.line_t = q.line + 1, now
        if q.script == "wake" and not narrator.script_line("wake", q.line):
            _say(q, "selfie", now)
            q.selfie_t = now
        elif q.script == "selfie" and not narrator.script_line("selfie", q.line):
            enter_stage(world, q, MIXED)


def _milestones(world: World, q: Quest) -> None:
    hits = objects.milestone_step(world, q)
    now = world.time
    for h in hits:
        if h.startswith("freed ") and h != f"freed {len(q.freed)}":
            _say(q, "freed", now)
            q.line = int(h.split()[1]) - 1
        elif h == "creatures free":
            _say(q, "crystals", now)
        elif h == "crystals gathered":
            _say(q, "gate", now)
    if hits:
        _slot_dirty(world)
    if q.gate_open_t >= 0 and now - q.gate_open_t >= objects.GATE_DELAY and q.stage == MIXED:
        enter_stage(world, q, VIRTUAL)


def quest_system(world: World) -> None:
    """The ``rules`` stage: pointer, menu, stage logic, narration, milestones."""
    q = world.resource(Quest)
    pressed, released = _pointer(world, q)
    if not q.stage:
        enter_stage(world, q, MENU if len(q.saved_reached) > 1 else REAL)
        return
    if q.stage == MENU or q.menu_open:
        _menu(world, q, pressed)
        return
    if pressed and marking.MENU_BUTTON.contains(q.pointer):
        q.menu_open = True
        return
    if q.stage == REAL:
        _real(world, q, pressed, released)
        return
    if q.pose_picker and q.stage == PROPS_ALIVE and picker_step(q, pressed, released):
        return
    _advance_line(world, q, pressed)
    if q.stage in (MIXED, VIRTUAL):
        _milestones(world, q)


def save_system(world: World) -> None:
    """Write the progress when it changed (after the hash stage; output only)."""
    slot = world.try_resource(SaveSlot)
    if slot is None or not slot.dirty or slot.path is None:
        return
    from games.tasbada.save import progress_of, save_progress

    slot.dirty = False
    slot.rescue = slot.rescue or Rescue(Path(slot.path))
    progress = progress_of(world.resource(Quest), slot.photo)
    saved = slot.rescue.save(lambda path: save_progress(path, progress))
    if saved.why and saved.why != slot.error:  # one line per new trouble; the journey goes on either way
        line = saved.line("progress", slot.rescue.target)
        hint = f"; play on from it with --set save={saved.path}" if saved.path else ""
        print(f"tasbada: {line}{hint}", file=sys.stderr)
        post_notice(world, f"progress kept in {saved.path}" if saved.path else "progress NOT saved (see the terminal)")
    slot.error = saved.why
