"""The overlay: what each puppet is doing, the source light, pairing lines for a waiting phone,
the help that H / F1 hides and brings back, and the notices the game posts."""

from engine.app import App
from engine.render.scene import RenderScene
from games.common import NOTICE_SECONDS
from games.sandbox import GAME
from input.hub import InputHub
from input.osc import OscSource
from input.plugin import input_plugin
from input.sample import SAVE
from puppetphone.games import load_game, make_app
from puppetphone.overlay import OverlayState, draw_overlay, overlay_lines
from puppetphone.session import build_activity


def test_overlay_shows_state_and_pairing_until_a_packet_arrives():
    osc = OscSource(host="127.0.0.1", port=0)
    hub = InputHub([osc])
    try:
        app = App(seed=0)
        app.add_plugin(input_plugin(hub))
        app.add_plugin(GAME.install)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert "puppet: standing" in lines
        assert not any("Locomotion" in line for line in lines)  # words, not state names
        assert "physics_recoveries 0" in lines[0]
        assert any(f"port {osc.port}" in line for line in lines)
        assert any("--osc-host 0.0.0.0" in line for line in lines)
        assert any("[idle]" in line or "[waiting for a phone]" in line for line in lines)
        assert not any("[gone]" in line for line in lines), "nothing has come yet: waiting, not gone"
    finally:
        hub.close()


def texts(scene: RenderScene) -> list[str]:
    return [t.text for t in scene.texts]


def test_h_and_f1_hide_and_bring_back_the_help():
    import pygame

    from input.mouse import MouseSource

    session = build_activity("snowman", 0, InputHub([MouseSource()]), setup={})  # a fresh field that saves nowhere
    controls = [
        line for line in session.simulation.game.controls if not line.startswith(("osc:", "web:", "hid:", "serial:"))
    ]
    assert controls and session.simulation.overlay.help_visible  # shown at the start

    def drawn() -> list[str]:
        scene = RenderScene()
        draw_overlay(
            scene,
            session.simulation.app.world,
            session.simulation.game,
            session.hub,
            60.0,
            False,
            session.simulation.overlay,
        )
        return texts(scene)

    assert all(line in drawn() for line in controls)
    press = lambda key: session.on_event(pygame.event.Event(pygame.KEYDOWN, key=key), None)  # noqa: E731
    assert press(pygame.K_h)
    hidden = drawn()
    assert not any(line in hidden for line in controls)
    assert "H / F1: help" in hidden[0]  # how to get it back stays on screen
    assert press(pygame.K_F1)
    assert all(line in drawn() for line in controls)
    state = OverlayState()
    state.toggle_help()
    state.toggle_help()
    assert state.help_visible


def test_a_notice_is_drawn_large_and_fades_after_two_seconds_of_simulation():
    hub = InputHub()
    app = make_app("snowman", 0, hub)
    game = load_game("snowman")
    hub.command(SAVE)
    app.step()

    def notice_line():
        scene = RenderScene()
        draw_overlay(scene, app.world, game, hub, 60.0, False)
        found = [t for t in scene.texts if t.text == "field saved"]
        others = [t for t in scene.texts if t.text != "field saved"]
        return (found[0] if found else None), others

    line, others = notice_line()
    assert line is not None and line.alpha == 1.0
    assert line.anchor is not None and line.size > max(t.size for t in others)  # centred and larger
    shown = round(NOTICE_SECONDS / app.world.dt)
    app.run_steps(int(0.7 * shown))
    assert notice_line()[0].alpha == 1.0
    app.run_steps(int(0.2 * shown))
    assert 0.0 < notice_line()[0].alpha < 1.0  # fading
    app.run_steps(int(0.1 * shown) + 1)
    assert notice_line()[0] is None  # gone after two simulated seconds, however long they took


def test_overlay_names_a_locked_out_phone():
    osc = OscSource(host="127.0.0.1", port=0, admit_after=1)
    hub = InputHub([osc])
    try:
        app = make_app("sandbox", 0, hub)
        pose = b"/puppetphone/orientation\x00\x00\x00\x00,ffff\x00\x00\x00" + bytes.fromhex("3f800000") + bytes(12)
        osc.handle_datagram(pose, "osc:10.0.0.5", now=1.0)
        osc.handle_datagram(pose, "osc:10.0.0.9", now=1.0)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert any("locked out" in line and "osc:10.0.0.9" in line for line in lines)
    finally:
        hub.close()


def test_a_crowd_is_summed_up_in_one_line():
    hub = InputHub()
    app = make_app("sandbox", 0, hub, {"puppets": 12})
    app.step()
    lines = overlay_lines(app.world, GAME, hub, 60.0, False)
    named = [line for line in lines if line.startswith(("puppet:", "wanderer"))]
    assert named[0] == "puppet: standing" and len(named) == 4
    summary = [line for line in lines if line.startswith("and 8 more: ")]
    assert len(summary) == 1 and any(word in summary[0] for word in ("walking", "running", "standing"))


def test_a_crowds_lines_are_those_of_one_description_per_puppet():
    """The crowd's summary comes from its arrays (:func:`describe_puppets`); the text is what one
    :func:`describe_puppet` per puppet gives, named lines and counts alike. Broken once by counting the last
    named puppet too (``words[MAX_PUPPET_LINES - 1:]``): the summary said 997 more and it failed."""
    from collections import Counter

    from engine.components import Name
    from engine.statemachine import Brain
    from engine.statemachine.puppet.words import describe_puppet
    from puppetphone.overlay import MAX_PUPPET_LINES

    hub = InputHub()
    app = make_app("sandbox", 0, hub, {"puppets": 1000})
    app.run_steps(120)
    world = app.world
    doing = [(e, describe_puppet(world, e, brain)) for e, brain in world.query(Brain)]
    named = [f"{world.get(e, Name).value}: {words}" for e, words in doing[:MAX_PUPPET_LINES]]
    rest = Counter(words for _, words in doing[MAX_PUPPET_LINES:])
    counts = ", ".join(f"{n} {w}" for w, n in sorted(rest.items(), key=lambda kv: (-kv[1], kv[0])))
    lines = overlay_lines(world, GAME, hub, 60.0, False)
    assert lines[1 : 2 + MAX_PUPPET_LINES] == [*named, f"and 996 more: {counts}"]
    assert len(rest) >= 2  # walkers and runners: the counts are sorted, not one word


def _help_drawn(source_kind: str, size: tuple[int, int] = (1280, 720)) -> tuple[list[str], RenderScene]:
    from input.factory import make_hub

    hub = make_hub(source_kind, web_port=0, osc_port=0)
    session = build_activity("snowman", 0, hub, setup={})
    try:
        scene = RenderScene()
        draw_overlay(
            scene,
            session.simulation.app.world,
            session.simulation.game,
            hub,
            60.0,
            False,
            session.simulation.overlay,
            size,
        )
        return texts(scene), scene
    finally:
        hub.close()


def test_the_help_shows_only_the_controls_of_the_source_in_use(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))  # the web source keeps its certificate there
    mouse, _ = _help_drawn("mouse")
    web, _ = _help_drawn("web")
    assert any(line.startswith("mouse:") for line in mouse) and not any(line.startswith("web:") for line in mouse)
    assert any(line.startswith("web:") for line in web) and not any(line.startswith("mouse:") for line in web)
    assert not any(line.startswith(("osc:", "hid:", "serial:")) for line in mouse + web)
    assert any(line.startswith("keys:") for line in web)  # the game's own lines stay


def test_the_overlay_text_scales_with_a_small_window():
    _, big = _help_drawn("mouse", (1280, 720))
    _, small = _help_drawn("mouse", (640, 360))
    assert [t.text for t in big.texts] == [t.text for t in small.texts]
    assert all(s.size <= b.size / 2 + 1 for s, b in zip(small.texts, big.texts))


def test_v_with_the_mouse_says_why_nothing_happens_and_the_tip_goes_away():
    import pygame

    from input.mouse import MouseSource
    from puppetphone.overlay import NO_VIEW, TIP_STEPS

    session = build_activity("snowman", 0, InputHub([MouseSource()]), setup={})
    assert session.on_event(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_v), None)
    assert session.simulation.view == "orbit"

    def drawn() -> list[str]:
        scene = RenderScene()
        draw_overlay(
            scene,
            session.simulation.app.world,
            session.simulation.game,
            session.hub,
            60.0,
            False,
            session.simulation.overlay,
        )
        return texts(scene)

    assert NO_VIEW in drawn() and "no held controller to see from" in NO_VIEW
    session.simulation.app.run_steps(TIP_STEPS)
    assert NO_VIEW not in drawn()
