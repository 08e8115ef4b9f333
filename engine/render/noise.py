"""The snow noise texture: tileable drift heights, their slopes, and a random channel.

Computing several octaves of value noise per ground pixel was the most expensive part of
a frame on llvmpipe. Instead the noise is made once here, on the CPU, by shaping white
noise with a ``1/f^beta`` spectrum (an FFT filter is periodic by construction, so the
texture tiles without seams), and the ground shader reads it with two texture fetches.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["snow_noise"]


def snow_noise(size: int = 256, seed: int = 7, beta: float = 2.2) -> NDArray[np.uint8]:
    """``[size,size,4]`` uint8: R height in [0,1], G/B x/z slope around 0.5, A uniform random.

    The slopes are normalised so the steepest texel maps to 0 or 255; the shader scales
    them to taste. Fixed ``seed``: the ground looks the same every run.
    """
    if size < 8 or size & (size - 1):
        raise ValueError(f"noise size must be a power of two >= 8, got {size}")
    rng = np.random.default_rng(seed)
    f = np.fft.fftfreq(size)
    k = np.sqrt(f[:, None] ** 2 + f[None, :] ** 2)
    k[0, 0] = 1.0
    spectrum = np.fft.fft2(rng.standard_normal((size, size))) / k ** (beta / 2.0)
    spectrum[0, 0] = 0.0
    h = np.fft.ifft2(spectrum).real
    h = (h - h.min()) / max(float(np.ptp(h)), 1e-12)
    gx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / 2.0
    gz = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / 2.0
    g = max(float(np.abs(gx).max()), float(np.abs(gz).max()), 1e-12)
    out = np.empty((size, size, 4), dtype=np.uint8)
    out[..., 0] = np.round(h * 255)
    out[..., 1] = np.round((gx / g * 0.5 + 0.5) * 255)
    out[..., 2] = np.round((gz / g * 0.5 + 0.5) * 255)
    out[..., 3] = rng.integers(0, 256, (size, size))
    return out
