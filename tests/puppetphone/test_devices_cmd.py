from puppetphone.cli import main


def test_devices_lists_where_to_send_and_draws_a_qr(capsys):
    assert main(["devices", "--osc-port", "9555"]) == 0
    out = capsys.readouterr().out
    assert "send to port 9555" in out and "HID devices:" in out and "Serial ports:" in out
    if ":9555/" in out:  # a LAN address exists: the QR code follows
        assert "Scan to pair" in out and "█" in out


def test_devices_warns_about_a_loopback_bind(capsys):
    assert main(["devices", "--osc-host", "127.0.0.1", "--no-qr"]) == 0
    assert "--osc-host 0.0.0.0" in capsys.readouterr().out


def test_the_play_command_devices_prints_listens_where_the_qr_code_points(tmp_path):
    """Pairing as a user does it: run the printed command, send to the printed LAN address."""
    import os
    import shlex
    import shutil
    import socket
    import subprocess
    import sys
    import time

    import pytest

    from input.recording import read_recording

    if shutil.which("oscsend") is None:
        pytest.skip("needs oscsend (Debian liblo-tools)")
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(tmp_path)}
    shown = subprocess.run(
        [sys.executable, "-m", "puppetphone", "devices", "--osc-port", str(port), "--no-qr"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    ).stdout
    urls = [w for w in shown.split() if w.startswith("(osc.udp://")]
    if not urls:
        pytest.skip("this machine has no LAN address to pair with")
    address = urls[0][len("(osc.udp://") :].split(":")[0]
    command = next(line.strip() for line in shown.splitlines() if line.strip().startswith("puppetphone play"))
    assert "127.0.0.1 only" in shown
    # 300 steps: five seconds of a live (paced) game, counted from its first step, so a slow start costs no
    # packet that counts; the phone below sends one every ~0.03 s and ten must arrive. (900 waited 15 s.)
    args = shlex.split(command)[1:] + ["--headless", "--frames", "300", "--record", "paired.rec"]
    game = subprocess.Popen(
        [sys.executable, "-m", "puppetphone", *args],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        # The phone streams for as long as the game runs (a game starting slowly on a busy
        # machine misses the first packets, as it would on a real phone).
        i, deadline = 0, time.monotonic() + 60.0
        while game.poll() is None and time.monotonic() < deadline:
            subprocess.run(
                ["oscsend", address, str(port), "/ZIGSIM/pair/quaternion", "ffff", "0", "0", str(0.1 * (i % 3)), "1"],
                check=True,
                timeout=10,
            )
            i += 1
            time.sleep(0.03)
        out, err = game.communicate(timeout=120)
    finally:
        game.kill()
    assert game.returncode == 0, err
    frames = read_recording(tmp_path / "paired.rec").frames
    assert sum(len(f.samples) for f in frames) >= 10, "the phone's packets never reached the game"


def test_devices_shows_the_running_web_session_with_its_qr_code(tmp_path):
    """``play --source web`` publishes its link; ``devices`` in another terminal shows it, then forgets it."""
    import os
    import re
    import subprocess
    import sys

    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(tmp_path)}
    idle = subprocess.run(
        [sys.executable, "-m", "puppetphone", "devices", "--no-qr"], capture_output=True, text=True, env=env, timeout=60
    )
    assert "no session is running" in idle.stdout and "--source web --web-host 0.0.0.0" in idle.stdout
    game = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "play",
            "sandbox",
            "--source",
            "web",
            "--web-port",
            "0",
            "--headless",
            "--frames",
            "600",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert game.stderr is not None
        printed = ""
        while "certificate SHA-256" not in printed:
            line = game.stderr.readline()
            assert line, "play ended without printing its link"
            printed += line
        url = re.search(r"https://\S+", printed).group(0)
        shown = subprocess.run(
            [sys.executable, "-m", "puppetphone", "devices"], capture_output=True, text=True, env=env, timeout=60
        ).stdout
        assert url in shown and "Scan with the phone's camera" in shown and "█" in shown
        assert re.search(r"certificate SHA-256: ([0-9A-F]{2}:){31}[0-9A-F]{2}", shown)
        assert "this machine only; a phone on the LAN needs --web-host 0.0.0.0" in shown
        game.communicate(timeout=60)
    finally:
        if game.poll() is None:
            game.kill()
        game.communicate()
    assert game.returncode == 0
    after = subprocess.run(
        [sys.executable, "-m", "puppetphone", "devices", "--no-qr"], capture_output=True, text=True, env=env, timeout=60
    )
    assert "no session is running" in after.stdout
