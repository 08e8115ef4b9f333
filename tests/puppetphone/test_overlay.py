"""The overlay: state of each puppet, the source light, pairing lines for a waiting phone."""

from engine.app import App
from games.sandbox import GAME
from input.hub import InputHub
from input.osc import OscSource
from input.plugin import install_input
from puppetphone.overlay import overlay_lines


def test_overlay_shows_state_and_pairing_until_a_packet_arrives():
    osc = OscSource(host="127.0.0.1", port=0)
    hub = InputHub([osc])
    try:
        app = App(seed=0)
        install_input(app, hub)
        GAME.install(app)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert any("Locomotion" in line for line in lines)
        assert any(f"port {osc.port}" in line for line in lines)
        assert any("--osc-host 0.0.0.0" in line for line in lines)
        assert any("[idle]" in line or "[gone]" in line for line in lines)
    finally:
        hub.close()


def test_overlay_names_a_locked_out_phone():
    osc = OscSource(host="127.0.0.1", port=0, admit_after=1)
    hub = InputHub([osc])
    try:
        app = App(seed=0)
        install_input(app, hub)
        GAME.install(app)
        pose = b"/puppetphone/orientation\x00\x00\x00\x00,ffff\x00\x00\x00" + bytes.fromhex("3f800000") + bytes(12)
        osc.handle_datagram(pose, "osc:10.0.0.5", now=1.0)
        osc.handle_datagram(pose, "osc:10.0.0.9", now=1.0)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert any("locked out" in line and "osc:10.0.0.9" in line for line in lines)
    finally:
        hub.close()
