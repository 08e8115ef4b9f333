"""Capsules and spheres as ray-cast impostors: four vertices per solid instead of dozens.

A crowd on a software rasteriser (llvmpipe) is bound by its vertex stage, which runs
on the main thread: 100 puppets are 2,100 capsules, and even at their coarsest level of
detail their meshes cost more than all the pixels they cover (measured: the crowd's
frame at 5 % of the pixels cost 80 % of the full frame). An impostor draws one quad
facing the eye (or the sun) over each solid's outline and finds the surface per pixel:
the ray from the eye through the pixel meets the capsule (a cylinder and two end spheres)
exactly, so the outline is round at any size and the depth written is the surface's.

The quad lies across the view in front of the whole solid, as wide as the solid is seen
across the view: seen from the eye every point of the solid is then behind the quad and
inside its outline (a central projection onto a nearer plane only shrinks it). It covers
about 1.3 times the outline of a sphere where the bounding box's back faces covered 2.2
times, with two triangles instead of six (the box, measured in the crowd's frame: the
triangles cost more than the pixels). When the eye is within the solid's depth or the quad
would cross the near plane, the quad covers the whole view at the near plane instead.
The same program draws the sun's shadow map, with the light's parallel rays.
"""

from __future__ import annotations

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.render import shaders as S
from engine.render.gpu import Instances, mesh_buffers, set_uniform
from engine.render.scene import CAPSULE_STRIDE
from engine.render.shadows import CAPSULE_FMT

__all__ = ["IMPOSTOR_VS", "IMPOSTOR_FS", "IMPOSTOR_DEPTH_FS", "quad_corners", "Impostors"]


def quad_corners() -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """The square ``[-1, 1]²``: four corners and two triangles (drawn without face culling)."""
    corners = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1]], dtype=np.float32)
    return corners, np.array([[0, 1, 2], [2, 1, 3]], dtype=np.int32)


# The quad over a capsule's outline, across the view and in front of the whole capsule.
IMPOSTOR_VS = """
uniform mat4 u_view_proj;
uniform mat4 u_inv_view_proj;
uniform vec4 u_view;            // xyz: the eye (w = 1), or the direction the light looks (w = 0)
uniform vec3 u_cam;
uniform float u_fog_density;
in vec2 in_corner;              // -1..1
in vec3 i_a;
in vec3 i_b;
in float i_r;
in vec3 i_color;
in float i_outline;
out vec3 v_pos;
flat out vec3 v_a;
flat out vec3 v_b;
flat out float v_r;
flat out vec3 v_color;
flat out float v_fog;
void main() {
    vec3 c = 0.5 * (i_a + i_b);
    vec3 h = 0.5 * (i_b - i_a);
    float r = i_r * 1.01;       // a hair larger: the quad's edges never clip the outline
    bool persp = u_view.w > 0.5;
    vec3 d = persp ? c - u_view.xyz : u_view.xyz;
    float dist = length(d);
    d = dist > 1e-9 ? d / dist : vec3(0.0, 0.0, -1.0);
    float ahead = abs(dot(h, d)) + r;           // how far the capsule reaches towards the eye
    vec3 across = h - d * dot(h, d);            // the half axis as seen across the view
    float half_len = length(across);
    vec3 helper = abs(d.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = half_len > 1e-6 * r ? across / half_len : normalize(cross(d, helper));
    vec3 side = cross(d, u);
    vec3 centre = persp ? u_view.xyz + d * (dist - ahead) : c - d * ahead;
    vec4 C = u_view_proj * vec4(centre, 1.0);
    vec4 U = u_view_proj * vec4(u * (half_len + r), 0.0);
    vec4 V = u_view_proj * vec4(side * r, 0.0);
    // Clip z + w is linear over the quad: its least value over the corners says whether any
    // corner is behind the near plane (same answer for the instance's four vertices).
    bool near = persp && (dist - ahead <= 0.0 || C.z + C.w - abs(U.z + U.w) - abs(V.z + V.w) <= 0.0);
    if (near) {
        vec4 p = u_inv_view_proj * vec4(in_corner, -1.0, 1.0);
        v_pos = p.xyz / p.w;
        gl_Position = vec4(in_corner, 0.0, 1.0);
    } else {
        v_pos = centre + u * (in_corner.x * (half_len + r)) + side * (in_corner.y * r);
        gl_Position = C + U * in_corner.x + V * in_corner.y;
    }
    v_a = i_a;
    v_b = i_b;
    v_r = i_r;
    v_color = i_color;
    float fog = length(c - u_cam) * u_fog_density;
    v_fog = fog / (1.0 + fog);
}
"""

# Where the ray first enters the capsule: the nearest of the cylinder's entry (if it lies
# between the ends) and the two end spheres' entries; a miss discards the pixel.
_HIT = """
uniform mat4 u_view_proj;
uniform vec4 u_view;
in vec3 v_pos;
flat in vec3 v_a;
flat in vec3 v_b;
flat in float v_r;
float sphere_entry(vec3 ro, vec3 rd, vec3 c, float r) {
    vec3 oc = ro - c;
    float b = dot(rd, oc);
    float h = b * b - dot(oc, oc) + r * r;
    return h >= 0.0 ? -b - sqrt(h) : 1e20;
}
vec3 hit_point(out vec3 ro, out vec3 rd) {
    float reach = length(v_b - v_a) + 4.0 * v_r;
    rd = u_view.w > 0.5 ? normalize(v_pos - u_view.xyz) : u_view.xyz;
    ro = u_view.w > 0.5 ? u_view.xyz : v_pos - rd * reach;
    vec3 ba = v_b - v_a;
    vec3 oa = ro - v_a;
    float baba = dot(ba, ba), bard = dot(ba, rd), baoa = dot(ba, oa);
    float a = baba - bard * bard;
    float b = baba * dot(rd, oa) - baoa * bard;
    float c = baba * dot(oa, oa) - baoa * baoa - v_r * v_r * baba;
    float h = b * b - a * c;
    float t = min(sphere_entry(ro, rd, v_a, v_r), sphere_entry(ro, rd, v_b, v_r));
    if (a > 1e-9 && h >= 0.0) {
        float tc = (-b - sqrt(h)) / a;
        float along = baoa + tc * bard;
        if (along > 0.0 && along < baba) t = min(t, tc);
    }
    if (t > 1e19 || t < 0.0) discard;
    vec3 p = ro + rd * t;
    vec4 clip = u_view_proj * vec4(p, 1.0);
    gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
    return p;
}
"""

IMPOSTOR_FS = (
    _HIT
    + """
flat in vec3 v_color;
flat in float v_fog;
out vec4 f_color;
void main() {
    vec3 ro, rd;
    vec3 p = hit_point(ro, rd);
    vec3 ba = v_b - v_a;
    float k = clamp(dot(p - v_a, ba) / max(dot(ba, ba), 1e-12), 0.0, 1.0);
    vec3 n = (p - (v_a + ba * k)) / v_r;
    float sh = shadow_factor(p, n);
    vec3 c = shade(to_linear(v_color), n, p, sh, 28.0, 0.25);
    f_color = vec4(finish(mix(c, u_horizon_lin * SKY_GAIN, v_fog)), 1.0);
}
"""
)

IMPOSTOR_DEPTH_FS = (
    _HIT
    + """
out vec4 f_color;
void main() {
    vec3 ro, rd;
    hit_point(ro, rd);
    f_color = vec4(1.0);
}
"""
)


class Impostors:
    """Capsule and sphere rows drawn as impostors, lit (camera) or depth only (shadow map)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        h, lit = S.HEADER, S.HEADER + S.LIGHTING
        self.lit = ctx.program(vertex_shader=h + IMPOSTOR_VS, fragment_shader=lit + IMPOSTOR_FS)
        self.depth = ctx.program(vertex_shader=h + IMPOSTOR_VS, fragment_shader=h + IMPOSTOR_DEPTH_FS)
        self._vbo, self._ibo = mesh_buffers(ctx, quad_corners())
        self._inst = Instances(ctx, 4 * CAPSULE_STRIDE)
        self._shadow_inst = Instances(ctx, 4 * CAPSULE_STRIDE)
        self._vaos = {
            name: ctx.vertex_array(
                prog, [(self._vbo, "2f", "in_corner"), (inst.buf, *CAPSULE_FMT)], self._ibo, 4, skip_errors=True
            )
            for name, prog, inst in (("lit", self.lit, self._inst), ("depth", self.depth, self._shadow_inst))
        }

    def draw(self, rows: NDArray[np.float32], eye: NDArray[np.float64]) -> None:
        """Lit solids seen from ``eye`` (the frame's uniforms are already set on :attr:`lit`).

        Face culling is off for the quads and on again afterwards.
        """
        if not self._inst.upload(rows):
            return
        set_uniform(self.lit, "u_view", (float(eye[0]), float(eye[1]), float(eye[2]), 1.0))
        self.ctx.disable(moderngl.CULL_FACE)
        self._vaos["lit"].render(moderngl.TRIANGLES, instances=self._inst.count)
        self.ctx.enable(moderngl.CULL_FACE)

    def draw_depth(self, rows: NDArray[np.float32], light_vp: NDArray[np.float64], look: NDArray[np.float64]) -> None:
        """The solids into the bound shadow map; ``look``: the unit direction the light's rays travel."""
        if not self._shadow_inst.upload(rows):
            return
        set_uniform(self.depth, "u_view_proj", light_vp)
        set_uniform(self.depth, "u_view", (float(look[0]), float(look[1]), float(look[2]), 0.0))
        self.ctx.disable(moderngl.CULL_FACE)
        self._vaos["depth"].render(moderngl.TRIANGLES, instances=self._shadow_inst.count)

    def release(self) -> None:
        """Free the GPU objects."""
        for vao in self._vaos.values():
            vao.release()
        for buf in (self._vbo, self._ibo, self._inst.buf, self._shadow_inst.buf):
            buf.release()
        self.lit.release()
        self.depth.release()
