"""The tasbada save as an outside format: bounded, never waited on, values checked; only our files set aside."""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path

import pytest

from games.base import GameOptionError
from games.tasbada.game import prepare
from games.tasbada.quest import Mark, Quest
from games.tasbada.save import SaveError, load_progress, progress_of, save_progress

OPTIONS = {"save": "", "photo": "", "selfie": "", "webcam": "off", "pose": "off", "light": ""}


def _load_within(path: Path, seconds: float = 10.0) -> BaseException | object:
    """What ``load_progress(path)`` returns or raises, failing the test if it has not ended in time."""
    out: list[object] = []

    def run() -> None:
        try:
            out.append(load_progress(path))
        except BaseException as exc:  # noqa: BLE001 - the test looks at what it was
            out.append(exc)

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(seconds)
    assert out, f"load_progress({path}) still running after {seconds} s"
    return out[0]


def test_a_pipe_is_refused_at_once(tmp_path: Path) -> None:
    pipe = tmp_path / "save.json"
    os.mkfifo(pipe)
    assert isinstance(_load_within(pipe), SaveError)


def test_an_endless_device_is_refused_before_reading() -> None:
    assert isinstance(_load_within(Path("/dev/zero")), SaveError)


@pytest.mark.parametrize(
    "text,says",
    [
        ('{"format": "tasbada-progress", "marks": ' + "[" * 100_000 + "]" * 100_000 + "}", "nested too deeply"),
        (
            json.dumps(
                {"format": "tasbada-progress", "version": 1, "reached": ["real"], "ground_v": 1e308, "marks": []}
            ),
            "floor line",
        ),
        (
            json.dumps(
                {
                    "format": "tasbada-progress",
                    "version": 1,
                    "reached": ["real"],
                    "ground_v": 0.5,
                    "marks": [{"kind": "lasso", "points": [[0.1, 0.2]] * 5000}],
                }
            ),
            "at most",
        ),
        (
            json.dumps({"format": "tasbada-progress", "version": 1, "reached": "real", "ground_v": 0.5, "marks": []}),
            "reached",
        ),
        (
            json.dumps(
                {
                    "format": "tasbada-progress",
                    "version": 1,
                    "reached": [],
                    "ground_v": 0.5,
                    "marks": [{"kind": "box", "points": [[0.1, "x"], [0.2, 0.3]]}],
                }
            ),
            "two numbers",
        ),
        (
            json.dumps(
                {
                    "format": "tasbada-progress",
                    "version": 1,
                    "reached": [],
                    "ground_v": 0.5,
                    "marks": [],
                    "photo": ["a"],
                }
            ),
            "text",
        ),
    ],
)
def test_a_damaged_save_is_one_save_error(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "save.json"
    path.write_text(text)
    with pytest.raises(SaveError, match=says) as err:
        load_progress(path)
    assert "\n" not in str(err.value)


def test_an_oversized_save_is_refused_without_reading_it(tmp_path: Path) -> None:
    path = tmp_path / "save.json"
    with open(path, "wb") as f:
        f.truncate(2 << 30)  # sparse: 2 GB claimed, nothing on disk
    with pytest.raises(SaveError, match="limit"):
        load_progress(path)


@pytest.mark.parametrize(
    "make",
    [
        lambda p: (p.mkdir(), (p / "holiday.jpg").write_bytes(b"\xff\xd8")),
        lambda p: p.write_text("my diary"),
    ],
)
def test_a_save_path_that_is_not_our_save_is_refused_and_untouched(tmp_path: Path, make) -> None:  # type: ignore[no-untyped-def]
    target = tmp_path / "save.json"
    make(target)
    before = sorted((str(p), p.read_bytes()) for p in tmp_path.rglob("*") if p.is_file())
    with pytest.raises(GameOptionError, match="not progress this program saved"):
        prepare({**OPTIONS, "save": str(target)})
    assert sorted((str(p), p.read_bytes()) for p in tmp_path.rglob("*") if p.is_file()) == before
    with pytest.raises(OSError, match="cannot save"):
        save_progress(target, progress_of(Quest()))


def test_a_damaged_save_of_ours_is_set_aside(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "save.json"
    q = Quest(stage="mixed", reached=["real", "props alive", "mixed"], ground_v=0.6)
    q.marks = [Mark("box", [[0.1, 0.2], [0.3, 0.5]])]
    save_progress(target, progress_of(q))
    cut = target.read_bytes()[:60]
    target.write_bytes(cut)
    setup = prepare({**OPTIONS, "save": str(target)})
    assert setup["reached"] == [] and Path(f"{target}.bad").read_bytes() == cut and not target.exists()
    assert "set aside" in capsys.readouterr().err
