"""The AR placement maths of the page (``page/placement.js``), run by node.

In WebXR ``immersive-ar`` the field's origin goes where the hit test met the floor, its
+Z (the side the game's camera looks from) turned towards the player, and the page
sends its pose in field coordinates. Checked: a viewer standing to one side ends up on
the field's +Z axis looking along -Z, and field → local undoes local → field.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import input.web

pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="no node executable: apt-get install nodejs")
PLACEMENT = Path(input.web.__file__).parent / "page" / "placement.js"


def run_page_maths(body: str) -> dict:
    script = (
        f"const {{ placeField, fieldToLocalMatrix, localToField }} = require({json.dumps(str(PLACEMENT))});\n"
        f"console.log(JSON.stringify((() => {{ {body} }})()));"
    )
    res = subprocess.run(["node", "-e", script], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def test_a_viewer_beside_the_hit_stands_on_the_fields_z_axis_looking_along_minus_z():
    s = math.sqrt(0.5)  # a quarter turn about Y: the camera's -Z looks along local -X, at the hit
    out = run_page_maths(f"""
      const pl = placeField([1, 0, -2], [3, 1.5, -2]);
      return {{ pl, pose: localToField(pl, [0, {s}, 0, {s}], [3, 1.5, -2]),
               front: Array.from(fieldToLocalMatrix(pl)).slice(8, 11) }};""")
    assert out["pl"]["origin"] == [1, 0, -2]
    assert out["pl"]["yaw"] == pytest.approx(math.pi / 2)
    assert out["pose"]["p"] == pytest.approx([0.0, 1.5, 2.0], abs=1e-9)
    q = np.array(out["pose"]["q"])
    assert abs(q[3]) == pytest.approx(1.0, abs=1e-9), f"the viewer should look along the field's -Z, q={q}"
    assert out["front"] == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)  # field +Z is local +X: towards the viewer


def test_field_to_local_undoes_local_to_field_for_any_placement():
    out = run_page_maths("""
      const res = [];
      for (const [hit, viewer, p] of [[[0, 0, 0], [0, 1.6, 2], [0.3, 1.2, 1.1]], [[2, -1.2, 3], [-1, 0.4, 0.5], [5, 1, -2]],
                                       [[-4, 0.1, 1], [-4.5, 1.5, -1], [-4, 1.5, 0]]]) {
        const pl = placeField(hit, viewer), m = fieldToLocalMatrix(pl), f = localToField(pl, [0, 0, 0, 1], p).p;
        res.push([p, [0, 1, 2].map((r) => m[r] * f[0] + m[4 + r] * f[1] + m[8 + r] * f[2] + m[12 + r])]);
      }
      return res;""")
    for local, back in out:
        assert back == pytest.approx(local, abs=1e-5)  # the matrix is float32, as WebGL takes it
