"""Every registered tool records a session and replays it with ``replay --verify``, through one session class.

Broken on purpose to see it fail: ``Session.step`` applying the decoded operations after
``advance`` instead of before (the recorded hashes then differ at the first edit), or a tool
left out of ``puppetphone.registry.TOOLS`` (its recording no longer replays: unknown tool).
"""

import pytest

from authoring.bindings import Bindings
from authoring.operations import Key, Move, Orbit, Press, Release, Zoom, decode, encode
from puppetphone.cli import main
from puppetphone.registry import TOOLS

#: A scripted session of each tool (a script is the hand, so the recording holds real operations).
RUNS = {
    "record": ["--script", "loops", "--frames", "240"],
    "edit": ["walk", "--frames", "20"],
    "curves": ["rest", "--script", "drag", "--frames", "70"],
    "flow": ["--script", "row", "--frames", "60"],
}


def test_every_registered_tool_has_a_run():
    assert set(RUNS) == set(TOOLS)


@pytest.mark.slow  # the flow scene's SEcurve search runs twice (record, replay): ~25 s of CPU
@pytest.mark.parametrize("tool", sorted(RUNS))
def test_tool_session_records_and_replays(tool, tmp_path, capsys):
    rec = tmp_path / f"{tool}.rec"
    out = ["-o", str(tmp_path / ("out.flow.json" if tool == "flow" else "out.ppclip"))]
    assert main(["author", tool, *RUNS[tool], *out, "--headless", "--record", str(rec)]) == 0
    capsys.readouterr()
    assert main(["replay", str(rec), "--verify", "--headless"]) == 0
    frames = RUNS[tool][RUNS[tool].index("--frames") + 1]
    assert f"all {frames} state hashes match" in capsys.readouterr().out


def test_operations_round_trip_and_old_forms_decode():
    for op in (
        Press(1.0, 2.0, True),
        Move(3.0, 4.0),
        Release(5.0, 6.0),
        Orbit(-2.0, 1.0),
        Zoom(1.1),
        Key("s", True, False),
    ):
        assert decode(encode(op)) == op
    assert decode(("key", "tab", False)) == Key("tab")  # a record or flow session's key before shift was kept
    assert decode(("pointer", 10, 20)) == Move(10.0, 20.0)  # the record scene's sampled drag position
    assert decode(("release",)) == Release()
    for bad in (("press", "x", 1), ("zoom", 0.0), ("size", 1.5, 2), ("warp", 1), ()):
        with pytest.raises(ValueError):
            decode(bad)


def test_bindings_are_one_mapping_left_acts_right_drag_orbits_wheel_zooms():
    import pygame

    b = Bindings()
    ev = pygame.event.Event
    assert b.operation(ev(pygame.MOUSEBUTTONDOWN, button=1, pos=(10, 20)), (100, 100)) == Press(10.0, 20.0, False)
    assert b.operation(ev(pygame.MOUSEBUTTONDOWN, button=3, pos=(10, 20)), (100, 100)) is None
    assert b.operation(ev(pygame.MOUSEMOTION, pos=(12, 20), rel=(2, 0), buttons=(0, 0, 1)), (100, 100)) == Orbit(
        2.0, 0.0
    )
    b.operation(ev(pygame.MOUSEBUTTONUP, button=3, pos=(12, 20)), (100, 100))
    assert b.operation(ev(pygame.MOUSEMOTION, pos=(13, 20), rel=(1, 0), buttons=(0, 0, 0)), (100, 100)) == Move(
        13.0, 20.0
    )
    assert b.operation(ev(pygame.MOUSEWHEEL, y=1, x=0), (100, 100)) == Zoom(1 / 1.1)
    game = Bindings(pointer_acts=False)  # a game: the left button and the wheel are the mouse source's
    assert game.operation(ev(pygame.MOUSEBUTTONDOWN, button=1, pos=(10, 20)), (100, 100)) is None
    for op in (Move(1.0, 1.0), Move(2.0, 2.0), Orbit(1.0, 0.0), Orbit(2.0, 1.0), Key("a")):
        b.queue(op)
    assert b.take() == [Move(2.0, 2.0), Orbit(3.0, 1.0), Key("a")]  # one move and one summed orbit per step


class _Counting:
    """A simulation that counts its steps and how often its state was hashed."""

    dt = 1.0 / 60.0

    def __init__(self) -> None:
        self.steps = self.hashed = 0

    def ready(self) -> bool:
        return True

    def apply(self, op) -> None:  # type: ignore[no-untyped-def]
        pass

    def advance(self, frame) -> None:  # type: ignore[no-untyped-def]
        self.steps += 1

    def digest(self) -> tuple[str, dict[str, bytes]]:
        self.hashed += 1
        return f"{self.steps:032x}", {}


def test_a_step_hashes_the_state_only_for_a_recording_or_a_check(tmp_path):
    """Play with no ``--record`` and no ``--verify`` never hashes (55 ms a step with 1000 puppets); a
    recorder gets every step's hash. Fails if ``Session.step`` hashes unconditionally again."""
    from authoring.session import Session
    from input.hub import InputHub

    sim = _Counting()
    session = Session(sim, InputHub())
    for _ in range(5):
        session.step()
    assert sim.steps == 5 and sim.hashed == 0
    recorder = session.record(tmp_path / "s.rec", "counting", 0, {}, "none")
    for _ in range(3):
        session.step()
    recorder.close()
    assert sim.steps == 8 and sim.hashed == 3 and recorder.frames == 3
