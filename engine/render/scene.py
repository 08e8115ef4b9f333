"""``RenderScene``: everything one frame draws, as plain numpy buffers.

The simulation never sees this: an extraction step (:mod:`engine.render.extract`)
or a tool fills a scene, the renderer uploads it. Each primitive kind lives in one
growable float32 array whose row layout is exactly the GPU instance layout, so a frame
costs one ``tobytes`` per kind and no per-item Python objects. ``clear()`` keeps the
capacity, so a scene reused every frame stops allocating after the first.

Row layouts (float32):

- capsules / spheres: ``a[3] b[3] radius color[3] outline`` (a sphere is a capsule with
  ``a == b``, which lets both share one shader);
- boxes: ``center[3] half_extents[3] rotation(w,x,y,z)[4] color[3] outline``;
- lines: ``p0[3] p1[3] color[3] width_px``;
- points: ``pos[3] size color[3] pixels`` (``pixels`` 1: size in pixels, 0: in metres);
- cones: ``base[3] apex[3] radius color[3] snow`` (conifer tiers; ``snow`` whitens the upper side);
- prints: ``x z heading_cos heading_sin half_length half_width strength`` (footprints on the ground).

The ground may also carry :class:`GroundMarks`: a grid of how much snow each cell lost
(a track), drawn as a soft groove.

Colours are sRGB in ``[0, 1]``; the renderer linearises them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine.io.gltf_mesh import SkinnedMeshes

__all__ = [
    "RenderScene",
    "SkinnedInstance",
    "Rows",
    "Ground",
    "GroundMarks",
    "Sun",
    "TextLine",
    "Overlay",
    "CAPSULE_STRIDE",
    "BOX_STRIDE",
    "LINE_STRIDE",
    "POINT_STRIDE",
    "CONE_STRIDE",
    "PRINT_STRIDE",
]

CAPSULE_STRIDE = 11
BOX_STRIDE = 14
LINE_STRIDE = 10
POINT_STRIDE = 8
CONE_STRIDE = 11
PRINT_STRIDE = 7


class Rows:
    """A growable ``[n, stride]`` float32 array with amortised O(1) appends."""

    def __init__(self, stride: int, capacity: int = 64) -> None:
        self.stride = stride
        self._data = np.zeros((max(capacity, 1), stride), dtype=np.float32)
        self._n = 0

    def __len__(self) -> int:
        return self._n

    @property
    def data(self) -> NDArray[np.float32]:
        """The filled rows ``[n, stride]`` (a view; valid until the next append)."""
        return self._data[: self._n]

    def extend(self, n: int) -> NDArray[np.float32]:
        """Reserve ``n`` new rows and return them (zeroed) for the caller to fill."""
        need = self._n + n
        if need > len(self._data):
            grown = np.zeros((max(need, 2 * len(self._data)), self.stride), dtype=np.float32)
            grown[: self._n] = self._data[: self._n]
            self._data = grown
        rows = self._data[self._n : need]
        rows[:] = 0.0
        self._n = need
        return rows

    def clear(self) -> None:
        """Forget the rows, keep the capacity."""
        self._n = 0


def _col(value: ArrayLike, n: int, width: int, name: str) -> NDArray[np.float64]:
    """Broadcast ``value`` to ``[n, width]`` (``[n]`` for width 1) with a clear error on a wrong shape."""
    arr = np.asarray(value, dtype=np.float64)
    shape = (n,) if width == 1 else (n, width)
    try:
        out = np.broadcast_to(arr, shape)
    except ValueError:
        raise ValueError(f"{name}: cannot use shape {arr.shape} for {n} items of width {width}") from None
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name}: values must be finite")
    return out


@dataclass
class Ground:
    """The snowy ground plane: height, colour, procedural snow and grid lines."""

    height: float = 0.0
    color: tuple[float, float, float] = (0.93, 0.95, 0.98)
    snow: float = 1.0
    """Strength of the procedural snow shading and sparkle (0 = flat colour)."""
    grid: bool = True
    grid_spacing: float = 1.0
    grid_color: tuple[float, float, float] = (0.55, 0.62, 0.72)
    grid_strength: float = 0.35
    visible: bool = True


@dataclass
class GroundMarks:
    """A track in the snow: ``amount [Nz, Nx]`` in [0, 1] (row ``k`` at ``z0 + (k + 0.5)·cell``), how much of
    its snow each cell lost; drawn as a soft groove, deepest where ``amount`` is 1."""

    amount: NDArray[np.float32]
    x0: float
    z0: float
    cell: float

    def __post_init__(self) -> None:
        a = np.asarray(self.amount, dtype=np.float32)
        if a.ndim != 2 or min(a.shape) < 1:
            raise ValueError(f"marks must be a 2-D grid, got shape {a.shape}")
        if not self.cell > 0:
            raise ValueError(f"marks cell must be positive, got {self.cell}")
        self.amount = np.clip(a, 0.0, 1.0)


@dataclass
class Sun:
    """The directional light. ``direction`` points from the scene towards the sun."""

    direction: tuple[float, float, float] = (0.6, 0.75, -0.1)
    color: tuple[float, float, float] = (1.0, 0.96, 0.9)
    intensity: float = 1.8
    ambient: float = 0.45
    """Hemisphere sky light strength, which keeps shadows soft blue rather than black."""
    shadows: bool = True
    softness: float = 0.04
    """Penumbra radius in metres (blur of the ground shadow, PCF radius on objects)."""


@dataclass
class TextLine:
    """One overlay string; ``x``/``y`` in pixels from the top-left, ``None`` to stack lines.

    ``anchor`` centres the line on a point given as fractions of the window
    (``(0.5, 0.5)`` is its middle) instead, for messages that must stand out whatever
    the window's size. ``alpha`` fades the line and its panel (1 opaque, 0 gone).
    Lines are wrapped to the window's width when drawn (:mod:`engine.render.text`).
    """

    text: str
    x: float | None = None
    y: float | None = None
    size: int = 18
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    anchor: tuple[float, float] | None = None
    alpha: float = 1.0


@dataclass
class Overlay:
    """A picture laid over the view, aligned with the background photo (tasbada's props and interface).

    ``image`` is ``[h,w,4]`` uint8 RGBA covering ``rect = (u0, v0, u1, v1)`` of the photo
    (normalised, top-left origin). With ``depth_at`` (a world point) its opaque pixels
    stand at that point's depth: 3-D objects nearer than it cover them, farther ones are
    covered (a real prop's matte as a depth mask); without, it draws over everything
    (an interface). ``photo`` pictures are tone-mapped like the background photo so they
    match it; ``alpha`` fades the whole picture.
    """

    image: NDArray[np.uint8]
    rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0)
    depth_at: tuple[float, float, float] | None = None
    photo: bool = False
    alpha: float = 1.0


@dataclass(frozen=True)
class SkinnedInstance:
    """One skinned character to draw: its meshes and ``[K,4,4]`` skinning matrices (world from bind space)."""

    meshes: SkinnedMeshes
    matrices: NDArray[np.float64]
    outline: bool = False
    """Drawn with the scene's outline round it (a held or grabbable character), as outlined capsules are."""

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(lo, hi)`` around the posed character, from about 128 skinned vertices of each primitive
        (padded by a tenth of the extent for the vertices between the samples): what the sun's
        shadow frustum must hold, at a fraction of skinning the whole mesh."""
        points = []
        for prim in self.meshes.primitives:
            step = max(1, len(prim.positions) // 128)
            m = np.einsum(
                "vk,vkij->vij",
                prim.weights[::step].astype(np.float64),
                np.asarray(self.matrices, dtype=np.float64)[prim.joints[::step].astype(np.int64)],
            )
            rest = prim.positions[::step].astype(np.float64)
            points.append(np.einsum("vij,vj->vi", m[:, :3, :3], rest) + m[:, :3, 3])
        every = np.vstack(points)
        lo, hi = every.min(axis=0), every.max(axis=0)
        pad = 0.1 * (hi - lo).max()
        return lo - pad, hi + pad


@dataclass
class RenderScene:
    """Primitives and settings for one rendered frame."""

    capsules: Rows = field(default_factory=lambda: Rows(CAPSULE_STRIDE, 256))
    spheres: Rows = field(default_factory=lambda: Rows(CAPSULE_STRIDE, 64))
    boxes: Rows = field(default_factory=lambda: Rows(BOX_STRIDE, 16))
    lines: Rows = field(default_factory=lambda: Rows(LINE_STRIDE, 256))
    points: Rows = field(default_factory=lambda: Rows(POINT_STRIDE, 256))
    cones: Rows = field(default_factory=lambda: Rows(CONE_STRIDE, 32))
    prints: Rows = field(default_factory=lambda: Rows(PRINT_STRIDE, 64))
    marks: GroundMarks | None = None
    """The snow track, if any (see :class:`GroundMarks`)."""
    texts: list[TextLine] = field(default_factory=list)
    ground: Ground = field(default_factory=Ground)
    sun: Sun = field(default_factory=Sun)
    sky_color: tuple[float, float, float] = (0.30, 0.52, 0.86)
    horizon_color: tuple[float, float, float] = (0.86, 0.9, 0.96)
    outline_color: tuple[float, float, float] = (1.0, 0.78, 0.2)
    outline_width: float = 3.0
    """Outline thickness in pixels (approximately, at the object's distance)."""
    background: NDArray[np.uint8] | None = None
    """Optional ``[H,W,3]`` uint8 photo drawn behind everything (tasbada's composite)."""
    background_fade: float = 1.0
    """0 shows only the photo behind objects, 1 only the sky and ground; between blends them."""
    overlays: list[Overlay] = field(default_factory=list)
    """Pictures over the 3-D view, in order (see :class:`Overlay`); the text overlay stays on top."""
    skinned: list[SkinnedInstance] = field(default_factory=list)
    """Skinned characters (glTF skins) in their poses, drawn lit beside the solids."""
    complete: bool = False
    """Draw everything, waiting for what is still being built in the background (a game's cut-out
    props): set for headless frames and screenshots, which nobody watches fill in."""

    def clear(self) -> None:
        """Empty every primitive buffer (settings and background stay)."""
        for rows in (self.capsules, self.spheres, self.boxes, self.lines, self.points, self.cones, self.prints):
            rows.clear()
        self.marks = None
        self.texts.clear()
        self.overlays.clear()
        self.skinned.clear()

    # -- builders ---------------------------------------------------------------------
    def add_capsules(
        self,
        a: ArrayLike,
        b: ArrayLike,
        radius: ArrayLike,
        color: ArrayLike = (0.8, 0.8, 0.8),
        outline: ArrayLike = False,
    ) -> None:
        """Append ``N`` capsules from ``a [N,3]`` to ``b [N,3]`` (one group: broadcasting applies)."""
        a_arr = np.asarray(a, dtype=np.float64).reshape(-1, 3)
        self._fill_capsule_rows(self.capsules, len(a_arr), a_arr, b, radius, color, outline)

    def add_capsule(
        self, a: ArrayLike, b: ArrayLike, radius: float, color: ArrayLike = (0.8, 0.8, 0.8), outline: bool = False
    ) -> None:
        """Append one capsule."""
        self.add_capsules(a, b, radius, color, outline)

    def add_spheres(
        self, center: ArrayLike, radius: ArrayLike, color: ArrayLike = (0.95, 0.95, 0.97), outline: ArrayLike = False
    ) -> None:
        """Append ``N`` spheres at ``center [N,3]``."""
        c = np.asarray(center, dtype=np.float64).reshape(-1, 3)
        self._fill_capsule_rows(self.spheres, len(c), c, c, radius, color, outline)

    def add_sphere(
        self, center: ArrayLike, radius: float, color: ArrayLike = (0.95, 0.95, 0.97), outline: bool = False
    ) -> None:
        """Append one sphere."""
        self.add_spheres(center, radius, color, outline)

    def add_cones(
        self,
        base: ArrayLike,
        apex: ArrayLike,
        radius: ArrayLike,
        color: ArrayLike = (0.16, 0.36, 0.24),
        snow: ArrayLike = 0.0,
    ) -> None:
        """Append ``N`` cones from a base disc of ``radius`` at ``base [N,3]`` to ``apex [N,3]``; ``snow`` in [0, 1]."""
        a = np.asarray(base, dtype=np.float64).reshape(-1, 3)
        self._fill_capsule_rows(self.cones, len(a), a, apex, radius, color, np.clip(np.asarray(snow, float), 0, 1))

    def add_prints(
        self, xz: ArrayLike, heading: ArrayLike, length: float = 0.26, width: float = 0.11, strength: ArrayLike = 1.0
    ) -> None:
        """Append ``N`` footprints at ``xz [N,2]`` pointing along ``heading [N]`` (radians from +x towards +z)."""
        p = _col(xz, np.asarray(xz).reshape(-1, 2).shape[0], 2, "xz")
        n = len(p)
        h = _col(heading, n, 1, "heading")
        rows = self.prints.extend(n)
        rows[:, 0:2], rows[:, 2], rows[:, 3] = p, np.cos(h), np.sin(h)
        rows[:, 4], rows[:, 5], rows[:, 6] = 0.5 * length, 0.5 * width, np.clip(_col(strength, n, 1, "strength"), 0, 1)

    def add_boxes(
        self,
        center: ArrayLike,
        half_extents: ArrayLike,
        rotation: ArrayLike = (1.0, 0.0, 0.0, 0.0),
        color: ArrayLike = (0.7, 0.6, 0.5),
        outline: ArrayLike = False,
    ) -> None:
        """Append ``N`` oriented boxes (rotation as (w,x,y,z) quaternions)."""
        c = _col(center, np.asarray(center).reshape(-1, 3).shape[0], 3, "center")
        n = len(c)
        h = _col(half_extents, n, 3, "half_extents")
        if np.any(h < 0):
            raise ValueError("half_extents must be non-negative")
        q = _col(rotation, n, 4, "rotation")
        q = q / np.maximum(np.linalg.norm(q, axis=1, keepdims=True), 1e-12)
        col = _col(color, n, 3, "color")
        out = _col(np.asarray(outline, dtype=np.float64), n, 1, "outline")
        rows = self.boxes.extend(n)
        rows[:, 0:3], rows[:, 3:6], rows[:, 6:10], rows[:, 10:13], rows[:, 13] = c, h, q, col, out

    def add_box(
        self,
        center: ArrayLike,
        half_extents: ArrayLike,
        rotation: ArrayLike = (1.0, 0.0, 0.0, 0.0),
        color: ArrayLike = (0.7, 0.6, 0.5),
        outline: bool = False,
    ) -> None:
        """Append one oriented box."""
        self.add_boxes(center, half_extents, rotation, color, outline)

    def add_lines(
        self, p0: ArrayLike, p1: ArrayLike, color: ArrayLike = (0.1, 0.1, 0.1), width: ArrayLike = 2.0
    ) -> None:
        """Append ``N`` debug line segments ``p0 [N,3] -> p1 [N,3]``, ``width`` in pixels."""
        a = _col(p0, np.asarray(p0).reshape(-1, 3).shape[0], 3, "p0")
        n = len(a)
        b, col, w = _col(p1, n, 3, "p1"), _col(color, n, 3, "color"), _col(width, n, 1, "width")
        rows = self.lines.extend(n)
        rows[:, 0:3], rows[:, 3:6], rows[:, 6:9], rows[:, 9] = a, b, col, w

    def add_line(self, p0: ArrayLike, p1: ArrayLike, color: ArrayLike = (0.1, 0.1, 0.1), width: float = 2.0) -> None:
        """Append one line segment."""
        self.add_lines(p0, p1, color, width)

    def add_polyline(
        self, points: ArrayLike, color: ArrayLike = (0.1, 0.1, 0.1), width: float = 2.0, closed: bool = False
    ) -> None:
        """Append the segments joining consecutive ``points [N,3]`` (a curve, a trajectory)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if closed and len(p) > 2:
            p = np.vstack([p, p[:1]])
        if len(p) >= 2:
            self.add_lines(p[:-1], p[1:], color, width)

    def add_points(
        self, pos: ArrayLike, size: ArrayLike = 0.03, color: ArrayLike = (1.0, 1.0, 1.0), pixels: bool = False
    ) -> None:
        """Append ``N`` round points (snowflakes, curve keypoints); ``size`` is a diameter in metres or pixels."""
        p = _col(pos, np.asarray(pos).reshape(-1, 3).shape[0], 3, "pos")
        n = len(p)
        s = _col(size, n, 1, "size")
        if np.any(s < 0):
            raise ValueError("point size must be non-negative")
        col = _col(color, n, 3, "color")
        rows = self.points.extend(n)
        rows[:, 0:3], rows[:, 3], rows[:, 4:7], rows[:, 7] = p, s, col, 1.0 if pixels else 0.0

    def add_text(
        self,
        text: str,
        x: float | None = None,
        y: float | None = None,
        size: int = 18,
        color: tuple[float, float, float] = (1.0, 1.0, 1.0),
        anchor: tuple[float, float] | None = None,
        alpha: float = 1.0,
    ) -> None:
        """Append an overlay line; without ``x``/``y`` it stacks below the previous auto-placed line
        (see :class:`TextLine` for ``anchor`` and ``alpha``)."""
        if not isinstance(text, str):
            raise TypeError(f"text must be a str, got {type(text).__name__}")
        if size <= 0:
            raise ValueError(f"text size must be positive, got {size}")
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"text alpha must be in [0, 1], got {alpha}")
        if anchor is not None:
            anchor = (float(anchor[0]), float(anchor[1]))
        rgb = (float(color[0]), float(color[1]), float(color[2]))
        self.texts.append(TextLine(text, x, y, int(size), rgb, anchor, float(alpha)))

    def set_background(self, image: ArrayLike | None, fade: float | None = None) -> None:
        """Set (or with ``None`` remove) the ``[H,W,3]`` uint8 background photo and optionally its fade."""
        if image is not None:
            img = np.asarray(image)
            if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8 or min(img.shape[:2]) < 1:
                raise ValueError(f"background must be uint8 [H,W,3], got {img.dtype} {img.shape}")
            image = np.ascontiguousarray(img)
        self.background = image
        if fade is not None:
            if not 0.0 <= fade <= 1.0:
                raise ValueError(f"background fade must be in [0, 1], got {fade}")
            self.background_fade = float(fade)

    def add_overlay(
        self,
        image: ArrayLike,
        rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0),
        depth_at: ArrayLike | None = None,
        photo: bool = False,
        alpha: float = 1.0,
    ) -> None:
        """Append an :class:`Overlay` (drawn after the 3-D scene, before the text)."""
        img = np.asarray(image)
        if img.ndim != 3 or img.shape[2] != 4 or img.dtype != np.uint8 or min(img.shape[:2]) < 1:
            raise ValueError(f"overlay must be uint8 [H,W,4], got {img.dtype} {img.shape}")
        at = None
        if depth_at is not None:
            a0, a1, a2 = (float(x) for x in np.asarray(depth_at, dtype=np.float64).reshape(3))
            at = (a0, a1, a2)
        r0, r1, r2, r3 = (float(x) for x in rect)
        r = (r0, r1, r2, r3)
        if not (r[0] < r[2] and r[1] < r[3]):
            raise ValueError(f"overlay rect must be (u0, v0, u1, v1) with u0 < u1 and v0 < v1, got {rect}")
        self.overlays.append(Overlay(np.ascontiguousarray(img), r, at, bool(photo), float(np.clip(alpha, 0.0, 1.0))))

    # -- views ------------------------------------------------------------------------
    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """``(lo [3], hi [3])`` of every shadow caster (capsules, spheres, cones, boxes, skinned characters),
        ``None`` if empty."""
        los, his = [], []
        for character in self.skinned:
            lo, hi = character.bounds()
            los.append(lo[None])
            his.append(hi[None])
        for rows in (self.capsules, self.spheres, self.cones):
            if len(rows):
                # Reduced per kind and by columns (numpy reduces a [N, 3] array along its rows slowly:
                # a crowd's 21,000 capsules took 3 ms, now 0.3): the same values to the bit.
                c = np.ascontiguousarray(rows.data[:, 0:7].T)
                los.append((np.minimum(c[0:3], c[3:6]) - c[6]).min(axis=1)[None])
                his.append((np.maximum(c[0:3], c[3:6]) + c[6]).max(axis=1)[None])
        b = self.boxes.data
        if len(b):
            r = np.linalg.norm(b[:, 3:6], axis=1, keepdims=True)
            los.append(b[:, 0:3] - r)
            his.append(b[:, 0:3] + r)
        if not los:
            return None
        return np.vstack(los).min(axis=0).astype(np.float64), np.vstack(his).max(axis=0).astype(np.float64)

    @staticmethod
    def _fill_capsule_rows(
        target: Rows,
        n: int,
        a: NDArray[np.float64],
        b: ArrayLike,
        radius: ArrayLike,
        color: ArrayLike,
        outline: ArrayLike,
    ) -> NDArray[np.float32]:
        b_arr = _col(b, n, 3, "b")
        r = _col(radius, n, 1, "radius")
        if np.any(r < 0):
            raise ValueError("radius must be non-negative")
        col = _col(color, n, 3, "color")
        out = _col(np.asarray(outline, dtype=np.float64), n, 1, "outline")
        a = _col(a, n, 3, "a")
        rows = target.extend(n)
        rows[:, 0:3], rows[:, 3:6], rows[:, 6], rows[:, 7:10], rows[:, 10] = a, b_arr, r, col, out
        return rows
