"""The page renderer's culling, under node: only what the phone's view can show goes to the rasteriser.

The software rasteriser a phone-sized page is judged on shades every vertex of every
instance, seen or not; the page culls rows by their bounding spheres against the view's
frustum (``render.js`` ``cull``). Break it: a ``cull`` that keeps every row fails the
count; one that drops rows half in view fails the edge case.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

import input.web

PAGE = Path(input.web.__file__).parent / "page"
pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="no node executable: apt-get install nodejs")


def test_rows_outside_the_view_are_culled_and_rows_partly_inside_are_kept():
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
// The camera 4 m back on +z, 1.5 m up, looking along -z; 60° vertical, a phone's aspect (±1.07 m at z = 0).
const planes = r.frustumPlanes(r.mul4(r.perspective(60, 390 / 844, 0.05, 200), r.viewMatrix([0, 1.5, 4], [1, 0, 0, 0])));
const row = (a, b, rad) => [...a, ...b, rad, 0.5, 0.5, 0.5, 0];
const rows = new Float32Array([
  ...row([0, 1, 0], [0, 1.5, 0], 0.1),      // in front: kept
  ...row([0, 1, 10], [0, 1.5, 10], 0.1),    // behind the camera
  ...row([30, 1, 0], [30, 1.5, 0], 0.1),    // far to the right
  ...row([2.2, 1, 0], [2.2, 1, 0], 0.5),    // beside the view, its sphere short of the edge
  ...row([1.4, 1, 0], [1.4, 1, 0], 0.5),    // its sphere reaches into the view: kept
]);
const kept = r.cull(rows, 11, planes);
const all = r.cull(rows.slice(0, 11), 11, planes);
console.log(JSON.stringify({{ kept: Array.from(kept.filter((_, i) => i % 11 === 0)), same: all.length === 11 }}));
"""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    assert out["kept"] == [0, pytest.approx(1.4)], out
    assert out["same"]
