"""The curated surface of ``input.web`` and its layering (engine and input only), and its packaged page."""

import ast
import importlib
from importlib import resources
from pathlib import Path

import input.web as pkg

ROOT = Path(pkg.__file__).parent


def test_all_names_exist():
    for path in ROOT.glob("*.py"):
        mod = importlib.import_module(f"input.web.{path.stem}") if path.stem != "__init__" else pkg
        assert hasattr(mod, "__all__"), path.stem
        for name in mod.__all__:
            assert hasattr(mod, name), f"{path.stem}.{name}"


def test_web_imports_only_engine_input_and_libraries():
    for path in ROOT.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else ([node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
            )
            for n in names:
                assert n.split(".")[0] not in ("games", "authoring", "puppetphone"), f"{path.name}: {n}"


def test_the_page_ships_with_the_package():
    page = resources.files("input.web").joinpath("page")
    html = page.joinpath("index.html").read_text()
    for name in ("app.js", "stream.js", "render.js", "placement.js", "style.css"):
        assert name in html and page.joinpath(name).is_file()
    # The workers are loaded by the scripts, not the HTML; the server serves every file of the page.
    from input.web.server import PAGE_FILES

    served = {name for name, _ in PAGE_FILES.values()}
    for name in ("stream_worker.js", "render_worker.js"):
        assert page.joinpath(name).is_file() and name in served
    assert served == {p.name for p in page.iterdir() if p.suffix in (".html", ".js", ".css")}
