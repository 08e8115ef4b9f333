"""A recording keeps the versions of the libraries that change numbers; ``replay`` says when they differ.

Broken on purpose to see these fail: the header written without ``libraries`` (the round trip
and the note test fail), ``replay`` not comparing them (no note), and the reader requiring
the field (every shipped recording, made before it, refused: the old-header test fails).
"""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

from input.hub import InputHub
from input.library_versions import NUMERIC_LIBRARIES, numpy_simd_level, running_versions, version_difference
from input.recording import MAGIC, Recorder, RecordingError, RecordingHeader, read_recording
from puppetphone.games import make_app

ROOT = Path(__file__).resolve().parents[2]


def _replay(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", "replay", str(path), "--verify", "--headless"],
        env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )


def _with_header(path: Path, edit) -> None:  # type: ignore[no-untyped-def]
    """Rewrite a recording's header (with its checksum), keeping every record."""
    data = path.read_bytes()
    n, _ = struct.unpack_from("<II", data, len(MAGIC))
    start = len(MAGIC) + 8
    head = json.loads(data[start : start + n])
    edit(head)
    raw = json.dumps(head, sort_keys=True).encode()
    path.write_bytes(MAGIC + struct.pack("<II", len(raw), zlib.crc32(raw)) + raw + data[start + n :])


GATE_TOOLS = ("mypy", "ruff")  # pinned so the type and lint gate flags the same things everywhere


def test_the_list_is_exactly_what_constraints_pins() -> None:
    pinned = [
        line.split("==")[0].strip().lower()
        for line in (ROOT / "constraints.txt").read_text().splitlines()
        if "==" in line and not line.lstrip().startswith("#")
    ]
    assert sorted(NUMERIC_LIBRARIES) == sorted(p for p in pinned if p not in GATE_TOOLS)


def test_one_line_names_what_differs() -> None:
    now = {"mujoco": "3.17.0", "numpy": "2.4.6"}
    assert version_difference({"mujoco": "3.17.0", "numpy": "2.4.6"}, now) == ""
    assert version_difference({}, now) == ""  # an older recording: nothing to compare
    assert (
        version_difference({"mujoco": "4.0.0", "numpy": "2.4.6"}, now)
        == "recorded with mujoco 4.0.0, running 3.17.0: hashes may differ"
    )
    two = version_difference({"mujoco": "4.0.0", "numpy": "2.3.0", "daqp": "0.11.0"}, now)
    assert (
        two == "recorded with mujoco 4.0.0, numpy 2.3.0, daqp 0.11.0; running mujoco 3.17.0, numpy 2.4.6, daqp none: "
        "hashes may differ"
    )


@pytest.fixture
def recording(tmp_path: Path) -> Path:
    app = make_app("sandbox", 5, InputHub())
    path = tmp_path / "s.rec"
    with Recorder(path, RecordingHeader("sandbox", 5, app.world.dt)) as rec:
        rec.attach(app)
        app.run_steps(10)
    return path


def test_a_new_recording_keeps_the_running_versions_and_replays_without_a_note(recording: Path) -> None:
    assert read_recording(recording).header.libraries == running_versions()
    assert set(running_versions()) == {*NUMERIC_LIBRARIES, "numpy-simd", "machine"}
    assert running_versions()["numpy"] != "none" and running_versions()["numpy-simd"] == numpy_simd_level()
    done = _replay(recording)
    assert done.returncode == 0 and "hashes may differ" not in done.stderr, done.stderr


def test_a_recording_made_with_another_mujoco_says_so_in_one_line_and_still_replays(recording: Path) -> None:
    running = running_versions()["mujoco"]
    _with_header(recording, lambda head: head["libraries"].update(mujoco="0.0.1"))
    done = _replay(recording)
    notes = [line for line in done.stderr.splitlines() if "hashes may differ" in line]
    assert notes == [f"note: recorded with mujoco 0.0.1, running {running}: hashes may differ"], done.stderr
    assert done.returncode == 0 and "all 10 state hashes match" in done.stdout


def test_a_recording_made_on_an_avx512_machine_says_so_in_one_line_and_still_replays(recording: Path) -> None:
    """Made where numpy ran its AVX-512 kernels (a program that imported numpy before the launcher's cap)."""
    running = numpy_simd_level()
    _with_header(recording, lambda head: head["libraries"].update({"numpy-simd": "X86_V4"}))
    done = _replay(recording)
    notes = [line for line in done.stderr.splitlines() if "hashes may differ" in line]
    assert notes == [f"note: recorded with numpy-simd X86_V4, running {running}: hashes may differ"], done.stderr
    assert done.returncode == 0 and "all 10 state hashes match" in done.stdout


def test_the_simd_level_is_the_widest_target_numpy_has_enabled() -> None:
    from numpy._core import _multiarray_umath as umath  # type: ignore[attr-defined]  # private, no stubs

    enabled = [t for t in umath.__cpu_dispatch__ if umath.__cpu_features__[t]]
    assert numpy_simd_level() == (enabled[-1] if enabled else "baseline")
    assert numpy_simd_level() not in ("X86_V4", "AVX512_ICL", "AVX512_SPR")  # the launcher's cap held here


def test_a_recording_from_before_the_versions_reads_and_verifies_with_no_note(recording: Path) -> None:
    """A header written before the versions were kept (the shipped recordings of earlier rounds)."""
    _with_header(recording, lambda head: head.pop("libraries"))
    raw = recording.read_bytes()
    (n,) = struct.unpack_from("<I", raw, len(MAGIC))
    assert "libraries" not in json.loads(raw[len(MAGIC) + 8 : len(MAGIC) + 8 + n])  # the old header
    assert read_recording(recording).header.libraries == {}
    done = _replay(recording)
    assert done.returncode == 0 and "hashes may differ" not in done.stderr, done.stderr
    assert "all 10 state hashes match" in done.stdout


@pytest.mark.parametrize(
    "bad",
    [[], {"mujoco": 4}, {"": "1"}, {"mujoco": "x" * 65}, {f"l{i}": "1" for i in range(4 * len(NUMERIC_LIBRARIES) + 1)}],
)
def test_a_bad_versions_field_is_one_line(recording: Path, bad: object) -> None:
    _with_header(recording, lambda head: head.update(libraries=bad))
    with pytest.raises(RecordingError, match="libraries must"):
        read_recording(recording)
