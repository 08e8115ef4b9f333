"""The Panda3D peer of ``render_fps_100_puppets``: 100 skinned, animated actors at 1280x720.

Run as a script in its own process (``python -m bench.render_panda``): Panda3D opens its
own EGL context (``p3headlessgl``, an off-screen buffer on the same Mesa llvmpipe), which
must not share a process with the renderer's. It prints one line, the median over 3
repeats of the process CPU seconds per frame (``renderFrame`` with ``gl-finish``, so the
rasteriser's work is counted, as ``ctx.finish()`` counts ours), and the triangles drawn.

The scene mirrors :func:`bench.render.demo_scene` with 100 puppets: ten rows of ten,
1.1 m apart in a row and 1.3 m between rows, each actor walking (``panda-walk4``, the
skinned panda that ships with Panda3D, scaled to about a puppet's height), the camera 25.5 m from the
crowd's centre, 0.28 rad above it. Panda3D's default state draws the actors unlit and
without shadows (less per-pixel work than ours, which lights, shadows and fogs them).
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = ["measure"]


def measure(actors: int = 100, frames: int = 5, repeats: int = 3) -> tuple[float, int]:
    """``(process CPU seconds per frame, triangles per frame)`` of ``actors`` walking pandas."""
    from direct.actor.Actor import Actor
    from direct.showbase.ShowBase import ShowBase
    from panda3d.core import loadPrcFileData

    loadPrcFileData(
        "",
        "window-type offscreen\nwin-size 1280 720\nload-display p3headlessgl\n"
        "audio-library-name null\ngl-finish true\nsync-video false\nnotify-level error\n",
    )
    base = ShowBase()
    per_row = 10
    triangles = 0
    for i in range(actors):
        actor = Actor("models/panda-model", {"walk": "models/panda-walk4"})
        actor.setScale(0.0025)
        col, row = i % per_row, i // per_row
        actor.setPos((col - (per_row - 1) / 2) * 1.1, 1.3 * row, 0.0)
        actor.setH(180.0)
        actor.reparentTo(base.render)
        actor.loop("walk", fromFrame=i % 7)
        if i == 0:
            triangles = sum(
                g.getPrimitive(p).getNumFaces()
                for node in actor.findAllMatches("**/+GeomNode")
                for g in node.node().getGeoms()
                for p in range(g.getNumPrimitives())
            )
    rows = -(-actors // per_row)
    centre_y, distance, pitch = 0.65 * (rows - 1), 7.5 + 2.0 * (rows - 1), 0.28
    base.camera.setPos(0.0, centre_y - distance * math.cos(pitch), 0.8 + distance * math.sin(pitch))
    base.camera.lookAt(0.0, centre_y, 0.8)
    engine = base.graphicsEngine
    for _ in range(3):
        engine.renderFrame()
    samples = []
    for _ in range(repeats):
        t0 = time.process_time()
        for _ in range(frames):
            engine.renderFrame()
        samples.append((time.process_time() - t0) / frames)
    base.destroy()
    return float(np.median(samples)), triangles * actors


if __name__ == "__main__":
    seconds, tris = measure()
    print(f"{seconds!r} {tris}")
