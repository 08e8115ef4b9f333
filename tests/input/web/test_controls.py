"""The page's buttons in the sandbox game: tap calibrates, press grabs, the slider crouches, Jump jumps."""

from __future__ import annotations

import json

from engine.components import Stick
from engine.statemachine.machine import Brain
from input.hub import InputHub
from input.sample import PoseSample
from input.source import PoseSource
from input.web.protocol import ControllerMessage, parse_message, to_sample_fields
from puppetphone.games import load_game, make_app


class Page(PoseSource):
    """Readings as the page sends them, through the same boundary as the server."""

    threaded = False

    def send(self, **fields: object) -> None:
        msg = parse_message(json.dumps({"seq": 0, "t": 0.0, "kind": "orientation", **fields}))
        assert isinstance(msg, ControllerMessage)
        self.push(PoseSample(**to_sample_fields(msg, "web:1", 0.0)))


def _states(app, page: Page, steps: int, **fields: object) -> list[str]:  # type: ignore[no-untyped-def]
    seen = []
    for _ in range(steps):
        page.send(**fields)
        app.step()
        seen += [brain.active for _, brain in app.world.query(Brain)]
    return seen


def test_buttons_drive_the_puppet():
    page = Page("page")
    game = load_game("sandbox")
    app = make_app("sandbox", 0, InputHub([page]), game.prepare(dict(game.options)))
    _states(app, page, 2, o=[0, 0, 0], touch=True)  # the first tap calibrates: this is the screen
    _states(app, page, 2, o=[0, 0, 0], touch=False)
    _states(app, page, 30, o=[0, -10, 0], touch=True)  # point at the puppet and press
    stick = app.world.query(Stick)[0][1]
    assert stick.grabbed is not None
    assert "Crouch" not in _states(app, page, 30, o=[0, -10, 0], touch=True)
    lowered = []
    for k in range(1, 41):  # the page moves the crouch at 1.5 of the slider per second
        lowered += _states(app, page, 1, o=[0, -10, 0], touch=True, crouch=min(1.0, k / 40))
    assert "Crouch" in lowered + _states(app, page, 30, o=[0, -10, 0], touch=True, crouch=1.0)
    raised = []
    for k in range(40, -1, -1):
        raised += _states(app, page, 1, o=[0, -10, 0], touch=True, crouch=k / 40)
    raised += _states(app, page, 30, o=[0, -10, 0], touch=True, crouch=0.0)
    assert "Jump" not in raised and raised[-1] == "Locomotion"
    jumped = _states(app, page, 1, o=[0, -10, 0], touch=True, jump=True)
    jumped += _states(app, page, 60, o=[0, -10, 0], touch=True)
    assert "Jump" in jumped
    _states(app, page, 2, o=[0, -10, 0], touch=False)
    assert stick.grabbed is None
