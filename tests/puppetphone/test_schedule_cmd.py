"""``puppetphone schedule GAME``: the printed stages are the documented ones; no system runs twice."""

import re

import pytest

import engine.app
from engine.app import STAGES, system_name
from input.hub import InputHub
from puppetphone.cli import main
from puppetphone.games import GAMES, make_app


def _documented_stages():
    doc = engine.app.__doc__
    schedule = doc[doc.index("Frame schedule") : doc.index("Plugins\n")]
    return re.findall(r"^\d+\. ``(\w+)``", schedule, flags=re.MULTILINE)


def test_schedule_prints_the_stages_of_the_app_docstring(capsys):
    assert main(["schedule", "snowman"]) == 0
    out = capsys.readouterr().out
    printed = re.findall(r"^\d+\. (\w+)$", out, flags=re.MULTILINE)
    assert printed == _documented_stages() == list(STAGES)
    assert "     games.snowman.rules.grow_snowballs" in out
    assert "  engine.statemachine.puppet.plugin.install_puppets" in out
    assert out.index("     engine.blend.locomotion.animate") < out.index("     engine.posing.fk_system")


def test_schedule_names_the_games_it_knows(capsys):
    assert main(["schedule", "chess"]) == 2
    assert "unknown game 'chess'; games are snowman" in capsys.readouterr().err


@pytest.mark.parametrize("game", sorted(GAMES))
def test_no_system_runs_twice(game):
    app = make_app(game, 0, InputHub())
    names = [system_name(s) for stage in STAGES for s in app.systems(stage)]
    assert len(names) == len(set(names)), names
    assert "input.plugin.install_input" in app.plugins
    assert "engine.statemachine.puppet.plugin.install_puppets" in app.plugins
