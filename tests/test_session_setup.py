"""What tests/conftest.py sets up for the whole session: a cache folder of its own, slow tests first.

Broken on purpose to see them fail: ``_own_cache_folder`` left out of ``pytest_configure`` (the
cache is then the real ``~/.cache/puppetphone``), or the sort in ``pytest_collection_modifyitems``
removed (the marked tests stay after unmarked ones).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from engine.cliplib.cache import cache_root
from tests.conftest import pytest_collection_modifyitems


def test_the_session_keeps_its_cache_out_of_the_users_one() -> None:
    if os.environ.get("PUPPETPHONE_TEST_SESSION_CACHE") is None:
        # the environment named a cache folder before the session (a CI's own): it is used as given
        assert os.environ.get("XDG_CACHE_HOME")
        return
    assert cache_root() != Path.home() / ".cache" / "puppetphone"
    assert Path(os.environ["XDG_CACHE_HOME"]).is_dir()
    # the glTF validator that .ci/run installs into the real cache is still found there
    assert os.environ.get("PUPPETPHONE_NPM")


class _Item:
    def __init__(self, name: str, slow: bool) -> None:
        self.name, self.slow = name, slow

    def get_closest_marker(self, name: str) -> object | None:
        return pytest.mark.slow.mark if name == "slow" and self.slow else None


def test_slow_tests_come_first_and_each_part_keeps_its_order(request: pytest.FixtureRequest) -> None:
    items = [_Item("a", False), _Item("b", True), _Item("c", False), _Item("d", True), _Item("e", False)]
    pytest_collection_modifyitems(items)  # type: ignore[arg-type]  # duck-typed items: only the marker is read
    assert [i.name for i in items] == ["b", "d", "a", "c", "e"]
    # and so in this session's own collection
    slow = [item.get_closest_marker("slow") is not None for item in request.session.items]
    assert slow == sorted(slow, reverse=True)
