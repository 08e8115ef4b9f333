"""The on-screen overlay: fps, physics recoveries, the game's status, what each puppet is doing, input sources,
the help, and the game's notices ("field saved").

The help shows only the controls of the sources that drive the session (a line of the
game's ``controls`` tagged ``mouse:`` is left out under ``--source web``), and all the
text is scaled with the window (a 640×360 window gets half-size text), so the puppet
in the middle of the view stays in sight.

Only reads the world; drawn as text lines into the render scene, light on the dark
panels the text renderer puts behind them (readable on snow and sky). The help is
the game's ``controls``: shown at the start, hidden and shown again by
:meth:`OverlayState.toggle_help` (H / F1 in the window). A notice a game posts
(:class:`games.common.Notice`) is drawn large in the lower middle of the window, clear
of the lines stacked at the top, and fades out after :data:`games.common.NOTICE_SECONDS`.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from engine.batches import batch
from engine.components import Name
from engine.ecs import World
from engine.ragdoll import PhysicsWorld
from engine.render.scene import RenderScene
from engine.statemachine import Brain
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.words import describe_puppets
from games.base import Game
from games.common import Notice
from input.hub import InputHub
from puppetphone.web_pairing import draw_web_pairing, web_pairing_lines

__all__ = [
    "OverlayState",
    "draw_overlay",
    "overlay_lines",
    "help_lines",
    "notice",
    "text_scale",
    "source_kinds",
    "HELP_KEYS",
    "COLORS",
    "MAX_PUPPET_LINES",
    "SOURCE_TAGS",
    "TIP_STEPS",
    "NO_VIEW",
]

#: Puppets named one per line in the overlay; the others are summed up in one line.
MAX_PUPPET_LINES = 4

HELP_KEYS = "H / F1"
COLORS = {"text": (0.96, 0.97, 1.0), "help": (0.8, 0.88, 1.0), "notice": (1.0, 0.86, 0.42)}
"""The overlay's text colours (sRGB), all light: the text renderer puts dark panels behind them."""
_SIZE, _NOTICE_SIZE = 20, 44
#: The window the text sizes above are made for; smaller windows scale them down.
_DESIGN_SIZE = (1280, 720)
#: Smallest text size in pixels (still readable).
_MIN_SIZE = 10
#: The source kinds a line of a game's ``controls`` may be tagged with.
SOURCE_TAGS = ("mouse", "osc", "web", "hid", "serial")
_NOTICE_ANCHOR = (0.5, 0.8)


#: What V says when no source can be seen from (the mouse's stick is held at the view's own eye).
NO_VIEW = "V: no held controller to see from (the mouse has no view of its own; a phone or SpaceMouse has)"

#: How long a tip (:meth:`OverlayState.tell`) stays, in simulation steps (2 s at 60 Hz).
TIP_STEPS = 120


@dataclass
class OverlayState:
    """What the player chose to see; the window's, not the world's (a replay does not repeat it).

    ``tip``: why a key did nothing (V with the mouse), shown like a notice until step
    ``tip_until``. It is the window's answer to a key, never simulation state.
    """

    help_visible: bool = True
    tip: str = ""
    tip_until: int = 0

    def toggle_help(self) -> None:
        """Hide the help if it is shown, show it if hidden."""
        self.help_visible = not self.help_visible

    def tell(self, text: str, frame: int) -> None:
        """Show ``text`` from step ``frame`` for :data:`TIP_STEPS` steps."""
        self.tip, self.tip_until = text, frame + TIP_STEPS


def overlay_lines(
    world: World, game: Game, hub: InputHub, fps: float, paused: bool, state: OverlayState | None = None
) -> list[str]:
    """The overlay's text, top to bottom (the notice apart: see :func:`draw_overlay`)."""
    state = state or OverlayState()
    hint = f"   {HELP_KEYS}: help" if game.controls and not state.help_visible else ""
    pause = "   PAUSED" if paused else ""
    physics = world.try_resource(PhysicsWorld)
    recoveries = "" if physics is None else f"   physics_recoveries {physics.recoveries}"
    lines = [f"PuppetPhone · {game.name}   {fps:5.1f} fps   frame {world.frame}{recoveries}{pause}{hint}"]
    lines += game.status(world)
    lines += _puppet_lines(world)
    for src in hub.sources:
        if type(src).__name__ == "OscSource" and not any(st.packets > 0 for st in hub.statuses()):
            lines += _pairing_lines(src)
    lines += web_pairing_lines(hub)
    for st in hub.statuses():
        # A source nothing has reached yet is waiting, not gone: "[gone]" is for a phone that was there.
        light = (
            "[live]"
            if st.connected and st.packets_per_s > 0
            else ("[idle]" if st.connected else ("[gone]" if st.packets else "[waiting for a phone]"))
        )
        err = f"  {st.last_error}" if st.last_error else ""
        lines.append(f"{light} {st.name}: {st.packets_per_s:5.1f} packets/s, dropped {st.dropped}{err}")
        if st.locked_out:
            lines.append(f"  locked out (another phone drives the stick): {', '.join(st.locked_out)}")
    return lines


def source_kinds(hub: InputHub) -> set[str]:
    """The kinds (``mouse``, ``osc``, …) of the sources driving the hub; none in a replay."""
    if hub.replay is not None:
        return set()
    return {src.name.split()[0].lower() for src in hub.sources}


def _tag(line: str) -> str | None:
    head, colon, _ = line.partition(":")
    return head if colon and head in SOURCE_TAGS else None


def help_lines(game: Game, state: OverlayState, kinds: set[str] | None = None, world: World | None = None) -> list[str]:
    """The game's controls while the help is shown, with how to hide them.

    ``kinds``: the active sources (:func:`source_kinds`); a control tagged with another
    source is left out. ``None`` shows every line. With ``world``, only the lines the game
    says apply now (``Game.controls_now``).
    """
    if not state.help_visible or not game.controls:
        return []
    lines = game.controls_now(world) if world is not None and game.controls_now is not None else game.controls
    shown = [line for line in lines if kinds is None or _tag(line) in (None, *kinds)]
    return [f"{HELP_KEYS} hides this help:", *shown] if shown else []  # the way out first: a small window cuts the end


def text_scale(size: tuple[int, int]) -> float:
    """How much smaller than at 1280×720 the overlay's text is drawn in a window of ``size`` (at most 1)."""
    return min(1.0, size[0] / _DESIGN_SIZE[0], size[1] / _DESIGN_SIZE[1])


def _scaled(points: int, scale: float) -> int:
    return max(_MIN_SIZE, round(points * scale))


def notice(world: World) -> tuple[str, float] | None:
    """The game's current notice and its opacity, or ``None`` when there is none to show."""
    posted = world.try_resource(Notice)
    if posted is None:
        return None
    alpha = posted.opacity(world.frame, world.dt)
    return (posted.text, alpha) if alpha > 0.0 else None


def _puppet_lines(world: World) -> list[str]:
    """What each puppet is doing; past :data:`MAX_PUPPET_LINES` the rest are counted by activity,
    so a crowd does not bury the screen.

    The words of a whole crowd come at once from its arrays (:func:`describe_puppets`): one
    :func:`describe_puppet` per puppet cost a thousand-puppet frame 5 ms of Python."""
    kept = batch(world, "overlay words", (Brain,), (PuppetBody,))
    brains, bodies = kept.lists
    words = describe_puppets(world, kept.entities, brains, bodies)
    lines = []
    for e, doing in zip(kept.entities[:MAX_PUPPET_LINES], words, strict=False):
        name = world.try_get(e, Name)
        lines.append(f"{name.value if name is not None else f'#{e}'}: {doing}")
    rest = Counter(words[MAX_PUPPET_LINES:])
    if rest:
        counts = ", ".join(f"{n} {doing}" for doing, n in sorted(rest.items(), key=lambda kv: (-kv[1], kv[0])))
        lines.append(f"and {sum(rest.values())} more: {counts}")
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


def draw_overlay(
    scene: RenderScene,
    world: World,
    game: Game,
    hub: InputHub,
    fps: float,
    paused: bool,
    state: OverlayState | None = None,
    size: tuple[int, int] = _DESIGN_SIZE,
) -> None:
    """Add the overlay's lines, the help (if shown), the notice (if any) and, while a web source waits
    for its phone, the QR code to the scene, sized for ``size`` (the window's; the QR code stays square)."""
    state = state or OverlayState()
    draw_web_pairing(scene, hub, size)
    scale = text_scale(size)
    for line in overlay_lines(world, game, hub, fps, paused, state):
        scene.add_text(line, size=_scaled(_SIZE, scale), color=COLORS["text"])
    for line in help_lines(game, state, source_kinds(hub), world):
        scene.add_text(line, size=_scaled(_SIZE - 2, scale), color=COLORS["help"])
    shown = notice(world)
    if shown is None and state.tip and world.frame < state.tip_until:
        shown = (state.tip, 1.0)
    if shown is not None:
        scene.add_text(
            shown[0], size=_scaled(_NOTICE_SIZE, scale), color=COLORS["notice"], anchor=_NOTICE_ANCHOR, alpha=shown[1]
        )
