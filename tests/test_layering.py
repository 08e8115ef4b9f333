"""Imports go downwards: puppetphone, tools -> games, authoring -> input -> engine (DESIGN.md).

``tools`` (developer tooling) sits on top, beside the launcher whose pieces it uses; the runtime
(engine, input, authoring, games) never imports it.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FORBIDDEN = {
    "engine": {"input", "authoring", "games", "puppetphone", "tools"},
    "input": {"authoring", "games", "puppetphone", "tools"},
    "authoring": {"games", "puppetphone", "tools"},
    "games": {"puppetphone", "tools"},
    "puppetphone": {"tools"},  # the installed launcher never needs the repository's developer scripts
}


def imported_packages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_package_imports_only_below_it(package):
    bad = []
    for path in sorted((ROOT / package).rglob("*.py")):
        wrong = imported_packages(path) & FORBIDDEN[package]
        if wrong:
            bad.append(f"{path.relative_to(ROOT)} imports {', '.join(sorted(wrong))}")
    assert not bad, "layering broken:\n" + "\n".join(bad)
