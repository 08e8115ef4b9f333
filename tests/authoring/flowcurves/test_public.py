"""The flowcurves package's public surface: every name exported exists, and nothing imports a game."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import authoring.flowcurves as fc

MODULES = sorted(p.stem for p in Path(fc.__file__).parent.glob("*.py") if p.stem != "__init__")


@pytest.mark.parametrize("name", ["authoring.flowcurves", *(f"authoring.flowcurves.{m}" for m in MODULES)])
def test_every_export_exists(name: str) -> None:
    module = importlib.import_module(name)
    assert module.__all__
    for symbol in module.__all__:
        assert hasattr(module, symbol), f"{name}.__all__ names missing {symbol}"


def test_no_module_imports_games_or_the_launcher() -> None:
    for m in MODULES:
        tree = ast.parse((Path(fc.__file__).parent / f"{m}.py").read_text())
        names = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
        names += [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
        assert not [x for x in names if x.split(".")[0] in ("games", "puppetphone")], m
