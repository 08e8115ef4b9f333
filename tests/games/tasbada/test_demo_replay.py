"""The shipped demo replays headless: every stage is reached, in order, and every hash matches."""

from __future__ import annotations

from pathlib import Path

import pytest

from input.recording import read_recording
from input.replay import verify

DEMO = Path(__file__).resolve().parents[3] / "games" / "tasbada" / "demo.rec"


def test_demo_replays_every_stage_in_order_with_matching_hashes(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    from puppetphone.games import make_app

    rec = read_recording(DEMO)
    assert rec.complete and rec.header.game == "tasbada"
    # The recorded setup, saving to a file of the test's (a replay itself saves nowhere).
    setup = {**rec.header.setup, "save_to": str(tmp_path / "save.json")}
    result = verify(lambda hub: make_app("tasbada", rec.header.seed, hub, setup), rec)
    assert result.ok, result.message()
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("stage: ")]
    assert lines == ["stage: real", "stage: props alive", "stage: mixed", "stage: virtual"]
    # The journey was saved as it went (atomically), and names every stage.
    from games.tasbada.save import load_progress

    progress = load_progress(tmp_path / "save.json")
    assert progress is not None and progress.reached == ["real", "props alive", "mixed", "virtual"]
    assert len(progress.marks) == 3 and progress.marks[1].kind == "lasso"
