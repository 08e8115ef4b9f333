"""Abstract contours around an object or a group (§3.3.2, Eq. 3.2–3.5) and the thinness test.

A closed cubic Hermite curve, started on the bounding box, is optimised by CMA-ES (the
``cma`` package, as the thesis does: ``E_O`` is a count and not differentiable) to

    E = w_A E_A + w_O E_O + w_C E_C,   w_A = 100, w_O = 1e5, w_C = 5,

E_A the enclosed area over the box area (Eq. 3.2), E_O the number of outline pixels
left outside (Eq. 3.3, by the parity of vertical-ray crossings), E_C the curvature
integral (Eq. 3.4). The thesis does not say how E_C is scaled; we take it relative to
the circle inscribed in the box (``∫‖c''‖² ds / ((2π)⁴ a0 / 4)``), so a circle scores
1 and the three weights compare as the thesis' numbers suggest: area dominates,
curvature lets the curve into cavities only a little. Search runs in box-normalised
coordinates with a fixed seed (repeatable), stopping on a small relative improvement.

``cma`` imports ``matplotlib.pyplot`` when it is imported, for plots we never draw: the
first time on a machine that costs ~20 s building matplotlib's font cache (with a
"Matplotlib is building the font cache" line on stderr), and without matplotlib cma warns
instead. :func:`_cma` imports it with matplotlib hidden and that one warning silenced.
"""

from __future__ import annotations

import math
import sys
import warnings
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from authoring.flowcurves.hermite import Hermite

__all__ = ["abstract_contour", "contour_energy", "outside_count", "thinness", "W_A", "W_O", "W_C", "THIN"]

from engine.arrays import F64 as F

W_A, W_O, W_C = 100.0, 1e5, 5.0
CONTROL_POINTS = 6
_SAMPLES = 64
#: Thinness threshold on the variance of curve-to-contour distances over their squared mean
#: (the thesis thresholds the raw variance without a number; relative, it does not depend on size).
THIN = 0.08


def outside_count(polygon: F, points: F) -> int:
    """Eq. 3.3: points whose vertical ray crosses the closed polygon an even number of times."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    x, y = points[:, 0:1], points[:, 1:2]
    lo, hi = np.minimum(a[:, 0], b[:, 0]), np.maximum(a[:, 0], b[:, 0])
    spans = (x >= lo) & (x < hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (x - a[:, 0]) / (b[:, 0] - a[:, 0])
    yc = a[:, 1] + t * (b[:, 1] - a[:, 1])
    crossings = np.sum(spans & (yc < y), axis=1)  # the ray goes up (towards smaller y) from each pixel
    return int(np.sum(crossings % 2 == 0))


def contour_energy(curve: Hermite, outline: F, box_area: float) -> float:
    """Eq. 3.5 for one closed curve."""
    s = np.linspace(0.0, 1.0, _SAMPLES, endpoint=False)
    p = curve(s)
    q = np.roll(p, -1, axis=0)
    e_a = abs(np.sum(p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0])) / (2.0 * box_area)
    e_o = outside_count(p, outline)
    c2 = curve(s, order=2)
    e_c = float(np.mean(np.sum(c2**2, axis=1))) / ((2 * math.pi) ** 4 * box_area / 4.0)
    return W_A * e_a + W_O * e_o + W_C * e_c


def _box_curve(lo: F, hi: F, n: int) -> Hermite:
    """A closed curve on the box outline (control points spread over its perimeter)."""
    w, h = hi - lo
    corners = np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]])
    loop = np.vstack([corners, corners[:1]])
    seg = np.linalg.norm(np.diff(loop, axis=0), axis=1)
    u = np.r_[0.0, np.cumsum(seg)] / seg.sum()
    t = np.arange(n) / n
    pts = np.c_[np.interp(t, u, loop[:, 0]), np.interp(t, u, loop[:, 1])]
    tang = np.roll(pts, -1, axis=0) - np.roll(pts, 1, axis=0)
    return Hermite(np.vstack([pts, tang / 2.0 * n]), closed=True)


def _cma() -> ModuleType:
    """The ``cma`` package, imported without its plotting (see the module docstring)."""
    if "cma" in sys.modules:
        return sys.modules["cma"]
    hide = "matplotlib" not in sys.modules
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Could not import matplotlib")
        if hide:
            sys.modules["matplotlib"] = None  # type: ignore[assignment]  # None makes `import matplotlib` fail
        try:
            import cma
        finally:
            if hide and sys.modules.get("matplotlib", 0) is None:
                del sys.modules["matplotlib"]
    return cma


def abstract_contour(
    outline: ArrayLike, n: int = CONTROL_POINTS, max_evaluations: int = 1500, seed: int = 1
) -> Hermite:
    """The abstract contour around outline pixels ``[N, 2]`` (an object's or a group's)."""
    cma = _cma()

    pts = np.asarray(outline, dtype=np.float64)
    if len(pts) < 3:
        raise ValueError("a contour needs at least three outline pixels")
    if len(pts) > 200:  # the count is over outline pixels; 200 spread evenly keep it fast
        pts = pts[np.linspace(0, len(pts) - 1, 200).astype(np.int64)]
    pad = 3.0
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    scale = np.maximum(hi - lo, 1.0)
    box_area = float(scale[0] * scale[1])
    start = _box_curve(lo, hi, n)
    x0 = ((start.q - np.r_[np.tile(lo, (n, 1)), np.zeros((n, 2))]) / scale).ravel()

    def curve_of(v: F) -> Hermite:
        q = np.asarray(v).reshape(2 * n, 2) * scale
        q[:n] += lo
        return Hermite(q, closed=True)

    es = cma.CMAEvolutionStrategy(
        x0, 0.08, {"seed": seed, "maxfevals": max_evaluations, "verbose": -9, "tolfunrel": 1e-4, "tolfun": 1e-3}
    )
    while not es.stop():
        xs = es.ask()
        es.tell(xs, [contour_energy(curve_of(v), pts, box_area) for v in xs])
    best = es.result.xbest if es.result.xbest is not None else x0
    return curve_of(best)


def thinness(principal: Hermite, contour: Hermite) -> float:
    """Variance of the distances from principal-curve points to the contour, over their squared mean."""
    p = principal.sample(48)
    c = contour.sample(_SAMPLES * 2)
    d = np.sqrt(((p[:, None, :] - c[None]) ** 2).sum(axis=-1)).min(axis=1)
    mean = float(d.mean())
    return float(d.var()) / max(mean * mean, 1e-9)
