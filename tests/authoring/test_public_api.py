"""The authoring package's curated public surface."""

from __future__ import annotations

import importlib

import pytest

MODULES = [
    "authoring.cycles",
    "authoring.cycles.trajectory",
    "authoring.cycles.descriptor",
    "authoring.cycles.period",
    "authoring.cycles.average",
    "authoring.cycles.stitch",
    "authoring.cycles.spline",
    "authoring.cycles.extract",
    "authoring.cycles.cutting",
    "authoring.cycles.formats",
    "authoring.cycles.plot",
    "authoring.cycles.baseline",
    "authoring.cycles.synthetic",
    "authoring.cycles.segments",
    "authoring.cycles.take_range",
    "authoring.batch",
    "authoring.batch.index",
    "authoring.batch.runner",
    "authoring.batch.worker",
]


@pytest.mark.parametrize("name", MODULES)
def test_every_export_exists(name: str) -> None:
    module = importlib.import_module(name)
    assert module.__all__, f"{name} exports nothing"
    for symbol in module.__all__:
        assert hasattr(module, symbol), f"{name}.__all__ names missing {symbol}"


def test_package_surface() -> None:
    import authoring.cycles as c

    assert {"extract_cycle", "Trajectory", "Item", "CycleError", "CycleResult"} <= set(c.__all__)


def test_authoring_does_not_import_games_or_cli() -> None:
    """DESIGN: authoring imports engine and input only."""
    import ast
    from pathlib import Path

    root = Path(importlib.import_module("authoring").__file__).parent
    for path in root.rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else []
            )
            for n in names:
                assert not n.startswith(("games", "puppetphone")), f"{path.name} imports {n}"
