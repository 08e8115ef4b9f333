"""Sun shadows: a depth map for shadows on objects, a blurred mask for the ground.

One depth map, read two ways, because the costs differ on a software rasteriser. Objects
cover few pixels, so they read the map with a 4-tap PCF kernel. The ground covers most of
the screen and a PCF kernel there cost more than all its other shading together, so the
map is instead read with that kernel once per texel of a small top-down mask of the
ground under the casters, and the ground reads the mask back with one bilinear fetch:
soft, smooth penumbrae at a fixed low cost.

Both fit themselves to the casters each frame (:func:`light_matrix`, :func:`ground_rect`)
so their resolution goes where the puppets are.

The scenery (cones and boxes: trees, rocks) is drawn into a depth map of its own and kept
while it and the sun's matrix stay the same; each frame starts the shadow map as a copy of
it and draws only the capsules, spheres and characters on top. In the loaded snowman field
the trees' cones were a third of the shadow pass at quality low (1.8 of 5.3 ms). The matrix
is fitted to every caster's bounds, so the copy is reused while the puppets move inside the
box the trees (and the outermost balls) span, which is where they play; it is redrawn when
that box changes.
"""

from __future__ import annotations

from collections.abc import Callable

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.camera import look_at
from engine.render import meshes
from engine.render import shaders as S
from engine.render import shaders_env as E
from engine.render.env_meshes import cone_mesh
from engine.render.gpu import Instances, LodBatches, Releasable, mesh_buffers, set_uniform
from engine.render.lod import LEVELS, LIMITS, choose_levels_orthographic, level_meshes
from engine.render.rawgl import blit_depth
from engine.render.scene import CAPSULE_STRIDE, RenderScene

__all__ = ["Shadows", "light_matrix", "ground_rect"]

CAPSULE_FMT = ("3f 3f 1f 3f 1f/i", "i_a", "i_b", "i_r", "i_color", "i_outline")
BOX_FMT = ("3f 3f 4f 3f 1f/i", "i_center", "i_half", "i_rot", "i_color", "i_outline")


def _ortho(half: float, near: float, far: float) -> NDArray[np.float64]:
    m = np.eye(4)
    m[0, 0] = m[1, 1] = 1.0 / half
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


def _sun(scene: RenderScene) -> NDArray[np.float64]:
    L = np.asarray(scene.sun.direction, dtype=np.float64)
    n = float(np.linalg.norm(L))
    if not n > 0:
        raise ValueError("sun direction must be non-zero")
    return L / n


def _corners(lo: NDArray[np.float64], hi: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def _on_ground(points: NDArray[np.float64], L: NDArray[np.float64], height: float) -> NDArray[np.float64]:
    """Where each point's shadow lands on the plane ``y = height`` (points below stay put)."""
    drop = np.maximum(points[:, 1] - height, 0.0) / max(L[1], 0.05)
    return points - drop[:, None] * L


Bounds = tuple[NDArray[np.float64], NDArray[np.float64]] | None
"""``scene.bounds()``: passed in by a caller that needs it twice (it walks every caster row)."""


def light_matrix(scene: RenderScene, bounds: Bounds = None) -> NDArray[np.float64] | None:
    """The sun's orthographic view-projection around every caster (``bounds``: ``scene.bounds()``
    if given), ``None`` without casters.

    The sides hug the casters' bounding sphere; the depth range runs from the nearest
    caster to where their shadows land on the ground, tight for depth precision.
    """
    b = scene.bounds() if bounds is None else bounds
    if b is None:
        return None
    lo, hi = b
    center = (lo + hi) / 2.0
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 0.25) * 1.05
    L = _sun(scene)
    up = np.array([0.0, 1.0, 0.0]) if abs(L[1]) < 0.99 else np.array([0.0, 0.0, 1.0])
    view = look_at(center + L * radius, center, up)
    corners = _corners(lo, hi)
    pts = np.vstack([corners, _on_ground(corners, L, scene.ground.height)])
    depth = -(pts @ view[:3, :3].T + view[:3, 3])[:, 2]
    near, far = float(depth.min()) - 0.1, float(depth.max()) + 0.1  # orthographic: near may be negative
    return _ortho(radius, near, far) @ view


def ground_rect(
    scene: RenderScene, margin: float = 0.5, bounds: Bounds = None
) -> tuple[float, float, float, float] | None:
    """``(x0, z0, width, depth)`` on the ground covering every caster's planar shadow (``bounds`` as for
    :func:`light_matrix`)."""
    b = scene.bounds() if bounds is None else bounds
    if b is None:
        return None
    g = _on_ground(_corners(*b), _sun(scene), scene.ground.height)
    x0, z0 = g[:, 0].min() - margin, g[:, 2].min() - margin
    x1, z1 = g[:, 0].max() + margin, g[:, 2].max() + margin
    return float(x0), float(z0), float(x1 - x0), float(z1 - z0)


class Shadows:
    """GPU side of both shadow techniques for one context.

    Args:
        ctx: the context.
        boxes, cones: the renderer's box and cone instance buffers (shared, not copied). Capsules and
            spheres come with each frame, since their level of detail in the shadow
            map depends on its texels as well as on the camera's.
        map_size: side of the object shadow map; mask_size: side of the ground mask.
    """

    def __init__(
        self,
        ctx: moderngl.Context,
        boxes: Instances,
        map_size: int = 1024,
        mask_size: int = 512,
        cones: Instances | None = None,
    ) -> None:
        if map_size < 16 or mask_size < 16:
            raise ValueError(f"shadow sizes must be at least 16, got {map_size} and {mask_size}")
        self.ctx = ctx
        self.map_size, self.mask_size = map_size, mask_size
        h = S.HEADER
        progs = self._programs = {
            "capsule_depth": ctx.program(vertex_shader=h + S.CAPSULE_VS, fragment_shader=h + S.DEPTH_FS),
            "box_depth": ctx.program(vertex_shader=h + S.BOX_VS, fragment_shader=h + S.DEPTH_FS),
            "cone_depth": ctx.program(vertex_shader=h + S.CONE_VS, fragment_shader=h + S.DEPTH_FS),
            "mask": ctx.program(vertex_shader=h + E.FULLSCREEN_VS, fragment_shader=h + E.MASK_FS),
        }
        # Casters at the coarsest level whose outline stays within a shadow-map texel.
        self._lod = {
            kind: LodBatches(ctx, progs["capsule_depth"], level_meshes(kind), CAPSULE_FMT, 4 * CAPSULE_STRIDE)
            for kind in LEVELS
        }
        self._boxes = boxes
        self._buffers = list(mesh_buffers(ctx, meshes.box_mesh()))
        self._box_vao = ctx.vertex_array(
            progs["box_depth"],
            [(self._buffers[0], "3f 3f", "in_pos", "in_normal"), (boxes.buf, *BOX_FMT)],
            self._buffers[1],
            4,
            skip_errors=True,
        )
        self._mask_vao = ctx.vertex_array(progs["mask"], [])
        self._cones = cones
        self._cone_vao = None
        if cones is not None:
            self._buffers += list(mesh_buffers(ctx, cone_mesh()))
            self._cone_vao = ctx.vertex_array(
                progs["cone_depth"],
                [(self._buffers[2], "4f", "in_vert"), (cones.buf, *CAPSULE_FMT)],
                self._buffers[3],
                4,
                skip_errors=True,
            )
        self.depth = ctx.depth_texture((map_size, map_size))
        self.depth.compare_func = "<="
        self.depth.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.depth.repeat_x = self.depth.repeat_y = False
        self._depth_fbo = ctx.framebuffer(depth_attachment=self.depth)
        self._scenery = ctx.depth_texture((map_size, map_size))
        self._scenery_fbo = ctx.framebuffer(depth_attachment=self._scenery)
        self._scenery_key: bytes | None = None
        """What :attr:`_scenery` holds: the sun's matrix and the cone and box rows it was drawn from."""
        self.mask = ctx.texture((mask_size, mask_size), 1)
        self.mask.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.mask.repeat_x = self.mask.repeat_y = False
        self._mask_fbo = ctx.framebuffer([self.mask])

    def render(
        self,
        scene: RenderScene,
        casters: dict[str, tuple[NDArray[np.float32], NDArray[np.intp]]],
        light_vp: NDArray[np.float64],
        rect: tuple[float, float, float, float],
        more_casters: Callable[[NDArray[np.float64]], None] | None = None,
    ) -> None:
        """Draw the object shadow map and the ground mask for this frame.

        ``casters`` maps "capsules" and "spheres" to the scene's rows and the level each
        is drawn at for the camera; ``more_casters(light_vp)`` draws what else casts (skinned
        characters) into the bound depth map. In the shadow map a caster is one level coarser than
        on screen (or coarser still if its texels allow): a coarser caster's faces lie
        inside the surface drawn, which keeps the PCF taps on curved, sun-facing surfaces
        from shadowing the surface itself in blotches (acne); a finer one stands outside it.
        """
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST)
        texels_per_metre = self.map_size * float(np.linalg.norm(light_vp[0, :3])) / 2.0
        for prog in (self._programs["capsule_depth"], self._programs["box_depth"], self._programs["cone_depth"]):
            set_uniform(prog, "u_view_proj", light_vp)
            set_uniform(prog, "u_inflate_px", 0.0)
        self._start_map(scene, light_vp)
        for kind, (rows, on_screen) in casters.items():
            in_map = choose_levels_orthographic(rows, texels_per_metre, LIMITS[kind])
            self._lod[kind].upload(rows, np.minimum(in_map, np.maximum(on_screen - 1, 0)))
            self._lod[kind].render()
        if more_casters is not None:
            more_casters(light_vp)
        self._mask_fbo.use()
        ctx.enable_only(moderngl.NOTHING)
        mask = self._programs["mask"]
        self.depth.use(location=0)
        # Ground points a centimetre below the casters' surface along the light are still
        # lit. The taps spread over half the penumbra (the spread of the Gaussian the
        # ground's penumbra once was), and at least over a mask texel's footprint, so a
        # caster thinner than a texel (a twig arm across a wide field) still darkens the
        # texels it crosses wherever it falls between their centres, rather than flicker.
        uv_per_metre = float(np.linalg.norm(light_vp[0, :3])) / 2.0
        spread = max(0.5 * scene.sun.softness, 0.5 * max(rect[2], rect[3]) / self.mask_size)
        for name, value in (
            ("u_shadow_map", 0),
            ("u_light_vp", light_vp),
            ("u_rect", rect),
            ("u_height", float(scene.ground.height)),
            ("u_spread", spread * uv_per_metre),
            ("u_depth_bias", 0.01 * float(np.linalg.norm(light_vp[2, :3])) / 2.0),
        ):
            set_uniform(mask, name, value)
        self._mask_vao.render(moderngl.TRIANGLES, vertices=3)

    def _start_map(self, scene: RenderScene, light_vp: NDArray[np.float64]) -> None:
        """Bind the shadow map holding the scenery's depth: a copy of :attr:`_scenery`, drawn again only
        when the sun's matrix or the cone and box rows changed (a plain clear without scenery)."""
        cones = self._cone_vao is not None and self._cones is not None and self._cones.count > 0
        if not cones and not self._boxes.count:
            self._depth_fbo.use()
            self._depth_fbo.clear(depth=1.0)
            return
        key = b"".join(np.ascontiguousarray(a).tobytes() for a in (light_vp, scene.cones.data, scene.boxes.data))
        if key != self._scenery_key:
            self._scenery_fbo.use()
            self._scenery_fbo.clear(depth=1.0)
            self._draw_scenery(cones)
            self._scenery_key = key
        if not blit_depth(self._depth_fbo.glo, self._scenery_fbo.glo, (self.map_size, self.map_size)):
            self._scenery_key = None  # no depth copy here: draw the scenery into the map itself
            self._depth_fbo.use()
            self._depth_fbo.clear(depth=1.0)
            self._draw_scenery(cones)
            return
        self._depth_fbo.use()

    def _draw_scenery(self, cones: bool) -> None:
        """The boxes and (if ``cones``) the cones into the bound depth buffer."""
        if self._boxes.count:
            self._box_vao.render(moderngl.TRIANGLES, instances=self._boxes.count)
        if cones and self._cone_vao is not None and self._cones is not None:
            self._cone_vao.render(moderngl.TRIANGLES, instances=self._cones.count)

    def release(self) -> None:
        """Free the GPU objects."""
        for batches in self._lod.values():
            batches.release()
        self._box_vao.release()
        self._mask_vao.release()
        if self._cone_vao is not None:
            self._cone_vao.release()
        objects: tuple[Releasable, ...] = (
            *self._buffers,
            *self._programs.values(),
            self._depth_fbo,
            self.depth,
            self._scenery_fbo,
            self._scenery,
            self._mask_fbo,
            self.mask,
        )
        for obj in objects:
            obj.release()
