"""The page renderer's culling, under node: only what the phone's view can show goes to the rasteriser.

The software rasteriser a phone-sized page is judged on shades every vertex of every
instance, seen or not; the page culls rows by their bounding spheres against the view's
frustum (``render.js`` ``cull``). Break it: a ``cull`` that keeps every row fails the
count; one that drops rows half in view fails the edge case.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

import input.web

PAGE = Path(input.web.__file__).parent / "page"
pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="no node executable: apt-get install nodejs")


def test_rows_outside_the_view_are_culled_and_rows_partly_inside_are_kept() -> None:
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


def run_node(script: str) -> dict[str, Any]:
    """What a node script printed as JSON (its exit checked)."""
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def test_the_tracks_are_shaded_per_cell_and_a_change_redoes_exactly_the_cells_it_reaches() -> None:
    """``shadeMarks``: untouched snow is exactly 1 (MARKS_ONE), a groove bluish and darker, the wall facing the
    sun lighter than the one turned away; shading only the cells a change reaches gives what shading the whole
    grid gives. Break it: redo the changed cells without the one-cell margin (the slope of the neighbours) and
    the incremental grid differs from the whole one; drop the tint and the groove is not bluish."""
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
const s = require({json.dumps(str(PAGE / "stream.js"))});
const nx = 20, nz = 12, sun = [1, 1, 0];  // the sun low in +x
const cells = new Uint8Array(nx * nz);
for (let row = 4; row < 8; row++) for (let c = 6; c < 12; c++) cells[row * nx + c] = 255;  // a groove
const soft = new Uint8Array(nx * nz), shade = new Uint8Array(4 * nx * nz);
r.shadeMarks(soft, shade, nx, nz, s.softenInto(cells, soft, nx, nz, [0, 0, nz, nx]), sun);
const at = (g, row, c) => Array.from(g.subarray(4 * (row * nx + c), 4 * (row * nx + c) + 3));
const before = {{ plain: at(shade, 0, 0), centre: at(shade, 5, 9), westWall: at(shade, 5, 5), eastWall: at(shade, 5, 12) }};
// The ball rolls on: two more cells, shaded incrementally, against the whole grid shaded afresh.
cells[5 * nx + 12] = 255; cells[6 * nx + 12] = 255;
r.shadeMarks(soft, shade, nx, nz, s.softenInto(cells, soft, nx, nz, [5, 12, 7, 13]), sun);
const soft2 = new Uint8Array(nx * nz), whole = new Uint8Array(4 * nx * nz);
r.shadeMarks(soft2, whole, nx, nz, s.softenInto(cells, soft2, nx, nz, [0, 0, nz, nx]), sun);
console.log(JSON.stringify({{ ...before, one: r.MARKS_ONE, same: shade.every((v, i) => v === whole[i]) }}));
"""
    out = run_node(script)
    assert out["plain"] == [out["one"]] * 3, out
    centre = out["centre"]
    assert max(centre) < out["one"] and centre[2] > centre[0] + 10, f"the groove is not darker and bluish: {out}"
    # The amount grows eastwards over the west wall: its slope tilts the normal towards the sun in +x (as
    # MARKS_FS's); the east wall's turns away.
    assert sum(out["westWall"]) > sum(out["eastWall"]) + 20, f"the sun does not light the walls differently: {out}"
    assert out["same"], "shading the cells a change reaches differs from shading the whole grid"


def test_the_ground_disc_covers_the_ground_round_the_eye_once() -> None:
    """``groundDisc``: its triangles tile the polygon of its outer ring (their areas add up to it, none flipped)
    and the ones under the eye are small. Break it: leave out the centre's fan and the areas fall short."""
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
const d = r.groundDisc(), v = d.vertices, idx = d.indices;
let area = 0, flipped = 0, centreEdge = 0;
for (let t = 0; t < idx.length; t += 3) {{
  const [a, b, c] = [idx[t], idx[t + 1], idx[t + 2]].map((i) => [v[2 * i], v[2 * i + 1]]);
  const s = ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2;
  area += Math.abs(s); if (s < 0) flipped += 1;
  if ([a, b, c].some((p) => p[0] === 0 && p[1] === 0)) centreEdge = Math.max(centreEdge, ...[a, b, c].map((p) => Math.hypot(p[0], p[1])));
}}
console.log(JSON.stringify({{ area, flipped, triangles: idx.length / 3, centreEdge }}));
"""
    out = run_node(script)
    polygon = 0.5 * 24 * 60.0**2 * math.sin(2 * math.pi / 24)
    assert out["area"] == pytest.approx(polygon, rel=1e-5), out
    assert out["flipped"] in (0, out["triangles"]), "the triangles do not all wind the same way"
    assert out["centreEdge"] <= 1.0, out
    assert out["triangles"] < 600, out


def test_the_sky_dome_follows_the_gradient_to_within_two_percent_everywhere() -> None:
    """``skyDome``: rings from straight down to straight up, each all round; between two rings (what the
    rasteriser interpolates) the sky's gradient, pow(height, 0.45), is off by under 2 % of the sky-to-horizon
    difference, steep as it is just above the horizon. Break it: drop the 0.1° ring and the first band is off
    by more (a visible step at the horizon, as coarse screen cells showed)."""
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
const d = r.skyDome(), v = d.vertices, segments = 24, rings = v.length / 3 / segments;
const g = (y) => Math.pow(Math.min(Math.max(y, 0), 1), 0.45);
let worst = 0;
for (let i = 0; i + 1 < rings; i++) {{
  const e0 = Math.asin(v[3 * i * segments + 1]), e1 = Math.asin(v[3 * (i + 1) * segments + 1]);
  for (let k = 1; k < 64; k++) {{
    const t = k / 64, e = e0 + (e1 - e0) * t;
    worst = Math.max(worst, Math.abs(g(Math.sin(e)) - (g(Math.sin(e0)) + (g(Math.sin(e1)) - g(Math.sin(e0))) * t)));
  }}
}}
const unit = Array.from({{ length: v.length / 3 }}, (_, i) => Math.hypot(v[3 * i], v[3 * i + 1], v[3 * i + 2]));
console.log(JSON.stringify({{ worst, rings, bottom: v[1], top: v[v.length - 2], unit: unit.every((n) => Math.abs(n - 1) < 1e-6),
  triangles: d.indices.length / 3, maxIndex: Math.max(...d.indices), vertices: v.length / 3 }}));
"""
    out = run_node(script)
    assert out["worst"] < 0.02, out
    assert out["bottom"] == pytest.approx(-1.0) and out["top"] == pytest.approx(1.0), out
    assert out["unit"], out
    assert out["triangles"] == 2 * 24 * (out["rings"] - 1) and out["maxIndex"] == out["vertices"] - 1, out


def test_a_capsules_outside_faces_come_out_clockwise() -> None:
    """The page culls the capsules' far sides with clockwise front faces: CAPSULE_VS maps the unit mesh's axes
    (x, y, z) to (u, w, v), a mirror. Here that mapping (written out as the shader does it) for an upright and
    a tilted capsule: every triangle of the mesh with any area, wound as indexed, faces into the capsule
    (so seen from outside it is clockwise). Break it: swap u and v in the mapping (no mirror) and every
    triangle faces out. The browser tests (test_page_view) see the other half: the puppet drawn whole."""
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
const m = r.capsuleMesh(), vv = m.vertices, ix = m.indices;
const sub = (a, b) => a.map((x, i) => x - b[i]), dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => {{ const n = Math.hypot(...a); return a.map((x) => x / n); }};
function facing(a, b, rad) {{
  const ax = sub(b, a), w = norm(ax), t = Math.abs(w[1]) < 0.99 ? [0, 1, 0] : [1, 0, 0];
  const u = norm(cross(t, w)), v = cross(w, u);
  const at = (i) => {{
    const [x, y, z, end] = vv.subarray(4 * i, 4 * i + 4), n = [0, 1, 2].map((k) => u[k] * x + w[k] * y + v[k] * z);
    return [0, 1, 2].map((k) => a[k] + ax[k] * end + rad * n[k]);
  }};
  const centre = a.map((x, k) => (x + b[k]) / 2);
  let inward = 0, outward = 0;
  for (let f = 0; f < ix.length; f += 3) {{
    const p = at(ix[f]), q = at(ix[f + 1]), s = at(ix[f + 2]), n = cross(sub(q, p), sub(s, p));
    if (Math.hypot(...n) < 1e-9) continue;  // a pole's degenerate triangles
    const mid = [0, 1, 2].map((k) => (p[k] + q[k] + s[k]) / 3);
    if (dot(n, sub(mid, centre)) < 0) inward += 1; else outward += 1;
  }}
  return {{ inward, outward }};
}}
console.log(JSON.stringify({{ upright: facing([0, 0, 0], [0, 1, 0], 0.2), tilted: facing([0.3, 0.5, -1], [1, 1.2, -0.4], 0.1) }}));
"""
    out = run_node(script)
    for pose in ("upright", "tilted"):
        assert out[pose]["outward"] == 0 and out[pose]["inward"] > 100, out


def test_a_slow_drawing_lowers_the_resolution_to_three_quarters_and_no_further() -> None:
    """``FrameCounter``: a page that draws under 40 fps lowers its resolution step by step, but never under
    MIN_RESOLUTION = 0.75 a side (half a side would be a quarter of the phone's pixels); a fast one climbs back
    to 1; a held resolution stays. Break it: MIN_RESOLUTION 0.5 and the slow page settles at 0.5."""
    script = f"""
const r = require({json.dumps(str(PAGE / "render.js"))});
const c = new r.FrameCounter(), seen = [];
let now = 0;
const second = (fps) => {{ for (let i = 0; i < fps; i++) {{ now += 1000 / fps; c.count(1, now); }} seen.push(c.resolution); }};
for (let s = 0; s < 10; s++) second(20);
const slow = c.resolution, lowest = Math.min(...seen);
for (let s = 0; s < 10; s++) second(60);
const fast = c.resolution;
c.hold(1); for (let s = 0; s < 5; s++) second(20);
console.log(JSON.stringify({{ slow, lowest, fast, held: c.resolution, min: r.MIN_RESOLUTION }}));
"""
    out = run_node(script)
    assert out["min"] == 0.75 and out["slow"] == 0.75 and out["lowest"] == 0.75, out
    assert out["fast"] == 1 and out["held"] == 1, out
