"""The on-screen overlay: fps, the game's status, each puppet's state, input sources.

Only reads the world; drawn as text lines into the render scene.
"""

from __future__ import annotations

from engine.ecs import World
from engine.render.scene import RenderScene
from engine.statemachine import Brain
from games.base import Game
from input.hub import InputHub

__all__ = ["draw_overlay", "overlay_lines"]


def overlay_lines(world: World, game: Game, hub: InputHub, fps: float, paused: bool) -> list[str]:
    """The overlay's text, top to bottom."""
    lines = [f"PuppetPhone · {game.name}   {fps:5.1f} fps   frame {world.frame}" + ("   PAUSED" if paused else "")]
    lines += game.status(world)
    for e, brain in world.query(Brain):
        events = ", ".join(brain.last_events[-3:])
        lines.append(f"#{e} {brain.active}" + (f"  ({events})" if events else ""))
    for src in hub.sources:
        if type(src).__name__ == "OscSource" and not any(st.packets > 0 for st in hub.statuses()):
            lines += _pairing_lines(src)
    for st in hub.statuses():
        light = "[live]" if st.connected and st.packets_per_s > 0 else ("[idle]" if st.connected else "[gone]")
        err = f"  {st.last_error}" if st.last_error else ""
        lines.append(f"{light} {st.name}: {st.packets_per_s:5.1f} packets/s, dropped {st.dropped}{err}")
        if st.locked_out:
            lines.append(f"  locked out (another phone drives the stick): {', '.join(st.locked_out)}")
    return lines


def _pairing_lines(source: object) -> list[str]:
    """Where a phone should send, until the first packet arrives (the pairing overlay)."""
    from input.pairing import pairing_info

    host = getattr(source, "host", "0.0.0.0")
    info = pairing_info(int(getattr(source, "port", 9000)), host)
    lines = info.lines()[:4]
    if host.startswith("127."):
        lines.append("  listening on 127.0.0.1 only: phones on the LAN need --osc-host 0.0.0.0")
    return lines


def draw_overlay(scene: RenderScene, world: World, game: Game, hub: InputHub, fps: float, paused: bool) -> None:
    """Add the overlay's lines to the scene."""
    for line in overlay_lines(world, game, hub, fps, paused):
        scene.add_text(line, size=16, color=(0.06, 0.08, 0.14))
