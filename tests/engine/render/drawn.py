"""One headless frame at a quality level, read back: the prologue many render tests share."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine.camera import Camera
from engine.render import RenderScene
from engine.render.quality import QUALITIES


def drawn(scene: RenderScene, camera: Camera, quality: str, size: tuple[int, int] = (320, 240)) -> NDArray[np.int32]:
    """``scene`` seen by ``camera`` at ``quality`` in a new off-screen viewer of ``size``, its pixels as int32
    (differences of them do not wrap). The viewer is closed before returning."""
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, *size, samples=0))
    try:
        with viewer.target.ctx:
            viewer.renderer.set_quality(QUALITIES[quality])
        viewer.camera = camera
        viewer.draw(scene)
        return viewer.read_pixels().astype(np.int32)
    finally:
        viewer.close()
