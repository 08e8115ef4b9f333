"""The curated surface of ``input`` and the layering rule (input imports only engine)."""

import ast
import importlib
from pathlib import Path

import input as pkg

ROOT = Path(pkg.__file__).parent


def test_all_names_exist():
    for name in pkg.__all__:
        assert hasattr(pkg, name), name
    for path in ROOT.glob("*.py"):
        mod = importlib.import_module(f"input.{path.stem}") if path.stem != "__init__" else pkg
        for name in getattr(mod, "__all__", []):
            assert hasattr(mod, name), f"{path.stem}.{name}"
        assert path.stem == "__init__" or hasattr(mod, "__all__"), path.stem


def test_input_imports_only_engine_and_itself():
    forbidden = ("games", "authoring", "puppetphone")
    for path in ROOT.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            for n in names:
                assert n.split(".")[0] not in forbidden, f"{path.name} imports {n}"
