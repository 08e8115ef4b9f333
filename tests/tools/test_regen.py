"""``python -m tools.regen``: one command for every shipped artefact, in dependency order."""

from __future__ import annotations

import pytest

from tools.regen import ORDER, TARGETS, main, regenerate


def test_every_target_has_a_script_and_all_runs_them_in_dependency_order(monkeypatch: pytest.MonkeyPatch) -> None:
    ran: list[str] = []
    for name in TARGETS:
        monkeypatch.setitem(TARGETS, name, lambda name=name: ran.append(name))
    regenerate(["screenshots", "all"])
    assert ran == list(ORDER) == ["assets", "demos", "recordings", "screenshots"]


def test_an_unknown_target_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ValueError, match="unknown target"):
        regenerate(["everything"])
    with pytest.raises(SystemExit) as stop:
        main(["everything"])
    assert stop.value.code == 2 and "invalid choice" in capsys.readouterr().err
