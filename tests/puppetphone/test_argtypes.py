"""Command-line values: each refused where argparse reads it, with one line and exit code 2."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest

from puppetphone.argtypes import MAX_WINDOW, int_range, output_file, port, window_size


def test_value_types():
    assert port("0") == 0 and port("65535") == 65535
    assert window_size("1280x720") == (1280, 720) and window_size(f"{MAX_WINDOW}X16") == (MAX_WINDOW, 16)
    assert int_range(1, 3)("2") == 2
    for bad in ("70000", "-1", "9000.5", ""):
        with pytest.raises(argparse.ArgumentTypeError):
            port(bad)
    for bad in ("0x0", "20000x20000", "1280", "x", "1280x720x3", "-5x10"):
        with pytest.raises(argparse.ArgumentTypeError):
            window_size(bad)


def test_output_file(tmp_path):
    assert output_file(str(tmp_path / "new.rec")) == tmp_path / "new.rec"
    (tmp_path / "old.rec").write_bytes(b"x")
    assert output_file(str(tmp_path / "old.rec")) == tmp_path / "old.rec"  # replaced, and the command says so
    for bad, reason in (
        (tmp_path / "missing" / "x.rec", "does not exist"),
        (tmp_path, "folder"),
        (Path("/dev/null"), "not a regular file"),
    ):
        with pytest.raises(argparse.ArgumentTypeError, match=reason):
            output_file(str(bad))


def _play(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    script = Path(sys.executable).with_name("puppetphone")
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "puppetphone"]
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    return subprocess.run(
        [*cmd, "play", "snowman", "--headless", "--frames", "1", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize(
    "args,says",
    [
        (("--source", "osc", "--osc-port", "70000"), "OSC port must be 0..65535"),
        (("--source", "osc", "--osc-senders", "0"), "OSC senders must be at least 1"),
        (("--size", "0x0"), "argument --size"),
        (("--size", "20000x20000"), "argument --size"),
        (("--record", "missing/x.rec"), "does not exist"),
        (("--record", "."), "it is a folder"),
        (("--frames", "-5"), "argument --frames"),
        (("--seed", "-1"), "argument --seed"),
    ],
)
def test_bad_values_give_one_line_and_exit_2(tmp_path, args, says):
    r = _play(*args, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert says in r.stderr and "Traceback" not in r.stderr
    assert r.stderr.strip().splitlines()[-1].count(says) == 1  # the reason is the last line


def test_recording_over_an_existing_file_says_so(tmp_path):
    (tmp_path / "old.rec").write_bytes(b"not a recording")
    r = _play("--record", "old.rec", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "replacing the existing old.rec" in r.stderr
    assert (tmp_path / "old.rec").read_bytes().startswith(b"PPREC\n")


def test_help_documents_the_exit_codes(tmp_path):
    script = Path(sys.executable).with_name("puppetphone")
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "puppetphone"]
    r = subprocess.run([*cmd, "play", "--help"], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert r.returncode == 0 and "exit codes: 0" in r.stdout and "WxH" in r.stdout
