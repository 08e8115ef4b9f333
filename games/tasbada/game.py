"""Tasbada, the multi-reality quest (thesis §6.4): the launcher's ``GAME``.

From the real world to a fully virtual one along the reality–virtuality continuum
(Fig. 6.9, 6.10): **real** (mark things in a photo of your room and set the floor
line) → **props alive** (a marked thing wakes up and tells the quest) → **mixed**
(your avatar, in your clothes' colour, frees creatures, gathers crystals and opens a
gate among virtual things over the photo) → **virtual** (the photo dissolves into
Tasbada). See ``games/tasbada/README.md``.

Options (``--set key=value``; the ``$TASBADA_*`` variables are read as defaults):
``save`` — the progress file (default ``$TASBADA_SAVE`` or the user's data folder);
``photo`` — the backdrop (``$TASBADA_PHOTO``, else the save's photo, else a webcam, else
the shipped ``assets/room.jpg``); ``selfie`` (``$TASBADA_SELFIE`` or the shipped one);
``webcam`` — ``auto`` or ``off``; ``pose`` — ``auto`` (find the player's pose in the selfie
with MediaPipe when installed) or ``off`` (pose the avatar by hand); ``light`` — where the
props' shadows fall, in degrees on the floor (0 right, 90 back, 180 left; empty: as measured
from their shadows in the photo).

:func:`prepare` reads the save file and picks the pictures; :func:`install` builds the
quest from that setup alone, so a recording replays from its header. The pictures and
the webcam are display only (no simulation state depends on them) and are not recorded:
a replay shows the shipped pictures and never opens a path named in a recording.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

from engine.app import App
from engine.atomic import WriteError, set_aside
from engine.camera import OrbitCamera
from engine.ecs import World
from engine.statemachine.puppet import install_puppets
from games.base import Game, GameOptionError, GameSetup
from games.tasbada import draw as draw_mod
from games.tasbada.flow import AvatarLook, SaveSlot, quest_system, save_system
from games.tasbada.objects import follow_system
from games.tasbada.picker import panel_aspect
from games.tasbada.pose import default_keypoints
from games.tasbada.pose import validate as validate_pose
from games.tasbada.posing import selfie_pose_system
from games.tasbada.quest import MIXED, PROPS_ALIVE, REAL, STAGES, VIRTUAL, Mark, Quest
from games.tasbada.reality import SHIPPED_PHOTO, SHIPPED_SELFIE, Reality
from games.tasbada.save import SAVE_HEADS, SaveError, checked_progress, default_save_path, load_progress
from games.tasbada.view import game_camera

__all__ = ["GAME", "install", "prepare", "replay_setup", "status", "CONTROLS"]

CONTROLS = (
    "Stage 1: drag a box or draw a lasso around things in the photo; drag the floor line by its knob; Undo; Done.",
    "Stage 2: the first thing you marked talks; click to skip a line; look into the camera for the selfie.",
    "Stage 3: grab your avatar and walk it to the cages, over the crystals, then through the gate.",
    "Menu (bottom right): restart from any stage you reached. Progress is saved as you go.",
)


OPTION_HELP = {
    "save": "PATH: the progress file (unset: $TASBADA_SAVE, else the user's data folder)",
    "photo": "IMAGE: the backdrop (unset: $TASBADA_PHOTO, else the save's photo, else a webcam, else the shipped room)",
    "selfie": "IMAGE: the player's selfie (unset: $TASBADA_SELFIE, else the shipped one)",
    "webcam": "auto|off: a live webcam backdrop when no photo is given",
    "pose": "auto|off: find the player's pose in the selfie (MediaPipe, the [pose] extra) or pose by hand",
    "light": "DEGREES, any finite number: where shadows fall on the floor (0 right, 90 back, 180 left; "
    "unset: measured from the photo)",
}


def controls_now(world: World) -> tuple[str, ...]:
    """The current stage's line (the menu's too in the first stage): the whole list covered the pose picker's title."""
    stage = world.resource(Quest).stage
    by_stage = {REAL: 0, PROPS_ALIVE: 1, MIXED: 2}
    now = (CONTROLS[by_stage[stage]],) if stage in by_stage else ()
    return now + (CONTROLS[-1],) if stage == REAL else now


def prepare(options: dict[str, str]) -> dict[str, Any]:
    """Read the save file (a damaged one is set aside) and choose the pictures."""
    if options["webcam"] not in ("auto", "off"):
        raise GameOptionError(f"tasbada webcam must be auto or off, not {options['webcam']!r}")
    save = Path(options["save"] or os.environ.get("TASBADA_SAVE") or default_save_path()).expanduser()
    progress = None
    try:
        progress = load_progress(save)
    except SaveError as exc:
        try:
            bad = set_aside(save, SAVE_HEADS)
        except WriteError as move:
            print(f"tasbada: {exc}; {move}, starting a new journey", file=sys.stderr)
        else:
            if bad is None:
                raise GameOptionError(
                    f"tasbada save {save} is not progress this program saved ({exc}); it is "
                    "left as it is: choose another file with --set save=PATH"
                ) from None
            print(f"tasbada: {exc}; set aside as {bad}, starting a new journey", file=sys.stderr)
    photo = options["photo"] or os.environ.get("TASBADA_PHOTO", "")
    if not photo and progress is not None and progress.photo and Path(progress.photo).is_file():
        photo = progress.photo
    selfie = options["selfie"] or os.environ.get("TASBADA_SELFIE", "") or str(SHIPPED_SELFIE)
    for label, path in (("photo", photo), ("selfie", selfie)):
        if path and not Path(path).is_file():
            raise GameOptionError(f"tasbada {label} {path!r} is not a file")
    if options["pose"] not in ("auto", "off"):
        raise GameOptionError(f"tasbada pose must be auto or off, not {options['pose']!r}")
    light = options["light"].strip()
    try:
        light_deg = float(light) if light else None
    except ValueError:
        raise GameOptionError(f"tasbada light must be a number of degrees, not {light!r}") from None
    if light_deg is not None and not np.isfinite(light_deg):
        raise GameOptionError(f"tasbada light must be a finite number of degrees, not {light!r}")
    found, aspect, note = _selfie_pose(selfie, options["pose"] == "auto")
    return {
        "save_to": str(save),
        "reached": list(progress.reached) if progress else [],
        "marks": [m.to_json() for m in progress.marks] if progress else [],
        "ground_v": progress.ground_v if progress else None,
        "photo": photo,
        "selfie": selfie,
        "webcam": not photo and options["webcam"] == "auto",
        "pose": found or {},
        "pose_aspect": aspect,
        "pose_note": note,
        "light": light_deg,
    }


def _selfie_pose(selfie: str, auto: bool) -> tuple[dict[str, list[float]] | None, float, str]:
    """The player's keypoints in the selfie (recorded in the set-up: a replay needs no estimator)."""
    from games.tasbada.images import PhotoError, load_image
    from games.tasbada.pose import estimate

    if not auto:
        return None, 1.0, "pose: off (tasbada pose=off); drag the avatar's hands and feet to pose it"
    try:
        img = load_image(selfie)
    except PhotoError as exc:
        raise GameOptionError(f"tasbada selfie: {exc}") from exc
    points, note = estimate(img)
    print(f"tasbada: {note}", file=sys.stderr)
    return points, img.shape[1] / img.shape[0], note


def replay_setup(recorded: dict[str, Any]) -> dict[str, Any]:
    """A recording's set-up, checked value by value; a replay saves nowhere, opens no camera and no file.

    The recorded photo and selfie paths are dropped (the shipped pictures are shown): a
    recording is self-contained, and a path in it must never make a replay read the
    replaying person's disk. The quest values are checked like a save's (:func:`checked_progress`).

    Raises:
        GameOptionError: a value of the wrong type or range (the recording was altered).
    """
    try:
        reached, marks, ground_v = checked_progress(
            recorded.get("reached", []), recorded.get("marks", []), recorded.get("ground_v")
        )
    except SaveError as exc:
        raise GameOptionError(f"the recorded progress: {exc}") from None
    aspect, light, note = recorded.get("pose_aspect", 1.0), recorded.get("light"), recorded.get("pose_note", "")
    if isinstance(aspect, bool) or not isinstance(aspect, (int, float)) or not 0.01 <= aspect <= 100.0:
        raise GameOptionError(f"the recorded pose_aspect {repr(aspect)[:30]} is not a number in [0.01, 100]")
    if light is not None and (isinstance(light, bool) or not isinstance(light, (int, float)) or not np.isfinite(light)):
        raise GameOptionError(f"the recorded light {repr(light)[:30]} is not a finite number of degrees")
    if not isinstance(note, str):
        raise GameOptionError("the recorded pose_note is not text")
    return {
        **recorded,
        "save_to": "",
        "webcam": False,
        "photo": "",
        "selfie": "",
        "reached": reached,
        "marks": [m.to_json() for m in marks],
        "ground_v": ground_v,
        "pose_note": note[:500],
    }


def install(app: App) -> None:
    """The Tasbada plugin: puppets, the quest (with the saved progress) and its rules, the photo."""
    app.add_plugin(install_puppets)
    world = app.world
    setup = world.try_resource(GameSetup) or GameSetup()
    q = Quest()
    q.saved_reached = list(setup.get("reached", []))
    q.marks = [Mark.from_json(m) for m in setup.get("marks", [])]
    if setup.get("ground_v") is not None:
        q.ground_v = float(setup.get("ground_v"))
    q.pose = validate_pose(setup.get("pose")) or {}
    q.pose_aspect = float(setup.get("pose_aspect", 1.0) or 1.0)
    if not q.pose:  # nothing from the selfie: the person poses a stick figure by hand
        q.pose, q.pose_aspect, q.pose_picker = default_keypoints(), panel_aspect(), True
    photo = setup.get("photo", "")
    webcam, message = None, ""
    if setup.get("webcam", False):
        from games.tasbada.webcam import open_camera

        webcam, message = open_camera(SHIPPED_PHOTO.name)
        print(f"tasbada: {message}", file=sys.stderr)
    elif not photo:
        message = f"using the photo {SHIPPED_PHOTO.name}"
    light = setup.get("light")
    reality = Reality(
        photo or SHIPPED_PHOTO,
        setup.get("selfie", "") or SHIPPED_SELFIE,
        webcam,
        message,
        light_deg=float(light) if isinstance(light, (int, float)) and np.isfinite(light) else None,
    )
    reality.pose_note = str(setup.get("pose_note", ""))
    save_to = setup.get("save_to", "")
    slot = SaveSlot(Path(save_to) if save_to else None)
    slot.photo = reality.photo_path if webcam is None else ""
    world.insert_resource(q)
    world.insert_resource(reality)
    world.insert_resource(slot)
    world.insert_resource(AvatarLook(reality.color))
    app.add_system("animation", selfie_pose_system)
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
    if reality is not None and reality.pose_note and q.stage in (PROPS_ALIVE, MIXED):
        lines.append(reality.pose_note)
    return lines


def _camera() -> OrbitCamera:
    return game_camera()


def close(world: World) -> None:
    """Let the props' worker finish and free the webcam."""
    reality = world.try_resource(Reality)
    if reality is not None:
        reality.close()


GAME = Game(
    name="tasbada",
    install=install,
    draw=draw_mod.draw,
    camera=_camera,
    status=status,
    controls=CONTROLS,
    controls_now=controls_now,
    options={"save": "", "photo": "", "selfie": "", "webcam": "auto", "pose": "auto", "light": ""},
    option_help=OPTION_HELP,
    prepare=prepare,
    replay_setup=replay_setup,
    close=close,
)
