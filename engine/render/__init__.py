"""Rendering: plain-data scenes, a moderngl renderer, window and headless targets.

The simulation never imports this package's GL side; it only carries the
:class:`~engine.render.components.Appearance` and :class:`~engine.render.components.Shape`
components. Each frame the app fills a :class:`RenderScene` (:func:`scene_from_world`
plus any debug drawing) and a :class:`Viewer` draws it:

- :mod:`engine.render.scene` — ``RenderScene`` buffers and builders (numpy only);
- :mod:`engine.render.extract` — world -> scene, with render interpolation;
- :mod:`engine.render.renderer` — the passes (shadows, objects, snow ground, sky, lines,
  points, text, outlines); :mod:`engine.render.shaders` holds the GLSL;
- :mod:`engine.render.target` — ``make_target(headless, w, h)``: a pygame window
  (:mod:`~engine.render.window`) or an EGL off-screen target (:mod:`~engine.render.headless`);
- :mod:`engine.render.viewer` — ``Viewer``: target + renderer + camera.

GL-dependent names are imported lazily, so importing the components costs no GL import.
"""

from __future__ import annotations

from typing import Any

from engine.render.components import SHAPE_KINDS, Appearance, Shape
from engine.render.extract import puppet_capsules, scene_from_world
from engine.render.scene import Ground, RenderScene, Sun, TextLine

__all__ = [
    "Appearance",
    "Shape",
    "SHAPE_KINDS",
    "RenderScene",
    "Ground",
    "Sun",
    "TextLine",
    "scene_from_world",
    "puppet_capsules",
    "Renderer",
    "Viewer",
    "make_target",
    "RenderTarget",
    "HeadlessTarget",
    "WindowTarget",
    "egl_available",
    "save_image",
]

_LAZY = {
    "Renderer": "engine.render.renderer",
    "Viewer": "engine.render.viewer",
    "make_target": "engine.render.target",
    "RenderTarget": "engine.render.target",
    "save_image": "engine.render.target",
    "HeadlessTarget": "engine.render.headless",
    "egl_available": "engine.render.headless",
    "WindowTarget": "engine.render.window",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'engine.render' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)
