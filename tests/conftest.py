"""Shared fixtures: where the real motion-capture data lives, and a headless-safe environment."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

_ROOT = Path(__file__).resolve().parent.parent


def data_dir() -> Path | None:
    """``$PUPPETPHONE_DATA`` or ``../shared/data`` beside the project, if present."""
    env = os.environ.get("PUPPETPHONE_DATA")
    candidates = [Path(env)] if env else []
    candidates.append(_ROOT.parent / "shared" / "data")
    for c in candidates:
        if (c / "mocap").is_dir():
            return c
    return None


@pytest.fixture
def mocap_dir() -> Path:
    """The real mocap folder; skips with the reason when it is absent (a user's fresh clone)."""
    d = data_dir()
    if d is None:
        pytest.skip("real mocap data not found: set PUPPETPHONE_DATA or put shared/data beside the project")
    return d / "mocap"
