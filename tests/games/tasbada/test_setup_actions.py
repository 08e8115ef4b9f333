"""Stage 1 and the pose picker through the real input path (mouse events → MotionStick → quest):
the floor line moves by its knob only, a box may start on the line, Undo takes back every set-up action."""

from __future__ import annotations

import numpy as np
import pytest

from games.tasbada.quest import MIXED, PROPS_ALIVE, Mark, Quest


@pytest.fixture
def driver():
    from games.tasbada.view import game_camera
    from input.hub import InputHub
    from input.mouse import MouseSource
    from puppetphone.games import make_app
    from tools.tasbada_demo import _Driver

    def make(setup: dict[str, object]):  # type: ignore[no-untyped-def]
        mouse = MouseSource()
        hub = InputHub([mouse]).start()
        app = make_app("tasbada", 0, hub, setup)
        made.append(hub)
        d = _Driver(app, mouse, game_camera(), None)
        d.step(3)
        return d

    made: list = []
    yield make
    for hub in made:
        hub.close()


def _px(u: float, v: float) -> tuple[float, float]:
    return (u * 1280, v * 720)


def test_a_box_started_on_the_floor_line_is_a_box_and_the_knob_moves_the_line(driver) -> None:
    from games.tasbada.marking import GROUND_HANDLE_U, REAL_BUTTONS

    d = driver({"pose_note": "test"})
    q: Quest = d.world.resource(Quest)
    v0 = q.ground_v
    d.move(_px(0.5, v0), 8)  # on the line, away from the knob
    d.press()
    d.move(_px(0.62, 0.8), 10)
    d.release()
    assert len(q.marks) == 1 and q.marks[0].kind == "box" and q.ground_v == v0
    d.move(_px(GROUND_HANDLE_U, v0), 8)  # the knob
    d.press()
    d.move(_px(GROUND_HANDLE_U, 0.65), 10)
    d.release()
    assert q.ground_v == pytest.approx(0.65, abs=0.01) and len(q.marks) == 1
    undo = next(b for b in REAL_BUTTONS if b.action == "undo").rect
    d.click(_px((undo[0] + undo[2]) / 2, (undo[1] + undo[3]) / 2), 8)
    assert q.ground_v == v0 and len(q.marks) == 1  # the line's move is taken back first
    d.click(_px((undo[0] + undo[2]) / 2, (undo[1] + undo[3]) / 2), 4)
    assert q.marks == [] and q.ground_v == v0  # then the mark
    d.click(_px((undo[0] + undo[2]) / 2, (undo[1] + undo[3]) / 2), 4)
    assert q.marks == [] and q.ground_v == v0  # nothing left: nothing happens


def test_with_no_pose_found_the_picker_poses_the_avatar(driver) -> None:
    from games.tasbada.flow import restart_from
    from games.tasbada.picker import to_panel
    from games.tasbada.posing import SelfiePose

    d = driver({"pose": {}, "pose_note": "pose: no person found in the selfie"})
    q: Quest = d.world.resource(Quest)
    assert q.pose_picker and "r_wrist" in q.pose
    q.marks = [Mark("box", [[0.49, 0.52], [0.675, 0.845]])]
    restart_from(d.world, q, PROPS_ALIVE)
    d.step(30)
    line = q.line
    start = to_panel(q.pose["r_wrist"])
    d.move(_px(*start), 6)
    d.press()
    d.move(_px(start[0] - 0.06, start[1] - 0.25), 8)
    d.release()
    assert q.line == line  # the press posed, it did not skip the narration
    moved = to_panel(q.pose["r_wrist"])
    assert moved[1] < start[1] - 0.2
    restart_from(d.world, q, MIXED)
    d.step(2)
    sp = d.world.get(q.avatar, SelfiePose)
    assert sp.posed.any() and np.isfinite(sp.rotations).all()
