"""Every game and authoring tool by name: what ``play``, ``author``, ``replay`` and ``schedule`` read.

A game is a module exposing ``GAME`` (:class:`games.base.Game`); a tool is a module exposing
``TOOL`` (:class:`authoring.session.ToolKind`). A recording's header names one of them (a
game by its name, a tool by its recorded name, ``author-edit``), so ``replay`` finds how to
rebuild any session here, with no special case. Adding a game or a tool is its module plus
one line below. Nothing is imported until an entry is loaded (``--help`` stays light).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:
    from authoring.session import ToolKind
    from games.base import Game

__all__ = ["GAMES", "TOOLS", "Entry", "load_game", "load_tool", "lookup"]


@dataclass(frozen=True)
class Entry:
    """One registered game or tool: its kind, its module and (for a tool) the name its recordings carry."""

    kind: Literal["game", "tool"]
    module: str
    recorded: str


GAMES: dict[str, Entry] = {
    "snowman": Entry("game", "games.snowman.game", "snowman"),
    "tasbada": Entry("game", "games.tasbada.game", "tasbada"),
    "sandbox": Entry("game", "games.sandbox", "sandbox"),
}
#: ``author SCENE`` → the tool.
TOOLS: dict[str, Entry] = {
    "record": Entry("tool", "authoring.record_tool", "author-record"),
    "edit": Entry("tool", "authoring.edit_tool", "author-edit"),
    "curves": Entry("tool", "authoring.curves_tool", "author-curves"),
    "flow": Entry("tool", "puppetphone.flow_scenes", "author-flow"),
}


def lookup(recorded: str) -> Entry:
    """The game or tool a recording names; ``ValueError`` lists the known ones."""
    for entry in (*GAMES.values(), *TOOLS.values()):
        if entry.recorded == recorded:
            return entry
    known = ", ".join(e.recorded for e in (*GAMES.values(), *TOOLS.values()))
    raise ValueError(f"unknown game or tool {recorded!r}; known: {known}")


def load_game(name: str) -> Game:
    """The game object of a registered game; ``ValueError`` lists the known ones."""
    if name not in GAMES:
        raise ValueError(f"unknown game {name!r}; games are {', '.join(GAMES)}")
    return importlib.import_module(GAMES[name].module).GAME


def load_tool(entry: Entry) -> ToolKind:
    """The tool of a registered entry."""
    return importlib.import_module(entry.module).TOOL
