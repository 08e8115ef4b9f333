"""What a plain snowman start loads: the bench's baseline libraries, and not what it does not need.

Broken on purpose to see it fail: ``from input.web.server import WebSource`` back at the top of
``puppetphone/web_pairing.py`` (websockets and asyncio appear), the flow imports of
``games/snowman/bent_scenery.prepare_flow`` back above its empty-path check (scipy.optimize), or
``default_clips`` building without its cache (engine.clips._library appears on the second start).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from puppetphone.bench.startup import HEAVY

_ROOT = Path(__file__).resolve().parents[3]
#: Libraries a headless snowman start without a web source or flow file has no use for.
UNNEEDED = ("scipy.optimize", "scipy.interpolate", "scipy.ndimage", "PIL", "websockets", "pythonosc", "pygame")


def _start_modules(cache: Path, out: Path) -> set[str]:
    code = (
        "import atexit, runpy, sys\n"
        f"atexit.register(lambda: open({str(out)!r}, 'w').write('\\n'.join(sorted(sys.modules))))\n"
        "sys.argv = ['puppetphone', 'play', 'snowman', '--headless', '--frames', '1']\n"
        "runpy.run_module('puppetphone', run_name='__main__')\n"
    )
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), SDL_VIDEODRIVER="dummy")
    subprocess.run([sys.executable, "-c", code], cwd=_ROOT, env=env, check=True, capture_output=True, timeout=300)
    return set(out.read_text().split())


def test_a_warm_start_loads_its_baseline_and_nothing_it_does_not_use(tmp_path: Path) -> None:
    cold = _start_modules(tmp_path / "cache", tmp_path / "cold.txt")
    assert "engine.clips._library" in cold  # the first start builds the clips…
    assert list((tmp_path / "cache" / "puppetphone" / "builtin-clips").glob("*.npz"))
    warm = _start_modules(tmp_path / "cache", tmp_path / "warm.txt")
    assert "engine.clips._library" not in warm  # …the next ones read them
    assert [m for m in HEAVY if m not in warm] == [], "the bench's baseline names a library the start does not load"
    loaded = [m for m in UNNEEDED if any(x == m or x.startswith(m + ".") for x in warm)]
    assert loaded == [], f"a plain start imported {loaded}"
