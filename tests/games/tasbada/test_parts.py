"""Gestures, narration timing, image work, layout and save files of Tasbada."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from games.tasbada import marking, narrator
from games.tasbada.images import PhotoError, clothes_color, fit_photo, load_image
from games.tasbada.objects import layout
from games.tasbada.quest import Mark, Quest
from games.tasbada.save import SaveError, load_progress, progress_of, save_progress
from games.tasbada.view import floor_point, to_image


def test_a_diagonal_drag_is_a_box_and_a_closed_loop_is_a_lasso() -> None:
    box = marking.classify_path([(0.1, 0.1), (0.2, 0.15), (0.3, 0.4)])
    assert box is not None and box.kind == "box" and box.bbox == pytest.approx((0.1, 0.1, 0.3, 0.4))
    a = np.linspace(0, 2 * np.pi, 30)
    loop = marking.classify_path(np.c_[0.5 + 0.1 * np.cos(a), 0.5 + 0.1 * np.sin(a)])
    assert loop is not None and loop.kind == "lasso" and len(loop.points) == 30
    assert marking.classify_path([(0.5, 0.5), (0.505, 0.6)]) is None  # too thin: a slip


def test_menu_offers_each_reached_stage_and_buttons_hit_only_inside() -> None:
    buttons = marking.menu_buttons(["real", "props alive"], startup=True)
    assert [b.action for b in buttons] == ["restart:real", "restart:props alive", "restart:new", "close"]
    assert buttons[-1].label == "Continue: props alive"
    b = buttons[1]
    inside = np.array([(b.rect[0] + b.rect[2]) / 2, (b.rect[1] + b.rect[3]) / 2])
    assert marking.hit_button(buttons, inside) is b
    assert marking.hit_button(buttons, np.array([0.05, 0.05])) is None


def test_narration_lines_last_longer_when_longer_and_props_squash_at_contact() -> None:
    assert narrator.line_duration("a much longer line of narration") > narrator.line_duration("hi")
    assert narrator.script_line("wake", 99) == ""
    contact = narrator.prop_motion(0.0)
    air = narrator.prop_motion(1.25 / 2)
    assert contact.sy < 1.0 < contact.sx and contact.hop == pytest.approx(0.0)
    assert air.hop > 0.02 and air.sy >= 1.0
    assert narrator.prop_motion(0.3, talking=True).mouth != narrator.prop_motion(0.3).mouth


def test_image_and_floor_mapping_agree() -> None:
    p = floor_point(0.4, 0.8)
    assert p is not None and p[1] == pytest.approx(0.0)
    assert to_image(p)[0] == pytest.approx([0.4, 0.8], abs=1e-9)
    assert floor_point(0.5, 0.1) is None  # above the horizon


def test_clothes_colour_is_the_sweater() -> None:
    from tools.tasbada_assets import draw_selfie

    color = clothes_color(np.asarray(draw_selfie(sweater=(200, 40, 60))))
    assert color == pytest.approx((200 / 255, 40 / 255, 60 / 255), abs=0.08)


def test_bad_photos_get_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(PhotoError, match="no picture"):
        load_image(tmp_path / "missing.jpg")
    (tmp_path / "x.jpg").write_bytes(b"not a jpeg")
    with pytest.raises(PhotoError, match="not a readable picture"):
        load_image(tmp_path / "x.jpg")
    assert fit_photo(np.zeros((300, 300, 3), dtype=np.uint8)).shape == (540, 960, 3)


def test_layout_keeps_quest_objects_off_the_marked_things() -> None:
    free = layout(0.555)
    pot = Mark("box", [[0.44, 0.55], [0.56, 0.78]])
    crowded = layout(0.555, [pot])
    assert free.gate[0] == 0.0 and crowded.gate[0] != 0.0  # the gate steps aside, not in front of the pot
    assert np.all(np.abs(crowded.cages[:, 0]) <= 3.0)


def test_progress_round_trips_atomically_and_damage_is_reported(tmp_path: Path) -> None:
    q = Quest(stage="mixed", reached=["real", "props alive", "mixed"], ground_v=0.6)
    q.marks = [Mark("box", [[0.1, 0.2], [0.3, 0.5]]), Mark("lasso", [[0.5, 0.5], [0.6, 0.5], [0.55, 0.6]])]
    path = tmp_path / "s.json"
    save_progress(path, progress_of(q, "room.jpg"))
    back = load_progress(path)
    assert back is not None and back.reached == q.reached and back.ground_v == 0.6 and back.photo == "room.jpg"
    assert [m.kind for m in back.marks] == ["box", "lasso"] and np.allclose(back.marks[1].points, q.marks[1].points)
    assert not list(tmp_path.glob(".s.json.*"))  # no temporary left behind
    path.write_text(json.dumps({"format": "tasbada-progress", "version": 99}))
    with pytest.raises(SaveError, match="version"):
        load_progress(path)
    path.write_text("{ cut")
    with pytest.raises(SaveError, match="damaged"):
        load_progress(path)
    assert load_progress(tmp_path / "none.json") is None
