"""The moderngl renderer: draws a :class:`RenderScene` through a camera into a framebuffer.

Passes, in order (each kind of primitive is one instanced draw call):

0. **sky and ground** of a view that stays still: copied in from the frame that drew them
   (:mod:`engine.render.env_cache`), in place of the clear; a new view is drawn here and kept.
1. **shadows** — a sun depth map for objects and, read from it, a blurred mask for the ground
   (:mod:`engine.render.shadows`), both fitted around the casters each frame, and kept from the
   last frame when nothing they are drawn from changed (``reuse_shadows``); the scenery's part
   of the map (cones, boxes) is kept while it and the sun's matrix stay.
2. **outline** — highlighted items, inflated by a few pixels and drawn with front-face
   culling in a flat colour: only a rim around the silhouette stays visible.
3. **objects** — capsules, spheres, cones, boxes, lit by sun, sky ambient and shadow; capsules
   and spheres with the coarsest mesh their size on screen allows (:mod:`engine.render.lod`),
   or ray-cast on a quad over their outline where the level says so (:mod:`engine.render.impostors`),
   and only those whose bounding sphere is in view.
4. **environment** (:mod:`engine.render.environment`) — the ground, the far ridge, the sky
   and the sun, shaded per vertex (the last three not drawn when the ground fills the view),
   here only when they cannot be kept (the ground reads the shadow mask or a photo); then the decals laid on the ground over the rectangles they cover: soft shadow, snow track,
   footprints.
5. **lines**, **points** — screen-space quads and round point sprites, depth-tested.
6. **overlays** — pictures aligned with the photo (:class:`~engine.render.scene.Overlay`): at a
   depth (a real prop in front of or behind 3-D objects) or over everything (an interface).
7. **text** — the overlay, in pixels, always at the window's full size.

The :class:`~engine.render.quality.Quality` level sets how many pixels passes 1-6 shade
(a smaller buffer, scaled up before the text), the shadow resolutions and the detail.

Opaque passes run nearest-first because on a software rasteriser (llvmpipe) fragment
shading is the cost: the early depth test then skips ground and sky under the puppets.
The renderer owns GPU objects only; it never writes the scene or the simulation.
"""

from __future__ import annotations

import hashlib
import math
import time
from collections.abc import Callable
from typing import Any

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.camera import Camera
from engine.render import meshes
from engine.render import shaders as S
from engine.render import shaders_env as E
from engine.render.bgra import colour_texture, release_texture
from engine.render.env_cache import EnvironmentCache, single_sampled, view_key
from engine.render.env_meshes import cone_mesh
from engine.render.environment import RIDGE_RADIUS, Environment, ground_fills_view
from engine.render.gpu import Instances, LodBatches, Releasable, mesh_buffers, set_uniform
from engine.render.impostors import Impostors
from engine.render.lod import LEVELS, LIMITS, choose_levels, level_meshes
from engine.render.noise import snow_noise
from engine.render.offscreen import is_software
from engine.render.quality import QUALITIES, Quality
from engine.render.scene import BOX_STRIDE, CAPSULE_STRIDE, CONE_STRIDE, LINE_STRIDE, POINT_STRIDE, RenderScene
from engine.render.shadows import BOX_FMT, CAPSULE_FMT, Shadows, ground_rect, light_matrix
from engine.render.skinned import SKIN_FS, SKIN_VS, SkinnedDraw
from engine.render.text import TextCache, layout_text

__all__ = ["Renderer"]

_LINE_FMT = ("3f 3f 3f 1f/i", "i_p0", "i_p1", "i_color", "i_width")
_POINT_FMT = ("3f 1f 3f 1f", "i_pos", "i_size", "i_color", "i_pixels")
_SOLIDS = ("capsules", "spheres", "boxes")
_KINDS = (*_SOLIDS, "cones", "lines", "points")
# Nearest texel at the interpolated uv of the full-screen triangle. On llvmpipe a filtered
# full-screen fetch cost 6.5 ms a frame at 1280x720, more than the pixels the smaller buffer
# saved; a nearest fetch by integer address (texelFetch of gl_FragCoord) cost 9.5 ms against
# 7.0 ms for this one in the same run (median of 12 × 8 frames, process CPU), same pixels.
_UPSCALE_FS = """
uniform sampler2D u_tex;
in vec2 v_uv;
out vec4 f_color;
void main() { f_color = texture(u_tex, v_uv); }
"""


def _nearest_first(rows: NDArray[np.float32], eye: NDArray[np.float64]) -> NDArray[np.float32]:
    """Instances sorted by the distance of their centre to the eye, nearest first.

    On llvmpipe a fragment is shaded unless the depth buffer already holds something
    nearer; drawing near shapes first lets the early depth test skip what they hide
    (tree tiers, balls behind puppets) instead of shading it and painting over it. The
    first six numbers of every row are two points (capsule ends; a box's centre and
    half sizes, where the first three are the centre too).
    """
    if len(rows) < 2:
        return rows
    # By columns: numpy sums a [N, 3] array along its rows slowly (a crowd's 21,000 capsules: 1.3 ms
    # against 0.3), and the same sums in the same order give the same distances to the bit.
    c = np.ascontiguousarray(rows[:, 0:6].T)
    if rows.shape[1] != BOX_STRIDE:  # cones too
        x, y, z = (0.5 * (c[k] + c[k + 3]) - eye[k] for k in range(3))
    else:
        x, y, z = (c[k] - eye[k] for k in range(3))
    return rows[np.argsort(x * x + y * y + z * z, kind="stable")]


def _in_view(rows: NDArray[np.float32], vp: NDArray[np.float64]) -> NDArray[np.intp]:
    """Indices of the capsule rows (ends in columns 0-5, radius in 6) whose bounding sphere meets
    the view frustum of ``vp``, in order.

    A crowd seen from within draws a tenth of its puppets or less: on a software rasteriser
    every instance drawn costs vertex work on the main thread, on screen or not.
    """
    if len(rows) == 0:
        return np.arange(0)
    c = np.ascontiguousarray(rows[:, 0:7].T, dtype=np.float64)  # by columns, as in _nearest_first
    centre = [0.5 * (c[k] + c[k + 3]) for k in range(3)]
    half = [c[k + 3] - c[k] for k in range(3)]
    reach = -(0.5 * np.sqrt(half[0] * half[0] + half[1] * half[1] + half[2] * half[2]) + c[6])
    m = np.asarray(vp, dtype=np.float64)
    planes = np.array([m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[3] + m[2], m[3] - m[2]])
    planes /= np.linalg.norm(planes[:, :3], axis=1, keepdims=True)
    inside = np.ones(len(rows), dtype=bool)
    for p in planes:
        inside &= centre[0] * p[0] + centre[1] * p[1] + centre[2] * p[2] + p[3] >= reach
    return np.nonzero(inside)[0]


def _shadow_key(
    scene: RenderScene,
    casters: dict[str, tuple[NDArray[np.float32], NDArray[np.intp]]],
    rows: dict[str, NDArray[np.float32]],
    light_vp: NDArray[np.float64],
    rect: tuple[float, float, float, float],
    how: tuple[object, bool],
) -> bytes | None:
    """A digest of everything the shadow map and the ground mask are drawn from, ``None`` if that
    cannot be told (skinned characters: their poses live in textures).

    When the sun and every caster stand still (an idle scene, a paused game) the key repeats
    and the frame reuses last frame's map and mask instead of drawing the casters again.
    ``how``: the shadow buffers in use and whether the casters are impostors.
    """
    if scene.skinned:
        return None
    h = hashlib.blake2b(digest_size=16)
    h.update(f"{id(how[0])} {how[1]} {scene.sun.softness!r} {scene.ground.height!r} {rect!r}".encode())
    h.update(np.ascontiguousarray(light_vp).tobytes())
    for kind in sorted(casters):
        for part in casters[kind]:
            h.update(np.ascontiguousarray(part).tobytes())
    for kind in ("boxes", "cones"):
        h.update(np.ascontiguousarray(rows[kind]).tobytes())
    return h.digest()


def _same_value(a: Any, b: Any) -> bool:
    """Whether two uniform values are equal (numbers, tuples or numpy matrices)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and np.array_equal(a, b)
    return bool(a == b)


def _linear(c: Any) -> tuple[float, float, float]:
    a = np.clip(np.asarray(c, dtype=np.float64), 0.0, None) ** 2  # the shaders' gamma 2.0
    return float(a[0]), float(a[1]), float(a[2])


class Renderer:
    """Draws scenes with one moderngl context (window or headless).

    Args:
        ctx: an OpenGL 3.3 core context.
        quality: the level drawn at (``high`` by default; :meth:`set_quality` changes it).
    """

    def __init__(self, ctx: moderngl.Context, quality: Quality = QUALITIES["high"]) -> None:
        self.ctx = ctx
        h, lit = S.HEADER, S.HEADER + S.LIGHTING
        p = self._programs = {
            "capsule": ctx.program(vertex_shader=h + S.CAPSULE_VS, fragment_shader=lit + S.LIT_FS),
            "capsule_flat": ctx.program(vertex_shader=h + S.CAPSULE_VS, fragment_shader=h + S.FLAT_FS),
            "box": ctx.program(vertex_shader=h + S.BOX_VS, fragment_shader=lit + S.LIT_FS),
            "box_flat": ctx.program(vertex_shader=h + S.BOX_VS, fragment_shader=h + S.FLAT_FS),
            "cone": ctx.program(vertex_shader=h + S.CONE_VS, fragment_shader=lit + S.LIT_FS),
            "upscale": ctx.program(vertex_shader=h + E.FULLSCREEN_VS, fragment_shader=h + _UPSCALE_FS),
            "sky_photo": ctx.program(
                vertex_shader=h + E.SKY_VS, fragment_shader=h + E.PHOTO_DEFINE + S.LIGHTING + E.BACKGROUND + E.SKY_FS
            ),
            "line": ctx.program(vertex_shader=h + S.LINE_VS, fragment_shader=h + S.LINE_FS),
            "point": ctx.program(vertex_shader=h + S.POINT_VS, fragment_shader=h + S.POINT_FS),
            "text": ctx.program(vertex_shader=h + S.TEXT_VS, fragment_shader=h + S.TEXT_FS),
            "overlay": ctx.program(vertex_shader=h + S.OVERLAY_VS, fragment_shader=lit + S.OVERLAY_FS),
            "skinned": ctx.program(vertex_shader=h + SKIN_VS, fragment_shader=lit + SKIN_FS),
            "skinned_flat": ctx.program(vertex_shader=h + SKIN_VS, fragment_shader=h + S.FLAT_FS),
        }
        self.skinned = SkinnedDraw(ctx, p["skinned"], p["skinned_flat"])
        strides = {
            "capsules": CAPSULE_STRIDE,
            "spheres": CAPSULE_STRIDE,
            "boxes": BOX_STRIDE,
            "lines": LINE_STRIDE,
            "points": POINT_STRIDE,
            "cones": CONE_STRIDE,
        }
        # Capsules and spheres have one buffer per level of detail (self._lod, below).
        self._inst = {k: Instances(ctx, 4 * strides[k]) for k in ("boxes", "cones", "lines", "points")}
        self._outline_inst = {k: Instances(ctx, 4 * strides[k]) for k in _SOLIDS}
        self._buffers: list[moderngl.Buffer] = []
        self._vaos: dict[str, moderngl.VertexArray] = {}
        # Lit capsules and spheres: one batch per level of detail.
        self._lod = {
            kind: LodBatches(ctx, p["capsule"], level_meshes(kind), CAPSULE_FMT, 4 * CAPSULE_STRIDE) for kind in LEVELS
        }
        # Outlines (a few focused items) take the default meshes.
        for kind, mesh in (("capsules", meshes.capsule_mesh()), ("spheres", meshes.sphere_mesh())):
            vbo, ibo = self._keep(mesh_buffers(ctx, mesh))
            self._vaos[kind + "_flat"] = ctx.vertex_array(
                p["capsule_flat"],
                [(vbo, "4f", "in_vert"), (self._outline_inst[kind].buf, *CAPSULE_FMT)],
                ibo,
                4,
                skip_errors=True,
            )
        vbo, ibo = self._keep(mesh_buffers(ctx, meshes.box_mesh()))
        for suffix, prog, inst in (
            ("", "box", self._inst["boxes"]),
            ("_flat", "box_flat", self._outline_inst["boxes"]),
        ):
            self._vaos["boxes" + suffix] = ctx.vertex_array(
                p[prog], [(vbo, "3f 3f", "in_pos", "in_normal"), (inst.buf, *BOX_FMT)], ibo, 4, skip_errors=True
            )
        vbo, ibo = self._keep(mesh_buffers(ctx, cone_mesh()))
        self._vaos["cones"] = ctx.vertex_array(
            p["cone"], [(vbo, "4f", "in_vert"), (self._inst["cones"].buf, *CAPSULE_FMT)], ibo, 4, skip_errors=True
        )
        unit, seg = self._keep(
            tuple(
                ctx.buffer(np.array(v, dtype=np.float32).tobytes())
                for v in ([0, 0, 1, 0, 0, 1, 1, 1], [0, -1, 1, -1, 0, 1, 1, 1])
            )
        )
        self._vaos["text"] = ctx.vertex_array(p["text"], [(unit, "2f", "in_corner")])
        self._vaos["overlay"] = ctx.vertex_array(p["overlay"], [(unit, "2f", "in_corner")])
        self._vaos["lines"] = ctx.vertex_array(
            p["line"], [(seg, "2f", "in_corner"), (self._inst["lines"].buf, *_LINE_FMT)], skip_errors=True
        )
        self._vaos["points"] = ctx.vertex_array(p["point"], [(self._inst["points"].buf, *_POINT_FMT)], skip_errors=True)
        for name in ("sky_photo", "upscale"):
            self._vaos[name] = ctx.vertex_array(p[name], [])
        self.env = Environment(ctx)
        self.env_cache = EnvironmentCache(ctx, is_software(ctx))
        self.impostors = Impostors(ctx)
        self.quality = quality
        self.shadows = Shadows(ctx, self._inst["boxes"], quality.shadow_map, quality.shadow_mask, self._inst["cones"])
        self._scaled: tuple[moderngl.Framebuffer, moderngl.Texture] | None = None
        self._colour_only: tuple[object, moderngl.Framebuffer] | None = None
        """The target's colour attachment and a framebuffer of it alone (the scale-up draws there)."""
        self._blank = ctx.texture((1, 1), 3, bytes([255, 255, 255]))
        noise = snow_noise()
        self._noise = ctx.texture(noise.shape[:2][::-1], 4, noise.tobytes())
        self._noise.filter = (moderngl.LINEAR, moderngl.LINEAR)  # no mipmaps: trilinear costs double here
        self._background: moderngl.Texture | None = None
        self._background_src: np.ndarray | None = None
        self.text = TextCache(ctx)
        self.profile = False
        """When true, each pass waits for the GPU and its time lands in :attr:`timings` (slow; benches only)."""
        self.timings: dict[str, float] = {}
        self._mark_t = 0.0
        self._common: dict[str, Any] = {}
        """The frame uniforms every program holds (:meth:`_set_frame_uniforms` writes only changes)."""
        self._shadow_key: bytes | None = None
        """What the shadow map and mask now hold (:func:`_shadow_key`); ``None``: nothing reusable."""
        self.reuse_shadows = False
        """Reuse last frame's shadows when nothing they are drawn from changed. Off by default, so a
        bench drawing one still frame again and again times the shadows a moving scene pays; the
        runner turns it on for play."""

    def _more_casters(
        self,
        scene: RenderScene,
        impostors: dict[str, tuple[NDArray[np.float32], NDArray[np.intp]]],
    ) -> Callable[[NDArray[np.float64]], None] | None:
        """What the shadow map draws besides its meshes: skinned characters, and the round solids
        ``impostors`` holds (by kind: rows, levels) when they are drawn as impostors."""
        if not scene.skinned and not impostors:
            return None
        look = -np.asarray(scene.sun.direction, dtype=np.float64)
        look /= np.linalg.norm(look)

        def draw(light_vp: NDArray[np.float64]) -> None:
            if impostors:
                self.impostors.draw_depth(np.concatenate([rows for rows, _ in impostors.values()]), light_vp, look)
            if scene.skinned:
                self.skinned.draw_depth(scene.skinned, light_vp)

        return draw

    def _keep(self, bufs: tuple[moderngl.Buffer, ...]) -> tuple[moderngl.Buffer, ...]:
        self._buffers += list(bufs)
        return bufs

    def _mark(self, name: str | None) -> None:
        if not self.profile:
            return
        self.ctx.finish()
        now = time.perf_counter()
        if name is not None:
            self.timings[name] = now - self._mark_t
        self._mark_t = now

    def set_quality(self, quality: Quality) -> None:
        """Draw from the next frame on at ``quality`` (shadow buffers are remade if their sizes change:
        the context must be current, as for :meth:`render`)."""
        if (quality.shadow_map, quality.shadow_mask) != (self.shadows.map_size, self.shadows.mask_size):
            self.shadows.release()
            self.shadows = Shadows(
                self.ctx, self._inst["boxes"], quality.shadow_map, quality.shadow_mask, self._inst["cones"]
            )
            self._shadow_key = None
        self.quality = quality

    def _scene_target(self, framebuffer: moderngl.Framebuffer) -> tuple[moderngl.Framebuffer, tuple[int, int]]:
        """Where the 3-D passes draw: ``framebuffer`` itself at full quality, else a smaller buffer."""
        w, h = framebuffer.size
        s = self.quality.scale
        if s >= 1.0:
            return framebuffer, (w, h)
        size = (max(1, round(w * s)), max(1, round(h * s)))
        if self._scaled is None or self._scaled[1].size != size:
            self._release_scaled()
            tex = colour_texture(self.ctx, size, is_software(self.ctx))  # BGRA: see _upscale
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)  # the scale-up's fetch (see _UPSCALE_FS)
            tex.repeat_x = tex.repeat_y = False
            self._scaled = (self.ctx.framebuffer([tex], self.ctx.depth_renderbuffer(size)), tex)
        return self._scaled[0], size

    def _release_scaled(self) -> None:
        if self._scaled is not None:
            fbo, tex = self._scaled
            fbo.depth_attachment.release()
            fbo.release()
            release_texture(tex)
            self._scaled = None
        if self._colour_only is not None:
            self._colour_only[1].release()
            self._colour_only = None

    def _colour_target(self, framebuffer: moderngl.Framebuffer) -> moderngl.Framebuffer:
        """``framebuffer``'s first colour attachment alone (made once per attachment), or ``framebuffer``
        itself when it has no depth to leave out (or no attachment to take, as a window's own)."""
        if framebuffer.depth_attachment is None or not framebuffer.color_attachments:
            return framebuffer
        colour = framebuffer.color_attachments[0]
        if self._colour_only is None or self._colour_only[0] is not colour:
            if self._colour_only is not None:
                self._colour_only[1].release()
            self._colour_only = (colour, self.ctx.framebuffer(color_attachments=[colour]))
        return self._colour_only[1]

    # -- frame ------------------------------------------------------------------------
    def draw_floor(self, scene: RenderScene, framebuffer: moderngl.Framebuffer) -> None:
        """What every frame at this level pays before it draws anything: its 3-D buffer cleared to
        ``scene``'s horizon colour and, below full size, scaled up over ``framebuffer``. The baseline
        the sky and ground are judged against at each level (``puppetphone bench render``)."""
        target, (w, h) = self._scene_target(framebuffer)
        target.use()
        target.viewport = (0, 0, w, h)
        target.clear(*scene.horizon_color, 1.0, depth=1.0)
        if target is not framebuffer:
            self._upscale(framebuffer)
            framebuffer.use()
        self.ctx.enable_only(moderngl.NOTHING)

    def render(self, scene: RenderScene, camera: Camera, framebuffer: moderngl.Framebuffer) -> None:
        """Draw ``scene`` seen by ``camera`` into ``framebuffer`` (cleared first)."""
        ctx = self.ctx
        target, (w, h) = self._scene_target(framebuffer)
        vp = camera.view_projection(w / h)
        self._mark(None)
        eye = np.asarray(camera.eye, dtype=np.float64)
        rows = {
            k: _nearest_first(getattr(scene, k).data, eye) if k in (*_SOLIDS, "cones") else getattr(scene, k).data
            for k in _KINDS
        }
        counts = {k: self._inst[k].upload(rows[k]) for k in ("boxes", "cones", "lines", "points")}
        # Coarser meshes where fewer pixels are drawn, or where the level allows a larger outline error.
        px_per_metre = h / (2.0 * math.tan(math.radians(camera.fov_y) / 2.0)) / self.quality.silhouette_px
        impostors = self.quality.impostors
        levels = {  # impostors need no mesh level: a crowd's 21,000 rows are not measured for nothing
            kind: np.zeros(len(rows[kind]), np.intp)
            if impostors
            else choose_levels(rows[kind], eye, px_per_metre, LIMITS[kind])
            for kind in self._lod
        }
        # The camera pass draws only what the view can see; the shadow map takes every caster (an
        # off-screen one may shade the ground in view).
        seen = {kind: _in_view(rows[kind], vp) for kind in self._lod}
        for kind, batches in self._lod.items():
            keep = seen[kind][:0] if impostors else seen[kind]
            batches.upload(rows[kind][keep], levels[kind][keep])
        outlined = {}
        for k, inst in self._outline_inst.items():
            d = getattr(scene, k).data
            outlined[k] = inst.upload(d[d[:, -1] > 0.5])
        bounds = scene.bounds() if scene.sun.shadows else None
        light_vp = light_matrix(scene, bounds) if bounds is not None else None
        rect = ground_rect(scene, bounds=bounds) if light_vp is not None else None
        self._set_frame_uniforms(scene, camera, vp, light_vp, (w, h))
        self._mark("uniforms")
        # The sky and ground, before the shadow pass is queued: copied in from the last frame of the
        # same view, or drawn and kept (a copy waits for the rasteriser's work on the buffers: here
        # there is none). Where they cannot be kept, they are drawn after the objects (early depth test).
        shadow_rect = rect if light_vp is not None else None
        ground = self._ground_uniforms(scene, camera, shadow_rect)
        view = self._view_key(scene, camera, target, ground)
        target.use()
        target.viewport = (0, 0, w, h)
        if view is not None and not self.env_cache.restore(view, target):
            target.clear(*scene.horizon_color, 1.0, depth=1.0)
            self._noise.use(location=3)
            self._draw_sky_and_ground(scene, camera, ground)
            self.env_cache.store(view, target)
        self._mark("sky_ground")
        if light_vp is not None and rect is not None:
            n = self.quality.max_casters  # rows are nearest-first: the nearest cast shadows
            casters = {kind: (rows[kind][:n], levels[kind][:n]) for kind in self._lod}
            key = _shadow_key(scene, casters, rows, light_vp, rect, (self.shadows, impostors))
            if key is None or key != self._shadow_key or not self.reuse_shadows:
                self.shadows.render(
                    scene,
                    {} if impostors else casters,
                    light_vp,
                    rect,
                    more_casters=self._more_casters(scene, casters if impostors else {}),
                )
            self._shadow_key = key
        self._mark("shadows")

        target.use()
        target.viewport = (0, 0, w, h)
        if view is None:
            target.clear(*scene.horizon_color, 1.0, depth=1.0)
        self._mark("clear")
        self.shadows.depth.use(location=1)
        self._background_texture(scene).use(location=2)
        self._noise.use(location=3)

        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.front_face = "ccw"
        ctx.cull_face = "front"
        for kind in _SOLIDS:
            if outlined[kind]:
                self._vaos[kind + "_flat"].render(moderngl.TRIANGLES, instances=outlined[kind])
        if any(c.outline for c in scene.skinned):
            self.skinned.draw_outline(scene.skinned)
        ctx.cull_face = "back"
        self._mark("outline")
        for batches in self._lod.values():
            batches.render()
        self._mark("lod")
        if impostors:
            solids = np.concatenate([rows["capsules"][seen["capsules"]], rows["spheres"][seen["spheres"]]])
            self.impostors.draw(_nearest_first(solids, eye), eye)
        self._mark("impostors")
        for kind in ("boxes", "cones"):
            if counts[kind]:
                self._vaos[kind].render(moderngl.TRIANGLES, instances=counts[kind])
        if scene.skinned:
            self.skinned.draw(scene.skinned)
        self._mark("objects")
        if view is None:
            self._draw_sky_and_ground(scene, camera, ground)
        self._draw_decals(scene, shadow_rect)
        self._mark("environment")

        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.PROGRAM_POINT_SIZE)
        target.depth_mask = False
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        if counts["lines"]:
            self._vaos["lines"].render(moderngl.TRIANGLE_STRIP, vertices=4, instances=counts["lines"])
        if counts["points"]:
            self._vaos["points"].render(moderngl.POINTS, vertices=counts["points"])
        self._mark("lines_points")
        self._draw_overlays(scene, vp)
        target.depth_mask = True
        if target is not framebuffer:
            self._upscale(framebuffer)
            framebuffer.use()  # the text, and whatever the caller draws next, go to the frame itself
        self._mark("upscale")
        ctx.enable_only(moderngl.BLEND)
        self._draw_text(scene, framebuffer.size)
        ctx.enable_only(moderngl.NOTHING)
        self._mark("text")

    def _ground_uniforms(
        self, scene: RenderScene, camera: Camera, rect: tuple[float, float, float, float] | None
    ) -> dict[str, Any]:
        """The ground program's own uniforms this frame (``rect``: the ground shadow's, if any)."""
        g, eye = scene.ground, camera.eye
        return {
            "u_center": (float(eye[0]), 0.0, float(eye[2])),
            "u_extent": min(camera.far * 0.9, 150.0),  # of the ground mesh around the eye
            "u_height": float(g.height),
            "u_ground_lin": _linear(g.color),
            "u_snow": float(g.snow),
            "u_grid_spacing": float(g.grid_spacing),
            "u_grid_lin": _linear(g.grid_color),
            "u_grid_strength": float(g.grid_strength),
            "u_noise": 3,
            "u_ground_mask": 4,
            "u_rect": rect if rect is not None else (0.0, 0.0, 1.0, 1.0),
            "u_shadow_strength": 0.9 if rect is not None else 0.0,
        }

    def _ground_detail(self, scene: RenderScene) -> bool:
        """Whether the ground is shaded per pixel near the camera (it then reads its shadow mask itself:
        one more fetch in a pass it pays anyway; otherwise the shadow is a decal over the casters' rectangle)."""
        return self.quality.ground_detail and scene.ground.snow > 0

    def _view_key(
        self, scene: RenderScene, camera: Camera, target: moderngl.Framebuffer, ground: dict[str, Any]
    ) -> bytes | None:
        """What this frame's sky and ground are drawn from (:mod:`engine.render.env_cache`), or ``None``
        when they cannot be kept: the ground reads the shadow mask (detail with a shadow) or a photo,
        or ``target`` is multisampled (no copy into it)."""
        photo = scene.background is not None and scene.background_fade < 1.0
        detail = self._ground_detail(scene)
        if (detail and ground["u_shadow_strength"] > 0.0) or photo or not single_sampled(target):
            return None
        g = scene.ground
        names = self.env.reads(self.env.ground_draws(detail, g.grid, photo, ground))
        hidden = self._sky_hidden(scene, camera, ground["u_extent"])
        flags = (target.size, g.grid, g.visible, hidden, tuple(float(c) for c in scene.horizon_color))
        return view_key(flags, names, {**self._common, **ground})

    def _sky_hidden(self, scene: RenderScene, camera: Camera, extent: float) -> bool:
        """Whether the ground fills the view, hiding the ridge, sky and sun (with a margin for the mesh's
        straight edges on the ground's extent and the ridge's distance)."""
        g = scene.ground
        photo = scene.background is not None and scene.background_fade < 1.0
        reach = 0.9 * min(extent, RIDGE_RADIUS)
        return (
            g.visible and not photo and ground_fills_view(self._common["u_inv_view_proj"], camera.eye, g.height, reach)
        )

    def _draw_sky_and_ground(self, scene: RenderScene, camera: Camera, ground: dict[str, Any]) -> None:
        """Ground, ridge, sky and sun (see :mod:`engine.render.environment`); ``ground``: the ground's uniforms."""
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST)
        photo = scene.background is not None and scene.background_fade < 1.0
        g = scene.ground
        self.shadows.mask.use(location=4)
        if g.visible:
            self.env.draw_ground(self.env.ground_draws(self._ground_detail(scene), g.grid, photo, ground), ground)
        self._mark("ground")
        if not self._sky_hidden(scene, camera, ground["u_extent"]):
            self.env.draw_sky(scene, photo, float(g.height))
        self._mark("sky")
        if photo:
            ctx.depth_func = "<="
            self._vaos["sky_photo"].render(moderngl.TRIANGLES, vertices=3)
            ctx.depth_func = "<"
        ctx.enable_only(moderngl.DEPTH_TEST)

    def _draw_decals(self, scene: RenderScene, rect: tuple[float, float, float, float] | None) -> None:
        """The decals laid on the ground: soft shadow (unless the ground read it), snow track, footprints."""
        if scene.ground.visible:
            decal = rect if rect is not None and not self._ground_detail(scene) else None
            self.env.draw_decals(scene, decal, self.shadows.mask if decal is not None else None)
        self.ctx.enable_only(moderngl.DEPTH_TEST)

    def _upscale(self, framebuffer: moderngl.Framebuffer) -> None:
        """Stretch the smaller 3-D buffer over ``framebuffer`` (nearest texel).

        Drawn into the colour attachment alone: with no depth buffer bound, a BGRA source and
        destination (:mod:`engine.render.bgra`), one texture fetch and no blending, llvmpipe
        copies the texels on its linear path instead of shading each pixel (same pixels,
        measured 5.6 -> 3 ms at 1280x720). Nothing after this pass reads the depth.
        """
        assert self._scaled is not None
        target = self._colour_target(framebuffer)
        target.use()
        target.viewport = (0, 0, *framebuffer.size)
        self.ctx.enable_only(moderngl.NOTHING)
        self._scaled[1].use(location=0)
        set_uniform(self._programs["upscale"], "u_tex", 0)
        self._vaos["upscale"].render(moderngl.TRIANGLES, vertices=3)

    def _set_frame_uniforms(
        self,
        scene: RenderScene,
        camera: Camera,
        vp: NDArray[np.float64],
        light_vp: NDArray[np.float64] | None,
        size: tuple[int, int],
    ) -> None:
        w, h = size
        sun = scene.sun
        direction = np.asarray(sun.direction, dtype=np.float64)
        L = tuple(float(x) for x in direction / np.linalg.norm(direction))
        tan_half = math.tan(math.radians(camera.fov_y) / 2.0)
        eye = tuple(float(x) for x in camera.eye)
        # World size of one shadow-map texel: the light frustum is 2/|row 0 of P@V| wide.
        # Window depth per metre along the light: row 2 of P@V is 2/(far-near) long.
        texel_world, depth_per_m = 0.01, 1.0
        if light_vp is not None:
            texel_world = 2.0 / float(np.linalg.norm(light_vp[0, :3])) / self.shadows.map_size
            depth_per_m = float(np.linalg.norm(light_vp[2, :3])) / 2.0
        bg = scene.background
        bg_scale = (1.0, 1.0)
        if bg is not None:
            img_aspect, view_aspect = bg.shape[1] / bg.shape[0], w / h
            bg_scale = (view_aspect / img_aspect, 1.0) if view_aspect < img_aspect else (1.0, img_aspect / view_aspect)
        common = {
            "u_view_proj": vp,
            "u_eye": eye,
            "u_cam": eye,
            "u_sun_dir": L,
            "u_sun_color": tuple(c * sun.intensity for c in _linear(sun.color)),
            "u_sky_lin": _linear(scene.sky_color),
            "u_horizon_lin": _linear(scene.horizon_color),
            "u_ambient": float(sun.ambient),
            "u_light_vp": light_vp if light_vp is not None else np.eye(4),
            "u_shadow_map": 1,
            "u_shadows_on": 0.0 if light_vp is None else 1.0,
            "u_shadow_texel": 1.0 / self.shadows.map_size,
            "u_softness": float(np.clip(sun.softness / texel_world, 0.5, 4.0)),
            "u_normal_bias": max(3.0 * texel_world, 0.01),
            "u_depth_bias": 0.01 * depth_per_m,
            "u_fog_density": 0.015,
            "u_px_scale": 2.0 * tan_half / h,
            "u_px_per_unit": h / (2.0 * tan_half),
            "u_viewport": (float(w), float(h)),
            "u_background": 2,
            "u_fade": 1.0 if bg is None else float(scene.background_fade),
            "u_bg_scale": bg_scale,
            "u_inv_view_proj": np.linalg.inv(vp),
            "u_inflate_px": 0.0,
        }
        # Only what changed since the last frame is written: a still camera and sun change nothing,
        # and each write is a Python call per program (25 names x 16 programs cost 1.3 ms a frame).
        # What a pass sets over these (the text's viewport, the outline's inflation) it sets every frame.
        last = self._common
        changed = [k for k, v in common.items() if k not in last or not _same_value(last[k], v)]
        for prog in (*self._programs.values(), self.impostors.lit):
            for name in changed:
                set_uniform(prog, name, common[name])
        self.env.set_common(common, changed)
        self._common = common
        outline = tuple(float(c) for c in scene.outline_color)
        for name in ("capsule_flat", "box_flat", "skinned_flat"):
            set_uniform(self._programs[name], "u_color", outline)
            set_uniform(self._programs[name], "u_inflate_px", float(scene.outline_width))

    def _background_texture(self, scene: RenderScene) -> moderngl.Texture:
        """The photo as a texture, uploaded again only when a different array is set."""
        bg = scene.background
        if bg is None:
            return self._blank
        if bg is not self._background_src or self._background is None:
            if self._background is not None:
                self._background.release()
            self._background = self.ctx.texture((bg.shape[1], bg.shape[0]), 3, np.ascontiguousarray(bg).tobytes())
            self._background.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._background_src = bg
        return self._background

    def _draw_overlays(self, scene: RenderScene, vp: NDArray[np.float64]) -> None:
        """Pictures over the view: depth-placed ones against the scene's depth, the rest on top."""
        if not scene.overlays:
            return
        prog = self._programs["overlay"]
        set_uniform(prog, "u_tex", 0)
        for ov in scene.overlays:
            depth = 0.0
            if ov.depth_at is not None:
                clip = vp @ np.array([*ov.depth_at, 1.0])
                if clip[3] <= 1e-9:
                    continue  # behind the camera
                depth = float(np.clip(clip[2] / clip[3] * 0.5 + 0.5, 0.0, 1.0))
                self.ctx.enable(moderngl.DEPTH_TEST)
            else:
                self.ctx.disable(moderngl.DEPTH_TEST)
            img = ov.image
            tex = self.ctx.texture((img.shape[1], img.shape[0]), 4, img.tobytes())
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.use(location=0)
            for name, value in (
                ("u_rect", ov.rect),
                ("u_alpha", ov.alpha),
                ("u_depth", depth),
                ("u_photo", 1.0 if ov.photo else 0.0),
            ):
                set_uniform(prog, name, value)
            self._vaos["overlay"].render(moderngl.TRIANGLE_STRIP)
            tex.release()
        self.ctx.enable(moderngl.DEPTH_TEST)

    def _draw_text(self, scene: RenderScene, size: tuple[int, int]) -> None:
        if not scene.texts:
            return
        self.ctx.disable(moderngl.DEPTH_TEST)
        prog = self._programs["text"]
        set_uniform(prog, "u_tex", 0)
        set_uniform(prog, "u_viewport", (float(size[0]), float(size[1])))
        for piece in layout_text(scene.texts, size, self.text):
            tex = self.text.texture(piece.text, piece.size, piece.color)
            tex.use(location=0)
            set_uniform(prog, "u_rect", (piece.x, piece.y, float(tex.size[0]), float(tex.size[1])))
            set_uniform(prog, "u_alpha", piece.alpha)
            self._vaos["text"].render(moderngl.TRIANGLE_STRIP)

    def release(self) -> None:
        """Free every GPU object this renderer made."""
        self.text.release()
        self.shadows.release()
        self.skinned.release()
        self.env.release()
        self.env_cache.release()
        self.impostors.release()
        self._release_scaled()
        for batches in self._lod.values():
            batches.release()
        for v in self._vaos.values():
            v.release()
        for i in (*self._inst.values(), *self._outline_inst.values()):
            i.buf.release()
        objects: tuple[Releasable, ...] = (*self._buffers, *self._programs.values(), self._blank, self._noise)
        for obj in objects:
            obj.release()
        if self._background is not None:
            self._background.release()
