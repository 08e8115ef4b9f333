"""Tasbada's help as laid out in the window: the current stage's line only, clear of the pose picker's title."""

from __future__ import annotations

import pytest

from engine.render.scene import RenderScene
from engine.render.text import TextCache, layout_text
from games.tasbada import picker
from games.tasbada.game import CONTROLS
from games.tasbada.quest import MENU, PROPS_ALIVE, Quest
from input.hub import InputHub
from input.mouse import MouseSource
from puppetphone.overlay import draw_overlay
from puppetphone.session import build_activity


@pytest.mark.parametrize("size", [(1280, 720), (960, 540), (640, 360)])
def test_the_help_in_stage_two_ends_above_the_pose_pickers_title(size: tuple[int, int]) -> None:
    hub = InputHub([MouseSource()])
    session = build_activity(
        "tasbada",
        0,
        hub,
        setup={"pose_note": "pose: off (tasbada pose=off); drag the avatar's hands and feet to pose it"},
    )
    world = session.simulation.app.world
    q = world.resource(Quest)
    q.stage = PROPS_ALIVE
    assert q.pose_picker  # no pose in the setup: the person poses the stick figure
    scene = RenderScene()
    draw_overlay(scene, world, session.simulation.game, hub, 60.0, False, session.simulation.overlay, size)
    shown = [t.text for t in scene.texts]
    assert CONTROLS[1] in shown and CONTROLS[0] not in shown and CONTROLS[2] not in shown
    cache = TextCache(None)
    placed = layout_text(scene.texts, size, cache)
    bottom = max(p.y + cache.measure(p.text, p.size)[1] for p in placed if p.x < picker.PANEL[2] * size[0])
    assert bottom < picker.PANEL[1] * size[1], (
        f"the help reaches {bottom:.0f} px, the picker starts at {picker.PANEL[1] * size[1]:.0f} px"
    )


def test_the_menu_shows_no_help_over_its_title() -> None:
    hub = InputHub([MouseSource()])
    session = build_activity("tasbada", 0, hub, setup={})
    session.simulation.app.world.resource(Quest).stage = MENU
    scene = RenderScene()
    draw_overlay(
        scene, session.simulation.app.world, session.simulation.game, hub, 60.0, False, session.simulation.overlay
    )
    assert not any(t.text in CONTROLS or "hides this help" in t.text for t in scene.texts)
