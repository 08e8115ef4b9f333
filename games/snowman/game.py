"""The snowman game (thesis §6.3): roll snowballs, stack them, and they come alive.

One puppet stands in a snowy field among rocks and pine trees. Crouch-walk it to
pack and roll a snowball (it grows with the snow it picks up and leaves a bare
track); stack two or three balls, largest at the bottom — lift a ball onto
another with the stick, or let the puppet carry a small one and put it down on a
big one — and the stack comes alive as a snowman, a puppet like the first that
can build more snowmen in turn.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from engine.app import App
from engine.camera import OrbitCamera
from engine.ecs import World
from engine.statemachine.puppet import install_puppets
from games.base import Game
from games.snowman.bent_scenery import prepare_flow, recorded_flow
from games.snowman.components import SnowmanStats, StackWatch
from games.snowman.draw import draw_snowman_game, draw_snowman_state
from games.snowman.field_save import field_commands, install_field_slot, prepare, replay_setup, spawn_first_puppet
from games.snowman.footprints import Footprints, leave_footprints
from games.snowman.rules import (
    aim_putdown_on_stacks,
    assemble_snowmen,
    grow_snowballs,
    snow_drag,
    snowmen_standing,
    start_snowballs,
    stick_stacked_balls,
)
from games.snowman.scenery import SNOWFALL, build_scenery
from games.snowman.snow import SnowField

__all__ = ["GAME", "install", "CONTROLS"]

CONTROLS = (
    "mouse: press on the puppet (or a snowball) to grab it, drag to walk or run it, release to let go",
    "mouse: wheel down while holding = crouch (crouch-walk to roll a snowball), wheel up = lift",
    "mouse: a quick upward flick while holding = jump; right-drag orbits the camera",
    "osc: point the phone at the screen and tap to calibrate, touch and hold to grab; see `puppetphone devices`",
    "web: scan the QR code and look through the phone; hold the big area to grab, release to drop; Jump jumps",
    "web: the Crouch slider (or a lower phone) crouches; the Calibrate button redoes 'this is the screen'",
    "hid: SpaceMouse button 1 or the DualShock/DualSense cross grabs; push the cap or tilt the pad to walk it",
    "serial: the IMU's touch value grabs; tilt the board to walk the puppet, lower it to crouch",
    "stack 2 or 3 balls, largest at the bottom, and the snowman comes alive (a 2-ball one needs a small head on top)",
    "keys: R new field, F5 save the field, F9 restore it, P pause, H or F1 help, Esc quit",
    "G: drawing quality, low / medium / high / auto (auto follows the frame rate; --quality sets it at start)",
)


def install(app: App) -> None:
    """The field, the first puppet, the snow and the rules."""
    app.add_plugin(install_puppets)
    world = app.world
    world.insert_resource(SnowField(size=24.0, cell=0.15, initial_depth=0.12))
    world.insert_resource(SnowmanStats())
    world.insert_resource(StackWatch())
    world.insert_resource(Footprints())
    build_scenery(world)
    spawn_first_puppet(world)
    app.add_plugin(install_field_slot)
    app.add_system("rules", field_commands)
    app.add_system("rules", aim_putdown_on_stacks)
    app.add_system("rules", stick_stacked_balls)
    app.add_system("rules", snow_drag)
    app.add_system("rules", grow_snowballs)
    app.add_system("rules", start_snowballs)
    app.add_system("rules", assemble_snowmen)
    app.add_system("rules", leave_footprints)


def camera() -> OrbitCamera:
    """Looking over the field from the south-east."""
    return OrbitCamera(target=np.array([0.0, 0.6, 0.0]), yaw=0.35, pitch=0.5, distance=9.0)


def status(world: World) -> list[str]:
    """Counter of snowmen built, and a hint while a stack waits for its head (the overlay shows the controls)."""
    stats = world.resource(SnowmanStats)
    lines = [
        f"snowmen built: {stats.built}   standing: {snowmen_standing(world)}   snowballs started: {stats.balls_started}"
    ]
    if world.resource(StackWatch).headless:
        lines.append("a snowman body is waiting for its head: put a smaller ball on top")
    return lines


OPTION_HELP = {
    "field": "PATH: the saved field F5 writes and F9 restores (unset: ~/.local/share/puppetphone/snowman_field.json)",
    "flow": "FILE: a flow file from `author flow`: play in the field it bent (unset: the field as shipped)",
}


def prepare_game(options: dict[str, str]) -> dict[str, Any]:
    """The saved field, and the bent scenery of a flow file when ``flow`` names one."""
    setup = prepare(options)
    flow = prepare_flow(options.get("flow", ""))
    if flow is not None:
        setup["flow"] = flow
    return setup


def replay_game(recorded: dict[str, Any]) -> dict[str, Any]:
    """A recording's set-up, checked: the saved field (dropped when unusable) and the bent scenery."""
    setup = replay_setup(recorded)
    if setup.get("flow") is not None:
        setup["flow"] = recorded_flow(setup["flow"])
    return setup


GAME = Game(
    name="snowman",
    install=install,
    draw=draw_snowman_game,
    camera=camera,
    status=status,
    controls=CONTROLS,
    options={"field": "", "flow": ""},
    option_help=OPTION_HELP,
    prepare=prepare_game,
    replay_setup=replay_game,
    draw_state=draw_snowman_state,
    snowfall=SNOWFALL,
)
