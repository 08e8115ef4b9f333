"""The skinned-character render figures: one per count, each beside as many mannequins in the same run."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.render.headless import egl_available


@pytest.mark.skipif(egl_available() is not None, reason=f"no headless EGL OpenGL 3.3 context: {egl_available()}")
def test_each_count_has_its_mannequin_baseline(mocap_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import puppetphone.bench.render_skinned as bench

    monkeypatch.setattr(bench, "COUNTS", (1, 3))
    monkeypatch.setattr(bench, "WIDTH", 320)
    monkeypatch.setattr(bench, "HEIGHT", 180)
    monkeypatch.setenv("PUPPETPHONE_DATA", str(mocap_dir.parent))
    figures = bench.run()
    assert [f.name for f in figures] == ["render_fps_skinned_1", "render_fps_skinned_3"]
    for f in figures:
        assert f.unit == "fps" and f.value > 0 and f.baseline_value is not None and f.baseline_value > 0
        assert "mannequins" in (f.baseline or "")


def test_without_the_character_file_it_says_so_and_gives_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import puppetphone.bench.render_skinned as bench

    monkeypatch.setenv("PUPPETPHONE_DATA", str(tmp_path))
    monkeypatch.setattr(bench, "character_file", lambda: None)
    assert bench.run() == []
    assert "CesiumMan.glb not found" in capsys.readouterr().err
