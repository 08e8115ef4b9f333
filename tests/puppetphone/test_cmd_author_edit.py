"""``author edit`` headless: opens a default clip or a saved session, screenshots, exports."""

from __future__ import annotations

import argparse

import pytest

from authoring.mocurves import EditSession, save_session
from engine.clips import default_clips
from puppetphone.cmd_author_edit import configure_edit, run_edit


def parse(*argv: str) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    configure_edit(p)
    return p.parse_args(list(argv))


def test_headless_run_screenshots_and_exports(tmp_path):
    from engine.render import egl_available

    if (reason := egl_available()) is not None:
        pytest.skip(f"no headless GL: {reason}")
    session = EditSession(default_clips()["walk"])
    session.retime("l_foot", {10: 0.2})
    saved = save_session(session, tmp_path / "walk.ppclip")
    shot, bvh = tmp_path / "shot.png", tmp_path / "out.bvh"
    args = parse(str(saved), "--headless", "--frames", "2", "--size", "320x180", "--screenshot", str(shot), "--export", str(bvh))
    assert run_edit(args) == 0
    assert shot.stat().st_size > 1000 and bvh.read_text().startswith("HIERARCHY")


def test_unknown_clip_is_a_clear_error(capsys):
    assert run_edit(parse("no_such_clip", "--headless", "--frames", "1")) == 2
    assert "neither a .ppclip file nor a default clip" in capsys.readouterr().err
