"""A tool started with ``--source web --web-port P`` listens on P and prints the link and QR code.

Regression: ``author record`` built its hub without the web options (it listened on the
default 8443) and announced nothing. Broken on purpose to see it fail: drop ``_announce(hub)``
in ``puppetphone.cmd_author.run`` (no link), or pass only the OSC options to ``make_hub`` (wrong port).
"""

import os
import select
import socket
import subprocess
import sys
import time


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_author_record_listens_on_the_given_web_port_and_prints_the_link(tmp_path):
    port = _free_port()
    env = {
        **os.environ,
        "SDL_VIDEODRIVER": "dummy",
        "SDL_AUDIODRIVER": "dummy",
        "XDG_DATA_HOME": str(tmp_path),
        "XDG_STATE_HOME": str(tmp_path),
        "XDG_CONFIG_HOME": str(tmp_path),
    }
    cmd = [
        sys.executable,
        "-m",
        "puppetphone",
        "author",
        "record",
        "--source",
        "web",
        "--web-host",
        "127.0.0.1",
        "--web-port",
        str(port),
        "--headless",
        "--frames",
        "100000",
        "-o",
        str(tmp_path / "c.ppclip"),
    ]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=env)
    try:
        lines = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            ready, _, _ = select.select([proc.stderr], [], [], max(0.0, deadline - time.monotonic()))
            line = proc.stderr.readline() if ready else ""
            if not line:
                break  # silent for the whole minute, or ended
            lines.append(line)
            if "█" in line or "▀" in line or "▄" in line:  # the QR code follows the link
                break
        text = "".join(lines)
        assert f"https://127.0.0.1:{port}/" in text, text
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass  # listening on the port asked for
    finally:
        proc.kill()
        proc.wait()
        proc.stderr.close()
