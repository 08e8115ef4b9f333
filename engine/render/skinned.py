"""Skinned characters on the GPU: glTF skins drawn with linear blend skinning in the vertex shader.

Each :class:`SkinnedInstance` of a scene is one character in one pose: its
:class:`~engine.io.gltf_mesh.SkinnedMeshes` and its joints' skinning matrices. All instances of
one mesh are one instanced draw per primitive: the matrices of every instance go into one
float texture (four texels — the four columns — per joint, one row per joint of each
instance), read with ``texelFetch`` at ``gl_InstanceID × joints + joint``. A texture, not a
uniform array, because a crowd of characters outgrows any uniform block.

Lighting and fog are the mannequin's (:mod:`engine.render.shaders`), so a character stands in
the same sun and receives the same shadows. The vertex stage is also compiled alone with
transform feedback (:meth:`SkinnedDraw.skinned_positions`), which lets a test read back what
the shader computed and compare it with the CPU reference, :func:`engine.skinning.blend_skin`.
"""

from __future__ import annotations

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.io.gltf_mesh import SkinnedMeshes, SkinnedPrimitive
from engine.render import shaders as S
from engine.render.gpu import set_uniform
from engine.render.scene import SkinnedInstance

__all__ = ["SkinnedInstance", "SkinnedDraw", "SKIN_VS", "SKIN_FS"]

SKIN_VS = """
uniform mat4 u_view_proj;
uniform vec3 u_cam;
uniform float u_fog_density;
uniform sampler2D u_joint_tex;  // RGBA32F: texel (c, row) is column c of a joint's matrix
uniform int u_joint_count;
uniform float u_inflate_px;     // the outline pass: grow along the normal by this many pixels
uniform float u_px_scale;
in vec3 in_pos;
in vec3 in_normal;
in vec2 in_uv;
in uvec4 in_joints;
in vec4 in_weights;
out vec3 v_pos;
out vec3 v_normal;
out vec2 v_uv;
out float v_fog;
mat4 joint_matrix(uint j) {
    int row = gl_InstanceID * u_joint_count + int(j);
    return mat4(texelFetch(u_joint_tex, ivec2(0, row), 0), texelFetch(u_joint_tex, ivec2(1, row), 0),
                texelFetch(u_joint_tex, ivec2(2, row), 0), texelFetch(u_joint_tex, ivec2(3, row), 0));
}
void main() {
    mat4 m = in_weights.x * joint_matrix(in_joints.x) + in_weights.y * joint_matrix(in_joints.y)
           + in_weights.z * joint_matrix(in_joints.z) + in_weights.w * joint_matrix(in_joints.w);
    vec4 p = m * vec4(in_pos, 1.0);
    v_normal = mat3(m) * in_normal;  // rigid joints with a uniform scale: no inverse-transpose needed
    if (u_inflate_px > 0.0) p.xyz += normalize(v_normal) * (u_inflate_px * u_px_scale * length(p.xyz - u_cam));
    v_pos = p.xyz;
    v_uv = in_uv;
    float fog = length(v_pos - u_cam) * u_fog_density;
    v_fog = fog / (1.0 + fog);
    gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
"""

SKIN_FS = """
uniform sampler2D u_base;
uniform vec4 u_base_factor;   // linear, as glTF gives it
in vec3 v_pos;
in vec3 v_normal;
in vec2 v_uv;
in float v_fog;
out vec4 f_color;
void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    float sh = shadow_factor(v_pos, n);
    vec3 albedo = to_linear(texture(u_base, v_uv).rgb) * u_base_factor.rgb;
    vec3 c = shade(albedo, n, v_pos, sh, 16.0, 0.1);
    f_color = vec4(finish(mix(c, u_horizon_lin * SKY_GAIN, v_fog)), 1.0);
}
"""

_VERTEX_FMT = ("3f 3f 2f 4u2 4f", "in_pos", "in_normal", "in_uv", "in_joints", "in_weights")
_JOINT_TEX_UNIT, _BASE_TEX_UNIT = 5, 6


def _vertices(p: SkinnedPrimitive) -> bytes:
    """Interleaved rows matching :data:`_VERTEX_FMT` (40 bytes a vertex)."""
    row = np.dtype([("pos", "<f4", 3), ("nrm", "<f4", 3), ("uv", "<f4", 2), ("j", "<u2", 4), ("w", "<f4", 4)])
    out = np.empty(len(p.positions), dtype=row)
    out["pos"], out["nrm"], out["uv"], out["j"], out["w"] = p.positions, p.normals, p.uv, p.joints, p.weights
    return out.tobytes()


class _PrimitiveGPU:
    """Buffers, vertex arrays and base-colour texture of one primitive."""

    def __init__(
        self,
        ctx: moderngl.Context,
        prim: SkinnedPrimitive,
        lit: moderngl.Program,
        feedback: moderngl.Program,
        depth: moderngl.Program,
        flat: moderngl.Program,
    ) -> None:
        self.vbo = ctx.buffer(_vertices(prim))
        self.ibo = ctx.buffer(np.ascontiguousarray(prim.indices, dtype=np.uint32).tobytes())
        self.lit = ctx.vertex_array(lit, [(self.vbo, *_VERTEX_FMT)], self.ibo, 4, skip_errors=True)
        self.feedback = ctx.vertex_array(feedback, [(self.vbo, *_VERTEX_FMT)], skip_errors=True)
        self.depth = ctx.vertex_array(depth, [(self.vbo, *_VERTEX_FMT)], self.ibo, 4, skip_errors=True)
        self.flat = ctx.vertex_array(flat, [(self.vbo, *_VERTEX_FMT)], self.ibo, 4, skip_errors=True)
        img = prim.texture if prim.texture is not None else np.full((1, 1, 4), 255, dtype=np.uint8)
        self.texture = ctx.texture((img.shape[1], img.shape[0]), 4, np.ascontiguousarray(img).tobytes())
        if prim.texture is not None:
            self.texture.build_mipmaps()
            self.texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        self.color = prim.color
        self.vertices = len(prim.positions)

    def release(self) -> None:
        for obj in (self.lit, self.feedback, self.depth, self.flat, self.vbo, self.ibo, self.texture):
            obj.release()


class SkinnedDraw:
    """Draws :class:`SkinnedInstance` lists; GPU copies of each mesh are made once and kept.

    ``lit`` must be compiled from :data:`SKIN_VS` and ``LIGHTING`` + :data:`SKIN_FS`, ``flat`` from
    :data:`SKIN_VS` and the flat outline shader, so the renderer's frame uniforms (camera, sun,
    shadow map, outline colour and width) reach them with the other programs'.
    """

    def __init__(self, ctx: moderngl.Context, lit: moderngl.Program, flat: moderngl.Program) -> None:
        self.ctx = ctx
        self.lit, self.flat = lit, flat
        self.feedback = ctx.program(vertex_shader=S.HEADER + SKIN_VS, varyings=("v_pos",))
        self.depth = ctx.program(vertex_shader=S.HEADER + SKIN_VS, fragment_shader=S.HEADER + S.DEPTH_FS)
        self._meshes: dict[int, tuple[SkinnedMeshes, list[_PrimitiveGPU]]] = {}
        self._joints: moderngl.Texture | None = None
        # Transform feedback still issues a draw call, which needs a bound framebuffer (a
        # standalone EGL context has none): a 1x1 one of our own, rasteriser discarded.
        self._scratch = ctx.simple_framebuffer((1, 1))

    def _gpu(self, meshes: SkinnedMeshes) -> list[_PrimitiveGPU]:
        key = id(meshes)
        if key not in self._meshes:  # the meshes object is kept with its copies, so its id stays its own
            programs = (self.lit, self.feedback, self.depth, self.flat)
            prims = [_PrimitiveGPU(self.ctx, p, *programs) for p in meshes.primitives]
            self._meshes[key] = (meshes, prims)
        return self._meshes[key][1]

    def _upload_joints(self, matrices: NDArray[np.float64]) -> int:
        """Write ``[n,K,4,4]`` matrices as rows of four column texels; the joint count."""
        n, k = matrices.shape[:2]
        cols = np.ascontiguousarray(matrices.transpose(0, 1, 3, 2).reshape(n * k, 4, 4), dtype=np.float32)
        size = (4, n * k)
        if self._joints is None or self._joints.size != size:
            if self._joints is not None:
                self._joints.release()
            self._joints = self.ctx.texture(size, 4, dtype="f4")
            self._joints.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._joints.write(cols.tobytes())
        self._joints.use(location=_JOINT_TEX_UNIT)
        for prog in (self.lit, self.feedback, self.depth, self.flat):
            set_uniform(prog, "u_joint_tex", _JOINT_TEX_UNIT)
            set_uniform(prog, "u_joint_count", k)
        return k

    @staticmethod
    def _by_mesh(instances: list[SkinnedInstance]) -> list[tuple[SkinnedMeshes, NDArray[np.float64]]]:
        """The instances grouped by mesh: each mesh once, with the ``[n,K,4,4]`` matrices of its instances."""
        groups: dict[int, list[SkinnedInstance]] = {}
        for inst in instances:
            groups.setdefault(id(inst.meshes), []).append(inst)
        return [(g[0].meshes, np.stack([np.asarray(i.matrices, dtype=np.float64) for i in g])) for g in groups.values()]

    def draw(self, instances: list[SkinnedInstance]) -> None:
        """Draw every instance (depth-tested, back faces culled as the caller set); one draw per mesh primitive."""
        for meshes, matrices in self._by_mesh(instances):
            self._upload_joints(matrices)
            set_uniform(self.lit, "u_base", _BASE_TEX_UNIT)
            for prim in self._gpu(meshes):
                prim.texture.use(location=_BASE_TEX_UNIT)
                set_uniform(self.lit, "u_base_factor", prim.color)
                prim.lit.render(moderngl.TRIANGLES, instances=len(matrices))

    def draw_outline(self, instances: list[SkinnedInstance]) -> None:
        """The outlined instances, grown along their normals in the flat outline colour (the caller culls
        front faces, so only a rim round the silhouette shows, as the mannequin's outline does)."""
        for meshes, matrices in self._by_mesh([i for i in instances if i.outline]):
            self._upload_joints(matrices)
            for prim in self._gpu(meshes):
                prim.flat.render(moderngl.TRIANGLES, instances=len(matrices))

    def draw_depth(self, instances: list[SkinnedInstance], view_proj: NDArray[np.float64]) -> None:
        """Draw every instance's depth only, seen through ``view_proj`` (the sun's shadow map)."""
        set_uniform(self.depth, "u_view_proj", view_proj)
        for meshes, matrices in self._by_mesh(instances):
            self._upload_joints(matrices)
            for prim in self._gpu(meshes):
                prim.depth.render(moderngl.TRIANGLES, instances=len(matrices))

    def skinned_positions(self, instance: SkinnedInstance) -> list[NDArray[np.float32]]:
        """What the vertex shader computes for each primitive's vertices ``[V,3]`` (transform feedback)."""
        self._upload_joints(np.asarray(instance.matrices, dtype=np.float64)[None])
        previous = self.ctx.fbo
        self._scratch.use()
        out = []
        for prim in self._gpu(instance.meshes):
            buf = self.ctx.buffer(reserve=prim.vertices * 12)
            prim.feedback.transform(buf, mode=moderngl.POINTS, vertices=prim.vertices)
            out.append(np.frombuffer(buf.read(), dtype=np.float32).reshape(-1, 3).copy())
            buf.release()
        if previous is not None:
            previous.use()
        return out

    def release(self) -> None:
        """Free every GPU object made here (the lit program belongs to the renderer)."""
        for _, prims in self._meshes.values():
            for p in prims:
                p.release()
        self._meshes.clear()
        self.feedback.release()
        self.depth.release()
        self._scratch.release()
        if self._joints is not None:
            self._joints.release()
