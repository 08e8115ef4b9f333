"""What the app draws into: a window or an off-screen buffer, behind one small interface.

``make_target(headless, width, height)`` returns either a
:class:`~engine.render.window.WindowTarget` (pygame/SDL2 window with a GL 3.3 context)
or a :class:`~engine.render.headless.HeadlessTarget` (EGL standalone context and an
off-screen framebuffer). Both offer ``ctx``, ``size``, ``framebuffer``, ``begin()``,
``end()``, ``keep_next_frame()``, ``read_pixels()``, ``screenshot(path)``, ``poll_events()`` and ``close()``,
so the play loop, replays and tests do not care which one they have.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

import moderngl
import numpy as np
from numpy.typing import NDArray

__all__ = ["RenderTarget", "make_target", "image_format", "save_image", "IMAGE_FORMATS"]

#: Image formats a screenshot or plot can be written as, by file suffix.
IMAGE_FORMATS: dict[str, str] = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG"}


class RenderTarget(Protocol):
    """The surface one frame is drawn into."""

    ctx: moderngl.Context

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        ...

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        """The framebuffer to draw into between ``begin()`` and ``end()``."""
        ...

    def begin(self) -> moderngl.Framebuffer:
        """Start a frame; returns the framebuffer, bound, with its viewport set."""
        ...

    def end(self) -> None:
        """Finish the frame (present it, or resolve it for reading)."""
        ...

    def keep_next_frame(self) -> None:
        """Make the next frame readable by :meth:`read_pixels` (a window may otherwise draw it where
        it cannot be read back once shown)."""
        ...

    def read_pixels(self) -> NDArray[np.uint8]:
        """The last finished frame as ``[H,W,3]`` uint8, top row first (in a window: one drawn after
        :meth:`keep_next_frame`)."""
        ...

    def screenshot(self, path: str | Path) -> Path:
        """Save the last finished frame (PNG or JPEG by suffix)."""
        ...

    def poll_events(self) -> list[Any]:
        """Pending window events (pygame events); always empty when headless."""
        ...

    def close(self) -> None:
        """Release the context and window."""
        ...


def image_format(path: str | Path) -> str:
    """The format for ``path``'s suffix; ``ValueError`` names the ones offered."""
    suffix = Path(path).suffix.lower()
    if suffix not in IMAGE_FORMATS:
        raise ValueError(f"{path}: cannot write a {suffix or 'suffix-less'} image; use .png or .jpg")
    return IMAGE_FORMATS[suffix]


def save_image(pixels: NDArray[np.uint8], path: str | Path) -> Path:
    """Write ``[H,W,3]`` uint8 pixels to ``path`` (PNG or JPEG by suffix) atomically, creating folders."""
    import io

    from PIL import Image

    from engine.atomic import atomic_write_bytes

    fmt = image_format(path)
    arr = np.asarray(pixels)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.dtype != np.uint8:
        raise ValueError(f"pixels must be uint8 [H,W,3], got {arr.dtype} {arr.shape}")
    buf = io.BytesIO()
    Image.fromarray(arr, "RGB").save(buf, format=fmt, **({"quality": 92} if fmt == "JPEG" else {}))
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(p, buf.getvalue())
    return p


def make_target(
    headless: bool,
    width: int = 1280,
    height: int = 720,
    *,
    title: str = "PuppetPhone",
    samples: int | None = None,
    vsync: bool = True,
) -> RenderTarget:
    """A window (``headless=False``) or an off-screen target of ``width`` x ``height``.

    ``samples``: MSAA samples; ``None`` chooses (4 on a GPU, 0 on llvmpipe).
    """
    if width <= 0 or height <= 0:
        raise ValueError(f"target size must be positive, got {width}x{height}")
    if headless:
        from engine.render.headless import HeadlessTarget

        return HeadlessTarget(width, height, samples=samples)
    from engine.render.window import WindowTarget

    return WindowTarget(width, height, title=title, samples=samples, vsync=vsync)
