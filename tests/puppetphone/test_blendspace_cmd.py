"""``puppetphone blendspace``: prints the space and draws the Fig. 6.4 lookup graph."""

from __future__ import annotations

from pathlib import Path

import pytest

from puppetphone.cli import main

pytest.importorskip("engine.clips")


def test_blendspace_prints_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "lookup.png"
    assert main(["blendspace", "--density", "11", "--query", "9", "0.8", "--plot", str(out)]) == 0
    text = capsys.readouterr().out
    assert "crouch_walk" in text and "outside" in text and "speed-up" in text
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_blendspace_rejects_bad_options(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["blendspace", "--density", "1"]) == 2
    assert main(["blendspace", "--query", "-1", "0.8", "--density", "5"]) == 2
    assert "non-negative" in capsys.readouterr().err
