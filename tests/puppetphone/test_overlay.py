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
        assert "physics_recoveries 0" in lines[0]
        assert any(f"port {osc.port}" in line for line in lines)
        assert any("--osc-host 0.0.0.0" in line for line in lines)
        assert any("[idle]" in line or "[gone]" in line for line in lines)
    finally:
        hub.close()
