"""Fixtures of the MoCurves tests: the default walk, in place and with root motion."""

from __future__ import annotations

from dataclasses import replace

import pytest

from engine.clip import Clip
from engine.clips import default_clips


@pytest.fixture(scope="session")
def walk() -> Clip:
    """The default puppet's walk cycle (root motion extracted, feet planted)."""
    return default_clips()["walk"]


@pytest.fixture(scope="session")
def sliding_walk(walk: Clip) -> Clip:
    """The walk with its root motion thrown away: played as is, the feet skate backwards."""
    return replace(walk, root_motion=None)
