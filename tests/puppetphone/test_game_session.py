"""A game runs in the same session class as the tools: right-drag orbits as a recorded operation,
R becomes a recorded command, and the recording replays with ``replay --verify``.

Broken on purpose to see it fail: ``GameSimulation.apply`` ignoring ``Orbit`` (the camera does not
turn, in the session or in its replay), or ``on_key`` passing R to the runner (no reset command).
"""

import pygame

from authoring.operations import Orbit, decode
from authoring.session import Session
from input.hub import InputHub
from input.sample import RESET
from puppetphone.cli import main
from puppetphone.session import GameSimulation, build_activity


class _Runner:
    size = (640, 360)


def test_game_session_orbits_records_and_replays(tmp_path, capsys):
    rec = tmp_path / "sandbox.rec"
    session = build_activity("sandbox", 3, InputHub(), record=rec)
    assert isinstance(session, Session) and isinstance(session.simulation, GameSimulation)
    yaw = session.simulation.orbit.yaw
    ev = pygame.event.Event
    assert session.on_event(ev(pygame.MOUSEBUTTONDOWN, button=3, pos=(100, 100)), _Runner()) is False
    assert session.on_event(ev(pygame.MOUSEMOTION, pos=(140, 100), rel=(40, 0), buttons=(0, 0, 1)), _Runner())
    assert session.on_event(ev(pygame.KEYDOWN, key=pygame.K_r, mod=0), _Runner())
    session.step()
    frame = session.hub.last_frame
    assert [decode(op) for op in frame.tool_operations()] == [Orbit(40.0, 0.0)]
    assert frame.has_event(RESET)
    assert session.simulation.orbit.yaw != yaw
    for _ in range(30):
        session.step()
    session.close()
    capsys.readouterr()
    assert main(["replay", str(rec), "--verify", "--headless"]) == 0
    assert "all 31 state hashes match" in capsys.readouterr().out
