"""The games the launcher knows, and how an app is assembled for one of them.

A game module (``games/<name>/game.py``, registered in :mod:`puppetphone.registry`) exposes a
:class:`games.base.Game`; the
launcher builds the simulation from its plugins plus the input plugin, so
``play``, ``replay --verify`` and the tests all assemble the same app.
"""

from __future__ import annotations

from typing import Any

from engine.app import App
from games.base import GameSetup
from input.hub import InputHub
from input.plugin import input_plugin
from puppetphone.registry import GAMES, load_game

__all__ = ["GAMES", "load_game", "make_app"]


def make_app(game: str, seed: int, hub: InputHub, setup: dict[str, Any] | None = None) -> App:
    """A headless simulation of ``game``: the setup, input first, then the game's plugins.

    ``setup`` is what the game's ``prepare`` returned (live) or what a recording's header
    carries (replay); ``None`` is the empty setup: the game's pure defaults (no save file,
    the shipped pictures, no camera). A setup's ``"clips"`` (``play --clips``) are the
    authored clips the puppets play (:mod:`engine.cliplib`).
    """
    g = load_game(game)
    app = App(seed=seed)
    app.world.insert_resource(GameSetup(setup))
    if setup and setup.get("clips") is not None:
        from puppetphone.cmd_clips import authored_resource

        app.world.insert_resource(authored_resource(setup["clips"]))
    app.add_plugin(input_plugin(hub))
    app.add_plugin(g.install)
    return app
