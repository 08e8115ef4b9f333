"""Tasbada, the multi-reality quest (thesis §6.4): the launcher's ``GAME``.

From the real world to a fully virtual one along the reality–virtuality continuum
(Fig. 6.9, 6.10): **real** (mark things in a photo of your room and set the floor
line) → **props alive** (a marked thing wakes up and tells the quest) → **mixed**
(your avatar, in your clothes' colour, frees creatures, gathers crystals and opens a
gate among virtual things over the photo) → **virtual** (the photo dissolves into
Tasbada). See ``games/tasbada/README.md``.

Setup (once, deterministic): the backdrop photo is ``$TASBADA_PHOTO`` or a webcam or
the shipped ``assets/room.jpg``; the selfie is ``$TASBADA_SELFIE`` or the webcam or
``assets/selfie.jpg``. Replays always use the files, never a camera or the save.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from engine.app import App
from engine.camera import OrbitCamera
from engine.ecs import World
from engine.statemachine.puppet import install_puppets
from games.base import Game
from games.tasbada import draw as draw_mod
from games.tasbada.flow import AvatarLook, SaveSlot, quest_system, save_system
from games.tasbada.objects import follow_system
from games.tasbada.quest import MIXED, STAGES, VIRTUAL, Quest
from games.tasbada.reality import SHIPPED_PHOTO, SHIPPED_SELFIE, Reality
from games.tasbada.save import SaveError, default_save_path, load_progress
from games.tasbada.view import game_camera

__all__ = ["GAME", "install", "status", "CONTROLS"]

CONTROLS = (
    "Stage 1: drag a box or draw a lasso around things in the photo; drag the dashed floor line; Done.",
    "Stage 2: the first thing you marked talks; click to skip a line; look into the camera for the selfie.",
    "Stage 3: grab your avatar and walk it to the cages, over the crystals, then through the gate.",
    "Menu (bottom right): restart from any stage you reached. Progress is saved as you go.",
)


def _is_replay(app: App) -> bool:
    from input.plugin import HubResource

    hub = app.world.try_resource(HubResource)
    return hub is not None and getattr(hub.hub, "replay", None) is not None


def install(app: App) -> None:
    """The Tasbada plugin: puppets, the quest resources and rules, the photo, saved progress."""
    app.add_plugin(install_puppets)
    world = app.world
    replay = _is_replay(app)
    q = Quest()
    explicit_save = bool(os.environ.get("TASBADA_SAVE"))
    slot = SaveSlot(default_save_path() if (explicit_save or not replay) else None)
    progress = None
    if slot.path is not None:
        try:
            progress = load_progress(slot.path)  # type: ignore[arg-type]
        except SaveError as exc:
            bad = Path(str(slot.path) + ".bad")
            os.replace(str(slot.path), bad)
            print(f"tasbada: {exc}; set aside as {bad}, starting a new journey", file=sys.stderr)
    photo = os.environ.get("TASBADA_PHOTO", "")
    if progress is not None:
        q.saved_reached = list(progress.reached)
        q.marks, q.ground_v = list(progress.marks), progress.ground_v
        if not photo and progress.photo and Path(progress.photo).is_file():
            photo = progress.photo
    selfie = os.environ.get("TASBADA_SELFIE", "") or SHIPPED_SELFIE
    webcam, message = None, ""
    if replay:
        message = "replay: using the photo files"
    elif not photo:
        from games.tasbada.webcam import open_camera

        webcam, message = open_camera(SHIPPED_PHOTO.name)
        print(f"tasbada: {message}", file=sys.stderr)
    reality = Reality(photo or SHIPPED_PHOTO, selfie, webcam, message)
    slot.photo = reality.photo_path if webcam is None else ""
    world.insert_resource(q)
    world.insert_resource(reality)
    world.insert_resource(slot)
    world.insert_resource(AvatarLook(reality.color))
    app.add_system("rules", quest_system)
    app.add_system("rules", follow_system)
    app.add_system("hash", save_system)


def status(world: World) -> list[str]:
    """Overlay lines: the stage and the quest's counters."""
    q = world.resource(Quest)
    stage = q.stage or "starting"
    n = STAGES.index(stage) + 1 if stage in STAGES else 0
    lines = [f"Tasbada · stage {n}/4: {stage}"]
    if q.stage in (MIXED, VIRTUAL) and q.freed:
        freed = sum(t >= 0 for t in q.freed)
        got = sum(t >= 0 for t in q.crystals)
        gate = "open" if q.gate_open_t >= 0 else ("glowing" if got == len(q.crystals) else "locked")
        lines.append(f"creatures freed {freed}/{len(q.freed)} · crystals {got}/{len(q.crystals)} · gate {gate}")
    reality = world.try_resource(Reality)
    if reality is not None and reality.message and q.stage != VIRTUAL:
        lines.append(reality.message)
    return lines


def _camera() -> OrbitCamera:
    return game_camera()


GAME = Game(name="tasbada", install=install, draw=draw_mod.draw, camera=_camera, status=status, controls=CONTROLS)
