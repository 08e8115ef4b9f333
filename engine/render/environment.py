"""The environment passes: ground, far ridge, sky and sun, then the decals on the ground.

The ground and the sky are shaded per vertex (see :mod:`engine.render.shaders_ground`
for why), so together they cost about one clear of the screen; the ground shadow, the
snow track and the footprints are each drawn over the bounded rectangle they cover.
Per-pixel variants of the ground exist for what per-vertex light cannot show: the fine
snow near the camera (``detail``, quality high), grid lines, the background photo.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.render import env_meshes
from engine.render import shaders as S
from engine.render import shaders_env as E
from engine.render import shaders_ground as G
from engine.render.gpu import Instances, Releasable, mesh_buffers, set_uniform
from engine.render.scene import PRINT_STRIDE, GroundMarks, RenderScene

__all__ = [
    "Environment",
    "GROOVE",
    "SHADOW_STRENGTH",
    "ground_fills_view",
    "groove_shade",
    "marks_rect",
    "shadow_take",
    "soften_marks",
]

_PRINT_FMT = ("2f 2f 2f 1f/i", "i_xz", "i_dir", "i_half", "i_strength")
RIDGE_RADIUS = 130.0
"""Distance of the far hills (inside the ground's extent, so they stand on it)."""


def soften_marks(amount: NDArray[np.float32]) -> NDArray[np.uint8]:
    """The track grid blurred by one cell ([1, 2, 1] both ways) as 8-bit: with bilinear
    filtering, a soft groove with no cell corners."""
    a = np.pad(np.asarray(amount, dtype=np.float32), 1, mode="edge")
    a = 0.25 * a[:-2] + 0.5 * a[1:-1] + 0.25 * a[2:]
    a = 0.25 * a[:, :-2] + 0.5 * a[:, 1:-1] + 0.25 * a[:, 2:]
    return np.clip(a * 255.0 + 0.5, 0, 255).astype(np.uint8)


GROOVE = 1.6
"""Groove depth per unit of slope of the softened track (how strongly its walls catch the sun)."""
_FLOOR_TINT = np.array([0.76, 0.82, 0.92], dtype=np.float32)
"""Packed, shaded snow at a track's bottom (multiplies the snow's colour)."""


def groove_shade(soft: NDArray[np.uint8], sun_dir: NDArray[np.float64]) -> NDArray[np.uint8]:
    """The track's texture ``[Nz, Nx, 4]``: rgb half the factor that multiplies the snow's colour, alpha
    how much snow the cell lost (``soft``, from :func:`soften_marks`).

    Each texel is a groove floor tinted with packed snow, its walls lit by how their normal
    (from the central differences of ``soft``, clamped at the edges) faces the sun:
    brighter towards it, darker away. Done here once per change of the track or the sun
    rather than per pixel, where the four extra fetches were most of the decal's cost.
    """
    m = soft.astype(np.float32) / 255.0
    p = np.pad(m, 1, mode="edge")
    gx = (p[1:-1, 2:] - p[1:-1, :-2]) * GROOVE
    gz = (p[2:, 1:-1] - p[:-2, 1:-1]) * GROOVE
    sx, sy, sz = (float(v) for v in sun_dir)
    # n = (gx, 1, gz) / |(gx, 1, gz)|, dotted with the sun (elementwise: no [N, N, 3] temporaries)
    ndl = (gx * sx + sy + gz * sz) / np.sqrt(1.0 + gx * gx + gz * gz)
    light = np.clip(np.maximum(ndl, 0.0) / max(sy, 0.2), 0.72, 1.12)

    def smoothstep(e0: float, e1: float, x: NDArray[np.float32]) -> NDArray[np.float32]:
        t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
        return t * t * (3.0 - 2.0 * t)

    tint = 1.0 + (_FLOOR_TINT - 1.0) * smoothstep(0.0, 1.0, m)[..., None]
    k = tint * (1.0 + (light - 1.0) * smoothstep(0.0, 0.4, m))[..., None]
    out = np.empty((*m.shape, 4), dtype=np.uint8)
    out[..., :3] = np.minimum(k * 127.5 + 0.5, 255.0).astype(np.uint8)  # k > 0: no lower clip
    out[..., 3] = soft
    return out


SHADOW_STRENGTH = 0.9
"""How much of the sun's light the ground shadow takes away."""


def shadow_take(common: dict[str, Any], strength: float = SHADOW_STRENGTH) -> tuple[float, float, float]:
    """The share of the snow's light (per channel, linear) the ground shadow takes away: the sun's share
    of it, ``sun / (sun + sky · ambient · 1.6)`` with ``sun`` its colour times its height, times
    ``strength`` (``u_shadow_take`` of :data:`~engine.render.shaders_ground.SHADOW_DECAL_FS` and of the
    ground's ``MASK``), from the frame's uniforms ``common`` (sun, sky, ambient)."""
    height, ambient = float(common["u_sun_dir"][1]), float(common["u_ambient"])
    out = []
    for c, s in zip(common["u_sun_color"], common["u_sky_lin"], strict=True):
        sun = float(c) * height
        out.append(strength * sun / (sun + float(s) * ambient * 1.6))
    return out[0], out[1], out[2]


def marks_rect(marks: GroundMarks, threshold: float = 0.02) -> tuple[float, float, float, float] | None:
    """``(x0, z0, width, depth)`` around the cells with a mark (one cell of margin), ``None`` without any."""
    rows = np.nonzero(marks.amount.max(axis=1) > threshold)[0]
    cols = np.nonzero(marks.amount.max(axis=0) > threshold)[0]
    if len(rows) == 0:
        return None
    c = marks.cell
    x0, x1 = marks.x0 + (cols[0] - 1) * c, marks.x0 + (cols[-1] + 2) * c
    z0, z1 = marks.z0 + (rows[0] - 1) * c, marks.z0 + (rows[-1] + 2) * c
    return float(x0), float(z0), float(x1 - x0), float(z1 - z0)


def ground_fills_view(
    inv_view_proj: NDArray[np.float64], eye: NDArray[np.float64], height: float, reach: float
) -> bool:
    """Whether every pixel's ray meets the ground (the plane ``y = height``) less than ``reach`` metres
    away across it: then the ground mesh hides the whole sky, ridge and sun, and they need not be drawn.

    A camera looking down at a field (the snowman game's) sees no sky, yet drawing the dome,
    the ridge and the sun set up and binned their ~2,000 triangles before the depth test threw
    every pixel away. Checking the view's four corner rays suffices: without roll the
    highest rays are at the top corners, and the ground seen is the convex quadrilateral
    between the corner rays' hits, inside the circle of ``reach`` when they are.
    """
    drop = float(eye[1]) - height
    if drop <= 0.0:
        return False
    far = np.array([[x, y, 1.0, 1.0] for x in (-1.0, 1.0) for y in (-1.0, 1.0)]) @ np.asarray(inv_view_proj).T
    rays = far[:, :3] / far[:, 3:4] - np.asarray(eye, dtype=np.float64)
    if not np.all(rays[:, 1] < 0.0):
        return False
    across = drop / -rays[:, 1] * np.hypot(rays[:, 0], rays[:, 2])
    return bool(np.all(across < reach))


class Environment:
    """GPU objects and draws of the environment for one context."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        h, lit = S.HEADER, S.HEADER + S.LIGHTING
        self._ground_vs = lit + G.GROUND_MESH_VS
        self._programs: dict[str, moderngl.Program] = {
            "sky": ctx.program(vertex_shader=lit + G.SKY_DOME_VS, fragment_shader=h + G.COLOR_FS),
            "ridge": ctx.program(vertex_shader=lit + G.RIDGE_VS, fragment_shader=h + G.COLOR_FS),
            "sun": ctx.program(vertex_shader=lit + G.SUN_VS, fragment_shader=lit + G.SUN_FS),
            "shadow": ctx.program(vertex_shader=h + G.DECAL_VS, fragment_shader=lit + G.SHADOW_DECAL_FS),
            "marks": ctx.program(vertex_shader=h + G.DECAL_VS, fragment_shader=lit + G.MARKS_FS),
            "prints": ctx.program(vertex_shader=h + G.PRINT_VS, fragment_shader=lit + G.PRINT_FS),
        }
        self._buffers: list[moderngl.Buffer] = []
        rings = env_meshes.ground_rings()
        self._ground_mesh = self._keep(*mesh_buffers(ctx, rings))
        segments = int(np.count_nonzero(rings[0][:, 2] == 0.0))  # the first ring is the centre
        self._band_indices = 6 * segments
        """Indices of one band of the mesh (between two rings): its triangles run ring by ring."""
        self._ring_bands = rings[0][::segments, 2][:-1].astype(np.float64) * np.cos(np.pi / segments)
        """Least distance from the centre of each band, as a fraction of the ground's extent."""
        self._vaos: dict[str, moderngl.VertexArray] = {}
        for name, mesh, fmt in (
            ("sky", env_meshes.sky_sphere(), ("3f", "in_dir")),
            ("ridge", env_meshes.ridge_strip(), ("4f", "in_ridge")),
        ):
            vbo, ibo = self._keep(*mesh_buffers(ctx, mesh))
            self._vaos[name] = ctx.vertex_array(self._programs[name], [(vbo, *fmt)], ibo, 4)
        square, unit = self._keep(
            ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype=np.float32).tobytes()),
            ctx.buffer(np.array([0, 0, 1, 0, 0, 1, 1, 1], dtype=np.float32).tobytes()),
        )
        self._vaos["sun"] = ctx.vertex_array(self._programs["sun"], [(square, "2f", "in_corner")])
        for name in ("shadow", "marks"):
            self._vaos[name] = ctx.vertex_array(self._programs[name], [(unit, "2f", "in_corner")])
        self._prints = Instances(ctx, 4 * PRINT_STRIDE)
        self._vaos["prints"] = ctx.vertex_array(
            self._programs["prints"], [(square, "2f", "in_corner"), (self._prints.buf, *_PRINT_FMT)]
        )
        self._marks_tex: moderngl.Texture | None = None
        self._marks_src: bytes = b""
        self._common: dict[str, Any] = {}
        self._reads: dict[tuple[str, ...], tuple[str, ...]] = {}

    def _keep(self, *bufs: moderngl.Buffer) -> tuple[moderngl.Buffer, ...]:
        self._buffers += list(bufs)
        return bufs

    def _ground_variant(self, features: tuple[str, ...]) -> str:
        """The key of the ground's program with these fragment ``features`` (``PIXEL``, ``NEAR``, ``MASK``,
        ``GRID``, ``PHOTO``: see :data:`~engine.render.shaders_ground.GROUND_MESH_FS`), compiled on first use."""
        key = "ground" + "".join("_" + f.lower() for f in features)
        if key not in self._programs:
            defines = f"#define NEAR_DETAIL {G.NEAR_DETAIL!r}\n" + "".join(f"#define {f} 1\n" for f in features)
            fs = S.HEADER + defines + S.LIGHTING + E.BACKGROUND + G.GROUND_MESH_FS
            prog = self._programs[key] = self.ctx.program(vertex_shader=self._ground_vs, fragment_shader=fs)
            for name, value in self._common.items():
                set_uniform(prog, name, value)
            vbo, ibo = self._ground_mesh
            self._vaos[key] = self.ctx.vertex_array(prog, [(vbo, "3f", "in_ring")], ibo, 4)
        return key

    def ground_draws(
        self, detail: bool, grid: bool, photo: bool, uniforms: dict[str, Any]
    ) -> list[tuple[str, int, int]]:
        """The ground's draws: ``(program key, first index, index count)`` over its mesh.

        Without ``detail`` one draw. With it (quality high) the fine snow is compiled only into
        the draw of the rings that come within :data:`~engine.render.shaders_ground.NEAR_DETAIL`
        of the eye, and the shadow mask is read only when there is a shadow
        (``u_shadow_strength`` above 0), by the rings that reach into its rectangle (``u_rect``,
        as far as its farthest corner): llvmpipe pays a branch's fetches and arithmetic on
        every pixel of a draw that contains it, taken or not (measured on the empty field at
        1280x720: 45-50 ms with both, 24-29 without the near branch, 32 without the mask's).
        A ring's band lies at least ``radius · cos(π/segments)`` from the centre under the eye
        (its chords' distance), so a band beyond that bound never enters the near branch and
        its pixels are the same without it; a band beyond the rectangle's farthest corner never
        passes the mask's rectangle test, likewise.
        """
        per_pixel = ("PIXEL",) if detail or grid or photo else ()
        extra = tuple(f for f, on in (("GRID", grid), ("PHOTO", photo)) if on)
        total = len(self._ring_bands) * self._band_indices
        if not detail:
            return [(self._ground_variant(per_pixel + extra), 0, total)]
        reach = self._ring_bands * float(uniforms["u_extent"])
        near_bands = int(np.count_nonzero(reach < G.NEAR_DETAIL * 1.01))  # 1 % margin for float rounding
        mask_bands = 0
        if uniforms["u_shadow_strength"] > 0.0:  # the bands that reach into the shadow's rectangle
            x0, z0, w, d = (float(v) for v in uniforms["u_rect"])
            cx, _, cz = (float(v) for v in uniforms["u_center"])
            corner = max(np.hypot(x - cx, z - cz) for x in (x0, x0 + w) for z in (z0, z0 + d))
            mask_bands = int(np.count_nonzero(reach < corner * 1.01))
        draws, start = [], 0
        for end in sorted({near_bands, mask_bands, len(reach)}):
            if end > start:
                features = ("NEAR",) * (start < near_bands) + ("MASK",) * (start < mask_bands)
                key = self._ground_variant(("PIXEL", *features, *extra))
                draws.append((key, start * self._band_indices, (end - start) * self._band_indices))
            start = end
        return draws

    def reads(self, draws: list[tuple[str, int, int]]) -> tuple[str, ...]:
        """The names of the uniforms the ground's ``draws`` (:meth:`ground_draws`), the ridge, the sky and the
        sun read (asked of the compiled programs: what a kept copy of them depends on, :mod:`engine.render.env_cache`)."""
        key = tuple(k for k, _, _ in draws)
        if key not in self._reads:
            progs = (*(self._programs[k] for k in key), *(self._programs[k] for k in ("ridge", "sky", "sun")))
            self._reads[key] = tuple(sorted({n for p in progs for n in p if isinstance(p[n], moderngl.Uniform)}))
        return self._reads[key]

    def set_common(self, uniforms: dict[str, Any], changed: Iterable[str] | None = None) -> None:
        """The frame's shared uniforms (camera, sun, fog), on every program and on any compiled later.

        ``changed``: the names whose values differ from the last call's (``None``: all); only
        those are written, since the programs still hold the others.
        """
        self._common = dict(uniforms)
        names = list(uniforms if changed is None else changed)
        for prog in self._programs.values():
            for name in names:
                set_uniform(prog, name, uniforms[name])

    def draw_ground(self, draws: list[tuple[str, int, int]], uniforms: dict[str, Any]) -> None:
        """The ground mesh in ``draws`` (:meth:`ground_draws`; ``uniforms``: centre, extent and the ground's colours)."""
        take = (
            shadow_take(self._common, float(uniforms["u_shadow_strength"])) if "u_shadow_strength" in uniforms else None
        )
        for key, first, count in draws:
            prog = self._programs[key]
            for name, value in uniforms.items():
                set_uniform(prog, name, value)
            if take is not None:
                set_uniform(prog, "u_shadow_take", take)
            self._vaos[key].render(moderngl.TRIANGLES, vertices=count, first=first)

    def draw_sky(self, scene: RenderScene, photo: bool, ground_height: float) -> None:
        """The far ridge, the sky and the sun (without a photo behind; with one, the caller draws its sky)."""
        ctx = self.ctx
        if not photo and scene.ground.visible:
            set_uniform(self._programs["ridge"], "u_radius", RIDGE_RADIUS)
            set_uniform(self._programs["ridge"], "u_height", ground_height)
            self._vaos["ridge"].render(moderngl.TRIANGLES)
        if photo:
            return
        ctx.depth_func = "<="
        self._vaos["sky"].render(moderngl.TRIANGLES)
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        set_uniform(self._programs["sun"], "u_sun_size", 0.09)
        self._vaos["sun"].render(moderngl.TRIANGLE_STRIP)
        ctx.disable(moderngl.BLEND)
        ctx.depth_func = "<"

    def draw_decals(
        self, scene: RenderScene, shadow_rect: tuple[float, float, float, float] | None, mask: moderngl.Texture | None
    ) -> None:
        """Ground shadow (``None``: the ground read it itself), snow track and footprints, each over the
        rectangle it covers.

        They modulate what the ground drew (``2·src·dst``) where the depth buffer still
        holds the ground: objects in front keep their pixels. Polygon offset keeps the
        decals above the ground mesh, whose triangles are not theirs.
        """
        ctx = self.ctx
        height = float(scene.ground.height)
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.depth_func = "<="
        ctx.blend_func = moderngl.DST_COLOR, moderngl.SRC_COLOR
        ctx.polygon_offset = -2.0, -8.0
        if shadow_rect is not None and mask is not None:
            prog = self._programs["shadow"]
            mask.use(location=4)
            for name, value in (
                ("u_rect", shadow_rect),
                ("u_height", height),
                ("u_ground_mask", 4),
                ("u_shadow_take", shadow_take(self._common)),
            ):
                set_uniform(prog, name, value)
            self._vaos["shadow"].render(moderngl.TRIANGLE_STRIP)
        if scene.marks is not None:
            sun = np.asarray(scene.sun.direction, dtype=np.float64)
            self._draw_marks(scene.marks, height, sun / np.linalg.norm(sun))
        if self._prints.upload(scene.prints.data):
            set_uniform(self._programs["prints"], "u_height", height)
            self._vaos["prints"].render(moderngl.TRIANGLE_STRIP, instances=self._prints.count)
        ctx.polygon_offset = 0.0, 0.0
        ctx.depth_func = "<"

    def _draw_marks(self, marks: GroundMarks, height: float, sun_dir: NDArray[np.float64]) -> None:
        rect = marks_rect(marks)
        if rect is None:
            return
        # The texture is made again only when the track or the sun changed (the key is the raw grid).
        key = np.ascontiguousarray(marks.amount).tobytes() + np.asarray(sun_dir, dtype=np.float64).tobytes()
        nz, nx = marks.amount.shape
        if self._marks_tex is None or self._marks_tex.size != (nx, nz):
            if self._marks_tex is not None:
                self._marks_tex.release()
            self._marks_tex = self.ctx.texture((nx, nz), 4, groove_shade(soften_marks(marks.amount), sun_dir).tobytes())
            self._marks_tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._marks_tex.repeat_x = self._marks_tex.repeat_y = False
        elif key != self._marks_src:
            self._marks_tex.write(groove_shade(soften_marks(marks.amount), sun_dir).tobytes())
        self._marks_src = key
        self._marks_tex.use(location=5)
        # The decal's rectangle in the texture's uv (texel centres at (i + 0.5) / n).
        w, d = marks.cell * nx, marks.cell * nz
        prog = self._programs["marks"]
        u0, v0 = (rect[0] - marks.x0) / w, (rect[1] - marks.z0) / d
        for name, value in (
            ("u_rect", rect),
            ("u_height", height),
            ("u_marks", 5),
            ("u_uv_rect", (u0, v0, rect[2] / w, rect[3] / d)),
        ):
            set_uniform(prog, name, value)
        self._vaos["marks"].render(moderngl.TRIANGLE_STRIP)

    def release(self) -> None:
        """Free the GPU objects."""
        objects: tuple[Releasable, ...] = (
            *self._vaos.values(),
            *self._buffers,
            *self._programs.values(),
            self._prints.buf,
        )
        for obj in objects:
            obj.release()
        if self._marks_tex is not None:
            self._marks_tex.release()
