"""The curated public surface of engine.io: every exported name exists, and the package stays in engine."""

from __future__ import annotations

import ast
from pathlib import Path

import engine.io


def test_all_names_resolve() -> None:
    assert len(set(engine.io.__all__)) == len(engine.io.__all__)
    for name in engine.io.__all__:
        assert getattr(engine.io, name) is not None, name
    for name in ("read_bvh", "write_bvh", "clip_to_bvh", "detect_tpose_frames", "read_gltf", "write_gltf", "retarget"):
        assert name in engine.io.__all__


def test_io_imports_only_engine() -> None:
    # engine/ must not import input/, authoring/, games/ or puppetphone/ (DESIGN: which way imports go).
    for path in Path(engine.io.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            mods = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else ([node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            )
            for mod in mods:
                assert mod.split(".")[0] not in ("input", "authoring", "games", "puppetphone"), (path.name, mod)
